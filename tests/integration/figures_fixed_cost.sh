#!/usr/bin/env bash
# run.sh: heavy — its lockstep run keeps a core busy (tests/run.sh)
# figures_fixed_cost.sh — what one figure run costs besides its simulation.
# `make figures` makes about 1,600 short lockstep runs (1,124 of them the
# pair module's), each through figures/lib.sh's fig_demo and scripts/demo.sh;
# every program they start for a small job (awk for arithmetic, date, seq,
# grep, dirname, a sleep per poll, one mv per file) costs 5-20 ms of CPU on a
# busy two-core machine. A 4 s pair run started 119 such programs,
# about half its CPU time; the scripts now do that work in the shell. Here
# one pair run, traced (strace -f, execve), starts at most HELPERS_MAX
# programs besides the project's own (undulate-sim, undulated,
# undulate-analyze, and bash and setsid running them), and its results are
# what they were: the result row with its columns, the phase given as
# -DELTA0, the switch found in the run, a wall time with two decimals. The
# shell helpers that replaced programs give the programs' answers (fig_num's
# range checks, fig_basename, fig_wall).
. "$(dirname "$0")/../lib.sh"
command -v strace >/dev/null 2>&1 || tap_skip_all "strace is not installed (Debian: strace)"
strace -f -qq -e trace=execve -o /dev/null true 2>/dev/null || tap_skip_all "strace cannot trace here (ptrace not allowed)"
command -v jq >/dev/null 2>&1 || tap_skip_all "jq is not installed"
for p in undulate-sim undulated undulate-analyze; do [ -x "$B/$p" ] || tap_skip_all "$B/$p is not built (make)"; done
# measured: 45 after the change, 119 before it
HELPERS_MAX=70

# The run's ports (end-to-end range), moved by TEST_PORT_OFFSET like every test's.
export FIG_PORT_LO FIG_PORT_SPAN=4
FIG_PORT_LO=$(lcm_port 7890)
unset PARALLEL_JOBSLOT

# ---- the shell's answers are the programs' ----------------------------------
# (in a subshell: lib.sh sets -u and defines the fig_ functions)
bad=$(
	source "$top/figures/lib.sh"
	fig_usage() { echo "refused"; }
	for c in "0.5 0 1 ok" "0 0 1 ok" "1 0 1 ok" "1.0000001 0 1 refused" "-3.1416 -3.1416 3.1416 ok" \
		"-3.14161 -3.1416 3.1416 refused" "3.1416 -3.1416 3.1416 ok" "2.99999999999 0 3 ok" \
		"3.0000000001 0 3 refused" "007 0 10 ok" "1e3 0 10000 refused" "x 0 1 refused"; do
		set -- $c
		got=$(fig_num X "$1" "$2" "$3"); got=${got:-ok}
		[ "$got" = "$4" ] || echo "fig_num $1 in [$2, $3]: $got, not $4"
	done
	for p in /a/b /a/b/ / a //x/y/ x/; do
		fig_basename got "$p"
		[ "$got" = "$(basename "$p")" ] || echo "fig_basename $p: '$got', basename says '$(basename "$p")'"
	done
	FIG_T0=$EPOCHREALTIME
	[[ $(fig_wall) =~ ^[0-9]+\.[0-9]$ ]] || echo "fig_wall: '$(fig_wall)'"
)
if [ -z "$bad" ]; then tap_ok "fig_num, fig_basename and fig_wall give what awk, basename and date gave"
else tap_fail "fig_num, fig_basename and fig_wall give what awk, basename and date gave" "$bad"; fi

# ---- one pair run, traced ---------------------------------------------------
out="$T/run-a"
rc=0
strace -f -qq -e trace=execve -o "$T/exec.txt" \
	"$top/figures/pair/fig.sh" run "$out" 0.67 0.5615 -1.7777 1561 4 >"$T/run.log" 2>&1 || rc=$?
if [ "$rc" = 0 ]; then tap_ok "the pair run exits 0"
else tap_fail "the pair run exits 0" "exit $rc: $(tail -n 5 "$T/run.log"; tail -n 5 "$out/demo.out" 2>/dev/null)"; fi

# every program started (a failed PATH lookup is not one), by name
awk '/execve\(/ && !/= -1 / { p = $0; sub(/^[^"]*"/, "", p); sub(/".*/, "", p); sub(/.*\//, "", p); n[p]++ }
	END { for (p in n) print n[p], p }' "$T/exec.txt" | sort -rn >"$T/programs.txt"
helpers=$(awk '$2 !~ /^(undulate-sim|undulated|undulate-analyze|bash|setsid|demo\.sh|fig\.sh|env|strace)$/ { s += $1 } END { print s + 0 }' "$T/programs.txt")
if [ "$helpers" -le "$HELPERS_MAX" ]; then
	tap_ok "one 4 s pair run starts $helpers helper programs (at most $HELPERS_MAX)"
else
	tap_fail "one 4 s pair run starts at most $HELPERS_MAX helper programs" "$helpers: $(tr '\n' ' ' <"$T/programs.txt")"
fi

# its results, as the old scripts wrote them
row=$(sed -n 2p "$out/result.csv" 2>/dev/null)
IFS=, read -r -a f <<<"$row"
if [ "$(head -n 1 "$out/result.csv" 2>/dev/null | tr ',' '\n' | wc -l)" = 21 ] && [ "${#f[@]}" = 21 ] &&
	[ "${f[0]}" = run-a ] && [ "${f[3]}" = -1.7777 ] && [ -n "${f[6]}" ] && [[ ${f[19]} =~ ^[0-9]+\.[0-9]{2}$ ]] &&
	[ "${f[20]}" = 3 ]; then
	tap_ok "result.csv: its 21 columns, the run's name, its class, a wall time of two decimals"
else
	tap_fail "result.csv: its 21 columns, the run's name, its class, a wall time of two decimals" "$(cat "$out/result.csv" 2>/dev/null)"
fi
if grep -q '^demo: phases at start (rad): 0 1.7777; sinusoid until +3 s, then oscillator$' "$out/demo.out" &&
	grep -q '^switched sinusoid -> oscillator at t = 3.0 s$' "$out/demo/demo-summary.txt" &&
	grep -q '^demo: lockstep: 4.0[0-9]* s of simulated time in [0-9.]* s ([0-9.]*x real time)$' "$out/demo.out"; then
	tap_ok "the right robot starts at -DELTA0, the switch is found in the run, the lockstep line is said"
else
	tap_fail "the right robot starts at -DELTA0, the switch is found in the run, the lockstep line is said" "$(head -n 8 "$out/demo.out")"
fi
# the run's files published into it (one mv for a folder's files)
missing=""
for f in summary.json summary.txt collision_rate.csv contact.csv events.csv demo-summary.txt seed switch_t \
	logs/sim.log logs/undulated-left.log logs/undulated-right.log logs/logger.log; do
	[ -s "$out/demo/$f" ] || missing+=" $f"
done
if [ -z "$missing" ] && [ -s "$out/delta_t.csv" ]; then
	tap_ok "the run's files are in its folder, its logs in logs/"
else
	tap_fail "the run's files are in its folder, its logs in logs/" "missing:$missing; $(ls -R "$out" 2>&1 | head -n 30)"
fi
tap_done
