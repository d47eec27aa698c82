/* test_analyze_broken.c — what undulate-analyze says about a run beyond its
 * pairs' phases, on logs written here with known content:
 *  - a pair locked within its bound whose contacts (SIM.TRUTH's contacts,
 *    resting contact included) average 0.05 N over the window is "grazing",
 *    at 0.5 N "still-colliding" (the 0.1 N mark between them);
 *  - a latched fault, a robot that stopped publishing and a simulator that
 *    fell behind real time are each a sentence in summary.json's "broken"
 *    and a BROKEN: line first in summary.txt; a clean run has "broken": [];
 *  - "world" is the simulator's, and "force" has the median contact force
 *    of the truth periods with contact before the switch to OSCILLATOR and
 *    in the final window. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../tools/analyze/alog.h"
#include "../../tools/analyze/analyze.h"
#include "anrun.h"
#include "scratch.h"
#include "undulate_robot_state_t.h"
#include "undulate_sim_truth_t.h"

ALOG_DEFINE_WRITER(robot_state_t)
ALOG_DEFINE_WRITER(sim_truth_t)

#define T_START_UTIME 1700000000000000LL
#define T_DT 0.01
#define T_SECONDS 30.0
#define T_FREQ 0.8
#define T_SWITCH_S 10.0

struct run {
	double force_n;           /* the pair's contact force, every truth period */
	double clock_force_n;     /* before the switch */
	double fault_at;          /* b latches a fault then (< 0: never) */
	double b_stops_at;        /* b's last state (< 0: to the end) */
	double late_at;           /* truth periods 35 ms late from then (< 0: never) */
	int late_n;               /* how many */
	bool plane;
};

static int write_state(struct alog_writer *w, const char *robot, int64_t cycle, double phase, const struct run *r)
{
	double t = (double)cycle * T_DT, om = 2.0 * M_PI * T_FREQ;
	undulate_joint_state_t j;
	memset(&j, 0, sizeof j);
	j.servo_id = 1;
	j.angle = 0.8 * cos(om * t + phase);
	j.speed = -0.8 * om * sin(om * t + phase);
	j.goal = j.angle;
	j.amplitude = 0.8;
	j.frequency = T_FREQ;
	j.torque = true;
	char name[8], chan[16], reason[] = "test", fault[80] = "";
	snprintf(name, sizeof name, "%s", robot);
	snprintf(chan, sizeof chan, "%s.STATE", robot);
	if (robot[0] == 'b' && r->fault_at >= 0 && t >= r->fault_at)
		snprintf(fault, sizeof fault, "servo 1 silent for 0.50 s");
	int64_t utime = T_START_UTIME + cycle * 10000;
	undulate_robot_state_t m = { .utime = utime, .robot = name, .cycle = cycle, .mode_reason = reason,
				     .fault = fault, .period_us = 1e4, .njoints = 1, .joints = &j };
	m.mode = t < T_SWITCH_S ? UNDULATE_ROBOT_STATE_T_MODE_SINUSOID : UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR;
	return alog_write_robot_state_t(w, chan, utime + 100, &m);
}

static double total_impulse;

/* SIM.TRUTH: a and b 0.3 m apart on an 0.1865 m lever (d~ 1.0: the bound is
 * pi, any locked phase is within it), touching every period with force F */
static int write_truth(struct alog_writer *w, int64_t cycle, const struct run *r)
{
	double t = (double)cycle * T_DT, f = t < T_SWITCH_S ? r->clock_force_n : r->force_n;
	char a[] = "a", b[] = "b";
	undulate_sim_body_t bodies[2] = {
		{ .robot = a, .servo_id = 1, .angle = 0.5, .lateral = -0.15 + 0.5 * 0.1865, .neutral = -0.15 },
		{ .robot = b, .servo_id = 1, .angle = 0.5, .lateral = 0.15 + 0.5 * 0.1865, .neutral = 0.15 },
	};
	undulate_sim_contact_t contact = { .robot_a = 0, .robot_b = 1, .impulse = f * T_DT, .normal_impulse = f * T_DT,
					   .force = f, .impact = cycle % 100 == 0 };
	total_impulse += f * T_DT;
	int64_t utime = T_START_UTIME + cycle * 10000;
	undulate_sim_truth_t m = {
		.utime = utime, .step = cycle * 10, .sim_time = t, .total_impulse = total_impulse,
		.worst_lateness_us = r->late_at >= 0 && t >= r->late_at - 0.001 &&
		                     t < r->late_at + r->late_n * T_DT - 0.001 ? 35000.0 : 50.0,
		.nbodies = 2, .bodies = bodies, .ncontacts = f > 0 ? 1 : 0, .contacts = &contact,
		.world = r->plane ? UNDULATE_SIM_TRUTH_T_WORLD_PLANE : UNDULATE_SIM_TRUTH_T_WORLD_ROW,
	};
	return alog_write_sim_truth_t(w, "SIM.TRUTH", utime + 200, &m);
}

static char *analyse(const char *name, const struct run *r)
{
	char logp[512], outp[512], err[256];
	snprintf(logp, sizeof logp, "%s/%s.log", scratch_dir, name);
	snprintf(outp, sizeof outp, "%s/%s", scratch_dir, name);
	struct alog_writer w;
	assert_int_equal(alog_writer_open(&w, logp, err, sizeof err), 0);
	total_impulse = 0;
	for (int64_t c = 0; c <= (int64_t)llround(T_SECONDS / T_DT); c++) {
		double t = (double)c * T_DT;
		assert_int_equal(write_state(&w, "a", c, 0.0, r), 0);
		if (r->b_stops_at < 0 || t <= r->b_stops_at)
			assert_int_equal(write_state(&w, "b", c, 0.4, r), 0);
		assert_int_equal(write_truth(&w, c, r), 0);
	}
	assert_int_equal(alog_writer_close(&w), 0);
	struct an_options o;
	anrun_options(&o, logp, outp);
	FILE *null = fopen("/dev/null", "w");
	o.msg = null;
	assert_int_equal(an_run(&o), AN_EXIT_OK);
	fclose(null);
	char rel[64];
	snprintf(rel, sizeof rel, "%s/summary.json", name);
	char *js = scratch_slurp(rel, 1 << 20);
	assert_non_null(js);
	return js;
}

static double json_num(const char *js, const char *key)
{
	char pat[64];
	snprintf(pat, sizeof pat, "\"%s\":", key);
	const char *k = strstr(js, pat);
	assert_non_null(k);
	return strtod(k + strlen(pat), NULL);
}

static void test_grazing_against_colliding(void **state)
{
	(void)state;
	struct run light = { .force_n = 0.05, .clock_force_n = 1.0, .fault_at = -1, .b_stops_at = -1, .late_at = -1 };
	char *js = analyse("light", &light);
	assert_non_null(strstr(js, "\"class\":\"grazing\""));
	assert_true(fabs(json_num(js, "window_contact_impulse") - 0.05 * 10.0) < 0.02);
	free(js);
	struct run hard = light;
	hard.force_n = 0.5;
	js = analyse("hard", &hard);
	assert_non_null(strstr(js, "\"class\":\"still-colliding\""));
	free(js);
	char *txt = scratch_slurp("light/summary.txt", 1 << 20);
	assert_non_null(strstr(txt, "grazing: a pair locked within its compatibility bound + 0.10 rad whose contacts "
	                            "in the final window average at most 0.100 N"));
	free(txt);
}

static void test_clean_world_and_force(void **state)
{
	(void)state;
	struct run r = { .force_n = 0.05, .clock_force_n = 2.0, .fault_at = -1, .b_stops_at = -1, .late_at = -1,
			 .plane = true };
	char *js = analyse("clean", &r);
	assert_non_null(strstr(js, "\"world\":\"plane\""));
	assert_non_null(strstr(js, "\"broken\":[]"));
	assert_true(fabs(json_num(js, "median_before_n") - 2.0) < 1e-6);
	assert_true(fabs(json_num(js, "median_after_n") - 0.05) < 1e-6);
	assert_true(fabs(json_num(js, "switch_s") - T_SWITCH_S) < 0.02);
	free(js);
	r.plane = false;
	js = analyse("row", &r);
	assert_non_null(strstr(js, "\"world\":\"row\""));
	free(js);
}

/* five late steps in 30 s are a hiccup the schedule catches up, not a
 * broken run (a loaded machine shows them) */
static void test_a_few_late_steps_are_not_broken(void **state)
{
	(void)state;
	struct run r = { .force_n = 0.05, .clock_force_n = 1.0, .fault_at = -1, .b_stops_at = -1, .late_at = 12.0,
			 .late_n = 5 };
	char *js = analyse("hiccup", &r);
	assert_non_null(strstr(js, "\"broken\":[]"));
	free(js);
}

static void test_broken_runs(void **state)
{
	(void)state;
	struct run r = { .force_n = 0.05, .clock_force_n = 1.0, .fault_at = 15.0, .b_stops_at = 25.0, .late_at = 12.0,
			 .late_n = 100 };
	char *js = analyse("broken", &r);
	assert_non_null(strstr(js, "\"robot b latched a fault at 15.0 s: servo 1 silent for 0.50 s\""));
	assert_non_null(strstr(js, "\"robot b stopped publishing at 25.0 s (the log runs to 30.0 s)"));
	assert_non_null(strstr(js, "\"the simulator fell behind real time: 100 truth period(s) with a step more than 10 ms "
	                           "late, the first at 12.0 s, the worst 35 ms\""));
	free(js);
	char *txt = scratch_slurp("broken/summary.txt", 1 << 20);
	/* said first, before anything else about the run */
	assert_non_null(strstr(txt, "undulate-analyze summary\nBROKEN: robot b latched a fault at 15.0 s"));
	free(txt);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_grazing_against_colliding),
		cmocka_unit_test(test_clean_world_and_force),
		cmocka_unit_test(test_a_few_late_steps_are_not_broken),
		cmocka_unit_test(test_broken_runs),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
