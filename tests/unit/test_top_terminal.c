/* test_top_terminal.c — the real undulate-top binary on a pseudo-terminal:
 * it switches the terminal to raw mode and the alternate screen, and gives
 * the terminal back as it found it on q, Ctrl-C and SIGTERM; its keys send
 * the documented commands to the robot's local command socket (a fake robot
 * here, in a directory of the test's own) and the robot's answer shows up.
 * Needs $BUILD/bin/undulate-top (tests/run.sh exports BUILD). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <lcm/lcm.h>
#include "csock.h"
#include "scratch.h"
#include "undulate_command_t.h"
#include "undulate_event_t.h"
#include "undulate_osc_params_t.h"
#include "undulate_robot_state_t.h"

/* Output kept from the program (a few screens). */
#define T_OUT (256 * 1024)
/* How long the program may take to draw or to exit (ms). */
#define T_TIMEOUT_MS 5000
/* This test's own multicast port (tools range 7750-7799), moved by
 * $TEST_PORT_OFFSET as tests/lib.sh moves every integration test's port. */
#define T_LCM_PORT 7751
/* Offsets tests/lib.sh accepts: the highest port, 7999 + offset, stays < 65536. */
#define T_PORT_OFFSET_MAX 57000

struct child {
	pid_t pid;
	int master;
	char out[T_OUT];
	size_t len;
};

static char binary[512];
static char lcm_url[64];

static int setup(void **state)
{
	(void)state;
	const char *offset_text = getenv("TEST_PORT_OFFSET");
	long offset = 0;
	if (offset_text != NULL && *offset_text != '\0') {
		char *end;
		errno = 0;
		offset = strtol(offset_text, &end, 10);
		if (errno != 0 || *end != '\0' || offset < 0 || offset > T_PORT_OFFSET_MAX) {
			fprintf(stderr, "# TEST_PORT_OFFSET must be 0..%d, not '%s'\n", T_PORT_OFFSET_MAX, offset_text);
			return -1;
		}
	}
	snprintf(lcm_url, sizeof(lcm_url), "udpm://239.255.76.67:%ld?ttl=0", T_LCM_PORT + offset);
	const char *b = getenv("BUILD");
	snprintf(binary, sizeof(binary), "%s/bin/undulate-top", b && *b ? b : "build");
	if (access(binary, X_OK) != 0) {
		fprintf(stderr, "# %s not built (set BUILD)\n", binary);
		return -1;
	}
	return 0;
}

/* The program under test, while it runs: a check that fails jumps out of
 * the test before wait_exit(), and the teardown must not leave it behind. */
static pid_t live_child = -1;

static void start(struct child *c, const char *extra)
{
	memset(c, 0, sizeof(*c));
	c->master = posix_openpt(O_RDWR | O_NOCTTY);
	assert_true(c->master >= 0);
	assert_int_equal(grantpt(c->master), 0);
	assert_int_equal(unlockpt(c->master), 0);
	char *slave = ptsname(c->master);
	assert_non_null(slave);
	c->pid = fork();
	assert_true(c->pid >= 0);
	if (c->pid == 0) {
		setsid();
		int s = open(slave, O_RDWR); /* becomes the controlling terminal */
		struct winsize ws = { .ws_row = 24, .ws_col = 80 };
		ioctl(s, TIOCSWINSZ, &ws);
		dup2(s, 0);
		dup2(s, 1);
		dup2(s, 2);
		execl(binary, binary, "--lcm-url", lcm_url, extra, (char *)NULL);
		_exit(127);
	}
	live_child = c->pid;
}

/* Reads output until NEEDLE appears or TIMEOUT_MS passed; returns whether it did. */
static int read_until_ms(struct child *c, const char *needle, long timeout_ms)
{
	struct timespec t0, t;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	for (;;) {
		c->out[c->len] = '\0';
		if (strstr(c->out, needle))
			return 1;
		clock_gettime(CLOCK_MONOTONIC, &t);
		long ms = (t.tv_sec - t0.tv_sec) * 1000 + (t.tv_nsec - t0.tv_nsec) / 1000000;
		if (ms > timeout_ms)
			return 0;
		struct pollfd p = { .fd = c->master, .events = POLLIN };
		if (poll(&p, 1, 50) > 0) {
			ssize_t n = read(c->master, c->out + c->len, T_OUT - 1 - c->len);
			if (n > 0)
				c->len += (size_t)n;
			else if (n < 0 && errno == EIO)
				return 0; /* the program closed the terminal */
			if (c->len >= T_OUT - 1)
				c->len = 0; /* keep the newest output */
		}
	}
}

static int read_until(struct child *c, const char *needle)
{
	return read_until_ms(c, needle, T_TIMEOUT_MS);
}

/* Waits for the child; returns its exit status, -1 on timeout (killed). */
static int wait_exit(struct child *c)
{
	for (int i = 0; i < T_TIMEOUT_MS / 10; i++) {
		int st;
		/* drain output so the program never blocks on a full pty */
		char sink[4096];
		while (read(c->master, sink, sizeof(sink)) > 0)
			;
		if (waitpid(c->pid, &st, WNOHANG) == c->pid) {
			live_child = -1;
			return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
		}
		usleep(10000);
	}
	kill(c->pid, SIGKILL);
	waitpid(c->pid, NULL, 0);
	live_child = -1;
	return -1;
}

/* KEY (or signal SIG) ends the session; the program exits with WANT. */
static void check_session(const char *key, int sig, int want)
{
	struct child *c = calloc(1, sizeof(*c));
	start(c, "--read-only");
	fcntl(c->master, F_SETFL, O_NONBLOCK);
	assert_true(read_until(c, "undulate-top"));
	assert_true(read_until(c, "READ-ONLY"));
	/* while running: raw (no canonical input, no echo, no signals from keys) */
	struct termios during;
	assert_int_equal(tcgetattr(c->master, &during), 0);
	assert_false(during.c_lflag & (ICANON | ECHO | ISIG));
	assert_non_null(strstr(c->out, "\033[?1049h"));
	if (key)
		assert_int_equal(write(c->master, key, strlen(key)), (ssize_t)strlen(key));
	else
		kill(c->pid, sig);
	assert_true(read_until(c, "\033[?1049l")); /* alternate screen left */
	assert_int_equal(wait_exit(c), want);
	/* the terminal is back in cooked mode, as a fresh pty starts */
	struct termios after;
	assert_int_equal(tcgetattr(c->master, &after), 0);
	assert_true((after.c_lflag & (ICANON | ECHO | ISIG)) == (ICANON | ECHO | ISIG));
	assert_non_null(strstr(c->out, "\033[?25h")); /* cursor shown again */
	close(c->master);
	free(c);
}

static void test_quit_key(void **state)
{
	(void)state;
	check_session("q", 0, 0);
}

static void test_ctrl_c(void **state)
{
	(void)state;
	/* an interrupt, not a plain quit: 130, as a shell reports SIGINT (the
	 * terminal is raw, so Ctrl-C is a key here and the demo learns of it
	 * only from this status) */
	check_session("\003", 0, 130);
	/* also from the legend (it used to close the legend only) */
	check_session("?\003", 0, 130);
}

static void test_sigterm(void **state)
{
	(void)state;
	check_session(NULL, SIGTERM, 0);
}

/* ---- keys send commands, answers are shown ----------------------------------- */

/* Commands received by the test, in order. */
#define T_MAX_CMDS 16
static undulate_command_t got[T_MAX_CMDS];
static char got_channel[T_MAX_CMDS][32], got_robot[T_MAX_CMDS][32], got_param[T_MAX_CMDS][32];
static int ngot;

/* Anything that still publishes commands on LCM (nothing should). */
static int nlcm;
static void on_command(const lcm_recv_buf_t *rbuf, const char *channel, const undulate_command_t *m, void *user)
{
	(void)rbuf;
	(void)channel;
	(void)m;
	(void)user;
	nlcm++;
}

/* The fake robot "r1": its local command socket, where top's commands arrive. */
static int robot_fd = -1;
static char robot_path[CSOCK_PATH_MAX];
static struct csock_peer last_peer;

static void robot_open(void)
{
	char why[256];
	if (scratch_dir[0] == '\0')
		assert_int_equal(scratch_make("top-terminal"), 0);
	setenv("UNDULATE_RUN_DIR", scratch_dir, 1);   /* top (the child) looks there */
	assert_true(csock_path(robot_path, sizeof robot_path, scratch_dir, "r1", lcm_url));
	robot_fd = csock_listen(robot_path, why, sizeof why);
	if (robot_fd < 0)
		fail_msg("%s", why);
}

static void robot_close(void)
{
	csock_close(robot_fd, robot_path);
	robot_fd = -1;
}

/* The program under test, whose screen output is drained while the robot
 * waits: a program that draws ten times a second blocks in write() once the
 * terminal's buffer is full, and then reads no key. */
static struct child *draining;

static void drain(void)
{
	if (draining == NULL)
		return;
	for (;;) {
		ssize_t n = read(draining->master, draining->out + draining->len, T_OUT - 1 - draining->len);
		if (n <= 0)
			return;
		draining->len += (size_t)n;
		if (draining->len >= T_OUT - 1)
			draining->len = 0;
	}
}

/* Collects what arrives on the robot's socket within MS (or until want). */
static void robot_receive_ms(int want, long ms)
{
	struct timespec t0, t;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	while (ngot < want) {
		clock_gettime(CLOCK_MONOTONIC, &t);
		if ((t.tv_sec - t0.tv_sec) * 1000 + (t.tv_nsec - t0.tv_nsec) / 1000000 > ms)
			return;
		drain();
		struct pollfd p = { .fd = robot_fd, .events = POLLIN };
		if (poll(&p, 1, 20) <= 0)
			continue;
		uint8_t buf[2048];
		bool truncated = false;
		ssize_t n = csock_recv(robot_fd, buf, sizeof buf, &last_peer, &truncated);
		if (n <= 0 || ngot >= T_MAX_CMDS)
			continue;
		undulate_command_t m;
		assert_int_equal(undulate_command_t_decode(buf, 0, (int)n, &m), (int)n);
		got[ngot] = m;
		snprintf(got_channel[ngot], 32, "socket");
		snprintf(got_robot[ngot], 32, "%s", m.robot);
		snprintf(got_param[ngot], 32, "%s", m.param);
		got[ngot].source = got[ngot].robot = got[ngot].param = NULL;
		undulate_command_t_decode_cleanup(&m);
		ngot++;
	}
}

static void robot_receive(int want)
{
	robot_receive_ms(want, T_TIMEOUT_MS);
}

/* What robot "r1" publishes: a STATE in OSCILLATOR and its PARAMS. */
static void publish_robot(lcm_t *lcm)
{
	char name[] = "r1", reason[] = "test";
	undulate_joint_state_t j[2] = { { .servo_id = 1 }, { .servo_id = 2 } };
	undulate_robot_state_t s = { .robot = name, .mode = UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR,
		.mode_reason = reason, .fault = "", .period_us = 10000, .njoints = 2, .joints = j };
	undulate_robot_state_t_publish(lcm, "r1.STATE", &s);
	double k[2] = { 1, 1 }, c[2] = { 0.02, 0.04 }, z[2] = { 0, 0 };
	undulate_osc_params_t p = { .robot = name, .njoints = 2, .k = k, .c = c, .mu = k, .lambda = z,
		.inertia = z, .friction = z, .neutral = z, .limit_min = z, .limit_max = z, .amplitude = 0.8 };
	undulate_osc_params_t_publish(lcm, "r1.PARAMS", &p);
}

/* The robot's answer to command SEQ, on the socket back to the sender (and,
 * with LCM, also on its EVENT channel, as a daemon sends it). */
static void answer(lcm_t *lcm, int64_t seq, const char *kind_text, const char *what)
{
	char name[] = "r1", kind[40], text[120];
	snprintf(kind, sizeof kind, "%s", kind_text);
	snprintf(text, sizeof text, "%s", what);
	undulate_event_t e = { .robot = name, .seq = seq, .level = 0, .kind = kind, .text = text };
	uint8_t ev[512];
	int n = undulate_event_t_encode(ev, 0, sizeof ev, &e);
	assert_true(n > 0);
	if (lcm != NULL)
		undulate_event_t_publish(lcm, "r1.EVENT", &e);
	assert_true(csock_reply(robot_fd, &last_peer, ev, (size_t)n));
}

/* Presses KEYS, then collects the commands that arrive at the robot's socket. */
static int press(struct child *c, const char *keys, int want)
{
	int before = ngot;
	draining = c;
	assert_int_equal(write(c->master, keys, strlen(keys)), (ssize_t)strlen(keys));
	robot_receive(before + want);
	draining = NULL;
	return ngot - before;
}

/* Presses KEYS that must send nothing: then three `v` (the view goes round
 * to auto again), whose "view: auto" on the screen shows every key before
 * was read; a command those keys sent would have been sent by then. */
static int press_none(struct child *c, const char *keys)
{
	int before = ngot;
	char buf[64];
	snprintf(buf, sizeof buf, "%svvv", keys);
	c->len = 0;
	assert_int_equal(write(c->master, buf, strlen(buf)), (ssize_t)strlen(buf));
	assert_true(read_until(c, "view: auto"));
	draining = c;
	robot_receive_ms(before + 1, 100); /* what was sent is queued by now */
	draining = NULL;
	return ngot - before;
}

/* The two command tests' session: our LCM listener for commands (LCM_URL),
 * the robot's local socket (robot_open), undulate-top started with ARG (or
 * none) and read without blocking. session_close quits it with q and
 * undoes the rest. */
static struct child *session_open(const char *arg, lcm_t **lcm, undulate_command_t_subscription_t **sub)
{
	*lcm = lcm_create(lcm_url);
	assert_non_null(*lcm);
	*sub = undulate_command_t_subscribe(*lcm, ".*CMD", on_command, NULL);
	ngot = 0;
	nlcm = 0;
	robot_open();
	struct child *c = calloc(1, sizeof(*c));
	start(c, arg);
	fcntl(c->master, F_SETFL, O_NONBLOCK);
	return c;
}

/* The robot's state published until its row ("r1 ") is on the screen. */
static void wait_for_robot(struct child *c, lcm_t *lcm)
{
	int seen = 0;
	for (int i = 0; i < 100 && !seen; i++) {
		publish_robot(lcm);
		seen = read_until_ms(c, "r1 ", 50);
	}
	assert_true(seen);
}

static void session_close(struct child *c, lcm_t *lcm, undulate_command_t_subscription_t *sub)
{
	robot_close();
	assert_int_equal(write(c->master, "q", 1), 1);
	assert_int_equal(wait_exit(c), 0);
	close(c->master);
	free(c);
	undulate_command_t_unsubscribe(lcm, sub);
	lcm_destroy(lcm);
}

static void test_commands_and_answer(void **state)
{
	(void)state;
	lcm_t *lcm;
	undulate_command_t_subscription_t *sub;
	struct child *c = session_open(NULL, &lcm, &sub);
	assert_true(read_until(c, "undulate-top"));
	wait_for_robot(c, lcm);
	/* navigating as vi does (h j k l), and the old one-key mode letters,
	 * send nothing: a mode change takes two keys */
	assert_int_equal(press_none(c, "hjkllhsoLHSO"), 0);
	/* ?: the legend, then any key back */
	c->len = 0;
	assert_int_equal(write(c->master, "?", 1), 1);
	assert_true(read_until(c, "SILENT xN"));
	assert_int_equal(press_none(c, "x"), 0);
	/* m o: OSCILLATOR for the selected robot, to its local socket */
	c->len = 0;
	assert_int_equal(write(c->master, "m", 1), 1);
	assert_true(read_until(c, "mode for the selected robot"));
	assert_int_equal(press(c, "o", 1), 1);
	assert_string_equal(got_robot[0], "r1");
	assert_int_equal(got[0].kind, UNDULATE_COMMAND_T_KIND_MODE);
	assert_int_equal(got[0].mode, UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR);
	/* M l: LIMP for all robots: every robot's socket on this LCM network;
	 * the status line counts the answers */
	c->len = 0;
	assert_int_equal(press(c, "Ml", 1), 1);
	assert_string_equal(got_robot[1], "*");
	assert_int_equal(got[1].mode, UNDULATE_ROBOT_STATE_T_MODE_LIMP);
	assert_true(got[1].seq > got[0].seq);
	assert_true(read_until(c, "all robots mode LIMP: 0 of 1 accepted"));
	/* a robot answers twice, on its EVENT channel and on the socket: one
	 * robot, one answer */
	c->len = 0;
	answer(lcm, got[1].seq, "command-accepted", "mode LIMP");
	assert_true(read_until(c, "all robots mode LIMP: 1 of 1 accepted"));
	read_until_ms(c, "2 of 1", 500);
	assert_null(strstr(c->out, "2 of 1"));
	/* m then a key that names no mode: cancelled, nothing sent */
	assert_int_equal(press_none(c, "mx"), 0);
	/* +: c of each joint up 10 % */
	assert_int_equal(press(c, "+", 2), 2);
	assert_string_equal(got_param[2], "c");
	assert_int_equal(got[2].kind, UNDULATE_COMMAND_T_KIND_PARAM);
	assert_int_equal(got[3].joint, 1);
	assert_true(got[2].value > 0.02199 && got[2].value < 0.02201);
	assert_true(got[3].value > 0.04399 && got[3].value < 0.04401);
	/* the robot's answer, on the socket back to the sender, appears in the status line */
	c->len = 0;
	answer(NULL, got[3].seq, "command-rejected", "mode OSCILLATOR refused: torque off");
	assert_true(read_until(c, "command-rejected: mode OSCILLATOR refused"));
	assert_int_equal(nlcm, 0);   /* and nothing went out on LCM */
	session_close(c, lcm, sub);
}

/* --read-only: the same keys send nothing and say so. */
static void test_read_only_sends_nothing(void **state)
{
	(void)state;
	lcm_t *lcm;
	undulate_command_t_subscription_t *sub;
	struct child *c = session_open("--read-only", &lcm, &sub);
	wait_for_robot(c, lcm);
	c->len = 0;
	assert_int_equal(write(c->master, "moMl+", 5), 5);
	assert_true(read_until(c, "read-only: commands are disabled"));
	for (int i = 0; i < 10; i++)
		lcm_handle_timeout(lcm, 20);
	robot_receive(1);
	assert_int_equal(ngot, 0);
	assert_int_equal(nlcm, 0);
	session_close(c, lcm, sub);
}

/* After every test, passed or not: no program and no socket left behind. */
static int kill_live_child(void **state)
{
	(void)state;
	if (live_child > 0) {
		kill(live_child, SIGKILL);
		waitpid(live_child, NULL, 0);
	}
	live_child = -1;
	if (robot_fd >= 0)
		robot_close();
	return 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_teardown(test_quit_key, kill_live_child),
		cmocka_unit_test_teardown(test_ctrl_c, kill_live_child),
		cmocka_unit_test_teardown(test_sigterm, kill_live_child),
		cmocka_unit_test_teardown(test_commands_and_answer, kill_live_child),
		cmocka_unit_test_teardown(test_read_only_sends_nothing, kill_live_child),
	};
	int rc = cmocka_run_group_tests(tests, setup, NULL);
	if (scratch_dir[0] != '\0')
		scratch_remove();
	return rc;
}
