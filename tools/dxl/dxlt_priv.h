/*
 * dxlt_priv.h — what the `dxl` commands share inside libdxl (commands.c and
 * doctor.c): the tool's state over one bus and the helpers every command
 * uses. Not for the tests: they go through dxlt_main() (dxlt.h).
 */
#ifndef UNDULATE_DXLT_PRIV_H
#define UNDULATE_DXLT_PRIV_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "dxlt.h"

struct dxlt {
	struct dxlt_args a;
	FILE *out, *err;
	struct port *port;
	struct port_latency latency;
	struct bus bus;
	/* Error bits any reply carried, per ID: the servo's news, reported once
	 * when the command ends (dxlt_report_errbits), whichever call saw them. */
	uint8_t errseen[DXL_BROADCAST_ID + 1];
	char hint[200];          /* what to do about them, when we know */
};

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
/* Transactions whose replies' error bits are remembered in t->errseen. */
int dxlt_ping(struct dxlt *t, uint8_t id);
int dxlt_read(struct dxlt *t, uint8_t id, uint8_t addr, uint8_t len, uint8_t *out);
const char *dxlt_model_name(uint16_t model);

/* `dxl doctor` (doctor.c): opens the port itself, after reading the
 * configuration that may name it. */
int dxlt_cmd_doctor(struct dxlt *t);

#endif
