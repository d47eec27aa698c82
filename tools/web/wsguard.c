/* wsguard.c — see wsguard.h. */
#include "wsguard.h"

#include <string.h>

enum { WSG_HEADERS, WSG_WAITING, WSG_FRAMES };

void wsg_init(struct wsg *g)
{
	memset(g, 0, sizeof *g);
	g->phase = WSG_HEADERS;
	g->need = 2;
}

static void wsg_fault(struct wsg *g, enum wsg_verdict v)
{
	if (g->verdict == WSG_OK)
		g->verdict = v;
}

/* The header so far says how long it is: 2, + 2 or 8 length bytes, + 4 mask. */
static uint8_t wsg_header_len(const uint8_t *hdr)
{
	uint8_t len7 = hdr[1] & 0x7f;
	return (uint8_t)(2 + (len7 == 126 ? 2 : len7 == 127 ? 8 : 0) + (hdr[1] & 0x80 ? 4 : 0));
}

static uint64_t wsg_payload_len(const uint8_t *hdr)
{
	uint8_t len7 = hdr[1] & 0x7f;
	if (len7 < 126)
		return len7;
	uint64_t n = 0;
	for (int i = 0; i < (len7 == 126 ? 2 : 8); i++)
		n = n << 8 | hdr[2 + i];
	return n;
}

/* One byte of a frame header; at its end, the frame's payload is skipped. */
static void wsg_header_byte(struct wsg *g, uint8_t b)
{
	g->hdr[g->have++] = b;
	if (g->have == 2) {
		if (!(b & 0x80))
			wsg_fault(g, WSG_UNMASKED);
		g->need = wsg_header_len(g->hdr);
	}
	if (g->have < g->need)
		return;
	if ((g->hdr[1] & 0x7f) == 127 && (g->hdr[2] & 0x80))
		wsg_fault(g, WSG_BAD_LENGTH);
	g->skip = wsg_payload_len(g->hdr);
	g->frames++;
	g->have = 0;
	g->need = 2;
}

static void wsg_frames_feed(struct wsg *g, const uint8_t *p, size_t n)
{
	size_t i = 0;
	while (i < n) {
		if (g->skip > 0) {
			uint64_t take = g->skip < n - i ? g->skip : n - i;
			g->skip -= take;
			i += (size_t)take;
			continue;
		}
		wsg_header_byte(g, p[i++]);
	}
}

void wsg_feed(struct wsg *g, const uint8_t *p, size_t n)
{
	static const uint8_t end[4] = { '\r', '\n', '\r', '\n' };
	size_t i = 0;
	for (; i < n && g->phase == WSG_HEADERS; i++) {
		g->crlf = p[i] == end[g->crlf] ? g->crlf + 1 : p[i] == '\r' ? 1 : 0;
		if (g->crlf == 4)
			g->phase = WSG_WAITING;
	}
	if (g->phase == WSG_WAITING) {
		g->early += n - i;
		return;
	}
	if (g->phase == WSG_FRAMES)
		wsg_frames_feed(g, p + i, n - i);
}

enum wsg_verdict wsg_upgraded(struct wsg *g)
{
	if (g->phase != WSG_WAITING || g->early > 0)
		wsg_fault(g, WSG_EARLY);
	g->phase = WSG_FRAMES;
	return g->verdict;
}

enum wsg_verdict wsg_verdict(const struct wsg *g)
{
	return g->verdict;
}

uint64_t wsg_frames(const struct wsg *g)
{
	return g->frames;
}

const char *wsg_why(enum wsg_verdict v)
{
	switch (v) {
	case WSG_OK: return "ok";
	case WSG_EARLY: return "data before the handshake's answer, or not the connection's first request";
	case WSG_UNMASKED: return "a client frame must be masked (RFC 6455 5.1)";
	case WSG_BAD_LENGTH: return "frame length with its top bit set (RFC 6455 5.2)";
	}
	return "?";
}
