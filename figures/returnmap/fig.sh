#!/usr/bin/env bash
# figures/returnmap/fig.sh — the return map at d~ = 0 (the paper's Fig. 5a
# measures the pair rig's return map): the phase difference
# after a collision, Delta_{n+1}, against the one before, Delta_n, beside
# theory.md's closed form -2 atan(r tan(Delta_n / 2)); and Delta_n against
# n beside 2 atan((-r)^n tan(Delta_0 / 2)), at r = 0.67 and 0.9.
#
#   fig.sh jobs [--quick]            one line per run: RUN_ID R DELTA0 SEED SECONDS
#   fig.sh run OUTDIR R DELTA0 SEED SECONDS
#   fig.sh merge RUNS_DIR FIGDIR     returnmap.csv, returnmap.png, returnmap-n.png, returnmap.md
#   fig.sh seconds [--quick]
#
# One run: the pair rig (pair-rig.scenario, torque on the current drive) with
# both bases on one spot (world.separation = 0), started as figures/pair/
# starts it: on the full sinusoid at the phases of DELTA0, switched to the
# oscillator just after the clock last pressed the bodies together (at
# d~ = 0 the clock presses them for half of every period; figures/lib.sh,
# fig_pair_switch). The oscillators meet half a period later at about
# DELTA0 and then at every crossing of their angles. The daemons' frequency
# estimate is not yet known at the first collisions: the log is analysed
# again with --frequency set to the frequency the first analysis measured,
# which gives a phase at every collision.
#
# FIG_TINY=1: `jobs` gives two short runs (the driver's test).
source "$(dirname "$0")/../lib.sh"
fig_init returnmap

SCENARIO=$FIG_PAIR_SCENARIO
RIG=("${FIG_PAIR_DRIVE[@]}" --daemon-set "sinusoid.amplitude=$FIG_SIN_AMP" --daemon-set "sinusoid.frequency=$FIG_SIN_HZ"
     --set sim.initial_spread=0)
# Measured: in phase (|Delta| < 0.05) 8-10 collisions after the switch,
# two collisions a period, at r = 0.67; r = 0.9 takes longer.
SECONDS_RUN=20
# Runs per restitution; |Delta0| from the golden-ratio sequence (figures/lib.sh).
FULL_RUNS=24 QUICK_RUNS=3
RESTITUTIONS="0.67 0.9"

jobs() {
	local n=$FULL_RUNS r k=0
	[ "${1:-}" = --quick ] && n=$QUICK_RUNS
	if [ "${FIG_TINY:-0}" = 1 ]; then
		echo "r067-t0 0.67 2.5000 21 8"
		echo "r090-t0 0.9 -2.0000 22 8"
		return
	fi
	for r in $RESTITUTIONS; do
		# |Delta0| from 1 to 3 rad, both signs alternating
		awk -v r="$r" -v n="$n" -v g="$FIG_GOLDEN" -v s="$SECONDS_RUN" -v base="$((k * 100))" 'BEGIN {
			for (i = 0; i < n; i++) {
				u = (i * g + 0.25) - int(i * g + 0.25); sgn = i % 2 ? -1 : 1
				printf "r%03d-%02d %s %.4f %d %d\n", r * 100, i, r, sgn * (1 + 2 * u), 2000 + base + i, s
			}
		}'
		k=$((k + 1))
	done
}

# Wall seconds of one run with four at once (2026-11-27: median 6.0 s of 20 s
# simulated, the log analysed twice).
seconds() { echo 1.4; }

RESULT_HEADER="run,r,delta0,seed,frequency,n,t,delta_n,delta_next,theory_next"

run() {
	[ $# -eq 5 ] || fig_usage "run: want OUTDIR R DELTA0 SEED SECONDS, got $*"
	local out=$1 r=$2 delta0=$3 seed=$4 secs=$5 right f sw
	fig_num R "$r" 0 1
	fig_num DELTA0 "$delta0" -3.1416 3.1416
	fig_uint SEED "$seed" 1 999999999
	fig_uint SECONDS "$secs" 4 3600
	right=$(awk -v d="$delta0" 'BEGIN { printf "%.4f", -d }')
	sw=$(fig_pair_switch 0 "$delta0")
	FIG_KEEP=1 fig_demo "$out" --scenario "$SCENARIO" --seconds "$secs" --switch-at "$sw" --seed "$seed" \
		--phases "0,$right" --set world.separation=0 --set "world.restitution=$r" "${RIG[@]}" || return 1
	local d="$out/demo"
	f=$(jq -r '[.robots[].joints[0].frequency_hz] | add / length' "$d/summary.json")
	awk -v f="$f" 'BEGIN { exit !(f > 0.2 && f < 5) }' ||
		{ echo "$FIG_NAME: $out: no usable frequency from the first analysis ($f Hz)" >&2; return 1; }
	outdir_new "$out/fixed.log" "$out/result.csv" || { echo "$FIG_NAME: cannot write in $out" >&2; return 1; }
	"$FIG_BIN/undulate-analyze" "$d/demo.lcmlog" --out "$out/fixed" --frequency "$f" --quiet >"$out/fixed.log" 2>&1 ||
		{ echo "$FIG_NAME: $out: undulate-analyze --frequency failed: $(tail -n 1 "$out/fixed.log")" >&2; return 1; }
	# the collisions under the clock (pressed, not free) are not the map's:
	# from the switch on, numbered again from 0
	local swt
	swt=$(awk -F, '$6 == "\"mode\"" && index($7, "-> OSCILLATOR") { print $2; exit }' "$out/fixed/events.csv")
	[ -n "$swt" ] || { echo "$FIG_NAME: $out: the daemons never switched to the oscillator (events.csv)" >&2; return 1; }
	{
		echo "$RESULT_HEADER"
		awk -F, -v run="$(basename "$out")" -v r="$r" -v d0="$delta0" -v seed="$seed" -v f="$f" -v sw="$swt" \
			'NR > 1 && $4 > sw { printf "%s,%s,%s,%s,%.5f,%d,%s,%s,%s,%s\n", run, r, d0, seed, f, n++, $4, $5, $6, $7 }' \
			"$out/fixed/return_map.csv"
	} >"$out/result.csv"
	[ "${FIG_KEEP:-0}" = 1 ] || rm -f "$d/demo.lcmlog"
	fig_clean "$d"
	fig_clean "$out/fixed"
}

# ---- merge -----------------------------------------------------------------------
merge() {
	fig_merge_args "$@"
	local runs=$1 fig=$FIG_OUT   # written here, moved into FIGDIR by fig_merge_end
	tmp=$FIG_TMP
	fig_results "$runs" >"$fig/returnmap.csv"
	local r
	for r in $RESTITUTIONS; do
		fig_theory map-d0 --restitution "$r" >"$tmp/map-$r.csv" || fig_die "undulate-analyze --theory failed"
		sequences "$fig/returnmap.csv" "$r" >"$tmp/seq-$r.csv" || fig_die "undulate-analyze --theory failed"
	done
	plot_map "$fig" "$tmp" || fig_die "returnmap.png could not be drawn"
	plot_n "$fig" "$tmp" || fig_die "returnmap-n.png could not be drawn"
	fragment "$fig/returnmap.csv" "$runs" >"$fig/returnmap.md" 2>"$tmp/fragment.err" && [ ! -s "$tmp/fragment.err" ] ||
		fig_die "the page's section failed: $(head -n 3 "$tmp/fragment.err")"
	fig_merge_end
}

# sequences CSV R: for each run at R, its measured Delta_n (from its first
# collision, n = 0) and the closed form from that first Delta: "run,n,
# measured,closed,tan_ratio" with tan_ratio = |tan(D_n/2)| / |tan(D_0/2)|
# (the closed form makes it r^n); a blank line between runs.
sequences() {
	local csv=$1 r=$2 run d0 steps
	for run in $(awk -F, -v r="$r" 'NR > 1 && $2 == r { print $1 }' "$csv" | sort -u); do
		d0=$(awk -F, -v run="$run" '$1 == run && $6 == 0 { print $8 }' "$csv")
		[ -n "$d0" ] || continue
		steps=$(awk -F, -v run="$run" '$1 == run { n = $6 } END { print n + 1 }' "$csv")
		fig_theory sequence --delta0 "$d0" --steps "$steps" --restitution "$r" | tail -n +2 |
			awk -F, -v run="$run" -v csv="$csv" -v d0="$d0" '
				BEGIN { while ((getline l < csv) > 0) { split(l, f, ","); if (f[1] == run) { m[f[6]] = f[8]; last = f[6]; nx = f[9] } }
					m[last + 1] = nx; t0 = sin(d0 / 2) / cos(d0 / 2); if (t0 < 0) t0 = -t0 }
				{ x = ($1 in m) ? m[$1] : ""
				  tr = x == "" ? "" : sprintf("%.6g", (sin(x / 2) / cos(x / 2) < 0 ? -1 : 1) * sin(x / 2) / cos(x / 2) / t0)
				  printf "%s,%s,%s,%s,%s\n", run, $1, x, $2, tr }'
		echo
	done
}

plot_map() {
	local fig=$1 t=$2 r
	{
		fig_gp_head 1300 660
		echo "set encoding utf8"
		echo "set output '$fig/returnmap.png'"
		echo "set multiplot layout 1,2 title 'Return map at d̃ = 0: Δ_{n+1} against Δ_n at each collision (points: runs; line: −2 atan(r tan(Δ_n/2)))'"
		echo "set xrange [-pi:pi]"
		echo "set yrange [-pi:pi]"
		echo "set size ratio -1"
		echo "set xtics ('−π' -pi, '−π/2' -pi/2, '0' 0, 'π/2' pi/2, 'π' pi)"
		echo "set ytics ('−π' -pi, '−π/2' -pi/2, '0' 0, 'π/2' pi/2, 'π' pi)"
		echo "set xlabel 'Δ_n (rad)'"
		echo "set ylabel 'Δ_{n+1} (rad)'"
		echo "set key bottom left font ',9'"
		echo "set cblabel 'collision n'"
		echo "set palette defined (0 '#440154', 3 '#21918c', 8 '#fde725')"
		echo "set cbrange [0:10]"
		for r in $RESTITUTIONS; do
			echo "set title 'r = $r: $(awk -F, -v r="$r" 'NR > 1 && $2 == r' "$fig/returnmap.csv" | wc -l) collisions in $(awk -F, -v r="$r" 'NR > 1 && $2 == r { print $1 }' "$fig/returnmap.csv" | sort -u | wc -l) runs'"
			echo "plot x with lines dt 3 lc rgb '#999999' title 'identity', \\"
			echo "  '$t/map-$r.csv' using 1:3 with lines lw 2 lc rgb 'black' title 'closed form, r = $r', \\"
			echo "  '$fig/returnmap.csv' using (\$2 == $r ? \$8 : 1/0):9:6 with points pt 7 ps 0.8 lc palette title 'runs (colour: n)'"
		done
		echo "unset multiplot"
	} >"$t/map.gp"
	fig_gnuplot "$t/map.gp"
}

plot_n() {
	local fig=$1 t=$2 r color
	{
		fig_gp_head 1300 1000
		echo "set encoding utf8"
		echo "set output '$fig/returnmap-n.png'"
		echo "set multiplot layout 2,2 title 'd̃ = 0: Δ_n against n, each run from its first collision after the switch (dashed: 2 atan((−r)^n tan(Δ_0/2)))'"
		echo "set key top right font ',9'"
		for r in $RESTITUTIONS; do
			color=$([ "$r" = 0.67 ] && echo '#1f77b4' || echo '#d62728')
			echo "set title 'r = $r: Δ_n'"
			echo "set xlabel 'collision n'"
			echo "set ylabel 'Δ_n (rad)'"
			echo "set yrange [-pi:pi]"
			echo "unset logscale y"
			echo "set ytics ('−π' -pi, '−π/2' -pi/2, '0' 0, 'π/2' pi/2, 'π' pi)"
			echo "plot '$t/seq-$r.csv' using 2:4 with lines dt 2 lw 1 lc rgb '#555555' title 'closed form', \\"
			echo "  '$t/seq-$r.csv' using 2:3 with linespoints pt 7 ps 0.6 lw 1 lc rgb '$color' title 'runs'"
			echo "set title 'r = $r: |tan(Δ_n/2)| / |tan(Δ_0/2)| (closed form: r^n)'"
			echo "set ylabel 'ratio (log scale)'"
			echo "set logscale y"
			echo "set yrange [1e-3:3]"
			echo "set ytics auto"
			echo "plot $r**x with lines lw 2 lc rgb 'black' title 'r^n = $r^n', \\"
			echo "  '$t/seq-$r.csv' using 2:(\$5 > 0 ? \$5 : 1/0) with linespoints pt 7 ps 0.6 lw 1 lc rgb '$color' title 'runs'"
		done
		echo "unset multiplot"
	} >"$t/n.gp"
	fig_gnuplot "$t/n.gp"
}

# stats CSV R: "key value" lines for the fragment: runs, points, the map's
# error (rms of Delta_{n+1} - theory over the points; first collisions apart),
# the measured contraction (median of |tan(D_{n+1}/2)| / |tan(D_n/2)| over
# points with |D_n| > 0.1, the closed form's being r), and how often the sign
# alternated (the map: always).
stats() {
	awk -F, -v r="$2" '
		function abs(x) { return x < 0 ? -x : x }
		function wrap(x) { while (x > 3.14159265) x -= 6.2831853; while (x < -3.14159265) x += 6.2831853; return x }
		NR > 1 && $2 == r {
			p++; runs[$1] = 1; e = wrap($9 - $10)
			if ($6 == 0) { s0 += e * e; n0++ } else { s1 += e * e; n1++ }
			ae[++ne] = abs(e)
			if (abs($8) > 0.1) { q[++nq] = abs(sin($9 / 2) / cos($9 / 2)) / abs(sin($8 / 2) / cos($8 / 2)); na++; if ($8 * $9 < 0) alt++
				if (q[nq] > 0) { lq += log(q[nq]); nl++ } }
			if (abs($8) > m) m = abs($8)
		}
		END {
			for (k in runs) nr++
			for (i = 2; i <= ne; i++) { v = ae[i]; for (j = i - 1; j > 0 && ae[j] > v; j--) ae[j + 1] = ae[j]; ae[j + 1] = v }
			printf "median_err %s\n", ne ? sprintf("%.3f", ae[int((ne + 1) / 2)]) : "-"
			for (i = 2; i <= nq; i++) { v = q[i]; for (j = i - 1; j > 0 && q[j] > v; j--) q[j + 1] = q[j]; q[j + 1] = v }
			printf "runs %d\npoints %d\nmax_delta %.2f\n", nr, p, m
			printf "rms_first %s\nrms_rest %s\n", n0 ? sprintf("%.2f", sqrt(s0 / n0)) : "-", n1 ? sprintf("%.2f", sqrt(s1 / n1)) : "-"
			printf "contraction %s\nalternate %s\n", nq ? sprintf("%.2f", q[int((nq + 1) / 2)]) : "-", na ? sprintf("%d of %d", alt, na) : "-"
			printf "q25 %s\nq75 %s\n", nq ? sprintf("%.2f", q[int(nq / 4) + 1]) : "-", nq ? sprintf("%.2f", q[int(3 * nq / 4) + 1]) : "-"
			printf "geomean %s\n", nl ? sprintf("%.3f", exp(lq / nl)) : "-"
		}' "$1"
}

fragment() {
	local csv=$1 runs=$2 a b
	a=$(stats "$csv" 0.67) b=$(stats "$csv" 0.9)
	v() { awk -v k="$2" '$1 == k { $1 = ""; sub(/^ /, ""); print }' <<<"$1"; }
	row() { printf '| %s | %s | %s |\n' "$1" "$2" "$3"; }
	# compound STATS R: tan(D/2) after 20 collisions, measured (geometric mean) against r^20
	compound() { awk -v g="$(v "$1" geomean)" -v r="$2" 'BEGIN { if (g == "-") print "-"; else printf "%.3g of its start against the closed form'"'"'s %.3g", g ^ 20, r ^ 20 }'; }
	local secs
	secs=$(awk 'NR == 1 { for (i = 1; i <= NF; i++) if ($i ~ /^seconds=/) { sub("seconds=", "", $i); print $i } }' "$runs"/*/run.info 2>/dev/null |
		sort -g | awk '{ a[NR] = $1 } END { if (NR) printf "%.1f", a[int((NR + 1) / 2)] }')
	cat <<EOF
## The return map at d̃ = 0 (the paper's Fig. 5a)

![Δₙ₊₁ against Δₙ at every collision, at d̃ = 0, beside the closed form](figures/returnmap.png)

**What ran.** The pair rig of the figure above with both bases on one spot (d̃ = 0), at r = 0.67
and 0.9, $SECONDS_RUN s of simulated time each (${secs:-?} s of wall time, median). At d̃ = 0 the
clock presses the bodies together for half of every period, so a phase difference set on a
sinusoid is lost before the switch: the robots start on the full sinusoid (0.8 rad) at a
phase difference Δ₀ (|Δ₀| from 1 to 3 rad) and switch to the oscillator just after the clock
released the bodies (figures/lib.sh, \`fig_pair_switch\`); the oscillators then meet half a
period later at about Δ₀, and at every crossing of their angles after that. Only the
collisions after the switch are the map's. The daemons' frequency estimate is not known yet
at the first of them: each log is analysed again with \`--frequency\` set to the frequency
the first analysis measured, which gives Δ at every collision (\`undulate-analyze\`'s return
map: Δ just before the first collision of each contact, collisions less than 0.1 s apart
being one contact).

| | r = 0.67 | r = 0.9 |
|---|---|---|
EOF
	row "runs / collisions (points)" "$(v "$a" runs) / $(v "$a" points)" "$(v "$b" runs) / $(v "$b" points)"
	row "largest \\|Δₙ\\| measured" "$(v "$a" max_delta)" "$(v "$b" max_delta)"
	row "Δₙ₊₁ − the closed form: median \\|error\\|; rms from the first collision (n = 0) / the later ones" "$(v "$a" median_err); $(v "$a" rms_first) / $(v "$a" rms_rest) rad" "$(v "$b" median_err); $(v "$b" rms_first) / $(v "$b" rms_rest) rad"
	row "\\|tan(Δₙ₊₁/2)\\| / \\|tan(Δₙ/2)\\| for \\|Δₙ\\| > 0.1 (theory: r): median (quartiles); geometric mean" "$(v "$a" contraction) ($(v "$a" q25)–$(v "$a" q75)); $(v "$a" geomean)" "$(v "$b" contraction) ($(v "$b" q25)–$(v "$b" q75)); $(v "$b" geomean)"
	row "the sign of Δ flipped at the collision (theory: always)" "$(v "$a" alternate)" "$(v "$b" alternate)"
	cat <<EOF

![Δₙ against n from each run's first collision, beside 2·atan((−r)ⁿ·tan(Δ₀/2)); below, |tan(Δₙ/2)| against rⁿ](figures/returnmap-n.png)

**Beside the theory and the paper.** theory.md: at d̃ = 0 the map is Δₙ₊₁ = −2·atan(r·tan(Δₙ/2)),
so every collision multiplies tan(Δ/2) by −r and the pair synchronizes in phase at a rate set
by r (the paper prints the closed form with a leading minus; iterating the map gives the
form plotted, theory.md and tools/analyze/README.md). The measured contraction of
tan(Δ/2) per collision (the table; its geometric mean is what compounds over the sequence,
the lower panels) against r = 0.67 and 0.9: where it is above r, the pair synchronizes more
slowly than the phase model says. Compounded over 20 collisions: $(compound "$a" 0.67) at r = 0.67,
$(compound "$b" 0.9) at r = 0.9. Where the points leave the curve:
the model's oscillators keep one amplitude, while a collision here takes amplitude too and
the oscillator regains it over the next half period; at small Δ the analyser's phase (from
the angle and the daemon's speed estimate, 100 samples a second) is uncertain by a few
hundredths of a radian, which the ratio of tangents magnifies (hence |Δₙ| > 0.1 above).
Every point is in [figures/returnmap.csv](figures/returnmap.csv).
EOF
}

case "${1:-}" in
jobs|run|merge|seconds) cmd=$1; shift; "$cmd" "$@" ;;
*) echo "usage: $(basename "$0") jobs [--quick] | run OUTDIR R DELTA0 SEED SECONDS | merge RUNS_DIR FIGDIR | seconds" >&2; exit 2 ;;
esac
