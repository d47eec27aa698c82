/*
 * fuzz_protocol_parser2.c — libFuzzer target for the Dynamixel 2.0 parser
 * (both kinds), the SYNC_READ reply tracker, and the bus layer's 2.0
 * transactions (a READ, a SYNC_READ of four servos, a broadcast PING) whose
 * replies are the input.
 *
 * The first input byte seeds the chunk sizes, so the fuzzer also explores how
 * a stream (and a stuffed FD) is split across read() calls. Invariants are
 * checked with abort(): every byte fed is accounted for (frame, dropped or
 * buffered), decoded frames obey the header rules, and a decoded frame
 * re-encodes to exactly the bytes it was read from (stuffing is canonical:
 * a frame that parses has one encoding) and parses back to itself.
 *
 *   make fuzz-build && build/fuzz/fuzz_protocol_parser2 -max_total_time=60
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bus.h"
#include "dxl2.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

static size_t next_chunk(uint32_t *seed)
{
	*seed = *seed * 1103515245u + 12345u;
	return 1 + (*seed >> 16) % 64;
}

/* The bytes a frame was read from are the last wire_bytes before the end of
 * what was fed: the parser reports a frame with its last byte. */
static void check_frame(enum dxl2_parse_kind kind, const struct dxl2_packet *pkt, const uint8_t *wire)
{
	static uint8_t buf[DXL2_MAX_PACKET];
	static struct dxl2_packet back;
	CHECK(pkt->nparams <= DXL2_MAX_PARAMS);
	CHECK(pkt->wire_bytes >= 10 && pkt->wire_bytes <= DXL2_MAX_PACKET);
	if (kind == DXL2_PARSE_STATUS) {
		CHECK(pkt->id <= DXL2_MAX_ID);
		CHECK(pkt->instr == DXL2_INST_STATUS);
	} else {
		CHECK(pkt->id <= DXL2_MAX_ID || pkt->id == DXL2_BROADCAST_ID);
		CHECK(pkt->instr != DXL2_INST_STATUS && pkt->err == 0);
	}
	int n = kind == DXL2_PARSE_STATUS
	      ? dxl2_encode_status(buf, sizeof buf, pkt->id, pkt->err, pkt->params, pkt->nparams)
	      : dxl2_encode_instruction(buf, sizeof buf, pkt->id, pkt->instr, pkt->params, pkt->nparams);
	CHECK(n == pkt->wire_bytes);
	CHECK(memcmp(buf, wire, (size_t)n) == 0);
	struct dxl2_parser again;
	size_t used = 0;
	dxl2_parser_init(&again, kind);
	CHECK(dxl2_parser_feed(&again, buf, (size_t)n, &used, &back) == DXL_FRAME);
	CHECK(used == (size_t)n);
	CHECK(back.id == pkt->id && back.instr == pkt->instr && back.err == pkt->err);
	CHECK(back.nparams == pkt->nparams && memcmp(back.params, pkt->params, pkt->nparams) == 0);
}

static void run_parser(enum dxl2_parse_kind kind, const uint8_t *data, size_t size, uint32_t seed)
{
	static struct dxl2_parser p;
	static struct dxl2_packet pkt;
	struct dxl2_multi_read m;
	const uint8_t ids[4] = { 1, 2, 3, 4 };
	CHECK(dxl2_multi_read_sync(&m, 4, ids, 4) == DXL_OK);
	dxl2_parser_init(&p, kind);
	uint64_t frame_bytes = 0, errors = 0;
	size_t off = 0;
	while (off < size) {
		size_t len = next_chunk(&seed);
		if (len > size - off)
			len = size - off;
		size_t coff = 0;
		for (;;) {
			size_t used = 0;
			int r = dxl2_parser_feed(&p, data + off + coff, len - coff, &used, &pkt);
			CHECK(used <= len - coff);
			coff += used;
			CHECK(p.have < DXL2_MAX_PACKET);
			if (r == DXL_FRAME) {
				check_frame(kind, &pkt, data + off + coff - pkt.wire_bytes);
				frame_bytes += pkt.wire_bytes;
				if (kind == DXL2_PARSE_STATUS) {
					size_t slot = 99;
					int a = dxl2_multi_read_accept(&m, &pkt, &slot);
					CHECK(a == DXL_OK || a == DXL_E_WRONG_ID || a == DXL_E_WRONG_LENGTH);
					CHECK(a != DXL_OK || (slot < 4 && ids[slot] == pkt.id));
				}
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
	CHECK(frame_bytes + p.bytes_dropped + p.have == size);
	CHECK(errors == (uint64_t)p.checksum_errors + p.header_errors + p.stuffing_errors);
	CHECK(m.answered + dxl2_multi_read_missing(&m, NULL, 0) == m.n);
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

/* Slots are either data or a failure, every one accounted for; no servo has
 * more replies than requests. */
static void check_multi(const struct bus *b, const struct bus_multi *m, int r)
{
	CHECK(!bus_is_pending(b));
	CHECK(r == DXL_OK || r < 0);
	CHECK(m->answered <= m->n && m->n <= BUS_MULTI_MAX);
	CHECK(m->answered + bus_multi_failed(m, NULL, 0) == m->n);
	for (size_t i = 0; i < m->n; i++) {
		CHECK((bus_multi_data(m, i) != NULL) == (m->status[i] == DXL_OK));
		CHECK(m->off[i] + m->len[i] <= m->cap);
	}
	for (size_t id = 0; id < BUS_NSERVOS; id++)
		CHECK(b->servo[id].replies <= b->servo[id].transactions);
}

static void run_bus(const uint8_t *data, size_t size, uint32_t seed, bool echo)
{
	static struct bus b; /* large: keep it off the stack */
	static uint8_t buf[BUS_MULTI_MAX * 4];
	static struct bus_multi m;
	struct fuzz_io f = { data, size, 0, seed, 0 };
	const struct bus_io io = { &f, fio_write, fio_read, fio_wait, fio_now, NULL, NULL };
	const struct bus_timing t = { 1000000, 0, 1000, 500 };
	const uint8_t ids[4] = { 1, 2, 3, 4 };
	uint8_t out[8], err = 0;
	bus_init(&b, &io, &t, echo);
	CHECK(bus_set_protocol(&b, BUS_PROTOCOL_2) == DXL_OK);
	int r = bus_read(&b, 1, 132, 8, out, &err);
	CHECK(r == DXL_OK || r < 0);
	CHECK(!bus_is_pending(&b));
	memset(&m, 0, sizeof m);
	m.data = buf;
	m.cap = sizeof buf;
	check_multi(&b, &m, bus_sync_read(&b, 126, 4, ids, 4, &m));
	memset(&m, 0, sizeof m);
	m.data = buf;
	m.cap = sizeof buf;
	r = bus_ping_all_begin(&b, &m);
	if (r == DXL_OK)
		r = bus_wait_done(&b, NULL);
	check_multi(&b, &m, r);
	for (size_t i = 0; i < m.n; i++)
		for (size_t k = i + 1; k < m.n; k++)
			CHECK(m.id[i] != m.id[k]);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size == 0)
		return 0;
	uint32_t seed = data[0];
	run_parser(DXL2_PARSE_STATUS, data + 1, size - 1, seed);
	run_parser(DXL2_PARSE_INSTRUCTION, data + 1, size - 1, seed);
	run_bus(data + 1, size - 1, seed, (data[0] & 1) != 0);
	return 0;
}
