/*
 * test_protocol_port.c — the serial transport on real pseudo-terminals:
 * raw mode byte-exactness, non-blocking reads, disconnection, baud setting,
 * the FTDI latency-timer logic against a fake sysfs tree, and one owner per
 * bus: a second open of a held pty refused with its holder named, through
 * any path to it, and free again at close; UUCP lock files honoured when
 * their program lives, replaced when stale.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>
#include <cmocka.h>

#include "port.h"
#include "ptypeer.h"
#include "scratch.h"

struct fixture {
	struct ptypeer peer;
	struct port *port;
};

static int setup_pty(void **state)
{
	struct fixture *f = calloc(1, sizeof *f);
	struct port_options opt = { .baud = 1000000 };
	char err[200] = "";

	assert_non_null(f);
	assert_int_equal(ptypeer_open(&f->peer), 0);
	f->port = port_open(f->peer.slave_path, &opt, err, sizeof err);
	if (f->port == NULL)
		fail_msg("port_open(%s): %s", f->peer.slave_path, err);
	*state = f;
	return 0;
}

static int teardown_pty(void **state)
{
	struct fixture *f = *state;

	port_close(f->port);
	ptypeer_close(&f->peer);
	free(f);
	return 0;
}

/* Read exactly n bytes from the port, waiting with port_wait. */
static size_t port_read_all(struct port *p, uint8_t *buf, size_t n, uint32_t timeout_us)
{
	uint64_t end = port_now_us() + timeout_us;
	size_t got = 0;

	while (got < n && port_now_us() < end) {
		int w = port_wait(p, (uint32_t)(end - port_now_us()));
		if (w < 0)
			break;
		long r = port_read(p, buf + got, n - got);
		if (r < 0)
			break;
		got += (size_t)r;
	}
	return got;
}

/* libserialport cannot open a pty: port_open falls back to the termios fd. */
static void test_pty_uses_termios_backend(void **state)
{
	struct fixture *f = *state;
	int flags = fcntl(port_fd(f->port), F_GETFL);

	assert_int_equal(port_backend(f->port), PORT_BACKEND_TERMIOS);
	assert_true(flags >= 0 && (flags & O_NONBLOCK));
	assert_int_equal(port_baud(f->port), 1000000);
	assert_string_equal(port_path(f->port), f->peer.slave_path);
}

/* The bytes a cooked tty mangles (LF, CR, ^C, XON, XOFF), then every value. */
static void test_raw_mode_peer_to_port(void **state)
{
	struct fixture *f = *state;
	const uint8_t special[] = { 0x0A, 0x0D, 0x03, 0x11, 0x13, 0x0D, 0x0A, 0x7F, 0x1A, 0x1C, 0x04, 0x16, 0xFF };
	uint8_t all[256], got[256];

	for (int i = 0; i < 256; i++)
		all[i] = (uint8_t)i;
	assert_int_equal(ptypeer_write(&f->peer, special, sizeof special), 0);
	assert_int_equal(port_read_all(f->port, got, sizeof special, 1000000), sizeof special);
	assert_memory_equal(got, special, sizeof special);
	assert_int_equal(ptypeer_write(&f->peer, all, sizeof all), 0);
	assert_int_equal(port_read_all(f->port, got, sizeof all, 1000000), sizeof all);
	assert_memory_equal(got, all, sizeof all);
	/* Nothing echoed back to the peer (ECHO off). */
	assert_int_equal(ptypeer_read(&f->peer, got, 1, 50), 0);
}

static void test_raw_mode_port_to_peer(void **state)
{
	struct fixture *f = *state;
	const uint8_t special[] = { 0x0A, 0x0D, 0x03, 0x11, 0x13, 0x09 };
	uint8_t all[256], got[512];

	for (int i = 0; i < 256; i++)
		all[i] = (uint8_t)(255 - i);
	assert_int_equal(port_write(f->port, special, sizeof special), DXL_OK);
	assert_int_equal(ptypeer_read(&f->peer, got, sizeof special, 1000), sizeof special);
	assert_memory_equal(got, special, sizeof special);
	assert_int_equal(port_write(f->port, all, sizeof all), DXL_OK);
	assert_int_equal(ptypeer_read(&f->peer, got, sizeof all, 1000), sizeof all);
	assert_memory_equal(got, all, sizeof all);
	/* No extra bytes (OPOST would have turned 0x0A into 0x0D 0x0A). */
	assert_int_equal(ptypeer_read(&f->peer, got, 1, 50), 0);
}

static void test_nonblocking_read_and_wait_timeout(void **state)
{
	struct fixture *f = *state;
	uint8_t b;
	uint64_t t0 = port_now_us();

	assert_int_equal(port_read(f->port, &b, 1), 0);
	assert_true(port_now_us() - t0 < 5000);
	t0 = port_now_us();
	assert_int_equal(port_wait(f->port, 3000), 0);
	uint64_t took = port_now_us() - t0;
	/* The wait honours microseconds: at least what was asked, not 10× it. */
	assert_true(took >= 3000);
	assert_true(took < 20000);
}

static void test_flush_input_discards_stale_bytes(void **state)
{
	struct fixture *f = *state;
	const uint8_t stale[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
	const uint8_t fresh[] = { 0x42 };
	uint8_t got[8];

	assert_int_equal(ptypeer_write(&f->peer, stale, sizeof stale), 0);
	assert_int_equal(port_wait(f->port, 1000000), 1);
	port_flush_input(f->port);
	assert_int_equal(ptypeer_write(&f->peer, fresh, sizeof fresh), 0);
	assert_int_equal(port_read_all(f->port, got, 1, 1000000), 1);
	assert_int_equal(got[0], 0x42);
	assert_int_equal(port_read(f->port, got, sizeof got), 0);
}

/* The simulator exiting closes the master: that must read as an unplugged adapter. */
static void test_peer_hangup_is_disconnected(void **state)
{
	struct fixture *f = *state;
	uint8_t b[4];

	close(f->peer.master);
	f->peer.master = -1;
	int w = port_wait(f->port, 1000000);
	assert_true(w == 1 || w == DXL_E_DISCONNECTED);
	assert_int_equal(port_read(f->port, b, sizeof b), DXL_E_DISCONNECTED);
	assert_int_equal(port_write(f->port, b, 1), DXL_E_DISCONNECTED);
}

static void test_bus_io_drives_the_port(void **state)
{
	struct fixture *f = *state;
	struct bus_io io;
	const uint8_t ping[] = { 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB };
	const uint8_t reply[] = { 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC };
	uint8_t got[8];

	port_bus_io(f->port, &io);
	assert_ptr_equal(io.ctx, f->port);
	assert_non_null(io.flush_input);
	uint64_t a = io.now_us(io.ctx);
	assert_int_equal(io.write(io.ctx, ping, sizeof ping), DXL_OK);
	assert_int_equal(ptypeer_read(&f->peer, got, sizeof ping, 1000), sizeof ping);
	assert_memory_equal(got, ping, sizeof ping);
	assert_int_equal(ptypeer_write(&f->peer, reply, sizeof reply), 0);
	size_t n = 0;
	while (n < sizeof reply && io.wait(io.ctx, 1000000) == 1) {
		long r = io.read(io.ctx, got + n, sizeof got - n);
		assert_true(r >= 0);
		n += (size_t)r;
	}
	assert_int_equal(n, sizeof reply);
	assert_memory_equal(got, reply, sizeof reply);
	assert_true(io.now_us(io.ctx) >= a);
}

static void test_baud_rates(void **state)
{
	struct fixture *f = *state;
	struct termios tio;

	/* A standard rate reads back as its constant... */
	assert_int_equal(port_set_baud(f->port, 57600), DXL_OK);
	assert_int_equal(tcgetattr(port_fd(f->port), &tio), 0);
	assert_int_equal(cfgetospeed(&tio), B57600);
	/* ...and the Dynamixel rates without one (2e6 / (v + 1)) are accepted too. */
	assert_int_equal(port_set_baud(f->port, 117647), DXL_OK);
	assert_int_equal(port_baud(f->port), 117647);
	assert_int_equal(port_set_baud(f->port, 1000000), DXL_OK);
	assert_int_equal(tcgetattr(port_fd(f->port), &tio), 0);
	assert_int_equal(cfgetospeed(&tio), B1000000);
	assert_int_equal(port_set_baud(f->port, 0), DXL_E_ARG);
	/* Raw mode survives a baud change. */
	assert_int_equal(tio.c_lflag & (ICANON | ECHO | ISIG), 0);
	assert_int_equal(tio.c_oflag & OPOST, 0);
}

static void test_open_missing_port(void **state)
{
	(void)state;
	char err[200] = "";
	struct port_options opt = { .baud = 1000000 };

	assert_null(port_open("/dev/nonexistent-undulate-bus", &opt, err, sizeof err));
	assert_non_null(strstr(err, "/dev/nonexistent-undulate-bus"));
	assert_non_null(strstr(err, "No such file"));
	/* A regular file is not a serial port. */
	assert_null(port_open("/dev/null", &opt, err, sizeof err));
	assert_non_null(strstr(err, "/dev/null"));
}

/* ---- one owner per bus ------------------------------------------------------------ */

struct lockdir {
	char dir[64];
	char lck[PORT_LOCKFILE_MAX];    /* LCK.. for the peer's pty in it */
	struct ptypeer peer;
};

/* A lock directory of the test's own ($UNDULATE_LOCK_DIR) and a pty. */
static void lockdir_make(struct lockdir *l)
{
	snprintf(l->dir, sizeof l->dir, "/tmp/test_port_lock.XXXXXX");
	assert_non_null(mkdtemp(l->dir));
	assert_int_equal(setenv("UNDULATE_LOCK_DIR", l->dir, 1), 0);
	assert_int_equal(ptypeer_open(&l->peer), 0);
	/* /dev/pts/3 -> LCK..pts_3, as minicom names it */
	assert_true(strncmp(l->peer.slave_path, "/dev/pts/", 9) == 0);
	snprintf(l->lck, sizeof l->lck, "%s/LCK..pts_%s", l->dir, l->peer.slave_path + 9);
}

static void lockdir_remove(struct lockdir *l)
{
	char alias[128];
	ptypeer_close(&l->peer);
	snprintf(alias, sizeof alias, "%s/alias", l->dir);
	unlink(alias);
	unlink(l->lck);
	assert_int_equal(rmdir(l->dir), 0);   /* nothing else left behind */
	unsetenv("UNDULATE_LOCK_DIR");
}

static void write_lck(const char *path, const char *text)
{
	FILE *fp = fopen(path, "w");
	assert_non_null(fp);
	fputs(text, fp);
	assert_int_equal(fclose(fp), 0);
}

/* A second open of a held port, as a second program's would be (another open
 * file: flock() does not care that it is the same process), is refused
 * before it touches the line, and names the holder from its lock file. */
static void test_second_open_refused(void **state)
{
	(void)state;
	struct lockdir l;
	struct holder h, f;
	char err[300] = "", alias[128];
	lockdir_make(&l);
	struct port_options mine = { .baud = 1000000, .owner = "robot t1" };
	struct port *p = port_open(l.peer.slave_path, &mine, err, sizeof err);
	assert_non_null(p);
	assert_true(holder_read_file(l.lck, &f));
	assert_int_equal(f.pid, getpid());
	assert_string_equal(f.robot, "t1");

	struct port_options other = { .baud = 57600, .holder = &h };
	assert_null(port_open(l.peer.slave_path, &other, err, sizeof err));
	assert_int_equal(h.pid, getpid());
	assert_string_equal(h.detail, "robot t1");
	assert_string_equal(h.robot, "t1");
	char want[200];
	snprintf(want, sizeof want, "cannot open %s: held by %s (pid %ld, robot t1)", l.peer.slave_path, f.program,
	         (long)getpid());
	assert_string_equal(err, want);
	/* the refused open changed nothing: the holder's rate stands */
	struct termios tio;
	assert_int_equal(tcgetattr(port_fd(p), &tio), 0);
	assert_int_equal(cfgetospeed(&tio), B1000000);
	/* any other path to the device meets the same lock */
	snprintf(alias, sizeof alias, "%s/alias", l.dir);
	assert_int_equal(symlink(l.peer.slave_path, alias), 0);
	assert_null(port_open(alias, &other, err, sizeof err));
	assert_non_null(strstr(err, "held by"));
	assert_true(port_holder(alias, &h));
	assert_int_equal(h.pid, getpid());

	/* closed: free again, our lock file gone */
	port_close(p);
	assert_int_equal(access(l.lck, F_OK), -1);
	assert_false(port_holder(alias, &h));
	p = port_open(alias, &other, err, sizeof err);
	assert_non_null(p);
	assert_int_equal(h.pid, 0);   /* not refused: zeroed */
	port_close(p);
	lockdir_remove(&l);
}

/* minicom's lock files: a live program's refuses the port; a dead one's, or
 * one whose pid now runs another program (reused after a kill), is replaced. */
static void test_uucp_lock_files(void **state)
{
	(void)state;
	struct lockdir l;
	struct holder h, f, parent;
	char err[400], text[96];
	lockdir_make(&l);
	struct port_options opt = { .baud = 1000000, .holder = &h, .owner = "command scan" };
	assert_true(holder_from_pid((long)getppid(), &parent));

	/* a live program named in its file: honoured */
	snprintf(text, sizeof text, "%10ld %s someone\n", (long)getppid(), parent.program);
	write_lck(l.lck, text);
	assert_null(port_open(l.peer.slave_path, &opt, err, sizeof err));
	assert_int_equal(h.pid, getppid());
	assert_string_equal(h.program, parent.program);
	char want[PORT_LOCKFILE_MAX + 16];
	snprintf(want, sizeof want, "lock file %s", l.lck);
	assert_string_equal(h.detail, want);
	/* HDB's pid alone: honoured, the program named from /proc */
	snprintf(text, sizeof text, "%10ld\n", (long)getppid());
	write_lck(l.lck, text);
	assert_null(port_open(l.peer.slave_path, &opt, err, sizeof err));
	assert_string_equal(h.program, parent.program);
	assert_non_null(strstr(err, "held by"));

	/* stale: the pid is gone, or runs another program now */
	const char *stale[] = { "%10ld undulated robot r9\n", "%10ld minicom-not-this-one x\n" };
	for (size_t i = 0; i < 2; i++) {
		snprintf(text, sizeof text, stale[i], i == 0 ? scratch_dead_pid() : (long)getppid());
		write_lck(l.lck, text);
		struct port *p = port_open(l.peer.slave_path, &opt, err, sizeof err);
		if (p == NULL)
			fail_msg("stale lock file %zu refused: %s", i, err);
		assert_true(holder_read_file(l.lck, &f));
		assert_int_equal(f.pid, getpid());
		assert_string_equal(f.detail, "command scan");
		port_close(p);
		assert_int_equal(access(l.lck, F_OK), -1);
	}
	/* garbage is not a lock */
	write_lck(l.lck, "not a pid\n");
	struct port *p = port_open(l.peer.slave_path, &opt, err, sizeof err);
	assert_non_null(p);
	port_close(p);
	lockdir_remove(&l);
}

/* A lock directory we cannot write costs the name in a refusal, not the lock. */
static void test_unwritable_lock_dir(void **state)
{
	(void)state;
	struct ptypeer peer;
	struct holder h;
	char err[300];
	assert_int_equal(setenv("UNDULATE_LOCK_DIR", "/nonexistent/undulate-locks", 1), 0);
	assert_int_equal(ptypeer_open(&peer), 0);
	struct port_options opt = { .baud = 1000000, .holder = &h, .owner = "robot t2" };
	struct port *p = port_open(peer.slave_path, &opt, err, sizeof err);
	assert_non_null(p);
	assert_null(port_open(peer.slave_path, &opt, err, sizeof err));
	/* named from /proc instead: this test program, its command line */
	assert_int_equal(h.pid, getpid());
	assert_true(strncmp(h.program, "test_protocol_p", 15) == 0);
	port_close(p);
	ptypeer_close(&peer);
	unsetenv("UNDULATE_LOCK_DIR");
}

/* ---- latency timer against a fake sysfs tree ------------------------------------ */

struct fake_sysfs {
	char root[64];
	char dev[PATH_MAX];     /* fake device node */
	char link[PATH_MAX];    /* symlink to it, as a udev rule would make */
	char timer[PATH_MAX];   /* .../latency_timer */
};

static void fake_write(const char *path, const char *text)
{
	FILE *fp = fopen(path, "w");
	assert_non_null(fp);
	fputs(text, fp);
	fclose(fp);
}

static int read_int_file(const char *path)
{
	FILE *fp = fopen(path, "r");
	int v = -1;
	assert_non_null(fp);
	if (fscanf(fp, "%d", &v) != 1)
		v = -1;
	fclose(fp);
	return v;
}

static void fake_sysfs_make(struct fake_sysfs *s, const char *timer_text)
{
	char dir[256];

	snprintf(s->root, sizeof s->root, "/tmp/undulate-sysfs.XXXXXX");
	assert_non_null(mkdtemp(s->root));
	snprintf(dir, sizeof dir, "%s/bus", s->root);
	assert_int_equal(mkdir(dir, 0755), 0);
	snprintf(dir, sizeof dir, "%s/bus/usb-serial", s->root);
	assert_int_equal(mkdir(dir, 0755), 0);
	snprintf(dir, sizeof dir, "%s/bus/usb-serial/devices", s->root);
	assert_int_equal(mkdir(dir, 0755), 0);
	snprintf(dir, sizeof dir, "%s/bus/usb-serial/devices/ttyUSB7", s->root);
	assert_int_equal(mkdir(dir, 0755), 0);
	snprintf(s->timer, sizeof s->timer, "%s/latency_timer", dir);
	if (timer_text != NULL)
		fake_write(s->timer, timer_text);
	snprintf(s->dev, sizeof s->dev, "%s/ttyUSB7", s->root);
	fake_write(s->dev, "");
	snprintf(s->link, sizeof s->link, "%s/robot-bus", s->root);
	assert_int_equal(symlink(s->dev, s->link), 0);
	setenv("UNDULATE_SYSFS_ROOT", s->root, 1);
}

static void fake_sysfs_remove(struct fake_sysfs *s)
{
	char cmd[PATH_MAX + 16];

	unsetenv("UNDULATE_SYSFS_ROOT");
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", s->root);
	assert_int_equal(system(cmd), 0);
}

static void test_latency_reported_not_lowered(void **state)
{
	(void)state;
	struct fake_sysfs s;
	struct port_latency lat;

	fake_sysfs_make(&s, "16\n");
	port_latency_check(s.link, false, &lat);
	assert_true(lat.known);
	assert_int_equal(lat.timer_ms, 16);
	assert_false(lat.lowered);
	assert_non_null(strstr(lat.note, "ttyUSB7"));
	assert_non_null(strstr(lat.note, "16 ms"));
	assert_int_equal(read_int_file(s.timer), 16);
	fake_sysfs_remove(&s);
}

/* The kernel writes "%d\n"; anything else is no timer we understand. */
static void test_latency_timer_text(void **state)
{
	(void)state;
	static const struct { const char *text; bool known; int ms; } rows[] = {
		{ "16", true, 16 },       /* no newline: still the number */
		{ "2\n", true, 2 },
		{ "16x\n", false, 0 },    /* trailing garbage: not half-read as 16 */
		{ " 16\n", false, 0 },
		{ "\n", false, 0 },
		{ "0\n", false, 0 },      /* outside the timer's 1..255 ms */
		{ "256\n", false, 0 },
		{ "16\n\n", false, 0 },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		struct fake_sysfs s;
		struct port_latency lat;
		fake_sysfs_make(&s, rows[i].text);
		port_latency_check(s.link, false, &lat);
		if (lat.known != rows[i].known || lat.timer_ms != rows[i].ms)
			fail_msg("timer text %zu: known %d ms %d", i, lat.known, lat.timer_ms);
		fake_sysfs_remove(&s);
	}
}

static void test_latency_lowered_through_symlink(void **state)
{
	(void)state;
	struct fake_sysfs s;
	struct port_latency lat;

	fake_sysfs_make(&s, "16\n");
	port_latency_check(s.link, true, &lat);
	assert_true(lat.known);
	assert_true(lat.lowered);
	assert_int_equal(lat.timer_ms, 1);
	assert_int_equal(read_int_file(s.timer), 1);
	assert_non_null(strstr(lat.note, "16 ms to 1 ms"));
	/* Already at 1: nothing to do, nothing claimed. */
	port_latency_check(s.link, true, &lat);
	assert_true(lat.known);
	assert_false(lat.lowered);
	assert_int_equal(lat.timer_ms, 1);
	fake_sysfs_remove(&s);
}

/* A timer that refuses the write: the kernel's read-only cap_last_cap file
 * stands in for a latency_timer without write permission (EACCES even for root). */
static void test_latency_cannot_lower(void **state)
{
	(void)state;
	struct fake_sysfs s;
	struct port_latency lat;
	const char *ro = "/proc/sys/kernel/cap_last_cap";

	if (access(ro, R_OK) != 0)
		skip();
	int expect = read_int_file(ro);
	fake_sysfs_make(&s, NULL);
	assert_int_equal(symlink(ro, s.timer), 0);
	port_latency_check(s.link, true, &lat);
	assert_true(lat.known);
	assert_false(lat.lowered);
	assert_int_equal(lat.timer_ms, expect);
	assert_non_null(strstr(lat.note, "could not be lowered"));
	assert_non_null(strstr(lat.note, "ttyUSB7"));
	fake_sysfs_remove(&s);
}

static void test_latency_not_ftdi(void **state)
{
	struct fixture *f = *state;
	struct port_latency lat;
	struct fake_sysfs s;

	fake_sysfs_make(&s, NULL); /* no latency_timer file at all */
	port_latency_check(s.link, true, &lat);
	assert_false(lat.known);
	assert_false(lat.lowered);
	assert_non_null(strstr(lat.note, "no latency timer"));
	fake_sysfs_remove(&s);
	assert_null(port_get_latency(f->port)); /* not asked for */
	/* A pty, through port_open's own check (the fixture's port let go
	 * first: one owner per bus). */
	port_close(f->port);
	f->port = NULL;
	struct port_options opt = { .baud = 1000000, .low_latency = true };
	char err[200];
	struct port *p = port_open(f->peer.slave_path, &opt, err, sizeof err);
	assert_non_null(p);
	assert_non_null(port_get_latency(p));
	assert_false(port_get_latency(p)->known);
	port_close(p);
}

static void test_adapter_names(void **state)
{
	(void)state;
	struct port_info info[16];

	assert_string_equal(port_adapter_name(0x0403, 0x6014), "U2D2");
	assert_string_equal(port_adapter_name(0x0403, 0x6001), "USB2Dynamixel");
	assert_string_equal(port_adapter_name(0x16d0, 0x06a7), "USB2AX");
	assert_null(port_adapter_name(0x0403, 0x6015));
	assert_null(port_adapter_name(-1, -1));
	int n = port_list(info, 16);
	assert_true(n >= 0);
	for (int i = 0; i < n && i < 16; i++) {
		assert_true(info[i].path[0] != '\0');
		if (info[i].usb_vid < 0)
			assert_null(info[i].adapter);
	}
}

/* A system without sysfs (a container with no /sys) has no ports to list:
 * 0 of them, not an I/O error, and nothing written. */
static void test_list_without_sysfs(void **state)
{
	(void)state;
	char root[64] = "/tmp/undulate-nosysfs.XXXXXX";
	char dir[128];
	struct port_info info[2];

	assert_non_null(mkdtemp(root));
	setenv("UNDULATE_SYSFS_ROOT", root, 1);
	memset(info, 0x5a, sizeof info);
	assert_int_equal(port_list(info, 2), 0);
	assert_int_equal(((unsigned char *)info)[0], 0x5a);
	/* A sysfs without the tty class says the same. */
	snprintf(dir, sizeof dir, "%s/class", root);
	assert_int_equal(mkdir(dir, 0755), 0);
	assert_int_equal(port_list(info, 2), 0);
	/* "tty" that is no directory is no tty class either. */
	snprintf(dir, sizeof dir, "%s/class/tty", root);
	fake_write(dir, "");
	assert_int_equal(port_list(info, 2), 0);
	assert_int_equal(port_list(NULL, 0), 0);
	unsetenv("UNDULATE_SYSFS_ROOT");
	assert_int_equal(unlink(dir), 0);
	snprintf(dir, sizeof dir, "%s/class", root);
	assert_int_equal(rmdir(dir), 0);
	assert_int_equal(rmdir(root), 0);
}

/* RS-485 mode names, as a configuration or `dxl --rs485` spells them. */
static void test_rs485_names(void **state)
{
	(void)state;
	/* ok: the name gives MODE (the parse starts from another mode); a
	 * refusal leaves the mode as it was, MODE */
	const struct {
		const char *text;
		bool ok;
		enum port_rs485 mode;
	} cases[] = {
		{ "rts-on-send", true, PORT_RS485_RTS_ON_SEND },
		{ "rts-after-send", true, PORT_RS485_RTS_AFTER_SEND },
		{ "off", true, PORT_RS485_OFF },
		/* "rts" is the common wiring: transmitter enabled while RTS is high */
		{ "rts", true, PORT_RS485_RTS_ON_SEND },
		{ "RTS", false, PORT_RS485_RTS_AFTER_SEND },
		{ "", false, PORT_RS485_RTS_AFTER_SEND },
		{ "rts-on-send ", false, PORT_RS485_RTS_AFTER_SEND },
		{ "on", false, PORT_RS485_RTS_AFTER_SEND },
		{ NULL, false, PORT_RS485_RTS_AFTER_SEND },
	};
	enum port_rs485 m;
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		m = !cases[i].ok ? cases[i].mode : cases[i].mode == PORT_RS485_OFF ? PORT_RS485_RTS_ON_SEND : PORT_RS485_OFF;
		print_message("'%s'\n", cases[i].text ? cases[i].text : "(null)");
		assert_int_equal(port_rs485_parse(cases[i].text, &m), cases[i].ok);
		assert_int_equal(m, cases[i].mode);
	}
	for (int i = PORT_RS485_OFF; i <= PORT_RS485_RTS_AFTER_SEND; i++) {
		assert_true(port_rs485_parse(port_rs485_name((enum port_rs485)i), &m));
		assert_int_equal(m, i);
	}
}

/* A pty has no RS-485 mode: the kernel refuses TIOCSRS485 (ENOTTY). One line
 * names the port and errno; the port stays usable; "off" asks nothing. */
static void test_rs485_refused_on_pty(void **state)
{
	struct fixture *f = *state;
	char err[512] = "", want[64];
	uint8_t b = 0;

	assert_int_equal(port_set_rs485(f->port, PORT_RS485_OFF, err, sizeof err), DXL_OK);
	assert_string_equal(err, "");
	assert_int_equal(port_set_rs485(f->port, PORT_RS485_RTS_ON_SEND, err, sizeof err), DXL_E_ARG);
	assert_non_null(strstr(err, f->peer.slave_path));
	assert_non_null(strstr(err, "RS-485"));
	assert_non_null(strstr(err, strerror(ENOTTY)));
	snprintf(want, sizeof want, "errno %d", ENOTTY);
	assert_non_null(strstr(err, want));
	assert_null(strchr(err, '\n'));
	assert_int_equal(port_set_rs485(f->port, PORT_RS485_RTS_AFTER_SEND, err, sizeof err), DXL_E_ARG);
	/* a short buffer gets a cut line, never an overflow */
	char tiny[8];
	memset(tiny, 'x', sizeof tiny);
	assert_int_equal(port_set_rs485(f->port, PORT_RS485_RTS_ON_SEND, tiny, sizeof tiny), DXL_E_ARG);
	assert_int_equal(tiny[7], '\0');
	assert_int_equal(port_write(f->port, (const uint8_t *)"\x55", 1), DXL_OK);
	assert_int_equal(ptypeer_read(&f->peer, &b, 1, 1000), 1);
	assert_int_equal(b, 0x55);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup_teardown(test_pty_uses_termios_backend, setup_pty, teardown_pty),
		cmocka_unit_test_setup_teardown(test_raw_mode_peer_to_port, setup_pty, teardown_pty),
		cmocka_unit_test_setup_teardown(test_raw_mode_port_to_peer, setup_pty, teardown_pty),
		cmocka_unit_test_setup_teardown(test_nonblocking_read_and_wait_timeout, setup_pty, teardown_pty),
		cmocka_unit_test_setup_teardown(test_flush_input_discards_stale_bytes, setup_pty, teardown_pty),
		cmocka_unit_test_setup_teardown(test_peer_hangup_is_disconnected, setup_pty, teardown_pty),
		cmocka_unit_test_setup_teardown(test_bus_io_drives_the_port, setup_pty, teardown_pty),
		cmocka_unit_test_setup_teardown(test_baud_rates, setup_pty, teardown_pty),
		cmocka_unit_test(test_open_missing_port),
		cmocka_unit_test(test_second_open_refused),
		cmocka_unit_test(test_uucp_lock_files),
		cmocka_unit_test(test_unwritable_lock_dir),
		cmocka_unit_test(test_latency_reported_not_lowered),
		cmocka_unit_test(test_latency_timer_text),
		cmocka_unit_test(test_latency_lowered_through_symlink),
		cmocka_unit_test(test_latency_cannot_lower),
		cmocka_unit_test_setup_teardown(test_latency_not_ftdi, setup_pty, teardown_pty),
		cmocka_unit_test(test_adapter_names),
		cmocka_unit_test(test_list_without_sysfs),
		cmocka_unit_test(test_rs485_names),
		cmocka_unit_test_setup_teardown(test_rs485_refused_on_pty, setup_pty, teardown_pty),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
