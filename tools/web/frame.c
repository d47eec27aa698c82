/* frame.c — see frame.h. */
#include "frame.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "json.h"
#include "modes.h"

void frame_cursor_init(struct frame_cursor *c, const struct hist *h)
{
	c->sample = hist_oldest(h);
	c->bin = hist_oldest_bin(h);
	c->mark = hist_oldest_mark(h);
	c->contact = wct_oldest(&h->contacts);
	c->truths = -1;
	c->frames = 0;
}

static void frame_status_joint(struct json *j, const struct top_joint *jt)
{
	char status[TOP_TEXT_MAX];
	json_object_begin(j);
	json_field_int(j, "id", jt->servo_id);
	json_field_string(j, "status", top_joint_status(jt, status, sizeof status));
	json_field_number(j, "temperature", jt->temperature);
	json_field_number(j, "voltage", jt->voltage);
	json_field_int(j, "error_bits", jt->error_bits);
	json_field_int(j, "stale_cycles", jt->stale_cycles);
	json_field_bool(j, "torque", jt->torque);
	json_field_int(j, "torque_read", jt->torque_read);
	json_field_string(j, "torque_shown", top_joint_torque(jt));
	json_field_bool(j, "torque_differs", top_joint_torque_differs(jt));
	json_object_end(j);
}

static void frame_status_robot(struct json *j, const struct top_robot *r, double now)
{
	json_object_begin(j);
	json_field_string(j, "name", r->name);
	json_field_string(j, "mode", r->have_state ? mode_name(r->mode) : "?");
	json_field_string(j, "mode_reason", r->mode_reason);
	json_field_bool(j, "stale", top_robot_stale(r, now));
	json_field_number(j, "age_s", r->have_state ? now - r->rx : NAN);
	json_field_number(j, "rate_hz", top_robot_rate_hz(r));
	json_field_number(j, "rx_hz", top_robot_rx_hz(r, now));
	json_field_number(j, "jitter_p99_us", top_robot_jitter_p99(r));
	if (r->have_bus)
		json_field_string(j, "bus", r->connected ? "ok" : "down");
	else {
		json_key(j, "bus");
		json_null(j);
	}
	json_field_int(j, "bus_errors", r->bus_errors);
	json_field_int(j, "timeouts", r->timeouts);
	json_field_int(j, "silent_joints", top_robot_silent_joints(r));
	json_field_string(j, "fault", r->fault);
	json_field_string(j, "last_event", r->last_event);
	json_key(j, "joints");
	json_array_begin(j);
	for (int k = 0; k < r->njoints && k < TOP_MAX_JOINTS; k++)
		frame_status_joint(j, &r->j[k]);
	json_array_end(j);
	json_object_end(j);
}

static void frame_counters(struct json *j, const struct frame_counters *c)
{
	json_key(j, "server");
	json_object_begin(j);
	json_field_int(j, "clients", c->clients);
	json_field_int(j, "http_requests", c->http_requests);
	json_field_int(j, "http_refused", c->http_refused);
	json_field_int(j, "ws_refused", c->ws_refused);
	json_field_int(j, "msgs_refused", c->msgs_refused);
	json_field_int(j, "commands_sent", c->commands_sent);
	json_field_int(j, "commands_refused", c->commands_refused);
	json_field_int(j, "frames_sent", c->frames_sent);
	json_field_int(j, "frames_skipped", c->frames_skipped);
	json_field_int(j, "clients_stalled", c->clients_stalled);
	json_field_int(j, "ws_bad_frames", c->ws_bad_frames);
	json_field_int(j, "conns_evicted", c->conns_evicted);
	json_object_end(j);
}

static void frame_status(struct json *j, const struct hist *h, const struct top_model *m,
                         const struct frame_counters *srv, double now)
{
	json_key(j, "status");
	json_object_begin(j);
	json_key(j, "robots");
	json_array_begin(j);
	for (int k = 0; k < m->nrobots; k++)
		frame_status_robot(j, &m->robots[m->order[k]], now);
	json_array_end(j);
	double impulse = 0;
	int coll = top_collisions_window(m, now, &impulse);
	json_key(j, "sim");
	json_object_begin(j);
	json_field_bool(j, "present", top_sim_present(m, now));
	json_field_int(j, "collisions_10s", coll);
	json_field_number(j, "impulse_10s", impulse);
	json_field_int(j, "total_collisions", m->sim_total_collisions);
	json_field_number(j, "total_impulse", m->sim_total_impulse);
	json_object_end(j);
	json_field_int(j, "dropped_robots", m->dropped_robots);
	json_field_int(j, "decode_errors", m->decode_errors);
	json_key(j, "world_refused");
	json_object_begin(j);
	json_field_int(j, "index", m->world.bad_index);
	json_field_int(j, "number", m->world.bad_number);
	json_field_int(j, "overflow", m->world.overflow);
	json_field_int(j, "marks", h->contacts.overflow);
	json_object_end(j);
	if (srv != NULL)
		frame_counters(j, srv);
	json_object_end(j);
}

/* values of ring[from..to) (sample indices); before `first` there is no data */
static void frame_series(struct json *j, const float *ring, uint64_t first, uint64_t from, uint64_t to)
{
	json_array_begin(j);
	for (uint64_t i = from; i < to; i++)
		json_number(j, i < first ? NAN : ring[hist_slot(i)]);
	json_array_end(j);
}

static void frame_samples(struct json *j, const struct hist *h, const struct top_model *m, uint64_t from,
                          uint64_t to)
{
	json_key(j, "samples");
	json_object_begin(j);
	json_key(j, "t");
	json_array_begin(j);
	for (uint64_t i = from; i < to; i++)
		json_int(j, h->t_ms[hist_slot(i)]);
	json_array_end(j);
	json_key(j, "robots");
	json_array_begin(j);
	for (int k = 0; k < m->nrobots && k < h->nrobots; k++) {
		int r = m->order[k];
		int nj = m->robots[r].njoints < TOP_MAX_JOINTS ? m->robots[r].njoints : TOP_MAX_JOINTS;
		json_object_begin(j);
		json_field_string(j, "name", m->robots[r].name);
		json_key(j, "a");
		json_array_begin(j);
		for (int jt = 0; jt < nj; jt++)
			frame_series(j, h->angle[r][jt], h->robot_first[r], from, to);
		json_array_end(j);
		json_key(j, "w");
		json_array_begin(j);
		for (int jt = 0; jt < nj; jt++)
			frame_series(j, h->speed[r][jt], h->robot_first[r], from, to);
		json_array_end(j);
		json_object_end(j);
	}
	json_array_end(j);
	json_object_end(j);
	json_key(j, "pairs");
	json_array_begin(j);
	for (int k = 0; k < h->npairs_now; k++) {
		const struct hist_pair *p = &h->pairs[h->pair_of[k]];
		json_object_begin(j);
		json_field_string(j, "a", m->robots[p->a].name);
		json_field_string(j, "b", m->robots[p->b].name);
		json_field_string(j, "class", p->cls);
		json_key(j, "d");
		frame_series(j, p->delta, p->first, from, to);
		json_key(j, "bound");
		frame_series(j, p->bound, p->first, from, to);
		json_object_end(j);
	}
	json_array_end(j);
}

static void frame_marks(struct json *j, const struct hist *h, const struct top_model *m, uint64_t from)
{
	json_key(j, "marks");
	json_array_begin(j);
	for (uint64_t i = from; i < h->nmarks; i++) {
		const struct hist_mark *k = &h->marks[i % HIST_MARKS];
		json_object_begin(j);
		json_field_int(j, "t", k->t_ms);
		json_field_string(j, "robot", m->robots[k->robot].name);
		json_field_string(j, "mode", mode_name(k->mode));
		json_object_end(j);
	}
	json_array_end(j);
}

/* The per-second bins' three columns, each sent as an array of its own. */
enum frame_bin_column { FRAME_BIN_T, FRAME_BIN_COLL, FRAME_BIN_FORCE };

/* One column of the bins from `from` on: the ring (HIST_BINS, oldest
 * overwritten) walked once here, in the order the bins were closed. */
static void frame_bin_column(struct json *j, const char *key, const struct hist *h, uint64_t from,
                             enum frame_bin_column col)
{
	json_key(j, key);
	json_array_begin(j);
	for (uint64_t i = from; i < h->nbins; i++) {
		uint64_t b = i % HIST_BINS;
		if (col == FRAME_BIN_FORCE)
			json_number(j, h->bin_force[b]);
		else
			json_int(j, col == FRAME_BIN_T ? h->bin_t_ms[b] : h->bin_coll[b]);
	}
	json_array_end(j);
}

static void frame_bins(struct json *j, const struct hist *h, uint64_t from)
{
	json_key(j, "bins");
	json_object_begin(j);
	frame_bin_column(j, "t", h, from, FRAME_BIN_T);
	frame_bin_column(j, "coll", h, from, FRAME_BIN_COLL);
	frame_bin_column(j, "force", h, from, FRAME_BIN_FORCE);
	json_object_end(j);
}

static void frame_notes(struct json *j, const struct frame_note *notes, int n)
{
	json_key(j, "notes");
	json_array_begin(j);
	for (int i = 0; i < n; i++) {
		json_object_begin(j);
		json_field_int(j, "id", notes[i].id);
		json_field_int(j, "seq", notes[i].seq);
		json_field_string(j, "robot", notes[i].robot);
		json_field_string(j, "kind", notes[i].kind);
		json_field_string(j, "text", notes[i].text);
		json_object_end(j);
	}
	json_array_end(j);
}

/* ---- the world ---------------------------------------------------------------------- */

static void frame_world_robot(struct json *j, const struct top_robot *r)
{
	json_object_begin(j);
	json_field_string(j, "name", r->name);
	json_field_number(j, "lateral", r->have_body ? r->lateral : NAN);
	json_field_number(j, "neutral", r->have_body ? r->neutral : NAN);
	int nlinks = 0;
	for (int k = 0; k < TOP_MAX_LINKS; k++)
		if (r->links[k].have)
			nlinks = k + 1;
	json_key(j, "links");
	json_array_begin(j);
	for (int k = 0; k < nlinks; k++) {
		const struct top_link *l = &r->links[k];
		if (!l->have) {
			json_null(j);
			continue;
		}
		json_array_begin(j);
		json_number(j, l->x);
		json_number(j, l->y);
		json_number(j, l->angle);
		json_number(j, l->length);
		json_number(j, l->width);
		json_array_end(j);
	}
	json_array_end(j);
	json_object_end(j);
}

/* the first mark to send: new to this browser and young enough to be seen */
static uint64_t frame_marks_from(const struct wct *w, uint64_t from, int64_t now_ms)
{
	if (from < wct_oldest(w))
		from = wct_oldest(w);
	while (from < w->n && wct_at(w, from)->t_ms < now_ms - (int64_t)(WCT_SHOW_S * 1000))
		from++;
	return from;
}

enum frame_mark_field { FM_T, FM_A, FM_B, FM_X, FM_Y, FM_F, FM_IMP, FM_IMPACT };

static void frame_mark_series(struct json *j, const struct wct *w, uint64_t from, const char *key,
                              enum frame_mark_field f)
{
	json_key(j, key);
	json_array_begin(j);
	for (uint64_t i = from; i < w->n; i++) {
		const struct wct_mark *k = wct_at(w, i);
		switch (f) {
		case FM_T: json_int(j, k->t_ms); break;
		case FM_A: json_int(j, k->a); break;
		case FM_B: json_int(j, k->b); break;
		case FM_X: json_number(j, k->x); break;
		case FM_Y: json_number(j, k->y); break;
		case FM_F: json_number(j, k->force); break;
		case FM_IMP: json_number(j, k->impulse); break;
		case FM_IMPACT: json_int(j, k->impact); break;
		}
	}
	json_array_end(j);
}

static void frame_world(struct json *j, const struct hist *h, const struct top_model *m, uint64_t from)
{
	const struct top_world *w = &m->world;
	json_key(j, "world");
	json_object_begin(j);
	json_field_string(j, "kind", w->plane ? "plane" : "row");
	json_field_number(j, "wall_left", w->wall_left);
	json_field_number(j, "wall_right", w->wall_right);
	json_key(j, "walls");
	json_array_begin(j);
	for (int i = 0; i < w->nwalls && i < TOP_WORLD_WALLS; i++) {
		json_array_begin(j);
		json_number(j, w->walls[i].ax);
		json_number(j, w->walls[i].ay);
		json_number(j, w->walls[i].bx);
		json_number(j, w->walls[i].by);
		json_array_end(j);
	}
	json_array_end(j);
	json_key(j, "robots");
	json_array_begin(j);
	for (int i = 0; i < m->nrobots && i < TOP_MAX_ROBOTS; i++)
		frame_world_robot(j, &m->robots[i]);
	json_array_end(j);
	static const struct { const char *key; enum frame_mark_field f; } fields[] = {
		{ "t", FM_T }, { "a", FM_A }, { "b", FM_B }, { "x", FM_X }, { "y", FM_Y },
		{ "f", FM_F }, { "imp", FM_IMP }, { "impact", FM_IMPACT },
	};
	json_key(j, "contacts");
	json_object_begin(j);
	for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++)
		frame_mark_series(j, &h->contacts, from, fields[i].key, fields[i].f);
	json_object_end(j);
	json_object_end(j);
}

static uint64_t frame_max(uint64_t a, uint64_t b)
{
	return a > b ? a : b;
}

/* One attempt with the samples [from, h->next); 0 if it does not fit. */
static size_t frame_try(const struct hist *h, const struct top_model *m, double now, const struct frame_cursor *c,
                        uint64_t from, const struct frame_counters *srv, const struct frame_note *notes, int nnotes,
                        char *buf, size_t cap)
{
	struct json j;
	json_init_buf(&j, buf, cap, FRAME_DIGITS);
	json_object_begin(&j);
	json_field_string(&j, "type", "frame");
	int64_t now_ms = llround((now - h->t0) * 1000.0);
	json_field_int(&j, "now_ms", now_ms);
	if (c->frames % FRAME_STATUS_EVERY == 0)
		frame_status(&j, h, m, srv, now);
	frame_samples(&j, h, m, from, h->next);
	frame_marks(&j, h, m, frame_max(c->mark, hist_oldest_mark(h)));
	frame_bins(&j, h, frame_max(c->bin, hist_oldest_bin(h)));
	frame_notes(&j, notes, nnotes);
	uint64_t marks = frame_marks_from(&h->contacts, c->contact, now_ms);
	if (m->world.truths > 0 && (m->world.truths != c->truths || marks < h->contacts.n))
		frame_world(&j, h, m, marks);
	json_object_end(&j);
	/* a frame that does not fit leaves json_end false */
	return json_end(&j) ? json_len(&j) : 0;
}

size_t frame_write(const struct hist *h, const struct top_model *m, double now, struct frame_cursor *c,
                   const struct frame_counters *srv, const struct frame_note *notes, int nnotes, char *buf,
                   size_t cap)
{
	uint64_t from = frame_max(c->sample, hist_oldest(h));
	uint64_t n = h->next > from ? h->next - from : 0;
	for (;;) {
		size_t len = frame_try(h, m, now, c, h->next - n, srv, notes, nnotes, buf, cap);
		if (len > 0) {
			c->sample = h->next;
			c->bin = h->nbins;
			c->mark = h->nmarks;
			c->contact = h->contacts.n;
			c->truths = m->world.truths;
			c->frames++;
			return len;
		}
		if (n == 0)
			return 0;
		n /= 2;   /* keep the newest half */
	}
}
