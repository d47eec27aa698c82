/* hist.h — what undulate-web remembers for its plots: the last HIST_SECONDS
 * of every robot's joints, every neighbouring pair's phase difference with
 * its compatibility bound and end state, mode switches, and the simulator's
 * collisions and contact force in one-second bins. Samples are taken from
 * undulate-top's model (tools/top/model.h) at HIST_HZ, whatever rate the
 * robots publish at: the browser draws HIST_HZ points per second per line.
 * Pure: the model and the current time come in as arguments, no I/O.
 *
 * Everything is indexed by a running count (sample, bin, mark), so that each
 * browser keeps a cursor and gets only what is new since its last frame
 * (frame.h); a cursor older than the ring simply starts at its oldest entry. */
#ifndef UNDULATE_WEB_HIST_H
#define UNDULATE_WEB_HIST_H

#include <stdbool.h>
#include <stdint.h>

#include "tools/top/model.h"
#include "wcontact.h"

#define HIST_HZ 25                 /* samples per second: smooth at a 10-20 Hz frame rate */
#define HIST_SECONDS 30            /* the plots' time span */
#define HIST_N (HIST_HZ * HIST_SECONDS)
#define HIST_PAIRS TOP_MAX_ROBOTS  /* pair slots; pairs no longer neighbours are recycled */
#define HIST_PAIR_COLL 256         /* collision times kept per pair (the class window's) */
#define HIST_CLASS_S 10.0          /* end-state window: undulate-analyze's default --window */
#define HIST_CLASS_EVERY 12        /* samples between two classifications (~2 Hz) */
#define HIST_MARKS 64              /* mode switches kept */
#define HIST_BIN_S 1.0             /* collision / contact-force bin */
#define HIST_BINS 300              /* five minutes of bins */
#define HIST_GAP_S 0.25            /* no STATE for this long: the plots show a gap, not the last angle repeated */

struct hist_pair {
	bool used;
	int a, b;                   /* robot indices in the model (stable: robots are never removed) */
	uint64_t first;             /* first sample index with data */
	uint64_t last_use;          /* last sample it was a neighbouring pair */
	float delta[HIST_N];        /* rad, phase(b) - phase(a) on the contact joints */
	float bound[HIST_N];        /* rad, 2 asin(d~); NAN unknown */
	double coll_t[HIST_PAIR_COLL];
	int ncoll, collnext;
	const char *cls;            /* end state (classify.h), "no-data" at first */
};

struct hist_mark {
	int64_t t_ms;
	int robot;
	int8_t mode;
};

struct hist {
	double t0;                  /* monotonic s of the first sample: times are ms after it */
	uint64_t next;              /* samples taken */
	int64_t t_ms[HIST_N];
	int nrobots;                /* robots with a slot (the model's first nrobots) */
	uint64_t robot_first[TOP_MAX_ROBOTS];
	float angle[TOP_MAX_ROBOTS][TOP_MAX_JOINTS][HIST_N];
	float speed[TOP_MAX_ROBOTS][TOP_MAX_JOINTS][HIST_N];
	struct hist_pair pairs[HIST_PAIRS];
	int pair_of[TOP_MAX_ROBOTS];   /* the pair slot of (order[k], order[k+1]), -1 none */
	int npairs_now;                /* model neighbours at the last sample */
	int8_t last_mode[TOP_MAX_ROBOTS];
	uint64_t nmarks;
	struct hist_mark marks[HIST_MARKS];
	/* simulator bins */
	double bin_t0;              /* monotonic s the open bin began; 0: none */
	int64_t bin_coll0;
	double bin_imp0;
	uint64_t nbins;
	int64_t bin_t_ms[HIST_BINS];
	int32_t bin_coll[HIST_BINS];
	float bin_force[HIST_BINS];  /* N: total impulse (impacts and resting contact) per second */
	int64_t untracked_collisions; /* SIM.COLLISION naming robots that are no neighbouring pair */
	struct wct contacts;         /* the simulator's contacts, for the world view's marks */
};

void hist_init(struct hist *h, double now);
/* Takes one sample of m at monotonic time now (call at HIST_HZ). */
void hist_sample(struct hist *h, const struct top_model *m, double now);
/* A collision heard on SIM.COLLISION between two robots (wall hits: a name
 * is ""), for the end state's "still-colliding". */
void hist_on_collision(struct hist *h, const struct top_model *m, const char *left, const char *right,
                       double now);

/* The contacts summed since the last call become marks stamped now (call
 * at the frame rate: wcontact.h). */
void hist_close_contacts(struct hist *h, double now);

/* Oldest sample index still held. */
uint64_t hist_oldest(const struct hist *h);
uint64_t hist_oldest_bin(const struct hist *h);
uint64_t hist_oldest_mark(const struct hist *h);
/* Ring slot of a running index. */
static inline int hist_slot(uint64_t i) { return (int)(i % HIST_N); }

#endif
