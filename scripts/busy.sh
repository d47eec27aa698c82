#!/usr/bin/env bash
# scripts/busy.sh COMMAND [ARGS...] — run COMMAND with one CPU-bound process
# per core beside it, started from this same session (as `yes >/dev/null &`
# typed in the shell before `make test` would be), and stop them afterwards.
#
#   make test-busy      is   scripts/busy.sh make test
#
# What it checks: that the daemons and the simulator keep their timing when
# the machine has no idle core (docs/LIMITS.md, "Under load"). The busy loops run at
# the caller's priority; the exit status is COMMAND's.
set -u
[ $# -gt 0 ] || { echo "usage: scripts/busy.sh COMMAND [ARGS...]" >&2; exit 2; }
n=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)
pids=()
stop_busy() {
	[ ${#pids[@]} -gt 0 ] && kill "${pids[@]}" 2>/dev/null
	[ ${#pids[@]} -gt 0 ] && wait "${pids[@]}" 2>/dev/null
	pids=()
}
trap stop_busy EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
for _ in $(seq "$n"); do
	# a shell loop: no fork, no I/O, all CPU
	sh -c 'while :; do :; done' &
	pids+=("$!")
done
echo "busy: $n CPU-bound process(es) beside: $*" >&2
"$@"
rc=$?
stop_busy
echo "busy: stopped the $n CPU-bound process(es); '$*' exited with $rc" >&2
exit "$rc"
