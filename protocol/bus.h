/*
 * bus.h — Dynamixel bus transactions over an abstract transport, for
 * Protocol 1.0 (AX-12) and Protocol 2.0 (X series).
 *
 * Pure code like the framing: the transport (write, non-blocking read, wait,
 * clock) comes in through `struct bus_io`, so tests can drive it with a fake
 * clock and the real backends live in protocol/io/ (port.h).
 *
 * Two ways to use it:
 *  - asynchronous, for programs with their own poll() loop (the daemon):
 *      bus_begin(..., now) sends the request; poll bus_io's fd for input until
 *      bus_deadline_us(); call bus_step(..., now) on input or at the deadline;
 *      it returns BUS_PENDING until the transaction completes or fails.
 *  - blocking, for tools: bus_ping/bus_read/bus_write/... use io->wait.
 *
 * A reply is checked against its request (ID and parameter count). Broadcast
 * requests and SYNC_WRITE wait for nothing. The timeout is derived from the
 * baud rate, the bytes on the wire, the servo's return delay and the adapter
 * latency — a missing servo costs that, not tens of milliseconds.
 *
 * One bus, either protocol: the framing is a table (dxl_proto.h), and this
 * layer calls b->proto->... without asking which one it has. bus_init starts
 * on Protocol 1.0; bus_set_protocol switches. Echo cancelling, the derived
 * timeouts, flushing, settling, lateness and the per-servo counters are one
 * code. The calls take 16-bit addresses and 32-bit values; what a protocol
 * cannot do (dxl_proto_can: SYNC_READ, BULK_READ, REBOOT, ...) returns
 * DXL_E_UNSUPPORTED and sends nothing.
 */
#ifndef UNDULATE_BUS_H
#define UNDULATE_BUS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl.h"
#include "dxl2.h"
#include "dxl_proto.h"

/* The transport seam. All functions are required unless noted. */
struct bus_io {
	void *ctx;
	/* Write all n bytes; DXL_OK or DXL_E_IO / DXL_E_DISCONNECTED. */
	int (*write)(void *ctx, const uint8_t *buf, size_t n);
	/* Non-blocking read: bytes read (>= 0, 0 = nothing available now), or
	 * DXL_E_IO / DXL_E_DISCONNECTED. */
	long (*read)(void *ctx, uint8_t *buf, size_t cap);
	/* Block until input is available or timeout_us passed: 1 readable,
	 * 0 timeout, negative dxl_status on error. Used by the blocking calls. */
	int (*wait)(void *ctx, uint32_t timeout_us);
	/* Monotonic time in microseconds. */
	uint64_t (*now_us)(void *ctx);
	/* Optional: discard unread input (stale bytes before a new request). */
	void (*flush_input)(void *ctx);
	/* Optional: bytes readable now without waiting (FIONREAD), -1 if unknown.
	 * With it, a request flushes the input only when there is something to
	 * flush or the line is dirty (a transaction that did not end cleanly):
	 * on a tty each flush may wait for the kernel's buffer worker, which a
	 * busy machine schedules late. */
	long (*pending_input)(void *ctx);
};

/* What the timeout is derived from. */
struct bus_timing {
	long baud;                    /* bits per second, 10 bits a byte (8N1) */
	uint32_t return_delay_us;     /* servo's return delay (register 5 × 2 µs) */
	uint32_t adapter_latency_us;  /* USB adapter hold time (FTDI latency timer) */
	uint32_t margin_us;           /* scheduling slack added to every timeout */
};

/* Per-servo counters (index = ID). */
struct bus_servo_stats {
	uint32_t transactions;     /* requests that expected a reply */
	uint32_t replies;          /* well-formed replies matched to their request */
	uint32_t timeouts;
	uint32_t checksum_errors;
	uint32_t resyncs;          /* header errors while waiting for this servo */
	uint32_t wrong_id;
	uint32_t wrong_length;
	uint32_t error_replies;    /* replies with any error bit set (2.0: ERR field not 0) */
	uint8_t errbits_seen;      /* OR of every error byte seen (2.0: of every ERR field) */
	uint8_t last_errbits;
	uint32_t alerts;           /* replies with proto->err_alert set (2.0: read Hardware Error Status) */
	uint32_t stuffing_errors;  /* 2.0: a header inside a reply's body (also counted in resyncs) */
	uint32_t rtt_last_us, rtt_max_us;
	uint64_t rtt_sum_us;       /* mean = rtt_sum_us / replies */
};

enum bus_step_result {
	BUS_PENDING = 1,           /* still waiting; poll again until the deadline */
	/* DXL_OK (0): complete, reply (if any) delivered; negative: dxl_status */
};

#define BUS_NSERVOS 254
/* The largest packet of any protocol: buffers sized once for both. */
#define BUS_MAX_PACKET DXL2_MAX_PACKET
/* Echo bytes remembered: a reply-less request's echo plus the next request
 * (two of the spoken protocol's largest packets). */
#define BUS_ECHO_QUEUE (2 * BUS_MAX_PACKET)

/* Protocol numbers as configuration files give them (dxl_proto_by_number). */
enum bus_protocol {
	BUS_PROTOCOL_1 = 1,        /* Dynamixel Protocol 1.0 (dxl.h) */
	BUS_PROTOCOL_2 = 2,        /* Dynamixel Protocol 2.0 (dxl2.h) */
};

/*
 * One SYNC_READ, BULK_READ or broadcast PING (where the protocol has them): a request
 * answered by one status packet per servo. The caller owns it, sets `data`
 * and `cap`, and leaves it alone from the begin call until bus_step returns
 * anything but BUS_PENDING (or bus_abort): the bus writes the replies into
 * it as they come. Slot i is the i-th servo of the request (for a broadcast
 * PING, the i-th servo that answered); its bytes are data + off[i], len[i]
 * of them, valid when status[i] is DXL_OK.
 */
#define BUS_MULTI_MAX DXL2_MULTI_MAX
struct bus_multi {
	uint8_t *data;             /* caller's buffer for every slot's bytes */
	size_t cap;
	size_t n;                  /* slots */
	uint8_t id[BUS_MULTI_MAX];
	uint16_t len[BUS_MULTI_MAX];
	uint32_t off[BUS_MULTI_MAX];
	/* DXL_OK, or why the slot has no data: DXL_E_TIMEOUT (missing),
	 * DXL_E_CHECKSUM (its reply was damaged), DXL_E_WRONG_LENGTH, and
	 * DXL_E_WRONG_ID (missing after a packet from a servo not asked) */
	int status[BUS_MULTI_MAX];
	uint8_t err[BUS_MULTI_MAX];  /* the reply's ERR field (data: alert bit, error number) */
	size_t answered;             /* slots with DXL_OK */
	bool ping_all;               /* a broadcast PING: any servo, each once */
	bool fast;                   /* a Fast Sync/Bulk Read: one packet holds every slot */
	struct dxl2_multi_read track;
};
/* Slot's bytes, or NULL when it has none (status[slot] != DXL_OK). */
const uint8_t *bus_multi_data(const struct bus_multi *m, size_t slot);
/* The IDs that did not answer well, in request order (up to cap); returns
 * how many. */
size_t bus_multi_failed(const struct bus_multi *m, uint8_t *ids, size_t cap);

struct bus {
	struct bus_io io;
	struct bus_timing timing;
	bool echo;                 /* single-wire wiring: our own bytes come back first */
	const struct dxl_proto *proto;     /* the protocol spoken: its table */
	union dxl_proto_parser parser;     /* its status parser (proto->parser_*) */
	/* the pending transaction */
	bool pending;
	uint8_t req_id, req_instr;
	int expect_params;         /* parameter count the reply must have; -1 = no reply */
	/* Echo cancelling: bytes written and not yet read back, in order. A request
	 * that expects no reply returns at once, so its echo may still be on its
	 * way when the next request starts: the queue holds up to two packets. */
	size_t echo_left;          /* echoed bytes still to discard (the queue's tail) */
	uint8_t echo_buf[BUS_ECHO_QUEUE];
	size_t echo_len;           /* bytes in echo_buf; the first echo_len - echo_left matched */
	uint64_t started_us, deadline_us;
	/* Stale bytes may be on their way: a transaction ended without its
	 * reply, with a damaged one or one from elsewhere. The next request
	 * flushes the input first. */
	bool line_dirty;
	/* The last single reply (bus_reply). With echo off, on a protocol whose
	 * request reads as a status (proto->echo_reads_as_status), a packet
	 * identical to the request may be an unexpected echo — or a genuine
	 * reply (a 1.0 PING answered with the input-voltage bit reads
	 * FF FF ID 02 01 CHK both ways): it is held here and delivered only if
	 * nothing else comes before the deadline. */
	struct dxl_frame reply;
	bool reply_held;
	/* The request as written. */
	uint8_t req_buf[BUS_MAX_PACKET];
	size_t req_len;
	/* The multi-reply request in flight (NULL for a single reply), and, on
	 * a protocol whose request never reads as a status, how much of our own
	 * request has come back at the start of the input with echo off: those
	 * bytes are held, not fed to the parser, until they differ or the
	 * whole request matched. */
	struct bus_multi *multi;
	size_t echo_probe;
	bool echo_probe_dead;
	/* counters */
	struct bus_servo_stats servo[BUS_NSERVOS];
	uint32_t stray_packets;    /* packets nobody asked for */
	uint32_t io_errors;
	uint32_t echo_errors;      /* echo cancelling saw other bytes than sent */
	uint32_t unexpected_echoes; /* echo off, yet our request came back: wiring echoes? */
	uint64_t bytes_out, bytes_in;
};

void bus_init(struct bus *b, const struct bus_io *io, const struct bus_timing *timing, bool echo);
void bus_set_timing(struct bus *b, const struct bus_timing *timing);
/* Speak another protocol from the next request on: DXL_OK, DXL_E_BUSY
 * while a transaction is pending, DXL_E_ARG for NULL. Bytes of the other
 * protocol still on the line are flushed before the next request. */
int bus_set_proto(struct bus *b, const struct dxl_proto *proto);
const struct dxl_proto *bus_proto(const struct bus *b);
/* The same by number (1 or 2; DXL_E_ARG for another value). */
int bus_set_protocol(struct bus *b, enum bus_protocol protocol);
enum bus_protocol bus_get_protocol(const struct bus *b);
/* Wire time of n bytes at the current baud, in µs (10 bits a byte). */
uint32_t bus_wire_time_us(const struct bus *b, size_t nbytes);
/* Timeout for a request of req_bytes answered by reply_bytes. */
uint32_t bus_timeout_us(const struct bus *b, size_t req_bytes, size_t reply_bytes);
/* A request of req_bytes answered by nreplies status packets of
 * reply_params[i] parameters: the wire time of the request and of every
 * reply at its largest (proto->status_bytes_max: 2.0's worst-case
 * stuffing), one return delay per reply, the adapter latency and the margin. */
uint32_t bus_multi_timeout_us(const struct bus *b, size_t req_bytes, const uint16_t *reply_params, size_t nreplies);
/* A Fast Sync/Bulk Read of parts of these lengths: the request and the one
 * status packet on the wire (never stuffed), ONE return delay (each next
 * servo's part follows the one before at once), the latency and the margin. */
uint32_t bus_fast_timeout_us(const struct bus *b, size_t req_bytes, const uint16_t *lens, size_t n);
void bus_reset_stats(struct bus *b);

/* ---- asynchronous core ------------------------------------------------------ */
/* Send a request: the protocol's instruction code and raw parameters
 * (2.0: 16-bit addresses and lengths). reply_params: the parameter count
 * the status packet must have, or -1 when no reply is expected (status
 * return level too low). Broadcast, SYNC_WRITE and BULK_WRITE wait for
 * nothing; SYNC_READ and BULK_READ go through bus_sync_read_begin /
 * bus_bulk_read_begin (DXL_E_ARG here). Returns DXL_OK (pending, or done
 * when no reply expected) or a negative dxl_status. */
int bus_begin(struct bus *b, uint8_t id, uint8_t instr, const uint8_t *params, size_t nparams,
              int reply_params);
/* One READ, WRITE or REBOOT by the protocol's table (16-bit addresses on
 * either protocol; 1.0 refuses an address above 255, and has no REBOOT:
 * DXL_E_UNSUPPORTED), left pending as bus_begin's. */
int bus_read_begin(struct bus *b, uint8_t id, uint16_t addr, uint16_t len);
int bus_write_begin(struct bus *b, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply);
int bus_reboot_begin(struct bus *b, uint8_t id, bool expect_reply);
/* Send pre-encoded bytes (e.g. a SYNC_WRITE) expecting no reply. */
int bus_send_raw(struct bus *b, const uint8_t *pkt, size_t n);
/* One SYNC_READ of len bytes at addr from n servos, or one BULK_READ
 * (DXL_CAP_SYNC_READ, DXL_CAP_BULK_READ; else DXL_E_UNSUPPORTED), into *m (its data/cap set by the caller; the rest is filled
 * here). The deadline is bus_multi_timeout_us of all n replies. Replies are
 * checked against the request one by one (dxl2_multi_read_accept): a servo
 * not asked, or answering twice, is DXL_E_WRONG_ID; the wrong size
 * DXL_E_WRONG_LENGTH; a damaged reply counts against the servo the bus
 * expected next (servos answer in request order). DXL_E_BUFFER when the
 * replies cannot all fit m->cap. */
int bus_sync_read_begin(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n,
                        struct bus_multi *m);
int bus_bulk_read_begin(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m);
/* The same as Fast Sync Read / Fast Bulk Read (DXL_CAP_FAST_READ; whether
 * the servos answer is their firmware's: X430/X540 from 45). The one status
 * packet fills every slot when it arrives whole (dxl2_fast_status_split):
 * a part whose CRC fails is DXL_E_CHECKSUM with every slot after it (the
 * parts before it are delivered), a packet whose own CRC fails makes every
 * slot DXL_E_CHECKSUM, another servo in a part's place DXL_E_WRONG_ID. A
 * packet that never completes (a servo that did not send its part stops
 * the chain) leaves every slot DXL_E_TIMEOUT at bus_fast_timeout_us. */
int bus_fast_sync_read_begin(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n,
                             struct bus_multi *m);
int bus_fast_bulk_read_begin(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m);
/* A broadcast PING (DXL_CAP_BROADCAST_PING). Every servo answers, in ID order, each
 * after its return delay; the deadline allows for every ID (the wire time
 * of a PING reply and a return delay each, at least 3 ms), and each reply found becomes a
 * slot of *m (its 3 bytes: model number, firmware). m->data needs 3 bytes a
 * servo; servos past m->cap are counted as stray packets. */
int bus_ping_all_begin(struct bus *b, struct bus_multi *m);
/* Drive a pending transaction: reads what is available, matches the reply.
 * Returns BUS_PENDING, DXL_OK (reply in *reply, if reply != NULL) or a negative
 * dxl_status (DXL_E_TIMEOUT once now >= deadline).
 * One reply: *reply gets its ID, the servo's error byte / ERR field as
 * `code` and its parameters when they fit DXL_MAX_PARAMS (else nparams 0:
 * read them with bus_reply). A multi-reply request ends when every servo answered
 * (DXL_OK) or at the deadline, or as soon as every slot is settled; the
 * result is DXL_OK when every slot has its data, else the first failed
 * slot's status — the replies that came are in the bus_multi either way,
 * and bus_multi_failed names the servos that did not answer. */
int bus_step(struct bus *b, struct dxl_packet *reply);
/* The last single reply bus_step delivered, whole. */
const struct dxl_frame *bus_reply(const struct bus *b);
/* Blocking: drive the pending transaction to its end with io->wait (what
 * every blocking call does after its begin). DXL_OK when nothing is pending. */
int bus_wait_done(struct bus *b, struct dxl_packet *reply);
uint64_t bus_deadline_us(const struct bus *b);
bool bus_is_pending(const struct bus *b);
/* Give up on a pending transaction (e.g. the port went away). */
void bus_abort(struct bus *b);

/* ---- blocking calls (tools, start-up) ------------------------------------------
 * Each returns DXL_OK or a negative dxl_status; *err (if not NULL) gets the
 * reply's error byte (1.0) or ERR field (2.0) — data, not failure, counted
 * per servo (error_replies, alerts). Writes wait for a reply unless id is
 * broadcast or expect_reply is false (status return level < 2). What the
 * protocol cannot do returns DXL_E_UNSUPPORTED and sends nothing. */
/* A broadcast PING here is sent on a protocol without DXL_CAP_BROADCAST_PING
 * (1.0: the replies collide; nothing is waited for) and refused with
 * DXL_E_ARG where bus_ping_all is the way. */
int bus_ping(struct bus *b, uint8_t id, uint8_t *err);
/* DXL_CAP_PING_MODEL: the model number and firmware the reply carries. */
int bus_ping_model(struct bus *b, uint8_t id, uint16_t *model, uint8_t *firmware, uint8_t *err);
/* A servo found by a broadcast PING. */
struct bus_found {
	uint8_t id;
	uint16_t model;
	uint8_t firmware;
	uint8_t err;
};
/* DXL_CAP_BROADCAST_PING: the servos that answered, in the order they did
 * (ID order), up to cap. DXL_OK even when none did (*n = 0). */
int bus_ping_all(struct bus *b, struct bus_found *found, size_t cap, size_t *n);
int bus_read(struct bus *b, uint8_t id, uint16_t addr, uint16_t len, uint8_t *out, uint8_t *err);
int bus_read_u8(struct bus *b, uint8_t id, uint16_t addr, uint8_t *v, uint8_t *err);
int bus_read_u16(struct bus *b, uint8_t id, uint16_t addr, uint16_t *v, uint8_t *err);
int bus_read_u32(struct bus *b, uint8_t id, uint16_t addr, uint32_t *v, uint8_t *err);
int bus_write(struct bus *b, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply,
              uint8_t *err);
int bus_write_u8(struct bus *b, uint8_t id, uint16_t addr, uint8_t v, uint8_t *err);
int bus_write_u16(struct bus *b, uint8_t id, uint16_t addr, uint16_t v, uint8_t *err);
int bus_write_u32(struct bus *b, uint8_t id, uint16_t addr, uint32_t v, uint8_t *err);
int bus_reg_write(struct bus *b, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply,
                  uint8_t *err);
int bus_action(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err);
/* option: enum dxl_reset_option (1.0: DXL_RESET_ALL only; 2.0 refuses
 * broadcast with DXL_RESET_ALL). */
int bus_factory_reset(struct bus *b, uint8_t id, uint8_t option, bool expect_reply, uint8_t *err);
int bus_reboot(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err);      /* DXL_CAP_REBOOT */
/* DXL_CAP_CLEAR: the multi-turn position back within one turn. */
int bus_clear_multi_turn(struct bus *b, uint8_t id, bool expect_reply, uint8_t *err);
int bus_sync_write(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, const uint8_t *data,
                   size_t n);
int bus_bulk_write(struct bus *b, const struct dxl_item *items, size_t n);      /* DXL_CAP_BULK_WRITE */
/* SYNC_READ / BULK_READ into *m (data/cap set by the caller); the result as
 * bus_step's for them. */
int bus_sync_read(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n, struct bus_multi *m);
int bus_bulk_read(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m);
int bus_fast_sync_read(struct bus *b, uint16_t addr, uint16_t len, const uint8_t *ids, size_t n,
                       struct bus_multi *m);
int bus_fast_bulk_read(struct bus *b, const struct dxl_item *items, size_t n, struct bus_multi *m);

/* How late replies come: n PINGs to id (at most BUS_LATENESS_MAX), each round
 * trip less the wire time of the PING and its reply
 * (proto->ping_round_trip_bytes) and the servo's return delay. What is left is time the bytes were held between the
 * line and us: an adapter's latency timer (an FTDI chip holds a short reply
 * up to 16 ms), a USB-serial bridge, a reader scheduled late. It is measured
 * where no setting can be read (a CDC-ACM adapter, an on-board UART, a pty).
 * DXL_OK when at least one PING was answered; else the last PING's status. */
#define BUS_LATENESS_MAX 32
struct bus_lateness {
	unsigned pings, replies;
	uint32_t min_us, median_us, max_us;
};
int bus_reply_lateness(struct bus *b, uint8_t id, uint32_t return_delay_us, unsigned n, struct bus_lateness *out);

/* Before trying a failed transaction again: read and discard input until the
 * line has been quiet for quiet_us, or max_us have passed. A reply that was
 * only late lands here instead of colliding with the next request. Returns
 * the bytes discarded (>= 0; the line is clean if it went quiet), DXL_E_BUSY
 * while a transaction is pending, or an I/O error. */
int bus_settle(struct bus *b, uint32_t quiet_us, uint32_t max_us);

/* After a single request timed out (DXL_E_TIMEOUT), whether its reply was
 * late or never came: listen up to max_us more, and parse what comes as
 * status packets. Stops at the first whole packet. What came is dropped
 * (the next request flushes the line). */
struct bus_late {
	long bytes;              /* bytes that came after the deadline */
	uint32_t waited_us;      /* the deadline the request had, from its start */
	uint32_t after_us;       /* from the deadline to the first of them */
	int id;                  /* the first whole packet's ID, or -1 */
};
/* DXL_OK (*out filled: bytes 0 = nothing came), DXL_E_BUSY while a
 * transaction is pending, or an I/O error. */
int bus_listen_late(struct bus *b, uint32_t max_us, struct bus_late *out);

#endif
