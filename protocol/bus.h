/*
 * bus.h — Dynamixel 1.0 bus transactions over an abstract transport.
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
 */
#ifndef UNDULATE_BUS_H
#define UNDULATE_BUS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl.h"

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
	uint32_t error_replies;    /* replies with any error bit set */
	uint8_t errbits_seen;      /* OR of every error byte seen */
	uint8_t last_errbits;
	uint32_t rtt_last_us, rtt_max_us;
	uint64_t rtt_sum_us;       /* mean = rtt_sum_us / replies */
};

enum bus_step_result {
	BUS_PENDING = 1,           /* still waiting; poll again until the deadline */
	/* DXL_OK (0): complete, reply (if any) delivered; negative: dxl_status */
};

#define BUS_NSERVOS 254
/* Echo bytes remembered: a reply-less request's echo plus the next request. */
#define BUS_ECHO_QUEUE (2 * DXL_MAX_PACKET)

struct bus {
	struct bus_io io;
	struct bus_timing timing;
	bool echo;                 /* single-wire wiring: our own bytes come back first */
	struct dxl_parser parser;
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
	struct dxl_packet reply;
	/* The request as written. With echo off, a packet identical to it may be
	 * an unexpected echo — or a genuine reply (a PING answered with the
	 * input-voltage bit reads FF FF ID 02 01 CHK both ways): it is held in
	 * `reply` and delivered only if nothing else comes before the deadline. */
	uint8_t req_buf[DXL_MAX_PACKET];
	size_t req_len;
	bool reply_held;
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
/* Wire time of n bytes at the current baud, in µs (10 bits a byte). */
uint32_t bus_wire_time_us(const struct bus *b, size_t nbytes);
/* Timeout for a request of req_bytes answered by reply_bytes. */
uint32_t bus_timeout_us(const struct bus *b, size_t req_bytes, size_t reply_bytes);
void bus_reset_stats(struct bus *b);

/* ---- asynchronous core ------------------------------------------------------ */
/* Send a request. reply_params: the parameter count the status packet must
 * have, or -1 when no reply is expected (broadcast, SYNC_WRITE, status return
 * level too low). Returns DXL_OK (pending, or done when no reply expected) or
 * a negative dxl_status. */
int bus_begin(struct bus *b, uint8_t id, uint8_t instr, const uint8_t *params, size_t nparams,
              int reply_params);
/* Send pre-encoded bytes (e.g. from dxl_encode_sync_write) expecting no reply. */
int bus_send_raw(struct bus *b, const uint8_t *pkt, size_t n);
/* Drive a pending transaction: reads what is available, matches the reply.
 * Returns BUS_PENDING, DXL_OK (reply in *reply, if reply != NULL) or a negative
 * dxl_status (DXL_E_TIMEOUT once now >= deadline). */
int bus_step(struct bus *b, struct dxl_packet *reply);
uint64_t bus_deadline_us(const struct bus *b);
bool bus_is_pending(const struct bus *b);
/* Give up on a pending transaction (e.g. the port went away). */
void bus_abort(struct bus *b);

/* ---- blocking calls (tools, start-up) ------------------------------------------
 * Each returns DXL_OK or a negative dxl_status; *errbits (if not NULL) gets the
 * servo's error byte, which is data, not failure. */
int bus_ping(struct bus *b, uint8_t id, uint8_t *errbits);
int bus_read(struct bus *b, uint8_t id, uint8_t addr, uint8_t len, uint8_t *out, uint8_t *errbits);
int bus_read_u8(struct bus *b, uint8_t id, uint8_t addr, uint8_t *v, uint8_t *errbits);
int bus_read_u16(struct bus *b, uint8_t id, uint8_t addr, uint16_t *v, uint8_t *errbits);
/* WRITE waits for a reply unless id is broadcast or expect_reply is false
 * (status return level < 2). */
int bus_write(struct bus *b, uint8_t id, uint8_t addr, const uint8_t *data, size_t n,
              bool expect_reply, uint8_t *errbits);
int bus_write_u8(struct bus *b, uint8_t id, uint8_t addr, uint8_t v, uint8_t *errbits);
int bus_write_u16(struct bus *b, uint8_t id, uint8_t addr, uint16_t v, uint8_t *errbits);
int bus_reg_write(struct bus *b, uint8_t id, uint8_t addr, const uint8_t *data, size_t n,
                  bool expect_reply, uint8_t *errbits);
int bus_action(struct bus *b, uint8_t id, uint8_t *errbits); /* broadcast: no reply */
int bus_sync_write(struct bus *b, uint8_t addr, uint8_t len, const uint8_t *ids,
                   const uint8_t *data, size_t n);
int bus_factory_reset(struct bus *b, uint8_t id, bool expect_reply, uint8_t *errbits);
/* How late replies come: n PINGs to id (at most BUS_LATENESS_MAX), each round
 * trip less the wire time of the PING and its reply (6 bytes each) and the
 * servo's return delay. What is left is time the bytes were held between the
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

#endif
