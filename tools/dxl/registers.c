/*
 * registers.c — the `dxl` commands that go by a servo's control table
 * (ping, read, dump, write, torque, setup), written once over every model: registers by name
 * through the model descriptor's rows (dxl2_table.h), values through the one
 * row type. Where the family's PING names the model (Protocol 2.0) the
 * servo is identified first and a model not in the tables still answers
 * raw addresses (--size bytes), saying so; where it does not (Protocol 1.0)
 * the family's first model is taken, as its servos all share one table.
 * The output contract is commands.c's.
 */
#include <limits.h>
#include <string.h>

#include "dxl2.h"
#include "dxl2_table.h"
#include "dxl_proto.h"
#include "daemon/servo_model.h"
#include "doctor.h"
#include "dxlt_priv.h"
#include "num.h"

/* The models dxl knows on this family's protocol, for messages. */
static const char *dxlt_known(const struct dxlt *t)
{
	static char names[160];
	return dxl2_model_names(t->fam->protocol, names, sizeof names);
}

size_t dxlt_image_len(const struct dxl2_model *m)
{
	size_t end = 0;

	if (m == NULL)
		return DXLT_IMAGE_MAX;
	for (size_t i = 0; i < m->nregs; i++)
		if ((size_t)m->regs[i].addr + m->regs[i].size > end)
			end = (size_t)m->regs[i].addr + m->regs[i].size;
	return end < DXLT_IMAGE_MAX ? end : DXLT_IMAGE_MAX;
}

int dxlt_identify(struct dxlt *t, uint8_t id, struct dxlt_servo *s)
{
	memset(s, 0, sizeof *s);
	s->id = id;
	if (!t->fam->ping_names_model) {
		s->m = t->fam_model;
		return DXLT_EXIT_OK;
	}
	int r = dxlt2_ping(t, id, &s->model, &s->firmware);
	if (r != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	s->pinged = true;
	s->m = dxl2_model_find(t->fam->protocol, s->model);
	return DXLT_EXIT_OK;
}

void dxlt_raw_note(struct dxlt *t, const struct dxlt_servo *s, uint16_t addr, uint8_t size)
{
	fprintf(t->err, "dxl: ID %u is model %u, not in dxl's tables (%s): address %u taken as "
	        "%u raw byte%s, unchecked (--size 1|2|4)\n", s->id, s->model, dxlt_known(t), addr, size,
	        size == 1 ? "" : "s");
}

int dxlt_arg_reg(struct dxlt *t, const struct dxlt_servo *s, const char *text, struct dxlt_reg *out)
{
	long addr;

	if (s->m != NULL) {
		out->row = dxl2_reg_lookup(s->m, text);
		if (out->row == NULL) {
			fprintf(t->err, "dxl: unknown register '%s' for the %s (names and addresses: dxl %s--port %s "
			        "dump %u)\n", text, s->m->name, t->fam->opt, port_path(t->port), s->id);
			return DXLT_EXIT_USAGE;
		}
		out->addr = out->row->addr;
		out->size = out->row->size;
		out->name = out->row->name;
		return DXLT_EXIT_OK;
	}
	if (num_parse_long(text, 0, UINT16_MAX, &addr) != NUM_OK) {
		fprintf(t->err, "dxl: ID %u is model %u, not in dxl's tables (%s): registers by "
		        "address only, not '%s'\n", s->id, s->model, dxlt_known(t), text);
		return DXLT_EXIT_USAGE;
	}
	out->row = NULL;
	out->addr = (uint16_t)addr;
	out->size = (uint8_t)(t->a.size > 0 ? t->a.size : 1);
	out->name = "address";
	dxlt_raw_note(t, s, out->addr, out->size);
	return DXLT_EXIT_OK;
}

int32_t dxlt_decode(const struct dxlt_reg *reg, const uint8_t *raw)
{
	if (reg->row != NULL)
		return dxl2_reg_decode(reg->row, raw);
	return reg->size == 4 ? (int32_t)dxl2_get_u32(raw) : reg->size == 2 ? dxl_get_u16(raw) : raw[0];
}

/* ---- ping ----------------------------------------------------------------------- */

/* Where the PING does not name the model, READ it (status return level 0
 * answers PING only: then the ID is all there is to say). */
static bool dxlt_ping_identity(struct dxlt *t, struct dxlt_servo *s)
{
	uint8_t raw[2], fw = 0;
	const struct dxl2_reg *model = dxl2_reg_lookup(t->fam_model, "model_number");
	const struct dxl2_reg *firmware = dxl2_reg_lookup(t->fam_model, "firmware_version");

	if (s->pinged)
		return true;
	if (dxlt_read(t, s->id, model->addr, model->size, raw) != DXL_OK)
		return false;
	s->model = dxl_get_u16(raw);
	s->m = dxl2_model_find(t->fam->protocol, s->model);
	if (dxlt_read(t, s->id, firmware->addr, 1, &fw) == DXL_OK)
		s->firmware = fw;
	return true;
}

int dxlt_cmd_ping(struct dxlt *t)
{
	struct dxlt_servo s;
	uint8_t id;
	int rc, r;

	if ((rc = dxlt_need_form(t, 1, "ping ID")) || (rc = dxlt_arg_servo_id(t, t->a.pos[0], &id)) ||
	    (rc = dxlt_identify(t, id, &s)))
		return rc;
	if (!s.pinged && (r = dxlt_ping(t, id)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	fprintf(t->out, "ID %u answered in %u us", id, (unsigned)t->bus.servo[id].rtt_last_us);
	if (dxlt_ping_identity(t, &s))
		fprintf(t->out, ": model %u (%s), firmware %u, %s\n", s.model, dxlt_model_name(t->fam->protocol, s.model), s.firmware,
		        t->fam->label);
	else
		fprintf(t->out, ": answers PING only (status return level 0), %s\n", t->fam->label);
	/* only where the model picks the table does an unknown one change what dxl can do */
	if (s.pinged && s.m == NULL)
		fprintf(t->err, "dxl: model %u is not in dxl's tables (%s): read and write it by "
		        "address (--size 1|2|4)\n", s.model, dxlt_known(t));
	return DXLT_EXIT_OK;
}

/* ---- read / dump ------------------------------------------------------------------ */

int dxlt_cmd_read(struct dxlt *t)
{
	struct dxlt_servo s;
	struct dxlt_reg reg;
	uint8_t id, raw[4] = { 0 };
	char text[96];
	int rc;

	if ((rc = dxlt_need_form(t, 2, "read ID REG [--units]")) || (rc = dxlt_arg_servo_id(t, t->a.pos[0], &id)) ||
	    (rc = dxlt_identify(t, id, &s)) || (rc = dxlt_arg_reg(t, &s, t->a.pos[1], &reg)))
		return rc;
	int r = dxlt_read(t, id, reg.addr, reg.size, raw);
	if (r == DXL_E_TIMEOUT && (s.pinged || dxlt_ping(t, id) == DXL_OK)) {
		fprintf(t->err, "dxl: ID %u answers PING but not READ: status return level 0 (raise it: dxl %s--port %s "
		        "write %u status_return_level 2)\n", id, t->fam->opt, port_path(t->port), id);
		return DXLT_EXIT_BUS;
	}
	if (r != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	int32_t v = dxlt_decode(&reg, raw);
	if (t->a.units && reg.row != NULL)
		fprintf(t->out, "%s\n", dxl2_reg_format(reg.row, v, text, sizeof text));
	else if (reg.row == NULL || !reg.row->is_signed)
		fprintf(t->out, "%lu\n", (unsigned long)(uint32_t)v);
	else
		fprintf(t->out, "%ld\n", (long)v);
	return DXLT_EXIT_OK;
}

/* One servo's line of a sync-read or bulk-read: ID, the register's name
 * (bulk-read: each servo its own), and the value (in units with --units). */
static void dxlt_multi_line(struct dxlt *t, uint8_t id, const struct dxlt_reg *reg, const uint8_t *raw, bool named)
{
	char text[96];
	int32_t v = dxlt_decode(reg, raw);
	fprintf(t->out, "%u ", id);
	if (named)
		fprintf(t->out, "%s ", reg->row != NULL ? reg->row->name : reg->name);
	if (t->a.units && reg->row != NULL)
		fprintf(t->out, "%s\n", dxl2_reg_format(reg->row, v, text, sizeof text));
	else if (reg->row == NULL || !reg->row->is_signed)
		fprintf(t->out, "%lu\n", (unsigned long)(uint32_t)v);
	else
		fprintf(t->out, "%ld\n", (long)v);
}

/* Nobody answered a fast read: the likely why, and what to do. */
static void dxlt_fast_hint(struct dxlt *t, const char *what, const uint8_t *ids)
{
	fprintf(t->err, "dxl: no reply to %s: servos answer it from firmware 45 (X430/X540; not "
	        "the 2XL/2XC), and one that does not stops the others' turns; see each servo's firmware with "
	        "dxl %s--port %s ping %u, or read without --fast\n", what, t->fam->opt, port_path(t->port), ids[0]);
}

/* A sync-read's or bulk-read's outcome: the lines of the servos that
 * answered, then each failure said (the exit of the last). each: a
 * register per slot (bulk-read), named on its line; else regs[0] for all. */
static int dxlt_multi_report(struct dxlt *t, const struct bus_multi *m, int r, const struct dxlt_reg *regs,
                             bool each, const char *cmd, const char *instr, const uint8_t *ids)
{
	int rc = DXLT_EXIT_OK;
	if (r == DXL_E_UNSUPPORTED) {
		fprintf(t->err, "dxl: Protocol %s has no %s (--protocol 2 for X servos)\n", bus_proto(&t->bus)->name,
		        instr);
		return DXLT_EXIT_USAGE;
	}
	if (r == DXL_E_ARG) {
		fprintf(t->err, "dxl: %s: each servo once, at most %d\n", cmd, BUS_MULTI_MAX);
		return DXLT_EXIT_USAGE;
	}
	for (size_t i = 0; i < m->n; i++) {
		const uint8_t *p = bus_multi_data(m, i);
		if (p == NULL)
			continue;
		dxlt_seen(t, m->id[i], m->err[i]);
		dxlt_multi_line(t, m->id[i], &regs[each ? i : 0], p, each);
	}
	if (m->answered == 0 && t->a.fast && bus_multi_failed(m, NULL, 0) == m->n && m->status[0] == DXL_E_TIMEOUT) {
		dxlt_fast_hint(t, instr, ids);
		return DXLT_EXIT_BUS;
	}
	for (size_t i = 0; i < m->n; i++)
		if (m->status[i] != DXL_OK)
			rc = dxlt_bus_fail(t, m->id[i], m->status[i]);
	return rc;
}

int dxlt_cmd_sync_read(struct dxlt *t)
{
	struct dxlt_servo s;
	struct dxlt_reg reg;
	uint8_t ids[BUS_MULTI_MAX], data[BUS_MULTI_MAX * 4];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	size_t n = 0;
	int rc;
	if (t->a.npos < 2 || t->a.npos - 1 > BUS_MULTI_MAX)
		return dxlt_need_form(t, t->a.npos < 2 ? 2 : -1, "sync-read REG ID... [--fast] [--units]");
	for (int i = 1; i < t->a.npos; i++)
		if ((rc = dxlt_arg_servo_id(t, t->a.pos[i], &ids[n++])) != DXLT_EXIT_OK)
			return rc;
	if ((rc = dxlt_identify(t, ids[0], &s)) || (rc = dxlt_arg_reg(t, &s, t->a.pos[0], &reg)))
		return rc;
	int r = t->a.fast ? bus_fast_sync_read(&t->bus, reg.addr, reg.size, ids, n, &m)
	                  : bus_sync_read(&t->bus, reg.addr, reg.size, ids, n, &m);
	return dxlt_multi_report(t, &m, r, &reg, false, "sync-read", t->a.fast ? "Fast Sync Read" : "SYNC_READ", ids);
}

/* bulk-read ID:REG...: each servo's register named by its own model. */
int dxlt_cmd_bulk_read(struct dxlt *t)
{
	struct dxlt_servo s;
	struct dxlt_reg regs[BUS_MULTI_MAX];
	struct dxl_item items[BUS_MULTI_MAX];
	uint8_t ids[BUS_MULTI_MAX], data[BUS_MULTI_MAX * 4];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	size_t n = 0;
	int rc;
	if (t->a.npos < 1 || t->a.npos > BUS_MULTI_MAX)
		return dxlt_need_form(t, t->a.npos < 1 ? 1 : -1, "bulk-read ID:REG... [--fast] [--units]");
	for (int i = 0; i < t->a.npos; i++, n++) {
		char id_text[8];
		const char *arg = t->a.pos[i], *colon = strchr(arg, ':');
		if (colon == NULL || colon == arg || (size_t)(colon - arg) >= sizeof id_text || colon[1] == '\0') {
			fprintf(t->err, "dxl: bulk-read: '%s' is not ID:REG (e.g. 1:present_position 2:present_current)\n",
			        arg);
			return DXLT_EXIT_USAGE;
		}
		memcpy(id_text, arg, (size_t)(colon - arg));
		id_text[colon - arg] = '\0';
		if ((rc = dxlt_arg_servo_id(t, id_text, &ids[n])) != DXLT_EXIT_OK)
			return rc;
		if ((rc = dxlt_identify(t, ids[n], &s)) || (rc = dxlt_arg_reg(t, &s, colon + 1, &regs[n])))
			return rc;
		items[n] = (struct dxl_item){ .id = ids[n], .addr = regs[n].addr, .len = regs[n].size };
	}
	int r = t->a.fast ? bus_fast_bulk_read(&t->bus, items, n, &m) : bus_bulk_read(&t->bus, items, n, &m);
	return dxlt_multi_report(t, &m, r, regs, true, "bulk-read",
	                         t->a.fast ? "Fast Bulk Read" : "BULK_READ", ids);
}

static void dxlt_dump_raw(struct dxlt *t, const uint8_t *mem, size_t len)
{
	fprintf(t->out, "ADDR  BYTES (model not in dxl's tables: raw, little-endian)\n");
	for (size_t a = 0; a < len; a += 16) {
		fprintf(t->out, "%-5zu", a);
		for (size_t k = a; k < a + 16 && k < len; k++)
			fprintf(t->out, " %02X", mem[k]);
		fputc('\n', t->out);
	}
}

/* The title line: the model and firmware as the image holds them. */
static void dxlt_dump_title(struct dxlt *t, const struct dxl2_model *m, const uint8_t *mem, size_t len)
{
	const struct dxl2_reg *model = dxl2_reg_lookup(m, "model_number");
	const struct dxl2_reg *firmware = dxl2_reg_lookup(m, "firmware_version");

	if (model == NULL || firmware == NULL || firmware->addr >= len)
		return;
	fprintf(t->out, "%s (model %ld), firmware %ld\n", m->name, (long)dxl2_reg_decode(model, &mem[model->addr]),
	        (long)dxl2_reg_decode(firmware, &mem[firmware->addr]));
}

int dxlt_cmd_dump(struct dxlt *t)
{
	struct dxlt_servo s;
	uint8_t id, mem[DXLT_IMAGE_MAX];
	char text[96];
	int rc;

	if ((rc = dxlt_need_form(t, 1, "dump ID")) || (rc = dxlt_arg_servo_id(t, t->a.pos[0], &id)) ||
	    (rc = dxlt_identify(t, id, &s)))
		return rc;
	size_t len = dxlt_image_len(s.m);
	int r = dxlt_read(t, id, 0, (uint16_t)len, mem);
	if (r != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (s.m == NULL) {
		fprintf(t->err, "dxl: ID %u is model %u, not in dxl's tables (%s): bytes 0-%zu "
		        "raw\n", id, s.model, dxlt_known(t), len - 1);
		dxlt_dump_raw(t, mem, len);
		return DXLT_EXIT_OK;
	}
	dxlt_dump_title(t, s.m, mem, len);
	fprintf(t->out, "%-4s %-24s %-26s %s\n", "ADDR", "NAME", "VALUE", "DESCRIPTION");
	for (size_t i = 0; i < s.m->nregs; i++) {
		const struct dxl2_reg *reg = &s.m->regs[i];
		if (reg->addr + reg->size > len)
			continue;
		fprintf(t->out, "%-4u %-24s %-26s %s%s\n", reg->addr, reg->name,
		        dxl2_reg_format(reg, dxl2_reg_decode(reg, &mem[reg->addr]), text, sizeof text), reg->desc,
		        reg->area == DXL_AREA_EEPROM ? " [EEPROM]" : "");
	}
	return DXLT_EXIT_OK;
}

/* ---- write / torque ------------------------------------------------------------------ */

/* The servo a write goes to: the broadcast ID too where the family's
 * models share one table (its PING does not pick one), as no reply says
 * which table a servo has. */
static int dxlt_arg_write_id(struct dxlt *t, const char *text, uint8_t *id)
{
	if (t->fam->ping_names_model)
		return dxlt_arg_servo_id(t, text, id);
	return dxlt_arg_id(t, text, true, id);
}

static int dxlt_parse_value(struct dxlt *t, const struct dxlt_reg *reg, const char *text, long *value)
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
 * wheel or joint, torque for EEPROM where the family refuses it. The servo
 * would answer an error; say why first. */
static int dxlt_check_live(struct dxlt *t, const struct dxlt_servo *s, const struct dxlt_reg *reg, long value,
                           const uint8_t *mem, size_t len)
{
	int32_t lo, hi;

	if (dxl2_reg_check_write(s->m, reg->row, value) != DXL_OK) {
		fprintf(t->err, "dxl: the %s has no %s %ld (operating modes: dxl %sdump %u)\n", s->m->name, reg->name,
		        value, t->fam->opt, s->id);
		return DXLT_EXIT_USAGE;
	}
	if (dxl2_reg_check_write_live(s->m, reg->row, value, mem, len) != DXL_OK &&
	    dxl2_reg_range(s->m, reg->row, mem, len, &lo, &hi) == DXL_OK) {
		fprintf(t->err, "dxl: value %ld outside %s's range on ID %u now (%ld..%ld, from its limit registers; "
		        "the servo would answer a data limit error)\n", value, reg->name, s->id, (long)lo, (long)hi);
		return DXLT_EXIT_USAGE;
	}
	if (t->fam->eeprom_needs_torque_off && reg->row->area == DXL_AREA_EEPROM &&
	    mem[dxlt_addr(t, "torque_enable")] != 0) {
		fprintf(t->err, "dxl: ID %u has torque on, and an X-series servo refuses EEPROM writes (%s) then with "
		        "an access error: dxl %s--port %s torque %u off\n", s->id, reg->name, t->fam->opt,
		        port_path(t->port), s->id);
		return DXLT_EXIT_REFUSED;
	}
	return DXLT_EXIT_OK;
}

/* What a refused write's error field says, per protocol (the field names the
 * symptom, not the remedy): (err & mask) == value, for a write to EEPROM or
 * to the goal position. 2.0's field is an error number, 1.0's a set of bits;
 * `dxl` refuses most of the 2.0 cases before sending (the family's
 * eeprom_needs_torque_off, dxl2_reg_check_write_live), the servo has the
 * last word. */
static const struct dxlt_refusal {
	const struct dxl_proto *proto;
	uint8_t mask, value;
	bool eeprom;                  /* else the goal position */
} dxlt_refusals[] = {
	{ &dxl_proto_v1, DXL_ERRBIT_RANGE, DXL_ERRBIT_RANGE, true },
	{ &dxl_proto_v1, DXL_ERRBIT_ANGLE_LIMIT, DXL_ERRBIT_ANGLE_LIMIT, false },
	{ &dxl_proto_v2, (uint8_t)~DXL2_ERR_ALERT, DXL2_ERRNUM_ACCESS, true },
	{ &dxl_proto_v2, (uint8_t)~DXL2_ERR_ALERT, DXL2_ERRNUM_DATA_LIMIT, false },
};

/* The registers that bound a goal position: the model's pair. */
static const char *const *dxlt_limit_rows(const struct dxl2_model *m)
{
	static const char *const pairs[][2] = {
		{ "cw_angle_limit", "ccw_angle_limit" }, { "min_position_limit", "max_position_limit" },
	};
	for (size_t i = 0; i < sizeof pairs / sizeof pairs[0]; i++)
		if (dxl2_reg_lookup(m, pairs[i][0]) != NULL)
			return pairs[i];
	return NULL;
}

static void dxlt_write_hint(struct dxlt *t, const struct dxlt_servo *s, const struct dxlt_reg *reg)
{
	uint8_t e = dxlt_errors(t, s->id);
	const struct dxl_proto *p = bus_proto(&t->bus);

	if (reg->row == NULL || s->m == NULL)
		return;
	for (size_t i = 0; i < sizeof dxlt_refusals / sizeof dxlt_refusals[0]; i++) {
		const struct dxlt_refusal *r = &dxlt_refusals[i];
		if (r->proto != p || (e & r->mask) != r->value)
			continue;
		const char *const *lim = dxlt_limit_rows(s->m);
		if (r->eeprom && reg->row->area == DXL_AREA_EEPROM)
			snprintf(t->hint, sizeof t->hint, "the %s refuses EEPROM writes (%s) while torque is on or the lock "
			         "is set: dxl %s--port %s torque %u off", s->m->name, reg->name, t->fam->opt,
			         port_path(t->port), s->id);
		else if (!r->eeprom && strcmp(reg->name, "goal_position") == 0 && lim != NULL)
			snprintf(t->hint, sizeof t->hint, "the goal is outside the servo's %s limits: dxl %s--port %s read %u "
			         "%s (and %s)", sm_family(t->fam->protocol)->limits_name, t->fam->opt, port_path(t->port), s->id,
			         lim[0], lim[1]);
	}
}

static bool dxlt_is_level_reg(const struct dxlt_reg *reg)
{
	return reg->row != NULL && strcmp(reg->name, "status_return_level") == 0;
}

/* Write one register and know whether it took, as far as the servo's status
 * return level lets us: level 2 answers the WRITE; level 1 answers only a
 * READ; at both, the value is read back and what the servo holds is what
 * the output says ("ID 1: goal_position = 512 (read back)"), so a write that
 * printed nothing is never mistaken for one that took. Level 0 answers
 * nothing but PING, so the write goes out unconfirmed and the output says
 * so. A write to the status return level itself is never waited for: which
 * level answers it is the servo's choice. */
static int dxlt_write_checked(struct dxlt *t, const struct dxlt_servo *s, const struct dxlt_reg *reg, long value,
                              uint8_t level)
{
	uint8_t raw[4], back[4];
	uint8_t id = s->id;
	bool answered = id != DXL_BROADCAST_ID && level >= 2 && !dxlt_is_level_reg(reg);

	/* multi-byte values go in one packet: the servo must never act on half */
	if (reg->row != NULL)
		dxl2_reg_encode(reg->row, (int32_t)value, raw);
	else
		dxl2_put_u32(raw, (uint32_t)value);
	int r = dxlt_write(t, id, reg->addr, raw, reg->size, answered);
	if (r != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (id == DXL_BROADCAST_ID) {
		fprintf(t->out, "broadcast: %s = %ld sent (servos do not answer a broadcast)\n", reg->name, value);
		return DXLT_EXIT_OK;
	}
	dxlt_write_hint(t, s, reg);
	uint8_t now_level = dxlt_is_level_reg(reg) ? (uint8_t)value : level;
	if (now_level == 0) {
		if ((r = dxlt_ping(t, id)) != DXL_OK)
			return dxlt_bus_fail(t, id, r);
		fprintf(t->out, "ID %u: %s = %ld sent, not confirmed: the servo answers PING only (status return level "
		        "0)\n", id, reg->name, value);
		return DXLT_EXIT_OK;
	}
	/* A READ right after a WRITE to EEPROM may find the servo busy writing. */
	if (reg->row != NULL && reg->row->area == DXL_AREA_EEPROM)
		dxlt_sleep_us(t->fam->settle_us);
	if ((r = dxlt_read(t, id, reg->addr, reg->size, back)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (memcmp(back, raw, reg->size) != 0) {
		if (answered)
			fprintf(t->err, "dxl: ID %u holds %s = %ld, not the %ld written\n", id, reg->name,
			        (long)dxlt_decode(reg, back), value);
		else
			fprintf(t->err, "dxl: ID %u kept %s at %ld (wrote %ld; status return level %u: the WRITE itself is "
			        "not answered, its read-back is)\n", id, reg->name, (long)dxlt_decode(reg, back), value, level);
		return dxlt_errors(t, id) != 0 ? DXLT_EXIT_SERVO : DXLT_EXIT_BUS;
	}
	/* what the servo holds, in the register's own signedness */
	long held = (long)dxlt_decode(reg, back);
	if (reg->row == NULL || !reg->row->is_signed)
		held = (long)(uint32_t)dxlt_decode(reg, back);
	if (answered)
		fprintf(t->out, "ID %u: %s = %ld (read back)\n", id, reg->name, held);
	else
		fprintf(t->out, "ID %u: %s = %ld (read back: status return level %u does not answer WRITE)\n", id,
		        reg->name, held, level);
	return DXLT_EXIT_OK;
}

/* The whole write: checked against the table and the servo's image first. */
static int dxlt_write_reg(struct dxlt *t, const struct dxlt_servo *s, const struct dxlt_reg *reg, long value)
{
	uint8_t mem[DXLT_IMAGE_MAX];
	size_t len = dxlt_image_len(s->m);
	int rc, r;

	/* a model we do not know: its level unknown too, a reply expected;
	 * a broadcast: nobody answers */
	if (reg->row == NULL || s->id == DXL_BROADCAST_ID)
		return dxlt_write_checked(t, s, reg, value, 2);
	if ((r = dxlt_read(t, s->id, 0, (uint16_t)len, mem)) == DXL_E_TIMEOUT) {
		/* level 0 (PING only), or nobody there */
		if (!s->pinged && (r = dxlt_ping(t, s->id)) != DXL_OK)
			return dxlt_bus_fail(t, s->id, r);
		fprintf(t->err, "dxl: ID %u answers PING but not READ (status return level 0): %s not checked against "
		        "its limits\n", s->id, reg->name);
		return dxlt_write_checked(t, s, reg, value, 0);
	}
	if (r != DXL_OK)
		return dxlt_bus_fail(t, s->id, r);
	if ((rc = dxlt_check_live(t, s, reg, value, mem, len)) != DXLT_EXIT_OK)
		return rc;
	uint8_t level = mem[dxlt_addr(t, "status_return_level")];
	return dxlt_write_checked(t, s, reg, value, level > 2 ? 2 : level);
}

int dxlt_cmd_write(struct dxlt *t)
{
	struct dxlt_servo s;
	struct dxlt_reg reg;
	uint8_t id;
	long value;
	int rc;

	if ((rc = dxlt_need_form(t, 3, "write ID REG VALUE")) || (rc = dxlt_arg_write_id(t, t->a.pos[0], &id)) ||
	    (rc = dxlt_identify(t, id, &s)) || (rc = dxlt_arg_reg(t, &s, t->a.pos[1], &reg)) ||
	    (rc = dxlt_parse_value(t, &reg, t->a.pos[2], &value)))
		return rc;
	/* After a new ID or baud the servo answers elsewhere: only the commands
	 * made for it know where to look for the answer. */
	bool is_id = reg.row != NULL && strcmp(reg.name, "id") == 0;
	if (is_id || (reg.row != NULL && strcmp(reg.name, "baud_rate") == 0)) {
		fprintf(t->err, "dxl: %s moves the servo away from this ID/rate: use dxl %s--port %s %s\n", reg.name,
		        t->fam->opt, port_path(t->port), is_id ? "set-id OLD NEW" : "set-baud ID BAUD");
		return DXLT_EXIT_USAGE;
	}
	return dxlt_write_reg(t, &s, &reg, value);
}

int dxlt_cmd_torque(struct dxlt *t)
{
	struct dxlt_servo s;
	struct dxlt_reg reg = { NULL, dxlt_addr(t, "torque_enable"), 1, "torque_enable" };
	uint8_t id;
	int rc;

	if ((rc = dxlt_need_form(t, 2, "torque ID on|off")) || (rc = dxlt_arg_write_id(t, t->a.pos[0], &id)))
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
		reg.row = dxl2_reg_lookup(s.m, "torque_enable");
	else
		dxlt_raw_note(t, &s, reg.addr, reg.size);
	return dxlt_write_reg(t, &s, &reg, on ? 1 : 0);
}

/* ---- setup ------------------------------------------------------------------------------ */

/* The rate `setup` puts a slower bus at: at the X series' factory 57600 bps
 * one cycle of two servos takes more than the 10 ms period on the wire alone. */
#define DXLT_SETUP_BAUD 1000000L

/* Write one EEPROM byte if it differs from what the image holds, then read
 * it back. A write to the status return level is never waited for. */
static int dxlt_setup_byte(struct dxlt *t, const struct dxlt_servo *s, const char *name, uint8_t want,
                           const uint8_t *mem, uint8_t level)
{
	const struct dxl2_reg *reg = dxl2_reg_lookup(s->m, name);
	uint8_t id = s->id, have = mem[reg->addr], before = dxlt_errors(t, id);
	int r;

	if (have == want) {
		fprintf(t->out, "ID %u: %s already %u\n", id, name, want);
		return DXLT_EXIT_OK;
	}
	if ((r = dxlt_write(t, id, reg->addr, &want, 1, level >= 2 && strcmp(name, "status_return_level") != 0)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if ((dxlt_errors(t, id)) & ~before)
		return DXLT_EXIT_SERVO;   /* refused: reported with the others at the end */
	dxlt_sleep_us(t->fam->settle_us);
	if ((r = dxlt_read(t, id, reg->addr, 1, &have)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (have != want) {
		fprintf(t->err, "dxl: ID %u kept %s at %u (wrote %u)%s\n", id, name, have, want,
		        dxl2_reg_lookup(s->m, "lock") != NULL ? ": EEPROM locked? (lock register; power-cycle)" : "");
		return dxlt_errors(t, id) ? DXLT_EXIT_SERVO : DXLT_EXIT_BUS;
	}
	fprintf(t->out, "ID %u: %s set to %u\n", id, name, want);
	return DXLT_EXIT_OK;
}

/* *loop: the model whose cycle reads the most bytes, for setup's budget line. */
static int dxlt_setup_one(struct dxlt *t, uint8_t id, const struct sm_model **loop)
{
	uint8_t mem[DXLT_IMAGE_MAX];
	struct dxlt_servo s;
	int rc, r;

	if ((rc = dxlt_identify(t, id, &s)) != DXLT_EXIT_OK)
		return rc;
	if (!s.pinged && (r = dxlt_ping(t, id)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (s.m == NULL) {
		fprintf(t->err, "dxl: ID %u is model %u, not in dxl's tables (%s): setup does not "
		        "know its registers\n", id, s.model, dxlt_known(t));
		return DXLT_EXIT_REFUSED;
	}
	const struct sm_model *sm = sm_by_number(t->fam->protocol, s.m->number);
	if (sm != NULL && (*loop == NULL || sm->present_len > (*loop)->present_len))
		*loop = sm;
	/* The loop READs every cycle, so level 0 (PING only) cannot work. */
	if ((r = dxlt_read(t, id, 0, (uint16_t)dxlt_image_len(s.m), mem)) != DXL_OK) {
		fprintf(t->err, "dxl: ID %u answers PING but not READ: status return level 0? (the loop's reads need 1 "
		        "or 2; dxl %swrite %u status_return_level 2 cannot be verified either)\n", id, t->fam->opt, id);
		return r == DXL_E_TIMEOUT ? DXLT_EXIT_BUS : dxlt_bus_fail(t, id, r);
	}
	uint8_t level = mem[dxlt_addr(t, "status_return_level")];
	/* A servo refuses EEPROM writes while its torque is on, and a robot just
	 * stopped by the daemon holds its pose. Turning torque off lets the
	 * joint fall, so it is done only when asked (--yes). */
	if (mem[dxlt_addr(t, "torque_enable")]) {
		if (!t->a.yes) {
			fprintf(t->err, "dxl: ID %u has torque on, and the %s refuses EEPROM writes then; add --yes to turn it "
			        "off first (the joint goes limp: support the robot), or dxl %s--port %s torque %u off\n", id,
			        s.m->name, t->fam->opt, port_path(t->port), id);
			return DXLT_EXIT_REFUSED;
		}
		if ((rc = dxlt_setup_byte(t, &s, "torque_enable", 0, mem, level)) != DXLT_EXIT_OK)
			return rc;
	}
	/* 0: the reply follows the request at once instead of after 500 µs */
	if ((rc = dxlt_setup_byte(t, &s, "return_delay_time", 0, mem, level)) != DXLT_EXIT_OK)
		return rc;
	/* level 2 costs nothing per cycle (goals go unanswered) and lets
	 * start-up and tools verify their writes */
	uint8_t want_level = (uint8_t)(t->a.status_level >= 0 ? t->a.status_level : 2);
	return dxlt_setup_byte(t, &s, "status_return_level", want_level, mem, level);
}

/* A bus slower than 1 Mbps cannot carry a 100 Hz cycle (57600 bps, the X
 * series' factory rate, needs 16 ms for two servos' SYNC_READ and
 * SYNC_WRITE): every servo goes to 1 Mbps, then the port, then each must
 * answer there. */
static int dxlt_setup_baud(struct dxlt *t, const uint8_t *ids, int n)
{
	uint8_t reg;
	int r, rc;

	if (port_baud(t->port) >= DXLT_SETUP_BAUD || t->fam->baud_to_reg(DXLT_SETUP_BAUD, &reg) != DXL_OK)
		return DXLT_EXIT_OK;
	for (int i = 0; i < n; i++)
		if ((r = dxlt_write(t, ids[i], dxlt_addr(t, "baud_rate"), &reg, 1, false)) != DXL_OK)
			return dxlt_bus_fail(t, ids[i], r);
	long before = port_baud(t->port);
	dxlt_sleep_us(t->fam->settle_us);
	if ((rc = dxlt_set_baud(t, DXLT_SETUP_BAUD)) != DXLT_EXIT_OK)
		return rc;
	for (int i = 0; i < n; i++) {
		if ((r = dxlt_verify_ping(t, ids[i])) != DXL_OK) {
			fprintf(t->err, "dxl: ID %u does not answer at %ld bps after the change (%s); try: dxl %s--port %s scan "
			        "--bauds all\n", ids[i], DXLT_SETUP_BAUD, dxl_strerror(r), t->fam->opt, port_path(t->port));
			return r == DXL_E_DISCONNECTED ? DXLT_EXIT_PORT : DXLT_EXIT_BUS;
		}
		fprintf(t->out, "ID %u: baud_rate %ld -> %ld bps (a 100 Hz cycle does not fit the period below 1 Mbps; "
		        "undulated's configuration needs baud = %ld)\n", ids[i], before, DXLT_SETUP_BAUD, DXLT_SETUP_BAUD);
	}
	return DXLT_EXIT_OK;
}

/* setup's last line: the bus time of one 100 Hz cycle of undulated's for n
 * servos (doctor.h's dr_cycle_wire_us: the model's present block read, one
 * READ a servo or one SYNC_READ as the protocol can, and one SYNC_WRITE of
 * goals), plus the adapter's hold time for each read. */
static void dxlt_setup_budget(struct dxlt *t, unsigned n, const struct sm_model *m, int latency_ms)
{
	const struct dxl_proto *p = bus_proto(&t->bus);
	bool sync = dxl_proto_can(p, DXL_CAP_SYNC_READ);
	double wire_ms = 1e-3 * dr_cycle_wire_us(p, n, m->present_len, m->goal_size, port_baud(t->port));
	double total_ms = wire_ms + (sync ? 1.0 : (double)n) * latency_ms;

	fprintf(t->out, "bus time per cycle for %u servo%s at %ld bps: %.2f ms on the wire (%s of %u bytes each, one "
	        "SYNC_WRITE) + %d ms adapter latency %s = %.2f ms of the 10 ms period%s\n", n, n == 1 ? "" : "s",
	        port_baud(t->port), wire_ms, sync ? "one SYNC_READ" : "a READ", m->present_len, latency_ms,
	        sync ? "for it" : "per read", total_ms, total_ms > 5.0 ? " (too much for 100 Hz)" : "");
}

int dxlt_cmd_setup(struct dxlt *t)
{
	uint8_t ids[DXLT_MAX_IDS];
	int worst = DXLT_EXIT_OK, n = t->a.npos;
	const struct sm_model *loop = NULL;   /* the servo whose cycle reads the most */

	if (n < 1 || n > t->fam->max_id + 1)
		return dxlt_need_form(t, -1, "setup ID... [--status-level N] [--yes]");
	for (int i = 0; i < n; i++) {
		int rc = dxlt_arg_servo_id(t, t->a.pos[i], &ids[i]);
		if (rc != DXLT_EXIT_OK)
			return rc;
	}
	for (int i = 0; i < n; i++) {
		int rc = dxlt_setup_one(t, ids[i], &loop);
		if (rc == DXLT_EXIT_PORT)
			return rc;
		worst = rc > worst ? rc : worst;
	}
	if (worst == DXLT_EXIT_OK && (worst = dxlt_setup_baud(t, ids, n)) == DXLT_EXIT_PORT)
		return worst;
	/* The adapter: lower the FTDI latency timer now that the servos are done. */
	port_latency_check_fd(port_path(t->port), port_fd(t->port), true, &t->latency);
	fprintf(t->out, "adapter: %s\n", t->latency.note);
	dxlt_setup_budget(t, (unsigned)n, loop != NULL ? loop : sm_family(t->fam->protocol),
	                  t->latency.known ? t->latency.timer_ms : 0);
	if (t->latency.known && t->latency.timer_ms > 1) {
		fprintf(t->err, "dxl: %s\n", t->latency.note);
		if (worst == DXLT_EXIT_OK)
			worst = DXLT_EXIT_PORT;
	}
	return worst;
}
