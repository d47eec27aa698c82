#!/usr/bin/env bash
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# sim_lockstep_buses.sh — a robot on two buses in virtual time
# (common/lockstep.h "Several buses"): one simulator serves both links, one
# daemon drives them (undulated --lockstep SOCK --port A --ids 1,tail:2
# --set bus.tail.port=B) over one connection to the clock:
#  - it joins once, naming both buses; the run starts with nobody else and
#    ends by itself; both joints swing under the oscillator;
#  - the same seed gives the same run: the simulator's ground truth
#    (SIM.TRUTH) and the daemon's states, message for message, byte for byte;
#  - a bus unplugged mid-run ([events] disconnect) is lost and reconnected
#    on its own, and meanwhile the other bus's joint holds, as in real time
#    (tests/integration/daemon_buses.sh);
#  - bytes for a bus the daemon did not name (a PART for bus 3 from a client
#    that named one): refused, said why, counted;
#  - the pty transport (--lockstep-pty) carries one bus a daemon: refused,
#    said why.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"; A="$B/undulate-analyze"
if [ ! -x "$S" ] || [ ! -x "$D" ] || [ ! -x "$A" ]; then
	tap_skip_all "undulate-sim, undulated or undulate-analyze not built"
fi
R="lb$$"
above() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a > b) }'; }
printf '[sim]\nseed = 1\n[robot ra]\nids = 1\n[robot rb]\nids = 2\n' >"$T/two.scenario"

# range (max - min) of field $1 in the watcher's states of run $2 with
# cycle in [$3, $4)
range_in() {
	grep -a "^STATE $R " "$T/$2-watch.log" | awk -v f="$1" -v c0="$3" -v c1="$4" '
		{ for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
		  if (v["cycle"] < c0 || v["cycle"] >= c1) next; x = v[f] + 0
		  if (n == 0 || x < lo) lo = x; if (n == 0 || x > hi) hi = x; n++ }
		END { printf "%.3f\n", n ? hi - lo : 0 }'
}

# run NAME PORT SECONDS [SIM ARGS...]: the two-bus robot in lockstep (the
# daemon's extra arguments in the array dargs); the LCM
# log in $T/NAME.lcmlog, the watcher's lines in $T/NAME-watch.log, the logs
# in $T/NAME-{sim,d}.log. Returns the daemon's exit status.
run() {
	local name=$1 port=$2 seconds=$3; shift 3
	local url; url=$(lcm_url "$port")
	spawn "$name-rec" "$A" --record "$T/$name.lcmlog" --lcm-url "$url"
	wait_log "$name-rec" '^undulate-analyze: recording' 10 || return 90
	spawn "$name-watch" "$D" --watch "$R" --raw --lcm-url "$url"
	spawn "$name-sim" "$S" --scenario "$T/two.scenario" --link-dir "$T/$name-links" --lcm-url "$url" \
		--lockstep "$T/$name-clock" --duration "$seconds" --lockstep-grace 20 "$@"
	wait_log "$name-sim" 'ready:' 10 || return 91
	local rc=0
	"$D" --port "$T/$name-links/ra" --ids 1,tail:2 --set "bus.tail.port=$T/$name-links/rb" --robot "$R" \
		--lcm-url "$url" --lockstep "$T/$name-clock" --mode oscillator ${dargs[@]+"${dargs[@]}"} >"$T/$name-d.log" 2>&1 ||
		rc=$?
	local var="pid_${name//-/_}_sim"
	wait "${!var}" 2>/dev/null
	stop "$name-rec" INT >/dev/null
	stop "$name-watch" TERM >/dev/null
	return "$rc"
}

# ---- one daemon, two buses, one run, twice ----------------------------------------------
for name in one two; do
	rc=0; run $name 7690 6 --seed 7 || rc=$?
	if [ "$rc" != 0 ]; then
		tap_fail "$name: the two-bus lockstep run ended by itself" "exit $rc: $(tail -n 5 "$T/$name-d.log") $(tail -n 5 "$T/$name-sim.log")"
		tap_done; exit
	fi
done
if grep -q "joined on bus ra" "$T/one-sim.log" && grep -q "joined on bus rb" "$T/one-sim.log" &&
	grep -q "1 daemon(s) joined.*ended: the run's 6.000 s are over" "$T/one-sim.log" &&
	grep -q 'lockstep: the simulator ended the run' "$T/one-d.log" &&
	[ "$(grep -c 'safe stop: holding present positions' "$T/one-d.log")" = 2 ]; then
	tap_ok "one daemon joined on both buses, the run ended by itself at 6 s, a safe stop on each bus"
else
	tap_fail "one daemon on both buses, the run ended by itself" "$(grep 'lockstep' "$T/one-sim.log" | tail -n 4); $(tail -n 3 "$T/one-d.log")"
fi
r0=$(range_in a0 one 300 600); r1=$(range_in a1 one 300 600)
if above "$r0" 0.4 && above "$r1" 0.4; then
	tap_ok "both joints swing under the oscillator (ranges $r0 and $r1 rad from 3 s to 6 s)"
else
	tap_fail "both joints swing" "ranges $r0 $r1; $(grep -a "^STATE $R " "$T/one-watch.log" | tail -n 1 | cut -c1-300)"
fi
channels "$T/one.lcmlog" | grep -E "^(SIM\.TRUTH|$R\.STATE) " >"$T/one.ch"
channels "$T/two.lcmlog" | grep -E "^(SIM\.TRUTH|$R\.STATE) " >"$T/two.ch"
if [ "$(wc -l <"$T/one.ch")" = 2 ] && cmp -s "$T/one.ch" "$T/two.ch"; then
	tap_ok "the same seed, the same run: SIM.TRUTH and $R.STATE the same, message for message ($(awk '{ printf "%s %s; ", $1, $2 }' "$T/one.ch"))"
else
	tap_fail "the same seed, the same run" "$(diff "$T/one.ch" "$T/two.ch")"
fi

# ---- bus tail unplugged from 2 s to 4 s ---------------------------------------------------
# (silent_s as in daemon_buses.sh: a bus gone 2 s latches no silent fault)
dargs=(--set robot.silent_s=6)
rc=0; run dc 7691 8 --seed 7 --set 'events.2=disconnect rb' --set 'events.4=reconnect rb' || rc=$?
# (the daemon's log, not the watcher's: a watcher may miss messages of a run
# faster than real time on a busy machine)
ev() { grep -a "$1" "$T/dc-d.log" | head -n 1; }
if [ "$rc" = 0 ] && [ -n "$(ev "bus-lost: bus tail")" ] && [ -n "$(ev "bus-back: bus tail")" ] &&
	grep -q "ended: the run's 8.000 s are over" "$T/dc-sim.log"; then
	tap_ok "bus tail unplugged at 2 s: lost, back on its own after the reconnect at 4 s, the run went on to its end"
else
	tap_fail "bus tail lost and back in lockstep" "exit $rc; $(grep -a "bus-" "$T/dc-d.log" | tail -n 4); $(tail -n 3 "$T/dc-d.log")"
fi
# (from 2.9 s: as daemon_buses.sh, a while after the loss; at 2.75 s joint
# 1's goal steps 0.1 rad for one cycle, a thing of the controller's to look at)
g0=$(range_in g0 dc 290 390); a1=$(range_in a1 dc 600 800); a0=$(range_in a0 dc 600 800)
if ! above "$g0" 0.005 && above "$a0" 0.4 && above "$a1" 0.4; then
	tap_ok "while it was gone joint 1 held (goal range $g0 rad), after it both swing again ($a0, $a1 rad)"
else
	tap_fail "hold while one bus is lost, swing after" "goal range $g0 during, $a0 $a1 after"
fi

# ---- bad input: bytes for a bus the daemon did not name ---------------------------------------
# A client that names bus ra alone (one HELLO) and then sends a PART for bus 3:
# refused, said why, counted (the simulator's "bad message(s)"), the run ends.
spawn bad-sim "$S" --scenario "$T/two.scenario" --link-dir "$T/bad-links" --lcm-url "$(lcm_url 7693)" \
	--lockstep "$T/bad-clock" --duration 5 --lockstep-grace 5
if wait_log bad-sim 'ready:' 10; then
	got=$(python3 - "$T/bad-clock" "$(realpath "$T/bad-links/ra")" <<'PY'
import socket, struct, sys
MAGIC, HELLO, WELCOME, PART = 0x4c4b5333, 1, 2, 9
def msg(t, a=0, b=0, c=0, flags=0, text=b'', payload=b''):
    # struct lks_msg's header (common/lockstep.h), then the payload
    return struct.pack('=IIQQQI32s256sI', MAGIC, t, a, b, c, flags, b'bad', text, len(payload)) + payload
s = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
s.connect(sys.argv[1])
s.send(msg(HELLO, a=1, b=1, c=0, text=sys.argv[2].encode()))
r = s.recv(8192)
if struct.unpack_from('=II', r)[1] != WELCOME:
    sys.exit('not welcomed')
s.send(msg(PART, c=3, payload=b'\xff\xff\x01\x02\x01\xfb'))
r = s.recv(8192)
t = struct.unpack_from('=II', r)[1]
print(t, r[68:324].split(b'\0')[0].decode())
PY
	)
	wait_for 10 sh -c "! kill -0 $pid_bad_sim 2>/dev/null"
	if [[ "$got" == "7 a PART for bus 3; it named 1 bus(es)" ]] && grep -q ' 1 bad message(s)' "$T/bad-sim.log"; then
		tap_ok "a PART for a bus the daemon did not name: refused ($got), counted, the run ended"
	else
		tap_fail "a PART for a bus not named: refused and counted" "got '$got'; $(grep lockstep "$T/bad-sim.log" | tail -n 3)"
	fi
else
	tap_fail "bad-input simulator ready" "$(cat "$T/bad-sim.log")"
fi
stop bad-sim TERM >/dev/null

# ---- the pty transport: one bus a daemon ----------------------------------------------------
spawn pty-sim "$S" --scenario "$T/two.scenario" --link-dir "$T/pty-links" --lcm-url "$(lcm_url 7692)" \
	--lockstep "$T/pty-clock" --lockstep-pty --duration 5 --lockstep-grace 3
if wait_log pty-sim 'ready:' 10; then
	rc=0; out=$(timeout 30 "$D" --port "$T/pty-links/ra" --ids 1,tail:2 --set "bus.tail.port=$T/pty-links/rb" \
		--robot "$R" --lcm-url "$(lcm_url 7692)" --lockstep "$T/pty-clock" 2>&1) || rc=$?
	if [ "$rc" != 0 ] && [ "$rc" != 124 ] && echo "$out" | grep -q "carries one bus a daemon"; then
		tap_ok "the pty transport refuses a daemon on two buses, said why (exit $rc)"
	else
		tap_fail "the pty transport refuses a daemon on two buses" "rc $rc: $(echo "$out" | tail -n 3)"
	fi
else
	tap_fail "pty simulator ready" "$(cat "$T/pty-sim.log")"
fi
stop pty-sim TERM >/dev/null
tap_done
