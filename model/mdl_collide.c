/* mdl_collide.c — the inelastic impact (mdl_collide.h). */
#include "mdl_collide.h"

void collide_pair(double r, double v_left, double v_right, double *post_left, double *post_right)
{
	*post_left = 0.5 * ((1 - r) * v_left + (1 + r) * v_right);
	*post_right = 0.5 * ((1 - r) * v_right + (1 + r) * v_left);
}

double collide_wall(double r, double v)
{
	return -r * v;
}

double collide_energy(double v_left, double v_right)
{
	return 0.5 * (v_left * v_left + v_right * v_right);
}
