/* test_web_params.c — one range per parameter, said alike by every program
 * that checks it: the daemon (a command), undulate-top (its + nudge) and
 * undulate-web (a command from the page, and the table it serves the page
 * at /api/params) refuse the same out-of-range value with the same range
 * in the message, taken from common/params.h. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "daemon/command.h"
#include "daemon/config.h"
#include "params.h"
#include "../../tools/top/keys.h"
#include "../../tools/top/model.h"
#include "../../tools/web/req.h"

/* 2.6 + undulate-top's step (0.05) is 2.65: past 150 degrees (2.618 rad) */
#define T_OUTSIDE "2.65"
#define T_RANGE "out of range 0..2.618"

static void test_daemon_refuses(void **state)
{
	(void)state;
	struct cfg c;
	struct cfg_errors e;
	struct cmd_request r;
	char param[CMD_STR_MAX], why[200];
	cfg_defaults(&c);
	memset(&e, 0, sizeof e);
	assert_true(cfg_override(&c, "robot.ids=1,2", &e) && cfg_override(&c, "robot.port=/dev/null", &e) &&
	            cfg_finish(&c, &e));
	memset(&r, 0, sizeof r);
	assert_true(cmd_parse_text("param amplitude " T_OUTSIDE, &r, param, sizeof param, why, sizeof why));
	r.robot = c.name;
	r.param = param;
	assert_int_not_equal(cmd_check(&r, &c, true, why, sizeof why), CMD_ACCEPT);
	assert_non_null(strstr(why, "amplitude: " T_OUTSIDE " " T_RANGE));
}

static void test_top_refuses(void **state)
{
	(void)state;
	static struct top_model model;
	top_model_init(&model);
	char name[] = "r1", reason[] = "test", fault[] = "";
	undulate_joint_state_t j[2] = { { .servo_id = 1 }, { .servo_id = 2 } };
	undulate_robot_state_t s = { .utime = 1, .robot = name, .mode = UNDULATE_ROBOT_STATE_T_MODE_SINUSOID,
	                             .mode_reason = reason, .fault = fault, .njoints = 2, .joints = j };
	top_on_state(&model, &s, 0.0);
	double k[2] = { 1, 1 }, c[2] = { 0.02, 0.02 }, mu[2] = { 1, 1 }, z[2] = { 0, 0 };
	undulate_osc_params_t p = { .robot = name, .njoints = 2, .k = k, .c = c, .mu = mu, .lambda = z, .inertia = z,
	                            .friction = z, .neutral = z, .limit_min = z, .limit_max = z, .amplitude = 2.6 };
	top_on_params(&model, &p);
	struct top_command out[TOP_MAX_JOINTS];
	char why[200];
	assert_int_equal(top_command_nudge(out, &model.robots[0], 1, 1, "me", why, sizeof why), -1);
	assert_non_null(strstr(why, "amplitude " T_OUTSIDE "0 rad " T_RANGE));
	/* the step it nudges by is the table's */
	p.amplitude = 1.0;
	top_on_params(&model, &p);
	assert_int_equal(top_command_nudge(out, &model.robots[0], 1, 2, "me", why, sizeof why), 1);
	assert_float_equal(out[0].msg.value, 1.0 + param_find("amplitude")->step, 1e-12);
}

static void test_web_refuses(void **state)
{
	(void)state;
	const char *msg = "cmd 7 r1 param amplitude " T_OUTSIDE;
	struct req_msg m;
	char why[200];
	assert_false(req_msg_parse(msg, strlen(msg), 2, &m, why, sizeof why));
	assert_non_null(strstr(why, "amplitude: " T_OUTSIDE " " T_RANGE));
}

/* What the page is served: every parameter a command may change, each with
 * the range as the programs say it, its unit and its step; nothing else. */
static void test_web_serves_the_table(void **state)
{
	(void)state;
	static char buf[8192];
	FILE *f = fmemopen(buf, sizeof buf, "w");
	assert_non_null(f);
	assert_true(param_table_json(f));
	fclose(f);
	assert_non_null(strstr(buf, "{\"name\":\"amplitude\",\"min\":0,\"max\":2.61799387799,\"min_open\":false,"
	                            "\"range\":\"0..2.618\",\"unit\":\"rad\",\"step\":0.05,\"per_joint\":false}"));
	size_t listed = 0;
	for (size_t i = 0; param_at(i) != NULL; i++) {
		char key[64];
		snprintf(key, sizeof key, "\"name\":\"%s\"", param_at(i)->key);
		assert_true((strstr(buf, key) != NULL) == param_at(i)->commandable);
		listed += param_at(i)->commandable;
	}
	assert_true(listed >= 12);
	assert_null(strstr(buf, "\"name\":\"neutral\""));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_daemon_refuses),
		cmocka_unit_test(test_top_refuses),
		cmocka_unit_test(test_web_refuses),
		cmocka_unit_test(test_web_serves_the_table),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
