# figures/lib.sh — shared by the figure modules (figures/<name>/fig.sh) and by
# scripts/figures.sh, the driver of `make figures`. Source it; bash, set -u.
#
#   fig_die MSG...              "fig: MSG" on stderr, exit 1
#   fig_hash TEXT               a number from TEXT (cksum): the same on every machine
#   fig_seed TEXT               a seed in 1..999999 from TEXT (a run's name)
#   FIG_GOLDEN                  the golden ratio's fraction: i * FIG_GOLDEN mod 1 spreads
#                               run i's initial phase evenly, the same on every machine
#   fig_lcm_url OUTDIR [TRY]    a private udpm URL (ttl=0) on a port in 30000-59999
#                               from OUTDIR's name, the PID and TRY, not bound here yet
#   fig_demo OUTDIR ARG...      one lockstep run of scripts/demo.sh into OUTDIR/demo
#                               (its own LCM port; again on another port if it
#                               heard another run); 0, or 1 with the reason on stderr
#   fig_json DIR JQ             a value of DIR/summary.json (jq)
#   fig_delta_trace DIR OUT STEP  the pair's phase difference every STEP s (OUT: t,delta)
#   fig_clean DIR               removes the large files of a run unless FIG_KEEP=1
#   fig_results DIR             every DIR/*/result.csv as one CSV (one header)
#   fig_need_gnuplot            exit 1 with a message when gnuplot is missing
#   fig_gp_head W H             gnuplot's first lines: PNG terminal and common style
#   fig_gnuplot SCRIPT          runs gnuplot on SCRIPT (messages in SCRIPT.log)
#   fig_theory ARG...           undulate-analyze --theory ARG... (tools/analyze/theory.c)
#   fig_pair_switch DSEP DELTA0 when to switch a pair started on the full sinusoid to the
#                               oscillator: just after the clock last pressed them together
#
# Programs come from $BUILD/bin (BUILD: default build/ of this checkout); the
# modules use nothing else outside their OUTDIR, so a run goes to any machine
# with the same checkout built (README.md, "A sweep on a cluster").

fig_top=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$fig_top/$BUILD" ;; esac
export BUILD
FIG_BIN="$BUILD/bin"

fig_die() { echo "fig: $*" >&2; exit 1; }

fig_hash() { printf '%s' "$1" | cksum | cut -d' ' -f1; }
fig_seed() { echo $(( $(fig_hash "$1") % 999999 + 1 )); }
FIG_GOLDEN=0.6180339887498949

# Ports for the figures' runs: above the tests' (7600-8000 plus their offsets
# of a few thousand), the demo's (17600-27599) and below the ephemeral range
# (32768 up is what the kernel hands out on its own; a port it gave to another
# program is skipped below).
# FIG_PORT_LO and FIG_PORT_SPAN from the environment move the block (the
# driver's test keeps its runs in its own ports, moved by TEST_PORT_OFFSET).
FIG_PORT_LO=${FIG_PORT_LO:-30000}
FIG_PORT_SPAN=${FIG_PORT_SPAN:-30000}

# fig_port_bound PORT: some UDP socket of this host is bound to PORT.
fig_port_bound() {
	local hex
	hex=$(printf ':%04X ' "$1")
	grep -q "$hex" /proc/net/udp /proc/net/udp6 2>/dev/null
}
# Each run records the LCM traffic of its own port; a port is only taken when
# nothing is bound to it yet. Under GNU parallel the job's slot (a number no
# other running job has) picks the port; elsewhere the run's folder and PID
# do. Two runs that pick the same free port at the same instant are noticed
# (a daemon finds another with its name on that network, or demo.sh sees
# more states than one daemon sends) and fig_demo runs again on another.
fig_lcm_url() {
	local out=$1 try=${2:-0} port k
	if [[ "${PARALLEL_JOBSLOT:-}" =~ ^[0-9]+$ ]]; then
		port=$(( FIG_PORT_LO + (PARALLEL_JOBSLOT - 1 + try * 7) % FIG_PORT_SPAN ))
	else
		port=$(( FIG_PORT_LO + ($(fig_hash "$out") + $$ * 7919 + try * 104729) % FIG_PORT_SPAN ))
	fi
	for k in $(seq 0 50); do
		fig_port_bound "$port" || break
		port=$(( FIG_PORT_LO + (port - FIG_PORT_LO + 1) % FIG_PORT_SPAN ))
	done
	echo "udpm://239.255.76.67:$port?ttl=0"
}

# Attempts of one run when it heard another run on its port.
FIG_PORT_TRIES=3
fig_demo() {
	local out=$1; shift
	local try rc
	mkdir -p "$out" || { echo "fig: cannot create $out" >&2; return 1; }
	for try in $(seq 0 $((FIG_PORT_TRIES - 1))); do
		rm -rf "$out/demo"
		rc=0
		"$fig_top/scripts/demo.sh" --lockstep --out "$out/demo" --lcm-url "$(fig_lcm_url "$out" "$try")" \
			"$@" >"$out/demo.out" 2>&1 || rc=$?
		# another run took the same port at the same moment: again, elsewhere
		grep -q 'another undulated for this robot runs on this computer' "$out/demo.out" && continue
		if [ "$rc" -ne 0 ] || [ ! -f "$out/demo/summary.json" ]; then
			echo "fig: $out: the lockstep run failed (demo.sh exit $rc): $(grep -m1 '^demo: ' "$out/demo.out" || tail -n 1 "$out/demo.out")" >&2
			return 1
		fi
		[ -f "$out/demo/crosstalk" ] || return 0
	done
	echo "fig: $out: another run used the run's LCM port $FIG_PORT_TRIES times in a row" >&2
	return 1
}

fig_json() { jq -r "$2" "$1/summary.json"; }

# fig_delta_trace DIR OUT STEP: the followed pair's (the first neighbour
# pair's) phase difference from DIR/phase_diff.csv, one sample per STEP s.
fig_delta_trace() {
	awk -F, -v step="$3" 'NR == 1 { next }
		$4 == "neighbour" && (pair == "" || $3 == pair) && $9 != "" && $2 >= next_t {
			pair = $3; printf "%.2f,%s\n", $2, $9; next_t = $2 + step }' "$1/phase_diff.csv" |
		{ echo "t,delta"; cat; } >"$2"
}

# What a run keeps: its result, the analyser's summary and small CSVs, the
# programs' logs. The LCM log (3 MB for a 40 s pair run) and the per-sample
# CSVs (1.5 MB) go, unless FIG_KEEP=1.
fig_clean() {
	[ "${FIG_KEEP:-0}" = 1 ] && return 0
	rm -f "$1/demo.lcmlog" "$1/states.csv" "$1/phase_diff.csv" "$1/bus.csv" "$1/params.csv"
}

fig_results() {
	local f first=1
	for f in "$1"/*/result.csv; do
		[ -f "$f" ] || continue
		if [ "$first" = 1 ]; then cat "$f"; first=0; else tail -n +2 "$f"; fi
	done
}

fig_need_gnuplot() {
	command -v "${GNUPLOT:-gnuplot}" >/dev/null 2>&1 ||
		fig_die "gnuplot is not installed: no figure can be drawn (Debian: apt-get install gnuplot-nox; or scripts/deps.sh)"
}

# The figures' look: one size of type, a light grid, the key inside; the
# paper's colours are not known here, so gnuplot's first ones.
fig_gp_head() {
	cat <<EOF
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size $1,$2 enhanced font ',11'
} else {
  set terminal png size $1,$2 enhanced
}
set datafile separator ','
set datafile missing ''
set grid lc rgb '#dddddd'
set border lw 1.2
set key box opaque samplen 2
EOF
}

fig_gnuplot() {
	"${GNUPLOT:-gnuplot}" "$1" >"$1.log" 2>&1 || { echo "fig: gnuplot failed on $1: $(tail -n 3 "$1.log")" >&2; return 1; }
	# gnuplot goes on after most errors: a script that drew nothing says so here
	if grep -qiE '(^|[^a-z])(error|warning: skipping)' "$1.log"; then
		echo "fig: gnuplot: $(grep -m1 -iE 'error|warning: skipping' "$1.log") ($1.log)" >&2
		return 1
	fi
}

fig_theory() { "$FIG_BIN/undulate-analyze" --theory "$@"; }

# ---- a pair started at full amplitude, released by the clock -------------------------
# Where the clock would press the bodies together at once (d~ = 0: for half
# of every period), a phase difference cannot be set by a sinusoid that runs
# long before the switch. fig_pair_switch gives the moment to switch a pair
# started on the full sinusoid (SINUSOID at FIG_SIN_AMP and FIG_SIN_HZ,
# phases 0 and -DELTA0: the analyser's DELTA0) to the oscillator: just after
# the clock released the bodies. At d~ the clock drives them together while
# sin(DELTA0/2) cos(w t + DELTA0/2) >= d~ A_nominal / A (angles
# x = A sin(phase - w t), a gap of 2 d~ A_nominal lever between the bodies);
# the oscillators then start from the clock's phases, apart, and meet half a
# period later at about DELTA0, at full amplitude. The sinusoid's phase is 0
# at simulated time 0: lockstep's wall clock starts at 2000-01-01T00:00:00Z,
# a whole number of 0.8 Hz cycles after the epoch (sim-bridge/README.md).
FIG_SIN_AMP=0.8
FIG_SIN_HZ=0.8
# Not before the daemons' 1.5 s ramp into the sinusoid is over, and a
# margin; the switch comes this long after the clock released them.
FIG_SWITCH_MIN_S=2.2
FIG_SWITCH_AFTER_S=0.1
# fig_pair_switch DSEP DELTA0 [NOMINAL_AMP]: the switch time (s), printed.
fig_pair_switch() {
	awk -v d="$1" -v D="$2" -v nom="${3:-0.8}" -v A="$FIG_SIN_AMP" -v f="$FIG_SIN_HZ" \
		-v tmin="$FIG_SWITCH_MIN_S" -v after="$FIG_SWITCH_AFTER_S" 'BEGIN {
		pi = atan2(0, -1); w = 2 * pi * f; s = sin(D / 2); c = d * nom / A; as = s < 0 ? -s : s
		if (c > as) { printf "%.3f\n", tmin + after; exit }   # the clock never presses them
		# the pressing ends at w t + D/2 = 2 pi k + a (s > 0) or pi (2k + 1) + a (s < 0)
		q = c / as; a = atan2(sqrt(1 - q * q), q); base = s > 0 ? 0 : pi
		for (k = -2; k < 100; k++) {
			te = (base + 2 * pi * k + a - D / 2) / w
			if (te >= tmin) { printf "%.3f\n", te + after; exit }
		}
	}'
}
