#!/usr/bin/env bash
# figures/rows/fig.sh — rows of oscillators (the paper's lattices, its Figs. 6
# and 7: per-pair results against d~, Fig. 6c; relaxation against beta, 7b)
# through the real daemons in lockstep: ten single-joint robots in a row with
# fixed ends (sim-bridge/scenarios/lattice10.scenario), each joint driven by
# the oscillator's torque as on the pair rig, started on the clock at random
# phases and switched to the oscillator at 3 s.
#  - immobile (β = 0) against mobile (β = 0.1 s) bases over d̃ 0.1-1.1: at the
#    end (last 10 s), collisions per pair per second and the compatibility
#    error, how far each pair's |Δ| lies beyond 2 asin(d̃);
#  - the mobile row at d̃ = 0.78 for β from 0.1 s down to 0.002 s: the
#    relaxation time, from the switch to the last collision;
#    a run still colliding in its last 20 s is censored (relaxed later, if
#    at all).
#
#   fig.sh jobs [--quick]                 one line per run: RUN_ID DSEP BETA SECONDS SEED
#   fig.sh run OUTDIR DSEP BETA SECONDS SEED  one run: OUTDIR/result.csv (one row)
#   fig.sh merge RUNS_DIR FIGDIR          FIGDIR/rows.csv, rows.png, rows_relax.png, rows.md
#   fig.sh seconds [--quick]              wall seconds of one run on the 2-core machine
#
# The ends, as the paper's lattice has them: no walls, and the two end robots'
# bases held (`[robot NAME] beta = 0`) while the others move by world.beta; an
# immobile row is then only its pairs, and a mobile row spreads between its
# held ends (its mean d̃ cannot change). Until 2026-11-28 walls stood an
# amplitude and a quarter beyond the end robots instead, and every base moved
# (the scenarios could not hold one robot's base): the model beside it
# (figures/lattice, figures/mobility) is the paper's row. The relaxation runs at
# the paper's d̃ = 0.78 (0.7 before).
#
# Ten robots: a row of 5 runs at 9.7x real time here, 10 at 3.8x, 20 at 2.9x
# (30 s lockstep runs on this 2-core machine with other work beside them,
# 2026-11-27). Ten give nine pairs and eleven contacts (walls included) per
# run at under half the cost of twenty, whose relaxation, being the last of
# more pairs, also takes longer.
source "$(dirname "$0")/../lib.sh"
fig_init rows

SWITCH=3
WINDOW=10
# lattice10.scenario's row: ten robots, the contact 0.1865 m/rad from the
# joint, d̃ for an amplitude of 0.8 rad
ROBOTS=10
LEVER_M=0.1865
AMPLITUDE_RAD=0.8
# A run whose last collision falls in its last CENSOR_S seconds has not shown
# that it relaxed.
CENSOR_S=20
SWEEP_DSEPS="0.1 0.3 0.5 0.7 0.9 1.1"
SWEEP_BETAS="0 0.1"
SWEEP_SECONDS=60
SWEEP_SEEDS=3
RELAX_DSEP=0.78
RELAX_BETAS="0.1 0.05 0.02 0.01 0.005 0.002"
RELAX_SECONDS=240
RELAX_SEEDS=3
QUICK_SWEEP_DSEPS="0.1 0.5 0.9"
QUICK_SWEEP_SECONDS=45
QUICK_RELAX_BETAS="0.1 0.02 0.005"
QUICK_RELAX_SECONDS=120
# FIG_TINY=1 (the tests): one immobile sweep run and one relaxation run,
# each only as long as the switch and the final window need.
TINY_SWEEP_SECONDS=14
TINY_RELAX_SECONDS=16
RIG=(--daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current)
# FIG_ROWS_ARGS: more scripts/demo.sh words for every run, after the module's
# own (a later --set or --daemon-set of the same key wins), split at blanks:
# e.g. "--daemon-set robot.period_ms=5" or "--set motor.drive=pwm". Unset (the
# default, as `make figures` runs) adds nothing. For measuring what the rows
# depend on (figures/model-vs-daemons.md), not for the figure.
read -r -a ROWS_ARGS <<<"${FIG_ROWS_ARGS:-}"

jobs() {
	local d seeds=$SWEEP_SEEDS rseeds=$RELAX_SEEDS dseps=$SWEEP_DSEPS secs=$SWEEP_SECONDS
	local rbetas=$RELAX_BETAS rsecs=$RELAX_SECONDS
	if [ "${FIG_TINY:-0}" = 1 ]; then
		echo "sweep-t0 $RELAX_DSEP 0 $TINY_SWEEP_SECONDS $(fig_seed rows tiny sweep)"
		echo "relax-t0 $RELAX_DSEP 0.02 $TINY_RELAX_SECONDS $(fig_seed rows tiny relax)"
		return
	fi
	if [ "${1:-}" = --quick ]; then
		seeds=1 rseeds=1 dseps=$QUICK_SWEEP_DSEPS secs=$QUICK_SWEEP_SECONDS
		rbetas=$QUICK_RELAX_BETAS rsecs=$QUICK_RELAX_SECONDS
	fi
	for d in $dseps; do
		fig_grid "sweep-d$d-b{v}-s{i}" "$SWEEP_BETAS" "$seeds" "rows sweep $d" "$d" '{v}' "$secs" '{seed}'
	done
	fig_grid 'relax-b{v}-s{i}' "$rbetas" "$rseeds" 'rows relax' "$RELAX_DSEP" '{v}' "$rsecs" '{seed}'
}

run() {
	[ $# -eq 5 ] || fig_usage "run OUTDIR DSEP BETA SECONDS SEED"
	local out=$1 dsep=$2 beta=$3 secs=$4 seed=$5
	fig_num DSEP "$dsep" 0.01 3
	fig_num BETA "$beta" 0 1
	fig_uint SECONDS "$secs" $((SWITCH + WINDOW + 1)) 3600
	fig_uint SEED "$seed" 1 999999999
	fig_run_start "$out"
	out=$FIG_RUN
	# the ends: no walls, the end robots' bases held (see the header)
	fig_demo "$out" --scenario "$fig_top/sim-bridge/scenarios/lattice10.scenario" --seconds "$secs" \
		--switch-at "$SWITCH" --seed "$seed" --window "$WINDOW" --set "world.separation=$dsep" \
		--set "world.beta=$beta" --set "world.walls=none" --set "robot r1.beta=0" --set "robot r$ROBOTS.beta=0" \
		"${RIG[@]}" ${ROWS_ARGS[@]+"${ROWS_ARGS[@]}"} || exit 1
	local r="$out/demo" swing wall
	outdir_new "$out/pairs.csv" "$out/result.csv" || fig_die "cannot write in $out"
	fig_pairs "$r/summary.json" >"$out/pairs.csv"
	[ -s "$out/pairs.csv" ] || fig_die "the analysis has no neighbouring pairs"
	swing=$(fig_min_swing "$r/summary.json")
	# the end: pairs' collisions in the window, each pair's |Δ| beyond its bound
	local ends
	ends=$(awk -F, -v w="$WINDOW" '{
			n++; c += $6; if ($6 > 0) colliding++
			d = $3 < 0 ? -$3 : $3; e = ($11 == "nan") ? 0 : d - $11; if (e < 0) e = 0
			err += e; if (e > emax) emax = e
			if ($2 == "compatible" || $2 == "in-phase") ok++
			if ($2 == "anti-phase") anti++
			if ($2 == "not-oscillating") still++
		} END { printf "%d,%d,%.5g,%.4g,%.4g,%d,%d,%d", n, colliding, c / n / w, err / n, emax, ok, anti, still }' "$out/pairs.csv")
	# walls in the window, and the last collision of any kind after the switch
	local walls last
	walls=$(awk -F, -v a="$((secs - WINDOW))" -v w="$WINDOW" 'NR > 1 && $1 >= a { s += $5 } END { printf "%.4g", s / w }' \
		"$r/collision_rate.csv")
	last=$(awk -F, -v sw="$SWITCH" 'NR > 1 && $1 + 1 > sw && $2 > 0 { last = $1 + 1 } END { print last + 0 }' \
		"$r/collision_rate.csv")
	local relax censored
	relax=$(awk -v l="$last" -v sw="$SWITCH" 'BEGIN { r = l - sw; if (r < 0) r = 0; printf "%.0f", r }')
	censored=$(awk -v l="$last" -v s="$secs" -v c="$CENSOR_S" 'BEGIN { print (l > s - c) ? 1 : 0 }')
	wall=$(fig_wall)
	{
		echo "dsep,beta,seconds,seed,pairs,colliding_pairs,pair_collisions_hz,compat_error_rad,compat_error_max_rad,compatible_pairs,antiphase_pairs,stopped_pairs,wall_collisions_hz,relax_s,censored,min_swing_rad,wall_s"
		echo "$dsep,$beta,$secs,$seed,$ends,$walls,$relax,$censored,$swing,$wall"
	} >"$out/result.csv"
	outdir_mv "$out/pairs.csv" "$out/end_pairs.csv"
	fig_clean "$out/demo"
}

merge() {
	fig_merge_runs "$@"
	local runs=$1 fig=$FIG_OUT   # rows.csv (the runs' rows) there; all moved into FIGDIR by fig_merge_end
	local csv="$fig/rows.csv" t=$FIG_TMP
	# the sweep's runs: β in SWEEP_BETAS and a sweep's length (a relaxation
	# run at β = 0.1 is not one of them)
	awk -F, -v betas=" $SWEEP_BETAS " -v secs=" $SWEEP_SECONDS $QUICK_SWEEP_SECONDS $TINY_SWEEP_SECONDS " \
		'NR == 1 || (index(betas, " " $2 " ") && index(secs, " " $3 " "))' "$csv" >"$t/sweep-runs.csv"
	# per (d̃, β) the mean over seeds
	awk -F, 'NR > 1 { k = $1 "," $2; n[k]++; r[k] += $7; e[k] += $8; w[k] += $13 }
		END { print "dsep,beta,runs,collisions_hz,compat_error_rad,wall_collisions_hz"
			for (k in n) printf "%s,%d,%.5g,%.5g,%.5g\n", k, n[k], r[k] / n[k], e[k] / n[k], w[k] / n[k] }' "$t/sweep-runs.csv" |
		{ IFS= read -r h; echo "$h"; sort -t, -k2,2g -k1,1g; } >"$t/sweep.csv"
	fig_has "$t/sweep.csv" 1 || fig_die "no sweep runs (beta $SWEEP_BETAS, $SWEEP_SECONDS or $QUICK_SWEEP_SECONDS s) in $csv"
	sweep_plot "$fig" "$t" || fig_die "rows.png could not be drawn"
	relax_plot "$fig" "$t" || fig_die "rows_relax.png could not be drawn"
	fragment "$fig"
	fig_merge_end
}

# sweep_plot FIGDIR TMP: rows.png, collisions and the compatibility error
# against d̃, each run and the mean per d̃, immobile and mobile.
sweep_plot() {
	local fig=$1 t=$2 csv="$2/sweep-runs.csv" col ylabel what imm=() mob=()
	{
		fig_gp_head 900 800
		echo "set output '$fig/rows.png'"
		echo "set termoption noenhanced"
		echo "set multiplot layout 2,1 title 'Ten oscillators in a row, immobile (β = 0) and mobile (β = 0.1 s) bases: the last $WINDOW s'"
		# top right: the runs at small d̃ reach the top of the panel
		echo "set key top right"
		echo "set xrange [0:1.2]"
		echo "set xlabel 'd̃ (set)'"
		echo "set yrange [0:*]"
		echo "set offsets 0, 0, graph 0.08, 0"
		for col in "7;4;collisions per pair per second;mean of runs" \
			"8;5;compatibility error (rad): |Δ| beyond 2 asin(d̃);mean over pairs and runs"; do
			IFS=';' read -r col mcol ylabel what <<<"$col"
			imm=() mob=()
			fig_has "$t/sweep.csv" '$2 == 0' && imm=(
				"'$csv' every ::1 using (\$2 == 0 ? \$1 - 0.01 : 1/0):$col with points pt 7 ps 0.8 lc rgb '#d62728' notitle"
				"'$t/sweep.csv' every ::1 using (\$2 == 0 ? \$1 : 1/0):$mcol with linespoints lw 2 pt 7 lc rgb '#d62728' title 'immobile, $what'")
			fig_has "$t/sweep.csv" '$2 > 0' && mob=(
				"'$csv' every ::1 using (\$2 > 0 ? \$1 + 0.01 : 1/0):$col with points pt 5 ps 0.8 lc rgb '#1f77b4' notitle"
				"'$t/sweep.csv' every ::1 using (\$2 > 0 ? \$1 : 1/0):$mcol with linespoints lw 2 pt 5 lc rgb '#1f77b4' title 'mobile, $what'")
			echo "set ylabel '$ylabel'"
			fig_plot ${imm[@]+"${imm[@]}"} ${mob[@]+"${mob[@]}"}
		done
		echo "unset multiplot"
	} >"$t/rows.gp"
	fig_gnuplot "$t/rows.gp"
}

# rows_relax.png: relaxation time against β at d̃ = RELAX_DSEP (every mobile
# run at that d̃, the sweep's included); censored runs drawn at their bound.
# relax_median CSV BETA: the median relaxation time of the mobile runs at
# RELAX_DSEP and BETA, a censored run counted as longer than any that
# relaxed: a number, or ">L" (L its time after the switch) when the median
# run had not relaxed.
relax_median() {
	awk -F, -v d="$RELAX_DSEP" -v b="$2" -v sw="$SWITCH" 'NR > 1 && $1 == d && $2 == b {
			if ($15 == 1) print 1e12, $3 - sw; else print $14, 0 }' "$1" | sort -g |
		awk '{ v[NR] = $1; L[NR] = $2 } END {
			if (NR == 0) { print "nan"; exit }
			k = int((NR + 1) / 2)
			if (NR % 2 == 0 && v[k + 1] < 1e12) { printf "%.4g\n", (v[k] + v[k + 1]) / 2; exit }
			if (NR % 2 == 0) k++
			if (v[k] >= 1e12) printf ">%g\n", L[k]; else printf "%.4g\n", v[k] }'
}

relax_plot() {
	local fig=$1 t=$2 csv="$1/rows.csv" b med series=()
	{
		echo "beta,median_s,censored_median_s,median"
		for b in $(awk -F, -v d="$RELAX_DSEP" 'NR > 1 && $1 == d && $2 > 0 { print $2 }' "$csv" | sort -gu); do
			med=$(relax_median "$csv" "$b")
			case "$med" in ">"*) echo "$b,nan,${med#>},$med" ;; *) echo "$b,$med,nan,$med" ;; esac
		done
	} >"$t/relax.csv"
	fig_has "$t/relax.csv" 1 || { echo "rows: no mobile runs at d̃ = $RELAX_DSEP: no relaxation plot" >&2; return 0; }
	fig_series series "$csv" "\$1 == $RELAX_DSEP && \$2 > 0 && \$15 == 0" "using (\$1 == $RELAX_DSEP && \$2 > 0 && \$15 == 0 ? \$2 : 1/0):(\$14 > 0 ? \$14 : 0.5) with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'relaxed (no collision in its last $CENSOR_S s)'"
	fig_series series "$csv" "\$1 == $RELAX_DSEP && \$2 > 0 && \$15 == 1" "using (\$1 == $RELAX_DSEP && \$2 > 0 && \$15 == 1 ? \$2 : 1/0):(\$3 - $SWITCH) with points pt 9 ps 1.6 lc rgb '#d62728' title 'censored: still colliding (drawn at its run length)'"
	# (log scale: a median of 0 s, a row that never collided after the switch, cannot be drawn)
	fig_series series "$t/relax.csv" '$2 != "nan" && $2 > 0' "using 1:2 with linespoints lw 2 pt 6 ps 2 lc rgb '#1f77b4' title 'median (censored runs counted as longest)'"
	fig_series series "$t/relax.csv" '$3 != "nan"' "using 1:3 with points pt 8 ps 2.5 lw 2 lc rgb '#d62728' title 'median censored: longer than its run'"
	{
		fig_gp_head 900 600
		echo "set output '$fig/rows_relax.png'"
		echo "set termoption noenhanced"
		echo "set logscale xy"
		echo "set xlabel 'mobility β (s)'"
		echo "set ylabel 'relaxation time (s): switch to the last collision'"
		echo "set title 'Mobile row at d̃ = $RELAX_DSEP: time to the last collision'"
		echo "set key top right"
		echo "set xrange [0.0015:0.15]"
		fig_plot "${series[@]}"
	} >"$t/relax.gp"
	fig_gnuplot "$t/relax.gp"
}

fragment() {
	local fig=$1 csv="$1/rows.csv" n
	n=$(($(wc -l <"$csv") - 1))
	{
		echo "## Rows of oscillators: immobile against mobile bases (the paper's Figs. 6c and 7b)"
		echo
		echo "![Fig. 6c: collisions and compatibility error against d̃, immobile and mobile rows](figures/rows.png)"
		echo
		echo "![Fig. 7b: relaxation time against mobility](figures/rows_relax.png)"
		echo
		echo "What ran: $n lockstep runs of \`sim-bridge/scenarios/lattice10.scenario\`: ten single-joint"
		echo "robots in a row, r = 0.67, joints driven by the oscillator's torque"
		echo "(torque actuation on the simulator's current drive), random phases on the clock, the"
		echo "oscillator from $SWITCH s; the paper's ends: no walls, the two end robots' bases held (β = 0 for"
		echo "them), the others moving by β. The end is the last $WINDOW s. Compatibility error: the mean over a row's"
		echo "nine pairs of max(0, |Δ| − 2 asin(d̃)), each pair with its own d̃ as the analyser"
		echo "measures it (d̃ ≥ 1: no contact possible, error 0)."
		if awk -F, -v q="$QUICK_SWEEP_SECONDS" -v r="$QUICK_RELAX_SECONDS" 'NR > 1 && ($3 == q || $3 == r) { found = 1 } END { exit !found }' "$csv"; then
			echo "(\`make figures QUICK=1\`: d̃ = ${QUICK_SWEEP_DSEPS// /, } with one seed and ${QUICK_SWEEP_SECONDS} s runs, β = ${QUICK_RELAX_BETAS// /, } s with one"
			echo "seed and ${QUICK_RELAX_SECONDS} s runs; the full set runs d̃ = ${SWEEP_DSEPS// /, } with $SWEEP_SEEDS seeds of ${SWEEP_SECONDS} s and β ="
			echo "${RELAX_BETAS// /, } s with $RELAX_SEEDS seeds of ${RELAX_SECONDS} s.)"
		fi
		echo
		echo "| d̃ | β (s) | runs | collisions per pair per s | compatibility error (rad) | pairs colliding at the end | pairs compatible or in phase | anti-phase |"
		echo "|---|---|---|---|---|---|---|---|"
		awk -F, 'NR > 1 {
				k = $1 " " $2; n[k]++; r[k] += $7; e[k] += $8; p[k] += $5; c[k] += $6; ok[k] += $10; a[k] += $11 }
			END { for (k in n) { split(k, kk, " "); printf "%s|%s|%d|%.3g|%.3g|%d of %d|%d of %d|%d\n", kk[1], kk[2], n[k], r[k] / n[k], e[k] / n[k], c[k], p[k], ok[k], p[k], a[k] } }' "$FIG_TMP/sweep-runs.csv" |
			sort -t'|' -k1,1g -k2,2g | awk -F'|' '{ printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5, $6, $7, $8 }'
		echo
		echo "Relaxation of the mobile row at d̃ = $RELAX_DSEP (time from the switch to the oscillator until"
		echo "the last collision; censored: a collision in the run's last $CENSOR_S s):"
		echo
		echo "| β (s) | runs | relaxed | each run (s; > censored) | median (s; censored runs counted as longest) |"
		echo "|---|---|---|---|---|"
		awk -F, -v d="$RELAX_DSEP" -v sw="$SWITCH" 'NR > 1 && $1 == d && $2 > 0 { n[$2]++; if ($15 == 0) ok[$2]++; if ($3 - sw > L[$2]) L[$2] = $3 - sw }
			END { for (b in n) print b, n[b], ok[b] + 0, L[b] }' "$csv" | sort -gr |
			while read -r b n ok len; do
				each=$(awk -F, -v d="$RELAX_DSEP" -v b="$b" -v sw="$SWITCH" 'NR > 1 && $1 == d && $2 == b {
					print ($15 == 1) ? 1e9 + $3 - sw : $14 }' "$csv" | sort -g |
					awk '{ printf "%s%s", (NR > 1 ? ", " : ""), ($1 >= 1e9 ? "> " ($1 - 1e9) : $1) }')
				printf '| %s | %s | %s of %s | %s | %s |\n' "$b" "$n" "$ok" "$n" "$each" "$(relax_median "$csv" "$b" | sed 's/^>/> /')"
			done
		echo
		awk -F, 'NR > 1 { n++; if ($16 < 0.2) s++; t += $17; if ($12 > 0) st += $12 } END {
			if (s) printf "In %d run(s) a joint swung less than 0.2 rad peak-to-peak at the end (%d pair(s) not oscillating).", s, st
			else printf "Every joint of every run still swung at the end."
			printf " Wall time per run: %.0f s on average.\n", t / n }' "$csv"
		echo
		beside "$fig"
	} >"$fig/rows.md"
}

# beside FIGDIR: the paper's lattice beside these rows (after relax_plot).
beside() {
	local csv="$1/rows.csv"
	awk -F, 'NR > 1 {
			k = ($2 == 0) ? "i" : "m"; p[k, $1] += $5; c[k, $1] += $6; if (!($1 in seen)) { seen[$1] = 1; ds[++nd] = $1 }
		}
		function list(k,   i, out) {
			for (i = 1; i <= nd; i++) if ((k, ds[i]) in p) out = out sprintf("%s%s: %d of %d", out == "" ? "" : ", ", ds[i], c[k, ds[i]], p[k, ds[i]])
			return out
		}
		END {
			n = asort_num(ds, nd)
			printf "**Beside the paper.** The paper'"'"'s lattice (50 oscillators, d̃ 0.06-1.2): immobile bases keep colliding above d̃ ≈ 0.5; mobile ones always relax to compatibility. Pairs still colliding at the end, by d̃ set: immobile %s; mobile %s.", list("i"), list("m")
			for (i = 1; i <= nd; i++) if (ds[i] >= 0.5 && ds[i] < 1 && ("i", ds[i]) in p && c["i", ds[i]] * 2 < p["i", ds[i]]) low = low sprintf("%s%s", low == "" ? "" : ", ", ds[i])
			if (low != "") printf " The immobile rows disagree with the paper at d̃ = %s, where fewer than half their pairs kept colliding: part of the reason, a uniformly random phase difference is already compatible (|Δ| < 2 asin(d̃), never touching) with probability 2 asin(d̃)/π, 0.33 at d̃ = 0.5, 0.49 at 0.7, 0.71 at 0.9.", low
			for (i = 1; i <= nd; i++) if (("m", ds[i]) in p && c["m", ds[i]] * 2 > p["m", ds[i]]) {
				bad = bad sprintf("%s%s", bad == "" ? "" : ", ", ds[i]); if (ds[i] + 0 <= 0.15) crowded = 1 }
			if (bad != "") printf " The mobile rows disagree at d̃ = %s, where most pairs still collided.", bad
			if (crowded) printf " At d̃ = 0.1 a base moves β·Δv, about 0.1 s × 1 m/s = 10 cm per impact, three times the 3 cm between neighbours, which probably keeps that row from settling (not measured further)."
			printf "\n"
		}
		function asort_num(a, n,   i, j, t) { for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j - 1] + 0 > a[j] + 0; j--) { t = a[j]; a[j] = a[j - 1]; a[j - 1] = t }; return n }' "$FIG_TMP/sweep-runs.csv"
	echo
	# the medians of relax_plot's table, by β
	awk -F, -v d="$RELAX_DSEP" 'NR == 1 { next } NR == 2 { b0 = $1; t0 = $4 } { b1 = $1; t1 = $4; n++ }
		END {
			if (n < 2) { print "Relaxation against β: fewer than two values of β."; exit }
			printf "Relaxation against β (mobile row, d̃ = %s): the median time to the last collision is %s s at β = %s s and %s s at β = %s s", d, t1, b1, t0, b0
			if (t0 !~ /^>/ && t1 + 0 > 0 && t0 + 0 > 0) printf ", as β^%.2f between the two", log(t0 / t1) / log(b0 / b1)
			print " (the paper: growing steeply as β → 0). The runs of one β spread widely (the table): the time to the last collision depends on the random start, and late single grazes count."
		}' "$FIG_TMP/relax.csv"
}

# Measured 2026-11-27, two runs at a time: 18 s a run on average and 14 s
# quick with little else running; 49 s (27 s for a 60 s sweep, 94 s for a
# 240 s relaxation) and 31 s beside other work (load average 9-17).
seconds() {
	if [ "${1:-}" = --quick ]; then echo 8; else echo 11; fi
}

fig_main "jobs [--quick] | run OUTDIR DSEP BETA SECONDS SEED | merge RUNS_DIR FIGDIR | seconds [--quick]" "$@"
