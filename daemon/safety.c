/* safety.c — see safety.h. */
#include "safety.h"

#include <math.h>

#include "dxl_table.h"

bool safety_limits_make(struct safety_limits *out, double neutral, double limit_min, double limit_max,
                        uint16_t servo_cw, uint16_t servo_ccw, double max_step)
{
	if (dxl_is_wheel_mode(servo_cw, servo_ccw) || servo_cw > servo_ccw)
		return false;
	/* The servo's limits are raw units; dxl_pos_to_rad() of them converts back
	 * to the same raw value, so a clamped goal never trips the angle-limit bit. */
	return safety_limits_make_rad(out, neutral, limit_min, limit_max, dxl_pos_to_rad(servo_cw),
	                              dxl_pos_to_rad(servo_ccw), max_step);
}

bool safety_limits_make_rad(struct safety_limits *out, double neutral, double limit_min, double limit_max,
                            double servo_lo, double servo_hi, double max_step)
{
	if (!isfinite(neutral) || !isfinite(limit_min) || !isfinite(limit_max) || !isfinite(max_step) ||
	    !(max_step > 0) || !isfinite(servo_lo) || !isfinite(servo_hi))
		return false;
	double lo = fmax(neutral + limit_min, servo_lo);
	double hi = fmin(neutral + limit_max, servo_hi);
	if (!(lo <= hi))
		return false;
	out->lo = lo;
	out->hi = hi;
	out->max_step = max_step;
	return true;
}

double safety_clamp(const struct safety_limits *l, double desired, double previous, double fallback,
                    unsigned *flags)
{
	unsigned f = 0;
	double goal = desired;
	if (!isfinite(goal)) {
		f |= SAFETY_NONFINITE;
		goal = isfinite(fallback) ? fallback : isfinite(previous) ? previous : 0.5 * (l->lo + l->hi);
	}
	if (isfinite(previous)) {
		if (goal > previous + l->max_step) {
			goal = previous + l->max_step;
			f |= SAFETY_STEP;
		} else if (goal < previous - l->max_step) {
			goal = previous - l->max_step;
			f |= SAFETY_STEP;
		}
	}
	/* Limits last: whatever happened above, the result is inside them. */
	if (goal < l->lo) {
		goal = l->lo;
		f |= SAFETY_LIMIT;
	} else if (goal > l->hi) {
		goal = l->hi;
		f |= SAFETY_LIMIT;
	}
	if (flags != NULL)
		*flags = f;
	return goal;
}
