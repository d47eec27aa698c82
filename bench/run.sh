#!/usr/bin/env bash
# bench/run.sh — the benchmark suite behind `make bench`.
#
# Runs the real programs (undulate-sim, undulated, lcm-logger, cyclictest) and
# small measuring helpers built here from bench/*.c, prints one markdown report
# and writes it to $BUILD/bench.md. Figures are printed next to the budgets in
# bench/README.md; nothing is asserted: the exit status says only whether the suite
# could run. See bench/README.md for what each figure means.
#
# Knobs (environment): BENCH_LOOP_S (loop timing window per policy, 20),
# BENCH_WINDOW_S (daemon bus-time windows, 5), BENCH_CYCLES (protocol-level
# bus cycles per configuration, 300), BENCH_CAP_S (simulator-only capacity
# runs, 8), BENCH_FLEET_S (20 robots with 20 daemons, 15), BENCH_CG_S (the
# daemon under callgrind, 3), BENCH_LOCK_REPS (lockstep runs per scenario, 3),
# BENCH_ONLY (a list of sections to run, e.g.
# "loop bus"; default all: loop bus missing cap plane codec cg web lockstep model),
# BENCH_MODEL_REPS (undulate-model runs per setting, 3),
# KEEP_BENCH_DIR=1 keeps the logs.
set -u
top=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$top" || exit 1
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$top/$BUILD" ;; esac
BIN=$BUILD/bin
HB=$BUILD/bench
SIM=$BIN/undulate-sim
DMN=$BIN/undulated
OUT=$BUILD/bench.md

LOOP_S=${BENCH_LOOP_S:-20}
WINDOW_S=${BENCH_WINDOW_S:-5}
CYCLES=${BENCH_CYCLES:-300}
CAP_S=${BENCH_CAP_S:-8}
CG_S=${BENCH_CG_S:-3}
FLEET_S=${BENCH_FLEET_S:-15}
ONLY=${BENCH_ONLY:-loop bus missing rate cap plane codec cg web lockstep model}
MODEL_REPS=${BENCH_MODEL_REPS:-3}
LOCK_REPS=${BENCH_LOCK_REPS:-3}
WEB_S=${BENCH_WEB_S:-15}
WEB_ROBOTS=20
# The daemon ramps into its mode over 1.5 s after start: measure after it.
RAMP_S=2
# Multicast ports of the benchmark (7900-7949): one per run, so runs never
# hear each other's messages.
PORT_LOOP_OTHER=7900 PORT_LOOP_FIFO=7901 PORT_BUS=7902 PORT_MISSING=7903 PORT_CAP=7904 PORT_FLEET=7905 PORT_CG=7906 PORT_WEB=7907
PORT_LOCK=7908 PORT_LOOP_X=7909
FIFO_PRIORITY=80
# The simulator's own real-time option (below the daemons' priority above).
SIM_RT_PRIORITY=10
# Start attempts per daemon (see start_daemon).
START_TRIES=3

T=$(mktemp -d "${TMPDIR:-/tmp}/undulate-bench.XXXXXX")
CLK_TCK=$(getconf CLK_TCK)

# ---- processes: started here, stopped by PID --------------------------------------
declare -A PID
start() {
	local name=$1
	shift
	"$@" >"$T/$name.log" 2>&1 &
	PID[$name]=$!
}
stop() {
	local pid=${PID[$1]:-}
	[ -n "$pid" ] || return 0
	kill -TERM "$pid" 2>/dev/null
	for _ in $(seq 150); do kill -0 "$pid" 2>/dev/null || break; sleep 0.02; done
	kill -KILL "$pid" 2>/dev/null
	wait "$pid" 2>/dev/null
	unset "PID[$1]"
}
cleanup() {
	local n
	for n in "${!PID[@]}"; do stop "$n"; done
	if [ -n "${KEEP_BENCH_DIR:-}" ]; then echo "bench: logs kept in $T" >&2; else rm -rf "$T"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# wait_ready NAME REGEX TIMEOUT_S: poll NAME's log; fail early if NAME died.
wait_ready() {
	local name=$1 re=$2 deadline=$(($(date +%s%N) + ${3:-10} * 1000000000))
	until grep -qE "$re" "$T/$name.log" 2>/dev/null; do
		kill -0 "${PID[$name]}" 2>/dev/null || return 1
		[ "$(date +%s%N)" -lt "$deadline" ] || return 1
		sleep 0.02
	done
}
wait_file() {
	local deadline=$(($(date +%s%N) + ${2:-10} * 1000000000))
	until [ -e "$1" ]; do
		[ "$(date +%s%N)" -lt "$deadline" ] || return 1
		sleep 0.02
	done
}
# Why a process did not come up: the last line it printed.
why() { tail -n 1 "$T/$1.log" 2>/dev/null | tr '|' '/' | cut -c1-240; }

# start_daemon NAME CMD...: start an undulated and wait for its ready line. Its
# start-up scan gives up when servos stay silent for a few timeouts, which a
# stall of the loaded machine can cause: it is started again (as systemd's
# Restart=on-failure would), up to START_TRIES times. RETRIES says how often.
start_daemon() {
	local name=$1 try
	shift
	RETRIES=0
	for try in $(seq 1 "$START_TRIES"); do
		start "$name" "$@"
		wait_ready "$name" 'ready:' 30 && return 0
		cp "$T/$name.log" "$T/$name.try$try.log"
		stop "$name"
		[ "$try" -lt "$START_TRIES" ] && RETRIES=$((RETRIES + 1))
	done
	return 1
}
# daemon_window NAME SETTLE_S WINDOW_S LCMLOG OUT: after SETTLE_S, WINDOW_S
# seconds of daemon dmn-NAME's run (its LCM logged by log-NAME into LCMLOG);
# both stopped, logstat's figures of the window into OUT
daemon_window() {
	local t0 t1
	sleep "$2"
	t0=$(now_us)
	sleep "$3"
	t1=$(now_us)
	stop "dmn-$1"; stop "log-$1"
	"$HB/logstat" --from-us "$t0" --to-us "$t1" "$4" >"$5"
	echo "start_retries $RETRIES" >>"$5"
	overrun_split "$T/dmn-$1.log" >>"$5"
}
# overrun_split DAEMON_LOG: the daemon's exit line on its overruns (the whole
# run, start-up included) as ov_total, ov_skipped (periods skipped: the loop
# woke a period or more late), ov_cut (cycles still on the bus at the next
# tick) and ov_cut_late (of those, begun over half a period late); nothing
# when it had none
overrun_split() {
	sed -n 's/.*overruns: \([0-9]*\) in [0-9]* cycles: \([0-9]*\) period(s) skipped.*, \([0-9]*\) cycle(s) still on the bus at the next tick (\([0-9]*\) of them.*/ov_total \1\nov_skipped \2\nov_cut \3\nov_cut_late \4/p' "$1" 2>/dev/null
}
# os_floor OUT PERIOD_US SECONDS SLACK_US: what this machine gives any thread
# at that period: cyclictest alone (no simulator, no daemon beside it), at the
# daemon's policy (SCHED_FIFO FIFO_PRIORITY where permitted), for as long as
# the daemon's window. Into OUT: ct_n (wake-ups), ct_slack (later than
# SLACK_US: the period less the cycle's bus time, too late for the cycle to
# fit), ct_period (a whole period or more late), ct_max (µs). An overrun count
# of the same order is the machine's, not the daemon's or the bus's.
os_floor() {
	local out=$1 p=$2 secs=$3 slack=$4 pol=(--policy=other)
	chrt -f 1 true 2>/dev/null && pol=(--policy=fifo -p "$FIFO_PRIORITY")
	cyclictest -q -m -i "$p" -l $((secs * 1000000 / p)) -h 20000 "${pol[@]}" >"$out.ct" 2>&1 || {
		echo "ct_status not measured: cyclictest failed ($(tail -n1 "$out.ct"))" >>"$out"
		return 0
	}
	awk -v s="$slack" -v p="$p" '/^[0-9]/ { n += $2; if ($1 + 0 > s) a += $2; if ($1 + 0 >= p) b += $2 }
		/Max Latencies/ { m = $NF + 0 } /Histogram Overflows/ { o = $NF + 0 }
		END { printf "ct_n %d\nct_slack %d\nct_period %d\nct_max %d\n", n + o, a + o, b + o, m }' "$out.ct" >>"$out"
}
# retried: " (N start-up retried)" or nothing
retried() { [ "${1:-0}" != nan ] && [ "${1:-0}" -gt 0 ] && echo "; $1 start-up retried"; }

# TEST_PORT_OFFSET moves every port, as it does the tests': two runs side by side do not hear each other
url() { echo "udpm://239.255.76.67:$(($1 + ${TEST_PORT_OFFSET:-0}))?ttl=0"; }
now_us() { echo $(($(date +%s%N) / 1000)); }
# utime + stime of a process, in clock ticks (fields 14 and 15 of stat; the
# name field may hold spaces, so count from after its closing parenthesis).
cpu_ticks() { sed 's/.*) //' "/proc/$1/stat" 2>/dev/null | awk '{ print $12 + $13 }'; }
hwm_kb() { awk '/^VmHWM:/ { print $2 }' "/proc/$1/status" 2>/dev/null; }
# cpu_pct TICKS0 TICKS1 US0 US1 -> percent of one core
cpu_pct() { awk -v a="$1" -v b="$2" -v t0="$3" -v t1="$4" -v hz="$CLK_TCK" \
	'BEGIN { if (a == "" || b == "" || t1 <= t0) print "nan"; else printf "%.2f", 100 * (b - a) / hz / ((t1 - t0) / 1e6) }'; }
policy_of() { chrt -p "$1" 2>/dev/null | awk -F': ' '/policy/ { p = $2 } /priority/ { q = $2 } END { print p (q > 0 ? " " q : "") }'; }

# v FILE KEY: a "key value" figure from a helper's output ("nan" if absent)
v() { awk -v k="$2" '$1 == k { print $2; found = 1; exit } END { if (!found) print "nan" }' "$1" 2>/dev/null || echo nan; }
# p50/p99/max (nearest rank) of the numbers in a file, one a line
pctl() {
	sort -n "$1" | awk '{ x[NR] = $1 }
		function rank(p,  r) { r = int(p * NR); if (r < p * NR) r++; return r < 1 ? 1 : r }
		END { if (NR == 0) print "nan nan nan"; else print x[rank(0.5)], x[rank(0.99)], x[NR] }'
}
# fmt VALUE [DECIMALS]: a number for the table ("–" when missing)
fmt() { awk -v x="$1" -v d="${2:-0}" 'BEGIN { if (x == "nan" || x == "" || x == "-nan") print "–"; else printf "%.*f", d, x }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (a == "nan" || b == "nan" || a == "" || b == "" || b + 0 == 0) print "–"; else printf "%.2f×", a / b }'; }
ids_upto() { seq -s, 1 "$1"; }
progress() { echo "bench: $*" >&2; }
wants() { [[ " $ONLY " == *" $1 "* ]]; }

# ---- the helpers ------------------------------------------------------------------
build_helpers() {
	local cflags="-std=c11 -D_DEFAULT_SOURCE -D_XOPEN_SOURCE=700 -O2 -g -Wall -Wextra -Wshadow
	              -Wmissing-prototypes -Wstrict-prototypes -Wpointer-arith -Wcast-qual -Wundef -Wvla
	              -Wformat-security -Werror"
	local inc libs
	inc="-I. -Icommon -Iprotocol -Iprotocol/io -I$BUILD/lcmgen $(pkg-config --cflags lcm 2>/dev/null)"
	# libprotocol uses libcommon (number parsing), so it comes after it
	libs="$BUILD/lib/libprotocol.a $BUILD/lib/libcommon.a $BUILD/lib/liblcmtypes.a $(pkg-config --libs lcm libserialport inih 2>/dev/null) -lm"
	mkdir -p "$HB"
	local p
	for p in logstat buscycle codec simctl webpub; do
		# shellcheck disable=SC2086 # word splitting of the flag lists is wanted
		${CC:-cc} $cflags $inc "bench/$p.c" -o "$HB/$p" $libs || return 1
	done
}

# ---- undulate-web: 20 robots at 100 Hz, one browser -------------------------------
# webpub publishes 20 robots' STATE and SIM.TRUTH at 100 Hz (2100 messages/s);
# a WebSocket client (tests/integration/web_cdp.py frames) reads every frame.
# The server's CPU over WEB_S seconds; the budget: 5 % of one core. Twice:
# SIM.TRUTH of the row (bodies only), then of the plane (each robot's three
# links, four walls, ten touching pairs a message: what the world view sends).
# web_run WORLD ("row" or "plane"): writes "pct frames/s kB/s bytes/frame" to
# $T/web-WORLD/result, or the reason it could not measure (status 1). Not in
# a subshell: the processes it starts stay in PID for the cleanup.
web_run() {
	local world=$1 fox=${2:-} u d=$T/web-$1${2:+-fox} port wpid t0 c0 t1 c1 pct frames bytes secs fpid=
	u=$(url "$PORT_WEB")
	mkdir -p "$d"
	start webpub "$HB/webpub" "$u" "$WEB_ROBOTS" $((WEB_S + 10)) $([ "$world" = plane ] && echo plane)
	start web "$BIN/undulate-web" --listen 127.0.0.1:0 --lcm-url "$u" --read-only
	if ! wait_ready web 'listening on' 10 || ! wait_ready webpub 'ready' 10; then
		echo "not measured: $(why web)" >"$d/result"
		stop web; stop webpub
		return 1
	fi
	port=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/web.log")
	sleep 2  # every robot heard, the first (whole-history) frame out of the way
	wpid=${PID[web]}
	# with fox: a Foxglove client subscribed to every channel beside the page's
	[ -n "$fox" ] && { python3 tests/integration/web_cdp.py fox 127.0.0.1 "$port" "$WEB_S" >"$d/fox" 2>&1 & fpid=$!; }
	t0=$(now_us) c0=$(cpu_ticks "$wpid")
	python3 tests/integration/web_cdp.py frames 127.0.0.1 "$port" "$WEB_S" >"$d/frames" 2>&1
	t1=$(now_us) c1=$(cpu_ticks "$wpid")
	[ -n "$fpid" ] && wait "$fpid"
	pct=$(cpu_pct "$c0" "$c1" "$t0" "$t1")
	frames=$(awk '/^FRAMES/ { print $2 }' "$d/frames")
	bytes=$(awk '/^FRAMES/ { print $4 }' "$d/frames")
	secs=$(awk '/^FRAMES/ { print $6 }' "$d/frames")
	stop web; stop webpub
	awk -v p="$pct" -v f="${frames:-0}" -v b="${bytes:-0}" -v s="${secs:-0}" 'BEGIN {
		if (s > 0 && f > 0) printf "%s %.1f %.0f %.0f\n", p, f / s, b / s / 1024, b / f; else print "nan nan nan nan" }' \
		>"$d/result"
}

section_web() {
	local world pct rate kbs per
	if [ ! -x "$BIN/undulate-web" ]; then
		sum "undulate-web CPU, 20 robots at 100 Hz, one browser" "≤ 5 % of a core" "not measured: not built"
		return 0
	fi
	say "## undulate-web"
	say ""
	local run fox what
	for run in row plane plane+fox; do
		world=${run%+fox} fox=; [ "$run" != "$world" ] && fox=fox
		what="one browser"; [ -n "$fox" ] && what="one browser and one Foxglove client on every channel"
		progress "web: undulate-web with $WEB_ROBOTS robots at 100 Hz ($world), $what, ${WEB_S} s"
		if ! web_run "$world" $fox; then
			sum "undulate-web CPU, 20 robots at 100 Hz ($world), $what" "≤ 5 % of a core" \
				"$(cat "$T/web-$world${fox:+-fox}/result")"
			continue
		fi
		read -r pct rate kbs per <"$T/web-$world${fox:+-fox}/result"
		sum "undulate-web CPU, 20 robots at 100 Hz ($world), $what" "≤ 5 % of a core" \
			"$(fmt "$pct" 2) % ($(fmt "$rate" 1) frames/s, $(fmt "$kbs") kB/s)"
		say "$WEB_ROBOTS robots' STATE and SIM.TRUTH of the $world at 100 Hz (bench/webpub.c), one WebSocket client"
		say "reading every frame for ${WEB_S} s: server CPU $(fmt "$pct" 2) % of one core, $(fmt "$rate" 1) frames/s,"
		say "$(fmt "$kbs") kB/s, $(fmt "$per") bytes a frame."
		[ -n "$fox" ] && say "Beside it a Foxglove client (foxglove.websocket.v1, web_cdp.py fox): $(cat "$T/web-$world-fox/fox")."
		say ""
	done
}

# ---- report -----------------------------------------------------------------------
# The details, section by section; the summary collects one row per budget
# of bench/README.md and goes first.
REPORT=$T/report.md
SUMMARY=$T/summary.md
say() { printf '%s\n' "$*" >>"$REPORT"; }
sum() { printf '| %s | %s | %s |\n' "$1" "$2" "$3" >>"$SUMMARY"; }

# sim_logged NAME INFO WHAT LCM SIM_ARG...: undulate-sim (SIM_ARG..., on $u,
# quiet, the caller's model options) and an lcm-logger of its LCM into LCM;
# when the simulator does not start, "status not measured: WHAT (why)" into
# INFO and 1. ($u and $model are the caller's locals.)
sim_logged() {
	local name=$1 info=$2 what=$3 log=$4
	shift 4
	start "sim-$name" "$SIM" "$@" --lcm-url "$u" --quiet ${model[@]+"${model[@]}"}
	if ! wait_ready "sim-$name" 'ready:' 10; then
		echo "status not measured: $what ($(why "sim-$name"))" >"$info"
		stop "sim-$name"
		return 1
	fi
	start "log-$name" lcm-logger --lcm-url="$u" -f "$log"
	wait_file "$log" 10
}

# ---- 1 + 4: loop timing against cyclictest, daemon CPU and memory ------------------
# loop_run RUN MCAST_PORT [MODEL]: one robot (2 servos, return delay 0) on the
# simulated bus, its daemon at RUN's policy (fifo, else SCHED_OTHER), cyclictest
# at the same policy for LOOP_S seconds meanwhile; MODEL: X servos of that
# model (Protocol 2.0, 1 Mbps). Leaves $T/loop-RUN/{stat,cyclictest,info}.
loop_run() {
	local run=$1 pol=other d=$T/loop-$1 u model=()
	[ "$run" = fifo ] && pol=fifo
	[ -n "${3:-}" ] && model=(--model "$3" --baud 1000000)
	u=$(url "$2")
	mkdir -p "$d"
	echo "status ok" >"$d/info"
	sim_logged "$run" "$d/info" "undulate-sim did not start" "$d/run.lcm" --link "$d/r1" --ids 1,2 --return-delay 0 ||
		return 1
	local extra=()
	[ "$pol" = fifo ] && extra=(--set "robot.priority=$FIFO_PRIORITY" --set robot.mlockall=true)
	if ! start_daemon "dmn-$run" "$DMN" --port "$d/r1" --ids 1,2 --robot r1 --lcm-url "$u" --mode oscillator "${extra[@]}"; then
		echo "status not measured: undulated did not start in $START_TRIES tries ($(why "dmn-$run"))" >"$d/info"
		stop "log-$run"; stop "sim-$run"
		return 1
	fi
	echo "start_retries $RETRIES" >>"$d/info"
	sleep "$RAMP_S"  # the ramp-in: a fixed wait, not a readiness guess
	local dpid=${PID[dmn-$run]} ct=(--policy=other)
	[ "$pol" = fifo ] && ct=(--policy=fifo -p "$FIFO_PRIORITY")
	echo "policy $(policy_of "$dpid" | tr ' ' '/')" >>"$d/info"
	local t0 c0 t1 c1
	t0=$(now_us) c0=$(cpu_ticks "$dpid")
	start "ct-$run" cyclictest -q -v -m -i 10000 -l $((LOOP_S * 100)) "${ct[@]}"
	local ctrc=0
	wait "${PID[ct-$run]}" || ctrc=$?
	unset "PID[ct-$run]"
	t1=$(now_us) c1=$(cpu_ticks "$dpid")
	{
		echo "cpu_pct $(cpu_pct "$c0" "$c1" "$t0" "$t1")"
		echo "hwm_kb $(hwm_kb "$dpid")"
		echo "cyclictest_rc $ctrc"
	} >>"$d/info"
	stop "dmn-$run"; stop "log-$run"; stop "sim-$run"
	"$HB/logstat" --from-us "$t0" --to-us "$t1" "$d/run.lcm" >"$d/stat"
	# cyclictest -v: "thread: loop: latency_us"; loop 0 is before the first period
	awk '$1 == "0:" && $2 + 0 > 0 { print $3 }' "$T/ct-$run.log" >"$d/ct-lat"
	echo "ct $(pctl "$d/ct-lat") $(wc -l <"$d/ct-lat")" >>"$d/info"
}

# loop_label RUN: the table's name of a loop_run
loop_label() {
	case "$1" in
	fifo) echo "SCHED_FIFO $FIFO_PRIORITY" ;;
	xm) echo "SCHED_OTHER, XM430-W350 (2.0)" ;;
	*) echo "SCHED_${1^^}" ;;
	esac
}

section_loop() {
	progress "1/5 loop timing at 100 Hz: SCHED_OTHER, ${LOOP_S} s (undulated and cyclictest side by side)"
	loop_run other $PORT_LOOP_OTHER
	if chrt -f 1 true 2>/dev/null; then
		progress "1/5 loop timing at 100 Hz: SCHED_FIFO $FIFO_PRIORITY, ${LOOP_S} s"
		loop_run fifo $PORT_LOOP_FIFO
	else
		mkdir -p "$T/loop-fifo"
		echo "status not measured: SCHED_FIFO not permitted for this user (CAP_SYS_NICE / RLIMIT_RTPRIO)" \
			>"$T/loop-fifo/info"
	fi
	progress "1/5 loop timing at 100 Hz: SCHED_OTHER on two XM430-W350 (Protocol 2.0), ${LOOP_S} s"
	loop_run xm $PORT_LOOP_X xm430-w350
	say "## 1. Control loop timing at 100 Hz"
	say ""
	say "Wake-up lateness = how late a cycle starts after its deadline; period = time between cycle starts (µs)."
	say "Both programs run at the same time on the same machine, ${LOOP_S} s each, with the same policy."
	say "Budget: undulated's p99 lateness within 2× of cyclictest's."
	say ""
	say "| policy | program | samples | lateness p50 | p99 | max | period p50 | p99 | max | overruns | p99 vs cyclictest |"
	say "|---|---|---|---|---|---|---|---|---|---|---|"
	local pol d st
	for pol in other fifo xm; do
		d=$T/loop-$pol
		st=$(v "$d/info" status)
		local label
		label=$(loop_label "$pol")
		if [ "$st" != ok ]; then
			say "| $label | – | – | – | – | – | – | – | – | – | $(sed -n 's/^status //p' "$d/info") |"
			sum "loop wake-up lateness p99, $label" "≤ 2× cyclictest" "$(sed -n 's/^status //p' "$d/info")"
			continue
		fi
		local ct50 ct99 ctmax ctn dpol
		read -r _ ct50 ct99 ctmax ctn < <(grep '^ct ' "$d/info")
		dpol="$(v "$d/info" policy | tr '/' ' ')$(retried "$(v "$d/info" start_retries)")"
		say "| $label | undulated ($dpol) | $(v "$d/stat" all.n) | $(fmt "$(v "$d/stat" all.jitter_p50)") |" \
			"$(fmt "$(v "$d/stat" all.jitter_p99)") | $(fmt "$(v "$d/stat" all.jitter_max)") |" \
			"$(fmt "$(v "$d/stat" all.period_p50)") | $(fmt "$(v "$d/stat" all.period_p99)") |" \
			"$(fmt "$(v "$d/stat" all.period_max)") | $(v "$d/stat" all.overruns) |" \
			"$(ratio "$(v "$d/stat" all.jitter_p99)" "$ct99") |"
		if [ "$ctn" -gt 0 ]; then
			say "| $label | cyclictest | $ctn | $(fmt "$ct50") | $(fmt "$ct99") | $(fmt "$ctmax") | – | – | – | – | 1× |"
		else
			say "| $label | cyclictest | – | – | – | – | – | – | – | – | not measured: cyclictest exited" \
				"$(v "$d/info" cyclictest_rc) ($(why "ct-$pol")) |"
		fi
		sum "loop wake-up lateness p99, $label" "≤ 2× cyclictest" \
			"$(fmt "$(v "$d/stat" all.jitter_p99)") µs vs $(fmt "$ct99") µs: $(ratio "$(v "$d/stat" all.jitter_p99)" "$ct99"); $(v "$d/stat" all.overruns) overruns in $(v "$d/stat" all.n) cycles"
	done
	say ""
}

section_resources() {
	say "## 4. Daemon CPU and memory at 100 Hz (2 servos)"
	say ""
	say "CPU = utime + stime from /proc over the measurement window, in % of one core; the daemon's own"
	say "figure (bus_stats_t.cpu_percent, mean of its 1 s reports) beside it. Peak RSS = VmHWM."
	say "Budget: < 2 % of one core; no allocation after start-up."
	say ""
	say "| policy | CPU % (/proc) | CPU % (self-reported) | peak RSS (KiB) | control step p50 (µs) |"
	say "|---|---|---|---|---|"
	local pol d
	for pol in other fifo xm; do
		d=$T/loop-$pol
		if [ "$(v "$d/info" status)" != ok ]; then
			say "| $(loop_label "$pol") | $(sed -n 's/^status //p' "$d/info") | – | – | – |"
			[ "$pol" = other ] && sum "daemon CPU at 100 Hz" "< 2 % of one core" "$(sed -n 's/^status //p' "$d/info")"
			continue
		fi
		[ "$pol" = other ] && sum "daemon CPU at 100 Hz (SCHED_OTHER, 2 servos)" "< 2 % of one core" \
			"$(fmt "$(v "$d/info" cpu_pct)" 2) % (self-reported $(fmt "$(v "$d/stat" all.cpu_mean)" 2) %); peak RSS $(v "$d/info" hwm_kb) KiB"
		[ "$pol" = xm ] && sum "daemon CPU at 100 Hz (SCHED_OTHER, 2 XM430-W350, Protocol 2.0)" "< 2 % of one core" \
			"$(fmt "$(v "$d/info" cpu_pct)" 2) % (self-reported $(fmt "$(v "$d/stat" all.cpu_mean)" 2) %); peak RSS $(v "$d/info" hwm_kb) KiB"
		say "| $(loop_label "$pol") | $(fmt "$(v "$d/info" cpu_pct)" 2) | $(fmt "$(v "$d/stat" all.cpu_mean)" 2) |" \
			"$(v "$d/info" hwm_kb) | $(fmt "$(v "$d/stat" all.control_p50)") |"
	done
	say ""
}

# ---- 2: bus time per cycle against the wire-time floor -----------------------------
# buscycle_run N RD_US: the protocol-level cycle alone against a fresh sim bus.
buscycle_run() {
	local n=$1 rd=$2 name="bc-$1-$2" d=$T/bus
	local out=$d/$name.txt link=$d/$name.pty
	mkdir -p "$d"
	start "sim-$name" "$SIM" --link "$link" --ids "$(ids_upto "$n")" --return-delay "$rd" --quiet
	if ! wait_ready "sim-$name" 'ready:' 10; then
		echo "status not measured: the simulator refused $n servos on one bus ($(why "sim-$name"))" >"$out"
		stop "sim-$name"
		return 1
	fi
	if ! "$HB/buscycle" --port "$link" --ids "$(ids_upto "$n")" --cycles "$CYCLES" --margin-us "$MARGIN_US" \
		>"$out" 2>"$d/$name.err"; then
		echo "status not measured: buscycle failed ($(tail -n1 "$d/$name.err"))" >"$out"
	fi
	stop "sim-$name"
}

# daemon_bus_run N RD_US [MODEL]: undulated's own bus_us over WINDOW_S seconds
# (MODEL: the simulator's X servos at 1 Mbps, Protocol 2.0; results in db2-N-RD).
daemon_bus_run() {
	local n=$1 rd=$2 name="db-$1-$2" d=$T/bus u model=()
	[ -n "${3:-}" ] && { name="db2-$1-$2"; model=(--model "$3" --baud 1000000); }
	u=$(url $PORT_BUS)
	mkdir -p "$d"
	sim_logged "$name" "$d/$name" "the simulator refused $n servos on one bus" "$d/$name.lcm" --link "$d/$name.pty" \
		--ids "$(ids_upto "$n")" --return-delay "$rd" || return 1
	if start_daemon "dmn-$name" "$DMN" --port "$d/$name.pty" --ids "$(ids_upto "$n")" --robot "r$n" --lcm-url "$u" --mode oscillator; then
		daemon_window "$name" "$RAMP_S" "$WINDOW_S" "$d/$name.lcm" "$d/$name"
	else
		echo "status not measured: undulated did not start in $START_TRIES tries ($(why "dmn-$name"))" >"$d/$name"
		stop "log-$name"
	fi
	stop "sim-$name"
}

section_bus() {
	local n rd
	progress "2/5 bus time per cycle: protocol-level cycle, 2/6/18 servos x return delay 0/500 us, $CYCLES cycles each"
	for n in 2 6 18; do
		for rd in 0 500; do buscycle_run $n $rd; done
	done
	progress "2/5 bus time per cycle: undulated, ${WINDOW_S} s per configuration"
	for n in 2 6 18; do
		for rd in 0 500; do
			local why_not
			if why_not=$("$DMN" --port /dev/null --ids "$(ids_upto "$n")" --check-config 2>&1); then
				daemon_bus_run $n $rd
			else
				echo "status not measured: $(echo "$why_not" | head -n1 | cut -c1-120)" >"$T/bus/db-$n-$rd"
			fi
		done
	done
	say "## 2. Bus time per cycle at 1 Mbps (simulated bus)"
	say ""
	say "One cycle = READ(36,6) of every servo (8 + 12 bytes each, plus the return delay) and one"
	say "SYNC_WRITE of the goal positions (LEN = 3N + 4). Floor = wire time at 10 bits a byte + N × return"
	say "delay. Measured bus time ends when the SYNC_WRITE is handed to the port (it has no reply)."
	say "\`buscycle\` is that cycle alone over the protocol library; undulated's figure is its own bus_us."
	say "Budget: 2 servos, return delay 0: within 1.5× of the floor."
	say ""
	say "| servos | return delay (µs, register) | floor (µs) | buscycle p50 | p99 | max | p50/floor | undulated p50 | p99 | max | p50/floor | undulated overruns |"
	say "|---|---|---|---|---|---|---|---|---|---|---|---|"
	local f b db floor
	for n in 2 6 18; do
		for rd in 0 500; do
			b=$T/bus/bc-$n-$rd.txt db=$T/bus/db-$n-$rd
			floor=$(v "$b" floor_us)
			local bcells dcells
			if [ "$(v "$b" status)" = not ]; then
				bcells="$(sed -n 's/^status //p' "$b") | – | – | –"
			else
				bcells="$(v "$b" bus_p50) | $(v "$b" bus_p99) | $(v "$b" bus_max) | $(ratio "$(v "$b" bus_p50)" "$floor")"
			fi
			if [ "$(v "$db" status)" = not ]; then
				dcells="$(sed -n 's/^status //p' "$db") | – | – | – | –"
			else
				dcells="$(fmt "$(v "$db" all.bus_p50)") | $(fmt "$(v "$db" all.bus_p99)") | $(fmt "$(v "$db" all.bus_max)") |"
				dcells="$dcells $(ratio "$(v "$db" all.bus_p50)" "$floor") | $(v "$db" all.overruns)$(retried "$(v "$db" start_retries)")"
			fi
			# the floor needs no servo: compute it here when the sim could not run
			[ "$floor" = nan ] && floor=$(awk -v n="$n" -v rd="$rd" 'BEGIN { print n * (200 + rd) + (3 * n + 8) * 10 }')
			say "| $n | $rd ($((rd / 2))) | $floor | $bcells | $dcells |"
			if [ "$n" = 2 ] && [ "$rd" = 0 ]; then
				local what
				if [ "$(v "$db" status)" = not ]; then
					what="undulated: $(sed -n 's/^status //p' "$db")"
				else
					what="undulated p50 $(fmt "$(v "$db" all.bus_p50)") µs: $(ratio "$(v "$db" all.bus_p50)" "$floor") (p99 $(fmt "$(v "$db" all.bus_p99)") µs)"
				fi
				[ "$(v "$b" status)" = not ] || what="$what; the protocol cycle alone $(ratio "$(v "$b" bus_p50)" "$floor")"
				sum "bus time per cycle, 2 servos, return delay 0, 1 Mbps (simulated bus)" "≤ 1.5× the wire floor ($floor µs)" "$what"
			fi
		done
	done
	say ""
	bus2_table
}

# ---- 2b: the Protocol 2.0 cycle --------------------------------------------------
# bus2_run N: buscycle's 2.0 cycle (one SYNC_READ of present current, velocity
# and position, 10 bytes a servo, and one SYNC_WRITE of 4-byte goals) on the
# simulator's XM430-W350 servos when it has them (--model), else on
# buscycle's in-process fake X bus. Return delay 0, 1 Mbps.
bus2_run() {
	local n=$1 read=${2:-sync} d=$T/bus out=$T/bus/bc2-$1.txt
	[ "$read" = fast ] && out=$T/bus/bc2f-$1.txt
	mkdir -p "$d"
	if "$SIM" --model xm430-w350 --help 2>&1 | grep -q "unrecognized option '--model'"; then
		"$HB/buscycle" --port fake --protocol 2 --read-len 10 --read "$read" --ids "$(ids_upto "$n")" --cycles "$CYCLES" \
			--margin-us "$MARGIN_US" >"$out" 2>"$d/bc2-$n.err" || echo "status not measured: buscycle failed ($(tail -n1 "$d/bc2-$n.err"))" >"$out"
		echo "bus fake" >>"$out"
		return 0
	fi
	# --baud: X servos leave the factory at 57600; the cycle runs at 1 Mbps
	start "sim-bc2-$n" "$SIM" --model xm430-w350 --link "$d/bc2-$n.pty" --ids "$(ids_upto "$n")" --return-delay 0 \
		--baud 1000000 --quiet
	if ! wait_ready "sim-bc2-$n" 'ready:' 10; then
		echo "status not measured: the simulator refused $n X servos on one bus ($(why "sim-bc2-$n"))" >"$out"
	elif ! "$HB/buscycle" --port "$d/bc2-$n.pty" --protocol 2 --read-len 10 --read "$read" --ids "$(ids_upto "$n")" \
		--cycles "$CYCLES" --margin-us "$MARGIN_US" >"$out" 2>"$d/bc2-$n.err"; then
		echo "status not measured: buscycle failed ($(tail -n1 "$d/bc2-$n.err"))" >"$out"
	fi
	echo "bus simulator" >>"$out"
	stop "sim-bc2-$n"
}

bus2_table() {
	local n b floor1
	progress "2/5 bus time per cycle: the Protocol 2.0 cycle, 2/6/18 servos, $CYCLES cycles each"
	for n in 2 6 18; do bus2_run $n; done
	say "### Protocol 2.0 (X series): one SYNC_READ, one SYNC_WRITE"
	say ""
	say "One cycle = SYNC_READ of present current, velocity and position (10 bytes a servo: a request of"
	say "14 + N bytes, N replies of 21) and SYNC_WRITE of 4-byte goal positions (14 + 5N bytes); return"
	say "delay 0, 1 Mbps. Floor = wire time at 10 bits a byte, no byte stuffed; 1.0's floor (above) beside it."
	say "Measured as above: from the SYNC_READ to the SYNC_WRITE handed to the port."
	say ""
	progress "2/5 bus time per cycle: undulated on Protocol 2.0 (XM430-W350), ${WINDOW_S} s per configuration"
	for n in 2 6 18; do daemon_bus_run $n 0 xm430-w350; done
	say "| servos | 1.0 floor (µs) | 2.0 floor (µs) | of it the SYNC_READ | bus | p50 | p99 | max | p50/2.0 floor | p50/SYNC_READ floor | replies missed | undulated p50 | p99 | max | p50/2.0 floor | overruns |"
	say "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
	for n in 2 6 18; do
		local db=$T/bus/db2-$n-0 dcells
		if [ "$(v "$db" status)" = not ]; then
			dcells="$(sed -n 's/^status //p' "$db") | – | – | – | –"
		else
			dcells="$(fmt "$(v "$db" all.bus_p50)") | $(fmt "$(v "$db" all.bus_p99)") | $(fmt "$(v "$db" all.bus_max)") |"
			dcells="$dcells $(ratio "$(v "$db" all.bus_p50)" "$(v "$T/bus/bc2-$n.txt" floor_us)") | $(v "$db" all.overruns)"
		fi
		b=$T/bus/bc2-$n.txt
		floor1=$(awk -v n="$n" 'BEGIN { print n * 200 + (3 * n + 8) * 10 }')
		if [ "$(v "$b" status)" = not ]; then
			say "| $n | $floor1 | – | – | – | $(sed -n 's/^status //p' "$b") | – | – | – | – | – | $dcells |"
			continue
		fi
		say "| $n | $floor1 | $(v "$b" floor_us) | $(v "$b" floor_reads_us) | $(v "$b" bus) | $(v "$b" bus_p50) | $(v "$b" bus_p99) |" \
			"$(v "$b" bus_max) | $(ratio "$(v "$b" bus_p50)" "$(v "$b" floor_us)") |" \
			"$(ratio "$(v "$b" bus_p50)" "$(v "$b" floor_reads_us)") | $(v "$b" timeouts) of $((n * CYCLES)) | $dcells |"
	done
	say ""
	bus2_fast_table
}

# The same cycle with the SYNC_READ a Fast Sync Read (0x8A): one status packet
# for all servos (8 + N (4 + 10) bytes), one return delay; the servos' firmware
# 46 answers it. Beside the SYNC_READ's figures above.
bus2_fast_table() {
	local n b s
	progress "2/5 bus time per cycle: the Protocol 2.0 cycle with Fast Sync Read, 2/6/18 servos"
	for n in 2 6 18; do bus2_run $n fast; done
	say "#### The same with one Fast Sync Read in place of the SYNC_READ"
	say ""
	say "One status packet for all servos (8 + 14N bytes), one return delay; what undulated reads with when"
	say "every servo has it (X430/X540 from firmware 45). Floor as above, with that reply."
	say ""
	say "| servos | floor (µs) | of it the read | SYNC_READ's floor | bus | p50 | p99 | max | p50/floor | SYNC_READ p50 | slots missed |"
	say "|---|---|---|---|---|---|---|---|---|---|---|"
	for n in 2 6 18; do
		b=$T/bus/bc2f-$n.txt; s=$T/bus/bc2-$n.txt
		if [ "$(v "$b" status)" = not ]; then
			say "| $n | – | – | $(v "$s" floor_us) | – | $(sed -n 's/^status //p' "$b") | – | – | – | $(v "$s" bus_p50) | – |"
			continue
		fi
		say "| $n | $(v "$b" floor_us) | $(v "$b" floor_reads_us) | $(v "$s" floor_us) | $(v "$b" bus) | $(v "$b" bus_p50) |" \
			"$(v "$b" bus_p99) | $(v "$b" bus_max) | $(ratio "$(v "$b" bus_p50)" "$(v "$b" floor_us)") |" \
			"$(v "$s" bus_p50) | $(v "$b" timeouts) of $((n * CYCLES)) |"
	done
	say ""
}

# ---- 3: a missing servo ------------------------------------------------------------
section_missing() {
	progress "3/5 a missing servo: 3 servos, the third stops answering; ${WINDOW_S} s before and after"
	local d=$T/missing u
	u=$(url $PORT_MISSING)
	mkdir -p "$d"
	# protocol level: IDs 1,2,3 against a bus with 1,2 only
	start sim-miss-bc "$SIM" --link "$d/bc.pty" --ids 1,2 --return-delay 0 --quiet
	if wait_ready sim-miss-bc 'ready:' 10; then
		"$HB/buscycle" --port "$d/bc.pty" --ids 1,2,3 --cycles "$CYCLES" --margin-us "$MARGIN_US" >"$d/bc.txt" 2>"$d/bc.err"
	else
		echo "status not measured: undulate-sim did not start ($(why sim-miss-bc))" >"$d/bc.txt"
	fi
	stop sim-miss-bc
	# the daemon: all three present at start, then servo 3 goes silent
	echo "status ok" >"$d/info"
	start sim-miss "$SIM" --link "$d/r1" --ids 1,2,3 --return-delay 0 --lcm-url "$u" --control "$d/sim.sock" --quiet
	if ! wait_ready sim-miss 'ready:' 10; then
		echo "status not measured: undulate-sim did not start ($(why sim-miss))" >"$d/info"
	else
		start log-miss lcm-logger --lcm-url="$u" -f "$d/run.lcm"
		wait_file "$d/run.lcm" 10
		if start_daemon dmn-miss "$DMN" --port "$d/r1" --ids 1,2,3 --robot r1 --lcm-url "$u" --mode oscillator; then
			echo "start_retries $RETRIES" >>"$d/info"
			sleep "$RAMP_S"
			local t0 t1 t2
			t0=$(now_us)
			sleep "$WINDOW_S"
			t1=$(now_us)
			"$HB/simctl" "$d/sim.sock" "fault r1 3 no-reply" >"$d/fault.out" 2>&1 ||
				echo "status not measured: fault injection failed ($(head -n1 "$d/fault.out"))" >"$d/info"
			sleep "$WINDOW_S"
			t2=$(now_us)
			"$HB/logstat" --from-us "$t0" --to-us "$t2" --missing-id 3 "$d/run.lcm" >"$d/stat"
			"$HB/logstat" --from-us "$t1" --to-us "$t2" "$d/run.lcm" >"$d/stat-after"
		else
			echo "status not measured: undulated did not start in $START_TRIES tries ($(why dmn-miss))" >"$d/info"
		fi
		stop dmn-miss; stop log-miss
	fi
	stop sim-miss
	say "## 3. Cost of a missing servo (3 servos, return delay 0)"
	say ""
	say "Derived READ timeout = wire time of request + reply + return delay + adapter latency (0 on a pty)"
	say "+ $MARGIN_SAY."
	say "Budget: a missing servo costs at most its timeout, never the loop (the period and overrun columns)."
	say ""
	say "| measured by | derived timeout (µs) | a READ to the missing servo (µs) | bus time p50: healthy → missing (µs) | bus p99 missing | period p99 missing | overruns while missing |"
	say "|---|---|---|---|---|---|---|"
	local b=$d/bc.txt
	if [ "$(v "$b" status)" = not ]; then
		say "| buscycle (IDs 1,2,3; the bus has 1,2) | – | $(sed -n 's/^status //p' "$b") | – | – | – | – |"
	else
		say "| buscycle (IDs 1,2,3; the bus has 1,2) | $(v "$b" timeout_us) |" \
			"$(v "$b" absent_read_mean_us) mean, $(v "$b" absent_read_max_us) max (a reply: $(v "$b" read_mean_us)) |" \
			"– → $(v "$b" bus_p50) | $(v "$b" bus_p99) | – | $(v "$b" overruns) |"
	fi
	if [ "$(v "$d/info" status)" != ok ]; then
		say "| undulated (servo 3 stops answering) | – | $(sed -n 's/^status //p' "$d/info") | – | – | – | – |"
		sum "a missing servo" "at most its timeout, never the loop" "$(sed -n 's/^status //p' "$d/info")"
	else
		local s=$d/stat h50 m50
		h50=$(v "$s" r1.healthy_bus_p50) m50=$(v "$s" r1.missing_bus_p50)
		say "| undulated (servo 3 stops answering; $(v "$s" r1.missing_n) cycles without it$(retried "$(v "$d/info" start_retries)")) | $(v "$b" timeout_us) |" \
			"$(awk -v a="$m50" -v b="$h50" 'BEGIN { if (a == "nan" || b == "nan") print "–"; else printf "%.0f more than a reply (p50 difference)", a - b }') |" \
			"$(fmt "$h50") → $(fmt "$m50") | $(fmt "$(v "$s" r1.missing_bus_p99)") | $(fmt "$(v "$s" r1.missing_period_p99)") |" \
			"$(v "$s" r1.missing_overruns) |"
		sum "a missing servo (3 servos, return delay 0)" "at most its timeout ($(v "$b" timeout_us) µs), never the loop" \
			"$(awk -v a="$m50" -v b="$h50" 'BEGIN { if (a == "nan" || b == "nan") print "–"; else printf "+%.0f µs", a - b }') a cycle (p50); period p99 $(fmt "$(v "$s" r1.missing_period_p99)") µs, $(v "$s" r1.missing_overruns) overruns in $(v "$s" r1.missing_n) cycles"
	fi
	say ""
}

# ---- 5: simulator capacity ---------------------------------------------------------
# scenario FILE N DIR: N two-servo robots in a row, links in DIR, servos
# set up as the docs recommend (return delay 0), the world's defaults.
scenario() {
	local f=$1 n=$2 dir=$3 i
	{
		echo "[sim]"
		echo "link_dir = $dir"
		echo "return_delay_us = 0"
		for i in $(seq 1 "$n"); do
			printf '[robot r%d]\nids = 1,2\n' "$i"
		done
	} >"$f"
}

# cap_run N: the sim alone with N robots for CAP_S seconds (its own --duration).
cap_run() {
	local n=$1 d=$T/cap u
	u=$(url $PORT_CAP)
	mkdir -p "$d/links-$n"
	scenario "$d/scen-$n.ini" "$n" "$d/links-$n"
	start "log-cap-$n" lcm-logger --lcm-url="$u" -f "$d/cap-$n.lcm"
	wait_file "$d/cap-$n.lcm" 10
	start "sim-cap-$n" "$SIM" --scenario "$d/scen-$n.ini" --lcm-url "$u" --duration "$CAP_S" --quiet
	wait "${PID[sim-cap-$n]}"
	unset "PID[sim-cap-$n]"
	cp "$T/sim-cap-$n.log" "$d/sim-$n.out"
	stop "log-cap-$n"
	"$HB/logstat" --skip 1 "$d/cap-$n.lcm" >"$d/stat-$n"
}

# fleet_run N TAG [SIM ARGS...]: the sim with N robots and one undulated per robot.
fleet_run() {
	local n=$1 d=$T/fleet-$2 u i
	shift 2
	u=$(url $PORT_FLEET)
	mkdir -p "$d/links"
	echo "status ok" >"$d/info"
	scenario "$d/scen.ini" "$n" "$d/links"
	start sim-fleet "$SIM" --scenario "$d/scen.ini" --lcm-url "$u" --quiet "$@"
	if ! wait_ready sim-fleet 'ready:' 10; then
		echo "status not measured: undulate-sim did not start ($(why sim-fleet))" >"$d/info"
		stop sim-fleet
		return 1
	fi
	start log-fleet lcm-logger --lcm-url="$u" -f "$d/run.lcm"
	wait_file "$d/run.lcm" 10
	# One after another, each once ready: twenty blocking start-up scans at
	# once on two cores measure the start-up, not the running fleet.
	local retries=0
	for i in $(seq 1 "$n"); do
		if ! start_daemon "dmn-fleet-$i" "$DMN" --port "$d/links/r$i" --ids 1,2 --robot "r$i" --lcm-url "$u" --mode oscillator; then
			echo "status not measured: undulated r$i did not start in $START_TRIES tries ($(why "dmn-fleet-$i"))" >"$d/info"
			break
		fi
		retries=$((retries + RETRIES))
	done
	echo "start_retries $retries" >>"$d/info"
	if [ "$(v "$d/info" status)" = ok ]; then
		sleep "$RAMP_S"
		local t0 t1 s0 s1 dc0=0 dc1=0 c
		t0=$(now_us) s0=$(cpu_ticks "${PID[sim-fleet]}")
		for i in $(seq 1 "$n"); do c=$(cpu_ticks "${PID[dmn-fleet-$i]}"); dc0=$((dc0 + ${c:-0})); done
		sleep "$FLEET_S"
		t1=$(now_us) s1=$(cpu_ticks "${PID[sim-fleet]}")
		for i in $(seq 1 "$n"); do c=$(cpu_ticks "${PID[dmn-fleet-$i]}"); dc1=$((dc1 + ${c:-0})); done
		{
			echo "sim_cpu $(cpu_pct "$s0" "$s1" "$t0" "$t1")"
			echo "daemons_cpu $(cpu_pct "$dc0" "$dc1" "$t0" "$t1")"
		} >>"$d/info"
		for i in $(seq 1 "$n"); do stop "dmn-fleet-$i"; done
		stop log-fleet
		"$HB/logstat" --from-us "$t0" --to-us "$t1" "$d/run.lcm" >"$d/stat"
	else
		for i in $(seq 1 "$n"); do stop "dmn-fleet-$i"; done
		stop log-fleet
	fi
	stop sim-fleet
	cp "$T/sim-fleet.log" "$d/sim.out"
}

# exit_field FILE REGEX: a number from the sim's exit summary line
exit_field() { sed -n "s/.*exit:.*$2.*/\\1/p" "$1" | head -n1; }

# realtime LATE_MAX OVERRUNS: the physics kept pace with the wall clock if it
# never fell so far behind that the schedule was reset (an overrun: more than
# 50 steps behind) and no step ran a whole control period (10 ms) late, i.e.
# no daemon could have read a state older than one of its own cycles.
realtime() { awk -v l="$1" -v o="$2" 'BEGIN { if (l == "nan" || o == "") print "–"; else print (o == 0 && l < 10000 ? "yes" : "no") }'; }

section_cap() {
	local n
	progress "4/5 simulator capacity: 5/10/20/30 robots alone (${CAP_S} s each), then 20 robots with 20 daemons (${FLEET_S} s)"
	for n in 5 10 20 30; do cap_run $n; done
	fleet_run 20 other
	if chrt -f 1 true 2>/dev/null && "$SIM" --help 2>&1 | grep -q -- '--realtime'; then
		progress "4/5 again with the simulator under SCHED_FIFO $SIM_RT_PRIORITY (--realtime)"
		fleet_run 20 fifo --realtime "$SIM_RT_PRIORITY"
	fi
	say "## 5. Simulator capacity (2 servos a robot, physics at 1 kHz)"
	say ""
	say "Step lateness = how late a physics step ran after its scheduled time: p99 over all steps from the"
	say "simulator's exit summary; p99 and max of the worst step of each 10 ms SIM.TRUTH message over the"
	say "window. Late steps are caught up, so lateness is not lost time. Real time = no overrun (the"
	say "schedule was never reset) and no step ran a whole control period (10 ms) late."
	say "Budget: 20 robots (40 servos) in real time on this machine while their 20 daemons run."
	say ""
	say "| robots | daemons | sim CPU % | step lateness p99, all steps (µs) | p99 of the 10 ms worst | max | overruns | real time | daemons' CPU % (sum) | daemons' lateness p99 (worst robot) | daemon overruns |"
	say "|---|---|---|---|---|---|---|---|---|---|---|"
	local d=$T/cap f cpu ovr late
	for n in 5 10 20 30; do
		f=$d/sim-$n.out
		if ! grep -q 'exit:' "$f" 2>/dev/null; then
			say "| $n | 0 | not measured: $(tail -n1 "$f" | cut -c1-120) | – | – | – | – | – | – | – | – |"
			continue
		fi
		cpu=$(exit_field "$f" 'cpu \([0-9.]*\)%')
		ovr=$(exit_field "$f" ' \([0-9]*\) overruns')
		late=$(v "$d/stat-$n" truth.late_p99)
		say "| $n | 0 | $(fmt "$cpu" 1) | $(fmt "$(exit_field "$f" '(p99 \([0-9.]*\) us')") | $(fmt "$late") |" \
			"$(fmt "$(v "$d/stat-$n" truth.late_max)") | $ovr |" \
			"$(realtime "$(v "$d/stat-$n" truth.late_max)" "$ovr") | – | – | – |"
	done
	local tag label
	for tag in other fifo; do
		d=$T/fleet-$tag
		[ -d "$d" ] || continue
		label="20 | 20"
		[ "$tag" = fifo ] && label="20 | 20 (sim SCHED_FIFO $SIM_RT_PRIORITY)"
		local sumwhat="simulator: 20 robots (40 servos) + 20 daemons"
		[ "$tag" = fifo ] && sumwhat="$sumwhat, sim SCHED_FIFO $SIM_RT_PRIORITY"
		if [ "$(v "$d/info" status)" != ok ]; then
			say "| $label | $(sed -n 's/^status //p' "$d/info") | – | – | – | – | – | – | – | – |"
			sum "$sumwhat" "real time on 2 cores" "$(sed -n 's/^status //p' "$d/info")"
			continue
		fi
		label="$label$(retried "$(v "$d/info" start_retries)")"
		ovr=$(exit_field "$d/sim.out" ' \([0-9]*\) overruns')
		late=$(v "$d/stat" truth.late_p99)
		say "| $label | $(fmt "$(v "$d/info" sim_cpu)" 1) | $(fmt "$(exit_field "$d/sim.out" '(p99 \([0-9.]*\) us')") (whole run) | $(fmt "$late") |" \
			"$(fmt "$(v "$d/stat" truth.late_max)") | $ovr | $(realtime "$(v "$d/stat" truth.late_max)" "$ovr") |" \
			"$(fmt "$(v "$d/info" daemons_cpu)" 1) ($(awk -v c="$(v "$d/info" daemons_cpu)" -v n="$(v "$d/stat" robots)" 'BEGIN { if (c == "nan" || n + 0 == 0) print "–"; else printf "%.1f", c / n }') each) |" \
			"$(fmt "$(v "$d/stat" worst.jitter_p99)") | $(v "$d/stat" all.overruns) |"
		sum "$sumwhat" "real time on 2 cores" \
			"$(realtime "$(v "$d/stat" truth.late_max)" "$ovr"): step lateness p99 $(fmt "$late") µs, max $(fmt "$(v "$d/stat" truth.late_max)") µs, $ovr overruns; sim $(fmt "$(v "$d/info" sim_cpu)" 1) % + daemons $(fmt "$(v "$d/info" daemons_cpu)" 1) % of one core; daemons' lateness p99 $(fmt "$(v "$d/stat" worst.jitter_p99)") µs (worst robot), $(v "$d/stat" all.overruns) overruns"
	done
	say ""
}

# ---- 5b: the plane world ------------------------------------------------------------
# plane_run NAME SCENARIO: the sim alone in real time for CAP_S seconds.
plane_run() {
	local name=$1 scen=$2 d=$T/plane
	mkdir -p "$d/links-$name"
	start "sim-plane-$name" "$SIM" --scenario "$scen" --link-dir "$d/links-$name" --lcm-url "$(url $PORT_CAP)" \
		--duration "$CAP_S" --quiet
	wait "${PID[sim-plane-$name]}"
	unset "PID[sim-plane-$name]"
	cp "$T/sim-plane-$name.log" "$d/$name.out"
}
section_plane() {
	progress "plane world: ten robots in the arena, the sim alone for ${CAP_S} s, beside the row's arena"
	plane_run row "$top/sim-bridge/scenarios/arena10.scenario"
	plane_run plane "$top/sim-bridge/scenarios/plane-arena10.scenario"
	say "## 5b. The plane world (sim-bridge/PHYSICS.md §6)"
	say ""
	say "The simulator alone (no daemons: joints idle, no contact) in real time at 1 kHz, ten two-servo robots"
	say "in the arena: the plane world (three Chipmunk2D links a robot, drag, walls) beside the row world."
	say "Budget: ten plane robots within 10 % of a core. The lockstep figure is in §8."
	say ""
	say "| world | sim CPU % of a core | step lateness p99 (µs) | overruns |"
	say "|---|---|---|---|"
	local w f cpu
	for w in row plane; do
		f=$T/plane/$w.out
		if ! grep -q 'exit:' "$f" 2>/dev/null; then
			say "| $w | not measured: $(tail -n1 "$f" | cut -c1-120) | – | – |"
			continue
		fi
		cpu=$(exit_field "$f" 'cpu \([0-9.]*\)%')
		say "| $w | $(fmt "$cpu" 1) | $(fmt "$(exit_field "$f" '(p99 \([0-9.]*\) us')") | $(exit_field "$f" ' \([0-9]*\) overruns') |"
		[ "$w" = plane ] && sum "simulator: ten plane robots at 1 kHz, alone" "within 10 % of a core" "$(fmt "$cpu" 1) % of a core"
	done
	say ""
}

# ---- 6: the framing code alone -----------------------------------------------------
section_codec() {
	progress "5/5 protocol framing throughput (1 s)"
	"$HB/codec" --seconds 1 >"$T/codec" 2>&1
	say "## 6. Protocol framing (no I/O)"
	say ""
	say "One READ(36,6) round trip = encode request, parse it (servo side), encode the 12-byte status,"
	say "parse it (controller side)."
	say ""
	say "| round trips / s | ns per round trip | packets / s (encoded and parsed) |"
	say "|---|---|---|"
	say "| $(fmt "$(v "$T/codec" round_trips_per_s)") | $(fmt "$(v "$T/codec" ns_per_round_trip)" 1) |" \
		"$(awk -v r="$(v "$T/codec" round_trips_per_s)" 'BEGIN { if (r == "nan") print "–"; else printf "%.0f", 2 * r }') |"
	say ""
}

# ---- 7: instructions per control cycle (optional: valgrind) -------------------------
section_cg() {
	say "## 7. Instructions per control cycle (callgrind)"
	say ""
	if ! command -v valgrind >/dev/null || ! command -v callgrind_control >/dev/null; then
		say "not measured: valgrind is not installed"
		say ""
		return 0
	fi
	progress "extra: callgrind instruction count of the control cycle (${CG_S} s under valgrind)"
	local d=$T/cg u
	u=$(url $PORT_CG)
	mkdir -p "$d"
	start sim-cg "$SIM" --link "$d/r1" --ids 1,2 --return-delay 0 --lcm-url "$u" --quiet
	if ! wait_ready sim-cg 'ready:' 10; then
		say "not measured: undulate-sim did not start ($(why sim-cg))"
		say ""
		stop sim-cg
		return 0
	fi
	# valgrind runs the daemon in the same process: its PID is the daemon's
	start dmn-cg valgrind --tool=callgrind --callgrind-out-file="$d/cg.out" \
		"$DMN" --port "$d/r1" --ids 1,2 --robot r1 --lcm-url "$u" --mode oscillator
	local ok=1
	if wait_ready dmn-cg 'ready:' 60; then
		sleep "$RAMP_S"
		callgrind_control --zero "${PID[dmn-cg]}" >/dev/null 2>&1 || ok=0
		sleep "$CG_S"
		callgrind_control --dump=window "${PID[dmn-cg]}" >/dev/null 2>&1 || ok=0
	else
		ok=0
	fi
	stop dmn-cg
	stop sim-cg
	local dump total cycles
	dump=$(find "$d" -name 'cg.out.*' | sort | head -n1)
	if [ "$ok" = 0 ] || [ -z "$dump" ]; then
		say "not measured: undulated under valgrind did not run or could not be dumped ($(why dmn-cg))"
		say ""
		return 0
	fi
	total=$(awk '/^summary:/ { print $2 }' "$dump")
	# cycles in the window = calls of the state encoder (once per cycle),
	# summed from the dump's call arcs (names are compressed: "(id) name"
	# the first time, "(id)" after)
	cycles=$(awk '
		/^c?fn=\(/ {
			s = $0; sub(/^c?fn=/, "", s); id = s; sub(/\).*/, "", id); sub(/^\(/, "", id)
			nm = s; if (sub(/^\([0-9]+\) /, "", nm)) names[id] = nm
			if ($0 ~ /^cfn=/) cur = id
		}
		/^calls=/ { c = $0; sub(/^calls=/, "", c); split(c, f, " "); if (names[cur] == "undulate_robot_state_t_encode") n += f[1] }
		END { print n + 0 }' "$dump")
	say "All threads (the loop and LCM's receive thread), user space, over a ${CG_S} s window at 100 Hz;"
	say "cycles counted as calls of the per-cycle state encoder. Self cost of the busiest functions:"
	say ""
	say "| cycles | instructions | per cycle | busiest functions (self, % of all) |"
	say "|---|---|---|---|"
	local top
	top=$(callgrind_annotate --inclusive=no --threshold=100 "$dump" 2>/dev/null | sed -n '/file:function/,$p' |
		grep -vE 'below main|libc-start|libc_start_call_main|main\.c:main|clone\.S|start_thread|\?\?\?:0x|^-|file:function|^ *$' |
		head -n 6 | awk '{ pct = $2 $3; gsub(/[()]/, "", pct); f = $NF == "" ? $4 : $4; sub(/.*:/, "", f); printf "%s%s %s", (NR > 1 ? ", " : ""), f, pct }')
	say "| ${cycles:-–} | $(fmt "$total") | $(awk -v t="$total" -v c="${cycles:-0}" 'BEGIN { if (c + 0 == 0) print "–"; else printf "%.0f", t / c }') | $top |"
	say ""
}

# ---- 8: lockstep (virtual time) ----------------------------------------------------
# lock_run NAME SCENARIO SECONDS ARGS...: one scripts/demo.sh --lockstep run; the
# simulator's lockstep line (simulated s, wall s from the first step, speed) and
# the whole run's wall time (start-up, recording and analysis included) go to
# $T/lock/NAME.res.
lock_run() {
	local name=$1 scen=$2 secs=$3 d=$T/lock t0 t1 line
	shift 3
	mkdir -p "$d"
	t0=$(now_us)
	BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep --scenario "$scen" --seconds "$secs" \
		--seed 7 --lcm-url "$(url $PORT_LOCK)" --out "$d/$name.out" "$@" >"$d/$name.log" 2>&1
	t1=$(now_us)
	line=$(sed -n 's/^undulate-sim: lockstep: \([0-9.]*\) s of simulated time in \([0-9.]*\) s (\([0-9.]*\)x real time.*/\1 \2 \3/p' \
		"$d/$name.out/logs/sim.log" 2>/dev/null)
	echo "${line:-nan nan nan} $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", (b - a) / 1e6 }')" >"$d/$name.res"
	rm -rf "$d/$name.out/demo.lcmlog"
}
# lock_row LABEL DAEMONS PREFIX BUDGET: the table row and the summary line of N runs
lock_row() {
	local label=$1 daemons=$2 prefix=$3 budget=$4 f speeds walls alls med
	speeds=$(for f in "$T/lock/$prefix".*.res; do awk '{ print $3 }' "$f"; done | sort -n)
	walls=$(for f in "$T/lock/$prefix".*.res; do awk '{ print $2 }' "$f"; done | sort -n | tr '\n' ' ')
	alls=$(for f in "$T/lock/$prefix".*.res; do awk '{ print $4 }' "$f"; done | sort -n | tr '\n' ' ')
	med=$(echo "$speeds" | awk '{ x[NR] = $1 } END { if (NR == 0 || x[1] == "nan") print "nan"; else print x[int((NR + 1) / 2)] }')
	local range
	range=$(echo "$speeds" | awk 'NR == 1 { lo = $1 } { hi = $1 } END { printf "%s–%s", lo, hi }')
	say "| $label | $daemons | $(fmt "$med" 1)× ($range×) | $walls | $alls |"
	sum "lockstep: $label ($daemons daemons)" "$budget" "$(fmt "$med" 1)× real time (median of $(echo "$speeds" | grep -c .) runs, $range×)"
}
section_lockstep() {
	local i
	progress "lockstep: the pair rig (40 s) and ten robots (45 s) in simulated time, $LOCK_REPS runs each"
	for i in $(seq "$LOCK_REPS"); do
		lock_run "pair.$i" "$top/sim-bridge/scenarios/pair-rig.scenario" 40 --phases 0,3.1416 \
			--set world.separation=0.7 --daemon-set robot.actuation=torque \
			--daemon-set robot.torque_drive=current --daemon-set sinusoid.amplitude=0.25
		lock_run "ten.$i" "$top/sim-bridge/scenarios/force10.scenario" 45
		lock_run "plane.$i" "$top/sim-bridge/scenarios/plane-arena10.scenario" 45
	done
	say "## 8. Lockstep: simulated time against wall time"
	say ""
	say "scripts/demo.sh --lockstep: the simulator and one undulated per robot in the simulator's time (sim-bridge/README.md,"
	say "\"Lockstep\"). Speed = simulated seconds over the wall seconds from the first simulated step to the end"
	say "(the simulator's own figure); whole run = the demo from start to summary (start-up, recording, analysis)."
	say "Real time is 1× by definition: the other sections run in it."
	say ""
	say "| scenario | daemons | speed, median (range) | wall s of the simulated part | whole run, s |"
	say "|---|---|---|---|---|"
	lock_row "pair rig, 40 s" 2 pair "≥ 20× real time"
	lock_row "ten two-joint robots, 45 s" 10 ten "≥ 5× real time"
	lock_row "ten plane robots in the arena, 45 s" 10 plane "≥ 5× real time"
	say ""
}

# ---- 9: the paper's model (undulate-model) ---------------------------------------
# model_run NAME ARGS...: one 50-oscillator, 600 s lattice on one core (CPU 0
# when taskset exists); "wall user+sys collisions steps root_evals" to
# $T/model/NAME.res, or "nan ..." when it failed.
model_run() {
	local name=$1 d=$T/model pin=() t rc
	shift
	mkdir -p "$d"
	command -v taskset >/dev/null && pin=(taskset -c 0)
	t=$( { TIMEFORMAT='%R %U %S'; time "${pin[@]}" "$BIN/undulate-model" lattice --n 50 --duration 600 \
		--seed 3 --out "$d/$name.out" --quiet "$@" >"$d/$name.log" 2>&1; } 2>&1)
	rc=$?
	if [ "$rc" != 0 ] || [ ! -s "$d/$name.out/summary.json" ]; then
		echo "nan nan nan nan nan" >"$d/$name.res"
		return 1
	fi
	echo "$t $(jq -r '[.collisions, .model.steps, .model.root_evals] | map(tostring) | join(" ")' \
		"$d/$name.out/summary.json")" | awk '{ printf "%s %.2f %s %s %s\n", $1, $2 + $3, $4, $5, $6 }' >"$d/$name.res"
	rm -rf "$d/$name.out"
}
section_model() {
	if [ ! -x "$BIN/undulate-model" ]; then
		sum "undulate-model: 50 oscillators, 600 s" "< 10 s on one core" "not measured: not built"
		return 0
	fi
	progress "model: undulate-model, 50 oscillators for 600 s, $MODEL_REPS runs a setting"
	local i set worst=nan label
	local -A args=(
		[d014]="--dsep 0.14"
		[d07]="--dsep 0.7"
		[d07ns]="--dsep 0.7 --no-samples"
		[mob]="--dsep 0.78 --beta 0.01 --fixed-ends"
	)
	local -A labels=(
		[d014]="d~ 0.14, immobile (relaxes within seconds), 20 samples/s written"
		[d07]="d~ 0.7, immobile (collides to the end), 20 samples/s written"
		[d07ns]="d~ 0.7, immobile, no sample rows"
		[mob]="d~ 0.78, beta 0.01 s, fixed ends, 20 samples/s written"
	)
	for set in d014 d07 d07ns mob; do
		for i in $(seq "$MODEL_REPS"); do
			# shellcheck disable=SC2086 # the settings are words
			model_run "$set.$i" ${args[$set]}
		done
	done
	say "## 9. The paper's model (undulate-model)"
	say ""
	say "\`undulate-model lattice --n 50 --duration 600 --seed 3\` on one core (taskset -c 0), $MODEL_REPS runs each:"
	say "the phase oscillators integrated with GSL's odeiv2, every collision located as an event (model/README.md)."
	say "Budget: under 10 s on one core. Wall and CPU (user + sys) seconds: the median and the range."
	say ""
	say "| setting | wall s | CPU s | collisions | steps | root evaluations |"
	say "|---|---|---|---|---|---|"
	for set in d014 d07 d07ns mob; do
		local walls cpus med cmed crange wrange one
		walls=$(cat "$T/model/$set".*.res | awk '{ print $1 }' | sort -n)
		cpus=$(cat "$T/model/$set".*.res | awk '{ print $2 }' | sort -n)
		med=$(echo "$walls" | awk '{ x[NR] = $1 } END { print x[int((NR + 1) / 2)] }')
		cmed=$(echo "$cpus" | awk '{ x[NR] = $1 } END { print x[int((NR + 1) / 2)] }')
		wrange=$(echo "$walls" | awk 'NR == 1 { lo = $1 } { hi = $1 } END { printf "%s–%s", lo, hi }')
		crange=$(echo "$cpus" | awk 'NR == 1 { lo = $1 } { hi = $1 } END { printf "%s–%s", lo, hi }')
		one=$(head -n1 "$T/model/$set.1.res")
		say "| ${labels[$set]} | $med ($wrange) | $cmed ($crange) | $(echo "$one" | awk '{ print $3 }') |" \
			"$(echo "$one" | awk '{ print $4 }') | $(echo "$one" | awk '{ print $5 }') |"
		[ "$set" = d07 ] && worst="$med s wall, $cmed s CPU (${labels[$set]})"
	done
	say ""
	sum "undulate-model: 50 oscillators, 600 s lattice" "< 10 s on one core" "$worst"
}

# ---- rate: the highest control rate one bus of X servos holds ------------------------
# For N XM430-W350 (2/6/12/18) at 1, 2 and 4 Mbps, each way of reading the
# joints (RATE_READS: a read's columns come from rate_read_label,
# rate_sim_args and rate_dmn_args alone):
#  - buscycle's cycle (one read of 10 bytes a servo, one SYNC_WRITE) at
#    RATE_CYCLE_US for RATE_CYCLES cycles, against that read's wire floor;
#  - undulated itself at period_ms 10, 5, 4, 2, 1: RATE_S seconds each after
#    RATE_SETTLE_S, its overruns counted from its STATE (logstat). The search
#    starts at the shortest period above 1.5x the floor and walks from there,
#    so a configuration costs two or three runs, not five.
RATE_S=${BENCH_RATE_S:-2}
RATE_1K_S=${BENCH_RATE_1K_S:-60}
RATE_2BUS_S=${BENCH_RATE_2BUS_S:-30}
RATE_CYCLES=${BENCH_RATE_CYCLES:-200}
RATE_SETTLE_S=1
RATE_CYCLE_US=5000
RATE_READS="sync fast indirect"
RATE_SERVOS=${BENCH_RATE_SERVOS:-2 6 12 18}
RATE_BAUDS=${BENCH_RATE_BAUDS:-1000000 2000000 4000000}
RATE_PERIODS_MS="10 5 4 2 1"
RATE_DMN_ARGS=()
PORT_RATE=7910 PORT_RATE_B=7911
rate_read_label() { case $1 in sync) echo "SYNC_READ" ;; fast) echo "Fast Sync Read" ;; indirect) echo "indirect + Fast Sync Read" ;; *) echo "$1" ;; esac; }
# lockstep_up CLOCK NAME OUT URL: the simulator sim-NAME has opened its lockstep
# socket CLOCK, and an lcm-logger log-NAME records URL into OUT.lcm; else OUT
# says why the status was not measured and the simulator is stopped (status 1).
lockstep_up() {
	if ! wait_file "$1" 10; then
		echo "status not measured: the simulator did not start in lockstep ($(why "sim-$2"))" >"$3"
		stop "sim-$2"
		return 1
	fi
	start "log-$2" lcm-logger --lcm-url="$4" -f "$3.lcm"
	wait_file "$3.lcm" 10
}

# The simulator's options that make the daemon read that way: it reads by Fast
# Sync Read when every servo has firmware 45 or later (the simulator's 46).
rate_sim_args() { case $1 in sync) echo "--firmware 44" ;; *) ;; esac; }
# The daemon's: the indirect block (robot.indirect, on by default) for the
# third read alone, so that the first two read the registers where they lie
# (21 bytes a servo on the slow cycles, 13 through the block).
rate_dmn_args() { case $1 in indirect) ;; *) echo "--set robot.indirect=off" ;; esac; }

# rate_sim NAME N BAUD READ: an X-servo simulator for one configuration, its
# LCM logged (for its SIM.TRUTH lateness). 1 when it does not start ("status"
# into $T/rate/NAME.sim).
rate_sim() {
	local name=$1 n=$2 baud=$3 read=$4 d=$T/rate u model=(--model xm430-w350)
	u=$(url $PORT_RATE)
	mkdir -p "$d"
	# shellcheck disable=SC2046 # the read's options are words
	start "sim-$name" "$SIM" --link "$d/$name.pty" --ids "$(ids_upto "$n")" --return-delay 0 --baud "$baud" \
		$(rate_sim_args "$read") --lcm-url "$u" --quiet "${model[@]}"
	if ! wait_ready "sim-$name" 'ready:' 10; then
		echo "status not measured: the simulator refused $n X servos at $baud bps ($(why "sim-$name"))" >"$d/$name.sim"
		stop "sim-$name"
		return 1
	fi
}

# rate_daemon NAME N BAUD PERIOD_MS WINDOW_S [READ]: undulated on sim-NAME's
# bus at that period, reading as READ says (rate_dmn_args; its own default
# without); logstat's figures of WINDOW_S seconds into $T/rate/NAME-PERIOD.
rate_daemon() {
	local name=$1 n=$2 baud=$3 p=$4 w=$5 read=${6:-} d=$T/rate u out rargs=()
	[ -n "$read" ] && read -r -a rargs <<<"$(rate_dmn_args "$read")"
	u=$(url $PORT_RATE)
	out=$d/$name-$p
	start "log-$name" lcm-logger --lcm-url="$u" -f "$out.lcm"
	wait_file "$out.lcm" 10
	if start_daemon "dmn-$name" "$DMN" --port "$d/$name.pty" --ids "$(ids_upto "$n")" --baud "$baud" --robot "r$n" \
		--lcm-url "$u" --mode oscillator --set robot.period_ms="$p" ${rargs[@]+"${rargs[@]}"} \
		${RATE_DMN_ARGS[@]+"${RATE_DMN_ARGS[@]}"}; then
		daemon_window "$name" "$RATE_SETTLE_S" "$w" "$out.lcm" "$out"
		grep -q 'reading by SYNC_READ from now on' "$T/dmn-$name.log" && echo "fell_back 1" >>"$out"
	else
		echo "status not measured: undulated did not start in $START_TRIES tries ($(why "dmn-$name"))" >"$out"
		stop "log-$name"
	fi
	[ -n "${KEEP_BENCH_DIR:-}" ] || rm -f "$out.lcm"
}

# rate_lockstep NAME N BAUD PERIOD_MS READ [SECONDS]: the same robot in the
# simulator's virtual time (lockstep), SECONDS (RATE_S) simulated seconds after 2: neither program
# can be late there, so an overrun is the cycle not fitting the period.
# Results in $T/rate/NAME-PERIOD like rate_daemon's.
rate_lockstep() {
	local name=$1 n=$2 baud=$3 p=$4 read=$5 secs=${6:-$RATE_S} d=$T/rate u out
	u=$(url $PORT_RATE)
	out=$d/$name-$p
	rm -f "$d/$name.clock"
	# shellcheck disable=SC2046 # the read's options are words
	start "sim-$name" "$SIM" --model xm430-w350 --link "$d/$name.pty" --ids "$(ids_upto "$n")" --return-delay 0 \
		--baud "$baud" $(rate_sim_args "$read") --lcm-url "$u" --quiet --lockstep "$d/$name.clock" \
		--duration "$((secs + 2))"
	lockstep_up "$d/$name.clock" "$name" "$out" "$u" || return 0
	# shellcheck disable=SC2046 # the read's options are words
	"$DMN" --port "$d/$name.pty" --ids "$(ids_upto "$n")" --baud "$baud" --robot "r$n" --lcm-url "$u" \
		--mode oscillator --set robot.period_ms="$p" $(rate_dmn_args "$read") --lockstep "$d/$name.clock" \
		>"$T/dmn-$name.log" 2>&1
	wait "${PID[sim-$name]}" 2>/dev/null
	unset "PID[sim-$name]"
	stop "log-$name"
	# the first 2 simulated seconds (start-up, ramp) left out
	"$HB/logstat" --sender-time --skip 2 "$out.lcm" >"$out"
	sed -n 's/^undulate-sim: lockstep: \([0-9.]*\) s of simulated time in \([0-9.]*\) s.*/lockstep_sim_s \1\nlockstep_wall_s \2/p' \
		"$T/sim-$name.log" >>"$out"
	grep -q 'reading by SYNC_READ from now on' "$T/dmn-$name.log" && echo "fell_back 1" >>"$out"
	[ -n "${KEEP_BENCH_DIR:-}" ] || rm -f "$out.lcm"
}

# rate_search NAME N BAUD FLOOR_US RUNNER [READ]: the shortest period of
# RATE_PERIODS_MS with no overrun over RATE_S seconds, each run by RUNNER
# (rate_daemon or rate_lockstep); writes "best P" and "next P OVERRUNS" (the
# next shorter period tried and its overruns) to $T/rate/NAME.best.
rate_search() {
	local name=$1 n=$2 baud=$3 floor=$4 runner=$5 read=${6:-} ps i start=0 best="" next="" o
	read -r -a ps <<<"$RATE_PERIODS_MS"
	for i in "${!ps[@]}"; do [ $((ps[i] * 1000)) -ge $((floor * 3 / 2)) ] && start=$i; done
	i=$start
	while [ "$i" -ge 0 ] && [ "$i" -lt ${#ps[@]} ]; do
		if [ "$runner" = rate_lockstep ]; then
			rate_lockstep "$name" "$n" "$baud" "${ps[i]}" "$read"
		else
			rate_daemon "$name" "$n" "$baud" "${ps[i]}" "$RATE_S" "$read"
		fi
		o=$(v "$T/rate/$name-${ps[i]}" all.overruns)
		# no STATE in the window: nothing was measured, which is not "no overrun"
		[ "$(v "$T/rate/$name-${ps[i]}" all.n)" = 0 ] && o=nan
		if [ "$o" = 0 ]; then
			best=${ps[i]}
			[ -n "$next" ] && break
			i=$((i + 1))
		else
			next="${ps[i]} $o"
			[ -n "$best" ] && break
			i=$((i - 1))
		fi
	done
	{ echo "best ${best:-none}"; echo "next ${next:-none}"; } >"$T/rate/$name.best"
}

# rate_hz PERIOD_MS: the rate it is
# rate_table COLUMNS K CELLS: a table by servos and rate with K columns a read
# (COLUMNS, READ standing for the read's name), each row's cells of a read
# from CELLS READ SERVOS BAUD
rate_table() {
	local cols=$1 k=$2 fn=$3 hdr="| servos | Mbps" sep="|---|---" cells read n baud i
	for read in $RATE_READS; do
		hdr="$hdr | ${cols//READ/$(rate_read_label "$read")}"
		for ((i = 0; i < k; i++)); do sep="$sep|---"; done
	done
	say "$hdr |"; say "$sep|"
	for n in $RATE_SERVOS; do
		for baud in $RATE_BAUDS; do
			cells="| $n | $((baud / 1000000))"
			for read in $RATE_READS; do cells="$cells | $("$fn" "$read" "$n" "$baud")"; done
			say "$cells |"
		done
	done
}
rate_cells_bus() { rate_bus_cells "$1-$2-$3"; }
rate_cells_best() { echo "$(rate_best_cell "$1-$2-$3") | $(rate_best_cell "lock-$1-$2-$3")"; }

rate_hz() { awk -v p="$1" 'BEGIN { printf "%g Hz", 1000 / p }'; }

# rate_cells NAME: "floor | p50 | p50/floor" of buscycle, then the highest rate
rate_bus_cells() {
	local b=$T/rate/$1.bc
	if [ "$(v "$b" status)" = not ]; then
		echo "– | $(sed -n 's/^status //p' "$b") | –"
	else
		echo "$(v "$b" floor_us) | $(v "$b" bus_p50) | $(ratio "$(v "$b" bus_p50)" "$(v "$b" floor_us)")"
	fi
}
rate_best_cell() {
	local f=$T/rate/$1.best best nx np no
	[ -e "$T/rate/$1.sim" ] && { sed -n 's/^status //p' "$T/rate/$1.sim"; return; }
	best=$(v "$f" best)
	read -r _ np no < <(grep '^next ' "$f")
	case $best in
	none) nx="none of ${RATE_PERIODS_MS// /, } ms" ;;
	*) nx="$(rate_hz "$best") ($best ms)" ;;
	esac
	[ "$np" != none ] && [ -n "$np" ] && nx="$nx; $np ms: $no overruns"
	grep -q '^fell_back' "$T/rate/$1-"* 2>/dev/null && nx="$nx; Fast Sync Read given up in a run"
	echo "$nx"
}

section_rate() {
	local n baud read name loads=""
	progress "rate: ${RATE_SERVOS// /\/} X servos x 1/2/4 Mbps x ${RATE_READS// /, }: buscycle $RATE_CYCLES cycles, undulated ${RATE_S} s a period, in real time and in lockstep"
	for n in $RATE_SERVOS; do
		for baud in $RATE_BAUDS; do
			for read in $RATE_READS; do
				name="$read-$n-$baud"
				loads="$loads $(cut -d' ' -f1 /proc/loadavg)"
				rate_sim "$name" "$n" "$baud" "$read" || continue
				"$HB/buscycle" --port "$T/rate/$name.pty" --protocol 2 --read-len 10 --read "$read" --baud "$baud" \
					--ids "$(ids_upto "$n")" --cycles "$RATE_CYCLES" --period-us "$RATE_CYCLE_US" \
					--margin-us "$MARGIN_US" >"$T/rate/$name.bc" 2>"$T/rate/$name.err" ||
					echo "status not measured: buscycle failed ($(tail -n1 "$T/rate/$name.err"))" >"$T/rate/$name.bc"
				local floor
				floor=$(v "$T/rate/$name.bc" floor_us)
				[ "$floor" = nan ] && floor=1000
				rate_search "$name" "$n" "$baud" "$floor" rate_daemon "$read"
				stop "sim-$name"
				rate_search "lock-$name" "$n" "$baud" "$floor" rate_lockstep "$read"
			done
		done
	done
	rate_1k
	rate_2bus
	say "## Rates above 100 Hz: X servos on one bus (simulated, return delay 0)"
	say ""
	say "XM430-W350 servos on \`undulate-sim --model xm430-w350 --baud B\`, 10 bytes a servo read (present"
	say "current, velocity, position; through the indirect block 13, with input voltage and temperature: what"
	say "undulated's slow cycle reads, 21 bytes a servo where they lie) and one SYNC_WRITE of goals. undulated reads"
	say "the registers where they lie in the first two reads (\`robot.indirect = off\`), its indirect block in the"
	say "third (its default). **Bus time**: buscycle's cycle at"
	say "$((RATE_CYCLE_US / 1000)) ms for $RATE_CYCLES cycles, p50 against the wire floor of its own read (bench/README.md, \"Rates\")."
	say "**Highest rate**: undulated (OSCILLATOR) at period_ms ${RATE_PERIODS_MS// /, }, ${RATE_S} s each after ${RATE_SETTLE_S} s;"
	say "the shortest period with 0 overruns in that window, and the next shorter one tried with its overruns;"
	say "normal scheduling. **In lockstep**: the same search in the simulator's virtual time ($RATE_S simulated s"
	say "after 2), where neither program can be late: an overrun there is the cycle not fitting the period."
	say "Load average (1 min) during the section: $(echo "$loads" | awk '{ lo = $1; hi = $1; for (i = 2; i <= NF; i++) { if ($i < lo) lo = $i; if ($i > hi) hi = $i } print lo "–" hi }')."
	say ""
	rate_table "READ floor (µs) | p50 | p50/floor" 3 rate_cells_bus
	say ""
	rate_table "READ: highest rate, no overrun | the same in lockstep" 2 rate_cells_best
	say ""
	say "Twelve on two buses: the budget's table below (real time and lockstep)."
	say ""
	rate_1k_table
	rate_2bus_table
}

# The budget: six XM430-W350 on one 4 Mbps bus at 1 kHz, RATE_1K_S seconds,
# twice: in real time (both programs under SCHED_FIFO where permitted, as a
# robot at 1 kHz would run: robot.priority), and in the simulator's virtual
# time (lockstep), where neither program can be late: what is left there is
# the cycle itself not fitting the period.
rate_1k() {
	local name=1k-6 n=6 baud=4000000 d=$T/rate u extra=()
	u=$(url $PORT_RATE)
	progress "rate: 6 X servos, 4 Mbps, Fast Sync Read, undulated at 1 kHz for ${RATE_1K_S} s, then as long in lockstep"
	RATE_1K_LOAD0=$(cut -d' ' -f1-3 /proc/loadavg)
	RATE_1K_POLICY="SCHED_OTHER (SCHED_FIFO not permitted)"
	if chrt -f 1 true 2>/dev/null; then
		RATE_1K_POLICY="SCHED_FIFO: undulated $FIFO_PRIORITY, undulate-sim $SIM_RT_PRIORITY"
		extra=(--realtime "$SIM_RT_PRIORITY")
	fi
	local model=(--model xm430-w350 "${extra[@]}")
	mkdir -p "$d"
	start "sim-$name" "$SIM" --link "$d/$name.pty" --ids "$(ids_upto "$n")" --return-delay 0 --baud "$baud" \
		--lcm-url "$u" --quiet "${model[@]}"
	if ! wait_ready "sim-$name" 'ready:' 10; then
		echo "status not measured: the simulator refused $n X servos at $baud bps ($(why "sim-$name"))" >"$d/$name.sim"
		stop "sim-$name"
		return 0
	fi
	"$HB/buscycle" --port "$d/$name.pty" --protocol 2 --read-len 10 --read fast --baud "$baud" \
		--ids "$(ids_upto "$n")" --cycles 20 --period-us "$RATE_CYCLE_US" --margin-us "$MARGIN_US" \
		>"$d/$name.bc" 2>"$d/$name.err" ||
		echo "status not measured: buscycle failed ($(tail -n1 "$d/$name.err"))" >"$d/$name.bc"
	RATE_DMN_ARGS=()
	[ ${#extra[@]} -gt 0 ] && RATE_DMN_ARGS=(--set "robot.priority=$FIFO_PRIORITY" --set robot.mlockall=true)
	rate_daemon "$name" "$n" "$baud" 1 "$RATE_1K_S"
	RATE_DMN_ARGS=()
	stop "sim-$name"
	rate_os_floor "$d/$name-1" 1000 "$RATE_1K_S"
	RATE_1K_LOAD1=$(cut -d' ' -f1-3 /proc/loadavg)
	rate_1k_lockstep
}

# rate_os_floor OUT PERIOD_US SECONDS: os_floor after a measured real-time
# window, its slack the period less the window's bus p50
rate_os_floor() {
	[ "$(v "$1" status)" = not ] && return 0
	local bus slack
	bus=$(v "$1" all.bus_p50)
	[ "$bus" = nan ] && return 0
	slack=$(awk -v p="$2" -v b="$bus" 'BEGIN { printf "%d", p - b }')
	progress "rate: cyclictest alone at ${2} µs for ${3} s (the machine's own lateness)"
	os_floor "$1" "$2" "$3" "$slack"
}

# rate_2bus: the second budget, twelve XM430-W350 on two 4 Mbps buses (six
# each, IDs 1-6 and 7-12, two simulators: one robot's joints on two ports,
# daemon/README.md "Several buses") at 500 Hz, RATE_2BUS_S seconds, both
# programs under SCHED_FIFO where permitted. Beside it, the same twelve on one
# bus, for the difference; then the two-bus run in lockstep (rate_2bus_lockstep).
rate_2bus() {
	local d=$T/rate u ub extra=() dargs=() out name
	u=$(url $PORT_RATE); ub=$(url $PORT_RATE_B)
	progress "rate: 12 X servos on two 4 Mbps buses, undulated at 500 Hz for ${RATE_2BUS_S} s, then on one bus"
	RATE_2BUS_POLICY="SCHED_OTHER (SCHED_FIFO not permitted)"
	if chrt -f 1 true 2>/dev/null; then
		RATE_2BUS_POLICY="SCHED_FIFO: undulated $FIFO_PRIORITY, undulate-sim $SIM_RT_PRIORITY"
		extra=(--realtime "$SIM_RT_PRIORITY")
		dargs=(--set "robot.priority=$FIFO_PRIORITY" --set robot.mlockall=true)
	fi
	mkdir -p "$d"
	RATE_2BUS_LOAD0=$(cut -d' ' -f1-3 /proc/loadavg)
	start sim-2a "$SIM" --model xm430-w350 --link "$d/2a.pty" --ids 1-6 --return-delay 0 --baud 4000000 \
		--lcm-url "$u" --quiet "${extra[@]}"
	start sim-2b "$SIM" --model xm430-w350 --link "$d/2b.pty" --ids 7-12 --return-delay 0 --baud 4000000 \
		--lcm-url "$ub" --quiet "${extra[@]}"
	for name in 2bus 1bus; do
		out=$d/$name
		if ! wait_ready sim-2a 'ready:' 10 || { [ "$name" = 2bus ] && ! wait_ready sim-2b 'ready:' 10; }; then
			echo "status not measured: the simulators did not start ($(why sim-2a); $(why sim-2b))" >"$out"
			continue
		fi
		start "log-$name" lcm-logger --lcm-url="$u" -f "$out.lcm"
		wait_file "$out.lcm" 10
		local ports=(--port "$d/2a.pty" --ids 1,2,3,4,5,6,b:7,b:8,b:9,b:10,b:11,b:12 --set "bus.b.port=$d/2b.pty"
			--set bus.b.baud=4000000)
		[ "$name" = 1bus ] && ports=(--port "$d/1.pty" --ids "$(ids_upto 12)")
		if start_daemon "dmn-$name" "$DMN" "${ports[@]}" --baud 4000000 --robot r12 --lcm-url "$u" \
			--mode oscillator --set robot.period_ms=2 "${dargs[@]}"; then
			daemon_window "$name" "$RATE_SETTLE_S" "$RATE_2BUS_S" "$out.lcm" "$out"
		else
			echo "status not measured: undulated did not start in $START_TRIES tries ($(why "dmn-$name"))" >"$out"
			stop "log-$name"
		fi
		[ -n "${KEEP_BENCH_DIR:-}" ] || rm -f "$out.lcm"
		if [ "$name" = 2bus ]; then
			# the same twelve on one bus: one simulator with all of them
			stop sim-2a; stop sim-2b
			start sim-2a "$SIM" --model xm430-w350 --link "$d/1.pty" --ids 1-12 --return-delay 0 --baud 4000000 \
				--lcm-url "$ub" --quiet "${extra[@]}"
		fi
	done
	stop sim-2a; stop sim-2b
	rate_os_floor "$d/2bus" 2000 "$RATE_2BUS_S"
	RATE_2BUS_LOAD1=$(cut -d' ' -f1-3 /proc/loadavg)
	rate_2bus_lockstep
}

# rate_2bus_lockstep: the same twelve on two buses in the simulator's virtual
# time, RATE_2BUS_S simulated seconds after 2: one simulator serving both
# links (a scenario with a robot a bus), one daemon on both over its one
# connection to the clock (common/lockstep.h "Several buses"). Neither
# program can be late there: an overrun is the cycle not fitting the period.
# Results in $T/rate/2bus-lock, like rate_lockstep's.
rate_2bus_lockstep() {
	local name=2bus-lock d=$T/rate u out
	u=$(url $PORT_RATE)
	out=$d/$name
	progress "rate: the same 12 X servos on two buses in lockstep, ${RATE_2BUS_S} simulated s"
	mkdir -p "$d"
	rm -f "$d/$name.clock"
	printf '[sim]\nmodel = xm430-w350\nbaud = 4000000\nreturn_delay_us = 0\n[robot a]\nids = 1,2,3,4,5,6\nlink = %s\n[robot b]\nids = 7,8,9,10,11,12\nlink = %s\n' \
		"$d/$name-a.pty" "$d/$name-b.pty" >"$d/$name.scenario"
	start "sim-$name" "$SIM" --scenario "$d/$name.scenario" --lcm-url "$u" --quiet --lockstep "$d/$name.clock" \
		--duration "$((RATE_2BUS_S + 2))"
	lockstep_up "$d/$name.clock" "$name" "$out" "$u" || return 0
	"$DMN" --port "$d/$name-a.pty" --ids 1,2,3,4,5,6,b:7,b:8,b:9,b:10,b:11,b:12 --set "bus.b.port=$d/$name-b.pty" \
		--set bus.b.baud=4000000 --baud 4000000 --robot r12 --lcm-url "$u" --mode oscillator \
		--set robot.period_ms=2 --lockstep "$d/$name.clock" >"$T/dmn-$name.log" 2>&1
	wait "${PID[sim-$name]}" 2>/dev/null
	unset "PID[sim-$name]"
	stop "log-$name"
	# the first 2 simulated seconds (start-up, ramp) left out
	"$HB/logstat" --sender-time --skip 2 "$out.lcm" >"$out"
	sed -n 's/^undulate-sim: lockstep: \([0-9.]*\) s of simulated time in \([0-9.]*\) s.*/lockstep_sim_s \1\nlockstep_wall_s \2/p' \
		"$T/sim-$name.log" >>"$out"
	[ -n "${KEEP_BENCH_DIR:-}" ] || rm -f "$out.lcm"
}

# rate_unmeasured FILE...: the first of the files that says "status not
# measured: ..." said, into $what; 1 when every one was measured
rate_unmeasured() {
	local f
	for f in "$@"; do
		[ -e "$f" ] && [ "$(v "$f" status)" = not ] || continue
		what=$(sed -n 's/^status //p' "$f")
		say "$what"
		return 0
	done
	return 1
}
# rate_realtime POLICY LOAD0 LOAD1: a budget run's first line
rate_realtime() { say "Real time, $1; load average at start $2, at the end $3."; }

# rate_why FILE PERIOD_US: why the real-time run overran, by the daemon's own
# count and beside what the machine gives a thread with nothing else running
rate_why() {
	local f=$1 p=$2 slack
	slack=$(awk -v p="$p" -v b="$(v "$f" all.bus_p50)" 'BEGIN { if (b == "nan") print "–"; else printf "%d", p - b }')
	if [ "$(v "$f" ov_total)" != nan ]; then
		say "Why, by undulated's own count over its whole run (start-up included): $(v "$f" ov_total) overruns, of"
		say "which $(v "$f" ov_skipped) periods skipped (the loop woke a period or more late) and $(v "$f" ov_cut) cycles still on the"
		say "bus at the next tick ($(v "$f" ov_cut_late) of them begun over half a period late)."
	else
		say "undulated counted no overrun over its whole run."
	fi
	if [ "$(v "$f" ct_n)" != nan ]; then
		say "The machine alone: cyclictest at the same period and policy for as long, nothing beside it, woke"
		say "$(v "$f" ct_slack) of $(v "$f" ct_n) times later than the cycle's slack ($p µs less the bus p50: $slack µs), $(v "$f" ct_period)"
		say "times a whole period or more late, at worst $(v "$f" ct_max) µs. The simulator's replies come from a second"
		say "thread open to the same lateness (its step lateness, where the table has it). The lockstep run, where"
		say "neither program can be late, is the cycle's own figure."
	elif [ "$(v "$f" ct_status)" = not ]; then
		say "The machine alone: $(sed -n 's/^ct_status //p' "$f")."
	fi
}
# rate_ct_what FILE: the summary's words on the machine's own lateness
rate_ct_what() {
	[ "$(v "$1" ct_n)" = nan ] && return 0
	echo "; cyclictest alone: $(v "$1" ct_slack) of $(v "$1" ct_n) wake-ups too late for the cycle to fit"
}

rate_2bus_table() {
	local f=$T/rate/2bus g=$T/rate/1bus lk=$T/rate/2bus-lock what lwhat
	say "### The budget: twelve XM430-W350 on two 4 Mbps buses, 500 Hz, ${RATE_2BUS_S} s"
	say ""
	if ! rate_unmeasured "$f"; then
		rate_realtime "$RATE_2BUS_POLICY" "$RATE_2BUS_LOAD0" "$RATE_2BUS_LOAD1"
		say "Six servos a bus (IDs 1-6 and b:7-12, two simulators), the daemon's reads in parallel; beside it the"
		say "same twelve on one bus. Bus time is the cycle's, the slower bus's. Lockstep: the two-bus run in"
		say "the simulator's virtual time (one simulator serving both links, one daemon on both over one"
		say "connection to the clock), where neither program can be late."
		say ""
		say "| run | STATEs | overruns | period p50 | p99 | max | bus p50 | p99 | max |"
		say "|---|---|---|---|---|---|---|---|---|"
		local r
		for r in "two buses:$f" "one bus:$g" "two buses, lockstep:$lk"; do
			local x=${r#*:}
			[ "$(v "$x" status)" = not ] && { say "| ${r%%:*} | $(sed -n 's/^status //p' "$x") |"; continue; }
			say "| ${r%%:*} | $(v "$x" all.n) | $(v "$x" all.overruns) | $(fmt "$(v "$x" all.period_p50)") |" \
				"$(fmt "$(v "$x" all.period_p99)") | $(fmt "$(v "$x" all.period_max)") | $(fmt "$(v "$x" all.bus_p50)") |" \
				"$(fmt "$(v "$x" all.bus_p99)") | $(fmt "$(v "$x" all.bus_max)") |"
		done
		what="real time ($RATE_2BUS_POLICY): $(v "$f" all.overruns) overruns in ${RATE_2BUS_S} s, bus p50 $(fmt "$(v "$f" all.bus_p50)") µs (one bus: $(v "$g" all.overruns) overruns, $(fmt "$(v "$g" all.bus_p50)") µs)$(rate_ct_what "$f"); load $RATE_2BUS_LOAD0"
		say ""
		rate_why "$f" 2000
	fi
	if [ "$(v "$lk" status)" = not ]; then
		lwhat="lockstep: $(sed -n 's/^status //p' "$lk")"
	else
		lwhat="lockstep (virtual time, $(fmt "$(v "$lk" lockstep_sim_s)" 1) s in $(fmt "$(v "$lk" lockstep_wall_s)" 1) s): $(v "$lk" all.overruns) overruns, bus p50 $(fmt "$(v "$lk" all.bus_p50)") µs"
	fi
	say ""
	sum "12 servos on two buses at 500 Hz" "no overrun" "$what; $lwhat"
}

# rate_1k_lockstep: the same robot in virtual time, RATE_1K_S simulated seconds
rate_1k_lockstep() { rate_lockstep 1k-lock 6 4000000 1 fast "$RATE_1K_S"; }

rate_1k_table() {
	local f=$T/rate/1k-6-1 b=$T/rate/1k-6.bc lk=$T/rate/1k-lock-1 floor what lwhat
	floor=$(v "$b" floor_us)
	say "### The budget: six XM430-W350, one 4 Mbps bus, 1 kHz, ${RATE_1K_S} s"
	say ""
	if ! rate_unmeasured "$T/rate/1k-6.sim" "$f"; then
		rate_realtime "$RATE_1K_POLICY" "$RATE_1K_LOAD0" "$RATE_1K_LOAD1"
		say "Fast Sync Read floor of the 10-byte cycle: $floor µs. At 1 ms undulated publishes every 10th cycle's"
		say "STATE: the percentiles below are over those, its slow cycles (13 bytes a servo through its indirect"
		say "block, the default: floor 435 µs; 21 bytes, 555 µs, without it); the overruns are its counter, over"
		say "every cycle. Lockstep: the same, in the simulator's virtual time."
		say ""
		say "| run | STATEs | overruns | period p50 | p99 | max | bus p50 | p99 | max | bus p50/floor | simulator step lateness p99 | max |"
		say "|---|---|---|---|---|---|---|---|---|---|---|---|"
		say "| real time | $(v "$f" all.n) | $(v "$f" all.overruns) | $(fmt "$(v "$f" all.period_p50)") | $(fmt "$(v "$f" all.period_p99)") |" \
			"$(fmt "$(v "$f" all.period_max)") | $(fmt "$(v "$f" all.bus_p50)") | $(fmt "$(v "$f" all.bus_p99)") |" \
			"$(fmt "$(v "$f" all.bus_max)") | $(ratio "$(v "$f" all.bus_p50)" "$floor") |" \
			"$(fmt "$(v "$f" truth.late_p99)") | $(fmt "$(v "$f" truth.late_max)") |"
		what="real time ($RATE_1K_POLICY): $(v "$f" all.overruns) overruns in ${RATE_1K_S} s; bus p50 $(fmt "$(v "$f" all.bus_p50)") µs = $(ratio "$(v "$f" all.bus_p50)" "$floor") the floor ($floor µs); simulator step lateness p99 $(fmt "$(v "$f" truth.late_p99)") µs; load $RATE_1K_LOAD0"
		grep -q '^fell_back' "$f" && what="$what; Fast Sync Read given up during the run"
		what="$what$(rate_ct_what "$f")"
	fi
	if [ "$(v "$lk" status)" = not ]; then
		lwhat="lockstep: $(sed -n 's/^status //p' "$lk")"
	else
		say "| lockstep, $(fmt "$(v "$lk" lockstep_sim_s)" 1) s in $(fmt "$(v "$lk" lockstep_wall_s)" 1) s | $(v "$lk" all.n) | $(v "$lk" all.overruns) |" \
			"$(fmt "$(v "$lk" all.period_p50)") | $(fmt "$(v "$lk" all.period_p99)") | $(fmt "$(v "$lk" all.period_max)") |" \
			"$(fmt "$(v "$lk" all.bus_p50)") | $(fmt "$(v "$lk" all.bus_p99)") | $(fmt "$(v "$lk" all.bus_max)") |" \
			"$(ratio "$(v "$lk" all.bus_p50)" "$floor") | – | – |"
		lwhat="lockstep (virtual time): $(v "$lk" all.overruns) overruns, bus p50 $(fmt "$(v "$lk" all.bus_p50)") µs"
	fi
	say ""
	[ -e "$f" ] && [ "$(v "$f" status)" != not ] && { rate_why "$f" 1000; say ""; }
	sum "6 XM430-W350, one 4 Mbps bus, 1 kHz, ${RATE_1K_S} s" "no overrun; bus time ≤ 1.3× the Fast Sync Read wire floor" "$what; $lwhat"
}

# ---- main -------------------------------------------------------------------------
main() {
	local missing=()
	for p in "$SIM" "$DMN"; do [ -x "$p" ] || missing+=("$p"); done
	command -v lcm-logger >/dev/null || missing+=(lcm-logger)
	command -v cyclictest >/dev/null || missing+=("cyclictest (apt-get install rt-tests)")
	if [ ${#missing[@]} -gt 0 ]; then
		echo "bench: missing: ${missing[*]} (run \`make bench\`, which builds everything first)" >&2
		return 1
	fi
	if ! build_helpers; then
		echo "bench: the helpers in bench/ did not compile" >&2
		return 1
	fi
	# The slack the daemon adds to every bus timeout, as its configuration
	# says: the derived timeout printed here is then the one it uses.
	MARGIN_US=$("$DMN" --port /dev/null --ids 1,2 --check-config -v 2>/dev/null |
		awk -F' *= *' '$1 == "bus_margin_us" { print $2 }')
	MARGIN_SAY="the daemon's scheduling margin (robot.bus_margin_us = $MARGIN_US µs)"
	if [ -z "$MARGIN_US" ]; then
		MARGIN_US=0
		MARGIN_SAY="the daemon's scheduling margin (unknown: \`undulated --check-config -v\` did not say; 0 used)"
	fi

	local started head
	started=$(date +%s)
	head="$(date -u '+%Y-%m-%d %H:%M UTC'); $(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //'), $(nproc) cores,"
	head="$head Linux $(uname -r); $(cyclictest --help 2>&1 | head -n1); load average at start $(cut -d' ' -f1-3 /proc/loadavg)."
	: >"$REPORT"
	: >"$SUMMARY"
	wants loop && section_loop
	wants bus && section_bus
	wants missing && section_missing
	wants rate && section_rate
	wants loop && section_resources
	wants cap && section_cap
	wants plane && section_plane
	wants codec && section_codec
	wants cg && section_cg
	wants web && section_web
	wants lockstep && section_lockstep
	wants model && section_model
	{
		echo "# undulate benchmarks"
		echo
		echo "$head"
		echo "Suite time: $(($(date +%s) - started)) s; load average at the end $(cut -d' ' -f1-3 /proc/loadavg)" \
			"(other work on the machine shows in every timing figure: compare runs at similar load)."
		echo "Figures, not pass/fail: see bench/README.md for how to read them."
		echo
		echo "## Summary against the budgets (bench/README.md)"
		echo
		echo "| what | budget | measured |"
		echo "|---|---|---|"
		cat "$SUMMARY"
		echo
		cat "$REPORT"
	} >"$OUT"
	echo
	cat "$OUT"
	echo "bench: written to $OUT" >&2
}

main
