#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# undulate-web against two daemons on the simulated bus: GET /api/snapshot is
# undulate-top --once --json's object; other methods, oversized and garbage
# requests are refused and the server lives on; a browser that stops reading
# is skipped, not queued for (memory stays bounded, other browsers keep their
# frames); --read-only and the network rules hold; and headless chromium
# draws the page (its screenshot has the plots' pixels), clicks a robot's mode
# button, the daemon changes mode and its answer appears on the page.
. "$(dirname "$0")/../lib.sh"
W="$B/undulate-web" D="$B/undulated" S="$B/undulate-sim"
CDP="$(dirname "$0")/web_cdp.py"
[ -x "$W" ] || tap_skip_all "undulate-web not built"
for t in curl jq python3; do command -v $t >/dev/null || tap_skip_all "$t missing"; done
URL=$(lcm_url 7790)

start_pair

# ---- the network rules: loopback unless said otherwise, then a secret --------------
"$W" --listen 0.0.0.0:0 --lcm-url "$URL" >"$T/remote.out" 2>&1; rc=$?
tap_check "a non-loopback address without --allow-remote: refused (exit 2), and says why" \
	bash -c "[ $rc = 2 ] && grep -q -- '--allow-remote' '$T/remote.out'"
"$W" --listen 0.0.0.0:0 --allow-remote --lcm-url "$URL" >"$T/remote2.out" 2>&1; rc=$?
tap_check "--allow-remote without --token-file or --read-only: refused (exit 2)" \
	bash -c "[ $rc = 2 ] && grep -q -- '--token-file' '$T/remote2.out'"

spawn web "$W" --listen 127.0.0.1:0 --lcm-url "$URL"
wait_log web 'listening on http://' 10 || { tap_fail "undulate-web listening" "$(cat "$T/web.log")"; tap_done; exit 1; }
port=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/web.log")
H="http://127.0.0.1:$port"
# the token it made: commands need it (the URL it printed carries it)
token_of() { sed -n 's|.*open http://[^ ]*/#token=\([A-Za-z0-9_.~-]*\) .*|\1|p' "$T/$1.log"; }
wait_log web 'open http://.*#token=' 5
# both robots heard (the snapshot lists them)
wait_for 10 bash -c "curl -s '$H/api/snapshot' | jq -e '.nrobots == 2' "

# ---- GET /api/snapshot is undulate-top --once --json -------------------------------
curl -s "$H/api/snapshot" >"$T/snap.json"
"$B/undulate-top" --once --json --wait 1.5 --lcm-url "$URL" >"$T/top.json"
tap_check "/api/snapshot: the same keys as undulate-top --once --json" \
	bash -c "[ \"\$(jq -c keys '$T/snap.json')\" = \"\$(jq -c keys '$T/top.json')\" ]"
tap_check "/api/snapshot: the same robots, each with the same keys, and the same pairs" \
	bash -c "[ \"\$(jq -c '[.robots[] | {name, k: keys, j: (.joints[0] | keys)}], [.neighbours[] | [.a, .b]], (.sim | keys)' '$T/snap.json')\" = \
	           \"\$(jq -c '[.robots[] | {name, k: keys, j: (.joints[0] | keys)}], [.neighbours[] | [.a, .b]], (.sim | keys)' '$T/top.json')\" ]"
tap_check "/api/snapshot: both robots in OSCILLATOR at ~100 Hz" \
	bash -c "jq -e '[.robots[].name] == [\"left\",\"right\"] and all(.robots[]; .mode == \"OSCILLATOR\" and .rate_hz > 90)' '$T/snap.json' >/dev/null"

# ---- refused requests, and the server lives on ------------------------------------------
code() { curl -s -o /dev/null -w '%{http_code}' "$@"; }
tap_check "POST /api/snapshot: 405" [ "$(code -X POST -d x=1 "$H/api/snapshot")" = 405 ]
tap_check "HEAD /api/snapshot: 405 (GET only)" [ "$(code -I "$H/api/snapshot")" = 405 ]
tap_check "GET /nothing: 404; GET /../etc/passwd: 404" \
	bash -c "[ \"\$(curl -s -o /dev/null -w '%{http_code}' '$H/nothing')\" = 404 ] && [ \"\$(curl -s --path-as-is -o /dev/null -w '%{http_code}' '$H/../etc/passwd')\" != 200 ]"
big=$(head -c 9000 /dev/zero | tr '\0' a)
c=$(code -H "X-Big: $big" "$H/api/snapshot")
tap_check "a request with 9000 bytes of headers is refused (got $c)" [ "$c" != 200 ]
python3 -c "
import socket; s = socket.create_connection(('127.0.0.1', $port)); s.sendall(b'\x16\x03\x01garbage\r\n\r\nGET\x00 / HTTP/9\r\n\r\n')
s.settimeout(3)
try: print(s.recv(200))
except Exception as e: print(e)" >"$T/garbage.out" 2>&1
tap_check "a garbage request gets no 200" bash -c "! grep -q ' 200 ' '$T/garbage.out'"
tap_check "after them, the page and the snapshot are still served" \
	bash -c "[ \"\$(curl -s -o /dev/null -w '%{http_code}' '$H/')\" = 200 ] && curl -s '$H/api/snapshot' | jq -e '.nrobots == 2' >/dev/null"
tap_check "the page's Chart.js is Debian's libjs-chart.js, served from its installed path" \
	bash -c "curl -s '$H/chart.js' | cmp -s - /usr/share/javascript/chart.js/chart.min.js"

# ---- a browser that stops reading ---------------------------------------------------------
rss() { awk '/^VmRSS/ { print $2 }' "/proc/$pid_web/status"; }
rss0=$(rss)
spawn slow python3 "$CDP" slow 127.0.0.1 "$port" 14
wait_log slow 'SLOW connected' 10
python3 "$CDP" frames 127.0.0.1 "$port" 8 >"$T/frames.out" 2>&1
rss1=$(rss)
nframes=$(awk '/^FRAMES/ { print $2 }' "$T/frames.out")
skipped=$(sed -n 's/^SERVER //p' "$T/frames.out" | jq '.frames_skipped')
echo "# VmRSS $rss0 kB -> $rss1 kB with a browser that does not read; $(head -1 "$T/frames.out"); skipped $skipped"
tap_check "another browser meanwhile gets >= 10 frames per second ($nframes in 8 s)" [ "${nframes:-0}" -ge 80 ]
tap_check "the one that does not read is skipped ($skipped frames skipped), not queued for" [ "${skipped:-0}" -gt 20 ]
tap_check "memory stays bounded: VmRSS grew $(( ${rss1:-0} - ${rss0:-0} )) kB (< 8 MB)" [ $(( ${rss1:-0} - ${rss0:-0} )) -lt 8192 ]

# ---- --read-only ------------------------------------------------------------------------------
spawn webro "$W" --listen 127.0.0.1:0 --lcm-url "$URL" --read-only
wait_log webro 'listening on http://' 10
roport=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/webro.log")
python3 "$CDP" say 127.0.0.1 "$roport" "cmd 1 left mode limp" >"$T/ro.out" 2>&1
tap_check "--read-only refuses a command: $(cat "$T/ro.out")" grep -q '^NOTE refused read-only' "$T/ro.out"
python3 "$CDP" say 127.0.0.1 "$port" "cmd 2 left param k 50 0" >"$T/bad.out" 2>&1
tap_check "a command out of range is refused before it is sent: $(cat "$T/bad.out")" \
	grep -q '^NOTE refused parameter k: 50 out of range' "$T/bad.out"
tap_check "no LIMP reached the robot" bash -c "! grep -q '^STATE left .* mode=0' '$T/watch.log'"
# one range per parameter (common/params.h): the daemon's words, here and on the page
python3 "$CDP" say 127.0.0.1 "$port" "cmd 3 left param amplitude 2.65" >"$T/amp.out" 2>&1
tap_check "amplitude 2.65 refused with the daemon's range: $(cat "$T/amp.out")" \
	grep -q '^NOTE refused parameter amplitude: 2.65 out of range 0..2.618$' "$T/amp.out"
curl -s "$H/api/params" >"$T/params.json"
tap_check "/api/params serves the table: amplitude $(jq -c '.[] | select(.name == "amplitude")' "$T/params.json")" \
	jq -e '(.[] | select(.name == "amplitude") | .range == "0..2.618" and .unit == "rad" and .step == 0.05)
		and ([.[].name] | index("stiffness") != null and index("neutral") == null)' "$T/params.json"

# ---- headless chromium: the page draws, a click commands a robot -------------------------------
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
	tap_skip "headless chromium draws the page and commands a robot" \
		"no chromium here (Debian package chromium; scripts/deps.sh chromium)"
else
	dport=$(python3 "$CDP" freeport)
	# its own TMPDIR: chromium leaves a singleton folder there even after SIGTERM
	spawn chromium env TMPDIR="$T" "$browser" --headless=new --no-sandbox --disable-gpu --no-first-run --user-data-dir="$T/chromium" \
		--remote-debugging-port="$dport" about:blank
	python3 "$CDP" page "$dport" "$H/#token=$(token_of web)" "$T/page.png" left hold >"$T/page.out" 2>&1
	sed 's/^/# /' "$T/page.out"
	drawn=$(awk '/^DRAWN/ { print $2 }' "$T/page.out")
	tap_check "the page draws both robots and their pair (${drawn:-0} points in its plots)" \
		bash -c "[ '${drawn:-0}' -gt 500 ] && grep -q '^ROBOTS left,right' '$T/page.out'"
	tap_check "the pair's end state is shown, named as undulate-analyze names it" \
		grep -qE '^CLASS (in-phase|anti-phase|compatible|grazing|still-colliding|unlocked|locked-[a-z-]+|not-oscillating|no-data)$' "$T/page.out"
	blue=$("$BUILD/tests/tools/pngdata" --rgb 1f77b4 "$T/page.png" 2>&1 | sed -n 's/.*matching=//p')
	tap_check "the screenshot shows drawn plots (${blue:-0} pixels of joint 0's colour, > 1500)" [ "${blue:-0}" -gt 1500 ]
	tap_check "the click reached the daemon: left publishes HOLD" wait_for 5 grep -q '^STATE left .* mode=1 ' "$T/watch.log"
	tap_check "the robot's answer is on the page: $(grep '^ANSWER' "$T/page.out")" \
		grep -q '^ANSWER command-accepted .*left command-accepted: mode HOLD' "$T/page.out"
	tap_check "the page shows left in HOLD" grep -q '^MODE_SHOWN HOLD' "$T/page.out"
	tap_check "the page's parameters and ranges are the server's: $(grep '^PARAM_RANGE' "$T/page.out")" \
		grep -qE '^PARAM_RANGE k,c,.*amplitude,.*stiffness,damping range 0\.\.2\.618 rad, step 0\.05' "$T/page.out"
	tap_check "the page's amplitude 2.65 refused with the same range: $(grep '^PARAM_REFUSED' "$T/page.out")" \
		grep -q '^PARAM_REFUSED .*refused: parameter amplitude: 2.65 out of range 0..2.618$' "$T/page.out"
	python3 "$CDP" view "$dport" "$H/" "$T/watch.png" >"$T/view.out" 2>&1
	tap_check "without the token the page watches: no command buttons, and says how to get them ($(cat "$T/view.out"))" \
		grep -q '^VIEW commands=False watching=True buttons=0$' "$T/view.out"
	if [ "$_tap_failed" -gt 0 ] || [ -n "${WEB_KEEP_SCREENSHOT:-}" ]; then mkdir -p "$BUILD/test-logs" && cp "$T/page.png" "$BUILD/test-logs/web_dashboard.png"; cp "$T/watch.png" "$BUILD/test-logs/web_dashboard_watch.png"; fi
fi

# ---- --key: signed over LCM, to a robot that takes commands from the network only --------------
URLN=$(lcm_url 7791)
"$D" --gen-key "$T/net.key" >/dev/null
"$D" --gen-key "$T/wrong.key" >/dev/null
spawn simn "$S" --link "$T/net" --ids 1 --lcm-url "$URLN" --seed 6
wait_log simn 'ready' 10
spawn watchn "$D" --watch net --raw --lcm-url "$URLN"
spawn d_net "$D" --port "$T/net" --ids 1 --robot net --lcm-url "$URLN" --mode oscillator \
	--set robot.commands=network --set "robot.command_key=$T/net.key"
wait_log d_net 'ready: net.STATE' 10
spawn webw "$W" --listen 127.0.0.1:0 --lcm-url "$URLN" --key "$T/wrong.key"
spawn webn "$W" --listen 127.0.0.1:0 --lcm-url "$URLN" --key "$T/net.key"
wait_log webw 'open http://' 10 && wait_log webn 'open http://' 10
wport=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/webw.log")
nport=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/webn.log")
WEB_TOKEN=$(token_of webw) python3 "$CDP" say 127.0.0.1 "$wport" "cmd 8 net mode limp" command-accepted >"$T/wrong.out" 2>&1
tap_check "--key with the wrong key: the robot takes nothing ($(tr '\n' ' ' <"$T/wrong.out"))" \
	bash -c "! grep -q '^NOTE command-accepted' '$T/wrong.out' && ! grep -q '^STATE net .* mode=0 ' '$T/watchn.log'"
WEB_TOKEN=$(token_of webn) python3 "$CDP" say 127.0.0.1 "$nport" "cmd 9 net mode hold" command-accepted >"$T/net.out" 2>&1
held=0; wait_for 5 grep -q '^STATE net .* mode=1 ' "$T/watchn.log" && held=1
tap_check "--key: signed over LCM, the robot takes it and its answer comes back ($(tr '\n' ' ' <"$T/net.out"))" \
	bash -c "[ $held = 1 ] && grep -q '^NOTE command-accepted mode HOLD' '$T/net.out'"
stop webn >/dev/null; stop webw >/dev/null; stop d_net >/dev/null; stop watchn >/dev/null; stop simn >/dev/null

stop web >/dev/null
tap_check "SIGTERM: undulate-web exits 0 and reports its counters" \
	bash -c "[ '$stop_rc' = 0 ] && grep -q 'exit: .* refused' '$T/web.log'"
tap_done
