/* wcontact.c — see wcontact.h. */
#include "wcontact.h"

#include <string.h>

void wct_init(struct wct *w)
{
	memset(w, 0, sizeof *w);
}

uint64_t wct_oldest(const struct wct *w)
{
	return w->n > WCT_RING ? w->n - WCT_RING : 0;
}

/* The pending slot of the pair of c: the one it has, a new one, or -1 (full). */
static int wct_slot(struct wct *w, const struct top_contact *c)
{
	for (int i = 0; i < w->npending; i++) {
		const struct wct_mark *p = &w->pending[i];
		if (p->a == c->a && p->b == c->b && p->link_a == c->link_a && p->link_b == c->link_b)
			return i;
	}
	if (w->npending == WCT_PENDING)
		return -1;
	int i = w->npending++;
	w->pending[i] = (struct wct_mark){ .a = c->a, .b = c->b, .link_a = c->link_a, .link_b = c->link_b };
	w->force_sum[i] = 0;
	w->nmsgs[i] = 0;
	return i;
}

void wct_add(struct wct *w, const struct top_model *m)
{
	for (int k = 0; k < m->world.ncontacts && k < TOP_WORLD_CONTACTS; k++) {
		const struct top_contact *c = &m->world.contacts[k];
		int i = wct_slot(w, c);
		if (i < 0) {
			w->overflow++;
			continue;
		}
		struct wct_mark *p = &w->pending[i];
		p->x = c->x;
		p->y = c->y;
		p->nx = c->nx;
		p->ny = c->ny;
		p->impulse += c->impulse;
		p->impact |= c->impact;
		w->force_sum[i] += c->force;
		w->nmsgs[i]++;
	}
}

void wct_close(struct wct *w, int64_t t_ms)
{
	for (int i = 0; i < w->npending; i++) {
		struct wct_mark *r = &w->ring[w->n % WCT_RING];
		*r = w->pending[i];
		r->t_ms = t_ms;
		r->force = w->force_sum[i] / w->nmsgs[i];
		w->n++;
	}
	w->npending = 0;
}
