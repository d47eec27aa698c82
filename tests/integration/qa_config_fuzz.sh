#!/usr/bin/env bash
# undulated --check-config fed 300 seeded mutations of the example configuration
# (systemd/undulated.conf.example): truncated lines, bad numbers, NaN/inf, huge
# values, unknown keys, binary bytes, broken sections, long lines, a key given
# twice. Never a crash: the exit status is 0, 1 or 2 (never a signal), every
# rejection is explained, and a mutation that breaks one line is named as
# FILE:LINE.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"
[ -x "$D" ] || tap_skip_all "undulated not built"
EX="$top/systemd/undulated.conf.example"
[ -f "$EX" ] || tap_skip_all "no example configuration"
N=${QA_CONFIG_MUTATIONS:-300}
SEED=${QA_SEED:-20261122}

# the example itself is valid (the mutations start from a good file)
if "$D" --check-config "$EX" >"$T/ex.out" 2>&1; then tap_ok "the example configuration is valid"; else
	tap_fail "the example configuration is valid" "$(cat "$T/ex.out")"; fi

# Writes $T/m<i>.conf and one line per file in $T/cases: "i kind line must_fail".
# kind says what was done; line is the physical line that was broken (0: no
# single line); must_fail=1 when no configuration could accept the change.
python3 - "$EX" "$T" "$N" "$SEED" <<'EOF'
import random, sys
src, out, n, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
rng = random.Random(seed)
lines = open(src, 'rb').read().split(b'\n')
def keyline(i):
    l = lines[i].strip()
    return b'=' in l and not l.startswith((b';', b'#', b'['))
keys = [i for i in range(len(lines)) if keyline(i)]
numeric = {b'baud', b'priority', b'adapter_latency_us', b'neutral', b'limit_min', b'limit_max',
           b'max_step', b'amplitude', b'frequency', b'phase'}
words = {b'mode', b'safe_stop', b'fault_action', b'velocity_source', b'commands', b'echo', b'mlockall'}
bad_numbers = [b'abc', b'nan', b'NaN', b'inf', b'-inf', b'+Infinity', b'1e999', b'-1e999', b'1e308',
               b'-1e308', b'0x', b'12abc', b'1..2', b'99999999999999999999999', b'1,5', b'--1', b'0.5.5',
               b'1e', b'\x01', b'\xff\xfe']
bad_words = [b'maybe', b'oscillatorx', b'\x01\x02', b'on off', b'1.5', b'-', b'nan', b'\xc3\xa9']
cases = []
for i in range(n):
    L = list(lines)
    kind = rng.choice(['number', 'word', 'unknown', 'binary', 'truncate', 'delete', 'section',
                       'huge', 'long', 'dup', 'nul', 'cr'])
    at, must = 0, 0
    k = rng.choice(keys)
    name, _, val = L[k].partition(b'=')
    name = name.strip()
    if kind == 'number' or (kind == 'word' and name not in words):
        k = rng.choice([j for j in keys if L[j].split(b'=')[0].strip() in numeric])
        name = L[k].split(b'=')[0].strip()
        L[k] = name + b' = ' + rng.choice(bad_numbers)
        kind, at, must = 'number', k + 1, 1
    elif kind == 'word':
        L[k] = name + b' = ' + rng.choice(bad_words)
        at, must = k + 1, 1
    elif kind == 'unknown':
        L.insert(k + 1, rng.choice([b'prot', b'k2', b'x', b'limit', b'ids2', b'\xe2\x82\xac']) + b' = 1')
        at, must = k + 2, 1
    elif kind == 'binary':
        # starts with a byte that is neither blank nor a comment
        L[k] = bytes([rng.randrange(0x80, 0x100)]) + bytes(rng.randrange(1, 256) for _ in range(rng.randrange(1, 40))).replace(b'\n', b'?')
        at, must = k + 1, 1
    elif kind == 'truncate':
        L[k] = L[k][:rng.randrange(1, len(L[k]))]
        at = k + 1
    elif kind == 'delete':
        del L[k]
    elif kind == 'section':
        s = [j for j in range(len(L)) if L[j].startswith(b'[')]
        j = rng.choice(s)
        L[j] = rng.choice([b'[joint.1', b'[joint.99]', b'[]', b'[robot', b'[joint.-1]', b'[joint.x]', b'[[robot]]'])
        at, must = j + 1, 1
    elif kind == 'huge':
        k = rng.choice([j for j in keys if L[j].split(b'=')[0].strip() in numeric])
        name = L[k].split(b'=')[0].strip()
        L[k] = name + b' = ' + rng.choice([b'1e300', b'-1e300', b'4294967297', b'9223372036854775808', b'1' * 150])
        kind, at, must = 'number', k + 1, 1
    elif kind == 'long':
        L[k] = L[k] + b' ; ' + b'x' * rng.randrange(200, 3000)
        at, must = k + 1, 1
        # a bad value further down must still be named by its own line
        j = rng.choice([j for j in keys if j > k and L[j].split(b'=')[0].strip() in numeric] or [None])
        if j is not None:
            L[j] = L[j].split(b'=')[0].strip() + b' = bad'
    elif kind == 'dup':
        # a key given twice: refused at its second line (the second no longer wins)
        L.insert(k, L[k])
        at, must = k + 2, 1
    elif kind == 'nul':
        p = rng.randrange(0, len(L[k]))
        L[k] = L[k][:p] + b'\x00' + L[k][p:]
        at = k + 1
    elif kind == 'cr':
        L[k] = L[k] + b'\r'
    open('%s/m%d.conf' % (out, i), 'wb').write(b'\n'.join(L))
    cases.append('%d %s %d %d' % (i, kind, at, must))
open(out + '/cases', 'w').write('\n'.join(cases) + '\n')
EOF

signals=() unexplained=() unnamed=() accepted=() count=0
declare -A kinds
while read -r i kind at must; do
	f="$T/m$i.conf"
	"$D" --check-config "$f" >"$T/out" 2>&1
	rc=$?
	count=$((count + 1))
	kinds[$kind]=$(( ${kinds[$kind]:-0} + 1 ))
	if [ "$rc" -gt 2 ]; then
		# the mutations are seeded: KEEP_TEST_DIR=1 keeps m$i.conf to reproduce
		signals+=("m$i ($kind, line $at): exit $rc: $(head -c 300 "$T/out")")
		continue
	fi
	if [ "$rc" -ne 0 ]; then
		# every rejection names the file; a broken line is named FILE:LINE
		grep -aq "config: $f" "$T/out" || unexplained+=("m$i ($kind): $(head -c 300 "$T/out")")
		# a broken section header is named by inih (syntax) or, when it still
		# parses as a section name, at each key under it
		want="$f:$at:"; [ "$kind" = section ] && want="$f:[0-9]+:"
		if [ "$at" -gt 0 ] && [ "$must" = 1 ] && ! grep -aqE "config: $want" "$T/out"; then
			unnamed+=("m$i ($kind, line $at): $(head -c 300 "$T/out" | tr -d '\000')")
		fi
	elif [ "$must" = 1 ]; then
		accepted+=("m$i ($kind, line $at: $(sed -n "${at}p" "$f" | head -c 80 | cat -v)): $(cat "$T/out")")
	fi
done <"$T/cases"
echo "# $count mutations:$(for k in "${!kinds[@]}"; do printf ' %s=%s' "$k" "${kinds[$k]}"; done)"

if [ "$count" -eq "$N" ] && [ ${#signals[@]} -eq 0 ]; then tap_ok "$count mutated configurations: exit 0/1/2, never a signal"
else tap_fail "never a signal ($count of $N run)" "$(printf '%s\n' "${signals[@]}" | head -5)"; fi
if [ ${#unexplained[@]} -eq 0 ]; then tap_ok "every rejection names the file"
else tap_fail "every rejection names the file" "$(printf '%s\n' "${unexplained[@]}" | head -5)"; fi
if [ ${#unnamed[@]} -eq 0 ]; then tap_ok "a broken line is named as FILE:LINE"
else tap_fail "a broken line is named as FILE:LINE (${#unnamed[@]} not)" "$(printf '%s\n' "${unnamed[@]}" | head -5)"; fi
if [ ${#accepted[@]} -eq 0 ]; then tap_ok "no bad value, unknown key or broken section is accepted"
else tap_fail "no bad value accepted (${#accepted[@]} were)" "$(printf '%s\n' "${accepted[@]}" | head -5)"; fi

# the same values as command-line overrides: exit 2 with a message, no signal
bad=0
for v in nan inf -inf 1e999 abc '' 1e308 $'\x01' 99999999999999999999999; do
	for k in robot.baud robot.priority joint.1.k joint.2.limit_max sinusoid.frequency robot.period_ms; do
		"$D" --check-config --port /dev/null --ids 1,2 --set "$k=$v" >"$T/out" 2>&1
		rc=$?
		if [ "$rc" -ne 1 ] && [ "$rc" -ne 2 ] || ! grep -q "command line: \[" "$T/out"; then
			bad=$((bad + 1)); echo "# --set $k=$(printf %q "$v"): exit $rc: $(head -c 200 "$T/out")"
		fi
	done
done
if [ $bad -eq 0 ]; then tap_ok "bad --set values are rejected with a message"; else tap_fail "bad --set values rejected" "$bad not"; fi
tap_done
