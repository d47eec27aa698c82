/* test_analyze_endstate.c — the end state of a pair when its joints stop:
 * logs of two one-joint robots with chosen motions (one stopped, both
 * stopped, both swinging) through the whole analyser, and the class and the
 * final-window swings it reports (tools/analyze/analyze.c). The daemon's
 * frequency stays in the messages after a stop, as it does on a stalled
 * robot: that is what gave stopped joints a phase of 0 or pi. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../tools/analyze/alog.h"
#include "../../tools/analyze/analyze.h"
#include "anrun.h"
#include "scratch.h"

#include "undulate_robot_state_t.h"

ALOG_DEFINE_WRITER(robot_state_t)

/* Largest file the tests read whole (summary.json / summary.txt). */
#define T_FILE_MAX (1 << 16)
/* The logs: 20 s at the daemon's 100 Hz; the default final window is 10 s. */
#define T_SECONDS 20.0
#define T_DT 0.01
#define T_FREQ_HZ 0.8
#define T_START_UTIME 1700000000000000LL
/* One AX-12 position step (300 deg / 1023) in rad: a still servo's reading
 * flickers by this much. */
#define T_AX12_STEP (300.0 / 1023.0 * M_PI / 180.0)


/* One joint's motion: A cos(2 pi f t + phase) + offset until stop_s (< 0:
 * never), then held where it was, flickering by one position step. The
 * reported frequency is T_FREQ_HZ, and 0 from freq_zero_s on (> 0 only). */
struct motion {
	double amplitude, phase, offset, stop_s, freq_zero_s;
};

static void motion_at(const struct motion *m, int64_t cycle, double *angle, double *speed)
{
	double w = 2.0 * M_PI * T_FREQ_HZ, t = (double)cycle * T_DT;
	bool stopped = m->stop_s >= 0 && t > m->stop_s;
	double tt = stopped ? m->stop_s : t;
	*angle = m->offset + m->amplitude * cos(w * tt + m->phase);
	*speed = stopped ? 0.0 : -m->amplitude * w * sin(w * tt + m->phase);
	if (stopped)
		*angle += (cycle % 2 ? 1.0 : -1.0) * T_AX12_STEP;
}

static int write_state(struct alog_writer *w, const char *robot, int64_t cycle, const struct motion *m)
{
	undulate_joint_state_t j;
	memset(&j, 0, sizeof(j));
	j.servo_id = 1;
	motion_at(m, cycle, &j.angle, &j.speed);
	j.goal = j.angle;
	j.amplitude = m->amplitude;
	/* kept after a stop, as a stalled daemon's is, unless told otherwise */
	j.frequency = m->freq_zero_s > 0 && (double)cycle * T_DT >= m->freq_zero_s ? 0.0 : T_FREQ_HZ;
	j.torque = true;
	char name[16], chan[32], reason[] = "test";
	snprintf(name, sizeof(name), "%s", robot);
	snprintf(chan, sizeof(chan), "%s.STATE", robot);
	int64_t utime = T_START_UTIME + cycle * (int64_t)llround(T_DT * 1e6);
	undulate_robot_state_t msg = { .utime = utime, .robot = name, .cycle = cycle,
		.mode = UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR, .mode_reason = reason, .fault = "", .period_us = T_DT * 1e6,
		.njoints = 1, .joints = &j };
	return alog_write_robot_state_t(w, chan, utime + 100, &msg);
}

/* Writes NAME.log with robots "a" and "b" moving as A and B. */
static void write_log(const char *name, const struct motion *a, const struct motion *b)
{
	char p[512];
	snprintf(p, sizeof(p), "%s/%s.log", scratch_dir, name);
	struct alog_writer w;
	char err[512];
	assert_int_equal(alog_writer_open(&w, p, err, sizeof err), 0);
	int64_t cycles = (int64_t)llround(T_SECONDS / T_DT);
	for (int64_t c = 0; c <= cycles; c++) {
		assert_int_equal(write_state(&w, "a", c, a), 0);
		assert_int_equal(write_state(&w, "b", c, b), 0);
	}
	assert_int_equal(alog_writer_close(&w), 0);
}

/* Analyses NAME.log into NAME/ with MIN_SWING (NAN: the default). */
static void analyse(const char *name, double min_swing)
{
	char logp[512], outp[512];
	snprintf(logp, sizeof(logp), "%s/%s.log", scratch_dir, name);
	snprintf(outp, sizeof(outp), "%s/%s", scratch_dir, name);
	struct an_options o;
	anrun_options(&o, logp, outp);
	if (!isnan(min_swing))
		o.min_swing = min_swing;
	assert_int_equal(an_run(&o), AN_EXIT_OK);
}

static char *slurp(const char *dir, const char *file)
{
	char rel[256];
	snprintf(rel, sizeof(rel), "%s/%s", dir, file);
	char *buf = scratch_slurp(rel, T_FILE_MAX);
	assert_non_null(buf);
	return buf;
}

/* The a:b pair's JSON object, NUL-terminated in a copy (free it). */
static char *pair_json(const char *dir)
{
	char *js = slurp(dir, "summary.json");
	char *p = strstr(js, "{\"pair\":\"a:b\"");
	assert_non_null(p);
	char *end = strchr(p, '}');
	assert_non_null(end);
	end[1] = '\0';
	char *copy = strdup(p);
	free(js);
	return copy;
}

static double json_num(const char *obj, const char *key)
{
	char pat[64];
	snprintf(pat, sizeof(pat), "\"%s\":", key);
	const char *k = strstr(obj, pat);
	assert_non_null(k);
	return strtod(k + strlen(pat), NULL);
}

/* The class and final-window swings of a:b, checked in summary.json and
 * summary.txt alike. */
static void expect_pair(const char *dir, const char *cls, double swing_a, double swing_b)
{
	char *obj = pair_json(dir);
	char want[64];
	snprintf(want, sizeof(want), "\"class\":\"%s\"", cls);
	if (!strstr(obj, want))
		fail_msg("%s: expected %s in %s", dir, want, obj);
	assert_true(fabs(json_num(obj, "swing_a") - swing_a) < 0.02);
	assert_true(fabs(json_num(obj, "swing_b") - swing_b) < 0.02);
	free(obj);

	/* summary.txt: header ends with the two swing columns, the row with the numbers */
	char *txt = slurp(dir, "summary.txt");
	const char *hdr = strstr(txt, "\npair ");
	assert_non_null(hdr);
	const char *hdr_end = strchr(hdr + 1, '\n');
	assert_non_null(hdr_end);
	assert_true(hdr_end - hdr > 16 && strncmp(hdr_end - 16, "swing_a  swing_b", 16) == 0);
	const char *row = strstr(txt, "\na:b ");
	assert_non_null(row);
	char got_cls[64];
	assert_int_equal(sscanf(row + 1, "a:b %63s", got_cls), 1);
	assert_string_equal(got_cls, cls);
	const char *row_end = strchr(row + 1, '\n');
	assert_non_null(row_end);
	/* the last two fields of the row */
	char line[512];
	snprintf(line, sizeof(line), "%.*s", (int)(row_end - row - 1), row + 1);
	char *fields[32], *save = NULL;
	int nf = 0;
	for (char *tok = strtok_r(line, " ", &save); tok && nf < 32; tok = strtok_r(NULL, " ", &save))
		fields[nf++] = tok;
	assert_true(nf >= 4);
	double sa = strtod(fields[nf - 2], NULL), sb = strtod(fields[nf - 1], NULL);
	assert_true(fabs(sa - swing_a) < 0.02 && fabs(sb - swing_b) < 0.02);
	free(txt);
}

/* One robot swings, the other stopped 5 s in (before the final window):
 * whatever their phases, the pair is not oscillating. */
static void test_one_stopped(void **state)
{
	(void)state;
	struct motion a = { .amplitude = 0.8, .phase = 0.0, .offset = 0.0, .stop_s = -1 };
	struct motion b = { .amplitude = 0.8, .phase = 0.0, .offset = 0.0, .stop_s = 5.3 };
	write_log("one", &a, &b);
	analyse("one", NAN);
	expect_pair("one", "not-oscillating", 1.6, 2 * T_AX12_STEP);
}

/* Both stopped on opposite sides of neutral: phases pi apart (the
 * analyser used to call this anti-phase), but nothing moves. */
static void test_both_stopped_opposite(void **state)
{
	(void)state;
	struct motion a = { .amplitude = 0.8, .phase = 0.0, .offset = 0.0, .stop_s = 5.0 };
	struct motion b = { .amplitude = 0.8, .phase = M_PI, .offset = 0.0, .stop_s = 5.0 };
	write_log("both", &a, &b);
	analyse("both", NAN);
	expect_pair("both", "not-oscillating", 2 * T_AX12_STEP, 2 * T_AX12_STEP);
	/* the stopped robot's joint in the robot section of summary.json */
	char *js = slurp("both", "summary.json");
	const char *r = strstr(js, "{\"name\":\"a\"");
	assert_non_null(r);
	const char *sw = strstr(r, "\"swing_rad\":");
	assert_non_null(sw);
	assert_true(sw < strstr(r, "]}"));
	assert_true(fabs(strtod(sw + strlen("\"swing_rad\":"), NULL) - 2 * T_AX12_STEP) < 1e-6);
	free(js);
}

/* Both stopped, and the daemon says so: its estimator reports 0 Hz three
 * periods after the last crossing (common/phase.h), so no phase is known in
 * the final window. Still not-oscillating, not no-data: the swing decides. */
static void test_both_stopped_no_frequency(void **state)
{
	(void)state;
	struct motion a = { .amplitude = 0.8, .phase = 0.0, .offset = 0.0, .stop_s = 5.0, .freq_zero_s = 8.8 };
	struct motion b = { .amplitude = 0.8, .phase = 1.0, .offset = 0.0, .stop_s = 5.0, .freq_zero_s = 8.8 };
	write_log("nofreq", &a, &b);
	analyse("nofreq", NAN);
	expect_pair("nofreq", "not-oscillating", 2 * T_AX12_STEP, 2 * T_AX12_STEP);
}

/* Both swinging in anti-phase: classified by their phases as before. */
static void test_both_anti_phase(void **state)
{
	(void)state;
	struct motion a = { .amplitude = 0.8, .phase = 0.0, .offset = 0.0, .stop_s = -1 };
	struct motion b = { .amplitude = 0.8, .phase = M_PI, .offset = 0.0, .stop_s = -1 };
	write_log("anti", &a, &b);
	analyse("anti", NAN);
	expect_pair("anti", "anti-phase", 1.6, 1.6);
}

/* A swing of 0.1 rad p-p is below the default threshold; --min-swing 0.05
 * lets the phases decide (in phase, about a nonzero offset). */
static void test_min_swing_option(void **state)
{
	(void)state;
	struct motion a = { .amplitude = 0.05, .phase = 0.0, .offset = 0.0, .stop_s = -1 };
	struct motion b = { .amplitude = 0.05, .phase = 0.02, .offset = 0.0, .stop_s = -1 };
	write_log("small", &a, &b);
	analyse("small", NAN);
	expect_pair("small", "not-oscillating", 0.1, 0.1);
	analyse("small", 0.05);
	expect_pair("small", "in-phase", 0.1, 0.1);
	char *js = slurp("small", "summary.json");
	assert_non_null(strstr(js, "\"min_swing\":0.05"));
	free(js);
}

/* A robot that stops inside the final window still swung in it: the swing
 * is over the window, the class follows the phases. */
static void test_stop_inside_window(void **state)
{
	(void)state;
	struct motion a = { .amplitude = 0.8, .phase = 0.0, .offset = 0.0, .stop_s = -1 };
	struct motion b = { .amplitude = 0.8, .phase = 0.0, .offset = 0.0, .stop_s = T_SECONDS - 1.0 };
	write_log("late", &a, &b);
	analyse("late", NAN);
	char *obj = pair_json("late");
	assert_null(strstr(obj, "not-oscillating"));
	assert_true(json_num(obj, "swing_b") > 1.5);
	free(obj);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_one_stopped),
		cmocka_unit_test(test_both_stopped_opposite),
		cmocka_unit_test(test_both_stopped_no_frequency),
		cmocka_unit_test(test_both_anti_phase),
		cmocka_unit_test(test_min_swing_option),
		cmocka_unit_test(test_stop_inside_window),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
