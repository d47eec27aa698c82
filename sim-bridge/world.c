/*
 * world.c — contact between neighbouring bodies in a row, and walls.
 *
 * One resolve, after the motors moved by dt:
 *  1. read X_i = n_i + lever_i·angle_i and V_i = lever_i·w_i;
 *  2. project the positions onto the ordered set (X_i + h_i <= X_{i+1} - h_{i+1},
 *     walls): an exact least-squares projection by pool-adjacent-violators, by
 *     index, so a body that went through its neighbour in one step (any speed,
 *     any dt) comes back to its own side — there is no tunnelling;
 *  3. every touching pair approaching faster than a resting contact collides
 *     (PHYSICS.md 2.2's law, walls with their own restitution), swept until none
 *     does (chains, Newton's cradle); mobility moves the neutral positions;
 *  4. resting contacts (a persistent push) are made plastic all at once per
 *     touching row: the speeds' monotone regression, O(N), no jitter;
 *  5. if mobility moved bodies, project again (and resolve again);
 *  6. write angles and speeds back to the motors that changed, remember which
 *     pairs touch for the next step.
 * Details and the reasons for them: sim-bridge/PHYSICS.md.
 */
#include "world.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>

/* Gap (m) at or below which two bodies (or a body and a wall) touch: the
 * projection leaves touching pairs at 0 up to rounding. */
#define WORLD_TOUCH_TOL      1e-9
/* Closing speed (m/s) above which a touching pair is approaching: below it the
 * pair is at rest relative to each other (stops r < 1 sweeps from running on
 * geometrically shrinking speeds). */
#define WORLD_APPROACH_TOL   1e-9
/* Velocity sweeps per projection: r = 1 chains sort in <= N sweeps, r < 1
 * chains converge geometrically; past this the rest is finished next step. */
#define WORLD_MAX_SWEEPS     (4 * SIM_MAX_BODIES)
/* A touching pair that closes no faster than the motors' own pushes could have
 * made it in this many steps is resting, not colliding (PHYSICS.md). */
#define WORLD_REST_STEPS     2.0
/* Projection/sweep rounds when mobility keeps moving neutral positions. */
#define WORLD_MAX_ROUNDS     8
/* Pairs: left wall|0, (0,1) .. (N-2,N-1), N-1|right wall. */
#define WORLD_MAX_PAIRS      (SIM_MAX_BODIES + 1)

/* Per-step working state, on the stack (no allocation). */
struct world_scratch {
	double x[SIM_MAX_BODIES];      /* lateral position */
	double v[SIM_MAX_BODIES];      /* lateral speed */
	double dv[SIM_MAX_BODIES];     /* speed change from contacts this step */
	double pushed[SIM_MAX_BODIES]; /* |speed change| the motors made since the last step */
	bool touched[SIM_MAX_BODIES];  /* position or speed changed: write back */
	/* per pair k: the step's collision, merged over sweeps */
	bool hit[WORLD_MAX_PAIRS];
	double pre_l[WORLD_MAX_PAIRS], pre_r[WORLD_MAX_PAIRS];
	double post_l[WORLD_MAX_PAIRS], post_r[WORLD_MAX_PAIRS];
	double impulse[WORLD_MAX_PAIRS];
	bool impact[WORLD_MAX_PAIRS];  /* at least one impulse of the pair was an impact */
	double rest_speed[WORLD_MAX_PAIRS];  /* closing speed below which contact rests */
	double spread[WORLD_MAX_PAIRS];      /* neutral separation mobility added */
	/* projection blocks */
	double block_sum[SIM_MAX_BODIES];
	size_t block_len[SIM_MAX_BODIES];
	bool moved_neutral;
};

static double world_clamp(double v, double lo, double hi)
{
	return v < lo ? lo : (v > hi ? hi : v);
}

static void world_warn(struct sim_world *w, const char *what)
{
	/* Rate-limited: the first few, then every 1000th. */
	w->bad_input++;
	if (w->bad_input <= 5 || w->bad_input % 1000 == 0)
		fprintf(stderr, "undulate-sim: world: %s (%llu so far)\n", what, w->bad_input);
}

void sim_world_init(struct sim_world *w, const struct sim_world_params *p)
{
	w->params = *p;
	w->nbodies = 0;
	w->time = 0;
	w->total_collisions = 0;
	w->total_impulse = 0;
	w->unresolved_steps = 0;
	w->infeasible_steps = 0;
	w->bad_input = 0;
	w->resting_contacts = 0;
	w->resting_impulse = 0;
	for (size_t k = 0; k <= SIM_MAX_BODIES; k++)
		w->in_contact[k] = 0;
	for (size_t i = 0; i < SIM_MAX_BODIES; i++)
		w->prev_speed[i] = 0;
	struct sim_world_params *q = &w->params;
	if (!(q->restitution >= 0 && q->restitution <= 1)) {
		q->restitution = isfinite(q->restitution) ? world_clamp(q->restitution, 0, 1) : 0.67;
		world_warn(w, "restitution outside 0..1, clamped");
	}
	if (!(q->wall_restitution >= 0 && q->wall_restitution <= 1)) {
		q->wall_restitution = isfinite(q->wall_restitution)
		                      ? world_clamp(q->wall_restitution, 0, 1) : 0.67;
		world_warn(w, "wall restitution outside 0..1, clamped");
	}
	if (!(q->beta >= 0) || !isfinite(q->beta)) {
		q->beta = 0;
		world_warn(w, "mobility beta negative or not finite, set to 0");
	}
	if (!isfinite(q->wall_left) || !isfinite(q->wall_right)) {
		q->wall_left = q->wall_right = 0;
		world_warn(w, "wall position not finite, walls removed");
	}
}

int sim_world_add_body(struct sim_world *w, const struct sim_body *b)
{
	if (w->nbodies >= SIM_MAX_BODIES) {
		world_warn(w, "too many contact bodies");
		return -1;
	}
	if (!b->motor || !isfinite(b->lever) || b->lever == 0 || !isfinite(b->neutral)
	    || !(b->half_width >= 0) || !isfinite(b->half_width)
	    || !(b->effective_mass > 0) || !isfinite(b->effective_mass)
	    || (b->own_beta && !(b->beta >= 0 && isfinite(b->beta)))) {
		world_warn(w, "invalid contact body rejected");
		return -1;
	}
	w->bodies[w->nbodies] = *b;
	return (int)w->nbodies++;
}

double sim_world_lateral(const struct sim_world *w, size_t i)
{
	const struct sim_body *b = &w->bodies[i];
	return b->neutral + b->lever * b->motor->angle;
}

double sim_world_lateral_speed(const struct sim_world *w, size_t i)
{
	const struct sim_body *b = &w->bodies[i];
	return b->lever * b->motor->speed;
}

static bool world_has_walls(const struct sim_world *w)
{
	return w->params.wall_left < w->params.wall_right;
}

/* Gap of pair k (see WORLD_MAX_PAIRS); +inf for a missing wall. */
static double world_gap(const struct sim_world *w, const struct world_scratch *s, size_t k)
{
	size_t n = w->nbodies;
	if (k == 0)
		return world_has_walls(w)
		       ? (s->x[0] - w->bodies[0].half_width) - w->params.wall_left : INFINITY;
	if (k == n)
		return world_has_walls(w)
		       ? w->params.wall_right - (s->x[n - 1] + w->bodies[n - 1].half_width) : INFINITY;
	return (s->x[k] - w->bodies[k].half_width) - (s->x[k - 1] + w->bodies[k - 1].half_width);
}

/* One step of pool-adjacent-violators (isotonic regression, equal weights):
 * append value y as a block of one to the nb blocks in s, merge while a block's
 * mean exceeds the next one's, and return the new block count. */
static size_t world_pool_push(struct world_scratch *s, size_t nb, double y)
{
	s->block_sum[nb] = y;
	s->block_len[nb] = 1;
	nb++;
	while (nb > 1 && s->block_sum[nb - 2] * (double)s->block_len[nb - 1]
	                 > s->block_sum[nb - 1] * (double)s->block_len[nb - 2]) {
		s->block_sum[nb - 2] += s->block_sum[nb - 1];
		s->block_len[nb - 2] += s->block_len[nb - 1];
		nb--;
	}
	return nb;
}

/* ---- positions: projection onto the ordered row ----------------------------------
 * With c_0 = 0, c_i = c_{i-1} + h_{i-1} + h_i and Y_i = X_i - c_i the constraints
 * are Y nondecreasing and lo <= Y <= hi (walls): the closest such Y is the
 * isotonic regression of Y (pool adjacent violators) clamped to [lo, hi].
 * Equal weights split every overlap equally, as equal inertia would. */
static void world_project(struct sim_world *w, struct world_scratch *s)
{
	size_t n = w->nbodies, nb = 0;
	double c = 0;
	for (size_t i = 0; i < n; i++) {
		if (i > 0)
			c += w->bodies[i - 1].half_width + w->bodies[i].half_width;
		nb = world_pool_push(s, nb, s->x[i] - c);
	}
	double lo = -INFINITY, hi = INFINITY;
	if (world_has_walls(w)) {
		lo = w->params.wall_left + w->bodies[0].half_width;
		hi = w->params.wall_right - w->bodies[n - 1].half_width - c;
		if (lo > hi) {
			w->infeasible_steps++;
			lo = hi = 0.5 * (lo + hi);
		}
	}
	/* Write back block by block, touching only bodies that move. */
	size_t i = 0;
	c = 0;
	for (size_t b = 0; b < nb; b++) {
		double mean = s->block_sum[b] / (double)s->block_len[b];
		double y = world_clamp(mean, lo, hi);
		bool keep = s->block_len[b] == 1 && y == mean;
		for (size_t j = 0; j < s->block_len[b]; j++, i++) {
			if (i > 0)
				c += w->bodies[i - 1].half_width + w->bodies[i].half_width;
			if (keep)
				continue;
			double x = y + c;
			if (x != s->x[i]) {
				s->x[i] = x;
				s->touched[i] = true;
			}
		}
	}
}

/* ---- speeds: collisions ---------------------------------------------------------- */

static void world_record(struct world_scratch *s, size_t k, double pre_l, double pre_r,
                         double post_l, double post_r, double impulse, bool resting)
{
	if (!s->hit[k]) {
		s->hit[k] = true;
		s->pre_l[k] = pre_l;
		s->pre_r[k] = pre_r;
		s->impulse[k] = 0;
		s->impact[k] = false;
	}
	s->impact[k] |= !resting;
	s->post_l[k] = post_l;
	s->post_r[k] = post_r;
	s->impulse[k] += impulse;
}

/* Body i's mobility: its own, or the world's. */
static double world_beta(const struct sim_world *w, size_t i)
{
	return w->bodies[i].own_beta ? w->bodies[i].beta : w->params.beta;
}

static void world_shift(struct sim_world *w, struct world_scratch *s, size_t i, double delta)
{
	if (delta == 0)
		return;
	w->bodies[i].neutral += delta;
	s->x[i] += delta;
	s->touched[i] = true;
	s->moved_neutral = true;
}

/* Resting contact: the pair touched at the end of the last step and closes only
 * as fast as the motors' pushes since then could make it. Such contacts are
 * left to world_plastic() (r = 0): bouncing on speeds made within one step
 * would be jitter, not an impact. */
static bool world_resting(const struct sim_world *w, const struct world_scratch *s,
                          size_t k, double closing)
{
	return w->in_contact[k] && closing <= s->rest_speed[k];
}

/* Body i hits body i+1 (pair k = i+1). */
static void world_collide_pair(struct sim_world *w, struct world_scratch *s, size_t i)
{
	double bi = world_beta(w, i), bj = world_beta(w, i + 1);
	double r = w->params.restitution;
	double vi = s->v[i], vj = s->v[i + 1];
	double vi_post = 0.5 * ((1 - r) * vi + (1 + r) * vj);
	double vj_post = 0.5 * ((1 - r) * vj + (1 + r) * vi);
	double mass = 0.5 * (w->bodies[i].effective_mass + w->bodies[i + 1].effective_mass);
	s->v[i] = vi_post;
	s->v[i + 1] = vj_post;
	s->dv[i] += vi_post - vi;
	s->dv[i + 1] += vj_post - vj;
	s->touched[i] = s->touched[i + 1] = true;
	world_record(s, i + 1, vi, vj, vi_post, vj_post, mass * fabs(vi_post - vi), false);
	world_shift(w, s, i, bi * (vj - vi));
	world_shift(w, s, i + 1, bj * (vi - vj));
	s->spread[i + 1] += (bi + bj) * fabs(vi - vj);
}

/* Body i hits a wall (pair k: 0 left, N right); the wall does not move. */
static void world_collide_wall(struct sim_world *w, struct world_scratch *s, size_t i, size_t k)
{
	double v = s->v[i];
	double v_post = -w->params.wall_restitution * v;
	s->v[i] = v_post;
	s->dv[i] += v_post - v;
	s->touched[i] = true;
	double impulse = w->bodies[i].effective_mass * fabs(v_post - v);
	if (k == 0)
		world_record(s, k, 0, v, 0, v_post, impulse, false);
	else
		world_record(s, k, v, 0, v_post, 0, impulse, false);
	world_shift(w, s, i, world_beta(w, i) * (0 - v));
	s->spread[k] += world_beta(w, i) * fabs(v);
}

/* Closing speed of pair k (positive: approaching; walls stand still). */
static double world_closing(const struct sim_world *w, const struct world_scratch *s, size_t k)
{
	size_t n = w->nbodies;
	if (k == 0)
		return -s->v[0];
	if (k == n)
		return s->v[n - 1];
	return s->v[k - 1] - s->v[k];
}

/* Impact of pair k if it touches and closes faster than resting contact.
 * Returns whether it collided. */
static bool world_try_pair(struct sim_world *w, struct world_scratch *s, size_t k)
{
	size_t n = w->nbodies;
	if (world_gap(w, s, k) > WORLD_TOUCH_TOL)
		return false;
	double closing = world_closing(w, s, k);
	if (!(closing > WORLD_APPROACH_TOL) || world_resting(w, s, k, closing))
		return false;
	if (k == 0)
		world_collide_wall(w, s, 0, 0);
	else if (k == n)
		world_collide_wall(w, s, n - 1, n);
	else
		world_collide_pair(w, s, k - 1);
	return true;
}

/* ---- resting contact: plastic, all at once ----------------------------------------
 * Within a touching cluster the speeds after a plastic contact (r = 0, equal
 * inertia) are the isotonic regression of the speeds (no touching pair may
 * close), clamped at a touching wall: exact, momentum-conserving, O(N), where
 * pairwise sweeps would need O(N²) passes through a long pressed row. */
static void world_plastic_cluster(struct sim_world *w, struct world_scratch *s,
                                  size_t a, size_t b, bool wall_a, bool wall_b)
{
	double before[SIM_MAX_BODIES];
	size_t nb = 0;
	for (size_t i = a; i <= b; i++) {
		before[i] = s->v[i];
		nb = world_pool_push(s, nb, s->v[i]);
	}
	double lo = wall_a ? 0.0 : -INFINITY, hi = wall_b ? 0.0 : INFINITY;
	size_t i = a;
	for (size_t k = 0; k < nb; k++) {
		double mean = s->block_sum[k] / (double)s->block_len[k];
		double v = world_clamp(mean, lo, hi);
		for (size_t j = 0; j < s->block_len[k]; j++, i++) {
			if (s->block_len[k] == 1 && v == mean)
				continue;
			s->dv[i] += v - s->v[i];
			s->v[i] = v;
			s->touched[i] = true;
		}
	}
	/* Impulse J through each pair (compressive, pushing its right body right):
	 * body j gains m_j Δv_j = J_j - J_{j+1}. Start from a free end. */
	double total = 0;
	for (size_t j = a; j <= b; j++)
		// cppcheck-suppress uninitvar ; before[a..b] was filled by the loop above over the same range
		total += w->bodies[j].effective_mass * (s->v[j] - before[j]);
	double J = 0;
	if (wall_a)
		J = wall_b ? (total > 0 ? total : 0) : total;
	for (size_t k = a; k <= b + 1; k++) {
		if (J > w->bodies[k > a ? k - 1 : a].effective_mass * WORLD_APPROACH_TOL) {
			double pl = k > a ? before[k - 1] : 0, pr = k <= b ? before[k] : 0;
			double ql = k > a ? s->v[k - 1] : 0, qr = k <= b ? s->v[k] : 0;
			world_record(s, k, pl, pr, ql, qr, J, true);
			if (pl > pr) {
				/* mobility, on the pre-contact closing speed */
				double bl = k > a ? world_beta(w, k - 1) : 0, br = k <= b ? world_beta(w, k) : 0;
				if (k > a)
					world_shift(w, s, k - 1, -bl * (pl - pr));
				if (k <= b)
					world_shift(w, s, k, br * (pl - pr));
				s->spread[k] += (bl + br) * (pl - pr);
			}
		}
		if (k <= b)
			J -= w->bodies[k].effective_mass * (s->v[k] - before[k]);
	}
}

static void world_plastic(struct sim_world *w, struct world_scratch *s)
{
	size_t n = w->nbodies, start = 0;
	for (size_t i = 0; i < n; i++) {
		if (i + 1 < n && world_gap(w, s, i + 1) <= WORLD_TOUCH_TOL)
			continue;
		bool wall_a = start == 0 && world_gap(w, s, 0) <= WORLD_TOUCH_TOL;
		bool wall_b = i == n - 1 && world_gap(w, s, n) <= WORLD_TOUCH_TOL;
		/* only clusters where something still closes */
		bool closing = (wall_a && s->v[start] < -WORLD_APPROACH_TOL)
		               || (wall_b && s->v[i] > WORLD_APPROACH_TOL);
		for (size_t j = start; j < i && !closing; j++)
			closing = s->v[j] - s->v[j + 1] > WORLD_APPROACH_TOL;
		if (closing)
			world_plastic_cluster(w, s, start, i, wall_a, wall_b);
		start = i + 1;
	}
}

/* Gauss–Seidel sweeps, alternating direction, until no touching pair closes.
 * Returns false when the cap was reached first. */
static bool world_sweep(struct sim_world *w, struct world_scratch *s)
{
	size_t pairs = w->nbodies + 1;
	for (int sweep = 0; sweep < WORLD_MAX_SWEEPS; sweep++) {
		bool any = false;
		for (size_t j = 0; j < pairs; j++) {
			size_t k = (sweep & 1) ? pairs - 1 - j : j;
			any |= world_try_pair(w, s, k);
		}
		if (!any)
			return true;
	}
	return false;
}

/* ---- the step ------------------------------------------------------------------- */

static void world_read(struct sim_world *w, struct world_scratch *s)
{
	for (size_t i = 0; i < w->nbodies; i++) {
		struct sim_motor *m = w->bodies[i].motor;
		if (!isfinite(m->angle) || !isfinite(m->speed)) {
			m->angle = isfinite(m->angle) ? m->angle : 0;
			m->speed = isfinite(m->speed) ? m->speed : 0;
			world_warn(w, "non-finite joint state repaired");
		}
		s->x[i] = sim_world_lateral(w, i);
		s->v[i] = sim_world_lateral_speed(w, i);
		s->dv[i] = 0;
		s->pushed[i] = fabs(s->v[i] - w->prev_speed[i]);
		s->touched[i] = false;
	}
	for (size_t k = 0; k <= w->nbodies; k++) {
		s->hit[k] = false;
		s->spread[k] = 0;
		s->rest_speed[k] = 0;
	}
}

/* Per touching cluster (after the first projection): the closing speed the
 * motors' pushes could have built inside it, for world_resting(). */
static void world_rest_speeds(const struct sim_world *w, struct world_scratch *s)
{
	size_t n = w->nbodies, start = 0;
	double sum = 0;
	for (size_t i = 0; i < n; i++) {
		sum += s->pushed[i];
		if (i + 1 < n && world_gap(w, s, i + 1) <= WORLD_TOUCH_TOL)
			continue;
		/* cluster start..i, with its outer pairs (walls) */
		for (size_t k = start; k <= i + 1; k++)
			s->rest_speed[k] = WORLD_REST_STEPS * sum;
		start = i + 1;
		sum = 0;
	}
}

/* Contact memory for the next step: a pair is in contact if it touches or
 * could close its gap within a step (mobility opens micro-gaps under a push). */
static void world_remember(struct sim_world *w, const struct world_scratch *s, double dt)
{
	size_t n = w->nbodies;
	for (size_t i = 0; i < n; i++)
		w->prev_speed[i] = s->v[i];
	for (size_t k = 0; k <= n; k++) {
		double reach = 0;
		if (k > 0)
			reach += fabs(s->v[k - 1]);
		if (k < n)
			reach += fabs(s->v[k]);
		double gap = world_gap(w, s, k);
		w->in_contact[k] = gap <= WORLD_TOUCH_TOL + dt * reach + s->spread[k];
	}
}

/* Whether anything touches at all: the common case is a free row. */
static bool world_any_contact(const struct sim_world *w, const struct world_scratch *s)
{
	for (size_t k = 0; k <= w->nbodies; k++)
		if (world_gap(w, s, k) <= WORLD_TOUCH_TOL)
			return true;
	return false;
}

static void world_write_back(struct sim_world *w, const struct world_scratch *s, double dt)
{
	for (size_t i = 0; i < w->nbodies; i++) {
		if (!s->touched[i])
			continue;
		const struct sim_body *b = &w->bodies[i];
		b->motor->angle = (s->x[i] - b->neutral) / b->lever;
		b->motor->speed = s->v[i] / b->lever;
		/* The contact's equivalent torque over the step, for ground truth:
		 * (effective mass · Δv) is the impulse, × lever a moment, / dt. */
		if (dt > 0)
			b->motor->ext_torque += b->effective_mass * s->dv[i] * b->lever / dt;
	}
}

static size_t world_report(struct sim_world *w, const struct world_scratch *s,
                           struct sim_collision *out, size_t cap)
{
	size_t n = w->nbodies, count = 0;
	for (size_t k = 0; k <= n; k++) {
		if (!s->hit[k])
			continue;
		w->total_collisions++;
		w->total_impulse += s->impulse[k];
		if (!s->impact[k]) {
			w->resting_contacts++;
			w->resting_impulse += s->impulse[k];
		}
		if (!out || count >= cap)
			continue;   /* counted in the totals only */
		struct sim_collision *c = &out[count++];
		c->time = w->time;
		c->left = k == 0 ? -1 : (int)(k - 1);
		c->right = k == n ? -1 : (int)k;
		c->pre_left = s->pre_l[k];
		c->pre_right = s->pre_r[k];
		c->post_left = s->post_l[k];
		c->post_right = s->post_r[k];
		c->impulse = s->impulse[k];
		c->resting = !s->impact[k];
	}
	return count;
}

size_t sim_world_resolve(struct sim_world *w, double dt, struct sim_collision *out, size_t cap)
{
	if (!(dt >= 0) || !isfinite(dt)) {
		world_warn(w, "resolve with a bad dt");
		dt = 0;
	}
	w->time += dt;
	if (w->nbodies == 0)
		return 0;
	struct world_scratch s;
	world_read(w, &s);
	size_t count = 0;
	if (world_any_contact(w, &s)) {
		bool settled = false;
		for (int round = 0; round < WORLD_MAX_ROUNDS && !settled; round++) {
			s.moved_neutral = false;
			world_project(w, &s);
			if (round == 0)
				world_rest_speeds(w, &s);
			bool swept = world_sweep(w, &s);
			world_plastic(w, &s);
			settled = swept && !s.moved_neutral;
		}
		if (!settled) {
			w->unresolved_steps++;
			world_project(w, &s);   /* the order holds whatever the speeds */
		}
		world_write_back(w, &s, dt);
		count = world_report(w, &s, out, cap);
	}
	world_remember(w, &s, dt);
	return count;
}
