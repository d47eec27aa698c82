#!/usr/bin/env bash
# safety_bus — one owner per bus (the audit's finding 8). While undulated
# drives a bus: a second undulated (another robot name) on the same port is
# refused with the holder named and the first keeps its bus without a new
# error; dxl (scan, read through another path to the same pty, doctor) is
# refused and told how to reach the servos instead; a second undulate-sim
# on the same --link is refused and the first's link survives its exit.
# After a SIGKILL the port and the link are free again (no stale lock); a
# daemon takes its port again when the bus comes back; a UUCP lock file
# (LCK..name, minicom's kind) of a live program is honoured.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"; X="$B/dxl"
if [ ! -x "$S" ] || [ ! -x "$D" ] || [ ! -x "$X" ]; then
	tap_skip_all "undulate-sim, undulated or dxl not built"
fi
R="u$$"
URL=$(lcm_url 7712)
bus="$T/bus"

# exits NAME S: the spawned process NAME ends within S seconds; its status in $rc.
# A program that was not refused keeps running: it is stopped, rc=running.
exits() {
	local var="pid_${1//[^A-Za-z0-9_]/_}"
	if wait_for "$2" sh -c "! kill -0 ${!var} 2>/dev/null"; then
		rc=0; wait "${!var}" 2>/dev/null || rc=$?
	else
		stop "$1" >/dev/null; rc=running
	fi
}
# dxl_run NAME ARGS...: dxl with its output in $T/NAME.{out,err}, status in $rc
dxl_run() {
	local name=$1; shift
	rc=0
	timeout 30 "$X" --timeout-ms 100 "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
}
errors() { last_state | field bus_errors; }
# Servo 3 is on the bus but not the robot's: only the programs refused below
# would address it (the second daemon and dxl ask for it). It hearing no
# instruction shows that none of their bytes reached the bus, however loaded
# the machine (where the daemon's own late replies can count bus errors).
heard3() { ctl servo r1 3 | sed -n 's/.* instructions=\([0-9]*\).*/\1/p'; }

spawn sim "$S" --link "$bus" --ids 1,2,3 --name r1 --lcm-url "$URL" --control "$T/ctl" --seed 3
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
pts=$(readlink "$bus")
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
spawn d1 "$D" --port "$bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode sinusoid
wait_log d1 "ready: $R.STATE" 10 || { tap_fail "daemon starts" "$(cat "$T/d1.log")"; tap_done; exit 1; }
wait_for 10 cycle_at_least 100
e0=$(errors)
holder="held by undulated \(pid $pid_d1, robot $R\)"

# ---- a second daemon, another robot name, the same port
spawn d2 "$D" --port "$bus" --ids 1,2,3 --robot "${R}b" --lcm-url "$URL" --mode sinusoid
exits d2 5
if [ "$rc" = 1 ] && grep -qE "cannot open $bus: $holder" "$T/d2.log"; then
	tap_ok "a second undulated on the port is refused (exit 1, $(grep -o 'held by [^:]*' "$T/d2.log" | head -1))"
else tap_fail "a second undulated is refused, naming the holder" "rc=$rc; $(tail -3 "$T/d2.log")"; fi

# ---- dxl beside the daemon: refused, and told how to reach the bus
dxl_run scan --port "$bus" scan --ids 1-4
if [ "$rc" = 3 ] && grep -qE "$holder" "$T/scan.err" && grep -qF "undulated --watch $R" "$T/scan.err" &&
	grep -qF "systemctl stop undulated@$R" "$T/scan.err" && [ ! -s "$T/scan.out" ]; then
	tap_ok "dxl scan beside the daemon: refused (exit 3), names the holder, says: undulated --watch $R, or stop the robot"
else tap_fail "dxl scan refused beside the daemon" "rc=$rc; $(cat "$T/scan.err" "$T/scan.out" | head -8)"; fi
# another path to the same pty: the lock is the device's, not the name's
ln -s "$pts" "$T/alias"
dxl_run read --port "$T/alias" read 3 present_position
if [ "$rc" = 3 ] && grep -qE "$holder" "$T/read.err" && [ ! -s "$T/read.out" ]; then
	tap_ok "dxl read through another path to the same pty: refused"
else tap_fail "dxl read through another path refused" "rc=$rc; $(cat "$T/read.err" "$T/read.out" | head -5)"; fi
dxl_run doctor --port "$bus" doctor 1 2 3 --cycles 50
if [ "$rc" = 3 ] && grep -qE "$holder" "$T/doctor.err"; then tap_ok "dxl doctor beside the daemon: refused"
else tap_fail "dxl doctor refused beside the daemon" "rc=$rc; $(cat "$T/doctor.err" | head -5)"; fi

# ---- a second simulator on the same link
spawn sim2 "$S" --link "$bus" --ids 1,2,3 --name r2 --lcm-url "$URL" --seed 4 --control "$T/ctl"
exits sim2 5
if [ "$rc" = 1 ] && grep -qE "$bus: held by undulate-sim \(pid $pid_sim[,)]" "$T/sim2.log"; then
	tap_ok "a second undulate-sim on a live link is refused (exit 1, names the first)"
else tap_fail "a second undulate-sim on a live link is refused" "rc=$rc; $(tail -3 "$T/sim2.log")"; fi
if [ "$(readlink "$bus")" = "$pts" ] && ctl list | grep -q "^ok"; then
	tap_ok "the first simulator's link and control socket survive the second's exit"
else tap_fail "the first simulator's link survives" "link now: '$(readlink "$bus")', was $pts; ctl: $(ctl list)"; fi

# ---- the first daemon never noticed
c=$(last_state | field cycle)
wait_for 10 cycle_at_least $((c + 100))
e1=$(errors)
h3=$(heard3)
# (a second master gave hundreds of bus errors in this time: 403 measured,
# the audit 458 -> 756; the numbers are printed, not asserted: see heard3)
if alive d1 && [ "$h3" = 0 ] && ! events | grep -q 'kind=bus-lost'; then
	tap_ok "the daemon kept its bus: running, no bus-lost, no byte of the refused programs on the bus (bus errors $e0 -> $e1)"
else tap_fail "the daemon kept its bus" "alive=$(alive d1 && echo yes); servo 3 heard '$h3' instructions; bus errors $e0 -> $e1; $(events | grep bus-lost | head -2)"; fi

# ---- SIGKILL: no stale lock (refused before, taken after)
stop d1 KILL >/dev/null
dxl_run ping1 --port "$bus" ping 1
if grep -qE "$holder" "$T/scan.err" && [ "$rc" = 0 ]; then
	tap_ok "after the daemon is SIGKILLed, dxl takes the port (its lock file left behind is stale)"
else tap_fail "the port is free after SIGKILL" "rc=$rc; $(cat "$T/ping1.err")"; fi

# ---- a UUCP lock file of a live program (minicom writes them) is honoured
lck="$T/LCK..$(echo "${pts#/dev/}" | tr / _)"
spawn foreign sleep 300
# until it has exec'd, the process is still "setsid": a lock file naming
# "sleep" would read as a pid reused by another program (stale), and dxl
# would rightly take the port (it did once, in a loaded make test)
wait_for 10 bash -c "[ \"\$(cat /proc/$pid_foreign/comm 2>/dev/null)\" = sleep ]"
printf '%10d sleep\n' "$pid_foreign" >"$lck"
dxl_run uucp --port "$bus" ping 1
rc_uucp=$rc
printf '%10d\n' "$pid_foreign" >"$lck"
dxl_run hdb --port "$bus" ping 1
rc_hdb=$rc
# what each run said and whether the holder still lived: printed on failure
alive_hdb=$(alive foreign && echo alive || echo gone)
stop foreign >/dev/null
dxl_run uucp2 --port "$bus" ping 1
if [ "$(cat "$T/uucp.err" "$T/hdb.err" | grep -cE "held by sleep \(pid $pid_foreign, lock file $lck\)")" = 2 ] &&
	[ "$rc" = 0 ] && [ ! -e "$lck" ]; then
	tap_ok "a UUCP lock file naming a live program refuses dxl; once that program is gone dxl takes the port and removes its own"
else tap_fail "UUCP lock files honoured" "rc uucp=$rc_uucp hdb=$rc_hdb uucp2=$rc; holder after hdb: $alive_hdb; $(cat "$T/uucp.err" "$T/hdb.err" "$T/hdb.out" "$T/uucp2.err"; ls "$T" | grep LCK)"; fi

# ---- a daemon takes its port again when the bus comes back
mark_states
spawn d3 "$D" --port "$bus" --ids 1,2 --robot "$R" --lcm-url "$URL" --mode sinusoid
wait_restarted 50 || { tap_fail "daemon restarts" "$(tail -5 "$T/d3.log")"; tap_done; exit 1; }
ctl disconnect r1 >/dev/null
wait_for 5 sh -c "grep -a '^EVENT $R .*kind=bus-lost' '$T/watch.log' | grep -q ."
ctl reconnect r1 >/dev/null
wait_for 5 sh -c "grep -a '^EVENT $R .*kind=bus-back' '$T/watch.log' | grep -q ."
dxl_run again --port "$bus" ping 1
if events | grep -q 'kind=bus-back' && [ "$rc" = 3 ] && grep -qE "held by undulated \(pid $pid_d3, robot $R\)" "$T/again.err"; then
	tap_ok "after a reconnect the daemon holds its port again"
else tap_fail "the port held again after a reconnect" "rc=$rc; $(cat "$T/again.err"); $(events | tail -2)"; fi

# ---- a killed simulator's link is replaced by the next simulator
# The daemon is paused while no simulator is there: the killed one's link
# still names its pty, whose number the next pty made on this machine gets —
# another test's simulator, beside this one — and the daemon, retrying the
# path, took that bus (seen: "held by undulated (..., robot u12137)" in
# e2e_pair). The claim is the link's replacement and the daemon's return.
kill -STOP "$pid_d3"
stop sim KILL >/dev/null
spawn sim3 "$S" --link "$bus" --ids 1,2,3 --name r1 --lcm-url "$URL" --seed 5
wait_log sim3 'ready' 10
kill -CONT "$pid_d3"
if wait_log sim3 'ready' 10 && wait_for 10 sh -c "grep -a '^EVENT $R .*kind=bus-back' '$T/watch.log' | wc -l | grep -q '^2$'"; then
	tap_ok "a SIGKILLed simulator's link is replaced by the next one, and the daemon comes back on it"
else tap_fail "a killed simulator's link is replaced" "$(tail -3 "$T/sim3.log"); link $(readlink "$bus"); $(events | tail -2)"; fi
stop d3 >/dev/null
stop sim3 >/dev/null
if [ ! -e "$bus" ] && [ ! -L "$bus" ] && [ ! -e "$bus.lock" ]; then tap_ok "the simulator removes its link and its lock file at exit"
else tap_fail "link and lock file removed at exit" "$(ls -l "$T" | grep bus)"; fi
tap_done
