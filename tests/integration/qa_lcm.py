#!/usr/bin/env python3
"""qa_lcm.py — raw LCM (udpm) traffic for the robustness tests, no LCM binding.

  qa_lcm.py capture PORT CHANNEL TIMEOUT_S    print the hex payload of the first
                                              message on CHANNEL (e.g. a command_t)
  qa_lcm.py hostile PORT ROBOT TEMPLATE_HEX SEED N SECONDS [KEYFILE]
        publish N messages over SECONDS on ROBOT.CMD and UNDULATE.CMD, built from a
        captured command_t (TEMPLATE_HEX gives its fingerprint and layout): random
        bytes, truncated and bit-flipped commands, lying string lengths, and
        well-formed commands with hostile values (NaN, inf, huge, joint -32768,
        unknown kind/mode/param, limits, empty or wrong robot, empty or 8 kB
        strings). With KEYFILE half of the well-formed ones are signed with the
        robot's key (a key holder's buggy client: they reach the validation), the
        rest carry a zero MAC (an attacker's: refused as unauthenticated).
                Prints "sent N undecodable U invalid I signed S" — U + I must be rejected.
  qa_lcm.py forge TEMPLATE_HEX ROBOT KIND MODE PARAM JOINT VALUE [key=FILE] [age=S] [source=S]
        print the hex of one command_t (fingerprint from the template), signed
        with FILE's key if given, its utime S seconds in the past (negative: the
        future), from source S (default "qa")
  qa_lcm.py send PORT CHANNEL HEX [to=ADDR] [times=N]
        publish the command_t HEX on CHANNEL (N times: a replay), to the group,
        or as a unicast datagram to ADDR:PORT (this host's own address: what
        LCM's sockets, bound to every address, take too). Prints "sent N".
  qa_lcm.py flood SOCKET HEX N
        send the command_t HEX N times to a robot's local command socket, as
        fast as it takes them. Prints "sent N".
  qa_lcm.py names PORT PREFIX N
        publish N small messages, each on a channel name never used before
        (PREFIX + a number), as fast as the socket takes them. Prints "sent N".
  qa_lcm.py garbage PORT CHANNEL TEMPLATE_HEX SEED N SECONDS
        publish N malformed messages on CHANNEL: random bytes, the template cut
        short, and the template with its first string's length (after the
        fingerprint, utime and seq) replaced by a lie (negative, zero, huge).
  qa_lcm.py arrays LOG OUT_LOG
        read one message of each type with an array (STATE, PARAMS, BUS, SIM.TRUTH)
        from the log LOG (e.g. undulate-analyze --synth) and write OUT_LOG: LOG with
        hostile copies of them appended, each with an array length that lies
        (0x7fffffff, 0x20000001: 8 x n wraps a 32-bit size, 200000, -1, -2^31, and
        one more than the payload holds). Prints the hostile payloads, one line each:
        "CHANNEL HEX".
  qa_lcm.py templates LOG
        the first message on each channel of LOG, one line each: "CHANNEL HEX".
  qa_lcm.py blast PORT FILE REPEAT
        publish every "CHANNEL HEX" line of FILE REPEAT times, in turn. Prints "sent N".

A udpm message is one datagram: magic "LC02", a sequence number, the channel
name and a NUL, then the payload (lcm_udpm.c, short messages). command_t is
encoded as lcm-gen does: the 8-byte fingerprint, then utime, seq (int64),
source, robot (string: int32 length with the NUL, bytes, NUL), kind, mode
(int8), param (string), joint (int16), value (double), torque (boolean, int8),
then mac (32 bytes: HMAC-SHA256 of everything before it, zeros when unsigned),
all big-endian.
"""
import hashlib, hmac, math, random, socket, struct, sys, time

GROUP = '239.255.76.67'


def sender():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    return s


def datagram(seq, channel, payload):
    return b'LC02' + struct.pack('>I', seq) + channel.encode() + b'\0' + payload


def capture(port, channel, timeout):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    if hasattr(socket, 'SO_REUSEPORT'):
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
    s.bind(('', port))
    mreq = struct.pack('4s4s', socket.inet_aton(GROUP), socket.inet_aton('0.0.0.0'))
    s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
    s.settimeout(0.1)
    print('listening', flush=True)
    end = time.time() + timeout
    while time.time() < end:
        try:
            d = s.recv(65536)
        except socket.timeout:
            continue
        if d[:4] != b'LC02':
            continue
        ch, _, payload = d[8:].partition(b'\0')
        if ch.decode(errors='replace') == channel:
            print(payload.hex(), flush=True)
            return 0
    return 1


def string(v):
    b = v.encode('utf-8', 'surrogateescape') if isinstance(v, str) else v
    return struct.pack('>i', len(b) + 1) + b + b'\0'


def command(fp, utime, seq, source, robot, kind, mode, param, joint, value, torque, key=None):
    body = (fp + struct.pack('>qq', utime, seq) + string(source) + string(robot) + struct.pack('>bb', kind, mode)
            + string(param) + struct.pack('>hd', joint, value) + struct.pack('>B', torque))
    mac = hmac.new(key, body, hashlib.sha256).digest() if key is not None else bytes(32)
    return body + mac


def read_key(path):
    return bytes.fromhex(open(path).read().strip())


def parse_template(raw):
    """The captured command back into its fields: proves our encoding is lcm-gen's."""
    fp, pos = raw[:8], 8
    utime, seq = struct.unpack_from('>qq', raw, pos); pos += 16
    def s(pos):
        n = struct.unpack_from('>i', raw, pos)[0]
        return raw[pos + 4:pos + 4 + n - 1], pos + 4 + n
    source, pos = s(pos)
    robot, pos = s(pos)
    kind, mode = struct.unpack_from('>bb', raw, pos); pos += 2
    param, pos = s(pos)
    joint, value = struct.unpack_from('>hd', raw, pos); pos += 10
    torque = raw[pos]
    again = command(fp, utime, seq, source, robot, kind, mode, param, joint, value, torque)
    if again[:-32] != raw[:-32] or len(again) != len(raw):
        sys.exit('qa_lcm.py: the captured command_t does not re-encode the same way')
    return fp


def hostile(port, robot, template_hex, seed, n, seconds, keyfile=None):
    key = read_key(keyfile) if keyfile else None
    signed = 0
    rng = random.Random(seed)
    raw = bytes.fromhex(template_hex)
    fp = parse_template(raw)
    out = sender()
    params = ['k', 'c', 'mu', 'lambda', 'inertia', 'friction', 'neutral', 'limit_min', 'limit_max', 'max_step',
              'amplitude', 'frequency', 'phase']
    bad_values = [math.nan, math.inf, -math.inf, 1e308, -1e308, 1e30, -1e30]
    undecodable = invalid = 0
    seq = 1000
    for i in range(n):
        seq += 1
        channel = rng.choice([robot + '.CMD', 'UNDULATE.CMD'])
        r = rng.random()
        if r < 0.25:    # random bytes (a fingerprint match is 2^-64)
            payload = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 200)))
            undecodable += 1
        elif r < 0.35:  # a real command cut short
            payload = raw[:rng.randrange(0, len(raw) - 1)]
            undecodable += 1
        elif r < 0.45:  # lying string length (negative or past the end)
            payload = fp + struct.pack('>qq', 0, seq) + struct.pack('>i', rng.choice([-1, -2**31, 2**31 - 1, 0, 10**6]))
            payload += bytes(rng.randrange(256) for _ in range(rng.randrange(0, 40)))
            undecodable += 1
        else:           # well-formed, hostile values: each one must be rejected
            which = rng.choice(['value', 'joint', 'kind', 'mode', 'param', 'robot', 'limits'])
            src = rng.choice(['', 'qa', 'x' * 8000, '\x01\x1b[2J%s%n'])
            kind, mode, param, joint, value, torque, tgt = 2, 0, rng.choice(params), -1, 0.5, 0, robot
            if which == 'value':
                value = rng.choice(bad_values)
                joint = rng.choice([-1, 0, 1])
                if param in ('amplitude', 'frequency', 'phase'):
                    joint = -1
            elif which == 'joint':
                joint = rng.choice([-32768, -2, 2, 3, 16, 32767])
                param, value = 'k', 0.05
            elif which == 'kind':
                kind = rng.choice([0, 5, 6, -1, 127, -128])   # 1..4 are mode, param, torque, clear
            elif which == 'mode':
                kind, mode = 1, rng.choice([-1, 4, 5, 127, -128])
            elif which == 'param':
                param = rng.choice(['', 'K', 'kk', 'x' * 300, 'limit', 'name', 'ids', 'port', 'k ', '\xff'])
                value = 0.05
            elif which == 'robot':
                # on <robot>.CMD naming another robot: rejected (on UNDULATE.CMD
                # it is ignored, so send it on the robot's own channel)
                channel = robot + '.CMD'
                tgt = rng.choice(['', robot + 'x', robot[:-1], 'x' * 200, ' ' + robot])
                kind, mode = 1, 0
            elif which == 'limits':
                # limits that do not contain 0 or leave the servo's range
                joint = rng.choice([-1, 0, 1])
                param, value = rng.choice([('limit_min', 0.2), ('limit_max', -0.2), ('limit_min', -6.0),
                                           ('limit_max', 6.0), ('max_step', 0.0), ('max_step', -0.1),
                                           ('max_step', 2.0)])
            sign = key is not None and rng.random() < 0.5
            payload = command(fp, int(time.time() * 1e6), seq, src, tgt, kind, mode, param, joint, value, torque,
                              key if sign else None)
            signed += sign
            invalid += 1
        out.sendto(datagram(i, channel, payload), (GROUP, port))
        time.sleep(seconds / n)
    print('sent %d undecodable %d invalid %d signed %d' % (n, undecodable, invalid, signed))
    return 0


def garbage(port, channel, template_hex, seed, n, seconds):
    rng = random.Random(seed)
    raw = bytes.fromhex(template_hex)
    out = sender()
    for i in range(n):
        r = rng.random()
        if r < 0.3:
            payload = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 200)))
        elif r < 0.5:
            payload = raw[:rng.randrange(0, len(raw) - 1)]
        else:
            lie = rng.choice([-1, -2**31, 0, 2**31 - 1, 10**6, len(raw)])
            payload = raw[:24] + struct.pack('>i', lie) + raw[28:]
        out.sendto(datagram(i, channel, payload), (GROUP, port))
        time.sleep(seconds / n)
    print('sent %d' % n)
    return 0


def forge(template_hex, robot, kind, mode, param, joint, value, opts):
    fp = parse_template(bytes.fromhex(template_hex))
    key = read_key(opts['key']) if 'key' in opts else None
    utime = int((time.time() - float(opts.get('age', 0))) * 1e6)
    payload = command(fp, utime, utime, opts.get('source', 'qa'), robot, kind, mode, param, joint, value, 0, key)
    print(payload.hex())
    return 0


def send(port, channel, payload_hex, opts):
    out = sender()
    payload = bytes.fromhex(payload_hex)
    n = int(opts.get('times', 1))
    to = opts.get('to', GROUP)
    for i in range(n):
        out.sendto(datagram(i, channel, payload), (to, port))
    print('sent %d' % n)
    return 0


def flood(path, payload_hex, n):
    s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    payload = bytes.fromhex(payload_hex)
    for i in range(n):
        s.sendto(payload, path)
    print('sent %d' % n)
    return 0


def names(port, prefix, n):
    out = sender()
    payload = bytes(16)
    for i in range(n):
        while True:
            try:
                out.sendto(datagram(i, '%s%d' % (prefix, i), payload), (GROUP, port))
                break
            except BlockingIOError:
                time.sleep(0.001)
    print('sent %d' % n)
    return 0


# ---- array lengths that lie ------------------------------------------------------------------
# Where each type's array count sits, as lcm-gen lays the fields out: the
# fixed fields are skipped by size, strings by their own (trusted: these are
# our own valid messages) length. 's' is a string, a number a fixed field.
ARRAY_LAYOUT = {
    'STATE':     [8, 8, 's', 8, 1, 's', 's', 32, 24],      # robot_state_t: ... njoints
    'PARAMS':    [8, 8, 's'],                              # osc_params_t: ... njoints
    'BUS':       [8, 8, 's', 's', 4, 1, 8, 8, 4, 48, 24],  # bus_stats_t: ... nservos
    'SIM.TRUTH': [8, 80],                                  # sim_truth_t: ... nbodies
}
LIES = [0x7fffffff, 0x20000001, 200000, -1, -2**31]


def read_log(path):
    d = open(path, 'rb').read()
    pos, events = 0, []
    while pos + 28 <= len(d):
        sync, ev, ts, clen, dlen = struct.unpack_from('>IqqII', d, pos)
        ch = d[pos + 28:pos + 28 + clen].decode()
        data = d[pos + 28 + clen:pos + 28 + clen + dlen]
        events.append((ev, ts, ch, data))
        pos += 28 + clen + dlen
    return events


def count_offset(kind, raw):
    pos = 0
    for f in ARRAY_LAYOUT[kind]:
        pos += 4 + struct.unpack_from('>i', raw, pos)[0] if f == 's' else f
    return pos


def hostile_arrays(events):
    """(channel, payload) for each lie in each type with an array."""
    out, seen = [], set()
    for _, _, ch, raw in events:
        kind = ch if ch == 'SIM.TRUTH' else ch.rsplit('.', 1)[-1]
        if kind not in ARRAY_LAYOUT or kind in seen:
            continue
        seen.add(kind)
        at = count_offset(kind, raw)
        n = struct.unpack_from('>i', raw, at)[0]
        for lie in LIES + [n + 1]:
            out.append((ch, raw[:at] + struct.pack('>i', lie) + raw[at + 4:]))
    return out


def arrays(log, out_log):
    events = read_log(log)
    bad = hostile_arrays(events)
    with open(out_log, 'wb') as f:
        ev, ts = events[-1][0] + 1, events[-1][1] + 1000
        for e, t, ch, data in events + [(ev + i, ts + 1000 * i, ch, p) for i, (ch, p) in enumerate(bad)]:
            c = ch.encode()
            f.write(struct.pack('>IqqII', 0xEDA1DA01, e, t, len(c), len(data)) + c + data)
    for ch, p in bad:
        print(ch, p.hex())
    return 0


def templates(log):
    seen = set()
    for _, _, ch, raw in read_log(log):
        if ch not in seen:
            seen.add(ch)
            print(ch, raw.hex())
    return 0


def blast(port, path, repeat):
    out = sender()
    lines = [l.split() for l in open(path) if l.strip()]
    n = 0
    for r in range(repeat):
        for ch, hx in lines:
            while True:
                try:
                    out.sendto(datagram(n, ch, bytes.fromhex(hx)), (GROUP, port))
                    break
                except BlockingIOError:
                    time.sleep(0.001)
            n += 1
            if n % 50 == 0:
                time.sleep(0.002)   # let the receivers keep up: lost datagrams test nothing
    print('sent %d' % n)
    return 0


def main(argv):
    if len(argv) >= 4 and argv[1] == 'capture':
        return capture(int(argv[2]), argv[3], float(argv[4]) if len(argv) > 4 else 5)
    if len(argv) in (8, 9) and argv[1] == 'hostile':
        return hostile(int(argv[2]), argv[3], argv[4], int(argv[5]), int(argv[6]), float(argv[7]),
                       argv[8] if len(argv) == 9 else None)
    kv = lambda args: dict(a.split('=', 1) for a in args)
    if len(argv) >= 9 and argv[1] == 'forge':
        return forge(argv[2], argv[3], int(argv[4]), int(argv[5]), argv[6], int(argv[7]), float(argv[8]),
                     kv(argv[9:]))
    if len(argv) >= 5 and argv[1] == 'send':
        return send(int(argv[2]), argv[3], argv[4], kv(argv[5:]))
    if len(argv) == 5 and argv[1] == 'flood':
        return flood(argv[2], argv[3], int(argv[4]))
    if len(argv) == 5 and argv[1] == 'names':
        return names(int(argv[2]), argv[3], int(argv[4]))
    if len(argv) == 8 and argv[1] == 'garbage':
        return garbage(int(argv[2]), argv[3], argv[4], int(argv[5]), int(argv[6]), float(argv[7]))
    if len(argv) == 4 and argv[1] == 'arrays':
        return arrays(argv[2], argv[3])
    if len(argv) == 3 and argv[1] == 'templates':
        return templates(argv[2])
    if len(argv) == 5 and argv[1] == 'blast':
        return blast(int(argv[2]), argv[3], int(argv[4]))
    sys.stderr.write(__doc__)
    return 2


if __name__ == '__main__':
    sys.exit(main(sys.argv))
