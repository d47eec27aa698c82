/* wcontact.h — the contacts undulate-web shows: every touching pair the
 * simulator reports (SIM.TRUTH's contacts, 100 messages a second) summed per
 * pair between two frames, then kept in a ring of marks, each stamped with
 * the frame time it was closed at. The page draws a mark at the contact point
 * and fades it over about a second; a browser's cursor takes only the marks
 * it has not had (frame.h). Pure: the model and times come in as arguments.
 *
 * A mark sums one pair (robots a, b and their links; b -1: a wall) over the
 * messages that listed it since the last close: impulses added, the mean
 * force the mean of the messages' mean forces (each over one truth period,
 * so the mean force over the time it touched), impact if it began touching
 * in any of them, the point and normal the last ones. */
#ifndef UNDULATE_WEB_WCONTACT_H
#define UNDULATE_WEB_WCONTACT_H

#include <stdbool.h>
#include <stdint.h>

#include "tools/top/model.h"

#define WCT_PENDING TOP_WORLD_CONTACTS /* pairs summed between two closes; more are counted */
/* Marks kept: the page fades one over WCT_SHOW_S; 40 pairs touching at once
 * closed 12.5 times a second fill WCT_SHOW_S with 750. */
#define WCT_RING 2048
#define WCT_SHOW_S 1.5                 /* a mark older than this is not sent: the page has faded it */

struct wct_mark {
	int64_t t_ms;               /* closed at (ms after the history's start, as the samples) */
	int a, b;                   /* robots (model indices); b -1: a wall */
	int link_a, link_b;
	double x, y, nx, ny;        /* m; the last point and normal */
	double impulse;             /* N·s summed */
	double force;               /* N, the mean force over the messages that listed it */
	bool impact;
};

struct wct {
	struct wct_mark pending[WCT_PENDING];
	double force_sum[WCT_PENDING];
	int nmsgs[WCT_PENDING];
	int npending;
	int64_t overflow;           /* pairs not summed: WCT_PENDING were already */
	uint64_t n;                 /* marks closed: the running index of the ring */
	struct wct_mark ring[WCT_RING];
};

void wct_init(struct wct *w);
/* Sums the model's last SIM.TRUTH contacts (m->world.contacts) into the
 * pending marks: call once per SIM.TRUTH taken. */
void wct_add(struct wct *w, const struct top_model *m);
/* The pending marks into the ring, stamped t_ms; none pending after. */
void wct_close(struct wct *w, int64_t t_ms);
/* Oldest running index still held. */
uint64_t wct_oldest(const struct wct *w);
static inline const struct wct_mark *wct_at(const struct wct *w, uint64_t i) { return &w->ring[i % WCT_RING]; }

#endif
