/* stats.c — see stats.h. */
#include "stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void stats_reset(struct stats_window *w)
{
	w->n = 0;
	w->count = 0;
	w->max = 0.0;
	w->sum = 0.0;
}

void stats_add(struct stats_window *w, double value)
{
	if (!isfinite(value))
		return;
	if (w->count == 0 || value > w->max)
		w->max = value;
	w->count++;
	w->sum += value;
	if (w->n < STATS_WINDOW)
		w->v[w->n++] = value;
}

static int stats_cmp(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

double stats_percentile_sorted(const double *sorted, size_t n, double p)
{
	if (n == 0)
		return 0.0;
	/* nearest rank: the smallest value with at least p % of samples <= it */
	double rank = ceil(p / 100.0 * (double)n);
	size_t i = rank < 1.0 ? 0 : (size_t)rank - 1;
	if (i >= n)
		i = n - 1;
	return sorted[i];
}

void stats_summarize(struct stats_window *w, struct stats_summary *out)
{
	memset(out, 0, sizeof *out);
	out->count = w->count;
	if (w->count == 0)
		return;
	memcpy(w->sorted, w->v, w->n * sizeof w->v[0]);
	qsort(w->sorted, w->n, sizeof w->sorted[0], stats_cmp);
	out->p50 = stats_percentile_sorted(w->sorted, w->n, 50.0);
	out->p99 = stats_percentile_sorted(w->sorted, w->n, 99.0);
	out->max = w->max;
	out->mean = w->sum / (double)w->count;
}
