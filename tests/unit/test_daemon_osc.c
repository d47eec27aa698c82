/*
 * test_daemon_osc.c — the control laws: limit cycle, coupling, integration
 * accuracy, reaction to a collision, the closed loop through a model of the
 * simulated AX-12A (the defaults give 0.8 Hz, 0.8 rad there),
 * the baseline sinusoid, phase helpers, estimator and velocity filter.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "../../daemon/osc.h"
#include "../../common/phase.h"

#define PI 3.14159265358979323846
#define TWO_JOINTS 2
#define MAX_CROSSINGS 512              /* upward zero crossings kept per joint */
#define AX12_POS_STEP (300.0 / 1023.0 * PI / 180.0)   /* 0.29°, one position unit */

/* ---- a closed-loop run, measured from upward zero crossings -------------- */

struct cycle {
	double amp[OSC_MAX_JOINTS];        /* half peak-to-peak over the window */
	double freq;                       /* Hz, joint 0 */
	double lag_deg;                    /* joint 1 behind joint 0, degrees (travelling wave > 0) */
	int ncross;
};

struct crossings {
	double t[OSC_MAX_JOINTS][MAX_CROSSINGS];
	int n[OSC_MAX_JOINTS];
	double hi[OSC_MAX_JOINTS], lo[OSC_MAX_JOINTS];
};

static void cross_init(struct crossings *c)
{
	for (int j = 0; j < OSC_MAX_JOINTS; j++) {
		c->n[j] = 0;
		c->hi[j] = -INFINITY;
		c->lo[j] = INFINITY;
	}
}

static void cross_sample(struct crossings *c, size_t j, double t_prev, double x_prev, double t,
                         double x)
{
	if (x > c->hi[j])
		c->hi[j] = x;
	if (x < c->lo[j])
		c->lo[j] = x;
	if (x_prev < 0.0 && x >= 0.0 && c->n[j] < MAX_CROSSINGS)
		c->t[j][c->n[j]++] = t_prev + (t - t_prev) * (-x_prev) / (x - x_prev);
}

static struct cycle cross_result(const struct crossings *c, size_t njoints)
{
	struct cycle r = { .freq = 0.0, .lag_deg = NAN, .ncross = c->n[0] };
	for (size_t j = 0; j < njoints; j++)
		r.amp[j] = 0.5 * (c->hi[j] - c->lo[j]);
	if (c->n[0] < 2)
		return r;
	double period = (c->t[0][c->n[0] - 1] - c->t[0][0]) / (c->n[0] - 1);
	r.freq = 1.0 / period;
	if (njoints >= 2 && c->n[1] >= 1) {
		/* joint 1's first crossing after joint 0's first one */
		double d = fmod(c->t[1][c->n[1] - 1] - c->t[0][c->n[0] - 1], period);
		if (d < 0.0)
			d += period;
		if (d > 0.5 * period)
			d -= period;
		r.lag_deg = 360.0 * d / period;
	}
	return r;
}

/* Ideal loop: the measured state is the previous prediction. Measures over
 * [t_from, t_to). */
static struct cycle run_ideal(const struct osc_joint_params *p, size_t n, const double *x0,
                              const double *v0, double dt, int substeps, double t_from, double t_to)
{
	double x[OSC_MAX_JOINTS], v[OSC_MAX_JOINTS], xn[OSC_MAX_JOINTS], vn[OSC_MAX_JOINTS];
	struct crossings c;
	cross_init(&c);
	for (size_t j = 0; j < n; j++) {
		x[j] = x0[j];
		v[j] = v0[j];
	}
	long steps = lround(t_to / dt);
	for (long s = 0; s < steps; s++) {
		assert_true(osc_step(p, n, x, v, dt, substeps, xn, vn));
		double t = (s + 1) * dt;
		for (size_t j = 0; j < n; j++) {
			if (t >= t_from)
				cross_sample(&c, j, t - dt, x[j], t, xn[j]);
			x[j] = xn[j];
			v[j] = vn[j];
		}
	}
	return cross_result(&c, n);
}

static void defaults(struct osc_joint_params *p, size_t n)
{
	for (size_t j = 0; j < n; j++)
		osc_default_params(&p[j], j, n);
}

/* ---- limit cycle ----------------------------------------------------------- */

static void test_limit_cycle_same_from_any_start(void **state)
{
	(void)state;
	struct osc_joint_params p[TWO_JOINTS];
	defaults(p, TWO_JOINTS);
	/* small, large, large and fast, zero but for a nudge */
	const double starts[][4] = {
		{ 0.05, 0.0, 0.0, 0.0 },
		{ 2.0, -1.5, 0.0, 0.0 },
		{ -1.0, 0.5, 6.0, -4.0 },
		{ 0.0, 0.0, 1e-3, 0.0 },
	};
	struct cycle ref = { .freq = 0.0 };
	for (size_t i = 0; i < sizeof starts / sizeof starts[0]; i++) {
		struct cycle r = run_ideal(p, TWO_JOINTS, starts[i], starts[i] + 2, 0.01, 4, 30.0, 45.0);
		print_message("start %zu: A0 %.4f A1 %.4f rad, f %.4f Hz, lag %.1f deg\n", i, r.amp[0],
		              r.amp[1], r.freq, r.lag_deg);
		/* the bare equation (no servo) with the defaults: the coupling
		 * lowers the frequency to 0.95 × √(k/I)/2π; the defaults' 0.8 Hz,
		 * 0.8 rad come from the servo loop (test_closed_loop_through_servo) */
		double f0 = sqrt(p[0].k / p[0].inertia) / (2.0 * PI);
		assert_true(fabs(r.freq / f0 - 0.952) < 0.01);
		assert_in_range(lround(r.amp[0] * 1000), 600, 700);
		assert_in_range(lround(r.amp[1] * 1000), 530, 630);
		if (i == 0) {
			ref = r;
			continue;
		}
		assert_true(fabs(r.freq - ref.freq) < 1e-3 * ref.freq);
		assert_true(fabs(r.amp[0] - ref.amp[0]) < 2e-3 * ref.amp[0]);
		assert_true(fabs(r.amp[1] - ref.amp[1]) < 2e-3 * ref.amp[1]);
		assert_true(fabs(r.lag_deg - ref.lag_deg) < 0.5);
	}
}

static void test_single_joint_limit_cycle(void **state)
{
	(void)state;
	struct osc_joint_params p;
	osc_default_params(&p, 0, 1);
	assert_true(p.lambda == 0.0);
	const double x0[][2] = { { 0.02, 0.0 }, { 1.8, 3.0 }, { 0.0, 1e-3 } };
	for (size_t i = 0; i < 3; i++) {
		struct cycle r = run_ideal(&p, 1, &x0[i][0], &x0[i][1], 0.01, 4, 30.0, 45.0);
		print_message("single start %zu: A %.4f rad, f %.4f Hz\n", i, r.amp[0], r.freq);
		/* van der Pol with weak nonlinearity (c/(Iω) = 0.24): f ≈ √(k/I)/2π,
		 * A ≈ 2√(c/μ), each within 1 % */
		double f0 = sqrt(p.k / p.inertia) / (2.0 * PI), a0 = 2.0 * sqrt(p.c / p.mu);
		assert_true(fabs(r.freq / f0 - 1.0) < 0.01);
		assert_true(fabs(r.amp[0] / a0 - 1.0) < 0.01);
	}
	/* one joint: λ is ignored whatever it holds */
	struct osc_joint_params q = p;
	q.lambda = 5.0;
	double x = 0.3, v = 0.7, a[2], b[2];
	assert_true(osc_step(&p, 1, &x, &v, 0.01, 4, &a[0], &a[1]));
	assert_true(osc_step(&q, 1, &x, &v, 0.01, 4, &b[0], &b[1]));
	assert_true(a[0] == b[0] && a[1] == b[1]);
}

/* ---- coupling: a steady travelling wave ----------------------------------- */

static void test_coupling_gives_steady_travelling_wave(void **state)
{
	(void)state;
	struct osc_joint_params p[TWO_JOINTS];
	defaults(p, TWO_JOINTS);
	const double x0[2] = { 0.3, -0.2 }, v0[2] = { 0.0, 0.0 };
	double lags[3];
	for (int w = 0; w < 3; w++) {
		struct cycle r = run_ideal(p, TWO_JOINTS, x0, v0, 0.01, 4, 20.0 + 10.0 * w,
		                           30.0 + 10.0 * w);
		lags[w] = r.lag_deg;
		print_message("window %d: joint 1 lags joint 0 by %.2f deg\n", w, lags[w]);
	}
	/* joint 1 behind joint 0: the wave runs from joint 0 to joint 1, as in the
	 * baseline sinusoid (there 120°); ≈86° for λ = (1.5, −0.5) */
	assert_true(lags[0] > 80.0 && lags[0] < 92.0);
	assert_true(fabs(lags[1] - lags[0]) < 0.5 && fabs(lags[2] - lags[0]) < 0.5);
	/* the sign comes from the coupling: swapping λ reverses the wave */
	p[0].lambda = -0.5;
	p[1].lambda = 1.5;
	struct cycle s = run_ideal(p, TWO_JOINTS, x0, v0, 0.01, 4, 30.0, 40.0);
	print_message("λ swapped: lag %.2f deg\n", s.lag_deg);
	assert_true(s.lag_deg < -80.0 && s.lag_deg > -92.0);
}

/* The coupling's phase θ_j (coupling_phase): joint j couples to the other
 * joint's angle a phase θ_j further on in its cycle,
 *     x_o cos θ_j + (ẋ_o / ω_j) sin θ_j,   ω_j = √(k_j / I_j),
 * from the other joint's measured angle and speed (no clock). With λ on the
 * angle alone the two joints' linear mode is a quarter period apart whatever λ
 * (86.5° with the damping terms); θ = (+35°, −35°) turns it to 120°, the
 * baseline's 2π/3, and leaves the frequency and the amplitudes as they were. */
static void test_coupling_phase_sets_the_lag(void **state)
{
	(void)state;
	struct osc_joint_params p[TWO_JOINTS];
	defaults(p, TWO_JOINTS);
	assert_true(p[0].coupling_phase == 0.0 && p[1].coupling_phase == 0.0);
	const double x0[2] = { 0.05, 0.0 }, v0[2] = { 0.0, 0.0 };
	struct cycle r0 = run_ideal(p, TWO_JOINTS, x0, v0, 0.01, 4, 40.0, 60.0);
	p[0].coupling_phase = 35.0 * PI / 180.0;
	p[1].coupling_phase = -35.0 * PI / 180.0;
	struct cycle r = run_ideal(p, TWO_JOINTS, x0, v0, 0.01, 4, 40.0, 60.0);
	print_message("coupling phase +-35 deg: lag %.2f deg (0: %.2f), f %.4f Hz (%.4f), A %.3f/%.3f (%.3f/%.3f)\n",
	              r.lag_deg, r0.lag_deg, r.freq, r0.freq, r.amp[0], r.amp[1], r0.amp[0], r0.amp[1]);
	assert_true(fabs(r.lag_deg - 120.0) < 1.5);
	assert_true(fabs(r.freq - r0.freq) < 0.01 * r0.freq);
	assert_true(fabs(r.amp[0] - r0.amp[0]) < 0.02 * r0.amp[0] && fabs(r.amp[1] - r0.amp[1]) < 0.02 * r0.amp[1]);
	/* the term itself: joint 0 at rest at neutral feels only the coupling */
	double w = sqrt(p[0].k / p[0].inertia);
	double x[2] = { 0.0, 0.4 }, v[2] = { 0.0, -1.5 }, tau[2];
	assert_true(osc_torque(p, TWO_JOINTS, x, v, tau));
	double seen = -p[0].k * p[0].lambda * (0.4 * cos(p[0].coupling_phase) - 1.5 / w * sin(p[0].coupling_phase));
	assert_true(fabs(tau[0] - seen) < 1e-12);
	/* one joint: no other, no coupling, whatever θ holds */
	struct osc_joint_params q;
	osc_default_params(&q, 0, 1);
	double a = 0.3, b = 0.7, t1;
	assert_true(osc_torque(&q, 1, &a, &b, &t1));
	q.coupling_phase = 1.0;
	double t2;
	assert_true(osc_torque(&q, 1, &a, &b, &t2));
	assert_true(t1 == t2);
	/* not finite: hold, no torque */
	p[1].coupling_phase = NAN;
	double xn[2];
	assert_false(osc_step(p, TWO_JOINTS, x, v, 0.01, 4, xn, NULL));
	assert_true(xn[0] == x[0] && xn[1] == x[1]);
	assert_false(osc_torque(p, TWO_JOINTS, x, v, tau));
	assert_true(tau[0] == 0.0 && tau[1] == 0.0);
}

static void test_chain_of_three_couples_to_next_joint(void **state)
{
	(void)state;
	struct osc_joint_params p[3];
	for (size_t j = 0; j < 3; j++) {
		p[j] = (struct osc_joint_params){ .k = 0.05, .c = 0.0, .mu = 0.0, .lambda = 2.0,
		                                  .inertia = 1e-3, .friction = 0.0 };
	}
	/* only joint 2 displaced: joint 1 (whose next is 2) and joint 2 (last:
	 * couples to 1, at 0) accelerate; joint 0 (next is 1, at 0) does not yet */
	const double x[3] = { 0.0, 0.0, 1.0 }, v[3] = { 0.0, 0.0, 0.0 };
	double xn[3];
	const double h = 1e-3;
	assert_true(osc_step(p, 3, x, v, h, 1, xn, NULL));
	double a_unit = 0.05 / 1e-3 * h * h / 2.0;
	assert_true(fabs(xn[1] - (-2.0 * a_unit)) < 1e-3 * a_unit);
	assert_true(fabs(xn[2] - (1.0 - a_unit)) < 1e-3 * a_unit);
	assert_true(fabs(xn[0]) < 1e-3 * a_unit);
	/* only joint 1 displaced: joint 0 (next is 1) and joint 2 (last, couples
	 * back to 1) both feel it */
	const double x1[3] = { 0.0, 1.0, 0.0 };
	assert_true(osc_step(p, 3, x1, v, h, 1, xn, NULL));
	assert_true(fabs(xn[0] - (-2.0 * a_unit)) < 1e-3 * a_unit);
	assert_true(fabs(xn[2] - (-2.0 * a_unit)) < 1e-3 * a_unit);
	assert_true(fabs(xn[1] - (1.0 - a_unit)) < 1e-3 * a_unit);
}

/* ---- integration accuracy -------------------------------------------------- */

static void test_rk4_matches_exact_harmonic(void **state)
{
	(void)state;
	/* c = μ = λ = 0: x(t) = cos ωt exactly; RK4 error falls as substeps⁻⁴ */
	struct osc_joint_params p = { .k = 0.05, .c = 0.0, .mu = 0.0, .lambda = 0.0,
	                              .inertia = 2e-3, .friction = 0.0 };
	double w = sqrt(p.k / p.inertia), x = 1.0, v = 0.0, xn, vn;
	double h = 0.2;
	double err[2];
	for (int i = 0; i < 2; i++) {
		assert_true(osc_step(&p, 1, &x, &v, h, i == 0 ? 2 : 4, &xn, &vn));
		err[i] = fabs(xn - cos(w * h)) + fabs(vn + w * sin(w * h)) / w;
	}
	print_message("RK4 error 2 vs 4 substeps: %.3g %.3g (ratio %.1f)\n", err[0], err[1],
	              err[0] / err[1]);
	assert_true(err[1] < 1e-4);
	/* one control period in one RK4 step is far inside that */
	assert_true(osc_step(&p, 1, &x, &v, 0.01, 1, &xn, &vn));
	assert_true(fabs(xn - cos(w * 0.01)) < 1e-10);
	assert_true(err[0] / err[1] > 12.0 && err[0] / err[1] < 20.0);
}

static void test_independent_of_step_size(void **state)
{
	(void)state;
	struct osc_joint_params p[TWO_JOINTS];
	defaults(p, TWO_JOINTS);
	const double x0[2] = { 0.4, 0.0 }, v0[2] = { 0.0, 0.0 };
	struct cycle ref = run_ideal(p, TWO_JOINTS, x0, v0, 0.01, 10, 30.0, 45.0);
	struct cycle one = run_ideal(p, TWO_JOINTS, x0, v0, 0.01, 1, 30.0, 45.0);
	struct cycle d5 = run_ideal(p, TWO_JOINTS, x0, v0, 0.005, 4, 30.0, 45.0);
	struct cycle d20 = run_ideal(p, TWO_JOINTS, x0, v0, 0.02, 4, 30.0, 45.0);
	/* period_ms = 1 (rates above 100 Hz on X servos) */
	struct cycle d1 = run_ideal(p, TWO_JOINTS, x0, v0, 0.001, 4, 30.0, 45.0);
	const struct cycle *all[] = { &one, &d5, &d20, &d1 };
	for (size_t i = 0; i < 4; i++) {
		print_message("variant %zu: A0 %.5f A1 %.5f f %.5f lag %.2f\n", i, all[i]->amp[0],
		              all[i]->amp[1], all[i]->freq, all[i]->lag_deg);
		assert_true(fabs(all[i]->freq - ref.freq) < 2e-3 * ref.freq);
		/* sampling at 20 ms can miss the true peak by up to ω²Δt²/8 ≈ 0.1 % */
		assert_true(fabs(all[i]->amp[0] - ref.amp[0]) < 3e-3 * ref.amp[0]);
		assert_true(fabs(all[i]->amp[1] - ref.amp[1]) < 3e-3 * ref.amp[1]);
		assert_true(fabs(all[i]->lag_deg - ref.lag_deg) < 1.0);
	}
}

/* ---- proprioception: a collision shifts the phase ------------------------- */

static double single_run_phase(const struct osc_joint_params *p, double x, double v, double dt,
                               double t_kick, double kick_factor, double t_end, double omega,
                               double *amp_after)
{
	double xn, vn, hi = 0.0;
	long steps = lround(t_end / dt), kick = lround(t_kick / dt);
	for (long s = 0; s < steps; s++) {
		if (s == kick)
			v *= kick_factor;    /* the measured speed after a collision */
		assert_true(osc_step(p, 1, &x, &v, dt, 4, &xn, &vn));
		x = xn;
		v = vn;
		if ((s + 1) * dt > t_end - 2.0 && fabs(x) > hi)
			hi = fabs(x);
	}
	*amp_after = hi;
	return phase_from_state(x, v, omega);
}

static void test_velocity_jump_shifts_phase(void **state)
{
	(void)state;
	struct osc_joint_params p;
	osc_default_params(&p, 0, 1);
	const double dt = 0.01;
	double x0 = 0.0, v0 = 0.01;
	/* settle on the limit cycle, then find a sample with x ≈ +A/√2 moving up */
	struct cycle r = run_ideal(&p, 1, &x0, &v0, dt, 4, 20.0, 30.0);
	double omega = 2.0 * PI * r.freq;
	double x = 0.0, v = 0.01, xn, vn;
	long s = 0;
	for (; s < 100000; s++) {
		assert_true(osc_step(&p, 1, &x, &v, dt, 4, &xn, &vn));
		bool settled = (s + 1) * dt > 30.0;
		x = xn;
		v = vn;
		if (settled && v > 0.0 && x > 0.55 && x < 0.6)
			break;
	}
	/* reverse and halve the speed, as against a wall with restitution 0.5 */
	double before = phase_from_state(x, v, omega), after = phase_from_state(x, -0.5 * v, omega);
	double expected = phase_wrap(after - before);
	double amp_ref, amp_kick;
	double ref = single_run_phase(&p, x, v, dt, 0.0, 1.0, 20.0, omega, &amp_ref);
	double kicked = single_run_phase(&p, x, v, dt, 0.0, -0.5, 20.0, omega, &amp_kick);
	double measured = phase_wrap(kicked - ref);
	print_message("phase shift expected %.3f rad, measured %.3f rad; amplitude %.4f vs %.4f\n",
	              expected, measured, amp_kick, amp_ref);
	assert_true(fabs(expected) > 0.8);      /* a real shift, not a no-op */
	assert_true(fabs(phase_wrap(measured - expected)) < 0.1);
	assert_true(fabs(amp_kick - amp_ref) < 0.01 * amp_ref);
	/* an open-loop clock would ignore the kick; the oscillator must not */
	assert_true(fabs(measured) > 0.5);
}

/* ---- bad input ------------------------------------------------------------- */

static void test_non_finite_input_holds(void **state)
{
	(void)state;
	struct osc_joint_params p[TWO_JOINTS];
	defaults(p, TWO_JOINTS);
	double xn[2], vn[2];
	const double x[2] = { 0.3, -0.2 }, v[2] = { 1.0, 2.0 };
	const double xnan[2] = { NAN, -0.2 }, vinf[2] = { 1.0, INFINITY };

	assert_false(osc_step(p, 2, xnan, v, 0.01, 4, xn, vn));
	assert_true(isnan(xn[0]) && xn[1] == -0.2);   /* held: x_next = x, whatever it was */
	assert_false(osc_step(p, 2, x, vinf, 0.01, 4, xn, NULL));
	assert_true(xn[0] == x[0] && xn[1] == x[1]);
	assert_false(osc_step(p, 2, x, v, NAN, 4, xn, vn));
	assert_true(xn[0] == x[0] && xn[1] == x[1]);
	assert_false(osc_step(p, 2, x, v, -0.01, 4, xn, vn));
	assert_true(xn[0] == x[0] && xn[1] == x[1]);

	struct osc_joint_params bad[TWO_JOINTS] = { p[0], p[1] };
	bad[1].inertia = 0.0;
	assert_false(osc_step(bad, 2, x, v, 0.01, 4, xn, vn));
	assert_true(xn[0] == x[0] && xn[1] == x[1]);
	bad[1] = p[1];
	bad[0].mu = NAN;
	assert_false(osc_step(bad, 2, x, v, 0.01, 4, xn, vn));
	assert_true(xn[0] == x[0] && xn[1] == x[1]);

	/* a finite state that blows up inside the integration also holds */
	assert_false(osc_step(p, 2, (const double[]){ 1e150, 0.0 }, v, 0.01, 4, xn, vn));
	assert_true(xn[0] == 1e150);

	assert_false(osc_step(p, 0, x, v, 0.01, 4, xn, vn));
	assert_false(osc_step(p, OSC_MAX_JOINTS + 1, x, v, 0.01, 4, xn, vn));

	/* and good input moves */
	assert_true(osc_step(p, 2, x, v, 0.01, 0, xn, vn));   /* substeps < 1 → 1 */
	assert_true(xn[0] > x[0] && xn[1] > x[1]);
}

static void test_friction_term_is_smooth_sign(void **state)
{
	(void)state;
	struct osc_joint_params p = { .k = 0.0, .c = 0.0, .mu = 0.0, .lambda = 0.0,
	                              .inertia = 1e-3, .friction = 0.01 };
	const double h = 1e-3;
	double xn, vn, x = 0.0;
	double speeds[] = { 1.0, -1.0, 0.0 }, want[] = { 10.0, -10.0, 0.0 };   /* b/I */
	for (int i = 0; i < 3; i++) {
		assert_true(osc_step(&p, 1, &x, &speeds[i], h, 1, &xn, &vn));
		double accel = (vn - speeds[i]) / h;
		assert_true(fabs(accel - want[i]) < 1e-3 * 10.0);
	}
	/* within the band it is proportional, not a step: half way at tanh(1) */
	double v = 0.05;
	assert_true(osc_step(&p, 1, &x, &v, 1e-6, 1, &xn, &vn));
	double accel = (vn - v) / 1e-6;
	assert_true(fabs(accel - 10.0 * tanh(1.0)) < 1e-3);
}

/* ---- the real loop: a servo between goal and measurement ------------------- */

/* An AX-12A as the simulator models it (sim-bridge/motor.c, PHYSICS.md): a
 * proportional controller on the servo's own whole-unit reading, shaped by the
 * compliance registers (no drive within the margin, punch just outside it,
 * ramping to full duty over the slope), the motor's torque–speed line
 * (τ = 1.5 N·m·(duty − w/6.18 rad/s), the back-EMF braking also inside the dead
 * band), the joint's inertia with the link's viscous and dry friction, stepped
 * at 1 kHz with semi-implicit Euler. Factory registers: margin 1, slope 32,
 * punch 32, full torque limit, moving speed 0. */
#define SERVO_SLOPE_UNITS 32.0
#define SERVO_PUNCH (32.0 / 1023.0)
#define SERVO_STALL_NM 1.5
#define SERVO_NO_LOAD_RAD_S 6.178
#define SERVO_INERTIA 4.39e-3       /* kg·m²: link + rotor through the gearbox */
#define SERVO_VISCOUS 0.002         /* N·m·s/rad, link bearing */
#define SERVO_COULOMB 0.005         /* N·m, link bearing */
#define SERVO_SUBSTEPS 10           /* 1 ms physics inside one 10 ms period */
#define SERVO_WRITE_DELAY 1         /* substeps between the read and the goal write (bus time) */

struct servo_joint {
	double angle, speed;   /* true, rad and rad/s */
	double goal_units;     /* position units from the centre */
};

static double servo_duty(double error_units, double margin_units)
{
	double mag = fabs(error_units);
	if (mag <= margin_units)
		return 0.0;
	double ramp = fmin(1.0, (mag - margin_units) / SERVO_SLOPE_UNITS);
	double u = SERVO_PUNCH + (1.0 - SERVO_PUNCH) * ramp;
	return error_units > 0.0 ? u : -u;
}

static void servo_physics(struct servo_joint *s, double margin_units, double h)
{
	double present = round(s->angle / AX12_POS_STEP);
	double duty = servo_duty(s->goal_units - present, margin_units);
	double torque = SERVO_STALL_NM * (duty - s->speed / SERVO_NO_LOAD_RAD_S);
	torque = fmax(-SERVO_STALL_NM, fmin(SERVO_STALL_NM, torque));
	double impulse = SERVO_INERTIA * s->speed + h * (torque - SERVO_VISCOUS * s->speed);
	double stick = h * SERVO_COULOMB;
	if (fabs(impulse) <= stick)
		impulse = 0.0;
	else
		impulse -= impulse > 0.0 ? stick : -stick;
	s->speed = impulse / SERVO_INERTIA;
	s->angle += h * s->speed;
}

struct servo_run {
	size_t njoints;
	double lead;           /* s, added to dt for the horizon */
	double margin;         /* compliance margin, position units */
	double x0[TWO_JOINTS]; /* start angles, at rest, goals there */
	double starter_s;      /* s of the baseline sinusoid first (the daemon's starter), 0 = none */
	double t_to;           /* s; measured over the last 15 s */
};

/* The daemon's loop: read quantized angles, speed from the filtered
 * difference, integrate dt + lead ahead, write the (quantized) goal. */
static struct cycle run_servo(const struct servo_run *run)
{
	struct osc_joint_params p[TWO_JOINTS];
	defaults(p, run->njoints);
	struct osc_velocity_filter vf[TWO_JOINTS];
	struct servo_joint sj[TWO_JOINTS];
	const double dt = 0.01, hs = dt / SERVO_SUBSTEPS;
	struct crossings c;
	cross_init(&c);
	for (size_t j = 0; j < run->njoints; j++) {
		osc_velocity_filter_init(&vf[j], OSC_VELOCITY_CUTOFF_HZ);
		sj[j] = (struct servo_joint){ .angle = run->x0[j], .speed = 0.0,
		                              .goal_units = round(run->x0[j] / AX12_POS_STEP) };
	}
	long steps = lround(run->t_to / dt);
	for (long s = 0; s < steps; s++) {
		double xm[TWO_JOINTS], vm[TWO_JOINTS], xn[TWO_JOINTS];
		for (size_t j = 0; j < run->njoints; j++) {
			xm[j] = AX12_POS_STEP * round(sj[j].angle / AX12_POS_STEP);
			vm[j] = osc_velocity_filter_update(&vf[j], xm[j], dt);
		}
		if (s * dt < run->starter_s) {
			for (size_t j = 0; j < run->njoints; j++)
				xn[j] = osc_sinusoid(0.8, 0.8, 0.0, j, s * dt);
		} else {
			assert_true(osc_step(p, run->njoints, xm, vm, dt + run->lead, 4, xn, NULL));
		}
		for (int k = 0; k < SERVO_SUBSTEPS; k++) {
			for (size_t j = 0; j < run->njoints; j++) {
				if (k == SERVO_WRITE_DELAY)
					sj[j].goal_units = round(xn[j] / AX12_POS_STEP);
				double before = sj[j].angle;
				servo_physics(&sj[j], run->margin, hs);
				double t = s * dt + (k + 1) * hs;
				if (t >= run->t_to - 15.0)
					cross_sample(&c, j, t - hs, before, t, sj[j].angle);
			}
		}
	}
	return cross_result(&c, run->njoints);
}

static void test_closed_loop_through_servo(void **state)
{
	(void)state;
	/* as the daemon starts: two seconds of the baseline sinusoid, then the oscillator */
	struct servo_run run = { .njoints = 2, .lead = OSC_SERVO_LEAD_S, .margin = 1.0,
	                         .x0 = { 0.0, 0.0 }, .starter_s = 2.0, .t_to = 40.0 };
	struct cycle r = run_servo(&run);
	print_message("servo loop, horizon dt+%.3f s: A0 %.3f A1 %.3f rad, f %.3f Hz, lag %.1f deg\n",
	              OSC_SERVO_LEAD_S, r.amp[0], r.amp[1], r.freq, r.lag_deg);
	/* the defaults' purpose: the paper's 0.8 Hz, 0.8 rad on the servo */
	assert_in_range(lround(r.freq * 100), 74, 86);
	assert_in_range(lround(r.amp[0] * 100), 72, 88);
	assert_in_range(lround(r.amp[1] * 100), 72, 88);
	assert_true(r.lag_deg > 60.0 && r.lag_deg < 120.0);
	/* from rest without the starter, one joint bent by 0.4 rad, either joint:
	 * the same cycle (the lead's surplus over the loop's lag gets it moving) */
	for (size_t j = 0; j < TWO_JOINTS; j++) {
		struct servo_run rest = run;
		rest.starter_s = 0.0;
		rest.x0[j] = 0.4;
		rest.x0[1 - j] = 0.0;
		struct cycle q = run_servo(&rest);
		print_message("servo loop from rest, joint %zu at 0.4 rad: A0 %.3f A1 %.3f rad, f %.3f Hz\n",
		              j, q.amp[0], q.amp[1], q.freq);
		assert_true(fabs(q.freq - r.freq) < 0.03 * r.freq);
		assert_true(fabs(q.amp[0] - r.amp[0]) < 0.03 && fabs(q.amp[1] - r.amp[1]) < 0.03);
	}
	/* compliance margin 0 (less dead band, less lag): faster, still near */
	struct servo_run m0 = run;
	m0.margin = 0.0;
	struct cycle z = run_servo(&m0);
	print_message("servo loop, margin 0: A0 %.3f A1 %.3f rad, f %.3f Hz\n", z.amp[0], z.amp[1], z.freq);
	assert_true(z.freq > r.freq && z.freq < 0.90);
	assert_true(z.amp[0] > 0.72 && z.amp[0] < 0.95 && z.amp[1] > 0.72 && z.amp[1] < 0.95);
	/* ... and with the lead meant for margin 0, back at 0.8 Hz, 0.8 rad, and a
	 * joint resting only 0.1 rad from neutral starts by itself */
	m0.lead = OSC_SERVO_LEAD_MARGIN0_S;
	struct cycle z0 = run_servo(&m0);
	m0.starter_s = 0.0;
	m0.x0[0] = 0.1;
	m0.x0[1] = 0.0;
	struct cycle z1 = run_servo(&m0);
	print_message("servo loop, margin 0, lead %.3f s: A0 %.3f A1 %.3f rad, f %.3f Hz; from 0.1 rad: "
	              "A0 %.3f, f %.3f Hz\n", OSC_SERVO_LEAD_MARGIN0_S, z0.amp[0], z0.amp[1], z0.freq,
	              z1.amp[0], z1.freq);
	assert_in_range(lround(z0.freq * 100), 74, 86);
	assert_in_range(lround(z0.amp[0] * 100), 72, 88);
	assert_in_range(lround(z0.amp[1] * 100), 72, 88);
	assert_true(fabs(z1.freq - z0.freq) < 0.03 * z0.freq && fabs(z1.amp[0] - z0.amp[0]) < 0.03);
	/* without the lead the servo never reaches the goal and the loop dies */
	struct servo_run none = run;
	none.lead = 0.0;
	none.starter_s = 0.0;
	none.x0[0] = 0.3;
	none.x0[1] = -0.1;
	none.t_to = 30.0;
	struct cycle d = run_servo(&none);
	print_message("servo loop, horizon dt only: A0 %.3f A1 %.3f rad\n", d.amp[0], d.amp[1]);
	assert_true(d.amp[0] < 0.2 && d.amp[1] < 0.2);
}

static void test_single_joint_through_servo(void **state)
{
	(void)state;
	struct servo_run run = { .njoints = 1, .lead = OSC_SERVO_LEAD_S, .margin = 1.0,
	                         .x0 = { 0.3, 0.0 }, .t_to = 40.0 };
	struct cycle r = run_servo(&run);
	print_message("single joint through the servo: A %.3f rad, f %.3f Hz\n", r.amp[0], r.freq);
	assert_in_range(lround(r.freq * 100), 74, 86);
	assert_in_range(lround(r.amp[0] * 100), 72, 88);
}

/* ---- baseline sinusoid, phase helpers ------------------------------------- */

static void test_sinusoid_values(void **state)
{
	(void)state;
	const double A = 0.8, f = 0.8;
	assert_true(fabs(osc_sinusoid(A, f, 0.0, 0, 0.0)) < 1e-12);
	assert_true(fabs(osc_sinusoid(A, f, PI / 2, 0, 0.0) - 0.8) < 1e-12);
	/* a quarter period later the argument fell by π/2 */
	assert_true(fabs(osc_sinusoid(A, f, 0.0, 0, 0.3125) + 0.8) < 1e-12);
	/* joint 1 leads by 2π/3 in the argument: 0.8·sin(2π/3) = 0.69282 */
	assert_true(fabs(osc_sinusoid(A, f, 0.0, 1, 0.0) - 0.6928203230) < 1e-9);
	/* joint 1 at time t equals joint 0 a third of a period earlier */
	for (double t = 0.0; t < 3.0; t += 0.137)
		assert_true(fabs(osc_sinusoid(A, f, 0.4, 1, t) -
		                 osc_sinusoid(A, f, 0.4, 0, t - 1.0 / (3.0 * f))) < 1e-12);
	/* periodic in t and in joint index mod 3 */
	assert_true(fabs(osc_sinusoid(A, f, 0.4, 0, 0.77) - osc_sinusoid(A, f, 0.4, 0, 0.77 + 1.25)) < 1e-12);
	assert_true(fabs(osc_sinusoid(A, f, 0.4, 3, 0.77) - osc_sinusoid(A, f, 0.4, 0, 0.77)) < 1e-12);
}

/* The phase and the frequency/amplitude estimator the daemon publishes:
 * test_common_phase.c (common/phase.h). */

static void test_velocity_filter_ramp(void **state)
{
	(void)state;
	struct osc_velocity_filter f;
	osc_velocity_filter_init(&f, 10.0);
	assert_true(osc_velocity_filter_update(&f, 1.0, 0.01) == 0.0);   /* primes */
	double v = 0.0;
	for (int i = 1; i <= 100; i++)
		v = osc_velocity_filter_update(&f, 1.0 + 2.0 * i * 0.01, 0.01);
	assert_true(fabs(v - 2.0) < 1e-6);
	/* after one step of the ramp the filter has moved 1 − e^(−2π·10·0.01) of the way */
	osc_velocity_filter_init(&f, 10.0);
	osc_velocity_filter_update(&f, 0.0, 0.01);
	v = osc_velocity_filter_update(&f, 0.02, 0.01);
	assert_true(fabs(v - 2.0 * (1.0 - exp(-2.0 * PI * 0.1))) < 1e-12);

	/* bad dt keeps the speed and counts; bad x keeps everything */
	osc_velocity_filter_init(&f, 10.0);
	for (int i = 0; i <= 100; i++)
		v = osc_velocity_filter_update(&f, 2.0 * i * 0.01, 0.01);
	assert_true(osc_velocity_filter_update(&f, 2.02, 0.0) == v);
	assert_true(osc_velocity_filter_update(&f, 2.04, -0.01) == v);
	assert_true(osc_velocity_filter_update(&f, 2.06, NAN) == v);
	assert_true(osc_velocity_filter_update(&f, NAN, 0.01) == v);
	assert_true(f.rejected == 4);
	/* and resumes from the newest good angle */
	v = osc_velocity_filter_update(&f, 2.08, 0.01);
	assert_true(fabs(v - 2.0) < 1e-6);

	/* cut-off <= 0: the raw finite difference */
	osc_velocity_filter_init(&f, 0.0);
	osc_velocity_filter_update(&f, 0.0, 0.01);
	assert_true(fabs(osc_velocity_filter_update(&f, 0.03, 0.01) - 3.0) < 1e-12);
}

static void test_velocity_filter_sine(void **state)
{
	(void)state;
	struct osc_velocity_filter f;
	osc_velocity_filter_init(&f, OSC_VELOCITY_CUTOFF_HZ);
	const double A = 0.8, fr = 0.8, w = 2.0 * PI * fr, dt = 0.01;
	double hi = 0.0, t_hi = 0.0;
	for (int i = 0; i <= 1000; i++) {
		double t = i * dt;
		double v = osc_velocity_filter_update(&f, A * sin(w * t), dt);
		if (t > 8.75 && t <= 10.0 && v > hi) {   /* one period */
			hi = v;
			t_hi = t;
		}
	}
	/* first-order low-pass: gain 1/√(1+(f/fc)²); delay atan(f/fc)/ω plus half a sample */
	double gain = 1.0 / sqrt(1.0 + (fr / OSC_VELOCITY_CUTOFF_HZ) * (fr / OSC_VELOCITY_CUTOFF_HZ));
	double delay = atan(fr / OSC_VELOCITY_CUTOFF_HZ) / w + dt / 2.0;
	print_message("sine: peak %.4f (want %.4f), delay %.4f s (want %.4f)\n", hi, A * w * gain,
	              fmod(t_hi, 1.0 / fr), delay);
	assert_true(fabs(hi - A * w * gain) < 0.01 * A * w);
	assert_true(fabs(fmod(t_hi, 1.0 / fr) - delay) <= dt);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_limit_cycle_same_from_any_start),
		cmocka_unit_test(test_single_joint_limit_cycle),
		cmocka_unit_test(test_coupling_gives_steady_travelling_wave),
		cmocka_unit_test(test_coupling_phase_sets_the_lag),
		cmocka_unit_test(test_chain_of_three_couples_to_next_joint),
		cmocka_unit_test(test_rk4_matches_exact_harmonic),
		cmocka_unit_test(test_independent_of_step_size),
		cmocka_unit_test(test_velocity_jump_shifts_phase),
		cmocka_unit_test(test_non_finite_input_holds),
		cmocka_unit_test(test_friction_term_is_smooth_sign),
		cmocka_unit_test(test_closed_loop_through_servo),
		cmocka_unit_test(test_single_joint_through_servo),
		cmocka_unit_test(test_sinusoid_values),
		cmocka_unit_test(test_velocity_filter_ramp),
		cmocka_unit_test(test_velocity_filter_sine),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
