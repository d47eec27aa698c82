#!/usr/bin/env bash
# undulated with 18 servos on one simulated bus at 1 Mbps, return delay 0:
# the cycle's reads (18 x ~240 us) and SYNC_WRITE fit the 10 ms period, but
# the start-up's torque-on (torque limit + torque enable per servo, 36 writes
# with replies) does not fit after them. The writes that do not fit must wait
# for the next cycle and be sent once: before, the queue was cut off at every
# tick and sent again from its start, so it never finished, every cycle
# overran, and the cut-off replies collided with the next cycle's first READ.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
R="b$$"
URL=$(lcm_url 7705)
ids=$(seq -s, 1 18)
ctl() { echo "$*" | socat -t 2 - UNIX-CONNECT:"$T/ctl"; }
field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }
states() { grep "^STATE $R " "$T/watch.log"; }
cycle_at_least() { [ "$(states | tail -1 | field cycle)" -ge "$1" ] 2>/dev/null; }

spawn sim "$S" --link "$T/bus" --ids "$ids" --name r1 --return-delay 0 --lcm-url "$URL" --control "$T/ctl"
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --lcm-url "$URL"
spawn d "$D" --port "$T/bus" --ids "$ids" --robot "$R" --lcm-url "$URL" --mode hold
wait_log d "ready: $R.STATE" 10 || { tap_fail "daemon starts with 18 servos" "$(cat "$T/d.log")"; tap_done; exit 1; }
wait_for 5 cycle_at_least 300
s=$(states | tail -1)
on=0
for id in $(seq 1 18); do [ "$(ctl peek r1 "$id" torque_enable)" = "ok 1" ] && on=$((on + 1)); done
if [ "$on" = 18 ]; then tap_ok "torque on for all 18 servos"; else tap_fail "torque on for all 18 servos" "$on of 18"; fi
# Not a timing test (the benchmarks measure timing): a loaded machine may cut
# off a few cycles; the failure this guards against cut off every one of them
# (about 300 overruns and 700 bus errors in these 3 s, torque never on for all).
ov=$(echo "$s" | field overruns); be=$(echo "$s" | field bus_errors)
cut=$(grep -c 'still on the bus' "$T/d.log")
if [ "$ov" -lt 30 ] && [ "$be" -lt 30 ] && [ "$cut" -lt 30 ]; then
	tap_ok "300 cycles at 100 Hz keep up: $ov overrun(s), $be bus error(s), $cut cycle(s) cut off"
else tap_fail "18 servos keep up" "overruns $ov, bus errors $be, $cut cycles cut off by the next tick"; fi
bus=$(states | tail -100 | field bus | sort -n | awk '{ a[NR] = $1 } END { print a[int(NR / 2) + 1] }')
echo "# bus time per cycle p50 $bus us (wire floor 4220 us)"
tap_done
