/*
 * send.c — `undulated --command`: publish one command_t and print the events
 * that answer it (matched by seq). For scripts, tests and quick lab use.
 */
#include <inttypes.h>
#include <lcm/lcm.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "command.h"
#include "daemon.h"
#include "undulate_command_t.h"
#include "undulate_event_t.h"

struct send_state {
	int64_t seq;
	int accepted, rejected;
	bool single;      /* one robot addressed: stop at its answer */
};

static void send_on_event(const lcm_recv_buf_t *rbuf, const char *channel, const undulate_event_t *e,
                          void *user)
{
	struct send_state *s = user;
	(void)rbuf;
	(void)channel;
	if (e->seq != s->seq)
		return;
	bool ok = strcmp(e->kind, "command-accepted") == 0;
	if (ok)
		s->accepted++;
	else
		s->rejected++;
	printf("%s: %s: %s\n", e->robot, e->kind, e->text);
	fflush(stdout);
}

static double send_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int dmn_send_command(const char *lcm_url, const char *robot, const char *text, double timeout_s)
{
	struct cmd_request r = { 0 };
	char param[64] = "", why[256];
	if (!cmd_parse_text(text, &r, param, sizeof param, why, sizeof why)) {
		fprintf(stderr, "undulated --command: %s\n", why);
		return 2;
	}
	lcm_t *lcm = lcm_create(lcm_url && lcm_url[0] ? lcm_url : NULL);
	if (lcm == NULL) {
		fprintf(stderr, "undulated --command: cannot create LCM (url %s)\n", lcm_url ? lcm_url : "default");
		return 2;
	}
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	struct send_state st = {
		.seq = ((int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000) ^ ((int64_t)getpid() << 40),
		.single = strcmp(robot, "*") != 0,
	};
	if (st.seq <= 0)
		st.seq = -st.seq + 1;
	char chan[96], events[96], host[64] = "?", source[128], target[64];
	snprintf(target, sizeof target, "%s", robot);
	gethostname(host, sizeof host);
	host[sizeof host - 1] = '\0';
	snprintf(source, sizeof source, "undulated-command@%s", host);
	if (st.single) {
		snprintf(chan, sizeof chan, "%s.CMD", robot);
		snprintf(events, sizeof events, "%s.EVENT", robot);
	} else {
		snprintf(chan, sizeof chan, "UNDULATE.CMD");
		snprintf(events, sizeof events, ".*\\.EVENT");
	}
	undulate_event_t_subscription_t *sub = undulate_event_t_subscribe(lcm, events, send_on_event, &st);
	undulate_command_t m = {
		.utime = (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000, .seq = st.seq, .source = source,
		.robot = target, .kind = (int8_t)r.kind, .mode = (int8_t)r.mode, .param = param,
		.joint = (int16_t)r.joint, .value = r.value, .torque = r.torque,
	};
	undulate_command_t_publish(lcm, chan, &m);
	double deadline = send_now() + timeout_s;
	while (send_now() < deadline) {
		if (st.single && st.accepted + st.rejected > 0)
			break;
		int left_ms = (int)((deadline - send_now()) * 1000.0) + 1;
		lcm_handle_timeout(lcm, left_ms);
	}
	/* the generated wrapper is not freed by lcm_destroy() */
	undulate_event_t_unsubscribe(lcm, sub);
	lcm_destroy(lcm);
	if (st.accepted + st.rejected == 0) {
		fprintf(stderr, "undulated --command: no answer from %s within %.1f s (seq %" PRId64 ")\n",
		        st.single ? robot : "any robot", timeout_s, st.seq);
		return 1;
	}
	return st.rejected == 0 ? 0 : 1;
}
