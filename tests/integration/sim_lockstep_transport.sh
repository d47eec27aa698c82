#!/usr/bin/env bash
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# sim_lockstep_transport.sh — the lockstep transports give the same run
# (common/lockstep.h): the bus bytes in the clock's messages (in-band, the
# default) and through the ptys (undulate-sim --lockstep-pty, here through
# UNDULATE_LOCKSTEP_PTY=1, which reaches the simulator scripts/demo.sh
# starts). One seed, a pair-rig run with the switch and a servo that stops
# answering (the daemon's time-outs and silent-joint fault), once on each:
#  - every LCM message of the run byte for byte, channel by channel: the
#    simulator's ground truth (SIM.TRUTH), its collisions and world, the
#    daemons' states, events and parameters; the BUS channels carry the
#    port's path and the process's CPU share (wall clock), so bus.csv is
#    compared without those two columns;
#  - the analysis (summary, phase differences, collisions, states, events),
#    the demo's summary, and the simulator's exit line and bus counters;
#  - each log says which transport ran.
# The same with the right bus disconnected at 6 s and reconnected at 7 s (the
# daemon's write fails as on a hung-up pty, it reopens the new one): the
# ground truth and the states the same, the events the same but for the
# run's directory in their text.
# And the baud the daemon sets on its pty is still followed in-band: a bus
# whose pty starts at 57600 bps with servos at 1 Mbps answers a daemon that
# set 1 Mbps (without the follow, nothing answers and the daemon cannot start).
. "$(dirname "$0")/../lib.sh"

scenario="$top/sim-bridge/scenarios/pair-rig.scenario"
rig=(--daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current --daemon-set sinusoid.amplitude=0.25)

# run NAME PORT [ENV...]: the pair rig in lockstep through scripts/demo.sh, in $T/NAME.
run() {
	local name=$1 port=$2; shift 2
	env "$@" BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep --scenario "$scenario" \
		--lcm-url "$(lcm_url "$port")" --out "$T/$name" --seconds 14 --switch-at 3 --seed 11 --phases 0,2.5 \
		--set world.separation=0.7 --set 'events.8=fault right 1 no-reply' "${rig[@]}" >"$T/$name.out" 2>&1
}
# run_dc NAME PORT [ENV...]: another seed, the right bus unplugged from 6 s to 7 s.
run_dc() {
	local name=$1 port=$2; shift 2
	env "$@" BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep --scenario "$scenario" \
		--lcm-url "$(lcm_url "$port")" --out "$T/$name" --seconds 12 --switch-at 3 --seed 5 --phases 0,2 \
		--set world.separation=0.7 --set 'events.6=disconnect right' --set 'events.7=reconnect right' "${rig[@]}" \
		>"$T/$name.out" 2>&1
}

# bus.csv without the port's path and the CPU share.
bus_csv() {
	awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "port" || $i == "cpu_percent") skip[i] = 1 }
		{ s = ""; for (i = 1; i <= NF; i++) if (!skip[i]) s = s FS $i; print s }' "$1"
}

run band 7670 || { tap_fail "in-band: the lockstep run ended by itself" "$(tail -n 20 "$T/band.out")"; keep_runs band; tap_done; exit; }
run pty 7671 UNDULATE_LOCKSTEP_PTY=1 || { tap_fail "pty: the lockstep run ended by itself" "$(tail -n 20 "$T/pty.out")"; keep_runs band pty; tap_done; exit; }
if grep -q 'bus bytes in-band; ended: the run.s 14.000 s are over' "$T/band/logs/sim.log" &&
	grep -q 'bus bytes through the ptys; ended: the run.s 14.000 s are over' "$T/pty/logs/sim.log"; then
	tap_ok "both runs ended by themselves, each on its transport (the simulator's log says which)"
else
	tap_fail "both runs ended by themselves, each on its transport" "$(grep -h 'of simulated time' "$T"/{band,pty}/logs/sim.log)"
fi

channels "$T/band/demo.lcmlog" | grep -v '\.BUS ' >"$T/band.ch"
channels "$T/pty/demo.lcmlog" | grep -v '\.BUS ' >"$T/pty.ch"
truth=$(grep -c '^SIM.TRUTH [1-9]' "$T/band.ch"); states=$(grep -c '^\(left\|right\).STATE [1-9]' "$T/band.ch")
if [ "$truth" = 1 ] && [ "$states" = 2 ] && cmp -s "$T/band.ch" "$T/pty.ch"; then
	tap_ok "every LCM message but the bus statistics the same byte for byte: $(awk '{ printf "%s%s %s", (NR > 1 ? ", " : ""), $1, $2 }' "$T/band.ch")"
else
	tap_fail "every LCM message but the bus statistics the same byte for byte" "$(diff "$T/band.ch" "$T/pty.ch" | head -20)"
fi

same=1 differs=""
for f in demo-summary.txt states.csv events.csv collisions.csv phase_diff.csv contact.csv return_map.csv; do
	cmp -s "$T/band/$f" "$T/pty/$f" || { same=0; differs="$differs $f"; }
done
diff <(grep -v '^log:' "$T/band/summary.txt") <(grep -v '^log:' "$T/pty/summary.txt") >/dev/null || { same=0; differs="$differs summary.txt"; }
diff <(bus_csv "$T/band/bus.csv") <(bus_csv "$T/pty/bus.csv") >/dev/null || { same=0; differs="$differs bus.csv"; }
diff <(grep -E '^undulate-sim: (exit|bus) ' "$T/band/logs/sim.log") <(grep -E '^undulate-sim: (exit|bus) ' "$T/pty/logs/sim.log") \
	>"$T/sim.diff" || { same=0; differs="$differs sim.log"; }
if [ "$same" = 1 ] && [ -s "$T/band/states.csv" ] && grep -q '^undulate-sim: bus right: .* replies' "$T/band/logs/sim.log"; then
	tap_ok "the analysis, the demo's summary and the simulator's exit and bus lines are the same"
else
	tap_fail "the analysis, the demo's summary and the simulator's exit and bus lines are the same" "differ:$differs; $(head -6 "$T/sim.diff")"
fi
fault=$(grep -c '"right".*silent' "$T/band/events.csv")
if [ "$fault" -gt 0 ]; then
	tap_ok "... with the daemon's time-outs in it: the silent servo's fault latched in both"
else
	tap_fail "... with the daemon's time-outs in it" "no silent-joint event: $(tail -n 5 "$T/band/events.csv")"
fi

# ---- a bus unplugged and plugged in again -------------------------------------------
run_dc dc-band 7673 && run_dc dc-pty 7674 UNDULATE_LOCKSTEP_PTY=1
rc=$?
channels "$T/dc-band/demo.lcmlog" | grep -E '^(SIM\.|[a-z]+\.STATE )' >"$T/dc-band.ch"
channels "$T/dc-pty/demo.lcmlog" | grep -E '^(SIM\.|[a-z]+\.STATE )' >"$T/dc-pty.ch"
undir() { sed 's/undulate-demo\.[A-Za-z0-9]*//g' "$1"; }
if [ "$rc" = 0 ] && grep -q 'bus-lost' "$T/dc-band/events.csv" && grep -q 'bus-back' "$T/dc-band/events.csv" &&
	cmp -s "$T/dc-band.ch" "$T/dc-pty.ch" && cmp -s "$T/dc-band/states.csv" "$T/dc-pty/states.csv" &&
	diff <(undir "$T/dc-band/events.csv") <(undir "$T/dc-pty/events.csv") >/dev/null; then
	tap_ok "a bus unplugged and plugged in again: the same ground truth, states and events on both transports"
else
	tap_fail "a bus unplugged and plugged in again: the same run on both transports" "exit $rc; $(diff "$T/dc-band.ch" "$T/dc-pty.ch" | head -6); $(diff <(undir "$T/dc-band/events.csv") <(undir "$T/dc-pty/events.csv") | head -6)"
fi

# ---- the baud the daemon set, followed in-band ---------------------------------------
URL=$(lcm_url 7672)
cat >"$T/baud.scenario" <<EOS
[robot solo]
ids = 1
link = $T/links/solo
baud = 57600
servo_baud = 1
EOS
spawn sim "$B/undulate-sim" --scenario "$T/baud.scenario" --lcm-url "$URL" --lockstep "$T/clock" --lockstep-grace 20 --duration 2
wait_log sim 'ready:' 10 || tap_fail "baud rig: the simulator started" "$(tail -n 5 "$T/sim.log")"
spawn d "$B/undulated" --port "$T/links/solo" --ids 1 --robot solo --baud 1000000 --lcm-url "$URL" --lockstep "$T/clock"
exited() { ! alive "$1"; }
wait_for 60 exited sim
rc=$(stop sim); stop d >/dev/null
if [ "$rc" = 0 ] && grep -q 'ready:' "$T/d.log" && grep -q 'bus bytes in-band' "$T/sim.log" &&
	grep -qE '^undulate-sim: bus solo: [1-9][0-9]* packets, [1-9][0-9]* replies, .* 0 wrong-baud' "$T/sim.log"; then
	tap_ok "in-band, the simulator follows the baud the daemon set on its pty (57600 -> 1 Mbps): the servos answer"
else
	tap_fail "in-band, the simulator follows the baud the daemon set on its pty" "exit $rc; $(grep -E 'bus solo|lockstep:' "$T/sim.log" | tail -n 3); daemon: $(tail -n 3 "$T/d.log")"
fi
keep_runs band pty dc-band dc-pty
tap_done
