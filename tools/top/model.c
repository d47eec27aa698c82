/* model.c — see model.h. */
#include "model.h"
#include "dxl.h"
#include "dxl2_table.h"
#include "json.h"
#include "modes.h"
#include "num.h"
#include "phase.h"
#include "text.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void top_model_init(struct top_model *m)
{
	memset(m, 0, sizeof(*m));
	m->world.wall_left = m->world.wall_right = NAN;
}

int top_robot_index(const struct top_model *m, const char *name)
{
	for (int i = 0; i < m->nrobots; i++)
		if (strcmp(m->robots[i].name, name) == 0)
			return i;
	return -1;
}

/* The robot called NAME, added on first sight; NULL (counted) when the table
 * is full or NAME is not a robot's name: '*' would be a robot whose commands
 * go to every robot, a control character or a space would reach the screen
 * and the page, and none of them is a name a daemon may take. */
static struct top_robot *top_robot_get(struct top_model *m, const char *name)
{
	if (!text_is_name(name, TOP_NAME_MAX - 1)) {
		m->dropped_robots++;
		return NULL;
	}
	int i = top_robot_index(m, name);
	if (i >= 0)
		return &m->robots[i];
	if (m->nrobots >= TOP_MAX_ROBOTS) {
		m->dropped_robots++;
		return NULL;
	}
	struct top_robot *r = &m->robots[m->nrobots];
	memset(r, 0, sizeof(*r));
	snprintf(r->name, sizeof(r->name), "%s", name);
	r->lever = NAN;
	m->order[m->nrobots] = m->nrobots;
	m->nrobots++;
	top_model_order(m);
	return r;
}

static void top_copy_text(char *dst, const char *src)
{
	snprintf(dst, TOP_TEXT_MAX, "%s", src ? src : "");
}

void top_on_state(struct top_model *m, const undulate_robot_state_t *s, double now)
{
	struct top_robot *r = top_robot_get(m, s->robot);
	if (!r)
		return;
	r->have_state = true;
	r->rx = now;
	r->utime = s->utime;
	r->cycle = s->cycle;
	r->mode = s->mode;
	top_copy_text(r->mode_reason, s->mode_reason);
	top_copy_text(r->fault, s->fault);
	r->period_us[r->winnext] = s->period_us;
	r->jitter_us[r->winnext] = s->jitter_us;
	r->rx_times[r->winnext] = now;
	r->winnext = (r->winnext + 1) % TOP_WINDOW;
	if (r->nwin < TOP_WINDOW)
		r->nwin++;
	r->overruns = s->overruns;
	r->bus_errors = s->bus_errors;
	r->bad_commands = s->bad_commands;
	r->states++;
	r->njoints = s->njoints < TOP_MAX_JOINTS ? s->njoints : TOP_MAX_JOINTS;
	for (int k = 0; k < r->njoints; k++) {
		const undulate_joint_state_t *js = &s->joints[k];
		r->j[k] = (struct top_joint){
			.servo_id = js->servo_id, .angle = js->angle, .speed = js->speed, .goal = js->goal, .drive = js->drive,
			.load = js->load, .phase = js->phase, .amplitude = js->amplitude,
			.frequency = js->frequency, .error_bits = js->error_bits,
			.temperature = js->temperature, .voltage = js->voltage,
			.stale_cycles = js->stale_cycles, .torque = js->torque,
			/* anything but the servo's 0 or 1 is "not read" */
			.torque_read = js->torque_read == 0 || js->torque_read == 1 ? js->torque_read : -1,
		};
	}
}

void top_on_bus(struct top_model *m, const undulate_bus_stats_t *b)
{
	struct top_robot *r = top_robot_get(m, b->robot);
	if (!r)
		return;
	r->have_bus = true;
	r->connected = b->connected;
	r->reconnects = b->reconnects;
	r->cpu_percent = b->cpu_percent;
	r->adapter_latency_ms = b->adapter_latency_ms;
	r->io_errors = b->io_errors;
	r->timeouts = r->checksum_errors = 0;
	for (int i = 0; i < b->nservos; i++) {
		r->timeouts = num_count_add(r->timeouts, b->servos[i].timeouts);
		r->checksum_errors = num_count_add(r->checksum_errors, b->servos[i].checksum_errors);
	}
}

void top_on_params(struct top_model *m, const undulate_osc_params_t *p)
{
	struct top_robot *r = top_robot_get(m, p->robot);
	if (!r)
		return;
	r->have_params = true;
	r->nparams = p->njoints < TOP_MAX_JOINTS ? p->njoints : TOP_MAX_JOINTS;
	for (int k = 0; k < r->nparams; k++) {
		r->c[k] = p->c[k];
		r->mu[k] = p->mu[k];
		r->k[k] = p->k[k];
	}
	r->sin_amplitude = p->amplitude;
	r->sin_frequency = p->frequency;
}

void top_on_event(struct top_model *m, const undulate_event_t *e)
{
	struct top_robot *r = top_robot_get(m, e->robot);
	if (!r)
		return;
	snprintf(r->last_event, sizeof(r->last_event), "%s: %s", e->kind ? e->kind : "", e->text ? e->text : "");
	r->last_event_seq = e->seq;
	r->last_event_level = e->level;
}

static bool top_seen_before(struct top_model *m, const undulate_sim_collision_t *c)
{
	for (int i = 0; i < TOP_COLL_DEDUP; i++)
		if (m->seen[i].utime == c->utime && m->seen[i].left == c->left && m->seen[i].right == c->right)
			return true;
	m->seen[m->seennext] = (struct top_seen){ c->utime, c->left, c->right };
	m->seennext = (m->seennext + 1) % TOP_COLL_DEDUP;
	return false;
}

void top_on_collision(struct top_model *m, const undulate_sim_collision_t *c, double now)
{
	m->have_sim = true;
	m->sim_rx = now;
	if (top_seen_before(m, c))
		return;
	m->collisions_heard++;
	m->impulse_heard += c->impulse;
	m->coll_rx[m->collnext] = now;
	m->coll_impulse[m->collnext] = c->impulse;
	m->collnext = (m->collnext + 1) % TOP_COLL_RING;
	if (m->ncoll < TOP_COLL_RING)
		m->ncoll++;
}

void top_on_sim_collision(struct top_model *m, const undulate_sim_collision_t *c, double now)
{
	m->coll_direct_rx = now;
	top_on_collision(m, c, now);
}

/* Angle (rad) a body's joint must be deflected by before its lever
 * (lateral offset per radian) is estimated from it. */
#define TOP_LEVER_MIN_ANGLE 0.2

static void top_trend_update(struct top_model *m, const undulate_sim_truth_t *t, double now)
{
	if (!isfinite(t->total_impulse) || t->total_impulse < 0)
		return; /* a broken total would poison every window after it */
	if (m->trend_t0 <= 0 || t->total_collisions < m->trend_coll0 || t->total_impulse < m->trend_imp0) {
		/* first message, or a restarted simulator: a new first window */
		m->trend_t0 = now;
		m->trend_coll0 = t->total_collisions;
		m->trend_imp0 = t->total_impulse;
		return;
	}
	double dt = now - m->trend_t0;
	if (dt < TOP_TREND_S)
		return;
	m->trend_coll[m->trendnext] = t->total_collisions - m->trend_coll0;
	m->trend_force[m->trendnext] = (t->total_impulse - m->trend_imp0) / dt;
	m->trendnext = (m->trendnext + 1) % TOP_TREND_N;
	if (m->ntrend < TOP_TREND_N)
		m->ntrend++;
	m->trend_t0 = now;
	m->trend_coll0 = t->total_collisions;
	m->trend_imp0 = t->total_impulse;
}

int top_trend(const struct top_model *m, int64_t *coll, double *force, int n)
{
	int have = m->ntrend < n ? m->ntrend : n;
	for (int i = 0; i < have; i++) {
		int k = (m->trendnext - have + i + TOP_TREND_N) % TOP_TREND_N;
		coll[i] = m->trend_coll[k];
		force[i] = m->trend_force[k];
	}
	return have;
}

/* ---- the world (SIM.TRUTH's links, walls and contacts) ----------------------------- */

/* A coordinate of a place in an arena. */
static bool top_world_place(double v)
{
	return isfinite(v) && fabs(v) <= TOP_WORLD_EXTENT_M;
}

static bool top_world_size(double v)
{
	return isfinite(v) && v > 0 && v <= TOP_WORLD_SIZE_M;
}

/* The model's robot of body index i of the message (-1: none: outside
 * bodies[], beyond what is mapped, or not a robot's name). */
static int top_world_robot(const int *body_robot, int nbodies, int i)
{
	if (i < 0 || i >= nbodies || i >= TOP_WORLD_BODIES)
		return -1;
	return body_robot[i];
}

static void top_world_links(struct top_model *m, const undulate_sim_truth_t *t, const int *body_robot)
{
	struct top_world *w = &m->world;
	for (int i = 0; i < m->nrobots; i++)
		for (int k = 0; k < TOP_MAX_LINKS; k++)
			m->robots[i].links[k].have = false;
	for (int i = 0; i < t->nlinks; i++) {
		const undulate_sim_link_t *l = &t->links[i];
		int r = top_world_robot(body_robot, t->nbodies, l->robot);
		if (r < 0 || l->link < 0 || l->link >= TOP_MAX_LINKS) {
			w->bad_index++;
			continue;
		}
		if (!top_world_place(l->x) || !top_world_place(l->y) || !isfinite(l->angle) ||
		    !top_world_size(l->length) || !top_world_size(l->width)) {
			w->bad_number++;
			continue;
		}
		m->robots[r].links[l->link] = (struct top_link){ .have = true, .x = l->x, .y = l->y,
			.angle = remainder(l->angle, 2 * M_PI), .length = l->length, .width = l->width };
	}
}

static void top_world_walls(struct top_world *w, const undulate_sim_truth_t *t)
{
	/* the row's walls: none when wall_left >= wall_right (sim-bridge/world.h) */
	bool walls = top_world_place(t->wall_left) && top_world_place(t->wall_right) && t->wall_left < t->wall_right;
	if (!walls && (!isfinite(t->wall_left) || !isfinite(t->wall_right)))
		w->bad_number++;
	w->wall_left = walls ? t->wall_left : NAN;
	w->wall_right = walls ? t->wall_right : NAN;
	w->nwalls = 0;
	for (int i = 0; i < t->nwalls; i++) {
		const undulate_sim_wall_t *s = &t->walls[i];
		if (!top_world_place(s->ax) || !top_world_place(s->ay) || !top_world_place(s->bx) ||
		    !top_world_place(s->by)) {
			w->bad_number++;
		} else if (w->nwalls == TOP_WORLD_WALLS) {
			w->overflow++;
		} else {
			w->walls[w->nwalls].ax = s->ax;
			w->walls[w->nwalls].ay = s->ay;
			w->walls[w->nwalls].bx = s->bx;
			w->walls[w->nwalls].by = s->by;
			w->nwalls++;
		}
	}
}

/* The contact's indices checked and mapped into out; false: refused (counted). */
static bool top_world_contact(struct top_world *w, const undulate_sim_truth_t *t, const int *body_robot,
                              const undulate_sim_contact_t *c, struct top_contact *out)
{
	int a = top_world_robot(body_robot, t->nbodies, c->robot_a);
	int b = c->robot_b == -1 ? -1 : top_world_robot(body_robot, t->nbodies, c->robot_b);
	/* a wall's link is its index in walls[] (the plane) or -1 (the row) */
	bool link_b_ok = c->robot_b == -1 ? c->link_b >= -1 && c->link_b < t->nwalls
	                                  : c->link_b >= 0 && c->link_b < TOP_MAX_LINKS;
	if (a < 0 || (c->robot_b != -1 && b < 0) || c->link_a < 0 || c->link_a >= TOP_MAX_LINKS || !link_b_ok) {
		w->bad_index++;
		return false;
	}
	if (!top_world_place(c->x) || !top_world_place(c->y) || !isfinite(c->impulse) || c->impulse < 0 ||
	    !isfinite(c->force) || c->force < 0) {
		w->bad_number++;
		return false;
	}
	bool normal = isfinite(c->nx) && isfinite(c->ny);
	*out = (struct top_contact){ .a = a, .b = b, .link_a = c->link_a, .link_b = c->link_b, .x = c->x, .y = c->y,
		.nx = normal ? c->nx : 0, .ny = normal ? c->ny : 0, .impulse = c->impulse, .force = c->force,
		.impact = c->impact != 0 };
	return true;
}

static void top_world_contacts(struct top_world *w, const undulate_sim_truth_t *t, const int *body_robot)
{
	w->ncontacts = 0;
	for (int i = 0; i < t->ncontacts; i++) {
		struct top_contact c;
		if (!top_world_contact(w, t, body_robot, &t->contacts[i], &c))
			continue;
		if (w->ncontacts == TOP_WORLD_CONTACTS) {
			w->overflow++;
			continue;
		}
		w->contacts[w->ncontacts++] = c;
	}
}

static void top_world_update(struct top_model *m, const undulate_sim_truth_t *t, const int *body_robot)
{
	struct top_world *w = &m->world;
	w->truths++;
	w->plane = t->world == UNDULATE_SIM_TRUTH_T_WORLD_PLANE;
	top_world_links(m, t, body_robot);
	top_world_walls(w, t);
	top_world_contacts(w, t, body_robot);
}

void top_on_truth(struct top_model *m, const undulate_sim_truth_t *t, double now)
{
	m->have_sim = true;
	m->sim_rx = now;
	m->sim_total_collisions = t->total_collisions;
	m->sim_total_impulse = t->total_impulse;
	bool moved = false;
	/* the model's robot of each body, for the links and contacts that name bodies by index */
	int body_robot[TOP_WORLD_BODIES];
	for (int i = 0; i < t->nbodies; i++) {
		const undulate_sim_body_t *b = &t->bodies[i];
		struct top_robot *r = top_robot_get(m, b->robot);
		if (i < TOP_WORLD_BODIES)
			body_robot[i] = r ? (int)(r - m->robots) : -1;
		if (!r || (r->have_body && r->body_servo != b->servo_id))
			continue;
		moved |= !r->have_body || r->neutral != b->neutral;
		r->have_body = true;
		r->body_servo = b->servo_id;
		r->neutral = b->neutral;
		r->lateral = b->lateral;
		/* the lever from a clearly deflected joint (small angles divide noise) */
		if (fabs(b->angle) > TOP_LEVER_MIN_ANGLE)
			r->lever = (b->lateral - b->neutral) / b->angle;
	}
	top_world_update(m, t, body_robot);
	top_trend_update(m, t, now);
	/* SIM.COLLISION is the per-collision channel; the copies inside
	 * SIM.TRUTH (stamped with the truth message's time, so not matchable)
	 * count only while no SIM.COLLISION is heard. */
	bool direct = m->coll_direct_rx > 0 && now - m->coll_direct_rx <= TOP_SIM_STALE_S;
	for (int i = 0; i < t->ncollisions && !direct; i++)
		top_on_collision(m, &t->collisions[i], now);
	if (moved)
		top_model_order(m);
}

static bool top_before(const struct top_model *m, int a, int b)
{
	const struct top_robot *ra = &m->robots[a], *rb = &m->robots[b];
	if (m->order_lateral && ra->neutral != rb->neutral)
		return ra->neutral < rb->neutral;
	return strcmp(ra->name, rb->name) < 0;
}

void top_model_order(struct top_model *m)
{
	m->order_lateral = m->have_sim;
	for (int i = 0; i < m->nrobots; i++)
		if (!m->robots[i].have_body && m->robots[i].have_state)
			m->order_lateral = false;
	/* insertion sort: few robots, and nearly sorted on every call */
	for (int i = 0; i < m->nrobots; i++)
		m->order[i] = i;
	for (int i = 1; i < m->nrobots; i++) {
		int v = m->order[i], k = i;
		while (k > 0 && top_before(m, v, m->order[k - 1])) {
			m->order[k] = m->order[k - 1];
			k--;
		}
		m->order[k] = v;
	}
}

bool top_joint_silent(const struct top_joint *j)
{
	return j->stale_cycles > 0;
}

int top_robot_silent_joints(const struct top_robot *r)
{
	int n = 0;
	for (int k = 0; k < r->njoints; k++)
		n += top_joint_silent(&r->j[k]);
	return n;
}

char *top_errbits_format(int16_t bits, char *buf, size_t cap)
{
	uint8_t low = (uint8_t)(bits & 0x7F);
	if (low == 0)
		snprintf(buf, cap, "%s", "");
	else if (bits & UNDULATE_JOINT_STATE_T_ERROR_BITS_X)
		dxl2_hwerr_format(low, buf, cap);
	else
		dxl_errbits_format(low, buf, cap);
	return buf;
}

const char *top_joint_status(const struct top_joint *j, char *buf, size_t cap)
{
	if (top_joint_silent(j))
		snprintf(buf, cap, "SILENT x%d", (int)j->stale_cycles);
	else if (j->error_bits & 0x7F)
		top_errbits_format(j->error_bits, buf, cap);
	else
		snprintf(buf, cap, "ok");
	return buf;
}

bool top_joint_torque_differs(const struct top_joint *j)
{
	return j->torque_read >= 0 && (j->torque_read == 1) != j->torque;
}

const char *top_joint_torque(const struct top_joint *j)
{
	if (j->torque_read < 0)
		return j->torque ? "on (wanted; not read yet)" : "off (wanted; not read yet)";
	if (top_joint_torque_differs(j))
		return j->torque ? "off (wanted on)" : "on (wanted off)";
	return j->torque_read ? "on" : "off";
}

bool top_robot_stale(const struct top_robot *r, double now)
{
	return !r->have_state || now - r->rx > TOP_STALE_S;
}

double top_robot_rate_hz(const struct top_robot *r)
{
	double sum = 0;
	int n = 0;
	for (int i = 0; i < r->nwin; i++)
		if (r->period_us[i] > 0 && isfinite(r->period_us[i])) {
			sum += r->period_us[i];
			n++;
		}
	return n ? 1e6 * n / sum : NAN;
}

double top_robot_rx_hz(const struct top_robot *r, double now)
{
	int n = 0;
	for (int i = 0; i < r->nwin; i++)
		if (now - r->rx_times[i] <= 1.0)
			n++;
	return (double)n;
}

static int top_cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

double top_robot_jitter_p99(const struct top_robot *r)
{
	double v[TOP_WINDOW];
	if (r->nwin == 0)
		return NAN;
	memcpy(v, r->jitter_us, sizeof(double) * (size_t)r->nwin);
	qsort(v, (size_t)r->nwin, sizeof(double), top_cmp_double);
	/* nearest-rank p99: with 100 samples the largest but one */
	int idx = (int)ceil(0.99 * r->nwin) - 1;
	return v[idx < 0 ? 0 : idx];
}

double top_robot_jitter_max(const struct top_robot *r)
{
	double mx = NAN;
	for (int i = 0; i < r->nwin; i++)
		if (isnan(mx) || r->jitter_us[i] > mx)
			mx = r->jitter_us[i];
	return mx;
}

int top_robot_contact_joint(const struct top_robot *r)
{
	if (r->have_body)
		for (int k = 0; k < r->njoints; k++)
			if (r->j[k].servo_id == r->body_servo)
				return k;
	return 0;
}

double top_robot_dphase_joints(const struct top_robot *r)
{
	/* a silent joint's phase is frozen: no difference to show */
	if (!r->have_state || r->njoints < 2 || top_joint_silent(&r->j[0]) || top_joint_silent(&r->j[1]))
		return NAN;
	return phase_wrap(r->j[1].phase - r->j[0].phase);
}

double top_neighbour_dphase(const struct top_model *m, int k)
{
	if (k < 0 || k + 1 >= m->nrobots)
		return NAN;
	const struct top_robot *a = &m->robots[m->order[k]], *b = &m->robots[m->order[k + 1]];
	if (!a->have_state || !b->have_state || a->njoints == 0 || b->njoints == 0)
		return NAN;
	const struct top_joint *ja = &a->j[top_robot_contact_joint(a)], *jb = &b->j[top_robot_contact_joint(b)];
	if (top_joint_silent(ja) || top_joint_silent(jb))
		return NAN;
	return phase_wrap(jb->phase - ja->phase);
}

double top_pair_bound(const struct top_model *m, int k)
{
	if (k < 0 || k + 1 >= m->nrobots)
		return NAN;
	const struct top_robot *a = &m->robots[m->order[k]], *b = &m->robots[m->order[k + 1]];
	if (!a->have_body || !b->have_body || !a->have_state || !b->have_state || a->njoints == 0 || b->njoints == 0)
		return NAN;
	double lever = 0.5 * (a->lever + b->lever);
	double amp = 0.5 * (a->j[top_robot_contact_joint(a)].amplitude + b->j[top_robot_contact_joint(b)].amplitude);
	if (!(fabs(lever) > 0) || !(amp > 0))
		return NAN;
	double d = fabs(b->neutral - a->neutral) / (2.0 * fabs(lever) * amp);
	return d >= 1.0 ? M_PI : 2.0 * asin(d);
}

int top_collisions_window(const struct top_model *m, double now, double *impulse)
{
	int n = 0;
	double imp = 0;
	for (int i = 0; i < m->ncoll; i++)
		if (now - m->coll_rx[i] <= TOP_COLL_WINDOW_S) {
			n++;
			imp += m->coll_impulse[i];
		}
	if (impulse)
		*impulse = imp;
	return n;
}

bool top_sim_present(const struct top_model *m, double now)
{
	return m->have_sim && now - m->sim_rx <= TOP_SIM_STALE_S;
}

/* ---- JSON --------------------------------------------------------------------- */

static void top_json_joint(struct json *j, const struct top_joint *jt)
{
	json_object_begin(j);
	json_field_int(j, "servo_id", jt->servo_id);
	json_field_number(j, "angle", jt->angle);
	json_field_number(j, "speed", jt->speed);
	json_field_number(j, "goal", jt->goal);
	json_field_number(j, "drive", jt->drive);
	json_field_number(j, "load", jt->load);
	json_field_number(j, "phase", jt->phase);
	json_field_number(j, "amplitude", jt->amplitude);
	json_field_number(j, "frequency", jt->frequency);
	json_field_int(j, "error_bits", jt->error_bits);
	json_field_int(j, "stale_cycles", jt->stale_cycles);
	json_field_number(j, "temperature", jt->temperature);
	json_field_number(j, "voltage", jt->voltage);
	char status[96];
	json_field_string(j, "status", top_joint_status(jt, status, sizeof status));
	json_field_bool(j, "torque", jt->torque);
	json_field_int(j, "torque_read", jt->torque_read);
	json_object_end(j);
}

static void top_json_bus(struct json *j, const struct top_robot *r)
{
	json_key(j, "bus");
	if (!r->have_bus) {
		json_null(j);
		return;
	}
	json_object_begin(j);
	json_field_bool(j, "connected", r->connected);
	json_field_int(j, "reconnects", r->reconnects);
	json_field_int(j, "timeouts", r->timeouts);
	json_field_int(j, "checksum_errors", r->checksum_errors);
	json_field_int(j, "io_errors", r->io_errors);
	json_field_number(j, "cpu_percent", r->cpu_percent);
	json_object_end(j);
}

static void top_json_params(struct json *j, const struct top_robot *r)
{
	json_key(j, "params");
	if (!r->have_params) {
		json_null(j);
		return;
	}
	json_object_begin(j);
	json_key(j, "c");
	json_array_begin(j);
	for (int k = 0; k < r->nparams; k++)
		json_number(j, r->c[k]);
	json_array_end(j);
	json_field_number(j, "amplitude", r->sin_amplitude);
	json_field_number(j, "frequency", r->sin_frequency);
	json_object_end(j);
}

static void top_json_robot(struct json *j, const struct top_robot *r, double now)
{
	json_object_begin(j);
	json_field_string(j, "name", r->name);
	json_field_bool(j, "stale", top_robot_stale(r, now));
	json_field_number(j, "age_s", r->have_state ? now - r->rx : NAN);
	json_field_string(j, "mode", mode_name(r->mode));
	json_field_int(j, "mode_id", r->mode);
	json_field_string(j, "mode_reason", r->mode_reason);
	json_field_string(j, "fault", r->fault);
	json_field_int(j, "utime", r->utime);
	json_field_int(j, "cycle", r->cycle);
	json_field_int(j, "states", r->states);
	json_field_number(j, "rate_hz", top_robot_rate_hz(r));
	json_field_number(j, "rx_hz", top_robot_rx_hz(r, now));
	json_field_number(j, "jitter_p99_us", top_robot_jitter_p99(r));
	json_field_number(j, "jitter_max_us", top_robot_jitter_max(r));
	json_field_int(j, "overruns", r->overruns);
	json_field_int(j, "bus_errors", r->bus_errors);
	json_field_int(j, "bad_commands", r->bad_commands);
	json_field_number(j, "dphase_joints", top_robot_dphase_joints(r));
	json_field_number(j, "neutral", r->have_body ? r->neutral : NAN);
	json_key(j, "joints");
	json_array_begin(j);
	for (int k = 0; k < r->njoints; k++)
		top_json_joint(j, &r->j[k]);
	json_array_end(j);
	top_json_bus(j, r);
	top_json_params(j, r);
	json_field_string(j, "last_event", r->last_event);
	json_object_end(j);
}

static void top_json_sim(struct json *j, const struct top_model *m, double now)
{
	double imp = 0;
	int n = top_collisions_window(m, now, &imp);
	json_key(j, "sim");
	json_object_begin(j);
	json_field_bool(j, "present", top_sim_present(m, now));
	json_field_bool(j, "heard", m->have_sim);
	json_field_int(j, "collisions_10s", n);
	json_field_number(j, "impulse_10s", imp);
	json_field_int(j, "collisions_heard", m->collisions_heard);
	json_field_number(j, "impulse_heard", m->impulse_heard);
	json_field_int(j, "total_collisions", m->sim_total_collisions);
	json_field_number(j, "total_impulse", m->sim_total_impulse);
	json_object_end(j);
}

void top_json(const struct top_model *m, double now, int64_t wall_utime, FILE *f)
{
	struct json j;
	int stale = 0;
	for (int i = 0; i < m->nrobots; i++)
		stale += top_robot_stale(&m->robots[i], now);
	json_init(&j, f, TOP_JSON_DIGITS);
	json_object_begin(&j);
	json_field_int(&j, "utime", wall_utime);
	json_field_int(&j, "nrobots", m->nrobots);
	json_field_int(&j, "stale", stale);
	json_field_string(&j, "order", m->order_lateral ? "lateral" : "name");
	json_key(&j, "robots");
	json_array_begin(&j);
	for (int k = 0; k < m->nrobots; k++)
		top_json_robot(&j, &m->robots[m->order[k]], now);
	json_array_end(&j);
	json_key(&j, "neighbours");
	json_array_begin(&j);
	for (int k = 0; k + 1 < m->nrobots; k++) {
		json_object_begin(&j);
		json_field_string(&j, "a", m->robots[m->order[k]].name);
		json_field_string(&j, "b", m->robots[m->order[k + 1]].name);
		json_field_number(&j, "dphase", top_neighbour_dphase(m, k));
		json_object_end(&j);
	}
	json_array_end(&j);
	top_json_sim(&j, m, now);
	json_field_int(&j, "dropped_robots", m->dropped_robots);
	json_field_int(&j, "decode_errors", m->decode_errors);
	json_object_end(&j);
	fputc('\n', f);
}
