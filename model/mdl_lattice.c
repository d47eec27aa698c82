/* mdl_lattice.c — the row of phase oscillators, integrated with GSL and its
 * collisions found as events (mdl_lattice.h). */
#include "mdl_lattice.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mdl_collide.h"
#include "phase.h"

/* Steps per period at most: g_k is a sinusoid at omega between impacts, so
 * a step of an eighth of a period holds at most one of its extrema and a dip
 * below zero inside a step is seen by the sign of g_k' at its ends. */
#define LAT_STEPS_PER_PERIOD 8
/* Brent iterations at most when locating a time; it converges in ~10-40. */
#define LAT_ROOT_ITER 200
#define LAT_TOL_DEFAULT 1e-12
/* Immediate collisions at one instant at most, per oscillator: each can
 * leave its neighbours overlapping again (the new phases jump the bodies),
 * and a chain that did not die out would hold the row at one instant. */
#define LAT_IMMEDIATE_PER_OSC 4

struct lat {
	int n;
	int dim;                 /* state values per oscillator: 1 (phase) or 2 (x, v: its own amplitude) */
	double omega, amp, r;
	double rate;             /* the limit cycle's amplitude rate R, 1/s (dim 2) */
	bool walls;
	double wall[2];
	double t;
	double *y;               /* the ODE's state: a phase each (the phase model), or x, v each (dim 2) */
	double *neutral;
	double *beta;
	double *y0;              /* the state at the current step's start */
	double *ytmp;            /* scratch: the state at a time inside the step */
	bool *pending;           /* contacts to look at after a jump */
	bool any_pending;
	double immediate_t;      /* the instant of the last immediate collisions */
	int immediate_n;         /* how many at that instant */
	double h, hmax, tol;
	gsl_odeiv2_system sys;
	gsl_odeiv2_step *step;
	gsl_odeiv2_control *ctl;
	gsl_odeiv2_evolve *evo;
	gsl_odeiv2_driver *drv;  /* from the step's start to a time inside it */
	gsl_odeiv2_system pair_sys[2];   /* one contact's oscillators alone: 1 (a wall's) or 2 */
	gsl_odeiv2_driver *pair_drv[2];
	gsl_root_fsolver *root;
	int64_t overlaps, steps, root_evals;
};

static int lat_err(char *err, size_t cap, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err, cap, fmt, ap);
	va_end(ap);
	return -1;
}


/* The oscillators' law for m of them from y into dydt. The phase model:
 * phi' = omega. With an amplitude (dim 2): the van der Pol limit cycle
 *   x'' = -omega^2 x + R (1 - 4 x^2 / A^2) x'
 * whose cycle has amplitude A (to O(R/omega)^2) and whose amplitude comes
 * back at the rate R after a disturbance (linearised, averaged over a
 * period) — the daemon's OSCILLATOR law for one joint, I x'' = -k x +
 * (c - mu x^2) x', with R = c / I (daemon/osc.h). Kept an ODE either way so
 * that the event machinery does not depend on the law. */
static void lat_law(const struct lat *l, const double *y, double *dydt, int m)
{
	if (l->dim == 1) {
		for (int i = 0; i < m; i++)
			dydt[i] = l->omega;
		return;
	}
	double w2 = l->omega * l->omega, q = 4 / (l->amp * l->amp);
	for (int i = 0; i < m; i++) {
		double x = y[2 * i], v = y[2 * i + 1];
		dydt[2 * i] = v;
		dydt[2 * i + 1] = -w2 * x + l->rate * (1 - q * x * x) * v;
	}
}

static int lat_rhs(double t, const double y[], double dydt[], void *params)
{
	(void)t;
	const struct lat *l = params;
	lat_law(l, y, dydt, l->n);
	return GSL_SUCCESS;
}

/* The same law for one contact's oscillators (1 or 2 of them). */
static int lat_rhs1(double t, const double y[], double dydt[], void *params)
{
	(void)t;
	lat_law(params, y, dydt, 1);
	return GSL_SUCCESS;
}

static int lat_rhs2(double t, const double y[], double dydt[], void *params)
{
	(void)t;
	lat_law(params, y, dydt, 2);
	return GSL_SUCCESS;
}

/* Oscillator i's displacement, speed and phase in state y. The phase of an
 * oscillator with an amplitude is read as the daemon's and the analyser's:
 * clockwise in the (x, x'/omega) plane. */
static double lat_x(const struct lat *l, const double *y, int i)
{
	return l->dim == 1 ? l->amp * cos(y[i]) : y[2 * i];
}

static double lat_v(const struct lat *l, const double *y, int i)
{
	return l->dim == 1 ? -l->amp * l->omega * sin(y[i]) : y[2 * i + 1];
}

static double lat_phi(const struct lat *l, const double *y, int i)
{
	return l->dim == 1 ? phase_wrap(y[i]) : atan2(-y[2 * i + 1] / l->omega, y[2 * i]);
}

/* Contact k's gap (positive: apart) and its rate of change, for state y. */
static double lat_gap(const struct lat *l, const double *y, int k)
{
	if (k == 0)
		return l->neutral[0] + lat_x(l, y, 0) - l->wall[0];
	if (k == l->n)
		return l->wall[1] - (l->neutral[l->n - 1] + lat_x(l, y, l->n - 1));
	return l->neutral[k] + lat_x(l, y, k) - l->neutral[k - 1] - lat_x(l, y, k - 1);
}

static double lat_gap_rate(const struct lat *l, const double *y, int k)
{
	if (k == 0)
		return lat_v(l, y, 0);
	if (k == l->n)
		return -lat_v(l, y, l->n - 1);
	return lat_v(l, y, k) - lat_v(l, y, k - 1);
}

static bool lat_has_contact(const struct lat *l, int k)
{
	return (k > 0 && k < l->n) || (l->walls && (k == 0 || k == l->n));
}

/* Values in the whole state. */
static size_t lat_len(const struct lat *l) { return (size_t)l->n * (size_t)l->dim; }

/* Contact k's oscillators at time t inside the step that started at
 * (t0, y0), into their places in ytmp (the others' are stale). Between
 * impacts the oscillators do not interact: the two of a contact are
 * integrated alone, so that locating an impact costs the same in a row of
 * a thousand as in a pair. */
static int lat_contact_at(struct lat *l, double t0, double t, int k)
{
	int first = k == 0 ? 0 : k - 1, m = (k == 0 || k == l->n) ? 1 : 2;
	size_t off = (size_t)(first * l->dim), len = (size_t)(m * l->dim);
	double y[4];
	memcpy(y, l->y0 + off, len * sizeof *y);
	l->root_evals++;
	if (t > t0) {
		gsl_odeiv2_driver_reset(l->pair_drv[m - 1]);
		double tt = t0;
		if (gsl_odeiv2_driver_apply(l->pair_drv[m - 1], &tt, t, y) != GSL_SUCCESS)
			return -1;
	}
	memcpy(l->ytmp + off, y, len * sizeof *y);
	return 0;
}

/* The state at time t inside the step that started at (t0, y0): into ytmp. */
static int lat_state_at(struct lat *l, double t0, double t)
{
	memcpy(l->ytmp, l->y0, lat_len(l) * sizeof *l->ytmp);
	l->root_evals++;
	if (t <= t0)
		return 0;
	gsl_odeiv2_driver_reset(l->drv);
	double tt = t0;
	return gsl_odeiv2_driver_apply(l->drv, &tt, t, l->ytmp) == GSL_SUCCESS ? 0 : -1;
}

struct lat_probe {
	struct lat *l;
	double t0;
	int k;
	bool rate;      /* g_k' instead of g_k */
	bool failed;
};

static double lat_probe_fn(double t, void *params)
{
	struct lat_probe *p = params;
	if (lat_contact_at(p->l, p->t0, t, p->k) != 0) {
		p->failed = true;
		return 0;
	}
	return p->rate ? lat_gap_rate(p->l, p->l->ytmp, p->k) : lat_gap(p->l, p->l->ytmp, p->k);
}

/* A root of the probe in [lo, hi] (values of opposite signs, or zero at an
 * end): Brent's method to the integrator's tolerance in time. */
static int lat_brent(struct lat *l, struct lat_probe *p, double lo, double hi, double *out)
{
	gsl_function f = { .function = lat_probe_fn, .params = p };
	double flo = lat_probe_fn(lo, p), fhi = lat_probe_fn(hi, p);
	if (p->failed)
		return -1;
	if (flo == 0 || fhi == 0 || (flo > 0) == (fhi > 0)) {
		/* the dip's minimum at zero, or an end exactly at it */
		*out = fhi == 0 || (flo > 0) == (fhi > 0) ? hi : lo;
		return 0;
	}
	if (gsl_root_fsolver_set(l->root, &f, lo, hi) != GSL_SUCCESS)
		return -1;
	double tol = l->tol * (1.0 + fabs(hi));
	for (int it = 0; it < LAT_ROOT_ITER; it++) {
		if (gsl_root_fsolver_iterate(l->root) != GSL_SUCCESS || p->failed)
			return -1;
		double a = gsl_root_fsolver_x_lower(l->root), b = gsl_root_fsolver_x_upper(l->root);
		if (gsl_root_test_interval(a, b, tol, 0) == GSL_SUCCESS)
			break;
	}
	*out = gsl_root_fsolver_root(l->root);
	return p->failed ? -1 : 0;
}

/* The least value over the step of the cubic Hermite interpolant of g from
 * its values g0, g1 and rates d0, d1 at the ends (h the step). */
static double lat_hermite_min(double g0, double g1, double d0, double d1, double h)
{
	/* p(s) = g0 + h d0 s + c2 s^2 + c3 s^3 on s in [0, 1] */
	double c1 = h * d0;
	double c2 = -3 * g0 - 2 * h * d0 + 3 * g1 - h * d1;
	double c3 = 2 * g0 + h * d0 - 2 * g1 + h * d1;
	double lo = fmin(g0, g1);
	/* p'(s) = c1 + 2 c2 s + 3 c3 s^2 */
	double a = 3 * c3, b = 2 * c2, disc = b * b - 4 * a * c1;
	double s[2];
	int ns = 0;
	if (fabs(a) < 1e-300) {
		if (fabs(b) > 1e-300)
			s[ns++] = -c1 / b;
	} else if (disc >= 0) {
		double q = -0.5 * (b + copysign(sqrt(disc), b));
		s[ns++] = q / a;
		if (fabs(q) > 1e-300)
			s[ns++] = c1 / q;
	}
	for (int i = 0; i < ns; i++)
		if (s[i] > 0 && s[i] < 1)
			lo = fmin(lo, g0 + s[i] * (c1 + s[i] * (c2 + s[i] * c3)));
	return lo;
}

/* When contact k, apart at the step's start (t0, y0) and given at its end
 * (t1, phi), closes inside the step: *tc, and 1; 0 when it does not. */
static int lat_crossing(struct lat *l, int k, double t0, double t1, double *tc)
{
	double g0 = lat_gap(l, l->y0, k), g1 = lat_gap(l, l->y, k);
	if (!(g0 > 0))
		return 0;   /* overlapping at the start: let through until apart */
	struct lat_probe p = { .l = l, .t0 = t0, .k = k };
	double hi = t1;
	if (!(g1 <= 0)) {
		/* both ends apart: a dip below zero between them needs g' < 0
		 * at the start and > 0 at the end (one extremum per step) */
		double d0 = lat_gap_rate(l, l->y0, k), d1 = lat_gap_rate(l, l->y, k);
		if (!(d0 < 0 && d1 > 0))
			return 0;
		/* and the cubic through the ends' values and rates within its
		 * error of zero: |g - p| <= h^4 max|g| / 384, where g =
		 * omega^4 (the A cos terms of g), at most 2 A omega^4 (twice
		 * that here, for rounding). Far from contact no search is made:
		 * in a row of a thousand it was most of the work. */
		double h = t1 - t0, w2 = l->omega * l->omega;
		double bound = 4 * l->amp * w2 * w2 * h * h * h * h / 384;
		/* (the bound is the phase model's: with an amplitude of its own
		 * every such step is searched) */
		if (l->dim == 1 && lat_hermite_min(g0, g1, d0, d1, h) > bound)
			return 0;
		p.rate = true;
		if (lat_brent(l, &p, t0, t1, &hi) != 0)
			return -1;
		p.rate = false;
		if (lat_contact_at(l, t0, hi, k) != 0)
			return -1;
		if (!(lat_gap(l, l->ytmp, k) <= 0))
			return 0;
	}
	return lat_brent(l, &p, t0, hi, tc) == 0 ? 1 : -1;
}

/* Resets the stepper after a jump of the state (its history is void). */
static void lat_jumped(struct lat *l)
{
	gsl_odeiv2_evolve_reset(l->evo);
	gsl_odeiv2_step_reset(l->step);
}

static void lat_mark_neighbours(struct lat *l, int k)
{
	for (int j = k - 1; j <= k + 1; j += 2)
		if (j >= 0 && j <= l->n && lat_has_contact(l, j)) {
			l->pending[j] = true;
			l->any_pending = true;
		}
}

/* Body i given speed v by an impact. The phase model puts it back on its
 * cycle at the new phase (mdl_lattice.h); an oscillator with an amplitude
 * keeps its place and takes the speed, off its cycle. */
static void lat_set_speed(struct lat *l, int i, double v)
{
	if (l->dim == 2) {
		l->y[2 * i + 1] = v;
		return;
	}
	double x = l->amp * cos(l->y[i]);
	l->y[i] = atan2(-v / l->omega, x);
}

/* Applies the impact at contact k now. */
static void lat_collide(struct lat *l, int k, struct lat_event *ev)
{
	memset(ev, 0, sizeof *ev);
	ev->t = l->t;
	ev->contact = k;
	ev->delta_before = ev->delta_after = ev->dsep_before = NAN;
	ev->x_left = k > 0 ? lat_x(l, l->y, k - 1) : NAN;
	ev->x_right = k < l->n ? lat_x(l, l->y, k) : NAN;
	if (k == 0 || k == l->n) {
		int i = k == 0 ? 0 : l->n - 1;
		double v = lat_v(l, l->y, i), w = collide_wall(l->r, v);
		l->neutral[i] += l->beta[i] * (0 - v);
		lat_set_speed(l, i, w);
		ev->left = k == 0 ? -1 : i;
		ev->right = k == 0 ? i : -1;
		ev->pre_left = k == 0 ? 0 : v;
		ev->pre_right = k == 0 ? v : 0;
		ev->post_left = k == 0 ? 0 : w;
		ev->post_right = k == 0 ? w : 0;
		ev->impulse = fabs(w - v);
	} else {
		int i = k - 1, j = k;
		double vi = lat_v(l, l->y, i), vj = lat_v(l, l->y, j), pi_, pj;
		ev->delta_before = phase_wrap(lat_phi(l, l->y, j) - lat_phi(l, l->y, i));
		ev->dsep_before = (l->neutral[j] - l->neutral[i]) / (2 * l->amp);
		collide_pair(l->r, vi, vj, &pi_, &pj);
		l->neutral[i] += l->beta[i] * (vj - vi);
		l->neutral[j] += l->beta[j] * (vi - vj);
		lat_set_speed(l, i, pi_);
		lat_set_speed(l, j, pj);
		ev->left = i;
		ev->right = j;
		ev->pre_left = vi;
		ev->pre_right = vj;
		ev->post_left = pi_;
		ev->post_right = pj;
		ev->impulse = fabs(pi_ - vi);
		ev->delta_after = phase_wrap(lat_phi(l, l->y, j) - lat_phi(l, l->y, i));
	}
	lat_jumped(l);
	lat_mark_neighbours(l, k);
}

/* After a jump: a neighbouring pair found overlapping and approaching
 * collides now. 1 with *ev filled, 0 when none. */
static int lat_pending(struct lat *l, struct lat_event *ev)
{
	if (!l->any_pending)
		return 0;
	for (int k = 0; k <= l->n; k++) {
		if (!l->pending[k])
			continue;
		l->pending[k] = false;
		/* <= 0: a neighbour that reached contact at the very instant of
		 * this impact (a symmetric row) would otherwise pass unseen, its
		 * gap not > 0 at the next step's start */
		if (!(lat_gap(l, l->y, k) <= 0))
			continue;
		if (l->t != l->immediate_t) {
			l->immediate_t = l->t;
			l->immediate_n = 0;
		}
		if (lat_gap_rate(l, l->y, k) < 0 && l->immediate_n < LAT_IMMEDIATE_PER_OSC * l->n) {
			l->immediate_n++;
			lat_collide(l, k, ev);
			ev->immediate = true;
			return 1;
		}
		l->overlaps++;
	}
	l->any_pending = false;
	return 0;
}

enum lat_status lat_advance(struct lat *l, double t_stop, struct lat_event *ev, char *err, size_t errcap)
{
	if (lat_pending(l, ev))
		return LAT_COLLISION;
	while (l->t < t_stop) {
		double t0 = l->t;
		memcpy(l->y0, l->y, lat_len(l) * sizeof *l->y0);
		double t1 = fmin(t_stop, t0 + l->hmax);
		int st = gsl_odeiv2_evolve_apply(l->evo, l->ctl, l->step, &l->sys, &l->t, t1, &l->h, l->y);
		if (st != GSL_SUCCESS) {
			lat_err(err, errcap, "the integrator failed at t = %.9g s: %s", t0, gsl_strerror(st));
			return LAT_FAILED;
		}
		l->steps++;
		if (l->h > l->hmax)
			l->h = l->hmax;
		int first = -1;
		double tfirst = l->t;
		for (int k = 0; k <= l->n; k++) {
			double tc;
			if (!lat_has_contact(l, k))
				continue;
			int found = lat_crossing(l, k, t0, l->t, &tc);
			if (found < 0) {
				lat_err(err, errcap, "locating a collision of contact %d failed near t = %.9g s", k, t0);
				return LAT_FAILED;
			}
			if (found && (first < 0 || tc < tfirst)) {
				first = k;
				tfirst = tc;
			}
		}
		if (first < 0)
			continue;
		if (lat_state_at(l, t0, tfirst) != 0) {
			lat_err(err, errcap, "the integrator failed at t = %.9g s", tfirst);
			return LAT_FAILED;
		}
		memcpy(l->y, l->ytmp, lat_len(l) * sizeof *l->y);
		l->t = tfirst;
		lat_collide(l, first, ev);
		return LAT_COLLISION;
	}
	return LAT_REACHED;
}

static int lat_check(const struct lat_params *p, char *err, size_t cap)
{
	if (p->n < 1 || p->n > LAT_MAX_OSC)
		return lat_err(err, cap, "oscillators: %d, not in 1..%d", p->n, LAT_MAX_OSC);
	if (!(p->frequency_hz > 0) || !isfinite(p->frequency_hz))
		return lat_err(err, cap, "frequency %g Hz: must be > 0", p->frequency_hz);
	if (!(p->amplitude > 0) || !isfinite(p->amplitude))
		return lat_err(err, cap, "amplitude %g: must be > 0", p->amplitude);
	if (!(p->restitution >= 0 && p->restitution <= 1))
		return lat_err(err, cap, "restitution %g: must be in [0, 1]", p->restitution);
	if (!(p->dsep >= 0) || !isfinite(p->dsep))
		return lat_err(err, cap, "separation d~ %g: must be >= 0", p->dsep);
	if (p->walls && (!(p->wall_dsep >= 0) || !isfinite(p->wall_dsep)))
		return lat_err(err, cap, "wall separation %g: must be >= 0", p->wall_dsep);
	if (!(p->amplitude_rate >= 0 && p->amplitude_rate <= LAT_AMPLITUDE_RATE_MAX))
		return lat_err(err, cap, "amplitude rate %g /s: must be in [0, %g] (0: the phase model)", p->amplitude_rate,
		               LAT_AMPLITUDE_RATE_MAX);
	if (!(p->tolerance >= 0 && p->tolerance < 1e-3))
		return lat_err(err, cap, "tolerance %g: must be in [0, 1e-3)", p->tolerance);
	for (int i = 0; p->beta && i < p->n; i++)
		if (!(p->beta[i] >= 0) || !isfinite(p->beta[i]))
			return lat_err(err, cap, "mobility beta of oscillator %d: %g, must be >= 0", i + 1, p->beta[i]);
	return 0;
}

static int lat_alloc(struct lat *l, char *err, size_t cap)
{
	size_t n = (size_t)l->n, len = lat_len(l), d = (size_t)l->dim;
	l->y = calloc(len, sizeof *l->y);
	l->neutral = calloc(n, sizeof *l->neutral);
	l->beta = calloc(n, sizeof *l->beta);
	l->y0 = calloc(len, sizeof *l->y0);
	l->ytmp = calloc(len, sizeof *l->ytmp);
	l->pending = calloc(n + 1, sizeof *l->pending);
	l->sys = (gsl_odeiv2_system){ .function = lat_rhs, .jacobian = NULL, .dimension = len, .params = l };
	/* rkf45 with error control: the phases' law is smooth; the steps are
	 * bounded by the period (LAT_STEPS_PER_PERIOD), not by accuracy */
	l->step = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rkf45, len);
	l->ctl = gsl_odeiv2_control_y_new(l->tol, l->tol);
	l->evo = gsl_odeiv2_evolve_alloc(len);
	l->drv = gsl_odeiv2_driver_alloc_y_new(&l->sys, gsl_odeiv2_step_rkf45, l->hmax / 4, l->tol, l->tol);
	l->root = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
	l->pair_sys[0] = (gsl_odeiv2_system){ .function = lat_rhs1, .dimension = d, .params = l };
	l->pair_sys[1] = (gsl_odeiv2_system){ .function = lat_rhs2, .dimension = 2 * d, .params = l };
	for (int m = 0; m < 2; m++)
		l->pair_drv[m] = gsl_odeiv2_driver_alloc_y_new(&l->pair_sys[m], gsl_odeiv2_step_rkf45, l->hmax / 4,
							       l->tol, l->tol);
	if (!l->pair_drv[0] || !l->pair_drv[1] || !l->y || !l->neutral || !l->beta || !l->y0 || !l->ytmp || !l->pending || !l->step || !l->ctl ||
	    !l->evo || !l->drv || !l->root)
		return lat_err(err, cap, "out of memory for %d oscillators", l->n);
	gsl_odeiv2_driver_set_hmax(l->drv, l->hmax);
	gsl_odeiv2_driver_set_hmax(l->pair_drv[0], l->hmax);
	gsl_odeiv2_driver_set_hmax(l->pair_drv[1], l->hmax);
	return 0;
}

struct lat *lat_new(const struct lat_params *p, const double *phase0, char *err, size_t errcap)
{
	if (lat_check(p, err, errcap) != 0)
		return NULL;
	/* GSL's default handler aborts; every status is checked here instead */
	gsl_set_error_handler_off();
	struct lat *l = calloc(1, sizeof *l);
	if (!l) {
		lat_err(err, errcap, "out of memory");
		return NULL;
	}
	l->n = p->n;
	l->dim = p->amplitude_rate > 0 ? 2 : 1;
	l->rate = p->amplitude_rate;
	l->omega = 2 * M_PI * p->frequency_hz;
	l->amp = p->amplitude;
	l->r = p->restitution;
	l->walls = p->walls;
	l->tol = p->tolerance > 0 ? p->tolerance : LAT_TOL_DEFAULT;
	l->hmax = 1.0 / (p->frequency_hz * LAT_STEPS_PER_PERIOD);
	l->h = l->hmax;
	l->immediate_t = NAN;
	if (lat_alloc(l, err, errcap) != 0) {
		lat_free(l);
		return NULL;
	}
	double d = 2 * p->amplitude * p->dsep;
	for (int i = 0; i < l->n; i++) {
		if (l->dim == 1) {
			l->y[i] = phase_wrap(phase0[i]);
		} else {
			/* on the cycle of amplitude A at that phase */
			l->y[2 * i] = l->amp * cos(phase0[i]);
			l->y[2 * i + 1] = -l->amp * l->omega * sin(phase0[i]);
		}
		l->neutral[i] = i * d;
		l->beta[i] = p->beta ? p->beta[i] : 0;
	}
	l->wall[0] = p->walls ? -2 * p->amplitude * p->wall_dsep : NAN;
	l->wall[1] = p->walls ? l->neutral[l->n - 1] + 2 * p->amplitude * p->wall_dsep : NAN;
	/* a row that starts overlapping: approaching pairs collide at once */
	for (int k = 0; k <= l->n; k++)
		l->pending[k] = lat_has_contact(l, k);
	l->any_pending = true;
	return l;
}

void lat_free(struct lat *l)
{
	if (!l)
		return;
	if (l->root)
		gsl_root_fsolver_free(l->root);
	if (l->drv)
		gsl_odeiv2_driver_free(l->drv);
	for (int m = 0; m < 2; m++)
		if (l->pair_drv[m])
			gsl_odeiv2_driver_free(l->pair_drv[m]);
	if (l->evo)
		gsl_odeiv2_evolve_free(l->evo);
	if (l->ctl)
		gsl_odeiv2_control_free(l->ctl);
	if (l->step)
		gsl_odeiv2_step_free(l->step);
	free(l->y);
	free(l->neutral);
	free(l->beta);
	free(l->y0);
	free(l->ytmp);
	free(l->pending);
	free(l);
}

double lat_time(const struct lat *l) { return l->t; }
int lat_count(const struct lat *l) { return l->n; }
double lat_omega(const struct lat *l) { return l->omega; }
double lat_phase(const struct lat *l, int i) { return lat_phi(l, l->y, i); }
double lat_displacement(const struct lat *l, int i) { return lat_x(l, l->y, i); }
double lat_amplitude(const struct lat *l, int i)
{
	double x = lat_x(l, l->y, i), v = lat_v(l, l->y, i) / l->omega;
	return l->dim == 1 ? l->amp : sqrt(x * x + v * v);
}
double lat_speed(const struct lat *l, int i) { return lat_v(l, l->y, i); }
double lat_neutral(const struct lat *l, int i) { return l->neutral[i]; }
double lat_wall(const struct lat *l, int right) { return l->wall[right ? 1 : 0]; }
int64_t lat_overlaps(const struct lat *l) { return l->overlaps; }
int64_t lat_steps(const struct lat *l) { return l->steps; }
int64_t lat_root_evals(const struct lat *l) { return l->root_evals; }

/* splitmix64 (Steele, Lea, Flood 2014): one 64-bit state, the same stream
 * on every machine and libc. */
static uint64_t lat_next(uint64_t *s)
{
	uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

static double lat_uniform_phase(uint64_t *s)
{
	return -M_PI + 2 * M_PI * (double)(lat_next(s) >> 11) * 0x1.0p-53;
}

/* Would oscillator i at phase phi overlap its left neighbour (or a wall)? */
static bool lat_draw_overlaps(const struct lat_params *p, const double *phase, int i, double phi)
{
	double d = 2 * p->amplitude * p->dsep, x = p->amplitude * cos(phi);
	if (i > 0 && i * d + x - ((i - 1) * d + p->amplitude * cos(phase[i - 1])) <= 0)
		return true;
	if (p->walls && i == 0 && x <= -2 * p->amplitude * p->wall_dsep)
		return true;
	if (p->walls && i == p->n - 1 && x >= 2 * p->amplitude * p->wall_dsep)
		return true;
	return false;
}

int lat_random_phases(const struct lat_params *p, uint64_t seed, double *phase)
{
	uint64_t s = seed;
	int left = 0;
	for (int i = 0; i < p->n; i++) {
		int tries = 0;
		do
			phase[i] = lat_uniform_phase(&s);
		while (lat_draw_overlaps(p, phase, i, phase[i]) && ++tries < LAT_DRAW_TRIES);
		left += tries >= LAT_DRAW_TRIES;
	}
	return left;
}
