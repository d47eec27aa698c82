#!/usr/bin/env bash
# undulate-sim under bad input from both of its doors:
#  - its pty: a raw client writes seeded random bytes (plain noise, broken
#    headers, impossible lengths, packets with bad checksums), then after a
#    pause a good PING, five rounds: every PING is answered, nothing crashes,
#    and the exit summary counts the bad bytes;
#  - SIM.CMD: random bytes, cut-short and lying-length sim_command_t messages
#    (qa_lcm.py garbage): each is counted in bad_commands, none crashes it.
. "$(dirname "$0")/../lib.sh"
S="$B/undulate-sim"; Q="$top/tests/integration/qa_lcm.py"
[ -x "$S" ] || tap_skip_all "undulate-sim not built"
PORT=$(lcm_port 7954)   # the UDP port itself: qa_lcm.py talks to it raw
URL=$(lcm_url 7954)
py_start sim "$top/tests/integration/sim_client.py"   # one interpreter (tests/lib.sh)
ctl() { py_call sim ctl "$T/ctl" "$1"; }

# a sim_command_t as lcm-gen encodes it, for its fingerprint
spawn cap python3 "$Q" capture $PORT SIM.CMD 10
wait_log cap listening 10
"$S" --cmd "stats" --lcm-url "$URL" >/dev/null 2>&1
wait_for 5 grep -qE '^[0-9a-f]{40,}$' "$T/cap.log"
TEMPLATE=$(grep -E '^[0-9a-f]{40,}$' "$T/cap.log" | head -1)

spawn sim "$S" --link "$T/bus" --ids 1,2 --name r1 --lcm-url "$URL" --control "$T/ctl" --return-delay 0
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }

python3 - "$T/bus" "${QA_SEED:-5}" >"$T/raw.out" 2>&1 <<'EOF'
import os, random, select, sys, termios, time, tty
link, seed = sys.argv[1], int(sys.argv[2])
rng = random.Random(seed)
fd = os.open(link, os.O_RDWR | os.O_NOCTTY)
tty.setraw(fd)
a = termios.tcgetattr(fd)
a[4] = a[5] = termios.B1000000
termios.tcsetattr(fd, termios.TCSANOW, a)

def pkt(i, ins, params=b''):
    body = bytes([i, len(params) + 2, ins]) + params
    return b'\xff\xff' + body + bytes([~sum(body) & 0xff])

def noise():
    k = rng.random()
    if k < 0.3:
        return bytes(rng.randrange(256) for _ in range(rng.randrange(1, 64)))
    if k < 0.5:   # headers that promise what never comes
        return b'\xff\xff' + bytes([rng.choice([1, 2, 0xfe, 0xfd, 0xff]), rng.choice([0, 1, 250, 255])])
    if k < 0.7:   # good shape, bad checksum
        p = bytearray(pkt(rng.choice([1, 2, 0xfe]), rng.choice([1, 2, 3, 4, 5, 6, 0x83, 0x92, 0x08]),
                          bytes(rng.randrange(256) for _ in range(rng.randrange(0, 8)))))
        p[-1] ^= 0xff
        return bytes(p)
    if k < 0.85:  # well-formed, hostile: writes to read-only and reserved registers, huge lengths
        return pkt(rng.choice([1, 2, 0xfe]), rng.choice([3, 2, 0x83, 0x06]),
                   bytes([rng.randrange(256), rng.randrange(256), rng.randrange(256)]))
    return b'\xff' * rng.randrange(1, 20)

def drain(t):
    got, end = b'', time.time() + t
    while time.time() < end:
        r, _, _ = select.select([fd], [], [], max(0, end - time.time()))
        if r:
            try:
                got += os.read(fd, 4096)
            except OSError:
                break
    return got

answered = 0
written = 0
for rnd in range(5):
    end = time.time() + 0.25
    while time.time() < end:
        b = noise()
        os.write(fd, b)
        written += len(b)
        drain(0.005)
    drain(0.15)   # > 100 ms: the servo drops a half-received packet
    os.write(fd, pkt(1, 1))
    reply = drain(0.05)
    if b'\xff\xff\x01\x02' in reply:
        answered += 1
print('written %d answered %d' % (written, answered))
EOF
echo "# $(cat "$T/raw.out")"
read -r _ written _ answered <"$T/raw.out"
if alive sim; then tap_ok "simulator survives $written random bytes on its pty"; else
	tap_fail "simulator survives random bytes" "$(tail -20 "$T/sim.log")"; fi
if [ "${answered:-0}" = 5 ]; then tap_ok "a good PING after each burst is answered (5 of 5)"; else
	tap_fail "PING answered after each burst" "$(cat "$T/raw.out")"; fi

b0=$(ctl stats | sed -n 's/.*bad_commands=\([0-9]*\).*/\1/p')
if [ -n "$TEMPLATE" ]; then
	python3 "$Q" garbage $PORT SIM.CMD "$TEMPLATE" "${QA_SEED:-5}" 200 1.5 >"$T/garbage.out" 2>&1
	bad_at_least() { [ "$(ctl stats | sed -n 's/.*bad_commands=\([0-9]*\).*/\1/p')" -ge "$1" ] 2>/dev/null; }
	wait_for 3 bad_at_least $((b0 + 200))
fi
b1=$(ctl stats | sed -n 's/.*bad_commands=\([0-9]*\).*/\1/p')
got=$(( ${b1:-0} - ${b0:-0} ))
if alive sim && [ "$got" -ge 190 ] && [ "$got" -le 200 ]; then tap_ok "200 malformed SIM.CMD messages: counted ($got)"
else tap_fail "malformed SIM.CMD counted" "template '${TEMPLATE:0:20}', bad_commands $b0 -> $b1; $(tail -5 "$T/sim.log")"; fi
r=$(ctl "servo r1 1")
case "$r" in ok*) tap_ok "control socket still answers";; *) tap_fail "control socket still answers" "$r";; esac

stop sim >/dev/null
summary=$(grep -a "bus r1:" "$T/sim.log" | tail -1)
echo "# $summary"
if [ "$stop_rc" = 0 ]; then tap_ok "clean exit"; else tap_fail "clean exit" "exit $stop_rc"; fi
bc=$(echo "$summary" | sed -n 's/.* \([0-9]*\) bad checksums.*/\1/p'); he=$(echo "$summary" | sed -n 's/.* \([0-9]*\) header errors.*/\1/p')
if [ "${bc:-0}" -gt 0 ] && [ "${he:-0}" -gt 0 ]; then tap_ok "summary counts bad checksums ($bc) and header errors ($he)"
else tap_fail "summary counts the bad input" "$summary"; fi
if grep -aqE "Sanitizer|runtime error" "$T/sim.log"; then
	tap_fail "no sanitizer report" "$(grep -aE -A8 "Sanitizer|runtime error" "$T/sim.log" | head -20)"
else tap_ok "no sanitizer report"; fi
tap_done
