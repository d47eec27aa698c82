/*
 * codec.c — throughput of the pure framing code, for the benchmark suite:
 * one READ(36, 6) round trip as both ends see it, with no I/O:
 *   the controller encodes the request, the servo side parses it,
 *   the servo side encodes the 6-byte status, the controller parses it.
 * Built by bench/run.sh against libprotocol.a.
 *
 *   codec [--seconds S]      prints "key value" lines
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dxl.h"
#include "dxl_table.h"

/* Round trips between two clock reads: keeps the clock out of the figure. */
#define CODEC_BATCH 4096
#define CODEC_READ_LEN 6

static double codec_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Parse a whole buffer; 0 when exactly one frame came out of it. */
static int codec_parse(struct dxl_parser *p, const uint8_t *buf, size_t n, struct dxl_packet *out)
{
	size_t used = 0;
	int r = dxl_parser_feed(p, buf, n, &used, out);
	return r == DXL_FRAME && used == n ? 0 : -1;
}

/* One round trip; returns a value derived from the data so it cannot be optimised away. */
static int codec_round_trip(struct dxl_parser *servo, struct dxl_parser *ctl, uint8_t id, uint32_t *sink)
{
	uint8_t req[DXL_MAX_PACKET], rep[DXL_MAX_PACKET], params[CODEC_READ_LEN];
	struct dxl_packet in, out;
	int n = dxl_encode_read(req, sizeof req, id, DXL_AX_PRESENT_POSITION, CODEC_READ_LEN);
	if (n < 0 || codec_parse(servo, req, (size_t)n, &in) != 0 || in.nparams != 2)
		return -1;
	for (int i = 0; i < CODEC_READ_LEN; i++)
		params[i] = (uint8_t)(in.params[0] + i + *sink);
	n = dxl_encode_status(rep, sizeof rep, in.id, 0, params, CODEC_READ_LEN);
	if (n < 0 || codec_parse(ctl, rep, (size_t)n, &out) != 0 || out.nparams != CODEC_READ_LEN)
		return -1;
	*sink += dxl_get_u16(out.params);
	return 0;
}

int main(int argc, char **argv)
{
	double seconds = 1.0;
	if (argc == 3 && !strcmp(argv[1], "--seconds"))
		seconds = atof(argv[2]);
	else if (argc != 1) {
		fprintf(stderr, "usage: codec [--seconds S]\n");
		return 2;
	}
	struct dxl_parser servo, ctl;
	dxl_parser_init(&servo, DXL_PARSE_INSTRUCTION);
	dxl_parser_init(&ctl, DXL_PARSE_STATUS);
	uint32_t sink = 0;
	uint64_t trips = 0;
	double t0 = codec_now(), t;
	do {
		for (int i = 0; i < CODEC_BATCH; i++)
			if (codec_round_trip(&servo, &ctl, (uint8_t)(1 + i % 18), &sink) != 0) {
				fprintf(stderr, "codec: round trip failed (framing bug?)\n");
				return 1;
			}
		trips += CODEC_BATCH;
		t = codec_now();
	} while (t - t0 < seconds);
	printf("round_trips %" PRIu64 "\nseconds %.3f\n", trips, t - t0);
	printf("round_trips_per_s %.0f\nns_per_round_trip %.1f\n", (double)trips / (t - t0),
	       1e9 * (t - t0) / (double)trips);
	printf("sink %" PRIu32 "\n", sink);
	return 0;
}
