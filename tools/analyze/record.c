/* record.c — see record.h. */
#include "record.h"

#include <errno.h>
#include <lcm/lcm.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include "alog.h"
#include "analyze.h"

struct rec {
	struct alog_writer w;
	long long bytes;
	bool failed;
};

static void rec_on_message(const lcm_recv_buf_t *rb, const char *channel, void *user)
{
	struct rec *r = user;
	if (r->failed)
		return;
	if (alog_write(&r->w, channel, rb->recv_utime, rb->data, (int32_t)rb->data_size) != 0) {
		fprintf(stderr, "undulate-analyze: --record: cannot write: %s\n", strerror(errno));
		r->failed = true;
		return;
	}
	r->bytes += rb->data_size;
}

/* The URL with a large receive buffer unless it names one. */
static void rec_url(const char *url, char *out, size_t cap)
{
	if (url == NULL || url[0] == '\0')
		url = "udpm://239.255.76.67:7667?ttl=0";
	if (strstr(url, "recv_buf_size=") != NULL || strncmp(url, "udpm://", 7) != 0)
		snprintf(out, cap, "%s", url);
	else
		snprintf(out, cap, "%s%crecv_buf_size=%d", url, strchr(url, '?') ? '&' : '?', REC_RCVBUF);
}

/* Signals come through a descriptor, so the loop ends between messages. */
static int rec_signal_fd(void)
{
	sigset_t set;
	sigemptyset(&set);
	sigaddset(&set, SIGINT);
	sigaddset(&set, SIGTERM);
	sigprocmask(SIG_BLOCK, &set, NULL);
	return signalfd(-1, &set, SFD_CLOEXEC);
}

int rec_run(const char *path, const char *url)
{
	static struct rec r;
	char full[512];
	rec_url(url, full, sizeof full);
	int sfd = rec_signal_fd();
	lcm_t *lcm = lcm_create(full);
	if (lcm == NULL || sfd < 0) {
		fprintf(stderr, "undulate-analyze: --record: cannot open LCM at %s\n", full);
		return AN_EXIT_USAGE;
	}
	char err[1024];
	if (alog_writer_open(&r.w, path, err, sizeof err) != 0) {
		fprintf(stderr, "undulate-analyze: --record %s: %s\n", path, err);
		lcm_destroy(lcm);
		return AN_EXIT_OUTPUT;
	}
	lcm_subscription_t *sub = lcm_subscribe(lcm, ".*", rec_on_message, &r);
	lcm_subscription_set_queue_capacity(sub, REC_QUEUE);
	printf("undulate-analyze: recording %s to %s\n", full, path);
	fflush(stdout);
	struct pollfd p[2] = { { .fd = lcm_get_fileno(lcm), .events = POLLIN }, { .fd = sfd, .events = POLLIN } };
	while (!r.failed) {
		if (poll(p, 2, -1) < 0 && errno != EINTR)
			break;
		if (p[1].revents & POLLIN)
			break;
		if (p[0].revents & POLLIN)
			lcm_handle(lcm);
	}
	/* what was queued before the signal is kept */
	while (!r.failed && lcm_handle_timeout(lcm, 0) > 0)
		;
	lcm_unsubscribe(lcm, sub);
	lcm_destroy(lcm);
	long long events = r.w.events;
	int rc = alog_writer_close(&r.w);
	printf("undulate-analyze: recorded %lld events (%.1f MB) to %s\n", events, (double)r.bytes / 1e6, path);
	close(sfd);
	return rc == 0 && !r.failed ? AN_EXIT_OK : AN_EXIT_OUTPUT;
}
