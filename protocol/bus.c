/*
 * bus.c — Dynamixel transactions over struct bus_io, for any protocol with
 * a table (dxl_proto.h).
 *
 * Pure like the framing: time comes only from io->now_us, waiting only through
 * io->wait (in the blocking calls). The asynchronous core is bus_begin /
 * bus_step; the blocking calls are a begin and a loop of bus_step and
 * io->wait. What a request costs and how its bytes are flushed, echoed, timed
 * and counted is one code; encoding a request and parsing its replies are
 * b->proto's, and what a protocol cannot do is a capability it lacks, never
 * a branch on its number.
 */
#include "bus.h"

#include <string.h>

/* 8N1: start bit, 8 data bits, stop bit. */
#define BUS_BITS_PER_BYTE 10u
/* Used when the timing names no baud: the AX-12's factory rate. */
#define BUS_DEFAULT_BAUD 1000000L
/* Bytes read from the transport per call in bus_step (more is simply read
 * on the next turn of the loop). */
#define BUS_READ_CHUNK 256
/* Time allowed for each ID after a broadcast PING: ROBOTIS's SDK waits
 * 3 ms an ID (protocol2_packet_handler.cpp, broadcastPing), a figure from
 * their firmware's behaviour that the manual does not state; the reply's
 * own wire time and return delay are used when they are longer. */
#define BUS_PING_ALL_SLOT_US 3000u

void bus_init(struct bus *b, const struct bus_io *io, const struct bus_timing *timing, bool echo)
{
	memset(b, 0, sizeof *b);
	if (io)
		b->io = *io;
	if (timing)
		b->timing = *timing;
	b->echo = echo;
	b->proto = &dxl_proto_v1;
	b->expect_params = -1;
	b->line_dirty = true;   /* whatever was on the line before us */
	b->proto->parser_init(&b->parser, false);
}

int bus_set_proto(struct bus *b, const struct dxl_proto *proto)
{
	if (proto == NULL)
		return DXL_E_ARG;
	if (b->pending)
		return DXL_E_BUSY;
	if (proto == b->proto) {
		proto->parser_reset(&b->parser);
		return DXL_OK;
	}
	b->line_dirty = true;   /* the other protocol's replies may still come */
	b->proto = proto;
	proto->parser_init(&b->parser, false);
	return DXL_OK;
}

const struct dxl_proto *bus_proto(const struct bus *b)
{
	return b->proto;
}

int bus_set_protocol(struct bus *b, enum bus_protocol protocol)
{
	return bus_set_proto(b, dxl_proto_by_number((int)protocol));
}

enum bus_protocol bus_get_protocol(const struct bus *b)
{
	return (enum bus_protocol)b->proto->number;
}

void bus_set_timing(struct bus *b, const struct bus_timing *timing)
{
	if (timing)
		b->timing = *timing;
}

uint32_t bus_wire_time_us(const struct bus *b, size_t nbytes)
{
	uint64_t baud = b->timing.baud > 0 ? (uint64_t)b->timing.baud : (uint64_t)BUS_DEFAULT_BAUD;
	uint64_t bits = (uint64_t)nbytes * BUS_BITS_PER_BYTE;
	/* rounded up: a timeout must never be shorter than the wire time */
	return (uint32_t)((bits * 1000000u + baud - 1) / baud);
}

uint32_t bus_timeout_us(const struct bus *b, size_t req_bytes, size_t reply_bytes)
{
	return bus_wire_time_us(b, req_bytes + reply_bytes) + b->timing.return_delay_us +
	       b->timing.adapter_latency_us + b->timing.margin_us;
}

uint32_t bus_multi_timeout_us(const struct bus *b, size_t req_bytes, const uint16_t *reply_params, size_t nreplies)
{
	size_t bytes = req_bytes;
	for (size_t i = 0; i < nreplies; i++)
		bytes += b->proto->status_bytes_max(reply_params[i]);
	uint64_t us = (uint64_t)bus_wire_time_us(b, bytes) + (uint64_t)nreplies * b->timing.return_delay_us +
	              b->timing.adapter_latency_us + b->timing.margin_us;
	return us > UINT32_MAX ? UINT32_MAX : (uint32_t)us;
}

uint32_t bus_fast_timeout_us(const struct bus *b, size_t req_bytes, const uint16_t *lens, size_t n)
{
	uint64_t us = (uint64_t)bus_wire_time_us(b, req_bytes + dxl2_fast_status_bytes(lens, n)) +
	              b->timing.return_delay_us + b->timing.adapter_latency_us + b->timing.margin_us;
	return us > UINT32_MAX ? UINT32_MAX : (uint32_t)us;
}

/* A broadcast PING's deadline: a slot for every ID that might answer. */
static uint32_t bus_ping_all_timeout_us(const struct bus *b, size_t req_bytes)
{
	const struct dxl_proto *pr = b->proto;
	uint32_t reply_us = bus_wire_time_us(b, pr->status_bytes_max(pr->ping_reply_params)) + b->timing.return_delay_us;
	uint32_t slot_us = reply_us > BUS_PING_ALL_SLOT_US ? reply_us : BUS_PING_ALL_SLOT_US;
	return bus_wire_time_us(b, req_bytes) + ((uint32_t)pr->max_id + 1) * slot_us + b->timing.adapter_latency_us +
	       b->timing.margin_us;
}

void bus_reset_stats(struct bus *b)
{
	memset(b->servo, 0, sizeof b->servo);
	b->stray_packets = 0;
	b->io_errors = 0;
	b->echo_errors = 0;
	b->bytes_out = 0;
	b->bytes_in = 0;
}

/* ---- echo cancelling -------------------------------------------------------- */

static void bus_echo_clear(struct bus *b)
{
	b->echo_len = 0;
	b->echo_left = 0;
}

/* Remember bytes just written; they must come back before anything else. */
static void bus_echo_push(struct bus *b, const uint8_t *pkt, size_t n)
{
	if (!b->echo)
		return;
	size_t matched = b->echo_len - b->echo_left;
	memmove(b->echo_buf, b->echo_buf + matched, b->echo_left);
	b->echo_len = b->echo_left;
	/* two packets of the protocol spoken */
	if (b->echo_len + n > 2 * b->proto->max_packet) {
		/* an older echo never came back (wiring without echo?): forget it;
		 * if it arrives after all, the mismatch is reported then */
		bus_echo_clear(b);
	}
	memcpy(b->echo_buf + b->echo_len, pkt, n);
	b->echo_len += n;
	b->echo_left += n;
}
/* Match received bytes against the echo queue. Returns how many of the n
 * bytes were echo (discarded), or DXL_E_ECHO on the first differing byte. */
static long bus_echo_eat(struct bus *b, const uint8_t *data, size_t n)
{
	size_t i = 0;
	while (i < n && b->echo_left > 0) {
		if (data[i] != b->echo_buf[b->echo_len - b->echo_left]) {
			b->echo_errors++;
			bus_echo_clear(b);
			return DXL_E_ECHO;
		}
		b->echo_left--;
		i++;
	}
	if (b->echo_left == 0)
		b->echo_len = 0;
	return (long)i;
}

/* Before a request: read back what already arrived of an earlier request's
 * echo, so that flushing cannot cut an echo in half. */
static int bus_echo_drain(struct bus *b)
{
	uint8_t chunk[BUS_READ_CHUNK];
	while (b->echo_left > 0) {
		size_t want = b->echo_left < sizeof chunk ? b->echo_left : sizeof chunk;
		long got = b->io.read(b->io.ctx, chunk, want);
		if (got < 0) {
			b->io_errors++;
			return (int)got;
		}
		if (got == 0)
			return DXL_OK;
		b->bytes_in += (uint64_t)got;
		long r = bus_echo_eat(b, chunk, (size_t)got);
		if (r < 0)
			return (int)r;
	}
	return DXL_OK;
}

/* ---- sending ------------------------------------------------------------------ */

/* Is there input to throw away before a request? Without a way to ask the
 * transport, assume so. */
static bool bus_needs_flush(const struct bus *b)
{
	if (b->line_dirty || b->io.pending_input == NULL)
		return true;
	return b->io.pending_input(b->io.ctx) != 0;
}

/* Stale input goes before a request; kept only while an echo is still due. */
static int bus_prepare(struct bus *b)
{
	if (b->pending)
		return DXL_E_BUSY;
	int r = bus_echo_drain(b);
	if (r == DXL_E_ECHO && b->io.flush_input)
		b->io.flush_input(b->io.ctx);
	if (r < 0)
		return r;
	if (b->echo_left == 0 && b->io.flush_input && bus_needs_flush(b)) {
		b->io.flush_input(b->io.ctx);
		b->line_dirty = false;
	}
	b->proto->parser_reset(&b->parser);
	b->echo_probe = 0;
	b->echo_probe_dead = false;
	return DXL_OK;
}

static int bus_send(struct bus *b, const uint8_t *pkt, size_t n)
{
	int r = b->io.write(b->io.ctx, pkt, n);
	if (r < 0) {
		b->io_errors++;
		return r;
	}
	b->bytes_out += n;
	bus_echo_push(b, pkt, n);
	return DXL_OK;
}

/* Sent: the request is pending until its reply or its deadline. */
static void bus_pend(struct bus *b, const uint8_t *pkt, size_t n, uint8_t id, uint8_t instr, int reply_params,
                     uint64_t now, uint32_t timeout_us)
{
	memcpy(b->req_buf, pkt, n);
	b->req_len = n;
	b->reply_held = false;
	b->pending = true;
	b->req_id = id;
	b->req_instr = instr;
	b->expect_params = reply_params;
	b->started_us = now;
	b->deadline_us = now + timeout_us;
}

/* Encoded (n bytes, or the encoder's negative status): flush, send; *now
 * gets the time the request went out. */
static int bus_send_request(struct bus *b, const uint8_t *pkt, int n, uint64_t *now)
{
	if (n < 0)
		return n;
	int r = bus_prepare(b);
	if (r < 0)
		return r;
	*now = b->io.now_us(b->io.ctx);
	return bus_send(b, pkt, (size_t)n);
}

/* One encoded request, at most one reply: pending until it comes, unless
 * none will (reply_params < 0, or broadcast: a broadcast is never answered
 * by one servo). */
static int bus_request(struct bus *b, const uint8_t *pkt, int n, uint8_t id, uint8_t instr, int reply_params)
{
	uint64_t now = 0;
	if (id == b->proto->broadcast_id)
		reply_params = -1;
	int r = bus_send_request(b, pkt, n, &now);
	if (r < 0 || reply_params < 0)
		return r;
	b->multi = NULL;
	bus_pend(b, pkt, (size_t)n, id, instr, reply_params, now,
	         bus_timeout_us(b, (size_t)n, b->proto->status_bytes_max((size_t)reply_params)));
	b->servo[id].transactions++;
	return DXL_OK;
}

int bus_begin(struct bus *b, uint8_t id, uint8_t instr, const uint8_t *params, size_t nparams,
              int reply_params)
{
	uint8_t pkt[BUS_MAX_PACKET];
	const struct dxl_proto *pr = b->proto;
	int replies = pr->instr_replies(instr);
	if (reply_params > (int)pr->max_read_len || replies == DXL_E_ARG)
		return DXL_E_ARG;
	if (replies < 0)
		reply_params = -1;
	int n = pr->encode_instruction(pkt, sizeof pkt, id, instr, params, nparams);
	return bus_request(b, pkt, n, id, instr, reply_params);
}

int bus_read_begin(struct bus *b, uint8_t id, uint16_t addr, uint16_t len)
{
	uint8_t pkt[BUS_MAX_PACKET];
	const struct dxl_proto *pr = b->proto;
	if (id > pr->max_id || len == 0 || len > pr->max_read_len)
		return DXL_E_ARG;
	return bus_request(b, pkt, pr->encode_read(pkt, sizeof pkt, id, addr, len), id, DXL_INST_READ, len);
}

int bus_write_begin(struct bus *b, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply)
{
	uint8_t pkt[BUS_MAX_PACKET];
	const struct dxl_proto *pr = b->proto;
	if (data == NULL || n == 0 || n + pr->addr_bytes > pr->max_params)
		return DXL_E_ARG;
	return bus_request(b, pkt, pr->encode_write(pkt, sizeof pkt, id, addr, data, n), id, DXL_INST_WRITE,
	                   expect_reply ? 0 : -1);
}

int bus_reboot_begin(struct bus *b, uint8_t id, bool expect_reply)
{
	uint8_t pkt[BUS_MAX_PACKET];
	const struct dxl_proto *pr = b->proto;
	if (!dxl_proto_can(pr, DXL_CAP_REBOOT) || pr->encode_reboot == NULL)
		return DXL_E_UNSUPPORTED;
	return bus_request(b, pkt, pr->encode_reboot(pkt, sizeof pkt, id), id, DXL_INST_REBOOT, expect_reply ? 0 : -1);
}

int bus_send_raw(struct bus *b, const uint8_t *pkt, size_t n)
{
	if (pkt == NULL || n == 0 || n > b->proto->max_packet)
		return DXL_E_ARG;
	int r = bus_prepare(b);
	if (r < 0)
		return r;
	return bus_send(b, pkt, n);
}

/* ---- receiving ------------------------------------------------------------------ */

/* Whether the parser takes a fast read's one status packet (only while one
 * is awaited: dxl2_parser_expect_fast says why). */
static void bus_parser_fast(struct bus *b, bool on)
{
	if (b->proto != NULL && b->proto->parser_expect_fast != NULL)
		b->proto->parser_expect_fast(&b->parser, on);
}

static void bus_finish(struct bus *b)
{
	bus_parser_fast(b, false);
	b->pending = false;
	b->expect_params = -1;
	b->reply_held = false;
	b->multi = NULL;
}

static void bus_frame_copy(struct dxl_frame *dst, const struct dxl_frame *src)
{
	if (dst == src)
		return;
	dst->id = src->id;
	dst->instr = src->instr;
	dst->err = src->err;
	dst->nparams = src->nparams;
	dst->wire_bytes = src->wire_bytes;
	memcpy(dst->params, src->params, src->nparams);
}

/* A reply matched its request: counted for its servo, its error byte (1.0)
 * or ERR field (2.0) kept as data. */
static void bus_count_reply(struct bus *b, struct bus_servo_stats *st, uint64_t now, uint8_t err)
{
	uint32_t rtt = (uint32_t)(now - b->started_us);
	st->replies++;
	st->rtt_last_us = rtt;
	if (rtt > st->rtt_max_us)
		st->rtt_max_us = rtt;
	st->rtt_sum_us += rtt;
	st->last_errbits = err;
	st->errbits_seen |= err;
	if (err)
		st->error_replies++;
	if (err & b->proto->err_alert)
		st->alerts++;
}

/* Is this packet byte for byte the request we sent (read as a status)? */
static bool bus_is_own_request(const struct bus *b, const struct dxl_frame *pkt)
{
	uint8_t again[BUS_MAX_PACKET];
	if (pkt->wire_bytes != b->req_len)
		return false;
	int n = b->proto->encode_status(again, sizeof again, pkt->id, pkt->err, pkt->params, pkt->nparams);
	return n == (int)b->req_len && memcmp(again, b->req_buf, b->req_len) == 0;
}

/* The one reply of a single request, checked against it (libmodbus's
 * check_confirmation): same ID, the expected parameter count. */
static int bus_match(struct bus *b, const struct dxl_frame *pkt, uint64_t now, struct dxl_packet *reply)
{
	struct bus_servo_stats *st = &b->servo[b->req_id];
	int expect_params = b->expect_params;
	bus_finish(b);
	if (pkt->id != b->req_id) {
		st->wrong_id++;
		b->line_dirty = true;
		return DXL_E_WRONG_ID;
	}
	if (pkt->nparams != expect_params) {
		st->wrong_length++;
		/* a late reply to an earlier request: this one's may follow */
		b->line_dirty = true;
		return DXL_E_WRONG_LENGTH;
	}
	bus_count_reply(b, st, now, pkt->err);
	bus_frame_copy(&b->reply, pkt);
	if (reply) {
		reply->id = pkt->id;
		reply->code = pkt->err;
		reply->nparams = pkt->nparams <= DXL_MAX_PARAMS ? (uint8_t)pkt->nparams : 0;
		memcpy(reply->params, pkt->params, reply->nparams);
	}
	return DXL_OK;
}

/* ---- multi-reply requests: SYNC_READ, BULK_READ, broadcast PING ------------------ */

/* A multi-reply slot still waiting for its servo. DXL_E_WRONG_ID marks one
 * that was expected when a packet from a servo not asked came. */
static bool bus_slot_open(int status)
{
	return status == DXL_E_TIMEOUT || status == DXL_E_WRONG_ID;
}

/* The slot the bus expects next: servos answer in request order. */
static size_t bus_next_open(const struct bus_multi *m)
{
	size_t i = 0;
	while (i < m->n && !bus_slot_open(m->status[i]))
		i++;
	return i;
}

static bool bus_multi_settled(const struct bus_multi *m)
{
	return bus_next_open(m) == m->n;
}

/* DXL_OK when every slot has its data, else the first failed slot's status. */
static int bus_multi_outcome(const struct bus_multi *m)
{
	for (size_t i = 0; i < m->n; i++)
		if (m->status[i] != DXL_OK)
			return m->status[i];
	return DXL_OK;
}

static void bus_slot_fill(struct bus *b, size_t slot, const struct dxl_frame *pkt, uint64_t now)
{
	struct bus_multi *m = b->multi;
	memcpy(m->data + m->off[slot], pkt->params, m->len[slot]);
	m->err[slot] = pkt->err;
	m->status[slot] = DXL_OK;
	m->answered++;
	bus_count_reply(b, &b->servo[pkt->id], now, pkt->err);
}

/* A broadcast PING's reply: a new slot for each servo, once. */
static void bus_ping_all_frame(struct bus *b, const struct dxl_frame *pkt, uint64_t now)
{
	struct bus_multi *m = b->multi;
	struct bus_servo_stats *st = &b->servo[pkt->id];
	size_t nparams = b->proto->ping_reply_params;
	for (size_t i = 0; i < m->n; i++) {
		if (m->id[i] == pkt->id) {
			/* two servos with one ID, or one answering twice */
			st->wrong_id++;
			b->line_dirty = true;
			return;
		}
	}
	if (pkt->nparams != nparams) {
		st->wrong_length++;
		b->line_dirty = true;
		return;
	}
	size_t slot = m->n;
	if (slot >= BUS_MULTI_MAX || (slot + 1) * nparams > m->cap) {
		b->stray_packets++;
		return;
	}
	m->id[slot] = pkt->id;
	m->len[slot] = (uint16_t)nparams;
	m->off[slot] = (uint32_t)(slot * nparams);
	m->n++;
	st->transactions++;
	bus_slot_fill(b, slot, pkt, now);
}

/* One status packet of a SYNC_READ / BULK_READ, checked against the request. */
static void bus_multi_frame(struct bus *b, const struct dxl_frame *pkt, uint64_t now)
{
	struct bus_multi *m = b->multi;
	size_t slot = 0;
	int r = dxl2_multi_read_take(&m->track, pkt->id, pkt->nparams, &slot);
	if (r == DXL_OK) {
		bus_slot_fill(b, slot, pkt, now);
		return;
	}
	b->line_dirty = true;
	if (r == DXL_E_WRONG_LENGTH) {
		/* its servo answered, with the wrong size: waiting cannot mend it */
		b->servo[pkt->id].wrong_length++;
		for (size_t i = 0; i < m->n; i++)
			if (m->id[i] == pkt->id && bus_slot_open(m->status[i]))
				m->status[i] = DXL_E_WRONG_LENGTH;
		return;
	}
	size_t next = bus_next_open(m);
	if (next < m->n) {
		b->servo[m->id[next]].wrong_id++;
		m->status[next] = DXL_E_WRONG_ID;
	} else {
		b->stray_packets++;
	}
}

/* A slot that failed with the fast read's packet; counted against its servo
 * when its own part was at fault (culprit), not when an earlier one was. */
static void bus_fast_fail(struct bus *b, size_t slot, int why, bool culprit)
{
	struct bus_multi *m = b->multi;
	struct bus_servo_stats *st = &b->servo[m->id[slot]];
	m->status[slot] = why;
	b->line_dirty = true;
	if (!culprit)
		return;
	if (why == DXL_E_CHECKSUM)
		st->checksum_errors++;
	else if (why == DXL_E_WRONG_LENGTH)
		st->wrong_length++;
	else
		st->wrong_id++;
}

/* The one status packet of a Fast Sync/Bulk Read: every slot at once. A
 * status from a single servo is not part of it (a stray). Returns whether
 * the packet was the fast read's. */
static bool bus_fast_frame(struct bus *b, const struct dxl_frame *pkt, uint64_t now)
{
	struct bus_multi *m = b->multi;
	struct dxl2_packet whole;
	struct dxl2_fast_part parts[BUS_MULTI_MAX];
	size_t good = 0;
	if (pkt->id != b->proto->broadcast_id) {
		b->stray_packets++;
		b->line_dirty = true;
		return false;
	}
	dxl_frame_to_packet2(pkt, &whole);
	int r = dxl2_fast_status_split(&whole, &m->track, parts, &good);
	for (size_t i = 0; i < m->n; i++) {
		if (i >= good) {
			/* a part's failure is the packet's from there on: the
			 * parts after it cannot be placed with certainty */
			bus_fast_fail(b, i, r, i == good || r == DXL_E_WRONG_LENGTH);
			continue;
		}
		memcpy(m->data + m->off[i], parts[i].data, m->len[i]);
		m->err[i] = parts[i].err;
		m->status[i] = DXL_OK;
		m->answered++;
		bus_count_reply(b, &b->servo[m->id[i]], now, parts[i].err);
	}
	return true;
}

/* ---- feeding the parser ---------------------------------------------------------- */

/* A reply was damaged (or bytes were dropped) while waiting. */
static int bus_damage(struct bus *b, int why)
{
	size_t next = b->multi != NULL ? bus_next_open(b->multi) : 0;
	uint8_t id = b->req_id;
	if (b->multi != NULL) {
		if (next >= b->multi->n)
			return BUS_PENDING;   /* nobody left to blame: the parser counted it */
		id = b->multi->id[next];
	}
	struct bus_servo_stats *st = &b->servo[id];
	if (why != DXL_E_CHECKSUM) {
		st->resyncs++;
		if (why == DXL_E_STUFFING)
			st->stuffing_errors++;
		return BUS_PENDING;
	}
	/* the reply is damaged; waiting longer cannot repair it */
	st->checksum_errors++;
	b->line_dirty = true;
	if (b->multi != NULL && b->multi->fast) {
		/* the one packet that held every slot */
		for (size_t i = 0; i < b->multi->n; i++)
			if (bus_slot_open(b->multi->status[i]))
				b->multi->status[i] = DXL_E_CHECKSUM;
		bus_finish(b);
		return DXL_E_CHECKSUM;
	}
	if (b->multi != NULL) {
		/* the servo expected next: the others may still answer */
		b->multi->status[next] = DXL_E_CHECKSUM;
		return BUS_PENDING;
	}
	bus_finish(b);
	return DXL_E_CHECKSUM;
}

/* A whole packet arrived: the reply, one of several, or a stray. */
static int bus_frame(struct bus *b, const struct dxl_frame *pkt, uint64_t now, struct dxl_packet *reply)
{
	if (!b->pending) {
		b->stray_packets++;
		b->line_dirty = true;
		return BUS_PENDING;
	}
	if (b->multi == NULL) {
		if (b->proto->echo_reads_as_status && !b->echo && !b->reply_held && bus_is_own_request(b, pkt)) {
			b->reply_held = true;
			bus_frame_copy(&b->reply, pkt);
			return BUS_PENDING;
		}
		if (b->reply_held)
			b->unexpected_echoes++;
		return bus_match(b, pkt, now, reply);
	}
	if (b->multi->fast) {
		if (!bus_fast_frame(b, pkt, now))
			return BUS_PENDING;
		int outcome = bus_multi_outcome(b->multi);
		bus_finish(b);
		return outcome;
	}
	if (b->multi->ping_all)
		bus_ping_all_frame(b, pkt, now);
	else
		bus_multi_frame(b, pkt, now);
	if (!b->multi->ping_all && bus_multi_settled(b->multi)) {
		int outcome = bus_multi_outcome(b->multi);
		bus_finish(b);
		return outcome;
	}
	return BUS_PENDING;
}

/* Feed received bytes to the parser. Returns BUS_PENDING while the reply is
 * incomplete, else the transaction's outcome; packets beyond the reply are
 * counted as strays. */
static int bus_feed(struct bus *b, const uint8_t *data, size_t n, uint64_t now, struct dxl_packet *reply)
{
	int outcome = BUS_PENDING;
	struct dxl_frame pkt;
	size_t off = 0;
	for (;;) {
		size_t used = 0;
		int r = b->proto->parser_feed(&b->parser, data + off, n - off, &used, &pkt);
		off += used;
		if (r == DXL_NEED_MORE)
			break;
		int o = r == DXL_FRAME ? bus_frame(b, &pkt, now, reply) : b->pending ? bus_damage(b, r) : BUS_PENDING;
		if (o != BUS_PENDING)
			outcome = o;
	}
	return outcome;
}

/* With echo off, our own request read back first means the wiring echoes.
 * Where an instruction never parses as a status (2.0), nothing is mistaken
 * for a reply: the bytes that match the request so far are held back from
 * the parser, and dropped when the whole request came back. (Where it does,
 * 1.0, bus_frame holds the whole packet instead.) */
static int bus_consume(struct bus *b, const uint8_t *data, size_t n, uint64_t now, struct dxl_packet *reply)
{
	size_t i = 0;
	if (b->echo || b->proto->echo_reads_as_status || b->echo_probe_dead || !b->pending)
		return bus_feed(b, data, n, now, reply);
	while (i < n && b->echo_probe < b->req_len && data[i] == b->req_buf[b->echo_probe]) {
		b->echo_probe++;
		i++;
	}
	if (b->echo_probe == b->req_len) {
		b->unexpected_echoes++;
		b->echo_probe_dead = true;
		return bus_feed(b, data + i, n - i, now, reply);
	}
	if (i == n)
		return BUS_PENDING;   /* all of it could still be the echo */
	/* not our request: what was held back goes to the parser first */
	b->echo_probe_dead = true;
	int held = bus_feed(b, b->req_buf, b->echo_probe, now, reply);
	int rest = bus_feed(b, data + i, n - i, now, reply);
	return held != BUS_PENDING ? held : rest;
}

/* The deadline of a multi-reply request: the servos that did not answer are
 * timeouts, the replies that came stay delivered. */
static int bus_multi_deadline(struct bus *b)
{
	struct bus_multi *m = b->multi;
	for (size_t i = 0; i < m->n; i++)
		if (m->status[i] == DXL_E_TIMEOUT)
			b->servo[m->id[i]].timeouts++;
	int outcome = m->ping_all ? DXL_OK : bus_multi_outcome(m);
	if (!m->ping_all && m->answered < m->n)
		b->line_dirty = true;   /* a late reply may still come */
	bus_finish(b);
	b->proto->parser_reset(&b->parser);
	bus_echo_clear(b);
	return outcome;
}

const struct dxl_frame *bus_reply(const struct bus *b)
{
	return &b->reply;
}

const uint8_t *bus_multi_data(const struct bus_multi *m, size_t slot)
{
	if (m == NULL || slot >= m->n || m->status[slot] != DXL_OK)
		return NULL;
	return m->data + m->off[slot];
}

size_t bus_multi_failed(const struct bus_multi *m, uint8_t *ids, size_t cap)
{
	size_t failed = 0;
	for (size_t i = 0; m != NULL && i < m->n; i++) {
		if (m->status[i] == DXL_OK)
			continue;
		if (ids != NULL && failed < cap)
			ids[failed] = m->id[i];
		failed++;
	}
	return failed;
}

/* ---- beginning a multi-reply request ------------------------------------------------ */

/* Slots from the tracker; DXL_E_BUFFER when their bytes exceed m->cap. */
static int bus_multi_layout(struct bus_multi *m)
{
	size_t off = 0;
	m->n = m->track.n;
	m->answered = 0;
	m->ping_all = false;
	m->fast = false;
	for (size_t i = 0; i < m->n; i++) {
		m->id[i] = m->track.ids[i];
		m->len[i] = m->track.len[i];
		m->off[i] = (uint32_t)off;
		m->status[i] = DXL_E_TIMEOUT;
		m->err[i] = 0;
		off += m->len[i];
	}
	return m->data != NULL && off <= m->cap ? DXL_OK : DXL_E_BUFFER;
}

/* Send the request the protocol's encoder wrote (n bytes or its status). */
static int bus_multi_send(struct bus *b, const uint8_t *pkt, int n, struct bus_multi *m, uint8_t instr)
{
	uint64_t now = 0;
	int r = bus_send_request(b, pkt, n, &now);
	if (r < 0)
		return r;
	uint32_t timeout = m->ping_all ? bus_ping_all_timeout_us(b, (size_t)n)
	                   : m->fast   ? bus_fast_timeout_us(b, (size_t)n, m->len, m->n)
	                               : bus_multi_timeout_us(b, (size_t)n, m->len, m->n);
	bus_pend(b, pkt, (size_t)n, b->proto->broadcast_id, instr, 0, now, timeout);
	b->multi = m;
	bus_parser_fast(b, m->fast);
	for (size_t i = 0; i < m->n; i++)
		b->servo[m->id[i]].transactions++;
	return DXL_OK;
}

/* Before encoding: the protocol can, and the bus is free. */
static int bus_multi_ready(const struct bus *b, uint32_t cap)
{
	if (!dxl_proto_can(b->proto, cap))
		return DXL_E_UNSUPPORTED;
	return b->pending ? DXL_E_BUSY : DXL_OK;
}

/* A SYNC_READ, plain or fast (one status packet from every servo): the same
 * tracking and layout; the capability, encoder and instruction differ. */
static int bus_sync_begin(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n,
                          struct bus_multi *m, bool fast)
{
	uint8_t pkt[BUS_MAX_PACKET];
	if (m == NULL || dxl2_multi_read_sync(&m->track, len, ids, n) != DXL_OK)
		return DXL_E_ARG;
	int r = bus_multi_layout(m);
	if (r == DXL_OK)
		r = bus_multi_ready(b, fast ? DXL_CAP_FAST_READ : DXL_CAP_SYNC_READ);
	if (r < 0)
		return r;
	if (fast)
		m->fast = true;
	int len_pkt = fast ? b->proto->encode_fast_sync_read(pkt, sizeof pkt, addr, len, ids, n)
	                      : b->proto->encode_sync_read(pkt, sizeof pkt, addr, len, ids, n);
	return bus_multi_send(b, pkt, len_pkt, m, fast ? DXL2_INST_FAST_SYNC_READ : DXL2_INST_SYNC_READ);
}

/* A BULK_READ, plain or fast, as bus_sync_begin. */
static int bus_bulk_begin(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m, bool fast)
{
	uint8_t pkt[BUS_MAX_PACKET];
	struct dxl2_bulk_item asked[DXL2_MULTI_MAX];
	if (m == NULL || items == NULL || n == 0 || n > DXL2_MULTI_MAX)
		return DXL_E_ARG;
	for (size_t i = 0; i < n; i++)
		asked[i] = (struct dxl2_bulk_item){ items[i].id, items[i].addr, items[i].len, NULL };
	if (dxl2_multi_read_bulk(&m->track, asked, n) != DXL_OK)
		return DXL_E_ARG;
	int r = bus_multi_layout(m);
	if (r == DXL_OK)
		r = bus_multi_ready(b, fast ? DXL_CAP_FAST_READ : DXL_CAP_BULK_READ);
	if (r < 0)
		return r;
	if (fast)
		m->fast = true;
	int len_pkt = fast ? b->proto->encode_fast_bulk_read(pkt, sizeof pkt, items, n)
	                      : b->proto->encode_bulk_read(pkt, sizeof pkt, items, n);
	return bus_multi_send(b, pkt, len_pkt, m, fast ? DXL2_INST_FAST_BULK_READ : DXL2_INST_BULK_READ);
}

int bus_sync_read_begin(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n,
                        struct bus_multi *m)
{
	return bus_sync_begin(b, addr, len, ids, n, m, false);
}

int bus_bulk_read_begin(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m)
{
	return bus_bulk_begin(b, items, n, m, false);
}

int bus_fast_sync_read_begin(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n,
                             struct bus_multi *m)
{
	return bus_sync_begin(b, addr, len, ids, n, m, true);
}

int bus_fast_bulk_read_begin(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m)
{
	return bus_bulk_begin(b, items, n, m, true);
}

int bus_ping_all_begin(struct bus *b, struct bus_multi *m)
{
	uint8_t pkt[BUS_MAX_PACKET];
	if (m == NULL || m->data == NULL)
		return DXL_E_ARG;
	m->n = 0;
	m->answered = 0;
	m->ping_all = true;
	m->fast = false;
	int r = bus_multi_ready(b, DXL_CAP_BROADCAST_PING);
	if (r < 0)
		return r;
	return bus_multi_send(b, pkt, b->proto->encode_ping(pkt, sizeof pkt, b->proto->broadcast_id), m,
	                      DXL_INST_PING);
}

/* ---- driving a transaction ---------------------------------------------------------- */

int bus_step(struct bus *b, struct dxl_packet *reply)
{
	if (!b->pending)
		return DXL_OK;
	uint64_t now = b->io.now_us(b->io.ctx);
	uint8_t chunk[BUS_READ_CHUNK];
	int outcome = BUS_PENDING;
	for (;;) {
		long got = b->io.read(b->io.ctx, chunk, sizeof chunk);
		if (got < 0) {
			b->io_errors++;
			bus_abort(b);
			return (int)got;
		}
		if (got == 0)
			break;
		b->bytes_in += (uint64_t)got;
		size_t off = 0;
		long echoed = bus_echo_eat(b, chunk, (size_t)got);
		if (echoed < 0) {
			bus_abort(b);
			return (int)echoed;
		}
		off = (size_t)echoed;
		int r = bus_consume(b, chunk + off, (size_t)got - off, now, reply);
		if (r != BUS_PENDING)
			outcome = r;
		/* A short read took what there was. Reading again only to be told
		 * "nothing" makes a tty wait for the kernel's buffer worker, which a
		 * busy machine schedules late: the next poll() says when more came. */
		if ((size_t)got < sizeof chunk)
			break;
	}
	if (outcome != BUS_PENDING)
		return outcome;
	if (now >= b->deadline_us && b->multi != NULL)
		return bus_multi_deadline(b);
	if (now >= b->deadline_us && b->reply_held) {
		/* nothing followed the packet that looked like our echo: it was the
		 * reply, held in b->reply */
		return bus_match(b, &b->reply, now, reply);
	}
	if (now >= b->deadline_us) {
		b->servo[b->req_id].timeouts++;
		bus_abort(b);
		return DXL_E_TIMEOUT;
	}
	return BUS_PENDING;
}

uint64_t bus_deadline_us(const struct bus *b)
{
	return b->deadline_us;
}

bool bus_is_pending(const struct bus *b)
{
	return b->pending;
}

void bus_abort(struct bus *b)
{
	if (b->pending)
		b->line_dirty = true;   /* its reply may still come */
	bus_finish(b);
	/* whatever was half-read belongs to the abandoned request */
	bus_echo_clear(b);
	/* a bus never given its protocol (a port closed before bus_init: the
	 * daemon refusing a wiring) has no parser to reset */
	if (b->proto != NULL)
		b->proto->parser_reset(&b->parser);
}

/* ---- blocking calls --------------------------------------------------------------- */

int bus_wait_done(struct bus *b, struct dxl_packet *reply)
{
	for (;;) {
		int r = bus_step(b, reply);
		if (r != BUS_PENDING)
			return r;
		uint64_t now = b->io.now_us(b->io.ctx);
		uint64_t left = b->deadline_us > now ? b->deadline_us - now : 0;
		int w = b->io.wait(b->io.ctx, (uint32_t)left);
		if (w < 0) {
			b->io_errors++;
			bus_abort(b);
			return w;
		}
	}
}

int bus_settle(struct bus *b, uint32_t quiet_us, uint32_t max_us)
{
	if (b->pending)
		return DXL_E_BUSY;
	uint64_t start = b->io.now_us(b->io.ctx), last = start;
	long dropped = 0;
	for (;;) {
		uint8_t chunk[64];
		long got;
		while ((got = b->io.read(b->io.ctx, chunk, sizeof chunk)) > 0) {
			dropped += got;
			b->bytes_in += (uint64_t)got;
			last = b->io.now_us(b->io.ctx);
		}
		if (got < 0) {
			b->io_errors++;
			return (int)got;
		}
		uint64_t now = b->io.now_us(b->io.ctx);
		if (now - last >= quiet_us) {
			b->line_dirty = false;
			break;
		}
		if (now - start >= max_us) {
			b->line_dirty = true;   /* still talking: the next request flushes */
			break;
		}
		uint64_t until_quiet = last + quiet_us - now, until_max = start + max_us - now;
		int w = b->io.wait(b->io.ctx, (uint32_t)(until_quiet < until_max ? until_quiet : until_max));
		if (w < 0) {
			b->io_errors++;
			return w;
		}
	}
	bus_echo_clear(b);
	b->proto->parser_reset(&b->parser);
	return dropped > INT32_MAX ? INT32_MAX : (int)dropped;
}

/* Feed late bytes to the parser: the first whole packet's ID, or -1. */
static int bus_late_feed(struct bus *b, const uint8_t *data, size_t n)
{
	size_t off = 0;
	for (;;) {
		struct dxl_frame pkt;
		size_t used = 0;
		int r = b->proto->parser_feed(&b->parser, data + off, n - off, &used, &pkt);
		off += used;
		if (r == DXL_FRAME)
			return pkt.id;
		if (r == DXL_NEED_MORE)
			return -1;
	}
}

int bus_listen_late(struct bus *b, uint32_t max_us, struct bus_late *out)
{
	if (b->pending)
		return DXL_E_BUSY;
	*out = (struct bus_late){ .id = -1 };
	out->waited_us = b->deadline_us > b->started_us ? (uint32_t)(b->deadline_us - b->started_us) : 0;
	b->proto->parser_reset(&b->parser);
	uint64_t start = b->io.now_us(b->io.ctx);
	int rc = DXL_OK;
	while (out->id < 0) {
		uint8_t chunk[BUS_READ_CHUNK];
		long got = b->io.read(b->io.ctx, chunk, sizeof chunk);
		uint64_t now = b->io.now_us(b->io.ctx);
		if (got < 0) {
			b->io_errors++;
			rc = (int)got;
			break;
		}
		if (got > 0) {
			if (out->bytes == 0)
				out->after_us = now > b->deadline_us ? (uint32_t)(now - b->deadline_us) : 0;
			out->bytes += got;
			b->bytes_in += (uint64_t)got;
			out->id = bus_late_feed(b, chunk, (size_t)got);
			continue;
		}
		if (now - start >= max_us)
			break;
		int w = b->io.wait(b->io.ctx, (uint32_t)(start + max_us - now));
		if (w < 0) {
			b->io_errors++;
			rc = w;
			break;
		}
	}
	b->line_dirty = true;
	b->proto->parser_reset(&b->parser);
	return rc;
}

/* One encoded request (n bytes, or the encoder's negative status), its
 * reply if one is expected, and the reply's error byte / ERR field. The
 * reply stays in the bus (bus_reply) for the caller to copy out. */
static int bus_transact(struct bus *b, const uint8_t *pkt, int n, uint8_t id, uint8_t instr, int reply_params,
                        uint8_t *err)
{
	if (err)
		*err = 0;
	int r = bus_request(b, pkt, n, id, instr, reply_params);
	if (r < 0 || !b->pending)
		return r;
	r = bus_wait_done(b, NULL);
	if (r == DXL_OK && err)
		*err = b->reply.err;
	return r;
}

static int bus_ping_params(struct bus *b, uint8_t id, uint8_t *err)
{
	uint8_t pkt[BUS_MAX_PACKET];
	const struct dxl_proto *pr = b->proto;
	/* where every servo answers a broadcast PING in turn, bus_ping_all */
	if (id > pr->max_id && dxl_proto_can(pr, DXL_CAP_BROADCAST_PING))
		return DXL_E_ARG;
	return bus_transact(b, pkt, pr->encode_ping(pkt, sizeof pkt, id), id, DXL_INST_PING, pr->ping_reply_params,
	                    err);
}

int bus_ping(struct bus *b, uint8_t id, uint8_t *err)
{
	return bus_ping_params(b, id, err);
}

int bus_ping_model(struct bus *b, uint8_t id, uint16_t *model, uint8_t *firmware, uint8_t *err)
{
	if (err)
		*err = 0;
	if (id > b->proto->max_id)
		return DXL_E_ARG;   /* broadcast: bus_ping_all */
	if (!dxl_proto_can(b->proto, DXL_CAP_PING_MODEL))
		return DXL_E_UNSUPPORTED;
	int r = bus_ping_params(b, id, err);
	if (r != DXL_OK)
		return r;
	if (model)
		*model = dxl_get_u16(b->reply.params);
	if (firmware)
		*firmware = b->reply.params[2];
	return DXL_OK;
}

int bus_ping_all(struct bus *b, struct bus_found *found, size_t cap, size_t *n)
{
	uint8_t data[BUS_MULTI_MAX * 3];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	*n = 0;
	int r = bus_ping_all_begin(b, &m);
	if (r == DXL_OK)
		r = bus_wait_done(b, NULL);
	for (size_t i = 0; i < m.n && *n < cap; i++) {
		const uint8_t *p = bus_multi_data(&m, i);
		if (p == NULL)
			continue;
		found[(*n)++] = (struct bus_found){ m.id[i], dxl_get_u16(p), p[2], m.err[i] };
	}
	return r;
}

int bus_read(struct bus *b, uint8_t id, uint16_t addr, uint16_t len, uint8_t *out, uint8_t *err)
{
	uint8_t pkt[BUS_MAX_PACKET];
	const struct dxl_proto *pr = b->proto;
	if (err)
		*err = 0;
	if (id > pr->max_id || len == 0 || len > pr->max_read_len || out == NULL)
		return DXL_E_ARG;
	int r = bus_transact(b, pkt, pr->encode_read(pkt, sizeof pkt, id, addr, len), id, DXL_INST_READ, len, err);
	if (r == DXL_OK)
		memcpy(out, b->reply.params, len);
	return r;
}

int bus_read_u8(struct bus *b, uint8_t id, uint16_t addr, uint8_t *v, uint8_t *err)
{
	return bus_read(b, id, addr, 1, v, err);
}

int bus_read_u16(struct bus *b, uint8_t id, uint16_t addr, uint16_t *v, uint8_t *err)
{
	uint8_t raw[2];
	if (v == NULL)
		return DXL_E_ARG;
	int r = bus_read(b, id, addr, 2, raw, err);
	if (r == DXL_OK)
		*v = dxl_get_u16(raw);
	return r;
}

int bus_read_u32(struct bus *b, uint8_t id, uint16_t addr, uint32_t *v, uint8_t *err)
{
	uint8_t raw[4];
	if (v == NULL)
		return DXL_E_ARG;
	int r = bus_read(b, id, addr, 4, raw, err);
	if (r == DXL_OK)
		*v = dxl2_get_u32(raw);
	return r;
}

/* WRITE and REG_WRITE: an address and the data. */
static int bus_addr_data(struct bus *b, uint8_t id, bool registered, uint16_t addr, const uint8_t *data, size_t n,
                         bool expect_reply, uint8_t *err)
{
	uint8_t pkt[BUS_MAX_PACKET];
	const struct dxl_proto *pr = b->proto;
	if (err)
		*err = 0;
	if (data == NULL || n == 0 || n + pr->addr_bytes > pr->max_params)
		return DXL_E_ARG;
	int len = registered ? pr->encode_reg_write(pkt, sizeof pkt, id, addr, data, n)
	                     : pr->encode_write(pkt, sizeof pkt, id, addr, data, n);
	return bus_transact(b, pkt, len, id, registered ? DXL_INST_REG_WRITE : DXL_INST_WRITE, expect_reply ? 0 : -1,
	                    err);
}

int bus_write(struct bus *b, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply,
              uint8_t *err)
{
	return bus_addr_data(b, id, false, addr, data, n, expect_reply, err);
}

int bus_write_u8(struct bus *b, uint8_t id, uint16_t addr, uint8_t v, uint8_t *err)
{
	return bus_write(b, id, addr, &v, 1, true, err);
}

int bus_write_u16(struct bus *b, uint8_t id, uint16_t addr, uint16_t v, uint8_t *err)
{
	uint8_t raw[2];
	dxl_put_u16(raw, v);
	return bus_write(b, id, addr, raw, 2, true, err);
}

int bus_write_u32(struct bus *b, uint8_t id, uint16_t addr, uint32_t v, uint8_t *err)
{
	uint8_t raw[4];
	dxl2_put_u32(raw, v);
	return bus_write(b, id, addr, raw, 4, true, err);
}

int bus_reg_write(struct bus *b, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply,
                  uint8_t *err)
{
	return bus_addr_data(b, id, true, addr, data, n, expect_reply, err);
}

int bus_action(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err)
{
	uint8_t pkt[BUS_MAX_PACKET];
	return bus_transact(b, pkt, b->proto->encode_action(pkt, sizeof pkt, id), id, DXL_INST_ACTION,
	                    expect_reply ? 0 : -1, err);
}

int bus_factory_reset(struct bus *b, uint8_t id, uint8_t option, bool expect_reply, uint8_t *err)
{
	uint8_t pkt[BUS_MAX_PACKET];
	return bus_transact(b, pkt, b->proto->encode_factory_reset(pkt, sizeof pkt, id, option), id,
	                    DXL_INST_FACTORY_RESET, expect_reply ? 0 : -1, err);
}

/* An instruction the protocol may not have: (cap) or DXL_E_UNSUPPORTED. */
static int bus_optional(struct bus *b, uint32_t cap, int (*encode)(uint8_t *, size_t, uint8_t), uint8_t id,
                        uint8_t instr, bool expect_reply, uint8_t *err)
{
	uint8_t pkt[BUS_MAX_PACKET];
	if (err)
		*err = 0;
	if (!dxl_proto_can(b->proto, cap) || encode == NULL)
		return DXL_E_UNSUPPORTED;
	return bus_transact(b, pkt, encode(pkt, sizeof pkt, id), id, instr, expect_reply ? 0 : -1, err);
}

int bus_reboot(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err)
{
	return bus_optional(b, DXL_CAP_REBOOT, b->proto->encode_reboot, id, DXL_INST_REBOOT, expect_reply, err);
}

int bus_clear_multi_turn(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err)
{
	return bus_optional(b, DXL_CAP_CLEAR, b->proto->encode_clear_multi_turn, id, DXL2_INST_CLEAR, expect_reply,
	                    err);
}

int bus_sync_write(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, const uint8_t *data, size_t n)
{
	uint8_t pkt[BUS_MAX_PACKET];
	int r = b->proto->encode_sync_write(pkt, sizeof pkt, addr, len, ids, data, n);
	return r < 0 ? r : bus_send_raw(b, pkt, (size_t)r);
}

int bus_bulk_write(struct bus *b, const struct dxl_item *items, size_t n)
{
	uint8_t pkt[BUS_MAX_PACKET];
	if (!dxl_proto_can(b->proto, DXL_CAP_BULK_WRITE))
		return DXL_E_UNSUPPORTED;
	int r = b->proto->encode_bulk_write(pkt, sizeof pkt, items, n);
	return r < 0 ? r : bus_send_raw(b, pkt, (size_t)r);
}

static int bus_multi_wait(struct bus *b, int begun)
{
	if (begun < 0)
		return begun;
	return bus_wait_done(b, NULL);
}

int bus_sync_read(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n, struct bus_multi *m)
{
	return bus_multi_wait(b, bus_sync_read_begin(b, addr, len, ids, n, m));
}

int bus_bulk_read(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m)
{
	return bus_multi_wait(b, bus_bulk_read_begin(b, items, n, m));
}

int bus_fast_sync_read(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n,
                       struct bus_multi *m)
{
	return bus_multi_wait(b, bus_fast_sync_read_begin(b, addr, len, ids, n, m));
}

int bus_fast_bulk_read(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m)
{
	return bus_multi_wait(b, bus_fast_bulk_read_begin(b, items, n, m));
}

int bus_reply_lateness(struct bus *b, uint8_t id, uint32_t return_delay_us, unsigned n, struct bus_lateness *out)
{
	uint32_t late[BUS_LATENESS_MAX];
	uint32_t floor_us = bus_wire_time_us(b, b->proto->ping_round_trip_bytes) + return_delay_us;
	int r = DXL_E_ARG;

	memset(out, 0, sizeof *out);
	if (n > BUS_LATENESS_MAX)
		n = BUS_LATENESS_MAX;
	for (unsigned i = 0; i < n; i++) {
		uint8_t eb;
		r = bus_ping(b, id, &eb);
		out->pings++;
		if (r == DXL_E_DISCONNECTED || r == DXL_E_IO)
			break;
		if (r != DXL_OK)
			continue;
		uint32_t rtt = b->servo[id].rtt_last_us;
		uint32_t v = rtt > floor_us ? rtt - floor_us : 0;
		/* insertion sort: a few dozen values */
		size_t k = out->replies++;
		while (k > 0 && late[k - 1] > v) {
			late[k] = late[k - 1];
			k--;
		}
		late[k] = v;
	}
	if (out->replies == 0)
		return r == DXL_OK ? DXL_E_TIMEOUT : r;
	out->min_us = late[0];
	out->max_us = late[out->replies - 1];
	/* the lower median: one slow wake-up in an even count does not move it */
	out->median_us = late[(out->replies - 1) / 2];
	return DXL_OK;
}
