/*
 * anrun.h — how the analysis tests (test_analyze_*) run the analyser: one
 * log into one folder, quietly, everything else the analyser's default, as
 * `undulate-analyze --quiet --out OUT_DIR LOG` would. The test then sets
 * what it varies (min_swing, msg, ...) and calls an_run.
 */
#ifndef UNDULATE_ANRUN_H
#define UNDULATE_ANRUN_H

#include <stdbool.h>

#include "../../tools/analyze/analyze.h"

static inline void anrun_options(struct an_options *o, const char *log, const char *out_dir)
{
	an_options_default(o);
	o->logs[0] = log;
	o->nlogs = 1;
	o->out_dir = out_dir;
	o->quiet = true;
}

#endif
