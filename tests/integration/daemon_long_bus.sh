#!/usr/bin/env bash
# undulated with 18 servos on one simulated bus at 1 Mbps, return delay 0:
# the cycle's reads (18 x ~240 us) and SYNC_WRITE fit the 10 ms period, but
# the start-up's torque-on (torque limit + torque enable per servo, 36 writes
# with replies) does not fit after them. The writes that do not fit must wait
# for the next cycle and be sent once: before, the queue was cut off at every
# tick and sent again from its start, so it never finished.
# Behaviour only: every servo's torque comes on and every joint is read, and
# a LIMP reaches every servo, however loaded the machine. How much of the
# period the bus takes is timing: `make bench` measures it (the 18-servo row);
# the figures are printed here as comments.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
R="b$$"
URL=$(lcm_url 7705)
ids=$(seq -s, 1 18)

spawn sim "$S" --link "$T/bus" --ids "$ids" --name r1 --return-delay 0 --lcm-url "$URL" --control "$T/ctl"
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
spawn d "$D" --port "$T/bus" --ids "$ids" --robot "$R" --lcm-url "$URL" --mode hold
wait_log d "ready: $R.STATE" 10 || { tap_fail "daemon starts with 18 servos" "$(cat "$T/d.log")"; tap_done; exit 1; }
torque() { # VALUE: how many of the 18 servos have torque enable = VALUE
	local n=0 id
	for id in $(seq 1 18); do [ "$(ctl peek r1 "$id" torque_enable)" = "ok $1" ] && n=$((n + 1)); done
	echo "$n"
}
all_torque() { [ "$(torque "$1")" = 18 ]; }
if wait_for 20 all_torque 1; then tap_ok "torque on for all 18 servos"; else tap_fail "torque on for all 18 servos" "$(torque 1) of 18"; fi
wait_for 10 cycle_at_least 300
# every joint read within the last cycles (none stale for good)
s=$(states | tail -1)
stale=$(echo "$s" | tr ' ' '\n' | awk -F= '/^st[0-9]+=/ && $2 > 50 { n++ } END { print n + 0 }')
if [ "$stale" = 0 ]; then tap_ok "all 18 joints read (none stale for more than 50 cycles)"
else tap_fail "all 18 joints read" "$stale joint(s) stale: $(echo "$s" | tr ' ' '\n' | grep '^st' | tr '\n' ' ')"; fi
out=$("$D" --command 'mode limp' --robot "$R" --lcm-url "$URL" --timeout 2 2>&1)
if wait_for 20 all_torque 0; then tap_ok "LIMP reaches all 18 servos"; else tap_fail "LIMP reaches all 18" "$out; $(torque 0) of 18 off"; fi
ov=$(echo "$s" | field overruns); be=$(echo "$s" | field bus_errors)
bus=$(states | tail -100 | field bus | sort -n | awk '{ a[NR] = $1 } END { print a[int(NR / 2) + 1] }')
echo "# figures (timing, not asserted): $ov overrun(s), $be bus error(s), $(grep -c 'still on the bus' "$T/d.log") cycle(s) cut off; bus time per cycle p50 $bus us (wire floor 4220 us)"
tap_done
