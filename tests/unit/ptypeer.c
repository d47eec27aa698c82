/*
 * ptypeer.c — scripted pty peer for tests (see ptypeer.h).
 */
#include "ptypeer.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

int ptypeer_open(struct ptypeer *p)
{
	const char *name;

	memset(p, 0, sizeof *p);
	p->master = posix_openpt(O_RDWR | O_NOCTTY);
	if (p->master < 0)
		return -1;
	if (grantpt(p->master) != 0 || unlockpt(p->master) != 0 ||
	    (name = ptsname(p->master)) == NULL || strlen(name) >= sizeof p->slave_path) {
		close(p->master);
		p->master = -1;
		return -1;
	}
	snprintf(p->slave_path, sizeof p->slave_path, "%s", name);
	return 0;
}

int ptypeer_write(struct ptypeer *p, const uint8_t *buf, size_t n)
{
	size_t done = 0;

	while (done < n) {
		ssize_t w = write(p->master, buf + done, n - done);
		if (w < 0 && errno == EINTR)
			continue;
		if (w <= 0)
			return -1;
		done += (size_t)w;
	}
	return 0;
}

static long ptypeer_ms_left(const struct timespec *end)
{
	struct timespec now;

	clock_gettime(CLOCK_MONOTONIC, &now);
	return (end->tv_sec - now.tv_sec) * 1000L + (end->tv_nsec - now.tv_nsec) / 1000000L;
}

size_t ptypeer_read(struct ptypeer *p, uint8_t *buf, size_t n, int timeout_ms)
{
	struct timespec end;
	size_t got = 0;

	clock_gettime(CLOCK_MONOTONIC, &end);
	end.tv_sec += timeout_ms / 1000;
	end.tv_nsec += (long)(timeout_ms % 1000) * 1000000L;
	if (end.tv_nsec >= 1000000000L) {
		end.tv_sec++;
		end.tv_nsec -= 1000000000L;
	}
	while (got < n) {
		long left = ptypeer_ms_left(&end);
		struct pollfd pfd = { .fd = p->master, .events = POLLIN };
		if (left <= 0)
			break;
		int r = poll(&pfd, 1, (int)left);
		if (r < 0 && errno == EINTR)
			continue;
		if (r <= 0)
			break;
		if (!(pfd.revents & POLLIN)) {
			/* POLLHUP with no slave open: nobody to hear from yet. */
			struct timespec nap = { 0, 1000000L };
			nanosleep(&nap, NULL);
			continue;
		}
		ssize_t rd = read(p->master, buf + got, n - got);
		if (rd > 0)
			got += (size_t)rd;
		else if (rd < 0 && errno != EINTR && errno != EAGAIN && errno != EIO)
			break;
	}
	return got;
}

static void ptypeer_fail(struct ptypeer *p, size_t step, const char *what)
{
	p->failed = true;
	snprintf(p->why, sizeof p->why, "step %zu: %s", step, what);
}

static void ptypeer_keep(struct ptypeer *p, const uint8_t *buf, size_t n)
{
	size_t room = sizeof p->log - p->log_len;

	if (n > room)
		n = room;
	memcpy(p->log + p->log_len, buf, n);
	p->log_len += n;
}

static bool ptypeer_step(struct ptypeer *p, size_t i)
{
	const struct ptypeer_step *s = &p->steps[i];
	uint8_t got[PTYPEER_LOG_MAX];

	if (s->expect != NULL && s->expect_len > 0) {
		size_t want = s->expect_len < sizeof got ? s->expect_len : sizeof got;
		size_t n = ptypeer_read(p, got, want, PTYPEER_STEP_TIMEOUT_MS);
		ptypeer_keep(p, got, n);
		if (n < want) {
			ptypeer_fail(p, i, "timed out waiting for the request");
			return false;
		}
		if (memcmp(got, s->expect, want) != 0) {
			ptypeer_fail(p, i, "request bytes differ from the script");
			return false;
		}
	}
	if (s->delay_us > 0) {
		struct timespec d = { (time_t)(s->delay_us / 1000000u),
		                      (long)(s->delay_us % 1000000u) * 1000L };
		nanosleep(&d, NULL);
	}
	if (s->reply != NULL && s->reply_len > 0 && ptypeer_write(p, s->reply, s->reply_len) != 0) {
		ptypeer_fail(p, i, "writing the reply failed");
		return false;
	}
	if (s->hang_up) {
		close(p->master);
		p->master = -1;
	}
	return true;
}

static void *ptypeer_main(void *arg)
{
	struct ptypeer *p = arg;

	for (size_t i = 0; i < p->nsteps && p->master >= 0; i++) {
		if (!ptypeer_step(p, i))
			break;
		p->steps_done = i + 1;
	}
	return NULL;
}

int ptypeer_start(struct ptypeer *p, const struct ptypeer_step *steps, size_t n)
{
	p->steps = steps;
	p->nsteps = n;
	p->steps_done = 0;
	p->failed = false;
	p->why[0] = '\0';
	p->log_len = 0;
	if (pthread_create(&p->thread, NULL, ptypeer_main, p) != 0)
		return -1;
	p->started = true;
	return 0;
}

bool ptypeer_join(struct ptypeer *p)
{
	if (p->started) {
		pthread_join(p->thread, NULL);
		p->started = false;
	}
	return !p->failed && p->steps_done == p->nsteps;
}

void ptypeer_close(struct ptypeer *p)
{
	(void)ptypeer_join(p);
	if (p->master >= 0)
		close(p->master);
	p->master = -1;
}
