/*
 * line.h — the half-duplex wire as seen by the controller: bytes scheduled
 * at the time their stop bit leaves the line (plus the adapter's hold time),
 * released to the pty when that time has come. Two servos driving the line
 * at once (a broadcast PING, a duplicated ID) collide: bytes within half a
 * byte time of each other share a slot and are AND-ed, as an open-drain line would, which on a real bus shows
 * up as garbage and bad checksums. Pure: times are given by the caller (ns).
 */
#ifndef UNDULATE_SIM_LINE_H
#define UNDULATE_SIM_LINE_H

#include <stddef.h>
#include <stdint.h>

/* Bytes in flight toward the controller: every servo on a bus answering a
 * full-size READ at once, plus echo and injected garbage, fits easily. */
#define SIM_LINE_CAP 4096

struct sim_line_byte {
	int64_t t;        /* ns: release time */
	uint8_t b;
};

struct sim_line {
	struct sim_line_byte q[SIM_LINE_CAP];
	size_t head, n;   /* queued bytes are q[head .. head+n) */
	uint64_t collisions;   /* bytes that overlapped another byte */
	uint64_t overflows;    /* bytes dropped because the queue was full */
};

void sim_line_init(struct sim_line *l);
/* Drop everything queued (disconnect, power loss of the whole bus). */
void sim_line_clear(struct sim_line *l);
/* Queue n bytes: byte i is released at first_end + i·byte_ns. A byte within
 * half a byte time of a queued byte collides with it; bytes further apart
 * interleave (also garbage to the controller's UART). */
void sim_line_put(struct sim_line *l, int64_t first_end, int64_t byte_ns, const uint8_t *bytes, size_t n);
/* Copy out (and dequeue) the bytes due at `now`, up to cap. */
size_t sim_line_take(struct sim_line *l, int64_t now, uint8_t *out, size_t cap);
/* Release time of the next queued byte, INT64_MAX when empty. */
int64_t sim_line_next(const struct sim_line *l);
/* When to hand over the next chunk: the release time of the last byte due
 * within slice_ns of the next one. Waking then delivers a short reply whole
 * and exactly when its last byte ends, with one wake-up instead of one per
 * byte; no byte is ever released early. INT64_MAX when empty. */
int64_t sim_line_chunk_end(const struct sim_line *l, int64_t slice_ns);

#endif
