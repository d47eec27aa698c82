/* model.c — see model.h. */
#include "model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void top_model_init(struct top_model *m)
{
	memset(m, 0, sizeof(*m));
}

double top_wrap(double a)
{
	if (!isfinite(a))
		return a;
	a = fmod(a, 2.0 * M_PI);
	if (a <= -M_PI)
		a += 2.0 * M_PI;
	else if (a > M_PI)
		a -= 2.0 * M_PI;
	return a;
}

const char *top_mode_name(int mode)
{
	switch (mode) {
	case UNDULATE_ROBOT_STATE_T_MODE_LIMP: return "LIMP";
	case UNDULATE_ROBOT_STATE_T_MODE_HOLD: return "HOLD";
	case UNDULATE_ROBOT_STATE_T_MODE_SINUSOID: return "SINUSOID";
	case UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR: return "OSCILLATOR";
	default: return "UNKNOWN";
	}
}

const char *top_mode_short(int mode)
{
	switch (mode) {
	case UNDULATE_ROBOT_STATE_T_MODE_LIMP: return "LIMP";
	case UNDULATE_ROBOT_STATE_T_MODE_HOLD: return "HOLD";
	case UNDULATE_ROBOT_STATE_T_MODE_SINUSOID: return "SIN";
	case UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR: return "OSC";
	default: return "?";
	}
}

int top_robot_index(const struct top_model *m, const char *name)
{
	for (int i = 0; i < m->nrobots; i++)
		if (strcmp(m->robots[i].name, name) == 0)
			return i;
	return -1;
}

/* The robot called NAME, added on first sight; NULL when the table is full
 * (counted) or the name is empty or too long. */
static struct top_robot *top_robot_get(struct top_model *m, const char *name)
{
	int i = top_robot_index(m, name);
	if (i >= 0)
		return &m->robots[i];
	if (!name || !name[0] || strlen(name) >= TOP_NAME_MAX || m->nrobots >= TOP_MAX_ROBOTS) {
		m->dropped_robots++;
		return NULL;
	}
	struct top_robot *r = &m->robots[m->nrobots];
	memset(r, 0, sizeof(*r));
	snprintf(r->name, sizeof(r->name), "%s", name);
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
			.stale_cycles = js->stale_cycles, .torque = js->torque,
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
		r->timeouts += b->servos[i].timeouts;
		r->checksum_errors += b->servos[i].checksum_errors;
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

void top_on_truth(struct top_model *m, const undulate_sim_truth_t *t, double now)
{
	m->have_sim = true;
	m->sim_rx = now;
	m->sim_total_collisions = t->total_collisions;
	m->sim_total_impulse = t->total_impulse;
	bool moved = false;
	for (int i = 0; i < t->nbodies; i++) {
		const undulate_sim_body_t *b = &t->bodies[i];
		struct top_robot *r = top_robot_get(m, b->robot);
		if (!r || (r->have_body && r->body_servo != b->servo_id))
			continue;
		moved |= !r->have_body || r->neutral != b->neutral;
		r->have_body = true;
		r->body_servo = b->servo_id;
		r->neutral = b->neutral;
		r->lateral = b->lateral;
	}
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
	if (!r->have_state || r->njoints < 2)
		return NAN;
	return top_wrap(r->j[1].phase - r->j[0].phase);
}

double top_neighbour_dphase(const struct top_model *m, int k)
{
	if (k < 0 || k + 1 >= m->nrobots)
		return NAN;
	const struct top_robot *a = &m->robots[m->order[k]], *b = &m->robots[m->order[k + 1]];
	if (!a->have_state || !b->have_state || a->njoints == 0 || b->njoints == 0)
		return NAN;
	return top_wrap(b->j[top_robot_contact_joint(b)].phase - a->j[top_robot_contact_joint(a)].phase);
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

static void top_json_str(FILE *f, const char *s)
{
	fputc('"', f);
	for (; s && *s; s++) {
		unsigned char ch = (unsigned char)*s;
		if (ch == '"' || ch == '\\')
			fprintf(f, "\\%c", ch);
		else if (ch < 0x20)
			fprintf(f, "\\u%04x", ch);
		else
			fputc(ch, f);
	}
	fputc('"', f);
}

/* "key":number (null when not finite), with a leading comma unless FIRST. */
static void top_json_num(FILE *f, const char *key, double v, bool first)
{
	fprintf(f, "%s\"%s\":", first ? "" : ",", key);
	if (isfinite(v))
		fprintf(f, "%.12g", v);
	else
		fputs("null", f);
}

static void top_json_joint(FILE *f, const struct top_joint *j)
{
	fprintf(f, "{\"servo_id\":%d", j->servo_id);
	top_json_num(f, "angle", j->angle, false);
	top_json_num(f, "speed", j->speed, false);
	top_json_num(f, "goal", j->goal, false);
	top_json_num(f, "drive", j->drive, false);
	top_json_num(f, "load", j->load, false);
	top_json_num(f, "phase", j->phase, false);
	top_json_num(f, "amplitude", j->amplitude, false);
	top_json_num(f, "frequency", j->frequency, false);
	fprintf(f, ",\"error_bits\":%d,\"stale_cycles\":%d,\"torque\":%s}", j->error_bits, j->stale_cycles,
		j->torque ? "true" : "false");
}

static void top_json_robot(FILE *f, const struct top_robot *r, double now)
{
	fputs("{\"name\":", f);
	top_json_str(f, r->name);
	fprintf(f, ",\"stale\":%s", top_robot_stale(r, now) ? "true" : "false");
	top_json_num(f, "age_s", r->have_state ? now - r->rx : NAN, false);
	fprintf(f, ",\"mode\":\"%s\",\"mode_id\":%d,\"mode_reason\":", top_mode_name(r->mode), r->mode);
	top_json_str(f, r->mode_reason);
	fprintf(f, ",\"utime\":%lld,\"cycle\":%lld,\"states\":%lld", (long long)r->utime, (long long)r->cycle,
		(long long)r->states);
	top_json_num(f, "rate_hz", top_robot_rate_hz(r), false);
	top_json_num(f, "rx_hz", top_robot_rx_hz(r, now), false);
	top_json_num(f, "jitter_p99_us", top_robot_jitter_p99(r), false);
	top_json_num(f, "jitter_max_us", top_robot_jitter_max(r), false);
	fprintf(f, ",\"overruns\":%lld,\"bus_errors\":%lld,\"bad_commands\":%lld", (long long)r->overruns,
		(long long)r->bus_errors, (long long)r->bad_commands);
	top_json_num(f, "dphase_joints", top_robot_dphase_joints(r), false);
	top_json_num(f, "neutral", r->have_body ? r->neutral : NAN, false);
	fputs(",\"joints\":[", f);
	for (int k = 0; k < r->njoints; k++) {
		if (k)
			fputc(',', f);
		top_json_joint(f, &r->j[k]);
	}
	fputc(']', f);
	if (r->have_bus)
		fprintf(f, ",\"bus\":{\"connected\":%s,\"reconnects\":%lld,\"timeouts\":%lld,\"checksum_errors\":%lld,"
			   "\"io_errors\":%lld,\"cpu_percent\":%.3f}",
			r->connected ? "true" : "false", (long long)r->reconnects, (long long)r->timeouts,
			(long long)r->checksum_errors, (long long)r->io_errors, r->cpu_percent);
	else
		fputs(",\"bus\":null", f);
	if (r->have_params) {
		fputs(",\"params\":{\"c\":[", f);
		for (int k = 0; k < r->nparams; k++)
			fprintf(f, "%s%.12g", k ? "," : "", r->c[k]);
		fputs("]", f);
		top_json_num(f, "amplitude", r->sin_amplitude, false);
		top_json_num(f, "frequency", r->sin_frequency, false);
		fputc('}', f);
	} else {
		fputs(",\"params\":null", f);
	}
	fputs(",\"last_event\":", f);
	top_json_str(f, r->last_event);
	fputc('}', f);
}

void top_json(const struct top_model *m, double now, int64_t wall_utime, FILE *f)
{
	int stale = 0;
	for (int i = 0; i < m->nrobots; i++)
		stale += top_robot_stale(&m->robots[i], now);
	fprintf(f, "{\"utime\":%lld,\"nrobots\":%d,\"stale\":%d,\"order\":\"%s\",\"robots\":[", (long long)wall_utime,
		m->nrobots, stale, m->order_lateral ? "lateral" : "name");
	for (int k = 0; k < m->nrobots; k++) {
		if (k)
			fputc(',', f);
		top_json_robot(f, &m->robots[m->order[k]], now);
	}
	fputs("],\"neighbours\":[", f);
	for (int k = 0; k + 1 < m->nrobots; k++) {
		fprintf(f, "%s{\"a\":", k ? "," : "");
		top_json_str(f, m->robots[m->order[k]].name);
		fputs(",\"b\":", f);
		top_json_str(f, m->robots[m->order[k + 1]].name);
		top_json_num(f, "dphase", top_neighbour_dphase(m, k), false);
		fputc('}', f);
	}
	double imp = 0;
	int n = top_collisions_window(m, now, &imp);
	fprintf(f, "],\"sim\":{\"present\":%s,\"heard\":%s,\"collisions_10s\":%d", top_sim_present(m, now) ? "true" : "false",
		m->have_sim ? "true" : "false", n);
	top_json_num(f, "impulse_10s", imp, false);
	fprintf(f, ",\"collisions_heard\":%lld", (long long)m->collisions_heard);
	top_json_num(f, "impulse_heard", m->impulse_heard, false);
	fprintf(f, ",\"total_collisions\":%lld", (long long)m->sim_total_collisions);
	top_json_num(f, "total_impulse", m->sim_total_impulse, false);
	fprintf(f, "},\"dropped_robots\":%lld,\"decode_errors\":%lld}\n", (long long)m->dropped_robots,
		(long long)m->decode_errors);
}
