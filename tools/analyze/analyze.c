/* analyze.c — undulate-analyze's pipeline (see analyze.h and README.md).
 *
 * Two passes over the logs. The first learns who is there: robots, their
 * joints, the simulator's contact bodies (neutral positions, lever), the time
 * span; from that the pairs to follow are fixed. The second streams every
 * event into the CSV files, estimating each joint's phase on the way, so a
 * long log never has to fit in memory. Only per-pair collision phase
 * differences (the return map) and the collision-rate bins are kept. */
#include "analyze.h"
#include "classify.h"
#include "csvrow.h"
#include "alog.h"
#include "json.h"
#include "phase.h"
#include "modes.h"
#include "num.h"
#include "outdir.h"
#include "pairsum.h"
#include "planecsv.h"
#include "plot.h"
#include "text.h"
#include "theory.h"
#include "window.h"
#include "wire.h"

#include "compat/lcm/lcmdec.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Samples kept per joint to find the state just before a collision: 160 ms
 * at 100 Hz, more than a collision message can lag the states around it. */
#define AN_HISTORY 16
/* Two robots' samples further apart than this (s) are not paired: one of
 * them has stopped publishing. 5 cycles at 100 Hz. */
#define AN_PAIR_FRESH_S 0.05
/* Recently seen collisions: the simulator reports each one on SIM.COLLISION
 * and again inside SIM.TRUTH; it is counted once. */
#define AN_COLL_DEDUP 64
/* Collision-rate bin (s). */
#define AN_RATE_BIN_S 1.0
/* Mode switches marked on the plots; switches of several robots within
 * AN_SWITCH_MERGE_S of the first are one (a command to all robots). */
#define AN_MAX_SWITCHES 16
/* r of the paper's pair rig (theory.md), for logs that do not say theirs. */
#define AN_DEFAULT_RESTITUTION 0.67
#define AN_SWITCH_MERGE_S 0.5
/* Bins allowed for the collision rate (one per second): ten days. */
#define AN_MAX_BINS (10 * 24 * 3600)
/* Warnings of one kind printed before going quiet (the count is reported). */
#define AN_WARN_LIMIT 5
/* Significant digits of summary.json numbers: finer than any estimate here. */
#define AN_JSON_DIGITS 9
/* What breaks a run (README.md, "Broken runs"): a robot silent this long
 * before the log's end stopped (a dead daemon, a lost bus); a physics step
 * later than a control period means the simulator fell behind real time. */
#define AN_STOPPED_S 1.0
#define AN_LATE_US 10000.0
#define AN_LATE_SHARE 0.01       /* of the truth periods, or */
#define AN_LATE_WORST_US 100000.0 /* one step this late */
#define AN_MAX_BROKEN 16
#define AN_BROKEN_TEXT 200
/* Contact-force samples kept (one per SIM.TRUTH period with contact): a
 * 100 Hz truth over 11 hours. */
#define AN_MAX_FORCES (4 * 1000 * 1000)

struct an_sample {
	int64_t utime;
	double t, phase, omega;
};

struct an_joint {
	int16_t servo_id;
	struct phase_estimator est;
	struct an_sample hist[AN_HISTORY];
	int hn, hnext;
	int64_t samples;
	double reported_freq;
	struct win_swing win_swing;  /* measured angle over the final window */
};

struct an_robot {
	char name[AN_NAME_MAX];
	int njoints;
	struct an_joint j[AN_MAX_JOINTS];
	int64_t states;
	/* from SIM.TRUTH */
	bool have_body;
	int16_t body_servo;
	double neutral;     /* m, last seen */
	double lever;       /* m/rad, NAN until estimated */
	int contact_joint;  /* joint the contact body is on; 0 without a simulator */
	bool seen_mode;     /* mode: its last published mode, once seen */
	int mode;
	double last_t;      /* s, its last state */
	bool faulted;       /* a latched fault was published (the first one told) */
};

enum an_pair_kind { AN_PAIR_NEIGHBOUR, AN_PAIR_USER, AN_PAIR_JOINTS };

struct an_pair {
	enum an_pair_kind kind;
	int a, b, ja, jb;
	char name[2 * AN_NAME_MAX + 8];
	struct win_circ win;
	int64_t rows, finite_rows, collisions, win_collisions, contacts;
	double impulse, win_impulse;
	double win_contact_impulse;   /* N·s of every contact in the window (SIM.TRUTH's contacts) */
	double last_coll_t;   /* s, NAN before the first */
	double *deltas;       /* phase difference just before each collision */
	int64_t *delta_utime;
	size_t ndeltas, cap;
	double dsep, amp_lateral, distance;
	double swing_a, swing_b;  /* rad p-p of joints a/ja and b/jb in the final window */
	const char *cls;
};

struct an_seen {
	int64_t utime;
	int32_t left, right;
};

struct an_ctx {
	const struct an_options *o;
	struct an_robot robots[AN_MAX_ROBOTS];
	int nrobots, dropped_robots;
	int order[AN_MAX_ROBOTS];
	bool order_lateral;
	struct an_pair pairs[AN_MAX_PAIRS];
	int npairs;
	/* time */
	bool have_origin;
	int64_t origin_ts;          /* first event's time (an_event_time: for --from/--to) */
	int64_t t_origin;           /* t = 0: the earlier of that and the first state's utime */
	int64_t from_ts, to_ts;     /* selected range in event times */
	int64_t last_state_utime;   /* end of the data, for the final window */
	bool have_state;
	int64_t last_utime;
	double window_start_t;
	/* counts */
	int64_t events, decode_errors, unknown_channels, truth_msgs, collision_msgs;
	int64_t collisions, wall_collisions, log_events[AN_MAX_LOGS];
	double impulse;
	int warned_decode;
	bool truncated;
	char trunc_note[AN_MAX_LOGS][160];
	/* outputs: written into a fresh private directory (stage) inside --out
	 * (dirfd), moved into --out at the end (outdir.h says why) */
	int dirfd, stagefd;
	char stage[64];
	FILE *states, *coll, *bus, *evt, *pdiff, *params;
	/* the plane world (SIM.TRUTH with links): plane.csv, plane_walls.csv */
	bool plane_seen;
	struct pcsv_sampler plane_sampler;
	FILE *plane_csv, *plane_walls_csv;
	struct an_seen seen[AN_COLL_DEDUP];
	int seen_next;
	int64_t *bins, *bin_walls;
	double *bin_impulse;
	/* SIM.TRUTH's running total impulse (impacts and resting contact) and
	 * its time, last seen in each bin: its rate is the mean contact force */
	double *bin_total, *bin_total_t;
	int64_t nbins;
	/* the theory's restitution, and where it came from */
	double restitution;
	const char *restitution_from;
	bool have_force;            /* a contact force was written to collision_rate.csv */
	double world_restitution;   /* from SIM.WORLD; NAN without */
	/* mode switches (any robot's published mode changing), for the plots */
	double switch_t[AN_MAX_SWITCHES];
	int switch_mode[AN_MAX_SWITCHES];
	int nswitches;
	/* the world the simulator ran (SIM.TRUTH), and what broke the run */
	bool plane;
	char broken[AN_MAX_BROKEN][AN_BROKEN_TEXT];
	int nbroken;
	int64_t late_msgs;          /* SIM.TRUTH periods with a step AN_LATE_US late */
	int64_t escaped;            /* the plane world's links outside the walls (link-steps), last seen */
	double wall_left, wall_right;   /* m, the walls as the last SIM.TRUTH had them (NAN: none) */
	double escaped_first_t;
	double late_worst_us, late_first_t;
	/* the contact force over each SIM.TRUTH period with contact */
	double *force_t, *force_n;
	size_t nforce, force_cap;
	bool have_prev_truth;
	double prev_total, prev_sim_t;
	bool have_contacts;         /* SIM.TRUTH lists contacts per pair (impacts and resting) */
};

void an_options_default(struct an_options *o)
{
	memset(o, 0, sizeof(*o));
	o->out_dir = ".";
	o->from_s = NAN;
	o->to_s = NAN;
	o->window_s = 10.0;
	o->separation = NAN;
	o->restitution = NAN;
	o->merge_s = 0.1;
	o->min_swing = AN_MIN_SWING_DEFAULT;
	o->frequency_hz = NAN;
	o->plane_every_s = AN_PLANE_EVERY_DEFAULT;
	o->msg = stderr;
}

static void an_warn(struct an_ctx *c, const char *fmt, ...)
{
	va_list ap;
	fputs("undulate-analyze: warning: ", c->o->msg);
	va_start(ap, fmt);
	vfprintf(c->o->msg, fmt, ap);
	va_end(ap);
	fputc('\n', c->o->msg);
}

/* ---- robots and channels ---------------------------------------------------- */

static int an_robot_find(struct an_ctx *c, const char *name, bool add)
{
	for (int i = 0; i < c->nrobots; i++)
		if (strcmp(c->robots[i].name, name) == 0)
			return i;
	if (!add || !name[0])
		return -1;
	if (c->nrobots >= AN_MAX_ROBOTS || strlen(name) >= AN_NAME_MAX) {
		if (c->dropped_robots++ == 0)
			an_warn(c, "robot \"%s\" ignored (more than %d robots or name longer than %d)",
				name, AN_MAX_ROBOTS, AN_NAME_MAX - 1);
		return -1;
	}
	struct an_robot *r = &c->robots[c->nrobots];
	memset(r, 0, sizeof(*r));
	snprintf(r->name, sizeof(r->name), "%s", name);
	r->lever = NAN;
	for (int j = 0; j < AN_MAX_JOINTS; j++) {
		phase_estimator_init(&r->j[j].est);
		win_swing_init(&r->j[j].win_swing);
	}
	return c->nrobots++;
}

enum an_chan { CH_UNKNOWN, CH_STATE, CH_BUS, CH_EVENT, CH_PARAMS, CH_CMD, CH_TRUTH, CH_COLLISION, CH_SIMCMD, CH_WORLD };

static bool an_ends_with(const char *s, const char *suffix)
{
	size_t n = strlen(s), m = strlen(suffix);
	return n > m && strcmp(s + n - m, suffix) == 0;
}

static enum an_chan an_channel(const char *ch)
{
	if (strcmp(ch, "SIM.TRUTH") == 0)
		return CH_TRUTH;
	if (strcmp(ch, "SIM.COLLISION") == 0)
		return CH_COLLISION;
	if (strcmp(ch, "SIM.CMD") == 0)
		return CH_SIMCMD;
	if (strcmp(ch, "SIM.WORLD") == 0)
		return CH_WORLD;
	if (an_ends_with(ch, ".STATE"))
		return CH_STATE;
	if (an_ends_with(ch, ".BUS"))
		return CH_BUS;
	if (an_ends_with(ch, ".EVENT"))
		return CH_EVENT;
	if (an_ends_with(ch, ".PARAMS"))
		return CH_PARAMS;
	if (an_ends_with(ch, ".CMD"))
		return CH_CMD;
	return CH_UNKNOWN;
}

/* Decodes EV as T into OUT (lcmdec: bounded and checked, a log may hold
 * anything anyone sent); a message that does not decode is counted and said. */
static bool an_decode(struct an_ctx *c, const lcm_eventlog_event_t *ev, const struct lcmdec_type *t, void *out)
{
	enum lcmdec_status s = ev->datalen < 0 ? LCMDEC_MALFORMED : lcmdec_decode(t, ev->data, (size_t)ev->datalen, out);
	if (s == LCMDEC_OK)
		return true;
	c->decode_errors++;
	if (c->warned_decode++ < AN_WARN_LIMIT) {
		char why[160];
		an_warn(c, "message on %s does not decode as its type (skipped): %s", ev->channel,
		        lcmdec_describe(why, sizeof why, t, ev->datalen < 0 ? 0 : (size_t)ev->datalen, s));
	}
	return false;
}

/* In doubles: a message's utime is anyone's (int64 subtraction could
 * overflow), and every real one is exact in a double (< 2^53 µs). */
static double an_t(const struct an_ctx *c, int64_t utime)
{
	return ((double)utime - (double)c->t_origin) * 1e-6;
}

/* ---- log iteration ------------------------------------------------------------ */

/* An event's time: the utime its message carries (every message type of ours
 * begins with it, after the 8-byte fingerprint), else the log's timestamp.
 * The two agree within milliseconds in real time; in lockstep the messages
 * carry the simulated time and the logger stamps its own wall clock, so only
 * the messages' times belong together. */
static int64_t an_event_time(const lcm_eventlog_event_t *ev)
{
	if (an_channel(ev->channel) == CH_UNKNOWN || ev->datalen < 16)
		return ev->timestamp;
	struct wire_reader w;
	wire_reader_init(&w, ev->data, (size_t)ev->datalen);
	(void)wire_take(&w, 8);
	return (int64_t)wire_take(&w, 8);
}

typedef void (*an_event_fn)(struct an_ctx *c, const lcm_eventlog_event_t *ev);

/* Events are taken in the order of their time, not of their arrival at the
 * logger: two robots' messages of one instant arrive in either order, and a
 * pair's phase difference is taken from what each robot has said so far, so
 * the same run must read the same whichever came first (a lockstep run is
 * analysed to the same bytes every time). A window of this many events is
 * sorted by (time, channel, arrival); messages arrive at most milliseconds
 * out of order, a few hundred events at 20 robots. */
#define AN_REORDER 4096

struct an_pending {
	lcm_eventlog_event_t *ev;
	int64_t t;
	uint64_t seq;
};

static bool an_pending_before(const struct an_pending *a, const struct an_pending *b)
{
	if (a->t != b->t)
		return a->t < b->t;
	int ch = strcmp(a->ev->channel, b->ev->channel);
	return ch != 0 ? ch < 0 : a->seq < b->seq;
}

/* A binary min-heap of pending events (static: the analyser is one thread
 * and this is 100 KB). */
static struct an_pending an_heap[AN_REORDER];
static size_t an_heap_n;

static void an_heap_push(lcm_eventlog_event_t *ev, int64_t t, uint64_t seq)
{
	size_t i = an_heap_n++;
	an_heap[i] = (struct an_pending){ ev, t, seq };
	while (i > 0 && an_pending_before(&an_heap[i], &an_heap[(i - 1) / 2])) {
		struct an_pending x = an_heap[i];
		an_heap[i] = an_heap[(i - 1) / 2];
		an_heap[(i - 1) / 2] = x;
		i = (i - 1) / 2;
	}
}

static struct an_pending an_heap_pop(void)
{
	struct an_pending top = an_heap[0];
	an_heap[0] = an_heap[--an_heap_n];
	for (size_t i = 0;;) {
		size_t l = 2 * i + 1, r = l + 1, m = i;
		if (l < an_heap_n && an_pending_before(&an_heap[l], &an_heap[m]))
			m = l;
		if (r < an_heap_n && an_pending_before(&an_heap[r], &an_heap[m]))
			m = r;
		if (m == i)
			break;
		struct an_pending x = an_heap[i];
		an_heap[i] = an_heap[m];
		an_heap[m] = x;
		i = m;
	}
	return top;
}

/* One event, in time order: the origin, the range, then FN. Frees it.
 * Another program's channel (LCM's own self-test, say) has only the logger's
 * clock, which in lockstep is not the run's: it sets neither the origin nor
 * the extent, and is only counted. */
static void an_take_event(struct an_ctx *c, an_event_fn fn, bool first_pass, struct an_pending p)
{
	if (an_channel(p.ev->channel) == CH_UNKNOWN) {
		fn(c, p.ev);
		lcm_eventlog_free_event(p.ev);
		return;
	}
	if (!c->have_origin) {
		c->have_origin = true;
		c->origin_ts = p.t;
		if (first_pass)
			c->t_origin = p.t;
		c->from_ts = isnan(c->o->from_s) ? INT64_MIN : p.t + (int64_t)(c->o->from_s * 1e6);
		c->to_ts = isnan(c->o->to_s) ? INT64_MAX : p.t + (int64_t)(c->o->to_s * 1e6);
	}
	if (p.t >= c->from_ts && p.t <= c->to_ts)
		fn(c, p.ev);
	lcm_eventlog_free_event(p.ev);
}

/* Runs FN on every event of every log inside the selected range, in time
 * order (AN_REORDER). Returns AN_EXIT_OK, AN_EXIT_BADLOG or
 * AN_EXIT_TRUNCATED; notes truncations once. */
static int an_each_event(struct an_ctx *c, an_event_fn fn, bool first_pass)
{
	uint64_t seq = 0;
	int rc = AN_EXIT_OK;
	for (int i = 0; i < c->o->nlogs; i++) {
		struct alog_reader rd;
		char err[512];
		if (alog_open(&rd, c->o->logs[i], err, sizeof(err)) != 0) {
			fprintf(c->o->msg, "undulate-analyze: %s\n", err);
			while (an_heap_n > 0)
				lcm_eventlog_free_event(an_heap_pop().ev);
			return AN_EXIT_BADLOG;
		}
		lcm_eventlog_event_t *ev;
		while ((ev = alog_next(&rd)) != NULL) {
			if (an_heap_n == AN_REORDER)
				an_take_event(c, fn, first_pass, an_heap_pop());
			an_heap_push(ev, an_event_time(ev), seq++);
		}
		if (first_pass)
			c->log_events[i] = rd.events;
		if (alog_damaged(&rd)) {
			rc = AN_EXIT_TRUNCATED;
			if (first_pass) {
				snprintf(c->trunc_note[i], sizeof(c->trunc_note[i]),
					 "truncated or damaged at byte %lld of %lld; %lld complete events before it were used",
					 (long long)rd.good_end, (long long)rd.file_size, (long long)rd.events);
				an_warn(c, "%s: %s", c->o->logs[i], c->trunc_note[i]);
			}
		}
		if (rd.events == 0 && first_pass) {
			fprintf(c->o->msg, "undulate-analyze: %s: no complete event in the log\n", c->o->logs[i]);
			alog_close(&rd);
			while (an_heap_n > 0)
				lcm_eventlog_free_event(an_heap_pop().ev);
			return AN_EXIT_BADLOG;
		}
		alog_close(&rd);
	}
	while (an_heap_n > 0)
		an_take_event(c, fn, first_pass, an_heap_pop());
	return rc;
}

/* ---- pass 1: who is there ---------------------------------------------------- */

static void an_scan_state(struct an_ctx *c, const undulate_robot_state_t *m)
{
	int ri = an_robot_find(c, m->robot, true);
	if (ri < 0)
		return;
	struct an_robot *r = &c->robots[ri];
	int nj = m->njoints < AN_MAX_JOINTS ? m->njoints : AN_MAX_JOINTS;
	if (nj > r->njoints) {
		for (int j = r->njoints; j < nj; j++)
			r->j[j].servo_id = m->joints[j].servo_id;
		r->njoints = nj;
	}
	r->states++;
	if (m->utime < c->t_origin)
		c->t_origin = m->utime;
	if (!c->have_state || m->utime > c->last_state_utime)
		c->last_state_utime = m->utime;
	c->have_state = true;
}

static void an_scan_truth(struct an_ctx *c, const undulate_sim_truth_t *m)
{
	c->truth_msgs++;
	if (m->world == UNDULATE_SIM_TRUTH_T_WORLD_PLANE && m->nlinks > 0)
		c->plane_seen = true;
	for (int i = 0; i < m->nbodies; i++) {
		const undulate_sim_body_t *b = &m->bodies[i];
		int ri = an_robot_find(c, b->robot, true);
		if (ri < 0)
			continue;
		struct an_robot *r = &c->robots[ri];
		/* A robot has one contact body; with several, the first is used. */
		if (r->have_body && r->body_servo != b->servo_id)
			continue;
		r->have_body = true;
		r->body_servo = b->servo_id;
		r->neutral = b->neutral;
		/* The lever is the body's lateral travel per radian; only
		 * measurable away from the neutral angle. */
		if (fabs(b->angle) > 0.1)
			r->lever = (b->lateral - b->neutral) / b->angle;
	}
}

static void an_scan_event(struct an_ctx *c, const lcm_eventlog_event_t *ev)
{
	c->events++;
	if (an_channel(ev->channel) != CH_UNKNOWN && an_event_time(ev) > c->last_utime)
		c->last_utime = an_event_time(ev);
	switch (an_channel(ev->channel)) {
	case CH_STATE: {
		undulate_robot_state_t m;
		if (!an_decode(c, ev, &lcmdec_robot_state_t, &m))
			return;
		if (m.utime > c->last_utime)
			c->last_utime = m.utime;
		an_scan_state(c, &m);
		lcmdec_free(&lcmdec_robot_state_t, &m);
		break;
	}
	case CH_TRUTH: {
		undulate_sim_truth_t m;
		if (!an_decode(c, ev, &lcmdec_sim_truth_t, &m))
			return;
		an_scan_truth(c, &m);
		lcmdec_free(&lcmdec_sim_truth_t, &m);
		break;
	}
	case CH_COLLISION:
		c->collision_msgs++;
		break;
	case CH_WORLD: {
		undulate_sim_world_t m;
		if (!an_decode(c, ev, &lcmdec_sim_world_t, &m))
			return;
		if (m.restitution >= 0 && m.restitution <= 1)
			c->world_restitution = m.restitution;
		lcmdec_free(&lcmdec_sim_world_t, &m);
		break;
	}
	case CH_UNKNOWN:
		c->unknown_channels++;
		break;
	default:
		break;
	}
}

/* ---- pairs ------------------------------------------------------------------ */

static bool an_robot_before(const struct an_ctx *c, int i, int k)
{
	const struct an_robot *a = &c->robots[i], *b = &c->robots[k];
	if (c->order_lateral && a->neutral != b->neutral)
		return a->neutral < b->neutral;
	return strcmp(a->name, b->name) < 0;
}

/* Neighbours are robots next to each other by neutral position when the
 * simulator tells where everyone is, by name otherwise. */
static void an_order_robots(struct an_ctx *c)
{
	c->order_lateral = c->truth_msgs > 0;
	for (int i = 0; i < c->nrobots; i++) {
		struct an_robot *r = &c->robots[i];
		if (r->njoints > 0 && !r->have_body)
			c->order_lateral = false;
		for (int j = 0; j < r->njoints; j++)
			if (r->have_body && r->j[j].servo_id == r->body_servo)
				r->contact_joint = j;
	}
	/* insertion sort: at most AN_MAX_ROBOTS, done once */
	for (int i = 0; i < c->nrobots; i++) {
		int k = i;
		while (k > 0 && an_robot_before(c, i, c->order[k - 1])) {
			c->order[k] = c->order[k - 1];
			k--;
		}
		c->order[k] = i;
	}
}

static const char *an_pair_kind_name(enum an_pair_kind kind)
{
	return kind == AN_PAIR_JOINTS ? "joints" : kind == AN_PAIR_USER ? "user" : "neighbour";
}

static struct an_pair *an_pair_add(struct an_ctx *c, enum an_pair_kind kind, int a, int ja, int b, int jb)
{
	if (c->npairs >= AN_MAX_PAIRS) {
		an_warn(c, "more than %d pairs; the rest are not followed", AN_MAX_PAIRS);
		return NULL;
	}
	struct an_pair *p = &c->pairs[c->npairs++];
	memset(p, 0, sizeof(*p));
	p->kind = kind;
	p->a = a;
	p->b = b;
	p->ja = ja;
	p->jb = jb;
	p->dsep = NAN;
	p->last_coll_t = NAN;
	p->amp_lateral = NAN;
	p->distance = NAN;
	char name[sizeof(p->name)];
	if (kind == AN_PAIR_JOINTS)
		snprintf(name, sizeof(name), "%s/%d:%d", c->robots[a].name, ja, jb);
	else
		snprintf(name, sizeof(name), "%s:%s", c->robots[a].name, c->robots[b].name);
	memcpy(p->name, name, sizeof(name));
	return p;
}

static int an_parse_pairs(struct an_ctx *c, const char *spec)
{
	char buf[4096];
	snprintf(buf, sizeof(buf), "%s", spec);
	char *save = NULL;
	for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		char *colon = strchr(tok, ':');
		if (!colon) {
			fprintf(c->o->msg, "undulate-analyze: --pairs: \"%s\" is not robot:robot\n", tok);
			return -1;
		}
		*colon = '\0';
		int a = an_robot_find(c, tok, false), b = an_robot_find(c, colon + 1, false);
		if (a < 0 || b < 0 || c->robots[a].njoints == 0 || c->robots[b].njoints == 0) {
			fprintf(c->o->msg, "undulate-analyze: --pairs: no robot state for \"%s\" in the log\n",
				a < 0 || c->robots[a].njoints == 0 ? tok : colon + 1);
			return -1;
		}
		an_pair_add(c, AN_PAIR_USER, a, c->robots[a].contact_joint, b, c->robots[b].contact_joint);
	}
	return 0;
}

static int an_make_pairs(struct an_ctx *c)
{
	an_order_robots(c);
	if (c->o->pairs) {
		if (an_parse_pairs(c, c->o->pairs) != 0)
			return -1;
	} else {
		int prev = -1;
		for (int k = 0; k < c->nrobots; k++) {
			int i = c->order[k];
			if (c->robots[i].njoints == 0)
				continue;
			if (prev >= 0)
				an_pair_add(c, AN_PAIR_NEIGHBOUR, prev, c->robots[prev].contact_joint,
					    i, c->robots[i].contact_joint);
			prev = i;
		}
	}
	for (int k = 0; k < c->nrobots; k++) {
		int i = c->order[k];
		if (c->robots[i].njoints >= 2)
			an_pair_add(c, AN_PAIR_JOINTS, i, 0, i, 1);
	}
	return 0;
}

/* ---- pass 2: CSV output ------------------------------------------------------- */

/* A CSV field: quoted, inner quotes doubled (names and event text are free text). */
static void an_hist_push(struct an_joint *j, int64_t utime, double t, double phase, double omega)
{
	j->hist[j->hnext] = (struct an_sample){ .utime = utime, .t = t, .phase = phase, .omega = omega };
	j->hnext = (j->hnext + 1) % AN_HISTORY;
	if (j->hn < AN_HISTORY)
		j->hn++;
}

/* The joint's latest sample strictly before UTIME (or the latest of all if
 * UTIME is INT64_MAX). NULL if none. */
static const struct an_sample *an_hist_before(const struct an_joint *j, int64_t utime)
{
	for (int k = 1; k <= j->hn; k++) {
		const struct an_sample *s = &j->hist[(j->hnext - k + AN_HISTORY) % AN_HISTORY];
		if (s->utime < utime)
			return s;
	}
	return NULL;
}

/* Phase of a sample carried forward to time T at its own frequency. */
static double an_phase_at(const struct an_sample *s, double t)
{
	double w = isfinite(s->omega) ? s->omega : 0.0;
	return phase_wrap(s->phase + w * (t - s->t));
}

static void an_pair_row(struct an_ctx *c, struct an_pair *p, int64_t utime, double t, double delta)
{
	fprintf(c->pdiff, "%lld,%.6f,", (long long)utime, t);
	csvrow_str(c->pdiff, p->name);
	fprintf(c->pdiff, ",%s,", an_pair_kind_name(p->kind));
	csvrow_str(c->pdiff, c->robots[p->a].name);
	fprintf(c->pdiff, ",%d,", p->ja);
	csvrow_str(c->pdiff, c->robots[p->b].name);
	fprintf(c->pdiff, ",%d", p->jb);
	csvrow_num(c->pdiff, delta);
	fputc('\n', c->pdiff);
	p->rows++;
	if (isfinite(delta))
		p->finite_rows++;
	if (t >= c->window_start_t)
		win_circ_add(&p->win, delta);
}

/* After robot RI got a sample: the phase difference of each pair it leads. */
static void an_update_pairs(struct an_ctx *c, int ri, int64_t utime, double t)
{
	for (int k = 0; k < c->npairs; k++) {
		struct an_pair *p = &c->pairs[k];
		if (p->a != ri)
			continue;
		const struct an_sample *sa = an_hist_before(&c->robots[p->a].j[p->ja], INT64_MAX);
		const struct an_sample *sb = an_hist_before(&c->robots[p->b].j[p->jb], INT64_MAX);
		if (!sa || !sb || !isfinite(sa->phase) || !isfinite(sb->phase))
			continue;
		if (fabs(sa->t - sb->t) > AN_PAIR_FRESH_S)
			continue;
		an_pair_row(c, p, utime, t, phase_wrap(an_phase_at(sb, t) - an_phase_at(sa, t)));
	}
}

/* One reason the run broke, in words (README.md, "Broken runs"). */
static void an_broken(struct an_ctx *c, const char *fmt, ...)
{
	if (c->nbroken == AN_MAX_BROKEN)
		return;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(c->broken[c->nbroken++], AN_BROKEN_TEXT, fmt, ap);
	va_end(ap);
}

/* A robot's mode changed at t: one mark per switch of the group. */
static void an_note_switch(struct an_ctx *c, double t, int mode)
{
	if (c->nswitches > 0 && c->switch_mode[c->nswitches - 1] == mode &&
	    t - c->switch_t[c->nswitches - 1] <= AN_SWITCH_MERGE_S)
		return;
	if (c->nswitches == AN_MAX_SWITCHES)
		return;
	c->switch_t[c->nswitches] = t;
	c->switch_mode[c->nswitches++] = mode;
}

static void an_on_state(struct an_ctx *c, const undulate_robot_state_t *m)
{
	int ri = an_robot_find(c, m->robot, false);
	if (ri < 0)
		return;
	struct an_robot *r = &c->robots[ri];
	double t = an_t(c, m->utime);
	int nj = m->njoints < r->njoints ? m->njoints : r->njoints;
	if (r->seen_mode && m->mode != r->mode)
		an_note_switch(c, t, m->mode);
	r->seen_mode = true;
	r->mode = m->mode;
	r->last_t = t;
	if (!r->faulted && m->fault != NULL && m->fault[0] != '\0') {
		char fault[120];
		r->faulted = true;
		an_broken(c, "robot %s latched a fault at %.1f s: %s", r->name, t, text_line(fault, sizeof fault, m->fault));
	}
	for (int j = 0; j < nj; j++) {
		const undulate_joint_state_t *js = &m->joints[j];
		struct an_joint *aj = &r->j[j];
		phase_estimator_update(&aj->est, js->angle, t);
		if (t >= c->window_start_t)
			win_swing_add(&aj->win_swing, js->angle);
		/* --frequency when given: a phase from the first sample, where
		 * an estimate needs four cycles (a pair that collides from its
		 * first swing). Else the daemon's running frequency estimate when
		 * it has one (it sees every cycle, and its phase is then ours);
		 * else our own, by the same rules (common/phase.h); else the
		 * phase is left empty. */
		double omega = c->o->frequency_hz > 0.0 ? 2.0 * M_PI * c->o->frequency_hz
		               : js->frequency > 0.0 && !c->o->zero_crossings ? 2.0 * M_PI * js->frequency
		                                                             : phase_estimator_omega(&aj->est);
		double phase = phase_from_state(js->angle, js->speed, omega);
		an_hist_push(aj, m->utime, t, phase, omega);
		aj->samples++;
		aj->reported_freq = js->frequency;

		FILE *f = c->states;
		fprintf(f, "%lld,%.6f,", (long long)m->utime, t);
		csvrow_str(f, r->name);
		fprintf(f, ",%d,%d", j, js->servo_id);
		csvrow_num(f, js->angle);
		csvrow_num(f, js->speed);
		csvrow_num(f, js->goal);
		csvrow_num(f, js->load);
		fprintf(f, ",%d", m->mode);
		csvrow_num(f, phase);
		csvrow_num(f, js->amplitude);
		csvrow_num(f, js->frequency);
		fprintf(f, ",%d", js->error_bits);
		csvrow_num(f, js->phase);
		csvrow_num(f, aj->est.frequency);
		/* the robot as a number: plots select rows by it (a name may hold
		 * quotes or commas that a gnuplot filter cannot match) */
		fprintf(f, ",%d\n", ri);
	}
	an_update_pairs(c, ri, m->utime, t);
}

static struct an_pair *an_pair_of(struct an_ctx *c, const char *left, const char *right)
{
	int l = an_robot_find(c, left, false), r = an_robot_find(c, right, false);
	if (l < 0 || r < 0)
		return NULL;
	for (int k = 0; k < c->npairs; k++) {
		struct an_pair *p = &c->pairs[k];
		if (p->kind != AN_PAIR_JOINTS && ((p->a == l && p->b == r) || (p->a == r && p->b == l)))
			return p;
	}
	return NULL;
}

static bool an_seen_before(struct an_ctx *c, const undulate_sim_collision_t *m)
{
	for (int i = 0; i < AN_COLL_DEDUP; i++) {
		const struct an_seen *s = &c->seen[i];
		if (s->utime == m->utime && s->left == m->left && s->right == m->right)
			return true;
	}
	c->seen[c->seen_next] = (struct an_seen){ m->utime, m->left, m->right };
	c->seen_next = (c->seen_next + 1) % AN_COLL_DEDUP;
	return false;
}

static void an_pair_store_delta(struct an_pair *p, int64_t utime, double delta)
{
	if (p->ndeltas == p->cap) {
		size_t cap = p->cap ? p->cap * 2 : 64;
		double *d = realloc(p->deltas, cap * sizeof(*d));
		int64_t *u = realloc(p->delta_utime, cap * sizeof(*u));
		if (d)
			p->deltas = d;
		if (u)
			p->delta_utime = u;
		if (!d || !u)
			return; /* out of memory: the return map loses points, nothing else */
		p->cap = cap;
	}
	p->deltas[p->ndeltas] = delta;
	p->delta_utime[p->ndeltas] = utime;
	p->ndeltas++;
}

static void an_on_collision(struct an_ctx *c, const undulate_sim_collision_t *m)
{
	if (an_seen_before(c, m))
		return;
	double t = an_t(c, m->utime);
	bool wall = m->left < 0 || m->right < 0;
	c->collisions++;
	c->impulse += m->impulse;
	if (wall)
		c->wall_collisions++;
	int64_t bin = (int64_t)floor(t / AN_RATE_BIN_S);
	if (bin >= 0 && bin < c->nbins) {
		c->bins[bin]++;
		c->bin_impulse[bin] += m->impulse;
		if (wall)
			c->bin_walls[bin]++;
	}
	struct an_pair *p = wall ? NULL : an_pair_of(c, m->left_robot, m->right_robot);
	double delta = NAN;
	bool new_contact = false;
	if (p) {
		const struct an_sample *sa = an_hist_before(&c->robots[p->a].j[p->ja], m->utime);
		const struct an_sample *sb = an_hist_before(&c->robots[p->b].j[p->jb], m->utime);
		if (sa && sb && isfinite(sa->phase) && isfinite(sb->phase))
			delta = phase_wrap(an_phase_at(sb, t) - an_phase_at(sa, t));
		p->collisions++;
		p->impulse += m->impulse;
		if (t >= c->window_start_t) {
			p->win_collisions++;
			if (isfinite(m->impulse))
				p->win_impulse += m->impulse;
		}
		/* A contact can be reported as a burst of collisions (one per
		 * physics step while the bodies touch); the return map wants
		 * one point per contact: the first of the burst. */
		new_contact = !(t - p->last_coll_t <= c->o->merge_s);
		p->last_coll_t = t;
		if (new_contact) {
			p->contacts++;
			if (isfinite(delta))
				an_pair_store_delta(p, m->utime, delta);
		}
	}
	csvrow_collision(c->coll, &(struct csvrow_collision){
		.utime = m->utime, .t = t, .left = m->left, .right = m->right, .left_robot = m->left_robot,
		.right_robot = m->right_robot, .pre_left = m->pre_left, .pre_right = m->pre_right,
		.post_left = m->post_left, .post_right = m->post_right, .impulse = m->impulse,
		.pair = p ? p->name : NULL, .delta = delta, .new_contact = new_contact });
}

static void an_on_bus(struct an_ctx *c, const undulate_bus_stats_t *m)
{
	int64_t timeouts = 0, checksum = 0, errrep = 0;
	for (int i = 0; i < m->nservos; i++) {
		timeouts = num_count_add(timeouts, m->servos[i].timeouts);
		checksum = num_count_add(checksum, m->servos[i].checksum_errors);
		errrep = num_count_add(errrep, m->servos[i].error_replies);
	}
	FILE *f = c->bus;
	fprintf(f, "%lld,%.6f,", (long long)m->utime, an_t(c, m->utime));
	csvrow_str(f, m->robot);
	fputc(',', f);
	csvrow_str(f, m->port);
	fprintf(f, ",%d,%d,%lld", m->baud, m->connected ? 1 : 0, (long long)m->reconnects);
	csvrow_num(f, m->adapter_latency_ms);
	fprintf(f, ",%d", m->return_delay_us);
	csvrow_nums(f, (const double[]){ m->period_p50_us, m->period_p99_us, m->period_max_us, m->jitter_p99_us,
	                                 m->bus_p99_us, m->cpu_percent }, 6);
	fprintf(f, ",%lld,%lld,%lld,%lld,%lld,%lld\n", (long long)m->overruns, (long long)m->stray_packets,
		(long long)m->io_errors, (long long)timeouts, (long long)checksum, (long long)errrep);
}

static void an_on_event(struct an_ctx *c, const undulate_event_t *m)
{
	FILE *f = c->evt;
	fprintf(f, "%lld,%.6f,", (long long)m->utime, an_t(c, m->utime));
	csvrow_str(f, m->robot);
	fprintf(f, ",%lld,%d,", (long long)m->seq, m->level);
	csvrow_str(f, m->kind);
	fputc(',', f);
	csvrow_str(f, m->text);
	fputc('\n', f);
}

static void an_on_params(struct an_ctx *c, const undulate_osc_params_t *m)
{
	FILE *f = c->params;
	for (int j = 0; j < m->njoints; j++) {
		fprintf(f, "%lld,%.6f,", (long long)m->utime, an_t(c, m->utime));
		csvrow_str(f, m->robot);
		fprintf(f, ",%d", j);
		csvrow_num(f, m->k[j]);
		csvrow_num(f, m->c[j]);
		csvrow_num(f, m->mu[j]);
		csvrow_num(f, m->lambda[j]);
		csvrow_num(f, m->inertia[j]);
		csvrow_num(f, m->friction[j]);
		csvrow_num(f, m->neutral[j]);
		csvrow_num(f, m->limit_min[j]);
		csvrow_num(f, m->limit_max[j]);
		csvrow_num(f, m->amplitude);
		csvrow_num(f, m->frequency);
		csvrow_num(f, m->phase);
		fputc('\n', f);
	}
}

/* Decodes EV as T and calls HANDLER; a message that does not decode is counted. */
#define AN_DISPATCH(T, handler)                                                   \
	do {                                                                      \
		undulate_##T m;                                                   \
		if (!an_decode(c, ev, &lcmdec_##T, &m))                           \
			return;                                                   \
		handler(c, &m);                                                   \
		lcmdec_free(&lcmdec_##T, &m);                                     \
	} while (0)

/* The plane's links and walls, at most every --plane-every seconds. A
 * link's robot is an index into the message's bodies (one per robot). */
static void an_on_plane(struct an_ctx *c, const undulate_sim_truth_t *m)
{
	double t = an_t(c, m->utime);
	if (!c->plane_csv || m->world != UNDULATE_SIM_TRUTH_T_WORLD_PLANE || !pcsv_take(&c->plane_sampler, t))
		return;
	for (int i = 0; i < m->nlinks; i++) {
		const undulate_sim_link_t *l = &m->links[i];
		double cx, cy, heading;
		if (l->robot < 0 || l->robot >= m->nbodies ||
		    !pcsv_robot_pose(m->links, m->nlinks, l->robot, &cx, &cy, &heading))
			continue;
		const char *name = m->bodies[l->robot].robot;
		fprintf(c->plane_csv, "%lld,%.6f,", (long long)m->utime, t);
		csvrow_str(c->plane_csv, name);
		fprintf(c->plane_csv, ",%d,%d", an_robot_find(c, name, false), l->link);
		csvrow_num(c->plane_csv, l->x);
		csvrow_num(c->plane_csv, l->y);
		csvrow_num(c->plane_csv, l->angle);
		csvrow_num(c->plane_csv, l->length);
		csvrow_num(c->plane_csv, l->width);
		csvrow_num(c->plane_csv, cx);
		csvrow_num(c->plane_csv, cy);
		csvrow_num(c->plane_csv, heading);
		fputc('\n', c->plane_csv);
	}
	for (int i = 0; i < m->nwalls; i++) {
		const undulate_sim_wall_t *w = &m->walls[i];
		fprintf(c->plane_walls_csv, "%lld,%.6f,%d", (long long)m->utime, t, i);
		csvrow_num(c->plane_walls_csv, w->ax);
		csvrow_num(c->plane_walls_csv, w->ay);
		csvrow_num(c->plane_walls_csv, w->bx);
		csvrow_num(c->plane_walls_csv, w->by);
		fputc('\n', c->plane_walls_csv);
	}
}

/* SIM.COLLISION is the per-collision channel; the copies inside SIM.TRUTH are
 * used only for logs without it (the simulator stamps those copies with the
 * truth message's time, so they cannot be matched to the originals). */
static void an_force_push(struct an_ctx *c, double t, double f)
{
	if (c->nforce == AN_MAX_FORCES || !isfinite(f))
		return;
	if (c->nforce == c->force_cap) {
		size_t cap = c->force_cap ? 2 * c->force_cap : 4096;
		double *ft = realloc(c->force_t, cap * sizeof *ft);
		if (ft != NULL)
			c->force_t = ft;
		double *fn = realloc(c->force_n, cap * sizeof *fn);
		if (fn != NULL)
			c->force_n = fn;
		if (ft == NULL || fn == NULL)
			return;
		c->force_cap = cap;
	}
	c->force_t[c->nforce] = t;
	c->force_n[c->nforce++] = f;
}

/* The contact forces of the SIM.TRUTH period that ended at m: each touching
 * pair's mean force over it (SIM.TRUTH's contacts: impacts and resting
 * contact, walls included); a log without contacts gives the period's total
 * (its total impulse's rise over its simulated time) when there was contact. */
static void an_truth_force(struct an_ctx *c, const undulate_sim_truth_t *m, double t)
{
	bool have = c->have_prev_truth;
	double di = m->total_impulse - c->prev_total, dt = m->sim_time - c->prev_sim_t;
	c->have_prev_truth = isfinite(m->total_impulse) && isfinite(m->sim_time);
	c->prev_total = m->total_impulse;
	c->prev_sim_t = m->sim_time;
	if (m->ncontacts > 0) {
		for (int i = 0; i < m->ncontacts; i++)
			if (m->contacts[i].impulse > 0)
				an_force_push(c, t, m->contacts[i].force);
		return;
	}
	if (have && c->have_prev_truth && dt > 0 && di > 0 && !c->have_contacts)
		an_force_push(c, t, di / dt);
}

/* Every pair's contact impulse in the final window, impacts and resting
 * contact alike, from SIM.TRUTH's contacts (bodies by index). */
static void an_truth_contacts(struct an_ctx *c, const undulate_sim_truth_t *m, double t)
{
	if (m->ncontacts > 0)
		c->have_contacts = true;
	if (t < c->window_start_t)
		return;
	for (int i = 0; i < m->ncontacts; i++) {
		const undulate_sim_contact_t *k = &m->contacts[i];
		if (k->robot_a < 0 || k->robot_a >= m->nbodies || k->robot_b < 0 || k->robot_b >= m->nbodies ||
		    !isfinite(k->impulse))
			continue;
		struct an_pair *p = an_pair_of(c, m->bodies[k->robot_a].robot, m->bodies[k->robot_b].robot);
		if (p != NULL)
			p->win_contact_impulse += k->impulse;
	}
}

static void an_truth_collisions(struct an_ctx *c, const undulate_sim_truth_t *m)
{
	double t = an_t(c, m->utime);
	c->plane |= m->world == UNDULATE_SIM_TRUTH_T_WORLD_PLANE;
	c->wall_left = m->wall_left < m->wall_right ? m->wall_left : NAN;
	c->wall_right = m->wall_left < m->wall_right ? m->wall_right : NAN;
	if (m->escaped_links > c->escaped) {
		if (c->escaped == 0)
			c->escaped_first_t = t;
		c->escaped = m->escaped_links;
	}
	if (m->worst_lateness_us > AN_LATE_US) {
		if (c->late_msgs++ == 0)
			c->late_first_t = t;
		if (m->worst_lateness_us > c->late_worst_us)
			c->late_worst_us = m->worst_lateness_us;
	}
	an_truth_force(c, m, t);
	an_truth_contacts(c, m, t);
	int64_t bin = (int64_t)floor(t / AN_RATE_BIN_S);
	if (bin >= 0 && bin < c->nbins && isfinite(m->total_impulse)) {
		c->bin_total[bin] = m->total_impulse;
		c->bin_total_t[bin] = t;
	}
	an_on_plane(c, m);
	if (c->collision_msgs > 0)
		return;
	for (int i = 0; i < m->ncollisions; i++)
		an_on_collision(c, &m->collisions[i]);
}

static void an_process_event(struct an_ctx *c, const lcm_eventlog_event_t *ev)
{
	switch (an_channel(ev->channel)) {
	case CH_STATE:
		AN_DISPATCH(robot_state_t, an_on_state);
		break;
	case CH_COLLISION:
		AN_DISPATCH(sim_collision_t, an_on_collision);
		break;
	case CH_TRUTH:
		AN_DISPATCH(sim_truth_t, an_truth_collisions);
		break;
	case CH_BUS:
		AN_DISPATCH(bus_stats_t, an_on_bus);
		break;
	case CH_EVENT:
		AN_DISPATCH(event_t, an_on_event);
		break;
	case CH_PARAMS:
		AN_DISPATCH(osc_params_t, an_on_params);
		break;
	default:
		break;
	}
}

/* ---- output files ------------------------------------------------------------- */

/* A new file NAME in the stage (nothing else can be there: it is ours, new
 * and private). */
static FILE *an_create(struct an_ctx *c, const char *name)
{
	FILE *f = outdir_stage_fopen(c->stagefd, name);
	if (!f)
		fprintf(c->o->msg, "undulate-analyze: %s/%s: %s\n", c->o->out_dir, name, strerror(errno));
	return f;
}

static FILE *an_open_out(struct an_ctx *c, const char *name, const char *header)
{
	FILE *f = an_create(c, name);
	if (f)
		fprintf(f, "%s\n", header);
	return f;
}

static int an_close_out(struct an_ctx *c, FILE **f, const char *name)
{
	if (outdir_stage_fclose(f) == 0)
		return 0;
	fprintf(c->o->msg, "undulate-analyze: writing %s/%s failed\n", c->o->out_dir, name);
	return -1;
}

/* --out: a directory of ours that no one else can write (outdir_open), and
 * the stage inside it. */
static int an_open_dir(struct an_ctx *c)
{
	char err[1024];
	c->dirfd = outdir_open(c->o->out_dir, true, err, sizeof err);
	if (c->dirfd < 0) {
		fprintf(c->o->msg, "undulate-analyze: --out %s\n", err);
		return -1;
	}
	c->stagefd = outdir_stage(c->dirfd, ".undulate-analyze", c->stage, sizeof c->stage, err, sizeof err);
	if (c->stagefd < 0) {
		fprintf(c->o->msg, "undulate-analyze: --out %s: %s\n", c->o->out_dir, err);
		return -1;
	}
	return 0;
}

/* --plots-only: the CSV files the plots' script (plots.gp) does not read —
 * the per-sample ones, hundreds of MB for a long demo — are not published:
 * they are the analysis's, kept where it was written. The plots drew from
 * them already (joints.dat, phase.dat, pair_collisions.dat). */
static void an_drop_csvs(struct an_ctx *c)
{
	static const char *const unread[] = { "states.csv", "phase_diff.csv", "collisions.csv", "plane.csv",
	                                      "plane_walls.csv", "bus.csv", "events.csv", "params.csv" };
	for (size_t i = 0; i < sizeof unread / sizeof unread[0]; i++)
		unlinkat(c->stagefd, unread[i], 0);   /* absent (no plane world): nothing to drop */
}

/* Moves what was written into --out, replacing what is there by name. */
static int an_publish(struct an_ctx *c)
{
	char err[1024];
	int rc = outdir_publish(c->dirfd, c->stagefd, c->stage, err, sizeof err);
	close(c->stagefd);
	c->stagefd = -1;
	if (rc != 0)
		fprintf(c->o->msg, "undulate-analyze: --out %s: %s\n", c->o->out_dir, err);
	return rc;
}

static int an_open_outputs(struct an_ctx *c)
{
	if (an_open_dir(c) != 0)
		return -1;
	c->states = an_open_out(c, "states.csv", CSVROW_STATES_HEADER);
	c->coll = an_open_out(c, "collisions.csv", CSVROW_COLLISIONS_HEADER);
	c->bus = an_open_out(c, "bus.csv",
		"utime,t,robot,port,baud,connected,reconnects,adapter_latency_ms,return_delay_us,period_p50_us,"
		"period_p99_us,period_max_us,jitter_p99_us,bus_p99_us,cpu_percent,overruns,stray_packets,io_errors,"
		"timeouts,checksum_errors,error_replies");
	c->evt = an_open_out(c, "events.csv", "utime,t,robot,seq,level,kind,text");
	c->pdiff = an_open_out(c, "phase_diff.csv", CSVROW_PDIFF_HEADER);
	c->params = an_open_out(c, "params.csv",
		"utime,t,robot,joint,k,c,mu,lambda,inertia,friction,neutral,limit_min,limit_max,"
		"sin_amplitude,sin_frequency,sin_phase");
	if (!c->states || !c->coll || !c->bus || !c->evt || !c->pdiff || !c->params)
		return -1;
	if (!c->plane_seen)
		return 0;
	pcsv_sampler_init(&c->plane_sampler, c->o->plane_every_s);
	c->plane_csv = an_open_out(c, "plane.csv",
		"utime,t,robot,robot_index,link,x,y,angle,length,width,centre_x,centre_y,heading");
	c->plane_walls_csv = an_open_out(c, "plane_walls.csv", "utime,t,wall,ax,ay,bx,by");
	return c->plane_csv && c->plane_walls_csv ? 0 : -1;
}

static int an_close_outputs(struct an_ctx *c)
{
	int rc = 0;
	rc |= an_close_out(c, &c->states, "states.csv");
	rc |= an_close_out(c, &c->coll, "collisions.csv");
	rc |= an_close_out(c, &c->bus, "bus.csv");
	rc |= an_close_out(c, &c->evt, "events.csv");
	rc |= an_close_out(c, &c->pdiff, "phase_diff.csv");
	rc |= an_close_out(c, &c->params, "params.csv");
	rc |= an_close_out(c, &c->plane_csv, "plane.csv");
	rc |= an_close_out(c, &c->plane_walls_csv, "plane_walls.csv");
	return rc;
}

static int an_write_return_map(struct an_ctx *c)
{
	FILE *f = an_open_out(c, "return_map.csv", "pair,n,utime,t,delta_n,delta_next,theory_next,dsep");
	if (!f)
		return -1;
	for (int k = 0; k < c->npairs; k++) {
		struct an_pair *p = &c->pairs[k];
		for (size_t n = 0; n + 1 < p->ndeltas; n++) {
			csvrow_str(f, p->name);
			double dsep = isfinite(p->dsep) ? p->dsep : 0.0;
			fprintf(f, ",%zu,%lld,%.6f", n, (long long)p->delta_utime[n], an_t(c, p->delta_utime[n]));
			csvrow_num(f, p->deltas[n]);
			csvrow_num(f, p->deltas[n + 1]);
			csvrow_num(f, theory_return_map(p->deltas[n], dsep, c->restitution));
			csvrow_num(f, p->dsep);
			fputc('\n', f);
		}
	}
	FILE *g = an_open_out(c, "collision_rate.csv",
		"t,collisions,impulse,pair_collisions,wall_collisions,contact_force");
	if (!g) {
		fclose(f);
		return -1;
	}
	/* contact force: the rate of SIM.TRUTH's total impulse between the last
	 * truth of the previous bin with one and this bin's last */
	int64_t prev = -1;
	for (int64_t b = 0; b < c->nbins; b++) {
		fprintf(g, "%.3f,%lld,%.9g,%lld,%lld,", (double)b * AN_RATE_BIN_S, (long long)c->bins[b],
			c->bin_impulse[b], (long long)(c->bins[b] - c->bin_walls[b]), (long long)c->bin_walls[b]);
		if (isfinite(c->bin_total_t[b])) {
			if (prev >= 0 && c->bin_total_t[b] > c->bin_total_t[prev])
			{
				fprintf(g, "%.9g", (c->bin_total[b] - c->bin_total[prev]) /
						   (c->bin_total_t[b] - c->bin_total_t[prev]));
				c->have_force = true;
			}
			prev = b;
		}
		fputc('\n', g);
	}
	return an_close_out(c, &f, "return_map.csv") | an_close_out(c, &g, "collision_rate.csv");
}

/* ---- classification ----------------------------------------------------------- */

static void an_pair_separation(struct an_ctx *c, struct an_pair *p)
{
	if (isfinite(c->o->separation)) {
		p->dsep = c->o->separation;
		return;
	}
	const struct an_robot *a = &c->robots[p->a], *b = &c->robots[p->b];
	if (!a->have_body || !b->have_body)
		return;
	double amp = 0.5 * (a->j[p->ja].est.amplitude + b->j[p->jb].est.amplitude);
	double lever = isfinite(a->lever) && isfinite(b->lever) ? 0.5 * (fabs(a->lever) + fabs(b->lever))
		: isfinite(a->lever) ? fabs(a->lever) : fabs(b->lever);
	p->distance = fabs(b->neutral - a->neutral);
	p->amp_lateral = lever * amp;
	if (isfinite(p->amp_lateral) && p->amp_lateral > 0.0)
		p->dsep = p->distance / (2.0 * p->amp_lateral);
}

/* The end state of a pair from the final window (see README.md for the
 * rules; classify.h holds them, shared with undulate-web). */
/* A pair's contact impulse in the final window: every contact's when the log
 * lists them, else its impacts' (older logs). */
static double an_pair_win_impulse(const struct an_pair *p, bool have_contacts)
{
	return have_contacts ? p->win_contact_impulse : p->win_impulse;
}

static const char *an_classify(const struct an_pair *p, bool have_sim, double min_swing, double window_s,
                               bool have_contacts)
{
	struct cls_window w = { .delta = p->win, .swing_a = p->swing_a, .swing_b = p->swing_b,
				.collisions = p->win_collisions, .impulse = an_pair_win_impulse(p, have_contacts),
				.window_s = window_s,
				.dsep = p->dsep, .have_sim = have_sim, .min_swing = min_swing };
	return cls_end_state(&w);
}

/* What broke the run besides the faults seen on the way: robots that
 * stopped publishing before the log's end, a simulator that fell behind. */
static void an_check_broken(struct an_ctx *c)
{
	double end = an_t(c, c->last_utime);
	for (int k = 0; k < c->nrobots; k++) {
		const struct an_robot *r = &c->robots[c->order[k]];
		if (r->states > 0 && end - r->last_t > AN_STOPPED_S)
			an_broken(c, "robot %s stopped publishing at %.1f s (the log runs to %.1f s): its daemon died or "
			          "lost its bus", r->name, r->last_t, end);
	}
	if (c->escaped > 0)
		an_broken(c, "the simulated world broke: links were pushed out through the walls (%lld link-steps outside, "
		          "the first seen at %.1f s)", (long long)c->escaped, c->escaped_first_t);
	/* a few late steps on a busy machine are caught up (the servos' replies
	 * are stamped by the schedule); a run whose physics kept falling behind,
	 * or once stood still for a tenth of a second, is not the experiment */
	if (c->late_msgs > AN_LATE_SHARE * (double)c->truth_msgs || c->late_worst_us > AN_LATE_WORST_US)
		an_broken(c, "the simulator fell behind real time: %lld truth period(s) with a step more than %.0f ms "
		          "late, the first at %.1f s, the worst %.0f ms", (long long)c->late_msgs, AN_LATE_US / 1000.0,
		          c->late_first_t, c->late_worst_us / 1000.0);
}

/* The switch from the clock to the oscillator: the first mode switch to
 * OSCILLATOR; NAN when the run never switched. */
static double an_switch_time(const struct an_ctx *c)
{
	for (int i = 0; i < c->nswitches; i++)
		if (c->switch_mode[i] == UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR)
			return c->switch_t[i];
	return NAN;
}

static int an_cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* The median contact force (N) of the truth periods with contact in
 * [from, to); NAN when none (*n = 0). */
static double an_force_median(const struct an_ctx *c, double from, double to, size_t *n)
{
	*n = 0;
	if (!(to > from) || c->nforce == 0)
		return NAN;
	double *v = malloc(c->nforce * sizeof *v);
	if (v == NULL)
		return NAN;
	for (size_t i = 0; i < c->nforce; i++)
		if (c->force_t[i] >= from && c->force_t[i] < to)
			v[(*n)++] = c->force_n[i];
	double med = NAN;
	if (*n > 0) {
		qsort(v, *n, sizeof *v, an_cmp_double);
		med = *n % 2 ? v[*n / 2] : 0.5 * (v[*n / 2 - 1] + v[*n / 2]);
	}
	free(v);
	return med;
}

struct an_forces {
	double switch_t, before, after;   /* s; N, N */
	size_t nbefore, nafter;
	double before_from, after_from, end;
};

/* Before: the --window seconds before the switch; after: the final window. */
static void an_forces(const struct an_ctx *c, struct an_forces *f)
{
	f->end = an_t(c, c->last_utime);
	f->switch_t = an_switch_time(c);
	f->before_from = isfinite(f->switch_t) ? fmax(0.0, f->switch_t - c->o->window_s) : NAN;
	f->after_from = fmax(isfinite(f->switch_t) ? f->switch_t : 0.0, f->end - c->o->window_s);
	f->before = isfinite(f->switch_t) ? an_force_median(c, f->before_from, f->switch_t, &f->nbefore) : NAN;
	if (!isfinite(f->switch_t))
		f->nbefore = 0;
	f->after = an_force_median(c, f->after_from, f->end + 1e-9, &f->nafter);
}

/* ---- summary ------------------------------------------------------------------ */

static void an_summary_text(struct an_ctx *c, FILE *f, int rc)
{
	fprintf(f, "undulate-analyze summary\n");
	for (int i = 0; i < c->nbroken; i++)
		fprintf(f, "BROKEN: %s\n", c->broken[i]);
	for (int i = 0; i < c->o->nlogs; i++)
		fprintf(f, "log: %s (%lld events)%s%s\n", c->o->logs[i], (long long)c->log_events[i],
			c->trunc_note[i][0] ? " WARNING: " : "", c->trunc_note[i]);
	double t_end = c->have_state ? an_t(c, c->last_state_utime) : 0.0;
	fprintf(f, "span: %.2f s of robot state; final window %.2f .. %.2f s (%.1f s)\n", t_end,
		c->window_start_t > 0 ? c->window_start_t : 0.0, t_end, c->o->window_s);
	fprintf(f, "robots: %d, order: %s\n", c->nrobots,
		c->order_lateral ? "lateral neutral position (SIM.TRUTH)" : "name");
	for (int k = 0; k < c->nrobots; k++) {
		const struct an_robot *r = &c->robots[c->order[k]];
		fprintf(f, "  %-16s joints %d  states %lld", r->name, r->njoints, (long long)r->states);
		for (int j = 0; j < r->njoints; j++)
			fprintf(f, "  j%d %.3f Hz %.3f rad", j, r->j[j].est.frequency, r->j[j].est.amplitude);
		if (r->have_body)
			fprintf(f, "  neutral %.4f m lever %.4f m/rad", r->neutral, r->lever);
		if (r->njoints > 0)
			fputs("  swing", f);
		for (int j = 0; j < r->njoints; j++)
			fprintf(f, " j%d %.3f", j, win_swing_pp(&r->j[j].win_swing));
		if (r->njoints > 0)
			fputs(" rad p-p", f);
		fputc('\n', f);
	}
	fprintf(f, "world: %s\n", c->plane ? "plane (links in a plane)" : c->truth_msgs > 0 ? "row (the theory's line)"
	                                                                       : "unknown (no simulator in the log)");
	fprintf(f, "collisions: %lld (%lld with walls), total impulse %.6g N*s\n", (long long)c->collisions,
		(long long)c->wall_collisions, c->impulse);
	struct an_forces fo;
	an_forces(c, &fo);
	if (isfinite(fo.switch_t))
		fprintf(f, "contact force, median of %s: %.4g N before the switch to OSCILLATOR at %.1f s (%.1f..%.1f s, "
			"%zu of them), %.4g N in the final window (%.1f..%.1f s, %zu)\n",
			c->have_contacts ? "every contact (a touching pair's mean force over a truth period)"
			                 : "the truth periods with contact (their total)",
			fo.before, fo.switch_t, fo.before_from, fo.switch_t, fo.nbefore, fo.after, fo.after_from, fo.end,
			fo.nafter);
	else if (c->truth_msgs > 0)
		fprintf(f, "contact force, median of %s in the final window: %.4g N (%zu of them; no switch to OSCILLATOR "
			"in the log)\n", c->have_contacts ? "every contact" : "the truth periods with contact", fo.after,
			fo.nafter);
	fprintf(f, "grazing: a pair locked within its compatibility bound + %.2f rad whose contacts in the final "
		"window average at most %.3f N (F.win: %s over the window; more: still-colliding)\n", CLS_COMPAT_TOL,
		CLS_GRAZE_FORCE_N, c->have_contacts ? "every contact's impulse, resting included," : "the impacts' impulse");
	fprintf(f, "restitution for theory: %.3f (%s); collisions less than %.3f s apart are one contact\n",
		c->restitution, c->restitution_from, c->o->merge_s);
	fprintf(f, "not oscillating: a joint of the pair swings less than %.3f rad peak-to-peak in the final window\n",
		c->o->min_swing);
	double win = fmin(c->o->window_s, t_end);
	fprintf(f, "%-24s %-28s %8s %8s %8s %6s %6s %7s %9s %5s %8s %8s %8s\n", "pair", "end state", "mean|D|", "meanD",
		"spread", "coll", "c.win", "d~", "2asin(d~)", "map", "F.win", "swing_a", "swing_b");
	for (int k = 0; k < c->npairs; k++) {
		const struct an_pair *p = &c->pairs[k];
		fprintf(f, "%-24s %-28s %8.4f %8.4f %8.4f %6lld %6lld %7.4f %9.4f %5zu %8.4f %8.4f %8.4f\n", p->name,
			p->cls, win_circ_mean_abs(&p->win), win_circ_mean(&p->win), win_circ_spread(&p->win),
			(long long)p->collisions, (long long)p->win_collisions, p->dsep,
			theory_compat_limit(p->dsep), p->ndeltas > 0 ? p->ndeltas - 1 : 0,
			win > 0 ? an_pair_win_impulse(p, c->have_contacts) / win : NAN, p->swing_a, p->swing_b);
	}
	if (c->decode_errors)
		fprintf(f, "undecodable messages: %lld\n", (long long)c->decode_errors);
	if (rc == AN_EXIT_TRUNCATED)
		fprintf(f, "WARNING: a log was truncated; results cover the events before the damage\n");
}

static void an_json_robot(struct json *j, const struct an_robot *r)
{
	json_object_begin(j);
	json_field_string(j, "name", r->name);
	json_field_int(j, "states", r->states);
	json_key(j, "joints");
	json_array_begin(j);
	for (int k = 0; k < r->njoints; k++) {
		json_object_begin(j);
		json_field_number(j, "frequency_hz", r->j[k].est.frequency);
		json_field_number(j, "amplitude_rad", r->j[k].est.amplitude);
		json_field_number(j, "swing_rad", win_swing_pp(&r->j[k].win_swing));
		json_object_end(j);
	}
	json_array_end(j);
	json_object_end(j);
}

static void an_json_pair(struct json *j, const struct an_pair *p)
{
	pairsum_json(j, &(struct pairsum){
		.name = p->name, .kind = an_pair_kind_name(p->kind), .cls = p->cls, .win = &p->win,
		.collisions = p->collisions, .contacts = p->contacts, .win_collisions = p->win_collisions,
		.win_impulse = p->win_impulse, .win_contact_impulse = p->win_contact_impulse, .impulse = p->impulse,
		.distance = p->distance, .amplitude = p->amp_lateral, .dsep = p->dsep,
		.return_map_points = p->ndeltas > 0 ? (int64_t)p->ndeltas - 1 : 0,
		.swing_a = p->swing_a, .swing_b = p->swing_b });
}

static void an_summary_json(struct an_ctx *c, FILE *f, int rc)
{
	struct json j;
	json_init(&j, f, AN_JSON_DIGITS);
	json_object_begin(&j);
	json_key(&j, "logs");
	json_array_begin(&j);
	for (int i = 0; i < c->o->nlogs; i++) {
		json_object_begin(&j);
		json_field_string(&j, "path", c->o->logs[i]);
		json_field_int(&j, "events", c->log_events[i]);
		json_field_bool(&j, "truncated", c->trunc_note[i][0] != '\0');
		json_object_end(&j);
	}
	json_array_end(&j);
	json_field_bool(&j, "truncated", rc == AN_EXIT_TRUNCATED);
	json_field_string(&j, "world", c->plane ? "plane" : c->truth_msgs > 0 ? "row" : "unknown");
	json_key(&j, "broken");
	json_array_begin(&j);
	for (int i = 0; i < c->nbroken; i++)
		json_string(&j, c->broken[i]);
	json_array_end(&j);
	struct an_forces fo;
	an_forces(c, &fo);
	json_key(&j, "walls");
	json_object_begin(&j);
	json_field_number(&j, "left_m", c->wall_left);
	json_field_number(&j, "right_m", c->wall_right);
	json_object_end(&j);
	json_key(&j, "force");
	json_object_begin(&j);
	json_field_number(&j, "switch_s", fo.switch_t);
	json_field_number(&j, "median_before_n", fo.before);
	json_field_string(&j, "of", c->have_contacts ? "contacts" : "periods");
	json_field_int(&j, "samples_before", (int64_t)fo.nbefore);
	json_field_number(&j, "median_after_n", fo.after);
	json_field_int(&j, "samples_after", (int64_t)fo.nafter);
	json_field_number(&j, "before_from_s", fo.before_from);
	json_field_number(&j, "after_from_s", fo.after_from);
	json_object_end(&j);
	json_field_number(&j, "t_end", c->have_state ? an_t(c, c->last_state_utime) : NAN);
	json_field_number(&j, "window_s", c->o->window_s);
	json_field_number(&j, "restitution", c->restitution);
	json_field_string(&j, "restitution_from", c->restitution_from);
	json_field_string(&j, "order", c->order_lateral ? "lateral" : "name");
	json_field_int(&j, "collisions", c->collisions);
	json_field_int(&j, "wall_collisions", c->wall_collisions);
	json_field_number(&j, "impulse", c->impulse);
	json_field_int(&j, "decode_errors", c->decode_errors);
	json_key(&j, "robots");
	json_array_begin(&j);
	for (int k = 0; k < c->nrobots; k++)
		an_json_robot(&j, &c->robots[c->order[k]]);
	json_array_end(&j);
	json_key(&j, "pairs");
	json_array_begin(&j);
	for (int k = 0; k < c->npairs; k++)
		an_json_pair(&j, &c->pairs[k]);
	json_array_end(&j);
	json_field_number(&j, "min_swing", c->o->min_swing);
	json_object_end(&j);
	fputc('\n', f);
}

static int an_write_summary(struct an_ctx *c, int rc)
{
	FILE *f = an_create(c, "summary.txt");
	FILE *g = an_create(c, "summary.json");
	if (!f || !g) {
		fprintf(c->o->msg, "undulate-analyze: cannot write the summary in %s\n", c->o->out_dir);
		if (f)
			fclose(f);
		if (g)
			fclose(g);
		return -1;
	}
	an_summary_text(c, f, rc);
	an_summary_json(c, g, rc);
	if (!c->o->quiet)
		an_summary_text(c, stdout, rc);
	return an_close_out(c, &f, "summary.txt") | an_close_out(c, &g, "summary.json");
}

/* ---- plots -------------------------------------------------------------------- */

static int an_plots(struct an_ctx *c)
{
	const char *names[AN_MAX_ROBOTS];
	int njoints[AN_MAX_ROBOTS];
	unsigned joint_mask[AN_MAX_ROBOTS];
	int robot_index[AN_MAX_ROBOTS];
	struct plot_pair pp[AN_MAX_PAIRS];
	struct plot_switch sw[AN_MAX_SWITCHES];
	int n = 0, np = 0;
	for (int k = 0; k < c->nrobots; k++) {
		const struct an_robot *r = &c->robots[c->order[k]];
		unsigned mask = 0;
		for (int j = 0; j < r->njoints && j < 32; j++)
			if (r->j[j].samples > 0)
				mask |= 1u << j;
		if (mask != 0) {
			names[n] = r->name;
			robot_index[n] = c->order[k];
			joint_mask[n] = mask;
			njoints[n++] = r->njoints;
		}
	}
	for (int k = 0; k < c->npairs; k++) {
		const struct an_pair *p = &c->pairs[k];
		if (p->kind == AN_PAIR_JOINTS)
			continue;
		pp[np++] = (struct plot_pair){ .name = p->name, .dsep = p->dsep,
					       .map_points = p->ndeltas > 0 ? (int)p->ndeltas - 1 : 0,
					       .delta_points = (int)(p->finite_rows < INT32_MAX ? p->finite_rows : INT32_MAX),
					       .collisions = (int)(p->collisions < INT32_MAX ? p->collisions : INT32_MAX) };
	}
	for (int i = 0; i < c->nswitches; i++)
		sw[i] = (struct plot_switch){ .t = c->switch_t[i], .to = mode_name(c->switch_mode[i]) };
	struct plot_input in = { .dir = c->o->out_dir, .dirfd = c->stagefd, .robots = names, .njoints = njoints, .joint_mask = joint_mask, .robot_index = robot_index, .nrobots = n,
				 .pairs = pp, .npairs = np, .switches = sw, .nswitches = c->nswitches,
				 .window_start = c->window_start_t > 0 ? c->window_start_t : 0.0,
				 .restitution = c->restitution, .restitution_from = c->restitution_from,
				 .have_collisions = c->collisions > 0, .have_force = c->have_force };
	return plot_all(&in, c->o->msg);
}

/* ---- entry -------------------------------------------------------------------- */

static void an_free(struct an_ctx *c)
{
	for (int k = 0; k < c->npairs; k++) {
		free(c->pairs[k].deltas);
		free(c->pairs[k].delta_utime);
	}
	free(c->bins);
	free(c->bin_impulse);
	free(c->bin_walls);
	free(c->bin_total);
	free(c->bin_total_t);
	free(c->force_t);
	free(c->force_n);
	an_close_outputs(c);
	if (c->stagefd >= 0) {
		outdir_discard(c->dirfd, c->stagefd, c->stage);
		close(c->stagefd);
	}
	if (c->dirfd >= 0)
		close(c->dirfd);
}

static int an_alloc_bins(struct an_ctx *c)
{
	double span = an_t(c, c->last_utime);
	c->nbins = span > 0 ? (int64_t)floor(span / AN_RATE_BIN_S) + 1 : 1;
	if (c->nbins > AN_MAX_BINS)
		c->nbins = AN_MAX_BINS;
	c->bins = calloc((size_t)c->nbins, sizeof(*c->bins));
	c->bin_impulse = calloc((size_t)c->nbins, sizeof(*c->bin_impulse));
	c->bin_walls = calloc((size_t)c->nbins, sizeof(*c->bin_walls));
	c->bin_total = calloc((size_t)c->nbins, sizeof(*c->bin_total));
	c->bin_total_t = malloc((size_t)c->nbins * sizeof(*c->bin_total_t));
	if (!c->bins || !c->bin_impulse || !c->bin_walls || !c->bin_total || !c->bin_total_t)
		return -1;
	for (int64_t b = 0; b < c->nbins; b++)
		c->bin_total_t[b] = NAN;
	return 0;
}

static int an_run_ctx(struct an_ctx *c)
{
	const struct an_options *o = c->o;
	c->world_restitution = NAN;
	c->wall_left = c->wall_right = NAN;
	int rc = an_each_event(c, an_scan_event, true);
	if (rc == AN_EXIT_BADLOG)
		return rc;
	/* The theory for the run's own restitution: the user's word, else the
	 * simulator's (SIM.WORLD), else the paper's rig. */
	if (!isnan(o->restitution)) {
		c->restitution = o->restitution;
		c->restitution_from = "--restitution";
	} else if (!isnan(c->world_restitution)) {
		c->restitution = c->world_restitution;
		c->restitution_from = "the simulator's, SIM.WORLD";
	} else {
		c->restitution = AN_DEFAULT_RESTITUTION;
		c->restitution_from = "the paper's rig: no SIM.WORLD in the log";
	}
	if (!c->have_state)
		an_warn(c, "no robot state (<robot>.STATE) in the selected part of the log");
	if (an_make_pairs(c) != 0)
		return AN_EXIT_USAGE;
	if (an_alloc_bins(c) != 0 || an_open_outputs(c) != 0)
		return AN_EXIT_OUTPUT;
	c->window_start_t = an_t(c, c->last_state_utime) - o->window_s;
	c->have_origin = false; /* pass 2 recomputes the same origin and range */
	an_each_event(c, an_process_event, false);
	for (int k = 0; k < c->npairs; k++) {
		struct an_pair *p = &c->pairs[k];
		p->swing_a = win_swing_pp(&c->robots[p->a].j[p->ja].win_swing);
		p->swing_b = win_swing_pp(&c->robots[p->b].j[p->jb].win_swing);
		if (p->kind != AN_PAIR_JOINTS)
			an_pair_separation(c, p);
		p->cls = p->kind == AN_PAIR_JOINTS ? "-"
			: an_classify(p, c->truth_msgs > 0 || c->collisions > 0, o->min_swing,
			              fmin(o->window_s, an_t(c, c->last_state_utime)), c->have_contacts);
	}
	an_check_broken(c);
	if (an_close_outputs(c) != 0 || an_write_return_map(c) != 0 || an_write_summary(c, rc) != 0)
		return AN_EXIT_OUTPUT;
	if (o->plots && an_plots(c) != 0)
		return rc == AN_EXIT_OK ? AN_EXIT_PLOTS : rc;
	return rc;
}

/* An --out that exists and will be refused is refused before the logs are
 * read (a long log takes a while); one that does not exist is made only
 * once there is something to write (a log that is not a log writes nothing). */
static int an_check_out_early(const struct an_options *o)
{
	struct stat st;
	if (lstat(o->out_dir, &st) != 0)
		return 0;
	char err[1024];
	int fd = outdir_open(o->out_dir, false, err, sizeof err);
	if (fd < 0) {
		fprintf(o->msg, "undulate-analyze: --out %s\n", err);
		return -1;
	}
	close(fd);
	return 0;
}

int an_run(const struct an_options *o)
{
	if (o->nlogs <= 0) {
		fprintf(o->msg, "undulate-analyze: no log given\n");
		return AN_EXIT_USAGE;
	}
	if (an_check_out_early(o) != 0)
		return AN_EXIT_OUTPUT;
	struct an_ctx *c = calloc(1, sizeof(*c));
	if (!c) {
		fprintf(o->msg, "undulate-analyze: out of memory\n");
		return AN_EXIT_OUTPUT;
	}
	c->o = o;
	c->dirfd = c->stagefd = -1;
	int rc = an_run_ctx(c);
	/* whatever was written, even when a later step failed (a truncated log's
	 * results, CSV files without their plots), as when it was written in place */
	if (c->stagefd >= 0) {
		an_close_outputs(c);
		if (o->plots_only)
			an_drop_csvs(c);
		if (an_publish(c) != 0)
			rc = AN_EXIT_OUTPUT;
	}
	an_free(c);
	free(c);
	return rc;
}
