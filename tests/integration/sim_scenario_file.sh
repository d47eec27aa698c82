#!/usr/bin/env bash
# sim_scenario_file.sh — what --scenario accepts: only a regular file of at
# most 1 MiB. Anything else (/dev/zero, a FIFO nobody writes to, a directory,
# a huge file, binary bytes, a missing path) is refused at once with one line
# naming the path and why, and exit status 2. Every run is under `timeout`:
# a regression that blocks (a FIFO's open, /dev/zero's endless read) fails
# here instead of hanging the suite.
. "$(dirname "$0")/../lib.sh"
S="$B/undulate-sim"
URL=$(lcm_url 7654)

# refused NAME PATH REGEX: exit 2 within 5 s, one stderr line naming PATH and matching REGEX
refused() {
	local name=$1 path=$2 want=$3 rc
	timeout -k 2 5 "$S" --scenario "$path" --link-dir "$T/links" --lcm-url "$URL" --duration 0.2 \
		>"$T/out.log" 2>"$T/err.log"
	rc=$?
	if [ "$rc" = 124 ] || [ "$rc" = 137 ]; then tap_fail "$name" "still running after 5 s (blocked)"; return; fi
	local lines; lines=$(wc -l <"$T/err.log")
	if [ "$rc" = 2 ] && [ "$lines" = 1 ] && grep -qF -- "$path" "$T/err.log" && grep -qE -- "$want" "$T/err.log" \
		&& [ ! -s "$T/out.log" ]; then
		tap_ok "$name: exit 2, '$(cat "$T/err.log")'"
	else
		tap_fail "$name" "rc $rc, stderr: $(cat "$T/err.log"), stdout: $(head -c 300 "$T/out.log")"
	fi
}

refused "/dev/zero" /dev/zero "not a regular file"
mkfifo "$T/fifo"
refused "a FIFO with no writer" "$T/fifo" "not a regular file"
mkdir "$T/dir"
refused "a directory" "$T/dir" "not a regular file"
refused "/dev/null" /dev/null "not a regular file"
truncate -s 2M "$T/huge.scenario"
refused "a 2 MiB file" "$T/huge.scenario" "larger than 1 MiB"
printf '[sim]\nseed = 1\n\0\0[robot a]\nids = 1\n' >"$T/nul.scenario"
refused "NUL bytes in the file" "$T/nul.scenario" "NUL"
refused "a missing file" "$T/nonexistent.scenario" "No such file"
chmod 000 "$T/dir"
if [ ! -r "$T/dir" ]; then   # root reads it anyway
	printf '[robot a]\nids = 1\n' >"$T/unreadable.scenario"; chmod 000 "$T/unreadable.scenario"
	refused "an unreadable file" "$T/unreadable.scenario" "Permission denied"
fi
chmod 755 "$T/dir"

# a symlink to a regular file is fine, and so is a file of exactly 1 MiB
printf '[robot a]\nids = 1\n' >"$T/ok.scenario"
ln -s "$T/ok.scenario" "$T/link.scenario"
timeout -k 2 10 "$S" --scenario "$T/link.scenario" --link-dir "$T/links" --lcm-url "$URL" --duration 0.2 --quiet \
	>"$T/ok.log" 2>&1; rc=$?
if [ "$rc" = 0 ] && grep -q 'ready:' "$T/ok.log"; then tap_ok "a symlink to a scenario runs"
else tap_fail "a symlink to a scenario runs" "rc $rc: $(cat "$T/ok.log")"; fi
{ printf '[robot a]\nids = 1\n'; head -c $(( 1048576 - 18 )) /dev/zero | tr '\0' '\n'; } >"$T/mib.scenario"
size=$(stat -c %s "$T/mib.scenario")
timeout -k 2 10 "$S" --scenario "$T/mib.scenario" --link-dir "$T/links" --lcm-url "$URL" --duration 0.2 --quiet \
	>"$T/ok.log" 2>&1; rc=$?
if [ "$size" = 1048576 ] && [ "$rc" = 0 ] && grep -q 'ready:' "$T/ok.log"; then tap_ok "a scenario of exactly 1 MiB runs"
else tap_fail "a scenario of exactly 1 MiB runs" "size $size, rc $rc: $(cat "$T/ok.log")"; fi
# the command line carries a long run's schedule: scripts/demo.sh --lockstep
# writes a --set per contact sample (every 5 s) and one for the switch, 62 for
# 300 s, which the simulator once refused ("too many settings", over 60)
sets=(); for t in $(seq 0 5 600); do sets+=(--set "events.$t=stats"); done
timeout -k 2 10 "$S" --scenario "$T/ok.scenario" --link-dir "$T/links" --lcm-url "$URL" --duration 0.2 --quiet \
	"${sets[@]}" >"$T/ok.log" 2>&1; rc=$?
if [ "$rc" = 0 ] && grep -q "t=0.000 event 'stats': ok" "$T/ok.log"; then tap_ok "121 --set events on the command line are taken"
else tap_fail "121 --set events on the command line" "rc $rc: $(head -3 "$T/ok.log")"; fi
sets=(); for t in $(seq 0 600); do sets+=(--set "events.$t=stats"); done
timeout -k 2 10 "$S" --scenario "$T/ok.scenario" --link-dir "$T/links" --lcm-url "$URL" --duration 0.2 --quiet \
	"${sets[@]}" >"$T/ok.log" 2>&1; rc=$?
if [ "$rc" = 2 ] && grep -q "too many settings (at most 576" "$T/ok.log"; then tap_ok "601 --set options: refused with the limit named"
else tap_fail "601 --set options refused" "rc $rc: $(head -3 "$T/ok.log")"; fi
tap_done
