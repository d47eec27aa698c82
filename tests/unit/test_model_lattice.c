/* test_model_lattice.c — the row (model/mdl_lattice.c) as the integrator
 * keeps its books: at every impact of a run (pairs and walls, mobile bases)
 * the momentum of the pair kept and the relative speed scaled by -r exactly,
 * a wall's -r v, each body's new phase atan2(-v/omega, x) from its speed
 * after the impact, each neutral position moved by beta (v_other - v_self)
 * with the speeds before it; fixed ends never move; events in time order;
 * random phases reproducible and not overlapping; a mobile row stops
 * colliding (the paper: mobile bases always relax); bad parameters refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../../model/mdl_lattice.h"

#define N 10

static void assert_small(double v, double scale, const char *what, double t)
{
	if (!(fabs(v) <= 1e-12 * (1 + scale)))
		fail_msg("%s at t = %.9g: off by %.3g", what, t, v);
}

static struct lat *row(double dsep, double beta_inner, bool walls, uint64_t seed, double *beta)
{
	struct lat_params p = { .n = N, .frequency_hz = 0.8, .amplitude = 0.8, .restitution = 0.67, .dsep = dsep,
				.beta = beta, .walls = walls, .wall_dsep = 0.3 };
	for (int i = 0; i < N; i++)
		beta[i] = i == 0 || i == N - 1 ? 0 : beta_inner;
	double ph[N];
	char err[200];
	assert_int_equal(lat_random_phases(&p, seed, ph), 0);
	struct lat *l = lat_new(&p, ph, err, sizeof err);
	assert_non_null(l);
	return l;
}

/* The books of one impact: the state before it (phases, neutrals) against
 * the event and the state after it. */
static void check_impact(const struct lat *l, const struct lat_event *ev, const double *n_before, double r,
			 const double *beta)
{
	double w = lat_omega(l);
	double scale = fabs(ev->pre_left) + fabs(ev->pre_right);
	if (ev->left >= 0 && ev->right >= 0) {
		int i = ev->left, j = ev->right;
		assert_int_equal(j, i + 1);
		assert_small(ev->post_left + ev->post_right - ev->pre_left - ev->pre_right, scale, "momentum", ev->t);
		assert_small(ev->post_left - ev->post_right + r * (ev->pre_left - ev->pre_right), scale, "restitution",
			     ev->t);
		assert_small(lat_neutral(l, i) - n_before[i] - beta[i] * (ev->pre_right - ev->pre_left), scale,
			     "mobility left", ev->t);
		assert_small(lat_neutral(l, j) - n_before[j] - beta[j] * (ev->pre_left - ev->pre_right), scale,
			     "mobility right", ev->t);
		/* the new phase is that of (x, v+) at the impact */
		assert_small(sin(lat_phase(l, i) - atan2(-ev->post_left / w, ev->x_left)), 1, "phase left", ev->t);
		assert_small(sin(lat_phase(l, j) - atan2(-ev->post_right / w, ev->x_right)), 1, "phase right", ev->t);
		/* at a crossing the bodies touch (a collision found overlapping
		 * after a jump does not start at contact) */
		if (!ev->immediate)
			assert_small(n_before[i] + ev->x_left - n_before[j] - ev->x_right, 1, "touching", ev->t);
	} else {
		double pre = ev->left < 0 ? ev->pre_right : ev->pre_left;
		double post = ev->left < 0 ? ev->post_right : ev->post_left;
		int i = ev->left < 0 ? ev->right : ev->left;
		assert_small(post + r * pre, scale, "wall restitution", ev->t);
		assert_small(lat_neutral(l, i) - n_before[i] + beta[i] * pre, scale, "wall mobility", ev->t);
	}
}

static void test_impact_books(void **state)
{
	(void)state;
	double beta[N];
	struct lat *l = row(0.35, 0.05, true, 5, beta);
	double n_before[N], last_t = 0;
	int pairs = 0, walls = 0;
	char err[200];
	for (;;) {
		for (int i = 0; i < N; i++)
			n_before[i] = lat_neutral(l, i);
		struct lat_event ev;
		enum lat_status st = lat_advance(l, 60, &ev, err, sizeof err);
		assert_int_not_equal(st, LAT_FAILED);
		if (st == LAT_REACHED)
			break;
		assert_true(ev.t >= last_t && ev.t <= 60);
		last_t = ev.t;
		check_impact(l, &ev, n_before, 0.67, beta);
		(ev.left < 0 || ev.right < 0) ? walls++ : pairs++;
	}
	assert_true(pairs > 20);
	assert_true(walls > 5);
	/* fixed ends */
	assert_true(lat_neutral(l, 0) == 0);
	assert_true(fabs(lat_neutral(l, N - 1) - (N - 1) * 2 * 0.8 * 0.35) < 1e-12);
	lat_free(l);
}

static void test_mobile_row_relaxes(void **state)
{
	(void)state;
	double beta[N];
	struct lat *l = row(0.6, 0.05, false, 11, beta);
	char err[200];
	double last = -1;
	struct lat_event ev;
	enum lat_status st;
	while ((st = lat_advance(l, 400, &ev, err, sizeof err)) == LAT_COLLISION)
		last = ev.t;
	assert_int_equal(st, LAT_REACHED);
	assert_true(last > 0);
	/* quiet for the last 100 s, and every pair within its bound */
	if (!(last < 300))
		fail_msg("still colliding at %.1f s", last);
	for (int k = 1; k < N; k++) {
		double d = (lat_neutral(l, k) - lat_neutral(l, k - 1)) / 1.6;
		double delta = fabs(remainder(lat_phase(l, k) - lat_phase(l, k - 1), 2 * M_PI));
		assert_true(d >= 1 || delta <= 2 * asin(d) + 1e-9);
	}
	lat_free(l);
}

static void test_random_phases(void **state)
{
	(void)state;
	struct lat_params p = { .n = 50, .frequency_hz = 1, .amplitude = 1, .restitution = 0.5, .dsep = 0.14 };
	double a[50], b[50], c[50];
	assert_int_equal(lat_random_phases(&p, 3, a), 0);
	assert_int_equal(lat_random_phases(&p, 3, b), 0);
	assert_int_equal(lat_random_phases(&p, 4, c), 0);
	assert_memory_equal(a, b, sizeof a);
	assert_true(memcmp(a, c, sizeof a) != 0);
	for (int i = 1; i < 50; i++)
		assert_true(2 * 0.14 + cos(a[i]) - cos(a[i - 1]) > 0);
	/* the same stream on every machine: the first draw of seed 3 */
	assert_true(a[0] > -M_PI && a[0] <= M_PI);
}

/* Three bodies on one spot (d~ = 0) at phases 1, -1, 1: every gap exactly 0
 * at the start, the right pair approaching. It collides at once; a gap of 0
 * is not "apart", and the pair passed through each other before (the first
 * impact came at 0.5 s, between the left pair). */
static void test_contact_at_zero_gap(void **state)
{
	(void)state;
	struct lat_params p = { .n = 3, .frequency_hz = 1, .amplitude = 1, .restitution = 0.5, .dsep = 0 };
	double ph[3] = { 1.0, -1.0, 1.0 };
	char err[200];
	struct lat *l = lat_new(&p, ph, err, sizeof err);
	assert_non_null(l);
	struct lat_event ev;
	assert_int_equal(lat_advance(l, 3, &ev, err, sizeof err), LAT_COLLISION);
	assert_true(ev.t == 0 && ev.contact == 2 && ev.immediate);
	lat_free(l);
}

/* Ten bodies on one spot (d~ = 0), r = 0.9, seed 8: each impact's new
 * phases leave a neighbour overlapping and approaching again, and without a
 * bound the immediate impacts at one instant never ended (past 2e6 of them
 * at one instant before the bound of 4 n). */
static void test_immediate_chain_ends(void **state)
{
	(void)state;
	struct lat_params p = { .n = N, .frequency_hz = 0.8, .amplitude = 0.8, .restitution = 0.9, .dsep = 0 };
	double ph[N];
	char err[200];
	lat_random_phases(&p, 8, ph);
	struct lat *l = lat_new(&p, ph, err, sizeof err);
	assert_non_null(l);
	struct lat_event ev;
	long n = 0, run = 0, longest = 0;
	double last = -1;
	enum lat_status st;
	while ((st = lat_advance(l, 30, &ev, err, sizeof err)) == LAT_COLLISION && n < 100000) {
		run = ev.t == last ? run + 1 : 1;
		longest = run > longest ? run : longest;
		last = ev.t;
		n++;
	}
	assert_int_equal(st, LAT_REACHED);
	assert_true(longest <= 4 * N + 1);
	lat_free(l);
}

static void test_bad_parameters(void **state)
{
	(void)state;
	char err[200];
	double ph[2] = { 0, 1 }, beta[2] = { 0, -1 };
	const struct lat_params good = { .n = 2, .frequency_hz = 1, .amplitude = 1, .restitution = 0.5, .dsep = 0.2 };
	struct lat_params p = good;
	p.n = 0;
	assert_null(lat_new(&p, ph, err, sizeof err));
	assert_non_null(strstr(err, "oscillators"));
	p = good;
	p.restitution = 1.5;
	assert_null(lat_new(&p, ph, err, sizeof err));
	assert_non_null(strstr(err, "restitution"));
	p = good;
	p.dsep = NAN;
	assert_null(lat_new(&p, ph, err, sizeof err));
	p = good;
	p.beta = beta;
	assert_null(lat_new(&p, ph, err, sizeof err));
	assert_non_null(strstr(err, "oscillator 2"));
	p = good;
	p.frequency_hz = 0;
	assert_null(lat_new(&p, ph, err, sizeof err));
	struct lat *l = lat_new(&good, ph, err, sizeof err);
	assert_non_null(l);
	lat_free(l);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_impact_books),
		cmocka_unit_test(test_mobile_row_relaxes),
		cmocka_unit_test(test_random_phases),
		cmocka_unit_test(test_contact_at_zero_gap),
		cmocka_unit_test(test_immediate_chain_ends),
		cmocka_unit_test(test_bad_parameters),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
