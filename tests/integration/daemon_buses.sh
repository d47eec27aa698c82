#!/usr/bin/env bash
# undulated with a robot on two buses ([bus.NAME], [robot] ids = 1,tail:2):
# joint 1 on one simulated bus, joint 2 on another (two undulate-sim links),
# both read and driven in the same cycle by the one oscillator; the state and
# the BUS messages carry both joints, each bus its own bus time on
# "<robot>.BUS.<bus>"; one bus dropped (the simulator's disconnect) is lost and
# reconnected on its own while the daemon stays up, and meanwhile the other
# bus's joint holds (the chain of oscillators is broken: docs/SAFETY.md); then
# both move again, and SIGTERM stops both buses safely. Refused at once: an ID
# on two buses (by this daemon). (Several buses in lockstep:
# sim_lockstep_buses.sh.)
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
R="mb$$"
URL=$(lcm_url 7611)
ctl_at() { local sock=$1; shift; echo "$*" | socat -t 2 - UNIX-CONNECT:"$T/$sock"; }
# range (max - min) of field $1 over the states from cycle $2 on
range_since() {
	states | awk -v f="$1" -v c="$2" '{ for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
		if (v["cycle"] < c) next; x = v[f] + 0; if (n == 0 || x < lo) lo = x; if (n == 0 || x > hi) hi = x; n++ }
		END { printf "%.3f\n", n ? hi - lo : 0 }'
}
above() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a > b) }'; }

# refused before any port is opened, saying why: IDs repeated across buses
# (the configuration allows them; this daemon keys writes by ID)
rc=0; out=$("$D" --port "$T/nowhere" --ids 1,tail:1 --set "bus.tail.port=$T/nowhere2" --robot "$R" --lcm-url "$URL" 2>&1) || rc=$?
if [ "$rc" = 2 ] && echo "$out" | grep -q "servo ID 1 is joint 1 (bus robot) and joint 2 (bus tail): the configuration allows it, but undulated needs each servo of a robot to have an ID of its own"; then
	tap_ok "an ID on two buses: refused by the daemon, exit 2, the joints named"
else tap_fail "ID on two buses" "rc $rc: $out"; fi

spawn simA "$S" --link "$T/busA" --ids 1 --name ra --lcm-url "$URL" --control "$T/ctlA" --seed 3
spawn simB "$S" --link "$T/busB" --ids 2 --name rb --lcm-url "$URL" --control "$T/ctlB" --seed 4
if ! wait_log simA 'ready' 10 || ! wait_log simB 'ready' 10; then
	tap_fail "simulators ready" "$(cat "$T/simA.log" "$T/simB.log")"; tap_done; exit 1
fi
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
spawn d "$D" --port "$T/busA" --ids 1,tail:2 --set "bus.tail.port=$T/busB" --robot "$R" --lcm-url "$URL" \
	--mode oscillator --set robot.silent_s=6
wait_log d "ready: $R.STATE" 10 || { tap_fail "daemon starts" "$(cat "$T/d.log")"; tap_done; exit 1; }
if grep -q "2 joint(s) on bus robot $T/busA at 1000000 bps (joint 1), bus tail $T/busB at 1000000 bps (joint 2)" \
	"$T/d.log"; then tap_ok "start-up names each bus with its port and joints"
else tap_fail "start-up line" "$(grep 'joint(s) on' "$T/d.log")"; fi

# ---- both joints move, each read on its own bus in the same cycle
wait_for 10 cycle_at_least 300
c0=$(($(last_state | field cycle) - 150))
r0=$(range_since a0 "$c0"); r1=$(range_since a1 "$c0")
s=$(last_state)
if above "$r0" 0.4 && above "$r1" 0.4 && [ "$(echo "$s" | field st0)" = 0 ] && [ "$(echo "$s" | field st1)" = 0 ]; then
	tap_ok "both joints swing under the oscillator (ranges $r0 and $r1 rad over 1.5 s), read every cycle"
else tap_fail "both joints swing" "ranges $r0 $r1; $(echo "$s" | cut -c1-300)"; fi

# ---- each bus's own figures: "<robot>.BUS.<bus>", beside the robot's message
bus_line() { grep -a "^BUS $R/$1 " "$T/watch.log" | tail -1; }
have_bus_lines() { [ -n "$(bus_line robot)" ] && [ -n "$(bus_line tail)" ]; }
wait_for 5 have_bus_lines
la=$(bus_line robot); lb=$(bus_line tail); lr=$(grep -a "^BUS $R " "$T/watch.log" | tail -1)
if echo "$la" | grep -q " port=$T/busA connected=1 " && echo "$lb" | grep -q " port=$T/busB connected=1 " &&
	above "$(echo "$la" | field bus99)" 0 && above "$(echo "$lb" | field bus99)" 0 &&
	echo "$la" | grep -q ' id0=1/' && ! echo "$la" | grep -q ' id1=' && echo "$lb" | grep -q ' id0=2/' &&
	echo "$lr" | grep -q ' id0=1/.* id1=2/'; then
	tap_ok "bus time per bus: robot $(echo "$la" | field bus99) us, tail $(echo "$lb" | field bus99) us (p99); the robot's BUS has both servos"
else tap_fail "per-bus BUS messages" "A: $la | B: $lb | robot: $(echo "$lr" | cut -c1-200)"; fi
st_bus=$(last_state | field bus)
if above "$st_bus" 0; then tap_ok "the state's bus time is the cycle's ($st_bus us, the slower bus)"
else tap_fail "state bus time" "$(last_state | cut -c1-200)"; fi

# ---- one bus dropped: its joint is lost, the other joint holds, the daemon stays up
ctl_at ctlB disconnect rb >/dev/null
if event "kind=bus-lost .*bus tail, $T/busB: .*its joints hold and so do the other buses'" 3; then
	tap_ok "the lost bus is named in the bus-lost event"
else tap_fail "bus-lost event" "$(events | tail -3)"; fi
c1=$(last_state | field cycle)
wait_for 5 cycle_at_least $((c1 + 60))
c2=$(($(last_state | field cycle) - 40))
g0=$(range_since g0 "$c2"); a0=$(range_since a0 "$c2")
s=$(last_state)
if alive d && [ "$(echo "$s" | field st0)" = 0 ] && [ "$(echo "$s" | field st1)" -ge 30 ] &&
	! above "$g0" 0.005 && ! above "$a0" 0.05; then
	tap_ok "bus tail gone: joint 2 stale ($(echo "$s" | field st1) cycles), joint 1 read and holding (goal range $g0 rad)"
else tap_fail "hold while one bus is lost" "goal range $g0, angle range $a0; $(echo "$s" | cut -c1-300)"; fi

ctl_at ctlB reconnect rb >/dev/null
if event "kind=bus-back .*bus tail, $T/busB: bus back \\(reconnect 1\\)" 5; then tap_ok "bus tail reconnected on its own"
else tap_fail "bus-back event" "$(events | tail -3) $(tail -3 "$T/d.log")"; fi
c3=$(last_state | field cycle)
wait_for 6 cycle_at_least $((c3 + 300))
r0=$(range_since a0 $((c3 + 150))); r1=$(range_since a1 $((c3 + 150)))
s=$(last_state)
if above "$r0" 0.4 && above "$r1" 0.4 && [ "$(echo "$s" | field st1)" = 0 ] && echo "$s" | grep -q ' fault="" '; then
	tap_ok "both joints swing again after the reconnect (ranges $r0 and $r1 rad), no fault latched"
else tap_fail "swinging again" "ranges $r0 $r1; $(echo "$s" | cut -c1-300); $(tail -5 "$T/d.log")"; fi
reconnected() { bus_line tail | grep -q ' reconnects=1 '; }
if wait_for 3 reconnected && bus_line robot | grep -q ' reconnects=0 '; then
	tap_ok "reconnects counted per bus (tail 1, robot 0)"
else tap_fail "per-bus reconnects" "$(bus_line robot | cut -c1-120) | $(bus_line tail | cut -c1-120)"; fi

# ---- SIGTERM: the safe stop on each bus
stop d TERM; rc=$?
n=$(grep -c 'safe stop: holding present positions' "$T/d.log")
if [ "$rc" = 0 ] && [ "$n" = 2 ]; then tap_ok "SIGTERM: exit 0, safe stop on both buses"
else tap_fail "safe stop on both buses" "rc $rc, $n safe stops; $(tail -4 "$T/d.log")"; fi
tap_done
