/* test_analyze_phase.c — what the analyser computes on phases: the
 * final-window statistics (tools/analyze/window.c) and the contact theory's
 * return map (tools/analyze/theory.c). The phase itself and the frequency
 * estimator are common/phase.c's, tested in test_common_phase.c. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "../../tools/analyze/theory.h"
#include "../../tools/analyze/window.h"
#include "phase.h"

static void test_circ(void **state)
{
	(void)state;
	struct win_circ c = { 0 };
	assert_true(isnan(win_circ_mean(&c)));
	/* values straddling +-pi: the circular mean is pi, not 0 */
	win_circ_add(&c, M_PI - 0.1);
	win_circ_add(&c, -M_PI + 0.1);
	assert_true(fabs(fabs(win_circ_mean(&c)) - M_PI) < 1e-9);
	assert_true(fabs(win_circ_mean_abs(&c) - (M_PI - 0.1)) < 1e-9);
	assert_true(win_circ_spread(&c) > 0.09 && win_circ_spread(&c) < 0.11);
	struct win_circ d = { 0 };
	for (int i = 0; i < 10; i++)
		win_circ_add(&d, 0.5);
	assert_true(fabs(win_circ_spread(&d)) < 1e-6);
}

/* d~ = 0: the map iterated n times equals the closed form, and -> 0. */
/* Peak-to-peak of the angle: empty is NAN, bad samples do not count. */
static void test_swing(void **state)
{
	(void)state;
	struct win_swing s;
	win_swing_init(&s);
	assert_true(isnan(win_swing_pp(&s)));
	win_swing_add(&s, NAN);
	win_swing_add(&s, INFINITY);
	assert_true(isnan(win_swing_pp(&s)));
	win_swing_add(&s, 0.3);
	assert_true(win_swing_pp(&s) == 0.0); /* one sample: no swing */
	for (double t = 0; t < 5.0; t += 0.01)
		win_swing_add(&s, 0.3 + 0.8 * sin(2 * M_PI * 0.8 * t));
	win_swing_add(&s, -INFINITY);
	assert_true(fabs(win_swing_pp(&s) - 1.6) < 1e-3);
	/* all negative: the extremes are not anchored at 0 */
	win_swing_init(&s);
	win_swing_add(&s, -0.5);
	win_swing_add(&s, -0.7);
	assert_true(fabs(win_swing_pp(&s) - 0.2) < 1e-12);
}

static void test_return_map_d0(void **state)
{
	(void)state;
	double r = 0.67;
	for (double d0 = -3.0; d0 <= 3.0; d0 += 0.25) {
		double d = d0;
		assert_true(fabs(theory_return_map_d0(d0, r, 0) - d0) < 1e-12);
		for (int n = 1; n <= 12; n++) {
			d = theory_return_map(d, 0.0, r);
			assert_true(fabs(d - theory_return_map_d0(d0, r, n)) < 1e-9);
		}
		assert_true(fabs(d) < fabs(d0) + 1e-12);
	}
	/* slope -r at 0 */
	double h = 1e-6;
	assert_true(fabs(theory_return_map(h, 0.0, r) / h + r) < 1e-6);
}

/* Fixed points (theory.md): grazing at 2 asin(d~), anti-phase at pi with
 * slope -(r(d^2-1)+d^2)/(r^2(d^2-1)-d^2); no contact below 2 asin(d~). */
static void test_return_map_fixed_points(void **state)
{
	(void)state;
	double r = 0.67;
	for (double ds = 0.1; ds < 0.95; ds += 0.1) {
		double g = theory_compat_limit(ds);
		assert_true(fabs(g - 2 * asin(ds)) < 1e-12);
		assert_true(fabs(theory_return_map(g + 1e-9, ds, r) - g) < 1e-3);
		assert_true(isnan(theory_return_map(0.9 * g, ds, r)));
		assert_true(fabs(fabs(theory_return_map(M_PI, ds, r)) - M_PI) < 1e-9);
		double h = 1e-5;
		double slope = phase_wrap(theory_return_map(M_PI - h, ds, r) - theory_return_map(M_PI, ds, r)) / -h;
		double d2 = ds * ds;
		double theory = -(r * (d2 - 1) + d2) / (r * r * (d2 - 1) - d2);
		assert_true(fabs(slope - theory) < 1e-3);
	}
	/* antisymmetry: f(-x) = -f(x) */
	for (double x = 1.4; x < 3.1; x += 0.2)
		assert_true(fabs(theory_return_map(-x, 0.6, r) + theory_return_map(x, 0.6, r)) < 1e-9);
	assert_true(fabs(theory_compat_limit(1.5) - M_PI) < 1e-12);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_circ),
		cmocka_unit_test(test_swing),
		cmocka_unit_test(test_return_map_d0),
		cmocka_unit_test(test_return_map_fixed_points),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
