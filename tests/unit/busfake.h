/*
 * busfake.h — a fake transport for the bus tests (test_protocol_bus.c, both
 * protocols): an in-memory peer that answers each request with
 * scripted literal bytes after a scripted delay, and a fake clock that only
 * io->wait advances, so timeouts are checked to the microsecond. Sized for
 * Protocol 2.0's packets (1024 bytes) and a SYNC_READ's replies.
 */
#ifndef UNDULATE_BUSFAKE_H
#define UNDULATE_BUSFAKE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "bus.h"
#include "dxl2.h"

/* Bytes the fake peer can have queued (several packets and their echoes). */
#define FAKE_RX_CAP 8192
/* Bytes the fake remembers of what the bus wrote. */
#define FAKE_TX_CAP 8192

struct fake {
	uint64_t now;
	/* receive queue: byte i becomes readable at rx_at[i] */
	uint8_t rx[FAKE_RX_CAP];
	uint64_t rx_at[FAKE_RX_CAP];
	size_t rx_head, rx_tail;
	/* what the bus wrote */
	uint8_t tx[FAKE_TX_CAP];
	size_t ntx;
	unsigned writes, waits, flushes;
	/* the peer: bytes to answer the next write with, after reply_delay_us */
	const uint8_t *reply;
	size_t reply_len;
	uint64_t reply_delay_us;
	/* single-wire echo: every written byte comes back after echo_delay_us,
	 * with echo_corrupt_at (1-based; 0 = none) flipped */
	bool echo;
	uint64_t echo_delay_us;
	size_t echo_corrupt_at;
	/* answer every write (not only the next one), after delays[i] for the
	 * i-th write when delays is set; UINT64_MAX: no answer to that one */
	bool reply_every;
	const uint64_t *delays;
	size_t ndelays, delay_i;
	/* transport faults and fragmentation */
	int write_error;
	size_t max_chunk;
};

static inline void fake_push(struct fake *f, const uint8_t *d, size_t n, uint64_t at)
{
	assert_true(f->rx_tail + n <= FAKE_RX_CAP);
	for (size_t i = 0; i < n; i++) {
		f->rx[f->rx_tail] = d[i];
		f->rx_at[f->rx_tail] = at;
		f->rx_tail++;
	}
}

static inline size_t fake_ready(const struct fake *f)
{
	size_t n = 0;
	while (f->rx_head + n < f->rx_tail && f->rx_at[f->rx_head + n] <= f->now)
		n++;
	return n;
}

static inline int fake_write(void *ctx, const uint8_t *buf, size_t n)
{
	struct fake *f = ctx;
	f->writes++;
	if (f->write_error)
		return f->write_error;
	assert_true(f->ntx + n <= FAKE_TX_CAP);
	memcpy(f->tx + f->ntx, buf, n);
	f->ntx += n;
	if (f->echo) {
		uint8_t copy[DXL2_MAX_PACKET];
		memcpy(copy, buf, n);
		if (f->echo_corrupt_at && f->echo_corrupt_at <= n)
			copy[f->echo_corrupt_at - 1] ^= 0x40;
		fake_push(f, copy, n, f->now + f->echo_delay_us);
	}
	if (f->reply) {
		uint64_t delay = f->delays != NULL ? f->delays[f->delay_i++ % f->ndelays] : f->reply_delay_us;
		if (delay != UINT64_MAX)
			fake_push(f, f->reply, f->reply_len, f->now + delay);
		if (!f->reply_every)
			f->reply = NULL;
	}
	return DXL_OK;
}

static inline long fake_read(void *ctx, uint8_t *buf, size_t cap)
{
	struct fake *f = ctx;
	size_t n = fake_ready(f);
	if (n > cap)
		n = cap;
	if (f->max_chunk && n > f->max_chunk)
		n = f->max_chunk;
	memcpy(buf, f->rx + f->rx_head, n);
	f->rx_head += n;
	return (long)n;
}

/* Advance the clock to the next byte's arrival or by the whole timeout. */
static inline int fake_wait(void *ctx, uint32_t timeout_us)
{
	struct fake *f = ctx;
	f->waits++;
	if (fake_ready(f))
		return 1;
	if (f->rx_head < f->rx_tail && f->rx_at[f->rx_head] <= f->now + timeout_us) {
		f->now = f->rx_at[f->rx_head];
		return 1;
	}
	f->now += timeout_us;
	return 0;
}

static inline uint64_t fake_now(void *ctx)
{
	return ((struct fake *)ctx)->now;
}

/* Like a kernel flush: only what has already arrived is discarded. */
static inline void fake_flush(void *ctx)
{
	struct fake *f = ctx;
	f->flushes++;
	f->rx_head += fake_ready(f);
}

static inline long fake_pending(void *ctx)
{
	struct fake *f = ctx;
	return (long)fake_ready(f);
}

#endif
