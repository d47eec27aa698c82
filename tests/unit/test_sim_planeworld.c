/*
 * test_sim_planeworld.c — the simulator with world.kind = plane: scenarios
 * that build one (robots in a row or where their keys put them, walls,
 * ends), the bad ones refused with the key and the reason, the servos'
 * registers driving the links (a goal position is reached through the plane
 * as through the row), walls that close over simulated time move the plane's
 * walls and squeeze the robots, contacts counted as the row's collisions,
 * and the same seed stepping to the same bits.
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

static struct sim_config cfg;
static struct sim sim, sim2;
static char err[400], reply[512];

/* n two-servo robots in the plane, with extra "section.key=value" settings */
static int plane(size_t n, const char *const *sets, size_t nsets)
{
	char name[8], link[40];
	sim_config_defaults(&cfg);
	for (size_t i = 0; i < n; i++) {
		snprintf(name, sizeof name, "r%zu", i + 1);
		snprintf(link, sizeof link, "/tmp/none/%s", name);
		assert_int_equal(sim_config_add_robot(&cfg, name, link, "1,2", err, sizeof err), 0);
	}
	assert_int_equal(sim_config_set(&cfg, "world.kind=plane", err, sizeof err), 0);
	assert_int_equal(sim_config_set(&cfg, "sim.overload_time=1000", err, sizeof err), 0);
	for (size_t i = 0; i < nsets; i++)
		if (sim_config_set(&cfg, sets[i], err, sizeof err) != 0)
			return -1;
	if (sim_config_finish(&cfg, err, sizeof err) != 0)
		return -1;
	return sim_init(&sim, &cfg, err, sizeof err);
}

static void steps(struct sim *s, int n)
{
	for (int i = 0; i < n; i++)
		sim_step(s);
}

static void test_builds_a_row_of_robots(void **state)
{
	(void)state;
	const char *sets[] = { "world.spacing=0.3", "sim.initial_spread=0" };
	assert_int_equal(plane(3, sets, 2), 0);
	assert_non_null(sim.plane);
	assert_int_equal(plane_robots(sim.plane), 3);
	assert_int_equal(plane_joints(sim.plane, 1), 2);
	assert_int_equal(sim.world.nbodies, 3);
	/* centred on 0, 0.3 m apart, heads towards +y: the head link above */
	assert_true(fabs(sim.world.bodies[0].neutral + 0.3) < 1e-9 && fabs(sim.world.bodies[2].neutral - 0.3) < 1e-9);
	struct plane_link_pose head, tail;
	plane_link(sim.plane, 1, 0, &head);
	plane_link(sim.plane, 1, 2, &tail);
	assert_true(head.y > 0.18 && tail.y < -0.18 && fabs(head.x) < 1e-9);
	assert_int_equal(plane_walls(sim.plane), 0);
	sim_free(&sim);
}

static void test_bad_scenarios_refused(void **state)
{
	(void)state;
	const char *beta[] = { "world.beta=0.02" };
	assert_int_equal(plane(2, beta, 1), -1);
	assert_non_null(strstr(err, "world.beta = 0.02: beta is the row world's mobility"));
	sim_free(&sim);
	const char *tight[] = { "world.spacing=0.01", "sim.initial_spread=0.5" };
	assert_int_equal(plane(2, tight, 2), -1);
	assert_non_null(strstr(err, "world: at the start robot r1's link 1 overlaps robot r2's link 1 (robots 0.01 m apart"));
	sim_free(&sim);
	const char *short_ends[] = { "world.ends=-0.2,0.2", "sim.initial_spread=0" };
	assert_int_equal(plane(2, short_ends, 2), -1);
	assert_non_null(strstr(err, "world.ends: the channel is 0.4 m long, robot r1 0.5915 m"));
	sim_free(&sim);
	const char *nan_key[] = { "world.drag_normal=nan" };
	assert_int_equal(plane(2, nan_key, 1), -1);
	assert_non_null(strstr(err, "drag_normal: 'nan' is not a number"));
	const char *bad_kind[] = { "world.kind=cube" };
	assert_int_equal(plane(2, bad_kind, 1), -1);
	assert_non_null(strstr(err, "kind: 'cube' is not row"));
	const char *bad_pos[] = { "robot r1.position=1" };
	assert_int_equal(plane(2, bad_pos, 1), -1);
	assert_non_null(strstr(err, "position: X,Y in metres"));
	const char *width[] = { "world.link_width=0.3" };
	assert_int_equal(plane(2, width, 1), -1);
	assert_non_null(strstr(err, "link_width = 0.3 m: must be less than the link's length"));
	sim_free(&sim);
	const char *none[] = { "robot r1.contact=none" };
	assert_int_equal(plane(2, none, 1), -1);
	assert_non_null(strstr(err, "contact = none has no meaning"));
	sim_free(&sim);
}

/* Robots whose seeded bends would start them inside each other are
 * straightened (their angles halved) until they fit: a crowded scenario
 * starts, the same way for a seed, with no link inside another. */
static void test_straightened_to_fit(void **state)
{
	(void)state;
	const char *sets[] = { "world.spacing=0.1", "sim.initial_spread=0.8", "sim.seed=3" };
	if (plane(6, sets, 3) != 0)
		fail_msg("%s", err);
	int ra, la, rb, lb;
	assert_false(plane_overlap(sim.plane, &ra, &la, &rb, &lb));
	double widest = 0;
	for (size_t i = 0; i < 6; i++)
		for (size_t k = 0; k < 2; k++)
			widest = fmax(widest, fabs(sim.buses[i].joints[k].motor.angle));
	print_message("# 6 robots 0.1 m apart, seeded bends up to 0.8 rad: started with joints within %.3f rad\n", widest);
	assert_true(widest > 0);
	sim_free(&sim);
}

static int cmd(const char *line) { return sim_command(&sim, line, 0, reply, sizeof reply); }

/* The servo's own controller drives the links: torque on and a goal 0.5 rad
 * away, the joint gets there through the plane as it does on the row. */
static void test_servo_drives_the_links(void **state)
{
	(void)state;
	const char *sets[] = { "sim.initial_spread=0" };
	assert_int_equal(plane(1, sets, 1), 0);
	struct sim_joint *j = &sim.buses[0].joints[0];
	uint16_t goal = dxl_rad_to_pos(0.5);
	sim_servo_poke(&j->servo, DXL_AX_GOAL_POSITION, goal);
	sim_servo_poke(&j->servo, DXL_AX_TORQUE_ENABLE, 1);
	steps(&sim, 1000);
	print_message("# plane: joint 1 at %.4f rad after 1 s towards 0.5 rad (present %u, goal %u)\n",
		      j->motor.angle, dxl_get_u16(&j->servo.mem[DXL_AX_PRESENT_POSITION]), goal);
	assert_true(fabs(j->motor.angle - 0.5) < 0.02);
	/* the link really turned: link 1 relative to link 0 */
	struct plane_link_pose a, b;
	plane_link(sim.plane, 0, 0, &a);
	plane_link(sim.plane, 0, 1, &b);
	assert_true(fabs((b.angle - a.angle) - j->motor.angle) < 1e-9);
	sim_free(&sim);
}

/* Walls closing over simulated time squeeze the row: contacts, collisions,
 * and the robots' centres pushed inwards. */
static void test_closing_walls_squeeze(void **state)
{
	(void)state;
	const char *sets[] = { "world.spacing=0.2", "world.walls=-0.4,0.4", "world.ends=-0.32,0.32",
			       "sim.initial_spread=0.2" };
	assert_int_equal(plane(3, sets, 4), 0);
	assert_int_equal(plane_walls(sim.plane), 4);
	assert_int_equal(cmd("walls -0.12 0.12 over 2"), 0);
	/* a kick is the row's: the plane says so, and changes nothing */
	double v = sim.buses[0].joints[0].motor.speed;
	assert_int_equal(cmd("kick r1 1 1"), -1);
	assert_non_null(strstr(reply, "error: kick: the plane world takes no kick"));
	assert_true(sim.buses[0].joints[0].motor.speed == v);
	steps(&sim, 3000);
	double ax, ay, bx, by;
	plane_wall(sim.plane, 0, &ax, &ay, &bx, &by);
	print_message("# closing walls: left wall's face at x = %.4f m (asked -0.12), %llu contacts, %.4f N s, robot centres "
		      "%.3f %.3f %.3f\n", sim.wall_face[0], sim.world.total_collisions, sim.world.total_impulse,
		      sim.world.bodies[0].neutral, sim.world.bodies[1].neutral, sim.world.bodies[2].neutral);
	/* the face where asked, the segment its half thickness further out */
	assert_true(fabs(sim.wall_face[0] + 0.12) < 1e-6);
	assert_true(fabs(ax + 0.12 + PLANE_WALL_RADIUS) < 1e-6);
	assert_int_equal(sim.escaped, 0);
	assert_true(sim.world.total_collisions > 0 && sim.world.total_impulse > 0);
	assert_true(sim.world.bodies[0].neutral > -0.12 && sim.world.bodies[2].neutral < 0.12);
	struct plane_contact c[16];
	size_t n = sim_contacts_drain(&sim, c, 16);
	assert_true(n > 0);
	assert_int_equal(sim_contacts_drain(&sim, c, 16), 0);   /* drained */
	sim_free(&sim);
}

/* Walls asked to close narrower than the robots lying side by side (ten of
 * them need 0.32 m; asked: 0.2 m): they hold where the crowd pushes back
 * with more than wall_force_max, and no link is pushed through a wall. */
static void test_walls_hold_against_a_crowd(void **state)
{
	(void)state;
	const char *sets[] = { "world.spacing=0.2", "world.walls=-1,1", "world.ends=-0.33,0.33",
			       "sim.initial_spread=0.2", "world.wall_force_max=20" };
	assert_int_equal(plane(10, sets, 5), 0);
	assert_int_equal(cmd("walls -0.1 0.1 over 10"), 0);
	steps(&sim, 16000);
	double width = sim.wall_face[1] - sim.wall_face[0];
	print_message("# a crowd against closing walls: asked 0.2 m, the walls stopped %.3f m apart after %llu held "
		      "steps; %llu link-steps outside; last forces %.1f / %.1f N\n", width, sim.held_steps, sim.escaped,
		      sim.wall_force[0], sim.wall_force[1]);
	assert_true(width > 0.3);
	assert_true(sim.held_steps > 0);
	assert_int_equal(sim.escaped, 0);
	sim_free(&sim);
}

/* The same scenario and seed, stepped twice: the same bits. */
static void test_deterministic(void **state)
{
	(void)state;
	const char *sets[] = { "world.spacing=0.3", "world.walls=auto", "sim.seed=7", "sim.initial_spread=0.3" };
	if (plane(3, sets, 4) != 0)
		fail_msg("%s", err);
	sim2 = sim;   /* the plane is a pointer: build the second one for real */
	if (sim_init(&sim2, &cfg, err, sizeof err) != 0)
		fail_msg("%s", err);
	for (size_t r = 0; r < 3; r++)
		for (size_t k = 0; k < 2; k++) {
			sim_servo_poke(&sim.buses[r].joints[k].servo, DXL_AX_GOAL_POSITION, 700);
			sim_servo_poke(&sim.buses[r].joints[k].servo, DXL_AX_TORQUE_ENABLE, 1);
			sim_servo_poke(&sim2.buses[r].joints[k].servo, DXL_AX_GOAL_POSITION, 700);
			sim_servo_poke(&sim2.buses[r].joints[k].servo, DXL_AX_TORQUE_ENABLE, 1);
		}
	steps(&sim, 2000);
	steps(&sim2, 2000);
	for (int r = 0; r < 3; r++)
		for (int k = 0; k < 3; k++) {
			struct plane_link_pose a, b;
			plane_link(sim.plane, r, k, &a);
			plane_link(sim2.plane, r, k, &b);
			assert_memory_equal(&a, &b, sizeof a);
		}
	assert_true(sim.world.total_impulse == sim2.world.total_impulse);
	sim_free(&sim);
	sim_free(&sim2);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_builds_a_row_of_robots),
		cmocka_unit_test(test_bad_scenarios_refused),
		cmocka_unit_test(test_straightened_to_fit),
		cmocka_unit_test(test_servo_drives_the_links),
		cmocka_unit_test(test_closing_walls_squeeze),
		cmocka_unit_test(test_walls_hold_against_a_crowd),
		cmocka_unit_test(test_deterministic),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
