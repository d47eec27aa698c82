#!/usr/bin/env bash
# `undulated --watch ROBOT` for a person: a few states a second (--rate HZ,
# default 4), the mode by name, named fields with units; --raw keeps the
# key=value line of every message that scripts (and these tests) parse.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
R="u$$"
URL=$(lcm_url 7745)

spawn sim "$S" --link "$T/bus" --ids 1,2 --name r1 --lcm-url "$URL" --seed 3
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode oscillator
if wait_log d "ready: $R.STATE" 10; then tap_ok "daemon starts"; else
	tap_fail "daemon starts" "$(cat "$T/d.log")"; tap_done; exit 1; fi

# the state's header line in words: "<robot> 18:55:01.25 OSCILLATOR (start), cycle N: ..."
headers() { grep -acE "^$R [0-9:.-]+ [A-Z]+ \(" "$1"; }

# ---- the default: words, about 4 states a second
"$D" --watch "$R" --lcm-url "$URL" --timeout 3 >"$T/words.out" 2>"$T/words.err"; rc=$?
n=$(headers "$T/words.out")
echo "# default --watch, 3 s: $n states; first lines:"
head -n 4 "$T/words.out" | sed 's/^/#   /'
# 4 Hz for 3 s is 12; a busy machine may deliver a few late or drop one
if [ "$rc" = 0 ] && [ "$n" -ge 8 ] && [ "$n" -le 14 ]; then tap_ok "default rate: $n states in 3 s (4 a second)"
else tap_fail "default rate about 4 states a second" "rc $rc, $n states in 3 s: $(head -c 600 "$T/words.out") $(cat "$T/words.err")"; fi
if grep -qaE "^$R [0-9:.]+ OSCILLATOR \(start\), cycle [0-9]+: period [0-9.]+ ms" "$T/words.out" && ! grep -qaE 'mode=[0-9]' "$T/words.out"; then
	tap_ok "the mode by name (OSCILLATOR), never mode=3"
else tap_fail "mode by name" "$(head -c 600 "$T/words.out")"; fi
if grep -qaE '^  joint 1 \(servo 1\): angle [+-][0-9.]+ rad, speed [+-][0-9.]+ rad/s, goal [+-][0-9.]+ rad' "$T/words.out" &&
	grep -qaE '^  joint 2 \(servo 2\): .*amplitude [0-9.]+ rad at [0-9.]+ Hz, load [+-][0-9]+ %, torque on' "$T/words.out" &&
	! grep -qaE ' (a|s|tl|dr)[0-9]+=' "$T/words.out"; then
	tap_ok "named fields with units, one line a joint"
else tap_fail "named fields with units" "$(head -c 800 "$T/words.out")"; fi

# ---- --rate HZ
"$D" --watch "$R" --lcm-url "$URL" --timeout 2 --rate 10 >"$T/r10.out" 2>&1
n=$(headers "$T/r10.out")
if [ "$n" -ge 14 ] && [ "$n" -le 22 ]; then tap_ok "--rate 10: $n states in 2 s"
else tap_fail "--rate 10 about 20 states in 2 s" "$n: $(head -c 400 "$T/r10.out")"; fi
for bad in 0 -1 abc 1001 nan; do
	out=$("$D" --watch "$R" --lcm-url "$URL" --timeout 1 --rate "$bad" 2>&1); rc=$?
	if [ "$rc" = 2 ] && echo "$out" | grep -q -- "--rate: '$bad' is not"; then :; else
		tap_fail "--rate $bad refused" "rc $rc: $out"; bad=; break; fi
done
[ -n "$bad" ] && tap_ok "--rate 0, -1, abc, 1001, nan refused (exit 2): $out"

# ---- --raw: every state, the key=value line scripts parse
"$D" --watch "$R" --lcm-url "$URL" --timeout 2 --raw >"$T/raw.out" 2>&1
n=$(grep -acE "^STATE $R cycle=[0-9]+ mode=3 .* a0=[-0-9.]+ s0=" "$T/raw.out")
# 100 a second; a busy machine may lose some
if [ "$n" -ge 120 ]; then tap_ok "--raw: every state as key=value ($n in 2 s)"
else tap_fail "--raw every state" "$n: $(head -c 400 "$T/raw.out")"; fi

# ---- what is rare is never thinned out: an event and the parameters in words
"$D" --watch "$R" --lcm-url "$URL" --timeout 3 >"$T/ev.out" 2>&1 &
wpid=$!; _pids+=("$wpid")
wait_for 5 grep -qE "^$R [0-9:.]+ OSC" "$T/ev.out"
"$D" --command 'param c 0.03' --robot "$R" --lcm-url "$URL" --timeout 2 >/dev/null 2>&1
wait "$wpid"
if grep -qaE "^$R event \(info, command-accepted\): " "$T/ev.out" &&
	grep -qaE "^$R parameters: joint 1 k [0-9.e-]+ N m/rad, c 0.03 " "$T/ev.out"; then
	tap_ok "events and changed parameters in words, each time"
else tap_fail "events and parameters in words" "$(grep -av "^ \|^$R at" "$T/ev.out" | head -c 800)"; fi
tap_done
