#!/usr/bin/env bash
# dxl_sim — the `dxl` program against the simulated bus (undulate-sim): it
# finds the servos, prepares them for 100 Hz, moves one, and reports the bus
# vanishing mid-command (the simulator stopping) as a lost port, exit 3.
. "$(dirname "$0")/../lib.sh"

bus="$T/bus"
url=$(lcm_url 7610)

# Replies get 100 ms: the simulator is a process a loaded machine may not
# schedule within even the one-shot commands' 50 ms (scan's deadline is shorter).
run() {
	local name=$1; shift
	rc=0
	timeout 30 "$dxl" --timeout-ms 100 "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
}

dxl_sim_built

spawn sim "$sim" --link "$bus" --ids 1,2 --lcm-url "$url" --quiet
if wait_log sim 'ready' 10; then tap_ok "simulator ready"; else tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit; fi

run scan --port "$bus" scan --ids 0-4
found=$(grep -cE '^[12] +12 +AX-12A +[0-9]+ +1000000 +1\.0$' "$T/scan.out")
[ "$rc" -eq 0 ] && [ "$found" = 2 ] && [ "$(wc -l <"$T/scan.out")" -eq 3 ] \
	&& tap_ok "scan finds exactly IDs 1 and 2" || tap_fail "scan finds exactly IDs 1 and 2" "rc=$rc $(cat "$T/scan.out" "$T/scan.err")"

run setup --port "$bus" setup 1 2
run delay1 --port "$bus" read 1 return_delay_time
run delay2 --port "$bus" read 2 return_delay_time
[ "$(cat "$T/delay1.out")" = 0 ] && [ "$(cat "$T/delay2.out")" = 0 ] && grep -q '^adapter: ' "$T/setup.out" \
	&& tap_ok "setup sets return delay 0 on both servos" \
	|| tap_fail "setup sets return delay 0 on both servos" "$(cat "$T/setup.out" "$T/setup.err")"

run torque --port "$bus" torque 1 on
run goal --port "$bus" write 1 goal_position 700
# The simulated motor needs a moment to get there: poll, don't sleep.
at_goal() { run pos --port "$bus" read 1 present_position; [ "$rc" -eq 0 ] && [ "$(cat "$T/pos.out")" -ge 690 ]; }
if wait_for 10 at_goal; then tap_ok "write goal_position moves the simulated joint"
else tap_fail "write goal_position moves the simulated joint" "present $(cat "$T/pos.out")"; fi

run bad --port "$bus" write 1 goal_position 1024
[ "$rc" -eq 2 ] && tap_ok "out-of-range goal refused before the bus (exit 2)" || tap_fail "out-of-range goal refused (exit 2)" "rc=$rc"

run missing --port "$bus" ping 9
[ "$rc" -eq 4 ] && grep -q 'no reply from ID 9' "$T/missing.err" \
	&& tap_ok "absent ID: exit 4" || tap_fail "absent ID: exit 4" "rc=$rc $(cat "$T/missing.err")"

# A long scan (every baud, every ID) while the simulator stops.
timeout 60 "$dxl" --port "$bus" scan --bauds all >"$T/long.out" 2>"$T/long.err" &
scanpid=$!
# Ready when the scan (timeout's child) holds the pty open.
holds_bus() {
	local p
	for p in $(pgrep -P "$scanpid"); do
		ls -l "/proc/$p/fd" 2>/dev/null | grep -q -- "-> $(readlink "$bus")\$" && return 0
	done
	return 1
}
wait_for 10 holds_bus || tap_fail "long scan started" "no dxl process holds $(readlink "$bus")"
stop sim >/dev/null
scanrc=0
wait "$scanpid" || scanrc=$?
[ "$scanrc" -eq 3 ] && grep -q 'went away' "$T/long.err" \
	&& tap_ok "simulator stopping mid-scan: exit 3, 'went away'" \
	|| tap_fail "simulator stopping mid-scan: exit 3, 'went away'" "rc=$scanrc $(cat "$T/long.err")"

tap_done
