/*
 * fuzz_protocol_parser2.c — libFuzzer target for the Dynamixel 2.0 parser
 * (both kinds), the SYNC_READ reply tracker, and the bus layer's 2.0
 * transactions (a READ, a SYNC_READ of four servos, a broadcast PING) whose
 * replies are the input. The body, shared with the 1.0 target, is
 * tests/fuzz/protocol_fuzz.h; here is what only 2.0 checks and does,
 * Fast Sync/Bulk Read included: a status from 0xFE is the bytes it came
 * from unstuffed, and splits against a request of four servos into sound
 * parts up to the first failure; the bus runs a Fast Sync Read too.
 *
 *   make fuzz-build && build/fuzz/fuzz_protocol_parser2 -max_total_time=60
 */
#include "protocol_fuzz.h"

/* A status is marked 0x55; an instruction never is, and has no ERR. */
static void v2_check_kind(const struct dxl_frame *f, bool instructions)
{
	if (instructions)
		CHECK(f->instr != DXL2_INST_STATUS && f->err == 0);
	else
		CHECK(f->instr == DXL2_INST_STATUS);
}

/* Every status frame offered to a SYNC_READ of IDs 1-4. */
static const uint8_t tracked_ids[4] = { 1, 2, 3, 4 };
static struct dxl2_multi_read tracker;

static void v2_tracker_begin(void)
{
	CHECK(dxl2_multi_read_sync(&tracker, 4, tracked_ids, 4) == DXL_OK);
}

static void v2_tracker_frame(const struct dxl_frame *f)
{
	static struct dxl2_packet pkt;
	dxl_frame_to_packet2(f, &pkt);
	size_t slot = 99;
	int a = dxl2_multi_read_accept(&tracker, &pkt, &slot);
	CHECK(a == DXL_OK || a == DXL_E_WRONG_ID || a == DXL_E_WRONG_LENGTH);
	CHECK(a != DXL_OK || (slot < 4 && tracked_ids[slot] == pkt.id));
}

/* A fast read's status: not stuffed, so its frame is its bytes (header,
 * INST, ERR, params, CRC); split against a Fast Sync Read of IDs 1-4 (4
 * bytes each) and a Fast Bulk Read, it gives sound parts up to the first
 * failure. */
static void v2_check_fast(const struct dxl2_packet *f)
{
	static struct dxl2_packet pkt, back;
	static struct dxl2_multi_read m;
	static struct dxl2_parser again;
	static uint8_t wire[DXL2_MAX_PACKET];
	struct dxl2_fast_part parts[4];
	const struct dxl2_bulk_item items[4] = { { 1, 0, 1, NULL }, { 2, 0, 2, NULL }, { 3, 0, 4, NULL },
		                                 { 4, 0, 3, NULL } };
	size_t good = 99, used = 0, len = 2u + f->nparams + DXL2_CRC_BYTES;  /* INST ERR params CRC */
	CHECK(f->wire_bytes == DXL2_HEADER_BYTES + len);
	const uint8_t head[9] = { 0xFF, 0xFF, 0xFD, 0x00, 0xFE, (uint8_t)len, (uint8_t)(len >> 8), 0x55, f->err };
	memcpy(wire, head, sizeof head);
	memcpy(wire + sizeof head, f->params, f->nparams);
	uint16_t crc = dxl2_crc_update(0, wire, sizeof head + f->nparams);
	wire[f->wire_bytes - 2] = (uint8_t)crc;
	wire[f->wire_bytes - 1] = (uint8_t)(crc >> 8);
	dxl2_parser_init(&again, DXL2_PARSE_STATUS);
	dxl2_parser_expect_fast(&again, true);
	CHECK(dxl2_parser_feed(&again, wire, f->wire_bytes, &used, &back) == DXL_FRAME && used == f->wire_bytes);
	CHECK(back.nparams == f->nparams && memcmp(back.params, f->params, f->nparams) == 0);
	pkt = *f;
	CHECK(dxl2_multi_read_sync(&m, 4, tracked_ids, 4) == DXL_OK);
	for (int round = 0; round < 2; round++) {
		int r = dxl2_fast_status_split(&pkt, &m, parts, &good);
		CHECK(r == DXL_OK || r == DXL_E_WRONG_ID || r == DXL_E_WRONG_LENGTH || r == DXL_E_CHECKSUM);
		CHECK(good <= m.n && (r == DXL_OK) == (good == m.n));
		for (size_t i = 0; i < good; i++) {
			CHECK(parts[i].id == m.ids[i] && parts[i].len == m.len[i]);
			CHECK(parts[i].data >= pkt.params && parts[i].data + parts[i].len <= pkt.params + pkt.nparams);
		}
		CHECK(dxl2_multi_read_bulk(&m, items, 4) == DXL_OK);
	}
}

/* The status parser awaiting a fast read, fed the input in chunks: frames
 * and errors only, every fast frame re-read from its bytes and split. */
static void v2_run_fast_parser(const uint8_t *data, size_t size)
{
	static struct dxl2_parser p;
	static struct dxl2_packet f;
	size_t off = 0;
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	dxl2_parser_expect_fast(&p, true);
	while (off < size) {
		size_t chunk = 1 + (data[off] % 64), used = 0;
		if (chunk > size - off)
			chunk = size - off;
		int r = dxl2_parser_feed(&p, data + off, chunk, &used, &f);
		off += used;
		for (;;) {
			if (r == DXL_FRAME && f.id == DXL2_BROADCAST_ID)
				v2_check_fast(&f);
			else
				CHECK(r == DXL_FRAME || r == DXL_NEED_MORE || r == DXL_E_CHECKSUM || r == DXL_E_HEADER ||
				      r == DXL_E_STUFFING);
			if (r == DXL_NEED_MORE)
				break;
			r = dxl2_parser_feed(&p, NULL, 0, &used, &f);
		}
	}
	CHECK(p.have <= DXL2_MAX_PACKET);
}

static void v2_tracker_end(void)
{
	CHECK(tracker.answered + dxl2_multi_read_missing(&tracker, NULL, 0) == tracker.n);
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

static void v2_run_bus(const uint8_t *data, size_t size, uint32_t seed, bool echo)
{
	static struct bus b; /* large: keep it off the stack */
	static uint8_t buf[BUS_MULTI_MAX * 4];
	static struct bus_multi m;
	struct fuzz_io f = { data, size, 0, seed, 0 };
	const uint8_t ids[4] = { 1, 2, 3, 4 };
	uint8_t out[8], err = 0;
	fuzz_bus_init(&b, &f, echo);
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
	check_multi(&b, &m, bus_fast_sync_read(&b, 132, 4, ids, 4, &m));
	for (size_t i = 0; i < m.n; i++)
		CHECK(m.status[i] != DXL_OK || b.servo[m.id[i]].replies > 0);
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

static const struct fuzz_backend v2 = {
	.proto = &dxl_proto_v2,
	.max_encodable_params = DXL2_MAX_PARAMS,
	.min_wire_bytes = 10,
	.frame_ends_last_fed = true,
	.check_kind = v2_check_kind,
	.tracker_begin = v2_tracker_begin,
	.tracker_frame = v2_tracker_frame,
	.tracker_end = v2_tracker_end,
	.run_bus = v2_run_bus,
};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	v2_run_fast_parser(data, size);
	return fuzz_protocol_one(&v2, data, size);
}
