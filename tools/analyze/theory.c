/* theory.c — see theory.h. */
#include "theory.h"

#include <math.h>

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
