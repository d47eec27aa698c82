#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# figures_driver.sh — `make figures`'s driver (scripts/figures.sh): its
# modules in the page's order, each with a tiny set of runs (FIG_TINY=1; the
# rows, channel and forces ones run in figures_modules.sh); and on a tiny
# set of runs (FIG_TINY=1: three short pair-rig runs and two at d~ = 0, 8-14
# s of simulated time each, in lockstep): the runs exported as independent
# command lines, run by GNU parallel here as a cluster would run them (one
# line also through the Slurm array script, with the variables Slurm sets),
# merged into figures whose PNGs are counted for data pixels
# (tests/tools/pngdata) and whose CSVs hold the runs; the local path (GNU
# parallel inside, progress, the page); and bad input: a clear message and a
# non-zero exit each.
source "$(dirname "$0")/../lib.sh"

command -v parallel >/dev/null 2>&1 || tap_skip_all "GNU parallel is not installed (scripts/deps.sh installs it)"
command -v gnuplot >/dev/null 2>&1 || tap_skip_all "gnuplot is not installed (scripts/deps.sh installs it)"
PNGDATA="$BUILD/tests/tools/pngdata"
[ -x "$PNGDATA" ] || tap_skip_all "$PNGDATA is not built (make)"

F="$top/scripts/figures.sh"
# FIG_TINY=1: each module's tiny set; --only: this test's two modules (the
# others' tests are theirs, and a module that ignored FIG_TINY would run its
# whole set here).
export FIG_TINY=1
ONLY=pair,returnmap
# The runs' LCM ports: this test's block of the tools' range (lib.sh), moved
# by TEST_PORT_OFFSET like every test's.
export FIG_PORT_LO FIG_PORT_SPAN=8
FIG_PORT_LO=$(lcm_port 7780)

# ---- every module: the page's order, a tiny set each -------------------------------------
order=$("$F" list 2>&1 | awk '{ printf "%s ", $1 }')
tap_check "list: the twelve modules in the page's order (heatmap steady pair returnmap rows lattice mobility channel swimmer channel-plane forces forces-plane)" \
	test "$order" = "heatmap steady pair returnmap rows lattice mobility channel swimmer channel-plane forces forces-plane "
"$F" --export-jobs "$T/tiny.txt" --runs "$T/tinyruns" >"$T/tiny.out" 2>&1
counts=$(awk '{ n[$3]++ } END { for (m in n) printf "%s %d\n", m, n[m] }' "$T/tiny.txt" 2>/dev/null | sort | tr '\n' ' ')
tap_check "FIG_TINY=1: every module a tiny set, 1-3 runs ($counts)" awk -v c="$counts" 'BEGIN {
	n = split(c, f, " "); if (n != 24) exit 1
	for (i = 2; i <= n; i += 2) if (f[i] < 1 || f[i] > 3) exit 1 }'

# the longest runs first (each module's `seconds`), so that no core idles
# while the last long runs finish: a module's runs never follow a module's
# whose runs are shorter
secs_of() { FIG_TINY=0 "$top/figures/$1/fig.sh" seconds; }
seq_secs=$(awk '{ print $3 }' "$T/tiny.txt" | uniq | while read -r m; do echo "$m $(secs_of "$m")"; done | tr '\n' ' ')
tap_check "the exported runs go longest first, by module ($seq_secs)" awk -v s="$seq_secs" 'BEGIN {
	n = split(s, f, " "); if (n != 24) exit 1
	for (i = 4; i <= n; i += 2) if (f[i] + 0 > f[i - 2] + 0) exit 1 }'

# ---- exported jobs, run by GNU parallel as on a cluster --------------------------------
"$F" --export-jobs "$T/jobs.txt" --runs "$T/runs" --only "$ONLY" >"$T/export.out" 2>&1
rc=$?
n=$(grep -c '^scripts/figures.sh run ' "$T/jobs.txt" 2>/dev/null)
if [ "$rc" = 0 ] && [ "$n" = 5 ] && [ "$(wc -l <"$T/jobs.txt")" = 5 ]; then
	tap_ok "--export-jobs: 5 independent command lines (3 pair, 2 returnmap)"
else
	tap_fail "--export-jobs: 5 independent command lines" "exit $rc, $n run lines: $(cat "$T/export.out" "$T/jobs.txt" 2>&1 | head -10)"
fi
tap_check "--export-jobs: every line has its own output folder and seed" \
	test "$(awk '{ print $4 }' "$T/jobs.txt" | sort -u | wc -l)" = 5
tap_check "--export-jobs: the same lines every time (seeds from the runs, not \$RANDOM)" \
	bash -c "'$F' --export-jobs '$T/jobs2.txt' --runs '$T/runs' --only '$ONLY' >/dev/null && cmp -s '$T/jobs.txt' '$T/jobs2.txt'"

(cd "$top" && parallel --jobs 3 --joblog "$T/joblog" <"$T/jobs.txt") >"$T/parallel.out" 2>&1
bad=$(awk -F'\t' 'NR > 1 && $7 != 0' "$T/joblog" | wc -l)
done_n=$(awk -F'\t' 'NR > 1' "$T/joblog" | wc -l)
if [ "$done_n" = 5 ] && [ "$bad" = 0 ]; then
	tap_ok "GNU parallel ran the 5 lines from the checkout, each exit 0"
else
	tap_fail "GNU parallel ran the 5 lines, each exit 0" "$done_n done, $bad failed: $(head -5 "$T/parallel.out")"
fi
tap_check "each run wrote its result.csv and nothing large (no LCM log kept)" bash -c "
	[ \$(ls '$T'/runs/*/*/result.csv | wc -l) = 5 ] && [ -z \"\$(find '$T/runs' -name demo.lcmlog)\" ]"

# one line again, as task 2 of a Slurm array (the variables Slurm sets)
first=$(sed -n 2p "$T/jobs.txt" | awk '{ print $4 }')
rm -f "$T/runs/${first#"$T/runs/"}/result.csv"
(cd "$T" && SLURM_ARRAY_TASK_ID=2 SLURM_SUBMIT_DIR="$top" "$top/scripts/figures-slurm.sh" "$T/jobs.txt") >"$T/slurm.out" 2>&1
rc=$?
if [ "$rc" = 0 ] && [ -s "$first/result.csv" ]; then
	tap_ok "figures-slurm.sh: array task 2 ran line 2 (its result.csv again)"
else
	tap_fail "figures-slurm.sh: array task 2 ran line 2" "exit $rc: $(tail -5 "$T/slurm.out")"
fi
(SLURM_ARRAY_TASK_ID=99 "$top/scripts/figures-slurm.sh" "$T/jobs.txt") 2>"$T/slurm2.err"
rc=$?
tap_check "figures-slurm.sh: a task beyond the file: exit 2, saying so" bash -c "[ $rc = 2 ] && grep -q 'has no line 99' '$T/slurm2.err'"

# ---- merged: the figures have their data ---------------------------------------------
"$F" --merge "$T/runs" --only "$ONLY" --out "$T/docs" >"$T/merge.out" 2>&1
rc=$?
if [ "$rc" = 0 ] && [ -s "$T/docs/FIGURES.md" ]; then
	tap_ok "--merge: exit 0, FIGURES.md written"
else
	tap_fail "--merge: exit 0, FIGURES.md written" "exit $rc: $(tail -8 "$T/merge.out")"
fi
# each module's pictures as its section shows them (a glob on the name once
# listed channel-plane's under channel)
tap_check "--merge names the pictures of each figure's section: pair (pair.png pair-onset.png)" \
	grep -q '^figures: pair: 3 of 3 runs merged into .* (pair.png pair-onset.png)$' "$T/merge.out"
# drawn NAME FILE MIN: at least MIN data pixels (coloured, not the frame's greys)
drawn() {
	local px
	px=$("$PNGDATA" "$2" 2>&1 | sed -n 's/.* coloured=\([0-9]*\).*/\1/p')
	if [ "${px:-0}" -ge "$3" ]; then tap_ok "$1 ($px data pixels)"; else tap_fail "$1" "${px:-no count}: $("$PNGDATA" "$2" 2>&1)"; fi
}
# The theory's curves alone draw thousands of coloured pixels, so the runs
# are counted by their own colours: a run's point (ps 0.5 at this size) is
# about 9 pixels, and the key shows one sample point per panel (two panels).
drawn "pair.png: the theory's fixed points and the runs" "$T/docs/figures/pair.png" 3000
drawn "pair-onset.png: |f'(pi)|, the cumulative and binned shares" "$T/docs/figures/pair-onset.png" 3000
drawn "returnmap.png: the points beside the closed form" "$T/docs/figures/returnmap.png" 2000
drawn "returnmap-n.png: Delta_n against n" "$T/docs/figures/returnmap-n.png" 2000
rgb() { "$PNGDATA" --rgb "$1" "$2" | sed -n 's/.* matching=\([0-9]*\).*/\1/p'; }
px=$(rgb a50f15 "$T/docs/figures/pair.png")
tap_check "pair.png: the anti-phase run (d~ = 0.7 from 3.0) drawn in its class's colour ($px pixels: 18 of them the key's)" \
	test "${px:-0}" -ge 23
# the measured series of r = 0.67 (the theory's lines are a lighter blue);
# a series without runs is left out, key sample and all
px=$(rgb 1f77b4 "$T/docs/figures/pair-onset.png")
tap_check "pair-onset.png: the runs at r = 0.67 drawn ($px pixels of their colour)" test "${px:-0}" -ge 40
tap_check "pair.csv: the three runs, with d~ and the map's end" awk -F, '
	NR == 1 { ok = $22 == "dsep" && $23 == "map_final"; next } { n++ } END { exit !(ok && n == 3) }' "$T/docs/figures/pair.csv"
tap_check "pair.csv: the run at d~ = 0.7 from 3.0 ended in anti-phase, as the map says" awk -F, '
	$1 == "r067-t0" { exit !($7 == "anti-phase" && ($23 > 3.14 || $23 < -3.14)) }' "$T/docs/figures/pair.csv"
tap_check "returnmap.csv: collisions of both runs, each with the theory's next Delta" awk -F, '
	NR > 1 && $10 != "" { r[$2]++ } END { exit !(r["0.67"] >= 3 && r["0.9"] >= 3) }' "$T/docs/figures/returnmap.csv"
tap_check "FIGURES.md: both sections, their pictures linked, the runs counted" bash -c "
	grep -q '(figures/pair.png)' '$T/docs/FIGURES.md' && grep -q '(figures/returnmap.png)' '$T/docs/FIGURES.md' &&
	grep -qE '^\| \[pair\]\(#pair\) \| 3 \(0\)' '$T/docs/FIGURES.md' && grep -qE '^\| \[returnmap\]\(#returnmap\) \| 2 \(0\)' '$T/docs/FIGURES.md'"

# ---- here, through the driver: progress, then the page -------------------------------
"$F" --only returnmap --jobs 2 --runs "$T/runs2" --out "$T/docs2" >"$T/local.out" 2>&1
rc=$?
tap_check "scripts/figures.sh --only returnmap: exit 0, its progress says 2/2 runs done" \
	bash -c "[ $rc = 0 ] && grep -q '2/2 runs done' '$T/local.out'"
tap_check "the page has the figure it made and no other" bash -c "
	grep -q '(figures/returnmap.png)' '$T/docs2/FIGURES.md' && ! grep -q 'figures/pair.png' '$T/docs2/FIGURES.md'"

# ---- bad input -------------------------------------------------------------------------------
"$F" --only nosuch --runs "$T/x" 2>"$T/e1"; rc=$?
tap_check "--only nosuch: exit 1, naming the modules there are" bash -c "[ $rc = 1 ] && grep -q \"no module 'nosuch'\" '$T/e1' && grep -q pair '$T/e1'"
"$F" --jobs 0 2>"$T/e2"; rc=$?
tap_check "--jobs 0: exit 1, saying so" bash -c "[ $rc = 1 ] && grep -q 'jobs' '$T/e2'"
GNUPLOT=/nonexistent/gnuplot "$F" --merge "$T/runs" --only "$ONLY" --out "$T/docs3" 2>"$T/e3"; rc=$?
tap_check "gnuplot missing: exit 1, 'gnuplot is not installed'" bash -c "[ $rc = 1 ] && grep -q 'gnuplot is not installed' '$T/e3'"
mkdir -p "$T/empty/pair"
"$F" --merge "$T/empty" --only pair --out "$T/docs4" >/dev/null 2>"$T/e4"; rc=$?
tap_check "--merge of runs without results: exit 1, saying so" bash -c "[ $rc = 1 ] && grep -q 'no run' '$T/e4'"
"$F" run pair "$T/bad" 0.67 notanumber 1.0 5 10 2>"$T/e5"; rc=$?
tap_check "a run with a bad argument: non-zero exit and one line why" bash -c "[ $rc != 0 ] && [ \$(wc -l <'$T/e5') = 1 ] && grep -q 'failed' '$T/e5'"
"$F" run pair "$T/bad2" 0.67 1.5 2>"$T/e6"; rc=$?
tap_check "a run with too few arguments: non-zero exit, saying what it wants" bash -c "[ $rc != 0 ] && grep -q 'want OUTDIR' '$T/e6'"
tap_done
