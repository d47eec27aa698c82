/*
 * test_dxl_fakeservo2.c — a fake bus of X-series servos (Protocol 2.0) on a
 * pty, and the `dxl --protocol 2` commands against it, in-process
 * (dxlt_main), as test_dxl_fakeservo.c does for the AX-12.
 *
 * The fake (xfake.h, shared with test_daemon_cycle.c) frames packets with
 * its own few lines — CRC, stuffing — not protocol/dxl2.c, and is checked
 * against the e-manual's packets first, so a bug shared by our encoder and
 * parser cannot pass through it unseen. Its control table is dxl2_table's
 * defaults; what a real servo refuses it refuses too. It hears only at its
 * own baud rate, read from the pty as the client set it.
 */
#include <asm/termbits.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>
#include <cmocka.h>

#include "dxl2.h"
#include "dxl2_table.h"
#include "../../tools/dxl/dxlt.h"
#include "port.h"
#include "ptypeer.h"
#include "xfake.h"

/* ---- the fake bus: xfake.h's servos on a pty ------------------------------------- */

struct fake_bus {
	struct xfake x;
	int master, slave;
	atomic_bool stop;
};

static long fake_line_baud(const struct fake_bus *fb)
{
	struct termios2 tio;
	if (ioctl(fb->slave, TCGETS2, &tio) != 0)
		return -1;
	return (long)tio.c_ospeed;
}

/* A status packet onto the pty, after the servo's return delay. */
static void fake_emit(void *ctx, const uint8_t *pkt, size_t k, unsigned delay_us)
{
	struct fake_bus *fb = ctx;
	if (delay_us > 0) {
		struct timespec d = { 0, (long)delay_us * 1000L };
		nanosleep(&d, NULL);
	}
	for (size_t done = 0; done < k;) {
		ssize_t w = write(fb->master, pkt + done, k - done);
		if (w <= 0 && errno != EINTR)
			return;
		if (w > 0)
			done += (size_t)w;
	}
}

static int fake_open(struct fake_bus *fb, const uint8_t *ids, const uint16_t *models, size_t n)
{
	struct ptypeer pty;
	memset(fb, 0, sizeof *fb);
	if (ptypeer_open(&pty) != 0)
		return -1;
	fb->master = pty.master;
	fb->slave = open(pty.slave_path, O_RDWR | O_NOCTTY);
	if (fb->slave < 0)
		return -1;
	fb->x.emit = fake_emit;
	fb->x.ctx = fb;
	for (size_t i = 0; i < n && i < XFAKE_MAX_SERVOS; i++)
		xfake_servo_defaults(&fb->x.servo[fb->x.nservos++], ids[i], models[i]);
	return 0;
}

static void *fake_serve(void *arg)
{
	struct fake_bus *fb = arg;
	uint8_t buf[XFAKE_RX_MAX];
	while (!atomic_load(&fb->stop)) {
		struct pollfd pfd = { .fd = fb->master, .events = POLLIN };
		if (poll(&pfd, 1, 20) <= 0 || !(pfd.revents & POLLIN))
			continue;
		ssize_t n = read(fb->master, buf, sizeof buf - fb->x.have);
		if (n <= 0)
			continue;
		/* it hears only at its own rate, as the client set the line */
		fb->x.line_baud = fake_line_baud(fb);
		if (fb->x.line_baud <= 0)
			fb->x.line_baud = -1;
		xfake_feed(&fb->x, buf, (size_t)n);
	}
	return NULL;
}

/* ---- fixture ------------------------------------------------------------------- */

struct fixture {
	struct fake_bus bus;
	pthread_t thread;
	char path[64];
	char *out, *err;
	size_t outlen, errlen;
};

static int setup(void **state)
{
	struct fixture *f = calloc(1, sizeof *f);
	const uint8_t ids[] = { 1, 2 };
	const uint16_t models[] = { DXL2_MODEL_XL430_W250, DXL2_MODEL_XM430_W350 };
	assert_non_null(f);
	assert_int_equal(fake_open(&f->bus, ids, models, 2), 0);
	snprintf(f->path, sizeof f->path, "%s", ptsname(f->bus.master));
	assert_int_equal(pthread_create(&f->thread, NULL, fake_serve, &f->bus), 0);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fixture *f = *state;
	atomic_store(&f->bus.stop, true);
	pthread_join(f->thread, NULL);
	close(f->bus.slave);
	close(f->bus.master);
	free(f->out);
	free(f->err);
	free(f);
	return 0;
}

/* The fake answers from a thread a loaded machine may schedule late: every
 * reply gets 100 ms (as test_dxl_fakeservo.c's). The servos' factory rate. */
static int run_dxl(struct fixture *f, char *first, ...)
{
	char *argv[40];
	int argc = 0;
	va_list ap;
	free(f->out);
	free(f->err);
	f->out = f->err = NULL;
	FILE *out = open_memstream(&f->out, &f->outlen), *err = open_memstream(&f->err, &f->errlen);
	assert_non_null(out);
	assert_non_null(err);
	char *fixed[] = { (char *)"dxl", (char *)"--port", f->path, (char *)"--timeout-ms", (char *)"100",
	                  (char *)"--baud", (char *)"57600" };
	for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
		argv[argc++] = fixed[i];
	va_start(ap, first);
	for (char *a = first; a != NULL && argc < 39; a = va_arg(ap, char *))
		argv[argc++] = a;
	va_end(ap);
	argv[argc] = NULL;
	int rc = dxlt_main(argc, argv, out, err);
	fclose(out);
	fclose(err);
	return rc;
}

static struct xfake_servo *servo_by_id(struct fixture *f, uint8_t id)
{
	for (size_t i = 0; i < f->bus.x.nservos; i++)
		if (f->bus.x.servo[i].mem[7] == id)
			return &f->bus.x.servo[i];
	return NULL;
}

/* ---- the fake against the manual --------------------------------------------- */

static size_t exchange(struct port *p, const uint8_t *req, size_t n, uint8_t *got, size_t want)
{
	size_t have = 0;
	assert_int_equal(port_write(p, req, n), DXL_OK);
	while (have < want && port_wait(p, 1000000) == 1)
		have += (size_t)port_read(p, got + have, want - have);
	return have;
}

static void test_fake_answers_manual_vectors(void **state)
{
	struct fixture *f = *state;
	/* e-manual, Protocol 2.0, Ping example 1 and Read example: ID 1, model
	 * 1030, firmware 38; Present Position 166 */
	const uint8_t ping1[] = { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E };
	const uint8_t ping1_ok[] = { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D };
	const uint8_t read_pos[] = { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15 };
	const uint8_t pos_ok[] = { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0 };
	/* hand-stuffed (test_protocol_packet.c, the 2.0 table): data FF FF FD comes back stuffed */
	const uint8_t read3[] = { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x03, 0x00 };
	const uint8_t stuffed_ok[] = { 0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0x9A,
	                               0x34 };
	struct port_options opt = { .baud = 57600 };
	char why[200];
	uint8_t got[32], req[16];
	struct port *p = port_open(f->path, &opt, why, sizeof why);
	struct xfake_servo *s = servo_by_id(f, 1);

	assert_non_null(p);
	xfake_put(s->mem, 0, 1030, 2);
	s->mem[6] = 38;
	s->mem[9] = 0;
	xfake_put(s->mem, 132, 166, 4);
	assert_int_equal(exchange(p, ping1, sizeof ping1, got, sizeof ping1_ok), sizeof ping1_ok);
	assert_memory_equal(got, ping1_ok, sizeof ping1_ok);
	assert_int_equal(exchange(p, read_pos, sizeof read_pos, got, sizeof pos_ok), sizeof pos_ok);
	assert_memory_equal(got, pos_ok, sizeof pos_ok);
	xfake_put(s->mem, 132, 0xFDFFFF, 3);
	memcpy(req, read3, sizeof read3);
	uint16_t crc = xfake_crc(req, sizeof read3);
	req[sizeof read3] = (uint8_t)crc;
	req[sizeof read3 + 1] = (uint8_t)(crc >> 8);
	assert_int_equal(exchange(p, req, sizeof read3 + 2, got, sizeof stuffed_ok), sizeof stuffed_ok);
	assert_memory_equal(got, stuffed_ok, sizeof stuffed_ok);
	port_close(p);
}

/* ---- dxl --protocol 2 ------------------------------------------------------------ */

static void test_ping_and_scan(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "--protocol", "2", "ping", "1", NULL), 0);
	assert_non_null(strstr(f->out, "ID 1 answered in "));
	assert_non_null(strstr(f->out, "model 1060 (XL430-W250), firmware 46, Protocol 2.0"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "ping", "2", NULL), 0);
	assert_non_null(strstr(f->out, "model 1020 (XM430-W350)"));
	/* without --protocol: both protocols at the rate, each line saying which */
	assert_int_equal(run_dxl(f, "scan", "--ids", "0-5", NULL), 0);
	assert_non_null(strstr(f->out, "PROTOCOL\n"));
	assert_non_null(strstr(f->out, "\n1    1060   XL430-W250    46        57600    2.0\n"));
	assert_non_null(strstr(f->out, "\n2    1020   XM430-W350    46        57600    2.0\n"));
	assert_null(strstr(f->out, " 1.0\n"));
	/* an ID range keeps to it */
	assert_int_equal(run_dxl(f, "scan", "--protocol", "2", "--ids", "2-2", NULL), 0);
	assert_null(strstr(f->out, "\n1 "));
	/* 1.0 alone finds nothing: the X servos do not answer it */
	assert_int_equal(run_dxl(f, "--protocol", "1", "scan", "--ids", "0-3", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "no servo answered"));
	assert_non_null(strstr(f->err, "Protocol 1.0"));
	/* at another rate: none */
	assert_int_equal(run_dxl(f, "--protocol", "2", "--baud", "1000000", "ping", "1", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "no reply from ID 1 at 1000000 bps"));
}

/* Every rate either protocol knows: one servo moved to 1 Mbps is found there. */
static void test_scan_all_bauds(void **state)
{
	struct fixture *f = *state;

	servo_by_id(f, 2)->mem[8] = 3;   /* 1 Mbps */
	assert_int_equal(run_dxl(f, "scan", "--protocol", "2", "--bauds", "all", "--ids", "0-5", NULL), 0);
	assert_non_null(strstr(f->out, "\n1    1060   XL430-W250    46        57600    2.0\n"));
	assert_non_null(strstr(f->out, "\n2    1020   XM430-W350    46        1000000  2.0\n"));
	/* an explicit list: only the rates the X series has */
	assert_int_equal(run_dxl(f, "scan", "--protocol", "2", "--bauds", "1000000,400000", NULL), 0);
	assert_non_null(strstr(f->out, "1000000  2.0\n"));
}

static void test_read_by_name(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "present_temperature", NULL), 0);
	assert_string_equal(f->out, "36\n");
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "132", NULL), 0);   /* by address */
	assert_string_equal(f->out, "2048\n");
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "position", "--units", NULL), 0);
	assert_non_null(strstr(f->out, "2048 ("));
	assert_non_null(strstr(f->out, "deg"));
	/* signed: -3 is -3, not 4294967293 */
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "present_velocity", NULL), 0);
	assert_string_equal(f->out, "-3\n");
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "present_input_voltage", "--units", NULL), 0);
	assert_non_null(strstr(f->out, "12.0 V"));
	/* the XM430 has a current limit; the XL430 does not */
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "2", "current_limit", NULL), 0);
	assert_string_equal(f->out, "1193\n");
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "current_limit", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "unknown register 'current_limit' for the XL430-W250"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "9", "position", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "no reply from ID 9"));
}

static void test_write_checks_first(void **state)
{
	struct fixture *f = *state;
	struct xfake_servo *s = servo_by_id(f, 1);

	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "goal_position", "3000", NULL), 0);
	assert_int_equal(xfake_get(s->mem, 116, 4), 3000);
	unsigned writes = atomic_load(&f->bus.x.writes);
	/* out of the table's range, read-only, not a number: nothing written */
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "goal_position", "2000000", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "out of range for goal_position (-1048575..1048575)"));
	/* within the table's (extended position mode), outside position mode's */
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "goal_position", "5000", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "outside goal_position's range on ID 1 now (0..4095"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "present_position", "10", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "read-only"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "goal_position", "1x", NULL), DXLT_EXIT_USAGE);
	/* within the table's range, outside the servo's position limits now */
	xfake_put(s->mem, 48, 3000, 4);
	xfake_put(s->mem, 52, 1000, 4);
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "goal_position", "3500", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "outside goal_position's range on ID 1 now (1000..3000"));
	/* the XL430 has no current mode */
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "operating_mode", "0", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "has no operating_mode 0"));
	/* EEPROM with torque on: refused before the servo says so */
	s->mem[64] = 1;
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "return_delay_time", "0", NULL), DXLT_EXIT_REFUSED);
	assert_non_null(strstr(f->err, "torque 1 off"));
	assert_int_equal(atomic_load(&f->bus.x.writes), writes);
	/* ID and baud go through their own commands */
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "id", "5", NULL), DXLT_EXIT_USAGE);
	/* torque off, then the EEPROM write goes through; signed values */
	assert_int_equal(run_dxl(f, "--protocol", "2", "torque", "1", "off", NULL), 0);
	assert_int_equal(s->mem[64], 0);
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "return_delay_time", "0", NULL), 0);
	assert_int_equal(s->mem[9], 0);
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "homing_offset", "--", "-100", NULL), 0);
	assert_int_equal((int32_t)xfake_get(s->mem, 20, 4), -100);
	/* status return level 1: WRITE not answered, read back instead */
	s->mem[68] = 1;
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "led", "1", NULL), 0);
	assert_non_null(strstr(f->out, "read back"));
	assert_int_equal(s->mem[65], 1);
	/* broadcast is not a servo with a table */
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "254", "led", "1", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "253", "led", "1", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "0-252 on Protocol 2.0"));
}

/* A model not in our tables: raw addresses work, and the tool says so. */
static void test_unknown_model(void **state)
{
	struct fixture *f = *state;
	struct xfake_servo *s = servo_by_id(f, 1);

	xfake_put(s->mem, 0, 1200, 2);
	assert_int_equal(run_dxl(f, "--protocol", "2", "ping", "1", NULL), 0);
	assert_non_null(strstr(f->out, "model 1200 (not in dxl's tables)"));
	assert_non_null(strstr(f->err, "by address"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "present_position", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "registers by address only, not 'present_position'"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "132", "--size", "4", NULL), 0);
	assert_string_equal(f->out, "2048\n");
	assert_non_null(strstr(f->err, "address 132 taken as 4 raw bytes, unchecked"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "65", "1", NULL), 0);
	assert_int_equal(s->mem[65], 1);
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "65", "300", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--protocol", "2", "dump", "1", NULL), 0);
	assert_non_null(strstr(f->out, "raw, little-endian"));
	assert_non_null(strstr(f->out, "\n128   FD FF FF FF 00 08 00 00"));
}

static void test_dump(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "--protocol", "2", "dump", "2", NULL), 0);
	assert_non_null(strstr(f->out, "XM430-W350 (model 1020), firmware 46\n"));
	assert_non_null(strstr(f->out, "\n38   current_limit"));
	assert_non_null(strstr(f->out, "\n146  present_temperature"));
	assert_non_null(strstr(f->out, "[EEPROM]"));
}

/* The ERR field is named, the alert explained; the value still comes out. */
static void test_err_field(void **state)
{
	struct fixture *f = *state;

	servo_by_id(f, 2)->err = 0x80;
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "2", "present_temperature", NULL), DXLT_EXIT_SERVO);
	assert_string_equal(f->out, "36\n");
	assert_non_null(strstr(f->err, "ID 2 reports error 0x80: alert (the alert bit: a hardware error"));
	assert_non_null(strstr(f->err, "reboot"));
	servo_by_id(f, 2)->err = 0;
	/* the servo's own refusal (access error: EEPROM with torque on, behind
	 * the tool's back) is named too */
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "led", NULL), 0);
	assert_string_equal(f->err, "");
	/* a refused write's error number gets its remedy, as 1.0's bits do
	 * (the hints were 1.0's alone; the error fields of both protocols are
	 * one table of refusals now) */
	servo_by_id(f, 1)->err = DXL2_ERRNUM_ACCESS;
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "return_delay_time", "0", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "ID 1 reports error 0x07: access"));
	assert_non_null(strstr(f->err, "refuses EEPROM writes (return_delay_time)"));
	assert_non_null(strstr(f->err, "dxl --protocol 2 --port "));
	servo_by_id(f, 1)->err = DXL2_ERRNUM_DATA_LIMIT;
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "goal_position", "2100", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "outside the servo's position limits"));
	assert_non_null(strstr(f->err, "read 1 min_position_limit (and max_position_limit)"));
	servo_by_id(f, 1)->err = 0;
}

static void test_set_id_baud_reset_reboot(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "--protocol", "2", "set-id", "1", "2", NULL), DXLT_EXIT_REFUSED);
	assert_non_null(strstr(f->err, "ID 2 is already taken"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "set-id", "1", "7", NULL), 0);
	assert_non_null(servo_by_id(f, 7));
	servo_by_id(f, 7)->mem[64] = 1;
	assert_int_equal(run_dxl(f, "--protocol", "2", "set-id", "7", "8", NULL), DXLT_EXIT_REFUSED);
	servo_by_id(f, 7)->mem[64] = 0;
	assert_int_equal(run_dxl(f, "--protocol", "2", "set-baud", "7", "1000000", NULL), 0);
	assert_int_equal(servo_by_id(f, 7)->mem[8], 3);
	assert_non_null(strstr(f->out, "now at 1000000 bps (register value 3)"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "set-baud", "7", "500000", NULL), DXLT_EXIT_USAGE);
	/* reset keeping the ID: back at 57600 under the same ID */
	assert_int_equal(run_dxl(f, "--protocol", "2", "--baud", "1000000", "reset", "7", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "--yes"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "--baud", "1000000", "reset", "7", "--yes", "--keep", "id", NULL), 0);
	assert_non_null(strstr(f->out, "now ID 7 at 57600 bps"));
	assert_int_equal(servo_by_id(f, 7)->mem[8], 1);
	/* a full reset: ID 1 */
	assert_int_equal(run_dxl(f, "--protocol", "2", "reset", "7", "--yes", NULL), 0);
	assert_non_null(servo_by_id(f, 1));
	/* reboot: torque off, the hardware error cleared */
	struct xfake_servo *s = servo_by_id(f, 2);
	s->mem[64] = 1;
	s->mem[70] = DXL2_HWERR_OVERLOAD;
	unsigned reboots = atomic_load(&f->bus.x.reboots);
	assert_int_equal(run_dxl(f, "--protocol", "2", "reboot", "2", NULL), 0);
	assert_non_null(strstr(f->out, "ID 2 rebooted"));
	assert_int_equal(atomic_load(&f->bus.x.reboots), reboots + 1);
	assert_int_equal(s->mem[70], 0);
	assert_int_equal(s->mem[64], 0);
	/* ... unless the cause is still there */
	s->hwerr_after_reboot = DXL2_HWERR_OVERHEAT;
	assert_int_equal(run_dxl(f, "--protocol", "2", "reboot", "2", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "hardware error status 4 (overheating)"));
	/* the AX-12 has none */
	assert_int_equal(run_dxl(f, "reboot", "2", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "no REBOOT"));
}

static void test_setup(void **state)
{
	struct fixture *f = *state;

	servo_by_id(f, 1)->mem[64] = 1;
	assert_int_equal(run_dxl(f, "--protocol", "2", "setup", "1", "2", NULL), DXLT_EXIT_REFUSED);
	assert_non_null(strstr(f->err, "ID 1 has torque on"));
	assert_int_equal(servo_by_id(f, 1)->mem[9], 250);
	assert_int_equal(run_dxl(f, "--protocol", "2", "setup", "1", "2", "--yes", NULL), 0);
	for (uint8_t id = 1; id <= 2; id++) {
		struct xfake_servo *s = servo_by_id(f, id);
		assert_int_equal(s->mem[64], 0);
		assert_int_equal(s->mem[9], 0);
		assert_int_equal(s->mem[68], 2);
		assert_int_equal(s->mem[8], 3);   /* 57600 -> 1 Mbps */
	}
	assert_non_null(strstr(f->out, "ID 1: return_delay_time set to 0"));
	assert_non_null(strstr(f->out, "baud_rate 57600 -> 1000000 bps"));
	/* at 1 Mbps, two servos, 10 bytes each (the XM430 has a current):
	 * (14 + 2) + 2 x (11 + 10) + (14 + 10) = 82 bytes */
	assert_non_null(strstr(f->out, "bus time per cycle for 2 servos at 1000000 bps: 0.82 ms on the wire"));
	/* a second run finds everything done */
	assert_int_equal(run_dxl(f, "--protocol", "2", "--baud", "1000000", "setup", "1", "2", NULL), 0);
	assert_non_null(strstr(f->out, "ID 2: return_delay_time already 0"));
	assert_null(strstr(f->out, "baud_rate"));
}

static void test_doctor(void **state)
{
	struct fixture *f = *state;

	servo_by_id(f, 2)->mem[70] = DXL2_HWERR_OVERLOAD;
	xfake_put(servo_by_id(f, 2)->mem, 144, 95, 2);     /* 9.5 V: below the XM430's 10 V */
	servo_by_id(f, 1)->mem[98] = 0xFF;                /* its watchdog fired */
	assert_int_equal(run_dxl(f, "--protocol", "2", "doctor", "1", "2", NULL), DXLT_EXIT_FAIL);
	const char *want[] = {
		"\nOK    ID 1 model          1060 (XL430-W250), firmware 46\n",
		"\nOK    ID 2 model          1020 (XM430-W350), firmware 46\n",
		"\nWARN  ID 1 return delay   500 us before every reply",
		"\nOK    ID 1 voltage        12.0 V (servo's limits 6.0..14.0 V)\n",
		"\nFAIL  ID 2 voltage        9.5 V (servo's limits 9.5..16.0 V), below the XM430-W350's 10..14.8 V",
		"\nOK    ID 1 operating mode 3 (position)\n",
		"\nOK    ID 1 position limits 0..4095, around the configuration's",
		"\nFAIL  ID 2 hardware error 32 (overload): the servo switched its torque off",
		"reboot 2",
		"\nOK    ID 2 bus watchdog   off\n",
		"\nFAIL  ID 1 bus watchdog   fired (-1)",
		/* two servos at 57600 bps, the XM430's current too: 82 bytes, 14.2 ms: more than the period */
		"\nFAIL  baud                57600 bps: one cycle's bytes for 2 servo(s) (a SYNC_READ, a SYNC_WRITE) take 14.24 ms",
		/* the daemon's own 2.0 cycle, timed, holding the servos it can drive */
		" cycles of undulated's own loop on 2 joint(s), holding:",
	};
	for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
		if (strstr(f->out, want[i]) == NULL) {
			fputs(f->out, stderr);
			fail_msg("missing '%s'", want[i]);
		}
	}
	assert_non_null(strstr(f->out, "summary: "));
	assert_non_null(strstr(f->out, "budget              bus time per cycle p50 "));
	assert_non_null(strstr(f->out, " FAIL: exit 7\n"));
}

static void test_usage(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "--protocol", "3", "ping", "1", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "bad protocol (want 1 or 2) for --protocol '3'"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "--size", "3", "read", "1", "7", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--protocol", "2", "reset", "1", "--keep", "baud", "--yes", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--protocol", "2", "ping", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--protocol", "2", "torque", "1", "sideways", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(atomic_load(&f->bus.x.writes), 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(test_fake_answers_manual_vectors, setup, teardown),
		cmocka_unit_test_setup_teardown(test_ping_and_scan, setup, teardown),
		cmocka_unit_test_setup_teardown(test_scan_all_bauds, setup, teardown),
		cmocka_unit_test_setup_teardown(test_read_by_name, setup, teardown),
		cmocka_unit_test_setup_teardown(test_write_checks_first, setup, teardown),
		cmocka_unit_test_setup_teardown(test_unknown_model, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dump, setup, teardown),
		cmocka_unit_test_setup_teardown(test_err_field, setup, teardown),
		cmocka_unit_test_setup_teardown(test_set_id_baud_reset_reboot, setup, teardown),
		cmocka_unit_test_setup_teardown(test_setup, setup, teardown),
		cmocka_unit_test_setup_teardown(test_doctor, setup, teardown),
		cmocka_unit_test_setup_teardown(test_usage, setup, teardown),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
