/*
 * torque.c — torque actuation: OSCILLATOR drives the law's torque itself
 * through the servo's wheel mode (the paper's torque-controlled pair rig;
 * CONTROL.md), on the AX-12's PWM drive (back-EMF added back) or on a
 * current-controlled drive; so does SINUSOID given a [sinusoid] stiffness
 * (the clock as a torque law, as the paper's force simulations drove their
 * joints). Part of the controller (control_priv.h).
 *
 * The servos go into wheel mode only for a running OSCILLATOR or such a
 * SINUSOID whose joints are all healthy, torqued and measured; everything
 * else (the oscillator's starter, HOLD, SINUSOID without a stiffness, faults,
 * LIMP) runs in joint mode, where the servo itself holds positions and
 * enforces its angle limits. Between the two driving modes the servos stay
 * in the drive: only the law changes, at the cycle boundary.
 *
 * X series: "wheel mode" is the drive's Operating Mode — current control (0)
 * on the XM430, PWM control (16) — and joint mode position control (3).
 * Operating Mode is EEPROM, written only with torque off, and a new mode puts
 * Goal PWM at PWM Limit (e-manual): each switch is one chain of writes
 * (writeq.h) per servo, so that a step given up stops it there —
 *   into the drive:  torque off, the mode, the drive register 0, torque on;
 *   back:            torque off, position control, Goal Position where the
 *                    joint is (inside its limits), Goal PWM at its limit,
 *                    the watchdog, torque on.
 * A joint's drive is written only once its switch is acknowledged to the
 * last step (drive_ready): a servo still in position control would take a
 * PWM duty as its output limit. A switch that stops half-way leaves the
 * servo with torque off (never torque on in a mode that was not set, never
 * a drive outside the limits); the robot goes back to joint mode, and a
 * switch that keeps failing counts as a reset (fault_retries, then latched).
 */
#include <math.h>
#include <stdio.h>

#include "control_priv.h"

/* A virtual spring pushes a joint back from TQ_WALL_MARGIN inside either
 * limit, reaching the stall torque at the limit itself, with TQ_WALL_DAMPING
 * against moving outwards; past the limit the robot falls back to
 * fault_action in joint mode, where the servo enforces its limits. */
#define TQ_WALL_MARGIN 0.15
#define TQ_WALL_DAMPING 0.1
double tq_stall_torque(const struct ctl *c, const struct ctl_joint *jt)
{
	const struct sm_model *m = jt->servo.model != NULL ? jt->servo.model : sm_ax12();
	/* the configuration's unless given is the AX-12A's datasheet: the model's */
	return c->cfg->stall_torque_given ? c->cfg->stall_torque : m->stall_torque_nm;
}

double tq_no_load_speed(const struct ctl *c, const struct ctl_joint *jt)
{
	const struct sm_model *m = jt->servo.model != NULL ? jt->servo.model : sm_ax12();
	return c->cfg->no_load_speed_given ? c->cfg->no_load_speed : m->no_load_speed_rad_s;
}

bool tq_mode_drives(const struct ctl *c, enum cfg_mode mode)
{
	if (c->cfg->actuation != CFG_ACT_TORQUE)
		return false;
	return mode == CFG_MODE_OSCILLATOR || (mode == CFG_MODE_SINUSOID && c->p.sin_stiffness > 0.0);
}

bool tq_want_wheel(const struct ctl *c)
{
	if (!tq_mode_drives(c, c->mode) || c->starter_active || c->latched)
		return false;
	for (size_t j = 0; j < c->n; j++) {
		const struct ctl_joint *jt = &c->j[j];
		if (jt->fault != CTL_FAULT_NONE || !jt->torque || !jt->have_reading || jt->limits.max_step <= 0.0)
			return false;
	}
	return true;
}

bool tq_check_limits(struct ctl *c, char *what, size_t cap)
{
	if (!c->wheel)
		return false;
	for (size_t j = 0; j < c->n; j++) {
		const struct ctl_joint *jt = &c->j[j];
		if (!jt->fresh || (jt->angle >= jt->limits.lo && jt->angle <= jt->limits.hi))
			continue;
		c->limit_trips++;
		double neutral = c->cfg->joint[j].neutral;
		snprintf(what, cap, "servo %u at %+.3f rad left its limits [%+.3f, %+.3f] under torque actuation",
		         jt->id, jt->angle - neutral, jt->limits.lo - neutral, jt->limits.hi - neutral);
		ctl_event(c, 2, "limit", "%s: robot %s in joint mode", what,
		          cfg_mode_name(c->cfg->fault_action == CFG_SAFE_LIMP ? CFG_MODE_LIMP : CFG_MODE_HOLD));
		/* HOLD where it is: the safety clamp puts the goal inside the limits */
		return true;
	}
	return false;
}

bool tq_check_supply(struct ctl *c, char *what, size_t cap)
{
	const struct cfg *cfg = c->cfg;
	if (cfg->torque_drive != CFG_DRIVE_PWM || !tq_mode_drives(c, c->mode))
		return false;
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		const struct sm_model *m = ctl_model(c, j);
		/* NaN: not read yet (the drive assumes the reference supply) */
		if (!isfinite(jt->voltage) || sm_supply_plausible(m, jt->voltage))
			continue;
		double lo, hi;
		sm_supply_range(m, &lo, &hi);
		jt->faults++;
		c->faults++;
		snprintf(what, cap, "servo %u reads its supply as %.1f V, outside the %s's %.2f..%.2f V", jt->id,
		         jt->voltage, m->name, lo, hi);
		/* within CTL_EVENT_TEXT for the longest model name and reading */
		ctl_event(c, 2, "supply", "%s (rated %.1f..%.1f V): not a gain for the PWM drive; robot %s in joint mode",
		          what, m->rated_min_v, m->rated_max_v,
		          cfg_mode_name(cfg->fault_action == CFG_SAFE_LIMP ? CFG_MODE_LIMP : CFG_MODE_HOLD));
		return true;
	}
	return false;
}

/* The virtual spring near a limit (N·m), on top of the law's torque. */
static double tq_wall(const struct ctl_joint *jt, double stall)
{
	double k = stall / TQ_WALL_MARGIN;
	double over_hi = jt->angle - (jt->limits.hi - TQ_WALL_MARGIN);
	double over_lo = (jt->limits.lo + TQ_WALL_MARGIN) - jt->angle;
	if (over_hi > 0.0)
		return -k * over_hi - TQ_WALL_DAMPING * fmax(jt->speed, 0.0);
	if (over_lo > 0.0)
		return k * over_lo - TQ_WALL_DAMPING * fmin(jt->speed, 0.0);
	return 0.0;
}

/* Output ratio that makes the drive deliver `tau` at speed v: a PWM drive
 * loses tau_stall(V)/w0(V) per rad/s to back-EMF (voltage-independent), so
 * that is added back; a current drive delivers duty × stall torque. Capped by
 * the servo's max torque, as the torque limit caps it in the servo. */
static double tq_duty(const struct ctl *c, const struct ctl_joint *jt, double tau)
{
	const struct cfg *cfg = c->cfg;
	const struct sm_model *m = jt->servo.model != NULL ? jt->servo.model : sm_ax12();
	/* the supply assumed until the servo's voltage is read: the datasheet's
	 * reference, which the stall torque and no-load speed are given at */
	double ref = m->ref_voltage;
	/* the AX-12's torque limit and the X's PWM Limit cap the output; an XM430
	 * keeps its current within Current Limit by itself (sm_drive_raw) */
	double cap = m->current_control && cfg->torque_drive == CFG_DRIVE_CURRENT ? 1.0
	           : jt->servo.max_torque / (double)m->torque_full;
	double u;
	if (cfg->torque_drive == CFG_DRIVE_CURRENT) {
		u = tau / tq_stall_torque(c, jt);
	} else {
		/* the supply read, never beyond what the servo can run at: a reading
		 * outside latches first (tq_check_supply), and is no gain here */
		double lo, hi;
		sm_supply_range(m, &lo, &hi);
		double volts = isfinite(jt->voltage) ? fmin(fmax(jt->voltage, lo), hi) : ref;
		double stall = tq_stall_torque(c, jt) * volts / ref;
		double w0 = tq_no_load_speed(c, jt) * volts / ref;
		u = tau / stall + jt->speed / w0;
	}
	return isfinite(u) ? fmax(-cap, fmin(cap, u)) : 0.0;
}

/* A joint that would be within TQ_WALL_MARGIN of a limit TQ_GUARD_S from
 * now, moving out, is never driven outwards, whatever the law or a belief
 * about the servo (its supply, its stall torque, its no-load speed) asks:
 * with no drive the servo's own back-EMF brakes it (an AX-12A joint at full
 * speed stops within ~0.11 rad: I·w0/stall = 18 ms), and the wall's push
 * harder. TQ_GUARD_S covers what passes before the brake acts: the duty
 * already sent holds until the next cycle's SYNC_WRITE (one period and its
 * bus time), and the speed is filtered (20 Hz, ~8 ms behind). */
#define TQ_GUARD_S 0.03
/* ... for a cycle on time. On a loaded computer the next cycle may come
 * late, and the duty sent holds until it does: the look-ahead grows by
 * the lateness measured lately (the period measured less the configured
 * one, the largest of the last second or so, decaying). Measured:
 * cycles 50 ms apart took a joint driven 1.4x harder than the law meant
 * (its supply read as 8.6 V at 12 V) 27 mrad past a 0.6 rad limit with the
 * fixed 30 ms (test_daemon_torque); real time under load once 9 mrad
 * (daemon_torque). In lockstep every cycle is on time: nothing changes. */
#define TQ_LATE_MEMORY_S 1.0
/* A cycle later than this is not load but a pause (a reconnect, a stopped
 * process): the joints were stale meanwhile, and a look-ahead of seconds
 * would hold every gait off its limits for as long. */
#define TQ_LATE_MAX_S 0.1
static void tq_note_lateness(struct ctl *c, double dt)
{
	double late = fmin(dt - c->cfg->period_ms / 1000.0, TQ_LATE_MAX_S);
	double kept = c->late_s * exp(-fmax(dt, 0.0) / TQ_LATE_MEMORY_S);
	c->late_s = isfinite(late) && late > kept ? late : kept;
}

static double tq_no_outward(const struct ctl_joint *jt, double u, double horizon_s)
{
	double ahead = jt->angle + jt->speed * horizon_s;
	if (jt->speed > 0.0 && ahead > jt->limits.hi - TQ_WALL_MARGIN)
		return fmin(u, 0.0);
	if (jt->speed < 0.0 && ahead < jt->limits.lo + TQ_WALL_MARGIN)
		return fmax(u, 0.0);
	return u;
}

/* The mode's law at the measured state: the oscillator's, or the clock's at
 * the SINUSOID's shared time t_real. */
static bool tq_law(const struct ctl *c, double t_real, const double *x, const double *v, double *tau)
{
	const struct cfg_params *p = &c->p;
	if (c->mode == CFG_MODE_SINUSOID) {
		const struct osc_clock k = { .amplitude = p->amplitude, .frequency = p->frequency,
		                             .phase = p->phase, .stiffness = p->sin_stiffness,
		                             .damping = p->sin_damping };
		return osc_clock_torque(&k, c->n, t_real, x, v, tau);
	}
	return osc_torque(p->osc, c->n, x, v, tau);
}

void tq_duties(struct ctl *c, double dt, double t_real)
{
	tq_note_lateness(c, dt);
	const double horizon = TQ_GUARD_S + c->late_s;
	double x[CFG_MAX_JOINTS], v[CFG_MAX_JOINTS], tau[CFG_MAX_JOINTS];
	for (size_t j = 0; j < c->n; j++) {
		x[j] = c->j[j].angle - c->cfg->joint[j].neutral;
		v[j] = c->j[j].fresh ? c->j[j].speed : 0.0;
	}
	if (!tq_law(c, t_real, x, v, tau))
		c->nonfinite++;
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		jt->write_goal = false;
		jt->clamp_flags = 0;
		jt->goal = NAN;
		if (!jt->fresh) {
			/* no reading, no law: the joint coasts until it answers again */
			jt->torque_cmd = 0.0;
			jt->duty = 0.0;
			continue;
		}
		double wall = tq_wall(jt, tq_stall_torque(c, jt));
		if (wall != 0.0) {
			jt->clamp_flags = SAFETY_LIMIT;
			c->clamps++;
		}
		jt->torque_cmd = tau[j] + wall;
		jt->duty = tq_no_outward(jt, tq_duty(c, jt, jt->torque_cmd), horizon);
	}
}

/* The angle limits are EEPROM, which the AX-12A writes only with torque off:
 * torque off, both limits in one 4-byte write (the servo never sees a
 * half-set pair), torque on again. The joint coasts for the ~1 ms this takes
 * on the bus (a real servo is then busy ~6 ms per EEPROM byte: its next
 * replies may be missed, which the loop takes as stale cycles). */
static void tq_switch_limits(struct ctl *c, size_t j, uint32_t limits, bool torque_after)
{
	uint8_t id = c->j[j].id;
	const struct sm_model *m = ctl_model(c, j);
	ctl_write_seq(c, id, m->torque_enable, 1, 0);
	ctl_write_seq(c, id, m->setup->angle_limits, 4, limits);
	if (!torque_after)
		return;
	/* Torque on the manual's way, the torque limit first: enabling torque
	 * clears a latched overload bit, so an alarm shutdown that zeroed the
	 * torque limit since the last reading would otherwise never be seen, and
	 * the joint would stay without drive. */
	ctl_write_seq(c, id, m->torque_limit, 2, ctl_torque_limit(c, &c->j[j]));
	ctl_write_seq(c, id, m->torque_enable, 1, 1);
}

/* X series: into the drive's mode, one chain per servo (above). */
static void tq_x_enter(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	bool current = c->cfg->torque_drive == CFG_DRIVE_CURRENT;
	const struct sm_model *m = ctl_model(c, j);
	uint16_t ch = wq_chain(&c->wq);
	jt->drive_ready = false;
	jt->drive_chain = ch;
	ctl_write_chain(c, ch, jt->id, m->torque_enable, 1, 0);
	ctl_write_chain(c, ch, jt->id, m->setup->opmode, 1, sm_drive_opmode(current));
	/* the new mode put Goal PWM at its limit: in PWM control a full drive */
	ctl_write_chain(c, ch, jt->id, sm_drive_register(m, current), 2, 0);
	ctl_write_chain(c, ch, jt->id, m->torque_enable, 1, 1);
}

void tq_enter_wheel(struct ctl *c)
{
	for (size_t j = 0; j < c->n; j++) {
		if (ctl_has(c, j, SM_CAP_OPMODE))
			tq_x_enter(c, j);
		else
			tq_switch_limits(c, j, 0, true);
	}
	c->wheel = true;
	ctl_event(c, 0, "actuation", "torque actuation: servos in wheel mode, the law drives their torque");
}

void tq_leave_wheel(struct ctl *c)
{
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		if (ctl_has(c, j, SM_CAP_OPMODE)) {
			jt->drive_ready = false;
			jt->drive_chain = 0;
			(void)ctl_x_setup(c, j, true);
		} else {
			tq_switch_limits(c, j, ctl_joint_mode_limits(c, j), jt->torque && c->mode != CFG_MODE_LIMP);
		}
		/* position modes start where the joint is, with no step bound from a
		 * goal it never had */
		jt->goal = NAN;
		ctl_blend_joint(c, j, jt->angle);
	}
	c->wheel = false;
	c->sync = CTL_SYNC_GOAL_STOP;
	ctl_event(c, 0, "actuation", "torque actuation: servos back in joint mode (%s)", cfg_mode_name(c->mode));
}

void tq_stop_goals(struct ctl *c)
{
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		jt->duty = NAN;
		jt->torque_cmd = NAN;
		/* X series: the SYNC_WRITE stops the drives, the chain sets the goal */
		if (jt->write_goal || !jt->have_reading || jt->limits.max_step <= 0.0 || ctl_has(c, j, SM_CAP_OPMODE))
			continue;
		jt->goal = safety_clamp(&jt->limits, jt->angle, NAN, jt->angle, NULL);
		jt->write_goal = true;
	}
}

bool tq_chain_result(struct ctl *c, size_t j, const struct wq_write *w, bool ok, char *what, size_t cap)
{
	struct ctl_joint *jt = &c->j[j];
	const struct sm_model *m = ctl_model(c, j);
	if (ok) {
		if (w->addr == m->torque_enable && w->value == 1)
			jt->drive_ready = true;
		return false;
	}
	jt->drive_ready = false;
	jt->drive_chain = 0;
	jt->resets++;
	c->resets++;
	ctl_event(c, 2, "actuation", "servo %u: the switch to %s control stopped at register %u (not acknowledged): "
	          "torque actuation ends, servos back in position control (reset %lld of %d)", jt->id,
	          c->cfg->torque_drive == CFG_DRIVE_CURRENT ? "current" : "PWM", w->addr, jt->resets,
	          c->cfg->fault_retries);
	if (jt->resets <= c->cfg->fault_retries)
		return false;
	snprintf(what, cap, "servo %u: its switch to torque actuation failed %lld times", jt->id, jt->resets);
	return true;
}
