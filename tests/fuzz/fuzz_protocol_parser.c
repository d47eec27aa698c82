/*
 * fuzz_protocol_parser.c — libFuzzer target for the Dynamixel 1.0 parser (both kinds)
 * and for a bus transaction fed with arbitrary reply bytes. The body, shared
 * with the 2.0 target, is tests/fuzz/protocol_fuzz.h; here is what only 1.0
 * checks and does.
 *
 *   make fuzz-build && build/fuzz/fuzz_protocol_parser -max_total_time=60
 */
#include "protocol_fuzz.h"

/* A status's error byte never has bit 7; an instruction has no error byte. */
static void v1_check_kind(const struct dxl_frame *f, bool instructions)
{
	if (instructions) {
		CHECK(f->err == 0);
	} else {
		CHECK(f->err <= DXL_ERRBIT_MASK);
		CHECK(f->instr == 0);
	}
}

static void v1_run_bus(const uint8_t *data, size_t size, uint32_t seed, bool echo)
{
	static struct bus b; /* large: keep it off the stack */
	struct fuzz_io f = { data, size, 0, seed, 0 };
	fuzz_bus_init(&b, &f, echo);
	uint8_t out[8], err = 0;
	int r = bus_read(&b, 1, 36, 8, out, &err);
	CHECK(r == DXL_OK || r < 0);
	CHECK(!bus_is_pending(&b));
	if (r == DXL_OK)
		CHECK(err <= DXL_ERRBIT_MASK);
	r = bus_ping(&b, 1, &err);
	CHECK(!bus_is_pending(&b));
}

static const struct fuzz_backend v1 = {
	.proto = &dxl_proto_v1,
	.max_encodable_params = DXL_MAX_TX_PARAMS,
	.min_wire_bytes = 6,
	.check_kind = v1_check_kind,
	.run_bus = v1_run_bus,
};

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	return fuzz_protocol_one(&v1, data, size);
}
