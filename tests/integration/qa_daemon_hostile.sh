#!/usr/bin/env bash
# undulated against undulate-sim under attack from both sides at once:
#  - LCM, on a robot that takes signed commands from the network
#    (commands = network): random bytes, truncated commands, lying string
#    lengths and well-formed commands with hostile values (NaN, inf, huge,
#    joint -32768, unknown kind, mode and parameter, limits, empty/wrong
#    robot, 8 kB strings) on <robot>.CMD and UNDULATE.CMD (qa_lcm.py, ~100 a
#    second), half of the well-formed ones signed with the robot's key (they
#    reach the validation), the rest unsigned (refused unauthenticated);
#  - the bus: random bytes on the line and corrupted replies (garbage,
#    bad-checksum, truncate, wrong-id faults of the simulator).
# The daemon keeps its 100 Hz loop and keeps publishing, counts every bad
# command (bad_commands) and bus error, accepts none of them, and no goal
# ever leaves the configured joint limits (narrowed to +-0.5 rad so that the
# 0.8 rad limit cycle presses against them).
# QA_MODEL (qa_daemon_hostile_x.sh): X servos of that model on the simulated
# bus (Protocol 2.0, 1 Mbps) instead of AX-12A; QA_PORT its own LCM port.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"; Q="$top/tests/integration/qa_lcm.py"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
PORT=$(lcm_port "${QA_PORT:-7952}")   # the UDP port itself: qa_lcm.py talks to it raw
URL=$(lcm_url "${QA_PORT:-7952}")
R="qa$$"
LIM=0.5
py_start sim "$top/tests/integration/sim_client.py"   # one interpreter (tests/lib.sh)
ctl() { py_call sim ctl "$T/ctl" "$1"; }

KEY="$T/command.key"
"$D" --gen-key "$KEY" >/dev/null || { tap_fail "command key made" "undulated --gen-key failed"; tap_done; exit 1; }
# a command_t as lcm-gen encodes it, for its fingerprint (sent to nobody)
spawn cap python3 "$Q" capture $PORT "nobody$$.CMD" 10
wait_log cap listening 10
"$D" --command 'mode hold' --robot "nobody$$" --lcm-url "$URL" --key "$KEY" --timeout 0.3 >/dev/null 2>&1
wait_for 5 grep -qE '^[0-9a-f]{40,}$' "$T/cap.log"
TEMPLATE=$(grep -E '^[0-9a-f]{40,}$' "$T/cap.log" | head -1)
[ -n "$TEMPLATE" ] || { tap_fail "capture a command_t" "$(cat "$T/cap.log")"; tap_done; exit 1; }

model=()
[ -n "${QA_MODEL:-}" ] && model=(--model "$QA_MODEL" --baud 1000000)
spawn sim "$S" --link "$T/bus" --ids 1,2 --name r1 --lcm-url "$URL" --control "$T/ctl" --seed 5 --return-delay 0 \
	${model[@]+"${model[@]}"}
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode oscillator \
	--set robot.commands=network --set robot.command_key="$KEY" \
	--set joint.1.limit_min=-$LIM --set joint.1.limit_max=$LIM \
	--set joint.2.limit_min=-$LIM --set joint.2.limit_max=$LIM
if wait_log d "ready: $R.STATE" 10 && wait_for 10 cycle_at_least 150 &&
	{ [ -z "${QA_MODEL:-}" ] || grep -q "Protocol 2.0 (${QA_MODEL^^})" "$T/d.log"; }; then
	tap_ok "daemon runs against the simulator${QA_MODEL:+ (${QA_MODEL^^}, Protocol 2.0)}"
else
	tap_fail "daemon runs" "$(tail -5 "$T/d.log")"; tap_done; exit 1
fi

s0=$(last_state)
c0=$(echo "$s0" | field cycle); bad0=$(echo "$s0" | field bad_commands); be0=$(echo "$s0" | field bus_errors)
t0=$(date +%s%N)
# the bus: corrupted replies on both servos, and bursts of random bytes
for f in "fault r1 1 garbage 16 prob=0.2" "fault r1 2 bad-checksum prob=0.2" \
         "fault r1 1 truncate prob=0.1" "fault r1 2 wrong-id prob=0.1"; do
	r=$(ctl "$f"); case "$r" in ok*) ;; *) tap_fail "sim accepts '$f'" "$r" ;; esac
done
spawn garbage bash -c "for i in \$(seq 40); do python3 '$top/tests/integration/sim_client.py' ctl '$T/ctl' 'garbage r1 64' >/dev/null; sleep 0.1; done"
# LCM: 400 hostile messages over 4 s
python3 "$Q" hostile $PORT "$R" "$TEMPLATE" "${QA_SEED:-11}" 400 4 "$KEY" >"$T/hostile.out" 2>&1
echo "# $(cat "$T/hostile.out")"
t1=$(date +%s%N)
ctl "clear r1" >/dev/null
wait_for 5 bash -c "! kill -0 $pid_garbage 2>/dev/null"
# let the last commands be answered
sleep_until=$(( $(last_state | field cycle) + 50 ))
wait_for 5 cycle_at_least $sleep_until
s1=$(last_state)
c1=$(echo "$s1" | field cycle); bad1=$(echo "$s1" | field bad_commands); be1=$(echo "$s1" | field bus_errors)

if alive d; then tap_ok "daemon survives"; else tap_fail "daemon survives" "$(tail -20 "$T/d.log")"; fi
# the loop kept its period: cycles advanced at 100 Hz over the attack
rate=$(awk -v c0="$c0" -v c1="$c1" -v t0="$t0" -v t1="$t1" -v w="$(date +%s%N)" \
	'BEGIN { printf "%.1f", (c1 - c0) / ((w - t0) / 1e9) }')
if awk -v r="$rate" 'BEGIN { exit !(r > 90 && r < 110) }'; then tap_ok "loop kept 100 Hz under attack ($rate Hz)"
else tap_fail "loop kept 100 Hz" "$rate cycles/s ($c0 -> $c1)"; fi
# every published cycle arrived (no gap in STATE longer than 5 cycles)
gap=$(states | awk -v c0="$c0" -v c1="$c1" '{ split($3, kv, "="); c = kv[2]
	if (c >= c0 && c <= c1) { if (have && c - p > g) g = c - p; p = c; have = 1 } } END { print g + 0 }')
if [ "$gap" -le 5 ]; then tap_ok "STATE kept coming (largest gap $gap cycles)"; else
	tap_fail "STATE kept coming" "gap of $gap cycles"; fi

sent=$(awk '{ print $4 + $6 }' "$T/hostile.out")
got=$((bad1 - bad0))
if [ -n "$sent" ] && [ "$got" -ge $((sent * 95 / 100)) ] && [ "$got" -le "$sent" ]; then
	tap_ok "bad commands counted ($got of $sent)"; else
	tap_fail "bad commands counted" "bad_commands rose by $got; $sent bad commands were sent"; fi
acc=$(grep -a "^EVENT $R " "$T/watch.log" | grep -ac "kind=command-accepted")
if [ "$acc" -eq 0 ]; then tap_ok "no hostile command accepted"; else
	tap_fail "no hostile command accepted" "$(grep -a "kind=command-accepted" "$T/watch.log" | head -3)"; fi
if [ "$((be1 - be0))" -gt 0 ]; then tap_ok "bus errors counted ($((be1 - be0)))"; else
	tap_fail "bus errors counted" "bus_errors $be0 -> $be1"; fi

# joints never left their limits: every goal, and the measured angles within
# what a servo overshoots its goal by
out=$(states | awk -v lim=$LIM '{
	for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
	for (j = 0; j < 2; j++) {
		g = v["g" j] + 0; a = v["a" j] + 0
		if (g < -lim - 1e-4 || g > lim + 1e-4) { bg++; if (!eg) eg = $3 " g" j "=" g }
		if (a < -lim - 0.1 || a > lim + 0.1) { ba++; if (!ea) ea = $3 " a" j "=" a }
		if (g > mx) mx = g; if (g < mn) mn = g
	}
	n++
} END { printf "%d %d %d %.4f %.4f %s %s\n", n, bg, ba, mn, mx, eg, ea }')
read -r n bg ba mn mx eg ea <<<"$out"
if [ "$n" -gt 500 ] && [ "$bg" -eq 0 ]; then tap_ok "$n states: goals inside +-$LIM rad (min $mn, max $mx)"
else tap_fail "goals inside the limits" "$n states, $bg outside: $eg"; fi
if [ "$ba" -eq 0 ]; then tap_ok "measured angles inside the limits (+0.1 rad overshoot)"
else tap_fail "measured angles inside the limits" "$ba outside: $ea"; fi
# the limits themselves never changed
pl=$(grep -a "^PARAMS $R " "$T/watch.log" | awk -v lim=$LIM '{
	for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
	n++; if (v["min0"] + lim != 0 || v["max0"] != lim || v["min1"] + lim != 0 || v["max1"] != lim) bad++
} END { print n + 0, bad + 0 }')
read -r np nb <<<"$pl"
if [ "$np" -ge 2 ] && [ "$nb" -eq 0 ]; then tap_ok "limits unchanged in all $np PARAMS"; else
	tap_fail "limits unchanged" "$nb of $np PARAMS differ"; fi

# still obeys a good command afterwards, and stops cleanly
if "$D" --command 'mode sinusoid' --robot "$R" --lcm-url "$URL" --timeout 2 >"$T/cmd.out" 2>&1 &&
	"$D" --command 'mode hold' --robot "$R" --lcm-url "$URL" --key "$KEY" --timeout 2 >>"$T/cmd.out" 2>&1; then
	tap_ok "valid commands are still accepted (local, and signed over LCM)"
else tap_fail "valid commands accepted" "$(cat "$T/cmd.out")"; fi
stop d >/dev/null; rc=$stop_rc
if [ "$rc" = 0 ]; then tap_ok "SIGTERM: clean stop"; else tap_fail "SIGTERM: clean stop" "exit $rc: $(tail -5 "$T/d.log")"; fi
if grep -aqE "Sanitizer|runtime error" "$T/d.log" "$T/sim.log" "$T/watch.log"; then
	tap_fail "no sanitizer report" "$(grep -aE -A5 "Sanitizer|runtime error" "$T/d.log" "$T/sim.log" | head -20)"
else tap_ok "no sanitizer report"; fi
tap_done
