/* test_model_pair.c — the integrator (model/mdl_lattice.c) against
 * theory.md's closed forms, to 1e-6:
 *  - d~ = 0: delta_n = 2 atan((-r)^n tan(delta_0/2)) over 25 collisions of
 *    one run, several r and delta_0 of both signs;
 *  - d~ > 0: each collision's delta_{n+1} against theory.md's map (its atan2
 *    form, written here again: an independent copy of the formula);
 *  - the compatibility fixed point: the phase difference below which a pair
 *    never touches, found by bisection on the integrator, is 2 asin(d~);
 *  - d~_c(r): where the integrator's slope of the map at anti-phase is -1,
 *    found by bisection on d~, is sqrt(r(r - 1) / (r^2 - r - 2)).
 * The last two need the event detection to see a contact that dips below
 * zero inside a step: at a step's end it is missed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "../../model/mdl_lattice.h"
#include "../../model/mdl_pairmap.h"

#define TOL 1e-6

static double wrap(double a)
{
	a = fmod(a, 2 * M_PI);
	return a > M_PI ? a - 2 * M_PI : a <= -M_PI ? a + 2 * M_PI : a;
}

static void assert_near(double got, double want, double tol, const char *what, double a, double b)
{
	if (!(fabs(wrap(got - want)) <= tol))
		fail_msg("%s (%g, %g): got %.12g, want %.12g (off %.3g)", what, a, b, got, want, fabs(wrap(got - want)));
}

/* theory.md's map with atan2 (its atan folds the branches). */
static double map_formula(double delta, double d, double r)
{
	double h = 0.5 * delta, k = asin(d / sin(h));
	double sk = sin(k), ck = cos(k), sh = sin(h), ch = cos(h);
	return wrap(atan2(sk * ch - r * ck * sh, ck * ch - sk * sh) - atan2(sk * ch + r * ck * sh, ck * ch + sk * sh));
}

static void test_d0_closed_form(void **state)
{
	(void)state;
	const double rs[] = { 0.3, 0.5, 0.67, 0.9 };
	const double d0s[] = { 0.3, 1.0, 2.0, 2.9, -0.7, -1.8, -3.0 };
	for (size_t a = 0; a < sizeof rs / sizeof rs[0]; a++)
		for (size_t b = 0; b < sizeof d0s / sizeof d0s[0]; b++) {
			struct lat_params p = { .n = 2, .frequency_hz = 0.8, .amplitude = 0.8, .restitution = rs[a] };
			double ph[2];
			char err[200];
			pmap_start(d0s[b], ph);
			struct lat *l = lat_new(&p, ph, err, sizeof err);
			assert_non_null(l);
			int n = 0;
			struct lat_event ev;
			while (n < 25) {
				enum lat_status st = lat_advance(l, 100.0, &ev, err, sizeof err);
				assert_int_equal(st, LAT_COLLISION);
				double want = 2 * atan(pow(-rs[a], n) * tan(0.5 * d0s[b]));
				assert_near(ev.delta_before, want, TOL, "d~=0 before", rs[a], d0s[b]);
				want = 2 * atan(pow(-rs[a], n + 1) * tan(0.5 * d0s[b]));
				assert_near(ev.delta_after, want, TOL, "d~=0 after", rs[a], d0s[b]);
				n++;
			}
			lat_free(l);
		}
}

static void test_map_formula(void **state)
{
	(void)state;
	char err[200];
	for (double r = 0.3; r <= 0.95; r += 0.3)
		for (double d = 0.05; d < 1.0; d += 0.15)
			for (double delta = -3.1; delta <= 3.1; delta += 0.2) {
				if (fabs(sin(0.5 * delta)) <= d + 1e-3)
					continue;
				struct pmap_result m;
				assert_int_equal(pmap_step(d, r, delta, 0, &m, err, sizeof err), 0);
				if (!m.collided)
					fail_msg("no collision at d~ %g delta %g", d, delta);
				assert_near(m.delta_before, delta, TOL, "before", d, delta);
				assert_near(m.delta_after, map_formula(delta, d, r), TOL, "map", d, delta);
			}
}

/* Does a pair at d~ and delta touch within two periods? Started a little
 * after the widest point (the steps' ends then miss the closest approach,
 * which a detector that looks only at them would miss too). */
static int collides(double d, double delta)
{
	struct lat_params p = { .n = 2, .frequency_hz = 0.8, .amplitude = 0.8, .restitution = 0.67, .dsep = d };
	double ph[2];
	char err[200];
	pmap_start(delta, ph);
	ph[0] += 0.3;
	ph[1] += 0.3;
	struct lat *l = lat_new(&p, ph, err, sizeof err);
	assert_non_null(l);
	struct lat_event ev;
	enum lat_status st = lat_advance(l, 2 / 0.8, &ev, err, sizeof err);
	assert_int_not_equal(st, LAT_FAILED);
	lat_free(l);
	return st == LAT_COLLISION;
}

static void test_compatibility_limit(void **state)
{
	(void)state;
	for (double d = 0.1; d < 0.95; d += 0.2) {
		double lo = 0, hi = M_PI;   /* never touches at lo, touches at hi */
		assert_false(collides(d, lo + 1e-3));
		assert_true(collides(d, hi));
		while (hi - lo > 1e-9) {
			double mid = 0.5 * (lo + hi);
			if (collides(d, mid))
				hi = mid;
			else
				lo = mid;
		}
		assert_near(hi, 2 * asin(d), TOL, "compatibility limit", d, 0);
		/* and negative phase differences: the same bound */
		assert_false(collides(d, -2 * asin(d) + 1e-5));
		assert_true(collides(d, -2 * asin(d) - 1e-5));
	}
}

/* The map's slope at anti-phase, from the integrator: a central difference. */
static double slope_at_pi(double d, double r)
{
	const double h = 1e-4;
	struct pmap_result a, b;
	char err[200];
	assert_int_equal(pmap_step(d, r, M_PI + h, 0, &a, err, sizeof err), 0);
	assert_int_equal(pmap_step(d, r, M_PI - h, 0, &b, err, sizeof err), 0);
	assert_true(a.collided && b.collided);
	return (wrap(a.delta_after - M_PI) - wrap(b.delta_after - M_PI)) / (2 * h);
}

static void test_critical_separation(void **state)
{
	(void)state;
	const double rs[] = { 0.3, 0.5, 0.67, 0.9 };
	for (size_t a = 0; a < sizeof rs / sizeof rs[0]; a++) {
		double r = rs[a], lo = 0.01, hi = 0.99;   /* |slope| > 1 at lo, < 1 at hi */
		assert_true(slope_at_pi(lo, r) < -1);
		assert_true(slope_at_pi(hi, r) > -1);
		while (hi - lo > 1e-8) {
			double mid = 0.5 * (lo + hi);
			if (slope_at_pi(mid, r) < -1)
				lo = mid;
			else
				hi = mid;
		}
		assert_near(0.5 * (lo + hi), sqrt(r * (r - 1) / (r * r - r - 2)), TOL, "d~_c", r, 0);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_d0_closed_form),
		cmocka_unit_test(test_map_formula),
		cmocka_unit_test(test_compatibility_limit),
		cmocka_unit_test(test_critical_separation),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
