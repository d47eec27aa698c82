/* render.c — see render.h. */
#include "render.h"
#include "modes.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* Lines above and below the robot list: title and column headers (two in
 * the detail view, one in the compact view, so twenty robots fit in 24
 * lines); status and keys. */
#define TOP_HEAD_LINES_DETAIL 3
#define TOP_HEAD_LINES_COMPACT 2
#define TOP_FOOT_LINES 2
/* Widest line we build before clipping to the terminal width. */
#define TOP_LINE_MAX 256

struct rbuf {
	char *buf;
	size_t cap, len;
	int cols, lines, max_lines;
	bool ansi;
};

static void rb_raw(struct rbuf *b, const char *s)
{
	size_t n = strlen(s);
	if (b->len + n + 1 > b->cap)
		n = b->cap > b->len + 1 ? b->cap - b->len - 1 : 0;
	memcpy(b->buf + b->len, s, n);
	b->len += n;
	b->buf[b->len] = '\0';
}

/* One screen line, clipped to the width; REVERSE for the selection. */
static void rb_line(struct rbuf *b, bool reverse, const char *fmt, ...)
{
	char line[TOP_LINE_MAX];
	if (b->max_lines > 0 && b->lines >= b->max_lines)
		return;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(line, sizeof(line), fmt, ap);
	va_end(ap);
	if (b->cols > 0 && b->cols < TOP_LINE_MAX)
		line[b->cols] = '\0';
	if (b->ansi && reverse)
		rb_raw(b, "\033[7m");
	rb_raw(b, line);
	if (b->ansi)
		rb_raw(b, reverse ? "\033[0m\033[K\r\n" : "\033[K\r\n");
	else
		rb_raw(b, "\n");
	b->lines++;
}

/* A number in a fixed width, or dashes when unknown. */
static const char *num(char *out, size_t n, const char *fmt, double v, int width)
{
	if (isfinite(v))
		snprintf(out, n, fmt, v);
	else
		snprintf(out, n, "%*s", width, "-");
	return out;
}

static int robot_height(const struct top_robot *r, bool detail)
{
	return detail ? 1 + (r->njoints > 0 ? r->njoints : 0) : 1;
}

bool top_view_detailed(const struct top_model *m, const struct top_view *v, int rows)
{
	if (v->kind != TOP_VIEW_AUTO)
		return v->kind == TOP_VIEW_DETAIL;
	int need = 0;
	for (int i = 0; i < m->nrobots; i++)
		need += robot_height(&m->robots[i], true);
	return need <= rows - TOP_HEAD_LINES_DETAIL - TOP_FOOT_LINES;
}

void top_view_move(struct top_view *v, const struct top_model *m, int delta)
{
	v->selected += delta;
	if (v->selected >= m->nrobots)
		v->selected = m->nrobots - 1;
	if (v->selected < 0)
		v->selected = 0;
}

static void title_line(struct rbuf *b, const struct top_model *m, const struct top_view *v, double now,
		       int first, int last)
{
	int stale = 0;
	for (int i = 0; i < m->nrobots; i++)
		stale += top_robot_stale(&m->robots[i], now);
	char sim[96] = "";
	if (m->have_sim) {
		double imp = 0;
		int n = top_collisions_window(m, now, &imp);
		snprintf(sim, sizeof(sim), " sim%s: %d/10s %.3gNs, total %lld %.3gNs",
			 top_sim_present(m, now) ? "" : "(gone)", n, imp, (long long)m->sim_total_collisions,
			 m->sim_total_impulse);
	}
	char range[32] = "";
	if (m->nrobots > 0 && (first > 0 || last < m->nrobots - 1))
		snprintf(range, sizeof(range), " [%d-%d]", first + 1, last + 1);
	rb_line(b, false, "undulate-top %d robots (%d stale)%s%s%s%s", m->nrobots, stale, range, sim,
		v->clock[0] ? "  " : "", v->clock);
}

static void flags_text(char *out, size_t n, const struct top_robot *r, double now)
{
	int16_t err = 0;
	for (int k = 0; k < r->njoints; k++)
		err |= r->j[k].error_bits;
	if (top_robot_stale(r, now))
		snprintf(out, n, r->have_state ? "STALE %.0fs" : "no state", now - r->rx);
	else if (err)
		snprintf(out, n, "err %02X", err & 0xFF);
	else if (r->have_bus && !r->connected)
		snprintf(out, n, "bus down");
	else
		out[0] = '\0';
}

static void robot_detail(struct rbuf *b, const struct top_model *m, const struct top_view *v, int pos, double now)
{
	const struct top_robot *r = &m->robots[m->order[pos]];
	char rate[16], jit[16], dj[16], dn[16], flags[32];
	flags_text(flags, sizeof(flags), r, now);
	rb_line(b, pos == v->selected, "%c%2d %-14.14s %-4s %s %s %5lld %s %s %s", pos == v->selected ? '>' : ' ',
		pos + 1, r->name, r->have_state ? mode_short(r->mode) : "-",
		num(rate, sizeof(rate), "%6.1f", top_robot_rate_hz(r), 6),
		num(jit, sizeof(jit), "%6.0f", top_robot_jitter_p99(r), 6), (long long)r->bus_errors,
		num(dj, sizeof(dj), "%+8.2f", top_robot_dphase_joints(r), 8),
		num(dn, sizeof(dn), "%+8.2f", top_neighbour_dphase(m, pos), 8), flags);
	if (r->fault[0] != '\0')
		rb_line(b, false, "     FAULT LATCHED: %s (send 'clear' once fixed)", r->fault);
	for (int k = 0; k < r->njoints; k++) {
		const struct top_joint *j = &r->j[k];
		/* torque actuation has no goal: the column shows the drive, marked d */
		char goal[16], ang[16], spd[16], load[16], ph[16], amp[16], freq[16];
		if (!isfinite(j->goal) && isfinite(j->drive))
			snprintf(goal, sizeof goal, "d%+6.3f", j->drive);
		else
			num(goal, sizeof goal, "%+7.3f", j->goal, 7);
		rb_line(b, false, "     j%d id%-3d %s %s %7s %s %s %s %s %02X", k, j->servo_id,
			num(ang, sizeof ang, "%+7.3f", j->angle, 7), num(spd, sizeof spd, "%+7.3f", j->speed, 7), goal,
			num(load, sizeof load, "%+6.2f", j->load, 6), num(ph, sizeof ph, "%+6.2f", j->phase, 6),
			num(amp, sizeof amp, "%5.2f", j->amplitude, 5), num(freq, sizeof freq, "%5.2f", j->frequency, 5),
			j->error_bits & 0xFF);
	}
}

static void robot_compact(struct rbuf *b, const struct top_model *m, const struct top_view *v, int pos, double now)
{
	const struct top_robot *r = &m->robots[m->order[pos]];
	char rate[16], jit[16], dj[16], dn[16], jt[2][32];
	for (int k = 0; k < 2; k++) {
		char ang[16], ph[16];
		if (k < r->njoints)
			snprintf(jt[k], sizeof(jt[k]), "%s %s", num(ang, sizeof ang, "%+6.2f", r->j[k].angle, 6),
			         num(ph, sizeof ph, "%+6.2f", r->j[k].phase, 6));
		else
			snprintf(jt[k], sizeof(jt[k]), "%13s", "");
	}
	int16_t err = 0;
	for (int k = 0; k < r->njoints; k++)
		err |= r->j[k].error_bits;
	char mark = top_robot_stale(r, now) ? 'x' : err ? '!' : ' ';
	rb_line(b, pos == v->selected, "%c%c%2d %-10.10s %-4s %s %s %4lld %s %s %s %s", pos == v->selected ? '>' : ' ',
		mark, pos + 1, r->name, r->have_state ? mode_short(r->mode) : "-",
		num(rate, sizeof(rate), "%5.1f", top_robot_rate_hz(r), 5),
		num(jit, sizeof(jit), "%5.0f", top_robot_jitter_p99(r), 5), (long long)r->bus_errors, jt[0], jt[1],
		num(dj, sizeof(dj), "%+6.2f", top_robot_dphase_joints(r), 6),
		num(dn, sizeof(dn), "%+6.2f", top_neighbour_dphase(m, pos), 6));
}

/* Keeps the selected robot on screen; returns the last position shown. */
static int scroll_to_selection(const struct top_model *m, struct top_view *v, bool detail, int avail)
{
	if (v->selected >= m->nrobots)
		v->selected = m->nrobots - 1;
	if (v->selected < 0)
		v->selected = 0;
	if (v->scroll > v->selected)
		v->scroll = v->selected;
	for (;;) {
		int used = 0, last = v->scroll - 1;
		for (int p = v->scroll; p < m->nrobots; p++) {
			int h = robot_height(&m->robots[m->order[p]], detail);
			if (used + h > avail)
				break;
			used += h;
			last = p;
		}
		if (last >= v->selected || v->scroll >= v->selected)
			return last < v->scroll ? v->scroll : last;
		v->scroll++;
	}
}

size_t top_render(const struct top_model *m, struct top_view *v, double now, int rows, int cols, bool ansi,
		  char *buf, size_t cap)
{
	struct rbuf b = { .buf = buf, .cap = cap, .cols = cols, .ansi = ansi, .max_lines = ansi ? rows : 0 };
	buf[0] = '\0';
	bool detail = ansi ? top_view_detailed(m, v, rows) : true;
	int avail = rows - (detail ? TOP_HEAD_LINES_DETAIL : TOP_HEAD_LINES_COMPACT) - TOP_FOOT_LINES;
	int first = 0, last = m->nrobots - 1;
	if (ansi) {
		rb_raw(&b, "\033[H");
		last = scroll_to_selection(m, v, detail, avail > 1 ? avail : 1);
		first = v->scroll;
	}
	title_line(&b, m, v, now, first, last);
	if (detail) {
		rb_line(&b, false, "  # robot          mode   rate  jit99  berr  dJ(1-0) d(next)");
		rb_line(&b, false, "     joint       angle   speed    goal   load  phase   amp  freq err");
	} else {
		rb_line(&b, false, "    # robot      mode  rate jit99 berr j0 angle phase j1 angle phase    dJ dnext");
	}
	if (m->nrobots == 0)
		rb_line(&b, false, "  (no robot heard yet: <robot>.STATE on this LCM URL)");
	for (int p = first; p <= last && p < m->nrobots; p++) {
		if (detail)
			robot_detail(&b, m, v, p, now);
		else
			robot_compact(&b, m, v, p, now);
	}
	if (ansi) {
		while (b.lines < rows - TOP_FOOT_LINES)
			rb_line(&b, false, "%s", "");
		rb_line(&b, false, "%s", v->status);
		if (v->read_only)
			rb_line(&b, false, "READ-ONLY  up/down 1-9 select  PgUp/PgDn  v view  q quit");
		else
			rb_line(&b, false, "up/dn 1-9 select  l h s o mode (LHSO: all)  +/- nudge  v view  q quit");
		/* no newline after the last line: the screen must not scroll */
		if (b.len >= 2 && strcmp(b.buf + b.len - 2, "\r\n") == 0)
			b.buf[b.len -= 2] = '\0';
		rb_raw(&b, "\033[J");
	} else if (m->have_sim) {
		rb_line(&b, false, "order: %s", m->order_lateral ? "lateral position (SIM.TRUTH)" : "name");
	}
	return b.len;
}
