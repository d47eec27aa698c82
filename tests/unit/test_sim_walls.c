/*
 * test_sim_walls.c — walls that move over a span of simulated time
 * ("walls LEFT RIGHT over S"): where they stand at every physics step,
 * what stops or replaces a motion, the commands refused, and a row of
 * held joints on mobile bases squeezed between closing walls (the paper's
 * arena in one dimension). And the kick ("kick BUS ID DW"): a tap on a
 * link, its speed changed at once by DW, the commands it refuses.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>
#include <math.h>

#include "dxl_table.h"
#include "../../sim-bridge/sim.h"

/* cmocka's assert_double_equal compares floats (7 digits); these are doubles */
#define assert_double_equal(a, b, eps)                                                    \
	do {                                                                              \
		double a_ = (a), b_ = (b);                                                \
		if (!(fabs(a_ - b_) <= (eps)))                                            \
			fail_msg("%s = %.12g, expected %.12g", #a, a_, b_);                \
	} while (0)

static struct sim_config cfg;
static struct sim sim;
static char reply[512];

/* n two-servo robots, contact on servo 2, neighbours spacing m apart. */
static void row(size_t n, double spacing, double beta, const char *walls)
{
	char err[256], name[8], link[40], set[64];
	sim_config_defaults(&cfg);
	for (size_t i = 0; i < n; i++) {
		snprintf(name, sizeof name, "r%zu", i + 1);
		snprintf(link, sizeof link, "/tmp/none/%s", name);
		assert_int_equal(sim_config_add_robot(&cfg, name, link, "1,2", err, sizeof err), 0);
	}
	snprintf(set, sizeof set, "world.spacing=%g", spacing);
	assert_int_equal(sim_config_set(&cfg, set, err, sizeof err), 0);
	snprintf(set, sizeof set, "world.beta=%g", beta);
	assert_int_equal(sim_config_set(&cfg, set, err, sizeof err), 0);
	snprintf(set, sizeof set, "world.walls=%s", walls);
	assert_int_equal(sim_config_set(&cfg, set, err, sizeof err), 0);
	assert_int_equal(sim_config_set(&cfg, "sim.initial_spread=0", err, sizeof err), 0);
	assert_int_equal(sim_config_set(&cfg, "sim.overload_time=1000", err, sizeof err), 0);  /* no shutdown */
	assert_int_equal(sim_config_finish(&cfg, err, sizeof err), 0);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof err), 0);
}

static void steps_to(double t)
{
	while ((double)sim.steps * sim.dt < t - 1e-9)
		sim_step(&sim);
}

static int cmd(const char *line) { return sim_command(&sim, line, 0, reply, sizeof reply); }

/* The paper's arena: 2.0 m closing to 0.3 m between 10 s and 100 s. The
 * walls stand still before, move on a straight line (the same distance every
 * step), and stop exactly at the target. */
static void test_walls_close_over_span(void **state)
{
	(void)state;
	row(2, 0.5, 0, "-1,1");
	steps_to(10.0);
	assert_int_equal(cmd("walls -0.15 0.15 over 90"), 0);
	assert_non_null(strstr(reply, "ok walls -1 1 -> -0.15 0.15 over 90 s"));
	assert_double_equal(sim.world.params.wall_left, -1.0, 1e-12);  /* not before the next step */
	double last = sim.world.params.wall_left, step = 0.85 / 90.0 * sim.dt;
	for (int i = 0; i < 45000; i++) {
		sim_step(&sim);
		assert_double_equal(sim.world.params.wall_left - last, step, 1e-9);
		assert_double_equal(sim.world.params.wall_right, -sim.world.params.wall_left, 1e-12);
		last = sim.world.params.wall_left;
	}
	/* halfway in time, halfway in distance */
	assert_double_equal(sim.world.params.wall_left, -0.575, 1e-9);
	steps_to(100.0);
	assert_double_equal(sim.world.params.wall_left, -0.15, 1e-12);
	assert_double_equal(sim.world.params.wall_right, 0.15, 1e-12);
	assert_false(sim.wall_motion.active);
	steps_to(110.0);
	assert_double_equal(sim.world.params.wall_left, -0.15, 1e-12);
}

/* A new placement or "walls none" ends a motion; a motion asked for in the
 * middle of another starts from where the walls are. */
static void test_motion_replaced_or_stopped(void **state)
{
	(void)state;
	row(2, 0.5, 0, "-1,1");
	assert_int_equal(cmd("walls -0.5 0.5 over 10"), 0);
	steps_to(5.0);
	assert_double_equal(sim.world.params.wall_left, -0.75, 1e-9);
	assert_int_equal(cmd("walls -2 3"), 0);
	steps_to(6.0);
	assert_double_equal(sim.world.params.wall_left, -2.0, 1e-12);
	assert_double_equal(sim.world.params.wall_right, 3.0, 1e-12);
	assert_int_equal(cmd("walls -1 1 over 2"), 0);
	steps_to(7.0);
	assert_double_equal(sim.world.params.wall_left, -1.5, 1e-9);
	assert_double_equal(sim.world.params.wall_right, 2.0, 1e-9);
	assert_int_equal(cmd("walls none"), 0);
	steps_to(9.0);
	assert_false(sim.world.params.wall_left < sim.world.params.wall_right);
	assert_false(sim.wall_motion.active);
}

/* Every malformed motion gets a clear error, is counted and changes nothing;
 * without walls there is nothing to move. */
static void test_bad_motions_refused(void **state)
{
	(void)state;
	row(2, 0.5, 0, "none");
	assert_int_equal(cmd("walls -1 1 over 5"), -1);
	assert_non_null(strstr(reply, "no walls to move"));
	assert_int_equal(cmd("walls -1 1"), 0);
	uint64_t bad = sim.bad_commands;
	const char *bads[] = {
		"walls -1 1 over 0", "walls -1 1 over -5", "walls -1 1 over x", "walls -1 1 over 1e300",
		"walls -1 1 over nan", "walls -1 1 over inf", "walls 1 -1 over 5", "walls -1 1 over",
		"walls -1 1 under 5", "walls -1 1 over 5 6", "walls -1 1 over 5s", "walls -1 1 over 86401",
	};
	for (size_t i = 0; i < sizeof bads / sizeof bads[0]; i++) {
		if (cmd(bads[i]) != -1)
			fail_msg("'%s' accepted: %s", bads[i], reply);
		assert_memory_equal(reply, "error: ", 7);
	}
	assert_int_equal(sim.bad_commands - bad, sizeof bads / sizeof bads[0]);
	assert_false(sim.wall_motion.active);
	steps_to(1.0);
	assert_double_equal(sim.world.params.wall_left, -1.0, 1e-12);
	assert_double_equal(sim.world.params.wall_right, 1.0, 1e-12);
}

/* Hold every joint at its centre and close the walls past the row: the end
 * bodies are pushed by the walls and press back. On mobile bases (beta > 0)
 * the push moves their neutral positions inward with the walls, so the row
 * is squeezed; on immobile ones the neutrals stay and only the angles give
 * way. Either way no body ever leaves the space between the walls. */
static double squeeze(double beta)
{
	row(4, 0.2, beta, "-0.4,0.4");
	for (size_t i = 0; i < sim.nbuses; i++)
		for (size_t k = 0; k < sim.buses[i].njoints; k++) {
			struct sim_servo *sv = &sim.buses[i].joints[k].servo;
			sv->mem[DXL_AX_TORQUE_ENABLE] = 1;
			dxl_put_u16(&sv->mem[DXL_AX_GOAL_POSITION], DXL_POS_CENTER);
		}
	assert_int_equal(cmd("walls -0.1 0.1 over 20"), 0);
	for (int i = 0; i < 25000; i++) {
		sim_step(&sim);
		for (size_t b = 0; b < sim.world.nbodies; b++) {
			double x = sim_world_lateral(&sim.world, b);
			assert_true(x >= sim.world.params.wall_left - 1e-9 && x <= sim.world.params.wall_right + 1e-9);
		}
	}
	assert_double_equal(sim.world.params.wall_left, -0.1, 1e-12);
	return sim.world.bodies[0].neutral;
}

static void test_closing_walls_squeeze_a_mobile_row(void **state)
{
	(void)state;
	/* the outer neutrals start at -0.3 and 0.3 m */
	assert_double_equal(squeeze(0), -0.3, 1e-12);
	double moved = squeeze(0.05);
	assert_true(moved > -0.1 - 0.02);
	assert_true(sim.world.bodies[3].neutral < 0.1 + 0.02);
	assert_true(sim.world.resting_impulse > 0);
}

/* kick: the joint's true speed jumps by DW at once, nothing else does; the
 * joint then swings further than its unkicked twin on the other robot. */
static void test_kick(void **state)
{
	(void)state;
	row(2, 2.0, 0, "none");
	steps_to(0.5);
	struct sim_joint *a = &sim.buses[0].joints[1], *b = &sim.buses[1].joints[1];
	assert_double_equal(a->motor.speed, b->motor.speed, 1e-12);
	double v = a->motor.speed, x = a->motor.angle;
	assert_int_equal(cmd("kick r1 2 1.5"), 0);
	assert_non_null(strstr(reply, "ok r1 2 speed"));
	assert_double_equal(a->motor.speed, v + 1.5, 1e-12);
	assert_double_equal(a->motor.angle, x, 0);
	assert_double_equal(b->motor.speed, v, 0);
	steps_to(0.6);
	print_message("# kicked by 1.5 rad/s: 0.1 s later %.4f rad against its twin's %.4f\n", a->motor.angle,
	              b->motor.angle);
	assert_true(a->motor.angle - b->motor.angle > 0.02);
	sim_free(&sim);
}

static void test_bad_kicks_refused(void **state)
{
	(void)state;
	row(1, 2.0, 0, "none");
	const char *bads[] = { "kick", "kick r1 2", "kick r1 2 1 2", "kick r9 2 1", "kick r1 7 1", "kick r1 2 nan",
	                       "kick r1 2 inf", "kick r1 2 20.5", "kick r1 2 -21", "kick r1 2 1x", "kick r1 300 1" };
	unsigned long long before = sim.bad_commands;
	double v = sim.buses[0].joints[1].motor.speed;
	for (size_t i = 0; i < sizeof bads / sizeof bads[0]; i++) {
		assert_int_equal(cmd(bads[i]), -1);
		print_message("# %-16s -> %s\n", bads[i], reply);
		assert_non_null(strstr(reply, "error: "));
	}
	assert_int_equal(sim.bad_commands - before, sizeof bads / sizeof bads[0]);
	assert_double_equal(sim.buses[0].joints[1].motor.speed, v, 0);
	assert_int_equal(cmd("kick r1 2 -20"), 0);
	sim_free(&sim);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_walls_close_over_span),
		cmocka_unit_test(test_motion_replaced_or_stopped),
		cmocka_unit_test(test_bad_motions_refused),
		cmocka_unit_test(test_closing_walls_squeeze_a_mobile_row),
		cmocka_unit_test(test_kick),
		cmocka_unit_test(test_bad_kicks_refused),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
