/*
 * dxl.c — Dynamixel Protocol 1.0 framing: encoders, checksum, the resumable
 * byte-fed parser and the names of errors. Pure code: no I/O, no clock, no
 * allocation; every buffer belongs to the caller.
 */
#include "dxl.h"
#include "dxl_lex.h"

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

/* Bytes around the parameters: FF FF ID LEN INSTR ... CHK. */
#define DXL_OVERHEAD 6
/* Header bytes that always start a packet. */
#define DXL_LEAD 0xFF

const char *dxl_instruction_name(uint8_t instr)
{
	switch (instr) {
	case DXL_INST_PING:          return "PING";
	case DXL_INST_READ:          return "READ";
	case DXL_INST_WRITE:         return "WRITE";
	case DXL_INST_REG_WRITE:     return "REG_WRITE";
	case DXL_INST_ACTION:        return "ACTION";
	case DXL_INST_FACTORY_RESET: return "FACTORY_RESET";
	case DXL_INST_REBOOT:        return "REBOOT";
	case DXL_INST_SYNC_WRITE:    return "SYNC_WRITE";
	case DXL_INST_BULK_READ:     return "BULK_READ";
	default:                     return "UNKNOWN";
	}
}

const char *dxl_errbit_name(uint8_t bit)
{
	switch (bit) {
	case DXL_ERRBIT_VOLTAGE:     return "input voltage";
	case DXL_ERRBIT_ANGLE_LIMIT: return "angle limit";
	case DXL_ERRBIT_OVERHEAT:    return "overheating";
	case DXL_ERRBIT_RANGE:       return "range";
	case DXL_ERRBIT_CHECKSUM:    return "checksum";
	case DXL_ERRBIT_OVERLOAD:    return "overload";
	case DXL_ERRBIT_INSTRUCTION: return "instruction";
	default:                     return NULL;
	}
}

char *dxl_bits_format(uint8_t bits, const char *(*name_of)(uint8_t bit), char *buf, size_t cap)
{
	if (buf == NULL || cap == 0)
		return buf;
	buf[0] = '\0';
	if (bits == 0) {
		snprintf(buf, cap, "none");
		return buf;
	}
	size_t off = 0;
	for (unsigned i = 0; i < 8; i++) {
		uint8_t bit = (uint8_t)(1u << i);
		if (!(bits & bit))
			continue;
		const char *name = name_of(bit);
		/* a bit no servo sends (1.0's bit 7): show it rather than hide it */
		int w = name ? snprintf(buf + off, cap - off, "%s%s", off ? "|" : "", name)
		             : snprintf(buf + off, cap - off, "%sbit%u", off ? "|" : "", i);
		if (w < 0 || (size_t)w >= cap - off)
			break; /* truncated: buf stays terminated */
		off += (size_t)w;
	}
	return buf;
}

char *dxl_errbits_format(uint8_t bits, char *buf, size_t cap)
{
	return dxl_bits_format(bits, dxl_errbit_name, buf, cap);
}

const char *dxl_strerror(int status)
{
	switch (status) {
	case DXL_OK:             return "success";
	case DXL_E_ARG:          return "invalid argument";
	case DXL_E_BUFFER:       return "buffer too small or packet too long";
	case DXL_E_CHECKSUM:     return "bad checksum in received packet";
	case DXL_E_HEADER:       return "invalid packet header (resynchronised)";
	case DXL_E_TIMEOUT:      return "no reply (timeout)";
	case DXL_E_WRONG_ID:     return "reply from an unexpected ID";
	case DXL_E_WRONG_LENGTH: return "reply with an unexpected length";
	case DXL_E_IO:           return "port I/O error";
	case DXL_E_DISCONNECTED: return "port disconnected";
	case DXL_E_BUSY:         return "a transaction is already pending";
	case DXL_E_ECHO:         return "echoed bytes differ from those sent";
	case DXL_E_UNSUPPORTED:  return "not supported";
	case DXL_E_STUFFING:     return "byte stuffing violated in received packet (cut short?)";
	default:                 return "unknown error";
	}
}

/* ---- encoding ------------------------------------------------------------- */

uint8_t dxl_checksum(const uint8_t *from_id, size_t n)
{
	unsigned sum = 0;
	for (size_t i = 0; i < n; i++)
		sum += from_id[i];
	return (uint8_t)(~sum & 0xFFu);
}

/* A packet of nparams parameters: its header into buf (the parameters go at
 * buf + 5, written by the caller), or why it does not fit. */
static int dxl_frame_begin(uint8_t *buf, size_t cap, uint8_t id, uint8_t code, size_t nparams)
{
	if (nparams > DXL_MAX_TX_PARAMS || cap < nparams + DXL_OVERHEAD)
		return DXL_E_BUFFER;
	buf[0] = DXL_LEAD;
	buf[1] = DXL_LEAD;
	buf[2] = id;
	buf[3] = (uint8_t)(nparams + 2);
	buf[4] = code;
	return DXL_OK;
}

/* Its checksum after the parameters; the packet's length. */
static int dxl_frame_end(uint8_t *buf, size_t nparams)
{
	buf[5 + nparams] = dxl_checksum(buf + 2, nparams + 3);
	return (int)(nparams + DXL_OVERHEAD);
}

/* Frame `code` and the parameters (given as up to two pieces, so encoders can
 * prepend an address without a scratch buffer). */
static int dxl_frame(uint8_t *buf, size_t cap, uint8_t id, uint8_t code, const uint8_t *head,
                     size_t nhead, const uint8_t *tail, size_t ntail)
{
	size_t nparams = nhead + ntail;
	if (buf == NULL || (nhead && head == NULL) || (ntail && tail == NULL))
		return DXL_E_ARG;
	int r = dxl_frame_begin(buf, cap, id, code, nparams);
	if (r != DXL_OK)
		return r;
	if (nhead)
		memcpy(buf + 5, head, nhead);
	if (ntail)
		memcpy(buf + 5 + nhead, tail, ntail);
	return dxl_frame_end(buf, nparams);
}

int dxl_encode_instruction(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr,
                           const uint8_t *params, size_t nparams)
{
	if (id > DXL_BROADCAST_ID)
		return DXL_E_ARG;
	return dxl_frame(buf, cap, id, instr, params, nparams, NULL, 0);
}

int dxl_encode_ping(uint8_t *buf, size_t cap, uint8_t id)
{
	return dxl_encode_instruction(buf, cap, id, DXL_INST_PING, NULL, 0);
}

int dxl_encode_read(uint8_t *buf, size_t cap, uint8_t id, uint8_t addr, uint8_t len)
{
	/* the reply must fit a status packet too */
	if (len == 0 || len > DXL_MAX_PARAMS)
		return DXL_E_ARG;
	const uint8_t params[2] = { addr, len };
	return dxl_encode_instruction(buf, cap, id, DXL_INST_READ, params, sizeof params);
}

static int dxl_encode_addr_data(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr, uint8_t addr,
                                const uint8_t *data, size_t n)
{
	if (id > DXL_BROADCAST_ID || n == 0 || data == NULL)
		return DXL_E_ARG;
	return dxl_frame(buf, cap, id, instr, &addr, 1, data, n);
}

int dxl_encode_write(uint8_t *buf, size_t cap, uint8_t id, uint8_t addr,
                     const uint8_t *data, size_t n)
{
	return dxl_encode_addr_data(buf, cap, id, DXL_INST_WRITE, addr, data, n);
}

int dxl_encode_reg_write(uint8_t *buf, size_t cap, uint8_t id, uint8_t addr,
                         const uint8_t *data, size_t n)
{
	return dxl_encode_addr_data(buf, cap, id, DXL_INST_REG_WRITE, addr, data, n);
}

int dxl_encode_action(uint8_t *buf, size_t cap, uint8_t id)
{
	return dxl_encode_instruction(buf, cap, id, DXL_INST_ACTION, NULL, 0);
}

int dxl_encode_factory_reset(uint8_t *buf, size_t cap, uint8_t id)
{
	return dxl_encode_instruction(buf, cap, id, DXL_INST_FACTORY_RESET, NULL, 0);
}

int dxl_encode_sync_write(uint8_t *buf, size_t cap, uint8_t addr, uint8_t len,
                          const uint8_t *ids, const uint8_t *data, size_t n)
{
	if (buf == NULL || ids == NULL || data == NULL || len == 0 || n == 0)
		return DXL_E_ARG;
	/* params: addr, L, then (ID + L bytes) per servo */
	size_t nparams = 2 + n * ((size_t)len + 1);
	if (nparams > DXL_MAX_TX_PARAMS || cap < nparams + DXL_OVERHEAD)
		return DXL_E_BUFFER;
	for (size_t i = 0; i < n; i++)
		if (ids[i] > DXL_MAX_ID)
			return DXL_E_ARG;
	(void)dxl_frame_begin(buf, cap, DXL_BROADCAST_ID, DXL_INST_SYNC_WRITE, nparams);
	buf[5] = addr;
	buf[6] = len;
	uint8_t *p = buf + 7;
	for (size_t i = 0; i < n; i++) {
		*p++ = ids[i];
		memcpy(p, data + i * len, len);
		p += len;
	}
	return dxl_frame_end(buf, nparams);
}

int dxl_encode_bulk_read(uint8_t *buf, size_t cap, const struct dxl_bulk_item *items, size_t n)
{
	if (buf == NULL || items == NULL || n == 0)
		return DXL_E_ARG;
	/* params: 0x00, then (L, ID, addr) per item (MX manual order) */
	size_t nparams = 1 + 3 * n;
	if (nparams > DXL_MAX_TX_PARAMS || cap < nparams + DXL_OVERHEAD)
		return DXL_E_BUFFER;
	for (size_t i = 0; i < n; i++)
		if (items[i].id > DXL_MAX_ID || items[i].len == 0)
			return DXL_E_ARG;
	(void)dxl_frame_begin(buf, cap, DXL_BROADCAST_ID, DXL_INST_BULK_READ, nparams);
	buf[5] = 0x00;
	uint8_t *p = buf + 6;
	for (size_t i = 0; i < n; i++) {
		*p++ = items[i].len;
		*p++ = items[i].id;
		*p++ = items[i].addr;
	}
	return dxl_frame_end(buf, nparams);
}

int dxl_encode_status(uint8_t *buf, size_t cap, uint8_t id, uint8_t err,
                      const uint8_t *params, size_t nparams)
{
	if (id > DXL_MAX_ID || err > DXL_ERRBIT_MASK)
		return DXL_E_ARG;
	return dxl_frame(buf, cap, id, err, params, nparams, NULL, 0);
}

/* ---- parsing ----------------------------------------------------------------
 * The parser appends one byte at a time to its buffer and rescans the buffer
 * after each, so a packet is reported the moment its last byte arrives and
 * *used never runs past it. On any doubt it drops the first buffered byte and
 * rescans (gpsd's rule: on an unexpected byte, go back to the start state). */

void dxl_parser_init(struct dxl_parser *p, enum dxl_parse_kind kind)
{
	memset(p, 0, sizeof *p);
	p->kind = kind;
}

void dxl_parser_reset(struct dxl_parser *p)
{
	p->have = 0;
}

static void dxl_parser_drop(struct dxl_parser *p, size_t n)
{
	dxl_lex_drop(p->buf, &p->have, n);
}

/* A header field is wrong: count it, drop one byte, let the caller rescan. */
static int dxl_parser_reject(struct dxl_parser *p, int why)
{
	if (why == DXL_E_CHECKSUM)
		p->checksum_errors++;
	else
		p->header_errors++;
	p->bytes_dropped++;
	dxl_parser_drop(p, 1);
	return why;
}

static bool dxl_parser_id_ok(const struct dxl_parser *p, uint8_t id)
{
	if (id <= DXL_MAX_ID)
		return true;
	/* instructions may be broadcast; status packets never come from 0xFE */
	return p->kind == DXL_PARSE_INSTRUCTION && id == DXL_BROADCAST_ID;
}

/* Look at what is buffered: DXL_NEED_MORE, DXL_FRAME or a negative error. */
static int dxl_parser_scan(struct dxl_parser *p, struct dxl_packet *out)
{
	for (;;) {
		static const uint8_t lead[2] = { DXL_LEAD, DXL_LEAD };
		if (!dxl_lex_sync(p->buf, &p->have, lead, sizeof lead, &p->bytes_dropped))
			return DXL_NEED_MORE;
		if (p->have < 3)
			return DXL_NEED_MORE;
		if (!dxl_parser_id_ok(p, p->buf[2]))
			return dxl_parser_reject(p, DXL_E_HEADER);
		if (p->have < 4)
			return DXL_NEED_MORE;
		uint8_t len = p->buf[3];
		if (len < DXL_MIN_LEN || len > DXL_MAX_LEN)
			return dxl_parser_reject(p, DXL_E_HEADER);
		if (p->have < 5)
			return DXL_NEED_MORE;
		/* the error byte's bit 7 is always 0: anything else is not a status */
		if (p->kind == DXL_PARSE_STATUS && p->buf[4] > DXL_ERRBIT_MASK)
			return dxl_parser_reject(p, DXL_E_HEADER);
		size_t total = (size_t)len + DXL_HEADER_BYTES;
		if (p->have < total)
			return DXL_NEED_MORE;
		if (dxl_checksum(p->buf + 2, total - 3) != p->buf[total - 1])
			return dxl_parser_reject(p, DXL_E_CHECKSUM);
		out->id = p->buf[2];
		out->code = p->buf[4];
		out->nparams = (uint8_t)(len - 2);
		memcpy(out->params, p->buf + 5, out->nparams);
		p->frames++;
		dxl_parser_drop(p, total);
		return DXL_FRAME;
	}
}

static int dxl_parser_scan_any(void *p, void *out)
{
	return dxl_parser_scan(p, out);
}

int dxl_parser_feed(struct dxl_parser *p, const uint8_t *data, size_t n, size_t *used,
                    struct dxl_packet *out)
{
	struct dxl_packet scratch;
	return dxl_lex_feed(p, p->buf, &p->have, dxl_parser_scan_any, out ? out : &scratch, data, n, used);
}
