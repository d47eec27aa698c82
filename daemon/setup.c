/* setup.c — see setup.h. */
#include "setup.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dxl.h"
#include "dxl2.h"
#include "dxl_table.h"
#include "log.h"
#include "setup_priv.h"

static bool setup_find(struct bus *bus, const struct ctl *ctl, const struct cfg *cfg, size_t on_bus,
                       const char *port_path, char *err, size_t cap)
{
	char missing[128] = "";
	size_t nmissing = 0;
	for (size_t j = 0; j < ctl->n; j++) {
		if (!ctl_on_bus(ctl, j, on_bus))
			continue;
		uint8_t id = ctl->j[j].id, eb = 0;
		int r = DXL_E_TIMEOUT;
		for (int t = 0; t < SETUP_TRIES && r != DXL_OK; t++) {
			setup_pause(bus, t, id, "PING", r);
			r = bus_ping(bus, id, &eb);
			if (r == DXL_E_DISCONNECTED || r == DXL_E_IO) {
				snprintf(err, cap, "%s: %s while pinging servo %u", port_path, dxl_strerror(r), id);
				return false;
			}
		}
		if (r != DXL_OK) {
			size_t len = strlen(missing);
			snprintf(missing + len, sizeof missing - len, "%s%u", nmissing ? ", " : "", id);
			nmissing++;
		}
	}
	if (nmissing == 0)
		return true;
	/* servos new from the factory at another rate than the one configured:
	 * said, with the command that raises them */
	const struct sm_setup *s = sm_family(bus_proto(bus)->number)->setup;
	char factory[160] = "";
	if (s->factory_baud != 0 && cfg->baud != s->factory_baud)
		snprintf(factory, sizeof factory, "; %s servos leave the factory at %ld bps: `dxl %s--port PATH --baud %ld "
		         "setup IDS` raises them to 1 Mbps", s->family, s->factory_baud, s->dxl_opt, s->factory_baud);
	snprintf(err, cap, "servo ID%s %s did not answer a PING on %s at %ld bps (%d tries each): check power, "
	         "wiring, the IDs and the baud rate (`dxl --port PATH scan --bauds all`)%s", nmissing > 1 ? "s" : "",
	         missing, port_path, cfg->baud, SETUP_TRIES, factory);
	return false;
}

bool setup_protocol(struct bus *bus, const struct cfg *cfg, const char *port_path, enum bus_protocol *found,
                    char *err, size_t cap)
{
	/* which backends protocol = auto tries, in order, the AX-12's first
	 * (the daemon's second branch on the protocol: dmn_protocol) */
	static const enum bus_protocol order[] = { BUS_PROTOCOL_1, BUS_PROTOCOL_2 };
	int r = DXL_E_TIMEOUT;
	/* round after round, each ID on each protocol once: a servo that was
	 * only late answers a later round, and no round's wait is logged as a
	 * failure (one of the two protocols never answers) */
	for (int t = 0; t < SETUP_TRIES; t++) {
		if (t > 0)
			(void)bus_settle(bus, (uint32_t)t * SETUP_QUIET_US, SETUP_SETTLE_MAX_US);
		for (size_t j = 0; j < cfg->njoints; j++) {
			for (size_t k = 0; k < sizeof order / sizeof order[0]; k++) {
				uint8_t eb = 0;
				bus_set_protocol(bus, order[k]);
				r = bus_ping(bus, cfg->ids[j], &eb);
				if (r == DXL_E_DISCONNECTED || r == DXL_E_IO) {
					snprintf(err, cap, "%s: %s while looking for the servos' protocol", port_path,
					         dxl_strerror(r));
					return false;
				}
				if (r != DXL_OK)
					continue;
				*found = order[k];
				const struct dxl_proto *pr = bus_proto(bus);
				log_info("protocol: servo %u answered a Protocol %s PING on %s at %ld bps: Protocol %s (%s)",
				         cfg->ids[j], pr->name, port_path, cfg->baud, pr->name, sm_family(pr->number)->setup->family);
				return true;
			}
		}
	}
	bus_set_protocol(bus, BUS_PROTOCOL_1);
	snprintf(err, cap, "no servo (ID%s %u%s) answered a PING on %s at %ld bps, on Protocol 1.0 or 2.0 (%d rounds): "
	         "check power, wiring, the IDs and the baud rate (`dxl --port PATH scan --bauds all`); X-series servos "
	         "leave the factory at 57600 bps: `dxl --protocol 2 --port PATH --baud 57600 setup IDS` raises them to "
	         "1 Mbps", cfg->njoints > 1 ? "s" : "", cfg->ids[0], cfg->njoints > 1 ? ", ..." : "", port_path, cfg->baud,
	         SETUP_TRIES);
	return false;
}

/* Little-endian, n bytes (1, 2 or 4) of the settings read at start. */
static uint32_t setup_get(const uint8_t *t, uint16_t addr, size_t n)
{
	uint32_t v = 0;
	for (size_t i = n; i-- > 0;)
		v = v << 8 | t[addr + i];
	return v;
}

/* A start-up WRITE of value's n low bytes, tried again (setup_io.c); one that
 * fails or that the servo refuses (sm_write_refused) is said in *err. */
static bool setup_put(struct bus *bus, const struct sm_model *m, uint8_t id, bool reply, uint16_t addr,
                      uint32_t value, size_t n, const char *what, char *err, size_t cap)
{
	uint8_t data[4] = { (uint8_t)value, (uint8_t)(value >> 8), (uint8_t)(value >> 16), (uint8_t)(value >> 24) };
	uint8_t eb = 0;
	int r = setup_write(bus, id, addr, data, n, reply, &eb);
	if (r == DXL_OK && sm_write_refused(m, eb)) {
		char why[48];
		snprintf(err, cap, "servo %u: %s refused (%s)", id, what, bus_proto(bus)->err_format(eb, why, sizeof why));
		return false;
	}
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: %s failed: %s", id, what, dxl_strerror(r));
		return false;
	}
	return true;
}

/* Present Position (the model's setup.position, goal_size bytes). */
static int setup_read_position(struct bus *bus, const struct sm_model *m, uint8_t id, int32_t *pos)
{
	uint8_t raw[4], eb = 0;
	int r = setup_read(bus, id, m->setup->position, m->goal_size, raw, &eb);
	if (r == DXL_OK)
		*pos = (int32_t)setup_get(raw, 0, m->goal_size);
	return r;
}

/* The model the settings name; NULL with *err when it is refused. A model
 * number this daemon does not know is refused where the family's models
 * differ (sm_setup.strict) and said where there is one table. */
static const struct sm_model *setup_model(struct bus *bus, const struct sm_model *family, const uint8_t *t, uint8_t id,
                                          const struct cfg *cfg, char *err, size_t cap)
{
	uint16_t number = (uint16_t)setup_get(t, 0, 2);
	const struct sm_model *m = sm_by_number(family->protocol, number);
	if (m == NULL && !family->setup->strict) {
		log_warn("servo %u: model number %u is not an %s (%u); continuing with the %s table", id, number,
		         family->setup->family, family->number, family->setup->family);
		return family;
	}
	if (m == NULL) {
		char known[160];
		snprintf(err, cap, "servo %u: model number %u is none undulated drives on Protocol %s (%s): its "
		         "registers may differ", id, number, bus_proto(bus)->name, dxl2_model_names(family->protocol, known, sizeof known));
		return NULL;
	}
	/* a drive chosen by Operating Mode has a current mode only where the
	 * servo senses its current; the AX-12's wheel mode drives whatever its
	 * Moving Speed is taken to be */
	if (cfg->actuation == CFG_ACT_TORQUE && cfg->torque_drive == CFG_DRIVE_CURRENT && sm_has(m, SM_CAP_OPMODE) &&
	    !m->current_control) {
		snprintf(err, cap, "servo %u is an %s, which has no current control: torque_drive = current needs a "
		         "servo that senses its current (an XM430); use torque_drive = pwm (PWM control, the back-EMF added "
		         "back)", id, m->name);
		return NULL;
	}
	return m;
}

/* Torque actuation found a servo in wheel mode (AX-12: the daemon was
 * stopped without its safe stop, or the bus went away while the law drove
 * it): stop the drive, make the present position the goal, and give it
 * angle limits again — the configured joint limits — so joint mode holds it. */
static bool setup_restore_joint_mode(struct bus *bus, const struct sm_model *m, uint8_t id, const struct cfg_joint *cj,
                                     struct ctl_servo_info *info, char *err, size_t cap)
{
	uint8_t eb = 0, raw[2];
	bool reply = info->status_return_level >= 2;
	int r = setup_read(bus, id, m->setup->position, 2, raw, &eb);
	/* Goal Position and Moving Speed (the drive), adjacent */
	uint8_t stop[4] = { raw[0], raw[1], 0, 0 }, off = 0;
	if (r == DXL_OK)
		r = setup_write(bus, id, m->goal, stop, 4, reply, &eb);
	/* EEPROM: the AX-12A takes it only with torque off; ctl_start() turns
	 * torque on again */
	if (r == DXL_OK)
		r = setup_write(bus, id, m->torque_enable, &off, 1, reply, &eb);
	int32_t lo, hi;
	setup_joint_limits_model(m, cj, &lo, &hi);
	uint8_t limits[4];
	dxl_put_u16(limits, (uint16_t)lo);
	dxl_put_u16(limits + 2, (uint16_t)hi);
	if (r == DXL_OK)
		r = setup_write(bus, id, m->setup->angle_limits, limits, 4, reply, &eb);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: in wheel mode, and putting it back in joint mode failed: %s", id,
		         dxl_strerror(r));
		return false;
	}
	log_warn("servo %u was in wheel mode: drive stopped, angle limits set to the joint's %ld..%ld", id, (long)lo,
	         (long)hi);
	info->cw_limit = (uint16_t)lo;
	info->ccw_limit = (uint16_t)hi;
	return true;
}

/* Operating Mode: position control, or put back from a torque-actuated run's
 * drive (as the AX-12's wheel mode is). Anything else is refused: the
 * daemon does not guess why it is so. */
static bool setup_mode_ok(const struct sm_model *m, uint8_t mode, uint8_t id, const struct cfg *cfg,
                          const char *port_path, char *err, size_t cap)
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
	const char *o = m->setup->dxl_opt;
	snprintf(err, cap, "servo %u is in operating mode %u (%s): undulated drives position control (%d); fix: "
	         "dxl %s--port %s torque %u off; dxl %s--port %s write %u operating_mode %d", id, mode,
	         name != NULL ? name : "unknown", SM_OPMODE_POSITION, o, port_path, id, o, port_path, id,
	         SM_OPMODE_POSITION);
	return false;
}

/* Operating Mode and Min/Max Position Limit are EEPROM, which takes writes
 * only with torque off: it is turned off for them, once, and only when one
 * differs; ctl_start() turns it on again. */
static bool setup_opmode(struct bus *bus, const struct sm_model *m, uint8_t id, const uint8_t *t,
                         const struct cfg_joint *cj, struct ctl_servo_info *info, char *err, size_t cap)
{
	const struct sm_setup *s = m->setup;
	bool reply = info->status_return_level >= 2;
	int32_t lo, hi;
	setup_joint_limits_model(m, cj, &lo, &hi);
	int32_t min = (int32_t)setup_get(t, s->pos_limit_min, 4), max = (int32_t)setup_get(t, s->pos_limit_max, 4);
	bool mode = t[s->opmode] != SM_OPMODE_POSITION, limits = min != lo || max != hi;
	if ((mode || limits) && t[m->torque_enable] &&
	    !setup_put(bus, m, id, reply, m->torque_enable, 0, 1, "torque off (for its EEPROM)", err, cap))
		return false;
	if (mode && !setup_put(bus, m, id, reply, s->opmode, SM_OPMODE_POSITION, 1, "operating mode 3", err, cap))
		return false;
	if (limits) {
		if (!setup_put(bus, m, id, reply, s->pos_limit_min, (uint32_t)lo, 4, "min position limit", err, cap) ||
		    !setup_put(bus, m, id, reply, s->pos_limit_max, (uint32_t)hi, 4, "max position limit", err, cap))
			return false;
		log_info("servo %u: position limits %ld..%ld set to the configuration's %ld..%ld (neutral %+.3f + "
		         "[%.3f, %.3f] rad)", id, (long)min, (long)max, (long)lo, (long)hi, cj->neutral, cj->limit_min,
		         cj->limit_max);
	}
	info->cw_limit = (uint16_t)lo;
	info->ccw_limit = (uint16_t)hi;
	return true;
}

/* Joint mode as the loop expects it: by Operating Mode (SM_CAP_OPMODE), or
 * by angle limits, where only torque actuation's wheel mode is put back (in
 * position actuation ctl_set_servo refuses a servo in wheel mode, saying how
 * to fix it). */
static bool setup_joint_mode(struct bus *bus, const struct sm_model *m, uint8_t id, const uint8_t *t,
                             const struct cfg *cfg, const struct cfg_joint *cj, const char *port_path,
                             struct ctl_servo_info *info, char *err, size_t cap)
{
	if (sm_has(m, SM_CAP_OPMODE))
		return setup_mode_ok(m, t[m->setup->opmode], id, cfg, port_path, err, cap) &&
		       setup_opmode(bus, m, id, t, cj, info, err, cap);
	if (cfg->actuation == CFG_ACT_TORQUE && dxl_is_wheel_mode(info->cw_limit, info->ccw_limit))
		return setup_restore_joint_mode(bus, m, id, cj, info, err, cap);
	return true;
}

/* What makes every goal a slow ramp (AX-12 Moving Speed, X profiles), left
 * non-zero by another program, is set to 0: the oscillator would be
 * sluggish. An unanswered read leaves it. */
static bool setup_no_ramp(struct bus *bus, const struct sm_model *m, uint8_t id, bool reply, char *err, size_t cap)
{
	const struct sm_setup *s = m->setup;
	uint8_t raw[8], eb = 0;
	size_t n = (size_t)s->ramp_size * s->nramp;
	if (setup_read(bus, id, s->ramp, (uint16_t)n, raw, &eb) != DXL_OK)
		return true;
	char was[40] = "";
	bool set = false;
	for (size_t k = 0; k < s->nramp; k++) {
		uint32_t v = setup_get(raw, (uint16_t)(k * s->ramp_size), s->ramp_size);
		size_t len = strlen(was);
		snprintf(was + len, sizeof was - len, "%s%u", k > 0 ? ", " : "", v);
		set = set || v != 0;
	}
	if (!set)
		return true;
	log_warn("servo %u: %s was %s (another program's); setting 0 (no ramp)", id, s->ramp_name, was);
	for (size_t k = 0; k < s->nramp; k++)
		if (!setup_put(bus, m, id, reply, (uint16_t)(s->ramp + k * s->ramp_size), 0, s->ramp_size,
		               "setting no ramp", err, cap))
			return false;
	return true;
}

/* RAM the loop relies on, written at every (re)connect (a power loss or a
 * REBOOT resets it; the read-back checks it afterwards): the compliance
 * margins and slopes where the servo has them, no ramp, a bus watchdog
 * cleared if it had stopped the servo, then set where it has one. */
static bool setup_ram(struct bus *bus, const struct sm_model *m, uint8_t id, const uint8_t *t, const struct cfg *cfg,
                      bool reply, char *err, size_t cap)
{
	const struct sm_setup *s = m->setup;
	char what[48];
	if (s->compliance_margin != 0 && cfg->compliance_margin >= 0) {
		uint32_t v = (uint32_t)cfg->compliance_margin;
		snprintf(what, sizeof what, "setting compliance margin %u", v);
		if (!setup_put(bus, m, id, reply, s->compliance_margin, v | v << 8, 2, what, err, cap))
			return false;
	}
	if (s->compliance_slope != 0 && cfg->compliance_slope >= 0) {
		uint32_t v = (uint32_t)cfg->compliance_slope;
		snprintf(what, sizeof what, "setting compliance slope %u", v);
		if (!setup_put(bus, m, id, reply, s->compliance_slope, v | v << 8, 2, what, err, cap))
			return false;
	}
	if (!setup_no_ramp(bus, m, id, reply, err, cap))
		return false;
	if (s->watchdog == 0)
		return true;
	if (t[s->watchdog] == SM_WATCHDOG_TRIPPED) {
		log_warn("servo %u: its bus watchdog had stopped it (its controller before was silent too long): cleared", id);
		if (!setup_put(bus, m, id, reply, s->watchdog, 0, 1, "bus watchdog 0", err, cap))
			return false;
	}
	if (cfg->bus_watchdog_ms < 0)
		return true;   /* the servo's own */
	return setup_put(bus, m, id, reply, s->watchdog, cfg_watchdog_units(cfg), 1, "bus watchdog", err, cap);
}

/* Goal Position where the joint stands (inside its limits): whatever another
 * program or a drive mode left there is not where torque-on may take the
 * joint before the first cycle's goal. (An AX-12's goal is set so where its
 * wheel mode is put back, the one drive it has.) */
static bool setup_goal_here(struct bus *bus, const struct sm_model *m, uint8_t id, const struct ctl_servo_info *info,
                            char *err, size_t cap)
{
	int32_t pos = 0;
	int r = setup_read_position(bus, m, id, &pos);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: reading its position failed: %s", id, dxl_strerror(r));
		return false;
	}
	pos = pos < info->cw_limit ? info->cw_limit : pos > info->ccw_limit ? info->ccw_limit : pos;
	return setup_put(bus, m, id, info->status_return_level >= 2, m->goal, (uint32_t)pos, m->goal_size,
	                 "goal position", err, cap);
}

/* What the settings say that start-up cannot mend, or says: a status return
 * level of 0, an output limit of 0, a hardware error, a return delay. */
static bool setup_judge(const struct sm_model *m, uint8_t id, const uint8_t *t, const struct cfg *cfg,
                        const char *port_path, struct ctl_servo_info *info, char *err, size_t cap)
{
	const struct sm_setup *s = m->setup;
	if (info->status_return_level == 0) {
		snprintf(err, cap, "servo %u: status return level 0 (answers PING only): set it to 2 "
		         "(`dxl %s--port %s write %u status_return_level 2`)", id, s->dxl_opt, port_path, id);
		return false;
	}
	if (info->max_torque == 0 && s->strict) {
		snprintf(err, cap, "servo %u: %s (EEPROM) is 0: it cannot move (`dxl %s--port %s write %u %s %u`)", id,
		         s->output_limit_name, s->dxl_opt, port_path, id, sm_register_name(m, s->output_limit),
		         m->torque_full);
		return false;
	}
	if (info->max_torque == 0) {
		log_warn("servo %u: %s (EEPROM) is 0: it cannot move; using %u as torque limit", id, s->output_limit_name,
		         m->torque_full);
		info->max_torque = (uint16_t)m->torque_full;
	}
	uint8_t hwerr = sm_has(m, SM_CAP_HWERR) ? t[s->hwerr] : 0;
	if (hwerr != 0) {
		char names[96];
		log_warn("servo %u: hardware error status %u (%s) at start: it %s until a REBOOT (fault_reboots = %d: "
		         "undulated may send one)", id, hwerr, dxl2_hwerr_format(hwerr, names, sizeof names),
		         (hwerr & t[s->shutdown]) ? "keeps its torque off" : "raises the alert", cfg->fault_reboots);
	}
	return true;
}

static bool setup_servo(struct bus *bus, struct ctl *ctl, size_t j, const struct cfg *cfg, const char *port_path,
                        int *max_return_delay_us, char *err, size_t cap)
{
	const struct sm_model *family = sm_family(bus_proto(bus)->number);
	uint8_t id = ctl->j[j].id, eb = 0, t[SM_SETTINGS_MAX];
	int r = setup_read(bus, id, 0, family->setup->settings_len, t, &eb);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: reading its settings failed: %s", id, dxl_strerror(r));
		return false;
	}
	const struct sm_model *m = setup_model(bus, family, t, id, cfg, err, cap);
	if (m == NULL)
		return false;
	const struct sm_setup *s = m->setup;
	struct ctl_servo_info info = {
		.cw_limit = s->angle_limits != 0 ? (uint16_t)setup_get(t, s->angle_limits, 2) : 0,
		.ccw_limit = s->angle_limits != 0 ? (uint16_t)setup_get(t, (uint16_t)(s->angle_limits + 2), 2) : 0,
		.max_torque = (uint16_t)setup_get(t, s->output_limit, 2),
		.current_limit = m->current_control ? (uint16_t)setup_get(t, s->current_limit, 2) : 0,
		.return_delay = t[s->return_delay],
		.status_return_level = t[s->status_return_level],
		.model = m,
		.firmware = t[s->firmware],
	};
	bool reply = info.status_return_level >= 2;
	if (!setup_judge(m, id, t, cfg, port_path, &info, err, cap) ||
	    !setup_joint_mode(bus, m, id, t, cfg, &cfg->joint[j], port_path, &info, err, cap) ||
	    !setup_ram(bus, m, id, t, cfg, reply, err, cap) ||
	    (sm_has(m, SM_CAP_OPMODE) && !setup_goal_here(bus, m, id, &info, err, cap)))
		return false;
	unsigned delay_us = dxl_return_delay_us(info.return_delay);   /* 2 µs a unit on every family */
	if (delay_us > 0)
		log_warn("servo %u: return delay %u µs costs %.1f ms a cycle on the bus; set it to 0 with "
		         "`dxl %s--port %s setup %u`", id, delay_us, 1e-3 * delay_us, s->dxl_opt, port_path, id);
	if ((int)delay_us > *max_return_delay_us)
		*max_return_delay_us = (int)delay_us;
	return ctl_set_servo(ctl, j, &info, err, cap);
}

bool setup_fast_read(const struct bus *bus, const struct ctl *ctl, char *why, size_t cap)
{
	return setup_fast_read_on(bus, ctl, CFG_BUS_ROBOT, why, cap);
}

bool setup_fast_read_on(const struct bus *bus, const struct ctl *ctl, size_t on_bus, char *why, size_t cap)
{
	if (!dxl_proto_can(bus_proto(bus), DXL_CAP_FAST_READ)) {
		snprintf(why, cap, "Protocol %s has none", bus_proto(bus)->name);
		return false;
	}
	size_t at = 0;
	for (size_t j = 0; j < ctl->n; j++) {
		if (!ctl_on_bus(ctl, j, on_bus))
			continue;
		const struct ctl_servo_info *s = &ctl->j[j].servo;
		const char *name = s->model != NULL ? s->model->name : "?";
		if (!dxl2_model_fast_read(s->model != NULL ? s->model->desc : NULL, s->firmware)) {
			snprintf(why, cap, "servo %u (%s, firmware %u) does not answer it (the e-manual: X430/X540 from "
			         "firmware 45)", ctl->j[j].id, name, s->firmware);
			return false;
		}
		int w = snprintf(why + at, at < cap ? cap - at : 0, "%sservo %u %s firmware %u", at ? ", " : "",
		                 ctl->j[j].id, name, s->firmware);
		at += w > 0 ? (size_t)w : 0;
	}
	return at > 0;
}

bool setup_servos(struct bus *bus, struct ctl *ctl, const struct cfg *cfg, size_t on_bus, const char *port_path,
                  int *max_return_delay_us, char *err, size_t cap)
{
	*max_return_delay_us = 0;
	if (!setup_find(bus, ctl, cfg, on_bus, port_path, err, cap))
		return false;
	for (size_t j = 0; j < ctl->n; j++)
		if (ctl_on_bus(ctl, j, on_bus) && !setup_servo(bus, ctl, j, cfg, port_path, max_return_delay_us, err, cap))
			return false;
	return true;
}

bool setup_read_present(struct bus *bus, struct ctl *ctl, size_t on_bus, double dt, char *err, size_t cap)
{
	for (size_t j = 0; j < ctl->n; j++) {
		if (!ctl_on_bus(ctl, j, on_bus))
			continue;
		const struct sm_model *m = ctl_model(ctl, j);
		uint8_t id = ctl->j[j].id, eb = 0, p[32];
		struct sm_present pr;
		int r = setup_read(bus, id, m->present, m->present_len, p, &eb);
		if (r == DXL_OK && !sm_decode_present(m, p, m->present_len, &pr))
			r = DXL_E_WRONG_LENGTH;
		if (r != DXL_OK) {
			snprintf(err, cap, "servo %u: reading its position failed: %s", id, dxl_strerror(r));
			return false;
		}
		ctl_measure_present(ctl, j, &pr, eb, dt);
	}
	return true;
}

/* ---- the safe stop --------------------------------------------------------------------------- */
/* One joint back from torque actuation's drive to joint mode, its drive
 * stopped already: torque off (EEPROM: the angle limits and Operating Mode
 * take writes only so), joint mode (angle limits | Operating Mode 3), the
 * output limit back where the drive was it (X: Goal PWM), torque on unless
 * limp. An AX-12 takes its goal first: it moves to it the moment it has
 * angle limits. Stops at the first write that fails, saying so. */
static void setup_stop_drive_joint(struct bus *bus, const struct ctl *ctl, size_t j, bool limp)
{
	const struct ctl_joint *jt = &ctl->j[j];
	const struct sm_model *m = ctl_model(ctl, j);
	bool reply = jt->servo.status_return_level >= 2, opmode = sm_has(m, SM_CAP_OPMODE);
	char err[160] = "";
	bool ok = true;
	if (!opmode) {
		int32_t pos = 0;
		int r = setup_read_position(bus, m, jt->id, &pos);
		if (r != DXL_OK)
			snprintf(err, sizeof err, "servo %u: reading its position failed: %s", jt->id, dxl_strerror(r));
		ok = r == DXL_OK && setup_put(bus, m, jt->id, reply, m->goal,
		                              (uint32_t)sm_rad_to_pos(m, safety_clamp(&jt->limits, sm_pos_to_rad(m, pos), NAN,
		                                                                      NAN, NULL)),
		                              m->goal_size, "goal position", err, sizeof err);
	}
	ok = ok && setup_put(bus, m, jt->id, reply, m->torque_enable, 0, 1, "torque off", err, sizeof err);
	if (opmode)
		ok = ok && setup_put(bus, m, jt->id, reply, m->setup->opmode, SM_OPMODE_POSITION, 1, "position control",
		                     err, sizeof err);
	else
		ok = ok && setup_put(bus, m, jt->id, reply, m->setup->angle_limits, ctl_joint_mode_limits(ctl, j), 4,
		                     "angle limits", err, sizeof err);
	if (!limp && sm_limit_is_pwm_drive(m))
		ok = ok && setup_put(bus, m, jt->id, reply, m->torque_limit, jt->servo.max_torque, 2, "goal PWM", err,
		                     sizeof err);
	if (!limp)
		ok = ok && setup_put(bus, m, jt->id, reply, m->torque_enable, 1, 1, "torque on", err, sizeof err);
	if (!ok)
		log_error("safe stop: %s; its drive was stopped", err);
}

/* Torque actuation at exit: no servo may be left driving. Every drive
 * stopped at once (one packet), then each servo back in joint mode; the
 * safe state then holds or goes limp. */
static void setup_stop_drive(struct bus *bus, const struct ctl *ctl, size_t on_bus, bool limp)
{
	uint8_t ids[CFG_MAX_JOINTS], zero[2 * CFG_MAX_JOINTS] = { 0 };
	const struct sm_model *m = ctl_model(ctl, 0);
	size_t n = 0;
	for (size_t j = 0; j < ctl->n; j++)
		if (ctl_on_bus(ctl, j, on_bus))
			ids[n++] = ctl->j[j].id;
	bus_sync_write(bus, sm_drive_register(m, ctl->cfg->torque_drive == CFG_DRIVE_CURRENT), 2, ids, zero, n);
	for (size_t j = 0; j < ctl->n; j++)
		if (ctl_on_bus(ctl, j, on_bus))
			setup_stop_drive_joint(bus, ctl, j, limp);
	log_info("safe stop: torque actuation ended, servos back in %s",
	         sm_has(m, SM_CAP_OPMODE) ? "position control" : "joint mode");
}

/* A bus watchdog left set would stop the servos by itself once this daemon
 * is gone (and after a trip the goals refuse writes): cleared first. */
static void setup_stop_watchdogs(struct bus *bus, const struct ctl *ctl, size_t on_bus)
{
	for (size_t j = 0; j < ctl->n; j++) {
		if (!ctl_on_bus(ctl, j, on_bus))
			continue;
		const struct ctl_joint *jt = &ctl->j[j];
		const struct sm_model *m = ctl_model(ctl, j);
		char err[160];
		if (m->setup->watchdog != 0 && !setup_put(bus, m, jt->id, jt->servo.status_return_level >= 2,
		                                          m->setup->watchdog, 0, 1, "bus watchdog 0", err, sizeof err))
			log_error("safe stop: %s", err);
	}
}

void setup_safe_stop(struct bus *bus, const struct ctl *ctl, const struct cfg *cfg, size_t on_bus)
{
	bus_abort(bus);
	/* a robot that is limp stays limp: writing goals could bring torque back */
	bool limp = cfg->safe_stop == CFG_SAFE_LIMP || ctl->mode == CFG_MODE_LIMP;
	const struct sm_model *m0 = ctl_model(ctl, 0);
	setup_stop_watchdogs(bus, ctl, on_bus);
	if (ctl->wheel)
		setup_stop_drive(bus, ctl, on_bus, limp);
	uint8_t ids[CFG_MAX_JOINTS], data[4 * CFG_MAX_JOINTS];
	size_t n = 0;
	for (size_t j = 0; j < ctl->n; j++) {
		if (!ctl_on_bus(ctl, j, on_bus))
			continue;
		const struct ctl_joint *jt = &ctl->j[j];
		const struct sm_model *m = ctl_model(ctl, j);
		int32_t pos = 0;
		if (limp) {
			setup_limp(bus, jt);
			continue;
		}
		if (setup_read_position(bus, m, jt->id, &pos) != DXL_OK) {
			log_error("safe stop: servo %u did not answer; it keeps its last goal", jt->id);
			continue;
		}
		double at = sm_pos_to_rad(m, pos);
		double hold = isfinite(jt->limits.lo) && jt->limits.max_step > 0 ? safety_clamp(&jt->limits, at, NAN, NAN, NULL)
		                                                                  : at;
		uint32_t goal = (uint32_t)sm_rad_to_pos(m, hold);
		ids[n] = jt->id;
		for (size_t b = 0; b < m0->goal_size; b++)
			data[m0->goal_size * n + b] = (uint8_t)(goal >> (8 * b));
		n++;
	}
	if (n > 0)
		bus_sync_write(bus, m0->goal, m0->goal_size, ids, data, n);
	log_info("safe stop: %s%s", limp ? "torque off (limp)" : "holding present positions, torque on",
	         m0->setup->watchdog != 0 ? "; bus watchdogs off" : "");
}
