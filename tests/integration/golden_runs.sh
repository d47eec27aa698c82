#!/usr/bin/env bash
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# golden_runs.sh — the golden runs (tests/golden/README.md): each
# tests/golden/NAME.run in lockstep (scripts/golden.sh --run), and what it gave
# compared with the committed tests/golden/NAME.chk (scripts/golden.sh
# --compare). sim_lockstep shows that a lockstep run is the same byte for byte
# every time; this holds it to what it was, so that a change of behaviour
# cannot pass unseen. A failure lists every value that changed, old -> new,
# the column named ("meanD [3.1409 -> 3.0012] spread"); a change that was
# meant is recorded with `make golden` and committed with it.
# The runs go two at a time (GOLDEN_JOBS), each on its own LCM port; their
# wall time is printed, not asserted (timing is not behaviour).
. "$(dirname "$0")/../lib.sh"

golden="$top/tests/golden"
jobs=${GOLDEN_JOBS:-2}
# LCM ports 7680-7689: one per run, so at most this many runs.
PORT0=7680
MAX_RUNS=10
# Wall seconds one run may take before it is called hung (a 30 s pair run
# took 2-3 s alone, 8 s at load 9 on 2 cores).
RUN_TIMEOUT_S=120

names=()
for f in "$golden"/*.run; do [ -f "$f" ] && names+=("$(basename "$f" .run)"); done
if [ ${#names[@]} -eq 0 ] || [ ${#names[@]} -gt $MAX_RUNS ]; then
	tap_fail "tests/golden holds 1 to $MAX_RUNS runs" "found ${#names[@]}: each needs an LCM port of its own ($PORT0..$((PORT0 + MAX_RUNS - 1)))"
	tap_done; exit
fi
for f in "$golden"/*.chk; do
	[ -f "$f" ] || continue
	n=$(basename "$f" .chk)
	[ -f "$golden/$n.run" ] || tap_fail "$n.chk: its run is there" "tests/golden/$n.chk has no $n.run: remove the .chk with the run"
done

# ---- the runs, JOBS at a time ------------------------------------------------------
# slot_free: fewer than JOBS runs going (a run not started yet is not alive)
slot_free() {
	local n=0 x var
	for x in "${names[@]}"; do
		var="pid_run_$x"
		[ -n "${!var:-}" ] && alive "run_$x" && n=$((n + 1))
	done
	[ "$n" -lt "$jobs" ]
}
t0=$(date +%s%N)
for i in "${!names[@]}"; do
	wait_for $RUN_TIMEOUT_S slot_free
	spawn "run_${names[$i]}" "$top/scripts/golden.sh" --run "${names[$i]}" "$T" "$(lcm_url $((PORT0 + i)))"
done
exited() { ! alive "$1"; }
for n in "${names[@]}"; do
	wait_for $RUN_TIMEOUT_S exited "run_$n"
	stop "run_$n" >/dev/null   # a run past its time is stopped here: SIGTERM, and demo.sh stops its programs
	eval "rc_$n=$stop_rc"
done
echo "# ${#names[@]} golden runs in $(( ($(date +%s%N) - t0) / 1000000 )) ms of wall time, $jobs at a time"

# ---- each compared with its expectation --------------------------------------------------
for n in "${names[@]}"; do
	var="rc_$n"
	if [ "${!var}" != 0 ]; then
		tap_fail "$n: the lockstep run ran" "golden.sh --run exit ${!var}: $(tail -n 12 "$T/$n.out" 2>/dev/null) $(tail -n 3 "$T/run_$n.log")"
		continue
	fi
	out=$("$top/scripts/golden.sh" --compare "$n" "$T/$n.rec")
	crc=$?
	last=$(echo "$out" | tail -n 1 | sed 's/^= //')
	case "$crc" in
	0) tap_ok "$n: as recorded in tests/golden/$n.chk ($last)" ;;
	3) tap_ok "$n: as recorded in tests/golden/$n.chk ($last)"
	   echo "$out" | sed '$d' | sed 's/^/# /' ;;
	*) tap_fail "$n: as recorded in tests/golden/$n.chk" "$(echo "$out" | sed '$d')
$last
If the change was meant: make golden (or scripts/golden.sh --update $n), and commit tests/golden/$n.chk with it." ;;
	esac
done

# ---- the comparison fails where it should ------------------------------------------------
# On the first run's record, changed by hand: a number moved by 0.01 is named
# with both values; a last digit that rounded the other way passes; other
# digests fail on the platform of the expectation and are only reported on another.
rec="$T/${names[0]}.rec"
# edit WHAT: the record with one change: "meanD+0.01", "meanD+unit" (its last
# digit), "digest" (the states log's), "platform"
edit() {
	awk -v what="$1" '
		what == "platform" && $1 == "platform" { print "platform another-cpu; another compiler; another libc"; next }
		what == "digest" && $1 == "sha256.states.csv" { print $1, "0" substr($2, 2); next }
		what ~ /^meanD/ && !done && match($0, / meanD=-?[0-9]+\.[0-9]+/) {
			v = substr($0, RSTART + 7, RLENGTH - 7); d = length(v) - index(v, ".")
			nv = sprintf("%." d "f", v + (what == "meanD+unit" ? 10 ^ -d : 0.01))
			print substr($0, 1, RSTART + 6) nv substr($0, RSTART + RLENGTH); done = 1; next
		}
		{ print }' "$rec"
}
cmp_edit() { "$top/scripts/golden.sh" --compare "$T/expect.chk" "$T/edited.rec" >"$T/cmp.out"; echo $?; }
if [ -f "$rec" ] && grep -q ' meanD=' "$rec"; then
	cp "$rec" "$T/expect.chk"
	old_d=$(grep -m1 -o ' meanD=[^ ]*' "$rec" | cut -d= -f2)
	edit meanD+0.01 >"$T/edited.rec"; rc=$(cmp_edit)
	new_d=$(grep -m1 -o ' meanD=[^ ]*' "$T/edited.rec" | cut -d= -f2)
	if [ "$rc" = 1 ] && grep -qF "meanD $old_d -> $new_d" "$T/cmp.out" && grep -q '^= 1 of [0-9]* values differ' "$T/cmp.out"; then
		tap_ok "a final phase difference moved by 0.01 fails, named with both values ('$(grep -m1 meanD "$T/cmp.out")')"
	else
		tap_fail "a final phase difference moved by 0.01 fails, named with both values" "exit $rc: $(cat "$T/cmp.out")"
	fi
	edit meanD+unit >"$T/edited.rec"; rc=$(cmp_edit)
	if [ "$rc" = 0 ] && ! cmp -s "$rec" "$T/edited.rec"; then
		tap_ok "... moved by one unit of its last digit (a rounding the other way), it passes"
	else
		tap_fail "... moved by one unit of its last digit (a rounding the other way), it passes" "exit $rc: $(cat "$T/cmp.out")"
	fi
	edit digest >"$T/edited.rec"; rc=$(cmp_edit)
	if [ "$rc" = 1 ] && grep -q '^sha256.states.csv: ' "$T/cmp.out"; then
		tap_ok "the states log's digest changed, every number the same: it fails on the expectation's platform"
	else
		tap_fail "the states log's digest changed: it fails on the expectation's platform" "exit $rc: $(cat "$T/cmp.out")"
	fi
	edit platform >"$T/expect.chk"; rc=$(cmp_edit)
	if [ "$rc" = 3 ] && grep -q 'informational: recorded on another-cpu' "$T/cmp.out"; then
		tap_ok "... and on another platform it is reported, not failed (exit 3)"
	else
		tap_fail "... and on another platform it is reported, not failed (exit 3)" "exit $rc: $(cat "$T/cmp.out")"
	fi
else
	tap_fail "the first run's record holds a pair's meanD to change" "$(head -n 20 "$rec" 2>&1)"
fi
keep_runs "${names[@]}"
tap_done
