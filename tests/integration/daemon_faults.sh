#!/usr/bin/env bash
# undulated against undulate-sim: a servo fault (overload injected by the
# simulator) is reported, the joint backs off and recovers per the manual;
# a fault that persists puts the robot in its configured fault state (LIMP
# here: torque off on the simulated servos) and says so.
. "$(dirname "$0")/../lib.sh"
rig_up 7701 5
# a moving speed left behind by another program: reset at start-up, with a warning
ctl poke r1 1 moving_speed 100 >/dev/null
# servo 2's first three replies 20 ms late (a busy machine, a slow adapter):
# start-up tries again after a quiet line, and the fourth try is answered
r=$(ctl fault r1 2 slow 20 count=3)
[ "${r%% *}" = ok ] || tap_fail "inject three late replies" "$r"
# backoff 1.5 s: the transient overload below must be cleared before three
# recovery attempts pass; at 0.5 s a loaded machine's checks in between took
# longer than that once, and the fault went persistent
spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode hold \
	--set robot.fault_backoff_s=1.5 --set robot.fault_retries=2 --set robot.fault_action=limp
wait_log d "ready: $R.STATE" 10 || { tap_fail "daemon starts" "$(cat "$T/d.log")"; tap_done; exit 1; }
wait_for 5 sh -c "grep -q '^STATE $R ' '$T/watch.log'"
if grep -q 'servo 2: PING: no reply (timeout); try 4 of 4 after 30 ms of quiet line (a late reply came' "$T/d.log"; then
	tap_ok "start-up rides out three late replies: quiet line, then a fourth try"
else tap_fail "start-up rides out three late replies" "$(grep -i 'servo 2' "$T/d.log")"; fi
if [ "$(ctl peek r1 1 moving_speed)" = "ok 0" ] && grep -q 'servo 1: moving speed was 100' "$T/d.log"; then
	tap_ok "start-up resets a slow moving speed and says so"; else tap_fail "moving speed reset" "$(ctl peek r1 1 moving_speed)"; fi

# ---- a transient overload on servo 2
r=$(ctl fault r1 2 stuck-error overload)
[ "${r%% *}" = ok ] || tap_fail "inject overload" "$r"
if event 'kind=fault text="servo 2: overload: backing off'; then tap_ok "overload reported as a fault event"
else tap_fail "fault event" "$(grep EVENT "$T/watch.log" | tail -3)"; fi
if wait_for 3 _state_has ' e1=32 '; then
	tap_ok "error bits published in robot_state_t (e1=32)"; else tap_fail "error bits published" "$(last_state | cut -c1-300)"; fi
# backing off: the joint holds where it is (the servo's alarm shutdown has
# zeroed its torque limit meanwhile, as on a real AX-12)
s=$(last_state); a=$(echo "$s" | field a1); g=$(echo "$s" | field g1)
if awk -v a="$a" -v g="$g" 'BEGIN { d = a - g; if (d < 0) d = -d; exit !(d < 0.02) }'; then
	tap_ok "joint backs off: holds at its present angle ($a)"; else tap_fail "joint holds" "angle $a goal $g"; fi
ctl clear r1 2 >/dev/null
if event 'kind=recovered text="servo 2: recovered' 5; then tap_ok "recovered after the fault cleared"
else tap_fail "recovered event" "$(grep EVENT "$T/watch.log" | tail -3)"; fi
tl=$(ctl peek r1 2 torque_limit); te=$(ctl peek r1 2 torque_enable)
if [ "$tl" = "ok 1023" ] && [ "$te" = "ok 1" ]; then tap_ok "recovery wrote torque limit 1023 and torque on"
else tap_fail "recovery writes" "torque_limit $tl, torque_enable $te"; fi
if last_state | grep -q ' mode=1 '; then tap_ok "robot stays in HOLD after a recovered fault"; else
	tap_fail "mode after recovery" "$(last_state | cut -c1-120)"; fi

# ---- a persistent overheating on servo 1: retries, then fault_action = limp
ctl fault r1 1 stuck-error overheating >/dev/null
if event 'kind=fault-persistent text="servo 1: overheating persists after 3 recovery attempts: robot LIMP' 15; then
	tap_ok "persistent fault reported after bounded retries"
else tap_fail "persistent fault" "$(grep EVENT "$T/watch.log" | tail -4)"; fi
if wait_for 3 _state_has ' mode=0 reason="fault: servo 1 overheating persists"'; then
	tap_ok "robot LIMP with the fault as its mode reason"; else tap_fail "robot LIMP" "$(last_state | cut -c1-160)"; fi
t1=$(ctl peek r1 1 torque_enable); t2=$(ctl peek r1 2 torque_enable)
if [ "$t1" = "ok 0" ] && [ "$t2" = "ok 0" ]; then tap_ok "torque off on both servos"; else
	tap_fail "torque off" "servo 1 $t1, servo 2 $t2"; fi
n=$(grep -c 'kind=fault text="servo 1' "$T/watch.log")
if [ "$n" -eq 3 ]; then tap_ok "3 fault events (first report + 2 retries)"; else tap_fail "fault events" "$n"; fi

# ---- the operator takes over: the cause cleared, then 'clear', then a mode command
ctl clear r1 >/dev/null
# latched: HOLD is refused until the operator clears the fault (fault_action is LIMP)
out=$("$D" --command "mode hold" --robot "$R" --lcm-url "$URL" --timeout 2); rc=$?
if [ $rc -eq 1 ] && echo "$out" | grep -q "fault latched (servo 1 overheating persists): only LIMP until 'clear'"; then
	tap_ok "HOLD refused while the fault is latched"; else tap_fail "HOLD refused while latched" "rc $rc $out"; fi
"$D" --command clear --robot "$R" --lcm-url "$URL" --timeout 2 >/dev/null
out=$("$D" --command "mode hold" --robot "$R" --lcm-url "$URL" --timeout 2); rc=$?
if [ $rc -eq 0 ] && wait_for 3 _state_has ' mode=1 .* tq0=1 .* tq1=1 '; then
	tap_ok "HOLD by command after the fault: torque back on"; else tap_fail "HOLD after fault" "rc $rc $out; $(last_state | cut -c1-200)"; fi
if alive d; then tap_ok "daemon alive throughout"; else tap_fail "daemon alive"; fi
tap_done
