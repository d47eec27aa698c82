/* test_top_model.c — undulate-top's model, keys, commands and screen,
 * without a terminal or a network. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../tools/top/keys.h"
#include "../../tools/top/model.h"
#include "../../tools/top/render.h"

#define T_SCREEN (256 * 1024)

static struct top_model model;
static char screen[T_SCREEN];

/* A STATE from robot NAME at time NOW with joint phases PH0, PH1. */
static void feed_state(const char *name, double now, double ph0, double ph1, double jitter, int mode)
{
	char n[32], reason[] = "test";
	snprintf(n, sizeof(n), "%s", name);
	undulate_joint_state_t j[2] = {
		{ .servo_id = 1, .angle = 0.8 * cos(ph0), .phase = ph0, .amplitude = 0.8, .frequency = 0.8 },
		{ .servo_id = 2, .angle = 0.8 * cos(ph1), .phase = ph1, .amplitude = 0.8, .frequency = 0.8,
		  .error_bits = 0 },
	};
	undulate_robot_state_t s = { .utime = (int64_t)(now * 1e6), .robot = n, .mode = (int8_t)mode,
		.mode_reason = reason, .fault = "", .period_us = 10000.0, .jitter_us = jitter, .njoints = 2, .joints = j };
	top_on_state(&model, &s, now);
}

/* The model as --json prints it. */
static const char *json_of(double now)
{
	static char buf[65536];
	FILE *f = fmemopen(buf, sizeof(buf), "w");
	assert_non_null(f);
	top_json(&model, now, 1234, f);
	fclose(f);
	return buf;
}

static int setup(void **state)
{
	(void)state;
	top_model_init(&model);
	return 0;
}

static void test_rate_jitter_stale(void **state)
{
	(void)state;
	for (int i = 0; i < 100; i++)
		feed_state("a", i * 0.01, 0, 0, i == 50 ? 900.0 : i == 60 ? 800.0 : 30.0 + (i % 10), 3);
	const struct top_robot *r = &model.robots[0];
	assert_true(fabs(top_robot_rate_hz(r) - 100.0) < 1e-9);
	/* p99 of 100 samples (nearest rank): the second largest */
	assert_true(top_robot_jitter_p99(r) == 800.0);
	assert_true(top_robot_jitter_max(r) == 900.0);
	assert_false(top_robot_stale(r, 1.5));
	assert_true(top_robot_stale(r, 2.1));
	assert_int_equal(model.nrobots, 1); /* stale robots are kept */
	assert_true(fabs(top_robot_rx_hz(r, 0.99) - 100.0) < 1.5);
}

static void test_order_and_phases(void **state)
{
	(void)state;
	feed_state("c", 0, 0.0, -2.0, 10, 3);
	feed_state("a", 0, 0.5, -1.5, 10, 3);
	feed_state("b", 0, 3.0, 1.0, 10, 3);
	assert_string_equal(model.robots[model.order[0]].name, "a");
	assert_string_equal(model.robots[model.order[2]].name, "c");
	assert_true(fabs(top_neighbour_dphase(&model, 0) - 2.5) < 1e-12);             /* b - a */
	assert_true(fabs(top_neighbour_dphase(&model, 1) - (0.0 - 3.0)) < 1e-12);      /* c - b */
	assert_true(isnan(top_neighbour_dphase(&model, 2)));
	assert_true(fabs(top_robot_dphase_joints(&model.robots[0]) + 2.0) < 1e-12);
	/* the simulator puts c leftmost: order follows lateral position */
	char ra[] = "a", rb[] = "b", rc[] = "c";
	undulate_sim_body_t bodies[3] = { { .robot = ra, .servo_id = 2, .neutral = 0.2 },
					  { .robot = rb, .servo_id = 1, .neutral = 0.3 },
					  { .robot = rc, .servo_id = 1, .neutral = 0.1 } };
	undulate_sim_truth_t t = { .nbodies = 3, .bodies = bodies, .total_collisions = 4, .total_impulse = 0.5 };
	top_on_truth(&model, &t, 0.5);
	assert_true(model.order_lateral);
	assert_string_equal(model.robots[model.order[0]].name, "c");
	assert_string_equal(model.robots[model.order[1]].name, "a");
	/* a's contact body is on its joint 1 (servo 2): a.j1 - c.j0 = -1.5 - 0 */
	assert_true(fabs(top_neighbour_dphase(&model, 0) + 1.5) < 1e-12);
	/* wrapped: b.j0 - a.j1 = 3.0 + 1.5 -> 4.5 - 2 pi */
	assert_true(fabs(top_neighbour_dphase(&model, 1) - (4.5 - 2 * M_PI)) < 1e-12);
}

static void test_collisions(void **state)
{
	(void)state;
	char l[] = "a", r[] = "b";
	undulate_sim_collision_t c = { .utime = 100, .left = 0, .right = 1, .left_robot = l, .right_robot = r,
				       .impulse = 0.25 };
	top_on_sim_collision(&model, &c, 1.0);
	/* the same collision again inside SIM.TRUTH, stamped with the truth's
	 * own time: counted once */
	undulate_sim_collision_t copy = c;
	copy.utime = 107;
	undulate_sim_truth_t t = { .ncollisions = 1, .collisions = &copy, .total_collisions = 1, .total_impulse = 0.25 };
	top_on_truth(&model, &t, 1.01);
	c.utime = 200;
	top_on_sim_collision(&model, &c, 5.0);
	double imp = 0;
	assert_int_equal(top_collisions_window(&model, 5.0, &imp), 2);
	assert_true(fabs(imp - 0.5) < 1e-12);
	assert_int_equal(top_collisions_window(&model, 12.0, &imp), 1); /* the first left the 10 s window */
	assert_true(model.collisions_heard == 2);
	assert_true(top_sim_present(&model, 6.0));
	assert_false(top_sim_present(&model, 9.0));
	/* without SIM.COLLISION (an older simulator), SIM.TRUTH's copies count */
	top_model_init(&model);
	top_on_truth(&model, &t, 1.0);
	assert_int_equal(top_collisions_window(&model, 1.0, NULL), 1);
}

static void test_keys(void **state)
{
	(void)state;
	struct top_keyparser kp = { 0 };
	int ch = 0;
	const unsigned char up[] = "\033[A", pgdn[] = "\033[6~", ss3down[] = "\033OB";
	enum top_key k = TOP_KEY_NONE;
	for (size_t i = 0; i < 3; i++)
		k = top_key_feed(&kp, up[i], &ch);
	assert_int_equal(k, TOP_KEY_UP);
	for (size_t i = 0; i < 4; i++)
		k = top_key_feed(&kp, pgdn[i], &ch);
	assert_int_equal(k, TOP_KEY_PGDN);
	for (size_t i = 0; i < 3; i++)
		k = top_key_feed(&kp, ss3down[i], &ch);
	assert_int_equal(k, TOP_KEY_DOWN);
	assert_int_equal(top_key_feed(&kp, 'q', &ch), TOP_KEY_CHAR);
	assert_int_equal(ch, 'q');
	/* an unknown sequence is swallowed, the next key is intact */
	const unsigned char junk[] = "\033[99Z";
	for (size_t i = 0; i < 5; i++)
		top_key_feed(&kp, junk[i], &ch);
	assert_int_equal(top_key_feed(&kp, 'o', &ch), TOP_KEY_CHAR);
	assert_int_equal(ch, 'o');
}

static void test_commands(void **state)
{
	(void)state;
	struct top_command c[TOP_MAX_JOINTS];
	assert_int_equal(top_command_mode(&c[0], "*", UNDULATE_ROBOT_STATE_T_MODE_HOLD, 42, "me"), 0);
	assert_string_equal(c[0].channel, "UNDULATE.CMD");
	assert_string_equal(c[0].msg.robot, "*");
	assert_int_equal(c[0].msg.kind, UNDULATE_COMMAND_T_KIND_MODE);
	assert_int_equal(c[0].msg.mode, 1);
	assert_true(c[0].msg.seq == 42);
	assert_int_equal(top_command_mode(&c[0], "r2", UNDULATE_ROBOT_STATE_T_MODE_SINUSOID, 43, "me"), 0);
	assert_string_equal(c[0].channel, "r2.CMD");
	assert_int_equal(top_command_mode(&c[0], "r2", 9, 44, "me"), -1);

	feed_state("r2", 0, 0, 0, 10, UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR);
	struct top_robot *r = &model.robots[0];
	char why[160];
	assert_int_equal(top_command_nudge(c, r, 1, 50, "me", why, sizeof(why)), -1);
	assert_non_null(strstr(why, "PARAMS"));
	char name[] = "r2";
	double k[2] = { 1, 1 }, cc[2] = { 0.02, 0.04 }, mu[2] = { 1, 1 }, z[2] = { 0, 0 };
	undulate_osc_params_t p = { .robot = name, .njoints = 2, .k = k, .c = cc, .mu = mu, .lambda = z, .inertia = z,
				    .friction = z, .neutral = z, .limit_min = z, .limit_max = z, .amplitude = 0.8 };
	top_on_params(&model, &p);
	assert_int_equal(top_command_nudge(c, r, 1, 50, "me", why, sizeof(why)), 2);
	assert_string_equal(c[1].channel, "r2.CMD");
	assert_string_equal(c[1].msg.param, "c");
	assert_int_equal(c[1].msg.joint, 1);
	assert_true(fabs(c[1].msg.value - 0.044) < 1e-12);
	assert_true(c[1].msg.seq == 51);
	assert_non_null(strstr(why, "0.04->0.044"));
	/* SINUSOID: the amplitude, bounded */
	feed_state("r2", 0.01, 0, 0, 10, UNDULATE_ROBOT_STATE_T_MODE_SINUSOID);
	assert_int_equal(top_command_nudge(c, r, -1, 60, "me", why, sizeof(why)), 1);
	assert_string_equal(c[0].msg.param, "amplitude");
	assert_true(fabs(c[0].msg.value - 0.75) < 1e-12);
	/* the daemon's range (common/params.h): 2.6 + 0.05 leaves 0..2.618 */
	r->sin_amplitude = 2.6;
	assert_int_equal(top_command_nudge(c, r, 1, 61, "me", why, sizeof(why)), -1);
	assert_non_null(strstr(why, "amplitude 2.650 rad out of range 0..2.618 rad: not sent"));
	r->sin_amplitude = 1.5;   /* the old limit of our own, which the daemon never had */
	assert_int_equal(top_command_nudge(c, r, 1, 61, "me", why, sizeof(why)), 1);
	assert_true(fabs(c[0].msg.value - 1.55) < 1e-12);
	r->sin_amplitude = 0.02;
	assert_int_equal(top_command_nudge(c, r, -1, 61, "me", why, sizeof(why)), -1);
	feed_state("r2", 0.02, 0, 0, 10, UNDULATE_ROBOT_STATE_T_MODE_LIMP);
	assert_int_equal(top_command_nudge(c, r, 1, 62, "me", why, sizeof(why)), -1);
}

static int max_line_width(const char *s)
{
	int w = 0, mx = 0;
	for (; *s; s++) {
		if (*s == '\n') {
			mx = w > mx ? w : mx;
			w = 0;
		} else if (*s == '\033') {
			while (*s && !((*s >= 'A' && *s <= 'Z') || (*s >= 'a' && *s <= 'z')))
				s++; /* skip the escape sequence */
		} else if (*s != '\r') {
			w++;
		}
	}
	return w > mx ? w : mx;
}

/* Twenty robots on 80x24: all visible (compact), no line wider than 80,
 * exactly 24 lines; the selection scrolls into view in the detail view. */
static void test_render_twenty(void **state)
{
	(void)state;
	for (int i = 0; i < 20; i++) {
		char name[16];
		snprintf(name, sizeof(name), "robot%02d", i + 1);
		feed_state(name, 0, 0.1 * i, 0.1 * i - 2, 10, 3);
	}
	struct top_view v = { 0 };
	top_render(&model, &v, 0.5, 24, 80, true, screen, sizeof(screen));
	assert_true(max_line_width(screen) <= 80);
	for (int i = 0; i < 20; i++) {
		char name[16];
		snprintf(name, sizeof(name), "robot%02d", i + 1);
		assert_non_null(strstr(screen, name));
	}
	int lines = 1;
	for (const char *p = screen; *p; p++)
		lines += *p == '\n';
	assert_int_equal(lines, 24);
	/* detail view: robot 20 selected must be on screen, robot 1 scrolled off */
	v.kind = TOP_VIEW_DETAIL;
	v.selected = 19;
	top_render(&model, &v, 0.5, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "robot20"));
	assert_null(strstr(screen, "robot01"));
	assert_true(max_line_width(screen) <= 80);
	/* stale robots are marked, not dropped */
	v.kind = TOP_VIEW_COMPACT;
	v.selected = 0;
	top_render(&model, &v, 5.0, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "(20 stale)"));
	assert_non_null(strstr(screen, "robot20"));
	/* --once text: every robot in detail, no escapes */
	top_render(&model, &v, 5.0, 0, 0, false, screen, sizeof(screen));
	assert_null(strchr(screen, '\033'));
	assert_non_null(strstr(screen, "STALE"));
	assert_non_null(strstr(screen, "robot01"));
	assert_non_null(strstr(screen, "robot20"));
}

static void test_json(void **state)
{
	(void)state;
	/* a name with a quote is no robot's (test_bad_names); text from the
	 * network is escaped (test_json_hostile_text) */
	feed_state("r\"1", 0, 0.25, -1.0, 10, 2);
	feed_state("r1", 0, 0.25, -1.0, 10, 2);
	feed_state("r2", 0, 0.75, -1.0, 10, 3);
	const char *buf = json_of(0.1);
	assert_null(strstr(buf, "\"name\":\"r\\\"1\""));
	assert_non_null(strstr(buf, "\"name\":\"r1\""));
	assert_non_null(strstr(buf, "\"mode\":\"SINUSOID\""));
	assert_non_null(strstr(buf, "\"dphase\":0.5"));
	assert_non_null(strstr(buf, "\"rate_hz\":100"));
	assert_non_null(strstr(buf, "\"stale\":false"));
	assert_non_null(strstr(buf, "\"sim\":{\"present\":false"));
	assert_int_equal(strchr(buf, '\n') - buf, (long)strlen(buf) - 1); /* one line */
}

/* Texts from the network reach JSON as valid JSON: a newline and a stray
 * byte in an event, and a reason cut by TOP_TEXT_MAX inside a UTF-8 character. */
static void test_json_hostile_text(void **state)
{
	(void)state;
	char n[] = "r1", reason[200];
	memset(reason, 'a', sizeof reason);
	memcpy(reason + TOP_TEXT_MAX - 3, "\xe2\x82\xac", 3);   /* U+20AC across the cut: 2 bytes kept */
	reason[sizeof reason - 1] = '\0';
	undulate_joint_state_t j[1] = { { .servo_id = 1, .angle = NAN, .speed = INFINITY } };
	undulate_robot_state_t s = { .utime = 1, .robot = n, .mode = 1, .mode_reason = reason, .fault = "",
		.period_us = 10000.0, .njoints = 1, .joints = j };
	top_on_state(&model, &s, 0.0);
	char kind[] = "fault", text[] = "line1\nline2 \xff end";
	undulate_event_t e = { .utime = 1, .robot = n, .seq = 1, .level = 1, .kind = kind, .text = text };
	top_on_event(&model, &e);
	const char *buf = json_of(0.1);
	assert_non_null(strstr(buf, "\"last_event\":\"fault: line1\\u000aline2 \\ufffd end\""));
	assert_non_null(strstr(buf, "aaa\\ufffd\\ufffd\",\"fault\":\"\",\"utime\""));
	assert_non_null(strstr(buf, "\"angle\":null,\"speed\":null"));
	assert_int_equal(strchr(buf, '\n') - buf, (long)strlen(buf) - 1); /* still one line */
}

/* A joint without a known phase (no frequency yet, a stale reading) publishes
 * NAN there (common/phase.h): both views show dashes, never "nan". */
static void test_unknown_phase(void **state)
{
	(void)state;
	char n[] = "r1", reason[] = "test";
	undulate_joint_state_t j[2] = {
		{ .servo_id = 1, .angle = 0.5, .phase = NAN, .amplitude = 0.0, .frequency = 0.0 },
		{ .servo_id = 2, .angle = NAN, .speed = NAN, .phase = NAN, .load = NAN, .amplitude = NAN,
		  .frequency = NAN },
	};
	undulate_robot_state_t s = { .utime = 1, .robot = n, .mode = 3, .mode_reason = reason, .fault = "",
		.period_us = 10000.0, .njoints = 2, .joints = j };
	top_on_state(&model, &s, 0.0);
	struct top_view v = { .kind = TOP_VIEW_DETAIL };
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_null(strstr(screen, "nan"));
	assert_non_null(strstr(screen, "+0.500"));
	v.kind = TOP_VIEW_COMPACT;
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_null(strstr(screen, "nan"));
	assert_non_null(strstr(screen, "+0.50"));
}

/* Torque actuation publishes no goal (NaN) but the drive sent: the goal
 * column shows the drive, marked d, and JSON carries both. */
static void test_drive_column(void **state)
{
	(void)state;
	char n[] = "rig", reason[] = "test";
	undulate_joint_state_t j[1] = {
		{ .servo_id = 1, .angle = 0.5, .goal = NAN, .drive = 0.124, .amplitude = 0.8, .frequency = 0.8 },
	};
	undulate_robot_state_t s = { .utime = 1, .robot = n, .mode = 3, .mode_reason = reason, .fault = "",
		.period_us = 10000.0, .njoints = 1, .joints = j };
	top_on_state(&model, &s, 0.0);
	struct top_view v = { .kind = TOP_VIEW_DETAIL };
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "d+0.124"));
	assert_null(strstr(screen, "nan"));
	assert_non_null(strstr(json_of(0.1), "\"goal\":null,\"drive\":0.124"));
}

/* A dead servo is shown as such: its frozen angle and speed are not shown as
 * live values; error bits are named; temperature and voltage are shown. */
static void test_joint_health(void **state)
{
	(void)state;
	char n[] = "r1", reason[] = "test";
	undulate_joint_state_t j[2] = {
		{ .servo_id = 1, .angle = 0.4321, .speed = 1.2345, .amplitude = 0.8, .frequency = 0.8,
		  .temperature = 41, .voltage = 11.8, .error_bits = 0x24, .torque = 1, .torque_read = 0 },
		{ .servo_id = 2, .angle = 0.6789, .speed = -2.3456, .amplitude = 0.8, .frequency = 0.8,
		  .temperature = 33, .voltage = 11.9, .stale_cycles = 37, .torque = 1, .torque_read = 7 },
	};
	undulate_robot_state_t s = { .utime = 1, .robot = n, .mode = 3, .mode_reason = reason, .fault = "",
		.period_us = 10000.0, .njoints = 2, .joints = j };
	top_on_state(&model, &s, 0.0);
	struct top_view v = { .kind = TOP_VIEW_DETAIL };
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "+0.432"));        /* joint 1 is live */
	assert_null(strstr(screen, "+0.679"));            /* joint 2 is frozen: not shown */
	assert_null(strstr(screen, "-2.346"));
	assert_non_null(strstr(screen, "SILENT x37"));
	assert_non_null(strstr(screen, "1 joint SILENT"));
	assert_true(isnan(top_robot_dphase_joints(&model.robots[0]))); /* j1's phase is frozen */
	assert_non_null(strstr(screen, " 41C 11.8V"));
	/* the status column ends the line: whole on a wider terminal */
	top_render(&model, &v, 0.1, 24, 100, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "41C 11.8V overheating|overload"));
	/* then the torque the servo reports, when it is not the one wanted */
	top_render(&model, &v, 0.1, 24, 130, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "41C 11.8V overheating|overload, torque off (wanted on)"));
	assert_null(strstr(screen, "SILENT x37, torque"));   /* joint 2: not read, nothing said */
	const char *js = json_of(0.1);
	assert_non_null(strstr(js, "\"status\":\"SILENT x37\""));
	assert_non_null(strstr(js, "\"temperature\":41"));
	/* torque as wanted and as read back (a servo that shut itself down reads 0);
	 * a value the servo cannot report is "not read" */
	assert_non_null(strstr(js, "\"torque\":true,\"torque_read\":0}"));
	assert_non_null(strstr(js, "\"torque\":true,\"torque_read\":-1}"));
	/* the text both monitors show */
	assert_string_equal(top_joint_torque(&model.robots[0].j[0]), "off (wanted on)");
	assert_string_equal(top_joint_torque(&model.robots[0].j[1]), "on (wanted; not read yet)");
	assert_true(top_joint_torque_differs(&model.robots[0].j[0]) && !top_joint_torque_differs(&model.robots[0].j[1]));
	/* compact view: an S marks the robot */
	v.kind = TOP_VIEW_COMPACT;
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, ">S 1 r1"));
}

/* An X servo's error_bits are its Hardware Error Status (ERROR_BITS_X set): bits 3
 * and 4 are the motor encoder and an electrical shock there, not the AX-12A's range
 * and checksum; the flag alone (no cause, no alert) is no error. */
static void test_x_error_bits(void **state)
{
	(void)state;
	char n[] = "x1", reason[] = "test";
	int16_t x = UNDULATE_JOINT_STATE_T_ERROR_BITS_X;
	undulate_joint_state_t j[2] = {
		{ .servo_id = 1, .amplitude = 0.8, .frequency = 0.8, .temperature = 41, .voltage = 11.8,
		  .error_bits = (int16_t)(x | 0x80 | 0x18) },
		{ .servo_id = 2, .amplitude = 0.8, .frequency = 0.8, .temperature = 33, .voltage = 11.9,
		  .error_bits = x },
	};
	undulate_robot_state_t s = { .utime = 1, .robot = n, .mode = 3, .mode_reason = reason, .fault = "",
		.period_us = 10000.0, .njoints = 2, .joints = j };
	top_on_state(&model, &s, 0.0);
	char buf[96];
	assert_string_equal(top_joint_status(&model.robots[0].j[0], buf, sizeof buf), "motor encoder|electrical shock");
	assert_string_equal(top_joint_status(&model.robots[0].j[1], buf, sizeof buf), "ok");
	assert_string_equal(top_errbits_format(0x18, buf, sizeof buf), "range|checksum");   /* the AX-12A's byte */
	assert_string_equal(top_errbits_format(x, buf, sizeof buf), "");
	struct top_view v = { .kind = TOP_VIEW_DETAIL };
	top_render(&model, &v, 0.1, 24, 120, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "motor encoder|electrical shock"));
	assert_null(strstr(screen, "checksum"));
	/* compact view: the joint with a cause marks the robot; without it, no mark */
	v.kind = TOP_VIEW_COMPACT;
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, ">! 1 x1"));
	j[0].error_bits = x;
	s.utime = 2;
	top_on_state(&model, &s, 0.05);
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, ">  1 x1"));
}

/* Nobody heard: the screen says which URL it listens on; ? shows the legend. */
/* A name that is not a robot's name never becomes a robot: '*' (whose card's
 * buttons would command every robot), control characters, spaces, '.', '/',
 * 48 characters. What a daemon may be called (common/text.h, text_is_name)
 * does. From every message that names a robot. */
static void test_bad_names(void **state)
{
	(void)state;
	char long_ok[TOP_NAME_MAX], too_long[TOP_NAME_MAX + 1];
	memset(long_ok, 'r', sizeof long_ok - 1);
	long_ok[sizeof long_ok - 1] = '\0';
	memset(too_long, 'r', sizeof too_long - 1);
	too_long[sizeof too_long - 1] = '\0';
	const char *bad[] = { "*", "", "a\x01" "b", "bell\a", "two words", "tab\tname", "a.b", "../x", "r1\n", "caf\xc3\xa9",
	                      "a*", too_long };
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		char n[TOP_NAME_MAX + 8], reason[] = "test", kind[] = "mode", text[] = "x";
		snprintf(n, sizeof n, "%s", bad[i]);
		undulate_joint_state_t j[1] = { { .servo_id = 1 } };
		undulate_robot_state_t s = { .utime = 1, .robot = n, .mode = 1, .mode_reason = reason, .fault = "",
			.period_us = 10000.0, .njoints = 1, .joints = j };
		top_on_state(&model, &s, 0.0);
		undulate_event_t e = { .utime = 1, .robot = n, .seq = 1, .level = 1, .kind = kind, .text = text };
		top_on_event(&model, &e);
		undulate_bus_stats_t b = { .utime = 1, .robot = n };
		top_on_bus(&model, &b);
		undulate_osc_params_t p = { .utime = 1, .robot = n };
		top_on_params(&model, &p);
		if (model.nrobots != 0)
			fail_msg("'%s' became a robot", bad[i]);
	}
	assert_int_equal(model.dropped_robots, 4 * (int)(sizeof bad / sizeof bad[0]));
	feed_state("r_1-X", 0.0, 0, 0, 0, 1);
	char n[TOP_NAME_MAX];
	snprintf(n, sizeof n, "%s", long_ok);
	undulate_joint_state_t j[1] = { { .servo_id = 1 } };
	char reason[] = "test";
	undulate_robot_state_t s = { .utime = 1, .robot = n, .mode = 1, .mode_reason = reason, .fault = "",
		.period_us = 10000.0, .njoints = 1, .joints = j };
	top_on_state(&model, &s, 0.0);
	assert_int_equal(model.nrobots, 2);
	assert_int_equal(top_robot_index(&model, long_ok), 1);
}

/* A plane SIM.TRUTH: robots named by bodies[], each link at x = robot index,
 * link k at y = k / 10; two walls; CONTACTS as given. */
static undulate_sim_truth_t plane_truth(undulate_sim_body_t *bodies, char (*names)[8], int nbodies,
                                        undulate_sim_link_t *links, undulate_sim_wall_t *walls,
                                        undulate_sim_contact_t *contacts, int ncontacts)
{
	for (int i = 0; i < nbodies; i++) {
		snprintf(names[i], sizeof names[i], "p%d", i);
		bodies[i] = (undulate_sim_body_t){ .robot = names[i], .servo_id = 1, .neutral = 0.2 * i };
		for (int k = 0; k < 3; k++)
			links[3 * i + k] = (undulate_sim_link_t){ .robot = (int16_t)i, .link = (int8_t)k, .x = i,
				.y = k / 10.0, .angle = M_PI / 2 + 4 * M_PI, .length = 0.1865, .width = 0.032 };
	}
	walls[0] = (undulate_sim_wall_t){ -1, -0.32, -1, 0.32 };
	walls[1] = (undulate_sim_wall_t){ 1, -0.32, 1, 0.32 };
	return (undulate_sim_truth_t){ .world = UNDULATE_SIM_TRUTH_T_WORLD_PLANE, .wall_left = -1, .wall_right = 1,
		.nbodies = nbodies, .bodies = bodies, .nlinks = 3 * nbodies, .links = links, .nwalls = 2,
		.walls = walls, .ncontacts = ncontacts, .contacts = contacts };
}

/* The plane's world as the last SIM.TRUTH drew it: each robot's links by
 * index, the walls, the contacts with their robots as the model's. */
static void test_world_plane(void **state)
{
	(void)state;
	feed_state("p2", 0, 0, 0, 10, 3);   /* p2 heard first: model index 0, body index 2 */
	undulate_sim_body_t bodies[3];
	char names[3][8];
	undulate_sim_link_t links[9];
	undulate_sim_wall_t walls[2];
	undulate_sim_contact_t contacts[2] = {
		{ .robot_a = 1, .link_a = 2, .robot_b = 2, .link_b = 0, .x = 0.5, .y = 0.1, .nx = 1, .ny = 0,
		  .impulse = 0.01, .normal_impulse = 0.01, .force = 1.0, .impact = 1 },
		{ .robot_a = 0, .link_a = 1, .robot_b = -1, .link_b = 1, .x = 0.9, .y = 0.2, .nx = NAN, .ny = 0,
		  .impulse = 0.002, .force = 0.2, .impact = 0 },
	};
	undulate_sim_truth_t t = plane_truth(bodies, names, 3, links, walls, contacts, 2);
	top_on_truth(&model, &t, 1.0);
	const struct top_world *w = &model.world;
	assert_int_equal(model.nrobots, 3);
	assert_int_equal(w->truths, 1);
	assert_true(w->plane);
	assert_int_equal(w->nwalls, 2);
	assert_true(w->walls[1].ax == 1 && w->walls[1].by == 0.32);
	assert_true(w->wall_left == -1 && w->wall_right == 1);
	const struct top_robot *p2 = &model.robots[top_robot_index(&model, "p2")];
	assert_true(p2->links[0].have && p2->links[2].have && !p2->links[3].have);
	assert_true(p2->links[1].x == 2 && p2->links[1].y == 0.1 && p2->links[1].length == 0.1865);
	/* the angle wrapped: 4 pi + pi/2 -> pi/2 */
	assert_true(fabs(p2->links[0].angle - M_PI / 2) < 1e-12);
	assert_int_equal(w->ncontacts, 2);
	assert_string_equal(model.robots[w->contacts[0].a].name, "p1");
	assert_string_equal(model.robots[w->contacts[0].b].name, "p2");
	assert_true(w->contacts[0].impact && w->contacts[0].force == 1.0 && w->contacts[0].link_a == 2);
	assert_int_equal(w->contacts[1].b, -1);           /* a wall, its index in walls[] */
	assert_int_equal(w->contacts[1].link_b, 1);
	assert_true(w->contacts[1].nx == 0 && !w->contacts[1].impact);   /* a normal that is not finite: none */
	assert_int_equal(w->bad_index + w->bad_number + w->overflow, 0);
	/* the next message replaces the world: no links, the row's walls absent */
	undulate_sim_truth_t row = { .nbodies = 3, .bodies = bodies, .wall_left = 0.5, .wall_right = 0.5 };
	top_on_truth(&model, &row, 1.01);
	assert_false(w->plane);
	assert_false(p2->links[0].have);
	assert_int_equal(w->nwalls + w->ncontacts, 0);
	assert_true(isnan(w->wall_left) && isnan(w->wall_right));
	assert_int_equal(w->bad_index + w->bad_number + w->overflow, 0);
}

/* Links, walls and contacts from the network that name what the message does
 * not hold, or carry numbers no arena has, are refused and counted, never kept
 * and never indexed with. */
static void test_world_hostile(void **state)
{
	(void)state;
	undulate_sim_body_t bodies[3];
	char names[3][8];
	undulate_sim_link_t links[9];
	undulate_sim_wall_t walls[2];
	undulate_sim_truth_t t = plane_truth(bodies, names, 3, links, walls, NULL, 0);
	/* body 1 is no robot's name: its links and contacts have no robot */
	snprintf(names[1], sizeof names[1], "*");
	/* indices: a robot beyond bodies[], negative, a link beyond a robot's */
	links[0].robot = 3;
	links[1].robot = -1;
	links[2].link = TOP_MAX_LINKS;
	links[6].link = -1;
	/* numbers: NaN, inf, beyond the extent, a zero and a huge size */
	links[7].x = NAN;
	links[8].angle = INFINITY;
	undulate_sim_link_t more[6] = {
		{ .robot = 2, .link = 0, .x = 1e9, .y = 0, .length = 0.1, .width = 0.01 },
		{ .robot = 2, .link = 0, .x = 0, .y = -INFINITY, .length = 0.1, .width = 0.01 },
		{ .robot = 2, .link = 0, .x = 0, .y = 0, .length = 0, .width = 0.01 },
		{ .robot = 2, .link = 0, .x = 0, .y = 0, .length = 0.1, .width = 1e30 },
		{ .robot = 2, .link = 0, .x = 0, .y = 0, .length = NAN, .width = 0.01 },
		{ .robot = 2, .link = 1, .x = 0.5, .y = 0.25, .angle = 1e300, .length = 0.1, .width = 0.01 },
	};
	undulate_sim_link_t all[15];
	memcpy(all, links, sizeof links);
	memcpy(all + 9, more, sizeof more);
	t.nlinks = 15;
	t.links = all;
	undulate_sim_wall_t wall_bad[TOP_WORLD_WALLS + 3];
	for (int i = 0; i < TOP_WORLD_WALLS + 3; i++)
		wall_bad[i] = (undulate_sim_wall_t){ 0, 0, 1, 1 };
	wall_bad[0].ax = NAN;
	wall_bad[1].by = -1e6;
	t.walls = wall_bad;
	t.nwalls = TOP_WORLD_WALLS + 3;   /* one beyond what is kept, after the two refused */
	t.wall_left = NAN;
	undulate_sim_contact_t c[] = {
		{ .robot_a = 3, .robot_b = 0, .x = 0, .y = 0 },            /* a beyond bodies[] */
		{ .robot_a = 0, .robot_b = 7, .x = 0, .y = 0 },            /* b beyond */
		{ .robot_a = 0, .robot_b = 1, .x = 0, .y = 0 },            /* b: no robot's name */
		{ .robot_a = -1, .robot_b = 0, .x = 0, .y = 0 },           /* a wall as a */
		{ .robot_a = 0, .link_a = 9, .robot_b = 2, .x = 0, .y = 0 },
		{ .robot_a = 0, .robot_b = 2, .link_b = -1, .x = 0, .y = 0 },
		{ .robot_a = 0, .robot_b = -1, .link_b = TOP_WORLD_WALLS + 3, .x = 0, .y = 0 }, /* a wall beyond walls[] */
		{ .robot_a = 0, .robot_b = 2, .x = NAN, .y = 0 },
		{ .robot_a = 0, .robot_b = 2, .x = 0, .y = 1e200 },
		{ .robot_a = 0, .robot_b = 2, .x = 0, .y = 0, .force = -1 },
		{ .robot_a = 0, .robot_b = 2, .x = 0, .y = 0, .impulse = INFINITY },
		{ .robot_a = 0, .robot_b = 2, .x = 0.1, .y = 0.2, .force = 2, .impulse = 0.02 },  /* the good one */
	};
	t.contacts = c;
	t.ncontacts = (int32_t)(sizeof c / sizeof c[0]);
	top_on_truth(&model, &t, 1.0);
	const struct top_world *w = &model.world;
	assert_int_equal(model.nrobots, 2);                     /* "*" made none */
	const struct top_robot *p0 = &model.robots[top_robot_index(&model, "p0")];
	const struct top_robot *p2 = &model.robots[top_robot_index(&model, "p2")];
	for (int k = 0; k < TOP_MAX_LINKS; k++)
		assert_false(p0->links[k].have);                  /* 0: robot 3, 1: robot -1, 2: link 5 */
	assert_false(p2->links[0].have);                      /* link -1; 7 NaN; every "more" one refused */
	assert_false(p2->links[2].have);                      /* angle inf */
	assert_true(p2->links[1].have && fabs(p2->links[1].angle) <= M_PI);   /* 1e300 wrapped */
	assert_int_equal(w->bad_index, 3 + 4 + 7);            /* p1's three links; links 0, 1, 2, 6; seven contacts */
	assert_int_equal(w->bad_number, 2 + 5 + 2 + 1 + 4);   /* links 7, 8; five "more"; two walls; wall_left; four contacts */
	assert_int_equal(w->nwalls, TOP_WORLD_WALLS);
	assert_int_equal(w->overflow, 1);
	assert_true(isnan(w->wall_left));
	assert_int_equal(w->ncontacts, 1);
	assert_int_equal(w->contacts[0].a, top_robot_index(&model, "p0"));
	/* more contacts than kept: the rest counted; a negative count is none */
	static undulate_sim_contact_t many[TOP_WORLD_CONTACTS + 5];
	for (int i = 0; i < TOP_WORLD_CONTACTS + 5; i++)
		many[i] = (undulate_sim_contact_t){ .robot_a = 0, .robot_b = 2, .force = 1, .impulse = 0.01 };
	undulate_sim_truth_t t2 = { .world = 7, .nbodies = 3, .bodies = bodies, .ncontacts = TOP_WORLD_CONTACTS + 5,
		.contacts = many, .nlinks = -4, .links = NULL, .nwalls = -1, .walls = NULL };
	int64_t over = w->overflow;
	top_on_truth(&model, &t2, 1.01);
	assert_int_equal(w->ncontacts, TOP_WORLD_CONTACTS);
	assert_int_equal(w->overflow - over, 5);
	assert_false(w->plane);                               /* an unknown kind: drawn as the row */
	/* more bodies than mapped: a link naming one beyond is refused, not read past the map */
	static undulate_sim_body_t crowd[TOP_WORLD_BODIES + 2];
	for (int i = 0; i < TOP_WORLD_BODIES + 2; i++)
		crowd[i] = bodies[2];
	undulate_sim_link_t far = { .robot = TOP_WORLD_BODIES + 1, .link = 0, .x = 0, .y = 0, .length = 0.1, .width = 0.01 };
	undulate_sim_truth_t t3 = { .nbodies = TOP_WORLD_BODIES + 2, .bodies = crowd, .nlinks = 1, .links = &far };
	int64_t bad = w->bad_index;
	top_on_truth(&model, &t3, 1.02);
	assert_int_equal(w->bad_index - bad, 1);
}

static void test_empty_and_help(void **state)
{
	(void)state;
	struct top_view v = { .kind = TOP_VIEW_AUTO, .url = "udpm://239.255.76.67:7667?ttl=0" };
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "no robot heard yet on udpm://239.255.76.67:7667?ttl=0"));
	v.help = true;
	top_render(&model, &v, 0.1, 24, 80, true, screen, sizeof(screen));
	assert_non_null(strstr(screen, "jit99   99th percentile"));
	assert_non_null(strstr(screen, "m then l/h/s/o"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup(test_joint_health, setup),
		cmocka_unit_test_setup(test_x_error_bits, setup),
		cmocka_unit_test_setup(test_empty_and_help, setup),
		cmocka_unit_test_setup(test_bad_names, setup),
		cmocka_unit_test_setup(test_rate_jitter_stale, setup),
		cmocka_unit_test_setup(test_drive_column, setup),
		cmocka_unit_test_setup(test_unknown_phase, setup),
		cmocka_unit_test_setup(test_order_and_phases, setup),
		cmocka_unit_test_setup(test_collisions, setup),
		cmocka_unit_test_setup(test_keys, setup),
		cmocka_unit_test_setup(test_commands, setup),
		cmocka_unit_test_setup(test_render_twenty, setup),
		cmocka_unit_test_setup(test_json, setup),
		cmocka_unit_test_setup(test_json_hostile_text, setup),
		cmocka_unit_test_setup(test_world_plane, setup),
		cmocka_unit_test_setup(test_world_hostile, setup),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
