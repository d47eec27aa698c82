/*
 * test_protocol_parser.c — the resumable byte-fed parsers of both protocols,
 * driven through their tables (struct dxl_proto): split points, garbage,
 * resynchronisation on bad header fields, broadcast on the instruction side,
 * reset, random streams. Each shared test runs once per backend, with that
 * protocol's golden vectors (struct backend_case); what only one protocol has
 * stays in its own section: 1.0's rescan of a damaged packet, 2.0's stuffing,
 * LEN field, alert bit, reply matching and SYNC_READ tracker.
 *
 * Packets are literal bytes (1.0: checksums computed by hand; 2.0: the
 * e-manual's, or derived by hand with a separate CRC: see
 * test_protocol_packet.c); the random runs use the encoder only to build
 * streams whose decoding is then compared field by field with what was
 * generated.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "dxl_proto.h"

/* ---- golden vectors --------------------------------------------------------- */

/* A packet as typed in, and the frame it must decode to. */
struct golden {
	const char *legend;
	const uint8_t *bytes;
	size_t n;
	uint8_t id, instr, err;   /* as struct dxl_frame has them */
	uint16_t nparams;
	const uint8_t *params;
};
#define BYTES(...) (const uint8_t[]){ __VA_ARGS__ }, sizeof (const uint8_t[]){ __VA_ARGS__ }

/* Protocol 1.0 */
static const struct golden v1_reply6 = {
	"1.0 READ(36, 6) reply from ID 1: position 512, speed 0, load 0",
	BYTES(0xFF, 0xFF, 0x01, 0x08, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x00, 0xF4),
	1, 0, 0, 6, (const uint8_t[]){ 0x00, 0x02, 0x00, 0x00, 0x00, 0x00 },
};
static const struct golden v1_ping_reply = {
	"1.0 PING reply from ID 1", BYTES(0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC), 1, 0, 0, 0, NULL,
};
static const struct golden v1_temp_reply = {
	"1.0 READ reply, 32 °C, from ID 1", BYTES(0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB),
	1, 0, 0, 1, (const uint8_t[]){ 32 },
};
static const struct golden v1_action_bc = {
	"1.0 broadcast ACTION", BYTES(0xFF, 0xFF, 0xFE, 0x02, 0x05, 0xFA),
	DXL_BROADCAST_ID, DXL_INST_ACTION, 0, 0, NULL,
};
static const struct golden v1_sync_write = {
	"1.0 SYNC_WRITE (goal, 2 bytes) to IDs 0, 1, 2",
	BYTES(0xFF, 0xFF, 0xFE, 0x0E, 0x83, 0x1E, 0x04, 0x00, 0x10, 0x00, 0x50, 0x01, 0x01, 0x20, 0x02,
	      0x60, 0x03, 0x67),
	DXL_BROADCAST_ID, DXL_INST_SYNC_WRITE, 0, 12,
	(const uint8_t[]){ 0x1E, 0x04, 0x00, 0x10, 0x00, 0x50, 0x01, 0x01, 0x20, 0x02, 0x60, 0x03 },
};

/* Protocol 2.0 */
#define HDR 0xFF, 0xFF, 0xFD, 0x00
static const struct golden v2_read_reply = {
	"2.0 e-manual, Read example: ID 1 status, Present Position 166",
	BYTES(HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0),
	1, DXL2_INST_STATUS, 0, 4, (const uint8_t[]){ 0xA6, 0x00, 0x00, 0x00 },
};
static const struct golden v2_sync_reply2 = {
	"2.0 e-manual, Sync Read example: ID 2 status, Present Position 2079",
	BYTES(HDR, 0x02, 0x08, 0x00, 0x55, 0x00, 0x1F, 0x08, 0x00, 0x00, 0xBA, 0xBE),
	2, DXL2_INST_STATUS, 0, 4, (const uint8_t[]){ 0x1F, 0x08, 0x00, 0x00 },
};
static const struct golden v2_stuffed_reply = {
	"2.0 derived: status FF FF FD FD (stuffed to FF FF FD FD FD)",
	BYTES(HDR, 0x01, 0x09, 0x00, 0x55, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0xFD, 0xD5, 0x1E),
	1, DXL2_INST_STATUS, 0, 4, (const uint8_t[]){ 0xFF, 0xFF, 0xFD, 0xFD },
};
static const struct golden v2_alert_reply = {
	"2.0 derived: alert + data range, no parameters",
	BYTES(HDR, 0x01, 0x04, 0x00, 0x55, 0x84, 0xB9, 0x0F), 1, DXL2_INST_STATUS, 0x84, 0, NULL,
};
static const struct golden v2_ping = {
	"2.0 e-manual, Ping example 1", BYTES(HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E),
	1, DXL2_INST_PING, 0, 0, NULL,
};
static const struct golden v2_ping_bc = {
	"2.0 broadcast PING", BYTES(HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42),
	DXL2_BROADCAST_ID, DXL2_INST_PING, 0, 0, NULL,
};

/* ---- one backend's cases ---------------------------------------------------- */

/* Bytes before a good packet: all dropped, with this many header errors. */
struct garbage_row {
	const char *legend;
	uint8_t bytes[12];
	size_t n;
	uint32_t header_errors;
};

/* A bad header, then a good packet of the same kind: the bad bytes dropped. */
struct bad_header_row {
	const char *legend;
	bool instructions;
	uint8_t bytes[12];
	size_t n;
	uint32_t header_errors;
	bool at_least;           /* header_errors is a lower bound (rescans may add more) */
};

/* A random packet to embed in garbage, in the frame's shape. */
#define EMBED_MAX_PARAMS 40
struct expected {
	uint8_t id, instr, err;
	uint16_t nparams;
	uint8_t params[EMBED_MAX_PARAMS];
};

struct backend_case {
	const struct dxl_proto *proto;
	/* the main status vector: split, byte by byte, behind garbage */
	const struct golden *reply;
	const struct garbage_row *garbage;
	size_t ngarbage;
	/* two status packets in one read */
	const struct golden *first, *second;
	/* a damaged `flip` (bytes from flip_from, XOR flip_mask), then
	 * `flip_good`; flipping byte `header_at` breaks the header instead */
	const struct golden *flip, *flip_good;
	size_t flip_from, header_at;
	uint8_t flip_mask;
	const struct bad_header_row *bad_headers;
	size_t nbad_headers;
	const struct golden *instruction_good;       /* after a bad instruction header */
	const struct golden *const *broadcasts;      /* instructions to every servo */
	size_t nbroadcasts;
	const uint8_t *bad_instruction_id;           /* NULL: in bad_headers instead */
	size_t nbad_instruction_id;
	/* reset: a whole `reset_first`, then `reset_cut` cut after reset_at bytes */
	const struct golden *reset_first, *reset_cut;
	size_t reset_at;
	/* random streams */
	size_t random_chunk;                         /* the largest read */
	void (*random_rich)(uint8_t *d, size_t n);   /* bytes that reach headers */
	size_t (*garbage_gen)(uint8_t *d, size_t max);
	void (*expected_gen)(bool instructions, struct expected *e);
	uint8_t status_err_max;                      /* 1.0: bit 7 is never a servo's */
};

/* Counters of either parser, read from the union the table fills. */
struct counts {
	uint32_t frames, checksum_errors, header_errors, stuffing_errors, bytes_dropped;
	size_t have;
};

static struct counts counts_of(const struct dxl_proto *proto, const union dxl_proto_parser *p)
{
	if (proto == &dxl_proto_v1)
		return (struct counts){ p->v1.frames, p->v1.checksum_errors, p->v1.header_errors, 0,
		                        p->v1.bytes_dropped, p->v1.have };
	return (struct counts){ p->v2.frames, p->v2.checksum_errors, p->v2.header_errors,
	                        p->v2.stuffing_errors, p->v2.bytes_dropped, p->v2.have };
}

/* ---- feeding ---------------------------------------------------------------- */

#define MAX_FRAMES 64

struct feed_result {
	size_t nframes;
	struct dxl_frame frames[MAX_FRAMES];
	size_t checksum_errors, header_errors, stuffing_errors;
};

/* Feed n bytes the way a caller does: again after every frame or error,
 * until the parser says it needs more. */
static void feed_all(const struct dxl_proto *proto, union dxl_proto_parser *p, const uint8_t *d, size_t n,
                     struct feed_result *res)
{
	size_t off = 0;
	for (;;) {
		size_t used = 0;
		static struct dxl_frame frame;
		int r = proto->parser_feed(p, d + off, n - off, &used, &frame);
		assert_true(used <= n - off);
		off += used;
		if (r == DXL_FRAME) {
			assert_true(res->nframes < MAX_FRAMES);
			res->frames[res->nframes++] = frame;
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

static void assert_golden(const struct dxl_frame *f, const struct golden *g)
{
	assert_int_equal(f->id, g->id);
	assert_int_equal(f->instr, g->instr);
	assert_int_equal(f->err, g->err);
	assert_int_equal(f->nparams, g->nparams);
	if (g->nparams)
		assert_memory_equal(f->params, g->params, g->nparams);
	assert_int_equal(f->wire_bytes, g->n);
}

static const struct backend_case *case_of(void **state)
{
	const struct backend_case *c = *state;
	print_message("# Protocol %s\n", c->proto->name);
	return c;
}

/* ---- shared: one run per backend ---------------------------------------------- */

/* Two pieces at every offset: one frame, and only after its last byte. */
static void test_split_two(void **state)
{
	const struct backend_case *c = case_of(state);
	const struct golden *g = c->reply;
	for (size_t k = 0; k <= g->n; k++) {
		union dxl_proto_parser p;
		static struct dxl_frame frame;
		size_t used = 99;
		c->proto->parser_init(&p, false);
		int r = c->proto->parser_feed(&p, g->bytes, k, &used, &frame);
		if (k < g->n) {
			assert_int_equal(r, DXL_NEED_MORE);
			assert_int_equal(used, k);
			r = c->proto->parser_feed(&p, g->bytes + k, g->n - k, &used, &frame);
			assert_int_equal(used, g->n - k);
		} else {
			assert_int_equal(used, g->n);
		}
		assert_int_equal(r, DXL_FRAME);
		assert_golden(&frame, g);
		struct counts n = counts_of(c->proto, &p);
		assert_int_equal(n.frames, 1);
		assert_int_equal(n.bytes_dropped, 0);
		assert_int_equal(n.have, 0);
	}
}

/* Every split into three reads: one frame, only after its last byte,
 * whatever falls between a pattern and its stuffed FD. */
static void test_split_three(void **state)
{
	const struct backend_case *c = case_of(state);
	const struct golden *g = c->reply;
	for (size_t a = 0; a <= g->n; a++) {
		for (size_t b = a; b <= g->n; b++) {
			union dxl_proto_parser p;
			struct feed_result res = { 0 };
			c->proto->parser_init(&p, false);
			feed_all(c->proto, &p, g->bytes, a, &res);
			assert_int_equal(res.nframes, a == g->n);
			feed_all(c->proto, &p, g->bytes + a, b - a, &res);
			assert_int_equal(res.nframes, b == g->n);
			feed_all(c->proto, &p, g->bytes + b, g->n - b, &res);
			assert_int_equal(res.nframes, 1);
			assert_golden(&res.frames[0], g);
			struct counts n = counts_of(c->proto, &p);
			assert_int_equal(n.bytes_dropped + n.header_errors + n.stuffing_errors, 0);
			assert_int_equal(n.have, 0);
		}
	}
}

static void test_byte_by_byte(void **state)
{
	const struct backend_case *c = case_of(state);
	const struct golden *g = c->reply;
	union dxl_proto_parser p;
	static struct dxl_frame frame;
	c->proto->parser_init(&p, false);
	for (int round = 0; round < 3; round++) {
		for (size_t i = 0; i < g->n; i++) {
			size_t used = 0;
			int r = c->proto->parser_feed(&p, g->bytes + i, 1, &used, &frame);
			assert_int_equal(used, 1);
			assert_int_equal(r, i + 1 == g->n ? DXL_FRAME : DXL_NEED_MORE);
		}
		assert_golden(&frame, g);
	}
	assert_int_equal(counts_of(c->proto, &p).frames, 3);
}

/* Leading garbage (gpsd-style rows with the garbage length as offset). */
static void test_leading_garbage(void **state)
{
	const struct backend_case *c = case_of(state);
	for (size_t i = 0; i < c->ngarbage; i++) {
		const struct garbage_row *row = &c->garbage[i];
		uint8_t stream[64];
		union dxl_proto_parser p;
		struct feed_result res = { 0 };
		print_message("# %s (offset %zu)\n", row->legend, row->n);
		memcpy(stream, row->bytes, row->n);
		memcpy(stream + row->n, c->reply->bytes, c->reply->n);
		c->proto->parser_init(&p, false);
		feed_all(c->proto, &p, stream, row->n + c->reply->n, &res);
		assert_int_equal(res.nframes, 1);
		assert_golden(&res.frames[0], c->reply);
		struct counts n = counts_of(c->proto, &p);
		assert_int_equal(n.bytes_dropped, row->n);
		assert_int_equal(n.header_errors, row->header_errors);
		assert_int_equal(n.checksum_errors + n.stuffing_errors, 0);
	}
}

static void test_two_packets_one_read(void **state)
{
	const struct backend_case *c = case_of(state);
	uint8_t stream[64];
	memcpy(stream, c->first->bytes, c->first->n);
	memcpy(stream + c->first->n, c->second->bytes, c->second->n);
	union dxl_proto_parser p;
	static struct dxl_frame frame;
	size_t used;
	c->proto->parser_init(&p, false);
	int r = c->proto->parser_feed(&p, stream, c->first->n + c->second->n, &used, &frame);
	assert_int_equal(r, DXL_FRAME);
	assert_int_equal(used, c->first->n);
	assert_golden(&frame, c->first);
	r = c->proto->parser_feed(&p, stream + used, c->second->n, &used, &frame);
	assert_int_equal(r, DXL_FRAME);
	assert_int_equal(used, c->second->n);
	assert_golden(&frame, c->second);
	assert_int_equal(counts_of(c->proto, &p).frames, 2);
}

static void test_bad_checksum_then_good(void **state)
{
	const struct backend_case *c = case_of(state);
	const struct golden *bad = c->flip, *good = c->flip_good;
	for (size_t k = c->flip_from; k < bad->n; k++) {
		uint8_t stream[64];
		memcpy(stream, bad->bytes, bad->n);
		stream[k] ^= c->flip_mask;
		memcpy(stream + bad->n, good->bytes, good->n);
		union dxl_proto_parser p;
		struct feed_result res = { 0 };
		print_message("# byte %zu flipped\n", k);
		c->proto->parser_init(&p, false);
		feed_all(c->proto, &p, stream, bad->n + good->n, &res);
		assert_int_equal(res.nframes, 1);
		assert_golden(&res.frames[0], good);
		/* 2.0's INST 0x55 flipped is no status: a header error, not a CRC error */
		assert_int_equal(res.checksum_errors + res.header_errors, 1);
		assert_int_equal(res.header_errors, k == c->header_at);
		struct counts n = counts_of(c->proto, &p);
		assert_int_equal(n.checksum_errors, k != c->header_at);
		assert_int_equal(n.bytes_dropped, bad->n);
	}
}

/* Each bad header field resyncs; the good packet after it still parses. */
static void test_bad_header_fields(void **state)
{
	const struct backend_case *c = case_of(state);
	for (size_t i = 0; i < c->nbad_headers; i++) {
		const struct bad_header_row *row = &c->bad_headers[i];
		const struct golden *good = row->instructions ? c->instruction_good : c->reply;
		uint8_t stream[64];
		union dxl_proto_parser p;
		struct feed_result res = { 0 };
		print_message("# %s\n", row->legend);
		memcpy(stream, row->bytes, row->n);
		memcpy(stream + row->n, good->bytes, good->n);
		c->proto->parser_init(&p, row->instructions);
		feed_all(c->proto, &p, stream, row->n + good->n, &res);
		struct counts n = counts_of(c->proto, &p);
		if (row->at_least)
			assert_true(res.header_errors >= row->header_errors);
		else
			assert_int_equal(res.header_errors, row->header_errors);
		assert_int_equal(res.header_errors, n.header_errors);
		assert_int_equal(res.nframes, 1);
		assert_golden(&res.frames[0], good);
		assert_int_equal(n.bytes_dropped, row->n);
	}
}

/* The simulator's side: broadcast is an instruction's ID, never a status's. */
static void test_instruction_side(void **state)
{
	const struct backend_case *c = case_of(state);
	union dxl_proto_parser p, s;
	struct feed_result res = { 0 }, sres = { 0 };
	c->proto->parser_init(&p, true);
	c->proto->parser_init(&s, false);
	for (size_t i = 0; i < c->nbroadcasts; i++) {
		feed_all(c->proto, &p, c->broadcasts[i]->bytes, c->broadcasts[i]->n, &res);
		feed_all(c->proto, &s, c->broadcasts[i]->bytes, c->broadcasts[i]->n, &sres);
	}
	assert_int_equal(res.nframes, c->nbroadcasts);
	for (size_t i = 0; i < c->nbroadcasts; i++)
		assert_golden(&res.frames[i], c->broadcasts[i]);
	assert_int_equal(counts_of(c->proto, &p).header_errors, 0);
	/* the same bytes are not status packets */
	assert_int_equal(sres.nframes, 0);
	assert_true(counts_of(c->proto, &s).header_errors >= c->nbroadcasts);

	if (c->bad_instruction_id) {
		struct feed_result bres = { 0 };
		c->proto->parser_init(&p, true);
		feed_all(c->proto, &p, c->bad_instruction_id, c->nbad_instruction_id, &bres);
		assert_int_equal(bres.nframes, 0);
		assert_true(counts_of(c->proto, &p).header_errors >= 1);
	}
}

static void test_reset_keeps_counters(void **state)
{
	const struct backend_case *c = case_of(state);
	const struct golden *cut = c->reset_cut;
	union dxl_proto_parser p;
	struct feed_result res = { 0 };
	c->proto->parser_init(&p, false);
	feed_all(c->proto, &p, c->reset_first->bytes, c->reset_first->n, &res);
	feed_all(c->proto, &p, cut->bytes, c->reset_at, &res);
	assert_int_equal(counts_of(c->proto, &p).have, c->reset_at);
	c->proto->parser_reset(&p);
	assert_int_equal(counts_of(c->proto, &p).have, 0);
	assert_int_equal(counts_of(c->proto, &p).frames, 1);
	/* the tail of the abandoned packet is garbage now, the next one parses */
	feed_all(c->proto, &p, cut->bytes + c->reset_at, cut->n - c->reset_at, &res);
	feed_all(c->proto, &p, cut->bytes, cut->n, &res);
	assert_int_equal(res.nframes, 2);
	assert_golden(&res.frames[1], cut);
	assert_int_equal(counts_of(c->proto, &p).frames, 2);
}

/* ---- shared: random streams ---------------------------------------------------- */

/* xorshift64*: a seeded, portable generator so failures reproduce. */
static uint64_t rng_state;
static uint32_t rng(void)
{
	rng_state ^= rng_state >> 12;
	rng_state ^= rng_state << 25;
	rng_state ^= rng_state >> 27;
	return (uint32_t)((rng_state * 0x2545F4914F6CDD1DULL) >> 32);
}

/* 1.0: about one byte in three is 0xFF, to reach headers and checksums. */
static void v1_random_rich(uint8_t *d, size_t n)
{
	for (size_t i = 0; i < n; i++)
		d[i] = rng() % 3 == 0 ? 0xFF : (uint8_t)rng();
}

/* 2.0: bytes drawn mostly from FF, FD, 00, 55 so headers, stuffing and CRCs
 * are all reached. */
static void v2_random_rich(uint8_t *d, size_t n)
{
	static const uint8_t alphabet[] = { 0xFF, 0xFF, 0xFD, 0x00, 0x55, 0x01, 0x04 };
	for (size_t i = 0; i < n; i++)
		d[i] = alphabet[rng() % sizeof alphabet];
}

/* Bytes fed = wire bytes of delivered frames + bytes dropped + bytes buffered. */
static void random_run(const struct backend_case *c, bool instructions, size_t total, bool rich)
{
	static uint8_t chunk[2048];
	assert_true(c->random_chunk <= sizeof chunk);
	union dxl_proto_parser p;
	c->proto->parser_init(&p, instructions);
	uint64_t fed = 0, frame_bytes = 0, errors = 0;
	while (fed < total) {
		size_t n = 1 + rng() % c->random_chunk;
		if (rich) {
			c->random_rich(chunk, n);
		} else {
			for (size_t i = 0; i < n; i++)
				chunk[i] = (uint8_t)rng();
		}
		size_t off = 0;
		for (;;) {
			size_t used = 0;
			static struct dxl_frame frame;
			int r = c->proto->parser_feed(&p, chunk + off, n - off, &used, &frame);
			assert_true(used <= n - off);
			off += used;
			assert_true(counts_of(c->proto, &p).have < c->proto->max_packet);
			if (r == DXL_FRAME) {
				frame_bytes += frame.wire_bytes;
				assert_true(frame.id <= c->proto->max_id ||
				            (instructions && frame.id == c->proto->broadcast_id));
				if (!instructions)
					assert_true(frame.err <= c->status_err_max);
			} else if (r < 0) {
				assert_true(r == DXL_E_CHECKSUM || r == DXL_E_HEADER || r == DXL_E_STUFFING);
				errors++;
			} else {
				break;
			}
		}
		fed += n;
	}
	struct counts n = counts_of(c->proto, &p);
	assert_int_equal(fed, frame_bytes + n.bytes_dropped + n.have);
	assert_int_equal(errors, (uint64_t)n.checksum_errors + n.header_errors + n.stuffing_errors);
	print_message("# %s %s %llu bytes: %u frames, %u checksum, %u header, %u stuffing errors, %u dropped\n",
	              instructions ? "instruction" : "status", rich ? "FF-rich" : "uniform",
	              (unsigned long long)fed, n.frames, n.checksum_errors, n.header_errors,
	              n.stuffing_errors, n.bytes_dropped);
}

static void test_random_bytes(void **state)
{
	const struct backend_case *c = case_of(state);
	rng_state = 0x9E3779B97F4A7C15ULL;
	random_run(c, false, 2u << 20, false);
	random_run(c, true, 2u << 20, false);
	random_run(c, false, 1u << 20, true);
	random_run(c, true, 1u << 20, true);
}

/* Garbage with no FF FF in it: it cannot complete a header with what follows
 * on 1.0 except through a trailing FF, which is recovered (FF FF FF is
 * rejected on the ID). */
static size_t v1_garbage(uint8_t *d, size_t max)
{
	size_t n = rng() % (max + 1);
	for (size_t i = 0; i < n; i++) {
		d[i] = (uint8_t)rng();
		if (d[i] == 0xFF && i > 0 && d[i - 1] == 0xFF)
			d[i] = 0x00;
	}
	return n;
}

/* Garbage that cannot complete FF FF FD: no FF FF in it, and none at its end. */
static size_t v2_garbage(uint8_t *d, size_t max)
{
	size_t n = v1_garbage(d, max);
	if (n > 0 && d[n - 1] == 0xFF)
		d[n - 1] = 0x00;
	return n;
}

static void v1_expected(bool instructions, struct expected *e)
{
	e->id = (uint8_t)(rng() % (DXL_MAX_ID + 1));
	uint8_t code = (uint8_t)(instructions ? rng() % 256 : rng() % 0x80);
	e->instr = instructions ? code : 0;
	e->err = instructions ? 0 : code;
	e->nparams = (uint16_t)(rng() % (EMBED_MAX_PARAMS + 1));
	for (size_t k = 0; k < e->nparams; k++)
		e->params[k] = (uint8_t)rng();
}

/* Parameters full of FF FF FD, to be stuffed. */
static void v2_expected(bool instructions, struct expected *e)
{
	e->id = (uint8_t)(rng() % (DXL2_MAX_ID + 1));
	e->instr = instructions ? (uint8_t)(rng() % 0x55) : DXL2_INST_STATUS;
	e->err = instructions ? 0 : (uint8_t)rng();
	e->nparams = (uint16_t)(rng() % (EMBED_MAX_PARAMS + 1));
	for (size_t k = 0; k < e->nparams; k++)
		e->params[k] = (uint8_t[]){ 0xFF, 0xFF, 0xFD, (uint8_t)rng() }[rng() % 4];
}

#define EMBED_PACKETS 3000
#define EMBED_MAX_GARBAGE 12

/* Random packets between garbage, read in random chunks: every one
 * recovered, in order (on 2.0 unstuffed). */
static void embedded_run(const struct backend_case *c, bool instructions)
{
	/* 2.0's worst case: every parameter stuffed, 12 bytes of framing */
	static uint8_t stream[EMBED_PACKETS * (2 * EMBED_MAX_PARAMS + 12 + EMBED_MAX_GARBAGE)];
	static struct expected want[EMBED_PACKETS];
	size_t n = 0;
	for (size_t i = 0; i < EMBED_PACKETS; i++) {
		struct expected *e = &want[i];
		c->expected_gen(instructions, e);
		n += c->garbage_gen(stream + n, EMBED_MAX_GARBAGE);
		int w = instructions
		      ? c->proto->encode_instruction(stream + n, sizeof stream - n, e->id, e->instr, e->params,
		                                     e->nparams)
		      : c->proto->encode_status(stream + n, sizeof stream - n, e->id, e->err, e->params, e->nparams);
		assert_true(w > 0);
		n += (size_t)w;
	}
	union dxl_proto_parser p;
	c->proto->parser_init(&p, instructions);
	size_t got = 0, off = 0;
	while (off < n) {
		size_t len = 1 + rng() % 300;
		if (len > n - off)
			len = n - off;
		size_t coff = 0;
		for (;;) {
			size_t used = 0;
			static struct dxl_frame frame;
			int r = c->proto->parser_feed(&p, stream + off + coff, len - coff, &used, &frame);
			coff += used;
			if (r == DXL_FRAME) {
				assert_true(got < EMBED_PACKETS);
				const struct expected *e = &want[got++];
				assert_int_equal(frame.id, e->id);
				assert_int_equal(frame.instr, e->instr);
				assert_int_equal(frame.err, e->err);
				assert_int_equal(frame.nparams, e->nparams);
				if (e->nparams)
					assert_memory_equal(frame.params, e->params, e->nparams);
			} else if (r == DXL_NEED_MORE) {
				break;
			}
		}
		off += len;
	}
	struct counts cn = counts_of(c->proto, &p);
	assert_int_equal(got, EMBED_PACKETS);
	assert_int_equal(cn.frames, EMBED_PACKETS);
	assert_int_equal(cn.checksum_errors + cn.stuffing_errors, 0);
}

static void test_embedded_packets(void **state)
{
	const struct backend_case *c = case_of(state);
	rng_state = 0xD1B54A32D192ED03ULL;
	embedded_run(c, false);
	embedded_run(c, true);
}

/* ---- Protocol 1.0 only ------------------------------------------------------- */

/* A damaged packet whose parameters hold a whole good one: after the
 * checksum error the parser rescans what it buffered and finds it. */
static void test_v1_rescan_buffered(void **state)
{
	(void)state;
	const uint8_t stream[] = { 0xFF, 0xFF, 0x01, 0x0A, 0x00,
	                           0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC, 0x00, 0x00,
	                           0x55 /* wrong checksum */ };
	union dxl_proto_parser p;
	struct feed_result res = { 0 };
	dxl_proto_v1.parser_init(&p, false);
	feed_all(&dxl_proto_v1, &p, stream, sizeof stream, &res);
	assert_int_equal(res.checksum_errors, 1);
	assert_int_equal(res.nframes, 1);
	assert_int_equal(res.frames[0].id, 1);
	assert_int_equal(res.frames[0].nparams, 0);
}

/* ---- Protocol 2.0 only ------------------------------------------------------- */

static void feed_v2(const struct golden *const *parts, size_t nparts, struct feed_result *res,
                    union dxl_proto_parser *p)
{
	dxl_proto_v2.parser_init(p, false);
	for (size_t i = 0; i < nparts; i++)
		feed_all(&dxl_proto_v2, p, parts[i]->bytes, parts[i]->n, res);
}

/* The reply matchers take 2.0's own packet. */
static struct dxl2_packet v2_packet(const struct dxl_frame *f)
{
	struct dxl2_packet pkt = { .id = f->id, .instr = f->instr, .err = f->err, .nparams = f->nparams,
	                           .wire_bytes = f->wire_bytes };
	memcpy(pkt.params, f->params, f->nparams);
	return pkt;
}

/* Garbage between two packets and two packets in one read. */
static void test_v2_between_packets(void **state)
{
	(void)state;
	uint8_t stream[64];
	size_t n = 0;
	memcpy(stream + n, v2_read_reply.bytes, v2_read_reply.n);
	n += v2_read_reply.n;
	const uint8_t junk[] = { 0xFF, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0x42 };
	memcpy(stream + n, junk, sizeof junk);
	n += sizeof junk;
	memcpy(stream + n, v2_sync_reply2.bytes, v2_sync_reply2.n);
	n += v2_sync_reply2.n;
	memcpy(stream + n, v2_stuffed_reply.bytes, v2_stuffed_reply.n);
	n += v2_stuffed_reply.n;
	union dxl_proto_parser p;
	struct feed_result res = { 0 };
	dxl_proto_v2.parser_init(&p, false);
	feed_all(&dxl_proto_v2, &p, stream, n, &res);
	assert_int_equal(res.nframes, 3);
	assert_golden(&res.frames[0], &v2_read_reply);
	assert_int_equal(res.frames[1].id, 2);
	assert_int_equal(dxl2_get_u32(res.frames[1].params), 2079);
	assert_golden(&res.frames[2], &v2_stuffed_reply);
	assert_int_equal(p.v2.bytes_dropped, sizeof junk);
	assert_int_equal(p.v2.header_errors + p.v2.checksum_errors + p.v2.stuffing_errors, 0);
}

/* A wrong LEN: too short for a status, beyond the limit, or simply wrong
 * (the CRC then fails) — the good packet after it is still found. */
static void test_v2_wrong_length(void **state)
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
	const struct golden *r = &v2_read_reply, *s = &v2_sync_reply2;
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		uint8_t stream[64];
		memcpy(stream, r->bytes, r->n);
		stream[5] = rows[i].len_l;
		stream[6] = rows[i].len_h;
		memcpy(stream + r->n, s->bytes, s->n);
		memcpy(stream + r->n + s->n, r->bytes, r->n);
		union dxl_proto_parser p;
		struct feed_result res = { 0 };
		print_message("# %s\n", rows[i].legend);
		dxl_proto_v2.parser_init(&p, false);
		feed_all(&dxl_proto_v2, &p, stream, 2 * r->n + s->n, &res);
		/* "one long" swallows the first byte of the next packet before its
		 * CRC fails; the rescan finds that packet all the same */
		assert_int_equal(res.nframes, 2);
		assert_int_equal(res.frames[0].id, 2);
		assert_golden(&res.frames[1], r);
		if (rows[i].why == DXL_E_HEADER)
			assert_int_equal(res.header_errors, 1);
		else
			assert_int_equal(res.checksum_errors, 1);
	}
}

/* A reply cut short, then a good one: the second header inside the first
 * packet's body is a stuffing error the moment the byte after FF FF FD
 * arrives, and the good reply is delivered with its own last byte — not
 * after the cut packet's LEN worth of bytes. */
static void test_v2_cut_short_then_good(void **state)
{
	(void)state;
	const struct golden *r = &v2_read_reply, *s = &v2_sync_reply2;
	for (size_t cut = 8; cut < r->n; cut++) {
		uint8_t stream[64];
		memcpy(stream, r->bytes, cut);
		memcpy(stream + cut, s->bytes, s->n);
		size_t n = cut + s->n;
		union dxl_proto_parser p;
		struct feed_result res = { 0 };
		print_message("# cut after %zu bytes\n", cut);
		dxl_proto_v2.parser_init(&p, false);
		feed_all(&dxl_proto_v2, &p, stream, n - 1, &res);
		assert_int_equal(res.nframes, 0);
		feed_all(&dxl_proto_v2, &p, stream + n - 1, 1, &res);
		assert_int_equal(res.nframes, 1);
		assert_int_equal(res.frames[0].id, 2);
		assert_int_equal(dxl2_get_u32(res.frames[0].params), 2079);
		assert_int_equal(p.v2.have, 0);
		assert_int_equal(p.v2.bytes_dropped, cut);
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
	memcpy(stream + 20, r->bytes, r->n);
	{
		union dxl_proto_parser q;
		struct feed_result qres = { 0 };
		dxl_proto_v2.parser_init(&q, false);
		feed_all(&dxl_proto_v2, &q, stream, 20 + r->n, &qres);
		assert_int_equal(qres.stuffing_errors, 1);
		assert_int_equal(qres.nframes, 1);
		assert_golden(&qres.frames[0], r);
		assert_int_equal(q.v2.have, 0);
	}
	/* a body that ends in an unstuffed FF FF FD: wrong stuffing */
	const uint8_t unstuffed[] = { HDR, 0x01, 0x07, 0x00, 0x55, 0x00, 0xFF, 0xFF, 0xFD, 0x00, 0x00 };
	union dxl_proto_parser p;
	struct feed_result res = { 0 };
	dxl_proto_v2.parser_init(&p, false);
	feed_all(&dxl_proto_v2, &p, unstuffed, sizeof unstuffed, &res);
	assert_int_equal(res.stuffing_errors, 1);
	assert_int_equal(p.v2.stuffing_errors, 1);
	assert_int_equal(res.nframes, 0);
}

static void test_v2_alert_bit(void **state)
{
	(void)state;
	const struct golden *const parts[] = { &v2_alert_reply };
	union dxl_proto_parser p;
	struct feed_result res = { 0 };
	char text[32];
	feed_v2(parts, 1, &res, &p);
	assert_int_equal(res.nframes, 1);
	assert_int_equal(res.frames[0].err, 0x84);
	assert_true(dxl2_err_alert(res.frames[0].err));
	assert_int_equal(dxl2_err_number(res.frames[0].err), DXL2_ERRNUM_DATA_RANGE);
	assert_string_equal(dxl2_err_format(res.frames[0].err, text, sizeof text), "alert|data range");
	/* the table names it the same */
	assert_string_equal(dxl_proto_v2.err_format(res.frames[0].err, text, sizeof text), "alert|data range");
	/* the servo's error is data: the reply still matches its request */
	struct dxl2_packet pkt = v2_packet(&res.frames[0]);
	assert_int_equal(dxl2_check_reply(&pkt, 1, 0), DXL_OK);
}

/* Replies checked against the request, as on 1.0. */
static void test_v2_check_reply(void **state)
{
	(void)state;
	const struct golden *const parts[] = { &v2_read_reply };
	union dxl_proto_parser p;
	struct feed_result res = { 0 };
	feed_v2(parts, 1, &res, &p);
	assert_int_equal(res.nframes, 1);
	struct dxl2_packet pkt = v2_packet(&res.frames[0]);
	assert_int_equal(dxl2_check_reply(&pkt, 1, 4), DXL_OK);
	assert_int_equal(dxl2_check_reply(&pkt, 2, 4), DXL_E_WRONG_ID);
	assert_int_equal(dxl2_check_reply(&pkt, 1, 2), DXL_E_WRONG_LENGTH);
	assert_int_equal(dxl2_check_reply(NULL, 1, 2), DXL_E_ARG);
}

/* SYNC_READ of IDs 1, 2, 3 (Present Position, 4 bytes): 2 and 1 answer, 3
 * never does; a stray ID 9 and a second reply from 2 are refused. */
static void test_v2_sync_read_missing(void **state)
{
	(void)state;
	const uint8_t ids[3] = { 1, 2, 3 };
	struct dxl2_multi_read m;
	uint8_t missing[4];
	assert_int_equal(dxl2_multi_read_sync(&m, 4, ids, 3), DXL_OK);
	assert_int_equal(dxl2_multi_read_missing(&m, missing, sizeof missing), 3);
	const struct golden *const parts[] = { &v2_sync_reply2, &v2_read_reply, &v2_sync_reply2 };
	union dxl_proto_parser p;
	struct feed_result res = { 0 };
	feed_v2(parts, 3, &res, &p);
	assert_int_equal(res.nframes, 3);
	static struct dxl2_packet frames[3];
	for (size_t i = 0; i < 3; i++)
		frames[i] = v2_packet(&res.frames[i]);
	size_t slot = 99;
	assert_int_equal(dxl2_multi_read_accept(&m, &frames[0], &slot), DXL_OK);
	assert_int_equal(slot, 1);
	assert_int_equal(m.out_of_order, 1);
	assert_int_equal(m.next, 0);
	assert_int_equal(dxl2_multi_read_accept(&m, &frames[1], &slot), DXL_OK);
	assert_int_equal(slot, 0);
	assert_int_equal(m.next, 2);
	assert_int_equal(dxl2_multi_read_accept(&m, &frames[2], &slot), DXL_E_WRONG_ID);
	static struct dxl2_packet stray;
	stray = frames[0];
	stray.id = 9;
	assert_int_equal(dxl2_multi_read_accept(&m, &stray, &slot), DXL_E_WRONG_ID);
	assert_false(dxl2_multi_read_done(&m));
	assert_int_equal(dxl2_multi_read_missing(&m, missing, sizeof missing), 1);
	assert_int_equal(missing[0], 3);
	/* a reply of the wrong size leaves the slot open */
	static struct dxl2_packet short3;
	short3 = frames[0];
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
	static struct dxl2_packet volt = { .id = 1, .instr = 0x55, .nparams = 2 };
	static struct dxl2_packet temp = { .id = 2, .instr = 0x55, .nparams = 2 };
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

/* ---- the two backends' cases --------------------------------------------------- */

static const struct garbage_row v1_garbage_rows[] = {
	{ "one zero byte", { 0x00 }, 1, 0 },
	{ "a lone FF", { 0xFF }, 1, 1 },             /* FF FF FF: ID 0xFF rejected */
	{ "FF FF", { 0xFF, 0xFF }, 2, 2 },
	{ "FF then noise", { 0xFF, 0x00, 0x12 }, 3, 0 },
	{ "noise with FF", { 0x12, 0x34, 0xFF, 0x00, 0xFF }, 5, 1 },
	{ "almost a header", { 0xFF, 0xFF, 0x01 }, 3, 1 }, /* LEN 0xFF rejected */
	{ "seven bytes", { 1, 2, 3, 4, 5, 6, 7 }, 7, 0 },
};

static const struct garbage_row v2_garbage_rows[] = {
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

static const struct bad_header_row v1_bad_headers[] = {
	{ "status ID 0xFF", false, { 0xFF, 0xFF, 0xFF, 0x02, 0x00, 0x00 }, 6, 1, true },
	{ "status ID 0xFE", false, { 0xFF, 0xFF, 0xFE, 0x02, 0x00, 0xFF }, 6, 1, true },
	{ "LEN 0", false, { 0xFF, 0xFF, 0x01, 0x00, 0x00, 0xFE }, 6, 1, true },
	{ "LEN 1", false, { 0xFF, 0xFF, 0x01, 0x01, 0x00, 0xFD }, 6, 1, true },
	{ "LEN 251", false, { 0xFF, 0xFF, 0x01, 0xFB, 0x00, 0x03 }, 6, 1, true },
	{ "LEN 255", false, { 0xFF, 0xFF, 0x01, 0xFF, 0x00, 0x00 }, 6, 1, true },
	{ "error byte 0x80", false, { 0xFF, 0xFF, 0x01, 0x02, 0x80, 0x7C }, 6, 1, true },
	{ "error byte 0xFF", false, { 0xFF, 0xFF, 0x01, 0x02, 0xFF, 0xFD }, 6, 1, true },
};

static const struct bad_header_row v2_bad_headers[] = {
	{ "status from broadcast", false, { HDR, 0xFE, 0x04, 0x00, 0x55, 0x00, 0, 0 }, 11, 1, false },
	{ "status from ID 253", false, { HDR, 0xFD, 0x04, 0x00, 0x55, 0x00, 0, 0 }, 11, 1, false },
	{ "status from ID 255", false, { HDR, 0xFF, 0x04, 0x00, 0x55, 0x00, 0, 0 }, 11, 1, false },
	{ "an instruction on the status side", false, { HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E }, 10, 1,
	  false },
	{ "a status on the instruction side", true, { HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C }, 11, 1,
	  false },
	{ "instruction to ID 253", true, { HDR, 0xFD, 0x03, 0x00, 0x01, 0, 0 }, 10, 1, false },
	{ "instruction LEN 2", true, { HDR, 0x01, 0x02, 0x00, 0x01, 0 }, 9, 1, false },
};

static const struct golden *const v1_broadcasts[] = { &v1_action_bc, &v1_sync_write };
static const struct golden *const v2_broadcasts[] = { &v2_ping_bc };
static const uint8_t v1_bad_instruction_id[] = { 0xFF, 0xFF, 0xFF, 0x02, 0x01, 0xFD };

#define ROWS(a) (a), sizeof (a) / sizeof (a)[0]

static struct backend_case case_v1 = {
	.proto = &dxl_proto_v1,
	.reply = &v1_reply6,
	.garbage = ROWS(v1_garbage_rows),
	.first = &v1_ping_reply, .second = &v1_temp_reply,
	/* the checksum byte's lowest bit */
	.flip = &v1_temp_reply, .flip_good = &v1_reply6, .flip_from = 6, .header_at = SIZE_MAX,
	.flip_mask = 0x01,
	.bad_headers = ROWS(v1_bad_headers),
	.instruction_good = NULL,
	.broadcasts = ROWS(v1_broadcasts),
	.bad_instruction_id = ROWS(v1_bad_instruction_id),
	.reset_first = &v1_reply6, .reset_cut = &v1_reply6, .reset_at = 5,
	.random_chunk = 512, .random_rich = v1_random_rich,
	.garbage_gen = v1_garbage, .expected_gen = v1_expected,
	.status_err_max = DXL_ERRBIT_MASK,
};

static struct backend_case case_v2 = {
	.proto = &dxl_proto_v2,
	.reply = &v2_stuffed_reply,
	.garbage = ROWS(v2_garbage_rows),
	.first = &v2_read_reply, .second = &v2_sync_reply2,
	/* any byte after the length: a CRC mismatch, but INST (byte 7) */
	.flip = &v2_read_reply, .flip_good = &v2_sync_reply2, .flip_from = 7, .header_at = 7, .flip_mask = 0x10,
	.bad_headers = ROWS(v2_bad_headers),
	.instruction_good = &v2_ping,
	.broadcasts = ROWS(v2_broadcasts),
	.bad_instruction_id = NULL, .nbad_instruction_id = 0,
	.reset_first = &v2_read_reply, .reset_cut = &v2_stuffed_reply,
	.reset_at = 12,   /* up to the stuffed FD's pattern */
	.random_chunk = 2048, .random_rich = v2_random_rich,
	.garbage_gen = v2_garbage, .expected_gen = v2_expected,
	.status_err_max = 0xFF,
};

#define BOTH(f) { #f " 1.0", f, NULL, NULL, &case_v1 }, { #f " 2.0", f, NULL, NULL, &case_v2 }
#define ONE(f) { #f, f, NULL, NULL, NULL }

int main(void)
{
	const struct CMUnitTest tests[] = {
		BOTH(test_split_two),
		BOTH(test_split_three),
		BOTH(test_byte_by_byte),
		BOTH(test_leading_garbage),
		BOTH(test_two_packets_one_read),
		BOTH(test_bad_checksum_then_good),
		BOTH(test_bad_header_fields),
		BOTH(test_instruction_side),
		BOTH(test_reset_keeps_counters),
		BOTH(test_random_bytes),
		BOTH(test_embedded_packets),
		ONE(test_v1_rescan_buffered),
		ONE(test_v2_between_packets),
		ONE(test_v2_wrong_length),
		ONE(test_v2_cut_short_then_good),
		ONE(test_v2_alert_bit),
		ONE(test_v2_check_reply),
		ONE(test_v2_sync_read_missing),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
