#!/usr/bin/env bash
# Runs every test and ends with one line: "N passed, N failed, N skipped".
#  - unit tests: $UNIT_TESTS_DIR/test_* (default $BUILD/tests; cmocka, TAP output)
#  - integration tests: $INTEGRATION_TESTS_DIR/*.sh (default tests/integration;
#    TAP lines: "ok ..." / "not ok ...", and a plan "1..N")
#  - with TEST_LONG=1: $LONG_TESTS_DIR/*.sh (default tests/long) as well
# Environment: TEST_FILTER (run the programs whose name contains it),
# TEST_TIMEOUT (seconds one program may run, default 300; a hang is a failure;
# a script that says "# run.sh: timeout SECONDS" may run that long if longer:
# a soak of minutes), TEST_JOBS (slots for programs side by side, default 4; see below).
# Logs: $BUILD/test-logs/<program>.log.
#
# What counts (TAP):
#  - "ok N - name" passes; "not ok N - name" fails.
#  - "# SKIP" after a result, "ok" or "not ok" (cmocka 1.1 writes a skip() as
#    "not ok N # SKIP name"), is a skip; a plan "1..0 # SKIP why" with no
#    result skips the whole program.
#  - "not ok ... # TODO" is a known unmet claim, counted apart (not a pass,
#    not a failure).
# On top of what a program prints, the runner counts one failure for a program
# that exits non-zero without a "not ok", prints no result, prints results but
# no plan, or whose plans (a plan at its start or end; cmocka prints one per
# group, and they add up) disagree with the number of results it printed.
# So nothing can fail, stop early or run half its tests silently.
set -u
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/.." && pwd)
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$top/$BUILD" ;; esac
export BUILD
unit_dir=${UNIT_TESTS_DIR:-$BUILD/tests}
integration_dir=${INTEGRATION_TESTS_DIR:-$top/tests/integration}
long_dir=${LONG_TESTS_DIR:-$top/tests/long}
logs="$BUILD/test-logs"
mkdir -p "$logs"
# One test may not run longer than this (seconds); a hang is a failure.
per_test_timeout=${TEST_TIMEOUT:-300}
filter=${TEST_FILTER:-}

passed=0 failed=0 skipped=0 todo=0 programs=0 cpu_total=0 run_start=$(date +%s%N)
failures=()
todos=()
skips=()

# tap_counts LOG: "passed failed skipped todo plans planned plan_skip" of a TAP log.
tap_counts() {
	awk '
		function directive(word) { return tolower($0) ~ ("#[ \t]*" word) }
		/^(not )?ok([ \t]|$)/ {
			if (directive("skip")) s++
			else if (/^not ok/ && directive("todo")) t++
			else if (/^not ok/) f++
			else p++
			next
		}
		/^1\.\.[0-9]+/ {
			plans++
			planned += substr($1, 4)
			if (substr($1, 4) + 0 == 0 && directive("skip")) plan_skip = 1
		}
		END { printf "%d %d %d %d %d %d %d\n", p, f, s, t, plans, planned, plan_skip }
	' "$1"
}

# exit_reason RC SECONDS LIMIT: what a non-zero exit status means, in words.
exit_reason() {
	local rc=$1 secs=$2 limit=$3
	if [ "$rc" -eq 124 ] || { [ "$rc" -eq 137 ] && [ "$secs" -ge "$limit" ]; }; then
		echo "timed out after ${limit}s (TEST_TIMEOUT)"
	elif [ "$rc" -gt 128 ]; then
		echo "killed by signal $((rc - 128)) (exit status $rc)"
	else
		echo "exited with status $rc"
	fi
}

# tap_lines LOG NAME PATTERN: the log's result lines matching PATTERN, as
# "NAME: description" (the "ok N - " in front dropped).
tap_lines() {
	grep -E "$3" "$1" | sed -E "s/^(not )?ok[[:space:]]*[0-9]*[[:space:]]*(- )?/$2: /"
}

# faults RC SECONDS LIMIT FAILED RESULTS PLANS PLANNED PLAN_SKIP: what the
# runner finds wrong with a program beyond its own "not ok" lines, as "a; b", or "".
faults() {
	local rc=$1 secs=$2 limit=$3 f=$4 results=$5 plans=$6 planned=$7 plan_skip=$8
	local why=()
	if [ "$rc" -ne 0 ]; then
		# a "not ok" explains a non-zero exit; nothing explains a crash without one
		[ "$f" -eq 0 ] && why+=("$(exit_reason "$rc" "$secs" "$limit")")
	elif [ "$results" -eq 0 ] && [ "$plan_skip" -eq 0 ]; then
		why+=("ran no test")
	fi
	if [ "$results" -gt 0 ] && [ "$plans" -eq 0 ]; then
		why+=("printed $results result(s) but no plan (1..N)")
	elif [ "$plans" -gt 0 ] && [ "$planned" -ne "$results" ]; then
		why+=("plan says $planned test(s), printed $results result(s)")
	fi
	# a program that stopped early shows it in its plan: say why it stopped
	[ "${#why[@]}" -gt 0 ] && [ "$rc" -ne 0 ] && [ "$f" -gt 0 ] && why+=("$(exit_reason "$rc" "$secs" "$limit")")
	local out="" w
	for w in "${why[@]}"; do out+="${out:+; }$w"; done
	echo "$out"
}

# timeout_of SCRIPT: the seconds SCRIPT may run: TEST_TIMEOUT, or more when it
# says so in a line "# run.sh: timeout SECONDS" (a soak of minutes); never less.
timeout_of() {
	local n
	n=$(sed -n 's/^# run\.sh: timeout \([0-9]\{1,6\}\)\([^0-9].*\)\{0,1\}$/\1/p' "$1" 2>/dev/null | head -n 1)
	if [ -n "$n" ] && [ "$((10#$n))" -gt "$per_test_timeout" ]; then echo "$((10#$n))"; else echo "$per_test_timeout"; fi
}

# cpu_ms: the CPU time (user + system, ms) of this shell's finished children,
# from bash's `times` (its second line); called in a subshell that ran one
# program, it is that program's and of every process it waited for. (A process
# left to init is not counted; the tests' traps wait for theirs.)
# (`times` itself, not in $( ): a subshell has no children of its own yet.)
cpu_ms() {
	times >"$1"
	# the children's line, "1m2.345s 0m0.678s": minutes, seconds
	awk 'function ms(t) { split(t, a, /[ms]/); return int((a[1] * 60 + a[2]) * 1000 + 0.5) }
		NR == 2 { print ms($1) + ms($2) }' "$1"
}

# execute NAME LIMIT CMD...: run one program into its log, for at most LIMIT
# seconds; print "RC MS LIMIT CPU_MS".
execute() {
	local name=$1 limit=$2; shift 2
	local start=$(date +%s%N) rc
	CMOCKA_MESSAGE_OUTPUT=TAP timeout --kill-after=10 "$limit" "$@" >"$logs/$name.log" 2>&1
	rc=$?
	cpu_ms "$logs/$name.times" >"$logs/$name.cpu"
	echo "$rc $(( ($(date +%s%N) - start) / 1000000 )) $limit $(cat "$logs/$name.cpu")"
	rm -f "$logs/$name.times" "$logs/$name.cpu"
}

# account NAME RC MS LIMIT CPU_MS: count a finished program's results and show its line.
account() {
	local name=$1 rc=$2 ms=$3 limit=$4 cpu=$5
	local log="$logs/$name.log"
	programs=$((programs + 1))
	local p f s t plans planned plan_skip
	read -r p f s t plans planned plan_skip < <(tap_counts "$log")
	local results=$((p + f + s + t))
	if [ "$results" -eq 0 ] && [ "$plan_skip" -eq 1 ]; then
		s=1
		skips+=("$name: $(grep -m1 -E '^1\.\.0' "$log" | sed -E 's/^1\.\.0[[:space:]]*#[[:space:]]*[Ss][Kk][Ii][Pp][[:alpha:]]*[[:space:]]*//')")
	fi
	local reason
	reason=$(faults "$rc" "$((ms / 1000))" "$limit" "$f" "$results" "$plans" "$planned" "$plan_skip")
	if [ -n "$reason" ]; then
		f=$((f + 1))
		echo "not ok - $name: $reason" >>"$log"
	fi

	passed=$((passed + p)); failed=$((failed + f)); skipped=$((skipped + s)); todo=$((todo + t))
	local line
	while IFS= read -r line; do todos+=("${line% # [Tt][Oo][Dd][Oo]*}"); done \
		< <(tap_lines "$log" "$name" '^not ok.*#[[:space:]]*[Tt][Oo][Dd][Oo]' | grep -viE '#[[:space:]]*skip')
	while IFS= read -r line; do skips+=("$line"); done \
		< <(tap_lines "$log" "$name" '^(not )?ok([[:space:]]|$).*#[[:space:]]*[Ss][Kk][Ii][Pp]')
	[ "$f" -gt 0 ] && failures+=("$name${reason:+: $reason}")
	cpu_total=$((cpu_total + cpu))
	show "$name" "$log" "$ms" "$cpu" "$p" "$f" "$s" "$t"
}

# tenths MS: MS as seconds with one decimal
tenths() { echo "$(($1 / 1000)).$(( ($1 % 1000) / 100 ))"; }

# show NAME LOG MS CPU_MS PASSED FAILED SKIPPED TODO: the program's line (its
# time, and the CPU its processes used: what it costs the others beside it),
# and on a failure its "not ok" and comment lines.
show() {
	local name=$1 log=$2 ms=$3 cpu=$4 p=$5 f=$6 s=$7 t=$8 extra=""
	local secs="$(tenths "$ms")s, cpu $(tenths "$cpu")"
	[ "$s" -gt 0 ] && extra+=", $s skipped"
	[ "$t" -gt 0 ] && extra+=", $t todo"
	if [ "$f" -gt 0 ]; then
		printf '%-40s %3d passed, %3d FAILED%s  (%ss)\n' "$name" "$p" "$f" "$extra" "$secs"
		grep -E '^not ok|^#' "$log" | grep -viE '^(not )?ok.*#[[:space:]]*(skip|todo)' | head -20 | sed 's/^/    /'
		echo "    (full log: $log)"
	else
		printf '%-40s %3d passed%s  (%ss)\n' "$name" "$p" "$extra" "$secs"
	fi
}

# The UUCP lock files that name a bus's holder (protocol/io/port_lock.c) go
# to a directory of this run's own, not the machine's /var/lock (integration
# tests have their own, tests/lib.sh).
UNDULATE_LOCK_DIR=$(mktemp -d "${TMPDIR:-/tmp}/undulate-locks.XXXXXX")
export UNDULATE_LOCK_DIR
trap 'rm -rf "$UNDULATE_LOCK_DIR"' EXIT

# ---- every program, TEST_JOBS slots at a time ----------------------------------------
# Most tests spend their time waiting: on simulated buses, on timeouts, on runs
# in real time. They run side by side, each on its own LCM ports and in its own
# temporary directory (tests/lib.sh), in TEST_JOBS slots (default 4). A program
# takes one slot, or says otherwise in a line of its own:
#   "# run.sh: heavy" — it keeps a core busy (runs in lockstep, the virtual
#     clock as fast as the machine goes): two slots, so that with the default
#     four, two of them at once have nothing beside them, and one has two
#     light ones at most;
#   "# run.sh: alone" — it measures a gait or an experiment in real time: every
#     slot, nothing beside it;
#   "# run.sh: realtime" — it measures in real time, with its simulators and
#     daemons under SCHED_FIFO (tests/lib.sh spawn_rt): where this user may
#     use FIFO, one slot, started early as the long ones; elsewhere alone.
# Order: the unit tests and the alone scripts first, one at a time (started on
# an idle machine, so no slot waits for the others to drain), then the
# scripts that say "# run.sh: long" (started early, the run does not end
# waiting on one of them) and the other scripts. They start in this order, each
# as soon as its slots are free; results are counted and shown in that order.
# TEST_JOBS=1 runs them one by one.
jobs_max=${TEST_JOBS:-4}
[[ "$jobs_max" =~ ^[1-9][0-9]?$ ]] || { echo "run.sh: TEST_JOBS must be 1..99, not '$jobs_max'" >&2; exit 2; }
# every script's "# run.sh:" lines, read with one grep (one per script and
# question cost seconds of forks before the first test started)
declare -A directives=()
while IFS= read -r line; do
	directives["${line%%:*}"]+=" ${line#*:# run.sh: }"
done < <(grep -H '^# run\.sh: ' "$integration_dir"/*.sh ${TEST_LONG:+"$long_dir"/*.sh} 2>/dev/null)
says() { [[ " ${directives[$1]:-}" == *" $2"* ]]; }
# SCHED_FIFO allowed (root, or an rtprio limit): "realtime" scripts need not run alone
rt_ok=0
chrt -f 1 true 2>/dev/null && rt_ok=1
# alone SCRIPT: nothing may run beside it
alone() { says "$1" alone || { [ "$rt_ok" = 0 ] && says "$1" realtime; }; }
names=() cmds=() weights=()
# add NAME WEIGHT CMD...: one program into the queue (unless the filter leaves it out)
add() {
	[ -n "$filter" ] && [[ "$1" != *$filter* ]] && return
	local w=$2
	[ "$w" -gt "$jobs_max" ] && w=$jobs_max
	names+=("$1") weights+=("$w")
	shift 2
	cmds+=("$(printf '%q ' "$@")")
}
scripts=()
for t in "$integration_dir"/*.sh; do [ -f "$t" ] && scripts+=("$t"); done
if [ -n "${TEST_LONG:-}" ]; then
	for t in "$long_dir"/*.sh; do [ -f "$t" ] && scripts+=("$t"); done
fi
# the unit tests time ptys and fake servos to the millisecond (a missing
# servo's timeout, the doctor's latency): one at a time, nothing beside them
for t in "$unit_dir"/test_*; do
	[ -f "$t" ] && [ -x "$t" ] && add "${t##*/}" "$jobs_max" "$t"
done
for t in ${scripts[@]+"${scripts[@]}"}; do alone "$t" && { n=${t##*/}; add "${n%.sh}" "$jobs_max" bash "$t"; }; done
for pass in long other; do
	for t in ${scripts[@]+"${scripts[@]}"}; do
		alone "$t" && continue
		if says "$t" long || says "$t" realtime; then [ "$pass" = long ] || continue; else [ "$pass" = other ] || continue; fi
		w=1; says "$t" heavy && w=2
		n=${t##*/}
		add "${n%.sh}" "$w" bash "$t"
	done
done

# A started program is over when its .rc file ("RC MS LIMIT") is there; its
# slots are free from then on, counted or not. Each one that ends also writes a
# line into a pipe the loop sleeps on (wait -n would miss one that ended
# before it was called).
over() { [ -f "$logs/${names[$1]}.rc" ]; }
ends="$logs/.ends.$$"
rm -f "$ends"; mkfifo "$ends" && exec 9<>"$ends" && rm -f "$ends" || { echo "run.sh: cannot make a pipe in $logs" >&2; exit 2; }
# limit_of I: the seconds program I may run (a script may ask for more)
limit_of() { case "${cmds[$1]}" in bash\ *) eval "set -- ${cmds[$1]}"; timeout_of "$2" ;; *) echo "$per_test_timeout" ;; esac; }
queued=(${names[@]+"${!names[@]}"}) order=() running=() used=0 reported=0
while [ "$reported" -lt "${#names[@]}" ]; do
	# free the slots of the ones that are over
	still=()
	for i in ${running[@]+"${running[@]}"}; do
		if over "$i"; then used=$((used - weights[i])); else still+=("$i"); fi
	done
	running=(${still[@]+"${still[@]}"})
	# start, in the queue's order, while the next one fits in the free slots:
	# nothing passes a program that waits for slots (light ones passing a
	# heavy one kept it waiting to the end of the run)
	while [ "${#queued[@]}" -gt 0 ] && [ $((used + weights[queued[0]])) -le "$jobs_max" ]; do
		i=${queued[0]}
		queued=("${queued[@]:1}")
		n=${names[$i]}
		rm -f "$logs/$n.rc"
		( eval "execute \"\$n\" \"\$(limit_of $i)\" ${cmds[$i]}" >"$logs/$n.rc.tmp" 9>&-
		  mv "$logs/$n.rc.tmp" "$logs/$n.rc"; echo >&9 ) &
		order+=("$i") running+=("$i") used=$((used + weights[i]))
	done
	# the finished ones, in the order they started
	while [ "$reported" -lt "${#order[@]}" ] && over "${order[$reported]}"; do
		i=${order[$reported]}
		read -r rc ms limit cpu <"$logs/${names[$i]}.rc"
		account "${names[$i]}" "$rc" "$ms" "$limit" "${cpu:-0}"
		reported=$((reported + 1))
	done
	# sleep until the next one ends
	[ "$reported" -lt "${#names[@]}" ] && read -r -u 9 _
done
exec 9>&-
for n in ${names[@]+"${names[@]}"}; do rm -f "$logs/$n.rc"; done
wait

echo
if [ "$todo" -gt 0 ]; then
	echo "$todo known unmet claim(s) (TAP TODO, not counted; see docs/EXPERIMENTS.md):"
	printf '  %s\n' "${todos[@]}"
fi
if [ "${#skips[@]}" -gt 0 ]; then
	echo "$skipped skipped:"
	printf '  %s\n' "${skips[@]}"
fi
if [ "${#failures[@]}" -gt 0 ]; then
	echo "failed in ${#failures[@]} program(s):"
	printf '  %s\n' "${failures[@]}"
fi
if [ "$programs" -eq 0 ]; then
	echo "no test program ran (TEST_FILTER='$filter'; unit tests from $unit_dir, integration tests from $integration_dir)"
fi
echo "$programs programs in $(tenths $(( ($(date +%s%N) - run_start) / 1000000 )))s, their CPU $(tenths "$cpu_total")s"
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ] && [ "$programs" -gt 0 ]
