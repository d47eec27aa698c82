/*
 * params.h — the documented ranges of a robot's parameters (daemon/README.md,
 * "Commands"): one table for the daemon, which checks the configuration file
 * and every command against it, and for the programs that send commands
 * (undulate-top's nudges), so that what one offers the other never refuses
 * for a range of its own.
 */
#ifndef UNDULATE_COMMON_PARAMS_H
#define UNDULATE_COMMON_PARAMS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#define PARAM_PI 3.14159265358979323846
/* The AX-12's goal spans ±150° around its centre (raw 0..1023 over 300°):
 * no amplitude or neutral beyond it names an angle the servo can take. */
#define PARAM_SERVO_HALF_RANGE (150.0 * PARAM_PI / 180.0)

struct param_range { double min, max; bool min_open; };

struct param_def {
	const char *key;
	struct param_range range;
	bool joint;        /* per joint ([joint.N]) or per robot ([sinusoid]) */
	bool commandable;  /* a command may change it (never what bounds a joint) */
	const char *unit;  /* ASCII, as printed after a value ("N m/rad"); "" when none */
	double step;       /* what a monitor's +/- or a form's arrows change it by */
};

/* The parameter named key (k, c, mu, ..., amplitude, ...); NULL if none. */
const struct param_def *param_find(const char *key);
/* v inside r (NaN never is). */
bool param_in_range(const struct param_range *r, double v);
/* The i-th parameter of the table (0 ..), NULL past its end: for the
 * programs that list them (undulate-web serves them to its page). */
const struct param_def *param_at(size_t i);
/* "[0, 2.618]" or "(0, 0.5]": the range as every program's messages say it. */
char *param_range_format(const struct param_range *r, char *buf, size_t cap);
/* The parameters a command may change, as one JSON array of
 * {name, min, max, min_open, range, unit, step, per_joint}: what undulate-web
 * serves its page at /api/params, so that the page offers the daemon's names,
 * ranges, units and steps rather than a copy of its own. False on a write
 * error. */
bool param_table_json(FILE *f);

#endif
