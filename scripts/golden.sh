#!/usr/bin/env bash
# scripts/golden.sh — golden runs: lockstep runs whose outcome is committed and
# compared, as gpsd's regression logs are (tests/golden/README.md).
#
#   scripts/golden.sh [NAME...]            every tests/golden/NAME.run (default:
#                                          all) in lockstep, each compared with
#                                          its NAME.chk: what changed, key by
#                                          key, old -> new; exit 0 when none did
#   scripts/golden.sh --update [NAME...]   the same, then NAME.chk rewritten from
#                                          this run (`make golden`: after a change
#                                          of behaviour that was meant)
#   options: --jobs N    runs side by side (default 2)
#            --keep DIR  keep the runs (LCM log, analysis, logs) in DIR/NAME
#            --lcm-port P  the runs on LCM ports P, P+1, ... (default: each
#                        demo.sh picks its own from its PID)
#
# tests/integration/golden_runs.sh takes it one step at a time:
#   scripts/golden.sh --run NAME DIR [LCM_URL]   one run into DIR/NAME/ and its
#                                                record into DIR/NAME.rec
#   scripts/golden.sh --compare NAME REC         REC against tests/golden/NAME.chk
#                                                (or against the file NAME, a path)
#   scripts/golden.sh --record DIR               the record of a run kept in DIR
#                                                (demo.sh --out DIR, or --keep's)
# --compare prints one line per difference and a last line starting "= ";
# exit 0: as recorded; 1: something differs; 3: every value as recorded, the
# digests not, and the expectation was recorded on another platform (where
# floating point may round otherwise: the digests are then informational).
#
# A record is one "KEY VALUE" line per thing worth reading in a diff: the
# analyser's summary (per robot, per pair and column), the demo summary's
# contact force and collisions per window, the simulator's totals, the
# daemons' events, and a SHA-256 of each deterministic output (the states log
# every daemon published, its events, the simulator's collisions, the
# analysis). A number matches within one unit of its last printed digit (a
# rounding that flips); an integer and a word match exactly; a digest matches
# exactly when the expectation was recorded on this platform.
set -u

top=$(cd "$(dirname "$0")/.." && pwd)
source "$top/scripts/outdir.sh"
BUILD=${BUILD:-build}
case "$BUILD" in /*) ;; *) BUILD="$top/$BUILD" ;; esac
export BUILD
B="$BUILD/bin"
golden="$top/tests/golden"
# Events kept as lines of a record; a run with more says how many more (a
# daemon that restarts its oscillator every period should not make a 100 kB file).
MAX_EVENTS=60
# The outputs whose bytes a lockstep run fixes (bus.csv is not one: it holds
# the pty's path and the CPU the loop took; the LCM log holds the wall-clock
# times it was recorded at).
DIGESTED="states.csv events.csv params.csv collisions.csv phase_diff.csv return_map.csv"

die() { echo "golden: $*" >&2; exit 2; }

usage() {
	sed -n '2,/^set -u/p' "$0" | sed -e '/^set -u/d' -e 's/^# \{0,1\}//' >&2
	exit 2
}

# ---- one run ----------------------------------------------------------------------
# run_args NAME: the demo.sh arguments of tests/golden/NAME.run, one a line
# (NUL-terminated): each line of the file is an option and its value (the rest
# of the line, spaces and all); '#' lines and blank lines are comments.
run_args() {
	local opt val
	while read -r opt val; do
		case "$opt" in ''|'#'*) continue ;; esac
		printf '%s\0' "$opt"
		[ -n "$val" ] && printf '%s\0' "$val"
	done <"$golden/$1.run"
}

# platform: where the binaries were built and what does their floating point:
# the CPU architecture, the compiler that built undulated (its .comment) and
# the C library (libm). Lockstep runs are byte for byte the same where these are.
platform() {
	local cc libc
	cc=$(readelf -p .comment "$B/undulated" 2>/dev/null | sed -n 's/^ *\[ *[0-9a-f]*\] *//p' | head -n 1)
	libc=$(getconf GNU_LIBC_VERSION 2>/dev/null)
	echo "$(uname -m); ${cc:-compiler unknown}; ${libc:-C library unknown}"
}

demo_pids=()
# start_run NAME DIR [URL]: NAME's lockstep run into DIR/NAME in the background
# (its output in DIR/NAME.out); its PID is appended to demo_pids.
start_run() {
	local name=$1 dir=$2 url=${3:-} args=()
	[ -f "$golden/$name.run" ] || die "no run '$name' (tests/golden/$name.run)"
	mapfile -d '' args < <(run_args "$name")
	( cd "$top" && exec env BUILD="$BUILD" TMPDIR="$dir" scripts/demo.sh --lockstep --out "$dir/$name" \
		${url:+--lcm-url "$url"} "${args[@]}" ) >"$dir/$name.out" 2>&1 &
	demo_pids+=("$!")
}
# stop_runs: SIGTERM to every run still going (demo.sh stops what it started), reaped.
stop_runs() {
	local pid
	for pid in ${demo_pids[@]+"${demo_pids[@]}"}; do kill -TERM "$pid" 2>/dev/null; done
	for pid in ${demo_pids[@]+"${demo_pids[@]}"}; do wait "$pid" 2>/dev/null; done
	demo_pids=()
}

# record DIR: the record of the run kept in DIR (demo.sh --out DIR), on stdout.
record() {
	local d=$1 f
	printf '%-22s %s\n' platform "$(platform)"
	awk '
		function put(k, v) { gsub(/[ \t]+/, " ", v); sub(/^ /, "", v); sub(/ $/, "", v); printf "%-22s %s\n", k, v }
		/^span: / { put("span", substr($0, 7)); next }
		/^world: / { put("world", substr($0, 8)); next }
		/^collisions: / { put("collisions", substr($0, 13)); next }
		/^contact force, median of every contact/ { v = $0; sub(/^[^:]*: /, "", v); put("contact_median", v); next }
		# "left joints 1 states 2999 j0 1.033 Hz 0.645 rad neutral -0.1044 m lever
		# 0.1865 m/rad swing j0 1.310 rad p-p": each number after its name
		/^  [^ ]+ +joints / {
			v = ""
			for (i = 2; i <= NF; i++) {
				if ($i == "joints" || $i == "states") { v = v " " $i "=" $(i + 1); i++ }
				else if ($i ~ /^j[0-9]+$/ && $(i + 2) == "Hz") { v = v " " $i ".hz=" $(i + 1) " " $i ".amp=" $(i + 3); i += 4 }
				else if ($i == "neutral" || $i == "lever") { v = v " " $i "=" $(i + 1); i += 2 }
				else if ($i == "swing") { for (i++; $i ~ /^j[0-9]+$/; i += 2) v = v " " $i ".swing=" $(i + 1); i++ }
				else v = v " " $i
			}
			put("robot." $1, v); next
		}
		# the pair table: a line per pair, each value after its column'"'"'s name
		# ("end state" is one column)
		$1 == "pair" && !hdr {
			for (i = 1; i <= NF; i++) if ($i == "end" && $(i + 1) == "state") { col[++n] = "state"; i++ } else col[++n] = $i
			hdr = 1; next
		}
		hdr && NF == n { v = ""; for (i = 2; i <= n; i++) v = v " " col[i] "=" $i; put("pair." $1, v) }
	' "$d/summary.txt"
	awk '
		function put(k, v) { gsub(/[ \t]+/, " ", v); sub(/^ /, "", v); sub(/ $/, "", v); printf "%-22s %s\n", k, v }
		/^switched / { put("switch", $0); next }
		/^  The mean contact force / { put("words.force", $0); next }
		/^  Collisions between robots per 10 s/ { v = $0; sub(/^[^:]*: /, "", v); put("words.collisions", v); next }
		/^  Neighbours at the end/ { v = $0; sub(/^[^:]*: /, "", v); put("words.neighbours", v); next }
		/^collisions per 10 s window:/ { sec = "collisions"; next }
		/^mean contact force between samples/ { sec = "force"; next }
		/^$/ { sec = ""; next }
		sec != "" && $2 == "s" { k = $1; $1 = ""; $2 = ""; put(sec "." k "s", $0); next }
		/^simulator: / { put("simulator", substr($0, 12)); next }
	' "$d/demo-summary.txt"
	# events.csv: utime,t,robot,seq,level,kind,text (the text may hold commas)
	awk -v max="$MAX_EVENTS" '
		NR == 1 { next }
		{
			line = $0
			for (i = 1; i <= 6; i++) { p = index(line, ","); f[i] = substr(line, 1, p - 1); line = substr(line, p + 1) }
			n++
			if (n > max) next
			gsub(/"/, "", f[3]); gsub(/"/, "", f[6]); gsub(/^"|"$/, "", line)
			printf "%-22s %s %s %s: %s\n", sprintf("event.%02d", n), f[2], f[3], f[6], line
		}
		END { if (n > max) printf "%-22s %d more events (%d in all)\n", "event.more", n - max, n }
	' "$d/events.csv"
	for f in $DIGESTED; do
		[ -f "$d/$f" ] && printf '%-22s %s\n' "sha256.$f" "$(sha256sum <"$d/$f" | cut -d' ' -f1)"
	done
	return 0
}

# run_one NAME DIR [URL]: start_run, wait, and write DIR/NAME.rec; demo.sh's status.
run_one() {
	local rc=0
	start_run "$@"
	wait "${demo_pids[0]}" || rc=$?
	demo_pids=()
	[ "$rc" = 0 ] || return "$rc"
	if [ -f "$2/$1/crosstalk" ]; then
		echo "golden: $1: another program published on the run's LCM URL; the run mixes two" >>"$2/$1.out"
		return 1
	fi
	record "$2/$1" >"$2/$1.rec"
}

# ---- comparing --------------------------------------------------------------------
# compare CHK REC: see the header. Differences are printed as
#   KEY: OLD -> NEW                          (a value of one word)
#   KEY: NAME OLD -> NEW; ...                (the NAME=VALUE words that changed)
#   KEY: prose {OLD => NEW} prose ...        (a sentence, its changed words marked)
#   KEY: gone (was: ...) / KEY: new: ...
compare() {
	awk -v chk="${1#"$top/"}" '
		function trim(s) { sub(/^[ \t]+/, "", s); sub(/[ \t]+$/, "", s); gsub(/[ \t]+/, " ", s); return s }
		# a number, maybe in brackets or before a comma, unit or colon: "(5", "15,", "18.7x"
		function split_num(t, part) {
			if (!match(t, /-?[0-9]+(\.[0-9]+)?/)) return 0
			part[1] = substr(t, 1, RSTART - 1); part[2] = substr(t, RSTART, RLENGTH); part[3] = substr(t, RSTART + RLENGTH)
			return part[1] ~ /^[(]?$/ && part[3] ~ /^[x%]?[),;:]*$/
		}
		# one unit of the last printed digit (0 for an integer: exact)
		function unit(s,   p) { p = index(s, "."); return p ? 10 ^ (p - length(s)) : 0 }
		function same_word(a, b,   pa, pb, u, d) {
			if (a == b) return 1
			# NAME=VALUE: the same name and the same value
			if (a ~ /=/ || b ~ /=/) {
				if (index(a, "=") == 0 || substr(a, 1, index(a, "=")) != substr(b, 1, index(b, "="))) return 0
				return same_word(substr(a, index(a, "=") + 1), substr(b, index(b, "=") + 1))
			}
			if (!split_num(a, pa) || !split_num(b, pb) || pa[1] != pb[1] || pa[3] != pb[3]) return 0
			u = unit(pa[2]); if (unit(pb[2]) > u) u = unit(pb[2])
			d = pa[2] - pb[2]; if (d < 0) d = -d
			return d <= u * (1 + 1e-9)
		}
		# what: "" when OLD and NEW match, else how they differ
		# (NAME=VALUE words that changed by their names: "meanD -3.1384 -> -3.1396";
		# prose whole, each changed word in it as "{OLD => NEW}")
		function differ(old, new,   na, nb, a, b, i, out, e, changed) {
			na = split(old, a, " "); nb = split(new, b, " ")
			if (na != nb) return "\"" old "\" -> \"" new "\""
			if (na == 1 && a[1] !~ /=/) return same_word(a[1], b[1]) ? "" : a[1] " -> " b[1]
			if (old ~ /[^ =]=[^ =]/) {
				for (i = 1; i <= na; i++) {
					if (same_word(a[i], b[i])) continue
					e = index(a[i], "=")
					out = out (out != "" ? "; " : "") (e ? substr(a[i], 1, e - 1) " " substr(a[i], e + 1) " -> " substr(b[i], e + 1) : a[i] " -> " b[i])
				}
				return out
			}
			for (i = 1; i <= na; i++) {
				if (same_word(a[i], b[i])) { out = out (i > 1 ? " " : "") a[i]; continue }
				out = out (i > 1 ? " " : "") "{" a[i] " => " b[i] "}"; changed = 1
			}
			return changed ? out : ""
		}
		function short(h) { return substr(h, 1, 12) "..." }
		FNR == 1 { file++ }
		/^#/ || !NF { next }
		{ key = $1; val = $0; sub(/^[^ \t]+[ \t]*/, "", val); val = trim(val) }
		file == 1 { if (!(key in old)) order[++n_old] = key; old[key] = val; next }
		{ if (!(key in new)) norder[++n_new] = key; new[key] = val }
		END {
			here = new["platform"]; there = old["platform"]
			strict = here != "" && here == there
			for (i = 1; i <= n_old; i++) {
				k = order[i]
				if (k == "platform") continue
				if (k ~ /^sha256\./) {
					nd++
					if (!(k in new) || new[k] != old[k]) {
						w = k ": " short(old[k]) " -> " ((k in new) ? short(new[k]) : "(none)")
						if (strict) { print w; bad++; dbad++ } else { notes[++nn] = w; dbad++ }
					}
					continue
				}
				nv++
				if (!(k in new)) { print k ": gone (was: " old[k] ")"; bad++; vbad++; continue }
				w = differ(old[k], new[k])
				if (w != "") { print k ": " w; bad++; vbad++ }
			}
			for (i = 1; i <= n_new; i++) {
				k = norder[i]
				if (k == "platform" || k in old) continue
				print k ": new: " new[k]; bad++; vbad++
			}
			# the notes first: the "= " line is the last
			for (i = 1; i <= nn; i++) print notes[i] " (informational)"
			if (vbad) printf "= %d of %d values differ from %s", vbad, nv, chk
			else printf "= %d values as recorded", nv
			if (!dbad) printf ", %d digests exact\n", nd
			else if (strict) printf "; %d of %d digests differ\n", dbad, nd
			else printf "; %d of %d digests differ, informational: recorded on %s, this is %s\n", dbad, nd, there, here
			exit bad ? 1 : (dbad ? 3 : 0)
		}
	' "$1" "$2"
}

# compare_named NAME REC: REC against tests/golden/NAME.chk (which must exist).
compare_named() {
	local chk="$golden/$1.chk"
	case "$1" in */*) chk=$1 ;; esac
	if [ ! -f "$chk" ]; then
		echo "= no tests/golden/$1.chk: record it with scripts/golden.sh --update $1 (make golden)"
		return 1
	fi
	compare "$chk" "$2"
}

# chk_of NAME REC: the expectation file written from REC.
chk_of() {
	echo "# tests/golden/$1.chk — what the lockstep run tests/golden/$1.run gave: one KEY VALUE a line"
	echo "# (tests/golden/README.md). Written by scripts/golden.sh --update (make golden), checked by"
	echo "# tests/integration/golden_runs.sh; the sha256 lines are exact only on the platform line's."
	cat "$2"
}

# ---- the command ----------------------------------------------------------------------
case "${1:-}" in
--run)
	[ $# -ge 3 ] && [ $# -le 4 ] || usage
	trap 'stop_runs; exit 143' TERM
	trap 'stop_runs; exit 130' INT
	run_one "$2" "$3" "${4:-}"
	exit
	;;
--compare)
	[ $# -eq 3 ] || usage
	compare_named "$2" "$3"
	exit
	;;
--record)
	[ $# -eq 2 ] || usage
	for f in summary.txt demo-summary.txt events.csv; do [ -f "$2/$f" ] || die "$2 holds no $f: not a run kept by demo.sh --out"; done
	record "$2"
	exit
	;;
esac

update=0 jobs=2 keep="" port="" names=()
while [ $# -gt 0 ]; do
	case "$1" in
	--update) update=1; shift ;;
	--jobs) jobs=${2:-}; shift 2 || usage ;;
	--keep) keep=${2:-}; shift 2 || usage ;;
	--lcm-port) port=${2:-}; shift 2 || usage ;;
	-h|--help) usage ;;
	-*) echo "golden: unknown option '$1' (--help)" >&2; exit 2 ;;
	*) names+=("$(basename "${1%.run}")"); shift ;;
	esac
done
[[ "$jobs" =~ ^[1-9][0-9]?$ ]] || die "--jobs: a number of runs from 1 to 99, not '$jobs'"
[ -z "$port" ] || { [[ "$port" =~ ^[1-9][0-9]{0,4}$ ]] && [ "$port" -le 65000 ]; } || die "--lcm-port: a port from 1 to 65000, not '$port'"
if [ ${#names[@]} -eq 0 ]; then
	for f in "$golden"/*.run; do [ -f "$f" ] && names+=("$(basename "$f" .run)"); done
fi
[ ${#names[@]} -gt 0 ] || die "no runs in tests/golden"
for n in "${names[@]}"; do [ -f "$golden/$n.run" ] || die "no run '$n' (tests/golden/$n.run)"; done
if [ -n "$keep" ]; then
	case "$keep" in /*) ;; *) keep="$PWD/$keep" ;; esac
	outdir_check "$keep" "golden: --keep" || exit 1
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/undulate-golden.XXXXXX") || die "cannot make a temporary directory"
trap 'stop_runs; rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Every run started, JOBS at a time, each on its own LCM port (demo.sh picks
# one from its PID); then, in order, each one's record and comparison.
t0=$(date +%s%N)
running() { local pid n=0; for pid in "${demo_pids[@]}"; do kill -0 "$pid" 2>/dev/null && n=$((n + 1)); done; echo "$n"; }
for i in "${!names[@]}"; do
	while [ "$(running)" -ge "$jobs" ]; do sleep 0.05; done
	start_run "${names[$i]}" "$work" ${port:+"udpm://239.255.76.67:$((port + i))?ttl=0"}
done
failed=0 changed=0
for i in "${!names[@]}"; do
	n=${names[$i]} rc=0
	wait "${demo_pids[$i]}" || rc=$?
	if [ "$rc" != 0 ]; then
		echo "$n: the run failed (demo.sh exit $rc):"
		tail -n 8 "$work/$n.out" | sed 's/^/    /'
		failed=1
		continue
	fi
	record "$work/$n" >"$work/$n.rec"
	out=$(compare_named "$n" "$work/$n.rec"); rc=$?
	echo "$n: $(echo "$out" | tail -n 1 | sed 's/^= //')"
	echo "$out" | sed '$d' | sed 's/^/    /'
	[ "$rc" = 0 ] || changed=1
	if [ "$update" = 1 ] && [ "$rc" != 0 ]; then
		chk_of "$n" "$work/$n.rec" | outdir_put "$golden/$n.chk" && echo "    -> tests/golden/$n.chk written"
	fi
done
demo_pids=()
[ -n "$keep" ] && for n in "${names[@]}"; do
	[ -d "$work/$n" ] && { rm -rf "${keep:?}/$n"; mv "$work/$n" "$keep/$n"; mv "$work/$n.out" "$keep/$n/golden-demo.out"; }
done
echo "golden: ${#names[@]} runs in $(( ($(date +%s%N) - t0) / 1000000000 )) s$([ -n "$keep" ] && echo ", kept in $keep")"
[ "$failed" = 0 ] || exit 1
[ "$update" = 1 ] || [ "$changed" = 0 ]
