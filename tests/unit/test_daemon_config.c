/* test_daemon_config.c — the robot configuration: a good file, every kind of
 * error with file:line and key, command-line overrides, defaults. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../daemon/config.h"
#include "text.h"

/* cmocka 1.1.5 has no assert_double_equal */
#define assert_double_equal(a, b, eps)                                                    \
	do {                                                                              \
		double a_ = (a), b_ = (b);                                                \
		if (!(fabs(a_ - b_) <= (eps)))                                            \
			fail_msg("%s = %.9g, expected %.9g", #a, a_, b_);                  \
	} while (0)

static const char good[] =
	"; robot one\n"
	"[robot]\n"
	"name = robot1\n"
	"port = /dev/ttyUSB0\n"
	"baud = 1000000\n"
	"ids = 3, 4\n"
	"mode = sinusoid\n"
	"lcm_url = udpm://239.255.76.67:7667?ttl=0\n"
	"priority = 50\n"
	"mlockall = on\n"
	"safe_stop = limp\n"
	"velocity_source = servo\n"
	"commands = off\n"
	"echo = no\n"
	"adapter_latency_us = 1000\n"
	"\n"
	"[joint.1]\n"
	"k = 0.06\n"
	"lambda = 1.5\n"
	"neutral = 0.1\n"
	"limit_min = -1.0\n"
	"limit_max = 1.2\n"
	"max_step = 0.05\n"
	"[joint.2]\n"
	"mu = 0.2   ; inline comment\n"
	"[sinusoid]\n"
	"amplitude = 0.7\n"
	"frequency = 0.9\n"
	"phase = 1.0\n";

static void load_ok(struct cfg *c, const char *text)
{
	struct cfg_errors e = { 0 };
	cfg_defaults(c);
	bool ok = cfg_load_string(c, "robot1.conf", text, &e) && cfg_finish(c, &e);
	if (!ok)
		fail_msg("unexpected error: %s", e.line[0]);
}

/* Loads text, expects exactly one error, returns it. */
static const char *load_error(const char *text, char *buf, size_t cap)
{
	static struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	if (cfg_load_string(&c, "robot1.conf", text, &e))
		cfg_finish(&c, &e);
	assert_int_equal(e.count, 1);
	snprintf(buf, cap, "%s", e.line[0]);
	return buf;
}

/* What --check-config -v prints for c (cfg_print), to search; the caller frees it. */
static char *printed(const struct cfg *c)
{
	char *text = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&text, &len);
	assert_non_null(f);
	cfg_print(c, f);
	fclose(f);
	assert_non_null(text);
	return text;
}

static void test_good_file(void **state)
{
	(void)state;
	struct cfg c;
	load_ok(&c, good);
	assert_string_equal(c.name, "robot1");
	assert_string_equal(c.port, "/dev/ttyUSB0");
	assert_int_equal(c.baud, 1000000);
	assert_int_equal(c.njoints, 2);
	assert_int_equal(c.ids[0], 3);
	assert_int_equal(c.ids[1], 4);
	assert_int_equal(c.mode, CFG_MODE_SINUSOID);
	assert_string_equal(c.lcm_url, "udpm://239.255.76.67:7667?ttl=0");
	assert_int_equal(c.priority, 50);
	assert_true(c.mlockall);
	assert_int_equal(c.safe_stop, CFG_SAFE_LIMP);
	assert_int_equal(c.velocity_source, CFG_VEL_SERVO);
	assert_int_equal(c.commands, CFG_CMD_OFF);
	assert_false(c.echo);
	assert_int_equal(c.adapter_latency_us, 1000);
	assert_double_equal(c.joint[0].osc.k, 0.06, 1e-12);
	assert_double_equal(c.joint[0].neutral, 0.1, 1e-12);
	assert_double_equal(c.joint[0].limit_min, -1.0, 1e-12);
	assert_double_equal(c.joint[0].max_step, 0.05, 1e-12);
	assert_double_equal(c.joint[1].osc.mu, 0.2, 1e-12);
	assert_double_equal(c.amplitude, 0.7, 1e-12);
	assert_double_equal(c.frequency, 0.9, 1e-12);
	assert_double_equal(c.phase, 1.0, 1e-12);
}

static void test_defaults_from_osc(void **state)
{
	(void)state;
	struct cfg c;
	load_ok(&c, "[robot]\nport=/dev/null\nids=1,2\n[joint.1]\nk=0.07\n");
	struct osc_joint_params d0, d1;
	osc_default_params(&d0, 0, 2);
	osc_default_params(&d1, 1, 2);
	assert_double_equal(c.joint[0].osc.k, 0.07, 1e-12);       /* explicit wins */
	assert_double_equal(c.joint[0].osc.c, d0.c, 1e-12);       /* the rest: oscillator defaults */
	assert_double_equal(c.joint[0].osc.lambda, d0.lambda, 1e-12);
	assert_double_equal(c.joint[1].osc.lambda, d1.lambda, 1e-12);
	assert_double_equal(c.joint[1].osc.mu, d1.mu, 1e-12);
	assert_int_equal(c.mode, CFG_MODE_HOLD);                  /* no mode given: hold */
	assert_int_equal(c.safe_stop, CFG_SAFE_HOLD);
	assert_int_equal(c.commands, CFG_CMD_LOCAL);
	assert_true(c.joint[0].limit_min < 0 && c.joint[0].limit_max > 0);
	assert_true(c.joint[0].max_step > 0);
	assert_string_equal(c.name, "robot");
	assert_int_equal(c.actuation, CFG_ACT_POSITION);
	/* torque actuation takes the physical defaults, wherever the key comes */
	load_ok(&c, "[joint.1]\nmu=0.05\n[robot]\nport=/dev/null\nids=1\nactuation = torque\n"
	        "torque_drive = current\n");
	struct osc_joint_params t0;
	osc_default_torque_params(&t0, 0, 1, false);
	struct osc_joint_params tp;
	osc_default_torque_params(&tp, 0, 1, true);
	assert_true(tp.k > t0.k);   /* the PWM drive's softer loop needs a stiffer spring */
	assert_int_equal(c.actuation, CFG_ACT_TORQUE);
	assert_int_equal(c.torque_drive, CFG_DRIVE_CURRENT);
	assert_double_equal(c.joint[0].osc.k, t0.k, 1e-12);
	assert_double_equal(c.joint[0].osc.inertia, t0.inertia, 1e-12);
	assert_double_equal(c.joint[0].osc.mu, 0.05, 1e-12);
	assert_double_equal(c.stall_torque, 1.5, 1e-12);
}

static void test_errors_name_file_line_key(void **state)
{
	(void)state;
	char b[CFG_ERR_MAX];
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n\n[joint.1]\nk = abc\n", b, sizeof b),
	                    "robot1.conf:6: [joint.1] k: not a number 'abc'");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nbuad = 9600\n", b, sizeof b),
	                    "robot1.conf:4: [robot] buad: unknown key");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\nkk = 1\n", b, sizeof b),
	                    "robot1.conf:5: [joint.1] kk: unknown key");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[jiont.1]\nk = 1\n", b, sizeof b),
	                    "robot1.conf:5: [jiont.1]: unknown section (robot, joint.N, sinusoid)");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[joint.25]\nk = 1\n", b, sizeof b),
	                    "robot1.conf:5: [joint.25]: joint sections are [joint.1] .. [joint.24]");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nmode = walk\n", b, sizeof b),
	                    "robot1.conf:4: [robot] mode: 'walk' is not limp, hold, sinusoid or oscillator");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,1\n", b, sizeof b),
	                    "robot1.conf:3: [robot] ids: servo ID 1 listed twice");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,300\n", b, sizeof b),
	                    "robot1.conf:3: [robot] ids: servo ID 300 out of range 0..253");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nbaud=fast\n", b, sizeof b),
	                    "robot1.conf:4: [robot] baud: not an integer 'fast'");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\npriority=120\n", b, sizeof b),
	                    "robot1.conf:4: [robot] priority: 120 out of range 0..99");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nmlockall=maybe\n", b, sizeof b),
	                    "robot1.conf:4: [robot] mlockall: not on/off 'maybe'");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nsafe_stop=drop\n", b, sizeof b),
	                    "robot1.conf:4: [robot] safe_stop: 'drop' is not hold or limp");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nvelocity_source=gps\n", b, sizeof b),
	                    "robot1.conf:4: [robot] velocity_source: 'gps' is not servo or filtered");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nactuation=force\n", b, sizeof b),
	                    "robot1.conf:4: [robot] actuation: 'force' is not position or torque");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\ntorque_drive=hydraulic\n", b, sizeof b),
	                    "robot1.conf:4: [robot] torque_drive: 'hydraulic' is not pwm or current");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nstall_torque=0\n", b, sizeof b),
	                    "robot1.conf:4: [robot] stall_torque: 0 out of range 0.01..100");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nname=a.b\n", b, sizeof b),
	                    "robot1.conf:4: [robot] name: 'a.b' must be letters, digits, '_' or '-' "
	                    "(it prefixes LCM channels)");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\nk = 0\n", b, sizeof b),
	                    "robot1.conf:5: [joint.1] k: 0 out of range 0.0001..10");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\ninertia = 1e-300\n", b, sizeof b),
	                    "robot1.conf:5: [joint.1] inertia: 1e-300 out of range 1e-05..1");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\ncommands=maybe\n", b, sizeof b),
	                    "robot1.conf:4: [robot] commands: 'maybe' is not off, local or network");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\nmax_step = nan\n", b, sizeof b),
	                    "robot1.conf:5: [joint.1] max_step: not a number 'nan'");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[sinusoid]\nfrequency = 9\n", b, sizeof b),
	                    "robot1.conf:5: [sinusoid] frequency: 9 out of range 0..5");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[sinusoid]\nperiod = 1\n", b, sizeof b),
	                    "robot1.conf:5: [sinusoid] period: unknown key (amplitude, frequency, phase, stiffness, damping)");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[sinusoid]\nstiffness = 11\n", b, sizeof b),
	                    "robot1.conf:5: [sinusoid] stiffness: 11 out of range 0..10");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[sinusoid]\ndamping = -0.1\n", b, sizeof b),
	                    "robot1.conf:5: [sinusoid] damping: -0.1 out of range 0..1");
	assert_string_equal(load_error("k = 1\n[robot]\nport=/dev/null\nids=1\n", b, sizeof b),
	                    "robot1.conf:1: k: key outside any section (start with [robot])");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nthis line has no equals\n", b, sizeof b),
	                    "robot1.conf:4: syntax error (expected [section] or key = value)");
}

static void test_whole_config_errors(void **state)
{
	(void)state;
	char b[CFG_ERR_MAX];
	assert_non_null(strstr(load_error("[robot]\nport=/dev/null\n", b, sizeof b), "ids: no servo IDs"));
	assert_non_null(strstr(load_error("[robot]\nids=1\n", b, sizeof b), "port: no port configured"));
	/* torque actuation reads the speed in wheel mode, where the servo's
	 * present speed is its output: the servo as the speed source is refused,
	 * whichever key comes first */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nvelocity_source=servo\nactuation=torque\n", b,
	                               sizeof b),
	                    "command line: [robot] velocity_source = servo cannot be used with actuation = torque: in "
	                    "wheel mode the AX-12's present speed is its output, not a speed; use "
	                    "velocity_source = filtered");
	assert_non_null(strstr(load_error("[robot]\nport=/dev/null\nids=1\nactuation=torque\nvelocity_source=servo\n",
	                                  b, sizeof b),
	                       "velocity_source = servo cannot be used with actuation = torque"));
	/* the clock as a torque law needs the servos' torque drive */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[sinusoid]\nstiffness=0.135\n", b, sizeof b),
	                    "command line: [sinusoid] stiffness 0.135 drives the clock as a torque: it needs [robot] "
	                    "actuation = torque (with position actuation SINUSOID follows the clock with the servo's "
	                    "position loop)");
	assert_non_null(strstr(load_error("[robot]\nport=/dev/null\nids=1\n[joint.2]\nk=1\n", b, sizeof b),
	                       "[joint.2]: the robot has only 1 joint(s)"));
	assert_non_null(strstr(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\nlimit_min=0.5\n"
	                                  "limit_max=0.2\n", b, sizeof b), "limit_min: 0.5 is not below limit_max"));
	assert_non_null(strstr(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\nneutral=2\nlimit_max=1\n",
	                                  b, sizeof b), "leaves the servo's"));
}

/* [sinusoid] stiffness and damping: the clock as a torque law (CONTROL.md,
 * "The clock as a torque law"), off (0) unless given, printed back. */
/* indirect: on by default (the X cycle reads the indirect block), off by
 * the key, anything else refused with the key named. */
static void test_indirect_key(void **state)
{
	(void)state;
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_load_string(&c, "r.conf", "[robot]\nport=/dev/null\nids=1,2\n", &e) && cfg_finish(&c, &e));
	assert_true(c.indirect);
	cfg_defaults(&c);
	assert_true(cfg_load_string(&c, "r.conf", "[robot]\nport=/dev/null\nids=1,2\nindirect = off\n", &e) &&
	            cfg_finish(&c, &e));
	assert_false(c.indirect);
	cfg_defaults(&c);
	struct cfg_errors e2 = { 0 };
	assert_false(cfg_load_string(&c, "r.conf", "[robot]\nport=/dev/null\nids=1,2\nindirect = maybe\n", &e2));
}

static void test_sinusoid_stiffness(void **state)
{
	(void)state;
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_load_string(&c, "r.conf", "[robot]\nport=/dev/null\nids=1,2\n", &e) && cfg_finish(&c, &e));
	assert_true(c.sin_stiffness == 0.0 && c.sin_damping == 0.0);
	/* and the coupling's phase 0: the paper's law */
	assert_true(c.joint[0].osc.coupling_phase == 0.0 && c.joint[1].osc.coupling_phase == 0.0);
	cfg_defaults(&c);
	e.count = 0;
	assert_true(cfg_load_string(&c, "r.conf", "[robot]\nport=/dev/null\nids=1,2\n[joint.1]\ncoupling_phase = 0.6\n"
	                            "[joint.2]\ncoupling_phase = -0.6\n", &e) && cfg_finish(&c, &e));
	assert_true(c.joint[0].osc.coupling_phase == 0.6 && c.joint[1].osc.coupling_phase == -0.6);
	assert_false(cfg_load_string(&c, "r.conf", "[joint.1]\ncoupling_phase = 4\n", &e));
	assert_non_null(strstr(e.line[e.count - 1], "[joint.1] coupling_phase: 4 out of range -3.142..3.142"));
	e.count = 0;
	cfg_defaults(&c);
	assert_true(cfg_load_string(&c, "r.conf", "[sinusoid]\nstiffness = 0.135\ndamping = 0.01\n[robot]\n"
	                            "port=/dev/null\nids=1,2\nactuation = torque\n", &e));
	assert_true(cfg_finish(&c, &e));
	assert_int_equal(e.count, 0);
	assert_true(c.sin_stiffness == 0.135 && c.sin_damping == 0.01);
	assert_true(cfg_param_is_robot("stiffness") && cfg_param_commandable("damping"));
	assert_ptr_equal(cfg_robot_param(&c, "stiffness"), &c.sin_stiffness);
	char why[200];
	assert_true(cfg_robot_param_check(&c, "stiffness", 0.5, why, sizeof why));
	c.actuation = CFG_ACT_POSITION;
	assert_false(cfg_robot_param_check(&c, "stiffness", 0.5, why, sizeof why));
	assert_true(cfg_robot_param_check(&c, "stiffness", 0.0, why, sizeof why));
	c.actuation = CFG_ACT_TORQUE;
	char *text = printed(&c);
	assert_non_null(strstr(text, "\n[sinusoid]\namplitude = 0.8\nfrequency = 0.8\nphase = 0\nstiffness = 0.135\n"
	                             "damping = 0.01\n"));
	free(text);
}

static void test_every_error_reported(void **state)
{
	(void)state;
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_false(cfg_load_string(&c, "r.conf", "[robot]\nbaud=x\nids=1\n[joint.1]\nk=y\nc=z\n", &e));
	assert_int_equal(e.count, 3);
	assert_string_equal(e.line[0], "r.conf:2: [robot] baud: not an integer 'x'");
	assert_string_equal(e.line[1], "r.conf:5: [joint.1] k: not a number 'y'");
	assert_string_equal(e.line[2], "r.conf:6: [joint.1] c: not a number 'z'");
}

/* A key or a section given twice is an error naming both lines: with the
 * parser's own rule the second silently won (a second limit_max widened
 * the joint). --set is meant to override, and still does. */
static void test_repeated_keys_and_sections(void **state)
{
	(void)state;
	char b[CFG_ERR_MAX];
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\nlimit_max = 0.5\nk = 0.1\n"
	                               "limit_max = 1.2\n", b, sizeof b),
	                    "robot1.conf:7: [joint.1] limit_max: given twice (first at line 5): give each key once");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,2\n[joint.1]\nk = 0.1\n[joint.2]\nk = 0.1\n"
	                               "[joint.1]\nmu = 0.1\n", b, sizeof b),
	                    "robot1.conf:8: [joint.1]: section given twice (first at line 4): give each section once");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[robot]\nmode=hold\n", b, sizeof b),
	                    "robot1.conf:4: [robot]: section given twice (first at line 1): give each section once");
	/* both, when the repeated section repeats a key */
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_false(cfg_load_string(&c, "r.conf", "[robot]\nport=/dev/null\nids=1\n[joint.1]\nlimit_max=0.5\n"
	                             "[sinusoid]\nphase=1\n[joint.1]\nlimit_max=1.2\n", &e));
	assert_int_equal(e.count, 2);
	assert_string_equal(e.line[0], "r.conf:8: [joint.1]: section given twice (first at line 4): give each section "
	                               "once");
	assert_string_equal(e.line[1], "r.conf:9: [joint.1] limit_max: given twice (first at line 5): give each key "
	                               "once");
	/* an indented line continues the value above it (the parser's multi-line
	 * values): it was a second value for the key, now an error */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\nk = 0.1\n  0.5\n", b, sizeof b),
	                    "robot1.conf:6: [joint.1] k: an indented line continues the value of line 5: a value is "
	                    "one line (remove the indentation)");
	/* so is an indented key after a key (the parser's rule, not ours) */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\n[joint.1]\nk = 0.1\n\n  mu = 0.2\n", b, sizeof b),
	                    "robot1.conf:7: [joint.1] k: an indented line continues the value of line 5: a value is "
	                    "one line (remove the indentation)");
	/* the same key in two sections is two keys; an indented key opening a
	 * section is a key; comments and blank lines between are nothing */
	static struct cfg ok;
	load_ok(&ok, "[robot]\nport=/dev/null\nids=1,2\n[joint.1]\n  k = 0.1\n  ; a comment\n\nmu = 0.2\n"
	             "[joint.2]\nk = 0.3\n");
	assert_double_equal(ok.joint[0].osc.k, 0.1, 1e-12);
	assert_double_equal(ok.joint[0].osc.mu, 0.2, 1e-12);
	assert_double_equal(ok.joint[1].osc.k, 0.3, 1e-12);
	/* --set overrides the file's key, and a second --set the first */
	e = (struct cfg_errors){ 0 };
	cfg_defaults(&c);
	assert_true(cfg_load_string(&c, "r.conf", "[robot]\nport=/dev/null\nids=1\n[joint.1]\nlimit_max = 0.5\n", &e));
	assert_true(cfg_override(&c, "joint.1.limit_max=0.7", &e));
	assert_true(cfg_override(&c, "joint.1.limit_max=0.9", &e));
	assert_true(cfg_finish(&c, &e));
	assert_double_equal(c.joint[0].limit_max, 0.9, 1e-12);
}

/* A line longer than the INI parser's buffer is named as such, and the lines
 * after it keep their own numbers (the parser reads a long line in pieces). */
static void test_long_line(void **state)
{
	(void)state;
	static char text[4096];
	char pad[700];
	memset(pad, 'x', sizeof pad - 1);
	pad[sizeof pad - 1] = '\0';
	snprintf(text, sizeof text, "[robot]\nname = r ; %s\nids = 1\nbaud = x\n", pad);
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_false(cfg_load_string(&c, "r.conf", text, &e));
	assert_int_equal(e.count, 2);
	assert_string_equal(e.line[0], "r.conf:4: [robot] baud: not an integer 'x'");
	assert_non_null(strstr(e.line[1], "r.conf:2: line too long"));
}

/* README: "A line may hold at most 199 characters". A line of exactly 199
 * filled the parser's buffer and was reported too long, whether a newline
 * or the end of the text followed it; 200 is too long. */
static void test_line_of_199_characters(void **state)
{
	(void)state;
	static char text[1024];
	char line[201];
	memset(line, 'x', sizeof line);
	memcpy(line, "name = r ; ", 11);
	struct cfg c;
	struct cfg_errors e = { 0 };
	line[199] = '\0';
	snprintf(text, sizeof text, "[robot]\nport = /dev/null\n%s\nids = 1\nbaud = x\n", line);
	cfg_defaults(&c);
	assert_false(cfg_load_string(&c, "r.conf", text, &e));
	assert_int_equal(e.count, 1);
	assert_string_equal(e.line[0], "r.conf:5: [robot] baud: not an integer 'x'");
	assert_string_equal(c.name, "r");
	/* at the end of the text, without a newline */
	snprintf(text, sizeof text, "[robot]\nport = /dev/null\nids = 1\n%s", line);
	e.count = 0;
	cfg_defaults(&c);
	if (!cfg_load_string(&c, "r.conf", text, &e))
		fail_msg("unexpected error: %s", e.line[0]);
	/* one more is too long, and the line after it keeps its number */
	line[199] = 'x';
	line[200] = '\0';
	snprintf(text, sizeof text, "[robot]\nport = /dev/null\n%s\nids = 1\nbaud = x\n", line);
	e.count = 0;
	cfg_defaults(&c);
	assert_false(cfg_load_string(&c, "r.conf", text, &e));
	assert_int_equal(e.count, 2);
	assert_string_equal(e.line[0], "r.conf:5: [robot] baud: not an integer 'x'");
	assert_string_equal(e.line[1], "r.conf:3: line too long (the parser reads at most 199 characters of a line)");
}

/* README: a robot name is letters, digits, '_' and '-' (it prefixes LCM
 * channels; the monitors make robots only of such names). A vertical tab or
 * form feed inside a line, or a CR or newline from the command line (--robot),
 * was accepted once; '/', control characters and non-ASCII were accepted until
 * the monitors' rule (text_is_name) became the daemon's. */
static void test_name_without_spaces(void **state)
{
	(void)state;
	static const char *const bad[] = { "a b", "a\tb", "a\vb", "a\fb", "a\rb", "a\nb", "a.b", "a*", "",
		                           "a/b", "a\x01b", "r\xc3\xa9", "a:b",
		                           "abcdefghijabcdefghijabcdefghijabcdefghijabcdefgh" /* 48 */ };
	struct cfg c;
	char assignment[80], want[CFG_ERR_MAX], shown[64];
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		struct cfg_errors e = { 0 };
		cfg_defaults(&c);
		snprintf(assignment, sizeof assignment, "robot.name=%s", bad[i]);
		assert_false(cfg_override(&c, assignment, &e));
		if (strlen(bad[i]) < CFG_NAME_MAX) {
			snprintf(want, sizeof want, "command line: [robot] name: '%s' must be letters, digits, '_' or '-' "
			         "(it prefixes LCM channels)", text_line(shown, sizeof shown, bad[i]));
			assert_string_equal(e.line[0], want);
		}
		assert_string_equal(c.name, "robot");
	}
	char b[CFG_ERR_MAX];
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nname = r\v1\n", b, sizeof b),
	                    "robot1.conf:4: [robot] name: 'r?1' must be letters, digits, '_' or '-' "
	                    "(it prefixes LCM channels)");
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_override(&c, "robot.name=abcdefghijabcdefghijabcdefghijabcdefghijabcdefg", &e)); /* 47 */
	cfg_defaults(&c);
	assert_true(cfg_override(&c, "robot.name=robot_1-b", &e));
	assert_string_equal(c.name, "robot_1-b");
}

static void test_file_and_missing_file(void **state)
{
	(void)state;
	char path[] = "/tmp/undulate-cfg-XXXXXX";
	int fd = mkstemp(path);
	assert_true(fd >= 0);
	const char *text = "[robot]\nport = /dev/null\nids = 1\n[joint.1]\nc = oops\n";
	assert_int_equal(write(fd, text, strlen(text)), (int)strlen(text));
	close(fd);
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_false(cfg_load_file(&c, path, &e));
	char want[128];
	snprintf(want, sizeof want, "%s:5: [joint.1] c: not a number 'oops'", path);
	assert_string_equal(e.line[0], want);
	assert_false(e.file_refused);   /* read, with errors of its own */
	unlink(path);
	e.count = 0;
	assert_false(cfg_load_file(&c, path, &e));
	assert_non_null(strstr(e.line[0], "cannot open"));
}

/* Loads path; expects it refused unread: one error, exactly want (or
 * containing it), file_refused set, the configuration as it was. */
static void expect_file_refused(const char *path, const char *want, bool partial)
{
	static struct cfg c, before;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_override(&c, "robot.ids=1,2", &e));
	memcpy(&before, &c, sizeof c);
	assert_false(cfg_load_file(&c, path, &e));
	assert_int_equal(e.count, 1);
	assert_true(e.file_refused);
	if (partial ? strstr(e.line[0], want) == NULL : strcmp(e.line[0], want) != 0)
		fail_msg("%s: got '%s', want '%s'", path, e.line[0], want);
	assert_memory_equal(&c, &before, sizeof c);
}

/* The configuration is a regular file of at most 1 MiB with no NUL byte:
 * anything else is refused at once, unread, with "PATH: why". A FIFO with no
 * writer blocked fopen() for ever, and /dev/zero was read for ever (a line
 * of NULs is an empty line to inih); a directory gave no error at all. */
static void test_only_regular_files(void **state)
{
	(void)state;
	/* a regression hangs: end this program instead of the suite's timeout */
	alarm(20);
	char dir[] = "/tmp/undulate-cfg-dir-XXXXXX";
	assert_non_null(mkdtemp(dir));
	char path[128], want[256];
	snprintf(want, sizeof want, "%s: not a regular file (a directory): a configuration is a text file", dir);
	expect_file_refused(dir, want, false);
	expect_file_refused("/dev/zero", "/dev/zero: not a regular file (a character device): "
	                    "a configuration is a text file", false);
	snprintf(path, sizeof path, "%s/fifo", dir);
	assert_int_equal(mkfifo(path, 0600), 0);
	snprintf(want, sizeof want, "%s: not a regular file (a FIFO): a configuration is a text file", path);
	expect_file_refused(path, want, false);
	unlink(path);
	/* 2 MiB (sparse: nothing is written) */
	snprintf(path, sizeof path, "%s/huge.conf", dir);
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fputs("[robot]\nport = /dev/null\nids = 1\n", f);
	fclose(f);
	assert_int_equal(truncate(path, 2 * 1024 * 1024), 0);
	snprintf(want, sizeof want, "%s: larger than 1 MiB (2097152 bytes): not a configuration", path);
	expect_file_refused(path, want, false);
	/* NUL bytes, named with their line */
	assert_int_equal(truncate(path, 40), 0);
	snprintf(want, sizeof want, "%s:4: a NUL byte: a configuration is a text file", path);
	expect_file_refused(path, want, false);
	unlink(path);
	snprintf(path, sizeof path, "%s/missing.conf", dir);
	snprintf(want, sizeof want, "%s: cannot open: No such file or directory", path);
	expect_file_refused(path, want, false);
	rmdir(dir);
	alarm(0);
}

static void test_overrides(void **state)
{
	(void)state;
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_load_string(&c, "r.conf", good, &e));
	assert_true(cfg_override(&c, "robot.port=/tmp/bus", &e));
	assert_true(cfg_override(&c, "robot.ids=7,8", &e));
	assert_true(cfg_override(&c, "joint.1.k=0.09", &e));
	assert_true(cfg_override(&c, "sinusoid.amplitude=0.5", &e));
	assert_true(cfg_override(&c, "robot.mode=HOLD", &e));
	assert_true(cfg_finish(&c, &e));
	assert_string_equal(c.port, "/tmp/bus");
	assert_int_equal(c.njoints, 2);
	assert_int_equal(c.ids[0], 7);
	assert_double_equal(c.joint[0].osc.k, 0.09, 1e-12);
	assert_double_equal(c.amplitude, 0.5, 1e-12);
	assert_int_equal(c.mode, CFG_MODE_HOLD);
	assert_int_equal(e.count, 0);

	assert_false(cfg_override(&c, "joint.1.k=abc", &e));
	assert_string_equal(e.line[0], "command line: [joint.1] k: not a number 'abc'");
	assert_false(cfg_override(&c, "robotport=/x", &e));
	assert_non_null(strstr(e.line[1], "expected section.key=value"));
	assert_false(cfg_override(&c, "robot.prot=/x", &e));
	assert_string_equal(e.line[2], "command line: [robot] prot: unknown key");
}

/* compliance_slope: the servo's own (factory 32) unless set; the register's
 * range; printed with the rest (what --check-config -v shows). */
static void test_compliance_slope(void **state)
{
	(void)state;
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_load_string(&c, "r.conf", good, &e));
	assert_true(cfg_finish(&c, &e));
	assert_int_equal(c.compliance_slope, -1);
	assert_true(cfg_override(&c, "robot.compliance_slope=128", &e));
	assert_int_equal(c.compliance_slope, 128);
	assert_false(cfg_override(&c, "robot.compliance_slope=255", &e));
	assert_false(cfg_override(&c, "robot.compliance_slope=-2", &e));
	assert_false(cfg_override(&c, "robot.compliance_slope=64.5", &e));
	assert_int_equal(c.compliance_slope, 128);
	char *text = printed(&c);
	assert_non_null(strstr(text, "\ncompliance_slope = 128\n"));
	free(text);
}

static void test_command_line_only(void **state)
{
	(void)state;
	/* undulated --port PATH --ids 1,2: one robot, defaults; no mode given:
	 * HOLD, the first-run default (nothing swings before it is asked to) */
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_override(&c, "robot.port=/dev/pts/9", &e));
	assert_true(cfg_override(&c, "robot.ids=1,2", &e));
	assert_true(cfg_finish(&c, &e));
	assert_int_equal(c.mode, CFG_MODE_HOLD);
	assert_false(c.mode_given);
	assert_int_equal(c.njoints, 2);
	assert_true(cfg_override(&c, "robot.mode=oscillator", &e));
	assert_int_equal(c.mode, CFG_MODE_OSCILLATOR);
	assert_true(c.mode_given);
}

/* Other rates (period_ms 1..100): what is counted in time keeps its time, the
 * default step limit its speed, and the watchdog and silent_s must span three
 * periods (CONTROL.md, "Other rates"). */
static bool rate_config(const char *period, const char *extra, struct cfg *c, struct cfg_errors *e)
{
	char set[64];
	cfg_defaults(c);
	*e = (struct cfg_errors){ 0 };
	snprintf(set, sizeof set, "robot.period_ms=%s", period);
	bool ok = cfg_override(c, "robot.port=/dev/pts/9", e) && cfg_override(c, "robot.ids=1,2", e) &&
	          cfg_override(c, set, e) && (extra == NULL || cfg_override(c, extra, e));
	return ok && cfg_finish(c, e);
}

static void test_other_rates(void **state)
{
	(void)state;
	struct cfg c;
	struct cfg_errors e;
	assert_true(rate_config("1", NULL, &c, &e));
	assert_true(fabs(c.joint[0].max_step - 0.01) < 1e-12);   /* 10 rad/s */
	assert_int_equal(c.bus_watchdog_ms, 100);
	assert_true(c.silent_s == 0.5);
	assert_false(rate_config("0.5", NULL, &c, &e));
	assert_true(rate_config("50", NULL, &c, &e));
	assert_true(fabs(c.joint[1].max_step - 0.5) < 1e-12);
	assert_int_equal(c.bus_watchdog_ms, 500);    /* ten periods above 10 ms */
	assert_true(rate_config("50", "joint.1.max_step=0.2", &c, &e));
	assert_true(c.joint[0].max_step == 0.2);     /* a set one is per cycle */
	assert_false(rate_config("50", "robot.bus_watchdog_ms=120", &c, &e));
	assert_non_null(strstr(e.line[0], "bus_watchdog_ms = 120 is shorter than 3 periods of 50 ms"));
	assert_true(rate_config("50", "robot.bus_watchdog_ms=0", &c, &e));   /* off */
	assert_true(rate_config("20", "robot.bus_watchdog_ms=100", &c, &e));
	assert_int_equal(c.bus_watchdog_ms, 100);    /* a set one is kept, even the default's value */
	assert_true(rate_config("100", NULL, &c, &e));
	assert_true(c.joint[0].max_step == 0.5);     /* the key's range */
	assert_false(rate_config("100", "robot.silent_s=0.2", &c, &e));
	assert_non_null(strstr(e.line[0], "silent_s = 0.2 is shorter than 3 periods of 100 ms"));
	assert_true(rate_config("2", "robot.silent_s=0.05", &c, &e));
}

/* A refused ID list leaves the configured one as it was (it was half
 * overwritten once: "5,j" wrote the 5 before failing). */
static void test_refused_ids_change_nothing(void **state)
{
	(void)state;
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_override(&c, "robot.ids=1,2", &e));
	static const char *const refused[] = { "robot.ids=5,j", "robot.ids=7,7", "robot.ids=9,300" };
	for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++)
		assert_false(cfg_override(&c, refused[i], &e));
	assert_int_equal(c.njoints, 2);
	assert_int_equal(c.ids[0], 1);
	assert_int_equal(c.ids[1], 2);
}

/* rs485: the port option of an on-board UART (port.h), off by default; a
 * refused value names itself and leaves the setting as it was. */
static void test_rs485(void **state)
{
	(void)state;
	struct cfg c;
	char err[CFG_ERR_MAX];
	load_ok(&c, good);
	assert_int_equal(c.rs485, PORT_RS485_OFF);
	load_ok(&c, "[robot]\nport=/dev/ttyAMA0\nids=1\nrs485 = rts-after-send\n");
	assert_int_equal(c.rs485, PORT_RS485_RTS_AFTER_SEND);
	load_ok(&c, "[robot]\nport=/dev/ttyAMA0\nids=1\nrs485 = rts\necho = on\n");
	assert_int_equal(c.rs485, PORT_RS485_RTS_ON_SEND);
	assert_true(c.echo);
	struct cfg_errors e = { 0 };
	assert_false(cfg_override(&c, "robot.rs485=yes", &e));
	assert_string_equal(e.line[0], "command line: [robot] rs485: 'yes' is not off, rts-on-send (or rts) or "
	                               "rts-after-send");
	assert_int_equal(c.rs485, PORT_RS485_RTS_ON_SEND);
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1\nrs485=\n", err, sizeof err),
	                    "robot1.conf:4: [robot] rs485: '' is not off, rts-on-send (or rts) or rts-after-send");
	/* --check-config -v prints it back in a form the parser takes */
	char *text = printed(&c);
	assert_non_null(strstr(text, "\nrs485 = rts-on-send\n"));
	free(text);
}

static void test_param_ranges(void **state)
{
	(void)state;
	struct param_range r;
	assert_true(cfg_param_range("k", &r));
	assert_false(r.min_open);
	assert_true(r.min > 0.0);
	assert_true(cfg_param_range("inertia", &r));
	assert_true(r.min >= 1e-5);
	/* what bounds a joint is the configuration's alone */
	assert_true(cfg_param_commandable("k") && cfg_param_commandable("amplitude"));
	assert_false(cfg_param_commandable("limit_min") || cfg_param_commandable("limit_max") ||
	             cfg_param_commandable("neutral") || cfg_param_commandable("max_step") ||
	             cfg_param_commandable("kk"));
	assert_false(cfg_param_range("kk", &r));
	assert_true(cfg_param_is_joint("lambda"));
	assert_false(cfg_param_is_joint("amplitude"));
	assert_true(cfg_param_is_robot("amplitude"));
	struct cfg_joint j;
	assert_ptr_equal(cfg_joint_param(&j, "friction"), &j.osc.friction);
	/* the coupling's phase (CONTROL.md, "The joints' lag"): per joint, commandable, ±π */
	assert_ptr_equal(cfg_joint_param(&j, "coupling_phase"), &j.osc.coupling_phase);
	assert_true(cfg_param_range("coupling_phase", &r) && cfg_param_commandable("coupling_phase") &&
	            cfg_param_is_joint("coupling_phase"));
	assert_true(fabs(r.min + M_PI) < 1e-9 && fabs(r.max - M_PI) < 1e-9);
	assert_null(cfg_joint_param(&j, "amplitude"));
	enum cfg_mode m;
	assert_true(cfg_mode_parse("Oscillator", &m));
	assert_int_equal(m, CFG_MODE_OSCILLATOR);
	assert_false(cfg_mode_parse("run", &m));
}

/* Several buses: [robot] ids names each joint's bus ("tail:1": servo 1 on
 * the port of [bus.tail]; no name: the [robot] port), so joint order stays
 * the robot's and IDs may repeat on different buses. */
static const char two_buses[] =
	"[robot]\nname = r2\nport = /dev/ttyUSB0\nids = 1, 2, tail:1, tail:2\nbaud = 57600\n"
	"[bus.tail]\nport = /dev/ttyUSB1\nbaud = 1000000\n";

static void test_buses(void **state)
{
	(void)state;
	static struct cfg c;
	load_ok(&c, two_buses);
	assert_int_equal(c.njoints, 4);
	assert_int_equal(c.nbuses, 2);
	assert_int_equal(cfg_buses_used(&c), 2);
	assert_string_equal(c.bus[0].name, "robot");
	assert_string_equal(c.bus[0].port, "/dev/ttyUSB0");
	assert_int_equal(c.bus[0].baud, 57600);
	assert_int_equal(c.bus[0].njoints, 2);
	assert_string_equal(c.bus[1].name, "tail");
	assert_string_equal(c.bus[1].port, "/dev/ttyUSB1");
	assert_int_equal(c.bus[1].baud, 1000000);
	assert_int_equal(c.bus[1].njoints, 2);
	assert_int_equal(c.bus[1].joints[0], 2);
	assert_int_equal(c.bus[1].joints[1], 3);
	assert_int_equal(c.ids[2], 1);
	assert_int_equal(c.joint_bus[0], 0);
	assert_int_equal(c.joint_bus[1], 0);
	assert_int_equal(c.joint_bus[2], 1);
	assert_int_equal(c.joint_bus[3], 1);
	assert_true(cfg_bus_has_joint(&c, 1, 3));
	assert_false(cfg_bus_has_joint(&c, 0, 3));
	/* printed, it reads back the same */
	char *text = printed(&c);
	assert_non_null(strstr(text, "ids = 1,2,tail:1,tail:2\n"));
	assert_non_null(strstr(text, "[bus.tail]\nport = /dev/ttyUSB1\nusb_serial = \nbaud = 1000000\n"));
	static struct cfg again;
	load_ok(&again, text);
	free(text);
	assert_int_equal(again.nbuses, 2);
	assert_int_equal(again.joint_bus[3], 1);

	/* the joints in any order, every one on a bus of its own: the [robot]
	 * port is not needed; a bus's baud is the robot's unless it says */
	load_ok(&c, "[bus.a]\nport = /dev/pts/1\n[robot]\nids = b:5, a:5\n[bus.b]\nusb_serial = A1\n");
	assert_int_equal(c.bus[0].njoints, 0);
	assert_int_equal(cfg_buses_used(&c), 2);
	assert_int_equal(c.joint_bus[0], 2);
	assert_int_equal(c.joint_bus[1], 1);
	assert_int_equal(c.bus[1].baud, 1000000);

	/* one-port configurations are what they were: one bus, every joint on it */
	load_ok(&c, good);
	assert_int_equal(c.nbuses, 1);
	assert_int_equal(cfg_buses_used(&c), 1);
	assert_int_equal(c.bus[0].njoints, 2);
	text = printed(&c);
	assert_null(strstr(text, "[bus."));
	assert_non_null(strstr(text, "ids = 3,4\n"));
	free(text);

	/* the command line: --ids with names, --set bus.NAME.key=value */
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_override(&c, "robot.port=/dev/pts/9", &e));
	assert_true(cfg_override(&c, "robot.ids=1,b:1", &e));
	assert_true(cfg_override(&c, "bus.b.port=/dev/pts/10", &e));
	assert_true(cfg_finish(&c, &e));
	assert_int_equal(c.joint_bus[1], 1);
	assert_string_equal(c.bus[1].port, "/dev/pts/10");
}

static void test_bus_errors(void **state)
{
	(void)state;
	char b[CFG_ERR_MAX];
	/* an ID twice on one bus; on two buses it is fine (above) */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,a:2,a:2\n[bus.a]\nport=/dev/pts/1\n", b, sizeof b),
	                    "robot1.conf:3: [robot] ids: servo ID 2 listed twice on bus a (an ID may repeat only on "
	                    "different buses)");
	/* the same port twice */
	assert_string_equal(load_error("[robot]\nport=/dev/pts/1\nids=1,a:2\n[bus.a]\nport=/dev/pts/1\n", b, sizeof b),
	                    "command line: [bus.a] port: /dev/pts/1 is bus robot's port too: each bus is a port of its own");
	assert_string_equal(load_error("[robot]\nusb_serial=X9\nids=1,a:2\n[bus.a]\nusb_serial=X9\n", b, sizeof b),
	                    "command line: [bus.a] usb_serial: X9 is bus robot's adapter too: each bus is a port of its own");
	/* too many buses */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,a:1,b:1,c:1,d:1\n", b, sizeof b),
	                    "robot1.conf:3: [robot] ids: bus d: more than 4 buses: a robot has at most 4 ports (the [robot] "
	                    "port and 3 [bus.NAME] sections)");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,a:1,b:1,c:1\n[bus.a]\nport=/dev/pts/1\n"
	                               "[bus.b]\nport=/dev/pts/2\n[bus.c]\nport=/dev/pts/3\n[bus.d]\nport=/dev/pts/4\n",
	                               b, sizeof b),
	                    "robot1.conf:11: [bus.d]: bus d: more than 4 buses: a robot has at most 4 ports (the [robot] "
	                    "port and 3 [bus.NAME] sections)");
	/* a bus without joints, a bus without a port */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,2\n[bus.a]\nport=/dev/pts/1\n", b, sizeof b),
	                    "command line: [bus.a]: no joint is on it: name its servos in [robot] ids (e.g. ids = 1, 2, "
	                    "a:1, a:2)");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,tail:2\n", b, sizeof b),
	                    "command line: [bus.tail] port: no port configured (a [bus.tail] section with port = "
	                    "/dev/ttyUSB1 or usb_serial = ..., or --set bus.tail.port=PATH)");
	/* torque actuation on several buses: a lost bus would leave the others'
	 * joints driven by torque against a stale reading (the hold is a goal) */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,a:2\nactuation=torque\n[bus.a]\nport=/dev/pts/1\n",
	                               b, sizeof b),
	                    "command line: [robot] actuation: torque actuation on several buses is refused: a lost bus "
	                    "holds the other buses' joints by their goals, which torque actuation does not send; run it "
	                    "on one bus, or in position actuation");
	/* the [robot] port with nothing left on it */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=a:1\n[bus.a]\nport=/dev/pts/1\n", b, sizeof b),
	                    "command line: [robot] port: no joint is left on it (each is on a [bus.NAME]): remove it, or "
	                    "leave some joints out of the [bus.NAME] sections");
	/* bad values, names and keys */
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,a:x\n[bus.a]\nport=/dev/pts/1\n", b, sizeof b),
	                    "robot1.conf:3: [robot] ids: not a list of servo IDs '1,a:x'");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,:2\n", b, sizeof b),
	                    "robot1.conf:3: [robot] ids: a bus name is 1..47 characters");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,robot:2\n", b, sizeof b),
	                    "robot1.conf:3: [robot] ids: bus 'robot': a bus is named by letters, digits, '_' or '-', and "
	                    "not 'robot' (the [robot] section's own port)");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,a:2\n[bus.a]\nport=/dev/pts/1\nbaud=12\n", b,
	                               sizeof b),
	                    "robot1.conf:6: [bus.a] baud: 12 out of range 9600..4500000");
	assert_string_equal(load_error("[robot]\nport=/dev/null\nids=1,a:2\n[bus.a]\nport=/dev/pts/1\nids=2\n", b,
	                               sizeof b),
	                    "robot1.conf:6: [bus.a] ids: unknown key (port, usb_serial, baud; its joints are named in "
	                    "[robot] ids, e.g. ids = 1, 2, a:1, a:2)");
	/* lockstep carries every bus of a robot on its one connection (common/lockstep.h "Several buses") */
	static struct cfg lks;
	load_ok(&lks, "[robot]\nport=/dev/null\nids=1,a:2\nlockstep=/tmp/x.sock\n[bus.a]\nport=/dev/pts/1\n");
	assert_string_equal(lks.lockstep, "/tmp/x.sock");
	/* each bus's channel "<robot>.BUS.<bus>" fits LCM's 63 characters */
	assert_string_equal(load_error("[robot]\nname=r0123456789012345678901234567890\nport=/dev/null\nids=1,"
	                               "b0123456789012345678901234567890:2\n[bus.b0123456789012345678901234567890]\n"
	                               "port=/dev/pts/1\n", b, sizeof b),
	                    "command line: [bus.b0123456789012345678901234567890]: its channel "
	                    "r0123456789012345678901234567890.BUS.b0123456789012345678901234567890 is 69 characters, LCM "
	                    "takes at most 63: give the bus or the robot a shorter name");
	/* a refused list leaves the buses' joints as they were */
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_override(&c, "robot.ids=1,a:1", &e));
	assert_false(cfg_override(&c, "robot.ids=a:1,1,a:1", &e));
	assert_int_equal(c.njoints, 2);
	assert_int_equal(c.joint_bus[0], 0);
	assert_int_equal(c.joint_bus[1], 1);
}

/* dxl doctor --bus NAME: the robot seen as one of its buses, joints with
 * their [joint.N] in the robot's order. */
static void test_only_bus(void **state)
{
	(void)state;
	static struct cfg c;
	load_ok(&c, "[robot]\nport = /dev/ttyUSB0\nids = 1, tail:7, 2, tail:8\n[bus.tail]\nport = /dev/ttyUSB1\n"
	            "baud = 57600\n[joint.4]\nlimit_max = 0.5\n");
	char why[256];
	assert_false(cfg_only_bus(&c, "head", why, sizeof why));
	assert_string_equal(why, "no bus 'head' with joints; the robot's buses: robot (/dev/ttyUSB0), tail (/dev/ttyUSB1)");
	assert_true(cfg_only_bus(&c, "tail", why, sizeof why));
	assert_int_equal(c.njoints, 2);
	assert_int_equal(c.ids[0], 7);
	assert_int_equal(c.ids[1], 8);
	assert_true(c.joint[1].limit_max == 0.5);
	assert_string_equal(c.port, "/dev/ttyUSB1");
	assert_int_equal(c.baud, 57600);
	assert_int_equal(c.nbuses, 1);
	assert_int_equal(cfg_buses_used(&c), 1);
	assert_true(cfg_bus_has_joint(&c, 0, 1));
	load_ok(&c, two_buses);
	assert_true(cfg_only_bus(&c, "robot", why, sizeof why));
	assert_int_equal(c.njoints, 2);
	assert_string_equal(c.port, "/dev/ttyUSB0");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_good_file),
		cmocka_unit_test(test_refused_ids_change_nothing),
		cmocka_unit_test(test_defaults_from_osc),
		cmocka_unit_test(test_errors_name_file_line_key),
		cmocka_unit_test(test_whole_config_errors),
		cmocka_unit_test(test_sinusoid_stiffness),
		cmocka_unit_test(test_indirect_key),
		cmocka_unit_test(test_every_error_reported),
		cmocka_unit_test(test_repeated_keys_and_sections),
		cmocka_unit_test(test_long_line),
		cmocka_unit_test(test_line_of_199_characters),
		cmocka_unit_test(test_name_without_spaces),
		cmocka_unit_test(test_file_and_missing_file),
		cmocka_unit_test(test_only_regular_files),
		cmocka_unit_test(test_overrides),
		cmocka_unit_test(test_command_line_only),
		cmocka_unit_test(test_other_rates),
		cmocka_unit_test(test_compliance_slope),
		cmocka_unit_test(test_param_ranges),
		cmocka_unit_test(test_rs485),
		cmocka_unit_test(test_buses),
		cmocka_unit_test(test_bus_errors),
		cmocka_unit_test(test_only_bus),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
