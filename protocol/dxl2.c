/*
 * dxl2.c — Dynamixel Protocol 2.0 framing: CRC, byte stuffing, encoders, the
 * resumable byte-fed parser, reply matching and error names. Pure code: no
 * I/O, no clock, no allocation; every buffer belongs to the caller.
 * The rules are the ROBOTIS e-manual's "DYNAMIXEL Protocol 2.0" page; where
 * it leaves a choice open, ROBOTIS's SDK (protocol2_packet_handler.cpp) was
 * read to make the same one, and the comment says so.
 */
#include "dxl2.h"
#include "dxl_lex.h"

#include <stdio.h>
#include <string.h>

/* The header, and the pattern byte stuffing protects. */
#define H1 0xFF
#define H2 0xFF
#define H3 0xFD
#define RESERVED 0x00
/* Offsets in a packet. */
#define OFF_RESERVED 3
#define OFF_ID       4
#define OFF_LEN_L    5
#define OFF_LEN_H    6
#define OFF_INST     7
#define OFF_ERR      8
/* LEN of the shortest packets: INST + CRC, and INST + ERR + CRC; a fast
 * read's status holds at least one part: INST + ERR ID 1 byte + CRC. */
#define MIN_LEN_INSTRUCTION 3
#define MIN_LEN_STATUS      4
#define MIN_LEN_FAST_STATUS 6
/* A fast read's status: header and INST, then per part ERR ID data CRC. */
#define FAST_HEAD_BYTES     (DXL2_HEADER_BYTES + 1)
#define FAST_PART_EXTRA     4
/* CLEAR option 0x01 must carry these four bytes ("DXL\"") to act. */
static const uint8_t clear_multi_turn_params[5] = { 0x01, 0x44, 0x58, 0x4C, 0x22 };

const char *dxl2_instruction_name(uint8_t instr)
{
	switch (instr) {
	case DXL2_INST_PING:          return "PING";
	case DXL2_INST_READ:          return "READ";
	case DXL2_INST_WRITE:         return "WRITE";
	case DXL2_INST_REG_WRITE:     return "REG_WRITE";
	case DXL2_INST_ACTION:        return "ACTION";
	case DXL2_INST_FACTORY_RESET: return "FACTORY_RESET";
	case DXL2_INST_REBOOT:        return "REBOOT";
	case DXL2_INST_CLEAR:         return "CLEAR";
	case DXL2_INST_STATUS:        return "STATUS";
	case DXL2_INST_SYNC_READ:     return "SYNC_READ";
	case DXL2_INST_SYNC_WRITE:    return "SYNC_WRITE";
	case DXL2_INST_BULK_READ:     return "BULK_READ";
	case DXL2_INST_BULK_WRITE:    return "BULK_WRITE";
	case DXL2_INST_FAST_SYNC_READ: return "FAST_SYNC_READ";
	case DXL2_INST_FAST_BULK_READ: return "FAST_BULK_READ";
	default:                      return "UNKNOWN";
	}
}

const char *dxl2_error_name(uint8_t number)
{
	switch (number) {
	case DXL2_ERRNUM_RESULT_FAIL: return "result fail";
	case DXL2_ERRNUM_INSTRUCTION: return "instruction";
	case DXL2_ERRNUM_CRC:         return "crc";
	case DXL2_ERRNUM_DATA_RANGE:  return "data range";
	case DXL2_ERRNUM_DATA_LENGTH: return "data length";
	case DXL2_ERRNUM_DATA_LIMIT:  return "data limit";
	case DXL2_ERRNUM_ACCESS:      return "access";
	default:                      return NULL;
	}
}

char *dxl2_err_format(uint8_t err, char *buf, size_t cap)
{
	if (buf == NULL || cap == 0)
		return buf;
	uint8_t num = dxl2_err_number(err);
	const char *alert = dxl2_err_alert(err) ? "alert" : "";
	const char *sep = (dxl2_err_alert(err) && num) ? "|" : "";
	const char *name = dxl2_error_name(num);
	if (err == 0)
		snprintf(buf, cap, "none");
	else if (num == 0)
		snprintf(buf, cap, "%s", alert);
	else if (name)
		snprintf(buf, cap, "%s%s%s", alert, sep, name);
	else /* a number the manual does not define: show it rather than hide it */
		snprintf(buf, cap, "%s%serror %u", alert, sep, num);
	return buf;
}

/* ---- CRC ------------------------------------------------------------------
 * CRC-16, polynomial x^16 + x^15 + x^2 + 1 (0x8005), MSB first, initial value
 * 0, no final XOR: the e-manual's "CRC Calculation" page prints this table
 * and the byte-wise update below. The test checks every entry against a
 * bit-by-bit division. */
const uint16_t dxl2_crc_table[256] = {
	0x0000, 0x8005, 0x800F, 0x000A, 0x801B, 0x001E, 0x0014, 0x8011,
	0x8033, 0x0036, 0x003C, 0x8039, 0x0028, 0x802D, 0x8027, 0x0022,
	0x8063, 0x0066, 0x006C, 0x8069, 0x0078, 0x807D, 0x8077, 0x0072,
	0x0050, 0x8055, 0x805F, 0x005A, 0x804B, 0x004E, 0x0044, 0x8041,
	0x80C3, 0x00C6, 0x00CC, 0x80C9, 0x00D8, 0x80DD, 0x80D7, 0x00D2,
	0x00F0, 0x80F5, 0x80FF, 0x00FA, 0x80EB, 0x00EE, 0x00E4, 0x80E1,
	0x00A0, 0x80A5, 0x80AF, 0x00AA, 0x80BB, 0x00BE, 0x00B4, 0x80B1,
	0x8093, 0x0096, 0x009C, 0x8099, 0x0088, 0x808D, 0x8087, 0x0082,
	0x8183, 0x0186, 0x018C, 0x8189, 0x0198, 0x819D, 0x8197, 0x0192,
	0x01B0, 0x81B5, 0x81BF, 0x01BA, 0x81AB, 0x01AE, 0x01A4, 0x81A1,
	0x01E0, 0x81E5, 0x81EF, 0x01EA, 0x81FB, 0x01FE, 0x01F4, 0x81F1,
	0x81D3, 0x01D6, 0x01DC, 0x81D9, 0x01C8, 0x81CD, 0x81C7, 0x01C2,
	0x0140, 0x8145, 0x814F, 0x014A, 0x815B, 0x015E, 0x0154, 0x8151,
	0x8173, 0x0176, 0x017C, 0x8179, 0x0168, 0x816D, 0x8167, 0x0162,
	0x8123, 0x0126, 0x012C, 0x8129, 0x0138, 0x813D, 0x8137, 0x0132,
	0x0110, 0x8115, 0x811F, 0x011A, 0x810B, 0x010E, 0x0104, 0x8101,
	0x8303, 0x0306, 0x030C, 0x8309, 0x0318, 0x831D, 0x8317, 0x0312,
	0x0330, 0x8335, 0x833F, 0x033A, 0x832B, 0x032E, 0x0324, 0x8321,
	0x0360, 0x8365, 0x836F, 0x036A, 0x837B, 0x037E, 0x0374, 0x8371,
	0x8353, 0x0356, 0x035C, 0x8359, 0x0348, 0x834D, 0x8347, 0x0342,
	0x03C0, 0x83C5, 0x83CF, 0x03CA, 0x83DB, 0x03DE, 0x03D4, 0x83D1,
	0x83F3, 0x03F6, 0x03FC, 0x83F9, 0x03E8, 0x83ED, 0x83E7, 0x03E2,
	0x83A3, 0x03A6, 0x03AC, 0x83A9, 0x03B8, 0x83BD, 0x83B7, 0x03B2,
	0x0390, 0x8395, 0x839F, 0x039A, 0x838B, 0x038E, 0x0384, 0x8381,
	0x0280, 0x8285, 0x828F, 0x028A, 0x829B, 0x029E, 0x0294, 0x8291,
	0x82B3, 0x02B6, 0x02BC, 0x82B9, 0x02A8, 0x82AD, 0x82A7, 0x02A2,
	0x82E3, 0x02E6, 0x02EC, 0x82E9, 0x02F8, 0x82FD, 0x82F7, 0x02F2,
	0x02D0, 0x82D5, 0x82DF, 0x02DA, 0x82CB, 0x02CE, 0x02C4, 0x82C1,
	0x8243, 0x0246, 0x024C, 0x8249, 0x0258, 0x825D, 0x8257, 0x0252,
	0x0270, 0x8275, 0x827F, 0x027A, 0x826B, 0x026E, 0x0264, 0x8261,
	0x0220, 0x8225, 0x822F, 0x022A, 0x823B, 0x023E, 0x0234, 0x8231,
	0x8213, 0x0216, 0x021C, 0x8219, 0x0208, 0x820D, 0x8207, 0x0202,
};

uint16_t dxl2_crc_update(uint16_t crc, const uint8_t *data, size_t n)
{
	for (size_t i = 0; i < n; i++)
		crc = (uint16_t)((crc << 8) ^ dxl2_crc_table[((crc >> 8) ^ data[i]) & 0xFF]);
	return crc;
}

/* ---- encoding ---------------------------------------------------------------
 * A body (INST to the last parameter) is emitted byte by byte through
 * `out_byte`, which stuffs. Each encoder runs its emitter twice: once to count
 * the stuffed size (nothing is written until it is known to fit), once to
 * write. */
struct dxl2_out {
	uint8_t *buf;      /* NULL while counting */
	size_t n;          /* bytes so far, header included */
	uint8_t prev1, prev2;  /* the last two bytes before stuffing */
};

static void out_byte(struct dxl2_out *o, uint8_t b)
{
	if (o->buf)
		o->buf[o->n] = b;
	o->n++;
	/* e-manual: "when the pattern FF FF FD appears, add a 0xFD". The pattern
	 * is looked for in the bytes as given, as ROBOTIS's SDK does: after
	 * FF FF FD FD the next FD is preceded by FF FD and is not stuffed. */
	if (o->prev2 == H1 && o->prev1 == H2 && b == H3) {
		if (o->buf)
			o->buf[o->n] = H3;
		o->n++;
	}
	o->prev2 = o->prev1;
	o->prev1 = b;
}

static void out_bytes(struct dxl2_out *o, const uint8_t *p, size_t n)
{
	for (size_t i = 0; i < n; i++)
		out_byte(o, p[i]);
}

static void out_u16(struct dxl2_out *o, uint16_t v)
{
	out_byte(o, (uint8_t)(v & 0xFF));
	out_byte(o, (uint8_t)(v >> 8));
}

/* What an encoder emits after INST. */
struct dxl2_body {
	const uint8_t *head;   /* a few fixed parameters (address, length, ERR) */
	size_t nhead;
	const uint8_t *tail;   /* then the caller's data */
	size_t ntail;
	/* or, for the multi-servo instructions: */
	void (*emit)(struct dxl2_out *o, const void *args);
	const void *args;
};

static void emit_body(struct dxl2_out *o, uint8_t instr, const struct dxl2_body *b)
{
	out_byte(o, instr);
	if (b->emit) {
		b->emit(o, b->args);
		return;
	}
	out_bytes(o, b->head, b->nhead);
	out_bytes(o, b->tail, b->ntail);
}

static int dxl2_frame(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr, const struct dxl2_body *b)
{
	if (buf == NULL)
		return DXL_E_ARG;
	/* The length bytes precede INST; they are never FF FF (LEN < 0xFF00),
	 * so the stuffing context starts empty. */
	struct dxl2_out o = { NULL, DXL2_HEADER_BYTES, 0, 0 };
	emit_body(&o, instr, b);
	size_t total = o.n + DXL2_CRC_BYTES;
	if (total > DXL2_MAX_PACKET || total > cap)
		return DXL_E_BUFFER;
	size_t len = total - DXL2_HEADER_BYTES;
	buf[0] = H1;
	buf[1] = H2;
	buf[2] = H3;
	buf[OFF_RESERVED] = RESERVED;
	buf[OFF_ID] = id;
	buf[OFF_LEN_L] = (uint8_t)(len & 0xFF);
	buf[OFF_LEN_H] = (uint8_t)(len >> 8);
	o = (struct dxl2_out){ buf, DXL2_HEADER_BYTES, 0, 0 };
	emit_body(&o, instr, b);
	uint16_t crc = dxl2_crc_update(0, buf, o.n);
	buf[o.n] = (uint8_t)(crc & 0xFF);
	buf[o.n + 1] = (uint8_t)(crc >> 8);
	return (int)total;
}

static bool dxl2_instruction_id_ok(uint8_t id)
{
	return id <= DXL2_MAX_ID || id == DXL2_BROADCAST_ID;
}

/* Instruction with up to two pieces of parameters. */
static int dxl2_encode_pieces(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr,
                              const uint8_t *head, size_t nhead, const uint8_t *tail, size_t ntail)
{
	if (!dxl2_instruction_id_ok(id) || instr == DXL2_INST_STATUS)
		return DXL_E_ARG;
	if ((nhead && head == NULL) || (ntail && tail == NULL))
		return DXL_E_ARG;
	/* refuse before counting: size_t sums of huge n must not wrap */
	if (nhead + ntail > DXL2_MAX_PARAMS || ntail > DXL2_MAX_PARAMS)
		return DXL_E_BUFFER;
	const struct dxl2_body b = { head, nhead, tail, ntail, NULL, NULL };
	return dxl2_frame(buf, cap, id, instr, &b);
}

int dxl2_encode_instruction(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr,
                            const uint8_t *params, size_t nparams)
{
	return dxl2_encode_pieces(buf, cap, id, instr, params, nparams, NULL, 0);
}

int dxl2_encode_ping(uint8_t *buf, size_t cap, uint8_t id)
{
	return dxl2_encode_pieces(buf, cap, id, DXL2_INST_PING, NULL, 0, NULL, 0);
}

static bool dxl2_read_len_ok(uint16_t len)
{
	return len >= 1 && len <= DXL2_MAX_READ_LEN;
}

int dxl2_encode_read(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr, uint16_t len)
{
	if (!dxl2_read_len_ok(len))
		return DXL_E_ARG;
	const uint8_t p[4] = { (uint8_t)addr, (uint8_t)(addr >> 8), (uint8_t)len, (uint8_t)(len >> 8) };
	return dxl2_encode_pieces(buf, cap, id, DXL2_INST_READ, p, sizeof p, NULL, 0);
}

static int dxl2_encode_addr_data(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr, uint16_t addr,
                                 const uint8_t *data, size_t n)
{
	if (n == 0 || data == NULL)
		return DXL_E_ARG;
	const uint8_t a[2] = { (uint8_t)addr, (uint8_t)(addr >> 8) };
	return dxl2_encode_pieces(buf, cap, id, instr, a, sizeof a, data, n);
}

int dxl2_encode_write(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr,
                      const uint8_t *data, size_t n)
{
	return dxl2_encode_addr_data(buf, cap, id, DXL2_INST_WRITE, addr, data, n);
}

int dxl2_encode_reg_write(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr,
                          const uint8_t *data, size_t n)
{
	return dxl2_encode_addr_data(buf, cap, id, DXL2_INST_REG_WRITE, addr, data, n);
}

int dxl2_encode_action(uint8_t *buf, size_t cap, uint8_t id)
{
	return dxl2_encode_pieces(buf, cap, id, DXL2_INST_ACTION, NULL, 0, NULL, 0);
}

int dxl2_encode_factory_reset(uint8_t *buf, size_t cap, uint8_t id, uint8_t option)
{
	if (option != DXL2_RESET_ALL && option != DXL2_RESET_KEEP_ID && option != DXL2_RESET_KEEP_ID_BAUD)
		return DXL_E_ARG;
	/* e-manual: broadcast + reset all is ignored by the servo (FW 42+) and
	 * would reset every servo to ID 1 on older firmware: never send it */
	if (id == DXL2_BROADCAST_ID && option == DXL2_RESET_ALL)
		return DXL_E_ARG;
	return dxl2_encode_pieces(buf, cap, id, DXL2_INST_FACTORY_RESET, &option, 1, NULL, 0);
}

int dxl2_encode_reboot(uint8_t *buf, size_t cap, uint8_t id)
{
	return dxl2_encode_pieces(buf, cap, id, DXL2_INST_REBOOT, NULL, 0, NULL, 0);
}

int dxl2_encode_clear_multi_turn(uint8_t *buf, size_t cap, uint8_t id)
{
	return dxl2_encode_pieces(buf, cap, id, DXL2_INST_CLEAR, clear_multi_turn_params,
	                          sizeof clear_multi_turn_params, NULL, 0);
}

/* Servo IDs of a multi-servo instruction: each a servo's (0-252), none twice. */
static bool dxl2_ids_ok(const uint8_t *ids, size_t n)
{
	bool seen[DXL2_MAX_ID + 1] = { false };
	if (ids == NULL || n == 0 || n > DXL2_MULTI_MAX)
		return false;
	for (size_t i = 0; i < n; i++) {
		if (ids[i] > DXL2_MAX_ID || seen[ids[i]])
			return false;
		seen[ids[i]] = true;
	}
	return true;
}

int dxl2_encode_sync_read(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len,
                          const uint8_t *ids, size_t n)
{
	if (!dxl2_read_len_ok(len) || !dxl2_ids_ok(ids, n))
		return DXL_E_ARG;
	const uint8_t p[4] = { (uint8_t)addr, (uint8_t)(addr >> 8), (uint8_t)len, (uint8_t)(len >> 8) };
	return dxl2_encode_pieces(buf, cap, DXL2_BROADCAST_ID, DXL2_INST_SYNC_READ, p, sizeof p, ids, n);
}

size_t dxl2_fast_status_bytes(const uint16_t *lens, size_t n)
{
	size_t bytes = FAST_HEAD_BYTES;
	for (size_t i = 0; lens != NULL && i < n; i++)
		bytes += (size_t)lens[i] + FAST_PART_EXTRA;
	return bytes;
}

int dxl2_encode_fast_sync_read(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len,
                               const uint8_t *ids, size_t n)
{
	if (!dxl2_read_len_ok(len) || !dxl2_ids_ok(ids, n))
		return DXL_E_ARG;
	/* n <= 253, len <= 759: no overflow */
	if (FAST_HEAD_BYTES + n * ((size_t)len + FAST_PART_EXTRA) > DXL2_MAX_PACKET)
		return DXL_E_ARG;   /* the one reply could not be received */
	const uint8_t p[4] = { (uint8_t)addr, (uint8_t)(addr >> 8), (uint8_t)len, (uint8_t)(len >> 8) };
	return dxl2_encode_pieces(buf, cap, DXL2_BROADCAST_ID, DXL2_INST_FAST_SYNC_READ, p, sizeof p, ids, n);
}

struct sync_write_args {
	uint16_t addr, len;
	const uint8_t *ids, *data;
	size_t n;
};

static void emit_sync_write(struct dxl2_out *o, const void *args)
{
	const struct sync_write_args *a = args;
	out_u16(o, a->addr);
	out_u16(o, a->len);
	for (size_t i = 0; i < a->n; i++) {
		out_byte(o, a->ids[i]);
		out_bytes(o, a->data + i * a->len, a->len);
	}
}

int dxl2_encode_sync_write(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len,
                           const uint8_t *ids, const uint8_t *data, size_t n)
{
	if (len == 0 || data == NULL || !dxl2_ids_ok(ids, n))
		return DXL_E_ARG;
	/* n <= 253 and len < 65536: the count below cannot wrap */
	if (n * ((size_t)len + 1) > DXL2_MAX_PARAMS)
		return DXL_E_BUFFER;
	const struct sync_write_args a = { addr, len, ids, data, n };
	const struct dxl2_body b = { NULL, 0, NULL, 0, emit_sync_write, &a };
	return dxl2_frame(buf, cap, DXL2_BROADCAST_ID, DXL2_INST_SYNC_WRITE, &b);
}

struct bulk_args {
	const struct dxl2_bulk_item *items;
	size_t n;
	bool write;
};

static void emit_bulk(struct dxl2_out *o, const void *args)
{
	const struct bulk_args *a = args;
	for (size_t i = 0; i < a->n; i++) {
		const struct dxl2_bulk_item *it = &a->items[i];
		out_byte(o, it->id);
		out_u16(o, it->addr);
		out_u16(o, it->len);
		if (a->write)
			out_bytes(o, it->data, it->len);
	}
}

static int dxl2_encode_bulk(uint8_t *buf, size_t cap, const struct dxl2_bulk_item *items, size_t n,
                            uint8_t instr)
{
	bool write = instr == DXL2_INST_BULK_WRITE;
	size_t reply = FAST_HEAD_BYTES;
	uint8_t ids[DXL2_MULTI_MAX];
	size_t bytes = 0;
	if (items == NULL || n == 0 || n > DXL2_MULTI_MAX)
		return DXL_E_ARG;
	for (size_t i = 0; i < n; i++) {
		ids[i] = items[i].id;
		if (write ? (items[i].len == 0 || items[i].data == NULL) : !dxl2_read_len_ok(items[i].len))
			return DXL_E_ARG;
		bytes += 5 + (write ? items[i].len : 0);
		reply += (size_t)items[i].len + FAST_PART_EXTRA;
	}
	if (instr == DXL2_INST_FAST_BULK_READ && reply > DXL2_MAX_PACKET)
		return DXL_E_ARG;   /* the one reply could not be received */
	/* e-manual: "the same ID cannot be used multiple times" */
	if (!dxl2_ids_ok(ids, n))
		return DXL_E_ARG;
	if (bytes > DXL2_MAX_PARAMS)
		return DXL_E_BUFFER;
	const struct bulk_args a = { items, n, write };
	const struct dxl2_body b = { NULL, 0, NULL, 0, emit_bulk, &a };
	return dxl2_frame(buf, cap, DXL2_BROADCAST_ID, instr, &b);
}

int dxl2_encode_bulk_read(uint8_t *buf, size_t cap, const struct dxl2_bulk_item *items, size_t n)
{
	return dxl2_encode_bulk(buf, cap, items, n, DXL2_INST_BULK_READ);
}

int dxl2_encode_fast_bulk_read(uint8_t *buf, size_t cap, const struct dxl2_bulk_item *items, size_t n)
{
	return dxl2_encode_bulk(buf, cap, items, n, DXL2_INST_FAST_BULK_READ);
}

int dxl2_encode_bulk_write(uint8_t *buf, size_t cap, const struct dxl2_bulk_item *items, size_t n)
{
	return dxl2_encode_bulk(buf, cap, items, n, DXL2_INST_BULK_WRITE);
}

/* The fast status is never stuffed: written byte by byte, each part's CRC
 * continuing over everything before it. */
static int dxl2_fast_parts_ok(const struct dxl2_fast_part *parts, size_t n, size_t *total)
{
	uint8_t ids[DXL2_MULTI_MAX];
	if (parts == NULL || n == 0 || n > DXL2_MULTI_MAX)
		return DXL_E_ARG;
	*total = FAST_HEAD_BYTES;
	for (size_t i = 0; i < n; i++) {
		if (parts[i].len == 0 || parts[i].data == NULL)
			return DXL_E_ARG;
		ids[i] = parts[i].id;
		*total += (size_t)parts[i].len + FAST_PART_EXTRA;
	}
	return dxl2_ids_ok(ids, n) ? DXL_OK : DXL_E_ARG;
}

int dxl2_encode_fast_status(uint8_t *buf, size_t cap, const struct dxl2_fast_part *parts, size_t n,
                            size_t *ends)
{
	size_t total = 0;
	int r = dxl2_fast_parts_ok(parts, n, &total);
	if (r != DXL_OK || buf == NULL)
		return DXL_E_ARG;
	if (total > DXL2_MAX_PACKET || total > cap)
		return DXL_E_BUFFER;
	size_t len = total - DXL2_HEADER_BYTES, at = 0;
	const uint8_t head[FAST_HEAD_BYTES] = { H1, H2, H3, RESERVED, DXL2_BROADCAST_ID, (uint8_t)(len & 0xFF),
		                                (uint8_t)(len >> 8), DXL2_INST_STATUS };
	memcpy(buf, head, sizeof head);
	at = sizeof head;
	for (size_t i = 0; i < n; i++) {
		buf[at++] = parts[i].err;
		buf[at++] = parts[i].id;
		memcpy(buf + at, parts[i].data, parts[i].len);
		at += parts[i].len;
		uint16_t crc = dxl2_crc_update(0, buf, at);
		buf[at++] = (uint8_t)(crc & 0xFF);
		buf[at++] = (uint8_t)(crc >> 8);
		if (ends)
			ends[i] = at;
	}
	return (int)total;
}

int dxl2_encode_status(uint8_t *buf, size_t cap, uint8_t id, uint8_t err,
                       const uint8_t *params, size_t nparams)
{
	if (id > DXL2_MAX_ID || (nparams && params == NULL))
		return DXL_E_ARG;
	if (nparams > DXL2_MAX_PARAMS)
		return DXL_E_BUFFER;
	const struct dxl2_body b = { &err, 1, params, nparams, NULL, NULL };
	return dxl2_frame(buf, cap, id, DXL2_INST_STATUS, &b);
}

size_t dxl2_status_bytes_max(size_t nparams)
{
	/* body = 55 ERR params; FF FF FD cannot overlap itself, so at most one
	 * stuffed byte for every three body bytes */
	size_t body = 2 + nparams;
	return DXL2_HEADER_BYTES + body + body / 3 + DXL2_CRC_BYTES;
}

/* ---- parsing ------------------------------------------------------------------
 * As 1.0's parser: append one byte, rescan the buffer, report a packet the
 * moment its last byte arrives; on any doubt drop the first byte and rescan. */

void dxl2_parser_init(struct dxl2_parser *p, enum dxl2_parse_kind kind)
{
	memset(p, 0, sizeof *p);
	p->kind = kind;
}

void dxl2_parser_reset(struct dxl2_parser *p)
{
	p->have = 0;
	p->checked = 0;
}

void dxl2_parser_expect_fast(struct dxl2_parser *p, bool on)
{
	p->fast = on && p->kind == DXL2_PARSE_STATUS;
}

static void dxl2_parser_drop(struct dxl2_parser *p, size_t n)
{
	dxl_lex_drop(p->buf, &p->have, n);
	p->checked = 0;  /* a new candidate starts at buf[0] */
}

static int dxl2_parser_reject(struct dxl2_parser *p, int why)
{
	if (why == DXL_E_CHECKSUM)
		p->checksum_errors++;
	else if (why == DXL_E_STUFFING)
		p->stuffing_errors++;
	else
		p->header_errors++;
	p->bytes_dropped++;
	dxl2_parser_drop(p, 1);
	return why;
}

static bool dxl2_parser_id_ok(const struct dxl2_parser *p, uint8_t id)
{
	if (id <= DXL2_MAX_ID)
		return true;
	/* instructions may be broadcast; a status from 0xFE is a fast read's */
	return id == DXL2_BROADCAST_ID && (p->kind == DXL2_PARSE_INSTRUCTION || p->fast);
}

/* A status from 0xFE: the servos' shared reply to a fast read. */
static bool dxl2_parser_fast(const struct dxl2_parser *p)
{
	return p->kind == DXL2_PARSE_STATUS && p->buf[OFF_ID] == DXL2_BROADCAST_ID;
}

/* The shortest LEN the packet's kind allows. */
static size_t dxl2_parser_min_len(const struct dxl2_parser *p)
{
	if (p->kind == DXL2_PARSE_INSTRUCTION)
		return MIN_LEN_INSTRUCTION;
	return dxl2_parser_fast(p) ? MIN_LEN_FAST_STATUS : MIN_LEN_STATUS;
}

static bool is_pattern(const uint8_t *b, size_t j)
{
	return b[j - 2] == H1 && b[j - 1] == H2 && b[j] == H3;
}

/* The buffered body bytes [checked, min(have, body_end)) obey the stuffing
 * rule: every FF FF FD is followed by FD inside the body. DXL_OK,
 * DXL_NEED_MORE-style waiting is expressed by leaving `checked` at the
 * pattern until its next byte arrives. */
static int dxl2_parser_check_stuffing(struct dxl2_parser *p, size_t body_end)
{
	size_t j = p->checked > OFF_INST ? p->checked : OFF_INST;
	size_t end = p->have < body_end ? p->have : body_end;
	for (; j < end; j++) {
		if (!is_pattern(p->buf, j))
			continue;
		if (j + 1 >= body_end)
			return DXL_E_STUFFING;   /* the body ends in an unstuffed FD */
		if (j + 1 >= p->have)
			break;                   /* decide when the next byte comes */
		if (p->buf[j + 1] != H3)
			return DXL_E_STUFFING;   /* a header inside the packet */
		j++;                         /* the stuffed FD starts no pattern */
	}
	p->checked = j;
	return DXL_OK;
}

/* Body [OFF_INST, body_end) without stuffing into out; false if it does not
 * hold the fields its kind needs. */
static bool dxl2_parser_unstuff(const struct dxl2_parser *p, size_t body_end, struct dxl2_packet *out)
{
	uint8_t *dst = out->params;
	size_t n = 0;
	uint8_t first[2] = { 0, 0 };
	size_t nfirst = p->kind == DXL2_PARSE_STATUS ? 2 : 1;  /* INST (+ ERR) */
	bool stuffed = !dxl2_parser_fast(p);
	for (size_t j = OFF_INST; j < body_end; j++) {
		uint8_t b = p->buf[j];
		if (stuffed && is_pattern(p->buf, j))
			j++;  /* checked already: the next byte is the stuffed FD */
		if (n < nfirst)
			first[n] = b;
		else
			dst[n - nfirst] = b;
		n++;
	}
	if (n < nfirst)
		return false;
	out->instr = first[0];
	out->err = p->kind == DXL2_PARSE_STATUS ? first[1] : 0;
	out->nparams = (uint16_t)(n - nfirst);
	return true;
}

static int dxl2_parser_scan(struct dxl2_parser *p, struct dxl2_packet *out)
{
	for (;;) {
		static const uint8_t lead[3] = { H1, H2, H3 };
		const uint8_t *b = p->buf;
		size_t had = p->have;
		bool synced = dxl_lex_sync(p->buf, &p->have, lead, sizeof lead, &p->bytes_dropped);
		if (p->have != had)
			p->checked = 0;  /* a new candidate starts at buf[0] */
		if (!synced || p->have <= OFF_RESERVED)
			return DXL_NEED_MORE;
		if (b[OFF_RESERVED] == H3) {
			/* FF FF FD FD: stuffed data of a packet we came into in the
			 * middle — the manual says to ignore it when looking for a header */
			p->bytes_dropped++;
			dxl2_parser_drop(p, 1);
			continue;
		}
		if (b[OFF_RESERVED] != RESERVED)
			return dxl2_parser_reject(p, DXL_E_HEADER);
		if (p->have <= OFF_ID)
			return DXL_NEED_MORE;
		if (!dxl2_parser_id_ok(p, b[OFF_ID]))
			return dxl2_parser_reject(p, DXL_E_HEADER);
		if (p->have <= OFF_LEN_H)
			return DXL_NEED_MORE;
		size_t len = (size_t)b[OFF_LEN_L] | ((size_t)b[OFF_LEN_H] << 8);
		if (len < dxl2_parser_min_len(p) || len > DXL2_MAX_LEN)
			return dxl2_parser_reject(p, DXL_E_HEADER);
		if (p->have <= OFF_INST)
			return DXL_NEED_MORE;
		bool status = b[OFF_INST] == DXL2_INST_STATUS;
		if (status != (p->kind == DXL2_PARSE_STATUS))
			return dxl2_parser_reject(p, DXL_E_HEADER);
		size_t total = DXL2_HEADER_BYTES + len;
		size_t body_end = total - DXL2_CRC_BYTES;
		int r = dxl2_parser_fast(p) ? DXL_OK : dxl2_parser_check_stuffing(p, body_end);
		if (r != DXL_OK)
			return dxl2_parser_reject(p, r);
		if (p->have < total)
			return DXL_NEED_MORE;
		uint16_t crc = (uint16_t)(b[body_end] | (b[body_end + 1] << 8));
		if (dxl2_crc_update(0, b, body_end) != crc)
			return dxl2_parser_reject(p, DXL_E_CHECKSUM);
		if (!dxl2_parser_unstuff(p, body_end, out))
			return dxl2_parser_reject(p, DXL_E_HEADER);
		out->id = b[OFF_ID];
		out->wire_bytes = (uint16_t)total;
		p->frames++;
		dxl2_parser_drop(p, total);
		return DXL_FRAME;
	}
}

static int dxl2_parser_scan_any(void *p, void *out)
{
	return dxl2_parser_scan(p, out);
}

int dxl2_parser_feed(struct dxl2_parser *p, const uint8_t *data, size_t n, size_t *used,
                     struct dxl2_packet *out)
{
	struct dxl2_packet scratch;
	return dxl_lex_feed(p, p->buf, &p->have, dxl2_parser_scan_any, out ? out : &scratch, data, n, used);
}

/* ---- matching replies ------------------------------------------------------ */

int dxl2_check_reply(const struct dxl2_packet *pkt, uint8_t req_id, uint16_t expect_params)
{
	if (pkt == NULL)
		return DXL_E_ARG;
	if (pkt->id != req_id)
		return DXL_E_WRONG_ID;
	if (pkt->nparams != expect_params)
		return DXL_E_WRONG_LENGTH;
	return DXL_OK;
}

static void dxl2_multi_clear(struct dxl2_multi_read *m)
{
	m->n = m->answered = m->next = 0;
	m->out_of_order = 0;
}

int dxl2_multi_read_sync(struct dxl2_multi_read *m, uint16_t len, const uint8_t *ids, size_t n)
{
	if (m == NULL || !dxl2_read_len_ok(len) || !dxl2_ids_ok(ids, n))
		return DXL_E_ARG;
	dxl2_multi_clear(m);
	for (size_t i = 0; i < n; i++) {
		m->ids[i] = ids[i];
		m->len[i] = len;
		m->got[i] = false;
	}
	m->n = n;
	return DXL_OK;
}

int dxl2_multi_read_bulk(struct dxl2_multi_read *m, const struct dxl2_bulk_item *items, size_t n)
{
	uint8_t ids[DXL2_MULTI_MAX];
	if (m == NULL || items == NULL || n == 0 || n > DXL2_MULTI_MAX)
		return DXL_E_ARG;
	for (size_t i = 0; i < n; i++) {
		if (!dxl2_read_len_ok(items[i].len))
			return DXL_E_ARG;
		ids[i] = items[i].id;
	}
	if (!dxl2_ids_ok(ids, n))
		return DXL_E_ARG;
	dxl2_multi_clear(m);
	for (size_t i = 0; i < n; i++) {
		m->ids[i] = items[i].id;
		m->len[i] = items[i].len;
		m->got[i] = false;
	}
	m->n = n;
	return DXL_OK;
}

int dxl2_multi_read_accept(struct dxl2_multi_read *m, const struct dxl2_packet *pkt, size_t *slot)
{
	if (pkt == NULL)
		return DXL_E_ARG;
	return dxl2_multi_read_take(m, pkt->id, pkt->nparams, slot);
}

int dxl2_multi_read_take(struct dxl2_multi_read *m, uint8_t id, uint16_t nparams, size_t *slot)
{
	if (m == NULL)
		return DXL_E_ARG;
	size_t i = 0;
	while (i < m->n && m->ids[i] != id)
		i++;
	if (i == m->n || m->got[i])
		return DXL_E_WRONG_ID;
	if (nparams != m->len[i])
		return DXL_E_WRONG_LENGTH;
	if (i != m->next)
		m->out_of_order++;
	m->got[i] = true;
	m->answered++;
	while (m->next < m->n && m->got[m->next])
		m->next++;
	if (slot)
		*slot = i;
	return DXL_OK;
}

/* The header a fast status of nparams parameters (after its first ERR)
 * began with: the parts' CRCs start from it. */
static uint16_t dxl2_fast_head_crc(const struct dxl2_packet *pkt)
{
	size_t len = 1u + 1u + pkt->nparams + DXL2_CRC_BYTES;  /* INST ERR params CRC */
	const uint8_t head[FAST_HEAD_BYTES + 1] = { H1, H2, H3, RESERVED, DXL2_BROADCAST_ID, (uint8_t)(len & 0xFF),
		                                    (uint8_t)(len >> 8), DXL2_INST_STATUS, pkt->err };
	return dxl2_crc_update(0, head, sizeof head);
}

int dxl2_fast_status_split(const struct dxl2_packet *pkt, const struct dxl2_multi_read *m,
                           struct dxl2_fast_part *parts, size_t *good)
{
	size_t ok = 0, at = 0, want = 0;
	if (good)
		*good = 0;
	if (pkt == NULL || m == NULL || parts == NULL || m->n == 0)
		return DXL_E_ARG;
	if (pkt->id != DXL2_BROADCAST_ID || pkt->instr != DXL2_INST_STATUS)
		return DXL_E_WRONG_ID;
	for (size_t i = 0; i < m->n; i++)
		want += (size_t)m->len[i] + FAST_PART_EXTRA;
	/* the first ERR is the packet's err, the last CRC the parser's */
	if (pkt->nparams + 3u != want)
		return DXL_E_WRONG_LENGTH;
	uint16_t crc = dxl2_fast_head_crc(pkt);
	int r = DXL_OK;
	for (size_t i = 0; i < m->n; i++) {
		const uint8_t *p = pkt->params;
		uint8_t err = pkt->err;
		if (i > 0) {
			err = p[at];
			crc = dxl2_crc_update(crc, p + at, 1);
			at++;
		}
		parts[i] = (struct dxl2_fast_part){ p[at], err, m->len[i], p + at + 1 };
		crc = dxl2_crc_update(crc, p + at, 1u + m->len[i]);
		at += 1u + m->len[i];
		if (parts[i].id != m->ids[i]) {
			r = DXL_E_WRONG_ID;
			break;
		}
		if (i + 1 < m->n) {
			if ((uint16_t)(p[at] | (p[at + 1] << 8)) != crc) {
				r = DXL_E_CHECKSUM;
				break;
			}
			crc = dxl2_crc_update(crc, p + at, DXL2_CRC_BYTES);
			at += DXL2_CRC_BYTES;
		}
		ok++;
	}
	if (good)
		*good = ok;
	return r;
}

size_t dxl2_multi_read_missing(const struct dxl2_multi_read *m, uint8_t *ids, size_t cap)
{
	size_t missing = 0;
	if (m == NULL)
		return 0;
	for (size_t i = 0; i < m->n; i++) {
		if (m->got[i])
			continue;
		if (ids && missing < cap)
			ids[missing] = m->ids[i];
		missing++;
	}
	return missing;
}
