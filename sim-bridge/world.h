/*
 * world.h — the contact world: robots in a row (the paper's one-dimensional
 * lattice). Each robot has one contact body attached to one of its joints;
 * the body's lateral coordinate is X = n + lever · angle (n its neutral
 * position). Neighbours collide when X_i reaches X_{i+1} while approaching:
 * an instantaneous inelastic collision with restitution r, equal effective
 * inertia, momentum conserved (PHYSICS.md, section 2):
 *     v_i+ = ½[(1 − r) v_i + (1 + r) v_j],  v_j+ = ½[(1 − r) v_j + (1 + r) v_i]
 * Mobility: right after a collision each body's neutral position moves by
 * δ_i = β (v_j − v_i) (pre-collision speeds). Walls bound the row; bodies
 * never pass each other or a wall (no tunnelling at any speed).
 *
 * Pure: the caller steps the motors, then calls sim_world_resolve(), which
 * reads and rewrites the joint speeds (and angles, to undo penetration) of
 * the motors the bodies point to.
 */
#ifndef UNDULATE_SIM_WORLD_H
#define UNDULATE_SIM_WORLD_H

#include <stdbool.h>
#include <stddef.h>

#include "motor.h"

#define SIM_MAX_BODIES 64
#define SIM_MAX_COLLISIONS_PER_STEP (SIM_MAX_BODIES + 2)

struct sim_body {
	struct sim_motor *motor;   /* the contact joint (not owned) */
	double lever;              /* m per rad: lateral displacement per joint angle */
	double neutral;            /* m, n_i */
	double half_width;         /* m, the body's extent on each side of X (bumper) */
	double effective_mass;     /* kg, for the impulse (equal for all, per the model) */
	int robot;                 /* index of the robot, for reports */
	/* The body's own mobility (s), in place of the world's β: the paper's
	 * lattices hold their end oscillators (β = 0 for them). */
	bool own_beta;
	double beta;
};

struct sim_world_params {
	double restitution;        /* r, 0..1 (paper's rig: 0.67) */
	double beta;               /* mobility, s (δ = β·Δv; 0 = immobile base) */
	double wall_left, wall_right;  /* m; wall_left >= wall_right means no walls */
	double wall_restitution;
};

struct sim_collision {
	double time;               /* s, world time */
	int left, right;           /* body indices; -1 = wall */
	double pre_left, pre_right, post_left, post_right;  /* m/s lateral */
	double impulse;            /* N·s = effective_mass · |Δv| */
	/* Resting contact, not an impact: the pair was already touching and closed
	 * only by what the motors did during this step (persistent push). Such a
	 * contact is perfectly inelastic and repeats every step while the push
	 * lasts; its impulses still sum to the contact force × time. */
	bool resting;
};

struct sim_world {
	struct sim_world_params params;
	size_t nbodies;            /* bodies ordered left to right */
	struct sim_body bodies[SIM_MAX_BODIES];
	double time;
	unsigned long long total_collisions;
	double total_impulse;
	/* additive diagnostics (PHYSICS.md): */
	unsigned long long unresolved_steps;  /* contact sweeps hit their cap; finished next step */
	unsigned long long infeasible_steps;  /* the row is wider than the space between the walls */
	unsigned long long bad_input;         /* rejected bodies/params, repaired non-finite state */
	unsigned long long resting_contacts;  /* of total_collisions, those with resting set */
	double resting_impulse;               /* of total_impulse, N·s carried by resting contact */
	/* contact memory between steps (for resting contact; see PHYSICS.md) */
	unsigned char in_contact[SIM_MAX_BODIES + 1];  /* pair k touched (or was within a step of it) */
	double prev_speed[SIM_MAX_BODIES];            /* lateral speed at the end of the last step */
};

void sim_world_init(struct sim_world *w, const struct sim_world_params *p);
/* Append a body (left to right). Returns its index, or -1 when full or when the
 * body is invalid (no motor, lever 0 or non-finite, negative half-width or mass). */
int sim_world_add_body(struct sim_world *w, const struct sim_body *b);
double sim_world_lateral(const struct sim_world *w, size_t i);          /* X_i */
double sim_world_lateral_speed(const struct sim_world *w, size_t i);    /* lever · angular speed */
/* After the motors moved by dt: detect and resolve every contact, write up to
 * cap collisions into out (one per touching pair and step, merged over the
 * pair's impulses) and return how many were written, <= cap (all are counted
 * in the totals even when out is full or NULL). */
size_t sim_world_resolve(struct sim_world *w, double dt, struct sim_collision *out, size_t cap);

#endif
