#!/usr/bin/env bash
# run.sh: alone — it measures a gait or an experiment in real time: nothing beside it (tests/run.sh)
# daemon_tune_plants.sh (make test-long) — undulated --tune on plants that
# differ: the simulator with its motor changed (return delay, load, friction,
# supply voltage, compliance), one joint, other targets, and the test plant
# unlike the simulator (tests/tools/plant.py) as a fast tracker and as a
# sluggish servo with a sensor delay. For each: what the starting parameters
# gave, what the tuned ones gave, windows and seconds. Asserted: every plant
# that can reach the target is tuned within 5 % (exit 0); at 7 V the target is
# out of reach and said so with what is reachable (exit 3, nothing written).
# Prints the table daemon/CONTROL.md quotes ("Tuning on the robot").
source "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"; X="$B/dxl"
PLANT="$top/tests/tools/plant.py"
[ -x "$D" ] && [ -x "$S" ] && [ -x "$X" ] || tap_skip_all "undulated, undulate-sim or dxl not built"
command -v python3 >/dev/null || tap_skip_all "python3 missing (the test plant)"

# name | plant | ids | targets (f a) | expect (0 tuned, 3 out of reach) | bus options | daemon options
variants=(
	"sim-default|sim --return-delay 0|1,2|0.8 0.8|0|"
	"sim-return-delay-500us|sim|1,2|0.8 0.8|0|"
	"sim-load-x3|sim --return-delay 0 --set motor.inertia=0.0132|1,2|0.8 0.8|0|"
	"sim-friction|sim --return-delay 0 --set motor.coulomb=0.05 --set motor.viscous=0.01|1,2|0.8 0.8|0|"
	"sim-9V|sim --return-delay 0 --voltage 9|1,2|0.8 0.8|0|"
	"sim-margin0|sim --return-delay 0|1,2|0.8 0.8|0|--set robot.compliance_margin=0"
	"sim-slope128|sim --return-delay 0 slope128|1,2|0.8 0.8|0|"
	"sim-one-joint|sim --return-delay 0|1|0.8 0.8|0|"
	"sim-1.0Hz-0.6rad|sim --return-delay 0|1,2|1.0 0.6|0|"
	"plant-fast-tracker|plant --gain 300 --tau 0.003|1,2|0.8 0.8|0|"
	"plant-sluggish-delayed|plant --gain 15 --tau 0.04 --delay-ms 10|1,2|0.8 0.8|0|"
	"sim-7V|sim --return-delay 0 --voltage 7|1,2|0.8 0.8|3|"
)
parallel=4

# tune_one INDEX: runs variant INDEX on its own bus and LCM port; leaves
# $T/<name>.result as "rc took windows | defaults | tuned"
tune_one() {
	local i=$1 name plant ids targets expect dopts
	IFS='|' read -r name plant ids targets expect dopts <<<"${variants[$i]}"
	local url; url=$(lcm_url $((7900 + i)))
	local kind=${plant%% *} opts=${plant#* } slope=0
	[ "$kind" = "$plant" ] && opts=""
	[[ "$opts" == *slope128* ]] && { slope=1; opts=${opts/slope128/}; }
	if [ "$kind" = sim ]; then
		spawn "bus$i" "$S" --link "$T/bus$i" --ids "$ids" --lcm-url "$url" --seed $((30 + i)) --duration 200 $opts
	else
		spawn "bus$i" timeout 200 python3 "$PLANT" --link "$T/bus$i" --ids "$ids" $opts
	fi
	wait_log "bus$i" 'ready' 10 || { echo "bus did not start" >"$T/$name.result"; return; }
	if [ "$slope" = 1 ]; then
		local id reg
		for id in ${ids//,/ }; do
			for reg in cw_compliance_slope ccw_compliance_slope; do
				"$X" --port "$T/bus$i" write "$id" "$reg" 128 >/dev/null 2>&1
			done
		done
	fi
	set -- $targets
	local start; start=$(date +%s)
	"$D" --tune --port "$T/bus$i" --ids "$ids" --robot "t$i" --lcm-url "$url" --target-freq "$1" \
		--target-amp "$2" --out "$T/$name.conf" -q $dopts >"$T/$name.log" 2>&1
	local rc=$?
	stop "bus$i" >/dev/null
	local took windows first tuned
	took=$(sed -n 's/^tune: done in \([0-9]*\) s (\([0-9]*\) windows).*/\1/p' "$T/$name.log")
	windows=$(sed -n 's/^tune: done in \([0-9]*\) s (\([0-9]*\) windows).*/\2/p' "$T/$name.log")
	first=$(grep -m1 -o 'window 1: [^(]*' "$T/$name.log" | sed 's/window 1: //; s/, joint 2 behind.*//')
	tuned=$(sed -n 's/.*measured with these parameters: //p' "$T/$name.conf" 2>/dev/null | sed 's/, joint 2 behind.*//')
	[ -n "$took" ] || took=$(( $(date +%s) - start ))
	echo "$rc|$took|${windows:--}|${first:--}|${tuned:--}" >"$T/$name.result"
}

n=${#variants[@]}
for ((i = 0; i < n; i += parallel)); do
	for ((j = i; j < i + parallel && j < n; j++)); do tune_one "$j" & done
	wait
done

echo "# | plant | targets | the starting parameters gave | tuned | windows | s |"
echo "# |---|---|---|---|---|---|"
for ((i = 0; i < n; i++)); do
	IFS='|' read -r name plant ids targets expect dopts <<<"${variants[$i]}"
	IFS='|' read -r rc took windows first tuned <"$T/$name.result"
	echo "# | $name | $targets | $first | $( [ "$rc" = 0 ] && echo "$tuned" || echo "exit $rc") | $windows | $took |"
	if [ "$rc" = "$expect" ] && [ "$expect" = 0 ]; then
		tap_ok "$name: tuned within 5 % of $targets ($tuned; $windows windows, $took s)"
	elif [ "$rc" = "$expect" ] && grep -q "out of reach" "$T/$name.log" && [ ! -e "$T/$name.conf" ]; then
		tap_ok "$name: out of reach, said with what is reachable: $(grep -o 'Reachable at that speed: .*; nothing' "$T/$name.log")"
	else
		tap_fail "$name: exit $expect" "exit $rc: $(tail -3 "$T/$name.log")"
	fi
done
tap_done
