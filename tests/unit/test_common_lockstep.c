/* test_common_lockstep.c — the lockstep protocol (common/lockstep.h): one
 * message a datagram, malformed ones refused; the daemon's client against a
 * simulator played by the test on the other end of a socket pair: a WAIT
 * says when and how many bytes, is sent once, TIME moves the virtual clock
 * (clock.h) and the announced byte count, commands are queued (and counted
 * when too many), STOP is noted, a closed socket ends a blocking wait; and
 * the whole join (HELLO, WELCOME or REFUSED) against a listening socket
 * served by a child process. */
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

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_round_trip),
		cmocka_unit_test(test_wait_once_then_time),
		cmocka_unit_test(test_commands_and_stop),
		cmocka_unit_test(test_block),
		cmocka_unit_test(test_join),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
