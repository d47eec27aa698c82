#!/usr/bin/env bash
# figures_heatmap.sh — the heatmap module of `make figures` (figures/heatmap/,
# the paper's Fig. 3a from undulate-model): its jobs the same every time,
# bad arguments refused (exit 2), and its quick set run and merged for real
# (no daemons: a second or two): the CSV's every point on theory.md's map,
# the picture with both colours of its data drawn (pixels counted: the
# colour bars alone hold about 1000 of each), the section with its numbers.
. "$(dirname "$0")/../lib.sh"
F="$top/figures/heatmap/fig.sh"
needs_plotting
[ -x "$B/undulate-model" ] || tap_skip_all "undulate-model is not built"

a=$("$F" jobs) b=$("$F" jobs) q=$("$F" jobs --quick)
tap_check "jobs: four restitutions, the same twice, unique names" \
	bash -c "[ '$a' = '$b' ] && [ \$(wc -l <<<'$a') = 4 ] && [ -z \"\$(awk '{ print \$1 }' <<<'$a' | sort | uniq -d)\" ] && [ \$(wc -l <<<'$q') = 4 ]"

refused() { tap_refused heatmap: "$1" "$F" "${@:2}"; }
refused "no subcommand"
refused "run: r above 1" run "$T/x" 1.5 11 12
refused "run: too few points" run "$T/x" 0.5 1 12
refused "run: missing argument" run "$T/x" 0.5 11

fig_module_runs "$F" quick "$q"
tap_check "heatmap.csv: 4 x 26 x 36 points" test "$(tail -n +2 "$T/fig/heatmap.csv" | wc -l)" = $((4 * 26 * 36))
tap_check "every touching point on theory.md's map (to the CSV's 6 digits)" awk -F, '
	function abs(x) { return x < 0 ? -x : x }
	NR > 1 && $6 == 1 { d = abs($4 - $7); if (d > 3.14159) d = 6.2831853 - d; if (d > 1e-5) bad++; n++ }
	NR > 1 && $6 == 0 { if ($5 != 0 || $2 != 0 && sin($3 / 2) > $2 + 1e-3) nc++ }
	END { exit !(n > 1000 && !bad && !nc) }' "$T/fig/heatmap.csv"
red=$("$PNG" --rgb ef8a62 "$T/fig/heatmap.png" 2>/dev/null | sed -n 's/.*matching=//p')
blue=$("$PNG" --rgb 67a9cf "$T/fig/heatmap.png" 2>/dev/null | sed -n 's/.*matching=//p')
if [ "${red:-0}" -gt 8000 ] && [ "${blue:-0}" -gt 8000 ]; then tap_ok "heatmap.png draws growth and shrink ($red, $blue pixels)"
else tap_fail "heatmap.png draws growth and shrink" "red ${red:-?}, blue ${blue:-?} pixels"; fi
tap_check "the section: a row per r, the grid's shares" \
	bash -c "grep -c '^| 0\\.[0-9]* | 936 | ' '$T/fig/heatmap.md' | grep -qx 4"
tap_check "the section: integrator against theory.md below 1e-5 at each r" \
	bash -c "[ \$(grep -cE '\\| [0-9.]+e-0[6-9] rad \\|$' '$T/fig/heatmap.md') = 4 ]"
tap_done
