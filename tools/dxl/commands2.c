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
