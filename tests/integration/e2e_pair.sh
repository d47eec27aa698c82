#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# e2e_pair.sh — the paper's pair rig through the real daemon on the simulated
# bus (theory.md, "Two phase oscillators that touch"): two single-joint robots
# on immobile bases, restitution r = 0.67, joints driven by torque as on the
# paper's rig (daemon torque actuation on the simulator's current drive;
# E2E_DAEMON_SETS="" runs the daemons as position servos instead, where the
# anti-phase case does not reproduce: docs/EXPERIMENTS.md). Each run starts both robots in
# SINUSOID at a chosen phase difference, switches them to OSCILLATOR by one
# LCM command, records the LCM traffic and reads the outcome with
# undulate-analyze. The three regimes the theory predicts, asserted as the
# paper states them:
#   small d~  (0.05)            -> in phase: final |D| < 0.3 rad
#   intermediate d~ (0.3)       -> compatible: |D| <= 2 asin(d~) + 0.1, the contact
#                                  impulse down tenfold, and no collision in the
#                                  last 10 s (a TODO when one graze remains:
#                                  docs/EXPERIMENTS.md)
#   large d~ (0.7), D0 = pi     -> anti-phase: |D| within 0.5 of pi, collisions go on
# The same three regimes run again in lockstep (virtual time), and on
# XM430-W350 servos in current control (Protocol 2.0).
# d~ is the analyser's, from the amplitude the daemons actually reach, and
# each run first checks that it landed in the regime it is meant to test. A
# pair that stopped swinging proves nothing: its regime checks are skipped (the
# stop is a failure of its own).
# make test runs the lockstep half (tests/lib.sh, E2E_PART); the real-time
# half runs alone in make test-long: tests/long/e2e_pair_realtime.sh.
source "$(dirname "$0")/../lib.sh"

scenario="$top/sim-bridge/scenarios/pair-rig.scenario"
seconds=${E2E_PAIR_SECONDS:-40}
# Daemon settings for every run: torque actuation on the rig's current drive;
# the daemon's single-joint torque defaults give ~0.8 rad at 0.80 Hz there.
# The robots start on a small sinusoid (0.25 rad) at the chosen phases, so the
# phase difference is set before any contact (at 0.8 rad the pair would already
# press into each other under the clock, and the moment of the switch would
# scramble it); the oscillators then grow to their limit cycle within a few
# periods, both alike, and the contact starts from the chosen difference.
rig=(${E2E_DAEMON_SETS---daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current --daemon-set sinusoid.amplitude=0.25})

# run NAME PORT SEPARATION PHASES: one rig run in the background, output in $T/NAME/.
run() {
	local name=$1 port=$2 sep=$3 phases=$4
	spawn "$name" env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --scenario "$scenario" \
		--seconds "$seconds" --switch-at 3 --seed 7 --phases "$phases" --set "world.separation=$sep" \
		--lcm-url "$(lcm_url "$port")" --out "$T/$name" "${rig[@]}"
	# Start the next run only when this one's daemons are up (start-up is the
	# busiest moment for the simulated buses).
	wait_log "$name" '^demo: phases' 20 || true
}
# col NAME COLUMN: a column of the pair's row in the run's summary.txt.
col() { summary_col "$T/$1" left:right "$2"; }
# collisions NAME FROM TO: collisions (pairs and walls) between FROM and TO s of the log.
collisions() {
	awk -F, -v a="$2" -v b="$3" 'NR > 1 && $1 >= a && $1 < b { n += $2 } END { print n + 0 }' "$T/$1/collision_rate.csv"
}
# after_switch NAME: collisions in the 10 s after the switch to the oscillator.
after_switch() {
	local sw
	sw=$(cat "$T/$1/switch_t")
	collisions "$1" "$sw" "$(awk "BEGIN { print $sw + 10 }")"
}
span() { awk -F, 'NR > 1 { t = $1 } END { print t + 1 }' "$T/$1/collision_rate.csv"; }
num() { awk "BEGIN { exit !($*) }"; }
# Peak-to-peak (rad) both robots must keep: half the rig's 2 x 0.8 rad.
MIN_SWING=0.8

# Three LCM ports, one of five blocks in 7855-7869 (two copies of this test
# running at once rarely meet; demo.sh warns when they do).
port=$((7855 + 3 * ($$ % 5)))
if realtime_part; then
	run inphase $port 0.05 0,2.0
	run compat $((port + 1)) 0.3 0,2.0
	run anti $((port + 2)) 0.7 0,3.1416
	for name in inphase compat anti; do
		run_ran "$name" $((seconds + 60)) "$name" "$name: rig ran ${seconds} s through sim + 2 daemons, log analysed" &&
			still_swings "$name" "$name: both robots still swing at the end" "a stopped pair proves nothing"
	done
fi

# regime NAME: the run's regime can be judged (it ran, and both robots still swing)
regime() { judged "$1" "$1: the regime's checks" "the robots stopped swinging: nothing to judge"; }
# collided LABEL SIZE COND D AFTER: the run's d~ (D) is SIZE (the num
# condition COND) and the robots collided after the switch (AFTER times): the
# separation that makes the regime, and contact the oscillator must resolve.
collided() {
	if num "$3" && [ "$5" -gt 0 ]; then
		tap_ok "$1: $2 d~ ($4); the robots collided after the switch ($5)"
	else
		tap_fail "$1: $2 d~; the robots collided after the switch" "d~ $4, collisions $5"
	fi
}

if realtime_part; then
	# ---- small separation: in phase --------------------------------------------------
	n=inphase
	if regime $n; then
		d=$(col $n d~); D=$(col $n meanD); after=$(after_switch $n)
		echo "# in phase: d~ $d, final D $D, collisions in the 10 s after the switch $after"
		collided "in phase" small "$d < 0.15" "$d" "$after"
		if num "${D#-} < 0.3"; then
			tap_ok "in phase: final |D| = ${D#-} < 0.3 rad (d~ = $d)"
		else
			tap_fail "in phase: final |D| < 0.3 rad" "final D $D (d~ $d, state $(col $n state))"
		fi
	fi

	# ---- intermediate separation: compatible ----------------------------------------
	n=compat
	if regime $n; then
		d=$(col $n d~); D=$(col $n meanD); lim=$(col $n "2asin(d~)"); end=$(span $n)
		sw=$(cat "$T/$n/switch_t"); after=$(after_switch $n)
		last=$(collisions $n "$(awk "BEGIN { print $end - 10 }")" "$end")
		echo "# compatible: d~ $d (2 asin $lim), final D $D, collisions in the 10 s after the switch $after, in the last 10 s $last"
		collided compatible intermediate "$d > 0.15 && $d < 0.45" "$d" "$after"
		# Two separate claims: the phase difference ends inside the compatible
		# set (at most the grazing value 2 asin(d~), the map's fixed point), and
		# the contact stops there.
		if num "${D#-} <= $lim + 0.1"; then
			tap_ok "compatible: final |D| = ${D#-} <= 2 asin(d~) + 0.1 = $lim + 0.1"
		else
			tap_fail "compatible: final |D| <= 2 asin(d~) + 0.1" "final D $D, 2 asin(d~) $lim (state $(col $n state))"
		fi
		# impulse (N*s) in the 10 s after the switch and in the last 10 s
		imp() { awk -F, -v a="$2" -v b="$3" 'NR > 1 && $1 >= a && $1 < b { s += $3 } END { printf "%.4f", s }' "$T/$1/collision_rate.csv"; }
		imp_after=$(imp $n "$sw" "$(awk "BEGIN { print $sw + 10 }")")
		imp_last=$(imp $n "$(awk "BEGIN { print $end - 10 }")" "$end")
		per10=$(awk -F, 'NR > 1 { b = int($1 / 10); s[b] += $3; if (b > m) m = b } END { for (b = 0; b <= m; b++) printf "%.3f ", s[b] }' "$T/$n/collision_rate.csv")
		if num "$imp_last == 0 || $imp_last <= 0.1 * $imp_after"; then
			tap_ok "compatible: contact impulse down at least tenfold ($imp_after -> $imp_last N*s per 10 s)"
		else
			tap_fail "compatible: contact impulse down at least tenfold" "$imp_after -> $imp_last N*s per 10 s; per 10 s: ${per10}N*s"
		fi
		if [ "$last" -eq 0 ]; then
			tap_ok "compatible: no collision in the last 10 s"
		else
			# The paper's "contact stops": in some runs one graze in 10 s remains at
			# |D| near 2 asin(d~) (docs/EXPERIMENTS.md says so): reported with the numbers.
			tap_todo "compatible: no collision in the last 10 s" "$last collisions in the last 10 s at final D $D (2 asin(d~) $lim, state $(col $n state)); impulse per 10 s: ${per10}N*s"
		fi
	fi

	# ---- large separation from a large phase difference: anti-phase ------------------
	n=anti
	if regime $n; then
		d=$(col $n d~); D=$(col $n meanD); end=$(span $n)
		last=$(collisions $n "$(awk "BEGIN { print $end - 10 }")" "$end")
		# d~_c = sqrt(r(r - 1) / (r^2 - r - 2)) for r = 0.67 (theory.md)
		dc=$(awk 'BEGIN { r = 0.67; printf "%.3f", sqrt(r * (r - 1) / (r * r - r - 2)) }')
		echo "# anti-phase: d~ $d (critical $dc), final D $D, collisions in the last 10 s $last"
		if num "$d > $dc + 0.1 && $d < 1"; then
			tap_ok "anti-phase: d~ = $d is above the critical separation $dc"
		else
			tap_fail "anti-phase: d~ above the critical separation" "d~ $d, critical $dc"
		fi
		# Through torque-driven joints, as on the paper's rig. Through position
		# servos (E2E_DAEMON_SETS="") it does not reproduce (docs/EXPERIMENTS.md):
		# there it is reported as TODO with the numbers.
		report=tap_fail
		[ ${#rig[@]} -eq 0 ] && report=tap_todo
		if num "${D#-} > 3.1416 - 0.5" && [ "$last" -gt 0 ]; then
			tap_ok "anti-phase: locked at |D| = ${D#-} (within 0.5 of pi), still colliding ($last in the last 10 s)"
		else
			$report "anti-phase: |D| within 0.5 of pi with collisions going on" "final D $D, collisions in the last 10 s $last, state $(col $n state); phase difference every 5 s: $(awk -F, 'NR > 1 && $3 == "\"left:right\"" && $2 >= next_t { printf "%.0fs %.2f  ", $2, $9; next_t = $2 + 5 }' "$T/$n/phase_diff.csv")"
		fi
	fi
fi
if lockstep_part; then
	# ---- the same three regimes in virtual time, three seeds each ---------------------------
	# scripts/demo.sh --lockstep: the same programs on the simulated bus, paced by
	# the simulator's clock. The real-time runs' seed (7) and two more; each must
	# land in the regime the theory and the real-time run put it in (the real-time
	# runs above assert the same regimes). Anti-phase must also carry the same
	# label as the real-time run; the other two are sets, not labels: a pair in
	# phase at d~ 0.05 still touches now and then ("in-phase" or "still-colliding"
	# by whether a touch fell in the final window), and a compatible one may end
	# anywhere in |D| <= 2 asin(d~) + 0.1 ("in-phase", "compatible", or
	# "still-colliding" while it grazes).
	lrun() {
		local name=$1 sep=$2 phases=$3 seed=$4
		env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep --scenario "$scenario" \
			--seconds "$seconds" --switch-at 3 --seed "$seed" --phases "$phases" --set "world.separation=$sep" \
			--lcm-url "$(lcm_url "$port")" --out "$T/$name" "${rig[@]}" >"$T/$name.log" 2>&1
	}
	# in_regime NAME REGIME: the run ended where REGIME's claim says.
	in_regime() {
		local D lim end last
		D=$(col "$1" meanD); lim=$(col "$1" "2asin(d~)")
		case $2 in
		inphase) num "${D#-} < 0.3" ;;
		compat) num "${D#-} <= $lim + 0.1" ;;
		anti)
			end=$(span "$1"); last=$(collisions "$1" "$(awk "BEGIN { print $end - 10 }")" "$end")
			num "${D#-} > 3.1416 - 0.5" && [ "$last" -gt 0 ] ;;
		esac
	}
	lock_runs=()
	for spec in "inphase 0.05 0,2.0" "compat 0.3 0,2.0" "anti 0.7 0,3.1416"; do
		read -r regime_name sep phases <<<"$spec"
		report=tap_fail
		[ "$regime_name" = anti ] && [ ${#rig[@]} -eq 0 ] && report=tap_todo
		rt_state=-
		[ -f "$T/$regime_name/moving" ] && rt_state=$(col "$regime_name" state)
		for seed in 7 8 9; do
			n="lock_${regime_name}_$seed"
			lock_runs+=("$n")
			if ! lrun "$n" "$sep" "$phases" "$seed" || [ ! -f "$T/$n/summary.txt" ]; then
				tap_fail "$regime_name in lockstep, seed $seed: ran" "$(tail -n 10 "$T/$n.log")"
				continue
			fi
			state=$(col "$n" state); D=$(col "$n" meanD)
			what="$regime_name in lockstep, seed $seed: in its regime (final D $D, $state$([ "$rt_state" = - ] || echo "; real time, seed 7: $rt_state"))"
			if ! in_regime "$n" "$regime_name"; then
				$report "$what" "d~ $(col "$n" d~), 2 asin(d~) $(col "$n" "2asin(d~)"), collisions in the last 10 s $(last_collisions "$T/$n")"
			elif [ "$regime_name" = anti ] && [ "$rt_state" != - ] && [ "$state" != "$rt_state" ]; then
				$report "$what" "the real-time run with this seed ended $rt_state"
			else
				tap_ok "$what"
			fi
		done
	done
	# ---- the same rig on XM430-W350 servos (Protocol 2.0), in virtual time --------------------
	# The paper's rig drove currents: torque actuation in the XM430's current
	# control (operating mode 0, Goal Current), the daemon's torque defaults
	# scaled to the XM430's joint (daemon/CONTROL.md). Two seeds per regime, each
	# must land where the theory puts it, as on the AX-12A's current drive.
	xrig=(--set sim.model=xm430-w350 --set sim.baud=1000000 --set sim.return_delay_us=0
		--daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current --daemon-set sinusoid.amplitude=0.25)
	for spec in "inphase 0.05 0,2.0" "compat 0.3 0,2.0" "anti 0.7 0,3.1416"; do
		read -r regime_name sep phases <<<"$spec"
		for seed in 7 8; do
			n="xm_${regime_name}_$seed"
			lock_runs+=("$n")
			if ! env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep --scenario "$scenario" \
				--seconds "$seconds" --switch-at 3 --seed "$seed" --phases "$phases" --set "world.separation=$sep" \
				--lcm-url "$(lcm_url "$port")" --out "$T/$n" "${xrig[@]}" >"$T/$n.log" 2>&1 || [ ! -f "$T/$n/summary.txt" ]; then
				tap_fail "XM430 $regime_name in lockstep, seed $seed: ran" "$(tail -n 10 "$T/$n.log")"
				continue
			fi
			if ! grep -q 'Protocol 2.0 (XM430-W350)' "$T/$n/logs/undulated-left.log"; then
				tap_fail "XM430 $regime_name in lockstep, seed $seed: on Protocol 2.0" "$(head -3 "$T/$n/logs/undulated-left.log")"
				continue
			fi
			state=$(col "$n" state); D=$(col "$n" meanD); sw=$(min_swing "$T/$n")
			what="XM430 $regime_name in lockstep, seed $seed: in its regime (final D $D, $state, d~ $(col "$n" d~); smallest swing ${sw%% *} rad)"
			if num "${sw%% *} >= $MIN_SWING" && in_regime "$n" "$regime_name"; then
				tap_ok "$what"
			else
				tap_fail "$what" "2 asin(d~) $(col "$n" "2asin(d~)"), collisions in the last 10 s $(last_collisions "$T/$n")"
			fi
		done
	done
fi
keep_runs inphase compat anti "${lock_runs[@]}"
tap_done
