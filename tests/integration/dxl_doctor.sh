#!/usr/bin/env bash
# dxl_doctor — `dxl doctor`, the first-run hardware check, against the
# simulated bus with one problem injected at a time: the factory return delay
# (500 us), a 16 ms adapter latency, a low supply voltage, a missing servo,
# servo angle limits narrower than the configuration. Each run must name the
# problem on the right line (WARN or FAIL) with its fix, and a clean bus must
# give nothing but OK lines and exit 0. Also: RS-485 mode asked for on a
# device that cannot do it (a pty) is one clear error, never a silent start,
# and an echo setting that does not match the wiring is named.
. "$(dirname "$0")/../lib.sh"


dxl_sim_built

# sim_up NAME PORT ARGS...: a simulator with servos 1 and 2 at $T/NAME.
sim_up() {
	local name=$1 port=$2; shift 2
	spawn "$name" "$sim" --link "$T/$name.bus" --ids 1,2 --lcm-url "$(lcm_url "$port")" --quiet "$@"
	wait_log "$name" 'ready' 10 || { tap_fail "$name: simulator ready" "$(cat "$T/$name.log")"; return 1; }
}

# robot_conf NAME IDS [EXTRA...]: the robot's configuration, as undulated reads it.
robot_conf() {
	local name=$1 ids=$2; shift 2
	{ printf '[robot]\nname = %s\nport = %s\nids = %s\n' "$name" "$T/$name.bus" "$ids"; printf '%s\n' "$@"; } >"$T/$name.conf"
}

# doctor NAME ARGS...: run dxl doctor; stdout in $T/NAME.out, stderr in $T/NAME.err, status in $rc.
# In a session of its own, as lib.sh's spawn runs programs under test: its
# timed cycles measure scheduling, and a session shared with CPU-bound work
# is scheduled late (lib.sh, spawn).
doctor() {
	local name=$1; shift
	rc=0
	${_own_session[@]+"${_own_session[@]}"} timeout 60 "$dxl" doctor "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
}
show() { cat "$T/$1.out" "$T/$1.err"; echo "exit $rc"; }
# line NAME LEVEL CHECK REGEX: the check's line has that level and matches REGEX.
line() { grep -E "^$2 +$3 " "$T/$1.out" | grep -qE -- "$4"; }

# ---- a clean bus: every check OK, exit 0 -------------------------------------------------
if sim_up clean 7760 --return-delay 0 --control "$T/ctl"; then
	robot_conf clean 1,2
	# Every check but the timed cycles: all OK, exit 0.
	doctor clean --config "$T/clean.conf" --cycles 0
	[ "$rc" -eq 0 ] && ! grep -qE '^(WARN|FAIL) ' "$T/clean.out" && line clean OK 'ID 1 return delay' '0 us' \
		&& line clean OK 'ID 2 voltage' '12\.0 V' && line clean OK latency 'ms' \
		&& tap_ok "clean bus: every line OK, exit 0" || tap_fail "clean bus: every line OK, exit 0" "$(show clean)"
	# The budget, measured on the daemon's own cycle: three figures, the floor,
	# the period. The timed cycles share the machine with whatever else runs:
	# beside CPU-bound work (make test-busy) the simulator's replies came late
	# and 10-15 of 664 transactions timed out, run after run — the doctor said
	# so (budget WARN, exit 1), and rightly: that bus was not clean then; at
	# load 20 cycles were cut off by the next tick as well. So the budget is
	# OK, or a WARN whose only causes are failed transactions below the FAIL
	# share and cycles cut off (printed); any other verdict fails.
	doctor clean --config "$T/clean.conf"
	budget_ok() {
		line clean "$1" budget 'p50 [0-9.]+ / p99 [0-9.]+ / max [0-9.]+ ms' && line clean "$1" budget 'wire floor [0-9.]+ ms' \
			&& line clean "$1" budget 'period 10 ms' && line clean "$1" budget '[0-9]+ cycles'
	}
	if budget_ok OK && [ "$rc" -eq 0 ]; then
		tap_ok "clean bus: the budget line gives p50/p99/max, the wire floor and the period (OK)"
	elif budget_ok WARN && [ "$rc" -eq 1 ] && [ "$(grep -cE '^(WARN|FAIL) ' "$T/clean.out")" = 1 ] &&
		grep -qE '^WARN +budget .*: [0-9]+ of [0-9]+ transactions failed, [0-9]+ cycle\(s\) cut off' "$T/clean.out"; then
		# a busy machine delays the simulated servos' replies and the loop's
		# ticks alike: failed transactions and cycles cut off by the next tick
		# are what the doctor must say then (a WARN, never a FAIL here)
		echo "# the timed cycles met a busy machine: $(grep -oE '[0-9]+ of [0-9]+ transactions failed, [0-9]+ cycle\(s\) cut off' "$T/clean.out")"
		tap_ok "clean bus: the budget line gives p50/p99/max, the wire floor and the period (WARN: a busy machine)"
	else
		tap_fail "clean bus: the budget line gives p50/p99/max, the wire floor and the period" "$(show clean)"
	fi
	# Torque is put back as it was found: off (asked through the simulator's
	# control socket, beside the bus).
	t1=$(ctl peek "$T/clean.bus" 1 torque_enable) t2=$(ctl peek "$T/clean.bus" 2 torque_enable)
	[ "$t1" = "ok 0" ] && [ "$t2" = "ok 0" ] && tap_ok "clean bus: torque left off as found" \
		|| tap_fail "clean bus: torque left off as found" "ID 1: $t1, ID 2: $t2"
	# Ctrl-C while the joints hold for the timed cycles: torque still put back,
	# the budget not claimed, exit 130.
	${_own_session[@]+"${_own_session[@]}"} timeout 60 "$dxl" doctor --config "$T/clean.conf" --cycles 5000 >"$T/int.out" 2>"$T/int.err" &
	dpid=$!
	torqued() { [ "$(ctl peek "$T/clean.bus" 1 torque_enable)" = "ok 1" ]; }
	if wait_for 20 torqued; then
		kill -INT "$dpid"; rc=0; wait "$dpid" || rc=$?
		t1=$(ctl peek "$T/clean.bus" 1 torque_enable) t2=$(ctl peek "$T/clean.bus" 2 torque_enable)
		[ "$rc" -eq 130 ] && line int SKIP budget 'interrupted after [0-9]+ of 5000 cycles' \
			&& [ "$t1" = "ok 0" ] && [ "$t2" = "ok 0" ] \
			&& tap_ok "interrupted in the timed cycles: torque put back, budget SKIP, exit 130" \
			|| tap_fail "interrupted in the timed cycles: torque put back, budget SKIP, exit 130" "$(show int; echo "ID 1: $t1, ID 2: $t2"; ctl servo "$T/clean.bus" 1; ctl servo "$T/clean.bus" 2)"
	else
		kill "$dpid" 2>/dev/null; wait "$dpid" 2>/dev/null
		tap_fail "interrupted in the timed cycles" "torque never came on: $(cat "$T/int.out" "$T/int.err")"
	fi
	stop clean >/dev/null
fi

# The checks below are the servos' and the adapter's: their runs skip the timed
# cycles (--cycles 0, a SKIP line that counts neither way), so that a machine
# too busy to serve the simulator in time cannot decide their exit status.
# The budget itself is checked on the clean bus above and with the latency.

# ---- the factory return delay (500 us) ---------------------------------------------------
if sim_up delay 7761; then
	doctor delay --port "$T/delay.bus" --cycles 0 1 2
	[ "$rc" -eq 1 ] && line delay WARN 'ID 1 return delay' '500 us' && line delay WARN 'ID 2 return delay' '500 us' \
		&& line delay WARN 'ID 1 return delay' "fix: dxl --port $T/delay.bus setup 1 2 --yes" \
		&& ! grep -qE '^FAIL ' "$T/delay.out" \
		&& tap_ok "return delay 500 us: WARN on each servo with the setup command, exit 1" \
		|| tap_fail "return delay 500 us: WARN on each servo with the setup command, exit 1" "$(show delay)"
	stop delay >/dev/null
fi

# ---- a 16 ms adapter latency (no sysfs on a pty: measured) -------------------------------
if sim_up latency 7762 --return-delay 0 --latency-ms 16; then
	doctor latency --port "$T/latency.bus" --cycles 100 1 2
	[ "$rc" -eq 7 ] && line latency FAIL latency '1[5-9]\.[0-9]+ ms' && line latency FAIL latency 'fix: ' \
		&& line latency FAIL budget '' \
		&& tap_ok "latency 16 ms: measured on the latency line, budget FAIL, exit 7" \
		|| tap_fail "latency 16 ms: measured on the latency line, budget FAIL, exit 7" "$(show latency)"
	stop latency >/dev/null
fi

# ---- a low supply voltage -------------------------------------------------------------------
if sim_up volt 7763 --return-delay 0 --voltage 7; then
	doctor volt --port "$T/volt.bus" --cycles 0 1 2
	[ "$rc" -eq 7 ] && line volt FAIL 'ID 1 voltage' '7\.0 V' && line volt FAIL 'ID 2 voltage' 'fix: ' \
		&& tap_ok "7 V supply: voltage FAIL on each servo with the fix, exit 7" \
		|| tap_fail "7 V supply: voltage FAIL on each servo with the fix, exit 7" "$(show volt)"
	stop volt >/dev/null
fi

# ---- a missing servo (the configuration asks for ID 3) -----------------------------------------
if sim_up missing 7764 --return-delay 0; then
	robot_conf missing 1,2,3
	doctor missing --config "$T/missing.conf" --cycles 0
	[ "$rc" -eq 7 ] && line missing FAIL 'ID 3' 'no reply' && line missing FAIL 'ID 3' 'scan --bauds all' \
		&& line missing OK 'ID 1 model' '12 \(AX-12A\)' && line missing OK 'ID 2 model' '12 \(AX-12A\)' \
		&& tap_ok "missing ID 3: FAIL naming it and the scan, the others checked, exit 7" \
		|| tap_fail "missing ID 3: FAIL naming it and the scan, the others checked, exit 7" "$(show missing)"
	stop missing >/dev/null
fi

# ---- servo angle limits narrower than the configuration -----------------------------------------
if sim_up limits 7765 --return-delay 0; then
	# The configuration allows neutral 0 +- 1.3 rad (raw 259..765, the daemon's own
	# conversion: whole units inside the limits); the servo is set to stop at 350..700.
	robot_conf limits 1,2 '[joint.1]' 'limit_min = -1.3' 'limit_max = 1.3'
	"$dxl" --port "$T/limits.bus" --timeout-ms 100 write 1 cw_angle_limit 350 >/dev/null 2>&1
	"$dxl" --port "$T/limits.bus" --timeout-ms 100 write 1 ccw_angle_limit 700 >/dev/null 2>&1
	doctor limits --config "$T/limits.conf" --cycles 0
	[ "$rc" -eq 1 ] && line limits WARN 'ID 1 angle limits' '350\.\.700' \
		&& line limits WARN 'ID 1 angle limits' 'write 1 cw_angle_limit 259' \
		&& line limits WARN 'ID 1 angle limits' 'write 1 ccw_angle_limit 765' \
		&& line limits OK 'ID 2 angle limits' '' \
		&& tap_ok "narrower servo limits: WARN with both limits and the writes, exit 1" \
		|| tap_fail "narrower servo limits: WARN with both limits and the writes, exit 1" "$(show limits)"
	# RS-485 mode on a pty: the driver refuses TIOCSRS485; one clear error, exit 3.
	doctor rs485 --port "$T/limits.bus" --rs485 rts-on-send 1
	[ "$rc" -eq 3 ] && grep -q "RS-485" "$T/rs485.out" "$T/rs485.err" \
		&& grep -q "$T/limits.bus" "$T/rs485.err" && grep -q 'Inappropriate ioctl' "$T/rs485.err" \
		&& tap_ok "--rs485 on a pty: refused, naming the port and errno, exit 3" \
		|| tap_fail "--rs485 on a pty: refused, naming the port and errno, exit 3" "$(show rs485)"
	stop limits >/dev/null
fi

# ---- the wiring against the echo setting --------------------------------------------------------
if sim_up echo 7766 --return-delay 0 --echo; then
	doctor echo --port "$T/echo.bus" --cycles 0 1 2
	[ "$rc" -eq 1 ] && line echo WARN echo 'our own request came back' && line echo WARN echo 'fix: echo = true' \
		&& line echo OK 'ID 2 model' '12 \(AX-12A\)' \
		&& tap_ok "an echoing wiring without echo: WARN with the fix, exit 1" \
		|| tap_fail "an echoing wiring without echo: WARN with the fix, exit 1" "$(show echo)"
	doctor echoon --port "$T/echo.bus" --echo --cycles 0 1 2
	[ "$rc" -eq 0 ] && ! grep -qE '^(WARN|FAIL) ' "$T/echoon.out" && line echoon OK adapter 'echo cancelling on' \
		&& tap_ok "the same wiring with --echo: all OK, exit 0" || tap_fail "the same wiring with --echo: all OK, exit 0" "$(show echoon)"
	stop echo >/dev/null
fi
if sim_up noecho 7767 --return-delay 0; then
	doctor noecho --port "$T/noecho.bus" --echo --cycles 0 1 2
	[ "$rc" -eq 7 ] && line noecho FAIL echo 'the wiring does not echo' && line noecho FAIL 'ID 1 ping' 'see the echo line' \
		&& tap_ok "echo on where the wiring has none: FAIL naming it, exit 7" \
		|| tap_fail "echo on where the wiring has none: FAIL naming it, exit 7" "$(show noecho)"
	stop noecho >/dev/null
fi

# ---- bad input ------------------------------------------------------------------------------------
printf '[robot]\nids = 1,2\nbaud = fast\n' >"$T/bad.conf"
doctor badconf --config "$T/bad.conf" --port /nonexistent
[ "$rc" -eq 2 ] && grep -q "bad.conf:3: \[robot\] baud: not an integer 'fast'" "$T/badconf.err" \
	&& tap_ok "a bad configuration: its line named, exit 2" || tap_fail "a bad configuration: its line named, exit 2" "$(show badconf)"
doctor noport 1 2
[ "$rc" -eq 2 ] && grep -q 'needs --port' "$T/noport.err" \
	&& tap_ok "no port and no configuration: usage, exit 2" || tap_fail "no port and no configuration: usage, exit 2" "$(show noport)"

tap_done
