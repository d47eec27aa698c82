#!/usr/bin/env bash
# run.sh: alone — it measures a gait or an experiment in real time: nothing beside it (tests/run.sh)
# e2e_force.sh — the paper's contact-force experiment, shortened: ten
# two-joint robots crowded in a row (sim-bridge/scenarios/force10.scenario), one
# undulated each, driven by the clock (SINUSOID) at random phases, then
# switched to the limit-cycle OSCILLATOR by one LCM command to every robot
# (UNDULATE.CMD). The paper's claim: contact forces collapse by orders of
# magnitude once the oscillators synchronize. Asserted: the contact impulse
# per second — the simulator's ground truth (SIM.TRUTH total_impulse: impacts
# and resting contact, i.e. the mean contact force), sampled by demo.sh — in
# the last 10 s of the OSCILLATOR phase is at least 3 times lower than in the
# last 10 s of the SINUSOID phase; the paper's 10 times is checked too and
# reported as a TODO when a run falls short. The impulse of the impacts alone
# (the collision messages, through undulate-analyze) is printed beside it.
source "$(dirname "$0")/../lib.sh"

switch_at=${E2E_FORCE_SWITCH_AT:-15}
seconds=${E2E_FORCE_SECONDS:-45}
# The paper's figure is "orders of magnitude"; one order is checked (TODO when short).
min_ratio=10   # the paper: an order of magnitude or more
min_fall=3     # the least fall docs/EXPERIMENTS.md records is 3.8x (2026-11-25)

spawn force env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" \
	--scenario "$top/sim-bridge/scenarios/force10.scenario" --seconds "$seconds" --switch-at "$switch_at" \
	--seed 3 --lcm-url "$(lcm_url $((7880 + $$ % 5)))" --out "$T/out"
wait_for $((seconds + 60)) bash -c "! kill -0 $pid_force"
kill -TERM "$pid_force" 2>/dev/null  # only if it overran
wait "$pid_force"
rc=$?
if [ -f "$T/out/crosstalk" ]; then
	tap_fail "nobody else on the run's LCM port" "another program published on the run's LCM URL; its results mix two runs"
	keep_runs out
	tap_done
	exit
fi
if [ "$rc" = 0 ] && [ -f "$T/out/contact.csv" ] && [ -f "$T/out/switch_t" ]; then
	tap_ok "ten robots ran ${seconds} s (SINUSOID, then OSCILLATOR at +${switch_at} s), log analysed"
else
	tap_fail "ten robots ran ${seconds} s, switched by LCM command, log analysed" "exit $rc: $(tail -n 20 "$T/force.log")"
	keep_runs out
	tap_done
	exit
fi

sw=$(cat "$T/out/switch_t")
# distinct robots that report a mode change to OSCILLATOR
nmode=$(grep '"mode".*-> OSCILLATOR' "$T/out/events.csv" | cut -d, -f3 | sort -u | wc -l)
if [ "$nmode" -eq 10 ]; then
	tap_ok "all ten robots report the switch to OSCILLATOR (at t = $sw s)"
else
	tap_fail "all ten robots report the switch to OSCILLATOR" "$nmode mode events"
fi

# The simulator's samples (contact.csv: simulated time, running impact count,
# total impulse), taken by demo.sh every 5 s from the start, just before the
# switch and at the end.
# force FROM TO: mean contact force (N) between the samples nearest FROM and TO s.
force() {
	awk -F, -v a="$1" -v b="$2" 'NR > 1 { t[NR] = $1; i[NR] = $3 }
		END { for (k in t) { if (ka == "" || (t[k] - a) ^ 2 < (t[ka] - a) ^ 2) ka = k
			if (kb == "" || (t[k] - b) ^ 2 < (t[kb] - b) ^ 2) kb = k }
		printf "%.6f %.1f %.1f", (i[kb] - i[ka]) / (t[kb] - t[ka]), t[ka], t[kb] }' "$T/out/contact.csv"
}
# The switch in simulated time: the sample demo.sh takes just before it.
t_end=$(awk -F, 'NR > 1 { t = $1 } END { print t }' "$T/out/contact.csv")
t_sw=$(awk -F, -v s="$switch_at" 'NR > 1 && $1 >= s - 1 { print $1; exit }' "$T/out/contact.csv")
read -r before b0 b1 <<<"$(force "$(awk "BEGIN { print $t_sw - 10 }")" "$t_sw")"
read -r after a0 a1 <<<"$(force "$(awk "BEGIN { print $t_end - 10 }")" "$t_end")"
ratio=$(awk -v a="$before" -v b="$after" 'BEGIN { if (b > 0) printf "%.1f", a / b; else print "inf" }')
echo "# mean contact force (simulator: impacts + resting contact): SINUSOID $b0-$b1 s $before N, OSCILLATOR $a0-$a1 s $after N, ratio $ratio"
awk -F, 'NR > 2 && $1 > t0 { printf "# %5.1f-%-5.1f s %.4f N\n", t0, $1, ($3 - i0) / ($1 - t0) } NR > 1 { t0 = $1; i0 = $3 }' "$T/out/contact.csv"
# Impacts alone (collision messages; 1 s bins of the log's time).
rate() { awk -F, -v a="$1" -v b="$2" 'NR > 1 && $1 >= a && $1 < b { s += $3 } END { printf "%.6f", s / (b - a) }' "$T/out/collision_rate.csv"; }
end=$(awk -F, 'NR > 1 { t = $1 } END { print t }' "$T/out/collision_rate.csv")  # last whole bin
ib=$(rate "$(awk "BEGIN { print int($sw) - 10 }")" "$(awk "BEGIN { print int($sw) }")")
ia=$(rate "$(awk "BEGIN { print $end - 10 }")" "$end")
echo "# impacts only (collision messages): SINUSOID $ib N*s/s, OSCILLATOR $ia N*s/s, ratio $(awk -v a="$ib" -v b="$ia" 'BEGIN { if (b > 0) printf "%.1f", a / b; else print "inf" }')"

# Robots that stopped would also stop colliding: every joint must still swing
# at least 0.6 rad peak-to-peak (a crowded end robot's free joint swings least).
sg=$(min_swing "$T/out")
if awk -v s="${sg%% *}" 'BEGIN { exit !(s >= 0.6) }'; then
	tap_ok "OSCILLATOR: every robot still undulates at the end (smallest peak-to-peak $sg rad)"
else
	tap_fail "OSCILLATOR: every robot still undulates at the end" "smallest peak-to-peak over the last 10 s: $sg rad (< 0.6)"
fi
if awk -v a="$before" 'BEGIN { exit !(a > 0.1) }'; then
	tap_ok "SINUSOID: the clock drives the crowded robots through contact ($before N)"
else
	tap_fail "SINUSOID: the crowded robots push each other" "mean contact force $before N"
fi
# The fall itself was seen in every run docs/EXPERIMENTS.md records (3.8x to 55x);
# the paper's order of magnitude in most runs but not all: reported as TODO
# with the numbers when a run falls short, never lowered.
at_least() { [ "$ratio" = inf ] || awk -v r="$ratio" -v m="$1" 'BEGIN { exit !(r >= m) }'; }
if at_least "$min_fall"; then
	tap_ok "OSCILLATOR: contact force falls clearly: $ratio x (>= $min_fall)"
else
	tap_fail "OSCILLATOR: contact force falls by >= $min_fall x" "before $before N, after $after N, ratio $ratio"
fi
if at_least "$min_ratio"; then
	tap_ok "OSCILLATOR: contact impulse per second falls by $ratio x (>= $min_ratio)"
else
	tap_todo "OSCILLATOR: contact impulse per second falls by >= $min_ratio x" "before $before N, after $after N, ratio $ratio"
fi
keep_runs out
tap_done
