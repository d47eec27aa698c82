/* params.c — see params.h. */
#include "params.h"

#include <stdio.h>
#include <string.h>

#include "json.h"

/* The ranges are physical: an AX-12 joint's link has an inertia of order
 * 1e-3 kg·m² and a stall torque of 1.5 N·m, so a law's spring of more than
 * 10 N·m/rad or an inertia below 1e-5 (the oscillator then asks for
 * accelerations the servo cannot give and one control period cannot
 * integrate) is a typo, not a tuning. */
/* unit: what a value is printed with (ASCII: a log, a terminal, JSON);
 * step: what undulate-top's +/- and the web page's arrows change it by, a
 * small fraction of the value that gives the paper's gait. */
static const struct param_def param_defs[] = {
	{ "k",         { 1e-4, 10.0, false }, true, true, "N m/rad", 0.005 },
	{ "c",         { -1.0, 1.0, false }, true, true, "N m s/rad", 0.002 },
	{ "mu",        { 0.0, 100.0, false }, true, true, "N m s/rad^3", 0.01 },
	{ "lambda",    { -10.0, 10.0, false }, true, true, "", 0.1 },
	{ "inertia",   { 1e-5, 1.0, false }, true, true, "kg m^2", 1e-4 },
	{ "friction",  { 0.0, 1.0, false }, true, true, "N m", 0.005 },
	{ "coupling_phase", { -PARAM_PI, PARAM_PI, false }, true, true, "rad", 0.1 },
	{ "neutral",   { -PARAM_SERVO_HALF_RANGE, PARAM_SERVO_HALF_RANGE, false }, true, false, "rad", 0.01 },
	{ "limit_min", { -2.0 * PARAM_SERVO_HALF_RANGE, 2.0 * PARAM_SERVO_HALF_RANGE, false }, true, false, "rad", 0.01 },
	{ "limit_max", { -2.0 * PARAM_SERVO_HALF_RANGE, 2.0 * PARAM_SERVO_HALF_RANGE, false }, true, false, "rad", 0.01 },
	{ "max_step",  { 0.0, 0.5, true }, true, false, "rad", 0.01 },
	{ "amplitude", { 0.0, PARAM_SERVO_HALF_RANGE, false }, false, true, "rad", 0.05 },
	{ "frequency", { 0.0, 5.0, false }, false, true, "Hz", 0.05 },
	{ "phase",     { -2.0 * PARAM_PI, 2.0 * PARAM_PI, false }, false, true, "rad", 0.1 },
	/* the clock as a torque law: the paper's 0.015..0.135 N·m/rad and far
	 * beyond (the position loop's own stiffness is 9.2 N·m/rad); 0 = off */
	{ "stiffness", { 0.0, 10.0, false }, false, true, "N m/rad", 0.005 },
	{ "damping",   { 0.0, 1.0, false }, false, true, "N m s/rad", 0.005 },
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

const struct param_def *param_at(size_t i)
{
	return i < PARAM_NDEFS ? &param_defs[i] : NULL;
}

/* Four significant digits: 150 degrees is 2.618 rad in every message, not
 * 2.61799 in one program's and 2.618 in another's. */
char *param_range_format(const struct param_range *r, char *buf, size_t cap)
{
	snprintf(buf, cap, "%s%.4g..%.4g", r->min_open ? ">" : "", r->min, r->max);
	return buf;
}

bool param_table_json(FILE *f)
{
	struct json j;
	char range[48];
	json_init(&j, f, 0);
	json_array_begin(&j);
	for (size_t i = 0; i < PARAM_NDEFS; i++) {
		const struct param_def *d = &param_defs[i];
		if (!d->commandable)
			continue;
		json_object_begin(&j);
		json_key(&j, "name");
		json_string(&j, d->key);
		json_key(&j, "min");
		json_number(&j, d->range.min);
		json_key(&j, "max");
		json_number(&j, d->range.max);
		json_key(&j, "min_open");
		json_bool(&j, d->range.min_open);
		json_key(&j, "range");
		json_string(&j, param_range_format(&d->range, range, sizeof range));
		json_key(&j, "unit");
		json_string(&j, d->unit);
		json_key(&j, "step");
		json_number(&j, d->step);
		json_key(&j, "per_joint");
		json_bool(&j, d->joint);
		json_object_end(&j);
	}
	json_array_end(&j);
	fputc('\n', f);
	return json_end(&j) && !ferror(f);
}
