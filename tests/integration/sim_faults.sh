#!/usr/bin/env bash
# sim_faults.sh — every fault undulate-sim injects, switched on through the
# control socket and LCM SIM.CMD and observed from the controller's side of
# the pty: no reply, bad checksum, truncated reply, garbage, wrong ID, stuck
# error bit, slow reply, power loss and return, disconnect and reconnect at
# the same path; bad commands get a clear error and never stop the sim.
. "$(dirname "$0")/../lib.sh"
# one interpreter for the whole test (tests/lib.sh, py_start)
py_start sim "$top/tests/integration/sim_client.py" SIM_CLIENT_BAUD
C="py_call sim"
URL=$(lcm_url 7651)
link="$T/bus/r1"

spawn sim "$B/undulate-sim" --link "$link" --ids 1,2 --return-delay 0 --lcm-url "$URL" --control "$T/ctl"
wait_log sim 'ready:' 5 || { tap_fail "sim ready" "$(cat "$T/sim.log")"; tap_done; exit; }

xfer() { read -r reply rtt < <($C xfer "$link" "$@"); }
ctl() { $C ctl "$T/ctl" "$1"; }
ctl_ok() {  # NAME COMMAND
	local r; r=$(ctl "$2")
	case "$r" in ok*) tap_ok "$1";; *) tap_fail "$1" "'$2' -> $r";; esac
}
PING1=FFFF010201FB
PING2=FFFF020201FA
OK1=FFFF010200FC

ctl_ok "fault no-reply accepted" "fault r1 1 no-reply"
xfer $PING1 40; tap_check "no-reply: servo 1 silent" test "$reply" = -
xfer $PING2 300 6; tap_check "no-reply: servo 2 still answers" test "$reply" = FFFF020200FB
ctl_ok "clear" "clear r1"
xfer $PING1 300 6; tap_check "cleared: servo 1 answers" test "$reply" = $OK1

ctl "fault r1 1 bad-checksum" >/dev/null
xfer $PING1 300 6
if [ "${#reply}" = 12 ] && [ "${reply:0:10}" = FFFF010200 ] && [ "$reply" != $OK1 ]; then tap_ok "bad-checksum: checksum byte wrong ($reply)"
else tap_fail "bad-checksum" "got $reply"; fi
ctl "clear r1 1 bad-checksum" >/dev/null

ctl "fault r1 1 truncate 2" >/dev/null
xfer $PING1 40; tap_check "truncate: 4 of 6 bytes" test "$reply" = FFFF0102
ctl "clear r1" >/dev/null

ctl "fault r1 1 garbage 4" >/dev/null
xfer $PING1 300 10
if [ "${#reply}" = 20 ] && [ "${reply:8}" = $OK1 ]; then tap_ok "garbage: 4 bytes before the reply"; else tap_fail "garbage" "got $reply"; fi
ctl "clear r1" >/dev/null

ctl "fault r1 1 wrong-id 7" >/dev/null
xfer $PING1 300 6; tap_check "wrong-id: reply from ID 7 with a valid checksum" test "$reply" = "$(status 7 0)"
ctl "clear r1" >/dev/null

ctl "fault r1 1 stuck-error overload|overheating" >/dev/null
# the manual's example status packet: overload + overheating
xfer $PING1 300 6; tap_check "stuck-error: overload|overheating in every reply" test "$reply" = FFFF010224D8
xfer "$(pkt 1 2 43 1)" 300 7
tap_check "stuck-error: in READ replies too" test "${reply:8:2}" = 24
ctl "clear r1" >/dev/null
# count=N and prob=P, as for every other fault
ctl_ok "stuck-error count=2 accepted" "fault r1 1 stuck-error overload count=2"
got=""; for _ in 1 2 3; do xfer $PING1 300 6; got+="$reply "; done
tap_check "stuck-error count=2: the bit in the next 2 replies only ($got)" \
	test "$got" = "FFFF010220DC FFFF010220DC $OK1 "
r=$(ctl "servo r1 1")
tap_check "stuck-error count=2: used up, no fault left" test "${r##*faults=}" = none
ctl_ok "stuck-error prob=0.5 accepted" "fault r1 1 stuck-error overload prob=0.5"
with=0 without=0 other=""
for _ in $(seq 12); do
	xfer "$(pkt 1 2 43 1)" 300 7
	case "${reply:8:2}" in 20) with=$((with + 1));; 00) without=$((without + 1));; *) other+="$reply ";; esac
done
if [ "$with" -gt 0 ] && [ "$without" -gt 0 ] && [ -z "$other" ]; then
	tap_ok "stuck-error prob=0.5: the bit in some READ replies ($with of 12), not all"
else tap_fail "stuck-error prob=0.5" "with $with, without $without, other: $other"; fi
ctl "clear r1" >/dev/null

ctl "fault r1 1 slow 30" >/dev/null
xfer $PING1 200 6
if [ "$reply" = $OK1 ] && [ "$rtt" -ge 30000 ]; then tap_ok "slow: reply 30 ms late ($rtt us)"; else tap_fail "slow" "$reply after $rtt us"; fi
ctl "clear r1" >/dev/null
xfer $PING1 300 6
if [ "$rtt" -lt 20000 ]; then tap_ok "cleared: prompt again ($rtt us)"; else tap_fail "cleared: prompt again" "$rtt us"; fi

ctl "fault r1 1 no-reply count=1" >/dev/null
xfer $PING1 40; r1=$reply
xfer $PING1 300 6
if [ "$r1" = - ] && [ "$reply" = $OK1 ]; then tap_ok "count=1: only the next reply lost"; else tap_fail "count=1" "$r1 then $reply"; fi

ctl "fault r1 1 temperature 80" >/dev/null
sleep 0.01
xfer "$(pkt 1 2 43 1)" 300 7
tap_check "temperature 80: READ says 80 C with the overheating bit" test "$reply" = "$(status 1 4 80)"
ctl "clear r1" >/dev/null

# ---- power loss and return: RAM back to its defaults ---------------------------------
xfer "$(pkt 1 3 25 1)" 300 6    # LED on
xfer "$(pkt 1 3 24 1)" 300 6    # torque on
ctl_ok "power off" "power r1 1 off"
xfer $PING1 40; tap_check "powered off: silent" test "$reply" = -
ctl_ok "power on" "power r1 1 on"
xfer "$(pkt 1 2 24 2)" 300 8
tap_check "power on: torque and LED back to 0" test "$reply" = "$(status 1 0 0 0)"

# ---- SIM.CMD over LCM ---------------------------------------------------------------
# The client prints the simulator's answer (SIM.REPLY) and exits by it.
simcmd() { rc=0; "$B/undulate-sim" --cmd "$1" --lcm-url "$URL" >"$T/cmd.out" 2>"$T/cmd.err" || rc=$?; }
simcmd "fault r1 2 no-reply"
[ "$rc" = 0 ] && [ "$(cat "$T/cmd.out")" = "ok 1 servo(s): no-reply" ] \
	&& tap_ok "--cmd prints the simulator's answer, exit 0" \
	|| tap_fail "--cmd prints the simulator's answer, exit 0" "rc=$rc $(cat "$T/cmd.out" "$T/cmd.err")"
silent2() { xfer $PING2 30; [ "$reply" = - ]; }
if wait_for 3 silent2; then tap_ok "SIM.CMD fault applied"; else tap_fail "SIM.CMD fault applied" "$(tail -3 "$T/sim.log")"; fi
simcmd "clear r1 2"
answers2() { xfer $PING2 300 6; [ "$reply" = FFFF020200FB ]; }
if wait_for 3 answers2; then tap_ok "SIM.CMD clear applied"; else tap_fail "SIM.CMD clear applied"; fi

# ---- disconnect / reconnect at the same path ------------------------------------------
spawn eio python3 -S "$top/tests/integration/sim_client.py" eio "$link"
wait_log eio '^open' 5
old=$(readlink "$link")
ctl_ok "disconnect" "disconnect r1"
tap_check "disconnect: link removed" test ! -L "$link"
if wait_log eio '^eio' 5; then tap_ok "disconnect: an open client sees the port go away"; else tap_fail "disconnect: client sees EIO" "$(cat "$T/eio.log")"; fi
xfer_fails() { ! $C xfer "$link" "$PING1" 20 >/dev/null 2>&1; }
tap_check "disconnect: opening the path fails" xfer_fails
ctl_ok "reconnect" "reconnect r1"
tap_check "reconnect: link back at the same path" test -L "$link" -a -c "$(readlink "$link")"
xfer $PING1 300 6; tap_check "reconnect: servo answers at the same path (was $old, now $(readlink "$link"))" test "$reply" = $OK1

# ---- bad commands: a clear error each, counted, sim unharmed ----------------------------
bad() {  # NAME COMMAND REGEX
	local r; r=$(ctl "$2")
	if [[ "$r" =~ ^error:\ .*$3 ]]; then tap_ok "$1"; else tap_fail "$1" "'$2' -> $r"; fi
}
bad "unknown verb" "explode everything" "unknown command"
bad "unknown bus" "fault nobus 1 no-reply" "no servo matches"
bad "unknown servo" "fault r1 99 no-reply" "no servo matches"
bad "bad fault argument" "fault r1 1 slow abc" "bad argument"
bad "unknown fault" "fault r1 1 explode" "unknown fault"
bad "bad power state" "power r1 1 sideways" "usage"
bad "reconnect while connected" "reconnect r1" "connected"
long=$(printf 'x%.0s' $(seq 600))
r=$(ctl "fault r1 1 $long")
if [ "$(echo "$r" | head -1)" = "error: line too long" ] && [ "$(echo "$r" | wc -l)" = 1 ]; then tap_ok "an over-long line: one error"
else tap_fail "an over-long line: one error" "$r"; fi
simcmd "explode now"
[ "$rc" = 1 ] && grep -q "^error: unknown command 'explode'" "$T/cmd.out" \
	&& tap_ok "--cmd refused by the simulator: its error, exit 1" \
	|| tap_fail "--cmd refused by the simulator: its error, exit 1" "rc=$rc $(cat "$T/cmd.out" "$T/cmd.err")"
simcmd help
[ "$rc" = 0 ] && grep -q "^ok commands: fault BUS ID KIND" "$T/cmd.out" \
	&& tap_ok "--cmd help lists the commands" || tap_fail "--cmd help lists the commands" "rc=$rc $(cat "$T/cmd.out")"
simcmd "stats $(printf 'x%.0s' $(seq 300))"
[ "$rc" = 2 ] && grep -q "longer than 255 bytes" "$T/cmd.err" \
	&& tap_ok "--cmd longer than a command may be: refused before sending, exit 2" \
	|| tap_fail "--cmd too long: exit 2" "rc=$rc $(cat "$T/cmd.out" "$T/cmd.err")"
rc=0; "$B/undulate-sim" --cmd stats --lcm-url "$(lcm_url 7699)" >"$T/none.out" 2>"$T/none.err" || rc=$?
[ "$rc" = 3 ] && grep -q "no simulator answered on udpm://.*:$(lcm_port 7699)" "$T/none.err" \
	&& tap_ok "--cmd with nobody listening: says so, exit 3" \
	|| tap_fail "--cmd with nobody listening: says so, exit 3" "rc=$rc $(cat "$T/none.out" "$T/none.err")"
counted() { ctl stats | grep -q 'bad_commands=9'; }
if wait_for 3 counted; then tap_ok "bad commands counted (control socket and SIM.CMD)"; else tap_fail "bad commands counted" "$(ctl stats)"; fi
tap_check "sim still running" alive sim
r=$(ctl "servo r1 1")
if [[ "$r" =~ ^ok\ id=1\ power=on.*checksum=0.*faults=none$ ]]; then tap_ok "servo status line"; else tap_fail "servo status line" "$r"; fi
xfer $PING1 300 6; tap_check "still answering" test "$reply" = $OK1
tap_done
