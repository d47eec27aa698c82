#!/usr/bin/env bash
# figures_pair_merge.sh — the pair module's merge (figures/pair/fig.sh) on
# results made up here, no runs: what its page section says of the controls
# comes from the control runs (the ctrl- lines of its jobs) and nothing
# else. A series' last runs are set just below d̃ = 1 and read just above it
# at the free amplitude (d̃ is the separation over twice the amplitude the
# runs without contact swing at, below the scenario's 0.8): they are not
# controls, and the table, which counts d̃ ≤ 1, says it leaves them out.
# (docs/FIGURES.md once said "12 runs at d̃ = 1.0" of 4 controls at d̃ = 2
# and 8 such runs.)
. "$(dirname "$0")/../lib.sh"
F="$top/figures/pair/fig.sh"
command -v gnuplot >/dev/null 2>&1 || tap_skip_all "gnuplot is not installed (Debian: gnuplot-nox)"
[ -x "$B/undulate-analyze" ] || tap_skip_all "undulate-analyze is not built"

# run ID R DSEP_SET DELTA0 CLASS DELTA_FINAL COLLISIONS: one run's result.csv
# (figures/pair/fig.sh's RESULT_HEADER), both joints at 0.76 rad
run() {
	mkdir -p "$T/runs/$1"
	{
		echo "run,r,dsep_set,delta0,seed,seconds,class,delta_final,spread,dsep_final,amp_left,amp_right,freq,collisions,window_collisions,last_collision_t,delta_first,swing_min,sim_speed,wall_s,switch_s"
		awk -v id="$1" -v r="$2" -v d="$3" -v d0="$4" -v c="$5" -v df="$6" -v n="$7" 'BEGIN {
			printf "%s,%s,%s,%s,1,40,%s,%s,0.05,%.6f,0.76,0.76,0.8,%d,0,%s,,1.52,30,1.5,3\n",
				id, r, d, d0, c, df, d * 0.8 / 0.76, n, n ? "7.5" : "" }'
	} >"$T/runs/$1/result.csv"
}
for i in $(seq 0 39); do
	d=$(awk -v i="$i" 'BEGIN { printf "%.4f", (i + 0.5) / 40 }')
	if [ "$i" -lt 12 ]; then run "$(printf 'r067-%04d' "$i")" 0.67 "$d" 1.0 compatible 0.3 5
	else run "$(printf 'r067-%04d' "$i")" 0.67 "$d" 3.0 anti-phase 3.1 $((i < 38 ? 9 : 0)); fi
done
for i in $(seq 0 9); do
	run "$(printf 'r090-%04d' "$i")" 0.9 "$(awk -v i="$i" 'BEGIN { printf "%.4f", (i + 0.5) / 10 * 0.8 }')" 0.5 in-phase 0.02 4
done
run ctrl-00 0.67 2 -1.0 compatible -1.05 0
run ctrl-01 0.67 2 1.0 compatible 1.10 0

"$F" merge "$T/runs" "$T/fig" >"$T/merge.log" 2>&1
rc=$?
if [ "$rc" = 0 ] && [ -s "$T/fig/pair.md" ]; then tap_ok "merge of 52 made-up runs exits 0"
else tap_fail "merge of 52 made-up runs exits 0" "exit $rc: $(tail -n 3 "$T/merge.log")"; fi
ctrl=$(grep -m1 '^the paper.s: ' "$T/fig/pair.md" | cut -c1-90)
tap_check "the controls: the two ctrl- runs at d̃ = 2, 2.105 at the free amplitude, no collision ($ctrl)" \
	grep -q 'the paper.s: 2 runs at d̃ = 2 as set (2.105 at the free amplitude): 0 collisions, the phase difference kept within 0.10 rad of its start' "$T/fig/pair.md"
tap_check "the series' two runs set at 0.9625-0.9875 that read above 1 are named as left out of the table" \
	grep -q '2 runs of the series, set at d̃ = 0.9625–0.9875, read 1.013–1.039 and are left out (0 collisions)' "$T/fig/pair.md"
tap_check "the table counts the 38 runs at r = 0.67 with d̃ ≤ 1 and the 10 at r = 0.9" \
	grep -q '^| runs (d̃ ≤ 1) | 38 | 10 |$' "$T/fig/pair.md"
# merge without its two folders: the module's usage line and exit 2, as every
# module's (pair and returnmap once stopped on bash's "unbound variable", exit 1)
for m in pair returnmap heatmap steady rows; do
	tap_refused "$m:" "$m merge without RUNS_DIR FIGDIR" "$top/figures/$m/fig.sh" merge
done
tap_done
