/* classify.h — the end state of a neighbouring pair from a window of its
 * phase differences: the rules of undulate-analyze's summary (README.md,
 * "End states"), in one place so that every program that names a pair's end
 * state (undulate-analyze on a log, undulate-web live) names it the same way.
 * Pure code: no I/O, no clock. */
#ifndef UNDULATE_ANALYZE_CLASSIFY_H
#define UNDULATE_ANALYZE_CLASSIFY_H

#include <stdbool.h>
#include <stdint.h>

#include "window.h"

/* Thresholds (rad). The mean phase difference of a pair in step stays within
 * a few degrees; in anti-phase within ~0.3 rad of pi in the paper's runs; a
 * spread above CLS_SPREAD_MAX means "not locked". */
#define CLS_INPHASE_TOL 0.25
#define CLS_ANTI_TOL 0.5
#define CLS_SPREAD_MAX 0.5
/* Margin on 2 asin(d~) for sensor noise and the amplitude estimate. */
#define CLS_COMPAT_TOL 0.1
/* A pair that still touches in the window, locked within its bound, whose
 * collisions' impulse averages at most this force over the window (N) is
 * grazing its bound, not colliding: README.md, "End states", says how it
 * was chosen. */
#define CLS_GRAZE_FORCE_N 0.1

/* What the window says about one pair. */
struct cls_window {
	struct win_circ delta;     /* the pair's phase differences in the window */
	double swing_a, swing_b;   /* rad peak-to-peak of each contact joint; NAN: no finite angle */
	int64_t collisions;        /* collisions of the pair in the window */
	double impulse;            /* N·s of the pair's contacts in the window (impacts, and resting
				      contact when the log lists it; 0 or NAN: none or unknown) */
	double window_s;           /* the window's length, s (0: unknown: never "grazing") */
	double dsep;               /* d~; NAN when unknown */
	bool have_sim;             /* contact data exists (a simulator was heard) */
	double min_swing;          /* below it a joint does not swing (AN_MIN_SWING_DEFAULT) */
};

/* "not-oscillating", "no-data", "anti-phase", "grazing", "still-colliding", "in-phase",
 * "compatible", "locked-no-contact-data", "locked-beyond-compatibility" or
 * "unlocked" (a static string). */
const char *cls_end_state(const struct cls_window *w);

#endif
