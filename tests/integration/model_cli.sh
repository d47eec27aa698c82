#!/usr/bin/env bash
# undulate-model from the command line: the files of undulate-analyze's
# layout (each CSV's header the analyser's own, read from an analysis of its
# synthetic log; summary.json with every key the analyser writes), the d~ = 0
# return map on its closed form, momentum and the factor r at every impact,
# the pair's three regimes, a lattice with fixed ends and walls, the map
# subcommand, and bad input refused with exit 2 and nothing written.
. "$(dirname "$0")/../lib.sh"
M="$B/undulate-model"
A="$B/undulate-analyze"

# ---- the analyser's layout, from the analyser itself ----
"$A" --synth "$T/s.log" --duration 8 >/dev/null 2>&1
"$A" "$T/s.log" --out "$T/an" --quiet >/dev/null 2>&1
tap_check "the analyser's reference analysis exists" test -s "$T/an/summary.json"

"$M" pair --dsep 0 --delta0 2 --restitution 0.67 --duration 20 --out "$T/p0" --quiet >"$T/p0.out" 2>&1
rc=$?
if [ "$rc" = 0 ]; then tap_ok "pair at d~ = 0 exits 0"; else tap_fail "pair at d~ = 0 exits 0" "rc=$rc: $(cat "$T/p0.out")"; fi
for f in states phase_diff collisions collision_rate; do
	tap_check "$f.csv: the analyser's header" test "$(head -n1 "$T/p0/$f.csv")" = "$(head -n1 "$T/an/$f.csv")"
	tap_check "$f.csv: rows" test "$(wc -l <"$T/p0/$f.csv")" -gt 2
done
# return_map.csv: the analyser's columns, then the model's delta_after
an_rm=$(head -n1 "$T/an/return_map.csv")
tap_check "return_map.csv: the analyser's columns first" test "$(head -n1 "$T/p0/return_map.csv")" = "$an_rm,delta_after"

# summary.json: every key the analyser writes, at the top, in a pair, in a robot's joint
keys() { jq -r "$1 | keys[]" "$2" | sort; }
missing() { comm -23 <(keys "$1" "$T/an/summary.json") <(keys "$1" "$2"); }
for path in '.' '.pairs[0]' '.robots[0]' '.robots[0].joints[0]' '.force' '.walls'; do
	miss=$(missing "$path" "$T/p0/summary.json" | tr '\n' ' ')
	if [ -z "$miss" ]; then tap_ok "summary.json $path: every key of the analyser's"
	else tap_fail "summary.json $path: every key of the analyser's" "missing: $miss"; fi
done
tap_check "summary.json: the model's parameters" \
	jq -e '.model.command == "pair" and .model.restitution == 0.67 and .model.dsep == 0 and .world == "model"' "$T/p0/summary.json"

# ---- the numbers ----
# d~ = 0: delta_n = 2 atan((-r)^n tan(delta0/2)), delta0 = 2, every point of the run
tap_check "d~ = 0 return map on the closed form (1e-6), 16 points or more" awk -F, '
	NR > 1 { n = $2; e0 = 2 * atan2((-0.67)^n * sin(1), cos(1)); e1 = 2 * atan2((-0.67)^(n + 1) * sin(1), cos(1));
		if (($5 - e0)^2 > 1e-12 || ($6 - e1)^2 > 1e-12 || ($7 - e1)^2 > 1e-12) bad = 1; pts++ }
	END { exit !(pts >= 16 && !bad) }' "$T/p0/return_map.csv"
tap_check "every impact keeps the momentum and scales the relative speed by -r" awk -F, '
	NR > 1 { m = ($7 + $8) - ($9 + $10); s = ($9 - $10) + 0.67 * ($7 - $8);
		if (m * m > 1e-14 || s * s > 1e-14) bad = 1; n++ }
	END { exit !(n > 0 && !bad) }' "$T/p0/collisions.csv"
# at d~ = 0 the pair touches once a period for ever, ever more lightly: the
# analyser's rules call that grazing (locked, contacts below 0.1 N)
tap_check "d~ = 0 ends in phase (|delta| < 0.01), grazing" \
	jq -e '.pairs[0].class == "grazing" and .pairs[0].mean_abs_delta < 0.01' "$T/p0/summary.json"

"$M" pair --dsep 0.3 --delta0 0.5 --duration 30 --out "$T/p3" --quiet >/dev/null 2>&1
tap_check "d~ = 0.3 from 0.5 rad (below 2 asin(0.3) = 0.61): compatible, no contact, relaxed at 0" \
	jq -e '.pairs[0].class == "compatible" and .pairs[0].collisions == 0 and .model.t_relax_s == 0' "$T/p3/summary.json"
"$M" pair --dsep 0.3 --delta0 1.0 --duration 30 --out "$T/p3b" --quiet >/dev/null 2>&1
tap_check "d~ = 0.3 from 1.0 rad: one collision, then no more" \
	jq -e '.pairs[0].collisions == 1 and .model.t_relax_s < 1.25' "$T/p3b/summary.json"
"$M" pair --dsep 0.6 --delta0 2.5 --duration 30 --out "$T/p6" --quiet >/dev/null 2>&1
tap_check "d~ = 0.6 from 2.5 rad: anti-phase, colliding every period" \
	jq -e '.pairs[0].class == "anti-phase" and .pairs[0].window_collisions >= 7' "$T/p6/summary.json"

# Anti-phase kicked: a pair locked at pi stays there collision after
# collision; kicked by 0.05 rad it comes back where pi is stable (d~ 0.5 > d~_c
# 0.316 at r 0.67), the kick shrinking by |f'(pi)| per collision, and leaves
# where it is not (d~ 0.25), the kick growing by |f'(pi)| — the theory's
# slopes from undulate-analyze --theory curves (0.430 and 1.170).
fp() { "$B/undulate-analyze" --theory curves --restitution 0.67 --points 5 | awk -F, -v d="$1" -v c="${2:-4}" '$1 == d { print $c }'; }
"$M" pair --dsep 0.5 --delta0 3.14159265358979 --duration 20 --no-samples --out "$T/a0" --quiet >/dev/null 2>&1
tap_check "anti-phase at d~ 0.5, locked: |delta| = pi (1e-8) at every collision" awk -F, '
	function abs(x) { return x < 0 ? -x : x }
	NR > 1 { n++; if (3.14159265358979 - abs($6) > 1e-8) bad++ } END { exit !(n >= 20 && !bad) }' "$T/a0/return_map.csv"
# kicked RUN: the kick pi - |delta| before each of the first collisions, and its
# ratio collision to collision (the first four)
kicks() { awk -F, 'function abs(x) { return x < 0 ? -x : x }
	NR > 1 && NR <= 6 { k[NR - 1] = 3.14159265358979 - abs($5) }
	END { for (i = 2; i <= 5; i++) printf "%.4f ", k[i] / k[i - 1] }' "$1/return_map.csv"; }
"$M" pair --dsep 0.5 --delta0 3.09159265358979 --duration 30 --no-samples --out "$T/a1" --quiet >/dev/null 2>&1
f=$(fp 0.5) k=$(kicks "$T/a1")
tap_check "kicked by 0.05 rad at d~ 0.5: back at pi (1e-6), the kick times $k per collision, |f'(pi)| = $f (1 %)" bash -c "
	jq -e '.pairs[0].class == \"anti-phase\" and 3.14159265 - .pairs[0].mean_abs_delta < 1e-6' '$T/a1/summary.json' >/dev/null &&
	awk -v k='$k' -v f='$f' 'BEGIN { n = split(k, a, \" \"); if (n != 4 || f == \"\") exit 1
		for (i = 1; i <= n; i++) if ((a[i] - f)^2 > (0.01 * f)^2) exit 1 }'"
"$M" pair --dsep 0.25 --delta0 3.09159265358979 --duration 30 --no-samples --out "$T/a2" --quiet >/dev/null 2>&1
f=$(fp 0.25) k=$(kicks "$T/a2") lim=$(fp 0.25 2)
tap_check "kicked by 0.05 rad at d~ 0.25: leaves pi for the compatible set (below 2 asin(d~) = $lim), the kick times $k per collision, |f'(pi)| = $f (2 %)" bash -c "
	jq -e '.pairs[0].class == \"compatible\" and .pairs[0].mean_abs_delta < ${lim:-0}' '$T/a2/summary.json' >/dev/null &&
	awk -v k='$k' -v f='$f' 'BEGIN { n = split(k, a, \" \"); if (n != 4 || f == \"\") exit 1
		for (i = 1; i <= n; i++) if ((a[i] - f)^2 > (0.02 * f)^2) exit 1 }'"

# ---- a lattice: per-oscillator beta, fixed ends, walls, one seed one run ----
run_lat() { "$M" lattice --n 8 --dsep 0.4 --beta 0.02 --fixed-ends --walls 0.1 --seed 7 --duration 60 \
	--sample-hz 10 --out "$1" --quiet; }
run_lat "$T/l1" >"$T/l1.out" 2>&1
rc=$?
if [ "$rc" = 0 ]; then tap_ok "lattice exits 0"; else tap_fail "lattice exits 0" "rc=$rc: $(cat "$T/l1.out")"; fi
run_lat "$T/l2" >/dev/null 2>&1
tap_check "the same seed gives the same collisions" cmp -s "$T/l1/collisions.csv" "$T/l2/collisions.csv"
tap_check "fixed ends: beta 0 at both ends, 0.02 inside" \
	jq -e '.model.beta[0] == 0 and .model.beta[7] == 0 and .model.beta[3] == 0.02' "$T/l1/summary.json"
tap_check "fixed ends stay where they were; an inner one moved" \
	jq -e '.model.neutral_final[0] == 0 and (.model.neutral_final[7] - 7 * 0.64 | fabs) < 1e-9
		and (.model.neutral_final[3] - 3 * 0.64 | fabs) > 1e-6' "$T/l1/summary.json"
tap_check "walls: impacts on them, as wall rows (-1)" \
	bash -c "jq -e '.wall_collisions > 0' '$T/l1/summary.json' >/dev/null && grep -q ',-1,' '$T/l1/collisions.csv'"
# the figure modules read a run's pairs with figures/lib.sh's fig_pairs
pairs=$(bash -c '. "$1/figures/lib.sh"; fig_pairs "$2"' _ "$top" "$T/l1/summary.json" 2>&1)
tap_check "fig_pairs reads the lattice's seven pairs: a name, a class and eleven numbers each" awk -F, '
	$1 ~ /^r[1-7]:r[2-8]$/ && $2 ~ /^[a-z-]+$/ && NF == 13 { for (i = 3; i <= NF; i++) if ($i !~ /^-?[0-9.e+-]+$|^nan$/) next; n++ }
	END { exit n != 7 }' <<<"$pairs"
tap_check "seven neighbouring pairs, r1:r2 .. r7:r8" \
	jq -e '[.pairs[].pair] == ["r1:r2","r2:r3","r3:r4","r4:r5","r5:r6","r6:r7","r7:r8"]' "$T/l1/summary.json"

# ---- map: the heatmap's data ----
"$M" map --dsep 0 --delta-points 30 --restitution 0.5 >"$T/map.csv" 2>"$T/map.err"
tap_check "map: header and 30 rows" bash -c "[ \"\$(head -n1 '$T/map.csv')\" = 'dsep,delta_n,delta_next,change,collided,theory_next' ] && [ \$(wc -l <'$T/map.csv') = 31 ]"
tap_check "map at d~ = 0: |delta'| - |delta| = |2 atan(r tan(delta/2))| - delta" awk -F, '
	NR > 1 { e = 2 * atan2(0.5 * sin($2 / 2), cos($2 / 2)); e = (e < 0 ? -e : e) - $2;
		if ($2 < 3.14159 && ($4 - e)^2 > 1e-12) bad = 1; n++ } END { exit !(n == 30 && !bad) }' "$T/map.csv"

# ---- an amplitude of its own (--amplitude-rate R: the van der Pol limit cycle) ----
# A pair that collides once (d~ 0.3 from 1.0 rad): after the impact the
# body's swing (its peaks of |x|) returns to the cycle's, the difference
# shrinking as exp(-R t) once it is small (the linearised rate: from the
# first peak within 1 % of A to the next, within 5 %; 0.90 and 1.67 /s from
# the first peaks, where the difference is 17 % and 10 % of A); the cycle's
# own peak within 0.2 % of A (0.8). The impact itself moves no body (the
# phase model's jumps them back onto their cycle).
# peaks RUN: "t peak" of |x| of r1 after the last impact
peaks() { awk -F, -v after="$(awk -F, 'NR > 1 { t = $2 } END { print t }' "$1/collisions.csv")" '
	NR > 1 && $3 == "\"r1\"" { x = $6 < 0 ? -$6 : $6
		if (n >= 2 && px > x && px >= ppx && pt > after) printf "%.4f %.6f\n", pt, px
		ppx = px; px = x; pt = $2; n++ }' "$1/states.csv"; }
for R in 0.75 1.5; do
	"$M" pair --dsep 0.3 --delta0 1.0 --duration 20 --amplitude-rate $R --sample-hz 1000 --out "$T/amp$R" --quiet \
		>/dev/null 2>&1
	got=$(peaks "$T/amp$R" | awk '{ t[NR] = $1; p[NR] = $2 } END { last = p[NR]
		for (i = 1; i < NR - 1; i++) if (p[i] - last < 0.008) break
		d1 = p[i] - last; d2 = p[i + 1] - last
		if (!(d1 > 0 && d2 > 0)) { print "none none"; exit }
		printf "%.3f %.6f", log(d1 / d2) / (t[i + 1] - t[i]), last }')
	rate=${got% *} peak=${got#* }
	tap_check "amplitude rate $R: one impact, the swing back at rate $rate /s (5 %), the cycle's peak $peak (A 0.8, 0.2 %)" \
		awk -v r="$rate" -v p="$peak" -v R=$R 'BEGIN { exit !((r - R)^2 <= (0.05 * R)^2 && (p - 0.8)^2 <= (0.0016)^2) }'
done
tap_check "amplitude rate: the impact changes the speeds only (x_left, x_right continuous: the states' last sample before it and first after it within 2 ms of travel)" awk -F, '
	function abs(v) { return v < 0 ? -v : v }
	FNR == 1 { f++ } f == 1 && FNR == 2 { tc = $2 }
	f == 2 && FNR > 1 && $3 == "\"r1\"" { if ($2 <= tc) { xb = $6; vb = $7 } else if (xa == "") { xa = $6; va = $7 } }
	END { exit !(xa != "" && abs(xa - xb) <= 0.002 * (abs(va) + abs(vb)) + 1e-9) }' "$T/amp0.75/collisions.csv" "$T/amp0.75/states.csv"
tap_check "amplitude rate 1.5: anti-phase at d~ 0.7 locks (the kick of 0.05 rad gone)" bash -c "
	'$M' pair --dsep 0.7 --delta0 3.09159265358979 --duration 60 --amplitude-rate 1.5 --no-samples --out '$T/amp-anti' --quiet >/dev/null 2>&1 &&
	jq -e '.pairs[0].class == \"anti-phase\" and 3.14159265 - .pairs[0].mean_abs_delta < 1e-4 and .model.amplitude_rate == 1.5' '$T/amp-anti/summary.json' >/dev/null"

# ---- bad input: exit 2, a message naming the program, nothing written ----
refused() {
	local name=$1 out
	shift
	out=$("$M" "$@" --out "$T/bad" 2>&1 >/dev/null)
	local rc=$?
	if [ "$rc" = 2 ] && [[ "$out" == undulate-model:* ]] && [ ! -e "$T/bad" ]; then tap_ok "refused: $name"
	else tap_fail "refused: $name" "rc=$rc, message: ${out%%$'\n'*}"; fi
}
out=$("$M" 2>&1); rc=$?
tap_check "no subcommand: exit 2" test "$rc" = 2
refused "unknown subcommand" swim
refused "restitution above 1" pair --restitution 1.5
refused "restitution not a number" pair --restitution x
refused "negative separation" lattice --dsep -0.1
refused "no oscillators" lattice --n 0
refused "n not whole" lattice --n 2.5
refused "too many oscillators" lattice --n 100000
refused "beta: wrong count" lattice --n 4 --beta 0.1,0.2
refused "beta negative" lattice --beta -1
refused "phases: wrong count" lattice --n 3 --phases 0,1
refused "delta0 to lattice" lattice --delta0 1
refused "beta to pair" pair --beta 0.1
refused "unknown option" pair --colour red
refused "an option without its value" pair --dsep
refused "a stray argument" pair extra
refused "duration 0" pair --duration 0
refused "nan" pair --dsep nan
refused "map: --dsep and a range" map --dsep 0.2 --dsep-from 0.1
refused "amplitude rate negative" pair --amplitude-rate -1
refused "amplitude rate nan" pair --amplitude-rate nan
refused "amplitude rate too large" pair --amplitude-rate 2000
refused "amplitude rate to map" map --amplitude-rate 1
tap_check "a bad argument prints the usage" bash -c "'$M' pair --dsep x 2>&1 | grep -q '^usage: undulate-model pair'"
# --out: the analyser's rules (common/outdir.h): another user's or a world-writable directory
mkdir -p "$T/open" && chmod 0777 "$T/open"
"$M" pair --duration 1 --out "$T/open" --quiet >/dev/null 2>"$T/open.err"
rc=$?
tap_check "--out world-writable: exit 5, saying why" bash -c "[ $rc = 5 ] && grep -q 'writable by other users' '$T/open.err'"
tap_check "--out world-writable: nothing written" test ! -e "$T/open/summary.json"

tap_done
