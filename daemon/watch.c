/*
 * watch.c — `undulated --watch ROBOT`: print what a robot publishes, one text
 * line per message, for terminals and scripts without lcm-spy:
 *   STATE <robot> cycle=N mode=M reason="..." period=us jitter=us bus=us overruns=N
 *         bus_errors=N bad_commands=N a0= s0= g0= amp0= f0= ph0= ld0= e0= st0= tq0= ...
 *   EVENT <robot> seq=N level=L kind=K text="..."
 *   BUS <robot> connected=B reconnects=N p50= p99= max= jitter99= bus99= cpu= overruns=N
 *       ... idJ=ID/replies/timeouts/rtt_mean/rtt_max ... badJ=checksum/wrong_id/wrong_length
 *   PARAMS <robot> k0= c0= mu0= lambda0= ... amplitude= frequency= phase=
 * Angles in rad relative to neutral, speeds rad/s.
 */
#include <inttypes.h>
#include <lcm/lcm.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "daemon.h"
#include "undulate_bus_stats_t.h"
#include "text.h"
#include "undulate_event_t.h"
#include "undulate_osc_params_t.h"
#include "undulate_robot_state_t.h"

/* Silence after which --watch says it hears nobody (seconds). */
#define WATCH_QUIET_S 3.0

static volatile sig_atomic_t watch_stop;
static unsigned long watch_heard; /* messages printed: none at the end is a failure */
static void watch_on_signal(int sig) { (void)sig; watch_stop = 1; }

static void watch_state(const lcm_recv_buf_t *rb, const char *ch, const undulate_robot_state_t *m, void *u)
{
	(void)rb; (void)ch; (void)u;
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

static void watch_event(const lcm_recv_buf_t *rb, const char *ch, const undulate_event_t *m, void *u)
{
	(void)rb; (void)ch; (void)u;
	watch_heard++;
	char robot[64], kind[48], text[600];
	printf("EVENT %s seq=%" PRId64 " level=%d kind=%s text=\"%s\"\n", text_line(robot, sizeof robot, m->robot),
	       m->seq, m->level, text_line(kind, sizeof kind, m->kind), text_line(text, sizeof text, m->text));
}

static void watch_bus(const lcm_recv_buf_t *rb, const char *ch, const undulate_bus_stats_t *m, void *u)
{
	(void)rb; (void)ch; (void)u;
	watch_heard++;
	printf("BUS %s connected=%d reconnects=%" PRId64 " p50=%.0f p99=%.0f max=%.0f jitter99=%.0f bus99=%.0f "
	       "cpu=%.2f overruns=%" PRId64 " stray=%" PRId64 " io_errors=%" PRId64, m->robot, m->connected,
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

static void watch_params(const lcm_recv_buf_t *rb, const char *ch, const undulate_osc_params_t *m, void *u)
{
	(void)rb; (void)ch; (void)u;
	watch_heard++;
	printf("PARAMS %s", m->robot);
	for (int j = 0; j < m->njoints; j++)
		printf(" k%d=%g c%d=%g mu%d=%g lambda%d=%g inertia%d=%g friction%d=%g neutral%d=%g min%d=%g max%d=%g",
		       j, m->k[j], j, m->c[j], j, m->mu[j], j, m->lambda[j], j, m->inertia[j], j, m->friction[j], j,
		       m->neutral[j], j, m->limit_min[j], j, m->limit_max[j]);
	printf(" amplitude=%g frequency=%g phase=%g\n", m->amplitude, m->frequency, m->phase);
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
	undulate_robot_state_t_subscription_t *s0 = undulate_robot_state_t_subscribe(lcm, ch[0], watch_state, NULL);
	undulate_event_t_subscription_t *s1 = undulate_event_t_subscribe(lcm, ch[1], watch_event, NULL);
	undulate_bus_stats_t_subscription_t *s2 = undulate_bus_stats_t_subscribe(lcm, ch[2], watch_bus, NULL);
	undulate_osc_params_t_subscription_t *s3 = undulate_osc_params_t_subscribe(lcm, ch[3], watch_params, NULL);
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
	/* the generated wrappers are not freed by lcm_destroy() */
	undulate_robot_state_t_unsubscribe(lcm, s0);
	undulate_event_t_unsubscribe(lcm, s1);
	undulate_bus_stats_t_unsubscribe(lcm, s2);
	undulate_osc_params_t_unsubscribe(lcm, s3);
	lcm_destroy(lcm);
	if (watch_heard == 0) {
		fprintf(stderr, "undulated --watch: nothing heard from '%s' on %s in %.1f s\n", robot, url, waited);
		return 1;
	}
	return 0;
}
