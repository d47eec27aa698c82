#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# run.sh: heavy — its demos keep a core busy (tests/run.sh)
# e2e_demo_stop.sh — a demo that ends before its end says what ran, what did
# not and where the run is kept, and keeps it (the LCM log so far and every
# program's log), whatever ended it: SIGTERM, Ctrl-C of a lockstep run, a
# daemon killed during the run; and q before the switch says, at the top of
# its summary, that the oscillator never ran. Nothing is left behind. On the
# channel's four robots (what is tested is the stopping).
source "$(dirname "$0")/../lib.sh"

demo="$top/scripts/demo.sh"
scen="$top/sim-bridge/scenarios/channel4.scenario"
mkdir -p "$T/tmp"
url=$(lcm_url $((7862 + $$ % 3)))

# kept DIR: the run so far is there: a log with messages in it, every program's log, the report
kept() {
	[ -s "$1/demo.lcmlog" ] && [ -f "$1/logs/sim.log" ] && [ -f "$1/logs/undulated-r1.log" ] && [ -s "$1/early-stop.txt" ]
}
clean() { tr -d '\r' <"$1" | sed 's/\x1b\[[0-9;?]*[A-Za-z]//g'; }

# ---- SIGTERM before the switch ------------------------------------------------------
spawn d1 env BUILD="$BUILD" DEMO_SECONDS=60 DEMO_LCM_URL="$url" TMPDIR="$T/tmp" DEMO_OUT="$T/out1" "$demo" --scenario "$scen"
if demo_up d1 "demo starts"; then
	wait_for 10 bash -c "[ \$(stat -c %s $T/tmp/undulate-demo.*/demo.lcmlog 2>/dev/null || echo 0) -gt 100000 ]"
	kill -TERM "$pid_d1"
	wait "$pid_d1"; rc=$?
	echo "# $(grep '^demo: ' "$T/d1.log" | tail -n 4 | tr '\n' '|')"
	if [ "$rc" = 143 ] && grep -qE '^demo: stopped early \(SIGTERM\) after [0-9]+ s of 60 s$' "$T/d1.log" &&
		grep -qE '^demo: ran: sinusoid \(the clock\) for [0-9]+ s; did not run: oscillator \(due at 20 s\): THE OSCILLATOR NEVER RAN$' "$T/d1.log" &&
		grep -qF "demo: the run so far is kept in $T/out1: demo.lcmlog" "$T/d1.log" && kept "$T/out1"; then
		tap_ok "SIGTERM before the switch: exit 143, says what ran and what did not, keeps the run in DEMO_OUT"
	else
		tap_fail "SIGTERM before the switch says what ran and keeps the run" "exit $rc; $(tail -n 8 "$T/d1.log"); $(ls "$T/out1" 2>&1)"
	fi
	next=$(sed -n 's/^demo: to analyse it: //p' "$T/d1.log")
	if [ -n "$next" ] && $next --quiet >"$T/next1.out" 2>&1; [ -f "$T/out1/analysis/summary.json" ]; then
		tap_ok "the kept log analyses with the command printed"
	else
		tap_fail "the kept log analyses with the command printed" "'$next': $(tail -n 3 "$T/next1.out")"
	fi
	left_nothing "SIGTERM"
fi

# ---- a daemon killed during the run ----------------------------------------------------
spawn d2 env BUILD="$BUILD" DEMO_SECONDS=8 DEMO_LCM_URL="$url" TMPDIR="$T/tmp" DEMO_OUT="$T/out2" "$demo" --scenario "$scen"
if demo_up d2 "demo starts"; then
	victim=$(awk '$2 == "undulated-r2" { print $1 }' "$T"/tmp/undulate-demo.*/pids)
	kill -KILL "$victim"
	wait_for 40 bash -c "! kill -0 $pid_d2"
	wait "$pid_d2"; rc=$?
	echo "# $(grep '^demo: ' "$T/d2.log" | tail -n 4 | tr '\n' '|')"
	if [ "$rc" = 1 ] && grep -qE '^demo: ended \(undulated-r2 stopped during the run: killed by SIGKILL\) after [0-7] s of 8 s$' "$T/d2.log" &&
		grep -qF "demo: the run so far is kept in $T/out2: demo.lcmlog" "$T/d2.log" && kept "$T/out2" &&
		grep -q 'undulated-r2 stopped during the run' "$T/out2/early-stop.txt"; then
		tap_ok "a daemon killed during the run: exit 1, named, found at the next sample, the run kept"
	else
		tap_fail "a daemon killed during the run: named, the run kept" "exit $rc; $(tail -n 12 "$T/d2.log"); $(ls "$T/out2" 2>&1)"
	fi
	left_nothing "a killed daemon"
fi

if ! command -v script >/dev/null; then
	tap_skip "Ctrl-C of a lockstep run, q before the switch" "no script(1) here (package bsdutils)"
	tap_done; exit
fi
# ---- Ctrl-C of a lockstep run (on a terminal: the line discipline's SIGINT) ---------------
# after the switch (at 2 s of simulated time), so that the report gives both
# parts' times; run from a folder of its own, where nothing may appear (an
# awk printf whose "e > s ? ..." was taken for a redirection once wrote the
# time into a file named by the difference, "46.9", and printed nothing)
mkdir -p "$T/cwd3"
( wait_for 40 grep -q '^demo: phases' "$T/tty1.out"; wait_for 10 bash -c "[ \$(stat -c %s $T/tmp/undulate-demo.*/demo.lcmlog 2>/dev/null || echo 0) -gt 100000 ]"
  wait_for 30 bash -c "grep -q \"event 'command \\* mode oscillator': ok\" $T/tmp/undulate-demo.*/sim.log"
  printf '\003'; wait_for 30 grep -q 'to analyse it' "$T/tty1.out" ) |
	(cd "$T/cwd3" && env BUILD="$BUILD" DEMO_LCM_URL="$url" TMPDIR="$T/tmp" DEMO_OUT="$T/out3" \
	timeout 90 script -qec "$demo --lockstep --seconds 600 --switch-at 2 --scenario $scen" /dev/null) >"$T/tty1.out" 2>&1
rc=$?
screen=$(clean "$T/tty1.out")
echo "# $(echo "$screen" | grep '^demo: ' | tail -n 4 | tr '\n' '|')"
if [ "$rc" = 130 ] && echo "$screen" | grep -qE '^demo: stopped early \(Ctrl-C\) after [0-9.]+ s of 600 s of simulated time' &&
	echo "$screen" | grep -qE '^demo: ran: sinusoid \(the clock\) for 2 s, then oscillator for [0-9]+ s$' &&
	echo "$screen" | grep -qF "demo: the run so far is kept in $T/out3" && kept "$T/out3" && [ -z "$(ls -A "$T/cwd3")" ]; then
	tap_ok "Ctrl-C of a lockstep run after the switch: exit 130, says what ran in simulated time, each part's, keeps the run, writes nothing where it ran"
else
	tap_fail "Ctrl-C of a lockstep run says what ran and keeps the run" "exit $rc; $(echo "$screen" | tail -n 8); $(ls "$T/out3" 2>&1); where it ran: $(ls -A "$T/cwd3")"
fi
left_nothing "Ctrl-C in lockstep"

# ---- q before the switch: the summary says the oscillator never ran ------------------------
( wait_for 40 grep -q 'r4 ' "$T/tty2.out"; sleep 2; printf 'q'; wait_for 60 grep -q 'Next, the plots' "$T/tty2.out" ) |
	env BUILD="$BUILD" DEMO_LCM_URL="$url" TMPDIR="$T/tmp" DEMO_OUT="$T/out4" \
	timeout 120 script -qec "$demo --scenario $scen --switch-at 600" /dev/null >"$T/tty2.out" 2>&1
rc=$?
screen=$(clean "$T/tty2.out")
if [ "$rc" = 0 ] && echo "$screen" | grep -qE '^THE OSCILLATOR NEVER RAN: the run ended after [0-9]+ s, before the switch due at 600 s: what follows is sinusoid \(the clock\) alone' &&
	grep -q '^THE OSCILLATOR NEVER RAN' "$T/out4/demo-summary.txt"; then
	tap_ok "q before the switch: the summary says first that the oscillator never ran"
else
	tap_fail "q before the switch: the summary says the oscillator never ran" "exit $rc; $(echo "$screen" | sed -n '/=== undulate demo/,+4p')"
fi
left_nothing "q"
tap_done
