/*
 * test_protocol_bus2.c — Protocol 2.0 bus transactions over the fake
 * transport (busfake.h) and its fake clock. Every request and reply is a
 * literal packet typed from the e-manual's "DYNAMIXEL Protocol 2.0" page
 * (the same rows as test_protocol_packet2.c), never produced by our encoder:
 * the simulator reuses the encoder, so a symmetric bug would pass.
 * Hand-made packets (a stuffed reply, a damaged CRC) say so.
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
#include "dxl2.h"

static struct fake fk;
static struct bus bus;

/* 1 Mbps, return delay 0, 1 ms adapter latency, 500 µs margin. */
static const struct bus_timing timing = { 1000000, 0, 1000, 500 };

static void setup_bus2(bool echo)
{
	memset(&fk, 0, sizeof fk);
	fk.now = 1000000;
	fk.echo = echo;
	const struct bus_io io = { &fk, fake_write, fake_read, fake_wait, fake_now, fake_flush, NULL };
	bus_init(&bus, &io, &timing, echo);
	assert_int_equal(bus_set_protocol(&bus, BUS_PROTOCOL_2), DXL_OK);
}

static void script(const uint8_t *reply, size_t n, uint64_t delay_us)
{
	fk.reply = reply;
	fk.reply_len = n;
	fk.reply_delay_us = delay_us;
}

#define HDR 0xFF, 0xFF, 0xFD, 0x00
/* e-manual, Protocol 2.0: Ping example 1 (ID 1: model 1030, firmware 38) */
static const uint8_t ping1[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
static const uint8_t ping1_reply[] = { HDR, 0x01, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D };
/* Ping example 2: broadcast, answered by ID 1 and ID 2 */
static const uint8_t ping_bc[] = { HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42 };
static const uint8_t ping2_reply[] = { HDR, 0x02, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x6F, 0x6D };
/* Read: ID 1, Present Position (132), 4 bytes -> 166 */
static const uint8_t read_pos1[] = { HDR, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15 };
static const uint8_t pos1_reply[] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0 };
/* Write: ID 1, Goal Position (116) = 512; its status */
static const uint8_t write_goal1[] = { HDR, 0x01, 0x09, 0x00, 0x03, 0x74, 0x00, 0x00, 0x02, 0x00, 0x00, 0xCA, 0x89 };
static const uint8_t ok1[] = { HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C };
/* Reg Write: ID 1, Goal Velocity (104) = 200 */
static const uint8_t regw1[] = { HDR, 0x01, 0x09, 0x00, 0x04, 0x68, 0x00, 0xC8, 0x00, 0x00, 0x00, 0xAE, 0x8E };
static const uint8_t action1[] = { HDR, 0x01, 0x03, 0x00, 0x05, 0x02, 0xCE };
static const uint8_t reset1[] = { HDR, 0x01, 0x04, 0x00, 0x06, 0x01, 0xA1, 0xE6 };
static const uint8_t reboot1[] = { HDR, 0x01, 0x03, 0x00, 0x08, 0x2F, 0x4E };
static const uint8_t clear1[] = { HDR, 0x01, 0x08, 0x00, 0x10, 0x01, 0x44, 0x58, 0x4C, 0x22, 0xB1, 0xDC };
/* Sync Read: IDs 1, 2, Present Position (132), 4 bytes; ID 2's status
 * (ID 1's is pos1_reply) */
static const uint8_t sync_read12[] = { HDR, 0xFE, 0x09, 0x00, 0x82, 0x84, 0x00, 0x04, 0x00, 0x01, 0x02, 0xCE, 0xFA };
static const uint8_t pos2_reply[] = { HDR, 0x02, 0x08, 0x00, 0x55, 0x00, 0x1F, 0x08, 0x00, 0x00, 0xBA, 0xBE };
/* Sync Write: ID 1 -> 150, ID 2 -> 170 at Goal Position */
static const uint8_t sync_write12[] = { HDR, 0xFE, 0x11, 0x00, 0x83, 0x74, 0x00, 0x04, 0x00, 0x01, 0x96, 0x00,
                                        0x00, 0x00, 0x02, 0xAA, 0x00, 0x00, 0x00, 0x82, 0x87 };
/* Bulk Read: ID 1 voltage (144, 2 bytes), ID 2 temperature (146, 1 byte) */
static const uint8_t bulk_read12[] = { HDR, 0xFE, 0x0D, 0x00, 0x92, 0x01, 0x90, 0x00, 0x02, 0x00, 0x02, 0x92,
                                       0x00, 0x01, 0x00, 0x1A, 0x05 };
static const uint8_t volt1_reply[] = { HDR, 0x01, 0x06, 0x00, 0x55, 0x00, 0x77, 0x00, 0xC3, 0x69 };
static const uint8_t temp2_reply[] = { HDR, 0x02, 0x05, 0x00, 0x55, 0x00, 0x24, 0x8B, 0xA9 };
/* Bulk Write: ID 1 LED (65)... as printed: ID 1 at 0x20 = A0 00, ID 2 at 0x1F = 50 */
static const uint8_t bulk_write12[] = { HDR, 0xFE, 0x10, 0x00, 0x93, 0x01, 0x20, 0x00, 0x02, 0x00, 0xA0, 0x00,
                                        0x02, 0x1F, 0x00, 0x01, 0x00, 0x50, 0xB7, 0x68 };
/* Hand-stuffed (test_protocol_packet2.c): a status of FF FF FD, and an
 * empty status with ERR 0x84 (alert | data range) */
static const uint8_t stuffed1_reply[] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0x9A, 0x34 };
static const uint8_t alert1[] = { HDR, 0x01, 0x04, 0x00, 0x55, 0x84, 0xB9, 0x0F };
/* pos1_reply with its last CRC byte changed */
static const uint8_t pos1_reply_bad[] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC1 };

/* Replies queued one after another, as a bus delivers them. */
static uint8_t queue[512];

static void test_protocol_switch(void **state)
{
	(void)state;
	setup_bus2(false);
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
	assert_int_equal(bus_begin(&bus, DXL2_BROADCAST_ID, DXL2_INST_SYNC_READ, sync_read12 + 8, 6, 4), DXL_E_ARG);
}

static void test_ping(void **state)
{
	(void)state;
	setup_bus2(false);
	script(ping1_reply, sizeof ping1_reply, 90);
	uint16_t model = 0;
	uint8_t fw = 0, err = 0xEE;
	assert_int_equal(bus_ping_model(&bus, 1, &model, &fw, &err), DXL_OK);
	assert_int_equal(fk.ntx, sizeof ping1);
	assert_memory_equal(fk.tx, ping1, sizeof ping1);
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
	script(ping1_reply, sizeof ping1_reply, 90);
	assert_int_equal(bus_ping(&bus, 1, &err), DXL_OK);
	assert_memory_equal(fk.tx + 10, ping1, sizeof ping1);
	assert_int_equal(bus_reply(&bus)->nparams, 3);
	/* broadcast is for bus_ping_all */
	assert_int_equal(bus_ping_model(&bus, DXL2_BROADCAST_ID, &model, &fw, &err), DXL_E_ARG);
}

/* The timeout: wire time of the request and of the reply at its worst
 * stuffing, the return delay, adapter latency and margin. */
static void test_timeout_exact(void **state)
{
	(void)state;
	setup_bus2(false);
	/* PING: 10 bytes, reply of 3 parameters at most 15 bytes (one stuffed) */
	assert_int_equal(dxl2_status_bytes_max(3), 15);
	uint64_t start = fk.now;
	assert_int_equal(bus_ping_model(&bus, 7, NULL, NULL, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, 250 + 1000 + 500);
	assert_int_equal(bus.servo[7].timeouts, 1);
	/* READ of 4: 14 bytes out, at most 17 back */
	start = fk.now;
	uint32_t v;
	assert_int_equal(bus_read_u32(&bus, 7, 132, &v, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, 310 + 1500);
	/* at 57600 with the factory 500 µs return delay */
	const struct bus_timing slow = { 57600, 500, 16000, 0 };
	bus_set_timing(&bus, &slow);
	assert_int_equal(bus_timeout_us(&bus, 14, dxl2_status_bytes_max(4)), 5382 + 500 + 16000);
	/* a reply just at the deadline is on time, 1 µs later is not */
	bus_set_timing(&bus, &timing);
	fk.now += 10000;
	start = fk.now;
	script(ping1_reply, sizeof ping1_reply, 1750);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_OK);
	assert_int_equal(fk.now - start, 1750);
	start = fk.now;
	script(ping1_reply, sizeof ping1_reply, 1751);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_E_TIMEOUT);
	assert_int_equal(fk.now - start, 1750);
}

static void test_read_write_golden(void **state)
{
	(void)state;
	setup_bus2(false);
	uint32_t pos = 0;
	uint8_t err = 0xEE;
	script(pos1_reply, sizeof pos1_reply, 120);
	assert_int_equal(bus_read_u32(&bus, 1, 132, &pos, &err), DXL_OK);
	assert_memory_equal(fk.tx, read_pos1, sizeof read_pos1);
	assert_int_equal(pos, 166);
	assert_int_equal(err, 0);
	size_t at = fk.ntx;
	script(ok1, sizeof ok1, 60);
	assert_int_equal(bus_write_u32(&bus, 1, 116, 512, &err), DXL_OK);
	assert_memory_equal(fk.tx + at, write_goal1, sizeof write_goal1);
	const uint8_t vel200[4] = { 0xC8, 0, 0, 0 };
	struct row {
		const uint8_t *want;
		size_t n;
		int r;
	} rows[5];
	at = fk.ntx;
	script(ok1, sizeof ok1, 60);
	rows[0] = (struct row){ regw1, sizeof regw1, bus_reg_write(&bus, 1, 104, vel200, 4, true, &err) };
	script(ok1, sizeof ok1, 60);
	rows[1] = (struct row){ action1, sizeof action1, bus_action(&bus, 1, true, &err) };
	script(ok1, sizeof ok1, 60);
	rows[2] = (struct row){ reset1, sizeof reset1, bus_factory_reset(&bus, 1, DXL2_RESET_KEEP_ID, true, &err) };
	script(ok1, sizeof ok1, 60);
	rows[3] = (struct row){ reboot1, sizeof reboot1, bus_reboot(&bus, 1, true, &err) };
	script(ok1, sizeof ok1, 60);
	rows[4] = (struct row){ clear1, sizeof clear1, bus_clear_multi_turn(&bus, 1, true, &err) };
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
	script(stuffed1_reply, sizeof stuffed1_reply, 80);
	assert_int_equal(bus_read(&bus, 1, 0, 3, three, &err), DXL_OK);
	assert_memory_equal(three, ((const uint8_t[]){ 0xFF, 0xFF, 0xFD }), 3);
}

/* The ERR field is data: the call succeeds, the field comes back and is counted. */
static void test_err_field(void **state)
{
	(void)state;
	setup_bus2(false);
	uint8_t err = 0;
	script(alert1, sizeof alert1, 50);
	assert_int_equal(bus_write_u8(&bus, 1, 65, 1, &err), DXL_OK);
	assert_int_equal(err, 0x84);
	assert_true(dxl2_err_alert(err));
	assert_int_equal(dxl2_err_number(err), DXL2_ERRNUM_DATA_RANGE);
	assert_int_equal(bus.servo[1].error_replies, 1);
	assert_int_equal(bus.servo[1].alerts, 1);
	assert_int_equal(bus.servo[1].errbits_seen, 0x84);
	script(ok1, sizeof ok1, 50);
	assert_int_equal(bus_write_u8(&bus, 1, 65, 0, &err), DXL_OK);
	assert_int_equal(err, 0);
	assert_int_equal(bus.servo[1].last_errbits, 0);
	assert_int_equal(bus.servo[1].alerts, 1);
	assert_int_equal(bus.servo[1].replies, 2);
}

/* Bad replies: the same status codes and counters as on 1.0. */
static void test_bad_replies(void **state)
{
	(void)state;
	setup_bus2(false);
	uint8_t v;
	/* wrong ID */
	script(ping2_reply, sizeof ping2_reply, 50);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_E_WRONG_ID);
	assert_int_equal(bus.servo[1].wrong_id, 1);
	/* wrong length: a READ of 1 answered with 3 bytes */
	script(ping1_reply, sizeof ping1_reply, 50);
	assert_int_equal(bus_read_u8(&bus, 1, 146, &v, NULL), DXL_E_WRONG_LENGTH);
	assert_int_equal(bus.servo[1].wrong_length, 1);
	/* bad CRC: at once, not at the deadline */
	uint32_t pos;
	uint64_t start = fk.now;
	script(pos1_reply_bad, sizeof pos1_reply_bad, 70);
	assert_int_equal(bus_read_u32(&bus, 1, 132, &pos, NULL), DXL_E_CHECKSUM);
	assert_int_equal(fk.now - start, 70);
	assert_int_equal(bus.servo[1].checksum_errors, 1);
	assert_int_equal(bus.parser.v2.checksum_errors, 1);
	/* a reply cut short by the header of the good one: a stuffing error,
	 * counted, and the good reply still delivered */
	static uint8_t cut2[5 + 4 + sizeof pos1_reply];
	const uint8_t head[9] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00 };
	memcpy(cut2, head, 9);
	memcpy(cut2 + 9, pos1_reply, sizeof pos1_reply);
	/* after 55 00 (INST, ERR) comes FF FF FD 00: a header in the body */
	script(cut2, 9 + sizeof pos1_reply, 70);
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
	static uint8_t two[sizeof ok1 * 2];
	memcpy(two, ok1, sizeof ok1);
	memcpy(two + sizeof ok1, ok1, sizeof ok1);
	script(two, sizeof two, 30);
	assert_int_equal(bus_write_u8(&bus, 1, 65, 1, NULL), DXL_OK);
	assert_int_equal(bus.stray_packets, 1);
}

/* SYNC_READ: one request, one reply per servo, each checked. */
static void test_sync_read(void **state)
{
	(void)state;
	setup_bus2(false);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const uint8_t ids[2] = { 1, 2 };
	size_t n = 0;
	memcpy(queue, pos1_reply, sizeof pos1_reply);
	memcpy(queue + sizeof pos1_reply, pos2_reply, sizeof pos2_reply);
	n = sizeof pos1_reply + sizeof pos2_reply;
	script(queue, n, 100);
	uint64_t start = fk.now;
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_OK);
	assert_memory_equal(fk.tx, sync_read12, sizeof sync_read12);
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
static void test_sync_read_missing(void **state)
{
	(void)state;
	setup_bus2(false);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const uint8_t ids[2] = { 1, 2 };
	script(pos1_reply, sizeof pos1_reply, 100);
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
	script(pos2_reply, sizeof pos2_reply, 100);
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_E_TIMEOUT);
	assert_int_equal(m.status[0], DXL_E_TIMEOUT);
	assert_int_equal(dxl2_get_u32(bus_multi_data(&m, 1)), 2079);
	assert_int_equal(m.track.out_of_order, 1);
	/* the return delay counts once per reply */
	const struct bus_timing rd = { 1000000, 500, 1000, 500 };
	bus_set_timing(&bus, &rd);
	assert_int_equal(bus_multi_timeout_us(&bus, 16, lens, 2), 500 + 2 * 500 + 1000 + 500);
}

static void test_sync_read_bad_replies(void **state)
{
	(void)state;
	setup_bus2(false);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const uint8_t ids[2] = { 1, 2 };
	/* ID 1's reply damaged, ID 2's good: settled when ID 2's arrives */
	memcpy(queue, pos1_reply_bad, sizeof pos1_reply_bad);
	memcpy(queue + sizeof pos1_reply_bad, pos2_reply, sizeof pos2_reply);
	script(queue, sizeof pos1_reply_bad + sizeof pos2_reply, 100);
	uint64_t start = fk.now;
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_E_CHECKSUM);
	assert_int_equal(fk.now - start, 100);
	assert_int_equal(m.status[0], DXL_E_CHECKSUM);
	assert_int_equal(m.status[1], DXL_OK);
	assert_int_equal(bus.servo[1].checksum_errors, 1);
	assert_int_equal(bus.servo[2].replies, 1);
	/* ID 2 answers with the wrong size */
	memcpy(queue, pos1_reply, sizeof pos1_reply);
	memcpy(queue + sizeof pos1_reply, temp2_reply, sizeof temp2_reply);
	script(queue, sizeof pos1_reply + sizeof temp2_reply, 100);
	assert_int_equal(bus_sync_read(&bus, 132, 4, ids, 2, &m), DXL_E_WRONG_LENGTH);
	assert_int_equal(m.status[1], DXL_E_WRONG_LENGTH);
	assert_int_equal(bus.servo[2].wrong_length, 1);
	assert_int_equal(dxl2_get_u32(bus_multi_data(&m, 0)), 166);
	/* a servo not asked answers first: counted against the one expected,
	 * who then answers all the same */
	memcpy(queue, ping2_reply, sizeof ping2_reply);
	memcpy(queue + sizeof ping2_reply, pos1_reply, sizeof pos1_reply);
	script(queue, sizeof ping2_reply + sizeof pos1_reply, 100);
	assert_int_equal(bus_sync_read(&bus, 132, 4, (const uint8_t[]){ 1 }, 1, &m), DXL_OK);
	assert_int_equal(bus.servo[1].wrong_id, 1);
	assert_int_equal(m.status[0], DXL_OK);
	/* ... and when it never does, its slot says so */
	script(pos2_reply, sizeof pos2_reply, 100);
	assert_int_equal(bus_sync_read(&bus, 132, 4, (const uint8_t[]){ 1 }, 1, &m), DXL_E_WRONG_ID);
	assert_int_equal(bus.servo[1].wrong_id, 2);
}

/* The asynchronous core as the daemon's poll loop would drive it. */
static void test_sync_read_async(void **state)
{
	(void)state;
	setup_bus2(false);
	uint8_t data[8];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const uint8_t ids[2] = { 1, 2 };
	uint64_t start = fk.now;
	fake_push(&fk, pos1_reply, sizeof pos1_reply, start + 200);
	fake_push(&fk, pos2_reply, sizeof pos2_reply, start + 400);
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
	fake_push(&fk, pos1_reply, sizeof pos1_reply, start + 300);
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
	script(ping1_reply, sizeof ping1_reply, 10);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_OK);
}

static void test_bulk(void **state)
{
	(void)state;
	setup_bus2(false);
	uint8_t data[3];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	const struct dxl_item items[2] = { { 1, 144, 2, NULL }, { 2, 146, 1, NULL } };
	memcpy(queue, volt1_reply, sizeof volt1_reply);
	memcpy(queue + sizeof volt1_reply, temp2_reply, sizeof temp2_reply);
	script(queue, sizeof volt1_reply + sizeof temp2_reply, 100);
	assert_int_equal(bus_bulk_read(&bus, items, 2, &m), DXL_OK);
	assert_memory_equal(fk.tx, bulk_read12, sizeof bulk_read12);
	assert_int_equal(dxl_get_u16(bus_multi_data(&m, 0)), 119);   /* 11.9 V */
	assert_int_equal(*bus_multi_data(&m, 1), 36);                 /* 36 °C */
	/* SYNC_WRITE and BULK_WRITE: no reply, no wait */
	size_t at = fk.ntx;
	uint64_t now = fk.now;
	uint8_t goals[8];
	dxl2_put_u32(goals, 150);
	dxl2_put_u32(goals + 4, 170);
	assert_int_equal(bus_sync_write(&bus, 116, 4, (const uint8_t[]){ 1, 2 }, goals, 2), DXL_OK);
	assert_memory_equal(fk.tx + at, sync_write12, sizeof sync_write12);
	at += sizeof sync_write12;
	const uint8_t d1[2] = { 0xA0, 0x00 }, d2[1] = { 0x50 };
	const struct dxl_item w[2] = { { 1, 0x20, 2, d1 }, { 2, 0x1F, 1, d2 } };
	assert_int_equal(bus_bulk_write(&bus, w, 2), DXL_OK);
	assert_memory_equal(fk.tx + at, bulk_write12, sizeof bulk_write12);
	assert_int_equal(fk.now, now);
	assert_false(bus_is_pending(&bus));
}

/* Broadcast PING: every servo answers, each after the one before; all are
 * collected until the deadline, which allows for every ID. */
static void test_ping_all(void **state)
{
	(void)state;
	setup_bus2(false);
	/* queued before the request; the flush before it drops only what arrived */
	fake_push(&fk, ping1_reply, sizeof ping1_reply, fk.now + 100);
	fake_push(&fk, ping2_reply, sizeof ping2_reply, fk.now + 3100);
	struct bus_found found[4];
	size_t n = 9;
	uint64_t start = fk.now;
	assert_int_equal(bus_ping_all(&bus, found, 4, &n), DXL_OK);
	assert_memory_equal(fk.tx, ping_bc, sizeof ping_bc);
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
	memcpy(queue, ping1_reply, sizeof ping1_reply);
	memcpy(queue + sizeof ping1_reply, ping1_reply, sizeof ping1_reply);
	script(queue, 2 * sizeof ping1_reply, 100);
	assert_int_equal(bus_ping_all(&bus, found, 4, &n), DXL_OK);
	assert_int_equal(n, 1);
	assert_int_equal(bus.servo[1].wrong_id, 1);
}

/* Echo: on single-wire wiring our bytes come back first. */
static void test_echo(void **state)
{
	(void)state;
	setup_bus2(true);
	script(ping1_reply, sizeof ping1_reply, 100);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_OK);
	assert_int_equal(bus.bytes_in, 24);
	assert_int_equal(bus.echo_errors, 0);
	/* a SYNC_WRITE's echo arriving during the next request: matched */
	fk.echo_delay_us = 50;
	uint8_t goals[8] = { 0 };
	assert_int_equal(bus_sync_write(&bus, 116, 4, (const uint8_t[]){ 1, 2 }, goals, 2), DXL_OK);
	uint32_t pos = 0;
	script(pos1_reply, sizeof pos1_reply, 150);
	assert_int_equal(bus_read_u32(&bus, 1, 132, &pos, NULL), DXL_OK);
	assert_int_equal(pos, 166);
	/* a differing echo byte */
	fk.echo_delay_us = 0;
	fk.echo_corrupt_at = 6;
	script(ping1_reply, sizeof ping1_reply, 100);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_E_ECHO);
	assert_int_equal(bus.echo_errors, 1);
	fk.echo_corrupt_at = 0;
	/* echo off, wiring that echoes: the echo is recognised, not parsed,
	 * and the reply behind it delivered at once */
	setup_bus2(false);
	fk.echo = true;
	script(ping1_reply, sizeof ping1_reply, 100);
	uint64_t start = fk.now;
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_OK);
	assert_int_equal(fk.now - start, 100);
	assert_int_equal(bus.unexpected_echoes, 1);
	assert_int_equal(bus.servo[1].resyncs, 0);
	assert_int_equal(bus.parser.v2.header_errors, 0);
	/* and a reply that starts like the request, then differs, is parsed
	 * whole (the held bytes go to the parser first) */
	setup_bus2(false);
	script(ping1_reply, sizeof ping1_reply, 100);
	assert_int_equal(bus_ping_model(&bus, 1, NULL, NULL, NULL), DXL_OK);
	assert_int_equal(bus.unexpected_echoes, 0);
}

/* Lateness on 2.0: the floor is a 10-byte PING and its 14-byte reply. */
static void test_reply_lateness(void **state)
{
	(void)state;
	struct bus_lateness lt;
	static const uint64_t held[] = { 1240, 1240, 1240 };
	setup_bus2(false);
	script(ping1_reply, sizeof ping1_reply, 0);
	fk.reply_every = true;
	fk.delays = held;
	fk.ndelays = 3;
	assert_int_equal(bus_reply_lateness(&bus, 1, 0, 3, &lt), DXL_OK);
	assert_int_equal(lt.replies, 3);
	assert_int_equal(lt.median_us, 1000);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_protocol_switch),
		cmocka_unit_test(test_ping),
		cmocka_unit_test(test_timeout_exact),
		cmocka_unit_test(test_read_write_golden),
		cmocka_unit_test(test_err_field),
		cmocka_unit_test(test_bad_replies),
		cmocka_unit_test(test_sync_read),
		cmocka_unit_test(test_sync_read_missing),
		cmocka_unit_test(test_sync_read_bad_replies),
		cmocka_unit_test(test_sync_read_async),
		cmocka_unit_test(test_bulk),
		cmocka_unit_test(test_ping_all),
		cmocka_unit_test(test_echo),
		cmocka_unit_test(test_reply_lateness),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
