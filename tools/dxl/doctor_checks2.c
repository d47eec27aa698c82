/*
 * doctor_checks2.c — `dxl doctor`'s verdicts for the X series (Protocol
 * 2.0): pure, values in, one line out, as doctor_checks.c's for the AX-12.
 * The fixes name `dxl --protocol 2`.
 */
#include <stdio.h>

#include "doctor.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "daemon/servo_model.h"
#include "daemon/setup.h"

static uint16_t dr2_u16(const uint8_t *m, unsigned a)
{
	return dxl_get_u16(m + a);
}

void dr2_servo_decode(struct dr2_servo *s, const uint8_t mem[DR2_IMAGE_LEN])
{
	s->model = dr2_u16(mem, DXL2_X_MODEL_NUMBER);
	s->firmware = mem[DXL2_X_FIRMWARE_VERSION];
	s->return_delay = mem[DXL2_X_RETURN_DELAY_TIME];
	s->operating_mode = mem[DXL2_X_OPERATING_MODE];
	s->temperature_limit = mem[DXL2_X_TEMPERATURE_LIMIT];
	s->max_voltage = dr2_u16(mem, DXL2_X_MAX_VOLTAGE_LIMIT);
	s->min_voltage = dr2_u16(mem, DXL2_X_MIN_VOLTAGE_LIMIT);
	s->max_position = (int32_t)dxl2_get_u32(mem + DXL2_X_MAX_POSITION_LIMIT);
	s->min_position = (int32_t)dxl2_get_u32(mem + DXL2_X_MIN_POSITION_LIMIT);
	s->shutdown = mem[DXL2_X_SHUTDOWN];
	s->torque_enable = mem[DXL2_X_TORQUE_ENABLE];
	s->status_return_level = mem[DXL2_X_STATUS_RETURN_LEVEL];
	s->hwerr = mem[DXL2_X_HARDWARE_ERROR_STATUS];
	s->bus_watchdog = mem[DXL2_X_BUS_WATCHDOG];
	s->pwm_limit = dr2_u16(mem, DXL2_X_PWM_LIMIT);
	s->voltage = dr2_u16(mem, DXL2_X_PRESENT_INPUT_VOLTAGE);
	s->temperature = mem[DXL2_X_PRESENT_TEMPERATURE];
}

bool dr2_model_volts(uint16_t model, double *lo, double *rec, double *hi)
{
	const struct dxl2_model *m = dxl2_model_by_number(model);
	if (m == NULL)
		return false;
	*lo = m->sheet.rated_min_v, *rec = m->sheet.rated_rec_v, *hi = m->sheet.rated_max_v;
	return true;
}

void dr2_check_model(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	const struct dxl2_model *m = dxl2_model_by_number(s->model);
	if (m != NULL) {
		dr_set(v, DR_OK, "%u (%s), firmware %u", s->model, m->name, s->firmware);
		return;
	}
	char known[160];
	dr_set(v, DR_WARN, "%u, firmware %u: not in dxl's tables (%s); the checks below read it "
	        "with the X series' addresses, which it may not share; fix: check its control table (dxl --protocol 2 "
	        "--port %s dump %u prints it raw)", s->model, s->firmware, dxl2_model_names(2, known, sizeof known), c->port,
	        s->id);
}

void dr2_check_return_delay(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	unsigned us = dxl2_return_delay_us(s->return_delay);
	if (us == 0) {
		dr_set(v, DR_OK, "0 us");
		return;
	}
	/* one reply of this servo per SYNC_READ, every cycle */
	dr_set(v, DR_WARN, "%u us before every reply: costs %.2f ms of every %g ms cycle", us, 1e-3 * us, c->period_ms);
	dr_setup_fix(v, c, "--protocol 2 ", "writes return delay 0");
}

void dr2_check_status_level(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	switch (s->status_return_level) {
	case 0:
		dr_set(v, DR_FAIL, "0: answers PING only, so the loop's SYNC_READ goes unanswered; fix: dxl --protocol 2 "
		        "--port %s write %u status_return_level 2", c->port, s->id);
		return;
	case 1:
		dr_set(v, DR_WARN, "1: SYNC_READ and READ answered, WRITEs not: register writes (torque, limits) cannot "
		        "be confirmed until read back");
		dr_setup_fix(v, c, "--protocol 2 ", "writes status return level 2");
		return;
	default:
		dr_set(v, DR_OK, "%u", s->status_return_level);
	}
}

void dr2_check_voltage(const struct dr2_servo *s, struct dr_verdict *v)
{
	double volts = dxl2_voltage_to_volts(s->voltage), lo, rec, hi;
	double own_lo = dxl2_voltage_to_volts(s->min_voltage), own_hi = dxl2_voltage_to_volts(s->max_voltage);
	const struct dxl2_model *m = dxl2_model_by_number(s->model);
	char range[64];

	snprintf(range, sizeof range, "(servo's limits %.1f..%.1f V)", own_lo, own_hi);
	if (s->voltage < s->min_voltage || s->voltage > s->max_voltage) {
		dr_set(v, DR_FAIL, "%.1f V %s: outside its limits, the servo raises an input voltage error; fix: the "
		        "supply — %s", volts, range, s->voltage < s->min_voltage ? "charge or replace the battery, check the "
		        "cable's drop" : "a lower voltage");
		return;
	}
	if (!dr2_model_volts(s->model, &lo, &rec, &hi)) {
		dr_set(v, DR_OK, "%.1f V %s", volts, range);
		return;
	}
	if (volts < lo || volts > hi)
		dr_set(v, DR_FAIL, "%.1f V %s, outside the %s's %.1f..%.1f V; fix: a supply of %.1f V", volts, range,
		        m->name, lo, hi, rec);
	else if (volts < rec - 1.0)
		dr_set(v, DR_WARN, "%.1f V %s: %.0f%% of the %s's recommended %.1f V, at rest; fix: charge the battery",
		        volts, range, 100.0 * volts / rec, m->name, rec);
	else
		dr_set(v, DR_OK, "%.1f V %s", volts, range);
}

void dr2_check_temperature(const struct dr2_servo *s, struct dr_verdict *v)
{
	unsigned t = s->temperature, lim = s->temperature_limit;
	if (t >= lim)
		dr_set(v, DR_FAIL, "%u C, at or above its limit %u C: overheating, %s; fix: torque off and about 20 minutes "
		        "of cooling, then a lighter load", t, lim, (s->shutdown & DXL2_HWERR_OVERHEAT) ? "its shutdown "
		        "switches torque off" : "and nothing switches its torque off");
	else if (t + DR_TEMP_MARGIN_C >= lim)
		dr_set(v, DR_WARN, "%u C, within %u C of its limit %u C: a gait heats it further; fix: let it cool before "
		        "a long run", t, DR_TEMP_MARGIN_C, lim);
	else
		dr_set(v, DR_OK, "%u C (limit %u C)", t, lim);
}

void dr2_check_mode(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	const char *name = dxl2_opmode_name(s->operating_mode);
	if (s->operating_mode == DXL2_OPMODE_POSITION) {
		dr_set(v, DR_OK, "3 (position)");
		return;
	}
	dr_set(v, DR_WARN, "%u (%s): a goal position is not what it follows, and outside position mode it ignores its "
	        "position limits; fix: dxl --protocol 2 --port %s torque %u off; dxl --protocol 2 --port %s write %u "
	        "operating_mode 3", s->operating_mode, name != NULL ? name : "unknown", c->port, s->id, c->port, s->id);
}

void dr2_check_limits(const struct dr2_servo *s, const struct cfg *cfg, size_t joint, const struct dr_context *c,
                      struct dr_verdict *v)
{
	const struct cfg_joint *cj = &cfg->joint[joint];
	/* what undulated writes (setup_joint_limits_model): inside the limits;
	 * every X model has the XL430's 4096 units a turn around 2048 */
	const struct sm_model *m = sm_by_number(2, s->model);
	int32_t lo, hi;
	setup_joint_limits_model(m != NULL ? m : sm_by_number(2, DXL2_MODEL_XL430_W250), cj, &lo, &hi);
	char conf[160];

	snprintf(conf, sizeof conf, "the configuration's %ld..%ld (joint %zu: neutral %+.3f + [%.3f, %.3f] rad)",
	         (long)lo, (long)hi, joint + 1, cj->neutral, cj->limit_min, cj->limit_max);
	if (s->max_position < lo || s->min_position > hi) {
		dr_set(v, DR_FAIL, "%ld..%ld have no position in common with %s", (long)s->min_position,
		        (long)s->max_position, conf);
	} else if (s->min_position > lo || s->max_position < hi) {
		dr_set(v, DR_WARN, "%ld..%ld, narrower than %s: the servo stops the joint short of what the configuration "
		        "allows", (long)s->min_position, (long)s->max_position, conf);
	} else {
		dr_set(v, DR_OK, "%ld..%ld, around %s", (long)s->min_position, (long)s->max_position, conf);
		return;
	}
	dr_add(v, "; fix: %sdxl --protocol 2 --port %s write %u min_position_limit %ld; dxl --protocol 2 --port %s "
	        "write %u max_position_limit %ld", s->torque_enable ? "(torque off first: EEPROM) " : "", c->port, s->id,
	        (long)lo, c->port, s->id, (long)hi);
}

void dr2_check_hwerr(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	char names[96];
	if (s->hwerr == 0) {
		dr_set(v, DR_OK, "none");
		return;
	}
	dr_set(v, DR_FAIL, "%u (%s): the servo %s until it is rebooted; fix: remove the cause (overload: a blocked "
	        "joint; overheating: let it cool; voltage: the supply), then dxl --protocol 2 --port %s reboot %u",
	        s->hwerr, dxl2_hwerr_format(s->hwerr, names, sizeof names),
	        (s->hwerr & s->shutdown) ? "switched its torque off and keeps it off" : "flags every reply with the alert",
	        c->port, s->id);
}

void dr2_check_torque(const struct dr2_servo *s, struct dr_verdict *v)
{
	dr_set(v, DR_OK, "%s%s", s->torque_enable ? "on" : "off", s->torque_enable ? "" : " (undulated turns it on at start)");
}

void dr2_check_watchdog(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	unsigned ms = dxl2_watchdog_ms(s->bus_watchdog);
	if (s->bus_watchdog == 0) {
		dr_set(v, DR_OK, "off");
		return;
	}
	if (s->bus_watchdog == 0xFF) {
		dr_set(v, DR_FAIL, "fired (-1): the bus went silent longer than the watchdog allowed and the servo stopped; "
		        "fix: dxl --protocol 2 --port %s write %u bus_watchdog 0, then torque on again", c->port, s->id);
		return;
	}
	if (ms < 2.0 * c->period_ms) {
		dr_set(v, DR_WARN, "%u ms, less than two %g ms periods: one late cycle stops the servo; fix: dxl --protocol 2 "
		        "--port %s write %u bus_watchdog %u (%g ms)", ms, c->period_ms, c->port, s->id,
		        (unsigned)(5.0 * c->period_ms / 20.0 + 0.999), 20.0 * (unsigned)(5.0 * c->period_ms / 20.0 + 0.999));
		return;
	}
	dr_set(v, DR_OK, "%u ms: the servo stops when the bus is silent that long", ms);
}

bool dr2_check_err(const struct dr2_servo *s, struct dr_verdict *v)
{
	char names[96];
	if (s->err == 0)
		return false;
	dr_set(v, dxl2_err_alert(s->err) ? DR_FAIL : DR_WARN, "its replies carry 0x%02X (%s)%s", s->err,
	        dxl2_err_format(s->err, names, sizeof names), dxl2_err_alert(s->err) ? ": the alert, a hardware error "
	        "(see its hardware error line)" : ": it refused a packet of ours");
	return true;
}
