/*
 * test_dxl_fakeservo.c — a fake AX-12 bus on a pty, and the `dxl` tool's
 * tests against it.
 *
 * Two uses of one program:
 *  - without arguments (as the test runner starts it): cmocka tests. The fake
 *    bus serves in a thread and every `dxl` command runs in-process
 *    (dxlt_main) with its output captured.
 *  - `test_dxl_fakeservo --serve LINK --ids 1,2 [--errbits ID:BITS]`: serve
 *    a fake bus on a pty whose slave LINK points to, print "ready LINK", run
 *    until SIGTERM. tests/integration/dxl_*.sh run the real `dxl` binary
 *    against it. (A test-only program must live here: the tests/unit files
 *    not named test_* are linked into every unit test.)
 *
 * The fake frames packets with its own few lines of code, not protocol/dxl.c,
 * and is itself checked against the manual's byte vectors first: a bug shared
 * by our encoder and our parser cannot pass through it unseen.
 *
 * It reads the baud rate the client set on the pty (termios2 on its own slave
 * fd) and stays silent when that differs from a servo's baud register, the
 * way a real servo hears only noise at the wrong rate.
 */
#include <asm/termbits.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include "dxl_table.h"
#include "../../tools/dxl/dxlt.h"
#include "port.h"
#include "ptypeer.h"

/* ---- the fake bus ------------------------------------------------------------- */

#define FAKE_MAX_SERVOS 8
#define FAKE_TABLE 50
#define FAKE_FIRMWARE 24
#define FAKE_RX_MAX 1024

struct fake_servo {
	uint8_t mem[FAKE_TABLE];
	uint8_t errbits;             /* forced into every status (fault injection) */
};

struct fake_bus {
	int master, slave;
	struct fake_servo servo[FAKE_MAX_SERVOS];
	size_t nservos;
	uint8_t rx[FAKE_RX_MAX];
	size_t have;
	atomic_bool stop;
	atomic_uint packets;         /* well-formed instruction packets heard */
	atomic_uint writes;          /* WRITE instructions executed */
	atomic_uint bad_checksums;
};

static void fake_servo_defaults(struct fake_servo *s, uint8_t id)
{
	memset(s->mem, 0, sizeof s->mem);
	for (size_t i = 0; i < dxl_ax12_nregs; i++) {
		const struct dxl_reg *r = &dxl_ax12_regs[i];
		uint16_t v = r->def >= 0 ? (uint16_t)r->def : 0;
		s->mem[r->addr] = (uint8_t)(v & 0xFF);
		if (r->size == 2)
			s->mem[r->addr + 1] = (uint8_t)(v >> 8);
	}
	s->mem[DXL_AX_FIRMWARE_VERSION] = FAKE_FIRMWARE;
	s->mem[DXL_AX_ID] = id;
	s->mem[DXL_AX_PRESENT_POSITION] = 0x00; /* 512: centre */
	s->mem[DXL_AX_PRESENT_POSITION + 1] = 0x02;
	s->mem[DXL_AX_GOAL_POSITION] = 0x00;
	s->mem[DXL_AX_GOAL_POSITION + 1] = 0x02;
	s->mem[DXL_AX_PRESENT_VOLTAGE] = 120;
	s->mem[DXL_AX_PRESENT_TEMPERATURE] = 32; /* the manual's READ example answers 32 °C */
}

/* The line rate the client set on the pty. */
static long fake_line_baud(const struct fake_bus *fb)
{
	struct termios2 tio;

	if (ioctl(fb->slave, TCGETS2, &tio) != 0)
		return -1;
	return (long)tio.c_ospeed;
}

static bool fake_hears(const struct fake_servo *s, long line)
{
	long own = 2000000L / (s->mem[DXL_AX_BAUD_RATE] + 1);
	long diff = own > line ? own - line : line - own;
	return line > 0 && diff * 100 <= own * 3; /* within 3 %: a UART's tolerance */
}

static void fake_send_status(struct fake_bus *fb, const struct fake_servo *s, uint8_t err,
                             const uint8_t *params, size_t n)
{
	uint8_t pkt[FAKE_TABLE + 6];
	unsigned sum;
	size_t i;

	pkt[0] = 0xFF;
	pkt[1] = 0xFF;
	pkt[2] = s->mem[DXL_AX_ID];
	pkt[3] = (uint8_t)(n + 2);
	pkt[4] = (uint8_t)(err | s->errbits);
	sum = pkt[2] + pkt[3] + pkt[4];
	for (i = 0; i < n; i++) {
		pkt[5 + i] = params[i];
		sum += params[i];
	}
	pkt[5 + n] = (uint8_t)~sum;
	unsigned delay_us = s->mem[DXL_AX_RETURN_DELAY_TIME] * 2u;
	if (delay_us > 0) {
		struct timespec d = { 0, (long)delay_us * 1000L };
		nanosleep(&d, NULL);
	}
	size_t done = 0;
	while (done < n + 6) {
		ssize_t w = write(fb->master, pkt + done, n + 6 - done);
		if (w <= 0 && errno != EINTR)
			return;
		if (w > 0)
			done += (size_t)w;
	}
}

static void fake_execute(struct fake_bus *fb, struct fake_servo *s, uint8_t instr,
                         const uint8_t *p, size_t n, bool broadcast)
{
	uint8_t level = s->mem[DXL_AX_STATUS_RETURN_LEVEL];

	switch (instr) {
	case 0x01: /* PING: always answered */
		if (!broadcast)
			fake_send_status(fb, s, 0, NULL, 0);
		break;
	case 0x02: /* READ addr len */
		if (n != 2 || p[0] + p[1] > FAKE_TABLE || p[1] == 0) {
			if (!broadcast && level >= 1)
				fake_send_status(fb, s, DXL_ERRBIT_RANGE, NULL, 0);
		} else if (!broadcast && level >= 1) {
			fake_send_status(fb, s, 0, &s->mem[p[0]], p[1]);
		}
		break;
	case 0x03: /* WRITE addr data... */
		if (n < 2 || p[0] + (n - 1) > FAKE_TABLE) {
			if (!broadcast && level >= 2)
				fake_send_status(fb, s, DXL_ERRBIT_RANGE, NULL, 0);
			break;
		}
		atomic_fetch_add(&fb->writes, 1);
		memcpy(&s->mem[p[0]], p + 1, n - 1);
		if (!broadcast && s->mem[DXL_AX_STATUS_RETURN_LEVEL] >= 2)
			fake_send_status(fb, s, 0, NULL, 0);
		break;
	case 0x06: /* FACTORY_RESET */
		fake_servo_defaults(s, 1);
		break;
	default:
		if (!broadcast && level >= 2)
			fake_send_status(fb, s, DXL_ERRBIT_INSTRUCTION, NULL, 0);
		break;
	}
}

static void fake_dispatch(struct fake_bus *fb, const uint8_t *pkt)
{
	uint8_t id = pkt[2], len = pkt[3], instr = pkt[4];
	long line = fake_line_baud(fb);

	atomic_fetch_add(&fb->packets, 1);
	for (size_t i = 0; i < fb->nservos; i++) {
		struct fake_servo *s = &fb->servo[i];
		if ((id == s->mem[DXL_AX_ID] || id == 0xFE) && fake_hears(s, line)) {
			fake_execute(fb, s, instr, pkt + 5, (size_t)len - 2, id == 0xFE);
			if (id != 0xFE)
				break;
		}
	}
}

/* Frame what is buffered: FF FF ID LEN INSTR P.. CHK; on any doubt drop a byte. */
static void fake_parse(struct fake_bus *fb)
{
	size_t off = 0;

	while (fb->have - off >= 4) {
		const uint8_t *b = fb->rx + off;
		if (b[0] != 0xFF || b[1] != 0xFF || b[2] == 0xFF || b[3] < 2 || b[3] > 250) {
			off++;
			continue;
		}
		size_t total = (size_t)b[3] + 4;
		if (fb->have - off < total)
			break;
		unsigned sum = 0;
		for (size_t i = 2; i < total - 1; i++)
			sum += b[i];
		if ((uint8_t)~sum != b[total - 1]) {
			atomic_fetch_add(&fb->bad_checksums, 1);
			off++;
			continue;
		}
		fake_dispatch(fb, b);
		off += total;
	}
	memmove(fb->rx, fb->rx + off, fb->have - off);
	fb->have -= off;
}

static int fake_open(struct fake_bus *fb, const uint8_t *ids, size_t n)
{
	struct ptypeer pty;

	memset(fb, 0, sizeof *fb);
	if (ptypeer_open(&pty) != 0)
		return -1;
	fb->master = pty.master;
	/* Our own slave fd: keeps the pty alive between clients, and tells us the
	 * baud rate they set. */
	fb->slave = open(pty.slave_path, O_RDWR | O_NOCTTY);
	if (fb->slave < 0)
		return -1;
	for (size_t i = 0; i < n && i < FAKE_MAX_SERVOS; i++)
		fake_servo_defaults(&fb->servo[fb->nservos++], ids[i]);
	return 0;
}

static const char *fake_slave_path(const struct fake_bus *fb)
{
	return ptsname(fb->master);
}

static void fake_serve(struct fake_bus *fb)
{
	while (!atomic_load(&fb->stop)) {
		struct pollfd pfd = { .fd = fb->master, .events = POLLIN };
		int r = poll(&pfd, 1, 20);
		if (r <= 0 || !(pfd.revents & POLLIN))
			continue;
		ssize_t n = read(fb->master, fb->rx + fb->have, sizeof fb->rx - fb->have);
		if (n <= 0)
			continue;
		fb->have += (size_t)n;
		fake_parse(fb);
		if (fb->have == sizeof fb->rx)
			fb->have = 0; /* a full buffer of garbage: start over */
	}
}

static void fake_close(struct fake_bus *fb)
{
	close(fb->slave);
	close(fb->master);
}

/* ---- serve mode ------------------------------------------------------------------ */

static struct fake_bus serve_bus;

static void serve_stop(int sig)
{
	(void)sig;
	atomic_store(&serve_bus.stop, true);
}

static int serve_main(int argc, char **argv)
{
	const char *link = NULL;
	uint8_t ids[FAKE_MAX_SERVOS] = { 1 };
	size_t nids = 1;
	uint8_t fault_id = 0, fault_bits = 0;

	for (int i = 1; i + 1 < argc; i += 2) {
		if (strcmp(argv[i], "--serve") == 0) {
			link = argv[i + 1];
		} else if (strcmp(argv[i], "--ids") == 0) {
			char *save = NULL;
			nids = 0;
			for (char *t = strtok_r(argv[i + 1], ",", &save); t && nids < FAKE_MAX_SERVOS;
			     t = strtok_r(NULL, ",", &save))
				ids[nids++] = (uint8_t)atoi(t);
		} else if (strcmp(argv[i], "--errbits") == 0) {
			unsigned a, b;
			if (sscanf(argv[i + 1], "%u:%i", &a, &b) == 2) {
				fault_id = (uint8_t)a;
				fault_bits = (uint8_t)(b & 0x7F);
			}
		}
	}
	if (link == NULL) {
		fprintf(stderr, "usage: %s --serve LINK [--ids 1,2] [--errbits ID:BITS]\n", argv[0]);
		return 2;
	}
	if (fake_open(&serve_bus, ids, nids) != 0) {
		perror("fakeservo: pty");
		return 1;
	}
	for (size_t i = 0; i < serve_bus.nservos; i++)
		if (serve_bus.servo[i].mem[DXL_AX_ID] == fault_id)
			serve_bus.servo[i].errbits = fault_bits;
	unlink(link);
	if (symlink(fake_slave_path(&serve_bus), link) != 0) {
		perror("fakeservo: symlink");
		return 1;
	}
	signal(SIGTERM, serve_stop);
	signal(SIGINT, serve_stop);
	printf("ready %s\n", link);
	fflush(stdout);
	fake_serve(&serve_bus);
	unlink(link);
	fake_close(&serve_bus);
	return 0;
}

/* ---- cmocka: the fake against the manual ----------------------------------------- */

struct fixture {
	struct fake_bus bus;
	pthread_t thread;
	char path[64];
	bool derived_timeout; /* run dxl with its own reply timeout, not TEST_REPLY_TIMEOUT_MS */
	char *out, *err;     /* what the last dxl run printed */
	size_t outlen, errlen;
};

static void *serve_thread(void *arg)
{
	fake_serve(arg);
	return NULL;
}

static int setup(void **state)
{
	struct fixture *f = calloc(1, sizeof *f);
	const uint8_t ids[] = { 1, 2 };

	assert_non_null(f);
	assert_int_equal(fake_open(&f->bus, ids, 2), 0);
	snprintf(f->path, sizeof f->path, "%s", fake_slave_path(&f->bus));
	assert_int_equal(pthread_create(&f->thread, NULL, serve_thread, &f->bus), 0);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fixture *f = *state;

	atomic_store(&f->bus.stop, true);
	pthread_join(f->thread, NULL);
	fake_close(&f->bus);
	free(f->out);
	free(f->err);
	free(f);
	return 0;
}

static void test_fake_answers_manual_vectors(void **state)
{
	struct fixture *f = *state;
	const uint8_t ping1[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	const uint8_t ping1_ok[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
	const uint8_t read_temp[] = { 0xFF, 0xFF, 0x01, 0x04, 0x02, 0x2B, 0x01, 0xCC };
	const uint8_t read_temp_ok[] = { 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB };
	const uint8_t goal512[] = { 0xFF, 0xFF, 0x01, 0x05, 0x03, 0x1E, 0x00, 0x02, 0xD6 };
	struct port_options opt = { .baud = 1000000 };
	char err[200];
	uint8_t got[16];
	struct port *p = port_open(f->path, &opt, err, sizeof err);

	assert_non_null(p);
	f->bus.servo[0].mem[DXL_AX_RETURN_DELAY_TIME] = 0;
	assert_int_equal(port_write(p, ping1, sizeof ping1), DXL_OK);
	size_t n = 0;
	while (n < sizeof ping1_ok && port_wait(p, 1000000) == 1)
		n += (size_t)port_read(p, got + n, sizeof ping1_ok - n);
	assert_int_equal(n, sizeof ping1_ok);
	assert_memory_equal(got, ping1_ok, sizeof ping1_ok);
	assert_int_equal(port_write(p, read_temp, sizeof read_temp), DXL_OK);
	n = 0;
	while (n < sizeof read_temp_ok && port_wait(p, 1000000) == 1)
		n += (size_t)port_read(p, got + n, sizeof read_temp_ok - n);
	assert_int_equal(n, sizeof read_temp_ok);
	assert_memory_equal(got, read_temp_ok, sizeof read_temp_ok);
	assert_int_equal(port_write(p, goal512, sizeof goal512), DXL_OK);
	n = 0;
	while (n < 6 && port_wait(p, 1000000) == 1)
		n += (size_t)port_read(p, got + n, 6 - n);
	assert_int_equal(n, 6);
	assert_memory_equal(got, ping1_ok, 6); /* the empty OK status: same bytes as PING's */
	assert_int_equal(dxl_get_u16(&f->bus.servo[0].mem[DXL_AX_GOAL_POSITION]), 512);
	port_close(p);
}

/* ---- cmocka: the dxl tool in-process ---------------------------------------------- */

/* The fake answers from a thread that a loaded test machine may not schedule
 * within the tool's 5 ms of slack: the tests give every reply this long,
 * except where the derived timeout itself is under test. */
#define TEST_REPLY_TIMEOUT_MS "100"

/* Run `dxl --port <fake> ARGS...` in-process; returns the exit code, output
 * in f->out / f->err. */
static int run_dxl(struct fixture *f, char *first, ...)
{
	char *argv[32];
	int argc = 0;
	va_list ap;
	FILE *out, *err;

	free(f->out);
	free(f->err);
	f->out = f->err = NULL;
	out = open_memstream(&f->out, &f->outlen);
	err = open_memstream(&f->err, &f->errlen);
	assert_non_null(out);
	assert_non_null(err);
	argv[argc++] = (char *)"dxl";
	argv[argc++] = (char *)"--port";
	argv[argc++] = f->path;
	if (!f->derived_timeout) {
		argv[argc++] = (char *)"--timeout-ms";
		argv[argc++] = (char *)TEST_REPLY_TIMEOUT_MS;
	}
	va_start(ap, first);
	for (char *a = first; a != NULL && argc < 31; a = va_arg(ap, char *))
		argv[argc++] = a;
	va_end(ap);
	argv[argc] = NULL;
	int rc = dxlt_main(argc, argv, out, err);
	fclose(out);
	fclose(err);
	return rc;
}

static struct fake_servo *servo_by_id(struct fixture *f, uint8_t id)
{
	for (size_t i = 0; i < f->bus.nservos; i++)
		if (f->bus.servo[i].mem[DXL_AX_ID] == id)
			return &f->bus.servo[i];
	return NULL;
}

static void test_dxl_ping_and_scan(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "ping", "2", NULL), 0);
	assert_non_null(strstr(f->out, "ID 2 answered"));
	assert_non_null(strstr(f->out, "model 12 (AX-12A), firmware 24, Protocol 1.0"));
	assert_int_equal(run_dxl(f, "scan", "--ids", "0-5", NULL), 0);
	/* header + exactly the two servos, with model, firmware, baud */
	assert_non_null(strstr(f->out, "\n1    12     AX-12A        24        1000000  1.0\n"));
	assert_non_null(strstr(f->out, "\n2    12     AX-12A        24        1000000  1.0\n"));
	assert_null(strstr(f->out, "\n3 "));
	assert_string_equal(f->err, "");
}

static void test_dxl_read_raw_and_units(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "read", "1", "present_temperature", NULL), 0);
	assert_string_equal(f->out, "32\n");
	assert_int_equal(run_dxl(f, "read", "1", "36", NULL), 0); /* by address */
	assert_string_equal(f->out, "512\n");
	assert_int_equal(run_dxl(f, "read", "1", "goal_position", "--units", NULL), 0);
	assert_non_null(strstr(f->out, "512 ("));
	assert_non_null(strstr(f->out, "deg"));
}

static void test_dxl_write_validates_first(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "700", NULL), 0);
	assert_int_equal(dxl_get_u16(&servo_by_id(f, 1)->mem[DXL_AX_GOAL_POSITION]), 700);
	unsigned writes = atomic_load(&f->bus.writes);
	unsigned packets = atomic_load(&f->bus.packets);
	/* out of range, read-only, unknown, not a number: nothing goes on the wire */
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "1024", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "out of range for goal_position (0..1023)"));
	assert_int_equal(run_dxl(f, "write", "1", "present_position", "10", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "read-only"));
	assert_int_equal(run_dxl(f, "write", "1", "warp_drive", "1", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "unknown register 'warp_drive'"));
	assert_int_equal(run_dxl(f, "write", "1", "led", "-1", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "5x", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "value '5x' for goal_position is not a number"));
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "1e3", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "is not a number"));
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "read", "1", "nonsense", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(atomic_load(&f->bus.writes), writes);
	assert_int_equal(atomic_load(&f->bus.packets), packets);
	assert_int_equal(dxl_get_u16(&servo_by_id(f, 1)->mem[DXL_AX_GOAL_POSITION]), 700);
	/* padded values are decimal: 0500 is 500, not octal 320 */
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "0500", NULL), 0);
	assert_int_equal(dxl_get_u16(&servo_by_id(f, 1)->mem[DXL_AX_GOAL_POSITION]), 500);
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "0x1f4", NULL), 0);
	assert_int_equal(dxl_get_u16(&servo_by_id(f, 1)->mem[DXL_AX_GOAL_POSITION]), 500);
}

static void test_dxl_no_reply_suggests_baud(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "read", "3", "present_position", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "no reply from ID 3 at 1000000 bps; wrong baud"));
	assert_non_null(strstr(f->err, "scan --bauds"));
	assert_string_equal(f->out, "");
	/* the servos are there, but the line runs at another rate */
	assert_int_equal(run_dxl(f, "--baud", "57600", "ping", "1", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "at 57600 bps; wrong baud"));
}

/* Every command reports a servo's error bits (names, not just a number) and
 * exits 5, after doing its work; the write whose reply carries them too (its
 * bits were once read before the call that filled them). */
static void test_dxl_errbits_exit_code(void **state)
{
	struct fixture *f = *state;
	struct {
		const char *what;
		char *argv[6];
	} cmds[] = {
		{ "read", { "read", "2", "present_load", NULL } },
		{ "write", { "write", "2", "goal_position", "600", NULL } },
		{ "ping", { "ping", "2", NULL } },
		{ "scan", { "scan", "--ids", "1-2", NULL } },
		{ "dump", { "dump", "2", NULL } },
		{ "setup", { "setup", "2", NULL } },
		{ "torque", { "torque", "2", "on", NULL } },
		{ "set-baud", { "set-baud", "2", "1000000", NULL } },
		{ "set-id", { "set-id", "2", "3", NULL } },
	};

	servo_by_id(f, 2)->errbits = DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT;
	for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
		char **a = cmds[i].argv;
		int rc = run_dxl(f, a[0], a[1], a[2], a[3], a[4]);
		if (rc != DXLT_EXIT_SERVO || strstr(f->err, "reports error bits 0x24: ") == NULL ||
		    strstr(f->err, "overload") == NULL || strstr(f->err, "overheating") == NULL)
			fail_msg("%s: exit %d, stderr '%s'", cmds[i].what, rc, f->err);
	}
	/* ...and did their work all the same */
	assert_int_equal(dxl_get_u16(&servo_by_id(f, 3)->mem[DXL_AX_GOAL_POSITION]), 600);
	assert_int_equal(servo_by_id(f, 3)->mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(run_dxl(f, "read", "3", "present_load", NULL), DXLT_EXIT_SERVO);
	assert_string_equal(f->out, "0\n"); /* the value still comes out */
	assert_int_equal(run_dxl(f, "reset", "3", "--yes", NULL), DXLT_EXIT_SERVO);
	/* the other servo is healthy: no bits, exit 0 */
	assert_int_equal(run_dxl(f, "read", "1", "present_load", NULL), 0);
	assert_string_equal(f->err, "");
}

/* A refused EEPROM write names the remedy, not only the bit. */
static void test_dxl_errbits_hint(void **state)
{
	struct fixture *f = *state;

	servo_by_id(f, 1)->errbits = DXL_ERRBIT_RANGE;
	assert_int_equal(run_dxl(f, "write", "1", "cw_angle_limit", "100", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "error bits 0x08: range"));
	assert_non_null(strstr(f->err, "torque 1 off"));
	servo_by_id(f, 1)->errbits = DXL_ERRBIT_ANGLE_LIMIT;
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "1000", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "angle limits"));
}

/* The servo's status return level decides what it answers: a write that took
 * effect is not "no reply". Level 1 is read back; level 0 is said unconfirmed. */
static void test_dxl_follows_status_level(void **state)
{
	struct fixture *f = *state;

	servo_by_id(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL] = 1;
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "700", NULL), 0);
	assert_int_equal(dxl_get_u16(&servo_by_id(f, 1)->mem[DXL_AX_GOAL_POSITION]), 700);
	assert_non_null(strstr(f->out, "read back"));
	assert_int_equal(run_dxl(f, "torque", "1", "on", NULL), 0);
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_TORQUE_ENABLE], 1);

	servo_by_id(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL] = 0;
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "300", NULL), 0);
	assert_int_equal(dxl_get_u16(&servo_by_id(f, 1)->mem[DXL_AX_GOAL_POSITION]), 300);
	assert_non_null(strstr(f->out, "not confirmed"));
	assert_int_equal(run_dxl(f, "read", "1", "goal_position", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "answers PING but not READ: status return level 0"));
	assert_int_equal(run_dxl(f, "ping", "1", NULL), 0);
	assert_non_null(strstr(f->out, "PING only"));
	/* raising the level back from 0, then writing with replies again */
	assert_int_equal(run_dxl(f, "write", "1", "status_return_level", "2", NULL), 0);
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL], 2);
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "400", NULL), 0);
	/* answered, and read back all the same: the output says what it holds */
	assert_string_equal(f->out, "ID 1: goal_position = 400 (read back)\n");
	/* ID and baud go through set-id / set-baud, which look for the answer
	 * where the servo went */
	assert_int_equal(run_dxl(f, "write", "1", "id", "6", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "set-id OLD NEW"));
	assert_int_equal(run_dxl(f, "write", "1", "baud_rate", "34", NULL), DXLT_EXIT_USAGE);
	assert_non_null(servo_by_id(f, 1));
	/* setup lowering the level: no false "no reply" (the write is read back) */
	assert_int_equal(run_dxl(f, "setup", "1", "--status-level", "1", "--yes", NULL), 0);
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL], 1);
	/* a servo absent at any level is still "no reply" */
	assert_int_equal(run_dxl(f, "write", "4", "goal_position", "400", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "no reply from ID 4"));
}

static void test_dxl_set_id(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "set-id", "1", "2", NULL), DXLT_EXIT_REFUSED);
	assert_non_null(strstr(f->err, "ID 2 is already taken"));
	assert_non_null(servo_by_id(f, 1));
	assert_int_equal(run_dxl(f, "set-id", "1", "7", NULL), 0);
	assert_non_null(servo_by_id(f, 7));
	assert_null(servo_by_id(f, 1));
	assert_int_equal(run_dxl(f, "set-id", "1", "254", NULL), DXLT_EXIT_USAGE);
}

static void test_dxl_set_baud_then_scan(void **state)
{
	struct fixture *f = *state;

	int rc = run_dxl(f, "set-baud", "2", "57600", NULL);
	if (rc != 0)
		fail_msg("set-baud: exit %d: %s", rc, f->err);
	assert_int_equal(servo_by_id(f, 2)->mem[DXL_AX_BAUD_RATE], 34);
	assert_non_null(strstr(f->out, "now at 57143 bps"));
	assert_int_equal(run_dxl(f, "scan", "--ids", "1-2", "--bauds", "1000000,57143", NULL), 0);
	assert_non_null(strstr(f->out, "\n1 "));
	assert_non_null(strstr(f->out, "1000000  1.0\n2 "));
	assert_non_null(strstr(f->out, "57143    1.0\n"));
	assert_int_equal(run_dxl(f, "set-baud", "1", "1500000", NULL), DXLT_EXIT_USAGE);
}

static void test_dxl_torque_reset_dump(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "torque", "2", "on", NULL), 0);
	assert_int_equal(servo_by_id(f, 2)->mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(run_dxl(f, "torque", "2", "sideways", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "reset", "2", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "--yes"));
	assert_int_equal(servo_by_id(f, 2)->mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(run_dxl(f, "dump", "2", NULL), 0);
	assert_non_null(strstr(f->out, "torque_enable"));
	assert_non_null(strstr(f->out, "present_temperature"));
	assert_non_null(strstr(f->out, "32 "));
	/* ID 1 is taken by the other servo: reset 2 makes a clash the tool reports */
	servo_by_id(f, 1)->mem[DXL_AX_ID] = 5;
	assert_int_equal(run_dxl(f, "reset", "2", "--yes", NULL), 0);
	assert_non_null(servo_by_id(f, 1));
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_TORQUE_ENABLE], 0);
}

static void test_dxl_setup(void **state)
{
	struct fixture *f = *state;

	servo_by_id(f, 1)->mem[DXL_AX_TORQUE_ENABLE] = 1;
	assert_int_equal(run_dxl(f, "setup", "1", "2", NULL), DXLT_EXIT_REFUSED);
	assert_non_null(strstr(f->err, "ID 1 has torque on"));
	assert_non_null(strstr(f->err, "add --yes to turn it off first"));
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(servo_by_id(f, 2)->mem[DXL_AX_RETURN_DELAY_TIME], 0);
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_RETURN_DELAY_TIME], 250);
	servo_by_id(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL] = 1;
	assert_int_equal(run_dxl(f, "setup", "1", "2", "--yes", NULL), 0);
	assert_non_null(strstr(f->out, "ID 1: torque_enable set to 0"));
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_TORQUE_ENABLE], 0);
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_RETURN_DELAY_TIME], 0);
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL], 2);
	assert_non_null(strstr(f->out, "adapter: "));
	assert_non_null(strstr(f->out, "no latency timer"));
	assert_non_null(strstr(f->out, "bus time per cycle for 2 servos"));
}

/* A fake sysfs with an FTDI latency timer for the fake bus's pty; returns the
 * timer file's path in `timer` (NULL text: leave the file for the caller). */
static void fake_ftdi_tree(char *root, size_t rootcap, const char *pty, const char *text,
                           char *timer, size_t cap)
{
	const char *name = strrchr(pty, '/') + 1;
	char cmd[512];

	snprintf(root, rootcap, "/tmp/undulate-dxl-sysfs.XXXXXX");
	assert_non_null(mkdtemp(root));
	snprintf(cmd, sizeof cmd, "mkdir -p '%s/bus/usb-serial/devices/%s'", root, name);
	assert_int_equal(system(cmd), 0);
	snprintf(timer, cap, "%s/bus/usb-serial/devices/%s/latency_timer", root, name);
	if (text != NULL) {
		FILE *fp = fopen(timer, "w");
		assert_non_null(fp);
		fputs(text, fp);
		fclose(fp);
	}
	setenv("UNDULATE_SYSFS_ROOT", root, 1);
}

static void fake_ftdi_remove(const char *root)
{
	char cmd[300];

	unsetenv("UNDULATE_SYSFS_ROOT");
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
	assert_int_equal(system(cmd), 0);
}

/* A 16 ms adapter: a missing servo's timeout includes it; setup lowers it. */
static void test_dxl_setup_lowers_latency_timer(void **state)
{
	struct fixture *f = *state;
	char root[64], timer[512], text[8] = "";

	fake_ftdi_tree(root, sizeof root, f->path, "16\n", timer, sizeof timer);
	f->derived_timeout = true;
	uint64_t t0 = port_now_us();
	assert_int_equal(run_dxl(f, "ping", "9", NULL), DXLT_EXIT_BUS);
	uint64_t took = port_now_us() - t0;
	assert_true(took >= 16000); /* the reply could be held 16 ms: wait for it */
	f->derived_timeout = false;
	assert_int_equal(run_dxl(f, "setup", "1", "2", NULL), 0);
	assert_non_null(strstr(f->out, "latency timer lowered from 16 ms to 1 ms"));
	FILE *fp = fopen(timer, "r");
	assert_non_null(fp);
	assert_non_null(fgets(text, sizeof text, fp));
	fclose(fp);
	assert_string_equal(text, "1\n");
	fake_ftdi_remove(root);
}

/* A timer that refuses the write (the kernel's read-only cap_last_cap stands
 * in: EACCES even for root): setup says so and fails with the port code. */
static void test_dxl_setup_latency_stuck(void **state)
{
	struct fixture *f = *state;
	char root[64], timer[512];

	if (access("/proc/sys/kernel/cap_last_cap", R_OK) != 0)
		skip();
	fake_ftdi_tree(root, sizeof root, f->path, NULL, timer, sizeof timer);
	assert_int_equal(symlink("/proc/sys/kernel/cap_last_cap", timer), 0);
	assert_int_equal(run_dxl(f, "setup", "1", NULL), DXLT_EXIT_PORT);
	assert_non_null(strstr(f->err, "could not be lowered"));
	assert_non_null(strstr(f->err, f->path + 5)); /* "pts/N" */
	assert_int_equal(servo_by_id(f, 1)->mem[DXL_AX_RETURN_DELAY_TIME], 0); /* servos done */
	fake_ftdi_remove(root);
}

static void test_dxl_usage_and_port_errors(void **state)
{
	struct fixture *f = *state;
	char *argv_help[] = { (char *)"dxl", (char *)"--help", NULL };
	char *argv_none[] = { (char *)"dxl", (char *)"--port", (char *)"/dev/nonexistent-bus",
	                      (char *)"ping", (char *)"1", NULL };
	char *argv_noport[] = { (char *)"dxl", (char *)"ping", (char *)"1", NULL };
	FILE *devnull = fopen("/dev/null", "w");

	assert_int_equal(dxlt_main(2, argv_help, devnull, devnull), 0);
	assert_int_equal(dxlt_main(5, argv_none, devnull, devnull), DXLT_EXIT_PORT);
	assert_int_equal(dxlt_main(3, argv_noport, devnull, devnull), DXLT_EXIT_USAGE);
	fclose(devnull);
	assert_int_equal(run_dxl(f, "frobnicate", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "unknown command 'frobnicate'"));
	assert_non_null(strstr(f->err, "usage: dxl"));
	assert_int_equal(run_dxl(f, "ping", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "ping", "300", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--bogus", "ping", "1", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "scan", "--ids", "9-3", NULL), DXLT_EXIT_USAGE);
	/* --rs485: a mode the kernel knows, or usage; on the fake's pty the
	 * kernel refuses it: exit 3, the port and errno named, nothing sent */
	assert_int_equal(run_dxl(f, "--rs485", "sideways", "ping", "1", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "bad mode (want rts-on-send, rts or rts-after-send, or off) for --rs485 'sideways'"));
	unsigned packets = atomic_load(&f->bus.packets);
	assert_int_equal(run_dxl(f, "--rs485", "rts-after-send", "ping", "1", NULL), DXLT_EXIT_PORT);
	assert_non_null(strstr(f->err, "cannot switch "));
	assert_non_null(strstr(f->err, f->path));
	assert_non_null(strstr(f->err, "to RS-485 mode (TIOCSRS485): Inappropriate ioctl for device (errno 25)"));
	assert_int_equal(atomic_load(&f->bus.packets), packets);
	assert_int_equal(run_dxl(f, "--rs485", "off", "ping", "1", NULL), 0);
	/* doctor's own options */
	assert_int_equal(run_dxl(f, "doctor", "1", "--cycles", "10001", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "--cycles '10001' is"));
	assert_int_equal(run_dxl(f, "doctor", "1", "300", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "servo ID 300 out of range 0..253"));
	assert_int_equal(run_dxl(f, "doctor", "--config", "/nonexistent/robot.conf", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "dxl: /nonexistent/robot.conf: "));
}

/* dxl doctor in-process on the fake bus: its servos keep the factory return
 * delay, and servo 2 flags every reply with overload — named on its own
 * line, once (not again as the other commands' closing error-bits line). */
static void test_dxl_doctor(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "doctor", "1", "2", "--cycles", "0", NULL), DXLT_EXIT_WARN);
	assert_non_null(strstr(f->out, "\nWARN  ID 1 return delay   500 us before every reply"));
	assert_non_null(strstr(f->out, "\nOK    ID 2 voltage        12.0 V"));
	assert_non_null(strstr(f->out, "\nSKIP  budget              not timed: --cycles 0\n"));
	assert_non_null(strstr(f->out, "summary: 17 OK, 2 WARN, 0 FAIL, 1 SKIP: exit 1\n"));
	servo_by_id(f, 2)->errbits = DXL_ERRBIT_OVERLOAD;
	assert_int_equal(run_dxl(f, "doctor", "1", "2", "--cycles", "0", NULL), DXLT_EXIT_FAIL);
	assert_non_null(strstr(f->out, "\nFAIL  ID 2 error bits     its replies carry 0x20 (overload)"));
	assert_null(strstr(f->out, "ID 1 error bits"));
	assert_null(strstr(f->err, "reports error bits"));
}

static void test_arg_parsers(void **state)
{
	(void)state;
	uint8_t lo, hi, id;
	long bauds[DXLT_MAX_BAUDS];
	size_t n;

	assert_int_equal(dxlt_parse_id_range("3-17", &lo, &hi), 0);
	assert_int_equal(lo, 3);
	assert_int_equal(hi, 17);
	assert_int_equal(dxlt_parse_id_range("5", &lo, &hi), 0);
	assert_int_equal(hi, 5);
	assert_int_equal(dxlt_parse_id_range("0-254", &lo, &hi), -1);
	assert_int_equal(dxlt_parse_id_range("-4", &lo, &hi), -1);
	assert_int_equal(dxlt_parse_id("254", true, &id), 0);
	assert_int_equal(dxlt_parse_id("254", false, &id), -1);
	assert_int_equal(dxlt_parse_id("0x10", false, &id), 0);
	assert_int_equal(id, 16);
	assert_int_equal(dxlt_parse_id("1x", false, &id), -1);
	/* a leading zero is decimal (num.h), not octal as strtol's base 0 had it */
	assert_int_equal(dxlt_parse_id("010", false, &id), 0);
	assert_int_equal(id, 10);
	assert_int_equal(dxlt_parse_id(" 1", false, &id), -1);
	assert_int_equal(dxlt_parse_id("1 ", false, &id), -1);
	assert_int_equal(dxlt_parse_id("", false, &id), -1);
	assert_int_equal(dxlt_parse_id_range("", &lo, &hi), -1);
	assert_int_equal(dxlt_parse_id_range("3-", &lo, &hi), -1);
	assert_int_equal(dxlt_parse_bauds("1000000,57143", bauds, DXLT_MAX_BAUDS, &n), 0);
	assert_int_equal(n, 2);
	assert_int_equal(bauds[1], 57143);
	assert_int_equal(dxlt_parse_bauds("all", bauds, DXLT_MAX_BAUDS, &n), 0);
	assert_int_equal(bauds[0], 1000000);
	assert_true(n >= 6);
	assert_int_equal(dxlt_parse_bauds("1000000,,x", bauds, DXLT_MAX_BAUDS, &n), -1);
}

int main(int argc, char **argv)
{
	if (argc > 1)
		return serve_main(argc, argv);
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(test_fake_answers_manual_vectors, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_ping_and_scan, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_read_raw_and_units, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_write_validates_first, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_no_reply_suggests_baud, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_errbits_exit_code, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_errbits_hint, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_follows_status_level, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_set_id, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_set_baud_then_scan, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_torque_reset_dump, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_setup, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_setup_lowers_latency_timer, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_setup_latency_stuck, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_usage_and_port_errors, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_doctor, setup, teardown),
		cmocka_unit_test(test_arg_parsers),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
