/* test_sim_plane.c — the plane world (sim-bridge/plane.c on Chipmunk2D)
 * against what mechanics says, not against itself:
 *  - a straight robot moving broadside into a wall leaves at r times its
 *    speed (r = 0.67 and 0.3), the wall's impulse = m_total (1 + r) v;
 *  - a joint pressing its link's tip on a wall, the other link held between
 *    two walls, presses with torque / lever, steadily (no chatter);
 *  - without drag, a robot's joints moving it about leave its momentum at 0
 *    and its centre of mass where it was;
 *  - drag alone: a link sliding along its axis slows as exp(-c_t L t / m),
 *    across it as exp(-c_n L t / m), a spinning one as exp(-c_n L^3 t / 12 I);
 *  - a three-link robot whose joints swing with a phase lag swims (Purcell):
 *    it moves along its axis, and the other way when the lag is reversed;
 *  - the same run twice is the same to the last bit; overlapping robots and
 *    bad parameters are refused with the parameter's name. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../../sim-bridge/plane.h"

#define L 0.1865
#define MASS 0.12
#define WIDTH 0.03

static struct plane_params params(double r, double ct, double cn)
{
	return (struct plane_params){ .link_length = L, .link_width = WIDTH, .link_mass = MASS, .restitution = r,
				      .wall_restitution = r, .friction = 0.0, .drag_tangent = ct, .drag_normal = cn,
				      .substeps = 2 };
}

static struct plane_drive drives[PLANE_MAX_ROBOTS * PLANE_MAX_JOINTS];
static struct plane_joint joints[PLANE_MAX_ROBOTS * PLANE_MAX_JOINTS];

/* no drive, joints free: the zero line */
/* The piston (a wall along x from -1 to 1 m, at Y) pushes for 40 steps of
 * DT at V m/s, then falls BACK m out of the way for one step more. */
static void push_and_drop(struct plane *pl, int piston, double y, double v, double back, double dt)
{
	for (int k = 0; k < 40; k++) {
		y += v * dt;
		plane_move_wall(pl, piston, -1, y, 1, y, dt);
		plane_step(pl, dt, drives, joints);
	}
	plane_move_wall(pl, piston, -1, y - back, 1, y - back, dt);
	plane_step(pl, dt, drives, joints);
}

static void free_joints(void)
{
	memset(drives, 0, sizeof drives);
}

/* A robot gets its speed for the analytic cases from a wall that moves
 * into it (a piston) and then steps back: the plane world has no call that
 * sets a speed, as a real one has none. */

static void test_wall_restitution(void **state)
{
	(void)state;
	const double rs[] = { 0.67, 0.3 };
	for (size_t i = 0; i < 2; i++) {
		char err[160];
		struct plane_params p = params(rs[i], 0, 0);
		struct plane *pl = plane_new(&p, err, sizeof err);
		assert_non_null(pl);
		double zero[2] = { 0, 0 };
		/* a straight robot along x at y = 0; a piston wall below it pushes it
		 * up to 0.5 m/s, then stops; a wall above at y = 0.2 */
		assert_int_equal(plane_add_robot(pl, 0, 0, 0, 2, zero, NULL, err, sizeof err), 0);
		int piston = plane_add_wall(pl, -1, -0.03, 1, -0.03, err, sizeof err);
		int top = plane_add_wall(pl, -1, 0.2, 1, 0.2, err, sizeof err);
		assert_true(piston >= 0 && top >= 0);
		free_joints();
		double dt = 0.001, v = 0.5;
		push_and_drop(pl, piston, -0.03, v, 0.1, dt);
		double x0, y0, vx, vy;
		plane_robot_centre(pl, 0, &x0, &y0, &vx, &vy);
		/* the piston's own impact launched it at (1 + r) x 0.5 m/s */
		double vin = vy;
		assert_true(fabs(vin - (1 + rs[i]) * 0.5) < 0.03 * vin);
		double impulse = 0;
		int impacts = 0;
		/* fly up into the top wall and back */
		for (int k = 0; k < 400 && vy > 0; k++) {
			plane_step(pl, dt, drives, joints);
			struct plane_contact c[8];
			size_t n = plane_contacts(pl, c, 8);
			for (size_t m = 0; m < n && m < 8; m++)
				if (c[m].robot_b == PLANE_WALL && c[m].link_b == top) {
					impulse += c[m].normal_impulse;
					impacts += c[m].impact;
				}
			plane_robot_centre(pl, 0, &x0, &y0, &vx, &vy);
		}
		for (int k = 0; k < 5; k++)
			plane_step(pl, dt, drives, joints);
		plane_robot_centre(pl, 0, &x0, &y0, &vx, &vy);
		print_message("# r = %.2f: in at %.4f m/s, out at %.4f m/s (r v = %.4f); wall impulse %.5f N s "
			      "(m (1 + r) v = %.5f), %d impacts\n", rs[i], vin, -vy, rs[i] * vin, impulse,
			      3 * MASS * (1 + rs[i]) * vin, impacts);
		assert_true(fabs(-vy - rs[i] * vin) < 0.02 * vin);
		assert_true(fabs(impulse - 3 * MASS * (1 + rs[i]) * vin) < 0.03 * 3 * MASS * vin);
		assert_true(impacts >= 1);
		assert_true(fabs(vx) < 1e-6);
		plane_free(pl);
	}
}

static void test_press_balances(void **state)
{
	(void)state;
	char err[160];
	struct plane_params p = params(0.0, 0, 0);
	p.friction = 0.0;
	struct plane *pl = plane_new(&p, err, sizeof err);
	assert_non_null(pl);
	/* a two-link robot, head link along +x from the joint at the origin to
	 * (L, 0): head is link 0, pointing +x, centre at (L/2, 0); the tail, link
	 * 1, at +90 deg: from the joint down... the joint angle is link 1 relative
	 * to link 0, so the tail points along -x rotated by the angle. */
	double angle[1] = { 0.5 };
	int r = plane_add_robot(pl, 0, 0, 0, 1, angle, NULL, err, sizeof err);
	assert_int_equal(r, 0);
	struct plane_link_pose head, tail;
	plane_link(pl, 0, 0, &head);
	plane_link(pl, 0, 1, &tail);
	/* the head between two walls along it, touching, short of its ends (the
	 * tail turns about the head's rear end) */
	double hw = 0.5 * WIDTH + PLANE_WALL_RADIUS;
	double ux = cos(head.angle), uy = sin(head.angle), nx = -uy, ny = ux;
	for (int s = -1; s <= 1; s += 2)
		assert_true(plane_add_wall(pl, head.x - 0.35 * L * ux + s * hw * nx, head.y - 0.35 * L * uy + s * hw * ny,
					   head.x + 0.35 * L * ux + s * hw * nx, head.y + 0.35 * L * uy + s * hw * ny, err,
					   sizeof err) >= 0);
	/* and a stop at its front end: the post's push has a part along the head */
	double fx = head.x + (0.5 * L + 0.5 * WIDTH + PLANE_WALL_RADIUS) * ux,
	       fy = head.y + (0.5 * L + 0.5 * WIDTH + PLANE_WALL_RADIUS) * uy;
	assert_true(plane_add_wall(pl, fx - 0.03 * nx, fy - 0.03 * ny, fx + 0.03 * nx, fy + 0.03 * ny, err, sizeof err) >= 0);
	/* a post (a short wall: a disc of the wall's radius) beside the tail at
	 * 0.8 L from the joint, where the tail's side meets it once the joint
	 * has closed to 0.3 rad: closing turns the tail towards (-sin, cos) of
	 * its direction */
	double jx = head.x - 0.5 * L * ux, jy = head.y - 0.5 * L * uy;
	double stop = head.angle + 0.3, rho = 0.8 * L, side = 0.5 * WIDTH + PLANE_WALL_RADIUS;
	double px = jx - rho * cos(stop) - side * sin(stop), py = jy - rho * sin(stop) + side * cos(stop);
	int w = plane_add_wall(pl, px, py, px + 1e-4 * cos(stop), py + 1e-4 * sin(stop), err, sizeof err);
	assert_true(w >= 0);
	/* the joint closes with 0.2 N m (a = -0.2: towards smaller angles) */
	const double tau = 0.2, dt = 0.001;
	free_joints();
	drives[0] = (struct plane_drive){ .a = -tau, .c = 0, .cap = 1.0, .viscous = 0.002 };
	double sum = 0, sum2 = 0;
	int n = 0;
	for (int k = 0; k < 1500; k++) {
		plane_step(pl, dt, drives, joints);
		if (k < 1000)
			continue;
		struct plane_contact c[8];
		size_t m = plane_contacts(pl, c, 8);
		double f = 0;
		for (size_t i = 0; i < m && i < 8; i++)
			if (c[i].robot_b == PLANE_WALL && c[i].link_b == w)
				f += c[i].normal_impulse / dt;
		sum += f;
		sum2 += f * f;
		n++;
	}
	double mean = sum / n, sd = sqrt(fmax(0, sum2 / n - mean * mean));
	/* the post touches the tail's side at rho from the joint */
	double lever = rho;
	print_message("# pressing: %.4f N (torque / lever = %.4f N), sd %.5f N over 0.5 s; joint at %.4f rad\n", mean,
		      tau / lever, sd, joints[0].angle);
	assert_true(fabs(mean - tau / lever) < 0.03 * tau / lever);
	assert_true(sd < 0.01 * mean);
	assert_true(fabs(joints[0].angle - 0.3) < 0.01);
	plane_free(pl);
}

/* joints driven about inside a robot without drag: momentum stays 0 */
static void test_momentum_without_drag(void **state)
{
	(void)state;
	char err[160];
	struct plane_params p = params(0.67, 0, 0);
	struct plane *pl = plane_new(&p, err, sizeof err);
	double a[2] = { 0.2, -0.3 };
	assert_int_equal(plane_add_robot(pl, 0.1, -0.2, 0.7, 2, a, (double[]){ 3e-3, 3e-3 }, err, sizeof err), 0);
	double x0, y0, vx, vy;
	plane_robot_centre(pl, 0, &x0, &y0, &vx, &vy);
	free_joints();
	double dt = 0.001, pmax = 0;
	for (int k = 0; k < 3000; k++) {
		double t = k * dt;
		drives[0] = (struct plane_drive){ .a = 0.3 * sin(2 * M_PI * 0.8 * t), .cap = 1.5 };
		drives[1] = (struct plane_drive){ .a = 0.3 * sin(2 * M_PI * 0.8 * t - 2.1), .cap = 1.5 };
		plane_step(pl, dt, drives, joints);
		double px, py;
		plane_momentum(pl, &px, &py);
		pmax = fmax(pmax, fmax(fabs(px), fabs(py)));
	}
	double x1, y1;
	plane_robot_centre(pl, 0, &x1, &y1, &vx, &vy);
	print_message("# no drag: |momentum| <= %.2e kg m/s over 3 s, centre moved %.2e m; joints swung to %.3f, %.3f rad\n",
		      pmax, hypot(x1 - x0, y1 - y0), joints[0].angle, joints[1].angle);
	assert_true(pmax < 1e-9);
	assert_true(hypot(x1 - x0, y1 - y0) < 1e-6);
	assert_true(fabs(joints[0].angle - 0.2) > 0.05);   /* something did move */
	plane_free(pl);
}

/* drag alone on a robot given a speed by a piston: the exponential law */
static void test_drag_decay(void **state)
{
	(void)state;
	const double ct = 0.5, cn = 1.0;
	for (int across = 0; across < 2; across++) {
		char err[160];
		struct plane_params p = params(0.0, ct, cn);
		struct plane *pl = plane_new(&p, err, sizeof err);
		double zero[2] = { 0, 0 };
		/* along: the robot points along y and the piston pushes along y; across: along x */
		plane_add_robot(pl, 0, 0, across ? 0 : M_PI / 2, 2, zero, NULL, err, sizeof err);
		double y = across ? -0.03 : -1.5 * L - 0.03;
		int piston = plane_add_wall(pl, -1, y, 1, y, err, sizeof err);
		free_joints();
		double dt = 0.001;
		push_and_drop(pl, piston, y, 0.4, 0.2, dt);
		double x0, y0, vx, v0;
		plane_robot_centre(pl, 0, &x0, &y0, &vx, &v0);
		for (int k = 0; k < 500; k++)
			plane_step(pl, dt, drives, joints);
		double v1;
		plane_robot_centre(pl, 0, &x0, &y0, &vx, &v1);
		double c = across ? cn : ct, want = v0 * exp(-c * L * 0.5 / MASS);
		print_message("# drag %s: %.4f -> %.4f m/s in 0.5 s, exp(-c L t / m) gives %.4f\n",
			      across ? "across" : "along", v0, v1, want);
		assert_true(fabs(v1 - want) < 0.01 * v0);
		plane_free(pl);
	}
}

/* a three-link robot swims: joints at 0.8 Hz, +-0.8 rad, lagging by 2 pi / 3 */
static double swim(double lag, int periods)
{
	char err[160];
	struct plane_params p = params(0.67, 1.0, 2.0);
	struct plane *pl = plane_new(&p, err, sizeof err);
	double zero[2] = { 0, 0 };
	plane_add_robot(pl, 0, 0, 0, 2, zero, (double[]){ 3e-3, 3e-3 }, err, sizeof err);
	free_joints();
	double dt = 0.001, f = 0.8, A = 0.8, k = 3.0, d = 0.1;
	double x0, y0, vx, vy;
	plane_robot_centre(pl, 0, &x0, &y0, &vx, &vy);
	int steps = (int)(periods / f / dt);
	for (int s = 0; s < steps; s++) {
		double t = s * dt;
		for (int j = 0; j < 2; j++) {
			double q = A * sin(2 * M_PI * f * t - j * lag), w = 2 * M_PI * f * A * cos(2 * M_PI * f * t - j * lag);
			double now = s == 0 ? 0 : joints[j].angle;
			/* a stiff PD controller as a drive line: a - c w */
			drives[j] = (struct plane_drive){ .a = k * (q - now) + d * w, .c = d, .cap = 1.5 };
		}
		plane_step(pl, dt, drives, joints);
	}
	double x1, y1;
	plane_robot_centre(pl, 0, &x1, &y1, &vx, &vy);
	plane_free(pl);
	/* along the robot's axis (heading 0: +x, the head's direction) */
	return x1 - x0;
}

static void test_purcell_swims(void **state)
{
	(void)state;
	double fwd = swim(2 * M_PI / 3, 8), back = swim(-2 * M_PI / 3, 8);
	print_message("# swimmer: %+.4f m in 8 periods with a lag of +2pi/3, %+.4f m with -2pi/3 (%.3f body lengths "
		      "a period)\n", fwd, back, fabs(fwd) / 8 / (3 * L));
	/* the start-up differs with the lag's sign (joint 2 starts at -A sin(lag)), so
	 * the two runs are not exact mirrors: the direction is the physics */
	assert_true(fabs(fwd) > 0.02 && fabs(back) > 0.02);
	assert_true(fwd * back < 0);
}

static void test_deterministic_and_refusals(void **state)
{
	(void)state;
	assert_true(swim(2.0, 2) == swim(2.0, 2));
	char err[160];
	struct plane_params p = params(0.67, 1, 2);
	struct plane *pl = plane_new(&p, err, sizeof err);
	double zero[2] = { 0, 0 };
	plane_add_robot(pl, 0, 0, M_PI / 2, 2, zero, NULL, err, sizeof err);
	plane_add_robot(pl, 0.02, 0.05, M_PI / 2, 2, zero, NULL, err, sizeof err);
	int ra, la, rb, lb;
	assert_true(plane_overlap(pl, &ra, &la, &rb, &lb));
	assert_true(ra == 0 && la == 0 && rb == 1 && lb == 0);
	plane_free(pl);
	pl = plane_new(&p, err, sizeof err);
	plane_add_robot(pl, 0, 0, M_PI / 2, 2, zero, NULL, err, sizeof err);
	plane_add_robot(pl, 0.2, 0, M_PI / 2, 2, zero, NULL, err, sizeof err);
	assert_false(plane_overlap(pl, &ra, &la, &rb, &lb));
	plane_free(pl);
	p.link_length = NAN;
	assert_null(plane_new(&p, err, sizeof err));
	assert_string_equal(err, "world.link_length = nan: must be positive and at most 10");
	p = params(1.2, 1, 2);
	assert_null(plane_new(&p, err, sizeof err));
	assert_string_equal(err, "world.restitution = 1.2: must be finite and >= 0 and at most 1");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_wall_restitution),
		cmocka_unit_test(test_press_balances),
		cmocka_unit_test(test_momentum_without_drag),
		cmocka_unit_test(test_drag_decay),
		cmocka_unit_test(test_purcell_swims),
		cmocka_unit_test(test_deterministic_and_refusals),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
