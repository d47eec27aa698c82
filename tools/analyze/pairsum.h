/* pairsum.h — one pair's object in summary.json's "pairs" (README.md,
 * "End states"): undulate-analyze writes it from a log, undulate-model from
 * its run, through this one writer, so that the two agree field by field and
 * the figures read either. Pure code: no I/O beyond the json writer. */
#ifndef UNDULATE_ANALYZE_PAIRSUM_H
#define UNDULATE_ANALYZE_PAIRSUM_H

#include <stdint.h>

#include "json.h"
#include "window.h"

struct pairsum {
	const char *name;           /* "left:right", "r1:r2" */
	const char *kind;           /* "neighbour", ... */
	const char *cls;            /* the end state (classify.h) */
	const struct win_circ *win; /* the phase differences of the final window */
	int64_t collisions, contacts, win_collisions;
	double win_impulse, win_contact_impulse, impulse;   /* N·s */
	double distance, amplitude; /* m: between the bases, lateral swing */
	double dsep;                /* d~; compat_limit follows from it (theory.h) */
	int64_t return_map_points;
	double swing_a, swing_b;    /* rad peak-to-peak in the final window */
};

void pairsum_json(struct json *j, const struct pairsum *s);

#endif
