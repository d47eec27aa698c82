/*
 * test_protocol_parser2.c — the Protocol 2.0 parser: stuffed bytes split at
 * every read boundary, garbage, a header inside stuffed data, bad CRC, wrong
 * length, a reply cut short, the alert bit, replies matched to requests and
 * SYNC_READ with a servo missing, random streams. Packets are literal bytes
 * (the manual's, or derived by hand with a separate CRC: see
 * test_protocol_packet2.c); the random runs use the encoder only to build
 * streams whose decoding is compared field by field with what was generated.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "dxl2.h"

#define HDR 0xFF, 0xFF, 0xFD, 0x00
/* e-manual, Read example: ID 1 status, Present Position 166. */
static const uint8_t read_reply[] = { HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0 };
/* e-manual, Sync Read example: ID 2 status, Present Position 2079. */
static const uint8_t sync_reply2[] = { HDR, 0x02, 0x08, 0x00, 0x55, 0x00, 0x1F, 0x08, 0x00, 0x00, 0xBA, 0xBE };
/* derived: status FF FF FD FD (stuffed to FF FF FD FD FD). */
static const uint8_t stuffed_reply[] = { HDR, 0x01, 0x09, 0x00, 0x55, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0xFD,
                                         0xD5, 0x1E };
/* derived: alert + data range, no parameters. */
static const uint8_t alert_reply[] = { HDR, 0x01, 0x04, 0x00, 0x55, 0x84, 0xB9, 0x0F };

#define MAX_FRAMES 64
struct feed_result {
	size_t nframes;
	struct dxl2_packet frames[MAX_FRAMES];
	size_t checksum_errors, header_errors, stuffing_errors;
};

/* Feed as a caller does: again after every frame or error until NEED_MORE. */
static void feed_all(struct dxl2_parser *p, const uint8_t *d, size_t n, struct feed_result *res)
{
	size_t off = 0;
	for (;;) {
		size_t used = 0;
		static struct dxl2_packet pkt;
		int r = dxl2_parser_feed(p, d + off, n - off, &used, &pkt);
		assert_true(used <= n - off);
		off += used;
		if (r == DXL_FRAME) {
			assert_true(res->nframes < MAX_FRAMES);
			res->frames[res->nframes++] = pkt;
		} else if (r == DXL_E_CHECKSUM) {
			res->checksum_errors++;
		} else if (r == DXL_E_HEADER) {
			res->header_errors++;
		} else if (r == DXL_E_STUFFING) {
			res->stuffing_errors++;
		} else {
			assert_int_equal(r, DXL_NEED_MORE);
			assert_int_equal(off, n);
			return;
		}
	}
}

static void assert_read_reply(const struct dxl2_packet *pkt)
{
	assert_int_equal(pkt->id, 1);
	assert_int_equal(pkt->instr, DXL2_INST_STATUS);
	assert_int_equal(pkt->err, 0);
	assert_int_equal(pkt->nparams, 4);
	assert_int_equal(dxl2_get_u32(pkt->params), 166);
}

static void assert_stuffed_reply(const struct dxl2_packet *pkt)
{
	const uint8_t want[4] = { 0xFF, 0xFF, 0xFD, 0xFD };
	assert_int_equal(pkt->id, 1);
	assert_int_equal(pkt->nparams, 4);
	assert_memory_equal(pkt->params, want, 4);
	assert_int_equal(pkt->wire_bytes, sizeof stuffed_reply);
}

/* Every split into two reads, and every split into three: one frame, only
 * after its last byte, whatever falls between the pattern and its stuffed FD. */
static void test_split_points(void **state)
{
	(void)state;
	static struct dxl2_packet pkt;
	const size_t n = sizeof stuffed_reply;
	for (size_t a = 0; a <= n; a++) {
		for (size_t b = a; b <= n; b++) {
			struct dxl2_parser p;
			struct feed_result res = { 0 };
			dxl2_parser_init(&p, DXL2_PARSE_STATUS);
			feed_all(&p, stuffed_reply, a, &res);
			assert_int_equal(res.nframes, a == n);
			feed_all(&p, stuffed_reply + a, b - a, &res);
			assert_int_equal(res.nframes, b == n);
			feed_all(&p, stuffed_reply + b, n - b, &res);
			assert_int_equal(res.nframes, 1);
			assert_stuffed_reply(&res.frames[0]);
			assert_int_equal(p.bytes_dropped + p.header_errors + p.stuffing_errors, 0);
			assert_int_equal(p.have, 0);
		}
	}
	/* byte by byte, three times over */
	struct dxl2_parser p;
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	for (int round = 0; round < 3; round++) {
		for (size_t i = 0; i < n; i++) {
			size_t used = 0;
			int r = dxl2_parser_feed(&p, stuffed_reply + i, 1, &used, &pkt);
			assert_int_equal(used, 1);
			assert_int_equal(r, i + 1 == n ? DXL_FRAME : DXL_NEED_MORE);
		}
		assert_stuffed_reply(&pkt);
	}
	assert_int_equal(p.frames, 3);
}

static void test_leading_garbage(void **state)
{
	(void)state;
	static const struct {
		const char *legend;
		uint8_t garbage[12];
		size_t n;
		uint32_t header_errors;
	} rows[] = {
		{ "one zero byte", { 0x00 }, 1, 0 },
		{ "a lone FF", { 0xFF }, 1, 0 },
		{ "FF FF", { 0xFF, 0xFF }, 2, 0 },
		{ "FF FF FD: a header with no packet", { 0xFF, 0xFF, 0xFD }, 3, 1 },  /* reserved FF */
		{ "1.0 PING reply", { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC }, 6, 0 },
		{ "header inside stuffed data: FF FF FD FD", { 0xFF, 0xFF, 0xFD, 0xFD, 0x12 }, 5, 0 },
		{ "stuffed data twice", { 0xFF, 0xFF, 0xFD, 0xFD, 0xFF, 0xFF, 0xFD, 0xFD, 0xFD }, 9, 0 },
		{ "reserved byte 01", { 0xFF, 0xFF, 0xFD, 0x01 }, 4, 1 },
		{ "seven bytes", { 1, 2, 3, 4, 5, 6, 7 }, 7, 0 },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		uint8_t stream[64];
		struct dxl2_parser p;
		struct feed_result res = { 0 };
		print_message("# %s (offset %zu)\n", rows[i].legend, rows[i].n);
		memcpy(stream, rows[i].garbage, rows[i].n);
		memcpy(stream + rows[i].n, read_reply, sizeof read_reply);
		dxl2_parser_init(&p, DXL2_PARSE_STATUS);
		feed_all(&p, stream, rows[i].n + sizeof read_reply, &res);
		assert_int_equal(res.nframes, 1);
		assert_read_reply(&res.frames[0]);
		assert_int_equal(p.bytes_dropped, rows[i].n);
		assert_int_equal(p.header_errors, rows[i].header_errors);
		assert_int_equal(p.checksum_errors + p.stuffing_errors, 0);
	}
}

/* Garbage between two packets and two packets in one read. */
static void test_between_packets(void **state)
{
	(void)state;
	uint8_t stream[64];
	size_t n = 0;
	memcpy(stream + n, read_reply, sizeof read_reply);
	n += sizeof read_reply;
	const uint8_t junk[] = { 0xFF, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0x42 };
	memcpy(stream + n, junk, sizeof junk);
	n += sizeof junk;
	memcpy(stream + n, sync_reply2, sizeof sync_reply2);
	n += sizeof sync_reply2;
	memcpy(stream + n, stuffed_reply, sizeof stuffed_reply);
	n += sizeof stuffed_reply;
	struct dxl2_parser p;
	struct feed_result res = { 0 };
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	feed_all(&p, stream, n, &res);
	assert_int_equal(res.nframes, 3);
	assert_read_reply(&res.frames[0]);
	assert_int_equal(res.frames[1].id, 2);
	assert_int_equal(dxl2_get_u32(res.frames[1].params), 2079);
	assert_stuffed_reply(&res.frames[2]);
	assert_int_equal(p.bytes_dropped, sizeof junk);
	assert_int_equal(p.header_errors + p.checksum_errors + p.stuffing_errors, 0);
}

static void test_bad_crc_then_good(void **state)
{
	(void)state;
	for (size_t k = 7; k < sizeof read_reply; k++) {
		uint8_t stream[64];
		memcpy(stream, read_reply, sizeof read_reply);
		stream[k] ^= 0x10;  /* any byte after the length: a CRC mismatch */
		memcpy(stream + sizeof read_reply, sync_reply2, sizeof sync_reply2);
		struct dxl2_parser p;
		struct feed_result res = { 0 };
		dxl2_parser_init(&p, DXL2_PARSE_STATUS);
		feed_all(&p, stream, sizeof read_reply + sizeof sync_reply2, &res);
		print_message("# byte %zu flipped\n", k);
		assert_int_equal(res.nframes, 1);
		assert_int_equal(res.frames[0].id, 2);
		/* INST 0x55 flipped is no status: a header error, not a CRC error */
		assert_int_equal(res.checksum_errors + res.header_errors, 1);
		assert_int_equal(res.header_errors, k == 7);
		assert_int_equal(p.checksum_errors, k != 7);
		assert_int_equal(p.bytes_dropped, sizeof read_reply);
	}
}

/* A wrong LEN: too short for a status, beyond the limit, or simply wrong
 * (the CRC then fails) — the good packet after it is still found. */
static void test_wrong_length(void **state)
{
	(void)state;
	static const struct {
		const char *legend;
		uint8_t len_l, len_h;
		int why;
	} rows[] = {
		{ "LEN 0", 0x00, 0x00, DXL_E_HEADER },
		{ "LEN 3 (no room for ERR)", 0x03, 0x00, DXL_E_HEADER },
		{ "LEN 1018 (beyond 1024 bytes)", 0xFA, 0x03, DXL_E_HEADER },
		{ "LEN 0xFFFF", 0xFF, 0xFF, DXL_E_HEADER },
		{ "LEN 7 (one short)", 0x07, 0x00, DXL_E_CHECKSUM },
		{ "LEN 9 (one long)", 0x09, 0x00, DXL_E_CHECKSUM },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		uint8_t stream[64];
		memcpy(stream, read_reply, sizeof read_reply);
		stream[5] = rows[i].len_l;
		stream[6] = rows[i].len_h;
		memcpy(stream + sizeof read_reply, sync_reply2, sizeof sync_reply2);
		memcpy(stream + sizeof read_reply + sizeof sync_reply2, read_reply, sizeof read_reply);
		struct dxl2_parser p;
		struct feed_result res = { 0 };
		print_message("# %s\n", rows[i].legend);
		dxl2_parser_init(&p, DXL2_PARSE_STATUS);
		feed_all(&p, stream, 2 * sizeof read_reply + sizeof sync_reply2, &res);
		/* "one long" swallows the first byte of the next packet before its
		 * CRC fails; the rescan finds that packet all the same */
		assert_int_equal(res.nframes, 2);
		assert_int_equal(res.frames[0].id, 2);
		assert_read_reply(&res.frames[1]);
		if (rows[i].why == DXL_E_HEADER)
			assert_int_equal(res.header_errors, 1);
		else
			assert_int_equal(res.checksum_errors, 1);
	}
}

/* Every other bad header field. */
static void test_bad_header_fields(void **state)
{
	(void)state;
	static const struct {
		const char *legend;
		enum dxl2_parse_kind kind;
		uint8_t bytes[12];
		size_t n;
	} rows[] = {
		{ "status from broadcast", DXL2_PARSE_STATUS, { HDR, 0xFE, 0x04, 0x00, 0x55, 0x00, 0, 0 }, 11 },
		{ "status from ID 253", DXL2_PARSE_STATUS, { HDR, 0xFD, 0x04, 0x00, 0x55, 0x00, 0, 0 }, 11 },
		{ "status from ID 255", DXL2_PARSE_STATUS, { HDR, 0xFF, 0x04, 0x00, 0x55, 0x00, 0, 0 }, 11 },
		{ "an instruction on the status side", DXL2_PARSE_STATUS, { HDR, 0x01, 0x03, 0x00, 0x01, 0x19,
		  0x4E }, 10 },
		{ "a status on the instruction side", DXL2_PARSE_INSTRUCTION, { HDR, 0x01, 0x04, 0x00, 0x55, 0x00,
		  0xA1, 0x0C }, 11 },
		{ "instruction to ID 253", DXL2_PARSE_INSTRUCTION, { HDR, 0xFD, 0x03, 0x00, 0x01, 0, 0 }, 10 },
		{ "instruction LEN 2", DXL2_PARSE_INSTRUCTION, { HDR, 0x01, 0x02, 0x00, 0x01, 0 }, 9 },
	};
	/* e-manual, Ping example 1, as the good packet on the instruction side */
	static const uint8_t ping[] = { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		uint8_t stream[64];
		bool status = rows[i].kind == DXL2_PARSE_STATUS;
		const uint8_t *good = status ? read_reply : ping;
		size_t ngood = status ? sizeof read_reply : sizeof ping;
		struct dxl2_parser p;
		struct feed_result res = { 0 };
		print_message("# %s\n", rows[i].legend);
		memcpy(stream, rows[i].bytes, rows[i].n);
		memcpy(stream + rows[i].n, good, ngood);
		dxl2_parser_init(&p, rows[i].kind);
		feed_all(&p, stream, rows[i].n + ngood, &res);
		assert_int_equal(res.header_errors, 1);
		assert_int_equal(res.nframes, 1);
		assert_int_equal(res.frames[0].wire_bytes, ngood);
		assert_int_equal(p.bytes_dropped, rows[i].n);
	}
	/* broadcast instructions are fine */
	static const uint8_t ping_bc[] = { HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42 };
	struct dxl2_parser p;
	struct feed_result res = { 0 };
	dxl2_parser_init(&p, DXL2_PARSE_INSTRUCTION);
	feed_all(&p, ping_bc, sizeof ping_bc, &res);
	assert_int_equal(res.nframes, 1);
	assert_int_equal(res.frames[0].id, DXL2_BROADCAST_ID);
}

/* A reply cut short, then a good one: the second header inside the first
 * packet's body is a stuffing error the moment the byte after FF FF FD
 * arrives, and the good reply is delivered with its own last byte — not
 * after the cut packet's LEN worth of bytes. */
static void test_cut_short_then_good(void **state)
{
	(void)state;
	for (size_t cut = 8; cut < sizeof read_reply; cut++) {
		uint8_t stream[64];
		memcpy(stream, read_reply, cut);
		memcpy(stream + cut, sync_reply2, sizeof sync_reply2);
		size_t n = cut + sizeof sync_reply2;
		struct dxl2_parser p;
		struct feed_result res = { 0 };
		print_message("# cut after %zu bytes\n", cut);
		dxl2_parser_init(&p, DXL2_PARSE_STATUS);
		feed_all(&p, stream, n - 1, &res);
		assert_int_equal(res.nframes, 0);
		feed_all(&p, stream + n - 1, 1, &res);
		assert_int_equal(res.nframes, 1);
		assert_int_equal(res.frames[0].id, 2);
		assert_int_equal(dxl2_get_u32(res.frames[0].params), 2079);
		assert_int_equal(p.have, 0);
		assert_int_equal(p.bytes_dropped, cut);
		/* a cut inside the body is a stuffing error; a cut that leaves the
		 * new header over the CRC bytes is a CRC error */
		assert_int_equal(res.stuffing_errors + res.checksum_errors, 1);
	}
	/* A long reply cut short, then a short good one: waiting for the long
	 * one's LEN would hold the good one until bytes that never come; the
	 * header inside the body is caught at once. (The long packet is built
	 * by the encoder: only its first 20 bytes are used, its CRC never.) */
	uint8_t stream[128], params[40];
	memset(params, 0x11, sizeof params);
	assert_int_equal(dxl2_encode_status(stream, sizeof stream, 3, 0, params, sizeof params), 51);
	memcpy(stream + 20, read_reply, sizeof read_reply);
	{
		struct dxl2_parser q;
		struct feed_result qres = { 0 };
		dxl2_parser_init(&q, DXL2_PARSE_STATUS);
		feed_all(&q, stream, 20 + sizeof read_reply, &qres);
		assert_int_equal(qres.stuffing_errors, 1);
		assert_int_equal(qres.nframes, 1);
		assert_read_reply(&qres.frames[0]);
		assert_int_equal(q.have, 0);
	}
	/* a body that ends in an unstuffed FF FF FD: wrong stuffing */
	const uint8_t unstuffed[] = { HDR, 0x01, 0x07, 0x00, 0x55, 0x00, 0xFF, 0xFF, 0xFD, 0x00, 0x00 };
	struct dxl2_parser p;
	struct feed_result res = { 0 };
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	feed_all(&p, unstuffed, sizeof unstuffed, &res);
	assert_int_equal(res.stuffing_errors, 1);
	assert_int_equal(p.stuffing_errors, 1);
	assert_int_equal(res.nframes, 0);
}

static void test_alert_bit(void **state)
{
	(void)state;
	struct dxl2_parser p;
	struct feed_result res = { 0 };
	char text[32];
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	feed_all(&p, alert_reply, sizeof alert_reply, &res);
	assert_int_equal(res.nframes, 1);
	assert_int_equal(res.frames[0].err, 0x84);
	assert_true(dxl2_err_alert(res.frames[0].err));
	assert_int_equal(dxl2_err_number(res.frames[0].err), DXL2_ERRNUM_DATA_RANGE);
	assert_string_equal(dxl2_err_format(res.frames[0].err, text, sizeof text), "alert|data range");
	/* the servo's error is data: the reply still matches its request */
	assert_int_equal(dxl2_check_reply(&res.frames[0], 1, 0), DXL_OK);
}

/* Replies checked against the request, as on 1.0. */
static void test_check_reply(void **state)
{
	(void)state;
	struct dxl2_parser p;
	struct feed_result res = { 0 };
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	feed_all(&p, read_reply, sizeof read_reply, &res);
	assert_int_equal(res.nframes, 1);
	assert_int_equal(dxl2_check_reply(&res.frames[0], 1, 4), DXL_OK);
	assert_int_equal(dxl2_check_reply(&res.frames[0], 2, 4), DXL_E_WRONG_ID);
	assert_int_equal(dxl2_check_reply(&res.frames[0], 1, 2), DXL_E_WRONG_LENGTH);
	assert_int_equal(dxl2_check_reply(NULL, 1, 2), DXL_E_ARG);
}

/* SYNC_READ of IDs 1, 2, 3 (Present Position, 4 bytes): 2 and 1 answer, 3
 * never does; a stray ID 9 and a second reply from 2 are refused. */
static void test_sync_read_missing(void **state)
{
	(void)state;
	const uint8_t ids[3] = { 1, 2, 3 };
	struct dxl2_multi_read m;
	uint8_t missing[4];
	assert_int_equal(dxl2_multi_read_sync(&m, 4, ids, 3), DXL_OK);
	assert_int_equal(dxl2_multi_read_missing(&m, missing, sizeof missing), 3);
	struct dxl2_parser p;
	struct feed_result res = { 0 };
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	feed_all(&p, sync_reply2, sizeof sync_reply2, &res);
	feed_all(&p, read_reply, sizeof read_reply, &res);
	feed_all(&p, sync_reply2, sizeof sync_reply2, &res);
	assert_int_equal(res.nframes, 3);
	size_t slot = 99;
	assert_int_equal(dxl2_multi_read_accept(&m, &res.frames[0], &slot), DXL_OK);
	assert_int_equal(slot, 1);
	assert_int_equal(m.out_of_order, 1);
	assert_int_equal(m.next, 0);
	assert_int_equal(dxl2_multi_read_accept(&m, &res.frames[1], &slot), DXL_OK);
	assert_int_equal(slot, 0);
	assert_int_equal(m.next, 2);
	assert_int_equal(dxl2_multi_read_accept(&m, &res.frames[2], &slot), DXL_E_WRONG_ID);
	struct dxl2_packet stray = res.frames[0];
	stray.id = 9;
	assert_int_equal(dxl2_multi_read_accept(&m, &stray, &slot), DXL_E_WRONG_ID);
	assert_false(dxl2_multi_read_done(&m));
	assert_int_equal(dxl2_multi_read_missing(&m, missing, sizeof missing), 1);
	assert_int_equal(missing[0], 3);
	/* a reply of the wrong size leaves the slot open */
	struct dxl2_packet short3 = res.frames[0];
	short3.id = 3;
	short3.nparams = 2;
	assert_int_equal(dxl2_multi_read_accept(&m, &short3, &slot), DXL_E_WRONG_LENGTH);
	assert_int_equal(dxl2_multi_read_missing(&m, NULL, 0), 1);
	short3.nparams = 4;
	assert_int_equal(dxl2_multi_read_accept(&m, &short3, &slot), DXL_OK);
	assert_true(dxl2_multi_read_done(&m));
	assert_int_equal(m.next, 3);

	/* BULK_READ: each its own length (e-manual example: 2 bytes, 1 byte) */
	const struct dxl2_bulk_item items[2] = { { 1, 144, 2, NULL }, { 2, 146, 1, NULL } };
	assert_int_equal(dxl2_multi_read_bulk(&m, items, 2), DXL_OK);
	struct dxl2_packet volt = { .id = 1, .instr = 0x55, .nparams = 2 };
	struct dxl2_packet temp = { .id = 2, .instr = 0x55, .nparams = 2 };
	assert_int_equal(dxl2_multi_read_accept(&m, &volt, &slot), DXL_OK);
	assert_int_equal(dxl2_multi_read_accept(&m, &temp, &slot), DXL_E_WRONG_LENGTH);
	temp.nparams = 1;
	assert_int_equal(dxl2_multi_read_accept(&m, &temp, &slot), DXL_OK);
	assert_int_equal(m.out_of_order, 0);
	/* bad lists */
	const uint8_t dup[2] = { 4, 4 };
	assert_int_equal(dxl2_multi_read_sync(&m, 4, dup, 2), DXL_E_ARG);
	assert_int_equal(dxl2_multi_read_sync(&m, 0, ids, 3), DXL_E_ARG);
}

static void test_reset_keeps_counters(void **state)
{
	(void)state;
	struct dxl2_parser p;
	struct feed_result res = { 0 };
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	feed_all(&p, read_reply, sizeof read_reply, &res);
	feed_all(&p, stuffed_reply, 12, &res);   /* up to the stuffed FD's pattern */
	assert_int_equal(p.have, 12);
	dxl2_parser_reset(&p);
	assert_int_equal(p.have, 0);
	assert_int_equal(p.frames, 1);
	feed_all(&p, stuffed_reply + 12, sizeof stuffed_reply - 12, &res);
	feed_all(&p, stuffed_reply, sizeof stuffed_reply, &res);
	assert_int_equal(res.nframes, 2);
	assert_stuffed_reply(&res.frames[1]);
}

/* ---- random streams --------------------------------------------------------- */
static uint64_t rng_state;
static uint32_t rng(void)
{
	rng_state ^= rng_state >> 12;
	rng_state ^= rng_state << 25;
	rng_state ^= rng_state >> 27;
	return (uint32_t)((rng_state * 0x2545F4914F6CDD1DULL) >> 32);
}

/* Bytes drawn mostly from FF, FD, 00, 55 so headers, stuffing and CRCs are
 * all reached; the counter invariant must hold throughout. */
static void random_run(enum dxl2_parse_kind kind, size_t total, bool rich)
{
	static uint8_t chunk[2048];
	static const uint8_t alphabet[] = { 0xFF, 0xFF, 0xFD, 0x00, 0x55, 0x01, 0x04 };
	struct dxl2_parser p;
	dxl2_parser_init(&p, kind);
	uint64_t fed = 0, frame_bytes = 0, errors = 0;
	while (fed < total) {
		size_t n = 1 + rng() % sizeof chunk;
		for (size_t i = 0; i < n; i++)
			chunk[i] = rich ? alphabet[rng() % sizeof alphabet] : (uint8_t)rng();
		size_t off = 0;
		for (;;) {
			size_t used = 0;
			static struct dxl2_packet pkt;
			int r = dxl2_parser_feed(&p, chunk + off, n - off, &used, &pkt);
			off += used;
			assert_true(p.have < DXL2_MAX_PACKET);
			if (r == DXL_FRAME) {
				frame_bytes += pkt.wire_bytes;
				assert_true(pkt.id <= DXL2_MAX_ID || (kind == DXL2_PARSE_INSTRUCTION &&
				                                      pkt.id == DXL2_BROADCAST_ID));
			} else if (r < 0) {
				errors++;
			} else {
				break;
			}
		}
		fed += n;
	}
	assert_int_equal(fed, frame_bytes + p.bytes_dropped + p.have);
	assert_int_equal(errors, (uint64_t)p.checksum_errors + p.header_errors + p.stuffing_errors);
	print_message("# %s %s %llu bytes: %u frames, %u crc, %u header, %u stuffing errors, %u dropped\n",
	              kind == DXL2_PARSE_STATUS ? "status" : "instruction", rich ? "FF-rich" : "uniform",
	              (unsigned long long)fed, p.frames, p.checksum_errors, p.header_errors,
	              p.stuffing_errors, p.bytes_dropped);
}

static void test_random_bytes(void **state)
{
	(void)state;
	rng_state = 0x9E3779B97F4A7C15ULL;
	random_run(DXL2_PARSE_STATUS, 2u << 20, false);
	random_run(DXL2_PARSE_INSTRUCTION, 2u << 20, false);
	random_run(DXL2_PARSE_STATUS, 1u << 20, true);
	random_run(DXL2_PARSE_INSTRUCTION, 1u << 20, true);
}

/* Garbage that cannot complete FF FF FD: no FF FF in it, and none at its end. */
static size_t garbage(uint8_t *d, size_t max)
{
	size_t n = rng() % (max + 1);
	for (size_t i = 0; i < n; i++) {
		d[i] = (uint8_t)rng();
		if (d[i] == 0xFF && i > 0 && d[i - 1] == 0xFF)
			d[i] = 0x00;
	}
	if (n > 0 && d[n - 1] == 0xFF)
		d[n - 1] = 0x00;
	return n;
}

#define EMBED_PACKETS 3000
#define EMBED_MAX_PARAMS 40
#define EMBED_MAX_GARBAGE 12
struct expected {
	uint8_t id, instr, err;
	uint16_t nparams;
	uint8_t params[EMBED_MAX_PARAMS];
};

/* Random packets whose parameters are full of FF FF FD, between garbage,
 * read in random chunks: every one recovered, in order, unstuffed. */
static void embedded_run(enum dxl2_parse_kind kind)
{
	static uint8_t stream[EMBED_PACKETS * (2 * EMBED_MAX_PARAMS + 12 + EMBED_MAX_GARBAGE)];
	static struct expected want[EMBED_PACKETS];
	size_t n = 0;
	for (size_t i = 0; i < EMBED_PACKETS; i++) {
		struct expected *e = &want[i];
		e->id = (uint8_t)(rng() % (DXL2_MAX_ID + 1));
		e->instr = kind == DXL2_PARSE_STATUS ? DXL2_INST_STATUS : (uint8_t)(rng() % 0x55);
		e->err = kind == DXL2_PARSE_STATUS ? (uint8_t)rng() : 0;
		e->nparams = (uint16_t)(rng() % (EMBED_MAX_PARAMS + 1));
		for (size_t k = 0; k < e->nparams; k++)
			e->params[k] = (uint8_t[]){ 0xFF, 0xFF, 0xFD, (uint8_t)rng() }[rng() % 4];
		n += garbage(stream + n, EMBED_MAX_GARBAGE);
		int w = kind == DXL2_PARSE_STATUS
		      ? dxl2_encode_status(stream + n, sizeof stream - n, e->id, e->err, e->params, e->nparams)
		      : dxl2_encode_instruction(stream + n, sizeof stream - n, e->id, e->instr, e->params,
		                                e->nparams);
		assert_true(w > 0);
		n += (size_t)w;
	}
	struct dxl2_parser p;
	dxl2_parser_init(&p, kind);
	size_t got = 0, off = 0;
	while (off < n) {
		size_t len = 1 + rng() % 300;
		if (len > n - off)
			len = n - off;
		size_t coff = 0;
		for (;;) {
			size_t used = 0;
			static struct dxl2_packet pkt;
			int r = dxl2_parser_feed(&p, stream + off + coff, len - coff, &used, &pkt);
			coff += used;
			if (r == DXL_FRAME) {
				assert_true(got < EMBED_PACKETS);
				const struct expected *e = &want[got++];
				assert_int_equal(pkt.id, e->id);
				assert_int_equal(pkt.instr, e->instr);
				assert_int_equal(pkt.err, e->err);
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
	assert_int_equal(p.checksum_errors + p.stuffing_errors, 0);
}

static void test_embedded_packets(void **state)
{
	(void)state;
	rng_state = 0xD1B54A32D192ED03ULL;
	embedded_run(DXL2_PARSE_STATUS);
	embedded_run(DXL2_PARSE_INSTRUCTION);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_split_points),
		cmocka_unit_test(test_leading_garbage),
		cmocka_unit_test(test_between_packets),
		cmocka_unit_test(test_bad_crc_then_good),
		cmocka_unit_test(test_wrong_length),
		cmocka_unit_test(test_bad_header_fields),
		cmocka_unit_test(test_cut_short_then_good),
		cmocka_unit_test(test_alert_bit),
		cmocka_unit_test(test_check_reply),
		cmocka_unit_test(test_sync_read_missing),
		cmocka_unit_test(test_reset_keeps_counters),
		cmocka_unit_test(test_random_bytes),
		cmocka_unit_test(test_embedded_packets),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
