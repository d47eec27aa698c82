/* setup_x.c — start-up and safe stop of X-series servos (setup.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dxl2.h"
#include "dxl2_table.h"
#include "log.h"
#include "setup_priv.h"

/* One READ at start-up covers the model (0) to the bus watchdog (98): mode,
 * limits, shutdown, torque, status return level, hardware error. */
#define SETUP_X_TABLE_LEN (DXL2_X_BUS_WATCHDOG + 1)

static int32_t setup_x_get(const uint8_t *t, const struct sm_model *m, uint16_t addr)
{
	const struct dxl2_reg *r = dxl2_reg_at(dxl2_model_by_number(m->number), addr);
	return r != NULL ? dxl2_reg_decode(r, &t[addr]) : 0;
}

static bool setup_x_write(struct bus *bus, uint8_t id, uint16_t addr, uint32_t value, size_t n, const char *what,
                          char *err, size_t cap)
{
	uint8_t data[4] = { (uint8_t)value, (uint8_t)(value >> 8), (uint8_t)(value >> 16), (uint8_t)(value >> 24) };
	uint8_t eb = 0;
	int r = setup_write(bus, id, addr, data, n, true, &eb);
	if (r == DXL_OK && dxl2_err_number(eb) != DXL2_ERRNUM_NONE) {
		char why[48];
		snprintf(err, cap, "servo %u: %s refused (%s)", id, what, dxl2_err_format(eb, why, sizeof why));
		return false;
	}
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: %s failed: %s", id, what, dxl_strerror(r));
		return false;
	}
	return true;
}

/* The model, and the drive torque actuation needs of it. */
static const struct sm_model *setup_x_model(const uint8_t *t, uint8_t id, const struct cfg *cfg, char *err, size_t cap)
{
	uint16_t number = dxl_get_u16(&t[DXL2_X_MODEL_NUMBER]);
	const struct sm_model *m = sm_by_number(2, number);
	if (m == NULL) {
		char known[160];
		snprintf(err, cap, "servo %u: model number %u is none undulated drives on Protocol 2.0 (%s): its "
		         "registers may differ", id, number, dxl2_model_names(2, known, sizeof known));
		return NULL;
	}
	if (cfg->actuation == CFG_ACT_TORQUE && cfg->torque_drive == CFG_DRIVE_CURRENT && !m->current_control) {
		snprintf(err, cap, "servo %u is an %s, which has no current control: torque_drive = current needs a "
		         "servo that senses its current (an XM430); use torque_drive = pwm (PWM control, the back-EMF added "
		         "back)", id, m->name);
		return NULL;
	}
	return m;
}

/* Operating Mode: position control, or put back from a torque-actuated run's
 * drive (as the AX-12's wheel mode is). Anything else is refused: the
 * daemon does not guess why it is so. */
static bool setup_x_mode_ok(uint8_t mode, uint8_t id, const struct cfg *cfg, const char *port_path, char *err,
                            size_t cap)
{
	if (mode == SM_OPMODE_POSITION)
		return true;
	bool ours = cfg->actuation == CFG_ACT_TORQUE && mode == sm_drive_opmode(cfg->torque_drive == CFG_DRIVE_CURRENT);
	if (ours) {
		log_warn("servo %u was in %s control (a torque-actuated run that did not stop cleanly): back to position "
		         "control", id, dxl2_opmode_name(mode));
		return true;
	}
	const char *name = dxl2_opmode_name(mode);
	snprintf(err, cap, "servo %u is in operating mode %u (%s): undulated drives position control (3); fix: "
	         "dxl --protocol 2 --port %s torque %u off; dxl --protocol 2 --port %s write %u operating_mode 3", id, mode,
	         name != NULL ? name : "unknown", port_path, id, port_path, id);
	return false;
}

/* EEPROM (Operating Mode, position limits) takes writes only with torque
 * off: it is turned off for them, once, and only when one differs;
 * ctl_start() turns it on again. */
static bool setup_x_eeprom(struct bus *bus, uint8_t id, const uint8_t *t, const struct sm_model *m,
                           const struct cfg_joint *cj, struct ctl_servo_info *info, char *err, size_t cap)
{
	int32_t lo, hi;
	setup_joint_limits_model(m, cj, &lo, &hi);
	int32_t min = setup_x_get(t, m, DXL2_X_MIN_POSITION_LIMIT), max = setup_x_get(t, m, DXL2_X_MAX_POSITION_LIMIT);
	bool mode = t[DXL2_X_OPERATING_MODE] != SM_OPMODE_POSITION, limits = min != lo || max != hi;
	if ((mode || limits) && t[DXL2_X_TORQUE_ENABLE] &&
	    !setup_x_write(bus, id, DXL2_X_TORQUE_ENABLE, 0, 1, "torque off (for its EEPROM)", err, cap))
		return false;
	if (mode && !setup_x_write(bus, id, DXL2_X_OPERATING_MODE, SM_OPMODE_POSITION, 1, "operating mode 3", err, cap))
		return false;
	if (limits) {
		if (!setup_x_write(bus, id, DXL2_X_MIN_POSITION_LIMIT, (uint32_t)lo, 4, "min position limit", err, cap) ||
		    !setup_x_write(bus, id, DXL2_X_MAX_POSITION_LIMIT, (uint32_t)hi, 4, "max position limit", err, cap))
			return false;
		log_info("servo %u: position limits %ld..%ld set to the configuration's %ld..%ld (neutral %+.3f + "
		         "[%.3f, %.3f] rad)", id, (long)min, (long)max, (long)lo, (long)hi, cj->neutral, cj->limit_min,
		         cj->limit_max);
	}
	info->cw_limit = (uint16_t)lo;
	info->ccw_limit = (uint16_t)hi;
	return true;
}

/* RAM the loop relies on, written at every (re)connect (a power loss or a
 * REBOOT resets it; the read-back checks it afterwards): no profile (a
 * profile makes every goal a slow ramp), the watchdog cleared if it had
 * stopped the servo, then set. */
static bool setup_x_ram(struct bus *bus, uint8_t id, const uint8_t *t, const struct sm_model *m, const struct cfg *cfg,
                        char *err, size_t cap)
{
	uint8_t prof[8];
	uint8_t eb = 0;
	if (setup_read(bus, id, DXL2_X_PROFILE_ACCELERATION, sizeof prof, prof, &eb) == DXL_OK &&
	    (dxl2_get_u32(prof) != 0 || dxl2_get_u32(prof + 4) != 0)) {
		log_warn("servo %u: profile acceleration %u, velocity %u left by another program; setting 0 (none)", id,
		         dxl2_get_u32(prof), dxl2_get_u32(prof + 4));
		if (!setup_x_write(bus, id, DXL2_X_PROFILE_ACCELERATION, 0, 4, "profile acceleration 0", err, cap) ||
		    !setup_x_write(bus, id, DXL2_X_PROFILE_VELOCITY, 0, 4, "profile velocity 0", err, cap))
			return false;
	}
	if (t[DXL2_X_BUS_WATCHDOG] == SM_WATCHDOG_TRIPPED) {
		log_warn("servo %u: its bus watchdog had stopped it (its controller before was silent too long): cleared", id);
		if (!setup_x_write(bus, id, DXL2_X_BUS_WATCHDOG, 0, 1, "bus watchdog 0", err, cap))
			return false;
	}
	(void)m;
	if (cfg->bus_watchdog_ms < 0)
		return true;   /* the servo's own */
	return setup_x_write(bus, id, DXL2_X_BUS_WATCHDOG, cfg_watchdog_units(cfg), 1, "bus watchdog", err, cap);
}

/* Goal Position where the joint stands (inside its limits): whatever another
 * program, a drive mode or an old run left there is not where torque-on may
 * take the joint before the first cycle's goal. */
static bool setup_x_goal_here(struct bus *bus, uint8_t id, const struct ctl_servo_info *info, char *err, size_t cap)
{
	uint8_t raw[4], eb = 0;
	int r = setup_read(bus, id, DXL2_X_PRESENT_POSITION, 4, raw, &eb);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: reading its position failed: %s", id, dxl_strerror(r));
		return false;
	}
	int32_t pos = (int32_t)dxl2_get_u32(raw);
	pos = pos < info->cw_limit ? info->cw_limit : pos > info->ccw_limit ? info->ccw_limit : pos;
	return setup_x_write(bus, id, DXL2_X_GOAL_POSITION, (uint32_t)pos, 4, "goal position", err, cap);
}

bool setup_servo_x(struct bus *bus, struct ctl *ctl, size_t j, const struct cfg *cfg, const char *port_path,
                   int *max_return_delay_us, char *err, size_t cap)
{
	uint8_t id = ctl->j[j].id, eb = 0, t[SETUP_X_TABLE_LEN];
	int r = setup_read(bus, id, 0, sizeof t, t, &eb);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: reading its settings failed: %s", id, dxl_strerror(r));
		return false;
	}
	const struct sm_model *m = setup_x_model(t, id, cfg, err, cap);
	if (m == NULL)
		return false;
	struct ctl_servo_info info = {
		.max_torque = (uint16_t)setup_x_get(t, m, DXL2_X_PWM_LIMIT),
		.current_limit = m->current_control ? (uint16_t)setup_x_get(t, m, DXL2_X_CURRENT_LIMIT) : 0,
		.return_delay = t[DXL2_X_RETURN_DELAY_TIME],
		.status_return_level = t[DXL2_X_STATUS_RETURN_LEVEL],
		.model = m,
	};
	if (info.status_return_level == 0) {
		snprintf(err, cap, "servo %u: status return level 0 (answers PING only): set it to 2 "
		         "(`dxl --protocol 2 --port %s write %u status_return_level 2`)", id, port_path, id);
		return false;
	}
	if (info.max_torque == 0) {
		snprintf(err, cap, "servo %u: PWM Limit (EEPROM) is 0: it cannot move (`dxl --protocol 2 --port %s write %u "
		         "pwm_limit 885`)", id, port_path, id);
		return false;
	}
	uint8_t hwerr = t[DXL2_X_HARDWARE_ERROR_STATUS];
	if (hwerr != 0) {
		char names[96];
		log_warn("servo %u: hardware error status %u (%s) at start: it %s until a REBOOT (fault_reboots = %d: "
		         "undulated may send one)", id, hwerr, dxl2_hwerr_format(hwerr, names, sizeof names),
		         (hwerr & t[DXL2_X_SHUTDOWN]) ? "keeps its torque off" : "raises the alert", cfg->fault_reboots);
	}
	if (!setup_x_mode_ok(t[DXL2_X_OPERATING_MODE], id, cfg, port_path, err, cap) ||
	    !setup_x_eeprom(bus, id, t, m, &cfg->joint[j], &info, err, cap) || !setup_x_ram(bus, id, t, m, cfg, err, cap) ||
	    !setup_x_goal_here(bus, id, &info, err, cap))
		return false;
	unsigned delay_us = dxl2_return_delay_us(info.return_delay);
	if (delay_us > 0)
		log_warn("servo %u: return delay %u µs costs %.1f ms a cycle on the bus; set it to 0 with "
		         "`dxl --protocol 2 --port %s setup %u`", id, delay_us, 1e-3 * delay_us, port_path, id);
	if ((int)delay_us > *max_return_delay_us)
		*max_return_delay_us = (int)delay_us;
	return ctl_set_servo(ctl, j, &info, err, cap);
}

/* ---- the safe stop ---------------------------------------------------------------------------- */
static void setup_x_stop_write(struct bus *bus, const struct ctl_joint *jt, uint16_t addr, uint32_t value, size_t n,
                               const char *what)
{
	char err[160];
	if (!setup_x_write(bus, jt->id, addr, value, n, what, err, sizeof err))
		log_error("safe stop: %s", err);
}

/* Torque actuation at exit: every drive stopped at once (one packet), then
 * each servo back in position control, holding where it is or limp. */
static void setup_x_stop_drive(struct bus *bus, const struct ctl *ctl, bool limp)
{
	uint8_t ids[CFG_MAX_JOINTS], zero[2 * CFG_MAX_JOINTS] = { 0 };
	bool current = ctl->cfg->torque_drive == CFG_DRIVE_CURRENT;
	for (size_t j = 0; j < ctl->n; j++)
		ids[j] = ctl->j[j].id;
	bus_sync_write(bus, sm_drive_register(ctl_model(ctl, 0), current), 2, ids, zero, ctl->n);
	for (size_t j = 0; j < ctl->n; j++) {
		const struct ctl_joint *jt = &ctl->j[j];
		setup_x_stop_write(bus, jt, DXL2_X_TORQUE_ENABLE, 0, 1, "torque off");
		setup_x_stop_write(bus, jt, DXL2_X_OPERATING_MODE, SM_OPMODE_POSITION, 1, "position control");
		if (!limp) {
			setup_x_stop_write(bus, jt, DXL2_X_GOAL_PWM, jt->servo.max_torque, 2, "goal PWM");
			setup_x_stop_write(bus, jt, DXL2_X_TORQUE_ENABLE, 1, 1, "torque on");
		}
	}
	log_info("safe stop: torque actuation ended, servos back in position control");
}

void setup_safe_stop_x(struct bus *bus, const struct ctl *ctl, bool limp)
{
	/* first: a watchdog left set would stop the servos by itself once this
	 * daemon is gone (and after a trip the goals refuse writes) */
	for (size_t j = 0; j < ctl->n; j++)
		setup_x_stop_write(bus, &ctl->j[j], DXL2_X_BUS_WATCHDOG, 0, 1, "bus watchdog 0");
	if (ctl->wheel)
		setup_x_stop_drive(bus, ctl, limp);
	uint8_t ids[CFG_MAX_JOINTS], data[4 * CFG_MAX_JOINTS];
	size_t n = 0;
	for (size_t j = 0; j < ctl->n; j++) {
		const struct ctl_joint *jt = &ctl->j[j];
		const struct sm_model *m = ctl_model(ctl, j);
		uint8_t raw[4], eb;
		if (limp) {
			setup_limp(bus, jt);
			continue;
		}
		if (setup_read(bus, jt->id, DXL2_X_PRESENT_POSITION, 4, raw, &eb) != DXL_OK) {
			log_error("safe stop: servo %u did not answer; it keeps its last goal", jt->id);
			continue;
		}
		double at = sm_pos_to_rad(m, (int32_t)dxl2_get_u32(raw));
		double hold = isfinite(jt->limits.lo) && jt->limits.max_step > 0 ? safety_clamp(&jt->limits, at, NAN, NAN, NULL)
		                                                                  : at;
		ids[n] = jt->id;
		uint32_t pos = (uint32_t)sm_rad_to_pos(m, hold);
		memcpy(&data[4 * n], (const uint8_t[4]){ (uint8_t)pos, (uint8_t)(pos >> 8), 0, 0 }, 4);
		n++;
	}
	if (n > 0)
		bus_sync_write(bus, DXL2_X_GOAL_POSITION, 4, ids, data, n);
	log_info("safe stop: %s; bus watchdogs off", limp ? "torque off (limp)" : "holding present positions, torque on");
}
