/* render.h — undulate-top's screen: plain text or ANSI for a terminal of any
 * size down to 80x24; ASCII only, so any ssh client shows it. */
#ifndef UNDULATE_TOP_RENDER_H
#define UNDULATE_TOP_RENDER_H

#include <stdbool.h>
#include <stddef.h>

#include "model.h"

#define TOP_STATUS_MAX 160

enum top_view_kind {
	TOP_VIEW_AUTO,    /* detail when every robot fits, else compact */
	TOP_VIEW_DETAIL,  /* a line per robot and one per joint */
	TOP_VIEW_COMPACT, /* one line per robot: 20 robots on an 80x24 screen */
};

struct top_view {
	int selected;            /* position in the display order */
	int scroll;              /* first position shown */
	enum top_view_kind kind;
	bool read_only;
	bool help;               /* `?`: the legend and keys instead of the list */
	int prefix;              /* 'm' or 'M' typed: the next key names the mode (0: none) */
	const char *url;         /* the LCM URL listened on, said when nobody is heard */
	char banner[TOP_STATUS_MAX]; /* a line from whoever runs the show (--banner-file), or "" */
	char status[TOP_STATUS_MAX];
	char clock[16];          /* HH:MM:SS shown in the title */
};

/* Renders into BUF (NUL-terminated, truncated at CAP). With ANSI: exactly
 * ROWS lines for a full-screen repaint (cursor home, clear to end of line),
 * the selection in reverse video; without: every robot, plain text (--once).
 * Returns the length written. */
size_t top_render(const struct top_model *m, struct top_view *v, double now, int rows, int cols, bool ansi,
		  char *buf, size_t cap);
/* Whether the view shows a line per joint, given the screen height. */
bool top_view_detailed(const struct top_model *m, const struct top_view *v, int rows);
/* Moves the selection by DELTA robots (clamped) and scrolls to show it. */
void top_view_move(struct top_view *v, const struct top_model *m, int delta);

#endif
