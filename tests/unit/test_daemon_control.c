/* test_daemon_control.c — the controller between bus and control laws, with a
 * small servo model in the loop: start-up ramp, mode switches without jumps,
 * stale readings hold, fault back-off / recovery / persistent failure, LIMP,
 * and non-finite numbers never reaching a goal. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../../daemon/control.h"
#include "dxl.h"
#include "dxl_table.h"

/* the control period (s): the daemon's default, 10 ms, unless a test runs
 * another rate (set before setup_config) */
static double dt_s = 0.01;

static struct cfg cfg;
static struct ctl c;
/* the servo model: a first-order lag of 27 ms (the AX-12's, CONTROL.md) toward
 * its goal, at most 6 rad/s, quantized like an AX-12 */
#define SERVO_TAU 0.027
static double servo_angle[2];
static uint8_t servo_err[2];
static bool servo_answers[2];
static bool servo_blocked;   /* held in place from outside (a jam) */
static double t;

/* Two joints configured, the controller initialised: nothing read yet. */
static void setup_config(enum cfg_mode mode)
{
	struct cfg_errors e = { 0 };
	cfg_defaults(&cfg);
	cfg_override(&cfg, "robot.port=/dev/null", &e);
	cfg_override(&cfg, "robot.ids=1,2", &e);
	cfg.mode = mode;
	cfg.period_ms = dt_s * 1e3;
	cfg.fault_backoff_s = 0.2;
	cfg.fault_retries = 2;
	assert_true(cfg_finish(&cfg, &e));
	ctl_init(&c, &cfg);
}

static void setup_robot(enum cfg_mode mode)
{
	setup_config(mode);
	char why[256];
	struct ctl_servo_info info = { .cw_limit = 0, .ccw_limit = 1023, .max_torque = 1023, .status_return_level = 2 };
	for (size_t j = 0; j < 2; j++) {
		assert_true(ctl_set_servo(&c, j, &info, why, sizeof why));
		servo_err[j] = 0;
		servo_answers[j] = true;
	}
	servo_blocked = false;
	servo_angle[0] = 0.3;
	servo_angle[1] = -0.2;
	t = 0.0;
	for (size_t j = 0; j < 2; j++)
		ctl_measure(&c, j, dxl_rad_to_pos(servo_angle[j]), 0, 0, 0, dt_s);
	ctl_start(&c, t, "test");
}

/* The cycle's side of the controller's outputs: every queued write sent and
 * acknowledged, every event taken. What a step queues is then what the
 * controller's queue and event list hold until the next drain. */
static void drain_outputs(void)
{
	while (ctl_take_write(&c) != NULL)
		ctl_write_result(&c, true);
	struct ctl_event e;
	while (ctl_next_event(&c, &e))
		;
}

static bool has_write(uint8_t id, uint8_t addr, uint16_t value)
{
	for (size_t i = 0; i < c.wq.n; i++)
		if (c.wq.w[i].id == id && c.wq.w[i].addr == addr && c.wq.w[i].value == value)
			return true;
	return false;
}

static const struct ctl_event *find_event(const char *kind)
{
	for (size_t i = 0; i < c.nevents; i++)
		if (strcmp(c.events[i].kind, kind) == 0)
			return &c.events[i];
	return NULL;
}

/* One cycle; returns the largest goal change of the cycle. */
static double cycle(void)
{
	double before[2] = { c.j[0].goal, c.j[1].goal };
	t += dt_s;
	for (size_t j = 0; j < 2; j++) {
		if (c.j[j].torque && isfinite(c.j[j].goal) && !servo_blocked) {
			double d = (c.j[j].goal - servo_angle[j]) * (dt_s / SERVO_TAU);
			if (dt_s > SERVO_TAU)
				d = c.j[j].goal - servo_angle[j];
			double lim = 6.0 * dt_s;
			servo_angle[j] += d > lim ? lim : d < -lim ? -lim : d;
		}
		if (servo_answers[j])
			ctl_measure(&c, j, dxl_rad_to_pos(servo_angle[j]), 0, 0, servo_err[j], dt_s);
	}
	drain_outputs();
	ctl_step(&c, t, dt_s, t);
	double m = 0.0;
	for (size_t j = 0; j < 2; j++) {
		assert_true(isfinite(c.j[j].goal));
		if (isfinite(before[j]) && c.j[j].write_goal)
			m = fmax(m, fabs(c.j[j].goal - before[j]));
	}
	return m;
}

static double run(int n)
{
	double m = 0.0;
	for (int i = 0; i < n; i++)
		m = fmax(m, cycle());
	return m;
}

static void test_start_hold(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_HOLD);
	/* start: torque limit back and torque on, per servo */
	assert_true(has_write(1, DXL_AX_TORQUE_LIMIT, 1023) && has_write(1, DXL_AX_TORQUE_ENABLE, 1));
	assert_true(has_write(2, DXL_AX_TORQUE_LIMIT, 1023) && has_write(2, DXL_AX_TORQUE_ENABLE, 1));
	assert_non_null(find_event("start"));
	double a0 = servo_angle[0];
	run(50);
	/* HOLD where it was: the goal is the present angle, no jump */
	assert_true(fabs(c.j[0].goal - a0) < 0.003);
	assert_true(c.j[0].write_goal);
}

/* The published phase is NAN until a joint has been read, never a 0 that
 * reads as "at the positive turning point" (common/phase.h). */
static void test_phase_unknown_until_read(void **state)
{
	(void)state;
	setup_config(CFG_MODE_HOLD);
	assert_true(isnan(c.j[0].phase) && isnan(c.j[1].phase));
	setup_robot(CFG_MODE_HOLD);
	run(5);
	assert_true(isfinite(c.j[0].phase) && isfinite(c.j[1].phase));
}

static void test_switches_without_jumps(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_SINUSOID);
	/* the start ramp blends from the present angle into the sinusoid */
	double m = run(400);
	assert_true(m < 0.05);
	/* the sinusoid itself: amplitude 0.8 rad at 0.8 Hz is at most 0.04 rad a cycle */
	ctl_set_mode(&c, CFG_MODE_HOLD, "test");
	assert_true(cycle() < 0.05);
	double held = c.j[0].goal;
	run(20);
	assert_true(fabs(c.j[0].goal - held) < 1e-12);
	ctl_set_mode(&c, CFG_MODE_SINUSOID, "test");
	assert_true(run(300) < 0.05);
	/* between moving modes: no change larger than the motion going on before */
	double before = run(20);
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	double first = run(3);
	if (!(first <= before + 0.01))
		fail_msg("goal jumped %.4f rad at the switch to OSCILLATOR (moving %.4f a cycle)", first, before);
	assert_true(run(300) <= cfg.joint[0].max_step + 1e-12);
	assert_false(c.starter_active);
	before = run(20);
	ctl_set_mode(&c, CFG_MODE_SINUSOID, "test");
	first = run(3);
	if (!(first <= before + 0.01))
		fail_msg("goal jumped %.4f rad at the switch to SINUSOID (moving %.4f a cycle)", first, before);
	run(300);
	const double a = c.p.amplitude;
	/* once blended, the commanded angle is the sinusoid itself */
	assert_true(fabs(c.j[0].goal - osc_sinusoid(a, cfg.frequency, cfg.phase, 0, t)) < 1e-9);
}

static void test_oscillator_starts_from_rest(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_HOLD);
	run(20);
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	/* from rest the starter (the sinusoid) runs first, then the oscillator */
	assert_true(c.starter_active && c.starter_until > c.t);
	/* through the starter and its hand-over: no change beyond the motion itself */
	double m = 0.0, prev_step = 0.0;
	int handover = -1;
	for (int i = 0; i < 400; i++) {
		bool was_starting = c.starter_active;
		double step = cycle();
		if (was_starting && !c.starter_active)
			handover = i;
		bool near = handover >= 0 && i - handover <= 5;
		if (i > 0 && (c.starter_active || near) && !(step <= prev_step + 0.02))
			fail_msg("cycle %d: goal changed %.4f after %.4f (starter %s)", i, step, prev_step,
			         c.starter_active ? "on" : "off");
		prev_step = step;
		m = fmax(m, step);
	}
	assert_true(m <= cfg.joint[0].max_step + 1e-12);
	assert_true(handover > 0);
	assert_false(c.starter_active);
	double lo = 1e9, hi = -1e9;
	for (int i = 0; i < 300; i++) {
		cycle();
		lo = fmin(lo, servo_angle[0]);
		hi = fmax(hi, servo_angle[0]);
	}
	assert_true(hi - lo > 0.5);   /* it keeps moving on its own */
}

/* Run OSCILLATOR, block the joints until the stall restart, return its offset. */
static double stall_offset(const char *name)
{
	setup_robot(CFG_MODE_OSCILLATOR);
	snprintf(cfg.name, sizeof cfg.name, "%s", name);
	run(400);
	assert_false(c.starter_active);
	long long starts = c.starts;
	servo_blocked = true;
	const struct ctl_event *stall = NULL;
	for (int i = 0; i < 300 && stall == NULL; i++) {
		cycle();
		stall = find_event("stall");
	}
	assert_non_null(stall);
	assert_true(c.starter_active && c.starts == starts + 1);
	assert_non_null(strstr(stall->text, "phase"));
	servo_blocked = false;
	/* the starter drives the sinusoid at the offset phase once blended in */
	run((int)(cfg.ramp_s / dt_s) + 2);
	assert_true(c.starter_active);
	double want = cfg.joint[0].neutral + osc_sinusoid(cfg.amplitude, cfg.frequency, cfg.phase + c.starter_offset, 0, t);
	assert_true(fabs(c.j[0].goal - want) < 1e-9);
	/* and hands over without a jump */
	double m = run(300);
	assert_true(m <= cfg.joint[0].max_step + 1e-12);
	return c.starter_offset;
}

/* At other rates the stall restart comes after the same time at rest (1 s),
 * not the same number of cycles (100 were 0.1 s at 1 kHz: a turning point of
 * the gait), and the default step limit is the same speed (10 rad/s). */
static void test_stall_time_at_other_rates(void **state)
{
	(void)state;
	const double periods[] = { 0.001, 0.002, 0.02 };
	for (size_t k = 0; k < sizeof periods / sizeof periods[0]; k++) {
		dt_s = periods[k];
		setup_robot(CFG_MODE_OSCILLATOR);
		assert_true(fabs(cfg.joint[0].max_step - 10.0 * dt_s) < 1e-12);
		run((int)lround(4.0 / dt_s));
		assert_false(c.starter_active);
		servo_blocked = true;
		double t0 = t;
		const struct ctl_event *stall = NULL;
		while (stall == NULL && t - t0 < 3.0) {
			cycle();
			stall = find_event("stall");
		}
		if (stall == NULL)
			fail_msg("period %g s: no stall restart within 3 s at rest", dt_s);
		/* the joints come to rest within a few cycles of the block, then 1 s */
		if (!(t - t0 >= 1.0 && t - t0 < 1.1))
			fail_msg("period %g s: stall restart %.3f s after the block, want 1.0 s", dt_s, t - t0);
		assert_non_null(strstr(stall->text, "at rest for 1.0 s"));
		servo_blocked = false;
	}
}

static int rate_back(void **state)
{
	(void)state;
	dt_s = 0.01;
	return 0;
}

/* A stall restart draws a phase offset from the robot's name: two robots
 * jammed in exact anti-phase do not restart into the same jam. */
static void test_stall_restart_offset(void **state)
{
	(void)state;
	double a = stall_offset("left"), b = stall_offset("right"), a2 = stall_offset("left");
	assert_true(fabs(a) <= 3.14159266 && fabs(b) <= 3.14159266);
	assert_true(fabs(a - b) > 1e-3);
	assert_true(a == a2);   /* deterministic */
}

static void test_stale_joint_holds(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_SINUSOID);
	run(200);
	servo_answers[1] = false;
	double g = c.j[1].goal;
	run(5);
	assert_true(c.j[1].goal == g);            /* holds its last goal */
	assert_int_equal(c.j[1].stale_cycles, 5);
	assert_true(c.j[0].goal != g);            /* the other joint goes on */
	drain_outputs();
	bool seen = false;
	for (int i = 0; i < cfg.stale_limit; i++) {
		cycle();
		seen = seen || find_event("stale") != NULL;
	}
	assert_true(seen);
	servo_answers[1] = true;
	assert_true(run(5) < 0.05);
	assert_int_equal(c.j[1].stale_cycles, 0);
}

static void test_fault_recovery(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_HOLD);
	run(10);
	servo_err[1] = DXL_ERRBIT_OVERLOAD;
	cycle();
	assert_non_null(find_event("fault"));
	assert_true(has_write(2, DXL_AX_TORQUE_LIMIT, 512));   /* backs off: half torque */
	assert_int_equal(c.j[1].fault, CTL_FAULT_BACKOFF);
	assert_int_equal(c.faults, 1);
	assert_true(fabs(c.j[1].goal - servo_angle[1]) < 0.003);  /* holds where it is */
	servo_err[1] = 0;
	bool wrote = false, recovered = false;
	for (int i = 0; i < 60; i++) {
		cycle();
		wrote = wrote || (has_write(2, DXL_AX_TORQUE_LIMIT, 1023) && has_write(2, DXL_AX_TORQUE_ENABLE, 1));
		recovered = recovered || find_event("recovered") != NULL;
	}
	assert_true(wrote);
	assert_true(recovered);
	assert_int_equal(c.j[1].fault, CTL_FAULT_NONE);
	assert_int_equal(c.mode, CFG_MODE_HOLD);
}

static void test_fault_persistent(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_SINUSOID);
	cfg.fault_action = CFG_SAFE_LIMP;
	run(100);
	servo_err[0] = DXL_ERRBIT_OVERHEAT;
	int fault_events = 0;
	const struct ctl_event *persistent = NULL;
	static struct ctl_event kept;
	for (int i = 0; i < 300 && persistent == NULL; i++) {
		cycle();
		for (size_t k = 0; k < c.nevents; k++)
			if (strcmp(c.events[k].kind, "fault") == 0)
				fault_events++;
		if (find_event("fault-persistent") != NULL) {
			kept = *find_event("fault-persistent");
			persistent = &kept;
			assert_true(has_write(1, DXL_AX_TORQUE_ENABLE, 0) && has_write(2, DXL_AX_TORQUE_ENABLE, 0));
		}
	}
	assert_non_null(persistent);
	assert_int_equal(fault_events, 1 + cfg.fault_retries);   /* first report + each retry */
	assert_non_null(strstr(persistent->text, "overheating persists"));
	assert_int_equal(c.mode, CFG_MODE_LIMP);
	assert_non_null(strstr(c.reason, "fault: servo 1 overheating persists"));
	/* LIMP: nothing is written to the goals */
	cycle();
	assert_false(c.j[0].write_goal || c.j[1].write_goal);
	/* latched: only LIMP (the fault action here) until cleared */
	char why[256];
	assert_true(c.latched);
	assert_false(ctl_mode_allowed(&c, CFG_MODE_HOLD, why, sizeof why));
	assert_non_null(strstr(why, "fault latched"));
	assert_false(ctl_mode_allowed(&c, CFG_MODE_OSCILLATOR, why, sizeof why));
	assert_true(ctl_mode_allowed(&c, CFG_MODE_LIMP, why, sizeof why));
	/* the operator clears it, then takes over */
	servo_err[0] = 0;
	assert_true(ctl_clear_faults(&c, why, sizeof why));
	assert_false(c.latched);
	assert_int_equal(c.j[0].fault, CTL_FAULT_NONE);
	assert_int_equal(c.mode, CFG_MODE_LIMP);   /* clearing changes no mode */
	ctl_set_mode(&c, CFG_MODE_HOLD, "command");
	assert_true(has_write(1, DXL_AX_TORQUE_ENABLE, 1));
	assert_true(run(20) < 0.01);
}

static void test_other_error_bits_reported_once(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_HOLD);
	run(5);
	servo_err[0] = DXL_ERRBIT_VOLTAGE;
	cycle();
	const struct ctl_event *e = find_event("servo-error");
	assert_non_null(e);
	assert_non_null(strstr(e->text, "servo 1 reports input voltage"));
	int again = 0;
	for (int i = 0; i < 20; i++) {
		cycle();
		again += find_event("servo-error") != NULL;
	}
	assert_int_equal(again, 0);            /* once, not every cycle */
	assert_int_equal(c.j[0].fault, CTL_FAULT_NONE);   /* not a fault: no back-off */
	servo_err[0] = 0;
	run(2);
	servo_err[0] = DXL_ERRBIT_VOLTAGE;
	cycle();
	assert_non_null(find_event("servo-error"));   /* a new occurrence is reported again */
}

static void test_torque_commands(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_OSCILLATOR);
	run(50);
	drain_outputs();
	ctl_torque(&c, false);
	assert_int_equal(c.mode, CFG_MODE_LIMP);
	assert_true(has_write(1, DXL_AX_TORQUE_ENABLE, 0));
	servo_angle[0] = 0.9;   /* moved by hand while limp */
	run(5);
	drain_outputs();
	ctl_torque(&c, true);
	assert_int_equal(c.mode, CFG_MODE_HOLD);
	assert_true(has_write(1, DXL_AX_TORQUE_ENABLE, 1));
	assert_true(run(5) < 0.01);
	assert_true(fabs(c.j[0].goal - 0.9) < 0.003);   /* holds where the hand left it */
}

/* A fault while the operator has the robot LIMP latches, and the robot stays
 * LIMP: the fault action (HOLD here) never turns torque on. The soak (make
 * test-long, qa_soak) found a servo going silent while LIMP switching the
 * robot to HOLD, torque on, 393 states over 34 LIMPs. */
static void test_fault_while_limp_stays_limp(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_OSCILLATOR);
	cfg.fault_action = CFG_SAFE_HOLD;
	run(50);
	ctl_torque(&c, false);
	assert_int_equal(c.mode, CFG_MODE_LIMP);
	run(5);
	drain_outputs();
	servo_answers[1] = false;
	int n = (int)(cfg.silent_s / (cfg.period_ms * 1e-3)) + 20;
	bool torque_on = false;
	for (int i = 0; i < n; i++) {
		cycle();
		torque_on = torque_on || has_write(1, DXL_AX_TORQUE_ENABLE, 1) || has_write(2, DXL_AX_TORQUE_ENABLE, 1);
	}
	assert_true(c.latched);
	assert_int_equal(c.mode, CFG_MODE_LIMP);
	assert_false(torque_on);
	assert_false(c.j[0].torque || c.j[1].torque);
	assert_non_null(strstr(c.reason, "silent"));
	/* the operator may still choose HOLD (the fault action) */
	char why[256];
	assert_true(ctl_mode_allowed(&c, CFG_MODE_HOLD, why, sizeof why));
	servo_answers[1] = true;
}

/* A joint found past its limit (moved by hand while limp, or a servo that
 * reset there) is held at the limit, never at where it is: the goal the
 * controller keeps and publishes is inside the limits from the first cycle. */
static void test_hold_from_past_limit_inside_limits(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_HOLD);
	run(20);
	ctl_torque(&c, false);
	run(3);
	servo_angle[1] = c.j[1].limits.lo - 0.01;   /* pushed past the limit by hand */
	run(3);
	drain_outputs();
	ctl_torque(&c, true);
	assert_int_equal(c.mode, CFG_MODE_HOLD);
	assert_true(c.j[1].goal >= c.j[1].limits.lo);
	assert_true(c.hold[1] >= c.j[1].limits.lo);
	for (int i = 0; i < 5; i++) {
		cycle();
		assert_true(c.j[1].goal >= c.j[1].limits.lo && c.j[1].goal <= c.j[1].limits.hi);
	}
}

/* The goal register never names an angle past the limits: +0.5 rad against
 * +-0.5 limits rounds to 98 steps (+0.5011 rad) on the AX-12A; the register
 * takes 97. */
static void test_goal_register_inside_limits(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_SINUSOID);
	cfg.joint[1].limit_min = -0.5;
	cfg.joint[1].limit_max = 0.5;
	char why[512];
	struct ctl_servo_info info = { .cw_limit = 0, .ccw_limit = 1023, .max_torque = 1023 };
	assert_true(ctl_set_servo(&c, 1, &info, why, sizeof why));
	assert_true(ctl_set_param(&c, "amplitude", -1, 2.5, why, sizeof why));
	uint16_t addr;
	uint8_t width, ids[8], data[64];
	int at_hi = 0, at_lo = 0;
	for (int i = 0; i < 400; i++) {
		cycle();
		size_t n = ctl_sync(&c, &addr, &width, ids, data);
		for (size_t k = 0; k < n; k++) {
			if (ids[k] != 2)
				continue;
			uint16_t pos = dxl_get_u16(&data[width * k]);
			double rad = dxl_pos_to_rad(pos);
			if (rad > 0.5 || rad < -0.5)
				fail_msg("goal register %u = %+.4f rad, past +-0.5", pos, rad);
			at_hi += pos == 512 + 97;
			at_lo += pos == 512 - 97;
		}
	}
	assert_true(at_hi > 0 && at_lo > 0);   /* it went to each limit */
}

/* ctl_set_param is the one door for a live parameter: a refused value
 * (not finite, out of its range, a joint that does not exist, a natural
 * frequency too high, a bound only the file sets, a name that is none)
 * changes nothing, says why, and the configuration is never written. */
static void test_set_param_refused_leaves_controller(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_SINUSOID);
	run(50);
	static struct cfg saved;
	saved = cfg;
	struct cfg_params before = c.p;
	double blend_t0 = c.blend_t0[0];
	static const struct { const char *name; int joint; double value; const char *why; } bad[] = {
		{ "k", 0, NAN, "parameter k: value is not finite" },
		{ "mu", -1, INFINITY, "parameter mu: value is not finite" },
		{ "k", 0, 20.0, "parameter k: 20 out of range 0.0001..10" },
		{ "amplitude", -1, 2.7, "parameter amplitude: 2.7 out of range 0..2.618" },
		{ "amplitude", 0, 0.5, "parameter amplitude is per robot: joint must be -1, not 0" },
		{ "c", 2, 0.01, "parameter c: joint 2 does not exist (0..1, or -1 for all)" },
		{ "k", -1, 9.0, "parameter k: joint 0: k 9 and inertia" },
		{ "stiffness", -1, 0.1, "parameter stiffness: stiffness 0.1 drives the clock as a torque" },
		{ "servo_lead_s", -1, 0.25, "parameter servo_lead_s: 0.25 out of range 0..0.2" },
		{ "servo_lead_s", 1, 0.05, "parameter servo_lead_s is per robot" },
		{ "limit_max", 0, 0.1, "parameter limit_max cannot be changed while the robot runs" },
		{ "neutral", -1, 0.1, "parameter neutral cannot be changed" },
		{ "period_ms", -1, 5.0, "parameter period_ms cannot be changed" },
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		char why[256] = "";
		if (ctl_set_param(&c, bad[i].name, bad[i].joint, bad[i].value, why, sizeof why))
			fail_msg("%s %g (joint %d) accepted", bad[i].name, bad[i].value, bad[i].joint);
		if (strstr(why, bad[i].why) != why)
			fail_msg("%s: why '%s', expected '%s...'", bad[i].name, why, bad[i].why);
		assert_memory_equal(&c.p, &before, sizeof before);
	}
	assert_true(c.blend_t0[0] == blend_t0);   /* no re-blend for nothing */
	/* accepted: applied at once, SINUSOID re-blends from where it is */
	char why[256];
	run(5);
	assert_true(ctl_set_param(&c, "frequency", -1, 0.5, why, sizeof why));
	assert_true(c.p.frequency == 0.5 && c.blend_t0[0] == c.t && isfinite(c.blend_from[0]));
	assert_true(ctl_set_param(&c, "servo_lead_s", -1, 0.05, why, sizeof why));
	assert_true(c.p.servo_lead_s == 0.05);
	assert_memory_equal(&cfg, &saved, sizeof cfg);
}

static void test_nonfinite_never_reaches_goal(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_SINUSOID);
	run(200);
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	c.p.osc[0].k = NAN;      /* a corrupted parameter (ctl_set_param refuses one) */
	c.p.osc[1].inertia = INFINITY;
	long long before = c.nonfinite;
	double m = run(50);
	assert_true(c.nonfinite > before);
	assert_true(m <= cfg.joint[0].max_step + 1e-12);
	for (size_t j = 0; j < 2; j++) {
		assert_true(isfinite(c.j[j].goal));
		assert_true(c.j[j].goal >= c.j[j].limits.lo && c.j[j].goal <= c.j[j].limits.hi);
	}
}

static void test_limits_respected(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_SINUSOID);
	char why[512];
	struct ctl_servo_info info = { .cw_limit = 400, .ccw_limit = 1023, .max_torque = 1023 };
	assert_true(ctl_set_servo(&c, 0, &info, why, sizeof why));
	assert_true(ctl_set_param(&c, "amplitude", -1, 2.5, why, sizeof why));   /* asks beyond ±1.3 */
	for (int i = 0; i < 400; i++) {
		cycle();
		assert_true(c.j[0].goal >= dxl_pos_to_rad(400) - 1e-12 && c.j[0].goal <= 1.3 + 1e-12);
		assert_true(c.j[1].goal >= -1.3 - 1e-12 && c.j[1].goal <= 1.3 + 1e-12);
		assert_true(dxl_rad_to_pos(c.j[0].goal) >= 400);
	}
	/* wheel mode and disjoint limits are refused with a reason */
	info.cw_limit = info.ccw_limit = 0;
	assert_false(ctl_set_servo(&c, 0, &info, why, sizeof why));
	assert_non_null(strstr(why, "wheel mode"));
	info.cw_limit = 1000;
	info.ccw_limit = 1023;
	assert_false(ctl_set_servo(&c, 0, &info, why, sizeof why));
	if (strstr(why, "no angle in common") == NULL)
		fail_msg("why: %s", why);
}

/* The read-back of a joint's RAM (24..43) as a servo would send it. */
static void readback(size_t j, uint8_t margin, uint8_t slope)
{
	uint8_t ram[CTL_READBACK_LEN] = { 0 };
	ram[DXL_AX_TORQUE_ENABLE - CTL_READBACK_ADDR] = c.j[j].torque;
	dxl_put_u16(&ram[DXL_AX_TORQUE_LIMIT - CTL_READBACK_ADDR], 1023);
	ram[DXL_AX_CW_COMPLIANCE_MARGIN - CTL_READBACK_ADDR] = ram[DXL_AX_CCW_COMPLIANCE_MARGIN - CTL_READBACK_ADDR] = margin;
	ram[DXL_AX_CW_COMPLIANCE_SLOPE - CTL_READBACK_ADDR] = ram[DXL_AX_CCW_COMPLIANCE_SLOPE - CTL_READBACK_ADDR] = slope;
	ram[DXL_AX_PRESENT_VOLTAGE - CTL_READBACK_ADDR] = 120;
	ram[DXL_AX_PRESENT_TEMPERATURE - CTL_READBACK_ADDR] = 30;
	ctl_readback(&c, j, ram, 0);
}

/* A configured compliance slope (the position loop's stiffness) is the
 * servo's: a slope found otherwise (another program, a reset) is counted
 * and written again, both sides in one write; unset, the servo keeps its
 * own. */
static void test_compliance_slope_read_back(void **state)
{
	(void)state;
	setup_robot(CFG_MODE_HOLD);
	run(20);
	drain_outputs();
	long before = c.readback_mismatches;
	readback(0, 0, 32);   /* the factory slope: not configured, so nothing */
	assert_int_equal(c.wq.n, 0);
	assert_int_equal(c.readback_mismatches, before);

	cfg.compliance_slope = 128;
	readback(0, 0, 128);
	assert_int_equal(c.wq.n, 0);
	readback(1, 0, 32);
	assert_true(has_write(2, DXL_AX_CW_COMPLIANCE_SLOPE, 128 | 128 << 8));
	assert_int_equal(c.readback_mismatches, before + 1);
	const struct ctl_event *ev = find_event("readback");
	assert_non_null(ev);
	assert_non_null(strstr(ev->text, "compliance slope read back 32, expected 128"));
	cfg.compliance_slope = -1;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_compliance_slope_read_back),
		cmocka_unit_test(test_start_hold),
		cmocka_unit_test(test_phase_unknown_until_read),
		cmocka_unit_test(test_switches_without_jumps),
		cmocka_unit_test(test_oscillator_starts_from_rest),
		cmocka_unit_test(test_stall_restart_offset),
		cmocka_unit_test_teardown(test_stall_time_at_other_rates, rate_back),
		cmocka_unit_test(test_stale_joint_holds),
		cmocka_unit_test(test_fault_recovery),
		cmocka_unit_test(test_fault_persistent),
		cmocka_unit_test(test_other_error_bits_reported_once),
		cmocka_unit_test(test_torque_commands),
		cmocka_unit_test(test_fault_while_limp_stays_limp),
		cmocka_unit_test(test_hold_from_past_limit_inside_limits),
		cmocka_unit_test(test_goal_register_inside_limits),
		cmocka_unit_test(test_set_param_refused_leaves_controller),
		cmocka_unit_test(test_nonfinite_never_reaches_goal),
		cmocka_unit_test(test_limits_respected),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
