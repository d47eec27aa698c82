/* test_common_lockstep.c — the lockstep protocol (common/lockstep.h): one
 * message a datagram, malformed ones refused; the daemon's client against a
 * simulator played by the test on the other end of a socket pair: a WAIT
 * says when and how many bytes, is sent once, TIME moves the virtual clock
 * (clock.h) and the announced byte count, commands are queued (and counted
 * when too many), STOP is noted, a closed socket ends a blocking wait; and
 * the whole join (HELLO, WELCOME or REFUSED) against a listening socket
 * served by a child process. In-band (LKS2): a message is its header and
 * the payload it says, nothing more or less (a payload too long is refused
 * when sent; a datagram too long, or not the length its header says, when
 * received); the client's WAIT carries what was written since the last one
 * and a TIME's bytes wait, unread ones first, for the daemon's reads; bytes
 * in a message that should have none are a protocol error. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "clock.h"
#include "lockstep.h"
#include "scratch.h"

/* A client on one end of a SOCK_SEQPACKET pair; the test holds the other. */
static int client_pair(struct lks_client *c, int *sim)
{
	int sv[2];
	assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
	memset(c, 0, sizeof *c);
	c->fd = sv[0];
	c->mono0_us = LKS_MONO0_US;
	c->wall0_us = LKS_WALL0_US;
	*sim = sv[1];
	return 0;
}

static void sim_send(int fd, uint32_t type, uint64_t a, uint64_t b, const char *text)
{
	struct lks_msg m = { .type = type, .a = a, .b = b };
	if (text)
		snprintf(m.text, sizeof m.text, "%s", text);
	assert_int_equal(lks_send(fd, &m), 0);
}

static void test_round_trip(void **state)
{
	(void)state;
	int sv[2];
	assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
	struct lks_msg m = { .type = LKS_WAIT, .a = 123, .b = 456, .flags = LKS_WANT_INPUT };
	memset(m.text, 'x', sizeof m.text);   /* no NUL: it gets one */
	assert_int_equal(lks_send(sv[0], &m), 0);
	struct lks_msg r;
	char why[200];
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), 1);
	assert_int_equal(r.type, LKS_WAIT);
	assert_int_equal(r.a, 123);
	assert_int_equal(r.b, 456);
	assert_int_equal(r.flags, LKS_WANT_INPUT);
	assert_int_equal(strlen(r.text), LKS_TEXT_MAX - 1);
	/* a datagram of another size, another magic, an unknown type */
	char junk[10] = "junk";
	assert_int_equal(send(sv[0], junk, sizeof junk, 0), (ssize_t)sizeof junk);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), -1);
	assert_int_equal(errno, EPROTO);
	assert_non_null(strstr(why, "not a lockstep message"));
	struct lks_msg bad = { .magic = 0, .type = LKS_TIME };
	assert_int_equal(send(sv[0], &bad, sizeof bad, 0), (ssize_t)sizeof bad);   /* wrong magic */
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), -1);
	bad.magic = LKS_MAGIC;
	bad.type = 99;
	assert_int_equal(send(sv[0], &bad, sizeof bad, 0), (ssize_t)sizeof bad);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), -1);
	assert_string_equal(lks_type_name(99), "UNKNOWN");
	assert_string_equal(lks_type_name(LKS_TIME), "TIME");
	close(sv[0]);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), 0);   /* the peer's end */
	close(sv[1]);
}

static void test_wait_once_then_time(void **state)
{
	(void)state;
	struct lks_client c;
	int sim;
	client_pair(&c, &sim);
	c.written = 77;
	/* wake at virtual 10 ms, as the daemon's clock counts it */
	assert_int_equal(lks_client_wait(&c, LKS_MONO0_US + 10000, true), 0);
	assert_true(c.waiting);
	assert_int_equal(lks_client_wait(&c, LKS_MONO0_US + 5000, false), 0);   /* not sent again */
	struct lks_msg m;
	char why[200];
	assert_int_equal(lks_recv(sim, &m, why, sizeof why), 1);
	assert_int_equal(m.type, LKS_WAIT);
	assert_int_equal(m.a, 10000000);     /* ns of virtual time */
	assert_int_equal(m.b, 77);
	assert_int_equal(m.flags, LKS_WANT_INPUT);
	/* only one WAIT went out */
	assert_int_equal(recv(sim, &m, sizeof m, MSG_DONTWAIT), -1);
	/* a wake-up that is not set: LKS_NEVER */
	c.waiting = false;
	assert_int_equal(lks_client_wait(&c, UINT64_MAX, false), 0);
	assert_int_equal(lks_recv(sim, &m, why, sizeof why), 1);
	assert_int_equal(m.a, LKS_NEVER);
	assert_int_equal(m.flags, 0);

	sim_send(sim, LKS_TIME, 10000500, 12, NULL);   /* 10.0005 ms, 12 bytes released */
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_TIME);
	assert_false(c.waiting);
	assert_int_equal(c.delivered, 12);
	assert_int_equal(lks_client_now_us(&c), LKS_MONO0_US + 10000);
	assert_true(clock_is_virtual());
	assert_int_equal(clock_mono_us(), LKS_MONO0_US + 10000);
	assert_int_equal(clock_wall_us(), LKS_WALL0_US + 10000);
	assert_true(lks_client_take_time(&c));
	assert_false(lks_client_take_time(&c));
	/* time never goes back */
	sim_send(sim, LKS_TIME, 5000, 12, NULL);
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_TIME);
	assert_int_equal(clock_mono_us(), LKS_MONO0_US + 10000);
	close(sim);
	close(c.fd);
}

static void test_commands_and_stop(void **state)
{
	(void)state;
	struct lks_client c;
	int sim;
	client_pair(&c, &sim);
	char why[200], out[LKS_TEXT_MAX];
	for (int i = 0; i < LKS_CMD_QUEUE + 2; i++) {
		char text[32];
		snprintf(text, sizeof text, "param k 0.0%d", i);
		sim_send(sim, LKS_CMD, 0, 0, text);
		assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_CMD);
	}
	assert_int_equal(c.ncmds, LKS_CMD_QUEUE);
	assert_int_equal(c.cmds_dropped, 2);
	assert_true(lks_client_next_cmd(&c, out, sizeof out));
	assert_string_equal(out, "param k 0.00");
	assert_true(lks_client_next_cmd(&c, out, sizeof out));
	assert_string_equal(out, "param k 0.01");   /* in the order sent */
	while (lks_client_next_cmd(&c, out, sizeof out))
		;
	assert_int_equal(c.ncmds, 0);
	sim_send(sim, LKS_STOP, 0, 0, "the run's 40 s are over");
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_STOP);
	assert_true(c.stop);
	assert_string_equal(c.stop_why, "the run's 40 s are over");
	/* something a simulator never sends */
	sim_send(sim, LKS_HELLO, 0, 0, NULL);
	assert_int_equal(lks_client_read(&c, why, sizeof why), -1);
	assert_non_null(strstr(why, "unexpected HELLO"));
	close(sim);
	close(c.fd);
}

static void test_block(void **state)
{
	(void)state;
	struct lks_client c;
	int sim;
	char why[200];
	client_pair(&c, &sim);
	/* the answer is already there: CMD, then TIME */
	sim_send(sim, LKS_CMD, 0, 0, "mode oscillator");
	sim_send(sim, LKS_TIME, 3000000000ull, 40, NULL);
	assert_int_equal(lks_client_block(&c, LKS_MONO0_US + 3000000, true, why, sizeof why), 0);
	assert_int_equal(c.delivered, 40);
	assert_int_equal(c.ncmds, 1);
	assert_int_equal(clock_mono_us(), LKS_MONO0_US + 3000000);
	/* the simulator went away: the wait ends with why */
	close(sim);
	assert_int_equal(lks_client_block(&c, LKS_MONO0_US + 4000000, false, why, sizeof why), -1);
	assert_non_null(strstr(why, "simulator"));
	close(c.fd);
}

/* The child plays the simulator: accepts one daemon, reads its HELLO and
 * answers as told. Exit 0 when the HELLO was as expected. */
static void fake_sim(int lfd, const char *answer)
{
	/* the listening socket is non-blocking (the simulator polls it): wait
	 * for the parent's connect, or accept would race it */
	struct pollfd p = { .fd = lfd, .events = POLLIN };
	int fd = poll(&p, 1, 10000) == 1 ? accept(lfd, NULL, NULL) : -1;
	struct lks_msg m;
	char why[200];
	int ok = fd >= 0 && lks_recv(fd, &m, why, sizeof why) == 1 && m.type == LKS_HELLO &&
	         strcmp(m.name, "robot7") == 0 && (pid_t)m.a == getppid() && strstr(m.text, "port-link") != NULL;
	struct lks_msg r = { .type = strcmp(answer, "welcome") == 0 ? LKS_WELCOME : LKS_REFUSED };
	r.a = 2500000;   /* virtual now: 2.5 ms */
	r.b = LKS_MONO0_US;
	r.c = (uint64_t)LKS_WALL0_US;
	snprintf(r.text, sizeof r.text, "no bus of this simulation is at that port");
	if (fd >= 0)
		lks_send(fd, &r);
	_exit(ok ? 0 : 1);
}

static void join(const char *answer, int expect_rc, const char *expect_err)
{
	char sock[300], port[300], err[400] = "";
	snprintf(sock, sizeof sock, "%s/clock-%s", scratch_dir, answer);
	snprintf(port, sizeof port, "%s/port-link", scratch_dir);
	int lfd = lks_listen(sock, err, sizeof err);
	assert_true(lfd >= 0);
	pid_t pid = fork();
	assert_true(pid >= 0);
	if (pid == 0)
		fake_sim(lfd, answer);
	struct lks_client c;
	int rc = lks_client_open(&c, sock, port, "robot7", err, sizeof err);
	int status = -1;
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
	assert_int_equal(rc, expect_rc);
	if (expect_err)
		assert_non_null(strstr(err, expect_err));
	if (rc == 0) {
		assert_int_equal(c.t_ns, 2500000);
		/* (the process's clock stays where earlier tests moved it: it never goes back) */
		assert_int_equal(lks_client_now_us(&c), LKS_MONO0_US + 2500);
		lks_client_close(&c);
	}
	assert_int_equal(c.fd, -1);
	close(lfd);
}

static void test_join(void **state)
{
	(void)state;
	join("welcome", 0, NULL);
	join("refused", -1, "no bus of this simulation");
	/* nobody listening */
	struct lks_client c;
	char err[400], sock[300];
	snprintf(sock, sizeof sock, "%s/nobody", scratch_dir);
	assert_int_equal(lks_client_open(&c, sock, "/dev/null", "r", err, sizeof err), -1);
	assert_non_null(strstr(err, "cannot reach the simulator"));
	assert_non_null(strstr(err, "--lockstep"));
	/* a path too long for a socket address */
	char longp[200];
	memset(longp, 'a', sizeof longp - 1);
	longp[sizeof longp - 1] = '\0';
	assert_int_equal(lks_client_open(&c, longp, "/dev/null", "r", err, sizeof err), -1);
	assert_non_null(strstr(err, "longer than"));
	/* the listener refuses to replace what is not a socket */
	char file[300];
	snprintf(file, sizeof file, "%s/plain", scratch_dir);
	FILE *f = fopen(file, "w");
	assert_non_null(f);
	fclose(f);
	assert_int_equal(lks_listen(file, err, sizeof err), -1);
	assert_non_null(strstr(err, "not a socket"));
	/* a live simulator's socket is refused and left alone; a dead one's replaced */
	char live[300];
	snprintf(live, sizeof live, "%s/live.sock", scratch_dir);
	int first = lks_listen(live, err, sizeof err);
	assert_true(first >= 0);
	assert_int_equal(lks_listen(live, err, sizeof err), -1);
	assert_non_null(strstr(err, "another simulator listens on it"));
	struct stat st;
	assert_int_equal(stat(live, &st), 0);
	close(first);
	int again = lks_listen(live, err, sizeof err);
	assert_true(again >= 0);
	close(again);
	unlink(live);
}

/* Send raw bytes as one datagram. */
static void raw_send(int fd, const void *p, size_t n)
{
	assert_int_equal(send(fd, p, n, 0), (ssize_t)n);
}

static void test_payload_framing(void **state)
{
	(void)state;
	int sv[2];
	assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
	struct lks_msg m = { .type = LKS_WAIT, .a = 1, .nbytes = 3, .bytes = { 0xff, 0xff, 0x01 } };
	assert_int_equal(lks_send(sv[0], &m), 0);
	/* only the header and the payload used went on the wire */
	struct lks_msg r;
	assert_int_equal(recv(sv[1], &r, sizeof r, MSG_PEEK | MSG_TRUNC), (ssize_t)(LKS_HEADER_SIZE + 3));
	char why[200];
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), 1);
	assert_int_equal(r.nbytes, 3);
	assert_memory_equal(r.bytes, m.bytes, 3);
	/* the most a message carries goes; one more is refused, not cut short */
	m.nbytes = LKS_BYTES_MAX;
	memset(m.bytes, 0x5a, sizeof m.bytes);
	assert_int_equal(lks_send(sv[0], &m), 0);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), 1);
	assert_int_equal(r.nbytes, LKS_BYTES_MAX);
	m.nbytes = LKS_BYTES_MAX + 1;
	assert_int_equal(lks_send(sv[0], &m), -1);
	assert_int_equal(errno, EMSGSIZE);
	/* a header that says more than came, or less */
	struct lks_msg bad = { .magic = LKS_MAGIC, .type = LKS_WAIT, .nbytes = 10 };
	raw_send(sv[0], &bad, LKS_HEADER_SIZE + 5);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), -1);
	assert_int_equal(errno, EPROTO);
	assert_non_null(strstr(why, "says it carries 10 bus bytes"));
	bad.nbytes = 0;
	raw_send(sv[0], &bad, LKS_HEADER_SIZE + 5);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), -1);
	assert_non_null(strstr(why, "says it carries 0 bus bytes"));
	/* a length beyond the largest, and a datagram longer than any message */
	bad.nbytes = LKS_BYTES_MAX + 1;
	raw_send(sv[0], &bad, LKS_HEADER_SIZE);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), -1);
	assert_non_null(strstr(why, "at most 4096 bus bytes"));
	static uint8_t huge[sizeof(struct lks_msg) + 100];
	memcpy(huge, &bad, LKS_HEADER_SIZE);
	raw_send(sv[0], huge, sizeof huge);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), -1);
	assert_non_null(strstr(why, "at most 4096 bus bytes"));
	/* shorter than a header */
	raw_send(sv[0], &bad, LKS_HEADER_SIZE - 1);
	assert_int_equal(lks_recv(sv[1], &r, why, sizeof why), -1);
	assert_non_null(strstr(why, "not a lockstep message"));
	close(sv[0]);
	close(sv[1]);
}

static void sim_send_bytes(int fd, uint64_t t, uint32_t flags, const void *bytes, size_t n)
{
	struct lks_msg m = { .type = LKS_TIME, .a = t, .flags = flags, .nbytes = (uint32_t)n };
	memcpy(m.bytes, bytes, n);
	assert_int_equal(lks_send(fd, &m), 0);
}

static void test_inband_client(void **state)
{
	(void)state;
	struct lks_client c;
	int sim;
	client_pair(&c, &sim);
	c.inband = true;
	/* what was written goes with the WAIT, once; the port's opening too */
	memcpy(c.bus[0].out, "\xff\xff\x01\x02", 4);
	c.bus[0].nout = 4;
	lks_client_port_opened(&c, 0);
	assert_int_equal(c.bus[0].nout, 0);   /* written for the port before: not for this one */
	memcpy(c.bus[0].out, "ping", 4);
	c.bus[0].nout = 4;
	assert_int_equal(lks_client_wait(&c, LKS_MONO0_US + 1000, true), 0);
	struct lks_msg m;
	char why[200];
	assert_int_equal(lks_recv(sim, &m, why, sizeof why), 1);
	assert_int_equal(m.type, LKS_WAIT);
	assert_int_equal(m.flags, LKS_WANT_INPUT | LKS_PORT_OPENED);
	assert_int_equal(m.nbytes, 4);
	assert_memory_equal(m.bytes, "ping", 4);
	assert_int_equal(c.bus[0].nout, 0);
	/* TIMEs' bytes queue behind the unread ones */
	sim_send_bytes(sim, 1000, 0, "abc", 3);
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_TIME);
	assert_int_equal(c.bus[0].nin - c.bus[0].in_off, 3);
	c.bus[0].in_off = 1;   /* the daemon read one */
	sim_send_bytes(sim, 2000, 0, "de", 2);
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_TIME);
	assert_int_equal(c.bus[0].nin - c.bus[0].in_off, 4);
	assert_memory_equal(c.bus[0].in + c.bus[0].in_off, "bcde", 4);
	assert_false(c.bus[0].bus_gone);
	/* more than fits unread is counted, not overrun */
	static uint8_t many[LKS_BYTES_MAX];
	sim_send_bytes(sim, 3000, LKS_BUS_GONE, many, sizeof many);
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_TIME);
	assert_int_equal(c.bus[0].nin, LKS_BYTES_MAX);
	assert_int_equal(c.bus[0].in_dropped, 4);
	assert_true(c.bus[0].bus_gone);
	/* a (re)opened port starts clean */
	lks_client_port_opened(&c, 0);
	assert_int_equal(c.bus[0].nin, 0);
	assert_false(c.bus[0].bus_gone);
	/* bytes in a message that carries none */
	struct lks_msg cmd = { .type = LKS_CMD, .nbytes = 1 };
	assert_int_equal(lks_send(sim, &cmd), 0);
	assert_int_equal(lks_client_read(&c, why, sizeof why), -1);
	assert_non_null(strstr(why, "a CMD from the simulator carries 1 bus bytes"));
	/* the last bytes go with BYE */
	memcpy(c.bus[0].out, "bye", 3);
	c.bus[0].nout = 3;
	lks_client_close(&c);
	assert_int_equal(lks_recv(sim, &m, why, sizeof why), 1);
	assert_int_equal(m.type, LKS_BYE);
	assert_int_equal(m.nbytes, 3);
	close(sim);
}

static void test_pty_transport_refuses_bytes(void **state)
{
	(void)state;
	struct lks_client c;
	int sim;
	client_pair(&c, &sim);   /* WELCOME said nothing of in-band */
	c.bus[0].nout = 0;
	sim_send_bytes(sim, 1000, 0, "x", 1);
	char why[200];
	assert_int_equal(lks_client_read(&c, why, sizeof why), -1);
	assert_int_equal(errno, EPROTO);
	assert_non_null(strstr(why, "through the pty"));
	close(sim);
	close(c.fd);
}

static void sim_recv(int fd, struct lks_msg *m)
{
	char why[200];
	assert_int_equal(lks_recv(fd, m, why, sizeof why), 1);
}

/* A daemon on two buses: each WAIT goes after a PART for bus 1 (its flags
 * and bytes), bus 0's in the WAIT itself; a PART before the TIME delivers
 * bus 1's bytes to bus 1 only; a PART for a bus it did not name is refused
 * and counted. */
static void test_two_buses(void **state)
{
	(void)state;
	struct lks_client c;
	int sim;
	char why[200];
	client_pair(&c, &sim);
	c.inband = true;
	c.nbuses = 2;
	lks_client_port_opened(&c, 1);
	memcpy(c.bus[0].out, "zero", 4);
	c.bus[0].nout = 4;
	memcpy(c.bus[1].out, "one!!", 5);
	c.bus[1].nout = 5;
	/* only bus 1 awaits a reply */
	assert_int_equal(lks_client_wait(&c, LKS_MONO0_US + 7000, 1u << 1), 0);
	struct lks_msg m;
	sim_recv(sim, &m);
	assert_int_equal(m.type, LKS_PART);
	assert_int_equal(m.c, 1);
	assert_int_equal(m.flags, LKS_WANT_INPUT | LKS_PORT_OPENED);
	assert_int_equal(m.nbytes, 5);
	assert_memory_equal(m.bytes, "one!!", 5);
	sim_recv(sim, &m);
	assert_int_equal(m.type, LKS_WAIT);
	assert_int_equal(m.a, 7000000);
	assert_int_equal(m.flags, 0);
	assert_int_equal(m.nbytes, 4);
	assert_memory_equal(m.bytes, "zero", 4);
	assert_int_equal(c.bus[0].nout + c.bus[1].nout, 0);
	/* the answer: bus 1's bytes and its loss in a PART, then the TIME */
	struct lks_msg part = { .type = LKS_PART, .c = 1, .flags = LKS_BUS_GONE, .nbytes = 3 };
	memcpy(part.bytes, "abc", 3);
	assert_int_equal(lks_send(sim, &part), 0);
	sim_send_bytes(sim, 7000000, 0, "xy", 2);
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_PART);
	assert_true(c.waiting);   /* a PART is not the answer */
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_TIME);
	assert_false(c.waiting);
	assert_int_equal(c.bus[1].nin, 3);
	assert_memory_equal(c.bus[1].in, "abc", 3);
	assert_true(c.bus[1].bus_gone);
	assert_int_equal(c.bus[0].nin, 2);
	assert_memory_equal(c.bus[0].in, "xy", 2);
	assert_false(c.bus[0].bus_gone);
	/* the next WAIT has nothing new to say for bus 1, but its PART still goes */
	assert_int_equal(lks_client_wait(&c, UINT64_MAX, 1u), 0);
	sim_recv(sim, &m);
	assert_int_equal(m.type, LKS_PART);
	assert_int_equal(m.flags, 0);
	assert_int_equal(m.nbytes, 0);
	sim_recv(sim, &m);
	assert_int_equal(m.type, LKS_WAIT);
	assert_int_equal(m.a, LKS_NEVER);
	assert_int_equal(m.flags, LKS_WANT_INPUT);
	/* bytes for a bus it did not name: refused, counted */
	part.c = 2;
	assert_int_equal(lks_send(sim, &part), 0);
	assert_int_equal(lks_client_read(&c, why, sizeof why), -1);
	assert_int_equal(errno, EPROTO);
	assert_non_null(strstr(why, "PART from the simulator for bus 2"));
	assert_int_equal(c.bad_parts, 1);
	part.c = 0;   /* bus 0's go in the TIME itself */
	assert_int_equal(lks_send(sim, &part), 0);
	assert_int_equal(lks_client_read(&c, why, sizeof why), -1);
	assert_int_equal(c.bad_parts, 2);
	/* BYE: bus 1's last bytes in a PART before it (once its WAIT is
	 * answered: while one is out, the simulator takes no PART, and the BYE
	 * goes alone) */
	sim_send_bytes(sim, 8000000, 0, "", 0);
	assert_int_equal(lks_client_read(&c, why, sizeof why), LKS_TIME);
	memcpy(c.bus[1].out, "end", 3);
	c.bus[1].nout = 3;
	lks_client_close(&c);
	sim_recv(sim, &m);
	assert_int_equal(m.type, LKS_PART);
	assert_int_equal(m.nbytes, 3);
	sim_recv(sim, &m);
	assert_int_equal(m.type, LKS_BYE);
	close(sim);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_round_trip),
		cmocka_unit_test(test_wait_once_then_time),
		cmocka_unit_test(test_commands_and_stop),
		cmocka_unit_test(test_block),
		cmocka_unit_test(test_join),
		cmocka_unit_test(test_payload_framing),
		cmocka_unit_test(test_inband_client),
		cmocka_unit_test(test_pty_transport_refuses_bytes),
		cmocka_unit_test(test_two_buses),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
