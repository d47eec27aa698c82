#!/usr/bin/env bash
# Array lengths that lie, as anyone on the LCM group can send them: every type
# with an array (robot_state_t.joints, osc_params_t's nine arrays,
# bus_stats_t.servos, sim_truth_t.bodies) with its count set to 0x7fffffff
# (LCM 1.3.1's decoder writes into the NULL its failed malloc returned),
# 0x20000001 (8 x n wraps to 8 in its 32-bit size check: it reads far past the
# packet), 200000 (the decode fails after a 20 MB malloc it never frees), -1,
# -2^31 and one more than the payload holds. Fed to every program that decodes
# what robots publish: `undulated --watch`, `undulate-top`, `undulate-web`
# (whose address space must not grow: the audit saw 90 MB become 122 GB) and
# `undulate-analyze` on a log holding them. Each bad message is counted and
# skipped; the valid ones still show. Decoding goes through
# compat/lcm/lcmdec.c (a checked path around lcm-gen's output).
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; TOP="$B/undulate-top"; A="$B/undulate-analyze"; W="$B/undulate-web"
Q="$top/tests/integration/qa_lcm.py"
for p in "$D" "$TOP" "$A" "$W"; do
	[ -x "$p" ] || tap_skip_all "$(basename "$p") not built"
done
PORT=$(lcm_port 7957)
URL=$(lcm_url 7957)

"$A" --synth "$T/good.log" --duration 3 >/dev/null 2>&1 || { tap_fail "synthetic log" ""; tap_done; exit 1; }
python3 "$Q" arrays "$T/good.log" "$T/bad.log" >"$T/hostile" || { tap_fail "hostile messages" ""; tap_done; exit 1; }
python3 "$Q" templates "$T/good.log" | grep -E '^(r1\.(STATE|PARAMS|BUS)|SIM\.TRUTH) ' >"$T/valid"
nbad=$(wc -l <"$T/hostile"); export nbad
[ "$nbad" -ge 24 ] || { tap_fail "hostile messages: all four types" "$(cut -c1-40 "$T/hostile")"; tap_done; exit 1; }

# ---- a log holding them ----------------------------------------------------------------------
"$A" "$T/bad.log" --out "$T/out" --quiet >"$T/an.log" 2>&1; rc=$?
skipped=$(grep -ac 'does not decode' "$T/an.log")
if [ "$rc" -eq 0 ] && ! grep -aqE "Sanitizer|runtime error" "$T/an.log"; then
	tap_ok "undulate-analyze on a log with $nbad lying array lengths: exit 0"
else tap_fail "undulate-analyze survives lying array lengths" "exit $rc: $(tail -5 "$T/an.log")"; fi
und=$(sed -n 's/^undecodable messages: \([0-9]*\).*/\1/p' "$T/out/summary.txt" 2>/dev/null)
if [ "${und:-0}" -ge "$nbad" ] && [ "$skipped" -ge 1 ]; then
	tap_ok "each is counted ($und undecodable in the summary; STATE and TRUTH are read twice) and named: $(grep -a -m1 'does not decode' "$T/an.log" | cut -c1-160)"
else tap_fail "bad messages counted" "undecodable ${und:-none}; $(head -3 "$T/an.log")"; fi
"$A" "$T/good.log" --out "$T/out_good" --quiet >/dev/null 2>&1
if diff <(grep -v '^log:\|^undecodable' "$T/out/summary.txt") <(grep -v '^log:\|^undecodable' "$T/out_good/summary.txt") >"$T/an.diff"; then
	tap_ok "the rest of the log is analysed as without them"
else tap_fail "analysis unchanged by the bad messages" "$(head "$T/an.diff")"; fi

# ---- on the network ---------------------------------------------------------------------------
spawn watch "$D" --watch '*' --raw --lcm-url "$URL"
spawn top env LCM_DEFAULT_URL="$URL" "$TOP" --json --interval 0.5
spawn web "$W" --listen 127.0.0.1:0 --lcm-url "$URL" --read-only
wait_log web 'listening on http://' 10 || { tap_fail "undulate-web listening" "$(cat "$T/web.log")"; tap_done; exit 1; }
H=$(grep -o 'http://127.0.0.1:[0-9]*' "$T/web.log" | head -1)
bound() { [ "$(grep -c ":$(printf '%04X' "$PORT") " /proc/net/udp)" -ge 3 ]; }
wait_for 5 bound || { tap_fail "watch, top and web listen" "$(cat "$T/watch.log" "$T/top.log")"; tap_done; exit 1; }
vm() { awk '/^VmSize/ { print int($2 / 1024) }' "/proc/$1/status" 2>/dev/null; }
vm0=$(vm "$pid_web")

# 60 rounds of every lie: 1440 messages, 60 of them asking for 200000 joints
rounds=60
python3 "$Q" blast "$PORT" "$T/hostile" "$rounds" >"$T/blast.out"
python3 "$Q" blast "$PORT" "$T/valid" 20 >/dev/null
# the valid messages after them reach every program
wait_for 5 grep -q '^STATE r1 ' "$T/watch.log"
for p in watch top web; do
	if alive "$p"; then tap_ok "$p survives $((nbad * rounds)) messages with lying array lengths"; else
		tap_fail "$p survives lying array lengths" "$(tail -5 "$T/$p.log")"; fi
done
if grep -q '^STATE r1 ' "$T/watch.log" && grep -q '^PARAMS r1 ' "$T/watch.log" && grep -q '^BUS r1 ' "$T/watch.log"; then
	tap_ok "undulated --watch still prints the valid STATE, PARAMS and BUS after them"
else tap_fail "watch prints valid messages" "$(tail -3 "$T/watch.log")"; fi
if grep -aq 'undecodable\|do not decode\|does not decode' "$T/watch.log"; then
	tap_ok "undulated --watch names the bad messages: $(grep -a -m1 'decode' "$T/watch.log" | cut -c1-150)"
else tap_fail "watch names bad messages" "$(grep -av '^STATE\|^BUS\|^PARAMS' "$T/watch.log" | head -3)"; fi
# jq prints true only for an object that says so (empty input prints nothing)
shows() { [ "$(jq -r "(.robots | map(.name) | index(\"r1\")) != null and .decode_errors >= $nbad" 2>/dev/null)" = true ]; }
wait_for 5 bash -c "curl -s '$H/api/snapshot' | $(declare -f shows); shows"
snap=$(curl -s "$H/api/snapshot")
if shows <<<"$snap"; then
	tap_ok "undulate-web shows r1 and counts $(jq .decode_errors <<<"$snap") undecodable messages"
else tap_fail "web shows r1 and counts the bad ones" "$(head -c 300 <<<"$snap")"; fi
wait_for 5 bash -c "tail -1 '$T/top.log' | $(declare -f shows); shows"
if tail -1 "$T/top.log" | shows; then
	tap_ok "undulate-top shows r1 and counts $(tail -1 "$T/top.log" | jq .decode_errors) undecodable messages"
else tap_fail "top shows r1 and counts the bad ones" "$(tail -c 300 "$T/top.log")"; fi
vm1=$(vm "$pid_web")
if [ -n "$vm0" ] && [ -n "$vm1" ] && [ $((vm1 - vm0)) -lt 64 ]; then
	tap_ok "undulate-web's address space: $vm0 MB before, $vm1 MB after (no decode leaks)"
else tap_fail "web does not leak failed decodes" "VmSize $vm0 MB -> $vm1 MB"; fi
for p in watch top web; do
	stop "$p" >/dev/null
	if [ "$stop_rc" -lt 128 ] || [ "$stop_rc" = 143 ]; then tap_ok "$p stops cleanly"; else tap_fail "$p stops" "exit $stop_rc"; fi
done
tap_done
