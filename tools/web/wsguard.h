/* wsguard.h — what a WebSocket client sent, checked where libwebsockets 4.1
 * does not: RFC 6455 5.1 wants every client frame masked and the server to
 * close the connection on an unmasked one (libwebsockets 4.1.6 unmasks what
 * is masked and passes the rest; upstream checks since 2026), and 4.1 wants
 * the client to wait for the server's 101 before it sends a frame. Masking is
 * what keeps a page's script from choosing the bytes on the wire, the defence
 * against cache poisoning of intermediaries; a client that skips it is not a
 * browser's WebSocket.
 *
 * Fed the bytes of one TCP connection as libwebsockets reads them (wsrecv.c
 * sees them): the first request's headers (up to CRLF CRLF), then, once the
 * server answered 101, frame headers, whose payloads it skips. A WebSocket
 * must be its connection's first request (browsers open a new connection for
 * one). Pure: bytes in, a verdict out; no allocation, O(1) state. */
#ifndef UNDULATE_WEB_WSGUARD_H
#define UNDULATE_WEB_WSGUARD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

enum wsg_verdict {
	WSG_OK,
	WSG_EARLY,         /* bytes after the handshake before the 101, or an earlier request */
	WSG_UNMASKED,      /* a client frame without a mask */
	WSG_BAD_LENGTH,    /* a 64-bit length with its top bit set (RFC 6455 5.2) */
};

struct wsg {
	uint8_t phase;          /* headers, waiting for the 101, frames */
	uint8_t crlf;           /* bytes of CRLF CRLF matched so far */
	uint8_t hdr[14];        /* the frame header being read */
	uint8_t have, need;     /* bytes of it read, and needed (2 until the length byte says) */
	uint64_t early;         /* bytes after the headers before the 101 */
	uint64_t skip;          /* payload bytes left of the current frame */
	uint64_t frames;        /* whole frame headers read */
	enum wsg_verdict verdict; /* the first fault, kept */
};

/* A new connection: its first request's headers come first. */
void wsg_init(struct wsg *g);
/* n bytes the server read from the client. */
void wsg_feed(struct wsg *g, const uint8_t *p, size_t n);
/* The server answered 101: from now on frames. The verdict (WSG_EARLY if
 * anything came between the headers and now). */
enum wsg_verdict wsg_upgraded(struct wsg *g);
enum wsg_verdict wsg_verdict(const struct wsg *g);
uint64_t wsg_frames(const struct wsg *g);
/* In words, for a log and the close frame's reason (at most 123 bytes). */
const char *wsg_why(enum wsg_verdict v);

#endif
