#!/usr/bin/env bash
# dxl_late — how long `dxl` waits for a reply, and what it says when none
# came in time. One-shot commands (read, ping, ...) wait as a person would
# (tens of milliseconds), so a servo behind an adapter that holds bytes
# 20 ms (undulate-sim --latency-ms) is read; a reply later than that is
# named as late, with how late, not as "no reply ... wrong baud or ID?";
# `scan` keeps its fast deadline per ID and rate.
. "$(dirname "$0")/../lib.sh"


dxl_sim_built

# No --timeout-ms here: the defaults are what is tested.
run() {
	local name=$1; shift
	rc=0
	timeout 30 "$dxl" "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
}

spawn slow "$sim" --link "$T/slow" --ids 1 --latency-ms 20 --lcm-url "$(lcm_url 7614)" --quiet
spawn late "$sim" --link "$T/late" --ids 1 --latency-ms 100 --lcm-url "$(lcm_url 7615)" --quiet
if wait_log slow 'ready' 10 && wait_log late 'ready' 10; then tap_ok "simulators ready"
else tap_fail "simulators ready" "$(cat "$T/slow.log" "$T/late.log")"; tap_done; exit; fi

run read --port "$T/slow" read 1 model_number
[ "$rc" -eq 0 ] && [ "$(cat "$T/read.out")" = 12 ] \
	&& tap_ok "read: a reply held 20 ms by the adapter is taken" \
	|| tap_fail "read: a reply held 20 ms by the adapter is taken" "rc=$rc $(cat "$T/read.out" "$T/read.err")"

run ping --port "$T/slow" ping 1
[ "$rc" -eq 0 ] && tap_ok "ping: the same" || tap_fail "ping: the same" "rc=$rc $(cat "$T/ping.out" "$T/ping.err")"

run lateread --port "$T/late" read 1 model_number
[ "$rc" -eq 4 ] && grep -qE 'reply from ID 1 came [0-9.]+ ms after' "$T/lateread.err" \
	&& grep -q 'is late, not missing' "$T/lateread.err" && ! grep -q 'wrong baud or ID' "$T/lateread.err" \
	&& tap_ok "read: a reply 100 ms late is named late, and how late (exit 4)" \
	|| tap_fail "read: a reply 100 ms late is named late, and how late (exit 4)" "rc=$rc $(cat "$T/lateread.err")"

run absent --port "$T/slow" read 9 model_number
[ "$rc" -eq 4 ] && grep -q 'no reply from ID 9' "$T/absent.err" && ! grep -q 'is late' "$T/absent.err" \
	&& tap_ok "read: an absent ID is still 'no reply' (exit 4)" \
	|| tap_fail "read: an absent ID is still 'no reply' (exit 4)" "rc=$rc $(cat "$T/absent.err")"

# 20 absent IDs at one rate: a few ms each at the scan's deadline, a second
# or more at the one-shot commands' (a clock bound: load only lengthens it).
t0=$(date +%s%N)
run scan --port "$T/slow" --protocol 1 scan --ids 3-22
ms=$(( ($(date +%s%N) - t0) / 1000000 ))
[ "$rc" -eq 4 ] && [ "$ms" -lt 700 ] \
	&& tap_ok "scan keeps its fast deadline: 20 absent IDs in $ms ms" \
	|| tap_fail "scan keeps its fast deadline: 20 absent IDs in < 700 ms" "rc=$rc ${ms} ms $(cat "$T/scan.err")"

tap_done
