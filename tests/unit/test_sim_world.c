/*
 * test_sim_world.c — the contact world: the collision law (restitution,
 * momentum), mobility, walls, no tunnelling at any speed, chains, a
 * persistent push between two position-controlled joints, and the ordering
 * invariant over long random runs.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <cmocka.h>

#include "dxl_table.h"
#include "../../sim-bridge/motor.h"
#include "../../sim-bridge/world.h"

#define LEVER 0.2
#define HALF  0.05
#define TOL   1e-9

/* Deterministic generator for the random runs (xorshift64*). */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double rnd(void)
{
	rng_state ^= rng_state >> 12;
	rng_state ^= rng_state << 25;
	rng_state ^= rng_state >> 27;
	return (double)((rng_state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}
static double rnd_range(double lo, double hi)
{
	return lo + (hi - lo) * rnd();
}

static struct sim_world_params world_params(double r, double beta)
{
	struct sim_world_params p = {
		.restitution = r, .beta = beta, .wall_left = 0, .wall_right = 0,
		.wall_restitution = 0.5,
	};
	return p;
}

static struct sim_motor motors[SIM_MAX_BODIES];

/* n bodies, lever LEVER, half-width HALF, neutrals `spacing` apart from 0. */
static void world_row(struct sim_world *w, const struct sim_world_params *p, size_t n, double spacing)
{
	struct sim_motor_params mp;
	sim_motor_default_params(&mp);
	sim_world_init(w, p);
	for (size_t i = 0; i < n; i++) {
		sim_motor_init(&motors[i], &mp, 0);
		struct sim_body b = {
			.motor = &motors[i], .lever = LEVER, .neutral = spacing * (double)i,
			.half_width = HALF, .effective_mass = 0.13, .robot = (int)i,
		};
		assert_int_equal(sim_world_add_body(w, &b), (int)i);
	}
}

/* Place body i at lateral X with lateral speed V (through its motor). */
static void put(struct sim_world *w, size_t i, double x, double v)
{
	motors[i].angle = (x - w->bodies[i].neutral) / w->bodies[i].lever;
	motors[i].speed = v / w->bodies[i].lever;
}

/* The motors' free flight over dt (what the motor step would do at constant speed). */
static void drift(struct sim_world *w, double dt)
{
	for (size_t i = 0; i < w->nbodies; i++)
		motors[i].angle += motors[i].speed * dt;
}

/* Resolve, returning how many collisions the step reported. */
static size_t resolve(struct sim_world *w, double dt)
{
	struct sim_collision c[SIM_MAX_COLLISIONS_PER_STEP];
	return sim_world_resolve(w, dt, c, SIM_MAX_COLLISIONS_PER_STEP);
}

static void assert_ordered(const struct sim_world *w)
{
	for (size_t i = 0; i + 1 < w->nbodies; i++) {
		double gap = (sim_world_lateral(w, i + 1) - w->bodies[i + 1].half_width)
		             - (sim_world_lateral(w, i) + w->bodies[i].half_width);
		if (!(gap >= -TOL))
			fail_msg("bodies %zu and %zu overlap by %g m", i, i + 1, -gap);
	}
	if (w->params.wall_left < w->params.wall_right && w->nbodies > 0) {
		size_t last = w->nbodies - 1;
		assert_true(sim_world_lateral(w, 0) - w->bodies[0].half_width >= w->params.wall_left - TOL);
		assert_true(sim_world_lateral(w, last) + w->bodies[last].half_width
		            <= w->params.wall_right + TOL);
	}
}

static void test_collision_law(void **state)
{
	(void)state;
	for (int trial = 0; trial < 1000; trial++) {
		double r = trial == 0 ? 0.67 : rnd();
		struct sim_world_params p = world_params(r, 0);
		struct sim_world w;
		world_row(&w, &p, 2, 0.3);
		if (trial & 1)
			w.bodies[1].lever = -LEVER;   /* a mirrored joint: CCW moves it left */
		double vi = rnd_range(-2, 3), vj = vi - rnd_range(0.01, 5);   /* closing */
		put(&w, 0, 0.1 + rnd_range(0, 0.01), vi);       /* touching or overlapping */
		put(&w, 1, 0.2, vj);
		struct sim_collision c[SIM_MAX_COLLISIONS_PER_STEP];
		size_t nc = sim_world_resolve(&w, 0.001, c, SIM_MAX_COLLISIONS_PER_STEP);
		assert_int_equal(nc, 1);
		double ui = sim_world_lateral_speed(&w, 0), uj = sim_world_lateral_speed(&w, 1);
		/* relative speed reversed and scaled by r; momentum kept (equal inertia) */
		assert_true(fabs((uj - ui) + r * (vj - vi)) < 1e-12);
		assert_true(fabs((ui + uj) - (vi + vj)) < 1e-12);
		/* the report carries the same numbers */
		assert_int_equal(c[0].left, 0);
		assert_int_equal(c[0].right, 1);
		assert_true(fabs(c[0].pre_left - vi) < 1e-12 && fabs(c[0].pre_right - vj) < 1e-12);
		assert_true(fabs(c[0].post_left - ui) < 1e-12 && fabs(c[0].post_right - uj) < 1e-12);
		assert_true(fabs(c[0].impulse - 0.13 * 0.5 * (1 + r) * (vi - vj)) < 1e-12);
		assert_true(w.total_collisions == 1 && fabs(w.total_impulse - c[0].impulse) < 1e-15);
		assert_ordered(&w);
	}
}

static void test_no_collision_when_separating_or_apart(void **state)
{
	(void)state;
	struct sim_world_params p = world_params(0.67, 0.1);
	struct sim_world w;
	world_row(&w, &p, 2, 0.3);
	/* touching but moving apart: no collision, speeds untouched */
	put(&w, 0, 0.1, -1);
	put(&w, 1, 0.2, 1);
	struct sim_motor before[2] = {motors[0], motors[1]};
	assert_int_equal(sim_world_resolve(&w, 0.001, NULL, 0), 0);
	assert_true(motors[0].speed == before[0].speed && motors[1].speed == before[1].speed);
	/* apart and closing: nothing yet, and not a bit of any motor changes */
	put(&w, 0, 0.05, 1);
	put(&w, 1, 0.25, -1);
	memcpy(before, motors, sizeof before);
	assert_int_equal(sim_world_resolve(&w, 0.001, NULL, 0), 0);
	assert_memory_equal(before, motors, sizeof before);
	assert_true(w.total_collisions == 0);
	assert_true(w.bodies[0].neutral == 0 && w.bodies[1].neutral == 0.3);
}

static void test_mobility_moves_neutrals(void **state)
{
	(void)state;
	double beta = 0.05;
	struct sim_world_params p = world_params(0.67, beta);
	struct sim_world w;
	world_row(&w, &p, 2, 0.3);
	double vi = 1.5, vj = -0.5;
	put(&w, 0, 0.105, vi);
	put(&w, 1, 0.2, vj);
	assert_int_equal(resolve(&w, 0.001), 1);
	/* δ_i = β (v_j − v_i) with the pre-collision speeds: the pair spreads */
	assert_true(fabs(w.bodies[0].neutral - (0 + beta * (vj - vi))) < 1e-15);
	assert_true(fabs(w.bodies[1].neutral - (0.3 + beta * (vi - vj))) < 1e-15);
	assert_ordered(&w);
	/* an immobile base (β = 0) keeps its neutral position */
	p = world_params(0.67, 0);
	world_row(&w, &p, 2, 0.3);
	put(&w, 0, 0.105, vi);
	put(&w, 1, 0.2, vj);
	assert_int_equal(resolve(&w, 0.001), 1);
	assert_true(w.bodies[0].neutral == 0 && w.bodies[1].neutral == 0.3);
	/* a mobile row pushed together spreads out until it is collision-free:
	 * bodies driven along fixed sinusoids about their (moving) neutrals */
	p = world_params(0.67, 0.02);
	world_row(&w, &p, 5, 0.12);
	double spread0 = w.bodies[4].neutral - w.bodies[0].neutral;
	unsigned long long late = 0;
	for (int k = 0; k < 30000; k++) {
		double t = k * 0.001;
		for (size_t i = 0; i < 5; i++) {
			double ph = 2 * M_PI * t + (double)i * 1.3;
			motors[i].angle = 0.1 * sin(ph) / LEVER;   /* 0.1 m at 1 Hz */
			motors[i].speed = 0.2 * M_PI * cos(ph) / LEVER;
		}
		unsigned long long before = w.total_collisions;
		sim_world_resolve(&w, 0.001, NULL, 0);
		assert_ordered(&w);
		if (k >= 25000)
			late += w.total_collisions - before;
	}
	assert_true(w.total_collisions > 10);
	assert_true(w.bodies[4].neutral - w.bodies[0].neutral > spread0 + 0.1);
	assert_true(late == 0);
}

/* Mobility per body (the paper's lattices hold their end oscillators): a
 * body with a mobility of its own moves by it, whatever the world's; the
 * others by the world's. */
static void test_mobility_per_body(void **state)
{
	(void)state;
	struct sim_world_params p = world_params(0.67, 0.05);
	struct sim_world w;
	world_row(&w, &p, 3, 0.3);
	w.bodies[0].own_beta = true;   /* a fixed end */
	w.bodies[0].beta = 0;
	w.bodies[2].own_beta = true;   /* more mobile than the world */
	w.bodies[2].beta = 0.2;
	double vi = 1.5, vj = -0.5;
	put(&w, 0, 0.105, vi);
	put(&w, 1, 0.2, vj);
	put(&w, 2, 0.6, 0);
	assert_int_equal(resolve(&w, 0.001), 1);
	assert_true(w.bodies[0].neutral == 0);
	assert_true(fabs(w.bodies[1].neutral - (0.3 + 0.05 * (vi - vj))) < 1e-15);
	assert_true(w.bodies[2].neutral == 0.6);
	/* the other pair: body 2's own β against body 1's, the world's */
	double n1 = w.bodies[1].neutral;
	put(&w, 1, n1 + 0.105, 0.8);
	put(&w, 2, n1 + 0.2, -0.4);
	assert_int_equal(resolve(&w, 0.001), 1);
	assert_true(fabs(w.bodies[1].neutral - (n1 + 0.05 * (-0.4 - 0.8))) < 1e-15);
	assert_true(fabs(w.bodies[2].neutral - (0.6 + 0.2 * (0.8 + 0.4))) < 1e-15);
	/* a fixed end against a wall does not move either */
	p = world_params(0.67, 0.05);
	p.wall_left = -0.5;
	p.wall_right = 0.8;
	world_row(&w, &p, 2, 0.3);
	w.bodies[0].own_beta = true;
	w.bodies[0].beta = 0;
	put(&w, 0, -0.46, -2);
	put(&w, 1, 0.3, 0);
	assert_int_equal(resolve(&w, 0.001), 1);
	assert_true(w.bodies[0].neutral == 0);
}

static void test_walls(void **state)
{
	(void)state;
	struct sim_world_params p = world_params(0.67, 0);
	p.wall_left = -0.5;
	p.wall_right = 0.8;
	p.wall_restitution = 0.4;
	struct sim_world w;
	world_row(&w, &p, 2, 0.3);
	put(&w, 0, -0.46, -2);
	put(&w, 1, 0.76, 3);
	struct sim_collision c[SIM_MAX_COLLISIONS_PER_STEP];
	size_t nc = sim_world_resolve(&w, 0.001, c, SIM_MAX_COLLISIONS_PER_STEP);
	assert_int_equal(nc, 2);
	assert_true(fabs(sim_world_lateral_speed(&w, 0) - 0.8) < 1e-12);
	assert_true(fabs(sim_world_lateral_speed(&w, 1) + 1.2) < 1e-12);
	assert_true(c[0].left == -1 && c[0].right == 0);
	assert_true(c[1].left == 1 && c[1].right == -1);
	assert_true(fabs(c[0].impulse - 0.13 * 2.8) < 1e-12);
	/* put back inside exactly at the wall */
	assert_true(fabs(sim_world_lateral(&w, 0) - HALF - p.wall_left) < 1e-12);
	assert_true(fabs(sim_world_lateral(&w, 1) + HALF - p.wall_right) < 1e-12);
	/* far through the wall at absurd speed: back inside, bouncing */
	world_row(&w, &p, 2, 0.3);
	put(&w, 0, -40, -1000);
	put(&w, 1, 0.1, 0);
	nc = sim_world_resolve(&w, 0.1, c, SIM_MAX_COLLISIONS_PER_STEP);
	assert_int_equal(nc, 1);
	assert_ordered(&w);
	assert_true(fabs(sim_world_lateral_speed(&w, 0) - 400) < 1e-9);
	/* walls closer than the row is wide: counted, squeezed evenly, in order,
	 * nothing non-finite */
	p.wall_left = 0;
	p.wall_right = 0.25;   /* three bodies of 0.1 m */
	world_row(&w, &p, 3, 0.1);
	put(&w, 0, 0.05, 1);
	put(&w, 1, 0.12, 0);
	put(&w, 2, 0.2, -1);
	resolve(&w, 0.001);
	assert_true(w.infeasible_steps == 1);
	for (size_t i = 0; i < 3; i++)
		assert_true(isfinite(motors[i].angle) && isfinite(motors[i].speed));
	assert_true(sim_world_lateral(&w, 0) < sim_world_lateral(&w, 1));
	assert_true(sim_world_lateral(&w, 1) < sim_world_lateral(&w, 2));
	assert_true(fabs(sim_world_lateral(&w, 1) - 0.125) < 1e-12);
}

static void test_no_tunnelling(void **state)
{
	(void)state;
	struct sim_world_params p = world_params(0.67, 0);
	struct sim_world w;
	world_row(&w, &p, 2, 0.3);
	/* 1 km/s each, dt 0.1 s: they pass 200 m through each other in one step */
	put(&w, 0, 0.0, 1000);
	put(&w, 1, 0.3, -1000);
	drift(&w, 0.1);
	assert_true(sim_world_lateral(&w, 0) > sim_world_lateral(&w, 1));
	assert_int_equal(resolve(&w, 0.1), 1);
	assert_ordered(&w);
	assert_true(fabs(sim_world_lateral_speed(&w, 0) + 670) < 1e-9);
	assert_true(fabs(sim_world_lateral_speed(&w, 1) - 670) < 1e-9);
	/* a fast body passing several: it ends on its own side of all of them */
	world_row(&w, &p, 6, 0.3);
	put(&w, 0, 0.0, 5000);
	drift(&w, 0.01);
	sim_world_resolve(&w, 0.01, NULL, 0);
	assert_ordered(&w);
	double sum = 0;
	for (size_t i = 0; i < 6; i++)
		sum += sim_world_lateral_speed(&w, i);
	assert_true(fabs(sum - 5000) < 1e-9);
	/* many fast bodies, walls, big steps, free flight: never out of order */
	p = world_params(0.9, 0.001);
	p.wall_left = -1;
	p.wall_right = 4;
	world_row(&w, &p, 12, 0.3);
	for (size_t i = 0; i < 12; i++)
		put(&w, i, 0.3 * (double)i, rnd_range(-500, 500));
	for (int k = 0; k < 5000; k++) {
		drift(&w, 0.05);
		sim_world_resolve(&w, 0.05, NULL, 0);
		assert_ordered(&w);
	}
}

static void test_chains(void **state)
{
	(void)state;
	/* Newton's cradle (r = 1): the speed goes through a touching row */
	struct sim_world_params p = world_params(1.0, 0);
	struct sim_world w;
	world_row(&w, &p, 4, 0.3);
	put(&w, 0, 0.001, 1.0);   /* pressed 1 mm into body 1 */
	put(&w, 1, 0.1, 0);       /* 1..3 touching: 0.1 apart = two half-widths */
	put(&w, 2, 0.2, 0);
	put(&w, 3, 0.3, 0);
	sim_world_resolve(&w, 0.001, NULL, 0);
	assert_true(fabs(sim_world_lateral_speed(&w, 0)) < 1e-12);
	assert_true(fabs(sim_world_lateral_speed(&w, 1)) < 1e-12);
	assert_true(fabs(sim_world_lateral_speed(&w, 2)) < 1e-12);
	assert_true(fabs(sim_world_lateral_speed(&w, 3) - 1.0) < 1e-12);
	assert_ordered(&w);
	/* random chains without walls keep total momentum, whatever r */
	for (int trial = 0; trial < 200; trial++) {
		p = world_params(rnd(), 0);
		world_row(&w, &p, 20, 0.1);
		double sum0 = 0;
		for (size_t i = 0; i < 20; i++) {
			put(&w, i, 0.1 * (double)i + rnd_range(-0.02, 0.02), rnd_range(-3, 3));
			sum0 += sim_world_lateral_speed(&w, i);
		}
		sim_world_resolve(&w, 0.001, NULL, 0);
		assert_ordered(&w);
		double sum1 = 0;
		for (size_t i = 0; i < 20; i++)
			sum1 += sim_world_lateral_speed(&w, i);
		assert_true(fabs(sum1 - sum0) < 1e-12 * 20 * 3);
		/* no touching pair is left closing */
		for (size_t i = 0; i + 1 < 20; i++) {
			double gap = sim_world_lateral(&w, i + 1) - sim_world_lateral(&w, i) - 2 * HALF;
			if (gap < 1e-9)
				assert_true(sim_world_lateral_speed(&w, i) - sim_world_lateral_speed(&w, i + 1) < 1e-9);
		}
	}
}

static void test_report_capacity(void **state)
{
	(void)state;
	struct sim_world_params p = world_params(0.5, 0);
	struct sim_world w;
	world_row(&w, &p, 4, 0.3);
	put(&w, 0, 0.2, 1);
	put(&w, 1, 0.3, -1);
	put(&w, 2, 0.8, 1);
	put(&w, 3, 0.9, -1);
	struct sim_collision c[1];
	assert_int_equal(sim_world_resolve(&w, 0.001, c, 1), 1);
	assert_true(w.total_collisions == 2);
	/* bad bodies are refused, counted */
	struct sim_body bad = {.motor = &motors[0], .lever = 0, .half_width = 0.01, .effective_mass = 1};
	assert_int_equal(sim_world_add_body(&w, &bad), -1);
	bad.lever = NAN;
	assert_int_equal(sim_world_add_body(&w, &bad), -1);
	bad.lever = 0.1;
	bad.motor = NULL;
	assert_int_equal(sim_world_add_body(&w, &bad), -1);
	assert_true(w.bad_input == 3 && w.nbodies == 4);
}

/* Two position-controlled joints pressing into each other: the contact holds
 * without overlap or jitter growth, and both servos show the push as load. */
static void test_persistent_push(void **state)
{
	(void)state;
	struct sim_motor_params mp;
	sim_motor_default_params(&mp);
	struct sim_world_params p = world_params(0.67, 0);
	struct sim_world w;
	sim_world_init(&w, &p);
	struct sim_motor_cmd cmd[2];
	for (size_t i = 0; i < 2; i++) {
		sim_motor_init(&motors[i], &mp, 0);
		cmd[i] = (struct sim_motor_cmd){
			.torque_enable = true, .torque_limit = 1023, .cw_margin = 1, .ccw_margin = 1,
			.cw_slope = 32, .ccw_slope = 32, .punch = 32, .cw_limit = 0, .ccw_limit = 1023,
		};
		/* effective lateral mass of the joint: I / lever² */
		struct sim_body b = {.motor = &motors[i], .lever = 0.1865, .neutral = 0.25 * (double)i,
		                     .half_width = 0.02, .effective_mass = mp.inertia / (0.1865 * 0.1865),
		                     .robot = (int)i};
		sim_world_add_body(&w, &b);
	}
	/* each wants 0.7 rad (13 cm) towards the other across a 21 cm gap */
	cmd[0].goal_position = (uint16_t)(512 + 0.7 / DXL_POS_RAD_PER_UNIT);
	cmd[1].goal_position = (uint16_t)(512 - 0.7 / DXL_POS_RAD_PER_UNIT);
	cmd[1].torque_limit = 600;   /* the weaker one gives way until torques balance */
	double max_speed_late = 0, load_min[2] = {1, 1}, load_max[2] = {-1, -1};
	for (int k = 0; k < 5000; k++) {
		sim_motor_step(&motors[0], &mp, &cmd[0], 0, 0.001);
		sim_motor_step(&motors[1], &mp, &cmd[1], 0, 0.001);
		sim_world_resolve(&w, 0.001, NULL, 0);
		assert_ordered(&w);
		assert_true(isfinite(motors[0].angle) && isfinite(motors[1].angle));
		if (k >= 3000) {
			for (size_t i = 0; i < 2; i++) {
				double load = sim_motor_load_fraction(&motors[i], &mp);
				load_min[i] = fmin(load_min[i], load);
				load_max[i] = fmax(load_max[i], load);
				max_speed_late = fmax(max_speed_late, fabs(motors[i].speed));
			}
		}
	}
	printf("# push: loads %.3f..%.3f and %.3f..%.3f, late |w| <= %.4f rad/s, %llu contacts\n",
	       load_min[0], load_max[0], load_min[1], load_max[1], max_speed_late, w.total_collisions);
	/* they press: the stronger at the weaker's limit, both near 600/1023; the
	 * stronger hunts by one unit of its position reading (1/32 of full torque
	 * at slope 32), as a loaded servo does */
	double lim = 600.0 / 1023;
	assert_true(load_min[0] > lim - 0.04 && load_max[0] < lim + 0.04);
	assert_true(load_max[1] < -0.95 * lim && load_min[1] > -1.02 * lim);
	/* steady: a resting contact, no bouncing (r = 0.67 bounces would show as
	 * tenths of rad/s in the joints' present speed); at most the hunting, a
	 * speed unit or so */
	assert_true(max_speed_late < 0.03);
	/* the contact's torque on each joint balances its motor's */
	assert_true(fabs(motors[0].ext_torque + motors[0].motor_torque) < 0.02 * motors[0].motor_torque);
	assert_true(fabs(motors[1].ext_torque + motors[1].motor_torque) < 0.02 * motors[0].motor_torque);
	double gap = (sim_world_lateral(&w, 1) - 0.02) - (sim_world_lateral(&w, 0) + 0.02);
	assert_true(gap >= -TOL && gap < 1e-4);
	/* contact force ≈ torque / lever: the reported impulses add up to it */
	double t0 = w.time, j0 = w.total_impulse;
	for (int k = 0; k < 1000; k++) {
		sim_motor_step(&motors[0], &mp, &cmd[0], 0, 0.001);
		sim_motor_step(&motors[1], &mp, &cmd[1], 0, 0.001);
		sim_world_resolve(&w, 0.001, NULL, 0);
	}
	double force = (w.total_impulse - j0) / (w.time - t0);
	/* all of the late contacts are resting; the first one was an impact */
	assert_true(w.resting_contacts >= w.total_collisions - 5);
	assert_true(w.resting_contacts < w.total_collisions);
	double expect = lim * 1.5 / 0.1865;
	printf("# push: mean contact force %.3f N (torque/lever %.3f N)\n", force, expect);
	assert_true(fabs(force - expect) < 0.02 * expect);
}

/* One joint pressing its body into a wall: it rests there, at the wall,
 * and its servo shows the torque limit as load. */
static void test_push_against_wall(void **state)
{
	(void)state;
	struct sim_motor_params mp;
	sim_motor_default_params(&mp);
	struct sim_world_params p = world_params(0.67, 0);
	p.wall_left = -1;
	p.wall_right = 0.1;
	p.wall_restitution = 0.8;
	struct sim_world w;
	sim_world_init(&w, &p);
	sim_motor_init(&motors[0], &mp, 0);
	struct sim_motor_cmd cmd = {
		.torque_enable = true, .torque_limit = 300, .cw_margin = 1, .ccw_margin = 1,
		.cw_slope = 32, .ccw_slope = 32, .punch = 32, .cw_limit = 0, .ccw_limit = 1023,
		.goal_position = 900,
	};
	struct sim_body b = {.motor = &motors[0], .lever = 0.1865, .neutral = 0, .half_width = 0.02,
	                     .effective_mass = mp.inertia / (0.1865 * 0.1865)};
	sim_world_add_body(&w, &b);
	struct sim_collision c[SIM_MAX_COLLISIONS_PER_STEP];
	int impacts = 0;
	for (int k = 0; k < 3000; k++) {
		sim_motor_step(&motors[0], &mp, &cmd, 0, 0.001);
		size_t nc = sim_world_resolve(&w, 0.001, c, SIM_MAX_COLLISIONS_PER_STEP);
		for (size_t i = 0; i < nc; i++) {
			assert_int_equal(c[i].right, -1);
			impacts += !c[i].resting;
		}
		assert_ordered(&w);
	}
	/* it hit the wall at speed once or a few times (bounces), then rests */
	assert_true(impacts >= 1 && impacts < 20);
	assert_true(fabs(sim_world_lateral(&w, 0) + 0.02 - 0.1) < 1e-9);
	assert_true(fabs(motors[0].speed) < 1e-9);
	assert_true(fabs(sim_motor_load_fraction(&motors[0], &mp) - 300.0 / 1023) < 1e-9);
	assert_true(sim_motor_overloaded(&motors[0], &mp, &cmd));
}

/* A row of joints all pushing into one wall: the whole row rests, every
 * servo shows its limit, and the wall carries the sum of their pushes. */
static void pressed_row(int dir)
{
	enum { N = 24 };
	struct sim_motor_params mp;
	sim_motor_default_params(&mp);
	struct sim_world_params p = world_params(0.67, 0);
	p.wall_left = dir > 0 ? -0.5 : -0.05;
	p.wall_right = dir > 0 ? 0.05 * N : 0.05 * N + 0.5;
	struct sim_world w;
	sim_world_init(&w, &p);
	struct sim_motor_cmd cmd[N];
	double lever = 0.1865, sum_torque = 0;
	for (size_t i = 0; i < N; i++) {
		sim_motor_init(&motors[i], &mp, 0);
		cmd[i] = (struct sim_motor_cmd){
			.torque_enable = true, .torque_limit = (uint16_t)(200 + 30 * i), .cw_margin = 1,
			.ccw_margin = 1, .cw_slope = 32, .ccw_slope = 32, .punch = 32, .cw_limit = 0,
			.ccw_limit = 1023, .goal_position = dir > 0 ? 1000 : 24,
		};
		sum_torque += cmd[i].torque_limit / 1023.0 * 1.5;
		struct sim_body b = {.motor = &motors[i], .lever = lever, .neutral = 0.05 * (double)i,
		                     .half_width = 0.02, .effective_mass = mp.inertia / (lever * lever)};
		sim_world_add_body(&w, &b);
	}
	struct sim_collision c[SIM_MAX_COLLISIONS_PER_STEP];
	double wall_impulse = 0;
	for (int k = 0; k < 3000; k++) {
		for (size_t i = 0; i < N; i++)
			sim_motor_step(&motors[i], &mp, &cmd[i], 0, 0.001);
		size_t nc = sim_world_resolve(&w, 0.001, c, SIM_MAX_COLLISIONS_PER_STEP);
		assert_ordered(&w);
		for (size_t i = 0; k >= 2000 && i < nc; i++)
			if ((dir > 0 ? c[i].right : c[i].left) == -1)
				wall_impulse += c[i].impulse;
	}
	for (size_t i = 0; i < N; i++) {
		assert_true(fabs(motors[i].speed) < 1e-9);
		assert_true(fabs(sim_motor_load_fraction(&motors[i], &mp) - dir * cmd[i].torque_limit / 1023.0) < 1e-9);
	}
	double force = wall_impulse / 1.0, expect = sum_torque / lever;
	printf("# pressed row (%s wall): wall force %.3f N, sum of pushes %.3f N, %llu unresolved\n",
	       dir > 0 ? "right" : "left", force, expect, w.unresolved_steps);
	assert_true(fabs(force - expect) < 0.02 * expect);
	assert_true(w.unresolved_steps == 0);
}

static void test_pressed_row(void **state)
{
	(void)state;
	pressed_row(1);
	pressed_row(-1);
}

/* 40 joints, sinusoidal goals, walls, mobility: the order always holds, and
 * the step is cheap. The timing is printed, not asserted. */
static void test_random_long_run(void **state)
{
	(void)state;
	enum { N = 40, STEPS = 20000 };
	struct sim_motor_params mp;
	sim_motor_default_params(&mp);
	struct sim_world_params p = world_params(0.67, 0.002);
	p.wall_left = -0.2;
	p.wall_right = 0.15 * (N - 1) + 0.2;
	p.wall_restitution = 0.67;
	struct sim_world w;
	sim_world_init(&w, &p);
	struct sim_motor_cmd cmd[N];
	double phase[N], amp[N];
	for (size_t i = 0; i < N; i++) {
		sim_motor_init(&motors[i], &mp, 0);
		cmd[i] = (struct sim_motor_cmd){
			.torque_enable = true, .torque_limit = 1023, .cw_margin = 1, .ccw_margin = 1,
			.cw_slope = 32, .ccw_slope = 32, .punch = 32, .cw_limit = 0, .ccw_limit = 1023,
			.goal_position = 512,
		};
		phase[i] = rnd_range(0, 2 * M_PI);
		amp[i] = rnd_range(0.3, 1.0);
		struct sim_body b = {.motor = &motors[i], .lever = 0.1865, .neutral = 0.15 * (double)i,
		                     .half_width = 0.01, .effective_mass = 0.13, .robot = (int)i};
		assert_int_equal(sim_world_add_body(&w, &b), (int)i);
	}
	struct sim_collision c[SIM_MAX_COLLISIONS_PER_STEP];
	struct timespec a, b;
	double busy = 0;
	for (int k = 0; k < STEPS; k++) {
		double t = k * 0.001;
		if (k % 10 == 0)   /* goals at 100 Hz, as the daemon writes them */
			for (size_t i = 0; i < N; i++)
				cmd[i].goal_position = dxl_rad_to_pos(amp[i] * sin(2 * M_PI * 0.8 * t + phase[i]));
		clock_gettime(CLOCK_MONOTONIC, &a);
		for (size_t i = 0; i < N; i++)
			sim_motor_step(&motors[i], &mp, &cmd[i], 0, 0.001);
		sim_world_resolve(&w, 0.001, c, SIM_MAX_COLLISIONS_PER_STEP);
		clock_gettime(CLOCK_MONOTONIC, &b);
		busy += (double)(b.tv_sec - a.tv_sec) + 1e-9 * (double)(b.tv_nsec - a.tv_nsec);
		assert_ordered(&w);
	}
	printf("# 40 joints + world: %.2f us per 1 ms step (%.2f %% of real time), %llu contacts, "
	       "%llu unresolved\n", busy / STEPS * 1e6, busy / (STEPS * 0.001) * 100,
	       w.total_collisions, w.unresolved_steps);
	assert_true(w.total_collisions > 100);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_collision_law),
		cmocka_unit_test(test_no_collision_when_separating_or_apart),
		cmocka_unit_test(test_mobility_moves_neutrals),
		cmocka_unit_test(test_mobility_per_body),
		cmocka_unit_test(test_walls),
		cmocka_unit_test(test_no_tunnelling),
		cmocka_unit_test(test_chains),
		cmocka_unit_test(test_report_capacity),
		cmocka_unit_test(test_persistent_push),
		cmocka_unit_test(test_push_against_wall),
		cmocka_unit_test(test_pressed_row),
		cmocka_unit_test(test_random_long_run),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
