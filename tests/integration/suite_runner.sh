#!/usr/bin/env bash
# suite_runner.sh — tests/run.sh itself, on fake test programs written into a
# temporary directory (UNIT_TESTS_DIR / INTEGRATION_TESTS_DIR point it there):
# what it counts as passed, failed and skipped, its closing line and its exit
# status for a pass, a failure, skips (TAP's, lib.sh's and cmocka's), a TODO,
# a crash, plans that disagree or are missing, a program that prints nothing
# or exits non-zero, and a hang under a short TEST_TIMEOUT.
# SUITE_RUNNER=FILE checks another runner instead, to see that these checks
# catch a wrong one.
. "$(dirname "$0")/../lib.sh"
runner=${SUITE_RUNNER:-$top/tests/run.sh}
lib="$top/tests/lib.sh"

# fake CASE unit|integration NAME <<EOF: a test program of CASE, from stdin:
# an executable test_NAME (in place of a cmocka program) or a script NAME.sh.
fake() {
	local dir="$T/$1/$2" file
	mkdir -p "$dir"
	if [ "$2" = unit ]; then file="$dir/test_$3"; else file="$dir/$3.sh"; fi
	cat >"$file"
	chmod +x "$file"
}

# suite CASE [VAR=VALUE...]: run the runner on CASE's programs alone, with the
# caller's TEST_* settings removed. Leaves $out (its output), $rc, $closing
# (its last line), $secs (how long it took) and $last_case.
out= rc= closing= secs= last_case=
suite() {
	local case=$1; shift
	last_case=$case
	out="$T/$case.out"
	local t0=$(date +%s%N)
	env -u TEST_FILTER -u TEST_LONG -u TEST_TIMEOUT -u CMOCKA_MESSAGE_OUTPUT \
		BUILD="$T/$case/build" UNIT_TESTS_DIR="$T/$case/unit" \
		INTEGRATION_TESTS_DIR="$T/$case/integration" LONG_TESTS_DIR="$T/$case/long" "$@" \
		bash "$runner" >"$out" 2>&1
	rc=$?
	secs=$(( ($(date +%s%N) - t0) / 1000000000 ))
	closing=$(tail -n 1 "$out")
}

# expect NAME CLOSING RC [REGEX [LOG REGEX]]: the last suite's closing line is
# exactly CLOSING, it exited RC, its output matches REGEX, and its log of
# program LOG ($BUILD/test-logs/LOG.log) matches the second REGEX.
expect() {
	local name=$1 want=$2 want_rc=$3 pattern=${4:-} log=${5:-} log_pattern=${6:-} why=""
	[ "$closing" = "$want" ] || why+="closing line '$closing', want '$want'; "
	[ "$rc" = "$want_rc" ] || why+="exit status $rc, want $want_rc; "
	[ -z "$pattern" ] || grep -qE -- "$pattern" "$out" || why+="no /$pattern/ in the output; "
	if [ -n "$log" ]; then
		local f="$T/$last_case/build/test-logs/$log.log"
		grep -qE -- "$log_pattern" "$f" 2>/dev/null || why+="no /$log_pattern/ in $log's log; "
	fi
	if [ -z "$why" ]; then tap_ok "$name"; else tap_fail "$name" "$why"$'\n'"$(tail -n 12 "$out")"; fi
}

# ---- one program at a time -------------------------------------------------------
fake pass integration pass <<EOF
. "$lib"
tap_ok "one"; tap_ok "two"; tap_done
EOF
suite pass
expect "a pass: 2 passed, exit 0" "2 passed, 0 failed, 0 skipped" 0 '^pass +2 passed  \('

fake fail unit fail <<'EOF'
#!/bin/sh
echo "1..2"; echo "ok 1 - a"; echo "not ok 2 - b"; exit 1
EOF
suite fail
expect "a failure: 1 passed, 1 failed, exit 1" "1 passed, 1 failed, 0 skipped" 1 '^ +not ok 2 - b'

fake skip integration skip <<EOF
. "$lib"
tap_ok "runs"
tap_skip "needs a robot" "no hardware here"
echo "ok 3 # SKIP written by hand, no description"
_tap_n=3
tap_done
EOF
suite skip
expect "TAP skips (lib.sh's tap_skip, and by hand) are skips, not passes" \
	"1 passed, 0 failed, 2 skipped" 0 '^skip +1 passed, 2 skipped' skip 'needs a robot # SKIP no hardware here'

fake skipall integration skipall <<EOF
. "$lib"
tap_skip_all "undulated not built"
tap_ok "never reached"; tap_done
EOF
suite skipall
expect "a whole script skipped (tap_skip_all): 1 skipped, exit 0" "0 passed, 0 failed, 1 skipped" 0 \
	'skipall: skipall # SKIP undulated not built'

fake planskip unit planskip <<'EOF'
#!/bin/sh
echo "1..0 # SKIP no serial adapter"
EOF
suite planskip
expect "a plan 1..0 with a SKIP directive: the program is one skip" "0 passed, 0 failed, 1 skipped" 0 'planskip: no serial adapter'

fake cmockaskip unit cmockaskip <<'EOF'
#!/bin/sh
# cmocka 1.1.5 with CMOCKA_MESSAGE_OUTPUT=TAP, a test calling skip()
echo "1..3"; echo "ok 1 - test_a"; echo "not ok 2 # SKIP test_b"; echo "ok 3 - test_c"; echo "# ok - tests"
EOF
suite cmockaskip
expect "cmocka's skip line (not ok N, a SKIP directive, the name) is a skip, not a failure" "2 passed, 0 failed, 1 skipped" 0 \
	'^test_cmockaskip +2 passed, 1 skipped'

fake todo integration todo <<EOF
. "$lib"
tap_ok "holds"; tap_todo "anti-phase through position servos" "|d| 0.2"; tap_done
EOF
suite todo
expect "a TODO is counted apart: 1 passed, exit 0" "1 passed, 0 failed, 0 skipped" 0 \
	'^1 known unmet claim.*$'

fake crash unit crash <<'EOF'
#!/bin/bash
echo "1..2"; echo "ok 1 - a"; kill -SEGV $$
EOF
suite crash
expect "a crash is a failure, named by its signal" "1 passed, 1 failed, 0 skipped" 1 \
	'killed by signal 11' test_crash 'not ok - test_crash: .*killed by signal 11'

fake exit integration exit <<'EOF'
echo "ok 1 - a"; echo "1..1"; exit 3
EOF
suite exit
expect "a non-zero exit without 'not ok' is a failure" "1 passed, 1 failed, 0 skipped" 1 'exited with status 3'

fake planend integration planend <<'EOF'
echo "ok 1 - a"; echo "ok 2 - b"; echo "1..3"
EOF
suite planend
expect "plan at the end says 3, 2 results: a failure, said in log and summary" \
	"2 passed, 1 failed, 0 skipped" 1 \
	'planend: plan says 3 test\(s\), printed 2 result' planend 'not ok - planend: plan says 3 test\(s\), printed 2'

fake planstart unit planstart <<'EOF'
#!/bin/sh
echo "1..1"; echo "ok 1 - a"; echo "ok 2 - b"
EOF
suite planstart
expect "plan at the start says 1, 2 results: a failure" "2 passed, 1 failed, 0 skipped" 1 \
	'test_planstart: plan says 1 test\(s\), printed 2 result'

fake noplan integration noplan <<'EOF'
echo "ok 1 - a"
EOF
suite noplan
expect "results without a plan: a failure, said in log and summary" "1 passed, 1 failed, 0 skipped" 1 \
	'noplan: printed 1 result\(s\) but no plan' noplan 'not ok - noplan: .*no plan'

fake silent unit silent <<'EOF'
#!/bin/sh
exit 0
EOF
suite silent
expect "a program that prints nothing ran no test: a failure" "0 passed, 1 failed, 0 skipped" 1 'test_silent: ran no test'

fake hang integration hang <<'EOF'
echo "ok 1 - started"
sleep 60
echo "1..1"
EOF
suite hang TEST_TIMEOUT=2
expect "a hang is stopped at TEST_TIMEOUT and is a failure" "1 passed, 1 failed, 0 skipped" 1 \
	'hang: .*timed out after 2s'
if [ "$secs" -lt 15 ]; then tap_ok "...and stopped in time (${secs}s for TEST_TIMEOUT=2)"
else tap_fail "hang stopped in time" "the runner took ${secs}s with TEST_TIMEOUT=2"; fi

# a soak says how long it runs: more than TEST_TIMEOUT, never less
fake soak integration soak <<'EOF'
# run.sh: timeout 20
echo "ok 1 - ran its 3 s"
sleep 3
echo "1..1"
EOF
fake soak integration short <<'EOF'
# run.sh: timeout 1
echo "ok 1 - started"
sleep 4
echo "1..1"
EOF
suite soak TEST_TIMEOUT=2
expect "'# run.sh: timeout 20' outlasts TEST_TIMEOUT=2; 'timeout 1' does not shorten it" \
	"2 passed, 1 failed, 0 skipped" 1 'short: .*timed out after 2s'

# A real cmocka program: what its TAP output says for skip(), with two groups
# (two plans, added up).
mkdir -p "$T/cmocka/unit"
if command -v cc >/dev/null && cc -x c -o "$T/cmocka/unit/test_cmocka" - -lcmocka >"$T/cc.log" 2>&1 <<'EOF'
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
static void passes(void **state) { (void)state; }
static void skips(void **state) { (void)state; skip(); }
int main(void)
{
	const struct CMUnitTest one[] = { cmocka_unit_test(passes), cmocka_unit_test(skips) };
	const struct CMUnitTest two[] = { cmocka_unit_test(passes) };
	return cmocka_run_group_tests_name("one", one, NULL, NULL) | cmocka_run_group_tests_name("two", two, NULL, NULL);
}
EOF
then
	suite cmocka
	expect "cmocka's own skip() and two groups: 2 passed, 1 skipped, exit 0" "2 passed, 0 failed, 1 skipped" 0
else
	tap_skip "cmocka's own skip() and two groups" "cannot build a cmocka program: $(head -1 "$T/cc.log")"
fi

# ---- a suite of several, and the filter -------------------------------------------
# copy CASE...: their programs into the mixed suite.
copy() { local c d; for c; do for d in unit integration; do [ -d "$T/$c/$d" ] && mkdir -p "$T/mixed/$d" && cp "$T/$c/$d"/* "$T/mixed/$d/"; done; done; }
copy pass skip todo planskip cmockaskip
suite mixed
expect "a passing suite: the sums, exit 0" "6 passed, 0 failed, 4 skipped" 0
copy planend
suite mixed
expect "one failing program fails the suite, and is listed" "8 passed, 1 failed, 4 skipped" 1 \
	'^  planend: plan says 3'
suite mixed TEST_FILTER=pass
expect "TEST_FILTER runs the programs whose name holds it" "2 passed, 0 failed, 0 skipped" 0
suite mixed TEST_FILTER=nosuchtest
expect "a filter that matches nothing ran no test: exit 1" "0 passed, 0 failed, 0 skipped" 1 'no test program ran'

# ---- side by side: slots, heavy and alone programs ------------------------------------
# Each fake program writes "+ NAME" when it starts and "- NAME" when it ends
# into one file; the most that ran at once, and who ran beside whom, are read
# from it.
spans="$T/spans"
slotted() { # CASE NAME [RUNSH-LINE]: a program that runs SLOT_S seconds (2: long
	# enough that a loaded machine starts three while the first still runs)
	fake "$1" integration "$2" <<EOF
${3:-}
echo "+ $2" >>"$spans"; sleep \${SLOT_S:-2}; echo "- $2" >>"$spans"
echo "ok 1 - $2"; echo "1..1"
EOF
}
# most_at_once [NAME...]: the most programs running at one time (of NAMEs, all if none)
most_at_once() { awk -v only=" $* " 'only == "  " || index(only, " " $2 " ") { n += ($1 == "+") ? 1 : -1; if (n > m) m = n } END { print m + 0 }' "$spans"; }
# beside NAME: the programs that ran at some time while NAME ran
beside() { awk -v me="$1" '
	$1 == "+" { run[$2] = 1; if ($2 == me) { on = 1; for (r in run) if (r != me) seen[r] = 1 } else if (on) seen[$2] = 1 }
	$1 == "-" { delete run[$2]; if ($2 == me) on = 0 }
	END { for (s in seen) printf "%s ", s }' "$spans"; }
for n in l1 l2 l3 l4 l5 l6; do slotted slots "$n"; done
slotted slots h1 '# run.sh: heavy'
slotted slots h2 '# run.sh: heavy'
slotted slots solo '# run.sh: alone'
slotted slots late '# run.sh: long'
: >"$spans"
suite slots TEST_JOBS=3
most=$(most_at_once) heavy=$(most_at_once h1 h2) solo=$(beside solo)
# the order they started in: the runner shows them so (two started at one
# moment may write their "+" lines either way round)
first=$(awk '$2 ~ /^[0-9]+$/ && $3 == "passed" { print $1; exit }' "$out")
second=$(awk '$2 ~ /^[0-9]+$/ && $3 == "passed" { if (++k == 2) { print $1; exit } }' "$out")
if [ "$closing" = "10 passed, 0 failed, 0 skipped" ] && [ "$most" = 3 ] && [ "$heavy" = 1 ] && [ -z "$solo" ] &&
	[ "$first" = solo ] && [ "$second" = late ]; then
	tap_ok "TEST_JOBS=3: three at once at most, the two heavy ones never together, the alone one first with none beside it, then the long one"
else tap_fail "slots" "closing '$closing'; at once $most (want 3), heavy together $heavy (want 1), beside solo '$solo', first $first, second $second"$'\n'"$(cat "$spans")"; fi
: >"$spans"
suite slots TEST_JOBS=1 SLOT_S=0.2
if [ "$closing" = "10 passed, 0 failed, 0 skipped" ] && [ "$(most_at_once)" = 1 ]; then
	tap_ok "TEST_JOBS=1: one at a time"
else tap_fail "TEST_JOBS=1" "closing '$closing', at once $(most_at_once)"; fi
: >"$spans"
suite slots TEST_JOBS=x
if [ "$rc" = 2 ] && grep -q "TEST_JOBS must be" "$out" && [ ! -s "$spans" ]; then tap_ok "TEST_JOBS=x: refused, nothing run"
else tap_fail "TEST_JOBS=x" "exit $rc: $(tail -2 "$out")"; fi

# "realtime": beside the others where SCHED_FIFO is allowed, alone where it is
# not (a chrt that refuses, first in PATH, plays the user who may not)
for n in r1 r2 r3; do slotted rt "$n"; done
slotted rt rtime '# run.sh: realtime'
mkdir -p "$T/nort"
printf '#!/bin/sh\necho "chrt: failed to set pid 0'"'"'s policy: Operation not permitted" >&2\nexit 1\n' >"$T/nort/chrt"
chmod +x "$T/nort/chrt"
: >"$spans"
suite rt TEST_JOBS=3 PATH="$T/nort:$PATH"
if [ "$closing" = "4 passed, 0 failed, 0 skipped" ] && [ -z "$(beside rtime)" ]; then
	tap_ok "realtime, without SCHED_FIFO: runs alone"
else tap_fail "realtime without SCHED_FIFO" "closing '$closing', beside it '$(beside rtime)'"$'\n'"$(cat "$spans")"; fi
if chrt -f 1 true 2>/dev/null; then
	: >"$spans"
	suite rt TEST_JOBS=3
	if [ "$closing" = "4 passed, 0 failed, 0 skipped" ] && [ -n "$(beside rtime)" ]; then
		tap_ok "realtime, with SCHED_FIFO: runs beside the others ($(beside rtime))"
	else tap_fail "realtime with SCHED_FIFO" "closing '$closing', beside it '$(beside rtime)'"$'\n'"$(cat "$spans")"; fi
else
	tap_skip "realtime, with SCHED_FIFO: runs beside the others" "this user may not use SCHED_FIFO"
fi

tap_done
