/* test_sim_vtime.c — the simulator's side of lockstep (sim-bridge/vtime.h)
 * with daemons played by the test on socket pairs: who may join (a bus by its
 * link or its pty, one daemon a bus, none after the end), the barrier (every
 * expected daemon joined, blocked, and every byte it wrote read), the next
 * wake-up (its own, or now for input it has not been told of, a command, the
 * end), what a release sends and to whom (CMD and STOP before TIME, only the
 * daemons due), commands to one robot or all, a daemon that leaves early or
 * stalls ending the run with its name. In-band (the default transport):
 * WELCOME says so, a WAIT's bytes go into its bus at the virtual now (a
 * PING from the AX-12 manual is answered), the reply goes to its daemon in
 * the TIME due when its last byte is on the wire, nothing waits on a byte
 * count; bytes before the daemon opened its port, or after its port went
 * away, are dropped and counted; a port gone is said in the TIME; a BYE's
 * last bytes still go into the bus. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "../../sim-bridge/sim.h"
#include "../../sim-bridge/vtime.h"

static const char scenario[] =
	"[robot a]\nids = 1\nlink = /tmp/vt-test/a\n"
	"[robot b]\nids = 1\nlink = /tmp/vt-test/b\n";

static struct sim sim;
static struct sim_config cfg;
static struct vt vt;

static void make_sim(void)
{
	char err[256];
	sim_config_defaults(&cfg);
	assert_int_equal(sim_config_load_text(&cfg, "mem", scenario, sizeof scenario - 1, err, sizeof err), 0);
	assert_int_equal(sim_config_finish(&cfg, err, sizeof err), 0);
	assert_int_equal(sim_init(&sim, &cfg, err, sizeof err), 0);
	memset(&vt, 0, sizeof vt);
	for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
		vt.c[i].fd = -1;
	vt.listen_fd = -1;
	vt.expected = 2;
	vt.mono0_us = LKS_MONO0_US;
	vt.wall0_us = LKS_WALL0_US;
}

/* A daemon connected in slot i; returns the test's end. */
static int connect_slot(size_t i)
{
	int sv[2];
	assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
	memset(&vt.c[i], 0, sizeof vt.c[i]);
	vt.c[i].fd = sv[0];
	vt.c[i].bus = -1;
	return sv[1];
}

static void daemon_send(int fd, uint32_t type, uint64_t a, uint64_t b, uint32_t flags, const char *text)
{
	struct lks_msg m = { .type = type, .a = a, .b = b, .flags = flags };
	snprintf(m.name, sizeof m.name, "robot%d", fd);
	if (text)
		snprintf(m.text, sizeof m.text, "%s", text);
	assert_int_equal(lks_send(fd, &m), 0);
}

/* The next message the daemon gets, or type 0 when none is waiting. */
static struct lks_msg daemon_recv(int fd)
{
	struct lks_msg m = { 0 };
	char why[200];
	if (recv(fd, &m, 0, MSG_PEEK | MSG_DONTWAIT) < 0)
		return (struct lks_msg){ 0 };
	assert_int_equal(lks_recv(fd, &m, why, sizeof why), 1);
	return m;
}

static int join(size_t slot, const char *path)
{
	int fd = connect_slot(slot);
	daemon_send(fd, LKS_HELLO, 4242, 0, 0, path);
	vt_on_client(&vt, &sim, slot, 1000);
	return fd;
}

static void test_join(void **state)
{
	(void)state;
	make_sim();
	int a = join(0, "/tmp/vt-test/a");
	struct lks_msg m = daemon_recv(a);
	assert_int_equal(m.type, LKS_WELCOME);
	assert_int_equal(m.a, 0);
	assert_int_equal(m.b, LKS_MONO0_US);
	assert_int_equal((int64_t)m.c, LKS_WALL0_US);
	assert_int_equal(vt.c[0].bus, 0);
	assert_int_equal(vt_clients(&vt), 1);
	/* the pty itself names the bus too */
	snprintf(sim.buses[1].slave_path, sizeof sim.buses[1].slave_path, "/dev/pts/77");
	int b = join(1, "/dev/pts/77");
	assert_int_equal(daemon_recv(b).type, LKS_WELCOME);
	assert_int_equal(vt.c[1].bus, 1);
	/* nobody's bus, and a bus taken */
	int x = join(2, "/tmp/vt-test/nowhere");
	m = daemon_recv(x);
	assert_int_equal(m.type, LKS_REFUSED);
	assert_non_null(strstr(m.text, "no bus of this simulation"));
	assert_int_equal(vt.c[2].fd, -1);
	int y = join(2, "/tmp/vt-test/a");
	m = daemon_recv(y);
	assert_int_equal(m.type, LKS_REFUSED);
	assert_non_null(strstr(m.text, "already has a daemon"));
	/* after the end nobody joins */
	vt_end(&vt, false, "over");
	int z = join(2, "/tmp/vt-test/b");
	assert_int_equal(daemon_recv(z).type, LKS_REFUSED);
	assert_int_equal(vt.refused, 3);
	close(x), close(y), close(z);
	vt_close(&vt);
	close(a), close(b);
}

static void test_barrier_and_release(void **state)
{
	(void)state;
	make_sim();
	int a = join(0, "/tmp/vt-test/a");
	daemon_recv(a);
	/* one of two joined: time may not move */
	daemon_send(a, LKS_WAIT, 10000000, 0, 0, NULL);
	vt_on_client(&vt, &sim, 0, 1000);
	assert_false(vt_all_blocked(&vt, &sim));
	int b = join(1, "/tmp/vt-test/b");
	daemon_recv(b);
	assert_false(vt_all_blocked(&vt, &sim));   /* b has not waited yet */
	/* b wrote 8 bytes: until they are read, b is not blocked for us */
	sim.buses[1].master = 0;   /* "connected": the byte count matters */
	daemon_send(b, LKS_WAIT, 4000000, 8, LKS_WANT_INPUT, NULL);
	vt_on_client(&vt, &sim, 1, 1000);
	assert_false(vt_all_blocked(&vt, &sim));
	sim.buses[1].count.rx_bytes += 5;
	assert_false(vt_all_blocked(&vt, &sim));
	sim.buses[1].count.rx_bytes += 3;
	assert_true(vt_all_blocked(&vt, &sim));
	/* the earliest wake-up; then input b has not been told of: now */
	assert_int_equal(vt_next_wake(&vt, &sim), 4000000);
	sim.buses[1].count.tx_bytes += 6;
	assert_int_equal(vt_next_wake(&vt, &sim), 0);
	/* release at 1 ms: b (input) wakes, a (10 ms) does not */
	vt_release(&vt, &sim, 1000000, 2000);
	struct lks_msg m = daemon_recv(b);
	assert_int_equal(m.type, LKS_TIME);
	assert_int_equal(m.a, 1000000);
	assert_int_equal(m.b, 6);
	assert_int_equal(daemon_recv(a).type, 0);
	assert_false(vt.c[1].blocked);
	assert_true(vt.c[0].blocked);
	assert_false(vt_all_blocked(&vt, &sim));
	/* b waits again, without asking for input: the same 6 bytes wake nobody */
	daemon_send(b, LKS_WAIT, LKS_NEVER, 8, 0, NULL);
	vt_on_client(&vt, &sim, 1, 3000);
	assert_true(vt_all_blocked(&vt, &sim));
	assert_int_equal(vt_next_wake(&vt, &sim), 10000000);
	/* a command for every robot: due now, and CMD comes before TIME */
	char why[200];
	assert_int_equal(vt_command(&vt, -1, "mode oscillator", why, sizeof why), 2);
	assert_int_equal(vt_next_wake(&vt, &sim), 1000000);
	vt_release(&vt, &sim, 1000000, 4000);
	for (int fd = a; fd != -1; fd = fd == a ? b : -1) {
		m = daemon_recv(fd);
		assert_int_equal(m.type, LKS_CMD);
		assert_string_equal(m.text, "mode oscillator");
		assert_int_equal(daemon_recv(fd).type, LKS_TIME);
	}
	/* to one robot; its queue full */
	for (int i = 0; i < LKS_CMD_QUEUE; i++)
		assert_int_equal(vt_command(&vt, 0, "clear", why, sizeof why), 1);
	assert_int_equal(vt_command(&vt, 0, "clear", why, sizeof why), -1);
	assert_non_null(strstr(why, "commands waiting"));
	/* the end: STOP (with why) before TIME, to everyone blocked */
	for (size_t i = 0; i < 2; i++)
		daemon_send(i == 0 ? a : b, LKS_WAIT, LKS_NEVER, 8, 0, NULL), vt_on_client(&vt, &sim, i, 5000);
	vt_end(&vt, false, "the run's 45.000 s are over");
	vt_release(&vt, &sim, 2000000, 6000);
	int seen = 0;
	for (m = daemon_recv(b); m.type != 0; m = daemon_recv(b))
		if (m.type == LKS_STOP) {
			assert_string_equal(m.text, "the run's 45.000 s are over");
			seen++;
		}
	assert_int_equal(seen, 1);
	assert_true(vt.c[1].stop_sent);
	sim.buses[1].master = -1;
	vt_close(&vt);
	close(a), close(b);
}

static void test_leave_and_stall(void **state)
{
	(void)state;
	make_sim();
	char why[VT_WHY_MAX];
	/* nobody joined within the grace: the missing ones are named */
	assert_false(vt_stalled(&vt, &sim, 5000000000, 0, 10000000000, why, sizeof why));
	assert_true(vt_stalled(&vt, &sim, 11000000000, 0, 10000000000, why, sizeof why));
	assert_non_null(strstr(why, "0 of 2 daemon(s) joined"));
	assert_non_null(strstr(why, "a (/tmp/vt-test/a)"));
	int a = join(0, "/tmp/vt-test/a");
	int b = join(1, "/tmp/vt-test/b");
	daemon_recv(a), daemon_recv(b);
	vt.t_ns = 1;
	/* a runs (never waits) for longer than the grace */
	daemon_send(b, LKS_WAIT, LKS_NEVER, 0, 0, NULL);
	vt_on_client(&vt, &sim, 1, 1000);
	assert_false(vt_stalled(&vt, &sim, 2000, 0, 10000000000, why, sizeof why));
	assert_true(vt_stalled(&vt, &sim, 20000000000, 0, 10000000000, why, sizeof why));
	assert_non_null(strstr(why, "robot"));
	assert_non_null(strstr(why, "stalled"));
	/* a daemon that leaves before the end ends the run, as failed */
	close(a);
	vt_on_client(&vt, &sim, 0, 3000);
	assert_true(vt.ending);
	assert_true(vt.failed);
	assert_non_null(strstr(vt.end_why, "left the run"));
	assert_int_equal(vt_clients(&vt), 1);
	assert_true(vt.c[1].stop_pending);   /* b is told with its next TIME */
	vt_close(&vt);
	close(b);
}

/* AX-12 manual, PING: "FF FF 01 02 01 FB"; its status "FF FF 01 02 00 FC". */
static const uint8_t ping1[] = { 0xff, 0xff, 0x01, 0x02, 0x01, 0xfb };
static const uint8_t status1[] = { 0xff, 0xff, 0x01, 0x02, 0x00, 0xfc };

static void daemon_send_bytes(int fd, uint32_t type, uint64_t a, uint32_t flags, const uint8_t *bytes, size_t n)
{
	struct lks_msg m = { .type = type, .a = a, .flags = flags, .nbytes = (uint32_t)n };
	if (n > 0)
		memcpy(m.bytes, bytes, n);
	assert_int_equal(lks_send(fd, &m), 0);
}

static void test_inband(void **state)
{
	(void)state;
	make_sim();
	vt.inband = true;
	/* bus a "connected" (a descriptor that is not a pty: nothing is written to it) */
	int null_fd = open("/dev/null", O_RDWR);
	sim.buses[0].master = null_fd;
	sim.buses[0].opens = 1;
	int a = join(0, "/tmp/vt-test/a");
	struct lks_msg m = daemon_recv(a);
	assert_int_equal(m.type, LKS_WELCOME);
	assert_int_equal(m.flags, LKS_INBAND);
	int b = join(1, "/tmp/vt-test/b");
	daemon_recv(b);
	/* bytes before its port is open are not for this pty: dropped, counted */
	daemon_send_bytes(a, LKS_WAIT, LKS_NEVER, 0, ping1, sizeof ping1);
	vt_on_client(&vt, &sim, 0, 1000);
	assert_int_equal(vt.bytes_lost, sizeof ping1);
	assert_int_equal(sim.buses[0].count.rx_bytes, 0);
	/* the port opened: a PING at virtual 1 ms goes into the bus then */
	vt.t_ns = 1000000;
	daemon_send_bytes(a, LKS_WAIT, 50000000, LKS_WANT_INPUT | LKS_PORT_OPENED, ping1, sizeof ping1);
	vt_on_client(&vt, &sim, 0, 1000);
	daemon_send(b, LKS_WAIT, LKS_NEVER, 0, 0, NULL);
	vt_on_client(&vt, &sim, 1, 1000);
	assert_int_equal(sim.buses[0].count.rx_bytes, sizeof ping1);
	assert_int_equal(sim.buses[0].count.packets, 1);
	/* no byte count to wait for: blocked as soon as it said so */
	assert_true(vt_all_blocked(&vt, &sim));
	/* the status is on the line: its bytes go to a when they are due */
	int64_t due = sim_line_chunk_end(&sim.buses[0].line, 1000000000);
	assert_true(due > 1000000 && due < 2000000);
	vt_hand_over(&vt, &sim, sim_line_next(&sim.buses[0].line) - 1);
	assert_int_equal(vt.c[0].l[0].nout, 0);
	vt_hand_over(&vt, &sim, due);
	assert_int_equal(vt.c[0].l[0].nout, sizeof status1);
	assert_int_equal(sim.buses[0].count.tx_bytes, sizeof status1);
	assert_int_equal(vt_next_wake(&vt, &sim), vt.t_ns);   /* input it waits for: now */
	vt_release(&vt, &sim, (uint64_t)due, 2000);
	m = daemon_recv(a);
	assert_int_equal(m.type, LKS_TIME);
	assert_int_equal(m.nbytes, sizeof status1);
	assert_memory_equal(m.bytes, status1, sizeof status1);
	assert_int_equal(m.flags, 0);
	assert_int_equal(vt.c[0].l[0].nout, 0);
	/* the disconnect fault: the port a has open is gone, and the TIME says so */
	sim.buses[0].master = -1;
	daemon_send(a, LKS_WAIT, 3000000, 0, 0, NULL);
	vt_on_client(&vt, &sim, 0, 3000);
	vt_release(&vt, &sim, 3000000, 4000);
	m = daemon_recv(a);
	assert_int_equal(m.type, LKS_TIME);
	assert_int_equal(m.flags, LKS_BUS_GONE);
	/* bytes for the port gone: dropped, counted */
	daemon_send_bytes(a, LKS_WAIT, LKS_NEVER, 0, ping1, sizeof ping1);
	vt_on_client(&vt, &sim, 0, 5000);
	assert_int_equal(vt.bytes_lost, 2 * sizeof ping1);
	/* reconnected (another pty) and the port opened again: its last bytes,
	 * sent with its BYE, still go into the bus */
	sim.buses[0].master = null_fd;
	sim.buses[0].opens = 2;
	daemon_send_bytes(a, LKS_WAIT, LKS_NEVER, LKS_PORT_OPENED, NULL, 0);
	vt_on_client(&vt, &sim, 0, 6000);
	daemon_send_bytes(a, LKS_BYE, 0, 0, ping1, sizeof ping1);
	vt_on_client(&vt, &sim, 0, 7000);
	assert_int_equal(sim.buses[0].count.rx_bytes, 2 * sizeof ping1);
	assert_int_equal(vt.c[0].fd, -1);
	assert_true(vt.ending);   /* it left before the end */
	sim.buses[0].master = -1;
	vt_close(&vt);
	close(null_fd);
	close(a), close(b);
}

/* Bad input on the clock: bytes from a connection with no bus (no HELLO
 * yet), a payload that is not the length it says, one longer than a message
 * carries: each refused with why and counted, the daemon's part over. */
static void test_inband_bad_input(void **state)
{
	(void)state;
	make_sim();
	vt.inband = true;
	int x = connect_slot(3);
	daemon_send_bytes(x, LKS_WAIT, LKS_NEVER, 0, ping1, sizeof ping1);
	vt_on_client(&vt, &sim, 3, 1000);
	struct lks_msg m = daemon_recv(x);
	assert_int_equal(m.type, LKS_REFUSED);
	assert_non_null(strstr(m.text, "WAIT out of turn"));
	assert_int_equal(vt.bad_messages, 1);
	assert_int_equal(vt.c[3].fd, -1);
	assert_int_equal(sim.buses[0].count.rx_bytes, 0);
	/* a joined daemon's malformed message ends its part, and the run as failed */
	int a = join(0, "/tmp/vt-test/a");
	daemon_recv(a);
	struct lks_msg bad = { .magic = LKS_MAGIC, .type = LKS_WAIT, .nbytes = 100 };
	assert_int_equal(send(a, &bad, LKS_HEADER_SIZE + 6, 0), (ssize_t)(LKS_HEADER_SIZE + 6));
	vt_on_client(&vt, &sim, 0, 2000);
	assert_int_equal(vt.bad_messages, 2);
	assert_int_equal(vt.c[0].fd, -1);
	assert_true(vt.ending && vt.failed);
	assert_int_equal(sim.buses[0].count.rx_bytes, 0);
	vt_close(&vt);
	close(x), close(a);
	make_sim();
	vt.inband = true;
	int b = join(1, "/tmp/vt-test/b");
	daemon_recv(b);
	static uint8_t huge[sizeof(struct lks_msg) + 64];
	memcpy(huge, &bad, LKS_HEADER_SIZE);
	assert_int_equal(send(b, huge, sizeof huge, 0), (ssize_t)sizeof huge);
	vt_on_client(&vt, &sim, 1, 3000);
	assert_int_equal(vt.bad_messages, 1);
	assert_true(vt.ending && vt.failed);
	vt_close(&vt);
	close(b);
}

static void send_part(int fd, uint64_t bus, uint32_t flags, const uint8_t *bytes, size_t n)
{
	struct lks_msg m = { .type = LKS_PART, .c = bus, .flags = flags, .nbytes = (uint32_t)n };
	if (n > 0)
		memcpy(m.bytes, bytes, n);
	assert_int_equal(lks_send(fd, &m), 0);
}

/* One daemon on both buses: it joins with a HELLO a bus on one connection,
 * counts once in the barrier and for both buses in `expected`; bus b's
 * bytes come in the PART before its WAIT and go back in the PART before its
 * TIME; a PART for a bus it did not name is refused and counted. */
static void test_one_daemon_two_buses(void **state)
{
	(void)state;
	make_sim();
	vt.inband = true;
	int null_fd = open("/dev/null", O_RDWR);
	for (int i = 0; i < 2; i++) {
		sim.buses[i].master = null_fd;
		sim.buses[i].opens = 1;
	}
	int d = connect_slot(0);
	struct lks_msg h = { .type = LKS_HELLO, .a = 4242, .b = 2, .c = 0 };
	snprintf(h.text, sizeof h.text, "/tmp/vt-test/a");
	assert_int_equal(lks_send(d, &h), 0);
	vt_on_client(&vt, &sim, 0, 1000);
	assert_int_equal(daemon_recv(d).type, LKS_WELCOME);
	assert_int_equal(vt.c[0].bus, -1);   /* not joined until it named both */
	assert_int_equal(vt_buses_covered(&vt), 0);
	h.c = 1;
	snprintf(h.text, sizeof h.text, "/tmp/vt-test/b");
	assert_int_equal(lks_send(d, &h), 0);
	vt_on_client(&vt, &sim, 0, 1000);
	assert_int_equal(daemon_recv(d).type, LKS_WELCOME);
	assert_int_equal(vt_clients(&vt), 1);
	assert_int_equal(vt_buses_covered(&vt), 2);   /* the run needs nobody else */
	assert_int_equal(vt.joined, 1);
	/* a second daemon for bus b is refused */
	int other = join(1, "/tmp/vt-test/b");
	assert_int_equal(daemon_recv(other).type, LKS_REFUSED);
	close(other);
	/* a PING on each bus: b's in the PART, a's in the WAIT; blocked only once the WAIT came */
	vt.t_ns = 1000000;
	send_part(d, 1, LKS_WANT_INPUT | LKS_PORT_OPENED, ping1, sizeof ping1);
	vt_on_client(&vt, &sim, 0, 1000);
	assert_false(vt_all_blocked(&vt, &sim));
	assert_int_equal(sim.buses[1].count.rx_bytes, sizeof ping1);
	daemon_send_bytes(d, LKS_WAIT, 50000000, LKS_PORT_OPENED, ping1, sizeof ping1);
	vt_on_client(&vt, &sim, 0, 1000);
	assert_true(vt_all_blocked(&vt, &sim));
	assert_int_equal(sim.buses[0].count.rx_bytes, sizeof ping1);
	/* both statuses come back; only b's wakes it (a did not ask) */
	int64_t due = sim_line_chunk_end(&sim.buses[1].line, 1000000000);
	vt_hand_over(&vt, &sim, due);
	assert_int_equal(vt.c[0].l[1].nout, sizeof status1);
	assert_int_equal(vt_next_wake(&vt, &sim), vt.t_ns);
	/* bus a goes (the disconnect fault): the PART says nothing of it, the TIME does */
	sim.buses[0].master = -1;
	vt_release(&vt, &sim, (uint64_t)due, 2000);
	struct lks_msg m = daemon_recv(d);
	assert_int_equal(m.type, LKS_PART);
	assert_int_equal(m.c, 1);
	assert_int_equal(m.flags, 0);
	assert_int_equal(m.nbytes, sizeof status1);
	assert_memory_equal(m.bytes, status1, sizeof status1);
	m = daemon_recv(d);
	assert_int_equal(m.type, LKS_TIME);
	assert_int_equal(m.flags, LKS_BUS_GONE);
	assert_false(vt.c[0].blocked);
	/* commands for bus b's robot reach the one daemon, once */
	char why[200];
	assert_int_equal(vt_command(&vt, 1, "freeze", why, sizeof why), 1);
	assert_int_equal(vt_command(&vt, -1, "go", why, sizeof why), 1);
	/* a PART for bus 2, which it did not name: refused, counted, the run ends */
	send_part(d, 2, 0, ping1, sizeof ping1);
	vt_on_client(&vt, &sim, 0, 3000);
	assert_int_equal(vt.bad_parts, 1);
	assert_true(vt.bad_messages >= 1);
	assert_int_equal(vt.c[0].fd, -1);
	assert_true(vt.ending);
	assert_true(vt.failed);
	m = daemon_recv(d);
	assert_int_equal(m.type, LKS_REFUSED);
	assert_non_null(strstr(m.text, "PART for bus 2"));
	close(d);
	close(null_fd);
	sim.buses[1].master = -1;
	vt_close(&vt);
}

/* The pty transport carries one bus a daemon: two are refused, said why;
 * HELLOs out of order too. */
static void test_two_buses_refused(void **state)
{
	(void)state;
	make_sim();
	vt.inband = false;
	int d = connect_slot(0);
	struct lks_msg h = { .type = LKS_HELLO, .a = 4242, .b = 2, .c = 0 };
	snprintf(h.text, sizeof h.text, "/tmp/vt-test/a");
	assert_int_equal(lks_send(d, &h), 0);
	vt_on_client(&vt, &sim, 0, 1000);
	struct lks_msg m = daemon_recv(d);
	assert_int_equal(m.type, LKS_REFUSED);
	assert_non_null(strstr(m.text, "one bus a daemon"));
	close(d);
	vt.inband = true;
	d = connect_slot(0);
	h.c = 1;   /* bus 1 first */
	assert_int_equal(lks_send(d, &h), 0);
	vt_on_client(&vt, &sim, 0, 1000);
	m = daemon_recv(d);
	assert_int_equal(m.type, LKS_REFUSED);
	assert_non_null(strstr(m.text, "in index order"));
	assert_false(vt.ending);   /* it never joined */
	close(d);
	vt_close(&vt);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_join),
		cmocka_unit_test(test_barrier_and_release),
		cmocka_unit_test(test_leave_and_stall),
		cmocka_unit_test(test_inband),
		cmocka_unit_test(test_one_daemon_two_buses),
		cmocka_unit_test(test_two_buses_refused),
		cmocka_unit_test(test_inband_bad_input),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
