/*
 * commands2.c — the `dxl` commands on Protocol 2.0 (X series, --protocol 2).
 *
 * Registers go by the names of the model's own control table (dxl2_table.h),
 * chosen by the model number the servo's PING returns; a model not in the
 * tables still answers raw addresses (--size bytes), and every command that
 * falls back to them says so. The output contract is commands.c's: results
 * on `out`, one line per failure on `err` naming the next command, the exit
 * code the kind. Nothing is written before it was checked against the table
 * and against what the servo holds now (limits, torque for EEPROM).
 */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "doctor.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "dxlt_priv.h"
#include "num.h"

/* The rate `setup` puts a slower bus at: at the factory 57600 bps one cycle
 * of two servos takes more than the 10 ms period on the wire alone. */
#define DXLT2_SETUP_BAUD 1000000L
/* The first bytes of the X tables, read in one READ for `dump`, `write`'s
 * checks and `setup` (0..147: model number .. present temperature). */
#define DXLT2_IMAGE_LEN DXLT_IMAGE_MAX

/* ---- scan ------------------------------------------------------------------ */

int dxlt2_scan_at(struct dxlt *t, long baud, unsigned *found)
{
	struct bus_found servo[BUS_MULTI_MAX];
	size_t n = 0;
	/* One broadcast PING: every servo answers in ID order with its model
	 * and firmware, so a rate costs one deadline, not 253 timeouts. */
	int r = bus_ping_all(&t->bus, servo, BUS_MULTI_MAX, &n);

	if (r == DXL_E_DISCONNECTED || r == DXL_E_IO)
		return dxlt_bus_fail(t, DXL2_BROADCAST_ID, r);
	for (size_t i = 0; i < n; i++) {
		const struct bus_found *f = &servo[i];
		const struct dxl2_model *m = dxl2_model_by_number(f->model);
		if (f->id < t->a.id_lo || f->id > t->a.id_hi)
			continue;
		t->errseen2[f->id] |= f->err;
		(*found)++;
		fprintf(t->out, "%-4u %-6u %-13s %-9u %-8ld 2.0\n", f->id, f->model, m != NULL ? m->name : "unknown",
		        f->firmware, baud);
	}
	return DXLT_EXIT_OK;
}

/* ---- write / torque ------------------------------------------------------------------ */

static int dxlt2_parse_value(struct dxlt *t, const struct dxlt_reg *reg, const char *text, long *value)
{
	enum num_status st = num_parse_long(text, LONG_MIN, LONG_MAX, value);
	if (st != NUM_OK && st != NUM_RANGE) {
		fprintf(t->err, "dxl: value '%s' for %s is %s\n", text, reg->name, num_strerror(st));
		return DXLT_EXIT_USAGE;
	}
	if (reg->row == NULL) {
		long lo = reg->size == 4 ? INT32_MIN : 0, hi = reg->size == 4 ? (long)UINT32_MAX : (1L << (8 * reg->size)) - 1;
		if (st != NUM_OK || *value < lo || *value > hi) {
			fprintf(t->err, "dxl: value '%s' does not fit %u byte(s)\n", text, reg->size);
			return DXLT_EXIT_USAGE;
		}
		return DXLT_EXIT_OK;
	}
	if (reg->row->access != DXL_ACCESS_RW) {
		fprintf(t->err, "dxl: %s (address %u) is read-only\n", reg->name, reg->addr);
		return DXLT_EXIT_USAGE;
	}
	if (st != NUM_OK || *value < reg->row->min || *value > reg->row->max) {
		fprintf(t->err, "dxl: value '%s' out of range for %s (%ld..%ld)\n", text, reg->name, (long)reg->row->min,
		        (long)reg->row->max);
		return DXLT_EXIT_USAGE;
	}
	return DXLT_EXIT_OK;
}

/* What the servo holds now decides what it takes: limits, operating modes,
 * torque for EEPROM. The servo would answer an error; say why first. */
static int dxlt2_check_live(struct dxlt *t, const struct dxlt_servo *s, const struct dxlt_reg *reg, long value,
                            const uint8_t *mem)
{
	int32_t lo, hi;

	if (dxl2_reg_check_write(s->m, reg->row, value) != DXL_OK) {
		fprintf(t->err, "dxl: the %s has no %s %ld (operating modes: dxl --protocol 2 dump %u)\n", s->m->name,
		        reg->name, value, s->id);
		return DXLT_EXIT_USAGE;
	}
	if (dxl2_reg_check_write_live(s->m, reg->row, value, mem, DXLT2_IMAGE_LEN) != DXL_OK &&
	    dxl2_reg_range(s->m, reg->row, mem, DXLT2_IMAGE_LEN, &lo, &hi) == DXL_OK) {
		fprintf(t->err, "dxl: value %ld outside %s's range on ID %u now (%ld..%ld, from its limit registers; "
		        "the servo would answer a data limit error)\n", value, reg->name, s->id, (long)lo, (long)hi);
		return DXLT_EXIT_USAGE;
	}
	if (reg->row->area == DXL_AREA_EEPROM && mem[DXL2_X_TORQUE_ENABLE] != 0) {
		fprintf(t->err, "dxl: ID %u has torque on, and an X-series servo refuses EEPROM writes (%s) then with "
		        "an access error: dxl --protocol 2 --port %s torque %u off\n", s->id, reg->name, port_path(t->port),
		        s->id);
		return DXLT_EXIT_REFUSED;
	}
	return DXLT_EXIT_OK;
}

/* Write and know whether it took, as far as the status return level lets
 * us (68: 0 PING only, 1 PING and READ, 2 everything): as commands.c's
 * dxlt_write_checked. */
static int dxlt2_write_checked(struct dxlt *t, uint8_t id, const struct dxlt_reg *reg, long value, uint8_t level)
{
	uint8_t raw[4], back[4];
	bool answered = level >= 2 && reg->addr != DXL2_X_STATUS_RETURN_LEVEL;

	if (reg->row != NULL)
		dxl2_reg_encode(reg->row, (int32_t)value, raw);
	else
		dxl2_put_u32(raw, (uint32_t)value);
	int r = dxlt_write(t, id, reg->addr, raw, reg->size, answered);
	if (r != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (answered)
		return DXLT_EXIT_OK;
	uint8_t now_level = reg->addr == DXL2_X_STATUS_RETURN_LEVEL ? (uint8_t)value : level;
	if (now_level == 0) {
		fprintf(t->out, "ID %u: %s = %ld sent, not confirmed: the servo answers PING only (status return level "
		        "0)\n", id, reg->name, value);
		return DXLT_EXIT_OK;
	}
	if (reg->row != NULL && reg->row->area == DXL_AREA_EEPROM)
		dxlt_sleep_us(t->fam->settle_us);
	if ((r = dxlt_read(t, id, reg->addr, reg->size, back)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (memcmp(back, raw, reg->size) != 0) {
		fprintf(t->err, "dxl: ID %u kept %s at %ld (wrote %ld)\n", id, reg->name, (long)dxlt_decode(reg, back),
		        value);
		return t->errseen2[id] != 0 ? DXLT_EXIT_SERVO : DXLT_EXIT_BUS;
	}
	fprintf(t->out, "ID %u: %s = %ld (read back: status return level %u does not answer WRITE)\n", id, reg->name,
	        value, level);
	return DXLT_EXIT_OK;
}

/* The whole write: checked against the table and the servo's image first. */
static int dxlt2_write_reg(struct dxlt *t, const struct dxlt_servo *s, const struct dxlt_reg *reg, long value)
{
	uint8_t mem[DXLT2_IMAGE_LEN];
	int rc, r;

	if (reg->row == NULL)   /* a model we do not know: its level unknown too, a reply expected */
		return dxlt2_write_checked(t, s->id, reg, value, 2);
	if ((r = dxlt_read(t, s->id, 0, sizeof mem, mem)) == DXL_E_TIMEOUT) {
		/* level 0: PING only; nothing can be checked or confirmed */
		fprintf(t->err, "dxl: ID %u answers PING but not READ (status return level 0): %s not checked against "
		        "its limits\n", s->id, reg->name);
		return dxlt2_write_checked(t, s->id, reg, value, 0);
	}
	if (r != DXL_OK)
		return dxlt_bus_fail(t, s->id, r);
	if ((rc = dxlt2_check_live(t, s, reg, value, mem)) != DXLT_EXIT_OK)
		return rc;
	uint8_t level = mem[DXL2_X_STATUS_RETURN_LEVEL] > 2 ? 2 : mem[DXL2_X_STATUS_RETURN_LEVEL];
	return dxlt2_write_checked(t, s->id, reg, value, level);
}

int dxlt2_cmd_write(struct dxlt *t)
{
	struct dxlt_servo s;
	struct dxlt_reg reg;
	uint8_t id;
	long value;
	int rc;

	if ((rc = dxlt_need_args(t, 3, "--protocol 2 write ID REG VALUE")) ||
	    (rc = dxlt_arg_servo_id(t, t->a.pos[0], &id)) || (rc = dxlt_identify(t, id, &s)) ||
	    (rc = dxlt_arg_reg(t, &s, t->a.pos[1], &reg)) || (rc = dxlt2_parse_value(t, &reg, t->a.pos[2], &value)))
		return rc;
	if (reg.row != NULL && (reg.addr == DXL2_X_ID || reg.addr == DXL2_X_BAUD_RATE)) {
		fprintf(t->err, "dxl: %s moves the servo away from this ID/rate: use dxl --protocol 2 --port %s %s\n",
		        reg.name, port_path(t->port), reg.addr == DXL2_X_ID ? "set-id OLD NEW" : "set-baud ID BAUD");
		return DXLT_EXIT_USAGE;
	}
	return dxlt2_write_reg(t, &s, &reg, value);
}

int dxlt2_cmd_torque(struct dxlt *t)
{
	struct dxlt_servo s;
	struct dxlt_reg reg = { NULL, DXL2_X_TORQUE_ENABLE, 1, "torque_enable" };
	uint8_t id;
	int rc;

	if ((rc = dxlt_need_args(t, 2, "--protocol 2 torque ID on|off")) || (rc = dxlt_arg_servo_id(t, t->a.pos[0], &id)))
		return rc;
	const char *w = t->a.pos[1];
	bool on = strcmp(w, "on") == 0 || strcmp(w, "1") == 0;
	if (!on && strcmp(w, "off") != 0 && strcmp(w, "0") != 0) {
		fprintf(t->err, "dxl: torque takes on or off, not '%s'\n", w);
		return DXLT_EXIT_USAGE;
	}
	if ((rc = dxlt_identify(t, id, &s)) != DXLT_EXIT_OK)
		return rc;
	if (s.m != NULL)
		reg.row = dxl2_reg_at(s.m, DXL2_X_TORQUE_ENABLE);
	else
		dxlt_raw_note(t, &s, reg.addr, reg.size);
	return dxlt2_write_reg(t, &s, &reg, on ? 1 : 0);
}

/* ---- setup ------------------------------------------------------------------------------ */

/* Write one byte if it differs, then read it back (writes not waited for:
 * the level may be below 2, or about to change). */
static int dxlt2_setup_byte(struct dxlt *t, uint8_t id, uint16_t addr, const char *name, uint8_t want, uint8_t have)
{
	uint8_t back = 0;
	int r;

	if (have == want) {
		fprintf(t->out, "ID %u: %s already %u\n", id, name, want);
		return DXLT_EXIT_OK;
	}
	if ((r = dxlt_write(t, id, addr, &want, 1, false)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	dxlt_sleep_us(t->fam->settle_us);
	if ((r = dxlt_read(t, id, addr, 1, &back)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (back != want) {
		fprintf(t->err, "dxl: ID %u kept %s at %u (wrote %u)\n", id, name, back, want);
		return t->errseen2[id] ? DXLT_EXIT_SERVO : DXLT_EXIT_BUS;
	}
	fprintf(t->out, "ID %u: %s set to %u\n", id, name, want);
	return DXLT_EXIT_OK;
}

static int dxlt2_setup_one(struct dxlt *t, uint8_t id, bool *current)
{
	uint8_t mem[DXLT2_IMAGE_LEN];
	struct dxlt_servo s;
	char names[160];
	int rc, r;

	if ((rc = dxlt_identify(t, id, &s)) != DXLT_EXIT_OK)
		return rc;
	if (s.m == NULL) {
		fprintf(t->err, "dxl: ID %u is model %u, not in dxl's tables (%s): setup does not "
		        "know its registers\n", id, s.model, dxl2_model_names(2, names, sizeof names));
		return DXLT_EXIT_REFUSED;
	}
	*current = *current || s.m->current_sensing;
	if ((r = dxlt_read(t, id, 0, sizeof mem, mem)) != DXL_OK) {
		fprintf(t->err, "dxl: ID %u answers PING but not READ: status return level 0? (the loop's SYNC_READ "
		        "needs 1 or 2)\n", id);
		return r == DXL_E_TIMEOUT ? DXLT_EXIT_BUS : dxlt_bus_fail(t, id, r);
	}
	if (mem[DXL2_X_TORQUE_ENABLE]) {
		if (!t->a.yes) {
			fprintf(t->err, "dxl: ID %u has torque on, and an X-series servo refuses EEPROM writes then; add --yes "
			        "to turn it off first (the joint goes limp: support the robot)\n", id);
			return DXLT_EXIT_REFUSED;
		}
		if ((rc = dxlt2_setup_byte(t, id, DXL2_X_TORQUE_ENABLE, "torque_enable", 0, 1)) != DXLT_EXIT_OK)
			return rc;
	}
	/* 0: the reply follows the request at once instead of after 500 µs */
	if ((rc = dxlt2_setup_byte(t, id, DXL2_X_RETURN_DELAY_TIME, "return_delay_time", 0,
	                           mem[DXL2_X_RETURN_DELAY_TIME])) != DXLT_EXIT_OK)
		return rc;
	uint8_t want_level = (uint8_t)(t->a.status_level >= 0 ? t->a.status_level : 2);
	return dxlt2_setup_byte(t, id, DXL2_X_STATUS_RETURN_LEVEL, "status_return_level", want_level,
	                        mem[DXL2_X_STATUS_RETURN_LEVEL]);
}

/* A bus slower than 1 Mbps cannot carry a 100 Hz cycle (57600 bps, the
 * factory rate, needs 16 ms for two servos' SYNC_READ and SYNC_WRITE): every
 * servo goes to 1 Mbps, then the port, then each must answer there. */
static int dxlt2_setup_baud(struct dxlt *t, const uint8_t *ids, int n)
{
	uint8_t reg;
	int r, rc;

	if (port_baud(t->port) >= DXLT2_SETUP_BAUD)
		return DXLT_EXIT_OK;
	dxl2_baud_to_reg(DXLT2_SETUP_BAUD, &reg);
	for (int i = 0; i < n; i++)
		if ((r = dxlt_write(t, ids[i], DXL2_X_BAUD_RATE, &reg, 1, false)) != DXL_OK)
			return dxlt_bus_fail(t, ids[i], r);
	long before = port_baud(t->port);
	dxlt_sleep_us(t->fam->settle_us);
	if ((rc = dxlt_set_baud(t, DXLT2_SETUP_BAUD)) != DXLT_EXIT_OK)
		return rc;
	for (int i = 0; i < n; i++) {
		if ((r = dxlt_verify_ping(t, ids[i])) != DXL_OK) {
			fprintf(t->err, "dxl: ID %u does not answer at %ld bps after the change (%s); try: dxl --port %s scan "
			        "--bauds all\n", ids[i], DXLT2_SETUP_BAUD, dxl_strerror(r), port_path(t->port));
			return r == DXL_E_DISCONNECTED ? DXLT_EXIT_PORT : DXLT_EXIT_BUS;
		}
		fprintf(t->out, "ID %u: baud_rate %ld -> %ld bps (a 100 Hz cycle does not fit the period below 1 Mbps; "
		        "undulated's configuration needs baud = %ld)\n", ids[i], before, DXLT2_SETUP_BAUD, DXLT2_SETUP_BAUD);
	}
	return DXLT_EXIT_OK;
}

int dxlt2_cmd_setup(struct dxlt *t)
{
	uint8_t ids[DXL2_MAX_ID + 1];
	int worst = DXLT_EXIT_OK, n = t->a.npos;
	bool current = false;   /* a servo senses its current: the loop reads it too */

	if (n < 1 || n > DXL2_MAX_ID + 1)
		return dxlt_need_args(t, -1, "--protocol 2 setup ID... [--status-level N] [--yes]");
	for (int i = 0; i < n; i++) {
		int rc = dxlt_arg_servo_id(t, t->a.pos[i], &ids[i]);
		if (rc != DXLT_EXIT_OK)
			return rc;
	}
	for (int i = 0; i < n; i++) {
		int rc = dxlt2_setup_one(t, ids[i], &current);
		if (rc == DXLT_EXIT_PORT)
			return rc;
		worst = rc > worst ? rc : worst;
	}
	if (worst == DXLT_EXIT_OK && (worst = dxlt2_setup_baud(t, ids, n)) == DXLT_EXIT_PORT)
		return worst;
	port_latency_check_fd(port_path(t->port), port_fd(t->port), true, &t->latency);
	fprintf(t->out, "adapter: %s\n", t->latency.note);
	/* the loop's SYNC_READ: position + velocity, and the current on the XM430 */
	unsigned read_len = current ? DR2_READ_LEN_CURRENT : DR2_READ_LEN;
	double wire_ms = 1e-3 * dr2_cycle_wire_us((unsigned)n, read_len, port_baud(t->port));
	int latency_ms = t->latency.known ? t->latency.timer_ms : 0;
	double total_ms = wire_ms + latency_ms;
	fprintf(t->out, "bus time per cycle for %d servo%s at %ld bps: %.2f ms on the wire (one SYNC_READ of %u bytes "
	        "each, one SYNC_WRITE) + %d ms adapter latency = %.2f ms of the 10 ms period%s\n", n, n == 1 ? "" : "s",
	        port_baud(t->port), wire_ms, read_len, latency_ms, total_ms, total_ms > 5.0 ? " (too much for 100 Hz)" : "");
	if (t->latency.known && t->latency.timer_ms > 1) {
		fprintf(t->err, "dxl: %s\n", t->latency.note);
		if (worst == DXLT_EXIT_OK)
			worst = DXLT_EXIT_PORT;
	}
	return worst;
}
