#!/usr/bin/env bash
# scripts/fuzz.sh — run every libFuzzer target (build/fuzz/fuzz_*) for a fixed
# number of inputs and print one line per target: executions, crashes, time.
#
#   make fuzz                         # the figures in the README
#   FUZZ_RUNS=100000 make fuzz        # a quick pass (every target, N inputs)
#   FUZZ_ONLY=daemon make fuzz        # targets whose name contains "daemon"
#
# Targets and their input counts: the packet parsers (1.0 and 2.0) 10 M (the bytes every
# servo reply and every simulated request go through), every LCM message type as
# it reaches the monitors (fuzz_web_feed) 10 M, a whole log through the analyser
# (fuzz_analyze_log, files written per input) 20 000, every other parser of
# outside input 2 M. Seed inputs, when a target has some, are in
# tests/fuzz/seeds/<target>/; the corpus grows in build/fuzz/corpus/<target>/.
# A crash leaves its input in build/fuzz/crash-<target>-* and fails the run.
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$here/$BUILD" ;; esac
dir="$BUILD/fuzz"
only=${FUZZ_ONLY:-}
failed=0
printf '%-32s %12s %8s %8s\n' target executions crashes seconds
for bin in "$dir"/fuzz_*; do
	[ -x "$bin" ] || continue
	name=$(basename "$bin")
	[ -n "$only" ] && [[ "$name" != *$only* ]] && continue
	runs=${FUZZ_RUNS:-}
	if [ -z "$runs" ]; then
		case "$name" in
		fuzz_protocol_parser|fuzz_protocol_parser2|fuzz_web_feed) runs=10000000 ;;
		# a whole analysis into files per input: ~20 a second
		fuzz_analyze_log) runs=20000 ;;
		*) runs=2000000 ;;
		esac
	fi
	corpus="$dir/corpus/$name"
	mkdir -p "$corpus"
	seeds="$here/tests/fuzz/seeds/$name"
	[ -d "$seeds" ] && cp -n "$seeds"/* "$corpus"/ 2>/dev/null
	log="$dir/$name.log"
	start=$(date +%s)
	"$bin" -runs="$runs" -max_len=4096 -print_final_stats=1 -artifact_prefix="$dir/crash-$name-" \
		"$corpus" >"$log" 2>&1
	rc=$?
	secs=$(( $(date +%s) - start ))
	execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
	crashes=0
	if [ $rc -ne 0 ]; then
		crashes=1
		failed=1
	fi
	printf '%-32s %12s %8s %8s\n' "$name" "${execs:-?}" "$crashes" "$secs"
	if [ $rc -ne 0 ]; then
		grep -E 'ERROR|SUMMARY|crash-' "$log" | head -5 | sed 's/^/    /'
	fi
done
exit $failed
