# figures/lib.sh — shared by the figure modules (figures/<name>/fig.sh) and by
# scripts/figures.sh, the driver of `make figures`. Source it (bash): it turns
# on set -u for its caller, so that in every module an unset variable is an error.
#
#   fig_init NAME               the module's name, which starts its messages
#   fig_main USAGE CMD ARG...   runs the module's subcommand CMD (jobs, run, merge,
#                               seconds, or one in FIG_MORE_COMMANDS), else the usage
#   fig_grid ID VALUES N SEED_WORDS ARG...  job lines: each value x runs 1..N, with
#                               {v}, {i} and {seed} filled in (fig_seed SEED_WORDS V I)
#   fig_run_start OUTDIR        a run's folder checked (fig_run_dir); FIG_RUN its
#                               absolute path, FIG_T0 the start; fig_wall: seconds since
#   fig_die MSG... / fig_usage MSG...   "NAME: MSG" on stderr, exit 1 / exit 2
#   fig_uint NAME VALUE MIN MAX a whole number in range, else fig_usage naming NAME
#   fig_num NAME VALUE MIN MAX  a decimal number in range, else fig_usage
#   fig_hash TEXT               a number from TEXT (cksum): the same on every machine
#   fig_seed WORDS...           a seed in 1..999999 from the words (a run's name)
#   FIG_GOLDEN                  the golden ratio's fraction: i * FIG_GOLDEN mod 1 spreads
#                               run i's initial phase evenly, the same on every machine
#   fig_basename VAR PATH       VAR = basename PATH (without running it)
#   fig_lcm_url OUTDIR [TRY]    a private udpm URL (ttl=0) on a port in 30000-59999
#                               from GNU parallel's job slot, else OUTDIR's name and
#                               the PID, and TRY; one nothing here is bound to yet
#                               (fig_lcm_url_v VAR OUTDIR [TRY]: the same into VAR)
#   fig_run_dir OUTDIR          a run's folder: made when missing, else it must be
#                               ours and writable by no other user (exit 1 saying
#                               why: scripts/outdir.sh); every file a run writes
#                               replaces what has its name (outdir_new, outdir_put)
#   fig_demo OUTDIR ARG...      one lockstep run of scripts/demo.sh into OUTDIR/demo
#                               (its own LCM port; again on another port if it
#                               heard another run); 0, or 1 with the reason on stderr
#   FIG_SESSION                 setsid where it exists: a program started outside
#                               fig_demo runs in a session of its own, as demo.sh's do
#   fig_json DIR JQ             a value of DIR/summary.json (jq)
#   fig_pairs SUMMARY_JSON      the analyser's neighbouring pairs as CSV (fig_pairs_header)
#   fig_min_swing SUMMARY_JSON  the smallest swing of any joint in the final window
#   fig_delta_trace DIR OUT STEP  the pair's phase difference every STEP s (OUT: t,delta)
#   fig_clean DIR               removes the large files of a run's analysis DIR
#                               unless FIG_KEEP=1
#   fig_results DIR [sorted]    every DIR/*/result.csv as one CSV (one header; the
#                               rows sorted with `sorted`); exit 1 when there is none
#   fig_median / fig_quantile Q of the numbers on stdin, one a line
#   fig_force_series RUNS V END OUT  the per-second contact force of the first run
#                               whose setting (result.csv's first field) is V
#   fig_summary_csv SUMMARY CSV HEADER  SUMMARY's blank-separated rows as SUMMARY.csv
#                               under HEADER; none: exit 1 (nothing in CSV to summarize)
#   fig_spread LIST             "MEDIAN MIN MAX" of the numbers in LIST (blank-separated)
#   fig_merge_begin FIGDIR      for a merge: gnuplot present, FIGDIR checked as a
#                               run's folder, FIG_TMP (a temporary folder) and
#                               FIG_OUT (a private folder inside FIGDIR, where
#                               the merge writes its files), removed at exit
#   fig_merge_runs RUNS FIGDIR  merge's arguments checked, fig_merge_begin FIGDIR,
#                               and the runs' rows (sorted) in FIG_OUT/NAME.csv
#   fig_merge_end               FIG_OUT's files moved into FIGDIR, replacing
#                               what has their names (never written through)
#   fig_need_gnuplot            exit 1 with a message when gnuplot is missing
#   fig_gp_head W H             gnuplot's first lines: PNG terminal and common style
#   fig_gnuplot SCRIPT          runs gnuplot on SCRIPT (messages in SCRIPT.log);
#                               1 also when a series drew nothing
#   fig_has CSV CONDITION      a row of CSV where the awk CONDITION holds
#   fig_series ARRAY CSV COND SPEC  ARRAY gets "'CSV' every ::1 SPEC" when fig_has CSV COND
#   fig_plot SPEC...            a gnuplot plot command of the series (empty ones left out)
#   fig_theory ARG...           undulate-analyze --theory ARG... (tools/analyze/theory.c)
#   FIG_PAIR_SCENARIO, FIG_PAIR_DRIVE  the pair rig's scenario and its robots' drive
#                               (demo.sh --daemon-set words), shared by pair and returnmap
#   fig_pair_switch DSEP DELTA0 when to switch a pair started on the full sinusoid to the
#                               oscillator: just after the clock last pressed them together
#   FIG_CHANNEL_* (widths, timeline, swept width), fig_channel_demo OUTDIR WIDTH_CM SEED
#   SCENARIO ARG...             the channel modules' trial, one run of it
#   fig_channel_series CSV TMP WORD PS SWEPT_M, fig_channel_axes WINDOW,
#   fig_channel_widths CSV, fig_channel_table CSV LAST [above], fig_channel_counts CSV,
#   fig_channel_trials CSV      the channel modules' figure
#                               (the paper's Fig. 9) and table, the same for both
#   FIG_PLANE_CONF              the oscillator tuned for the plane world's robot
#                               (figures/plane-oscillator.conf, made by fig_plane_tune)
#   fig_plane_sets [CONF]       its parameters as demo.sh --daemon-set words, one a line
#   fig_plane_tune OUT [SEED] [S]  the tuner in lockstep on one plane robot: OUT, a
#                               configuration of the tuned keys and how they were made
#   fig_ini FILE SECTION KEY    a value of an INI file (a daemon configuration)
#
# Programs come from $BUILD/bin (BUILD: default build/ of this checkout); the
# modules use nothing else outside their OUTDIR, so a run goes to any machine
# with the same checkout built (docs/CLUSTER.md).

set -u
# (dirname's answer without running it: every figure run sources this)
case "${BASH_SOURCE[0]}" in */*) fig_top=${BASH_SOURCE[0]%/*} ;; *) fig_top=. ;; esac
fig_top=$(cd "${fig_top:-/}/.." && pwd)

# fig_rows_csv HEADER_REGEX: the daemons' rows (figures/rows' rows.csv) for a
# module that draws the model beside them: FIG_ROWS_CSV, else the rows.csv of
# this invocation's merge, else the project's docs/figures/rows.csv — the
# first that is there and whose header matches; status 1 if none.
fig_rows_csv() {
	local c
	for c in "${FIG_ROWS_CSV:-}" "${FIG_MERGE_DIR:+$FIG_MERGE_DIR/rows.csv}" "$fig_top/docs/figures/rows.csv"; do
		[ -n "$c" ] && [ -s "$c" ] && head -n 1 "$c" | grep -q "$1" && { echo "$c"; return 0; }
	done
	return 1
}
source "$fig_top/scripts/outdir.sh"
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$fig_top/$BUILD" ;; esac
export BUILD
FIG_BIN="$BUILD/bin"
FIG_NAME=fig

fig_init() { FIG_NAME=$1; }
# fig_basename VAR PATH: VAR = basename PATH, without running it.
fig_basename() {
	local -n _base=$1
	local p=$2
	while [[ $p == */ && $p != / ]]; do p=${p%/}; done
	[ "$p" = / ] && { _base=/; return; }
	_base=${p##*/}
}
fig_die() { echo "$FIG_NAME: $*" >&2; exit 1; }
fig_usage() { echo "$FIG_NAME: $*" >&2; exit 2; }

# fig_main USAGE CMD ARG...: a module's last line. Every module answers the
# same four subcommands (README.md, "A module"), each a function of the same
# name; a module with more names them in FIG_MORE_COMMANDS. Anything else:
# "NAME: usage: fig.sh USAGE", exit 2.
fig_main() {
	local usage=$1 cmd=${2:-}
	case " jobs run merge seconds ${FIG_MORE_COMMANDS:-} " in
	*" $cmd "*) [ -n "$cmd" ] && { shift 2; "$cmd" "$@"; return; } ;;
	esac
	fig_usage "usage: fig.sh $usage"
}

# fig_grid ID VALUES N SEED_WORDS ARG...: the job lines of a sweep, N runs at
# each value: "ID ARG..." with {v} the value and {i} the run's number (1..N)
# in ID and the ARGs, and {seed} (an ARG) fig_seed SEED_WORDS V I: the same
# lines, names and seeds every time (README.md, "A module": jobs).
fig_grid() {
	local id=$1 values=$2 count=$3 words=$4 v i a line seed
	shift 4
	for v in $values; do
		for ((i = 1; i <= count; i++)); do
			fig_seed_v seed "$words" "$v" "$i"   # no subshell: hundreds of lines
			line=${id//\{v\}/$v}
			line=${line//\{i\}/$i}
			for a in "$@"; do
				a=${a//\{v\}/$v}
				a=${a//\{i\}/$i}
				line+=" ${a//\{seed\}/$seed}"
			done
			echo "$line"
		done
	done
}

fig_uint() {
	[[ "$2" =~ ^[0-9]{1,9}$ ]] && [ "$((10#$2))" -ge "$3" ] && [ "$((10#$2))" -le "$4" ] ||
		fig_usage "$1: want a whole number from $3 to $4, got '$2'"
}
fig_num() {
	local x a b
	if [[ "$2" =~ ^-?[0-9]+([.][0-9]+)?$ ]]; then
		# in the shell (a figure run checks a few numbers, each an awk
		# before) when all three fit _fig_fixed, else awk
		if _fig_fixed x "$2" && _fig_fixed a "$3" && _fig_fixed b "$4"; then
			[ "$x" -ge "$a" ] && [ "$x" -le "$b" ] && return 0
		elif awk -v x="$2" -v a="$3" -v b="$4" 'BEGIN { exit !(x >= a && x <= b) }'; then
			return 0
		fi
	fi
	fig_usage "$1: want a number from $3 to $4, got '$2'"
}
# _fig_fixed VAR X: VAR = the decimal number X in billionths, exactly, when
# it has at most 9 digits either side of the point; else 1.
_fig_fixed() {
	local -n _fx=$1
	[[ $2 =~ ^(-?)([0-9]{1,9})([.]([0-9]{1,9}))?$ ]] || return 1
	local frac=${BASH_REMATCH[4]}000000000
	_fx=$(( 10#${BASH_REMATCH[2]} * 1000000000 + 10#${frac:0:9} ))
	[ -z "${BASH_REMATCH[1]}" ] || _fx=$(( -_fx ))
}

# fig_hash is POSIX cksum's CRC (the seeds of every recorded run came from
# `cksum`), computed in the shell: a module lists its jobs with one seed each,
# hundreds of them, and a pipe of printf, cksum and cut per seed cost seconds
# on a loaded machine. The table (CRC-32, polynomial 0x04C11DB7, most
# significant bit first) is made once, at the first hash: a figure run under
# GNU parallel needs none, and the table costs 10 ms of CPU a run.
_fig_crc=()
_fig_crc_table() {
	local i k c
	for ((i = 0; i < 256; i++)); do
		c=$(( i << 24 ))
		for ((k = 0; k < 8; k++)); do
			if (( c & 0x80000000 )); then c=$(( ((c << 1) ^ 0x04C11DB7) & 0xFFFFFFFF )); else c=$(( (c << 1) & 0xFFFFFFFF )); fi
		done
		_fig_crc[i]=$c
	done
}
# fig_hash_v VAR TEXT: VAR = TEXT's cksum, without a subshell
fig_hash_v() {
	local -n _h=$1
	local s=$2 crc=0 i c n LC_ALL=C   # bytes, as cksum counts them
	[ ${#_fig_crc[@]} -eq 256 ] || _fig_crc_table
	for ((i = 0; i < ${#s}; i++)); do
		printf -v c '%d' "'${s:i:1}"
		crc=$(( ((crc << 8) & 0xFFFFFFFF) ^ _fig_crc[((crc >> 24) ^ c) & 0xFF] ))
	done
	for ((n = ${#s}; n > 0; n >>= 8)); do   # then the length, low byte first
		crc=$(( ((crc << 8) & 0xFFFFFFFF) ^ _fig_crc[((crc >> 24) ^ n) & 0xFF] ))
	done
	_h=$(( ~crc & 0xFFFFFFFF ))
}
fig_hash() { local h; fig_hash_v h "$1"; echo "$h"; }
fig_seed() { local h; fig_hash_v h "$*"; echo $(( h % 999999 + 1 )); }
# fig_seed_v VAR WORDS...: the same into VAR
fig_seed_v() { local -n _s=$1; shift; local h; fig_hash_v h "$*"; _s=$(( h % 999999 + 1 )); }
FIG_GOLDEN=0.6180339887498949

# Ports for the figures' runs: above the tests' (7600-8000 plus their offsets
# of a few thousand), the demo's (17600-27599) and below the ephemeral range
# (32768 up is what the kernel hands out on its own; a port it gave to another
# program is skipped below).
# FIG_PORT_LO and FIG_PORT_SPAN from the environment move the block (the
# driver's test keeps its runs in its own ports, moved by TEST_PORT_OFFSET).
FIG_PORT_LO=${FIG_PORT_LO:-30000}
FIG_PORT_SPAN=${FIG_PORT_SPAN:-30000}

# fig_port_bound PORT: some UDP socket of this host is bound to PORT (the
# tables read by the shell: a few hundred lines, no process).
fig_port_bound() {
	local hex f table
	printf -v hex ':%04X ' "$1"
	for f in /proc/net/udp /proc/net/udp6; do
		table=""
		{ IFS= read -r -d '' table; } 2>/dev/null <"$f"
		[[ $table == *"$hex"* ]] && return 0
	done
	return 1
}
# Each run records the LCM traffic of its own port; a port is only taken when
# nothing is bound to it yet. Under GNU parallel the job's slot (a number no
# other running job has) picks the port; elsewhere the run's folder and PID
# do. Two runs that pick the same free port at the same instant are noticed
# (a daemon finds another with its name on that network, or demo.sh sees
# more states than one daemon sends) and fig_demo runs again on another.
fig_lcm_url() { local url; fig_lcm_url_v url "$@"; echo "$url"; }
# fig_lcm_url_v VAR OUTDIR [TRY]: the same into VAR, without a subshell
fig_lcm_url_v() {
	local -n _url=$1
	local out=$2 try=${3:-0} port k h
	if [[ "${PARALLEL_JOBSLOT:-}" =~ ^[0-9]+$ ]]; then
		port=$(( FIG_PORT_LO + (PARALLEL_JOBSLOT - 1 + try * 7) % FIG_PORT_SPAN ))
	else
		fig_hash_v h "$out"
		port=$(( FIG_PORT_LO + (h + $$ * 7919 + try * 104729) % FIG_PORT_SPAN ))
	fi
	for ((k = 0; k <= 50; k++)); do
		fig_port_bound "$port" || break
		port=$(( FIG_PORT_LO + (port - FIG_PORT_LO + 1) % FIG_PORT_SPAN ))
	done
	_url="udpm://239.255.76.67:$port?ttl=0"
}

# A program started here runs in a session of its own where setsid exists,
# as scripts/demo.sh starts them (its header says why).
FIG_SESSION=()
command -v setsid >/dev/null 2>&1 && FIG_SESSION=(setsid)

# fig_run_dir OUTDIR: its parents made as needed, OUTDIR itself checked (or
# made): in another user's folder, or one others may write, the names a run
# writes may be links to our files already (scripts/outdir.sh).
fig_run_dir() {
	local parent=$1
	# dirname's answer, without running it
	while [[ $parent == */ && $parent != / ]]; do parent=${parent%/}; done
	case "$parent" in */*) parent=${parent%/*} ;; *) parent=. ;; esac
	while [[ $parent == */ && $parent != / ]]; do parent=${parent%/}; done
	parent=${parent:-/}
	[ -d "$parent" ] || mkdir -p -- "$parent" || fig_die "cannot create $parent"
	outdir_check "$1" "$FIG_NAME:" || exit 1
}

# fig_run_start OUTDIR: what every run does first: its folder checked or made
# (fig_run_dir), FIG_RUN its absolute path (the run's programs start in other
# folders) and FIG_T0 the moment, for fig_wall: the run's wall seconds so
# far, one decimal, for its result row.
fig_run_start() {
	fig_run_dir "$1"
	FIG_RUN=$(cd "$1" && pwd) || fig_die "cannot enter $1"
	FIG_T0=$EPOCHREALTIME
}
# (the clock is the shell's: microseconds, "s.us" or "s,us" by the locale)
fig_wall() {
	local a=${FIG_T0//[!0-9]/} b=${EPOCHREALTIME//[!0-9]/} d
	d=$(( (10#$b - 10#$a + 50000) / 100000 ))
	echo "$((d / 10)).$((d % 10))"
}

# Attempts of one run when it heard another run on its port.
FIG_PORT_TRIES=3
fig_demo() {
	local out=$1; shift
	local try rc url line crossed
	fig_run_dir "$out"
	for ((try = 0; try < FIG_PORT_TRIES; try++)); do
		if [ -e "$out/demo" ] || [ -L "$out/demo" ]; then rm -rf "$out/demo"; fi
		outdir_new "$out/demo.out" || { echo "$FIG_NAME: cannot write $out/demo.out" >&2; return 1; }
		rc=0
		fig_lcm_url_v url "$out" "$try"
		"$fig_top/scripts/demo.sh" --lockstep --out "$out/demo" --lcm-url "$url" \
			"$@" >"$out/demo.out" 2>&1 </dev/null || rc=$?
		# another run took the same port at the same moment: again, elsewhere
		# (demo.out, a few dozen lines, read by the shell)
		crossed=0
		while IFS= read -r line || [ -n "$line" ]; do
			[[ $line == *'another undulated for this robot runs on this computer'* ]] && { crossed=1; break; }
		done <"$out/demo.out"
		[ "$crossed" = 0 ] || continue
		if [ "$rc" -ne 0 ] || [ ! -f "$out/demo/summary.json" ]; then
			echo "$FIG_NAME: $out: the lockstep run failed (demo.sh exit $rc): $( { grep -m1 '^demo: ' "$out/demo.out" ||
				tail -n 1 "$out/demo.out"; } | cut -c1-300)" >&2
			return 1
		fi
		[ -f "$out/demo/crosstalk" ] || return 0
	done
	echo "$FIG_NAME: $out: another run used the run's LCM port $FIG_PORT_TRIES times in a row" >&2
	return 1
}

fig_json() { jq -r "$2" "$1/summary.json"; }

# The analyser's summary.json (one line) holds a "pairs" list of flat
# objects; these are the fields of its neighbouring pairs the figures use
# (tools/analyze/README.md, "End state of a pair"). null becomes nan.
fig_pairs_header="pair,class,mean_delta,mean_abs_delta,spread,window_collisions,collisions,impulse,distance_m,dsep,compat_limit,swing_a,swing_b"
fig_pairs() {
	sed -e 's/.*"pairs":\[{//' -e 's/}\],"min_swing".*//' -e 's/},{/\n/g' "$1" |
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
	# every "swing_rad":VALUE (grep -o's matches, in one awk)
	awk '{ while (match($0, /"swing_rad":[^,}]*/)) {
			v = substr($0, RSTART + 12, RLENGTH - 12); $0 = substr($0, RSTART + RLENGTH)
			x = (v == "null") ? 0 : v + 0; if (n++ == 0 || x < m) m = x } }
		END { if (n) printf "%.3f\n", m; else print "nan" }' "$1"
}

# fig_delta_trace DIR OUT STEP: the followed pair's (the first neighbour
# pair's) phase difference from DIR/phase_diff.csv, one sample per STEP s.
fig_delta_trace() {
	awk -F, -v step="$3" 'BEGIN { print "t,delta" } NR == 1 { next }
		$4 == "neighbour" && (pair == "" || $3 == pair) && $9 != "" && $2 >= next_t {
			pair = $3; printf "%.2f,%s\n", $2, $9; next_t = $2 + step }' "$1/phase_diff.csv" |
		outdir_put "$2"
}

# What a run keeps: its result, the analyser's summary and per-second rates,
# the programs' logs. The LCM log and the per-sample and per-collision CSVs
# go (3 MB and 1.5 MB for a 40 s pair run, 100-300 MB for a long run of ten
# robots; the plane world's plane.csv, 11 MB for 300 s of ten robots, which
# forces-plane's runs kept until this removed it for every module), unless
# FIG_KEEP=1.
fig_clean() {
	[ "${FIG_KEEP:-0}" = 1 ] && return 0
	rm -f "$1/demo.lcmlog" "$1/states.csv" "$1/phase_diff.csv" "$1/collisions.csv" "$1/return_map.csv" \
		"$1/bus.csv" "$1/params.csv" "$1/plane.csv" "$1/plane_walls.csv"
}

# fig_results DIR [sorted]: the runs' rows under the first run's header (with
# `sorted`, the rows in sort's order); a run with another header is left out,
# saying so. No row at all: exit 1.
fig_results() {
	local files=("$1"/*/result.csv) out=cat
	[ -f "${files[0]}" ] || fig_die "no run in $1 has a result.csv: nothing to draw (run the figure's jobs first)"
	[ "${2:-}" = sorted ] && out=sort
	awk -v name="$FIG_NAME" -v out="$out" '
		FNR == 1 {
			if (NR == 1) { h = $0; print; fflush() }
			else if ($0 != h) { printf "%s: %s: another header than the first run'"'"'s; left out\n", name, FILENAME >"/dev/stderr"; nextfile }
			next
		}
		{ print | out; n++ }
		END { close(out); exit n == 0 }' "${files[@]}" ||
		fig_die "no run in $1 has a row in its result.csv: nothing to draw"
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

# fig_spread LIST: the median, the least and the greatest of the numbers in
# LIST (separated by blanks: the lists a merge's awk gathers per setting), on
# one line with a space between; an empty LIST gives "nan" and two empty
# fields (three words for printf's %s, or read's three names, all the same).
fig_spread() {
	local med lo hi
	med=$(tr ' ' '\n' <<<"$1" | grep . | fig_median)
	lo=$(tr ' ' '\n' <<<"$1" | grep . | sort -g | head -1)
	hi=$(tr ' ' '\n' <<<"$1" | grep . | sort -g | tail -1)
	echo "$med $lo $hi"
}

# fig_force_series RUNS_DIR VALUE END OUT: the forces modules' picture of
# force against time draws one run per setting: the first run folder (in
# name order) with a series.csv whose result.csv row has VALUE first. OUT:
# that series' header and its whole seconds up to END with a force (the
# last bin holds the final message alone). 1 when no run has one.
fig_force_series() {
	local d
	for d in "$1"/*/; do
		[ -f "$d/series.csv" ] && [ -f "$d/result.csv" ] || continue
		[ "$(awk -F, 'NR == 2 { print $1 }' "$d/result.csv")" = "$2" ] || continue
		awk -F, -v e="$3" 'NR == 1 || ($2 != "" && $2 > 0 && $1 + 1 <= e)' "$d/series.csv" >"$4"
		return 0
	done
	return 1
}

# fig_force_time_plot RUNS_DIR TMP END PNG YLABEL TITLE_END TAG LABEL COLOURS
# [AT...]: the forces modules' second picture, PNG: the force per second
# through a whole run of END s, one run per setting (the first column of
# TMP/summary; fig_force_series into TMP/time.TAG<setting>.csv), each titled
# by the function LABEL given the setting, in the COLOURS (a blank-separated
# list, in turn); a dotted line at each AT s and at END/3 (the walls closed),
# a solid one at 2 END/3 (the switch to the oscillator). No run with a
# series: said, and no picture.
fig_force_time_plot() {
	local runs=$1 t=$2 end=$3 png=$4 ylabel=$5 title=$6 tag=$7 label=$8 colours series=() v x i=0
	read -r -a colours <<<"$9"
	shift 9
	for v in $(cut -d' ' -f1 "$t/summary"); do
		fig_force_series "$runs" "$v" "$end" "$t/time.$tag$v.csv" || continue
		fig_series series "$t/time.$tag$v.csv" 1 "using 1:2 with lines lw 1.5 lc rgb '${colours[$((i % ${#colours[@]}))]}' title '$("$label" "$v")'"
		i=$((i + 1))
	done
	[ ${#series[@]} -gt 0 ] || { echo "$FIG_NAME: no series.csv in the runs: no time plot" >&2; return 0; }
	{
		fig_gp_head 900 600
		echo "set output '$png'"
		echo "set termoption noenhanced"
		echo "set logscale y"
		echo "set xlabel 'simulated time (s)'"
		echo "set ylabel '$ylabel'"
		echo "set title 'Walls close 10-$((end / 3)) s; clock until $((2 * end / 3)) s, oscillator after$title'"
		echo "set key bottom left"
		for x in "$@" $((end / 3)); do echo "set arrow from $x, graph 0 to $x, graph 1 nohead dt 3 lc rgb 'gray'"; done
		echo "set arrow from $((2 * end / 3)), graph 0 to $((2 * end / 3)), graph 1 nohead lw 2 lc rgb 'black'"
		fig_plot "${series[@]}"
	} >"$t/time.gp"
	fig_gnuplot "$t/time.gp"
}

# fig_summary_csv SUMMARY CSV HEADER: a merge's table of one row per setting,
# written by the shell's printf (blank-separated, so fig_spread's empty fields
# stay in their columns), made a CSV for gnuplot: SUMMARY.csv under HEADER.
# An empty SUMMARY: no run of CSV to summarize, exit 1 saying so.
fig_summary_csv() {
	[ -s "$1" ] || fig_die "no runs to summarize in $2"
	{ echo "$3"; tr ' ' ',' <"$1"; } >"$1.csv"
}

fig_need_gnuplot() {
	command -v "${GNUPLOT:-gnuplot}" >/dev/null 2>&1 ||
		fig_die "gnuplot is not installed: no figure can be drawn (Debian: apt-get install gnuplot-nox; or scripts/deps.sh)"
}

# fig_merge_begin FIGDIR: what every merge does first. FIG_TMP holds the
# merge's intermediate files (kept with FIG_KEEP=1); the merge writes its
# figure, data and section into FIG_OUT, a private folder inside FIGDIR, and
# fig_merge_end moves them into FIGDIR by rename: gnuplot's `set output` and
# the shell's > never meet a link or FIFO someone left under those names.
fig_merge_begin() {
	fig_need_gnuplot
	fig_run_dir "$1"
	FIG_MERGE_DIR=$1
	FIG_TMP=$(mktemp -d "${TMPDIR:-/tmp}/fig-$FIG_NAME.XXXXXX") || fig_die "no temporary directory"
	FIG_OUT=$(mktemp -d "$1/.merge-$FIG_NAME.XXXXXX") || fig_die "cannot write in $1"
	if [ "${FIG_KEEP:-0}" = 1 ]; then trap 'rm -rf "$FIG_OUT"' EXIT
	else trap 'rm -rf "$FIG_TMP" "$FIG_OUT"' EXIT; fi
}
# fig_merge_args RUNS_DIR FIGDIR: a merge's beginning: its two arguments
# checked (else the usage line, exit 2), then fig_merge_begin FIGDIR.
fig_merge_args() {
	[ $# -eq 2 ] || fig_usage "merge RUNS_DIR FIGDIR"
	fig_merge_begin "$2"
}
# fig_merge_runs RUNS_DIR FIGDIR: the same where the module merges all its
# runs' rows into one table: FIG_OUT/NAME.csv the rows (fig_results, sorted).
fig_merge_runs() {
	fig_merge_args "$@"
	fig_results "$1" sorted >"$FIG_OUT/$FIG_NAME.csv"
}
fig_merge_end() {
	outdir_publish "$FIG_OUT" "$FIG_MERGE_DIR" || fig_die "could not move the figure into $FIG_MERGE_DIR"
}

# The figures' look: one size of type, a light grid, the key inside; the
# paper's colours are not known here, so gnuplot's first ones.
fig_gp_head() {
	cat <<EOG
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
EOG
}

fig_gnuplot() {
	"${GNUPLOT:-gnuplot}" "$1" >"$1.log" 2>&1 || { echo "$FIG_NAME: gnuplot failed on $1: $(tail -n 3 "$1.log")" >&2; return 1; }
	# gnuplot goes on after most errors: a script that drew nothing says so here
	if grep -qiE '(^|[^a-z])(error|warning: skipping)' "$1.log"; then
		echo "$FIG_NAME: gnuplot: $(grep -m1 -iE 'error|warning: skipping' "$1.log") ($1.log)" >&2
		return 1
	fi
}

# fig_has CSV CONDITION: a row of CSV (after its header) where the awk
# CONDITION holds: a series that would draw something.
fig_has() { awk -F, "NR > 1 && ($2) { found = 1; exit } END { exit !found }" "$1"; }
# fig_series ARRAY CSV CONDITION SPEC: append "'CSV' every ::1 SPEC" (the
# header line skipped) to the array named ARRAY when fig_has CSV CONDITION:
# gnuplot's "warning: skipping data file with no valid points", which
# fig_gnuplot takes for a failure, never meets a series that draws nothing.
fig_series() {
	local -n _fs_list=$1
	fig_has "$2" "$3" && _fs_list+=("'$2' every ::1 $4")
	return 0
}
# fig_plot SPEC...: a gnuplot plot command of the series given (the modules
# pass only those fig_has found; an empty panel without any).
fig_plot() {
	[ $# -gt 0 ] || { echo "plot NaN notitle"; return; }
	local sep="plot " s
	for s in "$@"; do printf '%s%s' "$sep" "$s"; sep=$', \\\n  '; done
	echo
}

fig_theory() { "$FIG_BIN/undulate-analyze" --theory "$@"; }
# ---- the pair rig (pair, returnmap) ---------------------------------------------------
# Its scenario, and its robots' drive in every run of both modules: torque
# actuation through the current drive, as the paper's rig drove each joint
# with a motor current (docs/EXPERIMENTS.md); each module adds its own clock
# (sinusoid.*) to these.
FIG_PAIR_SCENARIO="$fig_top/sim-bridge/scenarios/pair-rig.scenario"
FIG_PAIR_DRIVE=(--daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current)

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

# ---- four robots in a channel (channel, channel-plane: the paper's Fig. 9) ------------
# Both modules' rows are "width_cm,nominal_dsep,seed," and then fig_pairs'
# fields: $5 the class, $6 the mean Δ, $9 the collisions in the final window,
# $13 the analyser's d̃, $14 its bound 2 asin(d̃). The row world's robots and
# the plane's are drawn and tabled alike, so that the two pages compare.

# The paper's channel trial, the same in both modules (the plane's page sets
# its numbers beside the row's): four robots in a channel of these widths
# (cm); 2 s on the clock sets each robot's random phase, then 30 s on the
# oscillator (the paper's trials: 30 s); the final window the last 5 s (4
# periods at 0.8 Hz). FIG_CHANNEL_SWEPT_M, the nominal d̃'s unit: the width a
# row robot sweeps, 2 x 0.1865 m/rad x 0.8 rad.
FIG_CHANNEL_WIDTHS_CM="16 18 20 22 24"
FIG_CHANNEL_SWITCH=2
FIG_CHANNEL_SECONDS=32
FIG_CHANNEL_WINDOW=5
FIG_CHANNEL_SWEPT_M=0.2984

# fig_channel_demo OUTDIR WIDTH_CM SEED SCENARIO ARG...: one trial (fig_demo)
# in sim-bridge/scenarios/SCENARIO with the channel WIDTH_CM wide, the ARGs
# added; FIG_CHANNEL_NOMINAL its nominal d̃. 1 when the run failed.
fig_channel_demo() {
	local out=$1 width=$2 seed=$3 scenario=$4 spacing
	shift 4
	# the spacing (m) and from it the nominal d~, in one awk
	read -r spacing FIG_CHANNEL_NOMINAL < <(awk -v w="$width" -v s="$FIG_CHANNEL_SWEPT_M" \
		'BEGIN { d = sprintf("%.4f", w / 100); printf "%s %.4f\n", d, d / s }')
	fig_demo "$out" --scenario "$fig_top/sim-bridge/scenarios/$scenario" --seconds "$FIG_CHANNEL_SECONDS" \
		--switch-at "$FIG_CHANNEL_SWITCH" --seed "$seed" --window "$FIG_CHANNEL_WINDOW" --set "world.spacing=$spacing" "$@"
}

# fig_channel_series CSV TMP WORD PS SWEPT_M: the figure's series, one a line
# (for mapfile): the compatibility curve from the theory's own code
# (tools/analyze/theory.c, the analyser's per-pair compat_limit: "2 asin(d̃):
# the compatibility WORD"), anti-phase, then each width's pairs, final |Δ|
# against their d̃, points of size PS, a colour a width, titled with the
# nominal d̃ (width / SWEPT_M). 1 when the theory failed.
fig_channel_series() {
	local csv=$1 t=$2 w i=0 colors=('#1f77b4' '#2ca02c' '#ff7f0e' '#d62728' '#9467bd')
	fig_theory curves --points 401 >"$t/curves.csv" || return 1
	echo "'$t/curves.csv' every ::1 using 1:2 with lines lw 2 lc rgb 'black' title '2 asin(d̃): the compatibility $3'"
	echo "pi with lines dt 2 lc rgb 'gray' title 'anti-phase'"
	for w in $(awk -F, 'NR > 1 { print $1 }' "$csv" | sort -gu); do
		fig_has "$csv" "\$1 == $w && \$13 != \"nan\"" &&
			echo "'$csv' every ::1 using (\$1 == $w ? \$13 : 1/0):(abs(\$6)) with points pt 7 ps $4 lc rgb '${colors[$((i % 5))]}' title '$w cm (d̃ $(awk -v w="$w" -v s="$5" 'BEGIN { printf "%.2f", w / 100 / s }') nominal)'"
		i=$((i + 1))
	done
}

# fig_channel_axes WINDOW: the figure's axes, after its title and labels:
# final |Δ| (the mean over the last WINDOW s) from 0 to π, d̃ from 0.
fig_channel_axes() {
	echo "set ylabel 'final |Δ| (rad), mean over the last $1 s'"
	echo "set key top left"
	echo "set yrange [0:3.3]"
	echo "set xrange [0:*]"
	echo "set ytics ('0' 0, 'π/4' pi/4, 'π/2' pi/2, '3π/4' 3*pi/4, 'π' pi)"
}

# fig_channel_widths CSV: the table's numbers, a line per width (sorted):
# width, nominal d̃, pairs, pairs at or below the bound + 0.1 rad (the
# analyser's margin), above it, anti-phase, still colliding in the final
# window, the d̃ at the end (median, least, greatest) and the final |Δ|'s median.
fig_channel_widths() {
	awk -F, 'NR > 1 {
			w = $1; n[w]++; nom[w] = $2; d = $6 < 0 ? -$6 : $6
			dd[w] = dd[w] " " $13; ad[w] = ad[w] " " d
			if ($14 != "nan" && d <= $14 + 0.1) below[w]++
			else above[w]++
			if ($5 == "anti-phase") anti[w]++
			if ($9 > 0) coll[w]++
		}
		END { for (w in n) printf "%s %s %d %d %d %d %d|%s|%s\n", w, nom[w], n[w], below[w], above[w], anti[w], coll[w], dd[w], ad[w] }' "$1" |
		sort -g | while IFS='|' read -r head dlist alist; do
			echo "$head $(fig_spread "$dlist") $(tr ' ' '\n' <<<"$alist" | grep . | fig_median)"
		done
}

# fig_channel_table CSV LAST [above]: the page's table of fig_channel_widths,
# a row per width; LAST heads the column of pairs still colliding in the
# final window; with `above`, a column of the pairs above the bound too.
fig_channel_table() {
	local above=${3:-} w nom n below nabove anti coll dmed dmin dmax amed
	echo "| width | d̃ nominal | pairs | d̃ at the end, median (range) | final \|Δ\| median | at or below 2 asin(d̃) + 0.1 |${above:+ above it |} anti-phase | $2 |"
	echo "|---|---|---|---|---|---|${above:+---|}---|---|"
	fig_channel_widths "$1" | while read -r w nom n below nabove anti coll dmed dmin dmax amed; do
		printf '| %s cm | %.2f | %d | %.2f (%.2f-%.2f) | %.2f rad | %d of %d |' "$w" "$nom" "$n" "$dmed" "$dmin" "$dmax" "$amed" "$below" "$n"
		[ -n "$above" ] && printf ' %d |' "$nabove"
		printf ' %d | %d |\n' "$anti" "$coll"
	done
}

# fig_channel_counts CSV: the runs (a width and a seed each) and the
# neighbouring pairs (its rows) in CSV.
fig_channel_counts() {
	echo "$(awk -F, 'NR > 1 { print $1 " " $3 }' "$1" | sort -u | wc -l) $(($(wc -l <"$1") - 1))"
}

# fig_channel_trials CSV: the most runs (width and seed) at any one width:
# at most the quick set's trials a width, the page says it is the quick set.
fig_channel_trials() {
	awk -F, 'NR > 1 { t[$1 " " $3] = 1 } END { for (k in t) { split(k, a, " "); n[a[1]]++ } for (w in n) if (n[w] > m) m = n[w]; print m + 0 }' "$1"
}

# ---- the oscillator tuned for the plane world's robot -------------------------------
# The daemon's default oscillator was tuned on the row's joint (one link
# swinging against its gearbox); on the plane's three-link robot, whose
# links swim in drag, it runs at 1.04 Hz and 0.72-0.79 rad. The plane modules
# (swimmer, channel-plane) run the robots with FIG_PLANE_CONF, a file that
# `undulated --tune` made in lockstep on one robot of the plane world
# (fig_plane_tune; the file's head says when and what it measured), so that
# every run of every module has the same, committed parameters.
FIG_PLANE_CONF=${FIG_PLANE_CONF:-"$fig_top/figures/plane-oscillator.conf"}
# The keys the tuner sets (and the clock's gait it measured): what a
# configuration of the plane robot needs beyond the daemon's defaults.
FIG_PLANE_KEYS="robot.servo_lead_s joint.1.k joint.1.c joint.1.mu joint.1.lambda joint.1.coupling_phase joint.2.k joint.2.c joint.2.mu joint.2.lambda joint.2.coupling_phase sinusoid.amplitude sinusoid.frequency"
# The paper holds its robots' joints 2 pi / 3 apart; the oscillator's
# coupling on the angle alone gives 104 deg on the plane robot. coupling_phase
# +THETA on joint 1 and -THETA on joint 2 turns the lag (daemon/CONTROL.md,
# "The joints' lag": +-0.30 rad gives 120 deg on the plane robot with the
# default oscillator); the tuner runs with it, so k and mu are tuned with it.
FIG_PLANE_COUPLING=${FIG_PLANE_COUPLING:-0.30}

fig_ini() {
	awk -v sec="[$2]" -v key="$3" '/^\[/ { in_sec = ($1 == sec); next }
		in_sec && $1 == key && $2 == "=" { print $3; exit }' "$1"
}

# fig_plane_sets [CONF]: "--daemon-set" and "SEC.KEY=VALUE" on lines of their
# own, for mapfile; exit 1 naming a key the file lacks.
fig_plane_sets() {
	local conf=${1:-$FIG_PLANE_CONF} k sec key v
	[ -f "$conf" ] || { echo "$FIG_NAME: no tuned configuration $conf (figures/lib.sh, fig_plane_tune)" >&2; return 1; }
	# every key's value as fig_ini finds it (the first "KEY = VALUE" in its
	# section, VALUE's first word), in one awk rather than one per key: a
	# plane run reads 13; "K V" a line, in FIG_PLANE_KEYS' order
	local values
	values=$(awk -v keys="$FIG_PLANE_KEYS" 'BEGIN { n = split(keys, k, " ")
			for (i = 1; i <= n; i++) { s = k[i]; sub(/\.[^.]*$/, "", s); sec[i] = "[" s "]"; key[i] = k[i]; sub(/.*\./, "", key[i]) } }
		/^\[/ { cur = $1; next }
		{ for (i = 1; i <= n; i++) if (!(i in v) && cur == sec[i] && $1 == key[i] && $2 == "=") v[i] = $3 }
		END { for (i = 1; i <= n; i++) print k[i], v[i] }' "$conf")
	while read -r k v; do
		sec=${k%.*} key=${k##*.}
		[ -n "$v" ] || { echo "$FIG_NAME: $conf has no [$sec] $key" >&2; return 1; }
		printf -- '--daemon-set\n%s=%s\n' "$k" "$v"
	done <<<"$values"
}

# fig_plane_tune OUT [SEED] [TUNE_S]: one plane robot (two joints, no walls:
# sim-bridge/scenarios/plane-swimmer.scenario) on its own simulated bus, the
# tuner in lockstep (0.8 Hz, 0.8 rad, coupling_phase +-FIG_PLANE_COUPLING,
# the daemon's defaults otherwise); OUT
# gets the tuned keys under the tuner's own comments. The work folder is
# OUT.d, removed after.
fig_plane_tune() {
	local out=$1 seed=${2:-1} budget=${3:-200} dir url rc=0 sim i k sec key
	dir="$out.d"
	rm -rf "$dir" && mkdir -p "$dir" || fig_die "cannot create $dir"
	url=$(fig_lcm_url "$dir")
	${FIG_SESSION[@]+"${FIG_SESSION[@]}"} "$FIG_BIN/undulate-sim" --scenario "$fig_top/sim-bridge/scenarios/plane-swimmer.scenario" \
		--set "sim.seed=$seed" --link-dir "$dir" --lockstep "$dir/clock" --duration $((budget + 60)) --lcm-url "$url" >"$dir/sim.log" 2>&1 </dev/null &
	sim=$!
	for i in $(seq 500); do
		grep -q 'ready:' "$dir/sim.log" 2>/dev/null && break
		kill -0 "$sim" 2>/dev/null || break
		sleep 0.02
	done
	"$FIG_BIN/undulated" --tune --lockstep "$dir/clock" --port "$dir/r1" --ids 1,2 --robot r1 --lcm-url "$url" \
		--set "joint.1.coupling_phase=$FIG_PLANE_COUPLING" --set "joint.2.coupling_phase=-$FIG_PLANE_COUPLING" \
		--tune-time "$budget" --out "$dir/tuned.conf" >"$dir/tune.log" 2>&1 </dev/null || rc=$?
	wait "$sim" 2>/dev/null
	if [ "$rc" -ne 0 ] || [ ! -f "$dir/tuned.conf" ]; then
		echo "$FIG_NAME: tuning the plane robot failed (undulated --tune exit $rc): $(grep -m1 -E '^tune: (not|gave)|error' "$dir/tune.log" | cut -c1-200)" >&2
		return 1
	fi
	{
		echo "# The oscillator of the plane world's three-link robot, for the figures"
		echo "# (figures/lib.sh: FIG_PLANE_CONF). Made by fig_plane_tune: undulated --tune"
		echo "# in lockstep on one robot of the plane world (two AX-12A joints, links of"
		echo "# 18.65 cm, drag, no walls; sim seed $seed), targets 0.8 Hz and 0.8 rad, with"
		echo "# coupling_phase +$FIG_PLANE_COUPLING / -$FIG_PLANE_COUPLING rad for the paper's 2 pi / 3 between the joints:"
		grep -E '^# (r1: written|target|the parameters)' "$dir/tuned.conf"
		grep '^tune: done' "$dir/tune.log" | sed 's/; written to .*//; s/^tune: done in [0-9.]* s (\(.*\)):/# after \1:/'
		echo "# Only the tuned keys; everything else is the daemon's default."
		for sec in robot joint.1 joint.2 sinusoid; do
			echo
			echo "[$sec]"
			for k in $FIG_PLANE_KEYS; do
				[ "${k%.*}" = "$sec" ] || continue
				key=${k##*.}
				echo "$key = $(fig_ini "$dir/tuned.conf" "$sec" "$key")"
			done
		done
	} | outdir_put "$out" || return 1
	rm -rf "$dir"
}
