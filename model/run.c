/* run.c — a model run and its files (run.h). The pure parts are in mdl_*.c;
 * here: the loop that samples and records, and the writing. */
#include "run.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../tools/analyze/classify.h"
#include "../tools/analyze/csvrow.h"
#include "../tools/analyze/pairsum.h"
#include "../tools/analyze/theory.h"
#include "../tools/analyze/window.h"
#include "json.h"
#include "mdl_lattice.h"
#include "mdl_pairmap.h"
#include "outdir.h"
#include "phase.h"

/* summary.json's significant digits: the analyser's (AN_JSON_DIGITS). */
#define MRUN_JSON_DIGITS 9
/* The analyser's default for a joint that does not swing (rad p-p). */
#define MRUN_MIN_SWING 0.2

/* One collision of a neighbouring pair, for return_map.csv. */
struct mrun_hit {
	double t, delta, delta_after, dsep;
};

struct mrun_pair {
	int64_t collisions, win_collisions;
	double impulse, win_impulse;
	struct win_circ win;
	struct mrun_hit *hits;
	size_t nhits, caphits;
};

struct mrun {
	const struct cli_opts *o;
	FILE *msg;
	struct lat *lat;
	int n;
	int dirfd, stagefd;
	char stage[300];
	FILE *states, *pdiff, *coll;
	struct mrun_pair *pairs;       /* n - 1 neighbouring pairs */
	struct win_swing *swing;       /* per oscillator, final window */
	int64_t *bin_coll, *bin_wall;  /* per second */
	double *bin_impulse;
	int64_t nbins;
	int64_t collisions, wall_collisions, immediate, samples;
	double impulse, last_pair_collision, window_start;
	int initial_overlaps;
	double cpu_s;
};


static long long mrun_utime(double t)
{
	return llround(t * 1e6);
}

static FILE *mrun_create(struct mrun *m, const char *name, const char *header)
{
	FILE *f = outdir_stage_fopen(m->stagefd, name);
	if (!f) {
		fprintf(m->msg, "undulate-model: %s/%s: %s\n", m->o->out_dir, name, strerror(errno));
		return NULL;
	}
	if (header)
		fprintf(f, "%s\n", header);
	return f;
}

static int mrun_close(struct mrun *m, FILE **f, const char *name)
{
	if (outdir_stage_fclose(f) == 0)
		return 0;
	fprintf(m->msg, "undulate-model: writing %s/%s failed\n", m->o->out_dir, name);
	return -1;
}

/* ---- recording --------------------------------------------------------- */

static void mrun_sample(struct mrun *m, double t)
{
	const struct cli_opts *o = m->o;
	bool in_window = t >= m->window_start;
	m->samples++;
	for (int i = 0; i < m->n; i++) {
		double x = lat_displacement(m->lat, i), phi = lat_phase(m->lat, i);
		if (in_window)
			win_swing_add(&m->swing[i], x);
		if (!o->write_samples)
			continue;
		/* the columns of undulate-analyze's states.csv; mode 3 is
		 * OSCILLATOR, goal and load do not exist in the model */
		fprintf(m->states, "%lld,%.6f,\"r%d\",0,1", mrun_utime(t), t, i + 1);
		csvrow_num(m->states, x);
		csvrow_num(m->states, lat_speed(m->lat, i));
		fputs(",,,3", m->states);
		csvrow_num(m->states, phi);
		csvrow_num(m->states, lat_amplitude(m->lat, i));
		csvrow_num(m->states, o->frequency_hz);
		fputs(",0", m->states);
		csvrow_num(m->states, phi);
		csvrow_num(m->states, o->frequency_hz);
		fprintf(m->states, ",%d\n", i);
	}
	for (int k = 0; k + 1 < m->n; k++) {
		double delta = phase_wrap(lat_phase(m->lat, k + 1) - lat_phase(m->lat, k));
		if (in_window)
			win_circ_add(&m->pairs[k].win, delta);
		if (o->write_samples) {
			fprintf(m->pdiff, "%lld,%.6f,\"r%d:r%d\",neighbour,\"r%d\",0,\"r%d\",0", mrun_utime(t), t, k + 1,
				k + 2, k + 1, k + 2);
			csvrow_num(m->pdiff, delta);
			fputc('\n', m->pdiff);
		}
	}
}

static int mrun_hit_add(struct mrun_pair *p, const struct lat_event *ev)
{
	if (p->nhits == p->caphits) {
		size_t cap = p->caphits ? 2 * p->caphits : 64;
		struct mrun_hit *h = realloc(p->hits, cap * sizeof *h);
		if (!h)
			return -1;
		p->hits = h;
		p->caphits = cap;
	}
	p->hits[p->nhits++] = (struct mrun_hit){ ev->t, ev->delta_before, ev->delta_after, ev->dsep_before };
	return 0;
}

/* A robot's name in the files ("r1", ...; -1: "wall"), into buf. */
static const char *mrun_robot(char *buf, size_t cap, int i)
{
	if (i < 0)
		return "wall";
	snprintf(buf, cap, "r%d", i + 1);
	return buf;
}

static int mrun_collision(struct mrun *m, const struct lat_event *ev)
{
	bool wall = ev->left < 0 || ev->right < 0;
	bool in_window = ev->t >= m->window_start;
	m->collisions++;
	m->impulse += ev->impulse;
	m->immediate += ev->immediate;
	int64_t b = (int64_t)floor(ev->t);
	if (b >= 0 && b < m->nbins) {
		m->bin_coll[b]++;
		m->bin_impulse[b] += ev->impulse;
		m->bin_wall[b] += wall;
	}
	if (wall) {
		m->wall_collisions++;
	} else {
		struct mrun_pair *p = &m->pairs[ev->left];
		p->collisions++;
		p->impulse += ev->impulse;
		if (in_window) {
			p->win_collisions++;
			p->win_impulse += ev->impulse;
		}
		m->last_pair_collision = ev->t;
		if (mrun_hit_add(p, ev) != 0) {
			fprintf(m->msg, "undulate-model: out of memory for the return map\n");
			return -1;
		}
	}
	char left[16], right[16], pair[32];
	snprintf(pair, sizeof pair, "r%d:r%d", ev->left + 1, ev->right + 1);
	/* every collision of the model is a new contact */
	csvrow_collision(m->coll, &(struct csvrow_collision){
		.utime = mrun_utime(ev->t), .t = ev->t, .left = ev->left, .right = ev->right,
		.left_robot = mrun_robot(left, sizeof left, ev->left),
		.right_robot = mrun_robot(right, sizeof right, ev->right),
		.pre_left = ev->pre_left, .pre_right = ev->pre_right, .post_left = ev->post_left, .post_right = ev->post_right,
		.impulse = ev->impulse, .pair = wall ? NULL : pair, .delta = ev->delta_before, .new_contact = true });
	return 0;
}

/* ---- the run ----------------------------------------------------------- */

static int mrun_phases(struct mrun *m, double *phase)
{
	const struct cli_opts *o = m->o;
	struct lat_params p;
	cli_lat_params(o, &p);
	if (o->have_phases)
		memcpy(phase, o->phases, (size_t)o->n * sizeof *phase);
	else if (o->cmd == CLI_PAIR)
		pmap_start(o->delta0, phase);
	else
		m->initial_overlaps = lat_random_phases(&p, o->seed, phase);
	return 0;
}

static int mrun_loop(struct mrun *m)
{
	const struct cli_opts *o = m->o;
	double dt = 1.0 / o->sample_hz;
	int64_t k = 0;
	char err[256];
	mrun_sample(m, 0);
	for (;;) {
		double next = fmin((double)(k + 1) * dt, o->duration_s);
		struct lat_event ev;
		enum lat_status st = lat_advance(m->lat, next, &ev, err, sizeof err);
		if (st == LAT_FAILED) {
			fprintf(m->msg, "undulate-model: %s\n", err);
			return -1;
		}
		if (st == LAT_COLLISION) {
			if (mrun_collision(m, &ev) != 0)
				return -1;
			continue;
		}
		k++;
		mrun_sample(m, next);
		if (next >= o->duration_s)
			return 0;
	}
}

/* ---- summaries ------------------------------------------------------------ */

static const char *mrun_class(const struct mrun *m, int k)
{
	const struct mrun_pair *p = &m->pairs[k];
	struct cls_window w = {
		.delta = p->win, .swing_a = win_swing_pp(&m->swing[k]), .swing_b = win_swing_pp(&m->swing[k + 1]),
		.collisions = p->win_collisions, .impulse = p->win_impulse, .window_s = m->o->window_s,
		.dsep = (lat_neutral(m->lat, k + 1) - lat_neutral(m->lat, k)) / (2 * m->o->amplitude),
		.have_sim = true, .min_swing = MRUN_MIN_SWING,
	};
	return cls_end_state(&w);
}

/* The time the row stopped colliding: the last collision between
 * oscillators when none came in the final window, else NAN (censored); 0
 * for a row that never collided. */
static double mrun_t_relax(const struct mrun *m)
{
	if (isnan(m->last_pair_collision))
		return 0;   /* never touched: relaxed from the start */
	if (m->last_pair_collision >= m->window_start)
		return NAN;
	return m->last_pair_collision;
}

static void mrun_json_pair(const struct mrun *m, struct json *j, int k)
{
	const struct mrun_pair *p = &m->pairs[k];
	char name[32];
	double amp = m->o->amplitude, dist = lat_neutral(m->lat, k + 1) - lat_neutral(m->lat, k);
	snprintf(name, sizeof name, "r%d:r%d", k + 1, k + 2);
	/* every contact of the model is a pair's collision */
	pairsum_json(j, &(struct pairsum){
		.name = name, .kind = "neighbour", .cls = mrun_class(m, k), .win = &p->win,
		.collisions = p->collisions, .contacts = p->collisions, .win_collisions = p->win_collisions,
		.win_impulse = p->win_impulse, .win_contact_impulse = p->win_impulse, .impulse = p->impulse,
		.distance = dist, .amplitude = amp, .dsep = dist / (2 * amp),
		.return_map_points = p->nhits > 0 ? (int64_t)p->nhits - 1 : 0,
		.swing_a = win_swing_pp(&m->swing[k]), .swing_b = win_swing_pp(&m->swing[k + 1]) });
}

static void mrun_json_model(const struct mrun *m, struct json *j)
{
	const struct cli_opts *o = m->o;
	json_key(j, "model");
	json_object_begin(j);
	json_field_string(j, "command", o->cmd == CLI_PAIR ? "pair" : "lattice");
	json_field_int(j, "oscillators", o->n);
	json_field_number(j, "frequency_hz", o->frequency_hz);
	json_field_number(j, "amplitude", o->amplitude);
	json_field_number(j, "restitution", o->restitution);
	json_field_number(j, "dsep", o->dsep);
	json_field_number(j, "delta0", o->cmd == CLI_PAIR && !o->have_phases ? o->delta0 : NAN);
	json_field_bool(j, "walls", o->walls);
	json_field_number(j, "wall_dsep", o->walls ? o->wall_dsep : NAN);
	json_field_bool(j, "fixed_ends", o->fixed_ends);
	json_key(j, "beta");
	json_array_begin(j);
	for (int i = 0; i < m->n; i++)
		json_number(j, o->beta[i]);
	json_array_end(j);
	json_field_int(j, "seed", o->cmd == CLI_LATTICE && !o->have_phases ? (long long)o->seed : -1);
	json_field_number(j, "duration_s", o->duration_s);
	json_field_number(j, "sample_hz", o->sample_hz);
	json_field_number(j, "tolerance", o->tolerance > 0 ? o->tolerance : 1e-12);
	json_field_number(j, "amplitude_rate", o->amplitude_rate);
	json_field_number(j, "t_relax_s", mrun_t_relax(m));
	json_field_number(j, "last_collision_s", m->last_pair_collision);
	json_field_int(j, "immediate_collisions", m->immediate);
	json_field_int(j, "overlaps", lat_overlaps(m->lat));
	json_field_int(j, "initial_overlaps", m->initial_overlaps);
	json_field_int(j, "steps", lat_steps(m->lat));
	json_field_int(j, "root_evals", lat_root_evals(m->lat));
	json_field_number(j, "cpu_s", m->cpu_s);
	json_key(j, "neutral_final");
	json_array_begin(j);
	for (int i = 0; i < m->n; i++)
		json_number(j, lat_neutral(m->lat, i));
	json_array_end(j);
	json_object_end(j);
}

static void mrun_summary_json(const struct mrun *m, FILE *f)
{
	const struct cli_opts *o = m->o;
	struct json j;
	json_init(&j, f, MRUN_JSON_DIGITS);
	json_object_begin(&j);
	json_key(&j, "logs");
	json_array_begin(&j);
	json_array_end(&j);
	json_field_bool(&j, "truncated", false);
	json_field_string(&j, "world", "model");
	json_key(&j, "broken");
	json_array_begin(&j);
	json_array_end(&j);
	json_key(&j, "walls");
	json_object_begin(&j);
	json_field_number(&j, "left_m", lat_wall(m->lat, 0));
	json_field_number(&j, "right_m", lat_wall(m->lat, 1));
	json_object_end(&j);
	json_key(&j, "force");
	json_object_begin(&j);
	json_field_number(&j, "switch_s", NAN);
	json_field_number(&j, "median_before_n", NAN);
	json_field_string(&j, "of", "periods");
	json_field_int(&j, "samples_before", 0);
	json_field_number(&j, "median_after_n", NAN);
	json_field_int(&j, "samples_after", 0);
	json_field_number(&j, "before_from_s", NAN);
	json_field_number(&j, "after_from_s", NAN);
	json_object_end(&j);
	json_field_number(&j, "t_end", o->duration_s);
	json_field_number(&j, "window_s", o->window_s);
	json_field_number(&j, "restitution", o->restitution);
	json_field_string(&j, "restitution_from", "undulate-model --restitution");
	json_field_string(&j, "order", "lateral");
	json_field_int(&j, "collisions", m->collisions);
	json_field_int(&j, "wall_collisions", m->wall_collisions);
	json_field_number(&j, "impulse", m->impulse);
	json_field_int(&j, "decode_errors", 0);
	json_key(&j, "robots");
	json_array_begin(&j);
	for (int i = 0; i < m->n; i++) {
		char name[16];
		snprintf(name, sizeof name, "r%d", i + 1);
		json_object_begin(&j);
		json_field_string(&j, "name", name);
		json_field_int(&j, "states", m->samples);
		json_key(&j, "joints");
		json_array_begin(&j);
		json_object_begin(&j);
		json_field_number(&j, "frequency_hz", o->frequency_hz);
		json_field_number(&j, "amplitude_rad", o->amplitude);
		json_field_number(&j, "swing_rad", win_swing_pp(&m->swing[i]));
		json_object_end(&j);
		json_array_end(&j);
		json_object_end(&j);
	}
	json_array_end(&j);
	json_key(&j, "pairs");
	json_array_begin(&j);
	for (int k = 0; k + 1 < m->n; k++)
		mrun_json_pair(m, &j, k);
	json_array_end(&j);
	json_field_number(&j, "min_swing", MRUN_MIN_SWING);
	mrun_json_model(m, &j);
	json_object_end(&j);
	fputc('\n', f);
}

static void mrun_summary_text(const struct mrun *m, FILE *f)
{
	const struct cli_opts *o = m->o;
	fprintf(f, "undulate-model summary\n");
	fprintf(f, "model: %s, %d oscillators at %.3g Hz, amplitude %.3g, r %.3g, d~ %.4g at the start%s\n",
		o->cmd == CLI_PAIR ? "pair" : "lattice", o->n, o->frequency_hz, o->amplitude, o->restitution, o->dsep,
		o->walls ? ", walls" : ", no walls");
	if (o->amplitude_rate > 0)
		fprintf(f, "law: a van der Pol limit cycle of amplitude %.3g, its amplitude back at %.3g /s after an impact\n",
			o->amplitude, o->amplitude_rate);
	fprintf(f, "span: %.2f s; final window %.2f .. %.2f s\n", o->duration_s, m->window_start, o->duration_s);
	fprintf(f, "collisions: %lld (%lld with walls, %lld at once after a jump), %lld pairs let through overlapping\n",
		(long long)m->collisions, (long long)m->wall_collisions, (long long)m->immediate,
		(long long)lat_overlaps(m->lat));
	double tr = mrun_t_relax(m);
	if (isfinite(tr))
		fprintf(f, "relaxed: no collision between oscillators after %.3f s\n", tr);
	else
		fprintf(f, "relaxed: no (collisions in the final window)\n");
	fprintf(f, "%-12s %-28s %8s %8s %8s %6s %6s %8s %9s\n", "pair", "end state", "mean|D|", "meanD", "spread",
		"coll", "c.win", "d~", "2asin(d~)");
	for (int k = 0; k + 1 < m->n; k++) {
		const struct mrun_pair *p = &m->pairs[k];
		double d = (lat_neutral(m->lat, k + 1) - lat_neutral(m->lat, k)) / (2 * o->amplitude);
		char name[32];
		snprintf(name, sizeof name, "r%d:r%d", k + 1, k + 2);
		fprintf(f, "%-12s %-28s %8.4f %8.4f %8.4f %6lld %6lld %8.4f %9.4f\n", name, mrun_class(m, k),
			win_circ_mean_abs(&p->win), win_circ_mean(&p->win), win_circ_spread(&p->win),
			(long long)p->collisions, (long long)p->win_collisions, d, theory_compat_limit(d));
	}
}

static int mrun_write_maps(struct mrun *m)
{
	FILE *f = mrun_create(m, "return_map.csv", "pair,n,utime,t,delta_n,delta_next,theory_next,dsep,delta_after");
	if (!f)
		return -1;
	for (int k = 0; k + 1 < m->n; k++) {
		const struct mrun_pair *p = &m->pairs[k];
		for (size_t i = 0; i + 1 < p->nhits; i++) {
			const struct mrun_hit *h = &p->hits[i];
			fprintf(f, "\"r%d:r%d\",%zu,%lld,%.6f", k + 1, k + 2, i, mrun_utime(h->t), h->t);
			csvrow_num(f, h->delta);
			csvrow_num(f, p->hits[i + 1].delta);
			csvrow_num(f, theory_return_map(h->delta, h->dsep, m->o->restitution));
			csvrow_num(f, h->dsep);
			csvrow_num(f, h->delta_after);
			fputc('\n', f);
		}
	}
	int rc = mrun_close(m, &f, "return_map.csv");
	FILE *g = mrun_create(m, "collision_rate.csv", "t,collisions,impulse,pair_collisions,wall_collisions,contact_force");
	if (!g)
		return -1;
	for (int64_t b = 0; b < m->nbins; b++)
		fprintf(g, "%.3f,%lld,%.9g,%lld,%lld,%.9g\n", (double)b, (long long)m->bin_coll[b], m->bin_impulse[b],
			(long long)(m->bin_coll[b] - m->bin_wall[b]), (long long)m->bin_wall[b], m->bin_impulse[b]);
	return rc | mrun_close(m, &g, "collision_rate.csv");
}

static int mrun_write_summary(struct mrun *m)
{
	FILE *f = mrun_create(m, "summary.txt", NULL);
	FILE *g = f ? mrun_create(m, "summary.json", NULL) : NULL;
	if (!f || !g) {
		if (f)
			fclose(f);
		return -1;
	}
	mrun_summary_text(m, f);
	mrun_summary_json(m, g);
	if (!m->o->quiet)
		mrun_summary_text(m, stdout);
	return mrun_close(m, &f, "summary.txt") | mrun_close(m, &g, "summary.json");
}

/* ---- set-up and tear-down -------------------------------------------------- */

static int mrun_open_dir(struct mrun *m)
{
	char err[512];
	m->dirfd = outdir_open(m->o->out_dir, true, err, sizeof err);
	if (m->dirfd < 0) {
		fprintf(m->msg, "undulate-model: --out %s\n", err);
		return -1;
	}
	m->stagefd = outdir_stage(m->dirfd, ".undulate-model", m->stage, sizeof m->stage, err, sizeof err);
	if (m->stagefd < 0) {
		fprintf(m->msg, "undulate-model: --out %s: %s\n", m->o->out_dir, err);
		return -1;
	}
	m->states = mrun_create(m, "states.csv", CSVROW_STATES_HEADER);
	m->pdiff = mrun_create(m, "phase_diff.csv", CSVROW_PDIFF_HEADER);
	m->coll = mrun_create(m, "collisions.csv", CSVROW_COLLISIONS_HEADER);
	return m->states && m->pdiff && m->coll ? 0 : -1;
}

static int mrun_alloc(struct mrun *m)
{
	m->n = m->o->n;
	m->nbins = (int64_t)ceil(m->o->duration_s);
	m->pairs = calloc((size_t)m->n, sizeof *m->pairs);
	m->swing = calloc((size_t)m->n, sizeof *m->swing);
	m->bin_coll = calloc((size_t)m->nbins + 1, sizeof *m->bin_coll);
	m->bin_wall = calloc((size_t)m->nbins + 1, sizeof *m->bin_wall);
	m->bin_impulse = calloc((size_t)m->nbins + 1, sizeof *m->bin_impulse);
	if (!m->pairs || !m->swing || !m->bin_coll || !m->bin_wall || !m->bin_impulse) {
		fprintf(m->msg, "undulate-model: out of memory\n");
		return -1;
	}
	for (int i = 0; i < m->n; i++)
		win_swing_init(&m->swing[i]);
	m->window_start = m->o->duration_s - m->o->window_s;
	m->last_pair_collision = NAN;
	return 0;
}

static void mrun_free(struct mrun *m)
{
	if (m->states)
		fclose(m->states);
	if (m->pdiff)
		fclose(m->pdiff);
	if (m->coll)
		fclose(m->coll);
	if (m->stagefd >= 0) {
		outdir_discard(m->dirfd, m->stagefd, m->stage);
		close(m->stagefd);
	}
	if (m->dirfd >= 0)
		close(m->dirfd);
	for (int i = 0; m->pairs && i < m->n; i++)
		free(m->pairs[i].hits);
	free(m->pairs);
	free(m->swing);
	free(m->bin_coll);
	free(m->bin_wall);
	free(m->bin_impulse);
	lat_free(m->lat);
}

static double mrun_cpu(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int mrun_finish(struct mrun *m)
{
	char err[512];
	int rc = mrun_close(m, &m->states, "states.csv") | mrun_close(m, &m->pdiff, "phase_diff.csv") |
		 mrun_close(m, &m->coll, "collisions.csv");
	rc |= mrun_write_maps(m);
	rc |= mrun_write_summary(m);
	if (rc != 0)
		return MRUN_OUTPUT;
	if (outdir_publish(m->dirfd, m->stagefd, m->stage, err, sizeof err) != 0) {
		fprintf(m->msg, "undulate-model: --out %s: %s\n", m->o->out_dir, err);
		close(m->stagefd);
		m->stagefd = -1;
		return MRUN_OUTPUT;
	}
	close(m->stagefd);
	m->stagefd = -1;
	return MRUN_OK;
}

int mrun_row(const struct cli_opts *o, FILE *msg)
{
	struct mrun m = { .o = o, .msg = msg, .dirfd = -1, .stagefd = -1 };
	int rc = MRUN_FAILED;
	double phase[CLI_MAX_OSC], cpu0 = mrun_cpu();
	char err[256];
	struct lat_params p;
	cli_lat_params(o, &p);
	if (mrun_alloc(&m) != 0 || mrun_phases(&m, phase) != 0)
		goto out;
	m.lat = lat_new(&p, phase, err, sizeof err);
	if (!m.lat) {
		fprintf(msg, "undulate-model: %s\n", err);
		rc = MRUN_USAGE;
		goto out;
	}
	if (mrun_open_dir(&m) != 0) {
		rc = MRUN_OUTPUT;
		goto out;
	}
	if (mrun_loop(&m) != 0)
		goto out;
	m.cpu_s = mrun_cpu() - cpu0;
	rc = mrun_finish(&m);
out:
	mrun_free(&m);
	return rc;
}

int mrun_map(const struct cli_opts *o, FILE *out, FILE *msg)
{
	char err[256];
	fprintf(out, "dsep,delta_n,delta_next,change,collided,theory_next\n");
	for (int a = 0; a < o->dsep_points; a++) {
		double d = o->dsep_points == 1 ? o->dsep_from
		                               : o->dsep_from + (o->dsep_to - o->dsep_from) * a / (o->dsep_points - 1);
		for (int b = 0; b < o->delta_points; b++) {
			/* delta in (0, pi]: the map is odd, |delta| is what 3a shows */
			double delta = M_PI * (b + 1) / o->delta_points;
			struct pmap_result r;
			if (pmap_step(d, o->restitution, delta, o->tolerance, &r, err, sizeof err) != 0) {
				fprintf(msg, "undulate-model: map at d~ %g, delta %g: %s\n", d, delta, err);
				return MRUN_FAILED;
			}
			double next = r.collided ? r.delta_after : delta;
			fprintf(out, "%.6g,%.9g,%.9g,%.9g,%d", d, delta, next, fabs(next) - fabs(delta), r.collided);
			csvrow_num(out, theory_return_map(delta, d, o->restitution));
			fputc('\n', out);
		}
	}
	return ferror(out) ? MRUN_OUTPUT : MRUN_OK;
}
