/* wcmd.c — see wcmd.h. */
#include "wcmd.h"

#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "clock.h"
#include "compat/lcm/lcmdec.h"
#include "csock.h"
#include "undulate_command_t.h"

bool wcmd_init(struct wcmd *w, lcm_t *lcm, const char *url, const char *key_file, char *why, size_t cap)
{
	memset(w, 0, sizeof *w);
	w->lcm = lcm;
	w->url = url;
	w->fd = -1;
	char host[64] = "?";
	gethostname(host, sizeof host - 1);
	/* short enough for any robot to take (command.h's CMD_STR_MAX) */
	snprintf(w->source, sizeof w->source, "undulate-web@%.20s:%d", host, (int)getpid() % 10000000);
	/* from the clock, as undulate-top: two senders rarely pick the same
	 * numbers, and a restarted one never repeats its old ones (the robot's
	 * replay guard wants (time, seq) to grow per source) */
	w->next_seq = clock_wall_us();
	if (key_file != NULL) {
		w->signed_lcm = true;
		return auth_key_load(&w->key, key_file, true, why, cap);
	}
	w->fd = csock_client_open(why, cap);
	return w->fd >= 0;
}

void wcmd_close(struct wcmd *w)
{
	if (w->fd >= 0)
		close(w->fd);
	w->fd = -1;
	memset(&w->key, 0, sizeof w->key);
}

static int wcmd_send_local(struct wcmd *w, const char *robot, const uint8_t *msg, size_t len, char *why,
                           size_t cap)
{
	static char paths[WCMD_MAX_SOCKETS][CSOCK_PATH_MAX];
	size_t np = csock_find(robot, w->url, paths, WCMD_MAX_SOCKETS);
	if (np == 0) {
		snprintf(why, cap, "nothing sent: no robot %s runs on this computer with %s (commands go to local "
		         "robots only, unless undulate-web has --key)", strcmp(robot, "*") == 0 ? "at all" : robot,
		         w->url ? w->url : "the default LCM URL");
		return 0;
	}
	int sent = 0;
	for (size_t i = 0; i < np; i++)
		if (csock_send(w->fd, paths[i], msg, len, why, cap))
			sent++;
	return sent;
}

static int wcmd_send_signed(struct wcmd *w, const char *robot, uint8_t *msg, size_t len, size_t signed_len)
{
	uint8_t mac[CMD_MAC_BYTES];
	auth_mac(&w->key, msg, signed_len, mac);
	memcpy(msg + signed_len, mac, sizeof mac);
	char chan[CFG_NAME_MAX + 8];
	snprintf(chan, sizeof chan, "%s.CMD", strcmp(robot, "*") == 0 ? "UNDULATE" : robot);
	return lcm_publish(w->lcm, chan, msg, (unsigned)len) == 0 ? 1 : 0;
}

int64_t wcmd_send(struct wcmd *w, struct cmd_request *r, unsigned client, long long id, int *reached, char *why,
                  size_t cap)
{
	int64_t seq = w->next_seq++;
	/* signed commands must be recent: utime is now, seq only grows */
	r->utime = clock_wall_us();
	r->seq = seq;
	r->source = w->source;
	uint8_t msg[CSOCK_DGRAM_MAX];
	size_t signed_len = 0;
	size_t len = cmd_encode(r, __undulate_command_t_get_hash(), NULL, msg, sizeof msg, &signed_len);
	*reached = 0;
	if (len == 0) {
		snprintf(why, cap, "the command does not fit a message");
		w->refused_send++;
		return 0;
	}
	*reached = w->signed_lcm ? wcmd_send_signed(w, r->robot, msg, len, signed_len)
	                         : wcmd_send_local(w, r->robot, msg, len, why, cap);
	if (*reached == 0) {
		if (w->signed_lcm)
			snprintf(why, cap, "LCM publish failed");
		w->refused_send++;
		return 0;
	}
	w->commands++;
	w->robots_reached += *reached;
	w->sent[w->nsent % WCMD_PENDING] = (struct wcmd_sent){ .seq = seq, .client = client, .id = id };
	w->nsent++;
	return seq;
}

bool wcmd_client_of(const struct wcmd *w, int64_t seq, unsigned *client, long long *id)
{
	unsigned n = w->nsent < WCMD_PENDING ? w->nsent : WCMD_PENDING;
	for (unsigned i = 0; i < n; i++)
		if (w->sent[i].seq == seq) {
			*client = w->sent[i].client;
			*id = w->sent[i].id;
			return true;
		}
	return false;
}

void wcmd_read_local(struct wcmd *w, void (*fn)(void *ctx, const undulate_event_t *e), void *ctx)
{
	uint8_t buf[CSOCK_DGRAM_MAX];
	for (int i = 0; i < 64 && w->fd >= 0; i++) {
		ssize_t n = recv(w->fd, buf, sizeof buf, MSG_DONTWAIT);
		if (n <= 0)
			return;
		undulate_event_t e;
		if (lcmdec_decode(&lcmdec_event_t, buf, (size_t)n, &e) != LCMDEC_OK)
			continue;
		fn(ctx, &e);
		lcmdec_free(&lcmdec_event_t, &e);
	}
}
