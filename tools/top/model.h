/* model.h — undulate-top's picture of the LCM network: every robot heard,
 * the simulator's collisions, derived rates and phase differences. No I/O:
 * messages and the current time come in as arguments, so tests drive it. */
#ifndef UNDULATE_TOP_MODEL_H
#define UNDULATE_TOP_MODEL_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "undulate_bus_stats_t.h"
#include "undulate_event_t.h"
#include "undulate_osc_params_t.h"
#include "undulate_robot_state_t.h"
#include "undulate_sim_collision_t.h"
#include "undulate_sim_truth_t.h"

#define TOP_MAX_ROBOTS 64      /* robots tracked; the paper's largest group is 10, ours 20 */
#define TOP_MAX_JOINTS 4       /* joints shown per robot (ours have 2) */
#define TOP_NAME_MAX 48        /* robot name length kept */
#define TOP_TEXT_MAX 96        /* mode reason / event text kept */
#define TOP_WINDOW 128         /* per-cycle samples kept for rate and jitter: > 1 s at 100 Hz */
#define TOP_STALE_S 1.0        /* no STATE for this long: marked stale (kept) */
#define TOP_COLL_WINDOW_S 10.0 /* collision-rate window */
#define TOP_COLL_RING 2048     /* collision times kept: 200/s over the window */
#define TOP_COLL_DEDUP 64      /* recent collisions: one seen on SIM.COLLISION and SIM.TRUTH counts once */
#define TOP_SIM_STALE_S 2.0    /* simulator considered gone after this long */
#define TOP_JSON_DIGITS 12     /* significant digits of --json numbers */
#define TOP_TREND_S 5.0        /* contact trend: window length, s */
#define TOP_TREND_N 12         /* windows kept (a minute) */
/* The simulator's world as its last SIM.TRUTH drew it (struct top_world).
 * Everything in it came from the network: indices are checked against what
 * the message holds, numbers against what an arena can be. */
#define TOP_MAX_LINKS (TOP_MAX_JOINTS + 1) /* a robot's links in the plane: one more than its joints */
#define TOP_WORLD_WALLS 16     /* wall segments kept (the simulator makes at most 8) */
#define TOP_WORLD_CONTACTS 256 /* touching pairs kept of one message (the simulator lists at most 256) */
#define TOP_WORLD_BODIES 256   /* bodies[] a link or contact may name (more: refused) */
#define TOP_WORLD_EXTENT_M 100.0 /* |x|, |y| beyond this is no place in an arena: refused */
#define TOP_WORLD_SIZE_M 10.0  /* a link longer or wider than this is no robot's: refused */

struct top_joint {
	int16_t servo_id;
	double angle, speed, goal, load, phase, amplitude, frequency;
	double drive;          /* torque actuation: output ratio sent (NaN with goals) */
	double temperature;    /* °C, as the servo last reported */
	double voltage;        /* V */
	int16_t error_bits;
	int32_t stale_cycles;
	bool torque;           /* torque wanted on (the daemon's writes) */
	int8_t torque_read;    /* as the servo last reported it: 0, 1; -1 not read yet */
};

/* One rigid link of a robot in the plane world, from the last SIM.TRUTH. */
struct top_link {
	bool have;
	double x, y;               /* m, its centre */
	double angle;              /* rad, rear to front, wrapped to (-pi, pi] */
	double length, width;      /* m */
};

struct top_robot {
	char name[TOP_NAME_MAX];
	bool have_state;
	double rx;                 /* s (monotonic), last STATE */
	int64_t utime, cycle;
	int8_t mode;
	char mode_reason[TOP_TEXT_MAX];
	char fault[TOP_TEXT_MAX];          /* a latched fault ("" when none) */
	double period_us[TOP_WINDOW], jitter_us[TOP_WINDOW], rx_times[TOP_WINDOW];
	int nwin, winnext;
	int64_t overruns, bus_errors, bad_commands, states;
	int njoints;
	struct top_joint j[TOP_MAX_JOINTS];
	/* <robot>.BUS */
	bool have_bus, connected;
	int64_t timeouts, checksum_errors, io_errors, reconnects;
	double cpu_percent, adapter_latency_ms;
	/* <robot>.PARAMS */
	bool have_params;
	int nparams;
	double c[TOP_MAX_JOINTS], mu[TOP_MAX_JOINTS], k[TOP_MAX_JOINTS];
	double sin_amplitude, sin_frequency;
	/* SIM.TRUTH */
	struct top_link links[TOP_MAX_LINKS]; /* the plane: its links, by index (0: the head) */
	bool have_body;
	int16_t body_servo;
	double neutral, lateral;
	double lever;              /* m per rad of the contact joint; NAN until seen swinging */
	/* <robot>.EVENT */
	char last_event[TOP_TEXT_MAX];
	int64_t last_event_seq;
	int8_t last_event_level;
};

struct top_seen {
	int64_t utime;
	int32_t left, right;
};

/* A pair touching in the last SIM.TRUTH's period (sim_contact_t), its
 * robots as model indices. */
struct top_contact {
	int a, b;                  /* robots (indices into top_model.robots); b -1: a wall */
	int link_a, link_b;        /* links; a wall's index in walls[] when b is -1 (-1 on the row) */
	double x, y;               /* m, the last contact point */
	double nx, ny;             /* the contact normal, a to b (0 when the message's was not finite) */
	double impulse;            /* N·s over the period */
	double force;              /* N, the period's mean contact force */
	bool impact;               /* began touching in it (else resting contact) */
};

struct top_world {
	int64_t truths;            /* SIM.TRUTH messages taken (0: none) */
	bool plane;                /* world = WORLD_PLANE (else the row) */
	double wall_left, wall_right; /* m; NAN both: no walls (the row's wall_left >= wall_right) */
	int nwalls;
	struct { double ax, ay, bx, by; } walls[TOP_WORLD_WALLS];
	int ncontacts;             /* of the last message */
	struct top_contact contacts[TOP_WORLD_CONTACTS];
	/* links, walls and contacts refused, by why (all counted, none kept): */
	int64_t bad_index;         /* a robot index outside bodies[] (or not a robot's), a link outside
	                              0..TOP_MAX_LINKS-1, a wall outside walls[] */
	int64_t bad_number;        /* NaN, inf, beyond TOP_WORLD_EXTENT_M, a size outside (0, TOP_WORLD_SIZE_M],
	                              a negative impulse or force */
	int64_t overflow;          /* more walls or contacts than kept */
};

struct top_model {
	struct top_robot robots[TOP_MAX_ROBOTS];
	int nrobots;
	int64_t dropped_robots;     /* messages of a robot not kept: table full, or not a robot's name */
	int order[TOP_MAX_ROBOTS];  /* display order (indices into robots) */
	bool order_lateral;
	/* simulator */
	bool have_sim;
	double sim_rx;
	double coll_direct_rx;      /* s, last SIM.COLLISION (0 = never) */
	int64_t sim_total_collisions;
	double sim_total_impulse;
	int64_t collisions_heard;   /* distinct collisions received */
	double impulse_heard;
	double coll_rx[TOP_COLL_RING];
	double coll_impulse[TOP_COLL_RING];
	int ncoll, collnext;
	struct top_seen seen[TOP_COLL_DEDUP];
	int seennext;
	/* contact trend from SIM.TRUTH's running totals: per TOP_TREND_S window
	 * the impacts and the mean contact force (impacts and resting contact) */
	double trend_t0;            /* s (monotonic) the open window began; 0: none */
	int64_t trend_coll0;
	double trend_imp0;
	int64_t trend_coll[TOP_TREND_N];
	double trend_force[TOP_TREND_N];
	int ntrend, trendnext;
	int64_t decode_errors;
	struct top_world world;     /* the simulator's, as its last SIM.TRUTH drew it */
};

void top_model_init(struct top_model *m);
/* NOW: monotonic seconds at reception. */
void top_on_state(struct top_model *m, const undulate_robot_state_t *s, double now);
void top_on_bus(struct top_model *m, const undulate_bus_stats_t *b);
void top_on_params(struct top_model *m, const undulate_osc_params_t *p);
void top_on_event(struct top_model *m, const undulate_event_t *e);
/* Also the world (m->world, each robot's links): replaced by every message,
 * what does not pass the checks of struct top_world refused and counted. */
void top_on_truth(struct top_model *m, const undulate_sim_truth_t *t, double now);
void top_on_collision(struct top_model *m, const undulate_sim_collision_t *c, double now);
/* A collision received on SIM.COLLISION itself. */
void top_on_sim_collision(struct top_model *m, const undulate_sim_collision_t *c, double now);

/* Sorts the display order: by neutral position when the simulator reports
 * every robot's body, by name otherwise. */
void top_model_order(struct top_model *m);
int top_robot_index(const struct top_model *m, const char *name);

bool top_robot_stale(const struct top_robot *r, double now);
/* A joint whose servo has not given a valid reading for a cycle or more: its
 * angle and speed are the last good ones, frozen. */
bool top_joint_silent(const struct top_joint *j);
/* Joints of R that are silent. */
int top_robot_silent_joints(const struct top_robot *r);
/* A joint's health in words: "ok", "SILENT xN" (no valid reading for N cycles), or the
 * servo's error bits by name ("overload|overheating"). */
/* The error bits of joint_state_t.error_bits by name, by the AX-12A's error byte or,
 * with ERROR_BITS_X, an X servo's Hardware Error Status ("motor encoder"); "" when
 * none is set (the alert, bit 7, is not a cause). Returns buf. */
char *top_errbits_format(int16_t bits, char *buf, size_t cap);
const char *top_joint_status(const struct top_joint *j, char *buf, size_t cap);
/* The joint's torque as both monitors show it: as the servo last reported it
 * ("on", "off"), with the wanted one beside it when they differ ("off (wanted
 * on)": a servo its protection shut down, or reset), or the wanted one while
 * nothing was read ("on (wanted; not read yet)"). */
const char *top_joint_torque(const struct top_joint *j);
/* The servo reported a torque other than the one wanted. */
bool top_joint_torque_differs(const struct top_joint *j);
double top_robot_rate_hz(const struct top_robot *r);      /* 1e6 / mean period; NAN none */
double top_robot_rx_hz(const struct top_robot *r, double now); /* STATE messages received per second */
double top_robot_jitter_p99(const struct top_robot *r);   /* µs; NAN none */
double top_robot_jitter_max(const struct top_robot *r);
int top_robot_contact_joint(const struct top_robot *r);
/* phase(joint 1) - phase(joint 0), wrapped; NAN if fewer than two joints. */
double top_robot_dphase_joints(const struct top_robot *r);
/* phase(order[k+1]) - phase(order[k]) on their contact joints; NAN if unknown. */
double top_neighbour_dphase(const struct top_model *m, int k);
/* The compatibility bound 2·asin(d̃) of the pair (order[k], order[k+1]),
 * d̃ = |n_b − n_a| / (2·lever·A) from the simulator's neutral positions, the
 * bodies' lever and the contact joints' amplitude; π when d̃ >= 1 (they cannot
 * touch); NAN while unknown (no simulator, or no swing seen yet). */
double top_pair_bound(const struct top_model *m, int k);
/* The last N closed trend windows, oldest first: impacts and mean contact
 * force (N). Returns how many were written (<= n). */
int top_trend(const struct top_model *m, int64_t *coll, double *force, int n);
/* collisions received within the last TOP_COLL_WINDOW_S, and their impulse */
int top_collisions_window(const struct top_model *m, double now, double *impulse);
bool top_sim_present(const struct top_model *m, double now);


/* One JSON object (one line) describing everything, written with common/json.h
 * (non-finite numbers as null, names from the network escaped to valid UTF-8).
 * WALL_UTIME: µs since the epoch. */
void top_json(const struct top_model *m, double now, int64_t wall_utime, FILE *f);

#endif
