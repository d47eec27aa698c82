/*
 * test_sim_motor.c — the AX-12A joint model: compliance controller, motor
 * line, speed limit, torque limit and load, wheel mode, torque off, supply
 * voltage, heating, and step stability.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <cmocka.h>

#include "dxl_table.h"
#include "../../sim-bridge/motor.h"

#define DT 0.001

static struct sim_motor_params params(void)
{
	struct sim_motor_params p;
	sim_motor_default_params(&p);
	return p;
}

/* Factory RAM defaults of an AX-12A, torque on, goal at centre. */
static struct sim_motor_cmd cmd_default(void)
{
	struct sim_motor_cmd c = {
		.torque_enable = true, .goal_position = DXL_POS_CENTER, .moving_speed = 0,
		.torque_limit = 1023, .cw_margin = 1, .ccw_margin = 1, .cw_slope = 32,
		.ccw_slope = 32, .punch = 32, .cw_limit = 0, .ccw_limit = 1023,
	};
	return c;
}

static double units_to_rad(double units)
{
	return units * DXL_POS_RAD_PER_UNIT;
}

/* Run a goal step from `from` to `to` (raw units); returns the peak speed
 * and the time at which the joint first came within 2 units of the goal. */
static double run_step(const struct sim_motor_params *p, struct sim_motor_cmd *c,
                       int from, int to, double seconds, double *arrival, struct sim_motor *m)
{
	sim_motor_init(m, p, units_to_rad(from - DXL_POS_CENTER));
	c->goal_position = (uint16_t)to;
	double peak = 0;
	*arrival = -1;
	double goal = units_to_rad(to - DXL_POS_CENTER);
	for (int k = 0; k < (int)(seconds / DT); k++) {
		sim_motor_step(m, p, c, 0, DT);
		if (fabs(m->speed) > peak)
			peak = fabs(m->speed);
		if (*arrival < 0 && fabs(m->angle - goal) < units_to_rad(2))
			*arrival = (k + 1) * DT;
	}
	return peak;
}

static void test_step_reaches_no_load_speed(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	struct sim_motor m;
	double arrival;
	double peak = run_step(&p, &c, 212, 812, 2.0, &arrival, &m);
	double w0 = sim_motor_no_load_speed(&p);
	assert_true(fabs(w0 - 59.0 * 2 * M_PI / 60) < 1e-9);
	/* the link's own friction costs at most a few percent of the datasheet speed */
	assert_true(peak > 0.97 * w0);
	assert_true(peak <= w0);
	/* 600 units = 3.07 rad: a bit more than distance / no-load speed */
	double distance = units_to_rad(600);
	assert_true(arrival > distance / w0);
	assert_true(arrival < distance / w0 + 0.15);
	/* settles inside the compliance margin plus a unit, no overshoot blow-up */
	assert_true(fabs(m.angle - units_to_rad(812 - 512)) < units_to_rad(2));
	assert_true(fabs(m.speed) < 0.01);
}

static void test_moving_speed_limits_speed(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	struct sim_motor m;
	double arrival;
	c.moving_speed = 200;   /* 22.2 rpm */
	double wl = 200 * DXL_SPEED_RAD_S_PER_UNIT;
	double peak = run_step(&p, &c, 312, 712, 4.0, &arrival, &m);
	/* the firmware's target moves at the set speed; the joint follows it, with
	 * the position loop's small overshoot when the move starts */
	assert_true(peak <= wl * 1.10);
	assert_true(peak > wl * 0.99);
	double distance = units_to_rad(400);
	assert_true(arrival > distance / wl);
	assert_true(arrival < distance / wl + 0.05);
	/* cruising in the middle of the move: the set speed */
	sim_motor_init(&m, &p, units_to_rad(312 - 512));
	c.goal_position = 712;
	double cruise = 0;
	int n = 0;
	for (int k = 0; k < 1000; k++) {
		sim_motor_step(&m, &p, &c, 0, DT);
		if (k >= 300 && k < 700) {
			cruise += m.speed;
			n++;
		}
	}
	assert_true(fabs(cruise / n - wl) < 0.005 * wl);
	/* a joint blocked on its way still pushes with the full torque: the
	 * moving speed limits speed, not force */
	sim_motor_init(&m, &p, 0);
	c.goal_position = 712;
	for (int k = 0; k < 2000; k++) {
		sim_motor_step(&m, &p, &c, 0, DT);
		m.angle = m.speed = 0;
	}
	assert_true(fabs(sim_motor_load_fraction(&m, &p) - 1.0) < 1e-9);
	/* above the motor's own limit (≈530 at 12 V) the setting makes no
	 * difference worth measuring */
	c.moving_speed = 1000;
	double arrival_fast;
	double peak_fast = run_step(&p, &c, 312, 712, 2.0, &arrival_fast, &m);
	c.moving_speed = 0;
	double peak_max = run_step(&p, &c, 312, 712, 2.0, &arrival, &m);
	assert_true(fabs(peak_fast - peak_max) < 0.01 * peak_max);
	assert_true(fabs(arrival_fast - arrival) < 0.02);
	/* the profile starts from where the joint is when torque comes on, even
	 * if it was pushed around while limp */
	c.moving_speed = 100;
	c.torque_enable = false;
	c.goal_position = DXL_POS_CENTER;
	sim_motor_init(&m, &p, 0);
	for (int k = 0; k < 700; k++)   /* pushed for 0.5 s, then it comes to rest */
		sim_motor_step(&m, &p, &c, k < 500 ? 0.6 : 0, DT);
	assert_true(m.angle > 0.5 && m.speed == 0);
	c.torque_enable = true;
	peak = 0;
	for (int k = 0; k < 3000; k++) {
		sim_motor_step(&m, &p, &c, 0, DT);
		peak = fmax(peak, fabs(m.speed));
	}
	assert_true(peak < 1.1 * 100 * DXL_SPEED_RAD_S_PER_UNIT);
	assert_true(fabs(m.angle) < units_to_rad(2));
}

/* One step from rest: the torque the controller delivers at zero speed. */
static double torque_at_error(const struct sim_motor_params *p, const struct sim_motor_cmd *c,
                              double error_units)
{
	struct sim_motor m;
	sim_motor_init(&m, p, units_to_rad((double)c->goal_position - DXL_POS_CENTER - error_units));
	sim_motor_step(&m, p, c, 0, 1e-7);
	return m.motor_torque;
}

static void test_compliance_margin_dead_band(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	double stall = sim_motor_stall_torque(&p);
	c.cw_margin = 4;
	c.ccw_margin = 6;
	/* inside the dead band: no drive at all (the servo compares whole units of
	 * its position reading: 4.4 reads as 4) */
	assert_true(fabs(torque_at_error(&p, &c, 4)) < 1e-6);
	assert_true(fabs(torque_at_error(&p, &c, 4.4)) < 1e-6);
	assert_true(fabs(torque_at_error(&p, &c, -6)) < 1e-6);
	/* one unit outside: at least the punch, in the right direction */
	assert_true(torque_at_error(&p, &c, 5) >= 32.0 / 1023 * stall * 0.999);
	assert_true(torque_at_error(&p, &c, -7) <= -32.0 / 1023 * stall * 0.999);
	/* margin 0 still has the half unit of the reading: no punch chatter at the goal */
	c.cw_margin = c.ccw_margin = 0;
	assert_true(fabs(torque_at_error(&p, &c, 0.4)) < 1e-6);
	assert_true(torque_at_error(&p, &c, 0.6) > 0);
	c.cw_margin = 4;
	c.ccw_margin = 6;
	/* margins are per side: 5 units is inside CCW (6) but outside CW (4) */
	assert_true(fabs(torque_at_error(&p, &c, -5)) < 1e-6);
	assert_true(torque_at_error(&p, &c, 5) > 0);
	/* a joint left inside the dead band stays put */
	struct sim_motor m;
	sim_motor_init(&m, &p, units_to_rad(-3));
	for (int k = 0; k < 1000; k++)
		sim_motor_step(&m, &p, &c, 0, DT);
	assert_true(fabs(m.angle - units_to_rad(-3)) < 1e-12);
}

static void test_compliance_slope(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	double stall = sim_motor_stall_torque(&p);
	c.cw_margin = c.ccw_margin = 0;
	c.punch = 0;
	/* ramps linearly from 0 to full over 32 units, then stays at full */
	assert_true(fabs(torque_at_error(&p, &c, 8) - stall * 8 / 32) < 1e-4);
	assert_true(fabs(torque_at_error(&p, &c, 16) - stall * 16 / 32) < 1e-4);
	assert_true(fabs(torque_at_error(&p, &c, -24) + stall * 24 / 32) < 1e-4);
	assert_true(fabs(torque_at_error(&p, &c, 40) - stall) < 1e-4);
	/* the slope register works in powers of two: 40 acts as 32, 3 as 2 */
	c.ccw_slope = c.cw_slope = 40;
	assert_true(fabs(torque_at_error(&p, &c, 16) - stall * 16 / 32) < 1e-4);
	c.ccw_slope = c.cw_slope = 128;
	assert_true(fabs(torque_at_error(&p, &c, 16) - stall * 16 / 128) < 1e-4);
	c.ccw_slope = c.cw_slope = 3;
	assert_true(fabs(torque_at_error(&p, &c, 1) - stall * 1 / 2) < 1e-4);
	/* a softer slope holds with less stiffness: after a step the error is the same
	 * ramp fraction, so with an opposing torque the deflection scales with the slope */
	c = cmd_default();
	c.punch = 0;
	c.cw_margin = c.ccw_margin = 0;
	double defl[2];
	uint8_t slopes[2] = {16, 64};
	for (int s = 0; s < 2; s++) {
		struct sim_motor m;
		c.cw_slope = c.ccw_slope = slopes[s];
		sim_motor_init(&m, &p, 0);
		for (int k = 0; k < 3000; k++)
			sim_motor_step(&m, &p, &c, -0.3, DT);
		defl[s] = -m.angle / DXL_POS_RAD_PER_UNIT;
	}
	/* 0.3 N·m of 1.5 needs 20 % of the ramp: 3.2 and 12.8 units (to within
	 * the unit the servo resolves) */
	assert_true(fabs(defl[0] - 0.2 * 16) < 1.0);
	assert_true(fabs(defl[1] - 0.2 * 64) < 1.0);
	assert_true(defl[1] > 3 * defl[0]);
}

static void test_torque_limit_blocked_joint(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	double stall = sim_motor_stall_torque(&p);
	c.torque_limit = 512;
	c.goal_position = 812;
	double cap = 512.0 / 1023 * stall;
	/* a rigid block: the joint is held where it is */
	struct sim_motor m;
	sim_motor_init(&m, &p, 0);
	for (int k = 0; k < 500; k++) {
		sim_motor_step(&m, &p, &c, 0, DT);
		m.angle = 0;
		m.speed = 0;
	}
	assert_true(fabs(m.motor_torque - cap) < 1e-9);
	assert_true(fabs(sim_motor_load_fraction(&m, &p) - 512.0 / 1023) < 1e-9);
	assert_true(sim_motor_overloaded(&m, &p, &c));
	/* an external torque stronger than the limit back-drives it: the motor keeps
	 * delivering exactly the limit (no more), the load shows it */
	sim_motor_init(&m, &p, 0);
	for (int k = 0; k < 1000; k++)
		sim_motor_step(&m, &p, &c, -1.0, DT);
	assert_true(m.speed < 0);
	assert_true(fabs(m.motor_torque - cap) < 1e-9);
	assert_true(sim_motor_overloaded(&m, &p, &c));
	/* a weaker one stalls it short of the goal with torque balance */
	sim_motor_init(&m, &p, 0);
	for (int k = 0; k < 3000; k++)
		sim_motor_step(&m, &p, &c, -0.5, DT);
	assert_true(fabs(m.speed) < 1e-3);
	assert_true(fabs(m.motor_torque - 0.5) < 0.01);
	assert_false(sim_motor_overloaded(&m, &p, &c));
	/* the load carries the direction: pushing CW shows negative */
	c.goal_position = 212;
	sim_motor_init(&m, &p, 0);
	for (int k = 0; k < 100; k++) {
		sim_motor_step(&m, &p, &c, 0, DT);
		m.angle = 0;
		m.speed = 0;
	}
	assert_true(fabs(sim_motor_load_fraction(&m, &p) + 512.0 / 1023) < 1e-9);
	/* a free move is not an overload once it is under way */
	c.torque_limit = 1023;
	double arrival;
	run_step(&p, &c, 212, 812, 0.05, &arrival, &m);
	assert_false(sim_motor_overloaded(&m, &p, &c));
}

static void test_wheel_mode(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	double w0 = sim_motor_no_load_speed(&p);
	c.cw_limit = c.ccw_limit = 0;
	c.moving_speed = 512;   /* ≈50 % output, CCW */
	struct sim_motor m;
	sim_motor_init(&m, &p, 0);
	for (int k = 0; k < 1000; k++)
		sim_motor_step(&m, &p, &c, 0, DT);
	assert_true(m.speed > 0.95 * 512.0 / 1023 * w0 && m.speed < 512.0 / 1023 * w0);
	/* it turns past the joint-mode range: endless rotation */
	for (int k = 0; k < 3000; k++)
		sim_motor_step(&m, &p, &c, 0, DT);
	assert_true(m.angle > units_to_rad(600));
	/* bit 10: CW */
	c.moving_speed = 1024 + 256;
	for (int k = 0; k < 2000; k++)
		sim_motor_step(&m, &p, &c, 0, DT);
	assert_true(m.speed < -0.95 * 256.0 / 1023 * w0 && m.speed > -256.0 / 1023 * w0);
	/* speed 0 stops it */
	c.moving_speed = 0;
	for (int k = 0; k < 500; k++)
		sim_motor_step(&m, &p, &c, 0, DT);
	assert_true(fabs(m.speed) < 1e-3);
	/* the torque limit caps the output ratio */
	c.moving_speed = 1023;
	c.torque_limit = 256;
	for (int k = 0; k < 2000; k++)
		sim_motor_step(&m, &p, &c, 0, DT);
	assert_true(m.speed < 256.0 / 1023 * w0 && m.speed > 0.9 * 256.0 / 1023 * w0);
}

/* A current-controlled drive (motor.drive = current, not an AX-12A): the
 * wheel-mode register is a torque, with no back-EMF loss. */
static void test_current_drive(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	p.current_drive = true;
	p.viscous = 0;
	p.coulomb = 0;
	struct sim_motor_cmd c = cmd_default();
	c.cw_limit = c.ccw_limit = 0;
	c.moving_speed = 1024 + 102;   /* 10 % of 1.5 N·m, CW */
	struct sim_motor m;
	sim_motor_init(&m, &p, 0);
	m.speed = 3.0;                 /* no back-EMF: the speed does not change the torque */
	sim_motor_step(&m, &p, &c, 0, 1e-3);
	assert_true(fabs(m.motor_torque + 102.0 / 1023 * 1.5) < 1e-9);
	/* the acceleration is the commanded torque over the inertia */
	double w = m.speed;
	sim_motor_step(&m, &p, &c, 0, 1e-3);
	assert_true(fabs((m.speed - w) / 1e-3 + 102.0 / 1023 * 1.5 / p.inertia) < 1e-6);
	/* independent of the supply; capped by the torque limit */
	p.supply_voltage = 9.0;
	c.moving_speed = 1023;
	c.torque_limit = 512;
	sim_motor_step(&m, &p, &c, 0, 1e-3);
	assert_true(fabs(m.motor_torque - 512.0 / 1023 * 1.5) < 1e-9);
	/* joint mode is unchanged by the option */
	struct sim_motor_params q = params();
	struct sim_motor a, b;
	struct sim_motor_cmd j = cmd_default();
	sim_motor_init(&a, &q, 0);
	q.current_drive = true;
	sim_motor_init(&b, &q, 0);
	for (int k = 0; k < 200; k++) {
		q.current_drive = false;
		sim_motor_step(&a, &q, &j, 0, DT);
		q.current_drive = true;
		sim_motor_step(&b, &q, &j, 0, DT);
	}
	assert_true(a.angle == b.angle && a.speed == b.speed);
}

static void test_torque_off(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	c.torque_enable = false;
	c.goal_position = 900;
	struct sim_motor m;
	sim_motor_init(&m, &p, 0);
	for (int k = 0; k < 1000; k++)
		sim_motor_step(&m, &p, &c, 0, DT);
	/* no drive towards the goal */
	assert_true(m.angle == 0 && m.speed == 0 && m.motor_torque == 0);
	assert_true(sim_motor_load_fraction(&m, &p) == 0);
	assert_false(sim_motor_overloaded(&m, &p, &c));
	/* a push below the back-drive dry friction does not move it */
	sim_motor_step(&m, &p, &c, 0.9 * (p.coulomb + p.backdrive_coulomb), DT);
	assert_true(m.speed == 0);
	/* a steady push back-drives it against the stiff gearbox at
	 * (tau - coulomb) / viscous */
	double tau = 0.5;
	for (int k = 0; k < 2000; k++)
		sim_motor_step(&m, &p, &c, tau, DT);
	double expect = (tau - p.coulomb - p.backdrive_coulomb) / (p.viscous + p.backdrive_viscous);
	assert_true(fabs(m.speed - expect) < 1e-6 * expect);
	/* released, it stops within tens of milliseconds */
	for (int k = 0; k < 100; k++)
		sim_motor_step(&m, &p, &c, 0, DT);
	assert_true(m.speed == 0);
}

static void test_voltage_scaling(void **state)
{
	(void)state;
	double volts[3] = {7.4, 10.0, 12.0};
	for (int v = 0; v < 3; v++) {
		struct sim_motor_params p = params();
		p.supply_voltage = volts[v];
		double scale = volts[v] / 12.0;
		assert_true(fabs(sim_motor_stall_torque(&p) - 1.5 * scale) < 1e-12);
		assert_true(fabs(sim_motor_no_load_speed(&p) - 59 * 2 * M_PI / 60 * scale) < 1e-12);
		struct sim_motor_cmd c = cmd_default();
		struct sim_motor m;
		double arrival;
		double peak = run_step(&p, &c, 212, 812, 2.0, &arrival, &m);
		assert_true(peak > 0.96 * sim_motor_no_load_speed(&p));
		assert_true(peak <= sim_motor_no_load_speed(&p));
		/* blocked at full limit: the stall torque of that supply, 100 % load */
		sim_motor_init(&m, &p, 0);
		c.goal_position = 900;
		for (int k = 0; k < 10; k++) {
			sim_motor_step(&m, &p, &c, 0, DT);
			m.angle = m.speed = 0;
		}
		assert_true(fabs(m.motor_torque - 1.5 * scale) < 1e-9);
		assert_true(fabs(sim_motor_load_fraction(&m, &p) - 1.0) < 1e-9);
	}
}

static void test_heating_and_cooling(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	c.goal_position = 900;
	struct sim_motor m;
	sim_motor_init(&m, &p, 0);
	assert_true(m.temperature == p.ambient_c);
	/* held at stall: crosses the default 70 °C limit within minutes, not seconds */
	double crossed = -1;
	for (int k = 0; k < 300000 && crossed < 0; k++) {
		sim_motor_step(&m, &p, &c, 0, DT);
		m.angle = m.speed = 0;
		if (m.temperature >= 70)
			crossed = (k + 1) * DT;
	}
	printf("# stall at 12 V crosses 70 C after %.1f s\n", crossed);
	assert_true(crossed > 20 && crossed < 240);
	/* a free joint does not heat */
	struct sim_motor idle;
	sim_motor_init(&idle, &p, 0);
	c.goal_position = DXL_POS_CENTER;
	for (int k = 0; k < 60000; k++)
		sim_motor_step(&idle, &p, &c, 0, DT);
	assert_true(fabs(idle.temperature - p.ambient_c) < 1e-9);
	/* torque off: cools towards ambient, about 20 minutes to get close */
	c.torque_enable = false;
	double before = m.temperature, prev = before;
	for (int k = 0; k < 1200; k++) {
		for (int j = 0; j < 1000; j++)
			sim_motor_step(&m, &p, &c, 0, DT);
		assert_true(m.temperature < prev);
		prev = m.temperature;
	}
	assert_true(m.temperature > p.ambient_c);
	assert_true(m.temperature - p.ambient_c < 0.2 * (before - p.ambient_c));
}

/* The same step response at 1 ms and 0.1 ms, with the stiffest settings. */
static void test_stable_at_both_step_sizes(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	c.cw_slope = c.ccw_slope = 2;
	c.cw_margin = c.ccw_margin = 0;
	c.goal_position = 700;
	double dts[2] = {1e-3, 1e-4};
	double final_angle[2], peak[2];
	for (int d = 0; d < 2; d++) {
		struct sim_motor m;
		sim_motor_init(&m, &p, 0);
		peak[d] = 0;
		int steps = (int)lround(1.0 / dts[d]);
		for (int k = 0; k < steps; k++) {
			sim_motor_step(&m, &p, &c, 0, dts[d]);
			assert_true(isfinite(m.angle) && fabs(m.speed) < 2 * sim_motor_no_load_speed(&p));
			if (fabs(m.speed) > peak[d])
				peak[d] = fabs(m.speed);
		}
		final_angle[d] = m.angle;
	}
	double goal = units_to_rad(700 - 512);
	assert_true(fabs(final_angle[0] - goal) < units_to_rad(1));
	assert_true(fabs(final_angle[1] - goal) < units_to_rad(1));
	assert_true(fabs(peak[0] - peak[1]) < 0.02 * peak[1]);
}

static void test_bad_input_counted(void **state)
{
	(void)state;
	struct sim_motor_params p = params();
	struct sim_motor_cmd c = cmd_default();
	struct sim_motor m;
	sim_motor_init(&m, &p, 0.1);
	sim_motor_step(&m, &p, &c, 0, NAN);
	sim_motor_step(&m, &p, &c, 0, -1);
	assert_true(m.angle == 0.1 && m.bad_input == 2);
	sim_motor_step(&m, &p, &c, INFINITY, DT);
	assert_true(isfinite(m.angle) && isfinite(m.speed) && m.bad_input == 3);
	m.speed = NAN;
	sim_motor_step(&m, &p, &c, 0, DT);
	assert_true(isfinite(m.speed) && m.bad_input == 4);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_step_reaches_no_load_speed),
		cmocka_unit_test(test_moving_speed_limits_speed),
		cmocka_unit_test(test_compliance_margin_dead_band),
		cmocka_unit_test(test_compliance_slope),
		cmocka_unit_test(test_torque_limit_blocked_joint),
		cmocka_unit_test(test_wheel_mode),
		cmocka_unit_test(test_current_drive),
		cmocka_unit_test(test_torque_off),
		cmocka_unit_test(test_voltage_scaling),
		cmocka_unit_test(test_heating_and_cooling),
		cmocka_unit_test(test_stable_at_both_step_sizes),
		cmocka_unit_test(test_bad_input_counted),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
