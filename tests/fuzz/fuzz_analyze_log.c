/*
 * fuzz_analyze_log.c — libFuzzer target for every message type as it reaches
 * undulate-analyze: a log (written here with LCM's own eventlog writer) whose
 * events are the fuzzer's payloads on the channels the analyser reads
 * (<robot>.STATE, .BUS, .PARAMS, .EVENT, .CMD, SIM.TRUTH, SIM.COLLISION,
 * SIM.WORLD), analysed whole by an_run() into a private output folder, the
 * CSVs and the summary included (no plots: gnuplot is another program).
 *
 * Input: a sequence of records, each
 *     1 byte  the channel (modulo the eight; bit 7: robot r2 instead of r1)
 *     1 byte  the time step to the event (ms)
 *     2 bytes length (big-endian), then that many bytes of payload
 * Invariant: an_run() returns one of its exit codes. ASan/UBSan find the rest.
 *
 *   make fuzz-build && build/fuzz/fuzz_analyze_log tests/fuzz/seeds/fuzz_analyze_log
 */
#include <lcm/eventlog.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tools/analyze/analyze.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

static char dir[64], log_path[96], out_path[96];

static void fuzz_setup(void)
{
	snprintf(dir, sizeof dir, "/tmp/fuzz-analyze.XXXXXX");
	CHECK(mkdtemp(dir) != NULL);
	snprintf(log_path, sizeof log_path, "%s/run.lcmlog", dir);
	snprintf(out_path, sizeof out_path, "%s/out", dir);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static const char *const channels[2][8] = {
		{ "r1.STATE", "r1.BUS", "r1.PARAMS", "r1.EVENT", "r1.CMD", "SIM.TRUTH", "SIM.COLLISION", "SIM.WORLD" },
		{ "r2.STATE", "r2.BUS", "r2.PARAMS", "r2.EVENT", "r2.CMD", "SIM.TRUTH", "SIM.COLLISION", "SIM.WORLD" },
	};
	static FILE *null;
	if (null == NULL) {
		null = fopen("/dev/null", "w");
		fuzz_setup();
	}
	lcm_eventlog_t *log = lcm_eventlog_create(log_path, "w");
	CHECK(log != NULL);
	int64_t t = 1700000000000000;
	size_t pos = 0;
	int64_t n = 0;
	while (pos + 4 <= size) {
		uint8_t sel = data[pos];
		t += 1000 * (int64_t)data[pos + 1];
		size_t len = (size_t)data[pos + 2] << 8 | data[pos + 3];
		pos += 4;
		if (len > size - pos)
			len = size - pos;
		const char *ch = channels[sel >> 7][(sel & 0x7f) % 8];
		lcm_eventlog_event_t ev = { .eventnum = n++, .timestamp = t, .channellen = (int32_t)strlen(ch),
					    .datalen = (int32_t)len, .channel = (char *)ch, .data = (void *)(data + pos) };
		CHECK(lcm_eventlog_write_event(log, &ev) == 0);
		pos += len;
	}
	lcm_eventlog_destroy(log);
	struct an_options o;
	an_options_default(&o);
	o.logs[0] = log_path;
	o.nlogs = 1;
	o.out_dir = out_path;
	o.quiet = true;
	/* a window of a minute (--to 60): a message whose utime lies far ahead
	 * would otherwise make every run write ten days of 1 s bins (bounded,
	 * AN_MAX_BINS, but 0.9 M CSV rows a run) */
	o.to_s = 60.0;
	o.msg = null;
	int rc = an_run(&o);
	CHECK(rc >= 0 && rc < 16);
	return 0;
}
