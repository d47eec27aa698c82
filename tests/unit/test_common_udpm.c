/* test_common_udpm.c — LCM's URL checked as a configuration must be: good
 * udpm URLs with their group, port and ttl; non-multicast groups, ports 0
 * and 65536, unknown options and ttl out of range refused; the other
 * providers; the network's file-name-safe name; the effective URL with and
 * without $LCM_DEFAULT_URL. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "udpm.h"

static char saved_default[512];
static bool had_default;

static int group_setup(void **state)
{
	(void)state;
	const char *d = getenv("LCM_DEFAULT_URL");
	had_default = d != NULL;
	snprintf(saved_default, sizeof saved_default, "%s", d ? d : "");
	return unsetenv("LCM_DEFAULT_URL");
}

static int group_teardown(void **state)
{
	(void)state;
	return had_default ? setenv("LCM_DEFAULT_URL", saved_default, 1) : unsetenv("LCM_DEFAULT_URL");
}

static void expect_udpm(const char *url, const char *group, unsigned port, int ttl)
{
	struct udpm_url u;
	char why[200] = "";
	if (!udpm_parse_url(url, &u, why, sizeof why))
		fail_msg("'%s' refused: %s", url, why);
	assert_string_equal(u.provider, "udpm");
	char addr[INET_ADDRSTRLEN];
	assert_non_null(inet_ntop(AF_INET, &u.group, addr, sizeof addr));
	assert_string_equal(addr, group);
	assert_int_equal(u.port, port);
	assert_int_equal(u.ttl, ttl);
}

static void expect_refused(const char *url, const char *needle)
{
	struct udpm_url u;
	char why[200] = "";
	if (udpm_parse_url(url, &u, why, sizeof why))
		fail_msg("'%s' accepted (expected '%s')", url, needle);
	if (strstr(why, needle) == NULL)
		fail_msg("'%s': why '%s' does not contain '%s'", url, why, needle);
}

static void test_good_urls(void **state)
{
	(void)state;
	expect_udpm("udpm://239.255.76.67:7667?ttl=0", "239.255.76.67", 7667, 0);
	expect_udpm("udpm://239.255.76.67:7667", "239.255.76.67", 7667, -1);
	expect_udpm("udpm://239.255.76.67", "239.255.76.67", 7667, -1);
	expect_udpm("udpm://239.255.76.67?ttl=1", "239.255.76.67", 7667, 1);
	expect_udpm("udpm://224.0.0.1:1", "224.0.0.1", 1, -1);
	expect_udpm("udpm://239.255.255.255:65535?ttl=255", "239.255.255.255", 65535, 255);
	expect_udpm("udpm://239.1.2.3:7700?ttl=2&recv_buf_size=2097152", "239.1.2.3", 7700, 2);
	expect_udpm("udpm://239.1.2.3:7700?recv_buf_size=1&ttl=3", "239.1.2.3", 7700, 3);
	/* recv_buf_size is kept (the recorder asks the kernel for it); 0 when absent */
	struct udpm_url u;
	char why[200] = "";
	assert_true(udpm_parse_url("udpm://239.1.2.3:7700?ttl=2&recv_buf_size=2097152", &u, why, sizeof why));
	assert_int_equal(u.recv_buf_size, 2097152);
	assert_true(udpm_parse_url("udpm://239.1.2.3:7700?ttl=2", &u, why, sizeof why));
	assert_int_equal(u.recv_buf_size, 0);
	/* NULL and "": LCM's default ($LCM_DEFAULT_URL unset here) */
	expect_udpm(NULL, "239.255.76.67", 7667, 0);
	expect_udpm("", "239.255.76.67", 7667, 0);
}

static void test_bad_udpm(void **state)
{
	(void)state;
	/* not a multicast group (224.0.0.0/4) */
	expect_refused("udpm://10.0.0.1:7667", "multicast");
	expect_refused("udpm://127.0.0.1:7667", "multicast");
	expect_refused("udpm://223.255.255.255:7667", "multicast");
	expect_refused("udpm://240.0.0.1:7667", "multicast");
	expect_refused("udpm://255.255.255.255:7667", "multicast");
	expect_refused("udpm://0.0.0.0:7667", "multicast");
	expect_refused("udpm://localhost:7667", "multicast");
	expect_refused("udpm://239.255.76:7667", "multicast");
	expect_refused("udpm://239.255.76.67.1:7667", "multicast");
	expect_refused("udpm://[ff02::1]:7667", "multicast");
	expect_refused("udpm://:7667", "no multicast group");
	expect_refused("udpm://", "no multicast group");
	expect_refused("udpm://?ttl=0", "no multicast group");
	/* ports */
	expect_refused("udpm://239.255.76.67:0", "1..65535");
	expect_refused("udpm://239.255.76.67:65536", "1..65535");
	expect_refused("udpm://239.255.76.67:99999999999", "1..65535");
	expect_refused("udpm://239.255.76.67:-1", "1..65535");
	expect_refused("udpm://239.255.76.67:", "1..65535");
	expect_refused("udpm://239.255.76.67:7667x", "1..65535");
	expect_refused("udpm://239.255.76.67: 7667", "1..65535");
	expect_refused("udpm://239.255.76.67:7667/path", "1..65535");
	expect_refused("udpm://239.255.76.67:?ttl=0", "1..65535");
	/* options: only LCM 1.3.1's, with their ranges */
	expect_refused("udpm://239.255.76.67:7667?foo=1", "unknown option 'foo'");
	expect_refused("udpm://239.255.76.67:7667?ttl=0&bar=2", "unknown option 'bar'");
	expect_refused("udpm://239.255.76.67:7667?TTL=1", "unknown option 'TTL'");
	expect_refused("udpm://239.255.76.67:7667?ttlx=1", "unknown option");
	expect_refused("udpm://239.255.76.67:7667?tt=1", "unknown option");
	expect_refused("udpm://239.255.76.67:7667?ttl", "no value");
	expect_refused("udpm://239.255.76.67:7667?ttl=256", "ttl must be 0..255");
	expect_refused("udpm://239.255.76.67:7667?ttl=-1", "ttl must be 0..255");
	expect_refused("udpm://239.255.76.67:7667?ttl=", "ttl must be 0..255");
	expect_refused("udpm://239.255.76.67:7667?ttl=1.5", "ttl must be 0..255");
	expect_refused("udpm://239.255.76.67:7667?ttl=0x1", "ttl must be 0..255");
	expect_refused("udpm://239.255.76.67:7667?recv_buf_size=0", "recv_buf_size");
	expect_refused("udpm://239.255.76.67:7667?recv_buf_size=big", "recv_buf_size");
}

static void test_providers(void **state)
{
	(void)state;
	const char *others[][2] = {
		{ "file:///tmp/robot.log", "file" },
		{ "memq://", "memq" },
		{ "tcpq://127.0.0.1:7700", "tcpq" },
	};
	for (size_t i = 0; i < sizeof others / sizeof others[0]; i++) {
		struct udpm_url u;
		char why[200];
		if (!udpm_parse_url(others[i][0], &u, why, sizeof why))
			fail_msg("'%s' refused: %s", others[i][0], why);
		assert_string_equal(u.provider, others[i][1]);
		assert_int_equal(u.ttl, -1);
	}
	expect_refused("http://239.255.76.67:7667", "not an LCM URL");
	expect_refused("udp://239.255.76.67:7667", "not an LCM URL");
	expect_refused("udpmx://239.255.76.67:7667", "not an LCM URL");
	expect_refused("UDPM://239.255.76.67:7667", "not an LCM URL");
	expect_refused("udpm:/239.255.76.67:7667", "not an LCM URL");
	expect_refused("239.255.76.67:7667", "not an LCM URL");
	expect_refused("://239.255.76.67", "not an LCM URL");
	expect_refused("udpm", "not an LCM URL");
	/* a network socket needs udpm, whatever the provider */
	char why[200] = "";
	assert_int_equal(udpm_open_recv("memq://", why, sizeof why), -1);
	assert_non_null(strstr(why, "udpm://"));
	why[0] = '\0';
	assert_int_equal(udpm_open_recv("udpm://10.1.2.3:7667", why, sizeof why), -1);
	assert_non_null(strstr(why, "multicast"));
}

static void test_net_name(void **state)
{
	(void)state;
	char out[96];
	static const struct { const char *url, *want; } names[] = {
		{ "udpm://239.255.76.67:7667?ttl=0", "239.255.76.67-7667" },
		/* the same network, however it is written */
		{ "udpm://239.255.76.67?ttl=1&recv_buf_size=4096", "239.255.76.67-7667" },
		{ "udpm://239.255.76.67:07667", "239.255.76.67-7667" },
		{ "udpm://224.0.0.1:1", "224.0.0.1-1" },
		{ NULL, "239.255.76.67-7667" },
		/* others: the URL, every character but [A-Za-z0-9.-] made '_' */
		{ "memq://", "memq___" },
		{ "file:///tmp/a b.log", "file____tmp_a_b.log" },
		{ "udpm://10.0.0.1:7667?ttl=0", "udpm___10.0.0.1_7667_ttl_0" },
	};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
		udpm_net_name(names[i].url, out, sizeof out);
		if (strcmp(out, names[i].want) != 0)
			fail_msg("%s: got \"%s\", want \"%s\"", names[i].url ? names[i].url : "(null)", out, names[i].want);
	}
	/* no '/' or '@' ever, so it is one path component after the robot's '@' */
	udpm_net_name("tcpq://user@host:1/x/../y", out, sizeof out);
	assert_null(strchr(out, '/'));
	assert_null(strchr(out, '@'));
	/* cut to cap, terminated, nothing past it */
	char small[8];
	memset(small, 'Z', sizeof small);
	udpm_net_name("memq://abcdefgh", small, 5);
	assert_string_equal(small, "memq");
	assert_int_equal(small[5], 'Z');
	memset(small, 'Z', sizeof small);
	udpm_net_name("udpm://239.255.76.67:7667", small, 6);
	assert_string_equal(small, "239.2");
	assert_int_equal(small[6], 'Z');
	memset(small, 'Z', sizeof small);
	udpm_net_name("memq://", small, 0);
	assert_int_equal(small[0], 'Z');
}

static void test_effective_url(void **state)
{
	(void)state;
	const char *mine = "udpm://239.1.1.1:7000";
	assert_ptr_equal(udpm_effective_url(mine), mine);
	assert_string_equal(udpm_effective_url(NULL), UDPM_DEFAULT_URL);
	assert_string_equal(udpm_effective_url(""), UDPM_DEFAULT_URL);
	assert_string_equal(UDPM_DEFAULT_URL, "udpm://239.255.76.67:7667?ttl=0");   /* LCM's own default */
	assert_int_equal(setenv("LCM_DEFAULT_URL", "udpm://239.9.9.9:7777?ttl=0", 1), 0);
	assert_string_equal(udpm_effective_url(NULL), "udpm://239.9.9.9:7777?ttl=0");
	assert_string_equal(udpm_effective_url(""), "udpm://239.9.9.9:7777?ttl=0");
	assert_ptr_equal(udpm_effective_url(mine), mine);   /* a URL given wins */
	/* everything that takes NULL follows it */
	char out[96];
	udpm_net_name(NULL, out, sizeof out);
	assert_string_equal(out, "239.9.9.9-7777");
	struct udpm_url u;
	char why[200];
	assert_true(udpm_parse_url("", &u, why, sizeof why));
	assert_int_equal(u.port, 7777);
	/* set but empty: as if unset */
	assert_int_equal(setenv("LCM_DEFAULT_URL", "", 1), 0);
	assert_string_equal(udpm_effective_url(NULL), UDPM_DEFAULT_URL);
	assert_int_equal(unsetenv("LCM_DEFAULT_URL"), 0);
	assert_string_equal(udpm_effective_url(NULL), UDPM_DEFAULT_URL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_good_urls),
		cmocka_unit_test(test_bad_udpm),
		cmocka_unit_test(test_providers),
		cmocka_unit_test(test_net_name),
		cmocka_unit_test(test_effective_url),
	};
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
