#!/usr/bin/env bash
# readme_commands.sh — the README's commands still run, as a new user pastes them.
#  - Every ```sh block runs, line by line, from the top of the tree: a line
#    ending in '&' starts in the background (and is given up to 10 s to say
#    "ready"); any other line must succeed, and is tried again for up to 20 s
#    as a person would (a daemon that is not answering yet). /tmp/ and
#    demo-out/ are moved into this test's folder, LCM onto its own port, and
#    whatever a block leaves running is stopped with it.
#  - A ```sh robot block (it needs servos) or ```sh long one (make demo, make
#    test, make figures) is not run: it must parse, every program it names
#    must exist, every --option it gives one of ours must be in that
#    program's --help, and every make target must be in the Makefile.
# What the blocks show is checked too: the robot in undulate-top's snapshot,
# the lockstep run's speed line, and the plots with data in them.
. "$(dirname "$0")/../lib.sh"
README="$top/README.md"
[ -x "$B/undulated" ] && [ -x "$B/undulate-sim" ] || tap_skip_all "undulated or undulate-sim not built"
export LCM_DEFAULT_URL
LCM_DEFAULT_URL=$(lcm_url 7797)

# blocks FILE: each fenced block as "KIND<TAB>FIRST-LINE-NUMBER" then its lines
# into $T/block.N (continuation lines joined), KIND "sh", "sh robot", ...
awk -v dir="$T" '
	/^```/ && !inb { inb = 1; kind = substr($0, 4); n++; f = dir "/block." n; printf "" > f; start = NR + 1
		print n "\t" kind "\t" start; next }
	/^```/ && inb { inb = 0; close(f); next }
	inb { if (cont) line = line " " $0; else line = $0
		if (line ~ /\\$/) { sub(/\\$/, "", line); cont = 1; next }
		cont = 0; print line >> f }
' "$README" >"$T/blocks"
[ -s "$T/blocks" ] || { tap_fail "the README has shell blocks" "none found in $README"; tap_done; exit 1; }

ours="undulated undulate-sim undulate-top undulate-web undulate-analyze dxl"
# check_line LINE: what is wrong with a line that is not run ("" if nothing)
check_line() {
	local line=$1 why="" w prog opt
	line=${line%%#*}                       # the comment
	line=${line#sudo }
	read -r prog _ <<<"$line"
	[ -z "$prog" ] && return
	if [[ " $ours " == *" ${prog##*/} "* ]]; then
		local help
		help=$("$B/${prog##*/}" --help 2>&1)
		for opt in $(grep -oE '(^| )--[a-z][a-z0-9-]*' <<<"$line"); do
			grep -qe "$opt" <<<"$help" || why+="${prog##*/} has no $opt; "
		done
	else
		case $prog in
		make)
			for w in $line; do
				case $w in make | *=*) ;; *) grep -qE "^$w:" "$top/Makefile" || why+="no make target $w; " ;; esac
			done ;;
		scripts/*) [ -x "$top/$prog" ] || why+="no $prog; " ;;
		rsync | ssh | git | cd) ;;  # the user's own tools, to reach the robot
		*) command -v "$prog" >/dev/null 2>&1 || why+="unknown program $prog; " ;;
		esac
	fi
	echo "$why"
}

while IFS=$'\t' read -r n kind start; do
	f="$T/block.$n"
	first=$(head -n 1 "$f" | cut -c1-60)
	case "$kind" in
	sh)
		# the block as a script of its own: each line run as described above
		{
			echo 'cd "$1" || exit 9'
			echo 'fg_line() { local t0=$SECONDS; until eval "$1"; do [ $((SECONDS - t0)) -ge 20 ] && { echo "README-LINE-FAILED: $1"; return 1; }; sleep 0.5; done; }'
			echo 'bg_line() { eval "$1 >\"$2\" 2>&1 &"; local i; for i in $(seq 100); do grep -qi ready "$2" 2>/dev/null && return; kill -0 $! 2>/dev/null || return; sleep 0.1; done; }'
			k=0
			while IFS= read -r line; do
				line=${line//\/tmp\//$T/}
				line=${line//demo-out\//$T/demo-out/}
				[[ "$line" =~ ^[[:space:]]*$ ]] && continue
				k=$((k + 1))
				code=${line%%#*}
				if [[ "$code" =~ \&[[:space:]]*$ ]]; then
					code=${code%&*}
					printf 'bg_line %q %q\n' "$code" "$T/bg.$n.$k.log"
				else
					printf 'fg_line %q || exit 1\n' "$code"
				fi
			done <"$f"
		} >"$T/run.$n.sh"
		setsid bash "$T/run.$n.sh" "$top" >"$T/out.$n" 2>&1 &
		pid=$!
		wait_for 300 bash -c "! kill -0 $pid 2>/dev/null"
		kill -- -"$pid" 2>/dev/null
		wait "$pid"; rc=$?
		kill -TERM -- -"$pid" 2>/dev/null
		if [ "$rc" = 0 ]; then tap_ok "README line $start: the block '$first' runs"
		else tap_fail "README line $start: the block '$first'" "exit $rc: $(tail -n 8 "$T/out.$n")"; fi
		;;
	sh\ robot | sh\ long)
		why=""
		bash -n "$f" 2>"$T/syntax.$n" || why+="does not parse: $(head -2 "$T/syntax.$n"); "
		while IFS= read -r line; do why+=$(check_line "$line"); done <"$f"
		if [ -z "$why" ]; then tap_ok "README line $start: '$first' (${kind#sh }: not run) parses, names programs, options and targets that exist"
		else tap_fail "README line $start: '$first'" "$why"; fi
		;;
	*) ;;  # text, output and other fences: not commands
	esac
done <"$T/blocks"

# what the runnable blocks show
if grep -q ' r1 ' "$T"/out.* 2>/dev/null || grep -q '^r1\b\|"r1"\| r1$' "$T"/out.* 2>/dev/null; then
	tap_ok "undulate-top's snapshot shows the robot r1"
else tap_fail "undulate-top shows r1" "$(cat "$T"/out.1* 2>/dev/null | head -20)"; fi
if grep -qE 'of simulated time in [0-9.]+ s \([0-9.]+x real time\)' "$T"/out.*; then
	tap_ok "the lockstep run says how fast it ran: $(grep -ohE '[0-9.]+ s of simulated time in [0-9.]+ s \([0-9.]+x real time\)' "$T"/out.* | head -1)"
else tap_fail "the lockstep run's speed line" "$(tail -n 5 "$T"/out.* | head -30)"; fi
pngs=$(ls "$T"/demo-out/rig/plots/*.png 2>/dev/null | wc -l)
with=0
for p in "$T"/demo-out/rig/plots/*.png; do
	[ -f "$p" ] || continue
	c=$("$BUILD/tests/tools/pngdata" "$p" 2>/dev/null | sed -n 's/.*coloured=//p')
	[ "${c:-0}" -gt 500 ] && with=$((with + 1))
done
if [ "$pngs" -ge 3 ] && [ "$with" = "$pngs" ]; then tap_ok "the plots command drew $pngs PNGs, each with data drawn (pngdata)"
else tap_fail "the plots" "$pngs PNGs, $with with data: $(ls "$T"/demo-out/rig/plots 2>&1 | head)"; fi
tap_done
