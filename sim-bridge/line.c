/*
 * line.c — scheduled output bytes with collisions (see line.h).
 */
#include "line.h"

#include <string.h>

void sim_line_init(struct sim_line *l)
{
	memset(l, 0, sizeof(*l));
}

void sim_line_clear(struct sim_line *l)
{
	l->head = 0;
	l->n = 0;
}

/* Keep the queue contiguous from index 0 so inserts are a plain memmove. */
static void line_compact(struct sim_line *l)
{
	if (l->head == 0)
		return;
	memmove(l->q, &l->q[l->head], l->n * sizeof(l->q[0]));
	l->head = 0;
}

static void line_put_one(struct sim_line *l, int64_t t, int64_t byte_ns, uint8_t b)
{
	struct sim_line_byte *q = &l->q[l->head];
	size_t i = l->n;
	/* Walk back over bytes released later than this one; a byte within
	 * half a byte time shares its slot on the wire and collides. */
	int64_t half = byte_ns / 2;
	while (i > 0 && q[i - 1].t >= t - half) {
		int64_t d = q[i - 1].t - t;
		if (d <= half && d >= -half) {
			q[i - 1].b &= b;
			l->collisions++;
			return;
		}
		i--;
	}
	if (l->head + l->n >= SIM_LINE_CAP) {
		line_compact(l);
		q = l->q;
		if (l->n >= SIM_LINE_CAP) {
			l->overflows++;
			return;
		}
	}
	memmove(&q[i + 1], &q[i], (l->n - i) * sizeof(q[0]));
	q[i].t = t;
	q[i].b = b;
	l->n++;
}

void sim_line_put(struct sim_line *l, int64_t first_end, int64_t byte_ns, const uint8_t *bytes, size_t n)
{
	for (size_t i = 0; i < n; i++)
		line_put_one(l, first_end + (int64_t)i * byte_ns, byte_ns, bytes[i]);
}

size_t sim_line_take(struct sim_line *l, int64_t now, uint8_t *out, size_t cap)
{
	size_t k = 0;
	while (k < cap && l->n > 0 && l->q[l->head].t <= now) {
		out[k++] = l->q[l->head].b;
		l->head++;
		l->n--;
	}
	if (l->n == 0)
		l->head = 0;
	return k;
}

int64_t sim_line_next(const struct sim_line *l)
{
	return l->n ? l->q[l->head].t : INT64_MAX;
}

int64_t sim_line_chunk_end(const struct sim_line *l, int64_t slice_ns)
{
	if (l->n == 0)
		return INT64_MAX;
	int64_t first = l->q[l->head].t, end = first;
	for (size_t i = l->head; i < l->head + l->n && l->q[i].t <= first + slice_ns; i++)
		end = l->q[i].t;
	return end;
}
