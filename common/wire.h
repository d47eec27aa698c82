/*
 * wire.h — LCM's wire format read and written without allocation and without
 * trusting the bytes: big-endian integers, strings as an int32 length that
 * counts the NUL, then the bytes and the NUL (lcm-gen's encoding), and the
 * udpm transport's small-message datagram ("LC02", sequence number, channel,
 * payload). LCM 1.3.1's generated decoders malloc whatever length a string
 * claims; programs that take messages from the network decode them here.
 */
#ifndef UNDULATE_COMMON_WIRE_H
#define UNDULATE_COMMON_WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* A reader over n bytes. Once anything does not fit, `bad` stays set and
 * every further take returns 0 / "": check it once at the end. */
struct wire_reader {
	const uint8_t *p;
	size_t left;
	bool bad;
};

void wire_reader_init(struct wire_reader *r, const void *data, size_t n);
/* n = 1, 2, 4 or 8 big-endian bytes, as an unsigned value. */
uint64_t wire_take(struct wire_reader *r, size_t n);
double wire_take_double(struct wire_reader *r);
/* An LCM string into dst (cap >= 1). A length below 1, beyond the bytes left,
 * or a string whose last byte is not NUL marks the reader bad. A string
 * longer than cap - 1 is cut (*cut set, if cut != NULL): a caller that
 * compares names must treat a cut name as no match. */
void wire_take_string(struct wire_reader *r, char *dst, size_t cap, bool *cut);
/* n raw bytes into dst. */
void wire_take_bytes(struct wire_reader *r, uint8_t *dst, size_t n);

/* A writer into a caller's buffer; `bad` once something did not fit. */
struct wire_writer {
	uint8_t *p;
	size_t cap, len;
	bool bad;
};

void wire_writer_init(struct wire_writer *w, void *buf, size_t cap);
void wire_put(struct wire_writer *w, uint64_t v, size_t n);
void wire_put_double(struct wire_writer *w, double v);
void wire_put_string(struct wire_writer *w, const char *s);
void wire_put_bytes(struct wire_writer *w, const uint8_t *src, size_t n);

/* udpm small message (lcm_udpm.c): uint32 magic 0x4c433032 "LC02", uint32
 * sequence number, the channel NUL-terminated (at most WIRE_CHANNEL_MAX bytes
 * with the NUL), then the payload. Fragmented messages ("LC03") are parsed by
 * wire_udpm_frag_parse below; only the recorder reassembles them. */
#define WIRE_UDPM_MAGIC_SHORT 0x4c433032u
#define WIRE_CHANNEL_MAX 64
struct wire_udpm {
	uint32_t seqno;
	const char *channel;      /* points into the datagram */
	const uint8_t *payload;
	size_t payload_len;
};
/* False (with *why) unless the datagram is a well-formed small message. */
bool wire_udpm_parse(const uint8_t *dgram, size_t n, struct wire_udpm *out, const char **why);
/* udpm fragment (lcm_udpm.c, LCM 1.3.1's lcm2_header_long_t): a message too
 * large for one datagram (over about 64 kB) is sent as fragments, each uint32
 * magic 0x4c433033 "LC03", uint32 msg_seqno, uint32 msg_size (the payload's
 * whole size, channel not counted), uint32 fragment_offset (into the
 * payload), uint16 fragment_no, uint16 fragments_in_msg, then for fragment 0
 * the channel NUL-terminated, then the fragment's share of the payload. */
#define WIRE_UDPM_MAGIC_LONG 0x4c433033u
#define WIRE_UDPM_FRAG_HEADER 20
struct wire_udpm_frag {
	uint32_t seqno, msg_size, offset;
	uint16_t fragment_no, fragments;
	const char *channel;      /* fragment 0 only (else NULL), into the datagram */
	const uint8_t *data;
	size_t data_len;
};
/* False (with *why) unless the datagram is a well-formed fragment: its
 * number below the count, and fragment 0 with a channel. Whether it fits
 * the message is the reassembler's to check. */
bool wire_udpm_frag_parse(const uint8_t *dgram, size_t n, struct wire_udpm_frag *out, const char **why);
/* Builds one; returns the datagram's length, 0 if it does not fit in cap. */
size_t wire_udpm_build(uint8_t *buf, size_t cap, uint32_t seqno, const char *channel, const uint8_t *payload,
                       size_t payload_len);

#endif
