/* wsrecv.c — see wsrecv.h. */
/* recv() is defined here: with _FORTIFY_SOURCE glibc's header would make it
 * an inline wrapper of its own */
#undef _FORTIFY_SOURCE
#include "wsrecv.h"

#include <sys/socket.h>
#include <sys/types.h>

static struct wsr_slot {
	bool on;
	struct wsg g;
} wsr_slots[WSR_FDS];

static bool wsr_seen;   /* recv() was called on a watched descriptor */

ssize_t recv(int fd, void *buf, size_t len, int flags)
{
	ssize_t n = recvfrom(fd, buf, len, flags, NULL, NULL);
	if (n > 0 && !(flags & MSG_PEEK) && fd >= 0 && fd < WSR_FDS && wsr_slots[fd].on) {
		wsr_seen = true;
		wsg_feed(&wsr_slots[fd].g, buf, (size_t)n);
	}
	return n;
}

bool wsr_watch(int fd)
{
	if (fd < 0 || fd >= WSR_FDS)
		return false;
	wsr_slots[fd].on = true;
	wsg_init(&wsr_slots[fd].g);
	return true;
}

enum wsg_verdict wsr_upgraded(int fd)
{
	if (fd < 0 || fd >= WSR_FDS || !wsr_slots[fd].on)
		return WSG_EARLY;
	return wsg_upgraded(&wsr_slots[fd].g);
}

enum wsg_verdict wsr_verdict(int fd)
{
	return fd >= 0 && fd < WSR_FDS && wsr_slots[fd].on ? wsg_verdict(&wsr_slots[fd].g) : WSG_OK;
}

void wsr_forget(int fd)
{
	if (fd >= 0 && fd < WSR_FDS)
		wsr_slots[fd].on = false;
}

bool wsr_interposed(void)
{
	return wsr_seen;
}
