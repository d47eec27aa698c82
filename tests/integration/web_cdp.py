#!/usr/bin/env python3
"""web_cdp.py — the browser side of tests/integration/web_dashboard.sh, with
the standard library only (Debian packages no WebSocket module for python3).

  web_cdp.py page DEVTOOLS_PORT URL PNG ROBOT MODE
      drives headless chromium over the DevTools protocol: loads URL, waits
      until the page has drawn frames with samples, takes a screenshot (PNG),
      clicks the page's MODE button of ROBOT, waits for the robot's answer to
      appear in the page's answers box and prints it ("ANSWER <kind> <text>").
  web_cdp.py servos DEVTOOLS_PORT URL PNG ROBOT STATUS [TORQUE]
      loads URL, waits until one of ROBOT's servos shows STATUS (and TORQUE in
      its torque column, if given) in the page's servo table, prints the table's rows ("ROW id °C V error-bits status
      torque", tab-separated) and takes a screenshot (PNG).
  web_cdp.py view DEVTOOLS_PORT URL PNG
      loads URL and prints whether the page offers commands ("VIEW
      commands=<bool> watching=<bool> buttons=<visible mode buttons>");
      takes a screenshot (PNG).
  web_cdp.py world DEVTOOLS_PORT URL PNG KIND ROBOTS
      loads URL, waits until the world view (canvas #worldcanvas) draws KIND
      ("plane" or "row") with ROBOTS robots, then reads the canvas's own pixels
      at every drawn robot's link centres (the page keeps them, in device
      pixels) and prints "WORLD kind=K robots=N links=L marks=M", one
      "ROBOT name colour matching/centres" line per robot (a centre matches
      when its pixel is the robot's colour) and "COLOURED n" (robots with a
      centre in their colour); takes a screenshot of the page (PNG) and of
      the world view alone (PNG with .world before .png).
  web_cdp.py slow HOST PORT SECONDS
      opens a WebSocket to undulate-web and never reads from it: a browser that
      stopped reading. Exits after SECONDS.
  web_cdp.py frames HOST PORT SECONDS
      reads frames for SECONDS and prints "FRAMES n BYTES b SECONDS s" and the
      last status's server counters ("SERVER {...}").
  web_cdp.py say HOST PORT MESSAGE [UNTIL]
      sends MESSAGE as a page would (with the token in $WEB_TOKEN, if set)
      and prints the first note that answers it ("NOTE <kind> <text>"), or
      every note until one of kind UNTIL.
  web_cdp.py freeport
      prints a free TCP port on 127.0.0.1.
"""
import base64, json, os, socket, struct, sys, time, urllib.request


class Closed(ConnectionError):
    """The server's close frame: its status code (RFC 6455 7.4) and reason."""

    def __init__(self, code, reason):
        super().__init__(f"closed by the server: {code} {reason}")
        self.code, self.reason = code, reason


def token_protocols(token):
    """The subprotocols a page offers: "undulate", and with a token the token
    itself as "undulate-token.TOKEN" (tools/web/req.h), as the page does."""
    return "undulate" + (f", undulate-token.{token}" if token else "")


class WS:
    """A minimal RFC 6455 client: text frames, masked as a client must (a test
    may send an unmasked or a binary one: send(masked=False, opcode=2)).
    host_header and origin: what a browser on another site would send."""

    def __init__(self, host, port, path, protocol=None, rcvbuf=None, host_header=None, origin=None):
        self.s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        if rcvbuf:  # before connecting: it sets the window the server may fill
            self.s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        self.s.settimeout(30)
        self.s.connect((host, port))
        key = base64.b64encode(os.urandom(16)).decode()
        req = (f"GET {path} HTTP/1.1\r\nHost: {host_header or f'{host}:{port}'}\r\nUpgrade: websocket\r\n"
               f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n")
        if protocol:
            req += f"Sec-WebSocket-Protocol: {protocol}\r\n"
        if origin:
            req += f"Origin: {origin}\r\n"
        self.s.sendall((req + "\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            c = self.s.recv(1)
            if not c:
                raise ConnectionError("closed during the handshake")
            head += c
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise ConnectionError("handshake refused: " + head.split(b"\r\n")[0].decode())
        self.buf = b""

    def send(self, text, masked=True, opcode=1):
        data = text.encode()
        mask = os.urandom(4) if masked else b""
        m = 0x80 if masked else 0
        n = len(data)
        hdr = bytes([0x80 | opcode]) + (bytes([m | n]) if n < 126 else bytes([m | 126]) + struct.pack(">H", n)
                                        if n < 65536 else bytes([m | 127]) + struct.pack(">Q", n))
        body = bytes(b ^ mask[i % 4] for i, b in enumerate(data)) if masked else data
        self.s.sendall(hdr + mask + body)

    def _need(self, n):
        while len(self.buf) < n:
            c = self.s.recv(65536)
            if not c:
                raise ConnectionError("closed")
            self.buf += c
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def recv(self):
        """The next message: str for a text one, bytes for a binary one."""
        msg = b""
        kind = None
        while True:
            b0, b1 = self._need(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._need(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._need(8))[0]
            payload = self._need(n)
            op = b0 & 0x0F
            if op == 8:
                code = struct.unpack(">H", payload[:2])[0] if len(payload) >= 2 else 1005
                raise Closed(code, payload[2:].decode(errors="replace"))
            if op in (9, 10):
                continue
            if kind is None:
                kind = op
            msg += payload
            if b0 & 0x80:
                return msg if kind == 2 else msg.decode()


class CDP:
    def __init__(self, port):
        deadline = time.time() + 20
        while True:
            try:
                tabs = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json"))
                page = [t for t in tabs if t.get("type") == "page"][0]
                break
            except Exception:
                if time.time() > deadline:
                    raise
                time.sleep(0.1)
        url = page["webSocketDebuggerUrl"]
        rest = url.split("://", 1)[1]
        hostport, path = rest.split("/", 1)
        self.ws = WS("127.0.0.1", int(hostport.rsplit(":", 1)[1]), "/" + path)
        self.n = 0

    def call(self, method, **params):
        self.n += 1
        self.ws.send(json.dumps({"id": self.n, "method": method, "params": params}))
        while True:
            m = json.loads(self.ws.recv())
            if m.get("id") == self.n:
                if "error" in m:
                    raise RuntimeError(f"{method}: {m['error']}")
                return m.get("result", {})

    def js(self, expr):
        r = self.call("Runtime.evaluate", expression=expr, returnByValue=True)
        return r.get("result", {}).get("value")

    def wait(self, expr, timeout):
        deadline = time.time() + timeout
        while time.time() < deadline:
            v = self.js(expr)
            if v:
                return v
            time.sleep(0.1)
        return None


def page(devtools_port, url, png, robot, mode):
    cdp = CDP(int(devtools_port))
    cdp.call("Page.enable")
    cdp.call("Emulation.setDeviceMetricsOverride", width=1300, height=1500, deviceScaleFactor=1, mobile=False)
    cdp.call("Page.navigate", url=url)
    # frames with samples drawn: both robots' joint plots hold points, and a
    # pair's plot holds its phase difference
    drawn = cdp.wait("""(() => { const c = Object.values(Chart.instances || {});
        const pts = c.reduce((n, ch) => n + ch.data.datasets.reduce((m, d) => m + d.data.length, 0), 0);
        return document.querySelectorAll('.robot').length >= 2 && document.querySelectorAll('.pair').length >= 1
               && pts > 500 ? pts : 0; })()""", 20)
    print(f"DRAWN {drawn or 0} points", flush=True)
    print("ROBOTS " + str(cdp.js("[...document.querySelectorAll('.robot h3')].map(h => h.textContent).join(',')")))
    print("CLASS " + str(cdp.js("[...document.querySelectorAll('.pair')].map(p => p.dataset.class).join(',')")))
    time.sleep(1.0)  # another second of lines, so the screenshot shows them moving past
    shot = cdp.call("Page.captureScreenshot", format="png")
    with open(png, "wb") as f:
        f.write(base64.b64decode(shot["data"]))
    # the command: a click on the robot's button, as a person would
    sel = f'button[data-robot="{robot}"][data-mode="{mode}"]'
    clicked = cdp.js(f"(() => {{ const b = document.querySelector('#robot-{robot} {sel}'); if (!b) return false; b.click(); return true; }})()")
    print(f"CLICKED {bool(clicked)}", flush=True)
    ans = cdp.wait(f"""(() => {{ const a = [...document.querySelectorAll('#answers .answer')]
        .filter(e => e.dataset.robot === '{robot}' && e.dataset.kind.startsWith('command-'));
        return a.length ? a[0].dataset.kind + ' ' + a[0].textContent : ''; }})()""", 10)
    print(f"ANSWER {ans}", flush=True)
    mode_shown = cdp.wait(f"""(() => {{ const c = document.getElementById('robot-{robot}');
        return c && c.dataset.mode === '{mode.upper()}' ? c.dataset.mode : ''; }})()""", 5)
    print(f"MODE_SHOWN {mode_shown}", flush=True)
    # the parameter form: the names and ranges the server lists (/api/params),
    # and a value outside its range refused with the daemon's words
    listed = cdp.wait("""(() => { const s = document.getElementById('p-name');
        if (![...s.options].some(o => o.value === 'amplitude')) return '';
        s.value = 'amplitude'; s.dispatchEvent(new Event('change'));
        return [...s.options].map(o => o.value).join(',') + ' ' + document.getElementById('p-range').textContent; })()""", 5)
    print(f"PARAM_RANGE {listed}", flush=True)
    cdp.js("""(() => { document.getElementById('p-value').value = '2.65'; document.getElementById('p-joint').value = '-1';
        document.querySelector('#paramform button[type=submit]').click(); })()""")
    refused = cdp.wait("""(() => { const a = document.querySelector('#answers .answer.refused');
        return a ? a.textContent : ''; })()""", 5)
    print(f"PARAM_REFUSED {refused}", flush=True)


def servos(devtools_port, url, png, robot, want, torque=None):
    """The robot's servo table as the page shows it, once a row's status reads
    WANT (and its torque cell TORQUE, if given) or after 15 s: one "ROW id temp V
    error-bits status torque" line per servo, tab-separated."""
    cdp = CDP(int(devtools_port))
    cdp.call("Page.enable")
    cdp.call("Emulation.setDeviceMetricsOverride", width=1300, height=1100, deviceScaleFactor=1, mobile=False)
    cdp.call("Page.navigate", url=url)
    rows_js = f"""(() => {{ const t = document.querySelector('#robot-{robot} table');
        return t ? [...t.querySelectorAll('tr')].slice(1)
            .map(r => [...r.children].map(c => c.textContent)) : []; }})()"""
    also = f" && r[5] === {json.dumps(torque)}" if torque else ""
    # the rows from the one evaluation that matched: read again a moment later, a
    # busy machine's page may already show the next frame (a bus silent for three
    # cycles reads "SILENT x3" in every row)
    found = cdp.wait(f"(rows => rows.some(r => r[4] === {json.dumps(want)}{also}) && rows)({rows_js})", 15)
    print(f"FOUND {bool(found)}", flush=True)
    for r in found or cdp.js(rows_js) or []:  # tab-separated: a status may hold '|'
        print("ROW\t" + "\t".join(r), flush=True)
    shot = cdp.call("Page.captureScreenshot", format="png")
    with open(png, "wb") as f:
        f.write(base64.b64decode(shot["data"]))


def view(devtools_port, url, png):
    """Loads URL and, once the page has its robots, says whether it offers
    commands: "VIEW commands=<bool> watching=<bool> buttons=<visible mode buttons>",
    and takes a screenshot (PNG)."""
    cdp = CDP(int(devtools_port))
    cdp.call("Page.enable")
    cdp.call("Emulation.setDeviceMetricsOverride", width=1300, height=900, deviceScaleFactor=1, mobile=False)
    cdp.call("Page.navigate", url=url)
    cdp.wait("document.querySelectorAll('.robot').length >= 1 && Number(document.body.dataset.frames || 0) > 3", 20)
    v = cdp.js("""(() => ({ commands: document.body.classList.contains('commands'),
        watching: !document.getElementById('watching').hidden,
        buttons: [...document.querySelectorAll('button[data-mode]')].filter(b => b.offsetParent !== null).length }))()""")
    print(f"VIEW commands={v['commands']} watching={v['watching']} buttons={v['buttons']}", flush=True)
    shot = cdp.call("Page.captureScreenshot", format="png")
    with open(png, "wb") as f:
        f.write(base64.b64decode(shot["data"]))


def world(devtools_port, url, png, kind, robots):
    """The world view as drawn: what the page says it drew, checked against the
    canvas's pixels, and screenshots of the page and of the view."""
    cdp = CDP(int(devtools_port))
    cdp.call("Page.enable")
    cdp.call("Emulation.setDeviceMetricsOverride", width=1300, height=1100, deviceScaleFactor=1, mobile=False)
    cdp.call("Page.navigate", url=url)
    got = cdp.wait(f"""(() => {{ const c = document.getElementById('worldcanvas');
        return c && c.dataset.kind === {json.dumps(kind)} && Number(c.dataset.robots) >= {int(robots)}; }})()""", 40)
    time.sleep(1.0)  # a second of frames: marks appear and fade
    # in one evaluation, between two redraws: what was drawn and the pixels under it
    v = cdp.js("""(() => { const c = document.getElementById('worldcanvas'), ctx = c.getContext('2d');
        const rgb = (h) => { const e = document.createElement('canvas').getContext('2d'); e.fillStyle = h;
            const s = e.fillStyle; return [1, 3, 5].map(i => parseInt(s.slice(i, i + 2), 16)); };
        const near = (p, q) => p.every((v, i) => Math.abs(v - q[i]) <= 24);
        return { kind: c.dataset.kind, robots: Number(c.dataset.robots), links: Number(c.dataset.links),
                 marks: Number(c.dataset.marks),
                 drawn: world.drawn.map(d => ({ name: d.name, color: d.color, n: d.centres.length,
                     hit: d.centres.filter(([x, y]) => near([...ctx.getImageData(x, y, 1, 1).data].slice(0, 3),
                                                            rgb(d.color))).length })) }; })()""")
    print(f"WORLD ready={bool(got)} kind={v['kind']} robots={v['robots']} links={v['links']} marks={v['marks']}",
          flush=True)
    for d in v["drawn"]:
        print(f"ROBOT {d['name']} {d['color']} {d['hit']}/{d['n']}", flush=True)
    print(f"COLOURED {sum(1 for d in v['drawn'] if d['hit'] > 0)}", flush=True)
    shot = cdp.call("Page.captureScreenshot", format="png")
    with open(png, "wb") as f:
        f.write(base64.b64decode(shot["data"]))
    r = cdp.js("""(() => { const b = document.getElementById('worldcanvas').getBoundingClientRect();
        return { x: b.left + window.scrollX, y: b.top + window.scrollY, width: b.width, height: b.height }; })()""")
    shot = cdp.call("Page.captureScreenshot", format="png", clip=dict(r, scale=1), captureBeyondViewport=True)
    with open(png[:-4] + ".world.png", "wb") as f:
        f.write(base64.b64decode(shot["data"]))


def slow(host, port, seconds):
    ws = WS(host, int(port), "/", "undulate", rcvbuf=4096)
    print("SLOW connected", flush=True)
    time.sleep(float(seconds))


def frames(host, port, seconds):
    ws = WS(host, int(port), "/", "undulate")
    n = total = 0
    end = time.time() + float(seconds)
    first = None
    server = None
    while time.time() < end:
        m = ws.recv()
        if first is None:
            first = time.time()
        n += 1
        total += len(m)
        st = json.loads(m).get("status")
        if st:
            server = st.get("server")
    print(f"FRAMES {n} BYTES {total} SECONDS {time.time() - (first or end):.2f}", flush=True)
    print("SERVER " + json.dumps(server), flush=True)


def fox(host, port, seconds):
    """A Foxglove client (foxglove.websocket.v1) that subscribes to every
    channel the server advertises and counts the messages for SECONDS:
    "FOX CHANNELS n MESSAGES n BYTES n SECONDS s"."""
    ws = WS(host, int(port), "/", "foxglove.websocket.v1")
    channels, n, total, sub = {}, 0, 0, 0
    end = time.time() + float(seconds)
    first = None
    while time.time() < end:
        m = ws.recv()
        if isinstance(m, str):
            msg = json.loads(m)
            if msg.get("op") == "advertise":
                new = [c["id"] for c in msg.get("channels", []) if c["id"] not in channels]
                subs = []
                for c in new:
                    sub += 1
                    channels[c] = sub
                    subs.append({"id": sub, "channelId": c})
                if subs:
                    ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
            continue
        if first is None:
            first = time.time()
        n += 1
        total += len(m)
    print(f"FOX CHANNELS {len(channels)} MESSAGES {n} BYTES {total} SECONDS {time.time() - (first or end):.2f}",
          flush=True)


def say(host, port, message, until=None):
    """Send one message; print the first note (not the hello), or with
    `until` every note until one of that kind (the robot's answer)."""
    ws = WS(host, int(port), "/", token_protocols(os.environ.get("WEB_TOKEN")))
    ws.send(message)
    end = time.time() + 5
    seen = set()
    while time.time() < end:
        for n in json.loads(ws.recv()).get("notes", []):
            key = (n["kind"], n["text"])
            if n["kind"] == "hello" or key in seen:
                continue
            seen.add(key)
            print(f"NOTE {n['kind']} {n['text']}", flush=True)
            if until is None or n["kind"] == until:
                return
    print("NOTE none")


def freeport():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    print(s.getsockname()[1])


if __name__ == "__main__":
    cmd = sys.argv[1]
    {"page": page, "view": view, "servos": servos, "world": world, "slow": slow, "frames": frames, "fox": fox, "say": say, "freeport": freeport}[cmd](*sys.argv[2:])
