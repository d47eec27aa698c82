/*
 * fuzz_protocol_parser2.c — libFuzzer target for the Dynamixel 2.0 parser
 * (both kinds) and the SYNC_READ reply tracker.
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
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size == 0)
		return 0;
	uint32_t seed = data[0];
	run_parser(DXL2_PARSE_STATUS, data + 1, size - 1, seed);
	run_parser(DXL2_PARSE_INSTRUCTION, data + 1, size - 1, seed);
	return 0;
}
