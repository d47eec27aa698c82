/*
 * lockstep.h — virtual time shared by the simulator and the daemons that
 * drive its buses: the same binaries, the same bus bytes, the same physics;
 * only the clock changes hands (issue: lockstep simulation).
 *
 * The simulator owns time. Each daemon connects to its lockstep socket (a
 * local SOCK_SEQPACKET socket: one message a datagram, in order, and the end
 * of a peer is seen as the end of the stream), names the bus (or buses:
 * "Several buses" below) it drives, and from then on never reads the system's clock: when it has nothing to do
 * until some time, or until its bus answers, it says so (WAIT) and blocks
 * until the simulator says what time it is (TIME). The simulator advances
 * its time only while every daemon is blocked, to the earliest of: its next
 * physics step, a reply byte's wire time, a daemon's wake-up. So a daemon's
 * computation takes no virtual time, a bus transaction takes its wire time,
 * and nothing waits on the wall clock: a run goes as fast as the processes
 * can take turns, and the same seed gives the same run.
 *
 * The bus bytes travel with the clock (the in-band transport, the default):
 * a WAIT carries the bytes the daemon wrote to its bus since its last WAIT,
 * a TIME the bytes the simulator released toward the daemon since its last
 * TIME. The simulator feeds the former into the bus's input path (line
 * model, echo, parser, timing) at the virtual time the WAIT came at, which
 * is the time the daemon wrote them: nothing is ever "on its way". The pty
 * still exists and the daemon opens, locks and sets its baud as on a real
 * bus (the simulator follows the baud the daemon set on it), but no data
 * crosses it: on a paravirtualised machine each pty read, write and ioctl,
 * and each wake-up of the kernel's tty worker that moves the bytes, cost
 * more than the simulation (measured on a 45 s run of ten robots: 610 000
 * of its 2.2 M system calls were the ptys', and the tty worker woke
 * 240 000 times).
 *
 * The pty transport (undulate-sim --lockstep-pty, for one release: it is
 * the reference the in-band one is compared with) sends the bytes through
 * the pty. Bytes there cross the kernel's tty buffer worker, which may hold
 * them after write() returned; neither side may take "nothing there" for
 * "nothing sent", so both count: a WAIT's b is the bytes the daemon has
 * written so far, and the simulator reads its side of the pty until they
 * have all arrived before it counts the daemon as blocked; a TIME's b is the
 * bytes released toward the daemon so far, and port_bus_io_lockstep reads
 * until it has them before it lets the bus decide that a reply did not come.
 *
 * Messages (struct lks_msg: a fixed header and, on the wire, only nbytes of
 * its payload; same machine so host byte order):
 *   daemon → sim: HELLO  a = pid, text = the bus's port path, name = robot,
 *                        b = buses this daemon drives (0 is taken for 1),
 *                        c = this bus's index among them (0 .. b - 1):
 *                        one HELLO a bus, in index order, each answered
 *                        (WELCOME or REFUSED; see "Several buses" below)
 *                 WAIT   a = wake-up (virtual ns, LKS_NEVER: none),
 *                        b = bytes written to the bus (pty transport),
 *                        flags LKS_WANT_INPUT: wake up as soon as bytes
 *                        arrive; LKS_PORT_OPENED: the daemon (re)opened its
 *                        port since its last WAIT (in-band: its bytes are for
 *                        the pty the link points at now); LKS_RATE_SET: it
 *                        set its port's rate since (in-band: the simulator
 *                        reads the rate off the pty before it takes the next
 *                        bytes, as the pty transport does before every read;
 *                        the rate only changes when the daemon sets it, and
 *                        one ioctl per transaction was a fifth of the
 *                        simulator's system calls);
 *                        payload (in-band): the bytes written since the last WAIT
 *                 BYE    the daemon is leaving (after its safe stop);
 *                        payload (in-band): its last bytes, not waited on
 *   sim → daemon: WELCOME a = virtual now (ns), b = monotonic µs at virtual 0,
 *                        c = wall-clock µs at virtual 0, flags LKS_INBAND:
 *                        the bytes travel in the messages
 *                 TIME   a = virtual now (ns), b = bytes released to the bus
 *                        (pty transport), flags LKS_BUS_GONE: the port the
 *                        daemon has open is gone (the disconnect fault: what
 *                        the pty's EIO says on the other transport);
 *                        payload (in-band): the bytes released since the last TIME
 *                 CMD    text = a command for the robot, applied as one from
 *                        the robot's local socket (sent just before a TIME)
 *                 STOP   text = why: the run is over, stop as on SIGTERM
 *                 REFUSED text = why the daemon cannot join
 *   both ways:    PART   c = a bus index (1 .. buses - 1), flags and payload
 *                        as a WAIT's (daemon → sim) or a TIME's (sim →
 *                        daemon) say them for bus 0: the part of the WAIT,
 *                        BYE or TIME that follows it that is that bus's
 *
 * Several buses (a robot whose joints are on several ports, daemon/README.md
 * "Several buses"): one daemon, one connection, one clock. The daemon is
 * blocked or not as a whole (its one loop drives every bus), so the
 * simulator's barrier counts it once, and keeps per bus what each port did
 * (opened, rate set, bytes owed, gone). It names each bus with its own HELLO
 * (index c of b): a list would not fit one HELLO's text (four paths of up to
 * 255 bytes), and each bus is found, refused ("no bus there", "already has
 * a daemon") and answered as a lone daemon's is. Each WAIT (and BYE) is
 * preceded by one PART for every bus but the first, each TIME likewise: the
 * message itself is bus 0's, unchanged, so a one-bus daemon's messages are
 * exactly what they were (its runs stay byte-identical), and a bus's bytes
 * keep the framing and the limit (LKS_BYTES_MAX) they have on one bus. The
 * socket keeps the order of datagrams, and time moves only once the WAIT
 * itself has come: a WAIT's PARTs are all in by then, at the same virtual
 * time. A PART for a bus index the daemon did not name is refused and
 * counted on either side. The pty transport carries one bus a daemon (its
 * counts are the bus's): a daemon naming several is refused there.
 */
#ifndef UNDULATE_COMMON_LOCKSTEP_H
#define UNDULATE_COMMON_LOCKSTEP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define LKS_MAGIC 0x4c4b5333u        /* "LKS3": a version change changes it (2: bytes in band, 3: PART) */
#define LKS_TEXT_MAX 256             /* a port path, a command, a reason */
#define LKS_NAME_MAX 32
#define LKS_NEVER UINT64_MAX
/* Buses one daemon drives (its configuration's CFG_MAX_BUSES). */
#define LKS_BUSES_MAX 4
#define LKS_WANT_INPUT 1u            /* WAIT */
#define LKS_PORT_OPENED 2u           /* WAIT */
#define LKS_INBAND 4u                /* WELCOME */
#define LKS_BUS_GONE 8u              /* TIME */
#define LKS_RATE_SET 16u             /* WAIT */
/* The most bus bytes one message carries. A daemon writes between two
 * WAITs at most one cycle's packets before it waits for a reply: the
 * largest is a Protocol 2.0 sync write of every joint (a daemon's 24
 * with a 4-byte goal and a 4-byte profile: 14 + 24 * 9 = 230 bytes, a third
 * more at worst with byte stuffing), and the longest any packet may be is 1024
 * bytes (DXL2_MAX_PACKET): four of those fit. Toward the daemon,
 * the simulator's whole line (SIM_LINE_CAP) fits. More is refused and
 * counted on both sides, never cut short silently. */
#define LKS_BYTES_MAX 4096
/* Commands received while blocked and not yet taken by the daemon. */
#define LKS_CMD_QUEUE 8
/* Wall-clock patience of a daemon for its simulator (ms): the simulator
 * itself declares a stalled daemon after its own grace and ends the run, so
 * this only fires when the simulator is stopped (SIGSTOP) or hangs. */
#define LKS_CLIENT_GRACE_MS 120000
/* The pty transport's wall-clock patience for bytes already announced by
 * the other side (ms): the tty worker delivers them in microseconds; a
 * longer gap means they were lost (a pty closed under them) and the count is
 * set right instead. */
#define LKS_BYTES_GRACE_MS 2000
/* Virtual time 0 on both clocks. Fixed, so that the same seed gives the same
 * run: SINUSOID's phase is taken from the wall clock (robots on different
 * computers share it), and a wall clock that started wherever the real one
 * stood would start every run at another phase. 2000-01-01T00:00:00Z on the
 * wall clock (a lockstep log's utimes are from then, its log timestamps from
 * now); 1000 s on the monotonic one (never 0, which code may take for
 * "not set"). */
#define LKS_WALL0_US 946684800000000LL
#define LKS_MONO0_US 1000000000ULL

enum lks_type {
	LKS_HELLO = 1, LKS_WELCOME, LKS_WAIT, LKS_TIME, LKS_CMD, LKS_STOP, LKS_REFUSED, LKS_BYE, LKS_PART,
};

struct lks_msg {
	uint32_t magic;
	uint32_t type;
	uint64_t a, b, c;
	uint32_t flags;
	char name[LKS_NAME_MAX];
	char text[LKS_TEXT_MAX];
	uint32_t nbytes;            /* bytes of payload that follow (in-band transport) */
	uint8_t bytes[LKS_BYTES_MAX];
};
/* A message's size on the wire: the header and its payload. */
#define LKS_HEADER_SIZE offsetof(struct lks_msg, bytes)

const char *lks_type_name(uint32_t type);
/* Send one message, its header and m->nbytes of payload: 0, or -1 (errno
 * set; EPIPE when the peer is gone, EMSGSIZE for more than LKS_BYTES_MAX). */
int lks_send(int fd, const struct lks_msg *m);
/* Receive one message (blocking unless the socket is not): 1 a message,
 * 0 the peer closed, -1 an error or a malformed message (errno EPROTO;
 * `why` says what: not ours, shorter than its header, a payload that is not
 * the length it says, or longer than LKS_BYTES_MAX). Strings come
 * NUL-terminated whatever was sent. */
int lks_recv(int fd, struct lks_msg *m, char *why, size_t cap);

/* ---- the simulator's side: the listening socket ----------------------------- */
/* Bind and listen at path (a stale socket file is replaced; anything else at
 * path is refused). The fd, or -1 with err. */
int lks_listen(const char *path, char *err, size_t cap);

/* ---- the daemon's side -------------------------------------------------------- */
/* One bus's bytes and news (in-band): bus 0's go in the WAIT and TIME
 * themselves, the others' in the PARTs before them. */
struct lks_bus {
	/* bytes written since the last WAIT; bytes the TIMEs (PARTs) delivered,
	 * in[in_off .. nin) not read yet */
	uint8_t out[LKS_BYTES_MAX];
	size_t nout;
	uint8_t in[LKS_BYTES_MAX];
	size_t in_off, nin;
	bool port_opened;           /* LKS_PORT_OPENED goes with the next WAIT */
	bool rate_set;              /* LKS_RATE_SET goes with the next WAIT */
	bool bus_gone;              /* the last TIME said LKS_BUS_GONE */
	long long too_long;         /* writes refused: more than LKS_BYTES_MAX between two WAITs */
	long long in_dropped;       /* delivered bytes that did not fit unread ones */
};

struct lks_client {
	int fd;
	uint64_t mono0_us;          /* the daemon's monotonic clock at virtual 0 */
	int64_t wall0_us;
	uint64_t t_ns;              /* virtual now */
	bool inband;                /* the bus bytes travel in WAIT and TIME (WELCOME said so) */
	/* pty transport (one bus): bus bytes written by us, released by the
	 * simulator, read by us */
	uint64_t written, delivered, consumed;
	struct lks_bus bus[LKS_BUSES_MAX];
	size_t nbuses;              /* named in HELLOs (1 when opened with one port) */
	long long bad_parts;        /* PARTs from the simulator for a bus we did not name */
	bool waiting;               /* a WAIT is out and no TIME has answered it */
	bool time_moved;            /* a TIME came since lks_client_take_time() */
	bool stop;                  /* the simulator ended the run */
	char stop_why[LKS_TEXT_MAX];
	char cmds[LKS_CMD_QUEUE][LKS_TEXT_MAX];
	size_t ncmds;
	long long cmds_dropped;
	long long resyncs;          /* announced bytes that never came (or came unannounced) */
};

/* Connect to the simulator at sock_path, say which bus (port_path) and robot
 * this is, and wait for the answer. Sets the virtual clock (clock.h). 0, or
 * -1 with err (no simulator there, refused, or no answer in time). */
int lks_client_open(struct lks_client *c, const char *sock_path, const char *port_path, const char *robot,
                    char *err, size_t cap);
/* The same for a daemon driving nports buses (1 .. LKS_BUSES_MAX): one HELLO
 * each, index i for ports[i]; every one must be welcomed. */
int lks_client_open_buses(struct lks_client *c, const char *sock_path, const char *const *ports, size_t nports,
                          const char *robot, char *err, size_t cap);
/* Say goodbye and close (nothing if not open). */
void lks_client_close(struct lks_client *c);
/* Virtual now on the daemon's monotonic clock (µs). */
uint64_t lks_client_now_us(const struct lks_client *c);
/* Block until wake_us (the daemon's monotonic µs) or until bus bytes arrive
 * on a bus whose bit is set in want_input (bit i: bus i; true is bus 0):
 * send the WAIT, after a PART for every bus but the first (once: a WAIT
 * already out is not sent again). 0, or -1 when the simulator is gone. */
int lks_client_wait(struct lks_client *c, uint64_t wake_us, unsigned want_input);
/* The socket is readable: take one message. Returns its type, 0 when the
 * simulator closed the socket, -1 on an error (with why). TIME sets the
 * virtual clock; CMD is queued; STOP sets c->stop. */
int lks_client_read(struct lks_client *c, char *why, size_t cap);
/* Send a WAIT and read until the TIME that answers it (queueing commands,
 * noting STOP): what a blocking bus call does. 0, or -1 (simulator gone or
 * silent for LKS_CLIENT_GRACE_MS; why says which). */
int lks_client_block(struct lks_client *c, uint64_t wake_us, unsigned want_input, char *why, size_t cap);
/* The daemon (re)opened bus's port: what was delivered for the one before
 * is not for it (both transports), and the simulator hears so with the next
 * WAIT. */
void lks_client_port_opened(struct lks_client *c, size_t bus);
/* True once after each TIME: the daemon's loop has a new "now" to act on. */
bool lks_client_take_time(struct lks_client *c);
/* The next queued command into out (false when none). */
bool lks_client_next_cmd(struct lks_client *c, char *out, size_t cap);

#endif
