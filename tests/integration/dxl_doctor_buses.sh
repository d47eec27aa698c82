#!/usr/bin/env bash
# dxl_doctor_buses — `dxl doctor --config FILE` for a robot on two buses
# ([robot] ids = 1,tail:2, [bus.tail]): without --bus it says the robot has
# two buses and how to check each (exit 2, nothing touched); with --bus NAME
# it checks that bus alone — its port, its servo, the joint's own limits —
# and a bus that does not exist is named with the ones that do.
. "$(dirname "$0")/../lib.sh"
dxl_sim_built
spawn simA "$sim" --link "$T/a.bus" --ids 1 --name ra --lcm-url "$(lcm_url 7612)" --quiet --return-delay 0
spawn simB "$sim" --link "$T/b.bus" --ids 2 --name rb --lcm-url "$(lcm_url 7612)" --quiet --return-delay 0
if ! wait_log simA 'ready' 10 || ! wait_log simB 'ready' 10; then
	tap_fail "simulators ready" "$(cat "$T/simA.log" "$T/simB.log")"; tap_done; exit 1
fi
printf '[robot]\nname = r\nport = %s\nids = 1, tail:2\n[bus.tail]\nport = %s\n' "$T/a.bus" "$T/b.bus" >"$T/r.conf"
doctor() {
	local name=$1; shift
	rc=0
	${_own_session[@]+"${_own_session[@]}"} timeout 60 "$dxl" doctor "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
}
show() { cat "$T/$1.out" "$T/$1.err"; echo "exit $rc"; }

doctor all --config "$T/r.conf" --cycles 0
if [ "$rc" -eq 2 ] && grep -q "dxl: the robot's joints are on 2 buses: doctor checks one at a time, with --bus NAME (robot ($T/a.bus), tail ($T/b.bus))" "$T/all.err"; then
	tap_ok "several buses without --bus: named, with how to check each (exit 2)"
else tap_fail "several buses without --bus" "$(show all)"; fi

for bus in robot tail; do
	id=1; other=2; [ "$bus" = tail ] && { id=2; other=1; }
	doctor "$bus" --config "$T/r.conf" --bus "$bus" --cycles 0
	if [ "$rc" -eq 0 ] && ! grep -qE '^(WARN|FAIL) ' "$T/$bus.out" && grep -qE "^OK +ID $id " "$T/$bus.out" &&
		! grep -qE "ID $other " "$T/$bus.out"; then
		tap_ok "--bus $bus: its servo $id checked, every line OK, exit 0"
	else tap_fail "--bus $bus" "$(show "$bus")"; fi
done

doctor none --config "$T/r.conf" --bus head --cycles 0
if [ "$rc" -eq 2 ] && grep -q "dxl: --bus: no bus 'head' with joints; the robot's buses: robot ($T/a.bus), tail ($T/b.bus)" "$T/none.err"; then
	tap_ok "--bus with a name the robot does not have: refused, the buses named"
else tap_fail "--bus head" "$(show none)"; fi
tap_done
