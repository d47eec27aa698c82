/*
 * send.c — `undulated --command`: send one command and print the answers.
 * For scripts, tests and quick lab use.
 *
 * On this computer the command goes to each robot's local command socket
 * (cmdin.h) and the answers come back on it. With --key FILE it is signed
 * and published on the LCM network instead, for robots configured with
 * commands = network; their answers are the events on "<robot>.EVENT".
 */
#include <inttypes.h>
#include <lcm/lcm.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "clock.h"
#include "auth.h"
#include "command.h"
#include "compat/lcm/lcmdec.h"
#include "csock.h"
#include "daemon.h"
#include "udpm.h"
#include "undulate_command_t.h"
#include "undulate_event_t.h"

/* Robots one command may reach on this computer. */
#define SEND_MAX_ROBOTS 64
#define SEND_BUF 2048

struct send_state {
	int64_t seq;
	int accepted, rejected;
	size_t expected;      /* answers to wait for (0: as many as come) */
};

static void send_answer(struct send_state *s, const undulate_event_t *e)
{
	if (e->seq != s->seq)
		return;
	if (strcmp(e->kind, "command-accepted") == 0)
		s->accepted++;
	else
		s->rejected++;
	printf("%s: %s: %s\n", e->robot, e->kind, e->text);
	fflush(stdout);
}

static int send_verdict(const struct send_state *s, const char *robot, double timeout_s)
{
	if (s->accepted + s->rejected == 0) {
		fprintf(stderr, "undulated --command: no answer from %s within %.1f s (seq %" PRId64 ")\n",
		        strcmp(robot, "*") == 0 ? "any robot" : robot, timeout_s, s->seq);
		return 1;
	}
	return s->rejected == 0 ? 0 : 1;
}

/* ---- on this computer --------------------------------------------------------------------------- */
static int send_local(const struct send_opts *o, const uint8_t *msg, size_t len, struct send_state *st)
{
	static char paths[SEND_MAX_ROBOTS][CSOCK_PATH_MAX];
	char why[256], net[96];
	size_t n = csock_find(o->robot, o->lcm_url, paths, SEND_MAX_ROBOTS);
	if (n == 0) {
		char dirs[CSOCK_DIRS][CSOCK_PATH_MAX], list[CSOCK_DIRS * (CSOCK_PATH_MAX + 2)] = "";
		size_t nd = csock_client_dirs(dirs), used = 0;
		for (size_t i = 0; i < nd; i++) {
			size_t dl = strlen(dirs[i]);
			if (used + dl + 3 > sizeof list)
				break;
			memcpy(list + used, i ? ", " : "", i ? 2 : 0);
			used += i ? 2 : 0;
			memcpy(list + used, dirs[i], dl + 1);
			used += dl;
		}
		udpm_net_name(o->lcm_url, net, sizeof net);
		fprintf(stderr, "undulated --command: no robot %s on this computer's LCM network %s (looked for its "
		        "command socket in %s): is undulated running, with this --lcm-url? A robot elsewhere takes "
		        "signed commands: --key FILE\n", strcmp(o->robot, "*") == 0 ? "at all" : o->robot, net, list);
		return 1;
	}
	int fd = csock_client_open(why, sizeof why);
	if (fd < 0) {
		fprintf(stderr, "undulated --command: %s\n", why);
		return 1;
	}
	size_t sent = 0;
	for (size_t i = 0; i < n; i++) {
		if (csock_send(fd, paths[i], msg, len, why, sizeof why))
			sent++;
		else
			fprintf(stderr, "undulated --command: %s\n", why);
	}
	st->expected = sent;
	uint8_t buf[SEND_BUF];
	double deadline = clock_mono_s() + o->timeout_s;
	while ((size_t)(st->accepted + st->rejected) < st->expected && clock_mono_s() < deadline) {
		struct pollfd p = { .fd = fd, .events = POLLIN };
		int left_ms = (int)((deadline - clock_mono_s()) * 1000.0) + 1;
		if (poll(&p, 1, left_ms) <= 0)
			continue;
		ssize_t got = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
		undulate_event_t e;
		if (got > 0 && lcmdec_decode(&lcmdec_event_t, buf, (size_t)got, &e) == LCMDEC_OK) {
			send_answer(st, &e);
			lcmdec_free(&lcmdec_event_t, &e);
		}
	}
	close(fd);
	if (sent == 0)
		return 1;
	return send_verdict(st, o->robot, o->timeout_s);
}

/* ---- over the network, signed ------------------------------------------------------------------- */
static void send_on_event(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
	(void)channel;
	undulate_event_t e;
	if (lcmdec_decode(&lcmdec_event_t, rbuf->data, rbuf->data_size, &e) != LCMDEC_OK)
		return;
	send_answer(user, &e);
	lcmdec_free(&lcmdec_event_t, &e);
}

static int send_network(const struct send_opts *o, const uint8_t *msg, size_t len, struct send_state *st)
{
	lcm_t *lcm = lcm_create(o->lcm_url && o->lcm_url[0] ? o->lcm_url : NULL);
	if (lcm == NULL) {
		fprintf(stderr, "undulated --command: cannot create LCM (url %s)\n", o->lcm_url ? o->lcm_url : "default");
		return 2;
	}
	bool single = strcmp(o->robot, "*") != 0;
	char chan[96], events[96];
	snprintf(chan, sizeof chan, "%s", single ? o->robot : "UNDULATE");
	snprintf(chan + strlen(chan), sizeof chan - strlen(chan), ".CMD");
	if (single)
		snprintf(events, sizeof events, "%s\\.EVENT", o->robot);
	else
		snprintf(events, sizeof events, ".*\\.EVENT");
	lcm_subscription_t *sub = lcm_subscribe(lcm, events, send_on_event, st);
	st->expected = single ? 1 : 0;
	lcm_publish(lcm, chan, msg, (unsigned)len);
	double deadline = clock_mono_s() + o->timeout_s;
	while (clock_mono_s() < deadline) {
		if (st->expected > 0 && (size_t)(st->accepted + st->rejected) >= st->expected)
			break;
		int left_ms = (int)((deadline - clock_mono_s()) * 1000.0) + 1;
		lcm_handle_timeout(lcm, left_ms);
	}
	/* the generated wrapper is not freed by lcm_destroy() */
	lcm_unsubscribe(lcm, sub);
	lcm_destroy(lcm);
	return send_verdict(st, o->robot, o->timeout_s);
}

int dmn_send_command(const struct send_opts *o)
{
	struct cmd_request r = { 0 };
	char param[64] = "", why[256];
	if (!cmd_parse_text(o->text, &r, param, sizeof param, why, sizeof why)) {
		fprintf(stderr, "undulated --command: %s\n", why);
		return 2;
	}
	struct auth_key key;
	if (o->key_file != NULL && !auth_key_load(&key, o->key_file, true, why, sizeof why)) {
		fprintf(stderr, "undulated --command: --key: %s\n", why);
		return 2;
	}
	char host[64] = "?", source[AUTH_SOURCE_MAX];
	gethostname(host, sizeof host);
	host[sizeof host - 1] = '\0';
	/* one source per sending process: the robot's replay guard keeps the last
	 * (time, seq) of each */
	if (o->source != NULL)
		snprintf(source, sizeof source, "%s", o->source);
	else
		snprintf(source, sizeof source, "undulated@%.24s:%d", host, (int)getpid());
	struct send_state st = { .seq = clock_wall_us() };
	r.utime = st.seq;
	r.seq = st.seq;
	r.source = source;
	r.robot = o->robot;
	r.param = param;
	uint8_t msg[SEND_BUF], mac[CMD_MAC_BYTES];
	size_t signed_len = 0;
	size_t len = cmd_encode(&r, __undulate_command_t_get_hash(), NULL, msg, sizeof msg, &signed_len);
	if (len == 0) {
		fprintf(stderr, "undulated --command: the command does not fit a message\n");
		return 2;
	}
	if (o->key_file == NULL)
		return send_local(o, msg, len, &st);
	auth_mac(&key, msg, signed_len, mac);
	memcpy(msg + signed_len, mac, sizeof mac);
	memset(&key, 0, sizeof key);
	return send_network(o, msg, len, &st);
}
