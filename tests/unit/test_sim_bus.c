/*
 * test_sim_bus.c — one simulated bus without a pty: wire timing, collisions,
 * wrong baud, echo, adapter latency, the bad-checksum reply and every reply
 * fault, checked with our own encoder and parser (the controller's view) and
 * with raw bytes from the manual; and the link's owner: a second simulator on
 * a live link refused with the first named, a killed one's link replaced, a
 * disconnect keeping the link its own.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <cmocka.h>

#include "dxl.h"
#include "dxl_table.h"
#include "holder.h"
#include "port.h"
#include "../../sim-bridge/fault.h"
#include "../../sim-bridge/line.h"
#include "../../sim-bridge/simbus.h"

#define MS 1000000LL
#define US 1000LL

/* A bus at 1 Mbps (10 µs a byte) with servos 1 and 2, return delay 0. */
static void bus_two(struct sim_bus *b, double latency_s, bool echo)
{
	sim_bus_init(b, "t", "/nonexistent/t", 1000000, latency_s, echo, 7);
	for (uint8_t id = 1; id <= 2; id++) {
		struct sim_joint *j = &b->joints[b->njoints++];
		memset(j, 0, sizeof(*j));
		j->ops = sim_joint_ops_of(SIM_MODEL_AX12A);
		sim_servo_init(&j->servo, NULL, DXL_POS_CENTER);
		sim_servo_poke(&j->servo, DXL_AX_ID, id);
		sim_servo_poke(&j->servo, DXL_AX_RETURN_DELAY_TIME, 0);
	}
}

/* Everything queued on the line, with the release time of the first and last byte. */
static size_t drain(struct sim_bus *b, uint8_t *out, size_t cap, int64_t *first, int64_t *last)
{
	*first = sim_line_next(&b->line);
	*last = *first;
	size_t n = 0;
	while (b->line.n > 0 && n < cap) {
		*last = sim_line_next(&b->line);
		n += sim_line_take(&b->line, *last, out + n, 1);
	}
	return n;
}

/* Parse a status packet from the controller's side. */
static int parse_status(const uint8_t *buf, size_t n, struct dxl_packet *pkt)
{
	struct dxl_parser p;
	size_t used = 0, off = 0;
	dxl_parser_init(&p, DXL_PARSE_STATUS);
	int r;
	do {
		r = dxl_parser_feed(&p, buf + off, n - off, &used, pkt);
		off += used;
	} while (r < 0 && off < n);
	return r;
}

static void test_ping_timing(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_two(&b, 0, false);
	static const uint8_t ping[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	sim_bus_feed(&b, ping, sizeof(ping), 1000 * MS);
	size_t n = drain(&b, out, sizeof(out), &first, &last);
	static const uint8_t want[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
	assert_int_equal(n, sizeof(want));
	assert_memory_equal(out, want, sizeof(want));
	/* Request on the wire 60 µs, return delay 0, first byte ends 10 µs later. */
	assert_int_equal(first - 1000 * MS, 70 * US);
	assert_int_equal(last - first, 50 * US);  /* paced: 10 µs a byte */
	/* With the factory return delay (250 × 2 µs) the reply is 500 µs later. */
	sim_servo_poke(&b.joints[0].servo, DXL_AX_RETURN_DELAY_TIME, 250);
	sim_bus_feed(&b, ping, sizeof(ping), 2000 * MS);
	drain(&b, out, sizeof(out), &first, &last);
	assert_int_equal(first - 2000 * MS, 570 * US);
}

static void test_adapter_latency_and_echo(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_two(&b, 0.016, true);
	static const uint8_t ping[] = { 0xFF, 0xFF, 0x02, 0x02, 0x01, 0xFA };
	sim_bus_feed(&b, ping, sizeof(ping), 0);
	size_t n = drain(&b, out, sizeof(out), &first, &last);
	/* Echo of the request first, then the reply, all held 16 ms. */
	assert_int_equal(n, 12);
	assert_memory_equal(out, ping, sizeof(ping));
	static const uint8_t want[] = { 0xFF, 0xFF, 0x02, 0x02, 0x00, 0xFB };
	assert_memory_equal(out + 6, want, sizeof(want));
	assert_int_equal(first, 16 * MS + 10 * US);
	assert_int_equal(last, 16 * MS + 120 * US);
}

static void test_broadcast_ping_collides(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_two(&b, 0, false);
	static const uint8_t ping[] = { 0xFF, 0xFF, 0xFE, 0x02, 0x01, 0xFE };
	sim_bus_feed(&b, ping, sizeof(ping), 0);
	size_t n = drain(&b, out, sizeof(out), &first, &last);
	/* Both answer at the same instant: 6 bytes on top of each other. */
	assert_int_equal(n, 6);
	assert_true(b.line.collisions >= 6);
	struct dxl_packet pkt;
	assert_int_not_equal(parse_status(out, n, &pkt), DXL_FRAME);
	/* With different return delays they come out one after the other. */
	sim_servo_poke(&b.joints[1].servo, DXL_AX_RETURN_DELAY_TIME, 100);
	sim_bus_feed(&b, ping, sizeof(ping), 10 * MS);
	n = drain(&b, out, sizeof(out), &first, &last);
	assert_int_equal(n, 12);
	assert_int_equal(parse_status(out, 6, &pkt), DXL_FRAME);
	assert_int_equal(pkt.id, 1);
	assert_int_equal(parse_status(out + 6, 6, &pkt), DXL_FRAME);
	assert_int_equal(pkt.id, 2);
}

static void test_wrong_baud_no_reply(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_two(&b, 0, false);
	sim_servo_poke(&b.joints[0].servo, DXL_AX_BAUD_RATE, 34);  /* 57 143 bps */
	static const uint8_t ping[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	sim_bus_feed(&b, ping, sizeof(ping), 0);
	assert_int_equal(drain(&b, out, sizeof(out), &first, &last), 0);
	assert_int_equal(b.count.wrong_baud, 1);  /* servo 1 missed it */
	assert_true(sim_bus_baud_matches(&b, 1));
	assert_false(sim_bus_baud_matches(&b, 3));
}

static void test_conformance_through_library(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t req[DXL_MAX_PACKET], out[DXL_MAX_PACKET];
	int64_t first, last;
	struct dxl_packet pkt;
	bus_two(&b, 0, false);
	/* SYNC_WRITE goals for both, then READ(36, 8) from each. */
	const uint8_t ids[2] = { 1, 2 };
	const uint8_t data[4] = { 0x00, 0x01, 0x00, 0x03 };
	int n = dxl_encode_sync_write(req, sizeof(req), DXL_AX_GOAL_POSITION, 2, ids, data, 2);
	assert_true(n > 0);
	sim_bus_feed(&b, req, (size_t)n, 0);
	assert_int_equal(b.line.n, 0);
	assert_int_equal(sim_servo_peek(&b.joints[0].servo, DXL_AX_GOAL_POSITION), 0x100);
	assert_int_equal(sim_servo_peek(&b.joints[1].servo, DXL_AX_GOAL_POSITION), 0x300);
	for (uint8_t id = 1; id <= 2; id++) {
		n = dxl_encode_read(req, sizeof(req), id, DXL_AX_PRESENT_POSITION, 8);
		sim_bus_feed(&b, req, (size_t)n, (int64_t)id * MS);
		size_t got = drain(&b, out, sizeof(out), &first, &last);
		assert_int_equal(got, 14);
		assert_int_equal(parse_status(out, got, &pkt), DXL_FRAME);
		assert_int_equal(pkt.id, id);
		assert_int_equal(pkt.code, 0);
		assert_int_equal(pkt.nparams, 8);
		assert_int_equal(dxl_get_u16(pkt.params), DXL_POS_CENTER);
	}
	/* WRITE with our encoder: status with no error. */
	uint8_t torque = 1;
	n = dxl_encode_write(req, sizeof(req), 2, DXL_AX_TORQUE_ENABLE, &torque, 1);
	sim_bus_feed(&b, req, (size_t)n, 5 * MS);
	size_t got = drain(&b, out, sizeof(out), &first, &last);
	assert_int_equal(parse_status(out, got, &pkt), DXL_FRAME);
	assert_int_equal(pkt.code, 0);
	assert_int_equal(b.joints[1].servo.mem[DXL_AX_TORQUE_ENABLE], 1);
}

static void test_bad_checksum_gets_checksum_bit(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[64];
	int64_t first, last;
	bus_two(&b, 0, false);
	static const uint8_t bad[] = { 0xFF, 0xFF, 0x02, 0x02, 0x01, 0x00 };
	sim_bus_feed(&b, bad, sizeof(bad), 0);
	size_t n = drain(&b, out, sizeof(out), &first, &last);
	static const uint8_t want[] = { 0xFF, 0xFF, 0x02, 0x02, 0x10, 0xEB };
	assert_int_equal(n, sizeof(want));
	assert_memory_equal(out, want, sizeof(want));
	assert_int_equal(b.count.checksum_errors, 1);
	/* Leading garbage and a split packet still frame. */
	static const uint8_t noisy[] = { 0x00, 0x13, 0xFF, 0xFF, 0x01, 0x02 };
	static const uint8_t rest[] = { 0x01, 0xFB };
	sim_bus_feed(&b, noisy, sizeof(noisy), MS);
	sim_bus_feed(&b, rest, sizeof(rest), MS + 50 * US);
	n = drain(&b, out, sizeof(out), &first, &last);
	assert_int_equal(n, 6);
	assert_int_equal(out[2], 1);
	/* A gap of more than 100 ms inside a packet: the servo drops the start. */
	static const uint8_t head[] = { 0xFF, 0xFF, 0x01, 0x02 };
	static const uint8_t ping[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	sim_bus_feed(&b, head, sizeof(head), 10 * MS);
	sim_bus_feed(&b, ping, sizeof(ping), 200 * MS);
	n = drain(&b, out, sizeof(out), &first, &last);
	static const uint8_t ok[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
	assert_int_equal(n, 6);
	assert_memory_equal(out, ok, 6);
	assert_int_equal(b.count.stale_drops, 1);
}

/* Apply a fault to servo 1 and return what the controller reads for a PING. */
static size_t ping_with_fault(struct sim_bus *b, const char *fault, uint8_t *out, int64_t *first)
{
	char buf[64], err[128], *argv[8];
	int argc = 0;
	enum sim_fault_kind kind;
	struct sim_fault f;
	int64_t last;
	snprintf(buf, sizeof(buf), "%s", fault);
	for (char *save = NULL, *w = strtok_r(buf, " ", &save); w; w = strtok_r(NULL, " ", &save))
		argv[argc++] = w;
	assert_int_equal(sim_fault_parse(argc, argv, &kind, &f, err, sizeof(err)), 0);
	sim_faults_clear(&b->joints[0].faults);
	b->joints[0].faults.f[kind] = f;
	static const uint8_t ping[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	sim_bus_feed(b, ping, sizeof(ping), 0);
	b->rx_free_at = 0;
	return drain(b, out, 128, first, &last);
}

static void test_reply_faults(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[128];
	int64_t first;
	struct dxl_packet pkt;
	bus_two(&b, 0, false);
	assert_int_equal(ping_with_fault(&b, "no-reply", out, &first), 0);
	size_t n = ping_with_fault(&b, "bad-checksum", out, &first);
	assert_int_equal(n, 6);
	assert_int_equal(parse_status(out, n, &pkt), DXL_E_CHECKSUM);
	n = ping_with_fault(&b, "truncate 2", out, &first);
	assert_int_equal(n, 4);
	assert_int_equal(parse_status(out, n, &pkt), DXL_NEED_MORE);
	n = ping_with_fault(&b, "wrong-id 9", out, &first);
	assert_int_equal(parse_status(out, n, &pkt), DXL_FRAME);
	assert_int_equal(pkt.id, 9);
	n = ping_with_fault(&b, "garbage 5", out, &first);
	assert_int_equal(n, 11);
	n = ping_with_fault(&b, "slow 3", out, &first);
	assert_int_equal(first, 3 * MS + 70 * US);
	n = ping_with_fault(&b, "stuck-error overload|overheating", out, &first);
	static const uint8_t want[] = { 0xFF, 0xFF, 0x01, 0x02, 0x24, 0xD8 };  /* the manual's example */
	assert_int_equal(n, sizeof(want));
	assert_memory_equal(out, want, sizeof(want));
	/* count=N: only the next N replies. */
	static const uint8_t ping[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	int64_t last;
	n = ping_with_fault(&b, "no-reply count=1", out, &first);
	assert_int_equal(n, 0);
	sim_bus_feed(&b, ping, sizeof(ping), 2 * MS);
	assert_int_equal(drain(&b, out, sizeof(out), &first, &last), 6);
}

/* One PING to servo 1 at time t; its reply (6 bytes, or what the faults made
 * of it) in out. */
static size_t ping1(struct sim_bus *b, int64_t t, uint8_t *out)
{
	static const uint8_t ping[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	int64_t first, last;
	sim_bus_feed(b, ping, sizeof(ping), t);
	return drain(b, out, 128, &first, &last);
}

static void set_fault(struct sim_bus *b, const char *text)
{
	char buf[128], err[128], *argv[8];
	int argc = 0;
	enum sim_fault_kind kind;
	struct sim_fault f;
	snprintf(buf, sizeof(buf), "%s", text);
	for (char *save = NULL, *w = strtok_r(buf, " ", &save); w && argc < 8; w = strtok_r(NULL, " ", &save))
		argv[argc++] = w;
	assert_int_equal(sim_fault_parse(argc, argv, &kind, &f, err, sizeof(err)), 0);
	b->joints[0].faults.f[kind] = f;
}

/* stuck-error honours count=N and prob=P like every other fault: the bits
 * are in the next N replies only, or in a fraction P of them (the bus's
 * seeded generator), and each reply carrying them has a valid checksum. */
static void test_stuck_error_count_and_prob(void **state)
{
	(void)state;
	struct sim_bus b;
	uint8_t out[128];
	struct dxl_packet pkt;
	int64_t t = 0;
	bus_two(&b, 0, false);
	set_fault(&b, "stuck-error overload count=2");
	for (int i = 0; i < 4; i++) {
		assert_int_equal(ping1(&b, t += MS, out), 6);
		assert_int_equal(parse_status(out, 6, &pkt), DXL_FRAME);
		assert_int_equal(pkt.code, i < 2 ? DXL_ERRBIT_OVERLOAD : 0);
	}
	assert_false(b.joints[0].faults.f[SIM_FAULT_STUCK_ERROR].active);  /* used up */

	set_fault(&b, "stuck-error overload|overheating prob=0.5");
	int with = 0;
	for (int i = 0; i < 400; i++) {
		assert_int_equal(ping1(&b, t += MS, out), 6);
		assert_int_equal(parse_status(out, 6, &pkt), DXL_FRAME);
		assert_true(pkt.code == 0 || pkt.code == (DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT));
		with += pkt.code != 0;
	}
	assert_in_range(with, 140, 260);   /* 200 ± 6 sigma */
	set_fault(&b, "stuck-error prob=0");
	for (int i = 0; i < 50; i++) {
		ping1(&b, t += MS, out);
		assert_int_equal(out[4], 0);
	}
	/* the same seed gives the same replies */
	struct sim_bus c;
	int pattern_b = 0, pattern_c = 0;
	bus_two(&b, 0, false);
	bus_two(&c, 0, false);
	set_fault(&b, "stuck-error prob=0.5");
	set_fault(&c, "stuck-error prob=0.5");
	for (int i = 0; i < 20; i++) {
		ping1(&b, t += MS, out);
		pattern_b = pattern_b << 1 | (out[4] != 0);
		ping1(&c, t, out);
		pattern_c = pattern_c << 1 | (out[4] != 0);
	}
	assert_int_equal(pattern_b, pattern_c);
	assert_true(pattern_b != 0 && pattern_b != (1 << 20) - 1);
	/* together with bad-checksum: the bits are in, and the checksum (of the
	 * packet with the bits) is inverted */
	bus_two(&b, 0, false);
	set_fault(&b, "stuck-error range");
	set_fault(&b, "bad-checksum");
	ping1(&b, t += MS, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(out[5], (uint8_t)~dxl_checksum(&out[2], 3));
	/* the bits never reach the servo's own state: report only, no shutdown */
	assert_int_equal(b.joints[0].servo.conditions, 0);
}

/* The bus follows the rate its controller set on the pty, standard or not
 * (read back with protocol/io's termios2 helpers, the one home of that code). */
static void test_bus_follows_pty_rate(void **state)
{
	(void)state;
	char dir[] = "/tmp/test_sim_bus.XXXXXX", link[64];
	assert_non_null(mkdtemp(dir));
	snprintf(link, sizeof(link), "%s/bus", dir);
	static struct sim_bus b;
	char err[256];
	sim_bus_init(&b, "t", link, 57600, 0, false, 1);
	assert_int_equal(sim_bus_open(&b, err, sizeof(err)), 0);
	/* a new pty starts at the configured rate */
	assert_int_equal(port_termios2_get_baud(b.slave), 57600);
	assert_int_equal(b.baud, 57600);
	int fd = open(link, O_RDWR | O_NOCTTY | O_NONBLOCK);
	assert_true(fd >= 0);
	/* a standard rate through POSIX termios ... */
	struct termios t;
	assert_int_equal(tcgetattr(fd, &t), 0);
	cfsetspeed(&t, B500000);
	assert_int_equal(tcsetattr(fd, TCSANOW, &t), 0);
	assert_int_equal(port_termios2_get_baud(fd), 500000);
	sim_bus_read(&b, 0);
	assert_int_equal(b.baud, 500000);
	assert_int_equal(b.byte_ns, 20000);
	/* ... and a Dynamixel rate without a constant (BOTHER) */
	assert_int_equal(port_termios2_set_baud(fd, 117647), DXL_OK);
	assert_int_equal(port_termios2_get_baud(b.slave), 117647);
	sim_bus_read(&b, 0);
	assert_int_equal(b.baud, 117647);
	close(fd);
	sim_bus_release(&b);
	assert_int_equal(port_termios2_get_baud(-1), DXL_E_IO);
	assert_int_equal(rmdir(dir), 0);  /* the link and its lock file went with the bus */
}

/* One simulator per link. A second bus on a live link (another simulator:
 * a lock file is another open file to flock(), even in one process) is
 * refused before it makes a pty, naming the first, and leaves the link
 * alone; a disconnect keeps the link the first one's; one left by a killed
 * simulator (a dangling link, a lock file no process holds) is replaced. */
static void test_link_has_one_owner(void **state)
{
	(void)state;
	char dir[] = "/tmp/test_sim_link.XXXXXX", link[64], lock[80], target[SIM_PATH_MAX];
	assert_non_null(mkdtemp(dir));
	snprintf(link, sizeof(link), "%s/bus", dir);
	snprintf(lock, sizeof(lock), "%s/bus.lock", dir);
	static struct sim_bus a, b2;
	char err[400];
	sim_bus_init(&a, "r1", link, 1000000, 0, false, 1);
	sim_bus_init(&b2, "r2", link, 1000000, 0, false, 1);
	assert_int_equal(sim_bus_open(&a, err, sizeof(err)), 0);
	struct holder f;
	assert_true(holder_read_file(lock, &f));
	assert_int_equal(f.pid, getpid());
	assert_string_equal(f.detail, "bus r1");

	assert_int_equal(sim_bus_open(&b2, err, sizeof(err)), -1);
	char want[300];
	snprintf(want, sizeof(want), "%s: held by %s (pid %ld, bus r1)", link, f.program, (long)getpid());
	assert_non_null(strstr(err, want));
	assert_false(sim_bus_connected(&b2));
	ssize_t n = readlink(link, target, sizeof(target) - 1);
	assert_true(n > 0);
	target[n] = '\0';
	assert_string_equal(target, a.slave_path);
	sim_bus_release(&b2);   /* never held: the link and the lock stay */
	assert_int_equal(access(lock, F_OK), 0);
	assert_true(readlink(link, target, sizeof(target)) > 0);

	/* a disconnect removes the link but keeps it ours */
	sim_bus_close(&a);
	assert_int_equal(readlink(link, target, sizeof(target)), -1);
	assert_int_equal(sim_bus_open(&b2, err, sizeof(err)), -1);
	assert_int_equal(sim_bus_open(&a, err, sizeof(err)), 0);
	sim_bus_release(&a);
	assert_int_equal(access(lock, F_OK), -1);

	/* what a SIGKILLed simulator leaves: a link to a pty that is gone, a
	 * lock file naming a dead pid */
	pid_t c = fork();
	assert_true(c >= 0);
	if (c == 0)
		_exit(0);
	assert_int_equal(waitpid(c, NULL, 0), c);
	assert_int_equal(symlink("/dev/pts/999999", link), 0);
	FILE *fp = fopen(lock, "w");
	assert_non_null(fp);
	fprintf(fp, "%10ld undulate-sim bus r1\n", (long)c);
	fclose(fp);
	assert_int_equal(sim_bus_open(&b2, err, sizeof(err)), 0);
	n = readlink(link, target, sizeof(target) - 1);
	assert_true(n > 0);
	target[n] = '\0';
	assert_string_equal(target, b2.slave_path);
	sim_bus_release(&b2);
	assert_int_equal(rmdir(dir), 0);
}

/* A whole packet inside a damaged one (here in the parameters of a WRITE
 * with a bad checksum) is found by the parser's resync when the damaged one
 * ends, and answered then, in whatever reads the bytes came: the bus asks
 * the parser for more until it needs input, as its contract says. (Found by
 * fuzz_sim_serial: in one read, the PING stayed buffered, unanswered, until
 * the controller's next byte.) */
static void test_packet_inside_a_bad_packet(void **state)
{
	(void)state;
	static struct sim_bus b;
	uint8_t out[128];
	int64_t first, last;
	struct dxl_packet pkt;
	/* WRITE to 1 at address 6 of the bytes FF FF 02 02 01 FA (a PING to 2) */
	uint8_t outer[] = { 0xFF, 0xFF, 0x01, 0x09, 0x03, 0x06, 0xFF, 0xFF, 0x02, 0x02, 0x01, 0xFA, 0x00 };
	outer[sizeof(outer) - 1] = (uint8_t)(dxl_checksum(&outer[2], sizeof(outer) - 3) ^ 0x55);  /* bad */
	for (size_t cut = 1; cut <= sizeof(outer); cut++) {
		bus_two(&b, 0, false);
		/* servo 2 answers 100 µs later: the two replies do not collide */
		sim_servo_poke(&b.joints[1].servo, DXL_AX_RETURN_DELAY_TIME, 50);
		sim_bus_feed(&b, outer, cut, 0);
		sim_bus_feed(&b, outer + cut, sizeof(outer) - cut, 0);
		assert_int_equal(b.count.checksum_errors, 1);
		assert_int_equal(b.count.packets, 1);
		assert_int_equal(b.joints[0].servo.count.checksum_errors, 1);   /* servo 1: the checksum bit */
		assert_int_equal(b.joints[1].servo.count.instructions, 1);      /* servo 2: the PING */
		size_t n = drain(&b, out, sizeof(out), &first, &last);
		assert_int_equal(n, 12);
		assert_int_equal(parse_status(out, 6, &pkt), DXL_FRAME);
		assert_int_equal(pkt.id, 1);
		assert_int_equal(pkt.code, DXL_ERRBIT_CHECKSUM);
		assert_int_equal(parse_status(out + 6, 6, &pkt), DXL_FRAME);
		assert_int_equal(pkt.id, 2);
		assert_int_equal(pkt.code, 0);
	}
}

static void test_fault_parse_errors(void **state)
{
	(void)state;
	char err[128];
	enum sim_fault_kind kind;
	struct sim_fault f;
	char *bad1[] = { "explode" };
	char *bad2[] = { "slow", "abc" };
	char *bad3[] = { "temperature" };
	char *bad4[] = { "stuck-error", "nonsense" };
	char *bad5[] = { "no-reply", "prob=2" };
	assert_int_equal(sim_fault_parse(1, bad1, &kind, &f, err, sizeof(err)), -1);
	assert_non_null(strstr(err, "unknown fault"));
	assert_int_equal(sim_fault_parse(2, bad2, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse(1, bad3, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse(2, bad4, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse(2, bad5, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse(0, NULL, &kind, &f, err, sizeof(err)), -1);
	assert_int_equal(sim_fault_parse_bits("overload|range"), 0x28);
	assert_int_equal(sim_fault_parse_bits("36"), 36);
	assert_int_equal(sim_fault_parse_bits("200"), -1);
}

static void test_line_queue(void **state)
{
	(void)state;
	static struct sim_line l;
	uint8_t out[8];
	sim_line_init(&l);
	const uint8_t a[3] = { 1, 2, 3 }, c[2] = { 0xF0, 0x0F };
	sim_line_put(&l, 100, 10, a, 3);          /* at 100, 110, 120 */
	sim_line_put(&l, 135, 10, c, 2);          /* 135, 145: 15 ns after 120, no collision */
	assert_int_equal(l.collisions, 0);
	sim_line_put(&l, 104, 10, c, 1);          /* overlaps the byte at 100 */
	assert_int_equal(l.collisions, 1);
	assert_int_equal(sim_line_take(&l, 99, out, 8), 0);
	assert_int_equal(sim_line_take(&l, 110, out, 8), 2);
	assert_int_equal(out[0], 1 & 0xF0);
	assert_int_equal(out[1], 2);
	assert_int_equal(sim_line_next(&l), 120);
	/* chunks: 120 and 135 are within 20 of the next byte, 145 is not */
	assert_int_equal(sim_line_chunk_end(&l, 20), 135);
	assert_int_equal(sim_line_chunk_end(&l, 0), 120);
	assert_int_equal(sim_line_take(&l, 1000, out, 8), 3);
	assert_int_equal(sim_line_chunk_end(&l, 20), INT64_MAX);
	assert_int_equal(sim_line_next(&l), INT64_MAX);
	/* Overflow is counted, not crashed on. */
	for (int i = 0; i < SIM_LINE_CAP + 10; i++)
		sim_line_put(&l, 1000 + i * 20, 10, a, 1);
	assert_int_equal(l.overflows, 10);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ping_timing),
		cmocka_unit_test(test_adapter_latency_and_echo),
		cmocka_unit_test(test_broadcast_ping_collides),
		cmocka_unit_test(test_wrong_baud_no_reply),
		cmocka_unit_test(test_conformance_through_library),
		cmocka_unit_test(test_bad_checksum_gets_checksum_bit),
		cmocka_unit_test(test_reply_faults),
		cmocka_unit_test(test_stuck_error_count_and_prob),
		cmocka_unit_test(test_bus_follows_pty_rate),
		cmocka_unit_test(test_link_has_one_owner),
		cmocka_unit_test(test_packet_inside_a_bad_packet),
		cmocka_unit_test(test_fault_parse_errors),
		cmocka_unit_test(test_line_queue),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
