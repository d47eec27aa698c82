/*
 * doctor_checks.c — the verdicts of `dxl doctor` (see doctor.h): pure, values
 * in, one line out. Each line says what was found, why it matters to a 100 Hz
 * loop when it does, and the command or setting that fixes it. Written once
 * for every model: what a model has is asked of its descriptor
 * (dxl2_model_can, the rows of its table), what the bus's protocol does of
 * its backend table (dxl_proto.h), the family's start-up rules of
 * daemon/servo_model.h's sm_setup.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "doctor.h"
#include "dxl.h"
#include "dxl2.h"
#include "dxl_table.h"
#include "daemon/safety.h"
#include "daemon/servo_model.h"
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


/* The shutdown registers of both families put overheating and overload on
 * the same bits (Alarm Shutdown: the 1.0 error bits; Shutdown: Hardware
 * Error Status's), so one record field serves both. */
_Static_assert((unsigned)DXL_ERRBIT_OVERHEAT == (unsigned)DXL2_HWERR_OVERHEAT &&
               (unsigned)DXL_ERRBIT_OVERLOAD == (unsigned)DXL2_HWERR_OVERLOAD,
               "shutdown bits differ between the families");

/* A register of the table by the first of its names the table has: where
 * two models name one setting differently, the record has one field. */
static const struct dxl2_reg *dr_row(const struct dxl2_model *table, const char *name, const char *other)
{
	const struct dxl2_reg *r = dxl2_reg_lookup(table, name);
	return r == NULL && other != NULL ? dxl2_reg_lookup(table, other) : r;
}

static int32_t dr_get(const struct dxl2_model *table, const uint8_t *image, size_t len, const char *name,
                      const char *other)
{
	const struct dxl2_reg *r = dr_row(table, name, other);
	if (r == NULL || (size_t)r->addr + r->size > len)
		return 0;
	return dxl2_reg_decode(r, image + r->addr);
}

size_t dr_image_len(const struct dxl2_model *table)
{
	const struct dxl2_reg *last = dxl2_reg_lookup(table, "present_temperature");
	return last != NULL ? (size_t)last->addr + last->size : 0;
}

void dr_servo_decode(struct dr_servo *s, const struct dxl2_model *m, const struct dxl2_model *table,
                     const uint8_t *image, size_t len)
{
#define DR_GET(name, other) dr_get(table, image, len, name, other)
	s->m = m;
	s->table = table;
	s->model = (uint16_t)DR_GET("model_number", NULL);
	s->firmware = (uint8_t)DR_GET("firmware_version", NULL);
	s->return_delay = (uint8_t)DR_GET("return_delay_time", NULL);
	s->status_return_level = (uint8_t)DR_GET("status_return_level", NULL);
	s->temperature_limit = (uint8_t)DR_GET("temperature_limit", NULL);
	s->temperature = (uint8_t)DR_GET("present_temperature", NULL);
	s->min_voltage = (uint16_t)DR_GET("min_voltage_limit", NULL);
	s->max_voltage = (uint16_t)DR_GET("max_voltage_limit", NULL);
	s->voltage = (uint16_t)DR_GET("present_voltage", "present_input_voltage");
	s->min_limit = DR_GET("cw_angle_limit", "min_position_limit");
	s->max_limit = DR_GET("ccw_angle_limit", "max_position_limit");
	s->shutdown = (uint8_t)DR_GET("alarm_shutdown", "shutdown");
	s->has_alarm_led = dr_row(table, "alarm_led", NULL) != NULL;
	s->alarm_led = (uint8_t)DR_GET("alarm_led", NULL);
	s->max_output = (uint16_t)DR_GET("max_torque", "pwm_limit");
	s->has_torque_limit = dr_row(table, "torque_limit", NULL) != NULL;
	s->torque_limit = (uint16_t)DR_GET("torque_limit", NULL);
	s->torque_enable = (uint8_t)DR_GET("torque_enable", NULL);
	s->operating_mode = (uint8_t)DR_GET("operating_mode", NULL);
	s->hwerr = (uint8_t)DR_GET("hardware_error_status", NULL);
	s->bus_watchdog = (uint8_t)DR_GET("bus_watchdog", NULL);
#undef DR_GET
}

/* The family's start-up rules: the option its fixes carry, whether an
 * unknown model is refused. */
static const struct sm_setup *dr_family(const struct dr_context *c)
{
	return sm_family(c->proto->number)->setup;
}

static const struct sm_setup *dr_servo_family(const struct dr_servo *s)
{
	return sm_family(s->table->protocol)->setup;
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
/* Each packet's bytes from the protocol's own encoder (zeros stuff nothing). */
static double dr_packet(int bytes)
{
	return bytes > 0 ? (double)bytes : 0.0;
}

double dr_cycle_wire_us(const struct dxl_proto *p, unsigned nservos, unsigned read_len, unsigned write_len,
                        long baud)
{
	uint8_t buf[DXL2_MAX_PACKET], ids[DXL2_BROADCAST_ID], zero[DXL2_BROADCAST_ID * 4] = { 0 };
	double bytes = 0.0;

	if (nservos == 0 || baud <= 0 || nservos > DXL2_BROADCAST_ID - 1 || write_len > 4)
		return 0.0;
	for (unsigned i = 0; i < nservos; i++)
		ids[i] = (uint8_t)(i + 1);
	/* the replies: one status of read_len bytes a servo either way */
	bytes += nservos * dr_packet(p->encode_status(buf, sizeof buf, 1, 0, zero, read_len));
	if (dxl_proto_can(p, DXL_CAP_SYNC_READ))
		bytes += dr_packet(p->encode_sync_read(buf, sizeof buf, 0, (uint16_t)read_len, ids, nservos));
	else
		bytes += nservos * dr_packet(p->encode_read(buf, sizeof buf, 1, 0, (uint16_t)read_len));
	bytes += dr_packet(p->encode_sync_write(buf, sizeof buf, 0, (uint16_t)write_len, ids, zero, nservos));
	return bytes * 10.0 * 1e6 / (double)baud;
}

void dr_check_baud(const struct dr_context *c, unsigned asked, unsigned answered, struct dr_verdict *v)
{
	const char *opt = dr_family(c)->dxl_opt;

	if (answered == 0) {
		dr_set(v, DR_FAIL, "%ld bps: none of the %u servo(s) answered a PING; fix: find them at every rate: "
		       "dxl %s--port %s scan --bauds all (no servo at all: power, cable, and for a UART the wiring: "
		       "rs485 or echo, README \"On a robot\")", c->baud, asked, opt, c->port);
		return;
	}
	double wire_ms = 1e-3 * dr_cycle_wire_us(c->proto, answered, c->read_len, c->write_len, c->baud);
	const char *reads = dxl_proto_can(c->proto, DXL_CAP_SYNC_READ) ? "a SYNC_READ" : "a READ a servo";
	if (wire_ms > c->period_ms) {
		dr_set(v, DR_FAIL, "%ld bps: one cycle's bytes for %u servo(s) (%s, a SYNC_WRITE) take %.2f ms on "
		       "the wire, more than the %g ms period; fix: dxl %s--port %s setup %s (raises every servo "
		       "to 1000000 bps) and baud = 1000000 in [robot]", c->baud, answered, reads, wire_ms, c->period_ms,
		       opt, c->port, c->ids);
		return;
	}
	if (wire_ms > 0.5 * c->period_ms) {
		dr_set(v, DR_WARN, "%ld bps: one cycle's bytes for %u servo(s) take %.2f ms on the wire, more than half "
		       "the %g ms period; fix: a faster rate for every servo (dxl %s--port %s set-baud ID 1000000) and "
		       "baud = 1000000 in [robot]", c->baud, answered, wire_ms, c->period_ms, opt, c->port);
		return;
	}
	dr_set(v, DR_OK, "%ld bps: %u of %u servo(s) answered; one cycle's bytes take %.2f ms on the wire", c->baud,
	       answered, asked, wire_ms);
}

/* ---- each servo ----------------------------------------------------------------------------- */

void dr_check_model(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	const struct sm_setup *fam = dr_servo_family(s);
	char known[160];

	if (s->m != NULL) {
		dr_set(v, DR_OK, "%u (%s), firmware %u", s->model, s->m->name, s->firmware);
		return;
	}
	/* the AX-12A's start-up goes on with its own table (the AX series
	 * shares its addresses, not its speeds and torques); the X series'
	 * refuses, its models' tables differing */
	dr_set(v, DR_WARN, "%u, firmware %u: not in dxl's tables (%s); the checks below read it with the %s's "
	       "addresses, which it may not share, and undulated %s; fix: check its control table (dxl %s--port %s "
	       "dump %u prints it raw)", s->model, s->firmware, dxl2_model_names(s->table->protocol, known, sizeof known),
	       s->table->name, fam->strict ? "refuses to start with it" : "drives it with that table and motor figures",
	       fam->dxl_opt, c->port, s->id);
}

void dr_setup_fix(struct dr_verdict *v, const struct dr_context *c, const char *what)
{
	dr_add(v, "; fix: dxl %s--port %s setup %s --yes (%s)%s", dr_family(c)->dxl_opt, c->port, c->ids, what,
	       c->any_torque_on ? "; --yes turns torque off first: support the robot" : "");
}

void dr_check_return_delay(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	unsigned us = dxl2_return_delay_us(s->return_delay);

	if (us == 0) {
		dr_set(v, DR_OK, "0 us");
		return;
	}
	/* a reply of this servo's every cycle, and a read-back now and then */
	dr_set(v, DR_WARN, "%u us before every reply: costs %.2f ms of every %g ms cycle", us, 1e-3 * us, c->period_ms);
	dr_setup_fix(v, c, "writes return delay 0");
}

void dr_check_status_level(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	bool sync = dxl_proto_can(c->proto, DXL_CAP_SYNC_READ);

	switch (s->status_return_level) {
	case 0:
		dr_set(v, DR_FAIL, "0: answers PING only, so the loop's %s goes unanswered (undulated refuses to start); "
		       "fix: dxl %s--port %s write %u status_return_level 2", sync ? "SYNC_READ" : "READ of every joint",
		       dr_family(c)->dxl_opt, c->port, s->id);
		return;
	case 1:
		dr_set(v, DR_WARN, "1: %s answered, WRITEs not: undulated cannot confirm its register writes (torque, "
		       "limits) until its read-back", sync ? "SYNC_READ and READ" : "READ");
		dr_setup_fix(v, c, "writes status return level 2");
		return;
	default:
		dr_set(v, DR_OK, "%u", s->status_return_level);
	}
}

void dr_check_voltage(const struct dr_servo *s, struct dr_verdict *v)
{
	const struct dxl2_datasheet *d = &s->table->sheet;
	const char *name = s->m != NULL ? s->m->name : s->table->name;
	double volts = 0.1 * s->voltage, pct = 100.0 * volts / DXL2_REF_VOLTAGE;
	char range[64];

	snprintf(range, sizeof range, "(servo's limits %.1f..%.1f V)", 0.1 * s->min_voltage, 0.1 * s->max_voltage);
	if (s->voltage < s->min_voltage || s->voltage > s->max_voltage) {
		dr_set(v, DR_FAIL, "%.1f V %s: outside its limits, the servo flags every reply with its voltage error; fix: "
		       "the supply — %s", volts, range, s->voltage < s->min_voltage ? "charge or replace the battery, check "
		       "the cable's drop" : "a lower voltage");
		return;
	}
	if (s->m == NULL) {
		dr_set(v, DR_OK, "%.1f V %s", volts, range);   /* no datasheet to hold it against */
		return;
	}
	if (volts < d->rated_min_v - 1e-9) {
		dr_set(v, DR_FAIL, "%.1f V %s, below the %s's %g..%g V: it gives %.0f%% of its %g V torque and speed, and "
		       "sags further under load; fix: charge or replace the battery (%g V recommended), check the supply's "
		       "cable", volts, range, name, d->rated_min_v, d->rated_max_v, pct, DXL2_REF_VOLTAGE, d->rated_rec_v);
	} else if (volts < d->rated_rec_v - DR_VOLTS_BELOW_REC - 1e-9) {
		dr_set(v, DR_WARN, "%.1f V %s: %.0f%% of the %g V torque and speed, at rest, under the %s's recommended "
		       "%g V; fix: charge the battery", volts, range, pct, DXL2_REF_VOLTAGE, name, d->rated_rec_v);
	} else if (volts > d->rated_max_v * DR_VOLTS_OVER_SHARE + 1e-9) {
		dr_set(v, DR_WARN, "%.1f V %s, above the %s's %g V; fix: a supply of %g V", volts, range, name,
		       d->rated_max_v, d->rated_rec_v);
	} else {
		dr_set(v, DR_OK, "%.1f V %s", volts, range);
	}
}

void dr_check_temperature(const struct dr_servo *s, struct dr_verdict *v)
{
	unsigned t = s->temperature, lim = s->temperature_limit;

	if (t >= lim) {
		dr_set(v, DR_FAIL, "%u C, at or above its limit %u C: overheating, %s; fix: torque off and about 20 "
		       "minutes of cooling, then a lighter load", t, lim, (s->shutdown & DXL_ERRBIT_OVERHEAT) ?
		       "its shutdown switches torque off" : "and nothing switches its torque off");
	} else if (t + DR_TEMP_MARGIN_C >= lim) {
		dr_set(v, DR_WARN, "%u C, within %u C of its limit %u C: a gait heats it further; fix: let it cool "
		       "before a long run", t, DR_TEMP_MARGIN_C, lim);
	} else {
		dr_set(v, DR_OK, "%u C (limit %u C)", t, lim);
	}
}

/* The writes that give the servo the configured limits, lo and/or hi (-1:
 * that side is fine). The limits are EEPROM: every model refuses them with
 * torque on. */
static void dr_limits_fix(struct dr_verdict *v, const struct dr_context *c, const struct dr_servo *s, long lo,
                          long hi)
{
	const char *opt = dr_servo_family(s)->dxl_opt;
	const struct dxl2_reg *rlo = dr_row(s->table, "cw_angle_limit", "min_position_limit");
	const struct dxl2_reg *rhi = dr_row(s->table, "ccw_angle_limit", "max_position_limit");

	dr_add(v, "; fix: ");
	if (s->torque_enable)
		dr_add(v, "dxl %s--port %s torque %u off; ", opt, c->port, s->id);
	if (lo >= 0 && rlo != NULL)
		dr_add(v, "dxl %s--port %s write %u %s %ld%s", opt, c->port, s->id, rlo->name, lo, hi >= 0 ? "; " : "");
	if (hi >= 0 && rhi != NULL)
		dr_add(v, "dxl %s--port %s write %u %s %ld", opt, c->port, s->id, rhi->name, hi);
}

/* The servo model start-up would drive it as: its own, or where the
 * family runs an unknown model on its table (not strict), that one. */
static const struct sm_model *dr_sm(const struct dr_servo *s)
{
	const struct sm_model *m = sm_by_number(s->table->protocol, s->model);
	return m != NULL ? m : sm_family(s->table->protocol);
}

void dr_check_limits(const struct dr_servo *s, const struct cfg *cfg, size_t joint, const struct dr_context *c,
                     struct dr_verdict *v)
{
	const struct cfg_joint *cj = &cfg->joint[joint];
	const struct sm_model *sm = dr_sm(s);
	const char *what = sm->limits_name;
	int32_t lo, hi;
	char conf[160];

	setup_joint_limits_model(sm, cj, &lo, &hi);
	snprintf(conf, sizeof conf, "the configuration's %ld..%ld (joint %zu: neutral %+.3f + [%.3f, %.3f] rad)",
	         (long)lo, (long)hi, joint + 1, cj->neutral, cj->limit_min, cj->limit_max);
	if (dxl2_model_can(s->table, DXL2_CAP_WHEEL_BY_ANGLE_LIMITS) && s->min_limit == 0 && s->max_limit == 0) {
		if (cfg->actuation == CFG_ACT_TORQUE)
			dr_set(v, DR_WARN, "0..0: wheel mode, left by a torque-actuated run that did not stop cleanly; "
			       "undulated puts %s back at start", conf);
		else
			dr_set(v, DR_FAIL, "0..0: wheel mode (a goal position does nothing; undulated refuses to start), "
			       "against %s", conf);
		dr_limits_fix(v, c, s, lo, hi);
		return;
	}
	struct safety_limits both;
	if (!safety_limits_make_rad(&both, cj->neutral, cj->limit_min, cj->limit_max, sm_pos_to_rad(sm, s->min_limit),
	                            sm_pos_to_rad(sm, s->max_limit), cj->max_step)) {
		dr_set(v, DR_FAIL, "%ld..%ld have no %s in common with %s: undulated refuses to start", (long)s->min_limit,
		       (long)s->max_limit, what, conf);
		dr_limits_fix(v, c, s, lo, hi);
		return;
	}
	if (s->min_limit > lo || s->max_limit < hi) {
		dr_set(v, DR_WARN, "%ld..%ld, narrower than %s: undulated keeps goals inside both, so the joint stops at "
		       "%+.3f..%+.3f rad from neutral, short of what the configuration allows", (long)s->min_limit,
		       (long)s->max_limit, conf, both.lo - cj->neutral, both.hi - cj->neutral);
		dr_limits_fix(v, c, s, s->min_limit > lo ? lo : -1, s->max_limit < hi ? hi : -1);
		return;
	}
	dr_set(v, DR_OK, "%ld..%ld, around %s", (long)s->min_limit, (long)s->max_limit, conf);
}

void dr_check_alarms(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	char led[96], off[96], missing[96], extra[96];
	uint8_t lack = (uint8_t)(DR_SHUTDOWN_WANT & ~s->shutdown);
	uint8_t more = (uint8_t)(s->shutdown & ~DR_SHUTDOWN_WANT & DXL_ERRBIT_MASK);

	dxl_errbits_format(s->alarm_led, led, sizeof led);
	dxl_errbits_format(s->shutdown, off, sizeof off);
	if (lack == 0 && more == 0) {
		dr_set(v, DR_OK, "shutdown %u (%s), LED %u (%s)", s->shutdown, off, s->alarm_led, led);
		return;
	}
	dr_set(v, DR_WARN, "shutdown %u (%s), LED %u (%s)", s->shutdown, off, s->alarm_led, led);
	if (lack != 0)
		dr_add(v, ": %s does not switch torque off, and the motor is not protected from it",
		       dxl_errbits_format(lack, missing, sizeof missing));
	if (more != 0)
		dr_add(v, "%s %s switches torque off: a sagging battery or one damaged packet stops the joint until "
		       "undulated restores it", lack != 0 ? ";" : ":", dxl_errbits_format(more, extra, sizeof extra));
	dr_add(v, "; fix: %sdxl %s--port %s write %u alarm_shutdown %u (overheating|overload, the factory setting)",
	       s->torque_enable ? "(torque off first) " : "", dr_servo_family(s)->dxl_opt, c->port, s->id,
	       (unsigned)DR_SHUTDOWN_WANT);
}

void dr_check_mode(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	const char *name = dxl2_opmode_name(s->operating_mode), *opt = dr_servo_family(s)->dxl_opt;
	if (s->operating_mode == DXL2_OPMODE_POSITION) {
		dr_set(v, DR_OK, "3 (position)");
		return;
	}
	dr_set(v, DR_WARN, "%u (%s): a goal position is not what it follows, and outside position mode it ignores its "
	       "position limits; fix: dxl %s--port %s torque %u off; dxl %s--port %s write %u operating_mode 3",
	       s->operating_mode, name != NULL ? name : "unknown", opt, c->port, s->id, opt, c->port, s->id);
}

void dr_check_hwerr(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	char names[96];
	if (s->hwerr == 0) {
		dr_set(v, DR_OK, "none");
		return;
	}
	dr_set(v, DR_FAIL, "%u (%s): the servo %s until it is rebooted; fix: remove the cause (overload: a blocked "
	       "joint; overheating: let it cool; voltage: the supply), then dxl %s--port %s reboot %u",
	       s->hwerr, dxl2_hwerr_format(s->hwerr, names, sizeof names),
	       (s->hwerr & s->shutdown) ? "switched its torque off and keeps it off" : "flags every reply with the alert",
	       dr_servo_family(s)->dxl_opt, c->port, s->id);
}

void dr_check_torque(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	const struct dxl2_reg *out = dr_row(s->table, "max_torque", "pwm_limit");
	const char *opt = dr_servo_family(s)->dxl_opt, *out_name = dr_sm(s)->setup->output_limit_name;
	unsigned full = dr_sm(s)->torque_full;

	if (out != NULL && s->max_output == 0) {
		dr_set(v, DR_WARN, "%s 0 (EEPROM): it cannot move, and undulated %s; fix: dxl %s--port %s write %u %s %u",
		       out_name, dr_servo_family(s)->strict ? "refuses to start" : "uses full output as its limit", opt,
		       c->port, s->id, out->name, full);
		return;
	}
	if (s->has_torque_limit && s->torque_limit == 0) {
		dr_set(v, DR_WARN, "torque %s, torque limit 0: an alarm shut it down (what its replies say is on its "
		       "error-bits line); undulated writes the limit back at start, the cause stays", s->torque_enable ?
		       "on" : "off");
		dr_add(v, "; fix: find the cause (overload: a blocked joint; overheating: let it cool), then "
		       "dxl %s--port %s write %u torque_limit %u", opt, c->port, s->id, s->max_output);
		return;
	}
	dr_set(v, DR_OK, "%s", s->torque_enable ? "on" : "off");
	if (s->has_torque_limit)
		dr_add(v, ", torque limit %u of %s %u", s->torque_limit, out_name, s->max_output);
	else if (out != NULL)
		dr_add(v, ", %s %u", out_name, s->max_output);
	if (!s->torque_enable)
		dr_add(v, " (undulated turns it on at start)");
}

void dr_check_watchdog(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	unsigned ms = dxl2_watchdog_ms(s->bus_watchdog);
	const char *opt = dr_servo_family(s)->dxl_opt;
	if (s->bus_watchdog == 0) {
		dr_set(v, DR_OK, "off");
		return;
	}
	if (s->bus_watchdog == 0xFF) {
		dr_set(v, DR_FAIL, "fired (-1): the bus went silent longer than the watchdog allowed and the servo stopped; "
		       "fix: dxl %s--port %s write %u bus_watchdog 0, then torque on again", opt, c->port, s->id);
		return;
	}
	if (ms < 2.0 * c->period_ms) {
		unsigned units = (unsigned)(5.0 * c->period_ms / 20.0 + 0.999);
		dr_set(v, DR_WARN, "%u ms, less than two %g ms periods: one late cycle stops the servo; fix: dxl %s--port %s "
		       "write %u bus_watchdog %u (%u ms)", ms, c->period_ms, opt, c->port, s->id, units,
		       dxl2_watchdog_ms((uint8_t)units));
		return;
	}
	dr_set(v, DR_OK, "%u ms: the servo stops when the bus is silent that long", ms);
}

/* The bits of a reply's error field that are the servo's own condition,
 * with what to do about each: 1.0's error byte names the condition itself,
 * 2.0's ERR raises the alert and Hardware Error Status names it. Every
 * other bit (or 2.0's error number) answers a packet of ours the servo did
 * not like, which this tool should never send. */
static const struct dr_err_fix {
	const struct dxl_proto *proto;
	uint8_t bits;
	const char *fix;
} dr_err_fixes[] = {
	{ &dxl_proto_v1, DXL_ERRBIT_VOLTAGE, "the supply (voltage line)" },
	{ &dxl_proto_v1, DXL_ERRBIT_OVERHEAT, "let it cool (temperature line)" },
	{ &dxl_proto_v1, DXL_ERRBIT_OVERLOAD, "free the joint, then undulated's start writes the torque limit back" },
	{ &dxl_proto_v2, DXL2_ERR_ALERT, "the alert: a hardware error (its hardware error line)" },
};

bool dr_check_errbits(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v)
{
	char names[96];
	uint8_t state = 0;

	if (s->errbits == 0)
		return false;
	for (size_t i = 0; i < sizeof dr_err_fixes / sizeof dr_err_fixes[0]; i++)
		if (dr_err_fixes[i].proto == c->proto)
			state |= dr_err_fixes[i].bits;
	dr_set(v, (s->errbits & state) ? DR_FAIL : DR_WARN, "its replies carry 0x%02X (%s)", s->errbits,
	       c->proto->err_format(s->errbits, names, sizeof names));
	dr_add(v, "; fix: ");
	for (size_t i = 0; i < sizeof dr_err_fixes / sizeof dr_err_fixes[0]; i++)
		if (dr_err_fixes[i].proto == c->proto && (s->errbits & dr_err_fixes[i].bits))
			dr_add(v, "%s; ", dr_err_fixes[i].fix);
	if (s->errbits & ~state)
		dr_add(v, "it refused a packet of ours: a damaged line (%s: cable, termination, a second master on the "
		       "bus); ", c->proto->check_name);
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
	       "%lld of %lld transactions failed, %lld cycle(s) cut off by the next tick%s%s", b->p50_ms, b->p99_ms,
	       b->max_ms, b->floor_ms, b->floor_ms > 0 ? b->p50_ms / b->floor_ms : 0.0, b->period_ms,
	       100.0 * b->p99_ms / b->period_ms, b->cycles, b->joints, b->errors, b->transactions, b->cut_off,
	       b->read_by[0] ? "; read by " : "", b->read_by);
	if (lv != DR_OK)
		dr_add(v, "; fix:%s", why[0] ? why + 1 : " see the lines above");
}
