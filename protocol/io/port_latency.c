/*
 * port_latency.c — the FTDI latency timer, the setting that decides whether a
 * 100 Hz loop is possible on a USB adapter.
 *
 * An FTDI chip (USB2Dynamixel, U2D2) holds received bytes until its buffer
 * fills or its latency timer expires: 16 ms by default on Linux. A status
 * packet is a few bytes, so every reply waits the full timer. The driver
 * exposes it as /sys/bus/usb-serial/devices/<tty>/latency_timer (ms, 1..255);
 * writing 1 needs root, so TIOCSSERIAL with ASYNC_LOW_LATENCY — which ftdi_sio
 * turns into a 1 ms timer and which any user who may open the port may set —
 * is the fallback.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <linux/serial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "num.h"
#include "port.h"

/* Range the ftdi_sio driver accepts for latency_timer, in ms. */
#define PORT_LATENCY_MIN_MS 1
#define PORT_LATENCY_MAX_MS 255
/* Room for "<root>/bus/usb-serial/devices/<tty>/latency_timer". */
#define PORT_SYSFS_PATH_MAX 512

/* Notes are cut at the note's size: the tty name leads, so what matters
 * survives. */
__attribute__((format(printf, 2, 3)))
static void port_note(struct port_latency *out, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(out->note, sizeof out->note, fmt, ap);
	va_end(ap);
}

const char *port_sysfs_root(void)
{
	const char *root = getenv("UNDULATE_SYSFS_ROOT");

	return (root != NULL && root[0] != '\0') ? root : "/sys";
}

/* The kernel's name for the tty behind path (symlinks like
 * /dev/serial/by-id/... or /dev/undulate-bus resolved): "ttyUSB0" for
 * sysfs, and for messages the device path below /dev ("pts/3"). */
static int port_tty_name(const char *path, char *name, size_t cap, char *shown, size_t shown_cap)
{
	char real[PATH_MAX];
	const char *base;

	if (realpath(path, real) == NULL)
		return -1;
	base = strrchr(real, '/');
	base = base != NULL ? base + 1 : real;
	if (base[0] == '\0' || strlen(base) >= cap)
		return -1;
	memcpy(name, base, strlen(base) + 1);
	/* shown_cap >= cap, so the base name always fits as a fallback. */
	const char *show = strncmp(real, "/dev/", 5) == 0 && strlen(real + 5) < shown_cap ? real + 5 : base;
	memcpy(shown, show, strlen(show) + 1);
	return 0;
}

/* Read the timer in ms; -1 when the file cannot be read or holds no valid value.
 * The kernel writes "%d\n": one trailing newline is the format, anything
 * else around the number means a file we do not understand. */
static int port_read_timer(const char *file)
{
	char text[16];
	int v;
	ssize_t n;
	int fd = open(file, O_RDONLY | O_CLOEXEC);

	if (fd < 0)
		return -1;
	n = read(fd, text, sizeof text - 1);
	close(fd);
	if (n <= 0)
		return -1;
	text[n] = '\0';
	if (text[n - 1] == '\n')
		text[n - 1] = '\0';
	if (num_parse_int(text, PORT_LATENCY_MIN_MS, PORT_LATENCY_MAX_MS, &v) != NUM_OK)
		return -1;
	return v;
}

/* 0, or the errno of the failed write. */
static int port_write_timer(const char *file)
{
	int fd = open(file, O_WRONLY | O_TRUNC | O_CLOEXEC);
	int e = 0;

	if (fd < 0)
		return errno;
	if (write(fd, "1\n", 2) != 2)
		e = errno != 0 ? errno : EIO;
	if (close(fd) != 0 && e == 0)
		e = errno;
	return e;
}

/* ASYNC_LOW_LATENCY through TIOCSSERIAL; 0 or errno. */
static int port_set_low_latency_flag(int fd)
{
	struct serial_struct ss;

	if (fd < 0)
		return EBADF;
	if (ioctl(fd, TIOCGSERIAL, &ss) != 0)
		return errno;
	ss.flags |= ASYNC_LOW_LATENCY;
	if (ioctl(fd, TIOCSSERIAL, &ss) != 0)
		return errno;
	return 0;
}

static void port_try_lower(const char *tty, const char *file, int fd, struct port_latency *out)
{
	int was = out->timer_ms;
	int werr = port_write_timer(file);
	int serr = 0;
	int now = port_read_timer(file);

	if (now != 1) {
		serr = port_set_low_latency_flag(fd);
		now = port_read_timer(file);
	}
	if (now == 1) {
		out->timer_ms = 1;
		out->lowered = true;
		port_note(out, "%s: latency timer lowered from %d ms to 1 ms",
		         tty, was);
		return;
	}
	if (now > 0)
		out->timer_ms = now;
	port_note(out, "%s: latency timer is %d ms and could not be lowered (%s): every reply waits "
	         "up to %d ms; run `dxl setup` as root or use the udev rule",
	         tty, out->timer_ms, strerror(werr != 0 ? werr : serr != 0 ? serr : EPERM),
	         out->timer_ms);
}

void port_latency_check_fd(const char *path, int fd, bool lower, struct port_latency *out)
{
	char name[32], tty[48];
	char file[PORT_SYSFS_PATH_MAX];

	memset(out, 0, sizeof *out);
	if (path == NULL || port_tty_name(path, name, sizeof name, tty, sizeof tty) != 0) {
		port_note(out, "cannot resolve the device behind %s: %s",
		         path != NULL ? path : "(null)", strerror(errno));
		return;
	}
	snprintf(file, sizeof file, "%s/bus/usb-serial/devices/%s/latency_timer", port_sysfs_root(),
	         name);
	out->timer_ms = port_read_timer(file);
	if (out->timer_ms < 0) {
		out->timer_ms = 0;
		/* Not an FTDI usb-serial device (a pty, a CDC-ACM USB2AX, an on-board
		 * UART): no timer to hold replies. The low-latency flag still helps
		 * 8250-style UARTs, so set it when asked, quietly. */
		if (lower)
			(void)port_set_low_latency_flag(fd);
		port_note(out, "%s: no latency timer (not an FTDI adapter)", tty);
		return;
	}
	out->known = true;
	out->found_ms = out->timer_ms;
	if (out->timer_ms <= 1) {
		port_note(out, "%s: latency timer %d ms (good)", tty,
		         out->timer_ms);
		return;
	}
	if (lower) {
		port_try_lower(tty, file, fd, out);
		return;
	}
	port_note(out, "%s: latency timer is %d ms: every reply waits up to %d ms; `dxl setup` lowers it "
	         "to 1 ms", tty, out->timer_ms, out->timer_ms);
}

void port_latency_check(const char *path, bool lower, struct port_latency *out)
{
	/* The TIOCSSERIAL fallback needs the device open; a busy port (EBUSY)
	 * just leaves the sysfs route. */
	int fd = lower && path != NULL ? open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC) : -1;

	port_latency_check_fd(path, fd, lower, out);
	if (fd >= 0)
		close(fd);
}
