#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# safety_servo's reproductions on X-series servos (Protocol 2.0: undulate-sim
# --model xm430-w350 at 1 Mbps), and what only the X series has:
#  - HOLD followed within milliseconds by LIMP, 20 times: every servo ends
#    with torque off, as the robot reports;
#  - limits widened from the network are refused (the configuration's
#    position limits are the servo's: written at start-up, read back);
#  - a servo loses power and boots with torque off, RAM at its defaults
#    (the bus watchdog off): found by the read-back, set up again;
#  - an overload shuts a servo down (torque off, Hardware Error Status, the
#    alert in every status): found through the alert, backed off, one
#    REBOOT (fault_reboots = 1) and it is back;
#  - an overheating servo: the REBOOT does not help (the cause is still
#    there), the fault latches, torque is never turned on meanwhile; once it
#    cooled, 'clear' reboots it and OSCILLATOR goes on;
#  - the controller killed (SIGKILL): the bus watchdog stops the servos
#    within its time (bus_watchdog_ms 100; measured here), the next start
#    clears it; SIGTERM's safe stop clears every watchdog and holds.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then tap_skip_all "undulate-sim or undulated not built"; fi
URL=$(lcm_url 7731)
R="sx$$"
peek() { local v; v=$(ctl peek r1 "$1" "$2"); echo "${v#ok }"; }
torque() { echo "$(peek 1 torque_enable) $(peek 2 torque_enable)"; }

spawn sim "$S" --model xm430-w350 --link "$T/bus" --ids 1,2 --name r1 --baud 1000000 --return-delay 0 \
	--lcm-url "$URL" --control "$T/ctl" --seed 6
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
# the oscillator on the XM430's own defaults (daemon/CONTROL.md, "X-series servos"): with the
# AX-12A's it would run down between restarts there, and "it swings again" would mean little
# silent_s 5 (as safety_servo): the power loss below lasts two control-socket
# calls, and at load 10-12 on 2 cores those took more than the default 0.5 s:
# the joint's silence latched HOLD first, and every check after it failed
spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode limp --set robot.fault_action=hold \
	--set robot.fault_backoff_s=0.3 --set robot.silent_s=5
wait_log d "ready: $R.STATE" 15 && wait_for 10 cycle_at_least 50 ||
	{ tap_fail "daemon starts on the X bus" "$(cat "$T/d.log")"; tap_done; exit 1; }

# ---- the torque-off race ------------------------------------------------------------------------
torque_race 20

# ---- limits: the configuration's, on the servo too; none from the network -------------------------
out=$(cmd 'param limit_max 2.5 0' 2>&1)
if echo "$out" | grep -q "command-rejected" && [ "$(peek 1 max_position_limit)" = 2895 ] &&
	[ "$(peek 1 min_position_limit)" = 1201 ] && [ "$(peek 2 operating_mode)" = 3 ]; then
	tap_ok "limit_max from a command refused; the servos hold the configured limits 1201..2895 in position control"
else tap_fail "limits" "$out; limits $(peek 1 min_position_limit)..$(peek 1 max_position_limit) mode $(peek 2 operating_mode)"; fi

# ---- a power loss: set up again -----------------------------------------------------------------
cmd 'mode oscillator' >/dev/null
wait_cycles 200
ctl power r1 2 off >/dev/null
wait_cycles 20
ctl power r1 2 on >/dev/null
if event 'kind=servo-reset text="servo 2 found with torque off while OSCILLATOR wanted it on' 5 &&
	wait_for 10 sh -c "[ \"\$(echo 'peek r1 2 torque_enable' | socat -t 2 - UNIX-CONNECT:'$T/ctl')\" = 'ok 1' ]" &&
	[ "$(peek 2 bus_watchdog)" = 5 ]; then
	tap_ok "power loss found by the read-back, reported, set up again: torque on, bus watchdog 100 ms"
else tap_fail "power loss" "$(events | tail -3); torque $(peek 2 torque_enable) watchdog $(peek 2 bus_watchdog)"; fi

# ---- an overload shutdown: one REBOOT brings it back ---------------------------------------------
wait_cycles 100
ctl poke r1 2 hardware_error_status 32 >/dev/null   # overload: in Shutdown (52), torque off until REBOOT
if event 'kind=fault text="servo 2: overload \(shut down: torque off\): backing off' 3 &&
	event 'kind=reboot text="servo 2: overload shut it down: REBOOT 1 of 1' 3 &&
	event 'kind=recovered text="servo 2: recovered' 5 &&
	[ "$(peek 2 torque_enable)" = 1 ] && [ "$(peek 2 hardware_error_status)" = 0 ]; then
	tap_ok "overload shutdown: found through the alert, backed off, one REBOOT, set up again, torque on"
else tap_fail "shutdown recovered" "$(events | tail -4); torque $(peek 2 torque_enable)"; fi
wait_cycles 300
sw=$(swing 1 300)
if awk -v s="$sw" 'BEGIN { exit !(s > 0.5) }'; then tap_ok "OSCILLATOR goes on: joint 2 swings $sw rad again"
else tap_fail "swinging after the reboot" "$sw rad over the last 3 s"; fi

# ---- an overheating servo: the REBOOT does not help, the fault latches -------------------------------
ctl fault r1 1 temperature 90 >/dev/null   # above its 80 C limit, and it stays hot
on_while_hot=0
for _ in $(seq 40); do
	[ "$(peek 1 hardware_error_status)" != 0 ] && [ "$(peek 1 torque_enable)" = 1 ] && on_while_hot=$((on_while_hot + 1))
	sleep 0.05
done
if event 'kind=fault-latched text="servo 1 overheating persists: robot HOLD' 8 &&
	event 'kind=fault-persistent text="servo 1: overheating persists after 1 REBOOT\(s\) \(fault_reboots = 1\)' 1 && state_is ' mode=1 ' 2 && [ "$on_while_hot" = 0 ]; then
	tap_ok "overheating: one REBOOT, the cause still there, the fault latches (HOLD); torque never on while it stood"
else tap_fail "overheat latches" "$(events | tail -4); torque on while hot $on_while_hot"; fi
# published: Hardware Error Status with ERROR_BITS_X (256) so monitors name it by the
# X table; overheating is bit 2 (4), the alert bit 7 (128); joint 2 has none
if state_is ' e0=(260|388) .* e1=(256|384) ' 3; then
	tap_ok "STATE: joint 1's error bits the X servo's (overheating, ERROR_BITS_X), joint 2's none"
else tap_fail "X error bits published" "$(grep -a '^STATE' "$T/watch.log" | tail -1 | grep -oE ' e[01]=[0-9]+' | tr '\n' ' ')"; fi
# and a monitor names them by the X table: with the motor encoder's bit (3) set
# as well, the AX-12A's table would say "overheating|range"
ctl poke r1 1 hardware_error_status 12 >/dev/null
state_is ' e0=(268|396) ' 3
# a snapshot is one moment: on a busy machine a joint may read "SILENT x1" in
# it for a cycle, so up to five snapshots, the first that matches counts
for _ in 1 2 3 4 5; do
	top=$(timeout 15 "$B/undulate-top" --once --json --wait 1.5 --lcm-url "$URL" 2>/dev/null)
	st=$(echo "$top" | jq -r --arg r "$R" '.robots[] | select(.name == $r) | [.joints[].status] | join(",")' 2>/dev/null)
	[ "$st" = "overheating|motor encoder,ok" ] && break
done
if [ "$st" = "overheating|motor encoder,ok" ]; then tap_ok "undulate-top names them by the X table: joint 1 $st"
else tap_fail "undulate-top's joint status" "'$st'; $(grep -a '^STATE' "$T/watch.log" | tail -1 | grep -oE ' e[01]=[0-9]+' | tr '\n' ' ')"; fi
# and the browser view, in headless chromium: the robot's servo table as drawn
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ] || [ ! -x "$B/undulate-web" ]; then
	tap_skip "the browser view names them by the X table" "no chromium or undulate-web here (scripts/deps.sh chromium)"
else
	CDP="$(dirname "$0")/web_cdp.py"
	spawn web "$B/undulate-web" --listen 127.0.0.1:0 --lcm-url "$URL" --read-only
	wait_log web 'listening on http://' 10 || tap_fail "undulate-web listening" "$(tail -3 "$T/web.log")"
	wport=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/web.log")
	dport=$(python3 "$CDP" freeport)
	# its own TMPDIR: chromium leaves a singleton folder there even after SIGTERM
	spawn chromium env TMPDIR="$T" "$browser" --headless=new --no-sandbox --disable-gpu --no-first-run --user-data-dir="$T/chromium" \
		--remote-debugging-port="$dport" about:blank
	python3 "$CDP" servos "$dport" "http://127.0.0.1:$wport/" "$T/servos.png" "$R" "overheating|motor encoder" \
		"off (wanted on)" >"$T/servos.out" 2>&1
	sed 's/^/# /' "$T/servos.out"
	# servo 1: error bits 0xc (the byte the servo sent; 0x8c with the alert bit 7) named
	# overheating|motor encoder, its torque as read back: off, where HOLD wants it on
	# (the servo's protection holds it off); servo 2 ok, on.
	# Rows: ROW id °C V bits status torque, tab-separated.
	row1=$(awk -F'\t' '$1 == "ROW" && $2 == 1 { print $5 "; " $6 "; " $7 }' "$T/servos.out")
	row2=$(awk -F'\t' '$1 == "ROW" && $2 == 2 { print $5 "; " $6 "; " $7 }' "$T/servos.out")
	if [[ "$row1" =~ ^0x8?c\;\ overheating\|motor\ encoder\;\ off\ \(wanted\ on\)$ ]] && [ "$row2" = "0x0; ok; on" ]; then
		tap_ok "the browser view (undulate-web in headless chromium) names them by the X table, torque as read back: servo 1 $row1, servo 2 $row2"
	else
		tap_fail "the browser view names them by the X table" "$(tail -5 "$T/servos.out")"
		mkdir -p "$BUILD/test-logs" && cp "$T/servos.png" "$BUILD/test-logs/safety_x-servos.png" 2>/dev/null
	fi
	[ -n "${WEB_KEEP_SCREENSHOT:-}" ] && mkdir -p "$BUILD/test-logs" && cp "$T/servos.png" "$BUILD/test-logs/safety_x-servos.png"
	stop chromium >/dev/null
	stop web >/dev/null
fi
ctl clear r1 1 >/dev/null   # cooled down
wait_cycles 20
out=$( { cmd clear && cmd 'mode oscillator'; } 2>&1); rc=$?
if [ $rc = 0 ] && event 'kind=reboot text="servo 1: REBOOT \(.clear.\)' 3 &&
	wait_for 10 sh -c "[ \"\$(echo 'peek r1 1 torque_enable' | socat -t 2 - UNIX-CONNECT:'$T/ctl')\" = 'ok 1' ]"; then
	tap_ok "cooled: 'clear' reboots it, OSCILLATOR accepted, torque on"
else tap_fail "clear after cooling" "rc $rc $out; $(events | tail -3)"; fi

# ---- the controller killed: the bus watchdog stops the servos ------------------------------------------
wait_cycles 200
t0=$(date +%s%N)
stop d KILL >/dev/null
tripped=""
for _ in $(seq 100); do
	if [ "$(peek 1 bus_watchdog)" = 255 ] && [ "$(peek 2 bus_watchdog)" = 255 ]; then tripped=$(( ($(date +%s%N) - t0) / 1000000 )); break; fi
	sleep 0.01
done
a=$(ctl servo r1 1 | sed -n 's/.* angle=\([^ ]*\).*/\1/p'); sleep 0.3; b=$(ctl servo r1 1 | sed -n 's/.* angle=\([^ ]*\).*/\1/p')
if [ -n "$tripped" ] && awk -v a="$a" -v b="$b" 'BEGIN { d = a - b; exit !(d < 0.02 && d > -0.02) }'; then
	tap_ok "SIGKILL: both bus watchdogs stopped their servos ${tripped} ms after the kill (100 ms set); joint 1 then still ($a -> $b rad)"
else tap_fail "watchdog on a killed controller" "tripped '${tripped}' ms; joint 1 $a -> $b; $(ctl servo r1 1)"; fi
echo "# watchdog: stopped ${tripped} ms after SIGKILL (bus_watchdog_ms 100)"
mark_states
spawn d2 "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode hold
if wait_log d2 "ready: $R.STATE" 15 && grep -q 'servo 1: its bus watchdog had stopped it' "$T/d2.log" &&
	wait_restarted 50 && [ "$(peek 1 bus_watchdog)" = 5 ] && [ "$(peek 1 torque_enable)" = 1 ]; then
	tap_ok "the next start says the watchdog had stopped the servo, clears it and sets it again"
else tap_fail "restart after a watchdog stop" "$(grep -i watchdog "$T/d2.log"); watchdog $(peek 1 bus_watchdog)"; fi
stop d2 >/dev/null
if [ "$stop_rc" = 0 ] && [ "$(peek 1 bus_watchdog)" = 0 ] && [ "$(peek 2 bus_watchdog)" = 0 ] && [ "$(torque)" = "1 1" ]; then
	tap_ok "SIGTERM: safe stop holding, torque on, every bus watchdog off"
else tap_fail "safe stop" "exit $stop_rc; watchdog $(peek 1 bus_watchdog)/$(peek 2 bus_watchdog); torque $(torque)"; fi
tap_done
