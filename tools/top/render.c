/* render.c — see render.h. */
#include "render.h"
#include "dxl.h"
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
	int silent = top_robot_silent_joints(r);
	for (int k = 0; k < r->njoints; k++)
		err |= r->j[k].error_bits;
	char names[64];
	if (top_robot_stale(r, now))
		snprintf(out, n, r->have_state ? "STALE %.0fs" : "no state", now - r->rx);
	else if (silent > 0)
		snprintf(out, n, "%d joint%s SILENT", silent, silent == 1 ? "" : "s");
	else if (err & 0x7F)
		snprintf(out, n, "%s", top_errbits_format(err, names, sizeof names));
	else if (r->have_bus && !r->connected)
		snprintf(out, n, "bus down");
	else
		out[0] = '\0';
}

static void robot_detail(struct rbuf *b, const struct top_model *m, const struct top_view *v, int pos, double now)
{
	const struct top_robot *r = &m->robots[m->order[pos]];
	char rate[16], jit[16], dj[16], dn[16], bd[16], flags[80];
	flags_text(flags, sizeof(flags), r, now);
	rb_line(b, pos == v->selected, "%c%2d %-14.14s %-4s %s %s %5lld %s %s %s %s", pos == v->selected ? '>' : ' ',
		pos + 1, r->name, r->have_state ? mode_short(r->mode) : "-",
		num(rate, sizeof(rate), "%6.1f", top_robot_rate_hz(r), 6),
		num(jit, sizeof(jit), "%6.0f", top_robot_jitter_p99(r), 6), (long long)r->bus_errors,
		num(dj, sizeof(dj), "%+7.2f", top_robot_dphase_joints(r), 7),
		num(dn, sizeof(dn), "%+7.2f", top_neighbour_dphase(m, pos), 7),
		num(bd, sizeof(bd), "%5.2f", top_pair_bound(m, pos), 5), flags);
	if (r->fault[0] != '\0')
		rb_line(b, false, "     FAULT LATCHED: %s (send 'clear' once fixed)", r->fault);
	for (int k = 0; k < r->njoints; k++) {
		const struct top_joint *j = &r->j[k];
		/* A silent servo's angle and speed are its last good reading,
		 * frozen: shown as dashes, never as if live. */
		bool live = !top_joint_silent(j);
		double nan = NAN;
		/* torque actuation has no goal: the column shows the drive, marked d */
		char goal[16], ang[16], spd[16], load[16], ph[16], amp[16], freq[16], temp[16], volt[16], st[64];
		if (!isfinite(j->goal) && isfinite(j->drive))
			snprintf(goal, sizeof goal, "d%+6.3f", j->drive);
		else
			num(goal, sizeof goal, "%+7.3f", j->goal, 7);
		bool tq = top_joint_torque_differs(j);
		rb_line(b, false, "   j%d id%-3d %s %s %7s %s %s %s %s %s %s %s%s%s", k, j->servo_id,
			num(ang, sizeof ang, "%+7.3f", live ? j->angle : nan, 7),
			num(spd, sizeof spd, "%+7.3f", live ? j->speed : nan, 7), goal,
			num(load, sizeof load, "%+5.2f", live ? j->load : nan, 5),
			num(ph, sizeof ph, "%+5.2f", live ? j->phase : nan, 5),
			num(amp, sizeof amp, "%4.2f", j->amplitude, 4), num(freq, sizeof freq, "%4.2f", j->frequency, 4),
			num(temp, sizeof temp, "%3.0fC", j->temperature > 0 ? j->temperature : nan, 4),
			num(volt, sizeof volt, "%4.1fV", j->voltage > 0 ? j->voltage : nan, 5),
			top_joint_status(j, st, sizeof st), tq ? ", torque " : "", tq ? top_joint_torque(j) : "");
	}
}

static void robot_compact(struct rbuf *b, const struct top_model *m, const struct top_view *v, int pos, double now)
{
	const struct top_robot *r = &m->robots[m->order[pos]];
	char rate[16], jit[16], dj[16], dn[16], bd[16], jt[2][32];
	for (int k = 0; k < 2; k++) {
		char ang[16], ph[16];
		if (k < r->njoints && k == 0)
			snprintf(jt[k], sizeof(jt[k]), "%s %s", num(ang, sizeof ang, "%+6.2f", r->j[k].angle, 6),
			         num(ph, sizeof ph, "%+6.2f", r->j[k].phase, 6));
		else if (k < r->njoints)
			snprintf(jt[k], sizeof(jt[k]), "%s", num(ph, sizeof ph, "%+6.2f", r->j[k].phase, 6));
		else
			snprintf(jt[k], sizeof(jt[k]), "%*s", k == 0 ? 13 : 6, "");
	}
	int16_t err = 0;
	for (int k = 0; k < r->njoints; k++)
		err |= r->j[k].error_bits;
	char mark = top_robot_stale(r, now) ? 'x' : top_robot_silent_joints(r) > 0 ? 'S' : (err & 0xFF) ? '!' : ' ';
	rb_line(b, pos == v->selected, "%c%c%2d %-10.10s %-4s %s %s %4lld %s %s %s %s %s", pos == v->selected ? '>' : ' ',
		mark, pos + 1, r->name, r->have_state ? mode_short(r->mode) : "-",
		num(rate, sizeof(rate), "%5.1f", top_robot_rate_hz(r), 5),
		num(jit, sizeof(jit), "%5.0f", top_robot_jitter_p99(r), 5), (long long)r->bus_errors, jt[0], jt[1],
		num(dj, sizeof(dj), "%+6.2f", top_robot_dphase_joints(r), 6),
		num(dn, sizeof(dn), "%+6.2f", top_neighbour_dphase(m, pos), 6),
		num(bd, sizeof(bd), "%5.2f", top_pair_bound(m, pos), 5));
}

/* The banner (what the show is doing now) and, with a simulator, the contact
 * trend: collisions and mean contact force per TOP_TREND_S window, oldest
 * first. Returns the lines written. */
#define TOP_TREND_SHOWN 8
static int extra_count(const struct top_model *m, const struct top_view *v)
{
	return (v->banner[0] != '\0') + (m->have_sim && m->ntrend > 0 ? 2 : 0);
}

static int extra_lines(struct rbuf *b, const struct top_model *m, const struct top_view *v)
{
	int n = 0;
	if (v->banner[0] != '\0') {
		rb_line(b, false, "%s", v->banner);
		n++;
	}
	int64_t coll[TOP_TREND_SHOWN];
	double force[TOP_TREND_SHOWN];
	int k = m->have_sim ? top_trend(m, coll, force, TOP_TREND_SHOWN) : 0;
	if (k > 0) {
		char fl[TOP_LINE_MAX] = "", cl[TOP_LINE_MAX] = "";
		size_t fo = 0, co = 0;
		/* %g: a force from a hostile or broken SIM.TRUTH (1e300 N) stays
		 * one short field; the offsets never pass the buffers' ends */
		for (int i = 0; i < k; i++) {
			int w = snprintf(fl + fo, sizeof fl - fo, " %6.3g", force[i]);
			fo = w > 0 && (size_t)w < sizeof fl - fo ? fo + (size_t)w : sizeof fl - 1;
			w = snprintf(cl + co, sizeof cl - co, " %6lld", (long long)coll[i]);
			co = w > 0 && (size_t)w < sizeof cl - co ? co + (size_t)w : sizeof cl - 1;
		}
		rb_line(b, false, "contact force, N per %.0f s:%s", TOP_TREND_S, fl);
		rb_line(b, false, "collisions per %.0f s:     %s", TOP_TREND_S, cl);
		n += 2;
	}
	return n;
}

/* `?`: what the columns mean and what the keys do (also in undulate-top(1)). */
static const char *const top_help_lines[] = {
	"Robot line:  mode LIMP | HOLD | SIN(USOID) | OSC(ILLATOR)",
	"  rate    control loop rate, Hz (mean period over the last 128 cycles)",
	"  jit99   99th percentile of the loop's wake-up lateness, us",
	"  berr    bus errors since the daemon started (timeouts, bad replies)",
	"  dJ      phase of joint 1 minus joint 0, rad",
	"  d(next) phase of the next robot minus this one's (contact joints), rad",
	"  bound   2 asin(d~) with the next robot: |d(next)| below it, no contact needed",
	"  flags   STALE (no STATE > 1 s), N joints SILENT, error bits, bus down",
	"Joint line: angle (rad), speed (rad/s), goal (rad; d+x: torque drive),",
	"  load (of max torque), phase (rad), amp (rad), freq (Hz), temp (C), volt (V);",
	"  status: ok | SILENT xN (no valid reading for N cycles: its angle and speed",
	"  are frozen, shown as -) | the servo's error bits by name (overload, ...);",
	"  then 'torque off (wanted on)' while the servo reports otherwise than wanted",
	"Keys: up/down j/k 1-9 PgUp/PgDn Home/End select; v view (auto/detail/compact)",
	"  m then l/h/s/o  mode of the selected robot: LIMP HOLD SINUSOID OSCILLATOR",
	"  M then l/h/s/o  the same for every robot; the status line counts answers",
	"  + / -  OSCILLATOR: c of every joint +-10 %; SINUSOID: amplitude +-0.05 rad",
	"  ? this help; q quit (Ctrl-C: interrupt). Commands reach local robots only.",
};

static void help_screen(struct rbuf *b, const struct top_view *v, int rows)
{
	(void)v;
	for (size_t i = 0; i < sizeof top_help_lines / sizeof top_help_lines[0]; i++) {
		if (b->lines >= rows - TOP_FOOT_LINES)
			break;
		rb_line(b, false, "%s", top_help_lines[i]);
	}
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
	/* the banner and the contact trend take lines from the list */
	int extra = extra_count(m, v);
	bool detail = ansi ? top_view_detailed(m, v, rows - extra) : true;
	int avail = rows - extra - (detail ? TOP_HEAD_LINES_DETAIL : TOP_HEAD_LINES_COMPACT) - TOP_FOOT_LINES;
	int first = 0, last = m->nrobots - 1;
	if (ansi) {
		rb_raw(&b, "\033[H");
		last = scroll_to_selection(m, v, detail, avail > 1 ? avail : 1);
		first = v->scroll;
	}
	title_line(&b, m, v, now, first, last);
	extra_lines(&b, m, v);
	if (ansi && v->help) {
		help_screen(&b, v, rows);
	} else {
	if (detail) {
		rb_line(&b, false, "  # robot          mode   rate  jit99  berr dJ(1-0) d(next) bound");
		rb_line(&b, false, "   joint     angle   speed    goal  load phase  amp freq temp  volt status");
	} else {
		rb_line(&b, false, "    # robot      mode  rate jit99 berr j0 angle phase j1 ph     dJ  dnext bound");
	}
	if (m->nrobots == 0)
		rb_line(&b, false, "  (no robot heard yet on %s: is a daemon running with this --lcm-url?)",
			v->url && v->url[0] ? v->url : "LCM's default URL");
	for (int p = first; p <= last && p < m->nrobots; p++) {
		if (detail)
			robot_detail(&b, m, v, p, now);
		else
			robot_compact(&b, m, v, p, now);
	}
	}
	if (ansi) {
		while (b.lines < rows - TOP_FOOT_LINES)
			rb_line(&b, false, "%s", "");
		rb_line(&b, false, "%s", v->status);
		if (v->help)
			rb_line(&b, false, "any key: back to the robots");
		else if (v->read_only)
			rb_line(&b, false, "READ-ONLY  up/dn j/k 1-9 select  v view  ? help  q quit");
		else if (v->prefix)
			rb_line(&b, false, "mode for %s: l LIMP  h HOLD  s SINUSOID  o OSCILLATOR  (other key: cancel)",
				v->prefix == 'M' ? "EVERY robot" : "the selected robot");
		else
			rb_line(&b, false, "up/dn j/k 1-9 select  m mode  M mode for all  +/- nudge  v view  ? help  q quit");
		/* no newline after the last line: the screen must not scroll */
		if (b.len >= 2 && strcmp(b.buf + b.len - 2, "\r\n") == 0)
			b.buf[b.len -= 2] = '\0';
		rb_raw(&b, "\033[J");
	} else if (m->have_sim) {
		rb_line(&b, false, "order: %s", m->order_lateral ? "lateral position (SIM.TRUTH)" : "name");
	}
	return b.len;
}
