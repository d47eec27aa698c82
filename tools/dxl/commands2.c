/*
 * commands2.c — what of `dxl` is still Protocol 2.0's own: the scan of one
 * rate by one broadcast PING (every X servo answers in ID order with its
 * model and firmware), and the price `setup` puts on one cycle of the
 * daemon's SYNC_READ loop. The commands themselves are registers.c's and
 * commands.c's, written once over every model.
 */
#include "doctor.h"
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
		t->errseen2[f->id] |= f->err;
		(*found)++;
		fprintf(t->out, "%-4u %-6u %-13s %-9u %-8ld 2.0\n", f->id, f->model, dxlt_model_name(2, f->model),
		        f->firmware, baud);
	}
	return DXLT_EXIT_OK;
}

/* ---- setup's bus time ------------------------------------------------------------------ */

/* One 100 Hz cycle on Protocol 2.0 (daemon/cycle.c): one SYNC_READ of
 * position + velocity (+ current where a servo senses it), one SYNC_WRITE. */
void dxlt2_setup_budget(struct dxlt *t, unsigned n, bool current, int latency_ms)
{
	unsigned read_len = current ? DR2_READ_LEN_CURRENT : DR2_READ_LEN;
	double wire_ms = 1e-3 * dr2_cycle_wire_us(n, read_len, port_baud(t->port));
	double total_ms = wire_ms + latency_ms;

	fprintf(t->out, "bus time per cycle for %u servo%s at %ld bps: %.2f ms on the wire (one SYNC_READ of %u bytes "
	        "each, one SYNC_WRITE) + %d ms adapter latency = %.2f ms of the 10 ms period%s\n", n, n == 1 ? "" : "s",
	        port_baud(t->port), wire_ms, read_len, latency_ms, total_ms, total_ms > 5.0 ? " (too much for 100 Hz)" : "");
}
