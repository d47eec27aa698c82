#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# e2e_row.sh — a row of five single-joint robots at large separation
# (d~ = 0.7 at 0.8 rad), restitution 0.67, each end closed by a wall where a
# mirrored neighbour would stand (the paper's lattice has fixed ends), through
# the real daemons, each joint driven by the oscillator's torque (daemon torque
# actuation on the simulator's current drive). The paper's claims (theory.md, lattice):
#   immobile bases (beta = 0)  -> neighbours keep colliding: at least 3 of the
#                                 4 pairs collide in the last 10 s (docs/EXPERIMENTS.md)
#   mobile bases (beta > 0)    -> always relax to a collision-free compatible
#                                 state: every pair |D| <= 2 asin(d~) + 0.1 and
#                                 the contact impulse of the last 10 s at most
#                                 a fifth of the immobile row's (asserted: in
#                                 real time in at least one of two seeds, in
#                                 lockstep for each seed; see below why);
#                                 no collision (pairs or walls) in the last 10 s
#                                 (a TODO when a graze remains: docs/EXPERIMENTS.md)
# make test runs the lockstep half (tests/lib.sh, E2E_PART); the real-time
# half runs alone in make test-long: tests/long/e2e_row_realtime.sh.
source "$(dirname "$0")/../lib.sh"

seconds=${E2E_ROW_SECONDS:-60}
# Daemon settings for every run: the lattice's oscillators driven by torque, on
# the scenarios' current drive (as the pair rig; ~0.8 rad at 0.80 Hz).
# E2E_DAEMON_SETS="" runs them as position servos instead: there the mobile
# row's claim does not reproduce reliably and is reported as TODO.
rig=(${E2E_DAEMON_SETS---daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current})

# run NAME SCENARIO SEED PORT: a row in real time, in the background
run() {
	local name=$1 scenario=$2 seed=$3 port=$4
	spawn "$name" env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" \
		--scenario "$top/sim-bridge/scenarios/row-$scenario.scenario" --seconds "$seconds" --switch-at 3 \
		--seed "$seed" --lcm-url "$(lcm_url "$port")" --out "$T/$name" "${rig[@]}"
	wait_log "$name" '^demo: phases' 20 || true
}
# rows NAME: "pair state meanD d~ 2asin c.win" for each neighbouring pair.
rows() {
	awk '
		$1 == "pair" && !hdr { for (i = 1; i <= NF; i++) { if ($i == "end" && $(i + 1) == "state") { c["state"] = ++j; i++ } else c[$i] = ++j }; hdr = 1; next }
		hdr && $1 ~ /^r[0-9]:r[0-9]$/ { print $1, $c["state"], $c["meanD"], $c["d~"], $c["2asin(d~)"], $c["c.win"] }' "$T/$1/summary.txt"
}
# Peak-to-peak (rad) every robot must keep: half of 2 x 0.8 rad.
MIN_SWING=0.8

# The mobile row in real time twice, seeds 11 and 12, beside the immobile row:
# its relaxation time has a tail. Of 35 single real-time runs (seeds 1-11,
# 2026-11-27, alone and beside CPU burners, and CI's) 33 were relaxed within
# the 60 s and 2 (seeds 7 and 11) still collided in every pair at the end;
# in lockstep 1 seed of 160 (54: its last collision at 57 s), and a relaxed
# row may touch again later (seed 34 at 88 s): the phase differences drift
# and the walls bound how far the bases spread. One run would fail the claim
# in about 1 of 18 suites; two independent ones both fail in about 1 of 300.
# The lockstep runs below are deterministic and judge each seed.
# Three LCM ports, one of three blocks in 7870-7878.
port=$((7870 + 3 * ($$ % 3)))
if realtime_part; then
	run immobile immobile 11 $port
	run mobile mobile 11 $((port + 1))
	run mobile_b mobile 12 $((port + 2))
	for name in immobile mobile mobile_b; do
		run_ran "$name" $((seconds + 60)) "$name row" "$name row: ${seconds} s through sim + 5 daemons, log analysed" || continue
		# the switch is one command to every robot; a robot left on the clock
		# would keep colliding whatever its base does
		modes=$(end_modes "$T/$name")
		if [ "$(echo "$modes" | grep -o '=OSCILLATOR' | wc -l)" = 5 ]; then
			tap_ok "$name row: every robot took the switch (5 on OSCILLATOR at the end)"
		else
			tap_fail "$name row: every robot took the switch" "at the end: $modes; $(cat "$T/$name/logs/switch.log" 2>/dev/null | tr '\n' ';')"
		fi
		still_swings "$name" "$name row: every robot still swings at the end"
	done
fi

# regime NAME: the row can be judged (it ran, and every robot still swings:
# a stopped robot neither collides nor relaxes; the stop is a failure of its own)
regime() { judged "$1" "$1 row: the regime's check" "a robot stopped swinging: nothing to judge"; }

if realtime_part; then
	if regime immobile; then
		r=$(rows immobile)
		echo "$r" | sed 's/^/# immobile: /'
		npairs=$(echo "$r" | awk 'NF { n++ } END { print n + 0 }')
		quiet=$(echo "$r" | awk '$6 == 0 { print $1 }' | tr '\n' ' ')
		pair_coll=$(echo "$r" | awk '{ s += $6 } END { print s + 0 }')
		nquiet=$(echo $quiet | wc -w)
		# The paper: the immobile lattice keeps colliding (as a lattice). Not
		# every pair: the in-phase state is compatible at any separation, and a
		# pair that lands near it may stay out of contact while its neighbours
		# keep colliding (seen: r3:r4 at mean D -0.25, 0 contacts, the other
		# three 5-8 each).
		if [ "$npairs" = 4 ] && [ "$nquiet" -le 1 ]; then
			tap_ok "immobile row keeps colliding: $((4 - nquiet)) of the 4 pairs collide in the last 10 s ($pair_coll in all)"
		else
			tap_fail "immobile row keeps colliding: at least 3 of the 4 pairs collide in the last 10 s" "$npairs pairs; without a collision in the last 10 s: ${quiet:-none}"
			run_diag "$T/immobile"
		fi
	fi
fi

# imp NAME FROM TO: contact impulse (N*s, pairs and walls) between FROM and TO s.
imp() { awk -F, -v a="$2" -v b="$3" 'NR > 1 && $1 >= a && $1 < b { s += $3 } END { printf "%.4f", s }' "$T/$1/collision_rate.csv"; }
# Through position servos (E2E_DAEMON_SETS="") the mobile row's claim does not
# reproduce reliably (docs/EXPERIMENTS.md): reported as TODO there.
report=tap_fail
[ ${#rig[@]} -eq 0 ] && report=tap_todo

if realtime_part; then
	# relaxed NAME: the mobile row NAME ended every pair compatible with at most a
	# fifth of the immobile row's contact in the last 10 s; says how it ended.
	relaxed() {
		local name=$1 r bad last end from imp_first imp_last imp_imm
		r=$(rows "$name")
		echo "$r" | sed "s/^/# $name: /"
		bad=$(echo "$r" | awk '{ D = $3 < 0 ? -$3 : $3 } D > $5 + 0.1 { print $1 }' | tr '\n' ' ')
		# Contact impulse (N*s, pairs and walls) in the last 10 s, against the
		# immobile row's in the same seconds: the paper's contrast (a lattice that
		# keeps colliding unless its bases can move). Not "down tenfold from the
		# 10 s after the switch": the clock's contacts often spread the bases so
		# far that no contact follows the switch, and a reference of 0 turned one
		# late graze into a failure (seen in CI: 0.0000 -> 0.1271 N*s).
		end=$(awk -F, 'NR > 1 { t = $1 } END { print t + 1 }' "$T/$name/collision_rate.csv")
		from=$(awk "BEGIN { print $end - 10 }")
		imp_first=$(imp "$name" 0 10); imp_last=$(imp "$name" "$from" "$end"); imp_imm=$(imp immobile "$from" "$end")
		last=$(last_collisions "$T/$name")
		echo "# $name: contact impulse $imp_first N*s in the first 10 s, $imp_last in the last 10 s" \
			"(immobile: $imp_imm); collisions in the last 10 s: $last; pairs outside 2 asin(d~) + 0.1: ${bad:-none}"
		[ -z "$bad" ] && awk -v m="$imp_last" -v i="$imp_imm" 'BEGIN { exit !(i > 0 && m <= 0.2 * i) }' || return 1
		[ "$last" -eq 0 ] && : >"$T/$name/quiet"
		return 0
	}
	if [ ! -f "$T/immobile/moving" ]; then
		tap_skip "mobile rows: relaxed against the immobile row" "the immobile row cannot be judged (a robot stopped)"
	else
		ok_runs=() judged=0
		for name in mobile mobile_b; do
			regime "$name" || continue
			judged=$((judged + 1))
			if relaxed "$name"; then ok_runs+=("$name"); fi
		done
		if [ "$judged" -gt 0 ] && [ ${#ok_runs[@]} -gt 0 ]; then
			tap_ok "mobile row relaxed (every pair compatible, |D| <= 2 asin(d~) + 0.1; contact in the last 10 s at most a fifth of the immobile row's) in ${#ok_runs[@]} of $judged real-time runs: ${ok_runs[*]}"
		elif [ "$judged" -gt 0 ]; then
			# E2E_DAEMON_SETS="": position servos, where the claim does not hold reliably
			$report "mobile row relaxed in at least one of $judged real-time runs" "none did (above)"
		fi
		# a real-time run is not repeatable: what a row that did not relax did goes with it
		if [ ${#ok_runs[@]} -lt "$judged" ]; then
			for name in mobile mobile_b; do
				[[ " ${ok_runs[*]} " != *" $name "* ]] && [ -f "$T/$name/summary.txt" ] &&
					{ echo "# $name did not relax:"; run_diag "$T/$name"; }
			done
			echo "# the immobile row beside it:"; run_diag "$T/immobile"
		fi
		# The paper's "always reach collision-free states": in some runs one
		# graze remains in the last 10 s (docs/EXPERIMENTS.md says so).
		nq=0
		for name in "${ok_runs[@]}"; do [ -f "$T/$name/quiet" ] && nq=$((nq + 1)); done
		if [ ${#ok_runs[@]} -gt 0 ] && [ "$nq" = ${#ok_runs[@]} ]; then
			tap_ok "mobile row: collision-free in the last 10 s (the relaxed runs)"
		elif [ ${#ok_runs[@]} -gt 0 ]; then
			tap_todo "mobile row: collision-free in the last 10 s" "$((${#ok_runs[@]} - nq)) of the relaxed runs still touched (above)"
		fi
	fi
fi
if lockstep_part; then
	# ---- both rows in virtual time, the real-time seed and another --------------------------
	# scripts/demo.sh --lockstep: the same programs, the simulator's clock. Each
	# seed's immobile row must keep colliding and its mobile row end compatible,
	# with at most a fifth of the immobile row's contact in the last 10 s, as in
	# real time (the graze the real-time runs sometimes keep is not asserted here
	# either).
	lock_runs=()
	for seed in 11 12; do
		for name in immobile mobile; do
			n="lock_${name}_$seed"
			lock_runs+=("$n")
			env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep \
				--scenario "$top/sim-bridge/scenarios/row-$name.scenario" --seconds "$seconds" --switch-at 3 \
				--seed "$seed" --lcm-url "$(lcm_url "$port")" --out "$T/$n" "${rig[@]}" >"$T/$n.log" 2>&1
		done
		if [ ! -f "$T/lock_immobile_$seed/summary.txt" ] || [ ! -f "$T/lock_mobile_$seed/summary.txt" ]; then
			tap_fail "rows in lockstep, seed $seed: ran" "$(tail -n 10 "$T/lock_immobile_$seed.log" "$T/lock_mobile_$seed.log")"
			continue
		fi
		r=$(rows "lock_immobile_$seed")
		nquiet=$(echo "$r" | awk '$6 == 0 { n++ } END { print n + 0 }')
		if [ "$(echo "$r" | grep -c .)" = 4 ] && [ "$nquiet" -le 1 ]; then
			tap_ok "immobile row in lockstep, seed $seed: keeps colliding ($((4 - nquiet)) of 4 pairs in the last 10 s)"
		else
			tap_fail "immobile row in lockstep, seed $seed: keeps colliding" "$(echo "$r" | tr '\n' ';')"
		fi
		r=$(rows "lock_mobile_$seed")
		bad=$(echo "$r" | awk '{ D = $3 < 0 ? -$3 : $3 } D > $5 + 0.1 { print $1 }' | tr '\n' ' ')
		end=$(awk -F, 'NR > 1 { t = $1 } END { print t + 1 }' "$T/lock_mobile_$seed/collision_rate.csv")
		from=$(awk "BEGIN { print $end - 10 }")
		imp_last=$(imp "lock_mobile_$seed" "$from" "$end"); imp_imm=$(imp "lock_immobile_$seed" "$from" "$end")
		if [ -z "$bad" ] && awk -v m="$imp_last" -v i="$imp_imm" 'BEGIN { exit !(i > 0 && m <= 0.2 * i) }'; then
			tap_ok "mobile row in lockstep, seed $seed: every pair compatible, contact $imp_last against the immobile row's $imp_imm N*s"
		else
			$report "mobile row in lockstep, seed $seed: every pair compatible, contact at most a fifth of the immobile row's" \
				"pairs outside 2 asin(d~) + 0.1: ${bad:-none}; contact $imp_last against $imp_imm N*s"
			run_diag "$T/lock_mobile_$seed"
		fi
	done
	# ---- what the daemons publish is what the analyser measures ---------------------------------
	# Every joint's published frequency (<robot>.STATE) against the analyser's own
	# estimate from the published angles (states.csv: frequency, frequency_est),
	# in the immobile row, whose collisions bend a cycle every second or so: one
	# estimator (common/phase.h). Before the daemon took it, its running mean
	# differed by 0.047 Hz on average there, 0.30 Hz at worst.
	if [ -f "$T/lock_immobile_11/states.csv" ]; then
		d=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
			$c["t"] > 20 && $c["frequency"] > 0 && $c["frequency_est"] > 0 {
				d = $c["frequency"] - $c["frequency_est"]; if (d < 0) d = -d; n++; if (d > m) m = d; if (d > 0.005) far++ }
			END { printf "%d %.4f %d", n, m, far }' "$T/lock_immobile_11/states.csv")
		set -- $d
		# five joints at 100 Hz after 20 s: ask for half of them
		want=$(( 250 * (seconds - 20) ))
		if [ "$want" -gt 0 ] && [ "${1:-0}" -gt "$want" ] && [ "${3:-?}" = 0 ]; then
			tap_ok "published frequency = the analyser's within 0.005 Hz in a colliding row ($1 samples after 20 s, worst $2 Hz)"
		else
			tap_fail "published frequency = the analyser's within 0.005 Hz in a colliding row" "samples ${1:-?} (> $want wanted), worst ${2:-?} Hz, ${3:-?} further than 0.005 Hz"
		fi
	fi
	# ---- the rows on XM430-W350 servos (Protocol 2.0), in virtual time ---------------------------
	# Each joint in the XM430's current control (torque actuation, the daemon's
	# torque defaults scaled to the XM430's joint): the same two claims.
	xrig=(--set sim.model=xm430-w350 --set sim.baud=1000000 --set sim.return_delay_us=0
		--daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current)
	for name in immobile mobile; do
		n="xm_$name"
		lock_runs+=("$n")
		env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep \
			--scenario "$top/sim-bridge/scenarios/row-$name.scenario" --seconds "$seconds" --switch-at 3 \
			--seed 11 --lcm-url "$(lcm_url "$port")" --out "$T/$n" "${xrig[@]}" >"$T/$n.log" 2>&1
	done
	if [ ! -f "$T/xm_immobile/summary.txt" ] || [ ! -f "$T/xm_mobile/summary.txt" ] ||
		! grep -q 'Protocol 2.0 (XM430-W350)' "$T/xm_mobile/logs/undulated-r1.log"; then
		tap_fail "XM430 rows in lockstep: ran on Protocol 2.0" "$(tail -n 10 "$T/xm_immobile.log" "$T/xm_mobile.log")"
	else
		r=$(rows xm_immobile)
		nquiet=$(echo "$r" | awk '$6 == 0 { n++ } END { print n + 0 }')
		sw=$(min_swing "$T/xm_immobile")
		if [ "$(echo "$r" | grep -c .)" = 4 ] && [ "$nquiet" -le 1 ] && awk -v s="${sw%% *}" -v m=$MIN_SWING 'BEGIN { exit !(s >= m) }'; then
			tap_ok "XM430 immobile row in lockstep: keeps colliding ($((4 - nquiet)) of 4 pairs in the last 10 s; smallest swing ${sw%% *} rad)"
		else
			tap_fail "XM430 immobile row in lockstep: keeps colliding" "$(echo "$r" | tr '\n' ';'); smallest swing $sw"
		fi
		r=$(rows xm_mobile)
		bad=$(echo "$r" | awk '{ D = $3 < 0 ? -$3 : $3 } D > $5 + 0.1 { print $1 }' | tr '\n' ' ')
		end=$(awk -F, 'NR > 1 { t = $1 } END { print t + 1 }' "$T/xm_mobile/collision_rate.csv")
		from=$(awk "BEGIN { print $end - 10 }")
		imp_last=$(imp xm_mobile "$from" "$end"); imp_imm=$(imp xm_immobile "$from" "$end")
		if [ -z "$bad" ] && awk -v m="$imp_last" -v i="$imp_imm" 'BEGIN { exit !(i > 0 && m <= 0.2 * i) }'; then
			tap_ok "XM430 mobile row in lockstep: every pair compatible, contact $imp_last against the immobile row's $imp_imm N*s"
		else
			tap_fail "XM430 mobile row in lockstep: every pair compatible, contact at most a fifth of the immobile row's" \
				"pairs outside 2 asin(d~) + 0.1: ${bad:-none}; contact $imp_last against $imp_imm N*s"
		fi
	fi
fi
keep_runs immobile mobile mobile_b "${lock_runs[@]}"
tap_done
