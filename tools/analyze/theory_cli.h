/* theory_cli.h — `undulate-analyze --theory WHAT`: the contact theory's
 * curves (theory.h) as CSV on stdout, for plots that put them beside runs
 * (figures/, docs/FIGURES.md): the only place outside theory.c that turns
 * them into numbers, so no script keeps a second copy of a formula. */
#ifndef UNDULATE_ANALYZE_THEORY_CLI_H
#define UNDULATE_ANALYZE_THEORY_CLI_H

#include <stdio.h>

struct theory_request {
	const char *what;   /* curves, critical, map, map-d0, sequence, final */
	double r;           /* restitution, 0 < r <= 1 */
	double dsep;        /* d~ for `map`; NAN: not given */
	double delta0;      /* for `sequence`; NAN: not given */
	long points;        /* samples of a curve; 0: the curve's default */
	long steps;         /* collisions of `sequence` */
};

/* Upper bounds of --points and --steps: a curve of a million points is a
 * mistake, not a figure. */
#define THEORY_CLI_MAX_POINTS 100000
#define THEORY_CLI_MAX_STEPS 10000
/* Collisions `final` follows a pair before it gives up (a pair that ends
 * needs a few hundred at most: near d~_c the approach to pi is slowest). */
#define THEORY_CLI_MAX_COLLISIONS 100000

/* Checks the request and writes its CSV to out, reading `final`'s
 * "dsep,delta0" lines from in. Returns an enum an_exit (analyze.h):
 * 0, or 1 (AN_EXIT_USAGE) after saying on stderr what is wrong. */
int theory_cli_run(const struct theory_request *q, FILE *in, FILE *out);

#endif
