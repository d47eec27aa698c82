/* cli.h — undulate-model's command line: the subcommand and its options,
 * parsed and checked into one struct before anything runs (README.md,
 * "Options"). No I/O: a bad argument gives a one-line message in err. */
#ifndef UNDULATE_MODEL_CLI_H
#define UNDULATE_MODEL_CLI_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "mdl_lattice.h"

enum cli_command { CLI_PAIR, CLI_LATTICE, CLI_MAP, CLI_HELP };

/* Oscillators at most on the command line (the row's arrays: LAT_MAX_OSC). */
#define CLI_MAX_OSC 1000

struct cli_opts {
	enum cli_command cmd;
	int n;                       /* oscillators (pair: 2) */
	double frequency_hz, amplitude, restitution, dsep;
	double beta[CLI_MAX_OSC];    /* each oscillator's mobility, s */
	bool fixed_ends;             /* beta = 0 for the two end oscillators */
	bool walls;
	double wall_dsep;
	uint64_t seed;
	bool have_phases;            /* --phases given (else drawn from seed; pair: from delta0) */
	double phases[CLI_MAX_OSC];
	double delta0;               /* pair: the phase difference at the start */
	double duration_s, sample_hz, window_s, tolerance;
	double amplitude_rate;       /* 0: the phase model; else the limit cycle's (lat_params) */
	bool write_samples;          /* states.csv and phase_diff.csv rows */
	bool quiet;
	const char *out_dir;
	/* map: a grid of (d~, delta) */
	double dsep_from, dsep_to;
	int dsep_points, delta_points;
};

/* Parses argv (argv[0] the program, argv[1] the subcommand). 0, or -1 with
 * err saying what is wrong (a usage error: exit 2). */
int cli_parse(int argc, char **argv, struct cli_opts *o, char *err, size_t errcap);

/* The usage text. */
extern const char cli_usage[];

/* The struct lat_params the options describe (beta points into o). */
void cli_lat_params(const struct cli_opts *o, struct lat_params *p);

#endif
