/*
 * test_sim_bus.c — one simulated bus without a pty, per servo family: the
 * shared tests (wire timing and the return delay, adapter latency and echo,
 * wrong baud, the checksum-error reply, every reply fault) run once with
 * AX-12s (Protocol 1.0) and once with X-series servos (Protocol 2.0), each
 * with its own bytes and times (struct family_case), checked through the
 * controller's parser. What one family has alone stays in its own section:
 * 1.0's colliding broadcast PING, its conformance through our encoder, the
 * stuck-error fault's count and probability, a packet inside a damaged one;
 * 2.0's SYNC_READ and BULK_READ order, a servo missing, the broadcast PING
 * in ID order, the bad-input counters, its ERR vocabulary. Then what is
 * either's: the pty's rate followed, the link's one owner (a second
 * simulator on a live link refused with the first named, a killed one's
 * link replaced, a disconnect keeping the link its own), fault texts, the
 * line queue.
 *
 * Bytes are typed from the manuals where they print them; the 2.0 CRCs of
 * the rest were computed by a separate bit-by-bit CRC-16/0x8005 (python),
 * which reproduces the e-manual's.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <cmocka.h>

#include "dxl_proto.h"
#include "dxl_table.h"
#include "dxl2_table.h"
#include "holder.h"
#include "port.h"
#include "../../sim-bridge/fault.h"
#include "../../sim-bridge/line.h"
#include "../../sim-bridge/simbus.h"

#define MS 1000000LL
#define US 1000LL
#define HDR 0xFF, 0xFF, 0xFD, 0x00

/* A 1 Mbps bus (10 µs a byte) with AX-12s of these IDs, return delay 0. */
static void bus_ax(struct sim_bus *b, const uint8_t *ids, size_t n)
{
	sim_bus_init(b, "t", "/nonexistent/t", 1000000, 0, false, 7);
	for (size_t k = 0; k < n; k++) {
		struct sim_joint *j = &b->joints[b->njoints++];
		memset(j, 0, sizeof(*j));
		j->ops = sim_joint_ops_of(SIM_MODEL_AX12A);
		sim_servo_init(&j->servo, NULL, DXL_POS_CENTER);
		sim_servo_poke(&j->servo, DXL_AX_ID, ids[k]);
		sim_servo_poke(&j->servo, DXL_AX_RETURN_DELAY_TIME, 0);
	}
}

/* A bus with X servos of these IDs (XL430, XM430, ... alternating), return
 * delay 0. */
static void bus_x(struct sim_bus *b, const uint8_t *ids, size_t n, long baud)
{
	sim_bus_init(b, "x", "/nonexistent/x", baud, 0, false, 7);
	sim_bus_set_protocol(b, 2);
	uint8_t reg = 0;
	assert_int_equal(dxl2_baud_to_reg(baud, &reg), DXL_OK);
	for (size_t k = 0; k < n; k++) {
		struct sim_joint *j = &b->joints[b->njoints++];
		memset(j, 0, sizeof(*j));
		j->model = k % 2 ? SIM_MODEL_XM430_W350 : SIM_MODEL_XL430_W250;
		j->ops = sim_joint_ops_of(j->model);
		sim_xservo_init(&j->xservo, j->model, NULL, 0.0);
		sim_xservo_poke(&j->xservo, DXL2_X_ID, ids[k]);
		sim_xservo_poke(&j->xservo, DXL2_X_BAUD_RATE, reg);
		sim_xservo_poke(&j->xservo, DXL2_X_RETURN_DELAY_TIME, 0);
	}
}

static void bus_x_1m(struct sim_bus *b, const uint8_t *ids, size_t n)
{
	bus_x(b, ids, n, 1000000);
}

/* Everything queued on the line, with the release time of the first and last byte. */
static size_t drain(struct sim_bus *b, uint8_t *out, size_t cap, int64_t *first, int64_t *last)
{
	*first = sim_line_next(&b->line);
	*last = *first;
	size_t n = 0;
	while (b->line.n > 0 && n < cap) {
		*last = sim_line_next(&b->line);
		n += sim_line_take(&b->line, *last, out + n, 1);
	}
	return n;
}

/* ---- shared: one run per servo family ------------------------------------------ */

struct bytes {
	const uint8_t *p;
	size_t n;
};
#define V(a) { (a), sizeof (a) }

/* One family's bus and the bytes and times worked out by hand for it
 * (1 Mbps: 10 µs a byte; a reply's first byte ends one byte time after the
 * request's last, with return delay 0). */
struct family_case {
	const char *name;
	const struct dxl_proto *proto;
	void (*bus)(struct sim_bus *b, const uint8_t *ids, size_t n);   /* at 1 Mbps, return delay 0 */
	uint16_t reg_return_delay, reg_baud;
	long other_baud_reg;                 /* a rate far from 1 Mbps */
	struct bytes ping;                   /* PING to ID 1 */
	size_t ping_reply_n;
	const uint8_t *ping_reply;           /* its reply as printed, or NULL ... */
	uint16_t ping_model;                 /* ... the model its parameters name */
	int64_t first_us, span_us;           /* the reply's first byte; first to last */
	struct bytes bad, bad_reply;         /* to ID 2 with a bad checksum; the answer */
	uint32_t (*servo_checksum_errors)(const struct sim_joint *j);
	const char *truncate;                /* a truncate fault, and the bytes it leaves */
	size_t truncated_n;
	const char *stuck;                   /* a stuck-error fault, and the err it gives */
	uint8_t stuck_err;
	struct bytes stuck_reply;            /* that reply as printed (empty: none printed) */
};

static uint32_t ax_checksum_errors(const struct sim_joint *j)
{
	return j->servo.count.checksum_errors;
}

static uint32_t x_crc_errors(const struct sim_joint *j)
{
	return j->xservo.count.crc_errors;
}

static const uint8_t ax_ping1[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
static const uint8_t ax_ping1_reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
static const uint8_t ax_bad2[] = { 0xFF, 0xFF, 0x02, 0x02, 0x01, 0x00 };
static const uint8_t ax_bad2_reply[] = { 0xFF, 0xFF, 0x02, 0x02, 0x10, 0xEB };     /* the checksum bit */
static const uint8_t ax_stuck_reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x24, 0xD8 };   /* the manual's example */
/* the e-manual's Ping example, 10 bytes: 100 µs on the wire */
static const uint8_t x_ping1[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
static const uint8_t x_bad2[] = { HDR, 0x02, 0x03, 0x00, 0x01, 0x19, 0x4F };
static const uint8_t x_bad2_reply[] = { HDR, 0x02, 0x04, 0x00, 0x55, 0x03, 0x23, 0x0C };   /* CRC error (3) */

static const struct family_case case_ax = {
	.name = "AX-12 (1.0)", .proto = &dxl_proto_v1, .bus = bus_ax,
	.reg_return_delay = DXL_AX_RETURN_DELAY_TIME, .reg_baud = DXL_AX_BAUD_RATE,
	.other_baud_reg = 34,   /* 57 143 bps */
	.ping = V(ax_ping1), .ping_reply_n = sizeof ax_ping1_reply, .ping_reply = ax_ping1_reply,
	/* request on the wire 60 µs, first byte 10 µs later; 6 bytes */
	.first_us = 70, .span_us = 50,
	.bad = V(ax_bad2), .bad_reply = V(ax_bad2_reply), .servo_checksum_errors = ax_checksum_errors,
	.truncate = "truncate 2", .truncated_n = 4,
	.stuck = "stuck-error overload|overheating", .stuck_err = DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT,
	.stuck_reply = V(ax_stuck_reply),
};

static const struct family_case case_x = {
	.name = "X series (2.0)", .proto = &dxl_proto_v2, .bus = bus_x_1m,
	.reg_return_delay = DXL2_X_RETURN_DELAY_TIME, .reg_baud = DXL2_X_BAUD_RATE,
	.other_baud_reg = 1,    /* 57 600 bps */
	.ping = V(x_ping1), .ping_reply_n = 14, .ping_reply = NULL, .ping_model = DXL2_MODEL_XL430_W250,
	/* request 100 µs, first byte 10 µs later; 14 bytes */
	.first_us = 110, .span_us = 130,
	.bad = V(x_bad2), .bad_reply = V(x_bad2_reply), .servo_checksum_errors = x_crc_errors,
	.truncate = "truncate", .truncated_n = 7,   /* half */
	.stuck = "stuck-error alert|data-range", .stuck_err = DXL2_ERR_ALERT | DXL2_ERRNUM_DATA_RANGE,
	.stuck_reply = { NULL, 0 },
};

/* The status packets in buf, as the controller's parser (the table's) sees
 * them: count of frames, the first ones in pkts, and the parser's error count. */
static size_t statuses(const struct dxl_proto *proto, const uint8_t *buf, size_t n, struct dxl_frame *pkts,
                       size_t cap, uint32_t *errors)
{
	static union dxl_proto_parser p;
	size_t off = 0, got = 0, bad = 0;
	proto->parser_init(&p, false);
	for (;;) {
		size_t used = 0;
		static struct dxl_frame f;
		int r = proto->parser_feed(&p, buf + off, n - off, &used, &f);
		off += used;
		if (r == DXL_FRAME && got < cap)
			pkts[got++] = f;
		else if (r == DXL_NEED_MORE)
			break;
		else if (r < 0)
			bad++;
	}
	if (errors)
		*errors = (uint32_t)bad;
	return got;
}

static const struct family_case *case_of(void **state)
{
	const struct family_case *c = *state;
	print_message("# %s\n", c->name);
	return c;
}

static const uint8_t ids12[] = { 1, 2 };

static void test_ping_timing(void **state)
{
	const struct family_case *c = case_of(state);
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	struct dxl_frame st;
	c->bus(&b, ids12, 2);
	sim_bus_feed(&b, c->ping.p, c->ping.n, 1000 * MS);
	size_t n = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(n, c->ping_reply_n);
	assert_int_equal(statuses(c->proto, out, n, &st, 1, NULL), 1);
	assert_int_equal(st.id, 1);
	if (c->ping_reply)
		assert_memory_equal(out, c->ping_reply, c->ping_reply_n);
	else
		assert_int_equal(st.params[0] | (st.params[1] << 8), c->ping_model);
	assert_int_equal(first - 1000 * MS, c->first_us * US);
	assert_int_equal(last - first, c->span_us * US);  /* paced: 10 µs a byte */
	/* With the factory return delay (250 × 2 µs) the reply is 500 µs later. */
	b.joints[0].ops->poke(&b.joints[0], c->reg_return_delay, 250);
	sim_bus_feed(&b, c->ping.p, c->ping.n, 2000 * MS);
	drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(first - 2000 * MS, (c->first_us + 500) * US);
}

/* The adapter holds everything 16 ms; a single-wire echo comes first. */
static void test_adapter_latency_and_echo(void **state)
{
	const struct family_case *c = case_of(state);
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	struct dxl_frame st;
	c->bus(&b, ids12, 2);
	b.latency_ns = 16 * MS;
	b.echo = true;
	sim_bus_feed(&b, c->ping.p, c->ping.n, 0);
	size_t n = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(n, c->ping.n + c->ping_reply_n);
	assert_memory_equal(out, c->ping.p, c->ping.n);   /* our own bytes first */
	assert_int_equal(statuses(c->proto, out + c->ping.n, c->ping_reply_n, &st, 1, NULL), 1);
	if (c->ping_reply)
		assert_memory_equal(out + c->ping.n, c->ping_reply, c->ping_reply_n);
	assert_int_equal(first, 16 * MS + 10 * US);
	assert_int_equal(last, 16 * MS + (int64_t)(n * 10) * US);
}

/* A servo at another baud rate hears nothing. */
static void test_wrong_baud_no_reply(void **state)
{
	const struct family_case *c = case_of(state);
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	c->bus(&b, ids12, 2);
	b.joints[0].ops->poke(&b.joints[0], c->reg_baud, c->other_baud_reg);
	sim_bus_feed(&b, c->ping.p, c->ping.n, 0);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 0);
	assert_int_equal(b.count.wrong_baud, 1);  /* servo 1 missed it */
	assert_true(sim_joint_hears(&b, &b.joints[1]));
	assert_false(sim_joint_hears(&b, &b.joints[0]));
}

/* A packet to a servo with a bad checksum: the servo's checksum error in
 * its reply, counted by the bus and by the servo. */
static void test_bad_checksum_reply(void **state)
{
	const struct family_case *c = case_of(state);
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	c->bus(&b, ids12, 2);
	sim_bus_feed(&b, c->bad.p, c->bad.n, 0);
	size_t n = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(n, c->bad_reply.n);
	assert_memory_equal(out, c->bad_reply.p, c->bad_reply.n);
	assert_int_equal(b.count.checksum_errors, 1);
	assert_int_equal(c->servo_checksum_errors(&b.joints[1]), 1);
}

/* Set a fault on servo 1 from its text form, beside those it has. */
static void set_fault(struct sim_bus *b, const char *text)
{
	char buf[128], err[128], *argv[8];
	int argc = 0;
	enum sim_fault_kind kind;
	struct sim_fault f;
	snprintf(buf, sizeof(buf), "%s", text);
	for (char *save = NULL, *w = strtok_r(buf, " ", &save); w && argc < 8; w = strtok_r(NULL, " ", &save))
		argv[argc++] = w;
	assert_int_equal(sim_fault_parse(argc, argv, &kind, &f, err, sizeof(err)), 0);
	b->joints[0].faults.f[kind] = f;
}

/* Apply a fault to servo 1 alone and return what the controller reads for a PING. */
static size_t ping_with_fault(const struct family_case *c, struct sim_bus *b, const char *fault, uint8_t *out,
                              int64_t *first)
{
	int64_t last;
	sim_faults_clear(&b->joints[0].faults);
	set_fault(b, fault);
	sim_bus_feed(b, c->ping.p, c->ping.n, 0);
	b->rx_free_at = 0;
	return drain(b, out, 128, first, &last);
}

/* Every reply fault on the family's status packet. */
static void test_reply_faults(void **state)
{
	const struct family_case *c = case_of(state);
	struct sim_bus b;
	uint8_t out[128];
	int64_t first, last;
	struct dxl_frame st;
	uint32_t errors;
	c->bus(&b, ids12, 2);
	assert_int_equal(ping_with_fault(c, &b, "no-reply", out, &first), 0);
	/* bad-checksum: the checksum or CRC inverted, the packet whole */
	size_t n = ping_with_fault(c, &b, "bad-checksum", out, &first);
	assert_int_equal(n, c->ping_reply_n);
	assert_int_equal(statuses(c->proto, out, n, &st, 1, &errors), 0);
	assert_int_equal(errors, 1);
	n = ping_with_fault(c, &b, c->truncate, out, &first);
	assert_int_equal(n, c->truncated_n);
	assert_int_equal(statuses(c->proto, out, n, &st, 1, NULL), 0);
	/* wrong-id: another ID, a valid checksum */
	n = ping_with_fault(c, &b, "wrong-id 9", out, &first);
	assert_int_equal(statuses(c->proto, out, n, &st, 1, NULL), 1);
	assert_int_equal(st.id, 9);
	/* garbage before the reply; the reply still frames */
	n = ping_with_fault(c, &b, "garbage 5", out, &first);
	assert_int_equal(n, c->ping_reply_n + 5);
	assert_int_equal(statuses(c->proto, out, n, &st, 1, NULL), 1);
	n = ping_with_fault(c, &b, "slow 3", out, &first);
	assert_int_equal(first, 3 * MS + c->first_us * US);
	/* stuck-error: the error in a well-formed packet */
	n = ping_with_fault(c, &b, c->stuck, out, &first);
	assert_int_equal(statuses(c->proto, out, n, &st, 1, NULL), 1);
	assert_int_equal(st.err, c->stuck_err);
	if (c->stuck_reply.n) {
		assert_int_equal(n, c->stuck_reply.n);
		assert_memory_equal(out, c->stuck_reply.p, c->stuck_reply.n);
	}
	/* count=N: only the next N replies. */
	n = ping_with_fault(c, &b, "no-reply count=1", out, &first);
	assert_int_equal(n, 0);
	sim_bus_feed(&b, c->ping.p, c->ping.n, 2 * MS);
	assert_int_equal(drain(&b, out, sizeof(out), &first, &last), c->ping_reply_n);
}

/* ---- AX-12 (Protocol 1.0) only ----------------------------------------------- */

/* Parse a status packet from the controller's side. */
static int parse_status(const uint8_t *buf, size_t n, struct dxl_packet *pkt)
{
	struct dxl_parser p;
	size_t used = 0, off = 0;
	dxl_parser_init(&p, DXL_PARSE_STATUS);
	int r;
	do {
		r = dxl_parser_feed(&p, buf + off, n - off, &used, pkt);
		off += used;
	} while (r < 0 && off < n);
	return r;
}

/* One PING to servo 1 at time t; its reply (6 bytes, or what the faults made
 * of it) in out. */
static size_t ping1(struct sim_bus *b, int64_t t, uint8_t *out)
{
	static const uint8_t ping[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	int64_t first, last;
	sim_bus_feed(b, ping, sizeof(ping), t);
	return drain(b, out, 128, &first, &last);
}

static void test_v1_broadcast_ping_collides(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_ax(&b, ids12, 2);
	static const uint8_t ping[] = { 0xFF, 0xFF, 0xFE, 0x02, 0x01, 0xFE };
	sim_bus_feed(&b, ping, sizeof(ping), 0);
	size_t n = drain(&b, out, sizeof(out), &first, &last);
	/* Both answer at the same instant: 6 bytes on top of each other. */
	assert_int_equal(n, 6);
	assert_true(b.line.collisions >= 6);
	struct dxl_packet pkt;
	assert_int_not_equal(parse_status(out, n, &pkt), DXL_FRAME);
	/* With different return delays they come out one after the other. */
	sim_servo_poke(&b.joints[1].servo, DXL_AX_RETURN_DELAY_TIME, 100);
	sim_bus_feed(&b, ping, sizeof(ping), 10 * MS);
	n = drain(&b, out, sizeof(out), &first, &last);
	assert_int_equal(n, 12);
	assert_int_equal(parse_status(out, 6, &pkt), DXL_FRAME);
	assert_int_equal(pkt.id, 1);
	assert_int_equal(parse_status(out + 6, 6, &pkt), DXL_FRAME);
	assert_int_equal(pkt.id, 2);
}

static void test_v1_conformance_through_library(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t req[DXL_MAX_PACKET], out[DXL_MAX_PACKET];
	int64_t first, last;
	struct dxl_packet pkt;
	bus_ax(&b, ids12, 2);
	/* SYNC_WRITE goals for both, then READ(36, 8) from each. */
	const uint8_t ids[2] = { 1, 2 };
	const uint8_t data[4] = { 0x00, 0x01, 0x00, 0x03 };
	int n = dxl_encode_sync_write(req, sizeof(req), DXL_AX_GOAL_POSITION, 2, ids, data, 2);
	assert_true(n > 0);
	sim_bus_feed(&b, req, (size_t)n, 0);
	assert_int_equal(b.line.n, 0);
	assert_int_equal(sim_servo_peek(&b.joints[0].servo, DXL_AX_GOAL_POSITION), 0x100);
	assert_int_equal(sim_servo_peek(&b.joints[1].servo, DXL_AX_GOAL_POSITION), 0x300);
	for (uint8_t id = 1; id <= 2; id++) {
		n = dxl_encode_read(req, sizeof(req), id, DXL_AX_PRESENT_POSITION, 8);
		sim_bus_feed(&b, req, (size_t)n, (int64_t)id * MS);
		size_t got = drain(&b, out, sizeof(out), &first, &last);
		assert_int_equal(got, 14);
		assert_int_equal(parse_status(out, got, &pkt), DXL_FRAME);
		assert_int_equal(pkt.id, id);
		assert_int_equal(pkt.code, 0);
		assert_int_equal(pkt.nparams, 8);
		assert_int_equal(dxl_get_u16(pkt.params), DXL_POS_CENTER);
	}
	/* WRITE with our encoder: status with no error. */
	uint8_t torque = 1;
	n = dxl_encode_write(req, sizeof(req), 2, DXL_AX_TORQUE_ENABLE, &torque, 1);
	sim_bus_feed(&b, req, (size_t)n, 5 * MS);
	size_t got = drain(&b, out, sizeof(out), &first, &last);
	assert_int_equal(parse_status(out, got, &pkt), DXL_FRAME);
	assert_int_equal(pkt.code, 0);
	assert_int_equal(b.joints[1].servo.mem[DXL_AX_TORQUE_ENABLE], 1);
}

/* stuck-error honours count=N and prob=P like every other fault: the bits
 * are in the next N replies only, or in a fraction P of them (the bus's
 * seeded generator), and each reply carrying them has a valid checksum. */
static void test_v1_stuck_error_count_and_prob(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[128];
	struct dxl_packet pkt;
	int64_t t = 0;
	bus_ax(&b, ids12, 2);
	set_fault(&b, "stuck-error overload count=2");
	for (int i = 0; i < 4; i++) {
		assert_int_equal(ping1(&b, t += MS, out), 6);
		assert_int_equal(parse_status(out, 6, &pkt), DXL_FRAME);
		assert_int_equal(pkt.code, i < 2 ? DXL_ERRBIT_OVERLOAD : 0);
	}
	assert_false(b.joints[0].faults.f[SIM_FAULT_STUCK_ERROR].active);  /* used up */

	set_fault(&b, "stuck-error overload|overheating prob=0.5");
	int with = 0;
	for (int i = 0; i < 400; i++) {
		assert_int_equal(ping1(&b, t += MS, out), 6);
		assert_int_equal(parse_status(out, 6, &pkt), DXL_FRAME);
		assert_true(pkt.code == 0 || pkt.code == (DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT));
		with += pkt.code != 0;
	}
	assert_in_range(with, 140, 260);   /* 200 ± 6 sigma */
	set_fault(&b, "stuck-error prob=0");
	for (int i = 0; i < 50; i++) {
		ping1(&b, t += MS, out);
		assert_int_equal(out[4], 0);
	}
	/* the same seed gives the same replies */
	struct sim_bus c;
	int pattern_b = 0, pattern_c = 0;
	bus_ax(&b, ids12, 2);
	bus_ax(&c, ids12, 2);
	set_fault(&b, "stuck-error prob=0.5");
	set_fault(&c, "stuck-error prob=0.5");
	for (int i = 0; i < 20; i++) {
		ping1(&b, t += MS, out);
		pattern_b = pattern_b << 1 | (out[4] != 0);
		ping1(&c, t, out);
		pattern_c = pattern_c << 1 | (out[4] != 0);
	}
	assert_int_equal(pattern_b, pattern_c);
	assert_true(pattern_b != 0 && pattern_b != (1 << 20) - 1);
	/* together with bad-checksum: the bits are in, and the checksum (of the
	 * packet with the bits) is inverted */
	bus_ax(&b, ids12, 2);
	set_fault(&b, "stuck-error range");
	set_fault(&b, "bad-checksum");
	ping1(&b, t += MS, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(out[5], (uint8_t)~dxl_checksum(&out[2], 3));
	/* the bits never reach the servo's own state: report only, no shutdown */
	assert_int_equal(b.joints[0].servo.conditions, 0);
}

/* A whole packet inside a damaged one (here in the parameters of a WRITE
 * with a bad checksum) is found by the parser's resync when the damaged one
 * ends, and answered then, in whatever reads the bytes came: the bus asks
 * the parser for more until it needs input, as its contract says. (Found by
 * fuzz_sim_serial: in one read, the PING stayed buffered, unanswered, until
 * the controller's next byte.) */
static void test_v1_packet_inside_a_bad_packet(void **state)
{
	(void)state;
	static struct sim_bus b;
	uint8_t out[128];
	int64_t first, last;
	struct dxl_packet pkt;
	/* WRITE to 1 at address 6 of the bytes FF FF 02 02 01 FA (a PING to 2) */
	uint8_t outer[] = { 0xFF, 0xFF, 0x01, 0x09, 0x03, 0x06, 0xFF, 0xFF, 0x02, 0x02, 0x01, 0xFA, 0x00 };
	outer[sizeof(outer) - 1] = (uint8_t)(dxl_checksum(&outer[2], sizeof(outer) - 3) ^ 0x55);  /* bad */
	for (size_t cut = 1; cut <= sizeof(outer); cut++) {
		bus_ax(&b, ids12, 2);
		/* servo 2 answers 100 µs later: the two replies do not collide */
		sim_servo_poke(&b.joints[1].servo, DXL_AX_RETURN_DELAY_TIME, 50);
		sim_bus_feed(&b, outer, cut, 0);
		sim_bus_feed(&b, outer + cut, sizeof(outer) - cut, 0);
		assert_int_equal(b.count.checksum_errors, 1);
		assert_int_equal(b.count.packets, 1);
		assert_int_equal(b.joints[0].servo.count.checksum_errors, 1);   /* servo 1: the checksum bit */
		assert_int_equal(b.joints[1].servo.count.instructions, 1);      /* servo 2: the PING */
		size_t n = drain(&b, out, sizeof(out), &first, &last);
		assert_int_equal(n, 12);
		assert_int_equal(parse_status(out, 6, &pkt), DXL_FRAME);
		assert_int_equal(pkt.id, 1);
		assert_int_equal(pkt.code, DXL_ERRBIT_CHECKSUM);
		assert_int_equal(parse_status(out + 6, 6, &pkt), DXL_FRAME);
		assert_int_equal(pkt.id, 2);
		assert_int_equal(pkt.code, 0);
	}
}

/* Leading garbage and a split packet still frame; a gap of more than
 * 100 ms inside a packet: the servo drops the start. */
static void test_v1_garbage_and_gap(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_ax(&b, ids12, 2);
	static const uint8_t noisy[] = { 0x00, 0x13, 0xFF, 0xFF, 0x01, 0x02 };
	static const uint8_t rest[] = { 0x01, 0xFB };
	sim_bus_feed(&b, noisy, sizeof(noisy), MS);
	sim_bus_feed(&b, rest, sizeof(rest), MS + 50 * US);
	size_t n = drain(&b, out, sizeof(out), &first, &last);
	assert_int_equal(n, 6);
	assert_int_equal(out[2], 1);
	static const uint8_t head[] = { 0xFF, 0xFF, 0x01, 0x02 };
	sim_bus_feed(&b, head, sizeof(head), 10 * MS);
	sim_bus_feed(&b, ax_ping1, sizeof(ax_ping1), 200 * MS);
	n = drain(&b, out, sizeof(out), &first, &last);
	assert_int_equal(n, 6);
	assert_memory_equal(out, ax_ping1_reply, 6);
	assert_int_equal(b.count.stale_drops, 1);
}

/* The AX-12's Baud Rate register against the bus's rate. */
static void test_v1_baud_register(void **state)
{
	(void)state;
	struct sim_bus b;
	bus_ax(&b, ids12, 2);
	assert_true(sim_bus_baud_matches(&b, 1));
	assert_false(sim_bus_baud_matches(&b, 3));
}

/* ---- X series (Protocol 2.0) only --------------------------------------------- */

/* The status packets in buf, as the controller's parser sees them: count of
 * frames, the first ones in pkts, and the parser's error count. */
static size_t statuses2(const uint8_t *buf, size_t n, struct dxl2_packet *pkts, size_t cap, uint32_t *errors)
{
	static struct dxl2_parser p;
	size_t off = 0, got = 0;
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	for (;;) {
		size_t used = 0;
		struct dxl2_packet pkt;
		int r = dxl2_parser_feed(&p, buf + off, n - off, &used, &pkt);
		off += used;
		if (r == DXL_FRAME && got < cap)
			pkts[got++] = pkt;
		else if (r == DXL_NEED_MORE)
			break;
	}
	if (errors)
		*errors = p.checksum_errors + p.header_errors + p.stuffing_errors;
	return got;
}

/* SYNC_READ: the replies follow the request's list, each after the one
 * before it; a servo missing from the list leaves no gap (README). */
static void test_v2_sync_read_order_and_missing(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t req[64], out[128];
	int64_t first, last;
	struct dxl2_packet st[4];
	static const uint8_t ids[] = { 1, 2 };
	bus_x(&b, ids, 2, 1000000);
	static const uint8_t order[] = { 2, 1 };
	int n = dxl2_encode_sync_read(req, sizeof req, DXL2_X_PRESENT_POSITION, 4, order, 2);
	sim_bus_feed(&b, req, (size_t)n, 0);
	size_t got = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(got, 30);
	assert_int_equal(statuses2(out, got, st, 4, NULL), 2);
	assert_int_equal(st[0].id, 2);
	assert_int_equal(st[1].id, 1);
	assert_int_equal(b.line.collisions, 0);
	/* back to back: the second's first byte 10 µs after the first's last */
	assert_int_equal(first, (int64_t)(n + 1) * 10 * US);
	assert_int_equal(last - first, 29 * 10 * US);
	/* ID 3 is not on the bus: ID 2 answers right after ID 1 */
	static const uint8_t with_gap[] = { 1, 3, 2 };
	n = dxl2_encode_sync_read(req, sizeof req, DXL2_X_PRESENT_POSITION, 4, with_gap, 3);
	sim_bus_feed(&b, req, (size_t)n, 10 * MS);
	got = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(statuses2(out, got, st, 4, NULL), 2);
	assert_int_equal(st[0].id, 1);
	assert_int_equal(st[1].id, 2);
	assert_int_equal(last - first, 29 * 10 * US);
	/* the tracker of protocol/dxl2.c names the missing one */
	struct dxl2_multi_read m;
	size_t slot;
	uint8_t missing[4];
	assert_int_equal(dxl2_multi_read_sync(&m, 4, with_gap, 3), DXL_OK);
	assert_int_equal(dxl2_multi_read_accept(&m, &st[0], &slot), DXL_OK);
	assert_int_equal(dxl2_multi_read_accept(&m, &st[1], &slot), DXL_OK);
	assert_int_equal(dxl2_multi_read_missing(&m, missing, 4), 1);
	assert_int_equal(missing[0], 3);
	/* BULK_READ (the e-manual's example: voltage of 1, temperature of 2) */
	static const uint8_t bulk[] = { HDR, 0xFE, 0x0D, 0x00, 0x92, 0x01, 0x90, 0x00, 0x02, 0x00, 0x02, 0x92, 0x00,
	                                0x01, 0x00, 0x1A, 0x05 };
	sim_bus_feed(&b, bulk, sizeof bulk, 20 * MS);
	got = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(got, 13 + 12);
	assert_int_equal(statuses2(out, got, st, 4, NULL), 2);
	assert_int_equal(st[0].nparams, 2);
	assert_int_equal(st[1].nparams, 1);
}

/* Fast Sync Read / Fast Bulk Read (e-manual, Protocol 2.0): one status
 * packet from 0xFE, the servos' parts in the request's order, each going
 * out as soon as the one before it has ended: one return delay (the
 * first's) for all. A servo below firmware 45 does not know the
 * instruction and stays silent: the chain stops at its part. */
static void test_v2_fast_read(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t req[64], out[128];
	int64_t first, last;
	struct dxl2_parser p;
	struct dxl2_packet st;
	struct dxl2_multi_read m;
	struct dxl2_fast_part parts[3];
	size_t used = 0, good = 0;
	static const uint8_t ids[] = { 3, 7, 4 };
	bus_x(&b, ids, 3, 1000000);
	for (size_t k = 0; k < 3; k++) {
		sim_xservo_poke(&b.joints[k].xservo, DXL2_X_RETURN_DELAY_TIME, 50);   /* 100 µs */
		sim_xservo_poke(&b.joints[k].xservo, DXL2_X_PRESENT_POSITION, k == 0 ? 166 : k == 1 ? 2079 : 1023);
	}
	int n = dxl2_encode_fast_sync_read(req, sizeof req, DXL2_X_PRESENT_POSITION, 4, ids, 3);
	sim_bus_feed(&b, req, (size_t)n, 0);
	size_t got = drain(&b, out, sizeof out, &first, &last);
	/* the e-manual's example, byte for byte (its XC330s at these positions) */
	static const uint8_t manual[] = { HDR, 0xFE, 0x19, 0x00, 0x55, 0x00, 0x03, 0xA6, 0x00, 0x00, 0x00, 0x84, 0x08,
		                          0x00, 0x07, 0x1F, 0x08, 0x00, 0x00, 0x16, 0xCA, 0x00, 0x04, 0xFF, 0x03,
		                          0x00, 0x00, 0xD1, 0x9E };
	assert_int_equal(got, sizeof manual);
	assert_memory_equal(out, manual, sizeof manual);
	/* one return delay, then 32 bytes back to back */
	assert_int_equal(first, (int64_t)(n + 1) * 10 * US + 100 * US);
	assert_int_equal(last - first, 31 * 10 * US);
	assert_int_equal(b.line.collisions, 0);
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	dxl2_parser_expect_fast(&p, true);
	assert_int_equal(dxl2_parser_feed(&p, out, got, &used, &st), DXL_FRAME);
	assert_int_equal(dxl2_multi_read_sync(&m, 4, ids, 3), DXL_OK);
	assert_int_equal(dxl2_fast_status_split(&st, &m, parts, &good), DXL_OK);

	/* Fast Bulk Read: the manual's request, each servo its own register */
	sim_xservo_poke(&b.joints[1].xservo, DXL2_X_PRESENT_PWM, 421);
	sim_xservo_poke(&b.joints[2].xservo, DXL2_X_PRESENT_TEMPERATURE, 31);
	static const uint8_t bulk[] = { HDR, 0xFE, 0x12, 0x00, 0x9A, 0x03, 0x84, 0x00, 0x04, 0x00, 0x07, 0x7C, 0x00,
		                        0x02, 0x00, 0x04, 0x92, 0x00, 0x01, 0x00, 0xDA, 0x2D };
	static const uint8_t bulk_status[] = { HDR, 0xFE, 0x14, 0x00, 0x55, 0x00, 0x03, 0xA6, 0x00, 0x00, 0x00, 0x67,
		                               0xA4, 0x00, 0x07, 0xA5, 0x01, 0x24, 0x74, 0x00, 0x04, 0x1F, 0xD9, 0xC1 };
	sim_bus_feed(&b, bulk, sizeof bulk, 10 * MS);
	got = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(got, sizeof bulk_status);
	assert_memory_equal(out, bulk_status, sizeof bulk_status);

	/* ID 7 on firmware 44: it does not answer, and ID 4 after it cannot
	 * take its turn; ID 3's part went out (the packet cut after it) */
	sim_xservo_poke(&b.joints[1].xservo, DXL2_X_FIRMWARE_VERSION, 44);
	sim_bus_feed(&b, req, (size_t)n, 20 * MS);
	got = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(got, 16);
	assert_memory_equal(out, manual, 16);
	/* ID 3 on firmware 44: nothing at all; the plain SYNC_READ still works */
	sim_xservo_poke(&b.joints[1].xservo, DXL2_X_FIRMWARE_VERSION, 46);
	sim_xservo_poke(&b.joints[0].xservo, DXL2_X_FIRMWARE_VERSION, 44);
	sim_bus_feed(&b, req, (size_t)n, 30 * MS);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 0);
	n = dxl2_encode_sync_read(req, sizeof req, DXL2_X_PRESENT_POSITION, 4, ids, 3);
	sim_bus_feed(&b, req, (size_t)n, 40 * MS);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 3 * 15);

	/* a bad-checksum fault on ID 7's part: its CRC goes out wrong, and ID
	 * 4's (the packet's), computed over what it heard, checks: the
	 * controller finds the damage at ID 7's part, ID 3's part sound */
	sim_xservo_poke(&b.joints[0].xservo, DXL2_X_FIRMWARE_VERSION, 46);
	set_fault(&b, "bad-checksum count=1");
	b.joints[1].faults = b.joints[0].faults;
	sim_faults_clear(&b.joints[0].faults);
	n = dxl2_encode_fast_sync_read(req, sizeof req, DXL2_X_PRESENT_POSITION, 4, ids, 3);
	sim_bus_feed(&b, req, (size_t)n, 50 * MS);
	got = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(got, sizeof manual);
	assert_memory_equal(out, manual, 22);
	assert_int_equal(out[22], manual[22] ^ 0xFF);
	assert_int_equal(out[23], manual[23] ^ 0xFF);
	assert_memory_equal(out + 24, manual + 24, 6);
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	dxl2_parser_expect_fast(&p, true);
	assert_int_equal(dxl2_parser_feed(&p, out, got, &used, &st), DXL_FRAME);
	assert_int_equal(dxl2_fast_status_split(&st, &m, parts, &good), DXL_E_CHECKSUM);
	assert_int_equal(good, 1);
}

/* A broadcast PING: every servo answers, lowest ID first (e-manual: "in
 * their arranged order"), without colliding, whatever the wiring order. */
static void test_v2_broadcast_ping_in_id_order(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[128];
	int64_t first, last;
	struct dxl2_packet st[4];
	static const uint8_t ids[] = { 7, 2, 5 };
	bus_x(&b, ids, 3, 1000000);
	static const uint8_t ping[] = { HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42 };
	sim_bus_feed(&b, ping, sizeof ping, 0);
	size_t got = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(got, 42);
	assert_int_equal(statuses2(out, got, st, 4, NULL), 3);
	assert_int_equal(st[0].id, 2);
	assert_int_equal(st[1].id, 5);
	assert_int_equal(st[2].id, 7);
	assert_int_equal(b.line.collisions, 0);
}

/* Bad input is counted and survived: a header inside a packet (bad
 * stuffing), reserved byte, ID 253, a status on the instruction side; a
 * Protocol 1.0 packet is noise on a 2.0 bus. A good packet after all of it
 * is answered. */
static void test_v2_bad_input_counters(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	static const uint8_t ids[] = { 1 };
	bus_x(&b, ids, 1, 1000000);
	/* a WRITE cut short by a new header (FF FF FD then 00: not stuffed) */
	static const uint8_t cut[] = { HDR, 0x01, 0x09, 0x00, 0x03, 0x74, 0x00, 0xFF, 0xFF, 0xFD, 0x00 };
	sim_bus_feed(&b, cut, sizeof cut, 0);
	assert_int_equal(b.count.stuffing_errors, 1);
	static const uint8_t rsrv[] = { 0xFF, 0xFF, 0xFD, 0x01, 0x01, 0x03, 0x00, 0x01, 0x00, 0x00 };
	static const uint8_t id253[] = { HDR, 0xFD, 0x03, 0x00, 0x01, 0x00, 0x00 };
	static const uint8_t status[] = { HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C };
	static const uint8_t ping1[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	sim_bus_feed(&b, rsrv, sizeof rsrv, MS);
	sim_bus_feed(&b, id253, sizeof id253, 2 * MS);
	sim_bus_feed(&b, status, sizeof status, 3 * MS);
	sim_bus_feed(&b, ping1, sizeof ping1, 4 * MS);
	assert_true(b.count.header_errors >= 3);
	assert_int_equal(b.count.packets, 0);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 0);
	static const uint8_t ping[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
	sim_bus_feed(&b, ping, sizeof ping, 200 * MS);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 14);
	assert_int_equal(b.count.packets, 1);
	/* half a packet, then 100 ms of silence: dropped (as on 1.0) */
	sim_bus_feed(&b, ping, 5, 300 * MS);
	sim_bus_feed(&b, ping, sizeof ping, 450 * MS);
	assert_int_equal(b.count.stale_drops, 1);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 14);
}

/* The text forms: stuck-error takes 1.0's bits or 2.0's ERR field. */
static void test_v2_stuck_error_vocabularies(void **state)
{
	(void)state;
	assert_int_equal(sim_fault_parse_err2("alert"), 0x80);
	assert_int_equal(sim_fault_parse_err2("data-limit"), 6);
	assert_int_equal(sim_fault_parse_err2("alert|access"), 0x87);
	assert_int_equal(sim_fault_parse_err2("0x84"), 0x84);
	assert_int_equal(sim_fault_parse_err2("crc|access"), -1);      /* one error number at most */
	assert_int_equal(sim_fault_parse_err2("overload"), -1);        /* a 1.0 bit */
	assert_int_equal(sim_fault_parse_err2("256"), -1);
	assert_int_equal(sim_fault_parse_bits("alert"), -1);           /* a 2.0 name */
}


/* At the X series' factory 57600 bps a byte takes 173.6 µs. */
static void test_v2_ping_at_57600(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_x(&b, ids12, 2, 57600);
	sim_bus_feed(&b, x_ping1, sizeof x_ping1, 0);
	drain(&b, out, sizeof out, &first, &last);
	assert_true(first >= 11 * 173 * US && first <= 11 * 174 * US);
}

/* A bad CRC to the broadcast ID: counted, unanswered. */
static void test_v2_bad_crc_broadcast(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_x(&b, ids12, 2, 1000000);
	static const uint8_t bad_bc[] = { HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x43 };
	sim_bus_feed(&b, bad_bc, sizeof bad_bc, MS);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 0);
	assert_int_equal(b.count.checksum_errors, 1);
}

/* Faults on 2.0 alone: stuck-error's default (the alert bit, the packet
 * well formed), no-reply inside a SYNC_READ (the next servo answers at
 * once), slow with count=1. */
static void test_v2_faults(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[128];
	struct dxl2_packet st[2];
	uint32_t errors;
	int64_t first, last;
	bus_x(&b, ids12, 2, 1000000);
	set_fault(&b, "stuck-error count=1");
	sim_bus_feed(&b, x_ping1, sizeof x_ping1, 0);
	size_t n = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(statuses2(out, n, st, 2, &errors), 1);
	assert_int_equal(st[0].err, DXL2_ERR_ALERT);
	assert_int_equal(st[0].nparams, 3);
	set_fault(&b, "no-reply count=1");
	uint8_t req[64];
	int r = dxl2_encode_sync_read(req, sizeof req, DXL2_X_PRESENT_POSITION, 4, ids12, 2);
	sim_bus_feed(&b, req, (size_t)r, 10 * MS);
	n = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(statuses2(out, n, st, 2, NULL), 1);
	assert_int_equal(st[0].id, 2);
	assert_int_equal(first - 10 * MS, (int64_t)(r + 1) * 10 * US);
	set_fault(&b, "slow count=1");
	sim_bus_feed(&b, x_ping1, sizeof x_ping1, 20 * MS);
	drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(first - 20 * MS, 5 * MS + 110 * US);
}

/* ---- either family: the link, the fault texts, the line ------------------------ */

/* The bus follows the rate its controller set on the pty, standard or not
 * (read back with protocol/io's termios2 helpers, the one home of that code). */
static void test_bus_follows_pty_rate(void **state)
{
	(void)state;
	char dir[] = "/tmp/test_sim_bus.XXXXXX", link[64];
	assert_non_null(mkdtemp(dir));
	snprintf(link, sizeof(link), "%s/bus", dir);
	static struct sim_bus b;
	char err[256];
	sim_bus_init(&b, "t", link, 57600, 0, false, 1);
	assert_int_equal(sim_bus_open(&b, err, sizeof(err)), 0);
	/* a new pty starts at the configured rate */
	assert_int_equal(port_termios2_get_baud(b.slave), 57600);
	assert_int_equal(b.baud, 57600);
	int fd = open(link, O_RDWR | O_NOCTTY | O_NONBLOCK);
	assert_true(fd >= 0);
	/* a standard rate through POSIX termios ... */
	struct termios t;
	assert_int_equal(tcgetattr(fd, &t), 0);
	cfsetspeed(&t, B500000);
	assert_int_equal(tcsetattr(fd, TCSANOW, &t), 0);
	assert_int_equal(port_termios2_get_baud(fd), 500000);
	sim_bus_read(&b, 0);
	assert_int_equal(b.baud, 500000);
	assert_int_equal(b.byte_ns, 20000);
	/* ... and a Dynamixel rate without a constant (BOTHER) */
	assert_int_equal(port_termios2_set_baud(fd, 117647), DXL_OK);
	assert_int_equal(port_termios2_get_baud(b.slave), 117647);
	sim_bus_read(&b, 0);
	assert_int_equal(b.baud, 117647);
	close(fd);
	sim_bus_release(&b);
	assert_int_equal(port_termios2_get_baud(-1), DXL_E_IO);
	assert_int_equal(rmdir(dir), 0);  /* the link and its lock file went with the bus */
}

/* One simulator per link. A second bus on a live link (another simulator:
 * a lock file is another open file to flock(), even in one process) is
 * refused before it makes a pty, naming the first, and leaves the link
 * alone; a disconnect keeps the link the first one's; one left by a killed
 * simulator (a dangling link, a lock file no process holds) is replaced. */
static void test_link_has_one_owner(void **state)
{
	(void)state;
	char dir[] = "/tmp/test_sim_link.XXXXXX", link[64], lock[80], target[SIM_PATH_MAX];
	assert_non_null(mkdtemp(dir));
	snprintf(link, sizeof(link), "%s/bus", dir);
	snprintf(lock, sizeof(lock), "%s/bus.lock", dir);
	static struct sim_bus a, b2;
	char err[400];
	sim_bus_init(&a, "r1", link, 1000000, 0, false, 1);
	sim_bus_init(&b2, "r2", link, 1000000, 0, false, 1);
	assert_int_equal(sim_bus_open(&a, err, sizeof(err)), 0);
	struct holder f;
	assert_true(holder_read_file(lock, &f));
	assert_int_equal(f.pid, getpid());
	assert_string_equal(f.detail, "bus r1");

	assert_int_equal(sim_bus_open(&b2, err, sizeof(err)), -1);
	char want[300];
	snprintf(want, sizeof(want), "%s: held by %s (pid %ld, bus r1)", link, f.program, (long)getpid());
	assert_non_null(strstr(err, want));
	assert_false(sim_bus_connected(&b2));
	ssize_t n = readlink(link, target, sizeof(target) - 1);
	assert_true(n > 0);
	target[n] = '\0';
	assert_string_equal(target, a.slave_path);
	sim_bus_release(&b2);   /* never held: the link and the lock stay */
	assert_int_equal(access(lock, F_OK), 0);
	assert_true(readlink(link, target, sizeof(target)) > 0);

	/* a disconnect removes the link but keeps it ours */
	sim_bus_close(&a);
	assert_int_equal(readlink(link, target, sizeof(target)), -1);
	assert_int_equal(sim_bus_open(&b2, err, sizeof(err)), -1);
	assert_int_equal(sim_bus_open(&a, err, sizeof(err)), 0);
	sim_bus_release(&a);
	assert_int_equal(access(lock, F_OK), -1);

	/* what a SIGKILLed simulator leaves: a link to a pty that is gone, a
	 * lock file naming a dead pid */
	pid_t c = fork();
	assert_true(c >= 0);
	if (c == 0)
		_exit(0);
	assert_int_equal(waitpid(c, NULL, 0), c);
	assert_int_equal(symlink("/dev/pts/999999", link), 0);
	FILE *fp = fopen(lock, "w");
	assert_non_null(fp);
	fprintf(fp, "%10ld undulate-sim bus r1\n", (long)c);
	fclose(fp);
	assert_int_equal(sim_bus_open(&b2, err, sizeof(err)), 0);
	n = readlink(link, target, sizeof(target) - 1);
	assert_true(n > 0);
	target[n] = '\0';
	assert_string_equal(target, b2.slave_path);
	sim_bus_release(&b2);
	assert_int_equal(rmdir(dir), 0);
}

static void test_fault_parse_errors(void **state)
{
	(void)state;
	char err[128];
	enum sim_fault_kind kind;
	struct sim_fault f;
	char *bad1[] = { "explode" };
	char *bad2[] = { "slow", "abc" };
	char *bad3[] = { "temperature" };
	char *bad4[] = { "stuck-error", "nonsense" };
	char *bad5[] = { "no-reply", "prob=2" };
	assert_int_equal(sim_fault_parse(1, bad1, &kind, &f, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "unknown fault"));
	assert_int_equal(sim_fault_parse(2, bad2, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse(1, bad3, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse(2, bad4, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse(2, bad5, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse(0, NULL, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse_bits("overload|range"), 0x28);
	assert_int_equal(sim_fault_parse_bits("36"), 36);
	assert_int_equal(sim_fault_parse_bits("200"), -1);
}

static void test_line_queue(void **state)
{
	(void)state;
	static struct sim_line l;
	uint8_t out[8];
	sim_line_init(&l);
	const uint8_t a[3] = { 1, 2, 3 }, c[2] = { 0xF0, 0x0F };
	sim_line_put(&l, 100, 10, a, 3);          /* at 100, 110, 120 */
	sim_line_put(&l, 135, 10, c, 2);          /* 135, 145: 15 ns after 120, no collision */
	assert_int_equal(l.collisions, 0);
	sim_line_put(&l, 104, 10, c, 1);          /* overlaps the byte at 100 */
	assert_int_equal(l.collisions, 1);
	assert_int_equal(sim_line_take(&l, 99, out, 8), 0);
	assert_int_equal(sim_line_take(&l, 110, out, 8), 2);
	assert_int_equal(out[0], 1 & 0xF0);
	assert_int_equal(out[1], 2);
	assert_int_equal(sim_line_next(&l), 120);
	/* chunks: 120 and 135 are within 20 of the next byte, 145 is not */
	assert_int_equal(sim_line_chunk_end(&l, 20), 135);
	assert_int_equal(sim_line_chunk_end(&l, 0), 120);
	assert_int_equal(sim_line_take(&l, 1000, out, 8), 3);
	assert_int_equal(sim_line_chunk_end(&l, 20), INT64_MAX);
	assert_int_equal(sim_line_next(&l), INT64_MAX);
	/* Overflow is counted, not crashed on. */
	for (int i = 0; i < SIM_LINE_CAP + 10; i++)
		sim_line_put(&l, 1000 + i * 20, 10, a, 1);
	assert_int_equal(l.overflows, 10);
}


#define BOTH(f) { #f " AX", f, NULL, NULL, (void *)(uintptr_t)&case_ax }, \
                { #f " X", f, NULL, NULL, (void *)(uintptr_t)&case_x }
#define ONE(f) { #f, f, NULL, NULL, NULL }

int main(void)
{
	const struct CMUnitTest tests[] = {
		BOTH(test_ping_timing),
		BOTH(test_adapter_latency_and_echo),
		BOTH(test_wrong_baud_no_reply),
		BOTH(test_bad_checksum_reply),
		BOTH(test_reply_faults),
		ONE(test_v1_broadcast_ping_collides),
		ONE(test_v1_conformance_through_library),
		ONE(test_v1_garbage_and_gap),
		ONE(test_v1_baud_register),
		ONE(test_v1_stuck_error_count_and_prob),
		ONE(test_v1_packet_inside_a_bad_packet),
		ONE(test_v2_ping_at_57600),
		ONE(test_v2_sync_read_order_and_missing),
		ONE(test_v2_fast_read),
		ONE(test_v2_broadcast_ping_in_id_order),
		ONE(test_v2_bad_crc_broadcast),
		ONE(test_v2_bad_input_counters),
		ONE(test_v2_faults),
		ONE(test_v2_stuck_error_vocabularies),
		ONE(test_bus_follows_pty_rate),
		ONE(test_link_has_one_owner),
		ONE(test_fault_parse_errors),
		ONE(test_line_queue),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
