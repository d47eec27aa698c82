#!/usr/bin/env bash
# figures/swimmer/fig.sh — one three-link robot's joint motion (the paper's
# Fig. 8b) in the plane world, through the real daemon in lockstep: the two
# joints' angles over a few periods, their frequency, amplitude and the lag
# of joint 2 behind joint 1; and how the robot swims (a Purcell swimmer in
# drag): how far its centre moves along its heading per period.
#
#   fig.sh jobs [--quick]                 one line per run: RUN_ID MODE SECONDS SEED
#   fig.sh run OUTDIR MODE SECONDS SEED   one run: OUTDIR/result.csv (one row),
#                                         joints.csv, path.csv, body.csv
#   fig.sh tune OUT.conf [SEED]           the tuner in lockstep on this robot: a new
#                                         figures/plane-oscillator.conf (fig_plane_tune)
#   fig.sh merge RUNS_DIR FIGDIR          FIGDIR/swimmer.csv, swimmer.png, swimmer.md
#   fig.sh seconds [--quick]              wall seconds of one run on the 2-core machine
#
# The robot: sim-bridge/scenarios/plane-swimmer.scenario (two AX-12A joints
# on position servos, links of 18.65 cm, drag on every link, no walls), the
# daemon with the oscillator tuned for it (figures/plane-oscillator.conf,
# made by `undulated --tune` in lockstep: figures/lib.sh, fig_plane_tune).
# MODE oscillator runs the limit cycle from the start, its joints at the lag
# their coupling gives (lambda 1.5 / -0.5 on the other joint's angle, turned
# by coupling_phase +-0.30 rad to the paper's 2 pi / 3); MODE sinusoid runs
# the daemon's clock at the gait the tuner measured, with the paper's lag of
# 2 pi / 3 between the joints (DESIGN.md: x_j = A sin(phi + (2 pi / 3)(j - 1)
# - 2 pi f t)). The seed sets the robot's random start (initial_spread
# 0.3 rad). The numbers come from the steady part: the analyser's over the
# last SECONDS - SETTLE s, the centre's path from SETTLE s to the end.
source "$(dirname "$0")/../lib.sh"
fig_init swimmer

MODES="oscillator sinusoid"
SECONDS_FULL=30
SECONDS_QUICK=20
SECONDS_TINY=12
SEEDS=3
# After the daemon's 1.5 s ramp the gait settles within two periods; the
# path and the window start here.
SETTLE=5
# What the picture shows of a run: its joints over the last SHOW s (four
# periods at 0.82 Hz); its body every BODY_EVERY s.
SHOW=5
BODY_EVERY=5

jobs() {
	local secs=$SECONDS_FULL seeds=$SEEDS
	[ "${1:-}" = --quick ] && secs=$SECONDS_QUICK seeds=1
	if [ "${FIG_TINY:-0}" = 1 ]; then echo "oscillator-t0 oscillator $SECONDS_TINY $(fig_seed swimmer tiny)"; return; fi
	fig_grid '{v}-s{i}' "$MODES" "$seeds" swimmer '{v}' "$secs" '{seed}'
}

# json_joint SUMMARY J KEY: a joint's number in the analyser's summary.json
json_joint() { jq -r ".robots[0].joints[$2].$3 // \"nan\"" "$1"; }

run() {
	[ $# -eq 4 ] || fig_usage "run OUTDIR MODE SECONDS SEED"
	local out=$1 mode=$2 secs=$3 seed=$4
	case "$mode" in oscillator|sinusoid) ;; *) fig_usage "MODE: want oscillator or sinusoid, got '$mode'" ;; esac
	fig_uint SECONDS "$secs" $((SETTLE + SHOW + 2)) 3600
	fig_uint SEED "$seed" 1 999999999
	local sets
	mapfile -t sets < <(fig_plane_sets) && [ ${#sets[@]} -gt 0 ] || exit 1
	fig_run_start "$out"
	out=$FIG_RUN
	local r="$out/demo"
	fig_demo "$out" --scenario "$fig_top/sim-bridge/scenarios/plane-swimmer.scenario" --seconds "$secs" \
		--start-mode "$mode" --switch-at never --seed "$seed" --window $((secs - SETTLE)) "${sets[@]}" || exit 1
	[ -s "$r/plane.csv" ] || fig_die "the run's analysis has no plane.csv (a plane world's log gives one)"
	outdir_new "$out/joints.csv" "$out/path.csv" "$out/body.csv" "$out/result.csv" || fig_die "cannot write in $out"
	# the joints' angles over the last SHOW s, one row per sample
	awk -F, -v from=$((secs - SHOW)) 'NR > 1 && $2 >= from && ($4 == 0 || $4 == 1) {
			if ($1 != u) { if (u != "") print t "," a[0] "," a[1]; u = $1; t = $2; a[0] = a[1] = "" }
			a[$4] = $6 }
		END { if (u != "") print t "," a[0] "," a[1] }' "$r/states.csv" |
		{ echo "t,joint1_rad,joint2_rad"; cat; } >"$out/joints.csv"
	# the centre's path (10 poses a second) and the links over the last SHOW s
	awk -F, 'NR > 1 && $5 == 0 { print $2 "," $11 "," $12 "," $13 }' "$r/plane.csv" |
		{ echo "t,x,y,heading"; cat; } >"$out/path.csv"
	awk -F, -v every="$BODY_EVERY" 'NR == 1 { print; next } { k = $2 / every; if (k - int(k + 0.001) < 0.001) print }' \
		"$r/plane.csv" >"$out/body.csv"
	local f1 f2 a1 a2 lag spread swing wall
	f1=$(json_joint "$r/summary.json" 0 frequency_hz) f2=$(json_joint "$r/summary.json" 1 frequency_hz)
	a1=$(json_joint "$r/summary.json" 0 amplitude_rad) a2=$(json_joint "$r/summary.json" 1 amplitude_rad)
	# joint 2 behind joint 1: the analyser's joints pair r1/0:1 has
	# Δ = φ(joint 2) − φ(joint 1), negative when joint 2 lags
	lag=$(jq -r '[.pairs[] | select(.kind == "joints")][0].mean_delta // "nan" | if type == "number" then -. else . end' "$r/summary.json")
	spread=$(jq -r '[.pairs[] | select(.kind == "joints")][0].spread // "nan"' "$r/summary.json")
	swing=$(fig_min_swing "$r/summary.json")
	wall=$(fig_wall)
	# the swim from SETTLE s to the end: the centre's displacement along the
	# mean heading and across it, per period of the joints' mean frequency
	# how wide the swimming body is: per period from SETTLE s, the span of
	# its links' ends (their centre lines) across the period's mean heading;
	# the median over the whole periods. The row's d̃ takes a contact body
	# to sweep 2 x lever x A = 0.298 m at 0.8 rad.
	local sweep
	sweep=$(awk -F, -v from="$SETTLE" -v f1="$f1" -v f2="$f2" 'NR > 1 && $2 >= from && f1 + f2 > 0 {
			per = 2 / (f1 + f2); w = int(($2 - from) / per); n[w]++; hs[w] += $13
			k++; W[k] = w; X[k] = $6; Y[k] = $7; A[k] = $8; L[k] = $9 }
		END {
			for (i = 1; i <= k; i++) {
				w = W[i]; h = hs[w] / n[w]
				for (s = -1; s <= 1; s += 2) {
					p = -(X[i] + s * L[i] / 2 * cos(A[i])) * sin(h) + (Y[i] + s * L[i] / 2 * sin(A[i])) * cos(h)
					if (!(w in lo) || p < lo[w]) lo[w] = p
					if (!(w in hi) || p > hi[w]) hi[w] = p
				}
			}
			for (w in n) if (n[w] >= 0.9 * nmax(n)) print hi[w] - lo[w]
		}
		function nmax(a,   m, j) { m = 0; for (j in a) if (a[j] > m) m = a[j]; return m }' "$r/plane.csv" | fig_median)
	local swim
	swim=$(awk -F, -v from="$SETTLE" -v f1="$f1" -v f2="$f2" 'NR > 1 && $1 >= from {
			if (!n++) { t0 = $1; x0 = $2; y0 = $3; h0 = $4 }
			t1 = $1; x1 = $2; y1 = $3; h1 = $4; sh += $4 }
		END {
			if (n < 2 || f1 + f2 <= 0) { print "nan,nan,nan,nan,nan"; exit }
			h = sh / n; dx = x1 - x0; dy = y1 - y0
			along = dx * cos(h) + dy * sin(h); across = -dx * sin(h) + dy * cos(h)
			periods = (t1 - t0) * (f1 + f2) / 2
			printf "%.6f,%.6f,%.6f,%.6f,%.4f\n", along / periods, across / periods, along / (t1 - t0), h1 - h0, periods }' "$out/path.csv")
	{
		echo "mode,seed,seconds,freq1_hz,freq2_hz,amp1_rad,amp2_rad,lag_rad,lag_spread_rad,along_per_period_m,across_per_period_m,speed_m_s,turn_rad,periods,min_swing_rad,wall_s,sweep_m"
		echo "$mode,$seed,$secs,$f1,$f2,$a1,$a2,$lag,$spread,$swim,$swing,$wall,$sweep"
	} >"$out/result.csv"
	fig_clean "$r"
}

merge() {
	fig_merge_runs "$@"
	local runs=$1 fig=$FIG_OUT   # swimmer.csv (the runs' rows) there; all moved into FIGDIR by fig_merge_end
	draw "$runs" "$fig" "$FIG_TMP" || fig_die "swimmer.png could not be drawn"
	fragment "$fig"
	fig_merge_end
}

# first_run RUNS_DIR MODE: the folder of MODE's run with the smallest seed
first_run() {
	local d best="" bs=""
	for d in "$1"/*/; do
		[ -f "$d/result.csv" ] && [ -f "$d/joints.csv" ] || continue
		read -r m s < <(awk -F, 'NR == 2 { print $1, $2 }' "$d/result.csv")
		[ "$m" = "$2" ] || continue
		if [ -z "$bs" ] || [ "$s" -lt "$bs" ]; then bs=$s best=${d%/}; fi
	done
	echo "$best"
}

# draw RUNS_DIR FIGDIR TMP: swimmer.png. Left: both joints' angles over the
# last SHOW s of a run of each mode. Right: the body of the oscillator's run
# every BODY_EVERY s, and its centre's path.
draw() {
	local runs=$1 fig=$2 t=$3 osc clk series=() body=()
	osc=$(first_run "$runs" oscillator) clk=$(first_run "$runs" sinusoid)
	[ -n "$osc$clk" ] || { echo "swimmer: no run with its joints.csv in $runs" >&2; return 1; }
	local t_osc=0 t_clk=0 lag_o lag_c
	if [ -n "$osc" ]; then
		t_osc=$(awk -F, 'NR == 2 { print $1; exit }' "$osc/joints.csv")
		lag_o=$(awk -F, 'NR == 2 { printf "%.0f", $8 * 180 / 3.14159265 }' "$osc/result.csv")
		series+=("'$osc/joints.csv' every ::1 using (\$1 - $t_osc):2 with lines lw 2 lc rgb '#1f77b4' title 'oscillator: joint 1'"
			"'$osc/joints.csv' every ::1 using (\$1 - $t_osc):3 with lines lw 2 lc rgb '#ff7f0e' title 'oscillator: joint 2 (${lag_o}° behind)'")
	fi
	if [ -n "$clk" ]; then
		t_clk=$(awk -F, 'NR == 2 { print $1; exit }' "$clk/joints.csv")
		lag_c=$(awk -F, 'NR == 2 { printf "%.0f", $8 * 180 / 3.14159265 }' "$clk/result.csv")
		series+=("'$clk/joints.csv' every ::1 using (\$1 - $t_clk):2 with lines lw 1.5 dt 2 lc rgb '#1f77b4' title 'clock: joint 1'"
			"'$clk/joints.csv' every ::1 using (\$1 - $t_clk):3 with lines lw 1.5 dt 2 lc rgb '#ff7f0e' title 'clock: joint 2 (${lag_c}° behind)'")
	fi
	local src=${osc:-$clk} label=oscillator
	[ -n "$osc" ] || label=clock
	# the head link darker
	awk -F, -v OFS=, 'NR > 1 { print $2, $5, $6 - 0.5 * $9 * cos($8), $7 - 0.5 * $9 * sin($8), $9 * cos($8), $9 * sin($8) }' "$src/body.csv" \
		>"$t/body.csv"
	[ -s "$t/body.csv" ] || { echo "swimmer: $src/body.csv has no links" >&2; return 1; }
	{
		fig_gp_head 1200 560
		echo "set output '$fig/swimmer.png'"
		echo "set multiplot layout 1,2 title 'One three-link robot in the plane world, through the real daemon (lockstep)'"
		echo "set size 0.62,0.92; set origin 0,0"
		echo "set xlabel 'time (s) over the last $SHOW s of the run'"
		echo "set ylabel 'joint angle (rad)'"
		echo "set title 'joint motion (Fig. 8b)'"
		echo "set key inside top center horizontal maxrows 2 samplen 2 width -4 font ',10'"
		echo "set yrange [-1.0:1.6]"
		echo "set ytics -1, 0.5, 1"
		fig_plot "${series[@]}"
		echo "set size 0.38,0.92; set origin 0.62,0"
		echo "unset key"
		echo "set size ratio -1"
		echo "set title 'the $label run: body every $BODY_EVERY s, centre (red)'"
		echo "set xtics 0.1; set ytics 0.1"
		echo "set xlabel 'x (m)'"
		echo "set ylabel 'y (m)'"
		echo "set autoscale"
		echo "set offsets 0.05, 0.05, 0.05, 0.05"
		echo "plot '$t/body.csv' using 3:4:5:6:(\$2 == 0 ? 0x1f77b4 : 0x9ecae1) with vectors nohead lw 3 lc rgb variable, \\"
		echo "  '$src/path.csv' every ::1 using 2:3 with lines lw 2 lc rgb '#d62728'"
		echo "unset multiplot"
	} >"$t/swimmer.gp"
	fig_gnuplot "$t/swimmer.gp"
}

fragment() {
	local fig=$1 csv="$1/swimmer.csv"
	{
		echo "## One robot's joint motion, and how it swims (the paper's Fig. 8b)"
		echo
		echo "![the two joints' angles over four periods, on the oscillator and on the clock; the robot's body and path](figures/swimmer.png)"
		echo
		echo "What ran: $(($(wc -l <"$csv") - 1)) lockstep runs of \`sim-bridge/scenarios/plane-swimmer.scenario\`: one"
		echo "three-link robot in the plane world (two AX-12A joints on position servos, links of 18.65 cm,"
		echo "drag on every link, no walls), through \`undulated\` with the oscillator tuned for this robot"
		echo "(\`figures/plane-oscillator.conf\`: \`undulated --tune\` in lockstep on it, figures/lib.sh"
		echo "\`fig_plane_tune\`). *oscillator*: the limit cycle from the start; *clock*: the daemon's"
		echo "SINUSOID at the gait the tuner measured, its joints 2π/3 apart as the paper's. Frequency and"
		echo "amplitude: the analyser's per joint over the last $(awk -F, 'NR == 2 { print $3 - '"$SETTLE"' }' "$csv") s; lag: joint 2 behind joint 1, the mean"
		echo "phase difference of the analyser's joints pair; swim: the centre's displacement from"
		echo "$SETTLE s to the end along the robot's mean heading (positive: head first) and across it."
		echo
		echo "| mode | runs | frequency (Hz), joint 1 / 2 | amplitude (rad), joint 1 / 2 | lag of joint 2 | along the heading per period | across per period | speed | turned | sweep across the heading |"
		echo "|---|---|---|---|---|---|---|---|---|---|"
		awk -F, 'NR > 1 { m = $1; n[m]++; f1[m] += $4; f2[m] += $5; a1[m] += $6; a2[m] += $7; l[m] += $8
				al[m] += $10; ac[m] += $11; sp[m] += $12; tu[m] += ($13 < 0 ? -$13 : $13); sw[m] += $17
				if (!(m in lo) || $10 < lo[m]) lo[m] = $10; if (!(m in hi) || $10 > hi[m]) hi[m] = $10 }
			END { for (m in n) printf "| %s | %d | %.3f / %.3f | %.3f / %.3f | %.2f rad (%.0f°) | %.2f cm (%.2f-%.2f) | %.2f cm | %.2f cm/s | %.2f rad | %.3f m |\n",
				m == "sinusoid" ? "clock" : m, n[m], f1[m] / n[m], f2[m] / n[m], a1[m] / n[m], a2[m] / n[m], l[m] / n[m],
				l[m] / n[m] * 180 / 3.14159265, 100 * al[m] / n[m], 100 * lo[m], 100 * hi[m], 100 * ac[m] / n[m],
				100 * sp[m] / n[m], tu[m] / n[m], sw[m] / n[m] }' "$csv" | sort
		echo
		echo "(Means over the runs of a mode; the range of the distance per period in brackets; *turned*: the"
		echo "heading's change over the run, its size; *sweep*: per period, the span of the links' ends (their"
		echo "centre lines) across the period's mean heading, the median over the periods.)"
		echo
		awk -F, -v cp1="$(fig_ini "$FIG_PLANE_CONF" joint.1 coupling_phase)" -v cp2="$(fig_ini "$FIG_PLANE_CONF" joint.2 coupling_phase)" \
			'NR > 1 && $1 == "oscillator" { n++; l += $8; f += ($4 + $5) / 2; a += ($6 + $7) / 2; d += $10; sw += $17 }
			NR > 1 && $1 == "sinusoid" { m++; dc += $10 }
			END {
				pi = 3.14159265
				printf "**Beside the paper.** The paper'"'"'s robots oscillate at about 0.8 Hz and 0.8 rad, and its Fig. 8b shows the joint angles of experiment and simulation with joint 2 about 2π/3 behind joint 1, a lag the paper enforces."
				if (n) printf " Here the oscillator runs at %.2f Hz and %.2f rad (the tuner'"'"'s targets, 0.8 and 0.8, within 5 %%) with joint 2 %.2f rad (%.0f°) behind joint 1 (2π/3: 2.09 rad). The oscillator couples its joints by λ = 1.5 and −0.5 on the other joint'"'"'s angle, which alone puts them about a quarter period apart, 103° on this robot (measured here 2026-11-28 before the coupling'"'"'s phase was set: 1.79 rad, and 1.44 cm a period); the coupling'"'"'s phase (coupling_phase %s / %s rad in plane-oscillator.conf: daemon/CONTROL.md, \"The joints'"'"' lag\") turns the lag to 120°, and the oscillator still answers only its joints'"'"' measured angles and speeds.", f / n, a / n, l / n, l / n * 180 / pi, cp1, cp2
				if (m) printf " The clock, which sets the lag, gives 2π/3 as the paper'"'"'s."
				printf " The robot swims head first, as a Purcell swimmer in drag should"
				if (n) printf ": %.2f cm a period on the oscillator", 100 * d / n
				if (m) printf ", %.2f cm on the clock", 100 * dc / m
				printf " (drag coefficients chosen, not measured: sim-bridge/PHYSICS.md §6.2; PHYSICS.md §6.4 has the same swimmer reversing with the lag). The paper gives no distance per period to compare."
				if (n) printf " Its body sweeps %.3f m across its heading per period (the links'"'"' centre lines; %.3f m with their 3.2 cm width), where the row'"'"'s d̃ takes a contact body to sweep 2 x 0.1865 m/rad x 0.8 rad = 0.298 m: the plane robot'"'"'s swing is narrower than the row'"'"'s reading of it (the robots in a channel, below).", sw / n, sw / n + 0.032
				printf "\n"
			}' "$csv"
	} >"$fig/swimmer.md"
}

# Measured 2026-11-28: a 20 s run took 8-9 s of wall time, two at once
# with other work beside them (load average 6-9).
seconds() {
	if [ "${1:-}" = --quick ]; then echo 1.5; else echo 2; fi
}

# tune OUT.conf [SEED]: figures/plane-oscillator.conf made again (fig_plane_tune)
tune() {
	[ $# -ge 1 ] || fig_usage "tune OUT.conf [SEED]"
	fig_plane_tune "$@"
}
FIG_MORE_COMMANDS=tune

fig_main "jobs [--quick] | run OUTDIR MODE SECONDS SEED | merge RUNS_DIR FIGDIR | seconds [--quick] | tune OUT.conf [SEED]" "$@"
