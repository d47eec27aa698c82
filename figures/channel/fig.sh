#!/usr/bin/env bash
# figures/channel/fig.sh — four robots in a channel (the paper's Figs. 8
# and 9) in the row world, through the real daemons in lockstep: four
# two-joint robots driven as the paper's were (position servos, the
# daemon's default actuation), started on the clock at random phases, then
# 30 s on the oscillator; the final phase
# difference of each neighbouring pair against d̃ beside the compatibility
# bound 2 asin(d̃), at five channel widths.
#
#   fig.sh jobs [--quick]          one line per run: RUN_ID WIDTH_CM SEED
#   fig.sh run OUTDIR WIDTH_CM SEED  one run: OUTDIR/result.csv, a row per neighbouring pair
#   fig.sh merge RUNS_DIR FIGDIR   FIGDIR/channel.csv, channel.png, channel.md
#   fig.sh seconds [--quick]       wall seconds of one run on the 2-core machine
#
# The channel in the row's geometry: the paper's four robots lie side by side
# along its 55 cm (about one robot, 3 x 18.65 cm); its width, 16-24 cm, is
# taken as the distance between neighbouring robots' midlines: the row's
# spacing d (world.spacing), with the channel's sides half a spacing beyond
# the end robots (channel4.scenario's walls = auto). A contact body swings
# 0.1865 m/rad x 0.8 rad each way, a swept width of 0.298 m, so
# d̃ = d / 0.298 m: 0.54 at 16 cm to 0.81 at 24 cm (the preset's 0.55 is the
# 16 cm channel). Four robots sharing 16-24 cm would leave 4-6 cm each, d̃
# 0.13-0.20, less than the robots' own width; that reading is not used. The
# bases slide a little when pushed (channel4's beta = 0.02 s), so each pair's
# final d̃ is the analyser's, from the final neutral positions and measured
# amplitudes, and differs from the nominal one.
source "$(dirname "$0")/../lib.sh"
fig_init channel

# the trial's widths and timeline: lib.sh's (FIG_CHANNEL_*)
TRIALS=12
QUICK_TRIALS=3

jobs() {
	local trials=$TRIALS
	[ "${1:-}" = --quick ] && trials=$QUICK_TRIALS
	# FIG_TINY=1 (the tests): one run at the middle width
	if [ "${FIG_TINY:-0}" = 1 ]; then echo "w20cm-t0 20 $(fig_seed channel tiny)"; return; fi
	fig_grid 'w{v}cm-t{i}' "$FIG_CHANNEL_WIDTHS_CM" "$trials" channel '{v}' '{seed}'
}

run() {
	[ $# -eq 3 ] || fig_usage "run OUTDIR WIDTH_CM SEED"
	local out=$1 width=$2 seed=$3
	fig_num WIDTH_CM "$width" 5 60
	fig_uint SEED "$seed" 1 999999999
	fig_run_start "$out"
	out=$FIG_RUN
	fig_channel_demo "$out" "$width" "$seed" channel4.scenario || exit 1
	local r="$out/demo" wall swing nominal=$FIG_CHANNEL_NOMINAL
	swing=$(fig_min_swing "$r/summary.json")
	wall=$(fig_wall)
	outdir_new "$out/pairs.csv" "$out/result.csv" || fig_die "cannot write in $out"
	fig_pairs "$r/summary.json" >"$out/pairs.csv"
	[ -s "$out/pairs.csv" ] || fig_die "the analysis has no neighbouring pairs"
	{
		echo "width_cm,nominal_dsep,seed,$fig_pairs_header,min_swing_rad,wall_s"
		awk -v p="$width,$nominal,$seed," -v q=",$swing,$wall" '{ print p $0 q }' "$out/pairs.csv"
	} >"$out/result.csv"
	rm -f "$out/pairs.csv"
	fig_clean "$out/demo"
}

merge() {
	fig_merge_runs "$@"
	local runs=$1 fig=$FIG_OUT   # channel.csv (the runs' rows) there; all moved into FIGDIR by fig_merge_end
	draw "$fig" "$FIG_TMP" || fig_die "channel.png could not be drawn"
	fragment "$fig"
	fig_merge_end
}

# draw FIGDIR TMP: channel.png, each pair's final |Δ| against its d̃, one
# colour per width, beside the compatibility bound.
draw() {
	local fig=$1 t=$2 series
	fig_channel_series "$fig/channel.csv" "$t" bound 1.1 "$FIG_CHANNEL_SWEPT_M" >"$t/series" || return 1
	mapfile -t series <"$t/series"
	{
		fig_gp_head 900 600
		echo "set output '$fig/channel.png'"
		echo "set termoption noenhanced"
		echo "set xlabel 'd̃ of the pair at the end (analyser: final neutral positions, measured amplitude)'"
		echo "set title 'Four robots in a channel, 30 s on the oscillator from random phases'"
		fig_channel_axes "$FIG_CHANNEL_WINDOW"
		fig_plot "${series[@]}"
	} >"$t/channel.gp"
	fig_gnuplot "$t/channel.gp"
}

fragment() {
	local fig=$1 csv="$1/channel.csv"
	local runs pairs
	read -r runs pairs <<<"$(fig_channel_counts "$csv")"
	{
		echo "## Four robots in a channel, in the row world (the paper's Figs. 8 and 9)"
		echo
		echo "![final phase difference against d̃ beside the compatibility bound](figures/channel.png)"
		echo
		echo "What ran: $runs lockstep runs of \`sim-bridge/scenarios/channel4.scenario\` (four two-joint"
		echo "robots, position servos, bases that slide a little: β = 0.02 s, walls at the channel's"
		echo "sides), $FIG_CHANNEL_SWITCH s on the clock at random phases, then $((FIG_CHANNEL_SECONDS - FIG_CHANNEL_SWITCH)) s on the oscillator; $pairs"
		echo "neighbouring pairs. Channel width = the distance between neighbouring robots (d̃ ="
		echo "width / 0.298 m, the swept width of a contact body). Final Δ: the pair's mean over the"
		echo "last $FIG_CHANNEL_WINDOW s; d̃ and 2 asin(d̃): the analyser's, per pair."
		if [ "$(fig_channel_trials "$csv")" -le "$QUICK_TRIALS" ]; then
			echo "(\`make figures QUICK=1\`: $QUICK_TRIALS trials a width; the full set runs $TRIALS.)"
		fi
		echo
		fig_channel_table "$csv" "still colliding in the last $FIG_CHANNEL_WINDOW s"
		echo
		awk -F, 'NR > 1 { n++; d = $6 < 0 ? -$6 : $6; if ($5 == "anti-phase") a++; if ($14 != "nan" && d <= $14 + 0.1) b++
				if ($15 < 0.2 || $16 < 0.2) s++; t += $18 } END {
			printf "In all: %d of %d pairs ended at or below the compatibility bound (+0.1 rad, the analyser'"'"'s margin), %d in anti-phase", b, n, a
			printf " (the paper: all near or below the curve, never anti-phase).%s Wall time per run: %.1f s on average.\n", s ? sprintf(" In %d pair(s) a joint swung less than 0.2 rad at the end.", s) : "", t / n }' "$csv"
		echo
		awk -F, 'NR > 1 { n++; d = $6 < 0 ? -$6 : $6
				if ($14 != "nan" && d > $14 + 0.1) { over++; ex = ex sprintf(" %.2f", d - $14) }
				if ($5 == "anti-phase") { a++; if ($9 > 0) ac++ }
				if ($9 > 0) c++ }
			END {
				printf "**Beside the paper.** The paper'"'"'s four robots ended near or below the compatibility curve in every trial, never in anti-phase. Here %d of %d pairs ended above 2 asin(d̃) + 0.1 rad", over, n
				if (over) printf " (by%s rad)", ex
				printf "; %d anti-phase (%d of them still colliding, a lock the paper never saw); %d of %d pairs still touched in the last '"$FIG_CHANNEL_WINDOW"' s: through position servos a pair often settles grazing at its bound once a cycle (docs/EXPERIMENTS.md, section 1), which the paper'"'"'s \"near the curve\" may include.\n", a, ac, c, n
			}' "$csv"
	} >"$fig/channel.md"
}

# Measured 2026-11-27, two runs at a time: 3.3 s a run with little else
# running, 8-11 s beside other work (load average 9-17).
seconds() {
	echo 5
}

fig_main "jobs [--quick] | run OUTDIR WIDTH_CM SEED | merge RUNS_DIR FIGDIR | seconds [--quick]" "$@"
