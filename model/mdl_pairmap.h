/* mdl_pairmap.h — one step of a pair's return map, measured by the
 * integrator (mdl_lattice.h), not by theory.md's formula: two oscillators
 * at separation d~ and phase difference delta are started where their
 * bodies are furthest apart, and run until their first collision. What
 * `undulate-model map` prints and the tests hold against the closed forms.
 * Pure code. */
#ifndef UNDULATE_MODEL_PAIRMAP_H
#define UNDULATE_MODEL_PAIRMAP_H

#include <stddef.h>

/* Periods run before a pair is said not to touch: from the furthest-apart
 * start the first approach comes within one. */
#define PMAP_PERIODS 2.0

struct pmap_result {
	int collided;          /* 1: *_after valid; 0: no contact in PMAP_PERIODS */
	double delta_before;   /* phi_2 - phi_1 at the impact, (-pi, pi] */
	double delta_after;
	double t;              /* the impact's time from the start, s (f = 1 Hz) */
};

/* delta_{n+1} from delta_n = delta: 0 with *out, or -1 with err. tol: the
 * integrator's (0: its default). */
int pmap_step(double dsep, double r, double delta, double tol, struct pmap_result *out, char *err, size_t errcap);

/* The phases of a pair at phase difference delta whose bodies are furthest
 * apart (mean phase -pi/2 sign(sin(delta/2))): phase[0], phase[1]. */
void pmap_start(double delta, double phase[2]);

#endif
