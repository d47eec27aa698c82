/*
 * simbus.c — pty buses, wire timing and request dispatch (see simbus.h).
 */
#include "simbus.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include "dxl_table.h"
#include "port.h"

/* Bytes read from the pty per read() call. */
#define BUS_READ_CHUNK 512
/* A gap this long inside a packet makes the servo drop it (AX-12 manual). */
#define BUS_PACKET_GAP_NS 100000000LL
/* A servo hears the controller when the rates differ by less than this. */
#define BUS_BAUD_TOLERANCE 0.03

void sim_bus_init(struct sim_bus *b, const char *name, const char *link, long baud, double latency_s,
                  bool echo, uint64_t seed)
{
	memset(b, 0, sizeof(*b));
	snprintf(b->name, sizeof(b->name), "%s", name);
	snprintf(b->link, sizeof(b->link), "%s", link);
	sim_bus_set_baud(b, baud > 0 ? baud : 1000000);
	b->initial_baud = b->baud;
	b->follow_tty = true;
	b->latency_ns = (int64_t)llround(latency_s * 1e9);
	b->echo = echo;
	b->master = b->slave = -1;
	dxl_parser_init(&b->parser, DXL_PARSE_INSTRUCTION);
	sim_line_init(&b->line);
	b->rng = seed ? seed : 1;
}

void sim_bus_set_baud(struct sim_bus *b, long bps)
{
	if (bps <= 0)
		return;
	b->baud = bps;
	/* 8N1: start bit, 8 data bits, stop bit. */
	b->byte_ns = (int64_t)llround(10.0 * 1e9 / (double)bps);
}

bool sim_bus_baud_matches(const struct sim_bus *b, uint8_t reg)
{
	double servo = (double)dxl_baud_from_reg(reg);
	return fabs(servo - (double)b->baud) <= BUS_BAUD_TOLERANCE * (double)b->baud;
}

static void bus_hist_push(struct sim_bus *b, const uint8_t *data, size_t n)
{
	const size_t cap = sizeof(b->hist);
	if (n >= cap) {
		memcpy(b->hist, data + n - cap, cap);
		b->hist_n = cap;
		return;
	}
	if (b->hist_n + n > cap) {
		size_t drop = b->hist_n + n - cap;
		memmove(b->hist, b->hist + drop, b->hist_n - drop);
		b->hist_n -= drop;
	}
	memcpy(b->hist + b->hist_n, data, n);
	b->hist_n += n;
}

/* Schedule one servo's status packet: it starts after the request's end on
 * the wire plus the servo's return delay, then goes out at the baud rate. */
static void bus_send_reply(struct sim_bus *b, struct sim_joint *j, uint8_t *pkt, size_t len, int64_t req_end)
{
	uint8_t garbage[SIM_FAULT_MAX_GARBAGE];
	size_t ngarbage = 0;
	int64_t extra = 0;
	sim_faults_apply(&j->faults, &b->rng, pkt, &len, garbage, &ngarbage, &extra);
	int64_t start = req_end + (int64_t)dxl_return_delay_us(j->servo.mem[DXL_AX_RETURN_DELAY_TIME]) * 1000 + extra;
	int64_t first = start + b->byte_ns + b->latency_ns;
	if (ngarbage) {
		sim_line_put(&b->line, first, b->byte_ns, garbage, ngarbage);
		first += (int64_t)ngarbage * b->byte_ns;
	}
	if (len) {
		sim_line_put(&b->line, first, b->byte_ns, pkt, len);
		b->count.replies++;
	}
}

static void bus_dispatch(struct sim_bus *b, const struct dxl_packet *pkt, int64_t req_end)
{
	b->count.packets++;
	for (size_t i = 0; i < b->njoints; i++) {
		struct sim_joint *j = &b->joints[i];
		if (!j->servo.powered)
			continue;
		if (!sim_bus_baud_matches(b, j->servo.mem[DXL_AX_BAUD_RATE])) {
			b->count.wrong_baud++;
			continue;  /* at another rate the servo sees only framing noise */
		}
		uint8_t reply[DXL_MAX_PACKET];
		int len = sim_servo_handle(&j->servo, pkt, reply, sizeof(reply));
		if (len > 0)
			bus_send_reply(b, j, reply, (size_t)len, req_end);
	}
}

/* The parser dropped a packet for its checksum: find it in the bytes just
 * consumed (it ends there) so the addressed servo can answer with bit 4. */
static void bus_bad_checksum(struct sim_bus *b, int64_t req_end)
{
	b->count.checksum_errors++;
	for (size_t p = b->hist_n >= 6 ? b->hist_n - 6 + 1 : 0; p-- > 0;) {
		if (b->hist[p] != 0xFF || b->hist[p + 1] != 0xFF || p + 4 >= b->hist_n)
			continue;
		if ((size_t)b->hist[p + 3] + 4 != b->hist_n - p)
			continue;
		uint8_t id = b->hist[p + 2], instr = b->hist[p + 4];
		for (size_t i = 0; i < b->njoints; i++) {
			struct sim_joint *j = &b->joints[i];
			if (!j->servo.powered || !sim_bus_baud_matches(b, j->servo.mem[DXL_AX_BAUD_RATE]))
				continue;
			uint8_t reply[DXL_MAX_PACKET];
			int len = sim_servo_handle_bad_checksum(&j->servo, id, instr, reply, sizeof(reply));
			if (len > 0)
				bus_send_reply(b, j, reply, (size_t)len, req_end);
		}
		return;
	}
}

void sim_bus_feed(struct sim_bus *b, const uint8_t *data, size_t n, int64_t now)
{
	if (b->parser.have > 0 && now - b->last_rx > BUS_PACKET_GAP_NS) {
		dxl_parser_reset(&b->parser);
		b->count.stale_drops++;
	}
	b->last_rx = now;
	int64_t start = now > b->rx_free_at ? now : b->rx_free_at;
	b->rx_free_at = start + (int64_t)n * b->byte_ns;
	b->count.rx_bytes += n;
	if (b->echo)
		sim_line_put(&b->line, start + b->byte_ns + b->latency_ns, b->byte_ns, data, n);
	size_t off = 0;
	/* Until the parser needs more input, even when all of it is consumed:
	 * after an error the bytes it still holds may be a whole packet (one
	 * inside a damaged packet), due now, not at the controller's next byte.
	 * Each round consumes bytes or drops one buffered byte: bounded. */
	for (size_t rounds = 0; rounds < n + DXL_MAX_PACKET + 1; rounds++) {
		size_t used = 0;
		struct dxl_packet pkt;
		int r = dxl_parser_feed(&b->parser, data + off, n - off, &used, &pkt);
		bus_hist_push(b, data + off, used);
		off += used;
		int64_t end = start + (int64_t)off * b->byte_ns;
		if (r == DXL_FRAME)
			bus_dispatch(b, &pkt, end);
		else if (r == DXL_E_CHECKSUM)
			bus_bad_checksum(b, end);
		else if (r < 0)
			b->count.header_errors++;
		else
			break;   /* DXL_NEED_MORE: everything given was consumed */
	}
}

void sim_bus_inject(struct sim_bus *b, const uint8_t *data, size_t n, int64_t now)
{
	sim_line_put(&b->line, now + b->byte_ns, b->byte_ns, data, n);
}

/* ---- pty ------------------------------------------------------------------------ */

/* Raw 8N1 without any processing: pty line disciplines otherwise eat or
 * rewrite 0x03, 0x0A, 0x0D, 0x11, 0x13 (both ends must be raw: the
 * controller's end is set so by protocol/io/port.c, whose comments say which
 * flag does what). */
static int bus_raw(int fd)
{
	struct termios t;
	if (tcgetattr(fd, &t) != 0)
		return -1;
	cfmakeraw(&t);
	t.c_cflag |= CLOCAL | CREAD;  /* no modem lines on a pty */
	t.c_cflag &= (tcflag_t)~CRTSCTS;
	t.c_cc[VMIN] = 1;
	t.c_cc[VTIME] = 0;
	return tcsetattr(fd, TCSANOW, &t);
}

/* mkdir -p of the link's directory. */
static void bus_make_dirs(const char *path)
{
	char dir[SIM_PATH_MAX];
	snprintf(dir, sizeof(dir), "%s", path);
	for (char *p = dir + 1; *p; p++) {
		if (*p != '/')
			continue;
		*p = '\0';
		mkdir(dir, 0755);
		*p = '/';
	}
}

/* Point the link at the slave atomically (a reconnect re-points it). */
static int bus_link(struct sim_bus *b, char *err, size_t errcap)
{
	char tmp[SIM_PATH_MAX + 16];
	struct stat st;
	/* Never replace a real file or device (a mistyped --link /dev/ttyUSB0). */
	if (lstat(b->link, &st) == 0 && !S_ISLNK(st.st_mode)) {
		snprintf(err, errcap, "%s exists and is not a symlink: refusing to replace it", b->link);
		return -1;
	}
	bus_make_dirs(b->link);
	snprintf(tmp, sizeof(tmp), "%s.tmp%ld", b->link, (long)getpid());
	unlink(tmp);
	if (symlink(b->slave_path, tmp) != 0 || rename(tmp, b->link) != 0) {
		snprintf(err, errcap, "%s: cannot link to %s: %s", b->link, b->slave_path, strerror(errno));
		unlink(tmp);
		return -1;
	}
	return 0;
}

int sim_bus_open(struct sim_bus *b, char *err, size_t errcap)
{
	int m = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
	if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0) {
		snprintf(err, errcap, "%s: cannot create a pseudo-terminal: %s", b->name, strerror(errno));
		if (m >= 0)
			close(m);
		return -1;
	}
	const char *sp = ptsname(m);
	int s = sp ? open(sp, O_RDWR | O_NOCTTY | O_NONBLOCK) : -1;
	if (s < 0 || bus_raw(s) != 0 || bus_raw(m) != 0) {
		snprintf(err, errcap, "%s: cannot set up the pty: %s", b->name, strerror(errno));
		close(m);
		if (s >= 0)
			close(s);
		return -1;
	}
	/* Clients that never set a rate talk at the configured one (any rate:
	 * termios2, protocol/io/port_baud.c). */
	port_termios2_set_baud(s, b->initial_baud);
	sim_bus_set_baud(b, b->initial_baud);
	fcntl(m, F_SETFD, FD_CLOEXEC);
	fcntl(s, F_SETFD, FD_CLOEXEC);
	snprintf(b->slave_path, sizeof(b->slave_path), "%s", sp);
	b->master = m;
	b->slave = s;
	if (bus_link(b, err, errcap) != 0) {
		sim_bus_close(b);
		return -1;
	}
	dxl_parser_reset(&b->parser);
	sim_line_clear(&b->line);
	return 0;
}

void sim_bus_close(struct sim_bus *b)
{
	char target[SIM_PATH_MAX];
	if (b->master < 0)
		return;
	ssize_t n = readlink(b->link, target, sizeof(target) - 1);
	if (n > 0) {
		target[n] = '\0';
		if (strcmp(target, b->slave_path) == 0)
			unlink(b->link);
	}
	close(b->master);
	close(b->slave);
	b->master = b->slave = -1;
	sim_line_clear(&b->line);
	dxl_parser_reset(&b->parser);
}

bool sim_bus_connected(const struct sim_bus *b) { return b->master >= 0; }

void sim_bus_read(struct sim_bus *b, int64_t now)
{
	uint8_t buf[BUS_READ_CHUNK];
	if (b->master < 0)
		return;
	if (b->follow_tty) {
		long bps = port_termios2_get_baud(b->slave);
		if (bps > 0 && bps != b->baud)
			sim_bus_set_baud(b, bps);
	}
	for (;;) {
		ssize_t n = read(b->master, buf, sizeof(buf));
		if (n <= 0)
			return;  /* EAGAIN; EIO cannot happen while we hold the slave open */
		sim_bus_feed(b, buf, (size_t)n, now);
		/* A short read took what there was: reading again only to hear
		 * EAGAIN makes the pty wait for the kernel's buffer worker, which a
		 * busy machine schedules late (tens of ms seen), and that would
		 * stall the whole simulation. poll() says when more came. */
		if ((size_t)n < sizeof(buf))
			return;
	}
}

void sim_bus_flush(struct sim_bus *b, int64_t now)
{
	uint8_t buf[BUS_READ_CHUNK];
	for (;;) {
		size_t n = sim_line_take(&b->line, now, buf, sizeof(buf));
		if (n == 0)
			return;
		if (b->master < 0) {
			b->count.tx_dropped += n;
			continue;
		}
		ssize_t w = write(b->master, buf, n);
		size_t done = w > 0 ? (size_t)w : 0;
		b->count.tx_bytes += done;
		/* Nobody is reading the slave and its buffer is full: a real bus
		 * loses the bytes too. */
		b->count.tx_dropped += n - done;
	}
}

int64_t sim_bus_next_tx(const struct sim_bus *b, int64_t slice_ns)
{
	return sim_line_chunk_end(&b->line, slice_ns);
}
