#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# e2e_demo.sh — `make demo DEMO_SECONDS=...` end to end, as a new user runs
# it: the paper's contact-force scene (ten robots crowded in a row, one
# undulated each), 20 s on the clock, then the oscillator, headless; the
# summary says in words and numbers how the contact force and the collisions
# changed, each pair's final phase difference against its bound, where the
# run is kept and the exact command for the plots (run here: its plots must
# draw data); afterwards nothing is left behind (no process, no pty link, no
# socket, no temporary directory) — also when the demo is stopped early by
# SIGTERM, and on a terminal stopped by Ctrl-C. The paper's effect (the
# contact force falls after the switch) is asserted on the same scene in
# lockstep, where the outcome does not depend on the machine's load; in real
# time, alone, it is make test-long's (tests/long/e2e_force.sh, on the row
# world's ten robots).
source "$(dirname "$0")/../lib.sh"

demo="$top/scripts/demo.sh"
# The demo's temporary directory (links, logs) goes under here, so what it
# leaves behind can be seen.
mkdir -p "$T/tmp"
# One LCM port for the three runs (they never overlap), one of five in
# 7850-7854 so that two copies of this test running at once rarely meet.
url=$(lcm_url $((7850 + $$ % 5)))

# ---- a headless run, as `make demo DEMO_SECONDS=35 DEMO_OUT=...` ----------------
seconds=35
spawn demo env BUILD="$BUILD" DEMO_SECONDS=$seconds DEMO_LCM_URL="$url" TMPDIR="$T/tmp" \
	DEMO_OUT="$T/out" "$demo"
if wait_log demo '^demo: scenario' 40; then
	tap_ok "demo starts the simulator and ten daemons"
else
	tap_fail "demo starts the simulator and ten daemons" "$(tail -n 20 "$T/demo.log")"
fi
# While it runs: ten robots publish on the demo's LCM URL.
n=$("$B/undulate-top" --lcm-url "$url" --once --json --wait 2 2>/dev/null |
	grep -o '"name":"r[0-9]*"' | sort -u | wc -l)
if [ "$n" -eq 10 ]; then tap_ok "undulate-top sees the ten robots live"; else tap_fail "undulate-top sees the ten robots live" "saw $n"; fi

wait_for $((seconds + 40)) bash -c "! kill -0 $pid_demo"
kill -TERM "$pid_demo" 2>/dev/null  # only if it overran
wait "$pid_demo"
rc=$?
if [ "$rc" = 0 ]; then tap_ok "headless demo exits 0"; else tap_fail "headless demo exits 0" "exit $rc; $(tail -n 20 "$T/demo.log")"; fi

out="$T/demo.log"
if grep -q "^=== undulate demo summary: 10 robots, $seconds s, plane-demo.scenario" "$out"; then
	tap_ok "summary printed"
else
	tap_fail "summary printed" "$(tail -n 30 "$out")"
fi
# One row per neighbouring pair: name, state, final phase difference, d~, 2 asin(d~), collisions.
pair_rows=$(awk '$1 ~ /^r[0-9]+:r[0-9]+$/ && $2 ~ /^(in-phase|compatible|anti-phase|grazing|still-colliding|no-data|not-oscillating|unlocked|locked-[a-z-]*)$/ \
	&& $3 ~ /^-?[0-9.]+$/ && $4 ~ /^[0-9.]+$/' "$out" | awk '{ print $1 }' | tr '\n' ' ')
if [ "$pair_rows" = "r1:r2 r2:r3 r3:r4 r4:r5 r5:r6 r6:r7 r7:r8 r8:r9 r9:r10 " ]; then
	tap_ok "summary has the nine neighbouring pairs with phase difference, d~ and state"
else
	tap_fail "summary has the nine neighbouring pairs with phase difference, d~ and state" "got '$pair_rows'; $(sed -n '/=== undulate/,$p' "$out")"
fi
# Every pair's final phase difference is a real angle and its d~ comes from a
# measured amplitude (the plane demo: the robots' centres 6-18 cm apart over 0.37 m of swept width).
bad=$(awk '$1 ~ /^r[0-9]+:r[0-9]+$/ && $2 ~ /^(in-phase|compatible|anti-phase|grazing|still-colliding|no-data|not-oscillating|unlocked|locked-[a-z-]*)$/ \
	&& ($3 < -3.1416 || $3 > 3.1416 || $4 <= 0.05 || $4 > 2) { print }' "$out")
if [ -z "$bad" ]; then tap_ok "phase differences within (-pi, pi], d~ plausible"; else tap_fail "phase differences within (-pi, pi], d~ plausible" "$bad"; fi
windows=$(awk '/^collisions per 10 s window:/ { on = 1; next } on && /collisions/ { n++ } END { print n + 0 }' "$out")
if [ "$windows" -ge 3 ]; then
	tap_ok "collision count per 10 s window ($windows windows)"
else
	tap_fail "collision count per 10 s window" "$(sed -n '/collisions per 10 s/,$p' "$out")"
fi
# The switch to OSCILLATOR happened (by one command to every robot), after
# at least 15 s on the clock.
sw=$(sed -n 's/^switched sinusoid -> oscillator at t = \([0-9.]*\) s$/\1/p' "$out")
if [ -n "$sw" ] && awk -v s="$sw" 'BEGIN { exit !(s >= 15) }'; then
	tap_ok "robots switched from SINUSOID to OSCILLATOR after $sw s on the clock"
else
	tap_fail "robots switched from SINUSOID to OSCILLATOR after >= 15 s" "$(grep -i switch "$out")"
fi
# In words: the contact force's change, as a ratio, and the collisions.
words=$(grep -E '^  The mean contact force (fell [0-9.]+x after the switch|fell to zero after the switch|did not fall): [0-9.]+ N on the sinusoid' "$out")
if [ -n "$words" ] && grep -qE '^  Collisions between robots per 10 s: [0-9]+ -> [0-9]+; against the walls' "$out"; then
	tap_ok "summary in words: ${words#  }"
else
	tap_fail "summary says in words how the contact force and collisions changed" "$(sed -n '/In words/,+4p' "$out")"
fi
# Robots that stopped would also stop colliding: every joint must still swing
# at least 0.6 rad peak-to-peak (a crowded end robot's free joint swings least).
sg=$(min_swing "$T/out" 2>/dev/null)
if [ -n "$sg" ] && awk -v s="${sg%% *}" 'BEGIN { exit !(s >= 0.6) }'; then
	tap_ok "every robot still undulates at the end (smallest peak-to-peak $sg rad)"
else
	tap_fail "every robot still undulates at the end" "smallest peak-to-peak over the last 10 s: '$sg' rad (< 0.6)"
fi
if grep -qE '^  Neighbours at the end \(\|D\| against the compatibility bound 2 asin\(d~\)\): [0-9]+ of 9 at or within it' "$out"; then
	tap_ok "summary: each pair's final |D| against its bound ($(grep -oE '[0-9]+ of 9 at or within' "$out"))"
else
	tap_fail "summary: each pair's final |D| against its bound" "$(sed -n '/In words/,+14p' "$out")"
fi
# Where the run is kept, and the next command, which works as printed.
next=$(sed -n 's/^Next, the plots:  //p' "$out")
if grep -qF "The run is kept in $T/out: demo.lcmlog" "$out" && [ "$next" = "$B/undulate-analyze $T/out/demo.lcmlog --out $T/out/plots --plots-only" ] &&
	grep -qF "log: $T/out/demo.lcmlog" "$T/out/summary.txt"; then
	tap_ok "summary ends with the kept folder and the next command; summary.txt names the kept log"
else
	tap_fail "summary ends with the kept folder and the next command" "$(tail -n 4 "$out"; head -2 "$T/out/summary.txt")"
fi
if [ -n "$next" ] && $next >"$T/next.out" 2>&1 && [ -f "$T/out/plots/angles.png" ] &&
	n=$("$BUILD/tests/tools/pngdata" "$T/out/plots/angles.png" | sed -n 's/.*coloured=//p') && [ "${n:-0}" -ge 20000 ]; then
	tap_ok "the next command draws the plots (angles.png: $n data pixels)"
else
	tap_fail "the next command draws the plots" "$(tail -n 5 "$T/next.out")"
fi
# The summary's numbers are the analyser's: compare with the kept summary.json.
if [ -f "$T/out/summary.json" ] && [ -s "$T/out/demo.lcmlog" ] &&
	grep -q '"pair":"r1:r2"' "$T/out/summary.json"; then
	tap_ok "--out keeps the LCM log and the analysis"
else
	tap_fail "--out keeps the LCM log and the analysis" "$(ls -la "$T/out" 2>&1)"
fi
# The theory is drawn for the run's own restitution, which the log carries
# (SIM.WORLD): the channel scenario's r = 0.67, said to come from the simulator.
if grep -q '^restitution for theory: 0.670 (the simulator.s, SIM.WORLD)' "$T/out/summary.txt"; then
	tap_ok "the analysis takes the restitution from the simulator's SIM.WORLD"
else
	tap_fail "the analysis takes the restitution from the simulator's SIM.WORLD" "$(grep -i restitution "$T/out/summary.txt")"
fi
left_nothing "a full run"

# ---- the paper's effect: the same scene in lockstep ----------------------------------------
# (docs/EXPERIMENTS.md section 4: the simulator's total impulse per second,
# sampled by demo.sh, over the last 10 s on each side of the switch at 20 s.)
# Asserted 3x or more; 5x, as the README promises it for the demo, and the
# paper's order of magnitude are TODOs with their number when short. The
# robots must still swing: robots that stopped would also stop colliding.
# One seed (3, e2e_force's): the demo draws one per run otherwise, and the
# fall differs by seed (4.7x and 6.9x in two runs of one day).
env BUILD="$BUILD" DEMO_SECONDS=45 TMPDIR="$T/tmp" DEMO_OUT="$T/lout" "$demo" --lockstep --seed 3 --lcm-url "$url" \
	>"$T/ldemo.log" 2>&1
lrc=$?
words=$(grep -E '^  The mean contact force (fell [0-9.]+x after the switch|fell to zero after the switch|did not fall)' "$T/ldemo.log")
ratio=$(echo "$words" | sed -n 's/.*fell \([0-9.]*\)x after.*/\1/p')
lsw=$(min_swing "$T/lout" 2>/dev/null)
zero=0; echo "$words" | grep -q 'fell to zero' && zero=1
if [ "$lrc" = 0 ] && { [ "$zero" = 1 ] || { [ -n "$ratio" ] && awk -v r="$ratio" 'BEGIN { exit !(r >= 3) }'; }; } &&
	[ -n "$lsw" ] && awk -v s="${lsw%% *}" 'BEGIN { exit !(s >= 0.6) }'; then
	tap_ok "in lockstep: the contact force falls 3x or more after the switch (${ratio:-to zero}x), every robot undulates (smallest swing ${lsw%% *} rad)"
else
	tap_fail "in lockstep: the contact force falls 3x or more after the switch, every robot undulates" "exit $lrc; ${words:-no words}; swing $lsw; $(tail -n 5 "$T/ldemo.log")"
fi
for want in 5 10; do
	if [ "$zero" = 1 ] || { [ -n "$ratio" ] && awk -v r="$ratio" -v w="$want" 'BEGIN { exit !(r >= w) }'; }; then
		tap_ok "in lockstep: the contact force falls ${want}x or more after the switch (${ratio:-to zero}x)"
	else
		tap_todo "in lockstep: the contact force falls ${want}x or more after the switch" "${words:-no words}"
	fi
done

# ---- the row's experiment on XM430-W350 robots (Protocol 2.0), in virtual time --------------
# (force10.scenario: the row world, as before make demo moved to the plane.)
# Position servos as the paper's robots, on the daemon's defaults for the
# XM430 (what `undulated --tune` found for the simulated servo; the AX-12A's let
# its oscillator run down between restarts there: daemon/CONTROL.md).
xset=(--set sim.model=xm430-w350 --set sim.baud=1000000 --set sim.return_delay_us=0)
env BUILD="$BUILD" DEMO_SECONDS=$seconds TMPDIR="$T/tmp" DEMO_OUT="$T/xout" "$demo" --lockstep --seed 3 --lcm-url "$url" \
	--scenario "$top/sim-bridge/scenarios/force10.scenario" "${xset[@]}" \
	>"$T/xdemo.log" 2>&1
xrc=$?
xwords=$(grep -E '^  The mean contact force (fell [0-9.]+x after the switch|fell to zero after the switch|did not fall)' "$T/xdemo.log")
xratio=$(echo "$xwords" | sed -n 's/.*fell \([0-9.]*\)x after.*/\1/p')
xsw=$(min_swing "$T/xout" 2>/dev/null)
stalls=$(cat "$T/xout/logs"/undulated-r*.log 2>/dev/null | grep -c 'stall: oscillator at rest')
if [ "$xrc" = 0 ] && grep -q 'Protocol 2.0 (XM430-W350)' "$T/xout/logs/undulated-r1.log" &&
	{ echo "$xwords" | grep -q 'fell to zero' || { [ -n "$xratio" ] && awk -v r="$xratio" 'BEGIN { exit !(r >= 3) }'; }; } &&
	[ -n "$xsw" ] && awk -v s="${xsw%% *}" 'BEGIN { exit !(s >= 0.6) }'; then
	tap_ok "XM430 robots in lockstep: the contact force falls ${xratio:-to zero}x after the switch, every robot undulates (smallest swing ${xsw%% *} rad, $stalls stall restarts)"
else
	tap_fail "XM430 robots in lockstep: the contact force falls 3x or more, every robot undulates" "exit $xrc; ${xwords:-no words}; swing $xsw; $(tail -n 5 "$T/xdemo.log")"
fi
if [ -n "$xratio" ] && awk -v r="$xratio" 'BEGIN { exit !(r >= 10) }' || echo "$xwords" | grep -q 'fell to zero'; then
	tap_ok "XM430 robots: the contact force falls 10x or more (${xratio:-to zero}x)"
else
	tap_todo "XM430 robots: the contact force falls 10x or more" "${xwords:-no words}"
fi
left_nothing "the lockstep run"

# ---- stopped early ---------------------------------------------------------------
# SIGTERM (what `timeout`, a service manager or a closing terminal sends)
# must stop every child and remove the links, and keep the run so far. (Ctrl-C in a terminal goes to
# the whole foreground process group; a background job here ignores SIGINT.)
# (the four robots of the channel: what is tested is the stopping)
spawn demo2 env BUILD="$BUILD" DEMO_SECONDS=60 DEMO_LCM_URL="$url" TMPDIR="$T/tmp" DEMO_OUT="$T/out2" "$demo" \
	--scenario "$top/sim-bridge/scenarios/channel4.scenario"
if demo_up demo2 "second demo starts"; then
	links=$(find "$T/tmp" -type l | wc -l)
	# (not $(stop ...): a subshell cannot wait for a child of this shell)
	kill -TERM "$pid_demo2"
	wait "$pid_demo2"
	rc=$?
	if [ "$links" -eq 4 ] && [ "$rc" = 143 ] && grep -q '^demo: stopped early (SIGTERM)' "$T/demo2.log" && [ -f "$T/out2/early-stop.txt" ]; then
		tap_ok "SIGTERM stops the demo (exit 143) after it made 4 pty links, says so and keeps the run"
	else
		tap_fail "SIGTERM stops the demo (exit 143) after it made 4 pty links" "links $links, exit $rc; its log: $(tail -n 12 "$T/demo2.log")"
	fi
	left_nothing "SIGTERM"
fi

# ---- interactive, on a terminal: q, then Ctrl-C ------------------------------------
# `script` gives the demo a pseudo-terminal: undulate-top runs in the
# foreground. q ends it and the demo summarizes and keeps the run; the 0x03
# written to the terminal is the user's Ctrl-C (a key to undulate-top's raw
# terminal): everything stops at once, and the demo says what ran and keeps
# the run unanalysed (e2e_demo_stop: the other ways a run ends early).
# The switch comes after 3 s here, not 20, to see both phases of the banner.
clean() { tr -d '\r' <"$1" | sed 's/\x1b\[[0-9;?]*[A-Za-z]//g'; }
if command -v script >/dev/null; then
	( wait_for 40 grep -q 'on the oscillator:' "$T/tty.out"; wait_for 10 grep -q 'r10 ' "$T/tty.out"; sleep 3
	  printf 'q'; wait_for 60 grep -q 'Next, the plots' "$T/tty.out" ) |
		env BUILD="$BUILD" DEMO_LCM_URL="$url" TMPDIR="$T/tmp" DEMO_OUT="$T/iout" \
		timeout 120 script -qec "$demo --switch-at 3" /dev/null >"$T/tty.out" 2>&1
	rc=$?
	screen=$(clean "$T/tty.out")
	rows=$(echo "$screen" | grep -cE '^. *[0-9]+ r[0-9]+ +(SIN|OSC)')
	if [ "$rc" = 0 ] && echo "$screen" | grep -q 'DEMO [0-9]*s | on the CLOCK (sinusoid) | oscillator in [0-9]*s' &&
		echo "$screen" | grep -q 'DEMO [0-9]*s | on the oscillator: watch' && echo "$screen" | grep -q '^contact force, N per 5 s:' &&
		[ "$rows" -ge 10 ]; then
		tap_ok "interactive: the banner says what happens and when, the contact trend and the robots are shown"
	else
		tap_fail "interactive: banner, contact trend and robots on the screen" "exit $rc, robot rows $rows; $(echo "$screen" | tail -n 25)"
	fi
	if echo "$screen" | grep -q '^=== undulate demo summary: 10 robots' && [ -s "$T/iout/demo.lcmlog" ] &&
		[ -f "$T/iout/demo-summary.txt" ]; then
		tap_ok "interactive: q stops the run, prints the summary and keeps the run in DEMO_OUT"
	else
		tap_fail "interactive: q prints the summary and keeps the run" "$(echo "$screen" | tail -n 15; ls "$T/iout" 2>&1)"
	fi
	left_nothing "q"

	( wait_for 40 grep -q 'r4 ' "$T/tty2.out"; sleep 2; printf '\003'; sleep 5 ) |
		env BUILD="$BUILD" DEMO_LCM_URL="$url" TMPDIR="$T/tmp" DEMO_OUT="$T/iout2" \
		timeout 60 script -qec "$demo --scenario $top/sim-bridge/scenarios/channel4.scenario" /dev/null >"$T/tty2.out" 2>&1
	rc=$?
	if [ "$rc" = 130 ] && clean "$T/tty2.out" | grep -qE '^. *[0-9]+ r4 +SIN' &&
		clean "$T/tty2.out" | grep -qE '^demo: stopped early \(Ctrl-C\) after [0-9]+ s on the terminal' &&
		clean "$T/tty2.out" | grep -qF "demo: the run so far is kept in $T/iout2" && [ -s "$T/iout2/demo.lcmlog" ]; then
		tap_ok "interactive: Ctrl-C ends the demo at once (exit 130), says what ran and keeps the run unanalysed"
	else
		tap_fail "interactive: Ctrl-C ends the demo" "exit $rc; $(clean "$T/tty2.out" | tail -n 10)"
	fi
	left_nothing "Ctrl-C"
fi

# ---- bad input --------------------------------------------------------------------
out=$(BUILD="$BUILD" DEMO_SECONDS=abc TMPDIR="$T/tmp" "$demo" 2>&1)
rc=$?
if [ "$rc" -ne 0 ] && [[ "$out" == *"DEMO_SECONDS"* ]] && why=$(demo_leftovers); then
	tap_ok "bad DEMO_SECONDS: clear message, nothing started"
else
	tap_fail "bad DEMO_SECONDS: clear message, nothing started" "exit $rc: $out"
fi
tap_done
