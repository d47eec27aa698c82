/*
 * tune.c — see tune.h. The method and its numbers: daemon/CONTROL.md,
 * "Tuning on the robot".
 */
#include "tune.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "control.h"

/* Starting exponents of the plant's answer, f ∝ k^ef and A ∝ μ^(−ea): through
 * a position servo (CONTROL.md's tables: +10 % k gives +6.5 % f; A ≈ ∝ μ^−0.4),
 * and for the law's own torque (the bare equation: f ∝ √k, A ∝ 1/√μ). The
 * plant's own answers then correct them (tune_broyden). */
#define TUNE_EF_POSITION 0.66
#define TUNE_EA_POSITION 0.40
#define TUNE_EF_TORQUE 0.50
#define TUNE_EA_TORQUE 0.50
/* One update moves k by at most this factor, μ by at most TUNE_MU_STEP. */
#define TUNE_K_STEP 1.6
#define TUNE_MU_STEP 2.0
/* The search stays within these factors of the starting k and μ: beyond,
 * the law is not the one the defaults were designed as (μ → 0 leaves the
 * amplitude to the servo's limits), and the target is called out of reach.
 * k needs the room: a plant that needs a long lead runs fast with it (a
 * compliance slope of 128 ended at k × 0.22). */
#define TUNE_K_RANGE 10.0
#define TUNE_MU_RANGE 10.0
/* A joint short of amplitude with its μ at the floor: the lead grows by this. */
#define TUNE_LEAD_FEED 1.3
/* Two cycles agree: peak-to-peak and period within this of each other. */
#define TUNE_AGREE 0.03
/* A starter within this of a death already acted on is the same death. */
#define TUNE_DEAD_GRACE_S 2.0
/* Crossing hysteresis: a tenth of the last half peak-to-peak (5 % of the
 * peak-to-peak), at least this. */
#define TUNE_HYST_MIN 0.02
/* A sinusoid's peak speed uses at most this share of the servo's no-load
 * speed: the motor line leaves no torque for the load at its end. */
#define TUNE_SPEED_SHARE 0.9

double tune_needed_speed(double f, double a) { return 2.0 * M_PI * f * a; }

static void tune_window_reset(struct tune *t, double time)
{
	t->window_t0 = time;
	for (size_t i = 0; i < t->n; i++) {
		t->j[i].ncycles = 0;
		t->j[i].last_cycle_t = time;
	}
}

/* The plant's answer in logarithms, y = (log f, log A_1..A_n) against
 * u = (log k, log μ_1..μ_n), is nearly linear over the search: J = ∂y/∂u.
 * It starts as the design tables say (f ∝ k^ef, μ slows it a little; A_j ∝
 * μ_j^−ea) and Broyden's rank-one update corrects it from each change and
 * what the plant did: on a servo that runs at its speed limit the frequency
 * follows the amplitude (less μ, slower), which a fixed diagonal gets wrong. */
static void tune_jacobian_init(struct tune *t)
{
	size_t m = t->n + 1;
	for (size_t r = 0; r < m; r++)
		for (size_t c = 0; c < m; c++)
			t->jac[r][c] = 0.0;
	t->jac[0][0] = t->ef0;
	for (size_t i = 0; i < t->n; i++) {
		t->jac[0][i + 1] = -0.1 / (double)t->n;
		t->jac[i + 1][i + 1] = -t->ea0;
	}
}

static void tune_broyden(struct tune *t, const double *du, const double *dy)
{
	size_t m = t->n + 1;
	double dd = 0;
	for (size_t c = 0; c < m; c++)
		dd += du[c] * du[c];
	if (!(dd > 1e-6))
		return;
	for (size_t r = 0; r < m; r++) {
		double jd = 0;
		for (size_t c = 0; c < m; c++)
			jd += t->jac[r][c] * du[c];
		double e = (dy[r] - jd) / dd;
		if (!isfinite(e))
			return;
		for (size_t c = 0; c < m; c++)
			t->jac[r][c] += e * du[c];
	}
}

/* Solve J s = r (m ≤ CFG_MAX_JOINTS + 1) by Gaussian elimination with
 * partial pivoting. False when J is (nearly) singular. */
static bool tune_solve(const struct tune *t, const double *rhs, double *s)
{
	size_t m = t->n + 1;
	static double a[TUNE_M][TUNE_M + 1];
	for (size_t r = 0; r < m; r++) {
		for (size_t c = 0; c < m; c++)
			a[r][c] = t->jac[r][c];
		a[r][m] = rhs[r];
	}
	for (size_t c = 0; c < m; c++) {
		size_t p = c;
		for (size_t r = c + 1; r < m; r++)
			if (fabs(a[r][c]) > fabs(a[p][c]))
				p = r;
		if (!(fabs(a[p][c]) > 0.02))
			return false;
		for (size_t k = 0; k <= m; k++) {
			double x = a[c][k];
			a[c][k] = a[p][k];
			a[p][k] = x;
		}
		for (size_t r = 0; r < m; r++) {
			if (r == c)
				continue;
			double f = a[r][c] / a[c][c];
			for (size_t k = c; k <= m; k++)
				a[r][k] -= f * a[c][k];
		}
	}
	for (size_t r = 0; r < m; r++) {
		s[r] = a[r][m] / a[r][r];
		if (!isfinite(s[r]))
			return false;
	}
	return true;
}

bool tune_init(struct tune *t, const struct tune_opts *o, const struct cfg *cfg, const struct cfg_params *from,
               char *why, size_t cap)
{
	memset(t, 0, sizeof *t);
	t->opts = *o;
	if (from != NULL)
		t->ran = *from;
	else
		cfg_params_init(&t->ran, cfg);
	if (t->opts.max_s <= 0)
		t->opts.max_s = TUNE_DEFAULT_MAX_S;
	t->n = cfg->njoints;
	double f = o->target_freq, a = o->target_amp;
	if (!(f >= 0.1 && f <= 3.0)) {
		snprintf(why, cap, "target frequency %g Hz: choose 0.1 .. 3 Hz", f);
		return false;
	}
	if (!(a >= 0.05 && a <= 2.0)) {
		snprintf(why, cap, "target amplitude %g rad: choose 0.05 .. 2 rad", a);
		return false;
	}
	if (t->n == 0 || t->n > CFG_MAX_JOINTS) {
		snprintf(why, cap, "no joints to tune");
		return false;
	}
	double need = tune_needed_speed(f, a), vmax = TUNE_SPEED_SHARE * cfg->no_load_speed;
	if (need > vmax) {
		snprintf(why, cap,
		         "%.2f Hz at %.2f rad needs a peak speed of %.2f rad/s; the servo's no-load speed is %.2f rad/s "
		         "(no_load_speed, at 12 V) and a loaded joint gets at most about %.2f: at %.2f rad it reaches "
		         "about %.2f Hz, at %.2f Hz about %.2f rad", f, a, need, cfg->no_load_speed, vmax, a,
		         vmax / (2 * M_PI * a), f, vmax / (2 * M_PI * f));
		return false;
	}
	/* the configuration decides where a joint may go: the gait must fit
	 * inside every joint's limits, with room for the cycle's overshoot */
	for (size_t i = 0; i < t->n; i++) {
		const struct cfg_joint *jt = &cfg->joint[i];
		double room = fmin(-jt->limit_min, jt->limit_max) - 0.05;
		if (a > room) {
			snprintf(why, cap,
			         "target amplitude %.2f rad does not fit inside joint %zu's limits (%.2f .. %.2f rad "
			         "from neutral): at most %.2f rad, or widen limit_min/limit_max in the configuration",
			         a, i + 1, jt->limit_min, jt->limit_max, room > 0 ? room : 0.0);
			return false;
		}
		double step = tune_needed_speed(f, a) * cfg->period_ms * 1e-3;
		if (cfg->actuation == CFG_ACT_POSITION && step > 0.9 * jt->max_step) {
			snprintf(why, cap,
			         "%.2f Hz at %.2f rad moves a goal up to %.3f rad per %.0f ms cycle; joint %zu's max_step "
			         "is %.3f rad: raise max_step in the configuration or aim lower", f, a, step, cfg->period_ms,
			         i + 1, jt->max_step);
			return false;
		}
	}
	bool torque = cfg->actuation == CFG_ACT_TORQUE;
	t->k = 1.0;
	t->torque_actuation = torque;
	/* The search box: near where it started, and never where the
	 * configuration would refuse a value (the documented ranges, and the
	 * natural frequency one period integrates: cfg_joint_check) — the tuner
	 * sets parameters as a command would, so it is held to what a command
	 * may set, and the file it writes loads. */
	struct param_range kr, mr;
	cfg_param_range("k", &kr);
	cfg_param_range("mu", &mr);
	t->k_lo = 1.0 / TUNE_K_RANGE;
	t->k_hi = TUNE_K_RANGE;
	for (size_t i = 0; i < t->n; i++) {
		const struct osc_joint_params *jo = &t->ran.osc[i];
		double w = 2.0 * M_PI * CFG_MAX_NATURAL_HZ;
		t->k0[i] = jo->k;
		t->k_lo = fmax(t->k_lo, kr.min / jo->k);
		t->k_hi = fmin(t->k_hi, fmin(kr.max, 0.999 * w * w * jo->inertia) / jo->k);
		t->mu[i] = t->mu0[i] = jo->mu;
		t->mu_lo[i] = fmax(jo->mu / TUNE_MU_RANGE, mr.min);
		t->mu_hi[i] = fmin(jo->mu * TUNE_MU_RANGE, mr.max);
		t->j[i].cross_t = NAN;
		t->j[i].hyst = TUNE_HYST_MIN;
	}
	t->ef0 = torque ? TUNE_EF_TORQUE : TUNE_EF_POSITION;
	t->ea0 = torque ? TUNE_EA_TORQUE : TUNE_EA_POSITION;
	tune_jacobian_init(t);
	t->lead = t->ran.servo_lead_s;
	t->state = TUNE_STARTING;
	t->t0 = NAN;
	t->dead_t = NAN;
	t->supply_v = NAN;
	t->no_load_speed = cfg->no_load_speed;
	return true;
}

/* The crossing detector of one joint. Returns true when a cycle completed. */
static bool tune_track(struct tune *t, struct tune_joint *j, double time, double x, double v)
{
	bool done = false;
	if (!j->have_last) {
		j->have_last = true;
		j->hi = j->lo = x;
		j->vmax = fabs(v);
	}
	if (x > j->hi)
		j->hi = x;
	if (x < j->lo)
		j->lo = x;
	if (isfinite(v) && fabs(v) > j->vmax)
		j->vmax = fabs(v);
	if (x < j->centre - j->hyst)
		j->armed = true;
	if (j->armed && j->last_x < j->centre && x >= j->centre && time > j->last_t) {
		double tc = j->last_t + (time - j->last_t) * (j->centre - j->last_x) / (x - j->last_x);
		if (isfinite(j->cross_t) && j->cross_t >= t->window_t0 && j->ncycles < TUNE_MAX_WINDOW_CYCLES + 2) {
			int k = j->ncycles++;
			j->period[k] = tc - j->cross_t;
			j->p2p[k] = j->hi - j->lo;
			j->top[k] = j->hi;
			j->bottom[k] = j->lo;
			j->vpk[k] = j->vmax;
			j->start[k] = j->cross_t;
		}
		if (isfinite(j->cross_t)) {
			j->centre = 0.5 * (j->hi + j->lo);
			j->hyst = fmax(TUNE_HYST_MIN, 0.05 * (j->hi - j->lo));
			done = true;
		}
		j->cross_t = tc;
		j->hi = j->lo = x;
		j->vmax = isfinite(v) ? fabs(v) : 0;
		j->armed = false;
	}
	j->last_x = x;
	j->last_t = time;
	return done;
}

/* Cycles of joint i the window counts: those after the first (the transient
 * after a change; none dropped while confirming). */
static int tune_usable(const struct tune *t, size_t i)
{
	int skip = t->state == TUNE_CONFIRMING ? 0 : 1;
	return t->j[i].ncycles - skip;
}

static bool tune_agree(double a, double b) { return fabs(a / b - 1.0) <= TUNE_AGREE; }

/* Is the window complete? Every joint has two usable cycles that agree (or
 * one joint has waited TUNE_MAX_WINDOW_CYCLES). */
static bool tune_window_ready(const struct tune *t)
{
	bool all = true, any_full = false;
	for (size_t i = 0; i < t->n; i++) {
		const struct tune_joint *j = &t->j[i];
		int u = tune_usable(t, i);
		if (j->ncycles >= TUNE_MAX_WINDOW_CYCLES)
			any_full = true;
		if (u < 2) {
			all = false;
			continue;
		}
		int a = j->ncycles - 1, b = j->ncycles - 2;
		if (!tune_agree(j->p2p[a], j->p2p[b]) || !tune_agree(j->period[a], j->period[b]))
			all = false;
	}
	if (any_full)
		for (size_t i = 0; i < t->n; i++)
			if (tune_usable(t, i) < 2)
				return false;
	return all || any_full;
}

/* A joint whose motion is not a clean swing (clipped at a limit, or pushed
 * by its neighbour into a double hump) crosses its centre more than once a
 * cycle: its "cycles" come out short and small. Coupled joints share one
 * fundamental, so the window's frequency is the lowest joint's, and each
 * joint's amplitude is half its whole excursion over the last two such
 * periods (seen on the fast test plant: joint 1 read 2.05 Hz and 0.72 rad
 * while joint 2, clipped at 1.3 rad, read 1.0 Hz). */
static double tune_joint_freq(const struct tune_joint *j)
{
	int a = j->ncycles - 1, b = j->ncycles - 2;
	return 2.0 / (j->period[a] + j->period[b]);
}

static void tune_measure(const struct tune *t, struct tune_window *w)
{
	memset(w, 0, sizeof *w);
	const struct tune_joint *j0 = &t->j[0];
	w->freq = tune_joint_freq(j0);
	for (size_t i = 1; i < t->n; i++)
		w->freq = fmin(w->freq, tune_joint_freq(&t->j[i]));
	double e = fabs(w->freq / t->opts.target_freq - 1.0);
	double span = 2.0 / w->freq;
	for (size_t i = 0; i < t->n; i++) {
		const struct tune_joint *j = &t->j[i];
		int last = j->ncycles - 1;
		double end = j->start[last] + j->period[last], hi = -INFINITY, lo = INFINITY, vpk = 0;
		/* the cycles that end within the last two fundamental periods */
		for (int k = last; k >= 0 && end - j->start[k] <= 1.05 * span; k--) {
			hi = fmax(hi, j->top[k]);
			lo = fmin(lo, j->bottom[k]);
			vpk = fmax(vpk, j->vpk[k]);
		}
		if (!(hi >= lo)) {   /* a cycle longer than the span: its own */
			hi = j->top[last];
			lo = j->bottom[last];
			vpk = j->vpk[last];
		}
		w->amp[i] = 0.5 * (hi - lo);
		w->vpeak[i] = vpk;
		e = fmax(e, fabs(w->amp[i] / t->opts.target_amp - 1.0));
		w->mu[i] = t->mu[i];
	}
	w->lag_deg = NAN;
	if (t->n >= 2 && isfinite(t->j[1].cross_t) && isfinite(j0->cross_t)) {
		double period = 1.0 / w->freq;
		double d = fmod(t->j[1].cross_t - j0->cross_t, period);
		if (d < 0)
			d += period;
		w->lag_deg = 360.0 * d / period;
	}
	w->error = e;
	w->k = t->k;
	w->lead = t->lead;
}

static double tune_clamp(double v, double lo, double hi) { return v < lo ? lo : v > hi ? hi : v; }

static double tune_mean_amp(const struct tune *t, const struct tune_window *w)
{
	double s = 0;
	for (size_t i = 0; i < t->n; i++)
		s += w->amp[i];
	return s / (double)t->n;
}

/* "0.93 Hz, A 1.10/1.05 rad" */
static void tune_describe(const struct tune *t, const struct tune_window *w, char *buf, size_t cap)
{
	int n = snprintf(buf, cap, "%.3f Hz, A ", w->freq);
	for (size_t i = 0; i < t->n && n > 0 && (size_t)n < cap; i++)
		n += snprintf(buf + n, cap - (size_t)n, "%s%.3f", i ? "/" : "", w->amp[i]);
	if (n > 0 && (size_t)n < cap)
		n += snprintf(buf + n, cap - (size_t)n, " rad");
	if (n > 0 && (size_t)n < cap && isfinite(w->lag_deg))
		snprintf(buf + n, cap - (size_t)n, ", joint 2 behind joint 1 by %.0f deg", w->lag_deg);
}

static void tune_fail(struct tune *t, const char *why)
{
	t->state = TUNE_FAILED;
	snprintf(t->why, sizeof t->why, "%s", why);
}

/* The target is out of the plant's reach: the joints run as fast as they
 * can through it, and neither more k nor less μ gets more out of them. What
 * is in reach is judged from the joint furthest from the target amplitude in
 * the closest window: its peak speed, spent on the other target. */
static void tune_fail_unreachable(struct tune *t, const char *how)
{
	const struct tune_window *b = &t->best;
	char best[160];
	tune_describe(t, b, best, sizeof best);
	size_t weak = 0;
	for (size_t i = 1; i < t->n; i++)
		if (b->amp[i] < b->amp[weak])
			weak = i;
	double v = b->vpeak[weak], f = t->opts.target_freq, a = t->opts.target_amp;
	char why[TUNE_TEXT];
	if (v >= tune_needed_speed(f, a)) {
		/* Not the speed: the joints were fast enough and the parameters ran
		 * into the box around where the search started (two XC430-W150
		 * joints from the XL430's defaults: mu needed 10x and more) */
		snprintf(why, sizeof why,
		         "target not reached (%s), though joint %zu was fast enough (%.2f rad/s at most, %.2f needed): the "
		         "search stays within x%.0f of where it started; start it nearer (--set joint.N.k=, joint.N.mu=, "
		         "robot.servo_lead_s=). Closest: %s",
		         how, weak + 1, v, tune_needed_speed(f, a), TUNE_K_RANGE, best);
		tune_fail(t, why);
		return;
	}
	snprintf(why, sizeof why,
	         "target out of reach (%s): %.2f Hz at %.2f rad needs a peak speed of %.2f rad/s; joint %zu reached "
	         "%.2f rad/s at most, at %.2f rad. Closest: %s. Reachable at that speed: about %.2f Hz at %.2f rad, "
	         "or %.2f rad at %.2f Hz",
	         how, f, a, tune_needed_speed(f, a), weak + 1, v, b->amp[weak], best, v / (2 * M_PI * a), a,
	         v / (2 * M_PI * f), f);
	tune_fail(t, why);
}

/* Speed-limited: three windows in a row whose f·A stays put (within 3 %)
 * below the target's, while the updates asked for more. */
static bool tune_saturated(struct tune *t, const struct tune_window *w)
{
	static const int need = 3;
	double prod = w->freq * tune_mean_amp(t, w), want = t->opts.target_freq * t->opts.target_amp;
	if (!(prod < 0.95 * want)) {
		t->sat_count = 0;
		return false;
	}
	if (t->sat_count > 0 && fabs(prod / t->sat_prod - 1.0) <= 0.03)
		t->sat_count++;
	else {
		t->sat_count = 1;
		t->sat_prod = prod;
	}
	return t->sat_count >= need;
}

/* Every joint's peak speed within 15 % of the fastest's: a gait stuck short
 * of the target is then the servos' top speed, not one joint starved of
 * energy (which the lead can feed). */
static bool tune_same_speed(const struct tune *t, const struct tune_window *w)
{
	double lo = INFINITY, hi = 0;
	for (size_t i = 0; i < t->n; i++) {
		lo = fmin(lo, w->vpeak[i]);
		hi = fmax(hi, w->vpeak[i]);
	}
	return lo >= 0.85 * hi;
}

/* stuck: f·A has stayed put below the target's for windows (tune_saturated) */
static void tune_update(struct tune *t, const struct tune_window *w, bool stuck)
{
	double ft = t->opts.target_freq, at = t->opts.target_amp;
	size_t m = t->n + 1;
	double u[TUNE_M], y[TUNE_M], r[TUNE_M], step[TUNE_M];
	u[0] = log(t->k);
	y[0] = log(w->freq);
	r[0] = log(ft) - y[0];
	for (size_t i = 0; i < t->n; i++) {
		u[i + 1] = log(t->mu[i]);
		y[i + 1] = log(w->amp[i]);
		r[i + 1] = log(at) - y[i + 1];
	}
	if (t->have_prev) {
		double du[TUNE_M], dy[TUNE_M];
		for (size_t c = 0; c < m; c++) {
			du[c] = u[c] - t->prev_u[c];
			dy[c] = y[c] - t->prev_y[c];
		}
		tune_broyden(t, du, dy);
	}
	if (!tune_solve(t, r, step)) {
		/* the corrections made it singular: start again from the design */
		tune_jacobian_init(t);
		if (!tune_solve(t, r, step))
			for (size_t c = 0; c < m; c++)
				step[c] = 0;
	}
	for (size_t c = 0; c < m; c++) {
		t->prev_u[c] = u[c];
		t->prev_y[c] = y[c];
	}
	t->have_prev = true;
	/* a damped Newton step: scaled as a whole until every factor is within
	 * its step limit (clamping each alone would turn it: the k step was
	 * computed for μ steps that would not be taken) */
	double scale = 1.0;
	for (size_t c = 0; c < m; c++) {
		double lim = log(c == 0 ? TUNE_K_STEP : TUNE_MU_STEP);
		if (fabs(step[c]) * scale > lim)
			scale = lim / fabs(step[c]);
	}
	for (size_t c = 0; c < m; c++)
		step[c] *= scale;
	double kr = exp(step[0]);
	bool pinned = false;
	double k = tune_clamp(t->k * kr, t->k_lo, t->k_hi);
	pinned = pinned || (k != t->k * kr && fabs(w->freq / ft - 1.0) > TUNE_TOLERANCE);
	kr = k / t->k;
	t->k = k;
	char steps[200];
	int n = snprintf(steps, sizeof steps, "k x%.2f, mu x", kr);
	/* a joint short of amplitude with μ at its floor, or the gait stuck short
	 * of the target while the servo could go faster (the supply check above) */
	bool starved = false;
	for (size_t i = 0; i < t->n && stuck; i++)
		starved = starved || w->amp[i] < at * (1.0 - TUNE_TOLERANCE);
	for (size_t i = 0; i < t->n; i++) {
		double mr = exp(step[i + 1]);
		double mu = tune_clamp(t->mu[i] * mr, t->mu_lo[i], t->mu_hi[i]);
		bool clamped = mu != t->mu[i] * mr && fabs(w->amp[i] / at - 1.0) > TUNE_TOLERANCE;
		if (clamped && w->amp[i] < at && mu < t->mu0[i])
			starved = true;
		else
			pinned = pinned || clamped;
		mr = mu / t->mu[i];
		t->mu[i] = mu;
		if (n > 0 && (size_t)n < sizeof steps)
			n += snprintf(steps + n, sizeof steps - (size_t)n, "%s%.2f", i ? "/" : "", mr);
	}
	/* With μ at its floor the law has no more amplitude to give: what a
	 * joint still lacks, the loop loses to the servo's lag (a weak supply, a
	 * soft compliance slope). Under position actuation the horizon's lead
	 * feeds that energy back (CONTROL.md); when it is at its largest, the
	 * target is out of reach. */
	if (starved) {
		double lead = fmin(TUNE_MAX_LEAD_S, t->lead * TUNE_LEAD_FEED);
		if (t->torque_actuation || !(lead > t->lead + 1e-6))
			pinned = true;
		else {
			t->lead = lead;
			t->sat_count = 0;
			t->have_prev = false;   /* the plant changed under the Jacobian's feet */
			if (n > 0 && (size_t)n < sizeof steps)
				snprintf(steps + n, sizeof steps - (size_t)n, ", servo_lead_s -> %.3f s (%s)", t->lead,
				         stuck ? "the gait stays short" : "mu at its floor");
		}
	}
	t->pinned = pinned ? t->pinned + 1 : 0;
	char d[160];
	tune_describe(t, w, d, sizeof d);
	snprintf(t->progress, sizeof t->progress, "window %d: %s (off by %.0f %%) -> %s", t->iterations, d,
	         100.0 * w->error, steps);
	t->changed = true;
}

/* The servo's speed at the supply it reports: a target beyond it is out of
 * reach whatever the parameters (checked as soon as a voltage is read: a
 * loop that cannot keep cycling would never complete a window). */
static bool tune_supply_too_low(struct tune *t)
{
	if (!isfinite(t->supply_v))
		return false;
	double vmax = TUNE_SPEED_SHARE * t->no_load_speed * t->supply_v / 12.0;
	double f = t->opts.target_freq, a = t->opts.target_amp, need = tune_needed_speed(f, a);
	if (need <= vmax)
		return false;
	char why[TUNE_TEXT];
	snprintf(why, sizeof why,
	         "target out of reach: %.2f Hz at %.2f rad needs a peak speed of %.2f rad/s; at the %.1f V the "
	         "servos report, their no-load speed is %.2f rad/s and a loaded joint gets at most about %.2f. "
	         "Reachable: about %.2f Hz at %.2f rad, or %.2f rad at %.2f Hz (or a higher supply voltage)",
	         f, a, need, t->supply_v, t->no_load_speed * t->supply_v / 12.0, vmax, vmax / (2 * M_PI * a), a,
	         vmax / (2 * M_PI * f), f);
	tune_fail(t, why);
	return true;
}

static void tune_window_done(struct tune *t, double time)
{
	struct tune_window w;
	tune_measure(t, &w);
	t->iterations++;
	if (!t->have_first) {
		t->first = w;
		t->have_first = true;
	}
	if (!t->have_best || w.error < t->best.error) {
		t->best = w;
		t->have_best = true;
	}
	char d[160];
	tune_describe(t, &w, d, sizeof d);
	if (t->state == TUNE_CONFIRMING && w.error <= TUNE_TOLERANCE) {
		t->result = w;
		t->state = TUNE_DONE;
		snprintf(t->progress, sizeof t->progress, "window %d: %s, unchanged: confirmed", t->iterations, d);
		return;
	}
	if (w.error <= TUNE_AIM) {
		t->state = TUNE_CONFIRMING;
		snprintf(t->progress, sizeof t->progress, "window %d: %s (within %.1f %%): once more to confirm",
		         t->iterations, d, 100.0 * w.error);
		tune_window_reset(t, time);
		return;
	}
	t->state = TUNE_MEASURING;
	bool stuck = tune_saturated(t, &w);
	if (stuck && tune_same_speed(t, &w)) {
		tune_fail_unreachable(t, "three windows in a row, frequency times amplitude stayed put, every joint as "
		                         "fast as the others");
		return;
	}
	if (t->pinned >= 2) {
		tune_fail_unreachable(t, "k or mu at the end of its search range for two windows");
		return;
	}
	if (t->iterations >= TUNE_MAX_ITERATIONS) {
		char why[TUNE_TEXT], best[160];
		tune_describe(t, &t->best, best, sizeof best);
		snprintf(why, sizeof why, "no window within %.0f %% of the targets in %d windows; closest: %s",
		         100.0 * TUNE_TOLERANCE, t->iterations, best);
		tune_fail(t, why);
		return;
	}
	tune_update(t, &w, stuck);
	tune_window_reset(t, time);
}

/* The oscillation died (the daemon's starter had to run again, or no cycle
 * for TUNE_DEAD_S): the loop loses energy through this plant, whose servo
 * reaches a goal later than the horizon's lead assumes. Under position
 * actuation the lead feeds it (CONTROL.md): raise it. */
static void tune_dead(struct tune *t, double time, const char *what)
{
	double lead = fmin(TUNE_MAX_LEAD_S, t->lead * TUNE_LEAD_STEP);
	if (t->torque_actuation || !(lead > t->lead + 1e-6)) {
		char why[TUNE_TEXT];
		snprintf(why, sizeof why,
		         "the joints stopped oscillating (%s)%s: check that they move freely and that torque is on "
		         "(dxl doctor)", what, t->torque_actuation ? "" : " even with the horizon's lead at its largest");
		tune_fail(t, why);
		return;
	}
	t->lead = lead;
	t->dead_t = time;
	/* more lead feeds energy: keep the secant from crediting k with it */
	t->have_prev = false;
	t->changed = true;
	snprintf(t->progress, sizeof t->progress,
	         "%s: the loop loses energy on this plant (the servo lags more than the lead assumes); "
	         "servo_lead_s -> %.3f s", what, t->lead);
	tune_window_reset(t, time);
}

bool tune_sample(struct tune *t, double time, const double *x, const double *v, bool starter)
{
	t->progress[0] = '\0';
	if (t->state == TUNE_DONE || t->state == TUNE_FAILED || !isfinite(time))
		return false;
	if (!isfinite(t->t0))
		t->t0 = time;
	if (time - t->t0 > t->opts.max_s) {
		char why[TUNE_TEXT], best[160] = "none";
		if (t->have_best)
			tune_describe(t, &t->best, best, sizeof best);
		snprintf(why, sizeof why, "no result in %.0f s (%d windows); closest: %s", t->opts.max_s, t->iterations,
		         best);
		tune_fail(t, why);
		return false;
	}
	if (starter) {
		/* the daemon restarts a stalled oscillator with its starter: the
		 * loop died — unless that death was just seen as "no cycle" */
		bool restart = t->state != TUNE_STARTING && !(time - t->dead_t < TUNE_DEAD_GRACE_S);
		t->state = TUNE_STARTING;
		tune_window_reset(t, time);
		if (restart)
			tune_dead(t, time, "the joints stalled and the starter runs again");
		return t->changed;
	}
	if (tune_supply_too_low(t))
		return false;
	if (t->state == TUNE_STARTING) {
		t->state = TUNE_MEASURING;
		tune_window_reset(t, time);
	}
	/* every joint must keep cycling: one resting near neutral while its
	 * neighbour swings is a loop that died there */
	bool dead = false;
	for (size_t i = 0; i < t->n; i++) {
		if (isfinite(x[i]) && tune_track(t, &t->j[i], time, x[i], v[i]))
			t->j[i].last_cycle_t = time;
		dead = dead || time - t->j[i].last_cycle_t > TUNE_DEAD_S;
	}
	if (dead) {
		tune_dead(t, time, "a joint without a cycle for " TUNE_DEAD_TEXT);
		return t->changed;
	}
	if (tune_window_ready(t))
		tune_window_done(t, time);
	return t->changed;
}

void tune_supply(struct tune *t, double volts)
{
	if (isfinite(volts) && volts > 0)
		t->supply_v = volts;
}

bool tune_apply(struct tune *t, struct ctl *c)
{
	char why[256];
	bool ok = true;
	t->changed = false;
	/* all or nothing: checked first, so that a refusal leaves the
	 * controller running the parameters the last window measured */
	for (size_t i = 0; i < t->n && ok; i++)
		ok = ctl_check_param(c, "k", (int)i, t->k0[i] * t->k, why, sizeof why) &&
		     ctl_check_param(c, "mu", (int)i, t->mu[i], why, sizeof why);
	ok = ok && ctl_check_param(c, "servo_lead_s", -1, t->lead, why, sizeof why);
	for (size_t i = 0; i < t->n && ok; i++)
		ok = ctl_set_param(c, "k", (int)i, t->k0[i] * t->k, why, sizeof why) &&
		     ctl_set_param(c, "mu", (int)i, t->mu[i], why, sizeof why);
	ok = ok && ctl_set_param(c, "servo_lead_s", -1, t->lead, why, sizeof why);
	if (!ok) {
		snprintf(t->why, sizeof t->why, "the controller refused the tuner's step: %s", why);
		t->state = TUNE_FAILED;
	}
	t->ran = c->p;
	return ok;
}

void tune_write_config(const struct tune *t, const struct cfg *cfg, const char *when, double took_s, void *file)
{
	FILE *f = file;
	static struct cfg out;
	out = *cfg;
	cfg_params_put(&out, &t->ran);   /* what commands changed while it ran, too */
	const struct tune_window *r = &t->result;
	for (size_t i = 0; i < t->n; i++) {
		out.joint[i].osc.k = t->k0[i] * r->k;
		out.joint[i].osc.mu = r->mu[i];
	}
	out.servo_lead_s = r->lead;
	out.frequency = r->freq;
	out.amplitude = tune_mean_amp(t, r);
	out.mode = CFG_MODE_OSCILLATOR;
	out.mode_given = true;
	char d[160], d0[160];
	tune_describe(t, r, d, sizeof d);
	tune_describe(t, &t->first, d0, sizeof d0);
	fprintf(f,
	        "# %s: written by undulated --tune on %s\n"
	        "# target %.3f Hz, %.3f rad; measured with these parameters: %s\n"
	        "# the parameters it started from gave %s\n"
	        "# %d windows in %.0f s. [sinusoid] is the clock-driven baseline set to the frequency and\n"
	        "# (mean) amplitude measured, as the paper matched it to the oscillator's kinematics.\n"
	        "# Starts in OSCILLATOR: `undulated THIS_FILE` (--port PATH to use another port).\n\n",
	        cfg->name, when, t->opts.target_freq, t->opts.target_amp, d, d0, t->iterations, took_s);
	cfg_print(&out, f);
}
