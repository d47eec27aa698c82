#!/usr/bin/env python3
"""web_attack.py — hostile clients of undulate-web, for tests/integration/safety_web.sh
(standard library only; the WebSocket client is web_cdp.py's).

  web_attack.py ws HOST PORT [host=H] [origin=O] [token=T] [proto=P] [unmasked] [binary] MESSAGE [UNTIL]
      one WebSocket: the handshake with Host H (default HOST:PORT), Origin O,
      the token T offered as the page offers it (or the subprotocol list P
      instead; "none": no Sec-WebSocket-Protocol); prints "OPEN <ms>" (the time
      from connect to the server's 101) or "REFUSED <why>"; then sends MESSAGE
      (unmasked, or as a binary frame, if said) once the first frame came,
      and prints the notes ("NOTE <kind> <text>", the hello first) until one of kind
      UNTIL (default: the first after the hello), or "CLOSED <code> <reason>"
      when the server closes, or "NOTE none" after 5 s.
  web_attack.py crowd HOST PORT NWS NHALF SECONDS
      NWS token-less WebSockets and NHALF half-open HTTP connections (half of
      them send nothing, half a request that never ends), held for SECONDS; a
      connection the server closes is opened again, as an attacker who keeps
      at it would. Prints "CROWD ws=<open> ws_refused=<n> half=<open>" once all
      were tried, then "END ws=<open> half=<open> reopened=<n> ws_refused=<n>".
  web_attack.py state PORT TEMPLATE_HEX NAME N
      publishes N copies of a captured robot_state_t (hex, from qa_lcm.py
      capture) with its robot renamed NAME (Python escapes allowed, e.g.
      'a\\x07b'), on "evil.STATE" (udpm, ttl 0), one every 20 ms.
"""
import json, os, select, signal, socket, struct, sys, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from web_cdp import WS, Closed, token_protocols  # noqa: E402


def ws(host, port, *args):
    opts, flags, rest = {}, set(), []
    for a in args:
        if a.startswith(("host=", "origin=", "token=", "proto=")):
            k, _, v = a.partition("=")
            opts[k] = v
        elif a in ("unmasked", "binary"):
            flags.add(a)
        else:
            rest.append(a)
    message, until = rest[0], (rest[1] if len(rest) > 1 else None)
    t0 = time.time()
    try:
        proto = opts.get("proto", token_protocols(opts.get("token")))
        w = WS(host, int(port), "/", None if proto == "none" else proto, host_header=opts.get("host"),
               origin=opts.get("origin"))
    except (ConnectionError, OSError) as e:
        print(f"REFUSED {e}", flush=True)
        return 1
    print(f"OPEN {1000 * (time.time() - t0):.1f}", flush=True)
    # the first frame (whole history, the hello) read first, as a page does:
    # a server closing on our next frame then has nothing half-sent before its close frame
    seen = set()
    try:
        for n in json.loads(w.recv()).get("notes", []):
            seen.add((n["kind"], n["text"]))
            print(f"NOTE {n['kind']} {n['text']}", flush=True)
    except (ConnectionError, OSError) as e:
        print(f"CLOSED none {e}", flush=True)
        return 0
    w.send(message.encode().decode("unicode_escape"), masked="unmasked" not in flags,
           opcode=2 if "binary" in flags else 1)
    end = time.time() + 5
    try:
        while time.time() < end:
            w.s.settimeout(max(0.1, end - time.time()))
            for n in json.loads(w.recv()).get("notes", []):
                key = (n["kind"], n["text"])
                if key in seen:
                    continue
                seen.add(key)
                print(f"NOTE {n['kind']} {n['text']}", flush=True)
                if n["kind"] != "hello" and (until is None or n["kind"] == until):
                    return 0
    except Closed as e:
        print(f"CLOSED {e.code} {e.reason}", flush=True)
        return 0
    except (ConnectionError, OSError) as e:
        print(f"CLOSED none {e}", flush=True)
        return 0
    print("NOTE none", flush=True)
    return 0


class Crowd:
    def __init__(self, host, port):
        self.host, self.port = host, int(port)
        self.ws, self.half = [], []
        self.reopened = self.ws_refused = 0
        self.n = 0

    def open_ws(self):
        try:
            w = WS(self.host, self.port, "/", "undulate")
        except (ConnectionError, OSError):
            self.ws_refused += 1
            return False
        w.s.setblocking(False)
        self.ws.append(w.s)
        return True

    def open_half(self):
        s = socket.socket()
        try:
            s.connect((self.host, self.port))
            # a slow client: the request line, and never the end of the headers
            if self.n % 2:
                s.sendall(b"GET /api/snapshot HTTP/1.1\r\nHost: " + self.host.encode() + b"\r\n")
        except OSError:
            s.close()
            return False
        self.n += 1
        s.setblocking(False)
        self.half.append(s)
        return True

    def reap(self, socks):
        """The sockets the server closed (readable with nothing, or an error)."""
        gone = []
        r, _, _ = select.select(socks, [], [], 0)
        for s in r:
            try:
                if s.recv(65536) == b"":
                    gone.append(s)
            except BlockingIOError:
                pass
            except OSError:
                gone.append(s)
        for s in gone:
            socks.remove(s)
            s.close()
        return len(gone)


def crowd(host, port, nws, nhalf, seconds):
    c = Crowd(host, port)
    nws, nhalf = int(nws), int(nhalf)
    for _ in range(nws):
        c.open_ws()
    for _ in range(nhalf):
        c.open_half()
    print(f"CROWD ws={len(c.ws)} ws_refused={c.ws_refused} half={len(c.half)}", flush=True)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))  # stopped early: still say what it did
    end = time.time() + float(seconds)
    try:
        while time.time() < end:
            time.sleep(0.05)  # an attacker that keeps at it, not a CPU burner
            c.reap(c.ws)
            c.reap(c.half)
            while len(c.half) < nhalf and c.open_half():
                c.reopened += 1
            if len(c.ws) < nws and c.open_ws():
                c.reopened += 1
    finally:
        print(f"END ws={len(c.ws)} half={len(c.half)} reopened={c.reopened} ws_refused={c.ws_refused}", flush=True)
    return 0


def state(port, template_hex, name, n):
    raw = bytes.fromhex(template_hex)
    pos = 16  # fingerprint, utime
    ln = struct.unpack_from(">i", raw, pos)[0]
    rest = raw[pos + 4 + ln:]
    b = name.encode().decode("unicode_escape").encode("latin-1")
    payload = raw[:pos] + struct.pack(">i", len(b) + 1) + b + b"\0" + rest
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    for seq in range(int(n)):
        s.sendto(b"LC02" + struct.pack(">I", seq) + b"evil.STATE\0" + payload, ("239.255.76.67", int(port)))
        time.sleep(0.02)
    print(f"sent {n}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit({"ws": ws, "crowd": crowd, "state": state}[sys.argv[1]](*sys.argv[2:]))
