/* mdl_pairmap.c — the return map, one collision at a time (mdl_pairmap.h). */
#include "mdl_pairmap.h"

#include <math.h>

#include "mdl_lattice.h"

void pmap_start(double delta, double phase[2])
{
	/* g = 2A d~ - 2A sin(theta) sin(delta/2) for phases theta -+ delta/2:
	 * widest at theta = -pi/2 sign(sin(delta/2)) */
	double theta = sin(0.5 * delta) < 0 ? M_PI / 2 : -M_PI / 2;
	phase[0] = theta - 0.5 * delta;
	phase[1] = theta + 0.5 * delta;
}

int pmap_step(double dsep, double r, double delta, double tol, struct pmap_result *out, char *err, size_t errcap)
{
	struct lat_params p = {
		.n = 2, .frequency_hz = 1, .amplitude = 1, .restitution = r, .dsep = dsep, .tolerance = tol,
	};
	double phase[2];
	pmap_start(delta, phase);
	struct lat *l = lat_new(&p, phase, err, errcap);
	if (!l)
		return -1;
	struct lat_event ev;
	enum lat_status st = lat_advance(l, PMAP_PERIODS, &ev, err, errcap);
	out->collided = st == LAT_COLLISION;
	out->delta_before = st == LAT_COLLISION ? ev.delta_before : delta;
	out->delta_after = st == LAT_COLLISION ? ev.delta_after : NAN;
	out->t = st == LAT_COLLISION ? ev.t : NAN;
	lat_free(l);
	return st == LAT_FAILED ? -1 : 0;
}
