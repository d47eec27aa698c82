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
#include "holder.h"
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
	b->link_lock = -1;
	b->proto = &dxl_proto_v1;
	b->proto->parser_init(&b->parser, true);
	sim_line_init(&b->line);
	b->rng = seed ? seed : 1;
}

void sim_bus_set_protocol(struct sim_bus *b, int protocol)
{
	const struct dxl_proto *p = dxl_proto_by_number(protocol);
	b->proto = p ? p : &dxl_proto_v1;
	b->proto->parser_init(&b->parser, true);
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

bool sim_joint_hears(const struct sim_bus *b, const struct sim_joint *j)
{
	double servo = (double)j->ops->baud(j);
	return j->ops->powered(j) && servo > 0 && fabs(servo - (double)b->baud) <= BUS_BAUD_TOLERANCE * (double)b->baud;
}

uint8_t sim_joint_id(const struct sim_joint *j)
{
	return j->ops->id(j);
}

bool sim_joint_powered(const struct sim_joint *j)
{
	return j->ops->powered(j);
}

bool sim_joint_torque(const struct sim_joint *j)
{
	return j->ops->torque(j);
}

/* Keep the last cap bytes the parser consumed. */
static void hist_push(uint8_t *hist, size_t cap, size_t *hist_n, const uint8_t *data, size_t n)
{
	if (n >= cap) {
		memcpy(hist, data + n - cap, cap);
		*hist_n = cap;
		return;
	}
	if (*hist_n + n > cap) {
		size_t drop = *hist_n + n - cap;
		memmove(hist, hist + drop, *hist_n - drop);
		*hist_n -= drop;
	}
	memcpy(hist + *hist_n, data, n);
	*hist_n += n;
}

static void bus_hist_push(struct sim_bus *b, const uint8_t *data, size_t n)
{
	hist_push(b->hist, sizeof(b->hist), &b->hist_n, data, n);
}

/* The longest status packet a servo sends, with room for a fault's changes:
 * 1.0's largest packet (259 bytes); an X servo's READ of its whole table
 * (148 bytes), stuffed at worst (dxl2_status_bytes_max(148) = 209), with
 * room for a stuck-error fault's re-stuffing. */
#define BUS_REPLY_MAX 260

/* A servo hears the bus's protocol only: the configuration gives a bus one
 * family, a test may not. */
static bool bus_speaks(const struct sim_bus *b, const struct sim_joint *j)
{
	return j->ops->proto == b->proto;
}

/* Schedule one servo's status packet: it starts `after` (the request's
 * end, or the previous reply's in an ordered answer) plus the servo's return
 * delay, then goes out at the baud rate. Returns when its last byte has left
 * the wire (`after` if nothing went out). */
static int64_t bus_send_reply(struct sim_bus *b, struct sim_joint *j, uint8_t *pkt, size_t len, int64_t after)
{
	uint8_t garbage[SIM_FAULT_MAX_GARBAGE];
	size_t ngarbage = 0;
	int64_t extra = 0;
	j->ops->reply_faults(j, &b->rng, pkt, &len, BUS_REPLY_MAX, garbage, &ngarbage, &extra);
	if (len == 0 && ngarbage == 0)
		return after;
	int64_t start = after + j->ops->return_delay_ns(j) + extra;
	int64_t first = start + b->byte_ns;
	if (ngarbage) {
		sim_line_put(&b->line, first + b->latency_ns, b->byte_ns, garbage, ngarbage);
		first += (int64_t)ngarbage * b->byte_ns;
	}
	if (len) {
		sim_line_put(&b->line, first + b->latency_ns, b->byte_ns, pkt, len);
		b->count.replies++;
	}
	return first + (int64_t)len * b->byte_ns - b->byte_ns;
}

struct bus_reply {
	size_t joint;
	int rank;      /* its place among the replies (the protocol's reply_order); -1 none */
	size_t len;
	uint8_t bytes[BUS_REPLY_MAX];
};

/* Replies of several servos to one request: where the protocol orders them,
 * in that order, each after the one before it has ended plus its own return
 * delay; a servo that stays silent leaves no gap (README: the manual does not
 * say how long the others wait for it). Otherwise every reply starts from the
 * request's end, and two servos answering one request collide. */
static void bus_send_replies(struct sim_bus *b, struct bus_reply *r, size_t n, int64_t req_end)
{
	bool ordered = n > 0 && r[0].rank >= 0;
	for (size_t i = 1; ordered && i < n; i++)  /* insertion sort: a few replies */
		for (size_t k = i; k > 0 && r[k - 1].rank > r[k].rank; k--) {
			struct bus_reply t = r[k];
			r[k] = r[k - 1];
			r[k - 1] = t;
		}
	int64_t t = req_end;
	for (size_t i = 0; i < n; i++) {
		int64_t end = bus_send_reply(b, &b->joints[r[i].joint], r[i].bytes, r[i].len, ordered ? t : req_end);
		if (ordered)
			t = end;
	}
}

/* ---- Fast Sync/Bulk Read: one packet, each servo its part in turn ---------------- */

static uint16_t fast_le16(const uint8_t *p)
{
	return (uint16_t)(p[0] | (p[1] << 8));
}

/* The parts a fast read asks for, in its order (IDs and lengths; the data
 * placeholders until the servos' own): 0 when the request does not parse,
 * which no servo answers either. */
static size_t fast_asked(const struct dxl_frame *req, struct dxl2_fast_part *parts, const uint8_t *zeros)
{
	size_t n = 0;
	if (req->instr == DXL2_INST_FAST_SYNC_READ) {
		if (req->nparams < 5)
			return 0;
		for (size_t k = 4; k < req->nparams && n < DXL2_MULTI_MAX; k++)
			parts[n++] = (struct dxl2_fast_part){ req->params[k], 0, fast_le16(req->params + 2), zeros };
		return n;
	}
	if (req->nparams % 5 != 0)
		return 0;
	for (size_t k = 0; k + 5 <= req->nparams && n < DXL2_MULTI_MAX; k += 5)
		parts[n++] = (struct dxl2_fast_part){ req->params[k], 0, fast_le16(req->params + k + 3), zeros };
	return n;
}

/* What a servo's reply (its part as an ordinary status, after the line's
 * faults) puts in its slot: its ID and ERR, its data moved to the front of
 * bytes. A reply whose CRC a fault broke is its part with a broken CRC
 * (*bad_crc). False when a fault left no whole packet (silenced, cut): the
 * servo sends no part and the chain stops there. */
static bool fast_part_of(uint8_t *bytes, size_t len, struct dxl2_fast_part *part, const uint8_t *zeros,
                         bool *bad_crc)
{
	struct dxl2_parser p;
	struct dxl2_packet st;
	size_t used = 0;
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	int r = dxl2_parser_feed(&p, bytes, len, &used, &st);
	*bad_crc = false;
	if (r == DXL_E_CHECKSUM && len >= DXL2_HEADER_BYTES + DXL2_CRC_BYTES) {
		uint16_t crc = dxl2_crc_update(0, bytes, len - DXL2_CRC_BYTES);
		bytes[len - 2] = (uint8_t)crc;
		bytes[len - 1] = (uint8_t)(crc >> 8);
		dxl2_parser_init(&p, DXL2_PARSE_STATUS);
		r = dxl2_parser_feed(&p, bytes, len, &used, &st);
		*bad_crc = true;
	}
	if (r != DXL_FRAME)
		return false;
	part->id = st.id;
	part->err = st.err;
	if (st.nparams == part->len) {
		memcpy(bytes, st.params, st.nparams);
		part->data = bytes;
	} else {
		part->data = zeros;   /* an error status: the servo's ERR says why */
	}
	return true;
}

/* A bad-checksum fault on a servo's part: its CRC goes out wrong, and each
 * servo after it computes its own CRC over the bytes it heard, the wrong
 * one among them (so the last CRC, the packet's, checks: the controller
 * finds the damage at that part, dxl2_fast_status_split). */
static void fast_break_crcs(uint8_t *pkt, const size_t *ends, const bool *bad_crc, size_t n)
{
	bool broken = false;
	for (size_t k = 0; k < n; k++) {
		if (broken) {
			uint16_t crc = dxl2_crc_update(0, pkt, ends[k] - DXL2_CRC_BYTES);
			pkt[ends[k] - 2] = (uint8_t)crc;
			pkt[ends[k] - 1] = (uint8_t)(crc >> 8);
		}
		if (bad_crc[k]) {
			pkt[ends[k] - 2] ^= 0xFF;
			pkt[ends[k] - 1] ^= 0xFF;
			broken = true;
		}
	}
}

/* The servos that answered a fast read build one status packet: the first
 * sends the header and its part after its return delay, each next one its
 * part as soon as the one before has ended (no return delay of its own). A
 * servo asked that sends nothing (not on the bus, below firmware 45, a
 * fault) stops the chain: the packet ends with the part before it (README:
 * the manual does not say what the others do). Slow and garbage faults act
 * on a servo's turn, a bad checksum on its part's CRC (fast_break_crcs). */
static void bus_send_fast(struct sim_bus *b, const struct dxl_frame *req, struct bus_reply *r, size_t n,
                          int64_t req_end)
{
	static const uint8_t zeros[DXL2_MAX_PACKET];
	uint8_t pkt[DXL2_MAX_PACKET];
	struct dxl2_fast_part parts[DXL2_MULTI_MAX];
	size_t ends[DXL2_MULTI_MAX];
	int who[DXL2_MULTI_MAX];
	bool bad_crc[DXL2_MULTI_MAX];
	uint8_t garbage[SIM_BUS_MAX_SERVOS][SIM_FAULT_MAX_GARBAGE];
	size_t ngarbage[SIM_BUS_MAX_SERVOS];
	int64_t extra[SIM_BUS_MAX_SERVOS];
	size_t nasked = fast_asked(req, parts, zeros);
	for (size_t k = 0; k < nasked; k++) {
		who[k] = -1;
		bad_crc[k] = false;
	}
	for (size_t i = 0; i < n; i++) {
		struct sim_joint *j = &b->joints[r[i].joint];
		uint8_t id = j->ops->id(j);
		size_t k = 0;
		j->ops->reply_faults(j, &b->rng, r[i].bytes, &r[i].len, BUS_REPLY_MAX, garbage[i], &ngarbage[i], &extra[i]);
		while (k < nasked && parts[k].id != id)
			k++;
		if (k < nasked && who[k] < 0 && fast_part_of(r[i].bytes, r[i].len, &parts[k], zeros, &bad_crc[k]))
			who[k] = (int)i;
	}
	if (nasked == 0 || dxl2_encode_fast_status(pkt, sizeof pkt, parts, nasked, ends) < 0)
		return;
	fast_break_crcs(pkt, ends, bad_crc, nasked);
	int64_t t = req_end;
	size_t from = 0;
	for (size_t k = 0; k < nasked && who[k] >= 0; k++) {
		size_t i = (size_t)who[k];
		struct sim_joint *j = &b->joints[r[i].joint];
		int64_t first = (k == 0 ? t + j->ops->return_delay_ns(j) : t) + extra[i] + b->byte_ns;
		if (ngarbage[i]) {
			sim_line_put(&b->line, first + b->latency_ns, b->byte_ns, garbage[i], ngarbage[i]);
			first += (int64_t)ngarbage[i] * b->byte_ns;
		}
		size_t len = ends[k] - from;
		sim_line_put(&b->line, first + b->latency_ns, b->byte_ns, pkt + from, len);
		b->count.replies++;
		t = first + (int64_t)len * b->byte_ns - b->byte_ns;
		from = ends[k];
	}
}

static bool is_fast_read(uint8_t instr)
{
	return instr == DXL2_INST_FAST_SYNC_READ || instr == DXL2_INST_FAST_BULK_READ;
}

static void bus_dispatch(struct sim_bus *b, const struct dxl_frame *req, int64_t req_end)
{
	struct bus_reply r[SIM_BUS_MAX_SERVOS];
	size_t n = 0;
	b->count.packets++;
	for (size_t i = 0; i < b->njoints; i++) {
		struct sim_joint *j = &b->joints[i];
		if (!bus_speaks(b, j) || !j->ops->powered(j))
			continue;
		if (!sim_joint_hears(b, j)) {
			b->count.wrong_baud++;
			continue;  /* at another rate the servo sees only framing noise */
		}
		uint8_t id = j->ops->id(j);
		int len = j->ops->handle(j, req, r[n].bytes, sizeof r[n].bytes);
		if (len > 0) {
			r[n].joint = i;
			r[n].rank = b->proto->reply_order(req, id);
			r[n].len = (size_t)len;
			n++;
		}
	}
	if (dxl_proto_can(b->proto, DXL_CAP_FAST_READ) && is_fast_read(req->instr))
		bus_send_fast(b, req, r, n, req_end);
	else
		bus_send_replies(b, r, n, req_end);
}

/* The parser dropped a packet for its checksum: find it in the bytes just
 * consumed (it ends there) so the addressed servo can answer with its
 * checksum error. */
static void bus_bad_checksum(struct sim_bus *b, int64_t req_end)
{
	uint8_t id, instr;
	b->count.checksum_errors++;
	if (!b->proto->damaged_packet(b->hist, b->hist_n, &id, &instr))
		return;
	for (size_t i = 0; i < b->njoints; i++) {
		struct sim_joint *j = &b->joints[i];
		if (!bus_speaks(b, j) || !sim_joint_hears(b, j))
			continue;
		uint8_t reply[BUS_REPLY_MAX];
		int n = j->ops->handle_damaged(j, id, instr, reply, sizeof(reply));
		if (n > 0)
			bus_send_reply(b, j, reply, (size_t)n, req_end);
	}
}

/* ---- feeding ---------------------------------------------------------------------- */

void sim_bus_feed(struct sim_bus *b, const uint8_t *data, size_t n, int64_t now)
{
	struct dxl_parser_counts pc;
	b->proto->parser_counts(&b->parser, &pc);
	if (pc.have > 0 && now - b->last_rx > BUS_PACKET_GAP_NS) {
		b->proto->parser_reset(&b->parser);
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
	for (size_t rounds = 0; rounds < n + b->proto->max_packet + 1; rounds++) {
		size_t used = 0;
		int r = b->proto->parser_feed(&b->parser, data + off, n - off, &used, &b->frame);
		bus_hist_push(b, data + off, used);
		off += used;
		int64_t end = start + (int64_t)off * b->byte_ns;
		if (r == DXL_FRAME)
			bus_dispatch(b, &b->frame, end);
		else if (r == DXL_E_CHECKSUM)
			bus_bad_checksum(b, end);
		else if (r == DXL_E_STUFFING)
			b->count.stuffing_errors++;
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

/* LINK.lock beside the link: the link's owner. */
static void bus_link_lock_path(const struct sim_bus *b, char *out, size_t cap)
{
	snprintf(out, cap, "%s.lock", b->link);
}

/* Take the link for this simulator, for as long as it runs (a disconnect
 * keeps it): a lock file beside it, flock()ed, so that a second simulator
 * is refused with the first one named, and one killed leaves a lock that
 * the next one takes over. Not a lock on the pty: clients lock that
 * (protocol/io/port_lock.c), and a killed simulator's pty number goes to
 * the next pty opened anywhere. */
static int bus_link_lock(struct sim_bus *b, char *err, size_t errcap)
{
	char path[SIM_PATH_MAX + 8], detail[SIM_NAME_MAX + 8], why[SIM_PATH_MAX + 64], who[HOLDER_DETAIL_MAX + 64];
	struct holder h;
	if (b->link_lock >= 0)
		return 0;
	bus_make_dirs(b->link);
	bus_link_lock_path(b, path, sizeof(path));
	snprintf(detail, sizeof(detail), "bus %s", b->name);
	b->link_lock = holder_lockfile_take(path, detail, &h, why, sizeof(why));
	if (b->link_lock >= 0)
		return 0;
	if (b->link_lock == HOLDER_HELD) {
		holder_format(&h, who, sizeof(who));
		snprintf(err, errcap, "%s: held by %s: another simulator serves this link (stop it first, or choose "
		         "another --link)", b->link, who);
	} else {
		snprintf(err, errcap, "%s: %s", b->link, why);
	}
	b->link_lock = -1;
	return -1;
}

/* Point the link at the slave atomically (a reconnect re-points it). With
 * the link's lock held (bus_link_lock), a symlink already there is stale: a
 * killed simulator's. */
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
	if (bus_link_lock(b, err, errcap) != 0)
		return -1;
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
	b->opens++;
	if (bus_link(b, err, errcap) != 0) {
		sim_bus_close(b);
		return -1;
	}
	b->proto->parser_reset(&b->parser);
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
	b->proto->parser_reset(&b->parser);
}

void sim_bus_release(struct sim_bus *b)
{
	char path[SIM_PATH_MAX + 8];
	sim_bus_close(b);
	if (b->link_lock < 0)
		return;
	bus_link_lock_path(b, path, sizeof(path));
	holder_lockfile_drop(path, b->link_lock);
	b->link_lock = -1;
}

bool sim_bus_connected(const struct sim_bus *b) { return b->master >= 0; }

/* The rate the controller set on its side of the pty, when the bus follows
 * it: taken when its bytes come, whichever way they come. */
static void bus_follow_tty(struct sim_bus *b)
{
	if (!b->follow_tty || b->slave < 0)
		return;
	long bps = port_termios2_get_baud(b->slave);
	if (bps > 0 && bps != b->baud)
		sim_bus_set_baud(b, bps);
}

void sim_bus_receive(struct sim_bus *b, const uint8_t *data, size_t n, int64_t now, bool rate_may_differ)
{
	if (rate_may_differ)
		bus_follow_tty(b);
	sim_bus_feed(b, data, n, now);
}

size_t sim_bus_hand_over(struct sim_bus *b, int64_t now, uint8_t *out, size_t cap)
{
	uint8_t buf[BUS_READ_CHUNK];
	size_t given = 0;
	for (;;) {
		size_t n = sim_line_take(&b->line, now, buf, sizeof(buf));
		if (n == 0)
			return given;
		if (b->master < 0) {
			b->count.tx_dropped += n;
			continue;
		}
		size_t take = n < cap - given ? n : cap - given;
		memcpy(out + given, buf, take);
		given += take;
		b->count.tx_bytes += take;
		b->count.tx_dropped += n - take;
	}
}

void sim_bus_read(struct sim_bus *b, int64_t now)
{
	uint8_t buf[BUS_READ_CHUNK];
	if (b->master < 0)
		return;
	bus_follow_tty(b);
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
