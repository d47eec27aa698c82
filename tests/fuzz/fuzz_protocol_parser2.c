/*
 * fuzz_protocol_parser2.c — libFuzzer target for the Dynamixel 2.0 parser
 * (both kinds), the SYNC_READ reply tracker, and the bus layer's 2.0
 * transactions (a READ, a SYNC_READ of four servos, a broadcast PING) whose
 * replies are the input. The body, shared with the 1.0 target, is
 * tests/fuzz/protocol_fuzz.h; here is what only 2.0 checks and does.
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
	return fuzz_protocol_one(&v2, data, size);
}
