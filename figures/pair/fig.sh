#!/usr/bin/env bash
# figures/pair/fig.sh — the paper's pair rig, its Figs. 5b and 5c: the
# steady phase difference of two touching oscillators against their
# separation d~, from random initial phase differences, over the theory's
# return map's fixed points (its Fig. 3b); and
# where anti-phase sets in, against the stability of the anti-phase fixed
# point |f'(pi)|, at r = 0.67 (the rig's) and r = 0.9 (where d~_c moves).
#
#   fig.sh jobs [--quick]            one line per run: RUN_ID R DSEP DELTA0 SEED SECONDS
#   fig.sh run OUTDIR R DSEP DELTA0 SEED SECONDS
#   fig.sh merge RUNS_DIR FIGDIR     pair.csv, pair.png, pair-onset.png, pair.md
#   fig.sh seconds [--quick]
#
# One run is the rig as tests/integration/e2e_pair.sh runs it, in lockstep:
# sim-bridge/scenarios/pair-rig.scenario (two single-joint robots, immobile
# bases), the joints driven by torque on the simulator's current drive,
# started in SINUSOID (0.25 rad) at phases giving DELTA0, switched to the
# oscillator at SWITCH_S, SECONDS in all; world.separation = DSEP (d~ for
# the scenario's nominal 0.8 rad), world.restitution = R. DELTA0 is the
# analyser's phase difference (right minus left, phase read clockwise):
# demo.sh's --phases are the sinusoid's, which runs the other way, so the
# right robot gets -DELTA0. (Started instead on the full sinusoid and
# switched as the clock released the bodies, figures/lib.sh's
# fig_pair_switch, the same 100 runs of the quick set agreed with the map a
# little less: 88 against 92, 2026-11-27.)
#
# FIG_TINY=1: `jobs` gives three short runs (the driver's test).
source "$(dirname "$0")/../lib.sh"
fig_init pair

SCENARIO=$FIG_PAIR_SCENARIO
RIG=("${FIG_PAIR_DRIVE[@]}" --daemon-set sinusoid.amplitude=0.25)
# The switch: as e2e_pair (the phase difference is the clock's until then).
SWITCH_S=3
# Run length. Measured on 32 runs of 90 s near d~_c (2026-11-27): the last
# collision of a pair that ends compatible or in phase came 7-44 s after the
# switch (median 13 s); one run of the 32 still grazed at 80 s. 40 s leaves
# the final 10 s window after most of them; a run still settling is counted
# apart (still-colliding, unlocked) and shown on the page.
SECONDS_RUN=40
# The runs: r = 0.67 over d~ in [0, 1]; r = 0.9 over [0, R09_DMAX] (its
# d~_c is 0.21; above 0.8 every touching pair ends in anti-phase at both r);
# controls at d~ = 2 (no contact: the free amplitude, and Delta kept), as
# the paper's rig had.
# Initial phase differences: the golden-ratio sequence (figures/lib.sh),
# spread evenly over (-pi, pi] without following d~. The quick set fits the
# figures' share of `make figures QUICK=1` (a few minutes here).
# 600 at r = 0.67: thirty runs in each 0.05 of d~ for the anti-phase
# share (the page's onset bins); 1000 (until 2026-11-29) were about 37 of
# `make figures`'s CPU-minutes, and the whole was over its hour.
FULL_067=600 FULL_090=120 FULL_CTRL=4
QUICK_067=80 QUICK_090=30 QUICK_CTRL=2
R09_DMAX=0.8
CTRL_DSEP=2
# The scenario's nominal amplitude, for which world.separation is d~: read
# by merge (set there), not by each of the 724 runs.
nominal_amp() { awk -F= '$1 ~ /^amplitude *$/ { gsub(/ /, "", $2); print $2 }' "$SCENARIO"; }

# series TAG R N DMAX: N runs at restitution R, d~ = (i + 0.5) / N * DMAX.
series() {
	local tag=$1 r=$2 n=$3 dmax=$4
	awk -v tag="$tag" -v r="$r" -v n="$n" -v dmax="$dmax" -v g="$FIG_GOLDEN" -v s="$SECONDS_RUN" 'BEGIN {
		pi = atan2(0, -1)
		for (i = 0; i < n; i++) {
			u = (i * g + 0.5) - int(i * g + 0.5)
			printf "%s-%04d %s %.4f %.4f %d %d\n", tag, i, r, (i + 0.5) / n * dmax, -pi + 2 * pi * u, 1000 + i, s
		}
	}'
}

jobs() {
	local n067=$FULL_067 n090=$FULL_090 nctl=$FULL_CTRL
	if [ "${1:-}" = --quick ]; then n067=$QUICK_067 n090=$QUICK_090 nctl=$QUICK_CTRL; fi
	if [ "${FIG_TINY:-0}" = 1 ]; then
		# the driver's test: three short runs, one per kind of line
		echo "r067-t0 0.67 0.7000 3.0000 11 14"
		echo "r090-t0 0.9 0.1000 2.0000 12 14"
		echo "ctrl-t0 0.67 $CTRL_DSEP 1.5000 13 14"
		return
	fi
	series r067 0.67 "$n067" 1
	series r090 0.9 "$n090" "$R09_DMAX"
	local i
	for i in $(seq 0 $((nctl - 1))); do
		awk -v i="$i" -v n="$nctl" -v d="$CTRL_DSEP" -v s="$SECONDS_RUN" \
			'BEGIN { printf "ctrl-%02d 0.67 %s %.4f %d %d\n", i, d, -2.5 + 5 * i / (n > 1 ? n - 1 : 1), 900 + i, s }'
	done
}

# Wall seconds of one run with four at once (2026-11-27, this 2-core machine
# with other work on it: median 5.1 s of 40 s simulated); the driver divides
# the sum by --jobs.
seconds() { echo 2.6; }

# ---- run ------------------------------------------------------------------------
RESULT_HEADER="run,r,dsep_set,delta0,seed,seconds,class,delta_final,spread,dsep_final,amp_left,amp_right,freq,collisions,window_collisions,last_collision_t,delta_first,swing_min,sim_speed,wall_s,switch_s"

# neg4 VAR X: VAR = awk's printf "%.4f" of -X (X a number fig_num took): by
# the shell for X with at most 4 decimals (every job's), else by awk.
neg4() {
	local -n _n=$1
	if [[ $2 =~ ^(-?)0*([0-9]+)(\.([0-9]{1,4}))?$ ]]; then
		local frac=${BASH_REMATCH[4]}0000 sign=-
		[ -z "${BASH_REMATCH[1]}" ] || sign=""
		_n="$sign${BASH_REMATCH[2]}.${frac:0:4}"
	else
		_n=$(awk -v d="$2" 'BEGIN { printf "%.4f", -d }')
	fi
}

run() {
	[ $# -eq 6 ] || fig_usage "run: want OUTDIR R DSEP DELTA0 SEED SECONDS, got $*"
	local out=$1 r=$2 dsep=$3 delta0=$4 seed=$5 secs=$6
	fig_num R "$r" 0 1
	fig_num DSEP "$dsep" 0 3
	fig_num DELTA0 "$delta0" -3.1416 3.1416
	fig_uint SEED "$seed" 1 999999999
	fig_uint SECONDS "$secs" $((SWITCH_S + 1)) 3600
	local t0=$EPOCHREALTIME right sw
	neg4 right "$delta0"
	sw=$SWITCH_S
	fig_demo "$out" --scenario "$SCENARIO" --seconds "$secs" --switch-at "$sw" --seed "$seed" \
		--phases "0,$right" --set "world.separation=$dsep" --set "world.restitution=$r" "${RIG[@]}" || return 1
	local d="$out/demo"
	fig_delta_trace "$d" "$out/delta_t.csv" 0.25
	local speed wall last first us
	speed=$(sed -n 's/.*(\([0-9.]*\)x real time.*/\1/;T;p;q' "$d/logs/sim.log")
	# the last collision's time and the return map's first delta: one awk
	{ IFS= read -r last; IFS= read -r first; } < <(awk -F, 'FNR == 1 { f++ }
		f == 1 && FNR > 1 { t = $2 } f == 2 && FNR == 2 { r = $5 } END { print t; print r }' \
		"$d/collisions.csv" "$d/return_map.csv")
	us=$(( (10#${EPOCHREALTIME//[!0-9]/} - 10#${t0//[!0-9]/} + 5000) / 10000 ))
	printf -v wall '%d.%02d' $((us / 100)) $((us % 100))
	outdir_new "$out/result.csv" || { echo "$FIG_NAME: $out: cannot write result.csv" >&2; return 1; }
	local name
	fig_basename name "$out"
	{
		echo "$RESULT_HEADER"
		jq -r --arg run "$name" --arg r "$r" --arg ds "$dsep" --arg d0 "$delta0" --arg seed "$seed" \
			--arg secs "$secs" --arg last "$last" --arg first "$first" --arg speed "$speed" --arg wall "$wall" --arg sw "$sw" '
			.pairs[0] as $p | [$run, $r, $ds, $d0, $seed, $secs, $p.class, $p.mean_delta, $p.spread, $p.dsep,
			 .robots[0].joints[0].amplitude_rad, .robots[1].joints[0].amplitude_rad,
			 .robots[0].joints[0].frequency_hz, $p.collisions, $p.window_collisions, $last, $first,
			 ([$p.swing_a, $p.swing_b] | min), $speed, $wall, $sw] | map(. // "" | tostring) | join(",")' "$d/summary.json"
	} >"$out/result.csv" || { echo "$FIG_NAME: $out: cannot write result.csv" >&2; return 1; }
	fig_clean "$d"
}

# ---- merge -----------------------------------------------------------------------
# The free amplitude: the median over the runs that end without contact in
# their final window (controls, compatible, in phase) of both joints' mean.
free_amplitude() {
	awk -F, 'NR > 1 && ($7 == "compatible" || $7 == "in-phase") && $15 == 0 && $11 != "" { print ($11 + $12) / 2 }' "$1" |
		sort -g | awk '{ a[NR] = $1 } END { if (NR) print (NR % 2 ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2) }'
}

merge() {
	fig_merge_args "$@"
	local runs=$1 fig=$FIG_OUT   # written here, moved into FIGDIR by fig_merge_end
	tmp=$FIG_TMP
	fig_results "$runs" >"$tmp/runs.csv"
	amp=$(free_amplitude "$tmp/runs.csv")
	[ -n "$amp" ] || fig_die "no run ended without contact: cannot measure the free amplitude"
	NOMINAL_AMP=$(nominal_amp)
	predict "$tmp" || fig_die "undulate-analyze --theory failed"
	join_runs "$tmp" >"$fig/pair.csv"
	cp "$fig/pair.csv" "$tmp/pair.csv"
	local r
	for r in $RESTITUTIONS; do derived "$tmp" "$r"; done
	plot_steady "$fig" "$tmp" || fig_die "pair.png could not be drawn"
	plot_onset "$fig" "$tmp" || fig_die "pair-onset.png could not be drawn"
	fragment "$tmp" >"$fig/pair.md" 2>"$tmp/fragment.err" && [ ! -s "$tmp/fragment.err" ] ||
		fig_die "the page's section failed: $(head -n 3 "$tmp/fragment.err")"
	fig_merge_end
}

RESTITUTIONS="0.67 0.9"

# predict TMP: for each run, where the map leads from its (d~, delta0), d~
# at the free amplitude (TMP/pred.csv: run,final,collisions), and the
# theory's curves and d~_c per restitution.
predict() {
	local t=$1 r
	: >"$t/pred.csv"
	for r in $RESTITUTIONS; do
		awk -F, -v r="$r" -v a="$amp" -v nom="$NOMINAL_AMP" 'NR > 1 && $2 == r {
			print $1 >"/dev/stderr"; printf "%.6f,%s\n", $3 * nom / a, $4 }' "$t/runs.csv" 2>"$t/ids" >"$t/in"
		fig_theory final --restitution "$r" <"$t/in" | tail -n +2 | cut -d, -f3,4 | paste -d, "$t/ids" - >>"$t/pred.csv"
		fig_theory curves --restitution "$r" --points 401 >"$t/curves-$r.csv" || return 1
		fig_theory critical --restitution "$r" | awk -F, 'NR == 2 { print $2 }' >"$t/dc-$r" || return 1
	done
}

# join_runs TMP: the runs with three columns more: d~ at the free amplitude,
# and the map's end from the run's delta0 (final delta, collisions).
join_runs() {
	awk -F, -v a="$amp" -v nom="$NOMINAL_AMP" '
		FNR == NR { pred[$1] = $2 "," $3; next }
		FNR == 1 { print $0 ",dsep,map_final,map_collisions"; next }
		{ print $0 "," sprintf("%.6f", $3 * nom / a) "," ($1 in pred ? pred[$1] : ",") }' "$1/pred.csv" "$1/runs.csv"
}

# Columns of pair.csv used below.
C_R=2 C_D0=4 C_CLASS=7 C_DELTA=8 C_WCOLL=15 C_DSEP=22 C_MAP=23
# A run the map leads to anti-phase: within this of pi.
MAP_ANTI_EPS=1e-6
# Bins of d~ for the share of runs that end in anti-phase.
BIN=0.05

# derived TMP R: TMP/cum-{m,p}-R.csv, the d~ of each run that ended in
# anti-phase (m: measured; p: where the map leads from its delta0), sorted,
# with the share of all such runs at or below it; and TMP/bins-R.csv (bin
# centre, runs, the share ending in anti-phase: measured, by the map).
derived() {
	local t=$1 r=$2 k
	awk -F, -v r="$r" -v c="$C_CLASS" -v d="$C_DSEP" -v m="$C_MAP" -v eps="$MAP_ANTI_EPS" -v rr="$C_R" '
		NR > 1 && $rr == r && $d <= 1 {
			if ($c == "anti-phase") print $d >"/dev/stderr"
			if ($m != "" && 3.141592653589793 - ($m < 0 ? -$m : $m) < eps) print $d }' \
		"$t/pair.csv" 2>"$t/anti-m" >"$t/anti-p"
	for k in m p; do
		sort -g "$t/anti-$k" | awk -v n="$(wc -l <"$t/anti-$k")" 'BEGIN { print "dsep,share" } { printf "%s,%.5f\n", $1, NR / n }' \
			>"$t/cum-$k-$r.csv"
	done
	awk -F, -v r="$r" -v c="$C_CLASS" -v d="$C_DSEP" -v m="$C_MAP" -v eps="$MAP_ANTI_EPS" -v rr="$C_R" -v w="$BIN" '
		NR > 1 && $rr == r && $d <= 1 { b = int($d / w); n[b]++; if (b > top) top = b
			if ($c == "anti-phase") a[b]++
			if ($m != "" && 3.141592653589793 - ($m < 0 ? -$m : $m) < eps) p[b]++ }
		END { print "dsep,runs,measured,map"
			for (b = 0; b <= top; b++) if (n[b]) printf "%.3f,%d,%.4f,%.4f\n", (b + 0.5) * w, n[b], a[b] / n[b], p[b] / n[b] }' \
		"$t/pair.csv" >"$t/bins-$r.csv"
}

# Colours: the runs by their end state; the theory's anti-phase line light,
# so that the runs locked at pi show on it.
COL_ANTI='#a50f15' COL_COMPAT='#1f77b4' COL_INPHASE='#2ca02c' COL_COLL='#ff7f0e' COL_OTHER='#7f7f7f'
COL_PI='#f4a6a6'
# Per restitution: the runs' colour, and a lighter one for the theory's lines
# (the measured series can then be told from the theory's by colour alone:
# tests/integration/figures_driver.sh counts them).
rcolor() { case $1 in 0.67) echo '#1f77b4' ;; *) echo '#d62728' ;; esac; }
rlight() { case $1 in 0.67) echo '#6baed6' ;; *) echo '#fc9272' ;; esac; }

# gp_class R CLASS_TEST: a plot's `using` for pair.csv's runs at R whose
# class passes CLASS_TEST (a gnuplot expression of c(0), the class).
gp_class() {
	echo "using ((\$$C_R == $1 && ($2)) ? \$$C_DSEP : 1/0):(abs(\$$C_DELTA))"
}

# plot_steady FIG TMP: pair.png (the paper's Fig. 5b): |delta| at the end against d~,
# one point per run coloured by its end state, over the theory's fixed
# points: the compatible set (shaded, bounded by 2 asin(d~)), anti-phase pi
# (solid where stable), the third fixed point (dashed: the basins' boundary).
plot_steady() {
	local fig=$1 t=$2 r n dc
	{
		fig_gp_head 1400 800
		echo "set encoding utf8"
		echo "set output '$fig/pair.png'"
		echo "set multiplot layout 1,2 title 'Pair rig: the phase difference at the end of each run, from random Δ₀, over the return map of theory.md'"
		echo "set xrange [0:1]"
		echo "set yrange [0:3.4]"
		echo "set xlabel 'd̃ (separation / twice the free amplitude)'"
		echo "set ylabel '|Δ| over the last 10 s (rad)'"
		echo "set ytics ('0' 0, 'π/4' pi/4, 'π/2' pi/2, '3π/4' 3*pi/4, 'π' pi)"
		echo "set key outside below maxrows 4 font ',9' width -2"
		echo "c(s) = strcol($C_CLASS)"
		for r in $RESTITUTIONS; do
			n=$(awk -F, -v r="$r" -v d="$C_DSEP" 'NR > 1 && $2 == r && $d <= 1' "$t/pair.csv" | wc -l)
			dc=$(cat "$t/dc-$r")
			echo "set title sprintf('r = $r: %d runs; d̃_c = %.3f (dotted)', $n, $dc)"
			echo "unset arrow"
			echo "set arrow from $dc, graph 0 to $dc, graph 1 nohead dt 3 lw 1.5 lc rgb '#555555'"
			echo "C = '$t/curves-$r.csv'"
			echo "P = '$t/pair.csv'"
			echo "plot C using 1:(0):2 with filledcurves lc rgb '#dde8f5' title 'compatible set: |Δ| < 2 asin(d̃)', \\"
			echo "  C using 1:2 with lines lw 2 lc rgb 'black' title '2 asin(d̃)', \\"
			echo "  C using 1:(\$5 == 1 ? pi : 1/0) with lines lw 5 lc rgb '$COL_PI' title 'anti-phase π: stable', \\"
			echo "  C using 1:(\$5 == 0 ? pi : 1/0) with lines lw 2 dt 2 lc rgb '$COL_PI' title 'π: unstable', \\"
			echo "  C using 1:6 with lines lw 2 dt 2 lc rgb '#444444' title 'third fixed point (basins'' boundary)', \\"
			echo "  P $(gp_class "$r" "c(0) eq 'anti-phase'") with points pt 7 ps 0.5 lc rgb '$COL_ANTI' title 'run: anti-phase', \\"
			echo "  P $(gp_class "$r" "c(0) eq 'compatible'") with points pt 7 ps 0.5 lc rgb '$COL_COMPAT' title 'run: compatible', \\"
			echo "  P $(gp_class "$r" "c(0) eq 'in-phase'") with points pt 7 ps 0.5 lc rgb '$COL_INPHASE' title 'run: in phase', \\"
			echo "  P $(gp_class "$r" "c(0) eq 'still-colliding' || c(0) eq 'grazing'") with points pt 6 ps 0.7 lc rgb '$COL_COLL' title 'run: still touching (colliding or grazing)', \\"
			echo "  P $(gp_class "$r" "c(0) ne 'anti-phase' && c(0) ne 'compatible' && c(0) ne 'in-phase' && c(0) ne 'still-colliding' && c(0) ne 'grazing'") with points pt 2 ps 0.8 lc rgb '$COL_OTHER' title 'run: other (unlocked ...)'"
		done
		echo "unset multiplot"
	} >"$t/steady.gp"
	fig_gnuplot "$t/steady.gp"
}

# plot_onset FIG TMP: pair-onset.png (the paper's Fig. 5c): |f'(pi)| against d~ (anti-
# phase stable below 1), the cumulative share of the runs that ended in
# anti-phase, and per bin of d~ the share of runs that did, measured and
# where the map leads from each run's delta0.
plot_onset() {
	local fig=$1 t=$2 r color sep
	{
		fig_gp_head 1000 1200
		echo "set encoding utf8"
		echo "set output '$fig/pair-onset.png'"
		echo "set multiplot layout 3,1 title 'Pair rig: where anti-phase sets in, against the stability of π (dotted: d̃_c)'"
		echo "set xrange [0:1]"
		echo "set key top left font ',9'"
		for r in $RESTITUTIONS; do
			echo "set arrow from $(cat "$t/dc-$r"), graph 0 to $(cat "$t/dc-$r"), graph 1 nohead dt 3 lw 1.5 lc rgb '$(rlight "$r")'"
		done
		echo "set ylabel \"|f′(π)|\""
		echo "set yrange [0:1.6]"
		echo "set title \"the return map's slope at anti-phase: π is stable where it is below 1\""
		printf "plot 1 with lines lc rgb '#999999' dt 2 notitle"
		for r in $RESTITUTIONS; do printf ", '%s' using 1:4 with lines lw 2 lc rgb '%s' title 'r = %s'" "$t/curves-$r.csv" "$(rlight "$r")" "$r"; done
		echo
		echo "set ylabel 'share of the anti-phase runs'"
		echo "set yrange [0:1.05]"
		echo "set title 'cumulative: the runs that ended in anti-phase at or below d̃ (solid: measured; dashed: where the map leads from their Δ₀)'"
		printf "plot"
		sep=" "
		for r in $RESTITUTIONS; do
			# a series without a run (no anti-phase at this r) is left out:
			# gnuplot would draw nothing and say so
			if [ "$(wc -l <"$t/cum-m-$r.csv")" -gt 1 ]; then
				printf "%s'%s' using 1:2 with steps lw 2 lc rgb '%s' title 'r = %s, runs'" "$sep" "$t/cum-m-$r.csv" "$(rcolor "$r")" "$r"
				sep=", "
			fi
			if [ "$(wc -l <"$t/cum-p-$r.csv")" -gt 1 ]; then
				printf "%s'%s' using 1:2 with steps lw 2 dt 2 lc rgb '%s' title 'r = %s, map'" "$sep" "$t/cum-p-$r.csv" "$(rlight "$r")" "$r"
				sep=", "
			fi
		done
		[ "$sep" = ", " ] || printf " NaN notitle"
		echo
		echo "set ylabel 'share ending in anti-phase'"
		echo "set xlabel 'd̃ (separation / twice the free amplitude)'"
		echo "set title 'per bin of d̃ ($BIN wide): the runs that ended in anti-phase (points: measured; dashed: the map from their Δ₀)'"
		printf "plot"
		sep=" "
		for r in $RESTITUTIONS; do
			[ "$(wc -l <"$t/bins-$r.csv")" -gt 1 ] || continue
			printf "%s'%s' using 1:3 with linespoints pt 7 ps 0.8 lw 2 lc rgb '%s' title 'r = %s, runs'" "$sep" "$t/bins-$r.csv" "$(rcolor "$r")" "$r"
			printf ", '%s' using 1:4 with lines lw 2 dt 2 lc rgb '%s' title 'r = %s, map'" "$t/bins-$r.csv" "$(rlight "$r")" "$r"
			sep=", "
		done
		[ "$sep" = ", " ] || printf " NaN notitle"
		echo
		echo "unset multiplot"
	} >"$t/onset.gp"
	fig_gnuplot "$t/onset.gp"
}

# stats TMP R: "key value" lines of the runs at R with d~ <= 1 (see fragment).
stats() {
	local t=$1 r=$2
	awk -F, -v r="$r" -v c="$C_CLASS" -v ds="$C_DSEP" -v m="$C_MAP" -v D="$C_DELTA" -v eps="$MAP_ANTI_EPS" -v dc="$(cat "$t/dc-$r")" '
		function abs(x) { return x < 0 ? -x : x }
		NR > 1 && $2 == r && $ds <= 1 {
			n++; k[$c]++; d = $ds
			anti = $c == "anti-phase"; pa = $m != "" && 3.141592653589793 - abs($m) < eps
			if (anti && (mina == "" || d < mina)) mina = d
			if (pa && (minp == "" || d < minp)) minp = d
			if (anti == pa) agree++
			if (pa) { npa++; if (anti) paa++ } else { npc++; if (anti) pca++ }
			if ($c == "compatible" || $c == "in-phase") { nc++; if (abs($D) <= 2 * atan2(d, sqrt(1 - d * d)) + 0.1) within++ }
			if ($c != "anti-phase" && $c != "compatible" && $c != "in-phase") {
				ns++; if (lo == "" || d < lo) lo = d; if (hi == "" || d > hi) hi = d
				if (d < 1 && abs(abs($D) - 2 * atan2(d, sqrt(1 - d * d))) < 0.15) graze++ }
			if (anti) { na++; amp += ($11 + $12) / 2; if (d < dc) below++ }
		}
		END {
			printf "n %d\nin-phase %d\ncompatible %d\nanti-phase %d\nstill-colliding %d\n", n, k["in-phase"], k["compatible"], k["anti-phase"], k["still-colliding"] + k["grazing"]
			printf "other %d\nmin_anti %s\nmin_map %s\nagree %d\n", n - k["in-phase"] - k["compatible"] - k["anti-phase"] - k["still-colliding"] - k["grazing"], mina == "" ? "-" : sprintf("%.3f", mina), minp == "" ? "-" : sprintf("%.3f", minp), agree
			printf "map_anti %d\nmap_anti_ended %d\nmap_compat %d\nmap_compat_anti %d\n", npa, paa, npc, pca
			printf "nocontact %d\nwithin %d\nunsettled %d\nunsettled_range %s\n", nc, within, ns, ns ? sprintf("%.2f-%.2f", lo, hi) : "-"
			printf "anti_amp %s\nanti_below_dc %d\ngrazing %d\n", na ? sprintf("%.2f", amp / na) : "-", below, graze
		}' "$t/pair.csv"
	# the bins from d~_c on: "from-to measured % / map %", for the page
	awk -F, -v dc="$(cat "$t/dc-$r")" -v w="$BIN" 'NR > 1 && $1 + w / 2 > dc && k < 4 {
		printf "%s%.2f–%.2f: %.0f %% / %.0f %%", k++ ? "; " : "onset_bins ", $1 - w / 2, $1 + w / 2, 100 * $3, 100 * $4 }
		END { print k ? "" : "onset_bins -" }' "$t/bins-$r.csv"
	# the first bin of d~ in which at least a tenth of the runs ended in anti-phase
	awk -F, -v w="$BIN" 'NR > 1 && $3 >= 0.1 { printf "onset_bin %.2f-%.2f\n", $1 - w / 2, $1 + w / 2; f = 1; exit }
		END { if (!f) print "onset_bin -" }' "$t/bins-$r.csv"
}

# fragment TMP: pair.md, the page's section: the pictures, what ran, the
# numbers beside the paper's and the theory's, and where they disagree.
fragment() {
	local t=$1 r
	for r in $RESTITUTIONS; do stats "$t" "$r" >"$t/stats-$r"; done
	local a=$t/stats-0.67 b=$t/stats-0.9
	v() { awk -v k="$2" '$1 == k { $1 = ""; sub(/^ /, ""); print }' "$1"; }
	pc() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.0f %%", 100 * a / b; else printf "-" }'; }
	frac() { awk -v a="$1" -v b="$2" 'BEGIN { print (b > 0 ? a / b : 0) }'; }
	row() { printf '| %s | %s | %s |\n' "$1" "$2" "$3"; }
	# third R D: the third fixed point at d~ = D (the curves' nearest sample)
	third() { awk -F, -v d="$2" 'NR > 1 { e = $1 - d; e = e < 0 ? -e : e; if (!n++ || e < best) { best = e; x = $6 } }
		END { printf "%s", x == "" ? "none" : sprintf("%.2f", x) }' "$t/curves-$1.csv"; }
	median() { sort -g | awk '{ a[NR] = $1 } END { if (NR) printf "%.1f", a[int((NR + 1) / 2)] }'; }
	local ctrl wall speed secs nall dca dcb
	nall=$(($(wc -l <"$t/pair.csv") - 1))
	dca=$(printf '%.3f' "$(cat "$t/dc-0.67")") dcb=$(printf '%.3f' "$(cat "$t/dc-0.9")")
	# the controls are the ctrl- runs (jobs), not the runs whose d~ reads
	# above 1: a series' last runs, set just below 1, read just above it at
	# the free amplitude
	ctrl=$(awk -F, -v ds="$C_DSEP" 'function abs(x) { return x < 0 ? -x : x }
		NR > 1 && $1 ~ /^ctrl-/ { n++; e = $8 - $4; while (e > 3.14159265) e -= 6.2831853; while (e < -3.14159265) e += 6.2831853
			if (abs(e) > worst) worst = abs(e); c += $14; amp += ($11 + $12) / 2; f += $13
			if (n == 1 || $3 < lo) lo = $3; if (n == 1 || $3 > hi) hi = $3; if (n == 1 || $ds < dlo) dlo = $ds; if (n == 1 || $ds > dhi) dhi = $ds }
		function range(a, b, f) { return a == b ? sprintf(f, a) : sprintf(f "–" f, a, b) }
		END { if (n) printf "%d run%s at d̃ = %s as set (%s at the free amplitude): %d collisions, the phase difference kept within %.2f rad of its start, amplitude %.3f rad at %.3f Hz",
			n, (n > 1 ? "s" : ""), range(lo + 0, hi + 0, "%g"), range(dlo, dhi, "%.3f"), c, worst, amp / n, f / n
		      else printf "none in this set" }' "$t/pair.csv")
	# the series' runs the table leaves out: d~ above 1 at the free amplitude
	local beyond
	beyond=$(awk -F, -v ds="$C_DSEP" 'NR > 1 && $1 !~ /^ctrl-/ && $ds > 1 { n++; c += $14
			if (n == 1 || $3 < lo) lo = $3; if (n == 1 || $3 > hi) hi = $3; if (n == 1 || $ds < dlo) dlo = $ds; if (n == 1 || $ds > dhi) dhi = $ds }
		END { if (n) printf " The table counts the runs at d̃ ≤ 1 at the free amplitude: %d run%s of the series, set at d̃ = %g–%g, read %.3f–%.3f and %s left out (%d collisions).",
			n, (n > 1 ? "s" : ""), lo, hi, dlo, dhi, (n > 1 ? "are" : "is"), c }' "$t/pair.csv")
	wall=$(awk -F, 'NR > 1 { print $20 }' "$t/pair.csv" | median)
	speed=$(awk -F, 'NR > 1 && $19 != "" { print $19 }' "$t/pair.csv" | median)
	secs=$(awk -F, 'NR == 2 { print $6 }' "$t/pair.csv")
	cat <<EOF
## Pair rig: the steady state against d̃ (the paper's Fig. 5b), where anti-phase sets in (Fig. 5c)

![Fig. 5b: |Δ| at the end of each run against d̃, over the return map's fixed points (Fig. 3b)](figures/pair.png)

**What ran.** $nall runs of the paper's pair rig as \`e2e_pair\` runs it
(\`sim-bridge/scenarios/pair-rig.scenario\`: two single-joint robots on immobile bases, the
joints driven by torque on the simulator's current drive), $secs s of simulated time each:
SINUSOID (0.25 rad) at the phases that give Δ₀, switched to the oscillator at $SWITCH_S s; the
end state is \`undulate-analyze\`'s over the last 10 s. Δ₀ spreads evenly over (−π, π] (a
golden-ratio sequence), d̃ evenly over [0, 1] at r = 0.67 and over [0, $R09_DMAX] at r = 0.9.
(Started on the full 0.8 rad sinusoid instead and switched as the clock released the bodies,
the 100 runs of the quick set at r = 0.67 agreed with the map in 88 cases against 92 this
way, 2026-11-27.) A run took
$wall s of wall time (median, with the invocation's other runs beside it: the table at the top of the page says how many at once; $speed× real time in lockstep). d̃ is the
separation over twice the *free* amplitude, A = $(printf '%.3f' "$amp") rad (the median of the runs that
ended without contact); in anti-phase the swing shrinks (to $(v "$a" anti_amp) rad at r = 0.67),
so the analyser's final-window d̃ reads higher there (\`dsep_final\` in pair.csv). Controls, as
the paper's: $ctrl.$beyond

| | r = 0.67 | r = 0.9 |
|---|---|---|
EOF
	row "runs (d̃ ≤ 1)" "$(v "$a" n)" "$(v "$b" n)"
	row "ended in phase / compatible / anti-phase" "$(v "$a" in-phase) / $(v "$a" compatible) / $(v "$a" anti-phase)" "$(v "$b" in-phase) / $(v "$b" compatible) / $(v "$b" anti-phase)"
	row "still colliding or unlocked at the end (their d̃); of them grazing at \\|Δ\\| = 2·asin(d̃) ± 0.15" "$(v "$a" unsettled) ($(v "$a" unsettled_range)); $(v "$a" grazing)" "$(v "$b" unsettled) ($(v "$b" unsettled_range)); $(v "$b" grazing)"
	row "d̃_c, theory (\\|f′(π)\\| = 1)" "$dca" "$dcb"
	row "first run that ended in anti-phase, at d̃" "$(v "$a" min_anti)" "$(v "$b" min_anti)"
	row "first bin (0.05 wide) with ≥ 10 % of its runs in anti-phase" "$(v "$a" onset_bin)" "$(v "$b" onset_bin)"
	row "the map from the runs' Δ₀: first anti-phase at d̃" "$(v "$a" min_map)" "$(v "$b" min_map)"
	row "runs that ended where the map leads (anti-phase or not)" "$(pc "$(v "$a" agree)" "$(v "$a" n)")" "$(pc "$(v "$b" agree)" "$(v "$b" n)")"
	row "of the runs the map leads to anti-phase: ended there" "$(v "$a" map_anti_ended) of $(v "$a" map_anti) ($(pc "$(v "$a" map_anti_ended)" "$(v "$a" map_anti)"))" "$(v "$b" map_anti_ended) of $(v "$b" map_anti) ($(pc "$(v "$b" map_anti_ended)" "$(v "$b" map_anti)"))"
	row "of the runs the map leads to the compatible set: ended in anti-phase" "$(v "$a" map_compat_anti) of $(v "$a" map_compat)" "$(v "$b" map_compat_anti) of $(v "$b" map_compat)"
	row "ended in phase or compatible: \\|Δ\\| ≤ 2·asin(d̃) + 0.1" "$(v "$a" within) of $(v "$a" nocontact)" "$(v "$b" within) of $(v "$b" nocontact)"
	local basin
	basin=$(awk -v a="$(frac "$(v "$a" map_anti_ended)" "$(v "$a" map_anti)")" 'BEGIN {
		if (a >= 0.9) print "about the map'"'"'s: the runs it leads to anti-phase end there"
		else if (a >= 0.6) print "somewhat smaller than the map'"'"'s"
		else print "smaller than the map'"'"'s" }')
	cat <<EOF

**Beside the paper.** The paper ran 1312 pair-rig runs over d̃ ∈ [0, 1] (r = 0.67 ± 0.02)
plus controls at d̃ = 2: in phase at d̃ = 0, compatible at d̃ ≈ 0.3, anti-phase at d̃ ≈ 0.6
("violent, stable for hours"), anti-phase appearing where the theory's stability changes,
d̃_c = 0.316. Here the first run that ended in anti-phase is at d̃ = $(v "$a" min_anti) (r = 0.67)
and $(v "$b" min_anti) (r = 0.9) against d̃_c = $dca and $dcb; a tenth of the runs of a bin end in
anti-phase from d̃ = $(v "$a" onset_bin) and $(v "$b" onset_bin). Earlier sweeps here from Δ₀ = π
put the onset between 0.30 and 0.40 at r = 0.67 (docs/EXPERIMENTS.md). Most runs that ended
neither in phase, compatible nor anti-phase graze at the compatibility limit (the orange
circles on 2·asin(d̃)): the limit is a fixed point of the map, and a pair that reaches it
from above touches now and then, so the analyser counts it as still colliding.

![Fig. 5c: |f′(π)|, the cumulative share of anti-phase runs, and the share per bin, against d̃](figures/pair-onset.png)

**Where the runs and the map disagree.** The map (theory.md) is for two phase oscillators of
fixed amplitude; from a run's d̃ and Δ₀ it says where the pair ends (\`undulate-analyze
--theory final\`). Of the runs it leads to anti-phase, $(pc "$(v "$a" map_anti_ended)" "$(v "$a" map_anti)")
ended there at r = 0.67 and $(pc "$(v "$b" map_anti_ended)" "$(v "$b" map_anti)") at r = 0.9: the runs'
basin of anti-phase is $basin (the lower panels: measured against dashed). Near d̃_c the
map's basin is a sliver next to π (the third fixed point, its edge, is at
$(third 0.67 0.35) rad for d̃ = 0.35 and $(third 0.67 0.40) for 0.40). The share of the runs that
ended in anti-phase in the first bins from d̃_c, measured / the map's: at r = 0.67,
$(v "$a" onset_bins); at r = 0.9, $(v "$b" onset_bins). The daemons'
oscillators are not phase oscillators: a collision takes amplitude as well as phase (the
anti-phase swing settles at $(v "$a" anti_amp) rad instead of $(printf '%.2f' "$amp")), and the amplitude
comes back over a cycle, so the next collision is not the map's. Below d̃_c, where the map
has no stable anti-phase, $(v "$a" anti_below_dc) runs at r = 0.67 and $(v "$b" anti_below_dc) at r = 0.9 were
still at π after $secs s: where |f′(π)| is close to 1 a pair started near π leaves it slowly
(its distance from π grows by |f′(π)| per collision: 1.09 at r = 0.9 and d̃ = 0.1), and the
run ends first; they set the first anti-phase bins at r = 0.9 below d̃_c. Runs still
colliding or unlocked at the end are counted apart; the numbers of every run (Δ₀, d̃, the
end state, the map's end) are in [figures/pair.csv](figures/pair.csv).
EOF
}

# ---- dispatch -------------------------------------------------------------------------
case "${1:-}" in
jobs|run|merge|seconds) cmd=$1; shift; "$cmd" "$@" ;;
*) echo "usage: $(basename "$0") jobs [--quick] | run OUTDIR R DSEP DELTA0 SEED SECONDS | merge RUNS_DIR FIGDIR | seconds" >&2; exit 2 ;;
esac
