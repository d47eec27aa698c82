# tests/lib.sh — shared by the integration tests (source it).
#
#   tap_ok NAME / tap_fail NAME [WHY] / tap_check NAME CMD...   -> TAP lines
#   tap_skip NAME WHY      a check that cannot run here ("ok N - NAME # SKIP WHY")
#   tap_skip_all WHY       the whole script cannot run here: skip, plan, exit 0
#   tap_done               the plan (1..N); fails the script if a check failed
#   spawn NAME CMD...      start a background process; its PID is remembered
#                          and killed by the EXIT trap; stdout+stderr -> $T/NAME.log
#   wait_for TIMEOUT_S CMD...   poll (every 20 ms) until CMD succeeds
#   wait_log NAME REGEX [TIMEOUT_S]  poll a spawned process's log for a line
#   lcm_url PORT           udpm URL on multicast port PORT + $TEST_PORT_OFFSET, ttl=0
#   lcm_port PORT          that port number alone (for raw sockets, /proc/net/udp)
#
# Every test uses its own multicast port so tests never hear each other.
# Port ranges: protocol 7600-7649, sim 7650-7699, daemon 7700-7749,
# tools 7750-7799, systemd 7800-7849, end-to-end 7850-7899, bench 7900-7949,
# hostile-input QA 7950-7999. Tests name the port in these ranges and take it
# through lcm_url / lcm_port, never "udpm://..." by hand.
#
# TEST_PORT_OFFSET (default 0) is added to every port, so two copies of the
# suite can run on one machine without hearing each other: give each copy its
# own offset, 400 or more apart (the ranges above span 7600-7999), e.g.
# TEST_PORT_OFFSET=400 make test. The unit tests that use LCM read it too.
set -u
top=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${BUILD:-$top/build}
case "$BUILD" in /*) ;; *) BUILD="$top/$BUILD" ;; esac
B="$BUILD/bin"
TEST_PORT_OFFSET=${TEST_PORT_OFFSET:-0}
# Checked here, once: a bad offset inside $(lcm_url ...) could not stop the test.
if ! [[ "$TEST_PORT_OFFSET" =~ ^[0-9]{1,5}$ ]] || [ $((10#$TEST_PORT_OFFSET)) -gt 57000 ]; then
	echo "lib.sh: TEST_PORT_OFFSET must be a whole number from 0 to 57000 (ports reach 7999 + offset), not '$TEST_PORT_OFFSET'" >&2
	exit 2
fi
TEST_PORT_OFFSET=$((10#$TEST_PORT_OFFSET))
export TEST_PORT_OFFSET
T=$(mktemp -d "${TMPDIR:-/tmp}/undulate-test.XXXXXX")
# Each test's daemons put their local command sockets here, and
# `undulated --command` looks for them here: tests never command each other.
export UNDULATE_RUN_DIR="$T"
# ... and the UUCP lock files that name a bus's holder (protocol/io/port_lock.c)
# go here, not to the machine's /var/lock.
export UNDULATE_LOCK_DIR="$T"
_pids=()
_tap_n=0
_tap_failed=0

_cleanup() {
	local pid
	for pid in "${_pids[@]}"; do kill -TERM "$pid" 2>/dev/null; done
	for pid in "${_pids[@]}"; do
		for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; _nap 0.02; done
		kill -KILL "$pid" 2>/dev/null
		wait "$pid" 2>/dev/null
	done
	[ -n "${KEEP_TEST_DIR:-}" ] || rm -rf "$T"
}
trap _cleanup EXIT
trap 'exit 130' INT TERM

tap_ok()   { _tap_n=$((_tap_n + 1)); echo "ok $_tap_n - $1"; }
tap_fail() {
	_tap_n=$((_tap_n + 1)); _tap_failed=$((_tap_failed + 1))
	echo "not ok $_tap_n - $1"
	[ $# -gt 1 ] && echo "# ${2//$'\n'/$'\n'# }"
	return 0
}
# tap_todo NAME WHY: a claim of the paper that does not reproduce yet — a TAP
# "# TODO" line: reported in every run (with WHY and the numbers), counted
# apart by tests/run.sh, neither a pass nor a failure. Use it only for a
# claim documented as not reproduced in docs/EXPERIMENTS.md.
tap_todo() {
	_tap_n=$((_tap_n + 1))
	echo "not ok $_tap_n - $1 # TODO not reproduced yet"
	[ $# -gt 1 ] && echo "# ${2//$'\n'/$'\n'# }"
	return 0
}
# tap_skip NAME WHY: a check that cannot run on this machine (a program not
# built, a tool not installed): counted as a skip by tests/run.sh, never as a pass.
tap_skip() {
	_tap_n=$((_tap_n + 1))
	echo "ok $_tap_n - $1 # SKIP${2:+ $2}"
}
# tap_skip_all WHY: the whole script cannot run here: one skip named after
# the script, its plan, exit 0.
tap_skip_all() { tap_skip "$(basename "$0" .sh)" "$1"; tap_done; exit 0; }
tap_check() { local name=$1; shift; if "$@"; then tap_ok "$name"; else tap_fail "$name" "command failed: $*"; fi; }
tap_done() { echo "1..$_tap_n"; [ "$_tap_failed" -eq 0 ]; }
# needs_plotting: a test of pictures needs gnuplot to draw them and
# tests/tools/pngdata (PNG) to count their pixels; without either, the whole
# script is skipped.
needs_plotting() {
	PNG="$BUILD/tests/tools/pngdata"
	command -v gnuplot >/dev/null 2>&1 || tap_skip_all "gnuplot is not installed (Debian: gnuplot-nox)"
	[ -x "$PNG" ] || tap_skip_all "tests/tools/pngdata is not built"
}
# fig_module_runs FIG_SH SET JOBS: a figure module's runs, one per job line
# ("ID ARGS..."), into $T/runs, then its merge into $T/fig; a failed run is a
# failure, and "merge of the SET set exits 0" a result (its log: $T/merge.log).
fig_module_runs() {
	local f=$1 set=$2 jobs=$3 id args rc
	while read -r id args; do
		# shellcheck disable=SC2086 # a job line's arguments are words
		"$f" run "$T/runs/$id" $args >"$T/run-$id.log" 2>&1 || tap_fail "run $id" "$(tail -n 1 "$T/run-$id.log")"
	done <<<"$jobs"
	"$f" merge "$T/runs" "$T/fig" >"$T/merge.log" 2>&1
	rc=$?
	if [ "$rc" = 0 ]; then tap_ok "merge of the $set set exits 0"; else tap_fail "merge exits 0" "$(tail -n 3 "$T/merge.log")"; fi
}
# tap_refused PREFIX NAME CMD...: a usage refusal: CMD exits 2 and what it
# says (stdout and stderr) begins with PREFIX, e.g. a figure module's "name:".
tap_refused() {
	local prefix=$1 name=$2 out rc
	shift 2
	out=$("$@" 2>&1); rc=$?
	if [ "$rc" = 2 ] && [[ "$out" == "$prefix"* ]]; then tap_ok "refused: $name"; else tap_fail "refused: $name" "rc=$rc: $out"; fi
}

# Each spawned program runs in a session of its own (setsid), as a service runs
# in a cgroup of its own: with the kernel's autogroups, programs in the session
# of `make test` share one scheduling group with whatever CPU-bound work was
# started beside it, and then the kernel worker that carries a pseudo-terminal's
# bytes was traced runnable but waiting 577 ms (2 cores, one busy loop per core
# in that session; 2.4 ms with the programs in sessions of their own), so
# simulated servos answered half a second late. The PID stays the program's:
# a background job of a script is not a process group leader, so setsid execs.
# The kill-by-PID cleanup below does not depend on the session.
_own_session=()
command -v setsid >/dev/null 2>&1 && _own_session=(setsid)
spawn() {
	local name=$1; shift
	${_own_session[@]+"${_own_session[@]}"} "$@" >"$T/$name.log" 2>&1 &
	local pid=$!
	_pids+=("$pid")
	eval "pid_${name//[^A-Za-z0-9_]/_}=$pid"
}
# spawn_rt NAME CMD...: spawn, under SCHED_FIFO (chrt, priority
# TEST_RT_PRIORITY, default 40) where this user may (root, or an rtprio
# limit), as a robot's daemon runs (its `priority` key, the systemd unit) and
# as a servo answers (hardware: the CPU beside it never makes it late). For
# the simulators, plants and daemons of the tests that measure a gait in real
# time: with them on FIFO those tests pass beside a full machine (at load 20,
# daemon_limit_cycle; without, it failed at load 14), and the runner lets them
# run beside the others ("# run.sh: realtime"). Where FIFO is not allowed,
# a plain spawn, and the runner runs them alone.
_rt=
spawn_rt() {
	[ -n "$_rt" ] || { chrt -f 1 true 2>/dev/null && _rt=yes || _rt=no; }
	local name=$1; shift
	if [ "$_rt" = yes ]; then spawn "$name" chrt -f "${TEST_RT_PRIORITY:-40}" "$@"; else spawn "$name" "$@"; fi
}
# stop NAME [SIGNAL]: signal a spawned process and wait for it. Its exit status
# is left in $stop_rc and printed. Call it in this shell (`stop d >file` is fine):
# inside $(...) the process is not a child of the subshell and cannot be waited.
stop_rc=
stop() {
	local var="pid_${1//[^A-Za-z0-9_]/_}" sig=${2:-TERM}
	local pid=${!var}
	kill -"$sig" "$pid" 2>/dev/null
	stop_rc=0
	wait "$pid" 2>/dev/null || stop_rc=$?
	echo "$stop_rc"
}
alive() { local var="pid_${1//[^A-Za-z0-9_]/_}"; kill -0 "${!var}" 2>/dev/null; }

# Polling costs what its processes cost: a fork and exec is about 10 ms of
# CPU on a loaded machine, so a poll of `date`, `sleep` and the command every
# 20 ms kept a core busy while a test only waited. The clock ($EPOCHREALTIME)
# and the pause (`read -t` on a FIFO nobody writes) are the shell's own; only
# the command forks, every 20 ms for the first 0.4 s (most waits end there)
# and every 50 ms after.
mkfifo "$T/.nap" && exec {_nap_fd}<>"$T/.nap"
_nap() { read -r -t "$1" -u "$_nap_fd" _ || :; }
wait_for() {
	local timeout=$1 n=0; shift
	local now=${EPOCHREALTIME/[.,]/}
	local deadline=$(( now / 1000 + timeout * 1000 ))
	until "$@" >/dev/null 2>&1; do
		now=${EPOCHREALTIME/[.,]/}
		[ $(( now / 1000 )) -lt "$deadline" ] || return 1
		if [ $((n += 1)) -le 20 ]; then _nap 0.02; else _nap 0.05; fi
	done
}
wait_log() { wait_for "${3:-10}" grep -qE "$2" "$T/$1.log"; }

# py_start NAME SCRIPT [VAR...]: one Python interpreter that runs SCRIPT's
# main(argv) per call (tests/tools/pyserve.py): a Python start-up costs more
# than most exchanges a test makes with it, hundreds of times a test. The
# environment variables VAR... are passed on each call as they are then.
# py_call NAME ARG...: SCRIPT ARG... as if run on its own: its output, its
# stderr, its exit status. One caller at a time (not from two background
# jobs at once); a script that is a program of its own (spawn) runs as
# python3 SCRIPT.
py_start() {
	local name=$1 script=$2 fd_in fd_out; shift 2
	mkfifo "$T/py_$name.in" "$T/py_$name.out" || return 1
	python3 -S "$top/tests/tools/pyserve.py" "$script" <"$T/py_$name.in" >"$T/py_$name.out" 2>"$T/py_$name.err" &
	_pids+=("$!")
	# read-write: never blocks, and the server never sees its input end
	exec {fd_in}<>"$T/py_$name.in"
	# read-only: waits for the server's side, and ends (EOF) if it dies
	exec {fd_out}<"$T/py_$name.out"
	eval "_py_in_$name=$fd_in _py_out_$name=$fd_out"
	eval "_py_env_$name=\$*"
}
py_call() {
	local name=$1 in out envs e req="" line rc=""; shift
	in=_py_in_$name out=_py_out_$name envs=_py_env_$name
	for e in ${!envs}; do
		if [ -n "${!e+x}" ]; then req+="$e=${!e};"; else req+="$e;"; fi
	done
	local IFS=$'\x1f'   # "$*" joins the arguments with it
	printf '%s\x1f%s\n' "${req%;}" "$*" >&"${!in}"
	# The whole reply first, then print it: a reader that stops early (`| grep -q`)
	# must not leave the rest in the FIFO for the next call.
	local -a o=() e=()
	while IFS= read -r line <&"${!out}"; do
		case $line in
		"o "*) o+=("${line:2}") ;;
		"e "*) e+=("${line:2}") ;;
		"x "*) rc=${line:2}; break ;;
		esac
	done
	[ ${#e[@]} -eq 0 ] || printf '%s\n' "${e[@]}" >&2
	[ ${#o[@]} -eq 0 ] || printf '%s\n' "${o[@]}"
	[ -n "$rc" ] && return "$rc"
	echo "py_call: the $name interpreter is gone: $(tail -n 5 "$T/py_$name.err")" >&2
	return 1
}

lcm_port() { echo $(( $1 + TEST_PORT_OFFSET )); }
lcm_url() { echo "udpm://239.255.76.67:$(lcm_port "$1")?ttl=0"; }

# ---- a robot under test ---------------------------------------------------------------
# For scripts that run `undulated --watch $R` into $T/watch.log and a simulator
# with its control socket at $T/ctl (a script may define its own to replace one):
#   ctl CMD...            one command to the simulator; prints its answer line
#   cmd COMMAND [OPT...]  one command to the robot $R over $URL; prints the answers
#   field NAME            the value of NAME=... in the line on stdin
#   states / last_state   robot $R's STATE lines / the last one
#   sim_peek / swing / over  a simulated servo's register / a joint's peak-to-peak / A > B
#   cycle_at_least N      its last published cycle is >= N
#   wait_cycles N         wait (up to 10 s) until N more cycles were published
#   mark_states           after stopping $R's daemon: what it published is old
#   wait_restarted N      wait (up to 10 s) until the daemon started since has
#                         published N cycles (its counter starts at 0 again, and
#                         the watcher may still print the old one's last states)
#   events                robot $R's EVENT lines
#   event / state_is REGEX [TIMEOUT_S]  wait until an EVENT / the last STATE matches
ctl() { echo "$*" | socat -t 2 - UNIX-CONNECT:"$T/ctl"; }
# cmd COMMAND [OPTION...]: one command to robot $R over $URL (undulated --command)
cmd() { "$B/undulated" --command "$1" --robot "$R" --lcm-url "$URL" --timeout 2 "${@:2}"; }
field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }
states() { grep -a "^STATE $R " "$T/watch.log"; }
# sim_peek BUS ID REG: a register of a simulated servo (the simulator's socket $T/ctl)
sim_peek() { local v; v=$(ctl peek "$1" "$2" "$3"); echo "${v#ok }"; }
# swing J [N]: peak-to-peak (rad) of joint J's angle over robot $R's last N (150) states
swing() {
	states | tail -"${2:-150}" | awk -v k="a$1=" '{ for (i = 1; i <= NF; i++) if (index($i, k) == 1) { v = substr($i, 4) + 0
		if (!n++) { lo = v; hi = v } if (v < lo) lo = v; if (v > hi) hi = v } } END { printf "%.3f", hi - lo }'
}
# over A B: the number A is above B
over() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a > b) }'; }
# The watcher prints 100 lines a second, and these run in every poll: read
# the log from its end (tac), not all of it each time.
last_state() { tac "$T/watch.log" 2>/dev/null | grep -a -m1 "^STATE $R "; }
cycle_at_least() {
	local c
	c=$(tac "$T/watch.log" 2>/dev/null | awk -v r="$R" '$1 == "STATE" && $2 == r { sub("cycle=", "", $3); print $3 + 0; exit }')
	[ "${c:-0}" -ge "$1" ] 2>/dev/null
}
wait_cycles() { local c; c=$(last_state | field cycle); wait_for 10 cycle_at_least $((${c:-0} + $1)); }
events() { grep -a "^EVENT $R " "$T/watch.log"; }
# event REGEX [TIMEOUT_S]: wait (default 5 s) until one of $R's EVENT lines matches;
# state_is REGEX [TIMEOUT_S]: until its last STATE line matches
_event_has() { grep -qaE "^EVENT $R .*$1" "$T/watch.log"; }   # one process a poll
_state_has() { last_state | grep -qE "$1"; }
event() { wait_for "${2:-5}" _event_has "$1"; }
state_is() { wait_for "${2:-5}" _state_has "$1"; }
_mark=0
mark_states() { _mark=$(states | wc -l); }
restarted_at_least() {
	states | tail -n +$((_mark + 1)) | awk -v n="$1" '{ c = $3; sub("cycle=", "", c); c += 0; if (c < n) low = 1; last = c }
		END { exit !(low && last >= n) }'
}
wait_restarted() { wait_for 10 restarted_at_least "$1"; }

# rig_up LCM_PORT SEED: the daemon and simulator binaries ($D, $S; the test
# skipped when either is not built), a robot name of its own ($R: a
# concurrent run on the same multicast port from another build directory
# cannot answer for it), $URL, the simulator (servos 1 and 2 on $T/bus,
# robot r1, its control socket $T/ctl) ready, and a watcher of $R
# ($T/watch.log). Ends the test when the simulator does not start.
rig_up() {
	D="$B/undulated"; S="$B/undulate-sim"
	[ -x "$S" ] && [ -x "$D" ] || tap_skip_all "undulate-sim or undulated not built"
	R="u$$"
	URL=$(lcm_url "$1")
	spawn sim "$S" --link "$T/bus" --ids 1,2 --name r1 --lcm-url "$URL" --control "$T/ctl" --seed "$2"
	wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
	spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
}

# dxl_sim_built: $dxl and $sim, the dxl tests' two programs; a test without
# them fails at once (one result, the plan) rather than skipping unseen.
dxl_sim_built() {
	dxl="$B/dxl" sim="$B/undulate-sim"
	if [ ! -x "$dxl" ] || [ ! -x "$sim" ]; then
		tap_fail "dxl and undulate-sim are built" "missing $dxl or $sim"
		tap_done; exit
	fi
}

# demo_leftovers: what a demo run left behind under $T/tmp (its TMPDIR):
# processes whose command line names it, and files in it; nothing: status 0.
demo_leftovers() {
	local procs files
	procs=$(pgrep -af -- "$T/tmp" | grep -v pgrep)
	files=$(find "$T/tmp" -mindepth 1 2>/dev/null)
	[ -z "$procs$files" ] && return 0
	echo "processes: ${procs:-none}; files: ${files:-none}"
	return 1
}

# left_nothing WHEN: one TAP line, "nothing left behind after WHEN"
# (demo_leftovers, what it found if anything).
left_nothing() {
	local why
	if why=$(demo_leftovers); then tap_ok "nothing left behind after $1"; else tap_fail "nothing left behind after $1" "$why"; fi
}
# demo_up NAME CLAIM: the spawned scripts/demo.sh NAME printed its phases (its
# programs are up) within 40 s; if not, CLAIM fails with its log's tail.
demo_up() {
	wait_log "$1" '^demo: phases' 40 && return 0
	tap_fail "$2" "$(tail -n 20 "$T/$1.log")"
	return 1
}

# start_retried: the script's start_daemon, and once more as a unit's
# Restart=on-failure would when that start-up failed (exit 1, e.g. a servo
# read timing out on a loaded machine) before the script's `ready`; the
# failed run's errors are shown (daemon_errors: its log's error lines unless
# the script says otherwise). The daemon is spawned as "daemon".
daemon_errors() { grep -a error "$T/daemon.log"; }
_ready_or_exit() { ready || ! alive daemon; }
start_retried() {
	start_daemon
	wait_for 15 _ready_or_exit
	if ! ready && ! alive daemon; then
		stop daemon >"$T/daemon.rc"
		echo "# daemon start-up failed (exit $(cat "$T/daemon.rc")), restarted as Restart=on-failure would:"
		daemon_errors | sed 's/^/#   /'
		start_daemon
	fi
}

# torque_race N: HOLD then LIMP to robot $R, the second command leaving 0-4 ms
# after the first (process start-up jitter), N times; after each, whichever
# was applied last, the robot's mode and its servos' torque (the script's
# `torque`: "0 0" or "1 1") must agree once the writes are out. One TAP line.
# (A torque-off merged into a write already sent was once dropped.)
torque_race() {
	local n=$1 lost=0 wrong=0 i h s t
	for i in $(seq "$n"); do
		"$B/undulated" --command 'mode hold' --robot "$R" --lcm-url "$URL" --timeout 0.5 >/dev/null 2>&1 &
		h=$!
		sleep "0.00$((i % 5))"
		"$B/undulated" --command 'mode limp' --robot "$R" --lcm-url "$URL" --timeout 0.5 >/dev/null 2>&1
		wait "$h"
		wait_cycles 12
		s=$(last_state); t=$(torque)
		case "$(echo "$s" | field mode):$t" in
			0:"0 0") ;;
			1:"1 1") wrong=$((wrong + 1)) ;;   # HOLD applied after LIMP: consistent, but not the order sent
			*) lost=$((lost + 1)); echo "# trial $i: robot mode $(echo "$s" | field mode), servos torque '$t'" ;;
		esac
		cmd 'mode limp' >/dev/null; wait_cycles 5
	done
	if [ "$lost" = 0 ]; then
		tap_ok "HOLD then LIMP 0-4 ms apart, $n times: robot and servos agree every time ($wrong applied in the other order)"
	else tap_fail "torque-off race" "$lost of $n trials: the robot's mode and the servos' torque disagree"; fi
}

# start_pair: the simulated pair (sim-bridge/scenarios/pair.scenario, links
# $T/left and $T/right) on $URL with a daemon each on the oscillator and
# a watcher of left ($T/watch.log); ends the test when they do not start.
start_pair() {
	spawn sim "$B/undulate-sim" --scenario "$top/sim-bridge/scenarios/pair.scenario" --link-dir "$T" --lcm-url "$URL" --seed 5
	wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
	spawn watch "$B/undulated" --watch left --raw --lcm-url "$URL"
	local r
	for r in left right; do
		spawn "d_$r" "$B/undulated" --port "$T/$r" --ids 1 --robot "$r" --lcm-url "$URL" --mode oscillator
	done
	wait_log d_left 'ready:' 10 && wait_log d_right 'ready:' 10 ||
		{ tap_fail "daemons ready" "$(cat "$T/d_left.log" "$T/d_right.log")"; tap_done; exit 1; }
}

# ---- a raw client on a simulated bus (the sim_* tests) --------------------------------------
# pkt ID INSTR|ERR PARAM...: a Protocol 1.0 packet in hex with its checksum
# (instruction and status packets share the layout); written here, not by
# our encoder (a symmetric bug would pass), and in the shell without a
# subshell: a test builds hundreds.
pkt() {
	local id=$(($1)) code=$(($2)) p sum out
	shift 2
	sum=$(( id + $# + 2 + code ))
	printf -v out 'FFFF%02X%02X%02X' "$id" $(( $# + 2 )) "$code"
	for p; do p=$((p)); sum=$(( sum + p )); printf -v out '%s%02X' "$out" "$p"; done
	printf '%s%02X\n' "$out" $(( ~sum & 0xFF ))
}
status() { pkt "$@"; }
# expect_reply NAME REQUEST WANT / expect_silence NAME REQUEST: one exchange
# through the script's own `xfer HEX TIMEOUT_MS [EXPECT_BYTES]`, which sets
# $reply (the reply in hex, "-" for none).
expect_reply() {
	xfer "$2" 300 $(( ${#3} / 2 ))
	if [ "$reply" = "$3" ]; then tap_ok "$1"; else tap_fail "$1" "sent $2, want $3, got $reply"; fi
}
expect_silence() {
	xfer "$2" 30
	if [ "$reply" = "-" ]; then tap_ok "$1"; else tap_fail "$1" "sent $2, want no reply, got $reply"; fi
}

# ---- reading an experiment's analysis (scripts/demo.sh --out DIR) -------------------
# min_swing DIR: the smallest peak-to-peak angle (rad) of any robot's joint
# over the last 10 s of DIR/states.csv, and whose: "0.812 (\"r3\"/1)" (the
# number is ${x%% *}). Robots that stopped moving never collide either: no
# claim about phases or collisions means anything unless they all still swing.
min_swing() {
	awk -F, 'NR > 1 { t[NR] = $2; k[NR] = $3 "/" $4; a[NR] = $6; if ($2 > end) end = $2 }
		END { for (i in t) if (t[i] >= end - 10) { j = k[i]
			if (!(j in lo) || a[i] < lo[j]) lo[j] = a[i]; if (!(j in hi) || a[i] > hi[j]) hi[j] = a[i] }
		m = -1; for (j in lo) if (m < 0 || hi[j] - lo[j] < m) { m = hi[j] - lo[j]; w = j }
		printf "%.3f (%s)", m, w }' "$1/states.csv"
}
# summary_col DIR PAIR COLUMN: a column of PAIR's row in DIR/summary.txt, by
# its header name ("end state" is one column, named "state").
summary_col() {
	awk -v pair="$2" -v want="$3" '
		$1 == "pair" && !hdr { for (i = 1; i <= NF; i++) { if ($i == "end" && $(i + 1) == "state") { c["state"] = ++j; i++ } else c[$i] = ++j }; hdr = 1; next }
		hdr && $1 == pair { print $c[want]; exit }' "$1/summary.txt"
}
# last_collisions DIR: collisions (pairs and walls) in the last 10 s of DIR/collision_rate.csv.
last_collisions() {
	awk -F, 'NR > 1 { t[NR] = $1; n[NR] = $2; end = $1 + 1 } END { for (k in t) if (t[k] >= end - 10) s += n[k]; print s + 0 }' \
		"$1/collision_rate.csv"
}
# end_modes DIR: each robot's last published mode, "r1=OSCILLATOR r2=..." (states.csv).
end_modes() {
	awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
		{ r = $c["robot"]; gsub(/"/, "", r); m[r] = $c["mode"] }
		END { split("LIMP HOLD SINUSOID OSCILLATOR", n, " ")
			for (r in m) printf "%s=%s\n", r, ((m[r] + 1) in n) ? n[m[r] + 1] : m[r] }' \
		"$1/states.csv" | sort | tr '\n' ' ' | sed 's/ $//'
}
# run_diag DIR: what a failed experiment's check needs beside it, as TAP
# comments — each robot's gait and base at the end, the collisions per 10 s,
# and each daemon's loop (worst period p99, overruns, timeouts): a clean
# clone's logs are gone once it ends, so the reason must be in the output.
run_diag() {
	local d=$1
	[ -f "$d/summary.txt" ] && grep -E '^  [^ ]+ +joints ' "$d/summary.txt" |
		sed -E 's/ +/ /g; s/^ /# robot /'
	[ -f "$d/states.csv" ] && echo "# mode at the end: $(end_modes "$d")"
	[ -f "$d/demo-summary.txt" ] && sed -n '/^collisions per 10 s window:/,/^$/p' "$d/demo-summary.txt" |
		awk 'NR > 1 && NF { printf "%s%s", sep, $0; sep = ";" } END { if (sep) print "" }' |
		sed -E 's/ +/ /g; s/^/# collisions per 10 s:/'
	[ -f "$d/bus.csv" ] && awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
		{ r = $c["robot"]; gsub(/"/, "", r); if (!(r in p) || $c["period_p99_us"] > p[r]) p[r] = $c["period_p99_us"]
		  o[r] = $c["overruns"]; to[r] = $c["timeouts"] }
		END { for (r in p) printf "# loop %s: period p99 up to %d us, %d overruns, %d timeouts\n", r, p[r], o[r], to[r] }' \
		"$d/bus.csv" | sort
	return 0
}

# run_wait NAME TIMEOUT_S: wait for a spawned scripts/demo.sh run NAME (its
# --out in $T/NAME) to end, stopped if it overran; its exit status in $run_rc.
# Returns 0 when it ran and was analysed, 2 when another program published on
# its LCM URL (its results would mix two runs), 1 otherwise.
run_rc=
_gone() { ! kill -0 "$1" 2>/dev/null; }
run_wait() {
	local var="pid_${1//[^A-Za-z0-9_]/_}"
	wait_for "$2" _gone "${!var}"
	kill -TERM "${!var}" 2>/dev/null   # only if it overran
	run_rc=0
	wait "${!var}" || run_rc=$?
	[ -f "$T/$1/crosstalk" ] && return 2
	[ "$run_rc" = 0 ] && [ -f "$T/$1/summary.txt" ]
}
CROSSTALK="another program published on the run's LCM URL; its results mix two runs"
# run_ran NAME TIMEOUT_S LABEL CLAIM: run_wait, then one TAP line: CLAIM
# passed when it ran and was analysed; "LABEL: nobody else on its LCM port"
# failed on crosstalk. Returns 0 when it ran.
run_ran() {
	local ran
	run_wait "$1" "$2"; ran=$?
	if [ "$ran" = 2 ]; then
		tap_fail "$3: nobody else on its LCM port" "$CROSSTALK"
	elif [ "$ran" = 0 ]; then
		tap_ok "$4"
	else
		tap_fail "$4" "exit $run_rc: $(tail -n 20 "$T/$1.log")"
	fi
	[ "$ran" = 0 ]
}
# still_swings NAME CLAIM [WHY]: every robot of run NAME kept a peak-to-peak of
# at least MIN_SWING rad over the last 10 s (min_swing); marks the run
# $T/NAME/moving for judged. WHY follows the failure's numbers.
still_swings() {
	local sw
	sw=$(min_swing "$T/$1")
	if awk -v s="${sw%% *}" -v m="$MIN_SWING" 'BEGIN { exit !(s >= m) }'; then
		tap_ok "$2 (smallest peak-to-peak $sw rad)"
		: >"$T/$1/moving"
	else
		tap_fail "$2" "smallest peak-to-peak over the last 10 s: $sw rad (< $MIN_SWING)${3:+: $3}"
	fi
}
# judged NAME SKIP_NAME SKIP_WHY: run NAME's regime can be judged: it ran and
# its robots still swing (still_swings); a run that stopped gets one skip,
# the stop being a failure of its own.
judged() {
	[ -f "$T/$1/summary.txt" ] || return 1
	[ -f "$T/$1/moving" ] && return 0
	tap_skip "$2" "$3"
	return 1
}

# An end-to-end experiment (e2e_pair, e2e_row) asserts the paper's regimes
# twice: in lockstep, where the outcome is the same on any machine, and in
# real time, where a loaded machine changes the timing and so the
# trajectory. `make test` runs the lockstep half (it must pass on a busy
# machine); `make test-long` runs the real-time half alone
# (tests/long/e2e_*_realtime.sh). E2E_PART=lockstep|realtime|all.
e2e_part=${E2E_PART:-lockstep}
case $e2e_part in lockstep | realtime | all) ;; *) echo "lib.sh: E2E_PART must be lockstep, realtime or all, not '$e2e_part'" >&2; exit 2 ;; esac
realtime_part() { [ "$e2e_part" != lockstep ]; }
lockstep_part() { [ "$e2e_part" != realtime ]; }

# keep_runs DIR...: after a failure, keep the runs' logs and analysis (the
# test directory is removed on exit) in $BUILD/test-logs/<test>.d/.
keep_runs() {
	[ "$_tap_failed" -gt 0 ] || return 0
	local d="$BUILD/test-logs/$(basename "$0" .sh).d" x
	rm -rf "$d" && mkdir -p "$d"
	for x in "$@"; do [ -d "$T/$x" ] && cp -r "$T/$x" "$d/"; done
	echo "# runs kept in $d"
}

# ---- gait measurement from `undulated --watch` logs (daemon_limit_cycle, daemon_tune)
# samples ROBOT LOGNAME: "t a0 [a1]" per published state, t from the cycle counter (10 ms)
samples() { awk -v r="$1" '$1 == "STATE" && $2 == r && $4 == "mode=3" {
		c = $3; sub("cycle=", "", c); line = c * 0.01
		for (i = 5; i <= NF; i++) if ($i ~ /^a[0-9]=/) { v = $i; sub(/^a[0-9]=/, "", v); line = line " " v }
		print line }' "$T/$2.log"; }
# Per joint over [from, to): upward crossings of the window's centre with
# hysteresis (a tenth of the swing, well above the 5 mrad position step);
# frequency from the first to the last crossing; each whole cycle's half
# peak-to-peak (least, most, mean); joint 2's crossing after each of joint 1's,
# as a lag in degrees (least, most, mean and sd over the cycles).
measure() {
	awk -v from="$1" -v to="$2" '
	function cross(j, t, x) {
		if (x > c[j] + h[j]) hi[j] = 1
		if (hi[j] && x < c[j] - h[j]) armed[j] = 1
		if (armed[j] && px[j] < c[j] && x >= c[j]) {
			tc = pt + (t - pt) * (c[j] - px[j]) / (x - px[j])
			n[j]++; ct[j, n[j]] = tc
			if (n[j] > 1) { amp = (mx[j] - mn[j]) / 2; if (amp < amin[j]) amin[j] = amp; if (amp > amax[j]) amax[j] = amp; asum[j] += amp }
			mx[j] = x; mn[j] = x; hi[j] = 0; armed[j] = 0
		}
	}
	$1 >= from && $1 < to { ns++; for (j = 2; j <= NF; j++) { T[ns] = $1; X[ns, j - 1] = $j } nj = NF - 1 }
	END {
		for (j = 1; j <= nj; j++) {
			lo = 1e9; hiv = -1e9
			for (i = 1; i <= ns; i++) { if (X[i, j] < lo) lo = X[i, j]; if (X[i, j] > hiv) hiv = X[i, j] }
			c[j] = (lo + hiv) / 2; h[j] = (hiv - lo) / 20; amin[j] = 1e9; amax[j] = 0; n[j] = 0
			mx[j] = -1e9; mn[j] = 1e9
			for (i = 1; i <= ns; i++) {
				x = X[i, j]; if (i > 1) { pt = T[i - 1]; px[j] = X[i - 1, j]; cross(j, T[i], x) }
				if (x > mx[j]) mx[j] = x; if (x < mn[j]) mn[j] = x
			}
			f[j] = n[j] > 1 ? (n[j] - 1) / (ct[j, n[j]] - ct[j, 1]) : 0
			printf "j%d n=%d f=%.3f amin=%.3f amax=%.3f amean=%.3f\n", j, n[j], f[j], amin[j] == 1e9 ? 0 : amin[j], amax[j],
				(n[j] > 1 ? asum[j] / (n[j] - 1) : 0)
		}
		if (nj >= 2 && f[1] > 0) {
			k = 0; lmin = 1e9; lmax = -1e9
			for (a = 1; a < n[1]; a++) for (b = 1; b <= n[2]; b++)
				if (ct[2, b] >= ct[1, a] && ct[2, b] < ct[1, a + 1]) {
					l = 360 * (ct[2, b] - ct[1, a]) / (ct[1, a + 1] - ct[1, a]); if (l > 180) l -= 360
					k++; if (l < lmin) lmin = l; if (l > lmax) lmax = l; ls += l; lss += l * l; break
				}
			lm = k ? ls / k : 0; lsd = k > 1 ? sqrt((lss - k * lm * lm) / (k - 1) > 0 ? (lss - k * lm * lm) / (k - 1) : 0) : 0
			printf "lag n=%d min=%.1f max=%.1f mean=%.1f sd=%.1f\n", k, k ? lmin : 0, k ? lmax : 0, lm, lsd
		}
	}'
}
# csv_samples DIR ROBOT MODE: "t a0 [a1]" per state of ROBOT in MODE (0..3)
# from a demo run's DIR/states.csv (scripts/demo.sh --out DIR), for measure.
csv_samples() {
	awk -F, -v r="\"$2\"" -v m="$3" 'NR > 1 && $3 == r && $10 == m {
		if ($2 != t && line != "") print line
		if ($2 != t) { t = $2; line = t }
		line = line " " $6 }
		END { if (line != "") print line }' "$1/states.csv"
}
within() { awk -v v="$1" -v lo="$2" -v hi="$3" 'BEGIN { exit !(v >= lo && v <= hi) }'; }

# channels LOG: per LCM channel of a log, the count and a digest of its
# messages' bytes in order (the lockstep tests compare two runs with it).
channels() {
	python3 - "$1" <<'PY'
import collections, hashlib, struct, sys
buf = open(sys.argv[1], 'rb').read()
off, dig, n = 0, {}, collections.Counter()
while off + 28 <= len(buf):
    sync, _, _, cl, dl = struct.unpack_from('>IqqII', buf, off)
    if sync != 0xEDA1DA01:
        sys.exit('not an LCM log at byte %d' % off)
    off += 28
    ch = buf[off:off + cl].decode(); off += cl
    dig.setdefault(ch, hashlib.sha256()).update(buf[off:off + dl]); off += dl
    n[ch] += 1
for ch in sorted(dig):
    print(ch, n[ch], dig[ch].hexdigest())
PY
}
