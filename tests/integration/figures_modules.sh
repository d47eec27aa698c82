#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# run.sh: heavy — its lockstep runs keep a core busy (tests/run.sh)
# figures_modules.sh — the rows, channel, forces, forces-plane, swimmer and
# channel-plane modules of `make figures`
# (figures/<name>/fig.sh): their job lists are the same every time, with
# unique run names and seeds; bad arguments get one clear line and exit 2;
# each merge, on a fixed small set of result rows written here, writes its
# CSV, its pictures with the data drawn (the data colours' pixels counted by
# tests/tools/pngdata: a picture that exists is not a picture that shows
# data) and its fragment with the numbers those rows give; a merge without
# results or without gnuplot fails with a message; and the five modules'
# tiny set (FIG_TINY=1, 6 short lockstep runs, one of them from /) through the
# driver onto a page. Alone at load 6 it takes about 230 s, most of it the tiny
# set's lockstep runs; beside the rest of the suite on two cores it ran past
# the runner's 300 s default once:
# run.sh: timeout 600
. "$(dirname "$0")/../lib.sh"
F="$top/figures"
needs_plotting

# pixels COLOUR PNG: how many pixels of that colour (RRGGBB)
pixels() { "$PNG" --rgb "$1" "$2" 2>/dev/null | sed -n 's/.*matching=//p'; }
coloured() { "$PNG" "$1" 2>/dev/null | sed -n 's/.*coloured=//p'; }
# drawn CLAIM PNG COLOUR:MIN...: the picture shows its data: at least MIN
# pixels of each COLOUR (RRGGBB; "any": every coloured pixel), counted in
# the claim's TAP line.
drawn() {
	local claim=$1 png=$2 spec n got=() ok=1
	shift 2
	for spec in "$@"; do
		if [ "${spec%%:*}" = any ]; then n=$(coloured "$png"); else n=$(pixels "${spec%%:*}" "$png"); fi
		got+=("${n:-0}")
		[ "${n:-0}" -ge "${spec#*:}" ] || ok=0
	done
	if [ "$ok" = 1 ]; then tap_ok "$claim (${got[*]} pixels)"
	else tap_fail "$claim" "pixels of ${*%%:*}: ${got[*]}; at least ${*#*:} wanted"; fi
}
# merged MODULE: its merge of $T/runs/MODULE into $T/fig exits 0.
merged() {
	if "$F/$1/fig.sh" merge "$T/runs/$1" "$T/fig" >"$T/merge.out" 2>&1; then tap_ok "$1: merge"
	else tap_fail "$1: merge" "$(cat "$T/merge.out")"; fi
}
# section_has CLAIM MD SHOW LINE...: the section MD holds every LINE (a
# table row, "| ...", as it stands; anything else a grep pattern); if not,
# the failure shows MD's lines that match the extended pattern SHOW.
section_has() {
	local claim=$1 md=$2 show=$3 line
	shift 3
	for line in "$@"; do
		if [[ "$line" == "|"* ]]; then grep -qF -- "$line" "$md"; else grep -q -- "$line" "$md"; fi && continue
		tap_fail "$claim" "no line '$line' in: $(grep -E "$show" "$md")"
		return
	done
	tap_ok "$claim"
}
# csv_rows CSV N: the merge's CSV holds N rows under its header.
csv_rows() { tap_check "${1##*/}: $2 rows" test "$(wc -l <"$1")" = $(($2 + 1)); }
# result NAME DIR LINES...: a run folder with its result.csv
result() {
	local mod=$1 id=$2; shift 2
	mkdir -p "$T/runs/$mod/$id"
	printf '%s\n' "$@" >"$T/runs/$mod/$id/result.csv"
}

# ---- jobs ---------------------------------------------------------------------------
# the seed's field in a job line: the last but for forces (SLOPE SEED END),
# forces-plane (K SEED END WALLS) and channel-plane (WIDTH SEED ENDS)
for m in rows channel forces forces-plane swimmer channel-plane; do
	sf=NF; case $m in forces | forces-plane | channel-plane) sf=3 ;; esac
	a=$("$F/$m/fig.sh" jobs) b=$("$F/$m/fig.sh" jobs) q=$("$F/$m/fig.sh" jobs --quick)
	ids=$(awk '{ print $1 }' <<<"$a" | sort | uniq -d)
	bad=$(awk '$1 !~ /^[A-Za-z0-9_.-]+$/' <<<"$a")
	seeds=$(awk -v f="$sf" '{ print (f == "NF") ? $NF : $f }' <<<"$a" | sort | uniq -d)
	if [ -n "$a" ] && [ "$a" = "$b" ] && [ -z "$ids" ] && [ -z "$bad" ] && [ -z "$seeds" ] && [ -n "$q" ] &&
		[ "$(wc -l <<<"$q")" -lt "$(wc -l <<<"$a")" ]; then
		tap_ok "$m: $(wc -l <<<"$a") jobs ($(wc -l <<<"$q") quick), the same twice, unique names and seeds"
	else tap_fail "$m: jobs" "$(head -3 <<<"$a"); duplicate ids '$ids', bad '$bad', duplicate seeds '$seeds'"; fi
done

# ---- seeds: cksum's CRC, computed in the shell ------------------------------------------
# Every recorded run's seed came from `cksum`; figures/lib.sh computes the
# same CRC itself (no pipe per seed). Any other number would make the
# recorded runs irreproducible by their seeds.
diff=$(bash -c '. "$1/lib.sh"; for s in "" a "channel-plane 20 3" "rows 0.5 0 60 12" "forces-plane none 0.25 7" \
	"$(printf "caf\303\251 \001\377 %0300d" 0)"; do
	mine=$(fig_hash "$s") ref=$(printf "%s" "$s" | cksum | cut -d" " -f1)
	[ "$mine" = "$ref" ] || echo "\"$s\": $mine, cksum $ref"
done' _ "$F")
if [ -z "$diff" ]; then tap_ok "fig_hash is cksum's CRC (empty, ASCII, bytes above 127, 300+ bytes)"
else tap_fail "fig_hash is cksum's CRC" "$diff"; fi

# ---- a series only where it draws something ------------------------------------------
# gnuplot warns of a series with no points, and fig_gnuplot takes the
# warning for a failure: fig_series adds a series only when its CSV has a row
# (below the header) where the condition holds, the file named once.
printf 'x,y\n1,0\n2,5\n' >"$T/series.csv"
got=$(bash -c '. "$1/lib.sh"; s=("first")
	fig_series s "$2" "\$2 > 4" "using 1:2 title '"'"'big'"'"'"
	fig_series s "$2" "\$2 > 9" "using 1:2 title '"'"'none'"'"'"
	fig_series s "$2" 1 "using 1:(\$2 * 2)" || echo "status $?"
	printf "%s|" "${s[@]}"' _ "$F" "$T/series.csv" 2>&1)
want="first|'$T/series.csv' every ::1 using 1:2 title 'big'|'$T/series.csv' every ::1 using 1:(\$2 * 2)|"
if [ "$got" = "$want" ]; then tap_ok "fig_series: a series where its CSV has a matching row, none where not"
else tap_fail "fig_series: series where a row matches" "got '$got', want '$want'"; fi

# ---- bad arguments: one line, exit 2, nothing run --------------------------------
refused() { # NAME WANT CMD...
	local name=$1 want=$2 rc; shift 2
	"$@" >"$T/out" 2>"$T/err"; rc=$?
	if [ "$rc" = 2 ] && [ "$(wc -l <"$T/err")" = 1 ] && grep -q -- "$want" "$T/err"; then tap_ok "$name refused: $(cat "$T/err")"
	else tap_fail "$name refused (exit 2, one line with '$want')" "rc $rc: $(cat "$T/err" "$T/out" | head -3)"; fi
}
refused "forces: a slope of 999" "SLOPE: want a whole number from 2 to 254, got '999'" "$F/forces/fig.sh" run "$T/bad" 999 1
refused "rows: d~ abc" "DSEP: want a number" "$F/rows/fig.sh" run "$T/bad" abc 0 60 1
refused "rows: 5 s (shorter than the switch and the window)" "SECONDS: want a whole number from 14" "$F/rows/fig.sh" run "$T/bad" 0.5 0 5 1
refused "channel: width 0" "WIDTH_CM: want a number from 5 to 60" "$F/channel/fig.sh" run "$T/bad" 0 1
refused "channel: missing seed" "run OUTDIR WIDTH_CM SEED" "$F/channel/fig.sh" run "$T/bad" 20
refused "channel-plane: width 50" "WIDTH_CM: want a number from 10 to 40" "$F/channel-plane/fig.sh" run "$T/bad" 50 1
refused "channel-plane: ends 'open'" "ENDS: want ends or none" "$F/channel-plane/fig.sh" run "$T/bad" 20 1 open
refused "swimmer: mode 'clock'" "MODE: want oscillator or sinusoid" "$F/swimmer/fig.sh" run "$T/bad" clock 20 1
refused "swimmer: 5 s (shorter than settling and the picture)" "SECONDS: want a whole number from 12" "$F/swimmer/fig.sh" run "$T/bad" oscillator 5 1
refused "forces-plane: k 2" "K: want a number from 0 to 1, got '2'" "$F/forces-plane/fig.sh" run "$T/bad" 2 1
refused "forces-plane: walls 0.1 m" "WALLS: want a number from 0.3 to 2" "$F/forces-plane/fig.sh" run "$T/bad" 0.1 1 150 0.1
refused "an unknown subcommand" "usage: fig.sh" "$F/rows/fig.sh" draw
[ ! -e "$T/bad" ] && tap_ok "no run folder made by a refused run" || tap_fail "no run folder made by a refused run"
# FIG_ROWS_ARGS reaches demo.sh after the module's own words: a word demo.sh
# does not know stops the run there, before anything starts
FIG_ROWS_ARGS="--daemon-set robot.period_ms=5 --no-such-word" "$F/rows/fig.sh" run "$T/hook" 0.5 0 14 1 >"$T/out" 2>"$T/err"
rc=$?
if [ "$rc" = 1 ] && grep -q "demo: unknown argument '--no-such-word'" "$T/err"; then tap_ok "rows: FIG_ROWS_ARGS's words go to demo.sh ($(head -c 160 "$T/err"))"
else tap_fail "rows: FIG_ROWS_ARGS's words go to demo.sh (exit 1, demo.sh refusing the unknown word)" "rc $rc: $(cat "$T/err" "$T/out" | head -3)"; fi

# ---- forces: merge on fixed rows -----------------------------------------------------
H="slope,stiffness_nm_rad,seed,lead_s,k,sin_amplitude,sin_frequency,force_clock_n,force_osc_n,mean_clock_n,mean_osc_n,pair_impacts_clock_hz,pair_impacts_osc_hz,wall_impacts_clock_hz,wall_impacts_osc_hz,min_swing_rad,wall_s,end_s"
i=0
for row in "16,17.7,1,0.02,0.07,0.8,0.8,30,4" "16,17.7,2,0.02,0.07,0.8,0.8,34,6" "16,17.7,3,0.02,0.07,0.8,0.8,40,5" \
	"32,8.87,1,0.026,0.075,0.8,0.8,25,5" "32,8.87,2,0.026,0.075,0.8,0.8,27,7" \
	"64,4.43,1,0.05,0.03,0.8,0.8,22,4" "128,2.22,1,0.11,0.017,0.82,0.81,20,4.4" "128,2.22,2,0.11,0.017,0.82,0.81,22,4"; do
	i=$((i + 1))
	result forces "r$i" "$H" "$row,30,5,190,170,60,30,1.4,95,300"
	# the force per second: walls closing 10-100 s, clock, then the oscillator
	awk -v c="${row#*,*,*,*,*,*,*,}" 'BEGIN { split(c, v, ","); print "t,force_n,impacts,pair_impacts,wall_impacts"
		for (t = 0; t < 300; t++) { f = t < 10 ? 1 : (t < 100 ? 1 + (v[1] - 1) * (t - 10) / 90 : (t < 200 ? v[1] : v[2]))
			printf "%d,%g,10,8,2\n", t, f } }' >"$T/runs/forces/r$i/series.csv"
done
merged forces
drawn "forces.png: both series drawn (clock, oscillator)" "$T/fig/forces.png" d62728:400 1f77b4:400
drawn "forces_time.png: four runs' forces drawn (coloured)" "$T/fig/forces_time.png" any:3000
# slope 16: clock 30, 34, 40 -> median 34 (30-40); oscillator 4, 6, 5 -> 5; 6.8x
section_has "forces.md: the medians per slope with their ranges and ratios, the picture linked" "$T/fig/forces.md" '^\|' \
	'| 16 | 17.7 | 3 | 0.02, 0.07 | 34 (30-40) | 5 (4-6) | 6.8x |' \
	'| 128 | 2.22 | 2 | 0.11, 0.017 | 21 (20-22) | 4.2 (4-4.4) | 5.0x |' \
	'^!\[.*\](figures/forces.png)' \
	'median over 100-200 s (clock)'
csv_rows "$T/fig/forces.csv" 8

# ---- forces-plane: merge on fixed rows ---------------------------------------------------
# Two k, two whole runs each and one broken run (left out of the medians, counted).
H="k_nm_rad,seed,end_s,walls_m,damping,median_clock_n,median_osc_n,contacts_clock,contacts_osc,mean_clock_n,mean_osc_n,broken,min_swing_rad,wall_s,walls_end_m"
i=0
for row in "0.015,1,150,0.6,0.01,0.8,0.4,5000,3000,3.0,1.4,0,1.2,400,0.6" "0.015,2,150,0.6,0.01,0.9,0.5,5100,2900,3.1,1.5,0,1.1,410,0.6" \
	"0.135,1,150,0.6,0.01,0.5,0.05,6000,900,13,3.3,0,1.3,420,0.61" "0.135,2,150,0.6,0.01,0.6,0.07,6100,800,14,3.4,0,1.25,430,0.6" \
	"0.135,3,150,0.6,0.01,9,9,6000,6000,40,40,1,0.1,440,0.44"; do
	i=$((i + 1))
	result forces-plane "p$i" "$H" "$row"
	# the force per second: walls closing 10-50 s, clock to 100 s, then the oscillator
	awk -v c="$row" 'BEGIN { split(c, v, ","); print "t,force_n,pair_impacts,wall_impacts"
		for (t = 0; t < 150; t++) { f = t < 50 ? 0.5 + v[10] * t / 50 : (t < 100 ? v[10] : v[11])
			printf "%d,%g,8,2\n", t, f } }' >"$T/runs/forces-plane/p$i/series.csv"
done
merged forces-plane
drawn "forces-plane.png: both series drawn (clock, oscillator)" "$T/fig/forces-plane.png" d62728:400 1f77b4:400
drawn "forces-plane_time.png: a run per k drawn (k 0.015, k 0.135)" "$T/fig/forces-plane_time.png" 9467bd:300 1f77b4:300
section_has "forces-plane.md: per k the runs' medians with their ranges and ratios, the broken run left out and counted" "$T/fig/forces-plane.md" '^\||broken|above' \
	'| 0.015 | 2 | 0 | 0.85 (0.8-0.9) | 0.45 (0.4-0.5) | 1.9x | 3.05 → 1.45 (2.1x) | 5050 → 2950 (1.7x) |' \
	'a simulator behind): 1, left out of the medians' \
	'(1 of 2 k above 0.1 N); the clock.s median goes from 0.85 N at k 0.015 to 0.55 N at k 0.135' \
	'| 0.135 | 2 | 1 | 0.55 (0.5-0.6) | 0.06 (0.05-0.07) | 9.2x | 13.5 → 3.35 (4.0x) | 6050 → 850 (7.1x) |' \
	'^!\[.*\](figures/forces-plane.png)'
csv_rows "$T/fig/forces-plane.csv" 5

# ---- rows: merge on fixed rows ---------------------------------------------------------
H="dsep,beta,seconds,seed,pairs,colliding_pairs,pair_collisions_hz,compat_error_rad,compat_error_max_rad,compatible_pairs,antiphase_pairs,stopped_pairs,wall_collisions_hz,relax_s,censored,min_swing_rad,wall_s"
i=0
for row in "0.1,0,60,1,9,0,0,0,0,9,0,0,0,20,0,1.6,14" "0.5,0,60,1,9,5,0.8,0.3,1.1,4,3,0,0,55,1,1.5,14" \
	"0.5,0,60,2,9,3,0.6,0.1,0.9,6,1,0,0,55,1,1.5,14" "0.9,0,60,1,9,6,0.9,0.5,1.2,3,4,0,0,57,1,1.4,14" \
	"0.1,0.1,60,1,9,0,0,0,0,9,0,0,0,12,0,1.6,14" "0.5,0.1,60,1,9,0,0,0,0,9,0,0,0,9,0,1.6,14" \
	"0.9,0.1,60,1,9,0,0,0,0,9,0,0,0,4,0,1.6,14" "0.78,0.1,240,1,9,0,0,0,0,9,0,0,0,8,0,1.6,50" \
	"0.78,0.02,240,1,9,0,0,0,0,9,0,0,0,30,0,1.6,50" "0.78,0.005,240,1,9,0,0,0,0,9,0,0,0,90,0,1.6,50" \
	"0.78,0.005,240,2,9,1,0.1,0,0,8,0,0,0,236,1,1.6,50"; do
	i=$((i + 1))
	result rows "r$i" "$H" "$row"
done
merged rows
drawn "rows.png: immobile and mobile drawn" "$T/fig/rows.png" d62728:600 1f77b4:400
drawn "rows_relax.png: relaxed runs and the censored one drawn" "$T/fig/rows_relax.png" 1f77b4:300 d62728:60
section_has "rows.md: means per d~ and beta, relaxation per beta with the censored run counted as the longest, pairs colliding per d~ beside the paper" "$T/fig/rows.md" '^\|' \
	'| 0.5 | 0 | 2 | 0.7 | 0.2 | 8 of 18 | 10 of 18 | 4 |' \
	'| 0.005 | 2 | 1 of 2 | 90, > 237 | > 237 |' \
	'| 0.1 | 1 | 1 of 1 | 8 | 8 |' \
	'immobile 0.1: 0 of 9, 0.5: 8 of 18, 0.9: 6 of 9; mobile 0.1: 0 of 9'

# ---- channel: merge on fixed rows ----------------------------------------------------
H="width_cm,nominal_dsep,seed,pair,class,mean_delta,mean_abs_delta,spread,window_collisions,collisions,impulse,distance_m,dsep,compat_limit,swing_a,swing_b,min_swing_rad,wall_s"
result channel a "$H" "16,0.5362,1,r1:r2,compatible,1.0,1.0,0.1,0,30,3,0.16,0.55,1.1645,1.6,1.6,1.5,6" \
	"16,0.5362,1,r2:r3,still-colliding,-1.2,1.2,0.2,3,40,3,0.17,0.57,1.2130,1.6,1.6,1.5,6" \
	"16,0.5362,1,r3:r4,in-phase,0.1,0.1,0.1,0,20,2,0.15,0.50,1.0472,1.6,1.6,1.5,6"
result channel b "$H" "16,0.5362,2,r1:r2,compatible,0.8,0.8,0.1,0,30,3,0.16,0.52,1.0940,1.6,1.6,1.5,6" \
	"16,0.5362,2,r2:r3,anti-phase,3.1,3.1,0.1,9,90,9,0.17,0.60,1.2870,1.6,1.6,1.5,6" \
	"16,0.5362,2,r3:r4,compatible,-0.9,0.9,0.1,0,20,2,0.15,0.57,1.2130,1.6,1.6,1.5,6"
result channel c "$H" "24,0.8043,1,r1:r2,compatible,1.5,1.5,0.1,0,30,3,0.24,0.80,1.8546,1.6,1.6,1.5,6" \
	"24,0.8043,1,r2:r3,compatible,1.7,1.7,0.1,0,40,3,0.25,0.84,1.9736,1.6,1.6,1.5,6" \
	"24,0.8043,1,r3:r4,compatible,-1.6,1.6,0.1,0,20,2,0.23,0.78,1.7926,1.6,1.6,1.5,6"
merged channel
drawn "channel.png: both widths' pairs drawn (16 cm, 24 cm)" "$T/fig/channel.png" 1f77b4:150 2ca02c:80
section_has "channel.md: per width the pairs at or below 2 asin(d~), anti-phase counted" "$T/fig/channel.md" '^\||In all' \
	'| 16 cm | 0.54 | 6 | 0.56 (0.50-0.60) | 0.95 rad | 5 of 6 | 1 | 2 |' \
	'In all: 8 of 9 pairs ended at or below the compatibility bound .*, 1 in anti-phase'

# ---- channel-plane: merge on fixed rows --------------------------------------------------
H="width_cm,nominal_dsep,seed,pair,class,mean_delta,mean_abs_delta,spread,window_collisions,collisions,impulse,distance_m,dsep,compat_limit,swing_a,swing_b,dy_m,sweep_a_m,sweep_b_m,min_swing_rad,wall_s,ends"
result channel-plane w16cm-t1 "$H" "16,0.5362,1,r1:r2,compatible,1.0,1.0,0.1,0,30,3,0.16,0.55,1.1645,1.6,1.6,0.01,0.30,0.32,1.5,20,ends" \
	"16,0.5362,1,r2:r3,still-colliding,-1.2,1.2,0.2,3,40,3,0.17,0.57,1.2130,1.6,1.6,0.02,0.32,0.34,1.5,20,ends" \
	"16,0.5362,1,r3:r4,in-phase,0.1,0.1,0.1,0,20,2,0.15,0.50,1.0472,1.6,1.6,0.03,0.34,0.36,1.5,20,ends"
result channel-plane w16cm-t2 "$H" "16,0.5362,2,r1:r2,compatible,0.8,0.8,0.1,0,30,3,0.16,0.52,1.0940,1.6,1.6,0.01,0.30,0.30,1.5,22,ends" \
	"16,0.5362,2,r2:r3,anti-phase,3.1,3.1,0.1,9,90,9,0.17,0.60,1.2870,1.6,1.6,0.01,0.30,0.30,1.5,22,ends" \
	"16,0.5362,2,r3:r4,compatible,-0.9,0.9,0.1,0,20,2,0.15,0.57,1.2130,1.6,1.6,0.01,0.30,0.30,1.5,22,ends"
result channel-plane w24cm-t1 "$H" "24,0.8043,1,r1:r2,compatible,1.5,1.5,0.1,0,30,3,0.24,0.80,1.8546,1.6,1.6,0.01,0.30,0.30,1.5,18,ends" \
	"24,0.8043,1,r2:r3,compatible,1.7,1.7,0.1,0,40,3,0.25,0.84,1.9736,1.6,1.6,0.01,0.30,0.30,1.5,18,ends" \
	"24,0.8043,1,r3:r4,compatible,-1.6,1.6,0.1,0,20,2,0.23,0.78,1.7926,1.6,1.6,0.01,0.30,0.30,1.5,18,ends"
result channel-plane noends-w20cm-t1 "$H" "20,0.6702,5,r1:r2,compatible,0.5,0.5,0.1,0,10,1,0.2,0.6,1.2870,1.6,1.6,0.10,0.3,0.3,1.5,18,none" \
	"20,0.6702,5,r2:r3,compatible,0.6,0.6,0.1,0,10,1,0.2,0.6,1.2870,1.6,1.6,0.05,0.3,0.3,1.5,18,none" \
	"20,0.6702,5,r3:r4,still-colliding,2.0,2.0,0.1,2,10,1,0.2,0.6,1.2870,1.6,1.6,0.20,0.3,0.3,1.5,18,none"
# the frames of the narrowest and the widest run: four straight robots a width apart, walls
for id in w16cm-t1 w24cm-t1; do
	w=${id#w}; w=${w%%cm*}
	awk -v w="$w" 'BEGIN { print "moment,kind,index,x,y,angle_or_bx,length_or_by,robot_index"; d = w / 100
		n = split("2 5 15 32", m, " ")
		for (i = 1; i <= n; i++) {
			for (r = 0; r < 4; r++) for (k = 0; k < 3; k++)
				printf "%s,link,%d,%.4f,%.4f,1.5708,0.1865,%d\n", m[i], k, (r - 1.5) * d, 0.1865 * (1 - k), r
			printf "%s,wall,0,%.3f,-0.305,%.3f,0.305,-1\n", m[i], -2 * d, -2 * d
			printf "%s,wall,1,%.3f,-0.305,%.3f,0.305,-1\n", m[i], 2 * d, 2 * d
		} }' >"$T/runs/channel-plane/$id/frames.csv"
done
merged channel-plane
drawn "channel-plane.png: both widths' pairs and the control drawn (16 cm, 24 cm, control)" "$T/fig/channel-plane.png" \
	1f77b4:150 2ca02c:80 888888:40
# gnuplot's first four line colours: one robot each
drawn "channel-plane-frames.png: the robots drawn in eight panels (robots 1 and 4)" "$T/fig/channel-plane-frames.png" \
	9400d3:400 e69f00:400
section_has "channel-plane.md: per width the pairs at or below 2 asin(d~), anti-phase counted, the control apart" "$T/fig/channel-plane.md" '^\||In all|Without' \
	'| 16 cm | 0.54 | 6 | 0.56 (0.50-0.60) | 0.95 rad | 5 of 6 | 1 | 1 | 2 |' \
	'In all: 8 of 9 pairs ended at or below the compatibility curve .*, 1 in anti-phase, 1 more than 2π/3 apart' \
	'Without end walls.* 2 of 3 pairs ended at or below the curve, 0 in anti-phase, 1 still touched.* 0.100 m apart along the channel (median; up to 0.200 m), against 0.010 m with the ends' \
	'^!\[.*\](figures/channel-plane-frames.png)'
csv_rows "$T/fig/channel-plane.csv" 12

# ---- swimmer: merge on fixed rows ---------------------------------------------------------
H="mode,seed,seconds,freq1_hz,freq2_hz,amp1_rad,amp2_rad,lag_rad,lag_spread_rad,along_per_period_m,across_per_period_m,speed_m_s,turn_rad,periods,min_swing_rad,wall_s,sweep_m"
result swimmer oscillator-s1 "$H" "oscillator,1,30,0.82,0.82,0.80,0.81,1.80,0.3,0.0140,0.0001,0.0115,0.2,20.5,1.6,10,0.18"
result swimmer oscillator-s2 "$H" "oscillator,2,30,0.82,0.82,0.80,0.81,1.78,0.3,0.0146,-0.0001,0.0120,-0.3,20.5,1.6,10,0.20"
result swimmer sinusoid-s1 "$H" "sinusoid,3,30,0.824,0.824,0.80,0.80,2.09,0.04,0.0116,0,0.0095,0.25,20.6,1.6,10,0.17"
for id in oscillator-s1 oscillator-s2 sinusoid-s1; do
	d="$T/runs/swimmer/$id"
	awk 'BEGIN { print "t,joint1_rad,joint2_rad"; for (i = 0; i <= 500; i++) { t = 25 + i / 100
		printf "%.2f,%.4f,%.4f\n", t, 0.8 * cos(5.15 * t), 0.8 * cos(5.15 * t - 2.09) } }' >"$d/joints.csv"
	awk 'BEGIN { print "t,x,y,heading"; for (i = 0; i <= 300; i++) printf "%.1f,0,%.4f,1.5708\n", i / 10, 0.012 * i / 10 }' >"$d/path.csv"
	awk 'BEGIN { print "utime,t,robot,robot_index,link,x,y,angle,length,width,centre_x,centre_y,heading"
		for (t = 0; t <= 30; t += 5) for (k = 0; k < 3; k++)
			printf "0,%d,\"r1\",0,%d,0,%.4f,1.5708,0.1865,0.032,0,%.4f,1.5708\n", t, k, 0.012 * t + 0.1865 * (1 - k), 0.012 * t }' >"$d/body.csv"
done
merged swimmer
drawn "swimmer.png: both joints' angles and the centre's path drawn (joint 1, joint 2, path)" "$T/fig/swimmer.png" \
	1f77b4:1000 ff7f0e:1000 d62728:100
section_has "swimmer.md: per mode the gait, the lag and the swim per period, the lag beside the paper's 2 pi / 3" "$T/fig/swimmer.md" '^\||Beside' \
	'| oscillator | 2 | 0.820 / 0.820 | 0.800 / 0.810 | 1.79 rad (103°) | 1.43 cm (1.40-1.46) | 0.00 cm | 1.18 cm/s | 0.25 rad | 0.190 m |' \
	'| clock | 1 | 0.824 / 0.824 | 0.800 / 0.800 | 2.09 rad (120°) | 1.16 cm (1.16-1.16) | 0.00 cm | 0.95 cm/s | 0.25 rad | 0.170 m |' \
	'with joint 2 1.79 rad (103°) behind joint 1 (2π/3: 2.09 rad)' \
	'sweeps 0.190 m across its heading per period (.*0.222 m with'
csv_rows "$T/fig/swimmer.csv" 3

# ---- no results, no gnuplot ----------------------------------------------------------------
mkdir -p "$T/empty"
"$F/rows/fig.sh" merge "$T/empty" "$T/fig2" >"$T/out" 2>&1; rc=$?
if [ "$rc" = 1 ] && grep -q "^rows: no run in .* has a result.csv: nothing to draw" "$T/out"; then tap_ok "merge without results: exit 1, said so"
else tap_fail "merge without results" "rc $rc: $(cat "$T/out")"; fi
# a PATH of everything but gnuplot: links to every program, the first
# directory's winning as in PATH (made last, -f), in three processes
mkdir -p "$T/path"
for d in /bin /usr/bin /usr/local/bin; do
	[ -d "$d" ] && find "$d" -maxdepth 1 ! -type d ! -name gnuplot -exec ln -sf -t "$T/path" {} + 2>/dev/null
done
PATH="$T/path" "$F/forces/fig.sh" merge "$T/runs/forces" "$T/fig2" >"$T/out" 2>&1; rc=$?
if [ "$rc" = 1 ] && grep -q "gnuplot is not installed" "$T/out" && [ ! -e "$T/fig2/forces.png" ]; then tap_ok "merge without gnuplot: exit 1, said so"
else tap_fail "merge without gnuplot" "rc $rc: $(cat "$T/out")"; fi

# ---- the tiny set through the driver: the channel's run from /, the rest by the driver -----
# (FIG_TINY=1: one channel run, 32 s of four robots; two rows of ten robots, 14 and 16 s,
# the first immobile, so the mobile series are left out; one force run, 60 s after the
# tuner's 150 s of one robot; one swimmer run, 12 s of one plane robot; one channel-plane
# run, 32 s of four plane robots.) The channel's run is the tiny set's own, made from / into
# the runs' folder first: the driver's --resume keeps it and runs the other three.
if [ -x "$B/undulate-sim" ] && [ -x "$B/undulated" ] && [ -x "$B/undulate-analyze" ] && command -v parallel >/dev/null 2>&1; then
	export FIG_TINY=1 FIG_PORT_LO FIG_PORT_SPAN=8
	FIG_PORT_LO=$(lcm_port 7910)
	read -r id w seed <<<"$("$F/channel/fig.sh" jobs)"
	R="$T/tiny/runs"
	start=$(date +%s)
	(cd / && "$F/channel/fig.sh" run "$R/channel/$id" "$w" "$seed") >"$T/real.out" 2>&1; rc=$?
	r="$R/channel/$id/result.csv"
	if [ "$rc" = 0 ] && [ "$(wc -l <"$r")" = 4 ] &&
		awk -F, 'NR > 1 && !($13 > 0.1 && $13 < 2 && $14 > 0 && $15 > 0.2 && $16 > 0.2) { bad = 1 } END { exit bad }' "$r"; then
		tap_ok "channel: a real run from / in $(($(date +%s) - start)) s: three pairs with d~, bound and swings ($(awk -F, 'NR > 1 { printf "%s %s d~ %.2f; ", $4, $5, $13 }' "$r"))"
	else tap_fail "channel: a real run" "rc $rc: $(cat "$T/real.out"; cat "$r" 2>/dev/null)"; fi
	if [ ! -e "$R/channel/$id/demo/demo.lcmlog" ] && [ ! -e "$R/channel/$id/demo/states.csv" ] && [ -f "$R/channel/$id/demo/summary.json" ]; then
		tap_ok "the run's LCM log and sample tables removed, its summary kept"
	else tap_fail "large files removed" "$(ls "$R/channel/$id/demo" 2>&1 | tr '\n' ' ')"; fi
	"$top/scripts/figures.sh" --only rows,channel,forces,swimmer,channel-plane --resume --jobs 2 --runs "$R" \
		--out "$T/tiny/docs" >"$T/tiny.out" 2>&1; rc=$?
	if [ "$rc" = 0 ] && grep -q '5/5 runs done' "$T/tiny.out"; then tap_ok "the tiny set through the driver: 5 runs more, exit 0"
	else tap_fail "the tiny set through the driver" "rc $rc: $(tail -n 8 "$T/tiny.out")"; fi
	P="$T/tiny/docs/FIGURES.md" G="$T/tiny/docs/figures"
	order=$(grep -o '^<a id="[a-z-]*">' "$P" 2>/dev/null | tr -dc 'a-z\n-' | sed 's/^aid//' | tr '\n' ' ')
	if [ "$order" = "rows channel swimmer channel-plane forces " ] && grep -qE '^\| \[rows\]\(#rows\) \| 2 \(0\) \|' "$P" &&
		grep -qE '^\| \[channel\]\(#channel\) \| 1 \(0\) \|' "$P" && grep -qE '^\| \[forces\]\(#forces\) \| 1 \(0\) \|' "$P" &&
		grep -qE '^\| \[swimmer\]\(#swimmer\) \| 1 \(0\) \|' "$P" && grep -qE '^\| \[channel-plane\]\(#channel-plane\) \| 1 \(0\) \|' "$P"; then
		tap_ok "FIGURES.md: the five sections in the page's order, each in the header's table with its runs"
	else tap_fail "FIGURES.md: the five sections and the table" "order '$order': $(grep '^| \[' "$P" 2>&1)"; fi
	red=$(pixels d62728 "$G/rows.png") blue=$(pixels 1f77b4 "$G/rows.png")
	if [ "${red:-0}" -ge 60 ] && [ "${blue:-0}" = 0 ]; then tap_ok "rows.png: the immobile run drawn ($red pixels), the empty mobile series left out"
	else tap_fail "rows.png: immobile drawn, mobile left out" "immobile $red, mobile $blue pixels"; fi
	drawn "rows_relax.png: the censored relaxation run drawn" "$G/rows_relax.png" d62728:60
	drawn "forces_time.png: the run's force per second drawn (coloured)" "$G/forces_time.png" any:500
	# the plane modules' real runs: a gait near the tuned 0.8 Hz and 0.8 rad, the robot
	# swimming head first; four robots drawn from the run's own frames
	s="$R/swimmer/oscillator-t0/result.csv"
	if awk -F, 'NR == 2 { exit !($4 > 0.7 && $4 < 0.95 && $6 > 0.7 && $6 < 0.9 && $8 > 1.2 && $8 < 2.4 && $10 > 0.005 && $17 > 0.1 && $17 < 0.3) }' "$s" 2>/dev/null; then
		tap_ok "swimmer: a real run: $(awk -F, 'NR == 2 { printf "%.2f Hz, %.2f rad, joint 2 %.0f deg behind, %.2f cm a period, %.3f m wide", $4, $6, $8 * 57.2958, 100 * $10, $17 }' "$s")"
	else tap_fail "swimmer: a real run's gait and swim" "$(cat "$s" 2>&1)"; fi
	drawn "swimmer.png: the run's joints and path drawn" "$G/swimmer.png" 1f77b4:1000 d62728:20
	c="$R/channel-plane/w20cm-t0"
	if [ "$(wc -l <"$c/result.csv" 2>/dev/null)" = 4 ] && awk -F, 'NR > 1 && !($13 > 0.05 && $13 < 2 && $15 > 0.2 && $16 > 0.2 && $18 > 0.1 && $22 == "ends") { bad = 1 } END { exit bad }' "$c/result.csv" &&
		[ "$(grep -c ',link,' "$c/frames.csv")" = 48 ] && [ ! -e "$c/demo/plane.csv" ]; then
		tap_ok "channel-plane: a real run: three pairs with d~, bound, swings and sweeps; 48 links in its frames; plane.csv removed"
	else tap_fail "channel-plane: a real run" "$(cat "$c/result.csv" 2>&1 | head -4); $(grep -c ',link,' "$c/frames.csv" 2>&1) links"; fi
	drawn "channel-plane-frames.png: the run's robots drawn (one robot's colour)" "$G/channel-plane-frames.png" 9400d3:100
else
	tap_skip "the tiny set through the driver" "the programs or GNU parallel are missing"
fi
tap_done
