/*
 * port.h — serial transports for the Dynamixel bus (the I/O half of protocol/).
 *
 * Two backends behind one interface:
 *  - libserialport for real ports (enumeration with USB VID/PID, 8N1 at any
 *    Dynamixel baud including 1 Mbps, flush);
 *  - a raw termios fd for pseudo-terminals, which libserialport 0.1.1 cannot
 *    open (it wants a sysfs entry and TIOCMGET). The simulator's buses are ptys.
 * Either way the fd is non-blocking so the caller can poll() it in its own loop.
 */
#ifndef UNDULATE_PORT_H
#define UNDULATE_PORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "bus.h"
#include "holder.h"

struct port; /* opaque */

enum port_backend { PORT_BACKEND_TERMIOS, PORT_BACKEND_SERIALPORT };

struct port_options {
	long baud;                  /* bps; must be a rate the backend can set */
	bool force_termios;         /* use the termios backend even for a real tty */
	bool low_latency;           /* try to set the FTDI latency timer to 1 ms */
	/* What this program does with the bus, written beside its lock so that a
	 * refused second program can say who holds it: "robot r1" (undulated),
	 * "command scan" (dxl). NULL: nothing. */
	const char *owner;
	/* Out, may be NULL: when port_open() refuses a port because another
	 * program holds it, who that is (pid > 0 or a program name; the message
	 * in err names it too); zeroed otherwise. */
	struct holder *holder;
};

/* Open path (a device or a symlink to one) and take it for this program:
 * one owner per bus (port_lock.c). A port another program holds is refused
 * ("cannot open PATH: held by undulated (pid 812, robot r1)", *opt->holder)
 * before anything on it is touched. On failure returns NULL and writes one
 * clear line into err. port_close() lets it go. */
struct port *port_open(const char *path, const struct port_options *opt, char *err, size_t errcap);
void port_close(struct port *p);
int port_fd(const struct port *p);
const char *port_path(const struct port *p);
enum port_backend port_backend(const struct port *p);
int port_set_baud(struct port *p, long baud);
long port_baud(const struct port *p);
/* Non-blocking read: >= 0 bytes, or DXL_E_IO / DXL_E_DISCONNECTED (EIO, HUP, EOF). */
long port_read(struct port *p, uint8_t *buf, size_t cap);
/* Write everything (waits for the fd to drain if needed). */
int port_write(struct port *p, const uint8_t *buf, size_t n);
/* Wait up to timeout_us for input: 1 readable, 0 timeout, negative error. */
int port_wait(struct port *p, uint32_t timeout_us);
void port_flush_input(struct port *p);
/* Bytes readable now, without waiting (FIONREAD); -1 if it cannot say. */
long port_pending_input(struct port *p);
/* Fill a bus_io that drives this port (clock: common/clock.h's monotonic). */
void port_bus_io(struct port *p, struct bus_io *io);
uint64_t port_now_us(void);

/* The same port in lockstep (common/lockstep.h): time is the simulator's,
 * and waiting is a WAIT to it. In-band (the simulator's WELCOME says so)
 * the bytes written go with the next WAIT and what is read is what the
 * TIMEs carried: the pty is not read or written. On the pty transport what
 * is read is exactly what the simulator announced (bytes it released and
 * the tty worker has not handed over yet are waited for, not taken for
 * silence), and every byte written is counted for its WAITs. Call it each
 * time the port is (re)opened: what was delivered for an earlier one is
 * dropped. The caller owns *pl for as long as the bus_io is used. */
struct lks_client;
struct port_lockstep {
	struct port *port;
	struct lks_client *clock;
	long rate_told;             /* in-band: the port's rate the simulator was last told of */
	size_t bus;                 /* which of the clock's buses (lks_client_open_buses); the pty transport: 0 */
};
void port_bus_io_lockstep(struct port_lockstep *pl, struct port *p, struct lks_client *clock, size_t bus,
                          struct bus_io *io);

/* ---- RS-485 direction control (an on-board UART with a half-duplex buffer) ---- */
/* A single-board computer's UART drives the Dynamixel line through a tri-state
 * buffer whose direction pin is wired to RTS. The kernel's RS-485 mode
 * (TIOCSRS485) switches RTS around every transmission itself, as soon as the
 * transmitter is empty: far closer to the last stop bit than a user-space
 * toggle gets, and a servo with return delay 0 answers 22 µs after it. The level is the kernel's
 * "logical" one: on many UARTs an asserted RTS drives the pin low, so when
 * nothing answers in one mode, try the other. */
enum port_rs485 {
	PORT_RS485_OFF,             /* leave the port's RS-485 setting alone */
	PORT_RS485_RTS_ON_SEND,     /* RTS high while sending, low after (SER_RS485_RTS_ON_SEND) */
	PORT_RS485_RTS_AFTER_SEND,  /* RTS low while sending, high after (SER_RS485_RTS_AFTER_SEND) */
};
/* "off", "rts-on-send" (or "rts"), "rts-after-send"; false if none of them. */
bool port_rs485_parse(const char *s, enum port_rs485 *out);
const char *port_rs485_name(enum port_rs485 mode);
/* Switch the open port to RS-485 mode (SER_RS485_ENABLED, RTS as asked, no
 * delays before or after sending, the receiver off while sending) and read it
 * back. PORT_RS485_OFF does nothing. DXL_OK; DXL_E_ARG when the device refuses
 * (a pty, a USB adapter, a UART driver without RS-485: ENOTTY and kin) or
 * changes what was asked; DXL_E_IO otherwise. On failure err gets one line
 * naming the port and errno. port_close() puts back the setting found. */
int port_set_rs485(struct port *p, enum port_rs485 mode, char *err, size_t errcap);

/* ---- adapter latency (FTDI) -------------------------------------------------- */
struct port_latency {
	bool known;                 /* found a latency_timer for this tty */
	int timer_ms;               /* its value (FTDI default 16), after any lowering */
	int found_ms;               /* its value before we touched it */
	bool lowered;               /* we set it to 1 (or ASYNC_LOW_LATENCY) */
	char note[160];             /* human-readable outcome, e.g. why it stays at 16 */
};
/* Inspect (and if `lower`, try to lower) the adapter latency behind path. The
 * sysfs file is /sys/bus/usb-serial/devices/<tty>/latency_timer. */
void port_latency_check(const char *path, bool lower, struct port_latency *out);

/* The outcome of the latency check port_open() ran (opt->low_latency), or
 * NULL when it was not asked for. */
const struct port_latency *port_get_latency(const struct port *p);
/* As port_latency_check(), with the port's open fd (-1: none) so the
 * TIOCSSERIAL/ASYNC_LOW_LATENCY fallback can work when sysfs is not writable.
 * The sysfs root is $UNDULATE_SYSFS_ROOT when set (tests), else /sys. */
void port_latency_check_fd(const char *path, int fd, bool lower, struct port_latency *out);

/* The adapter hold time the bus timeouts must allow for, in µs, as the daemon
 * derives it: configured_us when >= 0 (a configuration's adapter_latency_us);
 * else the FTDI latency timer behind the open port — the check port_open() ran
 * (opt->low_latency: lowered if it could), or one run now on the port's fd,
 * lowering it — and 0 for a device without one. *lat (may be NULL) gets the
 * check's outcome; known = false when configured_us decided. */
long port_adapter_latency_us(struct port *p, long configured_us, struct port_latency *lat);

/* ---- one owner per bus (port_lock.c) ------------------------------------------ */
/* The directory of UUCP lock files (LCK..ttyUSB0): $UNDULATE_LOCK_DIR when
 * set (tests), else /var/lock. */
const char *port_lock_dir(void);
/* Who holds the bus device behind path (symlinks resolved) now: the process
 * holding its flock() (our programs, picocom, pyserial), named by its lock
 * file or /proc, or a live program named by a UUCP lock file. False when
 * nobody is seen. */
bool port_holder(const char *path, struct holder *h);

/* What port_open() holds while a port is open: the device, open and
 * flock()ed, and the UUCP lock file it wrote. Exposed for tests. */
#define PORT_LOCKFILE_MAX 320   /* "<lock dir>/LCK..<device below /dev>" */
struct port_claim {
	int fd;                             /* -1: none */
	char lockfile[PORT_LOCKFILE_MAX];   /* "" when none was written */
};
/* Take the device at real (a resolved path; `shown` is the caller's name
 * for it, for messages) before anything touches the line. DXL_OK;
 * DXL_E_BUSY with the holder in *holder (may be NULL) and err; DXL_E_ARG
 * (no such device) or DXL_E_IO with err. */
int port_claim_take(struct port_claim *c, const char *real, const char *shown, const char *owner,
                    struct holder *holder, char *err, size_t errcap);
void port_claim_drop(struct port_claim *c);

/* ---- low-level helpers (used by both backends; exposed for tests) ------------ */
/* Where sysfs is: $UNDULATE_SYSFS_ROOT when set (tests), else "/sys". */
const char *port_sysfs_root(void);
/* Put a tty fd in raw 8N1 mode, no flow control, receiver on, modem lines
 * ignored, keeping its speed. DXL_OK or DXL_E_IO (errno kept). */
int port_termios_raw(int fd);
/* Set any bit rate on a tty fd: the standard Bxxx constant when there is one,
 * else termios2/BOTHER. DXL_OK, DXL_E_ARG (rate <= 0) or DXL_E_IO. */
int port_termios_set_baud(int fd, long baud);
/* The termios2/BOTHER path alone (any rate; on a real UART the driver rounds
 * to what its divisor can do). Same returns. */
int port_termios2_set_baud(int fd, long baud);
/* The output rate of a tty fd in bps, however it was set (a Bxxx constant or
 * BOTHER; for a pty, also by the process at its other end), or DXL_E_IO. */
long port_termios2_get_baud(int fd);

/* ---- enumeration ------------------------------------------------------------- */
struct port_info {
	char path[128];
	char description[128];
	char serial[64];            /* USB serial number, "" if none */
	int usb_vid, usb_pid;       /* -1 when not a USB device */
	const char *adapter;        /* "U2D2", "USB2Dynamixel", "USB2AX" or NULL */
};
/* Fill up to cap entries; returns the number of ports found (may exceed cap),
 * or a negative dxl_status. Linux lists ttys in sysfs (<sysfs root>/class/tty):
 * without it (a container with no /sys) there is nothing to enumerate and
 * the answer is 0 ports, not an error. libserialport itself always reads /sys;
 * the root only decides whether there is a sysfs to list from. */
int port_list(struct port_info *out, size_t cap);
/* The port whose USB serial number is `serial`, wherever it is enumerated now
 * (ttyUSB numbers change on replugging): true with its path in path[cap];
 * false, with the number of ports looked at in *nports. */
bool port_find_by_serial(const char *serial, char *path, size_t cap, int *nports);
/* The listing's entry for the device behind path (symlinks resolved): its USB
 * IDs and adapter name. False when it is not listed (a pty, a missing device). */
bool port_info_for(const char *path, struct port_info *out);
/* Name of a known Dynamixel adapter for a VID:PID, or NULL. */
const char *port_adapter_name(int vid, int pid);

#endif
