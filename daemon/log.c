/* log.c — see log.h. */
#include "log.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

static enum log_level log_threshold = LOG_LVL_INFO;
/* The program named in front of every line: the daemon's modules also run
 * inside `dxl doctor`. */
static const char *log_program = "undulated";

void log_set_program(const char *name) { log_program = name != NULL ? name : "undulated"; }

void log_set_level(enum log_level level) { log_threshold = level; }
enum log_level log_get_level(void) { return log_threshold; }

bool log_level_parse(const char *name, enum log_level *out)
{
	static const struct { const char *name; enum log_level level; } names[] = {
		{ "error", LOG_LVL_ERROR }, { "warn", LOG_LVL_WARN }, { "warning", LOG_LVL_WARN },
		{ "info", LOG_LVL_INFO }, { "debug", LOG_LVL_DEBUG },
	};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
		if (strcasecmp(name, names[i].name) == 0) {
			*out = names[i].level;
			return true;
		}
	}
	return false;
}

static const char *log_prefix(enum log_level level)
{
	switch (level) {
	case LOG_LVL_ERROR: return "error";
	case LOG_LVL_WARN: return "warning";
	case LOG_LVL_INFO: return "info";
	default: return "debug";
	}
}

/* Under systemd, stderr goes to the journal when JOURNAL_STREAM names its
 * device:inode; a "<N>" syslog priority prefix then lets `journalctl -p
 * warning` select our warnings (sd-daemon(3)). Decided once, at the first line. */
static int log_journal = -1;

static bool log_to_journal(void)
{
	if (log_journal < 0) {
		const char *js = getenv("JOURNAL_STREAM");
		unsigned long long dev = 0, ino = 0;
		struct stat st;
		log_journal = js && sscanf(js, "%llu:%llu", &dev, &ino) == 2 && fstat(2, &st) == 0 &&
		              (unsigned long long)st.st_dev == dev && (unsigned long long)st.st_ino == ino;
	}
	return log_journal == 1;
}

static int log_syslog_priority(enum log_level level)
{
	switch (level) {
	case LOG_LVL_ERROR: return 3;
	case LOG_LVL_WARN: return 4;
	case LOG_LVL_INFO: return 6;
	default: return 7;
	}
}

static void log_vmsg(enum log_level level, const char *suffix, const char *fmt, va_list ap)
{
	if (level > log_threshold)
		return;
	/* One fprintf per line: stderr is unbuffered and journald splits on writes. */
	char line[512];
	vsnprintf(line, sizeof line, fmt, ap);
	if (log_to_journal())
		fprintf(stderr, "<%d>%s: %s: %s%s\n", log_syslog_priority(level), log_program, log_prefix(level), line,
		        suffix);
	else
		fprintf(stderr, "%s: %s: %s%s\n", log_program, log_prefix(level), line, suffix);
}

void log_msg(enum log_level level, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	log_vmsg(level, "", fmt, ap);
	va_end(ap);
}

bool log_limit_allow(struct log_limit *lim, uint64_t now_us, uint32_t *suppressed_before)
{
	if (!lim->primed) {
		lim->tokens = lim->burst;
		lim->last_refill_us = now_us;
		lim->primed = true;
	}
	if (lim->interval_us > 0 && now_us > lim->last_refill_us) {
		uint64_t earned = (now_us - lim->last_refill_us) / lim->interval_us;
		if (earned > 0) {
			uint64_t t = lim->tokens + earned;
			lim->tokens = t > lim->burst ? lim->burst : (uint32_t)t;
			lim->last_refill_us += earned * lim->interval_us;
		}
	}
	*suppressed_before = 0;
	if (lim->tokens == 0) {
		lim->suppressed++;
		return false;
	}
	lim->tokens--;
	*suppressed_before = lim->suppressed;
	lim->suppressed = 0;
	return true;
}

bool log_limited(struct log_limit *lim, uint64_t now_us, enum log_level level, const char *fmt, ...)
{
	uint32_t dropped;
	if (!log_limit_allow(lim, now_us, &dropped))
		return false;
	char suffix[64] = "";
	if (dropped > 0)
		snprintf(suffix, sizeof suffix, " (%u similar messages suppressed)", (unsigned)dropped);
	va_list ap;
	va_start(ap, fmt);
	log_vmsg(level, suffix, fmt, ap);
	va_end(ap);
	return true;
}
