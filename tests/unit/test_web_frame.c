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

/* ms after the history's start, as frames write times */
static int64_t hist_ms_of(double now)
{
	return llround((now - hist.t0) * 1000.0);
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

/* One SIM.TRUTH of the plane: robots w0 and w1, three links each (link k of
 * robot i at x = i, y = k / 10), a wall, and the contacts given. */
static void world_truth(double now, undulate_sim_contact_t *contacts, int ncontacts, double x0)
{
	static char names[2][8] = { "w0", "w1" };
	undulate_sim_body_t bodies[2] = { { .robot = names[0], .servo_id = 1, .neutral = 0, .lateral = 0.01 },
					  { .robot = names[1], .servo_id = 1, .neutral = 0.2, .lateral = 0.21 } };
	undulate_sim_link_t links[6];
	for (int i = 0; i < 6; i++)
		links[i] = (undulate_sim_link_t){ .robot = (int16_t)(i / 3), .link = (int8_t)(i % 3),
			.x = i / 3 + (i == 0 ? x0 : 0), .y = (i % 3) / 10.0, .angle = M_PI / 2, .length = 0.1865,
			.width = 0.032 };
	undulate_sim_wall_t wall = { -1, -0.32, -1, 0.32 };
	undulate_sim_truth_t t = { .world = UNDULATE_SIM_TRUTH_T_WORLD_PLANE, .wall_left = -1, .wall_right = 1,
		.nbodies = 2, .bodies = bodies, .nlinks = 6, .links = links, .nwalls = 1, .walls = &wall,
		.ncontacts = ncontacts, .contacts = contacts, .total_impulse = 1 };
	top_on_truth(&model, &t, now);
	wct_add(&hist.contacts, &model);
}

static size_t frame_of(struct frame_cursor *c, double now)
{
	size_t n = frame_write(&hist, &model, now, c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_whole(buf, n);
	return n;
}

/* The world goes to a browser when there is something new to draw: every
 * robot's links, the walls, and the contacts summed per pair between two
 * frames, each mark once; none without a simulator. */
static void test_world(void **state)
{
	(void)state;
	struct frame_cursor c;
	frame_cursor_init(&c, &hist);
	double t = run(0.0, 1.0, 0.0, 3);
	frame_of(&c, t);
	assert_null(strstr(buf, "\"world\""));                 /* no simulator heard */
	/* one pair touching in two messages: one mark, impulses summed, forces averaged */
	undulate_sim_contact_t touch = { .robot_a = 0, .link_a = 2, .robot_b = 1, .link_b = 0, .x = 0.5, .y = 0.25,
		.nx = 1, .impulse = 0.01, .force = 1.0, .impact = 0 };
	world_truth(t, &touch, 1, 0);
	touch.x = 0.55;
	touch.force = 3.0;
	touch.impact = 1;
	world_truth(t + 0.01, &touch, 1, 0);
	undulate_sim_contact_t wall = { .robot_a = 1, .link_a = 1, .robot_b = -1, .link_b = 0, .x = -1, .y = 0.1,
		.impulse = 0.004, .force = 0.4 };
	world_truth(t + 0.02, &wall, 1, 0);
	hist_sample(&hist, &model, t + 0.04);
	hist_close_contacts(&hist, t + 0.04);
	frame_of(&c, t + 0.04);
	assert_non_null(strstr(buf, "\"world\":{\"kind\":\"plane\",\"wall_left\":-1,\"wall_right\":1,"
	                            "\"walls\":[[-1,-0.32,-1,0.32]]"));
	/* every robot of the model, in the order first heard: r1, r2 (no body, no links), then w0, w1 */
	assert_non_null(strstr(buf, "{\"name\":\"r1\",\"lateral\":null,\"neutral\":null,\"links\":[]}"));
	assert_non_null(strstr(buf, "{\"name\":\"w1\",\"lateral\":0.21,\"neutral\":0.2,\"links\":"
	                            "[[1,0,1.5708,0.1865,0.032],[1,0.1,1.5708,0.1865,0.032],[1,0.2,1.5708,0.1865,0.032]]}"));
	int w0 = top_robot_index(&model, "w0"), w1 = top_robot_index(&model, "w1");
	char want[256];
	snprintf(want, sizeof want, "\"contacts\":{\"t\":[%lld,%lld],\"a\":[%d,%d],\"b\":[%d,-1],\"x\":[0.55,-1],"
	         "\"y\":[0.25,0.1],\"f\":[2,0.4],\"imp\":[0.02,0.004],\"impact\":[1,0]}",
	         (long long)hist_ms_of(t + 0.04), (long long)hist_ms_of(t + 0.04), w0, w1, w1);
	if (strstr(buf, want) == NULL)
		fail_msg("want %s in %s", want, strstr(buf, "\"contacts\""));
	/* nothing new: no world; a new SIM.TRUTH: the world, without the marks already sent */
	frame_of(&c, t + 0.05);
	assert_null(strstr(buf, "\"world\""));
	world_truth(t + 0.06, NULL, 0, 0.5);
	hist_close_contacts(&hist, t + 0.08);
	frame_of(&c, t + 0.08);
	assert_non_null(strstr(buf, "\"links\":[[0.5,0,"));
	assert_non_null(strstr(buf, "\"contacts\":{\"t\":[],"));
	/* a browser that comes later gets the marks it can still see, not older ones */
	struct frame_cursor late;
	frame_cursor_init(&late, &hist);
	frame_of(&late, t + 0.08 + WCT_SHOW_S - 0.1);
	assert_int_equal(count_after(buf, "\"contacts\":{\"t\":"), 2);
	frame_cursor_init(&late, &hist);
	frame_of(&late, t + 0.08 + WCT_SHOW_S + 0.1);
	assert_int_equal(count_after(buf, "\"contacts\":{\"t\":"), 0);
}

/* What the network sends that no drawing can use never reaches the page: a
 * link at NaN or inf, a contact naming a robot the message does not hold;
 * they are counted in the status's world_refused. More pairs between two
 * frames than are summed: counted, the frame stays whole. */
static void test_world_hostile(void **state)
{
	(void)state;
	struct frame_cursor c;
	frame_cursor_init(&c, &hist);
	double t = run(0.0, 0.2, 0.0, 3);
	static char names[2][8] = { "h0", "h1" };
	undulate_sim_body_t bodies[2] = { { .robot = names[0], .servo_id = 1 }, { .robot = names[1], .servo_id = 1 } };
	undulate_sim_link_t links[3] = {
		{ .robot = 0, .link = 0, .x = NAN, .y = 0, .length = 0.1, .width = 0.01 },
		{ .robot = 1, .link = 1, .x = 0.3, .y = INFINITY, .length = 0.1, .width = 0.01 },
		{ .robot = 1, .link = 2, .x = 0.3, .y = 0.1, .angle = -INFINITY, .length = 0.1, .width = 0.01 },
	};
	static undulate_sim_contact_t many[WCT_PENDING + 4];
	for (int i = 0; i < WCT_PENDING + 4; i++)   /* pairs of walls 0..: distinct, then more than summed */
		many[i] = (undulate_sim_contact_t){ .robot_a = 0, .robot_b = -1, .link_b = (int8_t)(i % 100),
			.link_a = (int8_t)(i / 100), .x = 0.1, .y = 0.1, .force = 1, .impulse = 0.01 };
	many[0].robot_a = 2;
	many[1].x = NAN;
	undulate_sim_truth_t tr = { .world = UNDULATE_SIM_TRUTH_T_WORLD_PLANE, .nbodies = 2, .bodies = bodies,
		.nlinks = 3, .links = links, .nwalls = 100, .walls = NULL, .ncontacts = WCT_PENDING + 4,
		.contacts = many, .wall_left = NAN, .wall_right = INFINITY };
	/* nwalls 100 with no walls: a wall index the contacts may name, no segment read */
	undulate_sim_wall_t walls[100];
	for (int i = 0; i < 100; i++)
		walls[i] = (undulate_sim_wall_t){ 0, 0, 0.1, 0.1 };
	tr.walls = walls;
	top_on_truth(&model, &tr, t);
	wct_add(&hist.contacts, &model);
	wct_add(&hist.contacts, &model);
	hist_close_contacts(&hist, t);
	frame_of(&c, t);
	assert_non_null(strstr(buf, "\"world\":{\"kind\":\"plane\",\"wall_left\":null,\"wall_right\":null,"));
	assert_non_null(strstr(buf, "{\"name\":\"h0\",\"lateral\":0,\"neutral\":0,\"links\":[]}"));
	assert_non_null(strstr(buf, "{\"name\":\"h1\",\"lateral\":0,\"neutral\":0,\"links\":[]}"));
	/* 84 of 100 walls overflow; contacts 0 (a robot beyond) and 1 (NaN); of the
	 * rest TOP_WORLD_CONTACTS kept, two over; WCT_PENDING pairs summed */
	assert_int_equal(model.world.bad_index, 1);
	assert_int_equal(model.world.bad_number, 3 + 1 + 1);
	assert_int_equal(model.world.overflow, 100 - TOP_WORLD_WALLS + 2);
	assert_int_equal(count_after(buf, "\"contacts\":{\"t\":"), TOP_WORLD_CONTACTS);
	assert_null(strstr(buf, "nan"));
	assert_null(strstr(buf, "inf"));
	char want[160];
	snprintf(want, sizeof want, "\"world_refused\":{\"index\":1,\"number\":5,\"overflow\":%d,\"marks\":0}",
	         100 - TOP_WORLD_WALLS + 2);
	assert_non_null(strstr(buf, want));
	/* another message's pairs, all new, while WCT_PENDING are summed already: counted */
	for (int i = 1; i < WCT_PENDING + 4; i++)
		many[i].robot_a = 1;   /* h1's: other pairs */
	top_on_truth(&model, &tr, t + 0.01);
	wct_add(&hist.contacts, &model);
	wct_add(&hist.contacts, &model);
	hist_close_contacts(&hist, t + 0.02);
	assert_int_equal(hist.contacts.overflow, 0);
	top_on_truth(&model, &tr, t + 0.03);
	wct_add(&hist.contacts, &model);
	for (int i = 1; i < WCT_PENDING + 4; i++)
		many[i].robot_a = 0;
	top_on_truth(&model, &tr, t + 0.04);
	wct_add(&hist.contacts, &model);
	assert_int_equal(hist.contacts.overflow, TOP_WORLD_CONTACTS);
	hist_close_contacts(&hist, t + 0.04);
	for (int i = 0; i < FRAME_STATUS_EVERY; i++)
		frame_of(&c, t + 0.04);
	assert_non_null(strstr(buf, "\"marks\":256}"));
}

/* The simulator's per-second bins: three arrays of the same bins, oldest
 * first; past HIST_BINS the ring has overwritten the oldest, and a frame
 * starts at the oldest still held, across the ring's end. */
static void test_bins(void **state)
{
	(void)state;
	hist.nbins = HIST_BINS + 2;    /* bins 2 .. HIST_BINS + 1 held: slots 2 .. end, then 0, 1 */
	for (uint64_t i = 2; i < hist.nbins; i++) {
		int s = (int)(i % HIST_BINS);
		hist.bin_t_ms[s] = (int64_t)i * 1000;
		hist.bin_coll[s] = (int32_t)(i % 7);
		hist.bin_force[s] = (float)i * 0.5f;
	}
	struct frame_cursor c;
	frame_cursor_init(&c, &hist);
	c.bin = 0;
	size_t n = frame_write(&hist, &model, 1.0, &c, NULL, NULL, 0, buf, sizeof buf);
	assert_true(n > 0);
	buf[n] = '\0';
	assert_whole(buf, n);
	assert_int_equal(count_after(buf, "\"bins\":{\"t\":"), HIST_BINS);
	assert_non_null(strstr(buf, "\"bins\":{\"t\":[2000,3000,4000,"));
	assert_non_null(strstr(buf, ",300000,301000],\"coll\":[2,3,4,5,6,0,1,"));
	assert_non_null(strstr(buf, ",6,0],\"force\":[1,1.5,2,2.5,"));
	assert_non_null(strstr(buf, ",150,150.5]}"));
	/* a cursor past them: three empty arrays */
	c.bin = hist.nbins;
	n = frame_write(&hist, &model, 1.0, &c, NULL, NULL, 0, buf, sizeof buf);
	buf[n] = '\0';
	assert_non_null(strstr(buf, "\"bins\":{\"t\":[],\"coll\":[],\"force\":[]}"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup(test_new_only, setup),
		cmocka_unit_test_setup(test_bounded, setup),
		cmocka_unit_test_setup(test_classes, setup),
		cmocka_unit_test_setup(test_marks_and_notes, setup),
		cmocka_unit_test_setup(test_world, setup),
		cmocka_unit_test_setup(test_world_hostile, setup),
		cmocka_unit_test_setup(test_bins, setup),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
