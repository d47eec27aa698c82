#!/usr/bin/env bash
# run.sh: realtime — it measures a gait and bytes in real time (tests/run.sh)
# undulated's cycle read through the X series' indirect block, against
# undulate-sim (XM430-W350s, firmware 46: Fast Sync Read):
#  - start-up maps Indirect Address 1..13 to the present registers the
#    cycle decodes (126..135, 144..146), reads the map back, says so, and
#    the cycle reads the 13-byte block at 224 by Fast Sync Read; the
#    servos hold the map; OSCILLATOR swings both joints, the supply read
#    through the block is the simulator's;
#  - a second start finds the map in place and writes nothing;
#  - bytes on the wire (the simulator's counters) with the indirect block and
#    with indirect = off, on servos of firmware 44 (plain SYNC_READ: a status
#    packet a servo): fewer bytes a status packet through the indirect block
#    (printed; in real time the mix of read-backs and writes moves with the
#    machine's load, so only the direction is asserted here: the exact 8
#    bytes a servo every slow cycle is test_daemon_cycle's, on its fake bus);
#  - a simulator whose servos have no indirect area ([sim] indirect = false):
#    the map's read is refused, said, the cycle reads the registers where
#    they lie, the robot runs;
#  - a REBOOT (an overload shutdown, fault_reboots 1) ends the indirect read:
#    said, the robot recovers on the direct read.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then tap_skip_all "undulate-sim or undulated not built"; fi
URL=$(lcm_url 7735)
R="di$$"
sim_stat() { ctl stats | sed -n "s/.* $1=\([0-9]*\).*/\1/p"; }
# the servos' bytes a status packet over the next $1 cycles (read-backs and
# acknowledgements included): per packet, so that replies a loaded machine
# lost to timeouts do not count as savings
per_reply() {
	local n0 t0 n1 t1
	n0=$(sim_stat replies); t0=$(sim_stat tx_bytes)
	wait_cycles "$1"
	n1=$(sim_stat replies); t1=$(sim_stat tx_bytes)
	awk -v n=$((n1 - n0)) -v t=$((t1 - t0)) 'BEGIN { printf "%.2f", (n > 0 ? t / n : 0) }'
}

cat >"$T/x.scenario" <<EOF
[sim]
seed = 8
baud = 1000000
return_delay_us = 0
[robot r1]
link = $T/xm
ids = 1,2
model = xm430-w350
contact = none
[robot r2]
link = $T/xs
ids = 1,2
model = xm430-w350
firmware = 44
contact = none
EOF
spawn_rt sim "$S" --scenario "$T/x.scenario" --lcm-url "$URL" --control "$T/ctl"
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
# robot NAME PORT WHAT [OPTION...]: undulated on PORT, ready and 50 cycles
# published, or WHAT failed and the test ends
robot() {
	local name=$1 port=$2 what=$3
	shift 3
	spawn_rt "$name" "$D" --port "$port" --ids 1,2 --robot "$R" --lcm-url "$URL" --set robot.fault_action=hold "$@"
	wait_log "$name" "ready: $R.STATE" 15 && wait_for 10 cycle_at_least 50 ||
		{ tap_fail "$what" "$(cat "$T/$name.log")"; tap_done; exit 1; }
}

# ---- mapped, read back, read ------------------------------------------------------------------------
robot d "$T/xm" "daemon starts on the X bus"
if grep -q "bus: the cycle reads the indirect block at 224, 10 or 13 bytes a servo where the present registers at 126 take 10 or 21 (Indirect Address 1..13 on every servo read back as mapped (2 written, 0 kept))" "$T/d.log" &&
	grep -q "bus: the cycle reads by Fast Sync Read" "$T/d.log"; then
	tap_ok "start-up maps Indirect Address 1..13 on both servos, reads the map back, says the cycle reads the block by Fast Sync Read"
else tap_fail "the indirect map said" "$(grep -a 'bus:' "$T/d.log" | head -4)"; fi
got="$(sim_peek r1 1 indirect_address_1) $(sim_peek r1 1 indirect_address_7) $(sim_peek r1 2 indirect_address_10) $(sim_peek r1 2 indirect_address_11) $(sim_peek r1 2 indirect_address_13) $(sim_peek r1 2 indirect_address_14)"
if [ "$got" = "126 132 135 144 146 237" ]; then
	tap_ok "the servos hold the map: slots 1..10 = 126..135, 11..13 = 144..146, slot 14 its factory value"
else tap_fail "the servos' map" "$got"; fi
cmd 'mode oscillator' >/dev/null
wait_cycles 600
s0=$(swing 0 300); s1=$(swing 1 300)
v=$(last_state | field v0)
if over "$s0" 0.5 && over "$s1" 0.5 && state_is ' mode=3 .* fault="" ' 1; then
	tap_ok "OSCILLATOR swings both joints on the indirect read ($s0, $s1 rad peak to peak)"
else tap_fail "OSCILLATOR on the indirect read" "$s0 / $s1 rad; $(last_state | cut -c1-300)"; fi
if state_is ' v0=1[12]\.[0-9] T0=[1-9]' 2; then
	tap_ok "supply and temperature read through the block's slow part (v0 $(last_state | field v0) V)"
else tap_fail "voltage through the block" "v0=$v; $(last_state | cut -c1-300)"; fi

# ---- a second start keeps the map; a REBOOT ends the indirect read ---------------------------------------
stop d >/dev/null
robot d3 "$T/xm" "daemon restarts"
if grep -q "read back as mapped (0 written, 2 kept)" "$T/d3.log"; then
	tap_ok "a second start finds the map in place and keeps it (nothing written)"
else tap_fail "the map kept" "$(grep -a 'bus:' "$T/d3.log" | head -3)"; fi
cmd 'mode oscillator' >/dev/null
wait_cycles 200
ctl poke r1 2 hardware_error_status 32 >/dev/null   # overload: in Shutdown (52), torque off until REBOOT
if wait_log d3 "bus: servo 2 is rebooted and may come back without its indirect map: the cycle reads the present registers where they lie" 5 &&
	event 'kind=recovered text="servo 2: recovered' 8; then
	tap_ok "a REBOOT ends the indirect read: said, the servo recovers on the direct read"
else tap_fail "REBOOT and the indirect read" "$(grep -a 'bus:' "$T/d3.log" | tail -3); $(events | tail -3)"; fi
wait_cycles 300
sw=$(swing 1 300)
if over "$sw" 0.5; then tap_ok "joint 2 swings again on the direct read ($sw rad)"
else tap_fail "swinging after the reboot" "$sw rad"; fi
stop d3 >/dev/null

# ---- what it saves on the wire ------------------------------------------------------------------------
# firmware 44: SYNC_READ, one status packet a servo; each daemon alone on the simulator
robot d4 "$T/xs" "daemon starts on firmware 44"
cmd 'mode oscillator' >/dev/null
wait_cycles 100
ind=$(per_reply 400)
stop d4 >/dev/null
robot d5 "$T/xs" "daemon restarts with indirect = off" --set robot.indirect=off
cmd 'mode oscillator' >/dev/null
wait_cycles 100
dir=$(per_reply 400)
stop d5 >/dev/null
echo "# servo bytes a status packet (SYNC_READ, read-backs and acknowledgements included): indirect block $ind, direct $dir"
if grep -q "bus: the cycle reads the indirect block at 224" "$T/d4.log" && grep -q "bus: the cycle reads by SYNC_READ" "$T/d4.log" &&
	grep -q "bus: the cycle reads the present registers at 126, 10 or 21 bytes a servo: no indirect block, as indirect = off" "$T/d5.log" &&
	awk -v a="$ind" -v b="$dir" 'BEGIN { exit !(a > 0 && a < b) }'; then
	tap_ok "the indirect block saves servo bytes: $ind a status packet where the direct read takes $dir (indirect = off, said)"
else tap_fail "indirect = off and the saving" "indirect $ind, direct $dir; $(grep -a 'bus:' "$T/d4.log" "$T/d5.log" | head -4)"; fi
stop sim >/dev/null

# ---- servos without the indirect areas --------------------------------------------------------------------
cat >"$T/n.scenario" <<EOF
[sim]
seed = 8
baud = 1000000
return_delay_us = 0
indirect = false
[robot r1]
link = $T/xn
ids = 1,2
model = xl430-w250
contact = none
EOF
spawn_rt sim2 "$S" --scenario "$T/n.scenario" --lcm-url "$URL" --control "$T/ctl2"
wait_log sim2 'ready' 10 || { tap_fail "simulator without indirect areas ready" "$(cat "$T/sim2.log")"; tap_done; exit 1; }
robot d6 "$T/xn" "daemon starts on servos without indirect areas"
if grep -q "bus: the cycle reads the present registers at 126, 10 or 21 bytes a servo: no indirect block, as servo 1 (XL430-W250): reading Indirect Address 1..13 failed" "$T/d6.log"; then
	tap_ok "servos without indirect areas: the map's read refused, said, the cycle reads the registers where they lie"
else tap_fail "no indirect areas" "$(grep -a 'bus:' "$T/d6.log" | head -3)"; fi
cmd 'mode oscillator' >/dev/null
wait_cycles 600
s0=$(swing 0 300); s1=$(swing 1 300)
if over "$s0" 0.3 && over "$s1" 0.3; then tap_ok "OSCILLATOR swings both joints there too ($s0, $s1 rad)"
else tap_fail "OSCILLATOR on the direct read" "$s0 / $s1 rad; $(last_state | cut -c1-300)"; fi
tap_done
