/* params.c — see params.h. */
#include "params.h"

#include <string.h>

/* The ranges are physical: an AX-12 joint's link has an inertia of order
 * 1e-3 kg·m² and a stall torque of 1.5 N·m, so a law's spring of more than
 * 10 N·m/rad or an inertia below 1e-5 (the oscillator then asks for
 * accelerations the servo cannot give and one control period cannot
 * integrate) is a typo, not a tuning. */
static const struct param_def param_defs[] = {
	{ "k",         { 1e-4, 10.0, false }, true, true },
	{ "c",         { -1.0, 1.0, false }, true, true },
	{ "mu",        { 0.0, 100.0, false }, true, true },
	{ "lambda",    { -10.0, 10.0, false }, true, true },
	{ "inertia",   { 1e-5, 1.0, false }, true, true },
	{ "friction",  { 0.0, 1.0, false }, true, true },
	{ "coupling_phase", { -PARAM_PI, PARAM_PI, false }, true, true },
	{ "neutral",   { -PARAM_SERVO_HALF_RANGE, PARAM_SERVO_HALF_RANGE, false }, true, false },
	{ "limit_min", { -2.0 * PARAM_SERVO_HALF_RANGE, 2.0 * PARAM_SERVO_HALF_RANGE, false }, true, false },
	{ "limit_max", { -2.0 * PARAM_SERVO_HALF_RANGE, 2.0 * PARAM_SERVO_HALF_RANGE, false }, true, false },
	{ "max_step",  { 0.0, 0.5, true }, true, false },
	{ "amplitude", { 0.0, PARAM_SERVO_HALF_RANGE, false }, false, true },
	{ "frequency", { 0.0, 5.0, false }, false, true },
	{ "phase",     { -2.0 * PARAM_PI, 2.0 * PARAM_PI, false }, false, true },
	/* the clock as a torque law: the paper's 0.015..0.135 N·m/rad and far
	 * beyond (the position loop's own stiffness is 9.2 N·m/rad); 0 = off */
	{ "stiffness", { 0.0, 10.0, false }, false, true },
	{ "damping",   { 0.0, 1.0, false }, false, true },
};
#define PARAM_NDEFS (sizeof param_defs / sizeof param_defs[0])

const struct param_def *param_find(const char *key)
{
	for (size_t i = 0; i < PARAM_NDEFS; i++)
		if (strcmp(key, param_defs[i].key) == 0)
			return &param_defs[i];
	return NULL;
}

bool param_in_range(const struct param_range *r, double v)
{
	if (r->min_open ? !(v > r->min) : !(v >= r->min))
		return false;
	return v <= r->max;
}
