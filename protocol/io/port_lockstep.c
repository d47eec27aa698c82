/*
 * port_lockstep.c — a port's bus_io in virtual time (port.h,
 * port_bus_io_lockstep; the protocol in common/lockstep.h). Two transports
 * for the bytes, as the simulator's WELCOME chose: in the clock's messages
 * (in-band: the pty is opened and set up, never read or written), or
 * through the pty with counts (the pty transport).
 */
#include "port.h"

#include <stdio.h>
#include <string.h>

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
static long pl_pty_read(void *ctx, uint8_t *buf, size_t cap)
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

static int pl_pty_write(void *ctx, const uint8_t *buf, size_t n)
{
	struct port_lockstep *pl = ctx;
	int r = port_write(pl->port, buf, n);
	if (r == DXL_OK)
		pl->clock->written += n;
	return r;
}

/* A blocking bus call's wait: a WAIT until the timeout, or until bytes come. */
static int pl_pty_wait(void *ctx, uint32_t timeout_us)
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
static void pl_pty_flush(void *ctx)
{
	struct port_lockstep *pl = ctx;
	uint8_t scratch[256];
	while (pl_announced(pl->clock) > 0)
		if (pl_pty_read(ctx, scratch, sizeof scratch) <= 0)
			break;
	port_flush_input(pl->port);
}

static long pl_pty_pending(void *ctx)
{
	struct port_lockstep *pl = ctx;
	return (long)pl_announced(pl->clock);
}

static uint64_t pl_now(void *ctx)
{
	(void)ctx;
	return clock_mono_us();
}

/* ---- in-band: the bytes travel in WAIT and TIME ------------------------------------ */

static size_t pl_unread(const struct lks_bus *c) { return c->nin - c->in_off; }

static struct lks_bus *pl_bus(struct port_lockstep *pl) { return &pl->clock->bus[pl->bus]; }

/* What the TIMEs delivered: all of it is here already. Nothing is nothing,
 * even on a port the simulator took away: the pty transport reads only
 * what was announced and never sees that port's hang-up on a read (its
 * next write does, as here), and the two give the same run. */
static long pl_band_read(void *ctx, uint8_t *buf, size_t cap)
{
	struct port_lockstep *pl = ctx;
	struct lks_bus *c = pl_bus(pl);
	size_t n = pl_unread(c);
	if (n == 0)
		return 0;
	if (n > cap)
		n = cap;
	memcpy(buf, c->in + c->in_off, n);
	c->in_off += n;
	if (c->in_off == c->nin)
		c->in_off = c->nin = 0;
	return (long)n;
}

/* Into the next WAIT. More than one message holds between two WAITs is
 * refused whole (the bus sees a failed write, as on a port that failed),
 * said once and counted: never cut short. */
static int pl_band_write(void *ctx, const uint8_t *buf, size_t n)
{
	struct port_lockstep *pl = ctx;
	struct lks_bus *c = pl_bus(pl);
	if (c->bus_gone)
		return DXL_E_DISCONNECTED;
	/* a new rate on the pty: the simulator reads it before these bytes */
	long rate = pl->port ? port_baud(pl->port) : 0;
	if (rate != pl->rate_told) {
		c->rate_set = true;
		pl->rate_told = rate;
	}
	if (n > sizeof c->out - c->nout) {
		if (c->too_long++ == 0)
			fprintf(stderr, "lockstep: %zu bus bytes after %zu already written since the last wait: more than "
			        "the %d bytes one clock message carries; the write is refused (counted; see common/lockstep.h "
			        "LKS_BYTES_MAX)\n", n, c->nout, LKS_BYTES_MAX);
		return DXL_E_BUFFER;
	}
	memcpy(c->out + c->nout, buf, n);
	c->nout += n;
	pl->clock->written += n;
	return DXL_OK;
}

static int pl_band_wait(void *ctx, uint32_t timeout_us)
{
	struct port_lockstep *pl = ctx;
	struct lks_client *c = pl->clock;
	if (pl_unread(pl_bus(pl)) > 0)
		return 1;
	/* the whole daemon waits: only this bus's bytes wake it early */
	char why[160];
	if (lks_client_block(c, lks_client_now_us(c) + timeout_us, 1u << pl->bus, why, sizeof why) != 0)
		return DXL_E_DISCONNECTED;
	return pl_unread(pl_bus(pl)) > 0 ? 1 : 0;
}

static void pl_band_flush(void *ctx)
{
	struct port_lockstep *pl = ctx;
	pl_bus(pl)->in_off = pl_bus(pl)->nin = 0;
}

static long pl_band_pending(void *ctx)
{
	struct port_lockstep *pl = ctx;
	return (long)pl_unread(pl_bus(pl));
}

void port_bus_io_lockstep(struct port_lockstep *pl, struct port *p, struct lks_client *clock, size_t bus,
                          struct bus_io *io)
{
	pl->port = p;
	pl->clock = clock;
	pl->bus = bus < LKS_BUSES_MAX ? bus : 0;
	pl->rate_told = p ? port_baud(p) : 0;   /* the opening says so: LKS_PORT_OPENED */
	lks_client_port_opened(clock, pl->bus);
	if (clock->inband)
		*io = (struct bus_io){
			.ctx = pl, .write = pl_band_write, .read = pl_band_read, .wait = pl_band_wait, .now_us = pl_now,
			.flush_input = pl_band_flush, .pending_input = pl_band_pending,
		};
	else
		*io = (struct bus_io){
			.ctx = pl, .write = pl_pty_write, .read = pl_pty_read, .wait = pl_pty_wait, .now_us = pl_now,
			.flush_input = pl_pty_flush, .pending_input = pl_pty_pending,
		};
}
