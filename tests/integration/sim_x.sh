#!/usr/bin/env bash
# sim_x.sh — undulate-sim with X-series servos (--model, Protocol 2.0) driven
# over its pty by a raw client: the e-manual's Protocol 2.0 examples byte for
# byte (the request bytes as the manual prints them, the replies compared
# with the manual's), then what the manual describes without printing it —
# the CRC error reply, error numbers, the bus watchdog, a hardware error with
# its alert bit until REBOOT, faults on 2.0 replies — and the bad-input
# counters in the exit summary. Packets the manual does not print are built
# by sim_client.py's pkt2 (its own bit-by-bit CRC and stuffing, not our
# encoder). The manual's servo is an XM430-W210 (model 1030, firmware 38):
# the simulated XM430-W350s get those two registers poked.
. "$(dirname "$0")/../lib.sh"
# one interpreter for the whole test (tests/lib.sh, py_start)
py_start sim "$top/tests/integration/sim_client.py" SIM_CLIENT_BAUD
C="py_call sim"
export SIM_CLIENT_BAUD=57600
xbus="$T/bus/x" lbus="$T/bus/l"

# ---- command line: models and their refusals ------------------------------------------
out=$("$B/undulate-sim" --link "$T/m1" --ids 1,2 --model ax12a,xl430-w250 2>&1); rc=$?
if [ $rc = 2 ] && [[ "$out" == *"cannot share a bus"* ]]; then tap_ok "a bus mixing 1.0 and 2.0 servos is refused (exit 2)"
else tap_fail "a bus mixing protocols is refused" "rc $rc: $out"; fi
out=$("$B/undulate-sim" --link "$T/m2" --ids 1 --model mx-28 2>&1); rc=$?
if [ $rc = 2 ] && [[ "$out" == *"xl430-w250"* ]]; then tap_ok "an unknown model is refused, naming the known ones"
else tap_fail "an unknown model is refused" "rc $rc: $out"; fi

cat >"$T/x.scenario" <<EOF
[sim]
initial_spread = 0
[robot x]
model = xm430-w350
ids = 1,2
contact = none
[robot l]
model = xl430-w250
ids = 1
contact = none
EOF
# 11.9 V and 36 C: the e-manual's Bulk Read example
spawn sim "$B/undulate-sim" --scenario "$T/x.scenario" --link-dir "$T/bus" --control "$T/ctl" \
	--voltage 11.9 --temperature 36 --lcm-url "$(lcm_url 7657)" --seed 2
wait_log sim 'ready:' 5 || { tap_fail "sim ready" "$(cat "$T/sim.log")"; tap_done; exit; }
tap_check "the ready line names each X bus's model" grep -q 'x=.*\[1,2\] x.model=XM430-W350 l=.*\[1\] l.model=XL430-W250' "$T/sim.log"

xfer() { read -r reply rtt < <($C xfer "$1" "$2" 300 "${3:-}"); }
ctl() { $C ctl "$T/ctl" "$1"; }
expect() {  # NAME BUS REQUEST WANT
	xfer "$2" "$3" $(( ${#4} / 2 ))
	if [ "$reply" = "$4" ]; then tap_ok "$1"; else tap_fail "$1" "sent $3, want $4, got $reply"; fi
}
silence() {  # NAME BUS REQUEST
	read -r reply rtt < <($C xfer "$2" "$3" 40)
	if [ "$reply" = "-" ]; then tap_ok "$1"; else tap_fail "$1" "sent $3, want no reply, got $reply"; fi
}
p2() { $C pkt2 "$@"; }
s2() { $C status2 "$@"; }
for id in 1 2; do ctl "poke x $id model_number 1030" >/dev/null; ctl "poke x $id firmware_version 38" >/dev/null; done

# ---- the e-manual's examples --------------------------------------------------------------
expect "Ping, Example 1" "$xbus" FFFFFD0001030001194E FFFFFD000107005500060426655D
expect "Ping, Example 2: broadcast, ID 1 then ID 2" "$xbus" FFFFFD00FE0300013142 \
	FFFFFD000107005500060426655DFFFFFD0002070055000604266F6D
expect "Write: 512 to Goal Position of ID 1 (whole status)" "$xbus" FFFFFD0001090003740000020000CA89 FFFFFD000104005500A10C
# Present Position 166 (ID 1) and 2079 (ID 2), as the Read example assumes:
# drive them there, then let go
move_to() {  # ID PULSES
	expect "ID $1: goal $2" "$xbus" "$(p2 "$1" 3 116 0 $(( $2 & 255 )) $(( $2 >> 8 )) 0 0)" "$(s2 "$1" 0)"
	expect "ID $1: torque on" "$xbus" "$(p2 "$1" 3 64 0 1)" "$(s2 "$1" 0)"
	at() { xfer "$xbus" "$(p2 "$1" 2 132 0 4 0)" 15; [ "${reply:18:4}" = "$(printf '%02X%02X' $(( $2 & 255 )) $(( $2 >> 8 )))" ]; }
	if wait_for 5 at "$1" "$2"; then tap_ok "ID $1 stands at $2"; else tap_fail "ID $1 stands at $2" "$reply"; fi
	expect "ID $1: torque off" "$xbus" "$(p2 "$1" 3 64 0 0)" "$(s2 "$1" 0)"
}
move_to 1 166
move_to 2 2079
expect "Read: Present Position of ID 1 = 166" "$xbus" FFFFFD0001070002840004001D15 FFFFFD000108005500A60000008CC0
expect "Sync Read: IDs 1 and 2, their replies in the request's order" "$xbus" FFFFFD00FE090082840004000102CEFA \
	FFFFFD000108005500A60000008CC0FFFFFD0002080055001F080000BABE
expect "Reg Write: 200 to Goal Velocity of ID 1" "$xbus" FFFFFD00010900046800C8000000AE8E FFFFFD000104005500A10C
tap_check "...registered, Goal Velocity still 0" test "$(ctl "peek x 1 goal_velocity")" = "ok 0"
expect "Action: ID 1" "$xbus" FFFFFD000103000502CE FFFFFD000104005500A10C
tap_check "...Goal Velocity 200" test "$(ctl "peek x 1 goal_velocity")" = "ok 200"
silence "Sync Write: Goal Position 150 to ID 1, 170 to ID 2 (no status)" "$xbus" \
	FFFFFD00FE11008374000400019600000002AA0000008287
tap_check "...ID 1 goal 150" test "$(ctl "peek x 1 goal_position")" = "ok 150"
tap_check "...ID 2 goal 170" test "$(ctl "peek x 2 goal_position")" = "ok 170"
expect "Bulk Read: voltage of ID 1 (11.9 V), temperature of ID 2 (36 C)" "$xbus" \
	FFFFFD00FE0D0092019000020002920001001A05 FFFFFD0001060055007700C369FFFFFD000205005500248BA9
expect "ID 1: max voltage limit 15.0 V" "$xbus" "$(p2 1 3 32 0 150 0)" "$(s2 1 0)"
expect "ID 2: temperature limit 70" "$xbus" "$(p2 2 3 31 0 70)" "$(s2 2 0)"
silence "Bulk Write: max voltage 160 to ID 1, temperature limit 80 to ID 2 (no status)" "$xbus" \
	FFFFFD00FE1000930120000200A000021F00010050B768
tap_check "...ID 1 max voltage limit 160" test "$(ctl "peek x 1 max_voltage_limit")" = "ok 160"
tap_check "...ID 2 temperature limit 80" test "$(ctl "peek x 2 temperature_limit")" = "ok 80"
expect "Clear: ID 1 multi-turn" "$xbus" FFFFFD00010800100144584C22B1DC FFFFFD000104005500A10C
expect "Reboot: ID 1" "$xbus" FFFFFD00010300082F4E FFFFFD000104005500A10C
expect "ID 1: max voltage limit 15.0 V again" "$xbus" "$(p2 1 3 32 0 150 0)" "$(s2 1 0)"
expect "Factory Reset: ID 1, all but the ID" "$xbus" FFFFFD000104000601A1E6 FFFFFD000104005500A10C
tap_check "...still ID 1, model back to 1020" test "$(ctl "peek x 1 model_number")" = "ok 1020"
tap_check "...max voltage limit back to 160" test "$(ctl "peek x 1 max_voltage_limit")" = "ok 160"

# ---- what the manual describes without printing it (an XL430-W250) ------------------------
ping1=$(p2 1 1)
bad=${ping1:0:16}$(printf '%02X' $(( (16#${ping1:16:2} + 1) & 255 )))${ping1:18:2}
expect "a PING with a bad CRC: the CRC error (3)" "$lbus" "$bad" "$(s2 1 3)"
expect "temperature limit 101: data range (4)" "$lbus" "$(p2 1 3 31 0 101)" "$(s2 1 4)"
expect "two bytes of the four-byte Goal Position: data length (5)" "$lbus" "$(p2 1 3 116 0 0 8)" "$(s2 1 5)"
expect "goal position 5000 (limits 0..4095): data limit (6)" "$lbus" "$(p2 1 3 116 0 0x88 0x13 0 0)" "$(s2 1 6)"
# one mistake, one number: a goal beyond its limit register is the data limit
# error whether or not it is also beyond the largest value that register takes
expect "goal PWM 886 (above every PWM limit): data limit (6)" "$lbus" "$(p2 1 3 100 0 0x76 3)" "$(s2 1 6)"
expect "PWM limit 500" "$lbus" "$(p2 1 3 36 0 0xF4 1)" "$(s2 1 0)"
expect "goal PWM 600 (PWM limit 500): data limit (6)" "$lbus" "$(p2 1 3 100 0 0x58 2)" "$(s2 1 6)"
expect "PWM limit 886: data range (4), a fixed range" "$lbus" "$(p2 1 3 36 0 0x76 3)" "$(s2 1 4)"
expect "PWM limit 885 again" "$lbus" "$(p2 1 3 36 0 0x75 3)" "$(s2 1 0)"
expect "a write of Present Position: access (7)" "$lbus" "$(p2 1 3 132 0 0 0 0 0)" "$(s2 1 7)"
expect "an instruction the servo lacks: instruction (2)" "$lbus" "$(p2 1 7)" "$(s2 1 2)"
expect "ACTION with nothing registered: instruction (2)" "$lbus" "$(p2 1 5)" "$(s2 1 2)"
expect "XL430: current control mode does not exist: data range (4)" "$lbus" "$(p2 1 3 11 0 0)" "$(s2 1 4)"
silence "a broadcast READ: no status" "$lbus" "$(p2 0xFE 2 7 0 1 0)"
# the bus watchdog: velocity mode, torque on, Goal Velocity 50, 100 ms
expect "velocity control mode" "$lbus" "$(p2 1 3 11 0 1)" "$(s2 1 0)"
expect "torque on" "$lbus" "$(p2 1 3 64 0 1)" "$(s2 1 0)"
expect "Goal Velocity 50" "$lbus" "$(p2 1 3 104 0 50 0 0 0)" "$(s2 1 0)"
expect "Bus Watchdog 5 (100 ms)" "$lbus" "$(p2 1 3 98 0 5)" "$(s2 1 0)"
tripped() { [ "$(ctl "peek l 1 bus_watchdog")" = "ok 255" ]; }
if wait_for 5 tripped; then tap_ok "no instruction for 100 ms: the watchdog trips"
else tap_fail "the watchdog trips" "$(ctl "servo l 1")"; fi
expect "...Bus Watchdog reads -1" "$lbus" "$(p2 1 2 98 0 1 0)" "$(s2 1 0 0xFF)"
expect "...Goal Velocity reads 0: stopped" "$lbus" "$(p2 1 2 104 0 4 0)" "$(s2 1 0 0 0 0 0)"
expect "...a goal is refused: data range (4)" "$lbus" "$(p2 1 3 104 0 60 0 0 0)" "$(s2 1 4)"
expect "...0 clears it" "$lbus" "$(p2 1 3 98 0 0)" "$(s2 1 0)"
expect "...then a goal is taken" "$lbus" "$(p2 1 3 104 0 60 0 0 0)" "$(s2 1 0)"
# a hardware error in Shutdown: overheating (80 C > the XL430's 72)
ctl "fault l 1 temperature 80" >/dev/null
hot() { [ "$(ctl "peek l 1 hardware_error_status")" = "ok 4" ]; }
if wait_for 5 hot; then tap_ok "80 C: Hardware Error Status overheating"; else tap_fail "overheating" "$(ctl "servo l 1")"; fi
expect "...PING carries the alert bit" "$lbus" "$(p2 1 1)" "$(s2 1 0x80 0x24 0x04 46)"
expect "...torque is off" "$lbus" "$(p2 1 2 64 0 1 0)" "$(s2 1 0x80 0)"
expect "...torque on is refused: result fail and alert" "$lbus" "$(p2 1 3 64 0 1)" "$(s2 1 0x81)"
ctl "clear l 1 temperature" >/dev/null
cool() { [ "$(ctl "peek l 1 present_temperature")" = "ok 36" ]; }
wait_for 5 cool
expect "...cooled down: the alert stays until REBOOT" "$lbus" "$(p2 1 1)" "$(s2 1 0x80 0x24 0x04 46)"
expect "...REBOOT (answered before the boot)" "$lbus" "$(p2 1 8)" "$(s2 1 0x80)"
expect "...after REBOOT: no alert" "$lbus" "$(p2 1 1)" "$(s2 1 0 0x24 0x04 46)"
tap_check "...RAM back to its defaults: position control mode kept (EEPROM), torque off" \
	test "$(ctl "servo l 1" | field torque)" = 0
# faults on 2.0 replies
ctl "fault l 1 stuck-error alert|access count=1" >/dev/null
expect "fault stuck-error alert|access: ERR 0x87 once" "$lbus" "$(p2 1 1)" "$(s2 1 0x87 0x24 0x04 46)"
expect "...then none" "$lbus" "$(p2 1 1)" "$(s2 1 0 0x24 0x04 46)"
r=$(ctl "fault l 1 stuck-error overload")
if [[ "$r" == error:*"Protocol 2.0"* ]]; then tap_ok "stuck-error overload (a 1.0 bit) on a 2.0 servo: refused"
else tap_fail "stuck-error overload on a 2.0 servo refused" "$r"; fi
ctl "fault l 1 no-reply count=1" >/dev/null
silence "fault no-reply: no status" "$lbus" "$(p2 1 1)"
silence "a Protocol 1.0 PING on a 2.0 bus: no reply" "$lbus" FFFF010201FB
# bad stuffing: a WRITE cut short by a new packet (FF FF FD inside its body
# not followed by the stuffed FD); the PING inside it is answered at once
expect "a WRITE cut short by a PING (bad stuffing): the PING is answered" "$lbus" \
	"FFFFFD00010F00037400$(p2 1 1)" "$(s2 1 0 0x24 0x04 46)"
# power loss: silent, then a boot (RAM reset, EEPROM kept)
expect "LED on" "$lbus" "$(p2 1 3 65 0 1)" "$(s2 1 0)"
ctl "power l 1 off" >/dev/null
silence "power off: no reply" "$lbus" "$(p2 1 1)"
ctl "power l 1 on" >/dev/null
expect "power on: the LED is off again (RAM reset)" "$lbus" "$(p2 1 2 65 0 1 0)" "$(s2 1 0 0)"
expect "...Operating Mode still velocity (EEPROM kept)" "$lbus" "$(p2 1 2 11 0 1 0)" "$(s2 1 0 1)"

tap_check "sim still running" alive sim
stop sim >/dev/null
grep '^undulate-sim: bus' "$T/sim.log" | sed 's/^/# /'
summary=$(grep '^undulate-sim: bus l (Protocol 2.0):' "$T/sim.log")
crc=$(echo "$summary" | sed -n 's/.* \([0-9]*\) bad CRCs.*/\1/p')
stuffing=$(echo "$summary" | sed -n 's/.* \([0-9]*\) bad stuffing.*/\1/p')
tap_check "exit summary of bus l: the bad CRC counted ($crc)" test "${crc:-0}" -ge 1
tap_check "...the bad stuffing counted ($stuffing)" test "${stuffing:-0}" -ge 1
tap_done
