#!/usr/bin/env bash
# model_xc430 — a servo model added as data only (protocol/dxl2_table.c: its
# control table's rows and its descriptor; daemon/servo_model.c and the
# simulator make theirs from it): the XC430-W150, simulated, found by `dxl`
# with its own factory values and datasheet, checked by `dxl doctor`, and
# driven by undulated in position actuation (its PWM-only drive refuses
# torque_drive = current, as the XL430's does).
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"; X="$B/dxl"
if [ ! -x "$S" ] || [ ! -x "$D" ] || [ ! -x "$X" ]; then tap_skip_all "undulate-sim, undulated or dxl not built"; fi
R="t$$"
URL=$(lcm_url 7724)

run() {   # run NAME ARGS...: dxl on Protocol 2.0 with 100 ms for replies (a loaded machine)
	local name=$1; shift
	rc=0
	timeout 60 "$X" --timeout-ms 100 --protocol 2 --port "$T/bus" --baud 1000000 "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
}

spawn sim "$S" --model xc430-w150 --link "$T/bus" --ids 1,2 --baud 1000000 --return-delay 0 --lcm-url "$URL" \
	--control "$T/ctl"
wait_log sim 'ready' 10 || { tap_fail "XC430-W150 simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
tap_ok "undulate-sim --model xc430-w150 starts"

run ping ping 1
if grep -qE 'model 1070 \(XC430-W150\), firmware [0-9]+, Protocol 2\.0' "$T/ping.out"; then
	tap_ok "dxl ping: model 1070 (XC430-W150)"; else tap_fail "dxl ping names the XC430-W150" "rc $rc: $(cat "$T/ping.out" "$T/ping.err")"; fi

# its own page's factory values, not the XL430's (265, 140, 640)
run vl read 1 velocity_limit; run mv read 1 max_voltage_limit; run pp read 1 position_p_gain
if [ "$(cat "$T/vl.out")/$(cat "$T/mv.out")/$(cat "$T/pp.out")" = 460/160/460 ]; then
	tap_ok "its registers: velocity_limit 460, max_voltage_limit 160, position_p_gain 460 (its page's)"
else tap_fail "XC430-W150 factory values" "$(cat "$T/vl.out")/$(cat "$T/mv.out")/$(cat "$T/pp.out")"; fi
run cur read 1 present_current
if [ "$rc" != 0 ] && grep -qi "present_current" "$T/cur.err"; then
	tap_ok "no present_current on it (no current sensing): refused by name (exit $rc)"
else tap_fail "present_current refused on the XC430" "rc $rc: $(cat "$T/cur.out" "$T/cur.err")"; fi

run doc doctor 1 2 --cycles 20
if grep -qE '^OK +ID 1 model +1070 \(XC430-W150\)' "$T/doc.out" && grep -qE '^OK +ID 2 voltage .*\(servo.s limits 6\.0\.\.16\.0 V\)' "$T/doc.out"; then
	tap_ok "dxl doctor: model OK, voltage against its own limits"
else tap_fail "dxl doctor on the XC430" "$(grep -E 'model|voltage' "$T/doc.out")"; fi

# torque actuation's current drive needs current sensing
out=$(timeout 20 "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --set robot.actuation=torque \
	--set robot.torque_drive=current 2>&1); rc=$?
if [ "$rc" != 0 ] && echo "$out" | grep -q "servo 1 is an XC430-W150, which has no current control"; then
	tap_ok "torque_drive = current refused: the XC430-W150 has no current control (exit $rc)"
else tap_fail "current drive refused on the XC430" "rc $rc: $(echo "$out" | tail -3)"; fi

spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode oscillator
wait_log d "ready: $R.STATE" 15 || { tap_fail "undulated starts on the XC430 bus" "$(cat "$T/d.log")"; tap_done; exit 1; }
if grep -q "Protocol 2.0 (XC430-W150), mode OSCILLATOR" "$T/d.log" &&
	grep -q "position actuation's default k 0.0234, mu 0.2838 are the XC430-W150's" "$T/d.log" &&
	grep -q "servo_lead_s 0.117 s, the XC430-W150's default" "$T/d.log"; then
	tap_ok "undulated: the model named, its own tuned defaults (k 0.0234, mu 0.2838, lead 0.117 s)"
else tap_fail "undulated names the model and its defaults" "$(grep -E 'XC430|default' "$T/d.log" | head -4)"; fi
# the paper's gait, 0.8 rad, through its tuned defaults: with the XL430's the
# simulated XC430 (its motor 1.7x faster) swung to the +-1.3 rad limits
wait_for 20 cycle_at_least 1000 || true
range=$(states | tail -300 | field a0 | sort -g | sed -n '1p;$p' | tr '\n' ' ')
lo=${range%% *}; hi=$(echo "$range" | awk '{ print $2 }')
if [ -n "$hi" ] && awk -v a="$lo" -v b="$hi" 'BEGIN { exit !(b - a > 1.0 && b - a < 2.1 && a > -1.2 && b < 1.2) }'; then
	tap_ok "the oscillator swings the XC430 joints near the paper's gait: a0 $lo .. $hi rad over 3 s"
else tap_fail "the XC430 joints swing near 0.8 rad" "a0 $lo .. $hi"; fi
stop d
if [ "$stop_rc" = 0 ]; then tap_ok "safe stop (exit 0)"; else tap_fail "safe stop" "exit $stop_rc: $(tail -3 "$T/d.log")"; fi
tap_done
