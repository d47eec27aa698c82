/* plot.c — gnuplot script for undulate-analyze's CSV files (see plot.h).
 * One script, plots.gp, is left in the output directory so a user can tweak
 * and re-run it (`gnuplot plots.gp` in that directory). Written, and run,
 * in the analyser's private directory: gnuplot runs only a script we just
 * wrote, and its `set output` can meet no link or FIFO another user put
 * there (tools/analyze/README.md, "Where the files go"). */
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
/* A new file in the private directory (nothing can be there before us). */
static FILE *plot_create(const struct plot_input *in, const char *name)
{
	int fd = openat(in->dirfd, name, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
	FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
	if (!f && fd >= 0)
		close(fd);
	return f;
}

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
	      "set grid\n"
	      "set key outside right top\n"
	      "# the colour scale of return maps: time\n"
	      "set palette rgb 33,13,10\n",
	      f);
}

/* A PNG of W x H pixels (cairo when there, else libgd). */
static void plot_terminal(FILE *f, int w, int h)
{
	fprintf(f, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
		   "  set terminal pngcairo size %d,%d noenhanced font ',10'\n"
		   "} else {\n"
		   "  set terminal png size %d,%d noenhanced\n"
		   "}\n", w, h, w, h);
}

/* Vertical marks at the mode switches, labelled with the new mode. */
static void plot_switch_marks(FILE *f, const struct plot_input *in, bool labels)
{
	fputs("unset arrow\nunset label\n", f);
	for (int i = 0; i < in->nswitches; i++) {
		fprintf(f, "set arrow from %.3f, graph 0 to %.3f, graph 1 nohead dt 2 lw 1.5 lc 'black'\n",
			in->switches[i].t, in->switches[i].t);
		if (labels) {
			fprintf(f, "set label '-> %s' at %.3f, graph 0.95 offset 0.5,0 front\n", in->switches[i].to,
				in->switches[i].t);
		}
	}
}

/* Datablock $s_R_J: time, angle, speed of robot R's joint J. states.csv
 * interleaves the robots' rows, so a filter inside `plot ... with lines`
 * leaves no two valid points in a row and draws nothing: filter into a
 * table first, then draw the table. */
static void plot_state_tables(FILE *f, const struct plot_input *in, int nrobots)
{
	for (int i = 0; i < nrobots; i++) {
		for (int j = 0; j < in->njoints[i]; j++) {
			if (!(in->joint_mask[i] & (1u << j)))
				continue;
			/* Rows by robot_index and joint, compared as text: gnuplot
			 * 5.4's table filter got 0 rows from `$4 == 1` on the whole
			 * file; a name may hold quotes or commas no filter matches. */
			fprintf(f, "set table $s_%d_%d separator comma\n"
				   "plot 'states.csv' skip 1 using 2:6:7 with table if ((strcol(17) eq \"%d\") && "
				   "(strcol(4) eq \"%d\"))\nunset table\n", i, j, in->robot_index[i], j);
		}
	}
}

static int plot_min(int a, int b) { return a < b ? a : b; }

/* Joint colours, dark for lines and pale for the whole run behind them. */
static const char *const plot_dark[] = { "'#1f4e9c'", "'#b3261e'", "'#2e7d32'", "'#6a1b9a'" };
static const char *const plot_pale[] = { "'#a9c1e8'", "'#eeb0aa'", "'#b3dab5'", "'#d1b3e0'" };

static void plot_angles_and_portraits(FILE *f, const struct plot_input *in)
{
	if (in->nrobots == 0)
		return;
	int n = plot_min(in->nrobots, PLOT_MAX_PANELS);
	plot_state_tables(f, in, n);
	char more[64] = "";
	if (in->nrobots > n)
		snprintf(more, sizeof more, " (first %d of %d robots)", n, in->nrobots);

	plot_terminal(f, 1100, n <= 2 ? 650 : 220 * n);
	fprintf(f, "set output 'angles.png'\nset multiplot layout %d,1 title 'joint angles%s'\n", n, more);
	fputs("set xlabel 't (s)'\nset ylabel 'angle (rad)'\n", f);
	plot_switch_marks(f, in, true);
	for (int i = 0; i < n; i++) {
		fputs("set title ", f);
		plot_str(f, in->robots[i]);
		fputc('\n', f);
		bool first = true;
		for (int j = 0; j < in->njoints[i]; j++) {
			if (!(in->joint_mask[i] & (1u << j)))
				continue;
			fprintf(f, "%s$s_%d_%d using 1:2 with lines lw 1.2 lc rgb %s title 'joint %d'",
				first ? "plot " : ", \\\n  ", i, j, plot_dark[j % 4], j);
			first = false;
		}
		fputc('\n', f);
	}
	fputs("unset multiplot\nunset arrow\nunset label\n", f);

	/* Phase portraits: the whole run thin and pale, the final window bold. */
	int cols = plot_min(n, 4), rows = (n + cols - 1) / cols;
	plot_terminal(f, 1100, rows * 330 + 40);
	fprintf(f, "set output 'portraits.png'\nset multiplot layout %d,%d title 'phase portraits "
		   "(bold: the final window from t = %.1f s)%s'\n", rows, cols, in->window_start, more);
	fputs("set xlabel 'angle (rad)'\nset ylabel 'speed (rad/s)'\nset key inside top right\n", f);
	for (int i = 0; i < n; i++) {
		fputs("set title ", f);
		plot_str(f, in->robots[i]);
		fputs("\nplot ", f);
		bool first = true;
		for (int j = 0; j < in->njoints[i]; j++) {
			if (!(in->joint_mask[i] & (1u << j)))
				continue;
			int c = j % 4;
			fprintf(f, "%s$s_%d_%d using 2:3 with lines lw 0.5 lc rgb %s notitle, \\\n"
				   "  $s_%d_%d using ($1 >= %.3f ? $2 : 1/0):3 with lines lw 2 lc rgb %s title 'joint %d'",
				first ? "" : ", \\\n  ", i, j, plot_pale[c], i, j, in->window_start, plot_dark[c], j);
			first = false;
		}
		fputc('\n', f);
	}
	fputs("unset multiplot\nset key outside right top\n", f);
}

/* Δ drawn on (cut, cut + 2π] instead of (−π, π]: anti-phase (±π) is then
 * one band instead of two at the edges, and the compatibility bounds
 * ±2·asin(d̃) stay inside (cut is below −2·asin(d̃)). */
static double plot_cut(double dsep)
{
	double b = isfinite(dsep) && dsep >= 0 ? 2.0 * asin(dsep < 1 ? dsep : 1.0) : 0.0;
	double cut = -(b + 0.3);
	if (cut > -M_PI / 2)
		cut = -M_PI / 2;
	if (cut < -M_PI)
		cut = -M_PI;
	return cut;
}

static void plot_phase_diff(FILE *f, const struct plot_input *in)
{
	const struct plot_pair *show[PLOT_MAX_PANELS];
	int n = 0, with_data = 0;
	for (int k = 0; k < in->npairs; k++) {
		if (in->pairs[k].delta_points <= 0)
			continue;
		with_data++;
		if (n < PLOT_MAX_PANELS)
			show[n++] = &in->pairs[k];
	}
	if (n == 0)
		return;
	char more[64] = "";
	if (with_data > n)
		snprintf(more, sizeof more, " (first %d of %d pairs)", n, with_data);
	plot_terminal(f, 1100, n <= 2 ? 650 : 230 * n);
	fprintf(f, "set output 'phase_diff.png'\nset multiplot layout %d,1 title 'phase difference "
		   "between neighbours, with the compatibility bounds +-2 asin(d~)%s'\n", n, more);
	fputs("set xlabel 't (s)'\nset ylabel 'delta (rad)'\n", f);
	for (int i = 0; i < n; i++) {
		const struct plot_pair *p = show[i];
		double cut = plot_cut(p->dsep);
		plot_switch_marks(f, in, i == 0);
		fprintf(f, "set yrange [%.4f:%.4f]\n", cut, cut + 2 * M_PI);
		fputs("set ytics ('-pi/2' -pi/2, '0' 0, 'pi/2' pi/2, 'pi' pi, '3pi/2' 3*pi/2)\n", f);
		char title[200];
		if (isfinite(p->dsep))
			snprintf(title, sizeof title, "%s: d~ = %.3f, bound 2 asin(d~) = %.3f rad", p->name, p->dsep,
				 p->dsep <= 1 ? 2 * asin(p->dsep) : M_PI);
		else
			snprintf(title, sizeof title, "%s: d~ unknown (no simulator data)", p->name);
		fputs("set title ", f);
		plot_str(f, title);
		fprintf(f, "\nplot 'phase_diff.csv' skip 1 using 2:(strcol(3) eq ");
		plot_str(f, p->name);
		fprintf(f, " ? ($9 <= %.4f ? $9 + 2*pi : $9) : 1/0) with points pt 7 ps 0.3 lc rgb '#1f4e9c' "
			   "title 'delta'", cut);
		if (isfinite(p->dsep) && p->dsep < 1) {
			double b = 2 * asin(p->dsep);
			fprintf(f, ", \\\n  %.5f with lines dt 2 lw 1.5 lc rgb '#2e7d32' title 'compatible bound', "
				   "\\\n  %.5f with lines dt 2 lw 1.5 lc rgb '#2e7d32' notitle", b, -b);
		}
		fputs(", \\\n  pi with lines dt 3 lc rgb '#777777' title 'anti-phase'", f);
		if (p->collisions > 0) {
			fprintf(f, ", \\\n  'collisions.csv' skip 1 using 2:(strcol(12) eq ");
			plot_str(f, p->name);
			fprintf(f, " ? %.4f : 1/0) with points pt 9 ps 0.7 lc rgb '#b3261e' title 'collision'",
				cut + 0.12);
		}
		fputc('\n', f);
	}
	fputs("unset multiplot\nunset arrow\nunset label\nset autoscale y\nset ytics autofreq\n", f);
}

static int plot_theory_file(const struct plot_input *in, int k, double dsep)
{
	char name[64];
	snprintf(name, sizeof(name), "theory_%d.csv", k);
	FILE *t = plot_create(in, name);
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
		plot_terminal(f, 900, 800);
		fprintf(f, "set output 'return_map_%d.png'\nset title ", k);
		char title[512];
		snprintf(title, sizeof(title), "return map %s: %d contacts; curve: theory at the final d~ = %.3f%s, "
			 "r = %.2f (%s)", p->name, p->map_points + 1, dsep, isfinite(p->dsep) ? "" : " (unknown, 0 drawn)",
			 in->restitution, in->restitution_from);
		plot_str(f, title);
		fputs("\nset xlabel 'delta_n (rad)'\nset ylabel 'delta_n+1 (rad)'\nset cblabel 't (s)'\n"
		      "set xrange [-pi:pi]\nset yrange [-pi:pi]\nset size ratio -1\nset key below\n", f);
		fprintf(f, "plot x with lines dt 2 lc 'gray' title 'identity', \\\n"
			   "  'theory_%d.csv' skip 1 using 1:2 with lines lw 2 lc rgb '#444444' title 'theory', \\\n"
			   "  'return_map.csv' skip 1 using (strcol(1) eq ", k);
		plot_str(f, p->name);
		fputs(" ? $5 : 1/0):7 with points pt 6 ps 0.9 lc rgb '#444444' title 'theory at each contact''s d~', \\\n"
		      "  '' skip 1 using (strcol(1) eq ", f);
		plot_str(f, p->name);
		fputs(" ? $5 : 1/0):6:4 with points pt 7 ps 0.8 lc palette title 'measured (colour: time)'\n"
		      "set autoscale x\nset autoscale y\nset size noratio\nset key outside right top\nunset cblabel\n", f);
	}
	return 0;
}

/* Collisions per second between each pair and against the walls, and the
 * mean contact force (impacts and resting contact) per second. */
static void plot_collision_rate(FILE *f, const struct plot_input *in)
{
	if (!in->have_collisions && !in->have_force)
		return;
	plot_terminal(f, 1100, 750);
	fputs("set output 'collision_rate.png'\nset multiplot layout 2,1\n", f);
	plot_switch_marks(f, in, true);
	fputs("set title 'collisions per second: each pair of robots, and the walls'\n"
	      "set xlabel 't (s)'\nset ylabel 'collisions / s'\n", f);
	if (in->have_collisions) {
		fputs("plot ", f);
		int shown = 0;
		for (int k = 0; k < in->npairs; k++) {
			if (in->pairs[k].collisions <= 0)
				continue;
			fprintf(f, "%s'collisions.csv' skip 1 using (floor($2)):(strcol(12) eq ", shown++ ? ", \\\n  " : "");
			plot_str(f, in->pairs[k].name);
			fputs(" ? 1 : 0) smooth frequency with steps lw 1.5 title ", f);
			plot_str(f, in->pairs[k].name);
		}
		fprintf(f, "%s'collision_rate.csv' skip 1 using 1:5 with steps lw 1.5 dt 2 lc 'black' title 'walls'\n",
			shown ? ", \\\n  " : "");
	} else {
		fputs("plot 'collision_rate.csv' skip 1 using 1:2 with steps title 'none'\n", f);
	}
	fputs("set title 'mean contact force per second (impacts and resting contact)'\n"
	      "set ylabel 'force (N)'\n", f);
	if (in->have_force)
		fputs("plot 'collision_rate.csv' skip 1 using 1:6 with steps lw 2 lc rgb '#b3261e' title 'contact force'\n", f);
	else
		fputs("plot 'collision_rate.csv' skip 1 using 1:3 with steps lw 2 lc rgb '#b3261e' "
		      "title 'impact impulse per second (no SIM.TRUTH)'\n", f);
	fputs("unset multiplot\nunset arrow\nunset label\n", f);
}

static int plot_run(const struct plot_input *in, FILE *msg)
{
	pid_t pid = fork();
	if (pid < 0) {
		fprintf(msg, "undulate-analyze: cannot start gnuplot: %s\n", strerror(errno));
		return -1;
	}
	if (pid == 0) {
		if (fchdir(in->dirfd) != 0)
			_exit(PLOT_EXEC_FAILED - 1);
		int fd = open("plots.log", O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW, 0666);
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
	FILE *f = plot_create(in, "plots.gp");
	if (!f) {
		fprintf(msg, "undulate-analyze: %s/plots.gp: %s\n", in->dir, strerror(errno));
		return -1;
	}
	plot_header(f);
	plot_angles_and_portraits(f, in);
	plot_phase_diff(f, in);
	int rc = plot_return_maps(f, in);
	plot_collision_rate(f, in);
	if (fclose(f) != 0 || rc != 0) {
		fprintf(msg, "undulate-analyze: cannot write the plot files in %s\n", in->dir);
		return -1;
	}
	return plot_run(in, msg);
}
