#!/usr/bin/env bash
# undulate-analyze --record against liblcm's own publisher: a stream replayed
# by lcm-logplayer (small messages, messages at and over the 64 kB datagram
# limit that LCM sends as fragments, a 1 MB one), recorded whole, in order,
# to the byte, without LCM_SELF_TEST (lcm-logger's self-test, sent to the
# group while the stream plays), by one thread (no liblcm receive thread),
# in a few write() calls (a large buffer), with the drop counters on its
# last line.
. "$(dirname "$0")/../lib.sh"
url=$(lcm_url 7768)
A="$B/undulate-analyze"

# A log of N events: channel, payload (bytes that say which event they are),
# 2 ms apart; big ones at a few places.
python3 - "$T/src.log" <<'EOF' || tap_fail "source log written"
import struct, sys
sizes = {10: 65400, 11: 65536, 20: 70000, 40: 200000, 60: 1000000, 61: 131072}
with open(sys.argv[1], "wb") as f:
    for i in range(150):
        ch = ("ROBOT_STATE_r%d" % (i % 4)) if i % 5 else "UNDULATE_EVENT"
        n = sizes.get(i, 40 + (i * 37) % 900)
        data = bytes((i * 7 + k * 13) & 0xFF for k in range(min(n, 4096)))
        data = (data * (n // len(data) + 1))[:n]
        data = struct.pack(">I", i) + data[4:]
        f.write(struct.pack(">IqqII", 0xEDA1DA01, i, 1_000_000 + i * 2000, len(ch), len(data)))
        f.write(ch.encode() + data)
EOF

t0=${EPOCHREALTIME/[.,]/}
spawn rec "$A" --record "$T/rec.lcmlog" --lcm-url "$url"
wait_log rec '^undulate-analyze: recording' 10 || tap_fail "recorder ready" "$(cat "$T/rec.log")"
threads=$(ls "/proc/$pid_rec/task" | wc -l)
# lcm-logger subscribes, and liblcm then sends its self-test to the group
spawn logger lcm-logger --lcm-url="$url" -q "$T/logger.lcmlog"
hexport=$(printf '%04X' "$(lcm_port 7768)")
# its socket is bound once it has subscribed: two sockets on the port then
wait_for 5 test "$(grep -c ":$hexport " /proc/net/udp)" -ge 2 || tap_fail "lcm-logger did not bind"
lcm-logplayer --lcm-url="$url" --speed=1 "$T/src.log" >"$T/player.out" 2>&1
# write() calls so far (the readiness line is one): liblcm's writer made
# one an event (150), a stdio buffer left at glibc's 4 kB about 25
writes=$(awk '$1 == "syscw:" { print $2 }' "/proc/$pid_rec/io")
stop logger INT >/dev/null
stop rec INT >/dev/null
t1=${EPOCHREALTIME/[.,]/}

tap_check "recorder exits 0" test "$stop_rc" = 0
tap_check "the recorder is one thread (no liblcm receive thread): $threads" test "$threads" = 1
tap_check "1.6 MB of events written in a few write() calls: $writes" test "$writes" -le 8

python3 - "$T/src.log" "$T/rec.lcmlog" "$t0" "$t1" >"$T/cmp.out" 2>&1 <<'EOF'
import struct, sys
def events(path):
    out = []
    with open(path, "rb") as f:
        b = f.read()
    o = 0
    while o < len(b):
        sync, num, ts, cl, dl = struct.unpack_from(">IqqII", b, o)
        assert sync == 0xEDA1DA01, "bad sync at %d" % o
        o += 28
        out.append((num, ts, b[o:o + cl].decode(), b[o + cl:o + cl + dl]))
        o += cl + dl
    return out
src, rec = events(sys.argv[1]), events(sys.argv[2])
t0, t1 = int(sys.argv[3]), int(sys.argv[4])
bad = []
if [e for e in rec if e[2] == "LCM_SELF_TEST"]:
    bad.append("LCM_SELF_TEST recorded")
rec = [e for e in rec if e[2] != "LCM_SELF_TEST"]
if [(c, d) for _, _, c, d in src] != [(c, d) for _, _, c, d in rec]:
    bad.append("stream differs: %d events sent, %d recorded" % (len(src), len(rec)))
    for k, (s, r) in enumerate(zip(src, rec)):
        if s[2:] != r[2:]:
            bad.append("first difference at event %d: %s %d bytes vs %s %d bytes" % (k, s[2], len(s[3]), r[2], len(r[3])))
            break
if [e[0] for e in rec] != list(range(len(rec))):
    bad.append("event numbers are not 0, 1, 2, ...")
ts = [e[1] for e in rec]
if ts != sorted(ts) or not ts or ts[0] < t0 or ts[-1] > t1:
    bad.append("timestamps are not the receive times (%d..%d, run %d..%d)" % (ts[0] if ts else 0, ts[-1] if ts else 0, t0, t1))
print("\n".join(bad) if bad else "same %d events" % len(rec))
sys.exit(1 if bad else 0)
EOF
rc=$?
if [ "$rc" = 0 ]; then tap_ok "every message recorded, in order, to the byte, no LCM_SELF_TEST"
else tap_fail "every message recorded, in order, to the byte, no LCM_SELF_TEST" "$(cat "$T/cmp.out")"; fi

last=$(tail -n 1 "$T/rec.log")
tap_check "last line: 150 events, nothing dropped: $last" \
	grep -qE '^undulate-analyze: recorded 150 events \(1\.[0-9] MB\) to .*; dropped 0 \(bad datagrams 0, lost fragments 0, too large 0, kernel 0\)$' \
	<<<"$last"

# bad datagrams on the group are counted, not recorded, and survived
spawn rec2 "$A" --record "$T/rec2.lcmlog" --lcm-url "$url"
wait_log rec2 '^undulate-analyze: recording' 10 || tap_fail "second recorder ready"
python3 - "$(lcm_port 7768)" <<'EOF'
import socket, struct, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
g = ("239.255.76.67", int(sys.argv[1]))
def lc02(seq, ch, data): return struct.pack(">II", 0x4C433032, seq) + ch + b"\0" + data
def lc03(seq, size, off, no, n, body): return struct.pack(">IIIIHH", 0x4C433033, seq, size, off, no, n) + body
s.sendto(b"junk", g)                                      # bad: too short
s.sendto(struct.pack(">II", 0x12345678, 1) + b"X\0", g)   # bad: magic
s.sendto(struct.pack(">II", 0x4C433032, 2) + b"NOEND", g) # bad: channel not ended
s.sendto(lc03(3, 100000, 0, 0, 2, b"BIG\0" + b"a" * 60000), g)   # first half ...
s.sendto(lc03(4, 100000, 0, 0, 2, b"BIG\0" + b"b" * 60000), g)   # ... lost: another message starts
s.sendto(lc03(4, 100000, 60000, 1, 2, b"c" * 50000), g)          # does not fit: lost
s.sendto(lc03(5, 900 << 20, 0, 0, 300, b"HUGE\0" + b"d" * 100), g)  # too large
s.sendto(lc02(6, b"OK", b"fine"), g)
EOF
stop rec2 TERM >/dev/null
last=$(tail -n 1 "$T/rec2.log")
tap_check "bad datagrams counted, the good one kept: $last" \
	grep -qE '^undulate-analyze: recorded 1 events .*; dropped 6 \(bad datagrams 3, lost fragments 2, too large 1, kernel 0\)$' <<<"$last"
tap_check "the second recorder exits 0" test "$stop_rc" = 0

# file:// goes through liblcm as before (read mode: the log replayed into the recording)
spawn rec3 "$A" --record "$T/rec3.lcmlog" --lcm-url "file://$T/src.log?speed=0"
wait_log rec3 'recorded|recording' 10 || :
wait_for 10 grep -q UNDULATE_EVENT "$T/rec3.log" || :
stop rec3 INT >/dev/null
tap_check "file:// URL: recording through liblcm ($(tail -n 1 "$T/rec3.log"))" \
	grep -qE 'recorded [1-9][0-9]* events' "$T/rec3.log"

tap_done
