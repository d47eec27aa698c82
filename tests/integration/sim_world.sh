#!/usr/bin/env bash
# sim_world.sh — the pair scenario through the wire: two single-joint robots
# driven into each other by a raw client collide in the contact world; the
# collisions show on SIM.COLLISION and SIM.TRUTH and in the exit summary, the
# blocked servo reports load, and the scenario's timed events and --set
# overrides take effect.
. "$(dirname "$0")/../lib.sh"
# one interpreter for the whole test (tests/lib.sh, py_start)
py_start sim "$top/tests/integration/sim_client.py" SIM_CLIENT_BAUD
C="py_call sim"
URL=$(lcm_url 7652)
top=$(cd "$(dirname "$0")/../.." && pwd)

# The pair rig plus one timed fault, from a scenario file of our own.
cat "$top/sim-bridge/scenarios/pair.scenario" >"$T/pair.scenario"
cat >>"$T/pair.scenario" <<'INI'

[events]
0.3 = fault right 1 stuck-error overheating
INI

spawn logger lcm-logger --lcm-url="$URL" -f "$T/w.lcmlog"
spawn sim "$B/undulate-sim" --scenario "$T/pair.scenario" --link-dir "$T/links" --set world.separation=0.2 \
	--set sim.return_delay_us=0 --set sim.overload_time=1000 --lcm-url "$URL" --control "$T/ctl"
if wait_log sim 'ready: 2 buses: left=.*/links/left\[1\] right=.*/links/right\[1\] bodies=2' 5; then
	tap_ok "pair scenario: two buses, two bodies"
else tap_fail "pair scenario ready" "$(cat "$T/sim.log")"; tap_done; exit; fi

# a reply is waited for up to 300 ms (done as soon as the expected bytes are in)
xfer() { read -r reply rtt < <($C xfer "$T/links/$1" "$2" $([ -n "${3:-}" ] && echo 300 || echo 40) "${3:-}"); }

# Left swings to +0.6 rad (towards the right), right to −0.6 rad (towards the
# left): at d̃ = 0.2 the bodies meet on the way.
xfer left "$(pkt 1 3 24 1)" 6
xfer right "$(pkt 1 3 24 1)" 6
xfer left "$(pkt 1 3 30 0x02 0x03)" 6    # 770 ≈ +0.66 rad
xfer right "$(pkt 1 3 30 0xFE 0x00)" 6   # 254 ≈ −0.66 rad
# Both keep pushing: each servo is held short of its goal and reports load.
load_seen() {
	xfer left "$(pkt 1 2 40 2)" 8
	local raw=$(( 16#${reply:12:2}${reply:10:2} ))
	[ $(( raw & 1023 )) -ge 100 ]
}
if wait_for 2 load_seen; then tap_ok "blocked joint reports present load ($reply)"; else tap_fail "blocked joint reports load" "last $reply"; fi
xfer left "$(pkt 1 2 36 2)" 8
pos=$(( 16#${reply:12:2}${reply:10:2} ))
if [ "$pos" -lt 740 ]; then tap_ok "blocked joint held short of its goal (at $pos, goal 770)"; else tap_fail "blocked joint held short" "at $pos"; fi

collided() { grep -q . "$T/w.lcmlog" 2>/dev/null && $C lcmlog "$T/w.lcmlog" | grep -q '^SIM.COLLISION '; }
if wait_for 5 collided; then tap_ok "SIM.COLLISION published when the bodies meet"; else tap_fail "SIM.COLLISION published" "$($C lcmlog "$T/w.lcmlog")"; fi

# The scenario's timed event (t = 0.3 s of simulated time) is in force once
# the simulator says it ran it: the first collision can come before it.
if wait_log sim "event 'fault right 1 stuck-error overheating': ok" 5; then
	xfer right FFFF010201FB 6
	tap_check "scenario event applied: right servo reports overheating" test "$reply" = FFFF010204F8
else tap_fail "scenario event applied" "the simulator never reported running it: $(grep event "$T/sim.log" | head -3)"; fi

# Truth carries the running collision count.
sleep 0.1
read -r _ total < <($C lcmlog "$T/w.lcmlog" | grep '^total_collisions')
if [ "${total:--1}" -ge 1 ]; then tap_ok "SIM.TRUTH total_collisions = $total"; else tap_fail "SIM.TRUTH total_collisions" "$total"; fi

# Truth carries every body: robot, servo, and the neutral positions of the
# layout (d = d̃·2·lever·A = 0.2·2·0.1865·0.8 = 0.05968 m, centred on 0).
$C lcmlog "$T/w.lcmlog" --bodies | grep '^body' >"$T/bodies"
if awk 'NR == 1 && $2 == "left" && $3 == 1 && ($7 + 0.02984) ^ 2 < 1e-10 { l = 1 }
        NR == 2 && $2 == "right" && $3 == 1 && ($7 - 0.02984) ^ 2 < 1e-10 { r = 1 }
        END { exit !(l && r && NR == 2) }' "$T/bodies"; then tap_ok "SIM.TRUTH bodies: robots, IDs, neutral positions"
else tap_fail "SIM.TRUTH bodies" "$(cat "$T/bodies")"; fi
# The left body's lateral position is neutral + lever · angle.
if awk 'NR == 1 { d = $6 - ($7 + 0.1865 * $4); exit !(d * d < 1e-12) }' "$T/bodies"; then tap_ok "SIM.TRUTH lateral = neutral + lever * angle"
else tap_fail "SIM.TRUTH lateral" "$(cat "$T/bodies")"; fi

stop sim TERM >"$T/rc"
if grep -qE 'undulate-sim: exit: .* [1-9][0-9]* collisions, total impulse [0-9.]+ N\*s' "$T/sim.log"; then
	tap_ok "exit summary counts collisions and impulse"
else tap_fail "exit summary counts collisions" "$(grep exit: "$T/sim.log")"; fi
tap_check "links removed" test ! -e "$T/links/left" -a ! -e "$T/links/right"

# ---- a long stall: overload bit, alarm shutdown, recovery -------------------------------
# Same rig, overload after 0.3 s at the torque limit (default shutdown mask 36).
spawn sim2 "$B/undulate-sim" --scenario "$T/pair.scenario" --link-dir "$T/links2" --set world.separation=0.2 \
	--set sim.return_delay_us=0 --set sim.overload_time=0.3 --lcm-url "$URL"
wait_log sim2 'ready:' 5
xfer() { read -r reply rtt < <($C xfer "$T/links2/$1" "$2" $([ -n "${3:-}" ] && echo 300 || echo 40) "${3:-}"); }
xfer left "$(pkt 1 3 24 1)" 6
xfer right "$(pkt 1 3 24 1)" 6
xfer left "$(pkt 1 3 30 0x02 0x03)" 6
xfer right "$(pkt 1 3 30 0xFE 0x00)" 6
shut=""
overloaded() {
	for r in left right; do
		xfer $r "$(pkt 1 2 24 1)" 7
		if [ $(( 16#${reply:8:2} & 0x20 )) -ne 0 ]; then shut=$r; return 0; fi
	done
	return 1
}
if wait_for 5 overloaded; then tap_ok "overload bit after a stall at the torque limit ($shut)"; else tap_fail "overload bit after a stall"; fi
shut=${shut:-left}
tap_check "alarm shutdown: torque off" test "${reply:10:2}" = 00
xfer $shut "$(pkt 1 2 34 2)" 8
tap_check "alarm shutdown: torque limit 0" test "${reply:10:4}" = 0000
# Recover with a goal away from the contact so it does not stall again.
if [ "$shut" = left ]; then away="0x2C 0x01"; else away="0xD4 0x02"; fi
xfer $shut "$(pkt 1 3 30 $away)" 6
xfer $shut "$(pkt 1 3 34 0xFF 0x03)" 6
xfer $shut "$(pkt 1 3 24 1)" 6
# (the right servo also carries the scenario's stuck overheating bit: report only)
tap_check "recovery: torque enable accepted, overload bit cleared ($reply)" test $(( 16#${reply:8:2} & 0x20 )) = 0
xfer $shut "$(pkt 1 2 24 1)" 7
tap_check "recovery: torque stays on" test "${reply:10:2}" = 01
stop sim2 TERM >"$T/rc"

# Every preset scenario loads and reaches ready.
for s in "$top"/sim-bridge/scenarios/*.scenario; do
	n=$(basename "$s" .scenario)
	"$B/undulate-sim" --scenario "$s" --link-dir "$T/p-$n" --duration 0.2 --quiet --lcm-url "$URL" >"$T/$n.log" 2>&1
	rc=$?
	if [ "$rc" = 0 ] && grep -q 'ready:' "$T/$n.log"; then tap_ok "scenario $n runs"; else tap_fail "scenario $n runs" "rc $rc: $(cat "$T/$n.log")"; fi
done
tap_done
