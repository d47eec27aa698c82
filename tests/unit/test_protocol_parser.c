/*
 * test_protocol_parser.c — the resumable byte-fed parser: split points,
 * garbage, resynchronisation on every bad header field, random streams.
 * Packets are literal bytes (checksums computed by hand); the random runs use
 * the encoder only to build streams whose decoding is then compared field by
 * field with what was generated.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "dxl.h"

/* READ(36, 6) reply from ID 1: position 512, speed 0, load 0. */
static const uint8_t reply6[] = { 0xFF, 0xFF, 0x01, 0x08, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
                                  0x00, 0xF4 };
/* PING reply from ID 1. */
static const uint8_t ping_reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
/* READ reply, 32 °C, from ID 1. */
static const uint8_t temp_reply[] = { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB };

/* Frames collected by feed_all. */
#define MAX_FRAMES 64

struct feed_result {
	size_t nframes;
	struct dxl_packet frames[MAX_FRAMES];
	size_t checksum_errors, header_errors;
};

/* Feed n bytes the way a caller does: again after every frame or error,
 * until the parser says it needs more. */
static void feed_all(struct dxl_parser *p, const uint8_t *d, size_t n, struct feed_result *res)
{
	size_t off = 0;
	for (;;) {
		size_t used = 0;
		struct dxl_packet pkt;
		int r = dxl_parser_feed(p, d + off, n - off, &used, &pkt);
		assert_true(used <= n - off);
		off += used;
		if (r == DXL_FRAME) {
			assert_true(res->nframes < MAX_FRAMES);
			res->frames[res->nframes++] = pkt;
		} else if (r == DXL_E_CHECKSUM) {
			res->checksum_errors++;
		} else if (r == DXL_E_HEADER) {
			res->header_errors++;
		} else {
			assert_int_equal(r, DXL_NEED_MORE);
			assert_int_equal(off, n);
			return;
		}
	}
}

static void assert_reply6(const struct dxl_packet *pkt)
{
	assert_int_equal(pkt->id, 1);
	assert_int_equal(pkt->code, 0);
	assert_int_equal(pkt->nparams, 6);
	assert_int_equal(dxl_get_u16(pkt->params), 512);
	assert_int_equal(dxl_get_u16(pkt->params + 2), 0);
	assert_int_equal(dxl_get_u16(pkt->params + 4), 0);
}

/* Two pieces at every offset: one frame, and only after its last byte. */
static void test_split_points(void **state)
{
	(void)state;
	const size_t n = sizeof reply6;
	for (size_t k = 0; k <= n; k++) {
		struct dxl_parser p;
		struct dxl_packet pkt;
		size_t used = 99;
		dxl_parser_init(&p, DXL_PARSE_STATUS);
		int r = dxl_parser_feed(&p, reply6, k, &used, &pkt);
		if (k < n) {
			assert_int_equal(r, DXL_NEED_MORE);
			assert_int_equal(used, k);
			r = dxl_parser_feed(&p, reply6 + k, n - k, &used, &pkt);
			assert_int_equal(used, n - k);
		} else {
			assert_int_equal(used, n);
		}
		assert_int_equal(r, DXL_FRAME);
		assert_reply6(&pkt);
		assert_int_equal(p.frames, 1);
		assert_int_equal(p.bytes_dropped, 0);
		assert_int_equal(p.have, 0);
	}
}

static void test_byte_by_byte(void **state)
{
	(void)state;
	struct dxl_parser p;
	struct dxl_packet pkt;
	dxl_parser_init(&p, DXL_PARSE_STATUS);
	for (int round = 0; round < 3; round++) {
		for (size_t i = 0; i < sizeof reply6; i++) {
			size_t used = 0;
			int r = dxl_parser_feed(&p, reply6 + i, 1, &used, &pkt);
			assert_int_equal(used, 1);
			assert_int_equal(r, i + 1 == sizeof reply6 ? DXL_FRAME : DXL_NEED_MORE);
		}
		assert_reply6(&pkt);
	}
	assert_int_equal(p.frames, 3);
}

/* Leading garbage (gpsd-style rows with the garbage length as offset). */
static void test_leading_garbage(void **state)
{
	(void)state;
	static const struct {
		const char *legend;
		uint8_t garbage[8];
		size_t n;
		uint32_t header_errors;
	} rows[] = {
		{ "one zero byte", { 0x00 }, 1, 0 },
		{ "a lone FF", { 0xFF }, 1, 1 },             /* FF FF FF: ID 0xFF rejected */
		{ "FF FF", { 0xFF, 0xFF }, 2, 2 },
		{ "FF then noise", { 0xFF, 0x00, 0x12 }, 3, 0 },
		{ "noise with FF", { 0x12, 0x34, 0xFF, 0x00, 0xFF }, 5, 1 },
		{ "almost a header", { 0xFF, 0xFF, 0x01 }, 3, 1 }, /* LEN 0xFF rejected */
		{ "seven bytes", { 1, 2, 3, 4, 5, 6, 7 }, 7, 0 },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		uint8_t stream[32];
		struct dxl_parser p;
		struct feed_result res = { 0 };
		print_message("# %s (offset %zu)\n", rows[i].legend, rows[i].n);
		memcpy(stream, rows[i].garbage, rows[i].n);
		memcpy(stream + rows[i].n, reply6, sizeof reply6);
		dxl_parser_init(&p, DXL_PARSE_STATUS);
		feed_all(&p, stream, rows[i].n + sizeof reply6, &res);
		assert_int_equal(res.nframes, 1);
		assert_reply6(&res.frames[0]);
		assert_int_equal(p.bytes_dropped, rows[i].n);
		assert_int_equal(p.header_errors, rows[i].header_errors);
		assert_int_equal(p.checksum_errors, 0);
	}
}

static void test_two_packets_one_read(void **state)
{
	(void)state;
	uint8_t stream[32];
	memcpy(stream, ping_reply, sizeof ping_reply);
	memcpy(stream + sizeof ping_reply, temp_reply, sizeof temp_reply);
	struct dxl_parser p;
	struct dxl_packet pkt;
	size_t used;
	dxl_parser_init(&p, DXL_PARSE_STATUS);
	int r = dxl_parser_feed(&p, stream, sizeof ping_reply + sizeof temp_reply, &used, &pkt);
	assert_int_equal(r, DXL_FRAME);
	assert_int_equal(used, sizeof ping_reply);
	assert_int_equal(pkt.nparams, 0);
	r = dxl_parser_feed(&p, stream + used, sizeof temp_reply, &used, &pkt);
	assert_int_equal(r, DXL_FRAME);
	assert_int_equal(used, sizeof temp_reply);
	assert_int_equal(pkt.nparams, 1);
	assert_int_equal(pkt.params[0], 32);
	assert_int_equal(p.frames, 2);
}

static void test_bad_checksum_then_good(void **state)
{
	(void)state;
	uint8_t stream[32];
	memcpy(stream, temp_reply, sizeof temp_reply);
	stream[sizeof temp_reply - 1] ^= 0x01;
	memcpy(stream + sizeof temp_reply, reply6, sizeof reply6);
	struct dxl_parser p;
	struct feed_result res = { 0 };
	dxl_parser_init(&p, DXL_PARSE_STATUS);
	feed_all(&p, stream, sizeof temp_reply + sizeof reply6, &res);
	assert_int_equal(res.checksum_errors, 1);
	assert_int_equal(p.checksum_errors, 1);
	assert_int_equal(res.nframes, 1);
	assert_reply6(&res.frames[0]);
	assert_int_equal(p.bytes_dropped, sizeof temp_reply);
}

/* A damaged packet whose parameters hold a whole good one: after the
 * checksum error the parser rescans what it buffered and finds it. */
static void test_rescan_buffered(void **state)
{
	(void)state;
	const uint8_t stream[] = { 0xFF, 0xFF, 0x01, 0x0A, 0x00,
	                           0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC, 0x00, 0x00,
	                           0x55 /* wrong checksum */ };
	struct dxl_parser p;
	struct feed_result res = { 0 };
	dxl_parser_init(&p, DXL_PARSE_STATUS);
	feed_all(&p, stream, sizeof stream, &res);
	assert_int_equal(res.checksum_errors, 1);
	assert_int_equal(res.nframes, 1);
	assert_int_equal(res.frames[0].id, 1);
	assert_int_equal(res.frames[0].nparams, 0);
}

/* Each bad header field resyncs; the good packet after it still parses. */
static void test_bad_header_fields(void **state)
{
	(void)state;
	static const struct {
		const char *legend;
		uint8_t bytes[8];
		size_t n;
	} rows[] = {
		{ "status ID 0xFF", { 0xFF, 0xFF, 0xFF, 0x02, 0x00, 0x00 }, 6 },
		{ "status ID 0xFE", { 0xFF, 0xFF, 0xFE, 0x02, 0x00, 0xFF }, 6 },
		{ "LEN 0", { 0xFF, 0xFF, 0x01, 0x00, 0x00, 0xFE }, 6 },
		{ "LEN 1", { 0xFF, 0xFF, 0x01, 0x01, 0x00, 0xFD }, 6 },
		{ "LEN 251", { 0xFF, 0xFF, 0x01, 0xFB, 0x00, 0x03 }, 6 },
		{ "LEN 255", { 0xFF, 0xFF, 0x01, 0xFF, 0x00, 0x00 }, 6 },
		{ "error byte 0x80", { 0xFF, 0xFF, 0x01, 0x02, 0x80, 0x7C }, 6 },
		{ "error byte 0xFF", { 0xFF, 0xFF, 0x01, 0x02, 0xFF, 0xFD }, 6 },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		uint8_t stream[32];
		struct dxl_parser p;
		struct feed_result res = { 0 };
		print_message("# %s\n", rows[i].legend);
		memcpy(stream, rows[i].bytes, rows[i].n);
		memcpy(stream + rows[i].n, reply6, sizeof reply6);
		dxl_parser_init(&p, DXL_PARSE_STATUS);
		feed_all(&p, stream, rows[i].n + sizeof reply6, &res);
		assert_true(res.header_errors >= 1);
		assert_int_equal(res.header_errors, p.header_errors);
		assert_int_equal(res.nframes, 1);
		assert_reply6(&res.frames[0]);
		assert_int_equal(p.bytes_dropped, rows[i].n);
	}
}

/* The simulator's side: broadcast ID and codes above 0x7F are instructions. */
static void test_instruction_side(void **state)
{
	(void)state;
	const uint8_t action_bc[] = { 0xFF, 0xFF, 0xFE, 0x02, 0x05, 0xFA };
	const uint8_t sync[] = { 0xFF, 0xFF, 0xFE, 0x0E, 0x83, 0x1E, 0x04, 0x00, 0x10, 0x00, 0x50,
	                         0x01, 0x01, 0x20, 0x02, 0x60, 0x03, 0x67 };
	struct dxl_parser p;
	struct feed_result res = { 0 };
	dxl_parser_init(&p, DXL_PARSE_INSTRUCTION);
	feed_all(&p, action_bc, sizeof action_bc, &res);
	feed_all(&p, sync, sizeof sync, &res);
	assert_int_equal(res.nframes, 2);
	assert_int_equal(res.frames[0].id, DXL_BROADCAST_ID);
	assert_int_equal(res.frames[0].code, DXL_INST_ACTION);
	assert_int_equal(res.frames[1].code, DXL_INST_SYNC_WRITE);
	assert_int_equal(res.frames[1].nparams, 12);
	assert_int_equal(p.header_errors, 0);

	/* the same bytes are not status packets */
	struct dxl_parser s;
	struct feed_result sres = { 0 };
	dxl_parser_init(&s, DXL_PARSE_STATUS);
	feed_all(&s, action_bc, sizeof action_bc, &sres);
	feed_all(&s, sync, sizeof sync, &sres);
	assert_int_equal(sres.nframes, 0);
	assert_true(s.header_errors >= 2);

	/* ID 0xFF is invalid for instructions too */
	const uint8_t bad_id[] = { 0xFF, 0xFF, 0xFF, 0x02, 0x01, 0xFD };
	struct feed_result bres = { 0 };
	dxl_parser_init(&p, DXL_PARSE_INSTRUCTION);
	feed_all(&p, bad_id, sizeof bad_id, &bres);
	assert_int_equal(bres.nframes, 0);
	assert_true(p.header_errors >= 1);
}

static void test_reset_keeps_counters(void **state)
{
	(void)state;
	struct dxl_parser p;
	struct feed_result res = { 0 };
	dxl_parser_init(&p, DXL_PARSE_STATUS);
	feed_all(&p, reply6, sizeof reply6, &res);
	feed_all(&p, reply6, 5, &res);
	assert_int_equal(p.have, 5);
	dxl_parser_reset(&p);
	assert_int_equal(p.have, 0);
	assert_int_equal(p.frames, 1);
	/* the tail of the abandoned packet is garbage now, the next one parses */
	feed_all(&p, reply6 + 5, sizeof reply6 - 5, &res);
	feed_all(&p, reply6, sizeof reply6, &res);
	assert_int_equal(res.nframes, 2);
	assert_int_equal(p.frames, 2);
}

/* ---- random streams --------------------------------------------------------- */

/* xorshift64*: a seeded, portable generator so failures reproduce. */
static uint64_t rng_state;
static uint32_t rng(void)
{
	rng_state ^= rng_state >> 12;
	rng_state ^= rng_state << 25;
	rng_state ^= rng_state >> 27;
	return (uint32_t)((rng_state * 0x2545F4914F6CDD1DULL) >> 32);
}

/* Random bytes of which about one in `ff_one_in` is 0xFF (to reach headers). */
static void random_bytes(uint8_t *d, size_t n, unsigned ff_one_in)
{
	for (size_t i = 0; i < n; i++)
		d[i] = (ff_one_in && rng() % ff_one_in == 0) ? 0xFF : (uint8_t)rng();
}

/* Bytes fed = bytes of delivered frames + bytes dropped + bytes buffered. */
static void random_run(enum dxl_parse_kind kind, size_t total, unsigned ff_one_in)
{
	static uint8_t chunk[512];
	struct dxl_parser p;
	dxl_parser_init(&p, kind);
	uint64_t fed = 0, frame_bytes = 0, errors = 0;
	while (fed < total) {
		size_t n = 1 + rng() % sizeof chunk;
		random_bytes(chunk, n, ff_one_in);
		size_t off = 0;
		for (;;) {
			size_t used = 0;
			struct dxl_packet pkt;
			int r = dxl_parser_feed(&p, chunk + off, n - off, &used, &pkt);
			assert_true(used <= n - off);
			off += used;
			assert_true(p.have < DXL_MAX_PACKET);
			if (r == DXL_FRAME) {
				frame_bytes += (uint64_t)pkt.nparams + 6;
				assert_true(pkt.id <= DXL_BROADCAST_ID);
				if (kind == DXL_PARSE_STATUS) {
					assert_true(pkt.id <= DXL_MAX_ID);
					assert_true(pkt.code <= DXL_ERRBIT_MASK);
				}
			} else if (r < 0) {
				assert_true(r == DXL_E_CHECKSUM || r == DXL_E_HEADER);
				errors++;
			} else {
				break;
			}
		}
		fed += n;
	}
	assert_int_equal(fed, frame_bytes + p.bytes_dropped + p.have);
	assert_int_equal(errors, (uint64_t)p.checksum_errors + p.header_errors);
	print_message("# %s %llu bytes: %u frames, %u checksum, %u header errors, %u dropped\n",
	              kind == DXL_PARSE_STATUS ? "status" : "instruction",
	              (unsigned long long)fed, p.frames, p.checksum_errors, p.header_errors,
	              p.bytes_dropped);
}

static void test_random_bytes(void **state)
{
	(void)state;
	rng_state = 0x9E3779B97F4A7C15ULL;
	random_run(DXL_PARSE_STATUS, 2u << 20, 0);
	random_run(DXL_PARSE_INSTRUCTION, 2u << 20, 0);
	/* FF-rich: headers and checksums get exercised, frames appear by chance */
	random_run(DXL_PARSE_STATUS, 1u << 20, 3);
	random_run(DXL_PARSE_INSTRUCTION, 1u << 20, 3);
}

/* Garbage that cannot complete a header with what follows: no two FF in a
 * row and no trailing FF... except that a trailing FF is also recovered
 * (FF FF FF is rejected on the ID). Single FFs are allowed anywhere. */
static size_t garbage(uint8_t *d, size_t max)
{
	size_t n = rng() % (max + 1);
	for (size_t i = 0; i < n; i++) {
		d[i] = (uint8_t)rng();
		if (d[i] == 0xFF && i > 0 && d[i - 1] == 0xFF)
			d[i] = 0x00;
	}
	return n;
}

#define EMBED_PACKETS 3000
#define EMBED_MAX_PARAMS 40
#define EMBED_MAX_GARBAGE 12

struct expected {
	uint8_t id, code, nparams;
	uint8_t params[EMBED_MAX_PARAMS];
};

static void embedded_run(enum dxl_parse_kind kind)
{
	static uint8_t stream[EMBED_PACKETS * (EMBED_MAX_PARAMS + 6 + EMBED_MAX_GARBAGE) + 16];
	static struct expected want[EMBED_PACKETS];
	size_t n = 0;
	for (size_t i = 0; i < EMBED_PACKETS; i++) {
		struct expected *e = &want[i];
		e->id = (uint8_t)(rng() % (DXL_MAX_ID + 1));
		e->code = (uint8_t)(kind == DXL_PARSE_STATUS ? rng() % 0x80 : rng() % 256);
		e->nparams = (uint8_t)(rng() % (EMBED_MAX_PARAMS + 1));
		for (size_t k = 0; k < e->nparams; k++)
			e->params[k] = (uint8_t)rng();
		n += garbage(stream + n, EMBED_MAX_GARBAGE);
		int w = kind == DXL_PARSE_STATUS
		      ? dxl_encode_status(stream + n, sizeof stream - n, e->id, e->code, e->params, e->nparams)
		      : dxl_encode_instruction(stream + n, sizeof stream - n, e->id, e->code, e->params,
		                               e->nparams);
		assert_true(w > 0);
		n += (size_t)w;
	}
	struct dxl_parser p;
	dxl_parser_init(&p, kind);
	size_t got = 0, off = 0;
	while (off < n) {
		size_t len = 1 + rng() % 300;
		if (len > n - off)
			len = n - off;
		size_t coff = 0;
		for (;;) {
			size_t used = 0;
			struct dxl_packet pkt;
			int r = dxl_parser_feed(&p, stream + off + coff, len - coff, &used, &pkt);
			coff += used;
			if (r == DXL_FRAME) {
				assert_true(got < EMBED_PACKETS);
				const struct expected *e = &want[got++];
				assert_int_equal(pkt.id, e->id);
				assert_int_equal(pkt.code, e->code);
				assert_int_equal(pkt.nparams, e->nparams);
				if (e->nparams)
					assert_memory_equal(pkt.params, e->params, e->nparams);
			} else if (r == DXL_NEED_MORE) {
				break;
			}
		}
		off += len;
	}
	assert_int_equal(got, EMBED_PACKETS);
	assert_int_equal(p.frames, EMBED_PACKETS);
}

static void test_embedded_packets(void **state)
{
	(void)state;
	rng_state = 0xD1B54A32D192ED03ULL;
	embedded_run(DXL_PARSE_STATUS);
	embedded_run(DXL_PARSE_INSTRUCTION);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_split_points),
		cmocka_unit_test(test_byte_by_byte),
		cmocka_unit_test(test_leading_garbage),
		cmocka_unit_test(test_two_packets_one_read),
		cmocka_unit_test(test_bad_checksum_then_good),
		cmocka_unit_test(test_rescan_buffered),
		cmocka_unit_test(test_bad_header_fields),
		cmocka_unit_test(test_instruction_side),
		cmocka_unit_test(test_reset_keeps_counters),
		cmocka_unit_test(test_random_bytes),
		cmocka_unit_test(test_embedded_packets),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
