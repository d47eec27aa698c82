/* control.c — see control.h. Torque actuation is in torque.c. */
#include "control.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "control_priv.h"
#include "dxl.h"
#include "dxl2.h"
#include "dxl_table.h"

/* After a recovery write, watch the error bits this long before calling it a
 * success: the servo needs a few control interrupts to load again. */
#define CTL_FAULT_CHECK_S 0.3
/* RK4 sub-steps per control period: the oscillator's fastest time scale is
 * ~1 s, so 4 steps of 2.5 ms are far inside RK4's accuracy. */
#define CTL_OSC_SUBSTEPS 4
/* Starting from rest: a position servo quantizes angles to 5 mrad, so from
 * rest the oscillator's first predicted steps round to the present angle and
 * the robot stays still (CONTROL.md). So OSCILLATOR starts the way the paper
 * switched: the baseline sinusoid ([sinusoid] amplitude and frequency) drives
 * the joints for ramp_s plus one period, then the oscillator takes over from
 * the measured, moving state. A joint counts as still below CTL_REST_V; an
 * oscillator with a joint still for CTL_STALL_S (far longer than a turning
 * point of a running gait; a time, not a count of cycles, so that it means the
 * same at every period_ms) is started again the same way. */
#define CTL_REST_V 0.1
/* A joint back after this many stale cycles is blended in again (its goal was
 * held while the mode's target moved on). */
#define CTL_RESUME_STALE 3
#define CTL_STALL_S 1.0

static size_t ctl_joint_of(const struct ctl *c, uint8_t id)
{
	size_t j = 0;
	while (j < c->n && c->j[j].id != id)
		j++;
	return j;
}

/* X series under torque actuation on the PWM drive: Goal PWM is the drive
 * itself, not a limit, and only the SYNC_WRITE sets it. */
static bool ctl_limit_is_drive(const struct ctl *c, size_t j)
{
	return sm_limit_is_pwm_drive(ctl_model(c, j)) && c->wheel && c->cfg->torque_drive == CFG_DRIVE_PWM;
}

/* The joint's output limit as ctl_torque_limit() has it, in its model's
 * register (AX-12 Torque Limit 34, X Goal PWM 100: never another model's
 * address), except where Goal PWM is the drive itself. */
static void ctl_limit_write(struct ctl *c, size_t j)
{
	const struct ctl_joint *jt = &c->j[j];
	if (!ctl_limit_is_drive(c, j))
		ctl_write(c, jt->id, ctl_model(c, j)->torque_limit, 2, ctl_torque_limit(c, jt));
}

static void ctl_torque_write(struct ctl *c, size_t j, bool on)
{
	struct ctl_joint *jt = &c->j[j];
	const struct sm_model *m = ctl_model(c, j);
	if (on) {
		/* The manual's recovery: the torque limit back (an alarm shutdown set
		 * it to 0), then torque enable. Harmless when nothing was wrong. */
		ctl_limit_write(c, j);
		ctl_write(c, jt->id, m->torque_enable, 1, 1);
	} else {
		ctl_write(c, jt->id, m->torque_enable, 1, 0);
	}
	jt->torque = on;
}

const struct wq_write *ctl_take_write(struct ctl *c)
{
	return wq_take(&c->wq);
}

const struct wq_write *ctl_next_write(const struct ctl *c)
{
	return wq_peek(&c->wq);
}

static const char *ctl_register_name(const struct sm_model *m, const struct wq_write *w)
{
	return w->len == 0 ? "REBOOT" : sm_register_name(m, w->addr);
}

static void ctl_fault_persistent(struct ctl *c, size_t j, const char *what, const char *after);

/* A REBOOT or a write of a chain (SM_CAP_HWERR, SM_CAP_OPMODE): what its
 * acknowledgement, or its giving up, means to the joint. */
static void ctl_chain_write_done(struct ctl *c, size_t j, const struct wq_write *w, bool ok)
{
	struct ctl_joint *jt = &c->j[j];
	if (w->len == 0) {
		if (!ok) {
			ctl_fault_persistent(c, j, "shutdown", "with its REBOOT unanswered");
			return;
		}
		/* the boot clears the hardware errors and the watchdog, turns the
		 * torque off: what the read-back would now say */
		jt->reboot_at = c->t;
		jt->hwerr = 0;
		jt->torque_read = 0;
		jt->watchdog_read = 0;
		jt->watchdog_cleared = false;
		return;
	}
	if (w->chain != 0 && w->chain == jt->drive_chain) {
		char what[CTL_LATCH_TEXT];
		if (tq_chain_result(c, j, w, ok, what, sizeof what))
			ctl_latch(c, what);
		/* a switch given up half-way: back to joint mode */
		if (!ok && c->wheel)
			tq_leave_wheel(c);
		return;
	}
	if (!ok && w->chain != 0) {
		ctl_event(c, 2, "write-failed", "servo %u: set-up stopped at %s: the writes after it were not sent; "
		          "the read-back will find what the servo holds", jt->id, ctl_register_name(ctl_model(c, j), w));
		jt->readback_due = true;
	}
}

void ctl_write_result(struct ctl *c, bool ok)
{
	struct wq_write w = { 0 };
	enum wq_outcome o = wq_done(&c->wq, ok, &w);
	size_t j = ctl_joint_of(c, w.id);
	/* a REBOOT or a chain's write: what its acknowledgement means to the joint */
	if (w.tries > 0 && j < c->n && (w.len == 0 || w.chain != 0) && (o == WQ_FAILED || (o == WQ_DONE && ok)))
		ctl_chain_write_done(c, j, &w, o == WQ_DONE);
	if (o != WQ_FAILED)
		return;
	c->write_failures++;
	ctl_event(c, 2, "write-failed", "servo %u: %s (%u) = %u not acknowledged after %d sends: given up; "
	          "the read-back will tell what the servo holds", w.id, ctl_register_name(ctl_model(c, j), &w), w.addr,
	          (unsigned)w.value, WQ_TRIES);
}

static void ctl_put_le(uint8_t *p, uint32_t v, uint8_t width)
{
	for (uint8_t i = 0; i < width; i++)
		p[i] = (uint8_t)(v >> (8 * i));
}

/* Torque actuation's outputs (or, X series leaving it, 0 for every drive). On
 * the X series only joints whose drive switch went through: a servo still in
 * position control would take Goal PWM as its limit. */
static size_t ctl_sync_drive(const struct ctl *c, uint16_t *addr, uint8_t *width, uint8_t *ids, uint8_t *data)
{
	bool current = c->cfg->torque_drive == CFG_DRIVE_CURRENT, x = ctl_has(c, 0, SM_CAP_OPMODE);
	size_t n = 0;
	*addr = sm_drive_register(ctl_model(c, 0), current);
	*width = 2;
	for (size_t j = 0; j < c->n; j++) {
		const struct ctl_joint *jt = &c->j[j];
		if (x && c->sync == CTL_SYNC_DUTY && !jt->drive_ready)
			continue;
		double ratio = c->sync == CTL_SYNC_DUTY ? jt->duty : 0.0;
		int32_t limit = current ? jt->servo.current_limit : jt->servo.max_torque;
		ids[n] = jt->id;
		/* the conversion keeps the servo's limits and turns a non-finite duty into 0 */
		dxl_put_u16(&data[2 * n], sm_drive_raw(ctl_model(c, j), current, ratio, limit));
		n++;
	}
	return n;
}

size_t ctl_sync(const struct ctl *c, uint16_t *addr, uint8_t *width, uint8_t *ids, uint8_t *data)
{
	size_t n = 0;
	const struct sm_model *m = ctl_model(c, 0);
	if (c->sync == CTL_SYNC_DUTY || (sm_has(m, SM_CAP_OPMODE) && c->sync == CTL_SYNC_GOAL_STOP))
		return ctl_sync_drive(c, addr, width, ids, data);
	*width = c->sync == CTL_SYNC_GOAL_STOP ? 4 : m->goal_size;
	*addr = m->goal;
	for (size_t j = 0; j < c->n; j++) {
		const struct ctl_joint *jt = &c->j[j];
		/* safety_clamp() made goal finite and inside the limits; the
		 * conversion clamps to the servo's range as a last line */
		if (!jt->write_goal || !isfinite(jt->goal))
			continue;
		ids[n] = jt->id;
		ctl_put_le(&data[*width * n], (uint32_t)ctl_goal_pos(jt, ctl_model(c, j), jt->goal), m->goal_size);
		/* the AX-12's stop: Moving Speed 0 after the goal, joint mode's "fastest" */
		if (*width > m->goal_size)
			memset(&data[*width * n + m->goal_size], 0, (size_t)(*width - m->goal_size));
		n++;
	}
	return n;
}

/* ---- set-up --------------------------------------------------------------------------------- */
void ctl_init(struct ctl *c, const struct cfg *cfg)
{
	memset(c, 0, sizeof *c);
	c->cfg = cfg;
	cfg_params_init(&c->p, cfg);
	c->n = cfg->njoints;
	c->mode = cfg->mode;
	c->fade_mode = CFG_NMODES;
	wq_init(&c->wq);
	snprintf(c->reason, sizeof c->reason, "start");
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		jt->id = cfg->ids[j];
		jt->goal = NAN;
		jt->angle = NAN;
		jt->phase = NAN;            /* unknown until the first reading (phase.h) */
		jt->speed = 0.0;
		jt->voltage = NAN;
		jt->temperature = NAN;
		jt->duty = NAN;
		jt->torque_cmd = NAN;
		jt->torque_read = -1;
		jt->torque_limit_read = -1;
		jt->hwerr = jt->watchdog_read = jt->opmode_read = -1;
		jt->hwerr_at = -INFINITY;
		jt->reboot_at = -INFINITY;
		jt->servo.max_torque = 1023;
		osc_velocity_filter_init(&jt->vfilter, cfg->velocity_cutoff_hz);
		phase_estimator_init(&jt->estimator);
		c->hold[j] = NAN;
		c->blend_from[j] = NAN;
	}
}

bool ctl_set_servo(struct ctl *c, size_t j, const struct ctl_servo_info *info, char *why, size_t cap)
{
	struct ctl_joint *jt = &c->j[j];
	const struct cfg_joint *cj = &c->cfg->joint[j];
	const struct sm_model *m = info->model != NULL ? info->model : sm_ax12();
	jt->servo = *info;
	jt->servo.model = m;
	if (!sm_has(m, SM_CAP_OPMODE) && dxl_is_wheel_mode(info->cw_limit, info->ccw_limit)) {
		snprintf(why, cap, "servo %u is in wheel mode (both angle limits 0): set its angle limits "
		         "(dxl --port PATH write %u ccw_angle_limit 1023)", jt->id, jt->id);
		return false;
	}
	double lo = sm_pos_to_rad(m, info->cw_limit), hi = sm_pos_to_rad(m, info->ccw_limit);
	if (info->cw_limit > info->ccw_limit ||
	    !safety_limits_make_rad(&jt->limits, cj->neutral, cj->limit_min, cj->limit_max, lo, hi, cj->max_step)) {
		snprintf(why, cap, "joint %zu (servo %u): configured limits neutral %+.3f + [%.3f, %.3f] rad and the "
		         "servo's %s limits %u..%u (%.3f..%.3f rad) have no angle in common", j, jt->id,
		         cj->neutral, cj->limit_min, cj->limit_max, m->limits_name, info->cw_limit,
		         info->ccw_limit, lo, hi);
		return false;
	}
	return true;
}

bool ctl_torque_defaults(struct ctl *c, size_t j, double scale)
{
	if (c->defaults_done[j] & CTL_DEFAULTS_TORQUE)
		return false;
	c->defaults_done[j] |= CTL_DEFAULTS_TORQUE;
	cfg_params_scale_torque_defaults(&c->p, c->cfg, j, scale);
	return c->cfg->joint[j].torque_defaults != 0;
}

bool ctl_position_defaults(struct ctl *c, size_t j, double k, double mu)
{
	if (c->defaults_done[j] & CTL_DEFAULTS_POSITION)
		return false;
	c->defaults_done[j] |= CTL_DEFAULTS_POSITION;
	return cfg_params_position_defaults(&c->p, c->cfg, j, k, mu);
}

static void ctl_blend_stop(struct ctl *c)
{
	for (size_t j = 0; j < c->n; j++)
		c->blend_from[j] = NAN;
}

/* Still: every joint below CTL_REST_V for CTL_STILL_CYCLES cycles in a row.
 * One reading would call a swinging robot still at its turning points, where
 * the quantized position stands for tens of milliseconds: a mode switch landing
 * there restarted it with the starter (seen: one robot of a pair on the clock
 * for 2.7 s while the other ran the oscillator, which scrambled their phase
 * difference). 0.25 s is far longer than a turning point, far shorter than a
 * stop anyone would switch modes after. */
#define CTL_STILL_CYCLES 25
static bool ctl_is_still(const struct ctl *c)
{
	return c->still_cycles >= CTL_STILL_CYCLES;
}

static void ctl_count_still(struct ctl *c)
{
	bool still = true;
	for (size_t j = 0; j < c->n; j++)
		still = still && c->j[j].fresh && fabs(c->j[j].speed) < CTL_REST_V;
	c->still_cycles = still ? c->still_cycles + 1 : 0;
}

/* A single joint at rest is enough to call the oscillator stalled: a contact
 * joint pushed to rest near neutral stays there (its first predicted steps
 * round to the present angle) while its neighbour keeps moving. */
static bool ctl_any_still(const struct ctl *c)
{
	for (size_t j = 0; j < c->n; j++)
		if (fabs(c->j[j].speed) < CTL_REST_V)
			return true;
	return false;
}

/* Drive the baseline sinusoid for ramp_s plus one period, then hand over. */
static void ctl_starter(struct ctl *c)
{
	c->starter_offset = 0.0;
	double period = c->p.frequency > 0.0 ? 1.0 / c->p.frequency : 1.0;
	c->starter_until = c->t + c->cfg->ramp_s + period;
	c->starter_active = true;
	c->starts++;
}

/* A position servo needs the starter from any rest (its first predicted
 * steps round to nothing). Under torque actuation the law's own torque, −k·x,
 * starts a joint resting away from neutral, and from rest at chosen angles the
 * phases are exactly 0 or π; only a robot resting at neutral, where the law
 * gives no torque, needs the starter. */
#define CTL_TORQUE_START_X 0.1
static bool ctl_needs_starter(const struct ctl *c)
{
	if (c->cfg->actuation != CFG_ACT_TORQUE)
		return true;
	for (size_t j = 0; j < c->n; j++)
		if (!(fabs(c->j[j].angle - c->cfg->joint[j].neutral) < CTL_TORQUE_START_X))
			return false;
	return true;
}

static double ctl_present_or_goal(const struct ctl_joint *jt)
{
	if (jt->torque && isfinite(jt->goal))
		return jt->goal;
	return jt->angle;
}

/* The writes that make a servo what the controller expects, after a start
 * or a reset: its compliance margins (RAM: a power loss resets them to the
 * factory value), moving speed 0 ("as fast as possible") in joint mode, and
 * torque as the mode wants it. */
static void ctl_servo_setup(struct ctl *c, size_t j, bool torque)
{
	struct ctl_joint *jt = &c->j[j];
	if (ctl_has(c, j, SM_CAP_OPMODE)) {
		/* under torque actuation the servo boots in its drive's mode with
		 * Goal PWM at its limit: every joint goes back to position control
		 * first (the next cycle may switch them again) */
		if (c->wheel)
			tq_leave_wheel(c);
		else
			(void)ctl_x_setup(c, j, false);
		return;
	}
	if (c->cfg->compliance_margin >= 0) {
		uint32_t m = (uint32_t)c->cfg->compliance_margin;
		ctl_write(c, jt->id, DXL_AX_CW_COMPLIANCE_MARGIN, 2, m | m << 8);
	}
	if (c->cfg->compliance_slope >= 0) {
		uint32_t sl = (uint32_t)c->cfg->compliance_slope;
		ctl_write(c, jt->id, DXL_AX_CW_COMPLIANCE_SLOPE, 2, sl | sl << 8);
	}
	if (!c->wheel)
		ctl_write(c, jt->id, DXL_AX_MOVING_SPEED, 2, 0);
	ctl_torque_write(c, j, torque);
}

void ctl_start(struct ctl *c, double t, const char *reason)
{
	c->t = t;
	c->bus_hold = false;
	/* the daemon's start-up checks leave every servo in joint mode, with its
	 * margins and moving speed set */
	c->wheel = false;
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		if (jt->fault != CTL_FAULT_FAILED)
			jt->fault = CTL_FAULT_NONE;
		jt->retries = 0;
		jt->drive_ready = false;
		/* the ramp starts where the joint is: no jump at torque-on */
		jt->goal = jt->angle;
		c->hold[j] = jt->angle;
		if (c->mode == CFG_MODE_LIMP) {
			ctl_torque_write(c, j, false);
			continue;
		}
		ctl_torque_write(c, j, true);
		ctl_blend_joint(c, j, jt->angle);
	}
	if (c->mode == CFG_MODE_OSCILLATOR && ctl_needs_starter(c))
		ctl_starter(c);
	/* The event's kind is already "start": name the reason only when it says
	 * more (a reconnection), or the log reads "start: start: ...". */
	bool plain = strcmp(reason, "start") == 0;
	ctl_event(c, 0, "start", "%s%s%s, ramping in over %.1f s%s%s", plain ? "" : reason, plain ? "" : ": ",
	          cfg_mode_name(c->mode), c->mode == CFG_MODE_LIMP ? 0.0 : c->cfg->ramp_s,
	          c->latched ? "; fault latched: " : "", c->latched ? c->latch : "");
}

static void ctl_joint_lost(struct ctl *c, size_t j)
{
	c->j[j].fresh = false;
	c->j[j].torque_read = -1;
	c->j[j].torque_limit_read = -1;
	c->j[j].hwerr = c->j[j].watchdog_read = c->j[j].opmode_read = -1;
	c->j[j].hwerr_at = -INFINITY;
	c->j[j].readback_due = false;
	c->j[j].drive_ready = false;
	/* the next reading after reconnecting starts a new difference */
	osc_velocity_filter_init(&c->j[j].vfilter, c->cfg->velocity_cutoff_hz);
}

void ctl_bus_lost(struct ctl *c)
{
	for (size_t j = 0; j < c->n; j++)
		ctl_joint_lost(c, j);
	wq_clear(&c->wq);
	ctl_blend_stop(c);
	c->fade_mode = CFG_NMODES;
}

bool ctl_on_bus(const struct ctl *c, size_t joint, size_t bus)
{
	return cfg_bus_has_joint(c->cfg, bus, joint);
}

void ctl_bus_lost_on(struct ctl *c, size_t bus)
{
	for (size_t j = 0; j < c->n; j++) {
		if (!ctl_on_bus(c, j, bus))
			continue;
		ctl_joint_lost(c, j);
		/* a write on the wire stays: its own bus reports how it went */
		wq_drop_id(&c->wq, c->j[j].id);
	}
	if (!c->bus_hold) {
		for (size_t j = 0; j < c->n; j++)
			c->hold[j] = isfinite(c->j[j].goal) ? c->j[j].goal : c->j[j].angle;
		c->bus_hold = true;
	}
	ctl_blend_stop(c);
	c->fade_mode = CFG_NMODES;
}

void ctl_bus_back_on(struct ctl *c, size_t bus)
{
	for (size_t j = 0; j < c->n; j++)
		if (ctl_on_bus(c, j, bus) && !c->j[j].torque)
			ctl_torque_write(c, j, false);
}

/* ---- inputs ----------------------------------------------------------------------------------- */
void ctl_measure(struct ctl *c, size_t j, uint16_t pos_raw, uint16_t speed_raw, uint16_t load_raw,
                 uint8_t errbits, double dt)
{
	struct sm_present p = {
		.pos_raw = pos_raw, .angle = dxl_pos_to_rad(pos_raw), .speed = dxl_speed_to_rad_s(speed_raw),
		.load = dxl_load_to_fraction(load_raw), .voltage = NAN, .temperature = NAN,
	};
	ctl_measure_present(c, j, &p, errbits, dt);
}

/* X series: what the status says, published as Hardware Error Status (as
 * last read) with the alert in bit 7. An alert the controller cannot explain
 * yet (no hardware error known) asks for the RAM block at once. */
static void ctl_x_status(struct ctl *c, size_t j, uint8_t status)
{
	struct ctl_joint *jt = &c->j[j];
	bool alert = sm_alert(ctl_model(c, j), status);
	if (alert && (!jt->alert || jt->hwerr <= 0))
		jt->readback_due = true;
	jt->alert = alert;
	jt->errbits = (uint8_t)((jt->hwerr > 0 ? jt->hwerr & 0x7F : 0) | (alert ? 0x80 : 0));
}

void ctl_measure_present(struct ctl *c, size_t j, const struct sm_present *p, uint8_t status, double dt)
{
	struct ctl_joint *jt = &c->j[j];
	jt->fresh = true;
	jt->have_reading = true;
	/* back after a gap: blend from the held goal to where the mode is now */
	jt->resumed = jt->stale_cycles >= CTL_RESUME_STALE;
	jt->stale_cycles = 0;
	jt->angle = p->angle;
	jt->load = p->load;
	if (ctl_has(c, j, SM_CAP_HWERR))
		ctl_x_status(c, j, status);
	else
		jt->errbits = status;
	/* Keep the filter primed whichever source is configured, so switching
	 * velocity_source at run time has no transient. */
	double filtered = osc_velocity_filter_update(&jt->vfilter, jt->angle, dt);
	jt->speed = c->cfg->velocity_source == CFG_VEL_SERVO ? p->speed : filtered;
	if (!isfinite(jt->speed))
		jt->speed = 0.0;
	if (p->slow) {
		jt->voltage = p->voltage;
		jt->temperature = p->temperature;
	}
}

void ctl_measure_slow(struct ctl *c, size_t j, uint8_t voltage_raw, uint8_t temperature_raw, uint8_t errbits)
{
	c->j[j].voltage = dxl_voltage_to_volts(voltage_raw);
	c->j[j].temperature = temperature_raw;
	c->j[j].errbits |= errbits;
}

/* Where a joint found at `angle` is held: there, or at the nearer limit when
 * it is past one (moved by hand while limp, or a servo that reset there). */
static double ctl_hold_point(const struct ctl_joint *jt, double angle)
{
	if (jt->limits.max_step <= 0.0 || !isfinite(angle))
		return angle;   /* no limits yet (never set up), or nothing measured */
	return safety_clamp(&jt->limits, angle, NAN, angle, NULL);
}

void ctl_hold_at_present(struct ctl *c)
{
	for (size_t j = 0; j < c->n; j++)
		c->hold[j] = ctl_hold_point(&c->j[j], isfinite(c->j[j].angle) ? c->j[j].angle : c->j[j].goal);
}

/* A servo that lost its set-up (its RAM back at the factory values, or
 * stopped by its watchdog): what was queued for it is dropped, it is set up
 * again with torque on and ramps in from goal, unless a fault holds it. */
static void ctl_set_up_again(struct ctl *c, size_t j, double goal)
{
	struct ctl_joint *jt = &c->j[j];
	wq_drop_id(&c->wq, jt->id);
	ctl_servo_setup(c, j, true);
	jt->goal = goal;
	c->hold[j] = goal;
	if (jt->fault == CTL_FAULT_NONE)
		ctl_blend_joint(c, j, goal);
}

/* A servo found with torque off that should be on: it lost power (or browned
 * out) and came back with its RAM at the factory values. It is set up again
 * and ramps in from where it is now; one that keeps resetting latches. */
static void ctl_servo_reset(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	jt->resets++;
	c->resets++;
	if (jt->resets > c->cfg->fault_retries) {
		ctl_event(c, 2, "servo-reset", "servo %u found with torque off again (reset %lld): giving up", jt->id,
		          jt->resets);
		ctl_latchf(c, "servo %u reset %lld times (power?)", jt->id, jt->resets);
		if (c->mode == CFG_MODE_LIMP)
			return;
	} else {
		ctl_event(c, 2, "servo-reset", "servo %u found with torque off while %s wanted it on (power loss or "
		          "brown-out: its RAM is back at the factory values): setting it up again, reset %lld of %d",
		          jt->id, cfg_mode_name(c->mode), jt->resets, c->cfg->fault_retries);
	}
	/* it may have been moved while limp: start where it is (inside the limits) */
	ctl_set_up_again(c, j, ctl_hold_point(jt, jt->angle));
}

static void ctl_mismatch(struct ctl *c, size_t j, const char *what, unsigned read, unsigned want)
{
	c->readback_mismatches++;
	ctl_event(c, 1, "readback", "servo %u: %s read back %u, expected %u: written again", c->j[j].id, what, read,
	          want);
}

/* The AX-12's read-back: torque enable, torque limit, compliance margins. */
static void ctl_readback_ax(struct ctl *c, size_t j, const struct sm_state *st, uint8_t errbits)
{
	struct ctl_joint *jt = &c->j[j];
	unsigned torque = (unsigned)st->torque, limit = (unsigned)st->torque_limit;
	unsigned margin_cw = (unsigned)st->margin_cw, margin_ccw = (unsigned)st->margin_ccw;
	unsigned slope_cw = (unsigned)st->slope_cw, slope_ccw = (unsigned)st->slope_ccw;
	jt->torque_read = (int)torque;
	jt->torque_limit_read = (int)limit;
	jt->voltage = st->voltage;
	jt->temperature = st->temperature;
	jt->errbits |= errbits;
	/* a write to this servo is queued or on the wire: its registers are
	 * about to change; judge them at the next read-back. A joint in a fault's
	 * back-off, recovery or latched failure is the fault machinery's. */
	if (wq_has_id(&c->wq, jt->id) || !jt->have_reading || jt->fault != CTL_FAULT_NONE)
		return;
	if (jt->torque && torque == 0 && limit == 0) {
		/* the manual's alarm shutdown (torque off, torque limit 0), though no
		 * reply showed its bit: a fault, backed off and recovered as one */
		jt->faults++;
		c->faults++;
		jt->retries = 0;
		ctl_event(c, 1, "fault", "servo %u found shut down (torque off, torque limit 0: an alarm): backing "
		          "off", jt->id);
		jt->fault = CTL_FAULT_BACKOFF;
		jt->fault_since = c->t;
		jt->fault_hold = jt->angle;
		return;
	}
	if (jt->torque && torque == 0) {
		ctl_servo_reset(c, j);
		return;
	}
	if (!jt->torque && torque != 0) {
		ctl_mismatch(c, j, "torque enable", torque, 0);
		ctl_torque_write(c, j, false);
		return;
	}
	if (!jt->torque)
		return;
	unsigned want_limit = ctl_torque_limit(c, jt);
	if (limit != want_limit && jt->fault != CTL_FAULT_CHECK) {
		/* 0 is an alarm shutdown the error bits did not show (they clear
		 * when torque is enabled again) */
		ctl_mismatch(c, j, limit == 0 ? "torque limit (alarm shutdown)" : "torque limit", limit, want_limit);
		ctl_write(c, jt->id, DXL_AX_TORQUE_LIMIT, 2, want_limit);
	}
	long want_margin = c->cfg->compliance_margin;
	if (want_margin >= 0 && (margin_cw != (unsigned)want_margin || margin_ccw != (unsigned)want_margin)) {
		ctl_mismatch(c, j, "compliance margin", margin_cw != (unsigned)want_margin ? margin_cw : margin_ccw,
		             (unsigned)want_margin);
		ctl_write(c, jt->id, DXL_AX_CW_COMPLIANCE_MARGIN, 2, (uint32_t)want_margin | (uint32_t)want_margin << 8);
	}
	long want_slope = c->cfg->compliance_slope;
	if (want_slope >= 0 && (slope_cw != (unsigned)want_slope || slope_ccw != (unsigned)want_slope)) {
		ctl_mismatch(c, j, "compliance slope", slope_cw != (unsigned)want_slope ? slope_cw : slope_ccw,
		             (unsigned)want_slope);
		ctl_write(c, jt->id, DXL_AX_CW_COMPLIANCE_SLOPE, 2, (uint32_t)want_slope | (uint32_t)want_slope << 8);
	}
}

void ctl_readback(struct ctl *c, size_t j, const uint8_t *ram, uint8_t errbits)
{
	ctl_readback_block(c, j, 0, ram, CTL_READBACK_LEN, errbits);
}

/* X series: the Bus Watchdog stopped the servo (nothing reached it for its
 * time: this controller was late, or the line was lost). Its goals are
 * read-only until the watchdog is written 0: recovered like a reset, and as
 * a reset counted (one that keeps happening latches). */
static void ctl_watchdog_tripped(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	jt->resets++;
	c->resets++;
	c->watchdog_trips++;
	unsigned ms = 20u * cfg_watchdog_units(c->cfg);
	if (jt->resets > c->cfg->fault_retries) {
		ctl_event(c, 2, "watchdog", "servo %u: its bus watchdog stopped it again (%lld): giving up", jt->id,
		          jt->resets);
		ctl_latchf(c, "servo %u stopped by its bus watchdog %lld times", jt->id, jt->resets);
	} else {
		ctl_event(c, 2, "watchdog", "servo %u: its bus watchdog stopped it (nothing reached it for %u ms: "
		          "this controller was late or the line was lost): cleared and set up again, reset %lld of %d",
		          jt->id, ms, jt->resets, c->cfg->fault_retries);
	}
	jt->watchdog_cleared = true;   /* read by the set-up: the watchdog written 0 first */
	ctl_set_up_again(c, j, jt->angle);
}

/* Error bits that are no fault (other) are reported once, when they appear:
 * those not set at the last report, named by format, with the register
 * (reg, its value) they came in. */
static void ctl_report_new_bits(struct ctl *c, struct ctl_joint *jt, uint8_t other,
                                char *(*format)(uint8_t, char *, size_t), const char *reg, unsigned value)
{
	uint8_t fresh_bits = other & (uint8_t)~jt->reported_bits;
	jt->reported_bits = other;
	if (fresh_bits == 0)
		return;
	char what[96];
	format(fresh_bits, what, sizeof what);
	ctl_event(c, 1, "servo-error", "servo %u reports %s (%s 0x%02x)", jt->id, what, reg, value);
}

/* X series: hardware errors that are no fault (the input voltage outside the
 * servo's limits). */
static void ctl_x_report_hwerr(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	uint8_t other = (uint8_t)(jt->hwerr > 0 ? jt->hwerr & ~SM_HWERR_FAULTS : 0);
	ctl_report_new_bits(c, jt, other, dxl2_hwerr_format, "Hardware Error Status", (unsigned)jt->hwerr);
}

/* X series, the RAM block: torque, the watchdog, Goal PWM, the profiles. */
static void ctl_readback_x_ram(struct ctl *c, size_t j, const struct sm_state *st)
{
	struct ctl_joint *jt = &c->j[j];
	if (st->hwerr & SM_HWERR_FAULTS)
		return;   /* a fault: ctl_fault_step's, at this cycle's step */
	if (st->watchdog == SM_WATCHDOG_TRIPPED) {
		ctl_watchdog_tripped(c, j);
		return;
	}
	if (jt->torque && st->torque == 0) {
		ctl_servo_reset(c, j);
		return;
	}
	if (!jt->torque && st->torque != 0) {
		ctl_mismatch(c, j, "torque enable", (unsigned)st->torque, 0);
		ctl_torque_write(c, j, false);
		return;
	}
	const struct sm_model *m = ctl_model(c, j);
	unsigned want_wd = cfg_watchdog_units(c->cfg);
	if (c->cfg->bus_watchdog_ms >= 0 && (unsigned)st->watchdog != want_wd) {
		ctl_mismatch(c, j, "bus watchdog", (unsigned)st->watchdog, want_wd);
		ctl_write(c, jt->id, DXL2_X_BUS_WATCHDOG, 1, want_wd);
	}
	if (st->profile_velocity != 0 || st->profile_acceleration != 0) {
		/* a profile would make every goal a slow ramp */
		ctl_mismatch(c, j, st->profile_velocity != 0 ? "profile velocity" : "profile acceleration",
		             (unsigned)(st->profile_velocity != 0 ? st->profile_velocity : st->profile_acceleration), 0);
		ctl_write(c, jt->id, DXL2_X_PROFILE_ACCELERATION, 4, 0);
		ctl_write(c, jt->id, DXL2_X_PROFILE_VELOCITY, 4, 0);
	}
	unsigned want_limit = ctl_torque_limit(c, jt);
	if (jt->torque && !ctl_limit_is_drive(c, j) && (unsigned)st->torque_limit != want_limit) {
		ctl_mismatch(c, j, "goal PWM (the output limit)", (unsigned)st->torque_limit, want_limit);
		ctl_write(c, jt->id, m->torque_limit, 2, want_limit);
	}
}

/* X series, the EEPROM block: Operating Mode and the position limits, which
 * only the configuration and this controller's switches decide. Found
 * otherwise: written again (torque off for it), counted as a reset. */
static void ctl_readback_x_eeprom(struct ctl *c, size_t j, const struct sm_state *st)
{
	struct ctl_joint *jt = &c->j[j];
	int want_mode = c->wheel && jt->drive_ready ? sm_drive_opmode(c->cfg->torque_drive == CFG_DRIVE_CURRENT)
	                                            : SM_OPMODE_POSITION;
	bool mode_wrong = st->opmode != want_mode && !(c->wheel && !jt->drive_ready);
	jt->limits_wrong = st->pos_min != jt->servo.cw_limit || st->pos_max != jt->servo.ccw_limit;
	if (st->pwm_limit >= 0 && (unsigned)st->pwm_limit != jt->servo.max_torque) {
		ctl_event(c, 1, "readback", "servo %u: PWM Limit read back %d, was %u at start: taken as the output "
		          "limit", jt->id, st->pwm_limit, jt->servo.max_torque);
		jt->servo.max_torque = (uint16_t)st->pwm_limit;
	}
	if (st->current_limit >= 0 && (unsigned)st->current_limit != jt->servo.current_limit)
		jt->servo.current_limit = (uint16_t)st->current_limit;
	if (!mode_wrong && !jt->limits_wrong)
		return;
	c->readback_mismatches++;
	jt->resets++;
	c->resets++;
	const char *mode = dxl2_opmode_name((uint8_t)st->opmode);
	ctl_event(c, 2, "readback", "servo %u: %s%s%s (operating mode %d %s, position limits %ld..%ld; this "
	          "controller's: %d, %u..%u): written again with torque off, reset %lld of %d", jt->id,
	          mode_wrong ? "operating mode changed" : "", mode_wrong && jt->limits_wrong ? " and " : "",
	          jt->limits_wrong ? "position limits changed" : "", st->opmode, mode != NULL ? mode : "unknown",
	          (long)st->pos_min, (long)st->pos_max, want_mode, jt->servo.cw_limit, jt->servo.ccw_limit, jt->resets,
	          c->cfg->fault_retries);
	if (jt->resets > c->cfg->fault_retries)
		ctl_latchf(c, "servo %u keeps being changed behind this controller's back", jt->id);
	wq_drop_id(&c->wq, jt->id);
	if (c->wheel)
		tq_leave_wheel(c);
	else
		(void)ctl_x_setup(c, j, true);
}

static void ctl_readback_x(struct ctl *c, size_t j, const struct sm_state *st, uint8_t status)
{
	struct ctl_joint *jt = &c->j[j];
	ctl_x_status(c, j, status);
	bool ram = st->torque >= 0;
	if (ram) {
		jt->torque_read = st->torque;
		jt->torque_limit_read = st->torque_limit;
		jt->hwerr = st->hwerr;
		jt->hwerr_at = c->t;
		jt->watchdog_read = st->watchdog;
		jt->readback_due = false;
		jt->errbits = (uint8_t)((st->hwerr & 0x7F) | (jt->alert ? 0x80 : 0));
		ctl_x_report_hwerr(c, j);
	} else {
		jt->opmode_read = st->opmode;
	}
	/* as on the AX-12: registers about to change, or the fault machinery's */
	if (wq_has_id(&c->wq, jt->id) || !jt->have_reading || jt->fault != CTL_FAULT_NONE)
		return;
	if (ram)
		ctl_readback_x_ram(c, j, st);
	else
		ctl_readback_x_eeprom(c, j, st);
}

void ctl_readback_block(struct ctl *c, size_t j, size_t block, const uint8_t *bytes, size_t n, uint8_t status)
{
	const struct sm_model *m = ctl_model(c, j);
	struct sm_state st;
	sm_state_unknown(&st);
	if (!sm_decode_readback(m, block, bytes, n, &st))
		return;
	if (sm_has(m, SM_CAP_OPMODE))
		ctl_readback_x(c, j, &st, status);
	else
		ctl_readback_ax(c, j, &st, status);
}

bool ctl_readback_due(const struct ctl *c, size_t *joint)
{
	for (size_t j = 0; j < c->n; j++)
		if (c->j[j].readback_due) {
			*joint = j;
			return true;
		}
	return false;
}

/* ---- modes ------------------------------------------------------------------------------------ */
static enum cfg_mode ctl_fault_mode(const struct ctl *c)
{
	return c->cfg->fault_action == CFG_SAFE_LIMP ? CFG_MODE_LIMP : CFG_MODE_HOLD;
}

bool ctl_mode_allowed(const struct ctl *c, enum cfg_mode mode, char *why, size_t cap)
{
	if (!c->latched || mode == CFG_MODE_LIMP || mode == ctl_fault_mode(c))
		return true;
	if (ctl_fault_mode(c) == CFG_MODE_LIMP)
		snprintf(why, cap, "fault latched (%s): only LIMP until 'clear'", c->latch);
	else
		snprintf(why, cap, "fault latched (%s): only LIMP or %s until 'clear'", c->latch,
		         cfg_mode_name(ctl_fault_mode(c)));
	return false;
}

void ctl_set_mode(struct ctl *c, enum cfg_mode mode, const char *reason)
{
	enum cfg_mode old = c->mode;
	snprintf(c->reason, sizeof c->reason, "%s", reason);
	if (mode == old)
		return;
	bool was_still = old == CFG_MODE_LIMP || old == CFG_MODE_HOLD || ctl_is_still(c);
	/* an OSCILLATOR still in its starter is commanding the sinusoid */
	enum cfg_mode commanding = old == CFG_MODE_OSCILLATOR && c->starter_active ? CFG_MODE_SINUSOID : old;
	bool was_moving_mode = commanding == CFG_MODE_SINUSOID || commanding == CFG_MODE_OSCILLATOR;
	bool moving = !was_still && was_moving_mode &&
	              (mode == CFG_MODE_SINUSOID || mode == CFG_MODE_OSCILLATOR);
	/* a restart's starter runs at its own phase offset, which the new mode's
	 * computation cannot reproduce: blend from the last goal instead */
	if (commanding == CFG_MODE_SINUSOID && old == CFG_MODE_OSCILLATOR && c->starter_offset != 0.0)
		moving = false;
	c->starter_offset = 0.0;
	c->mode = mode;
	c->starter_active = false;
	/* into a torque-actuated OSCILLATOR: the law takes the moving state as it is */
	if (mode == CFG_MODE_OSCILLATOR && c->cfg->actuation == CFG_ACT_TORQUE)
		moving = false;
	c->fade_mode = moving ? (int)commanding : CFG_NMODES;
	c->fade_t0 = c->t;
	ctl_blend_stop(c);
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		if (mode == CFG_MODE_LIMP) {
			ctl_torque_write(c, j, false);
			continue;
		}
		double from = ctl_present_or_goal(jt);
		if (!jt->torque) {
			/* from LIMP: the joint may have been moved by hand; start where it
			 * is, or at the nearer limit when that is past one */
			ctl_torque_write(c, j, true);
			from = ctl_hold_point(jt, jt->angle);
			jt->goal = from;
			ctl_blend_joint(c, j, from);
		}
		c->hold[j] = from;
		/* OSCILLATOR from a moving robot starts from the measured state:
		 * continuous by itself. SINUSOID (and the starter of an OSCILLATOR
		 * from rest) follows a clock: blend from where the joint is commanded. */
		if (!moving && (mode == CFG_MODE_SINUSOID || (mode == CFG_MODE_OSCILLATOR && was_still)))
			ctl_blend_joint(c, j, from);
	}
	if (mode == CFG_MODE_OSCILLATOR && was_still && ctl_needs_starter(c))
		ctl_starter(c);
	/* a fault's switch is an error; the operator's is news */
	ctl_event(c, c->latched && mode == ctl_fault_mode(c) ? 2 : 0, "mode", "%s -> %s (%s)",
	          cfg_mode_name(old), cfg_mode_name(mode), reason);
}

/* SINUSOID re-blends so that its new phase or frequency cannot jump. */
static void ctl_params_changed(struct ctl *c)
{
	if (c->mode != CFG_MODE_SINUSOID)
		return;
	for (size_t j = 0; j < c->n; j++)
		ctl_blend_joint(c, j, ctl_present_or_goal(&c->j[j]));
}

bool ctl_check_param(const struct ctl *c, const char *name, int joint, double value, char *why, size_t cap)
{
	return cfg_params_check(c->cfg, &c->p, name, joint, value, why, cap);
}

bool ctl_set_param(struct ctl *c, const char *name, int joint, double value, char *why, size_t cap)
{
	if (!ctl_check_param(c, name, joint, value, why, cap))
		return false;
	size_t first = joint < 0 ? 0 : (size_t)joint;
	size_t last = joint < 0 ? c->n : first + 1;
	for (size_t j = first; j < last; j++)
		*cfg_params_field(&c->p, name, j) = value;   /* a robot's parameter: the same field every time */
	ctl_params_changed(c);
	return true;
}

void ctl_torque(struct ctl *c, bool on)
{
	if (!on) {
		ctl_set_mode(c, CFG_MODE_LIMP, "command: torque off");
		return;
	}
	if (c->mode == CFG_MODE_LIMP)
		ctl_set_mode(c, CFG_MODE_HOLD, "command: torque on");
}

void ctl_latch(struct ctl *c, const char *what)
{
	enum cfg_mode m = ctl_fault_mode(c);
	if (c->latched) {
		/* the first cause stays the one reported; a second one is said */
		ctl_event(c, 2, "fault", "%s (latched already: %s)", what, c->latch);
		if (c->mode == m || c->mode == CFG_MODE_LIMP)
			return;
	} else {
		c->latched = true;
		snprintf(c->latch, sizeof c->latch, "%s", what);
		/* a fault never turns torque on: a robot the operator made LIMP
		 * stays LIMP (its joints may be in someone's hands) */
		ctl_event(c, 2, "fault-latched", "%s: robot %s until 'clear'", what,
		          cfg_mode_name(c->mode == CFG_MODE_LIMP ? CFG_MODE_LIMP : m));
	}
	char reason[sizeof c->reason];
	snprintf(reason, sizeof reason, "fault: %.80s", what);
	if (c->mode == CFG_MODE_LIMP) {
		snprintf(c->reason, sizeof c->reason, "%s", reason);
		return;
	}
	/* hold where the joints are, not where a failing joint was told to go */
	ctl_hold_at_present(c);
	if (c->mode == m) {
		snprintf(c->reason, sizeof c->reason, "%s", reason);
		return;
	}
	c->fade_mode = CFG_NMODES;
	c->starter_active = false;
	ctl_set_mode(c, m, reason);
	/* HOLD from a moving mode: where the joints are, no blend from elsewhere */
	ctl_blend_stop(c);
	ctl_hold_at_present(c);
}

void ctl_latchf(struct ctl *c, const char *fmt, ...)
{
	char what[CTL_LATCH_TEXT];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(what, sizeof what, fmt, ap);
	va_end(ap);
	ctl_latch(c, what);
}

bool ctl_clear_faults(struct ctl *c, char *why, size_t cap)
{
	for (size_t j = 0; j < c->n; j++) {
		const struct ctl_joint *jt = &c->j[j];
		if (jt->have_reading && jt->stale_cycles > 0 && jt->stale_cycles * c->cfg->period_ms * 1e-3 >= c->cfg->silent_s) {
			snprintf(why, cap, "servo %u is still silent (%.1f s): fix the cause first", jt->id,
			         jt->stale_cycles * c->cfg->period_ms * 1e-3);
			return false;
		}
	}
	bool was = c->latched;
	c->latched = false;
	c->latch[0] = '\0';
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		if (jt->fault == CTL_FAULT_FAILED) {
			/* hold where it is; the goal itself moves there within max_step
			 * a cycle, like every goal (it is the clamp's reference) */
			jt->fault = CTL_FAULT_NONE;
			c->hold[j] = isfinite(jt->angle) ? jt->angle : jt->goal;
		}
		jt->retries = 0;
		jt->resets = 0;
		jt->reboots = 0;
		if (ctl_has(c, j, SM_CAP_HWERR) && jt->hwerr > 0 && (jt->hwerr & SM_HWERR_FAULTS) && jt->torque_read == 0) {
			/* shut down: an X servo takes torque again only after a REBOOT,
			 * which the operator's 'clear' asks for (not counted against
			 * fault_reboots); then it is set up as after any */
			wq_drop_id(&c->wq, jt->id);
			ctl_write_chain(c, wq_chain(&c->wq), jt->id, 0, 0, 0);
			c->reboots++;
			jt->fault = CTL_FAULT_REBOOT;
			jt->fault_since = c->t;
			ctl_event(c, 0, "reboot", "servo %u: REBOOT ('clear'), then set up again", jt->id);
			continue;
		}
		/* the manual's recovery, whatever happened while latched (an alarm
		 * shutdown zeroes the torque limit and turns torque off) */
		if (jt->torque)
			ctl_torque_write(c, j, true);
	}
	snprintf(c->reason, sizeof c->reason, "fault cleared");
	ctl_event(c, 0, "fault-cleared", "%s", was ? "latched fault cleared: send a mode command to go on"
	                                           : "no fault was latched");
	return true;
}

/* ---- faults -------------------------------------------------------------------------------- */
static void ctl_backoff(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	jt->fault = CTL_FAULT_BACKOFF;
	jt->fault_since = c->t;
	jt->fault_hold = isfinite(jt->angle) ? jt->angle : jt->goal;
	ctl_limit_write(c, j);
}

/* The fault bits in play: the AX-12's overload and overheating in this
 * cycle's status; an X servo's hardware errors as last read back. */
static uint8_t ctl_fault_bits(const struct ctl *c, size_t j)
{
	const struct ctl_joint *jt = &c->j[j];
	if (ctl_has(c, j, SM_CAP_HWERR))
		return (uint8_t)(jt->hwerr > 0 ? jt->hwerr & SM_HWERR_FAULTS : 0);
	return jt->fresh ? (uint8_t)(jt->errbits & (DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT)) : 0;
}

static void ctl_fault_name(const struct ctl *c, size_t j, uint8_t bits, char *what, size_t cap)
{
	if (ctl_has(c, j, SM_CAP_HWERR))
		dxl2_hwerr_format(bits, what, cap);
	else
		dxl_errbits_format(bits, what, cap);
}

/* after: how it was tried (NULL: the recovery attempts counted). */
static void ctl_fault_persistent(struct ctl *c, size_t j, const char *what, const char *after)
{
	struct ctl_joint *jt = &c->j[j];
	jt->fault = CTL_FAULT_FAILED;
	char text[CTL_LATCH_TEXT], tried[64];
	if (after == NULL)
		snprintf(tried, sizeof tried, "after %d recovery attempts", jt->retries);
	snprintf(text, sizeof text, "servo %u %s persists", jt->id, what);
	ctl_event(c, 2, "fault-persistent", "servo %u: %s persists %s: robot %s; cool down / check the mechanics, "
	          "then 'clear'", jt->id, what, after != NULL ? after : tried, cfg_mode_name(ctl_fault_mode(c)));
	ctl_latch(c, text);
}

/* Error bits other than the fault kinds (voltage, angle limit, range,
 * checksum, instruction) are reported once when they appear (an X servo's at
 * its read-back). */
static void ctl_report_errbits(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	if (!jt->fresh || ctl_has(c, j, SM_CAP_HWERR))
		return;
	uint8_t other = jt->errbits & (uint8_t)~(DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT);
	ctl_report_new_bits(c, jt, other, dxl_errbits_format, "error byte", jt->errbits);
}

/* X series: a servo its hardware error shut down (torque off) recovers only
 * by a REBOOT: one per fault_reboots since the last 'clear', else the fault
 * latches. True when that was decided here. */
static bool ctl_x_reboot(struct ctl *c, size_t j, const char *what)
{
	struct ctl_joint *jt = &c->j[j];
	if (!ctl_has(c, j, SM_CAP_HWERR) || jt->torque_read != 0)
		return false;
	if (jt->reboots >= c->cfg->fault_reboots) {
		char after[64];
		snprintf(after, sizeof after, "after %d REBOOT(s) (fault_reboots = %d)", jt->reboots, c->cfg->fault_reboots);
		ctl_fault_persistent(c, j, what, after);
		return true;
	}
	jt->reboots++;
	c->reboots++;
	wq_drop_id(&c->wq, jt->id);
	ctl_write_chain(c, wq_chain(&c->wq), jt->id, 0, 0, 0);
	jt->fault = CTL_FAULT_REBOOT;
	jt->fault_since = c->t;
	ctl_event(c, 1, "reboot", "servo %u: %s shut it down: REBOOT %d of %d (fault_reboots), then set up again",
	          jt->id, what, jt->reboots, c->cfg->fault_reboots);
	return true;
}

/* X series: the hardware error status read back since `since`, if any. */
static bool ctl_x_read_since(const struct ctl_joint *jt, double since)
{
	return jt->hwerr_at >= since;
}

static void ctl_fault_step(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	bool x = ctl_has(c, j, SM_CAP_HWERR);
	uint8_t bad = ctl_fault_bits(c, j);
	char what[64];
	ctl_fault_name(c, j, bad ? bad : (x ? (uint8_t)(jt->hwerr > 0 ? jt->hwerr : 0) : jt->errbits), what, sizeof what);
	switch (jt->fault) {
	case CTL_FAULT_NONE:
		if (!bad)
			return;
		jt->faults++;
		c->faults++;
		jt->retries = 0;
		ctl_backoff(c, j);
		ctl_event(c, 1, "fault", "servo %u: %s%s: backing off (holding at %+.3f rad, torque limit %.0f %%)",
		          jt->id, what, x && jt->torque_read == 0 ? " (shut down: torque off)" : "", jt->fault_hold,
		          100.0 * c->cfg->backoff_torque);
		return;
	case CTL_FAULT_BACKOFF:
		if (c->t - jt->fault_since < c->cfg->fault_backoff_s)
			return;
		if (ctl_x_reboot(c, j, what))
			return;
		jt->fault = CTL_FAULT_CHECK;
		jt->fault_since = c->t;
		jt->errbits = 0;
		/* LIMP: only the full limit back, for the torque-on that may follow */
		if (c->mode != CFG_MODE_LIMP)
			ctl_torque_write(c, j, true);
		else
			ctl_limit_write(c, j);
		return;
	case CTL_FAULT_REBOOT:
		/* its acknowledgement sets reboot_at; then the boot's settle time */
		if (!(jt->reboot_at >= jt->fault_since) || c->t - jt->reboot_at < CTL_REBOOT_SETTLE_S)
			return;
		jt->fault = CTL_FAULT_CHECK;
		jt->fault_since = c->t;
		(void)ctl_x_setup(c, j, true);
		jt->readback_due = true;
		return;
	case CTL_FAULT_CHECK:
		/* an X servo's faults are known from a read-back: one since the
		 * recovery tells, an older one does not */
		if (x && !ctl_x_read_since(jt, jt->fault_since)) {
			jt->readback_due = true;
			return;
		}
		if (bad) {
			jt->retries++;
			if (jt->retries > c->cfg->fault_retries) {
				ctl_fault_persistent(c, j, what, NULL);
				return;
			}
			ctl_backoff(c, j);
			ctl_event(c, 1, "fault", "servo %u: %s persists, recovery attempt %d of %d", jt->id, what,
			          jt->retries, c->cfg->fault_retries);
			return;
		}
		if (c->t - jt->fault_since < CTL_FAULT_CHECK_S)
			return;
		jt->fault = CTL_FAULT_NONE;
		ctl_event(c, 0, "recovered", "servo %u: recovered (torque limit %u, torque on)", jt->id,
		          jt->servo.max_torque);
		{
			/* from where it is now; the goal (the clamp's reference) follows
			 * within max_step a cycle */
			double from = isfinite(jt->angle) ? jt->angle : jt->goal;
			if (c->mode == CFG_MODE_HOLD)
				c->hold[j] = from;
			else
				ctl_blend_joint(c, j, from);
		}
		return;
	case CTL_FAULT_FAILED:
		return;
	}
}

/* Stale: no valid reading this cycle. The joint holds its last goal; after
 * stale_limit cycles an event says so; silent for silent_s latches the
 * robot's fault action: the other joints must not go on against a frozen
 * reading. */
static void ctl_check_stale(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	if (jt->fresh || !jt->have_reading)
		return;
	jt->stale_cycles++;
	if (jt->stale_cycles == c->cfg->stale_limit)
		ctl_event(c, 1, "stale", "servo %u: no valid reading for %d cycles, joint holds", jt->id,
		          jt->stale_cycles);
	double silent = jt->stale_cycles * c->cfg->period_ms * 1e-3;
	double previous = (jt->stale_cycles - 1) * c->cfg->period_ms * 1e-3;
	if (silent >= c->cfg->silent_s && previous < c->cfg->silent_s)
		ctl_latchf(c, "servo %u silent for %.2f s", jt->id, silent);
}

/* ---- the step ------------------------------------------------------------------------------ */
static void ctl_targets_oscillator(struct ctl *c, double dt, double *target)
{
	double x[CFG_MAX_JOINTS], v[CFG_MAX_JOINTS], xn[CFG_MAX_JOINTS];
	for (size_t j = 0; j < c->n; j++) {
		const struct ctl_joint *jt = &c->j[j];
		x[j] = jt->angle - c->cfg->joint[j].neutral;
		v[j] = jt->fresh ? jt->speed : 0.0;
	}
	/* The horizon: the measured period, bounded (after a stall the oscillator
	 * must not leap seconds ahead), plus the servo's lead — the AX-12 lags its
	 * goal by ~27 ms, so a goal one period ahead damps the loop out (CONTROL.md). */
	double period = c->cfg->period_ms * 1e-3;
	double h = fmin(fmax(dt, 0.25 * period), 3.0 * period) + c->p.servo_lead_s;
	if (!osc_step(c->p.osc, c->n, x, v, h, CTL_OSC_SUBSTEPS, xn, NULL)) {
		for (size_t j = 0; j < c->n; j++)
			target[j] = NAN;
		return;
	}
	for (size_t j = 0; j < c->n; j++)
		target[j] = c->cfg->joint[j].neutral + xn[j];
}

static void ctl_targets(struct ctl *c, enum cfg_mode mode, double dt, double t_real, double *target)
{
	switch (mode) {
	case CFG_MODE_LIMP:
		for (size_t j = 0; j < c->n; j++)
			target[j] = NAN;
		return;
	case CFG_MODE_HOLD:
		for (size_t j = 0; j < c->n; j++)
			target[j] = c->hold[j];
		return;
	case CFG_MODE_OSCILLATOR:
	case CFG_MODE_SINUSOID:
		if (tq_mode_drives(c, mode) && !(mode == CFG_MODE_OSCILLATOR && c->starter_active)) {
			/* torque actuation drives through duties (torque.c); as a
			 * position it stands for where the joint is (the cycles that
			 * switch servo modes, a fault's back-off, fades out of it) */
			for (size_t j = 0; j < c->n; j++)
				target[j] = c->j[j].angle;
			return;
		}
		if (mode == CFG_MODE_OSCILLATOR && !c->starter_active) {
			ctl_targets_oscillator(c, dt, target);
			return;
		}
		/* SINUSOID, or the OSCILLATOR's starter (also while it fades out),
		 * which after a stall runs at its own offset */
		for (size_t j = 0; j < c->n; j++)
			target[j] = c->cfg->joint[j].neutral +
			            osc_sinusoid(c->p.amplitude, c->p.frequency,
			                         c->p.phase + (c->mode == CFG_MODE_OSCILLATOR ? c->starter_offset : 0.0),
			                         j, t_real);
		return;
	}
}

/* The phase offset of a restart after a stall, in [-pi, pi): a pseudo-random
 * number from the robot's name and its count of starts. Two robots jammed
 * against each other (started in exact anti-phase at a small separation,
 * docs/EXPERIMENTS.md) would otherwise restart on the same clock-driven
 * sinusoids and jam again the same way; different names draw different
 * offsets, and every restart draws again. Deterministic, so tests repeat. */
static double ctl_restart_offset(const struct ctl *c)
{
	uint64_t h = 1469598103934665603ULL;   /* FNV-1a of the name, then the count */
	for (const char *p = c->cfg->name; *p; p++)
		h = (h ^ (uint8_t)*p) * 1099511628211ULL;
	h = (h ^ (uint64_t)c->starts) * 1099511628211ULL;
	h ^= h >> 33;                          /* a murmur finalizer to spread the bits */
	h *= 0xff51afd7ed558ccdULL;
	h ^= h >> 33;
	return ((double)(h >> 11) / 9007199254740992.0 - 0.5) * 2.0 * 3.14159265358979323846;
}

/* An oscillator that has come to rest (blocked, or parameters that damp it)
 * is started again, and says so. */
static void ctl_check_stall(struct ctl *c)
{
	bool fresh = true;
	for (size_t j = 0; j < c->n; j++)
		fresh = fresh && c->j[j].fresh;
	bool running = c->mode == CFG_MODE_OSCILLATOR && !c->starter_active;
	c->rest_cycles = running && fresh && ctl_any_still(c) ? c->rest_cycles + 1 : 0;
	if (c->rest_cycles * c->cfg->period_ms * 1e-3 < CTL_STALL_S - 1e-9)
		return;
	c->rest_cycles = 0;
	for (size_t j = 0; j < c->n; j++)
		ctl_blend_joint(c, j, ctl_present_or_goal(&c->j[j]));
	ctl_starter(c);
	c->starter_offset = ctl_restart_offset(c);
	ctl_event(c, 1, "stall", "oscillator at rest for %.1f s: restarting it with the sinusoid starter, "
	          "phase %+.2f rad from its own", CTL_STALL_S, c->starter_offset);
}

/* Between two moving modes (SINUSOID <-> OSCILLATOR) the old mode's target
 * keeps being computed and the commanded angle fades from it to the new one
 * over ramp_s: neither a jump nor a stop. */
static void ctl_crossfade(struct ctl *c, double dt, double t_real, double *target)
{
	if (c->fade_mode == CFG_NMODES)
		return;
	double s = c->cfg->ramp_s > 0.0 ? (c->t - c->fade_t0) / c->cfg->ramp_s : 1.0;
	if (s >= 1.0) {
		c->fade_mode = CFG_NMODES;
		return;
	}
	double from[CFG_MAX_JOINTS];
	ctl_targets(c, (enum cfg_mode)c->fade_mode, dt, t_real, from);
	double w = s <= 0.0 ? 0.0 : s * s * (3.0 - 2.0 * s);
	for (size_t j = 0; j < c->n; j++)
		if (isfinite(from[j]) && isfinite(target[j]))
			target[j] = from[j] + w * (target[j] - from[j]);
}

/* Smoothstep: zero slope at both ends, so the blend adds no velocity kick. */
static double ctl_blend_weight(const struct ctl *c, size_t j)
{
	if (!isfinite(c->blend_from[j]) || c->cfg->ramp_s <= 0.0)
		return 1.0;
	double s = (c->t - c->blend_t0[j]) / c->cfg->ramp_s;
	if (s <= 0.0)
		return 0.0;
	if (s >= 1.0)
		return 1.0;
	return s * s * (3.0 - 2.0 * s);
}

static void ctl_finish_joint(struct ctl *c, size_t j, double desired)
{
	struct ctl_joint *jt = &c->j[j];
	jt->write_goal = false;
	jt->clamp_flags = 0;
	if (c->mode == CFG_MODE_LIMP || !jt->torque) {
		jt->goal = jt->angle;   /* reported only: nothing is written while limp */
		return;
	}
	if (jt->fault != CTL_FAULT_NONE)
		desired = jt->fault_hold;
	if (!jt->fresh)
		desired = jt->goal;     /* stale: hold the last goal */
	if (jt->limits.max_step <= 0.0 || !jt->have_reading)
		return;                 /* never talked to this servo: nothing safe to send */
	unsigned flags;
	double goal = safety_clamp(&jt->limits, desired, jt->goal, jt->angle, &flags);
	if (flags & SAFETY_NONFINITE)
		c->nonfinite++;
	if (flags & (SAFETY_STEP | SAFETY_LIMIT))
		c->clamps++;
	jt->clamp_flags = flags;
	jt->goal = goal;
	jt->write_goal = true;
}

static void ctl_update_estimates(struct ctl *c, size_t j)
{
	struct ctl_joint *jt = &c->j[j];
	if (!jt->fresh)
		return;
	const struct cfg_joint *cj = &c->cfg->joint[j];
	double x = jt->angle - cj->neutral;
	phase_estimator_update(&jt->estimator, x, c->t);
	/* before a frequency is measured, the law's own: sqrt(k / I) */
	double omega = jt->estimator.frequency > 0.0 ? phase_estimator_omega(&jt->estimator)
	                                            : sqrt(c->p.osc[j].k / c->p.osc[j].inertia);
	jt->phase = phase_from_state(x, jt->speed, omega);
}

void ctl_step(struct ctl *c, double t, double dt, double t_real)
{
	c->t = t;
	for (size_t j = 0; j < c->n; j++) {
		struct ctl_joint *jt = &c->j[j];
		ctl_check_stale(c, j);
		ctl_report_errbits(c, j);
		ctl_fault_step(c, j);
		if (jt->fresh && jt->resumed) {
			jt->resumed = false;
			ctl_blend_joint(c, j, jt->goal);
		}
	}
	ctl_count_still(c);
	ctl_check_stall(c);
	if (c->starter_active && c->t >= c->starter_until) {
		/* the starter hands over to the oscillator: cross-fade, no step */
		c->starter_active = false;
		/* under torque actuation the law takes the moving state as it is */
		if (c->mode == CFG_MODE_OSCILLATOR && c->cfg->actuation != CFG_ACT_TORQUE) {
			c->fade_mode = CFG_MODE_SINUSOID;
			c->fade_t0 = c->t;
		}
	}
	char what[CTL_LATCH_TEXT];
	if (tq_check_limits(c, what, sizeof what))
		ctl_latch(c, what);
	if (tq_check_supply(c, what, sizeof what))
		ctl_latch(c, what);
	c->sync = CTL_SYNC_GOAL;
	bool want = tq_want_wheel(c);
	if (want && c->wheel) {
		c->sync = CTL_SYNC_DUTY;
		tq_duties(c, dt, t_real);
		for (size_t j = 0; j < c->n; j++) {
			ctl_update_estimates(c, j);
			c->j[j].fresh = false;
		}
		return;
	}
	if (!want && c->wheel)
		tq_leave_wheel(c);
	double target[CFG_MAX_JOINTS];
	ctl_targets(c, c->bus_hold && c->mode != CFG_MODE_LIMP ? CFG_MODE_HOLD : c->mode, dt, t_real, target);
	ctl_crossfade(c, dt, t_real, target);
	for (size_t j = 0; j < c->n; j++) {
		double w = ctl_blend_weight(c, j);
		if (w < 1.0 && isfinite(target[j]))
			target[j] = c->blend_from[j] + w * (target[j] - c->blend_from[j]);
		else if (w >= 1.0)
			c->blend_from[j] = NAN;
		ctl_finish_joint(c, j, target[j]);
		c->j[j].duty = NAN;
		c->j[j].torque_cmd = NAN;
	}
	if (c->sync == CTL_SYNC_GOAL_STOP)
		tq_stop_goals(c);
	/* into wheel mode after this cycle's goals: the joint is held where it
	 * is for the half millisecond until the limits are written */
	if (want)
		tq_enter_wheel(c);
	for (size_t j = 0; j < c->n; j++) {
		ctl_update_estimates(c, j);
		c->j[j].fresh = false;
	}
}
