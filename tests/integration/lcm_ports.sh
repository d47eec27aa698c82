#!/usr/bin/env bash
# lcm_ports.sh — every test its own LCM ports: the tests run side by side
# (tests/run.sh), and two that share a multicast port hear each other (a full
# run once failed sim_world on sim_scenario_file's robot 'a', both on 7652).
# The ports a script names — `lcm_url N`, `lcm_port N`, and the span of
# FIG_PORT_LO=$(lcm_port N) FIG_PORT_SPAN=K — are read from the scripts, and
# none may be named by two of them.
. "$(dirname "$0")/../lib.sh"
dir=$(dirname "$0")
claims=$(for f in "$dir"/*.sh "$top"/tests/long/*.sh; do
	[ -f "$f" ] || continue
	n=${f##*/}
	grep -o 'lcm_\(url\|port\) [0-9]\+' "$f" | awk -v n="$n" '{ print $2, n }'
	# a figure driver's span: FIG_PORT_LO=$(lcm_port N) with FIG_PORT_SPAN=K (default 8) in the file
	lo=$(sed -n 's/.*FIG_PORT_LO=\$(lcm_port \([0-9]\+\)).*/\1/p' "$f" | head -n 1)
	span=$(sed -n 's/.*FIG_PORT_SPAN=\([0-9]\+\).*/\1/p' "$f" | head -n 1)
	[ -n "$lo" ] && seq "$((lo + 1))" "$((lo + ${span:-8} - 1))" | awk -v n="$n" '{ print $1, n }'
done | sort -u)
nfiles=$(awk '{ print $2 }' <<<"$claims" | sort -u | wc -l)
shared=$(awk '{ if ($1 == p && $2 != f) print $1 ": " f " and " $2; p = $1; f = $2 }' <<<"$(sort -n <<<"$claims")")
if [ "$nfiles" -ge 20 ] && [ -z "$shared" ]; then
	tap_ok "no LCM port is named by two test scripts ($(wc -l <<<"$claims") ports in $nfiles scripts)"
else
	tap_fail "no LCM port is named by two test scripts" "${shared:-only $nfiles scripts name ports}"
fi
tap_done
