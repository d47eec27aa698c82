/* test_common_text.c — text from outside made one safe line: text_sanitize's
 * escapes, its cut (only what does not fit, never inside an escape, marked
 * "..."), small and zero capacities, NULL; text_line's '?' without a second
 * escape; text_is_name's alphabet and bound. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "text.h"

/* A byte the functions must never write: the canary around dst. */
#define CANARY 0x5a

/* What text.h promises for a byte: itself when printable and not '\\',
 * else \xNN in lower-case hex. Written out independently of text.c. */
static size_t model_escape(unsigned char b, char out[5])
{
	if (b >= 0x20 && b <= 0x7e && b != '\\') {
		out[0] = (char)b;
		out[1] = '\0';
		return 1;
	}
	snprintf(out, 5, "\\x%02x", b);
	return 4;
}

/* Calls text_sanitize with dst inside a canary-filled buffer; fails on any
 * write past cap. Returns the result (static). */
static const char *sanitize(size_t cap, const char *src)
{
	static char buf[600];
	assert_true(cap + 16 <= sizeof buf);
	memset(buf, CANARY, sizeof buf);
	char *dst = buf + 8;
	assert_ptr_equal(text_sanitize(dst, cap, src), dst);
	for (size_t i = 0; i < 8; i++)
		assert_int_equal((unsigned char)buf[i], CANARY);
	for (size_t i = 8 + cap; i < sizeof buf; i++)
		if ((unsigned char)buf[i] != CANARY)
			fail_msg("cap %zu: byte %zu past dst's end written", cap, i - 8);
	if (cap > 0)
		assert_true(memchr(dst, '\0', cap) != NULL);
	return dst;
}

/* One call of text_sanitize and the line it must give: the tests below are
 * tables of these, checked one by one (a failure names its row). */
struct sanitize_case {
	size_t cap;
	const char *src;
	const char *want;
};

static void check_cases(const struct sanitize_case *cases, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		const char *got = sanitize(cases[i].cap, cases[i].src);
		if (strcmp(got, cases[i].want) != 0)
			fail_msg("row %zu (cap %zu): got \"%s\", want \"%s\"", i, cases[i].cap, got, cases[i].want);
	}
}

static void test_sanitize_plain(void **state)
{
	(void)state;
	static const struct sanitize_case cases[] = {
		{ 64, "robot1", "robot1" },
		{ 64, " ~!\"#$%&'()*+,-./09:;<=>?@AZ[]^_`az{|}", " ~!\"#$%&'()*+,-./09:;<=>?@AZ[]^_`az{|}" },
		{ 64, "", "" },
		{ 64, NULL, "" },
		{ 8, NULL, "" },
	};
	check_cases(cases, sizeof cases / sizeof cases[0]);
}

static void test_sanitize_escapes(void **state)
{
	(void)state;
	static const struct sanitize_case cases[] = {
		{ 64, "a\nb", "a\\x0ab" },
		/* the journal forgery text.h names: a newline, then a priority prefix */
		{ 64, "ok\n<0>emergency", "ok\\x0a<0>emergency" },
		{ 64, "\r\t\x1b[2J", "\\x0d\\x09\\x1b[2J" },
		/* the backslash itself, so an escape in the output is always ours */
		{ 64, "\\x0a", "\\x5cx0a" },
		{ 64, "\x1f\x7f\x80\xff", "\\x1f\\x7f\\x80\\xff" },
		{ 64, "caf\xc3\xa9", "caf\\xc3\\xa9" },
		/* nothing after the first NUL exists for a C string */
		{ 64, "ab\0cd", "ab" },
	};
	check_cases(cases, sizeof cases / sizeof cases[0]);
}

static void test_sanitize_cut(void **state)
{
	(void)state;
	static const struct sanitize_case cases[] = {
		/* does not fit: cut, and says so */
		{ 8, "abcdefgh", "abcd..." },
		{ 10, "abcdefghijklmnop", "abcdef..." },
		/* an escape is never split: "ab" + "\x0a" would need 6 + 3 > 7 */
		{ 8, "ab\ncdefgh", "ab..." },
		{ 8, "abc\n\n", "abc..." },
		/* fits exactly (cap - 1 bytes): not cut */
		{ 8, "abcdefg", "abcdefg" },
		{ 8, "abc\n", "abc\\x0a" },
		{ 9, "\n\\", "\\x0a\\x5c" },
		{ 8, "\n\\", "\\x0a..." },
		{ 12, "0123456789a", "0123456789a" },
		/* one byte more than fits */
		{ 8, "abc\nd", "abc..." },
		{ 12, "0123456789ab", "01234567..." },
	};
	check_cases(cases, sizeof cases / sizeof cases[0]);
}

static void test_sanitize_small_caps(void **state)
{
	(void)state;
	/* cap 0: nothing written at all, not even the NUL */
	static char zero[4] = { CANARY, CANARY, CANARY, CANARY };
	assert_ptr_equal(text_sanitize(zero + 1, 0, "abc"), zero + 1);
	for (size_t i = 0; i < sizeof zero; i++)
		assert_int_equal((unsigned char)zero[i], CANARY);
	/* below the documented minimum (8) nothing is promised but safety:
	 * terminated within cap, never past it, no raw control byte */
	const char *inputs[] = { "", "a", "abcdefghijkl", "\n", "\\\\\\\\", "ab\ncd", NULL };
	for (size_t cap = 1; cap <= 8; cap++) {
		for (size_t k = 0; k < sizeof inputs / sizeof inputs[0]; k++) {
			const char *out = sanitize(cap, inputs[k]);
			size_t len = strlen(out);
			if (len >= cap)
				fail_msg("cap %zu, input %zu: %zu bytes", cap, k, len);
			for (size_t i = 0; i < len; i++)
				assert_true(out[i] >= 0x20 && out[i] <= 0x7e);
		}
	}
	/* the documented minimum: a cut still says so */
	assert_string_equal(sanitize(8, "abcdefghijkl"), "abcd...");
	assert_string_equal(sanitize(8, "\n\n\n"), "\\x0a...");
}

/* Random bytes against the model: the output is the whole escaped text when
 * it fits in cap - 1 bytes, else a prefix of it that ends at an escape's
 * boundary followed by "...", as long as possible. */
static void test_sanitize_property(void **state)
{
	(void)state;
	unsigned seed = 12345;
	for (int round = 0; round < 20000; round++) {
		char src[40];
		seed = seed * 1103515245u + 12345u;
		size_t n = (seed >> 16) % sizeof src;
		for (size_t i = 0; i < n; i++) {
			seed = seed * 1103515245u + 12345u;
			/* mostly printable, some control bytes, backslashes and high bytes */
			unsigned r = (seed >> 16) & 0xff;
			src[i] = (char)(r < 160 ? 'a' + r % 26 : r < 200 ? '\\' - (r & 1) * 0x50 : r < 230 ? r % 32 + 1 : r);
		}
		src[n] = '\0';
		seed = seed * 1103515245u + 12345u;
		size_t cap = 8 + (seed >> 16) % 64;

		char full[200], piece[5];
		size_t bounds[41], nb = 0, flen = 0;
		full[0] = '\0';
		bounds[nb++] = 0;
		for (size_t i = 0; i < n; i++) {
			flen += model_escape((unsigned char)src[i], piece);
			strcat(full, piece);
			bounds[nb++] = flen;
		}
		const char *out = sanitize(cap, src);
		if (flen < cap) {
			if (strcmp(out, full) != 0)
				fail_msg("round %d: '%s' fits cap %zu, got '%s'", round, full, cap, out);
			continue;
		}
		/* the longest escape boundary that leaves room for "..." */
		size_t keep = 0;
		for (size_t b = 0; b < nb; b++)
			if (bounds[b] + 3 < cap)
				keep = bounds[b];
		char want[200];
		snprintf(want, sizeof want, "%.*s...", (int)keep, full);
		if (strcmp(out, want) != 0)
			fail_msg("round %d: cap %zu, '%s': got '%s', want '%s'", round, cap, full, out, want);
	}
}

static void test_line(void **state)
{
	(void)state;
	char buf[64];
	assert_ptr_equal(text_line(buf, sizeof buf, "mode OSCILLATOR"), buf);
	assert_string_equal(buf, "mode OSCILLATOR");
	assert_string_equal(text_line(buf, sizeof buf, "a\nb\rc\td"), "a?b?c?d");
	assert_string_equal(text_line(buf, sizeof buf, "\x7f\x80\xff\x01"), "????");
	/* already sanitized text is not escaped a second time */
	assert_string_equal(text_line(buf, sizeof buf, "src 'a\\x0ab'"), "src 'a\\x0ab'");
	assert_string_equal(text_line(buf, sizeof buf, NULL), "");
	assert_string_equal(text_line(buf, sizeof buf, ""), "");
	/* cut to cap - 1, no marker */
	assert_string_equal(text_line(buf, 5, "abcdefgh"), "abcd");
	assert_string_equal(text_line(buf, 5, "abcd"), "abcd");
	assert_string_equal(text_line(buf, 1, "abc"), "");
	char guard[3] = { CANARY, CANARY, CANARY };
	text_line(guard + 1, 0, "abc");
	for (size_t i = 0; i < sizeof guard; i++)
		assert_int_equal((unsigned char)guard[i], CANARY);
	/* never past cap */
	memset(buf, CANARY, sizeof buf);
	text_line(buf, 4, "abcdefgh\n");
	assert_string_equal(buf, "abc");
	for (size_t i = 4; i < sizeof buf; i++)
		assert_int_equal((unsigned char)buf[i], CANARY);
}

static void test_is_name(void **state)
{
	(void)state;
	assert_true(text_is_name("robot1", 48));
	assert_true(text_is_name("R_2-x", 48));
	assert_true(text_is_name("0", 1));
	assert_true(text_is_name("-", 48));
	assert_false(text_is_name(NULL, 48));
	assert_false(text_is_name("", 48));
	const char *bad[] = { "a.b", "a b", "a/b", "..", "a\n", "a@b", "a*", "*", "caf\xc3\xa9", "a\\b", "a:b", "a%" };
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
		if (text_is_name(bad[i], 48))
			fail_msg("'%s' taken as a name", bad[i]);
	/* at most max bytes */
	assert_true(text_is_name("abcd", 4));
	assert_false(text_is_name("abcde", 4));
	assert_false(text_is_name("a", 0));
	char longname[49];
	memset(longname, 'n', 48);
	longname[48] = '\0';
	assert_true(text_is_name(longname, 48));
	assert_false(text_is_name(longname, 47));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_sanitize_plain),
		cmocka_unit_test(test_sanitize_escapes),
		cmocka_unit_test(test_sanitize_cut),
		cmocka_unit_test(test_sanitize_small_caps),
		cmocka_unit_test(test_sanitize_property),
		cmocka_unit_test(test_line),
		cmocka_unit_test(test_is_name),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
