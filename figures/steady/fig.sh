#!/usr/bin/env bash
# figures/steady/fig.sh — the paper's Fig. 3c from its own model: the mean
# steady state |Δ| of a pair over (d̃, r), the mean over initial phase
# differences Δ₀ spread evenly over (−π, π), each pair run by undulate-model
# (the phase oscillators integrated, collisions as events: model/README.md)
# until its end state; beside it the same mean from theory.md's return map
# iterated from each Δ₀ (undulate-analyze --theory final), with d̃_c(r), right
# of which anti-phase is stable, over both.
#
#   fig.sh jobs [--quick]          one line per run: RUN_ID R DSEP_POINTS DELTA0_POINTS SECONDS
#   fig.sh run OUTDIR R DSEP_POINTS DELTA0_POINTS SECONDS
#   fig.sh merge RUNS_DIR FIGDIR   steady.csv, steady.png, steady.md
#   fig.sh seconds [--quick]
#
# A run is one restitution: for d̃ = 0 .. 1 in DSEP_POINTS steps and Δ₀ =
# −π + 2π (j + ½) / DELTA0_POINTS, one `undulate-model pair` of SECONDS
# simulated seconds each (about 40 ms), its end state the analyser's over
# the last 10 s. No daemons.
#
# FIG_TINY=1: `jobs` gives two small grids (the driver's test).
source "$(dirname "$0")/../lib.sh"
fig_init steady

# full: r every 0.1, d~ every 0.04, 16 starts (3744 pairs); quick: five r,
# d~ every 0.1, 8 starts (440 pairs)
FULL_RS="0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8 0.9" FULL_GRID="26 16"
QUICK_RS="0.1 0.3 0.5 0.7 0.9" QUICK_GRID="11 8"
# simulated seconds a pair: about 190 collisions at 0.8 Hz, enough for the
# slowest approach to anti-phase on the grid (|f'(pi)| near 1 at d~_c)
SECONDS_RUN=120

jobs() {
	local rs=$FULL_RS grid=$FULL_GRID r
	[ "${1:-}" = --quick ] && rs=$QUICK_RS grid=$QUICK_GRID
	if [ "${FIG_TINY:-0}" = 1 ]; then
		echo "r030 0.3 6 4 $SECONDS_RUN"
		echo "r090 0.9 6 4 $SECONDS_RUN"
		return
	fi
	for r in $rs; do
		awk -v r="$r" -v g="$grid" -v s="$SECONDS_RUN" 'BEGIN { printf "r%03d %s %s %d\n", r * 100 + 0.5, r, g, s }'
	done
}

# Wall seconds of one run (2026-11-28, two at once at load 5-12: 21 s for the
# full grid's 416 pairs, 8 s for the quick grid's 88; 50-90 ms a pair).
seconds() { [ "${1:-}" = --quick ] && echo 5 || echo 11; }

RESULT_HEADER="r,dsep,delta0,class,final_abs_delta,collisions,window_collisions,theory_final,theory_collisions"

run() {
	[ $# -eq 5 ] || fig_usage "run: want OUTDIR R DSEP_POINTS DELTA0_POINTS SECONDS, got $*"
	local out=$1 r=$2 nd=$3 na=$4 secs=$5 i j d d0 line
	fig_num R "$r" 0 1
	fig_uint DSEP_POINTS "$nd" 2 1001
	fig_uint DELTA0_POINTS "$na" 1 360
	fig_uint SECONDS "$secs" 20 3600
	fig_run_start "$out"
	outdir_new "$out/model.csv" "$out/grid.csv" "$out/theory.csv" "$out/pair.log" "$out/result.csv" ||
		{ echo "$FIG_NAME: cannot write in $out" >&2; return 1; }
	awk -v nd="$nd" -v na="$na" 'BEGIN { pi = atan2(0, -1)
		for (i = 0; i < nd; i++) for (j = 0; j < na; j++) printf "%.6f,%.6f\n", i / (nd - 1), -pi + 2 * pi * (j + 0.5) / na }' >"$out/grid.csv"
	: >"$out/model.csv"
	while IFS=, read -r d d0; do
		"$FIG_BIN/undulate-model" pair --restitution "$r" --dsep "$d" --delta0 "$d0" --duration "$secs" \
			--no-samples --quiet --out "$out/pair" >"$out/pair.log" 2>&1 ||
			{ echo "$FIG_NAME: $out: undulate-model pair at d~ $d, delta0 $d0 failed: $(tail -n 1 "$out/pair.log")" >&2; return 1; }
		# the pair's line of summary.txt: its class (one or more words), then
		# mean|D| meanD spread coll c.win d~ 2asin(d~)
		line=$(awk '$1 == "r1:r2" { c = $2; for (k = 3; k <= NF - 7; k++) c = c " " $k
			printf "%s,%s,%s,%s", c, $(NF - 6), $(NF - 3), $(NF - 2) }' "$out/pair/summary.txt")
		[ -n "$line" ] || { echo "$FIG_NAME: $out: no pair in $out/pair/summary.txt" >&2; return 1; }
		echo "$line" >>"$out/model.csv"
	done <"$out/grid.csv"
	fig_theory final --restitution "$r" <"$out/grid.csv" | tail -n +2 | cut -d, -f3,4 >"$out/theory.csv" ||
		{ echo "$FIG_NAME: $out: undulate-analyze --theory final failed" >&2; return 1; }
	{
		echo "$RESULT_HEADER"
		paste -d, "$out/grid.csv" "$out/model.csv" "$out/theory.csv" | awk -v r="$r" '{ print r "," $0 }'
	} >"$out/result.csv"
	rm -rf "$out/pair" "$out/pair.log" "$out/grid.csv" "$out/model.csv" "$out/theory.csv"
}

# ---- merge -----------------------------------------------------------------------
# Columns of steady.csv.
C_R=1 C_D=2 C_D0=3 C_CLASS=4 C_FINAL=5 C_THEORY=8
merge() {
	fig_merge_runs "$@"
	local r fig=$FIG_OUT tmp=$FIG_TMP
	cells "$fig/steady.csv" >"$tmp/cells.csv"
	# d~_c(r) over the whole range of r, for the curve
	for r in $(awk 'BEGIN { for (i = 1; i < 100; i++) printf "%.2f\n", i / 100 }'); do
		fig_theory critical --restitution "$r" | awk -F, -v r="$r" 'NR == 2 { print $2 "," r }'
	done >"$tmp/dc.csv" || fig_die "undulate-analyze --theory failed"
	plot "$fig" "$tmp" || fig_die "steady.png could not be drawn"
	fragment "$fig/steady.csv" "$tmp" >"$fig/steady.md" 2>"$tmp/fragment.err" && [ ! -s "$tmp/fragment.err" ] ||
		fig_die "the page's section failed: $(head -n 3 "$tmp/fragment.err")"
	fig_merge_end
}

# cells CSV: per (r, d~): "r,dsep,starts,model_mean,theory_mean,model_anti,theory_anti"
# (means of |final delta|; how many starts ended in anti-phase)
cells() {
	awk -F, -v cr=$C_R -v cd=$C_D -v cc=$C_CLASS -v cf=$C_FINAL -v ct=$C_THEORY '
		function abs(x) { return x < 0 ? -x : x }
		NR > 1 { k = $cr "," $cd; if (!(k in n)) order[++m] = k; n[k]++; sm[k] += abs($cf); st[k] += abs($ct)
			if (3.14159265 - abs($cf) < 0.01) am[k]++; if (3.14159265 - abs($ct) < 0.01) at[k]++ }
		END { print "r,dsep,starts,model_mean,theory_mean,model_anti,theory_anti"
			for (i = 1; i <= m; i++) { k = order[i]
				printf "%s,%d,%.6f,%.6f,%d,%d\n", k, n[k], sm[k] / n[k], st[k] / n[k], am[k], at[k] } }' "$1"
}

plot() {
	local fig=$1 t=$2
	{
		fig_gp_head 1300 600
		echo "set encoding utf8"
		echo "set output '$fig/steady.png'"
		echo "set multiplot layout 1,2 title \"Mean steady state |Δ| of a pair over (d̃, r), over starts Δ₀ spread over (−π, π)\""
		echo "set xrange [0:1]"
		echo "set yrange [0:1]"
		echo "set xlabel 'd̃'"
		echo "set ylabel 'r'"
		echo "set cbrange [0:pi]"
		echo "set cbtics ('0' 0, 'π/4' pi/4, 'π/2' pi/2, '3π/4' 3*pi/4, 'π' pi)"
		echo "set cblabel 'mean |Δ| at the end'"
		echo "set palette defined (0 '#08306b', 0.8 '#2171b5', 1.57 '#c6dbef', 2.4 '#fc9272', 3.1416 '#99000d')"
		echo "set key bottom right font ',9' opaque"
		echo "set datafile separator ','"
		echo "set title 'undulate-model: the pairs integrated'"
		echo "plot '$t/cells.csv' every ::1 using 2:1:4 with image pixels notitle, \\"
		echo "  '$t/dc.csv' using 1:2 with lines lw 2 lc rgb 'black' title 'd̃_c(r): anti-phase stable to the right'"
		echo "set title \"theory.md's return map iterated from each Δ₀\""
		echo "plot '$t/cells.csv' every ::1 using 2:1:5 with image pixels notitle, \\"
		echo "  '$t/dc.csv' using 1:2 with lines lw 2 lc rgb 'black' title 'd̃_c(r)'"
		echo "unset multiplot"
	} >"$t/steady.gp"
	fig_gnuplot "$t/steady.gp"
}

# rs CSV: the restitutions present, in order
rs() { awk -F, 'NR > 1 { print $1 }' "$1" | sort -gu; }

# stats CELLS R DC: "key value" lines for restitution R (d~_c DC)
stats() {
	awk -F, -v r="$2" -v dc="$3" '
		function abs(x) { return x < 0 ? -x : x }
		NR > 1 && $1 == r {
			n++; s += $3; e = abs($4 - $5); if (e > err) { err = e; errd = $2 }
			if ($2 == 0) zero = $4
			if ($2 == 1) one = $4
			if ($6 > 0 && (first == "" || $2 < first)) first = $2
			if ($7 > 0 && (tfirst == "" || $2 < tfirst)) tfirst = $2
			if ($2 < dc) { left += $3; left_anti += $6 }
			am += $6; at += $7 }
		END { printf "cells %d\nstarts %d\nzero %.3f\none %s\nerr %.3f\nerr_at %.2f\nfirst %s\ntfirst %s\nanti %d / %d\nleft %d\nleft_anti %d\n",
			n, s, zero, one == "" ? "-" : sprintf("%.3f", one), err, errd, first == "" ? "none" : sprintf("%.2f", first),
			tfirst == "" ? "none" : sprintf("%.2f", tfirst), am, at, left, left_anti }' "$1"
}

fragment() {
	local csv=$1 t=$2 r s dc n left=0 left_anti=0 zmax=0 err=0
	v() { awk -v k="$2" '$1 == k { $1 = ""; sub(/^ /, ""); print }' <<<"$1"; }
	n=$(($(wc -l <"$csv") - 1))
	cat <<EOF2
## The mean steady state over (d̃, r) (the paper's Fig. 3c), from its own model

![Mean steady state |Δ| over (d̃, r): the integrated pairs beside the return map](figures/steady.png)

**What ran.** No daemons and no servos: $n pairs of \`undulate-model pair\` (model/README.md),
the paper's phase oscillators integrated with collisions as events, $(awk -F, 'NR == 2 { print $3 }' "$t/cells.csv")
starts Δ₀ spread evenly over (−π, π) at each (d̃, r) of the grid, $SECONDS_RUN s of simulated time
each; the end state is the analyser's over the last 10 s (\`undulate-analyze\`'s rules). Left:
the mean of |Δ| at the end over the starts; right: the same mean where theory.md's return map,
iterated from each Δ₀, leads (\`undulate-analyze --theory final\`). The line: d̃_c(r), where
|f′(π)| = 1, right of which anti-phase is stable. An end at π: |Δ| within 0.01 rad of it.

| r | d̃_c | cells | mean \|Δ\| at d̃ = 0 | at d̃ = 1 | first d̃ with an end at π: model / map | ends at π: model / map | model − map, largest cell mean |
|---|---|---|---|---|---|---|---|
EOF2
	for r in $(rs "$t/cells.csv"); do
		dc=$(fig_theory critical --restitution "$r" | awk -F, 'NR == 2 { printf "%.4f", $2 }')
		s=$(stats "$t/cells.csv" "$r" "$dc")
		printf '| %s | %.3f | %s | %s rad | %s rad | %s / %s | %s | %s rad at d̃ = %s |\n' "$r" "$dc" "$(v "$s" cells)" "$(v "$s" zero)" \
			"$(v "$s" one)" "$(v "$s" first)" "$(v "$s" tfirst)" "$(v "$s" anti)" "$(v "$s" err)" "$(v "$s" err_at)"
		left=$((left + $(v "$s" left))) left_anti=$((left_anti + $(v "$s" left_anti)))
		zmax=$(awk -v a="$zmax" -v b="$(v "$s" zero)" 'BEGIN { print (b > a ? b : a) }')
		err=$(awk -v a="$err" -v b="$(v "$s" err)" 'BEGIN { print (b > a ? b : a) }')
	done
	cat <<EOF2

**What it shows.** The paper's three regimes over r. At d̃ = 0 every pair ends in phase
(mean |Δ| at most $(printf '%.3f' "$zmax") rad). Left of d̃_c(r) no pair ends at π ($left_anti of the $left starts
there): one that touches falls into the compatible band, |Δ| ≤ 2·asin(d̃), and the mean grows
slowly with d̃. Right of d̃_c the starts in anti-phase's basin end at π and the mean jumps up.
d̃_c(r) = √(r(r − 1)/(r² − r − 2)) is the same at r and 1 − r, largest at r = ½ (0.333), so
the jump comes at smaller d̃ for r near 0 or 1. At d̃ = 1 the bodies can no longer touch and the
mean is that of the starts, π/2. The integrated pairs and the map part by at most
$(printf '%.3f' "$err") rad in a cell's mean. $(worst "$csv")
EOF2
}

# worst CSV: the start where the model's end and the map's differ most, in words
worst() {
	awk -F, -v cf=$C_FINAL -v ct=$C_THEORY 'function abs(x) { return x < 0 ? -x : x }
		NR > 1 { e = abs(abs($cf) - abs($ct)); if (e > w) { w = e; row = $0 } }
		END { if (w < 1e-3) { print "At no start do their ends differ by 1 mrad."; exit }
			split(row, f, ",")
			printf "The largest difference at one start: r = %s, d̃ = %.2f, Δ₀ = %.4f, the integrated pair at |Δ| = %.3f after %d collisions, the map at %.3f after %d",
				f[1], f[2], f[3], abs(f[5]), f[6], abs(f[8]), f[9]
			# the compatibility limit 2 asin(d~), for the words only
			lim = 2 * atan2(f[2], sqrt(1 - f[2] * f[2]))
			if (abs(abs(f[3]) - lim) < 0.05)
				printf ": the start is %.4f rad from the compatibility limit 2·asin(d̃) = %.4f, a fixed point of the map, which a pair leaves slowly; the run ended first.\n", abs(abs(f[3]) - lim), lim
			else printf ": where |f′(π)| is near 1 a pair approaches π slowly; the run ended first.\n" }' "$1"
}

fig_main "jobs [--quick] | run OUTDIR R DSEP_POINTS DELTA0_POINTS SECONDS | merge RUNS_DIR FIGDIR | seconds" "$@"
