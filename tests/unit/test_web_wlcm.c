/*
 * test_web_wlcm.c — undulate-web's own reader of the LCM group (wlcm.h): the
 * subscriptions match channels whole, as LCM does ("x.STATE" is not
 * "x.STATEX"); a small message on a subscribed channel reaches its handler
 * with its payload, others do not; what is not LCM, a fragment and a
 * truncated datagram are counted and dropped; and on a real udpm group
 * (ttl 0) a burst sent by LCM itself is read whole by wlcm_drain; another
 * provider than udpm is declined.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <lcm/lcm.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tools/top/feed.h"
#include "tools/web/fox.h"
#include "tools/web/wlcm.h"
#include "wire.h"

static int heard_a, heard_b;
static char last_channel[64];
static uint8_t last_payload[64];
static size_t last_n;

static void on_a(const char *channel, const uint8_t *data, size_t n)
{
	heard_a++;
	snprintf(last_channel, sizeof last_channel, "%s", channel);
	last_n = n < sizeof last_payload ? n : sizeof last_payload;
	memcpy(last_payload, data, last_n);
}

static void on_b(const char *channel, const uint8_t *data, size_t n)
{
	(void)channel;
	(void)data;
	(void)n;
	heard_b++;
}

static void test_match_whole(void **state)
{
	(void)state;
	struct wlcm w;
	memset(&w, 0, sizeof w);
	w.fd = -1;
	for (size_t i = 0; i < top_feed_nchannels; i++)
		assert_true(wlcm_subscribe(&w, top_feed_channels[i], on_a));
	for (size_t i = 0; i < fox_extra_nchannels; i++)
		assert_true(wlcm_subscribe(&w, fox_extra_channels[i], on_b));
	assert_ptr_equal(wlcm_match(&w, "left.STATE"), on_a);
	assert_ptr_equal(wlcm_match(&w, "r10.EVENT"), on_a);
	assert_ptr_equal(wlcm_match(&w, "SIM.TRUTH"), on_a);
	assert_ptr_equal(wlcm_match(&w, "SIM.WORLD"), on_b);
	assert_null(wlcm_match(&w, "left.STATEX"));
	assert_null(wlcm_match(&w, "xSIM.TRUTH"));
	assert_null(wlcm_match(&w, "SIMxTRUTH"));
	assert_null(wlcm_match(&w, "left.CMD"));
	assert_null(wlcm_match(&w, ""));
	assert_false(wlcm_subscribe(&w, "a(", on_a));   /* does not compile */
	wlcm_close(&w);
}

static void test_datagrams(void **state)
{
	(void)state;
	struct wlcm w;
	memset(&w, 0, sizeof w);
	w.fd = -1;
	assert_true(wlcm_subscribe(&w, ".*\\.STATE", on_a));
	heard_a = 0;
	uint8_t d[256];
	const uint8_t payload[] = { 1, 2, 3, 4, 5 };
	size_t n = wire_udpm_build(d, sizeof d, 7, "left.STATE", payload, sizeof payload);
	assert_true(n > 0);
	wlcm_datagram(&w, d, n, false);
	assert_int_equal(heard_a, 1);
	assert_string_equal(last_channel, "left.STATE");
	assert_int_equal(last_n, sizeof payload);
	assert_memory_equal(last_payload, payload, sizeof payload);
	n = wire_udpm_build(d, sizeof d, 8, "left.EVENT", payload, sizeof payload);
	wlcm_datagram(&w, d, n, false);             /* not subscribed: not handed on, not an error */
	assert_int_equal(heard_a, 1);
	d[3] = '3';                                 /* "LC03": a fragment */
	wlcm_datagram(&w, d, n, false);
	wlcm_datagram(&w, (const uint8_t *)"hello", 5, false);
	wlcm_datagram(&w, d, 3, false);
	n = wire_udpm_build(d, sizeof d, 9, "left.STATE", payload, sizeof payload);
	wlcm_datagram(&w, d, n, true);              /* cut by the buffer */
	assert_int_equal(heard_a, 1);
	assert_int_equal(w.n.datagrams, 6);
	assert_int_equal(w.n.messages, 1);
	assert_int_equal(w.n.not_lcm, 3);
	assert_int_equal(w.n.truncated, 1);
	wlcm_close(&w);
}

static void test_group(void **state)
{
	(void)state;
	char url[64], why[200];
	/* a port of its own (7980-7989: no integration script names one; the unit
	 * tests run one at a time, before them), moved
	 * as the runner moves every test's (TEST_PORT_OFFSET) */
	const char *off = getenv("TEST_PORT_OFFSET");
	snprintf(url, sizeof url, "udpm://239.255.76.67:%d?ttl=0", 7980 + (int)(getpid() % 10) + (off ? atoi(off) : 0));
	struct wlcm w;
	assert_false(wlcm_open(&w, "memq://", why, sizeof why));
	assert_non_null(strstr(why, "memq"));
	assert_true(wlcm_open(&w, url, why, sizeof why));
	assert_true(wlcm_subscribe(&w, ".*\\.STATE", on_a));
	assert_true(wlcm_subscribe(&w, "SIM\\.WORLD", on_b));
	lcm_t *lcm = lcm_create(url);
	assert_non_null(lcm);
	heard_a = heard_b = 0;
	/* a burst larger than one recvmmsg, as 20 robots' STATE of a cycle */
	uint8_t big[20000];
	memset(big, 0x5a, sizeof big);
	for (int i = 0; i < 40; i++) {
		char ch[32];
		snprintf(ch, sizeof ch, "r%d.STATE", i);
		uint8_t p[3] = { (uint8_t)i, 0, 1 };
		assert_int_equal(lcm_publish(lcm, ch, p, sizeof p), 0);
	}
	assert_int_equal(lcm_publish(lcm, "SIM.WORLD", big, sizeof big), 0);
	assert_int_equal(lcm_publish(lcm, "r1.CMD", big, 10), 0);
	for (int tries = 0; tries < 200 && heard_a + heard_b < 41; tries++) {
		struct pollfd p = { .fd = w.fd, .events = POLLIN };
		if (poll(&p, 1, 20) > 0)
			wlcm_drain(&w, 4);
	}
	assert_int_equal(heard_a, 40);
	assert_int_equal(heard_b, 1);
	assert_int_equal(w.n.messages, 41);
	assert_int_equal(w.n.not_lcm, 0);
	lcm_destroy(lcm);
	wlcm_close(&w);
	assert_int_equal(w.fd, -1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_match_whole),
		cmocka_unit_test(test_datagrams),
		cmocka_unit_test(test_group),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
