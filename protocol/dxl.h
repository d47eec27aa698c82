/*
 * dxl.h — Dynamixel Protocol 1.0 framing: pure code, no I/O, no clock, no allocation.
 *
 * Instruction packet: FF FF ID LEN INSTR P1..Pn CHK
 * Status packet:      FF FF ID LEN ERR   P1..Pn CHK
 * LEN = n + 2, bytes on the wire = LEN + 4, CHK = ~(ID + LEN + INSTR|ERR + ΣP) & 0xFF.
 *
 * Two kinds of failure are kept apart (as libmodbus does):
 *  - the servo's own status error bits (DXL_ERRBIT_*) are *data* carried in a
 *    status packet: the reply arrived and is well formed;
 *  - `enum dxl_status` is ours: a malformed packet, a timeout, a wrong reply.
 * dxl_strerror() names both.
 */
#ifndef UNDULATE_DXL_H
#define UNDULATE_DXL_H

#include <stddef.h>
#include <stdint.h>

#define DXL_BROADCAST_ID 0xFE
#define DXL_MAX_ID       0xFD   /* 253: the largest ID a servo may have */
/* The LEN field is kept <= 250 (as ROBOTIS's SDK does); a header with a larger
 * LEN is garbage and triggers a resync. LEN >= 2 always (INSTR/ERR + CHK). */
#define DXL_MAX_LEN      250
#define DXL_MIN_LEN      2
#define DXL_MAX_PARAMS   (DXL_MAX_LEN - 2)
#define DXL_MAX_PACKET   (DXL_MAX_LEN + 4)   /* bytes on the wire, header included */
#define DXL_HEADER_BYTES 4                    /* FF FF ID LEN */
/* Our encoders write at most 250 bytes a packet (ROBOTIS's SDK buffer size;
 * a SYNC_WRITE of 4 bytes per servo then fits 48 servos). The parser still
 * accepts anything up to DXL_MAX_PACKET. */
#define DXL_MAX_TX_PACKET 250
#define DXL_MAX_TX_PARAMS (DXL_MAX_TX_PACKET - 6)

/* Instructions. REBOOT and BULK_READ do not exist on the AX-12 (MX/X only). */
enum dxl_instruction {
	DXL_INST_PING          = 0x01,
	DXL_INST_READ          = 0x02,
	DXL_INST_WRITE         = 0x03,
	DXL_INST_REG_WRITE     = 0x04,
	DXL_INST_ACTION        = 0x05,
	DXL_INST_FACTORY_RESET = 0x06,
	DXL_INST_REBOOT        = 0x08,
	DXL_INST_SYNC_WRITE    = 0x83,
	DXL_INST_BULK_READ     = 0x92,
};
/* Name of an instruction ("PING", ...) or "UNKNOWN". */
const char *dxl_instruction_name(uint8_t instr);

/* Status error byte bits, as reported by the servo. Bit 7 is never set. */
enum dxl_errbit {
	DXL_ERRBIT_VOLTAGE     = 1u << 0,  /* input voltage out of [min, max] */
	DXL_ERRBIT_ANGLE_LIMIT = 1u << 1,  /* goal position outside the angle limits */
	DXL_ERRBIT_OVERHEAT    = 1u << 2,  /* internal temperature above its limit */
	DXL_ERRBIT_RANGE       = 1u << 3,  /* instruction parameter out of range */
	DXL_ERRBIT_CHECKSUM    = 1u << 4,  /* the servo saw a bad checksum */
	DXL_ERRBIT_OVERLOAD    = 1u << 5,  /* load exceeded the torque limit */
	DXL_ERRBIT_INSTRUCTION = 1u << 6,  /* undefined instruction / ACTION without REG_WRITE */
};
#define DXL_ERRBIT_MASK 0x7Fu
/* Short name of a single error bit ("overload"), NULL if not a known bit. */
const char *dxl_errbit_name(uint8_t bit);
/* Writes "overload|overheating" (or "none") into buf; returns buf. */
char *dxl_errbits_format(uint8_t bits, char *buf, size_t cap);
/* Any register of bits as "a|b|bitN" ("none" for 0), each set bit named by
 * name_of (NULL: "bitN"); buf always terminated. Returns buf. */
char *dxl_bits_format(uint8_t bits, const char *(*name_of)(uint8_t bit), char *buf, size_t cap);

/* Our own status codes (control flow). 0 is success; errors are negative. */
enum dxl_status {
	DXL_OK             = 0,
	DXL_E_ARG          = -1,   /* invalid argument (ID, length, address, value) */
	DXL_E_BUFFER       = -2,   /* caller's buffer too small / packet too long */
	DXL_E_CHECKSUM     = -3,   /* received packet with a bad checksum */
	DXL_E_HEADER       = -4,   /* header field invalid (ID, LEN, error byte): resynced */
	DXL_E_TIMEOUT      = -5,   /* no (complete) reply within the derived timeout */
	DXL_E_WRONG_ID     = -6,   /* reply from another ID than the request's */
	DXL_E_WRONG_LENGTH = -7,   /* reply with an unexpected parameter count */
	DXL_E_IO           = -8,   /* read/write on the port failed */
	DXL_E_DISCONNECTED = -9,   /* the port went away (EIO, hang-up, 0-byte read) */
	DXL_E_BUSY         = -10,  /* a transaction is already pending */
	DXL_E_ECHO         = -11,  /* echo cancelling: the bytes read back differ */
	DXL_E_UNSUPPORTED  = -12,  /* not supported by this servo/port/build */
	/* Protocol 2.0 only (dxl2.h): a header inside a packet's body, i.e. an
	 * FF FF FD not followed by the stuffed FD — a packet cut short and a new
	 * one begun, or a sender that does not stuff. Resynchronised. */
	DXL_E_STUFFING     = -13,
};
/* Message for a dxl_status value (negative) — never NULL. */
const char *dxl_strerror(int status);

/* ---- encoding: into caller-owned buffers ----------------------------------
 * Every encoder returns the number of bytes written (> 0) or a negative
 * dxl_status (DXL_E_ARG, DXL_E_BUFFER). Nothing is written past `cap`. */
uint8_t dxl_checksum(const uint8_t *from_id, size_t n); /* ~sum of n bytes starting at ID */
int dxl_encode_instruction(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr,
                           const uint8_t *params, size_t nparams);
int dxl_encode_ping(uint8_t *buf, size_t cap, uint8_t id);
int dxl_encode_read(uint8_t *buf, size_t cap, uint8_t id, uint8_t addr, uint8_t len);
int dxl_encode_write(uint8_t *buf, size_t cap, uint8_t id, uint8_t addr,
                     const uint8_t *data, size_t n);
int dxl_encode_reg_write(uint8_t *buf, size_t cap, uint8_t id, uint8_t addr,
                         const uint8_t *data, size_t n);
int dxl_encode_action(uint8_t *buf, size_t cap, uint8_t id);
int dxl_encode_factory_reset(uint8_t *buf, size_t cap, uint8_t id);
/* SYNC_WRITE to `n` servos: ids[i] gets data[i*len .. i*len+len-1] at `addr`.
 * Always broadcast; LEN = (len + 1)·n + 4. */
int dxl_encode_sync_write(uint8_t *buf, size_t cap, uint8_t addr, uint8_t len,
                          const uint8_t *ids, const uint8_t *data, size_t n);
/* BULK_READ (MX series only): per item one status packet comes back. */
struct dxl_bulk_item {
	uint8_t id, addr, len;
};
int dxl_encode_bulk_read(uint8_t *buf, size_t cap, const struct dxl_bulk_item *items, size_t n);
/* A status packet (the simulator's side). err must be <= 0x7F. */
int dxl_encode_status(uint8_t *buf, size_t cap, uint8_t id, uint8_t err,
                      const uint8_t *params, size_t nparams);

/* Little-endian 16-bit helpers (the control table's byte order). */
static inline uint16_t dxl_get_u16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static inline void dxl_put_u16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)(v & 0xFF); p[1] = (uint8_t)(v >> 8); }

/* ---- parsing: one resumable, byte-fed parser --------------------------------
 * Fed with whatever read() returned; no timing inside. */
enum dxl_parse_kind {
	DXL_PARSE_STATUS,       /* the controller's side: FF FF ID LEN ERR ... */
	DXL_PARSE_INSTRUCTION,  /* the simulator's side: FF FF ID LEN INSTR ... */
};

/* A decoded packet. `code` is the ERR byte (status) or INSTR (instruction). */
struct dxl_packet {
	uint8_t id;
	uint8_t code;
	uint8_t nparams;
	uint8_t params[DXL_MAX_PARAMS];
};

struct dxl_parser {
	enum dxl_parse_kind kind;
	size_t have;                     /* bytes buffered in `buf` */
	uint8_t buf[DXL_MAX_PACKET];
	/* Counters since init (never reset by the parser itself). */
	uint32_t frames;                 /* good packets delivered */
	uint32_t checksum_errors;
	uint32_t header_errors;          /* headers rejected (ID, LEN, error byte) */
	uint32_t bytes_dropped;          /* bytes discarded while resynchronising */
};

enum dxl_parse_result {
	DXL_NEED_MORE = 0,  /* everything given was consumed, no complete packet yet */
	DXL_FRAME     = 1,  /* *out holds a packet; *used bytes were consumed */
	/* or a negative dxl_status: DXL_E_CHECKSUM / DXL_E_HEADER. The parser has
	 * already dropped one byte and will rescan; call again with the rest. */
};

void dxl_parser_init(struct dxl_parser *p, enum dxl_parse_kind kind);
/* Discard buffered bytes (e.g. before a new request); counters are kept. */
void dxl_parser_reset(struct dxl_parser *p);
/*
 * Feed up to n bytes. Returns DXL_NEED_MORE, DXL_FRAME or a negative error;
 * *used tells how many of the n bytes were consumed. After a frame or an error
 * call again with the rest — even when the rest is empty — until it returns
 * DXL_NEED_MORE: after an error the bytes still buffered may already hold a
 * whole packet (e.g. one inside a damaged packet's parameters). A frame is
 * reported the moment its last byte is fed; *used never runs past it.
 * Invariant: bytes fed = bytes of frames delivered + bytes_dropped + have.
 * Resync rule (ROBOTIS's good part): reject a
 * header whose ID > 0xFD (0xFE allowed for instructions), LEN > 250 or < 2,
 * or (status) error byte > 0x7F; drop one byte, rescan what is buffered.
 */
int dxl_parser_feed(struct dxl_parser *p, const uint8_t *data, size_t n, size_t *used,
                    struct dxl_packet *out);

#endif
