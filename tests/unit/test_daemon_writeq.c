/* test_daemon_writeq.c — the queue of register writes and the rules that
 * keep a torque-off from being lost: a taken write is never changed, a
 * queued one is updated only when it is the last for its servo, sequences
 * keep their order, LIMP after HOLD ends with torque off whatever was on the
 * wire, WQ_TRIES sends then WQ_FAILED, a full queue refuses and counts, and
 * wq_drop_id / wq_clear / wq_has. A randomized loop drives the queue against
 * a servo model. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "../../daemon/writeq.h"

/* AX-12 registers, as the controller writes them */
#define R_ANGLE_LIMITS 6     /* 4 bytes: CW and CCW limits */
#define R_TORQUE_EN 24
#define R_MARGINS 26
#define R_TORQUE_LIMIT 34

static struct wq q;

static int setup(void **state)
{
	(void)state;
	wq_init(&q);
	return 0;
}

static void expect_at(size_t i, uint8_t id, uint8_t addr, uint32_t value)
{
	assert_true(i < q.n);
	if (q.w[i].id != id || q.w[i].addr != addr || q.w[i].value != value)
		fail_msg("w[%zu] = (%u, %u, %u), want (%u, %u, %u)", i, q.w[i].id, q.w[i].addr, q.w[i].value, id,
		         addr, value);
}

/* Sends and acknowledges everything; returns the value the servo ends with in
 * register (id, addr), or -1 if nothing was written there. */
static long drain_to(uint8_t id, uint8_t addr)
{
	long last = -1;
	const struct wq_write *w;
	for (int sends = 0; (w = wq_take(&q)) != NULL; sends++) {
		struct wq_write copy;
		assert_true(sends < WQ_CAP);
		assert_int_equal(wq_done(&q, true, &copy), WQ_DONE);
		if (copy.id == id && copy.addr == addr)
			last = (long)copy.value;
	}
	assert_int_equal(q.n, 0);
	return last;
}

static void test_init_empty(void **state)
{
	(void)state;
	assert_int_equal(wq_pending(&q), 0);
	assert_null(wq_take(&q));
	assert_false(wq_has_id(&q, 1));
	/* a done without a take changes nothing */
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	assert_int_equal(wq_done(&q, false, NULL), WQ_DONE);
	assert_int_equal(q.n, 1);
	assert_int_equal(q.w[0].tries, 0);
	assert_int_equal(q.retried + q.failed, 0);
}

static void test_merge_last_of_servo(void **state)
{
	(void)state;
	/* the last write queued for the servo, same register: updated in place */
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 0));
	assert_int_equal(q.n, 1);
	expect_at(0, 1, R_TORQUE_EN, 0);
	/* another servo's writes in between do not matter */
	assert_true(wq_put(&q, 2, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	assert_int_equal(q.n, 2);
	expect_at(0, 1, R_TORQUE_EN, 1);
	expect_at(1, 2, R_TORQUE_EN, 1);
	/* not the last for its servo: appended, so the order of the servo's
	 * writes is what was asked */
	assert_true(wq_put(&q, 1, R_TORQUE_LIMIT, 2, 1023));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 0));
	assert_int_equal(q.n, 4);
	expect_at(0, 1, R_TORQUE_EN, 1);
	expect_at(2, 1, R_TORQUE_LIMIT, 1023);
	expect_at(3, 1, R_TORQUE_EN, 0);
	/* the same register with another width is another write */
	assert_true(wq_put(&q, 2, R_TORQUE_EN, 2, 5));
	assert_int_equal(q.n, 5);
	expect_at(1, 2, R_TORQUE_EN, 1);
	assert_int_equal(drain_to(1, R_TORQUE_EN), 0);
}

static void test_taken_never_changed(void **state)
{
	(void)state;
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	const struct wq_write *w = wq_take(&q);
	assert_non_null(w);
	assert_int_equal(w->value, 1);
	assert_int_equal(w->tries, 1);
	/* a second take while one is on the wire: none */
	assert_null(wq_take(&q));
	/* the later value is queued behind it */
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 0));
	assert_int_equal(q.n, 2);
	assert_int_equal(w->value, 1);
	assert_int_equal(w->tries, 1);
	/* ... and merges there, not into the taken one */
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 0));
	assert_int_equal(q.n, 2);
	expect_at(0, 1, R_TORQUE_EN, 1);
	expect_at(1, 1, R_TORQUE_EN, 0);
	/* failed: sent again as it was */
	struct wq_write copy;
	assert_int_equal(wq_done(&q, false, &copy), WQ_RETRY);
	assert_int_equal(copy.value, 1);
	w = wq_take(&q);
	assert_int_equal(w->value, 1);
	assert_int_equal(w->tries, 2);
	assert_int_equal(wq_done(&q, true, &copy), WQ_DONE);
	assert_int_equal(copy.value, 1);
	assert_int_equal(copy.tries, 2);
	/* the servo ends with the later value */
	assert_int_equal(drain_to(1, R_TORQUE_EN), 0);
}

/* HOLD queues the torque limit back and torque on; LIMP then asks torque
 * off. Whatever part of HOLD is on the wire, torque off is the servo's last
 * write to register 24. */
static void hold_then_limp(int taken_before_limp)
{
	wq_init(&q);
	assert_true(wq_put(&q, 1, R_TORQUE_LIMIT, 2, 1023));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	for (int i = 0; i < taken_before_limp; i++) {
		assert_non_null(wq_take(&q));
		if (i + 1 < taken_before_limp)
			assert_int_equal(wq_done(&q, true, NULL), WQ_DONE);
	}
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 0));
	/* the last write queued for servo 1 is torque off */
	size_t last = q.n;
	for (size_t i = 0; i < q.n; i++)
		if (q.w[i].id == 1)
			last = i;
	expect_at(last, 1, R_TORQUE_EN, 0);
	if (taken_before_limp > 0)
		assert_int_equal(wq_done(&q, true, NULL), WQ_DONE);
	assert_int_equal(drain_to(1, R_TORQUE_EN), 0);
}

static void test_limp_after_hold(void **state)
{
	(void)state;
	hold_then_limp(0);   /* nothing sent yet: torque on becomes torque off */
	hold_then_limp(1);   /* the torque limit on the wire */
	hold_then_limp(2);   /* torque on on the wire: torque off after it */
	/* a write for the servo queued between HOLD and LIMP */
	wq_init(&q);
	assert_true(wq_put(&q, 1, R_TORQUE_LIMIT, 2, 1023));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 1, R_MARGINS, 2, 0x0101));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 0));
	assert_int_equal(q.n, 4);
	expect_at(3, 1, R_TORQUE_EN, 0);
	assert_int_equal(drain_to(1, R_TORQUE_EN), 0);
}

static void test_sequence_order(void **state)
{
	(void)state;
	/* a wheel-mode switch back for two servos: torque off, limits, torque on,
	 * each exactly as queued, never merged */
	for (uint8_t id = 1; id <= 2; id++) {
		assert_true(wq_put_seq(&q, id, R_TORQUE_EN, 1, 0));
		assert_true(wq_put_seq(&q, id, R_ANGLE_LIMITS, 4, 0x03ff0000u));
		assert_true(wq_put_seq(&q, id, R_TORQUE_EN, 1, 1));
	}
	assert_true(wq_put_seq(&q, 2, R_TORQUE_EN, 1, 1));   /* the same as the last: still appended */
	assert_int_equal(q.n, 7);
	const uint8_t want_id[] = { 1, 1, 1, 2, 2, 2, 2 };
	const uint8_t want_addr[] = { R_TORQUE_EN, R_ANGLE_LIMITS, R_TORQUE_EN, R_TORQUE_EN, R_ANGLE_LIMITS,
		                      R_TORQUE_EN, R_TORQUE_EN };
	const uint32_t want_value[] = { 0, 0x03ff0000u, 1, 0, 0x03ff0000u, 1, 1 };
	for (size_t i = 0; i < 7; i++) {
		const struct wq_write *w = wq_take(&q);
		assert_non_null(w);
		assert_int_equal(w->id, want_id[i]);
		assert_int_equal(w->addr, want_addr[i]);
		assert_int_equal(w->value, want_value[i]);
		assert_int_equal(w->len, want_addr[i] == R_ANGLE_LIMITS ? 4 : 1);
		/* a failure in the middle repeats that write, not the sequence */
		if (i == 3) {
			assert_int_equal(wq_done(&q, false, NULL), WQ_RETRY);
			w = wq_take(&q);
			assert_int_equal(w->id, 2);
			assert_int_equal(w->value, 0);
		}
		assert_int_equal(wq_done(&q, true, NULL), WQ_DONE);
	}
	assert_null(wq_take(&q));
	/* a torque off after a sequence still ends it off */
	assert_true(wq_put_seq(&q, 1, R_TORQUE_EN, 1, 0));
	assert_true(wq_put_seq(&q, 1, R_ANGLE_LIMITS, 4, 0));
	assert_true(wq_put_seq(&q, 1, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 0));
	assert_int_equal(drain_to(1, R_TORQUE_EN), 0);
}

static void test_retries(void **state)
{
	(void)state;
	assert_true(wq_put(&q, 3, R_TORQUE_LIMIT, 2, 512));
	assert_true(wq_put(&q, 4, R_TORQUE_EN, 1, 1));
	struct wq_write copy;
	for (int send = 1; send <= WQ_TRIES; send++) {
		const struct wq_write *w = wq_take(&q);
		assert_non_null(w);
		assert_int_equal(w->id, 3);
		assert_int_equal(w->tries, send);
		memset(&copy, 0, sizeof copy);
		enum wq_outcome o = wq_done(&q, false, &copy);
		assert_int_equal(o, send < WQ_TRIES ? WQ_RETRY : WQ_FAILED);
		assert_int_equal(copy.id, 3);
		assert_int_equal(copy.value, 512);
		assert_int_equal(copy.tries, send);
	}
	/* given up: the next write comes */
	assert_int_equal(q.sent, WQ_TRIES);
	assert_int_equal(q.retried, WQ_TRIES - 1);
	assert_int_equal(q.failed, 1);
	assert_int_equal(q.n, 1);
	assert_false(wq_has(&q, 3, R_TORQUE_LIMIT));
	const struct wq_write *w = wq_take(&q);
	assert_int_equal(w->id, 4);
	assert_int_equal(w->tries, 1);
	assert_int_equal(wq_done(&q, true, NULL), WQ_DONE);
	assert_int_equal(q.sent, WQ_TRIES + 1);
	assert_int_equal(q.failed, 1);

	/* a new value for a write that failed (not on the wire, the last of its
	 * servo) replaces it and gets its own WQ_TRIES sends */
	assert_true(wq_put(&q, 5, R_TORQUE_EN, 1, 1));
	assert_non_null(wq_take(&q));
	assert_int_equal(wq_done(&q, false, NULL), WQ_RETRY);
	assert_true(wq_put(&q, 5, R_TORQUE_EN, 1, 0));
	assert_int_equal(q.n, 1);
	assert_int_equal(q.w[0].tries, 0);
	for (int send = 1; send <= WQ_TRIES; send++) {
		w = wq_take(&q);
		assert_int_equal(w->value, 0);
		assert_int_equal(wq_done(&q, false, NULL), send < WQ_TRIES ? WQ_RETRY : WQ_FAILED);
	}
	assert_int_equal(q.n, 0);
}

static void test_overflow(void **state)
{
	(void)state;
	/* WQ_CAP writes that cannot merge: distinct servos and registers */
	for (size_t i = 0; i < WQ_CAP; i++)
		assert_true(wq_put(&q, (uint8_t)(i % 250), (uint8_t)(i / 250), 1, (uint32_t)i));
	assert_int_equal(wq_pending(&q), WQ_CAP);
	struct wq before = q;
	/* one more: refused, counted, nothing changed */
	assert_false(wq_put(&q, 251, R_TORQUE_EN, 1, 0));
	assert_false(wq_put_seq(&q, 1, R_TORQUE_EN, 1, 0));
	assert_int_equal(q.overflowed, 2);
	assert_int_equal(q.n, WQ_CAP);
	assert_memory_equal(q.w, before.w, sizeof q.w);
	assert_false(wq_has_id(&q, 251));
	/* an update in place needs no room: the newest value still lands */
	assert_true(wq_put(&q, 5, 1, 1, 999));   /* w[255] = (5, 1): the last for servo 5 */
	assert_int_equal(q.w[WQ_CAP - 1].value, 999);
	assert_int_equal(q.overflowed, 2);
	/* room again after one is sent */
	assert_non_null(wq_take(&q));
	assert_int_equal(wq_done(&q, true, NULL), WQ_DONE);
	assert_true(wq_put(&q, 251, R_TORQUE_EN, 1, 0));
	assert_int_equal(q.n, WQ_CAP);
	assert_int_equal(q.overflowed, 2);
}

static void test_drop_id(void **state)
{
	(void)state;
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 2, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 1, R_TORQUE_LIMIT, 2, 1023));
	assert_true(wq_put(&q, 3, R_MARGINS, 2, 0x0101));
	assert_true(wq_put(&q, 1, R_MARGINS, 2, 0x0101));
	const struct wq_write *w = wq_take(&q);
	assert_int_equal(w->id, 1);
	/* servo 1 starts from scratch: its queued writes go, the one on the wire stays */
	wq_drop_id(&q, 1);
	assert_int_equal(q.n, 3);
	assert_true(q.taken);
	expect_at(0, 1, R_TORQUE_EN, 1);
	expect_at(1, 2, R_TORQUE_EN, 1);
	expect_at(2, 3, R_MARGINS, 0x0101);
	assert_true(wq_has_id(&q, 1));
	assert_false(wq_has(&q, 1, R_TORQUE_LIMIT));
	/* its outcome is still reported for it */
	struct wq_write copy;
	assert_int_equal(wq_done(&q, true, &copy), WQ_DONE);
	assert_int_equal(copy.id, 1);
	assert_int_equal(copy.addr, R_TORQUE_EN);
	assert_false(wq_has_id(&q, 1));
	/* nothing on the wire: everything of the servo goes */
	assert_true(wq_put(&q, 2, R_TORQUE_LIMIT, 2, 100));
	wq_drop_id(&q, 2);
	assert_int_equal(q.n, 1);
	expect_at(0, 3, R_MARGINS, 0x0101);
	wq_drop_id(&q, 9);
	assert_int_equal(q.n, 1);
}

static void test_has(void **state)
{
	(void)state;
	assert_false(wq_has(&q, 1, R_TORQUE_EN));
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 2, R_TORQUE_LIMIT, 2, 1));
	assert_true(wq_has(&q, 1, R_TORQUE_EN));
	assert_true(wq_has(&q, 2, R_TORQUE_LIMIT));
	assert_false(wq_has(&q, 1, R_TORQUE_LIMIT));
	assert_false(wq_has(&q, 2, R_TORQUE_EN));
	assert_true(wq_has_id(&q, 1));
	assert_true(wq_has_id(&q, 2));
	assert_false(wq_has_id(&q, 3));
	/* on the wire counts: what the servo reports may be about to change */
	assert_non_null(wq_take(&q));
	assert_true(wq_has(&q, 1, R_TORQUE_EN));
	assert_true(wq_has_id(&q, 1));
	assert_int_equal(wq_done(&q, true, NULL), WQ_DONE);
	assert_false(wq_has(&q, 1, R_TORQUE_EN));
	assert_false(wq_has_id(&q, 1));
	assert_true(wq_has_id(&q, 2));
}

static void test_clear(void **state)
{
	(void)state;
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 2, R_TORQUE_EN, 1, 1));
	assert_non_null(wq_take(&q));
	wq_clear(&q);
	assert_int_equal(wq_pending(&q), 0);
	assert_false(wq_has_id(&q, 1));
	assert_null(wq_take(&q));
	/* the outcome of what was on the wire when the bus went away: nothing to pop */
	assert_int_equal(wq_done(&q, false, NULL), WQ_DONE);
	assert_int_equal(q.n, 0);
	/* usable again */
	assert_true(wq_put(&q, 1, R_TORQUE_EN, 1, 0));
	const struct wq_write *w = wq_take(&q);
	assert_non_null(w);
	assert_int_equal(w->value, 0);
}

/* Random puts, sequences, takes, failures and acknowledgements against a
 * servo that keeps every write it acknowledged (and, at random, a failed
 * one: the reply was lost, not the write). Each write is acknowledged within
 * WQ_TRIES sends, so nothing is given up. Checked: a taken write comes back
 * from wq_done unchanged, and once everything is sent every register holds
 * the last value asked for it. */
static void test_random_against_servo(void **state)
{
	(void)state;
	enum { IDS = 4, ADDRS = 3 };
	const uint8_t addrs[ADDRS] = { R_TORQUE_EN, R_MARGINS, R_TORQUE_LIMIT };
	const uint8_t lens[ADDRS] = { 1, 2, 2 };
	unsigned seed = 4242;
	for (int round = 0; round < 300; round++) {
		long want[IDS][ADDRS], servo[IDS][ADDRS];
		for (int i = 0; i < IDS; i++)
			for (int a = 0; a < ADDRS; a++)
				want[i][a] = servo[i][a] = -1;
		wq_init(&q);
		struct wq_write on_wire;
		bool busy = false;
		for (int step = 0; step < 200; step++) {
			seed = seed * 1103515245u + 12345u;
			unsigned r = (seed >> 16) % 100;
			seed = seed * 1103515245u + 12345u;
			int id = (int)((seed >> 16) % IDS), a = (int)((seed >> 20) % ADDRS);
			uint32_t v = (seed >> 8) % 1024;
			if (r < 45) {
				bool seq = r < 10;
				assert_true(seq ? wq_put_seq(&q, (uint8_t)(id + 1), addrs[a], lens[a], v)
				                : wq_put(&q, (uint8_t)(id + 1), addrs[a], lens[a], v));
				want[id][a] = v;
			} else if (!busy) {
				const struct wq_write *w = wq_take(&q);
				if (w != NULL) {
					on_wire = *w;
					busy = true;
				}
			} else {
				bool ok = r >= 75 || on_wire.tries >= WQ_TRIES;
				struct wq_write back;
				enum wq_outcome o = wq_done(&q, ok, &back);
				assert_memory_equal(&back, &on_wire, sizeof back);
				assert_int_equal(o, ok ? WQ_DONE : WQ_RETRY);
				int bi = back.id - 1, ba = 0;
				while (addrs[ba] != back.addr)
					ba++;
				if (ok || r % 2 == 0)
					servo[bi][ba] = (long)back.value;
				busy = false;
			}
		}
		if (busy) {
			struct wq_write back;
			assert_int_equal(wq_done(&q, true, &back), WQ_DONE);
			assert_memory_equal(&back, &on_wire, sizeof back);
			int ba = 0;
			while (addrs[ba] != back.addr)
				ba++;
			servo[back.id - 1][ba] = (long)back.value;
		}
		const struct wq_write *w;
		for (int sends = 0; (w = wq_take(&q)) != NULL; sends++) {
			assert_true(sends < WQ_CAP);
			int bi = w->id - 1, ba = 0;
			while (addrs[ba] != w->addr)
				ba++;
			servo[bi][ba] = (long)w->value;
			assert_int_equal(wq_done(&q, true, NULL), WQ_DONE);
		}
		for (int i = 0; i < IDS; i++)
			for (int a = 0; a < ADDRS; a++)
				if (servo[i][a] != want[i][a])
					fail_msg("round %d: servo %d register %u holds %ld, %ld was asked last", round, i + 1,
					         addrs[a], servo[i][a], want[i][a]);
		assert_int_equal(q.failed, 0);
		assert_int_equal(q.overflowed, 0);
	}
}

/* An X servo's mode switch as a chain: a step given up takes the rest of its
 * chain with it (never torque on in a mode that was not set), but not the
 * other servo's writes, nor a torque-off queued behind the chain, which is
 * never merged into the chain's own torque-on. */
#define X_TORQUE_EN 64
#define X_MODE 11
#define X_GOAL_PWM 100
static void test_chain_stops_at_failed_step(void **state)
{
	(void)state;
	uint16_t ch = wq_chain(&q);
	assert_true(ch != 0);
	assert_true(wq_put_chain(&q, ch, 1, X_TORQUE_EN, 1, 0));
	assert_true(wq_put_chain(&q, ch, 1, X_MODE, 1, 16));
	assert_true(wq_put_chain(&q, ch, 1, X_GOAL_PWM, 2, 0));
	assert_true(wq_put_chain(&q, ch, 1, X_TORQUE_EN, 1, 1));
	assert_true(wq_put(&q, 2, X_TORQUE_EN, 1, 1));
	/* LIMP queued behind the chain: appended, not merged into its torque-on */
	assert_true(wq_put(&q, 1, X_TORQUE_EN, 1, 0));
	assert_int_equal(q.n, 6);
	expect_at(3, 1, X_TORQUE_EN, 1);
	expect_at(5, 1, X_TORQUE_EN, 0);
	/* torque off goes through; the mode is refused three times */
	assert_non_null(wq_take(&q));
	assert_int_equal(wq_done(&q, true, NULL), WQ_DONE);
	for (int t = 1; t < WQ_TRIES; t++) {
		assert_non_null(wq_take(&q));
		assert_int_equal(wq_done(&q, false, NULL), WQ_RETRY);
	}
	struct wq_write w;
	assert_non_null(wq_take(&q));
	assert_int_equal(wq_done(&q, false, &w), WQ_FAILED);
	assert_int_equal(w.addr, X_MODE);
	/* Goal PWM 0 and torque on went with it; servo 2 and the LIMP stay */
	assert_int_equal(q.chain_dropped, 2);
	assert_int_equal(q.n, 2);
	expect_at(0, 2, X_TORQUE_EN, 1);
	expect_at(1, 1, X_TORQUE_EN, 0);
	assert_int_equal(drain_to(1, X_TORQUE_EN), 0);
}

/* A chain that goes through is sent in order, whole; chains are numbered
 * apart, so one failing leaves the next. A REBOOT (len 0) is a step too. */
static void test_chain_whole_and_apart(void **state)
{
	(void)state;
	uint16_t a = wq_chain(&q), b = wq_chain(&q);
	assert_true(a != b);
	assert_true(wq_put_chain(&q, a, 3, 0, 0, 0));   /* REBOOT */
	assert_true(wq_put_chain(&q, a, 3, X_TORQUE_EN, 1, 1));
	assert_true(wq_put_chain(&q, b, 3, X_GOAL_PWM, 2, 885));
	/* a plain write of the chain's register is appended, never merged */
	assert_true(wq_put(&q, 3, X_GOAL_PWM, 2, 400));
	assert_int_equal(q.n, 4);
	for (int t = 0; t < WQ_TRIES; t++) {
		assert_non_null(wq_take(&q));
		assert_int_equal(q.w[0].len, 0);
		assert_int_equal(wq_done(&q, false, NULL), t + 1 < WQ_TRIES ? WQ_RETRY : WQ_FAILED);
	}
	/* chain a lost its torque-on; chain b and the plain write remain */
	assert_int_equal(q.n, 2);
	expect_at(0, 3, X_GOAL_PWM, 885);
	expect_at(1, 3, X_GOAL_PWM, 400);
	assert_int_equal(drain_to(3, X_GOAL_PWM), 400);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_setup(test_init_empty, setup),
		cmocka_unit_test_setup(test_merge_last_of_servo, setup),
		cmocka_unit_test_setup(test_taken_never_changed, setup),
		cmocka_unit_test_setup(test_limp_after_hold, setup),
		cmocka_unit_test_setup(test_sequence_order, setup),
		cmocka_unit_test_setup(test_retries, setup),
		cmocka_unit_test_setup(test_overflow, setup),
		cmocka_unit_test_setup(test_drop_id, setup),
		cmocka_unit_test_setup(test_has, setup),
		cmocka_unit_test_setup(test_clear, setup),
		cmocka_unit_test_setup(test_chain_stops_at_failed_step, setup),
		cmocka_unit_test_setup(test_chain_whole_and_apart, setup),
		cmocka_unit_test(test_random_against_servo),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
