/* test_common_lcmdec.c — every undulate message decoded the way our programs
 * decode what anyone on the LCM group may send (compat/lcm/lcmdec.h):
 * valid messages of every type round-trip; every array count that lies
 * (0x7fffffff, 0x20000001, 200000, -1, -2^31, one more than the payload
 * holds) is refused without a crash; every truncation of a message whose
 * strings and arrays were partly allocated is refused and frees them (the heap
 * in use is the same after 2000 failed decodes); trailing bytes, messages
 * longer than their type's maximum, strings without their NUL; the largest
 * honest messages still fit the allocation budget. LCM 1.3.1's own decoder
 * crashes on the first lie (0x7fffffff: NULL written; 0x20000001: read past
 * the end) and leaks on the third. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <limits.h>
#include <malloc.h>
#include <stdlib.h>
#include <string.h>

#include "compat/lcm/lcmdec.h"

static const int32_t lies[] = { 0x7fffffff, 0x20000001, 200000, -1, INT32_MIN };

/* Encodes a two-joint state; returns its length, *count_at the offset of njoints. */
static int make_state(uint8_t *buf, int cap, int njoints, size_t *count_at)
{
	undulate_joint_state_t joints[64];
	memset(joints, 0, sizeof joints);
	for (int j = 0; j < njoints; j++) {
		joints[j].servo_id = (int16_t)(j + 1);
		joints[j].angle = 0.25 * j;
	}
	char robot[] = "r1", reason[] = "start", fault[] = "";
	undulate_robot_state_t m = { .utime = 1, .robot = robot, .cycle = 7, .mode = 3, .mode_reason = reason,
				     .fault = fault, .njoints = njoints, .joints = joints };
	int n = undulate_robot_state_t_encode(buf, 0, cap, &m);
	/* njoints is the last fixed field before the joints */
	*count_at = (size_t)(n - njoints * __undulate_joint_state_t_encoded_array_size(joints, 1) - 4);
	return n;
}

static void put_be32(uint8_t *p, int32_t v)
{
	uint32_t u = (uint32_t)v;
	p[0] = (uint8_t)(u >> 24);
	p[1] = (uint8_t)(u >> 16);
	p[2] = (uint8_t)(u >> 8);
	p[3] = (uint8_t)u;
}

static size_t heap_in_use(void)
{
	struct mallinfo2 mi = mallinfo2();
	return mi.uordblks;
}

static void test_state_round_trip(void **state)
{
	(void)state;
	uint8_t buf[4096];
	size_t at;
	int n = make_state(buf, sizeof buf, 2, &at);
	undulate_robot_state_t m;
	assert_int_equal(lcmdec_decode(&lcmdec_robot_state_t, buf, (size_t)n, &m), LCMDEC_OK);
	assert_string_equal(m.robot, "r1");
	assert_string_equal(m.mode_reason, "start");
	assert_int_equal(m.njoints, 2);
	assert_int_equal(m.joints[1].servo_id, 2);
	assert_true(m.joints[1].angle == 0.25);
	lcmdec_free(&lcmdec_robot_state_t, &m);
	assert_null(m.joints);
}

static void test_state_lying_counts(void **state)
{
	(void)state;
	uint8_t buf[4096];
	size_t at;
	int n = make_state(buf, sizeof buf, 2, &at);
	for (size_t i = 0; i <= sizeof lies / sizeof lies[0]; i++) {
		uint8_t bad[4096];
		memcpy(bad, buf, (size_t)n);
		put_be32(bad + at, i < sizeof lies / sizeof lies[0] ? lies[i] : 3);
		undulate_robot_state_t m;
		memset(&m, 0x5a, sizeof m);
		enum lcmdec_status s = lcmdec_decode(&lcmdec_robot_state_t, bad, (size_t)n, &m);
		assert_int_not_equal(s, LCMDEC_OK);
		/* nothing left to free, nothing that looks decoded */
		assert_null(m.robot);
		assert_null(m.joints);
		assert_int_equal(m.njoints, 0);
	}
}

/* osc_params_t: nine double arrays of njoints; 8 x 0x20000001 wraps to 8 in
 * LCM's int size check */
static void test_params_wrapping_count(void **state)
{
	(void)state;
	double v[2] = { 0.5, 0.5 };
	char robot[] = "r1";
	undulate_osc_params_t p = { .utime = 1, .robot = robot, .njoints = 2, .k = v, .c = v, .mu = v, .lambda = v,
				    .inertia = v, .friction = v, .neutral = v, .limit_min = v, .limit_max = v };
	uint8_t buf[1024];
	int n = undulate_osc_params_t_encode(buf, 0, sizeof buf, &p);
	undulate_osc_params_t m;
	assert_int_equal(lcmdec_decode(&lcmdec_osc_params_t, buf, (size_t)n, &m), LCMDEC_OK);
	assert_true(m.limit_max[1] == 0.5);
	lcmdec_free(&lcmdec_osc_params_t, &m);
	size_t at = 8 + 8 + 4 + 3; /* fingerprint, utime, "r1" */
	for (size_t i = 0; i < sizeof lies / sizeof lies[0]; i++) {
		put_be32(buf + at, lies[i]);
		assert_int_not_equal(lcmdec_decode(&lcmdec_osc_params_t, buf, (size_t)n, &m), LCMDEC_OK);
		assert_null(m.k);
	}
}

/* SIM.TRUTH: bodies with strings, then collisions with two strings each: a
 * cut anywhere leaves strings and arrays allocated that must be freed */
static int make_truth(uint8_t *buf, int cap, int nb, int nc)
{
	static undulate_sim_body_t bodies[1000];
	static undulate_sim_collision_t coll[1000];
	static char name[] = "robot-with-a-name";
	for (int i = 0; i < nb; i++)
		bodies[i] = (undulate_sim_body_t){ .robot = name, .servo_id = 1, .lateral = i };
	for (int i = 0; i < nc; i++)
		coll[i] = (undulate_sim_collision_t){ .left = i, .right = i + 1, .left_robot = name, .right_robot = name };
	undulate_sim_truth_t t = { .utime = 1, .nbodies = nb, .bodies = bodies, .ncollisions = nc, .collisions = coll };
	return undulate_sim_truth_t_encode(buf, 0, cap, &t);
}

static void test_truncations_free_everything(void **state)
{
	(void)state;
	static uint8_t buf[8192];
	int n = make_truth(buf, sizeof buf, 10, 10);
	assert_true(n > 0);
	undulate_sim_truth_t m;
	/* warm up malloc's own bookkeeping, then measure */
	assert_int_equal(lcmdec_decode(&lcmdec_sim_truth_t, buf, (size_t)n, &m), LCMDEC_OK);
	assert_int_equal(m.ncollisions, 10);
	assert_string_equal(m.collisions[9].right_robot, "robot-with-a-name");
	lcmdec_free(&lcmdec_sim_truth_t, &m);
	size_t before = 0;
	int refused = 0;
	/* the first round fills malloc's per-thread caches (which mallinfo2
	 * counts as in use); a leak would grow with every round after it */
	for (int round = 0; round < 4; round++) {
		if (round == 1)
			before = heap_in_use();
		for (int len = 0; len < n; len++) {
			if (lcmdec_decode(&lcmdec_sim_truth_t, buf, (size_t)len, &m) != LCMDEC_OK)
				refused++;
			else
				lcmdec_free(&lcmdec_sim_truth_t, &m);
		}
	}
	assert_int_equal(refused, 4 * n);
	assert_int_equal(heap_in_use(), before);
}

static void test_lies_do_not_leak(void **state)
{
	(void)state;
	uint8_t buf[4096];
	size_t at;
	int n = make_state(buf, sizeof buf, 2, &at);
	put_be32(buf + at, 200000);
	undulate_robot_state_t m;
	size_t before = heap_in_use();
	for (int i = 0; i < 2000; i++)
		assert_int_not_equal(lcmdec_decode(&lcmdec_robot_state_t, buf, (size_t)n, &m), LCMDEC_OK);
	assert_int_equal(heap_in_use(), before);
}

static void test_trailing_long_and_strings(void **state)
{
	(void)state;
	static uint8_t buf[LCMDEC_MAX_ROBOT + 16];
	size_t at;
	int n = make_state(buf, sizeof buf, 2, &at);
	undulate_robot_state_t m;
	buf[n] = 0;
	assert_int_equal(lcmdec_decode(&lcmdec_robot_state_t, buf, (size_t)n + 1, &m), LCMDEC_TRAILING);
	assert_null(m.robot);
	assert_int_equal(lcmdec_decode(&lcmdec_robot_state_t, buf, LCMDEC_MAX_ROBOT + 1, &m), LCMDEC_TOO_LONG);
	/* the robot name's length (after fingerprint and utime): 0, negative, past the end, no NUL */
	const int32_t bad_len[] = { 0, -1, INT32_MIN, 0x7fffffff, n };
	for (size_t i = 0; i < sizeof bad_len / sizeof bad_len[0]; i++) {
		uint8_t b[4096];
		memcpy(b, buf, (size_t)n);
		put_be32(b + 16, bad_len[i]);
		assert_int_equal(lcmdec_decode(&lcmdec_robot_state_t, b, (size_t)n, &m), LCMDEC_MALFORMED);
	}
	uint8_t b[4096];
	memcpy(b, buf, (size_t)n);
	b[16 + 4 + 2] = 'x'; /* "r1" loses its NUL */
	assert_int_equal(lcmdec_decode(&lcmdec_robot_state_t, b, (size_t)n, &m), LCMDEC_MALFORMED);
	/* another type's fingerprint */
	undulate_bus_stats_t other;
	assert_int_equal(lcmdec_decode(&lcmdec_bus_stats_t, buf, (size_t)n, &other), LCMDEC_MALFORMED);
	char why[160];
	lcmdec_describe(why, sizeof why, &lcmdec_robot_state_t, 293, LCMDEC_OVER_BUDGET);
	assert_string_equal(why, "robot_state_t: 293 bytes do not decode (an array count larger than the message could hold)");
}

/* the largest honest messages stay inside the budget and the maxima */
static void test_largest_honest(void **state)
{
	(void)state;
	static uint8_t buf[LCMDEC_MAX_SIM];
	size_t at;
	int n = make_state(buf, sizeof buf, 64, &at);
	undulate_robot_state_t s;
	assert_int_equal(lcmdec_decode(&lcmdec_robot_state_t, buf, (size_t)n, &s), LCMDEC_OK);
	assert_int_equal(s.njoints, 64);
	lcmdec_free(&lcmdec_robot_state_t, &s);
	n = make_truth(buf, sizeof buf, 1000, 1000);
	assert_true(n > 0 && (size_t)n <= LCMDEC_MAX_SIM);
	undulate_sim_truth_t t;
	assert_int_equal(lcmdec_decode(&lcmdec_sim_truth_t, buf, (size_t)n, &t), LCMDEC_OK);
	assert_int_equal(t.nbodies, 1000);
	assert_int_equal(t.ncollisions, 1000);
	lcmdec_free(&lcmdec_sim_truth_t, &t);
}

/* random bytes, half of them after a valid state's first half: never a
 * crash (the ASan build: no overread), refusals leave nothing allocated */
static void test_random_payloads(void **state)
{
	(void)state;
	const struct lcmdec_type *types[] = { &lcmdec_robot_state_t, &lcmdec_bus_stats_t, &lcmdec_osc_params_t,
					      &lcmdec_event_t, &lcmdec_command_t, &lcmdec_sim_truth_t,
					      &lcmdec_sim_collision_t, &lcmdec_sim_world_t, &lcmdec_sim_command_t,
					      &lcmdec_sim_reply_t };
	uint8_t valid[4096];
	size_t at;
	int n = make_state(valid, sizeof valid, 2, &at);
	srand(7);
	size_t before = 0;
	for (int i = 0; i < 40000; i++) {
		if (i == 20000) /* after a first half that fills malloc's caches */
			before = heap_in_use();
		uint8_t b[512];
		size_t len = (size_t)(rand() % (int)sizeof b);
		for (size_t k = 0; k < len; k++)
			b[k] = (uint8_t)rand();
		/* half of them start as a real state, with random bytes after */
		if (i % 2 == 0 && len > 8)
			memcpy(b, valid, len < (size_t)n ? len / 2 : (size_t)n / 2);
		union {
			undulate_robot_state_t s;
			undulate_sim_truth_t t;
			undulate_bus_stats_t b;
			undulate_osc_params_t p;
			undulate_command_t c;
		} u;
		const struct lcmdec_type *t = types[i % (sizeof types / sizeof types[0])];
		if (lcmdec_decode(t, b, len, &u) == LCMDEC_OK)
			lcmdec_free(t, &u);
	}
	/* random sizes leave malloc's caches a little different (valgrind and the
	 * ASan build see no leak): a leak of even one small string per refused
	 * message would be 20000 x 32 bytes */
	assert_true(heap_in_use() < before + 4096);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_state_round_trip),
		cmocka_unit_test(test_state_lying_counts),
		cmocka_unit_test(test_params_wrapping_count),
		cmocka_unit_test(test_truncations_free_everything),
		cmocka_unit_test(test_lies_do_not_leak),
		cmocka_unit_test(test_trailing_long_and_strings),
		cmocka_unit_test(test_largest_honest),
		cmocka_unit_test(test_random_payloads),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
