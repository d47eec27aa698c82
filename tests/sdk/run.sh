#!/usr/bin/env bash
# tests/sdk/run.sh SDK_SOURCE_DIR — ROBOTIS's DynamixelSDK as a client of
# undulate-sim: code we did not write on the other end of the wire.
#
# SDK_SOURCE_DIR is a checkout of github.com/ROBOTIS-GIT/DynamixelSDK (or its
# c/ directory). Its C library is compiled from its sources into this test's
# scratch directory (under $TMPDIR, never inside this repository), then our
# clients tests/sdk/sdk_p1.c (Protocol 1.0, two AX-12A) and sdk_p2.c
# (Protocol 2.0, an XL430-W250 and an XM430-W350 on one bus) are built against
# it and run on a simulated bus each. Prints TAP. `make test-sdk DXL_SDK=DIR`
# runs it; `make test` does when DXL_SDK is set (tests/integration/sdk_client.sh).
. "$(dirname "$0")/../lib.sh"
here=$(cd "$(dirname "$0")" && pwd)
C="python3 -S $here/../integration/sim_client.py"
sdk=${1:-}
[ -n "$sdk" ] || tap_skip_all "no DynamixelSDK given: make test-sdk DXL_SDK=DIR (a checkout of https://github.com/ROBOTIS-GIT/DynamixelSDK)"
[ -d "$sdk/c/src/dynamixel_sdk" ] && sdk="$sdk/c"
src="$sdk/src/dynamixel_sdk" inc="$sdk/include/dynamixel_sdk"
if [ ! -f "$src/protocol2_packet_handler.c" ] || [ ! -f "$inc/dynamixel_sdk.h" ]; then
	tap_fail "DynamixelSDK sources in $1" "no $src/protocol2_packet_handler.c or $inc/dynamixel_sdk.h"
	tap_done; exit
fi
command -v gcc >/dev/null || tap_skip_all "no gcc"

# ---- the SDK's C library, built from its own sources (its Makefile's flags) ----------
lib="$T/sdk"
mkdir -p "$lib"
ok=1
for f in group_bulk_read group_bulk_write group_sync_read group_sync_write packet_handler port_handler \
         protocol1_packet_handler protocol2_packet_handler port_handler_linux; do
	gcc -O2 -DLINUX -D_GNU_SOURCE -w -I"$inc" -c "$src/$f.c" -o "$lib/$f.o" 2>>"$T/sdk-build.log" || ok=0
done
[ $ok = 1 ] && ar rcs "$lib/libdxl.a" "$lib"/*.o 2>>"$T/sdk-build.log" || ok=0
if [ $ok = 1 ]; then tap_ok "DynamixelSDK's C library built from $sdk (outside the repository)"
else tap_fail "DynamixelSDK's C library builds" "$(cat "$T/sdk-build.log")"; tap_done; exit; fi
# Our clients: our warning set; the SDK's headers are theirs (-isystem).
WARN="-Wall -Wextra -Wshadow -Wmissing-prototypes -Wstrict-prototypes -Wpointer-arith -Wcast-qual -Wundef -Wvla -Wformat-security -Werror"
for c in sdk_p1 sdk_p2; do
	if gcc -std=c11 -D_DEFAULT_SOURCE -D_XOPEN_SOURCE=700 -O2 $WARN -isystem "$inc" "$here/$c.c" "$lib/libdxl.a" \
		-lrt -o "$lib/$c" 2>"$T/$c-build.log"; then tap_ok "$c builds against it"
	else tap_fail "$c builds against it" "$(cat "$T/$c-build.log")"; fi
done

# ---- two buses: AX-12A at 1 Mbps, XL430 + XM430 at their factory 57600 ----------------
cat >"$T/sdk.scenario" <<EOT
[sim]
initial_spread = 0
[robot ax]
model = ax12a
ids = 3,4
contact = none
[robot x]
model = xl430-w250,xm430-w350
ids = 1,2
contact = none
[robot xc]
model = xc430-w150
ids = 5,6
contact = none
[robot fx]
model = xm430-w350
ids = 7,8,9
contact = none
[robot old]
model = xl430-w250
ids = 10,11
firmware = 44
contact = none
EOT
spawn sim "$B/undulate-sim" --scenario "$T/sdk.scenario" --link-dir "$T/bus" --control "$T/ctl" \
	--lcm-url "$(lcm_url 7698)" --seed 3
if ! wait_log sim 'ready:' 10; then tap_fail "sim ready" "$(cat "$T/sim.log")"; tap_done; exit; fi
tap_check "the ready line names the X bus's models" grep -q 'x.model=XL430-W250,XM430-W350' "$T/sim.log"

# run_client NAME ARGS...: its "ok"/"not ok" lines as TAP, its comments kept
run_client() {
	local name=$1; shift
	local rc=0 line n=0
	timeout 120 "$lib/$name" "$@" >"$T/$name.out" 2>&1 || rc=$?
	while IFS= read -r line; do
		case "$line" in
		"ok "*) tap_ok "$name: ${line#ok }"; n=$((n + 1)) ;;
		"not ok "*) tap_fail "$name: ${line#not ok }"; n=$((n + 1)) ;;
		*) echo "# $name: $line" ;;
		esac
	done <"$T/$name.out"
	if [ $rc -ne 0 ] || [ $n -lt 6 ]; then tap_fail "$name ran to its end" "exit $rc after $n checks"; fi
}
run_client sdk_p1 "$T/bus/ax" 3 4
run_client sdk_p2 "$T/bus/x" 1 2
# the model added as data only (protocol/dxl2_table.c), through the same SDK
run_client sdk_p2 "$T/bus/xc" --xc430 5 6

# ---- the Python SDK's Fast Sync Read / Fast Bulk Read (its C port has none) ----------
# Where the checkout has python/src and a python3 has pyserial (Debian:
# python3-serial): the one status packet of the fast reads, parsed by them.
py_src="${1%/}/python/src"; [ -d "$py_src" ] || py_src="${1%/}/../python/src"
py=""
for p in python3 /usr/bin/python3; do "$p" -c 'import serial' 2>/dev/null && { py=$p; break; }; done
if [ ! -d "$py_src/dynamixel_sdk" ] || [ -z "$py" ]; then
	echo "# the Python SDK's fast reads not tried: no $py_src/dynamixel_sdk or no python3 with pyserial (python3-serial)"
else
	for run in "fx fast 7 8 9" "old none 10 11"; do
		set -- $run
		while IFS= read -r line; do
			case "$line" in
			"ok "*) tap_ok "sdk_fast ($1): ${line#ok [0-9]* - }" ;;
			"not ok "*) tap_fail "sdk_fast ($1): ${line#not ok [0-9]* - }" ;;
			"1.."*) ;;
			*) echo "# sdk_fast: $line" ;;
			esac
		done < <(timeout 60 "$py" "$here/sdk_fast.py" "$py_src" "$T/bus/$1" 57600 "${@:2}" 2>&1)
	done
fi

# ---- what the simulator saw: every SDK packet parsed, nothing malformed ---------------
stop sim >/dev/null
grep '^undulate-sim: bus' "$T/sim.log" | sed 's/^/# /'
tap_check "bus ax: the SDK's 1.0 packets all well-formed (0 bad checksums, 0 header errors)" \
	grep -q 'bus ax: [0-9]* packets, [0-9]* replies, 0 bad checksums, 0 header errors' "$T/sim.log"
tap_check "bus x: the SDK's 2.0 packets all well-formed (0 bad CRCs, 0 bad stuffing, 0 header errors)" \
	grep -q 'bus x (Protocol 2.0): [0-9]* packets, [0-9]* replies, 0 bad CRCs, 0 bad stuffing, 0 header errors' "$T/sim.log"
tap_check "bus xc: the SDK's 2.0 packets to the XC430s all well-formed" \
	grep -q 'bus xc (Protocol 2.0): [0-9]* packets, [0-9]* replies, 0 bad CRCs, 0 bad stuffing, 0 header errors' "$T/sim.log"
tap_done
