/* test_daemon_command.c — command validation: every rejection path (limits
 * are the configuration's alone), the accepted kinds, addressing, decoding
 * and encoding command_t, and the --command text parser. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../../daemon/command.h"
#include "../../daemon/control.h"
#include "undulate_command_t.h"

static struct cfg cfg;

static int setup(void **state)
{
	(void)state;
	struct cfg_errors e = { 0 };
	cfg_defaults(&cfg);
	cfg_override(&cfg, "robot.name=robot1", &e);
	cfg_override(&cfg, "robot.port=/dev/null", &e);
	cfg_override(&cfg, "robot.ids=1,2", &e);
	return cfg_finish(&cfg, &e) ? 0 : -1;
}

static struct cmd_request base(int kind)
{
	return (struct cmd_request){ .seq = 7, .source = "test", .robot = "robot1", .kind = kind, .mode = 3,
	                             .param = "k", .joint = -1, .value = 0.05, .torque = true };
}

/* Expect a rejection whose reason contains `needle`. */
static void expect_reject(const struct cmd_request *r, bool direct, const char *needle)
{
	char why[256];
	enum cmd_verdict v = cmd_check(r, &cfg, direct, why, sizeof why);
	if (v != CMD_REJECT)
		fail_msg("expected a rejection containing '%s', got verdict %d", needle, v);
	if (strstr(why, needle) == NULL)
		fail_msg("reason '%s' does not contain '%s'", why, needle);
}

static void expect_accept(const struct cmd_request *r)
{
	char why[256];
	enum cmd_verdict v = cmd_check(r, &cfg, true, why, sizeof why);
	if (v != CMD_ACCEPT)
		fail_msg("expected acceptance, got %d: %s", v, why);
}

static void test_accepts_valid(void **state)
{
	(void)state;
	for (int m = 0; m < 4; m++) {
		struct cmd_request r = base(CMD_KIND_MODE);
		r.mode = m;
		expect_accept(&r);
	}
	struct cmd_request r = base(CMD_KIND_PARAM);
	expect_accept(&r);
	r.joint = 1;
	r.param = "lambda";
	r.value = -0.5;
	expect_accept(&r);
	r = base(CMD_KIND_PARAM);
	r.param = "amplitude";
	r.value = 0.6;
	expect_accept(&r);
	r = base(CMD_KIND_TORQUE);
	expect_accept(&r);
	r.robot = "*";
	expect_accept(&r);
}

static void test_addressing(void **state)
{
	(void)state;
	struct cmd_request r = base(CMD_KIND_MODE);
	char why[256];
	r.robot = "robot2";
	/* on the shared channel another robot's command is simply not ours */
	assert_int_equal(cmd_check(&r, &cfg, false, why, sizeof why), CMD_IGNORE);
	/* on our own channel it is a mistake worth answering */
	expect_reject(&r, true, "addressed to robot 'robot2'");
	r.robot = NULL;
	expect_reject(&r, true, "addressed to robot ''");
}

static void test_rejections(void **state)
{
	(void)state;
	struct cmd_request r = base(CMD_KIND_MODE);
	r.mode = 4;
	expect_reject(&r, true, "unknown mode 4");
	r.mode = -1;
	expect_reject(&r, true, "unknown mode -1");

	r = base(9);
	expect_reject(&r, true, "unknown command kind 9");
	r = base(0);
	expect_reject(&r, true, "unknown command kind 0");

	r = base(CMD_KIND_PARAM);
	r.param = "kk";
	expect_reject(&r, true, "unknown parameter 'kk'");
	r.param = NULL;
	expect_reject(&r, true, "unknown parameter ''");
	r = base(CMD_KIND_PARAM);
	r.value = NAN;
	expect_reject(&r, true, "not finite");
	r.value = INFINITY;
	expect_reject(&r, true, "not finite");
	r.value = -INFINITY;
	expect_reject(&r, true, "not finite");
	r = base(CMD_KIND_PARAM);
	r.joint = 2;
	expect_reject(&r, true, "joint 2 does not exist");
	r.joint = -2;
	expect_reject(&r, true, "joint -2 does not exist");
	r = base(CMD_KIND_PARAM);
	r.value = 0.0;   /* k >= 1e-4 */
	expect_reject(&r, true, "out of range");
	r.value = 5000;
	expect_reject(&r, true, "out of range");
	r = base(CMD_KIND_PARAM);
	r.param = "inertia";
	r.value = 1e-300;   /* a typo, not a tuning: the law would ask for the impossible */
	expect_reject(&r, true, "out of range");
	r.value = 1e-5;     /* in range, but with k 0.078 a 10 Hz oscillator */
	expect_reject(&r, true, "natural frequency");
	r = base(CMD_KIND_PARAM);
	r.param = "frequency";
	r.joint = 0;
	expect_reject(&r, true, "per robot: joint must be -1");
}

/* Nothing that bounds where a joint may go can be commanded, whatever the
 * value, the joint or the robot it is addressed to. */
static void test_limits_not_commandable(void **state)
{
	(void)state;
	const char *names[] = { "limit_min", "limit_max", "neutral", "max_step" };
	const double values[] = { -2.6, 2.6, 0.0, 0.01, -0.1, 0.5 };
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
		for (size_t k = 0; k < sizeof values / sizeof values[0]; k++) {
			for (int joint = -1; joint < 2; joint++) {
				struct cmd_request r = base(CMD_KIND_PARAM);
				r.param = names[i];
				r.value = values[k];
				r.joint = joint;
				expect_reject(&r, true, "only the configuration file");
				r.robot = "*";
				expect_reject(&r, false, "only the configuration file");
			}
		}
		/* and given to the controller anyway (a caller that skipped the
		 * check): refused there too, nothing changes */
		static struct ctl ctl;
		ctl_init(&ctl, &cfg);
		struct cfg_params before = ctl.p;
		char why[256];
		for (int joint = -1; joint < 2; joint++)
			assert_false(ctl_set_param(&ctl, names[i], joint, 0.25, why, sizeof why));
		assert_memory_equal(&ctl.p, &before, sizeof before);
		assert_null(cfg_params_field(&ctl.p, names[i], 0));
	}
}

/* An accepted parameter is the controller's to apply (ctl_set_param):
 * joint -1 is every joint; the configuration keeps its start values. */
static void test_apply(void **state)
{
	(void)state;
	static struct ctl ctl;
	struct cfg saved = cfg;
	char why[256];
	ctl_init(&ctl, &cfg);
	assert_true(ctl_set_param(&ctl, "c", -1, 0.004, why, sizeof why));
	assert_true(ctl.p.osc[0].c == 0.004 && ctl.p.osc[1].c == 0.004);
	assert_true(ctl_set_param(&ctl, "c", 1, 0.005, why, sizeof why));
	assert_true(ctl.p.osc[0].c == 0.004 && ctl.p.osc[1].c == 0.005);
	assert_true(ctl_set_param(&ctl, "phase", -1, 1.25, why, sizeof why));
	assert_true(ctl.p.phase == 1.25);
	assert_memory_equal(&cfg, &saved, sizeof cfg);
}

/* A value is judged against the values the robot runs with: k that the
 * configuration's inertia would refuse (natural frequency above 5 Hz) is
 * accepted once a command raised the inertia, and the other way round. */
static void test_judged_against_live(void **state)
{
	(void)state;
	static struct ctl ctl;
	char why[256];
	ctl_init(&ctl, &cfg);
	struct cmd_request r = base(CMD_KIND_PARAM);
	r.joint = 0;
	r.value = cfg.joint[0].osc.inertia * pow(2.0 * M_PI * 6.0, 2.0);   /* 6 Hz at this inertia */
	expect_reject(&r, true, "natural frequency");
	assert_int_equal(cmd_check_live(&r, &cfg, &ctl.p, true, why, sizeof why), CMD_REJECT);
	assert_true(ctl_set_param(&ctl, "inertia", 0, 4.0 * cfg.joint[0].osc.inertia, why, sizeof why));
	assert_int_equal(cmd_check_live(&r, &cfg, &ctl.p, true, why, sizeof why), CMD_ACCEPT);
	assert_true(ctl_set_param(&ctl, "k", 0, r.value, why, sizeof why));
	/* now the inertia cannot go back under that k */
	assert_false(ctl_set_param(&ctl, "inertia", 0, cfg.joint[0].osc.inertia, why, sizeof why));
	if (strstr(why, "parameter inertia: joint 0: ") == NULL)
		fail_msg("why '%s'", why);
	assert_true(ctl.p.osc[0].k == r.value);
}

/* The clock's stiffness (torque actuation's SINUSOID as a torque law) is a
 * robot parameter, commandable within 0..10 N·m/rad, and only where the
 * servos' torque is driven: with position actuation only 0 (off). */
static void test_sinusoid_stiffness(void **state)
{
	(void)state;
	struct cmd_request r = base(CMD_KIND_PARAM);
	r.param = "stiffness";
	r.value = 0.135;
	expect_reject(&r, true, "needs [robot] actuation = torque");
	r.value = 0.0;
	expect_accept(&r);
	struct cfg saved = cfg;
	cfg.actuation = CFG_ACT_TORQUE;
	r.value = 0.135;
	expect_accept(&r);
	r.value = 10.5;
	expect_reject(&r, true, "out of range 0..10");
	r.value = 0.135;
	r.joint = 1;
	expect_reject(&r, true, "per robot: joint must be -1");
	r = base(CMD_KIND_PARAM);
	r.param = "damping";
	r.value = 0.02;
	expect_accept(&r);
	r.value = -0.01;
	expect_reject(&r, true, "out of range 0..1");
	static struct ctl ctl;
	char why[256];
	ctl_init(&ctl, &cfg);
	assert_true(ctl_set_param(&ctl, "damping", -1, 0.02, why, sizeof why));
	assert_true(ctl_set_param(&ctl, "stiffness", -1, 0.015, why, sizeof why));
	assert_true(ctl.p.sin_stiffness == 0.015 && ctl.p.sin_damping == 0.02);
	cfg = saved;
}

static void test_parse_text(void **state)
{
	(void)state;
	struct cmd_request r;
	char p[32], why[128];
	memset(&r, 0, sizeof r);
	assert_true(cmd_parse_text("mode oscillator", &r, p, sizeof p, why, sizeof why));
	assert_int_equal(r.kind, CMD_KIND_MODE);
	assert_int_equal(r.mode, CFG_MODE_OSCILLATOR);
	assert_true(cmd_parse_text("mode 9", &r, p, sizeof p, why, sizeof why));
	assert_int_equal(r.mode, 9);   /* passed through: the daemon validates */
	assert_true(cmd_parse_text("param k 0.06 1", &r, p, sizeof p, why, sizeof why));
	assert_int_equal(r.kind, CMD_KIND_PARAM);
	assert_string_equal(r.param, "k");
	assert_true(r.value == 0.06);
	assert_int_equal(r.joint, 1);
	assert_true(cmd_parse_text("param mu nan", &r, p, sizeof p, why, sizeof why));
	assert_true(isnan(r.value));
	assert_int_equal(r.joint, -1);
	assert_true(cmd_parse_text("torque off", &r, p, sizeof p, why, sizeof why));
	assert_int_equal(r.kind, CMD_KIND_TORQUE);
	assert_false(r.torque);
	assert_false(cmd_parse_text("torque maybe", &r, p, sizeof p, why, sizeof why));
	assert_true(cmd_parse_text("clear", &r, p, sizeof p, why, sizeof why));
	assert_int_equal(r.kind, CMD_KIND_CLEAR);
	assert_false(cmd_parse_text("clear all", &r, p, sizeof p, why, sizeof why));
	assert_false(cmd_parse_text("dance", &r, p, sizeof p, why, sizeof why));
	assert_false(cmd_parse_text("param k fast", &r, p, sizeof p, why, sizeof why));
	assert_false(cmd_parse_text("mode walk", &r, p, sizeof p, why, sizeof why));
}

/* cmd_decode reads what lcm-gen's encoder writes (catches a command_t.lcm that
 * changed under it), cuts long strings, and refuses every malformed message
 * that LCM 1.3.1's generated decoder would malloc garbage for. */
static int encode(const undulate_command_t *m, uint8_t *buf, int cap)
{
	int n = undulate_command_t_encoded_size(m);
	assert_true(n > 0 && n <= cap);
	assert_int_equal(undulate_command_t_encode(buf, 0, cap, m), n);
	return n;
}

static void test_decode(void **state)
{
	(void)state;
	static uint8_t buf[4096];
	char why[160], longname[300];
	memset(longname, 'x', sizeof longname - 1);
	longname[sizeof longname - 1] = '\0';
	int64_t fp = __undulate_command_t_get_hash();
	undulate_command_t m = { .utime = 1, .seq = -77, .source = "qa", .robot = "robot1", .kind = 2, .mode = -3,
	                         .param = "limit_max", .joint = -32768, .value = -0.25, .torque = 1 };
	static struct cmd_wire w;
	int n = encode(&m, buf, sizeof buf);
	assert_true(cmd_decode(buf, (size_t)n, fp, &w, why, sizeof why));
	assert_int_equal(w.req.seq, -77);
	assert_string_equal(w.req.source, "qa");
	assert_string_equal(w.req.robot, "robot1");
	assert_int_equal(w.req.kind, 2);
	assert_int_equal(w.req.mode, -3);
	assert_string_equal(w.req.param, "limit_max");
	assert_int_equal(w.req.joint, -32768);
	assert_true(w.req.value == -0.25);
	assert_true(w.req.torque);
	/* every prefix is refused */
	for (int k = 0; k < n; k++)
		assert_false(cmd_decode(buf, (size_t)k, fp, &w, why, sizeof why));
	assert_false(cmd_decode(buf, (size_t)n, fp + 1, &w, why, sizeof why));
	assert_non_null(strstr(why, "fingerprint"));
	/* a string length that lies: negative, zero, past the end; a missing NUL */
	const int32_t lies[] = { -1, INT32_MIN, 0, INT32_MAX, 1000 };
	for (size_t i = 0; i < sizeof lies / sizeof lies[0]; i++) {
		n = encode(&m, buf, sizeof buf);
		uint32_t v = (uint32_t)lies[i];
		buf[24] = (uint8_t)(v >> 24); buf[25] = (uint8_t)(v >> 16); buf[26] = (uint8_t)(v >> 8); buf[27] = (uint8_t)v;
		assert_false(cmd_decode(buf, (size_t)n, fp, &w, why, sizeof why));
		assert_non_null(strstr(why, "malformed"));
	}
	n = encode(&m, buf, sizeof buf);
	buf[8 + 16 + 4 + 2] = 'y';   /* the NUL of source "qa" */
	assert_false(cmd_decode(buf, (size_t)n, fp, &w, why, sizeof why));
	/* a name longer than CMD_STR_MAX - 1 (which no robot name reaches), or
	 * with a NUL inside, would say less than the sender wrote: refused */
	m.robot = longname;
	m.param = longname;
	m.source = longname;
	n = encode(&m, buf, sizeof buf);
	assert_false(cmd_decode(buf, (size_t)n, fp, &w, why, sizeof why));
	assert_non_null(strstr(why, "longer than"));
	assert_true(CMD_STR_MAX - 1 > CFG_NAME_MAX - 1);
	m.source = m.param = "k";
	m.robot = "robot1\0";   /* lcm-gen writes up to the first NUL: build one by hand */
	n = encode(&m, buf, sizeof buf);
	buf[8 + 16 + 4 + 2] = 0;   /* source "k": its NUL stays, fine */
	assert_true(cmd_decode(buf, (size_t)n, fp, &w, why, sizeof why));
	buf[8 + 16 + 4 + 2 + 4 + 2] = 0;   /* "robot1" -> "ro\0ot1": a NUL inside */
	assert_false(cmd_decode(buf, (size_t)n, fp, &w, why, sizeof why));
	/* bytes after the end are no command_t either */
	n = encode(&m, buf, sizeof buf);
	assert_false(cmd_decode(buf, (size_t)n + 1, fp, &w, why, sizeof why));
	/* NaN survives decoding bit for bit, for cmd_check to refuse */
	m.robot = "robot1";
	m.param = "k";
	m.joint = 0;
	m.value = NAN;
	n = encode(&m, buf, sizeof buf);
	assert_true(cmd_decode(buf, (size_t)n, fp, &w, why, sizeof why));
	assert_true(isnan(w.req.value));
	assert_int_equal(cmd_check(&w.req, &cfg, true, why, sizeof why), CMD_REJECT);
}

/* cmd_encode writes what lcm-gen's encoder writes, byte for byte, and says
 * where the MAC starts: the MAC covers every byte before it. */
static void test_encode(void **state)
{
	(void)state;
	static uint8_t ours[1024], theirs[1024];
	int64_t fp = __undulate_command_t_get_hash();
	struct cmd_request r = { .utime = 1700000000123456, .seq = 42, .source = "a@b", .robot = "robot1",
	                         .kind = CMD_KIND_PARAM, .mode = 2, .param = "mu", .joint = 1, .value = -0.125,
	                         .torque = true };
	uint8_t mac[CMD_MAC_BYTES];
	for (size_t i = 0; i < sizeof mac; i++)
		mac[i] = (uint8_t)(0xA0 + i);
	size_t signed_len = 0;
	size_t n = cmd_encode(&r, fp, mac, ours, sizeof ours, &signed_len);
	undulate_command_t m = { .utime = r.utime, .seq = r.seq, .source = "a@b", .robot = "robot1", .kind = 2,
	                         .mode = 2, .param = "mu", .joint = 1, .value = -0.125, .torque = 1 };
	memcpy(m.mac, mac, sizeof mac);
	int k = encode(&m, theirs, sizeof theirs);
	assert_int_equal(n, (size_t)k);
	assert_memory_equal(ours, theirs, n);
	assert_int_equal(signed_len, n - CMD_MAC_BYTES);
	static struct cmd_wire w;
	char why[128];
	assert_true(cmd_decode(ours, n, fp, &w, why, sizeof why));
	assert_int_equal(w.signed_len, signed_len);
	assert_memory_equal(w.mac, mac, sizeof mac);
	assert_true(w.req.utime == r.utime);
	/* a buffer too small: 0, nothing claimed */
	assert_int_equal(cmd_encode(&r, fp, NULL, ours, n - 1, NULL), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_accepts_valid),
		cmocka_unit_test(test_addressing),
		cmocka_unit_test(test_rejections),
		cmocka_unit_test(test_limits_not_commandable),
		cmocka_unit_test(test_encode),
		cmocka_unit_test(test_apply),
		cmocka_unit_test(test_judged_against_live),
		cmocka_unit_test(test_sinusoid_stiffness),
		cmocka_unit_test(test_parse_text),
		cmocka_unit_test(test_decode),
	};
	return cmocka_run_group_tests(tests, setup, NULL);
}
