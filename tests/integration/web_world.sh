#!/usr/bin/env bash
# undulate-web's world view, on a simulator of each world (no daemons: the
# servos are limp and the closing walls push the robots together):
#  - the plane (plane-arena10, its side walls closing from 1 s): the frames
#    carry every robot's three links, the four walls and the contacts summed
#    between frames; forged SIM.TRUTH messages naming links and contacts the
#    message does not hold, or NaN / inf / 1e300 numbers, are refused and
#    counted (and said), the server lives on and the page keeps drawing;
#    headless chromium draws the ten robots' links: the canvas's own pixels at
#    each drawn link centre are that robot's colour, and the screenshot of the
#    view holds those colours;
#  - the row (arena10): the ten bodies, each on its lane between the walls.
# The screenshots are kept in build/test-logs/ when a check fails or with
# WEB_KEEP_SCREENSHOT=1.
. "$(dirname "$0")/../lib.sh"
W="$B/undulate-web" S="$B/undulate-sim" TP="$BUILD/tests/tools/truthpub"
CDP="$(dirname "$0")/web_cdp.py"
[ -x "$W" ] || tap_skip_all "undulate-web not built"
[ -x "$TP" ] || tap_skip_all "tests/tools/truthpub not built"
for t in curl jq python3; do command -v $t >/dev/null || tap_skip_all "$t missing"; done
browser=$(command -v chromium || command -v chromium-browser || true)

# The scenarios with their walls closing at once (the presets wait 10 s).
sed 's/^10 = walls .*/1 = walls -0.6 0.6 over 10/' "$top/sim-bridge/scenarios/plane-arena10.scenario" >"$T/plane.scenario"
sed 's/^10 = walls .*/1 = walls -0.5 0.5 over 4/' "$top/sim-bridge/scenarios/arena10.scenario" >"$T/row.scenario"
grep -q '^1 = walls' "$T/plane.scenario" && grep -q '^1 = walls' "$T/row.scenario" ||
	{ tap_fail "scenarios with early walls" "the presets' [events] changed"; tap_done; exit 1; }
port_of() { sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/$1.log"; }
ROBOTS="r1 r2 r3 r4 r5 r6 r7 r8 r9 r10"

if [ -n "$browser" ]; then
	dport=$(python3 "$CDP" freeport)
	# its own TMPDIR: chromium leaves a singleton folder there even after SIGTERM
	spawn chromium env TMPDIR="$T" "$browser" --headless=new --no-sandbox --disable-gpu --no-first-run \
		--user-data-dir="$T/chromium" --remote-debugging-port="$dport" about:blank
fi

# world_up SIM WEB SCENARIO LCM_PORT WHAT: the simulator on the scenario and a
# read-only undulate-web on it, both ready (else the test ends), its ten
# robots in the snapshot; the page's address in $H.
world_up() {
	URL=$(lcm_url "$4")
	spawn "$1" "$S" --scenario "$T/$3.scenario" --link-dir "$T" --lcm-url "$URL" --seed 5 --quiet
	spawn "$2" "$W" --listen 127.0.0.1:0 --lcm-url "$URL" --read-only
	wait_log "$1" 'ready' 10 && wait_log "$2" 'listening on http://' 10 ||
		{ tap_fail "${5}simulator and undulate-web ready" "$(cat "$T/$1.log" "$T/$2.log")"; tap_done; exit 1; }
	H="http://127.0.0.1:$(port_of "$2")"
	wait_for 10 bash -c "curl -s '$H/api/snapshot' | jq -e '.nrobots == 10' "
}

# ---- the plane ---------------------------------------------------------------------
world_up sim web plane 7794 ""
# the walls meet the outer robots about 4 s after they start moving (at 1 s)
# and push them together until 11 s: contacts go on while the frames are read
# (walls that stopped at 5 s left none by the time a loaded machine read them)
wait_for 30 bash -c "curl -s '$H/api/snapshot' | jq -e '.sim.total_impulse > 0' " ||
	echo "# no contact in the simulator's first 30 s: $(curl -s "$H/api/snapshot" | jq -c '.sim' 2>&1 | head -c 300)"

# Frames for 3 s (longer, up to 15 s, until a contact has come: a loaded
# machine once gave 3 s of frames without one): the world in each, and the
# contacts of every frame.
python3 - "$(port_of web)" >"$T/plane.frames" 2>&1 <<EOF
import json, sys, time
sys.path.insert(0, '$top/tests/integration')
import web_cdp
ws = web_cdp.WS('127.0.0.1', int(sys.argv[1]), '/', 'undulate')
n = worlds = marks = impacts = size = wsize = 0
last = None
end = time.time() + 3
deadline = time.time() + 15
while time.time() < end or (marks == 0 and time.time() < deadline):
    m = ws.recv()
    f = json.loads(m)
    n += 1
    if n > 2:                      # after the first (whole-history) frames
        size += len(m)
    w = f.get('world')
    if w:
        worlds += 1
        last = w
        if n > 2:
            wsize += len(json.dumps(w, separators=(',', ':')))
        marks += len(w['contacts']['t'])
        impacts += sum(w['contacts']['impact'])
r = [x for x in last['robots'] if x['links']]
print(f"FRAMES {n} WORLDS {worlds} MEAN_BYTES {size // max(n - 2, 1)} WORLD_BYTES {wsize // max(worlds - 2, 1)}")
print(f"KIND {last['kind']} WALLS {len(last['walls'])} ROBOTS {len(r)} "
      f"LINKS {','.join(sorted(set(str(len([l for l in x['links'] if l])) for x in r)))} MARKS {marks} IMPACTS {impacts}")
EOF
sed 's/^/# /' "$T/plane.frames"
tap_check "the plane: frames carry the world ($(head -1 "$T/plane.frames"))" \
	bash -c "awk '/^FRAMES/ { ok = \$2 >= 20 && \$4 >= \$2 - 2 } END { exit !ok }' '$T/plane.frames'"
tap_check "the plane's world: 4 walls, 10 robots of 3 links each, contacts summed between frames ($(sed -n 2p "$T/plane.frames"))" \
	grep -qE '^KIND plane WALLS 4 ROBOTS 10 LINKS 3 MARKS [1-9]' "$T/plane.frames"

# ---- forged SIM.TRUTH: refused, counted, said; the server lives on ----------------------
before=$(curl -s "$H/api/snapshot" | jq -c '.nrobots')
# shellcheck disable=SC2086 # the names are words
"$TP" "$URL" 200 $ROBOTS >"$T/truthpub.out" 2>&1
python3 "$CDP" frames 127.0.0.1 "$(port_of web)" 2 >"$T/after.frames" 2>&1
python3 - "$(port_of web)" >"$T/refused" 2>&1 <<EOF
import json, sys
sys.path.insert(0, '$top/tests/integration')
import web_cdp
ws = web_cdp.WS('127.0.0.1', int(sys.argv[1]), '/', 'undulate')
print(json.dumps(json.loads(ws.recv())['status']['world_refused']))
EOF
echo "# $(cat "$T/truthpub.out"); world_refused $(cat "$T/refused")"
tap_check "forged links, walls and contacts are refused and counted ($(cat "$T/refused"))" \
	jq -e '.index > 100 and .number > 100 and .overflow > 0' "$T/refused"
tap_check "... and said in the server's log" grep -q 'SIM.TRUTH: .* refused so far' "$T/web.log"
tap_check "... the server lives on, no robot was made by them ($before robots), frames keep coming ($(head -1 "$T/after.frames"))" \
	bash -c "kill -0 $pid_web && [ \"\$(curl -s '$H/api/snapshot' | jq '.nrobots')\" = 10 ] && awk '/^FRAMES/ { ok = \$2 >= 15 } END { exit !ok }' '$T/after.frames'"

# ---- headless chromium draws it ---------------------------------------------------------
if [ -z "$browser" ]; then
	tap_skip "headless chromium draws the plane's ten robots and the row's ten bodies" \
		"no chromium here (Debian package chromium; scripts/deps.sh chromium)"
else
	python3 "$CDP" world "$dport" "$H/" "$T/plane.png" plane 10 >"$T/plane.out" 2>&1
	sed 's/^/# /' "$T/plane.out"
	tap_check "the page draws the plane: 10 robots, 30 links ($(head -1 "$T/plane.out"))" \
		grep -qE '^WORLD .*kind=plane robots=10 links=30 ' "$T/plane.out"
	tap_check "the canvas's pixels at each robot's link centres are its colour: $(grep '^COLOURED' "$T/plane.out") of 10" \
		grep -q '^COLOURED 10$' "$T/plane.out"
	# the screenshot of the view: every robot's colour, a link's worth of pixels each
	shot=""
	for c in $(awk '/^ROBOT/ { sub("#", "", $3); print $3 }' "$T/plane.out"); do
		shot="$shot $("$BUILD/tests/tools/pngdata" --rgb "$c" "$T/plane.world.png" 2>&1 | sed -n 's/.*matching=//p')"
	done
	few=$(echo "$shot" | tr ' ' '\n' | awk 'NF && $1 < 300' | wc -l)
	tap_check "the screenshot of the view shows the ten robots (pixels of each colour:$shot)" \
		bash -c "[ '$(echo "$shot" | wc -w)' = 10 ] && [ '$few' = 0 ]"
fi
stop web >/dev/null
stop sim >/dev/null

# ---- the row ------------------------------------------------------------------------------
world_up simr webr row 7795 "row: "
HR=$H
if [ -n "$browser" ]; then
	python3 "$CDP" world "$dport" "$HR/" "$T/row.png" row 10 >"$T/row.out" 2>&1
	sed 's/^/# /' "$T/row.out"
	tap_check "the page draws the row: 10 bodies, each on its lane in its colour ($(head -1 "$T/row.out"); $(grep '^COLOURED' "$T/row.out"))" \
		bash -c "grep -qE '^WORLD .*kind=row robots=10 links=0 ' '$T/row.out' && grep -q '^COLOURED 10$' '$T/row.out'"
	if [ "$_tap_failed" -gt 0 ] || [ -n "${WEB_KEEP_SCREENSHOT:-}" ]; then
		mkdir -p "$BUILD/test-logs"
		for f in plane.png plane.world.png row.png row.world.png; do
			[ -f "$T/$f" ] && cp "$T/$f" "$BUILD/test-logs/web_world_$f"
		done
	fi
fi
stop webr >/dev/null
tap_check "SIGTERM: undulate-web exits 0" [ "$stop_rc" = 0 ]
tap_done
