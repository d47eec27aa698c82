#!/usr/bin/env bash
# figures_mobility.sh — the mobility module of `make figures` (figures/mobility/,
# the paper's Figs. 7a and 7b from undulate-model: 50 oscillators on mobile
# bases, ends held, d̃ 0.78): its jobs the same every time, bad arguments
# refused (exit 2), and its quick set (β 0.0151, 0.07, 0.7 s, two seeds; no
# daemons) run and merged for real, the CSV checked against the model's
# physics: the row's mean d̃ held by its ends; the bases rebuilt from the
# impacts (δ = β(ẋ_other − ẋ_self)) where the model put them; the pairs
# spread while the mean stays; every run relaxes to compatibility; t_relax
# falls with β; bases pass each other only at the large β. Then the pictures
# (pixels of each series counted) and the section's numbers.
. "$(dirname "$0")/../lib.sh"
F="$top/figures/mobility/fig.sh"
needs_plotting
[ -x "$B/undulate-model" ] || tap_skip_all "undulate-model is not built"

a=$("$F" jobs) b=$("$F" jobs) q=$("$F" jobs --quick) t=$(FIG_TINY=1 "$F" jobs)
tap_check "jobs: 10 β x 10 seeds and 2 x 5 below, the same twice, unique names, three decades; quick 6, tiny 2" \
	bash -c "[ '$a' = '$b' ] && [ \$(wc -l <<<'$a') = 110 ] && [ -z \"\$(awk '{ print \$1 }' <<<'$a' | sort | uniq -d)\" ] &&
		awk '{ if (\$2 >= 0.007) { if (lo == \"\" || \$2 < lo) lo = \$2; if (\$2 > hi) hi = \$2 } } END { exit !(hi / lo >= 999) }' <<<'$a' &&
		[ \$(wc -l <<<'$q') = 6 ] && [ \$(wc -l <<<'$t') = 2 ]"

refused() { tap_refused mobility: "$1" "$F" "${@:2}"; }
refused "no subcommand"
refused "run: negative beta" run "$T/x" -0.1 200 1 0
refused "run: too short" run "$T/x" 0.07 5 1 0
refused "run: DRIFT not 0 or 1" run "$T/x" 0.07 200 1 2
refused "run: missing argument" run "$T/x" 0.07 200 1

# the daemons' rows beside it: a rows.csv of our own (figures/rows' columns),
# its relaxation runs at d̃ 0.78 and one sweep run at 0.7 that must not count
H="dsep,beta,seconds,seed,pairs,colliding_pairs,pair_collisions_hz,compat_error_rad,compat_error_max_rad,compatible_pairs,antiphase_pairs,stopped_pairs,wall_collisions_hz,relax_s,censored,min_swing_rad,wall_s"
printf '%s\n' "$H" "0.78,0.1,240,1,9,0,0,0,0,9,0,0,0,3,0,1.6,50" "0.78,0.02,240,1,9,0,0,0,0,9,0,0,0,40,0,1.6,50" \
	"0.78,0.005,240,1,9,0,0,0,0,9,0,0,0,150,0,1.6,50" "0.78,0.002,240,1,9,1,0.1,0,0,8,0,0,0,236,1,1.6,50" \
	"0.78,0.01,240,2,9,0,0,0,0,9,0,0,0,60,0,1.6,50" "0.7,0.1,60,1,9,0,0,0,0,9,0,0,0,99,0,1.6,14" >"$T/rows.csv"
FIG_ROWS_CSV="$T/rows.csv" fig_module_runs "$F" quick "$q"
C="$T/fig/mobility.csv"
# columns: kind,dsep,beta,seed,seconds,t,collisions,mean_dsep_colliding,dsep_mean,dsep_sd,dsep_min,dsep_max,
#          incompatible_pairs,colliding_pairs,t_relax_s,last_collision_s,neutral_error,dsep_min_run
tap_check "mobility.csv: 6 runs, drift rows for two" \
	bash -c "[ \$(grep -c '^run,' '$C') = 6 ] && [ \$(grep '^drift,' '$C' | cut -d, -f3,4 | sort -u | wc -l) = 2 ]"
tap_check "the ends held: the row's mean d̃ stays 0.78 (to 1e-6) at every drift bin and every run's end" awk -F, '
	function abs(x) { return x < 0 ? -x : x }
	$1 == "run" || $1 == "drift" { n++; if (abs($9 - 0.78) > 1e-6) bad++ } END { exit !(n > 50 && !bad) }' "$C"
tap_check "the mobility's books: bases rebuilt from the impacts end where the model put them (1e-6)" awk -F, '
	$1 == "run" { n++; if ($17 == "" || $17 > 1e-6) bad++ } END { exit !(n == 6 && !bad) }' "$C"
tap_check "7a: the pairs spread while the mean stays (sd from 0 to > 0.05, largest d̃ > 0.9, least < 0.7)" awk -F, '
	$1 == "drift" { k = $3 " " $4; if (!(k in t0) || $6 + 0 < t0[k]) { t0[k] = $6 + 0; first[k] = $10 }
		if ($6 + 0 > t1[k]) { t1[k] = $6 + 0; sd[k] = $10; hi[k] = $12; lo[k] = $11 } }
	END { for (k in first) { n++; if (first[k] > 1e-9 || sd[k] < 0.05 || hi[k] < 0.9 || lo[k] > 0.7) bad++ } exit !(n == 2 && !bad) }' "$C"
tap_check "every run relaxed to compatibility: no pair beyond 2 asin(d̃), none colliding at the end" awk -F, '
	$1 == "run" { n++; if ($15 == "" || $13 != 0 || $14 != 0) bad++ } END { exit !(n == 6 && !bad) }' "$C"
tap_check "7b: t_relax falls with β (mean at 0.0151 s over 3x that at 0.7 s)" awk -F, '
	$1 == "run" { s[$3] += $15; n[$3]++ } END { exit !(n[0.0151] == 2 && n[0.7] == 2 && s[0.0151] / 2 > 3 * s[0.7] / 2) }' "$C"
tap_check "bases pass each other at β 0.7 s only (least d̃ of the run below 0 there, above 0.1 elsewhere)" awk -F, '
	$1 == "run" { if ($3 == 0.7 ? $18 >= 0 : $18 < 0.1) bad++; n++ } END { exit !(n == 6 && !bad) }' "$C"
blue=$("$PNG" --rgb 1f77b4 "$T/fig/mobility.png" 2>/dev/null | sed -n 's/.*matching=//p')
grey=$("$PNG" --rgb 555555 "$T/fig/mobility.png" 2>/dev/null | sed -n 's/.*matching=//p')
if [ "${blue:-0}" -gt 1000 ] && [ "${grey:-0}" -gt 300 ]; then tap_ok "mobility.png: the model's runs and median, the daemons' runs ($blue, $grey pixels)"
else tap_fail "mobility.png draws its series" "blue ${blue:-?}, grey ${grey:-?} pixels"; fi
orange=$("$PNG" --rgb ff7f0e "$T/fig/mobility-drift.png" 2>/dev/null | sed -n 's/.*matching=//p')
tap_check "mobility-drift.png: the second β's curves drawn (${orange:-no} pixels)" test "${orange:-0}" -ge 1000
tap_check "the section: a row per β, the books and the daemons" \
	bash -c "grep -qE '^\\| 0.7 \\| 2 \\| 2 \\| 0 \\| 200 \\| [0-9.]+ \\| ' '$T/fig/mobility.md' && grep -q 'the mobility.s books add up' '$T/fig/mobility.md' &&
		grep -q \"The daemons' runs by β: \" '$T/fig/mobility.md'"
tap_check "the daemons' runs are figures/rows' relaxation runs at d̃ 0.78 (5), not its sweep at 0.7" \
	grep -q "(5 runs from this invocation's rows.csv)" "$T/fig/mobility.md"
tap_done
