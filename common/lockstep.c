/* lockstep.c — see lockstep.h. */
#include "lockstep.h"

#include <errno.h>
#include <stdbool.h>
#include <limits.h>
#include <poll.h>
#include <stdlib.h>
#include <stdio.h>
#include <stdint.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <sys/un.h>
#include <unistd.h>

#include "clock.h"

const char *lks_type_name(uint32_t type)
{
	static const char *const names[] = {
		[LKS_HELLO] = "HELLO", [LKS_WELCOME] = "WELCOME", [LKS_WAIT] = "WAIT", [LKS_TIME] = "TIME",
		[LKS_CMD] = "CMD", [LKS_STOP] = "STOP", [LKS_REFUSED] = "REFUSED", [LKS_BYE] = "BYE", [LKS_PART] = "PART",
	};
	return type < sizeof names / sizeof names[0] && names[type] ? names[type] : "UNKNOWN";
}

int lks_send(int fd, const struct lks_msg *m)
{
	if (m->nbytes > LKS_BYTES_MAX) {
		errno = EMSGSIZE;
		return -1;
	}
	/* the header with the magic set, then only the payload's used part */
	struct lks_msg hdr;
	memcpy(&hdr, m, LKS_HEADER_SIZE);
	hdr.magic = LKS_MAGIC;
	struct iovec iov[2] = {
		{ .iov_base = &hdr, .iov_len = LKS_HEADER_SIZE },
		{ .iov_base = (void *)(uintptr_t)m->bytes, .iov_len = m->nbytes },
	};
	struct msghdr mh = { .msg_iov = iov, .msg_iovlen = m->nbytes > 0 ? 2 : 1 };
	size_t want = LKS_HEADER_SIZE + m->nbytes;
	ssize_t n;
	do {
		n = sendmsg(fd, &mh, MSG_NOSIGNAL);
	} while (n < 0 && errno == EINTR);
	if (n == (ssize_t)want)
		return 0;
	if (n >= 0)
		errno = EMSGSIZE;
	return -1;
}

int lks_recv(int fd, struct lks_msg *m, char *why, size_t cap)
{
	ssize_t n;
	do {
		n = recv(fd, m, sizeof *m, MSG_TRUNC);
	} while (n < 0 && errno == EINTR);
	if (n == 0 || (n < 0 && errno == ECONNRESET))
		return 0;   /* the peer is gone (reset: it left with our messages unread) */
	if (n < 0) {
		snprintf(why, cap, "lockstep socket: %s", strerror(errno));
		return -1;
	}
	if (n < (ssize_t)LKS_HEADER_SIZE || m->magic != LKS_MAGIC || m->type < LKS_HELLO || m->type > LKS_PART) {
		snprintf(why, cap, "lockstep socket: not a lockstep message (%zd bytes, magic %08x): the two "
		         "programs are from different builds?", n, n >= 4 ? m->magic : 0u);
		errno = EPROTO;
		return -1;
	}
	if (n > (ssize_t)sizeof *m || m->nbytes > LKS_BYTES_MAX) {
		snprintf(why, cap, "lockstep socket: a %s of %zd bytes (it says %u bus bytes): at most %d bus bytes a "
		         "message", lks_type_name(m->type), n, m->nbytes, LKS_BYTES_MAX);
		errno = EPROTO;
		return -1;
	}
	if ((size_t)n != LKS_HEADER_SIZE + m->nbytes) {
		snprintf(why, cap, "lockstep socket: a %s of %zd bytes says it carries %u bus bytes (%zu would be "
		         "%zu bytes)", lks_type_name(m->type), n, m->nbytes, (size_t)m->nbytes,
		         LKS_HEADER_SIZE + m->nbytes);
		errno = EPROTO;
		return -1;
	}
	m->name[LKS_NAME_MAX - 1] = '\0';
	m->text[LKS_TEXT_MAX - 1] = '\0';
	return 1;
}

static int lks_address(const char *path, struct sockaddr_un *sa, char *err, size_t cap)
{
	memset(sa, 0, sizeof *sa);
	sa->sun_family = AF_UNIX;
	if (path == NULL || path[0] == '\0' || strlen(path) >= sizeof sa->sun_path) {
		snprintf(err, cap, "lockstep socket path '%s': empty or longer than %zu bytes", path ? path : "",
		         sizeof sa->sun_path - 1);
		return -1;
	}
	memcpy(sa->sun_path, path, strlen(path) + 1);
	return 0;
}

int lks_listen(const char *path, char *err, size_t cap)
{
	struct sockaddr_un sa;
	if (lks_address(path, &sa, err, cap) != 0)
		return -1;
	struct stat st;
	if (lstat(path, &st) == 0) {
		if (!S_ISSOCK(st.st_mode)) {
			snprintf(err, cap, "lockstep socket %s: something that is not a socket is there", path);
			return -1;
		}
		/* a live simulator's is refused, not replaced: a connection there
		 * succeeds (it accepts, sees nobody register, and drops it) */
		int probe = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
		bool alive = probe >= 0 && connect(probe, (struct sockaddr *)&sa, sizeof sa) == 0;
		if (probe >= 0)
			close(probe);
		if (alive) {
			snprintf(err, cap, "lockstep socket %s: another simulator listens on it", path);
			return -1;
		}
		unlink(path);   /* a stale socket of an earlier run */
	}
	int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
	if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0 || listen(fd, 64) != 0) {
		snprintf(err, cap, "lockstep socket %s: %s", path, strerror(errno));
		if (fd >= 0)
			close(fd);
		return -1;
	}
	return fd;
}

/* ---- the daemon's side ------------------------------------------------------------ */

static void lks_client_set_clock(struct lks_client *c, uint64_t t_ns)
{
	c->t_ns = t_ns;
	clock_set_virtual(c->mono0_us + t_ns / 1000u, c->wall0_us + (int64_t)(t_ns / 1000u));
}

uint64_t lks_client_now_us(const struct lks_client *c) { return c->mono0_us + c->t_ns / 1000u; }

/* Wait up to ms for the socket to be readable: 1, 0 (time out), -1. */
static int lks_poll_in(int fd, int ms)
{
	struct pollfd p = { .fd = fd, .events = POLLIN };
	int r;
	do {
		r = poll(&p, 1, ms);
	} while (r < 0 && errno == EINTR);
	return r;
}

/* One HELLO for ports[i], index i of n. 0, or -1 with err. */
static int lks_client_hello(struct lks_client *c, const char *port_path, size_t i, size_t n, const char *robot,
                            char *err, size_t cap)
{
	/* the simulator knows its buses by their pty: name the device the link
	 * points at, wherever either program was started */
	char resolved[PATH_MAX];
	struct lks_msg m = { .type = LKS_HELLO, .a = (uint64_t)getpid(), .b = n, .c = i };
	const char *name = realpath(port_path, resolved) ? resolved : port_path;
	if (strlen(name) >= sizeof m.text) {
		snprintf(err, cap, "lockstep: port path longer than %zu bytes", sizeof m.text - 1);
		return -1;
	}
	memcpy(m.text, name, strlen(name) + 1);
	snprintf(m.name, sizeof m.name, "%s", robot);
	if (lks_send(c->fd, &m) != 0) {
		snprintf(err, cap, "lockstep: %s", strerror(errno));
		return -1;
	}
	return 0;
}

/* The answer to HELLO i: 0 (WELCOME), or -1 with err. */
static int lks_client_welcome(struct lks_client *c, const char *sock_path, const char *port_path, char *err,
                              size_t cap)
{
	struct lks_msg m;
	char why[200];
	int r;
	if ((r = lks_poll_in(c->fd, LKS_CLIENT_GRACE_MS)) <= 0) {
		snprintf(err, cap, "lockstep: the simulator at %s did not answer in %d s", sock_path,
		         LKS_CLIENT_GRACE_MS / 1000);
	} else if ((r = lks_recv(c->fd, &m, why, sizeof why)) <= 0) {
		snprintf(err, cap, "lockstep: %s", r == 0 ? "the simulator closed the socket" : why);
	} else if (m.type == LKS_REFUSED) {
		snprintf(err, cap, "lockstep: the simulator refused %s: %s", port_path, m.text);
	} else if (m.type != LKS_WELCOME) {
		snprintf(err, cap, "lockstep: the simulator answered %s to HELLO", lks_type_name(m.type));
	} else {
		c->mono0_us = m.b;
		c->wall0_us = (int64_t)m.c;
		c->inband = (m.flags & LKS_INBAND) != 0;
		lks_client_set_clock(c, m.a);
		return 0;
	}
	return -1;
}

int lks_client_open_buses(struct lks_client *c, const char *sock_path, const char *const *ports, size_t nports,
                          const char *robot, char *err, size_t cap)
{
	memset(c, 0, sizeof *c);
	c->fd = -1;
	if (nports == 0 || nports > LKS_BUSES_MAX) {
		snprintf(err, cap, "lockstep: %zu buses: a daemon drives 1 to %d", nports, LKS_BUSES_MAX);
		return -1;
	}
	struct sockaddr_un sa;
	if (lks_address(sock_path, &sa, err, cap) != 0)
		return -1;
	c->fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
	if (c->fd < 0 || connect(c->fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
		snprintf(err, cap, "lockstep: cannot reach the simulator at %s: %s (is undulate-sim running with "
		         "--lockstep %s?)", sock_path, strerror(errno), sock_path);
		lks_client_close(c);
		return -1;
	}
	/* each answered before the next goes: a refusal names its port */
	for (size_t i = 0; i < nports; i++)
		if (lks_client_hello(c, ports[i], i, nports, robot, err, cap) != 0 ||
		    lks_client_welcome(c, sock_path, ports[i], err, cap) != 0) {
			lks_client_close(c);
			return -1;
		}
	c->nbuses = nports;
	return 0;
}

int lks_client_open(struct lks_client *c, const char *sock_path, const char *port_path, const char *robot,
                    char *err, size_t cap)
{
	return lks_client_open_buses(c, sock_path, &port_path, 1, robot, err, cap);
}

/* In-band: what was written on bus since the last WAIT goes with this message. */
static void lks_client_take_out(struct lks_client *c, size_t bus, struct lks_msg *m)
{
	struct lks_bus *b = &c->bus[bus];
	if (!c->inband)
		return;
	memcpy(m->bytes, b->out, b->nout);
	m->nbytes = (uint32_t)b->nout;
	b->nout = 0;
}

/* A WAIT's or BYE's news for bus (its flags; the message's own for bus 0). */
static uint32_t lks_client_flags(struct lks_client *c, size_t bus, unsigned want_input)
{
	struct lks_bus *b = &c->bus[bus];
	uint32_t f = ((want_input >> bus) & 1u ? LKS_WANT_INPUT : 0u) | (b->port_opened ? LKS_PORT_OPENED : 0u) |
	             (b->rate_set ? LKS_RATE_SET : 0u);
	b->port_opened = b->rate_set = false;
	return f;
}

/* The PARTs that go before a WAIT or BYE: every bus but the first. */
static int lks_client_parts(struct lks_client *c, unsigned want_input)
{
	for (size_t i = 1; i < c->nbuses; i++) {
		struct lks_msg m = { .type = LKS_PART, .c = i, .flags = lks_client_flags(c, i, want_input) };
		lks_client_take_out(c, i, &m);
		if (lks_send(c->fd, &m) != 0)
			return -1;
	}
	return 0;
}

/* In-band: a TIME's bytes after the ones not read yet; what does not fit is
 * counted (the daemon reads every TIME's bytes before it waits again, so
 * this takes a bus that talks without being asked). */
static void lks_client_deliver(struct lks_bus *c, const uint8_t *bytes, size_t n)
{
	if (c->in_off > 0) {
		memmove(c->in, c->in + c->in_off, c->nin - c->in_off);
		c->nin -= c->in_off;
		c->in_off = 0;
	}
	size_t room = sizeof c->in - c->nin;
	size_t take = n < room ? n : room;
	memcpy(c->in + c->nin, bytes, take);
	c->nin += take;
	c->in_dropped += (long long)(n - take);
}

void lks_client_port_opened(struct lks_client *c, size_t bus)
{
	struct lks_bus *b = &c->bus[bus];
	if (bus == 0)
		c->consumed = c->delivered;
	b->in_off = b->nin = 0;
	b->nout = 0;
	b->bus_gone = false;
	b->port_opened = true;
}

void lks_client_close(struct lks_client *c)
{
	if (c->fd < 0)
		return;
	struct lks_msg m = { .type = LKS_BYE };
	lks_client_take_out(c, 0, &m);
	/* the other buses' last bytes in PARTs before it; not while a WAIT is
	 * out: the simulator takes a PART only before a WAIT or BYE of a
	 * daemon it is not holding, and a daemon that left without its TIME
	 * wrote nothing since that WAIT */
	if (c->waiting || lks_client_parts(c, 0) == 0)
		(void)lks_send(c->fd, &m);
	close(c->fd);
	c->fd = -1;
}

int lks_client_wait(struct lks_client *c, uint64_t wake_us, unsigned want_input)
{
	if (c->fd < 0)
		return -1;
	if (c->waiting)
		return 0;
	uint64_t wake_ns = LKS_NEVER;
	if (wake_us != UINT64_MAX)
		wake_ns = wake_us > c->mono0_us ? (wake_us - c->mono0_us) * 1000u : 0;
	if (lks_client_parts(c, want_input) != 0)
		return -1;
	struct lks_msg m = { .type = LKS_WAIT, .a = wake_ns, .b = c->written, .flags = lks_client_flags(c, 0, want_input) };
	lks_client_take_out(c, 0, &m);
	if (lks_send(c->fd, &m) != 0)
		return -1;
	c->waiting = true;
	return 0;
}

int lks_client_read(struct lks_client *c, char *why, size_t cap)
{
	struct lks_msg m;
	int r = lks_recv(c->fd, &m, why, cap);
	if (r <= 0)
		return r;
	if (m.nbytes > 0 && ((m.type != LKS_TIME && m.type != LKS_PART) || !c->inband)) {
		snprintf(why, cap, "lockstep: a %s from the simulator carries %u bus bytes (%s)", lks_type_name(m.type),
		         m.nbytes, c->inband ? "only a TIME or a PART does" : "the bytes go through the pty in this run");
		errno = EPROTO;
		return -1;
	}
	switch (m.type) {
	case LKS_PART:
		if (m.c < 1 || m.c >= c->nbuses) {
			c->bad_parts++;
			snprintf(why, cap, "lockstep: a PART from the simulator for bus %llu; this daemon named %zu bus(es)",
			         (unsigned long long)m.c, c->nbuses);
			errno = EPROTO;
			return -1;
		}
		c->bus[m.c].bus_gone = (m.flags & LKS_BUS_GONE) != 0;
		lks_client_deliver(&c->bus[m.c], m.bytes, m.nbytes);
		break;
	case LKS_TIME:
		c->waiting = false;
		c->time_moved = true;
		c->delivered = m.b;
		c->bus[0].bus_gone = (m.flags & LKS_BUS_GONE) != 0;
		lks_client_deliver(&c->bus[0], m.bytes, m.nbytes);
		lks_client_set_clock(c, m.a > c->t_ns ? m.a : c->t_ns);
		break;
	case LKS_CMD:
		if (c->ncmds < LKS_CMD_QUEUE)
			snprintf(c->cmds[c->ncmds++], LKS_TEXT_MAX, "%s", m.text);
		else
			c->cmds_dropped++;
		break;
	case LKS_STOP:
		c->stop = true;
		snprintf(c->stop_why, sizeof c->stop_why, "%s", m.text);
		break;
	default:
		snprintf(why, cap, "lockstep: unexpected %s from the simulator", lks_type_name(m.type));
		errno = EPROTO;
		return -1;
	}
	return (int)m.type;
}

int lks_client_block(struct lks_client *c, uint64_t wake_us, unsigned want_input, char *why, size_t cap)
{
	if (lks_client_wait(c, wake_us, want_input) != 0) {
		snprintf(why, cap, "lockstep: the simulator is gone (%s)", strerror(errno));
		return -1;
	}
	while (c->waiting) {
		int r = lks_poll_in(c->fd, LKS_CLIENT_GRACE_MS);
		if (r == 0) {
			snprintf(why, cap, "lockstep: no word from the simulator for %d s", LKS_CLIENT_GRACE_MS / 1000);
			return -1;
		}
		if (r < 0 || (r = lks_client_read(c, why, cap)) < 0)
			return -1;
		if (r == 0) {
			snprintf(why, cap, "lockstep: the simulator closed the socket");
			return -1;
		}
	}
	return 0;
}

bool lks_client_take_time(struct lks_client *c)
{
	bool moved = c->time_moved;
	c->time_moved = false;
	return moved;
}

bool lks_client_next_cmd(struct lks_client *c, char *out, size_t cap)
{
	if (c->ncmds == 0)
		return false;
	snprintf(out, cap, "%s", c->cmds[0]);
	memmove(c->cmds[0], c->cmds[1], (c->ncmds - 1) * sizeof c->cmds[0]);
	c->ncmds--;
	return true;
}
