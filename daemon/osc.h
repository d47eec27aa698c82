/*
 * osc.h — the control laws, pure: no clock (dt is an argument), no I/O.
 *
 * OSCILLATOR (the paper's limit cycle, integrated from the *measured* state):
 *     I ẍ_j = −k (x_j + λ_j x_other) + (c − μ x_j²) ẋ_j  [+ b·sgn(ẋ_j)]
 * Each cycle takes the measured (x, ẋ) of both joints, integrates the coupled
 * equations over the horizon (one control period, RK4 sub-steps), and returns
 * the angle to command. Never integrated open-loop from its own last state:
 * proprioception is what lets phases slip on contact.
 *
 * SINUSOID (the paper's clock-driven baseline):
 *     x̄_j(t) = A sin(φ + (2π/3)·j − 2π f t)
 *
 * Angles are radians relative to the joint's neutral angle.
 */
#ifndef UNDULATE_OSC_H
#define UNDULATE_OSC_H

#include <stdbool.h>
#include <stddef.h>

#define OSC_MAX_JOINTS 8   /* a robot has 2; a rig may have 1 */

struct osc_joint_params {
	double k;         /* N·m/rad: stiffness -> frequency ≈ √(k/I)/2π */
	double c;         /* N·m·s/rad: negative damping (energy in) */
	double mu;        /* N·m·s/rad³: amplitude ≈ 2√(c/μ) for weak nonlinearity */
	double lambda;    /* coupling to the other joint (paper: 1.5, −0.5) */
	double inertia;   /* kg·m² */
	double friction;  /* b, N·m: friction compensation (0 = off) */
};

/* Defaults giving ≈0.8 Hz and ≈0.8 rad on the simulated robot (documented in osc.c). */
void osc_default_params(struct osc_joint_params *p, size_t joint, size_t njoints);

/* Integrate the coupled oscillator from measured state (x[j], v[j]) over
 * `horizon` seconds (normally the measured dt), using `substeps` RK4 steps.
 * Writes the predicted angles into x_next (and speeds into v_next if not NULL).
 * Non-finite inputs give x_next = x (hold). Returns false if anything was non-finite. */
bool osc_step(const struct osc_joint_params *p, size_t njoints, const double *x, const double *v,
              double horizon, int substeps, double *x_next, double *v_next);

/* The baseline: commanded angle of joint j at time t (s). */
double osc_sinusoid(double amplitude, double frequency, double phase, size_t joint, double t);

/* Phase of an oscillation from (x, ẋ): atan2(−ẋ/ω, x), in (−π, π]. */
double osc_phase(double x, double v, double omega);
/* Wrap an angle into (−π, π]. */
double osc_wrap(double a);

/* Running estimate of amplitude and frequency from successive samples. */
struct osc_estimator {
	double amplitude;      /* rad, peak of |x| over recent half-cycles (smoothed) */
	double frequency;      /* Hz, from upward zero crossings (0 until two seen) */
	double last_x;
	double last_cross_t;
	double peak;
	bool have_last, have_cross;
};
void osc_estimator_init(struct osc_estimator *e);
void osc_estimator_update(struct osc_estimator *e, double x, double t);

/* Velocity from positions: first-order low-pass of the finite difference
 * (the servo's own speed reading is coarse: 0.111 rpm steps, noisy). */
struct osc_velocity_filter {
	double cutoff_hz;
	double last_x;
	double v;
	bool primed;
};
void osc_velocity_filter_init(struct osc_velocity_filter *f, double cutoff_hz);
double osc_velocity_filter_update(struct osc_velocity_filter *f, double x, double dt);

#endif
