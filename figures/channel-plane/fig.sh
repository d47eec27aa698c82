#!/usr/bin/env bash
# figures/channel-plane/fig.sh — four robots in a channel in the plane world
# (the paper's Figs. 8c-f and 9) through the real daemons in lockstep: four
# three-link robots (two AX-12A joints on position servos, links of 18.65 cm,
# drag, any link touching any link of another robot or a wall) side by side
# in a channel 16-24 cm wide, on the clock at random phases for 2 s, then
# 30 s on the oscillator tuned for this robot; each neighbouring pair's final
# phase difference against d̃ beside the compatibility curve 2 asin(d̃), and
# the robots in the channel at a few moments.
#
#   fig.sh jobs [--quick]            one line per run: RUN_ID WIDTH_CM SEED ENDS
#   fig.sh run OUTDIR WIDTH_CM SEED [ENDS]  one run: OUTDIR/result.csv (a row per
#                                    neighbouring pair), OUTDIR/frames.csv (the links at a
#                                    few moments); ENDS: ends (default) or none (no end walls)
#   fig.sh merge RUNS_DIR FIGDIR     FIGDIR/channel-plane.csv, channel-plane.png,
#                                    channel-plane-frames.png, channel-plane.md
#   fig.sh seconds [--quick]         wall seconds of one run on the 2-core machine
#
# The channel (sim-bridge/scenarios/plane-channel4.scenario): the width is
# read as the row module's (figures/channel/) reads it, the distance between
# neighbouring robots' midlines (world.spacing), the side walls half a width
# beyond the end robots (walls = auto). End walls stand across the robots'
# length, 0.61 m apart: the paper's channel is 55 cm long, which holds the
# robots side by side; without ends the robots swim 24-41 cm along their
# heading in 32 s, each at its own pace, and neighbours ended up to 18 cm apart
# along their length (one run at 20 cm, 2026-11-28), which changes what
# touches what. The full set adds CONTROL_TRIALS runs a width without end
# walls (ENDS = none), reported apart, to show what the ends change. 55 cm cannot hold a straight robot (0.56 m of links and 3.2 cm
# of width, as they start); 0.61 m is the least that does, with 1 cm to
# spare. The robots start straight (at 16 cm robots bent by the scenario's
# random start would overlap) and get their phases from the clock.
#
# d̃ as the analyser gives it: the final distance between the robots'
# centres over twice lever x the measured amplitude (lever 0.1865 m/rad, the
# row's reach per radian): width / 0.298 m at 0.8 rad, 0.54 at 16 cm to 0.80
# at 24 cm. A plane robot's true lateral sweep is not that: each run measures
# it (the envelope of its links across the channel over the final window),
# and the page gives it beside 0.298 m.
#
# The oscillator: figures/plane-oscillator.conf (made by `undulated --tune`
# in lockstep on one plane robot, its joints 2 pi / 3 apart by coupling_phase
# +-0.30 rad: figures/lib.sh, fig_plane_tune), passed to every daemon as
# --daemon-set values; the clock (SINUSOID) at the gait the tuner measured.
source "$(dirname "$0")/../lib.sh"
fig_init channel-plane

# the trial's widths and timeline: lib.sh's (FIG_CHANNEL_*), as figures/channel's.
# 42 trials a width: 210 runs, the paper's number of simulated trials
TRIALS=42
QUICK_TRIALS=3
CONTROL_TRIALS=3   # 6 until 2026-11-29: `make figures` had to fit its hour
# A free plane robot on this oscillator sweeps 0.159 m across its heading per
# period (its links' centre lines: figures/swimmer's sweep_m, 3 runs, 0.1590-
# 0.1595 m, 2026-11-28; 0.189 m with the joints 103 deg apart); two robots side by side, their centre lines a width less
# the links' 3.2 cm apart, can touch only below a "plane d̃" of
# (width - 0.032 m) / 0.189 m: the page sets it beside the row's.
FREE_SWEEP_M=0.159
LINK_WIDTH_M=0.032
# The moments of the picture: the switch, two on the way, the end.
FRAMES="2 5 15 32"

jobs() {
	local trials=$TRIALS
	[ "${1:-}" = --quick ] && trials=$QUICK_TRIALS
	if [ "${FIG_TINY:-0}" = 1 ]; then echo "w20cm-t0 20 $(fig_seed channel-plane tiny) ends"; return; fi
	fig_grid 'w{v}cm-t{i}' "$FIG_CHANNEL_WIDTHS_CM" "$trials" channel-plane '{v}' '{seed}' ends
	[ "${1:-}" = --quick ] && return
	fig_grid 'noends-w{v}cm-t{i}' "$FIG_CHANNEL_WIDTHS_CM" "$CONTROL_TRIALS" 'channel-plane none' '{v}' '{seed}' none
}

# robot_stats PLANE_CSV FROM: per robot over t >= FROM, from the analyser's
# plane.csv: its name, mean centre (x, y) and its lateral sweep: the span
# across the channel (x) of its links' ends, width included.
robot_stats() {
	awk -F, -v from="$2" 'NR > 1 && $2 >= from {
			r = $3; gsub(/"/, "", r)
			if ($5 == 0) { cx[r] += $11; cy[r] += $12; n[r]++ }
			for (s = -1; s <= 1; s += 2) {
				e = $6 + s * 0.5 * ($9 + $10) * cos($8)
				if (!(r in lo) || e < lo[r]) lo[r] = e
				if (!(r in hi) || e > hi[r]) hi[r] = e
			}
		}
		END { for (r in n) printf "%s %.6f %.6f %.6f\n", r, cx[r] / n[r], cy[r] / n[r], hi[r] - lo[r] }' "$1"
}

run() {
	[ $# -eq 3 ] || [ $# -eq 4 ] || fig_usage "run OUTDIR WIDTH_CM SEED [ENDS]"
	local out=$1 width=$2 seed=$3 ends=${4:-ends} ends_set=()
	fig_num WIDTH_CM "$width" 10 40
	fig_uint SEED "$seed" 1 999999999
	case "$ends" in ends) ;; none) ends_set=(--set world.ends=none) ;; *) fig_usage "ENDS: want ends or none, got '$ends'" ;; esac
	local sets
	mapfile -t sets < <(fig_plane_sets) && [ ${#sets[@]} -gt 0 ] || exit 1
	fig_run_start "$out"
	out=$FIG_RUN
	local r="$out/demo" nominal
	fig_channel_demo "$out" "$width" "$seed" plane-channel4.scenario ${ends_set[@]+"${ends_set[@]}"} "${sets[@]}" || exit 1
	nominal=$FIG_CHANNEL_NOMINAL
	[ -s "$r/plane.csv" ] || fig_die "the run's analysis has no plane.csv (a plane world's log gives one)"
	outdir_new "$out/pairs.csv" "$out/robots.txt" "$out/frames.csv" "$out/result.csv" || fig_die "cannot write in $out"
	fig_pairs "$r/summary.json" >"$out/pairs.csv"
	[ -s "$out/pairs.csv" ] || fig_die "the analysis has no neighbouring pairs"
	local t_end swing wall
	t_end=$(fig_json "$r" .t_end)
	robot_stats "$r/plane.csv" "$(awk -v t="$t_end" -v w="$FIG_CHANNEL_WINDOW" 'BEGIN { print t - w }')" >"$out/robots.txt"
	# the links and walls at the picture's moments (the pose of the 0.1 s
	# grid that ends at each: plane.csv's poses are at most 0.1 s apart)
	# (straight into frames.csv, made above: no temporary file beside it)
	{
		echo "moment,kind,index,x,y,angle_or_bx,length_or_by,robot_index"
		awk -F, -v want="$FRAMES" 'BEGIN { n = split(want, m, " ") }
			FNR == 1 { next }
			{ for (i = 1; i <= n; i++) if ($2 > m[i] - 0.099 && $2 <= m[i] + 0.001) print m[i] ",link," $5 "," $6 "," $7 "," $8 "," $9 "," $4 }' \
			"$r/plane.csv"
		awk -F, -v want="$FRAMES" 'BEGIN { n = split(want, m, " ") }
			FNR == 1 { next }
			{ for (i = 1; i <= n; i++) if ($2 > m[i] - 0.099 && $2 <= m[i] + 0.001) print m[i] ",wall," $3 "," $4 "," $5 "," $6 "," $7 ",-1" }' \
			"$r/plane_walls.csv"
	} >"$out/frames.csv"
	swing=$(fig_min_swing "$r/summary.json")
	wall=$(fig_wall)
	{
		echo "width_cm,nominal_dsep,seed,$fig_pairs_header,dy_m,sweep_a_m,sweep_b_m,min_swing_rad,wall_s,ends"
		awk -v p="$width,$nominal,$seed," -v q=",$swing,$wall,$ends" 'NR == FNR { cy[$1] = $3; sw[$1] = $4; next }
			{ split($0, f, ","); split(f[1], ab, ":"); a = ab[1]; b = ab[2]
			  dy = (a in cy && b in cy) ? cy[b] - cy[a] : "nan"; if (dy != "nan" && dy < 0) dy = -dy
			  printf "%s%s,%s,%s,%s%s\n", p, $0, dy, (a in sw ? sw[a] : "nan"), (b in sw ? sw[b] : "nan"), q }' \
			"$out/robots.txt" "$out/pairs.csv"
	} >"$out/result.csv"
	rm -f "$out/pairs.csv"
	fig_clean "$r"
}

merge() {
	fig_merge_runs "$@"
	local runs=$1 fig=$FIG_OUT   # channel-plane.csv (the runs' rows) there; all moved into FIGDIR by fig_merge_end
	# the channel with end walls (the figure), and the control runs without
	awk -F, 'NR == 1 || $22 != "none"' "$fig/channel-plane.csv" >"$FIG_TMP/main.csv"
	awk -F, 'NR == 1 || $22 == "none"' "$fig/channel-plane.csv" >"$FIG_TMP/control.csv"
	[ "$(wc -l <"$FIG_TMP/main.csv")" -gt 1 ] || fig_die "no run with end walls in $runs: nothing to draw"
	draw "$fig" "$FIG_TMP" || fig_die "channel-plane.png could not be drawn"
	frames "$runs" "$fig" "$FIG_TMP" || fig_die "channel-plane-frames.png could not be drawn"
	fragment "$fig" "$FIG_TMP"
	fig_merge_end
}

# draw FIGDIR TMP: channel-plane.png, each pair's final |Δ| against its d̃,
# one colour per width, beside the compatibility curve (the paper's Fig. 9).
draw() {
	local fig=$1 t=$2 series
	fig_channel_series "$t/main.csv" "$t" curve 1.0 "$FIG_CHANNEL_SWEPT_M" >"$t/series" || return 1
	mapfile -t series <"$t/series"
	fig_series series "$t/control.csv" "\$13 != \"nan\"" "using 13:(abs(\$6)) with points pt 6 ps 0.9 lc rgb '#888888' title 'control: no end walls, all widths'"
	{
		fig_gp_head 900 600
		echo "set output '$fig/channel-plane.png'"
		echo "set termoption noenhanced"
		echo "set xlabel 'd̃ of the pair at the end (analyser: final centres, measured amplitude)'"
		echo "set title 'Four three-link robots in a channel (plane world), 30 s on the oscillator from random phases'"
		fig_channel_axes "$FIG_CHANNEL_WINDOW"
		fig_plot "${series[@]}"
	} >"$t/channel-plane.gp"
	fig_gnuplot "$t/channel-plane.gp"
}

# picked RUNS_DIR WIDTH: the run folder of WIDTH with frames and the lowest trial
picked() {
	local d best="" bt=""
	for d in "$1"/w"$2"cm-t*/; do
		[ -f "$d/frames.csv" ] || continue
		local n=${d%/}; n=${n##*-t}
		if [ -z "$bt" ] || [ "$n" -lt "$bt" ]; then bt=$n best=${d%/}; fi
	done
	echo "$best"
}

# frames RUNS_DIR FIGDIR TMP: channel-plane-frames.png, the robots in the
# channel at the moments of FRAMES, one row per width shown (the narrowest
# and the widest run, each its lowest trial), coloured by robot.
frames() {
	local runs=$1 fig=$2 t=$3 widths=() w d rows=0
	for w in $(awk -F, 'NR > 1 { print $1 }' "$fig/channel-plane.csv" | sort -gu | sed -n '1p;$p' | sort -gu); do
		d=$(picked "$runs" "$w")
		[ -n "$d" ] || continue
		widths+=("$w|$d")
		rows=$((rows + 1))
	done
	[ "$rows" -gt 0 ] || { echo "channel-plane: no run with frames.csv in $runs" >&2; return 1; }
	local nf
	nf=$(wc -w <<<"$FRAMES")
	{
		fig_gp_head $((300 * nf)) $((330 * rows + 60))
		echo "set output '$fig/channel-plane-frames.png'"
		echo "set termoption noenhanced"
		echo "set multiplot layout $rows,$nf title 'The robots in the channel (links from SIM.TRUTH): the oscillator from ${FIG_CHANNEL_SWITCH} s'"
		echo "unset key"
		echo "set size ratio -1"
		echo "set xtics 0.2 font ',8'; set ytics 0.1 font ',8'"
		echo "set format x '%.1f'; set format y '%.1f'"
		for wd in "${widths[@]}"; do
			w=${wd%%|*} d=${wd#*|}
			for m in $FRAMES; do
				echo "set title '$w cm, $(basename "$d"), t = $m s' font ',10'"
				echo "plot '$d/frames.csv' every ::1 using ((\$1 == $m && strcol(2) eq 'link') ? \$4 - 0.5 * \$7 * cos(\$6) : 1/0):(\$5 - 0.5 * \$7 * sin(\$6)):(\$7 * cos(\$6)):(\$7 * sin(\$6)):(int(\$8) % 4 + 1) with vectors nohead lw 4 lc variable, \\"
				echo "  '$d/frames.csv' every ::1 using ((\$1 == $m && strcol(2) eq 'link' && \$3 == 0) ? \$4 + 0.5 * \$7 * cos(\$6) : 1/0):(\$5 + 0.5 * \$7 * sin(\$6)) with points pt 7 ps 0.8 lc rgb 'black', \\"
				echo "  '$d/frames.csv' every ::1 using ((\$1 == $m && strcol(2) eq 'wall') ? \$4 : 1/0):5:(\$6 - \$4):(\$7 - \$5) with vectors nohead lw 2 lc rgb 'black'"
			done
		done
		echo "unset multiplot"
	} >"$t/frames.gp"
	fig_gnuplot "$t/frames.gp"
}

fragment() {
	local fig=$1 csv="$2/main.csv" control="$2/control.csv"
	local runs pairs
	read -r runs pairs <<<"$(fig_channel_counts "$csv")"
	{
		echo "## Four three-link robots in a channel, in the plane (the paper's Figs. 8c-f and 9)"
		echo
		echo "![final phase difference against d̃ beside the compatibility curve](figures/channel-plane.png)"
		echo
		echo "![the robots in the channel at the switch, 3 s and 13 s after it, and at the end](figures/channel-plane-frames.png)"
		echo
		echo "What ran: $runs lockstep runs of \`sim-bridge/scenarios/plane-channel4.scenario\` through four"
		echo "\`undulated\`: four three-link robots in the plane world (two AX-12A joints each on position"
		echo "servos, links of 18.65 cm, drag on every link, any link touching any link of another robot or a"
		echo "wall, r = 0.67), side by side with their heads the same way, the channel's width the distance between"
		echo "neighbouring robots' midlines, side walls half a width beyond the end robots, end walls across"
		echo "their length 0.61 m apart (the paper's channel is 55 cm long: it keeps the robots side by side;"
		echo "0.61 m is the least that holds a straight robot, as they start). The oscillator tuned for this robot"
		echo "(\`figures/plane-oscillator.conf\`, \`undulated --tune\` in lockstep: 0.82 Hz, 0.78 rad, the joints 2π/3 apart"
		echo "through the coupling's phase, the swimmer's section above); $FIG_CHANNEL_SWITCH s on"
		echo "the clock at random phases, then $((FIG_CHANNEL_SECONDS - FIG_CHANNEL_SWITCH)) s on the oscillator; $pairs neighbouring pairs. Final Δ: the"
		echo "pair's mean over the last $FIG_CHANNEL_WINDOW s; d̃ and 2 asin(d̃): the analyser's per pair (final centres,"
		echo "lever 0.1865 m/rad, measured amplitude)."
		if [ "$(fig_channel_trials "$csv")" -le "$QUICK_TRIALS" ]; then
			echo "(\`make figures QUICK=1\`: $QUICK_TRIALS trials a width; the full set runs $TRIALS, the paper's 210 simulated trials.)"
		fi
		echo
		fig_channel_table "$csv" "still touching in the last $FIG_CHANNEL_WINDOW s" above
		echo
		local sweep dy
		sweep=$(awk -F, 'NR > 1 { print $18; print $19 }' "$csv" | grep -v nan | fig_median)
		dy=$(awk -F, 'NR > 1 { print $17 }' "$csv" | grep -v nan | fig_median)
		local plane
		plane=$(for w in $(awk -F, 'NR > 1 { print $1 }' "$csv" | sort -gu); do
			awk -v w="$w" -v lw="$LINK_WIDTH_M" -v f="$FREE_SWEEP_M" 'BEGIN { printf "%s cm %.2f, ", w, (w / 100 - lw) / f }'
		done | sed 's/, $//')
		awk -F, -v sweep="$sweep" -v dy="$dy" -v swept="$FIG_CHANNEL_SWEPT_M" -v free="$FREE_SWEEP_M" -v lw="$LINK_WIDTH_M" -v plane="$plane" 'NR > 1 { n++; d = $6 < 0 ? -$6 : $6
				if ($5 == "anti-phase") { a++; if ($9 > 0) ac++; ad = ad sprintf(" %.2f", $13) }
				if ($14 != "nan" && d <= $14 + 0.1) b++
				else { over++; ex = ex sprintf(" %.2f", d - $14) }
				if (d > 2.0944) big++
				if ($9 > 0) c++
				if ($20 < 0.2) s++; t += $21 }
			END {
				printf "In all: %d of %d pairs ended at or below the compatibility curve (+0.1 rad, the analyser'"'"'s margin), %d in anti-phase, %d more than 2π/3 apart (the paper: all near or below the curve, never anti-phase).", b, n, a, big
				printf "%s Wall time per run: %.1f s on average.\n\n", s ? sprintf(" In %d pair(s) a joint swung less than 0.2 rad at the end.", s) : "", t / n
				printf "**Beside the paper.** The paper'"'"'s four robots (210 simulated trials and 50 experiments) ended near or below the compatibility curve, never in anti-phase. Here %d of %d pairs ended above 2 asin(d̃) + 0.1 rad", over, n
				if (over && over <= 40) printf " (by%s rad)", ex
				printf "; %d in anti-phase", a
				if (a) printf " (at d̃%s; %d of them still touching in the last '"$FIG_CHANNEL_WINDOW"' s)", ad, ac
				printf "; %d of %d pairs still touched in the last '"$FIG_CHANNEL_WINDOW"' s. ", c, n
				printf "The d̃ is the row'"'"'s reading of the plane, a contact body sweeping 2 x 0.1865 m/rad x 0.8 rad = %.3f m. A free robot on this oscillator sweeps %.3f m across its heading per period (its links'"'"' centre lines: the swimmer'"'"'s section above), so two of them side by side and aligned could touch at all only while (width - %.3f m) / %.3f m is below 1 (%s), and then only out of phase. Here they touched far more than that: in the channel a robot occupied %.3f m across it over the final window (the median over the robots, width included: it turns and is pushed about as well as swinging), the side walls stand half a width beyond the end robots, and the robots pressed together (the d̃ at the end below the nominal, the table). Neighbours'"'"' centres ended %.3f m apart along the channel (median): the end walls hold them side by side.\n", swept, free, lw, free, plane, sweep, dy
			}' "$csv"
		if [ "$(wc -l <"$control")" -gt 1 ]; then
			echo
			local cdy cruns
			cdy=$(awk -F, 'NR > 1 { print $17 }' "$control" | grep -v nan | fig_median)
			cruns=$(awk -F, 'NR > 1 { print $1 " " $3 }' "$control" | sort -u | wc -l)
			awk -F, -v dy="$dy" -v cdy="$cdy" -v runs="$cruns" 'NR > 1 { n++; d = $6 < 0 ? -$6 : $6
					if ($5 == "anti-phase") a++
					if ($14 != "nan" && d <= $14 + 0.1) b++
					if ($9 > 0) c++
					if ($17 > mx) mx = $17 }
				END {
					printf "**Without end walls** (the control, %d run%s at the same widths and timeline, grey circles in the figure): %d of %d pairs ended at or below the curve, %d in anti-phase, %d still touched in the last '"$FIG_CHANNEL_WINDOW"' s. Their neighbours'"'"' centres ended %.3f m apart along the channel (median; up to %.3f m), against %.3f m with the ends: the end walls are what keeps the robots side by side, as the paper'"'"'s 55 cm channel does.\n", runs, runs == 1 ? "" : "s", b, n, a, c, cdy, mx, dy
				}' "$control"
		fi
	} >"$fig/channel-plane.md"
}

# Measured 2026-11-28: a run took 16-17 s of wall time alone (2.1x real
# time), beside other work (load average 6-9).
seconds() {
	echo 4.1
}

fig_main "jobs [--quick] | run OUTDIR WIDTH_CM SEED [ENDS] | merge RUNS_DIR FIGDIR | seconds [--quick]" "$@"
