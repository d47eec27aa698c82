/* test_analyze_phase.c — phase estimation, circular statistics and the
 * contact theory's return map (tools/analyze/phase.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "../../tools/analyze/phase.h"

static void test_wrap(void **state)
{
	(void)state;
	assert_true(fabs(phase_wrap(3 * M_PI) - M_PI) < 1e-12);
	assert_true(fabs(phase_wrap(-M_PI) - M_PI) < 1e-12); /* (-pi, pi] */
	assert_true(fabs(phase_wrap(2 * M_PI + 0.25) - 0.25) < 1e-12);
	assert_true(fabs(phase_wrap(-2 * M_PI - 0.25) + 0.25) < 1e-12);
	for (double a = -20; a < 20; a += 0.37) {
		double w = phase_wrap(a);
		assert_true(w > -M_PI && w <= M_PI);
		assert_true(fabs(sin(w) - sin(a)) < 1e-9 && fabs(cos(w) - cos(a)) < 1e-9);
	}
}

static void test_phase_from_state(void **state)
{
	(void)state;
	double w = 2 * M_PI * 0.8, A = 0.8;
	for (double phi = -3.1; phi < 3.1; phi += 0.1) {
		double x = A * cos(phi), v = -A * w * sin(phi);
		assert_true(fabs(phase_from_state(x, v, w) - phi) < 1e-9);
	}
	assert_true(isnan(phase_from_state(0.1, 0.2, 0.0)));
}

/* A noisy 0.8 Hz oscillation sampled at 100 Hz: the zero-crossing
 * estimator must find the frequency and amplitude. */
static void test_tracker_frequency(void **state)
{
	(void)state;
	struct phase_tracker tr;
	phase_tracker_init(&tr);
	srand(7);
	double f = 0.8, A = 0.6;
	assert_true(phase_tracker_omega(&tr) == 0.0);
	for (int i = 0; i < 2000; i++) {
		double t = i * 0.01;
		double noise = 0.005 * ((double)rand() / RAND_MAX - 0.5);
		phase_tracker_feed(&tr, t, A * sin(2 * M_PI * f * t + 0.3) + noise);
	}
	double est = phase_tracker_omega(&tr) / (2 * M_PI);
	assert_true(fabs(est - f) < 0.002);
	assert_true(fabs(tr.amplitude - A) < 0.01);
}

/* A phase jump (a collision) disturbs one period; the median ignores it. */
static void test_tracker_jump(void **state)
{
	(void)state;
	struct phase_tracker tr;
	phase_tracker_init(&tr);
	double w = 2 * M_PI * 1.0;
	for (int i = 0; i < 1000; i++) {
		double t = i * 0.01;
		double jump = t > 5.3 ? 1.5 : 0.0;
		phase_tracker_feed(&tr, t, cos(w * t + jump));
	}
	assert_true(fabs(phase_tracker_omega(&tr) - w) < 0.01 * w);
}

static void test_circ(void **state)
{
	(void)state;
	struct phase_circ c = { 0 };
	assert_true(isnan(phase_circ_mean(&c)));
	/* values straddling +-pi: the circular mean is pi, not 0 */
	phase_circ_add(&c, M_PI - 0.1);
	phase_circ_add(&c, -M_PI + 0.1);
	assert_true(fabs(fabs(phase_circ_mean(&c)) - M_PI) < 1e-9);
	assert_true(fabs(phase_circ_mean_abs(&c) - (M_PI - 0.1)) < 1e-9);
	assert_true(phase_circ_spread(&c) > 0.09 && phase_circ_spread(&c) < 0.11);
	struct phase_circ d = { 0 };
	for (int i = 0; i < 10; i++)
		phase_circ_add(&d, 0.5);
	assert_true(fabs(phase_circ_spread(&d)) < 1e-6);
}

/* d~ = 0: the map iterated n times equals the closed form, and -> 0. */
/* Peak-to-peak of the angle: empty is NAN, bad samples do not count. */
static void test_swing(void **state)
{
	(void)state;
	struct phase_swing s;
	phase_swing_init(&s);
	assert_true(isnan(phase_swing_pp(&s)));
	phase_swing_add(&s, NAN);
	phase_swing_add(&s, INFINITY);
	assert_true(isnan(phase_swing_pp(&s)));
	phase_swing_add(&s, 0.3);
	assert_true(phase_swing_pp(&s) == 0.0); /* one sample: no swing */
	for (double t = 0; t < 5.0; t += 0.01)
		phase_swing_add(&s, 0.3 + 0.8 * sin(2 * M_PI * 0.8 * t));
	phase_swing_add(&s, -INFINITY);
	assert_true(fabs(phase_swing_pp(&s) - 1.6) < 1e-3);
	/* all negative: the extremes are not anchored at 0 */
	phase_swing_init(&s);
	phase_swing_add(&s, -0.5);
	phase_swing_add(&s, -0.7);
	assert_true(fabs(phase_swing_pp(&s) - 0.2) < 1e-12);
}

static void test_return_map_d0(void **state)
{
	(void)state;
	double r = 0.67;
	for (double d0 = -3.0; d0 <= 3.0; d0 += 0.25) {
		double d = d0;
		assert_true(fabs(phase_return_map_d0(d0, r, 0) - d0) < 1e-12);
		for (int n = 1; n <= 12; n++) {
			d = phase_return_map(d, 0.0, r);
			assert_true(fabs(d - phase_return_map_d0(d0, r, n)) < 1e-9);
		}
		assert_true(fabs(d) < fabs(d0) + 1e-12);
	}
	/* slope -r at 0 */
	double h = 1e-6;
	assert_true(fabs(phase_return_map(h, 0.0, r) / h + r) < 1e-6);
}

/* Fixed points (theory.md): grazing at 2 asin(d~), anti-phase at pi with
 * slope -(r(d^2-1)+d^2)/(r^2(d^2-1)-d^2); no contact below 2 asin(d~). */
static void test_return_map_fixed_points(void **state)
{
	(void)state;
	double r = 0.67;
	for (double ds = 0.1; ds < 0.95; ds += 0.1) {
		double g = phase_compat_limit(ds);
		assert_true(fabs(g - 2 * asin(ds)) < 1e-12);
		assert_true(fabs(phase_return_map(g + 1e-9, ds, r) - g) < 1e-3);
		assert_true(isnan(phase_return_map(0.9 * g, ds, r)));
		assert_true(fabs(fabs(phase_return_map(M_PI, ds, r)) - M_PI) < 1e-9);
		double h = 1e-5;
		double slope = phase_wrap(phase_return_map(M_PI - h, ds, r) - phase_return_map(M_PI, ds, r)) / -h;
		double d2 = ds * ds;
		double theory = -(r * (d2 - 1) + d2) / (r * r * (d2 - 1) - d2);
		assert_true(fabs(slope - theory) < 1e-3);
	}
	/* antisymmetry: f(-x) = -f(x) */
	for (double x = 1.4; x < 3.1; x += 0.2)
		assert_true(fabs(phase_return_map(-x, 0.6, r) + phase_return_map(x, 0.6, r)) < 1e-9);
	assert_true(fabs(phase_compat_limit(1.5) - M_PI) < 1e-12);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_wrap),
		cmocka_unit_test(test_phase_from_state),
		cmocka_unit_test(test_tracker_frequency),
		cmocka_unit_test(test_tracker_jump),
		cmocka_unit_test(test_circ),
		cmocka_unit_test(test_swing),
		cmocka_unit_test(test_return_map_d0),
		cmocka_unit_test(test_return_map_fixed_points),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
