/*
 * control_core.c — what both files of the controller call (control_priv.h):
 * its events, its writes into the write queue, a joint's model, output
 * limit and goal register, the blend's start, and the set-up chain of a
 * servo switched by Operating Mode. control.c (modes, faults, read-back,
 * the position laws) and torque.c (torque actuation) call these; these call
 * neither, so the controller's files call each other one way only
 * (control.c -> torque.c -> control_core.c).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "control_priv.h"

/* ---- events and writes ------------------------------------------------------------------ */
void ctl_event(struct ctl *c, int level, const char *kind, const char *fmt, ...)
{
	if (c->nevents >= CTL_MAX_EVENTS) {
		c->events_dropped++;
		return;
	}
	struct ctl_event *e = &c->events[c->nevents++];
	e->level = level;
	snprintf(e->kind, sizeof e->kind, "%s", kind);
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(e->text, sizeof e->text, fmt, ap);
	va_end(ap);
}

bool ctl_next_event(struct ctl *c, struct ctl_event *out)
{
	if (c->nevents == 0)
		return false;
	*out = c->events[0];
	memmove(c->events, c->events + 1, (c->nevents - 1) * sizeof c->events[0]);
	c->nevents--;
	return true;
}

static void ctl_queue_full(struct ctl *c, uint8_t id, uint16_t addr)
{
	ctl_event(c, 2, "write-failed", "servo %u: register %u not written: the write queue is full (%d)", id, addr,
	          WQ_CAP);
}

void ctl_write(struct ctl *c, uint8_t id, uint16_t addr, uint8_t len, uint32_t value)
{
	if (!wq_put(&c->wq, id, addr, len, value))
		ctl_queue_full(c, id, addr);
}

void ctl_write_seq(struct ctl *c, uint8_t id, uint16_t addr, uint8_t len, uint32_t value)
{
	if (!wq_put_seq(&c->wq, id, addr, len, value))
		ctl_queue_full(c, id, addr);
}

void ctl_write_chain(struct ctl *c, uint16_t chain, uint8_t id, uint16_t addr, uint8_t len, uint32_t value)
{
	if (!wq_put_chain(&c->wq, chain, id, addr, len, value))
		ctl_queue_full(c, id, addr);
}

const struct sm_model *ctl_model(const struct ctl *c, size_t j)
{
	return j < c->n && c->j[j].servo.model != NULL ? c->j[j].servo.model : sm_ax12();
}

bool ctl_has(const struct ctl *c, size_t j, unsigned cap)
{
	return sm_has(ctl_model(c, j), cap);
}

uint16_t ctl_torque_limit(const struct ctl *c, const struct ctl_joint *jt)
{
	/* a recovery attempt (CHECK) is with the full limit back */
	if (jt->fault == CTL_FAULT_NONE || jt->fault == CTL_FAULT_CHECK)
		return jt->servo.max_torque;
	return (uint16_t)lround(c->cfg->backoff_torque * jt->servo.max_torque);
}

/* A goal's register value, rounded to the nearest step but never past the
 * limits it was clamped into: rounding to the nearest put a goal of +0.5 rad
 * against +-0.5 limits at 98 steps (+0.5015 rad) on the AX-12A, past the
 * configuration's limit by up to half a step (qa_soak: 28 of 138 goal
 * registers sampled, by up to 0.0016 rad). */
int32_t ctl_goal_pos(const struct ctl_joint *jt, const struct sm_model *m, double rad)
{
	int32_t pos = sm_rad_to_pos(m, rad);
	if (jt->limits.max_step > 0.0) {
		/* limits narrower than a step keep the nearest step: none is inside */
		if (sm_pos_to_rad(m, pos) > jt->limits.hi && pos > 0 && sm_pos_to_rad(m, pos - 1) >= jt->limits.lo)
			pos--;
		else if (sm_pos_to_rad(m, pos) < jt->limits.lo && pos < m->pos_max &&
		         sm_pos_to_rad(m, pos + 1) <= jt->limits.hi)
			pos++;
	}
	return pos;
}

uint32_t ctl_joint_mode_limits(const struct ctl *c, size_t j)
{
	return (uint32_t)c->j[j].servo.cw_limit | (uint32_t)c->j[j].servo.ccw_limit << 16;
}

void ctl_blend_joint(struct ctl *c, size_t j, double from)
{
	if (c->cfg->ramp_s <= 0.0 || !isfinite(from))
		return;
	c->blend_from[j] = from;
	c->blend_t0[j] = c->t;
}

static void ctl_x_write_limits(struct ctl *c, uint16_t ch, size_t j)
{
	const struct ctl_joint *jt = &c->j[j];
	const struct sm_model *m = ctl_model(c, j);
	ctl_write_chain(c, ch, jt->id, m->setup->pos_limit_min, 4, jt->servo.cw_limit);
	ctl_write_chain(c, ch, jt->id, m->setup->pos_limit_max, 4, jt->servo.ccw_limit);
}

uint16_t ctl_x_setup(struct ctl *c, size_t j, bool with_mode)
{
	struct ctl_joint *jt = &c->j[j];
	const struct sm_model *m = ctl_model(c, j);
	uint16_t ch = wq_chain(&c->wq);
	if (with_mode) {
		/* Operating Mode and the limits are EEPROM: torque off first */
		ctl_write_chain(c, ch, jt->id, m->torque_enable, 1, 0);
		ctl_write_chain(c, ch, jt->id, m->setup->opmode, 1, SM_OPMODE_POSITION);
		if (jt->limits_wrong)
			ctl_x_write_limits(c, ch, j);
		jt->limits_wrong = false;
	}
	/* after a watchdog stop the goals are read-only until it is 0 again */
	if (jt->watchdog_cleared)
		ctl_write_chain(c, ch, jt->id, m->setup->watchdog, 1, 0);
	jt->watchdog_cleared = false;
	/* a goal where the joint is, inside the limits: the servo's goal may be
	 * anything (a boot's, a drive mode's) */
	if (jt->have_reading && jt->limits.max_step > 0.0) {
		double hold = safety_clamp(&jt->limits, jt->angle, NAN, jt->angle, NULL);
		ctl_write_chain(c, ch, jt->id, m->goal, m->goal_size, (uint32_t)ctl_goal_pos(jt, m, hold));
	}
	if (c->cfg->bus_watchdog_ms >= 0)
		ctl_write_chain(c, ch, jt->id, m->setup->watchdog, 1, cfg_watchdog_units(c->cfg));
	ctl_write_chain(c, ch, jt->id, m->torque_limit, 2, ctl_torque_limit(c, jt));
	if (jt->torque && c->mode != CFG_MODE_LIMP)
		ctl_write_chain(c, ch, jt->id, m->torque_enable, 1, 1);
	return ch;
}
