#!/usr/bin/env bash
# dxl_cli — the `dxl` program (a real process on a real pty) against the fake
# AX-12 bus served by test_dxl_fakeservo --serve: stdout carries results only,
# every failure is one line on stderr, and the exit codes are the documented ones.
. "$(dirname "$0")/../lib.sh"

dxl="$B/dxl"
fake="$BUILD/tests/test_dxl_fakeservo"
bus="$T/bus"

# run NAME ARGS...: runs dxl, keeps stdout/stderr in $T/NAME.{out,err}, sets $rc.
# Replies get 100 ms: the fake is a process a loaded machine may not schedule
# within the tool's default 5 ms of slack (the derived timeout is tested in
# test_protocol_portbus and test_dxl_fakeservo).
run() {
	local name=$1; shift
	rc=0
	"$dxl" --timeout-ms 100 "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
}
lines() { wc -l <"$1" | tr -d ' '; }

if [ ! -x "$dxl" ] || [ ! -x "$fake" ]; then
	tap_fail "dxl and test_dxl_fakeservo are built" "missing $dxl or $fake"
	tap_done; exit
fi

# ID 2 reports overload (0x20) in every status packet.
spawn fake "$fake" --serve "$bus" --ids 1,2 --errbits 2:0x20
if wait_log fake '^ready' 10; then tap_ok "fake bus ready"; else tap_fail "fake bus ready" "$(cat "$T/fake.log")"; tap_done; exit; fi

run help --help
[ "$rc" -eq 0 ] && grep -q 'set-baud ID BAUD' "$T/help.out" && tap_ok "--help lists commands (exit 0)" \
	|| tap_fail "--help lists commands (exit 0)" "rc=$rc"

run noargs
[ "$rc" -eq 2 ] && grep -q '^usage: dxl' "$T/noargs.err" && [ ! -s "$T/noargs.out" ] \
	&& tap_ok "no command: usage on stderr, exit 2" || tap_fail "no command: usage on stderr, exit 2" "rc=$rc"

run ping --port "$bus" ping 1
[ "$rc" -eq 0 ] && grep -q '^ID 1 answered in [0-9]* us: model 12 (AX-12A), firmware 24, Protocol 1.0$' "$T/ping.out" \
	&& tap_ok "ping 1" || tap_fail "ping 1" "rc=$rc $(cat "$T/ping.out" "$T/ping.err")"

run temp --port "$bus" read 1 present_temperature
[ "$rc" -eq 0 ] && [ "$(cat "$T/temp.out")" = "32" ] && [ ! -s "$T/temp.err" ] \
	&& tap_ok "read prints the raw value alone" || tap_fail "read prints the raw value alone" "rc=$rc out=$(cat "$T/temp.out")"

run units --port "$bus" read 1 43 --units
[ "$rc" -eq 0 ] && grep -q '^32 (' "$T/units.out" && tap_ok "read --units (register by address)" \
	|| tap_fail "read --units (register by address)" "rc=$rc out=$(cat "$T/units.out")"

run write --port "$bus" write 1 goal_position 300
run readback --port "$bus" read 1 goal_position
[ "$(cat "$T/readback.out")" = "300" ] && tap_ok "write then read back" || tap_fail "write then read back" "$(cat "$T/readback.out" "$T/write.err")"
# a write says what the servo holds now (it printed nothing)
[ "$(cat "$T/write.out")" = "ID 1: goal_position = 300 (read back)" ] && [ ! -s "$T/write.err" ] \
	&& tap_ok "write confirms: $(cat "$T/write.out")" || tap_fail "write confirms what the servo holds" "out '$(cat "$T/write.out")' err '$(cat "$T/write.err")'"

# a negative value is a value, not an option: an unsigned register refuses it
# with its range (it said "unknown option '-3'"), after -- as well
run neg --port "$bus" write 1 cw_angle_limit -3
run neg2 --port "$bus" write -- 1 cw_angle_limit -3
[ "$rc" -eq 2 ] && [ ! -s "$T/neg.out" ] && [ "$(lines "$T/neg.err")" = 1 ] \
	&& grep -q "^dxl: value '-3' out of range for cw_angle_limit (0..1023)$" "$T/neg.err" && cmp -s "$T/neg.err" "$T/neg2.err" \
	&& tap_ok "write 1 cw_angle_limit -3: $(cat "$T/neg.err")" \
	|| tap_fail "a negative value refused with the register's range" "rc=$rc $(cat "$T/neg.err" "$T/neg2.err")"

run range --port "$bus" write 1 goal_position 5000
run after --port "$bus" read 1 goal_position
[ "$rc" -eq 0 ] && [ "$(cat "$T/after.out")" = "300" ] && [ "$(lines "$T/range.err")" = 1 ] \
	&& grep -q 'out of range for goal_position (0..1023)' "$T/range.err" \
	&& tap_ok "out-of-range write: one line, nothing written" \
	|| tap_fail "out-of-range write: one line, nothing written" "$(cat "$T/range.err" "$T/after.out")"
run range2 --port "$bus" write 1 goal_position 5000
[ "$rc" -eq 2 ] && tap_ok "out-of-range write exits 2" || tap_fail "out-of-range write exits 2" "rc=$rc"

run unknown --port "$bus" read 1 flux_capacitor
[ "$rc" -eq 2 ] && [ "$(lines "$T/unknown.err")" = 1 ] && grep -q "unknown register 'flux_capacitor'" "$T/unknown.err" \
	&& tap_ok "unknown register: exit 2" || tap_fail "unknown register: exit 2" "rc=$rc $(cat "$T/unknown.err")"

run missing --port "$bus" read 3 present_position
[ "$rc" -eq 4 ] && [ "$(lines "$T/missing.err")" = 1 ] \
	&& grep -q 'no reply from ID 3 at 1000000 bps; wrong baud or ID? try: dxl --port .* scan --bauds all' "$T/missing.err" \
	&& tap_ok "missing servo: exit 4 with a baud hint" || tap_fail "missing servo: exit 4 with a baud hint" "rc=$rc $(cat "$T/missing.err")"

run errbits --port "$bus" read 2 present_load
[ "$rc" -eq 5 ] && [ "$(cat "$T/errbits.out")" = "0" ] && grep -q 'ID 2 reports error bits 0x20: overload' "$T/errbits.err" \
	&& tap_ok "servo error bits: value printed, exit 5" || tap_fail "servo error bits: value printed, exit 5" "rc=$rc $(cat "$T/errbits.err")"

run noport --port "$T/no-such-port" ping 1
[ "$rc" -eq 3 ] && [ "$(lines "$T/noport.err")" = 1 ] && grep -q 'no-such-port.*No such file' "$T/noport.err" \
	&& tap_ok "no such port: exit 3" || tap_fail "no such port: exit 3" "rc=$rc $(cat "$T/noport.err")"

run scan --port "$bus" scan --ids 0-5
found=$(grep -cE '^[0-9]+ +12 +AX-12A +24 +1000000 +1\.0$' "$T/scan.out")
[ "$found" = 2 ] && tap_ok "scan finds both servos" || tap_fail "scan finds both servos" "$(cat "$T/scan.out" "$T/scan.err")"

run wrongbaud --port "$bus" --baud 57600 ping 1
[ "$rc" -eq 4 ] && grep -q 'at 57600 bps; wrong baud' "$T/wrongbaud.err" \
	&& tap_ok "wrong baud suspected" || tap_fail "wrong baud suspected" "rc=$rc $(cat "$T/wrongbaud.err")"

run setup --port "$bus" setup 1
[ "$rc" -eq 0 ] && grep -q 'return_delay_time set to 0' "$T/setup.out" && grep -q '^adapter: ' "$T/setup.out" \
	&& tap_ok "setup: return delay 0, adapter reported" || tap_fail "setup: return delay 0, adapter reported" "rc=$rc $(cat "$T/setup.out" "$T/setup.err")"
run delay --port "$bus" read 1 return_delay_time
[ "$(cat "$T/delay.out")" = "0" ] && tap_ok "setup persisted" || tap_fail "setup persisted" "$(cat "$T/delay.out")"

# The bus vanishing (simulator stopped) reads as a lost port, not a missing servo.
stop fake >/dev/null
run gone --port "$bus" ping 1
[ "$rc" -eq 3 ] && tap_ok "bus gone (fake stopped, link removed): exit 3" || tap_fail "bus gone (fake stopped, link removed): exit 3" "rc=$rc $(cat "$T/gone.err")"

tap_done
