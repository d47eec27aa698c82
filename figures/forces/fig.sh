#!/usr/bin/env bash
# figures/forces/fig.sh — the paper's contact-force experiment (its Fig. 10)
# through the real daemons in lockstep: ten two-joint robots in a row whose
# walls close from 2.0 m to 0.3 m apart between 10 s and 100 s
# (sim-bridge/scenarios/arena10.scenario), on the clock (SINUSOID, random
# phases) until 200 s, then on the oscillator until 300 s; the median contact
# force (the simulator's ground truth: the rate of its total impulse, impacts
# and resting contact, per second) over 100-200 s and over 200-300 s, at
# several controller stiffnesses.
#
#   fig.sh jobs [--quick]        one line per run: RUN_ID SLOPE SEED END
#   fig.sh run OUTDIR SLOPE SEED [END]  one run: OUTDIR/result.csv (+ series.csv, the force per second)
#   fig.sh merge RUNS_DIR FIGDIR FIGDIR/forces.csv, forces.png, forces_time.png, forces.md
#   fig.sh seconds [--quick]     wall seconds of one run on the 2-core machine
#
# The stiffness is the servo's: the AX-12's compliance slope (daemon
# robot.compliance_slope, written to the servos at start-up, as a lab sets
# it). At 12 V and full torque limit the compliance controller of
# sim-bridge/PHYSICS.md §1.1 drives a duty of punch + (1 - punch) (|e| -
# margin) / slope, so the torque grows with the error e at
#     K = 1.5 N·m · (1 - 32/1023) / (slope · 5.119 mrad)
# (punch 32, margin 0 as the daemon sets it; the servo uses the largest power
# of two not above the slope): 17.7 N·m/rad at 16 down to 2.22 at 128. A
# softer servo lags more, so each run first tunes the oscillator at its slope
# the way a lab would (undulated --tune on one robot, target 0.8 Hz and
# 0.8 rad; the tuner also sets the clock's amplitude and frequency to the gait
# it measured) and runs all ten robots with those parameters.
source "$(dirname "$0")/../lib.sh"
fig_init forces

# The experiment's timeline, as the paper's: END = 300 s of simulated time,
# the walls closing from 10 s to END/3, the clock until 2 END/3, the
# oscillator until END; the medians over END/3..2 END/3 and 2 END/3..END.
# QUICK runs the same timeline at half scale (END = 150).
END_FULL=300
END_QUICK=150
END_TINY=60
# Compliance slopes: the AX-12 acts on 2, 4, ..., 128; these four span the
# paper's factor of 9 in stiffness (0.015-0.135 N·m/rad) with a factor of 8.
SLOPES="16 32 64 128"
QUICK_SLOPES="16 128"
REPLICATES=3
QUICK_REPLICATES=1
# The tuner's budget (s of simulated time) and its targets (the paper's gait).
TUNE_S=150

stiffness() { # SLOPE -> N·m/rad (see the header)
	awk -v s="$1" 'BEGIN { e = 2; while (e * 2 <= s && e < 128) e *= 2
		printf "%.3g", 1.5 * (1 - 32 / 1023) / (e * (300 / 1023) * 3.14159265358979 / 180) }'
}

jobs() {
	local slopes=$SLOPES reps=$REPLICATES end=$END_FULL
	[ "${1:-}" = --quick ] && slopes=$QUICK_SLOPES reps=$QUICK_REPLICATES end=$END_QUICK
	# FIG_TINY=1 (the tests): one run at the shortest timeline a run takes
	if [ "${FIG_TINY:-0}" = 1 ]; then echo "slope64-t0 64 $(fig_seed forces tiny) $END_TINY"; return; fi
	fig_grid 'slope{v}-rep{i}' "$slopes" "$reps" forces '{v}' '{seed}' "$end"
}

# tune OUTDIR SLOPE SEED: one robot on its own simulated bus, the tuner in
# lockstep; OUTDIR/tuned.conf.
tune() {
	local out=$1 slope=$2 seed=$3 dir url rc=0
	dir="$out/tune"
	rm -rf "$dir" && mkdir -p "$dir" || fig_die "cannot create $dir"
	url=$(fig_lcm_url "$dir")
	${FIG_SESSION[@]+"${FIG_SESSION[@]}"} "$FIG_BIN/undulate-sim" --link "$dir/r1" --ids 1,2 --name r1 --lcm-url "$url" --seed "$seed" \
		--lockstep "$dir/clock" --duration $((TUNE_S + 60)) >"$dir/sim.log" 2>&1 </dev/null &
	local sim=$!
	local i
	for i in $(seq 500); do
		grep -q 'ready:' "$dir/sim.log" 2>/dev/null && break
		kill -0 "$sim" 2>/dev/null || break
		sleep 0.02
	done
	"$FIG_BIN/undulated" --tune --port "$dir/r1" --ids 1,2 --robot r1 --lcm-url "$url" --lockstep "$dir/clock" \
		--set "robot.compliance_slope=$slope" --tune-time "$TUNE_S" --out "$out/tuned.conf" \
		>"$dir/tune.log" 2>&1 </dev/null || rc=$?
	# the tuner leaving ends the simulator's run (it says so and exits 1)
	wait "$sim" 2>/dev/null
	if [ "$rc" -ne 0 ] || [ ! -f "$out/tuned.conf" ]; then
		echo "forces: tuning at compliance slope $slope failed (undulated --tune exit $rc): $(grep -m1 -E '^tune: (not|gave)|error' "$dir/tune.log" | cut -c1-200)" >&2
		return 1
	fi
	grep '^tune: done' "$dir/tune.log" | outdir_put "$out/tune.txt"
}

# ini FILE SECTION KEY: a value of the tuned configuration.
ini() {
	awk -v sec="[$2]" -v key="$3" '/^\[/ { in_sec = ($1 == sec); next }
		in_sec && $1 == key && $2 == "=" { print $3; exit }' "$1"
}

# median_force RUN_DIR FROM TO: the median of the per-second contact force
# (collision_rate.csv, simulated seconds [FROM, TO)).
force_stat() {
	awk -F, -v a="$2" -v b="$3" 'NR > 1 && $1 >= a && $1 < b && $6 != "" { print $6 }' "$1/collision_rate.csv" |
		if [ "$4" = mean ]; then awk '{ s += $1; n++ } END { printf "%.6g\n", n ? s / n : "nan" }'; else fig_median; fi
}
impact_rate() {
	awk -F, -v a="$2" -v b="$3" -v col="$4" 'NR > 1 && $1 >= a && $1 < b { s += $col; n++ }
		END { printf "%.4g\n", n ? s / n : "nan" }' "$1/collision_rate.csv"
}

run() {
	[ $# -eq 3 ] || [ $# -eq 4 ] || fig_usage "run OUTDIR SLOPE SEED [END]"
	local out=$1 slope=$2 seed=$3 end=${4:-$END_FULL}
	fig_uint SLOPE "$slope" 2 254
	fig_uint SEED "$seed" 1 999999999
	fig_uint END "$end" "$END_TINY" 3600
	local closed=$((end / 3)) switch=$((2 * end / 3))
	fig_run_start "$out"
	out=$FIG_RUN
	tune "$out" "$slope" "$seed" || exit 1
	local conf="$out/tuned.conf" sets=() key j
	sets+=(--daemon-set "robot.compliance_slope=$slope" --daemon-set "robot.servo_lead_s=$(ini "$conf" robot servo_lead_s)")
	for j in 1 2; do
		for key in k c mu; do sets+=(--daemon-set "joint.$j.$key=$(ini "$conf" "joint.$j" "$key")"); done
	done
	for key in amplitude frequency; do sets+=(--daemon-set "sinusoid.$key=$(ini "$conf" sinusoid "$key")"); done
	# the scenario closes its walls over 90 s from 10 s; a second event at
	# 10 s (run after the scenario's own) sets the span of this timeline
	fig_demo "$out" --scenario "$fig_top/sim-bridge/scenarios/arena10.scenario" --seconds "$end" \
		--switch-at "$switch" --seed "$seed" --window 10 --set "events.10=walls -0.15 0.15 over $((closed - 10))" \
		"${sets[@]}" || exit 1
	local r="$out/demo"
	[ -s "$r/collision_rate.csv" ] || fig_die "the run has no collision_rate.csv"
	awk -F, 'NR > 1 { printf "%s,%s,%s,%s,%s\n", $1, $6, $2, $4, $5 }' "$r/collision_rate.csv" |
		{ echo "t,force_n,impacts,pair_impacts,wall_impacts"; cat; } | outdir_put "$out/series.csv"
	local fc fo mc mo ic io wc wo swing
	fc=$(force_stat "$r" "$closed" "$switch" median)
	fo=$(force_stat "$r" "$switch" "$end" median)
	mc=$(force_stat "$r" "$closed" "$switch" mean)
	mo=$(force_stat "$r" "$switch" "$end" mean)
	ic=$(impact_rate "$r" "$closed" "$switch" 4)
	io=$(impact_rate "$r" "$switch" "$end" 4)
	wc=$(impact_rate "$r" "$closed" "$switch" 5)
	wo=$(impact_rate "$r" "$switch" "$end" 5)
	# the smallest swing of any contact joint in the last 10 s: robots that
	# stopped would also stop pushing
	swing=$(fig_min_swing "$r/summary.json")
	[ "$fc" != nan ] && [ "$fo" != nan ] || fig_die "no contact force in the run's analysis (no SIM.TRUTH?)"
	local wall
	wall=$(fig_wall)
	outdir_new "$out/result.csv" || fig_die "cannot write $out/result.csv"
	{
		echo "slope,stiffness_nm_rad,seed,lead_s,k,sin_amplitude,sin_frequency,force_clock_n,force_osc_n,mean_clock_n,mean_osc_n,pair_impacts_clock_hz,pair_impacts_osc_hz,wall_impacts_clock_hz,wall_impacts_osc_hz,min_swing_rad,wall_s,end_s"
		echo "$slope,$(stiffness "$slope"),$seed,$(ini "$conf" robot servo_lead_s),$(ini "$conf" joint.1 k),$(ini "$conf" sinusoid amplitude),$(ini "$conf" sinusoid frequency),$fc,$fo,$mc,$mo,$ic,$io,$wc,$wo,$swing,$wall,$end"
	} >"$out/result.csv"
	fig_clean "$out/demo"
}

merge() {
	fig_merge_runs "$@"
	local runs=$1 fig=$FIG_OUT   # forces.csv (the runs' rows) there; all moved into FIGDIR by fig_merge_end
	local csv="$fig/forces.csv" t=$FIG_TMP
	# per slope: the median over replicates of each run's median, and the range
	awk -F, 'NR > 1 { n[$1]++; k[$1] = $2; c[$1] = c[$1] " " $8; o[$1] = o[$1] " " $9 } END {
		for (s in n) print s, k[s], n[s], c[s] "|" o[s] }' "$csv" | sort -n |
	while read -r s k n rest; do
		local cs=${rest%%|*} os=${rest#*|}
		printf '%s %s %s %s %s\n' "$s" "$k" "$n" "$(fig_spread "$cs")" "$(fig_spread "$os")"
	done >"$t/summary"
	fig_summary_csv "$t/summary" "$csv" slope,k,runs,clock,clock_min,clock_max,osc,osc_min,osc_max
	force_plot "$fig" "$t" || fig_die "forces.png could not be drawn"
	time_plot "$runs" "$fig" "$t" || fig_die "forces_time.png could not be drawn"
	fragment "$fig"
	fig_merge_end
}

# force_plot FIGDIR TMP: forces.png, the median force of each run and per
# slope against the stiffness, on the clock and on the oscillator.
force_plot() {
	local fig=$1 t=$2 csv="$1/forces.csv" xtics
	xtics=$(awk '{ printf "%s\"%s\" %s", (NR > 1 ? ", " : ""), $2, $2 }' "$t/summary")
	{
		fig_gp_head 900 600
		echo "set output '$fig/forces.png'"
		echo "set termoption noenhanced"
		echo "set logscale xy"
		echo "set xlabel 'controller stiffness K (N·m/rad): AX-12 compliance slope 128, 64, 32, 16 at 12 V'"
		echo "set ylabel 'median contact force (N): all contacts in the row'"
		echo "set title 'Ten robots, walls closed to 0.3 m: median force on the clock (100-200 s) and on the oscillator (200-300 s)'"
		echo "set key bottom right"
		echo "set xrange [1.5:30]"
		echo "set xtics ($xtics)"
		echo "set yrange [0.01:*]"
		fig_plot "'$csv' every ::1 using 2:8 with points pt 7 ps 1.2 lc rgb '#d62728' title 'clock (SINUSOID), each run'" \
			"'$t/summary.csv' every ::1 using 2:4 with lines lw 2 lc rgb '#d62728' title 'clock, median of runs'" \
			"'$csv' every ::1 using 2:9 with points pt 5 ps 1.2 lc rgb '#1f77b4' title 'oscillator, each run'" \
			"'$t/summary.csv' every ::1 using 2:7 with lines lw 2 lc rgb '#1f77b4' title 'oscillator, median of runs'" \
			"0.1 with lines dt 2 lw 2 lc rgb '#2ca02c' title \"paper: below 0.1 N once synchronized\""
	} >"$t/forces.gp"
	fig_gnuplot "$t/forces.gp"
}

# time_plot RUNS_DIR FIGDIR TMP: forces_time.png, the force per second
# through the whole run, one run per slope (its first replicate that has a
# series).
time_plot() {
	local end
	end=$(run_end "$2/forces.csv")
	fig_force_time_plot "$1" "$3" "$end" "$2/forces_time.png" 'contact force (N), per second' '' s slope_label \
		'#9467bd #1f77b4 #ff7f0e #d62728' 10
}
slope_label() { echo "slope $1 ($(stiffness "$1") N·m/rad)"; }

# run_end CSV: the runs' END (the first run's; a merge of mixed timelines
# says so in its fragment).
run_end() { awk -F, 'NR == 2 { print ($18 == "" ? 300 : $18); exit }' "$1"; }

fragment() {
	local fig=$1 csv="$1/forces.csv" n end mixed
	n=$(($(wc -l <"$csv") - 1))
	end=$(run_end "$csv")
	mixed=$(awk -F, 'NR > 1 { e[$18]++ } END { n = 0; for (k in e) n++; print (n > 1 ? "yes" : "") }' "$csv")
	{
		echo "## Contact force on the clock and on the oscillator (the paper's Fig. 10)"
		echo
		echo "![median contact force against controller stiffness](figures/forces.png)"
		echo
		echo "![contact force per second through one run per stiffness](figures/forces_time.png)"
		echo
		echo "What ran: $n lockstep runs of \`sim-bridge/scenarios/arena10.scenario\` through ten \`undulated\`"
		echo "(position servos), each $end s of simulated time: walls closing from 2.0 m to 0.3 m apart"
		echo "between 10 s and $((end / 3)) s, SINUSOID at random phases until $((2 * end / 3)) s, OSCILLATOR until $end s."
		[ "$end" -lt "$END_FULL" ] && echo "(\`make figures QUICK=1\`: the paper's timeline at $(awk -v e="$end" -v f="$END_FULL" 'BEGIN { printf "%g", e / f }') of its length, slopes ${QUICK_SLOPES// /, }, $QUICK_REPLICATES run(s) each; the full set runs slopes ${SLOPES// /, }, $REPLICATES runs each, $END_FULL s.)"
		[ -n "$mixed" ] && echo "(Runs of different lengths are merged here; the timeline named is the first run's.)"
		echo "Each run tuned the oscillator first at its compliance slope (\`undulated --tune\`, 0.8 Hz,"
		echo "0.8 rad; the clock set to the gait measured). Force: the simulator's total impulse per"
		echo "second (impacts and resting contact, robots and walls), median over $((end / 3))-$((2 * end / 3)) s (clock)"
		echo "and $((2 * end / 3))-$end s (oscillator). The arena in one dimension: the row is the length along"
		echo "which the paper's walls closed (its 0.6 m width has no counterpart); neighbours start"
		echo "0.2 m apart (d̃ = 0.67) and, packed evenly, would end 3 cm apart (d̃ = 0.10); the bases"
		echo "slide when pushed (β = 0.02 s), which is how the walls push the robots together."
		echo
		echo "| slope | K (N·m/rad) | runs | tuned (its first run): lead (s), k | clock: median force (N), min-max | oscillator: median force (N), min-max | ratio |"
		echo "|---|---|---|---|---|---|---|"
		local line slope tuned
		while read -r line; do
			slope=${line%% *}
			tuned=$(awk -F, -v s="$slope" 'NR > 1 && $1 == s { printf "%.3g, %.3g", $4, $5; exit }' "$csv")
			awk -v t="$tuned" '{ printf "| %s | %s | %s | %s | %.3g (%.3g-%.3g) | %.3g (%.3g-%.3g) | %.1fx |\n", $1, $2, $3, t, $4, $5, $6, $7, $8, $9, ($7 > 0 ? $4 / $7 : 0) }' <<<"$line"
		done <"$FIG_TMP/summary"
		echo
		awk -F, 'NR > 1 { if (min == "" || $16 < min) min = $16; if ($16 < 0.2) stopped++; t += $17; n++ }
			END { if (stopped) printf "In %d run(s) a joint swung less than 0.2 rad peak-to-peak in the last 10 s (smallest %.2f rad): robots that stop also stop pushing.", stopped, min
			      else printf "Every joint of every robot still swung in the last 10 s of every run (the smallest swing %.2f rad peak-to-peak).", min
			      printf " Wall time per run: %.0f s on average, tuning included.\n", t / n }' "$csv"
		echo
		beside "$fig"
	} >"$fig/forces.md"
}

# beside FIGDIR: the paper's numbers beside these, and why they differ where
# that is known (measured here, with the date).
beside() {
	awk '{ r = $7 > 0 ? $4 / $7 : 0
		if (NR == 1 || $7 < omin) omin = $7; if (NR == 1 || $7 > omax) omax = $7
		if (NR == 1 || $4 < cmin) cmin = $4; if (NR == 1 || $4 > cmax) cmax = $4
		if (NR == 1 || r < rmin) rmin = r; if (NR == 1 || r > rmax) rmax = r
		if ($7 >= 0.1) above++; n++ }
		END {
			printf "**Beside the paper.** The paper: once the oscillators synchronized the median contact force fell below 0.1 N, orders of magnitude below the clock'"'"'s. Here the oscillator'"'"'s median force is %.2g-%.2g N (the row'"'"'s ten robots and two walls together; %.2g-%.2g N a robot) against the clock'"'"'s %.3g-%.3g N, %.1f-%.1fx lower", omin, omax, omin / 10, omax / 10, cmin, cmax, rmin, rmax
			if (above == 0 && rmin >= 100) print ": as the paper."
			else if (rmin >= 1.5) printf ": the fall reproduces, its size does not (%d of %d stiffnesses above 0.1 N on the oscillator, none 100x lower).\n", above, n
			else printf ": at some stiffness the force did not fall (less than 1.5x); %d of %d above 0.1 N on the oscillator.\n", above, n
		}' "$FIG_TMP/summary"
	echo
	echo "Why, as far as measured here:"
	echo
	echo "- The paper's stiffness is out of the AX-12's reach: its softest compliance slope (128) is"
	echo "  2.2 N·m/rad, 16x the paper's stiffest (0.135). The four slopes span the paper's factor of 9"
	echo "  with a factor of 8, and the force is drawn against the servo's own K."
	echo "- In one dimension the arena's final 0.3 m is one robot's swept width (2 x 0.1865 m/rad x"
	echo "  0.8 rad = 0.30 m): synchronized robots can swing only as one in-phase stack. In a run by hand"
	echo "  (slope 32, the daemon's defaults, 2026-11-27) eight robots formed that stack, neighbours"
	echo "  1-5 mm apart grazing about 20 times a second at |Δ| ≈ 0.04 rad, while the two end robots"
	echo "  were pinned between the stack and the walls (swings of 0.55-0.60 rad instead of 1.6); the"
	echo "  paper's robots could also move along the arena's other 0.6 m."
	echo "- The bases' mobility decides how the closing walls pack the row: the same run with β ="
	echo "  0.01, 0.02, 0.05, 0.1 s gave a fall of 12.5x, 5.8x, 2.1x, 2.0x (mean force over the last"
	echo "  10 s before the switch and of the run; one seed each, 2026-11-27). arena10 keeps β = 0.02 s,"
	echo "  the channel preset's, chosen before those runs."
}

# Measured 2026-11-27 on the 2-core machine, two runs at a time: 70 s a full
# run and 37 s a quick one with little else running; 153 s and 99 s beside
# other people's fuzzing and figure runs (load average 9-17).
seconds() {
	if [ "${1:-}" = --quick ]; then echo 22; else echo 44; fi
}

fig_main "jobs [--quick] | run OUTDIR SLOPE SEED | merge RUNS_DIR FIGDIR | seconds [--quick]" "$@"
