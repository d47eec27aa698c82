/* planecsv.c — see planecsv.h. */
#include "planecsv.h"

#include <math.h>

/* Slack for a message stamped a hair before its mark (s): the simulator's
 * times are whole steps, turned to seconds through a double. */
#define PCSV_T_EPS 1e-9

void pcsv_sampler_init(struct pcsv_sampler *s, double every_s)
{
	s->every_s = every_s > 0 ? every_s : 0.0;
	s->next_t = -INFINITY;
}

bool pcsv_take(struct pcsv_sampler *s, double t)
{
	if (!isfinite(t) || t < s->next_t - PCSV_T_EPS)
		return false;
	if (s->every_s > 0)
		s->next_t = (floor(t / s->every_s + PCSV_T_EPS) + 1.0) * s->every_s;
	return true;
}

bool pcsv_robot_pose(const undulate_sim_link_t *links, int n, int robot, double *cx, double *cy,
		     double *heading)
{
	double sx = 0.0, sy = 0.0, ux = 0.0, uy = 0.0, first = NAN;
	int k = 0;
	for (int i = 0; i < n; i++) {
		if (links[i].robot != robot)
			continue;
		sx += links[i].x;
		sy += links[i].y;
		ux += cos(links[i].angle);
		uy += sin(links[i].angle);
		if (k++ == 0)
			first = links[i].angle;
	}
	if (k == 0)
		return false;
	*cx = sx / k;
	*cy = sy / k;
	/* the mean direction, unwrapped next to the first link's angle */
	*heading = first + remainder(atan2(uy, ux) - first, 2.0 * M_PI);
	return true;
}
