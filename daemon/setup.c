/* setup.c — see setup.h. */
#include "setup.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dxl.h"
#include "dxl_table.h"
#include "log.h"
#include "setup_priv.h"

static bool setup_find(struct bus *bus, const struct ctl *ctl, const struct cfg *cfg, const char *port_path,
                       char *err, size_t cap)
{
	char missing[128] = "";
	size_t nmissing = 0;
	for (size_t j = 0; j < ctl->n; j++) {
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
	bool p2 = bus_get_protocol(bus) == BUS_PROTOCOL_2;
	snprintf(err, cap, "servo ID%s %s did not answer a PING on %s at %ld bps (%d tries each): check power, "
	         "wiring, the IDs and the baud rate (`dxl --port PATH scan --bauds all`)%s", nmissing > 1 ? "s" : "",
	         missing, port_path, cfg->baud, SETUP_TRIES,
	         p2 && cfg->baud != 57600 ? "; X-series servos leave the factory at 57600 bps: `dxl --protocol 2 "
	                                    "--port PATH --baud 57600 setup IDS` raises them to 1 Mbps" : "");
	return false;
}

bool setup_protocol(struct bus *bus, const struct cfg *cfg, const char *port_path, enum bus_protocol *found,
                    char *err, size_t cap)
{
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
				bool p2 = order[k] == BUS_PROTOCOL_2;
				log_info("protocol: servo %u answered a Protocol %s PING on %s at %ld bps: Protocol %s (%s)",
				         cfg->ids[j], p2 ? "2.0" : "1.0", port_path, cfg->baud, p2 ? "2.0" : "1.0",
				         p2 ? "X series" : "AX-12");
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

/* Torque actuation found a servo in wheel mode (the daemon was stopped
 * without its safe stop, or the bus went away while the law drove it): stop
 * the drive, make the present position the goal, and give it angle limits
 * again — the configured joint limits — so joint mode holds it. */
static bool setup_restore_joint_mode(struct bus *bus, uint8_t id, const struct cfg_joint *cj,
                                     struct ctl_servo_info *info, char *err, size_t cap)
{
	uint8_t eb = 0, raw[2];
	bool reply = info->status_return_level >= 2;
	int r = setup_read(bus, id, DXL_AX_PRESENT_POSITION, 2, raw, &eb);
	uint8_t stop[4] = { raw[0], raw[1], 0, 0 }, off = 0;
	if (r == DXL_OK)
		r = setup_write(bus, id, DXL_AX_GOAL_POSITION, stop, 4, reply, &eb);
	/* EEPROM: the AX-12A takes it only with torque off; ctl_start() turns
	 * torque on again */
	if (r == DXL_OK)
		r = setup_write(bus, id, DXL_AX_TORQUE_ENABLE, &off, 1, reply, &eb);
	uint16_t cw, ccw;
	setup_joint_limits(cj, &cw, &ccw);
	uint8_t limits[4];
	dxl_put_u16(limits, cw);
	dxl_put_u16(limits + 2, ccw);
	if (r == DXL_OK)
		r = setup_write(bus, id, DXL_AX_CW_ANGLE_LIMIT, limits, 4, reply, &eb);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: in wheel mode, and putting it back in joint mode failed: %s", id,
		         dxl_strerror(r));
		return false;
	}
	log_warn("servo %u was in wheel mode: drive stopped, angle limits set to the joint's %u..%u", id, cw, ccw);
	info->cw_limit = cw;
	info->ccw_limit = ccw;
	return true;
}

/* RAM settings the loop relies on, written at every (re)connect: a power
 * loss resets them (the read-back checks them afterwards). */
static bool setup_ram(struct bus *bus, uint8_t id, const struct cfg *cfg, const struct ctl_servo_info *info,
                      const char *port_path, char *err, size_t cap)
{
	uint8_t eb = 0;
	bool reply = info->status_return_level >= 2;
	if (cfg->compliance_margin >= 0) {
		uint8_t m = (uint8_t)cfg->compliance_margin;
		int wr = setup_write(bus, id, DXL_AX_CW_COMPLIANCE_MARGIN, (const uint8_t[2]){ m, m }, 2, reply, &eb);
		if (wr != DXL_OK) {
			snprintf(err, cap, "servo %u: setting compliance margin %u failed: %s", id, m, dxl_strerror(wr));
			return false;
		}
	}
	if (cfg->compliance_slope >= 0) {
		uint8_t sl = (uint8_t)cfg->compliance_slope;
		int wr = setup_write(bus, id, DXL_AX_CW_COMPLIANCE_SLOPE, (const uint8_t[2]){ sl, sl }, 2, reply, &eb);
		if (wr != DXL_OK) {
			snprintf(err, cap, "servo %u: setting compliance slope %u failed: %s", id, sl, dxl_strerror(wr));
			return false;
		}
	}
	/* A moving speed left by another program would make every goal a slow
	 * ramp and the oscillator sluggish: 0 is "as fast as possible". */
	uint8_t ms[2];
	uint16_t moving_speed = 0;
	if (setup_read(bus, id, DXL_AX_MOVING_SPEED, 2, ms, &eb) == DXL_OK)
		moving_speed = dxl_get_u16(ms);
	if (moving_speed == 0)
		return true;
	log_warn("servo %u: moving speed was %u (%.2f rad/s); setting 0 (maximum)", id, moving_speed,
	         moving_speed * DXL_SPEED_RAD_S_PER_UNIT);
	int wr = setup_write(bus, id, DXL_AX_MOVING_SPEED, (const uint8_t[2]){ 0, 0 }, 2, reply, &eb);
	if (wr != DXL_OK) {
		snprintf(err, cap, "servo %u on %s: setting moving speed 0 failed: %s", id, port_path, dxl_strerror(wr));
		return false;
	}
	return true;
}

static bool setup_servo(struct bus *bus, struct ctl *ctl, size_t j, const struct cfg *cfg, const char *port_path,
                        int *max_return_delay_us, char *err, size_t cap)
{
	uint8_t id = ctl->j[j].id, eb = 0;
	uint8_t t[DXL_AX_STATUS_RETURN_LEVEL + 1];
	int r = setup_read(bus, id, 0, sizeof t, t, &eb);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: reading its settings failed: %s", id, dxl_strerror(r));
		return false;
	}
	uint16_t model = dxl_get_u16(&t[DXL_AX_MODEL_NUMBER]);
	if (model != DXL_AX12_MODEL)
		log_warn("servo %u: model number %u is not an AX-12 (%u); continuing with the AX-12 table", id, model,
		         DXL_AX12_MODEL);
	struct ctl_servo_info info = {
		.cw_limit = dxl_get_u16(&t[DXL_AX_CW_ANGLE_LIMIT]),
		.ccw_limit = dxl_get_u16(&t[DXL_AX_CCW_ANGLE_LIMIT]),
		.max_torque = dxl_get_u16(&t[DXL_AX_MAX_TORQUE]),
		.return_delay = t[DXL_AX_RETURN_DELAY_TIME],
		.status_return_level = t[DXL_AX_STATUS_RETURN_LEVEL],
	};
	if (info.status_return_level == 0) {
		snprintf(err, cap, "servo %u: status return level 0 (answers PING only): set it to 2 "
		         "(`dxl --port %s write %u status_return_level 2`)", id, port_path, id);
		return false;
	}
	if (cfg->actuation == CFG_ACT_TORQUE && dxl_is_wheel_mode(info.cw_limit, info.ccw_limit) &&
	    !setup_restore_joint_mode(bus, id, &cfg->joint[j], &info, err, cap))
		return false;
	if (info.max_torque == 0) {
		log_warn("servo %u: max torque (EEPROM) is 0: it cannot move; using 1023 as torque limit", id);
		info.max_torque = 1023;
	}
	unsigned delay_us = dxl_return_delay_us(info.return_delay);
	if (delay_us > 0)
		log_warn("servo %u: return delay %u µs costs %.1f ms a cycle on the bus; set it to 0 with "
		         "`dxl --port %s setup %u`", id, delay_us, 1e-3 * delay_us, port_path, id);
	if ((int)delay_us > *max_return_delay_us)
		*max_return_delay_us = (int)delay_us;
	if (!setup_ram(bus, id, cfg, &info, port_path, err, cap))
		return false;
	return ctl_set_servo(ctl, j, &info, err, cap);
}

bool setup_servos(struct bus *bus, struct ctl *ctl, const struct cfg *cfg, const char *port_path,
                  int *max_return_delay_us, char *err, size_t cap)
{
	*max_return_delay_us = 0;
	if (!setup_find(bus, ctl, cfg, port_path, err, cap))
		return false;
	bool p2 = bus_get_protocol(bus) == BUS_PROTOCOL_2;
	for (size_t j = 0; j < ctl->n; j++) {
		bool ok = p2 ? setup_servo_x(bus, ctl, j, cfg, port_path, max_return_delay_us, err, cap)
		             : setup_servo(bus, ctl, j, cfg, port_path, max_return_delay_us, err, cap);
		if (!ok)
			return false;
	}
	return true;
}

bool setup_read_present(struct bus *bus, struct ctl *ctl, double dt, char *err, size_t cap)
{
	for (size_t j = 0; j < ctl->n; j++) {
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
/* Torque actuation at exit: no servo may be left driving in wheel mode. Stop
 * every drive first (one packet), then goals at the present positions, then
 * the angle limits back; the safe state then holds or goes limp. */
static void setup_stop_wheel(struct bus *bus, const struct ctl *ctl, bool limp)
{
	uint8_t ids[CFG_MAX_JOINTS], zero[2 * CFG_MAX_JOINTS] = { 0 };
	for (size_t j = 0; j < ctl->n; j++)
		ids[j] = ctl->j[j].id;
	bus_sync_write(bus, DXL_AX_MOVING_SPEED, 2, ids, zero, ctl->n);
	for (size_t j = 0; j < ctl->n; j++) {
		const struct ctl_joint *jt = &ctl->j[j];
		bool reply = jt->servo.status_return_level >= 2;
		uint8_t eb, raw[2], limits[4];
		const uint8_t off = 0, on = 1;
		int r = setup_read(bus, jt->id, DXL_AX_PRESENT_POSITION, 2, raw, &eb);
		if (r == DXL_OK) {
			double hold = safety_clamp(&jt->limits, dxl_pos_to_rad(dxl_get_u16(raw)), NAN, NAN, NULL);
			dxl_put_u16(raw, dxl_rad_to_pos(hold));
			r = setup_write(bus, jt->id, DXL_AX_GOAL_POSITION, raw, 2, reply, &eb);
		}
		uint32_t lim = ctl_joint_mode_limits(ctl, j);
		dxl_put_u16(limits, (uint16_t)(lim & 0xFFFF));
		dxl_put_u16(limits + 2, (uint16_t)(lim >> 16));
		/* EEPROM: written with torque off (AX-12A) */
		if (r == DXL_OK)
			r = setup_write(bus, jt->id, DXL_AX_TORQUE_ENABLE, &off, 1, reply, &eb);
		if (r == DXL_OK)
			r = setup_write(bus, jt->id, DXL_AX_CW_ANGLE_LIMIT, limits, 4, reply, &eb);
		if (r == DXL_OK && !limp)
			r = setup_write(bus, jt->id, DXL_AX_TORQUE_ENABLE, &on, 1, reply, &eb);
		if (r != DXL_OK)
			log_error("safe stop: servo %u: back to joint mode failed (%s); its drive was stopped", jt->id,
			          dxl_strerror(r));
	}
	log_info("safe stop: torque actuation ended, servos back in joint mode");
}

void setup_safe_stop(struct bus *bus, const struct ctl *ctl, const struct cfg *cfg)
{
	bus_abort(bus);
	/* a robot that is limp stays limp: writing goals could bring torque back */
	bool limp = cfg->safe_stop == CFG_SAFE_LIMP || ctl->mode == CFG_MODE_LIMP;
	if (bus_get_protocol(bus) == BUS_PROTOCOL_2) {
		setup_safe_stop_x(bus, ctl, limp);
		return;
	}
	if (ctl->wheel)
		setup_stop_wheel(bus, ctl, limp);
	uint8_t ids[CFG_MAX_JOINTS], data[2 * CFG_MAX_JOINTS];
	size_t n = 0;
	for (size_t j = 0; j < ctl->n; j++) {
		const struct ctl_joint *jt = &ctl->j[j];
		uint8_t eb;
		if (limp) {
			setup_limp(bus, jt);
			continue;
		}
		uint8_t raw[2];
		if (setup_read(bus, jt->id, DXL_AX_PRESENT_POSITION, 2, raw, &eb) != DXL_OK) {
			log_error("safe stop: servo %u did not answer; it keeps its last goal", jt->id);
			continue;
		}
		uint16_t pos = dxl_get_u16(raw);
		double hold = isfinite(jt->limits.lo) && jt->limits.max_step > 0
		            ? safety_clamp(&jt->limits, dxl_pos_to_rad(pos), NAN, NAN, NULL) : dxl_pos_to_rad(pos);
		ids[n] = jt->id;
		dxl_put_u16(&data[2 * n], dxl_rad_to_pos(hold));
		n++;
	}
	if (n > 0)
		bus_sync_write(bus, DXL_AX_GOAL_POSITION, 2, ids, data, n);
	log_info("safe stop: %s", limp ? "torque off (limp)" : "holding present positions, torque on");
}
