# figures/helpers.sh — what the rows, channel and forces modules share
# (sourced by their fig.sh; bash, set -u). The driver's own helpers are meant
# to live in figures/lib.sh; these are the ones these three modules need:
#
#   fig_init NAME              the module's name for messages; BUILD, FIG_B (its bin/)
#   fig_die MSG / fig_usage MSG   one line on stderr, exit 1 / 2
#   fig_uint NAME VALUE MIN MAX   a whole number in range, or exit 2 naming NAME
#   fig_num NAME VALUE MIN MAX    a decimal number in range, or exit 2
#   fig_seed WORDS...          a seed 1..999999 from the words (the same every time)
#   fig_lcm_url DIR            a private udpm URL (ttl=0) on a port in 30000-59999
#   fig_demo OUTDIR ARGS...    one lockstep run of scripts/demo.sh into OUTDIR/run
#   fig_shrink OUTDIR          drop the run's large files unless FIG_KEEP=1
#   fig_collect RUNS_DIR OUT   every RUNS_DIR/*/result.csv into OUT (one header)
#   fig_gnuplot                exit 1 with the package to install if gnuplot is missing
#   fig_term                   the gnuplot PNG terminal (pngcairo, else png)
#   fig_median / fig_quantile  of the numbers on stdin
#   fig_pairs SUMMARY_JSON     the analyser's neighbouring pairs as CSV (fig_pairs_header)
#   fig_min_swing SUMMARY_JSON the smallest swing of any joint in the final window
#
# A run uses only $BUILD/bin, the repository's scenario files and its OUTDIR,
# from any working directory: what makes it a job for another machine.

fig_top=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$fig_top/$BUILD" ;; esac
FIG_B="$BUILD/bin"
FIG_NAME=figure

# A program started here runs in a session of its own where setsid exists,
# as scripts/demo.sh starts them (its header says why).
FIG_SESSION=()
command -v setsid >/dev/null 2>&1 && FIG_SESSION=(setsid)

fig_init() { FIG_NAME=$1; }
fig_die() { echo "$FIG_NAME: $*" >&2; exit 1; }
fig_usage() { echo "$FIG_NAME: $*" >&2; exit 2; }

fig_uint() {
	[[ "$2" =~ ^[0-9]{1,9}$ ]] && [ "$((10#$2))" -ge "$3" ] && [ "$((10#$2))" -le "$4" ] ||
		fig_usage "$1: want a whole number from $3 to $4, got '$2'"
}
fig_num() {
	[[ "$2" =~ ^-?[0-9]+([.][0-9]+)?$ ]] && awk -v x="$2" -v a="$3" -v b="$4" 'BEGIN { exit !(x >= a && x <= b) }' ||
		fig_usage "$1: want a number from $3 to $4, got '$2'"
}

fig_seed() { printf '%s' "$*" | cksum | awk '{ print $1 % 999999 + 1 }'; }

# A port from the run's folder and this process: parallel runs (different
# folders) never share one, and a rerun of one folder beside its first try
# gets another. 30000-59999: above the tests' 7600-7999 (+ their offsets)
# and the demo's 17600-27599.
fig_lcm_url() {
	local abs h
	abs=$(cd "$1" && pwd) || fig_die "no folder '$1'"
	h=$(printf '%s %s' "$abs" "$$" | cksum | awk '{ print $1 % 30000 }')
	echo "udpm://239.255.76.67:$((30000 + h))?ttl=0"
}

# fig_demo OUTDIR ARGS...: scripts/demo.sh --lockstep with ARGS, the run kept
# in OUTDIR/run (the analysis; the LCM log until fig_shrink), its output in
# OUTDIR/demo.out. Returns 1 with one line on stderr when it failed or when
# another program spoke on its LCM port (the analysis would mix two runs).
fig_demo() {
	local out=$1; shift
	local url rc=0
	url=$(fig_lcm_url "$out")
	rm -rf "$out/run"
	BUILD=$BUILD "$fig_top/scripts/demo.sh" --lockstep --no-realtime --out "$out/run" --lcm-url "$url" "$@" \
		>"$out/demo.out" 2>&1 </dev/null || rc=$?
	if [ "$rc" -ne 0 ]; then
		echo "$FIG_NAME: the lockstep run failed (scripts/demo.sh exit $rc): $(grep -m1 '^demo: ' "$out/demo.out" |
			cut -c1-300)" >&2
		return 1
	fi
	if [ -f "$out/run/crosstalk" ]; then
		echo "$FIG_NAME: another program published on $url during the run; its analysis mixes two runs" >&2
		return 1
	fi
	[ -f "$out/run/summary.json" ] || { echo "$FIG_NAME: the run left no analysis (see $out/demo.out)" >&2; return 1; }
	sed -n 's/^demo: lockstep: //p' "$out/demo.out" >"$out/lockstep.txt"
}

# The LCM log and the per-sample tables are 100-300 MB for a long run of ten
# robots; the summary, the per-second rates and the programs' logs are small.
fig_shrink() {
	[ "${FIG_KEEP:-0}" = 1 ] && return 0
	rm -f "$1/run/demo.lcmlog" "$1/run/states.csv" "$1/run/phase_diff.csv" "$1/run/collisions.csv" \
		"$1/run/return_map.csv" "$1/run/bus.csv" "$1/run/params.csv"
}

fig_collect() {
	local dir=$1 out=$2 f n=0 header=""
	: >"$out.rows"
	for f in "$dir"/*/result.csv; do
		[ -f "$f" ] || continue
		[ -n "$header" ] || header=$(head -1 "$f")
		if [ "$(head -1 "$f")" != "$header" ]; then
			echo "$FIG_NAME: $f: another header than the first run's; left out" >&2
			continue
		fi
		tail -n +2 "$f" >>"$out.rows"
		n=$((n + 1))
	done
	if [ "$n" -eq 0 ] || [ ! -s "$out.rows" ]; then
		rm -f "$out.rows"
		fig_die "no results in $dir/*/result.csv: nothing to draw (run the jobs first)"
	fi
	{ echo "$header"; sort "$out.rows"; } >"$out"
	rm -f "$out.rows"
}

fig_gnuplot() {
	command -v gnuplot >/dev/null 2>&1 ||
		fig_die "gnuplot is missing: the figures are drawn with it (Debian: apt-get install gnuplot-nox, or scripts/deps.sh)"
}
fig_term() {
	if gnuplot -e 'set terminal pngcairo' >/dev/null 2>&1; then
		echo "pngcairo size 900,600 font 'Sans,11'"
	else
		echo "png size 900,600"
	fi
}

fig_median() { fig_quantile 0.5; }
# fig_quantile Q: the Q-quantile (linear between order statistics) of the
# numbers on stdin, one per line; empty input gives "nan".
fig_quantile() {
	sort -g | awk -v q="$1" '{ v[NR] = $1 } END {
		if (NR == 0) { print "nan"; exit }
		p = 1 + q * (NR - 1); i = int(p); f = p - i
		printf "%.6g\n", (i < NR ? v[i] + f * (v[i + 1] - v[i]) : v[NR]) }'
}

# The analyser's summary.json (one line) holds a "pairs" list of flat
# objects; these are the fields of its neighbouring pairs the figures use
# (tools/analyze/README.md, "End state of a pair"). null becomes nan.
fig_pairs_header="pair,class,mean_delta,mean_abs_delta,spread,window_collisions,collisions,impulse,distance_m,dsep,compat_limit,swing_a,swing_b"
fig_pairs() {
	sed -e 's/.*"pairs":\[{//' -e 's/}\],"min_swing".*//' "$1" | sed 's/},{/\n/g' |
		awk -v keys="$fig_pairs_header" 'BEGIN { nk = split(keys, want, ",") }
		{
			delete v
			n = split($0, kv, /,"/)
			for (i = 1; i <= n; i++) {
				sub(/^"/, "", kv[i]); p = index(kv[i], "\":")
				if (p == 0) continue
				k = substr(kv[i], 1, p - 1); x = substr(kv[i], p + 2)
				gsub(/"/, "", x); if (x == "null") x = "nan"
				v[k] = x
			}
			if (v["kind"] != "neighbour") next
			line = ""
			for (i = 1; i <= nk; i++) line = line (i > 1 ? "," : "") (want[i] in v ? v[want[i]] : "nan")
			print line
		}'
}

fig_min_swing() {
	grep -o '"swing_rad":[^,}]*' "$1" | awk -F: '{ x = ($2 == "null") ? 0 : $2 + 0; if (NR == 1 || x < m) m = x }
		END { if (NR) printf "%.3f\n", m; else print "nan" }'
}
