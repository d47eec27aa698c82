/* phase.h — phase estimation, circular statistics and the contact theory
 * (theory.md) used by undulate-analyze. Pure code: no I/O, no clock. */
#ifndef UNDULATE_ANALYZE_PHASE_H
#define UNDULATE_ANALYZE_PHASE_H

#include <stdbool.h>
#include <stdint.h>

/* Periods kept for the median frequency estimate: odd, and large enough that
 * the one or two periods disturbed by a collision's phase jump are outvoted. */
#define PHASE_PERIODS 5

/* Zero-crossing hysteresis (rad): the angle must go below -this before the next
 * upward crossing counts, so sensor noise around zero is not a new period. */
#define PHASE_HYSTERESIS 0.02

/* Periods outside this range (s) are not oscillation periods (a stalled
 * joint, a burst of noise) and are ignored. */
#define PHASE_PERIOD_MIN_S 0.05
#define PHASE_PERIOD_MAX_S 20.0

/* Running phase estimator of one joint. */
struct phase_tracker {
	double periods[PHASE_PERIODS]; /* s, ring of the last measured periods */
	int nperiods;                  /* how many are valid (<= PHASE_PERIODS) */
	int next;                      /* ring write index */
	bool armed;                    /* angle went below -PHASE_HYSTERESIS */
	bool have_prev;
	double prev_t, prev_x;         /* previous sample (s, rad) */
	double last_cross_t;           /* s, last upward zero crossing; <0 none */
	double cyc_min, cyc_max;       /* angle extremes since that crossing */
	double amplitude;              /* rad, half peak-to-peak of the last full cycle; 0 unknown */
};

void phase_tracker_init(struct phase_tracker *tr);
/* Feed one sample (t in s, monotonic per joint). */
void phase_tracker_feed(struct phase_tracker *tr, double t, double angle);
/* Angular frequency (rad/s) from the median measured period; 0 if none yet. */
double phase_tracker_omega(const struct phase_tracker *tr);

/* Peak-to-peak of a joint's measured angle over a span of samples (the final
 * window): a joint that does not swing has no phase worth comparing. */
struct phase_swing {
	double lo, hi;   /* rad, extremes seen */
	int64_t n;       /* finite samples seen */
};

void phase_swing_init(struct phase_swing *s);
/* Adds one angle (rad); a non-finite angle is not a measurement and is ignored. */
void phase_swing_add(struct phase_swing *s, double angle);
/* hi - lo (rad); NAN before the first finite sample. */
double phase_swing_pp(const struct phase_swing *s);

/* atan2(-speed/omega, angle): phase read clockwise in the (x, x') plane, in
 * (-pi, pi]. NAN if omega <= 0. */
double phase_from_state(double angle, double speed, double omega);

/* Wrap to (-pi, pi]. */
double phase_wrap(double a);

/* Circular statistics of angles. */
struct phase_circ {
	double sum_cos, sum_sin, sum_abs;
	int64_t n;
};
void phase_circ_add(struct phase_circ *c, double a);
double phase_circ_mean(const struct phase_circ *c);   /* NAN if empty */
/* Circular standard deviation sqrt(-2 ln R) (rad); NAN if empty. */
double phase_circ_spread(const struct phase_circ *c);
double phase_circ_mean_abs(const struct phase_circ *c); /* mean of |a| */

/* theory.md's collision-to-collision return map: delta_{n+1} from delta_n
 * for normalized separation d (d~) and restitution r. NAN where no contact
 * is possible (|sin(delta/2)| < d~). */
double phase_return_map(double delta, double dsep, double r);
/* Closed form at d~ = 0: delta_n = 2 atan((-r)^n tan(delta0/2)), the map
 * iterated n times (see phase.c on theory.md's sign). */
double phase_return_map_d0(double delta0, double r, int n);
/* Compatibility limit 2 asin(d~) (pi for d~ >= 1). */
double phase_compat_limit(double dsep);

#endif
