#!/usr/bin/env bash
# sim_manual.sh — undulate-sim driven with the manuals' own example packets,
# byte for byte, from a raw client on the link, and one packet for each rule
# the AX-12A e-manual gives that the simulator must follow (sim-bridge/README.md,
# "Servo semantics"):
#  - the e-manual's Protocol 1.0 examples (PING, READ of the temperature,
#    the checksum example, REG_WRITE + ACTION, SYNC_WRITE, FACTORY_RESET);
#  - the worked examples of the original AX-12 user's manual (§5, Examples 7
#    to 21: ID, baud, return delay, angle limits, temperature and voltage
#    limits, max torque, status return level, alarms, LED and torque,
#    compliance, goal and speed, REG_WRITE/ACTION, lock, punch). Where the
#    two manuals disagree the AX-12A e-manual wins and the check says so;
#  - a write outside the e-manual's ranges: the range bit, nothing stored;
#  - an error whose bit is set in Alarm Shutdown: torque off, torque limit 0,
#    for every bit (range, angle limit, instruction, checksum);
#  - wheel mode's Present Speed: the output share, not a measured speed;
#  - the simulator's choices where the manuals are silent (READ past
#    address 49, EEPROM with torque on, a baud change answered at the old rate).
# Instruction packets are written out as the manuals print them, never built by
# our encoder (STYLE.md: a symmetric bug would pass); replies the manuals do not
# print are built by pkt() below, an independent few lines of shell.
. "$(dirname "$0")/../lib.sh"
# one interpreter for the whole test (tests/lib.sh, py_start)
py_start sim "$top/tests/integration/sim_client.py" SIM_CLIENT_BAUD
C="py_call sim"
URL=$(lcm_url 7653)
link="$T/bus/r1"

# Two servos, IDs 1 and 2: the original manual's examples start from one
# servo with ID 1 (its Example 7 makes it ID 0) and later need an ID 1 beside
# it (Example 19). 32 °C is the temperature of the e-manual's READ example.
spawn sim "$B/undulate-sim" --link "$link" --ids 1,2 --temperature 32 --lcm-url "$URL" \
	--control "$T/ctl" --seed 5
wait_log sim 'ready:' 5 || { tap_fail "sim ready" "$(cat "$T/sim.log")"; tap_done; exit; }

xfer() { read -r reply rtt < <($C xfer "$link" "$@"); }
ctl() { $C ctl "$T/ctl" "$1"; }
# expect_regs NAME ID ADDR BYTE...: READ(ADDR, n) of servo ID answers BYTE...
expect_regs() {
	local name=$1 id=$2 addr=$3; shift 3
	expect_reply "$name" "$(pkt "$id" 2 "$addr" $#)" "$(status "$id" 0 "$@")"
}
field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }
OK0=FFFF000200FD   # "no error" from ID 0, as the manuals print it
OK1=FFFF010200FC   # ... from ID 1
RANGE0=FFFF000208F5   # the range bit (3) from ID 0, as the original manual prints it (Example 20)

# ---- the e-manual's Protocol 1.0 examples --------------------------------------------
expect_reply "e-manual PING ID 1" FFFF010201FB $OK1
expect_reply "e-manual READ ID 1 present temperature: 32 C" FFFF0104022B01CC FFFF01030020DB

# ---- the original AX-12 manual, §5, Examples 7-18 (one servo, ID 1 -> 0) --------------
expect_reply "Ex. 7 ID 1 -> 0: answered under the old ID 1" FFFF0104030300F4 $OK1
expect_reply "...the servo is ID 0 now" FFFF000201FC $OK0
expect_silence "...and ID 1 is gone" FFFF010201FB
expect_reply "Ex. 8 baud rate 1 Mbps" FFFF0004030401F3 $OK0
expect_reply "Ex. 9 return delay 4 us" FFFF0004030502F1 $OK0
expect_regs "...return delay register 2" 0 5 2
goal0=$(ctl "peek r1 0 goal_position")
expect_reply "Ex. 10 angle range 0-150 deg (CCW limit 0x1FF)" FFFF00050308FF01EF $OK0
expect_reply "...goal 512 beyond it: the angle-limit bit (e-manual, Goal Position)" "$(pkt 0 3 30 0x00 0x02)" "$(status 0 2)"
tap_check "...and the goal not stored (${goal0#ok })" test "$(ctl "peek r1 0 goal_position")" = "$goal0"
expect_reply "...CCW limit back to 1023" "$(pkt 0 3 8 0xFF 0x03)" $OK0
expect_reply "Ex. 11 temperature limit 80 C" FFFF0004030B509D $OK0
expect_reply "temperature limit 101 C: above the e-manual's 0-100, the range bit" "$(pkt 0 3 11 101)" $RANGE0
expect_regs "...not stored: still 80" 0 11 80
# The original manual's Example 12 sets 10-17 V with no error (its range was
# 50-250); the AX-12A e-manual gives 50-160 (5-16 V): 17 V is refused.
expect_reply "Ex. 12 voltage 10-17 V: 170 is above the e-manual's 160, the range bit" FFFF0005030C64AADD $RANGE0
expect_regs "...neither limit stored (a write is atomic): 60, 140" 0 12 60 140
expect_reply "min voltage 49: below 50, the range bit" "$(pkt 0 3 12 49)" $RANGE0
expect_reply "max voltage 160: the e-manual's top, accepted" "$(pkt 0 3 13 160)" $OK0
expect_reply "Ex. 13 max torque 50% (0x1FF)" FFFF0005030EFF01E9 $OK0
# Example 14 answers the write itself; the new level applies "starting with
# the following instruction" (the manual's words).
expect_reply "Ex. 14 status return level 0: the write itself is answered" FFFF0004031000E8 $OK0
expect_silence "...the next READ is not" "$(pkt 0 2 43 1)"
expect_reply "...PING always is" FFFF000201FC $OK0
expect_silence "...level 2 again: answered under the old level 0, i.e. not" "$(pkt 0 3 16 2)"
expect_regs "...and level 2 applies from the next instruction" 0 16 2
expect_reply "Ex. 15 alarm LED and shutdown: overheating (0x04)" FFFF000503110404DE $OK0
expect_reply "Ex. 16 LED on and torque on" FFFF000503180101DD $OK0
expect_regs "...both on" 0 24 1 1
# The AX-12A e-manual: "Data in the EEPROM Area can only be changed ... when
# the value of Torque Enable(24) is '0'"; the error it gets is not given: the
# simulator answers the range bit (README).
expect_reply "EEPROM write with torque on: the range bit (the simulator's choice)" "$(pkt 0 3 5 0)" $RANGE0
expect_regs "...not stored" 0 5 2
expect_regs "...and with alarm shutdown 0x04 the range error leaves the torque on" 0 24 1
expect_reply "Ex. 17 compliance margins 1, slopes 0x40" FFFF0007031A0101404059 $OK0
expect_reply "Ex. 18 goal 0x200 at moving speed 0x200" FFFF0007031E00020002D3 $OK0
expect_regs "...goal and moving speed stored" 0 30 0x00 0x02 0x00 0x02

# ---- Example 19 and the e-manual's REG_WRITE / ACTION / SYNC_WRITE -------------------
expect_reply "servo 2 -> ID 1 (answered under its old ID 2)" "$(pkt 2 3 3 1)" "$(status 2 0)"
expect_reply "Ex. 19 REG_WRITE ID 0 goal 0" FFFF0005041E0000D8 $OK0
expect_reply "Ex. 19 REG_WRITE ID 1 goal 0x3FF" FFFF0105041EFF03D5 $OK1
expect_regs "...registered, not yet moved" 1 44 1
expect_silence "Ex. 19 ACTION broadcast: no reply" FFFFFE0205FA
expect_regs "...ID 0 goal 0" 0 30 0x00 0x00
expect_regs "...ID 1 goal 0x3FF" 1 30 0xFF 0x03
expect_silence "e-manual SYNC_WRITE IDs 0, 1: no reply" FFFFFE0E831E040010005001012002600367
expect_regs "...ID 0: goal 0x010, speed 0x150" 0 30 0x10 0x00 0x50 0x01
expect_regs "...ID 1: goal 0x220, speed 0x360" 1 30 0x20 0x02 0x60 0x03
expect_reply "e-manual REG_WRITE ID 1 goal 500" FFFF0105041EF401E2 $OK1
expect_silence "e-manual ACTION broadcast" FFFFFE0205FA
expect_regs "...goal 500 (0x1F4)" 1 30 0xF4 0x01
expect_reply "WRITE ID 1 goal position 512 (ax12.md's vector)" FFFF0105031E0002D6 $OK1
# The e-manual's checksum example writes 0x64 0xAA at address 12: the Max
# Voltage Limit 170 is outside the same manual's 50-160.
expect_reply "e-manual checksum example (max voltage 170): the range bit" FFFF0105030C64AADC FFFF010208F4
expect_regs "...nothing stored" 1 12 60 140

# ---- Examples 20, 21: lock and punch ---------------------------------------------------
expect_reply "torque off (ID 0)" "$(pkt 0 3 24 0)" $OK0
expect_reply "Ex. 20 lock" FFFF0004032F01C8 $OK0
expect_reply "...an EEPROM write is refused: the range bit" "$(pkt 0 3 5 10)" $RANGE0
# The original manual's Example 20 also refuses a punch write under lock; the
# AX-12A e-manual locks the EEPROM area only, and punch (48) is RAM.
expect_reply "Ex. 21 punch 0x40 (RAM: writable under the e-manual's lock)" FFFF00050330400087 $OK0
expect_reply "punch 0x1F: below the e-manual's 0x20-0x3FF, the range bit" "$(pkt 0 3 48 0x1F 0x00)" $RANGE0
expect_regs "...not stored: still 0x40" 0 48 0x40 0x00
expect_reply "punch 0x20: the bottom of the range, accepted" "$(pkt 0 3 48 0x20 0x00)" $OK0

# ---- Alarm Shutdown acts on every bit --------------------------------------------------
# Servo 1 (torque off, factory alarm shutdown 36 = overheating | overload).
expect_reply "ID 1 angle limits 100..900" "$(pkt 1 3 6 100 0 0x84 0x03)" $OK1
expect_reply "ID 1 torque on" "$(pkt 1 3 24 1)" $OK1
expect_reply "factory mask 36: a range error is answered..." "$(pkt 1 3 48 0x10 0x00)" "$(status 1 8)"
expect_regs "...and leaves the torque on at limit 1023" 1 34 0xFF 0x03
expect_regs "...torque enable still 1" 1 24 1
expect_reply "torque off to write the mask (EEPROM)" "$(pkt 1 3 24 0)" $OK1
expect_reply "alarm shutdown 0x7F: every bit" "$(pkt 1 3 18 0x7F)" $OK1
on_again() {  # NAME: the manual's recovery, torque limit back then torque enable
	expect_reply "$1: torque limit written back" "$(pkt 1 3 34 0xFF 0x03)" $OK1
	expect_reply "$1: torque on" "$(pkt 1 3 24 1)" $OK1
}
shut_down() {  # NAME: torque enable 0 and torque limit 0 (e-manual, Alarm Shutdown)
	expect_regs "$1: torque off" 1 24 0
	expect_regs "$1: torque limit 0" 1 34 0 0
}
on_again "mask 0x7F"
expect_reply "range error (punch 0x10) under mask 0x7F: the range bit..." "$(pkt 1 3 48 0x10 0x00)" "$(status 1 8)"
shut_down "range error"
on_again "after the range error"
expect_reply "angle-limit error (goal 50 < CW limit 100): the angle-limit bit..." "$(pkt 1 3 30 50 0)" "$(status 1 2)"
shut_down "angle-limit error"
on_again "after the angle-limit error"
expect_reply "instruction error (ACTION with nothing registered): bit 6..." "$(pkt 1 5)" "$(status 1 0x40)"
shut_down "instruction error"
on_again "after the instruction error"
expect_reply "checksum error (a PING whose checksum is off by one): bit 4..." FFFF010201FA FFFF010210EC
shut_down "checksum error"
on_again "after the checksum error"
r=$(ctl "servo r1 1")
tap_check "four alarm shutdowns counted ($(echo "$r" | field shutdowns))" test "$(echo "$r" | field shutdowns)" = 4
expect_reply "torque off, factory mask 36 again" "$(pkt 1 3 24 0)" $OK1
expect_reply "...alarm shutdown 36" "$(pkt 1 3 18 36)" $OK1

# ---- Present Speed: measured in joint mode, the output share in wheel mode --------------
expect_reply "joint mode: limits 0..1023" "$(pkt 1 3 6 0 0 0xFF 0x03)" $OK1
expect_reply "torque on" "$(pkt 1 3 24 1)" $OK1
expect_reply "moving speed 100 (11.1 rpm)" "$(pkt 1 3 32 100 0)" $OK1
at_512() { xfer "$(pkt 1 2 36 2)" 300 8; p=$(( 16#${reply:12:2}${reply:10:2} )); [ "$p" -ge 506 ] && [ "$p" -le 518 ]; }
if wait_for 5 at_512; then tap_ok "the joint holds goal 512"; else tap_fail "the joint holds goal 512" "present $reply"; fi
expect_reply "goal 1000 at moving speed 100 (2 s away)" "$(pkt 1 3 30 0xE8 0x03)" $OK1
sleep 0.4
xfer "$(pkt 1 2 38 2)" 300 8
speed=$(( 16#${reply:12:2}${reply:10:2} ))
if [ "${#reply}" = 16 ] && [ "$speed" -ge 90 ] && [ "$speed" -le 110 ]; then
	tap_ok "joint mode: present speed is the measured speed, CCW ($speed for moving speed 100)"
else tap_fail "joint mode: present speed measured (90..110 CCW)" "got $reply ($speed)"; fi
expect_reply "torque off" "$(pkt 1 3 24 0)" $OK1
expect_reply "wheel mode: both angle limits 0" "$(pkt 1 3 6 0 0 0 0)" $OK1
expect_reply "torque on" "$(pkt 1 3 24 1)" $OK1
expect_reply "moving speed 512: 50 % output, CCW" "$(pkt 1 3 32 0x00 0x02)" $OK1
spinning() { [ "$(awk -v s="$(ctl "servo r1 1" | field speed)" 'BEGIN { print (s > 2.0) }')" = 1 ]; }
if wait_for 3 spinning; then tap_ok "the wheel turns ($(ctl "servo r1 1" | field speed) rad/s, true)"
else tap_fail "the wheel turns (> 2 rad/s)" "$(ctl "servo r1 1")"; fi
# A measured speed would be about 3 rad/s / 0.0116 = 260 units; the e-manual's
# wheel-mode Present Speed is the output, 0.1 % a step: 512.
expect_regs "wheel mode: present speed is the output share, 512" 1 38 0x00 0x02
expect_reply "moving speed 1024 + 300: 29 % output, CW" "$(pkt 1 3 32 0x2C 0x05)" $OK1
expect_regs "...present speed 1324 (bit 10: CW)" 1 38 0x2C 0x05
expect_reply "torque limit 256 caps the output" "$(pkt 1 3 34 0x00 0x01)" $OK1
expect_regs "...present speed: the output driven, 256 CW" 1 38 0x00 0x05
expect_reply "moving speed 0: no output" "$(pkt 1 3 32 0 0)" $OK1
expect_regs "...present speed 0" 1 38 0 0

# ---- the simulator's choices where the manuals are silent ---------------------------------
expect_reply "READ past address 49: the range bit" "$(pkt 1 2 45 10)" "$(status 1 8)"
expect_regs "READ of address 49 alone (punch high byte)" 1 49 0
expect_reply "torque off" "$(pkt 1 3 24 0)" $OK1
expect_reply "baud 500 kbps: answered at the old rate (1 Mbps)" "$(pkt 1 3 4 3)" $OK1
expect_silence "...then deaf at 1 Mbps" FFFF010201FB
export SIM_CLIENT_BAUD=500000
expect_reply "...and answers at 500 kbps" FFFF010201FB $OK1
expect_reply "baud back to 1 Mbps: answered at 500 kbps" "$(pkt 1 3 4 1)" $OK1
unset SIM_CLIENT_BAUD
expect_reply "...and at 1 Mbps again" FFFF010201FB $OK1

# ---- FACTORY_RESET (the e-manual's example, ID 0) --------------------------------------
expect_reply "e-manual FACTORY_RESET ID 0: answered under the old ID" FFFF000206F7 $OK0
expect_silence "...ID 0 is gone (it is ID 1 now)" FFFF000201FC
tap_check "sim still running" alive sim
tap_done
