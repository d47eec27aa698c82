#!/usr/bin/env bash
# undulated against undulate-sim: the bus disappearing (the simulator's
# disconnect, then the simulator killed and restarted) is survived — the loop
# keeps its period, joints hold, the daemon reconnects with back-off, re-runs
# its start-up checks and resumes from the present angles without a jump; a
# bus gone for longer than silent_s latches the fault action (HOLD) until
# 'clear' — and SIGTERM with safe_stop = limp leaves the servos with torque off.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
# a robot name of its own: a concurrent run of this test on the same
# multicast port (another build directory) cannot answer for it
R="u$$"
URL=$(lcm_url 7702)
count() { grep -c "^EVENT $R .*kind=$1 " "$T/watch.log"; }

start_sim() {
	spawn "$1" "$S" --link "$T/bus" --ids 1,2 --name r1 --lcm-url "$URL" --control "$T/ctl" --seed 7
	wait_log "$1" 'ready' 10
}
start_sim sim || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
# silent_s 2: the short outage below resumes by itself, the long one latches;
# compliance slope 16 (factory 32): written at start-up like the margin
spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode sinusoid --set robot.safe_stop=limp \
	--set robot.silent_s=2 --set robot.compliance_slope=16
wait_log d "ready: $R.STATE" 10 || { tap_fail "daemon starts" "$(cat "$T/d.log")"; tap_done; exit 1; }
wait_for 10 cycle_at_least 250
# start-up writes compliance margin 0 (the factory value is 1: a dead band in
# which a joint resting near neutral would stay)
margins() { echo "$(ctl peek r1 1 cw_compliance_margin) $(ctl peek r1 2 ccw_compliance_margin)"; }
m=$(margins)
if [ "$m" = "ok 0 ok 0" ]; then tap_ok "start-up set compliance margin 0"; else tap_fail "compliance margin at start-up" "$m"; fi
slopes() { echo "$(ctl peek r1 1 cw_compliance_slope) $(ctl peek r1 2 ccw_compliance_slope)"; }
m=$(slopes)
if [ "$m" = "ok 16 ok 16" ]; then tap_ok "start-up set compliance slope 16"; else tap_fail "compliance slope at start-up" "$m"; fi
# a slope changed behind the daemon's back is read back and written again
ctl poke r1 2 ccw_compliance_slope 64 >/dev/null
slopes_are() { [ "$(slopes)" = "$1" ]; }
if wait_for 3 slopes_are "ok 16 ok 16" &&
	wait_for 3 grep -q "^EVENT $R .*compliance slope read back 64, expected 16" "$T/watch.log"; then
	tap_ok "a compliance slope changed on the servo is reported and written again"
else tap_fail "compliance slope written again" "$(slopes); $(grep "^EVENT $R .*readback" "$T/watch.log" | tail -2)"; fi

# ---- the simulator drops the bus (like an unplugged adapter) and brings it back
ctl disconnect r1 >/dev/null
if wait_for 3 grep -q "^EVENT $R .*kind=bus-lost " "$T/watch.log"; then tap_ok "bus loss reported"; else
	tap_fail "bus-lost event" "$(tail -3 "$T/d.log")"; fi
c0=$(last_state | field cycle)
wait_for 5 cycle_at_least $((c0 + 50))
s=$(last_state)
if [ "$(echo "$s" | field st0)" -ge 40 ] && alive d; then
	tap_ok "loop keeps running without the bus (joints stale $(echo "$s" | field st0) cycles)"
else tap_fail "loop runs without the bus" "$(echo "$s" | cut -c1-300)"; fi
ctl reconnect r1 >/dev/null
if wait_for 5 grep -q "^EVENT $R .*kind=bus-back " "$T/watch.log"; then tap_ok "reconnected after the bus came back"
else tap_fail "bus-back event" "$(tail -5 "$T/d.log")"; fi

# resumed without a jump: the first goals after the reconnect start at the
# measured angles (the ramp), then the gait continues
resume_check() { # NAME
	local c1 line
	c1=$(last_state | field cycle)
	wait_for 5 cycle_at_least $((c1 + 30)) || true
	line=$(states | awk -v c="$c1" '{ for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
		if (v["cycle"] >= c && v["st0"] == 0 && v["st1"] == 0) {
			d0 = v["g0"] - v["a0"]; d1 = v["g1"] - v["a1"]; if (d0 < 0) d0 = -d0; if (d1 < 0) d1 = -d1
			print d0, d1; exit } }')
	if [ -n "$line" ] && awk -v l="$line" 'BEGIN { split(l, d, " "); exit !(d[1] < 0.03 && d[2] < 0.03) }'; then
		tap_ok "$1: first goal after resuming = measured angle (|goal - angle| $line rad)"
	else tap_fail "$1: resume without a jump" "|goal - angle| '$line'"; fi
}
resume_check "after reconnect"
if [ "$(grep "^BUS $R " "$T/watch.log" | tail -1 | field reconnects)" -ge 1 ] ||
	wait_for 2 sh -c "grep '^BUS $R ' '$T/watch.log' | tail -1 | grep -q ' reconnects=1 '"; then
	tap_ok "reconnects counted in bus_stats_t"; else tap_fail "reconnects counted" "$(grep '^BUS' "$T/watch.log" | tail -1)"; fi

# ---- the simulator exits (EIO on the pty) and is started again
stop sim TERM >/dev/null
if wait_for 3 sh -c "[ \$(grep -c '^EVENT $R .*kind=bus-lost ' '$T/watch.log') -ge 2 ]"; then
	tap_ok "simulator exit seen as a bus loss"; else tap_fail "bus loss on sim exit" "$(tail -3 "$T/d.log")"; fi
c0=$(last_state | field cycle)
wait_for 8 cycle_at_least $((c0 + 250))   # 2.5 s without a simulator: back-off grows, silent_s passes
n_fail=$(grep -c 'reconnect failed' "$T/d.log")
if alive d; then tap_ok "daemon alive while the simulator is gone ($n_fail failed reconnects logged)"; else
	tap_fail "daemon alive" "$(tail -5 "$T/d.log")"; fi
start_sim sim2 || tap_fail "simulator restarted" "$(cat "$T/sim2.log")"
if wait_for 5 sh -c "[ \$(grep -c '^EVENT $R .*kind=bus-back ' '$T/watch.log') -ge 2 ]"; then
	tap_ok "reconnected to the restarted simulator (start-up checks passed)"; else
	tap_fail "reconnect after restart" "$(tail -5 "$T/d.log")"; fi
resume_check "after simulator restart"
m=$(margins)
if [ "$m" = "ok 0 ok 0" ]; then tap_ok "compliance margin written again on the restarted (factory-fresh) servos"
else tap_fail "compliance margin after restart" "$m"; fi
m=$(slopes)
if [ "$m" = "ok 16 ok 16" ]; then tap_ok "compliance slope written again on the restarted servos"
else tap_fail "compliance slope after restart" "$m"; fi
c0=$(last_state | field cycle)
wait_for 5 cycle_at_least $((c0 + 100))
s=$(last_state)
if echo "$s" | grep -q ' mode=1 reason="fault: servo [12] silent for 2.00 s" fault="servo [12] silent for 2.00 s" ' &&
	[ "$(echo "$s" | field tq0)" = 1 ] && [ "$(echo "$s" | field tr0)" = 1 ]; then
	tap_ok "a bus gone longer than silent_s: fault latched, robot holds (torque on, read back)"
else tap_fail "latched after the long outage" "$(echo "$s" | cut -c1-300)"; fi
out=$("$D" --command 'mode sinusoid' --robot "$R" --lcm-url "$URL" --timeout 2); rc=$?
if [ $rc -eq 1 ] && echo "$out" | grep -q "fault latched (servo [12] silent for 2.00 s): only LIMP or HOLD until 'clear'"; then
	tap_ok "SINUSOID refused while the fault is latched"; else tap_fail "SINUSOID refused while latched" "rc $rc: $out"; fi
"$D" --command clear --robot "$R" --lcm-url "$URL" --timeout 2 >"$T/clear.out" 2>&1; rc1=$?
"$D" --command 'mode sinusoid' --robot "$R" --lcm-url "$URL" --timeout 2 >>"$T/clear.out" 2>&1; rc2=$?
c0=$(last_state | field cycle)
wait_for 5 cycle_at_least $((c0 + 100))
s=$(last_state)
if [ $rc1 -eq 0 ] && [ $rc2 -eq 0 ] && [ "$(echo "$s" | field tq0)" = 1 ] && [ "$(echo "$s" | field st0)" = 0 ] &&
	echo "$s" | grep -q ' mode=2 .* fault="" '; then
	tap_ok "cleared, then running again in SINUSOID with torque on"
else tap_fail "running again after clear" "rc $rc1 $rc2 $(cat "$T/clear.out"); $(echo "$s" | cut -c1-300)"; fi
p=$(states | awk '{ for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] } if (v["period"] > m) m = v["period"] } END { print m }')
echo "# longest period over the whole run: $p us (blocking start-up checks at reconnect)"

# ---- SIGTERM with safe_stop = limp: torque off
stop d TERM >"$T/stop.rc"; rc=$(cat "$T/stop.rc")
[ "$rc" = 0 ] && tap_ok "SIGTERM: exit 0" || tap_fail "SIGTERM exit" "$rc"
t1=$(ctl peek r1 1 torque_enable); t2=$(ctl peek r1 2 torque_enable)
if [ "$t1" = "ok 0" ] && [ "$t2" = "ok 0" ]; then tap_ok "after SIGTERM (limp): torque off on both servos"
else tap_fail "limp after SIGTERM" "servo 1 $t1, servo 2 $t2"; fi
tap_done
