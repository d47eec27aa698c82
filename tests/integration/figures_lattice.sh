#!/usr/bin/env bash
# figures_lattice.sh — the lattice module of `make figures` (figures/lattice/,
# the paper's Figs. 6b and 6c from undulate-model: 50 immobile oscillators):
# its jobs the same every time, bad arguments refused (exit 2), and its quick
# set (six d̃, one seed, 120 s; no daemons) run and merged for real, the CSV
# checked against the model's physics: immobile bases keep their d̃; a pair
# that stopped colliding lies within 2 asin(d̃); no pair touches at d̃ ≥ 1;
# the dense rows relax and those at d̃ 0.5 and 0.8 keep colliding (theory.md:
# the paper's lattice); after t_relax every phase turns at ω exactly. Then
# the pictures (pixels of each series counted) and the section's numbers.
. "$(dirname "$0")/../lib.sh"
F="$top/figures/lattice/fig.sh"
needs_plotting
[ -x "$B/undulate-model" ] || tap_skip_all "undulate-model is not built"

a=$("$F" jobs) b=$("$F" jobs) q=$("$F" jobs --quick) t=$(FIG_TINY=1 "$F" jobs)
tap_check "jobs: 14 d̃ x 5 seeds, the same twice, unique names, one 6b run; quick 6, tiny 2" \
	bash -c "[ '$a' = '$b' ] && [ \$(wc -l <<<'$a') = 70 ] && [ -z \"\$(awk '{ print \$1 }' <<<'$a' | sort | uniq -d)\" ] &&
		[ \$(awk '\$5 > 0' <<<'$a' | wc -l) = 1 ] && [ \$(wc -l <<<'$q') = 6 ] && [ \$(wc -l <<<'$t') = 2 ]"

refused() { tap_refused lattice: "$1" "$F" "${@:2}"; }
refused "no subcommand"
refused "run: negative d~" run "$T/x" -0.1 120 1 0
refused "run: too short" run "$T/x" 0.5 5 1 0
refused "run: phases longer than the run" run "$T/x" 0.5 60 1 90
refused "run: missing argument" run "$T/x" 0.5 60 1

fig_module_runs "$F" quick "$q"
C="$T/fig/lattice.csv"
# columns: kind,dsep,seed,seconds,i,t,phase,abs_delta,pair_dsep,compat_limit,collisions,window_collisions,class,t_relax_s,last_collision_s
tap_check "lattice.csv: 6 runs, 49 pairs each" \
	bash -c "[ \$(grep -c '^run,' '$C') = 6 ] && [ \$(grep -c '^pair,' '$C') = 294 ]"
tap_check "immobile bases: every pair keeps its d̃ (to 1e-6)" awk -F, '
	function abs(x) { return x < 0 ? -x : x }
	$1 == "pair" { n++; if (abs($9 - $2) > 1e-6) bad++ } END { exit !(n == 294 && !bad) }' "$C"
tap_check "a pair that stopped colliding lies within 2 asin(d̃) (+0.01 rad); none touches at d̃ ≥ 1" awk -F, '
	$1 == "pair" && $2 < 1 && $12 == 0 { q++; if ($8 > 2 * atan2($2, sqrt(1 - $2 * $2)) + 0.01) bad++ }
	$1 == "pair" && $2 >= 1 && $11 > 0 { touch++ }
	END { exit !(q > 150 && !bad && !touch) }' "$C"
tap_check "d̃ ≤ 0.3: relaxed (t_relax 0.1-60 s); 0.5 and 0.8: censored, most pairs colliding; 1.2: never touched" awk -F, '
	$1 == "run" && $2 <= 0.3 { if ($14 == "" || $14 < 0.1 || $14 > 60) bad++ }
	$1 == "run" && ($2 == 0.5 || $2 == 0.8) { if ($14 != "" || $12 < 10) bad++ }
	$1 == "run" && $2 == 1.2 { if ($14 != 0 || $11 != 0) bad++ }
	$1 == "pair" && ($2 == 0.5 || $2 == 0.8) { p++; if ($12 > 0) c++ }
	END { exit !(!bad && c * 2 > p) }' "$C"
# after the last collision nothing changes: each oscillator's φ − ωt holds
tap_check "6b: after t_relax every phase turns at ω (φ − ωt constant to 1e-3 rad)" awk -F, '
	function abs(x) { return x < 0 ? -x : x }
	NR == FNR { if ($1 == "run" && $2 == 0.14) tr = $14; next }
	$1 == "phase" { n++; if ($6 > tr + 0.1) { if ($5 in ref) { d = abs($7 - ref[$5]); if (d > 3.14159) d = 6.28319 - d; if (d > 1e-3) bad++ } else ref[$5] = $7; k++ } }
	END { exit !(tr > 0 && n >= 50 * 15 * 20 && k > 1000 && !bad && length(ref) == 50) }' "$C" "$C"
tap_check "6b: the collisions per second add up to the run's (it relaxed within the 15 s sampled)" awk -F, '
	$1 == "rate" { s += $11; r++ } $1 == "run" && $2 == 0.14 { n = $11 } END { exit !(r == 15 && s == n && n > 0) }' "$C"
blue=$("$PNG" --rgb 1f77b4 "$T/fig/lattice-pairs.png" 2>/dev/null | sed -n 's/.*matching=//p')
red=$("$PNG" --rgb d62728 "$T/fig/lattice-pairs.png" 2>/dev/null | sed -n 's/.*matching=//p')
grey=$("$PNG" --rgb 555555 "$T/fig/lattice-pairs.png" 2>/dev/null | sed -n 's/.*matching=//p')
if [ "${blue:-0}" -gt 300 ] && [ "${red:-0}" -gt 300 ] && [ "${grey:-0}" -gt 1000 ]; then
	tap_ok "lattice-pairs.png: pairs apart and colliding, the daemons' line ($blue, $red, $grey pixels)"
else tap_fail "lattice-pairs.png draws its series" "blue ${blue:-?}, red ${red:-?}, grey ${grey:-?} pixels"; fi
px=$("$PNG" "$T/fig/lattice.png" 2>&1 | sed -n 's/.* coloured=\([0-9]*\).*/\1/p')
tap_check "lattice.png: the phases drawn (${px:-no} coloured pixels)" test "${px:-0}" -ge 30000
tap_check "the section: a row per d̃, 6b's numbers, the daemons beside the model" \
	bash -c "grep -qE '^\| 0.5 \| 1 \| [0-9]+ of 49 \([0-9]+ %\) \| none relaxed \| 1 \| ' '$T/fig/lattice.md' && grep -q '^| 1.2 | 1 | 0 of 49 (0 %) | never touched | 0 | - |' '$T/fig/lattice.md' &&
		grep -q 't_relax = [0-9.]* s' '$T/fig/lattice.md' && grep -q 'model / daemons, at the d̃ both ran: 0.3: ' '$T/fig/lattice.md'"
tap_done
