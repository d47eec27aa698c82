/* plot.c — gnuplot script for undulate-analyze's CSV files (see plot.h).
 * One script, plots.gp, is left in the output directory so a user can tweak
 * and re-run it (`gnuplot plots.gp` in that directory). Written, and run,
 * in the analyser's private directory: gnuplot runs only a script we just
 * wrote, and its `set output` can meet no link or FIFO another user put
 * there (tools/analyze/README.md, "Where the files go"). */
#include "plot.h"
#include "outdir.h"
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

/* ---- one CSV split into blocks -----------------------------------------------------------------
 * states.csv interleaves every robot's rows, phase_diff.csv and
 * collisions.csv every pair's, so gnuplot could only filter them, as text,
 * once per panel: twenty passes over states.csv for ten two-joint robots,
 * nine over phase_diff.csv, two minutes of a loaded machine for a 45 s
 * demo. One pass here writes a file of blocks (gnuplot's `index K`, two
 * blank lines apart), a panel's rows in each, the columns it draws only,
 * as they were written. */
#define PLOT_MAX_JOINTS 32   /* joint_mask's bits */
#define PLOT_MAX_COLS 64
#define PLOT_MAX_KEEP 4

struct plot_split {
	const char *src, *dst;            /* "states.csv" -> "joints.dat" */
	const char *key[2];               /* the columns naming a row's block (the second may be NULL) */
	const char *keep[PLOT_MAX_KEEP];  /* the columns a block keeps, in order (NULL ends) */
	char (*blocks)[48];               /* each block's key: the key columns' text, ':' between, unquoted */
	char (*labels)[96];               /* each block's comment line */
	int nblocks;
};

/* Cut a CSV line at the commas outside quotes (a robot's name is quoted);
 * the fields stay as written. */
static int plot_csv_split(char *s, char **field, int max)
{
	int n = 0;
	bool quoted = false;
	field[n++] = s;
	for (; *s && *s != '\n' && *s != '\r'; s++) {
		if (*s == '"') {
			quoted = !quoted;
		} else if (*s == ',' && !quoted) {
			*s = '\0';
			if (n == max)
				return n;
			field[n++] = s + 1;
		}
	}
	*s = '\0';
	return n;
}

static int plot_column(char **field, int n, const char *name)
{
	for (int c = 0; c < n; c++) {
		if (strcmp(field[c], name) == 0)
			return c;
	}
	return -1;
}

/* A growing text per block. */
struct plot_text {
	char *s;
	size_t len, cap;
};

static bool plot_text_add(struct plot_text *t, const char *s, size_t n)
{
	if (t->len + n + 1 > t->cap) {
		size_t cap = t->cap ? t->cap : 4096;
		while (cap < t->len + n + 1)
			cap *= 2;
		char *p = realloc(t->s, cap);
		if (!p)
			return false;
		t->s = p;
		t->cap = cap;
	}
	memcpy(t->s + t->len, s, n);
	t->len += n;
	return true;
}

/* The block a row belongs to; -1 for none. Names are compared unquoted
 * (the names undulate allows hold no quote of their own). */
static int plot_block_of(const struct plot_split *sp, char **field, const int *kcol)
{
	char key[48];
	size_t len = 0;
	for (int k = 0; k < 2 && kcol[k] >= 0; k++) {
		const char *v = field[kcol[k]];
		size_t n = strlen(v);
		if (n >= 2 && v[0] == '"' && v[n - 1] == '"') {
			v++;
			n -= 2;
		}
		if (len + n + 2 > sizeof key)
			return -1;
		if (k > 0)
			key[len++] = ':';
		memcpy(key + len, v, n);
		len += n;
	}
	key[len] = '\0';
	for (int b = 0; b < sp->nblocks; b++) {
		if (strcmp(sp->blocks[b], key) == 0)
			return b;
	}
	return -1;
}

/* Reads sp->src once and writes sp->dst; 0, or -1 (nothing can be drawn of it then). */
static int plot_split_csv(const struct plot_input *in, const struct plot_split *sp)
{
	int fd = openat(in->dirfd, sp->src, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
	FILE *src = fd >= 0 ? fdopen(fd, "r") : NULL;
	if (!src) {
		if (fd >= 0)
			close(fd);
		return -1;
	}
	struct plot_text *text = calloc((size_t)sp->nblocks + 1, sizeof *text);
	char *line = NULL, *field[PLOT_MAX_COLS];
	size_t cap = 0;
	int kcol[2] = { -1, -1 }, keep[PLOT_MAX_KEEP], nkeep = 0, need = 0;
	bool ok = text && getline(&line, &cap, src) > 0;
	if (ok) {
		int n = plot_csv_split(line, field, PLOT_MAX_COLS);
		for (int k = 0; k < 2 && sp->key[k]; k++)
			ok &= (kcol[k] = plot_column(field, n, sp->key[k])) >= 0;
		for (; nkeep < PLOT_MAX_KEEP && sp->keep[nkeep]; nkeep++)
			ok &= (keep[nkeep] = plot_column(field, n, sp->keep[nkeep])) >= 0;
		for (int k = 0; k < 2; k++)
			need = kcol[k] >= need ? kcol[k] + 1 : need;
		for (int k = 0; k < nkeep; k++)
			need = keep[k] >= need ? keep[k] + 1 : need;
	}
	while (ok && getline(&line, &cap, src) > 0) {
		int b = plot_csv_split(line, field, PLOT_MAX_COLS) >= need ? plot_block_of(sp, field, kcol) : -1;
		for (int k = 0; b >= 0 && ok && k < nkeep; k++) {
			ok = plot_text_add(&text[b], field[keep[k]], strlen(field[keep[k]])) &&
			     plot_text_add(&text[b], k + 1 < nkeep ? "," : "\n", 1);
		}
	}
	free(line);
	fclose(src);
	FILE *f = ok ? outdir_stage_fopen(in->dirfd, sp->dst) : NULL;
	for (int b = 0; f && b < sp->nblocks; b++) {
		fprintf(f, "# index %d: %s\n", b, sp->labels[b]);
		if (text[b].len > 0)
			fwrite(text[b].s, 1, text[b].len, f);
		else
			fputs("NaN\n", f);   /* a block may not be empty: the next ones' indices would shift */
		fputs("\n\n", f);
	}
	int rc = f && fclose(f) == 0 ? 0 : -1;
	for (int b = 0; text && b < sp->nblocks; b++)
		free(text[b].s);
	free(text);
	return rc;
}

/* joints.dat: t, angle, speed of each drawn joint of the first nrobots;
 * idx[i][j] is robot i's joint j's block, -1 when not drawn. */
static int plot_write_joints(const struct plot_input *in, int nrobots, int idx[][PLOT_MAX_JOINTS])
{
	char blocks[PLOT_MAX_PANELS * PLOT_MAX_JOINTS][48], labels[PLOT_MAX_PANELS * PLOT_MAX_JOINTS][96];
	int k = 0;
	for (int i = 0; i < nrobots; i++) {
		for (int j = 0; j < PLOT_MAX_JOINTS; j++) {
			idx[i][j] = -1;
			if (j >= in->njoints[i] || !(in->joint_mask[i] & (1u << j)))
				continue;
			idx[i][j] = k;
			snprintf(blocks[k], sizeof blocks[k], "%d:%d", in->robot_index[i], j);
			snprintf(labels[k], sizeof labels[k], "robot %.47s, joint %d: t,angle,speed", in->robots[i], j);
			k++;
		}
	}
	struct plot_split sp = { "states.csv", "joints.dat", { "robot_index", "joint" }, { "t", "angle", "speed" },
				 blocks, labels, k };
	return plot_split_csv(in, &sp);
}

/* PAIRS (n of them) as the blocks of a split of SRC by its "pair" column. */
static int plot_write_pairs(const struct plot_input *in, const struct plot_pair *const *pairs, int n,
			    const char *src, const char *dst, const char *keep0, const char *keep1)
{
	char blocks[PLOT_MAX_PAIRS][48], labels[PLOT_MAX_PAIRS][96];
	for (int k = 0; k < n; k++) {
		snprintf(blocks[k], sizeof blocks[k], "%s", pairs[k]->name);
		snprintf(labels[k], sizeof labels[k], "pair %.47s: %s%s%s", pairs[k]->name, keep0, keep1 ? "," : "",
			 keep1 ? keep1 : "");
	}
	struct plot_split sp = { src, dst, { "pair", NULL }, { keep0, keep1 }, blocks, labels, n };
	return plot_split_csv(in, &sp);
}

/* pair_collisions.dat: the collision times of each pair that collided
 * (cidx[k]: pair k's block, -1 for none). */
static int plot_write_collisions(const struct plot_input *in, int *cidx)
{
	const struct plot_pair *with[PLOT_MAX_PAIRS];
	int n = 0;
	for (int k = 0; k < in->npairs; k++) {
		cidx[k] = -1;
		if (in->pairs[k].collisions > 0 && n < PLOT_MAX_PAIRS) {
			cidx[k] = n;
			with[n++] = &in->pairs[k];
		}
	}
	return n > 0 ? plot_write_pairs(in, with, n, "collisions.csv", "pair_collisions.dat", "t", NULL) : 0;
}

static int plot_min(int a, int b) { return a < b ? a : b; }

/* Joint colours, dark for lines and pale for the whole run behind them. */
static const char *const plot_dark[] = { "'#1f4e9c'", "'#b3261e'", "'#2e7d32'", "'#6a1b9a'" };
static const char *const plot_pale[] = { "'#a9c1e8'", "'#eeb0aa'", "'#b3dab5'", "'#d1b3e0'" };

static int plot_angles_and_portraits(FILE *f, const struct plot_input *in)
{
	if (in->nrobots == 0)
		return 0;
	int n = plot_min(in->nrobots, PLOT_MAX_PANELS);
	int idx[PLOT_MAX_PANELS][PLOT_MAX_JOINTS];
	if (plot_write_joints(in, n, idx) != 0)
		return -1;
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
			fprintf(f, "%s'joints.dat' index %d using 1:2 with lines lw 1.2 lc rgb %s title 'joint %d'",
				first ? "plot " : ", \\\n  ", idx[i][j], plot_dark[j % 4], j);
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
			fprintf(f, "%s'joints.dat' index %d using 2:3 with lines lw 0.5 lc rgb %s notitle, \\\n"
				   "  '' index %d using ($1 >= %.3f ? $2 : 1/0):3 with lines lw 2 lc rgb %s title 'joint %d'",
				first ? "" : ", \\\n  ", idx[i][j], plot_pale[c], idx[i][j], in->window_start,
				plot_dark[c], j);
			first = false;
		}
		fputc('\n', f);
	}
	fputs("unset multiplot\nset key outside right top\n", f);
	return 0;
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

static int plot_phase_diff(FILE *f, const struct plot_input *in, const int *cidx)
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
		return 0;
	/* phase.dat: each shown pair's t, delta */
	if (plot_write_pairs(in, show, n, "phase_diff.csv", "phase.dat", "t", "delta") != 0)
		return -1;
	char more[64] = "";
	if (with_data > n)
		snprintf(more, sizeof more, " (first %d of %d pairs)", n, with_data);
	plot_terminal(f, 1100, n <= 2 ? 650 : 230 * n);
	fprintf(f, "set output 'phase_diff.png'\nset multiplot layout %d,1 title 'phase difference "
		   "between neighbours, with the compatibility bounds +-2 asin(d~)%s'\n", n, more);
	/* every panel from the log's start (t >= 0), so that the pairs line up */
	fputs("set xlabel 't (s)'\nset ylabel 'delta (rad)'\nset xrange [0:*]\n", f);
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
		fprintf(f, "\nplot 'phase.dat' index %d using 1:($2 <= %.4f ? $2 + 2*pi : $2) with points pt 7 ps 0.3 "
			   "lc rgb '#1f4e9c' title 'delta'", i, cut);
		if (isfinite(p->dsep) && p->dsep < 1) {
			double b = 2 * asin(p->dsep);
			fprintf(f, ", \\\n  %.5f with lines dt 2 lw 1.5 lc rgb '#2e7d32' title 'compatible bound', "
				   "\\\n  %.5f with lines dt 2 lw 1.5 lc rgb '#2e7d32' notitle", b, -b);
		}
		fputs(", \\\n  pi with lines dt 3 lc rgb '#777777' title 'anti-phase'", f);
		int c = cidx[p - in->pairs];
		if (c >= 0) {
			fprintf(f, ", \\\n  'pair_collisions.dat' index %d using 1:(%.4f) with points pt 9 ps 0.7 "
				   "lc rgb '#b3261e' title 'collision'", c, cut + 0.12);
		}
		fputc('\n', f);
	}
	fputs("unset multiplot\nunset arrow\nunset label\nset autoscale xy\nset ytics autofreq\n", f);
	return 0;
}

static int plot_theory_file(const struct plot_input *in, int k, double dsep)
{
	char name[64];
	snprintf(name, sizeof(name), "theory_%d.csv", k);
	FILE *t = outdir_stage_fopen(in->dirfd, name);
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
static void plot_collision_rate(FILE *f, const struct plot_input *in, const int *cidx)
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
			if (cidx[k] < 0)
				continue;
			fprintf(f, "%s'pair_collisions.dat' index %d using (floor($1)):(1) smooth frequency with steps lw 1.5 title ",
				shown++ ? ", \\\n  " : "", cidx[k]);
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

int plot_all(const struct plot_input *all, FILE *msg)
{
	struct plot_input clip = *all;   /* the pairs a collision rate can draw (never more than the analyser has) */
	if (clip.npairs > PLOT_MAX_PAIRS)
		clip.npairs = PLOT_MAX_PAIRS;
	const struct plot_input *in = &clip;
	FILE *f = outdir_stage_fopen(in->dirfd, "plots.gp");
	if (!f) {
		fprintf(msg, "undulate-analyze: %s/plots.gp: %s\n", in->dir, strerror(errno));
		return -1;
	}
	plot_header(f);
	int cidx[PLOT_MAX_PAIRS];
	int rc = plot_write_collisions(in, cidx);
	rc |= plot_angles_and_portraits(f, in);
	rc |= plot_phase_diff(f, in, cidx);
	rc |= plot_return_maps(f, in);
	plot_collision_rate(f, in, cidx);
	if (fclose(f) != 0 || rc != 0) {
		fprintf(msg, "undulate-analyze: cannot write the plot files in %s\n", in->dir);
		return -1;
	}
	return plot_run(in, msg);
}
