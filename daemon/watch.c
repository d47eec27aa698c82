/*
 * watch.c — `undulated --watch ROBOT`: what a robot publishes, for terminals
 * and scripts without lcm-spy.
 *
 * In words (the default), for a person: at most --rate states a second per
 * robot (and at once when the mode or the fault changes), each a line with
 * the mode by name and one line a joint, named values with their units;
 * every event; the bus statistics (published once a second); the
 * parameters when they change:
 *   r1 18:55:01.25 OSCILLATOR (start), cycle 1234: period 10.0 ms, 0.9 ms late, bus 1.8 ms
 *     joint 1 (servo 1): angle +0.338 rad, speed -0.030 rad/s, goal +0.333 rad, amplitude 0.80 rad at 0.79 Hz, ...
 *   r1 event (warning, fault): servo 2 silent for 0.50 s
 *
 * --raw, for scripts (the tests parse it): every message, one key=value line:
 *   STATE <robot> cycle=N mode=M reason="..." period=us jitter=us bus=us overruns=N
 *         bus_errors=N bad_commands=N a0= s0= g0= amp0= f0= ph0= ld0= e0= st0= tq0= ...
 *   EVENT <robot> seq=N level=L kind=K text="..."
 *   BUS <robot> connected=B reconnects=N p50= p99= max= jitter99= bus99= cpu= overruns=N
 *       ... idJ=ID/replies/timeouts/rtt_mean/rtt_max ... badJ=checksum/wrong_id/wrong_length
 *   PARAMS <robot> k0= c0= mu0= lambda0= ... amplitude= frequency= phase=
 * Angles in rad relative to neutral, speeds rad/s. A message that does not
 * decode (anyone on the group can send one) is skipped and said on stderr,
 * the first WATCH_BAD_SAID, then every WATCH_BAD_EVERY-th, with the count.
 */
#include <inttypes.h>
#include <lcm/lcm.h>
#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "compat/lcm/lcmdec.h"
#include "daemon.h"
#include "dxl.h"
#include "dxl2_table.h"
#include "modes.h"
#include "params.h"
#include "text.h"

/* Silence after which --watch says it hears nobody (seconds). */
#define WATCH_QUIET_S 3.0
/* Robots told apart for the rate and the parameters' changes: with more
 * on one group, the longest unheard one's slot is taken over. */
#define WATCH_ROBOTS_MAX 64

/* What --watch remembers of one robot, in words: when its last state was
 * shown, in what mode and fault, and the parameters last shown. */
struct watch_robot {
	char name[64];
	double heard_s;     /* watcher's monotonic clock */
	double shown_s;     /* -1: none shown yet */
	int mode;
	char fault[160];
	bool have_params;
	uint64_t params_sum;
};

struct watch {
	bool raw;
	double every_s;     /* 0: every state */
	struct watch_robot robots[WATCH_ROBOTS_MAX];
	int nrobots;
};

static volatile sig_atomic_t watch_stop;
static unsigned long watch_heard; /* messages printed: none at the end is a failure */
static unsigned long watch_bad;   /* messages that did not decode */
#define WATCH_BAD_SAID 5
#define WATCH_BAD_EVERY 1000
static void watch_on_signal(int sig) { (void)sig; watch_stop = 1; }

static void watch_state_raw(const undulate_robot_state_t *m)
{
	/* whatever is on the network may say anything: one printable line each */
	char robot[64], reason[128], fault[160];
	printf("STATE %s cycle=%" PRId64 " mode=%d reason=\"%s\" fault=\"%s\" period=%.0f jitter=%.0f bus=%.0f "
	       "control=%.0f overruns=%" PRId64 " bus_errors=%" PRId64 " bad_commands=%" PRId64,
	       text_line(robot, sizeof robot, m->robot), m->cycle, m->mode,
	       text_line(reason, sizeof reason, m->mode_reason), text_line(fault, sizeof fault, m->fault),
	       m->period_us, m->jitter_us, m->bus_us, m->control_us, m->overruns, m->bus_errors, m->bad_commands);
	for (int j = 0; j < m->njoints; j++) {
		const undulate_joint_state_t *s = &m->joints[j];
		printf(" a%d=%.4f s%d=%.4f g%d=%.4f amp%d=%.4f f%d=%.4f ph%d=%.3f ld%d=%.3f e%d=%d st%d=%d tq%d=%d "
		       "tr%d=%d tl%d=%d v%d=%.1f T%d=%.0f dr%d=%.4f", j, s->angle, j, s->speed, j, s->goal, j, s->amplitude, j,
		       s->frequency, j, s->phase, j, s->load, j, s->error_bits, j, s->stale_cycles, j, s->torque, j,
		       s->torque_read, j, s->torque_limit, j, s->voltage, j, s->temperature, j, s->drive);
	}
	printf("\n");
}

static void watch_event_raw(const undulate_event_t *m)
{
	char robot[64], kind[48], text[600];
	printf("EVENT %s seq=%" PRId64 " level=%d kind=%s text=\"%s\"\n", text_line(robot, sizeof robot, m->robot),
	       m->seq, m->level, text_line(kind, sizeof kind, m->kind), text_line(text, sizeof text, m->text));
}

/* The bus of a robot on several (its "<robot>.BUS.<bus>" channel): "" for
 * the robot's own message. Set per message by watch_on_lcm. */
static char watch_bus_name[48];

static void watch_bus_raw(const undulate_bus_stats_t *m)
{
	char robot[64], port[96];
	/* one bus of several: "BUS robot/bus port=..." (scripts that read the
	 * robot's "BUS robot " lines do not take it for the robot's) */
	if (watch_bus_name[0] != '\0')
		printf("BUS %s/%s port=%s", text_line(robot, sizeof robot, m->robot), watch_bus_name,
		       text_line(port, sizeof port, m->port));
	else
		printf("BUS %s", text_line(robot, sizeof robot, m->robot));
	printf(" connected=%d reconnects=%" PRId64 " p50=%.0f p99=%.0f max=%.0f jitter99=%.0f bus99=%.0f "
	       "cpu=%.2f overruns=%" PRId64 " stray=%" PRId64 " io_errors=%" PRId64, m->connected,
	       m->reconnects, m->period_p50_us, m->period_p99_us, m->period_max_us, m->jitter_p99_us,
	       m->bus_p99_us, m->cpu_percent, m->overruns, m->stray_packets, m->io_errors);
	for (int j = 0; j < m->nservos; j++)
		printf(" id%d=%d/%" PRId64 "/%" PRId64 "/%.0f/%.0f", j, m->servos[j].servo_id, m->servos[j].replies,
		       m->servos[j].timeouts, m->servos[j].rtt_mean_us, m->servos[j].rtt_max_us);
	/* what the bus refused of each servo's replies: checksum, wrong ID, wrong length */
	for (int j = 0; j < m->nservos; j++)
		printf(" bad%d=%" PRId64 "/%" PRId64 "/%" PRId64, j, m->servos[j].checksum_errors, m->servos[j].wrong_id,
		       m->servos[j].wrong_length);
	printf("\n");
}

static void watch_params_raw(const undulate_osc_params_t *m)
{
	char robot[64];
	printf("PARAMS %s", text_line(robot, sizeof robot, m->robot));
	for (int j = 0; j < m->njoints; j++)
		printf(" k%d=%g c%d=%g mu%d=%g lambda%d=%g inertia%d=%g friction%d=%g neutral%d=%g min%d=%g max%d=%g",
		       j, m->k[j], j, m->c[j], j, m->mu[j], j, m->lambda[j], j, m->inertia[j], j, m->friction[j], j,
		       m->neutral[j], j, m->limit_min[j], j, m->limit_max[j]);
	printf(" amplitude=%g frequency=%g phase=%g\n", m->amplitude, m->frequency, m->phase);
}


/* ---- in words ------------------------------------------------------------ */

static double watch_now_s(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The robot's slot (name already made one printable line); a new robot takes
 * a free slot or the one heard longest ago. */
static struct watch_robot *watch_robot_of(struct watch *w, const char *name, double now)
{
	int oldest = 0;
	for (int i = 0; i < w->nrobots; i++) {
		if (strcmp(w->robots[i].name, name) == 0) {
			w->robots[i].heard_s = now;
			return &w->robots[i];
		}
		if (w->robots[i].heard_s < w->robots[oldest].heard_s)
			oldest = i;
	}
	int k = w->nrobots < WATCH_ROBOTS_MAX ? w->nrobots++ : oldest;
	struct watch_robot *r = &w->robots[k];
	memset(r, 0, sizeof *r);
	snprintf(r->name, sizeof r->name, "%s", name);
	r->heard_s = now;
	r->shown_s = -1;
	r->mode = -1;
	return r;
}

/* A signed value with its unit, or "unknown" for NaN (a goal in torque
 * actuation, a phase not known yet). */
static const char *watch_signed(char *buf, size_t cap, double v, int decimals, const char *unit)
{
	if (isfinite(v))
		snprintf(buf, cap, "%+.*f %s", decimals, v, unit);
	else
		snprintf(buf, cap, "unknown");
	return buf;
}

/* "18:55:01.25", local time of the cycle's start as the robot stamped it. */
static const char *watch_clock(char *buf, size_t cap, int64_t utime)
{
	time_t sec = (time_t)(utime / 1000000);
	struct tm tm;
	if (utime <= 0 || localtime_r(&sec, &tm) == NULL) {
		snprintf(buf, cap, "--:--:--.--");
		return buf;
	}
	snprintf(buf, cap, "%02d:%02d:%02d.%02d", tm.tm_hour, tm.tm_min, tm.tm_sec, (int)(utime % 1000000 / 10000));
	return buf;
}

static void watch_joint_words(const undulate_joint_state_t *s, int j)
{
	char angle[32], speed[32], goal[32], errs[160];
	printf("  joint %d (servo %d): angle %s, speed %s", j + 1, s->servo_id,
	       watch_signed(angle, sizeof angle, s->angle, 3, "rad"),
	       watch_signed(speed, sizeof speed, s->speed, 3, "rad/s"));
	if (isfinite(s->drive))   /* torque actuation: the drive, not a goal */
		printf(", drive %+.0f %%", 100.0 * s->drive);
	else
		printf(", goal %s", watch_signed(goal, sizeof goal, s->goal, 3, "rad"));
	printf(", amplitude %.2f rad at %.2f Hz, load %+.0f %%, torque %s", s->amplitude, s->frequency,
	       100.0 * s->load, s->torque_read < 0 ? (s->torque ? "on (not read back yet)" : "off (not read back yet)")
	       : (s->torque_read == 1) == s->torque ? (s->torque ? "on" : "off")
	       : (s->torque ? "off (wanted on)" : "on (wanted off)"));
	printf(", %.1f V, %.0f C", s->voltage, s->temperature);
	if (s->stale_cycles > 0)
		printf(", SILENT for %d cycles", (int)s->stale_cycles);
	uint8_t low = (uint8_t)(s->error_bits & 0x7F);
	if (low != 0) {
		if (s->error_bits & UNDULATE_JOINT_STATE_T_ERROR_BITS_X)
			dxl2_hwerr_format(low, errs, sizeof errs);
		else
			dxl_errbits_format(low, errs, sizeof errs);
		printf(", ERROR %s", errs);
	}
	printf("\n");
}

/* Whether this state is one to show: --rate's interval since the robot's
 * last one shown, or a change of its mode or fault (shown at once). */
static bool watch_due(struct watch *w, const undulate_robot_state_t *m)
{
	if (w->every_s <= 0)
		return true;
	char robot[64], fault[160];
	text_line(robot, sizeof robot, m->robot);
	text_line(fault, sizeof fault, m->fault);
	double now = watch_now_s();
	struct watch_robot *r = watch_robot_of(w, robot, now);
	bool changed = r->mode != m->mode || strcmp(r->fault, fault) != 0;
	if (!changed && r->shown_s >= 0 && now - r->shown_s < w->every_s)
		return false;
	/* on the rate's grid, so that one late message does not delay the next ones */
	r->shown_s = r->shown_s >= 0 && now - r->shown_s < 2.0 * w->every_s ? r->shown_s + w->every_s : now;
	r->mode = m->mode;
	snprintf(r->fault, sizeof r->fault, "%s", fault);
	return true;
}

static void watch_state_words(const undulate_robot_state_t *m)
{
	char robot[64], reason[128], fault[160], when[24];
	text_line(robot, sizeof robot, m->robot);
	text_line(fault, sizeof fault, m->fault);
	printf("%s %s %s (%s), cycle %" PRId64 ": period %.1f ms, %.1f ms late, bus %.1f ms", robot,
	       watch_clock(when, sizeof when, m->utime), mode_name(m->mode),
	       text_line(reason, sizeof reason, m->mode_reason), m->cycle, 1e-3 * m->period_us, 1e-3 * m->jitter_us,
	       1e-3 * m->bus_us);
	if (m->overruns > 0)
		printf(", %" PRId64 " overruns", m->overruns);
	if (m->bus_errors > 0)
		printf(", %" PRId64 " bus errors", m->bus_errors);
	if (m->bad_commands > 0)
		printf(", %" PRId64 " commands refused", m->bad_commands);
	if (fault[0])
		printf("; FAULT: %s", fault);
	printf("\n");
	for (int j = 0; j < m->njoints; j++)
		watch_joint_words(&m->joints[j], j);
}

static void watch_event_words(const undulate_event_t *m)
{
	static const char *const levels[] = { "info", "warning", "error" };
	char robot[64], kind[48], text[600];
	printf("%s event (%s, %s): %s\n", text_line(robot, sizeof robot, m->robot),
	       m->level >= 0 && m->level <= 2 ? levels[m->level] : "level ?", text_line(kind, sizeof kind, m->kind),
	       text_line(text, sizeof text, m->text));
}

static void watch_bus_words(const undulate_bus_stats_t *m)
{
	char robot[64];
	if (watch_bus_name[0] != '\0') {
		printf("%s bus %s: %s, bus p99 %.2f ms", text_line(robot, sizeof robot, m->robot), watch_bus_name,
		       m->connected ? "connected" : "DISCONNECTED", 1e-3 * m->bus_p99_us);
	} else {
		printf("%s bus: %s, period median %.2f ms (p99 %.2f, max %.2f), late p99 %.2f ms, bus p99 %.2f ms, cpu %.1f %%",
		       text_line(robot, sizeof robot, m->robot), m->connected ? "connected" : "DISCONNECTED",
		       1e-3 * m->period_p50_us, 1e-3 * m->period_p99_us, 1e-3 * m->period_max_us, 1e-3 * m->jitter_p99_us,
		       1e-3 * m->bus_p99_us, m->cpu_percent);
	}
	if (m->reconnects > 0)
		printf(", %" PRId64 " reconnects", m->reconnects);
	if (m->overruns > 0)
		printf(", %" PRId64 " overruns", m->overruns);
	for (int j = 0; j < m->nservos; j++) {
		const undulate_servo_stats_t *v = &m->servos[j];
		printf("; servo %d: %" PRId64 " replies, %" PRId64 " timeouts, round trip %.2f ms (max %.2f)", v->servo_id,
		       v->replies, v->timeouts, 1e-3 * v->rtt_mean_us, 1e-3 * v->rtt_max_us);
		int64_t bad = v->checksum_errors + v->wrong_id + v->wrong_length;
		if (bad > 0)
			printf(", %" PRId64 " bad replies", bad);
	}
	printf("\n");
}

/* FNV-1a over the values: a robot republishes its parameters every second,
 * and the words show them again only when one changed. */
static uint64_t watch_sum(uint64_t h, const double *v, int n)
{
	const unsigned char *b = (const unsigned char *)v;
	for (size_t i = 0; i < (size_t)n * sizeof *v; i++)
		h = (h ^ b[i]) * 1099511628211u;
	return h;
}

static const char *watch_unit(const char *key)
{
	const struct param_def *d = param_find(key);
	return d != NULL ? d->unit : "";
}

static void watch_params_words(struct watch *w, const undulate_osc_params_t *m)
{
	char robot[64];
	text_line(robot, sizeof robot, m->robot);
	struct watch_robot *r = watch_robot_of(w, robot, watch_now_s());
	uint64_t h = 14695981039346656037u;
	const double *per_joint[] = { m->k, m->c, m->mu, m->lambda, m->inertia, m->friction, m->neutral,
	                              m->limit_min, m->limit_max };
	for (size_t i = 0; i < sizeof per_joint / sizeof per_joint[0]; i++)
		h = watch_sum(h, per_joint[i], m->njoints);
	const double robot_wide[] = { m->amplitude, m->frequency, m->phase };
	h = watch_sum(h, robot_wide, 3);
	if (r->have_params && r->params_sum == h)
		return;
	r->have_params = true;
	r->params_sum = h;
	printf("%s parameters:", robot);
	for (int j = 0; j < m->njoints; j++)
		printf(" joint %d k %g %s, c %g %s, mu %g %s, lambda %g, inertia %g %s, friction %g %s, "
		       "neutral %+.3f rad, limits %+.3f..%+.3f rad;", j + 1, m->k[j], watch_unit("k"), m->c[j],
		       watch_unit("c"), m->mu[j], watch_unit("mu"), m->lambda[j], m->inertia[j], watch_unit("inertia"),
		       m->friction[j], watch_unit("friction"), m->neutral[j], m->limit_min[j], m->limit_max[j]);
	printf(" sinusoid amplitude %g rad, frequency %g Hz, phase %g rad\n", m->amplitude, m->frequency, m->phase);
}

union watch_msg {
	undulate_robot_state_t state;
	undulate_event_t event;
	undulate_bus_stats_t bus;
	undulate_osc_params_t params;
};

static void watch_show(struct watch *w, int kind, const union watch_msg *m)
{
	watch_heard++;
	if (w->raw) {
		switch (kind) {
		case 0:
			if (watch_due(w, &m->state))
				watch_state_raw(&m->state);
			break;
		case 1: watch_event_raw(&m->event); break;
		case 2: watch_bus_raw(&m->bus); break;
		default: watch_params_raw(&m->params); break;
		}
		return;
	}
	switch (kind) {
	case 0:
		if (watch_due(w, &m->state))
			watch_state_words(&m->state);
		break;
	case 1: watch_event_words(&m->event); break;
	case 2: watch_bus_words(&m->bus); break;
	default: watch_params_words(w, &m->params); break;
	}
}
/* Subscribed by channel suffix: the suffix names the type. */
static void watch_on_lcm(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
	struct watch *w = u;
	static const struct { const char *suffix; const struct lcmdec_type *type; } kinds[] = {
		{ ".STATE", &lcmdec_robot_state_t }, { ".EVENT", &lcmdec_event_t },
		{ ".BUS", &lcmdec_bus_stats_t },     { ".PARAMS", &lcmdec_osc_params_t },
	};
	size_t n = strlen(ch), k = 0;
	while (k < sizeof kinds / sizeof kinds[0] &&
	       (n < strlen(kinds[k].suffix) || strcmp(ch + n - strlen(kinds[k].suffix), kinds[k].suffix) != 0))
		k++;
	/* "<robot>.BUS.<bus>": one bus of a robot on several */
	const char *busch = strstr(ch, ".BUS.");
	watch_bus_name[0] = '\0';
	if (k == sizeof kinds / sizeof kinds[0] && busch != NULL) {
		k = 2;
		text_line(watch_bus_name, sizeof watch_bus_name, busch + 5);
	}
	if (k == sizeof kinds / sizeof kinds[0])
		return;
	union watch_msg m;
	enum lcmdec_status st = lcmdec_decode(kinds[k].type, rb->data, rb->data_size, &m);
	if (st != LCMDEC_OK) {
		if (++watch_bad <= WATCH_BAD_SAID || watch_bad % WATCH_BAD_EVERY == 0) {
			char why[160], shown[64];
			fprintf(stderr, "undulated --watch: message on %s skipped: %s (%lu so far)\n",
			        text_line(shown, sizeof shown, ch),
			        lcmdec_describe(why, sizeof why, kinds[k].type, rb->data_size, st), watch_bad);
		}
		return;
	}
	watch_show(w, (int)k, &m);
	lcmdec_free(kinds[k].type, &m);
}

int dmn_watch(const struct watch_opts *o)
{
	const char *lcm_url = o->lcm_url, *robot = o->robot;
	double duration_s = o->duration_s;
	static struct watch w;   /* 64 robots' names and faults: off the stack */
	memset(&w, 0, sizeof w);
	w.raw = o->raw;
	w.every_s = o->rate_hz > 0 ? 1.0 / o->rate_hz : 0.0;
	lcm_t *lcm = lcm_create(lcm_url && lcm_url[0] ? lcm_url : NULL);
	if (lcm == NULL) {
		fprintf(stderr, "undulated --watch: cannot create LCM (url %s)\n", lcm_url ? lcm_url : "default");
		return 2;
	}
	char ch[5][96];
	const char *r = strcmp(robot, "*") == 0 ? "[^.]*" : robot;
	snprintf(ch[0], sizeof ch[0], "%s\\.STATE", r);
	snprintf(ch[1], sizeof ch[1], "%s\\.EVENT", r);
	snprintf(ch[2], sizeof ch[2], "%s\\.BUS", r);
	snprintf(ch[3], sizeof ch[3], "%s\\.PARAMS", r);
	snprintf(ch[4], sizeof ch[4], "%s\\.BUS\\.[^.]*", r);   /* a robot on several buses: each one's */
	for (int i = 0; i < 5; i++)
		lcm_subscribe(lcm, ch[i], watch_on_lcm, &w);
	signal(SIGINT, watch_on_signal);
	signal(SIGTERM, watch_on_signal);
	setvbuf(stdout, NULL, _IOLBF, 0);
	const char *url = lcm_url && lcm_url[0] ? lcm_url : "LCM's default URL";
	struct timespec t0, t;
	double waited = 0;
	bool told = false;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	while (!watch_stop) {
		lcm_handle_timeout(lcm, 100);
		clock_gettime(CLOCK_MONOTONIC, &t);
		waited = (double)(t.tv_sec - t0.tv_sec) + 1e-9 * (double)(t.tv_nsec - t0.tv_nsec);
		/* A robot publishes its state at 100 Hz: seconds of silence mean a
		 * wrong name or URL, or no daemon. Say so once, keep listening. */
		if (!told && watch_heard == 0 && waited >= WATCH_QUIET_S && (duration_s <= 0 || duration_s > WATCH_QUIET_S)) {
			fprintf(stderr, "undulated --watch: nothing heard from '%s' on %s for %.0f s yet (is its daemon "
			        "running, with this --lcm-url?)\n", robot, url, WATCH_QUIET_S);
			told = true;
		}
		if (duration_s > 0 && waited >= duration_s)
			break;
	}
	lcm_destroy(lcm);
	if (watch_heard == 0) {
		/* the time listened for, as asked: a loaded machine comes round
		 * a little after it (1.1 s for --timeout 1) */
		double said = duration_s > 0 && waited >= duration_s ? duration_s : waited;
		fprintf(stderr, "undulated --watch: nothing heard from '%s' on %s in %.1f s\n", robot, url, said);
		return 1;
	}
	return 0;
}
