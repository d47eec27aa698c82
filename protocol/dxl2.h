/*
 * dxl2.h — Dynamixel Protocol 2.0 framing (X series): pure code, no I/O, no
 * clock, no allocation. It lives beside Protocol 1.0 (dxl.h) and shares its
 * error codes (`enum dxl_status`): a bad CRC is DXL_E_CHECKSUM, a bad header
 * DXL_E_HEADER, a reply from the wrong servo DXL_E_WRONG_ID, as on 1.0.
 *
 * Instruction packet: FF FF FD 00 ID LEN_L LEN_H INST P1..Pn CRC_L CRC_H
 * Status packet:      FF FF FD 00 ID LEN_L LEN_H 55   ERR P1..Pn CRC_L CRC_H
 * LEN counts INST (and ERR), the parameters *after byte stuffing*, and the
 * two CRC bytes. Byte stuffing (e-manual, "Packet Process"): from INST to the
 * last parameter, every FD that follows FF FF gets a second FD, so the header
 * FF FF FD can never appear inside a packet. The CRC is CRC-16 with
 * polynomial 0x8005 (initial value 0, no reflection: "CRC-16/BUYPASS"),
 * computed over every byte from the first FF to the last (stuffed) parameter.
 *
 * The status packet's ERR field is the servo's, and is data (as on 1.0):
 * bit 7 is the alert (read Hardware Error Status, address 70, for the cause),
 * bits 0-6 an error number (result fail, instruction, CRC, data range, data
 * length, data limit, access). A reply with a non-zero ERR is a well-formed
 * reply: the parser delivers it; what to do about it is the caller's choice.
 */
#ifndef UNDULATE_DXL2_H
#define UNDULATE_DXL2_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl.h"

/* IDs (e-manual, Protocol 2.0, "Packet ID"): 0-252 are servos; 253 (FD) and
 * 255 (FF) are never used, so an ID byte can never complete a header. */
#define DXL2_MAX_ID        252
#define DXL2_BROADCAST_ID  0xFE

#define DXL2_HEADER_BYTES  7    /* FF FF FD 00 ID LEN_L LEN_H */
#define DXL2_CRC_BYTES     2
/* The largest packet on the wire, stuffing included. ROBOTIS's SDK uses
 * 1024-byte buffers for Protocol 2.0 (TXPACKET_MAX_LEN/RXPACKET_MAX_LEN); we
 * accept and send nothing larger, so its LEN_H can never be 0xFF and the
 * length bytes can never start a stuffing pattern. */
#define DXL2_MAX_PACKET    1024
#define DXL2_MAX_LEN       (DXL2_MAX_PACKET - DXL2_HEADER_BYTES)
/* Parameters of a decoded packet (unstuffed): INST + params + CRC <= LEN. */
#define DXL2_MAX_PARAMS    (DXL2_MAX_LEN - 3)
/* The longest READ / SYNC_READ / BULK_READ length whose reply fits
 * DXL2_MAX_PACKET however it is stuffed (every 3 bytes of the body may
 * grow to 4: see dxl2_status_bytes_max). */
#define DXL2_MAX_READ_LEN  759

enum dxl2_instruction {
	DXL2_INST_PING          = 0x01,
	DXL2_INST_READ          = 0x02,
	DXL2_INST_WRITE         = 0x03,
	DXL2_INST_REG_WRITE     = 0x04,
	DXL2_INST_ACTION        = 0x05,
	DXL2_INST_FACTORY_RESET = 0x06,
	DXL2_INST_REBOOT        = 0x08,
	DXL2_INST_CLEAR         = 0x10,
	DXL2_INST_STATUS        = 0x55,  /* the INST field of every status packet */
	DXL2_INST_SYNC_READ     = 0x82,
	DXL2_INST_SYNC_WRITE    = 0x83,
	DXL2_INST_FAST_SYNC_READ = 0x8A, /* one status packet for all servos (see below) */
	DXL2_INST_BULK_READ     = 0x92,
	DXL2_INST_BULK_WRITE    = 0x93,
	DXL2_INST_FAST_BULK_READ = 0x9A,
};
/* "SYNC_READ", ..., or "UNKNOWN". */
const char *dxl2_instruction_name(uint8_t instr);

/* FACTORY_RESET's one parameter (e-manual). */
enum dxl2_reset_option {
	DXL2_RESET_ALL             = 0xFF,
	DXL2_RESET_KEEP_ID         = 0x01,
	DXL2_RESET_KEEP_ID_BAUD    = 0x02,
};

/* ---- the status ERR field: the servo's report, data not control flow ------ */
#define DXL2_ERR_ALERT       0x80u  /* a hardware error: see register 70 */
#define DXL2_ERR_NUMBER_MASK 0x7Fu
enum dxl2_error_number {
	DXL2_ERRNUM_NONE        = 0,
	DXL2_ERRNUM_RESULT_FAIL = 1,  /* could not process the instruction */
	DXL2_ERRNUM_INSTRUCTION = 2,  /* undefined instruction, ACTION without REG_WRITE */
	DXL2_ERRNUM_CRC         = 3,  /* the servo saw a bad CRC */
	DXL2_ERRNUM_DATA_RANGE  = 4,  /* value outside the register's min/max */
	DXL2_ERRNUM_DATA_LENGTH = 5,  /* fewer bytes than the register has */
	DXL2_ERRNUM_DATA_LIMIT  = 6,  /* value outside a limit register */
	DXL2_ERRNUM_ACCESS      = 7,  /* read-only/undefined address, EEPROM with torque on */
};
static inline bool dxl2_err_alert(uint8_t err) { return (err & DXL2_ERR_ALERT) != 0; }
static inline uint8_t dxl2_err_number(uint8_t err) { return (uint8_t)(err & DXL2_ERR_NUMBER_MASK); }
/* "data range" for an error number; NULL for 0 and for numbers the manual
 * does not define. */
const char *dxl2_error_name(uint8_t number);
/* The whole ERR field as text: "none", "data range", "alert",
 * "alert|access", "error 9" (undefined number). Returns buf, always
 * terminated when cap > 0. */
char *dxl2_err_format(uint8_t err, char *buf, size_t cap);

/* ---- CRC ------------------------------------------------------------------ */
/* Continue a CRC over n more bytes (start with crc = 0). */
uint16_t dxl2_crc_update(uint16_t crc, const uint8_t *data, size_t n);
/* The 256-entry table of the manual ("CRC Calculation"), for tests. */
extern const uint16_t dxl2_crc_table[256];

/* ---- encoding: into caller-owned buffers ------------------------------------
 * Every encoder stuffs, fills LEN and the CRC, and returns the number of bytes
 * written (> 0) or a negative dxl_status: DXL_E_ARG (an ID out of range, a
 * zero length, an ID listed twice, a bad option) or DXL_E_BUFFER (the stuffed
 * packet exceeds `cap` or DXL2_MAX_PACKET). On error nothing is written. */
/* Any instruction with raw parameters (stuffing applied here). ID 0-252 or
 * broadcast; instr must not be DXL2_INST_STATUS. */
int dxl2_encode_instruction(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr,
                            const uint8_t *params, size_t nparams);
int dxl2_encode_ping(uint8_t *buf, size_t cap, uint8_t id);
/* len 1..DXL2_MAX_READ_LEN */
int dxl2_encode_read(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr, uint16_t len);
int dxl2_encode_write(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr,
                      const uint8_t *data, size_t n);
int dxl2_encode_reg_write(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr,
                          const uint8_t *data, size_t n);
int dxl2_encode_action(uint8_t *buf, size_t cap, uint8_t id);
/* option: enum dxl2_reset_option. The servo ignores broadcast + RESET_ALL
 * (firmware 42 and later); we refuse to encode it. */
int dxl2_encode_factory_reset(uint8_t *buf, size_t cap, uint8_t id, uint8_t option);
int dxl2_encode_reboot(uint8_t *buf, size_t cap, uint8_t id);
/* CLEAR option 0x01: reset the multi-turn Present Position to within one
 * turn (only while the servo stands still; else it answers Result Fail).
 * The only option the manual defines; the fixed key 44 58 4C 22 is added. */
int dxl2_encode_clear_multi_turn(uint8_t *buf, size_t cap, uint8_t id);
/* SYNC_READ of `len` bytes at `addr` from n servos (broadcast). Each servo
 * answers with its own status packet, in the order of ids[]. */
int dxl2_encode_sync_read(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len,
                          const uint8_t *ids, size_t n);
/* SYNC_WRITE: ids[i] gets data[i*len .. i*len+len-1] at addr (broadcast, no reply). */
int dxl2_encode_sync_write(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len,
                           const uint8_t *ids, const uint8_t *data, size_t n);
struct dxl2_bulk_item {
	uint8_t id;
	uint16_t addr, len;
	const uint8_t *data;   /* BULK_WRITE only: len bytes */
};
/* BULK_READ: one status packet per item, in the order of items[]. */
int dxl2_encode_bulk_read(uint8_t *buf, size_t cap, const struct dxl2_bulk_item *items, size_t n);
int dxl2_encode_bulk_write(uint8_t *buf, size_t cap, const struct dxl2_bulk_item *items, size_t n);
/*
 * Fast Sync Read (0x8A) and Fast Bulk Read (0x9A) (e-manual, Protocol 2.0;
 * X430/X540 from firmware 45, not the 2XL/2XC): the request is SYNC_READ's
 * or BULK_READ's with another code, but the servos answer with ONE status
 * packet, from ID 0xFE, that they build together, each its part in turn:
 *
 *   FF FF FD 00 FE LEN_L LEN_H 55 | ERR ID data CRC | ERR ID data CRC | ...
 *
 * The first servo sends the header (LEN counts every servo asked) and its
 * part, each next one its part as soon as the one before has ended. A
 * part's CRC is the CRC of every byte of the packet before it (header and
 * the earlier parts with their CRCs), so the last part's CRC is the
 * packet's. The packet is never stuffed ("Fast Sync Read Status Packet does
 * not perform Byte Stuffing"). The encoders refuse (DXL_E_ARG) a request
 * whose reply would not fit DXL2_MAX_PACKET.
 */
int dxl2_encode_fast_sync_read(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len,
                               const uint8_t *ids, size_t n);
int dxl2_encode_fast_bulk_read(uint8_t *buf, size_t cap, const struct dxl2_bulk_item *items, size_t n);
/* One servo's part of a fast read's status. */
struct dxl2_fast_part {
	uint8_t id;            /* 0-252 */
	uint8_t err;           /* its own ERR field (data, as in any status) */
	uint16_t len;
	const uint8_t *data;
};
/* Bytes on the wire of the status answering parts of these lengths. */
size_t dxl2_fast_status_bytes(const uint16_t *lens, size_t n);
/* The simulator's side: the whole status packet of n parts, in request
 * order; ends[i] (when not NULL) gets the offset just past part i, so that
 * each servo's part can go out in its turn (and a chain that stops at a
 * silent servo is the packet cut at ends[k - 1]). */
int dxl2_encode_fast_status(uint8_t *buf, size_t cap, const struct dxl2_fast_part *parts, size_t n,
                            size_t *ends);
/* A status packet (the simulator's side): id 0-252, any err byte. */
int dxl2_encode_status(uint8_t *buf, size_t cap, uint8_t id, uint8_t err,
                       const uint8_t *params, size_t nparams);
/* The most bytes a status packet with nparams parameters can take on the
 * wire (worst-case stuffing): for timeouts and buffer sizes. */
size_t dxl2_status_bytes_max(size_t nparams);

/* Little-endian helpers (the control table's byte order). */
static inline uint32_t dxl2_get_u32(const uint8_t *p)
{
	return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static inline void dxl2_put_u32(uint8_t *p, uint32_t v)
{
	p[0] = (uint8_t)v;
	p[1] = (uint8_t)(v >> 8);
	p[2] = (uint8_t)(v >> 16);
	p[3] = (uint8_t)(v >> 24);
}

/* ---- parsing: one resumable, byte-fed parser ------------------------------ */
enum dxl2_parse_kind {
	DXL2_PARSE_STATUS,       /* the controller's side: INST must be 0x55 */
	DXL2_PARSE_INSTRUCTION,  /* the simulator's side: INST must not be 0x55 */
};

/* A decoded packet, stuffing removed. */
struct dxl2_packet {
	uint8_t id;
	uint8_t instr;           /* DXL2_INST_STATUS for a status packet */
	uint8_t err;             /* status only: the ERR field (0 for instructions) */
	uint16_t nparams;
	uint16_t wire_bytes;     /* bytes it took on the wire, header to CRC */
	uint8_t params[DXL2_MAX_PARAMS];
};

struct dxl2_parser {
	enum dxl2_parse_kind kind;
	size_t have;             /* bytes buffered in `buf` (stuffed, as received) */
	size_t checked;          /* body bytes of the buffered candidate already
	                            checked for stuffing (0 = none yet) */
	uint8_t buf[DXL2_MAX_PACKET];
	/* A status from 0xFE (a Fast Sync/Bulk Read's) is taken only while
	 * one is expected (dxl2_parser_expect_fast): it is not stuffed, so a
	 * header inside it cannot be told from data, and a candidate that long
	 * could hold back a good packet after it until its CRC fails. */
	bool fast;
	/* Counters since init (never reset by the parser itself). */
	uint32_t frames;
	uint32_t checksum_errors;   /* CRC mismatch */
	uint32_t header_errors;     /* reserved byte, ID, LEN or INST invalid */
	uint32_t stuffing_errors;   /* a header inside a packet's body */
	uint32_t bytes_dropped;     /* bytes discarded while resynchronising */
};

/* Same values as dxl_parse_result: DXL_NEED_MORE (0), DXL_FRAME (1), or a
 * negative dxl_status (DXL_E_CHECKSUM, DXL_E_HEADER, DXL_E_STUFFING). */
void dxl2_parser_init(struct dxl2_parser *p, enum dxl2_parse_kind kind);
/* Discard buffered bytes (before a new request); counters are kept. */
void dxl2_parser_reset(struct dxl2_parser *p);
/* Take a status from 0xFE, a fast read's, from now on (on) or refuse it as
 * a bad header (off, the initial state). The status side only. */
void dxl2_parser_expect_fast(struct dxl2_parser *p, bool on);
/*
 * Feed up to n bytes; *used tells how many were consumed. The contract is
 * 1.0's (dxl_parser_feed): call again after a frame or an error — even with
 * nothing left — until DXL_NEED_MORE; a frame is reported the moment its last
 * byte is fed and *used never runs past it. Invariant:
 * bytes fed = wire_bytes of frames delivered + bytes_dropped + have.
 *
 * Resync rules (gpsd: on an unexpected byte go back to the start state):
 *  - bytes before FF FF FD are dropped silently (bytes_dropped);
 *  - FF FF FD FD is stuffed data, not a header: dropped silently;
 *  - reserved byte not 00, ID 253/255 (or broadcast on the status side
 *    unless a fast read's status is expected), LEN too short for the kind
 *    (a fast read's status must hold one part) or longer than
 *    DXL2_MAX_LEN, INST 0x55 on the instruction side or not 0x55 on the
 *    status side: DXL_E_HEADER;
 *  - an expected status from 0xFE is a fast read's: not stuffed, so its
 *    body is not checked for stuffing and is delivered as it came — `err`
 *    the first part's ERR, `params` the rest up to the last CRC
 *    (dxl2_fast_status_split); while it is buffered, a packet after it
 *    comes out only once its CRC has failed;
 *  - FF FF FD followed by anything but FD inside the body: DXL_E_STUFFING,
 *    reported as soon as that byte arrives, so a reply cut short does not
 *    swallow the good one that follows it;
 *  - a CRC mismatch: DXL_E_CHECKSUM.
 * Each rejection drops one byte and rescans what is buffered.
 */
int dxl2_parser_feed(struct dxl2_parser *p, const uint8_t *data, size_t n, size_t *used,
                     struct dxl2_packet *out);

/* ---- matching replies to requests (libmodbus's check_confirmation) -------- */
/* A status packet for a request to req_id expecting expect_params parameters
 * (READ: len; PING: 3; WRITE and the rest: 0): DXL_OK, DXL_E_WRONG_ID or
 * DXL_E_WRONG_LENGTH. The ERR field is not judged here: it is data. */
int dxl2_check_reply(const struct dxl2_packet *pkt, uint8_t req_id, uint16_t expect_params);

/*
 * SYNC_READ / BULK_READ bookkeeping: one status packet per servo comes back,
 * each parsed as an ordinary frame. The tracker says which servo a frame
 * answers and which servos are still missing. It has no clock: the caller
 * decides when to stop waiting (its deadline), then asks
 * dxl2_multi_read_missing(); each missing servo is a DXL_E_TIMEOUT for that
 * servo, exactly as a missing reply to a 1.0 READ is. Servos answer in the
 * order of the request, so `next` is the slot the bus expects next; a reply
 * out of that order is still accepted (counted in `out_of_order`).
 */
#define DXL2_MULTI_MAX 253   /* every servo ID at most once */
struct dxl2_multi_read {
	size_t n;                            /* servos asked */
	size_t answered;                     /* replies accepted */
	size_t next;                         /* first slot not answered yet */
	uint32_t out_of_order;
	uint8_t ids[DXL2_MULTI_MAX];
	uint16_t len[DXL2_MULTI_MAX];        /* parameter count each reply must have */
	bool got[DXL2_MULTI_MAX];
};
/* From a SYNC_READ request (the same len for all). DXL_E_ARG on a bad list. */
int dxl2_multi_read_sync(struct dxl2_multi_read *m, uint16_t len, const uint8_t *ids, size_t n);
/* From a BULK_READ request. */
int dxl2_multi_read_bulk(struct dxl2_multi_read *m, const struct dxl2_bulk_item *items, size_t n);
/* Account for one parsed status packet: DXL_OK and *slot (the index in the
 * request) when it answers a servo that has not answered yet;
 * DXL_E_WRONG_ID for an ID not asked or answering twice; DXL_E_WRONG_LENGTH
 * for a reply of the wrong size (the slot stays unanswered). */
int dxl2_multi_read_accept(struct dxl2_multi_read *m, const struct dxl2_packet *pkt, size_t *slot);
/* The same for a reply known by its ID and parameter count (the bus's
 * frames are either protocol's). */
int dxl2_multi_read_take(struct dxl2_multi_read *m, uint8_t id, uint16_t nparams, size_t *slot);
static inline bool dxl2_multi_read_done(const struct dxl2_multi_read *m) { return m->answered == m->n; }
/*
 * A fast read's status (a frame from 0xFE) against the request's tracker
 * (dxl2_multi_read_sync/_bulk, untouched here): parts[i] gets slot i's ID,
 * ERR, length and data (pointing into pkt). Returns DXL_OK when every part
 * is there; else *good is how many parts from the front are sound and the
 * return says what is wrong with the next: DXL_E_WRONG_ID (not a fast
 * status, or another servo in that place), DXL_E_WRONG_LENGTH (the packet's
 * size is not the request's: *good is 0), DXL_E_CHECKSUM (that part's CRC).
 * The final CRC was the parser's to check; the parts' CRCs are checked here.
 */
int dxl2_fast_status_split(const struct dxl2_packet *pkt, const struct dxl2_multi_read *m,
                           struct dxl2_fast_part *parts, size_t *good);
/* Copies the IDs not answered (in request order) into ids (up to cap);
 * returns how many are missing. */
size_t dxl2_multi_read_missing(const struct dxl2_multi_read *m, uint8_t *ids, size_t cap);

#endif
