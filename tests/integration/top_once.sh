#!/usr/bin/env bash
# undulate-top --once (JSON and text) against recorded traffic: a synthetic
# log with known content (undulate-analyze --synth) replayed by lcm-logplayer.
# The numbers undulate-top reports are checked against the log itself, read
# back by undulate-analyze, and against the values the log was built from.
. "$(dirname "$0")/../lib.sh"
url=$(lcm_url 7750)

command -v lcm-logplayer >/dev/null || { tap_fail "lcm-logplayer missing (liblcm-bin)"; tap_done; exit; }
command -v jq >/dev/null || { tap_fail "jq missing"; tap_done; exit; }

"$B/undulate-analyze" --synth "$T/t.log" --duration 2 >/dev/null
"$B/undulate-analyze" "$T/t.log" --out "$T/a" --quiet

spawn topjson "$B/undulate-top" --once --json --wait 4.5 --lcm-url "$url" -v
spawn toptext "$B/undulate-top" --once --wait 4.5 --lcm-url "$url" -v
wait_log topjson 'listening' && wait_log toptext 'listening' || tap_fail "undulate-top did not start"
lcm-logplayer --lcm-url="$url" "$T/t.log" >"$T/player.log" 2>&1
wait_for 10 bash -c "! kill -0 $pid_topjson 2>/dev/null && ! kill -0 $pid_toptext 2>/dev/null"
stop topjson >/dev/null; rc=$stop_rc
tap_check "--once exits 0" [ "$rc" = 0 ]

json=$(grep '^{' "$T/topjson.log")
tap_check "--once --json prints exactly one JSON object" [ "$(grep -c '^{' "$T/topjson.log")" = 1 ]
echo "$json" >"$T/snap.json"
# (jq -e succeeds on empty input: require the snapshot first)
j() { [ -s "$T/snap.json" ] && jq -e "$@" "$T/snap.json" >/dev/null; }

tap_check "four robots, ordered by SIM.TRUTH lateral position" \
	j '.nrobots == 4 and .order == "lateral" and ([.robots[].name] == ["r1","r2","r3","r4"])'
tap_check "loop rate 100 Hz and jitter p99 140 us from period_us/jitter_us" \
	j 'all(.robots[]; (.rate_hz - 100 | fabs) < 1e-6 and .jitter_p99_us == 140)'
tap_check "bus errors per robot (0, 3, 6, 9)" j '[.robots[].bus_errors] == [0,3,6,9]'
tap_check "mode OSCILLATOR" j 'all(.robots[]; .mode == "OSCILLATOR" and .mode_id == 3)'
tap_check "PARAMS heard: c and sinusoid amplitude" j 'all(.robots[]; .params.c == [0.02,0.02] and .params.amplitude == 0.8)'
tap_check "neighbour phase differences 0.4, pi, 2.0 (as built)" \
	j '(.neighbours[0].dphase - 0.4 | fabs) < 1e-9 and ((.neighbours[1].dphase | fabs) - 3.141592653589793 | fabs) < 1e-9 and (.neighbours[2].dphase - 2 | fabs) < 1e-9'
tap_check "joint phase difference -2 pi / 3" j 'all(.robots[]; (.dphase_joints + 2.0943951023931953 | fabs) < 1e-9)'
tap_check "collisions: 2 heard once each (SIM.COLLISION + SIM.TRUTH), impulse 0.003" \
	j '.sim.heard and .sim.collisions_heard == 2 and .sim.total_collisions == 2 and (.sim.total_impulse - 0.003 | fabs) < 1e-12 and .sim.collisions_10s == 2'
tap_check "replay over: robots marked stale, not dropped" j 'all(.robots[]; .stale == (.age_s > 1)) and .stale >= 1'

# the last r1/r4 joint-0 samples, as undulate-analyze read them from the log
for r in r1 r4; do
	row=$(grep "^[0-9]*,[0-9.]*,\"$r\",0," "$T/a/states.csv" | tail -1)
	angle=$(echo "$row" | cut -d, -f6)
	speed=$(echo "$row" | cut -d, -f7)
	utime=$(echo "$row" | cut -d, -f1)
	# the CSV carries 9 significant digits
	tap_check "$r joint 0 angle/speed/utime equal the log's last sample" \
		j --argjson a "$angle" --argjson s "$speed" --argjson u "$utime" \
		'.robots[] | select(.name == "'$r'") | (.joints[0].angle - $a | fabs) < 1e-8 and (.joints[0].speed - $s | fabs) < 1e-8 and .utime == $u'
done

tap_check "text snapshot lists every robot, stale, and the order" \
	bash -c "grep -q 'r1' '$T/toptext.log' && grep -q 'r4' '$T/toptext.log' && grep -q STALE '$T/toptext.log' && grep -q 'order: lateral' '$T/toptext.log'"
tap_check "text snapshot has no escape sequences" bash -c "! grep -q $'\033' '$T/toptext.log'"
tap_done
