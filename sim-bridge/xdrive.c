/*
 * xdrive.c — an X-series servo's controllers (see xdrive.h and PHYSICS.md §5).
 *
 *   Goal Position -> profile -> Position Trajectory -> PID -> PWM (<= Goal PWM)
 *   Goal Velocity -> acceleration ramp -> Velocity Trajectory -> PI -> PWM
 *   Goal PWM -> PWM                                   (PWM Control Mode)
 *   Goal Current -> current loop -> torque            (XM430: Current Control)
 *   PID -> PWM, current <= Goal Current               (XM430: Current-based Position)
 *
 * A PWM share u drives the motor's line tau = tau_stall(V)·(u − w/w0(V)) (as
 * the AX-12A's H-bridge, motor.c); a current loop holds its torque with no
 * back-EMF loss, but never beyond what full PWM (at most Goal PWM) gives at
 * the present speed: the supply bounds it.
 */
#include "xdrive.h"

#include <math.h>

#include "dxl2_table.h"

/* Operating Mode values (dxl2_table.h). */
#define MODE_CURRENT   DXL2_OPMODE_CURRENT
#define MODE_VELOCITY  DXL2_OPMODE_VELOCITY
#define MODE_POSITION  DXL2_OPMODE_POSITION
#define MODE_EXTENDED  DXL2_OPMODE_EXTENDED_POSITION
#define MODE_CURPOS    DXL2_OPMODE_CURRENT_POSITION
#define MODE_PWM       DXL2_OPMODE_PWM

/* Gain conversions (e-manual, Position PID Gain and Velocity PI Gain):
 * K = table value / divisor. */
#define GAIN_P_DIV   128.0
#define GAIN_I_DIV   65536.0
#define GAIN_D_DIV   16.0
#define GAIN_FF_DIV  4.0
/* The loops' time unit: errors are integrated and differentiated per
 * millisecond (PHYSICS.md §5: the manual gives no unit; 1 ms is the
 * firmware's control period as far as can be told). */
#define MS_PER_S     1000.0

static const double pulses_per_rad = DXL2_POS_PER_REV / (2.0 * DXL2_PI);

static double clamp(double v, double lo, double hi)
{
	return v < lo ? lo : (v > hi ? hi : v);
}

void sim_xdrive_init(struct sim_xdrive *d)
{
	*d = (struct sim_xdrive){ 0 };
}

double sim_xdrive_present(const struct sim_xdrive_cmd *c, double angle)
{
	/* The encoder reads whole pulses. */
	return floor(c->offset + (double)c->dir * angle * pulses_per_rad + 0.5);
}

/* Restart from where the joint is: no profile running, loops emptied. */
static void xdrive_restart(struct sim_xdrive *d, double present)
{
	d->traj_pos = d->target = present;
	d->traj_vel = d->traj_acc = 0;
	d->prof_v = d->prof_a = 0;
	d->profile = SIM_XDRIVE_PROFILE_STEP;
	d->profile_ongoing = false;
	d->pos_integral = d->vel_integral = 0;
}

/* The goal of the position loop: within the position limits in Position
 * Control Mode (a goal written in another mode may lie outside them). */
static double xdrive_goal(const struct sim_xdrive_cmd *c)
{
	double g = c->goal_position;
	if (c->mode == MODE_POSITION && c->min_position <= c->max_position)
		g = clamp(g, c->min_position, c->max_position);
	return g;
}

/* A new profile from the trajectory's state to the goal (e-manual, "What is
 * the Profile"): velocity-based (Profile Velocity a top speed, Profile
 * Acceleration its ramp) or time-based (Drive Mode bit 2: the whole move in
 * Profile Velocity ms, ramps of Profile Acceleration ms). 0 = unlimited. */
static void xdrive_profile_start(struct sim_xdrive *d, const struct sim_xdrive_cmd *c)
{
	d->target = xdrive_goal(c);
	double dist = fabs(d->target - d->traj_pos);
	double v = 0, a = 0;
	if (!c->step_profile && c->time_profile && c->profile_velocity > 0) {
		double tp = c->profile_velocity / MS_PER_S;
		double ta = fmin(c->profile_acceleration, c->profile_velocity / 2) / MS_PER_S;
		v = dist / (tp - ta);
		a = ta > 0 ? v / ta : 0;
		if (!(v > 0))
			v = a = 0;   /* already there */
	} else if (!c->step_profile) {
		v = c->profile_velocity * SIM_XDRIVE_PULSES_PER_VEL_UNIT;
		a = v > 0 ? c->profile_acceleration * SIM_XDRIVE_PULSES_PER_ACC_UNIT : 0;
	}
	d->prof_v = v;
	d->prof_a = a;
	if (!(v > 0))
		d->profile = SIM_XDRIVE_PROFILE_STEP;
	else if (!(a > 0))
		d->profile = SIM_XDRIVE_PROFILE_RECTANGULAR;
	else
		d->profile = dist < v * v / a ? SIM_XDRIVE_PROFILE_TRIANGULAR : SIM_XDRIVE_PROFILE_TRAPEZOIDAL;
	d->profile_ongoing = v > 0 && dist > 0;
	if (!(v > 0)) {
		d->traj_pos = d->target;
		d->traj_vel = d->traj_acc = 0;
	}
}

/* Advance the position profile by dt: toward the target at most prof_v, with
 * ramps of prof_a, braking in time to stop on it. */
static void xdrive_profile_advance(struct sim_xdrive *d, double dt)
{
	if (!d->profile_ongoing) {
		d->traj_pos = d->target;
		d->traj_vel = d->traj_acc = 0;
		return;
	}
	double rem = d->target - d->traj_pos;
	double s = rem > 0 ? 1.0 : -1.0;
	double want = d->prof_v;
	if (d->prof_a > 0)
		want = fmin(want, sqrt(2.0 * d->prof_a * fabs(rem)));
	want *= s;
	double v0 = d->traj_vel, v = want;
	if (d->prof_a > 0)
		v = clamp(want, v0 - d->prof_a * dt, v0 + d->prof_a * dt);
	d->traj_acc = (v - v0) / dt;
	double step = v * dt;
	if (fabs(step) >= fabs(rem) || fabs(rem) < 0.5) {
		d->traj_pos = d->target;
		d->traj_vel = d->traj_acc = 0;
		d->profile_ongoing = false;
		return;
	}
	d->traj_pos += step;
	d->traj_vel = v;
}

/* Velocity Control Mode: the trajectory ramps to Goal Velocity at Profile
 * Acceleration (0: at once), and its position follows. */
static void xdrive_velocity_advance(struct sim_xdrive *d, const struct sim_xdrive_cmd *c, double dt)
{
	double goal = c->goal_velocity * SIM_XDRIVE_PULSES_PER_VEL_UNIT;
	double a = c->step_profile ? 0 : c->profile_acceleration * SIM_XDRIVE_PULSES_PER_ACC_UNIT;
	double v0 = d->traj_vel;
	double v = a > 0 ? clamp(goal, v0 - a * dt, v0 + a * dt) : goal;
	d->traj_acc = (v - v0) / dt;
	d->traj_vel = v;
	d->traj_pos += v * dt;
	d->profile = a > 0 ? SIM_XDRIVE_PROFILE_TRAPEZOIDAL : SIM_XDRIVE_PROFILE_STEP;
	d->profile_ongoing = v != goal;
}

/* The position loop's output in PWM units (885 = full), with the integral
 * held where its share alone would exceed full output (anti-windup). */
static double xdrive_position_pid(struct sim_xdrive *d, const struct sim_xdrive_cmd *c, double present,
                                  double speed, double dt)
{
	double e = d->traj_pos - present;
	double edot = (d->traj_vel - speed) / MS_PER_S;
	double ki = c->pos_i / GAIN_I_DIV;
	d->pos_integral += e * dt * MS_PER_S;
	if (ki > 0)
		d->pos_integral = clamp(d->pos_integral, -SIM_XDRIVE_PWM_FULL / ki, SIM_XDRIVE_PWM_FULL / ki);
	return c->pos_p / GAIN_P_DIV * e + c->pos_d / GAIN_D_DIV * edot + ki * d->pos_integral +
	       c->ff1 / GAIN_FF_DIV * d->traj_vel / MS_PER_S +
	       c->ff2 / GAIN_FF_DIV * d->traj_acc / (MS_PER_S * MS_PER_S);
}

/* The velocity loop's output in PWM units. Its error is taken in pulses a
 * second (PHYSICS.md §5: in 0.229 rpm units the factory gains would need
 * 0.6 s to reach a goal velocity, a wheel the watchdog stops as long). */
static double xdrive_velocity_pi(struct sim_xdrive *d, const struct sim_xdrive_cmd *c, double speed, double dt)
{
	double e = d->traj_vel - speed;
	double ki = c->vel_i / GAIN_I_DIV;
	d->vel_integral += e * dt * MS_PER_S;
	if (ki > 0)
		d->vel_integral = clamp(d->vel_integral, -SIM_XDRIVE_PWM_FULL / ki, SIM_XDRIVE_PWM_FULL / ki);
	return c->vel_p / GAIN_P_DIV * e + ki * d->vel_integral;
}

double sim_xdrive_cap(const struct sim_xdrive_cmd *c, double stall)
{
	if (c->current_limit < 0)
		return stall;
	return fmin(stall, c->current_limit * SIM_XDRIVE_AMPS_PER_UNIT * c->torque_constant);
}

/* A torque asked of the current loop, bounded by what full PWM (at most
 * Goal PWM) gives at this speed (servo coordinates, rad/s). */
static void xdrive_current_line(struct sim_xdrive *d, const struct sim_xdrive_cmd *c, const struct sim_motor_params *p,
                                double torque, double w, double ulim, struct sim_motor_drive *out)
{
	double stall = sim_motor_stall_torque(p), w0 = sim_motor_no_load_speed(p);
	torque = clamp(torque, stall * (-ulim - w / w0), stall * (ulim - w / w0));
	d->torque_cmd = torque;
	d->duty = clamp(torque / stall + w / w0, -1.0, 1.0);
	out->a = c->dir * torque;
	out->c = 0;
	out->cap = sim_xdrive_cap(c, stall);
	out->duty = c->dir * d->duty;
}

void sim_xdrive_step(struct sim_xdrive *d, const struct sim_xdrive_cmd *c, const struct sim_motor *m,
                     const struct sim_motor_params *p, double dt, struct sim_motor_drive *out)
{
	double present = sim_xdrive_present(c, m->angle);
	double speed = c->dir * m->speed * pulses_per_rad;   /* pulses/s, servo coordinates */
	double stall = sim_motor_stall_torque(p), w0 = sim_motor_no_load_speed(p);
	*out = (struct sim_motor_drive){ 0, 0, 0, 0 };
	d->duty = d->torque_cmd = 0;
	if (!c->torque_enable || !(stall > 0) || !(w0 > 0) || !(dt > 0) || !isfinite(present)) {
		d->active = false;
		xdrive_restart(d, isfinite(present) ? present : 0);
		return;
	}
	if (!d->active || c->reset_seq != d->reset_seq) {
		xdrive_restart(d, present);
		d->active = true;
		d->reset_seq = c->reset_seq;
		d->goal_seq = c->goal_seq - 1;   /* the goal as it stands now starts a profile */
	}
	double pwm = 0;
	double ulim = clamp(fabs((double)c->goal_pwm) / SIM_XDRIVE_PWM_FULL, 0.0, 1.0);
	switch (c->mode) {
	case MODE_POSITION:
	case MODE_EXTENDED:
	case MODE_CURPOS:
		if (c->goal_seq != d->goal_seq) {
			d->goal_seq = c->goal_seq;
			xdrive_profile_start(d, c);
		}
		xdrive_profile_advance(d, dt);
		pwm = xdrive_position_pid(d, c, present, speed, dt);
		break;
	case MODE_VELOCITY:
		d->goal_seq = c->goal_seq;
		xdrive_velocity_advance(d, c, dt);
		pwm = xdrive_velocity_pi(d, c, speed, dt);
		break;
	case MODE_PWM:
		pwm = c->goal_pwm;
		d->traj_pos = present;
		break;
	case MODE_CURRENT:
	default:
		d->traj_pos = present;
		break;
	}
	double w = speed / pulses_per_rad;
	if (c->mode == MODE_CURRENT) {
		xdrive_current_line(d, c, p, c->goal_current * SIM_XDRIVE_AMPS_PER_UNIT * c->torque_constant, w, ulim, out);
		return;
	}
	d->duty = clamp(pwm / SIM_XDRIVE_PWM_FULL, -ulim, ulim);
	out->a = c->dir * d->duty * stall;
	/* back-EMF damping tau_stall / w0 does not depend on the supply */
	out->c = p->stall_torque_12v / p->no_load_speed_12v;
	out->cap = sim_xdrive_cap(c, stall);
	/* Current-based Position: the same loop, its current held to Goal
	 * Current (e-manual: "sets a limit to current") */
	if (c->mode == MODE_CURPOS)
		out->cap = fmin(out->cap, fabs((double)c->goal_current) * SIM_XDRIVE_AMPS_PER_UNIT * c->torque_constant);
	out->duty = c->dir * d->duty;
}
