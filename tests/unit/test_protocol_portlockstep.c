/*
 * test_protocol_portlockstep.c — the bus through port_bus_io_lockstep with
 * the bytes in band (common/lockstep.h, LKS2), the simulator played by the
 * test on the other end of a socket pair: a PING's bytes (the AX-12 manual's,
 * not our encoder's) go with the WAIT the bus's wait sends, the status the
 * TIME carries is the reply the bus reads; no pty is touched (the port is
 * NULL); a reply that does not come is a time-out at the virtual deadline;
 * a write longer than a message carries is refused and counted; a write to
 * a port the simulator says is gone fails like one to a hung-up pty.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "bus.h"
#include "clock.h"
#include "lockstep.h"
#include "port.h"

struct rig {
	struct lks_client c;
	struct port_lockstep pl;
	struct bus_io io;
	struct bus bus;
	int sim;
};

static void rig_open(struct rig *r)
{
	int sv[2];
	assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
	memset(r, 0, sizeof *r);
	r->c.fd = sv[0];
	r->c.mono0_us = LKS_MONO0_US;
	r->c.wall0_us = LKS_WALL0_US;
	r->c.inband = true;
	r->sim = sv[1];
	port_bus_io_lockstep(&r->pl, NULL, &r->c, 0, &r->io);
	struct bus_timing tm = { .baud = 1000000, .return_delay_us = 500 };
	bus_init(&r->bus, &r->io, &tm, false);
}

static void rig_close(struct rig *r)
{
	close(r->c.fd);
	close(r->sim);
}

/* The simulator's answer, queued before the bus asks. */
static void sim_time(struct rig *r, uint64_t t_ns, uint32_t flags, const uint8_t *bytes, size_t n)
{
	struct lks_msg m = { .type = LKS_TIME, .a = t_ns, .flags = flags, .nbytes = (uint32_t)n };
	if (n)
		memcpy(m.bytes, bytes, n);
	assert_int_equal(lks_send(r->sim, &m), 0);
}

static struct lks_msg sim_wait(struct rig *r)
{
	struct lks_msg m;
	char why[200];
	assert_int_equal(lks_recv(r->sim, &m, why, sizeof why), 1);
	assert_int_equal(m.type, LKS_WAIT);
	return m;
}

/* AX-12 manual, PING: "FF FF 01 02 01 FB"; its status "FF FF 01 02 00 FC". */
static const uint8_t ping1[] = { 0xff, 0xff, 0x01, 0x02, 0x01, 0xfb };
static const uint8_t status1[] = { 0xff, 0xff, 0x01, 0x02, 0x00, 0xfc };

static void test_ping_in_band(void **state)
{
	(void)state;
	struct rig r;
	rig_open(&r);
	sim_time(&r, 200000, 0, status1, sizeof status1);
	uint8_t err = 0xff;
	assert_int_equal(bus_ping(&r.bus, 1, &err), DXL_OK);
	assert_int_equal(err, 0);
	struct lks_msg w = sim_wait(&r);
	assert_int_equal(w.flags, LKS_WANT_INPUT | LKS_PORT_OPENED);
	assert_int_equal(w.nbytes, sizeof ping1);
	assert_memory_equal(w.bytes, ping1, sizeof ping1);
	assert_int_equal(r.c.written, sizeof ping1);
	assert_int_equal(clock_mono_us(), LKS_MONO0_US + 200);
	rig_close(&r);
}

static void test_no_reply_is_a_timeout(void **state)
{
	(void)state;
	struct rig r;
	rig_open(&r);
	/* the wake-up came with no bytes: the bus's deadline has passed */
	sim_time(&r, 50000000, 0, NULL, 0);
	uint8_t err;
	assert_int_equal(bus_ping(&r.bus, 1, &err), DXL_E_TIMEOUT);
	struct lks_msg w = sim_wait(&r);
	assert_int_equal(w.nbytes, sizeof ping1);
	assert_true(w.a != LKS_NEVER && w.a < 50000000);   /* the bus said its deadline */
	rig_close(&r);
}

static void test_too_long_and_gone(void **state)
{
	(void)state;
	struct rig r;
	rig_open(&r);
	static uint8_t big[LKS_BYTES_MAX];
	assert_int_equal(r.io.write(r.io.ctx, big, 100), DXL_OK);
	assert_int_equal(r.io.write(r.io.ctx, big, LKS_BYTES_MAX - 99), DXL_E_BUFFER);   /* whole, not cut */
	assert_int_equal(r.c.bus[0].too_long, 1);
	assert_int_equal(r.c.bus[0].nout, 100);
	assert_int_equal(r.io.write(r.io.ctx, big, LKS_BYTES_MAX - 100), DXL_OK);   /* exactly full */
	assert_int_equal(r.c.bus[0].nout, LKS_BYTES_MAX);
	/* the simulator took the port away (disconnect fault): a write fails as
	 * on a hung-up pty, until the port is opened again; a read finds nothing,
	 * as the pty transport's does (it reads only what was announced) */
	sim_time(&r, 1000, LKS_BUS_GONE, NULL, 0);
	assert_int_equal(r.io.wait(r.io.ctx, 10000), 0);
	assert_int_equal(sim_wait(&r).nbytes, LKS_BYTES_MAX);
	assert_int_equal(r.io.write(r.io.ctx, ping1, sizeof ping1), DXL_E_DISCONNECTED);
	uint8_t buf[16];
	assert_int_equal(r.io.read(r.io.ctx, buf, sizeof buf), 0);
	port_bus_io_lockstep(&r.pl, NULL, &r.c, 0, &r.io);
	assert_int_equal(r.io.write(r.io.ctx, ping1, sizeof ping1), DXL_OK);
	assert_int_equal(r.io.read(r.io.ctx, buf, sizeof buf), 0);
	/* pending and flush see only what was delivered */
	sim_time(&r, 2000, 0, status1, sizeof status1);
	assert_int_equal(r.io.wait(r.io.ctx, 10000), 1);
	assert_int_equal(r.io.pending_input(r.io.ctx), (long)sizeof status1);
	r.io.flush_input(r.io.ctx);
	assert_int_equal(r.io.pending_input(r.io.ctx), 0);
	rig_close(&r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ping_in_band),
		cmocka_unit_test(test_no_reply_is_a_timeout),
		cmocka_unit_test(test_too_long_and_gone),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
