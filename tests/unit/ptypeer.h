/*
 * ptypeer.h — a scripted peer on a pseudo-terminal, for tests.
 *
 * The test opens the pty's slave (ptypeer.slave_path) with the code under
 * test; a thread holding the master side plays a script: wait for exactly
 * these bytes, then answer with those (after an optional delay), or hang up.
 * Everything the peer received is kept so a test can check it byte for byte.
 *
 * The master side is left as the kernel creates it (no echo, no translation),
 * so whatever mangling happens, happens on the slave side under test.
 * Self-contained (libc + POSIX threads, which live in libc): this file is
 * linked into every unit test.
 */
#ifndef UNDULATE_PTYPEER_H
#define UNDULATE_PTYPEER_H

#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Bytes the peer keeps of what it received (a few long packets). */
#define PTYPEER_LOG_MAX 4096
/* How long a step waits for its expected bytes before failing (ms). */
#define PTYPEER_STEP_TIMEOUT_MS 3000

struct ptypeer_step {
	const uint8_t *expect;   /* bytes to wait for, compared exactly (NULL: none) */
	size_t expect_len;
	const uint8_t *reply;    /* bytes to send after them (NULL: none) */
	size_t reply_len;
	uint32_t delay_us;       /* pause before replying */
	bool hang_up;            /* close the master after this step: the bus vanishes */
};

struct ptypeer {
	int master;
	char slave_path[64];
	pthread_t thread;
	bool started;
	const struct ptypeer_step *steps;
	size_t nsteps;
	/* results, valid after ptypeer_join() */
	size_t steps_done;
	bool failed;
	char why[160];
	uint8_t log[PTYPEER_LOG_MAX];
	size_t log_len;
};

/* Create the pty; 0 or -1 (errno). */
int ptypeer_open(struct ptypeer *p);
/* Play steps[0..n) in a thread. The steps must outlive the join. */
int ptypeer_start(struct ptypeer *p, const struct ptypeer_step *steps, size_t n);
/* Wait for the script to end; returns true when every step matched. */
bool ptypeer_join(struct ptypeer *p);
/* Close the master if still open (and join a running script first). */
void ptypeer_close(struct ptypeer *p);
/* Blocking helpers for tests that drive the master by hand. */
int ptypeer_write(struct ptypeer *p, const uint8_t *buf, size_t n);
/* Read exactly n bytes within timeout_ms; returns bytes read (< n on timeout). */
size_t ptypeer_read(struct ptypeer *p, uint8_t *buf, size_t n, int timeout_ms);

#endif
