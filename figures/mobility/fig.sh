#!/usr/bin/env bash
# figures/mobility/fig.sh — the paper's Figs. 7a and 7b from its own model: a
# row of 50 phase oscillators on mobile bases (at each of its impacts a base
# moves by β(ẋ_other − ẋ_self), the end oscillators held: β = 0 for them, no
# walls), started at d̃ = 0.78 from random phases, integrated by
# undulate-model (model/README.md), no daemons.
#  - 7a: the drift: the d̃ of the pairs that collide, over time, rising as each
#    impact pushes its pair apart, and the spread of the row's d̃. The row's
#    mean d̃ cannot move (its ends are held: the gaps add up to the distance
#    between them), so the drift is the colliding pairs' at the expense of
#    the others';
#  - 7b: t_relax (the time of the last collision) against β over three
#    decades, every seed drawn, with the daemons' mobile rows (figures/rows,
#    ten robots at d̃ 0.78) over it, and below the decades two β at which
#    the row never relaxes in its run (censored).
#
#   fig.sh jobs [--quick]                 one line per run: RUN_ID BETA SECONDS SEED DRIFT
#   fig.sh run OUTDIR BETA SECONDS SEED DRIFT
#   fig.sh merge RUNS_DIR FIGDIR          mobility.csv, mobility.png (7b), mobility-drift.png (7a), mobility.md
#   fig.sh seconds [--quick]
#
# A run's rows (result.csv, one header for both kinds):
#   run    one: collisions, t_relax_s (empty: censored, still colliding in
#          the last 10 s), last_collision_s; the row's d̃ at the end (mean,
#          sd, least, greatest), the pairs then beyond their compatibility
#          limit 2 asin(d̃) and colliding; with DRIFT 1 also neutral_error,
#          how far the bases rebuilt from collisions.csv end from the
#          model's own (the mobility's books)
#   drift  (DRIFT 1) one a time bin (log-spaced, 8 a decade from 0.1 s, t its
#          end): collisions in it, the mean d̃ of the pairs at them (just
#          before each impact), and the row's d̃ at the bin's end (mean, sd,
#          least, greatest)
#
# FIG_TINY=1: `jobs` gives two short runs (the driver's test).
source "$(dirname "$0")/../lib.sh"
fig_init mobility

OSCILLATORS=50
DSEP=0.78
AMPLITUDE=0.8   # undulate-model's default A: d̃ = gap / 2A
WINDOW=10
# three decades, 0.007-7 s, ten values evenly spaced in log β (0.007·10^(k/3))
BETAS="0.007 0.0151 0.0325 0.07 0.151 0.325 0.7 1.51 3.25 7"
SEEDS=10
# below the decades: the row settles into a steady colliding state (about 18
# collisions a second, 2026-11-28: none of 4 seeds relaxed in 30 000 s at
# 0.003 or 0.001 s, 3 of 6 in 20 000 s at 0.005 s)
STUCK_BETAS="0.005 0.003"
STUCK_SEEDS=5
STUCK_SECONDS=20000
# the β whose runs (seeds 1-3) give 7a
DRIFT_BETAS="0.007 0.0151 0.0325 0.07"
DRIFT_SEEDS=3
QUICK_BETAS="0.0151 0.07 0.7"
QUICK_SEEDS=2

# run_seconds BETA: long enough that every seed relaxes well before the end
# (t_relax measured 2026-11-28 over 4-10 seeds: 270-3400 s at 0.007 s, 74-155 s
# at 0.01 s, 7-12 s at 0.02 s, under 6 s from 0.05 s); a run's cost grows with
# its length even after it relaxed (the integrator's steps are at most an
# eighth of a period: 40 000 s take 7 s)
run_seconds() {
	awk -v b="$1" 'BEGIN { print (b >= 0.05) ? 200 : (b >= 0.02) ? 600 : (b >= 0.01) ? 3000 : 40000 }'
}

jobs() {
	local b i secs betas=$BETAS seeds=$SEEDS drift
	if [ "${FIG_TINY:-0}" = 1 ]; then
		echo "b0.07-s1 0.07 60 1 1"
		echo "b0.7-s1 0.7 60 1 0"
		return
	fi
	[ "${1:-}" = --quick ] && betas=$QUICK_BETAS seeds=$QUICK_SEEDS
	for b in $betas; do
		secs=$(run_seconds "$b")
		for ((i = 1; i <= seeds; i++)); do
			drift=0
			if [ "${1:-}" = --quick ]; then [ "$i" = 1 ] && [ "$b" != 0.7 ] && drift=1
			elif [[ " $DRIFT_BETAS " == *" $b "* ]] && [ "$i" -le "$DRIFT_SEEDS" ]; then drift=1; fi
			echo "b$b-s$i $b $secs $i $drift"
		done
	done
	[ "${1:-}" = --quick ] && return
	for b in $STUCK_BETAS; do
		for ((i = 1; i <= STUCK_SEEDS; i++)); do echo "b$b-s$i $b $STUCK_SECONDS $i 0"; done
	done
}

# Wall seconds of one run (2026-11-28, load 5-6): 0.3 s of the model for
# 200 s, 7-15 s for 40 000 s, 8 s for 20 000 s still colliding; the full set
# niced at load 9-22, two at once: 12.4 s a run on average (173 s of the
# model's CPU in all); the quick set 2-3 s a run
seconds() { [ "${1:-}" = --quick ] && echo 3 || echo 8; }

RESULT_HEADER="kind,dsep,beta,seed,seconds,t,collisions,mean_dsep_colliding,dsep_mean,dsep_sd,dsep_min,dsep_max,incompatible_pairs,colliding_pairs,t_relax_s,last_collision_s,neutral_error,dsep_min_run"

run() {
	[ $# -eq 5 ] || fig_usage "run: want OUTDIR BETA SECONDS SEED DRIFT, got $*"
	local out=$1 b=$2 secs=$3 seed=$4 drift=$5 m
	fig_num BETA "$b" 0 100
	fig_uint SECONDS "$secs" $((WINDOW + 10)) 100000
	fig_uint SEED "$seed" 1 999999999
	fig_uint DRIFT "$drift" 0 1
	fig_run_start "$out"
	out=$FIG_RUN m="$out/model"
	outdir_new "$out/model.log" "$out/result.csv" || { echo "$FIG_NAME: cannot write in $out" >&2; return 1; }
	"$FIG_BIN/undulate-model" lattice --n "$OSCILLATORS" --dsep "$DSEP" --beta "$b" --fixed-ends --seed "$seed" \
		--duration "$secs" --window "$WINDOW" --no-samples --quiet --out "$m" >"$out/model.log" 2>&1 ||
		{ echo "$FIG_NAME: $out: undulate-model lattice failed: $(tail -n 1 "$out/model.log")" >&2; return 1; }
	local pre="$DSEP,$b,$seed,$secs" tr lc n ends err=""
	tr=$(fig_json "$m" '.model.t_relax_s // ""') lc=$(fig_json "$m" '.model.last_collision_s // ""') n=$(fig_json "$m" .collisions)
	# the row at the end: each pair's d̃ and whether its |Δ| is beyond its limit
	ends=$(fig_pairs "$m/summary.json" | awk -F, '{ k++; d = $10; s += d; q += d * d; if (k == 1 || d < lo) lo = d; if (k == 1 || d > hi) hi = d
			if ($11 != "nan" && $4 > $11 + 0.01) bad++; if ($6 > 0) c++ }
		END { m = s / k; v = q / k - m * m; printf "%.6f,%.6f,%.6f,%.6f,%d,%d", m, sqrt(v > 0 ? v : 0), lo, hi, bad, c }')
	{
		echo "$RESULT_HEADER"
		drift_rows "$m" "$b" "$pre" "$secs" "$out/err" "$drift"
		err=$(cat "$out/err")
		echo "run,$pre,,$n,,$ends,$tr,$lc,$err"
	} >"$out/result.csv"
	rm -f "$out/err"
	fig_clean "$m"
}

# drift_rows MODEL BETA PRE SECONDS ERRFILE DRIFT: the bases rebuilt impact
# by impact from collisions.csv (each moves by β(v_other − v_self), the
# speeds before the impact; the ends never), the drift rows per time bin when
# DRIFT is 1, and into ERRFILE "E,M": how far the rebuilt bases end from
# summary.json's neutral_final, and the least d̃ of any pair after any impact
# (below 0: two bases passed each other, which the model does not forbid).
drift_rows() {
	local m=$1 b=$2 pre=$3 secs=$4
	local final
	final=$(fig_json "$m" '.model.neutral_final | map(tostring) | join(" ")')
	awk -F, -v b="$b" -v n="$OSCILLATORS" -v d="$DSEP" -v a="$AMPLITUDE" -v pre="$pre" -v secs="$secs" \
		-v final="$final" -v errfile="$5" -v drift="$6" '
		function gap(k) { return (x[k + 1] - x[k]) / (2 * a) }
		function stats(   k, g, s, q, lo, hi, mm, v) {
			for (k = 0; k < n - 1; k++) { g = gap(k); s += g; q += g * g; if (k == 0 || g < lo) lo = g; if (k == 0 || g > hi) hi = g }
			mm = s / (n - 1); v = q / (n - 1) - mm * mm
			return sprintf("%.6f,%.6f,%.6f,%.6f", mm, sqrt(v > 0 ? v : 0), lo, hi) }
		function flush() {
			if (drift) printf "drift,%s,%.4g,%d,%s,%s,,,,,,\n", pre, edge, cnt, cnt ? sprintf("%.6f", sd / cnt) : "", stats()
			cnt = 0; sd = 0 }
		BEGIN { for (k = 0; k < n; k++) { x[k] = k * d * 2 * a; be[k] = (k == 0 || k == n - 1) ? 0 : b }
			edge = 0.1; step = 10 ^ (1 / 8); lo_run = d }
		NR == 1 { next }
		{ t = $2; while (t >= edge) { flush(); edge *= step } }
		$3 >= 0 && $4 >= 0 {
			l = $3; r = $4; vl = $7; vr = $8
			cnt++; sd += gap(l)
			x[l] += be[l] * (vr - vl); x[r] += be[r] * (vl - vr)
			for (k = l - 1; k <= r; k++) if (k >= 0 && k < n - 1 && gap(k) < lo_run) lo_run = gap(k) }
		END { if (drift) while (edge < secs * step) { flush(); if (edge >= secs) break; edge *= step }
			nf = split(final, f, " "); e = 0
			for (k = 0; k < n; k++) { dx = x[k] - f[k + 1]; if (dx < 0) dx = -dx; if (dx > e) e = dx }
			printf "%.3g,%.6f\n", (nf == n) ? e : 1e9, lo_run >errfile }' "$m/collisions.csv"
}

# ---- merge -----------------------------------------------------------------------
# mobility.csv's columns
C_KIND=1 C_D=2 C_B=3 C_SEED=4 C_SECS=5 C_T=6 C_COLL=7 C_MCOLL=8 C_MEAN=9 C_SD=10 C_MIN=11 C_MAX=12 C_BAD=13 C_CPAIRS=14 C_TR=15 C_LAST=16 C_ERR=17 C_LORUN=18

merge() {
	fig_merge_runs "$@"
	local fig=$FIG_OUT t=$FIG_TMP csv="$FIG_OUT/mobility.csv"
	fig_has "$csv" "\$$C_KIND == \"run\"" || fig_die "no run rows in the runs"
	per_beta "$csv" >"$t/betas.csv"
	daemon_relax >"$t/daemons.csv"
	relax_plot "$fig" "$t" || fig_die "mobility.png could not be drawn"
	if fig_has "$csv" "\$$C_KIND == \"drift\""; then
		drift_plot "$fig" "$t" || fig_die "mobility-drift.png could not be drawn"
	else
		echo "mobility: no run with DRIFT 1: no Fig. 7a" >&2
	fi
	fragment "$fig" "$t" >"$fig/mobility.md" 2>"$t/fragment.err" && [ ! -s "$t/fragment.err" ] ||
		fig_die "the page's section failed: $(head -n 3 "$t/fragment.err")"
	fig_merge_end
}

# per_beta CSV: per β: runs, relaxed, censored, t_relax median (censored
# runs counted as longest: ">L" when the median run had not relaxed), least,
# greatest of the relaxed, the run length, the pairs beyond their limit at
# the end in the relaxed runs
per_beta() {
	awk -F, -v k=$C_KIND -v cb=$C_B -v ctr=$C_TR -v cs=$C_SECS -v cbad=$C_BAD -v clo=$C_LORUN '
		$k == "run" { n[$cb]++; L[$cb] = $cs; if ($clo < 0) crossed[$cb]++; if (!($cb in lo) || $clo < lo[$cb]) lo[$cb] = $clo
			if ($ctr == "") cen[$cb]++; else { r = ++nr[$cb]; v[$cb, r] = $ctr; bad[$cb] += $cbad } }
		END { for (b in n) {
				m = nr[b]; for (i = 2; i <= m; i++) for (j = i; j > 1 && v[b, j - 1] > v[b, j]; j--) { x = v[b, j]; v[b, j] = v[b, j - 1]; v[b, j - 1] = x }
				# the median of all runs, the censored ones above every relaxed one
				h = int((n[b] + 1) / 2)
				if (n[b] % 2) med = (h <= m) ? v[b, h] : ">" L[b]
				else med = (h + 1 <= m) ? (v[b, h] + v[b, h + 1]) / 2 : ">" L[b]
				printf "%s,%d,%d,%d,%s,%s,%s,%s,%d,%d,%.3f\n", b, n[b], m, cen[b], med, m ? v[b, 1] : "nan", m ? v[b, m] : "nan", L[b], bad[b], crossed[b], lo[b] } }' "$1" |
		sort -t, -k1,1g | { echo "beta,runs,relaxed,censored,median_s,min_s,max_s,seconds,incompatible_pairs,crossed,least_dsep"; cat; }
}

# The daemons' mobile rows (figures/rows: ten robots, d̃ 0.78, the paper's ends:
# no walls, the end bases held; t from the switch to the oscillator at 3 s): this
# invocation's rows.csv, else docs/figures/rows.csv; FIG_ROWS_CSV names another.
rows_csv() { fig_rows_csv '^dsep,beta,seconds,seed,pairs,colliding_pairs,.*,relax_s,censored,'; }
# daemon_relax: beta,relax_s,censored,run_s of every mobile run at d̃ 0.78 (figures/rows' RELAX_DSEP)
daemon_relax() {
	local c
	echo "beta,relax_s,censored,run_s"
	c=$(rows_csv) || return 0
	awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
		$1 == 0.78 && $2 > 0 { printf "%s,%s,%s,%s\n", $2, $col["relax_s"], $col["censored"], $3 - 3 }' "$c" | sort -t, -k1,1g
}

relax_plot() {
	local fig=$1 t=$2 csv="$1/mobility.csv" series=() lo hi
	# each run at its β, spread sideways by its seed (a few per cent)
	awk -F, -v k=$C_KIND -v cb=$C_B -v cs=$C_SEED -v ctr=$C_TR -v cl=$C_SECS -v clo=$C_LORUN '
		$k == "run" { x = $cb * exp(0.04 * (($cs % 10) - 4.5)); printf "%s,%.6g,%s,%s,%d\n", $cb, x, ($ctr == "") ? "" : ($ctr > 0.05 ? $ctr : 0.05), ($ctr == "") ? $cl : "", $clo < 0 }' "$csv" |
		{ echo "beta,x,t_relax,censored_at,crossed"; cat; } >"$t/runs.csv"
	fig_series series "$t/runs.csv" '$3 != "" && $5 == 0' "using 2:(\$5 == 0 ? \$3 : 1/0) with points pt 7 ps 0.8 lc rgb '#1f77b4' title 'model: a run (50 oscillators, ends held, d̃ 0.78)'"
	fig_series series "$t/runs.csv" '$3 != "" && $5 == 1' "using 2:(\$5 == 1 ? \$3 : 1/0) with points pt 6 ps 0.8 lc rgb '#1f77b4' title 'model: a run in which two bases passed each other (d̃ < 0)'"
	fig_series series "$t/betas.csv" '$5 !~ />/ && $3 > 0' "using 1:(strstrt(strcol(5), '>') > 0 ? 1/0 : \$5) with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4' title 'model: median over the seeds'"
	fig_series series "$t/runs.csv" '$4 != ""' "using 2:4 with points pt 8 ps 1.4 lw 1.5 lc rgb '#d62728' title 'model: censored, still colliding at the end of its run (drawn there)'"
	fig_series series "$t/daemons.csv" '$3 == 0' "using (\$3 == 0 ? \$1 : 1/0):(\$2 > 0.05 ? \$2 : 0.05) with points pt 5 ps 1.1 lc rgb '#555555' title 'daemons (figures/rows): 10 robots, ends held (0 s drawn at 0.05)'"
	fig_series series "$t/daemons.csv" '$3 == 1' "using (\$3 == 1 ? \$1 : 1/0):4 with points pt 4 ps 1.3 lw 1.5 lc rgb '#555555' title 'daemons: censored (drawn at the length of the run)'"
	lo=$(awk -F, 'NR > 1 { if (m == "" || $1 < m) m = $1 } END { print m / 2 }' "$t/runs.csv")
	hi=$(awk -F, 'NR > 1 { if ($1 > m) m = $1 } END { print m * 2 }' "$t/runs.csv")
	{
		fig_gp_head 1000 700
		echo "set encoding utf8"
		echo "set output '$fig/mobility.png'"
		echo "set logscale xy"
		echo "set xrange [$lo:$hi]"
		echo "set yrange [0.04:*]"
		echo "set format y '%g'"
		echo "set format x '%g'"
		echo "set xlabel 'mobility β (s)'"
		echo "set ylabel 't_{relax}: the last collision (s)'"
		echo "set title \"Fig. 7b: relaxation of mobile rows against β, undulate-model (no walls, the end oscillators held)\""
		echo "set key top right font ',9'"
		fig_plot "${series[@]}"
	} >"$t/relax.gp"
	fig_gnuplot "$t/relax.gp"
}

# drift_plot: per β (drift runs) per time bin, over its seeds: the row's
# greatest, mean and least d̃ at the bin's end, and its sd
drift_plot() {
	local fig=$1 t=$2 csv="$1/mobility.csv" b i=0 top=() bottom=() colours=('#1f77b4' '#ff7f0e' '#2ca02c' '#9467bd' '#8c564b' '#e377c2') seeds
	awk -F, -v k=$C_KIND -v cb=$C_B -v ct=$C_T -v csd=$C_SD -v cmean=$C_MEAN -v clo=$C_MIN -v chi=$C_MAX '
		$k == "drift" { key = $cb "," $ct; n[key]++; sd[key] += $csd; mn[key] += $cmean; lo[key] += $clo; hi[key] += $chi }
		END { for (key in n) printf "%s,%.6f,%.6f,%.6f,%.6f\n", key, hi[key] / n[key], mn[key] / n[key], lo[key] / n[key], sd[key] / n[key] }' "$csv" |
		sort -t, -k1,1g -k2,2g | { echo "beta,t,dsep_max,dsep_mean,dsep_min,dsep_sd"; cat; } >"$t/drift.csv"
	seeds=$(awk -F, -v k=$C_KIND '$k == "drift" { print $3, $4 }' "$csv" | sort -u | awk '{ n[$1]++ } END { for (b in n) if (n[b] > m) m = n[b]; print m }')
	for b in $(awk -F, 'NR > 1 { print $1 }' "$t/drift.csv" | sort -gu); do
		local c=${colours[$((i % ${#colours[@]}))]}
		i=$((i + 1))
		top+=("'$t/drift.csv' every ::1 using (\$1 == $b ? \$2 : 1/0):3 with lines lw 2 lc rgb '$c' title 'β = $b s: the largest d̃'"
			"'$t/drift.csv' every ::1 using (\$1 == $b ? \$2 : 1/0):5 with lines lw 2 dt 4 lc rgb '$c' title 'the least'")
		bottom+=("'$t/drift.csv' every ::1 using (\$1 == $b ? \$2 : 1/0):6 with lines lw 2 lc rgb '$c' title 'β = $b s'")
	done
	top+=("'$t/drift.csv' every ::1 using 2:4 with lines lw 1.5 dt 2 lc rgb 'black' title 'the mean (its ends held)'")
	{
		fig_gp_head 1000 950
		echo "set encoding utf8"
		echo "set output '$fig/mobility-drift.png'"
		echo "set multiplot layout 2,1 title \"Fig. 7a: mobile rows spreading from d̃ = $DSEP, undulate-model: the mean over $seeds seed(s) of each β\""
		echo "set lmargin at screen 0.09"
		echo "set rmargin at screen 0.70"
		echo "set logscale x"
		echo "set format x '%g'"
		echo "set xlabel 'time (s)'"
		echo "set ylabel 'd̃ over the row'"
		echo "set key outside right font ',9'"
		fig_plot "${top[@]}"
		echo "set ylabel 'spread (sd) of d̃ over the row'"
		fig_plot "${bottom[@]}"
		echo "unset multiplot"
	} >"$t/drift.gp"
	fig_gnuplot "$t/drift.gp"
}

fragment() {
	local fig=$1 t=$2 csv="$1/mobility.csv" runs src
	runs=$(awk -F, -v k=$C_KIND '$k == "run"' "$csv" | wc -l)
	echo "## Rows of 50 mobile oscillators (the paper's Figs. 7a and 7b), from its own model"
	echo
	echo "![Fig. 7b: t_relax against β, each run, the median, the daemons' rows](figures/mobility.png)"
	echo
	[ -s "$fig/mobility-drift.png" ] && { echo "![Fig. 7a: the d̃ of colliding pairs over time, and the row's spread](figures/mobility-drift.png)"; echo; }
	echo "**What ran.** No daemons and no servos: $runs runs of \`undulate-model lattice\` (model/README.md),"
	echo "$OSCILLATORS phase oscillators in a row started $DSEP apart in d̃ from random phases (seeds 1, 2, ...),"
	echo "r = 0.67, f = 0.8 Hz, A = 0.8, no walls, the two end oscillators held (\`--fixed-ends\`: β = 0"
	echo "for them), every other base moving by β(ẋ_other − ẋ_self) at each of its impacts. t_relax: the"
	echo "time of the last collision, exact when none came in the last $WINDOW s (between collisions nothing"
	echo "changes); a run still colliding in its last $WINDOW s is censored. Each β ran long enough that"
	echo "its slowest seed relaxed well before the end (the table's run length)."
	echo
	echo "| β (s) | runs | relaxed | censored | run length (s) | t_relax median (s) | least - greatest relaxed (s) | pairs beyond 2·asin(d̃) at the end, relaxed runs | runs whose bases crossed (least d̃) |"
	echo "|---|---|---|---|---|---|---|---|---|"
	awk -F, 'NR > 1 { printf "| %s | %d | %d | %d | %d | %s | %s | %d | %d (%.2f) |\n", $1, $2, $3, $4, $8,
		($5 ~ />/) ? "> " substr($5, 2) : sprintf("%.3g", $5), ($3 > 0) ? sprintf("%.3g - %.3g", $6, $7) : "-", $9, $10, $11 }' "$t/betas.csv"
	echo
	relax_words "$t" "$csv"
	echo
	drift_words "$csv"
	echo
	if src=$(rows_csv) && fig_has "$t/daemons.csv" 1; then
		echo "**Beside the daemons.** Grey: figures/rows' mobile rows through the daemons and the simulated"
		echo "servos ($(awk 'END { print NR - 1 }' "$t/daemons.csv") runs from $(case "$src" in "$fig_top/docs/figures/rows.csv") echo "docs/figures/rows.csv" ;; *) echo "this invocation's rows.csv" ;; esac)): ten single-joint robots at d̃ 0.78,"
		echo "the ends as here (no walls, the two end robots' bases held, β for the others), time"
		echo "from the switch to the oscillator at 3 s. $(daemon_words "$t") rows.csv keeps no"
		echo "positions over time, so 7a has no daemons' curve."
	else
		echo "**Beside the daemons.** No merged figures/rows (rows.csv) was found: the daemons' rows are not overlaid."
	fi
}

relax_words() {
	awk -F, 'NR > 1 && $5 !~ />/ && $3 == $2 { if (lo == "" || $1 + 0 < lo) { lo = $1; tlo = $5 }; if ($1 + 0 > hi) { hi = $1; thi = $5 } }
		NR > 1 && $1 + 0 >= 0.05 && $5 !~ />/ { if (flo == "" || $5 + 0 < flo) flo = $5 + 0; if ($5 + 0 > fhi) fhi = $5 + 0 }
		NR > 1 && $4 > 0 { cen = cen sprintf("%s%s s: %d of %d censored after %d s", cen == "" ? "" : "; ", $1, $4, $2, $8) }
		NR > 1 && $4 == 0 && $2 > 0 { full = full sprintf("%s%s", full == "" ? "" : ", ", $1) }
		END {
			printf "**What it shows (7b).** Where every run relaxed, the median t_relax falls from %.4g s at β = %s s to %.4g s at β = %s s", tlo, lo, thi, hi
			if (lo + 0 > 0 && hi + 0 > lo + 0 && thi + 0 > 0) printf " (%.2g decades of t_relax over %.2g of β)", log(tlo / thi) / log(10), log(hi / lo) / log(10)
			printf ": steep as β → 0, as the paper says. "
			if (flo != "") printf "From β = 0.05 s up the medians lie between %.3g and %.3g s (a period is 1.25 s). ", flo, fhi
			printf "Every run relaxed at β = %s s. ", full
			if (cen != "") printf "Censored: %s. Below 0.007 s the row mostly does not relax in the runs'"'"' time: it keeps colliding at a steady rate (the paper: mobile bases always relax; its β is in its own units, which theory.md does not give). ", cen
			printf "\n" }' "$1/betas.csv"
	awk -F, -v k=$C_KIND -v cb=$C_B -v ctr=$C_TR -v cc=$C_COLL -v cs=$C_SECS '$k == "run" && $ctr == "" { r[$cb] += $cc / $cs; n[$cb]++ }
		END { for (b in n) printf "%s,%.1f,%d\n", b, r[b] / n[b], n[b] }' "$2" | sort -t, -k1,1g |
		awk -F, '{ s = s sprintf("%s%.1f at β = %s s (%d runs)", s == "" ? "" : ", ", $2, $1, $3) }
			END { if (s != "") printf "The censored runs'"'"' collisions per second over the whole run: %s.\n", s }'

	awk -F, 'NR > 1 && $10 > 0 && (c == "" || $1 + 0 < c) { c = $1 } NR > 1 && $10 == 0 && $1 + 0 > ok { ok = $1 }
		END { if (c != "") printf "From β = %s s two bases passed each other in some runs (a pair'"'"'s d̃ below 0 after an impact; the model moves a base by β·Δv, up to 8β, and does not forbid it): there the decades are the model'"'"'s formal continuation, not a row of bodies. ", c
			if (ok != "") printf "Up to β = %s s no base passed a neighbour.\n", ok }' "$1/betas.csv"
	awk -F, 'NR > 1 && $3 > 0 { n += $9 } END { printf "In every relaxed run, %d pairs lie beyond their compatibility limit 2·asin(d̃) (each pair at its own d̃ at the end): the mobile row relaxes to compatibility.\n", n }' "$1/betas.csv"
}

drift_words() {
	awk -F, -v k=$C_KIND -v cb=$C_B -v cs=$C_SEED -v ct=$C_T -v cmean=$C_MEAN -v csd=$C_SD -v clo=$C_MIN -v chi=$C_MAX -v cm=$C_MCOLL -v cc=$C_COLL -v cerr=$C_ERR -v d0=$DSEP '
		function abs(x) { return x < 0 ? -x : x }
		$k == "drift" { key = $cb; if (abs($cmean - d0) > dev) dev = abs($cmean - d0)
			if ($ct > tl[key, $cs]) { tl[key, $cs] = $ct; hi[key, $cs] = $chi; lo[key, $cs] = $clo; sd[key, $cs] = $csd }
			bs[$cb] = 1; if ($cc > 0) { cw[key] += $cm * $cc; cn[key] += $cc } }
		$k == "run" && $cerr != "" { if ($cerr + 0 > err) err = $cerr + 0; ne++ }
		END {
			if (!length(bs)) { print "**7a.** No drift runs."; exit }
			printf "**What it shows (7a).** The row'"'"'s mean d̃ cannot drift: its ends are held and its gaps add up to the distance between them (it stays %s within %s). ", d0, dev < 1e-6 ? "10⁻⁶" : sprintf("%.1g", dev)
			printf "What drifts is each pair: an impact pushes its two bases apart, so the pairs that collide move to larger d̃ and the ones beside them close up, until every pair is compatible. At the end, by β (each drift run: the largest d̃ / the least / the sd):"
			nb = 0; for (b in bs) ob[++nb] = b + 0
			for (i = 2; i <= nb; i++) for (j = i; j > 1 && ob[j - 1] > ob[j]; j--) { x = ob[j]; ob[j] = ob[j - 1]; ob[j - 1] = x }
			for (key in tl) { split(key, kk, SUBSEP); s[kk[1] + 0] = s[kk[1] + 0] sprintf(" %.2f / %.2f / %.3f;", hi[key], lo[key], sd[key]) }
			for (i = 1; i <= nb; i++) printf " β = %s s:%s", ob[i], s[ob[i]]
			printf " The d̃ at which collisions happen does not grow with them (the mean over each run'"'"'s collisions:"
			for (i = 1; i <= nb; i++) for (b in bs) if (b + 0 == ob[i]) printf "%s %.3f at β = %s s", (i > 1 ? "," : ""), cw[b] / cn[b], b
			printf "): the row spreads, the colliding pairs moving apart and their neighbours closing up. The bases rebuilt from the impacts alone (each δ = β(ẋ_other − ẋ_self)) end within %.1g of the model'"'"'s own (%d runs): the mobility'"'"'s books add up.\n", err, ne }' "$1"
}

daemon_words() {
	awk -F, 'NR == FNR { if (FNR > 1) { med[++nm] = $5; mb[nm] = $1 }; next }
		FNR > 1 { if (!($1 in n)) ord[++no] = $1; n[$1]++; if ($3 == 0) { r[$1]++; v[$1] = v[$1] " " $2 } else c[$1]++ }
		END { for (i = 1; i <= no; i++) { b = ord[i]; s = s sprintf("%s%s s: %d of %d relaxed%s", s == "" ? "" : "; ", b, r[b], n[b], r[b] ? " (" substr(v[b], 2) " s)" : "") }
			printf "The daemons'"'"' runs by β: %s. The model'"'"'s medians for comparison:", s
			for (i = 1; i <= nm; i++) m = m sprintf("%s %s s at %s s", m == "" ? "" : ",", med[i] ~ />/ ? med[i] : sprintf("%.3g", med[i]), mb[i])
			printf "%s. Both run at f = 0.8 Hz, so a shift β·Δv (Δv at most 2Aω) is at most βω of 2A in either: their β compare as they stand.", m }' "$1/betas.csv" "$1/daemons.csv"
}

fig_main "jobs [--quick] | run OUTDIR BETA SECONDS SEED DRIFT | merge RUNS_DIR FIGDIR | seconds [--quick]" "$@"
