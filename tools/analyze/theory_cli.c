/* theory_cli.c — see theory_cli.h. */
#include "theory_cli.h"
#include "analyze.h"
#include "num.h"
#include "theory.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

/* Default samples: d~ over [0, 1] in steps of 0.005; delta over (-pi, pi]
 * in steps of 0.5 degree. */
#define THEORY_CLI_DSEP_POINTS 201
#define THEORY_CLI_DELTA_POINTS 721
#define THEORY_CLI_LINE_MAX 256

/* A number, or an empty field (gnuplot's "missing": the curve breaks there). */
static void theory_num(FILE *out, double v, bool last)
{
	if (isfinite(v))
		fprintf(out, "%.9g", v);
	fputc(last ? '\n' : ',', out);
}

static long theory_points(const struct theory_request *q, long dflt)
{
	return q->points > 0 ? q->points : dflt;
}

/* d~ from 0 to 1: the compatibility limit, the anti-phase slope and its
 * stability, the third fixed point (the basins' boundary). */
static void theory_curves(const struct theory_request *q, FILE *out)
{
	long n = theory_points(q, THEORY_CLI_DSEP_POINTS);
	fputs("dsep,compat_limit,fprime_pi,abs_fprime_pi,antiphase_stable,third_fixed_point\n", out);
	for (long i = 0; i < n; i++) {
		double d = (double)i / (double)(n - 1);
		double s = theory_antiphase_slope(d, q->r);
		theory_num(out, d, false);
		theory_num(out, theory_compat_limit(d), false);
		theory_num(out, s, false);
		theory_num(out, fabs(s), false);
		fprintf(out, "%d,", fabs(s) < 1.0);
		theory_num(out, theory_third_fixed_point(d, q->r), true);
	}
}

/* delta_n over (-pi, pi] and the map's delta_{n+1} at d~ (empty where the
 * pair cannot touch); at d~ = 0 also the closed form's one step. */
static void theory_map(const struct theory_request *q, double dsep, bool d0, FILE *out)
{
	long n = theory_points(q, THEORY_CLI_DELTA_POINTS);
	fputs(d0 ? "delta_n,delta_next,closed_form\n" : "delta_n,delta_next\n", out);
	for (long i = 1; i <= n; i++) {
		double x = -M_PI + 2.0 * M_PI * (double)i / (double)n;
		theory_num(out, x, false);
		theory_num(out, theory_return_map(x, dsep, q->r), !d0);
		if (d0)
			theory_num(out, theory_return_map_d0(x, q->r, 1), true);
	}
}

/* delta_n against n at d~ = 0 from delta0: the closed form and the map
 * iterated, side by side. */
static void theory_sequence(const struct theory_request *q, FILE *out)
{
	fputs("n,closed_form,iterated\n", out);
	double it = q->delta0;
	for (long n = 0; n <= q->steps; n++) {
		if (n > 0)
			it = theory_return_map(it, 0.0, q->r);
		fprintf(out, "%ld,", n);
		theory_num(out, theory_return_map_d0(q->delta0, q->r, (int)n), false);
		theory_num(out, it, true);
	}
}

/* One "dsep,delta0" line; a header (a first line starting with a letter)
 * is skipped. Returns 1 for a pair, 0 to skip, -1 after a message. */
static int theory_read_pair(char *line, long lineno, double *dsep, double *delta0)
{
	line[strcspn(line, "\r\n")] = '\0';
	if (!line[0] || (lineno == 1 && ((line[0] >= 'a' && line[0] <= 'z') || (line[0] >= 'A' && line[0] <= 'Z'))))
		return 0;
	char *comma = strchr(line, ',');
	if (comma)
		*comma = '\0';
	if (!comma || num_parse_double_in(line, 0.0, 1e6, dsep) != NUM_OK ||
	    num_parse_double_in(comma + 1, -1e6, 1e6, delta0) != NUM_OK) {
		fprintf(stderr, "undulate-analyze: --theory final: line %ld of stdin: want \"dsep,delta0\" "
				"(d~ >= 0, delta0 in rad)\n", lineno);
		return -1;
	}
	return 1;
}

/* For each (d~, delta0) on in: where the map leads and in how many
 * collisions. */
static int theory_final(const struct theory_request *q, FILE *in, FILE *out)
{
	char line[THEORY_CLI_LINE_MAX];
	long lineno = 0;
	fputs("dsep,delta0,final,collisions\n", out);
	while (fgets(line, sizeof(line), in)) {
		double dsep, delta0;
		int got = theory_read_pair(line, ++lineno, &dsep, &delta0);
		if (got < 0)
			return AN_EXIT_USAGE;
		if (got == 0)
			continue;
		int n = 0;
		double end = theory_iterate(delta0, dsep, q->r, THEORY_CLI_MAX_COLLISIONS, &n);
		theory_num(out, dsep, false);
		theory_num(out, delta0, false);
		theory_num(out, end, false);
		fprintf(out, "%d\n", n);
	}
	return AN_EXIT_OK;
}

static int theory_usage_error(const char *what)
{
	fprintf(stderr, "undulate-analyze: --theory: %s\n", what);
	return AN_EXIT_USAGE;
}

int theory_cli_run(const struct theory_request *q, FILE *in, FILE *out)
{
	if (!(q->r > 0.0 && q->r <= 1.0))
		return theory_usage_error("--restitution must be in (0, 1] (the theory divides by it)");
	if (q->points != 0 && (q->points < 2 || q->points > THEORY_CLI_MAX_POINTS)) {
		fprintf(stderr, "undulate-analyze: --points: %ld is not 2..%d\n", q->points, THEORY_CLI_MAX_POINTS);
		return AN_EXIT_USAGE;
	}
	const char *w = q->what;
	if (!strcmp(w, "curves")) {
		theory_curves(q, out);
	} else if (!strcmp(w, "critical")) {
		fprintf(out, "restitution,dsep_c\n%.9g,%.9g\n", q->r, theory_critical_dsep(q->r));
	} else if (!strcmp(w, "map")) {
		if (!(q->dsep >= 0.0))
			return theory_usage_error("map needs --separation D (d~ >= 0)");
		theory_map(q, q->dsep, false, out);
	} else if (!strcmp(w, "map-d0")) {
		theory_map(q, 0.0, true, out);
	} else if (!strcmp(w, "sequence")) {
		if (!isfinite(q->delta0))
			return theory_usage_error("sequence needs --delta0 RAD");
		if (q->steps < 0 || q->steps > THEORY_CLI_MAX_STEPS) {
			fprintf(stderr, "undulate-analyze: --steps: %ld is not 0..%d\n", q->steps, THEORY_CLI_MAX_STEPS);
			return AN_EXIT_USAGE;
		}
		theory_sequence(q, out);
	} else if (!strcmp(w, "final")) {
		return theory_final(q, in, out);
	} else {
		fprintf(stderr, "undulate-analyze: --theory '%s': want curves, critical, map, map-d0, sequence or final\n", w);
		return AN_EXIT_USAGE;
	}
	return ferror(out) ? AN_EXIT_OUTPUT : AN_EXIT_OK;
}
