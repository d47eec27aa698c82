/* vtime.c — see vtime.h. */
#include "vtime.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

int vt_open(struct vt *v, const char *path, size_t expected, uint64_t mono0_us, int64_t wall0_us, char *err,
            size_t cap)
{
	memset(v, 0, sizeof *v);
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
		v->c[i].fd = -1;
	v->expected = expected;
	v->inband = true;
	v->mono0_us = mono0_us;
	v->wall0_us = wall0_us;
	snprintf(v->path, sizeof v->path, "%s", path);
	v->listen_fd = lks_listen(path, err, cap);
	return v->listen_fd >= 0 ? 0 : -1;
}

static void vt_drop(struct vt *v, struct vt_client *c)
{
	if (c->fd >= 0)
		close(c->fd);
	if (c->bus >= 0)
		v->left++;
	memset(c, 0, sizeof *c);
	c->fd = -1;
	c->bus = -1;
}

void vt_close(struct vt *v)
{
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
		if (v->c[i].fd >= 0)
			vt_drop(v, &v->c[i]);
	if (v->listen_fd >= 0) {
		close(v->listen_fd);
		unlink(v->path);
	}
	v->listen_fd = -1;
}

void vt_accept(struct vt *v)
{
	int fd = accept(v->listen_fd, NULL, NULL);
	if (fd < 0)
		return;
	fcntl(fd, F_SETFD, FD_CLOEXEC);
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
		if (v->c[i].fd < 0) {
			memset(&v->c[i], 0, sizeof v->c[i]);
			v->c[i].fd = fd;
			v->c[i].bus = -1;
			return;
		}
	struct lks_msg m = { .type = LKS_REFUSED };
	snprintf(m.text, sizeof m.text, "too many connections to the lockstep socket");
	(void)lks_send(fd, &m);
	close(fd);
	v->refused++;
}

size_t vt_clients(const struct vt *v)
{
	size_t n = 0;
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
		n += v->c[i].fd >= 0 && v->c[i].bus >= 0;
	return n;
}

size_t vt_buses_covered(const struct vt *v)
{
	size_t n = 0;
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
		if (v->c[i].fd >= 0 && v->c[i].bus >= 0)
			n += v->c[i].nl;
	return n;
}

/* The daemon (joined or joining) that named bus: its index, and which of
 * its links it is (-1: none). */
static int vt_owner_at(const struct vt *v, int bus, size_t *link)
{
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
		for (size_t k = 0; v->c[i].fd >= 0 && k < v->c[i].nl; k++)
			if (v->c[i].l[k].bus == bus) {
				if (link)
					*link = k;
				return (int)i;
			}
	return -1;
}

static struct vt_client *vt_owner(struct vt *v, int bus, struct vt_link **link)
{
	size_t k = 0;
	int i = vt_owner_at(v, bus, &k);
	if (i < 0)
		return NULL;
	if (link)
		*link = &v->c[i].l[k];
	return &v->c[i];
}

/* The bus a daemon names: its pty's device (the daemon resolves its link)
 * or the link itself. -1 if none. */
static int vt_find_bus(const struct sim *s, const char *path)
{
	char resolved[PATH_MAX];
	for (size_t i = 0; i < s->nbuses; i++) {
		const struct sim_bus *b = &s->buses[i];
		if (!strcmp(path, b->link) || (b->slave_path[0] && !strcmp(path, b->slave_path)))
			return (int)i;
		if (realpath(b->link, resolved) && !strcmp(path, resolved))
			return (int)i;
	}
	return -1;
}

void vt_end(struct vt *v, bool failed, const char *why);

/* A joined daemon refused leaves the run, which cannot go on without it. */
static void vt_refuse(struct vt *v, struct vt_client *c, const char *why)
{
	struct lks_msg m = { .type = LKS_REFUSED };
	snprintf(m.text, sizeof m.text, "%s", why);
	(void)lks_send(c->fd, &m);
	fprintf(stderr, "undulate-sim: lockstep: refused a daemon (pid %ld, robot '%s'): %s\n", c->pid, c->robot, why);
	v->refused++;
	if (c->bus >= 0 && !v->ending) {
		char what[LKS_TEXT_MAX + 64];
		snprintf(what, sizeof what, "robot %s's daemon (pid %ld) was refused: %s", c->robot, c->pid, why);
		vt_end(v, true, what);
	}
	vt_drop(v, c);
}

static void vt_hello(struct vt *v, const struct sim *s, struct vt_client *c, const struct lks_msg *m,
                     int64_t wall_ns)
{
	char why[LKS_TEXT_MAX + 64];
	uint64_t n = m->b > 0 ? m->b : 1;   /* buses it drives: one HELLO each, in index order */
	if (c->nl == 0) {
		c->pid = (long)m->a;
		snprintf(c->robot, sizeof c->robot, "%s", m->name);
		c->nnamed = n <= LKS_BUSES_MAX ? (size_t)n : 0;
	}
	int bus = vt_find_bus(s, m->text);
	if (v->ending)
		return vt_refuse(v, c, "the run is over");
	if (n > LKS_BUSES_MAX || n != c->nnamed || m->c != c->nl) {
		snprintf(why, sizeof why, "a HELLO for bus %llu of %llu after %zu of %zu: one HELLO a bus, in index order, "
		         "at most %d", (unsigned long long)m->c, (unsigned long long)n, c->nl, c->nnamed, LKS_BUSES_MAX);
		v->bad_messages++;
		return vt_refuse(v, c, why);
	}
	if (n > 1 && !v->inband)
		return vt_refuse(v, c, "the pty transport (--lockstep-pty) carries one bus a daemon: run a robot on several "
		                       "buses with the bytes in band (the default)");
	if (bus < 0) {
		snprintf(why, sizeof why, "no bus of this simulation is at %.200s", m->text);
		return vt_refuse(v, c, why);
	}
	const struct vt_client *owner = vt_owner(v, bus, NULL);
	if (owner != NULL) {
		snprintf(why, sizeof why, "bus %s already has a daemon (pid %ld)", s->buses[bus].name, owner->pid);
		return vt_refuse(v, c, why);
	}
	c->l[c->nl++] = (struct vt_link){ .bus = bus };
	if (c->nl == 1) {
		c->rx_base = s->buses[bus].count.rx_bytes;
		c->tx_base = s->buses[bus].count.tx_bytes;
	}
	c->running_since_ns = wall_ns;
	struct lks_msg w = { .type = LKS_WELCOME, .a = v->t_ns, .b = v->mono0_us, .c = (uint64_t)v->wall0_us,
	                     .flags = v->inband ? LKS_INBAND : 0 };
	if (lks_send(c->fd, &w) != 0) {
		vt_drop(v, c);
		return;
	}
	if (c->nl == c->nnamed) {
		c->bus = c->l[0].bus;   /* joined: every bus it drives is named */
		v->joined++;
	}
	fprintf(stderr, "undulate-sim: lockstep: robot %s (pid %ld) joined on bus %s at t=%.3f s\n", c->robot, c->pid,
	        s->buses[bus].name, 1e-9 * (double)v->t_ns);
}

void vt_end(struct vt *v, bool failed, const char *why)
{
	if (!v->ending) {
		snprintf(v->end_why, sizeof v->end_why, "%s", why);
		v->failed = failed;
	} else if (failed && !v->failed) {
		v->failed = true;
	}
	v->ending = true;
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
		if (v->c[i].fd >= 0 && v->c[i].bus >= 0 && !v->c[i].stop_sent)
			v->c[i].stop_pending = true;
}

/* Its port is on the bus's pty now (in-band: the one the bytes are for). */
static bool vt_attached(const struct vt_link *l, const struct sim *s)
{
	const struct sim_bus *b = &s->buses[l->bus];
	return sim_bus_connected(b) && l->port_open == b->opens;
}

/* In-band: the bytes a daemon wrote, into its bus at the time it wrote them
 * (now: time has not moved since its last TIME). Bytes for a port that is
 * gone are lost, as the pty's write would have failed; bytes on the pty
 * transport do not belong in a message. Both counted, said once. */
static void vt_bytes_in(struct vt *v, struct sim *s, struct vt_client *c, struct vt_link *l,
                        const struct lks_msg *m)
{
	if (m->nbytes == 0)
		return;
	if (v->inband && vt_attached(l, s)) {
		sim_bus_receive(&s->buses[l->bus], m->bytes, m->nbytes, (int64_t)v->t_ns, l->rate_unread);
		l->rate_unread = false;
		return;
	}
	v->bytes_lost += m->nbytes;
	if (!l->said_lost)
		fprintf(stderr, "undulate-sim: lockstep: robot %s's daemon (pid %ld) sent %u bus byte(s) in a %s %s; "
		        "dropped (counted; said once)\n", c->robot, c->pid, m->nbytes, lks_type_name(m->type),
		        !v->inband ? "on the pty transport, which carries them through the pty" : "for a port not open (or gone)");
	l->said_lost = true;
}

/* A WAIT's (bus 0) or a PART's news for one of its buses. */
static void vt_link_news(struct vt *v, struct sim *s, struct vt_client *c, struct vt_link *l, const struct lks_msg *m)
{
	if (m->flags & LKS_PORT_OPENED) {
		const struct sim_bus *b = &s->buses[l->bus];
		l->port_open = sim_bus_connected(b) ? b->opens : 0;
		l->nout = 0;   /* released for the port before, which the daemon closed */
	}
	if (m->flags & (LKS_PORT_OPENED | LKS_RATE_SET))
		l->rate_unread = true;
	vt_bytes_in(v, s, c, l, m);
	l->want_input = (m->flags & LKS_WANT_INPUT) != 0;
}

/* A PART: bus m->c's share of the WAIT or BYE that follows. One for a bus
 * the daemon did not name, or while it is blocked, is refused (counted). */
static void vt_part(struct vt *v, struct sim *s, struct vt_client *c, const struct lks_msg *m)
{
	if (c->bus >= 0 && !c->blocked && m->c >= 1 && m->c < c->nl)
		return vt_link_news(v, s, c, &c->l[m->c], m);
	char why[160];
	v->bad_messages++;
	v->bad_parts++;
	snprintf(why, sizeof why, "a PART for bus %llu%s; it named %zu bus(es)", (unsigned long long)m->c,
	         c->blocked ? " while it waits" : "", c->nl);
	vt_refuse(v, c, why);
}

void vt_on_client(struct vt *v, struct sim *s, size_t i, int64_t wall_ns)
{
	struct vt_client *c = &v->c[i];
	struct lks_msg m;
	char why[200];
	int r = lks_recv(c->fd, &m, why, sizeof why);
	if (r > 0 && m.type == LKS_BYE && c->bus >= 0)
		vt_bytes_in(v, s, c, &c->l[0], &m);   /* its safe stop's last bytes, not waited on */
	if (r <= 0 || m.type == LKS_BYE) {
		if (r < 0) {
			v->bad_messages++;
			fprintf(stderr, "undulate-sim: %s\n", why);
		}
		bool joined = c->bus >= 0;
		char what[200];
		snprintf(what, sizeof what, "robot %s's daemon (pid %ld) left the run at t=%.3f s", c->robot, c->pid,
		         1e-9 * (double)v->t_ns);
		if (joined && !v->ending)
			vt_end(v, true, what);
		if (joined)
			fprintf(stderr, "undulate-sim: lockstep: %s%s\n", what, v->ending && !v->failed ? "" : "");
		vt_drop(v, c);
		return;
	}
	if (m.type == LKS_HELLO && c->bus < 0)
		return vt_hello(v, s, c, &m, wall_ns);
	if (m.type == LKS_PART)
		return vt_part(v, s, c, &m);
	if (m.type != LKS_WAIT || c->bus < 0) {
		v->bad_messages++;
		snprintf(why, sizeof why, "%s out of turn", lks_type_name(m.type));
		return vt_refuse(v, c, why);
	}
	vt_link_news(v, s, c, &c->l[0], &m);
	c->blocked = true;
	c->wake_ns = m.a;
	c->written = m.b;
}

void vt_hand_over(struct vt *v, struct sim *s, int64_t now)
{
	uint8_t scratch[LKS_BYTES_MAX];
	for (size_t bus = 0; bus < s->nbuses; bus++) {
		struct vt_link *to = NULL;
		struct vt_client *c = vt_owner(v, (int)bus, &to);
		if (c != NULL && (c->bus < 0 || !vt_attached(to, s)))
			to = NULL;
		struct sim_bus *b = &s->buses[bus];
		if (to == NULL) {
			/* no port open on it: the bytes go, as into a pty nobody reads */
			(void)sim_bus_hand_over(b, now, scratch, sizeof scratch);
			continue;
		}
		uint64_t dropped = b->count.tx_dropped;
		to->nout += sim_bus_hand_over(b, now, to->out + to->nout, sizeof to->out - to->nout);
		if (b->count.tx_dropped > dropped && v->bytes_dropped == 0)
			fprintf(stderr, "undulate-sim: lockstep: bus %s: more bytes toward robot %s's daemon than a clock "
			        "message carries (%d) before it woke; dropped (counted in the bus's tx_dropped)\n", b->name,
			        c->robot, LKS_BYTES_MAX);
		v->bytes_dropped += b->count.tx_dropped - dropped;
	}
}

/* Every byte the daemon wrote has reached our side of its pty (in-band
 * they came with its WAIT). */
static bool vt_caught_up(const struct vt *v, const struct vt_client *c, const struct sim *s)
{
	const struct sim_bus *b = &s->buses[c->bus];
	return v->inband || !sim_bus_connected(b) || b->count.rx_bytes - c->rx_base >= c->written;
}

bool vt_all_blocked(const struct vt *v, const struct sim *s)
{
	if (!v->ending && vt_buses_covered(v) < v->expected)
		return false;
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++) {
		const struct vt_client *c = &v->c[i];
		if (c->fd < 0)
			continue;
		if (c->bus < 0 || !c->blocked || !vt_caught_up(v, c, s))
			return false;
	}
	return true;
}

static uint64_t vt_delivered(const struct vt_client *c, const struct sim *s)
{
	return s->buses[c->bus].count.tx_bytes - c->tx_base;
}

/* Bytes released toward it on a bus it waits for input on that it has not
 * been told of. */
static bool vt_news(const struct vt *v, const struct vt_client *c, const struct sim *s)
{
	if (!v->inband)
		return c->l[0].want_input && vt_delivered(c, s) > c->told;
	for (size_t k = 0; k < c->nl; k++)
		if (c->l[k].want_input && c->l[k].nout > 0)
			return true;
	return false;
}

/* Something to tell it now, whatever its wake-up. */
static bool vt_due_now(const struct vt *v, const struct vt_client *c, const struct sim *s)
{
	return c->ncmds > 0 || c->stop_pending || vt_news(v, c, s);
}

/* In-band: a TIME's (bus 0) or PART's flags and bytes for link l. */
static void vt_link_out(const struct sim *s, struct vt_link *l, struct lks_msg *m)
{
	/* what the pty's EIO says on the other transport */
	if (l->port_open != 0 && !vt_attached(l, s))
		m->flags |= LKS_BUS_GONE;
	memcpy(m->bytes, l->out, l->nout);
	m->nbytes = (uint32_t)l->nout;
	l->nout = 0;
}

uint64_t vt_next_wake(const struct vt *v, const struct sim *s)
{
	uint64_t t = LKS_NEVER;
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++) {
		const struct vt_client *c = &v->c[i];
		if (c->fd < 0 || c->bus < 0 || !c->blocked)
			continue;
		uint64_t w = vt_due_now(v, c, s) ? v->t_ns : c->wake_ns;
		if (w < t)
			t = w;
	}
	return t;
}

void vt_release(struct vt *v, const struct sim *s, uint64_t t, int64_t wall_ns)
{
	v->t_ns = t;
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++) {
		struct vt_client *c = &v->c[i];
		if (c->fd < 0 || c->bus < 0 || !c->blocked || (c->wake_ns > t && !vt_due_now(v, c, s)))
			continue;
		bool ok = true;
		for (size_t k = 0; k < c->ncmds && ok; k++) {
			struct lks_msg m = { .type = LKS_CMD };
			snprintf(m.text, sizeof m.text, "%s", c->cmds[k]);
			ok = lks_send(c->fd, &m) == 0;
		}
		c->ncmds = 0;
		if (ok && c->stop_pending) {
			struct lks_msg m = { .type = LKS_STOP };
			snprintf(m.text, sizeof m.text, "%.*s", (int)sizeof m.text - 1, v->end_why);
			ok = lks_send(c->fd, &m) == 0;
			c->stop_pending = false;
			c->stop_sent = true;
		}
		c->told = vt_delivered(c, s);
		struct lks_msg m = { .type = LKS_TIME, .a = t, .b = c->told };
		for (size_t k = 1; k < c->nl && ok; k++) {   /* in-band only: the pty transport is one bus */
			struct lks_msg part = { .type = LKS_PART, .c = k };
			vt_link_out(s, &c->l[k], &part);
			ok = lks_send(c->fd, &part) == 0;
		}
		if (v->inband)
			vt_link_out(s, &c->l[0], &m);
		if (!ok || lks_send(c->fd, &m) != 0) {
			/* it is gone: its socket's end is read next, and says so */
			c->blocked = false;
			continue;
		}
		c->blocked = false;
		c->running_since_ns = wall_ns;
		c->wakes++;
		v->wakes++;
	}
}

int vt_command(struct vt *v, int bus, const char *text, char *why, size_t cap)
{
	int sent = 0;
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++) {
		struct vt_client *c = &v->c[i];
		if (c->fd < 0 || c->bus < 0 || (bus >= 0 && vt_owner(v, bus, NULL) != c))
			continue;
		if (c->ncmds == LKS_CMD_QUEUE) {
			snprintf(why, cap, "robot %s has %d commands waiting already", c->robot, LKS_CMD_QUEUE);
			return -1;
		}
		snprintf(c->cmds[c->ncmds++], LKS_TEXT_MAX, "%s", text);
		sent++;
	}
	if (sent == 0) {
		snprintf(why, cap, "no daemon is connected%s", bus >= 0 ? " for that robot" : "");
		return -1;
	}
	v->commands += (uint64_t)sent;
	return sent;
}

bool vt_stalled(const struct vt *v, const struct sim *s, int64_t wall_ns, int64_t start_wall_ns, int64_t grace_ns,
                char *why, size_t cap)
{
	if (!v->ending && vt_buses_covered(v) < v->expected && wall_ns - start_wall_ns > grace_ns && v->t_ns == 0) {
		/* counted by bus (a daemon on two counts two): the missing are buses */
		size_t off = (size_t)snprintf(why, cap, "lockstep: %zu of %zu daemon(s) joined within %.0f s; missing:",
		                              vt_buses_covered(v), v->expected, 1e-9 * (double)grace_ns);
		for (size_t b = 0; b < s->nbuses && off < cap; b++) {
			int o = vt_owner_at(v, (int)b, NULL);
			if (o < 0 || v->c[o].bus < 0)
				off += (size_t)snprintf(why + off, cap - off, " %s (%s)", s->buses[b].name, s->buses[b].link);
		}
		return true;
	}
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++) {
		const struct vt_client *c = &v->c[i];
		if (c->fd < 0 || c->bus < 0 || wall_ns - c->running_since_ns <= grace_ns)
			continue;
		if (!c->blocked) {
			snprintf(why, cap, "lockstep: robot %s's daemon (pid %ld) has not waited for %.0f s of wall time "
			         "at t=%.3f s: stalled", c->robot, c->pid, 1e-9 * (double)grace_ns, 1e-9 * (double)v->t_ns);
			return true;
		}
		if (!vt_caught_up(v, c, s)) {
			const struct sim_bus *b = &s->buses[c->bus];
			snprintf(why, cap, "lockstep: robot %s's daemon (pid %ld) wrote %llu byte(s) to bus %s, %llu arrived in "
			         "%.0f s of wall time (t=%.3f s)", c->robot, c->pid, (unsigned long long)c->written, b->name,
			         (unsigned long long)(b->count.rx_bytes - c->rx_base), 1e-9 * (double)grace_ns,
			         1e-9 * (double)v->t_ns);
			return true;
		}
	}
	return false;
}
