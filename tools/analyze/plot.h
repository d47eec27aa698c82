/* plot.h — PNG plots of undulate-analyze's CSV files through gnuplot. */
#ifndef UNDULATE_ANALYZE_PLOT_H
#define UNDULATE_ANALYZE_PLOT_H

#include <stdbool.h>
#include <stdio.h>

/* Panels per figure at most (robots in angles.png, pairs in phase_diff.png);
 * more are left out of the picture and the title says how many. */
#define PLOT_MAX_PANELS 12
/* Pairs drawn in the collision rate at most (the analyser's AN_MAX_PAIRS). */
#define PLOT_MAX_PAIRS 192

struct plot_pair {
	const char *name;   /* "a:b", as in phase_diff.csv and return_map.csv */
	double dsep;        /* d~ for the theory curve; NAN unknown (then 0 is drawn, labelled) */
	int map_points;     /* return-map points; no return-map plot without any */
	int delta_points;   /* phase_diff.csv rows of the pair; no panel without any */
	int collisions;     /* collisions of the pair */
};

struct plot_switch {
	double t;           /* s from the log's start */
	const char *to;     /* the new mode's name */
};

struct plot_input {
	const char *dir;           /* --out, for messages */
	int dirfd;                 /* where the CSV files are and the PNGs go: a
	                            * private directory only we can write (outdir.h) */
	const char *const *robots; /* robot names in display order */
	const int *njoints;        /* joints of each robot */
	const unsigned *joint_mask; /* bit j: robot's joint j has samples (only those are drawn) */
	const int *robot_index;     /* each robot's robot_index in states.csv */
	int nrobots;
	const struct plot_pair *pairs;
	int npairs;
	const struct plot_switch *switches;
	int nswitches;
	double window_start;       /* s: the final window's start (portraits draw it bold) */
	double restitution;
	const char *restitution_from;
	bool have_collisions;      /* any collision in collisions.csv */
	bool have_force;           /* a contact force in collision_rate.csv (SIM.TRUTH) */
};

/* Writes plots.gp into dirfd and runs gnuplot on it there. Returns 0, or -1 with a reason
 * printed to MSG (gnuplot missing, gnuplot failed). */
int plot_all(const struct plot_input *in, FILE *msg);
/* The gnuplot program to run: $GNUPLOT or "gnuplot". */
const char *plot_gnuplot(void);

#endif
