/* classify.c — see classify.h. */
#include "classify.h"

#include <math.h>

#include "theory.h"

const char *cls_end_state(const struct cls_window *w)
{
	/* A joint at rest still has a phase (0 or pi from its sign, at the
	 * daemon's last frequency): two stopped robots would pass for in-phase
	 * or anti-phase. No phase relation means anything unless both swing.
	 * A stopped joint whose frequency went to 0 has no phase at all: the
	 * swing still says why, so it is asked first. */
	bool have_angles = isfinite(w->swing_a) && isfinite(w->swing_b);
	if (have_angles && (w->swing_a < w->min_swing || w->swing_b < w->min_swing))
		return "not-oscillating";
	if (w->delta.n == 0)
		return "no-data";
	/* NAN (no finite angle in the window) counts as not swinging */
	if (!(w->swing_a >= w->min_swing) || !(w->swing_b >= w->min_swing))
		return "not-oscillating";
	double mean = fabs(win_circ_mean(&w->delta));
	double spread = win_circ_spread(&w->delta);
	bool locked = spread <= CLS_SPREAD_MAX;
	if (locked && mean >= M_PI - CLS_ANTI_TOL)
		return "anti-phase";
	/* touching: an impact, or (with SIM.TRUTH's contacts) any contact impulse */
	if (w->collisions > 0 || (isfinite(w->impulse) && w->impulse > 0)) {
		bool within = isfinite(w->dsep) && mean <= theory_compat_limit(w->dsep) + CLS_COMPAT_TOL;
		bool light = w->window_s > 0 && isfinite(w->impulse) && w->impulse / w->window_s <= CLS_GRAZE_FORCE_N;
		return locked && within && light ? "grazing" : "still-colliding";
	}
	if (locked && mean <= CLS_INPHASE_TOL)
		return "in-phase";
	if (locked && isfinite(w->dsep) && mean <= theory_compat_limit(w->dsep) + CLS_COMPAT_TOL)
		return "compatible";
	if (!w->have_sim && locked)
		return "locked-no-contact-data";
	return locked ? "locked-beyond-compatibility" : "unlocked";
}
