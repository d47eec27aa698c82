/*
 * protocol_fuzz.h — the body both protocol fuzz targets share
 * (fuzz_protocol_parser.c for 1.0, fuzz_protocol_parser2.c for 2.0): the
 * parser driven through its table (struct dxl_proto), in both kinds, and a
 * fake transport for bus transactions whose replies are the input. Each
 * entry file fills a struct fuzz_backend with what only its protocol checks
 * and does; the Makefile builds one target per entry file, so the names,
 * seeds and corpora stay as they were.
 *
 * Included once, by one entry file: the definitions are static.
 *
 * The first input byte seeds the chunk sizes, so the fuzzer also explores how
 * a stream (and a 2.0 stuffed FD) is split across read() calls. Invariants
 * are checked with abort(): every byte fed is accounted for (frame, dropped
 * or buffered), decoded frames obey the header rules, and a decoded frame
 * re-encodes to as many bytes as it took and parses back to itself; on 2.0
 * to exactly the bytes it was read from (stuffing is canonical: a frame that
 * parses has one encoding).
 */
#ifndef UNDULATE_TESTS_PROTOCOL_FUZZ_H
#define UNDULATE_TESTS_PROTOCOL_FUZZ_H

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bus.h"
#include "dxl_proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

/* What one protocol adds to the shared body. */
struct fuzz_backend {
	const struct dxl_proto *proto;
	/* frames with more parameters come in but are never sent (1.0: its
	 * encoders stay within 250 bytes on the wire) */
	size_t max_encodable_params;
	size_t min_wire_bytes;
	/* A frame comes out with its last byte, so the bytes it was read from
	 * are the last wire_bytes fed (2.0). 1.0's rescan after an error can
	 * deliver a frame from bytes it had buffered past it: there only the
	 * length and the round trip are checked. */
	bool frame_ends_last_fed;
	/* the header rules of one kind, beyond the ID */
	void (*check_kind)(const struct dxl_frame *f, bool instructions);
	/* status frames handed to a reply tracker (NULL: none) */
	void (*tracker_begin)(void);
	void (*tracker_frame)(const struct dxl_frame *f);
	void (*tracker_end)(void);
	/* bus transactions answered by the input */
	void (*run_bus)(const uint8_t *data, size_t size, uint32_t seed, bool echo);
};

/* Chunk sizes from a small generator seeded by the input. */
static size_t next_chunk(uint32_t *seed)
{
	*seed = *seed * 1103515245u + 12345u;
	return 1 + (*seed >> 16) % 64;
}

/* The bytes a frame was read from are the last wire_bytes before the end of
 * what was fed: the parser reports a frame with its last byte. */
static void check_frame(const struct fuzz_backend *fb, bool instructions, const struct dxl_frame *f,
                        const uint8_t *wire)
{
	const struct dxl_proto *proto = fb->proto;
	static uint8_t buf[DXL2_MAX_PACKET];
	static struct dxl_frame back;
	CHECK(f->nparams <= proto->max_params);
	CHECK(f->wire_bytes >= fb->min_wire_bytes && f->wire_bytes <= proto->max_packet);
	if (instructions)
		CHECK(f->id <= proto->max_id || f->id == proto->broadcast_id);
	else
		CHECK(f->id <= proto->max_id);
	fb->check_kind(f, instructions);
	if (f->nparams > fb->max_encodable_params)
		return;
	int n = instructions
	      ? proto->encode_instruction(buf, sizeof buf, f->id, f->instr, f->params, f->nparams)
	      : proto->encode_status(buf, sizeof buf, f->id, f->err, f->params, f->nparams);
	CHECK(n == f->wire_bytes);
	if (fb->frame_ends_last_fed)
		CHECK(memcmp(buf, wire, (size_t)n) == 0);
	static union dxl_proto_parser again;
	size_t used = 0;
	proto->parser_init(&again, instructions);
	CHECK(proto->parser_feed(&again, buf, (size_t)n, &used, &back) == DXL_FRAME);
	CHECK(used == (size_t)n);
	CHECK(back.id == f->id && back.instr == f->instr && back.err == f->err);
	CHECK(back.nparams == f->nparams && memcmp(back.params, f->params, f->nparams) == 0);
}

/* Counters of either parser. */
struct fuzz_counts {
	uint64_t frames, errors, dropped, have;
};

static struct fuzz_counts counts_of(const struct dxl_proto *proto, const union dxl_proto_parser *p)
{
	if (proto == &dxl_proto_v1)
		return (struct fuzz_counts){ p->v1.frames, (uint64_t)p->v1.checksum_errors + p->v1.header_errors,
		                             p->v1.bytes_dropped, p->v1.have };
	return (struct fuzz_counts){ p->v2.frames,
		                     (uint64_t)p->v2.checksum_errors + p->v2.header_errors + p->v2.stuffing_errors,
		                     p->v2.bytes_dropped, p->v2.have };
}

static void run_parser(const struct fuzz_backend *fb, bool instructions, const uint8_t *data, size_t size,
                       uint32_t seed)
{
	const struct dxl_proto *proto = fb->proto;
	static union dxl_proto_parser p;
	static struct dxl_frame f;
	bool track = !instructions && fb->tracker_frame;
	if (track)
		fb->tracker_begin();
	proto->parser_init(&p, instructions);
	uint64_t frame_bytes = 0, errors = 0;
	size_t off = 0;
	while (off < size) {
		size_t len = next_chunk(&seed);
		if (len > size - off)
			len = size - off;
		size_t coff = 0;
		for (;;) {
			size_t used = 0;
			int r = proto->parser_feed(&p, data + off + coff, len - coff, &used, &f);
			CHECK(used <= len - coff);
			coff += used;
			CHECK(counts_of(proto, &p).have < proto->max_packet);
			if (r == DXL_FRAME) {
				check_frame(fb, instructions, &f, data + off + coff - f.wire_bytes);
				frame_bytes += f.wire_bytes;
				if (track)
					fb->tracker_frame(&f);
			} else if (r == DXL_E_CHECKSUM || r == DXL_E_HEADER || r == DXL_E_STUFFING) {
				errors++;
			} else {
				CHECK(r == DXL_NEED_MORE);
				CHECK(coff == len);
				break;
			}
		}
		off += len;
	}
	struct fuzz_counts c = counts_of(proto, &p);
	CHECK(frame_bytes + c.dropped + c.have == size);
	CHECK(errors == c.errors);
	if (track)
		fb->tracker_end();
}

/* ---- bus transactions whose replies are the fuzz input ---------------------- */
struct fuzz_io {
	const uint8_t *data;
	size_t size, off;
	uint32_t seed;
	uint64_t now;
};

static int fio_write(void *ctx, const uint8_t *buf, size_t n)
{
	(void)ctx;
	(void)buf;
	(void)n;
	return DXL_OK;
}

static long fio_read(void *ctx, uint8_t *buf, size_t cap)
{
	struct fuzz_io *f = ctx;
	size_t n = next_chunk(&f->seed);
	if (n > f->size - f->off)
		n = f->size - f->off;
	if (n > cap)
		n = cap;
	memcpy(buf, f->data + f->off, n);
	f->off += n;
	return (long)n;
}

static int fio_wait(void *ctx, uint32_t timeout_us)
{
	struct fuzz_io *f = ctx;
	if (f->off < f->size)
		return 1;
	f->now += timeout_us;
	return 0;
}

static uint64_t fio_now(void *ctx)
{
	return ((struct fuzz_io *)ctx)->now;
}

/* A bus whose peer answers with the input; f must outlive the bus's use. */
static void fuzz_bus_init(struct bus *b, struct fuzz_io *f, bool echo)
{
	const struct bus_io io = { f, fio_write, fio_read, fio_wait, fio_now, NULL, NULL };
	const struct bus_timing t = { 1000000, 0, 1000, 500 };
	bus_init(b, &io, &t, echo);
}

static int fuzz_protocol_one(const struct fuzz_backend *fb, const uint8_t *data, size_t size)
{
	if (size == 0)
		return 0;
	uint32_t seed = data[0];
	run_parser(fb, false, data + 1, size - 1, seed);
	run_parser(fb, true, data + 1, size - 1, seed);
	fb->run_bus(data + 1, size - 1, seed, (data[0] & 1) != 0);
	return 0;
}

#endif
