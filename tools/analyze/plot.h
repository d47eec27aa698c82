/* plot.h — PNG plots of undulate-analyze's CSV files through gnuplot. */
#ifndef UNDULATE_ANALYZE_PLOT_H
#define UNDULATE_ANALYZE_PLOT_H

#include <stdbool.h>
#include <stdio.h>

struct plot_pair {
	const char *name;   /* "a:b", as in phase_diff.csv and return_map.csv */
	double dsep;        /* d~ for the theory curve; NAN unknown (then 0 is drawn, labelled) */
	int map_points;     /* return-map points; no return-map plot without any */
};

struct plot_input {
	const char *dir;           /* where the CSV files are and the PNGs go */
	const char *const *robots; /* robot names in display order */
	int nrobots;
	const struct plot_pair *pairs;
	int npairs;
	double restitution;
	bool have_collisions;
};

/* Writes DIR/plots.gp and runs gnuplot on it. Returns 0, or -1 with a reason
 * printed to MSG (gnuplot missing, gnuplot failed). */
int plot_all(const struct plot_input *in, FILE *msg);
/* The gnuplot program to run: $GNUPLOT or "gnuplot". */
const char *plot_gnuplot(void);

#endif
