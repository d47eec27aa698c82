/*
 * test_protocol_backend.c — both protocol tables (dxl_proto.h) driven
 * through the table alone, as the bus drives them. Every expected packet is
 * typed from the manuals (ax12.md's worked examples; the e-manual's
 * Protocol 2.0 page, the 2.0 rows of test_protocol_packet.c), never produced by
 * our encoder.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "bus.h"
#include "dxl_proto.h"

struct golden {
	const struct dxl_proto *proto;
	uint8_t ping[16];          /* PING id 1 */
	size_t ping_len;
	uint8_t read[16];          /* READ id 1 */
	size_t read_len;
	uint16_t read_addr, read_count;
	uint8_t reply[16];         /* the READ's status packet */
	size_t reply_len;
	uint8_t reply_params[4];
	uint8_t err;               /* a status error and its text */
	const char *err_text;
};

static const struct golden rows[] = {
	{ &dxl_proto_v1,
	  /* ax12.md: PING id 1; READ id 1, addr 43, 1 byte -> 32 °C */
	  { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB }, 6,
	  { 0xFF, 0xFF, 0x01, 0x04, 0x02, 0x2B, 0x01, 0xCC }, 8, 43, 1,
	  { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB }, 7, { 0x20 },
	  0x24, "overheating|overload" },
	{ &dxl_proto_v2,
	  /* e-manual 2.0: Ping example 1; Read of Present Position (132), 4 bytes -> 166 */
	  { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E }, 10,
	  { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15 }, 14, 132, 4,
	  { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0 }, 15,
	  { 0xA6, 0x00, 0x00, 0x00 },
	  0x84, "alert|data range" },
};
#define NROWS (sizeof rows / sizeof rows[0])

static void test_lookup(void **state)
{
	(void)state;
	assert_ptr_equal(dxl_proto_by_number(1), &dxl_proto_v1);
	assert_ptr_equal(dxl_proto_by_number(2), &dxl_proto_v2);
	assert_null(dxl_proto_by_number(0));
	assert_null(dxl_proto_by_number(3));
	for (size_t i = 0; i < NROWS; i++)
		assert_int_equal(rows[i].proto->number, (int)i + 1);
}

static void test_encoders_golden(void **state)
{
	(void)state;
	for (size_t i = 0; i < NROWS; i++) {
		const struct golden *g = &rows[i];
		uint8_t buf[64];
		assert_int_equal(g->proto->encode_ping(buf, sizeof buf, 1), (int)g->ping_len);
		assert_memory_equal(buf, g->ping, g->ping_len);
		assert_int_equal(g->proto->encode_read(buf, sizeof buf, 1, g->read_addr, g->read_count), (int)g->read_len);
		assert_memory_equal(buf, g->read, g->read_len);
		/* the table's round trip: the PING and its reply (no stuffing in these bytes) */
		uint8_t zeros[8] = { 0 };
		int reply = g->proto->encode_status(buf, sizeof buf, 1, 0, zeros, g->proto->ping_reply_params);
		assert_int_equal((size_t)reply + g->ping_len, g->proto->ping_round_trip_bytes);
		/* a reply is never longer than status_bytes_max says */
		assert_true((size_t)reply <= g->proto->status_bytes_max(g->proto->ping_reply_params));
		assert_true(g->reply_len <= g->proto->status_bytes_max(g->read_count));
	}
	/* 1.0's 8-bit fields refuse what does not fit */
	uint8_t buf[64];
	assert_int_equal(dxl_proto_v1.encode_read(buf, sizeof buf, 1, 0x100, 1), DXL_E_ARG);
	assert_int_equal(dxl_proto_v1.encode_write(buf, sizeof buf, 1, 0x100, buf, 1), DXL_E_ARG);
	assert_int_equal(dxl_proto_v1.encode_factory_reset(buf, sizeof buf, 1, DXL_RESET_KEEP_ID), DXL_E_ARG);
}

/* The golden reply fed one byte at a time, behind garbage, through the table's parser. */
static void test_parser_golden(void **state)
{
	(void)state;
	for (size_t i = 0; i < NROWS; i++) {
		const struct golden *g = &rows[i];
		union dxl_proto_parser p;
		struct dxl_frame f;
		static const uint8_t garbage[] = { 0x00, 0xFF, 0x13 };
		g->proto->parser_init(&p, false);
		size_t used = 0;
		assert_int_equal(g->proto->parser_feed(&p, garbage, sizeof garbage, &used, &f), DXL_NEED_MORE);
		int r = DXL_NEED_MORE;
		for (size_t k = 0; k < g->reply_len; k++) {
			assert_int_equal(r, DXL_NEED_MORE);
			r = g->proto->parser_feed(&p, &g->reply[k], 1, &used, &f);
			assert_int_equal(used, 1);
		}
		assert_int_equal(r, DXL_FRAME);
		assert_int_equal(f.id, 1);
		assert_int_equal(f.err, 0);
		assert_int_equal(f.nparams, g->read_count);
		assert_int_equal(f.wire_bytes, g->reply_len);
		assert_memory_equal(f.params, g->reply_params, g->read_count);
		assert_int_equal(g->proto->parser_feed(&p, NULL, 0, &used, &f), DXL_NEED_MORE);
	}
}

static void test_texts(void **state)
{
	(void)state;
	for (size_t i = 0; i < NROWS; i++) {
		const struct golden *g = &rows[i];
		char buf[64];
		assert_string_equal(g->proto->err_format(g->err, buf, sizeof buf), g->err_text);
		assert_string_equal(g->proto->err_format(0, buf, sizeof buf), "none");
		assert_string_equal(g->proto->instruction_name(DXL_INST_PING), "PING");
		assert_true(g->proto->err_alert == 0 || (g->err & g->proto->err_alert) != 0);
	}
}

/* A capability and its encoder come together; 1.0 (the AX-12's) has none
 * of the optional ones, 2.0 all. */
static void test_caps(void **state)
{
	(void)state;
	for (size_t i = 0; i < NROWS; i++) {
		const struct dxl_proto *pr = rows[i].proto;
		assert_int_equal(dxl_proto_can(pr, DXL_CAP_SYNC_READ), pr->encode_sync_read != NULL);
		assert_int_equal(dxl_proto_can(pr, DXL_CAP_BULK_READ), pr->encode_bulk_read != NULL);
		assert_int_equal(dxl_proto_can(pr, DXL_CAP_BULK_WRITE), pr->encode_bulk_write != NULL);
		assert_int_equal(dxl_proto_can(pr, DXL_CAP_REBOOT), pr->encode_reboot != NULL);
		assert_int_equal(dxl_proto_can(pr, DXL_CAP_CLEAR), pr->encode_clear_multi_turn != NULL);
		assert_non_null(pr->encode_instruction);
		assert_non_null(pr->encode_write);
		assert_non_null(pr->encode_reg_write);
		assert_non_null(pr->encode_action);
		assert_non_null(pr->encode_factory_reset);
		assert_non_null(pr->encode_sync_write);
		assert_true(pr->max_packet <= BUS_MAX_PACKET);
	}
	assert_int_equal(dxl_proto_v1.caps, 0);
	assert_true(dxl_proto_can(&dxl_proto_v2, DXL_CAP_SYNC_READ | DXL_CAP_BULK_READ | DXL_CAP_REBOOT |
	                                             DXL_CAP_PING_MODEL | DXL_CAP_BROADCAST_PING));
	assert_true(dxl_proto_v1.echo_reads_as_status);
	assert_false(dxl_proto_v2.echo_reads_as_status);
}

/* Seeded random status packets: what a table encodes, its parser gives back. */
static void test_round_trip(void **state)
{
	(void)state;
	srand(24);
	for (size_t i = 0; i < NROWS; i++) {
		const struct dxl_proto *pr = rows[i].proto;
		for (int k = 0; k < 2000; k++) {
			uint8_t params[64], wire[256];
			struct dxl_frame f;
			union dxl_proto_parser p;
			size_t n = (size_t)rand() % sizeof params, used = 0;
			uint8_t id = (uint8_t)(rand() % (pr->max_id + 1));
			/* 1.0's error byte has 7 bits; 2.0's ERR field 8 */
			uint8_t err = (uint8_t)(rand() & (pr->err_alert ? 0xFF : 0x7F));
			for (size_t j = 0; j < n; j++)
				params[j] = (uint8_t)(k % 3 == 0 ? (j % 3 == 2 ? 0xFD : 0xFF) : rand());
			int len = pr->encode_status(wire, sizeof wire, id, err, params, n);
			assert_true(len > 0);
			assert_true((size_t)len <= pr->status_bytes_max(n));
			pr->parser_init(&p, false);
			assert_int_equal(pr->parser_feed(&p, wire, (size_t)len, &used, &f), DXL_FRAME);
			assert_int_equal(used, (size_t)len);
			assert_int_equal(f.id, id);
			assert_int_equal(f.err, err);
			assert_int_equal(f.nparams, n);
			assert_int_equal(f.wire_bytes, len);
			assert_memory_equal(f.params, params, n);
		}
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_lookup),
		cmocka_unit_test(test_encoders_golden),
		cmocka_unit_test(test_parser_golden),
		cmocka_unit_test(test_texts),
		cmocka_unit_test(test_caps),
		cmocka_unit_test(test_round_trip),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
