/*
 * writeq.h — the register writes a controller wants on the bus (torque on and
 * off, torque limits, the angle limits of a wheel-mode switch), queued until
 * the cycle sends them. Pure: no I/O, no clock.
 *
 * One owner: the controller (control.h) queues and reads the queue; the cycle
 * takes one write at a time and reports how it went, through ctl's narrow
 * calls, and never touches the queue itself. The rules that keep a torque-off
 * from being lost:
 *  - A write that was taken (is on the wire) is never changed: a later write
 *    to the same register is queued behind it, so the servo ends with the
 *    later value whatever became of the first.
 *  - A queued write not yet taken is updated in place when it is the last
 *    write queued for its servo (its final value is what matters); anything
 *    else is appended, so sequences (torque off, EEPROM, torque on) keep
 *    their order.
 *  - A write that failed (no reply, a damaged one, the cycle cut off before
 *    it was answered) stays at the front and is sent again, WQ_TRIES times in
 *    all; then it is dropped and the caller is told, to report it (the
 *    controller's read-back notices what it left undone).
 *  - A chain (wq_put_chain: the writes of one servo that only make sense
 *    together, such as an X servo's switch of Operating Mode — torque off,
 *    the mode, the goal, torque on) stops at its first write given up: the
 *    rest of it is dropped, never sent after a step that did not happen
 *    (torque on in a mode that was not set could drive a joint the servo no
 *    longer bounds). Nothing is ever merged into a chained write, so a later
 *    torque-off queued behind a chain is never dropped with it.
 * A queued write may also be an instruction without data: REBOOT (X series).
 */
#ifndef UNDULATE_DAEMON_WRITEQ_H
#define UNDULATE_DAEMON_WRITEQ_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Room for every servo of a 24-joint robot to be switched into and out of
 * wheel mode (4 writes each way) with its recovery writes on top: a queue
 * that fills means writes that never reach the bus, which is reported, so it
 * is sized far above any burst the controller makes. */
#define WQ_CAP 256
/* Sends of one write before it is given up. */
#define WQ_TRIES 3

struct wq_write {
	uint8_t id;
	uint16_t addr;        /* Protocol 2.0 addresses are 16 bits */
	uint8_t len;          /* 1, 2 or 4 bytes, little-endian as the registers; 0: a REBOOT */
	uint32_t value;
	uint8_t tries;        /* sends so far */
	uint16_t chain;       /* 0, or the chain it belongs to (wq_put_chain) */
};

struct wq {
	struct wq_write w[WQ_CAP];
	size_t n;
	bool taken;           /* w[0] is on the wire, waiting for wq_done() */
	uint16_t next_chain;  /* the last chain number given (never 0) */
	/* counters */
	long long sent, retried, failed, overflowed;
	long long chain_dropped;   /* writes dropped with the chain whose step failed */
};

enum wq_outcome {
	WQ_DONE,      /* written */
	WQ_RETRY,     /* failed; it is sent again next time */
	WQ_FAILED,    /* failed WQ_TRIES times: dropped */
};

void wq_init(struct wq *q);
/* Queue a write of a register's new value (see the rules above). False when
 * the queue is full (counted in `overflowed`; nothing was queued). */
bool wq_put(struct wq *q, uint8_t id, uint16_t addr, uint8_t len, uint32_t value);
/* Queue a write after everything queued, never merged into another. */
bool wq_put_seq(struct wq *q, uint8_t id, uint16_t addr, uint8_t len, uint32_t value);
/* A new chain's number, for wq_put_chain. */
uint16_t wq_chain(struct wq *q);
/* Queue a write as a step of `chain` (appended, never merged; see above).
 * len 0 queues a REBOOT of servo id. */
bool wq_put_chain(struct wq *q, uint16_t chain, uint8_t id, uint16_t addr, uint8_t len, uint32_t value);
size_t wq_pending(const struct wq *q);
/* True when a write to (id, addr) is queued or on the wire: what the servo
 * reports for that register may be about to change. */
bool wq_has(const struct wq *q, uint8_t id, uint16_t addr);
/* True when any write to servo id is queued or on the wire. */
bool wq_has_id(const struct wq *q, uint8_t id);
/* The next write to send (NULL: none, or one is already taken). From now on
 * it is on the wire: call wq_done() with the outcome. */
const struct wq_write *wq_take(struct wq *q);
/* The next write wq_take would give, without taking it (NULL: none, or one
 * is on the wire): a robot on several buses sends it on its servo's bus. */
const struct wq_write *wq_peek(const struct wq *q);
/* The outcome of the taken write; *w (may be NULL) gets a copy of it. A
 * chained write given up (WQ_FAILED) takes the rest of its chain with it. */
enum wq_outcome wq_done(struct wq *q, bool ok, struct wq_write *w);
/* Forget every queued write of servo id that is not on the wire (the servo
 * is being brought back from scratch). */
void wq_drop_id(struct wq *q, uint8_t id);
/* Forget everything (the bus went away: the start-up sequence rewrites what
 * matters). */
void wq_clear(struct wq *q);

#endif
