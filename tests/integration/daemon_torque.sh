#!/usr/bin/env bash
# run.sh: realtime — it measures a gait in real time: its simulators and daemons under SCHED_FIFO where allowed, else alone (tests/run.sh)
# undulated with torque actuation against undulate-sim (daemon/README.md,
# "Torque actuation"): OSCILLATOR puts the servos in wheel mode and drives their
# output; the register traffic is read back from the simulator. Checked: a
# servo found in wheel mode is refused in position actuation and repaired in
# torque actuation; the starter runs in joint mode, then wheel mode with the
# law's duty (published as `drive`, goals NaN) and a limit cycle; HOLD goes
# back to joint mode holding where the joint is; the safe stop leaves no servo
# driving in wheel mode. And the clock as a torque law ([sinusoid] stiffness),
# in lockstep: at the paper's stiffest k undamped (the limit fault), damped
# (0.8 Hz, the 2pi/3 lag, the linear law's amplitude, then the oscillator in
# the same drive), at its softest (a small swing, measured).
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
R="t$$"
URL=$(lcm_url 7704)
peek() { local v; v=$(ctl peek r1 "$1" "$2"); echo "${v#ok }"; }
num() { awk "BEGIN { exit !($*) }"; }

spawn_rt sim "$S" --link "$T/bus" --ids 1 --name r1 --lcm-url "$URL" --control "$T/ctl" --seed 3
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"

# ---- a servo left in wheel mode, spinning
ctl poke r1 1 torque_enable 0 >/dev/null
ctl poke r1 1 cw_angle_limit 0 >/dev/null
ctl poke r1 1 ccw_angle_limit 0 >/dev/null
ctl poke r1 1 torque_enable 1 >/dev/null
ctl poke r1 1 moving_speed 200 >/dev/null
spawn_rt pos "$D" --port "$T/bus" --ids 1 --robot "$R" --lcm-url "$URL" --mode oscillator
wait_for 10 bash -c "! kill -0 $pid_pos" && stop pos
if [ "$stop_rc" != 0 ] && grep -q 'servo 1 is in wheel mode' "$T/pos.log"; then
	tap_ok "position actuation refuses a servo in wheel mode, saying so (exit $stop_rc)"
else tap_fail "position actuation refuses wheel mode" "exit $stop_rc: $(tail -3 "$T/pos.log")"; fi

spawn_rt d "$D" --port "$T/bus" --ids 1 --robot "$R" --lcm-url "$URL" --mode hold \
	--set robot.actuation=torque --set robot.torque_drive=pwm \
	--set joint.1.limit_min=-1.2 --set joint.1.limit_max=1.2
wait_log d "ready: $R.STATE" 10 || { tap_fail "daemon starts" "$(cat "$T/d.log")"; tap_done; exit 1; }
cw=$(peek 1 cw_angle_limit); ccw=$(peek 1 ccw_angle_limit); ms=$(peek 1 moving_speed)
# the configured limits +-1.2 rad in whole units inside: 512 -+ 234
if [ "$cw" = 278 ] && [ "$ccw" = 746 ] && [ "$ms" = 0 ] && grep -q 'servo 1 was in wheel mode: drive stopped' "$T/d.log"; then
	tap_ok "torque actuation repairs it: drive stopped, joint limits as angle limits ($cw..$ccw)"
else tap_fail "wheel mode repaired at start-up" "limits $cw..$ccw, moving speed $ms: $(grep -i wheel "$T/d.log")"; fi

# ---- OSCILLATOR: starter in joint mode, then wheel mode driven by the law
wait_for 5 sh -c "grep -q '^STATE $R ' '$T/watch.log'"
"$D" --command 'mode oscillator' --robot "$R" --lcm-url "$URL" >/dev/null
if event 'kind=actuation text="torque actuation: servos in wheel mode' 10; then
	tap_ok "after the starter the servos go into wheel mode (event)"
else tap_fail "into wheel mode" "$(grep "EVENT $R" "$T/watch.log" | tail -3)"; fi
if [ "$(peek 1 cw_angle_limit)/$(peek 1 ccw_angle_limit)" = 0/0 ] && [ "$(peek 1 torque_enable)" = 1 ]; then
	tap_ok "angle limits 0/0 on the servo, torque on"; else tap_fail "wheel mode on the servo" "$(peek 1 cw_angle_limit)/$(peek 1 ccw_angle_limit)"; fi
# 12 s of the law driving the joint: it swings, goals are NaN, drive is published
sleep_until() { local t0=$SECONDS; wait_for "$1" bash -c "[ \$((SECONDS - $t0)) -ge $1 ]"; }
sleep_until 12
lo=$(grep "^STATE $R " "$T/watch.log" | tail -500 | field a0 | sort -g | head -1)
hi=$(grep "^STATE $R " "$T/watch.log" | tail -500 | field a0 | sort -g | tail -1)
s=$(last_state); g=$(echo "$s" | field g0); dr=$(echo "$s" | field dr0)
if num "$hi - $lo > 1.0"; then tap_ok "the law swings the joint through torque: $lo .. $hi rad over 5 s"
else tap_fail "joint swings under torque actuation" "angle $lo .. $hi"; fi
if [ "$g" = nan ] || [ "$g" = -nan ]; then tap_ok "no goal published in wheel mode (goal NaN)"; else tap_fail "goal NaN in wheel mode" "g0=$g"; fi
# over the last second: every drive a number in [-1, 1], and the law does drive
# (a single sample may be 0: a joint without a reading that cycle gets none)
drives=$(grep "^STATE $R " "$T/watch.log" | tail -100 | field dr0)
rng=$(echo "$drives" | awk '{ v = $1 + 0; if ($1 !~ /^-?[0-9.]+$/ || v < -1 || v > 1) bad++; a = v < 0 ? -v : v; if (a > m) m = a }
	END { printf "%d %.4f", bad, m }')
if [ "${rng% *}" = 0 ] && num "${rng#* } > 0.01"; then tap_ok "drive published: within [-1, 1], up to ${rng#* } of full output"
else tap_fail "drive published" "non-numbers or out of range: ${rng% *}; largest |drive| ${rng#* }"; fi
if ! grep -q "kind=stall" "$T/watch.log"; then tap_ok "no stall restart"; else tap_fail "no stall restart" "$(grep kind=stall "$T/watch.log" | head -2)"; fi

# ---- HOLD: back to joint mode where the joint is
"$D" --command 'mode hold' --robot "$R" --lcm-url "$URL" >/dev/null
if event 'kind=actuation text="torque actuation: servos back in joint mode' 5; then
	tap_ok "HOLD: servos back in joint mode (event)"; else tap_fail "back to joint mode" "$(grep "EVENT $R" "$T/watch.log" | tail -3)"; fi
wait_for 3 bash -c "[ \"\$(echo 'peek r1 1 cw_angle_limit' | socat -t 2 - UNIX-CONNECT:$T/ctl)\" = 'ok 278' ]"
pos=$(peek 1 present_position); goal=$(peek 1 goal_position); ms=$(peek 1 moving_speed)
if [ "$(peek 1 cw_angle_limit)/$(peek 1 ccw_angle_limit)" = 278/746 ] && [ "$ms" = 0 ] && [ "$(peek 1 torque_enable)" = 1 ] &&
	num "$pos - $goal < 25 && $goal - $pos < 25"; then
	tap_ok "joint mode again: limits 278..746, moving speed 0, holding (present $pos, goal $goal)"
else tap_fail "joint mode holds" "limits $(peek 1 cw_angle_limit)/$(peek 1 ccw_angle_limit) speed $ms present $pos goal $goal"; fi

# ---- the safe stop from wheel mode
# the servo's own register says wheel mode (an event counted after the
# command may already be in the log before the count is taken)
said=$("$D" --command 'mode oscillator' --robot "$R" --lcm-url "$URL" --timeout 5 2>&1); said_rc=$?
wait_for 15 bash -c "[ \"\$(echo 'peek r1 1 ccw_angle_limit' | socat -t 2 - UNIX-CONNECT:$T/ctl)\" = 'ok 0' ]"
if [ "$(peek 1 ccw_angle_limit)" = 0 ]; then
	stop d
	lim="$(peek 1 cw_angle_limit)/$(peek 1 ccw_angle_limit)"; ms=$(peek 1 moving_speed); te=$(peek 1 torque_enable)
	if [ "$stop_rc" = 0 ] && [ "$lim" = 278/746 ] && [ "$ms" = 0 ] && [ "$te" = 1 ] &&
		grep -q 'safe stop: torque actuation ended' "$T/d.log"; then
		tap_ok "SIGTERM in wheel mode: drive stopped, joint mode back, holding (exit 0)"
	else tap_fail "safe stop from wheel mode" "exit $stop_rc, limits $lim, speed $ms, torque $te"; fi
else
	tap_fail "back in wheel mode before the stop" "ccw limit $(peek 1 ccw_angle_limit); the command said (exit $said_rc): $said; $(grep "EVENT $R" "$T/watch.log" | tail -4)"
	stop d
fi

# ---- the supply the servo reports ---------------------------------------------------------------
# The PWM drive scales with it. An audit faked it to 1.5 V on a servo running
# at 12 V: the drive scaled up eightfold and the joint reached 0.638 rad
# against a 0.6 limit before the limit fault latched. A supply no AX-12A runs
# at (1.5 V, 0, 25 V) is a fault that names it, latched before the drive
# starts; one it may run at (8.6 V: its rated 9..12 V less 5 %) drives; the
# joint stays inside +-0.6 rad either way.
spawn_rt d2 "$D" --port "$T/bus" --ids 1 --robot "$R" --lcm-url "$URL" --mode hold \
	--set robot.actuation=torque --set robot.torque_drive=pwm \
	--set joint.1.limit_min=-0.6 --set joint.1.limit_max=0.6
wait_log d2 "ready: $R.STATE" 10 || { tap_fail "daemon with +-0.6 rad starts" "$(cat "$T/d2.log")"; tap_done; exit 1; }
cmd() { "$D" --command "$1" --robot "$R" --lcm-url "$URL" --timeout 2 >/dev/null; }
# reads VOLTS: the daemon publishes the supply as read (v0, one decimal)
reads() { wait_for 5 _state_has " v0=$1 "; }
# widest_since N: the farthest the published angle got from neutral after line N
widest_since() { grep -a "^STATE $R " "$T/watch.log" | tail -n +"$1" | field a0 |
	awk '{ a = $1 < 0 ? -$1 : $1; if (a > m) m = a } END { printf "%.4f", m }'; }
for v in 1.5 0.0 25.0; do
	ctl fault r1 1 voltage "$v" >/dev/null
	if ! reads "$v"; then tap_fail "supply read as $v V" "not published: $(last_state | cut -c1-200)"; continue; fi
	from=$(grep -ac "^STATE $R " "$T/watch.log")
	cmd 'mode oscillator'
	if event "kind=supply text=\"servo 1 reads its supply as $v V, outside the AX-12A's 8.55..12.60 V" 5 &&
		wait_for 5 _state_has "mode=1 .*fault=\"servo 1 reads its supply as $v V"; then
		sleep_until 1
		w=$(widest_since "$from"); lim="$(peek 1 cw_angle_limit)/$(peek 1 ccw_angle_limit)"
		if num "$w <= 0.6" && [ "$lim" != 0/0 ]; then
			tap_ok "supply read as $v V: fault named and latched, HOLD in joint mode (servo angle limits $lim), joint within $w rad"
		else tap_fail "supply read as $v V: joint inside its limits, joint mode" "widest $w rad, servo angle limits $lim"; fi
	else tap_fail "supply read as $v V: a fault naming it" "$(events | tail -3)"; fi
	cmd clear
done
ctl fault r1 1 voltage 8.6 >/dev/null
reads 8.6
from=$(grep -ac "^STATE $R " "$T/watch.log")
n=$(grep -c 'servos in wheel mode' "$T/watch.log")
cmd 'mode oscillator'
sleep_until 8
w=$(widest_since "$from")
if [ "$(grep -c 'servos in wheel mode' "$T/watch.log")" -gt "$n" ] && num "$w <= 0.6 && $w > 0.3" &&
	! events | tail -n 20 | grep -q 'kind=limit' && [ "$(last_state | field mode)" = 3 ]; then
	tap_ok "supply read as 8.6 V (the servo at 12 V): driven in wheel mode for 8 s, widest $w rad, limits +-0.6 held"
else tap_fail "supply read as 8.6 V: limits held in wheel mode" "widest $w rad, mode $(last_state | field mode): $(events | tail -2)"; fi
# and read as 1.5 V while the law drives: latched at once, back to joint mode
from=$(grep -ac "^STATE $R " "$T/watch.log")
ctl fault r1 1 voltage 1.5 >/dev/null
if event 'kind=supply text="servo 1 reads its supply as 1.5 V' 5 &&
	event 'kind=actuation text="torque actuation: servos back in joint mode' 5; then
	sleep_until 1
	w=$(widest_since "$from")
	if num "$w <= 0.6"; then tap_ok "read as 1.5 V while driving: latched, back in joint mode, joint within $w rad"
	else tap_fail "read as 1.5 V while driving: limits held" "widest $w rad"; fi
else tap_fail "read as 1.5 V while driving: a fault naming it" "$(events | tail -3)"; fi
ctl clear r1 1 >/dev/null
stop d2

# ---- the clock as a torque law ([sinusoid] stiffness) ---------------------------------------------------
# The paper's force simulations drove the joints on the clock with
# tau = k (xbar(t) - x), k 0.015..0.135 N·m/rad. In lockstep (scripts/demo.sh,
# one two-joint robot: tests/scenarios/one-robot.scenario, seed 1), the
# simulated AX-12A's wheel mode as a current drive, measured from the published
# states. The joint's inertia (4.39e-3 kg·m², the rotor through the gearbox
# most of it) puts the stiff law's natural frequency at sqrt(k/I)/2pi =
# 0.88 Hz, next to the clock's 0.8: undamped, the joints resonate past their
# limits; with the tracking damping d the amplitude is the linear law's,
#   A |k + i d w| / |k - I w^2 + i (d + c_j) w|   (c_j 0.002: the link's own damping),
# and the soft law (natural 0.29 Hz) swings the joints little, against the clock
# (daemon/CONTROL.md, "The clock as a torque law").
scenario="$top/tests/scenarios/one-robot.scenario"
clock_run() {   # NAME SECONDS ARGS...: a lockstep run of the clock, kept in $T/NAME
	local name=$1 secs=$2; shift 2
	env BUILD="$BUILD" TMPDIR="$T" "$top/scripts/demo.sh" --lockstep --scenario "$scenario" \
		--lcm-url "$(lcm_url 7706)" --out "$T/$name" --start-mode sinusoid --seconds "$secs" --seed 1 \
		--daemon-set robot.actuation=torque --daemon-set robot.torque_drive=current --set motor.drive=current \
		"$@" >"$T/$name.out" 2>&1
}
clock_events() { tail -n +2 "$T/$1/events.csv" | cut -d, -f2,6-; }   # t,"kind","text"
val() { echo "$1" | grep "^$2 " | field "$3"; }
# linear_amp K D: the linear law's amplitude on the simulated joint at the clock's 0.8 rad, 0.8 Hz
linear_amp() { awk -v k="$1" -v d="$2" 'BEGIN { i = 4.39e-3; cj = 0.002; w = 2 * 3.14159265 * 0.8
	re = k - i * w * w; im = (d + cj) * w; printf "%.3f", 0.8 * sqrt(k * k + d * d * w * w) / sqrt(re * re + im * im) }'; }

if clock_run k135 20 --switch-at never --daemon-set sinusoid.stiffness=0.135; then
	ev=$(clock_events k135)
	widest=$(awk -F, 'NR > 1 { a = $6 < 0 ? -$6 : $6; if (a > m) m = a } END { printf "%.3f", m }' "$T/k135/states.csv")
	lt=$(echo "$ev" | awk -F, '$2 == "\"limit\"" { print $1; exit }')
	if [ -n "$lt" ] && num "$lt < 3" && echo "$ev" | grep -q '"mode","SINUSOID -> HOLD (fault: servo' &&
		echo "$ev" | grep -q 'servos back in joint mode (HOLD)' && num "$widest < 1.35"; then
		tap_ok "k 0.135, the paper's law undamped: resonance; the limit fault at $lt s holds it (HOLD in joint mode, widest $widest rad)"
	else tap_fail "k 0.135 undamped: the limit fault holds it" "limit at '${lt}' s, widest $widest rad: $(echo "$ev" | head -5)"; fi
else tap_fail "k 0.135: the lockstep run ended by itself" "$(tail -n 15 "$T/k135.out")"; fi

# the experiment in short: the clock (k 0.135, d 0.035) for 40 s, then the oscillator
if clock_run k135d 60 --switch-at 40 --daemon-set sinusoid.stiffness=0.135 --daemon-set sinusoid.damping=0.035; then
	m=$(csv_samples "$T/k135d" r1 2 | measure 15 40)
	echo "# k 0.135, d 0.035, 15..40 s: ${m//$'\n'/; } (linear law: $(linear_amp 0.135 0.035) rad)"
	want=$(linear_amp 0.135 0.035)
	f1=$(val "$m" j1 f); f2=$(val "$m" j2 f); a1=$(val "$m" j1 amean); a2=$(val "$m" j2 amean)
	lm=$(val "$m" lag mean); lsd=$(val "$m" lag sd); ln=$(val "$m" lag n)
	if [ "${ln:-0}" -ge 18 ] && num "$f1 > 0.79 && $f1 < 0.81 && $f2 > 0.79 && $f2 < 0.81 && $lm > 117 && $lm < 123 && $lsd < 2"; then
		tap_ok "k 0.135, d 0.035: the joints swing at $f1 Hz, joint 2 behind joint 1 by $lm deg (sd $lsd over $ln periods)"
	else tap_fail "k 0.135, d 0.035: 0.8 Hz with the 2pi/3 lag" "${m//$'\n'/; }"; fi
	if num "$a1 > 0.92 * $want && $a1 < 1.08 * $want && $a2 > 0.92 * $want && $a2 < 1.08 * $want"; then
		tap_ok "k 0.135, d 0.035: amplitudes $a1/$a2 rad, the linear law on the joint's inertia gives $want"
	else tap_fail "k 0.135, d 0.035: amplitude as the law and the inertia give ($want rad +- 8 %)" "${m//$'\n'/; }"; fi
	ev=$(clock_events k135d)
	after=$(echo "$ev" | awk -F, '$1 >= 39.9')
	o=$(csv_samples "$T/k135d" r1 3 | measure 45 60)
	echo "# after the switch, 45..60 s: ${o//$'\n'/; }"
	if echo "$after" | grep -q '"mode","SINUSOID -> OSCILLATOR' && ! echo "$after" | grep -q '"actuation"\|"limit"\|"stall"' &&
		num "$(val "$o" j1 amean) > 0.5 && $(val "$o" j2 amean) > 0.5"; then
		tap_ok "SINUSOID -> OSCILLATOR at 40 s: no servo mode switch (the drive kept), the oscillator swings $(val "$o" j1 amean)/$(val "$o" j2 amean) rad"
	else tap_fail "SINUSOID -> OSCILLATOR in the drive" "events after 40 s: $after; ${o//$'\n'/; }"; fi
else tap_fail "k 0.135, d 0.035: the lockstep run ended by itself" "$(tail -n 15 "$T/k135d.out")"; fi

# the paper's softest law: small, measured and reported; bounded by the frictionless linear law
if clock_run k015 45 --switch-at never --daemon-set sinusoid.stiffness=0.015; then
	m=$(csv_samples "$T/k015" r1 2 | measure 15 45)
	bound=$(linear_amp 0.015 0)
	echo "# k 0.015, 15..45 s: ${m//$'\n'/; } (linear law without friction: $bound rad)"
	f1=$(val "$m" j1 f); a1=$(val "$m" j1 amean); a2=$(val "$m" j2 amean); lm=$(val "$m" lag mean)
	if num "$f1 > 0.79 && $f1 < 0.81 && $a1 > 0.5 * $bound && $a1 < $bound && $a2 > 0.5 * $bound && $a2 < $bound && $lm > 110 && $lm < 130" &&
		! clock_events k015 | grep -q '"limit"'; then
		tap_ok "k 0.015: the joints swing $a1/$a2 rad at $f1 Hz, lag $lm deg (the law alone would give $bound: the link's friction takes the rest)"
	else tap_fail "k 0.015: a small swing at 0.8 Hz under the linear bound $bound rad" "${m//$'\n'/; }"; fi
else tap_fail "k 0.015: the lockstep run ended by itself" "$(tail -n 15 "$T/k015.out")"; fi
keep_runs k135 k135d k015
tap_done
