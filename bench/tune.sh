#!/usr/bin/env bash
# bench/tune.sh — what the oscillator settings give on the simulated robot.
#
# Runs undulate-sim and undulated (with any daemon options you pass after
# --), lets the robot settle from rest, and measures the joints' published
# angles: per joint the frequency, the smallest and largest amplitude of the
# cycles in the window, and the lag of each joint behind the previous one.
# Use it to tune k, mu, servo_lead_s for your servo model (daemon/CONTROL.md).
#
#   bench/tune.sh [--ids 1,2] [--settle S] [--window S] [--seed N]
#                 [--return-delay US] [--lcm-port P] [-- UNDULATED-OPTIONS...]
#   e.g. bench/tune.sh -- --set joint.1.k=0.086 --set joint.2.k=0.086
#
# Output: one line per joint, "joint N: f HZ Hz, A MIN..MAX rad, n CYCLES",
# then "lag joint N behind N-1: MIN..MAX deg". BUILD selects the build
# directory (default build). Exit 0 when the run could be measured.
set -u
top=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$top/$BUILD" ;; esac
SIM=$BUILD/bin/undulate-sim
DMN=$BUILD/bin/undulated
ids=1,2 settle=8 window=10 seed=1 rdelay=500 port=7747
usage() { sed -n '10,11p' "$0" | sed 's/^# *//'; exit 1; }
while [ $# -gt 0 ]; do
	case "$1" in
	--ids) ids=$2; shift 2 ;;
	--settle) settle=$2; shift 2 ;;
	--window) window=$2; shift 2 ;;
	--seed) seed=$2; shift 2 ;;
	--return-delay) rdelay=$2; shift 2 ;;
	--lcm-port) port=$2; shift 2 ;;
	--) shift; break ;;
	*) usage ;;
	esac
done
[ -x "$SIM" ] && [ -x "$DMN" ] || { echo "tune.sh: build $SIM and $DMN first" >&2; exit 1; }
dir=$(mktemp -d "${TMPDIR:-/tmp}/undulate-tune.XXXXXX")
url="udpm://239.255.76.67:$port?ttl=0"
robot="tune$$"
pids=()
cleanup() {
	local p
	for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null; done
	for p in "${pids[@]}"; do wait "$p" 2>/dev/null; done
	rm -rf "$dir"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
# poll a log for a line (never sleep-and-hope)
wait_line() {
	local i
	for i in $(seq 500); do grep -q "$2" "$1" 2>/dev/null && return 0; sleep 0.02; done
	return 1
}

"$SIM" --link "$dir/bus" --ids "$ids" --lcm-url "$url" --seed "$seed" --return-delay "$rdelay" \
	>"$dir/sim.log" 2>&1 &
pids+=($!)
wait_line "$dir/sim.log" ready || { echo "tune.sh: simulator did not start" >&2; cat "$dir/sim.log" >&2; exit 1; }
"$DMN" --watch "$robot" --raw --lcm-url "$url" >"$dir/watch.log" 2>&1 &
pids+=($!)
"$DMN" --port "$dir/bus" --ids "$ids" --robot "$robot" --lcm-url "$url" --mode oscillator "$@" >"$dir/d.log" 2>&1 &
pids+=($!)
wait_line "$dir/d.log" "ready: $robot.STATE" || { echo "tune.sh: daemon did not start" >&2; cat "$dir/d.log" >&2; exit 1; }

end=$(awk -v a="$settle" -v b="$window" 'BEGIN { print int((a + b) * 100) }')
last_cycle() { awk -v r="$robot" '$1 == "STATE" && $2 == r { c = $3 } END { sub("cycle=", "", c); print c + 0 }' "$dir/watch.log"; }
for i in $(seq $(( (end / 100 + 20) * 10 ))); do
	[ "$(last_cycle)" -ge "$end" ] && break
	sleep 0.1
done
[ "$(last_cycle)" -ge "$end" ] || { echo "tune.sh: the robot stopped publishing" >&2; tail -5 "$dir/d.log" >&2; exit 1; }
upsets=$(grep -c "timeout\|overrun\|stall" "$dir/d.log")

# "t x0 x1 ..." in OSCILLATOR mode, t from the cycle counter (10 ms), then
# upward crossings of each joint's centre with hysteresis (a tenth of the swing)
awk -v r="$robot" '$1 == "STATE" && $2 == r && $4 == "mode=3" {
	c = $3; sub("cycle=", "", c); line = c * 0.01
	for (i = 5; i <= NF; i++) if ($i ~ /^a[0-9]=/) { v = $i; sub(/^a[0-9]=/, "", v); line = line " " v }
	print line }' "$dir/watch.log" |
awk -v from="$settle" -v to="$(awk -v a="$settle" -v b="$window" 'BEGIN { print a + b }')" '
$1 >= from && $1 < to { ns++; T[ns] = $1; for (j = 2; j <= NF; j++) X[ns, j - 1] = $j; nj = NF - 1 }
END {
	for (j = 1; j <= nj; j++) {
		lo = 1e9; hi = -1e9
		for (i = 1; i <= ns; i++) { if (X[i, j] < lo) lo = X[i, j]; if (X[i, j] > hi) hi = X[i, j] }
		c = (lo + hi) / 2; h = (hi - lo) / 20; n[j] = 0; amin = 1e9; amax = 0
		up = 0; armed = 0; mx = -1e9; mn = 1e9
		for (i = 1; i <= ns; i++) {
			x = X[i, j]
			if (x > c + h) up = 1
			if (up && x < c - h) armed = 1
			if (i > 1 && armed && X[i - 1, j] < c && x >= c) {
				tc = T[i - 1] + (T[i] - T[i - 1]) * (c - X[i - 1, j]) / (x - X[i - 1, j])
				n[j]++; ct[j, n[j]] = tc
				if (n[j] > 1) { a = (mx - mn) / 2; if (a < amin) amin = a; if (a > amax) amax = a }
				mx = x; mn = x; up = 0; armed = 0
			}
			if (x > mx) mx = x; if (x < mn) mn = x
		}
		f = n[j] > 1 ? (n[j] - 1) / (ct[j, n[j]] - ct[j, 1]) : 0
		if (n[j] > 1) printf "joint %d: f %.3f Hz, A %.3f..%.3f rad, n %d cycles\n", j, f, amin, amax, n[j] - 1
		else printf "joint %d: no whole cycle (stopped?), range %.3f..%.3f rad\n", j, lo, hi
	}
	for (j = 2; j <= nj; j++) {
		k = 0; lmin = 1e9; lmax = -1e9
		for (a = 1; a < n[j - 1]; a++) for (b = 1; b <= n[j]; b++)
			if (ct[j, b] >= ct[j - 1, a] && ct[j, b] < ct[j - 1, a + 1]) {
				l = 360 * (ct[j, b] - ct[j - 1, a]) / (ct[j - 1, a + 1] - ct[j - 1, a]); if (l > 180) l -= 360
				k++; if (l < lmin) lmin = l; if (l > lmax) lmax = l; break
			}
		if (k) printf "lag joint %d behind %d: %.1f..%.1f deg over %d cycles\n", j, j - 1, lmin, lmax, k
	}
}'
[ "$upsets" -eq 0 ] || echo "note: $upsets bus timeouts/overruns/stalls in the daemon's log (a loaded machine disturbs the loop)"
exit 0
