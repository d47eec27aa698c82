/*
 * notify.h — the systemd notification protocol without libsystemd: one
 * datagram per message to $NOTIFY_SOCKET (a path, or '@' for the abstract
 * namespace). READY=1 once the loop runs, WATCHDOG=1 while cycles complete,
 * STATUS=..., STOPPING=1. Without NOTIFY_SOCKET every call is a no-op.
 */
#ifndef UNDULATE_DAEMON_NOTIFY_H
#define UNDULATE_DAEMON_NOTIFY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/socket.h>
#include <sys/un.h>

struct notify {
	int fd;                        /* -1 when not under systemd */
	struct sockaddr_un addr;
	socklen_t addr_len;
	uint64_t watchdog_usec;        /* 0 = no watchdog requested */
};

/* Build the socket address from a NOTIFY_SOCKET value. False if unusable. */
bool notify_make_addr(const char *value, struct sockaddr_un *addr, socklen_t *len);
/* Read NOTIFY_SOCKET / WATCHDOG_USEC (/ WATCHDOG_PID) from the environment. */
void notify_init(struct notify *n);
void notify_close(struct notify *n);
bool notify_enabled(const struct notify *n);
/* Send one message ("READY=1\nSTATUS=..."). True if sent or disabled. */
bool notify_send(struct notify *n, const char *msg);
/* How often to send WATCHDOG=1: half the watchdog period, 0 if none. */
uint64_t notify_watchdog_interval_us(const struct notify *n);
/* Parse WATCHDOG_USEC (and WATCHDOG_PID against pid): µs, or 0. */
uint64_t notify_parse_watchdog(const char *usec, const char *pid_str, long pid);

/* The STATUS line: "STATUS=OSCILLATOR 100.0 Hz, 2 joints, bus ok, 0 overruns, ..." */
struct notify_status {
	const char *mode;
	double rate_hz;
	size_t njoints;
	bool bus_connected;
	long long overruns;
	long long bus_errors;
	long long faults;
	long long bad_commands;
};
int notify_format_status(char *buf, size_t cap, const struct notify_status *s);

#endif
