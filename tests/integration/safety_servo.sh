#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# What a servo and a race may do to a robot, tried on the simulated bus (the
# reproductions of an audit, each of which succeeded once):
#  - HOLD followed within milliseconds by LIMP, 40 times: every servo ends
#    with torque off, as the robot reports;
#  - a servo loses power for 2 s and comes back with torque off and factory
#    RAM: found by the read-back, reported, set up again (torque on,
#    compliance margin back), and the robot's report matches the servo;
#  - a joint that stops answering: the fault action latches within
#    silent_s, the other joint does not go on against a frozen reading, and
#    only 'clear' (once it answers again) lets the robot move again;
#  - an overheating servo shut down by its alarm (torque off, torque limit 0)
#    until the fault latches; once it cooled, 'clear' and OSCILLATOR bring
#    back its torque limit and torque.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then tap_skip_all "undulate-sim or undulated not built"; exit 0; fi
URL=$(lcm_url 7711)
R="ss$$"
torque() { local a b; a=$(ctl peek r1 1 torque_enable); b=$(ctl peek r1 2 torque_enable); echo "${a#ok } ${b#ok }"; }

spawn sim "$S" --link "$T/bus" --ids 1,2 --name r1 --lcm-url "$URL" --control "$T/ctl" --seed 6 --return-delay 0
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode limp \
	--set robot.fault_action=hold --set robot.fault_backoff_s=0.2 --set robot.fault_retries=1
wait_log d "ready: $R.STATE" 10 && wait_for 10 cycle_at_least 50 ||
	{ tap_fail "daemon starts" "$(cat "$T/d.log")"; tap_done; exit 1; }

# ---- the torque-off race ------------------------------------------------------------------------
torque_race 40
s=$(last_state); t=$(torque)
if [ "$t" = "0 0" ] && [ "$(echo "$s" | field tq0)$(echo "$s" | field tr0)$(echo "$s" | field tr1)" = "000" ]; then
	tap_ok "LIMP: torque off on the servos, reported and read back"; else tap_fail "LIMP read back" "servos '$t'; $(echo "$s" | cut -c1-200)"; fi

# ---- a servo loses power: found, reported, set up again -------------------------------------------
# silent_s 5: long enough that a 2 s outage does not latch, so the reset itself is seen
stop d >/dev/null
mark_states
spawn d2 "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode oscillator \
	--set robot.fault_action=hold --set robot.silent_s=5
wait_log d2 "ready: $R.STATE" 10 && wait_restarted 300 || { tap_fail "daemon restarts" "$(cat "$T/d2.log")"; tap_done; exit 1; }
ctl power r1 2 off >/dev/null
wait_cycles 200
ctl power r1 2 on >/dev/null
if event 'kind=servo-reset text="servo 2 found with torque off while OSCILLATOR wanted it on' 5; then
	tap_ok "power loss found by the read-back and reported"; else tap_fail "servo reset reported" "$(events | tail -3)"; fi
if wait_for 3 sh -c "[ \"\$(echo 'peek r1 2 torque_enable' | socat -t 2 - UNIX-CONNECT:'$T/ctl')\" = 'ok 1' ]" &&
	[ "$(ctl peek r1 2 cw_compliance_margin)" = "ok 0" ] && state_is ' tq1=1 tr1=1 ' 3; then
	tap_ok "the servo set up again: torque on and compliance margin 0 on the servo, read back in the state"
else tap_fail "servo set up again" "torque $(ctl peek r1 2 torque_enable), margin $(ctl peek r1 2 cw_compliance_margin); $(last_state | cut -c1-200)"; fi
wait_cycles 300
lo=$(states | tail -150 | awk '{ for (i = 1; i <= NF; i++) if ($i ~ /^a1=/) { v = substr($i, 4) + 0; if (!n++ || v < lo) lo = v; if (v > hi || n == 1) hi = v } } END { printf "%.3f", hi - lo }')
if state_is ' mode=3 ' 1 && awk -v s="$lo" 'BEGIN { exit !(s > 0.5) }'; then
	tap_ok "OSCILLATOR goes on: joint 2 swings $lo rad peak to peak again"; else tap_fail "oscillating again" "swing $lo; $(last_state | cut -c1-160)"; fi

# ---- a joint falls silent: the fault action latches --------------------------------------------
stop d2 >/dev/null
mark_states
spawn d3 "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode oscillator --set robot.fault_action=hold
wait_log d3 "ready: $R.STATE" 10 && wait_restarted 300 || { tap_fail "daemon restarts" "$(cat "$T/d3.log")"; tap_done; exit 1; }
ctl fault r1 2 no-reply >/dev/null
if event 'kind=fault-latched text="servo 2 silent for 0.50 s: robot HOLD until .clear.' 3 &&
	state_is ' mode=1 reason="fault: servo 2 silent for 0.50 s" fault="servo 2 silent for 0.50 s" ' 2; then
	tap_ok "a silent joint latches the fault action (HOLD) after silent_s"; else tap_fail "silent joint latches" "$(events | tail -3)"; fi
wait_cycles 100
g=$(states | tail -50 | awk '{ for (i = 1; i <= NF; i++) if ($i ~ /^g0=/) { v = substr($i, 4) + 0; if (!n++) { lo = v; hi = v } if (v < lo) lo = v; if (v > hi) hi = v } } END { printf "%.4f", hi - lo }')
if awk -v g="$g" 'BEGIN { exit !(g < 0.001) }'; then tap_ok "the other joint holds (its goal moved $g rad in 0.5 s)"
else tap_fail "the other joint holds" "goal 0 moved $g rad"; fi
out=$(cmd 'mode oscillator' 2>&1)
if echo "$out" | grep -q "command-rejected: fault latched (servo 2 silent for 0.50 s): only LIMP or HOLD until 'clear'"; then
	tap_ok "OSCILLATOR refused while latched"; else tap_fail "OSCILLATOR refused while latched" "$out"; fi
out=$(cmd clear 2>&1)
if echo "$out" | grep -q "command-rejected: servo 2 is still silent"; then tap_ok "'clear' refused while the joint is still silent"
else tap_fail "clear refused while silent" "$out"; fi
ctl clear r1 2 >/dev/null
wait_cycles 20
out=$( { cmd clear && cmd 'mode oscillator'; } 2>&1); rc=$?
# the oscillator grows its swing from the hold: poll for it (at load 15 it was
# still at 0.44 rad after 300 cycles), up to 1500 cycles
swing1() { states | tail -150 | awk '{ for (i = 1; i <= NF; i++) if ($i ~ /^a1=/) { v = substr($i, 4) + 0; if (!n++) { lo = v; hi = v } if (v < lo) lo = v; if (v > hi) hi = v } } END { printf "%.3f", hi - lo }'; }
for _ in 1 2 3 4 5; do
	wait_cycles 300
	sw=$(swing1)
	awk -v s="$sw" 'BEGIN { exit !(s > 0.5) }' && break
done
if [ $rc = 0 ] && state_is ' mode=3 .* fault="" ' 1 && awk -v s="$sw" 'BEGIN { exit !(s > 0.5) }'; then
	tap_ok "answering again: 'clear' and OSCILLATOR accepted, joint 2 swings $sw rad"
else tap_fail "clear after the joint answers" "rc $rc $out; swing $sw"; fi

# ---- an overheat shutdown, then recovery through 'clear' --------------------------------------------
ctl fault r1 1 temperature 85 >/dev/null   # above the 70 degree limit: the servo's alarm shuts it down
if event 'kind=fault-latched text="servo 1 overheating persists' 10 && state_is ' mode=1 ' 2; then
	tap_ok "overheating: alarm shutdown, recovery attempts, then the fault latches (HOLD)"
else tap_fail "overheat latches" "$(events | tail -4)"; fi
tl=$(ctl peek r1 1 torque_limit)
ctl clear r1 1 >/dev/null   # cooled down
wait_cycles 50
out=$( { cmd clear && cmd 'mode oscillator'; } 2>&1); rc=$?
if [ $rc = 0 ] && wait_for 2 sh -c "[ \"\$(echo 'peek r1 1 torque_limit' | socat -t 2 - UNIX-CONNECT:'$T/ctl')\" = 'ok 1023' ]" &&
	[ "$(ctl peek r1 1 torque_enable)" = "ok 1" ]; then
	tap_ok "cooled: 'clear' and OSCILLATOR bring back torque limit 1023 and torque (was '$tl')"
else tap_fail "torque back after the shutdown" "rc $rc $out; torque limit $(ctl peek r1 1 torque_limit), torque $(ctl peek r1 1 torque_enable)"; fi
wait_cycles 300
sw=$(states | tail -150 | awk '{ for (i = 1; i <= NF; i++) if ($i ~ /^a0=/) { v = substr($i, 4) + 0; if (!n++) { lo = v; hi = v } if (v < lo) lo = v; if (v > hi) hi = v } } END { printf "%.3f", hi - lo }')
if awk -v s="$sw" 'BEGIN { exit !(s > 0.5) }'; then tap_ok "joint 1 swings again ($sw rad)"; else tap_fail "joint 1 swings again" "$sw rad"; fi
stop d3 >/dev/null
[ "$stop_rc" = 0 ] && tap_ok "clean stop" || tap_fail "clean stop" "exit $stop_rc"
tap_done
