/*
 * port.c — the serial transport: open a bus device with libserialport or as a
 * raw termios fd, and move bytes without blocking.
 *
 * Backend choice: libserialport first (real ports: it knows the USB details
 * and sets 8N1 portably); when it cannot open the device — always the case for
 * a pseudo-terminal with libserialport 0.1.1, which wants a sysfs entry and
 * TIOCMGET — the device is opened as a plain fd. Both backends end the same
 * way: raw mode set by port_termios_raw() and O_NONBLOCK, so the transaction
 * layer sees one kind of fd. Before either, the device is taken for this
 * program (port_lock.c); real ports are also claimed with TIOCEXCL.
 */
#include <errno.h>
#include <fcntl.h>
#include <libserialport.h>
#include <limits.h>
#include <linux/serial.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/select.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "port.h"

#include "clock.h"

/* Longest device path we keep (Linux PATH_MAX would be wasteful: by-id
 * symlinks, the longest real names, are under 120 characters). */
#define PORT_PATH_MAX 256
/* How long port_write waits for room in the output queue before calling the
 * port stuck. 100 ms: longer than any AX-12 packet at 9600 bps (250 B, 26 ms). */
#define PORT_WRITE_STALL_MS 100
/* Unix98 pty slaves (/dev/pts/N): majors 136..143 (UNIX98_PTY_SLAVE_MAJOR,
 * UNIX98_PTY_MAJOR_COUNT in the kernel's major.h). */
#define PORT_PTY_SLAVE_MAJOR 136
#define PORT_PTY_MAJOR_COUNT 8

struct port {
	int fd;
	enum port_backend backend;
	struct sp_port *sp;          /* NULL for the termios backend */
	long baud;
	char path[PORT_PATH_MAX];
	bool latency_checked;
	struct port_latency latency;
	/* RS-485 mode as found before port_set_rs485() changed it: put back at
	 * close, so a later program that did not ask for it does not get it */
	bool rs485_changed;
	struct serial_rs485 rs485_found;
	struct port_claim claim;     /* this program's hold on the device */
	bool exclusive;              /* TIOCEXCL set: cleared at close */
};

/* ---- raw mode ----------------------------------------------------------------- */

int port_termios_raw(int fd)
{
	struct termios tio;

	if (tcgetattr(fd, &tio) != 0)
		return DXL_E_IO;
	/* Input: no BREAK-to-SIGINT (BRKINT) and no parity marking (PARMRK, INPCK):
	 * 0xFF is a packet header byte and must never be doubled or replaced. No
	 * stripping to 7 bits (ISTRIP). No CR/NL translation (INLCR, IGNCR, ICRNL):
	 * 0x0D and 0x0A are ordinary bytes in a checksum or a position. No XON/XOFF
	 * (IXON, IXOFF, IXANY): 0x11 and 0x13 are data. IGNBRK off so a line break
	 * reads as a 0x00 byte the parser drops, rather than vanishing silently. */
	tio.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | INPCK | ISTRIP | INLCR | IGNCR |
	                           ICRNL | IXON | IXOFF | IXANY);
	/* Output: no post-processing (OPOST), which would turn 0x0A into 0x0D 0x0A. */
	tio.c_oflag &= ~(tcflag_t)OPOST;
	/* Local: no echo of received bytes back onto the bus (ECHO, ECHONL), no
	 * line buffering (ICANON), no signals from 0x03/0x1A/0x1C (ISIG), no
	 * extended input processing (IEXTEN, e.g. 0x16 literal-next). */
	tio.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
	/* Control: 8 data bits (CS8), no parity (PARENB), one stop bit (CSTOPB):
	 * Dynamixel is 8N1. CREAD: enable the receiver. CLOCAL: ignore modem
	 * status lines, adapters do not drive DCD. No hardware flow control
	 * (CRTSCTS): the half-duplex bus has no RTS/CTS wiring. HUPCL off: dropping
	 * DTR on close resets some adapters' direction logic. */
	tio.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB | CRTSCTS | HUPCL);
	tio.c_cflag |= (tcflag_t)(CS8 | CREAD | CLOCAL);
	/* read() returns whatever is there; with O_NONBLOCK it never waits anyway,
	 * and VTIME 0 disables the inter-byte timer. */
	tio.c_cc[VMIN] = 1;
	tio.c_cc[VTIME] = 0;
	if (tcsetattr(fd, TCSANOW, &tio) != 0)
		return DXL_E_IO;
	return DXL_OK;
}

/* The POSIX/Linux constants for rates a Dynamixel setup uses or a user may
 * type; anything else goes through termios2. */
static const struct {
	long bps;
	speed_t code;
} port_std_rates[] = {
	{ 9600, B9600 },     { 19200, B19200 },     { 38400, B38400 },   { 57600, B57600 },
	{ 115200, B115200 }, { 230400, B230400 },   { 460800, B460800 }, { 500000, B500000 },
	{ 576000, B576000 }, { 921600, B921600 },   { 1000000, B1000000 },
	{ 2000000, B2000000 }, { 3000000, B3000000 }, { 4000000, B4000000 },
};

/* Rate changes wait for queued output to leave (TCSADRAIN): a packet still
 * in the UART would otherwise go out half at each rate. */
int port_termios_set_baud(int fd, long baud)
{
	struct termios tio;

	if (baud <= 0)
		return DXL_E_ARG;
	for (size_t i = 0; i < sizeof port_std_rates / sizeof port_std_rates[0]; i++) {
		if (port_std_rates[i].bps != baud)
			continue;
		if (tcgetattr(fd, &tio) != 0 || cfsetispeed(&tio, port_std_rates[i].code) != 0 ||
		    cfsetospeed(&tio, port_std_rates[i].code) != 0 || tcsetattr(fd, TCSADRAIN, &tio) != 0)
			return DXL_E_IO;
		return DXL_OK;
	}
	return port_termios2_set_baud(fd, baud);
}

/* ---- opening ------------------------------------------------------------------ */

static void port_errf(char *err, size_t errcap, const char *fmt, const char *path, const char *why)
{
	if (err != NULL && errcap > 0)
		snprintf(err, errcap, fmt, path, why);
}

static bool port_is_pty(int fd)
{
	struct stat st;

	return fstat(fd, &st) == 0 && S_ISCHR(st.st_mode) && major(st.st_rdev) >= PORT_PTY_SLAVE_MAJOR &&
	       major(st.st_rdev) < PORT_PTY_SLAVE_MAJOR + PORT_PTY_MAJOR_COUNT;
}

static int port_finish_fd(struct port *p, char *err, size_t errcap)
{
	int flags = fcntl(p->fd, F_GETFL);

	/* Callers poll() the fd in their own loop: reads must never block. */
	if (flags < 0 || fcntl(p->fd, F_SETFL, flags | O_NONBLOCK) != 0) {
		port_errf(err, errcap, "cannot make %s non-blocking: %s", p->path, strerror(errno));
		return DXL_E_IO;
	}
	if (port_termios_raw(p->fd) != DXL_OK) {
		port_errf(err, errcap, "%s is not a serial port (raw mode: %s)", p->path, strerror(errno));
		return DXL_E_IO;
	}
	/* One master per real bus: beside the lock (port_lock.c), which our
	 * programs honour, the kernel refuses other programs' opens with EBUSY
	 * (root's excepted). Not on a pty: a simulator keeps its slaves open, so
	 * the flag would outlive a crashed client and lock its restart out. */
	if (!port_is_pty(p->fd))
		p->exclusive = ioctl(p->fd, TIOCEXCL) == 0;
	return DXL_OK;
}

static bool port_open_serialport(struct port *p, const char *real)
{
	struct sp_port *sp = NULL;
	int fd = -1;

	if (sp_get_port_by_name(real, &sp) != SP_OK)
		return false;
	if (sp_open(sp, SP_MODE_READ_WRITE) != SP_OK || sp_set_bits(sp, 8) != SP_OK ||
	    sp_set_parity(sp, SP_PARITY_NONE) != SP_OK || sp_set_stopbits(sp, 1) != SP_OK ||
	    sp_set_flowcontrol(sp, SP_FLOWCONTROL_NONE) != SP_OK ||
	    sp_get_port_handle(sp, &fd) != SP_OK || fd < 0) {
		sp_close(sp);
		sp_free_port(sp);
		return false;
	}
	p->sp = sp;
	p->fd = fd;
	p->backend = PORT_BACKEND_SERIALPORT;
	return true;
}

static int port_open_termios(struct port *p, const char *real, char *err, size_t errcap)
{
	p->fd = open(real, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
	if (p->fd < 0) {
		const char *why = errno == EBUSY    ? "port busy (is another program using the bus?)"
		                  : errno == EACCES ? "permission denied (is the user in the dialout group?)"
		                                    : strerror(errno);
		port_errf(err, errcap, "cannot open %s: %s", p->path, why);
		return errno == ENOENT ? DXL_E_ARG : DXL_E_IO;
	}
	p->backend = PORT_BACKEND_TERMIOS;
	return DXL_OK;
}

struct port *port_open(const char *path, const struct port_options *opt, char *err, size_t errcap)
{
	char real[PATH_MAX];
	struct port *p;

	/* who holds the port, when that is why it fails: nobody, on every other path */
	if (opt != NULL && opt->holder != NULL)
		memset(opt->holder, 0, sizeof *opt->holder);
	if (path == NULL || path[0] == '\0' || strlen(path) >= PORT_PATH_MAX) {
		port_errf(err, errcap, "bad port path '%s'%s", path != NULL ? path : "", " (empty or too long)");
		return NULL;
	}
	if (realpath(path, real) == NULL) {
		port_errf(err, errcap, "cannot open %s: %s", path, strerror(errno));
		return NULL;
	}
	p = calloc(1, sizeof *p);
	if (p == NULL) {
		port_errf(err, errcap, "cannot open %s: %s", path, "out of memory");
		return NULL;
	}
	p->fd = -1;
	snprintf(p->path, sizeof p->path, "%s", path);
	/* before libserialport, whose sp_open() already sets the line up: a
	 * port held by another program is not touched at all */
	if (port_claim_take(&p->claim, real, path, opt != NULL ? opt->owner : NULL, opt != NULL ? opt->holder : NULL, err,
	                    errcap) != DXL_OK) {
		free(p);
		return NULL;
	}
	if ((opt == NULL || !opt->force_termios) && port_open_serialport(p, real)) {
		/* opened by libserialport */
	} else if (port_open_termios(p, real, err, errcap) != DXL_OK) {
		port_close(p);
		return NULL;
	}
	if (port_finish_fd(p, err, errcap) != DXL_OK) {
		port_close(p);
		return NULL;
	}
	if (opt != NULL && opt->baud > 0 && port_set_baud(p, opt->baud) != DXL_OK) {
		port_errf(err, errcap, "cannot set %s to the requested baud rate: %s", p->path,
		          strerror(errno));
		port_close(p);
		return NULL;
	}
	if (opt != NULL && opt->low_latency) {
		port_latency_check_fd(p->path, p->fd, true, &p->latency);
		p->latency_checked = true;
	}
	port_flush_input(p);
	return p;
}

void port_close(struct port *p)
{
	if (p == NULL)
		return;
	if (p->rs485_changed)
		(void)ioctl(p->fd, TIOCSRS485, &p->rs485_found);
	if (p->exclusive)
		(void)ioctl(p->fd, TIOCNXCL);
	if (p->sp != NULL) {
		sp_close(p->sp);
		sp_free_port(p->sp);
	} else if (p->fd >= 0) {
		close(p->fd);
	}
	port_claim_drop(&p->claim);
	free(p);
}

int port_fd(const struct port *p) { return p->fd; }
const char *port_path(const struct port *p) { return p->path; }
enum port_backend port_backend(const struct port *p) { return p->backend; }
long port_baud(const struct port *p) { return p->baud; }

const struct port_latency *port_get_latency(const struct port *p)
{
	return p->latency_checked ? &p->latency : NULL;
}

/* Here, not in port_latency.c: it reads the port, which port_latency.c
 * (fd and path level, called by port_open) never does. */
long port_adapter_latency_us(struct port *p, long configured_us, struct port_latency *lat)
{
	struct port_latency found;

	memset(&found, 0, sizeof found);
	if (configured_us >= 0) {
		snprintf(found.note, sizeof found.note, "adapter latency %ld us as configured", configured_us);
	} else {
		/* port_open() checked on the fd it holds: opening the device again
		 * would fail with EBUSY on an exclusively held real port and lose the
		 * ASYNC_LOW_LATENCY fallback. */
		if (p->latency_checked)
			found = p->latency;
		else
			port_latency_check_fd(p->path, p->fd, true, &found);
	}
	if (lat != NULL)
		*lat = found;
	if (configured_us >= 0)
		return configured_us;
	return found.known ? 1000L * found.timer_ms : 0;
}

int port_set_baud(struct port *p, long baud)
{
	if (baud <= 0 || baud > INT_MAX)
		return DXL_E_ARG;
	/* libserialport knows the standard rates; anything else (117 647 bps)
	 * goes through termios2, which also serves the termios backend. */
	if (p->sp != NULL && sp_set_baudrate(p->sp, (int)baud) == SP_OK) {
		p->baud = baud;
		return DXL_OK;
	}
	if (port_termios_set_baud(p->fd, baud) != DXL_OK)
		return DXL_E_IO;
	p->baud = baud;
	return DXL_OK;
}

/* ---- RS-485 direction control ---------------------------------------------------- */

static const char *const port_rs485_names[] = { "off", "rts-on-send", "rts-after-send" };

bool port_rs485_parse(const char *s, enum port_rs485 *out)
{
	if (s == NULL)
		return false;
	/* "rts": the common wiring, a buffer enabled while RTS is high */
	if (strcmp(s, "rts") == 0) {
		*out = PORT_RS485_RTS_ON_SEND;
		return true;
	}
	for (size_t i = 0; i < sizeof port_rs485_names / sizeof port_rs485_names[0]; i++) {
		if (strcmp(s, port_rs485_names[i]) == 0) {
			*out = (enum port_rs485)i;
			return true;
		}
	}
	return false;
}

const char *port_rs485_name(enum port_rs485 mode)
{
	return (unsigned)mode < sizeof port_rs485_names / sizeof port_rs485_names[0] ? port_rs485_names[mode] : "?";
}

/* errno values that mean "this device cannot do RS-485", not "it failed". */
static bool port_rs485_unsupported(int e)
{
	return e == ENOTTY || e == EINVAL || e == EOPNOTSUPP;
}

int port_set_rs485(struct port *p, enum port_rs485 mode, char *err, size_t errcap)
{
	struct serial_rs485 want, found, got;
	const uint32_t rts = SER_RS485_RTS_ON_SEND | SER_RS485_RTS_AFTER_SEND;

	if (mode == PORT_RS485_OFF)
		return DXL_OK;
	memset(&found, 0, sizeof found);
	bool have_found = ioctl(p->fd, TIOCGRS485, &found) == 0;
	memset(&want, 0, sizeof want);
	/* No RX_DURING_TX: the buffer's receiver is off while we send (a board
	 * whose receiver hears the transmitter anyway wants echo = true). No
	 * delays: the servo may answer 22 us after the last stop bit. */
	want.flags = SER_RS485_ENABLED |
	             (mode == PORT_RS485_RTS_ON_SEND ? SER_RS485_RTS_ON_SEND : SER_RS485_RTS_AFTER_SEND);
	if (ioctl(p->fd, TIOCSRS485, &want) != 0) {
		int e = errno;
		char why[200];
		snprintf(why, sizeof why, "%s (errno %d): %s", strerror(e), e,
		         port_rs485_unsupported(e) ? "this device has no RS-485 mode (a pty, a USB adapter, a "
		                                     "UART driver without it)" : "the driver refused it");
		port_errf(err, errcap, "cannot switch %s to RS-485 mode (TIOCSRS485): %s", p->path, why);
		errno = e;
		return port_rs485_unsupported(e) ? DXL_E_ARG : DXL_E_IO;
	}
	if (have_found) {
		p->rs485_found = found;
		p->rs485_changed = true;
	}
	/* Drivers adjust what they cannot do (the serial core rewrites an RTS
	 * polarity the hardware lacks): a direction backwards would leave the
	 * bus silent, so read it back. */
	memset(&got, 0, sizeof got);
	if (ioctl(p->fd, TIOCGRS485, &got) != 0 || !(got.flags & SER_RS485_ENABLED) ||
	    (got.flags & rts) != (want.flags & rts)) {
		char why[96];
		snprintf(why, sizeof why, "the driver kept flags 0x%x for 0x%x", (unsigned)got.flags, (unsigned)want.flags);
		port_errf(err, errcap, "cannot switch %s to RS-485 mode as asked: %s", p->path, why);
		return DXL_E_ARG;
	}
	return DXL_OK;
}

/* ---- moving bytes ------------------------------------------------------------- */

static int port_errno_status(int e)
{
	/* EIO: pty master closed or USB adapter unplugged; ENXIO/ENODEV: the
	 * device node lost its driver. All mean "the bus went away". */
	return (e == EIO || e == ENXIO || e == ENODEV) ? DXL_E_DISCONNECTED : DXL_E_IO;
}

long port_read(struct port *p, uint8_t *buf, size_t cap)
{
	ssize_t n;

	if (cap == 0)
		return 0;
	n = read(p->fd, buf, cap);
	if (n > 0)
		return (long)n;
	/* With O_NONBLOCK an empty tty answers EAGAIN; 0 is end of file, which a
	 * tty only reports after hang-up. */
	if (n == 0)
		return DXL_E_DISCONNECTED;
	if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)
		return 0;
	return port_errno_status(errno);
}

int port_write(struct port *p, const uint8_t *buf, size_t n)
{
	size_t done = 0;

	while (done < n) {
		ssize_t w = write(p->fd, buf + done, n - done);
		if (w > 0) {
			done += (size_t)w;
			continue;
		}
		if (w < 0 && errno == EINTR)
			continue;
		if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
			struct pollfd pfd = { .fd = p->fd, .events = POLLOUT };
			int r = poll(&pfd, 1, PORT_WRITE_STALL_MS);
			if (r > 0 && (pfd.revents & (POLLHUP | POLLERR)) && !(pfd.revents & POLLOUT))
				return DXL_E_DISCONNECTED;
			if (r == 0)
				return DXL_E_IO;
			continue;
		}
		return w == 0 ? DXL_E_IO : port_errno_status(errno);
	}
	return DXL_OK;
}

/* For an fd select() cannot take: millisecond poll, rounded up so a wait is
 * never shorter than asked. */
static int port_wait_poll(struct port *p, uint32_t timeout_us)
{
	struct pollfd pfd = { .fd = p->fd, .events = POLLIN };
	int r;

	do {
		r = poll(&pfd, 1, (int)((timeout_us + 999u) / 1000u));
	} while (r < 0 && errno == EINTR);
	if (r < 0)
		return DXL_E_IO;
	if (r == 0)
		return 0;
	return (pfd.revents & POLLIN) ? 1 : DXL_E_DISCONNECTED;
}

int port_wait(struct port *p, uint32_t timeout_us)
{
	struct timespec ts = { .tv_sec = timeout_us / 1000000u,
	                       .tv_nsec = (long)(timeout_us % 1000000u) * 1000L };
	fd_set rd;
	int r;

	/* pselect, not poll: a 1 Mbps reply takes 100 µs and poll() counts in
	 * milliseconds. A hung-up tty selects readable and read() then reports
	 * the disconnection. */
	if (p->fd >= FD_SETSIZE)
		return port_wait_poll(p, timeout_us);
	do {
		FD_ZERO(&rd);
		FD_SET(p->fd, &rd);
		r = pselect(p->fd + 1, &rd, NULL, NULL, &ts, NULL);
	} while (r < 0 && errno == EINTR);
	if (r < 0)
		return errno == EBADF ? DXL_E_DISCONNECTED : DXL_E_IO;
	return r > 0 ? 1 : 0;
}

void port_flush_input(struct port *p)
{
	if (p->sp != NULL)
		(void)sp_flush(p->sp, SP_BUF_INPUT);
	else
		(void)tcflush(p->fd, TCIFLUSH);
}

long port_pending_input(struct port *p)
{
	int n = 0;
	/* FIONREAD on a tty counts what its line discipline holds, without
	 * waiting for the kernel's buffer worker (libserialport asks the same) */
	if (ioctl(p->fd, FIONREAD, &n) != 0)
		return -1;
	return n;
}

/* The program's monotonic clock (common/clock.h): virtual in lockstep. */
uint64_t port_now_us(void)
{
	return clock_mono_us();
}

/* ---- the bus_io seam ---------------------------------------------------------- */

static int port_io_write(void *ctx, const uint8_t *buf, size_t n) { return port_write(ctx, buf, n); }
static long port_io_read(void *ctx, uint8_t *buf, size_t cap) { return port_read(ctx, buf, cap); }
static int port_io_wait(void *ctx, uint32_t timeout_us) { return port_wait(ctx, timeout_us); }
static void port_io_flush(void *ctx) { port_flush_input(ctx); }
static long port_io_pending(void *ctx) { return port_pending_input(ctx); }

static uint64_t port_io_now(void *ctx)
{
	(void)ctx;
	return port_now_us();
}

void port_bus_io(struct port *p, struct bus_io *io)
{
	memset(io, 0, sizeof *io);
	io->ctx = p;
	io->write = port_io_write;
	io->read = port_io_read;
	io->wait = port_io_wait;
	io->now_us = port_io_now;
	io->flush_input = port_io_flush;
	io->pending_input = port_io_pending;
}
