#!/usr/bin/env bash
# The programs that decode what robots publish — `undulated --watch`,
# `undulate-top`, `undulate-analyze` — fed robot_state_t messages whose first
# string length lies (0, -1, 2^31-1, 2^30), on LCM and inside a log file:
# each bad message is skipped with a warning, valid ones still show, nothing
# crashes. LCM 1.3.1's generated decoders trust those lengths (a crash per bad
# message); the lcm-gen output is compiled with a checked string decoder
# (compat/lcm/lcm_coretypes.h), and this test fails without it.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; TOP="$B/undulate-top"; A="$B/undulate-analyze"; Q="$top/tests/integration/qa_lcm.py"
for p in "$D" "$TOP" "$A"; do
	[ -x "$p" ] || tap_skip_all "$(basename "$p") not built"
done
PORT=$(lcm_port 7955)   # the UDP port itself: the sender below talks to it raw
URL=$(lcm_url 7955)

# a synthetic log: its STATE messages are the template, and a copy of it with
# 60 of them corrupted is the bad log
"$A" --synth "$T/good.log" --duration 3 >/dev/null 2>&1 || { tap_fail "synthetic log" ""; tap_done; exit 1; }
python3 - "$T" <<'EOF' >"$T/template"
import struct, sys
T = sys.argv[1]
d = bytearray(open(T + '/good.log', 'rb').read())
pos, n, template = 0, 0, None
while pos + 28 <= len(d):
    sync, ev, ts, clen, dlen = struct.unpack_from('>IqqII', d, pos)
    ch = d[pos + 28:pos + 28 + clen].decode()
    data = pos + 28 + clen
    if ch == 'r1.STATE':
        if template is None:
            template = bytes(d[data:data + dlen])
        elif n < 60:   # after the fingerprint and utime: the robot name's length
            struct.pack_into('>i', d, data + 16, [0, -1, 2**31 - 1, 2**30][n % 4])
            n += 1
    pos = data + dlen
open(T + '/bad.log', 'wb').write(d)
print(template.hex())
EOF
TEMPLATE=$(cat "$T/template")

spawn watch "$D" --watch '*' --raw --lcm-url "$URL"
# snapshots every half second until stopped: a one-shot window (--once --wait
# 6) closed before the sender's first datagram at load 15
spawn top env LCM_DEFAULT_URL="$URL" "$TOP" --json --interval 0.5
# both have joined the group once two sockets are bound to the port
bound() { [ "$(grep -c ":$(printf '%04X' $PORT) " /proc/net/udp)" -ge 2 ]; }
wait_for 5 bound || { tap_fail "watch and top listen" "$(cat "$T/watch.log" "$T/top.log")"; tap_done; exit 1; }
python3 - "$PORT" "$TEMPLATE" <<EOF
import struct, sys, time
sys.path.insert(0, '$top/tests/integration')
import qa_lcm
port, raw = int(sys.argv[1]), bytes.fromhex(sys.argv[2])
s = qa_lcm.sender()
for i in range(120):
    p = raw if i % 6 == 0 else raw[:16] + struct.pack('>i', [0, -1, 2**31 - 1, 2**30][i % 4]) + raw[20:]
    s.sendto(qa_lcm.datagram(i, 'r1.STATE', p), (qa_lcm.GROUP, port))
    time.sleep(0.005)
EOF
wait_for 20 grep -aq '"r1"' "$T/top.log"
if alive watch; then tap_ok "undulated --watch survives 100 malformed STATE messages"; else
	tap_fail "watch survives" "$(tail -5 "$T/watch.log")"; fi
n=$(grep -ac '^STATE r1 ' "$T/watch.log")
if [ "$n" -ge 15 ]; then tap_ok "it still prints the valid ones ($n of 20)"; else tap_fail "valid STATE printed" "$n"; fi
stop watch >/dev/null
if [ "$stop_rc" -lt 128 ] || [ "$stop_rc" = 143 ]; then tap_ok "watch stops cleanly"; else tap_fail "watch stops" "exit $stop_rc"; fi
top_alive=0; alive top && top_alive=1
stop top >/dev/null
if [ "$top_alive" = 1 ] && { [ "$stop_rc" = 0 ] || [ "$stop_rc" = 143 ]; } && grep -aq '"r1"' "$T/top.log"; then
	tap_ok "undulate-top --json survives them, r1 shown, and stops cleanly"; else
	tap_fail "undulate-top --json survives" "alive $top_alive, exit $stop_rc: $(tail -c 300 "$T/top.log")"; fi

"$A" "$T/bad.log" --out "$T/out" --quiet >"$T/an.log" 2>&1; rc=$?
if [ "$rc" -lt 128 ] && ! grep -aqE "Sanitizer|runtime error" "$T/an.log"; then
	tap_ok "undulate-analyze on a log with 60 corrupted messages: exit $rc, $(grep -ac 'does not decode' "$T/an.log") skipped"
else tap_fail "undulate-analyze survives a corrupted log" "exit $rc: $(tail -5 "$T/an.log")"; fi
tap_done
