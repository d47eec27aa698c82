/*
 * logstat.c — loop statistics from an LCM log (lcm-logger output), for the
 * benchmark suite. Built by bench/run.sh, not by the Makefile's programs.
 *
 *   logstat [--skip S] [--window S] [--from-us T] [--to-us T] [--missing-id ID] [--sender-time] LOGFILE
 *
 * Reads every "<robot>.STATE" (robot_state_t), "<robot>.BUS" (bus_stats_t)
 * and "SIM.TRUTH" (sim_truth_t) message and prints "key value" lines:
 *
 *   all.<figure>    every robot's cycles together
 *   worst.<figure>  the largest value of that figure over the robots
 *   <robot>.<figure>
 *   truth.<figure>  the simulator's step lateness
 *
 * figures: n (cycles), jitter_p50/p99/max, period_p50/p99/max, bus_p50/p99/max,
 * control_p50/p99/max (µs), overruns and bus_errors (counted inside the window), cpu_mean (the
 * daemon's own bus_stats_t.cpu_percent).
 *
 * --skip S      ignore each robot's first S seconds (start-up and ramp-in)
 * --window S    then keep S seconds (0: to the end of the log)
 * --from-us T, --to-us T   keep only messages logged in [T, T') (µs since
 *               the epoch, the logger's clock): a window the caller timed
 * --sender-time --skip and --window count a robot's STATE by its own utime
 *               (the start of its cycle), not by the logger's clock: in
 *               lockstep the daemon's clock is the simulator's virtual time,
 *               which runs faster than the logger's
 * --missing-id  also split the cycles by whether that servo's reading was
 *               stale this cycle: <robot>.missing_* and <robot>.healthy_*
 *
 * Times are the logger's receive timestamps; the figures themselves come from
 * the daemon's own clock (period_us, jitter_us, bus_us), so logger latency
 * does not enter them.
 */
#include <inttypes.h>
#include <lcm/eventlog.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compat/lcm/lcmdec.h"

/* Robots in one log: the sim holds at most 32 buses; room to spare. */
#define LS_MAX_ROBOTS 64
#define LS_NAME_MAX 64

/* A growable sample list (a benchmark tool: allocation is fine here). */
struct ls_series {
	double *v;
	size_t n, cap;
};

enum ls_split { LS_ALL, LS_HEALTHY, LS_MISSING, LS_NSPLIT };
static const char *const ls_split_prefix[LS_NSPLIT] = { "", "healthy_", "missing_" };

struct ls_cycles {
	struct ls_series jitter, period, bus, control;
	int64_t overruns_first, overruns_last, errors_first, errors_last;
	bool seen;
};

struct ls_robot {
	char name[LS_NAME_MAX];
	int64_t t0_us;              /* first STATE seen (log time) */
	struct ls_cycles c[LS_NSPLIT];
	struct ls_series cpu;
};

struct ls_state {
	double skip_s, window_s;
	int64_t from_us, to_us;     /* 0: no bound */
	bool sender_time;           /* --sender-time */
	int missing_id;             /* -1: no split */
	struct ls_robot robots[LS_MAX_ROBOTS];
	size_t nrobots;
	int64_t truth_t0_us;
	struct ls_series truth_late;
	uint64_t decode_errors;
};

static void ls_push(struct ls_series *s, double x)
{
	if (s->n == s->cap) {
		size_t cap = s->cap ? 2 * s->cap : 1024;
		double *v = realloc(s->v, cap * sizeof(*v));
		if (!v) {
			fprintf(stderr, "logstat: out of memory\n");
			exit(1);
		}
		s->v = v;
		s->cap = cap;
	}
	s->v[s->n++] = x;
}

static int ls_cmp(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* Nearest-rank percentile of a sorted series (p in (0, 1]). */
static double ls_pct(const struct ls_series *s, double p)
{
	if (s->n == 0)
		return NAN;
	size_t rank = (size_t)ceil(p * (double)s->n);
	return s->v[rank ? rank - 1 : 0];
}

static double ls_mean(const struct ls_series *s)
{
	double sum = 0;
	for (size_t i = 0; i < s->n; i++)
		sum += s->v[i];
	return s->n ? sum / (double)s->n : NAN;
}

static struct ls_robot *ls_robot(struct ls_state *st, const char *name, size_t len, int64_t t_us)
{
	for (size_t i = 0; i < st->nrobots; i++)
		if (strlen(st->robots[i].name) == len && !strncmp(st->robots[i].name, name, len))
			return &st->robots[i];
	if (st->nrobots == LS_MAX_ROBOTS || len >= LS_NAME_MAX)
		return NULL;
	struct ls_robot *r = &st->robots[st->nrobots++];
	memcpy(r->name, name, len);
	r->name[len] = '\0';
	r->t0_us = t_us;
	return r;
}

/* Inside the measurement window of something first seen at t0? */
static bool ls_in_window(const struct ls_state *st, int64_t t0_us, int64_t t_us)
{
	double t = 1e-6 * (double)(t_us - t0_us);
	if ((st->from_us && t_us < st->from_us) || (st->to_us && t_us >= st->to_us))
		return false;
	return t >= st->skip_s && (st->window_s <= 0 || t < st->skip_s + st->window_s);
}

static void ls_add_cycle(struct ls_cycles *c, const undulate_robot_state_t *m)
{
	ls_push(&c->jitter, m->jitter_us);
	ls_push(&c->period, m->period_us);
	ls_push(&c->bus, m->bus_us);
	ls_push(&c->control, m->control_us);
	if (!c->seen) {
		c->overruns_first = m->overruns;
		c->errors_first = m->bus_errors;
		c->seen = true;
	}
	c->overruns_last = m->overruns;
	c->errors_last = m->bus_errors;
}

static bool ls_is_missing(const undulate_robot_state_t *m, int id)
{
	for (int j = 0; j < m->njoints; j++)
		if (m->joints[j].servo_id == id)
			return m->joints[j].stale_cycles > 0;
	return false;
}

static void ls_state_msg(struct ls_state *st, const lcm_eventlog_event_t *ev, size_t namelen)
{
	undulate_robot_state_t m;
	if (ev->datalen < 0 || lcmdec_decode(&lcmdec_robot_state_t, ev->data, (size_t)ev->datalen, &m) != LCMDEC_OK) {
		st->decode_errors++;
		return;
	}
	int64_t t_us = st->sender_time ? m.utime : ev->timestamp;
	struct ls_robot *r = ls_robot(st, ev->channel, namelen, t_us);
	if (r && ls_in_window(st, r->t0_us, t_us)) {
		ls_add_cycle(&r->c[LS_ALL], &m);
		if (st->missing_id >= 0)
			ls_add_cycle(&r->c[ls_is_missing(&m, st->missing_id) ? LS_MISSING : LS_HEALTHY], &m);
	}
	lcmdec_free(&lcmdec_robot_state_t, &m);
}

static void ls_bus_msg(struct ls_state *st, const lcm_eventlog_event_t *ev, size_t namelen)
{
	undulate_bus_stats_t m;
	if (ev->datalen < 0 || lcmdec_decode(&lcmdec_bus_stats_t, ev->data, (size_t)ev->datalen, &m) != LCMDEC_OK) {
		st->decode_errors++;
		return;
	}
	struct ls_robot *r = ls_robot(st, ev->channel, namelen, ev->timestamp);
	if (r && ls_in_window(st, r->t0_us, ev->timestamp))
		ls_push(&r->cpu, m.cpu_percent);
	lcmdec_free(&lcmdec_bus_stats_t, &m);
}

static void ls_truth_msg(struct ls_state *st, const lcm_eventlog_event_t *ev)
{
	undulate_sim_truth_t m;
	if (ev->datalen < 0 || lcmdec_decode(&lcmdec_sim_truth_t, ev->data, (size_t)ev->datalen, &m) != LCMDEC_OK) {
		st->decode_errors++;
		return;
	}
	if (st->truth_t0_us == 0)
		st->truth_t0_us = ev->timestamp;
	if (ls_in_window(st, st->truth_t0_us, ev->timestamp))
		ls_push(&st->truth_late, m.worst_lateness_us);
	lcmdec_free(&lcmdec_sim_truth_t, &m);
}

static bool ls_suffix(const char *ch, size_t len, const char *suffix, size_t *namelen)
{
	size_t sl = strlen(suffix);
	if (len <= sl || strcmp(ch + len - sl, suffix) != 0)
		return false;
	*namelen = len - sl;
	return true;
}

static int ls_read(struct ls_state *st, const char *path)
{
	lcm_eventlog_t *log = lcm_eventlog_create(path, "r");
	if (!log) {
		fprintf(stderr, "logstat: cannot open %s\n", path);
		return -1;
	}
	lcm_eventlog_event_t *ev;
	while ((ev = lcm_eventlog_read_next_event(log)) != NULL) {
		size_t len = strlen(ev->channel), namelen;
		if (ls_suffix(ev->channel, len, ".STATE", &namelen))
			ls_state_msg(st, ev, namelen);
		else if (ls_suffix(ev->channel, len, ".BUS", &namelen))
			ls_bus_msg(st, ev, namelen);
		else if (!strcmp(ev->channel, "SIM.TRUTH"))
			ls_truth_msg(st, ev);
		lcm_eventlog_free_event(ev);
	}
	lcm_eventlog_destroy(log);
	return 0;
}

static void ls_sort(struct ls_series *s)
{
	if (s->n > 0)  /* an empty series has no buffer: qsort wants a valid pointer */
		qsort(s->v, s->n, sizeof(double), ls_cmp);
}

static void ls_print_series(const char *who, const char *pre, const char *what, struct ls_series *s)
{
	ls_sort(s);
	printf("%s.%s%s_p50 %.1f\n", who, pre, what, ls_pct(s, 0.50));
	printf("%s.%s%s_p99 %.1f\n", who, pre, what, ls_pct(s, 0.99));
	printf("%s.%s%s_max %.1f\n", who, pre, what, s->n ? s->v[s->n - 1] : NAN);
}

static void ls_print_cycles(const char *who, const char *pre, struct ls_cycles *c)
{
	printf("%s.%sn %zu\n", who, pre, c->jitter.n);
	ls_print_series(who, pre, "jitter", &c->jitter);
	ls_print_series(who, pre, "period", &c->period);
	ls_print_series(who, pre, "bus", &c->bus);
	ls_print_series(who, pre, "control", &c->control);
	printf("%s.%soverruns %" PRId64 "\n", who, pre, c->overruns_last - c->overruns_first);
	printf("%s.%sbus_errors %" PRId64 "\n", who, pre, c->errors_last - c->errors_first);
}

static void ls_merge(struct ls_series *into, const struct ls_series *from)
{
	for (size_t i = 0; i < from->n; i++)
		ls_push(into, from->v[i]);
}

/* all.*: every robot's cycles pooled; worst.*: the worst robot's figure. */
static void ls_print_pooled(struct ls_state *st)
{
	struct ls_cycles all = { 0 };
	struct ls_series cpu = { 0 };
	double worst_p99 = NAN, worst_max = NAN, worst_cpu = NAN;
	int64_t overruns = 0, errors = 0;
	for (size_t i = 0; i < st->nrobots; i++) {
		struct ls_robot *r = &st->robots[i];
		ls_merge(&all.jitter, &r->c[LS_ALL].jitter);
		ls_merge(&all.period, &r->c[LS_ALL].period);
		ls_merge(&all.bus, &r->c[LS_ALL].bus);
		ls_merge(&all.control, &r->c[LS_ALL].control);
		ls_merge(&cpu, &r->cpu);
		overruns += r->c[LS_ALL].overruns_last - r->c[LS_ALL].overruns_first;
		errors += r->c[LS_ALL].errors_last - r->c[LS_ALL].errors_first;
		ls_sort(&r->c[LS_ALL].jitter);
		double p99 = ls_pct(&r->c[LS_ALL].jitter, 0.99);
		double mx = r->c[LS_ALL].jitter.n ? r->c[LS_ALL].jitter.v[r->c[LS_ALL].jitter.n - 1] : NAN;
		double cm = ls_mean(&r->cpu);
		worst_p99 = isnan(worst_p99) || p99 > worst_p99 ? p99 : worst_p99;
		worst_max = isnan(worst_max) || mx > worst_max ? mx : worst_max;
		worst_cpu = isnan(worst_cpu) || cm > worst_cpu ? cm : worst_cpu;
	}
	printf("robots %zu\n", st->nrobots);
	printf("all.n %zu\n", all.jitter.n);
	ls_print_series("all", "", "jitter", &all.jitter);
	ls_print_series("all", "", "period", &all.period);
	ls_print_series("all", "", "bus", &all.bus);
	ls_print_series("all", "", "control", &all.control);
	printf("all.overruns %" PRId64 "\nall.bus_errors %" PRId64 "\n", overruns, errors);
	printf("all.cpu_mean %.2f\n", ls_mean(&cpu));
	printf("worst.jitter_p99 %.1f\nworst.jitter_max %.1f\nworst.cpu_mean %.2f\n", worst_p99, worst_max,
	       worst_cpu);
	free(all.jitter.v);
	free(all.period.v);
	free(all.bus.v);
	free(all.control.v);
	free(cpu.v);
}

static void ls_print(struct ls_state *st)
{
	ls_print_pooled(st);
	for (size_t i = 0; i < st->nrobots; i++) {
		struct ls_robot *r = &st->robots[i];
		ls_print_cycles(r->name, "", &r->c[LS_ALL]);
		printf("%s.cpu_mean %.2f\n", r->name, ls_mean(&r->cpu));
		for (int k = LS_HEALTHY; st->missing_id >= 0 && k < LS_NSPLIT; k++)
			ls_print_cycles(r->name, ls_split_prefix[k], &r->c[k]);
	}
	ls_sort(&st->truth_late);
	printf("truth.n %zu\n", st->truth_late.n);
	printf("truth.late_p99 %.1f\n", ls_pct(&st->truth_late, 0.99));
	printf("truth.late_max %.1f\n", st->truth_late.n ? st->truth_late.v[st->truth_late.n - 1] : NAN);
	printf("decode_errors %" PRIu64 "\n", st->decode_errors);
}

static void ls_usage(void)
{
	fprintf(stderr, "usage: logstat [--skip S] [--window S] [--from-us T] [--to-us T] [--missing-id ID] [--sender-time] "
	        "LOGFILE\n");
}

int main(int argc, char **argv)
{
	static struct ls_state st;
	const char *path = NULL;
	st.missing_id = -1;
	for (int i = 1; i < argc; i++) {
		bool has_val = i + 1 < argc;
		if (!strcmp(argv[i], "--skip") && has_val)
			st.skip_s = atof(argv[++i]);
		else if (!strcmp(argv[i], "--window") && has_val)
			st.window_s = atof(argv[++i]);
		else if (!strcmp(argv[i], "--from-us") && has_val)
			st.from_us = atoll(argv[++i]);
		else if (!strcmp(argv[i], "--to-us") && has_val)
			st.to_us = atoll(argv[++i]);
		else if (!strcmp(argv[i], "--sender-time"))
			st.sender_time = true;
		else if (!strcmp(argv[i], "--missing-id") && has_val)
			st.missing_id = atoi(argv[++i]);
		else if (argv[i][0] != '-' && !path)
			path = argv[i];
		else {
			ls_usage();
			return 2;
		}
	}
	if (!path) {
		ls_usage();
		return 2;
	}
	if (ls_read(&st, path) != 0)
		return 1;
	ls_print(&st);
	return 0;
}
