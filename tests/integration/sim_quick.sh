#!/usr/bin/env bash
# sim_quick.sh — undulate-sim's quick form seen from a raw client on the
# link: the manual's golden bytes, reply timing, motion toward a goal, the
# broadcast PING collision, a wrong-baud bus, --duration and SIGTERM exits
# with their clean-up, and ground truth on LCM.
. "$(dirname "$0")/../lib.sh"
# one interpreter for the whole test (tests/lib.sh, py_start)
py_start sim "$top/tests/integration/sim_client.py" SIM_CLIENT_BAUD
C="py_call sim"
URL=$(lcm_url 7650)
link="$T/bus/r1"

spawn logger lcm-logger --lcm-url="$URL" -f "$T/truth.lcmlog"
spawn sim "$B/undulate-sim" --link "$link" --ids 0,1 --temperature 32 --lcm-url "$URL" \
	--control "$T/ctl" --seed 3
if wait_log sim 'undulate-sim: ready: 1 bus: r1=' 5; then tap_ok "ready line names the bus"; else
	tap_fail "ready line names the bus" "$(cat "$T/sim.log")"; touch "$T/plainfile"
"$B/undulate-sim" --link "$T/plainfile" --ids 1 --lcm-url "$URL" --duration 1 >"$T/bad.log" 2>&1; rc=$?
if [ "$rc" = 1 ] && grep -q 'not a symlink' "$T/bad.log" && [ -f "$T/plainfile" ] && [ ! -L "$T/plainfile" ]; then
	tap_ok "never replaces a file that is not a symlink"; else tap_fail "never replaces a plain file" "rc $rc: $(cat "$T/bad.log")"; fi
tap_done; exit; fi
tap_check "link is a symlink to a pty" test -L "$link" -a -c "$(readlink "$link")"

# xfer HEX [timeout_ms] [expect_bytes] -> $reply, $rtt
xfer() { read -r reply rtt < <($C xfer "$link" "$@"); }

# ---- the manual's examples, byte for byte --------------------------------------
expect_reply "golden PING id 1" FFFF010201FB FFFF010200FC
# Wire 60 µs + factory return delay 500 µs + 60 µs reply: never earlier.
if [ "$rtt" -ge 600 ] && [ "$rtt" -lt 20000 ]; then tap_ok "PING answered after wire time + return delay ($rtt us)"
else tap_fail "PING answered after wire time + return delay" "rtt $rtt us"; fi
expect_reply "golden READ temperature (32 C)" FFFF0104022B01CC FFFF01030020DB
# The e-manual's checksum example writes 0x64 0xAA at address 12: its max
# voltage limit 170 is outside the AX-12A's 50-160, so it gets the range bit
# (more of the manuals' examples: sim_manual.sh).
expect_reply "golden WRITE addr 12 = 64 AA: the range bit (170 > 160)" FFFF0105030C64AADC FFFF010208F4
expect_reply "...nothing stored" "$(pkt 1 2 12 2)" "$(status 1 0 60 140)"
expect_reply "golden WRITE goal position 512" FFFF0105031E0002D6 FFFF010200FC
expect_silence "golden SYNC_WRITE ids 0,1: no reply" FFFFFE0E831E040010005001012002600367
expect_reply "SYNC_WRITE reached id 0" "$(pkt 0 2 30 4)" "$(status 0 0 0x10 0x00 0x50 0x01)"
expect_reply "SYNC_WRITE reached id 1" "$(pkt 1 2 30 4)" "$(status 1 0 0x20 0x02 0x60 0x03)"
expect_reply "REG_WRITE goal 0x300" "$(pkt 1 4 30 0x00 0x03)" "$(status 1 0)"
expect_reply "...registered" "$(pkt 1 2 44 1)" "$(status 1 0 1)"
expect_silence "golden ACTION broadcast: no reply" FFFFFE0205FA
expect_reply "ACTION applied the goal" "$(pkt 1 2 30 2)" "$(status 1 0 0x00 0x03)"
expect_reply "range error: status return level 3" "$(pkt 1 3 16 3)" "$(status 1 8)"
expect_reply "read-only present position" "$(pkt 1 3 36 0 0)" "$(status 1 8)"

# ---- the motor follows the goal ---------------------------------------------------
expect_reply "torque on" "$(pkt 1 3 24 1)" "$(status 1 0)"
expect_reply "goal 700 at full speed" "$(pkt 1 3 30 0xBC 0x02 0 0)" "$(status 1 0)"
reached() {
	xfer "$(pkt 1 2 36 2)" 300 8
	local pos=$(( 16#${reply:12:2}${reply:10:2} ))
	[ "$pos" -ge 697 ] && [ "$pos" -le 703 ]
}
if wait_for 3 reached; then tap_ok "present position reaches the goal"; else tap_fail "present position reaches the goal" "last $reply"; fi

# ---- broadcast PING: every servo answers at once, the bytes collide -----------------
xfer FFFFFE0201FE 50 6
if [ "$reply" != "-" ] && [ "$reply" != FFFF000200FD ] && [ "$reply" != FFFF010200FC ]; then
	tap_ok "broadcast PING replies collide ($reply)"
else tap_fail "broadcast PING replies collide" "got $reply"; fi

# ---- golden broadcast "set ID to 1": both servos become ID 1 --------------------------------
expect_silence "golden broadcast WRITE ID=1: no reply" FFFFFE04030301F6
expect_silence "no servo 0 any more" FFFF000201FC
# Their positions differ (one moved to 700): two READ replies on top of each other.
xfer "$(pkt 1 2 36 2)" 100 8
if [ "$reply" != - ] && [ "$($C check "$reply")" = invalid ]; then tap_ok "two servos with ID 1 answer at once: garbage ($reply)"
else tap_fail "two servos with ID 1 collide" "got $reply"; fi

# ---- ground truth ---------------------------------------------------------------
# The rate over the log's own span, first to last SIM.TRUTH by the logger's
# timestamps, once that span is 2 s or more (it usually is by now).
truth_rate() {
	read -r ntruth span hz < <($C rate "$T/truth.lcmlog" SIM.TRUTH)
	awk -v s="${span:-0}" 'BEGIN { exit !(s >= 2) }'
}
ntruth=0 span=0 hz=0
wait_for 10 truth_rate
# The simulator publishes on a 10 ms schedule and drops, never catches up, a
# message more than a period late, so load can only lower the rate: 10 %
# either way catches a wrong period (50 and 130 Hz fail) with room for load.
if awk -v s="$span" -v h="$hz" 'BEGIN { exit !(s >= 2 && h >= 90 && h <= 110) }'; then
	tap_ok "SIM.TRUTH at 100 Hz: $hz Hz ($ntruth messages over $span s of the log)"
else tap_fail "SIM.TRUTH at 100 Hz (90-110)" "$hz Hz: $ntruth messages over $span s of the log"; fi

# ---- SIGTERM: clean exit, link and socket removed, summary printed ---------------------
stop sim TERM >"$T/rc"; rc=$(cat "$T/rc")  # not $(stop): wait needs this shell
tap_check "SIGTERM exits 0" test "$rc" = 0
tap_check "link removed on exit" test ! -e "$link" -a ! -L "$link"
tap_check "control socket removed on exit" test ! -e "$T/ctl"
if grep -qE 'undulate-sim: exit: .* collisions, total impulse .* worst step lateness' "$T/sim.log"; then
	tap_ok "exit summary printed"; else tap_fail "exit summary printed" "$(tail -3 "$T/sim.log")"; fi

# ---- --duration and a servo at another baud ----------------------------------------------
link2="$T/bus/slow"
spawn sim2 "$B/undulate-sim" --link "$link2" --ids 1 --name slow --set "robot slow.servo_baud=3" \
	--duration 4 --lcm-url "$URL"   # long enough for three exchanges on a loaded machine (SAN build)
wait_log sim2 'ready:' 5
xfer() { read -r reply rtt < <($C xfer "$link2" "$@"); }
expect_silence "servo at 500 kbps ignores a 1 Mbps PING" FFFF010201FB
export SIM_CLIENT_BAUD=500000
xfer FFFF010201FB 300 6
tap_check "...and answers when the controller sets the pty to 500 kbps" test "$reply" = FFFF010200FC
unset SIM_CLIENT_BAUD
t0=$(date +%s%N)
wait_for 10 bash -c "! kill -0 $pid_sim2 2>/dev/null"
stop sim2 >"$T/rc"; rc=$(cat "$T/rc")
ms=$(( ($(date +%s%N) - t0) / 1000000 ))
tap_check "--duration exits by itself with 0" test "$rc" = 0
tap_check "--duration removed its link" test ! -e "$link2" -a ! -L "$link2"
grep -q "1 wrong-baud" "$T/sim2.log" && tap_ok "wrong-baud packet counted" || tap_fail "wrong-baud packet counted" "$(cat "$T/sim2.log")"

# ---- single-wire echo and a 16 ms USB adapter ----------------------------------------------
link3="$T/bus/ftdi"
spawn sim3 "$B/undulate-sim" --link "$link3" --ids 1 --echo --latency-ms 16 --lcm-url "$URL"
wait_log sim3 'ready:' 5
read -r reply rtt < <($C xfer "$link3" FFFF010201FB 300 12)
tap_check "echo: the request comes back before the reply" test "$reply" = FFFF010201FBFFFF010200FC
if [ "$rtt" -ge 16000 ]; then tap_ok "adapter latency: nothing before 16 ms ($rtt us)"; else tap_fail "adapter latency" "first byte after $rtt us"; fi
stop sim3 >"$T/rc"

# ---- a stall: the simulator says that its servos stopped with it -----------------------------
# (a machine too busy for the physics: stopped here with SIGSTOP for 0.4 s)
spawn sim4 "$B/undulate-sim" --link "$T/bus/stall" --ids 1 --lcm-url "$URL"
wait_log sim4 'ready:' 5
kill -STOP "$pid_sim4"; sleep 0.4; kill -CONT "$pid_sim4"
if wait_log sim4 'fell behind real time: simulated time stopped for [0-9.]+ ms' 5; then
	tap_ok "a stall is said: $(grep -o 'stopped for [0-9.]* ms' "$T/sim4.log" | head -1)"
else tap_fail "a stall of 0.4 s is said" "$(cat "$T/sim4.log")"; fi
stop sim4 >"$T/rc"
lost=$(sed -n 's/.*overruns (simulated time stopped \([0-9.]*\) ms).*/\1/p' "$T/sim4.log")
if awk -v l="${lost:-0}" 'BEGIN { exit !(l >= 300 && l <= 1000) }'; then
	tap_ok "the summary counts the simulated time lost: $lost ms (0.4 s stopped, 50 steps caught up)"
else tap_fail "summary: simulated time lost 300..1000 ms" "$(grep exit: "$T/sim4.log")"; fi

# ---- bad configuration: a clear message, exit 2 -----------------------------------------------
"$B/undulate-sim" --link "$T/x" --ids 1,1 >"$T/bad.log" 2>&1; rc=$?
if [ "$rc" = 2 ] && grep -q 'ids' "$T/bad.log"; then tap_ok "duplicate IDs refused"; else tap_fail "duplicate IDs refused" "rc $rc: $(cat "$T/bad.log")"; fi
"$B/undulate-sim" --link "$T/x" --ids 1 --set world.restitution=2 >"$T/bad.log" 2>&1; rc=$?
if [ "$rc" = 2 ] && grep -q 'restitution' "$T/bad.log"; then tap_ok "bad --set refused"; else tap_fail "bad --set refused" "rc $rc: $(cat "$T/bad.log")"; fi
touch "$T/plainfile"
"$B/undulate-sim" --link "$T/plainfile" --ids 1 --lcm-url "$URL" --duration 1 >"$T/bad.log" 2>&1; rc=$?
if [ "$rc" = 1 ] && grep -q 'not a symlink' "$T/bad.log" && [ -f "$T/plainfile" ] && [ ! -L "$T/plainfile" ]; then
	tap_ok "never replaces a file that is not a symlink"; else tap_fail "never replaces a plain file" "rc $rc: $(cat "$T/bad.log")"; fi
tap_done
