/*
 * bus2_calls.c — the blocking Protocol 2.0 calls for tools and start-up.
 * Each is a begin on bus.c's shared core (the same flushing, echo
 * cancelling, timeouts and counters as 1.0) and a wait for its end through
 * io->wait (bus_wait_done); nothing here touches the line itself.
 */
#include "bus.h"

#include <string.h>

/* The largest parameter count of a request built here: address + data. */
#define BUS2_ADDR_BYTES 2

static int bus2_check(const struct bus *b)
{
	return b->protocol == BUS_PROTOCOL_2 ? DXL_OK : DXL_E_UNSUPPORTED;
}

/* One request, its reply (if expected) and its ERR field. The reply stays
 * in the bus (bus_reply2) for the caller to copy out. */
static int bus2_transact(struct bus *b, uint8_t id, uint8_t instr, const uint8_t *params, size_t nparams,
                         int reply_params, uint8_t *err)
{
	if (err)
		*err = 0;
	int r = bus2_check(b);
	if (r < 0)
		return r;
	r = bus_begin(b, id, instr, params, nparams, reply_params);
	if (r < 0 || !bus_is_pending(b))
		return r;
	r = bus_wait_done(b, NULL);
	if (r == DXL_OK && err)
		*err = bus_reply2(b)->err;
	return r;
}

int bus2_ping(struct bus *b, uint8_t id, uint16_t *model, uint8_t *firmware, uint8_t *err)
{
	if (id > DXL2_MAX_ID)
		return DXL_E_ARG;   /* broadcast: bus2_ping_all */
	int r = bus2_transact(b, id, DXL2_INST_PING, NULL, 0, 3, err);
	if (r != DXL_OK)
		return r;
	const uint8_t *p = bus_reply2(b)->params;
	if (model)
		*model = dxl_get_u16(p);
	if (firmware)
		*firmware = p[2];
	return DXL_OK;
}

int bus2_ping_all(struct bus *b, struct bus2_found *found, size_t cap, size_t *n)
{
	uint8_t data[BUS_MULTI_MAX * 3];
	struct bus_multi m = { .data = data, .cap = sizeof data };
	*n = 0;
	int r = bus2_check(b);
	if (r == DXL_OK)
		r = bus_ping_all_begin(b, &m);
	if (r == DXL_OK)
		r = bus_wait_done(b, NULL);
	for (size_t i = 0; i < m.n && *n < cap; i++) {
		const uint8_t *p = bus_multi_data(&m, i);
		if (p == NULL)
			continue;
		found[(*n)++] = (struct bus2_found){ m.id[i], dxl_get_u16(p), p[2], m.err[i] };
	}
	return r;
}

int bus2_read(struct bus *b, uint8_t id, uint16_t addr, uint16_t len, uint8_t *out, uint8_t *err)
{
	if (id > DXL2_MAX_ID || len == 0 || len > DXL2_MAX_READ_LEN || out == NULL)
		return DXL_E_ARG;
	const uint8_t params[4] = { (uint8_t)addr, (uint8_t)(addr >> 8), (uint8_t)len, (uint8_t)(len >> 8) };
	int r = bus2_transact(b, id, DXL2_INST_READ, params, sizeof params, len, err);
	if (r == DXL_OK)
		memcpy(out, bus_reply2(b)->params, len);
	return r;
}

int bus2_read_u8(struct bus *b, uint8_t id, uint16_t addr, uint8_t *v, uint8_t *err)
{
	return bus2_read(b, id, addr, 1, v, err);
}

int bus2_read_u16(struct bus *b, uint8_t id, uint16_t addr, uint16_t *v, uint8_t *err)
{
	uint8_t raw[2];
	if (v == NULL)
		return DXL_E_ARG;
	int r = bus2_read(b, id, addr, 2, raw, err);
	if (r == DXL_OK)
		*v = dxl_get_u16(raw);
	return r;
}

int bus2_read_u32(struct bus *b, uint8_t id, uint16_t addr, uint32_t *v, uint8_t *err)
{
	uint8_t raw[4];
	if (v == NULL)
		return DXL_E_ARG;
	int r = bus2_read(b, id, addr, 4, raw, err);
	if (r == DXL_OK)
		*v = dxl2_get_u32(raw);
	return r;
}

static int bus2_addr_data(struct bus *b, uint8_t id, uint8_t instr, uint16_t addr, const uint8_t *data, size_t n,
                          bool expect_reply, uint8_t *err)
{
	uint8_t params[DXL2_MAX_PARAMS];
	if (data == NULL || n == 0 || n + BUS2_ADDR_BYTES > sizeof params)
		return DXL_E_ARG;
	params[0] = (uint8_t)addr;
	params[1] = (uint8_t)(addr >> 8);
	memcpy(params + BUS2_ADDR_BYTES, data, n);
	return bus2_transact(b, id, instr, params, n + BUS2_ADDR_BYTES, expect_reply ? 0 : -1, err);
}

int bus2_write(struct bus *b, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply,
               uint8_t *err)
{
	return bus2_addr_data(b, id, DXL2_INST_WRITE, addr, data, n, expect_reply, err);
}

int bus2_write_u8(struct bus *b, uint8_t id, uint16_t addr, uint8_t v, uint8_t *err)
{
	return bus2_write(b, id, addr, &v, 1, true, err);
}

int bus2_write_u16(struct bus *b, uint8_t id, uint16_t addr, uint16_t v, uint8_t *err)
{
	uint8_t raw[2];
	dxl_put_u16(raw, v);
	return bus2_write(b, id, addr, raw, 2, true, err);
}

int bus2_write_u32(struct bus *b, uint8_t id, uint16_t addr, uint32_t v, uint8_t *err)
{
	uint8_t raw[4];
	dxl2_put_u32(raw, v);
	return bus2_write(b, id, addr, raw, 4, true, err);
}

int bus2_reg_write(struct bus *b, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply,
                   uint8_t *err)
{
	return bus2_addr_data(b, id, DXL2_INST_REG_WRITE, addr, data, n, expect_reply, err);
}

int bus2_action(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err)
{
	return bus2_transact(b, id, DXL2_INST_ACTION, NULL, 0, expect_reply ? 0 : -1, err);
}

int bus2_reboot(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err)
{
	return bus2_transact(b, id, DXL2_INST_REBOOT, NULL, 0, expect_reply ? 0 : -1, err);
}

int bus2_clear_multi_turn(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err)
{
	/* CLEAR option 1 and its fixed key (dxl2.h) */
	static const uint8_t params[5] = { 0x01, 0x44, 0x58, 0x4C, 0x22 };
	return bus2_transact(b, id, DXL2_INST_CLEAR, params, sizeof params, expect_reply ? 0 : -1, err);
}

int bus2_factory_reset(struct bus *b, uint8_t id, uint8_t option, bool expect_reply, uint8_t *err)
{
	uint8_t probe[DXL2_MAX_PACKET];
	/* the encoder's rules (options, never broadcast + reset all) first */
	int n = dxl2_encode_factory_reset(probe, sizeof probe, id, option);
	if (n < 0)
		return n;
	return bus2_transact(b, id, DXL2_INST_FACTORY_RESET, &option, 1, expect_reply ? 0 : -1, err);
}

static int bus2_multi_wait(struct bus *b, int begun)
{
	if (begun < 0)
		return begun;
	return bus_wait_done(b, NULL);
}

int bus2_sync_read(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n, struct bus_multi *m)
{
	int r = bus2_check(b);
	return r < 0 ? r : bus2_multi_wait(b, bus_sync_read_begin(b, addr, len, ids, n, m));
}

int bus2_bulk_read(struct bus *b, const struct dxl2_bulk_item *items, size_t n, struct bus_multi *m)
{
	int r = bus2_check(b);
	return r < 0 ? r : bus2_multi_wait(b, bus_bulk_read_begin(b, items, n, m));
}

int bus2_sync_write(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, const uint8_t *data, size_t n)
{
	uint8_t pkt[DXL2_MAX_PACKET];
	int r = bus2_check(b);
	if (r < 0)
		return r;
	r = dxl2_encode_sync_write(pkt, sizeof pkt, addr, len, ids, data, n);
	return r < 0 ? r : bus_send_raw(b, pkt, (size_t)r);
}

int bus2_bulk_write(struct bus *b, const struct dxl2_bulk_item *items, size_t n)
{
	uint8_t pkt[DXL2_MAX_PACKET];
	int r = bus2_check(b);
	if (r < 0)
		return r;
	r = dxl2_encode_bulk_write(pkt, sizeof pkt, items, n);
	return r < 0 ? r : bus_send_raw(b, pkt, (size_t)r);
}
