#!/usr/bin/env bash
# The man pages installed by `make install` stay true to the programs:
#   - each renders without a groff/man warning;
#   - every long option a program's --help lists is documented in its page;
#   - every option the page's SYNOPSIS/OPTIONS/COMMANDS sections name exists
#     in --help (no stale flags), written with ASCII hyphens (a page that
#     renders "‐‐port" with typographic hyphens cannot be copied into a shell);
#   - it has EXAMPLES: at least two command lines that run the program, whose
#     options exist in --help and are ASCII too (copied into a shell, they run).
# A program that is not built is skipped (TAP SKIP), its page still rendered.
. "$(dirname "$0")/../lib.sh"

pages=(undulated.8 undulate-sim.1 dxl.1 undulate-top.1 undulate-analyze.1 undulate-web.1 undulate-model.1)

render() { LC_ALL=C.UTF-8 MANWIDTH=2000 man --warnings -E UTF-8 -l "$1"; }
long_opts() { grep -oE -- '(^|[^A-Za-z0-9-])--[a-z][a-z0-9-]*' | grep -oE -- '--[a-z][a-z0-9-]*' | sort -u; }
# The text of the sections that define a program's interface.
iface_sections() { awk '/^[A-Z][A-Z ]*$/ { keep = ($0 ~ /^(SYNOPSIS|OPTIONS|COMMANDS)$/) } keep'; }
examples() { awk '/^[A-Z][A-Z ]*$/ { keep = ($0 == "EXAMPLES"); next } keep'; }

if ! command -v man >/dev/null; then
	tap_skip "man pages" "man not installed"
	tap_done; exit
fi

for page in "${pages[@]}"; do
	prog=${page%.*}
	src="$top/man/$page"
	if [ ! -f "$src" ]; then
		tap_fail "$page exists"
		continue
	fi
	warn=$(render "$src" 2>&1 >/dev/null)
	text=$(render "$src" 2>/dev/null)
	if [ -z "$warn" ] && [ -n "$text" ]; then tap_ok "$page renders without warnings"
	else tap_fail "$page renders without warnings" "$warn"; fi

	ex=$(echo "$text" | examples)
	runs=$(echo "$ex" | grep -cE "^ *(\\$ |# )?$prog( |$)" || true)
	ex_typographic=$(echo "$ex" | grep -c $'\u2010' || true)
	if [ "$runs" -ge 2 ] && [ "$ex_typographic" -eq 0 ]; then tap_ok "$page has EXAMPLES ($runs command lines running $prog)"
	else tap_fail "$page has EXAMPLES: two or more command lines running $prog, ASCII hyphens" \
		"$runs command lines, $ex_typographic typographic hyphens: $(echo "$ex" | head -n 5)"; fi

	if [ ! -x "$B/$prog" ]; then
		tap_skip "$page matches $prog --help" "$prog not built"
		continue
	fi
	# --help itself works (exit 0) even where the text does not list it.
	help=$("$B/$prog" --help 2>&1) && help+=$'\n--help'
	help_opts=$(echo "$help" | long_opts)
	page_opts=$(echo "$text" | long_opts)
	iface_opts=$(echo "$text" | iface_sections | long_opts)
	undocumented=$(comm -23 <(echo "$help_opts") <(echo "$page_opts") | tr '\n' ' ')
	# the options of the example lines that run this program (others run beside it)
	ex_opts=$(echo "$ex" | grep -E "^ *$prog( |$)" | long_opts)
	stale=$(comm -13 <(echo "$help_opts") <(sort -u <(echo "$iface_opts") <(echo "$ex_opts") | grep .) | tr '\n' ' ')
	typographic=$(echo "$text" | iface_sections | grep -c $'\u2010\u2010' || true)
	if [ -n "$help_opts" ] && [ -z "$undocumented" ] && [ -z "$stale" ] && [ "$typographic" -eq 0 ]; then
		tap_ok "$page documents every option of $prog --help ($(echo "$help_opts" | wc -l)), and no other"
	else
		tap_fail "$page matches $prog --help" \
			"undocumented: ${undocumented:-none}; not in --help: ${stale:-none}; typographic hyphens: $typographic"
	fi
done
tap_done
