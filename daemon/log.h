/*
 * log.h — the daemon's stderr log: levels, and rate limiting for messages that
 * can repeat every cycle (bus timeouts, bad commands), so a fault cannot flood
 * the journal or cost the loop its period.
 */
#ifndef UNDULATE_DAEMON_LOG_H
#define UNDULATE_DAEMON_LOG_H

#include <stdbool.h>
#include <stdint.h>

enum log_level { LOG_LVL_ERROR = 0, LOG_LVL_WARN = 1, LOG_LVL_INFO = 2, LOG_LVL_DEBUG = 3 };

void log_set_level(enum log_level level);
/* The name in front of every line ("undulated" unless set; a static string). */
void log_set_program(const char *name);
enum log_level log_get_level(void);
/* "error", "warn"/"warning", "info", "debug" -> level; false if unknown. */
bool log_level_parse(const char *name, enum log_level *out);

void log_msg(enum log_level level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
#define log_error(...) log_msg(LOG_LVL_ERROR, __VA_ARGS__)
#define log_warn(...)  log_msg(LOG_LVL_WARN, __VA_ARGS__)
#define log_info(...)  log_msg(LOG_LVL_INFO, __VA_ARGS__)
#define log_debug(...) log_msg(LOG_LVL_DEBUG, __VA_ARGS__)

/* A token bucket per message site: `burst` messages, then one per
 * `interval_us`; the next message that passes says how many were dropped. */
struct log_limit {
	uint32_t burst;
	uint64_t interval_us;
	uint32_t tokens;
	uint64_t last_refill_us;
	uint32_t suppressed;
	bool primed;
};
#define LOG_LIMIT_INIT(burst_, interval_us_) { .burst = (burst_), .interval_us = (interval_us_) }

/* Log through the limiter; `now_us` is a monotonic time. Returns true if printed. */
bool log_limited(struct log_limit *lim, uint64_t now_us, enum log_level level, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* Pure decision used by log_limited (tests drive it with a fake clock). */
bool log_limit_allow(struct log_limit *lim, uint64_t now_us, uint32_t *suppressed_before);

#endif
