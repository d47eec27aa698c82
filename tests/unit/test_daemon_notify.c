/* test_daemon_notify.c — the sd_notify protocol without libsystemd: socket
 * addresses (path and abstract '@'), WATCHDOG_USEC/WATCHDOG_PID, the STATUS
 * line, and real datagrams to a bound socket; the rate limiter of the log. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../daemon/log.h"
#include "../../daemon/notify.h"

static void test_addr(void **state)
{
	(void)state;
	struct sockaddr_un a;
	socklen_t len;
	assert_true(notify_make_addr("/run/systemd/notify", &a, &len));
	assert_string_equal(a.sun_path, "/run/systemd/notify");
	assert_int_equal(len, offsetof(struct sockaddr_un, sun_path) + strlen("/run/systemd/notify"));
	assert_true(notify_make_addr("@/org/freedesktop/systemd1/notify/1", &a, &len));
	assert_int_equal(a.sun_path[0], '\0');
	assert_memory_equal(a.sun_path + 1, "/org/freedesktop/systemd1/notify/1", 34);
	assert_int_equal(len, offsetof(struct sockaddr_un, sun_path) + 35);
	assert_false(notify_make_addr(NULL, &a, &len));
	assert_false(notify_make_addr("", &a, &len));
	assert_false(notify_make_addr("relative/path", &a, &len));
	assert_false(notify_make_addr("@", &a, &len));
	char longp[200];
	memset(longp, 'x', sizeof longp - 1);
	longp[0] = '/';
	longp[sizeof longp - 1] = '\0';
	assert_false(notify_make_addr(longp, &a, &len));
}

static void test_watchdog(void **state)
{
	(void)state;
	assert_int_equal(notify_parse_watchdog("20000000", NULL, 42), 20000000);
	assert_int_equal(notify_parse_watchdog("20000000", "42", 42), 20000000);
	assert_int_equal(notify_parse_watchdog("20000000", "43", 42), 0);   /* another process's */
	assert_int_equal(notify_parse_watchdog("0", NULL, 42), 0);
	assert_int_equal(notify_parse_watchdog("abc", NULL, 42), 0);
	assert_int_equal(notify_parse_watchdog("12x", NULL, 42), 0);
	assert_int_equal(notify_parse_watchdog(NULL, NULL, 42), 0);
	struct notify n = { .fd = -1, .watchdog_usec = 3000000 };
	assert_int_equal(notify_watchdog_interval_us(&n), 1500000);
	assert_false(notify_enabled(&n));
	assert_true(notify_send(&n, "READY=1"));   /* disabled: a no-op that succeeds */
}

static void test_status(void **state)
{
	(void)state;
	char buf[256];
	struct notify_status s = { .mode = "OSCILLATOR", .rate_hz = 99.96, .njoints = 2, .bus_connected = true,
	                           .overruns = 3, .bus_errors = 12, .faults = 1, .bad_commands = 4 };
	notify_format_status(buf, sizeof buf, &s);
	assert_string_equal(buf, "STATUS=OSCILLATOR 100.0 Hz, 2 joints, bus ok, 3 overruns, 12 bus errors, "
	                         "1 faults, 4 bad commands");
	s.bus_connected = false;
	s.mode = "HOLD";
	notify_format_status(buf, sizeof buf, &s);
	assert_non_null(strstr(buf, "STATUS=HOLD "));
	assert_non_null(strstr(buf, "bus lost"));
	/* truncation never overruns */
	char small[16];
	notify_format_status(small, sizeof small, &s);
	assert_int_equal(strlen(small), sizeof small - 1);
}

static void test_send_real(void **state)
{
	(void)state;
	char path[64];
	snprintf(path, sizeof path, "/tmp/undulate-notify-%d", (int)getpid());
	unlink(path);
	int rx = socket(AF_UNIX, SOCK_DGRAM, 0);
	struct sockaddr_un a;
	socklen_t len;
	assert_true(notify_make_addr(path, &a, &len));
	assert_int_equal(bind(rx, (struct sockaddr *)&a, len), 0);
	setenv("NOTIFY_SOCKET", path, 1);
	setenv("WATCHDOG_USEC", "500000", 1);
	unsetenv("WATCHDOG_PID");
	struct notify n;
	notify_init(&n);
	assert_true(notify_enabled(&n));
	assert_int_equal(n.watchdog_usec, 500000);
	assert_true(notify_send(&n, "READY=1"));
	assert_true(notify_send(&n, "WATCHDOG=1"));
	char buf[64];
	ssize_t r = recv(rx, buf, sizeof buf - 1, 0);
	assert_int_equal(r, 7);
	buf[r] = '\0';
	assert_string_equal(buf, "READY=1");
	r = recv(rx, buf, sizeof buf - 1, 0);
	buf[r] = '\0';
	assert_string_equal(buf, "WATCHDOG=1");
	notify_close(&n);
	close(rx);
	unlink(path);
	/* abstract socket */
	char name[64];
	snprintf(name, sizeof name, "@undulate-test-%d", (int)getpid());
	rx = socket(AF_UNIX, SOCK_DGRAM, 0);
	assert_true(notify_make_addr(name, &a, &len));
	assert_int_equal(bind(rx, (struct sockaddr *)&a, len), 0);
	setenv("NOTIFY_SOCKET", name, 1);
	notify_init(&n);
	assert_true(notify_send(&n, "STOPPING=1"));
	r = recv(rx, buf, sizeof buf - 1, 0);
	buf[r] = '\0';
	assert_string_equal(buf, "STOPPING=1");
	notify_close(&n);
	close(rx);
	unsetenv("NOTIFY_SOCKET");
	notify_init(&n);
	assert_false(notify_enabled(&n));
}

static void test_log_limit(void **state)
{
	(void)state;
	struct log_limit lim = LOG_LIMIT_INIT(3, 1000000);
	uint32_t dropped;
	uint64_t t = 5000000;
	/* a burst of 3, then silence (counted) until a token is earned */
	assert_true(log_limit_allow(&lim, t, &dropped));
	assert_true(log_limit_allow(&lim, t, &dropped));
	assert_true(log_limit_allow(&lim, t, &dropped));
	for (int i = 0; i < 100; i++)
		assert_false(log_limit_allow(&lim, t + 1000 * (uint64_t)i, &dropped));
	assert_false(log_limit_allow(&lim, t + 999999, &dropped));
	assert_true(log_limit_allow(&lim, t + 1000000, &dropped));
	assert_int_equal(dropped, 101);    /* the message that passes says how many were dropped */
	assert_false(log_limit_allow(&lim, t + 1000001, &dropped));
	/* after a long quiet time the burst is back, no more */
	assert_true(log_limit_allow(&lim, t + 60000000, &dropped));
	assert_int_equal(dropped, 1);
	assert_true(log_limit_allow(&lim, t + 60000000, &dropped));
	assert_true(log_limit_allow(&lim, t + 60000000, &dropped));
	assert_false(log_limit_allow(&lim, t + 60000000, &dropped));
	enum log_level lv;
	assert_true(log_level_parse("WARN", &lv));
	assert_int_equal(lv, LOG_LVL_WARN);
	assert_false(log_level_parse("loud", &lv));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_addr),
		cmocka_unit_test(test_watchdog),
		cmocka_unit_test(test_status),
		cmocka_unit_test(test_send_real),
		cmocka_unit_test(test_log_limit),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
