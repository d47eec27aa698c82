/* test_common_json.c — the JSON writer: escaping of quotes, backslashes,
 * control bytes and broken UTF-8; non-finite numbers as null; commas and
 * nesting; misuse reported by json_end instead of a broken document. Every
 * case runs twice, once over each sink (a FILE, a memory buffer): the same
 * calls must give the same bytes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "json.h"

#define T_BUF 4096

/* The sink the cases run over: the group runs once with each. */
static bool buffer_sink;

struct out {
	char buf[T_BUF];
	FILE *f;
	struct json j;
};

static void out_open(struct out *o, int digits)
{
	memset(o->buf, 0, sizeof o->buf);
	if (buffer_sink) {
		o->f = NULL;
		json_init_buf(&o->j, o->buf, sizeof o->buf, digits);
		return;
	}
	o->f = fmemopen(o->buf, sizeof o->buf, "w");
	assert_non_null(o->f);
	json_init(&o->j, o->f, digits);
}

/* Closes the stream and returns what was written. */
static const char *out_text(struct out *o)
{
	if (o->f != NULL)
		fclose(o->f);
	else
		assert_int_equal(json_len(&o->j), strlen(o->buf));
	return o->buf;
}

static const char *quoted(struct out *o, const char *s)
{
	out_open(o, 0);
	json_string(&o->j, s);
	assert_true(json_end(&o->j));
	return out_text(o);
}

static void test_escaping(void **state)
{
	(void)state;
	static struct out o;
	assert_string_equal(quoted(&o, "plain"), "\"plain\"");
	assert_string_equal(quoted(&o, ""), "\"\"");
	assert_string_equal(quoted(&o, NULL), "\"\"");
	assert_string_equal(quoted(&o, "a\"b"), "\"a\\\"b\"");
	assert_string_equal(quoted(&o, "a\\b"), "\"a\\\\b\"");
	assert_string_equal(quoted(&o, "\\\""), "\"\\\\\\\"\"");
	/* every control byte as \u00XX, the line breaks a log reader splits on included */
	assert_string_equal(quoted(&o, "l1\nl2\r\t"), "\"l1\\u000al2\\u000d\\u0009\"");
	assert_string_equal(quoted(&o, "\x01\x1f"), "\"\\u0001\\u001f\"");
	assert_string_equal(quoted(&o, "\x1b[2J"), "\"\\u001b[2J\"");
	/* DEL and '/' need nothing */
	assert_string_equal(quoted(&o, "a/b\x7f"), "\"a/b\x7f\"");
}

static void test_utf8(void **state)
{
	(void)state;
	static struct out o;
	/* well-formed UTF-8 passes unchanged: é, €, U+1F600 */
	assert_string_equal(quoted(&o, "\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80"),
	                    "\"\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80\"");
	/* a stray continuation byte, a lone lead byte, a cut sequence at the end */
	assert_string_equal(quoted(&o, "a\x80z"), "\"a\\ufffdz\"");
	assert_string_equal(quoted(&o, "\xc3z"), "\"\\ufffdz\"");
	assert_string_equal(quoted(&o, "\xe2\x82"), "\"\\ufffd\\ufffd\"");
	/* overlong '/' (C0 AF), a surrogate (ED A0 80), above U+10FFFF (F4 90 ..), FF */
	assert_string_equal(quoted(&o, "\xc0\xaf"), "\"\\ufffd\\ufffd\"");
	assert_string_equal(quoted(&o, "\xed\xa0\x80"), "\"\\ufffd\\ufffd\\ufffd\"");
	assert_string_equal(quoted(&o, "\xf4\x90\x80\x80"), "\"\\ufffd\\ufffd\\ufffd\\ufffd\"");
	assert_string_equal(quoted(&o, "\xff"), "\"\\ufffd\"");
	/* an escaped quote right after a broken byte stays escaped */
	assert_string_equal(quoted(&o, "\xc3\""), "\"\\ufffd\\\"\"");
}

static void test_numbers(void **state)
{
	(void)state;
	static struct out o;
	out_open(&o, 0);
	json_array_begin(&o.j);
	json_number(&o.j, 0.1);
	json_number(&o.j, -2.5);
	json_number(&o.j, 1e300);
	json_number(&o.j, NAN);
	json_number(&o.j, INFINITY);
	json_number(&o.j, -INFINITY);
	json_number(&o.j, 1.0 / 3.0);
	json_int(&o.j, -9223372036854775807LL - 1);
	json_bool(&o.j, true);
	json_bool(&o.j, false);
	json_null(&o.j);
	json_array_end(&o.j);
	assert_true(json_end(&o.j));
	assert_string_equal(out_text(&o), "[0.1,-2.5,1e+300,null,null,null,0.333333333333,"
	                                  "-9223372036854775808,true,false,null]");
	/* the writer's own precision */
	out_open(&o, 4);
	json_number(&o.j, M_PI);
	assert_string_equal(out_text(&o), "3.142");
	out_open(&o, 99);   /* out of 1..17: the default */
	json_number(&o.j, 1.0 / 3.0);
	assert_string_equal(out_text(&o), "0.333333333333");
}

static void test_nesting_and_commas(void **state)
{
	(void)state;
	static struct out o;
	out_open(&o, 0);
	json_object_begin(&o.j);
	json_field_string(&o.j, "name", "r\"1");
	json_field_number(&o.j, "goal", NAN);
	json_field_int(&o.j, "n", 3);
	json_field_bool(&o.j, "stale", false);
	json_key(&o.j, "joints");
	json_array_begin(&o.j);
	for (int k = 0; k < 2; k++) {
		json_object_begin(&o.j);
		json_field_int(&o.j, "id", k + 1);
		json_key(&o.j, "c");
		json_array_begin(&o.j);
		json_array_end(&o.j);
		json_object_end(&o.j);
	}
	json_array_end(&o.j);
	json_key(&o.j, "bus");
	json_null(&o.j);
	json_key(&o.j, "empty");
	json_object_begin(&o.j);
	json_object_end(&o.j);
	json_key(&o.j, "we\"ird\nkey");
	json_int(&o.j, 0);
	json_object_end(&o.j);
	assert_true(json_end(&o.j));
	assert_string_equal(out_text(&o), "{\"name\":\"r\\\"1\",\"goal\":null,\"n\":3,\"stale\":false,"
	                                  "\"joints\":[{\"id\":1,\"c\":[]},{\"id\":2,\"c\":[]}],"
	                                  "\"bus\":null,\"empty\":{},\"we\\\"ird\\u000akey\":0}");
}

static void test_misuse(void **state)
{
	(void)state;
	static struct out o;
	/* a value in an object without a key: nothing more is written */
	out_open(&o, 0);
	json_object_begin(&o.j);
	json_int(&o.j, 1);
	json_field_int(&o.j, "a", 2);
	json_object_end(&o.j);
	assert_false(json_end(&o.j));
	assert_string_equal(out_text(&o), "{");
	/* a key in an array */
	out_open(&o, 0);
	json_array_begin(&o.j);
	json_key(&o.j, "a");
	assert_false(json_end(&o.j));
	out_text(&o);
	/* closing the wrong kind, closing at the top, a dangling key */
	out_open(&o, 0);
	json_array_begin(&o.j);
	json_object_end(&o.j);
	assert_false(json_end(&o.j));
	out_text(&o);
	out_open(&o, 0);
	json_array_end(&o.j);
	assert_false(json_end(&o.j));
	out_text(&o);
	out_open(&o, 0);
	json_object_begin(&o.j);
	json_key(&o.j, "a");
	json_object_end(&o.j);
	assert_false(json_end(&o.j));
	out_text(&o);
	/* unclosed, nothing at all, two documents */
	out_open(&o, 0);
	json_object_begin(&o.j);
	assert_false(json_end(&o.j));
	out_text(&o);
	out_open(&o, 0);
	assert_false(json_end(&o.j));
	out_text(&o);
	out_open(&o, 0);
	json_int(&o.j, 1);
	json_int(&o.j, 2);
	assert_false(json_end(&o.j));
	assert_string_equal(out_text(&o), "1");
	/* JSON_MAX_DEPTH levels are fine, one more is not */
	out_open(&o, 0);
	for (int k = 0; k < JSON_MAX_DEPTH; k++)
		json_array_begin(&o.j);
	for (int k = 0; k < JSON_MAX_DEPTH; k++)
		json_array_end(&o.j);
	assert_true(json_end(&o.j));
	out_text(&o);
	out_open(&o, 0);
	for (int k = 0; k <= JSON_MAX_DEPTH; k++)
		json_array_begin(&o.j);
	for (int k = 0; k <= JSON_MAX_DEPTH; k++)
		json_array_end(&o.j);
	assert_false(json_end(&o.j));
	out_text(&o);
}

/* The number as the writer writes it, and as printf would. */
static void number_is_printf(double v, int digits)
{
	static struct out o;
	out_open(&o, digits);
	json_number(&o.j, v);
	assert_true(json_end(&o.j));
	char want[40];
	snprintf(want, sizeof want, "%.*g", digits, v);
	if (strcmp(out_text(&o), want) != 0)
		fail_msg("%.17g with %d digits: wrote %s, printf %s", v, digits, o.buf, want);
}

/* xorshift64: the same values every run */
static uint64_t rnd(void)
{
	static uint64_t x = 88172645463325252ull;
	x ^= x << 13;
	x ^= x >> 7;
	x ^= x << 17;
	return x;
}

/* Numbers are written without printf where that is safe: whatever the
 * value and the digits, the bytes are printf's "%.*g" (values drawn at
 * random over every scale, decimal fractions with their exact ties, and
 * the neighbours of powers of ten, where the exponent changes). */
static void test_numbers_are_printf(void **state)
{
	(void)state;
	static const double edge[] = { 0.0, -0.0, 1, -1, 0.1, 0.5, 1.5, 2.5, 0.125, 1e-4, 9.99999e-5, 1e-5,
	                               999999999999.5, 99999.5, 9.9999999999995, 0.30000000000000004,
	                               123456789012.49, 1e12, 1e15, 1e16, 1e22, 1e23, 5e-324, 1.7976931348623157e308 };
	for (int d = 1; d <= 17; d++) {
		for (size_t i = 0; i < sizeof edge / sizeof edge[0]; i++) {
			number_is_printf(edge[i], d);
			number_is_printf(-edge[i], d);
		}
		for (int e = -12; e <= 22; e++) {
			double t = pow(10, e);
			number_is_printf(t, d);
			number_is_printf(nextafter(t, 0), d);
			number_is_printf(nextafter(t, INFINITY), d);
		}
	}
	for (int i = 0; i < 150000; i++) {
		int d = 1 + (int)(rnd() % 17);
		/* any bit pattern (NaN and infinities: null, not printf's) */
		uint64_t bits = rnd();
		double v;
		memcpy(&v, &bits, sizeof v);
		if (isfinite(v))
			number_is_printf(v, d);
		/* every scale from 1e-7 to 1e17 */
		v = pow(10, -7 + (double)(rnd() % 2400000) / 100000.0) * (rnd() & 1 ? 1 : -1);
		number_is_printf(v, d);
		/* short decimal fractions, where rounding meets exact halves */
		v = (double)(int64_t)(rnd() % 2000001 - 1000000) / pow(10, (double)(rnd() % 9));
		number_is_printf(v, d);
	}
}

/* A stream that cannot take the document: json_end says so. */
static void test_write_error(void **state)
{
	(void)state;
	char small[8];
	struct json j;
	FILE *f = NULL;
	if (buffer_sink) {
		json_init_buf(&j, small, sizeof small, 0);
	} else {
		f = fmemopen(small, sizeof small, "w");
		assert_non_null(f);
		setvbuf(f, NULL, _IONBF, 0);
		json_init(&j, f, 0);
	}
	json_string(&j, "longer than eight bytes");
	assert_false(json_end(&j));
	if (f != NULL)
		fclose(f);
}

/* The buffer's edge: a document of cap - 1 bytes fits (NUL after it); one of
 * cap bytes does not: the buffer holds a NUL-terminated start of it, no byte
 * beyond cap is touched, and json_end says false. */
static void test_buffer_edge(void **state)
{
	(void)state;
	char b[8];
	struct json j;
	json_init_buf(&j, b, 8, 0);
	json_string(&j, "abcde");   /* 7 bytes with its quotes */
	assert_true(json_end(&j));
	assert_int_equal(json_len(&j), 7);
	assert_string_equal(b, "\"abcde\"");
	char big[16];
	memset(big, 'x', sizeof big);
	json_init_buf(&j, big, 8, 0);
	json_array_begin(&j);
	json_string(&j, "abcde");   /* 1 + 7 bytes: the closing quote does not fit */
	json_array_end(&j);
	assert_false(json_end(&j));
	assert_true(json_len(&j) < 8);
	assert_int_equal(strlen(big), json_len(&j));
	assert_memory_equal(big, "[\"abcde\"]", json_len(&j));
	for (size_t k = 8; k < sizeof big; k++)
		assert_int_equal(big[k], 'x');
	json_init_buf(&j, b, 0, 0);
	json_null(&j);
	assert_false(json_end(&j));
}

static int over_file(void **state)
{
	(void)state;
	buffer_sink = false;
	return 0;
}

static int over_buffer(void **state)
{
	(void)state;
	buffer_sink = true;
	return 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_escaping),           cmocka_unit_test(test_utf8),
		cmocka_unit_test(test_numbers),            cmocka_unit_test(test_nesting_and_commas),
		cmocka_unit_test(test_misuse),             cmocka_unit_test(test_write_error),
		cmocka_unit_test(test_numbers_are_printf),
	};
	const struct CMUnitTest buffer_only[] = {
		cmocka_unit_test(test_buffer_edge),
	};
	int failed = cmocka_run_group_tests_name("over a FILE", tests, over_file, NULL);
	failed += cmocka_run_group_tests_name("over a buffer", tests, over_buffer, NULL);
	return failed + cmocka_run_group_tests_name("buffer only", buffer_only, NULL, NULL);
}
