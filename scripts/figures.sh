#!/usr/bin/env bash
# scripts/figures.sh — the paper's figures from the real daemons on the
# simulated bus, in lockstep (`make figures`, `make figures QUICK=1`).
#
#   scripts/figures.sh [--quick] [--only a,b] [--jobs N] [--out DIR] [--runs DIR] [--resume]
#       every module's runs through GNU parallel on this machine (progress:
#       runs done/total, time left), then each module merged into
#       DIR/figures/ (default docs/figures/) and DIR/FIGURES.md assembled
#   scripts/figures.sh --export-jobs FILE [--quick] [--only a,b] [--runs DIR]
#       the runs as independent command lines, one per line, for GNU
#       parallel across ssh hosts or a Slurm array (scripts/figures-slurm.sh);
#       run them from the top of this checkout (README.md, "A sweep on a cluster")
#   scripts/figures.sh --merge RUNS_DIR [--only a,b] [--out DIR]
#       merges runs done elsewhere (RUNS_DIR/<module>/<run>/result.csv)
#   scripts/figures.sh run MODULE OUTDIR ARG...
#       one run (what every exported line calls); its output in OUTDIR/run.log
#   scripts/figures.sh list
#       the modules and how many runs each has (full and quick)
#
# A module is figures/<name>/fig.sh (figures/lib.sh says what it must do).
# Raw runs go to RUNS (default $BUILD/figures/runs/<module>/<run>/); a local
# run starts each selected module afresh unless --resume (then runs with a
# result.csv are kept). --jobs: runs at once (default FIGURES_JOBS, else 3:
# the best throughput measured on this 2-core machine, README.md). FIG_TINY=1
# asks the modules for a tiny set (the driver's test). Exit 0 when every
# selected figure was drawn; 1 with a message otherwise (a module without any
# result, gnuplot or GNU parallel missing, a bad option, a folder of another
# user's or one others may write: figures/README.md, "Where the files go").
set -u
top=$(cd "$(dirname "$0")/.." && pwd)
source "$top/figures/lib.sh"
fig_init figures
self="$top/scripts/figures.sh"

# The page's order: the paper's. Modules not named here follow by name.
ORDER="heatmap steady pair returnmap rows lattice mobility channel swimmer channel-plane forces forces-plane"
# Progress: a new line this often when stdout is not a terminal (s).
PROGRESS_EVERY_S=30

# modules: every figures/<name>/ with an executable fig.sh, in page order.
modules() {
	local m all=()
	for m in "$top"/figures/*/fig.sh; do [ -x "$m" ] && all+=("$(basename "$(dirname "$m")")"); done
	for m in $ORDER; do printf '%s\n' "${all[@]}" | grep -qx "$m" && echo "$m"; done
	for m in "${all[@]}"; do [[ " $ORDER " == *" $m "* ]] || echo "$m"; done
	return 0
}
fig() { local m=$1; shift; "$top/figures/$m/fig.sh" "$@"; }

# ---- one run -----------------------------------------------------------------------
run_one() {
	[ $# -ge 2 ] || fig_die "run: want MODULE OUTDIR ARG..."
	local m=$1 out=$2; shift 2
	[ -x "$top/figures/$m/fig.sh" ] || fig_die "run: no module '$m' (figures/$m/fig.sh)"
	# another user's folder, or one others may write, is refused; run.log and
	# run.info replace whatever had their names (figures/lib.sh, scripts/outdir.sh)
	fig_run_dir "$out"
	rm -f "$out/result.csv"
	outdir_new "$out/run.log" || fig_die "run: cannot write $out/run.log"
	local t0 rc=0
	t0=$(date +%s%N)
	fig "$m" run "$out" "$@" >"$out/run.log" 2>&1 || rc=$?
	[ "$rc" -ne 0 ] || [ -s "$out/result.csv" ] || { echo "fig: $m run wrote no result.csv" >>"$out/run.log"; rc=1; }
	printf 'host=%s seconds=%s rc=%s date=%s\n' "$(hostname)" \
		"$(awk -v a="$t0" -v b="$(date +%s%N)" 'BEGIN { printf "%.2f", (b - a) / 1e9 }')" "$rc" \
		"$(date -u +%Y-%m-%dT%H:%M:%SZ)" | outdir_put "$out/run.info"
	if [ "$rc" -ne 0 ]; then
		echo "figures: $m $(basename "$out") failed: $(grep -v '^$' "$out/run.log" | tail -n 1)" >&2
		exit "$rc"
	fi
}

# ---- options -------------------------------------------------------------------------
quick=0 only="" jobs=${FIGURES_JOBS:-3} out="$top/docs" runs="" resume=0 export_file="" merge_dir=""
parse() {
	while [ $# -gt 0 ]; do
		case "$1" in
		--quick) quick=1; shift ;;
		--only) [ $# -ge 2 ] || fig_die "--only: want a,b"; only=$2; shift 2 ;;
		--jobs) [ $# -ge 2 ] || fig_die "--jobs: want a number"; jobs=$2; shift 2 ;;
		--out) [ $# -ge 2 ] || fig_die "--out: want a directory"; out=$2; shift 2 ;;
		--runs) [ $# -ge 2 ] || fig_die "--runs: want a directory"; runs=$2; shift 2 ;;
		--resume) resume=1; shift ;;
		--export-jobs) [ $# -ge 2 ] || fig_die "--export-jobs: want a file"; export_file=$2; shift 2 ;;
		--merge) [ $# -ge 2 ] || fig_die "--merge: want the runs' directory"; merge_dir=$2; shift 2 ;;
		-h|--help) sed -n '2,/^set -u/p' "$0" | sed -e '/^set -u/d' -e 's/^# \{0,1\}//'; exit 0 ;;
		*) fig_die "unknown argument '$1' (--help)" ;;
		esac
	done
	[[ "$jobs" =~ ^[1-9][0-9]{0,2}$ ]] || fig_die "--jobs: want a whole number 1..999, not '$jobs'"
	[ -z "$export_file" ] || [ -z "$merge_dir" ] || fig_die "--export-jobs and --merge: one at a time"
}

# selected: the modules to work on (--only, checked against what exists).
selected() {
	local all m
	all=$(modules)
	[ -n "$all" ] || fig_die "no figure module in $top/figures/"
	if [ -z "$only" ]; then echo "$all"; return; fi
	for m in ${only//,/ }; do
		grep -qx "$m" <<<"$all" || fig_die "--only: no module '$m' (there are: $(echo $all))"
	done
	for m in $all; do [[ ",$only," == *",$m,"* ]] && echo "$m"; done
	return 0
}

# ---- the jobs ------------------------------------------------------------------------
# A RUN_ID or an argument: what a command line can carry unquoted.
SAFE_WORD='^[A-Za-z0-9._:=+,-]+$'
# write_jobs RUNS_PREFIX MODULE...: one command line per run on stdout, each
# `scripts/figures.sh run MODULE RUNS_PREFIX/MODULE/RUN_ID ARG...`.
write_jobs() {
	local prefix=$1; shift
	local m lines id args a n
	for m in "$@"; do
		lines=$(fig "$m" jobs ${quick_flag[@]+"${quick_flag[@]}"}) || fig_die "$m: fig.sh jobs failed"
		n=0
		while read -r id args; do
			[ -n "$id" ] || continue
			[[ "$id" =~ ^[A-Za-z0-9_.-]+$ ]] || fig_die "$m jobs: bad RUN_ID '$id'"
			for a in $args; do [[ "$a" =~ $SAFE_WORD ]] || fig_die "$m jobs: $id: argument '$a' needs quoting"; done
			printf 'scripts/figures.sh run %s %q %s\n' "$m" "$prefix/$m/$id" "$args"
			n=$((n + 1))
		done <<<"$lines"
		[ "$n" -gt 0 ] || fig_die "$m jobs: no run"
		[ "$(cut -d' ' -f1 <<<"$lines" | sort | uniq -d)" = "" ] || fig_die "$m jobs: a RUN_ID twice"
	done
}

# longest_first JOBFILE MODULE...: the lines reordered, the modules with the
# longest runs (their `seconds`) first, each module's runs in its own order.
# GNU parallel starts them in file order: long runs left to the end would
# leave a core idle while the last of them finish (forces-plane's five-minute
# timelines after a thousand short pair runs); started first, the short runs
# fill in around them.
longest_first() {
	local f=$1 m s; shift
	local secs=()
	for m in "$@"; do
		s=$(fig "$m" seconds ${quick_flag[@]+"${quick_flag[@]}"} 2>/dev/null) || s=10
		secs+=("$m=$s")
	done
	outdir_new "$f.sorted" || return 1
	awk -v list="${secs[*]}" 'BEGIN { n = split(list, kv, " "); for (i = 1; i <= n; i++) { split(kv[i], a, "="); s[a[1]] = a[2] } }
		{ printf "%s\t%d\t%s\n", ($3 in s ? s[$3] : 10), NR, $0 }' "$f" |
		sort -t "$(printf '\t')" -k1,1gr -k2,2n | cut -f3- >"$f.sorted" && outdir_mv "$f.sorted" "$f"
}

# ---- progress ------------------------------------------------------------------------
human() { awk -v s="$1" 'BEGIN { s = int(s + 0.5); if (s >= 3600) printf "%d h %02d min", s / 3600, (s % 3600) / 60; else if (s >= 60) printf "%d min %02d s", s / 60, s % 60; else printf "%d s", s }'; }
# progress JOBLOG TOTAL T0 ESTIMATE_S: one line: runs done/total, failures,
# elapsed, and the time left (from the rate so far; the modules' estimate
# until the first run is done).
progress_line() {
	local log=$1 total=$2 t0=$3 est=$4 done fail el left
	read -r done fail < <(awk -F'\t' 'NR > 1 { n++; if ($7 != 0) f++ } END { print n + 0, f + 0 }' "$log" 2>/dev/null || echo 0 0)
	el=$(( $(date +%s) - t0 ))
	if [ "${done:-0}" -gt 0 ]; then left=$(awk -v e="$el" -v d="$done" -v t="$total" 'BEGIN { print e / d * (t - d) }')
	else left=$(awk -v e="$el" -v s="$est" 'BEGIN { l = s - e; print (l > 0 ? l : 0) }'); fi
	printf 'figures: %d/%d runs done%s, %s elapsed, about %s left' "${done:-0}" "$total" \
		"$([ "${fail:-0}" -gt 0 ] && echo ", ${fail} failed")" "$(human "$el")" "$(human "$left")"
}
watch_progress() {
	local log=$1 total=$2 t0=$3 est=$4 last=0 now
	while :; do
		now=$(date +%s)
		if [ -t 1 ]; then printf '\r%s   ' "$(progress_line "$log" "$total" "$t0" "$est")"
		elif [ $((now - last)) -ge "$PROGRESS_EVERY_S" ]; then progress_line "$log" "$total" "$t0" "$est"; echo; last=$now; fi
		sleep 2
	done
}

# estimate MODULE...: the runs' wall seconds added up (each module's
# `seconds`: one run's wall time with three at once, the default --jobs);
# the driver divides by --jobs.
estimate() {
	local m s n total=0
	for m in "$@"; do
		s=$(fig "$m" seconds ${quick_flag[@]+"${quick_flag[@]}"} 2>/dev/null) || s=10
		n=$(fig "$m" jobs ${quick_flag[@]+"${quick_flag[@]}"} | grep -c .)
		total=$(awk -v t="$total" -v s="$s" -v n="$n" 'BEGIN { print t + s * n }')
	done
	echo "$total"
}

# ---- merge and the page ---------------------------------------------------------------
# run_stats DIR: "runs ok failed seconds hosts" of a module's runs (run.info).
run_stats() {
	local d=$1
	cat "$d"/*/run.info 2>/dev/null | awk '
		{ for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
		  n++; if (v["rc"] == 0) ok++; s += v["seconds"]; h[v["host"]] = 1 }
		END { for (k in h) nh++; printf "%d %d %d %.0f %d\n", n, ok, n - ok, s, nh }'
}

# merge_module MODULE RUNS_DIR FIGDIR HOW WALL LOAD: the module's figure, and
# FIGDIR/MODULE.run, what the page's table says of it (WALL: seconds of the
# invocation's runs, "" when merged from elsewhere; LOAD: the machine's load
# average at their start and end).
merge_module() {
	local m=$1 rdir=$2 figdir=$3 how=$4 wall=$5 load=$6
	[ -d "$rdir/$m" ] || { echo "figures: $m: no runs in $rdir/$m" >&2; return 1; }
	local n ok failed secs hosts
	read -r n ok failed secs hosts < <(run_stats "$rdir/$m")
	# runs merged from elsewhere may lack run.info: count their results
	[ "${n:-0}" -gt 0 ] || { ok=$(ls "$rdir/$m"/*/result.csv 2>/dev/null | wc -l); n=$ok; failed=0; secs=0; hosts=0; }
	if ! fig "$m" merge "$rdir/$m" "$figdir"; then
		echo "figures: $m: the figure could not be made (above)" >&2
		return 1
	fi
	[ -s "$figdir/$m.md" ] || { echo "figures: $m: merge wrote no $figdir/$m.md" >&2; return 1; }
	{
		echo "module=$m"
		echo "date=$(date -u +%Y-%m-%d)"
		echo "set=$set_name"
		echo "runs=$n"
		echo "ok=$ok"
		echo "failed=$failed"
		echo "run_seconds=$secs"
		echo "wall_seconds=$wall"
		echo "load=$load"
		echo "hosts=$hosts"
		echo "how=$how"
	} | outdir_put "$figdir/$m.run"
	# its pictures: those its section shows (a glob on its name took
	# channel-plane's for channel's, forces-plane's for forces')
	local pngs
	pngs=$(grep -o '(figures/[^)/]*\.png)' "$figdir/$m.md" 2>/dev/null | sed 's|^(figures/||; s|)$||' | tr '\n' ' ')
	echo "figures: $m: $ok of $n runs merged into $figdir (${pngs% })"
}

# The machine, in one line, for the page's header.
machine() {
	local cpu
	cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -1)
	echo "${cpu:-unknown CPU}, $(nproc) cores, $(awk '/MemTotal/ { printf "%.0f GB", $2 / 1048576 }' /proc/meminfo), $(uname -s) $(uname -r | cut -d. -f1,2)"
}

# page DIR: DIR/FIGURES.md from the fragments in DIR/figures/, in page order.
page() {
	local dir=$1 m f
	local figdir="$dir/figures"
	{
		echo "# The paper's figures, from the real daemons and from the paper's own model"
		echo
		echo "Two sources. Most figures below come from runs of the unchanged programs — \`undulate-sim\`"
		echo "and one \`undulated\` per robot on the simulated Dynamixel bus — in lockstep (the simulator owns"
		echo "the clock: sim-bridge/README.md, \"Lockstep\"), each run analysed by \`undulate-analyze\`,"
		echo "the theory's curves from \`undulate-analyze --theory\` (theory.md's formulas, tools/analyze/theory.c)."
		echo "Those the paper draws from its own equations (heatmap, steady, lattice, mobility) come from"
		echo "\`undulate-model\` (model/README.md: the phase oscillators and the lattice, integrated with"
		echo "GSL, nothing of ours in between), with the daemons' runs laid over them where we have them."
		echo "The numbers of every figure are in the CSV beside its picture (\`figures/\`)."
		echo
		echo "Made by \`make figures\` (\`scripts/figures.sh\`) on $(machine). Per figure: its runs,"
		echo "the wall time of the invocation that ran them (the figures of one invocation share the"
		echo "machine, so it is theirs together), their run time added up, the set, the date, and the"
		echo "machine's load average at the start and the end of the runs (work beside them slows them)."
		echo
		echo "| figure | runs (failed) | wall time of the runs | run time, summed | set | made | load | how |"
		echo "|---|---|---|---|---|---|---|---|"
		for m in $(modules); do
			f="$figdir/$m.run"
			[ -f "$f" ] || continue
			awk -F= 'function t(s) { return s >= 3600 ? sprintf("%.1f h", s / 3600) : sprintf("%.1f min", s / 60) }
				{ v[$1] = $2 } END {
				printf "| [%s](#%s) | %d (%d) | %s | %s | %s | %s | %s | %s |\n", v["module"], v["module"], v["runs"], v["failed"],
					v["wall_seconds"] == "" ? "-" : t(v["wall_seconds"]), t(v["run_seconds"]), v["set"], v["date"], v["load"], v["how"] }' "$f"
		done
		echo
		echo "Regenerate: \`make figures\` (the whole set), \`make figures QUICK=1\` (fewer runs), one figure:"
		echo "\`scripts/figures.sh --only pair\` (the page keeps the other figures' sections). A sweep larger"
		echo "than one machine: README.md, \"A sweep on a cluster\" (\`--export-jobs\`, GNU parallel over ssh"
		echo "or a Slurm array, then \`--merge\`)."
		# the comparison, kept by hand beside the modules (its numbers from their CSVs)
		if [ -f "$fig_top/figures/model-vs-daemons.md" ]; then
			echo
			cat "$fig_top/figures/model-vs-daemons.md"
		fi
		for m in $(modules); do
			f="$figdir/$m.md"
			[ -f "$f" ] || continue
			echo
			echo "<a id=\"$m\"></a>"
			echo
			cat "$f"
		done
	} | outdir_put "$dir/FIGURES.md"
}

# ---- main -------------------------------------------------------------------------------
case "${1:-}" in
run) shift; run_one "$@"; exit 0 ;;
list)
	for m in $(modules); do
		printf '%-12s %5d runs, quick %4d\n' "$m" "$(fig "$m" jobs | grep -c .)" "$(fig "$m" jobs --quick | grep -c .)"
	done
	exit 0 ;;
esac
parse "$@"
quick_flag=()
[ "$quick" = 1 ] && quick_flag=(--quick)
# the set, as the page names it
set_name=$([ "$quick" = 1 ] && echo quick || echo full)$([ "${FIG_TINY:-0}" = 1 ] && echo ' (tiny)')
mods=$(selected) || exit 1
case "$out" in /*) ;; *) out="$PWD/$out" ;; esac

if [ -n "$merge_dir" ]; then
	[ -d "$merge_dir" ] || fig_die "--merge: no directory $merge_dir"
	fig_need_gnuplot
	fig_run_dir "$out"
	fig_run_dir "$out/figures"
	t0=$(date +%s) rc=0
	for m in $mods; do
		[ -d "$merge_dir/$m" ] || { [ -n "$only" ] && { echo "figures: $m: no runs in $merge_dir" >&2; rc=1; }; continue; }
		# runs made here keep what their invocation measured (invocation.txt)
		inv="$merge_dir/invocation.txt" how="merged from $(basename "$merge_dir")" wall="" load="-"
		if [ -f "$inv" ]; then
			how="$(sed -n 's/^how=//p' "$inv"), merged again"
			wall=$(sed -n 's/^wall_seconds=//p' "$inv") load=$(sed -n 's/^load=//p' "$inv")
			set_name=$(sed -n 's/^set=//p' "$inv")
		fi
		merge_module "$m" "$merge_dir" "$out/figures" "$how" "$wall" "$load" || rc=1
	done
	page "$out"
	echo "figures: $out/FIGURES.md"
	exit "$rc"
fi

[ -n "$runs" ] || runs="$BUILD/figures/runs"
if [ -n "$export_file" ]; then
	outdir_check "$(dirname "$export_file")" "figures: --export-jobs" && outdir_new "$export_file" || exit 1
	write_jobs "$runs" $mods >"$export_file" || exit 1
	longest_first "$export_file" $mods || exit 1
	echo "figures: $(wc -l <"$export_file") runs in $export_file; from the top of the checkout ($top):"
	echo "  parallel --joblog runs.joblog < $export_file                    (here, or --sshloginfile HOSTS)"
	echo "  sbatch --array=1-$(wc -l <"$export_file")%50 --output=$runs/slurm-%A_%a.out scripts/figures-slurm.sh $export_file   (Slurm)"
	echo "then: scripts/figures.sh --merge $runs"
	exit 0
fi

# ---- here, through GNU parallel ----------------------------------------------------------
command -v parallel >/dev/null 2>&1 || fig_die "GNU parallel is not installed (Debian: apt-get install parallel; or scripts/deps.sh parallel)"
fig_need_gnuplot
for p in undulate-sim undulated undulate-analyze; do
	[ -x "$FIG_BIN/$p" ] || fig_die "$FIG_BIN/$p is not built (run: make)"
done
case "$runs" in /*) ;; *) runs="$PWD/$runs" ;; esac
fig_run_dir "$runs"
fig_run_dir "$out"
fig_run_dir "$out/figures"
for m in $mods; do
	[ "$resume" = 1 ] || rm -rf "${runs:?}/$m"
	fig_run_dir "$runs/$m"
done
# every file written below replaces what had its name (scripts/outdir.sh)
jobfile="$runs/jobs.txt"
outdir_new "$jobfile.all" "$jobfile" "$runs/failures.txt" || fig_die "cannot write in $runs"
write_jobs "$runs" $mods >"$jobfile.all" || exit 1
longest_first "$jobfile.all" $mods || exit 1
if [ "$resume" = 1 ]; then
	# keep the runs that have their result
	while read -r _ _ _ dir _; do
		eval "d=$dir"
		[ -s "$d/result.csv" ] || grep -F " $dir " "$jobfile.all"
	done <"$jobfile.all" >"$jobfile"
else
	outdir_mv "$jobfile.all" "$jobfile"
fi
rm -f "$jobfile.all"
total=$(wc -l <"$jobfile")
est=$(awk -v s="$(estimate $mods)" -v j="$jobs" 'BEGIN { print s / j }')
echo "figures: $total runs of $(echo $mods) ($([ "$quick" = 1 ] && echo quick || echo full) set), $jobs at once, raw runs in $runs"
t0=$(date +%s)
load0=$(cut -d' ' -f1 /proc/loadavg)
joblog="$runs/joblog.txt"
outdir_new "$joblog" || fig_die "cannot write $joblog"
watch_progress "$joblog" "$total" "$t0" "$est" &
watcher=$!
trap 'kill "$watcher" 2>/dev/null' EXIT
# The jobs are lines of shell: run from the top of the checkout, as on a cluster.
( cd "$top" && parallel --jobs "$jobs" --joblog "$joblog" <"$jobfile" 2>"$runs/failures.txt" )
kill "$watcher" 2>/dev/null
wait "$watcher" 2>/dev/null
[ -t 1 ] && echo
run_wall=$(( $(date +%s) - t0 ))
load1=$(cut -d' ' -f1 /proc/loadavg)
echo "$(progress_line "$joblog" "$total" "$t0" 0 | sed 's/, about .* left//')."
if [ -s "$runs/failures.txt" ]; then
	echo "figures: failed runs (their run.log says more):"
	head -n 10 "$runs/failures.txt" | sed 's/^/  /'
fi
rc=0
how="here, --jobs $jobs"
printf 'how=%s\nwall_seconds=%s\nload=%s\nset=%s\n' "$how" "$run_wall" "$load0 → $load1" "$set_name" | outdir_put "$runs/invocation.txt"
for m in $mods; do merge_module "$m" "$runs" "$out/figures" "$how" "$run_wall" "$load0 → $load1" || rc=1; done
page "$out"
echo "figures: $out/FIGURES.md ($(human $(( $(date +%s) - t0 ))))"
exit "$rc"
