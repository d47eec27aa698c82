/*
 * test_sim_bus2.c — a simulated Protocol 2.0 bus without a pty: the wire
 * timing (the same model as 1.0's: 10 bit times a byte, the return delay),
 * replies of several servos one after another in the order the manual gives
 * (SYNC_READ and BULK_READ: the request's list; a broadcast PING: by ID), a
 * servo missing from a SYNC_READ, the CRC error reply, the bad-input counters
 * (bad CRC, bad stuffing, header errors), the wrong baud, and every reply
 * fault on a 2.0 status packet. Request bytes come from the manual where it
 * prints them; the expected CRCs of the rest are computed by a bit-by-bit
 * CRC written here, not by the project's table.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "dxl2.h"
#include "dxl2_table.h"
#include "../../sim-bridge/fault.h"
#include "../../sim-bridge/line.h"
#include "../../sim-bridge/simbus.h"

#define MS 1000000LL
#define US 1000LL
#define HDR 0xFF, 0xFF, 0xFD, 0x00

/* A 1 Mbps bus (10 µs a byte) with X servos of these IDs (XL430, XM430, ...
 * alternating), return delay 0. */
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

/* Everything queued, with the release times of the first and last byte. */
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

/* The status packets in buf, as the controller's parser sees them: count of
 * frames, the first ones in pkts, and the parser's error count. */
static size_t statuses(const uint8_t *buf, size_t n, struct dxl2_packet *pkts, size_t cap, uint32_t *errors)
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

/* CRC-16/0x8005, bit by bit (the e-manual's definition, not its table). */
static uint16_t crc_bitwise(const uint8_t *d, size_t n)
{
	uint16_t crc = 0;
	for (size_t i = 0; i < n; i++) {
		crc ^= (uint16_t)(d[i] << 8);
		for (int k = 0; k < 8; k++)
			crc = (uint16_t)((crc & 0x8000) ? (crc << 1) ^ 0x8005 : crc << 1);
	}
	return crc;
}

static void test_ping_timing(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	static const uint8_t ids[] = { 1, 2 };
	bus_x(&b, ids, 2, 1000000);
	/* the e-manual's Ping example, 10 bytes: 100 µs on the wire */
	static const uint8_t ping[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
	sim_bus_feed(&b, ping, sizeof ping, 1000 * MS);
	size_t n = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(n, 14);
	struct dxl2_packet st;
	assert_int_equal(statuses(out, n, &st, 1, NULL), 1);
	assert_int_equal(st.id, 1);
	assert_int_equal(st.params[0] | (st.params[1] << 8), DXL2_MODEL_XL430_W250);
	assert_int_equal(first - 1000 * MS, 110 * US);
	assert_int_equal(last - first, 130 * US);
	/* the factory return delay: 500 µs more */
	sim_xservo_poke(&b.joints[0].xservo, DXL2_X_RETURN_DELAY_TIME, 250);
	sim_bus_feed(&b, ping, sizeof ping, 2000 * MS);
	drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(first - 2000 * MS, 610 * US);
	/* at the X series' factory 57600 bps a byte takes 173.6 µs */
	bus_x(&b, ids, 2, 57600);
	sim_bus_feed(&b, ping, sizeof ping, 0);
	drain(&b, out, sizeof out, &first, &last);
	assert_true(first >= 11 * 173 * US && first <= 11 * 174 * US);
}

/* SYNC_READ: the replies follow the request's list, each after the one
 * before it; a servo missing from the list leaves no gap (README). */
static void test_sync_read_order_and_missing(void **state)
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
	assert_int_equal(statuses(out, got, st, 4, NULL), 2);
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
	assert_int_equal(statuses(out, got, st, 4, NULL), 2);
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
	assert_int_equal(statuses(out, got, st, 4, NULL), 2);
	assert_int_equal(st[0].nparams, 2);
	assert_int_equal(st[1].nparams, 1);
}

/* A broadcast PING: every servo answers, lowest ID first (e-manual: "in
 * their arranged order"), without colliding, whatever the wiring order. */
static void test_broadcast_ping_in_id_order(void **state)
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
	assert_int_equal(statuses(out, got, st, 4, NULL), 3);
	assert_int_equal(st[0].id, 2);
	assert_int_equal(st[1].id, 5);
	assert_int_equal(st[2].id, 7);
	assert_int_equal(b.line.collisions, 0);
}

/* A packet to a servo with a bad CRC: the CRC error (3) in its reply. */
static void test_bad_crc_reply(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	static const uint8_t ids[] = { 1, 2 };
	bus_x(&b, ids, 2, 1000000);
	static const uint8_t bad[] = { HDR, 0x02, 0x03, 0x00, 0x01, 0x19, 0x4F };
	sim_bus_feed(&b, bad, sizeof bad, 0);
	size_t n = drain(&b, out, sizeof out, &first, &last);
	uint8_t want[11] = { HDR, 0x02, 0x04, 0x00, 0x55, 0x03 };
	uint16_t crc = crc_bitwise(want, 9);
	want[9] = (uint8_t)crc;
	want[10] = (uint8_t)(crc >> 8);
	assert_int_equal(n, sizeof want);
	assert_memory_equal(out, want, sizeof want);
	assert_int_equal(b.count.checksum_errors, 1);
	assert_int_equal(b.joints[1].xservo.count.crc_errors, 1);
	/* to the broadcast ID: counted, unanswered */
	static const uint8_t bad_bc[] = { HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x43 };
	sim_bus_feed(&b, bad_bc, sizeof bad_bc, MS);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 0);
	assert_int_equal(b.count.checksum_errors, 2);
}

/* Bad input is counted and survived: a header inside a packet (bad
 * stuffing), reserved byte, ID 253, a status on the instruction side; a
 * Protocol 1.0 packet is noise on a 2.0 bus. A good packet after all of it
 * is answered. */
static void test_bad_input_counters(void **state)
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

/* The adapter's latency and a single-wire echo act on a 2.0 bus as on 1.0. */
static void test_latency_and_echo(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	static const uint8_t ids[] = { 1 };
	bus_x(&b, ids, 1, 1000000);
	b.latency_ns = 16 * MS;
	b.echo = true;
	static const uint8_t ping[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
	sim_bus_feed(&b, ping, sizeof ping, 0);
	size_t n = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(n, 24);
	assert_memory_equal(out, ping, sizeof ping);   /* our own bytes first */
	assert_int_equal(first, 16 * MS + 10 * US);
	assert_int_equal(last, 16 * MS + 240 * US);
	struct dxl2_packet st;
	assert_int_equal(statuses(out + 10, 14, &st, 1, NULL), 1);
}

/* A servo at another baud rate hears nothing. */
static void test_wrong_baud(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	static const uint8_t ids[] = { 1, 2 };
	bus_x(&b, ids, 2, 57600);
	sim_xservo_poke(&b.joints[0].xservo, DXL2_X_BAUD_RATE, 3);   /* 1 Mbps */
	static const uint8_t ping[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
	sim_bus_feed(&b, ping, sizeof ping, 0);
	assert_int_equal(drain(&b, out, sizeof out, &first, &last), 0);
	assert_int_equal(b.count.wrong_baud, 1);
	assert_true(sim_joint_hears(&b, &b.joints[1]));
	assert_false(sim_joint_hears(&b, &b.joints[0]));
}

/* Set a fault on servo 1 from its text form. */
static void set_fault(struct sim_bus *b, size_t joint, const char *text)
{
	char buf[128], err[128], *argv[8];
	int argc = 0;
	enum sim_fault_kind kind;
	struct sim_fault f;
	snprintf(buf, sizeof buf, "%s", text);
	for (char *save = NULL, *w = strtok_r(buf, " ", &save); w && argc < 8; w = strtok_r(NULL, " ", &save))
		argv[argc++] = w;
	assert_int_equal(sim_fault_parse(argc, argv, &kind, &f, err, sizeof err), 0);
	b->joints[joint].faults.f[kind] = f;
}

static size_t ping_x(struct sim_bus *b, uint8_t *out, int64_t at)
{
	int64_t first, last;
	static const uint8_t ping[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
	sim_bus_feed(b, ping, sizeof ping, at);
	return drain(b, out, 128, &first, &last);
}

static void test_faults_on_status2(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[128];
	struct dxl2_packet st[2];
	uint32_t errors;
	static const uint8_t ids[] = { 1, 2 };
	bus_x(&b, ids, 2, 1000000);
	/* stuck-error: the alert bit (default), a well-formed packet */
	set_fault(&b, 0, "stuck-error count=1");
	size_t n = ping_x(&b, out, 0);
	assert_int_equal(statuses(out, n, st, 2, &errors), 1);
	assert_int_equal(st[0].err, DXL2_ERR_ALERT);
	assert_int_equal(st[0].nparams, 3);
	/* ... or an error number, or both */
	set_fault(&b, 0, "stuck-error alert|data-range count=1");
	n = ping_x(&b, out, MS);
	assert_int_equal(statuses(out, n, st, 2, &errors), 1);
	assert_int_equal(st[0].err, DXL2_ERR_ALERT | DXL2_ERRNUM_DATA_RANGE);
	/* wrong-id: another ID, a valid CRC */
	set_fault(&b, 0, "wrong-id 9 count=1");
	n = ping_x(&b, out, 2 * MS);
	assert_int_equal(statuses(out, n, st, 2, &errors), 1);
	assert_int_equal(st[0].id, 9);
	/* bad-checksum: the CRC inverted */
	set_fault(&b, 0, "bad-checksum count=1");
	n = ping_x(&b, out, 3 * MS);
	assert_int_equal(statuses(out, n, st, 2, &errors), 0);
	assert_int_equal(errors, 1);
	/* truncate: half a packet */
	set_fault(&b, 0, "truncate count=1");
	n = ping_x(&b, out, 4 * MS);
	assert_int_equal(n, 7);
	/* garbage before the reply; the reply still frames */
	set_fault(&b, 0, "garbage 5 count=1");
	n = ping_x(&b, out, 5 * MS);
	assert_int_equal(n, 19);
	assert_int_equal(statuses(out, n, st, 2, &errors), 1);
	/* no-reply inside a SYNC_READ: the next servo answers at once */
	set_fault(&b, 0, "no-reply count=1");
	uint8_t req[64];
	int64_t first, last;
	static const uint8_t both[] = { 1, 2 };
	int r = dxl2_encode_sync_read(req, sizeof req, DXL2_X_PRESENT_POSITION, 4, both, 2);
	sim_bus_feed(&b, req, (size_t)r, 10 * MS);
	n = drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(statuses(out, n, st, 2, NULL), 1);
	assert_int_equal(st[0].id, 2);
	assert_int_equal(first - 10 * MS, (int64_t)(r + 1) * 10 * US);
	/* slow: 5 ms late */
	set_fault(&b, 0, "slow count=1");
	sim_bus_feed(&b, (const uint8_t[]){ HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E }, 10, 20 * MS);
	drain(&b, out, sizeof out, &first, &last);
	assert_int_equal(first - 20 * MS, 5 * MS + 110 * US);
}

/* The text forms: stuck-error takes 1.0's bits or 2.0's ERR field. */
static void test_stuck_error_vocabularies(void **state)
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

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ping_timing),
		cmocka_unit_test(test_sync_read_order_and_missing),
		cmocka_unit_test(test_broadcast_ping_in_id_order),
		cmocka_unit_test(test_bad_crc_reply),
		cmocka_unit_test(test_bad_input_counters),
		cmocka_unit_test(test_latency_and_echo),
		cmocka_unit_test(test_wrong_baud),
		cmocka_unit_test(test_faults_on_status2),
		cmocka_unit_test(test_stuck_error_vocabularies),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
