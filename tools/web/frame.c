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

static void frame_status(struct json *j, const struct top_model *m, const struct frame_counters *srv, double now)
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

static void frame_bins(struct json *j, const struct hist *h, uint64_t from)
{
	json_key(j, "bins");
	json_object_begin(j);
	json_key(j, "t");
	json_array_begin(j);
	for (uint64_t i = from; i < h->nbins; i++)
		json_int(j, h->bin_t_ms[i % HIST_BINS]);
	json_array_end(j);
	json_key(j, "coll");
	json_array_begin(j);
	for (uint64_t i = from; i < h->nbins; i++)
		json_int(j, h->bin_coll[i % HIST_BINS]);
	json_array_end(j);
	json_key(j, "force");
	json_array_begin(j);
	for (uint64_t i = from; i < h->nbins; i++)
		json_number(j, h->bin_force[i % HIST_BINS]);
	json_array_end(j);
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

static uint64_t frame_max(uint64_t a, uint64_t b)
{
	return a > b ? a : b;
}

/* One attempt with the samples [from, h->next); 0 if it does not fit. */
static size_t frame_try(const struct hist *h, const struct top_model *m, double now, const struct frame_cursor *c,
                        uint64_t from, const struct frame_counters *srv, const struct frame_note *notes, int nnotes,
                        char *buf, size_t cap)
{
	FILE *f = fmemopen(buf, cap, "w");
	if (f == NULL)
		return 0;
	setvbuf(f, NULL, _IONBF, 0);
	struct json j;
	json_init(&j, f, FRAME_DIGITS);
	json_object_begin(&j);
	json_field_string(&j, "type", "frame");
	json_field_int(&j, "now_ms", (long long)llround((now - h->t0) * 1000.0));
	if (c->frames % FRAME_STATUS_EVERY == 0)
		frame_status(&j, m, srv, now);
	frame_samples(&j, h, m, from, h->next);
	frame_marks(&j, h, m, frame_max(c->mark, hist_oldest_mark(h)));
	frame_bins(&j, h, frame_max(c->bin, hist_oldest_bin(h)));
	frame_notes(&j, notes, nnotes);
	json_object_end(&j);
	bool ok = json_end(&j);
	long len = ftell(f);
	fclose(f);
	/* fmemopen in "w" mode keeps a NUL after the data: a full buffer
	 * holds cap - 1 bytes of it */
	return ok && len > 0 && (size_t)len < cap ? (size_t)len : 0;
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
			c->frames++;
			return len;
		}
		if (n == 0)
			return 0;
		n /= 2;   /* keep the newest half */
	}
}
