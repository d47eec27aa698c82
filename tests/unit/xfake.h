/*
 * xfake.h — a fake bus of X-series servos (Protocol 2.0) for tests, whatever
 * carries its bytes: test_dxl_fakeservo.c serves it on a pty from a thread,
 * test_daemon_cycle.c in memory against a fake clock. The transport feeds
 * it the controller's bytes (xfake_feed) and takes its status packets
 * through `emit`, with the servo's return delay to apply.
 *
 * It frames packets with its own few lines: a bit-by-bit CRC-16 (polynomial
 * 0x8005), its own stuffing and unstuffing — not protocol/dxl2.c — checked
 * against the e-manual's packets (test_dxl_fakeservo.c), so a bug shared by
 * our encoder and parser cannot pass through it unseen. Its control table
 * is dxl2_table's defaults; what a real servo refuses (EEPROM with torque
 * on: access error 7; torque on after a shutdown: result fail 1) it refuses
 * too. It answers PING, READ, WRITE, FACTORY_RESET, REBOOT (a boot: RAM to
 * its defaults), SYNC_READ (each listed servo in the list's order) and
 * SYNC_WRITE; it hears only at its own baud rate when line_baud is set.
 * The indirect areas: a READ of Indirect Data n gives the byte Indirect
 * Address n holds (one level), and the Indirect Address registers are
 * refused with torque on, as EEPROM; a servo may have none (no_indirect:
 * 148.. refused) or keep one slot at its factory value (ind_stuck).
 * Header-only (static inline, as busfake.h): a helper .c would be linked
 * into every unit test, also those that do not link the protocol library.
 */
#ifndef UNDULATE_XFAKE_H
#define UNDULATE_XFAKE_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "dxl2.h"
#include "dxl2_table.h"

#define XFAKE_MAX_SERVOS 8
#define XFAKE_TABLE DXL2_X_TABLE_SIZE
#define XFAKE_RX_MAX 2048
#define XFAKE_FIRMWARE 46

struct xfake_servo {
	uint8_t mem[XFAKE_TABLE];
	uint8_t err;                 /* forced into every status (fault injection) */
	uint8_t hwerr_after_reboot;  /* hardware error status a REBOOT leaves (a cause still there) */
	bool powered;                /* false: hears nothing */
	bool refuse_writes;          /* every write refused (access error), nothing written */
	unsigned drive_parts;        /* SYNC_WRITE parts naming it with a non-zero Goal PWM or Current */
	bool no_indirect;            /* no indirect areas: 148.. answers the access error */
	int ind_stuck;               /* 1..56: that Indirect Address keeps its value, the write acknowledged */
};

struct xfake {
	struct xfake_servo servo[XFAKE_MAX_SERVOS];
	size_t nservos;
	uint8_t rx[XFAKE_RX_MAX];
	size_t have;
	long line_baud;              /* the rate the controller set; 0: heard at any */
	/* every status packet, and the return delay the servo waits before it */
	void (*emit)(void *ctx, const uint8_t *pkt, size_t n, unsigned delay_us);
	void *ctx;
	/* the alert bit (7) in every status while Hardware Error Status (70) is
	 * not 0, as the e-manual has it (off: test_dxl_fakeservo.c's X fake, which
	 * injects the ERR field itself) */
	bool alert_from_hwerr;
	/* every WRITE and SYNC_WRITE part addressed to a servo that hears, before
	 * the servo judges it (NULL: none): what the controller sent, not what
	 * the servo took */
	void (*on_write)(void *ctx, const struct xfake_servo *s, uint16_t addr, size_t len);
	atomic_uint packets;         /* well-formed instruction packets heard */
	atomic_uint writes;          /* WRITEs executed (SYNC_WRITE parts too) */
	atomic_uint reboots;
	atomic_uint sync_reads, sync_writes;
	atomic_uint fast_reads;      /* Fast Sync Reads heard (firmware or not) */
};

static inline uint16_t xfake_crc(const uint8_t *p, size_t n)
{
	uint16_t crc = 0;
	for (size_t i = 0; i < n; i++) {
		crc ^= (uint16_t)(p[i] << 8);
		for (int b = 0; b < 8; b++)
			crc = (uint16_t)((crc & 0x8000) ? (crc << 1) ^ 0x8005 : crc << 1);
	}
	return crc;
}

static inline void xfake_put(uint8_t *m, uint16_t addr, uint32_t v, int size)
{
	for (int i = 0; i < size; i++)
		m[addr + i] = (uint8_t)(v >> (8 * i));
}

static inline uint32_t xfake_get(const uint8_t *m, uint16_t addr, int size)
{
	uint32_t v = 0;
	for (int i = 0; i < size; i++)
		v |= (uint32_t)m[addr + i] << (8 * i);
	return v;
}

/* RAM as a boot leaves it (e-manual: the goals where the servo stands, Goal
 * PWM and Goal Current at their limits, torque off, no error, no watchdog). */
static inline void xfake_boot(struct xfake_servo *s)
{
	const struct dxl2_model *m = dxl2_model_by_number((uint16_t)xfake_get(s->mem, 0, 2));
	for (size_t i = 0; m != NULL && i < m->nregs; i++)
		if (m->regs[i].has_default && m->regs[i].addr >= DXL2_X_EEPROM_END)
			xfake_put(s->mem, m->regs[i].addr, (uint32_t)m->regs[i].def, m->regs[i].size);
	s->mem[64] = 0;
	s->mem[70] = 0;
	s->mem[98] = 0;
	xfake_put(s->mem, 116, xfake_get(s->mem, 132, 4), 4);
	xfake_put(s->mem, 100, xfake_get(s->mem, 36, 2), 2);
	if (dxl2_reg_at(m, 102) != NULL)
		xfake_put(s->mem, 102, xfake_get(s->mem, 38, 2), 2);
}

static inline void xfake_servo_defaults(struct xfake_servo *s, uint8_t id, uint16_t model)
{
	const struct dxl2_model *m = dxl2_model_by_number(model);
	memset(s, 0, sizeof *s);
	s->powered = true;
	for (size_t i = 0; m != NULL && i < m->nregs; i++)
		if (m->regs[i].has_default)
			xfake_put(s->mem, m->regs[i].addr, (uint32_t)m->regs[i].def, m->regs[i].size);
	xfake_put(s->mem, 0, model, 2);
	s->mem[6] = XFAKE_FIRMWARE;
	s->mem[7] = id;
	xfake_put(s->mem, 132, 2048, 4);          /* present position: centre */
	xfake_put(s->mem, 116, 2048, 4);
	xfake_put(s->mem, 128, (uint32_t)-3, 4);  /* present velocity: -3 (0.229 rpm each) */
	xfake_put(s->mem, 144, 120, 2);           /* 12.0 V */
	s->mem[146] = 36;                         /* 36 °C */
}

/* len bytes from addr as a READ answers them: Indirect Data n as the byte
 * Indirect Address n holds (within 64..661), every other byte itself. */
static inline const uint8_t *xfake_view(const struct xfake_servo *s, uint16_t addr, uint16_t len, uint8_t *buf)
{
	for (uint16_t i = 0; i < len; i++) {
		uint16_t a = (uint16_t)(addr + i);
		int n = dxl2_indirect_slot(a);
		uint16_t to = n ? (uint16_t)xfake_get(s->mem, dxl2_indirect_address_reg(n), 2) : a;
		buf[i] = s->mem[to >= DXL2_X_INDIRECT_MIN && to <= DXL2_X_INDIRECT_MAX ? to : a];
	}
	return buf;
}

/* The end of what the servo answers. */
static inline size_t xfake_end(const struct xfake_servo *s)
{
	return s->no_indirect ? DXL2_X_PRESENT_END : XFAKE_TABLE;
}

static inline bool xfake_hears(const struct xfake *fb, const struct xfake_servo *s)
{
	static const long rates[8] = { 9600, 57600, 115200, 1000000, 2000000, 3000000, 4000000, 4500000 };
	long own = s->mem[8] < 8 ? rates[s->mem[8]] : 0;
	long line = fb->line_baud;
	long diff = own > line ? own - line : line - own;
	return s->powered && (line == 0 || (line > 0 && diff * 100 <= own * 3));
}

static inline void xfake_send_status(struct xfake *fb, const struct xfake_servo *s, uint8_t err, const uint8_t *params,
                                     size_t n)
{
	uint8_t pkt[2 * XFAKE_TABLE + 16];
	size_t k = 0;
	pkt[k++] = 0xFF; pkt[k++] = 0xFF; pkt[k++] = 0xFD; pkt[k++] = 0x00;
	pkt[k++] = s->mem[7];
	k += 2;                      /* LEN, once the stuffed body is known */
	uint8_t alert = fb->alert_from_hwerr && s->mem[70] ? 0x80 : 0;
	const uint8_t head[2] = { 0x55, (uint8_t)(err | s->err | alert) };
	for (size_t i = 0; i < n + 2; i++) {
		uint8_t b = i < 2 ? head[i] : params[i - 2];
		pkt[k++] = b;
		if (b == 0xFD && pkt[k - 2] == 0xFF && pkt[k - 3] == 0xFF)
			pkt[k++] = 0xFD;
	}
	size_t len = k - 7 + 2;
	pkt[5] = (uint8_t)len;
	pkt[6] = (uint8_t)(len >> 8);
	uint16_t crc = xfake_crc(pkt, k);
	pkt[k++] = (uint8_t)crc;
	pkt[k++] = (uint8_t)(crc >> 8);
	fb->emit(fb->ctx, pkt, k, s->mem[9] * 2u);
}

/* Level 2 answers everything, 1 PING and READ, 0 PING only. */
static inline void xfake_reply(struct xfake *fb, struct xfake_servo *s, bool broadcast, int level_needed, uint8_t err,
                               const uint8_t *p, size_t n)
{
	if (!broadcast && s->mem[68] >= level_needed)
		xfake_send_status(fb, s, err, p, n);
}

/* A write's error number, nothing written when it is not 0: EEPROM with
 * torque on (access), torque on while a shutdown's error stands (result
 * fail, until REBOOT), outside the table (data length). */
static inline uint8_t xfake_write_error(const struct xfake_servo *s, uint16_t addr, size_t n, const uint8_t *data)
{
	if (addr + n > XFAKE_TABLE)
		return DXL2_ERRNUM_DATA_LENGTH;
	if (s->refuse_writes || addr + n > xfake_end(s))
		return DXL2_ERRNUM_ACCESS;
	if (addr < DXL2_X_EEPROM_END && s->mem[64])
		return DXL2_ERRNUM_ACCESS;
	bool ind_addr = (addr + n > DXL2_X_INDIRECT_ADDRESS_1 && addr < DXL2_X_INDIRECT_DATA_1) ||
	                (addr + n > DXL2_X_INDIRECT_ADDRESS_29 && addr < DXL2_X_INDIRECT_DATA_29);
	if (ind_addr && s->mem[64])
		return DXL2_ERRNUM_ACCESS;
	if (addr <= 64 && addr + n > 64 && data[64 - addr] && (s->mem[70] & s->mem[63]))
		return DXL2_ERRNUM_RESULT_FAIL;
	return 0;
}

static inline void xfake_write(struct xfake *fb, struct xfake_servo *s, const uint8_t *p, size_t n, bool broadcast)
{
	uint16_t addr = (uint16_t)xfake_get(p, 0, 2);
	if (fb->on_write != NULL && n >= 3)
		fb->on_write(fb->ctx, s, addr, n - 2);
	uint8_t err = n < 3 ? DXL2_ERRNUM_DATA_LENGTH : xfake_write_error(s, addr, n - 2, p + 2);
	if (err == 0) {
		uint16_t stuck = dxl2_indirect_address_reg(s->ind_stuck);
		uint8_t keep[2] = { stuck ? s->mem[stuck] : 0, stuck ? s->mem[stuck + 1] : 0 };
		atomic_fetch_add(&fb->writes, 1);
		memcpy(&s->mem[addr], p + 2, n - 2);
		if (stuck)
			memcpy(&s->mem[stuck], keep, 2);
	}
	xfake_reply(fb, s, broadcast, 2, err, NULL, 0);
}

static inline void xfake_reset(struct xfake_servo *s, uint8_t option)
{
	uint8_t id = s->mem[7], baud = s->mem[8];
	uint16_t model = (uint16_t)xfake_get(s->mem, 0, 2);
	xfake_servo_defaults(s, option == DXL2_RESET_ALL ? 1 : id, model);
	if (option == DXL2_RESET_KEEP_ID_BAUD)
		s->mem[8] = baud;
}

static inline void xfake_execute(struct xfake *fb, struct xfake_servo *s, uint8_t instr, const uint8_t *p, size_t n,
                                 bool broadcast)
{
	switch (instr) {   /* PING is the dispatch's: answered at every level */
	case 0x02: { /* READ addr(2) len(2) */
		uint16_t addr = (uint16_t)xfake_get(p, 0, 2), len = (uint16_t)xfake_get(p, 2, 2);
		uint8_t buf[XFAKE_TABLE];
		if (n != 4 || len == 0 || addr + len > XFAKE_TABLE)
			xfake_reply(fb, s, broadcast, 1, DXL2_ERRNUM_DATA_RANGE, NULL, 0);
		else if (addr + len > xfake_end(s))
			xfake_reply(fb, s, broadcast, 1, DXL2_ERRNUM_ACCESS, NULL, 0);
		else
			xfake_reply(fb, s, broadcast, 1, 0, xfake_view(s, addr, len, buf), len);
		break;
	}
	case 0x03:
		xfake_write(fb, s, p, n, broadcast);
		break;
	case 0x06: /* FACTORY_RESET option */
		xfake_reply(fb, s, broadcast, 2, 0, NULL, 0);
		xfake_reset(s, n == 1 ? p[0] : DXL2_RESET_ALL);
		break;
	case 0x08: /* REBOOT: answered, then a boot (RAM defaults), the cause of an error perhaps still there */
		xfake_reply(fb, s, broadcast, 2, 0, NULL, 0);
		atomic_fetch_add(&fb->reboots, 1);
		xfake_boot(s);
		s->mem[70] = s->hwerr_after_reboot;
		break;
	default:
		xfake_reply(fb, s, broadcast, 2, DXL2_ERRNUM_INSTRUCTION, NULL, 0);
		break;
	}
}

static inline struct xfake_servo *xfake_servo_by_id(struct xfake *fb, uint8_t id)
{
	for (size_t i = 0; i < fb->nservos; i++)
		if (fb->servo[i].mem[7] == id)
			return &fb->servo[i];
	return NULL;
}

/* SYNC_READ: addr(2) len(2) IDs — each listed servo answers in the list's
 * order; SYNC_WRITE: addr(2) len(2) (ID, len bytes)... — no status. */
static inline void xfake_sync(struct xfake *fb, uint8_t instr, const uint8_t *p, size_t n)
{
	if (n < 5)
		return;
	uint16_t addr = (uint16_t)xfake_get(p, 0, 2), len = (uint16_t)xfake_get(p, 2, 2);
	size_t stride = instr == 0x83 ? (size_t)len + 1 : 1;
	if (len == 0 || addr + len > XFAKE_TABLE || (n - 4) % stride != 0)
		return;
	atomic_fetch_add(instr == 0x83 ? &fb->sync_writes : &fb->sync_reads, 1);
	for (size_t off = 4; off < n; off += stride) {
		struct xfake_servo *s = xfake_servo_by_id(fb, p[off]);
		if (s == NULL || !xfake_hears(fb, s))
			continue;
		if (instr == 0x83 && (addr == 100 || addr == 102) && len == 2 && (p[off + 1] | p[off + 2]) != 0)
			s->drive_parts++;
		if (instr == 0x83 && fb->on_write != NULL)
			fb->on_write(fb->ctx, s, addr, len);
		if (instr == 0x82) {
			uint8_t buf[XFAKE_TABLE];
			if (s->mem[68] >= 1 && addr + len > xfake_end(s))
				xfake_send_status(fb, s, DXL2_ERRNUM_ACCESS, NULL, 0);
			else if (s->mem[68] >= 1)
				xfake_send_status(fb, s, 0, xfake_view(s, addr, len, buf), len);
		} else if (xfake_write_error(s, addr, len, &p[off + 1]) == 0) {
			atomic_fetch_add(&fb->writes, 1);
			memcpy(&s->mem[addr], &p[off + 1], len);
		}
	}
}

/* FAST_SYNC_READ (0x8A): addr(2) len(2) IDs — ONE status packet from 0xFE
 * (e-manual, Protocol 2.0): the first listed servo sends the header and its
 * part after its return delay, each next one its part, every part ERR ID
 * data CRC, the CRC over every byte before it; never stuffed. Built here on
 * its own (this fake's CRC, not protocol/'s encoder). A servo below
 * firmware 45, silent or not there ends the chain: the packet is cut. */
#define XFAKE_FAST_READ_FIRMWARE 45
static inline void xfake_fast_sync(struct xfake *fb, const uint8_t *p, size_t n)
{
	uint8_t pkt[1024];
	if (n < 5)
		return;
	uint16_t addr = (uint16_t)xfake_get(p, 0, 2), len = (uint16_t)xfake_get(p, 2, 2);
	size_t total = 8 + (n - 4) * ((size_t)len + 4), k = 8;
	if (len == 0 || addr + len > XFAKE_TABLE || total > sizeof pkt)
		return;
	atomic_fetch_add(&fb->fast_reads, 1);
	const uint8_t head[8] = { 0xFF, 0xFF, 0xFD, 0x00, 0xFE, (uint8_t)(total - 7), (uint8_t)((total - 7) >> 8), 0x55 };
	memcpy(pkt, head, sizeof head);
	unsigned delay_us = 0;
	for (size_t off = 4; off < n; off++) {
		struct xfake_servo *s = xfake_servo_by_id(fb, p[off]);
		if (s == NULL || !xfake_hears(fb, s) || s->mem[68] < 1 || s->mem[6] < XFAKE_FAST_READ_FIRMWARE)
			break;
		if (off == 4)
			delay_us = s->mem[9] * 2u;
		uint8_t alert = fb->alert_from_hwerr && s->mem[70] ? 0x80 : 0;
		pkt[k++] = (uint8_t)(s->err | alert);
		pkt[k++] = s->mem[7];
		uint8_t buf[XFAKE_TABLE];
		memcpy(&pkt[k], xfake_view(s, addr, len, buf), len);
		k += len;
		uint16_t crc = xfake_crc(pkt, k);
		pkt[k++] = (uint8_t)crc;
		pkt[k++] = (uint8_t)(crc >> 8);
	}
	if (k > 8)
		fb->emit(fb->ctx, pkt, k, delay_us);
}

static inline void xfake_dispatch(struct xfake *fb, uint8_t id, uint8_t instr, const uint8_t *p, size_t n)
{
	atomic_fetch_add(&fb->packets, 1);
	if (id == 0xFE && (instr == 0x82 || instr == 0x83)) {
		xfake_sync(fb, instr, p, n);
		return;
	}
	if (id == 0xFE && instr == 0x8A) {
		xfake_fast_sync(fb, p, n);
		return;
	}
	/* a broadcast PING is answered by every servo, in ID order */
	for (unsigned want = 0; want <= DXL2_MAX_ID; want++) {
		for (size_t i = 0; i < fb->nservos; i++) {
			struct xfake_servo *s = &fb->servo[i];
			if (s->mem[7] != want || !xfake_hears(fb, s) || (id != s->mem[7] && id != 0xFE))
				continue;
			if (instr == 0x01) {
				const uint8_t pp[3] = { s->mem[0], s->mem[1], s->mem[6] };
				xfake_send_status(fb, s, 0, pp, 3);
			} else {
				xfake_execute(fb, s, instr, p, n, id == 0xFE);
			}
			if (id != 0xFE)
				return;
		}
	}
}

/* Frame what is buffered: FF FF FD 00 ID LEN_L LEN_H INST P.. CRC; on any doubt drop a byte. */
static inline void xfake_parse(struct xfake *fb)
{
	size_t off = 0;
	while (fb->have - off >= 10) {
		const uint8_t *b = fb->rx + off;
		size_t len = (size_t)b[5] | ((size_t)b[6] << 8);
		if (b[0] != 0xFF || b[1] != 0xFF || b[2] != 0xFD || b[3] != 0x00 || len < 3 || len > 1000) {
			off++;
			continue;
		}
		size_t total = 7 + len;
		if (fb->have - off < total)
			break;
		if (xfake_crc(b, total - 2) != (uint16_t)(b[total - 2] | (b[total - 1] << 8))) {
			off++;
			continue;
		}
		uint8_t params[XFAKE_RX_MAX];
		size_t n = 0;
		for (size_t j = 8; j < total - 2; j++) {
			params[n++] = b[j];
			if (b[j] == 0xFD && j >= 2 && b[j - 1] == 0xFF && b[j - 2] == 0xFF)
				j++;   /* the stuffed FD */
		}
		xfake_dispatch(fb, b[4], b[7], params, n);
		off += total;
	}
	memmove(fb->rx, fb->rx + off, fb->have - off);
	fb->have -= off;
}

/* The controller's bytes, as they arrive. */
static inline void xfake_feed(struct xfake *fb, const uint8_t *d, size_t n)
{
	while (n > 0) {
		size_t room = sizeof fb->rx - fb->have, k = n < room ? n : room;
		memcpy(fb->rx + fb->have, d, k);
		fb->have += k;
		d += k;
		n -= k;
		xfake_parse(fb);
		if (fb->have == sizeof fb->rx)
			fb->have = 0;
	}
}

#endif
