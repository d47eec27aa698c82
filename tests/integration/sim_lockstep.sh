#!/usr/bin/env bash
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# sim_lockstep.sh — the same simulator and daemons in virtual time
# (undulate-sim --lockstep, undulated --lockstep, scripts/demo.sh --lockstep):
#  - a pair-rig run ends by itself after its simulated seconds, and the
#    anti-phase lock it reaches is the one the real-time run reaches
#    (e2e_pair); the speed is printed, not asserted (timing is not behaviour);
#  - the same seed gives the same run: the demo's summary and the analysis
#    byte for byte, the simulator's ground truth line too; another seed, another run;
#  - the schedule happens at simulated times: the switch of mode (a command the
#    simulator delivers), a servo that stops answering (the daemon's timeouts
#    and its silent-joint fault come at their simulated times, 0.5 s later);
#  - nothing hangs: a daemon killed, a daemon stopped (SIGSTOP), the
#    simulator killed, a daemon for a bus that is not there, no simulator at
#    the socket: each ends with a clear message and a non-zero exit, within
#    seconds of wall time.
. "$(dirname "$0")/../lib.sh"

scenario="$top/sim-bridge/scenarios/pair-rig.scenario"
rig=(--daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current --daemon-set sinusoid.amplitude=0.25)
num() { awk "BEGIN { exit !($*) }"; }

# demo NAME PORT ARGS...: a lockstep run of the pair rig through scripts/demo.sh,
# kept in $T/NAME; its output in $T/NAME.out. Returns demo.sh's status.
demo() {
	local name=$1 port=$2; shift 2
	env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep --scenario "$scenario" \
		--lcm-url "$(lcm_url "$port")" --out "$T/$name" "$@" >"$T/$name.out" 2>&1
}

# ---- the anti-phase pair, twice with one seed, once with another ---------------------
for name in anti anti2; do
	demo $name 7660 --seconds 40 --switch-at 3 --seed 7 --phases 0,3.1416 --set world.separation=0.7 "${rig[@]}"
	rc=$?
	[ "$rc" = 0 ] || { tap_fail "$name: the lockstep run ended by itself" "exit $rc: $(tail -n 20 "$T/$name.out")"; keep_runs anti anti2; tap_done; exit; }
done
speed=$(sed -n 's/^demo: lockstep: //p' "$T/anti.out")
simline=$(grep -m1 '^undulate-sim: lockstep: .* of simulated time' "$T/anti/logs/sim.log")
if [[ "$speed" =~ ^40\.0[0-9]*\ s\ of\ simulated\ time\ in\ [0-9.]+\ s ]] && [[ "$simline" == *"ended: the run's 40.000 s are over"* ]]; then
	tap_ok "a 40 s pair-rig run in virtual time ended by itself: $speed"
else
	tap_fail "a 40 s pair-rig run in virtual time ended by itself" "demo said '$speed'; simulator: $simline"
fi
for r in left right; do
	if grep -q 'lockstep: the simulator ended the run' "$T/anti/logs/undulated-$r.log" &&
		grep -q 'stop: joints' "$T/anti/logs/undulated-$r.log"; then
		tap_ok "$r: its daemon was told the run was over and made its safe stop"
	else
		tap_fail "$r: its daemon was told the run was over and made its safe stop" "$(tail -n 5 "$T/anti/logs/undulated-$r.log")"
	fi
done
state=$(summary_col "$T/anti" left:right state); D=$(summary_col "$T/anti" left:right meanD)
last=$(last_collisions "$T/anti")
if [ "$state" = anti-phase ] && num "${D#-} > 3.1416 - 0.5" && [ "$last" -gt 0 ]; then
	tap_ok "from D0 = pi at d~ 0.7 it locks in anti-phase as in real time (|D| ${D#-}, $last collisions in the last 10 s)"
else
	tap_fail "from D0 = pi at d~ 0.7 it locks in anti-phase as in real time" "state $state, D $D, last 10 s: $last collisions"
fi
if cmp -s "$T/anti/demo-summary.txt" "$T/anti2/demo-summary.txt"; then
	tap_ok "the same seed, the same run: the demo's summary is the same byte for byte"
else
	tap_fail "the same seed, the same run: the demo's summary is the same byte for byte" "$(diff "$T/anti/demo-summary.txt" "$T/anti2/demo-summary.txt" | head -20)"
fi
if diff <(grep -v '^log:' "$T/anti/summary.txt") <(grep -v '^log:' "$T/anti2/summary.txt") >"$T/anti.diff" &&
	cmp -s "$T/anti/phase_diff.csv" "$T/anti2/phase_diff.csv" && cmp -s "$T/anti/collisions.csv" "$T/anti2/collisions.csv"; then
	tap_ok "... and the analysis: summary, phase differences, collisions"
else
	tap_fail "... and the analysis: summary, phase differences, collisions" "$(head -20 "$T/anti.diff")"
fi

# another seed: random phases drawn from it, another run
demo seed8 7661 --seconds 20 --switch-at 3 --seed 8 --set world.separation=0.7 "${rig[@]}"
demo seed9 7661 --seconds 20 --switch-at 3 --seed 9 --set world.separation=0.7 "${rig[@]}"
t8=$(grep -m1 '^simulator:' "$T/seed8/demo-summary.txt"); t9=$(grep -m1 '^simulator:' "$T/seed9/demo-summary.txt")
if [ -n "$t8" ] && [ -n "$t9" ] && [ "$t8" != "$t9" ]; then
	tap_ok "another seed, another run (the simulator's totals differ)"
else
	tap_fail "another seed, another run" "seed 8: $t8; seed 9: $t9"
fi

# ---- the schedule in simulated time ---------------------------------------------------
# The switch at 5 s and, at 8 s, the right servo stops answering: the daemon
# times out at its derived timeouts and latches its silent-joint fault
# silent_s (0.5 s) later, in simulated time.
demo sched 7662 --seconds 12 --switch-at 5 --seed 3 --phases 0,2 --set 'events.8=fault right 1 no-reply' "${rig[@]}"
rc=$?
# simulated seconds of an event: its utime less the virtual clock's start
# (2000-01-01T00:00:00Z, common/lockstep.h)
sim_t() { awk -F, "$1"' { printf "%.6f\n", ($1 - 946684800000000) / 1e6 }' "$T/sched/events.csv" 2>/dev/null | sort -n; }
mode_t=$(sim_t '$6 == "\"mode\"" && index($0, "-> OSCILLATOR")')
n_mode=$(echo "$mode_t" | grep -c .)
if [ "$rc" = 0 ] && [ "$n_mode" = 2 ] && echo "$mode_t" | awk '$1 < 5.0 || $1 > 5.05 { bad = 1 } END { exit bad }'; then
	tap_ok "the switch came at its simulated time: both robots' mode events at $(echo $mode_t)"
else
	tap_fail "the switch came at its simulated time" "exit $rc; mode events at: $(echo $mode_t); $(tail -n 5 "$T/sched.out")"
fi
fault_t=$(sim_t '$3 == "\"right\"" && $6 ~ /fault/ && /silent/' | head -n 1)
if [ -n "$fault_t" ] && num "$fault_t >= 8.45 && $fault_t <= 8.65"; then
	tap_ok "a servo silent from 8 s: the daemon's fault latched at t = $fault_t s (silent_s 0.5 s later, simulated)"
else
	tap_fail "a servo silent from 8 s: the daemon's fault latched 0.5 s later" "fault at '$fault_t'; right's events: $(grep '"right"' "$T/sched/events.csv" | tail -n 6)"
fi
if grep -q 'ended: the run.s 12.000 s are over' "$T/sched/logs/sim.log"; then
	tap_ok "... and the run went on to its end"
else
	tap_fail "... and the run went on to its end" "$(grep 'lockstep:' "$T/sched/logs/sim.log" | tail -n 3)"
fi

# ---- nothing hangs ----------------------------------------------------------------------
# direct NAME: a simulator with a long run and a short grace, and both daemons.
URL=$(lcm_url 7663)
start_rig() {
	spawn sim "$B/undulate-sim" --scenario "$scenario" --link-dir "$T/links" --lcm-url "$URL" \
		--lockstep "$T/clock" --lockstep-grace 2 --duration 3600
	wait_log sim 'ready:' 5 || return 1
	for r in left right; do
		spawn "d_$r" "$B/undulated" --port "$T/links/$r" --ids 1 --robot "$r" --lcm-url "$URL" \
			--lockstep "$T/clock" --mode oscillator
	done
	wait_log d_left 'ready:' 10 && wait_log d_right 'ready:' 10
}
exited() { ! alive "$1"; }
# sim_ends_run SECONDS PATTERN NAME: within SECONDS the simulator ends the
# run, exits 1 and its log says PATTERN (grep -q). One TAP line, NAME.
sim_ends_run() {
	local rc
	if ! wait_for "$1" exited sim; then
		tap_fail "$3" "still running after $1 s: $(tail -n 3 "$T/sim.log")"
		return
	fi
	rc=$(stop sim)
	if [ "$rc" = 1 ] && grep -q "$2" "$T/sim.log"; then tap_ok "$3"
	else tap_fail "$3" "exit $rc: $(tail -n 4 "$T/sim.log")"; fi
}

start_rig || tap_fail "rig started in lockstep" "$(tail -n 5 "$T/sim.log" "$T/d_left.log")"
# No SIM.CMD in lockstep (a command from the network would land at any
# simulated time), so no liblcm receive thread waking for every message on
# the group: the simulator is one thread, says why, and a SIM.CMD client
# gets no answer (exit 3).
threads=$(ls "/proc/$pid_sim/task" 2>/dev/null | wc -l)
rc=0; "$B/undulate-sim" --cmd stats --lcm-url "$URL" >"$T/cmd.log" 2>&1 || rc=$?
if [ "$threads" = 1 ] && [ "$rc" = 3 ] && grep -q 'lockstep: SIM.CMD is not listened to' "$T/sim.log"; then
	tap_ok "in lockstep the simulator listens to no SIM.CMD, says so, and runs one thread"
else
	tap_fail "in lockstep the simulator listens to no SIM.CMD, says so, and runs one thread" \
		"threads $threads, --cmd exit $rc: $(head -c 300 "$T/cmd.log"); $(grep -c 'not listened' "$T/sim.log") line(s) saying so"
fi
kill -KILL "$pid_d_left"
sim_ends_run 15 "robot left's daemon (pid $pid_d_left) left the run at t=" \
	"a daemon killed: the simulator ends the run, naming it (exit 1)"
if wait_for 15 exited d_right && [ "$(stop d_right)" = 0 ] && grep -q 'ended the run' "$T/d_right.log"; then
	tap_ok "... and the other daemon is told, makes its safe stop and exits 0"
else
	tap_fail "... and the other daemon is told, makes its safe stop and exits 0" "$(tail -n 4 "$T/d_right.log")"
fi
stop d_left >/dev/null

start_rig || tap_fail "rig started in lockstep (2)" "$(tail -n 5 "$T/sim.log")"
kill -STOP "$pid_d_left"
sim_ends_run 20 "robot left's daemon (pid $pid_d_left) has not waited for 2 s" \
	"a daemon stopped (SIGSTOP): the simulator calls it stalled after its grace and ends the run (exit 1)"
kill -CONT "$pid_d_left"
if wait_for 15 exited d_left && [ "$(stop d_left)" = 1 ] && grep -qE 'lockstep: the simulator (closed the clock|is gone)' "$T/d_left.log"; then
	tap_ok "... and when it runs again it finds the simulator gone, says so, exits 1"
else
	tap_fail "... and when it runs again it finds the simulator gone" "$(tail -n 4 "$T/d_left.log")"
fi
wait_for 15 exited d_right; stop d_right >/dev/null

start_rig || tap_fail "rig started in lockstep (3)" "$(tail -n 5 "$T/sim.log")"
kill -KILL "$pid_sim"
if wait_for 15 exited d_left && wait_for 15 exited d_right; then
	rl=$(stop d_left); rr=$(stop d_right)
	if [ "$rl" = 1 ] && [ "$rr" = 1 ] && grep -qE 'lockstep: the simulator (closed the clock|is gone)' "$T/d_left.log"; then
		tap_ok "the simulator killed: both daemons say the clock is gone and exit 1"
	else
		tap_fail "the simulator killed: both daemons say so and exit 1" "exits $rl $rr: $(tail -n 3 "$T/d_left.log")"
	fi
else
	tap_fail "the simulator killed: the daemons exit" "still running after 15 s"
fi
stop sim >/dev/null

# a daemon for a port the simulator does not have; no simulator at all
spawn sim "$B/undulate-sim" --scenario "$scenario" --link-dir "$T/links" --lcm-url "$URL" \
	--lockstep "$T/clock" --lockstep-grace 2 --duration 10
wait_log sim 'ready:' 5
rc=0; "$B/undulated" --port /dev/null --ids 1 --robot stray --lcm-url "$URL" --lockstep "$T/clock" >"$T/stray.log" 2>&1 || rc=$?
if [ "$rc" = 1 ] && grep -q 'the simulator refused .*no bus of this simulation is at /dev/null' "$T/stray.log"; then
	tap_ok "a daemon for a bus the simulation has not: refused with why (exit 1)"
else
	tap_fail "a daemon for a bus the simulation has not: refused" "exit $rc: $(cat "$T/stray.log")"
fi
if wait_for 15 exited sim && [ "$(stop sim)" = 1 ] && grep -q '0 of 2 daemon(s) joined within 2 s; missing: left .* right' "$T/sim.log"; then
	tap_ok "nobody joins: the simulator gives up after its grace, naming the buses without a daemon (exit 1)"
else
	tap_fail "nobody joins: the simulator gives up after its grace" "$(tail -n 3 "$T/sim.log")"
fi
rc=0; "$B/undulated" --port "$T/links/left" --ids 1 --robot nosim --lcm-url "$URL" --lockstep "$T/no-such-clock" >"$T/nosim.log" 2>&1 || rc=$?
if [ "$rc" = 1 ] && grep -q "cannot reach the simulator at $T/no-such-clock" "$T/nosim.log"; then
	tap_ok "no simulator at the socket: the daemon says where it looked (exit 1)"
else
	tap_fail "no simulator at the socket: the daemon says where it looked" "exit $rc: $(cat "$T/nosim.log")"
fi
for bad in "--lockstep-grace 0" "--lockstep-grace abc" "--lockstep ''"; do
	rc=0; eval "\"$B/undulate-sim\" --link \"$T/x\" --ids 1 $bad" >"$T/bad.log" 2>&1 || rc=$?
	if [ "$rc" = 2 ] && grep -q 'lockstep' "$T/bad.log"; then
		tap_ok "undulate-sim $bad: refused with a message (exit 2)"
	else
		tap_fail "undulate-sim $bad: refused with a message (exit 2)" "exit $rc: $(cat "$T/bad.log")"
	fi
done
keep_runs anti anti2 seed8 seed9 sched
tap_done
