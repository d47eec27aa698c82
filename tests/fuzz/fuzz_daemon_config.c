/*
 * fuzz_daemon_config.c — libFuzzer target for undulated's configuration:
 * arbitrary text as an INI file (cfg_load_string, the parser behind
 * cfg_load_file), then --set overrides (cfg_override), then cfg_finish(), in
 * the order main.c applies them.
 *
 * Input: the INI text, optionally followed by a line "%%" and one override
 * per line ("robot.ids=1,2", "joint.1.k=0.5"). Each part is a C string, as
 * the file's text and argv are: an embedded NUL ends it.
 *
 * Invariants (abort() on violation):
 *  - every error kept is one NUL-terminated line, non-empty, naming where it
 *    came from ("fuzz:..." for the text, "command line: ..." for an
 *    override, "<source>: ..." for the whole-config checks — the file's
 *    name, or "command line" when none was loaded; config.h);
 *  - the count of errors matches what each call returned: a load succeeds
 *    only with no error, an override fails with exactly one, finish() fails
 *    only with new ones;
 *  - a line of at most 199 characters is never "too long", and a longer one
 *    is never accepted (daemon/README.md, "Configuration");
 *  - a configuration accepted with no error at all (what main.c runs) has
 *    every value in its documented range (daemon/README.md): numbers
 *    finite, enums among their names, a robot name of letters, digits,
 *    '_' and '-', a port, 1..CFG_MAX_JOINTS unique servo IDs 0..253, every joint
 *    filled in, limits ordered, containing 0 and inside the servo's ±2.618
 *    rad around neutral, and no joint beyond the IDs configured;
 *  - cfg_print() handles it.
 *
 *   make fuzz-build && build/fuzz/fuzz_daemon_config tests/fuzz/seeds/fuzz_daemon_config
 */
#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../daemon/config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

/* Overrides after the text: at most main.c's MAIN_MAX_OVERRIDES (64); a few
 * reach every key. */
#define FUZZ_MAX_SETS 16
/* The longest line libinih reads (INI_MAX_LINE less the NUL); README: "A line
 * may hold at most 199 characters". */
#define FUZZ_INI_LINE_MAX 199
/* The AX-12's ±150° around its centre. */
#define FUZZ_HALF_RANGE (150.0 * 3.14159265358979323846 / 180.0)
#define FUZZ_PI 3.14159265358979323846

static bool in(double v, double lo, double hi) { return isfinite(v) && v >= lo && v <= hi; }

static bool terminated(const char *s, size_t cap) { return memchr(s, '\0', cap) != NULL; }

/* Errors [from, to) of e, those that were kept: one line each, with its prefix. */
static void check_messages(const struct cfg_errors *e, size_t from, size_t to, const char *prefix)
{
	for (size_t i = from; i < to && i < CFG_MAX_ERRORS; i++) {
		const char *m = e->line[i];
		CHECK(terminated(m, CFG_ERR_MAX));
		CHECK(m[0] != '\0' && strchr(m, '\n') == NULL);
		CHECK(strncmp(m, prefix, strlen(prefix)) == 0);
	}
}

/* The whole message "fuzz:LINE: line too long (...)", not a key or value
 * that happens to say so. */
static bool said_too_long(const struct cfg_errors *e, size_t to)
{
	static const char what[] = ": line too long (the parser reads at most 199 characters of a line)";
	for (size_t i = 0; i < to && i < CFG_MAX_ERRORS; i++) {
		const char *after = e->line[i] + strlen("fuzz:");
		after += strspn(after, "0123456789");
		if (strcmp(after, what) == 0)
			return true;
	}
	return false;
}

static size_t longest_line(const char *text)
{
	size_t longest = 0;
	while (*text) {
		size_t n = strcspn(text, "\n");
		if (n > longest)
			longest = n;
		text += n + (text[n] == '\n');
	}
	return longest;
}

static void check_joint(const struct cfg_joint *j)
{
	CHECK(in(j->osc.k, 0, 1000) && j->osc.k > 0);
	CHECK(in(j->osc.c, -100, 100));
	CHECK(in(j->osc.mu, 0, 1000));
	CHECK(in(j->osc.lambda, -10, 10));
	CHECK(in(j->osc.inertia, 0, 10) && j->osc.inertia > 0);
	CHECK(in(j->osc.friction, 0, 10));
	CHECK(in(j->neutral, -FUZZ_HALF_RANGE, FUZZ_HALF_RANGE));
	CHECK(in(j->limit_min, -2 * FUZZ_HALF_RANGE, 2 * FUZZ_HALF_RANGE));
	CHECK(in(j->limit_max, -2 * FUZZ_HALF_RANGE, 2 * FUZZ_HALF_RANGE));
	CHECK(j->limit_min < j->limit_max && j->limit_min <= 0 && j->limit_max >= 0);
	CHECK(j->neutral + j->limit_min >= -FUZZ_HALF_RANGE - 1e-9);
	CHECK(j->neutral + j->limit_max <= FUZZ_HALF_RANGE + 1e-9);
	CHECK(in(j->max_step, 0, 0.5) && j->max_step > 0);
}

static bool joint_unset(const struct cfg_joint *j)
{
	return isnan(j->osc.k) && isnan(j->osc.c) && isnan(j->osc.mu) && isnan(j->osc.lambda) &&
	       isnan(j->osc.inertia) && isnan(j->osc.friction) && isnan(j->neutral) && isnan(j->limit_min) &&
	       isnan(j->limit_max) && isnan(j->max_step);
}

static void check_config(const struct cfg *c)
{
	/* [robot] */
	CHECK(terminated(c->name, sizeof c->name) && c->name[0] != '\0');
	for (const char *p = c->name; *p; p++)
		CHECK(isalnum((unsigned char)*p) || *p == '_' || *p == '-');
	CHECK(terminated(c->port, sizeof c->port) && terminated(c->usb_serial, sizeof c->usb_serial));
	CHECK(c->port[0] != '\0' || c->usb_serial[0] != '\0');
	CHECK(terminated(c->lcm_url, sizeof c->lcm_url) && terminated(c->source, sizeof c->source));
	CHECK(c->baud >= 9600 && c->baud <= 4500000);
	CHECK(c->njoints >= 1 && c->njoints <= CFG_MAX_JOINTS);
	for (size_t k = 0; k < c->njoints; k++) {
		CHECK(c->ids[k] <= 253);
		for (size_t q = 0; q < k; q++)
			CHECK(c->ids[q] != c->ids[k]);
	}
	CHECK((unsigned)c->mode < CFG_NMODES);
	CHECK(c->priority >= 0 && c->priority <= 99);
	CHECK(c->safe_stop == CFG_SAFE_HOLD || c->safe_stop == CFG_SAFE_LIMP);
	CHECK(c->fault_action == CFG_SAFE_HOLD || c->fault_action == CFG_SAFE_LIMP);
	CHECK(c->velocity_source == CFG_VEL_SERVO || c->velocity_source == CFG_VEL_FILTERED);
	CHECK(in(c->velocity_cutoff_hz, 0.5, 50));
	CHECK(c->adapter_latency_us >= -1 && c->adapter_latency_us <= 100000);
	CHECK(in(c->period_ms, 2, 100));
	CHECK(in(c->servo_lead_s, 0, 0.2));
	CHECK(c->compliance_margin >= -1 && c->compliance_margin <= 255);
	CHECK(c->actuation == CFG_ACT_POSITION || c->actuation == CFG_ACT_TORQUE);
	CHECK(c->torque_drive == CFG_DRIVE_PWM || c->torque_drive == CFG_DRIVE_CURRENT);
	CHECK(in(c->stall_torque, 0.01, 100));
	CHECK(in(c->no_load_speed, 0.01, 1000));
	CHECK(c->bus_margin_us >= 0 && c->bus_margin_us <= 100000);
	CHECK(in(c->ramp_s, 0, 10));
	CHECK(in(c->backoff_torque, 0, 1));
	CHECK(in(c->fault_backoff_s, 0.05, 600));
	CHECK(c->fault_retries >= 0 && c->fault_retries <= 100);
	CHECK(c->stale_limit >= 1 && c->stale_limit <= 1000);
	/* [joint.N]: the robot's joints filled in, none beyond them */
	for (size_t j = 0; j < CFG_MAX_JOINTS; j++) {
		if (j < c->njoints)
			check_joint(&c->joint[j]);
		else
			CHECK(joint_unset(&c->joint[j]));
	}
	/* [sinusoid] */
	CHECK(in(c->amplitude, 0, FUZZ_HALF_RANGE));
	CHECK(in(c->frequency, 0, 5));
	CHECK(in(c->phase, -2 * FUZZ_PI, 2 * FUZZ_PI));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct cfg c;
	static struct cfg_errors e;
	static char text[4096 + 1];
	static char line[1024];
	static FILE *sink;
	if (sink == NULL)
		sink = fopen("/dev/null", "w");
	CHECK(sink != NULL);
	/* the text ends at the first "\n%%\n"; the rest are override lines */
	size_t ini_len = size;
	for (size_t i = 0; i + 4 <= size; i++)
		if (memcmp(data + i, "\n%%\n", 4) == 0) {
			ini_len = i + 1;
			break;
		}
	if (ini_len >= sizeof text)
		return 0;
	memcpy(text, data, ini_len);
	text[ini_len] = '\0';

	cfg_defaults(&c);
	memset(&e, 0x55, sizeof e);   /* every message must be terminated by the code */
	e.count = 0;
	e.file_refused = false;
	bool loaded = cfg_load_string(&c, "fuzz", text, &e);
	CHECK(loaded == (e.count == 0));
	check_messages(&e, 0, e.count, "fuzz:");
	size_t longest = longest_line(text);
	if (longest <= FUZZ_INI_LINE_MAX)
		CHECK(!said_too_long(&e, e.count));
	else
		CHECK(!loaded);

	size_t off = ini_len < size ? ini_len + 3 : size;
	for (int n = 0; off < size && n < FUZZ_MAX_SETS; n++) {
		const uint8_t *nl = memchr(data + off, '\n', size - off);
		size_t len = nl ? (size_t)(nl - (data + off)) : size - off;
		size_t keep = len < sizeof line - 1 ? len : sizeof line - 1;
		memcpy(line, data + off, keep);
		line[keep] = '\0';
		size_t before = e.count;
		bool ok = cfg_override(&c, line, &e);
		CHECK(ok ? e.count == before : e.count == before + 1);
		check_messages(&e, before, e.count, "command line: ");
		off += len + 1;
	}

	/* main.c stops before finish() at the first error; going on explores
	 * more states, but only an error-free configuration is checked */
	size_t before = e.count;
	bool finished = cfg_finish(&c, &e);
	CHECK(finished == (e.count == before));
	/* the whole-config checks name the configuration's source: the file's
	 * name when one was loaded, else the command line */
	char whole[CFG_PATH_MAX + 3];
	snprintf(whole, sizeof whole, "%s: ", c.source[0] ? c.source : "command line");
	check_messages(&e, before, e.count, whole);
	if (before == 0 && finished) {
		check_config(&c);
		cfg_print(&c, sink);
	}
	return 0;
}
