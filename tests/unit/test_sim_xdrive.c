/*
 * test_sim_xdrive.c — an X-series servo's controllers on the simulator's
 * motor and contact world (sim-bridge/xdrive.c through sim_step()): each
 * Operating Mode does what the e-manual says with its goal registers and
 * limits — position (a step and a profile, Moving Status), velocity, PWM,
 * current and current-based position (XM430) — and the physics shows it: the
 * datasheet's no-load speed at full PWM, Goal Current's torque on a joint
 * pressed against a wall, the load a push shows, the overload shutdown, the
 * bus watchdog's stop, Drive Mode's reverse. Bands are wide enough for the
 * model's choices (PHYSICS.md §5) and narrow enough to catch a wrong unit.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "dxl2.h"
#include "dxl2_table.h"
#include "../../sim-bridge/sim.h"

static struct sim sim;
static struct sim_config cfg;

/* One robot with one servo of this model; extra: more of its [robot] keys
 * and sections after it. The joint starts centred, at rest. */
static struct sim_joint *rig(const char *model, const char *extra)
{
	char text[1024], err[300];
	snprintf(text, sizeof text, "[sim]\nmodel = %s\ninitial_spread = 0\n[robot r]\nids = 1\n%s", model, extra);
	sim_config_defaults(&cfg);
	assert_int_equal(sim_config_load_text(&cfg, "rig", text, strlen(text), err, sizeof err), 0);
	assert_int_equal(sim_config_finish(&cfg, err, sizeof err), 0);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof err), 0);
	assert_int_equal(sim.buses[0].proto->number, 2);
	return &sim.buses[0].joints[0];
}

/* A WRITE as the bus would hand it over; returns the status ERR field. */
static int w(struct sim_joint *j, uint16_t addr, int32_t v, size_t size)
{
	uint8_t data[4], buf[64], out[256];
	struct dxl2_parser p;
	struct dxl2_packet pkt;
	size_t used = 0;
	dxl2_put_u32(data, (uint32_t)v);
	int n = dxl2_encode_write(buf, sizeof buf, sim_joint_id(j), addr, data, size);
	assert_true(n > 0);
	dxl2_parser_init(&p, DXL2_PARSE_INSTRUCTION);
	assert_int_equal(dxl2_parser_feed(&p, buf, (size_t)n, &used, &pkt), DXL_FRAME);
	int len = sim_xservo_handle(&j->xservo, &pkt, out, sizeof out);
	assert_true(len >= 11);
	return out[8];
}

static int32_t r(const struct sim_joint *j, uint16_t addr)
{
	int32_t v = 0;
	assert_int_equal(sim_xservo_peek(&j->xservo, addr, &v), DXL_OK);
	return v;
}

static void run_ms(int ms)
{
	for (int i = 0; i < ms; i++)
		sim_step(&sim);
}

/* Position Control Mode: a step of 652 pulses (~1 rad) is reached without
 * overshoot, within the time a drive at the datasheet's top speed allows. */
static void position_step(const char *model)
{
	struct sim_joint *j = rig(model, "contact = none\n");
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_POSITION, 2048 + 652, 4), 0);
	int t90 = -1;
	int32_t peak = 0;
	for (int t = 1; t <= 1000; t++) {
		sim_step(&sim);
		int32_t p = r(j, DXL2_X_PRESENT_POSITION) - 2048;
		peak = p > peak ? p : peak;
		if (t90 < 0 && p >= 587)
			t90 = t;
	}
	print_message("# %s: 90 %% of a 652-pulse step in %d ms, peak %d\n", model, t90, peak);
	assert_true(t90 >= 100 && t90 <= 400);
	assert_true(peak <= 652 + 20);
	assert_true(abs(r(j, DXL2_X_PRESENT_POSITION) - (2048 + 652)) <= 2);
	assert_int_equal(r(j, DXL2_X_MOVING), 0);
	assert_int_equal(r(j, DXL2_X_MOVING_STATUS) & 0x01, 0x01);   /* in position */
}

static void test_position_step_xl430(void **state)
{
	(void)state;
	position_step("xl430-w250");
}

static void test_position_step_xm430(void **state)
{
	(void)state;
	position_step("xm430-w350");
}

/* Profile Velocity and Acceleration make a trapezoid: the trajectory's speed
 * stays at Profile Velocity, Moving Status tells the profile and its end. */
static void test_profile(void **state)
{
	(void)state;
	struct sim_joint *j = rig("xl430-w250", "contact = none\n");
	assert_int_equal(w(j, DXL2_X_PROFILE_VELOCITY, 50, 4), 0);
	assert_int_equal(w(j, DXL2_X_PROFILE_ACCELERATION, 20, 4), 0);
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_POSITION, 2048 + 1000, 4), 0);
	run_ms(700);
	assert_int_equal(r(j, DXL2_X_VELOCITY_TRAJECTORY), 50);
	assert_true(abs(r(j, DXL2_X_PRESENT_VELOCITY) - 50) <= 2);
	assert_int_equal(r(j, DXL2_X_MOVING), 1);
	assert_int_equal(r(j, DXL2_X_MOVING_STATUS), 0x32);   /* trapezoidal, ongoing */
	/* 1000 pulses at 782 pulses/s with 0.16 s ramps: done after ~1.45 s */
	run_ms(900);
	assert_int_equal(r(j, DXL2_X_POSITION_TRAJECTORY), 2048 + 1000);
	assert_int_equal(r(j, DXL2_X_VELOCITY_TRAJECTORY), 0);
	run_ms(400);
	assert_int_equal(r(j, DXL2_X_MOVING_STATUS), 0x31);   /* trapezoidal, in position */
	assert_true(abs(r(j, DXL2_X_PRESENT_POSITION) - (2048 + 1000)) <= 2);
	/* a short move at the same settings never reaches the top speed */
	assert_int_equal(w(j, DXL2_X_GOAL_POSITION, 2048 + 900, 4), 0);
	sim_step(&sim);
	assert_int_equal(r(j, DXL2_X_MOVING_STATUS), 0x22);   /* triangular, ongoing */
}

/* Velocity Control Mode: the PI loop holds Goal Velocity. */
static void test_velocity_mode(void **state)
{
	(void)state;
	struct sim_joint *j = rig("xl430-w250", "contact = none\n");
	assert_int_equal(w(j, DXL2_X_OPERATING_MODE, DXL2_OPMODE_VELOCITY, 1), 0);
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_VELOCITY, -50, 4), 0);
	run_ms(1500);
	assert_true(abs(r(j, DXL2_X_PRESENT_VELOCITY) + 50) <= 2);
	assert_true(r(j, DXL2_X_PRESENT_PWM) < 0);
	assert_true(j->motor.speed < -1.1 && j->motor.speed > -1.3);   /* 50 x 0.229 rpm = 1.2 rad/s */
}

/* PWM Control Mode at full PWM: the datasheet's no-load speed at 12 V, less
 * the link's friction; half the supply, half the speed. */
static void test_pwm_mode_no_load_speed(void **state)
{
	(void)state;
	static const struct { const char *model; double rpm; } m[] = { { "xl430-w250", 61 }, { "xm430-w350", 46 } };
	for (size_t i = 0; i < 2; i++) {
		struct sim_joint *j = rig(m[i].model, "contact = none\n");
		assert_int_equal(w(j, DXL2_X_OPERATING_MODE, DXL2_OPMODE_PWM, 1), 0);
		assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
		assert_int_equal(w(j, DXL2_X_GOAL_PWM, 885, 2), 0);
		run_ms(800);
		double w0 = m[i].rpm * 2 * M_PI / 60;
		print_message("# %s: %.3f rad/s at full PWM (no-load %.3f)\n", m[i].model, j->motor.speed, w0);
		assert_true(j->motor.speed > 0.97 * w0 && j->motor.speed < w0);
		assert_int_equal(r(j, DXL2_X_PRESENT_PWM), 885);
		/* Goal PWM above PWM Limit is refused; a lower limit caps the goal */
		assert_int_equal(w(j, DXL2_X_GOAL_PWM, -442, 2), 0);
		run_ms(800);
		assert_true(j->motor.speed < -0.47 * w0 && j->motor.speed > -0.5 * w0);
	}
}

/* XM430 Current Control Mode, the joint pressed against a wall: the torque
 * is Goal Current times the torque constant (4.1 N·m / 2.3 A at 12 V), and
 * Present Current reads it. */
static void test_current_mode(void **state)
{
	(void)state;
	struct sim_joint *j = rig("xm430-w350", "contact = 1\n[world]\nwalls = -0.5,0.05\n");
	assert_int_equal(w(j, DXL2_X_OPERATING_MODE, DXL2_OPMODE_CURRENT, 1), 0);
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_CURRENT, 300, 2), DXL2_ERRNUM_NONE);
	run_ms(600);
	double want = 300 * 0.00269 * 4.1 / 2.3;
	assert_float_equal(j->motor.motor_torque, want, 0.01 * want);
	assert_int_equal(r(j, DXL2_X_PRESENT_CURRENT), 300);
	assert_float_equal(j->motor.angle, 0.05 / 0.1865, 0.002);   /* at the wall */
	assert_int_equal(r(j, DXL2_X_HARDWARE_ERROR_STATUS), 0);    /* below the cap: no overload */
	/* the XL430 has no current modes */
	struct sim_joint *xl = rig("xl430-w250", "contact = none\n");
	assert_int_equal(w(xl, DXL2_X_OPERATING_MODE, DXL2_OPMODE_CURRENT, 1), DXL2_ERRNUM_DATA_RANGE);
}

/* Current-based Position Control Mode: the position loop, its push limited
 * by Goal Current. */
static void test_current_based_position(void **state)
{
	(void)state;
	struct sim_joint *j = rig("xm430-w350", "contact = 1\n[world]\nwalls = -0.5,0.05\n");
	assert_int_equal(w(j, DXL2_X_OPERATING_MODE, DXL2_OPMODE_CURRENT_POSITION, 1), 0);
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_CURRENT, 200, 2), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_POSITION, 2048 + 652, 4), 0);
	run_ms(1000);
	assert_int_equal(r(j, DXL2_X_PRESENT_CURRENT), 200);
	assert_float_equal(j->motor.motor_torque, 200 * 0.00269 * 4.1 / 2.3, 0.01);
	assert_int_equal(sim_joint_torque(j), true);   /* a limited push: no overload */
	/* the goal within reach: it gets there */
	assert_int_equal(w(j, DXL2_X_GOAL_POSITION, 2048 + 100, 4), 0);
	run_ms(1000);
	assert_true(abs(r(j, DXL2_X_PRESENT_POSITION) - (2048 + 100)) <= 3);
}

/* A push against a wall in Position Control Mode: the load shows it, and at
 * full output for overload_time (0.5 s) the overload error shuts the servo
 * down (in the factory Shutdown, 52) with the alert bit until REBOOT. */
static void test_push_load_overload(void **state)
{
	(void)state;
	struct sim_joint *j = rig("xl430-w250", "contact = 1\n[world]\nwalls = -0.5,0.05\n");
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_POSITION, 2048 + 652, 4), 0);
	run_ms(300);
	print_message("# pressed: load %d (0.1 %%), PWM %d\n", r(j, DXL2_X_PRESENT_LOAD), r(j, DXL2_X_PRESENT_PWM));
	assert_true(r(j, DXL2_X_PRESENT_LOAD) >= 950);
	assert_int_equal(r(j, DXL2_X_PRESENT_PWM), 885);
	assert_int_equal(r(j, DXL2_X_HARDWARE_ERROR_STATUS), 0);
	run_ms(400);
	assert_int_equal(r(j, DXL2_X_HARDWARE_ERROR_STATUS), DXL2_HWERR_OVERLOAD);
	assert_int_equal(r(j, DXL2_X_TORQUE_ENABLE), 0);
	assert_int_equal(r(j, DXL2_X_PRESENT_LOAD), 0);
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), DXL2_ERR_ALERT | DXL2_ERRNUM_RESULT_FAIL);
	/* a lower PWM limit is a softer push: no overload */
	j = rig("xl430-w250", "contact = 1\n[world]\nwalls = -0.5,0.05\n");
	assert_int_equal(w(j, DXL2_X_PWM_LIMIT, 300, 2), 0);
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_POSITION, 2048 + 652, 4), 0);
	run_ms(1000);
	assert_int_equal(r(j, DXL2_X_PRESENT_PWM), 300);
	assert_true(abs(r(j, DXL2_X_PRESENT_LOAD) - 339) <= 5);   /* 300 / 885 of stall */
	assert_int_equal(r(j, DXL2_X_HARDWARE_ERROR_STATUS), 0);
}

/* The bus watchdog's stop reaches the motor: a turning wheel stops. */
static void test_watchdog_stops(void **state)
{
	(void)state;
	struct sim_joint *j = rig("xl430-w250", "contact = none\n");
	assert_int_equal(w(j, DXL2_X_OPERATING_MODE, DXL2_OPMODE_VELOCITY, 1), 0);
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_GOAL_VELOCITY, 100, 4), 0);
	assert_int_equal(w(j, DXL2_X_BUS_WATCHDOG, 5, 1), 0);   /* 100 ms */
	for (int i = 0; i < 10; i++) {
		run_ms(50);
		assert_int_equal(w(j, DXL2_X_LED, i & 1, 1), 0);   /* a controller that keeps talking */
	}
	assert_true(j->motor.speed > 1.5);
	run_ms(400);
	assert_int_equal(r(j, DXL2_X_BUS_WATCHDOG), SIM_XSERVO_WATCHDOG_ERROR);
	assert_true(fabs(j->motor.speed) < 0.05);
	assert_int_equal(sim_joint_torque(j), true);   /* stopped, not limp */
}

/* Torque off: no drive, the joint back-drives its gearbox; Drive Mode's
 * reverse bit turns the goal the other way. */
static void test_torque_off_and_reverse(void **state)
{
	(void)state;
	struct sim_joint *j = rig("xm430-w350", "contact = none\n");
	assert_int_equal(w(j, DXL2_X_GOAL_POSITION, 2048 + 652, 4), 0);
	run_ms(300);
	assert_true(fabs(j->motor.angle) < 1e-9);
	assert_int_equal(w(j, DXL2_X_DRIVE_MODE, 1, 1), 0);
	assert_int_equal(w(j, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	run_ms(1000);
	assert_true(abs(r(j, DXL2_X_PRESENT_POSITION) - (2048 + 652)) <= 2);
	assert_float_equal(j->motor.angle, -652 * 2 * M_PI / 4096, 0.005);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_position_step_xl430),
		cmocka_unit_test(test_position_step_xm430),
		cmocka_unit_test(test_profile),
		cmocka_unit_test(test_velocity_mode),
		cmocka_unit_test(test_pwm_mode_no_load_speed),
		cmocka_unit_test(test_current_mode),
		cmocka_unit_test(test_current_based_position),
		cmocka_unit_test(test_push_load_overload),
		cmocka_unit_test(test_watchdog_stops),
		cmocka_unit_test(test_torque_off_and_reverse),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
