/*
 * phase.h — the phase of a joint's oscillation and the running estimates of
 * its frequency and amplitude: one definition for the daemon (which publishes
 * them in every <robot>.STATE) and the analyser (which recomputes them from
 * logs and must agree with it). Pure code: no clock (t is an argument), no
 * I/O, no allocation.
 *
 * Phase. φ = atan2(−ẋ/ω, x), in (−π, π]: read clockwise in the (x, ẋ) plane,
 * the convention of the contact theory (theory.md). On x = A cos φ,
 * ẋ = −Aω sin φ it returns φ exactly, and φ grows with time. x is the angle
 * from the joint's neutral, ω the oscillation's angular frequency.
 *
 * Unknown stays unknown: without a usable ω (≤ 0: not measured yet) or with a
 * non-finite x or ẋ the phase is NAN, never a number that looks measured (the
 * daemon's old phase function gave 0; a 0 reads as "at the
 * positive turning point" and pairs with real phases). Consumers already skip
 * non-finite phases (undulate-top shows "-", the analyser leaves rows empty).
 */
#ifndef UNDULATE_COMMON_PHASE_H
#define UNDULATE_COMMON_PHASE_H

#include <stdbool.h>

/* Cycles the estimates are the median of: odd, and large enough that the one
 * or two cycles a collision's phase jump disturbs are outvoted. */
#define PHASE_CYCLES 5
/* Cycles the centre is the median of: three outvote one bent cycle and lag a
 * drifting centre by one cycle only (five would lag two, and the periods
 * measured while the lag builds up would outvote the good ones for longer). */
#define PHASE_CENTRE_CYCLES 3

/* Wrap an angle into (−π, π] (−π becomes π). Non-finite stays NAN. */
double phase_wrap(double a);

/* atan2(−v/omega, x) wrapped into (−π, π]; NAN unless x, v and omega are
 * finite and omega > 0. */
double phase_from_state(double x, double v, double omega);

/*
 * Running frequency and amplitude of one joint, sample by sample:
 * - cycles are counted at upward crossings of a centre (the median of the
 *   last PHASE_CENTRE_CYCLES cycles' mid-points between their extremes), not
 *   of zero, so a swing about a non-zero mean is measured too;
 * - a Schmitt trigger: up through centre + h, down through centre − h, then
 *   up through the centre is one cycle, h = max(0.02 rad, 0.1·amplitude)
 *   (four AX-12 position steps: quantization flicker never counts);
 * - crossing instants are interpolated between samples (at 100 Hz the grid
 *   alone would put ±5 ms on every period);
 * - frequency = 1 / the median of the last PHASE_CYCLES periods, amplitude =
 *   the median of their half peak-to-peaks: a collision's phase jump shortens
 *   or lengthens one period (two if it falls on a crossing); a running
 *   mean (newest cycle weighs 0.5, the daemon's own estimator until it took
 *   this one) lets one jump move the frequency by 16 % for cycles, the median
 *   not at all (test_common_phase). The first two crossings are timed
 *   against a guessed centre and give no period, so a frequency appears from
 *   the fourth crossing; a period shorter than PHASE_PERIOD_MIN_S is noise;
 * - stale: no crossing for three estimated periods (PHASE_MAX_PERIOD_S before
 *   one is known) and both estimates return to 0, the centre is searched
 *   anew: a stopped joint reads 0 Hz, not its last value.
 * Non-finite x or t, and t not increasing, are ignored and counted.
 */
#define PHASE_PERIOD_MIN_S 0.05
#define PHASE_MAX_PERIOD_S 10.0

struct phase_estimator {
	double frequency;       /* Hz; 0 until known */
	double amplitude;       /* rad, half peak-to-peak; 0 until known */
	unsigned long rejected; /* samples ignored: non-finite, or time not increasing */
	/* the rest is the estimator's own */
	double periods[PHASE_CYCLES];   /* s, ring of the last periods */
	double halves[PHASE_CYCLES];    /* rad, ring of the last half peak-to-peaks */
	double mids[PHASE_CENTRE_CYCLES]; /* rad, ring of the last cycles' mid-points */
	int nperiods, next_period, nhalves, next_half, nmids, next_mid;
	double last_x, last_t;
	double last_cross_t;
	double peak, trough;    /* extremes since the last upward crossing */
	double centre;          /* rad: crossings are counted about it */
	bool have_last, have_cross;
	bool centred;           /* centre comes from a whole cycle */
	bool last_cross_centred;/* the last crossing was timed against such a centre */
	bool high;              /* above centre + h since the last crossing */
	bool armed;             /* ... then below centre − h: the next upward crossing counts */
};

void phase_estimator_init(struct phase_estimator *e);
/* One sample: x in rad from neutral, t in s (strictly increasing). */
void phase_estimator_update(struct phase_estimator *e, double x, double t);
/* 2π·frequency (rad/s); 0 until known: what phase_from_state takes. */
double phase_estimator_omega(const struct phase_estimator *e);

#endif
