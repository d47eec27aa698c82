/* test_daemon_cmdin.c — where commands come in: a struct cin opened with its
 * run directory in a scratch directory, fake clocks and an event hook that
 * records, a controller set up as in test_daemon_control.c. Datagrams are
 * handed to cin_local_datagram / cin_network_datagram directly (and once
 * through the real local socket, for the answer). Covered: a queued command
 * applied at the boundary with its strings intact after the stack it came
 * from is reused; commands = off; refusals at intake never queued; the 17th
 * command of a period "busy"; the network door's channels, signatures,
 * replays and time window; the rate limits of what reaches the event
 * channel; and cin_open's failures. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../daemon/cmdin.h"
#include "../../daemon/control.h"
#include "dxl_table.h"
#include "scratch.h"
#include "undulate_command_t.h"
#include "undulate_event_t.h"
#include "wire.h"

#define T0 1700000000000000LL   /* wall clock at cin_open, µs */

static struct cfg cfg;
static struct ctl ctl;
static struct cin in;
static int64_t fake_wall;
static uint64_t fake_mono;
static int64_t fp;
static struct auth_key key;

/* ---- the hooks ------------------------------------------------------------------------------ */
struct ev {
	int64_t seq;
	int level;
	char kind[32];
	char text[512];
};
#define EV_MAX 4096
static struct ev evs[EV_MAX];
static size_t nev;

static void hook_event(void *ctx, int64_t seq, int level, const char *kind, const char *text)
{
	assert_ptr_equal(ctx, &evs);
	assert_true(nev < EV_MAX);
	evs[nev].seq = seq;
	evs[nev].level = level;
	snprintf(evs[nev].kind, sizeof evs[nev].kind, "%s", kind);
	snprintf(evs[nev].text, sizeof evs[nev].text, "%s", text);
	nev++;
}

static int64_t hook_wall(void *ctx)
{
	(void)ctx;
	return fake_wall;
}

static uint64_t hook_mono(void *ctx)
{
	(void)ctx;
	return fake_mono;
}

static const struct cin_hooks hooks = { .ctx = &evs, .event = hook_event, .wall_us = hook_wall,
	                                .mono_us = hook_mono };

static size_t count_kind(const char *kind)
{
	size_t n = 0;
	for (size_t i = 0; i < nev; i++)
		n += strcmp(evs[i].kind, kind) == 0;
	return n;
}

/* The last event, which must be new since the previous call (or the test's
 * start), of `kind` and contain `needle`. */
static size_t ev_checked;

static const struct ev *expect_last_event(const char *kind, const char *needle)
{
	if (nev <= ev_checked)
		fail_msg("no new event (want %s with '%s')", kind, needle);
	ev_checked = nev;
	const struct ev *e = &evs[nev - 1];
	if (strcmp(e->kind, kind) != 0 || strstr(e->text, needle) == NULL)
		fail_msg("last event %s '%s', want %s with '%s'", e->kind, e->text, kind, needle);
	return e;
}

/* ---- set-up --------------------------------------------------------------------------------- */
static int group_setup(void **state)
{
	(void)state;
	log_set_level(LOG_LVL_ERROR);   /* the refusals' lines would fill the test log */
	fp = __undulate_command_t_get_hash();
	for (size_t i = 0; i < AUTH_KEY_BYTES; i++)
		key.bytes[i] = (uint8_t)(0x40 + i);
	return scratch_make("cmdin");
}

static int group_teardown(void **state)
{
	(void)state;
	return scratch_remove();
}

static void make_cfg(struct cfg *c)
{
	struct cfg_errors e = { 0 };
	char run_dir[300];
	snprintf(run_dir, sizeof run_dir, "robot.run_dir=%s", scratch_dir);
	cfg_defaults(c);
	assert_true(cfg_override(c, "robot.name=robot1", &e));
	assert_true(cfg_override(c, "robot.port=/dev/null", &e));
	assert_true(cfg_override(c, "robot.ids=1,2", &e));
	assert_true(cfg_override(c, "robot.mode=oscillator", &e)); /* running: commands change it */
	assert_true(cfg_override(c, run_dir, &e));
	assert_true(cfg_override(c, "robot.lcm_url=udpm://239.255.76.67:7667?ttl=0", &e));
	assert_true(cfg_finish(c, &e));
}

static int setup(void **state)
{
	(void)state;
	make_cfg(&cfg);
	fake_wall = T0;
	fake_mono = 5000000;
	nev = ev_checked = 0;
	char why[300];
	if (!cin_open(&in, &cfg, &ctl, &hooks, fp, why, sizeof why)) {
		print_error("cin_open: %s\n", why);
		return -1;
	}
	/* the controller, as test_daemon_control.c sets it up */
	ctl_init(&ctl, &cfg);
	struct ctl_servo_info info = { .cw_limit = 0, .ccw_limit = 1023, .max_torque = 1023, .status_return_level = 2 };
	for (size_t j = 0; j < 2; j++) {
		if (!ctl_set_servo(&ctl, j, &info, why, sizeof why))
			return -1;
		ctl_measure(&ctl, j, dxl_rad_to_pos(0.1), 0, 0, 0, 0.01);
	}
	ctl_start(&ctl, 0.0, "test");
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	cin_close(&in);
	return 0;
}

/* Network commands: the robot's key, as if cin_open had loaded it (opening
 * the network door needs a multicast route; what is tested here is what
 * happens to a datagram once it is read). */
static void go_network(void)
{
	cfg.commands = CFG_CMD_NETWORK;
	in.key = key;
}

/* ---- commands ------------------------------------------------------------------------------- */
static struct cmd_request base_cmd(int kind, int64_t seq)
{
	return (struct cmd_request){ .utime = fake_wall, .seq = seq, .source = "operator-1", .robot = "robot1",
	                             .kind = kind, .mode = CFG_MODE_HOLD, .param = "amplitude", .joint = -1,
	                             .value = 0.5, .torque = true };
}

static const struct csock_peer local_peer = { .cred = true, .uid = 1000, .gid = 1000, .pid = 4242 };

static void send_local(const struct cmd_request *r)
{
	uint8_t buf[1024];
	size_t n = cmd_encode(r, fp, NULL, buf, sizeof buf, NULL);
	assert_true(n > 0);
	cin_local_datagram(&in, buf, n, false, &local_peer);
}

/* Encodes r, signed with k (NULL: unsigned), into a udpm datagram on channel. */
static size_t net_datagram(const struct cmd_request *r, const struct auth_key *k, const char *channel, uint8_t *d,
                           size_t cap)
{
	uint8_t buf[1024];
	size_t signed_len = 0;
	size_t n = cmd_encode(r, fp, NULL, buf, sizeof buf, &signed_len);
	assert_true(n > 0);
	if (k != NULL)
		auth_mac(k, buf, signed_len, buf + signed_len);
	size_t len = wire_udpm_build(d, cap, 77, channel, buf, n);
	assert_true(len > 0);
	return len;
}

static void send_net(const struct cmd_request *r, const struct auth_key *k, const char *channel)
{
	uint8_t d[CIN_DGRAM_MAX];
	size_t n = net_datagram(r, k, channel, d, sizeof d);
	cin_network_datagram(&in, d, n, false);
}

/* The same, a second after the last datagram: each refusal's event then
 * passes the limiter of unauthenticated traffic (one a second). */
static void send_net_later(const struct cmd_request *r, const struct auth_key *k, const char *channel)
{
	fake_mono += 1000000;
	send_net(r, k, channel);
}

static void dgram_later(const uint8_t *d, size_t n, bool truncated)
{
	fake_mono += 1000000;
	cin_network_datagram(&in, d, n, truncated);
}

/* Reuses the stack below the caller, as the daemon's loop does between a
 * datagram's intake and the cycle boundary. */
static __attribute__((noinline)) void clobber_stack(void)
{
	volatile char junk[32768];
	for (size_t i = 0; i < sizeof junk; i++)
		junk[i] = 'Z';
	(void)junk[sizeof junk - 1];
}

/* ---- tests ---------------------------------------------------------------------------------- */
static void test_queued_then_applied(void **state)
{
	(void)state;
	double amp0 = cfg.amplitude, k0 = cfg.joint[0].osc.k;
	struct cmd_request r = base_cmd(CMD_KIND_PARAM, 11);
	send_local(&r);
	r = base_cmd(CMD_KIND_PARAM, 12);
	r.param = "k";
	r.joint = 0;
	r.value = 0.05;
	send_local(&r);
	r = base_cmd(CMD_KIND_MODE, 13);
	send_local(&r);
	/* queued, not applied: nothing changed, nothing answered yet */
	assert_int_equal(cin_pending(&in), 3);
	assert_int_equal(nev, 0);
	assert_true(ctl.p.amplitude == amp0);
	assert_true(ctl.p.osc[0].k == k0);
	assert_int_not_equal(ctl.mode, CFG_MODE_HOLD);
	/* the intake's stack is gone by the boundary */
	clobber_stack();
	cin_apply(&in, &ctl);
	assert_int_equal(cin_pending(&in), 0);
	assert_true(ctl.p.amplitude == 0.5);
	assert_true(ctl.p.osc[0].k == 0.05);
	assert_true(ctl.p.osc[1].k == k0);
	/* the controller owns the live values: the configuration keeps the start */
	assert_true(cfg.amplitude == amp0);
	assert_true(cfg.joint[0].osc.k == k0);
	assert_int_equal(ctl.mode, CFG_MODE_HOLD);
	if (strstr(ctl.reason, "uid 1000 pid 4242 'operator-1'") == NULL)
		fail_msg("reason '%s'", ctl.reason);
	/* answered in order, seq echoed, with what was done */
	assert_int_equal(nev, 3);
	assert_int_equal(count_kind("command-accepted"), 3);
	assert_int_equal(evs[0].seq, 11);
	assert_non_null(strstr(evs[0].text, "param amplitude = 0.5"));
	assert_int_equal(evs[1].seq, 12);
	assert_non_null(strstr(evs[1].text, "param k = 0.05 (joint 0)"));
	assert_int_equal(evs[2].seq, 13);
	assert_non_null(strstr(evs[2].text, "mode HOLD"));
	assert_int_equal(in.received, 3);
	assert_int_equal(in.accepted, 3);
	assert_int_equal(cin_refused(&in), 0);
}

static void test_source_escaped(void **state)
{
	(void)state;
	struct cmd_request r = base_cmd(CMD_KIND_MODE, 1);
	r.source = "op\n<0>forged";
	send_local(&r);
	clobber_stack();
	cin_apply(&in, &ctl);
	assert_int_equal(ctl.mode, CFG_MODE_HOLD);
	assert_null(strchr(ctl.reason, '\n'));
	assert_non_null(strstr(ctl.reason, "op\\x0a<0>forged"));
}

static void test_commands_off(void **state)
{
	(void)state;
	cfg.commands = CFG_CMD_OFF;
	struct cmd_request r = base_cmd(CMD_KIND_MODE, 21);
	send_local(&r);
	assert_int_equal(cin_pending(&in), 0);
	assert_int_equal(in.rejected, 1);
	assert_int_equal(expect_last_event("command-rejected", "commands = off")->seq, 21);
	/* a signed network command too */
	go_network();
	cfg.commands = CFG_CMD_OFF;
	r.seq = 22;
	send_net(&r, &key, "robot1.CMD");
	assert_int_equal(cin_pending(&in), 0);
	assert_int_equal(in.rejected, 2);
	expect_last_event("command-rejected", "commands = off");
	cin_apply(&in, &ctl);
	assert_int_not_equal(ctl.mode, CFG_MODE_HOLD);
	assert_int_equal(count_kind("command-accepted"), 0);
	assert_int_equal(cin_refused(&in), 2);
}

static void test_refused_at_intake(void **state)
{
	(void)state;
	struct cfg_params before = ctl.p;
	struct {
		const char *param;
		int joint;
		double value;
		const char *needle;
	} bad[] = {
		{ "limit_max", 0, 0.1, "only the configuration file" },
		{ "neutral", -1, 0.0, "only the configuration file" },
		{ "max_step", 1, 0.01, "only the configuration file" },
		{ "k", 0, 100.0, "out of range" },
		{ "k", 7, 0.05, "does not exist" },
		{ "amplitude", 0, 0.5, "joint must be -1" },
		{ "frequency", -1, NAN, "not finite" },
		{ "nonsense", -1, 1.0, "unknown parameter" },
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		struct cmd_request r = base_cmd(CMD_KIND_PARAM, (int64_t)(100 + i));
		r.param = bad[i].param;
		r.joint = bad[i].joint;
		r.value = bad[i].value;
		send_local(&r);
		assert_int_equal(cin_pending(&in), 0);
		assert_int_equal(expect_last_event("command-rejected", bad[i].needle)->seq, (int64_t)(100 + i));
	}
	/* another robot's name on our own socket, an unknown kind and mode */
	struct cmd_request r = base_cmd(CMD_KIND_MODE, 200);
	r.robot = "robot2";
	send_local(&r);
	expect_last_event("command-rejected", "addressed to robot 'robot2'");
	r = base_cmd(CMD_KIND_MODE, 201);
	r.mode = 9;
	send_local(&r);
	expect_last_event("command-rejected", "unknown mode 9");
	r = base_cmd(77, 202);
	send_local(&r);
	expect_last_event("command-rejected", "unknown command kind 77");
	/* bytes that are no command_t, and a datagram cut by the socket */
	const uint8_t junk[] = "not a command";
	cin_local_datagram(&in, junk, sizeof junk, false, &local_peer);
	expect_last_event("command-rejected", "undecodable");
	uint8_t buf[1024];
	r = base_cmd(CMD_KIND_MODE, 203);
	size_t n = cmd_encode(&r, fp, NULL, buf, sizeof buf, NULL);
	cin_local_datagram(&in, buf, n, true, &local_peer);
	expect_last_event("command-rejected", "longer than a command_t");
	size_t refused = sizeof bad / sizeof bad[0] + 5;
	assert_int_equal(in.rejected, refused);
	assert_int_equal(in.received, refused);
	assert_int_equal(cin_pending(&in), 0);
	/* and the boundary has nothing to apply */
	size_t events = nev;
	cin_apply(&in, &ctl);
	assert_int_equal(nev, events);
	assert_memory_equal(&ctl.p, &before, sizeof before);
	assert_int_not_equal(ctl.mode, CFG_MODE_HOLD);
}

static void test_busy(void **state)
{
	(void)state;
	for (int i = 0; i < CIN_QUEUE; i++) {
		struct cmd_request r = base_cmd(CMD_KIND_PARAM, i);
		r.value = 0.01 * (i + 1);
		send_local(&r);
		assert_int_equal(cin_pending(&in), (size_t)i + 1);
	}
	assert_int_equal(nev, 0);
	struct cmd_request r = base_cmd(CMD_KIND_PARAM, 99);
	r.value = 0.99;
	send_local(&r);
	assert_int_equal(cin_pending(&in), CIN_QUEUE);
	assert_int_equal(in.busy, 1);
	assert_int_equal(cin_refused(&in), 1);
	assert_int_equal(expect_last_event("command-rejected", "busy")->seq, 99);
	/* the queue is applied in arrival order: the last queued value stays,
	 * the refused one never lands */
	cin_apply(&in, &ctl);
	assert_true(fabs(ctl.p.amplitude - 0.01 * CIN_QUEUE) < 1e-12);
	assert_int_equal(count_kind("command-accepted"), CIN_QUEUE);
	for (int i = 0; i < CIN_QUEUE; i++)
		assert_int_equal(evs[1 + i].seq, i);
	/* room again in the next period */
	send_local(&r);
	assert_int_equal(cin_pending(&in), 1);
	assert_int_equal(in.busy, 1);
}

static void test_network_ignored(void **state)
{
	(void)state;
	go_network();
	struct cmd_request r = base_cmd(CMD_KIND_MODE, 31);
	/* other channels on the group: not ours, not counted */
	const char *others[] = { "robot1.STATE", "robot2.CMD", "robot1.CMDX", "robot1.cmd", "UNDULATE.CMD2", "R" };
	for (size_t i = 0; i < sizeof others / sizeof others[0]; i++) {
		send_net(&r, &key, others[i]);
		send_net(&r, NULL, others[i]);
	}
	/* not LCM at all, and a fragment */
	const uint8_t junk[] = "hello";
	cin_network_datagram(&in, junk, sizeof junk, false);
	uint8_t d[CIN_DGRAM_MAX];
	size_t n = net_datagram(&r, NULL, "robot1.CMD", d, sizeof d);
	d[3] = '3';
	cin_network_datagram(&in, d, n, false);
	/* another robot's command on the shared channel, signed or not */
	r.robot = "robot2";
	send_net(&r, NULL, "UNDULATE.CMD");
	send_net(&r, &key, "UNDULATE.CMD");
	assert_int_equal(in.unauthenticated, 0);
	assert_int_equal(cin_refused(&in), 0);
	assert_int_equal(in.accepted, 0);
	assert_int_equal(cin_pending(&in), 0);
	assert_int_equal(nev, 0);
	assert_int_equal(in.received, 2);   /* only the two on a command channel */
}

static void test_network_refused(void **state)
{
	(void)state;
	go_network();
	struct auth_key wrong = key;
	wrong.bytes[31] ^= 1;
	struct cmd_request r = base_cmd(CMD_KIND_MODE, 41);
	/* unsigned */
	send_net_later(&r, NULL, "robot1.CMD");
	expect_last_event("command-rejected", "not signed");
	/* another key */
	r.seq = 42;
	send_net_later(&r, &wrong, "robot1.CMD");
	expect_last_event("command-rejected", "not signed");
	/* signed, then changed on the way */
	uint8_t d[CIN_DGRAM_MAX];
	r.seq = 43;
	size_t n = net_datagram(&r, &key, "robot1.CMD", d, sizeof d);
	d[n - CMD_MAC_BYTES - 1] ^= 1;   /* torque flag */
	dgram_later(d, n, false);
	expect_last_event("command-rejected", "not signed");
	assert_int_equal(in.unauthenticated, 3);
	/* a good one, then the same datagram again */
	r.seq = 44;
	n = net_datagram(&r, &key, "robot1.CMD", d, sizeof d);
	dgram_later(d, n, false);
	assert_int_equal(cin_pending(&in), 1);
	dgram_later(d, n, false);
	expect_last_event("command-rejected", "replayed");
	assert_int_equal(cin_pending(&in), 1);
	/* ... or an older sequence number at the same time */
	r.seq = 43;
	send_net_later(&r, &key, "robot1.CMD");
	expect_last_event("command-rejected", "replayed");
	/* outside the window (command_window_s), either way */
	int64_t win = (int64_t)(cfg.command_window_s * 1e6);
	fake_wall = T0 + 10 * win;
	r = base_cmd(CMD_KIND_MODE, 50);
	r.utime = fake_wall - win - 1;
	send_net_later(&r, &key, "robot1.CMD");
	expect_last_event("command-rejected", "too old");
	r.utime = fake_wall + win + 1;
	send_net_later(&r, &key, "robot1.CMD");
	expect_last_event("command-rejected", "from the future");
	/* signed before the robot started (a recording from an earlier run) */
	fake_wall = T0 + win / 4;
	r.utime = T0 - 1;
	r.source = "operator-2";
	send_net_later(&r, &key, "robot1.CMD");
	expect_last_event("command-rejected", "too old");
	/* undecodable, and longer than any command, on a command channel */
	uint8_t junk[64];
	memset(junk, 0xab, sizeof junk);
	n = wire_udpm_build(d, sizeof d, 1, "robot1.CMD", junk, sizeof junk);
	dgram_later(d, n, false);
	expect_last_event("command-rejected", "undecodable");
	dgram_later(d, n, true);
	expect_last_event("command-rejected", "longer than any command_t");
	assert_int_equal(in.unauthenticated, 10);
	assert_int_equal(in.rejected, 0);
	assert_int_equal(cin_refused(&in), 10);
	assert_int_equal(cin_pending(&in), 1);
	/* only the good one reaches the controller */
	cin_apply(&in, &ctl);
	assert_int_equal(count_kind("command-accepted"), 1);
	expect_last_event("command-accepted", "mode HOLD");
	assert_int_equal(evs[nev - 1].seq, 44);
}

static void test_network_signed_applied(void **state)
{
	(void)state;
	go_network();
	fake_wall = T0 + 1000000;
	struct cmd_request r = base_cmd(CMD_KIND_PARAM, 61);
	r.utime = fake_wall - 300000;   /* the sender's clock a little behind */
	r.value = 0.25;
	send_net(&r, &key, "robot1.CMD");
	/* every robot on the shared channel */
	r = base_cmd(CMD_KIND_MODE, 62);
	r.robot = "*";
	r.source = "operator-2";
	r.utime = fake_wall + 300000;   /* ... or ahead */
	send_net(&r, &key, "UNDULATE.CMD");
	/* this robot by name on the shared channel */
	r = base_cmd(CMD_KIND_PARAM, 63);
	r.param = "frequency";
	r.value = 0.6;
	r.source = "operator-3";
	send_net(&r, &key, "UNDULATE.CMD");
	assert_int_equal(cin_pending(&in), 3);
	assert_int_equal(in.unauthenticated, 0);
	assert_int_equal(nev, 0);
	clobber_stack();
	cin_apply(&in, &ctl);
	assert_int_equal(count_kind("command-accepted"), 3);
	assert_true(ctl.p.amplitude == 0.25);
	assert_true(ctl.p.frequency == 0.6);
	assert_int_equal(ctl.mode, CFG_MODE_HOLD);
	assert_non_null(strstr(ctl.reason, "the network 'operator-2'"));
	/* the next command of a source must be newer */
	r = base_cmd(CMD_KIND_MODE, 64);
	r.mode = CFG_MODE_LIMP;
	r.source = "operator-2";
	r.utime = fake_wall + 300000;
	send_net(&r, &key, "UNDULATE.CMD");
	assert_int_equal(cin_pending(&in), 1);
}

/* A flood of refusals: with the clock standing still, what reaches the event
 * channel is the limiter's burst (cin_open: 20 for authentic senders, 5 for
 * unauthenticated traffic), and the next one after the interval says how
 * many were left out. The two budgets are apart. */
static void test_rate_limits(void **state)
{
	(void)state;
	struct cmd_request r = base_cmd(CMD_KIND_PARAM, 0);
	r.param = "limit_min";
	for (int i = 0; i < 1000; i++) {
		r.seq = i;
		send_local(&r);
	}
	assert_int_equal(in.rejected, 1000);
	assert_int_equal(count_kind("command-rejected"), 20);
	for (size_t i = 0; i < nev; i++)
		assert_int_equal(evs[i].seq, (int64_t)i);
	/* one interval later: one more, with the count of those left out */
	fake_mono += 100000;
	r.seq = 1000;
	send_local(&r);
	assert_int_equal(count_kind("command-rejected"), 21);
	expect_last_event("command-rejected", "(and 980 more refused since)");

	/* unauthenticated network traffic: its own, smaller budget */
	go_network();
	size_t before = nev;
	r = base_cmd(CMD_KIND_MODE, 0);
	for (int i = 0; i < 1000; i++) {
		r.seq = 2000 + i;
		send_net(&r, NULL, "robot1.CMD");
	}
	assert_int_equal(in.unauthenticated, 1000);
	assert_int_equal(nev - before, 5);
	/* ... which it cannot spend for an authentic sender */
	fake_mono += 100000;
	r = base_cmd(CMD_KIND_PARAM, 5000);
	r.param = "limit_min";
	send_local(&r);
	assert_int_equal(nev - before, 6);
	expect_last_event("command-rejected", "only the configuration file");
	/* unauthenticated traffic earns one event a second, not sooner */
	r = base_cmd(CMD_KIND_MODE, 6000);
	send_net(&r, NULL, "robot1.CMD");
	fake_mono += 800000;
	send_net(&r, NULL, "robot1.CMD");
	assert_int_equal(nev - before, 6);
	fake_mono += 100000;
	send_net(&r, NULL, "robot1.CMD");
	assert_int_equal(nev - before, 7);
	expect_last_event("command-rejected", "(and 997 more refused since)");
}

/* The real local socket: a refusal is answered at once, an acceptance at the
 * boundary, to the sender's own address; the kernel's credentials name it. */
static void test_local_socket_answers(void **state)
{
	(void)state;
	char why[300];
	int c = csock_client_open(why, sizeof why);
	assert_true(c >= 0);
	uint8_t buf[1024];
	struct cmd_request r = base_cmd(CMD_KIND_MODE, 71);
	r.mode = 9;
	size_t n = cmd_encode(&r, fp, NULL, buf, sizeof buf, NULL);
	assert_true(csock_send(c, cin_local_path(&in), buf, n, why, sizeof why));
	r = base_cmd(CMD_KIND_MODE, 72);
	n = cmd_encode(&r, fp, NULL, buf, sizeof buf, NULL);
	assert_true(csock_send(c, cin_local_path(&in), buf, n, why, sizeof why));
	cin_on_local(&in);
	assert_int_equal(in.received, 2);
	assert_int_equal(cin_pending(&in), 1);
	ssize_t got = recv(c, buf, sizeof buf, MSG_DONTWAIT);
	assert_true(got > 0);
	undulate_event_t e;
	assert_true(undulate_event_t_decode(buf, 0, (int)got, &e) > 0);
	assert_string_equal(e.kind, "command-rejected");
	assert_string_equal(e.robot, "robot1");
	assert_int_equal(e.seq, 71);
	assert_non_null(strstr(e.text, "unknown mode 9"));
	undulate_event_t_decode_cleanup(&e);
	assert_int_equal(recv(c, buf, sizeof buf, MSG_DONTWAIT), -1);
	cin_apply(&in, &ctl);
	got = recv(c, buf, sizeof buf, MSG_DONTWAIT);
	assert_true(got > 0);
	assert_true(undulate_event_t_decode(buf, 0, (int)got, &e) > 0);
	assert_string_equal(e.kind, "command-accepted");
	assert_int_equal(e.seq, 72);
	undulate_event_t_decode_cleanup(&e);
	char who[64];
	snprintf(who, sizeof who, "uid %u pid %d 'operator-1'", (unsigned)getuid(), (int)getpid());
	if (strstr(ctl.reason, who) == NULL)
		fail_msg("reason '%s' does not name '%s'", ctl.reason, who);
	close(c);
}

static void test_open_failures(void **state)
{
	(void)state;
	char why[400] = "";
	struct stat st;
	/* a second daemon for this robot: refused, and closing it leaves the
	 * first one's socket alone */
	static struct cin second;
	assert_false(cin_open(&second, &cfg, &ctl, &hooks, fp, why, sizeof why));
	assert_non_null(strstr(why, "another undulated"));
	assert_int_equal(cin_local_fd(&second), -1);
	cin_close(&second);
	assert_int_equal(stat(cin_local_path(&in), &st), 0);
	assert_true(S_ISSOCK(st.st_mode));
	/* commands = network without a usable key: refused, no socket left behind */
	static struct cfg other;
	make_cfg(&other);
	snprintf(other.name, sizeof other.name, "robot9");
	other.commands = CFG_CMD_NETWORK;
	assert_true(snprintf(other.command_key, sizeof other.command_key, "%s/no-such.key", scratch_dir) <
	            (int)sizeof other.command_key);
	why[0] = '\0';
	assert_false(cin_open(&second, &other, NULL, &hooks, fp, why, sizeof why));
	assert_non_null(strstr(why, "command_key"));
	char p[CSOCK_PATH_MAX];
	assert_true(csock_path(p, sizeof p, scratch_dir, "robot9", other.lcm_url));
	assert_int_equal(stat(p, &st), -1);
	assert_int_equal(cin_local_fd(&second), -1);
	/* a key others may read is no key */
	char keyp[CFG_PATH_MAX];
	assert_true(snprintf(keyp, sizeof keyp, "%s/open.key", scratch_dir) < (int)sizeof keyp);
	FILE *f = fopen(keyp, "w");
	assert_non_null(f);
	fputs("000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n", f);
	fclose(f);
	assert_int_equal(chmod(keyp, 0644), 0);
	memcpy(other.command_key, keyp, sizeof keyp);
	assert_false(cin_open(&second, &other, NULL, &hooks, fp, why, sizeof why));
	assert_non_null(strstr(why, "chmod 600"));
	assert_int_equal(stat(p, &st), -1);
	/* a run_dir too long for any socket in it, and one that leaves no room
	 * for this robot's socket name: refused, with the reason */
	make_cfg(&other);
	memset(other.run_dir, 'd', 150);
	other.run_dir[0] = '/';
	other.run_dir[150] = '\0';
	snprintf(why, sizeof why, "unset");
	assert_false(cin_open(&second, &other, NULL, &hooks, fp, why, sizeof why));
	if (strstr(why, "too long") == NULL)
		fail_msg("why '%s'", why);
	other.run_dir[90] = '\0';
	assert_false(cin_open(&second, &other, NULL, &hooks, fp, why, sizeof why));
	assert_non_null(strstr(why, "does not fit a socket address"));
	cin_close(&second);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(test_queued_then_applied, setup, teardown),
		cmocka_unit_test_setup_teardown(test_source_escaped, setup, teardown),
		cmocka_unit_test_setup_teardown(test_commands_off, setup, teardown),
		cmocka_unit_test_setup_teardown(test_refused_at_intake, setup, teardown),
		cmocka_unit_test_setup_teardown(test_busy, setup, teardown),
		cmocka_unit_test_setup_teardown(test_network_ignored, setup, teardown),
		cmocka_unit_test_setup_teardown(test_network_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(test_network_signed_applied, setup, teardown),
		cmocka_unit_test_setup_teardown(test_rate_limits, setup, teardown),
		cmocka_unit_test_setup_teardown(test_local_socket_answers, setup, teardown),
		cmocka_unit_test_setup_teardown(test_open_failures, setup, teardown),
	};
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
