/*
 * test_dxl_fakeservo.c — the `dxl` tool against fake buses on a pty, one per
 * protocol, each with its own independent fake:
 *  - the AX-12's (Protocol 1.0): framed here with its own few lines, not
 *    protocol/dxl.c;
 *  - the X series' (Protocol 2.0): xfake.h's servos (shared with
 *    test_daemon_cycle.c), their own CRC and stuffing, not protocol/dxl2.c,
 *    their control table dxl2_table's defaults, refusing what a real one
 *    refuses.
 * Each fake is checked against its manual's byte vectors first, so a bug
 * shared by our encoder and our parser cannot pass through it unseen, and
 * hears only at its own baud rate, read from the pty as the client set it.
 *
 * What `dxl` must do on either bus is one test body run once per backend
 * (struct backend: the fake, its factory rate, the lines its servos give);
 * what one family alone has (the AX-12's error bits and status levels, the
 * X series' ERR field, reboot, Operating Mode) is tested on its own bus.
 *
 * Two uses of one program:
 *  - without arguments (as the test runner starts it): cmocka tests. The fake
 *    bus serves in a thread and every `dxl` command runs in-process
 *    (dxlt_main) with its output captured.
 *  - `test_dxl_fakeservo --serve LINK --ids 1,2 [--errbits ID:BITS]`: serve
 *    an AX-12 fake bus on a pty whose slave LINK points to, print "ready
 *    LINK", run until SIGTERM. tests/integration/dxl_*.sh run the real `dxl`
 *    binary against it. (A test-only program must live here: the tests/unit
 *    files not named test_* are linked into every unit test.)
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

#include "dxl2.h"
#include "dxl2_table.h"
#include "dxl_table.h"
#include "../../tools/dxl/dxlt.h"
#include "port.h"
#include "ptypeer.h"
#include "xfake.h"

/* ---- the pty both fakes serve on ----------------------------------------------- */

/* The line rate the client set on the pty, read on the fake's own slave fd. */
static long line_baud(int slave)
{
	struct termios2 tio;

	if (ioctl(slave, TCGETS2, &tio) != 0)
		return -1;
	return (long)tio.c_ospeed;
}

/* A pty, and our own slave fd: it keeps the pty alive between clients and
 * tells us the baud rate they set. */
static int pty_pair(int *master, int *slave)
{
	struct ptypeer pty;

	if (ptypeer_open(&pty) != 0)
		return -1;
	*master = pty.master;
	*slave = open(pty.slave_path, O_RDWR | O_NOCTTY);
	return *slave < 0 ? -1 : 0;
}

/* ---- the AX-12 fake (Protocol 1.0) ------------------------------------------------------------- */

#define AX_MAX_SERVOS 8
#define AX_TABLE 50
#define AX_FIRMWARE 24
#define AX_RX_MAX 1024

struct ax_servo {
	uint8_t mem[AX_TABLE];
	uint8_t errbits;             /* forced into every status (fault injection) */
};

struct ax_bus {
	int master, slave;
	struct ax_servo servo[AX_MAX_SERVOS];
	size_t nservos;
	uint8_t rx[AX_RX_MAX];
	size_t have;
	atomic_bool stop;
	atomic_uint packets;         /* well-formed instruction packets heard */
	atomic_uint writes;          /* WRITE instructions executed */
	atomic_uint bad_checksums;
};

static void ax_servo_defaults(struct ax_servo *s, uint8_t id)
{
	memset(s->mem, 0, sizeof s->mem);
	for (size_t i = 0; i < dxl_ax12_nregs; i++) {
		const struct dxl_reg *r = &dxl_ax12_regs[i];
		uint16_t v = r->def >= 0 ? (uint16_t)r->def : 0;
		s->mem[r->addr] = (uint8_t)(v & 0xFF);
		if (r->size == 2)
			s->mem[r->addr + 1] = (uint8_t)(v >> 8);
	}
	s->mem[DXL_AX_FIRMWARE_VERSION] = AX_FIRMWARE;
	s->mem[DXL_AX_ID] = id;
	s->mem[DXL_AX_PRESENT_POSITION] = 0x00; /* 512: centre */
	s->mem[DXL_AX_PRESENT_POSITION + 1] = 0x02;
	s->mem[DXL_AX_GOAL_POSITION] = 0x00;
	s->mem[DXL_AX_GOAL_POSITION + 1] = 0x02;
	s->mem[DXL_AX_PRESENT_VOLTAGE] = 120;
	s->mem[DXL_AX_PRESENT_TEMPERATURE] = 32; /* the manual's READ example answers 32 °C */
}


static bool ax_hears(const struct ax_servo *s, long line)
{
	long own = 2000000L / (s->mem[DXL_AX_BAUD_RATE] + 1);
	long diff = own > line ? own - line : line - own;
	return line > 0 && diff * 100 <= own * 3; /* within 3 %: a UART's tolerance */
}

static void ax_send_status(struct ax_bus *fb, const struct ax_servo *s, uint8_t err,
                             const uint8_t *params, size_t n)
{
	uint8_t pkt[AX_TABLE + 6];
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

static void ax_execute(struct ax_bus *fb, struct ax_servo *s, uint8_t instr,
                         const uint8_t *p, size_t n, bool broadcast)
{
	uint8_t level = s->mem[DXL_AX_STATUS_RETURN_LEVEL];

	switch (instr) {
	case 0x01: /* PING: always answered */
		if (!broadcast)
			ax_send_status(fb, s, 0, NULL, 0);
		break;
	case 0x02: /* READ addr len */
		if (n != 2 || p[0] + p[1] > AX_TABLE || p[1] == 0) {
			if (!broadcast && level >= 1)
				ax_send_status(fb, s, DXL_ERRBIT_RANGE, NULL, 0);
		} else if (!broadcast && level >= 1) {
			ax_send_status(fb, s, 0, &s->mem[p[0]], p[1]);
		}
		break;
	case 0x03: /* WRITE addr data... */
		if (n < 2 || p[0] + (n - 1) > AX_TABLE) {
			if (!broadcast && level >= 2)
				ax_send_status(fb, s, DXL_ERRBIT_RANGE, NULL, 0);
			break;
		}
		atomic_fetch_add(&fb->writes, 1);
		memcpy(&s->mem[p[0]], p + 1, n - 1);
		if (!broadcast && s->mem[DXL_AX_STATUS_RETURN_LEVEL] >= 2)
			ax_send_status(fb, s, 0, NULL, 0);
		break;
	case 0x06: /* FACTORY_RESET */
		ax_servo_defaults(s, 1);
		break;
	default:
		if (!broadcast && level >= 2)
			ax_send_status(fb, s, DXL_ERRBIT_INSTRUCTION, NULL, 0);
		break;
	}
}

static void ax_dispatch(struct ax_bus *fb, const uint8_t *pkt)
{
	uint8_t id = pkt[2], len = pkt[3], instr = pkt[4];
	long line = line_baud(fb->slave);

	atomic_fetch_add(&fb->packets, 1);
	for (size_t i = 0; i < fb->nservos; i++) {
		struct ax_servo *s = &fb->servo[i];
		if ((id == s->mem[DXL_AX_ID] || id == 0xFE) && ax_hears(s, line)) {
			ax_execute(fb, s, instr, pkt + 5, (size_t)len - 2, id == 0xFE);
			if (id != 0xFE)
				break;
		}
	}
}

/* Frame what is buffered: FF FF ID LEN INSTR P.. CHK; on any doubt drop a byte. */
static void ax_parse(struct ax_bus *fb)
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
		ax_dispatch(fb, b);
		off += total;
	}
	memmove(fb->rx, fb->rx + off, fb->have - off);
	fb->have -= off;
}

static int ax_open(struct ax_bus *fb, const uint8_t *ids, size_t n)
{
	memset(fb, 0, sizeof *fb);
	if (pty_pair(&fb->master, &fb->slave) != 0)
		return -1;
	for (size_t i = 0; i < n && i < AX_MAX_SERVOS; i++)
		ax_servo_defaults(&fb->servo[fb->nservos++], ids[i]);
	return 0;
}

static const char *ax_slave_path(const struct ax_bus *fb)
{
	return ptsname(fb->master);
}

static void ax_serve(struct ax_bus *fb)
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
		ax_parse(fb);
		if (fb->have == sizeof fb->rx)
			fb->have = 0; /* a full buffer of garbage: start over */
	}
}

static void ax_close(struct ax_bus *fb)
{
	close(fb->slave);
	close(fb->master);
}

/* ---- serve mode ------------------------------------------------------------------ */

static struct ax_bus serve_bus;

static void serve_stop(int sig)
{
	(void)sig;
	atomic_store(&serve_bus.stop, true);
}

static int serve_main(int argc, char **argv)
{
	const char *link = NULL;
	uint8_t ids[AX_MAX_SERVOS] = { 1 };
	size_t nids = 1;
	uint8_t fault_id = 0, fault_bits = 0;

	for (int i = 1; i + 1 < argc; i += 2) {
		if (strcmp(argv[i], "--serve") == 0) {
			link = argv[i + 1];
		} else if (strcmp(argv[i], "--ids") == 0) {
			char *save = NULL;
			nids = 0;
			for (char *t = strtok_r(argv[i + 1], ",", &save); t && nids < AX_MAX_SERVOS;
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
	if (ax_open(&serve_bus, ids, nids) != 0) {
		perror("fakeservo: pty");
		return 1;
	}
	for (size_t i = 0; i < serve_bus.nservos; i++)
		if (serve_bus.servo[i].mem[DXL_AX_ID] == fault_id)
			serve_bus.servo[i].errbits = fault_bits;
	unlink(link);
	if (symlink(ax_slave_path(&serve_bus), link) != 0) {
		perror("fakeservo: symlink");
		return 1;
	}
	signal(SIGTERM, serve_stop);
	signal(SIGINT, serve_stop);
	printf("ready %s\n", link);
	fflush(stdout);
	ax_serve(&serve_bus);
	unlink(link);
	ax_close(&serve_bus);
	return 0;
}

/* ---- the X fake: xfake.h's servos (Protocol 2.0) on a pty ------------------------------------- */

struct x_bus {
	struct xfake x;
	int master, slave;
	atomic_bool stop;
};


/* A status packet onto the pty, after the servo's return delay. */
static void x_emit(void *ctx, const uint8_t *pkt, size_t k, unsigned delay_us)
{
	struct x_bus *fb = ctx;
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

static int x_open(struct x_bus *fb, const uint8_t *ids, const uint16_t *models, size_t n)
{
	memset(fb, 0, sizeof *fb);
	if (pty_pair(&fb->master, &fb->slave) != 0)
		return -1;
	fb->x.emit = x_emit;
	fb->x.ctx = fb;
	for (size_t i = 0; i < n && i < XFAKE_MAX_SERVOS; i++)
		xfake_servo_defaults(&fb->x.servo[fb->x.nservos++], ids[i], models[i]);
	return 0;
}

static void *x_serve(void *arg)
{
	struct x_bus *fb = arg;
	uint8_t buf[XFAKE_RX_MAX];
	while (!atomic_load(&fb->stop)) {
		struct pollfd pfd = { .fd = fb->master, .events = POLLIN };
		if (poll(&pfd, 1, 20) <= 0 || !(pfd.revents & POLLIN))
			continue;
		ssize_t n = read(fb->master, buf, sizeof buf - fb->x.have);
		if (n <= 0)
			continue;
		/* it hears only at its own rate, as the client set the line */
		fb->x.line_baud = line_baud(fb->slave);
		if (fb->x.line_baud <= 0)
			fb->x.line_baud = -1;
		xfake_feed(&fb->x, buf, (size_t)n);
	}
	return NULL;
}

/* ---- the fixture: one backend's fake serving in a thread ----------------------------- */

struct fixture;
struct backend {
	const char *name;
	int (*open)(struct fixture *f);          /* its fake on a pty, f->path its slave */
	void *(*serve)(void *f);
	void (*close)(struct fixture *f);
	char *baud;                              /* the servos' factory rate, given to every run */
	char *protocol;                          /* --protocol's value for it */
	char *other_protocol, *other_label;      /* the protocol its servos do not speak */
	/* the control table's bytes of servo id, and what its PING and scan say */
	uint8_t *(*mem)(struct fixture *f, uint8_t id);
	const struct dxl2_model *(*model)(uint8_t id);
	const char *ping_model[2];               /* IDs 1, 2 */
	const char *scan_line[2];
	const char *setup_line;                  /* setup's price of the cycle, once at 1 Mbps */
	const char *setup_baud;                  /* what setup says raising the rate (NULL: at 1 Mbps already) */
	unsigned (*writes)(struct fixture *f);   /* WRITEs its servos executed */
};

struct fixture {
	const struct backend *b;
	struct ax_bus ax;
	struct x_bus x;
	pthread_t thread;
	char path[64];
	bool derived_timeout; /* run dxl with its own reply timeout, not TEST_REPLY_TIMEOUT_MS */
	char *out, *err;      /* what the last dxl run printed */
	size_t outlen, errlen;
};

static struct ax_servo *ax_servo(struct fixture *f, uint8_t id)
{
	for (size_t i = 0; i < f->ax.nservos; i++)
		if (f->ax.servo[i].mem[DXL_AX_ID] == id)
			return &f->ax.servo[i];
	return NULL;
}

static struct xfake_servo *x_servo(struct fixture *f, uint8_t id)
{
	for (size_t i = 0; i < f->x.x.nservos; i++)
		if (f->x.x.servo[i].mem[7] == id)
			return &f->x.x.servo[i];
	return NULL;
}

static int ax_fixture_open(struct fixture *f)
{
	const uint8_t ids[] = { 1, 2 };
	if (ax_open(&f->ax, ids, 2) != 0)
		return -1;
	snprintf(f->path, sizeof f->path, "%s", ax_slave_path(&f->ax));
	return 0;
}

static void *ax_fixture_serve(void *arg)
{
	ax_serve(&((struct fixture *)arg)->ax);
	return NULL;
}

static void ax_fixture_close(struct fixture *f)
{
	atomic_store(&f->ax.stop, true);
	pthread_join(f->thread, NULL);
	ax_close(&f->ax);
}

static uint8_t *ax_mem(struct fixture *f, uint8_t id) { return ax_servo(f, id)->mem; }
static const struct dxl2_model *ax_model(uint8_t id) { (void)id; return dxl2_model_find(1, DXL_AX12_MODEL); }
static unsigned ax_writes(struct fixture *f) { return atomic_load(&f->ax.writes); }

/* An XL430-W250 (ID 1) and an XM430-W350 (ID 2): two models on one bus. */
static const uint16_t x_models[] = { DXL2_MODEL_XL430_W250, DXL2_MODEL_XM430_W350 };

static int x_fixture_open(struct fixture *f)
{
	const uint8_t ids[] = { 1, 2 };
	if (x_open(&f->x, ids, x_models, 2) != 0)
		return -1;
	snprintf(f->path, sizeof f->path, "%s", ptsname(f->x.master));
	return 0;
}

static void *x_fixture_serve(void *arg)
{
	return x_serve(&((struct fixture *)arg)->x);
}

static void x_fixture_close(struct fixture *f)
{
	atomic_store(&f->x.stop, true);
	pthread_join(f->thread, NULL);
	close(f->x.slave);
	close(f->x.master);
}

static uint8_t *x_mem(struct fixture *f, uint8_t id) { return x_servo(f, id)->mem; }
static const struct dxl2_model *x_model(uint8_t id) { return dxl2_model_find(2, x_models[id - 1]); }
static unsigned x_writes(struct fixture *f) { return atomic_load(&f->x.x.writes); }

static struct backend ax_backend = {
	.name = "AX-12A", .open = ax_fixture_open, .serve = ax_fixture_serve, .close = ax_fixture_close,
	.baud = NULL, .protocol = "1", .other_protocol = "2", .other_label = "Protocol 2.0",
	.mem = ax_mem, .model = ax_model,
	.ping_model = { "model 12 (AX-12A), firmware 24, Protocol 1.0", "model 12 (AX-12A), firmware 24, Protocol 1.0" },
	.scan_line = { "\n1    12     AX-12A        24        1000000  1.0\n",
	               "\n2    12     AX-12A        24        1000000  1.0\n" },
	/* READ(36, 6) a servo, 2-byte goals: 2 x (8 + 12) + 14 bytes */
	.setup_line = "bus time per cycle for 2 servos at 1000000 bps: 0.54 ms on the wire",
	.writes = ax_writes,
};

static struct backend x_backend = {
	.name = "X series", .open = x_fixture_open, .serve = x_fixture_serve, .close = x_fixture_close,
	.baud = "57600", .protocol = "2", .other_protocol = "1", .other_label = "Protocol 1.0",
	.mem = x_mem, .model = x_model,
	.ping_model = { "model 1060 (XL430-W250), firmware 46, Protocol 2.0",
	                "model 1020 (XM430-W350), firmware 46, Protocol 2.0" },
	.scan_line = { "\n1    1060   XL430-W250    46        57600    2.0\n",
	               "\n2    1020   XM430-W350    46        57600    2.0\n" },
	/* at 1 Mbps, two servos, 10 bytes each (undulated's X cycle):
	 * (14 + 2) + 2 x (11 + 10) + (14 + 10) = 82 bytes */
	.setup_line = "bus time per cycle for 2 servos at 1000000 bps: 0.82 ms on the wire",
	.setup_baud = "baud_rate 57600 -> 1000000 bps",
	.writes = x_writes,
};

static int setup_backend(void **state, const struct backend *b)
{
	struct fixture *f = calloc(1, sizeof *f);

	assert_non_null(f);
	f->b = b;
	assert_int_equal(b->open(f), 0);
	assert_int_equal(pthread_create(&f->thread, NULL, b->serve, f), 0);
	*state = f;
	return 0;
}

static int setup(void **state) { return setup_backend(state, &ax_backend); }
static int setup_x(void **state) { return setup_backend(state, &x_backend); }
/* the shared bodies: the backend comes as the prestate */
static int setup_any(void **state) { return setup_backend(state, *state); }

static int teardown(void **state)
{
	struct fixture *f = *state;

	f->b->close(f);
	free(f->out);
	free(f->err);
	free(f);
	return 0;
}

/* The fakes answer from a thread that a loaded test machine may not schedule
 * within the tool's 5 ms of slack: the tests give every reply this long,
 * except where the derived timeout itself is under test. */
#define TEST_REPLY_TIMEOUT_MS "100"

/* Run `dxl --port <fake> [--baud <its factory rate>] ARGS...` in-process;
 * returns the exit code, output in f->out / f->err. */
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
	argv[argc++] = (char *)"dxl";
	argv[argc++] = (char *)"--port";
	argv[argc++] = f->path;
	if (!f->derived_timeout) {
		argv[argc++] = (char *)"--timeout-ms";
		argv[argc++] = (char *)TEST_REPLY_TIMEOUT_MS;
	}
	if (f->b->baud != NULL) {
		argv[argc++] = (char *)"--baud";
		argv[argc++] = f->b->baud;
	}
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

/* A register of servo id's by name, through its model's table. */
static uint8_t *reg8(struct fixture *f, uint8_t id, const char *name)
{
	const struct dxl2_reg *r = dxl2_reg_lookup(f->b->model(id), name);
	assert_non_null(r);
	return &f->b->mem(f, id)[r->addr];
}

/* ---- the AX-12 fake against the manual ---- */

static void test_ax_fake_answers_manual_vectors(void **state)
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
	f->ax.servo[0].mem[DXL_AX_RETURN_DELAY_TIME] = 0;
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
	assert_int_equal(dxl_get_u16(&f->ax.servo[0].mem[DXL_AX_GOAL_POSITION]), 512);
	port_close(p);
}

/* ---- dxl on either bus: one body, run once per backend ------------------------------- */

/* PING names the model, scan lists exactly the servos (both protocols at the
 * rate without --protocol, each line saying which), an ID range keeps to it,
 * the other protocol alone finds nothing, another rate neither. */
static void test_ping_and_scan(void **state)
{
	struct fixture *f = *state;
	const struct backend *b = f->b;
	char line[64];

	for (uint8_t id = 1; id <= 2; id++) {
		char arg[4];
		snprintf(arg, sizeof arg, "%u", id);
		assert_int_equal(run_dxl(f, "--protocol", b->protocol, "ping", arg, NULL), 0);
		snprintf(line, sizeof line, "ID %u answered in ", id);
		assert_non_null(strstr(f->out, line));
		assert_non_null(strstr(f->out, b->ping_model[id - 1]));
	}
	assert_int_equal(run_dxl(f, "scan", "--ids", "0-5", NULL), 0);
	/* header + exactly the two servos, with model, firmware, baud, protocol */
	assert_non_null(strstr(f->out, "PROTOCOL\n"));
	assert_non_null(strstr(f->out, b->scan_line[0]));
	assert_non_null(strstr(f->out, b->scan_line[1]));
	assert_null(strstr(f->out, "\n3 "));
	snprintf(line, sizeof line, " %s.0\n", b->other_protocol);
	assert_null(strstr(f->out, line));
	assert_string_equal(f->err, "");
	assert_int_equal(run_dxl(f, "scan", "--protocol", b->protocol, "--ids", "2-2", NULL), 0);
	assert_null(strstr(f->out, "\n1 "));
	assert_non_null(strstr(f->out, b->scan_line[1]));
	assert_int_equal(run_dxl(f, "--protocol", b->other_protocol, "scan", "--ids", "0-3", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "no servo answered"));
	assert_non_null(strstr(f->err, b->other_label));
	assert_int_equal(run_dxl(f, "--protocol", b->protocol, "--baud", "115200", "ping", "1", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "no reply from ID 1 at 115200 bps"));
}

/* setup refuses a servo with torque on unless --yes, then makes every servo
 * ready for 100 Hz (torque off for its EEPROM, return delay 0, status return
 * level 2, the bus at 1 Mbps), prices the cycle, and a second run finds
 * everything done. */
static void test_setup(void **state)
{
	struct fixture *f = *state;
	const struct backend *b = f->b;

	*reg8(f, 1, "torque_enable") = 1;
	assert_int_equal(run_dxl(f, "--protocol", b->protocol, "setup", "1", "2", NULL), DXLT_EXIT_REFUSED);
	assert_non_null(strstr(f->err, "ID 1 has torque on"));
	assert_non_null(strstr(f->err, "add --yes to turn it off first"));
	assert_int_equal(*reg8(f, 1, "torque_enable"), 1);
	assert_int_equal(*reg8(f, 1, "return_delay_time"), 250);
	assert_int_equal(*reg8(f, 2, "return_delay_time"), 0);   /* the others are done */
	*reg8(f, 1, "status_return_level") = 1;                  /* its WRITEs unanswered: read back */
	assert_int_equal(run_dxl(f, "--protocol", b->protocol, "setup", "1", "2", "--yes", NULL), 0);
	assert_non_null(strstr(f->out, "ID 1: torque_enable set to 0"));
	assert_non_null(strstr(f->out, "ID 1: return_delay_time set to 0"));
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(*reg8(f, id, "torque_enable"), 0);
		assert_int_equal(*reg8(f, id, "return_delay_time"), 0);
		assert_int_equal(*reg8(f, id, "status_return_level"), 2);
		assert_int_equal(dxl2_baud_from_reg(*reg8(f, id, "baud_rate")) == 1000000 ||
		                 dxl_baud_from_reg(*reg8(f, id, "baud_rate")) == 1000000, 1);
	}
	assert_non_null(strstr(f->out, "adapter: "));
	assert_non_null(strstr(f->out, "no latency timer"));
	assert_non_null(strstr(f->out, b->setup_line));
	assert_true(b->setup_baud != NULL ? strstr(f->out, b->setup_baud) != NULL : strstr(f->out, "baud_rate") == NULL);
	/* a second run at 1 Mbps finds everything done */
	assert_int_equal(run_dxl(f, "--protocol", b->protocol, "--baud", "1000000", "setup", "1", "2", NULL), 0);
	assert_non_null(strstr(f->out, "ID 2: return_delay_time already 0"));
	assert_null(strstr(f->out, "baud_rate"));
}

/* Bad usage of every kind: exit 2, nothing written. */
static void test_usage(void **state)
{
	struct fixture *f = *state;
	const struct backend *b = f->b;

	assert_int_equal(run_dxl(f, "--protocol", "3", "ping", "1", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "bad protocol (want 1 or 2) for --protocol '3'"));
	assert_int_equal(run_dxl(f, "--protocol", b->protocol, "--size", "3", "read", "1", "7", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--protocol", b->protocol, "reset", "1", "--keep", "baud", "--yes", NULL),
	                 DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--protocol", b->protocol, "ping", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "--protocol", b->protocol, "torque", "1", "sideways", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(b->writes(f), 0);
}

/* ---- dxl on the AX-12 bus ---- */

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
	assert_int_equal(dxl_get_u16(&ax_servo(f, 1)->mem[DXL_AX_GOAL_POSITION]), 700);
	unsigned writes = atomic_load(&f->ax.writes);
	unsigned packets = atomic_load(&f->ax.packets);
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
	assert_int_equal(atomic_load(&f->ax.writes), writes);
	assert_int_equal(atomic_load(&f->ax.packets), packets);
	assert_int_equal(dxl_get_u16(&ax_servo(f, 1)->mem[DXL_AX_GOAL_POSITION]), 700);
	/* padded values are decimal: 0500 is 500, not octal 320 */
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "0500", NULL), 0);
	assert_int_equal(dxl_get_u16(&ax_servo(f, 1)->mem[DXL_AX_GOAL_POSITION]), 500);
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "0x1f4", NULL), 0);
	assert_int_equal(dxl_get_u16(&ax_servo(f, 1)->mem[DXL_AX_GOAL_POSITION]), 500);
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

	ax_servo(f, 2)->errbits = DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT;
	for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++) {
		char **a = cmds[i].argv;
		int rc = run_dxl(f, a[0], a[1], a[2], a[3], a[4]);
		if (rc != DXLT_EXIT_SERVO || strstr(f->err, "reports error bits 0x24: ") == NULL ||
		    strstr(f->err, "overload") == NULL || strstr(f->err, "overheating") == NULL)
			fail_msg("%s: exit %d, stderr '%s'", cmds[i].what, rc, f->err);
	}
	/* ...and did their work all the same */
	assert_int_equal(dxl_get_u16(&ax_servo(f, 3)->mem[DXL_AX_GOAL_POSITION]), 600);
	assert_int_equal(ax_servo(f, 3)->mem[DXL_AX_TORQUE_ENABLE], 1);
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

	ax_servo(f, 1)->errbits = DXL_ERRBIT_RANGE;
	assert_int_equal(run_dxl(f, "write", "1", "cw_angle_limit", "100", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "error bits 0x08: range"));
	assert_non_null(strstr(f->err, "torque 1 off"));
	ax_servo(f, 1)->errbits = DXL_ERRBIT_ANGLE_LIMIT;
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "1000", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "angle limits"));
}

/* The servo's status return level decides what it answers: a write that took
 * effect is not "no reply". Level 1 is read back; level 0 is said unconfirmed. */
static void test_dxl_follows_status_level(void **state)
{
	struct fixture *f = *state;

	ax_servo(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL] = 1;
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "700", NULL), 0);
	assert_int_equal(dxl_get_u16(&ax_servo(f, 1)->mem[DXL_AX_GOAL_POSITION]), 700);
	assert_non_null(strstr(f->out, "read back"));
	assert_int_equal(run_dxl(f, "torque", "1", "on", NULL), 0);
	assert_int_equal(ax_servo(f, 1)->mem[DXL_AX_TORQUE_ENABLE], 1);

	ax_servo(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL] = 0;
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "300", NULL), 0);
	assert_int_equal(dxl_get_u16(&ax_servo(f, 1)->mem[DXL_AX_GOAL_POSITION]), 300);
	assert_non_null(strstr(f->out, "not confirmed"));
	assert_int_equal(run_dxl(f, "read", "1", "goal_position", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "answers PING but not READ: status return level 0"));
	assert_int_equal(run_dxl(f, "ping", "1", NULL), 0);
	assert_non_null(strstr(f->out, "PING only"));
	/* raising the level back from 0, then writing with replies again */
	assert_int_equal(run_dxl(f, "write", "1", "status_return_level", "2", NULL), 0);
	assert_int_equal(ax_servo(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL], 2);
	assert_int_equal(run_dxl(f, "write", "1", "goal_position", "400", NULL), 0);
	/* answered, and read back all the same: the output says what it holds */
	assert_string_equal(f->out, "ID 1: goal_position = 400 (read back)\n");
	/* ID and baud go through set-id / set-baud, which look for the answer
	 * where the servo went */
	assert_int_equal(run_dxl(f, "write", "1", "id", "6", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "set-id OLD NEW"));
	assert_int_equal(run_dxl(f, "write", "1", "baud_rate", "34", NULL), DXLT_EXIT_USAGE);
	assert_non_null(ax_servo(f, 1));
	/* setup lowering the level: no false "no reply" (the write is read back) */
	assert_int_equal(run_dxl(f, "setup", "1", "--status-level", "1", "--yes", NULL), 0);
	assert_int_equal(ax_servo(f, 1)->mem[DXL_AX_STATUS_RETURN_LEVEL], 1);
	/* a servo absent at any level is still "no reply" */
	assert_int_equal(run_dxl(f, "write", "4", "goal_position", "400", NULL), DXLT_EXIT_BUS);
	assert_non_null(strstr(f->err, "no reply from ID 4"));
}

static void test_dxl_set_id(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "set-id", "1", "2", NULL), DXLT_EXIT_REFUSED);
	assert_non_null(strstr(f->err, "ID 2 is already taken"));
	assert_non_null(ax_servo(f, 1));
	assert_int_equal(run_dxl(f, "set-id", "1", "7", NULL), 0);
	assert_non_null(ax_servo(f, 7));
	assert_null(ax_servo(f, 1));
	assert_int_equal(run_dxl(f, "set-id", "1", "254", NULL), DXLT_EXIT_USAGE);
}

static void test_dxl_set_baud_then_scan(void **state)
{
	struct fixture *f = *state;

	int rc = run_dxl(f, "set-baud", "2", "57600", NULL);
	if (rc != 0)
		fail_msg("set-baud: exit %d: %s", rc, f->err);
	assert_int_equal(ax_servo(f, 2)->mem[DXL_AX_BAUD_RATE], 34);
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
	assert_int_equal(ax_servo(f, 2)->mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(run_dxl(f, "torque", "2", "sideways", NULL), DXLT_EXIT_USAGE);
	assert_int_equal(run_dxl(f, "reset", "2", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "--yes"));
	assert_int_equal(ax_servo(f, 2)->mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(run_dxl(f, "dump", "2", NULL), 0);
	assert_non_null(strstr(f->out, "torque_enable"));
	assert_non_null(strstr(f->out, "present_temperature"));
	assert_non_null(strstr(f->out, "32 "));
	/* ID 1 is taken by the other servo: reset 2 makes a clash the tool reports */
	ax_servo(f, 1)->mem[DXL_AX_ID] = 5;
	assert_int_equal(run_dxl(f, "reset", "2", "--yes", NULL), 0);
	assert_non_null(ax_servo(f, 1));
	assert_int_equal(ax_servo(f, 1)->mem[DXL_AX_TORQUE_ENABLE], 0);
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
	assert_int_equal(ax_servo(f, 1)->mem[DXL_AX_RETURN_DELAY_TIME], 0); /* servos done */
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
	unsigned packets = atomic_load(&f->ax.packets);
	assert_int_equal(run_dxl(f, "--rs485", "rts-after-send", "ping", "1", NULL), DXLT_EXIT_PORT);
	assert_non_null(strstr(f->err, "cannot switch "));
	assert_non_null(strstr(f->err, f->path));
	assert_non_null(strstr(f->err, "to RS-485 mode (TIOCSRS485): Inappropriate ioctl for device (errno 25)"));
	assert_int_equal(atomic_load(&f->ax.packets), packets);
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
	ax_servo(f, 2)->errbits = DXL_ERRBIT_OVERLOAD;
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

/* ---- the fake against the manual --------------------------------------------- */

static size_t exchange(struct port *p, const uint8_t *req, size_t n, uint8_t *got, size_t want)
{
	size_t have = 0;
	assert_int_equal(port_write(p, req, n), DXL_OK);
	while (have < want && port_wait(p, 1000000) == 1)
		have += (size_t)port_read(p, got + have, want - have);
	return have;
}

static void test_x_fake_answers_manual_vectors(void **state)
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
	struct xfake_servo *s = x_servo(f, 1);

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

/* Every rate either protocol knows: one servo moved to 1 Mbps is found there. */
static void test_x_scan_all_bauds(void **state)
{
	struct fixture *f = *state;

	x_servo(f, 2)->mem[8] = 3;   /* 1 Mbps */
	assert_int_equal(run_dxl(f, "scan", "--protocol", "2", "--bauds", "all", "--ids", "0-5", NULL), 0);
	assert_non_null(strstr(f->out, "\n1    1060   XL430-W250    46        57600    2.0\n"));
	assert_non_null(strstr(f->out, "\n2    1020   XM430-W350    46        1000000  2.0\n"));
	/* an explicit list: only the rates the X series has */
	assert_int_equal(run_dxl(f, "scan", "--protocol", "2", "--bauds", "1000000,400000", NULL), 0);
	assert_non_null(strstr(f->out, "1000000  2.0\n"));
}

static void test_x_read_by_name(void **state)
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

/* The indirect areas by name (protocol/dxl2_table.c's rows): the factory map,
 * a slot pointed at Present Temperature, read through its data byte. */
static void test_x_indirect_by_name(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "indirect_address_1", NULL), 0);
	assert_string_equal(f->out, "224\n");
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "indirect_address_29", NULL), 0);
	assert_string_equal(f->out, "634\n");
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "indirect_address_1", "146", NULL), 0);
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "indirect_data_1", NULL), 0);
	assert_string_equal(f->out, "36\n");
	/* outside 64..661: refused before anything is sent */
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "indirect_address_2", "63", NULL), DXLT_EXIT_USAGE);
}

static void test_x_write_checks_first(void **state)
{
	struct fixture *f = *state;
	struct xfake_servo *s = x_servo(f, 1);

	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "goal_position", "3000", NULL), 0);
	assert_int_equal(xfake_get(s->mem, 116, 4), 3000);
	unsigned writes = atomic_load(&f->x.x.writes);
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
	assert_int_equal(atomic_load(&f->x.x.writes), writes);
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
static void test_x_unknown_model(void **state)
{
	struct fixture *f = *state;
	struct xfake_servo *s = x_servo(f, 1);

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

static void test_x_dump(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "--protocol", "2", "dump", "2", NULL), 0);
	assert_non_null(strstr(f->out, "XM430-W350 (model 1020), firmware 46\n"));
	assert_non_null(strstr(f->out, "\n38   current_limit"));
	assert_non_null(strstr(f->out, "\n146  present_temperature"));
	assert_non_null(strstr(f->out, "[EEPROM]"));
}

/* The ERR field is named, the alert explained; the value still comes out. */
static void test_x_err_field(void **state)
{
	struct fixture *f = *state;

	x_servo(f, 2)->err = 0x80;
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "2", "present_temperature", NULL), DXLT_EXIT_SERVO);
	assert_string_equal(f->out, "36\n");
	assert_non_null(strstr(f->err, "ID 2 reports error 0x80: alert (the alert bit: a hardware error"));
	assert_non_null(strstr(f->err, "reboot"));
	x_servo(f, 2)->err = 0;
	/* the servo's own refusal (access error: EEPROM with torque on, behind
	 * the tool's back) is named too */
	assert_int_equal(run_dxl(f, "--protocol", "2", "read", "1", "led", NULL), 0);
	assert_string_equal(f->err, "");
	/* a refused write's error number gets its remedy, as 1.0's bits do
	 * (the hints were 1.0's alone; the error fields of both protocols are
	 * one table of refusals now) */
	x_servo(f, 1)->err = DXL2_ERRNUM_ACCESS;
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "return_delay_time", "0", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "ID 1 reports error 0x07: access"));
	assert_non_null(strstr(f->err, "refuses EEPROM writes (return_delay_time)"));
	assert_non_null(strstr(f->err, "dxl --protocol 2 --port "));
	x_servo(f, 1)->err = DXL2_ERRNUM_DATA_LIMIT;
	assert_int_equal(run_dxl(f, "--protocol", "2", "write", "1", "goal_position", "2100", NULL), DXLT_EXIT_SERVO);
	assert_non_null(strstr(f->err, "outside the servo's position limits"));
	assert_non_null(strstr(f->err, "read 1 min_position_limit (and max_position_limit)"));
	x_servo(f, 1)->err = 0;
}

static void test_x_set_id_baud_reset_reboot(void **state)
{
	struct fixture *f = *state;

	assert_int_equal(run_dxl(f, "--protocol", "2", "set-id", "1", "2", NULL), DXLT_EXIT_REFUSED);
	assert_non_null(strstr(f->err, "ID 2 is already taken"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "set-id", "1", "7", NULL), 0);
	assert_non_null(x_servo(f, 7));
	x_servo(f, 7)->mem[64] = 1;
	assert_int_equal(run_dxl(f, "--protocol", "2", "set-id", "7", "8", NULL), DXLT_EXIT_REFUSED);
	x_servo(f, 7)->mem[64] = 0;
	assert_int_equal(run_dxl(f, "--protocol", "2", "set-baud", "7", "1000000", NULL), 0);
	assert_int_equal(x_servo(f, 7)->mem[8], 3);
	assert_non_null(strstr(f->out, "now at 1000000 bps (register value 3)"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "set-baud", "7", "500000", NULL), DXLT_EXIT_USAGE);
	/* reset keeping the ID: back at 57600 under the same ID */
	assert_int_equal(run_dxl(f, "--protocol", "2", "--baud", "1000000", "reset", "7", NULL), DXLT_EXIT_USAGE);
	assert_non_null(strstr(f->err, "--yes"));
	assert_int_equal(run_dxl(f, "--protocol", "2", "--baud", "1000000", "reset", "7", "--yes", "--keep", "id", NULL), 0);
	assert_non_null(strstr(f->out, "now ID 7 at 57600 bps"));
	assert_int_equal(x_servo(f, 7)->mem[8], 1);
	/* a full reset: ID 1 */
	assert_int_equal(run_dxl(f, "--protocol", "2", "reset", "7", "--yes", NULL), 0);
	assert_non_null(x_servo(f, 1));
	/* reboot: torque off, the hardware error cleared */
	struct xfake_servo *s = x_servo(f, 2);
	s->mem[64] = 1;
	s->mem[70] = DXL2_HWERR_OVERLOAD;
	unsigned reboots = atomic_load(&f->x.x.reboots);
	assert_int_equal(run_dxl(f, "--protocol", "2", "reboot", "2", NULL), 0);
	assert_non_null(strstr(f->out, "ID 2 rebooted"));
	assert_int_equal(atomic_load(&f->x.x.reboots), reboots + 1);
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

static void test_x_doctor(void **state)
{
	struct fixture *f = *state;

	x_servo(f, 2)->mem[70] = DXL2_HWERR_OVERLOAD;
	xfake_put(x_servo(f, 2)->mem, 144, 95, 2);     /* 9.5 V: below the XM430's 10 V */
	x_servo(f, 1)->mem[98] = 0xFF;                /* its watchdog fired */
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

int main(int argc, char **argv)
{
	if (argc > 1)
		return serve_main(argc, argv);
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(test_ax_fake_answers_manual_vectors, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_read_raw_and_units, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_write_validates_first, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_no_reply_suggests_baud, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_errbits_exit_code, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_errbits_hint, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_follows_status_level, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_set_id, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_set_baud_then_scan, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_torque_reset_dump, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_setup_lowers_latency_timer, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_setup_latency_stuck, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_usage_and_port_errors, setup, teardown),
		cmocka_unit_test_setup_teardown(test_dxl_doctor, setup, teardown),
		cmocka_unit_test(test_arg_parsers),
		cmocka_unit_test_setup_teardown(test_x_fake_answers_manual_vectors, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_scan_all_bauds, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_read_by_name, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_indirect_by_name, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_write_checks_first, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_unknown_model, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_dump, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_err_field, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_set_id_baud_reset_reboot, setup_x, teardown),
		cmocka_unit_test_setup_teardown(test_x_doctor, setup_x, teardown),
		cmocka_unit_test_prestate_setup_teardown(test_ping_and_scan, setup_any, teardown, &ax_backend),
		cmocka_unit_test_prestate_setup_teardown(test_ping_and_scan, setup_any, teardown, &x_backend),
		cmocka_unit_test_prestate_setup_teardown(test_setup, setup_any, teardown, &ax_backend),
		cmocka_unit_test_prestate_setup_teardown(test_setup, setup_any, teardown, &x_backend),
		cmocka_unit_test_prestate_setup_teardown(test_usage, setup_any, teardown, &ax_backend),
		cmocka_unit_test_prestate_setup_teardown(test_usage, setup_any, teardown, &x_backend),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
