/* theory.c — see theory.h. */
#include "theory.h"

#include <math.h>
#include <stdbool.h>

#include "phase.h"

double theory_return_map(double delta, double dsep, double r)
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

double theory_return_map_d0(double delta0, double r, int n)
{
	/* Iterating the map's d~ = 0 form delta' = -2 atan(r tan(delta/2)) gives
	 * tan(delta_n/2) = (-r)^n tan(delta_0/2); theory.md prints the result
	 * with an extra minus sign, which would make n = 0 return -delta_0. */
	return 2.0 * atan(pow(-r, n) * tan(0.5 * delta0));
}

double theory_compat_limit(double dsep)
{
	if (!(dsep >= 0.0))
		return NAN;
	return dsep >= 1.0 ? M_PI : 2.0 * asin(dsep);
}

double theory_antiphase_slope(double dsep, double r)
{
	if (!(dsep >= 0.0 && dsep <= 1.0 && r > 0.0 && r <= 1.0))
		return NAN;
	double d2 = dsep * dsep;
	return -(r * (d2 - 1.0) + d2) / (r * r * (d2 - 1.0) - d2);
}

double theory_critical_dsep(double r)
{
	if (!(r > 0.0 && r <= 1.0))
		return NAN;
	return sqrt(r * (r - 1.0) / (r * r - r - 2.0));
}

/* |f(delta)| - delta: its roots in (2 asin(d~), pi) are the third fixed
 * point; NAN where the pair cannot touch. */
static double theory_gain(double delta, double dsep, double r)
{
	return fabs(theory_return_map(delta, dsep, r)) - delta;
}

/* Steps of the scan for a sign change of theory_gain; bisection then halves
 * the bracket to double precision. The map is smooth between the limit and
 * pi, and its one root there is simple (checked by the unit test against
 * a finer scan). */
#define THEORY_SCAN_STEPS 2000
#define THEORY_BISECTIONS 60

double theory_third_fixed_point(double dsep, double r)
{
	double lo = theory_compat_limit(dsep);
	if (isnan(lo) || dsep >= 1.0 || !(r > 0.0 && r <= 1.0))
		return NAN;
	/* stay off both ends: each is a fixed point itself (a root of the gain) */
	double eps = 1e-6, a = lo + eps, b = M_PI - eps;
	double step = (b - a) / THEORY_SCAN_STEPS, x0 = a, g0 = theory_gain(a, dsep, r);
	for (int i = 1; i <= THEORY_SCAN_STEPS; i++) {
		double x1 = a + i * step, g1 = theory_gain(x1, dsep, r);
		if (g0 < 0.0 && g1 >= 0.0) {
			for (int k = 0; k < THEORY_BISECTIONS; k++) {
				double m = 0.5 * (x0 + x1);
				if (theory_gain(m, dsep, r) < 0.0)
					x0 = m;
				else
					x1 = m;
			}
			return 0.5 * (x0 + x1);
		}
		x0 = x1;
		g0 = g1;
	}
	return NAN;
}

double theory_iterate(double delta0, double dsep, double r, int max_n, int *n)
{
	double d = phase_wrap(delta0);
	int k = 0;
	for (; k < max_n; k++) {
		if (M_PI - fabs(d) < THEORY_SETTLED || fabs(d) < THEORY_SETTLED)
			break;
		double next = theory_return_map(d, dsep, r);
		if (isnan(next))
			break; /* inside the compatible set: no contact any more */
		/* at the limit the pair grazes: the collision changes nothing */
		bool grazing = fabs(next - d) < THEORY_SETTLED;
		d = next;
		if (grazing) {
			k++;
			break;
		}
	}
	if (n)
		*n = k;
	return d;
}
