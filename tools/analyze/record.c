/* record.c — see record.h. */
#define _GNU_SOURCE /* recvmmsg */
#include "record.h"

#include <arpa/inet.h>
#include <errno.h>
#include <lcm/lcm.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "alog.h"
#include "clock.h"
#include "analyze.h"
#include "udpm.h"
#include "wire.h"

/* LCM's default group when no URL is given (the recorder has always used it
 * rather than $LCM_DEFAULT_URL). */
#define REC_DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0"
/* Largest UDP payload: a longer datagram cannot arrive whole. */
#define REC_DGRAM_MAX 65536
/* liblcm's self-test message, sent to the group by every liblcm program that
 * subscribes; never a message of ours (lcm-logger and the liblcm recorder
 * did not record it). */
#define REC_SELF_TEST "LCM_SELF_TEST"

/* One sender's fragmented message in reassembly. */
struct rec_sender {
	struct sockaddr_in from;
	bool used, active;
	uint64_t last_heard;            /* rec.tick at its last fragment */
	uint32_t seqno, size, refused_seqno;
	bool refused;                   /* refused_seqno is a message refused (too large) */
	uint16_t fragments, remaining;
	char channel[WIRE_CHANNEL_MAX];
	uint8_t *buf;
	size_t cap;
};

struct rec {
	struct alog_writer w;
	long long bytes;
	long long bad, lost, too_large;  /* datagrams, messages, messages */
	uint32_t kernel_drops;           /* SO_RXQ_OVFL: the socket's drops so far */
	bool failed;
	uint64_t tick;
	struct rec_sender senders[REC_SENDERS];
	struct mmsghdr msgs[REC_BATCH];
	struct iovec iov[REC_BATCH];
	struct sockaddr_in from[REC_BATCH];
	/* SCM_TIMESTAMP (struct timeval) and SO_RXQ_OVFL (uint32) */
	union {
		char buf[CMSG_SPACE(sizeof(struct timeval)) + CMSG_SPACE(sizeof(uint32_t))];
		struct cmsghdr align;
	} ctl[REC_BATCH];
	uint8_t dgram[REC_BATCH][REC_DGRAM_MAX];
};

static void rec_event(struct rec *r, const char *channel, int64_t utime, const void *data, size_t len)
{
	if (r->failed || strcmp(channel, REC_SELF_TEST) == 0)
		return;
	if (alog_write(&r->w, channel, utime, data, (int32_t)len) != 0) {
		fprintf(stderr, "undulate-analyze: --record: cannot write: %s\n", strerror(errno));
		r->failed = true;
		return;
	}
	r->bytes += (long long)len;
}

/* ---- liblcm (file://, memq://) ---- */

static void rec_on_message(const lcm_recv_buf_t *rb, const char *channel, void *user)
{
	rec_event(user, channel, rb->recv_utime, rb->data, rb->data_size);
}

/* ---- udpm, read here ---- */

static struct rec_sender *rec_sender_find(struct rec *r, const struct sockaddr_in *from, bool make)
{
	struct rec_sender *oldest = &r->senders[0];
	for (int i = 0; i < REC_SENDERS; i++) {
		struct rec_sender *s = &r->senders[i];
		if (s->used && s->from.sin_addr.s_addr == from->sin_addr.s_addr && s->from.sin_port == from->sin_port)
			return s;
		if (!s->used || (oldest->used && s->last_heard < oldest->last_heard))
			oldest = s;
	}
	if (!make)
		return NULL;
	if (oldest->active)
		r->lost++;
	oldest->used = true;
	oldest->active = false;
	oldest->refused = false;
	oldest->from = *from;
	return oldest;
}

/* Fragment 0 starts a message (what the sender had in progress is lost). */
static bool rec_frag_start(struct rec *r, struct rec_sender *s, const struct wire_udpm_frag *f)
{
	if (s->active)
		r->lost++;
	s->active = false;
	if (f->msg_size > REC_MSG_MAX) {
		r->too_large++;
		s->refused = true;
		s->refused_seqno = f->seqno;
		return false;
	}
	if (s->cap < f->msg_size) {
		uint8_t *nb = realloc(s->buf, f->msg_size);
		if (nb == NULL) {
			r->lost++;
			return false;
		}
		s->buf = nb;
		s->cap = f->msg_size;
	}
	snprintf(s->channel, sizeof s->channel, "%s", f->channel);
	s->seqno = f->seqno;
	s->size = f->msg_size;
	s->fragments = s->remaining = f->fragments;
	s->active = true;
	return true;
}

/* LCM 1.3.1's reassembly (_recv_message_fragment): one message in progress a
 * sender; a fragment of another message ends it, one that does not fit drops
 * it; complete when as many fragments as announced arrived. Its time is the
 * last fragment's, as liblcm gives it. */
static void rec_fragment(struct rec *r, const struct sockaddr_in *from, int64_t utime, const uint8_t *d, size_t n)
{
	struct wire_udpm_frag f;
	const char *why;
	if (!wire_udpm_frag_parse(d, n, &f, &why)) {
		r->bad++;
		return;
	}
	struct rec_sender *s = rec_sender_find(r, from, f.fragment_no == 0);
	if (s != NULL)
		s->last_heard = ++r->tick;
	if (s != NULL && s->active && (s->seqno != f.seqno || s->size != f.msg_size || s->fragments != f.fragments)) {
		s->active = false;
		r->lost++;
	}
	if (f.fragment_no == 0 && !rec_frag_start(r, s, &f))
		return;
	if (s == NULL || !s->active) {
		/* its fragment 0 was lost (counted here), or refused (counted then) */
		if (s == NULL || !s->refused || s->refused_seqno != f.seqno)
			r->lost++;
		return;
	}
	if (f.offset > s->size || f.data_len > s->size - f.offset) {
		s->active = false;
		r->lost++;
		return;
	}
	memcpy(s->buf + f.offset, f.data, f.data_len);
	if (--s->remaining == 0) {
		s->active = false;
		rec_event(r, s->channel, utime, s->buf, s->size);
	}
}

static void rec_datagram(struct rec *r, const struct sockaddr_in *from, int64_t utime, const uint8_t *d, size_t n)
{
	struct wire_udpm m;
	const char *why;
	uint32_t magic = n >= 4 ? (uint32_t)d[0] << 24 | (uint32_t)d[1] << 16 | (uint32_t)d[2] << 8 | d[3] : 0;
	if (magic == WIRE_UDPM_MAGIC_LONG)
		rec_fragment(r, from, utime, d, n);
	else if (wire_udpm_parse(d, n, &m, &why))
		rec_event(r, m.channel, utime, m.payload, m.payload_len);
	else
		r->bad++;
}

/* The kernel's receive time (SO_TIMESTAMP, as liblcm takes it), and the
 * socket's drop count if it has changed (SO_RXQ_OVFL, cumulative). */
static int64_t rec_control(struct rec *r, struct msghdr *h, int64_t fallback)
{
	int64_t utime = fallback;
	for (struct cmsghdr *c = CMSG_FIRSTHDR(h); c != NULL; c = CMSG_NXTHDR(h, c)) {
		if (c->cmsg_level != SOL_SOCKET)
			continue;
		if (c->cmsg_type == SCM_TIMESTAMP) {
			struct timeval tv;
			memcpy(&tv, CMSG_DATA(c), sizeof tv);
			utime = (int64_t)tv.tv_sec * 1000000 + tv.tv_usec;
		} else if (c->cmsg_type == SO_RXQ_OVFL) {
			uint32_t drops;
			memcpy(&drops, CMSG_DATA(c), sizeof drops);
			if (drops > r->kernel_drops)
				r->kernel_drops = drops;
		}
	}
	return utime;
}

/* Reads what the socket holds, a batch a call. A batch that comes back short
 * emptied the queue: no call to be told EAGAIN (poll() wakes again for what
 * arrives next). */
static void rec_drain(struct rec *r, int fd)
{
	for (;;) {
		for (int i = 0; i < REC_BATCH; i++) {
			r->iov[i] = (struct iovec){ .iov_base = r->dgram[i], .iov_len = REC_DGRAM_MAX };
			r->msgs[i].msg_hdr = (struct msghdr){
				.msg_name = &r->from[i], .msg_namelen = sizeof r->from[i],
				.msg_iov = &r->iov[i], .msg_iovlen = 1,
				.msg_control = r->ctl[i].buf, .msg_controllen = sizeof r->ctl[i].buf,
			};
		}
		int n = recvmmsg(fd, r->msgs, REC_BATCH, MSG_DONTWAIT, NULL);
		if (n <= 0)
			return;
		int64_t fallback = clock_wall_us();
		for (int i = 0; i < n && !r->failed; i++) {
			struct msghdr *h = &r->msgs[i].msg_hdr;
			int64_t utime = rec_control(r, h, fallback);
			if (h->msg_flags & MSG_TRUNC)
				r->bad++;
			else
				rec_datagram(r, &r->from[i], utime, r->dgram[i], r->msgs[i].msg_len);
		}
		if (n < REC_BATCH || r->failed)
			return;
	}
}

/* SO_RCVBUFFORCE (root may pass net.core.rmem_max), else SO_RCVBUF; said
 * once if the kernel gave less. */
static void rec_rcvbuf(int fd, long want)
{
	int v = (int)want, got = 0;
	socklen_t len = sizeof got;
	if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &v, sizeof v) != 0)
		setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &v, sizeof v);
	/* the kernel reports twice what it counts as payload room */
	if (getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &got, &len) == 0 && got / 2 < want)
		fprintf(stderr,
			"undulate-analyze: --record: asked for a %ld-byte receive buffer, the kernel gave %d "
			"(net.core.rmem_max)\n", want, got / 2);
}

static int rec_open_udpm(const char *url, const struct udpm_url *u)
{
	char why[256];
	int fd = udpm_open_recv(url, why, sizeof why);
	if (fd < 0) {
		fprintf(stderr, "undulate-analyze: --record: %s\n", why);
		return -1;
	}
	int one = 1;
	rec_rcvbuf(fd, u->recv_buf_size > 0 ? u->recv_buf_size : REC_RCVBUF);
	if (setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &one, sizeof one) != 0)
		fprintf(stderr, "undulate-analyze: --record: no SO_TIMESTAMP (%s): events stamped as read\n",
			strerror(errno));
	setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one);
	return fd;
}

/* milliseconds on the monotonic clock (common/clock.h) */
static int64_t rec_ms(void) { return (int64_t)(clock_mono_us() / 1000); }

static void rec_flush(struct rec *r)
{
	if (!r->failed && alog_flush(&r->w) != 0) {
		fprintf(stderr, "undulate-analyze: --record: cannot write: %s\n", strerror(errno));
		r->failed = true;
	}
}

static void rec_loop_udpm(struct rec *r, int fd, int sfd)
{
	struct pollfd p[2] = { { .fd = fd, .events = POLLIN }, { .fd = sfd, .events = POLLIN } };
	int64_t flushed = rec_ms();
	bool stop = false;
	while (!stop && !r->failed) {
		int64_t wait = REC_FLUSH_MS - (rec_ms() - flushed);
		int timeout = r->w.unflushed == 0 ? -1 : wait < 0 ? 0 : (int)wait;
		int n = poll(p, 2, timeout);
		if (n < 0 && errno != EINTR)
			break;
		/* what arrived before the signal is kept */
		stop = n > 0 && (p[1].revents & POLLIN);
		if (stop || (n > 0 && (p[0].revents & POLLIN))) {
			rec_drain(r, fd);
			/* gather (REC_GATHER_MS); a signal meanwhile ends it at once */
			if (!stop && poll(&p[1], 1, REC_GATHER_MS) > 0 && (p[1].revents & POLLIN)) {
				stop = true;
				rec_drain(r, fd);
			}
		}
		if (r->w.unflushed > 0 && rec_ms() - flushed >= REC_FLUSH_MS) {
			rec_flush(r);
			flushed = rec_ms();
		}
	}
}

static void rec_loop_lcm(struct rec *r, lcm_t *lcm, int sfd)
{
	lcm_subscription_t *sub = lcm_subscribe(lcm, ".*", rec_on_message, r);
	lcm_subscription_set_queue_capacity(sub, REC_QUEUE);
	struct pollfd p[2] = { { .fd = lcm_get_fileno(lcm), .events = POLLIN }, { .fd = sfd, .events = POLLIN } };
	while (!r->failed) {
		if (poll(p, 2, -1) < 0 && errno != EINTR)
			break;
		if (p[1].revents & POLLIN)
			break;
		if (p[0].revents & POLLIN)
			lcm_handle(lcm);
	}
	/* what was queued before the signal is kept */
	while (!r->failed && lcm_handle_timeout(lcm, 0) > 0)
		;
	lcm_unsubscribe(lcm, sub);
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
	struct udpm_url u;
	char why[256];
	if (url == NULL || url[0] == '\0')
		url = REC_DEFAULT_URL;
	if (!udpm_parse_url(url, &u, why, sizeof why)) {
		fprintf(stderr, "undulate-analyze: --record: %s\n", why);
		return AN_EXIT_USAGE;
	}
	bool udpm = strcmp(u.provider, "udpm") == 0;
	int sfd = rec_signal_fd();
	int fd = udpm && sfd >= 0 ? rec_open_udpm(url, &u) : -1;
	lcm_t *lcm = !udpm && sfd >= 0 ? lcm_create(url) : NULL;
	if (sfd < 0 || (udpm ? fd < 0 : lcm == NULL)) {
		fprintf(stderr, "undulate-analyze: --record: cannot open LCM at %s\n", url);
		return AN_EXIT_USAGE;
	}
	char err[1024];
	if (alog_writer_open(&r.w, path, err, sizeof err) != 0) {
		fprintf(stderr, "undulate-analyze: --record %s: %s\n", path, err);
		if (lcm != NULL)
			lcm_destroy(lcm);
		if (fd >= 0)
			close(fd);
		return AN_EXIT_OUTPUT;
	}
	printf("undulate-analyze: recording %s to %s\n", url, path);
	fflush(stdout);
	if (udpm) {
		alog_writer_buffer(&r.w);
		rec_loop_udpm(&r, fd, sfd);
		close(fd);
	} else {
		rec_loop_lcm(&r, lcm, sfd);
		lcm_destroy(lcm);
	}
	long long events = r.w.events;
	int rc = alog_writer_close(&r.w);
	if (rc != 0 && !r.failed)
		fprintf(stderr, "undulate-analyze: --record: cannot write: %s\n", strerror(errno));
	long long dropped = r.bad + r.lost + r.too_large + r.kernel_drops;
	printf("undulate-analyze: recorded %lld events (%.1f MB) to %s; dropped %lld (bad datagrams %lld, "
	       "lost fragments %lld, too large %lld, kernel %u)\n",
	       events, (double)r.bytes / 1e6, path, dropped, r.bad, r.lost, r.too_large, r.kernel_drops);
	for (int i = 0; i < REC_SENDERS; i++)
		free(r.senders[i].buf);
	close(sfd);
	return rc == 0 && !r.failed ? AN_EXIT_OK : AN_EXIT_OUTPUT;
}
