/* test_daemon_stats.c — loop timing statistics: nearest-rank percentiles,
 * max and mean over a window, overflow of the sample array, bad samples. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "../../daemon/stats.h"

static struct stats_window w;

static void test_percentiles(void **state)
{
	(void)state;
	struct stats_summary s;
	stats_reset(&w);
	/* 100 samples 1..100 in scrambled order */
	for (int i = 0; i < 100; i++)
		stats_add(&w, (double)((i * 37) % 100 + 1));
	stats_summarize(&w, &s);
	assert_int_equal(s.count, 100);
	assert_true(s.p50 == 50.0);
	assert_true(s.p99 == 99.0);
	assert_true(s.max == 100.0);
	assert_true(fabs(s.mean - 50.5) < 1e-12);
}

static void test_period_like(void **state)
{
	(void)state;
	struct stats_summary s;
	stats_reset(&w);
	/* a second of 10 ms periods with two late wake-ups */
	for (int i = 0; i < 98; i++)
		stats_add(&w, 10000.0 + (i % 3) - 1);
	stats_add(&w, 10400.0);
	stats_add(&w, 12500.0);
	stats_summarize(&w, &s);
	assert_true(s.p50 == 10000.0);
	assert_true(s.p99 == 10400.0);   /* nearest rank: the 99th of 100 */
	assert_true(s.max == 12500.0);
}

static void test_empty_and_bad(void **state)
{
	(void)state;
	struct stats_summary s;
	stats_reset(&w);
	stats_summarize(&w, &s);
	assert_int_equal(s.count, 0);
	assert_true(s.p50 == 0.0 && s.p99 == 0.0 && s.max == 0.0);
	stats_add(&w, NAN);
	stats_add(&w, INFINITY);
	stats_add(&w, 5.0);
	stats_summarize(&w, &s);
	assert_int_equal(s.count, 1);
	assert_true(s.p50 == 5.0 && s.p99 == 5.0 && s.max == 5.0);
	/* one sample: every percentile is it; negative values are fine (jitter) */
	stats_reset(&w);
	stats_add(&w, -3.0);
	stats_summarize(&w, &s);
	assert_true(s.p50 == -3.0 && s.max == -3.0);
}

static void test_overflow_keeps_max(void **state)
{
	(void)state;
	struct stats_summary s;
	stats_reset(&w);
	for (int i = 0; i < STATS_WINDOW + 100; i++)
		stats_add(&w, i < STATS_WINDOW ? 1.0 : 1000.0);
	stats_summarize(&w, &s);
	assert_int_equal(s.count, STATS_WINDOW + 100);
	assert_true(s.max == 1000.0);    /* counted beyond the kept samples */
	assert_true(s.p99 == 1.0);
	/* summarizing does not reset; reset does */
	stats_summarize(&w, &s);
	assert_int_equal(s.count, STATS_WINDOW + 100);
	stats_reset(&w);
	stats_summarize(&w, &s);
	assert_int_equal(s.count, 0);
}

static void test_percentile_sorted(void **state)
{
	(void)state;
	const double v[] = { 1, 2, 3, 4 };
	assert_true(stats_percentile_sorted(v, 4, 0.0) == 1);
	assert_true(stats_percentile_sorted(v, 4, 25.0) == 1);
	assert_true(stats_percentile_sorted(v, 4, 26.0) == 2);
	assert_true(stats_percentile_sorted(v, 4, 50.0) == 2);
	assert_true(stats_percentile_sorted(v, 4, 100.0) == 4);
	assert_true(stats_percentile_sorted(v, 0, 50.0) == 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_percentiles),
		cmocka_unit_test(test_period_like),
		cmocka_unit_test(test_empty_and_bad),
		cmocka_unit_test(test_overflow_keeps_max),
		cmocka_unit_test(test_percentile_sorted),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
