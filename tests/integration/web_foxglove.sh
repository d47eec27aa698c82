#!/usr/bin/env bash
# run.sh: long — started early, so that the run does not end waiting for it (tests/run.sh)
# undulate-web speaks Foxglove's WebSocket protocol (foxglove.websocket.v1)
# to a client written with the published client library @foxglove/ws-protocol
# (0.8.x, installed at set-up into a cache directory outside the repository,
# run under Debian's nodejs): against two daemons on the simulated bus, it
# gets serverInfo, one channel per kind of message heard, each with a JSON
# Schema that parses; subscribed to a robot's STATE it receives the robot's
# messages at its publish rate (100 Hz), every cycle; unsubscribed, none.
# Hostile clients (bad JSON, unknown and publishing ops, binary and 1 MB
# frames, unknown channels and subscriptions, thousands of subscriptions) get
# an error status each, are counted, and the server's memory stays flat; a
# foreign Host is refused and the crowd limit holds for Foxglove too; a
# robot that stops is unadvertised after 10 s of silence.
. "$(dirname "$0")/../lib.sh"
W="$B/undulate-web" D="$B/undulated" S="$B/undulate-sim"
JS="$top/tests/integration/web_foxglove.js"
[ -x "$W" ] && [ -x "$D" ] && [ -x "$S" ] || tap_skip_all "undulate-web, undulated or undulate-sim not built"
for t in node npm jq python3; do command -v $t >/dev/null || tap_skip_all "$t missing (Debian: apt-get install nodejs npm jq)"; done
node --experimental-websocket -e 'new WebSocket("ws://127.0.0.1:9")' 2>/dev/null ||
	tap_skip_all "this nodejs has no WebSocket (node >= 20.10 with --experimental-websocket)"

# ---- the client library, outside the repository -------------------------------------------------
# One copy per user, reused by later runs; npm is asked only when it is missing.
NPM_CACHE=${UNDULATE_TEST_NPM_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/undulate-tests/npm-foxglove-ws-protocol-0.8}
have_lib() { jq -e '.version | startswith("0.8.")' "$NPM_CACHE/node_modules/@foxglove/ws-protocol/package.json" >/dev/null 2>&1; }
if ! have_lib; then
	mkdir -p "$NPM_CACHE" 2>/dev/null || tap_skip_all "cannot create $NPM_CACHE for the npm client library"
	timeout 180 npm install --prefix "$NPM_CACHE" --no-audit --no-fund --no-save --silent \
		'@foxglove/ws-protocol@~0.8.0' >"$T/npm.log" 2>&1 ||
		tap_skip_all "npm could not install @foxglove/ws-protocol@0.8 (network?): $(tail -1 "$T/npm.log")"
	have_lib || tap_skip_all "npm installed no @foxglove/ws-protocol 0.8.x in $NPM_CACHE"
fi
fox() { NODE_PATH="$NPM_CACHE/node_modules" node --experimental-websocket --no-warnings "$JS" "$@"; }

# ---- two robots on the simulated bus, and the server -------------------------------------------
URL=$(lcm_url 7796)
spawn sim "$S" --scenario "$top/sim-bridge/scenarios/pair.scenario" --link-dir "$T" --lcm-url "$URL" --seed 5
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
for r in left right; do
	spawn "d_$r" "$D" --port "$T/$r" --ids 1 --robot "$r" --lcm-url "$URL" --mode oscillator
done
wait_log d_left 'ready:' 10 && wait_log d_right 'ready:' 10 ||
	{ tap_fail "daemons ready" "$(cat "$T/d_left.log" "$T/d_right.log")"; tap_done; exit 1; }
# Under AddressSanitizer (make SAN=1) freed memory waits in a quarantine
# (256 MB by default) that would show as growth in the VmRSS check below.
spawn web env ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}quarantine_size_mb=1" \
	"$W" --listen 127.0.0.1:0 --lcm-url "$URL" --read-only
wait_log web 'listening on http://' 10 || { tap_fail "undulate-web listening" "$(cat "$T/web.log")"; tap_done; exit 1; }
port=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/web.log")
WS="ws://127.0.0.1:$port/"
rss() { awk '/^VmRSS/ { print $2 }' "/proc/$pid_web/status"; }

# ---- serverInfo, channels, a subscription at the robot's rate ---------------------------------
fox watch "$WS" left.STATE 4 >"$T/watch.json" 2>"$T/watch.err"
o="$T/watch.json"
jqo() { jq -e "$@" "$o" >/dev/null 2>&1; }
jqf() { jq -e "$@" >/dev/null 2>&1; }   # jqf FILTER [ARGS] FILE
tap_check "serverInfo: a name, no clientPublish ($(jq -c '.serverInfo // .error' "$o" 2>/dev/null | head -c 300))" \
	jqo '(.serverInfo.name | test("undulate")) and ((.serverInfo.capabilities // []) | index("clientPublish") | not)'
tap_check "channels advertised as heard: left.STATE, right.STATE, left.BUS, left.PARAMS ($(jq -c '[.channels[]?.topic]' "$o" 2>/dev/null))" \
	jqo '[.channels[].topic] as $t | all(("left.STATE", "right.STATE", "left.BUS", "left.PARAMS"); . as $x | $t | index($x))'
tap_check "every channel: encoding json, a JSON Schema (jsonschema) that parses, an object of its fields" \
	jqo '(.channels | length) > 0 and all(.channels[]; .encoding == "json" and .schemaEncoding == "jsonschema"
		and .schema.type == "object" and (.schema.properties | length) > 3)'
tap_check "the STATE schema: undulate.robot_state_t, its joints an array of objects with angle and speed" \
	jqo '.channels[] | select(.topic == "left.STATE") | .schemaName == "undulate.robot_state_t"
		and .schema.properties.joints.type == "array" and .schema.properties.joints.items.properties.angle.type == "number"'
rate=$(jq -r '.rate // 0 | . * 10 | round / 10' "$o" 2>/dev/null)
tap_check "subscribed to left.STATE: $(jq -r '.count // "no"' "$o" 2>/dev/null) messages in $(jq -r '.seconds // "?"' "$o" 2>/dev/null) s = $rate per second (the robot publishes 100; 50 to 150)" \
	jqo '.rate >= 50 and .rate <= 150'
tap_check "every cycle reached the client: $(jq -r '.count // 0' "$o") messages for $(jq -r '.cycles // 0' "$o") cycles (at least 90 %), one subscription id" \
	jqo '.count >= 0.9 * .cycles and .cycles > 0 and (.subIds | length) == 1'
tap_check "the messages are the robot's state: robot left, OSCILLATOR (3), one joint with its angle; stamped when received ($(jq -r '.stampAgeMs // "?"' "$o") ms before the client read it)" \
	jqo '.sample.robot == "left" and .sample.mode == 3 and .sample.njoints == 1 and (.sample.joints[0].angle | type) == "number"
		and .stampAgeMs > -1000 and .stampAgeMs < 5000'
tap_check "unsubscribed: no message in the next second ($(jq -r '.afterUnsubscribe // "?"' "$o"))" jqo '.afterUnsubscribe == 0'
[ "$_tap_failed" -gt 0 ] && echo "# client: $(head -c 1500 "$o") $(head -c 500 "$T/watch.err")"

# ---- hostile clients -------------------------------------------------------------------------
rss0=$(rss)
fox hostile "$WS" left.STATE >"$T/hostile.json" 2>"$T/hostile.err"
o="$T/hostile.json"
for what in "bad JSON" "unknown op" "client advertise (no clientPublish)" "binary client message data" \
	"subscribe to an unknown channel" "unsubscribe an unknown subscription" \
	"a subscription id that is not a number" "a 1 MB message" "3000 subscriptions" \
	"3000 subscriptions in one message"; do
	tap_check "$what: an error status ($(jq -r --arg w "$what" '.cases[]? | select(.what == $w) | "\(.level) \(.message)"' "$o" 2>/dev/null | head -c 200))" \
		jqf --arg w "$what" '.cases[] | select(.what == $w) | .level == 2 and (.message | length) > 10' "$o"
done
tap_check "the 1 MB message and the one with 3000 subscriptions: refused for their length" \
	jqo '[.cases[] | select(.what | test("1 MB|in one message")) | .message | test("longer than 4096 bytes")] == [true, true]'
tap_check "after them the connection is open and serves at most 64 subscriptions ($(jq -r '.subscriptionsServed // "?"' "$o"))" \
	jqo '.stillOpen and .subscriptionsServed >= 1 and .subscriptionsServed <= 64'
for i in 1 2 3; do fox hostile "$WS" left.STATE >/dev/null 2>&1; done
rss1=$(rss)
tap_check "memory after four hostile clients: VmRSS ${rss0} kB -> ${rss1} kB (less than 16 MB more)" \
	[ "$((rss1 - rss0))" -lt 16384 ]
fox watch "$WS" left.STATE 1 >"$T/watch2.json" 2>&1
tap_check "the server lives on: a new client still subscribes ($(jq -r '.rate // .error' "$T/watch2.json" | head -c 200) per second)" \
	jqf '.rate > 30' "$T/watch2.json"

# ---- the same gate as every WebSocket --------------------------------------------------------
# ws_try PORT PROTOCOL [host=H] [origin=O]: OPEN or REFUSED, as a browser's handshake would end
ws_try() {
	python3 - "$@" 2>&1 <<EOF
import sys
sys.path.insert(0, '$top/tests/integration')
import web_cdp
port, proto = int(sys.argv[1]), sys.argv[2]
kw = dict(a.split('=', 1) for a in sys.argv[3:])
try:
    web_cdp.WS('127.0.0.1', port, '/', proto, host_header=kw.get('host'), origin=kw.get('origin'))
    print('OPEN')
except Exception as e:
    print('REFUSED', e)
EOF
}
r=$(ws_try "$port" foxglove.websocket.v1 "host=evil.example:$port")
tap_check "Host evil.example (DNS rebinding): the Foxglove WebSocket is refused ($r)" grep -q '^REFUSED' <<<"$r"
FG=https://app.foxglove.dev
r1=$(ws_try "$port" foxglove.websocket.v1 "origin=$FG") r2=$(ws_try "$port" foxglove.websocket.v1 "origin=http://127.0.0.1:$port")
tap_check "Origin $FG: refused by default ($r1); the server's own origin: open ($r2)" \
	bash -c "grep -q '^REFUSED' <<<'$r1' && grep -q '^OPEN' <<<'$r2'"
spawn web2 "$W" --listen 127.0.0.1:0 --lcm-url "$URL" --read-only --allow-origin "$FG"
wait_log web2 'listening on http://' 10
port2=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/web2.log")
r1=$(ws_try "$port2" foxglove.websocket.v1 "origin=$FG") r2=$(ws_try "$port2" undulate "origin=$FG")
r3=$(ws_try "$port2" foxglove.websocket.v1 "origin=$FG" "host=evil.example:$port2")
tap_check "--allow-origin $FG: its Foxglove WebSocket opens ($r1), the page's protocol stays refused to it ($r2), and a foreign Host still is ($r3)" \
	bash -c "grep -q '^OPEN' <<<'$r1' && grep -q '^REFUSED' <<<'$r2' && grep -q '^REFUSED' <<<'$r3'"
stop web2 >/dev/null
fox crowd "$WS" 30 >"$T/crowd.json" 2>&1
tap_check "30 Foxglove clients without the token: 24 taken, the rest refused ($(jq -c . "$T/crowd.json" | head -c 200))" \
	jqf '.taken == 24' "$T/crowd.json"

# ---- a source that goes quiet is unadvertised ------------------------------------------------
spawn quiet env NODE_PATH="$NPM_CACHE/node_modules" node --experimental-websocket --no-warnings "$JS" quiet "$WS" right.STATE 30
if wait_log quiet 'subscribed to right.STATE' 15; then
	stop d_right >/dev/null
	wait_for 40 bash -c "grep -q '^{' '$T/quiet.log'"
fi
q=$(grep '^{' "$T/quiet.log")
tap_check "right's daemon stopped: right.STATE unadvertised $(jq -r '.afterSeconds // "?"' <<<"$q") s later (10 s of silence), left.STATE still advertised" \
	jqf '.unadvertised and (.othersLive | index("left.STATE")) and (.othersLive | index("right.STATE") | not)' <<<"${q:-null}"

stop web >/dev/null
tap_check "at exit the refusals are counted ($(grep -o '[0-9]* Foxglove messages refused' "$T/web.log"))" \
	grep -Eq '[1-9][0-9]* Foxglove messages refused' "$T/web.log"
tap_done
