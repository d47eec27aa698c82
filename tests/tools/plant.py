#!/usr/bin/env python3
"""plant.py — a test plant unlike undulate-sim: AX-12 servos on a pty whose
joints track the goal at a rated speed.

undulate-sim models the AX-12A's insides (a DC motor's torque-speed line
under a compliance-slope position loop, link inertia, friction). This plant
shares none of that, nor any of the project's code: its own Protocol 1.0
parser, its own control table, and a kinematic joint — the velocity wanted
is the goal error times a gain (a proportional servo), capped at a rated
speed, and the joint's velocity follows it with a first-order lag; an
optional sensor delay makes the reported position old. It is what an
emulator that "tracks the goal at the servo's rated speed" does, and the
oscillator's gait through it differs from the simulator's: that is what the
tests use it for (undulated --tune on a plant it was not tuned on).

    plant.py --link PATH --ids 1,2 [--rated-speed RAD_S] [--gain 1/S]
             [--tau S] [--delay-ms MS] [--voltage V]

Prints "plant: ready PATH" once the link exists; runs until SIGTERM/SIGINT,
then removes the link and prints its counters. Joint mode only (wheel mode,
CW = CCW = 0, is refused with an instruction error). Replies are sent at
once (the return delay register is stored, not waited for).
"""
import argparse
import math
import os
import select
import signal
import sys
import time
import tty

RAD_PER_UNIT = math.radians(300.0) / 1023.0   # present/goal position
SPEED_UNIT = 0.111 * 2 * math.pi / 60         # rad/s per speed unit (0.111 rpm)

# AX-12A control table at power-up (address: value); 16-bit values little-endian.
EEPROM = {0: 12, 1: 0, 2: 24, 3: 1, 4: 1, 5: 250, 6: 0, 7: 0, 8: 0xFF, 9: 0x03, 11: 70, 12: 60, 13: 140,
          14: 0xFF, 15: 0x03, 16: 2, 17: 36, 18: 36}
RAM = {24: 0, 25: 0, 26: 1, 27: 1, 28: 32, 29: 32, 48: 32, 49: 0}
TABLE_LEN = 50
INST_PING, INST_READ, INST_WRITE, INST_REG_WRITE, INST_ACTION, INST_RESET, INST_SYNC_WRITE = 1, 2, 3, 4, 5, 6, 0x83
ERR_VOLTAGE, ERR_ANGLE, ERR_RANGE, ERR_CHECKSUM, ERR_INSTRUCTION = 0x01, 0x02, 0x08, 0x10, 0x40


def u16(t, a):
    return t[a] | t[a + 1] << 8


class Servo:
    def __init__(self, sid, args):
        self.args = args
        self.t = bytearray(TABLE_LEN)
        for a, v in EEPROM.items():
            self.t[a] = v
        for a, v in RAM.items():
            self.t[a] = v
        self.t[3] = sid
        self.t[34], self.t[35] = self.t[14], self.t[15]  # torque limit from max torque
        self.t[42] = int(round(args.voltage * 10))
        self.t[43] = 35
        self.t[30], self.t[31] = 0, 2   # goal 512
        self.angle = 0.05                # at rest, a little off centre
        self.speed = 0.0
        self.history = []   # (time, angle, speed) for the sensor delay
        self.registered = None

    @property
    def sid(self):
        return self.t[3]

    def step(self, dt):
        a = self.args
        t = self.t
        limit = u16(t, 34) / 1023.0
        if t[24] and limit > 0:
            goal = (u16(t, 30) - 512) * RAD_PER_UNIT
            err = goal - self.angle
            margin = (t[26] if err < 0 else t[27]) * RAD_PER_UNIT
            vmax = a.rated_speed * a.voltage / 12.0 * min(1.0, 2.0 * limit)
            ms = u16(t, 32) & 0x3FF
            if ms:
                vmax = min(vmax, ms * SPEED_UNIT)
            want = 0.0 if abs(err) <= margin else max(-vmax, min(vmax, a.gain * err))
            self.speed += (want - self.speed) * min(1.0, dt / a.tau)
        else:
            self.speed *= math.exp(-dt / 0.05)
        self.angle += self.speed * dt
        lo, hi = -512 * RAD_PER_UNIT, 511 * RAD_PER_UNIT
        if self.angle < lo or self.angle > hi:
            self.angle = max(lo, min(hi, self.angle))
            self.speed = 0.0

    def sense(self, now):
        """Present position/speed/moving, as old as --delay-ms."""
        self.history.append((now, self.angle, self.speed))
        cut = now - self.args.delay_ms * 1e-3
        while len(self.history) > 1 and self.history[1][0] <= cut:
            self.history.pop(0)
        _, ang, spd = self.history[0]
        pos = max(0, min(1023, int(round(512 + ang / RAD_PER_UNIT))))
        units = min(1023, int(round(abs(spd) / SPEED_UNIT)))
        raw = units | (0x400 if spd < 0 else 0)
        t = self.t
        t[36], t[37] = pos & 0xFF, pos >> 8
        t[38], t[39] = raw & 0xFF, raw >> 8
        t[40] = t[41] = 0
        t[46] = 1 if abs(spd) > 0.02 else 0

    def write(self, addr, data):
        """Returns the error byte."""
        if addr + len(data) > TABLE_LEN or addr < 0:
            return ERR_RANGE
        t = self.t
        new = bytearray(t)
        new[addr:addr + len(data)] = data
        if u16(new, 6) == 0 and u16(new, 8) == 0:
            return ERR_INSTRUCTION   # wheel mode: not modelled here
        for a in range(addr, addr + len(data)):
            if a in (0, 1, 2) or 36 <= a <= 46:
                continue   # read-only
            t[a] = new[a]
        if addr <= 24 < addr + len(data) and t[24]:
            # torque on: the limit comes back from max torque
            t[34], t[35] = t[14], t[15]
        goal = u16(t, 30)
        if goal < u16(t, 6) or goal > u16(t, 8):
            return ERR_ANGLE
        return 0


class Plant:
    def __init__(self, args):
        self.args = args
        self.servos = {}
        for sid in args.ids:
            s = Servo(sid, args)
            self.servos[sid] = s
        self.buf = bytearray()
        self.packets = self.replies = self.bad = 0
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        tty.setraw(self.master)
        if os.path.lexists(args.link):
            if not os.path.islink(args.link):
                sys.exit(f"plant: {args.link} exists and is not a symlink: refusing to replace it")
            os.unlink(args.link)
        os.symlink(os.ttyname(self.slave), args.link)
        self.last = time.monotonic()

    def advance(self):
        now = time.monotonic()
        dt = now - self.last
        steps = max(1, int(math.ceil(dt / 0.001)))
        for s in self.servos.values():
            for _ in range(steps):
                s.step(dt / steps)
            s.sense(now)
        self.last = now

    def reply(self, s, err, params=b""):
        body = bytes([s.sid, len(params) + 2, err]) + bytes(params)
        pkt = b"\xff\xff" + body + bytes([(~sum(body)) & 0xFF])
        os.write(self.master, pkt)
        self.replies += 1

    def handle(self, sid, inst, p):
        self.packets += 1
        if inst == INST_SYNC_WRITE:
            if sid != 0xFE or len(p) < 2:
                return
            addr, n = p[0], p[1]
            body = p[2:]
            for i in range(0, len(body) - n, n + 1):
                s = self.servos.get(body[i])
                if s:
                    s.write(addr, body[i + 1:i + 1 + n])
            return
        targets = list(self.servos.values()) if sid == 0xFE else [self.servos[sid]] if sid in self.servos else []
        for s in targets:
            level = s.t[16]
            if inst == INST_PING:
                if sid != 0xFE:
                    self.reply(s, 0)   # at every status return level
            elif inst == INST_READ and len(p) == 2:
                a, n = p[0], p[1]
                if sid != 0xFE and level >= 1:
                    if a + n > TABLE_LEN:
                        self.reply(s, ERR_RANGE)
                    else:
                        self.reply(s, 0, s.t[a:a + n])
            elif inst == INST_WRITE and len(p) >= 2:
                err = s.write(p[0], p[1:])
                if sid != 0xFE and level >= 2:
                    self.reply(s, err)
            elif inst == INST_REG_WRITE and len(p) >= 2:
                s.registered = (p[0], bytes(p[1:]))
                s.t[44] = 1
                if sid != 0xFE and level >= 2:
                    self.reply(s, 0)
            elif inst == INST_ACTION:
                if s.registered:
                    s.write(*s.registered)
                    s.registered = None
                    s.t[44] = 0
            elif inst == INST_RESET:
                keep = s.sid
                if sid != 0xFE and level >= 2:
                    self.reply(s, 0)
                self.servos.pop(keep)
                n = Servo(1, self.args)
                self.servos[1] = n
            elif sid != 0xFE:
                self.reply(s, ERR_INSTRUCTION)

    def feed(self, data):
        self.buf += data
        while True:
            i = self.buf.find(b"\xff\xff")
            if i < 0:
                self.buf = self.buf[-1:] if self.buf[-1:] == b"\xff" else bytearray()
                return
            if i:
                del self.buf[:i]
            if len(self.buf) < 4:
                return
            sid, ln = self.buf[2], self.buf[3]
            if sid == 0xFF:
                del self.buf[:1]
                continue
            if len(self.buf) < ln + 4:
                return
            pkt = bytes(self.buf[:ln + 4])
            del self.buf[:ln + 4]
            if ln < 2 or (~sum(pkt[2:-1])) & 0xFF != pkt[-1]:
                self.bad += 1
                continue
            self.advance()
            self.handle(sid, pkt[4], pkt[5:-1])

    def run(self):
        stop = []
        signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
        signal.signal(signal.SIGINT, lambda *_: stop.append(1))
        print(f"plant: ready {self.args.link}", flush=True)
        try:
            while not stop:
                try:
                    r, _, _ = select.select([self.master], [], [], 0.001)
                except InterruptedError:
                    continue
                if r:
                    try:
                        data = os.read(self.master, 4096)
                    except OSError:
                        data = b""
                    if data:
                        self.feed(data)
                self.advance()
        finally:
            try:
                os.unlink(self.args.link)
            except OSError:
                pass
            print(f"plant: {self.packets} packets, {self.replies} replies, {self.bad} bad", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--link", required=True)
    ap.add_argument("--ids", default="1,2", type=lambda s: [int(x) for x in s.split(",")])
    ap.add_argument("--rated-speed", type=float, default=6.18, help="rad/s at 12 V (AX-12A: 59 rpm)")
    ap.add_argument("--gain", type=float, default=40.0, help="1/s: wanted speed per rad of goal error")
    ap.add_argument("--tau", type=float, default=0.015, help="s: velocity lag")
    ap.add_argument("--delay-ms", type=float, default=0.0, help="sensor delay")
    ap.add_argument("--voltage", type=float, default=12.0)
    args = ap.parse_args()
    for v, name in ((args.rated_speed, "rated speed"), (args.gain, "gain"), (args.tau, "tau"), (args.voltage, "voltage")):
        if not (v > 0 and math.isfinite(v)):
            ap.error(f"{name} must be a positive number")
    if not (0 <= args.delay_ms <= 200):
        ap.error("delay-ms: 0 .. 200")
    Plant(args).run()


if __name__ == "__main__":
    main()
