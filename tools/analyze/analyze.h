/* analyze.h — undulate-analyze's pipeline: LCM logs in, CSV files, a summary
 * and (optionally) plots out. main.c only parses the command line. */
#ifndef UNDULATE_ANALYZE_ANALYZE_H
#define UNDULATE_ANALYZE_ANALYZE_H

#include <stdbool.h>
#include <stdio.h>

/* Exit codes of an_run (and of the program). */
enum an_exit {
	AN_EXIT_OK = 0,
	AN_EXIT_USAGE = 1,     /* bad options */
	AN_EXIT_BADLOG = 2,    /* a log is missing, unreadable or not an LCM log: no output */
	AN_EXIT_TRUNCATED = 3, /* a log was cut short: everything before the damage written */
	AN_EXIT_PLOTS = 4,     /* CSV and summary written, plots could not be made */
	AN_EXIT_OUTPUT = 5,    /* output directory or files could not be written */
};

/* Limits; beyond them robots/pairs are counted as dropped, with a warning. */
#define AN_MAX_LOGS 64
#define AN_MAX_ROBOTS 64      /* robots in one experiment (the paper's largest group: 10) */
#define AN_MAX_JOINTS 4       /* joints per robot (ours have 2) */
#define AN_MAX_PAIRS 192      /* neighbour/user pairs plus one joint pair per robot */
#define AN_MAX_BODIES 128     /* contact bodies in SIM.TRUTH */
#define AN_NAME_MAX 64        /* robot name length */

struct an_options {
	const char *logs[AN_MAX_LOGS];
	int nlogs;
	const char *out_dir;   /* default "." */
	const char *pairs;     /* "a:b,c:d" or NULL for neighbours */
	bool plots;
	bool plots_only;       /* --plots-only: the plots and what their script reads; the
	                        * per-sample CSVs are left out (they are the analysis's, in
	                        * its own folder: no second copy) */
	double from_s, to_s;   /* seconds from the first event; NAN = open */
	double window_s;       /* final window for the classification */
	double separation;     /* d~ for every pair; NAN = from SIM.TRUTH */
	double restitution;    /* r for the theory curve; NAN: the log's (SIM.WORLD), else 0.67 */
	double merge_s;        /* collisions of a pair closer than this are one contact */
	FILE *msg;             /* warnings and the summary go here (stderr/stdout) */
	bool quiet;            /* do not print the summary to msg */
	bool zero_crossings;   /* phase from our zero-crossing frequency, never the daemon's */
	double frequency_hz;   /* > 0: every joint's phase at this frequency, from the first
				  sample (the gait's known frequency; NAN: estimated) */
	double min_swing;      /* rad p-p: a pair with a joint swinging less in the final
				  window is "not-oscillating", whatever its phases say */
	double plane_every_s;  /* plane.csv: the links' poses at most this often (s; 0:
				  every SIM.TRUTH) */
};

/* Default of min_swing (rad peak-to-peak): the robots swing about 1.6 rad
 * p-p; a stopped AX-12 reads within a few 0.005 rad steps of one angle. */
#define AN_MIN_SWING_DEFAULT 0.2
/* Default of plane_every_s: ten poses a second draw a 0.8 Hz gait at 12 a
 * cycle and keep a long run's plane.csv small (10 robots, 300 s: 9 MB). */
#define AN_PLANE_EVERY_DEFAULT 0.1

void an_options_default(struct an_options *o);
/* Runs the whole analysis; returns an enum an_exit. */
int an_run(const struct an_options *o);

#endif
