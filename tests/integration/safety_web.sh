#!/usr/bin/env bash
# run.sh: alone — its crowd (a few thousand connections in seconds) is a load of its own, and it times the operator under it (tests/run.sh)
# safety_web.sh — undulate-web against hostile clients, as the security
# review reproduced them (each succeeded on the dashboard before its fix):
#  - DNS rebinding: a page of another site whose name now points to this
#    computer sends Host: evil.example (and Origin http://evil.example): it
#    must read nothing (every path, /api/snapshot too) and open no WebSocket;
#  - authority: a command through the dashboard needs what only the user who
#    started it holds (the token it made, in a file only that user reads, or
#    its --token-file); without it, a browser watches and never commands —
#    also another local user, whom the robot's command socket refuses;
#  - crowds: 40 token-less WebSockets and 120 half-open HTTP connections,
#    reopened as the server closes them, do not keep the operator (with the
#    token) out: its command takes effect, and plain GETs keep answering;
#  - robot names that are not robot names ('*', control characters, spaces,
#    too long) never become a robot of the dashboard (a card whose buttons
#    would command every robot);
#  - RFC 6455: an unmasked client frame closes the connection (1002), a
#    binary one too (1003: the protocol is text), and neither is obeyed.
. "$(dirname "$0")/../lib.sh"
W="$B/undulate-web" D="$B/undulated" S="$B/undulate-sim"
ATK="$(dirname "$0")/web_attack.py" Q="$(dirname "$0")/qa_lcm.py"
[ -x "$W" ] || tap_skip_all "undulate-web not built"
for t in curl jq python3; do command -v $t >/dev/null || tap_skip_all "$t missing"; done
URL=$(lcm_url 7792) LPORT=$(lcm_port 7792)

start_pair

spawn web "$W" --listen 127.0.0.1:0 --lcm-url "$URL"
wait_log web 'listening on http://' 10 || { tap_fail "undulate-web listening" "$(cat "$T/web.log")"; tap_done; exit 1; }
port=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/web.log")
token=$(sed -n 's|.*http://127.0.0.1:[0-9]*/#token=\([A-Za-z0-9_.~-]*\).*|\1|p' "$T/web.log" | head -1)
H="http://127.0.0.1:$port"
wait_for 10 bash -c "curl -s '$H/api/snapshot' | jq -e '.nrobots == 2'"

# What reached the robot: the commands its log says it took, and its mode.
taken() { grep -c 'command .* from ' "$T/d_left.log"; }
left_field() { grep -a '^STATE left ' "$T/watch.log" | tail -1 | sed -n "s/.* $1=\([0-9]*\).*/\1/p"; }
is_mode() { [ "$(left_field mode)" = "$1" ]; }
cycle_past() { [ "$(left_field cycle)" -ge "$1" ] 2>/dev/null; }
back_to_oscillator() {
	"$D" --command 'mode oscillator' --robot left --lcm-url "$URL" --timeout 2 >/dev/null 2>&1
	wait_for 5 is_mode 3
}
# untouched N0: 30 cycles on, the robot took no command since it had taken N0, and runs on.
untouched() {
	local c; c=$(left_field cycle)
	wait_for 5 cycle_past $((${c:-0} + 30)) && [ "$(taken)" = "$1" ] && is_mode 3
}
# answered OUT REGEX N0: the client's output matches REGEX, and the robot is untouched.
answered() { grep -qE "$2" "$1" && untouched "$3"; }
shown() { grep -vE '^(NOTE hello|OPEN)' "$1" | head -${2:-1} | tr '\n' ' '; }
atk() { python3 "$ATK" "$@" 2>&1; }
code() { curl -s -o /dev/null -w '%{http_code}' --max-time 5 "$@"; }
wait_for 5 is_mode 3

# ---- 3. DNS rebinding: Host must name this server -------------------------------------------
evil="evil.example:$port"
c1=$(code -H "Host: $evil" "$H/api/snapshot") c2=$(code -H "Host: $evil" "$H/") c3=$(code -H "Host: $evil" "$H/app.js")
tap_check "Host: $evil reads nothing: /api/snapshot $c1, / $c2, /app.js $c3 (not 200)" \
	bash -c "[ '$c1' != 200 ] && [ '$c2' != 200 ] && [ '$c3' != 200 ]"
n0=$(taken)
atk ws 127.0.0.1 "$port" "host=$evil" "origin=http://$evil" "cmd 1 left mode hold" command-accepted >"$T/rebind.out"
tap_check "Host and Origin evil.example: the WebSocket is refused, nothing reaches the robot ($(shown "$T/rebind.out" 2))" \
	answered "$T/rebind.out" '^REFUSED' "$n0"
back_to_oscillator
c1=$(code -H "Host: localhost:$port" "$H/api/snapshot") c2=$(code "$H/api/snapshot")
c3=$(code -H "Host: LocalHost:$port" "$H/") c4=$(code -H "Host: [::1]:$port" "$H/")
c5=$(code -H "Host: localhost.evil.example:$port" "$H/") c6=$(code -H "Host: 127.0.0.1.evil.example" "$H/")
tap_check "Host localhost, 127.0.0.1, LocalHost, [::1] name this server ($c1 $c2 $c3 $c4); localhost.evil.example, 127.0.0.1.evil.example do not ($c5 $c6)" \
	bash -c "[ '$c1$c2$c3$c4' = 200200200200 ] && [ '$c5' != 200 ] && [ '$c6' != 200 ]"
spawn web2 "$W" --listen 127.0.0.1:0 --lcm-url "$URL" --read-only --allow-host lab.example
wait_log web2 'listening on http://' 10
port2=$(sed -n 's|.*listening on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$T/web2.log")
c1=$(code -H "Host: lab.example:$port2" "http://127.0.0.1:$port2/api/snapshot")
c2=$(code -H "Host: evil.example:$port2" "http://127.0.0.1:$port2/api/snapshot")
tap_check "--allow-host lab.example: Host lab.example:$port2 is served ($c1), evil.example still not ($c2)" \
	bash -c "[ '$c1' = 200 ] && [ '$c2' != 200 ]"
stop web2 >/dev/null

# ---- 4. a command carries the authority of the person, not of the dashboard -------------------
tf="$T/undulate-web-$port.token"
tap_check "commands on, no --token-file: the dashboard made a token and printed the URL with it" [ -n "$token" ]
tap_check "its token file: ours, mode 0600, a regular file, holding the printed token" \
	bash -c "[ -f '$tf' ] && [ ! -L '$tf' ] && [ \"\$(stat -c '%a %u' '$tf')\" = '600 $(id -u)' ] && [ \"\$(head -1 '$tf')\" = '$token' ]"
n0=$(taken)
atk ws 127.0.0.1 "$port" "cmd 2 left mode hold" >"$T/notoken.out"
tap_check "a browser on this computer without the token watches, never commands ($(shown "$T/notoken.out"))" \
	answered "$T/notoken.out" '^NOTE refused .*token' "$n0"
atk ws 127.0.0.1 "$port" "token=not-$token" "cmd 3 left mode hold" >"$T/badtoken.out"
tap_check "a wrong token: watching only ($(shown "$T/badtoken.out"))" answered "$T/badtoken.out" '^NOTE refused' "$n0"
# the system's python3: another user may not reach the one on our PATH (a pyenv shim in a home)
if [ "$(id -u)" = 0 ] && command -v setpriv >/dev/null && [ -x /usr/bin/python3 ]; then
	# another local user: the robot's socket refuses them; so must the dashboard
	as_nobody() { setpriv --reuid=65534 --regid=65534 --clear-groups "$@"; }
	as_nobody env UNDULATE_RUN_DIR="$T" "$D" --command 'mode hold' --robot left --lcm-url "$URL" --timeout 1 \
		>"$T/nobody_direct.out" 2>&1; rc=$?
	as_nobody /usr/bin/python3 "$ATK" ws 127.0.0.1 "$port" "cmd 4 left mode hold" command-accepted >"$T/nobody.out" 2>&1
	tap_check "another user (nobody): the robot's command socket refuses them (exit $rc)" [ "$rc" != 0 ]
	tap_check "... and so does the dashboard: the robot takes nothing from them ($(shown "$T/nobody.out"))" \
		answered "$T/nobody.out" '^NOTE refused' "$n0"
else
	tap_skip "another local user cannot command through the dashboard" "needs root, setpriv and /usr/bin/python3 to run as another user"
fi
atk ws 127.0.0.1 "$port" "token=$token" "cmd 5 left mode hold" command-accepted >"$T/owner.out"
tap_check "with the printed token the command is taken ($(grep -v hello "$T/owner.out" | tail -1))" \
	bash -c "grep -q '^NOTE command-accepted mode HOLD' '$T/owner.out'"
wait_for 5 is_mode 1
back_to_oscillator
# the token file is created without following a link planted at its path
p3=$(python3 "$(dirname "$0")/web_cdp.py" freeport)
echo keep >"$T/victim"
ln -s "$T/victim" "$T/undulate-web-$p3.token"
spawn web3 "$W" --listen "127.0.0.1:$p3" --lcm-url "$URL"
wait_log web3 'listening on http://|cannot' 10
tap_check "a link planted at the token file's path is not followed (the file it names is untouched)" \
	bash -c "[ \"\$(cat '$T/victim')\" = keep ] && [ ! -L '$T/undulate-web-$p3.token' ]"
stop web3 >/dev/null
tap_check "at exit the token file is removed" [ ! -e "$T/undulate-web-$p3.token" ]

# ---- 9. names that are not robot names ---------------------------------------------------------
spawn cap python3 "$Q" capture "$LPORT" left.STATE 10
wait_for 10 grep -qE '^[0-9a-f]{40,}$' "$T/cap.log"
tmpl=$(grep -E '^[0-9a-f]{40,}$' "$T/cap.log" | head -1)
long=$(printf 'r%.0s' $(seq 47))
for name in '*' 'bad\x07name' 'two words' "${long}r" 'a.b' '../x' 'tab\tname'; do
	atk state "$LPORT" "$tmpl" "$name" 3 >/dev/null
done
atk state "$LPORT" "$tmpl" "$long" 3 >/dev/null
wait_for 5 bash -c "curl -s '$H/api/snapshot' | jq -e '[.robots[].name] | index(\"$long\")'"
names=$(curl -s "$H/api/snapshot" | jq -c '[.robots[].name] | sort')
want=$(jq -cn --arg l "$long" '["left", "right", $l] | sort')
tap_check "'*', a control character, a space, a tab, '.', '/', 48 characters: no robot of the dashboard; 47 are (robots: $names)" \
	[ "$names" = "$want" ]

# ---- 9. frames as RFC 6455 wants them -------------------------------------------------------------
n0=$(taken)
atk ws 127.0.0.1 "$port" "token=$token" unmasked "cmd 6 left mode hold" command-accepted >"$T/unmasked.out"
tap_check "an unmasked client frame closes the connection with 1002, and is not obeyed ($(grep -v hello "$T/unmasked.out" | tail -1))" \
	answered "$T/unmasked.out" '^CLOSED 1002' "$n0"
atk ws 127.0.0.1 "$port" "token=$token" binary "cmd 7 left mode hold" command-accepted >"$T/binary.out"
tap_check "a binary frame closes the connection with 1003, and is not obeyed ($(grep -v hello "$T/binary.out" | tail -1))" \
	answered "$T/binary.out" '^CLOSED 1003' "$n0"

# ---- 5. a crowd without the token does not lock the operator out ----------------------------------
# a WebSocket past the checks of "undulate" (and its count): no protocol, or another of the server's
for p in none http undulate-raw; do
	atk ws 127.0.0.1 "$port" "proto=$p" "cmd 9 left mode hold" >"$T/proto_$p.out"
done
tap_check "a WebSocket without the protocol 'undulate' (none, 'http', 'undulate-raw') is refused ($(cat "$T"/proto_*.out | tr '\n' ' '))" \
	bash -c "[ \"\$(cat '$T'/proto_*.out | grep -c '^REFUSED')\" = 3 ]"
gets() { # N: N GETs of /api/snapshot one after another; "<answered> <ms>"
	local ok=0 t0; t0=$(date +%s%N)
	for _ in $(seq "$1"); do [ "$(code "$H/api/snapshot")" = 200 ] && ok=$((ok + 1)); done
	echo "$ok $(( ($(date +%s%N) - t0) / 1000000 ))"
}
read -r ok ms <<<"$(gets 20)"
echo "# 20 GETs of /api/snapshot without a crowd: $ok answered in $ms ms"
spawn crowd python3 "$ATK" crowd 127.0.0.1 "$port" 40 120 25
wait_log crowd '^CROWD' 60
echo "# $(grep '^CROWD' "$T/crowd.log")"
atk ws 127.0.0.1 "$port" "token=$token" "cmd 8 left mode limp" command-accepted >"$T/operator.out"
ms=$(sed -n 's/^OPEN //p' "$T/operator.out")
tap_check "under the crowd the operator connects (in ${ms:-never} ms) and LIMP is taken ($(grep -v hello "$T/operator.out" | tail -1))" \
	bash -c "grep -q '^NOTE command-accepted mode LIMP' '$T/operator.out'"
wait_for 5 is_mode 0
read -r ok ms <<<"$(gets 20)"
echo "# 20 GETs of /api/snapshot under the crowd: $ok answered in $ms ms"
tap_check "under the crowd plain GETs keep answering ($ok of 20, within 5 s each)" [ "$ok" = 20 ]
stop crowd >/dev/null
echo "# $(grep '^END' "$T/crowd.log")"
back_to_oscillator

stop web >/dev/null
echo "# $(grep 'exit:' "$T/web.log")"
tap_check "SIGTERM: undulate-web exits 0; its token file is gone" bash -c "[ '$stop_rc' = 0 ] && [ ! -e '$tf' ]"
tap_done
