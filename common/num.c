/* num.c — see num.h. The accepted form is checked here, character by
 * character, before strtod/strtol see the text: their own grammar is wider
 * (leading spaces, octal, hex floats, "nan", a partial read) and differs
 * between them, and it is exactly that width num.h promises to refuse. */
#include "num.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

static bool num_is_digit(char c)
{
	return c >= '0' && c <= '9';
}

static bool num_is_xdigit(char c)
{
	return num_is_digit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

/* Skips a run of digits; returns how many there were. */
static size_t num_skip_digits(const char **p, bool (*is_digit)(char))
{
	size_t n = 0;
	while (is_digit(**p)) {
		(*p)++;
		n++;
	}
	return n;
}

const char *num_strerror(enum num_status st)
{
	switch (st) {
	case NUM_OK: return "ok";
	case NUM_EMPTY: return "empty";
	case NUM_SYNTAX: return "not a number";
	case NUM_RANGE: return "out of range";
	}
	return "not a number";
}

/* [+-]DIGITS or [+-]0xHEXDIGITS, nothing else. Sets *negative and *base. */
static enum num_status num_check_integer(const char *s, bool *negative, int *base)
{
	const char *p = s;
	if (s == NULL || *s == '\0')
		return NUM_EMPTY;
	*negative = *p == '-';
	if (*p == '-' || *p == '+')
		p++;
	*base = 10;
	bool (*is_digit)(char) = num_is_digit;
	if (p[0] == '0' && (p[1] == 'x' || p[1] == 'X')) {
		*base = 16;
		is_digit = num_is_xdigit;
		p += 2;
	}
	if (num_skip_digits(&p, is_digit) == 0 || *p != '\0')
		return NUM_SYNTAX;
	return NUM_OK;
}

/* [+-](DIGITS[.DIGITS*] | .DIGITS)[(e|E)[+-]DIGITS], nothing else. */
static enum num_status num_check_decimal(const char *s)
{
	const char *p = s;
	if (s == NULL || *s == '\0')
		return NUM_EMPTY;
	if (*p == '-' || *p == '+')
		p++;
	size_t mantissa = num_skip_digits(&p, num_is_digit);
	if (*p == '.') {
		p++;
		mantissa += num_skip_digits(&p, num_is_digit);
	}
	if (mantissa == 0)
		return NUM_SYNTAX;
	if (*p == 'e' || *p == 'E') {
		p++;
		if (*p == '-' || *p == '+')
			p++;
		if (num_skip_digits(&p, num_is_digit) == 0)
			return NUM_SYNTAX;
	}
	return *p == '\0' ? NUM_OK : NUM_SYNTAX;
}

enum num_status num_parse_double_in(const char *s, double min, double max, double *out)
{
	enum num_status st = num_check_decimal(s);
	if (st != NUM_OK)
		return st;
	/* errno is not consulted: ERANGE also flags an underflow, which num.h
	 * accepts; an overflow shows as an infinite result. */
	double v = strtod(s, NULL);
	if (!isfinite(v) || !(v >= min && v <= max))
		return NUM_RANGE;
	*out = v;
	return NUM_OK;
}

enum num_status num_parse_double(const char *s, double *out)
{
	return num_parse_double_in(s, -INFINITY, INFINITY, out);
}

enum num_status num_parse_long(const char *s, long min, long max, long *out)
{
	bool negative;
	int base;
	enum num_status st = num_check_integer(s, &negative, &base);
	if (st != NUM_OK)
		return st;
	/* strtol reads the sign and the 0x itself, so LONG_MIN needs no negation
	 * of LONG_MAX + 1. */
	errno = 0;
	long v = strtol(s, NULL, base);
	if (errno == ERANGE || v < min || v > max)
		return NUM_RANGE;
	*out = v;
	return NUM_OK;
}

enum num_status num_parse_int(const char *s, int min, int max, int *out)
{
	long v;
	enum num_status st = num_parse_long(s, min, max, &v);
	if (st == NUM_OK)
		*out = (int)v;
	return st;
}

enum num_status num_parse_u64(const char *s, uint64_t min, uint64_t max, uint64_t *out)
{
	bool negative;
	int base;
	enum num_status st = num_check_integer(s, &negative, &base);
	if (st != NUM_OK)
		return st;
	if (negative)
		return NUM_RANGE;
	errno = 0;
	unsigned long long v = strtoull(s, NULL, base);
	if (errno == ERANGE || v < min || v > max)
		return NUM_RANGE;
#if ULLONG_MAX > UINT64_MAX
	if (v > UINT64_MAX)
		return NUM_RANGE;
#endif
	*out = (uint64_t)v;
	return NUM_OK;
}
