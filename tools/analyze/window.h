/* window.h — statistics of angles over a span of samples (the final window
 * the end state is decided on): how far a joint swings, and the circular mean
 * and spread of a pair's phase differences. Pure code: no I/O, no clock. */
#ifndef UNDULATE_ANALYZE_WINDOW_H
#define UNDULATE_ANALYZE_WINDOW_H

#include <stdint.h>

/* Peak-to-peak of a joint's measured angle: a joint that does not swing has
 * no phase worth comparing. */
struct win_swing {
	double lo, hi;   /* rad, extremes seen */
	int64_t n;       /* finite samples seen */
};

void win_swing_init(struct win_swing *s);
/* Adds one angle (rad); a non-finite angle is not a measurement and is ignored. */
void win_swing_add(struct win_swing *s, double angle);
/* hi - lo (rad); NAN before the first finite sample. */
double win_swing_pp(const struct win_swing *s);

/* Circular statistics of angles (zero-initialise to start); non-finite
 * angles are ignored. */
struct win_circ {
	double sum_cos, sum_sin, sum_abs;
	int64_t n;
};
void win_circ_add(struct win_circ *c, double a);
double win_circ_mean(const struct win_circ *c);   /* NAN if empty */
/* Circular standard deviation sqrt(-2 ln R) (rad); NAN if empty. */
double win_circ_spread(const struct win_circ *c);
/* Mean of |a| with a wrapped into (-pi, pi]; NAN if empty. */
double win_circ_mean_abs(const struct win_circ *c);

#endif
