/*
 * stats.h — loop timing statistics over a window (one second of cycles):
 * percentiles by sorting a fixed sample array once per window, no allocation.
 */
#ifndef UNDULATE_DAEMON_STATS_H
#define UNDULATE_DAEMON_STATS_H

#include <stddef.h>

/* Samples kept per window: 1 s at up to 500 Hz; beyond that the window keeps
 * its first STATS_WINDOW samples and counts the rest in max/count only. */
#define STATS_WINDOW 512

struct stats_window {
	size_t n;                   /* samples kept */
	size_t count;               /* samples added (may exceed n) */
	double max;
	double sum;
	double v[STATS_WINDOW];
	double sorted[STATS_WINDOW];
};

struct stats_summary {
	size_t count;
	double p50, p99, max, mean;
};

void stats_reset(struct stats_window *w);
void stats_add(struct stats_window *w, double value);   /* non-finite values are ignored */
/* Nearest-rank percentiles of the window (zeros when empty). Does not reset. */
void stats_summarize(struct stats_window *w, struct stats_summary *out);
/* Nearest-rank percentile p (0..100) of n sorted values. */
double stats_percentile_sorted(const double *sorted, size_t n, double p);

#endif
