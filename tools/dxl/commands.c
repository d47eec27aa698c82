/*
 * commands.c — the `dxl` commands over one bus.
 *
 * Output contract: results go to `out` (a read prints the value alone so
 * scripts can use it), every failure is one line on `err` naming what to do
 * next, and the exit code tells the kind (dxlt.h). Nothing is written to a
 * servo before its arguments were checked against the control table.
 */
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "dxl2_table.h"
#include "dxl_table.h"
#include "daemon/servo_model.h"
#include "doctor.h"
#include "dxlt_priv.h"
#include "num.h"

/* ---- transactions: every reply's error bits are remembered ------------------- */

static const struct dxlt_family *dxlt_family_for(int protocol, const struct dxl2_model **model);

/* One line per servo whose replies carried error bits (1.0) or a non-zero
 * ERR field (2.0); exit 5 unless the command already failed in a way that
 * says more (a lost bus, bad usage). */
static int dxlt_report_errbits(struct dxlt *t, int rc)
{
	char names[128];
	bool any = false;

	for (size_t i = 0; i < DXLT_PROTOCOLS; i++) {
		const struct dxl_proto *p = dxl_proto_by_number((int)i + 1);
		const struct dxl2_model *unused;
		const struct dxlt_family *f = dxlt_family_for((int)i + 1, &unused);
		for (size_t id = 0; id < sizeof t->errseen[i]; id++) {
			uint8_t e = t->errseen[i][id];
			if (e == 0)
				continue;
			fprintf(t->err, "dxl: ID %zu reports %s 0x%02X: %s", id, f->err_field, e,
			        p->err_format(e, names, sizeof names));
			if ((e & p->err_alert) && f->alert_fix != NULL) {
				fputs(" (", t->err);
				fprintf(t->err, f->alert_fix, f->opt, f->opt);
				fputc(')', t->err);
			}
			fputc('\n', t->err);
			any = true;
		}
	}
	if (!any)
		return rc;
	if (t->hint[0] != '\0')
		fprintf(t->err, "dxl: %s\n", t->hint);
	return rc == DXLT_EXIT_OK ? DXLT_EXIT_SERVO : rc;
}

/* ---- ports -------------------------------------------------------------------- */

/* Enumeration beyond this many ports is truncated (a robot has one or two). */
#define DXLT_MAX_PORTS 64

static int dxlt_cmd_ports(struct dxlt *t)
{
	static struct port_info info[DXLT_MAX_PORTS];
	int n = port_list(info, DXLT_MAX_PORTS);

	if (n < 0) {
		fprintf(t->err, "dxl: cannot list serial ports: %s\n", dxl_strerror(n));
		return DXLT_EXIT_PORT;
	}
	if (n == 0)
		fprintf(t->err, "dxl: no serial ports found\n");
	for (int i = 0; i < n && i < DXLT_MAX_PORTS; i++) {
		const struct port_info *p = &info[i];
		fprintf(t->out, "%s", p->path);
		if (p->usb_vid >= 0)
			fprintf(t->out, "  %04x:%04x", p->usb_vid, p->usb_pid);
		if (p->serial[0] != '\0')
			fprintf(t->out, "  serial %s", p->serial);
		if (p->description[0] != '\0')
			fprintf(t->out, "  \"%s\"", p->description);
		if (p->adapter != NULL)
			fprintf(t->out, "  [Dynamixel adapter: %s]", p->adapter);
		fputc('\n', t->out);
	}
	return DXLT_EXIT_OK;
}

/* ---- scan / ping -------------------------------------------------------------- */

static void dxlt_print_identity(struct dxlt *t, uint8_t id, long baud)
{
	uint8_t raw[2], fw = 0;
	bool have_model = dxlt_read(t, id, DXL_AX_MODEL_NUMBER, 2, raw) == DXL_OK;
	bool have_fw = dxlt_read(t, id, DXL_AX_FIRMWARE_VERSION, 1, &fw) == DXL_OK;
	uint16_t model = have_model ? dxl_get_u16(raw) : 0;

	/* Status return level 0 answers PING only: the ID is real, the rest unknown. */
	fprintf(t->out, "%-4u ", id);
	if (have_model)
		fprintf(t->out, "%-6u %-13s ", model, dxlt_model_name(1, model));
	else
		fprintf(t->out, "%-6s %-13s ", "?", "?");
	if (have_fw)
		fprintf(t->out, "%-9u ", fw);
	else
		fprintf(t->out, "%-9s ", "?");
	fprintf(t->out, "%-8ld 1.0\n", baud);
}

/* Protocol 1.0 at one rate: a unicast PING to every ID (a broadcast PING
 * makes every AX-12 answer at once). */
static int dxlt_scan1_at(struct dxlt *t, long baud, unsigned *found)
{
	for (unsigned id = t->a.id_lo; id <= t->a.id_hi; id++) {
		int r = dxlt_ping(t, (uint8_t)id);
		if (r == DXL_E_DISCONNECTED || r == DXL_E_IO)
			return dxlt_bus_fail(t, (uint8_t)id, r);
		if (r != DXL_OK)
			continue;
		(*found)++;
		dxlt_print_identity(t, (uint8_t)id, baud);
	}
	return DXLT_EXIT_OK;
}

/* The rates one protocol is scanned at: `--bauds all` gives each its own
 * list; a list given keeps the rates that protocol's servos can run at
 * (within 3 %); without one, --baud. */
static size_t dxlt_scan_bauds(const struct dxlt *t, const struct dxlt_family *f, long *out, size_t cap)
{
	size_t n = 0;
	uint8_t reg;

	if (t->a.bauds_all)
		return dxlt_bauds_for(f->protocol, out, cap);
	if (t->a.nbauds == 0) {
		out[0] = t->a.baud;
		return 1;
	}
	for (size_t i = 0; i < t->a.nbauds && n < cap; i++) {
		long b = t->a.bauds[i];
		if (f->baud_to_reg(b, &reg) == DXL_OK)
			out[n++] = b;
	}
	return n;
}

/* The two families `dxl` speaks to, in scan order. */
static const struct dxlt_family dxlt_families[] = {
	{ .protocol = 1, .bus = BUS_PROTOCOL_1, .label = "Protocol 1.0", .opt = "", .max_id = DXL_MAX_ID,
	  .settle_us = DXLT_EEPROM_SETTLE_US, .eeprom_needs_torque_off = false, .err_field = "error bits",
	  .no_rate = "dxl: an AX-12 cannot run at '%s' bps (rates are 2000000/(n+1), e.g. 1000000, 500000, 117647, "
	             "57143)\n",
	  .reset_form = "reset ID --yes",
	  .reset_refusal = "dxl: a factory reset sets ID 1, 1000000 bps and every default (including angle limits); "
	                   "add --yes to do it\n",
	  .baud_to_reg = dxl_baud_to_reg, .baud_from_reg = dxl_baud_from_reg, .scan_at = dxlt_scan1_at },
	/* An X servo writes its EEPROM in a few ms; 20 ms before asking. */
	{ .protocol = 2, .bus = BUS_PROTOCOL_2, .label = "Protocol 2.0", .opt = "--protocol 2 ", .max_id = DXL2_MAX_ID,
	  .settle_us = 20000, .eeprom_needs_torque_off = true, .ping_names_model = true, .err_field = "error",
	  .alert_fix = "the alert bit: a hardware error; see dxl %sread ID hardware_error_status --units, and dxl %sreboot "
	               "ID to clear it",
	  .no_rate = "dxl: an X-series servo cannot run at '%s' bps (9600, 57600, 115200, 1000000, 2000000, 3000000, "
	             "4000000, 4500000)\n",
	  .reset_form = "reset ID --yes [--keep id|id-baud]",
	  .reset_refusal = "dxl: a factory reset sets %s (position limits and operating mode included); add --yes "
	                   "to do it (--keep id or id-baud keeps those)\n",
	  .baud_to_reg = dxl2_baud_to_reg, .baud_from_reg = dxl2_baud_from_reg, .scan_at = dxlt2_scan_at },
};
#define DXLT_NFAMILIES (sizeof dxlt_families / sizeof dxlt_families[0])

/* --protocol's family (0, not given: Protocol 1.0's), its first model
 * descriptor found once. */
static const struct dxlt_family *dxlt_family_for(int protocol, const struct dxl2_model **model)
{
	const struct dxlt_family *f = &dxlt_families[0];
	for (size_t i = 0; i < DXLT_NFAMILIES; i++)
		if (dxlt_families[i].protocol == protocol)
			f = &dxlt_families[i];
	*model = dxl2_model_first(f->protocol);
	return f;
}

static int dxlt_cmd_scan(struct dxlt *t)
{
	unsigned found = 0;
	size_t tried = 0;
	int rc;

	if (t->a.npos != 0)
		return dxlt_need_args(t, 0, "scan [--ids A-B] [--bauds LIST|all]");
	/* absent IDs are most of a scan: each keeps the derived deadline, not a
	 * one-shot command's DXLT_ONESHOT_WAIT_MS */
	t->scanning = true;
	dxlt_apply_timing(t);
	fprintf(t->out, "%-4s %-6s %-13s %-9s %-8s %s\n", "ID", "MODEL", "NAME", "FIRMWARE", "BAUD", "PROTOCOL");
	for (size_t i = 0; i < DXLT_NFAMILIES; i++) {
		const struct dxlt_family *f = &dxlt_families[i];
		long bauds[DXLT_MAX_BAUDS];
		if (t->a.protocol != 0 && t->a.protocol != f->protocol)
			continue;
		size_t nbauds = dxlt_scan_bauds(t, f, bauds, DXLT_MAX_BAUDS);
		bus_set_protocol(&t->bus, f->bus);
		for (size_t b = 0; b < nbauds; b++, tried++) {
			if ((rc = dxlt_set_baud(t, bauds[b])) != DXLT_EXIT_OK)
				return rc;
			rc = f->scan_at(t, bauds[b], &found);
			if (rc != DXLT_EXIT_OK)
				return rc;
			fflush(t->out);
		}
	}
	if (found == 0) {
		fprintf(t->err, "dxl: no servo answered on %s (IDs %u-%u, %zu baud rate%s on %s)%s\n",
		        port_path(t->port), t->a.id_lo, t->a.id_hi, tried, tried == 1 ? "" : "s",
		        t->a.protocol != 0 ? t->fam->label : "Protocols 1.0 and 2.0",
		        t->a.nbauds == 0 ? "; try --bauds all" : "");
		return DXLT_EXIT_BUS;
	}
	return DXLT_EXIT_OK;
}

/* ---- read / write / dump ------------------------------------------------------ */

/* ---- set-id / set-baud / torque / reset --------------------------------------- */

/* EEPROM (ID, rate) is refused while torque is on where the family says
 * so: say it before sending. */
static int dxlt_need_torque_off(struct dxlt *t, uint8_t id, const char *what)
{
	uint8_t torque = 0;
	int r;

	if (!t->fam->eeprom_needs_torque_off)
		return DXLT_EXIT_OK;
	if ((r = dxlt_read(t, id, dxlt_addr(t, "torque_enable"), 1, &torque)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (torque == 0)
		return DXLT_EXIT_OK;
	fprintf(t->err, "dxl: ID %u has torque on, and an X-series servo refuses EEPROM writes (%s) then: dxl "
	        "%s--port %s torque %u off\n", id, what, t->fam->opt, port_path(t->port), id);
	return DXLT_EXIT_REFUSED;
}

static int dxlt_cmd_set_id(struct dxlt *t)
{
	uint8_t old_id, new_id;
	int rc;

	if ((rc = dxlt_need_form(t, 2, "set-id OLD NEW")) ||
	    (rc = dxlt_arg_servo_id(t, t->a.pos[0], &old_id)) ||
	    (rc = dxlt_arg_servo_id(t, t->a.pos[1], &new_id)))
		return rc;
	if (old_id == new_id) {
		fprintf(t->out, "ID %u unchanged\n", old_id);
		return DXLT_EXIT_OK;
	}
	int r = dxlt_ping(t, old_id);
	if (r != DXL_OK)
		return dxlt_bus_fail(t, old_id, r);
	/* Two servos with one ID answer at once and garble each other. */
	if (dxlt_ping(t, new_id) == DXL_OK) {
		fprintf(t->err, "dxl: ID %u is already taken on this bus; pick another\n", new_id);
		return DXLT_EXIT_REFUSED;
	}
	if ((rc = dxlt_need_torque_off(t, old_id, "id")) != DXLT_EXIT_OK)
		return rc;
	r = dxlt_write(t, old_id, dxlt_addr(t, "id"), &new_id, 1, false);
	if (r != DXL_OK)
		return dxlt_bus_fail(t, old_id, r);
	r = dxlt_verify_ping(t, new_id);
	if (r != DXL_OK) {
		fprintf(t->err, "dxl: wrote ID %u to servo %u but ID %u does not answer (%s)\n", new_id,
		        old_id, new_id, dxl_strerror(r));
		return r == DXL_E_DISCONNECTED ? DXLT_EXIT_PORT : DXLT_EXIT_BUS;
	}
	fprintf(t->out, "ID %u is now ID %u\n", old_id, new_id);
	return DXLT_EXIT_OK;
}

static int dxlt_cmd_set_baud(struct dxlt *t)
{
	uint8_t id, reg_value;
	long bps;
	int rc;

	if ((rc = dxlt_need_form(t, 2, "set-baud ID BAUD")) ||
	    (rc = dxlt_arg_servo_id(t, t->a.pos[0], &id)))
		return rc;
	if (num_parse_long(t->a.pos[1], 1, DXLT_MAX_BAUD, &bps) != NUM_OK ||
	    t->fam->baud_to_reg(bps, &reg_value) != DXL_OK) {
		fprintf(t->err, t->fam->no_rate, t->a.pos[1]);
		return DXLT_EXIT_USAGE;
	}
	int r = dxlt_ping(t, id);
	if (r != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if ((rc = dxlt_need_torque_off(t, id, "baud_rate")) != DXLT_EXIT_OK)
		return rc;
	r = dxlt_write(t, id, dxlt_addr(t, "baud_rate"), &reg_value, 1, false);
	if (r != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	long exact = t->fam->baud_from_reg(reg_value);
	/* Let the servo take the old-rate packet before the line changes rate. */
	dxlt_sleep_us(t->fam->settle_us);
	if ((rc = dxlt_set_baud(t, exact)) != DXLT_EXIT_OK)
		return rc;
	r = dxlt_verify_ping(t, id);
	if (r != DXL_OK) {
		fprintf(t->err, "dxl: ID %u does not answer at %ld bps after the change (%s); try: dxl "
		        "--port %s scan --bauds all\n", id, exact, dxl_strerror(r), port_path(t->port));
		return r == DXL_E_DISCONNECTED ? DXLT_EXIT_PORT : DXLT_EXIT_BUS;
	}
	fprintf(t->out, "ID %u now at %ld bps (register value %u)\n", id, exact, reg_value);
	return DXLT_EXIT_OK;
}

/* What a factory reset keeps: --keep where the models can (their
 * descriptor's DXL2_CAP_FACTORY_RESET_KEEP), else everything goes. */
static uint8_t dxlt_reset_keep(const struct dxlt *t, const char **what)
{
	uint8_t keep = dxl2_model_can(t->fam_model, DXL2_CAP_FACTORY_RESET_KEEP) ? (uint8_t)t->a.keep : DXL_RESET_ALL;
	*what = keep == DXL2_RESET_KEEP_ID ? "every default but the ID (57600 bps)"
	        : keep == DXL2_RESET_KEEP_ID_BAUD ? "every default but the ID and the baud rate"
	        : "ID 1, 57600 bps and every default";
	return keep;
}

static int dxlt_cmd_reset(struct dxlt *t)
{
	uint8_t id, e = 0;
	const char *what;
	int rc, r;

	if ((rc = dxlt_need_form(t, 1, t->fam->reset_form)) || (rc = dxlt_arg_servo_id(t, t->a.pos[0], &id)))
		return rc;
	uint8_t keep = dxlt_reset_keep(t, &what);
	if (!t->a.yes) {
		fprintf(t->err, t->fam->reset_refusal, what);
		return DXLT_EXIT_USAGE;
	}
	if ((r = dxlt_ping(t, id)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if ((r = bus_factory_reset(&t->bus, id, keep, false, &e)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	/* where the servo went: its model's factory ID and rate, or what it kept */
	uint8_t now_id = keep == DXL_RESET_ALL ? 1 : id;
	long now_baud = keep == DXL2_RESET_KEEP_ID_BAUD ? port_baud(t->port) : t->fam_model->factory_baud;
	dxlt_sleep_us(t->fam->settle_us);
	if ((rc = dxlt_set_baud(t, now_baud)) != DXLT_EXIT_OK)
		return rc;
	if ((r = dxlt_verify_ping(t, now_id)) != DXL_OK) {
		fprintf(t->err, "dxl: reset sent to ID %u but ID %u does not answer at %ld bps (%s)\n", id, now_id, now_baud,
		        dxl_strerror(r));
		return r == DXL_E_DISCONNECTED ? DXLT_EXIT_PORT : DXLT_EXIT_BUS;
	}
	fprintf(t->out, "ID %u reset to factory defaults: now ID %u at %ld bps\n", id, now_id, now_baud);
	return DXLT_EXIT_OK;
}

/* ---- reboot ------------------------------------------------------------------- */

/* A REBOOT takes the servo off the bus while it starts again: the e-manual
 * gives no figure; PINGs are tried for this long. */
#define DXLT_REBOOT_WAIT_US 2000000L
#define DXLT_REBOOT_POLL_US 50000L

/* After a REBOOT: wait until the servo answers, and say whether it came
 * back with a hardware error (where it has the register). */
static int dxlt_reboot_wait(struct dxlt *t, uint8_t id)
{
	bool hwerr = dxl2_model_can(t->fam_model, DXL2_CAP_HWERR_STATUS);

	for (long waited = 0; waited < DXLT_REBOOT_WAIT_US; waited += DXLT_REBOOT_POLL_US) {
		dxlt_sleep_us(DXLT_REBOOT_POLL_US);
		uint8_t hw = 0;
		if (dxlt_ping(t, id) != DXL_OK)
			continue;
		if (hwerr && dxlt_read(t, id, dxlt_addr(t, "hardware_error_status"), 1, &hw) == DXL_OK && hw != 0) {
			char names[96];
			fprintf(t->err, "dxl: ID %u restarted with hardware error status %u (%s): the cause is still there\n",
			        id, hw, dxl2_hwerr_format(hw, names, sizeof names));
			return DXLT_EXIT_SERVO;
		}
		fprintf(t->out, "ID %u rebooted: answers again after %ld ms, torque off\n", id,
		        (waited + DXLT_REBOOT_POLL_US) / 1000);
		return DXLT_EXIT_OK;
	}
	fprintf(t->err, "dxl: ID %u does not answer %ld ms after REBOOT\n", id, DXLT_REBOOT_WAIT_US / 1000);
	return DXLT_EXIT_BUS;
}

/* REBOOT is a capability: the X series' (Protocol 2.0), not the AX-12's. */
static int dxlt_cmd_reboot(struct dxlt *t)
{
	uint8_t id, e = 0, level = 2;
	int rc, r;

	if (!dxl2_model_can(t->fam_model, DXL2_CAP_REBOOT)) {
		fprintf(t->err, "dxl: the AX-12 has no REBOOT (Protocol 1.0): power-cycle it; an X-series servo: "
		        "dxl --protocol 2 --port %s reboot ID\n", port_path(t->port));
		return DXLT_EXIT_USAGE;
	}
	if ((rc = dxlt_need_form(t, 1, "reboot ID")) || (rc = dxlt_arg_servo_id(t, t->a.pos[0], &id)))
		return rc;
	if ((r = dxlt_ping(t, id)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	if (dxlt_read(t, id, dxlt_addr(t, "status_return_level"), 1, &level) != DXL_OK)
		level = 0;
	/* the reply (level 2) comes before the servo restarts */
	if ((r = bus_reboot(&t->bus, id, level >= 2, &e)) != DXL_OK)
		return dxlt_bus_fail(t, id, r);
	dxlt_seen(t, id, e);
	return dxlt_reboot_wait(t, id);
}

/* ---- main --------------------------------------------------------------------- */

/* A command, and what runs it on each family (dxlt_families' order); one
 * function where it is written once. */
struct dxlt_command {
	const char *name;
	int (*run[DXLT_NFAMILIES])(struct dxlt *t);
};

static const struct dxlt_command dxlt_commands[] = {
	{ "scan", { dxlt_cmd_scan, dxlt_cmd_scan } },          { "ping", { dxlt_cmd_ping, dxlt_cmd_ping } },
	{ "read", { dxlt_cmd_read, dxlt_cmd_read } },         { "write", { dxlt_cmd_write, dxlt_cmd_write } },
	{ "dump", { dxlt_cmd_dump, dxlt_cmd_dump } },         { "set-id", { dxlt_cmd_set_id, dxlt_cmd_set_id } },
	{ "set-baud", { dxlt_cmd_set_baud, dxlt_cmd_set_baud } }, { "torque", { dxlt_cmd_torque, dxlt_cmd_torque } },
	{ "reset", { dxlt_cmd_reset, dxlt_cmd_reset } },      { "setup", { dxlt_cmd_setup, dxlt_cmd_setup } },
	{ "reboot", { dxlt_cmd_reboot, dxlt_cmd_reboot } },    { "sync-read", { dxlt_cmd_sync_read, dxlt_cmd_sync_read } },
	{ "bulk-read", { dxlt_cmd_bulk_read, dxlt_cmd_bulk_read } },
};

static int dxlt_dispatch(struct dxlt *t)
{
	if (t->a.help) {
		dxlt_help(t->out);
		return DXLT_EXIT_OK;
	}
	if (t->a.command == NULL) {
		fprintf(t->err, "dxl: no command given\n");
		dxlt_usage(t->err);
		return DXLT_EXIT_USAGE;
	}
	t->fam = dxlt_family_for(t->a.protocol, &t->fam_model);
	if (strcmp(t->a.command, "ports") == 0)
		return t->a.npos == 0 ? dxlt_cmd_ports(t) : dxlt_need_args(t, 0, "ports");
	if (strcmp(t->a.command, "doctor") == 0)
		return dxlt_cmd_doctor(t);
	for (size_t i = 0; i < sizeof dxlt_commands / sizeof dxlt_commands[0]; i++) {
		if (strcmp(t->a.command, dxlt_commands[i].name) != 0)
			continue;
		if (t->a.port_path == NULL) {
			fprintf(t->err, "dxl: %s needs --port PATH (see dxl ports)\n", t->a.command);
			return DXLT_EXIT_USAGE;
		}
		int rc = dxlt_open(t, t->a.port_path, false);
		if (rc != DXLT_EXIT_OK)
			return rc;
		return dxlt_report_errbits(t, dxlt_commands[i].run[t->fam - dxlt_families](t));
	}
	fprintf(t->err, "dxl: unknown command '%s'\n", t->a.command);
	dxlt_usage(t->err);
	return DXLT_EXIT_USAGE;
}

int dxlt_main(int argc, char **argv, FILE *out, FILE *err)
{
	struct dxlt *t = calloc(1, sizeof *t);
	int rc;

	if (t == NULL) {
		fprintf(err, "dxl: out of memory\n");
		return 1;
	}
	t->out = out;
	t->err = err;
	rc = dxlt_parse_args(argc, argv, &t->a, err);
	if (rc == DXLT_EXIT_OK)
		rc = dxlt_dispatch(t);
	fflush(out);
	port_close(t->port);
	free(t);
	return rc;
}
