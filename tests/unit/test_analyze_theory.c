/* test_analyze_theory.c — the theory's numbers the figures put beside the
 * runs (tools/analyze/theory.c), against theory.md's formulas and their
 * known values: d~_c = 0.316 at r = 0.67 and 0.21 at r = 0.9, f'(pi) = -1
 * at d~_c, the d~ = 0 closed form against iterating the map. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "phase.h"
#include "../../tools/analyze/theory.h"

static void test_critical_separation(void **state)
{
	(void)state;
	/* theory.md and the paper: 0.316 for the rig's r = 0.67, 0.21 at r = 0.9 */
	assert_true(fabs(theory_critical_dsep(0.67) - 0.316) < 0.0005);
	assert_true(fabs(theory_critical_dsep(0.9) - 0.21) < 0.005);
	/* elastic: anti-phase stable at any separation */
	assert_true(fabs(theory_critical_dsep(1.0)) < 1e-12);
	assert_true(isnan(theory_critical_dsep(0.0)));
	assert_true(isnan(theory_critical_dsep(1.2)));
	assert_true(isnan(theory_critical_dsep(NAN)));
}

static void test_antiphase_slope(void **state)
{
	(void)state;
	/* docs/EXPERIMENTS.md's values at r = 0.67 */
	assert_true(fabs(theory_antiphase_slope(0.5, 0.67) + 0.43) < 0.005);
	assert_true(fabs(theory_antiphase_slope(0.2, 0.67) + 1.28) < 0.005);
	/* -1 at d~_c for every r: where anti-phase changes stability */
	for (double r = 0.1; r <= 1.0; r += 0.1) {
		double dc = theory_critical_dsep(r);
		assert_true(fabs(theory_antiphase_slope(dc, r) + 1.0) < 1e-9);
		if (dc > 0.01)
			assert_true(fabs(theory_antiphase_slope(dc - 0.01, r)) > 1.0);
		assert_true(fabs(theory_antiphase_slope(dc + 0.01, r)) < 1.0);
	}
	/* d~ = 0: the map's slope there is -1/r (f(x) = -2 atan(r tan(x/2))) */
	assert_true(fabs(theory_antiphase_slope(0.0, 0.67) + 1.0 / 0.67) < 1e-12);
	/* the same slope, measured on the map itself */
	for (double ds = 0.05; ds < 1.0; ds += 0.1) {
		double h = 1e-5;
		double measured = phase_wrap(theory_return_map(M_PI - h, ds, 0.9) - theory_return_map(M_PI, ds, 0.9)) / -h;
		assert_true(fabs(measured - theory_antiphase_slope(ds, 0.9)) < 1e-3);
	}
	assert_true(isnan(theory_antiphase_slope(1.1, 0.67)));
	assert_true(isnan(theory_antiphase_slope(0.5, 0.0)));
}

static void test_d0_closed_form_iterated(void **state)
{
	(void)state;
	for (double r = 0.3; r <= 1.0; r += 0.35)
		for (double d0 = -3.0; d0 <= 3.0; d0 += 0.5) {
			if (fabs(d0) < 1e-12)
				continue; /* in phase already: no step (below) */
			for (int n = 0; n <= 15; n++) {
				int k = -1;
				double it = theory_iterate(d0, 0.0, r, n, &k);
				assert_int_equal(k, n);
				assert_true(fabs(it - theory_return_map_d0(d0, r, n)) < 1e-9);
			}
		}
	int k = -1;
	assert_true(theory_iterate(0.0, 0.0, 0.67, 10, &k) == 0.0);
	assert_int_equal(k, 0);
}

static void test_third_fixed_point(void **state)
{
	(void)state;
	double r = 0.67, dc = theory_critical_dsep(r);
	/* below d~_c there is none: anti-phase repels, every pair ends compatible */
	for (double ds = 0.0; ds < dc - 0.005; ds += 0.05)
		assert_true(isnan(theory_third_fixed_point(ds, r)));
	/* Found numerically (r = 0.3, 0.5, 0.67, 0.9): from d~ = 0.5 on it stays
	 * at 2 atan(1/sqrt(r)), whatever d~, until the compatibility limit
	 * passes it at d~ = 1/sqrt(1 + r); beyond, every pair that touches
	 * goes to anti-phase. */
	double plateau = 2.0 * atan(1.0 / sqrt(r)), last = 1.0 / sqrt(1.0 + r);
	for (double ds = 0.5; ds < last - 0.005; ds += 0.05)
		assert_true(fabs(theory_third_fixed_point(ds, r) - plateau) < 1e-6);
	for (double ds = last + 0.005; ds <= 1.0; ds += 0.05) {
		assert_true(isnan(theory_third_fixed_point(ds, r)));
		assert_true(M_PI - fabs(theory_iterate(theory_compat_limit(ds) + 0.01, ds, r, 100000, NULL)) < 1e-6);
	}
	double prev = M_PI;
	for (double ds = dc + 0.005; ds < last - 0.005; ds += 0.05) {
		double x = theory_third_fixed_point(ds, r);
		assert_false(isnan(x));
		assert_true(x > theory_compat_limit(ds) && x < M_PI);
		/* a collision keeps its size */
		assert_true(fabs(fabs(theory_return_map(x, ds, r)) - x) < 1e-7);
		/* it bounds the basins: above it anti-phase, below it compatible */
		double above = theory_iterate(x + 0.02, ds, r, 10000, NULL);
		double below = theory_iterate(x - 0.02, ds, r, 10000, NULL);
		assert_true(M_PI - fabs(above) < 1e-6);
		assert_true(fabs(below) <= theory_compat_limit(ds) + 1e-6);
		/* it moves away from pi as d~ grows (the anti-phase basin widens) */
		assert_true(x < prev + 1e-9);
		prev = x;
	}
	/* just above d~_c it sits next to pi */
	assert_true(theory_third_fixed_point(dc + 0.002, r) > 2.9);
	assert_true(isnan(theory_third_fixed_point(1.0, r)));
}

static void test_iterate_ends(void **state)
{
	(void)state;
	int n = -1;
	/* inside the compatible set: no collision at all */
	assert_true(theory_iterate(1.0, 0.7, 0.67, 100, &n) == 1.0);
	assert_int_equal(n, 0);
	/* at the limit: one grazing collision, nothing changes */
	double g = theory_compat_limit(0.7);
	assert_true(fabs(theory_iterate(g, 0.7, 0.67, 100, &n) - g) < 1e-9);
	assert_int_equal(n, 1);
	/* anti-phase above d~_c from near pi */
	assert_true(M_PI - fabs(theory_iterate(3.0, 0.7, 0.67, 10000, &n)) < 1e-6);
	assert_true(n > 1 && n < 10000);
	/* below d~_c the pair leaves pi for the compatible set */
	double end = theory_iterate(3.1, 0.2, 0.67, 10000, &n);
	assert_true(fabs(end) <= theory_compat_limit(0.2) + 1e-9);
	/* max_n bounds the work */
	theory_iterate(3.1, 0.2, 0.67, 3, &n);
	assert_int_equal(n, 3);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_critical_separation),
		cmocka_unit_test(test_antiphase_slope),
		cmocka_unit_test(test_d0_closed_form_iterated),
		cmocka_unit_test(test_third_fixed_point),
		cmocka_unit_test(test_iterate_ends),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
