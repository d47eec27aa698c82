#!/usr/bin/env python3
"""sim_client.py — a raw Dynamixel 1.0 client for the simulator's tests.

  sim_client.py xfer LINK HEX [TIMEOUT_MS] [EXPECT_BYTES]
        write HEX on the pty behind LINK, print "REPLYHEX RTT_US" ("- -1" if
        nothing came within TIMEOUT_MS; stops early at EXPECT_BYTES)
  sim_client.py pkt ID INSTR [PARAM...]      print an instruction packet (hex)
  sim_client.py status ID ERR [PARAM...]     print a status packet (hex)
  sim_client.py ctl SOCKET COMMAND           one control-socket command, print the reply
  sim_client.py lcmlog FILE [--bodies]       per-channel message counts of an LCM log,
                                             the last SIM.TRUTH's total_collisions (and
                                             its bodies: robot id angle speed lateral
                                             neutral load temperature)
  sim_client.py rate FILE CHANNEL            CHANNEL's rate in an LCM log over the log's own
                                             time span: "COUNT SPAN_S HZ" (HZ = (COUNT - 1) /
                                             SPAN_S, from the logger's event timestamps)
  sim_client.py check HEX                    print "valid" if HEX is one well-formed status packet
  sim_client.py pkt2 ID INSTR [PARAM...]     a Protocol 2.0 instruction packet (hex): stuffed,
                                             LEN and CRC filled in (a bitwise CRC-16/0x8005
                                             written here, not the project's table)
  sim_client.py status2 ID ERR [PARAM...]    a Protocol 2.0 status packet (hex)
  sim_client.py split2 HEX                   the 2.0 status packets in HEX, one per line as
                                             "ID ERR PARAMHEX" (unstuffed; "bad" for one whose
                                             CRC or LEN is wrong)
  sim_client.py eio LINK                     print "eio" once reads on LINK fail (bus gone)
Bytes are written in hex, e.g. FFFF010201FB; exits non-zero on usage errors.
The pty is set to $SIM_CLIENT_BAUD bps (default 1000000): the simulator runs
each bus at the rate its controller set.
"""
import os, select, socket, struct, sys, termios, time, tty


def open_link(path):
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(fd)
    attr = termios.tcgetattr(fd)  # the simulator runs the bus at the pty's rate
    rate = os.environ.get("SIM_CLIENT_BAUD", "1000000")
    attr[4] = attr[5] = getattr(termios, "B" + rate)
    termios.tcsetattr(fd, termios.TCSANOW, attr)
    termios.tcflush(fd, termios.TCIFLUSH)  # stale bytes of an earlier exchange
    return fd


def xfer(path, hexs, timeout_ms=100, expect=None):
    fd = open_link(path)
    try:
        data = bytes.fromhex(hexs)
        t0 = time.monotonic()
        os.write(fd, data)
        out, first = b"", None
        end = t0 + timeout_ms / 1000.0
        while True:
            left = end - time.monotonic()
            if left <= 0 or (expect is not None and len(out) >= expect):
                break
            r, _, _ = select.select([fd], [], [], left)
            if r:
                chunk = os.read(fd, 512)
                if first is None:
                    first = time.monotonic() - t0
                out += chunk
        rtt = int(first * 1e6) if first is not None else -1
        print((out.hex().upper() or "-"), rtt)
    finally:
        os.close(fd)


def pkt(args):
    body = [int(a, 0) for a in args]
    ident, instr, params = body[0], body[1], body[2:]
    frame = [ident, len(params) + 2, instr] + params
    print(bytes([0xFF, 0xFF] + frame + [(~sum(frame)) & 0xFF]).hex().upper())


def crc16(data):
    """CRC-16, polynomial 0x8005, initial 0, no reflection: bit by bit, as the
    e-manual's "CRC Calculation" page defines it (not its table)."""
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


def stuff(body):
    """Protocol 2.0 byte stuffing: an FD after FF FF gets a second FD."""
    out = []
    for b in body:
        out.append(b)
        if len(out) >= 3 and out[-3:] == [0xFF, 0xFF, 0xFD]:
            out.append(0xFD)
    return out


def pkt2(args):
    vals = [int(a, 0) for a in args]
    ident, code, params = vals[0], vals[1], vals[2:]
    body = stuff([code] + params)
    frame = [0xFF, 0xFF, 0xFD, 0x00, ident, (len(body) + 2) & 0xFF, (len(body) + 2) >> 8] + body
    crc = crc16(frame)
    print(bytes(frame + [crc & 0xFF, crc >> 8]).hex().upper())


def split2(hexs):
    b = bytes.fromhex(hexs) if hexs != "-" else b""
    i = 0
    while True:
        i = b.find(b"\xff\xff\xfd\x00", i)
        if i < 0 or i + 7 > len(b):
            return
        n = b[i + 5] | (b[i + 6] << 8)
        end = i + 7 + n
        if end > len(b) or n < 4 or crc16(b[i:end - 2]) != (b[end - 2] | (b[end - 1] << 8)):
            print("bad")
            i += 1
            continue
        body, un = list(b[i + 7:end - 2]), []   # INST, ERR, parameters: stuffed
        for k, x in enumerate(body):
            if x == 0xFD and k >= 3 and body[k - 3:k] == [0xFF, 0xFF, 0xFD]:
                continue
            un.append(x)
        print("%d %02X %s" % (b[i + 4], un[1], bytes(un[2:]).hex().upper() or "-"))
        i = end


def ctl(path, command):
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.settimeout(2.0)
    s.connect(path)
    s.sendall((command + "\n").encode())
    buf = b""
    while not buf.endswith(b"\n"):
        chunk = s.recv(1024)
        if not chunk:
            break
        buf += chunk
    s.close()
    print(buf.decode().strip())


def truth_bodies(payload):
    """Decode the bodies of one SIM.TRUTH payload (LCM encoding, big-endian)."""
    # fingerprint, then utime .. worst_lateness_us: ten 8-byte fields
    # (utime, step, sim_time, wall_left, wall_right, total_collisions,
    #  total_impulse, total_resting_steps, total_resting_impulse, worst_lateness_us)
    off = 8 + 10 * 8
    (n,) = struct.unpack(">i", payload[off:off + 4])
    off += 4
    bodies = []
    for _ in range(n):
        (slen,) = struct.unpack(">i", payload[off:off + 4])
        robot = payload[off + 4:off + 4 + slen - 1].decode()
        off += 4 + slen
        (sid,) = struct.unpack(">h", payload[off:off + 2])
        vals = struct.unpack(">6d", payload[off + 2:off + 2 + 48])
        off += 2 + 48
        bodies.append((robot, sid) + vals)
    return bodies


def log_events(path):
    """(utime, channel, payload) of each whole event of an LCM log; stops at
    the first bad sync word or an event the logger has not finished writing."""
    with open(path, "rb") as f:
        data = f.read()
    off = 0
    while off + 28 <= len(data):
        sync, _num, utime, clen, dlen = struct.unpack(">IqqII", data[off:off + 28])
        if sync != 0xEDA1DA01 or off + 28 + clen + dlen > len(data):
            break
        yield utime, data[off + 28:off + 28 + clen].decode(), data[off + 28 + clen:off + 28 + clen + dlen]
        off += 28 + clen + dlen


def rate(path, channel):
    times = [t for t, chan, _ in log_events(path) if chan == channel]
    span = (times[-1] - times[0]) / 1e6 if len(times) > 1 else 0.0
    print("%d %.3f %.1f" % (len(times), span, (len(times) - 1) / span if span > 0 else 0.0))


def lcmlog(path, show_bodies=False):
    counts, last_total, last_payload = {}, None, None
    for _utime, chan, payload in log_events(path):
        counts[chan] = counts.get(chan, 0) + 1
        if chan == "SIM.TRUTH" and len(payload) >= 8 + 8 * 6:
            # fingerprint, utime, step, sim_time, wall_left, wall_right, total_collisions
            last_total = struct.unpack(">q", payload[8 + 40:8 + 48])[0]
            last_payload = payload
    for chan in sorted(counts):
        print(chan, counts[chan])
    print("total_collisions", last_total if last_total is not None else -1)
    if show_bodies and last_payload is not None:
        # robot servo_id angle speed lateral neutral load temperature
        for b in truth_bodies(last_payload):
            print("body", b[0], b[1], " ".join("%.6f" % v for v in b[2:]))


def eio(path, timeout_s=5.0):
    fd = open_link(path)
    print("open", flush=True)
    end = time.monotonic() + timeout_s
    try:
        while time.monotonic() < end:
            r, _, _ = select.select([fd], [], [], 0.05)
            if r:
                try:
                    if os.read(fd, 64) == b"":
                        print("eio")
                        return
                except OSError:
                    print("eio")
                    return
        print("alive")
    finally:
        os.close(fd)


def check(hexs):
    b = bytes.fromhex(hexs) if hexs != "-" else b""
    ok = (len(b) >= 6 and b[0] == 0xFF and b[1] == 0xFF and b[3] + 4 == len(b)
          and b[-1] == (~sum(b[2:-1])) & 0xFF)
    print("valid" if ok else "invalid")


def main(argv):
    if len(argv) >= 3 and argv[1] == "xfer":
        xfer(argv[2], argv[3], int(argv[4]) if len(argv) > 4 else 100,
             int(argv[5]) if len(argv) > 5 else None)
    elif len(argv) >= 4 and argv[1] in ("pkt", "status"):
        pkt(argv[2:])
    elif len(argv) == 4 and argv[1] == "ctl":
        ctl(argv[2], argv[3])
    elif len(argv) in (3, 4) and argv[1] == "lcmlog":
        lcmlog(argv[2], len(argv) == 4 and argv[3] == "--bodies")
    elif len(argv) == 4 and argv[1] == "rate":
        rate(argv[2], argv[3])
    elif len(argv) == 3 and argv[1] == "check":
        check(argv[2])
    elif len(argv) >= 4 and argv[1] == "pkt2":
        pkt2(argv[2:])
    elif len(argv) >= 4 and argv[1] == "status2":
        v = [int(a, 0) for a in argv[2:]]
        pkt2([str(v[0]), "0x55", str(v[1])] + [str(x) for x in v[2:]])
    elif len(argv) == 3 and argv[1] == "split2":
        split2(argv[2])
    elif len(argv) >= 3 and argv[1] == "eio":
        eio(argv[2])
    else:
        sys.stderr.write(__doc__)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
