#!/usr/bin/env bash
# scripts/demo.sh — robots on the simulated bus, one undulated per robot.
#
#   make demo                       the paper's contact-force experiment, watched live:
#                                   ten three-link robots in the plane, in an arena
#                                   whose walls close over its first 12 s, 20 s on
#                                   the clock (SINUSOID), then on the oscillator,
#                                   the joints torque-driven as in the paper's
#                                   force simulations; q stops it and prints the
#                                   summary
#   make demo DEMO_SECONDS=60       the same headless for 60 s, then the summary
#
# The run is kept (the LCM log, the analysis, the programs' logs) in DEMO_OUT
# or --out, by default demo-out/<date>-<time> in the current directory (a
# directory of yours that no other user can write: another user's, or one
# others may write, is refused before the run; scripts/outdir.sh); the
# summary says how the contact force and the collisions changed at the switch,
# each neighbouring pair's final phase difference against its compatibility
# bound 2 asin(d~), and the command that draws the plots.
#
# Used directly it runs any scenario the same way (the experiments in
# docs/EXPERIMENTS.md and the end-to-end tests are built on it):
#
#   scripts/demo.sh [--scenario FILE] [--seconds S] [--set SEC.KEY=VAL]...
#                   [--daemon-set SEC.KEY=VAL]... [--start-mode MODE]
#                   [--switch-at S|never] [--switch-to MODE] [--phases random|LIST]
#                   [--seed N] [--window S] [--out DIR] [--lcm-url URL]
#                   [--no-realtime] [--lockstep] [--compress]
#
# The robots start in --start-mode (default SINUSOID, each with its own phase:
# random, or the comma-separated radians of --phases in scenario order) and are
# switched to --switch-to (default OSCILLATOR) by one command to every
# robot --switch-at seconds after they are all running (default 20). Starting
# from the clock-driven sinusoid is how the paper starts its runs, and it is
# what gives every robot a chosen phase: a robot started in OSCILLATOR from
# rest begins at phase 0 or π only.
#
# The simulator and the daemons run under SCHED_FIFO where the machine allows
# it (root, or LimitRTPRIO/an rtprio limit), the simulator above the daemons:
# servos do not slow down when their computer is busy, and a robot's unit runs
# its daemon at real-time priority (systemd/). Where it is not allowed each says
# so once and runs with normal scheduling; --no-realtime (or DEMO_REALTIME=0)
# never asks.
#
# --lockstep (or DEMO_LOCKSTEP=1) runs the same scenario with the same
# programs in the simulator's virtual time, headless, as fast as the machine
# allows: the simulator owns the clock and every daemon's cycle is paced by it
# (sim-bridge/README.md, "Lockstep"). --seconds, --switch-at and the contact
# samples are then simulated seconds from the start, the switch is a command
# the simulator delivers to every daemon at that simulated time, and the same
# --seed gives the same run.
#
# --compress (or DEMO_COMPRESS=1; make demo sets it) keeps the run in a
# third of the space, everything in it: the LCM log as demo.lcmlog.xz (every
# message; undulate-analyze reads it as it is) and the per-sample CSVs
# (states, phase_diff, collisions, plane) as .csv.xz (every row; xz -dc,
# pandas and R read them). Measured on the default scene in lockstep, 30 s:
# 32 MB plain (64 MB a minute: the log 40, states.csv 15, phase_diff.csv 6),
# 8.6 MB compressed (17 MB a minute); xz -1 takes about 4 s per 20 MB of log.
# The experiments' scripts and the tests read the plain files: off by default.
#
# Everything runs in a private temporary directory on a private LCM port
# (printed at start), so two demos, or a demo and the tests, never hear each
# other. Ctrl-C (or SIGTERM, SIGHUP) stops the daemons, the simulator and the
# logger by PID, waits for them, and removes the pty links and the directory.
# A run that ends early — a signal, Ctrl-C in undulate-top, a program that
# stopped during the run (a daemon killed) — says what ran (the start mode
# and for how long, the switch mode if it came) and what did not, and keeps
# what it has in the run's folder: the LCM log so far, every program's log,
# early-stop.txt with those lines, unanalysed, and the command that analyses it.
set -u

# Every process this script starts costs a few milliseconds: `make figures`
# runs it about 1,600 times, so what the shell can do itself (clock, arithmetic,
# names, reading a short log) it does without starting one.
case "$0" in */*) top=${0%/*} ;; *) top=. ;; esac
top=$(cd "${top:-/}/.." && pwd)
source "$top/scripts/outdir.sh"

BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$top/$BUILD" ;; esac
B="$BUILD/bin"

# now_ns VAR: the wall clock in ns (date +%s%N's number, to the microsecond),
# without a process.
now_ns() { local -n _now=$1; _now=${EPOCHREALTIME//[!0-9]/}000; }
# parent_of VAR PATH: VAR = dirname PATH, without a process.
parent_of() {
	local -n _par=$1
	local p=$2
	while [[ $p == */ && $p != / ]]; do p=${p%/}; done
	case "$p" in */*) p=${p%/*} ;; *) p=. ;; esac
	while [[ $p == */ && $p != / ]]; do p=${p%/}; done
	_par=${p:-/}
}
# nap S: a pause of S seconds without a process: read's timeout on a pipe
# no one writes (opened once, read and written by this shell alone).
nap_fd=""
nap() {
	[ -n "$nap_fd" ] || exec {nap_fd}<> <(:)
	read -r -t "$1" -u "$nap_fd" _ || :
}

# ---- a run that ends early ------------------------------------------------------
# early_keep RUN WHY [VERB]: the run in RUN stopped before its end, its
# programs already stopped (WHY: "SIGTERM", "Ctrl-C", "undulated-r2 stopped
# during the run: killed by SIGKILL"; VERB: "stopped early", or "ended" for a
# run that broke). Says on stderr what ran and what did not, keeps
# the LCM log so far and every program's log in the run's folder (RUN/out,
# written by the worker once it is known), and prints the command that
# analyses the log. The worker's record of the run (RUN/plan, RUN/t_ready,
# RUN/switch.time) says what ran; in lockstep the simulator's log does (its
# samples every 5 simulated seconds, and the switch it delivered).
early_keep() {
	local run=$1 why=$2 verb=${3:-stopped early} out k v start_mode="" switch_at="" switch_to="" lockstep=0 seconds="" el="" sw="" of
	[ -d "$run" ] || return 0   # the worker ended and cleaned up: nothing was cut short
	if [ ! -f "$run/out" ] || [ ! -f "$run/plan" ]; then
		echo "demo: stopped early ($why) before the robots started: nothing ran, nothing kept" >&2
		return 0
	fi
	out=$(cat "$run/out")
	while IFS='=' read -r k v; do
		case $k in
		start_mode) start_mode=$v ;; switch_at) switch_at=$v ;; switch_to) switch_to=$v ;;
		lockstep) lockstep=$v ;; seconds) seconds=$v ;;
		esac
	done <"$run/plan"
	if [ -f "$run/analysing" ]; then
		echo "demo: stopped ($why) while the run was being analysed; its LCM log is kept: $out/demo.lcmlog" >&2
		echo "demo: to analyse it: $B/undulate-analyze $out/demo.lcmlog --out $out/analysis" >&2
		return 0
	fi
	if [ "$lockstep" = 1 ]; then
		# the simulator's exit line (it was stopped), else its last sample
		el=$(sed -n "s/^undulate-sim: lockstep: \([0-9.]*\) s of simulated time.*/\1/p" "$run/sim.log" 2>/dev/null)
		[ -n "$el" ] || el=$(sed -n "s/^undulate-sim: t=\([0-9.]*\) event .*/\1/p" "$run/sim.log" 2>/dev/null | tail -n 1)
		el=$(awk -v t="${el:-0}" 'BEGIN { printf "%.1f", t }')
		of="of $seconds s of simulated time"
		grep -q "event 'command \* mode $switch_to': ok" "$run/sim.log" 2>/dev/null && sw=$switch_at
	elif [ -f "$run/t_ready" ]; then
		local t0
		t0=$(cat "$run/t_ready")
		# when it was found stopped (RUN/t_end), not after its programs were
		el=$(( ($(cat "$run/t_end" 2>/dev/null || date +%s%N) - t0) / 1000000000 ))
		of=${seconds:+of $seconds s}
		of=${of:-on the terminal}
		[ -f "$run/switch.time" ] && sw=$(( ($(cat "$run/switch.time") - t0) / 1000000000 ))
	fi
	local report=()
	if [ -z "$el" ]; then
		report+=("demo: $verb ($why) while the robots were starting: nothing ran")
	else
		report+=("demo: $verb ($why) after $el s $of")
		if [ -n "$sw" ]; then
			report+=("demo: ran: $start_mode (the clock) for $sw s, then $switch_to for $(awk -v e="$el" -v s="$sw" 'BEGIN { printf "%.0f", (e > s ? e - s : 0) }') s")
		elif [ "$switch_at" = never ]; then
			report+=("demo: ran: $start_mode for $el s (no switch planned)")
		else
			report+=("demo: ran: $start_mode (the clock) for $el s; did not run: $switch_to (due at $switch_at s): THE ${switch_to^^} NEVER RAN")
		fi
	fi
	printf '%s\n' "${report[@]}" >&2
	local parent keep
	parent_of parent "$out"
	{ [ -d "$parent" ] || mkdir -p -- "$parent"; } && outdir_check "$out" "demo: --out" ||
		{ echo "demo: the run could not be kept (above)" >&2; return 1; }
	keep="$run/keep"
	rm -rf -- "$keep"
	mkdir -m 700 "$keep" "$keep/logs" || { echo "demo: cannot create $keep: the run is not kept" >&2; return 1; }
	cp "$run"/*.log "$keep/logs/" 2>/dev/null
	printf '%s\n' "${report[@]}" >"$keep/early-stop.txt"
	[ -f "$run/seed" ] && cp "$run/seed" "$keep/seed"
	local what="logs/ (every program's log), early-stop.txt (these lines); not analysed"
	if [ -s "$run/demo.lcmlog" ]; then
		outdir_mv "$run/demo.lcmlog" "$out/demo.lcmlog" || { echo "demo: cannot move the LCM log into $out" >&2; return 1; }
		what="demo.lcmlog ($(du -k "$out/demo.lcmlog" | cut -f1) kB, the LCM log so far), $what"
	fi
	outdir_publish "$keep" "$out" || { echo "demo: could not move everything into $out (above)" >&2; return 1; }
	echo "demo: the run so far is kept in $out: $what" >&2
	[ -f "$out/demo.lcmlog" ] && echo "demo: to analyse it: $B/undulate-analyze $out/demo.lcmlog --out $out/analysis" >&2
	return 0
}

# ---- supervisor ---------------------------------------------------------------
# The demo runs as two processes: this one only waits, and a worker (this
# script again, with UNDULATE_DEMO_RUN set) does the work. A signal trap in
# bash 5.2 that fires while the shell is parsing a command substitution (the
# worker runs many: timing, awk) is itself parsed in the middle of it and
# fails ("trap: unexpected EOF while looking for matching `)'"); the script
# then went on as if nothing had happened: a SIGTERM gave a summary and exit 0
# (seen under the sanitizer build's timing). Here the traps fire while the
# shell sits in `wait`, where nothing is being parsed: they kill the worker,
# stop what it started (its "PID NAME" lines in $run/pids: the daemons first,
# which leave the robots in their safe state while the simulated bus still
# answers, then the simulator and the logger) and remove the directory.
# stop_pids PID...: SIGTERM to all at once, up to 3 s, then SIGKILL. Watched
# with kill -0, which works for the supervisor too (they are not its children).
stop_pids() {
	local pid k
	[ $# -gt 0 ] || return 0
	kill -TERM "$@" 2>/dev/null
	for ((k = 0; k < 600; k++)); do
		for pid in "$@"; do kill -0 "$pid" 2>/dev/null && break; pid=""; done
		[ -z "$pid" ] && return 0
		nap 0.005
	done
	for pid in "$@"; do
		kill -0 "$pid" 2>/dev/null && echo "demo: pid $pid ignored SIGTERM for 3 s; killing it" >&2
	done
	kill -KILL "$@" 2>/dev/null
}
if [ -z "${UNDULATE_DEMO_RUN:-}" ]; then
	sv_run=$(mktemp -d "${TMPDIR:-/tmp}/undulate-demo.XXXXXX") ||
		{ echo "demo: cannot make a temporary directory" >&2; exit 1; }
	# stdin stays the terminal: undulate-top reads its keys from it
	UNDULATE_DEMO_RUN=$sv_run "$0" "$@" <&0 &
	sv_worker=$!
	sv_stop() {
		trap '' INT TERM HUP
		[ -d "$sv_run" ] && date +%s%N >"$sv_run/t_end"
		kill -KILL "$sv_worker" 2>/dev/null
		wait "$sv_worker" 2>/dev/null
		local pid name first=() rest=()
		if [ -f "$sv_run/pids" ]; then
			while read -r pid name; do
				case "$name" in sim|logger) rest+=("$pid") ;; *) first+=("$pid") ;; esac
			done <"$sv_run/pids"
		fi
		stop_pids ${first[@]+"${first[@]}"}
		stop_pids ${rest[@]+"${rest[@]}"}
		# the worker is gone (SIGKILL): whatever it was doing, its record says what ran
		# (after the terminal's "^C", on a line of its own)
		[ "$2" = Ctrl-C ] && [ -t 2 ] && echo >&2
		[ -f "$sv_run/done" ] || early_keep "$sv_run" "$2"
		rm -rf "$sv_run"
		exit "$1"
	}
	trap 'sv_stop 130 Ctrl-C' INT
	trap 'sv_stop 143 SIGTERM' TERM
	trap 'sv_stop 129 "SIGHUP: the terminal closed"' HUP
	sv_rc=0
	wait "$sv_worker" || sv_rc=$?
	[ ! -e "$sv_run" ] || rm -rf "$sv_run"   # normally gone already: the worker removes it
	exit "$sv_rc"
fi
scenario="$top/sim-bridge/scenarios/plane-demo.scenario"
default_scenario=1
seconds=${DEMO_SECONDS:-}
sim_sets=()
daemon_sets=()
# make demo's robots (plane-demo.scenario), driven as the paper's force
# simulations were: torque-driven joints on a current drive, the clock as
# tau = k (alpha_bar - alpha) with the paper's stiffest k (and the damping the
# plane robot's joints need: daemon/CONTROL.md, "The clock as a torque law"),
# then the oscillator as a torque law with the parameters undulated --tune
# found on the plane robot, its joints 2 pi / 3 apart ("The joints' lag").
# Given only for the default scenario; another scenario runs the daemon's
# defaults and the --daemon-set given.
plane_demo_sets=(--set robot.actuation=torque --set robot.torque_drive=current
	--set sinusoid.stiffness=0.135 --set sinusoid.damping=0.01 --set sinusoid.amplitude=0.8 --set sinusoid.frequency=0.8
	--set joint.1.k=0.0368 --set joint.2.k=0.0368 --set joint.1.mu=0.064 --set joint.2.mu=0.088
	--set joint.1.coupling_phase=-0.05 --set joint.2.coupling_phase=0.05)
start_mode=sinusoid
switch_at=20
switch_to=oscillator
phases=random
seed=""
window=10
out=${DEMO_OUT:-}
url=${DEMO_LCM_URL:-}
# SCHED_FIFO priorities: the simulated servos first, then the control loops
RT_SIM=30
RT_DAEMON=20
realtime=${DEMO_REALTIME:-1}
lockstep=${DEMO_LOCKSTEP:-0}
compress=${DEMO_COMPRESS:-0}
# How long a program may take to say it is ready (s).
READY_TIMEOUT_S=10

usage() {
	sed -n '2,/^set -u/p' "$0" | sed -e '/^set -u/d' -e 's/^# \{0,1\}//' >&2
	exit 2
}

while [ $# -gt 0 ]; do
	case "$1" in
	--scenario) scenario=$2; default_scenario=0; shift 2 ;;
	--seconds) seconds=$2; shift 2 ;;
	--set) sim_sets+=(--set "$2"); shift 2 ;;
	--daemon-set) daemon_sets+=(--set "$2"); shift 2 ;;
	--start-mode) start_mode=$2; shift 2 ;;
	--switch-at) switch_at=$2; shift 2 ;;
	--switch-to) switch_to=$2; shift 2 ;;
	--phases) phases=$2; shift 2 ;;
	--seed) seed=$2; shift 2 ;;
	--window) window=$2; shift 2 ;;
	--out) out=$2; shift 2 ;;
	--lcm-url) url=$2; shift 2 ;;
	--no-realtime) realtime=0; shift ;;
	--lockstep) lockstep=1; shift ;;
	--compress) compress=1; shift ;;
	-h|--help) usage ;;
	*) echo "demo: unknown argument '$1' (--help)" >&2; exit 2 ;;
	esac
done

die() { echo "demo: $*" >&2; exit 1; }
[ "$default_scenario" = 1 ] && daemon_sets=("${plane_demo_sets[@]}" ${daemon_sets[@]+"${daemon_sets[@]}"})
is_number() { [[ "$1" =~ ^-?[0-9]+([.][0-9]+)?$ ]]; }
# fixed9 VAR X: VAR = X (is_number's) in billionths, when it has at most 9
# digits either side of the point; else 1.
fixed9() {
	local -n _f=$1
	[[ $2 =~ ^(-?)([0-9]{1,9})([.]([0-9]{1,9}))?$ ]] || return 1
	local frac=${BASH_REMATCH[4]}000000000
	_f=$(( 10#${BASH_REMATCH[2]} * 1000000000 + 10#${frac:0:9} ))
	[ -z "${BASH_REMATCH[1]}" ] || _f=$(( -_f ))
}
# num_lt A B: A < B for numbers is_number accepts: in the shell for every
# setting with at most 9 digits either side of the point, else by awk.
num_lt() {
	local x y
	if fixed9 x "$1" && fixed9 y "$2"; then
		[ "$x" -lt "$y" ]
	else
		awk -v a="$1" -v b="$2" 'BEGIN { exit !(a < b) }'
	fi
}

[ -f "$scenario" ] || die "no scenario file '$scenario'"
for p in undulate-sim undulated undulate-analyze undulate-top; do
	[ -x "$B/$p" ] || die "$B/$p is not built (run: make BUILD=$BUILD)"
done
[ -z "$seconds" ] || { is_number "$seconds" && [ "${seconds%.*}" -gt 0 ]; } || die "--seconds/DEMO_SECONDS: want a positive number, got '$seconds'"
[ "$switch_at" = never ] || is_number "$switch_at" || die "--switch-at: seconds or 'never'"
is_number "$window" || die "--window: seconds"
interactive=0
[ -z "$seconds" ] && [ -t 1 ] && [ "$lockstep" != 1 ] && interactive=1
if [ -z "$seconds" ] && [ "$interactive" -eq 0 ]; then
	seconds=60  # not a terminal: nobody could watch or press Ctrl-C
fi
# Where the run is kept: created at the end, when there is something to keep.
[ -n "$out" ] || out="$PWD/demo-out/$(date +%Y%m%d-%H%M%S)"
case "$out" in /*) ;; *) out="$PWD/$out" ;; esac
# One that exists must be ours and writable by no other user (scripts/outdir.sh
# says why): said now rather than after the run.
if [ -e "$out" ] || [ -L "$out" ]; then outdir_check "$out" "demo: --out" || exit 1; fi

# A private multicast port (udpm, ttl=0: nothing leaves this host). The tests
# use 7600-7949; the demo picks one of 10000 ports above them from its PID.
[ -n "$url" ] || url="udpm://239.255.76.67:$((17600 + $$ % 10000))?ttl=0"
[ -n "$seed" ] || seed=$(( (RANDOM << 15 | RANDOM) % 1000000 + 1 ))

run=$UNDULATE_DEMO_RUN
links="$run/links"
# nap's pipe, opened before anything is started (start closes it for them)
exec {nap_fd}<> <(:)
mkdir -p "$links"
# what an early stop (early_keep, above) needs to say what ran and to keep it
echo "$out" >"$run/out"
echo "$seed" >"$run/seed"
printf '%s\n' "start_mode=$start_mode" "switch_at=$switch_at" "switch_to=$switch_to" "lockstep=$lockstep" \
	"seconds=$seconds" >"$run/plan"

pids=()       # everything we started, in start order
names=()
cleaning=0
# stop_group PID...: stop them (stop_pids) and reap them.
stop_group() {
	local pid
	stop_pids "$@"
	for pid in "$@"; do wait "$pid" 2>/dev/null; done
}
# stop_children: the daemons first (they leave the robots in their safe state
# while the simulated bus still answers), then the simulator and the logger.
stop_children() {
	local i first=() rest=()
	for i in "${!pids[@]}"; do
		case "${names[$i]}" in sim|logger) rest+=("${pids[$i]}") ;; *) first+=("${pids[$i]}") ;; esac
	done
	stop_group ${first[@]+"${first[@]}"}
	stop_group ${rest[@]+"${rest[@]}"}
	pids=() names=()
}
cleanup() {
	[ "$cleaning" -eq 1 ] && return
	cleaning=1
	trap '' INT TERM
	[ -n "${sleep_pid:-}" ] && kill "$sleep_pid" 2>/dev/null
	stop_children
	rm -rf "$run"
}
trap cleanup EXIT
# No INT/TERM traps here: the supervisor (above) takes the signals, and as its
# background job this worker ignores SIGINT anyway.

# Each program runs in a session of its own (setsid), as a robot's service runs
# in a cgroup of its own. With the kernel's autogroups everything started from
# one session shares one scheduling group: started from a shell that also runs
# CPU-bound work, the kernel worker that carries the simulated buses' bytes was
# seen waiting over half a second to run (docs/LIMITS.md, "Under load"). A background
# job of a script is not a process group leader, so setsid execs and the PID
# kept below is the program's; stopping by PID does not depend on the session.
own_session=()
command -v setsid >/dev/null 2>&1 && own_session=(setsid)
# record PID NAME: keep what was started, here and for the supervisor.
record() {
	pids+=("$1")
	names+=("$2")
	echo "$1 $2" >>"$run/pids"
}
start() {
	local name=$1; shift
	${own_session[@]+"${own_session[@]}"} "$@" >"$run/$name.log" 2>&1 {nap_fd}<&- &
	record "$!" "$name"
}

# pid_of VAR NAME: VAR = the PID of a process we started ("" if none).
pid_of() {
	local -n _pid=$1
	local i
	_pid=""
	for i in "${!names[@]}"; do [ "${names[$i]}" = "$2" ] && _pid=${pids[$i]}; done
	return 0
}
# log_has FILE REGEX: a line of FILE (a program's log, short while it starts)
# matches the extended REGEX, as grep -qE finds it, read by the shell itself;
# the first such line in log_line.
log_line=""
log_has() {
	local line
	while IFS= read -r line || [ -n "$line" ]; do
		[[ $line =~ $2 ]] && { log_line=$line; return 0; }
	done 2>/dev/null <"$1"
	return 1
}
# wait_ready NAME REGEX: poll NAME's log until REGEX appears; 1 (with its log's
# tail) if it exits or takes longer than READY_TIMEOUT_S.
wait_ready() {
	local name=$1 re=$2 pid now deadline
	pid_of pid "$name"
	now_ns now
	deadline=$(( now + READY_TIMEOUT_S * 1000000000 ))
	until log_has "$run/$name.log" "$re"; do
		now_ns now
		if ! kill -0 "$pid" 2>/dev/null || [ "$now" -ge "$deadline" ]; then
			echo "demo: $name did not become ready; its log:" >&2
			tail -n 15 "$run/$name.log" | sed 's/^/    /' >&2
			return 1
		fi
		nap 0.005
	done
}

# ---- logger -------------------------------------------------------------------
# Always: the run is analysed and kept, watched live or not.
log="$run/demo.lcmlog"
# undulate-analyze --record rather than lcm-logger: LCM 1.3.1 queues 30
# messages per subscription and drops the rest, which lcm-logger keeps; with
# the robots publishing several times faster than in real time (lockstep),
# or on a busy machine, a recorder that waits for a core lost messages.
start logger "$B/undulate-analyze" --record "$log" --lcm-url "$url"
wait_ready logger '^undulate-analyze: recording' || exit 1

# ---- simulator --------------------------------------------------------------
rt_sim=() rt_daemon=() lk_sim=() lk_daemon=()
[ "$lockstep" = 1 ] && realtime=0   # virtual time: no priority makes it truer
if [ "$realtime" = 1 ]; then rt_sim=(--realtime "$RT_SIM"); rt_daemon=(--set "robot.priority=$RT_DAEMON"); fi
if [ "$lockstep" = 1 ]; then
	# The simulator ends the run after --seconds of simulated time; the
	# contact samples (every CONTACT_SAMPLE_S, one just before the switch)
	# and the switch are its scheduled events, at simulated times.
	lk_sim=(--lockstep "$run/clock" --duration "$seconds")
	# (t is whole: t <= seconds is t <= its whole part, a positive number)
	for ((t = 0; t <= 10#${seconds%.*}; t += 5)); do
		lk_sim+=(--set "events.$t=stats")
	done
	if [ "$switch_at" != never ] && num_lt "$switch_at" "$seconds"; then
		lk_sim+=(--set "events.$switch_at=stats" --set "events.$switch_at=command * mode $switch_to")
	fi
	lk_daemon=(--lockstep "$run/clock")
fi
start sim "$B/undulate-sim" --scenario "$scenario" --link-dir "$links" --lcm-url "$url" \
	--seed "$seed" ${rt_sim[@]+"${rt_sim[@]}"} ${lk_sim[@]+"${lk_sim[@]}"} ${sim_sets[@]+"${sim_sets[@]}"}
wait_ready sim '^undulate-sim: ready:' || exit 1
# "ready: 4 buses: r1=/path/r1[1,2] r2=... bodies=..." names every robot, its
# pty and its servo IDs, in scenario (left to right) order.
ready_line=$log_line   # the line wait_ready found
robots=() ports=() ids=()
for word in $ready_line; do
	[[ "$word" =~ ^([A-Za-z0-9_-]+)=(/[^[]+)\[([0-9,]+)\]$ ]] || continue
	robots+=("${BASH_REMATCH[1]}"); ports+=("${BASH_REMATCH[2]}"); ids+=("${BASH_REMATCH[3]}")
done
[ ${#robots[@]} -gt 0 ] || die "cannot read the robots from the simulator's ready line: $ready_line"

# ---- phases -------------------------------------------------------------------
robot_phase=()
if [ "$phases" = random ]; then
	RANDOM=$seed
	draws=()
	for _ in "${robots[@]}"; do
		# drawn here, not inside $(...): bash reseeds RANDOM in every
		# subshell, and the seed would not fix the phases
		draws+=("$RANDOM")
	done
	# one awk for every robot's phase
	read -r -a robot_phase < <(awk -v rs="${draws[*]}" 'BEGIN { n = split(rs, r, " ")
		for (i = 1; i <= n; i++) printf "%s%.3f", (i > 1 ? " " : ""), (r[i] / 32768.0) * 6.283185 - 3.141593; print "" }')
	[ ${#robot_phase[@]} -eq ${#robots[@]} ] || die "could not draw the robots' random phases (awk)"
else
	IFS=, read -r -a robot_phase <<<"$phases"
	[ ${#robot_phase[@]} -eq ${#robots[@]} ] || die "--phases: ${#robots[@]} robots, ${#robot_phase[@]} phases"
	for p in "${robot_phase[@]}"; do is_number "$p" || die "--phases: '$p' is not a number (radians)"; done
fi

# ---- one daemon per robot -----------------------------------------------------
start_daemon() {
	local i=$1
	start "undulated-${robots[$i]}" "$B/undulated" --port "${ports[$i]}" --ids "${ids[$i]}" \
		--robot "${robots[$i]}" --lcm-url "$url" --mode "$start_mode" \
		--set "sinusoid.phase=${robot_phase[$i]}" ${rt_daemon[@]+"${rt_daemon[@]}"} \
		${lk_daemon[@]+"${lk_daemon[@]}"} ${daemon_sets[@]+"${daemon_sets[@]}"}
}
# In lockstep every daemon starts at once: the simulated time (and so every
# daemon's start-up) moves only once all of them have joined.
if [ "$lockstep" = 1 ]; then
	for i in "${!robots[@]}"; do start_daemon "$i"; done
	for i in "${!robots[@]}"; do wait_ready "undulated-${robots[$i]}" 'ready:' || exit 1; done
fi
# Start-up attempts per daemon (see below).
START_ATTEMPTS=3
# One after the other: start-up is the busiest moment on the simulated buses
# (every daemon pings, reads and configures its servos), and the robots need
# not start together (SINUSOID runs on the wall clock, and the switch comes
# when all are up).
for i in "${!robots[@]}"; do
	[ "$lockstep" = 1 ] && break
	name="undulated-${robots[$i]}"
	start_daemon "$i"
	for ((attempt = 1; attempt <= START_ATTEMPTS; attempt++)); do
		wait_ready "$name" 'ready:' && continue 2
		# A start-up transaction that fails for good (a reply lost or
		# garbled more often than undulated retries it: "... failed: no
		# reply / bad checksum / unexpected length") ends undulated's start;
		# on a heavily loaded machine the simulated bus can answer late. Say
		# so and try again; anything else (e.g. a bad setting) is fatal.
		pid_of pid "$name"
		kill -0 "$pid" 2>/dev/null && break
		grep -qE 'failed: |did not answer a PING' "$run/$name.log" || break
		[ "$attempt" -lt "$START_ATTEMPTS" ] || break
		echo "demo: $name: the simulated bus answered too late during start-up; starting it again" >&2
		# forget the failed process (it has exited) so it is not taken for a crash later
		for k in "${!names[@]}"; do
			[ "${names[$k]}" = "$name" ] || continue
			wait "${pids[$k]}" 2>/dev/null
			unset 'names[k]' 'pids[k]'
		done
		names=("${names[@]}") pids=("${pids[@]}")
		mv "$run/$name.log" "$run/$name.$attempt.log"
		start_daemon "$i"
	done
	exit 1
done
now_ns t_ready
echo "$t_ready" >"$run/t_ready"

# ---- the web dashboard, beside the terminal view --------------------------------
# undulate-web on loopback (DEMO_WEB_PORT, default 8080; any free port when
# that one is taken): the same robots in a browser, with the plots. Its URL
# carries the token it made (commands need it; a page without it watches).
web_url=""
start_web() {
	start web "$B/undulate-web" --listen "127.0.0.1:$1" --lcm-url "$url"
	wait_ready web 'open http://[^ ]*#token=' 2>/dev/null || return 1
	web_url=$(sed -n 's|^undulate-web: open \(http://[^ ]*#token=[^ ]*\) .*|\1|p' "$run/web.log")
}
if [ -x "$B/undulate-web" ] && [ "$lockstep" != 1 ]; then
	start_web "${DEMO_WEB_PORT:-8080}" || { mv "$run/web.log" "$run/web.1.log"; start_web 0; } ||
		echo "demo: undulate-web did not start (its log: $run/web.log); the terminal view only" >&2
fi

say() { [ "$interactive" -eq 1 ] || echo "demo: $*"; }
say "scenario ${scenario##*/}, ${#robots[@]} robots (${robots[*]}), seed $seed, LCM $url"
say "phases at start (rad): ${robot_phase[*]}; $start_mode until +${switch_at} s, then $switch_to"
[ -n "$web_url" ] && echo "demo: the dashboard: open $web_url in a browser (undulate-web; undulate-top is the terminal view)"

# switch_modes: one command to every robot (UNDULATE.CMD).
switch_modes() {
	if "$B/undulated" --command "mode $switch_to" --robot '*' --lcm-url "$url" --timeout 2 \
		>"$run/switch.log" 2>&1; then
		local now
		now_ns now
		echo "$now" >"$run/switch.time"
	else
		echo "demo: the switch to $switch_to was not accepted by every robot:" >&2
		sed 's/^/    /' "$run/switch.log" >&2
	fi
}

# sleep_until T_NS: sleep until the monotonic-enough wall time T_NS.
sleep_until() {
	local now left
	now_ns now
	left=$(( $1 - now ))
	[ "$left" -gt 0 ] || return 0
	# In the background and waited for: a trapped SIGTERM/SIGINT interrupts
	# `wait` at once, where a foreground sleep would delay it to its end.
	sleep "$(awk -v n="$left" 'BEGIN { printf "%.3f", n / 1e9 }')" &
	sleep_pid=$!
	wait "$sleep_pid"
	sleep_pid=""
	return 0
}
secs_ns() { awk -v s="$1" 'BEGIN { printf "%.0f", s * 1e9 }'; }

# ---- interactive: undulate-top in the foreground ------------------------------
# banner_loop: once a second, what the demo is doing and what comes next, on
# the line undulate-top shows under its title (--banner-file).
banner_loop() {
	local now el left
	trap '[ -n "${sleep_pid:-}" ] && kill "$sleep_pid" 2>/dev/null; exit 143' TERM
	while :; do
		now_ns now
		el=$(( (now - t_ready) / 1000000000 ))
		if [ -n "$web_url" ] && [ $((el % 5)) -eq 4 ]; then
			echo "DEMO ${el}s | in a browser: $web_url | ? legend  q end" >"$run/banner.new"
		elif [ "$switch_at" != never ] && [ ! -f "$run/switch.time" ]; then
			left=$(awk -v s="$switch_at" -v e="$el" 'BEGIN { printf "%d", s - e }')
			echo "DEMO ${el}s | on the CLOCK (${start_mode}) | ${switch_to} in ${left}s | ? legend  q end" >"$run/banner.new"
		else
			echo "DEMO ${el}s | on the ${switch_to}: watch contact force, collisions | ? legend  q end" >"$run/banner.new"
		fi
		mv -f "$run/banner.new" "$run/banner"
		sleep_until $(( now + 1000000000 ))
	done
}

if [ "$interactive" -eq 1 ]; then
	if [ "$switch_at" != never ]; then
		( trap '[ -n "${sleep_pid:-}" ] && kill "$sleep_pid" 2>/dev/null; exit 143' TERM
		  sleep_until $(( t_ready + $(secs_ns "$switch_at") )); switch_modes ) &
		record "$!" "switch timer"
	fi
	banner_loop &
	record "$!" banner
	# Ctrl-C reaches undulate-top (it restores the terminal and exits) and this
	# script, whose EXIT trap then stops everything (nothing is kept); q ends
	# undulate-top alone, and the run is analysed and kept below.
	# In the background and recorded, so that a signal to the supervisor
	# stops it too (it gives the terminal back on SIGTERM); its keys still
	# come from the terminal.
	"$B/undulate-top" --lcm-url "$url" --banner-file "$run/banner" <&0 &
	record "$!" top
	top_rc=0
	wait "$!" || top_rc=$?
	# 130: Ctrl-C (a key to undulate-top's raw terminal): stop at once, keep
	# the run unanalysed and say what ran
	if [ "$top_rc" -ne 0 ]; then
		now_ns now
		echo "$now" >"$run/t_end"
		# undulate-top leaves the cursor at the end of its last line
		[ -t 2 ] && echo >&2
		stop_children
		early_keep "$run" "$([ "$top_rc" -eq 130 ] && echo Ctrl-C || echo "undulate-top exit $top_rc")"
		exit "$top_rc"
	fi
	now_ns now
	seconds=$(awk -v n="$(( now - t_ready ))" 'BEGIN { printf "%.0f", n / 1e9 }')
fi

# ---- lockstep: the simulator runs the schedule and ends the run -------------------
if [ "$lockstep" = 1 ]; then
	sim_rc=0
	pid_of pid sim
	wait "$pid" || sim_rc=$?
	for i in "${!robots[@]}"; do pid_of pid "undulated-${robots[$i]}"; wait "$pid" 2>/dev/null; done
	# what the simulator's log (a few dozen lines) says, read once by the
	# shell: why the run ended, whether the switch was delivered, its speed
	ended="" switched=0 speed=""
	re_ended='^undulate-sim: lockstep: .*; ended: (.*)$'
	re_speed='^undulate-sim: lockstep: ([0-9.]* s of simulated time in [0-9.]* s \([0-9.]*x real time)'
	while IFS= read -r line || [ -n "$line" ]; do
		[[ $line == *"event 'command * mode $switch_to': ok"* ]] && switched=1
		[[ $line == "undulate-sim: lockstep: "* ]] || continue
		[[ $line =~ $re_ended ]] && ended+=${ended:+$'\n'}${BASH_REMATCH[1]}
		[[ $line =~ $re_speed ]] && speed+=${speed:+$'\n'}${BASH_REMATCH[1]}")"
	done 2>/dev/null <"$run/sim.log"
	if [ "$sim_rc" -ne 0 ]; then
		# a daemon killed stalls the lockstep clock: the simulator ends the run
		echo "demo: the lockstep run failed (undulate-sim exit $sim_rc): ${ended:-see its log}; its log ends:" >&2
		tail -n 8 "$run/sim.log" | sed 's/^/    /' >&2
		stop_children
		early_keep "$run" "the lockstep run failed: ${ended:-undulate-sim exit $sim_rc}"
		exit 1
	fi
	[ "$switched" = 1 ] && echo lockstep >"$run/switch.time"
	say "lockstep: $speed"
fi

# check_alive: a program that stopped during the run (a daemon killed, the
# simulator crashed) makes it another experiment: say which, keep what there
# is (early_keep) and end with exit 1. Checked at every contact sample and at
# the end (in lockstep the simulator ends a run whose daemon is gone).
check_alive() {
	local i gone gone_rc how now
	for i in "${!pids[@]}"; do
		[ "$lockstep" = 1 ] && return 0
		case "${names[$i]}" in "switch timer"|banner|top|web|analyze) continue ;; esac
		kill -0 "${pids[$i]}" 2>/dev/null && continue
		gone=${names[$i]}
		gone_rc=0
		wait "${pids[$i]}" 2>/dev/null || gone_rc=$?
		how="exit $gone_rc"
		[ "$gone_rc" -gt 128 ] && how="killed by SIG$(kill -l $((gone_rc - 128)) 2>/dev/null || echo $((gone_rc - 128)))"
		now_ns now
		echo "$now" >"$run/t_end"
		echo "demo: $gone stopped during the run ($how); its log ends:" >&2
		tail -n 8 "$run/$gone.log" | sed 's/^/    /' >&2
		stop_children
		early_keep "$run" "$gone stopped during the run: $how" "ended"
		exit 1
	done
}

# ---- headless -------------------------------------------------------------------
if [ "$interactive" -eq 0 ] && [ "$lockstep" != 1 ]; then
# sample_contact: ask the simulator for its running totals (SIM.CMD "stats");
# the reply, with the simulated time, lands in its log. The rate of its total
# impulse (impacts + resting contact) is the mean contact force: ground truth
# that the collision messages (impacts only) do not carry.
sample_contact() { "$B/undulate-sim" --cmd stats --lcm-url "$url" >/dev/null 2>&1; }
# Seconds between samples.
CONTACT_SAMPLE_S=5
sample_contact
next_sample=$CONTACT_SAMPLE_S
switch_pending=0
[ "$switch_at" != never ] && [ "$(secs_ns "$switch_at")" -lt "$(secs_ns "$seconds")" ] && switch_pending=1
while :; do
	# the next event: a sample, the switch, or the end
	next=$next_sample what=sample
	if [ "$switch_pending" -eq 1 ] && awk -v a="$switch_at" -v b="$next" 'BEGIN { exit !(a <= b) }'; then
		next=$switch_at what=switch
	fi
	if awk -v a="$seconds" -v b="$next" 'BEGIN { exit !(a <= b) }'; then
		next=$seconds what=end
	fi
	sleep_until $(( t_ready + $(secs_ns "$next") ))
	case $what in
	switch) sample_contact; switch_modes; switch_pending=0 ;;
	sample) sample_contact; next_sample=$(awk -v a="$next_sample" -v d=$CONTACT_SAMPLE_S 'BEGIN { print a + d }') ;;
	end) sample_contact; break ;;
	esac
	check_alive
done
fi
check_alive

# Stop the robots and the simulator, then the logger, so the log is complete.
stop_children

# The run is kept: $out checked again (it may have been made during the run),
# the log moved in first, so that the analysis names the kept file; everything
# else is made in $keep, inside our private $run, and moved into $out at the
# end, replacing whatever has those names there (scripts/outdir.sh): nothing
# is written through a link or read back from a file another user placed.
parent_of parent "$out"
[ -d "$parent" ] || mkdir -p -- "$parent" || die "cannot create $parent (DEMO_OUT / --out)"
outdir_check "$out" "demo: --out" || exit 1
keep="$run/keep"
mkdir -m 700 "$keep" || die "cannot create $keep"
: >"$run/analysing"   # a stop from now on finds the log in $out (early_keep)
outdir_mv "$log" "$out/demo.lcmlog" || die "cannot move the LCM log into $out"
log="$out/demo.lcmlog"
analysis="$keep"
"$B/undulate-analyze" "$log" --out "$analysis" --window "$window" --quiet >"$run/analyze.log" 2>&1 &
record "$!" analyze
rc=0
wait "$!" || rc=$?
# 3 = truncated log (the logger was stopped mid-message): partial results are still written.
[ "$rc" -eq 0 ] || [ "$rc" -eq 3 ] || die "undulate-analyze failed (exit $rc): $(tail -n 5 "$run/analyze.log")"

# Seconds from the start of the log to the switch: the daemons' "mode" events.
switch_t=""
if [ -f "$run/switch.time" ]; then
	switch_t=$(awk -F, -v to="-> ${switch_to^^}" \
		'$6 == "\"mode\"" && index($0, to) { printf "%.1f", $2; exit }' "$analysis/events.csv")
fi

# ---- summary --------------------------------------------------------------------
summary() {
echo
echo "=== undulate demo summary: ${#robots[@]} robots, $seconds s, ${scenario##*/} ==="
# A run that broke says so first: what follows describes a broken run
# (the analyser's "broken": latched faults, robots that stopped publishing,
# a simulator that fell behind real time).
# One jq for the two things read from summary.json (jq's start is its cost):
# the "broken" lines, then, after a record separator, the median contact
# force's line (said below, when there was a switch).
from_json=$(jq -r --arg from "$start_mode" --arg to "$switch_to" '(.broken[]?), "\u001e",
	(.force | select(.median_before_n != null and .median_after_n != null) |
	"  Median contact force of \(if .of == "contacts" then "all contacts (each touching pair over each 10 ms)" else "the 10 ms periods with contact" end): \(.median_before_n * 1000 | round / 1000) N on the \($from) (\(.samples_before) before the switch) -> \(.median_after_n * 1000 | round / 1000) N on the \($to) (\(.samples_after) in the final window).")' \
	"$analysis/summary.json" 2>/dev/null)
broken=${from_json%%$'\x1e'*} median_line=""
[[ $from_json == *$'\x1e'* ]] && median_line=${from_json#*$'\x1e'} && median_line=${median_line#$'\n'}
while [[ $broken == *$'\n' ]]; do broken=${broken%$'\n'}; done
if [ -n "$broken" ]; then
	echo "THIS RUN BROKE: what follows is not the experiment's result:"
	sed 's/^/  - /' <<<"$broken"
fi
[ -n "$switch_t" ] && echo "switched $start_mode -> $switch_to at t = $switch_t s"
# q (or --seconds) before the switch: a run of the clock alone, and said so
# before its numbers are taken for the experiment's
if [ -z "$switch_t" ] && [ "$switch_at" != never ]; then
	echo "THE ${switch_to^^} NEVER RAN: the run ended after $seconds s, before the switch due at $switch_at s: what follows is $start_mode (the clock) alone"
fi

# In words: the contact force and the collisions between robots in the last
# $window s before the switch and in the last $window s of the run, from the
# analysis (collision_rate.csv: 1 s bins; contact_force is SIM.TRUTH's total
# impulse rate, impacts and resting contact).
if [ -n "$switch_t" ]; then
	awk -F, -v sw="$switch_t" -v w="$window" -v from="$start_mode" -v to="$switch_to" '
		NR == 1 { next }
		{ t[NR] = $1; pc[NR] = $4; wc[NR] = $5; f[NR] = $6; last = $1 }
		END {
			b0 = sw - w; if (b0 < 0) b0 = 0; a0 = last + 1 - w; if (a0 < sw) a0 = sw
			for (k in t) {
				if (t[k] >= b0 && t[k] + 1 <= sw) { bp += pc[k]; bw += wc[k]; if (f[k] != "") { bf += f[k]; bn++ }; bs++ }
				if (t[k] >= a0) { ap += pc[k]; aw += wc[k]; if (f[k] != "") { af += f[k]; an++ }; as++ }
			}
			if (bn == 0 || an == 0 || bs == 0 || as == 0) { print "(no contact-force data around the switch: no words)"; exit }
			fb = bf / bn; fa = af / an
			printf "\nIn words:\n"
			if (fa <= 0 && fb <= 0)
				printf "  No contact force before the switch or after it (t = %.0f-%.0f s and %.0f-%.0f s): nothing to compare.\n", b0, sw, a0, last + 1
			else if (fa <= 0)
				printf "  The mean contact force fell to zero after the switch: %.3f N on the %s (t = %.0f-%.0f s) -> 0 N on the %s (t = %.0f-%.0f s).\n", fb, from, b0, sw, to, a0, last + 1
			else if (fb / fa >= 1.5)
				printf "  The mean contact force fell %.1fx after the switch: %.3f N on the %s (t = %.0f-%.0f s) -> %.3f N on the %s (t = %.0f-%.0f s).\n", fb / fa, fb, from, b0, sw, fa, to, a0, last + 1
			else
				printf "  The mean contact force did not fall: %.3f N on the %s (t = %.0f-%.0f s), %.3f N on the %s (t = %.0f-%.0f s).\n", fb, from, b0, sw, fa, to, a0, last + 1
			printf "  Collisions between robots per 10 s: %.0f -> %.0f; against the walls: %.0f -> %.0f.\n", bp * 10 / bs, ap * 10 / as, bw * 10 / bs, aw * 10 / as
		}' "$analysis/collision_rate.csv"
	# the median contact force of the 10 ms periods with contact (the analyser's)
	[ -z "$median_line" ] || echo "$median_line"
fi
awk '
	$1 == "pair" && !hdr {
		for (i = 1; i <= NF; i++) { if ($i == "end" && $(i + 1) == "state") { col["end"] = ++j; i++ } else col[$i] = ++j }
		hdr = 1; next }
	hdr && NF == 0 { hdr = 2 }
	hdr == 1 && NF > 5 && $col["end"] != "-" && $col["2asin(d~)"] ~ /^[0-9.]+$/ {
		n++; d = $col["meanD"]; if (d < 0) d = -d; b = $col["2asin(d~)"]
		if (d <= b + 0.1) within++
		if ($col["end"] == "grazing") grazing++
		if ($col["end"] == "still-colliding") colliding++
		rows = rows sprintf("    %-10s |D| %5.2f rad %s bound %4.2f: %s (%s N)\n", $col["pair"], d, d <= b + 0.1 ? "<=" : "> ", b, $col["end"], $col["F.win"]) }
	END { if (n) { printf "  Neighbours at the end (|D| against the compatibility bound 2 asin(d~)): %d of %d at or within it; %d grazing (touching with at most 0.1 N on average), %d touching harder (still-colliding).\n%s", within, n, grazing, colliding, rows } }
' "$analysis/summary.txt"

echo
echo "final window: the last $window s"
# summary.txt has one row per pair under a header line starting with "pair";
# columns are found by name so a new column does not break this.
awk -v OFS='' '
	$1 == "pair" && !hdr {
		# "end state" is one column of the rows but two words of the header
		for (i = 1; i <= NF; i++) { if ($i == "end" && $(i + 1) == "state") { col["end"] = ++j; i++ } else col[$i] = ++j }
		hdr = 1;
		printf "%-20s %-16s %10s %8s %10s %8s\n", "pair", "state", "final D", "d~", "2asin(d~)", "coll.";
		next }
	hdr && NF == 0 { hdr = 2 }
	hdr == 1 && NF > 5 && $col["end"] != "-" {
		printf "%-20s %-16s %10s %8s %10s %8s\n", $col["pair"], $col["end"], $col["meanD"], $col["d~"], $col["2asin(d~)"], $col["c.win"] }
' "$analysis/summary.txt"
echo "(final D: mean phase difference in the final window, rad; d~: normalized separation"
echo " from the measured amplitude; coll.: collisions in the final window)"
echo
echo "collisions per 10 s window:"
awk -F, 'NR > 1 { b = int($1 / 10); n[b] += $2; imp[b] += $3; if (b > last) last = b; end = $1 + 1 }
	END { for (b = 0; b <= last; b++) {
		e = b * 10 + 10 < end ? b * 10 + 10 : end
		printf "  %4d-%-4d s  %6d collisions  %9.4f N*s\n", b * 10, e, n[b], imp[b] } }' \
	"$analysis/collision_rate.csv"

# Contact force from the simulator's samples: "t,impacts,impulse,resting_impulse"
# (simulated seconds since its start, running totals).
{ echo "t,impacts,impulse,resting_impulse"
  sed -nE "s/^undulate-sim: (SIM.CMD seq [0-9]* 'stats *'|t=[0-9.]* event 'stats'): ok steps=[0-9]* time=([0-9.]*) collisions=([0-9]*) impulse=([0-9.]*) resting_impulse=([0-9.]*).*/\2,\3,\4,\5/p" \
	"$run/sim.log" | sort -t, -k1,1n; } >"$analysis/contact.csv"
mapfile -t contact_rows <"$analysis/contact.csv"
if [ "${#contact_rows[@]}" -gt 2 ]; then
	echo
	echo "mean contact force between samples (simulator ground truth: impacts + resting contact):"
	awk -F, 'NR > 2 && $1 >= t0 + 1 { printf "  %6.1f-%-6.1f s  %9.4f N  (%d impacts)\n", t0, $1, ($3 - i0) / ($1 - t0), $2 - n0 }
		NR > 1 { t0 = $1; n0 = $2; i0 = $3 }' "$analysis/contact.csv"
	[ -f "$run/switch.time" ] && echo "  (simulated time; one sample is taken just before the switch)"
fi

# One daemon publishes 100 STATE messages a second: many more means another
# program publishes on this LCM URL (e.g. the same test run twice at once),
# and the analysis mixes two runs.
crosstalk=$(awk -v ORS=' ' '/^span:/ { span = $2 } $2 == "joints" && $4 == "states" && span > 0 && $5 > 1.15 * 100 * span { print $1 }' \
	"$analysis/summary.txt")
if [ -n "$crosstalk" ]; then
	echo
	echo "WARNING: more STATE messages from ${crosstalk}than one daemon sends: another program uses $url; these results mix two runs"
	echo "$crosstalk" >"$analysis/crosstalk"
fi

# The simulator's own count over the whole run (ground truth, SIM.TRUTH).
truth=$(sed -n '/^undulate-sim: exit:/{s/^undulate-sim: exit: //;p;q}' "$run/sim.log")
[ -n "$truth" ] && echo "simulator: $truth"

}

summary | tee "$keep/demo-summary.txt"
mkdir "$keep/logs"
cp "$run"/*.log "$keep/logs/" 2>/dev/null
kept_log="$out/demo.lcmlog"
kept_what="demo.lcmlog (the LCM log), demo-summary.txt, the analysis (summary.txt, CSV files), logs/"
if [ "$compress" = 1 ]; then
	# xz -1: a third of the size in seconds (-6 saves 4 % more in three times as long)
	if xz -1 -T0 -c "$out/demo.lcmlog" >"$keep/demo.lcmlog.xz" &&
		xz -1 -T0 -f -- "$keep/states.csv" "$keep/phase_diff.csv" "$keep/collisions.csv" $( [ -f "$keep/plane.csv" ] && echo "$keep/plane.csv"); then
		rm -f -- "$out/demo.lcmlog"
		kept_log="$out/demo.lcmlog.xz"
		sed -i "s|^log: $out/demo.lcmlog\b|log: $kept_log|" "$keep/summary.txt"
		kept_what="demo.lcmlog.xz (the LCM log, xz), demo-summary.txt, the analysis (summary.txt, CSV files; the per-sample ones .csv.xz), logs/"
	else
		rm -f -- "$keep/demo.lcmlog.xz"
		echo "demo: xz failed: the run is kept uncompressed" >&2
	fi
fi
[ -n "$switch_t" ] && echo "$switch_t" >"$keep/switch_t"
echo "$seed" >"$keep/seed"
outdir_publish "$keep" "$out" || die "could not move everything into $out (above)"
echo
echo "The run is kept in $out: $kept_what."
# --plots-only: the plots without a second copy of the analysis's CSVs
echo "Next, the plots:  $B/undulate-analyze $kept_log --out $out/plots --plots-only"
: >"$run/done"   # kept and said: a signal now has nothing more to keep
exit 0
