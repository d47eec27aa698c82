/*
 * test_protocol_bus.c — Protocol 1.0 bus transactions over a fake transport
 * (busfake.h: an in-memory peer that answers each request with scripted
 * literal bytes after a scripted delay, and a fake clock that only io->wait
 * advances). Timeouts are therefore checked to the microsecond.
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
#include "dxl.h"

static struct fake fk;
static struct bus bus;

/* 1 Mbps, return delay 0, 1 ms adapter latency, 500 µs margin. */
static const struct bus_timing timing = { 1000000, 0, 1000, 500 };

static void setup_bus(bool echo)
{
	memset(&fk, 0, sizeof fk);
	fk.now = 1000000;
	fk.echo = echo;
	const struct bus_io io = { &fk, fake_write, fake_read, fake_wait, fake_now, fake_flush, NULL };
	bus_init(&bus, &io, &timing, echo);
}

static void script(const uint8_t *reply, size_t n, uint64_t delay_us)
{
	fk.reply = reply;
	fk.reply_len = n;
	fk.reply_delay_us = delay_us;
}

/* Literal packets (manual examples and hand-computed checksums). */
static const uint8_t ping1[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
static const uint8_t ping1_reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
static const uint8_t ping2_reply[] = { 0xFF, 0xFF, 0x02, 0x02, 0x00, 0xFB };
static const uint8_t read_temp1[] = { 0xFF, 0xFF, 0x01, 0x04, 0x02, 0x2B, 0x01, 0xCC };
static const uint8_t temp1_reply[] = { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB };
static const uint8_t temp1_reply_bad[] = { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDA };
static const uint8_t overload_reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x24, 0xD8 };
static const uint8_t pos512_reply[] = { 0xFF, 0xFF, 0x01, 0x04, 0x00, 0x00, 0x02, 0xF8 };
static const uint8_t sync_golden[] = { 0xFF, 0xFF, 0xFE, 0x0E, 0x83, 0x1E, 0x04, 0x00, 0x10, 0x00,
                                       0x50, 0x01, 0x01, 0x20, 0x02, 0x60, 0x03, 0x67 };
static const uint8_t goal512_golden[] = { 0xFF, 0xFF, 0x01, 0x05, 0x03, 0x1E, 0x00, 0x02, 0xD6 };
static const uint8_t bc_id1_golden[] = { 0xFF, 0xFF, 0xFE, 0x04, 0x03, 0x03, 0x01, 0xF6 };

/* The transport can say what is waiting: a request flushes the input only
 * when there is something, or the line is dirty (a timeout, a damaged or
 * stray reply) — on a tty every flush may wait for the kernel's worker. */
static void test_flush_only_when_needed(void **state)
{
	(void)state;
	setup_bus(false);
	bus.io.pending_input = fake_pending;
	script(ping1_reply, sizeof ping1_reply, 80);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.flushes, 1);           /* the first request: the line is unknown */
	for (int i = 0; i < 5; i++) {
		script(ping1_reply, sizeof ping1_reply, 80);
		assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	}
	assert_int_equal(fk.flushes, 1);           /* clean transactions: never again */
	assert_int_equal(bus_ping(&bus, 7, NULL), DXL_E_TIMEOUT);
	script(ping1_reply, sizeof ping1_reply, 80);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.flushes, 2);           /* after the timeout: flushed */
	/* bytes waiting (a servo answering late, unasked) are flushed too */
	fake_push(&fk, ping2_reply, sizeof ping2_reply, fk.now);
	script(ping1_reply, sizeof ping1_reply, 80);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.flushes, 3);
	assert_int_equal(bus.stray_packets, 0);
}

static void test_timeout_formula(void **state)
{
	(void)state;
	setup_bus(false);
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

static void test_ping_ok(void **state)
{
	(void)state;
	setup_bus(false);
	script(ping1_reply, sizeof ping1_reply, 80);
	uint8_t err = 0xEE;
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_int_equal(err, 0);
	assert_int_equal(fk.ntx, sizeof ping1);
	assert_memory_equal(fk.tx, ping1, sizeof ping1);
	assert_int_equal(fk.now, 1000000 + 80);
	assert_int_equal(fk.flushes, 1);
	const struct bus_servo_stats *st = &bus.servo[1];
	assert_int_equal(st->transactions, 1);
	assert_int_equal(st->replies, 1);
	assert_int_equal(st->rtt_last_us, 80);
	assert_int_equal(st->rtt_max_us, 80);
	assert_int_equal(st->rtt_sum_us, 80);
	assert_int_equal(bus.bytes_out, 6);
	assert_int_equal(bus.bytes_in, 6);
	assert_false(bus_is_pending(&bus));
}

static void test_read_returns_data(void **state)
{
	(void)state;
	setup_bus(false);
	script(temp1_reply, sizeof temp1_reply, 100);
	uint8_t temp = 0, err = 0xEE;
	assert_int_equal(bus_read_u8(&bus, 1, 43, &temp, &err), DXL_OK);
	assert_memory_equal(fk.tx, read_temp1, sizeof read_temp1);
	assert_int_equal(temp, 32);
	assert_int_equal(err, 0);

	/* a fragmented 16-bit reply */
	fk.max_chunk = 3;
	script(pos512_reply, sizeof pos512_reply, 100);
	uint16_t pos = 0;
	assert_int_equal(bus_read_u16(&bus, 1, 36, &pos, &err), DXL_OK);
	assert_int_equal(pos, 512);
	assert_int_equal(bus.servo[1].replies, 2);
}

/* No reply: DXL_E_TIMEOUT after exactly the derived timeout. */
static void test_timeout_exact(void **state)
{
	(void)state;
	setup_bus(false);
	uint64_t start = fk.now;
	assert_int_equal(bus_ping(&bus, 7, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, bus_timeout_us(&bus, 6, 6));
	assert_int_equal(fk.now - start, 1620);
	assert_int_equal(bus.servo[7].timeouts, 1);
	assert_int_equal(bus.servo[7].transactions, 1);
	assert_int_equal(bus.servo[7].replies, 0);

	/* READ(36, 8): 8 + 14 bytes */
	start = fk.now;
	uint8_t out[8];
	assert_int_equal(bus_read(&bus, 7, 36, 8, out, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, 220 + 1000 + 500);

	/* a reply arriving 1 µs after the deadline is too late */
	start = fk.now;
	script(ping1_reply, sizeof ping1_reply, 1621);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, 1620);
	/* ... and one arriving just at the deadline is on time */
	fk.now += 10000; /* let the late one arrive; the next request flushes it */
	start = fk.now;
	script(ping1_reply, sizeof ping1_reply, 1620);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.now - start, 1620);
}

/* The asynchronous core, driven as the daemon's poll loop would. */
static void test_async(void **state)
{
	(void)state;
	setup_bus(false);
	script(temp1_reply, sizeof temp1_reply, 300);
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
	script(ping1_reply, sizeof ping1_reply, 10);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
}

static void test_wrong_id(void **state)
{
	(void)state;
	setup_bus(false);
	script(ping2_reply, sizeof ping2_reply, 50);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_WRONG_ID);
	assert_int_equal(bus.servo[1].wrong_id, 1);
	assert_int_equal(bus.servo[1].replies, 0);
	assert_int_equal(bus.servo[2].replies, 0);
	assert_false(bus_is_pending(&bus));
}

static void test_wrong_length(void **state)
{
	(void)state;
	setup_bus(false);
	/* READ of 1 byte answered with no data */
	script(ping1_reply, sizeof ping1_reply, 50);
	uint8_t v;
	assert_int_equal(bus_read_u8(&bus, 1, 43, &v, NULL), DXL_E_WRONG_LENGTH);
	assert_int_equal(bus.servo[1].wrong_length, 1);
	/* PING answered with data */
	script(temp1_reply, sizeof temp1_reply, 50);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_WRONG_LENGTH);
	assert_int_equal(bus.servo[1].wrong_length, 2);
}

/* A damaged reply fails at once (not at the deadline) and is counted. */
static void test_checksum_error(void **state)
{
	(void)state;
	setup_bus(false);
	script(temp1_reply_bad, sizeof temp1_reply_bad, 70);
	uint64_t start = fk.now;
	uint8_t v;
	assert_int_equal(bus_read_u8(&bus, 1, 43, &v, NULL), DXL_E_CHECKSUM);
	assert_int_equal(fk.now - start, 70);
	assert_int_equal(bus.servo[1].checksum_errors, 1);
	assert_int_equal(bus.parser.v1.checksum_errors, 1);
	assert_int_equal(bus.servo[1].replies, 0);
}

/* The servo's error bits are data: the call succeeds and reports them. */
static void test_error_bits(void **state)
{
	(void)state;
	setup_bus(false);
	script(overload_reply, sizeof overload_reply, 40);
	uint8_t err = 0;
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_int_equal(err, DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT);
	assert_int_equal(bus.servo[1].error_replies, 1);
	assert_int_equal(bus.servo[1].last_errbits, 0x24);
	assert_int_equal(bus.servo[1].errbits_seen, 0x24);
	script(ping1_reply, sizeof ping1_reply, 40);
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_int_equal(err, 0);
	assert_int_equal(bus.servo[1].error_replies, 1);
	assert_int_equal(bus.servo[1].last_errbits, 0);
	assert_int_equal(bus.servo[1].errbits_seen, 0x24);
	assert_int_equal(bus.servo[1].replies, 2);
}

/* Broadcast and SYNC_WRITE wait for nothing, even if asked to. */
static void test_no_wait(void **state)
{
	(void)state;
	setup_bus(false);
	uint64_t start = fk.now;
	const uint8_t ids[2] = { 0, 1 };
	uint8_t data[8];
	dxl_put_u16(data + 0, 0x010);
	dxl_put_u16(data + 2, 0x150);
	dxl_put_u16(data + 4, 0x220);
	dxl_put_u16(data + 6, 0x360);
	assert_int_equal(bus_sync_write(&bus, 30, 4, ids, data, 2), DXL_OK);
	assert_memory_equal(fk.tx, sync_golden, sizeof sync_golden);
	uint8_t err = 0xEE;
	assert_int_equal(bus_write_u8(&bus, DXL_BROADCAST_ID, 3, 1, &err), DXL_OK);
	assert_memory_equal(fk.tx + sizeof sync_golden, bc_id1_golden, sizeof bc_id1_golden);
	assert_int_equal(err, 0);
	assert_int_equal(bus_action(&bus, DXL_BROADCAST_ID, true, NULL), DXL_OK);
	assert_int_equal(bus_begin(&bus, DXL_BROADCAST_ID, DXL_INST_PING, NULL, 0, 0), DXL_OK);
	assert_false(bus_is_pending(&bus));
	/* a unicast write with status return level < 2 */
	uint8_t goal[2];
	dxl_put_u16(goal, 512);
	size_t before = fk.ntx;
	assert_int_equal(bus_write(&bus, 1, 30, goal, 2, false, NULL), DXL_OK);
	assert_memory_equal(fk.tx + before, goal512_golden, sizeof goal512_golden);
	assert_int_equal(fk.waits, 0);
	assert_int_equal(fk.now, start);
	assert_int_equal(bus.servo[1].transactions, 0);
}

/* Single-wire wiring: our own bytes come back first and are discarded. */
static void test_echo(void **state)
{
	(void)state;
	setup_bus(true);
	script(ping1_reply, sizeof ping1_reply, 100);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(bus.servo[1].replies, 1);
	assert_int_equal(bus.bytes_in, 12);
	assert_int_equal(bus.parser.v1.bytes_dropped, 0);

	/* the echo of a reply-less SYNC_WRITE arrives after the next request
	 * started: it is still matched and discarded */
	fk.echo_delay_us = 50;
	const uint8_t ids[2] = { 0, 1 };
	uint8_t data[8] = { 0 };
	assert_int_equal(bus_sync_write(&bus, 30, 4, ids, data, 2), DXL_OK);
	uint8_t temp = 0;
	script(temp1_reply, sizeof temp1_reply, 150);
	assert_int_equal(bus_read_u8(&bus, 1, 43, &temp, NULL), DXL_OK);
	assert_int_equal(temp, 32);
	assert_int_equal(bus.echo_errors, 0);

	/* a differing echo byte is DXL_E_ECHO */
	fk.echo_delay_us = 0;
	fk.echo_corrupt_at = 3;
	script(ping1_reply, sizeof ping1_reply, 100);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_ECHO);
	assert_int_equal(bus.echo_errors, 1);
	assert_false(bus_is_pending(&bus));
	fk.echo_corrupt_at = 0;

	/* echo expected but the wiring has none: the reply is not our echo */
	fk.now += 10000;
	fk.echo = false;
	script(ping1_reply, sizeof ping1_reply, 100);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_ECHO);
	assert_int_equal(bus.echo_errors, 2);

	/* echo off but the wiring echoes: a PING's echo reads as a valid status
	 * packet with the input-voltage bit (FF FF 01 02 01 FB); it is held, and
	 * the real reply behind it wins */
	setup_bus(false);
	fk.echo = true;
	script(ping1_reply, sizeof ping1_reply, 100);
	uint8_t err = 0xEE;
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_int_equal(err, 0);
	assert_int_equal(bus.unexpected_echoes, 1);
	/* the same for READ(36, 2), whose echo looks like 2 bytes of data */
	uint16_t pos = 0;
	script(pos512_reply, sizeof pos512_reply, 100);
	assert_int_equal(bus_read_u16(&bus, 1, 36, &pos, &err), DXL_OK);
	assert_int_equal(pos, 512);
	assert_int_equal(err, 0);
	assert_int_equal(bus.unexpected_echoes, 2);
}

/* A genuine reply identical to the request (PING answered with the
 * input-voltage bit) is still delivered, at the deadline. */
static void test_reply_like_request(void **state)
{
	(void)state;
	setup_bus(false);
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

static void test_stale_input_and_strays(void **state)
{
	(void)state;
	setup_bus(false);
	/* stale bytes from before the request are flushed */
	fake_push(&fk, temp1_reply, sizeof temp1_reply, fk.now);
	script(ping1_reply, sizeof ping1_reply, 30);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(bus.stray_packets, 0);

	/* garbage before the reply: resynced, counted, reply delivered */
	static const uint8_t noisy[] = { 0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
	script(noisy, sizeof noisy, 30);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_true(bus.servo[1].resyncs >= 1);

	/* a second packet in the same read is a stray */
	static uint8_t two[sizeof ping1_reply * 2];
	memcpy(two, ping1_reply, sizeof ping1_reply);
	memcpy(two + sizeof ping1_reply, ping2_reply, sizeof ping2_reply);
	script(two, sizeof two, 30);
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
	(void)state;
	setup_bus(false);
	bus.io.pending_input = fake_pending;
	/* nothing comes: quiet at once, after quiet_us */
	uint64_t start = fk.now;
	assert_int_equal(bus_settle(&bus, 5000, 50000), 0);
	assert_int_equal(fk.now - start, 5000);

	/* a ping whose reply comes 2 ms after the deadline */
	script(ping1_reply, sizeof ping1_reply, 1620 + 2000);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_E_TIMEOUT);
	start = fk.now;
	assert_int_equal(bus_settle(&bus, 5000, 50000), (int)sizeof ping1_reply);
	assert_int_equal(fk.now - start, 2000 + 5000);   /* the late reply, then 5 ms of quiet */
	unsigned flushes = fk.flushes;
	script(ping1_reply, sizeof ping1_reply, 80);
	assert_int_equal(bus_ping(&bus, 1, NULL), DXL_OK);
	assert_int_equal(fk.flushes, flushes);            /* the line is known clean */
	assert_int_equal(bus.stray_packets, 0);

	/* a line that never goes quiet: given up after max_us, still dirty */
	for (int i = 0; i < 40; i++)
		fake_push(&fk, ping2_reply, sizeof ping2_reply, fk.now + 1000u * (unsigned)i);
	start = fk.now;
	assert_true(bus_settle(&bus, 5000, 20000) > 0);
	assert_true(fk.now - start >= 20000 && fk.now - start < 21000);
	assert_true(bus.line_dirty);

	/* not while a transaction is pending */
	assert_int_equal(bus_begin(&bus, 1, DXL_INST_PING, NULL, 0, 0), DXL_OK);
	assert_int_equal(bus_settle(&bus, 5000, 50000), DXL_E_BUSY);
	bus_abort(&bus);
}

static void test_io_errors_and_args(void **state)
{
	(void)state;
	setup_bus(false);
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

/* Reply lateness: round trip less the PING's and reply's wire time (12 bytes,
 * 120 µs at 1 Mbps) and the return delay; the lower median, the extremes;
 * lost PINGs counted apart. */
static void test_reply_lateness(void **state)
{
	(void)state;
	struct bus_lateness lt;
	/* an FTDI adapter at its 16 ms default, once a bit less, once a reader late */
	static const uint64_t held[] = { 16620, 16620, 12620, 16620, 21620, 16620 };
	/* the probe's timeout must outlast the hold it measures */
	static const struct bus_timing patient = { 1000000, 500, 0, 30000 };
	setup_bus(false);
	bus_set_timing(&bus, &patient);
	script(ping1_reply, sizeof ping1_reply, 0);
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
	static const uint64_t prompt[] = { 100, 120, 130 };
	setup_bus(false);
	script(ping1_reply, sizeof ping1_reply, 0);
	fk.reply_every = true;
	fk.delays = prompt;
	fk.ndelays = 3;
	assert_int_equal(bus_reply_lateness(&bus, 1, 0, 3, &lt), DXL_OK);
	assert_int_equal(lt.min_us, 0);
	assert_int_equal(lt.median_us, 0);
	assert_int_equal(lt.max_us, 10);

	/* lost PINGs: counted, not taken as late replies */
	static const uint64_t lossy[] = { 1120, UINT64_MAX };
	setup_bus(false);
	script(ping1_reply, sizeof ping1_reply, 0);
	fk.reply_every = true;
	fk.delays = lossy;
	fk.ndelays = 2;
	assert_int_equal(bus_reply_lateness(&bus, 1, 0, 4, &lt), DXL_OK);
	assert_int_equal(lt.pings, 4);
	assert_int_equal(lt.replies, 2);
	assert_int_equal(lt.median_us, 1000);

	/* nobody there: the PING's own status; more than BUS_LATENESS_MAX asked is capped */
	setup_bus(false);
	assert_int_equal(bus_reply_lateness(&bus, 9, 0, 1000, &lt), DXL_E_TIMEOUT);
	assert_int_equal(lt.pings, BUS_LATENESS_MAX);
	assert_int_equal(lt.replies, 0);
	assert_int_equal(bus_reply_lateness(&bus, 9, 0, 0, &lt), DXL_E_ARG);
	/* the port gone: stop at once */
	setup_bus(false);
	fk.write_error = DXL_E_DISCONNECTED;
	assert_int_equal(bus_reply_lateness(&bus, 1, 0, 8, &lt), DXL_E_DISCONNECTED);
	assert_int_equal(lt.pings, 1);
}

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

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_abort_before_init),
		cmocka_unit_test(test_flush_only_when_needed),
		cmocka_unit_test(test_timeout_formula),
		cmocka_unit_test(test_ping_ok),
		cmocka_unit_test(test_read_returns_data),
		cmocka_unit_test(test_timeout_exact),
		cmocka_unit_test(test_async),
		cmocka_unit_test(test_wrong_id),
		cmocka_unit_test(test_wrong_length),
		cmocka_unit_test(test_checksum_error),
		cmocka_unit_test(test_error_bits),
		cmocka_unit_test(test_no_wait),
		cmocka_unit_test(test_echo),
		cmocka_unit_test(test_reply_like_request),
		cmocka_unit_test(test_stale_input_and_strays),
		cmocka_unit_test(test_settle),
		cmocka_unit_test(test_io_errors_and_args),
		cmocka_unit_test(test_reply_lateness),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
