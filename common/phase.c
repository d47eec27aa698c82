/* phase.c — see phase.h. */
#include "phase.h"

#include <math.h>
#include <string.h>

#define PHASE_PI 3.14159265358979323846

/* Hysteresis about the centre: at least four AX-12 position steps (0.29°
 * each) so quantization flicker near the centre never counts twice, and a
 * tenth of the amplitude so sensor noise does not. */
#define PHASE_HYST_MIN 0.02
#define PHASE_HYST_FRAC 0.1
/* No upward crossing for this many estimated periods: the joint stopped or
 * its centre moved beyond the swing. */
#define PHASE_STALE_PERIODS 3.0
/* Before the first whole cycle the extremes seen so far set the centre; they
 * fade towards the present angle with this time constant so that a value
 * held while the joint was stopped does not pin the centre outside the swing. */
#define PHASE_FADE_S 1.0

double phase_wrap(double a)
{
	if (!isfinite(a))
		return NAN;
	/* remainder is exact and lands in [−π, π] in one step, for any size of a */
	double w = remainder(a, 2.0 * PHASE_PI);
	if (w <= -PHASE_PI)
		w += 2.0 * PHASE_PI;
	return w;
}

double phase_from_state(double x, double v, double omega)
{
	if (!isfinite(x) || !isfinite(v) || !isfinite(omega) || !(omega > 0.0))
		return NAN;
	/* atan2 gives −π for (−0, x < 0): the wrap makes it π */
	return phase_wrap(atan2(-v / omega, x));
}

/* Median of n values (1..PHASE_CYCLES), without changing them. */
static double phase_median(const double *values, int n)
{
	double v[PHASE_CYCLES];
	for (int i = 0; i < n; i++) {
		int k = i;
		for (; k > 0 && v[k - 1] > values[i]; k--)
			v[k] = v[k - 1];
		v[k] = values[i];
	}
	return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static void phase_ring_add(double *ring, int *n, int *next, double value)
{
	ring[*next] = value;
	*next = (*next + 1) % PHASE_CYCLES;
	if (*n < PHASE_CYCLES)
		(*n)++;
}

void phase_estimator_init(struct phase_estimator *e)
{
	memset(e, 0, sizeof *e);
	e->peak = -INFINITY;
	e->trough = INFINITY;
}

double phase_estimator_omega(const struct phase_estimator *e)
{
	return 2.0 * PHASE_PI * e->frequency;
}

/* An upward crossing of the centre at time tc closes one cycle. */
static void phase_estimator_cross(struct phase_estimator *e, double tc)
{
	bool timed_ok = e->centred;
	if (e->have_cross && tc > e->last_cross_t) {
		double period = tc - e->last_cross_t;
		/* a period from a crossing timed against the first-cycle guess of the
		 * centre is skewed: skip it */
		if (timed_ok && e->last_cross_centred && period >= PHASE_PERIOD_MIN_S) {
			phase_ring_add(e->periods, &e->nperiods, &e->next_period, period);
			e->frequency = 1.0 / phase_median(e->periods, e->nperiods);
		}
		/* peak and trough cover a whole cycle only after the first crossing */
		phase_ring_add(e->halves, &e->nhalves, &e->next_half, 0.5 * (e->peak - e->trough));
		e->mids[e->next_mid] = 0.5 * (e->peak + e->trough);
		e->next_mid = (e->next_mid + 1) % PHASE_CENTRE_CYCLES;
		if (e->nmids < PHASE_CENTRE_CYCLES)
			e->nmids++;
		e->amplitude = phase_median(e->halves, e->nhalves);
		/* the centre too: a cycle bent by a collision would otherwise time
		 * the next crossing wrong and disturb a second period */
		e->centre = phase_median(e->mids, e->nmids);
		e->centred = true;
	}
	e->last_cross_t = tc;
	e->last_cross_centred = timed_ok;
	e->have_cross = true;
	e->high = false;
	e->armed = false;
}

static void phase_estimator_restart(struct phase_estimator *e, double x)
{
	e->frequency = 0.0;
	e->amplitude = 0.0;
	e->nperiods = e->next_period = e->nhalves = e->next_half = e->nmids = e->next_mid = 0;
	e->have_cross = false;
	e->centred = false;
	e->last_cross_centred = false;
	e->high = false;
	e->armed = false;
	e->peak = x;
	e->trough = x;
}

void phase_estimator_update(struct phase_estimator *e, double x, double t)
{
	if (!isfinite(x) || !isfinite(t) || (e->have_last && !(t > e->last_t))) {
		e->rejected++;
		return;
	}
	if (e->have_cross) {
		double stale = e->frequency > 0.0 ? PHASE_STALE_PERIODS / e->frequency : PHASE_MAX_PERIOD_S;
		if (t - e->last_cross_t > stale)
			phase_estimator_restart(e, x);
	}
	double hyst = fmax(PHASE_HYST_MIN, PHASE_HYST_FRAC * e->amplitude);
	if (x > e->peak)
		e->peak = x;
	if (x < e->trough)
		e->trough = x;
	if (!e->have_cross) {
		if (e->have_last) {
			double keep = exp(-(t - e->last_t) / PHASE_FADE_S);
			e->peak = x + (e->peak - x) * keep;
			e->trough = x + (e->trough - x) * keep;
		}
		e->centre = 0.5 * (e->peak + e->trough);   /* no whole cycle yet */
	}
	/* a centre that moved at the last crossing cannot make a second one: the
	 * trigger is disarmed there */
	if (x > e->centre + hyst)
		e->high = true;
	if (e->high && x < e->centre - hyst)
		e->armed = true;
	if (e->have_last && e->armed && e->last_x < e->centre && x >= e->centre) {
		double tc = e->last_t + (t - e->last_t) * (e->centre - e->last_x) / (x - e->last_x);
		phase_estimator_cross(e, tc);
		e->peak = x;
		e->trough = x;
	}
	e->last_x = x;
	e->last_t = t;
	e->have_last = true;
}
