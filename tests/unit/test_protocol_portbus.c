/*
 * test_protocol_portbus.c — bus transactions through the real transport: a
 * pty whose other end is a scripted peer that answers with raw bytes written
 * literally from the AX-12 manual (not produced by our encoder).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "bus.h"
#include "port.h"
#include "ptypeer.h"

/* A correctness bound for a 1 Mbps READ that nobody answers: the derived
 * timeout is a few ms; the old SDKs' fixed 34 ms would fail this. */
#define MISSING_SERVO_BOUND_US 20000

struct fixture {
	struct ptypeer peer;
	struct port *port;
	struct bus bus;
};

static int setup(void **state)
{
	struct fixture *f = calloc(1, sizeof *f);
	struct port_options opt = { .baud = 1000000 };
	/* Return delay as the factory sets it (500 µs); a pty adds no adapter
	 * latency; 8 ms of slack so a loaded test machine may be late to
	 * schedule the peer thread (the timeout then still stays under
	 * MISSING_SERVO_BOUND_US). */
	struct bus_timing timing = { .baud = 1000000, .return_delay_us = 500,
	                             .adapter_latency_us = 0, .margin_us = 8000 };
	struct bus_io io;
	char err[200] = "";

	assert_non_null(f);
	assert_int_equal(ptypeer_open(&f->peer), 0);
	f->port = port_open(f->peer.slave_path, &opt, err, sizeof err);
	if (f->port == NULL)
		fail_msg("port_open: %s", err);
	port_bus_io(f->port, &io);
	bus_init(&f->bus, &io, &timing, false);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fixture *f = *state;

	ptypeer_close(&f->peer);
	port_close(f->port);
	free(f);
	return 0;
}

static void expect_script_ok(struct fixture *f)
{
	if (!ptypeer_join(&f->peer))
		fail_msg("peer script: %s", f->peer.why);
}

/* Golden: PING id 1 → FF FF 01 02 01 FB, answered FF FF 01 02 00 FC. */
static const uint8_t ping1[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
static const uint8_t ping1_ok[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
/* Golden: READ id 1 addr 43 (temperature) len 1 → 32 °C. */
static const uint8_t read_temp[] = { 0xFF, 0xFF, 0x01, 0x04, 0x02, 0x2B, 0x01, 0xCC };
static const uint8_t read_temp_ok[] = { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB };

static void test_ping_and_read_golden(void **state)
{
	struct fixture *f = *state;
	const struct ptypeer_step steps[] = {
		{ .expect = ping1, .expect_len = sizeof ping1, .reply = ping1_ok, .reply_len = sizeof ping1_ok },
		{ .expect = read_temp, .expect_len = sizeof read_temp,
		  .reply = read_temp_ok, .reply_len = sizeof read_temp_ok },
	};
	uint8_t errbits = 0xFF, temp = 0;

	assert_int_equal(ptypeer_start(&f->peer, steps, 2), 0);
	assert_int_equal(bus_ping(&f->bus, 1, &errbits), DXL_OK);
	assert_int_equal(errbits, 0);
	assert_int_equal(bus_read_u8(&f->bus, 1, 43, &temp, &errbits), DXL_OK);
	assert_int_equal(temp, 32);
	assert_int_equal(errbits, 0);
	expect_script_ok(f);
	assert_int_equal(f->bus.servo[1].replies, 2);
	print_message("# round trip over the pty: %u us\n", (unsigned)f->bus.servo[1].rtt_last_us);
}

/* Golden: status with overload + overheating: the reply is good, the bits are data. */
static void test_error_bits_surface(void **state)
{
	struct fixture *f = *state;
	const uint8_t bad_status[] = { 0xFF, 0xFF, 0x01, 0x02, 0x24, 0xD8 };
	const struct ptypeer_step steps[] = {
		{ .expect = ping1, .expect_len = sizeof ping1, .reply = bad_status, .reply_len = sizeof bad_status },
	};
	uint8_t errbits = 0;

	assert_int_equal(ptypeer_start(&f->peer, steps, 1), 0);
	assert_int_equal(bus_ping(&f->bus, 1, &errbits), DXL_OK);
	assert_int_equal(errbits, 0x24);
	expect_script_ok(f);
	assert_int_equal(f->bus.servo[1].error_replies, 1);
	assert_int_equal(f->bus.servo[1].errbits_seen, 0x24);
}

/* Nobody answers a READ(36, 6) to ID 3: the call costs about the derived
 * timeout, not a fixed tens of milliseconds. */
static void test_missing_servo_costs_its_timeout(void **state)
{
	struct fixture *f = *state;
	/* FF FF 03 04 02 24 06 CHK, CHK = ~(03+04+02+24+06) = ~0x33 = 0xCC */
	const uint8_t read36[] = { 0xFF, 0xFF, 0x03, 0x04, 0x02, 0x24, 0x06, 0xCC };
	const struct ptypeer_step steps[] = { { .expect = read36, .expect_len = sizeof read36 } };
	uint8_t out[6], errbits;

	assert_int_equal(ptypeer_start(&f->peer, steps, 1), 0);
	uint32_t derived = bus_timeout_us(&f->bus, 8, 12);
	uint64_t t0 = port_now_us();
	int r = bus_read(&f->bus, 3, 36, 6, out, &errbits);
	uint64_t took = port_now_us() - t0;
	assert_int_equal(r, DXL_E_TIMEOUT);
	expect_script_ok(f); /* the request went out byte-exact */
	print_message("# missing servo: derived timeout %u us, took %llu us\n", (unsigned)derived,
	              (unsigned long long)took);
	assert_true(took >= derived);
	assert_true(took < MISSING_SERVO_BOUND_US);
	assert_int_equal(f->bus.servo[3].timeouts, 1);
}

static void test_wrong_id_reply(void **state)
{
	struct fixture *f = *state;
	/* ID 2 answers a request to ID 1: FF FF 02 03 00 20 CHK, CHK = ~0x25 = 0xDA */
	const uint8_t from2[] = { 0xFF, 0xFF, 0x02, 0x03, 0x00, 0x20, 0xDA };
	const struct ptypeer_step steps[] = {
		{ .expect = read_temp, .expect_len = sizeof read_temp, .reply = from2, .reply_len = sizeof from2 },
	};
	uint8_t temp = 0, errbits;

	assert_int_equal(ptypeer_start(&f->peer, steps, 1), 0);
	assert_int_equal(bus_read_u8(&f->bus, 1, 43, &temp, &errbits), DXL_E_WRONG_ID);
	expect_script_ok(f);
	assert_int_equal(f->bus.servo[1].wrong_id, 1);
}

static void test_corrupted_reply(void **state)
{
	struct fixture *f = *state;
	/* the golden temperature reply with its checksum off by one */
	const uint8_t corrupt[] = { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDC };
	const struct ptypeer_step steps[] = {
		{ .expect = read_temp, .expect_len = sizeof read_temp, .reply = corrupt, .reply_len = sizeof corrupt },
		{ .expect = read_temp, .expect_len = sizeof read_temp,
		  .reply = read_temp_ok, .reply_len = sizeof read_temp_ok },
	};
	uint8_t temp = 0, errbits;

	assert_int_equal(ptypeer_start(&f->peer, steps, 2), 0);
	assert_int_equal(bus_read_u8(&f->bus, 1, 43, &temp, &errbits), DXL_E_CHECKSUM);
	assert_int_equal(f->bus.servo[1].checksum_errors, 1);
	/* the next transaction is not poisoned by the bad one */
	assert_int_equal(bus_read_u8(&f->bus, 1, 43, &temp, &errbits), DXL_OK);
	assert_int_equal(temp, 32);
	expect_script_ok(f);
}

/* Line noise before the reply: the parser resyncs and the reply still counts. */
static void test_garbage_before_reply(void **state)
{
	struct fixture *f = *state;
	const uint8_t noisy[] = { 0x00, 0xFF, 0x13, 0x0A, 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB };
	const struct ptypeer_step steps[] = {
		{ .expect = read_temp, .expect_len = sizeof read_temp, .reply = noisy, .reply_len = sizeof noisy },
	};
	uint8_t temp = 0, errbits;

	assert_int_equal(ptypeer_start(&f->peer, steps, 1), 0);
	assert_int_equal(bus_read_u8(&f->bus, 1, 43, &temp, &errbits), DXL_OK);
	assert_int_equal(temp, 32);
	expect_script_ok(f);
}

/* The peer (the simulator, an adapter) goes away mid-request. */
static void test_peer_hangup_is_disconnected(void **state)
{
	struct fixture *f = *state;
	const struct ptypeer_step steps[] = {
		{ .expect = read_temp, .expect_len = sizeof read_temp, .hang_up = true },
	};
	uint8_t temp, errbits;

	assert_int_equal(ptypeer_start(&f->peer, steps, 1), 0);
	uint64_t t0 = port_now_us();
	assert_int_equal(bus_read_u8(&f->bus, 1, 43, &temp, &errbits), DXL_E_DISCONNECTED);
	assert_true(port_now_us() - t0 < MISSING_SERVO_BOUND_US);
	expect_script_ok(f);
	/* and it stays gone */
	assert_int_equal(bus_ping(&f->bus, 1, &errbits), DXL_E_DISCONNECTED);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(test_ping_and_read_golden, setup, teardown),
		cmocka_unit_test_setup_teardown(test_error_bits_surface, setup, teardown),
		cmocka_unit_test_setup_teardown(test_missing_servo_costs_its_timeout, setup, teardown),
		cmocka_unit_test_setup_teardown(test_wrong_id_reply, setup, teardown),
		cmocka_unit_test_setup_teardown(test_corrupted_reply, setup, teardown),
		cmocka_unit_test_setup_teardown(test_garbage_before_reply, setup, teardown),
		cmocka_unit_test_setup_teardown(test_peer_hangup_is_disconnected, setup, teardown),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
