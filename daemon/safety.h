/*
 * safety.h — the last word on every goal before it reaches the bus. Pure.
 * A goal is kept inside the intersection of the configured joint limits and
 * the servo's own angle limits, moves at most max_step per cycle, and a
 * non-finite number is replaced by a hold, never encoded.
 * Angles here are absolute servo radians (relative to the centre, raw 512).
 */
#ifndef UNDULATE_DAEMON_SAFETY_H
#define UNDULATE_DAEMON_SAFETY_H

#include <stdbool.h>
#include <stdint.h>

struct safety_limits {
	double lo, hi;       /* rad, absolute */
	double max_step;     /* rad per cycle */
};

enum safety_flag {
	SAFETY_NONFINITE = 1u << 0,   /* the desired goal was NaN/Inf: held instead */
	SAFETY_STEP      = 1u << 1,   /* limited by max_step */
	SAFETY_LIMIT     = 1u << 2,   /* limited by a joint or servo limit */
};

/* Intersect the configured limits (neutral + [limit_min, limit_max]) with the
 * servo's angle limits (raw cw..ccw). False if the intersection is empty or
 * the servo is in wheel mode (both limits 0). */
bool safety_limits_make(struct safety_limits *out, double neutral, double limit_min, double limit_max,
                        uint16_t servo_cw, uint16_t servo_ccw, double max_step);
/* The same with the servo's limits already in radians (any servo model:
 * the caller converts its raw limits, so that a clamped goal converts back
 * inside them). False if the intersection is empty. */
bool safety_limits_make_rad(struct safety_limits *out, double neutral, double limit_min, double limit_max,
                            double servo_lo, double servo_hi, double max_step);

/* The goal to send. `previous` is the last goal sent (NaN if none: no step
 * bound), `fallback` what to hold when desired is not finite (normally the
 * measured angle; if that is not finite either, previous, then the middle of
 * the limits). *flags (may be NULL) gets SAFETY_* bits. Always finite and
 * inside [lo, hi]. */
double safety_clamp(const struct safety_limits *l, double desired, double previous, double fallback,
                    unsigned *flags);

#endif
