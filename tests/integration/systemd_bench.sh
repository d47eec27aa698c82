#!/usr/bin/env bash
# The bench-machine set-up of systemd/README.md, run from the installed units'
# own command lines: install into a DESTDIR, take ExecStart= from
# undulate-sim.service and undulated@.service, and run them (paths moved under
# the test directory, LCM on this test's port) with a preset scenario as
# /etc/undulate/sim.scenario and a robot config as /etc/undulate/r1.conf.
# Checks that the simulator's buses and control socket appear where the README
# says, and that undulated@r1 comes up (READY=1, "bus ok") on its bus and
# stops cleanly, as does the simulator.
. "$(dirname "$0")/../lib.sh"

PORT=7803
URL=$(lcm_url $PORT)
SCENARIO="$top/sim-bridge/scenarios/channel4.scenario"

for p in undulated undulate-sim dxl undulate-top undulate-analyze; do
	if [ ! -x "$B/$p" ]; then
		tap_skip "bench set-up from the installed units" "$p not built"
		tap_done; exit
	fi
done
command -v python3 >/dev/null || { tap_skip "bench set-up" "python3 not installed"; tap_done; exit; }
[ -f "$SCENARIO" ] || { tap_fail "preset scenario $SCENARIO exists"; tap_done; exit; }

R="$T/root"
P=/usr/local
if ! PREFIX=$P DESTDIR="$R" BUILD="$BUILD" "$top/scripts/install.sh" install >"$T/install.out" 2>&1; then
	tap_fail "install" "$(cat "$T/install.out")"; tap_done; exit
fi

# The unit's command line, with the machine's paths moved into the test dir.
exec_of() { # UNIT INSTANCE
	grep '^ExecStart=' "$R$P/lib/systemd/system/$1" | sed -e 's/^ExecStart=//' \
		-e "s#$P/bin/#$R$P/bin/#g" -e "s#/etc/undulate/#$T/etc/undulate/#g" \
		-e "s#/run/undulate#$T/run/undulate#g" -e "s#%i#${2:-}#g"
}
mkdir -p "$T/etc/undulate" "$T/run/undulate"   # RuntimeDirectory=undulate
cp "$R$P/share/undulate/scenarios/channel4.scenario" "$T/etc/undulate/sim.scenario"

read -r -a sim_cmd <<<"$(exec_of undulate-sim.service)"
spawn sim "${sim_cmd[@]}" --set "sim.lcm_url=$URL"
if wait_log sim 'ready' 15; then
	tap_ok "undulate-sim.service's command line runs the scenario from /etc/undulate/sim.scenario"
else
	tap_fail "undulate-sim.service's command line runs" "${sim_cmd[*]}"$'\n'"$(cat "$T/sim.log")"
	tap_done; exit
fi

links_ok=1
for r in r1 r2 r3 r4; do [ -L "$T/run/undulate/$r" ] || links_ok=0; done
reply=$(python3 - "$T/run/undulate/sim.control" <<'PY' 2>&1
import socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
s.settimeout(5)
s.connect(sys.argv[1])
s.sendall(b"list\n")
print(s.recv(4096).decode().strip())
PY
)
if [ $links_ok -eq 1 ] && [[ "$reply" == ok* ]]; then
	tap_ok "buses at /run/undulate/<robot>, control socket /run/undulate/sim.control answers"
else
	tap_fail "buses and control socket under /run/undulate" "$(ls -l "$T/run/undulate")"$'\n'"$reply"
fi

# A robot config as the README has the operator write it.
cat >"$T/etc/undulate/r1.conf" <<EOF
[robot]
name = r1
port = /run/undulate/r1
ids = 1,2
lcm_url = $URL
EOF
sed -i "s#/run/undulate#$T/run/undulate#" "$T/etc/undulate/r1.conf"

cat >"$T/recv.py" <<'PY'
import socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1])
out = open(sys.argv[2], "w", buffering=1)
print("listening", file=out)
while True:
    for line in s.recv(4096).decode("utf-8", "replace").split("\n"):
        print(line, file=out)
PY
spawn notify python3 "$T/recv.py" "$T/notify.sock" "$T/notify.msgs"
wait_for 10 grep -q listening "$T/notify.msgs"

read -r -a d_cmd <<<"$(exec_of undulated@.service r1)"
start_daemon() { spawn daemon env NOTIFY_SOCKET="$T/notify.sock" WATCHDOG_USEC=2000000 "${d_cmd[@]}"; }
ready() { grep -q '^READY=1$' "$T/notify.msgs"; }
start_retried
if wait_for 15 ready &&
	wait_for 5 grep -qE '^STATUS=.* 2 joints, bus ok' "$T/notify.msgs"; then
	tap_ok "undulated@r1's command line (--config /etc/undulate/r1.conf) reaches READY=1, bus ok"
else
	tap_fail "undulated@r1 comes up" "${d_cmd[*]}"$'\n'"$(cat "$T/notify.msgs" "$T/daemon.log")"
fi

stop daemon TERM >"$T/daemon.rc"
stop sim TERM >"$T/sim.rc"
if [ "$(cat "$T/daemon.rc")" = 0 ] && [ "$(cat "$T/sim.rc")" = 0 ] && [ ! -e "$T/run/undulate/sim.control" ]; then
	tap_ok "both stop cleanly on SIGTERM (exit 0, control socket removed)"
else
	tap_fail "clean stop" "daemon $(cat "$T/daemon.rc"), sim $(cat "$T/sim.rc")"$'\n'"$(tail -3 "$T/sim.log")"
fi
tap_done
