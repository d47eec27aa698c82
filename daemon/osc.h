/*
 * osc.h — the control laws, pure: no clock (dt is an argument), no I/O.
 *
 * OSCILLATOR (the paper's limit cycle, integrated from the *measured* state):
 *     I ẍ_j = −k (x_j + λ_j x̃_other) + (c − μ x_j²) ẋ_j  [+ b·sgn(ẋ_j)]
 *     x̃_other = x_other cos θ_j + (ẋ_other / ω_j) sin θ_j,   ω_j = √(k_j / I_j)
 * θ_j = 0 (the default) is the paper's law, x̃_other = x_other; a θ turns the
 * joints' lag (CONTROL.md, "The joints' lag").
 * Each cycle takes the measured (x, ẋ) of both joints, integrates the coupled
 * equations over the horizon (one control period plus OSC_SERVO_LEAD_S, RK4
 * sub-steps), and returns the angle to command. "Other" is the next joint in
 * the chain; the last joint couples to the one before it (so with two joints
 * each couples to the other); a single joint ignores λ. sgn is smoothed:
 * tanh(ẋ / 0.05 rad/s). Never integrated open-loop from its own last state:
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

#define OSC_MAX_JOINTS 24  /* a robot has 2, a rig 1; up to 24 so one daemon can drive a long bus (benchmarks) */

struct osc_joint_params {
	double k;         /* N·m/rad: stiffness -> frequency ≈ √(k/I)/2π */
	double c;         /* N·m·s/rad: negative damping (energy in) */
	double mu;        /* N·m·s/rad³: amplitude ≈ 2√(c/μ) for weak nonlinearity */
	double lambda;    /* coupling to the other joint (paper: 1.5, −0.5) */
	double inertia;   /* kg·m² */
	double friction;  /* b, N·m: friction compensation (0 = off) */
	double coupling_phase;   /* θ, rad: the coupling sees the other joint θ further on in its
	                            cycle (0: its angle as it is; CONTROL.md, "The joints' lag") */
};

/* What the daemon should pass as `horizon`: the measured dt plus this lead.
 * The servo reaches a goal late: its position loop trails by ≈ 27 ms at
 * compliance slope 32 (slope / no-load speed), plus half a control period of
 * goal hold, the bus time and the dead band. Measured on the simulated AX-12A
 * (factory margin 1), the loop neither gains nor loses energy with a lead of
 * ≈ 0.0245 s; less and it dies into the position quantum, more and it feeds
 * energy. 0.028 s keeps a margin above that edge, so that a joint stopped
 * 0.3 rad from neutral starts again by itself. The defaults of
 * osc_default_params() are tuned for this value: change one, retune the other
 * (CONTROL.md has the tables). Configurable in the daemon: it depends on the
 * servo (compliance, inertia, bus). */
#define OSC_SERVO_LEAD_S 0.028
/* The same for a servo whose compliance margin was set to 0 (less dead band,
 * less lag): with this lead the same defaults give 0.81–0.82 Hz, 0.81–0.85 rad,
 * and a joint resting 0.1 rad from neutral starts by itself (CONTROL.md). */
#define OSC_SERVO_LEAD_MARGIN0_S 0.026
/* Cut-off for osc_velocity_filter (on measured positions) with which the lead
 * and the defaults were tuned: a lower cut-off lags more and slows the closed
 * loop down (10 Hz: −10 % in frequency), a higher one speeds it up. */
#define OSC_VELOCITY_CUTOFF_HZ 20.0

/* Defaults giving ≈0.8 Hz and ≈0.8 rad on the simulated AX-12A through the
 * daemon with OSC_SERVO_LEAD_S and OSC_VELOCITY_CUTOFF_HZ (not in the bare
 * equation, which runs faster and smaller; CONTROL.md has the measured numbers):
 * two joints get λ = 1.5 (even joints) and −0.5 (odd joints), one joint λ = 0. */
void osc_default_params(struct osc_joint_params *p, size_t joint, size_t njoints);

/* Defaults for torque actuation (CONTROL.md, "Torque actuation"): the law's
 * torque drives the joint directly, so the parameters are physical; tuned for
 * ≈0.8 Hz, ≈0.8 rad on one simulated AX-12A joint with an 18.65 cm link, on a
 * current drive, or on the AX-12's PWM drive (`pwm`: a stiffer k). */
void osc_default_torque_params(struct osc_joint_params *p, size_t joint, size_t njoints, bool pwm);
/* The joint those defaults are for: the simulated AX-12A's with its link
 * (kg·m²). Another servo's joint scales them by its inertia over this one
 * (servo_model.h, sm_torque_scale): the same law on a heavier joint gives
 * the same gait when k, c, μ, b and I scale alike. */
#define OSC_TORQUE_JOINT_INERTIA 4.39e-3

/* Torque actuation: the law's right-hand side at the measured state,
 *     τ_j = −k (x_j + λ_j x̃_other) + (c − μ x_j²) ẋ_j + b·sgn(ẋ_j)   (N·m).
 * Non-finite state or parameters give 0 for every joint (no drive) and false;
 * njoints 0 or > OSC_MAX_JOINTS: false, nothing written. */
bool osc_torque(const struct osc_joint_params *p, size_t njoints, const double *x, const double *v,
                double *torque);

/* Integrate the coupled oscillator from measured state (x[j], v[j]) over
 * `horizon` seconds (the daemon passes measured dt + OSC_SERVO_LEAD_S), using
 * `substeps` RK4 steps (clamped to 1..1000).
 * Writes the predicted angles into x_next (and speeds into v_next if not NULL).
 * Non-finite inputs or parameters (or inertia <= 0, horizon < 0) give x_next = x
 * (hold; v_next = v, 0 where non-finite) and return false; so does a state that
 * overflows during the integration. njoints 0 or > OSC_MAX_JOINTS: false, nothing written. */
bool osc_step(const struct osc_joint_params *p, size_t njoints, const double *x, const double *v,
              double horizon, int substeps, double *x_next, double *v_next);

/* The baseline: commanded angle of joint j at time t (s). Non-finite arguments
 * give a non-finite result: the caller checks before commanding it. */
double osc_sinusoid(double amplitude, double frequency, double phase, size_t joint, double t);
/* Its speed, dx̄_j/dt (rad/s), with the same care for a wall-clock t. */
double osc_sinusoid_rate(double amplitude, double frequency, double phase, size_t joint, double t);

/* Torque actuation's SINUSOID: the clock as a torque law, as the paper's
 * force simulations drove their joints (k_s 0.015..0.135 N·m/rad there):
 *     τ_j = k_s (x̄_j(t) − x_j) + d_s (dx̄_j/dt − ẋ_j)      (N·m)
 * from the measured state. d_s = 0 is the paper's (purely proportional) law;
 * the damping acts on the difference from the clock's own speed, so it never
 * resists following the clock. Non-finite state, time or parameters give 0
 * for every joint (no drive) and false; njoints 0 or > OSC_MAX_JOINTS:
 * false, nothing written. */
struct osc_clock {
	double amplitude;   /* rad */
	double frequency;   /* Hz */
	double phase;       /* rad */
	double stiffness;   /* k_s, N·m/rad */
	double damping;     /* d_s, N·m·s/rad */
};
bool osc_clock_torque(const struct osc_clock *k, size_t njoints, double t, const double *x, const double *v,
                      double *torque);

/* The phase of a joint and its running frequency and amplitude: common/phase.h
 * (one definition for the daemon and the analyser). */

/* Velocity from positions: first-order low-pass of the finite difference
 * (the servo's own speed reading is coarse: 0.111 rpm steps, noisy). */
struct osc_velocity_filter {
	double cutoff_hz;
	double last_x;
	double v;
	bool primed;
	unsigned long rejected;  /* samples ignored: non-finite x, or dt <= 0 / non-finite */
};
void osc_velocity_filter_init(struct osc_velocity_filter *f, double cutoff_hz);
/* dt: seconds since the previous sample. The first sample primes (returns 0);
 * dt <= 0 or non-finite keeps the previous speed; cut-off <= 0: raw difference. */
double osc_velocity_filter_update(struct osc_velocity_filter *f, double x, double dt);

#endif
