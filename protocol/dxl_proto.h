/*
 * dxl_proto.h — a Dynamixel protocol as a table (libmodbus's backend
 * struct): its encoders, its resumable status parser, its limits, its
 * error texts and what it can do. Protocol 1.0 (dxl.h) and 2.0 (dxl2.h) are
 * two const tables; the bus (bus.h) calls b->proto->... and never asks which
 * protocol it speaks. A second protocol was a second table; a branch on the
 * protocol number outside protocol/ is a missing entry here.
 *
 * Pure code like the framing: no I/O, no clock, no allocation. Addresses are
 * 16-bit and lengths 16-bit for both; 1.0's encoders refuse (DXL_E_ARG)
 * what does not fit its 8-bit fields.
 */
#ifndef UNDULATE_DXL_PROTO_H
#define UNDULATE_DXL_PROTO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl.h"
#include "dxl2.h"

/* What a protocol can do beyond PING, READ, WRITE, REG_WRITE, ACTION,
 * FACTORY_RESET and SYNC_WRITE, which both have. Code asks "can it?". */
enum dxl_cap {
	DXL_CAP_SYNC_READ      = 1u << 0,  /* one request, one reply per servo */
	DXL_CAP_BULK_READ      = 1u << 1,  /* as SYNC_READ, an address and length per servo */
	DXL_CAP_BULK_WRITE     = 1u << 2,
	DXL_CAP_REBOOT         = 1u << 3,
	DXL_CAP_CLEAR          = 1u << 4,  /* CLEAR multi-turn */
	DXL_CAP_PING_MODEL     = 1u << 5,  /* a PING's reply carries model number and firmware */
	DXL_CAP_BROADCAST_PING = 1u << 6,  /* every servo answers a broadcast PING in turn */
	DXL_CAP_RESET_OPTIONS  = 1u << 7,  /* FACTORY_RESET can keep the ID (and baud) */
	/* Fast Sync Read / Fast Bulk Read: one status packet for all servos.
	 * The protocol has them; whether the servos do is their firmware's
	 * (X430/X540 from 45): ask them (dxl2_model_fast_read). */
	DXL_CAP_FAST_READ      = 1u << 8,
};

/* FACTORY_RESET's option: 2.0's parameter byte. 1.0 resets everything and
 * takes DXL_RESET_ALL only. */
enum dxl_reset_option {
	DXL_RESET_ALL          = DXL2_RESET_ALL,
	DXL_RESET_KEEP_ID      = DXL2_RESET_KEEP_ID,
	DXL_RESET_KEEP_ID_BAUD = DXL2_RESET_KEEP_ID_BAUD,
};

/* A decoded packet of either protocol, in the wider shape (2.0's 16-bit
 * parameter count). A status packet's `err` is the servo's (1.0: the error
 * byte; 2.0: the ERR field) and `instr` its protocol's status mark (2.0:
 * 0x55; 1.0 has none: 0); an instruction's `err` is 0. */
#define DXL_FRAME_MAX_PARAMS DXL2_MAX_PARAMS
struct dxl_frame {
	uint8_t id;
	uint8_t instr;
	uint8_t err;
	uint16_t nparams;
	uint16_t wire_bytes;     /* bytes it took on the wire, header to checksum */
	uint8_t params[DXL_FRAME_MAX_PARAMS];
};

/* One servo's part of a BULK_READ or BULK_WRITE (data: BULK_WRITE only). */
struct dxl_item {
	uint8_t id;
	uint16_t addr, len;
	const uint8_t *data;
};

/* Room for either protocol's parser; which one is the table's business. */
union dxl_proto_parser {
	struct dxl_parser v1;
	struct dxl2_parser v2;
};

/* A parser's counters and its buffered bytes, either protocol's
 * (stuffing_errors: 2.0 only, 0 on 1.0). */
struct dxl_parser_counts {
	uint32_t frames, checksum_errors, header_errors, stuffing_errors, bytes_dropped;
	size_t have;
};

/* Every encoder writes into buf (cap bytes) and returns the bytes written or
 * a negative dxl_status (DXL_E_ARG, DXL_E_BUFFER); nothing past cap. */
struct dxl_proto {
	const char *name;            /* "1.0", "2.0" */
	int number;                  /* 1 or 2: what configuration files say */
	uint32_t caps;               /* enum dxl_cap */
	/* limits */
	uint8_t max_id;              /* the largest servo ID */
	uint8_t broadcast_id;
	size_t max_packet;           /* bytes on the wire, either direction */
	size_t max_params;           /* parameters of one request */
	uint16_t max_read_len;       /* the longest READ whose reply fits max_packet */
	uint8_t addr_bytes;          /* an address's size in WRITE's parameters */
	uint8_t ping_reply_params;   /* a PING reply's parameters (2.0: model, firmware) */
	size_t ping_round_trip_bytes; /* a PING and its reply on the wire */
	uint8_t err_alert;           /* ERR bits that mean "read the hardware error" (0: none) */
	/* Our own request read back (wiring that echoes, echo cancelling off)
	 * parses as a status packet: 1.0's instruction and status share
	 * FF FF ID LEN CODE; a 2.0 instruction never does (its INST is not 0x55).
	 * The bus holds a packet identical to the request (true) or the bytes
	 * that match it (false) until it knows which it was. */
	bool echo_reads_as_status;
	/* The most bytes a status packet with nparams parameters can take on
	 * the wire (2.0: at its worst-case stuffing): timeouts are built on it. */
	size_t (*status_bytes_max)(size_t nparams);
	/* What bus_begin does with a raw instruction code: 0 one reply at most,
	 * -1 never a reply (SYNC_WRITE, BULK_WRITE), DXL_E_ARG one reply per
	 * servo (SYNC_READ, BULK_READ: they have their own calls). */
	int (*instr_replies)(uint8_t instr);

	/* encoders; NULL where the protocol (caps) has no such instruction */
	int (*encode_instruction)(uint8_t *buf, size_t cap, uint8_t id, uint8_t instr, const uint8_t *params,
	                          size_t nparams);
	int (*encode_ping)(uint8_t *buf, size_t cap, uint8_t id);
	int (*encode_read)(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr, uint16_t len);
	int (*encode_write)(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr, const uint8_t *data, size_t n);
	int (*encode_reg_write)(uint8_t *buf, size_t cap, uint8_t id, uint16_t addr, const uint8_t *data,
	                        size_t n);
	int (*encode_action)(uint8_t *buf, size_t cap, uint8_t id);
	int (*encode_factory_reset)(uint8_t *buf, size_t cap, uint8_t id, uint8_t option);
	int (*encode_reboot)(uint8_t *buf, size_t cap, uint8_t id);
	int (*encode_clear_multi_turn)(uint8_t *buf, size_t cap, uint8_t id);
	int (*encode_sync_write)(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len, const uint8_t *ids,
	                         const uint8_t *data, size_t n);
	int (*encode_sync_read)(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len, const uint8_t *ids,
	                        size_t n);
	int (*encode_bulk_read)(uint8_t *buf, size_t cap, const struct dxl_item *items, size_t n);
	int (*encode_bulk_write)(uint8_t *buf, size_t cap, const struct dxl_item *items, size_t n);
	int (*encode_fast_sync_read)(uint8_t *buf, size_t cap, uint16_t addr, uint16_t len, const uint8_t *ids,
	                             size_t n);
	int (*encode_fast_bulk_read)(uint8_t *buf, size_t cap, const struct dxl_item *items, size_t n);
	/* the simulator's side */
	int (*encode_status)(uint8_t *buf, size_t cap, uint8_t id, uint8_t err, const uint8_t *params,
	                     size_t nparams);

	/* The resumable parser, with the contract of dxl_parser_feed: feed what
	 * read() returned, call again after a frame or an error until
	 * DXL_NEED_MORE. `instructions` picks the simulator's side. */
	void (*parser_init)(union dxl_proto_parser *p, bool instructions);
	void (*parser_reset)(union dxl_proto_parser *p);
	int (*parser_feed)(union dxl_proto_parser *p, const uint8_t *data, size_t n, size_t *used,
	                   struct dxl_frame *out);
	void (*parser_counts)(const union dxl_proto_parser *p, struct dxl_parser_counts *out);
	/* DXL_CAP_FAST_READ: take the one status packet of a fast read (a
	 * status from the broadcast ID) while on; NULL where there is none. */
	void (*parser_expect_fast)(union dxl_proto_parser *p, bool on);

	/* The simulator's side: a packet that just failed its checksum ends at
	 * bytes[n - 1] (the bytes the parser consumed last). Its ID and
	 * instruction from its header, so the addressed servo can answer with
	 * its checksum error; false when no header's LEN spans exactly to there. */
	bool (*damaged_packet)(const uint8_t *bytes, size_t n, uint8_t *id, uint8_t *instr);
	/* Several servos answering one request: the place of servo id's reply
	 * among them (each follows the one before, in this order), or -1 when
	 * every reply to req starts at the request's end (and two collide). */
	int (*reply_order)(const struct dxl_frame *req, uint8_t id);

	/* texts */
	const char *check_name;      /* what a damaged packet failed: "checksum", "CRC" */
	const char *(*instruction_name)(uint8_t instr);
	/* The servo's error byte / ERR field as text ("overheating|overload",
	 * "alert|data range", "none"); returns buf. */
	char *(*err_format)(uint8_t err, char *buf, size_t cap);
};

/* A frame as 2.0's own packet (what dxl2_* calls take): its fields and its
 * nparams parameters copied, the rest of out's kilobyte left alone. */
void dxl_frame_to_packet2(const struct dxl_frame *f, struct dxl2_packet *out);

extern const struct dxl_proto dxl_proto_v1;
extern const struct dxl_proto dxl_proto_v2;

/* The table for a protocol number (1 or 2); NULL for any other. */
const struct dxl_proto *dxl_proto_by_number(int number);

static inline bool dxl_proto_can(const struct dxl_proto *p, uint32_t caps)
{
	return (p->caps & caps) == caps;
}

#endif
