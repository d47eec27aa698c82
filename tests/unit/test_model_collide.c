/* test_model_collide.c — the model's impact rule (model/mdl_collide.h):
 * momentum kept exactly for two mobile bodies of equal mass, the relative
 * speed reversed and scaled by r, the energy of the relative motion scaled by
 * r^2 (the loss (1 - r^2)(v_l - v_r)^2 / 4), and the wall's -r v. Random
 * speeds, many r: a property loop, as chrony's unit tests do. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "../../model/mdl_collide.h"

/* Equal to rounding: a few ulps of the largest term. */
static void assert_close(double a, double b, double scale)
{
	if (!(fabs(a - b) <= 1e-14 * (1.0 + scale)))
		fail_msg("%.17g != %.17g (scale %g)", a, b, scale);
}

static double draw(unsigned *s, double lo, double hi)
{
	return lo + (hi - lo) * (double)rand_r(s) / RAND_MAX;
}

static void test_momentum_and_energy(void **state)
{
	(void)state;
	unsigned seed = 25;
	for (int k = 0; k < 10000; k++) {
		double r = k % 11 == 0 ? 0.0 : k % 13 == 0 ? 1.0 : draw(&seed, 0, 1);
		double vl = draw(&seed, -5, 5), vr = draw(&seed, -5, 5);
		double pl, pr;
		collide_pair(r, vl, vr, &pl, &pr);
		double scale = fabs(vl) + fabs(vr);
		assert_close(pl + pr, vl + vr, scale);
		assert_close(pl - pr, -r * (vl - vr), scale);
		double lost = collide_energy(vl, vr) - collide_energy(pl, pr);
		assert_close(lost, (1 - r * r) * (vl - vr) * (vl - vr) / 4, scale * scale);
	}
}

static void test_elastic_and_plastic(void **state)
{
	(void)state;
	double pl, pr;
	/* r = 1, equal masses: the speeds are exchanged */
	collide_pair(1.0, 2.0, -0.5, &pl, &pr);
	assert_close(pl, -0.5, 0);
	assert_close(pr, 2.0, 0);
	/* r = 0: one common speed, the mean */
	collide_pair(0.0, 2.0, -0.5, &pl, &pr);
	assert_close(pl, 0.75, 0);
	assert_close(pr, 0.75, 0);
	/* the paper's rig, r = 0.67 */
	collide_pair(0.67, 1.0, -1.0, &pl, &pr);
	assert_close(pl, -0.67, 0);
	assert_close(pr, 0.67, 0);
}

static void test_wall(void **state)
{
	(void)state;
	assert_close(collide_wall(0.67, 2.0), -1.34, 0);
	assert_close(collide_wall(0.0, -3.0), 0.0, 0);
	/* energy lost against a wall: the factor r^2 on all of it */
	double v = 1.7, r = 0.4, w = collide_wall(r, v);
	assert_close(w * w, r * r * v * v, v * v);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_momentum_and_energy),
		cmocka_unit_test(test_elastic_and_plastic),
		cmocka_unit_test(test_wall),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
