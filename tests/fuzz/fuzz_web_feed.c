/*
 * fuzz_web_feed.c — libFuzzer target for every message type as it reaches the
 * monitors: LCM payloads on each channel undulate-top and undulate-web
 * subscribe to (<robot>.STATE, .BUS, .PARAMS, .EVENT, SIM.TRUTH,
 * SIM.COLLISION), decoded through lcmdec (compat/lcm/lcmdec.h) by top_feed()
 * into the model both programs draw and the web's history after every message
 * (SIM.TRUTH's contacts summed, closed into marks every few messages), then the
 * web's JSON frame (with the world) and undulate-top's JSON snapshot of the result.
 *
 * Input: one byte of flags (bit 0: keep the web's history and write its frame;
 * the history is 2 MB to clear, so half the inputs skip it and run faster),
 * then a sequence of records, each
 *     1 byte  the channel (its value modulo the six; bit 7: a second robot's)
 *     2 bytes length (big-endian), then that many bytes of payload
 * Invariants (abort() on violation): every record is either taken or counted
 * in decode_errors; a frame always fits its buffer and is one line; the model never holds more than TOP_MAX_ROBOTS
 * robots, a world contact never names a robot it does not hold. ASan/UBSan
 * find the rest.
 *
 *   make fuzz-build && build/fuzz/fuzz_web_feed tests/fuzz/seeds/fuzz_web_feed
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_records.h"
#include "tools/top/feed.h"
#include "tools/web/frame.h"
#include "tools/web/hist.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

static struct top_model model;
static struct hist hist;
static char frame[1 << 20];

static void fuzz_on_truth(const struct top_model *m, double now, void *user)
{
	(void)now;
	if (user != NULL)
		wct_add(&hist.contacts, m);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static const char *const channels[2][6] = {
		{ "r1.STATE", "r1.BUS", "r1.PARAMS", "r1.EVENT", "SIM.TRUTH", "SIM.COLLISION" },
		{ "r2.STATE", "r2.BUS", "r2.PARAMS", "r2.EVENT", "SIM.TRUTH", "SIM.COLLISION" },
	};
	static FILE *null;
	if (null == NULL)
		null = fopen("/dev/null", "w");
	if (size == 0)
		return 0;
	bool web = data[0] & 1;
	top_model_init(&model);
	double now = 100.0;
	struct frame_cursor cur;
	if (web) {
		hist_init(&hist, now);
		frame_cursor_init(&cur, &hist);
	}
	const struct top_feed_hooks hooks = { .on_truth = fuzz_on_truth, .user = web ? &hist : NULL };
	int64_t records = 0, taken = 0;
	size_t pos = 1;
	uint8_t sel;
	const uint8_t *rec;
	size_t len;
	while (fuzz_next_record(data, size, &pos, &sel, &rec, &len)) {
		char why[160];
		records++;
		if (top_feed(&model, channels[sel >> 7][(sel & 0x7f) % 6], rec, len, now, &hooks, why, sizeof why))
			taken++;
		else
			CHECK(why[0] != '\0');
		now += 0.01;
		for (int i = 0; i < model.world.ncontacts; i++) {
			const struct top_contact *c = &model.world.contacts[i];
			CHECK(c->a >= 0 && c->a < model.nrobots && c->b >= -1 && c->b < model.nrobots);
		}
		if (web) {
			hist_sample(&hist, &model, now);
			if (records % 4 == 0)
				hist_close_contacts(&hist, now);
		}
	}
	if (web) {
		size_t n = frame_write(&hist, &model, now, &cur, NULL, NULL, 0, frame, sizeof frame);
		CHECK(n < sizeof frame);
		CHECK(memchr(frame, '\n', n) == NULL);
	}
	CHECK(taken + model.decode_errors == records);
	CHECK(model.nrobots <= TOP_MAX_ROBOTS);
	top_model_order(&model);
	top_json(&model, now, 0, null);
	return 0;
}
