#!/usr/bin/env bash
# run.sh: realtime — it measures a gait in real time: its simulators and daemons under SCHED_FIFO where allowed, else alone (tests/run.sh)
# run.sh: timeout 420 (the test plant may take the tuner its 180 s)
# undulated --tune, through real processes:
#   - on the simulated robot and, at the same time, on a test plant unlike the
#     simulator (tests/tools/plant.py: its own protocol code, joints that
#     track the goal at a rated speed — the defaults run fast and wide there):
#     both reach 0.8 Hz and 0.8 rad within 5 % and write a configuration;
#   - the plant's configuration, run as it is (`undulated FILE`), gives that
#     gait: its joints' own published angles measured as daemon_limit_cycle
#     measures them;
#   - Ctrl-C (SIGINT) stops it with the joints holding (torque on), nothing
#     written; bad options and impossible targets are refused at once.
# A target out of the plant's reach found by running (the simulator at 7 V),
# and the sweep over motor parameters: tests/long/daemon_tune_plants.sh.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"; X="$B/dxl"
PLANT="$top/tests/tools/plant.py"
if [ ! -x "$S" ] || [ ! -x "$D" ] || [ ! -x "$X" ]; then
	tap_skip_all "undulate-sim, undulated or dxl not built"
fi
command -v python3 >/dev/null || tap_skip_all "python3 missing (the test plant)"
URL_SIM=$(lcm_url 7720)
URL_PLANT=$(lcm_url 7721)
URL_INT=$(lcm_url 7723)

# ---- refused at once --------------------------------------------------------------------
out=$("$D" --tune --ids 1,2 2>&1); rc=$?
[ "$rc" = 2 ] && [[ "$out" == *"--port PATH"* ]] && tap_ok "--tune without a port: exit 2, says which option" ||
	tap_fail "--tune without a port: exit 2" "exit $rc: $out"
out=$("$D" --tune --port "$T/none" --ids 1,2 --target-freq abc 2>&1); rc=$?
[ "$rc" = 2 ] && [[ "$out" == *"--target-freq"* ]] && tap_ok "--target-freq abc: exit 2" ||
	tap_fail "--target-freq abc: exit 2" "exit $rc: $out"
out=$("$D" --port "$T/none" --ids 1,2 --out "$T/x.conf" 2>&1); rc=$?
[ "$rc" = 2 ] && [[ "$out" == *"go with --tune"* ]] && tap_ok "--out without --tune: exit 2" ||
	tap_fail "--out without --tune: exit 2" "exit $rc: $out"
# 2 Hz at 0.8 rad needs 10 rad/s: more than an AX-12's no-load speed
out=$("$D" --tune --port "$T/none" --ids 1,2 --target-freq 2 --out "$T/x.conf" 2>&1); rc=$?
[ "$rc" = 2 ] && [[ "$out" == *"no-load speed"* ]] && [[ "$out" == *"reaches about"* ]] && [ ! -e "$T/x.conf" ] &&
	tap_ok "a target faster than the servo: exit 2 before any motion, with what it reaches" ||
	tap_fail "a target faster than the servo: exit 2 with what it reaches" "exit $rc: $out"
# the configuration decides where a joint may go: 1.0 rad does not fit in +-0.9
out=$("$D" --tune --port "$T/none" --ids 1,2 --set joint.1.limit_max=0.9 --target-amp 1.0 --out "$T/x.conf" 2>&1); rc=$?
[ "$rc" = 2 ] && [[ "$out" == *"joint 1's limits"* ]] && tap_ok "an amplitude outside the joint limits: exit 2" ||
	tap_fail "an amplitude outside the joint limits: exit 2" "exit $rc: $out"

# ---- the simulator and the test plant, tuned at the same time ---------------------------
spawn_rt sim "$S" --link "$T/sim" --ids 1,2 --lcm-url "$URL_SIM" --seed 21 --return-delay 0
# the plant the audit described: joints that reach the goal at once up to the rated speed
# A servo is hardware: the CPU around it never makes it late. The Python plant
# is a process, and on a loaded machine it missed replies (READ timeouts) and
# the tuner's windows wandered (0.66..0.97 Hz at load 10-13, no result): it
# runs ahead of the rest where that is allowed (spawn_rt: SCHED_FIFO, as the
# simulator and the daemons; where it is not, the runner runs this test alone).
spawn_rt plant python3 "$PLANT" --link "$T/plant" --ids 1,2 --gain 300 --tau 0.003
wait_log sim 'ready' 10 && wait_log plant 'ready' 10 ||
	{ tap_fail "simulator and plant ready" "$(cat "$T/sim.log" "$T/plant.log")"; tap_done; exit 1; }
spawn_rt tsim "$D" --tune --port "$T/sim" --ids 1,2 --robot tsim --lcm-url "$URL_SIM" --out "$T/tsim.conf" -q
# The plant gets more than the default 90 s: its Python loop misses replies
# now and then (READ timeouts), a disturbed window (0.51 Hz once) costs two
# more, and one make test run ended "no result in 90 s (11 windows); closest:
# 0.800 Hz, A 0.798/0.798 rad", on target but not yet confirmed.
spawn_rt tplant "$D" --tune --port "$T/plant" --ids 1,2 --robot tplant --lcm-url "$URL_PLANT" --out "$T/tplant.conf" -q \
	--tune-time 180
wait_for 240 bash -c "! kill -0 $pid_tsim 2>/dev/null && ! kill -0 $pid_tplant 2>/dev/null"
wait "$pid_tsim"; rc_sim=$?
wait "$pid_tplant"; rc_plant=$?

# "f a1 a2" from a tuned file's header line "measured with these parameters: F Hz, A A1/A2 rad"
measured() { sed -n 's/.*measured with these parameters: \([0-9.]*\) Hz, A \([0-9.]*\)\/\([0-9.]*\) rad.*/\1 \2 \3/p' "$1"; }
started() { sed -n 's/.*started from gave \([0-9.]*\) Hz, A \([0-9.]*\)\/\([0-9.]*\) rad.*/\1 \2 \3/p' "$1"; }
near() { awk -v v="$1" -v t="$2" -v tol="$3" 'BEGIN { d = v / t - 1; if (d < 0) d = -d; exit !(d <= tol) }'; }
tuned_ok() {   # NAME: exit 0, a file, its measured gait within 5 % of 0.8 Hz / 0.8 rad
	local name=$1 rc=$2 m
	m=$(measured "$T/$name.conf")
	echo "# $name: $(grep -E '^tune: +[0-9.]+ s|^tune: done' "$T/$name.log" | tr '\n' ';' | cut -c1-900)"
	echo "# $name: defaults gave $(started "$T/$name.conf"), tuned $(echo "$m") (f a1 a2)"
	[ "$rc" = 0 ] && [ -n "$m" ] && set -- $m && near "$1" 0.8 0.05 && near "$2" 0.8 0.05 && near "$3" 0.8 0.05
}
if tuned_ok tsim "$rc_sim"; then
	tap_ok "simulator: tuned to 0.8 Hz, 0.8 rad within 5 % ($(measured "$T/tsim.conf")) in $(sed -n 's/^tune: done in \([0-9]*\) s.*/\1/p' "$T/tsim.log") s"
else
	tap_fail "simulator: tuned to 0.8 Hz, 0.8 rad within 5 %" "exit $rc_sim: $(tail -5 "$T/tsim.log")"
fi
if tuned_ok tplant "$rc_plant"; then
	tap_ok "test plant: tuned to 0.8 Hz, 0.8 rad within 5 % ($(measured "$T/tplant.conf")) in $(sed -n 's/^tune: done in \([0-9]*\) s.*/\1/p' "$T/tplant.log") s"
else
	tap_fail "test plant: tuned to 0.8 Hz, 0.8 rad within 5 %" "exit $rc_plant: $(tail -5 "$T/tplant.log")"
fi
# the plant is not the simulator: the defaults run it wide (the audit: 1.07 Hz,
# 1.23-1.30 rad; the simulator's 0.85 rad). Fast too on an idle machine (1.06
# Hz), but its Python loop slows with the machine: 0.905 Hz beside two CPU-bound
# processes (make test-busy, 2026-11-27), still 1.29 rad wide.
s=$(started "$T/tplant.conf")
if [ -n "$s" ] && set -- $s && awk -v a="$2" -v b="$3" 'BEGIN { exit !(a > 1.0 && b > 1.0) }'; then
	tap_ok "test plant: the defaults gave another gait there ($s: f a1 a2)"
else
	tap_fail "test plant: the defaults gave another gait there (A > 1.0 rad on both joints)" "started: '$s'"
fi
# the SINUSOID baseline is the gait measured
m=$(measured "$T/tplant.conf")
base_f=$(sed -n '/^\[sinusoid\]/,$ s/^frequency = //p' "$T/tplant.conf")
base_a=$(sed -n '/^\[sinusoid\]/,$ s/^amplitude = //p' "$T/tplant.conf")
if [ -n "$m" ] && set -- $m && near "$base_f" "$1" 0.002 && near "$base_a" "$(awk -v a="$2" -v b="$3" 'BEGIN { print (a + b) / 2 }')" 0.002; then
	tap_ok "test plant: [sinusoid] set to the gait measured ($base_f Hz, $base_a rad)"
else
	tap_fail "test plant: [sinusoid] set to the gait measured" "measured '$m', sinusoid $base_f Hz $base_a rad"
fi

# ---- the plant's file, run as it is --------------------------------------------------------
out=$("$D" "$T/tplant.conf" --check-config 2>&1)
tap_check "the written file passes --check-config ($out)" grep -q "mode OSCILLATOR" <<<"$out"
spawn watch "$D" --watch tplant --raw --lcm-url "$URL_PLANT"
spawn_rt run "$D" "$T/tplant.conf" -q
# ---- Ctrl-C ---------------------------------------------------------------------------------
spawn_rt simint "$S" --link "$T/int" --ids 1,2 --lcm-url "$URL_INT" --seed 23 --return-delay 0
wait_log simint 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/simint.log")"; tap_done; exit 1; }
spawn_rt tint "$D" --tune --port "$T/int" --ids 1,2 --robot tint --lcm-url "$URL_INT" --out "$T/tint.conf" -q
# Ctrl-C once it has measured a window
if wait_log tint '^tune: .* window 1' 40; then
	kill -INT "$pid_tint"
	wait_for 10 bash -c "! kill -0 $pid_tint 2>/dev/null"
	wait "$pid_tint"; rc=$?
	torque=$("$X" --port "$T/int" read 1 torque_enable 2>&1)
	if [ "$rc" = 130 ] && grep -q "nothing written" "$T/tint.log" && [ ! -e "$T/tint.conf" ] &&
		[ -z "$(ls -A "$T" | grep -E '^\.?tint\.conf\.')" ] && [ "$torque" = 1 ]; then
		tap_ok "Ctrl-C: exit 130, nothing written (no temporary left), joints holding (torque on)"
	else
		tap_fail "Ctrl-C: exit 130, nothing written, joints holding" "exit $rc, torque: $torque; $(tail -3 "$T/tint.log"); $(ls "$T")"
	fi
else
	tap_fail "Ctrl-C: the tuner measured a window first" "$(tail -5 "$T/tint.log")"
fi
if wait_log run 'ready' 10 || wait_for 10 grep -q "^STATE tplant " "$T/watch.log"; then
	# 6 s to settle (starter, then the cycle), 10 s measured
	past_1600() { [ "$(awk '$1 == "STATE" && $2 == "tplant" { c = $3 } END { sub("cycle=", "", c); print c + 0 }' "$T/watch.log")" -ge 1600 ]; }
	wait_for 40 past_1600
	m=$(samples tplant watch | measure 6 16)
	echo "# run from the file, cycles 600..1600: ${m//$'\n'/; }"
	ok=1
	for j in 1 2; do
		line=$(echo "$m" | grep "^j$j ")
		f=$(echo "$line" | sed -n 's/.* f=\([0-9.]*\).*/\1/p'); amin=$(echo "$line" | sed -n 's/.* amin=\([0-9.]*\).*/\1/p')
		amax=$(echo "$line" | sed -n 's/.* amax=\([0-9.]*\).*/\1/p')
		# 10 %: the tuner stops within 5 % of a window, and the plant's gait
		# moves between runs (tuned 0.819 Hz, the file run 0.871 Hz once)
		{ near "${f:-0}" 0.8 0.10 && near "${amin:-0}" 0.8 0.12 && near "${amax:-0}" 0.8 0.12; } || ok=0
	done
	[ "$ok" = 1 ] && tap_ok "the plant's file, run as it is: 0.8 Hz and 0.8 rad (within 10 %, every cycle within 12 %)" ||
		tap_fail "the plant's file, run as it is: 0.8 Hz and 0.8 rad" "$m"
else
	tap_fail "the plant's file, run as it is, starts" "$(tail -5 "$T/run.log")"
fi
stop run >/dev/null
stop watch >/dev/null
stop plant >/dev/null

tap_done
