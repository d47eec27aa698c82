/*
 * num.h — numbers from text a person typed (options, config values, commands
 * from the network), parsed strictly and the same way everywhere: the whole
 * string is the number, it fits its type without overflow, it is finite, and
 * it lies in the range the caller names. A value that is "almost" a number
 * ("5 ", "1x", "nan", "1e400") is refused rather than half-read, so a typo
 * fails where it was made instead of becoming 0 or infinity downstream.
 *
 * Accepted forms (the "C" locale; no program here calls setlocale):
 *   integers  [+-]DIGITS, or [+-]0xHEXDIGITS (0X too). Leading zeros are
 *             decimal, never octal: "010" is 10 (people pad register values,
 *             and the AX-12 manual writes addresses in decimal).
 *   doubles   [+-]DIGITS[.DIGITS][e[+-]DIGITS], also ".5" and "5.". Not hex
 *             floats ("0x1p3"), "inf", "infinity" or "nan": no one means those
 *             on a command line. An exponent so small the value underflows
 *             ("1e-400") is accepted as the nearest double (0 or subnormal):
 *             it is a tiny number, not a wrong one.
 * Never accepted: NULL, "", whitespace anywhere (strip it first if the source
 * may carry some, e.g. a line read from a file), anything after the number.
 *
 * Every parser returns NUM_OK and writes *out, or returns why not and leaves
 * *out untouched (so a default stays in place). Note NUM_OK is 0: test with
 * `!= NUM_OK`, not with `!`.
 */
#ifndef UNDULATE_COMMON_NUM_H
#define UNDULATE_COMMON_NUM_H

#include <stdint.h>

enum num_status {
	NUM_OK = 0,
	NUM_EMPTY,    /* NULL or "" */
	NUM_SYNTAX,   /* not a number of the accepted form (see above) */
	NUM_RANGE,    /* a number, but outside [min, max] or beyond the type */
};

/* A phrase that completes "'<text>' is ...": "empty", "not a number",
 * "out of range" (and "ok"). Never NULL. */
const char *num_strerror(enum num_status st);

/* Any finite double. "1e400" is NUM_RANGE. */
enum num_status num_parse_double(const char *s, double *out);

/* A finite double in [min, max] (inclusive; pass -INFINITY / INFINITY for an
 * open side). */
enum num_status num_parse_double_in(const char *s, double min, double max, double *out);

/* An integer in [min, max] (LONG_MIN / LONG_MAX: the whole type). */
enum num_status num_parse_long(const char *s, long min, long max, long *out);

/* The same for an int, the type most callers store. */
enum num_status num_parse_int(const char *s, int min, int max, int *out);

/* An unsigned 64-bit integer in [min, max] (microsecond counts, sizes). A
 * minus sign is NUM_RANGE, not a wrap-around to a huge value as strtoull's;
 * "-0" is refused too. */
enum num_status num_parse_u64(const char *s, uint64_t min, uint64_t max, uint64_t *out);

/* A counter from outside (a message anyone could send) added to a sum
 * without trusting it: a negative one counts as 0, and the sum stops at
 * INT64_MAX instead of overflowing. */
static inline int64_t num_count_add(int64_t sum, int64_t v)
{
	if (v <= 0)
		return sum;
	return sum > INT64_MAX - v ? INT64_MAX : sum + v;
}

#endif
