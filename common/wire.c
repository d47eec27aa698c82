/* wire.c — see wire.h. */
#include "wire.h"

#include <string.h>

void wire_reader_init(struct wire_reader *r, const void *data, size_t n)
{
	r->p = data;
	r->left = data != NULL ? n : 0;
	r->bad = false;
}

uint64_t wire_take(struct wire_reader *r, size_t n)
{
	uint64_t v = 0;
	if (r->bad || r->left < n) {
		r->bad = true;
		return 0;
	}
	for (size_t i = 0; i < n; i++)
		v = v << 8 | r->p[i];
	r->p += n;
	r->left -= n;
	return v;
}

double wire_take_double(struct wire_reader *r)
{
	uint64_t bits = wire_take(r, 8);
	double v;
	memcpy(&v, &bits, sizeof v);
	return v;
}

void wire_take_string(struct wire_reader *r, char *dst, size_t cap, bool *cut)
{
	int32_t n = (int32_t)(uint32_t)wire_take(r, 4);
	dst[0] = '\0';
	if (cut != NULL)
		*cut = false;
	if (r->bad || n < 1 || (size_t)n > r->left || r->p[n - 1] != '\0') {
		r->bad = true;
		return;
	}
	size_t len = strnlen((const char *)r->p, (size_t)n - 1);
	size_t keep = len < cap - 1 ? len : cap - 1;
	memcpy(dst, r->p, keep);
	dst[keep] = '\0';
	/* an embedded NUL also shortens what the name says: a cut */
	if (cut != NULL)
		*cut = keep != (size_t)n - 1;
	r->p += n;
	r->left -= (size_t)n;
}

void wire_take_bytes(struct wire_reader *r, uint8_t *dst, size_t n)
{
	if (r->bad || r->left < n) {
		r->bad = true;
		memset(dst, 0, n);
		return;
	}
	memcpy(dst, r->p, n);
	r->p += n;
	r->left -= n;
}

void wire_writer_init(struct wire_writer *w, void *buf, size_t cap)
{
	w->p = buf;
	w->cap = buf != NULL ? cap : 0;
	w->len = 0;
	w->bad = false;
}

void wire_put(struct wire_writer *w, uint64_t v, size_t n)
{
	if (w->bad || w->cap - w->len < n) {
		w->bad = true;
		return;
	}
	for (size_t i = 0; i < n; i++)
		w->p[w->len + i] = (uint8_t)(v >> (8 * (n - 1 - i)));
	w->len += n;
}

void wire_put_double(struct wire_writer *w, double v)
{
	uint64_t bits;
	memcpy(&bits, &v, sizeof bits);
	wire_put(w, bits, 8);
}

void wire_put_string(struct wire_writer *w, const char *s)
{
	size_t n = strlen(s != NULL ? s : "") + 1;
	if (n > INT32_MAX) {
		w->bad = true;
		return;
	}
	wire_put(w, (uint64_t)n, 4);
	wire_put_bytes(w, (const uint8_t *)(s != NULL ? s : ""), n);
}

void wire_put_bytes(struct wire_writer *w, const uint8_t *src, size_t n)
{
	if (w->bad || w->cap - w->len < n) {
		w->bad = true;
		return;
	}
	memcpy(w->p + w->len, src, n);
	w->len += n;
}

bool wire_udpm_parse(const uint8_t *dgram, size_t n, struct wire_udpm *out, const char **why)
{
	struct wire_reader r;
	wire_reader_init(&r, dgram, n);
	uint32_t magic = (uint32_t)wire_take(&r, 4);
	out->seqno = (uint32_t)wire_take(&r, 4);
	if (r.bad) {
		*why = "shorter than an LCM header";
		return false;
	}
	if (magic != WIRE_UDPM_MAGIC_SHORT) {
		*why = "not an LCM small message (magic)";
		return false;
	}
	size_t len = strnlen((const char *)r.p, r.left < WIRE_CHANNEL_MAX ? r.left : WIRE_CHANNEL_MAX);
	if (len == 0 || len >= WIRE_CHANNEL_MAX || len >= r.left) {
		*why = "channel name empty, unterminated or too long";
		return false;
	}
	out->channel = (const char *)r.p;
	out->payload = r.p + len + 1;
	out->payload_len = r.left - len - 1;
	return true;
}

bool wire_udpm_frag_parse(const uint8_t *dgram, size_t n, struct wire_udpm_frag *out, const char **why)
{
	struct wire_reader r;
	wire_reader_init(&r, dgram, n);
	uint32_t magic = (uint32_t)wire_take(&r, 4);
	out->seqno = (uint32_t)wire_take(&r, 4);
	out->msg_size = (uint32_t)wire_take(&r, 4);
	out->offset = (uint32_t)wire_take(&r, 4);
	out->fragment_no = (uint16_t)wire_take(&r, 2);
	out->fragments = (uint16_t)wire_take(&r, 2);
	out->channel = NULL;
	if (r.bad) {
		*why = "shorter than an LCM fragment header";
		return false;
	}
	if (magic != WIRE_UDPM_MAGIC_LONG) {
		*why = "not an LCM fragment (magic)";
		return false;
	}
	if (out->fragment_no >= out->fragments) {
		*why = "fragment number beyond the fragment count";
		return false;
	}
	if (out->fragment_no == 0) {
		size_t len = strnlen((const char *)r.p, r.left < WIRE_CHANNEL_MAX ? r.left : WIRE_CHANNEL_MAX);
		if (len == 0 || len >= WIRE_CHANNEL_MAX || len >= r.left) {
			*why = "channel name empty, unterminated or too long";
			return false;
		}
		out->channel = (const char *)r.p;
		r.p += len + 1;
		r.left -= len + 1;
	}
	out->data = r.p;
	out->data_len = r.left;
	return true;
}

size_t wire_udpm_build(uint8_t *buf, size_t cap, uint32_t seqno, const char *channel, const uint8_t *payload,
                       size_t payload_len)
{
	struct wire_writer w;
	size_t clen = strlen(channel);
	if (clen == 0 || clen >= WIRE_CHANNEL_MAX)
		return 0;
	wire_writer_init(&w, buf, cap);
	wire_put(&w, WIRE_UDPM_MAGIC_SHORT, 4);
	wire_put(&w, seqno, 4);
	wire_put_bytes(&w, (const uint8_t *)channel, clen + 1);
	wire_put_bytes(&w, payload, payload_len);
	return w.bad ? 0 : w.len;
}
