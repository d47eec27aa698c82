#!/usr/bin/env bash
# undulated speaks systemd's notify protocol as Type=notify + WatchdogSec need:
# the test plays systemd. It owns a unix datagram socket ($NOTIFY_SOCKET),
# starts the daemon against the simulator with WATCHDOG_USEC set, and checks:
#   - READY=1 arrives, then WATCHDOG=1, from the daemon's own PID
#     (NotifyAccess=main drops anything else);
#   - while healthy, no gap between WATCHDOG=1 pings reaches WATCHDOG_USEC
#     (systemd would kill it);
#   - STATUS= carries the documented summary;
#   - when the control loop stalls, the pings stop (so systemd kills and
#     restarts it), and come back when the loop runs again;
#   - SIGTERM gives STOPPING=1 and exit status 0.
#
# The stall: the daemon is single-threaded and logs to stderr, like under
# journald. The test fills the stderr pipe and then makes the daemon log a
# line (it rejects a bad LCM command): the write blocks, and with it the loop,
# while the process is alive and well otherwise — the case the watchdog exists
# for (a stuck journald, a hung device write). A daemon that pinged from a
# timer, a thread or a signal handler instead of its loop would keep pinging.
. "$(dirname "$0")/../lib.sh"

PORT=7800
URL=$(lcm_url $PORT)
WD_USEC=1000000         # pings expected every 500 ms

for p in undulated undulate-sim; do
	if [ ! -x "$B/$p" ]; then
		tap_skip "sd_notify READY/WATCHDOG/STATUS/STOPPING" "daemon not built ($B/$p missing)"
		tap_done; exit
	fi
done
if ! command -v python3 >/dev/null; then
	tap_skip "sd_notify READY/WATCHDOG/STATUS/STOPPING" "python3 not installed"
	tap_done; exit
fi

# ---- the systemd side: receive datagrams with the sender's credentials -------------
cat >"$T/notify_recv.py" <<'PY'
import os, signal, socket, struct, sys, time
path, log = sys.argv[1], sys.argv[2]
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.setsockopt(socket.SOL_SOCKET, socket.SO_PASSCRED, 1)
s.bind(path)
signal.signal(signal.SIGTERM, lambda *a: sys.exit(0))
out = open(log, "w", buffering=1)
print("listening", file=out)
ucred = struct.calcsize("3i")
while True:
    data, anc, _, _ = s.recvmsg(4096, socket.CMSG_SPACE(ucred))
    t = time.monotonic()
    pid = 0
    for level, kind, cdata in anc:
        if level == socket.SOL_SOCKET and kind == socket.SCM_CREDENTIALS:
            pid = struct.unpack("3i", cdata[:ucred])[0]
    for line in data.decode("utf-8", "replace").split("\n"):
        if line:
            print(f"{t:.6f} {pid} {line}", file=out)
PY
spawn notify python3 "$T/notify_recv.py" "$T/notify.sock" "$T/notify.msgs"
wait_for 10 grep -q listening "$T/notify.msgs" || { tap_fail "notify receiver started"; tap_done; exit; }
msgs() { grep -v '^listening' "$T/notify.msgs"; }

# ---- simulator and daemon ------------------------------------------------------------
spawn sim "$B/undulate-sim" --link "$T/bus" --ids 1,2 --lcm-url "$URL"
if ! wait_log sim 'ready' 10; then
	tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit
fi

# The daemon's stderr goes through a FIFO to a relay (cat) the test can pause;
# its log is then $T/relay.log. The relay holds the FIFO read-write, so it
# sees no end of file when a daemon exits. env and sh exec: the PID is the daemon's.
mkfifo "$T/daemon.err"
spawn relay sh -c 'exec cat 0<>"$0"' "$T/daemon.err"
# Started the way undulated@.service starts it: --config FILE.
cat >"$T/sysd1.conf" <<EOF
[robot]
name = sysd1
port = $T/bus
ids = 1,2
mode = oscillator
lcm_url = $URL
EOF
start_daemon() {
	spawn daemon env NOTIFY_SOCKET="$T/notify.sock" WATCHDOG_USEC=$WD_USEC \
		sh -c 'exec "$@" 2>"$0"' "$T/daemon.err" \
		"$B/undulated" --config "$T/sysd1.conf"
}
daemon_log() { cat "$T/relay.log" "$T/daemon.log" 2>/dev/null | grep -v '^####'; }
ready() { grep -q ' READY=1$' "$T/notify.msgs"; }
daemon_errors() { daemon_log | grep -E 'error'; }
start_retried
daemon_pid=$pid_daemon

if wait_for 15 ready; then
	tap_ok "READY=1 received"
else
	tap_fail "READY=1 received" "messages:"$'\n'"$(msgs)"$'\n'"daemon log:"$'\n'"$(daemon_log)"
	tap_done; exit
fi

# WATCHDOG=1 after READY=1.
if wait_for 5 sh -c "sed -n '/ READY=1\$/,\$p' '$T/notify.msgs' | grep -q ' WATCHDOG=1\$'"; then
	tap_ok "WATCHDOG=1 follows READY=1"
else
	tap_fail "WATCHDOG=1 follows READY=1" "$(msgs)"
fi

# Every message from the main PID (what NotifyAccess=main accepts).
others=$(msgs | awk -v pid="$daemon_pid" '$2 != pid')
if [ -z "$others" ]; then tap_ok "every notification comes from the daemon's main PID ($daemon_pid)"
else tap_fail "notifications from the main PID" "from other PIDs:"$'\n'"$others"; fi

# Healthy: over ~2 s of pings, the largest gap stays well under WATCHDOG_USEC.
start=$(msgs | grep -c ' WATCHDOG=1$')
wait_for 5 sh -c "[ \$(grep -c ' WATCHDOG=1\$' '$T/notify.msgs') -ge $((start + 4)) ]"
gap=$(msgs | awk '$3 == "WATCHDOG=1" { if (last) { g = $1 - last; if (g > max) max = g } last = $1 }
	END { printf "%d", max * 1e6 }')
n=$(msgs | grep -c ' WATCHDOG=1$')
if [ "$n" -ge $((start + 4)) ] && [ "$gap" -lt $((WD_USEC * 3 / 4)) ]; then
	tap_ok "healthy loop pings every WATCHDOG_USEC/2 (largest gap ${gap} us < ${WD_USEC} us)"
else
	tap_fail "healthy loop pings in time" "$n pings, largest gap ${gap} us (WATCHDOG_USEC=$WD_USEC)"
fi

# STATUS=: "MODE RATE Hz, N joints, bus ok|lost, N overruns, N bus errors, N faults, N bad commands"
status_re='^STATUS=(LIMP|HOLD|SINUSOID|OSCILLATOR) [0-9]+\.[0-9] Hz, 2 joints, bus (ok|lost), [0-9]+ overruns, [0-9]+ bus errors, [0-9]+ faults, [0-9]+ bad commands$'
if wait_for 5 sh -c "msgs() { grep -v '^listening' '$T/notify.msgs'; }; msgs | cut -d' ' -f3- | grep -Eq '$status_re'"; then
	tap_ok "STATUS= shows mode, rate, joints, bus state and counters"
else
	tap_fail "STATUS= format" "$(msgs | grep STATUS= | tail -3)"
fi

# ---- the stall --------------------------------------------------------------------
# Pause the relay and fill the pipe: the daemon's next log line blocks it.
kill -STOP "$pid_relay"
python3 - "$T/daemon.err" <<'PY'
import os, sys
fd = os.open(sys.argv[1], os.O_WRONLY | os.O_NONBLOCK)
try:
    while True:
        os.write(fd, b"#" * 4096 + b"\n")
except BlockingIOError:
    pass
PY
# A bad command makes the daemon log its rejection (and so block).
"$B/undulated" --lcm-url "$URL" --robot sysd1 --command "param k -1" >"$T/cmd.log" 2>&1 &
cmd_pid=$!
# Wait 3 watchdog periods: a stalled loop must have sent nothing since.
sleep_until=$(( $(date +%s%N) + 3 * WD_USEC * 1000 ))
wait_for 5 sh -c "[ \$(date +%s%N) -ge $sleep_until ]"
# The pings stop within one period of the stall; none in the last 2 periods.
last_ping=$(msgs | awk '$3 == "WATCHDOG=1" { t = $1 } END { print t }')
now=$(python3 -c 'import time; print(f"{time.monotonic():.6f}")')
silent_us=$(awk -v a="$last_ping" -v b="$now" 'BEGIN { printf "%d", (b - a) * 1e6 }')
if alive daemon && [ "$silent_us" -ge $((2 * WD_USEC)) ]; then
	tap_ok "stalled loop (blocked on a full stderr): no WATCHDOG=1 for ${silent_us} us, systemd would restart it"
else
	tap_fail "WATCHDOG=1 stops when the loop stalls" \
		"last ping ${silent_us} us ago (WATCHDOG_USEC=$WD_USEC); daemon alive: $(alive daemon && echo yes || echo no)
(the stall relies on the daemon writing a line to stderr for the rejected command)"
fi

# Let it run again: the pings return.
kill -CONT "$pid_relay"
after=$(msgs | grep -c ' WATCHDOG=1$')
if wait_for 5 sh -c "[ \$(grep -c ' WATCHDOG=1\$' '$T/notify.msgs') -ge $((after + 2)) ]"; then
	tap_ok "WATCHDOG=1 resumes once the loop runs again"
else
	tap_fail "WATCHDOG=1 resumes" "$(msgs | tail -5)"
fi
wait "$cmd_pid" 2>/dev/null

# ---- stop ------------------------------------------------------------------------------
# (not rc=$(stop ...): a subshell cannot wait for this shell's children)
stop daemon TERM >"$T/daemon.rc"
rc=$(cat "$T/daemon.rc")
if [ "$rc" = 0 ] && msgs | grep -q ' STOPPING=1$'; then
	tap_ok "SIGTERM: STOPPING=1, exit status 0"
else
	tap_fail "SIGTERM: STOPPING=1, exit 0" "exit status $rc; last messages:"$'\n'"$(msgs | tail -3)"
fi
tap_done
