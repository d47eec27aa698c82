/*
 * buscycle.c — the daemon's bus cycle alone, timed, for the benchmark suite:
 * per cycle one READ(36, 6) per servo, then one SYNC_WRITE of goal positions
 * (the servos' own present positions, so nothing moves), at a fixed rate.
 * Built by bench/run.sh against libprotocol.a; runs against a real bus or
 * the simulator's pty.
 *
 *   buscycle --port PATH --ids 1,2,3 [--baud BPS] [--cycles N] [--period-us P]
 *            [--latency-us L] [--margin-us M]
 *
 * IDs that do not answer a PING at start are kept in the cycle as "absent":
 * every cycle then pays their READ timeout, the cost of a missing servo.
 * Prints "key value" lines: the wire-time floor of one cycle, the derived
 * READ timeout, and the measured bus time per cycle (p50/p99/max, µs).
 *
 * Bus time is measured as the daemon measures it: from the first request to
 * the SYNC_WRITE handed to the port (it expects no reply, so its own wire
 * time overlaps the idle rest of the period). The floor printed beside it
 * includes the SYNC_WRITE's wire time, as a bus analyser would see the cycle.
 */
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bus.h"
#include "dxl.h"
#include "dxl_table.h"
#include "port.h"

/* Servos per cycle: the largest configuration the benchmark runs is 18. */
#define BC_MAX_IDS 32
/* Bytes of READ(36, 6): request FF FF ID 04 02 24 06 CHK, reply FF FF ID 08 ERR 6×P CHK. */
#define BC_READ_REQ_BYTES 8
#define BC_READ_REPLY_BYTES 12
#define BC_READ_LEN 6
/* Goal position: 2 bytes per servo in the SYNC_WRITE. */
#define BC_GOAL_BYTES 2
/* Largest return delay a servo can have (register 254 × 2 µs) and a generous
 * margin: the timing used to find the servos, before their real return delay
 * is known (a servo missed here would be counted as absent). */
#define BC_MAX_RETURN_DELAY_US 508
#define BC_DISCOVERY_MARGIN_US 20000

struct bc_opts {
	const char *port;
	uint8_t ids[BC_MAX_IDS];
	size_t nids;
	long baud;
	long cycles;
	long period_us;
	long latency_us, margin_us;
};

struct bc_run {
	struct bus bus;
	bool present[BC_MAX_IDS];
	uint16_t position[BC_MAX_IDS];
	unsigned return_delay_us;           /* largest of the present servos */
	double *cycle_us;                   /* one per cycle */
	double absent_sum_us, absent_max_us, present_sum_us;
	long absent_reads, present_reads, timeouts, errors, overruns;
};

static int bc_cmp(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

static double bc_pct(const double *v, size_t n, double p)
{
	size_t rank = (size_t)ceil(p * (double)n);
	return n ? v[rank ? rank - 1 : 0] : NAN;
}

static int bc_parse_ids(const char *text, struct bc_opts *o)
{
	char *end;
	const char *p = text;
	o->nids = 0;
	while (*p) {
		long id = strtol(p, &end, 10);
		if (end == p || id < 0 || id > DXL_MAX_ID || o->nids == BC_MAX_IDS)
			return -1;
		o->ids[o->nids++] = (uint8_t)id;
		p = *end == ',' ? end + 1 : end;
		if (*end && *end != ',')
			return -1;
	}
	return o->nids ? 0 : -1;
}

static int bc_parse(int argc, char **argv, struct bc_opts *o)
{
	*o = (struct bc_opts){ .baud = 1000000, .cycles = 500, .period_us = 10000 };
	for (int i = 1; i < argc; i++) {
		const char *k = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
		if (!v)
			return -1;
		i++;
		if (!strcmp(k, "--port"))
			o->port = v;
		else if (!strcmp(k, "--ids")) {
			if (bc_parse_ids(v, o) != 0)
				return -1;
		} else if (!strcmp(k, "--baud"))
			o->baud = atol(v);
		else if (!strcmp(k, "--cycles"))
			o->cycles = atol(v);
		else if (!strcmp(k, "--period-us"))
			o->period_us = atol(v);
		else if (!strcmp(k, "--latency-us"))
			o->latency_us = atol(v);
		else if (!strcmp(k, "--margin-us"))
			o->margin_us = atol(v);
		else
			return -1;
	}
	return o->port && o->nids && o->baud > 0 && o->cycles > 0 && o->period_us > 0 ? 0 : -1;
}

static void bc_timing(struct bc_run *r, const struct bc_opts *o, unsigned return_delay_us, long margin_us)
{
	struct bus_timing t = {
		.baud = o->baud, .return_delay_us = return_delay_us,
		.adapter_latency_us = (uint32_t)o->latency_us, .margin_us = (uint32_t)margin_us,
	};
	bus_set_timing(&r->bus, &t);
}

/* PING every ID; read the present servos' return delay, as the daemon does
 * at start-up, so the READ timeout is derived from the real value. */
static void bc_discover(struct bc_run *r, const struct bc_opts *o)
{
	bc_timing(r, o, BC_MAX_RETURN_DELAY_US, o->margin_us > BC_DISCOVERY_MARGIN_US ? o->margin_us : BC_DISCOVERY_MARGIN_US);
	r->return_delay_us = 0;
	for (size_t i = 0; i < o->nids; i++) {
		uint8_t eb = 0, rd = 0;
		r->present[i] = bus_ping(&r->bus, o->ids[i], &eb) == DXL_OK ||
		                bus_ping(&r->bus, o->ids[i], &eb) == DXL_OK;
		if (r->present[i] && bus_read_u8(&r->bus, o->ids[i], DXL_AX_RETURN_DELAY_TIME, &rd, &eb) == DXL_OK &&
		    dxl_return_delay_us(rd) > r->return_delay_us)
			r->return_delay_us = dxl_return_delay_us(rd);
		if (r->present[i])
			bus_read_u16(&r->bus, o->ids[i], DXL_AX_PRESENT_POSITION, &r->position[i], &eb);
	}
	bc_timing(r, o, r->return_delay_us, o->margin_us);
}

static void bc_read_one(struct bc_run *r, const struct bc_opts *o, size_t i)
{
	uint8_t data[BC_READ_LEN], eb = 0;
	uint64_t t0 = port_now_us();
	int rc = bus_read(&r->bus, o->ids[i], DXL_AX_PRESENT_POSITION, BC_READ_LEN, data, &eb);
	double us = (double)(port_now_us() - t0);
	if (rc == DXL_OK)
		r->position[i] = dxl_get_u16(data);
	else if (rc == DXL_E_TIMEOUT)
		r->timeouts++;
	else
		r->errors++;
	if (r->present[i]) {
		r->present_sum_us += us;
		r->present_reads++;
	} else {
		r->absent_sum_us += us;
		r->absent_max_us = us > r->absent_max_us ? us : r->absent_max_us;
		r->absent_reads++;
	}
}

static void bc_sync_write(struct bc_run *r, const struct bc_opts *o)
{
	uint8_t ids[BC_MAX_IDS], data[BC_GOAL_BYTES * BC_MAX_IDS], pkt[DXL_MAX_PACKET];
	size_t n = 0;
	for (size_t i = 0; i < o->nids; i++) {
		if (!r->present[i])
			continue;
		ids[n] = o->ids[i];
		dxl_put_u16(&data[BC_GOAL_BYTES * n], r->position[i]);
		n++;
	}
	int len = n ? dxl_encode_sync_write(pkt, sizeof pkt, DXL_AX_GOAL_POSITION, BC_GOAL_BYTES, ids, data, n) : 0;
	if (len > 0 && bus_send_raw(&r->bus, pkt, (size_t)len) != DXL_OK)
		r->errors++;
}

static void bc_sleep_until(struct timespec *next, long period_us, long *overruns)
{
	next->tv_nsec += period_us * 1000;
	while (next->tv_nsec >= 1000000000) {
		next->tv_nsec -= 1000000000;
		next->tv_sec++;
	}
	struct timespec now;
	clock_gettime(CLOCK_MONOTONIC, &now);
	if (now.tv_sec > next->tv_sec || (now.tv_sec == next->tv_sec && now.tv_nsec >= next->tv_nsec)) {
		/* the cycle outlasted the period: start the next one now */
		(*overruns)++;
		*next = now;
		return;
	}
	while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, next, NULL) != 0) {
	}
}

static void bc_cycles(struct bc_run *r, const struct bc_opts *o)
{
	struct timespec next;
	clock_gettime(CLOCK_MONOTONIC, &next);
	for (long c = 0; c < o->cycles; c++) {
		uint64_t t0 = port_now_us();
		for (size_t i = 0; i < o->nids; i++)
			bc_read_one(r, o, i);
		bc_sync_write(r, o);
		r->cycle_us[c] = (double)(port_now_us() - t0);
		bc_sleep_until(&next, o->period_us, &r->overruns);
	}
}

static void bc_report(struct bc_run *r, const struct bc_opts *o)
{
	size_t npresent = 0;
	for (size_t i = 0; i < o->nids; i++)
		npresent += r->present[i];
	/* SYNC_WRITE: LEN = (L + 1)·N + 4, on the wire LEN + 4 bytes. */
	size_t sync_bytes = npresent ? (BC_GOAL_BYTES + 1) * npresent + 4 + 4 : 0;
	uint32_t reads = (uint32_t)npresent * (bus_wire_time_us(&r->bus, BC_READ_REQ_BYTES + BC_READ_REPLY_BYTES) +
	                                       r->return_delay_us);
	uint32_t sync = bus_wire_time_us(&r->bus, sync_bytes);
	qsort(r->cycle_us, (size_t)o->cycles, sizeof(double), bc_cmp);
	printf("servos %zu\npresent %zu\nabsent %zu\n", o->nids, npresent, o->nids - npresent);
	printf("return_delay_us %u\n", r->return_delay_us);
	printf("floor_reads_us %" PRIu32 "\nfloor_sync_us %" PRIu32 "\nfloor_us %" PRIu32 "\n", reads, sync,
	       reads + sync);
	printf("timeout_us %" PRIu32 "\n", bus_timeout_us(&r->bus, BC_READ_REQ_BYTES, BC_READ_REPLY_BYTES));
	printf("cycles %ld\n", o->cycles);
	printf("bus_p50 %.0f\nbus_p99 %.0f\nbus_max %.0f\n", bc_pct(r->cycle_us, (size_t)o->cycles, 0.5),
	       bc_pct(r->cycle_us, (size_t)o->cycles, 0.99), r->cycle_us[o->cycles - 1]);
	printf("read_mean_us %.0f\n", r->present_reads ? r->present_sum_us / (double)r->present_reads : NAN);
	printf("absent_read_mean_us %.0f\nabsent_read_max_us %.0f\n",
	       r->absent_reads ? r->absent_sum_us / (double)r->absent_reads : NAN,
	       r->absent_reads ? r->absent_max_us : NAN);
	printf("timeouts %ld\nerrors %ld\noverruns %ld\n", r->timeouts, r->errors, r->overruns);
}

int main(int argc, char **argv)
{
	static struct bc_run r;
	struct bc_opts o;
	char err[256];
	if (bc_parse(argc, argv, &o) != 0) {
		fprintf(stderr, "usage: buscycle --port PATH --ids 1,2 [--baud BPS] [--cycles N] [--period-us P] "
		                "[--latency-us L] [--margin-us M]\n");
		return 2;
	}
	struct port_options popt = { .baud = o.baud, .force_termios = false, .low_latency = true };
	struct port *p = port_open(o.port, &popt, err, sizeof err);
	if (!p) {
		fprintf(stderr, "buscycle: %s\n", err);
		return 1;
	}
	struct bus_io io;
	struct bus_timing t = { .baud = o.baud };
	port_bus_io(p, &io);
	bus_init(&r.bus, &io, &t, false);
	r.cycle_us = calloc((size_t)o.cycles, sizeof(double));
	if (!r.cycle_us) {
		port_close(p);
		return 1;
	}
	bc_discover(&r, &o);
	bc_cycles(&r, &o);
	bc_report(&r, &o);
	free(r.cycle_us);
	port_close(p);
	return 0;
}
