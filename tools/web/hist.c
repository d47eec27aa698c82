/* hist.c — see hist.h. */
#include "hist.h"

#include <math.h>
#include <string.h>

#include "tools/analyze/classify.h"
#include "tools/analyze/analyze.h"

void hist_init(struct hist *h, double now)
{
	memset(h, 0, sizeof *h);
	h->t0 = now;
	for (int i = 0; i < TOP_MAX_ROBOTS; i++) {
		h->pair_of[i] = -1;
		h->last_mode[i] = -1;
	}
	wct_init(&h->contacts);
}

uint64_t hist_oldest(const struct hist *h)
{
	return h->next > HIST_N ? h->next - HIST_N : 0;
}

uint64_t hist_oldest_bin(const struct hist *h)
{
	return h->nbins > HIST_BINS ? h->nbins - HIST_BINS : 0;
}

uint64_t hist_oldest_mark(const struct hist *h)
{
	return h->nmarks > HIST_MARKS ? h->nmarks - HIST_MARKS : 0;
}

static int64_t hist_ms(const struct hist *h, double now)
{
	return (int64_t)llround((now - h->t0) * 1000.0);
}

/* The slot of pair (a, b): the one it had, a free one, or the one unused
 * longest (a pair that stopped being neighbours long ago). */
static int hist_pair_slot(struct hist *h, int a, int b)
{
	int free_slot = -1, oldest = -1;
	for (int i = 0; i < HIST_PAIRS; i++) {
		struct hist_pair *p = &h->pairs[i];
		if (p->used && p->a == a && p->b == b)
			return i;
		if (!p->used && free_slot < 0)
			free_slot = i;
		if (p->used && (oldest < 0 || p->last_use < h->pairs[oldest].last_use))
			oldest = i;
	}
	int s = free_slot >= 0 ? free_slot : oldest;
	struct hist_pair *p = &h->pairs[s];
	p->used = true;
	p->a = a;
	p->b = b;
	p->first = h->next;
	p->ncoll = p->collnext = 0;
	p->cls = "no-data";
	return s;
}

static void hist_sample_robots(struct hist *h, const struct top_model *m, int s, int64_t t_ms, double now)
{
	for (int i = 0; i < m->nrobots && i < TOP_MAX_ROBOTS; i++) {
		const struct top_robot *r = &m->robots[i];
		if (i >= h->nrobots) {
			h->robot_first[i] = h->next;
			h->nrobots = i + 1;
		}
		for (int j = 0; j < TOP_MAX_JOINTS; j++) {
			bool live = r->have_state && now - r->rx < HIST_GAP_S && j < r->njoints &&
			            !top_joint_silent(&r->j[j]);
			h->angle[i][j][s] = live ? (float)r->j[j].angle : NAN;
			h->speed[i][j][s] = live ? (float)r->j[j].speed : NAN;
		}
		if (r->have_state && r->mode != h->last_mode[i]) {
			/* a robot's first mode is its start, not a switch */
			if (h->last_mode[i] >= 0) {
				struct hist_mark *k = &h->marks[h->nmarks % HIST_MARKS];
				k->t_ms = t_ms;
				k->robot = i;
				k->mode = r->mode;
				h->nmarks++;
			}
			h->last_mode[i] = r->mode;
		}
	}
}

static void hist_sample_pairs(struct hist *h, const struct top_model *m, int s)
{
	for (int i = 0; i < TOP_MAX_ROBOTS; i++)
		h->pair_of[i] = -1;
	h->npairs_now = m->nrobots > 1 ? m->nrobots - 1 : 0;
	for (int k = 0; k < h->npairs_now; k++) {
		int slot = hist_pair_slot(h, m->order[k], m->order[k + 1]);
		struct hist_pair *p = &h->pairs[slot];
		h->pair_of[k] = slot;
		p->last_use = h->next;
		p->delta[s] = (float)top_neighbour_dphase(m, k);
		p->bound[s] = (float)top_pair_bound(m, k);
	}
}

static void hist_sample_sim(struct hist *h, const struct top_model *m, double now)
{
	if (!m->have_sim || !isfinite(m->sim_total_impulse))
		return;
	if (h->bin_t0 <= 0 || m->sim_total_collisions < h->bin_coll0 || m->sim_total_impulse < h->bin_imp0) {
		/* first totals, or a restarted simulator */
		h->bin_t0 = now;
		h->bin_coll0 = m->sim_total_collisions;
		h->bin_imp0 = m->sim_total_impulse;
		return;
	}
	double dt = now - h->bin_t0;
	if (dt < HIST_BIN_S)
		return;
	int s = (int)(h->nbins % HIST_BINS);
	h->bin_t_ms[s] = hist_ms(h, now);
	h->bin_coll[s] = (int32_t)(m->sim_total_collisions - h->bin_coll0);
	h->bin_force[s] = (float)((m->sim_total_impulse - h->bin_imp0) / dt);
	h->nbins++;
	h->bin_t0 = now;
	h->bin_coll0 = m->sim_total_collisions;
	h->bin_imp0 = m->sim_total_impulse;
}

/* The contact joint's angle ring of robot r: the joint the phase difference
 * is taken on (undulate-top's choice). */
static const float *hist_contact_angles(const struct hist *h, const struct top_model *m, int r)
{
	int j = top_robot_contact_joint(&m->robots[r]);
	if (j < 0 || j >= TOP_MAX_JOINTS)
		j = 0;
	return h->angle[r][j];
}

/* undulate-analyze's end state over the last HIST_CLASS_S of the pair. */
static void hist_classify(struct hist *h, const struct top_model *m, struct hist_pair *p, double now)
{
	struct cls_window w = { .min_swing = AN_MIN_SWING_DEFAULT, .have_sim = m->have_sim, .dsep = NAN };
	struct win_swing sa, sb;
	win_swing_init(&sa);
	win_swing_init(&sb);
	const float *aa = hist_contact_angles(h, m, p->a), *ab = hist_contact_angles(h, m, p->b);
	uint64_t n = (uint64_t)(HIST_CLASS_S * HIST_HZ);
	uint64_t from = h->next > n ? h->next - n : 0;
	if (from < p->first)
		from = p->first;
	double bound = NAN;
	for (uint64_t i = from; i < h->next; i++) {
		int s = hist_slot(i);
		win_swing_add(&sa, aa[s]);
		win_swing_add(&sb, ab[s]);
		win_circ_add(&w.delta, p->delta[s]);
		if (isfinite(p->bound[s]))
			bound = p->bound[s];
	}
	w.swing_a = win_swing_pp(&sa);
	w.swing_b = win_swing_pp(&sb);
	/* 2 asin(d~) back to d~ (pi: d~ >= 1, they cannot touch) */
	if (isfinite(bound))
		w.dsep = bound >= M_PI - 1e-6 ? 1.0 : sin(bound / 2.0);
	for (int k = 0; k < p->ncoll; k++)
		if (now - p->coll_t[k] <= HIST_CLASS_S)
			w.collisions++;
	p->cls = cls_end_state(&w);
}

void hist_sample(struct hist *h, const struct top_model *m, double now)
{
	int s = hist_slot(h->next);
	h->t_ms[s] = hist_ms(h, now);
	hist_sample_robots(h, m, s, h->t_ms[s], now);
	hist_sample_pairs(h, m, s);
	hist_sample_sim(h, m, now);
	h->next++;
	if (h->next % HIST_CLASS_EVERY == 0)
		for (int k = 0; k < h->npairs_now; k++)
			hist_classify(h, m, &h->pairs[h->pair_of[k]], now);
}

void hist_on_collision(struct hist *h, const struct top_model *m, const char *left, const char *right,
                       double now)
{
	int a = top_robot_index(m, left), b = top_robot_index(m, right);
	for (int i = 0; i < HIST_PAIRS && a >= 0 && b >= 0; i++) {
		struct hist_pair *p = &h->pairs[i];
		if (p->used && ((p->a == a && p->b == b) || (p->a == b && p->b == a))) {
			p->coll_t[p->collnext] = now;
			p->collnext = (p->collnext + 1) % HIST_PAIR_COLL;
			if (p->ncoll < HIST_PAIR_COLL)
				p->ncoll++;
			return;
		}
	}
	if (a >= 0 && b >= 0)
		h->untracked_collisions++;
}

void hist_close_contacts(struct hist *h, double now)
{
	wct_close(&h->contacts, hist_ms(h, now));
}
