/* undulate-model — the paper's phase-oscillator model integrated (README.md):
 * `pair`, `lattice` and `map`. Exit 0 done, 1 the integrator failed, 2 a bad
 * argument, 5 the output could not be written. */
#include <stdio.h>

#include "cli.h"
#include "run.h"

int main(int argc, char **argv)
{
	static struct cli_opts o;   /* ~16 kB of per-oscillator arrays */
	char err[256];
	if (cli_parse(argc, argv, &o, err, sizeof err) != 0) {
		fprintf(stderr, "undulate-model: %s\n%s", err, cli_usage);
		return MRUN_USAGE;
	}
	if (o.cmd == CLI_HELP) {
		fputs(cli_usage, stdout);
		return MRUN_OK;
	}
	if (o.cmd == CLI_MAP)
		return mrun_map(&o, stdout, stderr);
	return mrun_row(&o, stderr);
}
