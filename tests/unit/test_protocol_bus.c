/*
 * test_protocol_bus.c — bus transactions of both protocols over a fake
 * transport (busfake.h: an in-memory peer that answers each request with
 * scripted literal bytes after a scripted delay, and a fake clock that only
 * io->wait advances), so timeouts are checked to the microsecond. The shared
 * tests run once per backend (struct backend_case: that protocol's literal
 * packets and the numbers worked out by hand for them); what only one
 * protocol has stays in its own section.
 *
 * Every request and reply is a literal packet, never produced by our
 * encoder: the simulator reuses the encoder, so a symmetric bug would pass.
 * 1.0: the AX-12 manual's examples and hand-computed checksums. 2.0: typed
 * from the e-manual's "DYNAMIXEL Protocol 2.0" page (the same rows as
 * test_protocol_packet.c); hand-made packets (a stuffed reply, a damaged
 * CRC) say so.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "bus.h"
#include "busfake.h"
#include "dxl_proto.h"

static struct fake fk;
static struct bus bus;

/* 1 Mbps, return delay 0, 1 ms adapter latency, 500 µs margin. */
static const struct bus_timing timing = { 1000000, 0, 1000, 500 };

static void script(const uint8_t *reply, size_t n, uint64_t delay_us)
{
	fk.reply = reply;
	fk.reply_len = n;
	fk.reply_delay_us = delay_us;
}

/* ---- Protocol 1.0 vectors ----------------------------------------------------- */

/* Literal packets (manual examples and hand-computed checksums). */
static const uint8_t v1_ping1[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
static const uint8_t v1_ping1_reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
static const uint8_t v1_ping2_reply[] = { 0xFF, 0xFF, 0x02, 0x02, 0x00, 0xFB };
static const uint8_t v1_read_temp1[] = { 0xFF, 0xFF, 0x01, 0x04, 0x02, 0x2B, 0x01, 0xCC };
static const uint8_t v1_temp1_reply[] = { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB };
static const uint8_t v1_temp1_reply_bad[] = { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDA };
static const uint8_t v1_overload_reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x24, 0xD8 };
static const uint8_t v1_pos512_reply[] = { 0xFF, 0xFF, 0x01, 0x04, 0x00, 0x00, 0x02, 0xF8 };
static const uint8_t v1_sync_golden[] = { 0xFF, 0xFF, 0xFE, 0x0E, 0x83, 0x1E, 0x04, 0x00, 0x10, 0x00,
                                       0x50, 0x01, 0x01, 0x20, 0x02, 0x60, 0x03, 0x67 };
static const uint8_t v1_goal512_golden[] = { 0xFF, 0xFF, 0x01, 0x05, 0x03, 0x1E, 0x00, 0x02, 0xD6 };
static const uint8_t v1_bc_id1_golden[] = { 0xFF, 0xFF, 0xFE, 0x04, 0x03, 0x03, 0x01, 0xF6 };

/* A stray byte, then a header with ID 0xFF, which no packet has. */
static const uint8_t v1_noise[] = { 0x00, 0xFF, 0xFF, 0xFF };

/* ---- Protocol 2.0 vectors ----------------------------------------------------- */

#define HDR 0xFF, 0xFF, 0xFD, 0x00
/* e-manual, Protocol 2.0: Ping example 1 (ID 1: model 1030, firmware 38) */
static const uint8_t v2_ping1[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
static const uint8_t v2_ping1_reply[] = { HDR, 0x01, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D };
/* Ping example 2: broadcast, answered by ID 1 and ID 2 */
static const uint8_t v2_ping_bc[] = { HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42 };
static const uint8_t v2_ping2_reply[] = { HDR, 0x02, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x6F, 0x6D };
/* Read: ID 1, Present Position (132), 4 bytes -> 166 */
static const uint8_t v2_read_pos1[] = { HDR, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15 };
static const uint8_t v2_pos1_reply[] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0 };
/* Write: ID 1, Goal Position (116) = 512; its status */
static const uint8_t v2_write_goal1[] = { HDR, 0x01, 0x09, 0x00, 0x03, 0x74, 0x00, 0x00, 0x02, 0x00, 0x00, 0xCA, 0x89 };
static const uint8_t v2_ok1[] = { HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C };
/* Reg Write: ID 1, Goal Velocity (104) = 200 */
static const uint8_t v2_regw1[] = { HDR, 0x01, 0x09, 0x00, 0x04, 0x68, 0x00, 0xC8, 0x00, 0x00, 0x00, 0xAE, 0x8E };
static const uint8_t v2_action1[] = { HDR, 0x01, 0x03, 0x00, 0x05, 0x02, 0xCE };
static const uint8_t v2_reset1[] = { HDR, 0x01, 0x04, 0x00, 0x06, 0x01, 0xA1, 0xE6 };
static const uint8_t v2_reboot1[] = { HDR, 0x01, 0x03, 0x00, 0x08, 0x2F, 0x4E };
static const uint8_t v2_clear1[] = { HDR, 0x01, 0x08, 0x00, 0x10, 0x01, 0x44, 0x58, 0x4C, 0x22, 0xB1, 0xDC };
/* Sync Read: IDs 1, 2, Present Position (132), 4 bytes; ID 2's status
 * (ID 1's is v2_pos1_reply) */
static const uint8_t v2_sync_read12[] = { HDR, 0xFE, 0x09, 0x00, 0x82, 0x84, 0x00, 0x04, 0x00, 0x01, 0x02, 0xCE, 0xFA };
static const uint8_t v2_pos2_reply[] = { HDR, 0x02, 0x08, 0x00, 0x55, 0x00, 0x1F, 0x08, 0x00, 0x00, 0xBA, 0xBE };
/* Sync Write: ID 1 -> 150, ID 2 -> 170 at Goal Position */
static const uint8_t v2_sync_write12[] = { HDR, 0xFE, 0x11, 0x00, 0x83, 0x74, 0x00, 0x04, 0x00, 0x01, 0x96, 0x00,
                                        0x00, 0x00, 0x02, 0xAA, 0x00, 0x00, 0x00, 0x82, 0x87 };
/* Bulk Read: ID 1 voltage (144, 2 bytes), ID 2 temperature (146, 1 byte) */
static const uint8_t v2_bulk_read12[] = { HDR, 0xFE, 0x0D, 0x00, 0x92, 0x01, 0x90, 0x00, 0x02, 0x00, 0x02, 0x92,
                                       0x00, 0x01, 0x00, 0x1A, 0x05 };
static const uint8_t v2_volt1_reply[] = { HDR, 0x01, 0x06, 0x00, 0x55, 0x00, 0x77, 0x00, 0xC3, 0x69 };
static const uint8_t v2_temp2_reply[] = { HDR, 0x02, 0x05, 0x00, 0x55, 0x00, 0x24, 0x8B, 0xA9 };
/* Bulk Write: ID 1 LED (65)... as printed: ID 1 at 0x20 = A0 00, ID 2 at 0x1F = 50 */
static const uint8_t v2_bulk_write12[] = { HDR, 0xFE, 0x10, 0x00, 0x93, 0x01, 0x20, 0x00, 0x02, 0x00, 0xA0, 0x00,
                                        0x02, 0x1F, 0x00, 0x01, 0x00, 0x50, 0xB7, 0x68 };
/* Hand-stuffed (test_protocol_packet.c, the 2.0 table): a status of FF FF FD, and an
 * empty status with ERR 0x84 (alert | data range) */
static const uint8_t v2_stuffed1_reply[] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0x9A, 0x34 };
static const uint8_t v2_alert1[] = { HDR, 0x01, 0x04, 0x00, 0x55, 0x84, 0xB9, 0x0F };
/* v2_pos1_reply with its last CRC byte changed */
static const uint8_t v2_pos1_reply_bad[] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC1 };

/* A stray byte, then a header with ID 0xFF, which no packet has. */
static const uint8_t v2_noise[] = { 0x00, HDR, 0xFF };

/* Replies queued one after another, as a bus delivers them. */
static uint8_t queue[512];

/* ---- shared: one run per backend ------------------------------------------------ */

struct bytes {
	const uint8_t *p;
	size_t n;
};
#define V(a) { (a), sizeof (a) }

/* One protocol's literal vectors and the numbers worked out by hand for
 * them (wire time at 1 Mbps is 10 µs a byte; timing adds 1000 + 500 µs). */
struct backend_case {
	enum bus_protocol protocol;
	struct bytes ping, ping_reply, ping2_reply;  /* PING ID 1, its reply, ID 2's reply */
	uint64_t ping_timeout_us;                    /* PING to a silent ID */
	uint64_t ping_wire_us;                       /* PING and its reply on the wire */
	/* a READ: its request, reply, the reply damaged, the data it carries */
	uint16_t read_addr, read_len;
	struct bytes read, read_reply, read_reply_bad;
	const uint8_t *read_value;
	uint64_t read_timeout_us;                    /* that READ to a silent ID */
	uint16_t byte_addr;                          /* a 1-byte register */
	struct bytes data_reply;                     /* ID 1's status with data a PING has not */
	/* a WRITE's status with the servo's error, as the bus reports it */
	struct bytes err_reply, ok_reply;
	uint8_t err;
	uint32_t alerts;                             /* replies counted as alerts */
	uint16_t sync_addr;                          /* a SYNC_WRITE of 4 bytes to sync_ids */
	uint8_t sync_ids[2];
	size_t echo_corrupt_at;                      /* an echo byte after the header */
	struct bytes noise;                          /* garbage whose header is refused */
};

static struct backend_case case_v1 = {
	.protocol = BUS_PROTOCOL_1,
	.ping = V(v1_ping1), .ping_reply = V(v1_ping1_reply), .ping2_reply = V(v1_ping2_reply),
	.ping_timeout_us = 120 + 1500, .ping_wire_us = 120,
	.read_addr = 43, .read_len = 1,
	.read = V(v1_read_temp1), .read_reply = V(v1_temp1_reply), .read_reply_bad = V(v1_temp1_reply_bad),
	.read_value = (const uint8_t[]){ 32 },
	.read_timeout_us = 150 + 1500,
	.byte_addr = 43,
	.data_reply = V(v1_temp1_reply),
	.err_reply = V(v1_overload_reply), .ok_reply = V(v1_ping1_reply),
	.err = DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT, .alerts = 0,
	.sync_addr = 30, .sync_ids = { 0, 1 },
	.echo_corrupt_at = 3,
	.noise = V(v1_noise),
};

static struct backend_case case_v2 = {
	.protocol = BUS_PROTOCOL_2,
	.ping = V(v2_ping1), .ping_reply = V(v2_ping1_reply), .ping2_reply = V(v2_ping2_reply),
	/* the reply of 3 parameters at its worst stuffing: 15 bytes */
	.ping_timeout_us = 250 + 1500, .ping_wire_us = 240,
	.read_addr = 132, .read_len = 4,
	.read = V(v2_read_pos1), .read_reply = V(v2_pos1_reply), .read_reply_bad = V(v2_pos1_reply_bad),
	.read_value = (const uint8_t[]){ 0xA6, 0, 0, 0 },
	.read_timeout_us = 310 + 1500,   /* 14 bytes out, at most 17 back */
	.byte_addr = 146,
	.data_reply = V(v2_volt1_reply),
	.err_reply = V(v2_alert1), .ok_reply = V(v2_ok1),
	.err = DXL2_ERR_ALERT | DXL2_ERRNUM_DATA_RANGE, .alerts = 1,
	.sync_addr = 116, .sync_ids = { 1, 2 },
	.echo_corrupt_at = 6,
	.noise = V(v2_noise),
};

static const struct backend_case *case_of(void **state)
{
	const struct backend_case *c = *state;
	print_message("# Protocol %d\n", (int)c->protocol);
	return c;
}

static void setup_bus(const struct backend_case *c, bool echo)
{
	memset(&fk, 0, sizeof fk);
	fk.now = 1000000;
	fk.echo = echo;
	const struct bus_io io = { &fk, fake_write, fake_read, fake_wait, fake_now, fake_flush, NULL };
	bus_init(&bus, &io, &timing, echo);
	assert_int_equal(bus_set_protocol(&bus, c->protocol), DXL_OK);
}

static void script_bytes(struct bytes b, uint64_t delay_us)
{
	script(b.p, b.n, delay_us);
}

/* The bus's parser counters, from the union its table fills. */
static uint32_t parser_checksum_errors(const struct backend_case *c)
{
	return c->protocol == BUS_PROTOCOL_1 ? bus.parser.v1.checksum_errors : bus.parser.v2.checksum_errors;
}

static uint32_t parser_bytes_dropped(const struct backend_case *c)
{
	return c->protocol == BUS_PROTOCOL_1 ? bus.parser.v1.bytes_dropped : bus.parser.v2.bytes_dropped;
}

/* The transport can say what is waiting: a request flushes the input only
 * when there is something, or the line is dirty (a timeout, a damaged or
 * stray reply) — on a tty every flush may wait for the kernel's worker. */
static void test_flush_only_when_needed(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	bus.io.pending_input = fake_pending;
	script_bytes(c->ping_reply, 80);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.flushes, 1);           /* the first request: the line is unknown */
	for (int i = 0; i < 5; i++) {
		script_bytes(c->ping_reply, 80);
		assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	}
	assert_int_equal(fk.flushes, 1);           /* clean transactions: never again */
	assert_int_equal(bus_ping(&bus, 7, NULL), DXL_E_TIMEOUT);
	script_bytes(c->ping_reply, 80);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.flushes, 2);           /* after the timeout: flushed */
	/* bytes waiting (a servo answering late, unasked) are flushed too */
	fake_push(&fk, c->ping2_reply.p, c->ping2_reply.n, fk.now);
	script_bytes(c->ping_reply, 80);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.flushes, 3);
	assert_int_equal(bus.stray_packets, 0);
}

static void test_ping(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	script_bytes(c->ping_reply, 80);
	uint8_t err = 0xEE;
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_int_equal(err, 0);
	assert_int_equal(fk.ntx, c->ping.n);
	assert_memory_equal(fk.tx, c->ping.p, c->ping.n);
	assert_int_equal(fk.now, 1000000 + 80);
	assert_int_equal(fk.flushes, 1);
	const struct bus_servo_stats *st = &bus.servo[1];
	assert_int_equal(st->transactions, 1);
	assert_int_equal(st->replies, 1);
	assert_int_equal(st->rtt_last_us, 80);
	assert_int_equal(st->rtt_max_us, 80);
	assert_int_equal(st->rtt_sum_us, 80);
	assert_int_equal(bus.bytes_out, c->ping.n);
	assert_int_equal(bus.bytes_in, c->ping_reply.n);
	assert_false(bus_is_pending(&bus));
}

/* No reply: DXL_E_TIMEOUT after exactly the derived timeout; a reply just
 * at the deadline is on time, 1 µs later is not. */
static void test_timeout_exact(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	uint64_t start = fk.now;
	assert_int_equal(bus_ping(&bus, 7, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, c->ping_timeout_us);
	assert_int_equal(bus.servo[7].timeouts, 1);
	assert_int_equal(bus.servo[7].transactions, 1);
	assert_int_equal(bus.servo[7].replies, 0);

	start = fk.now;
	uint8_t out[8];
	assert_int_equal(bus_read(&bus, 7, c->read_addr, c->read_len, out, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, c->read_timeout_us);

	start = fk.now;
	script_bytes(c->ping_reply, c->ping_timeout_us + 1);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, c->ping_timeout_us);
	fk.now += 10000; /* let the late one arrive; the next request flushes it */
	start = fk.now;
	script_bytes(c->ping_reply, c->ping_timeout_us);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.now - start, c->ping_timeout_us);
}

static void test_wrong_id(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	script_bytes(c->ping2_reply, 50);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_WRONG_ID);
	assert_int_equal(bus.servo[1].wrong_id, 1);
	assert_int_equal(bus.servo[1].replies, 0);
	assert_int_equal(bus.servo[2].replies, 0);
	assert_false(bus_is_pending(&bus));
}

static void test_wrong_length(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	/* READ of 1 byte answered with a PING's reply */
	script_bytes(c->ping_reply, 50);
	uint8_t v;
	assert_int_equal(bus_read_u8(&bus, 1, c->byte_addr, &v, NULL), DXL_E_WRONG_LENGTH);
	assert_int_equal(bus.servo[1].wrong_length, 1);
	/* PING answered with data */
	script_bytes(c->data_reply, 50);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_WRONG_LENGTH);
	assert_int_equal(bus.servo[1].wrong_length, 2);
}

/* A damaged reply fails at once (not at the deadline) and is counted. */
static void test_checksum_error(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	script_bytes(c->read_reply_bad, 70);
	uint64_t start = fk.now;
	uint8_t out[8];
	assert_int_equal(bus_read(&bus, 1, c->read_addr, c->read_len, out, NULL), DXL_E_CHECKSUM);
	assert_int_equal(fk.now - start, 70);
	assert_int_equal(bus.servo[1].checksum_errors, 1);
	assert_int_equal(parser_checksum_errors(c), 1);
	assert_int_equal(bus.servo[1].replies, 0);
}

/* The servo's error bits (1.0) or ERR field (2.0) are data: the call
 * succeeds, reports them, and they are counted. */
static void test_error_bits(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	script_bytes(c->err_reply, 40);
	uint8_t err = 0;
	assert_int_equal(bus_write_u8(&bus, 1, 65, 1, &err), DXL_OK);
	assert_int_equal(err, c->err);
	assert_int_equal(bus.servo[1].error_replies, 1);
	assert_int_equal(bus.servo[1].last_errbits, c->err);
	assert_int_equal(bus.servo[1].errbits_seen, c->err);
	assert_int_equal(bus.servo[1].alerts, c->alerts);
	script_bytes(c->ok_reply, 40);
	assert_int_equal(bus_write_u8(&bus, 1, 65, 0, &err), DXL_OK);
	assert_int_equal(err, 0);
	assert_int_equal(bus.servo[1].error_replies, 1);
	assert_int_equal(bus.servo[1].last_errbits, 0);
	assert_int_equal(bus.servo[1].errbits_seen, c->err);
	assert_int_equal(bus.servo[1].alerts, c->alerts);
	assert_int_equal(bus.servo[1].replies, 2);
}

/* Single-wire wiring: our own bytes come back first and are discarded. */
static void test_echo(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, true);
	script_bytes(c->ping_reply, 100);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(bus.servo[1].replies, 1);
	assert_int_equal(bus.bytes_in, c->ping.n + c->ping_reply.n);
	assert_int_equal(parser_bytes_dropped(c), 0);
	assert_int_equal(bus.echo_errors, 0);

	/* the echo of a reply-less SYNC_WRITE arrives after the next request
	 * started: it is still matched and discarded */
	fk.echo_delay_us = 50;
	uint8_t data[8] = { 0 };
	assert_int_equal(bus_sync_write(&bus, c->sync_addr, 4, c->sync_ids, data, 2), DXL_OK);
	script_bytes(c->read_reply, 150);
	assert_int_equal(bus_read(&bus, 1, c->read_addr, c->read_len, data, NULL), DXL_OK);
	assert_memory_equal(data, c->read_value, c->read_len);
	assert_int_equal(bus.echo_errors, 0);

	/* a differing echo byte is DXL_E_ECHO */
	fk.echo_delay_us = 0;
	fk.echo_corrupt_at = c->echo_corrupt_at;
	script_bytes(c->ping_reply, 100);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_ECHO);
	assert_int_equal(bus.echo_errors, 1);
	assert_false(bus_is_pending(&bus));
	fk.echo_corrupt_at = 0;

	/* echo off but the wiring echoes: the echo is set aside and the real
	 * reply behind it delivered */
	setup_bus(c, false);
	fk.echo = true;
	script_bytes(c->ping_reply, 100);
	uint8_t err = 0xEE;
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_int_equal(err, 0);
	assert_int_equal(bus.unexpected_echoes, 1);
}

static void test_stale_input_and_strays(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	/* stale bytes from before the request are flushed */
	fake_push(&fk, c->read_reply.p, c->read_reply.n, fk.now);
	script_bytes(c->ping_reply, 30);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(bus.stray_packets, 0);

	/* garbage before the reply: resynced, counted, reply delivered */
	static uint8_t noisy[64];
	memcpy(noisy, c->noise.p, c->noise.n);
	memcpy(noisy + c->noise.n, c->ping_reply.p, c->ping_reply.n);
	script(noisy, c->noise.n + c->ping_reply.n, 30);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_true(bus.servo[1].resyncs >= 1);

	/* a second packet in the same read is a stray */
	static uint8_t two[64];
	memcpy(two, c->ping_reply.p, c->ping_reply.n);
	memcpy(two + c->ping_reply.n, c->ping2_reply.p, c->ping2_reply.n);
	script(two, c->ping_reply.n + c->ping2_reply.n, 30);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(bus.stray_packets, 1);
	assert_int_equal(bus.servo[1].wrong_id, 0);
}

/* After a failed transaction, a blocking caller that will try again waits
 * for the line to go quiet: a reply that was only late lands in the wait,
 * not on top of the next request (on a half-duplex bus the two would
 * collide). */
static void test_settle(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	bus.io.pending_input = fake_pending;
	/* nothing comes: quiet at once, after quiet_us */
	uint64_t start = fk.now;
	assert_int_equal(bus_settle(&bus, 5000, 50000), 0);
	assert_int_equal(fk.now - start, 5000);

	/* a ping whose reply comes 2 ms after the deadline */
	script_bytes(c->ping_reply, c->ping_timeout_us + 2000);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_TIMEOUT);
	start = fk.now;
	assert_int_equal(bus_settle(&bus, 5000, 50000), (int)c->ping_reply.n);
	assert_int_equal(fk.now - start, 2000 + 5000);   /* the late reply, then 5 ms of quiet */
	unsigned flushes = fk.flushes;
	script_bytes(c->ping_reply, 80);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.flushes, flushes);            /* the line is known clean */
	assert_int_equal(bus.stray_packets, 0);

	/* a line that never goes quiet: given up after max_us, still dirty */
	for (int i = 0; i < 40; i++)
		fake_push(&fk, c->ping2_reply.p, c->ping2_reply.n, fk.now + 1000u * (unsigned)i);
	start = fk.now;
	assert_true(bus_settle(&bus, 5000, 20000) > 0);
	assert_true(fk.now - start >= 20000 && fk.now - start < 21000);
	assert_true(bus.line_dirty);

	/* not while a transaction is pending */
	assert_int_equal(bus_begin(&bus, 1, DXL_INST_PING, NULL, 0, 0), DXL_OK);
	assert_int_equal(bus_settle(&bus, 5000, 50000), DXL_E_BUSY);
	bus_abort(&bus);
}

/* After a timeout, a late reply is told from none (`dxl`'s message): bytes
 * after the deadline, how late the first came, the ID of the packet. */
static void test_listen_late(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	struct bus_late late;
	/* nothing comes: the whole window, nothing seen */
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_TIMEOUT);
	uint64_t start = fk.now;
	assert_int_equal(bus_listen_late(&bus, 30000, &late), DXL_OK);
	assert_int_equal(late.bytes, 0);
	assert_int_equal(late.id, -1);
	assert_int_equal(fk.now - start, 30000);
	assert_int_equal(late.waited_us, c->ping_timeout_us);

	/* a reply 7 ms after the deadline: named, and how late; the wait ends with it */
	script_bytes(c->ping_reply, c->ping_timeout_us + 7000);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_TIMEOUT);
	start = fk.now;
	assert_int_equal(bus_listen_late(&bus, 30000, &late), DXL_OK);
	assert_int_equal(late.bytes, (long)c->ping_reply.n);
	assert_int_equal(late.id, 1);
	assert_true(late.after_us >= 7000 && late.after_us < 8000);
	assert_true(fk.now - start < 8000);
	assert_true(bus.line_dirty);   /* the next request flushes */

	/* bytes that are no packet: counted, no ID */
	static const uint8_t noise[] = { 0x55, 0x00, 0x13 };
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_TIMEOUT);
	fake_push(&fk, noise, sizeof noise, fk.now + 1000);
	assert_int_equal(bus_listen_late(&bus, 30000, &late), DXL_OK);
	assert_int_equal(late.bytes, 3);
	assert_int_equal(late.id, -1);

	/* not while a transaction is pending */
	assert_int_equal(bus_begin(&bus, 1, DXL_INST_PING, NULL, 0, 0), DXL_OK);
	assert_int_equal(bus_listen_late(&bus, 30000, &late), DXL_E_BUSY);
	bus_abort(&bus);
}

static void test_io_errors_and_args(void **state)
{
	const struct backend_case *c = case_of(state);
	setup_bus(c, false);
	fk.write_error = DXL_E_DISCONNECTED;
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_DISCONNECTED);
	assert_int_equal(bus.io_errors, 1);
	assert_false(bus_is_pending(&bus));
	fk.write_error = 0;
	uint8_t out[4];
	assert_int_equal(bus_read(&bus, 1, 36, 0, out, NULL), DXL_E_ARG);
	assert_int_equal(bus_read(&bus, DXL_BROADCAST_ID, 36, 2, out, NULL), DXL_E_ARG);
	assert_int_equal(bus_ping(&bus, 0xFF, NULL), DXL_E_ARG);
	assert_int_equal(bus_write(&bus, 1, 30, out, 0, true, NULL), DXL_E_ARG);
	assert_int_equal(fk.writes, 1);

	bus_reset_stats(&bus);
	assert_int_equal(bus.io_errors, 0);
	assert_int_equal(bus.bytes_out, 0);
}

/* Reply lateness: round trip less the PING's and reply's wire time and the
 * return delay; the lower median, the extremes; lost PINGs counted apart. */
static void test_reply_lateness(void **state)
{
	const struct backend_case *c = case_of(state);
	struct bus_lateness lt;
	/* an FTDI adapter at its 16 ms default, once a bit less, once a reader
	 * late; round trips = floor + 500 µs return delay + the hold */
	static const uint64_t hold[] = { 16000, 16000, 12000, 16000, 21000, 16000 };
	uint64_t held[6];
	for (size_t i = 0; i < 6; i++)
		held[i] = c->ping_wire_us + 500 + hold[i];
	/* the probe's timeout must outlast the hold it measures */
	static const struct bus_timing patient = { 1000000, 500, 0, 30000 };
	setup_bus(c, false);
	bus_set_timing(&bus, &patient);
	script_bytes(c->ping_reply, 0);
	fk.reply_every = true;
	fk.delays = held;
	fk.ndelays = 6;
	assert_int_equal(bus_reply_lateness(&bus, 1, 500, 6, &lt), DXL_OK);
	assert_int_equal(lt.pings, 6);
	assert_int_equal(lt.replies, 6);
	assert_int_equal(lt.min_us, 12000);
	assert_int_equal(lt.median_us, 16000);
	assert_int_equal(lt.max_us, 21000);
	assert_int_equal(fk.writes, 6);

	/* no hold at all: the floor itself, never below 0 */
	const uint64_t prompt[] = { c->ping_wire_us - 20, c->ping_wire_us, c->ping_wire_us + 10 };
	setup_bus(c, false);
	script_bytes(c->ping_reply, 0);
	fk.reply_every = true;
	fk.delays = prompt;
	fk.ndelays = 3;
	assert_int_equal(bus_reply_lateness(&bus, 1, 0, 3, &lt), DXL_OK);
	assert_int_equal(lt.min_us, 0);
	assert_int_equal(lt.median_us, 0);
	assert_int_equal(lt.max_us, 10);

	/* lost PINGs: counted, not taken as late replies */
	const uint64_t lossy[] = { c->ping_wire_us + 1000, UINT64_MAX };
	setup_bus(c, false);
	script_bytes(c->ping_reply, 0);
	fk.reply_every = true;
	fk.delays = lossy;
	fk.ndelays = 2;
	assert_int_equal(bus_reply_lateness(&bus, 1, 0, 4, &lt), DXL_OK);
	assert_int_equal(lt.pings, 4);
	assert_int_equal(lt.replies, 2);
	assert_int_equal(lt.median_us, 1000);

	/* nobody there: the PING's own status; more than BUS_LATENESS_MAX asked is capped */
	setup_bus(c, false);
	assert_int_equal(bus_reply_lateness(&bus, 9, 0, 1000, &lt), DXL_E_TIMEOUT);
	assert_int_equal(lt.pings, BUS_LATENESS_MAX);
	assert_int_equal(lt.replies, 0);
	assert_int_equal(bus_reply_lateness(&bus, 9, 0, 0, &lt), DXL_E_ARG);
	/* the port gone: stop at once */
	setup_bus(c, false);
	fk.write_error = DXL_E_DISCONNECTED;
	assert_int_equal(bus_reply_lateness(&bus, 1, 0, 8, &lt), DXL_E_DISCONNECTED);
	assert_int_equal(lt.pings, 1);
}

/* ---- Protocol 1.0 only ---------------------------------------------------------- */

/* A bus closed before it was given a protocol (the daemon refusing an
 * RS-485 wiring closes its port before bus_init) is aborted without a
 * parser to reset: it crashed the daemon once (exit 139). */
static void test_abort_before_init(void **state)
{
	(void)state;
	struct bus b;
	memset(&b, 0, sizeof b);
	bus_abort(&b);
	assert_false(bus_is_pending(&b));
}

static void test_v1_timeout_formula(void **state)
{
	(void)state;
	setup_bus(&case_v1, false);
	/* 12 bytes at 1 Mbps = 120 µs, + latency 1000 + margin 500 */
	assert_int_equal(bus_wire_time_us(&bus, 12), 120);
	assert_int_equal(bus_timeout_us(&bus, 6, 6), 1620);
	/* READ(36, 6) at 57600 with the default 500 µs return delay:
	 * 20 bytes = 200 bits / 57600 = 3472.2 µs, rounded up */
	struct bus_timing slow = { 57600, 500, 16000, 0 };
	bus_set_timing(&bus, &slow);
	assert_int_equal(bus_wire_time_us(&bus, 20), 3473);
	assert_int_equal(bus_timeout_us(&bus, 8, 12), 3473 + 500 + 16000);
}

static void test_v1_read_returns_data(void **state)
{
	(void)state;
	setup_bus(&case_v1, false);
	script(v1_temp1_reply, sizeof v1_temp1_reply, 100);
	uint8_t temp = 0, err = 0xEE;
	assert_int_equal(bus_read_u8(&bus, 1, 43, &temp, &err), DXL_OK);
	assert_memory_equal(fk.tx, v1_read_temp1, sizeof v1_read_temp1);
	assert_int_equal(temp, 32);
	assert_int_equal(err, 0);

	/* a fragmented 16-bit reply */
	fk.max_chunk = 3;
	script(v1_pos512_reply, sizeof v1_pos512_reply, 100);
	uint16_t pos = 0;
	assert_int_equal(bus_read_u16(&bus, 1, 36, &pos, &err), DXL_OK);
	assert_int_equal(pos, 512);
	assert_int_equal(bus.servo[1].replies, 2);
}

/* The asynchronous core, driven as the daemon's poll loop would. */
static void test_v1_async(void **state)
{
	(void)state;
	setup_bus(&case_v1, false);
	script(v1_temp1_reply, sizeof v1_temp1_reply, 300);
	const uint8_t params[2] = { 43, 1 };
	uint64_t start = fk.now;
	assert_int_equal(bus_begin(&bus, 1, DXL_INST_READ, params, 2, 1), DXL_OK);
	assert_true(bus_is_pending(&bus));
	assert_int_equal(bus_deadline_us(&bus), start + bus_timeout_us(&bus, 8, 7));
	struct dxl_packet reply;
	assert_int_equal(bus_step(&bus, &reply), BUS_PENDING);
	assert_int_equal(bus_begin(&bus, 2, DXL_INST_PING, NULL, 0, 0), DXL_E_BUSY);
	fk.now += 299;
	assert_int_equal(bus_step(&bus, &reply), BUS_PENDING);
	fk.now += 1;
	assert_int_equal(bus_step(&bus, &reply), DXL_OK);
	assert_int_equal(reply.nparams, 1);
	assert_int_equal(reply.params[0], 32);
	assert_false(bus_is_pending(&bus));
	assert_int_equal(fk.waits, 0);

	/* abort: nothing pending afterwards, the next request works */
	assert_int_equal(bus_begin(&bus, 1, DXL_INST_PING, NULL, 0, 0), DXL_OK);
	bus_abort(&bus);
	assert_false(bus_is_pending(&bus));
	script(v1_ping1_reply, sizeof v1_ping1_reply, 10);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
}

/* Broadcast and SYNC_WRITE wait for nothing, even if asked to. */
static void test_v1_no_wait(void **state)
{
	(void)state;
	setup_bus(&case_v1, false);
	uint64_t start = fk.now;
	const uint8_t ids[2] = { 0, 1 };
	uint8_t data[8];
	dxl_put_u16(data + 0, 0x010);
	dxl_put_u16(data + 2, 0x150);
	dxl_put_u16(data + 4, 0x220);
	dxl_put_u16(data + 6, 0x360);
	assert_int_equal(bus_sync_write(&bus, 30, 4, ids, data, 2), DXL_OK);
	assert_memory_equal(fk.tx, v1_sync_golden, sizeof v1_sync_golden);
	uint8_t err = 0xEE;
	assert_int_equal(bus_write_u8(&bus, DXL_BROADCAST_ID, 3, 1, &err), DXL_OK);
	assert_memory_equal(fk.tx + sizeof v1_sync_golden, v1_bc_id1_golden, sizeof v1_bc_id1_golden);
	assert_int_equal(err, 0);
	assert_int_equal(bus_action(&bus, DXL_BROADCAST_ID, true, NULL), DXL_OK);
	assert_int_equal(bus_begin(&bus, DXL_BROADCAST_ID, DXL_INST_PING, NULL, 0, 0), DXL_OK);
	assert_false(bus_is_pending(&bus));
	/* a unicast write with status return level < 2 */
	uint8_t goal[2];
	dxl_put_u16(goal, 512);
	size_t before = fk.ntx;
	assert_int_equal(bus_write(&bus, 1, 30, goal, 2, false, NULL), DXL_OK);
	assert_memory_equal(fk.tx + before, v1_goal512_golden, sizeof v1_goal512_golden);
	assert_int_equal(fk.waits, 0);
	assert_int_equal(fk.now, start);
	assert_int_equal(bus.servo[1].transactions, 0);
}

/* A genuine reply identical to the request (PING answered with the
 * input-voltage bit) is still delivered, at the deadline. */
static void test_v1_reply_like_request(void **state)
{
	(void)state;
	setup_bus(&case_v1, false);
	static const uint8_t voltage_reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	script(voltage_reply, sizeof voltage_reply, 100);
	uint64_t start = fk.now;
	uint8_t err = 0;
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_int_equal(err, DXL_ERRBIT_VOLTAGE);
	assert_int_equal(fk.now - start, 1620);
	assert_int_equal(bus.servo[1].replies, 1);
	assert_int_equal(bus.servo[1].timeouts, 0);
	assert_int_equal(bus.unexpected_echoes, 0);
}

/* READ(36, 8) to a silent ID: 8 + 14 bytes. */
static void test_v1_timeout_read8(void **state)
{
	(void)state;
	setup_bus(&case_v1, false);
	uint64_t start = fk.now;
	uint8_t out[8];
	assert_int_equal(bus_read(&bus, 7, 36, 8, out, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, 220 + 1000 + 500);
}

/* The rest of the echo cases on 1.0, whose request reads as a status. */
static void test_v1_echo_wiring(void **state)
{
	(void)state;
	/* echo expected but the wiring has none: the reply is not our echo */
	setup_bus(&case_v1, true);
	fk.echo = false;
	script(v1_ping1_reply, sizeof v1_ping1_reply, 100);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_ECHO);
	assert_int_equal(bus.echo_errors, 1);

	/* echo off but the wiring echoes: a PING's echo reads as a valid status
	 * packet with the input-voltage bit (FF FF 01 02 01 FB); it is held, and
	 * the real reply behind it wins; the same for READ(36, 2), whose echo
	 * looks like 2 bytes of data */
	setup_bus(&case_v1, false);
	fk.echo = true;
	uint8_t err = 0xEE;
	script(v1_ping1_reply, sizeof v1_ping1_reply, 100);
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_int_equal(bus.unexpected_echoes, 1);
	uint16_t pos = 0;
	script(v1_pos512_reply, sizeof v1_pos512_reply, 100);
	assert_int_equal(bus_read_u16(&bus, 1, 36, &pos, &err), DXL_OK);
	assert_int_equal(pos, 512);
	assert_int_equal(err, 0);
	assert_int_equal(bus.unexpected_echoes, 2);
}

/* ---- Protocol 2.0 only ---------------------------------------------------------- */

static void test_v2_protocol_switch(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	assert_int_equal(bus_get_protocol(&bus), BUS_PROTOCOL_2);
	assert_int_equal(bus_set_protocol(&bus, (enum bus_protocol)3), DXL_E_ARG);
	uint8_t out[2], err = 0;
	/* one API: what 1.0 cannot do is refused on a 1.0 bus, nothing sent;
	 * what it can (a READ of an address past its 8 bits aside) goes out */
	assert_int_equal(bus_set_protocol(&bus, BUS_PROTOCOL_1), DXL_OK);
	assert_int_equal(bus_read(&bus, 1, 0x100, 4, out, &err), DXL_E_ARG);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, &err), DXL_E_UNSUPPORTED);
	assert_int_equal(bus_reboot(&bus, 1, true, &err), DXL_E_UNSUPPORTED);
	assert_int_equal(bus_clear_multi_turn(&bus, 1, true, &err), DXL_E_UNSUPPORTED);
	assert_int_equal(bus_factory_reset(&bus, 1, DXL_RESET_KEEP_ID, false, &err), DXL_E_ARG);
	assert_int_equal(bus_bulk_write(&bus, (const struct dxl_item[]){ { 1, 30, 1, out } }, 1), DXL_E_UNSUPPORTED);
	size_t nfound = 9;
	struct bus_found found[1];
	assert_int_equal(bus_ping_all(&bus, found, 1, &nfound), DXL_E_UNSUPPORTED);
	assert_int_equal(nfound, 0);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	assert_int_equal(bus_sync_read_begin(&bus, 132, 4, (const uint8_t[]){ 1, 2 }, 2, &m), DXL_E_UNSUPPORTED);
	assert_int_equal(bus_bulk_read_begin(&bus, (const struct dxl_item[]){ { 1, 36, 2, NULL } }, 1, &m),
	                 DXL_E_UNSUPPORTED);
	assert_int_equal(fk.writes, 0);
	/* not while a transaction is pending */
	assert_int_equal(bus_set_protocol(&bus, BUS_PROTOCOL_2), DXL_OK);
	assert_int_equal(bus_begin(&bus, 1, DXL2_INST_PING, NULL, 0, 3), DXL_OK);
	assert_int_equal(bus_set_protocol(&bus, BUS_PROTOCOL_1), DXL_E_BUSY);
	bus_abort(&bus);
	/* SYNC_READ and BULK_READ have their own begin */
	assert_int_equal(bus_begin(&bus, DXL2_BROADCAST_ID, DXL2_INST_SYNC_READ, v2_sync_read12 + 8, 6, 4), DXL_E_ARG);
}

static void test_v2_ping_model(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	script(v2_ping1_reply, sizeof v2_ping1_reply, 90);
	uint16_t model = 0;
	uint8_t fw = 0, err = 0xEE;
	assert_int_equal(bus_ping_model(&bus, 1, &model, &fw, &err), DXL_OK);
	assert_int_equal(fk.ntx, sizeof v2_ping1);
	assert_memory_equal(fk.tx, v2_ping1, sizeof v2_ping1);
	assert_int_equal(model, 1030);
	assert_int_equal(fw, 38);
	assert_int_equal(err, 0);
	assert_int_equal(fk.now, 1000000 + 90);
	assert_int_equal(bus.servo[1].transactions, 1);
	assert_int_equal(bus.servo[1].replies, 1);
	assert_int_equal(bus.servo[1].rtt_last_us, 90);
	assert_int_equal(bus.bytes_out, 10);
	assert_int_equal(bus.bytes_in, 14);
	/* bus_ping speaks 2.0 on a 2.0 bus */
	script(v2_ping1_reply, sizeof v2_ping1_reply, 90);
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_memory_equal(fk.tx + 10, v2_ping1, sizeof v2_ping1);
	assert_int_equal(bus_reply(&bus)->nparams, 3);
	/* broadcast is for bus_ping_all */
	assert_int_equal(bus_ping_model(&bus, DXL2_BROADCAST_ID, &model, &fw, &err), DXL_E_ARG);
}

static void test_v2_read_write_golden(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	uint32_t pos = 0;
	uint8_t err = 0xEE;
	script(v2_pos1_reply, sizeof v2_pos1_reply, 120);
	assert_int_equal(bus_read_u32(&bus, 1, 132, &pos, &err), DXL_OK);
	assert_memory_equal(fk.tx, v2_read_pos1, sizeof v2_read_pos1);
	assert_int_equal(pos, 166);
	assert_int_equal(err, 0);
	size_t at = fk.ntx;
	script(v2_ok1, sizeof v2_ok1, 60);
	assert_int_equal(bus_write_u32(&bus, 1, 116, 512, &err), DXL_OK);
	assert_memory_equal(fk.tx + at, v2_write_goal1, sizeof v2_write_goal1);
	const uint8_t vel200[4] = { 0xC8, 0, 0, 0 };
	struct row {
		const uint8_t *want;
		size_t n;
		int r;
	} rows[5];
	at = fk.ntx;
	script(v2_ok1, sizeof v2_ok1, 60);
	rows[0] = (struct row){ v2_regw1, sizeof v2_regw1, bus_reg_write(&bus, 1, 104, vel200, 4, true, &err) };
	script(v2_ok1, sizeof v2_ok1, 60);
	rows[1] = (struct row){ v2_action1, sizeof v2_action1, bus_action(&bus, 1, true, &err) };
	script(v2_ok1, sizeof v2_ok1, 60);
	rows[2] = (struct row){ v2_reset1, sizeof v2_reset1, bus_factory_reset(&bus, 1, DXL2_RESET_KEEP_ID, true, &err) };
	script(v2_ok1, sizeof v2_ok1, 60);
	rows[3] = (struct row){ v2_reboot1, sizeof v2_reboot1, bus_reboot(&bus, 1, true, &err) };
	script(v2_ok1, sizeof v2_ok1, 60);
	rows[4] = (struct row){ v2_clear1, sizeof v2_clear1, bus_clear_multi_turn(&bus, 1, true, &err) };
	for (size_t i = 0; i < 5; i++) {
		assert_int_equal(rows[i].r, DXL_OK);
		assert_memory_equal(fk.tx + at, rows[i].want, rows[i].n);
		at += rows[i].n;
	}
	assert_int_equal(bus.servo[1].replies, 7);
	/* never broadcast + reset all; nothing sent */
	assert_int_equal(bus_factory_reset(&bus, DXL2_BROADCAST_ID, DXL2_RESET_ALL, false, &err), DXL_E_ARG);
	assert_int_equal(fk.ntx, at);
	/* a reply whose data is stuffed: FF FF FD comes back unstuffed */
	uint8_t three[3];
	script(v2_stuffed1_reply, sizeof v2_stuffed1_reply, 80);
	assert_int_equal(bus_read(&bus, 1, 0, 3, three, &err), DXL_OK);
	assert_memory_equal(three, ((const uint8_t[]){ 0xFF, 0xFF, 0xFD }), 3);
}

/* SYNC_READ: one request, one reply per servo, each checked. */
static void test_v2_sync_read(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const uint8_t ids[2] = { 1, 2 };
	size_t n = 0;
	memcpy(queue, v2_pos1_reply, sizeof v2_pos1_reply);
	memcpy(queue + sizeof v2_pos1_reply, v2_pos2_reply, sizeof v2_pos2_reply);
	n = sizeof v2_pos1_reply + sizeof v2_pos2_reply;
	script(queue, n, 100);
	uint64_t start = fk.now;
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_OK);
	assert_memory_equal(fk.tx, v2_sync_read12, sizeof v2_sync_read12);
	assert_int_equal(fk.now - start, 100);   /* done with the last reply, not at the deadline */
	assert_int_equal(m.n, 2);
	assert_int_equal(m.answered, 2);
	assert_int_equal(dxl2_get_u32(bus_multi_data(&m, 0)), 166);
	assert_int_equal(dxl2_get_u32(bus_multi_data(&m, 1)), 2079);
	assert_int_equal(m.status[1], DXL_OK);
	assert_int_equal(bus.servo[1].replies, 1);
	assert_int_equal(bus.servo[2].replies, 1);
	assert_int_equal(bus.servo[2].transactions, 1);
	assert_int_equal(bus_multi_failed(&m, NULL, 0), 0);
	/* the buffer must hold every reply */
	struct bus_multi small = { .data = data, .cap = 7 };
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &small), DXL_E_BUFFER);
	/* bad lists: refused before anything is sent */
	size_t before = fk.ntx;
	assert_int_equal(bus_sync_read(&bus, 132, 4, (const uint8_t[]){ 1, 1 }, 2, &m), DXL_E_ARG);
	assert_int_equal(bus_sync_read(&bus, 132, 0, ids, 2, &m), DXL_E_ARG);
	assert_int_equal(fk.ntx, before);
}

/* A servo missing costs the derived timeout of all replies; the replies
 * that came are delivered, the missing one named. */
static void test_v2_sync_read_missing(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const uint8_t ids[2] = { 1, 2 };
	script(v2_pos1_reply, sizeof v2_pos1_reply, 100);
	uint64_t start = fk.now;
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_E_TIMEOUT);
	/* 14 + 2 bytes out, 2 x 17 back at worst, two return delays (0 here) */
	const uint16_t lens[2] = { 4, 4 };
	assert_int_equal(bus_multi_timeout_us(&bus, 16, lens, 2), 500 + 1000 + 500);
	assert_int_equal(fk.now - start, 2000);
	assert_int_equal(dxl2_get_u32(bus_multi_data(&m, 0)), 166);
	assert_null(bus_multi_data(&m, 1));
	uint8_t missing[4];
	assert_int_equal(bus_multi_failed(&m, missing, 4), 1);
	assert_int_equal(missing[0], 2);
	assert_int_equal(m.status[1], DXL_E_TIMEOUT);
	assert_int_equal(bus.servo[2].timeouts, 1);
	assert_int_equal(bus.servo[1].timeouts, 0);
	assert_true(bus.line_dirty);
	/* the first servo missing, the second answering: out of order, accepted */
	script(v2_pos2_reply, sizeof v2_pos2_reply, 100);
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_E_TIMEOUT);
	assert_int_equal(m.status[0], DXL_E_TIMEOUT);
	assert_int_equal(dxl2_get_u32(bus_multi_data(&m, 1)), 2079);
	assert_int_equal(m.track.out_of_order, 1);
	/* the return delay counts once per reply */
	const struct bus_timing rd = { 1000000, 500, 1000, 500 };
	bus_set_timing(&bus, &rd);
	assert_int_equal(bus_multi_timeout_us(&bus, 16, lens, 2), 500 + 2 * 500 + 1000 + 500);
}

static void test_v2_sync_read_bad_replies(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const uint8_t ids[2] = { 1, 2 };
	/* ID 1's reply damaged, ID 2's good: settled when ID 2's arrives */
	memcpy(queue, v2_pos1_reply_bad, sizeof v2_pos1_reply_bad);
	memcpy(queue + sizeof v2_pos1_reply_bad, v2_pos2_reply, sizeof v2_pos2_reply);
	script(queue, sizeof v2_pos1_reply_bad + sizeof v2_pos2_reply, 100);
	uint64_t start = fk.now;
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_E_CHECKSUM);
	assert_int_equal(fk.now - start, 100);
	assert_int_equal(m.status[0], DXL_E_CHECKSUM);
	assert_int_equal(m.status[1], DXL_OK);
	assert_int_equal(bus.servo[1].checksum_errors, 1);
	assert_int_equal(bus.servo[2].replies, 1);
	/* ID 2 answers with the wrong size */
	memcpy(queue, v2_pos1_reply, sizeof v2_pos1_reply);
	memcpy(queue + sizeof v2_pos1_reply, v2_temp2_reply, sizeof v2_temp2_reply);
	script(queue, sizeof v2_pos1_reply + sizeof v2_temp2_reply, 100);
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_E_WRONG_LENGTH);
	assert_int_equal(m.status[1], DXL_E_WRONG_LENGTH);
	assert_int_equal(bus.servo[2].wrong_length, 1);
	assert_int_equal(dxl2_get_u32(bus_multi_data(&m, 0)), 166);
	/* a servo not asked answers first: counted against the one expected,
	 * who then answers all the same */
	memcpy(queue, v2_ping2_reply, sizeof v2_ping2_reply);
	memcpy(queue + sizeof v2_ping2_reply, v2_pos1_reply, sizeof v2_pos1_reply);
	script(queue, sizeof v2_ping2_reply + sizeof v2_pos1_reply, 100);
	assert_int_equal(bus_sync_read(&bus, 132, 4, (const uint8_t[]){ 1 }, 1, &m), DXL_OK);
	assert_int_equal(bus.servo[1].wrong_id, 1);
	assert_int_equal(m.status[0], DXL_OK);
	/* ... and when it never does, its slot says so */
	script(v2_pos2_reply, sizeof v2_pos2_reply, 100);
	assert_int_equal(bus_sync_read(&bus, 132, 4, (const uint8_t[]){ 1 }, 1, &m), DXL_E_WRONG_ID);
	assert_int_equal(bus.servo[1].wrong_id, 2);
}

/* The asynchronous core as the daemon's poll loop would drive it. */
static void test_v2_sync_read_async(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const uint8_t ids[2] = { 1, 2 };
	uint64_t start = fk.now;
	fake_push(&fk, v2_pos1_reply, sizeof v2_pos1_reply, start + 200);
	fake_push(&fk, v2_pos2_reply, sizeof v2_pos2_reply, start + 400);
	assert_int_equal(bus_sync_read_begin(&bus, 132, 4, ids, 2, &m), DXL_OK);
	assert_true(bus_is_pending(&bus));
	assert_int_equal(bus_deadline_us(&bus), start + 2000);
	assert_int_equal(bus_step(&bus, NULL), BUS_PENDING);
	assert_int_equal(bus_begin(&bus, 1, DXL2_INST_PING, NULL, 0, 3), DXL_E_BUSY);
	fk.now = start + 200;
	assert_int_equal(bus_step(&bus, NULL), BUS_PENDING);
	assert_int_equal(m.answered, 1);
	fk.now = start + 400;
	assert_int_equal(bus_step(&bus, NULL), DXL_OK);
	assert_false(bus_is_pending(&bus));
	assert_int_equal(fk.waits, 0);
	/* at the deadline with one missing */
	start = fk.now;
	fake_push(&fk, v2_pos1_reply, sizeof v2_pos1_reply, start + 300);
	assert_int_equal(bus_sync_read_begin(&bus, 132, 4, ids, 2, &m), DXL_OK);
	fk.now = start + 1999;
	assert_int_equal(bus_step(&bus, NULL), BUS_PENDING);
	fk.now = start + 2000;
	assert_int_equal(bus_step(&bus, NULL), DXL_E_TIMEOUT);
	assert_int_equal(m.answered, 1);
	/* aborted: nothing pending, the bus is usable */
	assert_int_equal(bus_sync_read_begin(&bus, 132, 4, ids, 2, &m), DXL_OK);
	bus_abort(&bus);
	assert_false(bus_is_pending(&bus));
	script(v2_ping1_reply, sizeof v2_ping1_reply, 10);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_OK);
}

static void test_v2_bulk(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	uint8_t data[3];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const struct dxl_item items[2] = { { 1, 144, 2, NULL }, { 2, 146, 1, NULL } };
	memcpy(queue, v2_volt1_reply, sizeof v2_volt1_reply);
	memcpy(queue + sizeof v2_volt1_reply, v2_temp2_reply, sizeof v2_temp2_reply);
	script(queue, sizeof v2_volt1_reply + sizeof v2_temp2_reply, 100);
	assert_int_equal(bus_bulk_read(&bus, items, 2, &m), DXL_OK);
	assert_memory_equal(fk.tx, v2_bulk_read12, sizeof v2_bulk_read12);
	assert_int_equal(dxl_get_u16(bus_multi_data(&m, 0)), 119);   /* 11.9 V */
	assert_int_equal(*bus_multi_data(&m, 1), 36);                 /* 36 °C */
	/* SYNC_WRITE and BULK_WRITE: no reply, no wait */
	size_t at = fk.ntx;
	uint64_t now = fk.now;
	uint8_t goals[8];
	dxl2_put_u32(goals, 150);
	dxl2_put_u32(goals + 4, 170);
	assert_int_equal(bus_sync_write(&bus, 116, 4, (const uint8_t[]){ 1, 2 }, goals, 2), DXL_OK);
	assert_memory_equal(fk.tx + at, v2_sync_write12, sizeof v2_sync_write12);
	at += sizeof v2_sync_write12;
	const uint8_t d1[2] = { 0xA0, 0x00 }, d2[1] = { 0x50 };
	const struct dxl_item w[2] = { { 1, 0x20, 2, d1 }, { 2, 0x1F, 1, d2 } };
	assert_int_equal(bus_bulk_write(&bus, w, 2), DXL_OK);
	assert_memory_equal(fk.tx + at, v2_bulk_write12, sizeof v2_bulk_write12);
	assert_int_equal(fk.now, now);
	assert_false(bus_is_pending(&bus));
}

/* Broadcast PING: every servo answers, each after the one before; all are
 * collected until the deadline, which allows for every ID. */
static void test_v2_ping_all(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	/* queued before the request; the flush before it drops only what arrived */
	fake_push(&fk, v2_ping1_reply, sizeof v2_ping1_reply, fk.now + 100);
	fake_push(&fk, v2_ping2_reply, sizeof v2_ping2_reply, fk.now + 3100);
	struct bus_found found[4];
	size_t n = 9;
	uint64_t start = fk.now;
	assert_int_equal(bus_ping_all(&bus, found, 4, &n), DXL_OK);
	assert_memory_equal(fk.tx, v2_ping_bc, sizeof v2_ping_bc);
	assert_int_equal(n, 2);
	assert_int_equal(found[0].id, 1);
	assert_int_equal(found[1].id, 2);
	assert_int_equal(found[1].model, 1030);
	assert_int_equal(found[1].firmware, 38);
	/* 253 slots of 3 ms (longer than a reply's wire time at 1 Mbps) */
	assert_int_equal(fk.now - start, 100 + 253 * 3000 + 1000 + 500);
	assert_int_equal(found[0].model, 1030);
	assert_int_equal(bus.servo[2].replies, 1);
	/* nobody: no servo, not an error */
	assert_int_equal(bus_ping_all(&bus, found, 4, &n), DXL_OK);
	assert_int_equal(n, 0);
	/* one ID twice: counted, listed once */
	memcpy(queue, v2_ping1_reply, sizeof v2_ping1_reply);
	memcpy(queue + sizeof v2_ping1_reply, v2_ping1_reply, sizeof v2_ping1_reply);
	script(queue, 2 * sizeof v2_ping1_reply, 100);
	assert_int_equal(bus_ping_all(&bus, found, 4, &n), DXL_OK);
	assert_int_equal(n, 1);
	assert_int_equal(bus.servo[1].wrong_id, 1);
}


/* The timeout allows for the reply's worst stuffing, and for the factory
 * 500 µs return delay at 57600. */
static void test_v2_timeout_stuffing(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	/* PING: 10 bytes, reply of 3 parameters at most 15 bytes (one stuffed) */
	assert_int_equal(dxl2_status_bytes_max(3), 15);
	uint64_t start = fk.now;
	assert_int_equal(bus_ping_model(&bus, 7, NULL, NULL, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, 250 + 1000 + 500);
	const struct bus_timing slow = { 57600, 500, 16000, 0 };
	bus_set_timing(&bus, &slow);
	assert_int_equal(bus_timeout_us(&bus, 14, dxl2_status_bytes_max(4)), 5382 + 500 + 16000);
}

/* Bad replies only 2.0 has: a reply cut short (stuffing), a status from
 * the broadcast ID, a second status behind a WRITE's. */
static void test_v2_bad_replies(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	uint32_t pos;
	/* a reply cut short by the header of the good one: a stuffing error,
	 * counted, and the good reply still delivered */
	static uint8_t cut2[5 + 4 + sizeof v2_pos1_reply];
	const uint8_t head[9] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00 };
	memcpy(cut2, head, 9);
	memcpy(cut2 + 9, v2_pos1_reply, sizeof v2_pos1_reply);
	/* after 55 00 (INST, ERR) comes FF FF FD 00: a header in the body */
	script(cut2, 9 + sizeof v2_pos1_reply, 70);
	assert_int_equal(bus_read_u32(&bus, 1, 132, &pos, NULL), DXL_OK);
	assert_int_equal(pos, 166);
	assert_int_equal(bus.servo[1].stuffing_errors, 1);
	assert_true(bus.servo[1].resyncs >= 1);
	/* a reply from a broadcast-looking ID is no status: resynced, then a timeout */
	static const uint8_t from_bc[] = { HDR, 0xFE, 0x04, 0x00, 0x55, 0x00, 0x00, 0x00 };
	script(from_bc, sizeof from_bc, 40);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_E_TIMEOUT);
	assert_true(bus.parser.v2.header_errors >= 1);
	/* a second packet after the reply is a stray */
	static uint8_t two[sizeof v2_ok1 * 2];
	memcpy(two, v2_ok1, sizeof v2_ok1);
	memcpy(two + sizeof v2_ok1, v2_ok1, sizeof v2_ok1);
	script(two, sizeof two, 30);
	assert_int_equal(bus_write_u8(&bus, 1, 65, 1, NULL), DXL_OK);
	assert_int_equal(bus.stray_packets, 1);
}

/* Echo off, wiring that echoes: a 2.0 request never reads as a status, so
 * the echo is recognised, not parsed, and the reply behind it delivered at
 * once; a reply that starts like the request, then differs, is parsed whole
 * (the held bytes go to the parser first). */
static void test_v2_echo_recognised(void **state)
{
	(void)state;
	setup_bus(&case_v2, false);
	fk.echo = true;
	script(v2_ping1_reply, sizeof v2_ping1_reply, 100);
	uint64_t start = fk.now;
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_OK);
	assert_int_equal(fk.now - start, 100);
	assert_int_equal(bus.unexpected_echoes, 1);
	assert_int_equal(bus.servo[1].resyncs, 0);
	assert_int_equal(bus.parser.v2.header_errors, 0);
	setup_bus(&case_v2, false);
	script(v2_ping1_reply, sizeof v2_ping1_reply, 100);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_OK);
	assert_int_equal(bus.unexpected_echoes, 0);
}

#define BOTH(f) { #f " 1.0", f, NULL, NULL, &case_v1 }, { #f " 2.0", f, NULL, NULL, &case_v2 }
#define ONE(f) { #f, f, NULL, NULL, NULL }

int main(void)
{
	const struct CMUnitTest tests[] = {
		ONE(test_abort_before_init),
		BOTH(test_flush_only_when_needed),
		BOTH(test_ping),
		BOTH(test_timeout_exact),
		BOTH(test_wrong_id),
		BOTH(test_wrong_length),
		BOTH(test_checksum_error),
		BOTH(test_error_bits),
		BOTH(test_echo),
		BOTH(test_stale_input_and_strays),
		BOTH(test_settle),
		BOTH(test_listen_late),
		BOTH(test_io_errors_and_args),
		BOTH(test_reply_lateness),
		ONE(test_v1_timeout_formula),
		ONE(test_v1_timeout_read8),
		ONE(test_v1_read_returns_data),
		ONE(test_v1_async),
		ONE(test_v1_no_wait),
		ONE(test_v1_echo_wiring),
		ONE(test_v1_reply_like_request),
		ONE(test_v2_protocol_switch),
		ONE(test_v2_ping_model),
		ONE(test_v2_timeout_stuffing),
		ONE(test_v2_read_write_golden),
		ONE(test_v2_bad_replies),
		ONE(test_v2_sync_read),
		ONE(test_v2_sync_read_missing),
		ONE(test_v2_sync_read_bad_replies),
		ONE(test_v2_sync_read_async),
		ONE(test_v2_bulk),
		ONE(test_v2_ping_all),
		ONE(test_v2_echo_recognised),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
