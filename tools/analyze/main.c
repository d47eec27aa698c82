/* undulate-analyze — LCM logs to CSV files, phase differences, return maps,
 * an end-state classification and plots. See tools/analyze/README.md. */
#include "analyze.h"
#include "num.h"
#include "record.h"
#include "synth.h"
#include "theory_cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void usage(FILE *f)
{
	fputs("usage: undulate-analyze LOG... [--out DIR] [--pairs a:b,...] [--plots|--plots-only]\n"
	      "                        [--from S] [--to S] [--window S] [--separation D]\n"
	      "                        [--restitution R] [--merge S] [--min-swing RAD] [--zero-crossings]\n"
	      "                        [--frequency HZ] [--plane-every S]\n"
	      "                        [--quiet]\n"
	      "       undulate-analyze --synth OUT.log [--duration S] [--synth-stop-after S]\n"
	      "       undulate-analyze --record OUT.log [--lcm-url URL]\n"
	      "       undulate-analyze --theory curves|critical|map|map-d0|sequence|final [--restitution R]\n"
	      "                        [--separation D] [--delta0 RAD] [--steps N] [--points N]\n"
	      "Reads lcm-logger logs and writes states.csv, collisions.csv, bus.csv, events.csv,\n"
	      "phase_diff.csv, return_map.csv, collision_rate.csv, summary.txt, summary.json\n"
	      "(plane.csv and plane_walls.csv for a plane world's log; PNG plots with --plots)\n"
	      "into DIR (default: current directory). A LOG may be xz-compressed (LOG.xz).\n"
	      "  --plots-only      the plots, the summary and the files the plots' script reads,\n"
	      "                    without the per-sample CSVs (states.csv, phase_diff.csv, ...)\n"
	      "  --pairs a:b,...   pairs to follow (default: neighbours by SIM.TRUTH position, else name)\n"
	      "  --from/--to S     only events between S seconds after the log start\n"
	      "  --window S        final window for the end-state classification (default 10)\n"
	      "  --separation D    normalized separation d~ for every pair (default: from SIM.TRUTH)\n"
	      "  --restitution R   r for the theory curve (default: the simulator's, from SIM.WORLD; else 0.67)\n"
	      "  --merge S         collisions of a pair less than S apart are one contact (default 0.1)\n"
	      "  --min-swing RAD   a pair with a joint swinging less than RAD peak-to-peak in the final\n"
	      "                    window is not-oscillating, whatever its phases (default 0.2)\n"
	      "  --zero-crossings  phase from our own frequency estimate (centre crossings), not the daemon's\n"
	      "  --frequency HZ    every joint's phase at this frequency from the first sample (no estimate)\n"
	      "  --plane-every S   plane.csv: the links' poses every S seconds (default 0.1; 0: every\n"
	      "                    SIM.TRUTH)\n"
	      "  --synth OUT.log   write a synthetic log with known phases and collisions\n"
	      "  --duration S      length of the synthetic log (default 45)\n"
	      "  --synth-stop-after S  in the synthetic log, r3 and r4 stand still from S seconds on\n"
	      "  --record OUT.log  record the LCM group into OUT.log until SIGINT/SIGTERM, like lcm-logger\n"
	      "                    but keeping every message when it falls behind (--lcm-url URL)\n"
	      "  --theory WHAT     the contact theory as CSV on stdout (r: --restitution, default 0.67):\n"
	      "                    curves: d~, 2 asin(d~), f'(pi), |f'(pi)|, stable, third fixed point;\n"
	      "                    critical: d~_c; map: the return map at --separation D; map-d0: at\n"
	      "                    d~ = 0 with its closed form; sequence: delta_n from --delta0 at d~ = 0\n"
	      "                    (--steps N, default 10); final: where the map leads each \"dsep,delta0\"\n"
	      "                    line of stdin; --points N: samples of a curve\n"
	      "exit: 0 ok, 1 usage, 2 bad/missing log, 3 truncated log (partial results),\n"
	      "      4 plots failed, 5 output not writable\n",
	      f);
}

static int parse_double(const char *opt, const char *s, double *out)
{
	enum num_status st = num_parse_double(s, out);
	if (st != NUM_OK) {
		fprintf(stderr, "undulate-analyze: %s: \"%s\" is %s\n", opt, s, num_strerror(st));
		return -1;
	}
	return 0;
}

enum { OPT_OUT = 256, OPT_PAIRS, OPT_PLOTS, OPT_PLOTS_ONLY, OPT_FROM, OPT_TO, OPT_WINDOW, OPT_SEP, OPT_REST,
       OPT_SYNTH, OPT_DURATION, OPT_QUIET, OPT_ZC, OPT_MERGE, OPT_MIN_SWING, OPT_STOP_AFTER, OPT_HELP,
       OPT_RECORD, OPT_LCM_URL, OPT_FREQ, OPT_THEORY, OPT_DELTA0, OPT_STEPS, OPT_POINTS, OPT_PLANE_EVERY };

static const struct option long_opts[] = {
	{ "out", required_argument, NULL, OPT_OUT },       { "pairs", required_argument, NULL, OPT_PAIRS },
	{ "plots", no_argument, NULL, OPT_PLOTS },         { "plots-only", no_argument, NULL, OPT_PLOTS_ONLY },         { "from", required_argument, NULL, OPT_FROM },
	{ "to", required_argument, NULL, OPT_TO },         { "window", required_argument, NULL, OPT_WINDOW },
	{ "separation", required_argument, NULL, OPT_SEP }, { "restitution", required_argument, NULL, OPT_REST },
	{ "synth", required_argument, NULL, OPT_SYNTH },   { "duration", required_argument, NULL, OPT_DURATION },
	{ "quiet", no_argument, NULL, OPT_QUIET },         { "zero-crossings", no_argument, NULL, OPT_ZC },
	{ "merge", required_argument, NULL, OPT_MERGE },   { "min-swing", required_argument, NULL, OPT_MIN_SWING },
	{ "synth-stop-after", required_argument, NULL, OPT_STOP_AFTER },
	{ "record", required_argument, NULL, OPT_RECORD }, { "lcm-url", required_argument, NULL, OPT_LCM_URL },
	{ "frequency", required_argument, NULL, OPT_FREQ }, { "plane-every", required_argument, NULL, OPT_PLANE_EVERY },
	{ "theory", required_argument, NULL, OPT_THEORY }, { "delta0", required_argument, NULL, OPT_DELTA0 },
	{ "steps", required_argument, NULL, OPT_STEPS },   { "points", required_argument, NULL, OPT_POINTS },
	{ "help", no_argument, NULL, OPT_HELP },
	{ NULL, 0, NULL, 0 },
};

/* What --synth takes besides the output path; 0 / NAN: not given. And
 * --record's and --theory's. */
struct synth_args {
	const char *path;
	double duration;
	double stop_after;
	const char *record;
	const char *lcm_url;
	const char *theory;
	double delta0;
	long steps, points;
};

static int parse_long_opt(const char *opt, const char *s, long *out)
{
	enum num_status st = num_parse_long(s, -1000000000L, 1000000000L, out);
	if (st != NUM_OK) {
		fprintf(stderr, "undulate-analyze: %s: \"%s\" is %s\n", opt, s, num_strerror(st));
		return -1;
	}
	return 0;
}

static int parse_option(int c, struct an_options *o, struct synth_args *sa)
{
	switch (c) {
	case OPT_OUT: o->out_dir = optarg; return 0;
	case OPT_PAIRS: o->pairs = optarg; return 0;
	case OPT_PLOTS: o->plots = true; return 0;
	case OPT_PLOTS_ONLY: o->plots = o->plots_only = true; return 0;
	case OPT_QUIET: o->quiet = true; return 0;
	case OPT_ZC: o->zero_crossings = true; return 0;
	case OPT_MERGE: return parse_double("--merge", optarg, &o->merge_s);
	case OPT_FROM: return parse_double("--from", optarg, &o->from_s);
	case OPT_TO: return parse_double("--to", optarg, &o->to_s);
	case OPT_WINDOW: return parse_double("--window", optarg, &o->window_s);
	case OPT_SEP: return parse_double("--separation", optarg, &o->separation);
	case OPT_REST: return parse_double("--restitution", optarg, &o->restitution);
	case OPT_MIN_SWING: return parse_double("--min-swing", optarg, &o->min_swing);
	case OPT_FREQ: return parse_double("--frequency", optarg, &o->frequency_hz);
	case OPT_PLANE_EVERY: return parse_double("--plane-every", optarg, &o->plane_every_s);
	case OPT_SYNTH: sa->path = optarg; return 0;
	case OPT_DURATION: return parse_double("--duration", optarg, &sa->duration);
	case OPT_STOP_AFTER: return parse_double("--synth-stop-after", optarg, &sa->stop_after);
	case OPT_RECORD: sa->record = optarg; return 0;
	case OPT_LCM_URL: sa->lcm_url = optarg; return 0;
	case OPT_THEORY: sa->theory = optarg; return 0;
	case OPT_DELTA0: return parse_double("--delta0", optarg, &sa->delta0);
	case OPT_STEPS: return parse_long_opt("--steps", optarg, &sa->steps);
	case OPT_POINTS: return parse_long_opt("--points", optarg, &sa->points);
	case OPT_HELP: usage(stdout); exit(AN_EXIT_OK);
	default: return -1;
	}
}

/* Highest --frequency: half the daemons' 100 Hz state rate (a phase needs
 * at least two samples a cycle). */
#define AN_MAX_FREQUENCY_HZ 50.0
/* Longest --plane-every: an hour (one pose of a long run). */
#define AN_MAX_PLANE_EVERY_S 3600.0

static int check_options(const struct an_options *o)
{
	if (!(o->window_s > 0)) {
		fputs("undulate-analyze: --window must be > 0\n", stderr);
		return -1;
	}
	if (!isnan(o->restitution) && !(o->restitution >= 0 && o->restitution <= 1)) {
		fputs("undulate-analyze: --restitution must be in [0, 1]\n", stderr);
		return -1;
	}
	if (!(o->merge_s >= 0)) {
		fputs("undulate-analyze: --merge must be >= 0\n", stderr);
		return -1;
	}
	if (!(o->min_swing >= 0)) {
		fputs("undulate-analyze: --min-swing must be >= 0\n", stderr);
		return -1;
	}
	if (!isnan(o->frequency_hz) && !(o->frequency_hz > 0 && o->frequency_hz <= AN_MAX_FREQUENCY_HZ)) {
		fprintf(stderr, "undulate-analyze: --frequency must be > 0 and <= %g Hz\n", AN_MAX_FREQUENCY_HZ);
		return -1;
	}
	if (!(o->plane_every_s >= 0 && o->plane_every_s <= AN_MAX_PLANE_EVERY_S)) {
		fprintf(stderr, "undulate-analyze: --plane-every must be >= 0 and <= %g s\n", AN_MAX_PLANE_EVERY_S);
		return -1;
	}
	if (isfinite(o->separation) && o->separation < 0) {
		fputs("undulate-analyze: --separation must be >= 0\n", stderr);
		return -1;
	}
	if (!isnan(o->from_s) && !isnan(o->to_s) && o->to_s <= o->from_s) {
		fputs("undulate-analyze: --to must be after --from\n", stderr);
		return -1;
	}
	return 0;
}

#define AN_SYNTH_MAX_S 3600.0   /* longest synthetic log, s */

static int run_synth(const struct synth_args *sa)
{
	struct synth_spec s;
	synth_default(&s);
	if (sa->duration > 0)
		s.duration_s = sa->duration;
	if (!isnan(sa->stop_after))
		s.stop_after_s = sa->stop_after;
	char err[1024];
	int n = synth_write(&s, sa->path, err, sizeof err);
	if (n < 0) {
		fprintf(stderr, "undulate-analyze: --synth %s: %s\n", sa->path, err);
		return AN_EXIT_OUTPUT;
	}
	printf("%s: %.1f s, %d robots, %d collisions", sa->path, s.duration_s, SYNTH_ROBOTS, n);
	if (s.stop_after_s >= 0)
		printf(", r3 and r4 still from %.1f s", s.stop_after_s);
	putchar('\n');
	return AN_EXIT_OK;
}

/* The --synth options; returns 0 or -1 after saying what is wrong. */
static int check_synth(const struct synth_args *sa)
{
	/* 0: not given (the synthetic default); a log of hours would only fill a disk */
	if (!(sa->duration >= 0 && sa->duration <= AN_SYNTH_MAX_S)) {
		fprintf(stderr, "undulate-analyze: --duration: %g is not 0 < S <= %.0f seconds\n", sa->duration,
		        AN_SYNTH_MAX_S);
		return -1;
	}
	if (!isnan(sa->stop_after) && !(sa->stop_after >= 0)) {
		fprintf(stderr, "undulate-analyze: --synth-stop-after: %g is not >= 0 seconds\n", sa->stop_after);
		return -1;
	}
	return 0;
}

/* --theory: nothing else is read or written. */
static int run_theory(const struct an_options *o, const struct synth_args *sa, const char *stray)
{
	if (stray || sa->path || sa->record) {
		fprintf(stderr, "undulate-analyze: --theory prints the theory and reads no log: unexpected '%s'\n",
		        stray ? stray : sa->path ? "--synth" : "--record");
		return AN_EXIT_USAGE;
	}
	struct theory_request q = {
		.what = sa->theory,
		/* the paper's rig, as for a log without SIM.WORLD */
		.r = isnan(o->restitution) ? 0.67 : o->restitution,
		.dsep = o->separation,
		.delta0 = sa->delta0,
		.points = sa->points,
		.steps = sa->steps < 0 ? 10 : sa->steps,
	};
	return theory_cli_run(&q, stdin, stdout);
}

int main(int argc, char **argv)
{
	struct an_options o;
	an_options_default(&o);
	struct synth_args sa = { .path = NULL, .duration = 0, .stop_after = NAN, .delta0 = NAN, .steps = -1 };
	int c;
	while ((c = getopt_long(argc, argv, "ho:", long_opts, NULL)) != -1) {
		if (c == 'h')
			c = OPT_HELP;
		if (c == 'o')
			c = OPT_OUT;
		if (parse_option(c, &o, &sa) != 0) {
			usage(stderr);
			return AN_EXIT_USAGE;
		}
	}
	if (sa.theory)
		return run_theory(&o, &sa, optind < argc ? argv[optind] : NULL);
	if (!isnan(sa.delta0) || sa.steps >= 0 || sa.points != 0) {
		fputs("undulate-analyze: --delta0, --steps and --points only go with --theory\n", stderr);
		return AN_EXIT_USAGE;
	}
	if (sa.record) {
		if (optind < argc || sa.path) {
			fprintf(stderr, "undulate-analyze: --record writes a log and reads none: unexpected '%s'\n",
			        sa.path ? "--synth" : argv[optind]);
			return AN_EXIT_USAGE;
		}
		return rec_run(sa.record, sa.lcm_url);
	}
	if (sa.lcm_url) {
		fputs("undulate-analyze: --lcm-url only goes with --record\n", stderr);
		return AN_EXIT_USAGE;
	}
	if (sa.path && optind < argc) {
		/* a log named here would silently not be read */
		fprintf(stderr, "undulate-analyze: --synth writes a log and reads none: unexpected '%s'\n", argv[optind]);
		return AN_EXIT_USAGE;
	}
	if (sa.path)
		return check_synth(&sa) != 0 ? AN_EXIT_USAGE : run_synth(&sa);
	if (!isnan(sa.stop_after)) {
		fputs("undulate-analyze: --synth-stop-after only goes with --synth\n", stderr);
		return AN_EXIT_USAGE;
	}
	for (; optind < argc; optind++) {
		if (o.nlogs >= AN_MAX_LOGS) {
			fprintf(stderr, "undulate-analyze: at most %d logs\n", AN_MAX_LOGS);
			return AN_EXIT_USAGE;
		}
		o.logs[o.nlogs++] = argv[optind];
	}
	if (o.nlogs == 0) {
		usage(stderr);
		return AN_EXIT_USAGE;
	}
	if (check_options(&o) != 0)
		return AN_EXIT_USAGE;
	return an_run(&o);
}
