/* window.c — see window.h. */
#include "window.h"

#include <math.h>

#include "phase.h"

void win_swing_init(struct win_swing *s)
{
	*s = (struct win_swing){ .lo = 0.0, .hi = 0.0, .n = 0 };
}

void win_swing_add(struct win_swing *s, double angle)
{
	if (!isfinite(angle))
		return;
	if (s->n == 0 || angle < s->lo)
		s->lo = angle;
	if (s->n == 0 || angle > s->hi)
		s->hi = angle;
	s->n++;
}

double win_swing_pp(const struct win_swing *s)
{
	return s->n > 0 ? s->hi - s->lo : NAN;
}

void win_circ_add(struct win_circ *c, double a)
{
	if (!isfinite(a))
		return;
	c->sum_cos += cos(a);
	c->sum_sin += sin(a);
	c->sum_abs += fabs(phase_wrap(a));
	c->n++;
}

double win_circ_mean(const struct win_circ *c)
{
	return c->n ? atan2(c->sum_sin, c->sum_cos) : NAN;
}

double win_circ_spread(const struct win_circ *c)
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

double win_circ_mean_abs(const struct win_circ *c)
{
	return c->n ? c->sum_abs / (double)c->n : NAN;
}
