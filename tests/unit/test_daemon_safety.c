/* test_daemon_safety.c — the clamp every goal passes: limits (configured and
 * the servo's), the per-cycle step bound, non-finite input; plus a randomized
 * property loop: whatever goes in, what comes out is finite and inside. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "../../daemon/safety.h"
#include "dxl_table.h"

static void test_limits_intersection(void **state)
{
	(void)state;
	struct safety_limits l;
	/* configured ±1.3 around 0, servo full range: configured wins */
	assert_true(safety_limits_make(&l, 0.0, -1.3, 1.3, 0, 1023, 0.1));
	assert_true(fabs(l.lo + 1.3) < 1e-12 && fabs(l.hi - 1.3) < 1e-12);
	/* servo limits tighter (raw 400..600) win */
	assert_true(safety_limits_make(&l, 0.0, -1.3, 1.3, 400, 600, 0.1));
	assert_true(fabs(l.lo - dxl_pos_to_rad(400)) < 1e-12);
	assert_true(fabs(l.hi - dxl_pos_to_rad(600)) < 1e-12);
	/* the neutral shifts the configured window */
	assert_true(safety_limits_make(&l, 0.5, -0.2, 0.2, 0, 1023, 0.1));
	assert_true(fabs(l.lo - 0.3) < 1e-12 && fabs(l.hi - 0.7) < 1e-12);
	/* empty intersection, wheel mode, bad step: refused */
	assert_false(safety_limits_make(&l, 0.0, -0.1, 0.1, 700, 800, 0.1));
	assert_false(safety_limits_make(&l, 0.0, -1.0, 1.0, 0, 0, 0.1));
	assert_false(safety_limits_make(&l, 0.0, -1.0, 1.0, 0, 1023, 0.0));
	assert_false(safety_limits_make(&l, NAN, -1.0, 1.0, 0, 1023, 0.1));
}

static void test_clamp(void **state)
{
	(void)state;
	struct safety_limits l = { .lo = -1.0, .hi = 1.0, .max_step = 0.1 };
	unsigned f;
	assert_true(safety_clamp(&l, 0.55, 0.5, 0.5, &f) == 0.55);
	assert_int_equal(f, 0);
	/* step bound both ways */
	assert_true(fabs(safety_clamp(&l, 0.9, 0.5, 0.5, &f) - 0.6) < 1e-12);
	assert_int_equal(f, SAFETY_STEP);
	assert_true(fabs(safety_clamp(&l, -0.9, 0.5, 0.5, &f) - 0.4) < 1e-12);
	assert_int_equal(f, SAFETY_STEP);
	/* limits */
	assert_true(safety_clamp(&l, 1.05, 0.98, 0.98, &f) == 1.0);
	assert_int_equal(f, SAFETY_LIMIT);
	assert_true(safety_clamp(&l, -3.0, NAN, 0.0, &f) == -1.0);   /* no previous: no step bound */
	assert_int_equal(f, SAFETY_LIMIT);
	/* a previous goal outside (limits changed): limits still win */
	assert_true(safety_clamp(&l, 2.0, 1.5, 1.5, &f) == 1.0);
	/* non-finite desired: hold the fallback (measured) */
	assert_true(safety_clamp(&l, NAN, 0.3, 0.25, &f) == 0.25);
	assert_true(f & SAFETY_NONFINITE);
	assert_true(safety_clamp(&l, INFINITY, 0.3, NAN, &f) == 0.3);
	assert_true(f & SAFETY_NONFINITE);
	assert_true(safety_clamp(&l, -INFINITY, NAN, NAN, &f) == 0.0);  /* middle of the limits */
	assert_true(f & SAFETY_NONFINITE);
	assert_true(safety_clamp(&l, 0.1, 0.0, 0.0, NULL) == 0.1);
}

static double rnd_any(void)
{
	switch (rand() % 8) {
	case 0: return NAN;
	case 1: return INFINITY;
	case 2: return -INFINITY;
	case 3: return 1e300 * ((rand() & 1) ? 1 : -1);
	default: return ((double)rand() / RAND_MAX - 0.5) * 8.0;
	}
}

static void test_property(void **state)
{
	(void)state;
	srand(12345);
	for (int i = 0; i < 100000; i++) {
		struct safety_limits l;
		double n = ((double)rand() / RAND_MAX - 0.5) * 2.0;
		double lo = -(double)rand() / RAND_MAX * 1.5, hi = (double)rand() / RAND_MAX * 1.5;
		uint16_t cw = (uint16_t)(rand() % 512), ccw = (uint16_t)(512 + rand() % 512);
		if (!safety_limits_make(&l, n, lo, hi, cw, ccw, 0.01 + (double)rand() / RAND_MAX * 0.3))
			continue;
		double prev = rnd_any();
		double g = safety_clamp(&l, rnd_any(), prev, rnd_any(), NULL);
		assert_true(isfinite(g));
		assert_true(g >= l.lo && g <= l.hi);
		/* the raw value sent stays inside the servo's own limits */
		uint16_t raw = dxl_rad_to_pos(g);
		assert_true(raw >= cw && raw <= ccw);
		if (isfinite(prev) && prev >= l.lo && prev <= l.hi)
			assert_true(fabs(g - prev) <= l.max_step + 1e-12);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_limits_intersection),
		cmocka_unit_test(test_clamp),
		cmocka_unit_test(test_property),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
