/* writeq.c — see writeq.h. */
#include "writeq.h"

#include <string.h>

void wq_init(struct wq *q)
{
	memset(q, 0, sizeof *q);
}

static bool wq_append(struct wq *q, uint8_t id, uint16_t addr, uint8_t len, uint32_t value, uint16_t chain)
{
	if (q->n >= WQ_CAP) {
		q->overflowed++;
		return false;
	}
	q->w[q->n++] = (struct wq_write){ .id = id, .addr = addr, .len = len, .value = value, .chain = chain };
	return true;
}

bool wq_put(struct wq *q, uint8_t id, uint16_t addr, uint8_t len, uint32_t value)
{
	/* the last write queued for this servo, if it is this register and not
	 * on the wire nor a step of a chain, takes the new value */
	for (size_t i = q->n; i-- > 0;) {
		if (q->w[i].id != id)
			continue;
		if (q->w[i].addr == addr && q->w[i].len == len && q->w[i].chain == 0 && !(i == 0 && q->taken)) {
			q->w[i].value = value;
			q->w[i].tries = 0;
			return true;
		}
		break;
	}
	return wq_append(q, id, addr, len, value, 0);
}

bool wq_put_seq(struct wq *q, uint8_t id, uint16_t addr, uint8_t len, uint32_t value)
{
	return wq_append(q, id, addr, len, value, 0);
}

uint16_t wq_chain(struct wq *q)
{
	q->next_chain = (uint16_t)(q->next_chain == UINT16_MAX ? 1 : q->next_chain + 1);
	return q->next_chain;
}

bool wq_put_chain(struct wq *q, uint16_t chain, uint8_t id, uint16_t addr, uint8_t len, uint32_t value)
{
	return wq_append(q, id, addr, len, value, chain);
}

size_t wq_pending(const struct wq *q)
{
	return q->n;
}

bool wq_has(const struct wq *q, uint8_t id, uint16_t addr)
{
	for (size_t i = 0; i < q->n; i++)
		if (q->w[i].id == id && q->w[i].addr == addr)
			return true;
	return false;
}

bool wq_has_id(const struct wq *q, uint8_t id)
{
	for (size_t i = 0; i < q->n; i++)
		if (q->w[i].id == id)
			return true;
	return false;
}

const struct wq_write *wq_peek(const struct wq *q)
{
	return q->n == 0 || q->taken ? NULL : &q->w[0];
}

const struct wq_write *wq_take(struct wq *q)
{
	if (q->n == 0 || q->taken)
		return NULL;
	q->taken = true;
	q->w[0].tries++;
	q->sent++;
	return &q->w[0];
}

/* The steps of a chain after one given up (none of them is on the wire). */
static void wq_drop_chain(struct wq *q, uint8_t id, uint16_t chain)
{
	size_t out = 0;
	for (size_t i = 0; i < q->n; i++) {
		if (q->w[i].id == id && q->w[i].chain == chain) {
			q->chain_dropped++;
			continue;
		}
		q->w[out++] = q->w[i];
	}
	q->n = out;
}

static void wq_pop(struct wq *q)
{
	memmove(q->w, q->w + 1, (q->n - 1) * sizeof q->w[0]);
	q->n--;
}

enum wq_outcome wq_done(struct wq *q, bool ok, struct wq_write *w)
{
	if (!q->taken || q->n == 0)
		return WQ_DONE;
	q->taken = false;
	if (w != NULL)
		*w = q->w[0];
	if (ok) {
		wq_pop(q);
		return WQ_DONE;
	}
	if (q->w[0].tries < WQ_TRIES) {
		q->retried++;
		return WQ_RETRY;
	}
	q->failed++;
	struct wq_write gone = q->w[0];
	wq_pop(q);
	if (gone.chain != 0)
		wq_drop_chain(q, gone.id, gone.chain);
	return WQ_FAILED;
}

void wq_drop_id(struct wq *q, uint8_t id)
{
	size_t out = 0;
	for (size_t i = 0; i < q->n; i++) {
		bool on_wire = i == 0 && q->taken;
		if (q->w[i].id == id && !on_wire)
			continue;
		q->w[out++] = q->w[i];
	}
	q->n = out;
}

void wq_clear(struct wq *q)
{
	q->n = 0;
	q->taken = false;
}
