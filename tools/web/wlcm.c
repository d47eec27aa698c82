/* wlcm.c — see wlcm.h. */
#define _GNU_SOURCE /* recvmmsg */
#include "wlcm.h"

#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "udpm.h"
#include "wire.h"

/* The batch's buffers: static, 1 MB, only the pages a burst touches are
 * resident (a STATE is 200 bytes). One reader per process. */
static uint8_t wlcm_buf[WLCM_BATCH][WLCM_DGRAM_MAX];

bool wlcm_open(struct wlcm *w, const char *url, char *why, size_t cap)
{
	memset(w, 0, sizeof *w);
	w->fd = -1;
	struct udpm_url u;
	const char *eff = udpm_effective_url(url);
	if (!udpm_parse_url(eff, &u, why, cap))
		return false;
	if (strcmp(u.provider, "udpm") != 0) {
		snprintf(why, cap, "%s:// is not a multicast group", u.provider);
		return false;
	}
	w->fd = udpm_open_recv(eff, why, cap);
	if (w->fd < 0)
		return false;
	/* a loop busy with a burst of browsers leaves the datagrams to the
	 * socket: room for a second of 20 robots (best effort, as LCM's) */
	int size = 2 * 1024 * 1024;
	(void)setsockopt(w->fd, SOL_SOCKET, SO_RCVBUF, &size, sizeof size);
	return true;
}

void wlcm_close(struct wlcm *w)
{
	if (w->fd >= 0)
		close(w->fd);
	w->fd = -1;
	for (size_t i = 0; i < w->nsubs; i++)
		regfree(&w->re[i]);
	w->nsubs = 0;
}

bool wlcm_subscribe(struct wlcm *w, const char *pattern, wlcm_handler h)
{
	char whole[256];
	if (w->nsubs >= WLCM_MAX_SUBS ||
	    snprintf(whole, sizeof whole, "^(%s)$", pattern) >= (int)sizeof whole ||
	    regcomp(&w->re[w->nsubs], whole, REG_EXTENDED | REG_NOSUB) != 0)
		return false;
	w->handler[w->nsubs++] = h;
	return true;
}

wlcm_handler wlcm_match(const struct wlcm *w, const char *channel)
{
	for (size_t i = 0; i < w->nsubs; i++)
		if (regexec(&w->re[i], channel, 0, NULL, 0) == 0)
			return w->handler[i];
	return NULL;
}

void wlcm_datagram(struct wlcm *w, const uint8_t *d, size_t n, bool truncated)
{
	w->n.datagrams++;
	if (truncated) {
		w->n.truncated++;
		return;
	}
	struct wire_udpm m;
	const char *bad;
	if (!wire_udpm_parse(d, n, &m, &bad)) {
		w->n.not_lcm++;
		return;
	}
	wlcm_handler h = wlcm_match(w, m.channel);
	if (h == NULL)
		return;
	w->n.messages++;
	h(m.channel, m.payload, m.payload_len);
}

int wlcm_drain(struct wlcm *w, int rounds)
{
	static struct mmsghdr msgs[WLCM_BATCH];
	static struct iovec iov[WLCM_BATCH];
	int total = 0;
	for (int r = 0; r < rounds && w->fd >= 0; r++) {
		for (int i = 0; i < WLCM_BATCH; i++) {
			iov[i] = (struct iovec){ .iov_base = wlcm_buf[i], .iov_len = WLCM_DGRAM_MAX };
			msgs[i] = (struct mmsghdr){ .msg_hdr = { .msg_iov = &iov[i], .msg_iovlen = 1 } };
		}
		int got = recvmmsg(w->fd, msgs, WLCM_BATCH, MSG_DONTWAIT, NULL);
		if (got <= 0)
			break;
		for (int i = 0; i < got; i++)
			wlcm_datagram(w, wlcm_buf[i], msgs[i].msg_len, (msgs[i].msg_hdr.msg_flags & MSG_TRUNC) != 0);
		total += got;
		if (got < WLCM_BATCH)
			break;
	}
	return total;
}
