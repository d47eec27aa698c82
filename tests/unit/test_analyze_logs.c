/* test_analyze_logs.c — undulate-analyze on synthetic logs with known phases,
 * collisions and return map (tools/analyze/synth.c), and on missing,
 * foreign and truncated logs. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../tools/analyze/analyze.h"
#include "anrun.h"
#include "../../tools/analyze/theory.h"
#include "../../tools/analyze/synth.h"
#include "scratch.h"

/* Largest file the tests read whole (summary.json, return_map.csv). */
#define T_FILE_MAX (1 << 20)

static void path_of(char *out, size_t n, const char *a, const char *b)
{
	snprintf(out, n, "%s/%s%s%s", scratch_dir, a, b ? "/" : "", b ? b : "");
}

static char *slurp(const char *dir, const char *name)
{
	char rel[256];
	snprintf(rel, sizeof(rel), "%s/%s", dir, name);
	return scratch_slurp(rel, T_FILE_MAX);
}

static long count_lines(const char *dir, const char *name)
{
	char p[512];
	path_of(p, sizeof(p), dir, name);
	FILE *f = fopen(p, "r");
	if (!f)
		return -1;
	long n = 0;
	int ch;
	while ((ch = fgetc(f)) != EOF)
		n += ch == '\n';
	fclose(f);
	return n;
}

/* The number after "key": inside the JSON object of pair PAIR. */
static double pair_num(const char *json, const char *pair, const char *key)
{
	char pat[128];
	snprintf(pat, sizeof(pat), "\"pair\":\"%s\"", pair);
	const char *p = strstr(json, pat);
	if (!p)
		return NAN;
	const char *end = strchr(p, '}');
	snprintf(pat, sizeof(pat), "\"%s\":", key);
	const char *k = strstr(p, pat);
	if (!k || k > end)
		return NAN;
	return strtod(k + strlen(pat), NULL);
}

static int pair_has(const char *json, const char *pair, const char *text)
{
	char pat[128];
	snprintf(pat, sizeof(pat), "\"pair\":\"%s\"", pair);
	const char *p = strstr(json, pat);
	if (!p)
		return 0;
	const char *end = strchr(p, '}');
	const char *k = strstr(p, text);
	return k && k < end;
}

static int run(const char *log, const char *out, void (*tweak)(struct an_options *))
{
	static char logp[AN_MAX_LOGS][512], outp[512];
	path_of(logp[0], sizeof(logp[0]), log, NULL);
	path_of(outp, sizeof(outp), out, NULL);
	struct an_options o;
	anrun_options(&o, logp[0], outp);
	if (tweak)
		tweak(&o);
	return an_run(&o);
}

static void write_synth(const char *name, struct synth_spec *s)
{
	char p[512];
	path_of(p, sizeof(p), name, NULL);
	char err[512];
	assert_true(synth_write(s, p, err, sizeof err) > 0);
}

/* The whole pipeline on the default synthetic log: classes, numbers,
 * counts, return map. */
static void test_synthetic_classes(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	write_synth("a.log", &s);
	assert_int_equal(run("a.log", "a", NULL), AN_EXIT_OK);
	char *js = slurp("a", "summary.json");
	assert_non_null(js);
	assert_true(pair_has(js, "r1:r2", "\"class\":\"compatible\""));
	assert_true(pair_has(js, "r2:r3", "\"class\":\"anti-phase\""));
	assert_true(pair_has(js, "r3:r4", "\"class\":\"in-phase\""));
	assert_true(fabs(pair_num(js, "r1:r2", "mean_abs_delta") - SYNTH_COMPAT_DELTA) < 1e-6);
	assert_true(fabs(pair_num(js, "r1:r2", "dsep") - SYNTH_DSEP_12) < 2e-3);
	assert_true(fabs(pair_num(js, "r2:r3", "dsep") - SYNTH_DSEP_23) < 2e-3);
	assert_true(fabs(pair_num(js, "r1:r2", "compat_limit") - 2 * asin(SYNTH_DSEP_12)) < 5e-3);
	assert_true(fabs(pair_num(js, "r2:r3", "mean_abs_delta") - M_PI) < 1e-6);
	assert_int_equal((int)pair_num(js, "r1:r2", "collisions"), 0);
	assert_true(pair_num(js, "r2:r3", "window_collisions") >= 7);
	assert_int_equal((int)pair_num(js, "r3:r4", "collisions"), s.ncoll);
	assert_int_equal((int)pair_num(js, "r3:r4", "window_collisions"), 0);
	/* the final r3:r4 difference is the closed form after ncoll collisions */
	double final = theory_return_map_d0(s.delta0, s.restitution, s.ncoll);
	assert_true(fabs(pair_num(js, "r3:r4", "mean_delta") - final) < 1e-6);
	/* every joint swings 2A in the final window */
	assert_true(fabs(pair_num(js, "r2:r3", "swing_a") - 2 * s.amplitude) < 1e-3);
	assert_true(fabs(pair_num(js, "r3:r4", "swing_b") - 2 * s.amplitude) < 1e-3);
	/* joints of one robot: joint 1 lags by 2 pi / 3 */
	assert_true(fabs(pair_num(js, "r2/0:1", "mean_delta") + 2 * M_PI / 3) < 1e-6);
	free(js);
	/* every joint sample is one row (+ header) */
	long cycles = lround(s.duration_s / s.dt_s) + 1;
	assert_int_equal(count_lines("a", "states.csv"), 1 + SYNTH_ROBOTS * 2 * cycles);
	/* collisions are sent twice (SIM.COLLISION and SIM.TRUTH) and counted once */
	char p[512];
	path_of(p, sizeof(p), "b.log", NULL);
	char err[512];
	int ncoll = synth_write(&s, p, err, sizeof err);
	assert_int_equal(count_lines("a", "collisions.csv"), 1 + ncoll);
	assert_int_equal(count_lines("a", "events.csv"), 1 + SYNTH_ROBOTS);
	assert_int_equal(count_lines("a", "bus.csv"), 1 + SYNTH_ROBOTS * ((long)s.duration_s + 1));
	assert_int_equal(count_lines("a", "params.csv"), 1 + 2 * SYNTH_ROBOTS * ((long)s.duration_s + 1));
	double impulse = 0;
	for (int k = 0; k < ncoll; k++)
		impulse += synth_impulse(k);
	js = slurp("a", "summary.json");
	char *imp = strstr(js, "\"impulse\":");
	assert_non_null(imp);
	assert_true(fabs(strtod(imp + 10, NULL) - impulse) < 1e-9);
	free(js);
}

/* return_map.csv: the r3:r4 points are the d~ = 0 closed form. FIRST: the
 * first collision (from 1) with a phase before it; the n column counts from
 * there. */
static void check_return_map(const char *dir, const struct synth_spec *s, double tol, int first)
{
	char *rm = slurp(dir, "return_map.csv");
	assert_non_null(rm);
	int found = 0;
	for (char *line = strstr(rm, "\"r3:r4\","); line; line = strstr(line + 1, "\"r3:r4\",")) {
		int n;
		long long ut;
		double t, dn, dn1, th;
		assert_int_equal(sscanf(line, "\"r3:r4\",%d,%lld,%lf,%lf,%lf,%lf", &n, &ut, &t, &dn, &dn1, &th), 6);
		int k = n + first - 1;   /* collisions before this one */
		assert_true(fabs(dn - theory_return_map_d0(s->delta0, s->restitution, k)) < tol);
		assert_true(fabs(dn1 - theory_return_map_d0(s->delta0, s->restitution, k + 1)) < tol);
		/* the theory column is the map applied to the measured point */
		assert_true(fabs(th - theory_return_map(dn, 0.0, s->restitution)) < 1e-6);
		assert_true(fabs(t - (k + 1) * s->coll_period_s) < 1e-3);
		found++;
	}
	assert_int_equal(found, s->ncoll - first);
	free(rm);
}

static void test_return_map(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 36.0;
	write_synth("rm.log", &s);
	assert_int_equal(run("rm.log", "rm", NULL), AN_EXIT_OK);
	check_return_map("rm", &s, 1e-6, 1);
}

/* A contact reported as a burst of collisions 1 ms apart is one contact:
 * every collision is listed and counted, the return map is unchanged. */
static void test_bursts(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 36.0;
	s.burst = 5;
	write_synth("burst.log", &s);
	assert_int_equal(run("burst.log", "burst", NULL), AN_EXIT_OK);
	check_return_map("burst", &s, 1e-6, 1);
	char *js = slurp("burst", "summary.json");
	assert_int_equal((int)pair_num(js, "r3:r4", "collisions"), 5 * s.ncoll);
	assert_int_equal((int)pair_num(js, "r3:r4", "contacts"), s.ncoll);
	free(js);
}

static void use_zero_crossings(struct an_options *o)
{
	o->zero_crossings = true;
}

/* Without the daemon's frequency, phases come from the analyser's own
 * estimate (common/phase.h), known from a joint's fourth upward crossing,
 * 4.8 to 6 s into the log at 0.8 Hz (by the joint's starting phase): the
 * first collision, at 4 s, has no phase difference, the map starts at the
 * second. */
static void test_zero_crossings(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 36.0;
	s.report_frequency = false;
	write_synth("zc.log", &s);
	assert_int_equal(run("zc.log", "zc", use_zero_crossings), AN_EXIT_OK);
	check_return_map("zc", &s, 5e-3, 2);
	char *js = slurp("zc", "summary.json");
	assert_true(pair_has(js, "r1:r2", "\"class\":\"compatible\""));
	free(js);
}

static void pairs_and_range(struct an_options *o)
{
	o->pairs = "r1:r3";
	o->from_s = 10.0;
	o->to_s = 20.0;
	o->separation = 0.9;
}

static void test_pairs_and_range(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 25.0;
	write_synth("pr.log", &s);
	assert_int_equal(run("pr.log", "pr", pairs_and_range), AN_EXIT_OK);
	char *js = slurp("pr", "summary.json");
	assert_true(pair_has(js, "r1:r3", "\"kind\":\"user\""));
	assert_null(strstr(js, "\"pair\":\"r1:r2\""));
	/* r3 - r1 = 0.4 + pi -> |delta| = pi - 0.4 */
	assert_true(fabs(pair_num(js, "r1:r3", "mean_abs_delta") - (M_PI - 0.4)) < 1e-6);
	assert_true(fabs(pair_num(js, "r1:r3", "dsep") - 0.9) < 1e-12);
	free(js);
	char *st = slurp("pr", "states.csv");
	char *row = strchr(st, '\n') + 1;
	long long ut;
	double t;
	assert_int_equal(sscanf(row, "%lld,%lf", &ut, &t), 2);
	assert_true(t >= 9.99 && t <= 10.02);
	free(st);
	assert_true(count_lines("pr", "states.csv") < 1 + 8 * 1002);
}

/* --synth-stop-after: r3 and r4 stand still; the pairs with a stopped robot
 * are not oscillating (r3:r4 would otherwise pass for in-phase), r1:r2 is
 * untouched, and the swings say why. */
static void test_synth_stop(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 25.0;
	s.stop_after_s = 12.0;
	write_synth("stop.log", &s);
	assert_int_equal(run("stop.log", "stop", NULL), AN_EXIT_OK);
	char *js = slurp("stop", "summary.json");
	assert_non_null(js);
	assert_true(pair_has(js, "r1:r2", "\"class\":\"compatible\""));
	assert_true(pair_has(js, "r2:r3", "\"class\":\"not-oscillating\""));
	assert_true(pair_has(js, "r3:r4", "\"class\":\"not-oscillating\""));
	double pp = 2 * s.amplitude;
	assert_true(fabs(pair_num(js, "r1:r2", "swing_a") - pp) < 1e-3);
	assert_true(fabs(pair_num(js, "r2:r3", "swing_a") - pp) < 1e-3);
	assert_true(pair_num(js, "r2:r3", "swing_b") < 1e-9);
	assert_true(pair_num(js, "r3:r4", "swing_a") < 1e-9 && pair_num(js, "r3:r4", "swing_b") < 1e-9);
	assert_true(pair_num(js, "r3/0:1", "swing_b") < 1e-9);
	/* no contact with a robot at rest after the stop */
	assert_int_equal((int)pair_num(js, "r2:r3", "window_collisions"), 0);
	free(js);
}

static void test_missing_and_foreign(void **state)
{
	(void)state;
	assert_int_equal(run("nonexistent.log", "m", NULL), AN_EXIT_BADLOG);
	char p[512];
	path_of(p, sizeof(p), "foreign.log", NULL);
	FILE *f = fopen(p, "w");
	fputs("utime,robot,angle\n1,r1,0.5\n", f);
	fclose(f);
	assert_int_equal(run("foreign.log", "f", NULL), AN_EXIT_BADLOG);
	assert_int_equal(count_lines("f", "states.csv"), -1); /* nothing written */
	path_of(p, sizeof(p), "empty.log", NULL);
	f = fopen(p, "w");
	fclose(f);
	assert_int_equal(run("empty.log", "e", NULL), AN_EXIT_BADLOG);
}

/* A log cut in the middle of an event yields every event before the cut. */
/* A length that cuts the log inside the event that spans its middle (an
 * arbitrary byte count may fall on an event's end, and then nothing is cut). */
static off_t mid_event_cut(const char *path)
{
	FILE *f = fopen(path, "rb");
	assert_non_null(f);
	struct stat st;
	assert_int_equal(fstat(fileno(f), &st), 0);
	off_t pos = 0;
	for (;;) {
		uint8_t h[28];
		assert_int_equal(fseeko(f, pos, SEEK_SET), 0);
		assert_int_equal(fread(h, 1, sizeof h, f), sizeof h);
		uint32_t clen = (uint32_t)h[20] << 24 | (uint32_t)h[21] << 16 | (uint32_t)h[22] << 8 | h[23];
		uint32_t dlen = (uint32_t)h[24] << 24 | (uint32_t)h[25] << 16 | (uint32_t)h[26] << 8 | h[27];
		off_t end = pos + 28 + (off_t)clen + (off_t)dlen;
		assert_true(end <= st.st_size);
		if (end > st.st_size / 2) {
			fclose(f);
			return pos + 28 + (off_t)clen + (off_t)dlen / 2;
		}
		pos = end;
	}
}

static void test_truncated(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 10.0;
	write_synth("full.log", &s);
	char src[512], dst[512];
	path_of(src, sizeof(src), "full.log", NULL);
	path_of(dst, sizeof(dst), "cut.log", NULL);
	assert_int_equal(truncate(src, mid_event_cut(src)), 0);
	assert_int_equal(rename(src, dst), 0);
	assert_int_equal(run("cut.log", "cut", NULL), AN_EXIT_TRUNCATED);
	long rows = count_lines("cut", "states.csv");
	long full = 1 + SYNTH_ROBOTS * 2 * (lround(s.duration_s / s.dt_s) + 1);
	assert_true(rows > full / 2 - 100 && rows < full);
	char *txt = slurp("cut", "summary.txt");
	assert_non_null(strstr(txt, "truncated or damaged at byte"));
	free(txt);
	char *js = slurp("cut", "summary.json");
	assert_non_null(strstr(js, "\"truncated\":true"));
	free(js);
}

/* A log path is text from outside: summary.json escapes it (quote, newline,
 * a byte that is not UTF-8) and stays valid JSON. */
static void test_json_path_escaped(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 2.0;
	write_synth("we\"ird\n\xff.log", &s);
	assert_int_equal(run("we\"ird\n\xff.log", "esc", NULL), AN_EXIT_OK);
	char *js = slurp("esc", "summary.json");
	assert_non_null(js);
	assert_non_null(strstr(js, "/we\\\"ird\\u000a\\ufffd.log\",\"events\":"));
	assert_int_equal(strchr(js, '\n') - js, (long)strlen(js) - 1); /* one line */
	free(js);
}

/* Garbage in the middle: everything before it is used, and it is reported. */
static void test_damaged_middle(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 5.0;
	write_synth("dm.log", &s);
	char p[512];
	path_of(p, sizeof(p), "dm.log", NULL);
	/* The format has no checksum: damage is seen where it breaks an
	 * event's framing, so overwrite the sync word of an event mid-file. */
	FILE *f = fopen(p, "r+b");
	unsigned char buf[4096];
	assert_int_equal(fseek(f, 100000, SEEK_SET), 0);
	size_t n = fread(buf, 1, sizeof(buf), f);
	size_t at = 0;
	while (at + 4 <= n && memcmp(buf + at, "\xed\xa1\xda\x01", 4) != 0)
		at++;
	assert_true(at + 4 <= n);
	assert_int_equal(fseek(f, 100000 + (long)at, SEEK_SET), 0);
	fwrite("\xde\xad\xbe\xef", 1, 4, f);
	fclose(f);
	assert_int_equal(run("dm.log", "dm", NULL), AN_EXIT_TRUNCATED);
	long rows = count_lines("dm", "states.csv");
	assert_true(rows > 100 && rows < 1 + SYNTH_ROBOTS * 2 * 501);
}

static void want_plots(struct an_options *o)
{
	o->plots = true;
}

static int is_png(const char *dir, const char *name)
{
	char p[512];
	path_of(p, sizeof(p), dir, name);
	FILE *f = fopen(p, "rb");
	if (!f)
		return 0;
	unsigned char sig[8] = { 0 };
	size_t n = fread(sig, 1, 8, f);
	fseek(f, 0, SEEK_END);
	long size = ftell(f);
	fclose(f);
	return n == 8 && memcmp(sig, "\x89PNG\r\n\x1a\n", 8) == 0 && size > 1000;
}

static void test_plots(void **state)
{
	(void)state;
	if (system("command -v gnuplot >/dev/null 2>&1") != 0)
		skip();
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 20.0;
	s.ncoll = 4;
	write_synth("pl.log", &s);
	assert_int_equal(run("pl.log", "pl", want_plots), AN_EXIT_OK);
	assert_true(is_png("pl", "angles.png"));
	assert_true(is_png("pl", "portraits.png"));
	assert_true(is_png("pl", "phase_diff.png"));
	assert_true(is_png("pl", "collision_rate.png"));
	assert_true(is_png("pl", "return_map_2.png")); /* r3:r4, the third neighbour pair */
	assert_true(is_png("pl", "return_map_1.png")); /* r2:r3 */
	assert_false(is_png("pl", "return_map_0.png")); /* r1:r2 never touch */
}

/* One row of plane.csv: utime,t,robot,robot_index,link,x,y,angle,length,
 * width,centre_x,centre_y,heading. */
struct plane_row {
	double t, x, y, angle, length, cx, cy, heading;
	int robot, index, link;
};

static int plane_row_parse(const char *line, struct plane_row *r)
{
	long long utime;
	double width;
	return sscanf(line, "%lld,%lf,\"r%d\",%d,%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &utime, &r->t, &r->robot,
		      &r->index, &r->link, &r->x, &r->y, &r->angle, &r->length, &width, &r->cx, &r->cy,
		      &r->heading) == 13;
}

/* Every row of DIR/plane.csv against the synthetic plane (synth_plane_links):
 * the link's pose as logged, its robot's centre the mean of its links' centres
 * (the neutral position, moving along +y), its heading +y; samples EVERY s
 * apart. Returns the rows checked. */
static long check_plane_csv(const char *dir, const struct synth_spec *s, double every)
{
	char p[512], line[512];
	path_of(p, sizeof(p), dir, "plane.csv");
	FILE *f = fopen(p, "r");
	assert_non_null(f);
	assert_non_null(fgets(line, sizeof line, f));
	assert_string_equal(line, "utime,t,robot,robot_index,link,x,y,angle,length,width,centre_x,centre_y,heading\n");
	long n = 0;
	double last_t = -1.0;
	while (fgets(line, sizeof line, f)) {
		struct plane_row r;
		assert_true(plane_row_parse(line, &r));
		assert_true(r.robot >= 1 && r.robot <= SYNTH_ROBOTS && r.link >= 0 && r.link < SYNTH_LINKS);
		double x[SYNTH_LINKS], y[SYNTH_LINKS], a[SYNTH_LINKS], mx = 0.0, my = 0.0;
		synth_plane_links(s, r.robot - 1, r.t, x, y, a);
		assert_float_equal(r.x, x[r.link], 1e-6);
		assert_float_equal(r.y, y[r.link], 1e-6);
		assert_float_equal(r.angle, a[r.link], 1e-6);
		assert_float_equal(r.length, SYNTH_LINK_M, 1e-9);
		for (int k = 0; k < SYNTH_LINKS; k++) {
			mx += x[k] / SYNTH_LINKS;
			my += y[k] / SYNTH_LINKS;
		}
		assert_float_equal(r.cx, mx, 1e-6);
		assert_float_equal(r.cy, my, 1e-6);
		assert_float_equal(r.cy, SYNTH_PLANE_SPEED * r.t, 1e-6);
		assert_float_equal(r.heading, M_PI / 2.0, 1e-6);
		if (r.t > last_t + 1e-9) {
			/* a new sample: EVERY after the last (the log's 10 ms steps) */
			if (last_t >= 0)
				assert_float_equal(r.t - last_t, every, 0.011);
			last_t = r.t;
		}
		n++;
	}
	fclose(f);
	return n;
}

static void plane_every_half(struct an_options *o)
{
	o->plane_every_s = 0.5;
}

/* The plane world's SIM.TRUTH: plane.csv holds every link of every robot at
 * the default 0.1 s (--plane-every), with its robot's centre and heading;
 * plane_walls.csv the walls; a row world's log has neither file. */
static void test_plane_csv(void **state)
{
	(void)state;
	struct synth_spec s;
	synth_default(&s);
	s.duration_s = 10.0;
	s.ncoll = 2;
	s.plane = true;
	write_synth("plane.log", &s);
	assert_int_equal(run("plane.log", "plane", NULL), AN_EXIT_OK);
	/* 0, 0.1, ..., 10 s: 101 samples of 4 robots' 3 links, 2 walls */
	assert_int_equal(check_plane_csv("plane", &s, 0.1), 101 * SYNTH_ROBOTS * SYNTH_LINKS);
	assert_int_equal(count_lines("plane", "plane_walls.csv"), 1 + 101 * 2);
	char *w = slurp("plane", "plane_walls.csv");
	assert_non_null(w);
	assert_non_null(strstr(w, "utime,t,wall,ax,ay,bx,by\n"));
	assert_non_null(strstr(w, ",0,-1,-1,-1,1\n"));
	assert_non_null(strstr(w, ",1,1,-1,1,1\n"));
	free(w);
	/* the analysis otherwise as a row run's */
	char *json = slurp("plane", "summary.json");
	assert_non_null(json);
	assert_string_equal(pair_has(json, "r1:r2", "\"class\":\"compatible\"") ? "compatible" : "other", "compatible");
	free(json);
	assert_int_equal(run("plane.log", "half", plane_every_half), AN_EXIT_OK);
	assert_int_equal(check_plane_csv("half", &s, 0.5), 21 * SYNTH_ROBOTS * SYNTH_LINKS);
	s.plane = false;
	write_synth("row.log", &s);
	assert_int_equal(run("row.log", "row", NULL), AN_EXIT_OK);
	assert_int_equal(count_lines("row", "plane.csv"), -1);
	assert_int_equal(count_lines("row", "plane_walls.csv"), -1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_synthetic_classes),
		cmocka_unit_test(test_return_map),
		cmocka_unit_test(test_zero_crossings),
		cmocka_unit_test(test_bursts),
		cmocka_unit_test(test_pairs_and_range),
		cmocka_unit_test(test_synth_stop),
		cmocka_unit_test(test_missing_and_foreign),
		cmocka_unit_test(test_truncated),
		cmocka_unit_test(test_json_path_escaped),
		cmocka_unit_test(test_damaged_middle),
		cmocka_unit_test(test_plots),
		cmocka_unit_test(test_plane_csv),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
