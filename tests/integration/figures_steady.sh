#!/usr/bin/env bash
# figures_steady.sh — the steady module of `make figures` (figures/steady/,
# the paper's Fig. 3c from undulate-model): its jobs the same every time,
# bad arguments refused (exit 2), and its tiny set (FIG_TINY=1: 2 x 24 pairs,
# no daemons, a few seconds) run and merged for real: every pair's end where
# theory.md's map iterated from its start leads, no end at π left of d̃_c,
# the picture drawn, the section with its numbers.
. "$(dirname "$0")/../lib.sh"
F="$top/figures/steady/fig.sh"
needs_plotting
[ -x "$B/undulate-model" ] || tap_skip_all "undulate-model is not built"

a=$("$F" jobs) b=$("$F" jobs) q=$("$F" jobs --quick) t=$(FIG_TINY=1 "$F" jobs)
tap_check "jobs: nine restitutions, the same twice, unique names; quick five, tiny two" \
	bash -c "[ '$a' = '$b' ] && [ \$(wc -l <<<'$a') = 9 ] && [ -z \"\$(awk '{ print \$1 }' <<<'$a' | sort | uniq -d)\" ] &&
		[ \$(wc -l <<<'$q') = 5 ] && [ \$(wc -l <<<'$t') = 2 ]"

refused() { tap_refused steady: "$1" "$F" "${@:2}"; }
refused "no subcommand"
refused "run: r above 1" run "$T/x" 1.5 6 4 120
refused "run: one d~ point" run "$T/x" 0.5 1 4 120
refused "run: too short" run "$T/x" 0.5 6 4 5
refused "run: missing argument" run "$T/x" 0.5 6 4

fig_module_runs "$F" tiny "$t"
tap_check "steady.csv: 2 x 6 x 4 pairs" test "$(tail -n +2 "$T/fig/steady.csv" | wc -l)" = 48
tap_check "every pair ends where the map from its start leads (|Δ| within 1e-3 rad)" awk -F, '
	function abs(x) { return x < 0 ? -x : x }
	NR > 1 { n++; if (abs(abs($5) - abs($8)) > 1e-3) bad++ } END { exit !(n == 48 && !bad) }' "$T/fig/steady.csv"
# d~_c: 0.308 at r = 0.3, 0.207 at 0.9 (theory.md)
tap_check "ends at π only right of d̃_c, and some there at r = 0.9" awk -F, '
	function abs(x) { return x < 0 ? -x : x }
	NR > 1 && 3.14159265 - abs($5) < 0.01 { if ($2 < ($1 == 0.3 ? 0.308 : 0.207)) left++; else if ($1 == 0.9) right++ }
	END { exit !(!left && right >= 2) }' "$T/fig/steady.csv"
px=$("$PNG" "$T/fig/steady.png" 2>&1 | sed -n 's/.* coloured=\([0-9]*\).*/\1/p')
tap_check "steady.png: both panels coloured (${px:-no} data pixels)" test "${px:-0}" -ge 100000
tap_check "the section: a row per r with d̃_c, the model and the map side by side" \
	bash -c "grep -q '^| 0.3 | 0.308 | 6 | 0.000 rad | 1.571 rad | ' '$T/fig/steady.md' && grep -q '^| 0.9 | 0.207 | 6 | ' '$T/fig/steady.md'"
tap_done
