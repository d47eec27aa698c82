#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# undulated on X-series servos (Protocol 2.0) against undulate-sim --model:
#  - the protocol: --protocol 1 on an X bus finds nobody and says so; auto
#    (the default) finds Protocol 2.0 by PING and names the model;
#  - start-up: position control, the configured position limits on the
#    servos, the bus watchdog, torque on; HOLD, then OSCILLATOR swings;
#  - bad input on the 2.0 bus while it runs (damaged CRCs, replies from the
#    wrong ID, garbage before replies, a servo missing from SYNC_READs):
#    named in the log, counted, the robot runs on in OSCILLATOR;
#  - an Operating Mode changed behind the daemon's back is put back;
#  - torque actuation: an XM430 in current control (the paper's rig), an
#    XL430 in PWM control, each back in position control on HOLD and at
#    the safe stop; current control asked of an XL430 is refused;
#  - the cycle's read: the XM430s run firmware 44 (no Fast Sync Read: the
#    plain SYNC_READ, said at start), the XL430 46 (Fast Sync Read, said;
#    its servo silent for a while: back to SYNC_READ, said, still read;
#    answering again: the fast read taken up again within 10 s, said).
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then tap_skip_all "undulate-sim or undulated not built"; fi
URL=$(lcm_url 7730)
R="dx$$"

cat >"$T/x.scenario" <<EOF
[sim]
seed = 8
baud = 1000000
return_delay_us = 0
[robot r1]
link = $T/xm
ids = 1,2
model = xm430-w350
firmware = 44
contact = none
[robot r2]
link = $T/xl
ids = 1
model = xl430-w250
contact = none
EOF
spawn sim "$S" --scenario "$T/x.scenario" --lcm-url "$URL" --control "$T/ctl"
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"

# ---- the protocol -------------------------------------------------------------------------------
out=$(timeout 20 "$D" --port "$T/xm" --ids 1,2 --robot "$R" --lcm-url "$URL" --protocol 1 2>&1); rc=$?
if [ $rc = 1 ] && echo "$out" | grep -q "servo IDs 1, 2 did not answer a PING on $T/xm at 1000000 bps"; then
	tap_ok "--protocol 1 on an X bus: nobody answers, said so, exit 1"
else tap_fail "--protocol 1 on an X bus" "rc $rc: $out"; fi
spawn d "$D" --port "$T/xm" --ids 1,2 --robot "$R" --lcm-url "$URL" --set robot.fault_action=hold
wait_log d "ready: $R.STATE" 15 && wait_for 10 cycle_at_least 50 ||
	{ tap_fail "daemon starts on the X bus" "$(cat "$T/d.log")"; tap_done; exit 1; }
# (whichever servo answers first names it: servo 2 when servo 1's first reply came late)
if grep -qE "protocol: servo [12] answered a Protocol 2.0 PING on $T/xm at 1000000 bps: Protocol 2.0 \(X series\)" "$T/d.log" &&
	grep -q "Protocol 2.0 (XM430-W350), mode HOLD" "$T/d.log"; then
	tap_ok "protocol auto: Protocol 2.0 found by PING, the model named"
else tap_fail "protocol auto" "$(head -5 "$T/d.log")"; fi
if grep -q "bus: the cycle reads by SYNC_READ, a status packet per servo: no Fast Sync Read, as servo 1 (XM430-W350, firmware 44) does not answer it" "$T/d.log"; then
	tap_ok "servos on firmware 44: the cycle reads by SYNC_READ, and the log says why"
else tap_fail "firmware 44: SYNC_READ said" "$(grep -a 'bus:' "$T/d.log" | head -3)"; fi

# ---- start-up: what the servos hold -------------------------------------------------------------------
got="$(sim_peek r1 1 operating_mode) $(sim_peek r1 2 operating_mode) $(sim_peek r1 1 min_position_limit) $(sim_peek r1 1 max_position_limit)"
got="$got $(sim_peek r1 2 bus_watchdog) $(sim_peek r1 1 torque_enable) $(sim_peek r1 2 torque_enable)"
if [ "$got" = "3 3 1201 2895 5 1 1" ] && state_is ' tq0=1 tr0=1 tl0=885 .* tq1=1 tr1=1 tl1=885 ' 3; then
	tap_ok "start-up: position control, limits 1201..2895 (±1.3 rad), watchdog 100 ms, torque on, read back"
else tap_fail "start-up" "servos: $got; $(last_state | cut -c1-300)"; fi

# ---- OSCILLATOR ----------------------------------------------------------------------------------------
# position actuation's defaults are the XM430's own (the AX-12A's run down on it)
if grep -q "joint 1: position actuation's default k 0.0304, mu 0.0757 are the XM430-W350's" "$T/d.log" &&
	grep -q "joint 2: position actuation's default k 0.0304, mu 0.0571 are the XM430-W350's" "$T/d.log" &&
	grep -q "servo_lead_s 0.047 s, the XM430-W350's default" "$T/d.log"; then
	tap_ok "position actuation's defaults: the XM430-W350's k, mu and servo_lead_s, logged"
else tap_fail "the XM430's defaults" "$(grep -a "default" "$T/d.log" | head -4)"; fi
cmd 'mode oscillator' >/dev/null
wait_cycles 600
s0=$(swing 0 300); s1=$(swing 1 300)
# on those defaults the law keeps the joints going: the starter never has to
# restart them (a 'stall' event), as it did every few seconds on the AX-12A's
stalls=$(events | grep -c 'kind=stall')
if over "$s0" 0.5 && over "$s1" 0.5 && [ "$stalls" = 0 ]; then
	tap_ok "OSCILLATOR swings both joints on the defaults ($s0, $s1 rad peak to peak), no stall"
else tap_fail "OSCILLATOR swings" "$s0 / $s1 rad, $stalls stall event(s): $(events | grep 'kind=stall' | head -2)"; fi

# ---- bad input on the 2.0 bus --------------------------------------------------------------------------
e0=$(last_state | field bus_errors)
ctl fault r1 2 bad-checksum prob=0.1 >/dev/null
ctl fault r1 1 wrong-id prob=0.05 >/dev/null
wait_cycles 150
ctl clear r1 1 >/dev/null; ctl clear r1 2 >/dev/null
ctl fault r1 1 garbage 12 prob=0.1 >/dev/null
ctl fault r1 2 no-reply count=5 >/dev/null
wait_cycles 150
ctl clear r1 1 >/dev/null
wait_cycles 100
e1=$(last_state | field bus_errors)
# the counters as the daemon publishes them (BUS, once a second) prove each kind
# was told apart; the log names them within its rate limit (5, then one per
# 2 s): which kind comes first is chance, so any of them is enough there (a
# run beside another test logged only timeouts in its window). Per servo
# replies/timeouts and checksum/wrong ID/wrong length
wait_for 10 sh -c "grep -a '^BUS $R ' '$T/watch.log' | tail -1 | grep -q ' bad1=[1-9]'"
b=$(grep -a "^BUS $R " "$T/watch.log" | tail -1)
cks=$(echo "$b" | sed -n 's/.* bad1=\([0-9]*\)\/.*/\1/p'); wid=$(echo "$b" | sed -n 's/.* bad0=[0-9]*\/\([0-9]*\)\/.*/\1/p')
tmo=$(echo "$b" | sed -n 's/.* id1=2\/[0-9]*\/\([0-9]*\)\/.*/\1/p')
if [ "${cks:-0}" -gt 0 ] && [ "${wid:-0}" -gt 0 ] && [ "${tmo:-0}" -ge 5 ] && [ "${e1:-0}" -gt "${e0:-0}" ] &&
	grep -qE 'servo [12]: SYNC_READ: (bad checksum|wrong ID|no reply)' "$T/d.log" && state_is ' mode=3 .* fault="" ' 1; then
	tap_ok "bad CRCs, wrong IDs, garbage, a servo missing from SYNC_READs: named in the log, counted ($cks bad CRCs and $tmo timeouts of servo 2, $wid wrong IDs for servo 1; $e0 -> $e1 bus errors), OSCILLATOR runs on"
else tap_fail "bad input on the 2.0 bus" "crc $cks wrong-id $wid timeouts $tmo; errors $e0 -> $e1; $b; $(last_state | cut -c1-200)"; fi
echo "# period while it lasted: $(echo "$b" | sed 's/.*\(p50=[0-9]* p99=[0-9]* max=[0-9]*\).*/\1/') us, overruns $(last_state | field overruns)"
s1=$(swing 1 300)
if over "$s1" 0.5; then tap_ok "joint 2 still swings after it ($s1 rad)"; else tap_fail "swinging after bad input" "$s1"; fi

# ---- an Operating Mode changed behind the daemon's back --------------------------------------------------
ctl poke r1 1 torque_enable 0 >/dev/null
ctl poke r1 1 operating_mode 1 >/dev/null
if event 'kind=readback text="servo 1: operating mode changed' 5 &&
	wait_for 10 sh -c "[ \"\$(echo 'peek r1 1 operating_mode' | socat -t 2 - UNIX-CONNECT:'$T/ctl')\" = 'ok 3' ]" &&
	wait_for 10 sh -c "[ \"\$(echo 'peek r1 1 torque_enable' | socat -t 2 - UNIX-CONNECT:'$T/ctl')\" = 'ok 1' ]"; then
	tap_ok "operating mode changed behind its back: found in the read-back, position control and torque again"
else tap_fail "operating mode put back" "$(events | tail -3); mode $(sim_peek r1 1 operating_mode)"; fi
stop d >/dev/null

# ---- torque actuation on the XM430: current control ----------------------------------------------------
ctl poke r1 1 goal_position 2300 >/dev/null   # resting away from neutral: the law starts it
mark_states
spawn dt "$D" --port "$T/xm" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode oscillator \
	--set robot.actuation=torque --set robot.torque_drive=current
wait_log dt "ready: $R.STATE" 15 && wait_restarted 100 || { tap_fail "torque daemon starts" "$(cat "$T/dt.log")"; tap_done; exit 1; }
wait_cycles 500
gc=$(sim_peek r1 1 goal_current)
if [ "$(sim_peek r1 1 operating_mode)" = 0 ] && [ "$(sim_peek r1 2 operating_mode)" = 0 ] && [ "${gc#-}" -le 1193 ] &&
	state_is ' g0=nan .* dr0=[-0-9]' 1 && over "$(swing 0 300)" 0.5; then
	tap_ok "torque actuation on the XM430: current control, the law's current ($gc now), joint 1 swings $(swing 0 300) rad"
else tap_fail "current control" "modes $(sim_peek r1 1 operating_mode)/$(sim_peek r1 2 operating_mode), current $gc, swing $(swing 0 300); $(last_state | cut -c1-200)"; fi
cmd 'mode hold' >/dev/null
# The daemon writes each joint's mode in turn (torque off, mode, torque on, a
# chain per joint over cycles): wait for the last of them, not the first.
if wait_for 10 sh -c "for j in 1 2; do [ \"\$(echo \"peek r1 \$j operating_mode\" | socat -t 2 - UNIX-CONNECT:'$T/ctl')\" = 'ok 3' ] &&
		[ \"\$(echo \"peek r1 \$j torque_enable\" | socat -t 2 - UNIX-CONNECT:'$T/ctl')\" = 'ok 1' ] || exit 1; done"; then
	tap_ok "HOLD: back in position control, torque on"
else tap_fail "back to position control" "modes $(sim_peek r1 1 operating_mode)/$(sim_peek r1 2 operating_mode)"; fi
stop dt >/dev/null

# ---- the XL430: no current control; PWM control -----------------------------------------------------------
out=$(timeout 20 "$D" --port "$T/xl" --ids 1 --robot "$R" --lcm-url "$URL" --mode hold \
	--set robot.actuation=torque --set robot.torque_drive=current 2>&1); rc=$?
if [ $rc = 1 ] && echo "$out" | grep -q "servo 1 is an XL430-W250, which has no current control"; then
	tap_ok "current control asked of an XL430: refused at start, saying why"
else tap_fail "XL430 current refused" "rc $rc: $out"; fi
ctl poke r2 1 goal_position 2300 >/dev/null
mark_states
spawn dl "$D" --port "$T/xl" --ids 1 --robot "$R" --lcm-url "$URL" --mode oscillator \
	--set robot.actuation=torque --set robot.torque_drive=pwm
wait_log dl "ready: $R.STATE" 15 && wait_restarted 100 || { tap_fail "XL430 daemon starts" "$(cat "$T/dl.log")"; tap_done; exit 1; }
wait_cycles 400
if [ "$(sim_peek r2 1 operating_mode)" = 16 ] && over "$(swing 0 300)" 0.4; then
	tap_ok "torque actuation on the XL430: PWM control, joint swings $(swing 0 300) rad"
else tap_fail "PWM control" "mode $(sim_peek r2 1 operating_mode), swing $(swing 0 300)"; fi
stop dl >/dev/null
if [ "$stop_rc" = 0 ] && [ "$(sim_peek r2 1 operating_mode)" = 3 ] && [ "$(sim_peek r2 1 torque_enable)" = 1 ] &&
	[ "$(sim_peek r2 1 bus_watchdog)" = 0 ]; then
	tap_ok "safe stop after torque actuation: position control, holding, watchdog off"
else tap_fail "safe stop" "exit $stop_rc, mode $(sim_peek r2 1 operating_mode), torque $(sim_peek r2 1 torque_enable)"; fi

# ---- one XL430 joint in position control on its own defaults ------------------------------------------------
# The XL430's position loop lags most: on the AX-12A's defaults a single joint
# runs down to rest within seconds and the starter restarts it ('stall');
# on the XL430's own (k 0.0105, mu 0.036, servo_lead_s 0.117) it keeps the gait.
n0=$(events | grep -c 'kind=stall')
mark_states
spawn dp "$D" --port "$T/xl" --ids 1 --robot "$R" --lcm-url "$URL" --mode oscillator
wait_log dp "ready: $R.STATE" 15 && wait_restarted 100 || { tap_fail "XL430 position daemon starts" "$(cat "$T/dp.log")"; tap_done; exit 1; }
wait_cycles 800
sw=$(swing 0 300); n1=$(events | grep -c 'kind=stall')
if grep -q "joint 1: position actuation's default k 0.0105, mu 0.036 are the XL430-W250's" "$T/dp.log" &&
	[ "$n1" = "$n0" ] && over "$sw" 1.2; then
	tap_ok "one XL430 joint on its own defaults: swings $sw rad peak to peak, no stall in 8 s"
else tap_fail "XL430 on its defaults" "swing $sw rad, $((n1 - n0)) stall(s); $(grep -a default "$T/dp.log" | head -2)"; fi
if grep -q "bus: the cycle reads by Fast Sync Read, one status packet for all servos (servo 1 XL430-W250 firmware 46)" "$T/dp.log"; then
	tap_ok "firmware 46: the cycle reads by Fast Sync Read, said at start (the swing above ran on it)"
else tap_fail "Fast Sync Read said" "$(grep -a 'bus:' "$T/dp.log" | head -3)"; fi
ctl fault r2 1 no-reply count=5 >/dev/null
wait_cycles 100
# 5 cycles without a reading may stop the gait for a moment (the starter
# restarts it): swinging again is waited for, not assumed at once
swings_again() { over "$(swing 0 100)" 0.3; }
if wait_log dp "Fast Sync Read read nobody 3 cycles in a row \(30 ms\): reading by SYNC_READ" 5 && state_is ' mode=3 ' 1 &&
	wait_for 15 swings_again; then
	tap_ok "its servo silent 5 cycles: back to SYNC_READ after 3, said; the joint read and swinging again"
else tap_fail "fast read fallback" "$(grep -a 'Fast Sync Read' "$T/dp.log" | tail -3); swing $(swing 0 100)"; fi
# its servo answering again: the Fast Sync Read is tried again within 10 s and kept
if wait_log dp "Fast Sync Read read every servo again: reading by it from now on" 15; then
	tap_ok "the servo answering again: the Fast Sync Read taken up again within 10 s, said"
else tap_fail "fast read taken up again" "$(grep -a 'Fast Sync Read' "$T/dp.log" | tail -3)"; fi
stop dp >/dev/null

# ---- --tune on an X servo: from the model's defaults, and the file says so ----------------------------------
# (in lockstep: a simulated minute in a few seconds). The tuner starts from what
# the robot runs once the model is known; it once wrote the AX-12A's k and lead
# beside a gait measured on the XL430's defaults.
spawn lsim "$S" --lockstep "$T/ls.sock" --model xl430-w250 --baud 1000000 --link "$T/lbus" --ids 1 \
	--return-delay 0 --duration 300 --lcm-url "$URL"
wait_log lsim 'ready' 10 || { tap_fail "lockstep simulator ready" "$(cat "$T/lsim.log")"; tap_done; exit 1; }
timeout 120 "$D" --tune --lockstep "$T/ls.sock" --port "$T/lbus" --ids 1 --robot "$R" --lcm-url "$URL" \
	--out "$T/tuned.conf" >"$T/tune.log" 2>&1; rc=$?
stop lsim >/dev/null
done_line=$(grep -a '^tune: done' "$T/tune.log" | head -1)
kx=$(echo "$done_line" | sed -n 's/.* k x\([0-9.]*\),.*/\1/p')
fk=$(sed -n 's/^k = //p' "$T/tuned.conf" 2>/dev/null); fl=$(sed -n 's/^servo_lead_s = //p' "$T/tuned.conf" 2>/dev/null)
if [ "$rc" = 0 ] && [ -n "$kx" ] && [ -n "$fk" ] &&
	awk -v k="$fk" -v x="$kx" -v l="$fl" 'BEGIN { exit !(k > 0.0105 * x * 0.99 && k < 0.0105 * x * 1.01 && l >= 0.117) }'; then
	tap_ok "--tune on an XL430 (lockstep): from its defaults; the file's k $fk = 0.0105 x $kx, servo_lead_s $fl"
else tap_fail "--tune on an XL430" "rc $rc; ${done_line:-no result}; file k $fk lead $fl; $(tail -3 "$T/tune.log")"; fi
tap_done
