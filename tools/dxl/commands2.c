/*
 * commands2.c — what of `dxl` is still Protocol 2.0's own: the scan of one
 * rate by one broadcast PING (every X servo answers in ID order with its
 * model and firmware). The commands themselves are registers.c's and
 * commands.c's, written once over every model.
 */
#include "dxl2_table.h"
#include "dxlt_priv.h"

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
		if (f->id < t->a.id_lo || f->id > t->a.id_hi)
			continue;
		dxlt_seen(t, f->id, f->err);
		(*found)++;
		fprintf(t->out, "%-4u %-6u %-13s %-9u %-8ld 2.0\n", f->id, f->model, dxlt_model_name(2, f->model),
		        f->firmware, baud);
	}
	return DXLT_EXIT_OK;
}
