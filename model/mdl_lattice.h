/* mdl_lattice.h — the paper's model integrated: N phase oscillators in a row
 * (a pair is N = 2), each x_i = A cos(phi_i) about its neutral position n_i,
 * phi_i' = omega; neighbours collide when their bodies X_i = n_i + x_i meet
 * while approaching, inelastically (mdl_collide.h), and the collision gives
 * each its new phase phi = atan2(-v/omega, x) back on its cycle of amplitude A
 * (theory.md: the phase model has no amplitude of its own; lat_params.
 * amplitude_rate gives each one, mdl_lattice.c lat_law). Mobility: at each
 * impact a body's neutral position moves by beta_i (v_other - v_self), with
 * the speeds before the impact (DESIGN.md; the simulator's rule); a wall's
 * speed is 0. Pure code: no I/O, no clock.
 *
 * The phases are integrated with GSL's odeiv2 (an embedded Runge-Kutta pair
 * with error control). Collisions are events: after each step, every contact
 * function g_k = X_k - X_{k-1} (a wall's: the gap to it) is looked at over
 * the step; a fall through zero, or a dip below zero inside the step (found
 * by Brent's method on g_k' = the relative speed), is located by Brent's
 * method on g_k(t), each value obtained by integrating from the step's start
 * to t. The collision is applied at that instant, never at a step's end.
 * Steps are at most an eighth of a period, so each holds at most one
 * extremum of a g_k (a sinusoid at omega between impacts).
 *
 * A collision's jump (the new phases on the cycle of amplitude A, a
 * mobility shift) can leave a neighbouring pair overlapping. Such a pair
 * collides at once when it is approaching (`immediate` in the event), and is
 * let through until it separates when it is not (counted in lat_overlaps);
 * so is one still approaching after 4 n immediate collisions at one instant
 * (a chain that does not die out).
 * The pair that just collided is never collided again before its next
 * approach: that is theory.md's return map. */
#ifndef UNDULATE_MODEL_LATTICE_H
#define UNDULATE_MODEL_LATTICE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Oscillators at most: the row's arrays are allocated once at lat_new. */
#define LAT_MAX_OSC 10000

struct lat_params {
	int n;                  /* oscillators, 1..LAT_MAX_OSC */
	double frequency_hz;    /* every oscillator's: omega = 2 pi f */
	double amplitude;       /* A: x = A cos(phi) */
	double restitution;     /* r in [0, 1], between bodies and against walls */
	double dsep;            /* d~ of each neighbouring pair at the start: neutral positions 2 A d~ apart */
	const double *beta;     /* n mobilities (s), >= 0; NULL: all 0 (immobile bases) */
	bool walls;             /* walls beyond both end oscillators */
	double wall_dsep;       /* a wall stands 2 A wall_dsep beyond its end oscillator's neutral position */
	double tolerance;       /* the integrator's absolute and relative error per step; 0: 1e-12 */
	/* 0: the paper's phase model. > 0: each oscillator has an amplitude of
	 * its own, a van der Pol limit cycle of amplitude A whose amplitude
	 * comes back at this rate (1/s) after an impact takes some (mdl_lattice.c,
	 * lat_law): an impact changes a body's speed only, not its place. */
	double amplitude_rate;
};
/* Largest amplitude rate (1/s): far above any limit cycle a joint runs. */
#define LAT_AMPLITUDE_RATE_MAX 1000.0

/* One impact. Contact k (0..n): k = 0 the left wall, k = n the right wall,
 * else oscillators k-1 (left) and k (right). Speeds are dx/dt; a wall's are 0. */
struct lat_event {
	double t;
	int contact;
	int left, right;                /* oscillator indices; -1 for a wall */
	double pre_left, pre_right;
	double post_left, post_right;
	double x_left, x_right;         /* displacements A cos(phi) at the impact; a wall's NAN */
	double impulse;                 /* unit mass: the left body's change of speed (a wall's body's) */
	double delta_before;            /* phi_right - phi_left in (-pi, pi]; NAN at a wall */
	double delta_after;
	double dsep_before;             /* the pair's (n_right - n_left) / 2A before the impact; NAN at a wall */
	bool immediate;                 /* found overlapping and approaching after a jump */
};

enum lat_status { LAT_REACHED, LAT_COLLISION, LAT_FAILED };

struct lat;

/* A row at t = 0 with phases phase0 (n values), or NULL and err. Neutral
 * positions 0, 2A d~, 4A d~, ... */
struct lat *lat_new(const struct lat_params *p, const double *phase0, char *err, size_t errcap);
void lat_free(struct lat *l);

/* Integrates until t_stop or the next collision, whichever comes first. At
 * a collision the impact is applied (phases, neutral positions), *ev filled
 * and LAT_COLLISION returned with lat_time() at the impact; call again to go
 * on. LAT_FAILED: the integrator failed (err says why). */
enum lat_status lat_advance(struct lat *l, double t_stop, struct lat_event *ev, char *err, size_t errcap);

double lat_time(const struct lat *l);
int lat_count(const struct lat *l);
double lat_omega(const struct lat *l);
/* phase of oscillator i in (-pi, pi], its displacement A cos(phi), speed,
 * neutral position, body position n_i + x_i */
double lat_phase(const struct lat *l, int i);
double lat_displacement(const struct lat *l, int i);
/* its amplitude: A in the phase model, else |(x, x'/omega)| now */
double lat_amplitude(const struct lat *l, int i);
double lat_speed(const struct lat *l, int i);
double lat_neutral(const struct lat *l, int i);
double lat_wall(const struct lat *l, int right);      /* NAN without walls */
/* Pairs left overlapping and separating after a jump (see above). */
int64_t lat_overlaps(const struct lat *l);
/* Integrator steps taken and contact-function values computed to locate
 * collisions: the work done, for the benchmark. */
int64_t lat_steps(const struct lat *l);
int64_t lat_root_evals(const struct lat *l);

/* n phases drawn uniformly from seed (splitmix64: the same on every
 * machine), each oscillator's drawn again (up to LAT_DRAW_TRIES times) while
 * it would overlap its left neighbour or a wall at t = 0. Returns how many
 * were left overlapping after the tries (a row packed so tight that no
 * draw fits: such pairs collide at once when approaching). */
#define LAT_DRAW_TRIES 1000
int lat_random_phases(const struct lat_params *p, uint64_t seed, double *phase);

#endif
