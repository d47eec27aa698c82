/* json.c — see json.h. */
#include "json.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

/* Length of the well-formed UTF-8 sequence at p (RFC 3629: no overlong forms,
 * no surrogates, nothing above U+10FFFF), or 0 if there is none. */
static size_t json_utf8_len(const unsigned char *p)
{
	unsigned char lo = 0x80, hi = 0xbf;
	size_t n;
	if (p[0] < 0x80)
		return 1;
	if (p[0] >= 0xc2 && p[0] <= 0xdf)
		n = 2;
	else if (p[0] >= 0xe0 && p[0] <= 0xef)
		n = 3;
	else if (p[0] >= 0xf0 && p[0] <= 0xf4)
		n = 4;
	else
		return 0;
	/* the second byte's range is what rules out the forbidden code points */
	if (p[0] == 0xe0)
		lo = 0xa0;
	else if (p[0] == 0xed)
		hi = 0x9f;
	else if (p[0] == 0xf0)
		lo = 0x90;
	else if (p[0] == 0xf4)
		hi = 0x8f;
	if (p[1] < lo || p[1] > hi)
		return 0;
	for (size_t k = 2; k < n; k++)
		if (p[k] < 0x80 || p[k] > 0xbf)
			return 0;
	return n;
}

/* Every byte goes through here: into the FILE, or into the buffer while it
 * has room (one byte kept for the NUL). A buffer that was once too small
 * stays full: it holds the document's start, never a later piece after a
 * missing one. */
static void json_put(struct json *j, const char *s, size_t n)
{
	if (j->f != NULL) {
		fwrite(s, 1, n, j->f);
		return;
	}
	if (j->full || n >= j->cap - j->len) {
		j->full = true;
		return;
	}
	memcpy(j->buf + j->len, s, n);
	j->len += n;
	j->buf[j->len] = '\0';
}

static void json_putc(struct json *j, char c)
{
	if (j->f != NULL)
		fputc(c, j->f);
	else
		json_put(j, &c, 1);
}

static void json_put_string(struct json *j, const char *s)
{
	static const char hex[] = "0123456789abcdef";
	const unsigned char *p = (const unsigned char *)(s != NULL ? s : "");
	const unsigned char *run = p;   /* bytes that go out as they are, from here to p */
	json_putc(j, '"');
	while (*p) {
		size_t n = json_utf8_len(p);
		if (n != 0 && *p != '"' && *p != '\\' && *p >= 0x20) {
			p += n;
			continue;
		}
		json_put(j, (const char *)run, (size_t)(p - run));
		if (n == 0) {
			json_put(j, "\\ufffd", 6);
			n = 1;
		} else if (*p == '"' || *p == '\\') {
			char esc[2] = { '\\', (char)*p };
			json_put(j, esc, 2);
		} else {
			char esc[6] = { '\\', 'u', '0', '0', hex[*p >> 4], hex[*p & 0xf] };
			json_put(j, esc, 6);
		}
		p += n;
		run = p;
	}
	json_put(j, (const char *)run, (size_t)(p - run));
	json_putc(j, '"');
}

void json_write_string(FILE *f, const char *s)
{
	struct json j = { .f = f };
	json_put_string(&j, s);
}

static int json_digits(int digits)
{
	return digits > 0 && digits <= 17 ? digits : JSON_DEFAULT_DIGITS;
}

void json_init(struct json *j, FILE *f, int digits)
{
	*j = (struct json){ .f = f, .digits = json_digits(digits), .ok = true };
}

void json_init_buf(struct json *j, char *buf, size_t cap, int digits)
{
	*j = (struct json){ .buf = buf, .cap = cap, .full = cap == 0, .digits = json_digits(digits), .ok = true };
	if (cap > 0)
		buf[0] = '\0';
}

size_t json_len(const struct json *j)
{
	return j->len;
}

bool json_end(const struct json *j)
{
	bool written = j->f != NULL ? !ferror(j->f) : !j->full;
	return j->ok && j->depth == 0 && j->has_items[0] && !j->after_key && written;
}

/* Before any value: the comma it needs, or false (and the writer stopped)
 * when a value may not go here. */
static bool json_value_prefix(struct json *j)
{
	if (!j->ok)
		return false;
	if (j->after_key) {
		j->after_key = false;
		return true;
	}
	if (j->in_object[j->depth] || (j->depth == 0 && j->has_items[0])) {
		j->ok = false;   /* a value without its key, or a second document */
		return false;
	}
	if (j->has_items[j->depth])
		json_putc(j, ',');
	j->has_items[j->depth] = true;
	return true;
}

void json_key(struct json *j, const char *key)
{
	if (!j->ok)
		return;
	if (!j->in_object[j->depth] || j->after_key) {
		j->ok = false;
		return;
	}
	if (j->has_items[j->depth])
		json_putc(j, ',');
	j->has_items[j->depth] = true;
	json_put_string(j, key);
	json_putc(j, ':');
	j->after_key = true;
}

static void json_open(struct json *j, bool object)
{
	if (!json_value_prefix(j))
		return;
	if (j->depth == JSON_MAX_DEPTH) {
		j->ok = false;
		return;
	}
	json_putc(j, object ? '{' : '[');
	j->depth++;
	j->in_object[j->depth] = object;
	j->has_items[j->depth] = false;
}

static void json_close(struct json *j, bool object)
{
	if (!j->ok)
		return;
	if (j->depth == 0 || j->in_object[j->depth] != object || j->after_key) {
		j->ok = false;
		return;
	}
	json_putc(j, object ? '}' : ']');
	j->depth--;
}

void json_object_begin(struct json *j)
{
	json_open(j, true);
}

void json_object_end(struct json *j)
{
	json_close(j, true);
}

void json_array_begin(struct json *j)
{
	json_open(j, false);
}

void json_array_end(struct json *j)
{
	json_close(j, false);
}

void json_string(struct json *j, const char *s)
{
	if (json_value_prefix(j))
		json_put_string(j, s);
}

/* Exact powers of ten as doubles: 10^0 .. 10^22 (10^23 is not a double). */
static const double json_pow10[] = { 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
                                     1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22 };

/* "%.*g" of v with p significant digits, written without printf for the
 * common case: a nonzero v whose printf form has no exponent (1e-4 <= |v| <
 * 10^p) and p <= JSON_FAST_DIGITS. Its digits are |v| * 10^k rounded to an
 * integer: one multiplication by an exact power of ten, so at most half a
 * unit in the last place from the exact product; when that could decide the
 * rounding (the product within JSON_FAST_TIE of a half) the answer is 0 and
 * printf writes it, as it does every other case. The same bytes as printf
 * (test_common_json compares them on millions of values); undulate-web
 * writes ~100 000 numbers a second, and printf's were a sixth of its time. */
#define JSON_FAST_DIGITS 13
#define JSON_FAST_TIE 0.01
static size_t json_fast_g(char out[32], double v, int p)
{
	double a = fabs(v);
	if (v == 0) {
		memcpy(out, signbit(v) ? "-0" : "0", 2);
		return signbit(v) ? 2 : 1;
	}
	if (p > JSON_FAST_DIGITS || !(a >= 1e-4) || a >= json_pow10[p])
		return 0;
	/* e: the decimal exponent of a, so that a * 10^(p-1-e) has p digits
	 * before the point; log10 may be one off next to a power of ten */
	int e = (int)floor(log10(a));
	double m = 0;
	for (int tries = 0; tries < 2; tries++) {
		int k = p - 1 - e;
		if (k < 0 || k > 22)
			return 0;
		m = a * json_pow10[k];
		if (m < json_pow10[p - 1])
			e--;
		else if (m >= json_pow10[p])
			e++;
		else
			break;
	}
	double r = floor(m + 0.5);
	/* a near-tie, or a rounding up to 10^p (another exponent): printf's */
	if (m < json_pow10[p - 1] || fabs(m - floor(m) - 0.5) < JSON_FAST_TIE || r >= json_pow10[p])
		return 0;
	char digits[JSON_FAST_DIGITS];
	unsigned long long d = (unsigned long long)r;
	for (int i = p - 1; i >= 0; i--, d /= 10)
		digits[i] = (char)('0' + d % 10);
	int last = p - 1;                       /* printf drops trailing zeros of the fraction */
	while (last > 0 && last > e && digits[last] == '0')
		last--;
	size_t n = 0;
	if (v < 0)
		out[n++] = '-';
	if (e < 0) {
		out[n++] = '0';
		out[n++] = '.';
		for (int i = -1; i > e; i--)
			out[n++] = '0';
		for (int i = 0; i <= last; i++)
			out[n++] = digits[i];
		return n;
	}
	for (int i = 0; i <= e; i++)
		out[n++] = digits[i];
	if (last > e) {
		out[n++] = '.';
		for (int i = e + 1; i <= last; i++)
			out[n++] = digits[i];
	}
	return n;
}

void json_number(struct json *j, double v)
{
	if (!json_value_prefix(j))
		return;
	if (!isfinite(v)) {
		json_put(j, "null", 4);
		return;
	}
	char text[32];   /* "%.17g" of any double: at most 24 bytes */
	size_t n = json_fast_g(text, v, j->digits);
	if (n == 0)
		n = (size_t)snprintf(text, sizeof text, "%.*g", j->digits, v);
	json_put(j, text, n);
}

void json_int(struct json *j, long long v)
{
	if (!json_value_prefix(j))
		return;
	/* by hand: printf's machinery costs more than the digits (undulate-web
	 * writes tens of thousands of integers a second) */
	char text[24], *p = text + sizeof text;
	unsigned long long u = v < 0 ? 0ULL - (unsigned long long)v : (unsigned long long)v;
	do {
		*--p = (char)('0' + u % 10);
		u /= 10;
	} while (u != 0);
	if (v < 0)
		*--p = '-';
	json_put(j, p, (size_t)(text + sizeof text - p));
}

void json_bool(struct json *j, bool v)
{
	if (json_value_prefix(j))
		json_put(j, v ? "true" : "false", v ? 4 : 5);
}

void json_null(struct json *j)
{
	if (json_value_prefix(j))
		json_put(j, "null", 4);
}

void json_field_string(struct json *j, const char *key, const char *s)
{
	json_key(j, key);
	json_string(j, s);
}

void json_field_number(struct json *j, const char *key, double v)
{
	json_key(j, key);
	json_number(j, v);
}

void json_field_int(struct json *j, const char *key, long long v)
{
	json_key(j, key);
	json_int(j, v);
}

void json_field_bool(struct json *j, const char *key, bool v)
{
	json_key(j, key);
	json_bool(j, v);
}
