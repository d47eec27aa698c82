/*
 * doctor_checks.c — the verdicts of `dxl doctor` (see doctor.h): pure, values
 * in, one line out. Each line says what was found, why it matters to a 100 Hz
 * loop when it does, and the command or setting that fixes it.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "doctor.h"
#include "dxl.h"
#include "dxl_table.h"
#include "daemon/safety.h"
#include "daemon/setup.h"

const char *dr_level_name(enum dr_level level)
{
	switch (level) {
	case DR_OK: return "OK";
	case DR_WARN: return "WARN";
	case DR_FAIL: return "FAIL";
	default: return "SKIP";
	}
}

void dr_set(struct dr_verdict *v, enum dr_level level, const char *fmt, ...)
{
	va_list ap;

	v->level = level;
	va_start(ap, fmt);
	vsnprintf(v->text, sizeof v->text, fmt, ap);
	va_end(ap);
}

void dr_add(struct dr_verdict *v, const char *fmt, ...)
{
	size_t len = strlen(v->text);
	va_list ap;

	if (len + 1 >= sizeof v->text)
		return;
	va_start(ap, fmt);
	vsnprintf(v->text + len, sizeof v->text - len, fmt, ap);
	va_end(ap);
}

void dr_servo_decode(struct dr_servo *s, const uint8_t eeprom[DR_EEPROM_LEN], const uint8_t ram[DR_RAM_LEN])
{
	s->model = dxl_get_u16(&eeprom[DXL_AX_MODEL_NUMBER]);
	s->firmware = eeprom[DXL_AX_FIRMWARE_VERSION];
	s->return_delay = eeprom[DXL_AX_RETURN_DELAY_TIME];
	s->cw_limit = dxl_get_u16(&eeprom[DXL_AX_CW_ANGLE_LIMIT]);
	s->ccw_limit = dxl_get_u16(&eeprom[DXL_AX_CCW_ANGLE_LIMIT]);
	s->temperature_limit = eeprom[DXL_AX_TEMPERATURE_LIMIT];
	s->min_voltage = eeprom[DXL_AX_MIN_VOLTAGE_LIMIT];
	s->max_voltage = eeprom[DXL_AX_MAX_VOLTAGE_LIMIT];
	s->max_torque = dxl_get_u16(&eeprom[DXL_AX_MAX_TORQUE]);
	s->status_return_level = eeprom[DXL_AX_STATUS_RETURN_LEVEL];
	s->alarm_led = eeprom[DXL_AX_ALARM_LED];
	s->alarm_shutdown = eeprom[DXL_AX_ALARM_SHUTDOWN];
	s->torque_enable = ram[DXL_AX_TORQUE_ENABLE - DR_RAM_ADDR];
	s->torque_limit = dxl_get_u16(&ram[DXL_AX_TORQUE_LIMIT - DR_RAM_ADDR]);
	s->voltage = ram[DXL_AX_PRESENT_VOLTAGE - DR_RAM_ADDR];
	s->temperature = ram[DXL_AX_PRESENT_TEMPERATURE - DR_RAM_ADDR];
}

/* ---- the bus ------------------------------------------------------------------------------ */

static void dr_adapter_name(const struct dr_adapter *a, char *buf, size_t cap)
{
	if (a->is_pty)
		snprintf(buf, cap, "%s: a pseudo-terminal (a simulator's bus)", a->tty);
	else if (a->listed && a->info.usb_vid >= 0)
		snprintf(buf, cap, "%s: %s %04x:%04x%s%s", a->tty, a->info.adapter != NULL ? a->info.adapter : "USB serial",
		         a->info.usb_vid, a->info.usb_pid, a->info.description[0] ? ", " : "", a->info.description);
	else
		snprintf(buf, cap, "%s: a serial port (no USB: an on-board UART?)", a->tty);
}

void dr_check_adapter(const struct dr_adapter *a, struct dr_verdict *v)
{
	char name[200];
	const char *tty = strrchr(a->tty, '/') != NULL ? strrchr(a->tty, '/') + 1 : a->tty;

	dr_adapter_name(a, name, sizeof name);
	if (!a->lat.known) {
		dr_set(v, DR_OK, "%s; no latency timer (not an FTDI adapter: the latency line measures)", name);
	} else if (a->lat.found_ms <= 1) {
		dr_set(v, DR_OK, "%s; latency timer %d ms", name, a->lat.found_ms);
	} else if (a->lat.timer_ms <= 1) {
		/* undulated lowers it at every start, as this run did: it works,
		 * but every other program waits, and a re-plug brings 16 back */
		dr_set(v, DR_WARN, "%s; latency timer was %d ms, lowered to %d ms for now as undulated does at each "
		       "start; other programs wait %d ms per reply until then, and re-plugging brings it back; fix: "
		       "install systemd/99-undulate.rules (1 ms at every plug-in), or echo 1 > "
		       "%s/bus/usb-serial/devices/%s/latency_timer", name, a->lat.found_ms, a->lat.timer_ms,
		       a->lat.found_ms, a->sysfs_root, tty);
	} else {
		dr_set(v, DR_FAIL, "%s; latency timer %d ms and it could not be lowered (%s): every reply waits up to "
		       "%d ms, 100 Hz is out of reach; fix: as root, echo 1 > %s/bus/usb-serial/devices/%s/latency_timer, "
		       "and for good systemd/99-undulate.rules", name, a->lat.timer_ms, a->lat.note, a->lat.timer_ms,
		       a->sysfs_root, tty);
	}
	if (a->rs485 != PORT_RS485_OFF)
		dr_add(v, "; RS-485 mode %s (the kernel switches RTS around every packet)", port_rs485_name(a->rs485));
	if (a->echo)
		dr_add(v, "; echo cancelling on (our own bytes come back first)");
}

void dr_check_latency(const struct dr_latency *l, struct dr_verdict *v)
{
	if (!l->measured) {
		dr_set(v, DR_SKIP, "not measured: no servo answered a PING");
		return;
	}
	const struct bus_lateness *t = &l->late;
	double ms = 1e-3 * t->median_us;
	char seen[160];
	snprintf(seen, sizeof seen, "replies come %.2f ms after their wire time (median of %u PINGs to ID %u; "
	         "%.2f..%.2f ms)", ms, t->replies, l->id, 1e-3 * t->min_us, 1e-3 * t->max_us);
	if ((long)t->median_us > l->allowed_us) {
		dr_set(v, DR_FAIL, "%s, more than undulated's timeouts allow (%.1f ms: the adapter latency it assumes "
		       "+ bus_margin_us): every READ of its cycle would time out", seen, 1e-3 * (double)l->allowed_us);
	} else if (t->median_us > DR_LATE_FAIL_US) {
		dr_set(v, DR_FAIL, "%s: every READ waits that long, %.1f ms a cycle for %u joint(s) of the 10 ms", seen,
		       ms * l->njoints, l->njoints);
	} else if (t->median_us > DR_LATE_WARN_US) {
		dr_set(v, DR_WARN, "%s: %.1f ms a cycle for %u joint(s)", seen, ms * l->njoints, l->njoints);
	} else {
		dr_set(v, DR_OK, "%s", seen);
		return;
	}
	if (l->ftdi)
		dr_add(v, "; fix: the latency timer to 1 ms (adapter line)");
	else
		dr_add(v, "; fix: an adapter that passes replies on at once (an FTDI one with its latency timer at 1 ms, "
		       "a UART); or make undulated wait for them, slower: adapter_latency_us = %u in [robot] and a "
		       "longer period_ms", (unsigned)(ceil(1e-3 * t->max_us) * 1000.0 + 1000.0));
}

bool dr_check_echo(bool echo, uint32_t unexpected_echoes, uint32_t echo_errors, struct dr_verdict *v)
{
	if (!echo && unexpected_echoes > 0) {
		/* the bus still tells echo from reply by waiting for what follows,
		 * but a missing servo's PING then reads as answered */
		dr_set(v, DR_WARN, "our own request came back before the reply %u time(s): a single-wire wiring (or a "
		       "buffer whose receiver hears its transmitter); fix: echo = true in [robot] (dxl --echo)",
		       unexpected_echoes);
		return true;
	}
	if (echo && echo_errors > 0) {
		dr_set(v, DR_FAIL, "echo cancelling is on and %u time(s) the bytes read back were not our request: the "
		       "wiring does not echo; fix: echo = false in [robot] (no --echo)", echo_errors);
		return true;
	}
	return false;
}

/* READ(36, 8) is 8 bytes out and 14 back; the SYNC_WRITE of 2-byte goals is
 * (2 + 1)·N + 8 bytes (ax12.md); 10 bits a byte. */
double dr_cycle_wire_us(unsigned nservos, long baud)
{
	double bytes = nservos * (8.0 + 14.0) + (nservos > 0 ? 3.0 * nservos + 8.0 : 0.0);
	return baud > 0 ? bytes * 10.0 * 1e6 / (double)baud : 0.0;
}

double dr2_cycle_wire_us(unsigned nservos, unsigned read_len, long baud)
{
	double n = nservos;
	double bytes = nservos > 0 ? (14.0 + n) + n * (11.0 + read_len) + (14.0 + 5.0 * n) : 0.0;
	return baud > 0 ? bytes * 10.0 * 1e6 / (double)baud : 0.0;
}

void dr_check_baud(const struct dr_context *c, unsigned asked, unsigned answered, struct dr_verdict *v)
{
	if (answered == 0) {
		dr_set(v, DR_FAIL, "%ld bps: none of the %u servo(s) answered a PING; fix: find them at every rate: "
		       "dxl --port %s scan --bauds all (no servo at all: power, cable, and for a UART the wiring: "
		       "rs485 or echo, README \"On a robot\")", c->baud, asked, c->port);
		return;
	}
	bool p2 = c->protocol == 2;
	double wire_ms = 1e-3 * (p2 ? dr2_cycle_wire_us(answered, c->read_len2, c->baud) : dr_cycle_wire_us(answered, c->baud));
	if (p2 && wire_ms > c->period_ms) {
		dr_set(v, DR_FAIL, "%ld bps: one cycle's bytes for %u servo(s) (a SYNC_READ, a SYNC_WRITE) take %.2f ms on "
		       "the wire, more than the %g ms period; fix: dxl --protocol 2 --port %s setup %s (raises every servo "
		       "to 1000000 bps) and baud = 1000000 in [robot]", c->baud, answered, wire_ms, c->period_ms, c->port,
		       c->ids);
		return;
	}
	if (wire_ms > 0.5 * c->period_ms) {
		dr_set(v, DR_WARN, "%ld bps: one cycle's bytes for %u servo(s) take %.2f ms on the wire, more than half "
		       "the %g ms period; fix: a faster rate for every servo (dxl %s--port %s set-baud ID 1000000) and "
		       "baud = 1000000 in [robot]", c->baud, answered, wire_ms, c->period_ms, p2 ? "--protocol 2 " : "",
		       c->port);
		return;
	}
	dr_set(v, DR_OK, "%ld bps: %u of %u servo(s) answered; one cycle's bytes take %.2f ms on the wire", c->baud,
	       answered, asked, wire_ms);
}

/* ---- each servo ----------------------------------------------------------------------------- */

void dr_check_model(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	const char *name = s->model == DXL_AX12_MODEL ? "AX-12" : s->model == 18 ? "AX-18" : s->model == 300 ? "AX-12W"
	                 : "not an AX-12";
	if (s->model == DXL_AX12_MODEL) {
		dr_set(v, DR_OK, "%u (%s), firmware %u", s->model, name, s->firmware);
		return;
	}
	/* undulated warns and goes on with the AX-12 table: addresses agree
	 * across the AX series, speeds and torques do not */
	dr_set(v, DR_WARN, "%u (%s), firmware %u: undulated drives it with the AX-12's table and motor figures; "
	       "fix: an AX-12, or check its control table against the AX-12's (dxl --port %s dump %u)", s->model,
	       name, s->firmware, c->port, s->id);
}

void dr_setup_fix(struct dr_verdict *v, const struct dr_context *c, const char *protocol_opt, const char *what)
{
	dr_add(v, "; fix: dxl %s--port %s setup %s --yes (%s)%s", protocol_opt, c->port, c->ids, what,
	       c->any_torque_on ? "; --yes turns torque off first: support the robot" : "");
}

void dr_check_return_delay(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	unsigned us = dxl_return_delay_us(s->return_delay);

	if (us == 0) {
		dr_set(v, DR_OK, "0 us");
		return;
	}
	/* one READ of this servo per cycle, and a read-back every fifth */
	dr_set(v, DR_WARN, "%u us before every reply: costs %.2f ms of every %g ms cycle", us, 1e-3 * us, c->period_ms);
	dr_setup_fix(v, c, "", "writes return delay 0");
}

void dr_check_status_level(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	switch (s->status_return_level) {
	case 0:
		dr_set(v, DR_FAIL, "0: answers PING only, and undulated READs every joint every cycle (it refuses to "
		       "start); fix: dxl --port %s write %u status_return_level 2", c->port, s->id);
		return;
	case 1:
		dr_set(v, DR_WARN, "1: WRITEs are not answered, so undulated cannot confirm its register writes (torque, "
		       "limits) until its read-back");
		dr_setup_fix(v, c, "", "writes status return level 2");
		return;
	default:
		dr_set(v, DR_OK, "%u", s->status_return_level);
	}
}

void dr_check_voltage(const struct dr_servo *s, struct dr_verdict *v)
{
	double volts = dxl_voltage_to_volts(s->voltage);
	double lo = dxl_voltage_to_volts(s->min_voltage), hi = dxl_voltage_to_volts(s->max_voltage);
	char range[64];
	snprintf(range, sizeof range, "(servo's limits %.1f..%.1f V)", lo, hi);

	if (s->voltage < s->min_voltage || s->voltage > s->max_voltage) {
		dr_set(v, DR_FAIL, "%.1f V %s: the servo flags every reply with the voltage error; fix: the supply — "
		       "%s", volts, range, s->voltage < s->min_voltage ? "charge or replace the battery, check the cable's drop" :
		       "a supply within the AX-12A's 9..12 V");
	} else if (s->voltage < DR_DECIVOLTS_MIN) {
		dr_set(v, DR_FAIL, "%.1f V %s, below the AX-12A's 9..12 V: it gives %.0f%% of its 12 V torque and speed, and "
		       "sags further under load; fix: charge or replace the battery (11.1..12 V), check the supply's cable",
		       volts, range, 100.0 * volts / DXL2_REF_VOLTAGE);
	} else if (s->voltage < DR_DECIVOLTS_LOW) {
		dr_set(v, DR_WARN, "%.1f V %s: %.0f%% of the 12 V torque and speed, at rest; fix: charge the battery "
		       "(11.1..12 V)", volts, range, 100.0 * volts / DXL2_REF_VOLTAGE);
	} else if (s->voltage > DR_DECIVOLTS_MAX) {
		dr_set(v, DR_WARN, "%.1f V %s, above the AX-12A's 12 V; fix: a 12 V supply or a 3S battery", volts, range);
	} else {
		dr_set(v, DR_OK, "%.1f V %s", volts, range);
	}
}

void dr_check_temperature(const struct dr_servo *s, struct dr_verdict *v)
{
	unsigned t = s->temperature, lim = s->temperature_limit;

	if (t >= lim) {
		dr_set(v, DR_FAIL, "%u C, at or above its limit %u C: overheating, %s; fix: torque off and about 20 "
		       "minutes of cooling, then a lighter load", t, lim,
		       (s->alarm_shutdown & DXL_ERRBIT_OVERHEAT) ? "the alarm switches its torque off"
		                                                 : "and no alarm switches its torque off");
	} else if (t + DR_TEMP_MARGIN_C >= lim) {
		dr_set(v, DR_WARN, "%u C, within %u C of its limit %u C: a gait heats it further; fix: let it cool "
		       "before a long run", t, DR_TEMP_MARGIN_C, lim);
	} else {
		dr_set(v, DR_OK, "%u C (limit %u C)", t, lim);
	}
}

/* The writes that give the servo the configured limits: cw and/or ccw. */
static void dr_limits_fix(struct dr_verdict *v, const struct dr_context *c, uint8_t id, int cw, int ccw,
                          bool torque_on)
{
	dr_add(v, "; fix: ");
	/* the AX-12A refuses EEPROM writes while torque is on */
	if (torque_on)
		dr_add(v, "dxl --port %s torque %u off; ", c->port, id);
	if (cw >= 0)
		dr_add(v, "dxl --port %s write %u cw_angle_limit %d%s", c->port, id, cw, ccw >= 0 ? "; " : "");
	if (ccw >= 0)
		dr_add(v, "dxl --port %s write %u ccw_angle_limit %d", c->port, id, ccw);
}

void dr_check_limits(const struct dr_servo *s, const struct cfg *cfg, size_t joint, const struct dr_context *c,
                     struct dr_verdict *v)
{
	const struct cfg_joint *cj = &cfg->joint[joint];
	uint16_t cw, ccw;
	char conf[160];

	setup_joint_limits(cj, &cw, &ccw);
	snprintf(conf, sizeof conf, "the configuration's %u..%u (joint %zu: neutral %+.3f + [%.3f, %.3f] rad)", cw, ccw,
	         joint + 1, cj->neutral, cj->limit_min, cj->limit_max);
	if (dxl_is_wheel_mode(s->cw_limit, s->ccw_limit)) {
		if (cfg->actuation == CFG_ACT_TORQUE) {
			dr_set(v, DR_WARN, "0..0: wheel mode, left by a torque-actuated run that did not stop cleanly; "
			       "undulated puts %s back at start", conf);
		} else {
			dr_set(v, DR_FAIL, "0..0: wheel mode (a goal position does nothing; undulated refuses to start), "
			       "against %s", conf);
		}
		dr_limits_fix(v, c, s->id, cw, ccw, s->torque_enable != 0);
		return;
	}
	struct safety_limits both;
	if (!safety_limits_make(&both, cj->neutral, cj->limit_min, cj->limit_max, s->cw_limit, s->ccw_limit,
	                        cj->max_step)) {
		dr_set(v, DR_FAIL, "%u..%u have no angle in common with %s: undulated refuses to start", s->cw_limit,
		       s->ccw_limit, conf);
		dr_limits_fix(v, c, s->id, cw, ccw, s->torque_enable != 0);
		return;
	}
	if (s->cw_limit > cw || s->ccw_limit < ccw) {
		dr_set(v, DR_WARN, "%u..%u, narrower than %s: undulated keeps goals inside both, so the joint stops at "
		       "%+.3f..%+.3f rad from neutral, short of what the configuration allows", s->cw_limit, s->ccw_limit,
		       conf, both.lo - cj->neutral, both.hi - cj->neutral);
		dr_limits_fix(v, c, s->id, s->cw_limit > cw ? cw : -1, s->ccw_limit < ccw ? ccw : -1, s->torque_enable != 0);
		return;
	}
	dr_set(v, DR_OK, "%u..%u, around %s", s->cw_limit, s->ccw_limit, conf);
}

void dr_check_alarms(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	char led[96], off[96], missing[96], extra[96];
	uint8_t lack = (uint8_t)(DR_SHUTDOWN_WANT & ~s->alarm_shutdown);
	uint8_t more = (uint8_t)(s->alarm_shutdown & ~DR_SHUTDOWN_WANT & DXL_ERRBIT_MASK);

	dxl_errbits_format(s->alarm_led, led, sizeof led);
	dxl_errbits_format(s->alarm_shutdown, off, sizeof off);
	if (lack == 0 && more == 0) {
		dr_set(v, DR_OK, "shutdown %u (%s), LED %u (%s)", s->alarm_shutdown, off, s->alarm_led, led);
		return;
	}
	dr_set(v, DR_WARN, "shutdown %u (%s), LED %u (%s)", s->alarm_shutdown, off, s->alarm_led, led);
	if (lack != 0)
		dr_add(v, ": %s does not switch torque off, and the motor is not protected from it",
		       dxl_errbits_format(lack, missing, sizeof missing));
	if (more != 0)
		dr_add(v, "%s %s switches torque off: a sagging battery or one damaged packet stops the joint until "
		       "undulated restores it", lack != 0 ? ";" : ":", dxl_errbits_format(more, extra, sizeof extra));
	dr_add(v, "; fix: %sdxl --port %s write %u alarm_shutdown %u (overheating|overload, the factory setting)",
	       s->torque_enable ? "(torque off first) " : "", c->port, s->id, (unsigned)DR_SHUTDOWN_WANT);
}

void dr_check_torque(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	if (s->max_torque == 0) {
		dr_set(v, DR_WARN, "max torque 0 (EEPROM): it cannot move, undulated uses 1023 as its torque limit; "
		       "fix: dxl --port %s write %u max_torque 1023", c->port, s->id);
		return;
	}
	if (s->torque_limit == 0) {
		dr_set(v, DR_WARN, "torque %s, torque limit 0: an alarm shut it down (what its replies say is on its "
		       "error-bits line); undulated writes the limit back at start, the cause stays", s->torque_enable ?
		       "on" : "off");
		dr_add(v, "; fix: find the cause (overload: a blocked joint; overheating: let it cool), then "
		       "dxl --port %s write %u torque_limit %u", c->port, s->id, s->max_torque);
		return;
	}
	dr_set(v, DR_OK, "%s, torque limit %u of max torque %u%s", s->torque_enable ? "on" : "off", s->torque_limit,
	       s->max_torque, s->torque_enable ? "" : " (undulated turns it on at start)");
}

bool dr_check_errbits(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	char names[96];
	const uint8_t conditions = DXL_ERRBIT_VOLTAGE | DXL_ERRBIT_OVERHEAT | DXL_ERRBIT_OVERLOAD;

	(void)c;
	if (s->errbits == 0)
		return false;
	/* conditions are the servo's state; the others answer a packet of ours
	 * the servo did not like, which this tool should never send */
	dr_set(v, (s->errbits & conditions) ? DR_FAIL : DR_WARN, "its replies carry 0x%02X (%s)", s->errbits,
	       dxl_errbits_format(s->errbits, names, sizeof names));
	dr_add(v, "; fix: ");
	if (s->errbits & DXL_ERRBIT_VOLTAGE)
		dr_add(v, "the supply (voltage line); ");
	if (s->errbits & DXL_ERRBIT_OVERHEAT)
		dr_add(v, "let it cool (temperature line); ");
	if (s->errbits & DXL_ERRBIT_OVERLOAD)
		dr_add(v, "free the joint, then undulated's start writes the torque limit back; ");
	if (s->errbits & ~conditions)
		dr_add(v, "a damaged line (checksum: cable, termination, a second master on the bus); ");
	size_t len = strlen(v->text);
	if (len >= 2 && strcmp(v->text + len - 2, "; ") == 0)
		v->text[len - 2] = '\0';
	return true;
}

/* ---- the budget ------------------------------------------------------------------------------ */

void dr_check_budget(const struct dr_budget *b, struct dr_verdict *v)
{
	if (b->skipped != NULL) {
		dr_set(v, DR_SKIP, "not timed: %s", b->skipped);
		return;
	}
	double late_ms = 0.7 * b->period_ms;   /* CYC_LATE_SHARE: past it writes and read-backs wait */
	double err_share = b->transactions > 0 ? (double)b->errors / (double)b->transactions : 0.0;
	double cut_share = b->cycles > 0 ? (double)b->cut_off / (double)b->cycles : 0.0;
	enum dr_level lv = DR_OK;
	char why[200] = "";

	if (err_share > DR_BUDGET_FAIL_SHARE || cut_share > DR_BUDGET_FAIL_SHARE || b->p50_ms > late_ms)
		lv = DR_FAIL;
	else if (err_share > DR_BUDGET_WARN_SHARE || cut_share > DR_BUDGET_WARN_SHARE || b->p99_ms > late_ms ||
	         b->p50_ms > 0.5 * b->period_ms)
		lv = DR_WARN;
	if (lv != DR_OK) {
		snprintf(why, sizeof why, "%s%s", b->errors > 0 ? "; the failed transactions are timeouts or bad replies: see "
		         "the latency and return delay lines" : "",
		         b->p50_ms > 0.5 * b->period_ms ? "; too much bus time: return delay 0, latency timer 1 ms, a "
		         "faster baud or fewer servos per bus" : "");
	}
	dr_set(v, lv, "bus time per cycle p50 %.2f / p99 %.2f / max %.2f ms; wire floor %.2f ms (p50 %.1fx it); "
	       "period %g ms (p99 %.0f%% of it); %u cycles of undulated's own loop on %u joint(s), holding: "
	       "%lld of %lld transactions failed, %lld cycle(s) cut off by the next tick", b->p50_ms, b->p99_ms,
	       b->max_ms, b->floor_ms, b->floor_ms > 0 ? b->p50_ms / b->floor_ms : 0.0, b->period_ms,
	       100.0 * b->p99_ms / b->period_ms, b->cycles, b->joints, b->errors, b->transactions, b->cut_off);
	if (lv != DR_OK)
		dr_add(v, "; fix:%s", why[0] ? why + 1 : " see the lines above");
}
