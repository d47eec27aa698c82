#!/usr/bin/env bash
# run.sh: realtime — it measures a gait in real time: its simulators and daemons under SCHED_FIFO where allowed, else alone (tests/run.sh)
# The oscillator's defaults on the simulated robot, through the real daemon:
# undulate-sim + undulated with no oscillator settings at all, from rest (the
# daemon's starter), settle, then measure the joints' own angles as published
# (not the daemon's estimator): every joint at 0.8 ± 0.08 Hz and 0.8 ± 0.12 rad,
# every cycle's amplitude steady, and joint 2 behind joint 1 by a steady lag
# (the paper's travelling wave). A one-joint robot runs at the same time,
# and a one-joint robot on torque actuation (the simulator's current drive,
# as the pair rig's), whose frequency and amplitude are printed, not asserted
# (the figures the README and docs/EXPERIMENTS.md quote for it).
# The bands are the paper's numbers with room for what was measured across
# seeds, return delays 0/500 µs and a loaded 2-core machine (CONTROL.md:
# 0.78–0.82 Hz, 0.77–0.89 rad per cycle, lag 88–97°; 9 runs of this test on
# 2026-11-25: 0.816–0.830 Hz, 0.82–0.88 rad, lag 88–96°).
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
URL2=$(lcm_url 7740)
URL1=$(lcm_url 7741)
URL3=$(lcm_url 7742)
R2="lc2_$$"
R1="lc1_$$"
R3="lct_$$"
SETTLE_CYCLES=800      # 8 s: starter (ramp 1.5 s + one period), then the cycle settles
MEASURE_CYCLES=1000    # 10 s: eight periods (a disturbed window: one more)

spawn_rt sim2 "$S" --link "$T/bus2" --ids 1,2 --lcm-url "$URL2" --seed 11 --return-delay 0
spawn_rt sim1 "$S" --link "$T/bus1" --ids 1 --lcm-url "$URL1" --seed 12
spawn_rt sim3 "$S" --link "$T/bus3" --ids 1 --lcm-url "$URL3" --seed 13 --set motor.drive=current
wait_log sim2 'ready' 10 && wait_log sim1 'ready' 10 ||
	{ tap_fail "simulators ready" "$(cat "$T/sim2.log" "$T/sim1.log")"; tap_done; exit 1; }
spawn watch2 "$D" --watch "$R2" --raw --lcm-url "$URL2"
spawn watch1 "$D" --watch "$R1" --raw --lcm-url "$URL1"
spawn watch3 "$D" --watch "$R3" --raw --lcm-url "$URL3"
# start-up is not what this test is about: on a heavily loaded machine the
# first settings read can time out and the daemon exits (status 1, "a service
# manager should retry"); retry once, as the service would, and say so
start_daemon() {   # NAME ROBOT BUS IDS URL [DAEMON OPTIONS...]
	local try
	for try in 1 2; do
		spawn_rt "$1" "$D" --port "$T/$3" --ids "$4" --robot "$2" --lcm-url "$5" --mode oscillator "${@:6}"
		wait_log "$1" "ready: $2.STATE" 10 && return 0
		alive "$1" && return 1
		echo "# $1 exited at start-up (try $try): $(tail -1 "$T/$1.log")"
	done
	return 1
}
start_daemon d2 "$R2" bus2 1,2 "$URL2" && start_daemon d1 "$R1" bus1 1 "$URL1" ||
	{ tap_fail "daemons ready" "$(cat "$T/d2.log" "$T/d1.log")"; tap_done; exit 1; }
# the torque-driven robot's figures are printed only: a failed start is said, not failed
torque3=1
wait_log sim3 'ready' 10 && start_daemon d3 "$R3" bus3 1 "$URL3" --set robot.actuation=torque \
	--set robot.torque_drive=current || { torque3=0; echo "# torque-driven robot did not start: not measured"; }

last_cycle() { awk -v r="$1" '$1 == "STATE" && $2 == r { c = $3 } END { sub("cycle=", "", c); print c + 0 }' "$T/$2.log"; }
past() { [ "$(last_cycle "$1" "$2")" -ge "$3" ]; }

field() { sed -n "s/.* $1=\([-0-9.]*\).*/\1/p" | head -1; }

# bus errors + overruns the daemon counted between two cycles (from its STATE)
upsets() {   # ROBOT LOG FROM_CYCLE TO_CYCLE
	awk -v r="$1" -v a="$3" -v b="$4" '$1 == "STATE" && $2 == r {
		c = $3; sub("cycle=", "", c); c += 0; n = 0
		for (i = 5; i <= NF; i++) if ($i ~ /^(overruns|bus_errors)=/) { v = $i; sub(/^[a-z_]*=/, "", v); n += v }
		if (c <= a) first = n; if (c <= b) last = n }
		END { print last - first }' "$T/$2.log"
}
joint_ok() {   # MEASUREMENT JOINT
	local line; line=$(echo "$1" | grep "^j$2 ")
	[ "$(echo "$line" | field n)" -ge 6 ] 2>/dev/null && within "$(echo "$line" | field f)" 0.72 0.88 &&
		within "$(echo "$line" | field amin)" 0.68 0.92 && within "$(echo "$line" | field amax)" 0.68 0.92
}
lag_ok() {
	local lag; lag=$(echo "$1" | grep '^lag ')
	local lmin lmax; lmin=$(echo "$lag" | field min); lmax=$(echo "$lag" | field max)
	[ "$(echo "$lag" | field n)" -ge 6 ] 2>/dev/null && within "$lmin" 60 120 && within "$lmax" 60 120 &&
		awk -v a="$lmin" -v b="$lmax" 'BEGIN { exit !(b - a <= 15) }'
}
# states the watcher did not print in cycles [from, to) (UDP multicast
# drops what a starved reader does not take in time)
missed() {   # ROBOT LOG FROM_CYCLE TO_CYCLE
	awk -v r="$1" -v a="$3" -v b="$4" '$1 == "STATE" && $2 == r {
		c = $3; sub("cycle=", "", c); c += 0; if (c >= a && c < b) n++ }
		END { print b - a - n }' "$T/$2.log"
}

measure_window() {   # FROM_CYCLE TO_CYCLE -> sets m2, m1
	wait_for 40 past "$R2" watch2 "$2" && wait_for 10 past "$R1" watch1 "$2" ||
		{ tap_fail "both robots publish for $2 cycles" "$(tail -3 "$T/d2.log" "$T/d1.log")"; tap_done; exit 1; }
	local from to; from=$(awk -v c="$1" 'BEGIN { print c * 0.01 }'); to=$(awk -v c="$2" 'BEGIN { print c * 0.01 }')
	m2=$(samples "$R2" watch2 | measure "$from" "$to")
	m1=$(samples "$R1" watch1 | measure "$from" "$to")
	echo "# cycles $1..$2, two joints: ${m2//$'\n'/; } ($(missed "$R2" watch2 "$1" "$2") states not heard)"
	echo "# cycles $1..$2, one joint: ${m1//$'\n'/; } ($(missed "$R1" watch1 "$1" "$2") states not heard)"
	[ "$torque3" = 1 ] || return 0
	if wait_for 10 past "$R3" watch3 "$2"; then
		m3=$(samples "$R3" watch3 | measure "$from" "$to")
		echo "# cycles $1..$2, one joint, torque actuation on a current drive (not asserted): ${m3//$'\n'/; }"
	else
		echo "# torque-driven robot: did not publish for $2 cycles, not measured"
	fi
}

# A window measured on an overloaded machine — a daemon counted bus errors or
# overruns (the simulator then falls behind real time, which slows every
# joint), or the watcher missed more than 5 % of the states (crossings fall
# in the gaps: a full-suite run beside other work read 6 crossings in 10 s
# at 0.82 Hz) — is measured once more if it misses the bands.
end=$((SETTLE_CYCLES + MEASURE_CYCLES))
measure_window "$SETTLE_CYCLES" "$end"
if ! { joint_ok "$m2" 1 && joint_ok "$m2" 2 && joint_ok "$m1" 1 && lag_ok "$m2"; }; then
	u=$(( $(upsets "$R2" watch2 "$SETTLE_CYCLES" "$end") + $(upsets "$R1" watch1 "$SETTLE_CYCLES" "$end") ))
	g=$(( $(missed "$R2" watch2 "$SETTLE_CYCLES" "$end") + $(missed "$R1" watch1 "$SETTLE_CYCLES" "$end") ))
	if [ "$u" -gt 0 ] || [ "$g" -gt $((2 * MEASURE_CYCLES / 20)) ]; then
		echo "# $u bus errors/overruns and $g states not heard in that window: measuring the next one"
		measure_window "$end" $((end + MEASURE_CYCLES))
	fi
fi


check_joint() {   # NAME MEASUREMENT JOINT
	local line f amin amax n
	line=$(echo "$2" | grep "^j$3 ")
	f=$(echo "$line" | field f); amin=$(echo "$line" | field amin); amax=$(echo "$line" | field amax)
	n=$(echo "$line" | field n)
	if [ "${n:-0}" -ge 6 ] && within "$f" 0.72 0.88; then tap_ok "$1 joint $3: $f Hz (0.8 ± 0.08)"
	else tap_fail "$1 joint $3 frequency 0.8 ± 0.08 Hz" "$line"; fi
	if [ "${n:-0}" -ge 6 ] && within "$amin" 0.68 0.92 && within "$amax" 0.68 0.92; then
		tap_ok "$1 joint $3: every cycle $amin .. $amax rad (0.8 ± 0.12)"
	else tap_fail "$1 joint $3 amplitude 0.8 ± 0.12 rad in every cycle" "$line"; fi
}
check_joint "two-joint robot" "$m2" 1
check_joint "two-joint robot" "$m2" 2
check_joint "one-joint robot" "$m1" 1

# the travelling wave: joint 2 behind joint 1 by about a quarter period
# (CONTROL.md: ≈ 90°), the same every cycle
lag=$(echo "$m2" | grep '^lag ')
lmin=$(echo "$lag" | field min); lmax=$(echo "$lag" | field max); ln=$(echo "$lag" | field n)
if [ "${ln:-0}" -ge 6 ] && within "$lmin" 60 120 && within "$lmax" 60 120 &&
	awk -v a="$lmin" -v b="$lmax" 'BEGIN { exit !(b - a <= 15) }'; then
	tap_ok "joint 2 lags joint 1 by $lmin .. $lmax deg, steady (spread ≤ 15°)"
else tap_fail "steady travelling wave, joint 2 behind by 60..120° within 15°" "$lag"; fi

for p in d2 d1; do
	stop "$p" >"$T/$p.rc"; rc=$(cat "$T/$p.rc")
	tap_check "$p stops cleanly on SIGTERM" [ "$rc" = 0 ]
done
tap_done
