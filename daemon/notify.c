/* notify.c — see notify.h. */
#include "notify.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

bool notify_make_addr(const char *value, struct sockaddr_un *addr, socklen_t *len)
{
	if (value == NULL)
		return false;
	size_t n = strlen(value);
	/* A path must be absolute; '@' names an abstract socket (leading NUL). */
	if (n < 2 || (value[0] != '/' && value[0] != '@') || n >= sizeof addr->sun_path)
		return false;
	memset(addr, 0, sizeof *addr);
	addr->sun_family = AF_UNIX;
	memcpy(addr->sun_path, value, n);
	if (value[0] == '@')
		addr->sun_path[0] = '\0';
	/* Abstract names are length-delimited, so the length must not include a
	 * terminating NUL; for paths it does not matter. */
	*len = (socklen_t)(offsetof(struct sockaddr_un, sun_path) + n);
	return true;
}

uint64_t notify_parse_watchdog(const char *usec, const char *pid_str, long pid)
{
	if (usec == NULL)
		return 0;
	char *end;
	errno = 0;
	unsigned long long v = strtoull(usec, &end, 10);
	if (end == usec || *end != '\0' || errno != 0 || v == 0)
		return 0;
	if (pid_str != NULL) {
		long want = strtol(pid_str, &end, 10);
		if (*end != '\0' || want != pid)
			return 0;   /* meant for another process */
	}
	return (uint64_t)v;
}

void notify_init(struct notify *n)
{
	memset(n, 0, sizeof *n);
	n->fd = -1;
	if (!notify_make_addr(getenv("NOTIFY_SOCKET"), &n->addr, &n->addr_len))
		return;
	n->fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
	n->watchdog_usec = notify_parse_watchdog(getenv("WATCHDOG_USEC"), getenv("WATCHDOG_PID"),
	                                         (long)getpid());
}

void notify_close(struct notify *n)
{
	if (n->fd >= 0)
		close(n->fd);
	n->fd = -1;
}

bool notify_enabled(const struct notify *n) { return n->fd >= 0; }

bool notify_send(struct notify *n, const char *msg)
{
	if (n->fd < 0)
		return true;
	ssize_t r = sendto(n->fd, msg, strlen(msg), MSG_NOSIGNAL, (const struct sockaddr *)&n->addr,
	                   n->addr_len);
	return r == (ssize_t)strlen(msg);
}

uint64_t notify_watchdog_interval_us(const struct notify *n)
{
	return n->watchdog_usec / 2;
}

int notify_format_status(char *buf, size_t cap, const struct notify_status *s)
{
	return snprintf(buf, cap,
	                "STATUS=%s %.1f Hz, %zu joints, bus %s, %lld overruns, %lld bus errors, "
	                "%lld faults, %lld bad commands",
	                s->mode, s->rate_hz, s->njoints, s->bus_connected ? "ok" : "lost", s->overruns,
	                s->bus_errors, s->faults, s->bad_commands);
}
