/* phase.c — see phase.h. */
#include "phase.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void phase_tracker_init(struct phase_tracker *tr)
{
	memset(tr, 0, sizeof(*tr));
	tr->last_cross_t = -1.0;
}

static void tracker_add_period(struct phase_tracker *tr, double period)
{
	tr->periods[tr->next] = period;
	tr->next = (tr->next + 1) % PHASE_PERIODS;
	if (tr->nperiods < PHASE_PERIODS)
		tr->nperiods++;
}

void phase_tracker_feed(struct phase_tracker *tr, double t, double angle)
{
	if (!isfinite(angle) || !isfinite(t))
		return;
	if (angle < -PHASE_HYSTERESIS)
		tr->armed = true;
	if (tr->have_prev && tr->armed && tr->prev_x < 0.0 && angle >= 0.0 && t > tr->prev_t) {
		/* Linear interpolation of the crossing instant: at 100 Hz the
		 * sample grid alone would put +-5 ms of noise on every period. */
		double tc = tr->prev_t + (t - tr->prev_t) * (-tr->prev_x) / (angle - tr->prev_x);
		if (tr->last_cross_t >= 0.0) {
			double period = tc - tr->last_cross_t;
			if (period >= PHASE_PERIOD_MIN_S && period <= PHASE_PERIOD_MAX_S) {
				tracker_add_period(tr, period);
				tr->amplitude = 0.5 * (tr->cyc_max - tr->cyc_min);
			}
		}
		tr->last_cross_t = tc;
		tr->armed = false;
		tr->cyc_min = tr->cyc_max = angle;
	}
	if (tr->last_cross_t >= 0.0) {
		if (angle < tr->cyc_min)
			tr->cyc_min = angle;
		if (angle > tr->cyc_max)
			tr->cyc_max = angle;
	}
	tr->have_prev = true;
	tr->prev_t = t;
	tr->prev_x = angle;
}

void phase_swing_init(struct phase_swing *s)
{
	*s = (struct phase_swing){ .lo = 0.0, .hi = 0.0, .n = 0 };
}

void phase_swing_add(struct phase_swing *s, double angle)
{
	if (!isfinite(angle))
		return;
	if (s->n == 0 || angle < s->lo)
		s->lo = angle;
	if (s->n == 0 || angle > s->hi)
		s->hi = angle;
	s->n++;
}

double phase_swing_pp(const struct phase_swing *s)
{
	return s->n > 0 ? s->hi - s->lo : NAN;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

double phase_tracker_omega(const struct phase_tracker *tr)
{
	double sorted[PHASE_PERIODS];
	if (tr->nperiods == 0)
		return 0.0;
	memcpy(sorted, tr->periods, sizeof(double) * (size_t)tr->nperiods);
	qsort(sorted, (size_t)tr->nperiods, sizeof(double), cmp_double);
	return 2.0 * M_PI / sorted[tr->nperiods / 2];
}

double phase_wrap(double a)
{
	if (!isfinite(a))
		return a;
	a = fmod(a, 2.0 * M_PI);
	if (a <= -M_PI)
		a += 2.0 * M_PI;
	else if (a > M_PI)
		a -= 2.0 * M_PI;
	return a;
}

double phase_from_state(double angle, double speed, double omega)
{
	if (!(omega > 0.0) || !isfinite(angle) || !isfinite(speed))
		return NAN;
	return phase_wrap(atan2(-speed / omega, angle));
}

void phase_circ_add(struct phase_circ *c, double a)
{
	if (!isfinite(a))
		return;
	c->sum_cos += cos(a);
	c->sum_sin += sin(a);
	c->sum_abs += fabs(phase_wrap(a));
	c->n++;
}

double phase_circ_mean(const struct phase_circ *c)
{
	return c->n ? atan2(c->sum_sin, c->sum_cos) : NAN;
}

double phase_circ_spread(const struct phase_circ *c)
{
	if (!c->n)
		return NAN;
	double r = hypot(c->sum_cos, c->sum_sin) / (double)c->n;
	if (r >= 1.0)
		return 0.0;
	if (r <= 0.0)
		return INFINITY;
	return sqrt(-2.0 * log(r));
}

double phase_circ_mean_abs(const struct phase_circ *c)
{
	return c->n ? c->sum_abs / (double)c->n : NAN;
}

double phase_return_map(double delta, double dsep, double r)
{
	double h = 0.5 * phase_wrap(delta);
	double s = sin(h);
	if (s == 0.0 && dsep <= 0.0)
		return 0.0; /* in phase on the same spot: the fixed point itself */
	if (fabs(s) < dsep || s == 0.0)
		return NAN;
	double k = asin(dsep / s);
	double sk = sin(k), ck = cos(k), sh = sin(h), ch = cos(h);
	/* theory.md's closed form, each term the new phase of one body. atan2
	 * instead of theory.md's atan: the terms are phases of points in the
	 * (x, -x'/w) plane, and atan would fold them into (-pi/2, pi/2) and map
	 * the anti-phase fixed point pi to 0. */
	double right = atan2(sk * ch - r * ck * sh, ck * ch - sk * sh);
	double left = atan2(sk * ch + r * ck * sh, ck * ch + sk * sh);
	return phase_wrap(right - left);
}

double phase_return_map_d0(double delta0, double r, int n)
{
	/* Iterating the map's d~ = 0 form delta' = -2 atan(r tan(delta/2)) gives
	 * tan(delta_n/2) = (-r)^n tan(delta_0/2); theory.md prints the result
	 * with an extra minus sign, which would make n = 0 return -delta_0. */
	return 2.0 * atan(pow(-r, n) * tan(0.5 * delta0));
}

double phase_compat_limit(double dsep)
{
	if (!(dsep >= 0.0))
		return NAN;
	return dsep >= 1.0 ? M_PI : 2.0 * asin(dsep);
}
