#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# run.sh: heavy — its demos keep a core busy (tests/run.sh)
# e2e_demo_disk.sh — what `make demo` keeps: under 20 MB a minute for its ten
# robots, and nothing the analysis needs lost. make demo passes
# DEMO_COMPRESS=1: the LCM log is kept xz-compressed (every message) and
# so are the two per-sample CSVs (every row); undulate-analyze reads the
# compressed log as it reads a plain one, to the same results; and the plot
# command it prints writes the plots without a second copy of the CSVs.
# In lockstep (the same run on any machine): 30 s of the default scene.
source "$(dirname "$0")/../lib.sh"

demo="$top/scripts/demo.sh"
mkdir -p "$T/tmp"
url=$(lcm_url $((7866 + $$ % 3)))
seconds=30
# the budget: 20 MB a minute, in kB for this run
budget_kb=$((20 * 1024 * seconds / 60))

if grep -qE '^demo:' "$top/Makefile" && grep -A3 -E '^demo:' "$top/Makefile" | grep -q 'DEMO_COMPRESS=1'; then
	tap_ok "make demo keeps its run compressed (DEMO_COMPRESS=1)"
else
	tap_fail "make demo keeps its run compressed (DEMO_COMPRESS=1)" "$(grep -A3 -E '^demo:' "$top/Makefile")"
fi

env BUILD="$BUILD" DEMO_COMPRESS=1 DEMO_SECONDS=$seconds TMPDIR="$T/tmp" DEMO_OUT="$T/out" "$demo" --lockstep --seed 3 \
	--lcm-url "$url" >"$T/demo.log" 2>&1
rc=$?
kb=$(du -sk "$T/out" | cut -f1)
echo "# kept: $kb kB for $seconds s of ten robots ($((kb * 60 / seconds / 1024)) MB a minute); the largest:"
ls -lS "$T/out" | head -n 8 | sed 's/^/#   /'
if [ "$rc" = 0 ] && [ "$kb" -lt "$budget_kb" ]; then
	tap_ok "kept $kb kB for $seconds s: under 20 MB a minute ($budget_kb kB)"
else
	tap_fail "kept under 20 MB a minute" "exit $rc, $kb kB >= $budget_kb kB; $(tail -n 5 "$T/demo.log")"
fi
if [ -s "$T/out/demo.lcmlog.xz" ] && [ ! -e "$T/out/demo.lcmlog" ] && [ -s "$T/out/states.csv.xz" ] &&
	[ -s "$T/out/phase_diff.csv.xz" ] && [ ! -e "$T/out/states.csv" ] && xz -t "$T/out/demo.lcmlog.xz" "$T/out/states.csv.xz"; then
	tap_ok "the log and the per-sample CSVs are kept xz-compressed"
else
	tap_fail "the log and the per-sample CSVs are kept xz-compressed" "$(ls "$T/out")"
fi
# nothing lost: every state row is there (the summary counts them), and the
# compressed log analyses to the same results as the log it was
rows=$(xz -dc "$T/out/states.csv.xz" 2>/dev/null | tail -n +2 | wc -l)
"$B/undulate-analyze" "$T/out/demo.lcmlog.xz" --out "$T/again" --quiet >"$T/again.out" 2>&1; arc=$?
if [ "$arc" = 0 ] && [ "$rows" -gt 1000 ] && cmp -s <(xz -dc "$T/out/states.csv.xz") "$T/again/states.csv" &&
	diff <(grep -v '^log:' "$T/out/summary.txt") <(grep -v '^log:' "$T/again/summary.txt") >/dev/null; then
	tap_ok "undulate-analyze reads demo.lcmlog.xz: the same states.csv ($rows rows) and summary"
else
	tap_fail "undulate-analyze reads demo.lcmlog.xz to the same results" "exit $arc; $(tail -n 3 "$T/again.out"); $rows rows"
fi
# the plot command as printed: plots, and no second copy of the CSVs
next=$(sed -n 's/^Next, the plots:  //p' "$T/demo.log")
if [ -n "$next" ] && $next >"$T/next.out" 2>&1 && [ -f "$T/out/plots/angles.png" ] &&
	[ -z "$(find "$T/out/plots" -name 'states.csv*' -o -name 'phase_diff.csv*' -o -name 'plane.csv*' -o -name 'collisions.csv*')" ]; then
	tap_ok "the plot command draws the plots without copying the CSVs ($(du -sk "$T/out/plots" | cut -f1) kB in plots/)"
else
	tap_fail "the plot command draws the plots without copying the CSVs" "'$next': $(tail -n 3 "$T/next.out"); $(ls "$T/out/plots" 2>&1 | tr '\n' ' ')"
fi
tap_done
