/* cli.c — undulate-model's options (cli.h). */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "num.h"

const char cli_usage[] =
	"usage: undulate-model pair    [--dsep D] [--restitution R] [--delta0 X] [OPTIONS]\n"
	"       undulate-model lattice [--n N] [--dsep D] [--restitution R] [--beta B|B1,...,BN] [--fixed-ends]\n"
	"                              [--walls D] [--seed S | --phases P1,...,PN] [OPTIONS]\n"
	"       undulate-model map     [--restitution R] [--dsep D | --dsep-from A --dsep-to B] [--dsep-points K]\n"
	"                              [--delta-points M]          (CSV on stdout)\n"
	"OPTIONS: --duration S (60) --out DIR (.) --frequency HZ (0.8) --amplitude A (0.8) --sample-hz H (20)\n"
	"         --window S (10) --tolerance T (1e-12) --amplitude-rate R (0: the phase model) --no-samples --quiet\n"
	"The paper's phase-oscillator model, integrated (README.md in the source's model/).\n";

static int cli_err(char *err, size_t cap, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err, cap, fmt, ap);
	va_end(ap);
	return -1;
}

static int cli_num(const char *name, const char *s, double lo, double hi, double *out, char *err, size_t cap)
{
	enum num_status st = num_parse_double_in(s, lo, hi, out);
	if (st != NUM_OK)
		return cli_err(err, cap, "--%s '%s' is %s (expected a number in [%g, %g])", name, s, num_strerror(st), lo, hi);
	return 0;
}

/* "x" or "x1,...,xN" into out[0..n): one value fills all n. *count gets
 * how many were given. */
static int cli_list(const char *name, const char *s, double lo, double hi, double *out, int *count, char *err,
		    size_t cap)
{
	char buf[16384];
	if (strlen(s) >= sizeof buf)
		return cli_err(err, cap, "--%s: the list is too long", name);
	strcpy(buf, s);
	int k = 0;
	char *save = NULL;
	for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		if (k >= CLI_MAX_OSC)
			return cli_err(err, cap, "--%s: more than %d values", name, CLI_MAX_OSC);
		if (cli_num(name, tok, lo, hi, &out[k], err, cap) != 0)
			return -1;
		k++;
	}
	if (k == 0)
		return cli_err(err, cap, "--%s: no value", name);
	*count = k;
	return 0;
}

static void cli_defaults(struct cli_opts *o)
{
	memset(o, 0, sizeof *o);
	o->n = 2;
	/* the robots' gait (DESIGN.md): model runs line up with the daemons' */
	o->frequency_hz = 0.8;
	o->amplitude = 0.8;
	o->restitution = 0.67;
	o->dsep = 0.3;
	o->seed = 1;
	o->delta0 = 2.0;
	o->duration_s = 60;
	o->sample_hz = 20;
	o->window_s = 10;
	o->write_samples = true;
	o->out_dir = ".";
	o->dsep_from = 0;
	o->dsep_to = 1;
	o->dsep_points = 101;
	o->delta_points = 181;
}

enum {
	OPT_N = 256, OPT_DSEP, OPT_R, OPT_BETA, OPT_FIXED, OPT_WALLS, OPT_SEED, OPT_PHASES, OPT_DELTA0, OPT_DUR,
	OPT_FREQ, OPT_AMP, OPT_SAMPLE, OPT_WINDOW, OPT_TOL, OPT_NOSAMP, OPT_QUIET, OPT_OUT, OPT_DFROM, OPT_DTO,
	OPT_DPTS, OPT_APTS, OPT_ARATE, OPT_HELP
};

static const struct option cli_long[] = {
	{ "n", required_argument, NULL, OPT_N },
	{ "dsep", required_argument, NULL, OPT_DSEP },
	{ "restitution", required_argument, NULL, OPT_R },
	{ "beta", required_argument, NULL, OPT_BETA },
	{ "fixed-ends", no_argument, NULL, OPT_FIXED },
	{ "walls", required_argument, NULL, OPT_WALLS },
	{ "seed", required_argument, NULL, OPT_SEED },
	{ "phases", required_argument, NULL, OPT_PHASES },
	{ "delta0", required_argument, NULL, OPT_DELTA0 },
	{ "duration", required_argument, NULL, OPT_DUR },
	{ "frequency", required_argument, NULL, OPT_FREQ },
	{ "amplitude", required_argument, NULL, OPT_AMP },
	{ "sample-hz", required_argument, NULL, OPT_SAMPLE },
	{ "window", required_argument, NULL, OPT_WINDOW },
	{ "tolerance", required_argument, NULL, OPT_TOL },
	{ "amplitude-rate", required_argument, NULL, OPT_ARATE },
	{ "no-samples", no_argument, NULL, OPT_NOSAMP },
	{ "quiet", no_argument, NULL, OPT_QUIET },
	{ "out", required_argument, NULL, OPT_OUT },
	{ "dsep-from", required_argument, NULL, OPT_DFROM },
	{ "dsep-to", required_argument, NULL, OPT_DTO },
	{ "dsep-points", required_argument, NULL, OPT_DPTS },
	{ "delta-points", required_argument, NULL, OPT_APTS },
	{ "help", no_argument, NULL, OPT_HELP },
	{ NULL, 0, NULL, 0 },
};

/* Which options each subcommand takes: an option another one takes is a
 * mistake worth saying (a --beta given to `pair` would be ignored). */
static bool cli_allowed(enum cli_command cmd, int opt)
{
	switch (opt) {
	case OPT_N: case OPT_BETA: case OPT_FIXED: case OPT_WALLS: case OPT_SEED: case OPT_PHASES:
		return cmd == CLI_LATTICE;
	case OPT_DELTA0:
		return cmd == CLI_PAIR;
	case OPT_DFROM: case OPT_DTO: case OPT_DPTS: case OPT_APTS:
		return cmd == CLI_MAP;
	case OPT_DSEP: case OPT_R: case OPT_TOL: case OPT_HELP:
		return true;
	default:
		return cmd != CLI_MAP;
	}
}

struct cli_lists {
	double beta[CLI_MAX_OSC];
	int nbeta, nphases;
	bool dsep_given, range_given;
};

static int cli_one(struct cli_opts *o, struct cli_lists *ls, int c, const char *arg, char *err, size_t cap)
{
	double v;
	switch (c) {
	case OPT_N:
		if (cli_num("n", arg, 1, CLI_MAX_OSC, &v, err, cap) != 0)
			return -1;
		if (v != floor(v))
			return cli_err(err, cap, "--n '%s' is not a whole number", arg);
		o->n = (int)v;
		return 0;
	case OPT_DSEP: ls->dsep_given = true; return cli_num("dsep", arg, 0, 1e6, &o->dsep, err, cap);
	case OPT_R: return cli_num("restitution", arg, 0, 1, &o->restitution, err, cap);
	case OPT_BETA: return cli_list("beta", arg, 0, 1e6, ls->beta, &ls->nbeta, err, cap);
	case OPT_FIXED: o->fixed_ends = true; return 0;
	case OPT_WALLS: o->walls = true; return cli_num("walls", arg, 0, 1e6, &o->wall_dsep, err, cap);
	case OPT_SEED: {
		enum num_status st = num_parse_u64(arg, 0, UINT64_MAX, &o->seed);
		return st == NUM_OK ? 0 : cli_err(err, cap, "--seed '%s' is %s", arg, num_strerror(st));
	}
	case OPT_PHASES:
		o->have_phases = true;
		return cli_list("phases", arg, -1e6, 1e6, o->phases, &ls->nphases, err, cap);
	case OPT_DELTA0: return cli_num("delta0", arg, -M_PI, M_PI, &o->delta0, err, cap);
	case OPT_DUR: return cli_num("duration", arg, 1e-3, 1e7, &o->duration_s, err, cap);
	case OPT_FREQ: return cli_num("frequency", arg, 1e-3, 1e3, &o->frequency_hz, err, cap);
	case OPT_AMP: return cli_num("amplitude", arg, 1e-6, 1e6, &o->amplitude, err, cap);
	case OPT_SAMPLE: return cli_num("sample-hz", arg, 0.01, 1e5, &o->sample_hz, err, cap);
	case OPT_WINDOW: return cli_num("window", arg, 0, 1e7, &o->window_s, err, cap);
	case OPT_TOL: return cli_num("tolerance", arg, 1e-15, 1e-4, &o->tolerance, err, cap);
	case OPT_ARATE: return cli_num("amplitude-rate", arg, 0, LAT_AMPLITUDE_RATE_MAX, &o->amplitude_rate, err, cap);
	case OPT_NOSAMP: o->write_samples = false; return 0;
	case OPT_QUIET: o->quiet = true; return 0;
	case OPT_OUT:
		if (!*arg)
			return cli_err(err, cap, "--out: an empty name");
		o->out_dir = arg;
		return 0;
	case OPT_DFROM: ls->range_given = true; return cli_num("dsep-from", arg, 0, 1e6, &o->dsep_from, err, cap);
	case OPT_DTO: ls->range_given = true; return cli_num("dsep-to", arg, 0, 1e6, &o->dsep_to, err, cap);
	case OPT_DPTS:
		if (cli_num("dsep-points", arg, 1, 100000, &v, err, cap) != 0)
			return -1;
		o->dsep_points = (int)v;
		return v == floor(v) ? 0 : cli_err(err, cap, "--dsep-points '%s' is not a whole number", arg);
	case OPT_APTS:
		if (cli_num("delta-points", arg, 1, 100000, &v, err, cap) != 0)
			return -1;
		o->delta_points = (int)v;
		return v == floor(v) ? 0 : cli_err(err, cap, "--delta-points '%s' is not a whole number", arg);
	default:
		return cli_err(err, cap, "unknown option");
	}
}

/* What the options say together (each alone was checked as it came). */
static int cli_finish(struct cli_opts *o, const struct cli_lists *ls, char *err, size_t cap)
{
	if (o->cmd == CLI_PAIR)
		o->n = 2;
	if (ls->nbeta > 1 && ls->nbeta != o->n)
		return cli_err(err, cap, "--beta: %d values for %d oscillators (give one, or one each)", ls->nbeta, o->n);
	for (int i = 0; i < o->n; i++)
		o->beta[i] = ls->nbeta == 0 ? 0 : ls->nbeta == 1 ? ls->beta[0] : ls->beta[i];
	if (o->fixed_ends) {
		o->beta[0] = 0;
		o->beta[o->n - 1] = 0;
	}
	if (o->have_phases && ls->nphases != o->n)
		return cli_err(err, cap, "--phases: %d values for %d oscillators", ls->nphases, o->n);
	if (o->window_s > o->duration_s)
		o->window_s = o->duration_s;
	if (o->cmd == CLI_MAP) {
		if (ls->dsep_given && ls->range_given)
			return cli_err(err, cap, "--dsep and --dsep-from/--dsep-to: give one or the other");
		if (ls->dsep_given) {
			o->dsep_from = o->dsep_to = o->dsep;
			o->dsep_points = 1;
		}
		if (o->dsep_to < o->dsep_from)
			return cli_err(err, cap, "--dsep-to %g is below --dsep-from %g", o->dsep_to, o->dsep_from);
	}
	return 0;
}

int cli_parse(int argc, char **argv, struct cli_opts *o, char *err, size_t cap)
{
	cli_defaults(o);
	if (argc < 2)
		return cli_err(err, cap, "no subcommand (pair, lattice or map)");
	const char *sub = argv[1];
	if (!strcmp(sub, "pair"))
		o->cmd = CLI_PAIR;
	else if (!strcmp(sub, "lattice"))
		o->cmd = CLI_LATTICE;
	else if (!strcmp(sub, "map"))
		o->cmd = CLI_MAP;
	else if (!strcmp(sub, "--help") || !strcmp(sub, "-h") || !strcmp(sub, "help"))
		return o->cmd = CLI_HELP, 0;
	else
		return cli_err(err, cap, "unknown subcommand '%.40s' (pair, lattice or map)", sub);
	if (o->cmd == CLI_LATTICE)
		o->n = 50;
	struct cli_lists ls = { .nbeta = 0 };
	/* getopt over the words after the subcommand */
	char **av = argv + 1;
	int ac = argc - 1;
	opterr = 0;
	optind = 1;
	int c;
	while ((c = getopt_long(ac, av, ":", cli_long, NULL)) != -1) {
		if (c == '?' || c == ':')
			return cli_err(err, cap, c == ':' ? "%s: the option %.60s needs a value" : "%s: unknown option %.60s",
				       sub, av[optind - 1]);
		if (c == OPT_HELP)
			return o->cmd = CLI_HELP, 0;
		if (!cli_allowed(o->cmd, c))
			return cli_err(err, cap, "%s: --%s is not an option of this subcommand", sub,
				       cli_long[c - OPT_N].name);
		if (cli_one(o, &ls, c, optarg, err, cap) != 0)
			return -1;
	}
	if (optind < ac)
		return cli_err(err, cap, "%s: unexpected argument '%.60s'", sub, av[optind]);
	return cli_finish(o, &ls, err, cap);
}

void cli_lat_params(const struct cli_opts *o, struct lat_params *p)
{
	*p = (struct lat_params){
		.n = o->n, .frequency_hz = o->frequency_hz, .amplitude = o->amplitude,
		.restitution = o->restitution, .dsep = o->dsep, .beta = o->beta, .walls = o->walls,
		.wall_dsep = o->wall_dsep, .tolerance = o->tolerance, .amplitude_rate = o->amplitude_rate,
	};
}
