/*
 * tune.h — `undulated --tune`: finds the oscillator parameters that give a
 * target frequency and amplitude on the plant the loop closes through (the
 * servo, its load, the bus), by measuring the running gait and adjusting
 * (daemon/CONTROL.md, "Tuning on the robot"). Pure: no clock, no I/O. The
 * daemon feeds it every cycle's measured angles and speeds; between
 * measurements it asks for new parameters, which the daemon applies at the
 * cycle boundary as it applies a command's.
 *
 * The method, in short: wait for the starter to hand over; after each change
 * drop the first whole cycle (the transient), then collect cycles until the
 * last two agree (or TUNE_MAX_WINDOW_CYCLES); the window's frequency and
 * per-joint amplitude are the means of its last two cycles. Frequency moves
 * mostly with k (all joints alike), amplitude with each joint's μ; each
 * update is a Newton step on logarithms with a Jacobian that starts from the
 * design's exponents and is corrected from the plant's own answers
 * (Broyden), so a plant whose gains differ from the simulator's still
 * converges. A window within TUNE_AIM of both targets is confirmed by
 * one more window without any change; that window's numbers are the result.
 */
#ifndef UNDULATE_DAEMON_TUNE_H
#define UNDULATE_DAEMON_TUNE_H

#include <stdbool.h>
#include <stddef.h>

#include "config.h"

struct ctl;

#define TUNE_TOLERANCE 0.05        /* the result: every joint within 5 % of both targets */
#define TUNE_AIM 0.035             /* a window this close is confirmed by one more */
#define TUNE_MAX_WINDOW_CYCLES 6   /* cycles a window waits for two that agree */
#define TUNE_MAX_ITERATIONS 14
#define TUNE_DEFAULT_MAX_S 90.0
#define TUNE_MAX_LEAD_S 0.2        /* the horizon's lead is raised up to this for a loop that dies */
#define TUNE_LEAD_STEP 1.35        /* ... by this factor each time it dies */
#define TUNE_DEAD_S 4.0            /* no cycle completed for this long after the starter: the loop died */
#define TUNE_DEAD_TEXT "4 s"
#define TUNE_TEXT 512
#define TUNE_M (CFG_MAX_JOINTS + 1)    /* unknowns: k, and μ of every joint */

struct tune_opts {
	double target_freq;   /* Hz */
	double target_amp;    /* rad, each joint's half peak-to-peak */
	double max_s;         /* give up after this long (s of controller time) */
};

enum tune_state {
	TUNE_STARTING,        /* the starter still drives, or the first cycle not seen */
	TUNE_MEASURING,       /* collecting a window */
	TUNE_CONFIRMING,      /* a window was close: one more, without changes */
	TUNE_DONE,            /* converged: `result` holds the confirmed window */
	TUNE_FAILED,          /* gave up: `why` says why, `best` the closest window */
};

/* What one window measured. */
struct tune_window {
	double freq;                     /* Hz, the lowest joint's (coupled joints share it) */
	double amp[CFG_MAX_JOINTS];      /* rad, half peak-to-peak */
	double vpeak[CFG_MAX_JOINTS];    /* rad/s, largest |speed| seen */
	double lag_deg;                  /* joint 1 behind joint 0, degrees in [0, 360) (NaN: one joint) */
	double error;                    /* largest |measured/target − 1| over f and every A */
	double k, mu[CFG_MAX_JOINTS], lead;   /* the parameters it ran with (k: the factor on k0) */
};

/* One joint's cycles, found at upward crossings of its centre. */
struct tune_joint {
	double last_x, last_t;
	bool have_last;
	double centre;                   /* mid-point of the last whole cycle (0 until one) */
	double hi, lo, vmax;             /* extremes since the last crossing */
	bool armed;                      /* went below centre − hysteresis since the last crossing */
	double cross_t;                  /* the last upward crossing (NaN: none yet) */
	double hyst;
	double last_cycle_t;             /* its last whole cycle (or the window's start) */
	/* cycles completed since the window began */
	int ncycles;
	double period[TUNE_MAX_WINDOW_CYCLES + 2], p2p[TUNE_MAX_WINDOW_CYCLES + 2],
	       top[TUNE_MAX_WINDOW_CYCLES + 2], bottom[TUNE_MAX_WINDOW_CYCLES + 2],
	       vpk[TUNE_MAX_WINDOW_CYCLES + 2], start[TUNE_MAX_WINDOW_CYCLES + 2];
};

struct tune {
	struct tune_opts opts;
	size_t n;
	enum tune_state state;
	double t0;                       /* first sample */
	double window_t0;                /* parameters last changed (or the starter ended) */
	double dead_t;                   /* the last time the loop was found dead (NaN: never) */
	struct tune_joint j[CFG_MAX_JOINTS];
	/* the parameters in force (and the last update's, for the secant): k is a factor on every joint's starting k0
	 * (frequency is the coupled joints' common property), μ per joint */
	double k0[CFG_MAX_JOINTS], k, mu[CFG_MAX_JOINTS], lead;
	bool torque_actuation;
	int sat_count;                   /* windows in a row whose f·A stayed put below the target's */
	double sat_prod;
	/* the plant's answer in logarithms: J = ∂(log f, log A_j)/∂(log k, log μ_j),
	 * from the design's exponents, corrected after every change (Broyden) */
	double ef0, ea0;
	double jac[TUNE_M][TUNE_M];
	bool have_prev;
	double prev_u[TUNE_M], prev_y[TUNE_M];
	int iterations;                  /* windows measured */
	bool changed;                    /* new parameters for the daemon to apply */
	struct tune_window first;        /* the parameters it started with, as measured */
	bool have_first;
	struct tune_window best, result;
	bool have_best;
	double mu0[CFG_MAX_JOINTS];      /* the starting μ (the search stays near it) */
	double k_lo, k_hi;               /* the search box of the k factor ... */
	double mu_lo[CFG_MAX_JOINTS], mu_hi[CFG_MAX_JOINTS];   /* ... and of each μ (tune_init) */
	int pinned;                      /* windows in a row that wanted k or μ beyond the search range */
	double supply_v;                 /* V the servos report (NaN: not yet) */
	double no_load_speed;            /* rad/s at 12 V (the configuration's) */
	struct cfg_params ran;           /* what the controller runs: the start, then after every
	                                    tune_apply (and what the daemon saw last, commands too) */
	char why[TUNE_TEXT];             /* TUNE_FAILED: in words, with what can be reached */
	char progress[TUNE_TEXT];        /* a new line to show ("" when none) */
};

/* Targets, and `from` (NULL: cfg's own parameters) as the start; cfg for
 * the joints' limits and the servo. False with *why when the targets are not
 * plausible or do not fit inside the joints' limits. */
bool tune_init(struct tune *t, const struct tune_opts *o, const struct cfg *cfg, const struct cfg_params *from,
               char *why, size_t cap);

/* One control cycle: time (s), each joint's x = angle − neutral (rad) and
 * speed (rad/s), NaN for a joint without a reading this cycle; starter: the
 * daemon's sinusoid starter is still driving (OSCILLATOR not yet running).
 * Returns true when new parameters wait (k, mu[], lead): apply them with
 * tune_apply() before the next control step. */
bool tune_sample(struct tune *t, double time, const double *x, const double *v, bool starter);

/* The supply voltage the servos report (V); the speed they can reach scales
 * with it, and a target beyond it is called out of reach. */
void tune_supply(struct tune *t, double volts);

/* Hand the parameters in force to the controller (k and mu of every joint,
 * servo_lead_s) through ctl_set_param, all or none, and clear `changed`.
 * False when the controller refused one (nothing changed then): the tuning
 * has failed (TUNE_FAILED, *why says which and why). */
bool tune_apply(struct tune *t, struct ctl *c);

/* The peak speed a sinusoid of f and A needs, and what a servo with peak
 * speed vmax reaches: the frequency at amplitude a, the amplitude at f. */
double tune_needed_speed(double f, double a);

/* Write the tuned configuration (cfg with the parameters the robot ran
 * with, `ran`, and over them the result's k, mu and lead, the SINUSOID
 * baseline set to the measured frequency and mean amplitude, start mode
 * OSCILLATOR) with a header saying how it was measured. */
void tune_write_config(const struct tune *t, const struct cfg *cfg, const char *when, double took_s, void *file);

#endif
