/* plot.c — gnuplot script for undulate-analyze's CSV files (see plot.h).
 * One script, plots.gp, is left in the output directory so a user can tweak
 * and re-run it (`gnuplot plots.gp` in that directory). */
#include "plot.h"
#include "theory.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

/* Points of the theory curve over (-pi, pi]. */
#define PLOT_THEORY_POINTS 721
/* Exit status of the child when exec failed (as the shell's "not found"). */
#define PLOT_EXEC_FAILED 127

const char *plot_gnuplot(void)
{
	const char *g = getenv("GNUPLOT");
	return g && *g ? g : "gnuplot";
}

/* A gnuplot double-quoted string: backslash and quote escaped. */
static void plot_str(FILE *f, const char *s)
{
	fputc('"', f);
	for (; *s; s++) {
		if (*s == '"' || *s == '\\')
			fputc('\\', f);
		fputc(*s, f);
	}
	fputc('"', f);
}

static void plot_header(FILE *f)
{
	fputs("# undulate-analyze plots; run `gnuplot plots.gp` in this directory\n"
	      "set datafile separator ','\n"
	      "set datafile missing ''\n"
	      "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
	      "  set terminal pngcairo size 1100,650 noenhanced font ',10'\n"
	      "} else {\n"
	      "  set terminal png size 1100,650 noenhanced\n"
	      "}\n"
	      "set grid\n"
	      "set key outside right top\n",
	      f);
}

/* One clause per robot: states.csv filtered on robot and joint 0. */
static void plot_states(FILE *f, const struct plot_input *in, const char *xcol, const char *ycol)
{
	for (int i = 0; i < in->nrobots; i++) {
		fputs(i ? ", \\\n  '' skip 1 using " : "plot 'states.csv' skip 1 using ", f);
		fputs("(strcol(3) eq ", f);
		plot_str(f, in->robots[i]);
		fprintf(f, " && $4 == 0 ? %s : 1/0):%s with lines title ", xcol, ycol);
		plot_str(f, in->robots[i]);
	}
	fputc('\n', f);
}

static void plot_angles_and_portraits(FILE *f, const struct plot_input *in)
{
	if (in->nrobots == 0)
		return;
	fputs("set output 'angles.png'\nset title 'joint 0 angle'\n"
	      "set xlabel 't (s)'\nset ylabel 'angle (rad, from neutral)'\n", f);
	plot_states(f, in, "$2", "6");
	fputs("set output 'portraits.png'\nset title 'phase portraits, joint 0'\n"
	      "set xlabel 'angle (rad)'\nset ylabel 'speed (rad/s)'\n", f);
	plot_states(f, in, "$6", "7");
}

static void plot_phase_diff(FILE *f, const struct plot_input *in)
{
	if (in->npairs == 0)
		return;
	fputs("set output 'phase_diff.png'\nset title 'phase difference between neighbours'\n"
	      "set xlabel 't (s)'\nset ylabel 'delta (rad)'\nset yrange [-pi:pi]\n"
	      "set ytics ('-pi' -pi, '-pi/2' -pi/2, '0' 0, 'pi/2' pi/2, 'pi' pi)\n", f);
	for (int k = 0; k < in->npairs; k++) {
		fputs(k ? ", \\\n  '' skip 1 using 2:(strcol(3) eq " : "plot 'phase_diff.csv' skip 1 using 2:(strcol(3) eq ", f);
		plot_str(f, in->pairs[k].name);
		fputs(" ? $9 : 1/0) with points pt 7 ps 0.3 title ", f);
		plot_str(f, in->pairs[k].name);
	}
	fputs("\nset autoscale y\nset ytics autofreq\n", f);
}

static int plot_theory_file(const struct plot_input *in, int k, double dsep)
{
	char path[4096];
	snprintf(path, sizeof(path), "%s/theory_%d.csv", in->dir, k);
	FILE *t = fopen(path, "w");
	if (!t)
		return -1;
	fputs("delta_n,delta_next\n", t);
	double prev = NAN;
	for (int i = 0; i < PLOT_THEORY_POINTS; i++) {
		double x = -M_PI + 2.0 * M_PI * (i + 0.5) / PLOT_THEORY_POINTS;
		double y = theory_return_map(x, dsep, in->restitution);
		/* A blank line breaks the curve where no contact is possible
		 * and where it wraps from pi to -pi. */
		if (!isfinite(y) || (isfinite(prev) && fabs(y - prev) > M_PI))
			fputs("\n", t);
		if (isfinite(y))
			fprintf(t, "%.6f,%.6f\n", x, y);
		prev = y;
	}
	return fclose(t);
}

static int plot_return_maps(FILE *f, const struct plot_input *in)
{
	for (int k = 0; k < in->npairs; k++) {
		const struct plot_pair *p = &in->pairs[k];
		if (p->map_points <= 0)
			continue;
		double dsep = isfinite(p->dsep) ? p->dsep : 0.0;
		if (plot_theory_file(in, k, dsep) != 0)
			return -1;
		fprintf(f, "set output 'return_map_%d.png'\nset title ", k);
		char title[512];
		snprintf(title, sizeof(title), "return map %s: theory d~ = %.3f%s, r = %.2f", p->name, dsep,
			 isfinite(p->dsep) ? "" : " (unknown, 0 drawn)", in->restitution);
		plot_str(f, title);
		fputs("\nset xlabel 'delta_n (rad)'\nset ylabel 'delta_n+1 (rad)'\n"
		      "set xrange [-pi:pi]\nset yrange [-pi:pi]\nset size square\n", f);
		fprintf(f, "plot x with lines dt 2 lc 'gray' title 'identity', \\\n"
			   "  'theory_%d.csv' skip 1 using 1:2 with lines lw 2 title 'theory', \\\n"
			   "  'return_map.csv' skip 1 using (strcol(1) eq ", k);
		plot_str(f, p->name);
		fputs(" ? $5 : 1/0):6 with points pt 7 ps 0.8 title 'measured'\n"
		      "set autoscale x\nset autoscale y\nset size nosquare\n", f);
	}
	return 0;
}

static void plot_collision_rate(FILE *f)
{
	fputs("set output 'collision_rate.png'\nset title 'collisions per second (all pairs and walls)'\n"
	      "set xlabel 't (s)'\nset ylabel 'collisions / s'\nset y2label 'impulse (N*s) / s'\n"
	      "set y2tics\n"
	      "plot 'collision_rate.csv' skip 1 using 1:2 with steps lw 2 title 'collisions', \\\n"
	      "  '' skip 1 using 1:3 axes x1y2 with steps title 'impulse'\n"
	      "unset y2tics\nunset y2label\n", f);
}

static int plot_run(const struct plot_input *in, FILE *msg)
{
	pid_t pid = fork();
	if (pid < 0) {
		fprintf(msg, "undulate-analyze: cannot start gnuplot: %s\n", strerror(errno));
		return -1;
	}
	if (pid == 0) {
		if (chdir(in->dir) != 0)
			_exit(PLOT_EXEC_FAILED - 1);
		int fd = open("plots.log", O_WRONLY | O_CREAT | O_TRUNC, 0666);
		if (fd >= 0) {
			dup2(fd, STDOUT_FILENO);
			dup2(fd, STDERR_FILENO);
		}
		execlp(plot_gnuplot(), plot_gnuplot(), "plots.gp", (char *)NULL);
		_exit(PLOT_EXEC_FAILED);
	}
	int status = 0;
	while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
		;
	if (WIFEXITED(status) && WEXITSTATUS(status) == PLOT_EXEC_FAILED) {
		fprintf(msg, "undulate-analyze: %s not found (Debian: apt-get install gnuplot-nox); "
			     "CSV files and summary are written, plots are not\n", plot_gnuplot());
		return -1;
	}
	if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
		fprintf(msg, "undulate-analyze: gnuplot failed; see %s/plots.log\n", in->dir);
		return -1;
	}
	return 0;
}

int plot_all(const struct plot_input *in, FILE *msg)
{
	char path[4096];
	snprintf(path, sizeof(path), "%s/plots.gp", in->dir);
	FILE *f = fopen(path, "w");
	if (!f) {
		fprintf(msg, "undulate-analyze: %s: %s\n", path, strerror(errno));
		return -1;
	}
	plot_header(f);
	plot_angles_and_portraits(f, in);
	plot_phase_diff(f, in);
	int rc = plot_return_maps(f, in);
	plot_collision_rate(f);
	if (fclose(f) != 0 || rc != 0) {
		fprintf(msg, "undulate-analyze: cannot write the plot files in %s\n", in->dir);
		return -1;
	}
	return plot_run(in, msg);
}
