#!/usr/bin/env bash
# "No allocation after start-up" (the budgets in bench/README.md), measured: an LD_PRELOAD
# shim, built here, counts every malloc/calloc/realloc/memalign of the daemon
# (all threads, LCM's included) between SIGUSR1 and SIGUSR2 and writes the
# count with the first call sites. The daemon runs OSCILLATOR against the
# simulator, whose SIM.TRUTH shares the daemon's multicast group, with a
# watcher subscribed: after the ramp-in, 3 s of steady state allocate nothing —
# and neither do LCM commands (accepted, rejected and undecodable ones).
# The shim proves itself on the watcher, whose generated decoders allocate.
. "$(dirname "$0")/../lib.sh"
D="$B/undulated"; S="$B/undulate-sim"; Q="$top/tests/integration/qa_lcm.py"
if [ ! -x "$S" ] || [ ! -x "$D" ]; then
	tap_skip_all "undulate-sim or undulated not built"
fi
# a sanitizer build brings its own allocator, which must come first
if ldd "$D" | grep -q 'libasan\|libtsan'; then
	tap_skip_all "sanitizer build: the malloc shim needs the C library's allocator"
fi
command -v cc >/dev/null || tap_skip_all "no C compiler"
PORT=$(lcm_port 7953)   # the UDP port itself: qa_lcm.py talks to it raw
URL=$(lcm_url 7953)
R="qa$$"

cat >"$T/shim.c" <<'EOF'
#define _GNU_SOURCE
#include <dlfcn.h>
#include <execinfo.h>
#include <fcntl.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/syscall.h>
#include <unistd.h>

static void *(*real_malloc)(size_t);
static void *(*real_calloc)(size_t, size_t);
static void *(*real_realloc)(void *, size_t);
static void (*real_free)(void *);
static int (*real_posix_memalign)(void **, size_t, size_t);
static void *(*real_aligned_alloc)(size_t, size_t);
static void *(*real_memalign)(size_t, size_t);

/* dlsym itself may calloc before the real allocator is known */
static char boot[1 << 16];
static size_t boot_used;
static void *boot_alloc(size_t n)
{
	n = (n + 15) & ~(size_t)15;
	if (boot_used + n > sizeof boot)
		return NULL;
	void *p = boot + boot_used;
	boot_used += n;
	return p;
}
static int is_boot(void *p) { return (char *)p >= boot && (char *)p < boot + sizeof boot; }

static volatile sig_atomic_t counting;
static atomic_long count, count_main;
#define KEEP 8
#define DEPTH 16
static void *stacks[KEEP][DEPTH];
static int depth[KEEP];
static size_t sizes[KEEP];
static long tids[KEEP];
static __thread int inside;
static int resolving;

static void resolve(void)
{
	if (real_malloc || resolving)
		return;
	resolving = 1;
	real_malloc = dlsym(RTLD_NEXT, "malloc");
	real_calloc = dlsym(RTLD_NEXT, "calloc");
	real_realloc = dlsym(RTLD_NEXT, "realloc");
	real_free = dlsym(RTLD_NEXT, "free");
	real_posix_memalign = dlsym(RTLD_NEXT, "posix_memalign");
	real_aligned_alloc = dlsym(RTLD_NEXT, "aligned_alloc");
	real_memalign = dlsym(RTLD_NEXT, "memalign");
	resolving = 0;
}

static void record(size_t n)
{
	if (!counting || inside)
		return;
	long k = atomic_fetch_add(&count, 1);
	if (syscall(SYS_gettid) == getpid())
		atomic_fetch_add(&count_main, 1);
	if (k < KEEP) {
		inside = 1;
		depth[k] = backtrace(stacks[k], DEPTH);
		sizes[k] = n;
		tids[k] = syscall(SYS_gettid);
		inside = 0;
	}
}

void *malloc(size_t n)
{
	resolve();
	if (!real_malloc)
		return boot_alloc(n);
	record(n);
	return real_malloc(n);
}
void *calloc(size_t a, size_t b)
{
	resolve();
	if (!real_calloc)
		return boot_alloc(a * b);   /* static: already zero */
	record(a * b);
	return real_calloc(a, b);
}
void *realloc(void *p, size_t n)
{
	resolve();
	if (is_boot(p)) {
		void *q = malloc(n);
		if (q)
			memcpy(q, p, n);
		return q;
	}
	record(n);
	return real_realloc(p, n);
}
void free(void *p)
{
	if (is_boot(p))
		return;
	resolve();
	if (real_free)
		real_free(p);
}
int posix_memalign(void **r, size_t a, size_t n) { resolve(); record(n); return real_posix_memalign(r, a, n); }
void *aligned_alloc(size_t a, size_t n) { resolve(); record(n); return real_aligned_alloc(a, n); }
void *memalign(size_t a, size_t n) { resolve(); record(n); return real_memalign(a, n); }

static void put(int fd, const char *s) { ssize_t r = write(fd, s, strlen(s)); (void)r; }
static void putnum(int fd, long v)
{
	char b[24];
	int i = sizeof b;
	b[--i] = '\0';
	if (v == 0)
		b[--i] = '0';
	for (; v > 0; v /= 10)
		b[--i] = (char)('0' + v % 10);
	put(fd, b + i);
}

static void on_start(int sig) { (void)sig; atomic_store(&count, 0); atomic_store(&count_main, 0); counting = 1; }
/* the report: async-signal-safe calls only */
static void on_stop(int sig)
{
	(void)sig;
	counting = 0;
	const char *path = getenv("QA_MALLOC_OUT");
	int fd = path ? open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644) : 2;
	long n = atomic_load(&count);
	put(fd, "mallocs ");
	putnum(fd, n);
	put(fd, "\nmain ");
	putnum(fd, atomic_load(&count_main));
	put(fd, "\n");
	for (long k = 0; k < n && k < KEEP; k++) {
		put(fd, "--- allocation ");
		putnum(fd, k + 1);
		put(fd, ": ");
		putnum(fd, (long)sizes[k]);
		put(fd, tids[k] == (long)getpid() ? " bytes, main thread\n" : " bytes, another thread\n");
		backtrace_symbols_fd(stacks[k], depth[k], fd);
	}
	if (fd != 2)
		close(fd);
}

__attribute__((constructor)) static void shim_init(void)
{
	void *prime[2];
	backtrace(prime, 2);   /* loads the unwinder now, not while counting */
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sa.sa_flags = SA_RESTART;
	sa.sa_handler = on_start;
	sigaction(SIGUSR1, &sa, NULL);
	sa.sa_handler = on_stop;
	sigaction(SIGUSR2, &sa, NULL);
}
EOF
if ! cc -shared -fPIC -O1 -o "$T/shim.so" "$T/shim.c" -ldl 2>"$T/cc.log"; then
	tap_fail "build the malloc shim" "$(cat "$T/cc.log")"; tap_done; exit 1
fi
count() { sed -n 's/^mallocs //p' "$1" 2>/dev/null; }
report() { [ -f "$1" ] && head -40 "$1"; }

# the robot takes signed commands from the network too, so both doors are counted
KEY="$T/command.key"
"$D" --gen-key "$KEY" >/dev/null
# a command_t to send during the count (its fingerprint; sent to nobody)
spawn cap python3 "$Q" capture $PORT "nobody$$.CMD" 10
wait_log cap listening 10
"$D" --command 'mode hold' --robot "nobody$$" --lcm-url "$URL" --key "$KEY" --timeout 0.3 >/dev/null 2>&1
wait_for 5 grep -qE '^[0-9a-f]{40,}$' "$T/cap.log"
TEMPLATE=$(grep -E '^[0-9a-f]{40,}$' "$T/cap.log" | head -1)

spawn sim "$S" --link "$T/bus" --ids 1,2 --name r1 --lcm-url "$URL" --seed 2 --return-delay 0
wait_log sim 'ready' 10 || { tap_fail "simulator ready" "$(cat "$T/sim.log")"; tap_done; exit 1; }
QA_MALLOC_OUT="$T/watch.count" LD_PRELOAD="$T/shim.so" spawn watch "$D" --watch "$R" --raw --lcm-url "$URL"
# a short ramp: the oscillator takes over from the starter within ~1.5 s
QA_MALLOC_OUT="$T/d.count" LD_PRELOAD="$T/shim.so" spawn d "$D" --port "$T/bus" --ids 1,2 --robot "$R" --mode oscillator \
	--lcm-url "$URL" --set robot.ramp_s=0.3 --set robot.commands=network --set robot.command_key="$KEY"
if wait_log d "ready: $R.STATE" 10 && wait_for 10 cycle_at_least 250; then
	tap_ok "daemon runs OSCILLATOR against the simulator (shim preloaded)"
else
	tap_fail "daemon runs" "$(tail -5 "$T/d.log")"; tap_done; exit 1
fi

# steady state: 3 s, nothing coming in but the group's own traffic
c0=$(last_state | field cycle)
kill -USR1 "$pid_d" "$pid_watch"
wait_for 10 cycle_at_least $((c0 + 300))
kill -USR2 "$pid_d" "$pid_watch"
wait_for 5 test -s "$T/d.count"
wait_for 5 test -s "$T/watch.count"
s=$(last_state)
echo "# steady state cycles $c0 .. $(echo "$s" | field cycle), mode $(echo "$s" | field mode), amp $(echo "$s" | field amp0) rad"
n=$(count "$T/d.count")
if [ "$n" = 0 ]; then tap_ok "no allocation in 3 s of steady state (300 cycles)"
else tap_fail "no allocation in steady state" "${n:-no report} allocations
$(report "$T/d.count")"; fi
w=$(count "$T/watch.count")
if [ -n "$w" ] && [ "$w" -gt 0 ]; then tap_ok "the shim counts allocations (the watcher's decoders: $w)"
else tap_fail "the shim counts allocations" "watcher count '${w}'"; fi
if [ "$(echo "$s" | field mode)" = 3 ]; then tap_ok "it was OSCILLATOR"; else tap_fail "it was OSCILLATOR" "$s"; fi

# commands: accepted, rejected and undecodable ones, from the local socket
# and the network, are handled without allocating. Each must have reached the
# daemon: its answer, and the rejections counted in robot_state_t.
"$D" --command 'param c 0.003 0' --robot "$R" --lcm-url "$URL" --timeout 2 >/dev/null 2>&1
bad0=$(last_state | field bad_commands)
rm -f "$T/d.count"
kill -USR1 "$pid_d"
"$D" --command 'param c 0.002 0' --robot "$R" --lcm-url "$URL" --timeout 2 >"$T/cmd1.out" 2>&1; a1=$?
"$D" --command 'param k nan 0' --robot "$R" --lcm-url "$URL" --timeout 2 >"$T/cmd2.out" 2>&1; a2=$?
"$D" --command 'param c 0.0025 1' --robot "$R" --lcm-url "$URL" --key "$KEY" --timeout 2 >"$T/cmd3.out" 2>&1; a3=$?
[ -n "$TEMPLATE" ] && python3 "$Q" hostile $PORT "$R" "$TEMPLATE" 3 60 0.6 "$KEY" >"$T/hostile.out" 2>&1
wait_for 5 cycle_at_least $(( $(last_state | field cycle) + 20 ))
kill -USR2 "$pid_d"
wait_for 5 test -s "$T/d.count"
n=$(count "$T/d.count")
bad1=$(last_state | field bad_commands)
echo "# accepted: $(cat "$T/cmd1.out"); rejected: $(cat "$T/cmd2.out"); signed: $(cat "$T/cmd3.out"); $(cat "$T/hostile.out" 2>/dev/null)"
sent=$(sed -n 's/^sent \([0-9]*\) .*/\1/p' "$T/hostile.out")
if [ "$a1" = 0 ] && [ "$a2" = 1 ] && [ "$a3" = 0 ] && [ "${sent:-0}" = 60 ] && [ $((bad1 - bad0)) -ge 55 ] &&
	[ "$n" = 0 ]; then
	tap_ok "no allocation while handling 63 commands (3 answered, $((bad1 - bad0)) refusals counted)"
else tap_fail "no allocation handling commands" "accept rc $a1, reject rc $a2, signed rc $a3, hostile sent '${sent}', refusals counted $bad0 -> $bad1, ${n:-no report} allocations
$(report "$T/d.count")"; fi
# new channel names on the group cost the daemon nothing: it has no LCM
# receive (whose table of names never shrinks); its own socket drops them
rm -f "$T/d.count"
kill -USR1 "$pid_d"
python3 "$Q" names $PORT "nobody$$-" 1000 >"$T/names.out" 2>&1
wait_for 5 cycle_at_least $(( $(last_state | field cycle) + 10 ))
kill -USR2 "$pid_d"
wait_for 5 test -s "$T/d.count"
echo "# $(cat "$T/names.out") messages on new channel names: $(count "$T/d.count") allocations"
if [ "$(cat "$T/names.out")" = "sent 1000" ] && [ "$(count "$T/d.count")" = 0 ]; then
	tap_ok "1000 new channel names: nothing allocated"
else tap_fail "new channel names: nothing allocated" "$(cat "$T/names.out"); $(report "$T/d.count")"; fi
stop d >/dev/null
if [ "$stop_rc" = 0 ]; then tap_ok "clean stop"; else tap_fail "clean stop" "exit $stop_rc"; fi

# ---- on Protocol 2.0: XM430-W350 servos in current control (torque actuation) ----------------
# the SYNC_READ into its fixed buffer, both read-back blocks, the drive's SYNC_WRITE
spawn simx "$S" --model xm430-w350 --link "$T/xbus" --ids 1,2 --name x1 --baud 1000000 --lcm-url "$URL" --seed 2 \
	--return-delay 0 --control "$T/ctlx"
wait_log simx 'ready' 10 || { tap_fail "X simulator ready" "$(cat "$T/simx.log")"; tap_done; exit 1; }
RX="qx$$"
spawn watchx "$D" --watch "$RX" --raw --lcm-url "$URL"
xcycle() { grep -a "^STATE $RX " "$T/watchx.log" | tail -1 | field cycle; }
xcycle_at_least() { [ "$(xcycle)" -ge "$1" ] 2>/dev/null; }
QA_MALLOC_OUT="$T/dx.count" LD_PRELOAD="$T/shim.so" spawn dx "$D" --port "$T/xbus" --ids 1,2 --robot "$RX" \
	--mode oscillator --lcm-url "$URL" --set robot.ramp_s=0.3 --set robot.actuation=torque --set robot.torque_drive=current
if wait_log dx "ready: $RX.STATE" 15 && wait_for 10 xcycle_at_least 250; then
	c0=$(xcycle)
	kill -USR1 "$pid_dx"
	wait_for 10 xcycle_at_least $((c0 + 300))
	kill -USR2 "$pid_dx"
	wait_for 5 test -s "$T/dx.count"
	n=$(count "$T/dx.count")
	mode=$(echo 'peek x1 1 operating_mode' | socat -t 2 - UNIX-CONNECT:"$T/ctlx" 2>/dev/null)
	if [ "$n" = 0 ] && [ "$mode" = "ok 0" ]; then
		tap_ok "Protocol 2.0, current control: no allocation in 300 cycles of steady state"
	else tap_fail "no allocation on Protocol 2.0, in current control" "operating mode '$mode'; ${n:-no report} allocations
$(report "$T/dx.count")"; fi
else
	tap_fail "daemon runs on the X bus (shim preloaded)" "$(tail -5 "$T/dx.log")"
fi
stop dx >/dev/null
tap_done
