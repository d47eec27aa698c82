/* fox.h — the pure parts of Foxglove's WebSocket protocol
 * (foxglove.websocket.v1, github.com/foxglove/ws-protocol docs/spec.md) as
 * undulate-web speaks it (foxsrv.h owns the connections):
 *
 *  - which LCM channel carries which message type (fox_kind_of);
 *  - one description per type (its fields, as lcm-gen's C struct holds
 *    them), from which both the JSON Schema advertised for a channel and the
 *    JSON of each message are written: the two cannot disagree;
 *  - the header of a binary messageData frame;
 *  - the client's JSON operations, parsed with libwebsockets' lejp (the
 *    library the program already links) into a bounded struct.
 *
 * No I/O beyond the FILE the caller gives, no clock, no allocation. */
#ifndef UNDULATE_WEB_FOX_H
#define UNDULATE_WEB_FOX_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "compat/lcm/lcmdec.h"

#define FOX_SUBPROTOCOL "foxglove.websocket.v1"
#define FOX_OP_MESSAGE_DATA 0x01        /* server binary opcode (spec: "Message Data") */
#define FOX_DATA_HEADER 13              /* opcode, subscription id (u32 LE), receive time ns (u64 LE) */
/* Subscriptions one operation may carry (and one client may hold): a
 * Foxglove layout subscribes to a few topics; more is a mistake or an attack. */
#define FOX_OP_ITEMS 64
#define FOX_OP_NAME_MAX 32              /* the longest op name kept (longer ones are unknown anyway) */

/* One field of a message type, as lcm-gen lays it out in C. */
enum fox_field_kind {
	FOX_I8, FOX_I16, FOX_I32, FOX_I64, FOX_F64, FOX_BOOL, FOX_STRING,
	FOX_F64_ARRAY,                  /* double *, its count an int32_t field */
	FOX_STRUCT_ARRAY,               /* struct *, its count an int32_t field */
};
struct fox_type;
struct fox_field {
	const char *name;
	enum fox_field_kind kind;
	size_t off;                     /* offsetof in the C struct */
	size_t count_off;               /* arrays: offsetof of the int32_t count */
	const struct fox_type *item;    /* FOX_STRUCT_ARRAY: the element's type */
};
struct fox_type {
	const char *name;               /* "undulate.robot_state_t", the channel's schemaName */
	const struct fox_field *fields;
	size_t nfields;
	size_t size;                    /* sizeof the C struct (array strides) */
	const struct lcmdec_type *dec;  /* top-level types: how to decode the bytes */
};

/* The type a channel carries (<robot>.STATE, .BUS, .PARAMS, .EVENT,
 * SIM.TRUTH, SIM.COLLISION, SIM.WORLD, SIM.REPLY), or NULL. */
const struct fox_type *fox_kind_of(const char *channel);

/* The channel patterns to subscribe to on LCM beside the monitors' (feed.h). */
extern const char *const fox_extra_channels[];
extern const size_t fox_extra_nchannels;

/* A JSON Schema (draft 2020-12 keywords: type, properties, items, title) of
 * t: every field, in the order of the .lcm file. Doubles are "number": NaN
 * and infinities, which JSON cannot hold, are written as null. false on a
 * write error. */
bool fox_schema(const struct fox_type *t, FILE *f);
/* msg (a decoded t) as one JSON object with the schema's keys. Strings come
 * from the network: json.h escapes them and replaces bytes that are not
 * UTF-8. false on a write error. */
bool fox_encode(const struct fox_type *t, const void *msg, FILE *f);
/* The same bytes into buf (cap bytes, NUL-terminated, json.h's buffer sink,
 * what the server uses: no stdio per message): their count, or 0 if they do
 * not fit. */
size_t fox_encode_buf(const struct fox_type *t, const void *msg, char *buf, size_t cap);

/* The 13 bytes before a message's payload in a messageData frame. */
void fox_data_header(unsigned char out[FOX_DATA_HEADER], uint32_t subscription, uint64_t receive_ns);

/* A server's WebSocket frame header (RFC 6455 5.2) for one whole binary
 * message of len bytes: FIN, opcode 2, no mask, the length in 7, 16 or 64
 * bits. Its size (2, 4 or 10). The server writes several messageData frames
 * into one buffer and hands it to libwebsockets as raw bytes: one send for
 * what is queued instead of one per message (libwebsockets 4.1 frames one
 * message per lws_write and has no batch call). */
#define FOX_WS_HEADER_MAX 10
size_t fox_ws_header(unsigned char out[FOX_WS_HEADER_MAX], size_t len);

/* A client operation. */
enum fox_op_kind {
	FOX_OP_SUBSCRIBE,
	FOX_OP_UNSUBSCRIBE,
	FOX_OP_OTHER,                   /* a known op of the protocol we do not serve (name in .name) */
};
struct fox_sub_item {
	uint32_t id, channel;
};
struct fox_op {
	enum fox_op_kind kind;
	char name[FOX_OP_NAME_MAX];
	struct fox_sub_item subs[FOX_OP_ITEMS];  /* subscribe */
	uint32_t unsubs[FOX_OP_ITEMS];           /* unsubscribe */
	int n;                                   /* items in whichever */
};
/* Parses one text message. false: not JSON, not an object with a string
 * "op", an op this protocol does not have, an item without its fields or
 * with a value that is not an integer in 0..2^32-1, more than FOX_OP_ITEMS
 * items: why says which, for the client's status message. */
bool fox_op_parse(const char *text, size_t len, struct fox_op *op, char *why, size_t cap);

#endif
