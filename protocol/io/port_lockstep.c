/*
 * port_lockstep.c — a port's bus_io in virtual time (port.h,
 * port_bus_io_lockstep; the protocol in common/lockstep.h).
 */
#include "port.h"

#include <stdio.h>

#include "clock.h"
#include "lockstep.h"

/* Bytes the simulator released and we have not read yet. */
static uint64_t pl_announced(const struct lks_client *c)
{
	return c->delivered > c->consumed ? c->delivered - c->consumed : 0;
}

/* Read every announced byte that fits in cap, waiting (wall clock) for the
 * tty worker to hand them over: all of them, never some, or the bus would
 * see half a reply at one virtual time and the rest at its deadline, as the
 * worker's timing had it (a run would then not repeat). Announced bytes that
 * do not come within the grace were lost with a pty closed under them: the
 * count is set right. */
static long pl_read(void *ctx, uint8_t *buf, size_t cap)
{
	struct port_lockstep *pl = ctx;
	struct lks_client *c = pl->clock;
	uint64_t avail = pl_announced(c);
	if (avail == 0 || cap == 0)
		return 0;
	if (cap > avail)
		cap = (size_t)avail;
	size_t got = 0;
	while (got < cap) {
		long n = port_read(pl->port, buf + got, cap - got);
		if (n < 0) {
			if (got > 0)
				break;   /* these first; the error comes with the next read */
			return n;
		}
		if (n == 0 && port_wait(pl->port, LKS_BYTES_GRACE_MS * 1000u) != 1) {
			c->resyncs++;
			c->consumed = c->delivered;
			return (long)got;
		}
		got += (size_t)n;
		c->consumed += (uint64_t)n;
	}
	return (long)got;
}

static int pl_write(void *ctx, const uint8_t *buf, size_t n)
{
	struct port_lockstep *pl = ctx;
	int r = port_write(pl->port, buf, n);
	if (r == DXL_OK)
		pl->clock->written += n;
	return r;
}

/* A blocking bus call's wait: a WAIT until the timeout, or until bytes come. */
static int pl_wait(void *ctx, uint32_t timeout_us)
{
	struct port_lockstep *pl = ctx;
	struct lks_client *c = pl->clock;
	if (pl_announced(c) > 0)
		return 1;
	char why[160];
	if (lks_client_block(c, lks_client_now_us(c) + timeout_us, true, why, sizeof why) != 0)
		return DXL_E_DISCONNECTED;
	return pl_announced(c) > 0 ? 1 : 0;
}

/* Discard what was announced (read, so the counts stay right), then
 * whatever else the port holds. */
static void pl_flush(void *ctx)
{
	struct port_lockstep *pl = ctx;
	uint8_t scratch[256];
	while (pl_announced(pl->clock) > 0)
		if (pl_read(ctx, scratch, sizeof scratch) <= 0)
			break;
	port_flush_input(pl->port);
}

static long pl_pending(void *ctx)
{
	struct port_lockstep *pl = ctx;
	return (long)pl_announced(pl->clock);
}

static uint64_t pl_now(void *ctx)
{
	(void)ctx;
	return clock_mono_us();
}

void port_bus_io_lockstep(struct port_lockstep *pl, struct port *p, struct lks_client *clock, struct bus_io *io)
{
	pl->port = p;
	pl->clock = clock;
	*io = (struct bus_io){
		.ctx = pl, .write = pl_write, .read = pl_read, .wait = pl_wait, .now_us = pl_now,
		.flush_input = pl_flush, .pending_input = pl_pending,
	};
}
