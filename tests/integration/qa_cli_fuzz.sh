#!/usr/bin/env bash
# Seeded random command lines for every program (undulated, undulate-sim, dxl,
# undulate-top --once, undulate-analyze, undulate-model). Each command line holds at least one
# bad element — an unknown option, a missing or non-numeric value (abc, nan,
# inf, 1e999, '', '1x'), stray words — among random valid options and hostile
# strings (format directives, 4 kB, control bytes, UTF-8). Every program must
# answer with a message on stderr and a non-zero exit: never a signal, never a
# sanitizer report, never a hang. A few valid but extreme command lines run too.
. "$(dirname "$0")/../lib.sh"
for p in undulated undulate-sim dxl undulate-top undulate-analyze undulate-model; do
	[ -x "$B/$p" ] || tap_skip_all "$p not built"
done
# anything that talks LCM stays on this test's own port
export LCM_DEFAULT_URL; LCM_DEFAULT_URL=$(lcm_url 7951)
N=${QA_CLI_RUNS:-60}   # per program
cd "$T" || exit 1

python3 - "$B" "$T" "$N" "${QA_SEED:-7}" <<'EOF' >"$T/result"
import os, random, subprocess, sys
B, T, N, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
rng = random.Random(seed)
hostile = ['%s%n%x%p', 'A' * 4096, '\x01\x1b[2J', '\u00e9\u20ac', '-', '--', ' ', '..', '/', T + '/nope',
           '/dev/null', '1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17', '-1', '0', '4294967296', '1e308']
badnum = ['abc', 'nan', 'inf', '-inf', '1e999', '', '1x', '0x', '--', '%n']
# program: (options taking a value, numeric ones among them, flags, words)
progs = {
    'undulated': (['--config', '--set', '--port', '--ids', '--baud', '--robot', '--mode', '--lcm-url',
                   '--log-level', '--command', '--timeout', '--watch'],
                  ['--timeout'], ['--check-config', '-v', '-q'], []),
    'undulate-sim': (['--link', '--ids', '--name', '--scenario', '--set', '--link-dir', '--control', '--seed',
                      '--duration', '--baud', '--return-delay', '--latency-ms', '--rate-hz', '--truth-hz',
                      '--temperature', '--voltage', '--tx-slice-us', '--realtime', '--cmd'],
                     ['--seed', '--duration', '--baud', '--return-delay', '--latency-ms', '--rate-hz',
                      '--truth-hz', '--temperature', '--voltage', '--tx-slice-us', '--realtime'],
                     ['--echo', '--bench', '--quiet'], []),
    'dxl': (['--port', '--baud', '--latency-us', '--timeout-ms', '--rs485', '--config', '--cycles', '--protocol',
             '--size', '--keep'],
            ['--baud', '--latency-us', '--timeout-ms', '--cycles', '--protocol', '--size'],
            ['--echo'], ['ports', 'scan', 'ping', 'read', 'write', 'dump', 'set-id', 'set-baud', 'torque',
                         'reset', 'reboot', 'setup', 'doctor', '--ids', '--bauds', '--units', '--yes',
                         '--status-level']),
    'undulate-top': (['--lcm-url', '--wait', '--interval'], ['--wait', '--interval'],
                     ['--read-only', '--json', '-v'], []),
    'undulate-analyze': (['--out', '--pairs', '--from', '--to', '--window', '--separation', '--restitution',
                          '--merge', '--synth', '--duration', '--min-swing', '--synth-stop-after'],
                         ['--from', '--to', '--window', '--separation', '--restitution', '--merge', '--duration',
                          '--min-swing', '--synth-stop-after'],
                         ['--plots', '--zero-crossings', '--quiet'], []),
    'undulate-model': (['--n', '--dsep', '--restitution', '--beta', '--walls', '--seed', '--phases', '--delta0',
                        '--duration', '--frequency', '--amplitude', '--sample-hz', '--window', '--tolerance',
                        '--out', '--dsep-from', '--dsep-to', '--dsep-points', '--delta-points'],
                       ['--n', '--dsep', '--restitution', '--walls', '--seed', '--delta0', '--duration',
                        '--frequency', '--amplitude', '--sample-hz', '--window', '--tolerance', '--dsep-points'],
                       ['--fixed-ends', '--no-samples', '--quiet'], []),
}

def value():
    return rng.choice(hostile + badnum + ['1', '2', '0.5', T + '/x'])

def argv(prog):
    opts, nums, flags, words = progs[prog]
    groups = [['--once', '--wait', '0.2']] if prog == 'undulate-top' else []
    # undulate-model's subcommand comes first
    head = [rng.choice(['pair', 'lattice', 'map'])] if prog == 'undulate-model' else []
    for _ in range(rng.randrange(0, 5)):
        r = rng.random()
        if r < 0.4:
            groups.append([rng.choice(opts), value()])
        elif r < 0.6:
            groups.append([rng.choice(flags)])
        elif r < 0.8 and words:
            groups.append([rng.choice(words)])
        else:
            groups.append([value()])
    # the bad element, between two groups (never taken as an option's value);
    # an option missing its value goes last
    bad = rng.choice([['--qa-no-such-option'], ['-Z'], [rng.choice(nums), rng.choice(badnum)], []])
    if bad:
        groups.insert(rng.randrange(0, len(groups) + 1), bad)
    else:
        groups.append([rng.choice(opts)])
    return head + [x for g in groups for x in g]

def run(prog, args, timeout=3):
    env = dict(os.environ, ASAN_OPTIONS='detect_leaks=1:abort_on_error=0')
    try:
        p = subprocess.run([B + '/' + prog] + args, stdin=subprocess.DEVNULL, capture_output=True,
                           timeout=timeout, cwd=T, env=env)
        return p.returncode, p.stderr.decode('utf-8', 'replace') + p.stdout.decode('utf-8', 'replace')
    except subprocess.TimeoutExpired:
        return 'hang', ''

def show(args):
    return ' '.join(repr(x) if len(x) < 40 else repr(x[:20] + '...') for x in args)

problems = {'signal': [], 'sanitizer': [], 'hang': [], 'zero': [], 'silent': []}
total = 0
for prog in progs:
    for _ in range(N):
        args = argv(prog)
        rc, out = run(prog, args)
        total += 1
        what = None
        if rc == 'hang':
            what = 'hang'
        elif 'Sanitizer' in out or 'runtime error:' in out:
            what = 'sanitizer'
        elif rc < 0 or rc >= 128:
            what = 'signal'
        elif rc == 0:
            what = 'zero'
        elif not out.strip():
            what = 'silent'
        if what:
            problems[what].append('%s %s -> %s: %s' % (prog, show(args), rc, out.strip()[:200]))

# valid but extreme: these run and must end cleanly
extreme = [
    ('undulate-sim', ['--link', T + '/l1', '--ids', '0-15', '--duration', '0.3', '--rate-hz', '20000',
                      '--truth-hz', '1000', '--quiet', '--seed', '18446744073709551615']),
    ('undulate-sim', ['--link', T + '/l2', '--ids', '253', '--duration', '0.3', '--baud', '9600',
                      '--voltage', '0', '--temperature', '-40', '--latency-ms', '1000', '--tx-slice-us', '0']),
    ('undulate-top', ['--once', '--wait', '0.01', '--json']),
    ('undulate-analyze', ['--synth', T + '/s.log', '--duration', '2']),
    ('undulate-analyze', [T + '/s.log', '--out', T + '/o', '--from', '1e300', '--to', '-1e300', '--window', '0',
                          '--merge', '0', '--pairs', 'a:a,:,b:', '--quiet']),
    ('undulated', ['--watch', '*', '--timeout', '0.2']),
    ('undulated', ['--command', 'param k 1e308 -32768', '--robot', '*', '--timeout', '0.2']),
    ('undulate-model', ['lattice', '--n', '1000', '--dsep', '0.5', '--restitution', '1', '--duration', '2',
                        '--seed', '18446744073709551615', '--out', T + '/m', '--quiet', '--no-samples']),
    ('undulate-model', ['map', '--dsep-points', '2', '--delta-points', '3600', '--restitution', '0',
                        '--tolerance', '1e-4']),
    ('dxl', ['--port', '/dev/null', 'ports']),
    ('dxl', ['--protocol', '2', '--port', T + '/nothing', '--size', '4', 'read', '252', '0xFFFF']),
    ('dxl', ['--protocol', '2', '--port', T + '/nothing', 'reset', '252', '--keep', 'id-baud', '--yes']),
]
ran_extreme = []
for prog, args in extreme:
    rc, out = run(prog, args, timeout=10)
    total += 1
    ran_extreme.append('%s=%s' % (prog, rc))
    if rc == 'hang':
        problems['hang'].append('%s %s' % (prog, show(args)))
    elif 'Sanitizer' in out or 'runtime error:' in out:
        problems['sanitizer'].append('%s %s: %s' % (prog, show(args), out.strip()[:300]))
    elif rc < 0 or rc >= 128:
        problems['signal'].append('%s %s -> %s: %s' % (prog, show(args), rc, out.strip()[:200]))
print('total %d' % total)
print('extreme %s' % ' '.join(ran_extreme))
for k, v in problems.items():
    print('%s %d' % (k, len(v)))
    for line in v[:5]:
        print('# ' + line.replace('\n', ' | '))
EOF
count() { sed -n "s/^$1 \([0-9]*\)$/\1/p" "$T/result"; }
details() { awk -v k="$1" '$1 == k { on = 1; next } /^[a-z]+ [0-9]+$/ { on = 0 } on' "$T/result"; }
echo "# $(grep '^total' "$T/result"); $(grep '^extreme' "$T/result")"
total=$(sed -n 's/^total //p' "$T/result")
if [ -n "$total" ] && [ "$(count signal)" = 0 ]; then tap_ok "$total command lines: never a signal"
else tap_fail "never a signal" "$(details signal)$(tail -3 "$T/result")"; fi
if [ "$(count sanitizer)" = 0 ]; then tap_ok "no sanitizer report"; else tap_fail "no sanitizer report" "$(details sanitizer)"; fi
if [ "$(count hang)" = 0 ]; then tap_ok "no program hangs on a bad command line"; else tap_fail "no hang" "$(details hang)"; fi
if [ "$(count zero)" = 0 ]; then tap_ok "a bad command line never exits 0"; else tap_fail "bad command line exits non-zero" "$(details zero)"; fi
if [ "$(count silent)" = 0 ]; then tap_ok "every refusal says why"; else tap_fail "every refusal says why" "$(details silent)"; fi
tap_done
