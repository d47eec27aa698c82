/* test_web_frame.c — undulate-web's history and the frames it sends each
 * browser: only what is new, bounded in size, newest kept, and the pairs'
 * end states named as undulate-analyze names them. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../tools/web/frame.h"
#include "../../tools/web/hist.h"

static struct top_model model;
static struct hist hist;
static char buf[4 * 1024 * 1024];

/* robot NAME's STATE at time NOW: joints swinging 0.8 rad at phase PH (+ the
 * travelling wave's lag on joint 1), mode MODE */
static void feed(const char *name, double now, double ph, int mode)
{
	char n[32], reason[] = "test", fault[] = "";
	snprintf(n, sizeof n, "%s", name);
	undulate_joint_state_t j[2] = {
		{ .servo_id = 1, .angle = 0.8 * cos(ph), .speed = -0.8 * 5 * sin(ph), .phase = ph, .amplitude = 0.8,
		  .frequency = 0.8, .temperature = 33, .voltage = 12 },
		{ .servo_id = 2, .angle = 0.8 * cos(ph - 2.1), .speed = 0, .phase = ph - 2.1, .amplitude = 0.8,
		  .frequency = 0.8, .temperature = 34, .voltage = 12 },
	};
	undulate_robot_state_t s = { .utime = (int64_t)(now * 1e6), .robot = n, .mode = (int8_t)mode,
		.mode_reason = reason, .fault = fault, .period_us = 10000.0, .jitter_us = 20, .njoints = 2,
		.joints = j };
	top_on_state(&model, &s, now);
}

/* SECONDS of two robots at HIST_HZ from t0, phase difference DPH, r2's mode MODE2 */
static double run(double t0, double seconds, double dph, int mode2)
{
	double t = t0;
	for (int i = 0; i < (int)(seconds * HIST_HZ); i++) {
		t = t0 + (double)i / HIST_HZ;
		double ph = 2 * M_PI * 0.8 * t;
		feed("r1", t, remainder(ph, 2 * M_PI), 3);
		feed("r2", t, remainder(ph + dph, 2 * M_PI), mode2);
		hist_sample(&hist, &model, t);
	}
	return t + 1.0 / HIST_HZ;
}

static int setup(void **state)
{
	(void)state;
	top_model_init(&model);
	hist_init(&hist, 0.0);
	return 0;
}

/* how many numbers the array after KEY (first occurrence after FROM) holds */
static int count_after(const char *from, const char *key)
{
	const char *p = strstr(from, key);
	if (p == NULL)
		return -1;
	p += strlen(key);
	assert_int_equal(*p, '[');
	if (p[1] == ']')
		return 0;
	int n = 1;
	for (p++; *p != ']'; p++)
		n += *p == ',';
	return n;
}

/* brackets and braces balance outside strings: the frame is whole */
static void assert_whole(const char *s, size_t len)
{
	int depth = 0;
	bool in_str = false;
	for (size_t i = 0; i < len; i++) {
		char c = s[i];
		if (in_str) {
			if (c == '\\')
				i++;
			else if (c == '"')
				in_str = false;
			continue;
		}
		if (c == '"')
			in_str = true;
		else if (c == '{' || c == '[')
			depth++;
		else if (c == '}' || c == ']')
			assert_true(--depth >= 0);
	}
	assert_int_equal(depth, 0);
	assert_false(in_str);
	assert_int_equal(s[0], '{');
	assert_int_equal(s[len - 1], '}');
}

static void test_new_only(void **state)
{
	(void)state;
	double t = run(0.0, 2.0, 0.0, 3);
	struct frame_cursor c;
	frame_cursor_init(&c, &hist);
	size_t n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, sizeof buf);
	assert_true(n > 0);
	buf[n] = '\0';
	assert_whole(buf, n);
	/* the first frame: the whole history and the status */
	assert_int_equal(count_after(buf, "\"samples\":{\"t\":"), 2 * HIST_HZ);
	assert_non_null(strstr(buf, "\"status\":{\"robots\":[{\"name\":\"r1\",\"mode\":\"OSCILLATOR\""));
	assert_non_null(strstr(buf, "\"temperature\":33"));
	assert_non_null(strstr(buf, "\"pairs\":[{\"a\":\"r1\",\"b\":\"r2\""));
	/* a robot not heard for HIST_GAP_S: a gap (null), not its last angle again */
	hist_sample(&hist, &model, t + HIST_GAP_S + 0.01);
	struct frame_cursor gap = c;
	gap.sample = hist.next - 1;
	n = frame_write(&hist, &model, t, &gap, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_non_null(strstr(buf, "\"a\":[[null]"));
	c.sample = hist.next;
	/* nothing new: no samples, no status (every FRAME_STATUS_EVERY-th frame) */
	n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_whole(buf, n);
	assert_int_equal(count_after(buf, "\"samples\":{\"t\":"), 0);
	assert_null(strstr(buf, "\"status\""));
	/* three new samples: exactly those, per joint and per pair */
	t = run(t, 3.0 / HIST_HZ, 0.0, 3);
	n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_int_equal(count_after(buf, "\"samples\":{\"t\":"), 3);
	assert_int_equal(count_after(buf, "\"a\":["), 3);
	assert_int_equal(count_after(buf, "\"d\":"), 3);
	assert_int_equal(count_after(buf, "\"bound\":"), 3);
	/* the fifth frame (index FRAME_STATUS_EVERY) carries the status again */
	n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_null(strstr(buf, "\"status\""));
	n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_non_null(strstr(buf, "\"status\""));
}

/* a browser that fell behind by more than the ring starts at its oldest
 * sample; one whose frame does not fit gets the newest samples that do */
static void test_bounded(void **state)
{
	(void)state;
	struct frame_cursor c;
	frame_cursor_init(&c, &hist);
	double t = run(0.0, HIST_SECONDS + 5, 0.0, 3);
	size_t n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_int_equal(count_after(buf, "\"samples\":{\"t\":"), HIST_N);
	t = run(t, 10.0, 0.0, 3);
	size_t small = 8000;
	n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, small);
	assert_true(n > 0 && n < small);
	buf[n] = '\0';
	assert_whole(buf, n);
	int got = count_after(buf, "\"samples\":{\"t\":");
	assert_true(got > 0 && got < 10 * HIST_HZ);
	/* the last sample sent is the newest one */
	char last[32];
	snprintf(last, sizeof last, "%lld]", (long long)hist.t_ms[hist_slot(hist.next - 1)]);
	assert_non_null(strstr(buf, last));
	assert_int_equal(c.sample, hist.next);
	/* not even an empty frame fits: 0, the cursor stays */
	uint64_t before = c.sample;
	t = run(t, 1.0, 0.0, 3);
	assert_int_equal(frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, 20), 0);
	assert_int_equal(c.sample, before);
}

static const char *pair_class(void)
{
	return hist.pairs[hist.pair_of[0]].cls;
}

/* the end state over the last 10 s, by undulate-analyze's rules */
static void test_classes(void **state)
{
	(void)state;
	double t = run(0.0, 12.0, 0.05, 3);
	assert_string_equal(pair_class(), "in-phase");
	/* anti-phase, locked */
	t = run(t, 12.0, M_PI, 3);
	assert_string_equal(pair_class(), "anti-phase");
	/* locked at 1 rad without a simulator: no contact data to call it compatible */
	t = run(t, 12.0, 1.0, 3);
	assert_string_equal(pair_class(), "locked-no-contact-data");
	/* with collisions of the pair in the window (heard on SIM.COLLISION) */
	hist_on_collision(&hist, &model, "r2", "r1", t);
	t = run(t, 12.0 / HIST_HZ, 1.0, 3);
	assert_string_equal(pair_class(), "still-colliding");
	/* a robot that stops swinging */
	for (int i = 0; i < 12 * HIST_HZ; i++, t += 1.0 / HIST_HZ) {
		feed("r1", t, 0, 3);
		feed("r2", t, 1.0, 3);
		hist_sample(&hist, &model, t);
	}
	assert_string_equal(pair_class(), "not-oscillating");
}

static void test_marks_and_notes(void **state)
{
	(void)state;
	struct frame_cursor c;
	frame_cursor_init(&c, &hist);
	double t = run(0.0, 1.0, 0.0, 2);
	size_t n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	/* a robot's first mode is no switch */
	assert_non_null(strstr(buf, "\"marks\":[]"));
	t = run(t, 1.0, 0.0, 3);
	struct frame_note note = { .seq = 17, .robot = "r2", .kind = "command-accepted", .text = "mode \"OSC\"" };
	n = frame_write(&hist, &model, t, &c, NULL, &note, 1, buf, sizeof buf);
	buf[n] = '\0';
	assert_whole(buf, n);
	assert_non_null(strstr(buf, "\"robot\":\"r2\",\"mode\":\"OSCILLATOR\"}]"));
	assert_non_null(strstr(buf, "\"notes\":[{\"id\":0,\"seq\":17,\"robot\":\"r2\",\"kind\":\"command-accepted\","
	                            "\"text\":\"mode \\\"OSC\\\"\"}]"));
	/* once sent, a mark is not sent again */
	n = frame_write(&hist, &model, t, &c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_non_null(strstr(buf, "\"marks\":[]"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup(test_new_only, setup),
		cmocka_unit_test_setup(test_bounded, setup),
		cmocka_unit_test_setup(test_classes, setup),
		cmocka_unit_test_setup(test_marks_and_notes, setup),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
