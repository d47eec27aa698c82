/*
 * dxl_proto.c — Protocol 1.0 and 2.0 as tables (dxl_proto.h). Each entry is
 * the protocol's own function from dxl.c or dxl2.c, or a few lines fitting
 * it to the table's shape: 16-bit addresses, one frame type. Pure code.
 */
#include "dxl_proto.h"

#include <string.h>

/* ---- Protocol 1.0 ------------------------------------------------------------ */

/* Bytes around a 1.0 packet's parameters: FF FF ID LEN ERR ... CHK. */
#define V1_OVERHEAD 6
/* The 8-bit fields of a 1.0 READ, WRITE and SYNC_WRITE. */
#define V1_FIELD_MAX 0xFFu

static size_t v1_status_bytes(size_t nparams)
{
	return nparams + V1_OVERHEAD;
}

static int v1_instr_replies(uint8_t instr)
{
	/* SYNC_WRITE is always broadcast */
	return instr == DXL_INST_SYNC_WRITE ? -1 : 0;
}

static int v1_encode_read(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr, uint16_t len)
{
	if (addr > V1_FIELD_MAX || len > V1_FIELD_MAX)
		return DXL_E_ARG;
	return dxl_encode_read(buf, cap, id, (uint8_t)addr, (uint8_t)len);
}

static int v1_encode_write(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr, const uint8_t *data, size_t n)
{
	return addr > V1_FIELD_MAX ? DXL_E_ARG : dxl_encode_write(buf, cap, id, (uint8_t)addr, data, n);
}

static int v1_encode_reg_write(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr, const uint8_t *data,
                               size_t n)
{
	return addr > V1_FIELD_MAX ? DXL_E_ARG : dxl_encode_reg_write(buf, cap, id, (uint8_t)addr, data, n);
}

static int v1_encode_factory_reset(uint8_t *buf, size_t cap, uint8_t id, uint8_t option)
{
	/* 1.0's FACTORY_RESET has no option: it resets everything, ID included */
	return option != DXL_RESET_ALL ? DXL_E_ARG : dxl_encode_factory_reset(buf, cap, id);
}

static int v1_encode_sync_write(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len, const uint8_t *ids,
                                const uint8_t *data, size_t n)
{
	if (addr > V1_FIELD_MAX || len > V1_FIELD_MAX)
		return DXL_E_ARG;
	return dxl_encode_sync_write(buf, cap, (uint8_t)addr, (uint8_t)len, ids, data, n);
}

static void v1_parser_init(union dxl_proto_parser *p, bool instructions)
{
	dxl_parser_init(&p->v1, instructions ? DXL_PARSE_INSTRUCTION : DXL_PARSE_STATUS);
}

static void v1_parser_reset(union dxl_proto_parser *p)
{
	dxl_parser_reset(&p->v1);
}

static int v1_parser_feed(union dxl_proto_parser *p, const uint8_t *data, size_t n, size_t *used,
                          struct dxl_frame *out)
{
	struct dxl_packet pkt;
	int r = dxl_parser_feed(&p->v1, data, n, used, &pkt);
	if (r != DXL_FRAME || out == NULL)
		return r;
	bool status = p->v1.kind == DXL_PARSE_STATUS;
	out->id = pkt.id;
	out->instr = status ? 0 : pkt.code;
	out->err = status ? pkt.code : 0;
	out->nparams = pkt.nparams;
	out->wire_bytes = (uint16_t)(pkt.nparams + V1_OVERHEAD);
	memcpy(out->params, pkt.params, pkt.nparams);
	return r;
}

static void v1_parser_counts(const union dxl_proto_parser *p, struct dxl_parser_counts *out)
{
	*out = (struct dxl_parser_counts){ p->v1.frames, p->v1.checksum_errors, p->v1.header_errors, 0,
	                                   p->v1.bytes_dropped, p->v1.have };
}

/* FF FF ID LEN INSTR ... CHK, LEN counting from INSTR to CHK. */
static bool v1_damaged_packet(const uint8_t *h, size_t n, uint8_t *id, uint8_t *instr)
{
	for (size_t p = n >= 6 ? n - 6 + 1 : 0; p-- > 0;) {
		if (h[p] != 0xFF || h[p + 1] != 0xFF || p + 4 >= n)
			continue;
		if ((size_t)h[p + 3] + 4 != n - p)
			continue;
		*id = h[p + 2];
		*instr = h[p + 4];
		return true;
	}
	return false;
}

/* 1.0 servos answer a broadcast PING all at once (they collide). */
static int v1_reply_order(const struct dxl_frame *req, uint8_t id)
{
	(void)req;
	(void)id;
	return -1;
}

/* The AX-12, the 1.0 servo driven here, has no REBOOT, SYNC_READ or
 * BULK_READ (ax12.md): the MX series' REBOOT and BULK_READ are left out
 * until a 1.0 servo that has them is driven. */
const struct dxl_proto dxl_proto_v1 = {
	.name = "1.0",
	.number = 1,
	.caps = 0,
	.max_id = DXL_MAX_ID,
	.broadcast_id = DXL_BROADCAST_ID,
	.max_packet = DXL_MAX_PACKET,
	.max_params = DXL_MAX_PARAMS,
	.max_read_len = DXL_MAX_PARAMS,
	.addr_bytes = 1,
	.ping_reply_params = 0,
	.ping_round_trip_bytes = 2 * V1_OVERHEAD,
	.err_alert = 0,
	.echo_reads_as_status = true,
	.status_bytes_max = v1_status_bytes,
	.instr_replies = v1_instr_replies,
	.encode_instruction = dxl_encode_instruction,
	.encode_ping = dxl_encode_ping,
	.encode_read = v1_encode_read,
	.encode_write = v1_encode_write,
	.encode_reg_write = v1_encode_reg_write,
	.encode_action = dxl_encode_action,
	.encode_factory_reset = v1_encode_factory_reset,
	.encode_sync_write = v1_encode_sync_write,
	.encode_status = dxl_encode_status,
	.parser_init = v1_parser_init,
	.parser_reset = v1_parser_reset,
	.parser_feed = v1_parser_feed,
	.parser_counts = v1_parser_counts,
	.damaged_packet = v1_damaged_packet,
	.reply_order = v1_reply_order,
	.check_name = "checksum",
	.instruction_name = dxl_instruction_name,
	.err_format = dxl_errbits_format,
};

/* ---- Protocol 2.0 ------------------------------------------------------------ */

/* A PING (10 bytes) and its reply with model number and firmware (14). */
#define V2_PING_ROUND_TRIP 24

static int v2_instr_replies(uint8_t instr)
{
	switch (instr) {
	case DXL2_INST_SYNC_READ:
	case DXL2_INST_BULK_READ:
	case DXL2_INST_FAST_SYNC_READ:
	case DXL2_INST_FAST_BULK_READ:
		return DXL_E_ARG;
	case DXL2_INST_SYNC_WRITE:
	case DXL2_INST_BULK_WRITE:
		return -1;
	default:
		return 0;
	}
}

static int v2_encode_bulk(uint8_t *buf, size_t cap, const struct dxl_item *items, size_t n, uint8_t instr)
{
	struct dxl2_bulk_item v2[DXL2_MULTI_MAX];
	if (items == NULL || n == 0 || n > DXL2_MULTI_MAX)
		return DXL_E_ARG;
	for (size_t i = 0; i < n; i++)
		v2[i] = (struct dxl2_bulk_item){ items[i].id, items[i].addr, items[i].len, items[i].data };
	if (instr == DXL2_INST_BULK_WRITE)
		return dxl2_encode_bulk_write(buf, cap, v2, n);
	if (instr == DXL2_INST_FAST_BULK_READ)
		return dxl2_encode_fast_bulk_read(buf, cap, v2, n);
	return dxl2_encode_bulk_read(buf, cap, v2, n);
}

static int v2_encode_bulk_read(uint8_t *buf, size_t cap, const struct dxl_item *items, size_t n)
{
	return v2_encode_bulk(buf, cap, items, n, DXL2_INST_BULK_READ);
}

static int v2_encode_fast_bulk_read(uint8_t *buf, size_t cap, const struct dxl_item *items, size_t n)
{
	return v2_encode_bulk(buf, cap, items, n, DXL2_INST_FAST_BULK_READ);
}

static int v2_encode_bulk_write(uint8_t *buf, size_t cap, const struct dxl_item *items, size_t n)
{
	return v2_encode_bulk(buf, cap, items, n, DXL2_INST_BULK_WRITE);
}

static void v2_parser_init(union dxl_proto_parser *p, bool instructions)
{
	dxl2_parser_init(&p->v2, instructions ? DXL2_PARSE_INSTRUCTION : DXL2_PARSE_STATUS);
}

static void v2_parser_reset(union dxl_proto_parser *p)
{
	dxl2_parser_reset(&p->v2);
}

static int v2_parser_feed(union dxl_proto_parser *p, const uint8_t *data, size_t n, size_t *used,
                          struct dxl_frame *out)
{
	struct dxl2_packet pkt;
	int r = dxl2_parser_feed(&p->v2, data, n, used, &pkt);
	if (r != DXL_FRAME || out == NULL)
		return r;
	out->id = pkt.id;
	out->instr = pkt.instr;
	out->err = pkt.err;
	out->nparams = pkt.nparams;
	out->wire_bytes = pkt.wire_bytes;
	memcpy(out->params, pkt.params, pkt.nparams);
	return r;
}

static void v2_parser_expect_fast(union dxl_proto_parser *p, bool on)
{
	dxl2_parser_expect_fast(&p->v2, on);
}

static void v2_parser_counts(const union dxl_proto_parser *p, struct dxl_parser_counts *out)
{
	*out = (struct dxl_parser_counts){ p->v2.frames, p->v2.checksum_errors, p->v2.header_errors,
	                                   p->v2.stuffing_errors, p->v2.bytes_dropped, p->v2.have };
}

/* FF FF FD 00 ID LEN_L LEN_H INSTR ..., LEN counting from INSTR to the CRC. */
static bool v2_damaged_packet(const uint8_t *bytes, size_t n, uint8_t *id, uint8_t *instr)
{
	for (size_t p = n >= 10 ? n - 9 : 0; p-- > 0;) {
		const uint8_t *h = &bytes[p];
		if (h[0] != 0xFF || h[1] != 0xFF || h[2] != 0xFD || h[3] != 0x00)
			continue;
		size_t len = (size_t)h[5] | ((size_t)h[6] << 8);
		if (p + DXL2_HEADER_BYTES + len != n)
			continue;
		*id = h[4];
		*instr = h[7];
		return true;
	}
	return false;
}

/* SYNC_READ and BULK_READ (and their fast forms' parts) are answered in the order the request lists the
 * servos, a broadcast PING in the order of their IDs (e-manual, Protocol
 * 2.0): a servo's slot in the list, or its ID. */
static int v2_reply_order(const struct dxl_frame *req, uint8_t id)
{
	if (req->instr == DXL2_INST_SYNC_READ || req->instr == DXL2_INST_FAST_SYNC_READ) {
		for (size_t k = 4; k < req->nparams; k++)
			if (req->params[k] == id)
				return (int)k;
	} else if (req->instr == DXL2_INST_BULK_READ || req->instr == DXL2_INST_FAST_BULK_READ) {
		for (size_t k = 0; k + 5 <= req->nparams; k += 5)
			if (req->params[k] == id)
				return (int)k;
	} else if (req->instr != DXL2_INST_PING || req->id != DXL2_BROADCAST_ID) {
		return -1;
	}
	return id;
}

const struct dxl_proto dxl_proto_v2 = {
	.name = "2.0",
	.number = 2,
	.caps = DXL_CAP_SYNC_READ | DXL_CAP_BULK_READ | DXL_CAP_BULK_WRITE | DXL_CAP_REBOOT | DXL_CAP_CLEAR |
	        DXL_CAP_PING_MODEL | DXL_CAP_BROADCAST_PING | DXL_CAP_RESET_OPTIONS | DXL_CAP_FAST_READ,
	.max_id = DXL2_MAX_ID,
	.broadcast_id = DXL2_BROADCAST_ID,
	.max_packet = DXL2_MAX_PACKET,
	.max_params = DXL2_MAX_PARAMS,
	.max_read_len = DXL2_MAX_READ_LEN,
	.addr_bytes = 2,
	.ping_reply_params = 3,
	.ping_round_trip_bytes = V2_PING_ROUND_TRIP,
	.err_alert = DXL2_ERR_ALERT,
	.echo_reads_as_status = false,
	.status_bytes_max = dxl2_status_bytes_max,
	.instr_replies = v2_instr_replies,
	.encode_instruction = dxl2_encode_instruction,
	.encode_ping = dxl2_encode_ping,
	.encode_read = dxl2_encode_read,
	.encode_write = dxl2_encode_write,
	.encode_reg_write = dxl2_encode_reg_write,
	.encode_action = dxl2_encode_action,
	.encode_factory_reset = dxl2_encode_factory_reset,
	.encode_reboot = dxl2_encode_reboot,
	.encode_clear_multi_turn = dxl2_encode_clear_multi_turn,
	.encode_sync_write = dxl2_encode_sync_write,
	.encode_sync_read = dxl2_encode_sync_read,
	.encode_bulk_read = v2_encode_bulk_read,
	.encode_bulk_write = v2_encode_bulk_write,
	.encode_fast_sync_read = dxl2_encode_fast_sync_read,
	.encode_fast_bulk_read = v2_encode_fast_bulk_read,
	.encode_status = dxl2_encode_status,
	.parser_init = v2_parser_init,
	.parser_reset = v2_parser_reset,
	.parser_feed = v2_parser_feed,
	.parser_counts = v2_parser_counts,
	.parser_expect_fast = v2_parser_expect_fast,
	.damaged_packet = v2_damaged_packet,
	.reply_order = v2_reply_order,
	.check_name = "CRC",
	.instruction_name = dxl2_instruction_name,
	.err_format = dxl2_err_format,
};

const struct dxl_proto *dxl_proto_by_number(int number)
{
	switch (number) {
	case 1: return &dxl_proto_v1;
	case 2: return &dxl_proto_v2;
	default: return NULL;
	}
}

void dxl_frame_to_packet2(const struct dxl_frame *f, struct dxl2_packet *out)
{
	out->id = f->id;
	out->instr = f->instr;
	out->err = f->err;
	out->nparams = f->nparams;
	out->wire_bytes = f->wire_bytes;
	memcpy(out->params, f->params, f->nparams);
}
