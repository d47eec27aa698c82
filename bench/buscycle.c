/*
 * buscycle.c — the daemon's bus cycle alone, timed, for the benchmark suite:
 * per cycle one READ(36, 6) per servo, then one SYNC_WRITE of goal positions
 * (the servos' own present positions, so nothing moves), at a fixed rate.
 * Built by bench/run.sh against libprotocol.a; runs against a real bus or
 * the simulator's pty.
 *
 *   buscycle --port PATH|fake --ids 1,2,3 [--protocol 1|2] [--read-len 8|10]
 *            [--baud BPS] [--cycles N] [--period-us P] [--latency-us L] [--margin-us M]
 *            [--read sync|fast|indirect]
 *
 * --protocol 2: the X series' cycle instead — one SYNC_READ of read_len
 * bytes from every servo (present velocity + position at 128, 8 bytes; with
 * the present current at 126, 10 bytes, on the XM430) and one SYNC_WRITE
 * of 4-byte goal positions. --read fast: the SYNC_READ is a Fast Sync Read
 * (one status packet for all servos: one header and one return delay for the
 * lot; its floor: a request of 14 + N bytes, one reply of 8 + N (4 +
 * read_len), one return delay). --read indirect: what undulated's slow cycle
 * reads (present current, velocity, position at 126..135, input voltage and
 * temperature at 144..146: 21 bytes where they lie) mapped at start into
 * every servo's Indirect Data 1..13 (224) and read there by Fast Sync Read,
 * 13 bytes a servo (the map is written and read back first; a servo that
 * refuses it ends the run: nothing is measured). --port fake serves that bus in-process: a pty
 * whose other end answers as X servos with return delay 0, holding each
 * reply until the wire time of the request and the replies at the baud has
 * passed (what undulate-sim does for the AX-12; its X servos come with the
 * simulator's --model).
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
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "bus.h"
#include "dxl.h"
#include "dxl2.h"
#include "dxl2_table.h"
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
	int protocol;
	unsigned read_len;                  /* 2.0: bytes a servo in the SYNC_READ */
	bool fast;                          /* 2.0: --read fast, a Fast Sync Read */
	bool indirect;                      /* 2.0: --read indirect, Fast Sync Read of the indirect block */
};

/* undulated's indirect map on the X series (daemon/servo_model.c,
 * sm_x_indirect_src): present current, velocity, position, then input
 * voltage and temperature, each byte one slot. */
static const uint16_t bc_indirect_src[] = { 126, 127, 128, 129, 130, 131, 132, 133, 134, 135, 144, 145, 146 };
#define BC_INDIRECT_LEN (sizeof bc_indirect_src / sizeof bc_indirect_src[0])

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
	*o = (struct bc_opts){ .baud = 1000000, .cycles = 500, .period_us = 10000, .protocol = 1, .read_len = 8 };
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
		else if (!strcmp(k, "--protocol"))
			o->protocol = atoi(v);
		else if (!strcmp(k, "--read-len"))
			o->read_len = (unsigned)atoi(v);
		else if (!strcmp(k, "--read") && (!strcmp(v, "fast") || !strcmp(v, "sync") || !strcmp(v, "indirect"))) {
			o->fast = strcmp(v, "sync") != 0;
			o->indirect = !strcmp(v, "indirect");
		} else
			return -1;
	}
	/* the indirect block's length is the map's, whatever --read-len said;
	 * its 13 bytes read where the registers lie would be another block */
	if (o->indirect)
		o->read_len = BC_INDIRECT_LEN;
	else if (o->read_len == BC_INDIRECT_LEN)
		return -1;
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

/* ---- Protocol 2.0 ------------------------------------------------------------------ */

/* The SYNC_READ's first address: present velocity (128), or the present
 * current before it (126) when 10 bytes are read; Indirect Data 1 (224) for
 * the indirect block. */
static uint16_t bc2_read_addr(const struct bc_opts *o)
{
	if (o->indirect)
		return DXL2_X_INDIRECT_DATA_1;
	return o->read_len == 10 ? DXL2_X_PRESENT_CURRENT : DXL2_X_PRESENT_VELOCITY;
}

/* Where the present position lies in a servo's data: last of 8 or 10 bytes,
 * slots 7..10 of the indirect block. */
static size_t bc2_position_at(const struct bc_opts *o)
{
	return o->indirect ? 6 : o->read_len - 4;
}

/* One cycle: every servo's state in one SYNC_READ, every goal in one SYNC_WRITE. */
static void bc2_cycle(struct bc_run *r, const struct bc_opts *o)
{
	uint8_t data[BC_MAX_IDS * BC_INDIRECT_LEN], goals[BC_MAX_IDS * 4];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	int rc = o->fast ? bus_fast_sync_read(&r->bus, bc2_read_addr(o), (uint16_t)o->read_len, o->ids, o->nids, &m)
	                 : bus_sync_read(&r->bus, bc2_read_addr(o), (uint16_t)o->read_len, o->ids, o->nids, &m);
	if (rc != DXL_OK && rc != DXL_E_TIMEOUT)
		r->errors++;
	for (size_t i = 0; i < m.n; i++) {
		const uint8_t *p = bus_multi_data(&m, i);
		if (p != NULL)
			r->position[i] = (uint16_t)dxl2_get_u32(p + bc2_position_at(o));
		else if (m.status[i] == DXL_E_TIMEOUT)
			r->timeouts++;
		dxl2_put_u32(goals + 4 * i, r->position[i]);
	}
	if (bus_sync_write(&r->bus, DXL2_X_GOAL_POSITION, 4, o->ids, goals, o->nids) != DXL_OK)
		r->errors++;
}

/* Wire bytes of the 2.0 cycle: SYNC_READ request 14 + N, each reply
 * 11 + read_len, SYNC_WRITE 14 + 5 N (no byte stuffed: the floor); a Fast
 * Sync Read's one reply 8 + N (4 + read_len), one return delay. */
static void bc2_floor(const struct bc_run *r, const struct bc_opts *o, size_t n, uint32_t *reads, uint32_t *sync)
{
	if (o->fast)
		*reads = bus_wire_time_us(&r->bus, 14 + n + 8 + n * (4 + o->read_len)) + (n ? r->return_delay_us : 0);
	else
		*reads = bus_wire_time_us(&r->bus, 14 + n + n * (11 + o->read_len)) + (uint32_t)n * r->return_delay_us;
	*sync = bus_wire_time_us(&r->bus, 14 + 5 * n);
}

/* ---- what differs by protocol ---------------------------------------------------- */

/* One protocol's cycle and the registers the bench reads at start: the
 * bench's one choice of protocol, made from --protocol (bc_proto_of). */
struct bc_proto {
	enum bus_protocol bus;
	bool fake;                                /* the in-process fake serves it */
	bool (*read_len_ok)(unsigned len);        /* --read-len */
	uint16_t return_delay_reg, position_reg;
	unsigned (*return_delay_us)(uint8_t v);
	void (*cycle)(struct bc_run *r, const struct bc_opts *o);
	/* the wire-time floor of the cycle's reads and SYNC_WRITE, the reads' timeout */
	void (*floor)(const struct bc_run *r, const struct bc_opts *o, size_t npresent, uint32_t *reads,
	              uint32_t *sync, uint32_t *timeout);
};

static bool bc_any_read_len(unsigned len)
{
	(void)len;   /* 1.0 reads READ(36, 6) whatever --read-len says */
	return true;
}

/* One READ per servo, then one SYNC_WRITE. */
static void bc_cycle(struct bc_run *r, const struct bc_opts *o)
{
	for (size_t i = 0; i < o->nids; i++)
		bc_read_one(r, o, i);
	bc_sync_write(r, o);
}

static void bc_floor(const struct bc_run *r, const struct bc_opts *o, size_t npresent, uint32_t *reads,
                     uint32_t *sync, uint32_t *timeout)
{
	(void)o;
	/* SYNC_WRITE: LEN = (L + 1)·N + 4, on the wire LEN + 4 bytes. */
	size_t sync_bytes = npresent ? (BC_GOAL_BYTES + 1) * npresent + 4 + 4 : 0;
	*reads = (uint32_t)npresent * (bus_wire_time_us(&r->bus, BC_READ_REQ_BYTES + BC_READ_REPLY_BYTES) +
	                               r->return_delay_us);
	*sync = bus_wire_time_us(&r->bus, sync_bytes);
	*timeout = bus_timeout_us(&r->bus, BC_READ_REQ_BYTES, BC_READ_REPLY_BYTES);
}

/* present velocity + position (8 bytes), or with the present current before
 * them (10); the indirect block's 13 (set by --read indirect) */
static bool bc2_read_len_ok(unsigned len)
{
	return len == 8 || len == 10 || len == BC_INDIRECT_LEN;
}

/* --read indirect: every present servo's Indirect Address 1..13 set to the
 * map (torque is off on a servo just found: the registers are writable),
 * then read back. 0, or -1 with why. */
static int bc2_map_indirect(struct bc_run *r, const struct bc_opts *o, char *why, size_t cap)
{
	uint8_t want[2 * BC_INDIRECT_LEN], got[2 * BC_INDIRECT_LEN], eb = 0;
	for (size_t k = 0; k < BC_INDIRECT_LEN; k++) {
		want[2 * k] = (uint8_t)(bc_indirect_src[k] & 0xFF);
		want[2 * k + 1] = (uint8_t)(bc_indirect_src[k] >> 8);
	}
	/* set-up, not the cycle: the discovery's patience (a late reply here
	 * would end the run) */
	bc_timing(r, o, r->return_delay_us, o->margin_us > BC_DISCOVERY_MARGIN_US ? o->margin_us : BC_DISCOVERY_MARGIN_US);
	for (size_t i = 0; i < o->nids; i++) {
		if (!r->present[i])
			continue;
		int rc = bus_write(&r->bus, o->ids[i], DXL2_X_INDIRECT_ADDRESS_1, want, sizeof want, true, &eb);
		if (rc == DXL_OK)
			rc = bus_read(&r->bus, o->ids[i], DXL2_X_INDIRECT_ADDRESS_1, sizeof got, got, &eb);
		if (rc != DXL_OK || (eb & DXL2_ERR_NUMBER_MASK) || memcmp(got, want, sizeof want) != 0) {
			snprintf(why, cap, "servo %u did not take the indirect map (%s)", o->ids[i],
			         rc != DXL_OK ? dxl_strerror(rc) : (eb & DXL2_ERR_NUMBER_MASK) ? dxl2_error_name(eb & DXL2_ERR_NUMBER_MASK) : "read back otherwise");
			return -1;
		}
	}
	bc_timing(r, o, r->return_delay_us, o->margin_us);
	return 0;
}

static void bc2_floor_timeout(const struct bc_run *r, const struct bc_opts *o, size_t npresent, uint32_t *reads,
                              uint32_t *sync, uint32_t *timeout)
{
	uint16_t lens[BC_MAX_IDS];
	for (size_t i = 0; i < o->nids; i++)
		lens[i] = (uint16_t)o->read_len;
	bc2_floor(r, o, npresent, reads, sync);
	*timeout = o->fast ? bus_fast_timeout_us(&r->bus, 14 + o->nids, lens, o->nids)
	                   : bus_multi_timeout_us(&r->bus, 14 + o->nids, lens, o->nids);
}

static const struct bc_proto bc_v1 = {
	.bus = BUS_PROTOCOL_1, .fake = false, .read_len_ok = bc_any_read_len,
	.return_delay_reg = DXL_AX_RETURN_DELAY_TIME, .position_reg = DXL_AX_PRESENT_POSITION,
	.return_delay_us = dxl_return_delay_us, .cycle = bc_cycle, .floor = bc_floor,
};

static const struct bc_proto bc_v2 = {
	.bus = BUS_PROTOCOL_2, .fake = true, .read_len_ok = bc2_read_len_ok,
	.return_delay_reg = DXL2_X_RETURN_DELAY_TIME, .position_reg = DXL2_X_PRESENT_POSITION,
	.return_delay_us = dxl2_return_delay_us, .cycle = bc2_cycle, .floor = bc2_floor_timeout,
};

/* The table for --protocol N; NULL for a protocol the bench does not run. */
static const struct bc_proto *bc_proto_of(int protocol)
{
	const struct bc_proto *all[] = { NULL, &bc_v1, &bc_v2 };
	return protocol >= 1 && protocol <= 2 ? all[protocol] : NULL;
}

/* PING every ID; read the present servos' return delay, as the daemon does
 * at start-up, so the READ timeout is derived from the real value, and
 * their present position (its low 16 bits: the goal written back). */
static void bc_discover(struct bc_run *r, const struct bc_opts *o, const struct bc_proto *bp)
{
	bc_timing(r, o, BC_MAX_RETURN_DELAY_US, o->margin_us > BC_DISCOVERY_MARGIN_US ? o->margin_us : BC_DISCOVERY_MARGIN_US);
	r->return_delay_us = 0;
	for (size_t i = 0; i < o->nids; i++) {
		uint8_t eb = 0, rd = 0, pos[2];
		r->present[i] = bus_ping(&r->bus, o->ids[i], &eb) == DXL_OK ||
		                bus_ping(&r->bus, o->ids[i], &eb) == DXL_OK;
		if (r->present[i] && bus_read_u8(&r->bus, o->ids[i], bp->return_delay_reg, &rd, &eb) == DXL_OK &&
		    bp->return_delay_us(rd) > r->return_delay_us)
			r->return_delay_us = bp->return_delay_us(rd);
		if (r->present[i] && bus_read(&r->bus, o->ids[i], bp->position_reg, sizeof pos, pos, &eb) == DXL_OK)
			r->position[i] = dxl_get_u16(pos);
	}
	bc_timing(r, o, r->return_delay_us, o->margin_us);
}

/* The in-process fake X bus: the pty's master end, served by a thread. */
struct bc_fake {
	int master;
	long baud;
	atomic_bool stop;
	pthread_t thread;
	uint8_t mem[BC_MAX_IDS][DXL2_X_TABLE_SIZE];
	uint8_t ids[BC_MAX_IDS];
	size_t n;
};

static int bc_fake_servo(const struct bc_fake *f, uint8_t id)
{
	for (size_t i = 0; i < f->n; i++)
		if (f->ids[i] == id)
			return (int)i;
	return -1;
}

static void bc_fake_sleep_us(uint64_t us)
{
	struct timespec ts = { (time_t)(us / 1000000u), (long)(us % 1000000u) * 1000L };
	while (nanosleep(&ts, &ts) != 0) {
	}
}

/* Replies queued for one request, sent once their wire time has passed. */
static void bc_fake_answer(struct bc_fake *f, const struct dxl2_packet *pkt, uint64_t got_us)
{
	static uint8_t out[8192];
	size_t len = 0;
	int k;
	uint16_t addr = pkt->nparams >= 2 ? (uint16_t)(pkt->params[0] | pkt->params[1] << 8) : 0;
	uint16_t n = pkt->nparams >= 4 ? (uint16_t)(pkt->params[2] | pkt->params[3] << 8) : 0;
	if (pkt->instr == DXL2_INST_SYNC_WRITE) {
		for (size_t i = 4; n > 0 && i + n < pkt->nparams + 1u; i += 1u + n)
			if ((k = bc_fake_servo(f, pkt->params[i])) >= 0 && addr + n <= DXL2_X_TABLE_SIZE)
				memcpy(&f->mem[k][addr], &pkt->params[i + 1], n);
		return;
	}
	if (pkt->instr == DXL2_INST_FAST_SYNC_READ && addr + n <= DXL2_X_TABLE_SIZE && n > 0) {
		/* one packet, each servo's part in turn; a missing one ends it */
		struct dxl2_fast_part parts[BC_MAX_IDS];
		size_t ends[BC_MAX_IDS], np = 0, asked = pkt->nparams > 4 ? pkt->nparams - 4u : 0u;
		for (size_t i = 0; i < asked && i < BC_MAX_IDS; i++) {
			uint8_t id = pkt->params[4 + i];
			k = bc_fake_servo(f, id);
			parts[i] = (struct dxl2_fast_part){ id, 0, n, k >= 0 ? &f->mem[k][addr] : f->mem[0] };
			np += k >= 0 && np == i;
		}
		int w = asked && asked <= BC_MAX_IDS ? dxl2_encode_fast_status(out, sizeof out, parts, asked, ends) : -1;
		len = w > 0 && np > 0 ? ends[np - 1] : 0;
	} else if (pkt->instr == DXL2_INST_SYNC_READ && addr + n <= DXL2_X_TABLE_SIZE) {
		for (size_t i = 4; i < pkt->nparams; i++) {
			if ((k = bc_fake_servo(f, pkt->params[i])) < 0)
				continue;   /* a missing servo: the rest still answer */
			int w = dxl2_encode_status(out + len, sizeof out - len, pkt->params[i], 0, &f->mem[k][addr], n);
			len += w > 0 ? (size_t)w : 0;
		}
	} else if ((k = bc_fake_servo(f, pkt->id)) >= 0) {
		if (pkt->instr == DXL2_INST_PING) {
			const uint8_t p[3] = { f->mem[k][0], f->mem[k][1], f->mem[k][DXL2_X_FIRMWARE_VERSION] };
			int w = dxl2_encode_status(out, sizeof out, pkt->id, 0, p, 3);
			len = w > 0 ? (size_t)w : 0;
		} else if (pkt->instr == DXL2_INST_READ && addr + n <= DXL2_X_TABLE_SIZE) {
			int w = dxl2_encode_status(out, sizeof out, pkt->id, 0, &f->mem[k][addr], n);
			len = w > 0 ? (size_t)w : 0;
		}
	}
	if (len == 0)
		return;
	/* the request took its wire time to arrive, the replies take theirs */
	uint64_t wire_us = (uint64_t)(pkt->wire_bytes + len) * 10u * 1000000u / (uint64_t)f->baud;
	uint64_t now = port_now_us();
	if (got_us + wire_us > now)
		bc_fake_sleep_us(got_us + wire_us - now);
	for (size_t done = 0; done < len;) {
		ssize_t wr = write(f->master, out + done, len - done);
		if (wr <= 0)
			return;
		done += (size_t)wr;
	}
}

static void *bc_fake_serve(void *arg)
{
	struct bc_fake *f = arg;
	struct dxl2_parser parser;
	struct dxl2_packet pkt;
	uint8_t buf[1024];
	dxl2_parser_init(&parser, DXL2_PARSE_INSTRUCTION);
	while (!atomic_load(&f->stop)) {
		struct pollfd pfd = { .fd = f->master, .events = POLLIN };
		if (poll(&pfd, 1, 20) <= 0)
			continue;
		ssize_t n = read(f->master, buf, sizeof buf);
		uint64_t got = port_now_us();
		size_t off = 0;
		while (n > 0) {
			size_t used = 0;
			int r = dxl2_parser_feed(&parser, buf + off, (size_t)n - off, &used, &pkt);
			off += used;
			if (r == DXL_NEED_MORE)
				break;
			if (r == DXL_FRAME)
				bc_fake_answer(f, &pkt, got);
		}
	}
	return NULL;
}

/* A pty served as X servos (model XM430-W350, return delay 0, at the centre);
 * its slave's path in path. */
static int bc_fake_start(struct bc_fake *f, const struct bc_opts *o, char *path, size_t cap)
{
	struct termios tio;
	f->master = posix_openpt(O_RDWR | O_NOCTTY);
	if (f->master < 0 || grantpt(f->master) != 0 || unlockpt(f->master) != 0 || tcgetattr(f->master, &tio) != 0)
		return -1;
	cfmakeraw(&tio);   /* both ends raw, or the line discipline mangles bytes */
	tcsetattr(f->master, TCSANOW, &tio);
	snprintf(path, cap, "%s", ptsname(f->master));
	f->baud = o->baud;
	f->n = o->nids;
	for (size_t i = 0; i < o->nids; i++) {
		f->ids[i] = o->ids[i];
		memset(f->mem[i], 0, sizeof f->mem[i]);
		dxl_put_u16(&f->mem[i][DXL2_X_MODEL_NUMBER], DXL2_MODEL_XM430_W350);
		dxl2_put_u32(&f->mem[i][DXL2_X_PRESENT_POSITION], DXL2_POS_CENTER);
	}
	return pthread_create(&f->thread, NULL, bc_fake_serve, f) == 0 ? 0 : -1;
}

static void bc_fake_stop(struct bc_fake *f)
{
	atomic_store(&f->stop, true);
	pthread_join(f->thread, NULL);
	close(f->master);
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

static void bc_cycles(struct bc_run *r, const struct bc_opts *o, const struct bc_proto *bp)
{
	struct timespec next;
	clock_gettime(CLOCK_MONOTONIC, &next);
	for (long c = 0; c < o->cycles; c++) {
		uint64_t t0 = port_now_us();
		bp->cycle(r, o);
		r->cycle_us[c] = (double)(port_now_us() - t0);
		bc_sleep_until(&next, o->period_us, &r->overruns);
	}
}

static void bc_report(struct bc_run *r, const struct bc_opts *o, const struct bc_proto *bp)
{
	size_t npresent = 0;
	for (size_t i = 0; i < o->nids; i++)
		npresent += r->present[i];
	uint32_t reads, sync, timeout;
	bp->floor(r, o, npresent, &reads, &sync, &timeout);
	printf("protocol %d\n", o->protocol);
	printf("read %s\n", o->indirect ? "indirect" : o->fast ? "fast" : "sync");
	printf("read_len %u\n", o->read_len);
	qsort(r->cycle_us, (size_t)o->cycles, sizeof(double), bc_cmp);
	printf("servos %zu\npresent %zu\nabsent %zu\n", o->nids, npresent, o->nids - npresent);
	printf("return_delay_us %u\n", r->return_delay_us);
	printf("floor_reads_us %" PRIu32 "\nfloor_sync_us %" PRIu32 "\nfloor_us %" PRIu32 "\n", reads, sync,
	       reads + sync);
	printf("timeout_us %" PRIu32 "\n", timeout);
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
	static struct bc_fake fake;
	struct bc_opts o;
	char err[256], fake_path[64];
	const struct bc_proto *bp = NULL;
	if (bc_parse(argc, argv, &o) != 0 || (bp = bc_proto_of(o.protocol)) == NULL || !bp->read_len_ok(o.read_len)) {
		fprintf(stderr, "usage: buscycle --port PATH|fake --ids 1,2 [--protocol 1|2] [--read-len 8|10] [--baud BPS] "
		                "[--cycles N] [--period-us P] [--latency-us L] [--margin-us M] [--read sync|fast|indirect]\n");
		return 2;
	}
	bool fake_bus = strcmp(o.port, "fake") == 0;
	if (o.indirect && (fake_bus || o.protocol != 2)) {
		fprintf(stderr, "buscycle: --read indirect wants X servos on a real bus or undulate-sim (--protocol 2; the "
		                "in-process fake has no indirect area)\n");
		return 2;
	}
	if (fake_bus && (!bp->fake || bc_fake_start(&fake, &o, fake_path, sizeof fake_path) != 0)) {
		fprintf(stderr, "buscycle: the in-process fake serves Protocol 2.0 only (--protocol 2)\n");
		return 1;
	}
	struct port_options popt = { .baud = o.baud, .force_termios = false, .low_latency = true };
	struct port *p = port_open(fake_bus ? fake_path : o.port, &popt, err, sizeof err);
	if (!p) {
		fprintf(stderr, "buscycle: %s\n", err);
		return 1;
	}
	struct bus_io io;
	struct bus_timing t = { .baud = o.baud };
	port_bus_io(p, &io);
	bus_init(&r.bus, &io, &t, false);
	bus_set_protocol(&r.bus, bp->bus);
	r.cycle_us = calloc((size_t)o.cycles, sizeof(double));
	if (!r.cycle_us) {
		port_close(p);
		return 1;
	}
	bc_discover(&r, &o, bp);
	if (o.indirect && bc2_map_indirect(&r, &o, err, sizeof err) != 0) {
		fprintf(stderr, "buscycle: %s\n", err);
		free(r.cycle_us);
		port_close(p);
		return 1;
	}
	bc_cycles(&r, &o, bp);
	bc_report(&r, &o, bp);
	free(r.cycle_us);
	port_close(p);
	if (fake_bus)
		bc_fake_stop(&fake);
	return 0;
}
