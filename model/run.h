/* run.h — one undulate-model run (pair or lattice) written as undulate-analyze
 * writes a run's analysis: states.csv, phase_diff.csv, collisions.csv,
 * return_map.csv, collision_rate.csv, summary.txt and summary.json, with
 * the same columns and keys (README.md, "Files"), into a directory by the
 * rules of common/outdir.h. And the map subcommand's CSV. */
#ifndef UNDULATE_MODEL_RUN_H
#define UNDULATE_MODEL_RUN_H

#include <stdio.h>

#include "cli.h"

/* Exit statuses (README.md, "Exit status"). */
enum mrun_exit { MRUN_OK = 0, MRUN_FAILED = 1, MRUN_USAGE = 2, MRUN_OUTPUT = 5 };

/* Runs the pair or lattice the options describe; messages on msg. */
int mrun_row(const struct cli_opts *o, FILE *msg);

/* The map subcommand: one collision per (d~, delta) grid point, CSV on out. */
int mrun_map(const struct cli_opts *o, FILE *out, FILE *msg);

#endif
