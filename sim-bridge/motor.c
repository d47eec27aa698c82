/*
 * motor.c — one AX-12A joint: compliance controller -> PWM duty -> DC motor
 * line -> joint dynamics, plus a first-order thermal model.
 *
 * The models, their parameters and where the numbers come from are in
 * sim-bridge/PHYSICS.md. In short:
 *   duty u (signed, |u| <= torque limit) from the compliance curve;
 *   motor torque  tau = tau_stall(V) * (u - w / w0(V)), clamped to the torque
 *   limit (the driver limits current);
 *   I dw/dt = tau + tau_ext - viscous * w - coulomb * sgn(w),
 * stepped with semi-implicit Euler (speed first, then angle with the new
 * speed); the terms linear in w (back-EMF, viscous friction)
 * are explicit while dt·c/I is small and implicit beyond, and Coulomb friction
 * is a stick/slip projection; the position loop is explicit (stable for dt up
 * to ≈ 11 ms at the stiffest compliance slope). A step costs a few
 * multiplications (no transcendental functions).
 */
#include "motor.h"

#include <math.h>

#include "dxl2_table.h"
#include "dxl_table.h"

/* The datasheet's motor line is given at this supply voltage. */
#define MOTOR_REF_VOLTAGE    DXL2_REF_VOLTAGE
/* Full scale of torque limit, punch and wheel-mode speed registers. */
#define MOTOR_RAW_FULL       1023.0
#define MOTOR_SPEED_MASK     0x3FFu
/* The delivered torque counts as "at the limit" within this fraction of it. */
#define MOTOR_LIMIT_TOL      0.98

static const double motor_units_per_rad = 1.0 / DXL_POS_RAD_PER_UNIT;

/* Defaults, derived in PHYSICS.md. */
#define MOTOR_LINK_MASS_KG      0.12      /* 18.65 cm link with its bumper */
#define MOTOR_LINK_LENGTH_M     0.1865
#define MOTOR_ROTOR_REFLECTED   3.0e-3    /* kg·m²: ≈4.6e-8 rotor × 254² */

double sim_motor_link_inertia(void)
{
	/* A uniform rod about its end: m L² / 3. */
	return MOTOR_LINK_MASS_KG * MOTOR_LINK_LENGTH_M * MOTOR_LINK_LENGTH_M / 3.0;
}

void sim_motor_default_params(struct sim_motor_params *p)
{
	/* The link plus the motor's rotor seen through the gearbox (which
	 * dominates). */
	p->inertia = sim_motor_link_inertia() + MOTOR_ROTOR_REFLECTED;
	/* The datasheet line is measured at the output, gearbox losses included:
	 * these are only what the link adds (bearing, drag). */
	p->viscous = 0.002;
	p->coulomb = 0.005;
	const struct dxl2_datasheet *ax = &dxl2_model_find(1, DXL_AX12_MODEL)->sheet;
	p->stall_torque_12v = ax->stall_torque_nm;
	p->no_load_speed_12v = dxl2_sheet_no_load_rad_s(ax);
	p->supply_voltage = DXL2_REF_VOLTAGE;
	p->ambient_c = 25.0;
	p->thermal_tau_s = 600.0;
	p->heat_gain = 0.6;
	p->backdrive_viscous = 0.2;
	p->backdrive_coulomb = 0.05;
	p->current_drive = false;   /* the AX-12A's PWM */
}

double sim_motor_stall_torque(const struct sim_motor_params *p)
{
	double v = p->supply_voltage > 0 ? p->supply_voltage : 0;
	return p->stall_torque_12v * v / MOTOR_REF_VOLTAGE;
}

double sim_motor_no_load_speed(const struct sim_motor_params *p)
{
	double v = p->supply_voltage > 0 ? p->supply_voltage : 0;
	return p->no_load_speed_12v * v / MOTOR_REF_VOLTAGE;
}

void sim_motor_init(struct sim_motor *m, const struct sim_motor_params *p, double angle)
{
	m->angle = isfinite(angle) ? angle : 0.0;
	m->speed = 0;
	m->motor_torque = 0;
	m->temperature = p->ambient_c;
	m->ext_torque = 0;
	m->drive = 0;
	m->bad_input = 0;
	m->setpoint = m->angle * motor_units_per_rad + DXL_POS_CENTER;
}

/* The AX-12 uses the compliance slope in 7 steps: the largest power of two
 * not above the register value, at least 2 (e-manual, address 28). */
static double motor_slope_units(uint8_t reg)
{
	unsigned s = 2;
	while (s < 128 && (s << 1) <= reg)
		s <<= 1;
	return (double)s;
}

static double motor_clamp(double v, double lo, double hi)
{
	return v < lo ? lo : (v > hi ? hi : v);
}

/* Nearest whole number, halves up, without a libm call in the step (the
 * argument is a position in units: far inside the range of long). */
static double motor_round(double v)
{
	if (!(fabs(v) < 1e15))
		return v;   /* already whole at this size, and (long) would overflow */
	double t = v + 0.5;
	double i = (double)(long)t;
	return i > t ? i - 1.0 : i;
}

static double motor_limit_fraction(const struct sim_motor_cmd *cmd)
{
	return motor_clamp(cmd->torque_limit / MOTOR_RAW_FULL, 0.0, 1.0);
}

/* Wheel mode: moving speed is the PWM output ratio, bit 10 = CW; with a
 * current drive it is the torque ratio (no back-EMF term). */
static void motor_wheel(const struct sim_motor_cmd *cmd, const struct sim_motor_params *p, double stall,
                        double c_emf, double limit, struct sim_motor_drive *ln)
{
	double u = (cmd->moving_speed & MOTOR_SPEED_MASK) / MOTOR_RAW_FULL;
	double dir = (cmd->moving_speed & DXL_DIRECTION_BIT) ? -1.0 : 1.0;
	if (u > limit)
		u = limit;
	ln->duty = dir * u;
	if (p->current_drive) {
		/* a current loop holds the torque whatever the speed and supply */
		ln->a = ln->duty * p->stall_torque_12v;
		ln->c = 0.0;
		ln->cap = limit * p->stall_torque_12v;
		return;
	}
	ln->a = ln->duty * stall;
	ln->c = c_emf;
}

/* Compliance curve: no drive inside the margin, then punch ramping to full
 * over the slope; capped by the torque limit. Positive error = present is
 * CW of the goal (drives CCW), which is where the CW margin/slope apply. */
static double motor_compliance(const struct sim_motor_cmd *cmd, double error, double limit)
{
	bool cw_side = error > 0;
	double margin = cw_side ? cmd->cw_margin : cmd->ccw_margin;
	double slope = motor_slope_units(cw_side ? cmd->cw_slope : cmd->ccw_slope);
	double mag = fabs(error);
	if (mag <= margin)
		return 0;
	double punch = motor_clamp(cmd->punch / MOTOR_RAW_FULL, 0.0, 1.0);
	double ramp = (mag - margin) / slope;
	double u = punch + (1.0 - punch) * (ramp < 1.0 ? ramp : 1.0);
	return u < limit ? u : limit;
}

/* Joint mode, moving speed: the firmware moves its own target (the setpoint)
 * towards the goal at the moving speed and runs the compliance controller on
 * the setpoint, so a free joint follows at that speed while a blocked one still
 * builds up the full error and torque. 0 = maximum: the goal at once. */
static double motor_setpoint(struct sim_motor *m, const struct sim_motor_cmd *cmd, double dt)
{
	double lo = cmd->cw_limit <= cmd->ccw_limit ? cmd->cw_limit : 0;
	double hi = cmd->cw_limit <= cmd->ccw_limit ? cmd->ccw_limit : DXL_POS_MAX;
	double goal = motor_clamp(cmd->goal_position, lo, hi);
	unsigned ms = cmd->moving_speed & MOTOR_SPEED_MASK;
	if (ms == 0 || !isfinite(m->setpoint)) {
		m->setpoint = goal;
		return goal;
	}
	double step = ms * DXL_SPEED_RAD_S_PER_UNIT * motor_units_per_rad * dt;
	m->setpoint = motor_clamp(goal, m->setpoint - step, m->setpoint + step);
	return m->setpoint;
}

static void motor_joint(struct sim_motor *m, const struct sim_motor_cmd *cmd, double stall,
                        double c_emf, double limit, double dt, struct sim_motor_drive *ln)
{
	/* The firmware sees its own 10-bit position reading: the error moves in
	 * whole units, so margin 0 still leaves ±0.5 unit without drive (no punch
	 * chatter at the goal), and a loaded joint settles to within a unit. */
	double present = motor_round(m->angle * motor_units_per_rad + DXL_POS_CENTER);
	double error = motor_setpoint(m, cmd, dt) - present;
	double s = error > 0 ? 1.0 : -1.0;
	double u = motor_compliance(cmd, error, limit);
	ln->duty = s * u;
	ln->a = ln->duty * stall;
	ln->c = c_emf;
}

static void motor_line_for(struct sim_motor *m, const struct sim_motor_params *p,
                           const struct sim_motor_cmd *cmd, double dt, struct sim_motor_drive *ln)
{
	double stall = sim_motor_stall_torque(p);
	double w0 = sim_motor_no_load_speed(p);
	ln->a = ln->c = ln->cap = ln->duty = 0;
	bool wheel = cmd->cw_limit == 0 && cmd->ccw_limit == 0;
	if (!cmd->torque_enable || wheel || !(stall > 0) || !(w0 > 0)) {
		/* no profile running: it starts from where the joint is */
		m->setpoint = m->angle * motor_units_per_rad + DXL_POS_CENTER;
		if (!cmd->torque_enable || !(stall > 0) || !(w0 > 0))
			return;
	}
	/* Back-EMF damping tau_stall / w0 does not depend on the supply voltage. */
	double c_emf = p->stall_torque_12v / p->no_load_speed_12v;
	double limit = motor_limit_fraction(cmd);
	ln->cap = limit * stall;
	if (wheel)
		motor_wheel(cmd, p, stall, c_emf, limit, ln);
	else
		motor_joint(m, cmd, stall, c_emf, limit, dt, ln);
}

/* End-of-step speed of I dw = dt (drive - c w - coulomb sgn w), with the
 * Coulomb term as a stick/slip projection (no chatter around w = 0).
 * The linear term is explicit (taken at the start speed) while dt·c/I is
 * small: then a joint held by contact gets exactly drive·dt per step, so the
 * contact impulses add up to the motor's torque. Past that it is implicit,
 * stable for any dt. */
#define MOTOR_EXPLICIT_MAX 0.5
static double motor_solve(double inertia, double w, double drive, double c,
                          double coulomb, double dt)
{
	bool implicit = dt * c > MOTOR_EXPLICIT_MAX * inertia;
	double impulse = inertia * w + dt * (implicit ? drive : drive - c * w);
	double stick = dt * coulomb;
	if (fabs(impulse) <= stick)
		return 0;
	impulse -= impulse > 0 ? stick : -stick;
	return impulse / (implicit ? inertia + dt * c : inertia);
}

/* Non-finite state (a caller bug or a bad scenario) is repaired, counted. */
static bool motor_sane(struct sim_motor *m, const struct sim_motor_params *p,
                       double *ext_torque, double dt)
{
	if (!(dt > 0) || !isfinite(dt)) {
		m->bad_input++;
		return false;
	}
	if (!isfinite(*ext_torque)) {
		*ext_torque = 0;
		m->bad_input++;
	}
	if (!isfinite(m->angle) || !isfinite(m->speed)) {
		m->angle = isfinite(m->angle) ? m->angle : 0;
		m->speed = 0;
		m->bad_input++;
	}
	if (!isfinite(m->temperature)) {
		m->temperature = p->ambient_c;
		m->bad_input++;
	}
	return true;
}

static void motor_heat(struct sim_motor *m, const struct sim_motor_params *p, double dt)
{
	/* Copper loss goes with current², i.e. with torque² whatever the supply. */
	double rel = p->stall_torque_12v > 0 ? m->motor_torque / p->stall_torque_12v : 0;
	double dT = p->heat_gain * rel * rel;
	if (p->thermal_tau_s > 0)
		dT -= (m->temperature - p->ambient_c) / p->thermal_tau_s;
	m->temperature += dt * dT;
}

/* One step under the line ln (state and dt already checked). */
static void motor_integrate(struct sim_motor *m, const struct sim_motor_params *p,
                            const struct sim_motor_drive *d, double ext_torque, double dt)
{
	struct sim_motor_drive ln = *d;
	double viscous = p->viscous, coulomb = p->coulomb;
	if (!(ln.cap > 0)) {
		/* no drive at all (torque off, torque limit 0 after an alarm, no
		 * supply): the joint back-drives the gearbox */
		viscous += p->backdrive_viscous;
		coulomb += p->backdrive_coulomb;
	}
	double inertia = p->inertia > 0 ? p->inertia : 1e-6;
	/* The torque is reported at the speed the step started from: when contact
	 * holds the joint (the world stops it after every step) that is the torque
	 * pressing on the obstacle. */
	double tau = ln.a - ln.c * m->speed;
	double w;
	if (fabs(tau) > ln.cap) {
		/* Current limit: the torque is a constant over the step. */
		tau = tau > 0 ? ln.cap : -ln.cap;
		w = motor_solve(inertia, m->speed, tau + ext_torque, viscous, coulomb, dt);
	} else {
		w = motor_solve(inertia, m->speed, ln.a + ext_torque, ln.c + viscous, coulomb, dt);
	}
	m->speed = w;
	m->angle += w * dt;
	m->motor_torque = tau;
	m->ext_torque = ext_torque;
	m->drive = ln.duty;
	motor_heat(m, p, dt);
}

void sim_motor_step(struct sim_motor *m, const struct sim_motor_params *p,
                    const struct sim_motor_cmd *cmd, double ext_torque, double dt)
{
	if (!motor_sane(m, p, &ext_torque, dt))
		return;
	struct sim_motor_drive ln;
	motor_line_for(m, p, cmd, dt, &ln);
	motor_integrate(m, p, &ln, ext_torque, dt);
}

void sim_motor_drive_for(struct sim_motor *m, const struct sim_motor_params *p, const struct sim_motor_cmd *cmd,
                         double dt, struct sim_motor_drive *d)
{
	double none = 0;
	if (!motor_sane(m, p, &none, dt)) {
		*d = (struct sim_motor_drive){ 0, 0, 0, 0 };
		return;
	}
	motor_line_for(m, p, cmd, dt, d);
}

double sim_motor_rotor_inertia(const struct sim_motor_params *p)
{
	double r = p->inertia - sim_motor_link_inertia();
	return isfinite(r) && r > 0 ? r : 0;
}

void sim_motor_loss(const struct sim_motor_params *p, const struct sim_motor_drive *d, double *viscous,
                    double *coulomb)
{
	bool driven = d->cap > 0;
	*viscous = driven ? 0 : p->backdrive_viscous;
	*coulomb = driven ? 0 : p->backdrive_coulomb;
}

void sim_motor_moved(struct sim_motor *m, const struct sim_motor_params *p, const struct sim_motor_drive *d,
                     double angle, double speed, double motor_torque, double dt)
{
	if (!isfinite(angle) || !isfinite(speed) || !isfinite(motor_torque)) {
		m->bad_input++;
		return;
	}
	m->angle = angle;
	m->speed = speed;
	m->motor_torque = motor_torque;
	m->ext_torque = 0;
	m->drive = d->duty;
	if (dt > 0 && isfinite(dt))
		motor_heat(m, p, dt);
}

void sim_motor_step_drive(struct sim_motor *m, const struct sim_motor_params *p,
                          const struct sim_motor_drive *d, double ext_torque, double dt)
{
	if (!motor_sane(m, p, &ext_torque, dt))
		return;
	struct sim_motor_drive ln = *d;
	/* A controller's arithmetic on a repaired state is not trusted either. */
	if (!isfinite(ln.a) || !isfinite(ln.c) || !isfinite(ln.cap) || !isfinite(ln.duty)) {
		ln = (struct sim_motor_drive){ 0, 0, 0, 0 };
		m->bad_input++;
	}
	if (ln.cap < 0)
		ln.cap = 0;
	motor_integrate(m, p, &ln, ext_torque, dt);
}

double sim_motor_load_fraction(const struct sim_motor *m, const struct sim_motor_params *p)
{
	double stall = sim_motor_stall_torque(p);
	if (!(stall > 0))
		return 0;
	return motor_clamp(m->motor_torque / stall, -1.0, 1.0);
}

bool sim_motor_overloaded(const struct sim_motor *m, const struct sim_motor_params *p,
                          const struct sim_motor_cmd *cmd)
{
	if (!cmd->torque_enable)
		return false;
	double cap = motor_limit_fraction(cmd) * sim_motor_stall_torque(p);
	return cap > 0 && fabs(m->motor_torque) >= MOTOR_LIMIT_TOL * cap;
}
