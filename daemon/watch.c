/*
 * watch.c — `undulated --watch ROBOT`: print what a robot publishes, one text
 * line per message, for terminals and scripts without lcm-spy:
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
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "compat/lcm/lcmdec.h"
#include "daemon.h"
#include "text.h"

/* Silence after which --watch says it hears nobody (seconds). */
#define WATCH_QUIET_S 3.0

static volatile sig_atomic_t watch_stop;
static unsigned long watch_heard; /* messages printed: none at the end is a failure */
static unsigned long watch_bad;   /* messages that did not decode */
#define WATCH_BAD_SAID 5
#define WATCH_BAD_EVERY 1000
static void watch_on_signal(int sig) { (void)sig; watch_stop = 1; }

static void watch_state(const undulate_robot_state_t *m)
{
	watch_heard++;
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

static void watch_event(const undulate_event_t *m)
{
	watch_heard++;
	char robot[64], kind[48], text[600];
	printf("EVENT %s seq=%" PRId64 " level=%d kind=%s text=\"%s\"\n", text_line(robot, sizeof robot, m->robot),
	       m->seq, m->level, text_line(kind, sizeof kind, m->kind), text_line(text, sizeof text, m->text));
}

static void watch_bus(const undulate_bus_stats_t *m)
{
	watch_heard++;
	char robot[64];
	printf("BUS %s connected=%d reconnects=%" PRId64 " p50=%.0f p99=%.0f max=%.0f jitter99=%.0f bus99=%.0f "
	       "cpu=%.2f overruns=%" PRId64 " stray=%" PRId64 " io_errors=%" PRId64, text_line(robot, sizeof robot, m->robot),
	       m->connected,
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

static void watch_params(const undulate_osc_params_t *m)
{
	watch_heard++;
	char robot[64];
	printf("PARAMS %s", text_line(robot, sizeof robot, m->robot));
	for (int j = 0; j < m->njoints; j++)
		printf(" k%d=%g c%d=%g mu%d=%g lambda%d=%g inertia%d=%g friction%d=%g neutral%d=%g min%d=%g max%d=%g",
		       j, m->k[j], j, m->c[j], j, m->mu[j], j, m->lambda[j], j, m->inertia[j], j, m->friction[j], j,
		       m->neutral[j], j, m->limit_min[j], j, m->limit_max[j]);
	printf(" amplitude=%g frequency=%g phase=%g\n", m->amplitude, m->frequency, m->phase);
}

union watch_msg {
	undulate_robot_state_t state;
	undulate_event_t event;
	undulate_bus_stats_t bus;
	undulate_osc_params_t params;
};

/* Subscribed by channel suffix: the suffix names the type. */
static void watch_on_lcm(const lcm_recv_buf_t *rb, const char *ch, void *u)
{
	(void)u;
	static const struct { const char *suffix; const struct lcmdec_type *type; } kinds[] = {
		{ ".STATE", &lcmdec_robot_state_t }, { ".EVENT", &lcmdec_event_t },
		{ ".BUS", &lcmdec_bus_stats_t },     { ".PARAMS", &lcmdec_osc_params_t },
	};
	size_t n = strlen(ch), k = 0;
	while (k < sizeof kinds / sizeof kinds[0] &&
	       (n < strlen(kinds[k].suffix) || strcmp(ch + n - strlen(kinds[k].suffix), kinds[k].suffix) != 0))
		k++;
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
	switch (k) {
	case 0: watch_state(&m.state); break;
	case 1: watch_event(&m.event); break;
	case 2: watch_bus(&m.bus); break;
	default: watch_params(&m.params); break;
	}
	lcmdec_free(kinds[k].type, &m);
}

int dmn_watch(const char *lcm_url, const char *robot, double duration_s)
{
	lcm_t *lcm = lcm_create(lcm_url && lcm_url[0] ? lcm_url : NULL);
	if (lcm == NULL) {
		fprintf(stderr, "undulated --watch: cannot create LCM (url %s)\n", lcm_url ? lcm_url : "default");
		return 2;
	}
	char ch[4][96];
	const char *r = strcmp(robot, "*") == 0 ? "[^.]*" : robot;
	snprintf(ch[0], sizeof ch[0], "%s\\.STATE", r);
	snprintf(ch[1], sizeof ch[1], "%s\\.EVENT", r);
	snprintf(ch[2], sizeof ch[2], "%s\\.BUS", r);
	snprintf(ch[3], sizeof ch[3], "%s\\.PARAMS", r);
	for (int i = 0; i < 4; i++)
		lcm_subscribe(lcm, ch[i], watch_on_lcm, NULL);
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
		fprintf(stderr, "undulated --watch: nothing heard from '%s' on %s in %.1f s\n", robot, url, waited);
		return 1;
	}
	return 0;
}
