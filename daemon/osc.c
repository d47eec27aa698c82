/*
 * osc.c — the control laws (see osc.h and CONTROL.md). Pure: no clock, no I/O,
 * no allocation. Every function survives any double it is given.
 */
#include "osc.h"

#include <math.h>

#define OSC_PI 3.14159265358979323846

/*
 * Default oscillator parameters. Target: 0.8 Hz, 0.8 rad on the simulated AX-12A
 * robot through the real daemon (factory compliance margin 1 / slope 32 /
 * punch 32, speed from the 20 Hz filter, horizon = dt + OSC_SERVO_LEAD_S), on
 * both joints of the two-joint robot with the paper's coupling λ = (1.5, −0.5),
 * and on a single joint. The servo loop moves both numbers away from what the
 * bare equation gives (CONTROL.md, "Through the servo"):
 * - the speed estimate lags the angle (≈ 13 ms); predicting with it acts like a
 *   softer spring, so the loop runs at 0.82–0.84 of the equation's frequency
 *   and k is set for 0.95 (two joints) / 0.99 Hz (one) in the bare equation;
 * - the lead puts the horizon ≈ 3.5 ms past the loop's own lag; that surplus
 *   feeds energy like extra negative damping, so μ is larger than A ≈ 2√(c/μ)
 *   would ask for (the bare equation: 0.65 / 0.58 rad, single joint 0.38 rad).
 */
#define OSC_DEF_INERTIA 2.0e-3   /* kg·m²: a control parameter, order of the real link's */
#define OSC_DEF_K       0.078    /* N·m/rad: 0.80 Hz through the servo loop (bare: 0.947 Hz) */
#define OSC_DEF_C       3.0e-3   /* N·m·s/rad: c/(I·ω) = 0.24; the lead's surplus adds more */
#define OSC_DEF_MU0     0.175    /* N·m·s/rad³, joint 0: 0.80 rad through the servo loop */
#define OSC_DEF_MU1     0.125    /* joint 1: smaller natural swing, smaller μ equalises */
#define OSC_DEF_K_SINGLE 0.078   /* N·m/rad, single joint: 0.80 Hz through the servo loop */
#define OSC_DEF_MU_SINGLE 0.082  /* single joint: 0.80 rad through the servo loop */
#define OSC_DEF_LAMBDA0 1.5      /* paper: first joint */
#define OSC_DEF_LAMBDA1 (-0.5)   /* paper: second joint */

/*
 * Torque actuation (the joint driven by a torque, as on the paper's pair rig):
 * the law's torque is applied to the joint itself, so k, c, μ are physical and
 * `inertia` is the joint's own (the simulated AX-12A joint with its 18.65 cm
 * link: 4.39e-3 kg·m², sim-bridge/PHYSICS.md). Target 0.8 Hz, 0.8 rad through
 * the daemon on the simulated bus, one joint; measured in CONTROL.md.
 * - k = I·(2π·0.8 Hz)² = 0.111 N·m/rad;
 * - c = 0.3·I·ω = 6.6e-3 N·m·s/rad: van der Pol ε = 0.3, a few periods to
 *   recover the amplitude after a collision, little distortion;
 * - μ below 4c/A² = 0.041: the 10 ms hold of each command and the lag of the
 *   speed estimate take energy out, so the loop settles lower than A = 2√(c/μ);
 * - friction 5 mN·m: the link's dry friction (PHYSICS.md), so the joint
 *   starts from a turning point without a dead zone.
 * On a PWM drive (the AX-12's wheel mode) the daemon adds the back-EMF back
 * from a speed estimate a few ms late: the error goes with the acceleration,
 * i.e. with −x, and softens the spring (0.61 Hz with k = 0.111); k = 0.19
 * gives 0.79–0.80 Hz, 0.77 rad there (measured, CONTROL.md).
 * Two or more joints: the paper's coupling pumps energy into the travelling
 * wave (growth ≈ 0.37·ω in the bare law), so one joint's μ let two joints
 * swing 2.0/1.6 rad, past the ±1.3 rad limits (measured on the simulated
 * robot: the limit fault at 13 s on the current drive, 1.13 rad at 0.90 Hz on
 * the PWM drive). A larger μ, smaller on the odd joints as in the position
 * defaults, found by `undulated --tune` on the simulated two-joint robot in
 * lockstep and rounded: 0.809 Hz, 0.82/0.80 rad (current), 0.813 Hz,
 * 0.83/0.80 rad (PWM).
 */
#define OSC_TQ_INERTIA OSC_TORQUE_JOINT_INERTIA
#define OSC_TQ_K        0.111
#define OSC_TQ_K_PWM    0.19
#define OSC_TQ_C        6.6e-3
#define OSC_TQ_MU       0.032
#define OSC_TQ_MU0      0.18     /* two or more joints, even joints, current drive */
#define OSC_TQ_MU1      0.10     /* ... odd joints */
#define OSC_TQ_MU0_PWM  0.26     /* two or more joints on the PWM drive */
#define OSC_TQ_MU1_PWM  0.15
#define OSC_TQ_FRICTION 0.005

/* Width (rad/s) of the smooth sign used for friction compensation:
 * sgn(v) ≈ tanh(v / band). A true step would make RK4's stages straddle a
 * discontinuity at every reversal; 0.05 rad/s is four steps of the servo's
 * speed reading (0.0116 rad/s each), too small to change the motion visibly. */
#define OSC_FRICTION_BAND 0.05

/* Largest number of RK4 sub-steps per call: bounds the work per cycle. */
#define OSC_MAX_SUBSTEPS 1000

void osc_default_params(struct osc_joint_params *p, size_t joint, size_t njoints)
{
	p->k = OSC_DEF_K;
	p->c = OSC_DEF_C;
	p->mu = OSC_DEF_MU0;
	p->inertia = OSC_DEF_INERTIA;
	p->friction = 0.0;
	p->coupling_phase = 0.0;
	if (njoints < 2) {
		p->lambda = 0.0;   /* uncoupled: a van der Pol oscillator */
		p->mu = OSC_DEF_MU_SINGLE;
		p->k = OSC_DEF_K_SINGLE;
	} else if (joint % 2 == 0) {
		p->lambda = OSC_DEF_LAMBDA0;
	} else {
		p->lambda = OSC_DEF_LAMBDA1;
		p->mu = OSC_DEF_MU1;
	}
}

void osc_default_torque_params(struct osc_joint_params *p, size_t joint, size_t njoints, bool pwm)
{
	p->k = pwm ? OSC_TQ_K_PWM : OSC_TQ_K;
	p->c = OSC_TQ_C;
	if (njoints < 2)
		p->mu = OSC_TQ_MU;
	else if (joint % 2 == 0)
		p->mu = pwm ? OSC_TQ_MU0_PWM : OSC_TQ_MU0;
	else
		p->mu = pwm ? OSC_TQ_MU1_PWM : OSC_TQ_MU1;
	p->inertia = OSC_TQ_INERTIA;
	p->friction = OSC_TQ_FRICTION;
	p->coupling_phase = 0.0;
	p->lambda = njoints < 2 ? 0.0 : (joint % 2 == 0 ? OSC_DEF_LAMBDA0 : OSC_DEF_LAMBDA1);
}

/* The joint whose angle couples into joint j: the next joint in the chain,
 * and for the last joint the previous one (so two joints couple each other). */
static size_t osc_other(size_t j, size_t njoints)
{
	return (j + 1 < njoints) ? j + 1 : j - 1;
}

/* The other joint as joint j's coupling sees it: its angle θ_j further on in
 * its cycle, from its angle and speed (on x = a cos ωt, exactly
 * a cos(ωt + θ) when ω is the law's own √(k/I)). θ = 0: the angle as it is,
 * bit for bit the law without the term. */
static double osc_coupled(const struct osc_joint_params *p, size_t j, double x_other, double v_other)
{
	double theta = p[j].coupling_phase;
	if (theta == 0.0)
		return x_other;
	double omega = sqrt(p[j].k / p[j].inertia);
	return x_other * cos(theta) + v_other / omega * sin(theta);
}

/* The right-hand side of the law for joint j at state (x, v). */
static double osc_law(const struct osc_joint_params *p, size_t njoints, const double *x,
                      const double *v, size_t j)
{
	size_t o = njoints >= 2 ? osc_other(j, njoints) : j;
	double coupled = (njoints >= 2) ? p[j].lambda * osc_coupled(p, j, x[o], v[o]) : 0.0;
	double torque = -p[j].k * (x[j] + coupled) + (p[j].c - p[j].mu * x[j] * x[j]) * v[j];
	if (p[j].friction != 0.0)
		torque += p[j].friction * tanh(v[j] / OSC_FRICTION_BAND);
	return torque;
}

/* ẍ for every joint at state (x, v). */
static void osc_accel(const struct osc_joint_params *p, size_t njoints, const double *x,
                      const double *v, double *a)
{
	for (size_t j = 0; j < njoints; j++)
		a[j] = osc_law(p, njoints, x, v, j) / p[j].inertia;
}

static bool osc_all_finite(const double *a, size_t n)
{
	for (size_t i = 0; i < n; i++)
		if (!isfinite(a[i]))
			return false;
	return true;
}

static bool osc_params_ok(const struct osc_joint_params *p, size_t njoints)
{
	for (size_t j = 0; j < njoints; j++) {
		const struct osc_joint_params *q = &p[j];
		if (!isfinite(q->k) || !isfinite(q->c) || !isfinite(q->mu) || !isfinite(q->lambda) ||
		    !isfinite(q->friction) || !isfinite(q->inertia) || !(q->inertia > 0.0) ||
		    !isfinite(q->coupling_phase))
			return false;
	}
	return true;
}

/* One classical RK4 step of size h on (x, v), in place. */
static void osc_rk4(const struct osc_joint_params *p, size_t n, double *x, double *v, double h)
{
	double k1x[OSC_MAX_JOINTS], k1v[OSC_MAX_JOINTS], k2x[OSC_MAX_JOINTS], k2v[OSC_MAX_JOINTS];
	double k3x[OSC_MAX_JOINTS], k3v[OSC_MAX_JOINTS], k4x[OSC_MAX_JOINTS], k4v[OSC_MAX_JOINTS];
	double tx[OSC_MAX_JOINTS], tv[OSC_MAX_JOINTS];
	size_t j;

	for (j = 0; j < n; j++)
		k1x[j] = v[j];
	osc_accel(p, n, x, v, k1v);
	for (j = 0; j < n; j++) {
		tx[j] = x[j] + 0.5 * h * k1x[j];
		tv[j] = v[j] + 0.5 * h * k1v[j];
		k2x[j] = tv[j];
	}
	osc_accel(p, n, tx, tv, k2v);
	for (j = 0; j < n; j++) {
		tx[j] = x[j] + 0.5 * h * k2x[j];
		tv[j] = v[j] + 0.5 * h * k2v[j];
		k3x[j] = tv[j];
	}
	osc_accel(p, n, tx, tv, k3v);
	for (j = 0; j < n; j++) {
		tx[j] = x[j] + h * k3x[j];
		tv[j] = v[j] + h * k3v[j];
		k4x[j] = tv[j];
	}
	osc_accel(p, n, tx, tv, k4v);
	for (j = 0; j < n; j++) {
		x[j] += h / 6.0 * (k1x[j] + 2.0 * k2x[j] + 2.0 * k3x[j] + k4x[j]);
		v[j] += h / 6.0 * (k1v[j] + 2.0 * k2v[j] + 2.0 * k3v[j] + k4v[j]);
	}
}

static void osc_hold(size_t njoints, const double *x, const double *v, double *x_next,
                     double *v_next)
{
	for (size_t j = 0; j < njoints; j++) {
		x_next[j] = x[j];
		if (v_next)
			v_next[j] = isfinite(v[j]) ? v[j] : 0.0;
	}
}

bool osc_step(const struct osc_joint_params *p, size_t njoints, const double *x, const double *v,
              double horizon, int substeps, double *x_next, double *v_next)
{
	double xs[OSC_MAX_JOINTS], vs[OSC_MAX_JOINTS];

	if (njoints == 0 || njoints > OSC_MAX_JOINTS)
		return false;
	if (!osc_all_finite(x, njoints) || !osc_all_finite(v, njoints) || !isfinite(horizon) ||
	    horizon < 0.0 || !osc_params_ok(p, njoints)) {
		osc_hold(njoints, x, v, x_next, v_next);
		return false;
	}
	if (substeps < 1)
		substeps = 1;
	if (substeps > OSC_MAX_SUBSTEPS)
		substeps = OSC_MAX_SUBSTEPS;
	for (size_t j = 0; j < njoints; j++) {
		xs[j] = x[j];
		vs[j] = v[j];
	}
	double h = horizon / substeps;
	for (int s = 0; s < substeps; s++)
		osc_rk4(p, njoints, xs, vs, h);
	if (!osc_all_finite(xs, njoints) || !osc_all_finite(vs, njoints)) {
		osc_hold(njoints, x, v, x_next, v_next);
		return false;
	}
	for (size_t j = 0; j < njoints; j++) {
		x_next[j] = xs[j];
		if (v_next)
			v_next[j] = vs[j];
	}
	return true;
}

bool osc_torque(const struct osc_joint_params *p, size_t njoints, const double *x, const double *v,
                double *torque)
{
	if (njoints == 0 || njoints > OSC_MAX_JOINTS)
		return false;
	bool ok = osc_all_finite(x, njoints) && osc_all_finite(v, njoints);
	for (size_t j = 0; ok && j < njoints; j++)
		ok = isfinite(p[j].k) && isfinite(p[j].c) && isfinite(p[j].mu) && isfinite(p[j].lambda) &&
		     isfinite(p[j].friction) && isfinite(p[j].coupling_phase) &&
		     (p[j].coupling_phase == 0.0 || p[j].inertia > 0.0);
	for (size_t j = 0; j < njoints; j++)
		torque[j] = ok ? osc_law(p, njoints, x, v, j) : 0.0;
	for (size_t j = 0; ok && j < njoints; j++)
		ok = isfinite(torque[j]);
	if (!ok)
		for (size_t j = 0; j < njoints; j++)
			torque[j] = 0.0;
	return ok;
}

double osc_sinusoid(double amplitude, double frequency, double phase, size_t joint, double t)
{
	/* t is wall-clock time (robots on different computers share it), so f·t is
	 * ~1e9 cycles: keep only its fraction. sin() of a ~1e10 rad argument takes
	 * the slow argument-reduction path, and the fraction keeps ~1e-7 cycle. */
	double cycles = frequency * t;
	cycles -= floor(cycles);
	return amplitude * sin(phase + (2.0 * OSC_PI / 3.0) * (double)joint - 2.0 * OSC_PI * cycles);
}

double osc_sinusoid_rate(double amplitude, double frequency, double phase, size_t joint, double t)
{
	double cycles = frequency * t;
	cycles -= floor(cycles);
	return -2.0 * OSC_PI * frequency * amplitude *
	       cos(phase + (2.0 * OSC_PI / 3.0) * (double)joint - 2.0 * OSC_PI * cycles);
}

bool osc_clock_torque(const struct osc_clock *k, size_t njoints, double t, const double *x, const double *v,
                      double *torque)
{
	if (njoints == 0 || njoints > OSC_MAX_JOINTS)
		return false;
	bool ok = osc_all_finite(x, njoints) && osc_all_finite(v, njoints) && isfinite(t) &&
	          isfinite(k->amplitude) && isfinite(k->frequency) && isfinite(k->phase) &&
	          isfinite(k->stiffness) && isfinite(k->damping);
	for (size_t j = 0; j < njoints; j++) {
		double target = osc_sinusoid(k->amplitude, k->frequency, k->phase, j, t);
		double rate = osc_sinusoid_rate(k->amplitude, k->frequency, k->phase, j, t);
		torque[j] = ok ? k->stiffness * (target - x[j]) + k->damping * (rate - v[j]) : 0.0;
		ok = ok && isfinite(torque[j]);
	}
	if (!ok)
		for (size_t j = 0; j < njoints; j++)
			torque[j] = 0.0;
	return ok;
}

void osc_velocity_filter_init(struct osc_velocity_filter *f, double cutoff_hz)
{
	f->cutoff_hz = cutoff_hz;
	f->last_x = 0.0;
	f->v = 0.0;
	f->primed = false;
	f->rejected = 0;
}

double osc_velocity_filter_update(struct osc_velocity_filter *f, double x, double dt)
{
	if (!isfinite(x)) {
		f->rejected++;
		return f->v;
	}
	if (!f->primed) {
		f->last_x = x;
		f->v = 0.0;
		f->primed = true;
		return f->v;
	}
	if (!isfinite(dt) || dt <= 0.0) {
		/* no usable interval: keep the speed, but the newest angle is the
		 * best base for the next difference */
		f->rejected++;
		f->last_x = x;
		return f->v;
	}
	double raw = (x - f->last_x) / dt;
	/* exact discretisation of a first-order low-pass for any dt; cut-off <= 0
	 * means no smoothing (the raw finite difference) */
	double alpha = (isfinite(f->cutoff_hz) && f->cutoff_hz > 0.0)
	                   ? 1.0 - exp(-2.0 * OSC_PI * f->cutoff_hz * dt)
	                   : 1.0;
	f->v += alpha * (raw - f->v);
	f->last_x = x;
	return f->v;
}
