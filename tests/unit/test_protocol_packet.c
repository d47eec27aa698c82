/*
 * test_protocol_packet.c — encoders and decoding against the manual's worked
 * examples. The expected bytes are typed in from the AX-12 manual (ax12.md's
 * table), never produced by our own encoder: the simulator reuses this code,
 * so a symmetric bug would otherwise pass every integration test.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "dxl.h"

/* Guard value written past the end of encoder buffers. */
#define GUARD 0xA5

struct golden {
	const char *legend;
	enum dxl_parse_kind kind;
	uint8_t bytes[32];
	size_t n;
	/* decoded fields */
	uint8_t id, code, nparams;
	uint8_t params[16];
};

static const struct golden goldens[] = {
	{ "PING id 1", DXL_PARSE_INSTRUCTION,
	  { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB }, 6, 0x01, DXL_INST_PING, 0, { 0 } },
	{ "PING reply", DXL_PARSE_STATUS,
	  { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC }, 6, 0x01, 0x00, 0, { 0 } },
	{ "READ id 1 temperature", DXL_PARSE_INSTRUCTION,
	  { 0xFF, 0xFF, 0x01, 0x04, 0x02, 0x2B, 0x01, 0xCC }, 8, 0x01, DXL_INST_READ, 2, { 0x2B, 0x01 } },
	{ "READ reply 32 C", DXL_PARSE_STATUS,
	  { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB }, 7, 0x01, 0x00, 1, { 0x20 } },
	{ "WRITE id 1 addr 12 64 AA", DXL_PARSE_INSTRUCTION,
	  { 0xFF, 0xFF, 0x01, 0x05, 0x03, 0x0C, 0x64, 0xAA, 0xDC }, 9, 0x01, DXL_INST_WRITE, 3,
	  { 0x0C, 0x64, 0xAA } },
	{ "WRITE id 1 goal 512", DXL_PARSE_INSTRUCTION,
	  { 0xFF, 0xFF, 0x01, 0x05, 0x03, 0x1E, 0x00, 0x02, 0xD6 }, 9, 0x01, DXL_INST_WRITE, 3,
	  { 0x1E, 0x00, 0x02 } },
	{ "broadcast set ID 1", DXL_PARSE_INSTRUCTION,
	  { 0xFF, 0xFF, 0xFE, 0x04, 0x03, 0x03, 0x01, 0xF6 }, 8, 0xFE, DXL_INST_WRITE, 2, { 0x03, 0x01 } },
	{ "ACTION broadcast", DXL_PARSE_INSTRUCTION,
	  { 0xFF, 0xFF, 0xFE, 0x02, 0x05, 0xFA }, 6, 0xFE, DXL_INST_ACTION, 0, { 0 } },
	{ "SYNC_WRITE ids 0,1 goal+speed", DXL_PARSE_INSTRUCTION,
	  { 0xFF, 0xFF, 0xFE, 0x0E, 0x83, 0x1E, 0x04, 0x00, 0x10, 0x00, 0x50, 0x01, 0x01, 0x20, 0x02,
	    0x60, 0x03, 0x67 }, 18, 0xFE, DXL_INST_SYNC_WRITE, 12,
	  { 0x1E, 0x04, 0x00, 0x10, 0x00, 0x50, 0x01, 0x01, 0x20, 0x02, 0x60, 0x03 } },
	{ "status overload+overheating", DXL_PARSE_STATUS,
	  { 0xFF, 0xFF, 0x01, 0x02, 0x24, 0xD8 }, 6, 0x01, 0x24, 0, { 0 } },
};
#define NGOLDEN (sizeof goldens / sizeof goldens[0])

static void check_encoded(const struct golden *g, const uint8_t *buf, int n)
{
	print_message("# %s\n", g->legend);
	assert_int_equal(n, (int)g->n);
	assert_memory_equal(buf, g->bytes, g->n);
	assert_int_equal(buf[g->n], GUARD);
}

/* Each row encoded by the matching encoder. */
static void test_golden_encode(void **state)
{
	(void)state;
	uint8_t buf[64];
	int n;

	memset(buf, GUARD, sizeof buf);
	n = dxl_encode_ping(buf, sizeof buf, 1);
	check_encoded(&goldens[0], buf, n);

	memset(buf, GUARD, sizeof buf);
	n = dxl_encode_status(buf, sizeof buf, 1, 0, NULL, 0);
	check_encoded(&goldens[1], buf, n);

	memset(buf, GUARD, sizeof buf);
	n = dxl_encode_read(buf, sizeof buf, 1, 43, 1);
	check_encoded(&goldens[2], buf, n);

	memset(buf, GUARD, sizeof buf);
	const uint8_t temp = 32;
	n = dxl_encode_status(buf, sizeof buf, 1, 0, &temp, 1);
	check_encoded(&goldens[3], buf, n);

	memset(buf, GUARD, sizeof buf);
	const uint8_t d64aa[2] = { 0x64, 0xAA };
	n = dxl_encode_write(buf, sizeof buf, 1, 12, d64aa, 2);
	check_encoded(&goldens[4], buf, n);

	memset(buf, GUARD, sizeof buf);
	uint8_t goal[2];
	dxl_put_u16(goal, 512);
	n = dxl_encode_write(buf, sizeof buf, 1, 30, goal, 2);
	check_encoded(&goldens[5], buf, n);

	memset(buf, GUARD, sizeof buf);
	const uint8_t one = 1;
	n = dxl_encode_write(buf, sizeof buf, DXL_BROADCAST_ID, 3, &one, 1);
	check_encoded(&goldens[6], buf, n);

	memset(buf, GUARD, sizeof buf);
	n = dxl_encode_action(buf, sizeof buf, DXL_BROADCAST_ID);
	check_encoded(&goldens[7], buf, n);

	memset(buf, GUARD, sizeof buf);
	const uint8_t ids[2] = { 0, 1 };
	uint8_t data[8];
	dxl_put_u16(data + 0, 0x010);
	dxl_put_u16(data + 2, 0x150);
	dxl_put_u16(data + 4, 0x220);
	dxl_put_u16(data + 6, 0x360);
	n = dxl_encode_sync_write(buf, sizeof buf, 30, 4, ids, data, 2);
	check_encoded(&goldens[8], buf, n);

	memset(buf, GUARD, sizeof buf);
	n = dxl_encode_status(buf, sizeof buf, 1, DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT, NULL, 0);
	check_encoded(&goldens[9], buf, n);
}

/* Each row through the generic encoder as well (instruction or status). */
static void test_golden_encode_generic(void **state)
{
	(void)state;
	for (size_t i = 0; i < NGOLDEN; i++) {
		const struct golden *g = &goldens[i];
		uint8_t buf[64];
		memset(buf, GUARD, sizeof buf);
		int n = g->kind == DXL_PARSE_INSTRUCTION
		      ? dxl_encode_instruction(buf, sizeof buf, g->id, g->code, g->params, g->nparams)
		      : dxl_encode_status(buf, sizeof buf, g->id, g->code, g->params, g->nparams);
		check_encoded(g, buf, n);
	}
}

/* Each row decoded by the parser of its kind, in one piece. */
static void test_golden_decode(void **state)
{
	(void)state;
	for (size_t i = 0; i < NGOLDEN; i++) {
		const struct golden *g = &goldens[i];
		struct dxl_parser p;
		struct dxl_packet pkt;
		size_t used = 0;
		print_message("# %s\n", g->legend);
		dxl_parser_init(&p, g->kind);
		int r = dxl_parser_feed(&p, g->bytes, g->n, &used, &pkt);
		assert_int_equal(r, DXL_FRAME);
		assert_int_equal(used, g->n);
		assert_int_equal(pkt.id, g->id);
		assert_int_equal(pkt.code, g->code);
		assert_int_equal(pkt.nparams, g->nparams);
		if (g->nparams)
			assert_memory_equal(pkt.params, g->params, g->nparams);
		assert_int_equal(p.frames, 1);
		assert_int_equal(p.have, 0);
		assert_int_equal(p.bytes_dropped, 0);
	}
}

/* The checksum of each row, computed from ID to the last parameter. */
static void test_golden_checksum(void **state)
{
	(void)state;
	for (size_t i = 0; i < NGOLDEN; i++) {
		const struct golden *g = &goldens[i];
		assert_int_equal(dxl_checksum(g->bytes + 2, g->n - 3), g->bytes[g->n - 1]);
	}
}

static void test_encode_args(void **state)
{
	(void)state;
	uint8_t buf[DXL_MAX_PACKET + 8];
	const uint8_t data[DXL_MAX_PARAMS] = { 0 };

	/* too small: nothing written at all */
	memset(buf, GUARD, sizeof buf);
	assert_int_equal(dxl_encode_ping(buf, 5, 1), DXL_E_BUFFER);
	assert_int_equal(buf[0], GUARD);
	assert_int_equal(dxl_encode_ping(buf, 6, 1), 6);
	memset(buf, GUARD, sizeof buf);
	assert_int_equal(dxl_encode_write(buf, 9, 1, 30, data, 3), DXL_E_BUFFER);
	assert_int_equal(buf[0], GUARD);

	/* IDs: 0xFF is never valid; a status never comes from broadcast */
	assert_int_equal(dxl_encode_ping(buf, sizeof buf, 0xFF), DXL_E_ARG);
	assert_int_equal(dxl_encode_ping(buf, sizeof buf, DXL_BROADCAST_ID), 6);
	assert_int_equal(dxl_encode_status(buf, sizeof buf, DXL_BROADCAST_ID, 0, NULL, 0), DXL_E_ARG);
	/* an error byte with bit 7 would not parse */
	assert_int_equal(dxl_encode_status(buf, sizeof buf, 1, 0x80, NULL, 0), DXL_E_ARG);

	/* READ of 0 bytes, WRITE of nothing */
	assert_int_equal(dxl_encode_read(buf, sizeof buf, 1, 36, 0), DXL_E_ARG);
	assert_int_equal(dxl_encode_write(buf, sizeof buf, 1, 30, data, 0), DXL_E_ARG);
	assert_int_equal(dxl_encode_write(buf, sizeof buf, 1, 30, NULL, 2), DXL_E_ARG);

	/* encoded packets stay within 250 bytes on the wire (ROBOTIS's limit) */
	assert_int_equal(dxl_encode_instruction(buf, sizeof buf, 1, DXL_INST_WRITE, data,
	                                        DXL_MAX_TX_PARAMS), DXL_MAX_TX_PACKET);
	assert_int_equal(buf[3], DXL_MAX_TX_PACKET - 4);
	assert_int_equal(dxl_encode_instruction(buf, sizeof buf, 1, DXL_INST_WRITE, data,
	                                        DXL_MAX_TX_PARAMS + 1), DXL_E_BUFFER);
	assert_int_equal(dxl_encode_write(buf, sizeof buf, 1, 0, data, DXL_MAX_TX_PARAMS), DXL_E_BUFFER);
	assert_int_equal(dxl_encode_status(buf, sizeof buf, 1, 0, data, DXL_MAX_TX_PARAMS + 1),
	                 DXL_E_BUFFER);
}

/* ax12.md: a SYNC_WRITE of 4 bytes per servo fits 48 servos, LEN = (L+1)N + 4. */
static void test_sync_write_limits(void **state)
{
	(void)state;
	uint8_t buf[DXL_MAX_PACKET];
	uint8_t ids[49];
	uint8_t data[49 * 4];
	for (int i = 0; i < 49; i++)
		ids[i] = (uint8_t)i;
	memset(data, 0x11, sizeof data);
	int n = dxl_encode_sync_write(buf, sizeof buf, 30, 4, ids, data, 48);
	assert_int_equal(n, 5 * 48 + 8);
	assert_int_equal(buf[3], 5 * 48 + 4);
	assert_int_equal(dxl_encode_sync_write(buf, sizeof buf, 30, 4, ids, data, 49), DXL_E_BUFFER);
	ids[3] = DXL_BROADCAST_ID;
	assert_int_equal(dxl_encode_sync_write(buf, sizeof buf, 30, 4, ids, data, 4), DXL_E_ARG);
	assert_int_equal(dxl_encode_sync_write(buf, sizeof buf, 30, 0, ids, data, 2), DXL_E_ARG);
}

/* BULK_READ (MX manual): FF FF FE 09 92 00 02 01 1E 02 02 24 chk */
static void test_bulk_read(void **state)
{
	(void)state;
	const struct dxl_bulk_item items[2] = { { 1, 30, 2 }, { 2, 36, 2 } };
	const uint8_t want[] = { 0xFF, 0xFF, 0xFE, 0x09, 0x92, 0x00, 0x02, 0x01, 0x1E, 0x02, 0x02,
	                         0x24, 0x1D };
	uint8_t buf[32];
	int n = dxl_encode_bulk_read(buf, sizeof buf, items, 2);
	assert_int_equal(n, sizeof want);
	assert_memory_equal(buf, want, sizeof want);
}

static void test_names(void **state)
{
	(void)state;
	char buf[128];
	assert_string_equal(dxl_instruction_name(DXL_INST_SYNC_WRITE), "SYNC_WRITE");
	assert_string_equal(dxl_instruction_name(0x77), "UNKNOWN");
	assert_string_equal(dxl_errbit_name(DXL_ERRBIT_OVERLOAD), "overload");
	assert_null(dxl_errbit_name(0x03));
	assert_string_equal(dxl_errbits_format(0, buf, sizeof buf), "none");
	assert_string_equal(dxl_errbits_format(0x24, buf, sizeof buf), "overheating|overload");
	assert_string_equal(dxl_errbits_format(0x81, buf, sizeof buf), "input voltage|bit7");
	/* truncation keeps the string terminated */
	dxl_errbits_format(0x7F, buf, 10);
	assert_true(strlen(buf) < 10);
	for (int s = DXL_OK; s >= DXL_E_UNSUPPORTED; s--) {
		assert_non_null(dxl_strerror(s));
		assert_string_not_equal(dxl_strerror(s), "unknown error");
	}
	assert_string_equal(dxl_strerror(-999), "unknown error");
	assert_string_equal(dxl_strerror(DXL_E_TIMEOUT), "no reply (timeout)");
}

static void test_u16(void **state)
{
	(void)state;
	uint8_t b[2];
	dxl_put_u16(b, 0x1234);
	assert_int_equal(b[0], 0x34);
	assert_int_equal(b[1], 0x12);
	assert_int_equal(dxl_get_u16(b), 0x1234);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_golden_encode),
		cmocka_unit_test(test_golden_encode_generic),
		cmocka_unit_test(test_golden_decode),
		cmocka_unit_test(test_golden_checksum),
		cmocka_unit_test(test_encode_args),
		cmocka_unit_test(test_sync_write_limits),
		cmocka_unit_test(test_bulk_read),
		cmocka_unit_test(test_names),
		cmocka_unit_test(test_u16),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
