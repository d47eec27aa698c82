/*
 * fuzz_protocol_parser.c — libFuzzer target for the Dynamixel 1.0 parser (both kinds)
 * and for a bus transaction fed with arbitrary reply bytes.
 *
 * The first input byte seeds the chunk sizes, so the fuzzer also explores how
 * a stream is split across read() calls. Invariants are checked with abort():
 * every byte fed is accounted for (frame, dropped or buffered), decoded frames
 * obey the header rules, and a decoded frame re-encodes to a packet that parses
 * back to itself.
 *
 *   make fuzz && build/fuzz/fuzz_protocol_parser -max_total_time=60
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bus.h"
#include "dxl.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

/* Chunk sizes from a small generator seeded by the input. */
static size_t next_chunk(uint32_t *seed)
{
	*seed = *seed * 1103515245u + 12345u;
	return 1 + (*seed >> 16) % 64;
}

static void check_frame(enum dxl_parse_kind kind, const struct dxl_packet *pkt)
{
	CHECK(pkt->nparams <= DXL_MAX_PARAMS);
	if (kind == DXL_PARSE_STATUS) {
		CHECK(pkt->id <= DXL_MAX_ID);
		CHECK(pkt->code <= DXL_ERRBIT_MASK);
	} else {
		CHECK(pkt->id <= DXL_BROADCAST_ID);
	}
	/* decode(encode(frame)) == frame, for frames our encoder may produce */
	if (pkt->nparams > DXL_MAX_TX_PARAMS)
		return;
	uint8_t buf[DXL_MAX_PACKET];
	int n = kind == DXL_PARSE_STATUS
	      ? dxl_encode_status(buf, sizeof buf, pkt->id, pkt->code, pkt->params, pkt->nparams)
	      : dxl_encode_instruction(buf, sizeof buf, pkt->id, pkt->code, pkt->params, pkt->nparams);
	CHECK(n == pkt->nparams + 6);
	struct dxl_parser again;
	struct dxl_packet back;
	size_t used = 0;
	dxl_parser_init(&again, kind);
	CHECK(dxl_parser_feed(&again, buf, (size_t)n, &used, &back) == DXL_FRAME);
	CHECK(used == (size_t)n);
	CHECK(back.id == pkt->id && back.code == pkt->code && back.nparams == pkt->nparams);
	CHECK(memcmp(back.params, pkt->params, pkt->nparams) == 0);
}

static void run_parser(enum dxl_parse_kind kind, const uint8_t *data, size_t size, uint32_t seed)
{
	struct dxl_parser p;
	dxl_parser_init(&p, kind);
	uint64_t frame_bytes = 0, errors = 0;
	size_t off = 0;
	while (off < size) {
		size_t len = next_chunk(&seed);
		if (len > size - off)
			len = size - off;
		size_t coff = 0;
		for (;;) {
			size_t used = 0;
			struct dxl_packet pkt;
			int r = dxl_parser_feed(&p, data + off + coff, len - coff, &used, &pkt);
			CHECK(used <= len - coff);
			coff += used;
			CHECK(p.have < DXL_MAX_PACKET);
			if (r == DXL_FRAME) {
				check_frame(kind, &pkt);
				frame_bytes += (uint64_t)pkt.nparams + 6;
			} else if (r == DXL_E_CHECKSUM || r == DXL_E_HEADER) {
				errors++;
			} else {
				CHECK(r == DXL_NEED_MORE);
				CHECK(coff == len);
				break;
			}
		}
		off += len;
	}
	CHECK(frame_bytes + p.bytes_dropped + p.have == size);
	CHECK(errors == (uint64_t)p.checksum_errors + p.header_errors);
}

/* ---- a bus transaction whose reply is the fuzz input ---------------------- */
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

static void run_bus(const uint8_t *data, size_t size, uint32_t seed, bool echo)
{
	static struct bus b; /* large: keep it off the stack */
	struct fuzz_io f = { data, size, 0, seed, 0 };
	const struct bus_io io = { &f, fio_write, fio_read, fio_wait, fio_now, NULL, NULL };
	const struct bus_timing t = { 1000000, 0, 1000, 500 };
	bus_init(&b, &io, &t, echo);
	uint8_t out[8], err = 0;
	int r = bus_read(&b, 1, 36, 8, out, &err);
	CHECK(r == DXL_OK || r < 0);
	CHECK(!bus_is_pending(&b));
	if (r == DXL_OK)
		CHECK(err <= DXL_ERRBIT_MASK);
	r = bus_ping(&b, 1, &err);
	CHECK(!bus_is_pending(&b));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size == 0)
		return 0;
	uint32_t seed = data[0];
	run_parser(DXL_PARSE_STATUS, data + 1, size - 1, seed);
	run_parser(DXL_PARSE_INSTRUCTION, data + 1, size - 1, seed);
	run_bus(data + 1, size - 1, seed, (data[0] & 1) != 0);
	return 0;
}
