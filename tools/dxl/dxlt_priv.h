/*
 * dxlt_priv.h — what the `dxl` commands share inside libdxl: the tool's
 * state over one bus and the helpers every command uses (session.c, which
 * commands.c, registers.c, commands2.c and doctor.c call down into). Not for the tests:
 * they go through dxlt_main() (dxlt.h).
 */
#ifndef UNDULATE_DXLT_PRIV_H
#define UNDULATE_DXLT_PRIV_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "dxl2_table.h"
#include "dxlt.h"

struct dxlt;
/* The protocols `dxl` speaks, numbered 1 .. DXLT_PROTOCOLS. */
#define DXLT_PROTOCOLS 2
/* What a command needs of the protocol it speaks beyond the bus's backend
 * table (bus.h) and the model descriptors (dxl2_table.h): chosen once at
 * start from --protocol (dxlt_family_for), then asked, never branched on. */
struct dxlt_family {
	int protocol;                  /* 1 or 2 */
	enum bus_protocol bus;
	const char *label;             /* "Protocol 1.0" */
	const char *opt;               /* what a suggested command carries: "" or "--protocol 2 " */
	uint8_t max_id;
	long settle_us;                /* after an EEPROM write whose reply is not waited for */
	/* the servo refuses EEPROM writes while its torque is on, with an error
	 * the tool can name before sending */
	bool eeprom_needs_torque_off;
	/* its PING answers the model number: commands identify the servo
	 * first and take that model's table (else the family's first model's) */
	bool ping_names_model;
	const char *err_field;         /* what its replies' error field is called: "error bits" | "error" */
	/* what to do about the protocol's alert bit (bus_proto's err_alert), "%s"
	 * twice the family's option; NULL where it has none */
	const char *alert_fix;
	const char *no_rate;           /* set-baud's refusal, "%s" the rate asked */
	const char *reset_form;        /* reset's usage */
	/* reset without --yes: what it would set ("%s": the keep form's words) */
	const char *reset_refusal;
	int (*baud_to_reg)(long bps, uint8_t *v);
	long (*baud_from_reg)(uint8_t v);
	/* one rate of `scan`: a line per servo found */
	int (*scan_at)(struct dxlt *t, long baud, unsigned *found);
};

struct dxlt {
	struct dxlt_args a;
	const struct dxlt_family *fam;   /* set before any command runs */
	const struct dxl2_model *fam_model;   /* its first model: the addresses its models share */
	FILE *out, *err;
	struct port *port;
	struct port_latency latency;
	struct bus bus;
	/* The error field any reply carried, per protocol and ID: the servo's
	 * news, reported once when the command ends (dxlt_report_errbits),
	 * whichever call saw them. A row per protocol (number - 1): scan speaks
	 * both, and a field means what its protocol says (1.0's error bits,
	 * 2.0's alert bit and error number; the protocol table's err_format
	 * names it). dxlt_errors: the bus's protocol's. */
	uint8_t errseen[DXLT_PROTOCOLS][DXL2_BROADCAST_ID + 1];
	char hint[200];          /* what to do about them, when we know */
	bool scanning;           /* scan: the fast per-ID deadline (dxlt_apply_timing) */
};

/* ---- session.c ---- */
/* Open path as the bus (t->a.baud, t->a.echo, t->a.rs485) with the derived
 * reply timeouts. low_latency: lower the FTDI latency timer as undulated
 * does at start (only setup and doctor touch the adapter). DXLT_EXIT_OK or
 * DXLT_EXIT_PORT with one line on t->err. */
int dxlt_open(struct dxlt *t, const char *path, bool low_latency);
/* Reply timeouts for the current baud from --timeout-ms / --latency-us or the
 * adapter's latency timer (dxlt.h: the defaults' reasons). */
void dxlt_apply_timing(struct dxlt *t);
/* One line for a failed transaction, and its exit code. */
int dxlt_bus_fail(struct dxlt *t, uint8_t id, int status);
/* Transactions whose replies' error fields are remembered in t->errseen. */
int dxlt_ping(struct dxlt *t, uint8_t id);
/* PING, and the model number where the protocol's PING carries one
 * (*model untouched where it does not). */
int dxlt_ping_model(struct dxlt *t, uint8_t id, uint16_t *model);
/* An error byte a reply carried outside these (a REBOOT's). */
void dxlt_seen(struct dxlt *t, uint8_t id, uint8_t e);
/* The error fields remembered of id's replies on the bus's protocol. */
uint8_t dxlt_errors(const struct dxlt *t, uint8_t id);
int dxlt_read(struct dxlt *t, uint8_t id, uint16_t addr, uint16_t len, uint8_t *out);
int dxlt_write(struct dxlt *t, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply);
/* The address of a register every model of the protocol has at one place
 * ("id", "baud_rate", "torque_enable", "status_return_level"). */
uint16_t dxlt_addr(const struct dxlt *t, const char *name);
/* An ID on the command line, within the protocol's range. */
int dxlt_arg_servo_id(struct dxlt *t, const char *s, uint8_t *id);
/* After a write whose reply was not waited for, give the servo time, then PING. */
int dxlt_verify_ping(struct dxlt *t, uint8_t id);
/* A model's name as a reply on that protocol numbers it: its descriptor's,
 * or "not in dxl's tables". */
const char *dxlt_model_name(int protocol, uint16_t model);
/* Switch the port (and the reply timeouts) to baud. */
int dxlt_set_baud(struct dxlt *t, long baud);
void dxlt_sleep_us(long us);
/* The command's positional count, or a usage line (form) and exit 2. */
int dxlt_need_args(struct dxlt *t, int n, const char *form);
/* dxlt_need_args with the family's option a suggestion must carry
 * ("--protocol 2 " + "set-id OLD NEW"). */
int dxlt_need_form(struct dxlt *t, int n, const char *form);
int dxlt_arg_id(struct dxlt *t, const char *s, bool allow_broadcast, uint8_t *id);

/* Protocol 2.0's PING, with the model and firmware it answers. */
int dxlt2_ping(struct dxlt *t, uint8_t id, uint16_t *model, uint8_t *firmware);

/* ---- registers.c: the commands that go by the control table ---- */
/* The longest image of a control table read in one READ (`dump`, `write`'s
 * checks, `setup`): the X series' 0..147, model number .. present temperature.
 * The indirect areas past it (168-661) are read and written by name, one
 * register at a time, never dumped: 514 more bytes a READ for rows that
 * only repeat other registers. */
#define DXLT_IMAGE_MAX DXL2_X_PRESENT_END

/* A servo a command addresses, and the model whose table it goes by. */
struct dxlt_servo {
	uint8_t id;
	uint16_t model;
	uint8_t firmware;
	bool pinged;                  /* identified by PING (the family's PING names the model) */
	const struct dxl2_model *m;   /* NULL: not in our tables, raw addresses only */
};

/* A register named on the command line: the table's row, or a raw address. */
struct dxlt_reg {
	const struct dxl2_reg *row;   /* NULL for a raw address */
	uint16_t addr;
	uint8_t size;
	const char *name;
};

/* The model's table: identified by PING where the family's PING names it. */
int dxlt_identify(struct dxlt *t, uint8_t id, struct dxlt_servo *s);
/* The register REG names on this servo. */
int dxlt_arg_reg(struct dxlt *t, const struct dxlt_servo *s, const char *text, struct dxlt_reg *out);
/* A raw address on a model not in the tables: said once on err. */
void dxlt_raw_note(struct dxlt *t, const struct dxlt_servo *s, uint16_t addr, uint8_t size);
int32_t dxlt_decode(const struct dxlt_reg *reg, const uint8_t *raw);
/* Bytes from address 0 that hold every row of m (DXLT_IMAGE_MAX at most; NULL: that). */
size_t dxlt_image_len(const struct dxl2_model *m);
int dxlt_cmd_ping(struct dxlt *t);
int dxlt_cmd_read(struct dxlt *t);
/* sync-read REG ID... [--fast] [--units]: one SYNC_READ (or Fast Sync Read)
 * of REG from every servo listed, in the list's order. */
int dxlt_cmd_sync_read(struct dxlt *t);
/* bulk-read ID:REG... [--fast] [--units]: one BULK_READ (or Fast Bulk Read),
 * each servo's own register, in the list's order: ID REG VALUE a line. */
int dxlt_cmd_bulk_read(struct dxlt *t);
int dxlt_cmd_dump(struct dxlt *t);
int dxlt_cmd_write(struct dxlt *t);
int dxlt_cmd_torque(struct dxlt *t);
int dxlt_cmd_setup(struct dxlt *t);
/* ---- commands.c ---- */

/* ---- Protocol 2.0 (commands2.c) ---- */
/* Broadcast PING at the current rate: one scan line per servo in the ID range. */
int dxlt2_scan_at(struct dxlt *t, long baud, unsigned *found);

/* `dxl doctor` (doctor.c): opens the port itself, after reading the
 * configuration that may name it. */
int dxlt_cmd_doctor(struct dxlt *t);

#endif
