#!/usr/bin/env bash
# e2e_demo.sh — `make demo DEMO_SECONDS=...` end to end: four robots in the
# channel, one undulated each, headless with an LCM log; the summary names
# every neighbouring pair with its final phase difference, separation and
# state and the collisions per 10 s window; afterwards nothing is left behind
# (no process, no pty link, no socket, no temporary directory) — also when
# the demo is stopped early by SIGTERM.
source "$(dirname "$0")/../lib.sh"

demo="$top/scripts/demo.sh"
# The demo's temporary directory (links, logs) goes under here, so what it
# leaves behind can be seen.
mkdir -p "$T/tmp"
# One LCM port for the three runs (they never overlap), one of five in
# 7850-7854 so that two copies of this test running at once rarely meet.
url=$(lcm_url $((7850 + $$ % 5)))

# leftovers: processes whose command line names the demo's directory, and files in it.
leftovers() {
	local procs files
	procs=$(pgrep -af -- "$T/tmp" | grep -v pgrep)
	files=$(find "$T/tmp" -mindepth 1 2>/dev/null)
	[ -z "$procs$files" ] && return 0
	echo "processes: ${procs:-none}; files: ${files:-none}"
	return 1
}

# ---- a short headless run ------------------------------------------------------
seconds=20
spawn demo env BUILD="$BUILD" DEMO_SECONDS=$seconds DEMO_LCM_URL="$url" TMPDIR="$T/tmp" \
	"$demo" --out "$T/out"
if wait_log demo '^demo: scenario' 15; then
	tap_ok "demo starts the simulator and four daemons"
else
	tap_fail "demo starts the simulator and four daemons" "$(tail -n 20 "$T/demo.log")"
fi
# While it runs: four robots publish on the demo's LCM URL.
n=$("$B/undulate-top" --lcm-url "$url" --once --json --wait 2 2>/dev/null |
	grep -o '"name":"r[0-9]"' | sort -u | wc -l)
if [ "$n" -eq 4 ]; then tap_ok "undulate-top sees the four robots live"; else tap_fail "undulate-top sees the four robots live" "saw $n"; fi

wait_for $((seconds + 40)) bash -c "! kill -0 $pid_demo"
kill -TERM "$pid_demo" 2>/dev/null  # only if it overran
wait "$pid_demo"
rc=$?
if [ "$rc" = 0 ]; then tap_ok "headless demo exits 0"; else tap_fail "headless demo exits 0" "exit $rc; $(tail -n 20 "$T/demo.log")"; fi

out="$T/demo.log"
if grep -q '^=== undulate demo summary: 4 robots' "$out"; then
	tap_ok "summary printed"
else
	tap_fail "summary printed" "$(tail -n 30 "$out")"
fi
# One row per neighbouring pair: name, state, final phase difference, d~, 2 asin(d~), collisions.
pair_rows=$(awk '$1 ~ /^r[0-9]:r[0-9]$/ && $2 ~ /^(in-phase|compatible|anti-phase|still-colliding|no-data)$/ \
	&& $3 ~ /^-?[0-9.]+$/ && $4 ~ /^[0-9.]+$/' "$out" | awk '{ print $1 }' | tr '\n' ' ')
if [ "$pair_rows" = "r1:r2 r2:r3 r3:r4 " ]; then
	tap_ok "summary has the three neighbouring pairs with phase difference, d~ and state"
else
	tap_fail "summary has the three neighbouring pairs with phase difference, d~ and state" "got '$pair_rows'; $(sed -n '/=== undulate/,$p' "$out")"
fi
# Every pair's final phase difference is a real angle and its d~ comes from a
# measured amplitude (channel4: d~ = 0.55 at 0.8 rad; the bases slide a little).
bad=$(awk '$1 ~ /^r[0-9]:r[0-9]$/ && ($3 < -3.1416 || $3 > 3.1416 || $4 <= 0.05 || $4 > 2) { print }' "$out")
if [ -z "$bad" ]; then tap_ok "phase differences within (-pi, pi], d~ plausible"; else tap_fail "phase differences within (-pi, pi], d~ plausible" "$bad"; fi
windows=$(awk '/^collisions per 10 s window:/ { on = 1; next } on && /collisions/ { n++ } END { print n + 0 }' "$out")
if [ "$windows" -ge 2 ]; then
	tap_ok "collision count per 10 s window ($windows windows)"
else
	tap_fail "collision count per 10 s window" "$(sed -n '/collisions per 10 s/,$p' "$out")"
fi
# The switch to OSCILLATOR happened (by one LCM command to every robot).
if grep -qE '^switched sinusoid -> oscillator at t = [0-9.]+ s' "$out"; then
	tap_ok "robots switched from SINUSOID to OSCILLATOR by LCM command"
else
	tap_fail "robots switched from SINUSOID to OSCILLATOR by LCM command" "$(grep -i switch "$out")"
fi
# The summary's numbers are the analyser's: compare with the kept summary.json.
if [ -f "$T/out/summary.json" ] && [ -s "$T/out/demo.lcmlog" ] &&
	grep -q '"pair":"r1:r2"' "$T/out/summary.json"; then
	tap_ok "--out keeps the LCM log and the analysis"
else
	tap_fail "--out keeps the LCM log and the analysis" "$(ls -la "$T/out" 2>&1)"
fi
if why=$(leftovers); then tap_ok "nothing left behind after a full run"; else tap_fail "nothing left behind after a full run" "$why"; fi

# ---- stopped early ---------------------------------------------------------------
# SIGTERM (what `timeout`, a service manager or a closing terminal sends)
# must stop every child and remove the links. (Ctrl-C in a terminal goes to
# the whole foreground process group; a background job here ignores SIGINT.)
spawn demo2 env BUILD="$BUILD" DEMO_SECONDS=60 DEMO_LCM_URL="$url" TMPDIR="$T/tmp" "$demo"
if wait_log demo2 '^demo: phases' 15; then
	links=$(find "$T/tmp" -type l | wc -l)
	# (not $(stop ...): a subshell cannot wait for a child of this shell)
	kill -TERM "$pid_demo2"
	wait "$pid_demo2"
	rc=$?
	if [ "$links" -eq 4 ] && [ "$rc" = 143 ]; then
		tap_ok "SIGTERM stops the demo (exit 143) after it made 4 pty links"
	else
		tap_fail "SIGTERM stops the demo (exit 143) after it made 4 pty links" "links $links, exit $rc"
	fi
	if why=$(leftovers); then tap_ok "nothing left behind after SIGTERM"; else tap_fail "nothing left behind after SIGTERM" "$why"; fi
else
	tap_fail "second demo starts" "$(tail -n 20 "$T/demo2.log")"
fi

# ---- interactive, on a terminal, stopped by Ctrl-C --------------------------------
# `script` gives the demo a pseudo-terminal: undulate-top runs in the
# foreground, and the 0x03 written to the terminal is the user's Ctrl-C (the
# line discipline turns it into SIGINT for the foreground process group).
if command -v script >/dev/null; then
	( wait_for 15 grep -q 'r4 ' "$T/tty.out"; sleep 4; printf '\003'; sleep 5 ) |
		env BUILD="$BUILD" DEMO_LCM_URL="$url" TMPDIR="$T/tmp" \
		timeout 40 script -qec "$demo" /dev/null >"$T/tty.out" 2>&1
	rc=$?
	screen=$(tr -d '\r' <"$T/tty.out" | sed 's/\x1b\[[0-9;?]*[A-Za-z]//g')
	rows=$(echo "$screen" | grep -cE '^. *[1-4] r[1-4] +(SIN|OSC)')
	if [ "$rc" -ne 124 ] && echo "$screen" | grep -q 'OSC' && [ "$rows" -ge 4 ]; then
		tap_ok "interactive: undulate-top shows the four robots, OSCILLATOR after the switch; Ctrl-C ends it"
	else
		tap_fail "interactive: undulate-top shows the four robots; Ctrl-C ends it" "exit $rc, robot rows $rows; $(echo "$screen" | tail -n 15)"
	fi
	if why=$(leftovers); then tap_ok "nothing left behind after Ctrl-C"; else tap_fail "nothing left behind after Ctrl-C" "$why"; fi
fi

# ---- bad input --------------------------------------------------------------------
out=$(BUILD="$BUILD" DEMO_SECONDS=abc TMPDIR="$T/tmp" "$demo" 2>&1)
rc=$?
if [ "$rc" -ne 0 ] && [[ "$out" == *"DEMO_SECONDS"* ]] && why=$(leftovers); then
	tap_ok "bad DEMO_SECONDS: clear message, nothing started"
else
	tap_fail "bad DEMO_SECONDS: clear message, nothing started" "exit $rc: $out"
fi
tap_done
