/* test_common_num.c — the strict number parsers: every form num.h promises to
 * accept, every near-miss it promises to refuse, the type limits, and that a
 * refused value leaves the caller's default alone. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <limits.h>
#include <math.h>
#include <string.h>

#include "num.h"

/* Parses s as a double; on NUM_OK the value must be want. */
static void expect_double(const char *s, enum num_status st, double want)
{
	double v = -7.25;
	enum num_status got = num_parse_double(s, &v);
	if (got != st)
		fail_msg("'%s': status %d, want %d", s ? s : "(null)", (int)got, (int)st);
	if (st == NUM_OK)
		assert_true(v == want);
	else
		assert_true(v == -7.25);   /* untouched */
}

static void expect_long(const char *s, long min, long max, enum num_status st, long want)
{
	long v = -77;
	enum num_status got = num_parse_long(s, min, max, &v);
	if (got != st)
		fail_msg("'%s': status %d, want %d", s ? s : "(null)", (int)got, (int)st);
	assert_int_equal(v, st == NUM_OK ? want : -77);
}

static void test_double_accepts(void **state)
{
	(void)state;
	expect_double("0", NUM_OK, 0);
	expect_double("1.5", NUM_OK, 1.5);
	expect_double("-2.25", NUM_OK, -2.25);
	expect_double("+3", NUM_OK, 3);
	expect_double(".5", NUM_OK, 0.5);
	expect_double("5.", NUM_OK, 5);
	expect_double("-.5", NUM_OK, -0.5);
	expect_double("1e3", NUM_OK, 1000);
	expect_double("1E-3", NUM_OK, 1e-3);
	expect_double("2.5e+2", NUM_OK, 250);
	expect_double("007", NUM_OK, 7);
	expect_double("1.7976931348623157e308", NUM_OK, DBL_MAX);
	/* underflow is a tiny number, not an error (num.h) */
	double v = 1;
	assert_int_equal(num_parse_double("1e-400", &v), NUM_OK);
	assert_true(v >= 0 && v < 1e-300);
	assert_int_equal(num_parse_double("-1e-400", &v), NUM_OK);
	assert_true(v <= 0 && v > -1e-300);
}

static void test_double_refuses(void **state)
{
	(void)state;
	expect_double(NULL, NUM_EMPTY, 0);
	expect_double("", NUM_EMPTY, 0);
	expect_double(" ", NUM_SYNTAX, 0);
	expect_double(" 1", NUM_SYNTAX, 0);
	expect_double("1 ", NUM_SYNTAX, 0);
	expect_double("1\n", NUM_SYNTAX, 0);
	expect_double("\t1", NUM_SYNTAX, 0);
	expect_double("1x", NUM_SYNTAX, 0);
	expect_double("1.5.2", NUM_SYNTAX, 0);
	expect_double("1e", NUM_SYNTAX, 0);
	expect_double("e5", NUM_SYNTAX, 0);
	expect_double(".", NUM_SYNTAX, 0);
	expect_double("-", NUM_SYNTAX, 0);
	expect_double("+", NUM_SYNTAX, 0);
	expect_double("--1", NUM_SYNTAX, 0);
	expect_double("+-1", NUM_SYNTAX, 0);
	expect_double("- 1", NUM_SYNTAX, 0);
	expect_double("1,5", NUM_SYNTAX, 0);
	expect_double("nan", NUM_SYNTAX, 0);
	expect_double("NaN", NUM_SYNTAX, 0);
	expect_double("-nan", NUM_SYNTAX, 0);
	expect_double("nan(1)", NUM_SYNTAX, 0);
	expect_double("inf", NUM_SYNTAX, 0);
	expect_double("-inf", NUM_SYNTAX, 0);
	expect_double("Infinity", NUM_SYNTAX, 0);
	expect_double("0x10", NUM_SYNTAX, 0);
	expect_double("0X1p3", NUM_SYNTAX, 0);
	expect_double("-0x1", NUM_SYNTAX, 0);
	/* overflow: a number, too big for the type */
	expect_double("1e400", NUM_RANGE, 0);
	expect_double("-1e400", NUM_RANGE, 0);
	expect_double("1.8e308", NUM_RANGE, 0);
}

static void test_double_range(void **state)
{
	(void)state;
	double v = 9;
	assert_int_equal(num_parse_double_in("0", 0, 1, &v), NUM_OK);
	assert_true(v == 0);
	assert_int_equal(num_parse_double_in("1", 0, 1, &v), NUM_OK);
	assert_true(v == 1);
	assert_int_equal(num_parse_double_in("1.0000001", 0, 1, &v), NUM_RANGE);
	assert_int_equal(num_parse_double_in("-0.1", 0, 1, &v), NUM_RANGE);
	assert_true(v == 1);
	assert_int_equal(num_parse_double_in("1e300", -INFINITY, INFINITY, &v), NUM_OK);
	assert_true(v == 1e300);
	assert_int_equal(num_parse_double_in("x", 0, 1, &v), NUM_SYNTAX);
	assert_int_equal(num_parse_double_in("", 0, 1, &v), NUM_EMPTY);
	/* -0 is 0: inside [0, 1] */
	assert_int_equal(num_parse_double_in("-0", 0, 1, &v), NUM_OK);
	assert_true(v == 0);
}

static void test_long_accepts(void **state)
{
	(void)state;
	expect_long("0", LONG_MIN, LONG_MAX, NUM_OK, 0);
	expect_long("42", LONG_MIN, LONG_MAX, NUM_OK, 42);
	expect_long("-42", LONG_MIN, LONG_MAX, NUM_OK, -42);
	expect_long("+42", LONG_MIN, LONG_MAX, NUM_OK, 42);
	/* leading zeros are decimal, not octal */
	expect_long("010", LONG_MIN, LONG_MAX, NUM_OK, 10);
	expect_long("-010", LONG_MIN, LONG_MAX, NUM_OK, -10);
	expect_long("08", LONG_MIN, LONG_MAX, NUM_OK, 8);
	expect_long("0x10", LONG_MIN, LONG_MAX, NUM_OK, 16);
	expect_long("0X1f", LONG_MIN, LONG_MAX, NUM_OK, 31);
	expect_long("0xFF", LONG_MIN, LONG_MAX, NUM_OK, 255);
	expect_long("-0x10", LONG_MIN, LONG_MAX, NUM_OK, -16);
	expect_long("0x0", LONG_MIN, LONG_MAX, NUM_OK, 0);
	expect_long("9223372036854775807", LONG_MIN, LONG_MAX, NUM_OK, LONG_MAX);
	expect_long("-9223372036854775808", LONG_MIN, LONG_MAX, NUM_OK, LONG_MIN);
	expect_long("0x7fffffffffffffff", LONG_MIN, LONG_MAX, NUM_OK, LONG_MAX);
	expect_long("-0x8000000000000000", LONG_MIN, LONG_MAX, NUM_OK, LONG_MIN);
}

static void test_long_refuses(void **state)
{
	(void)state;
	expect_long(NULL, 0, 10, NUM_EMPTY, 0);
	expect_long("", 0, 10, NUM_EMPTY, 0);
	expect_long(" 1", 0, 10, NUM_SYNTAX, 0);
	expect_long("1 ", 0, 10, NUM_SYNTAX, 0);
	expect_long("1\n", 0, 10, NUM_SYNTAX, 0);
	expect_long("- 1", -10, 10, NUM_SYNTAX, 0);
	expect_long("-", -10, 10, NUM_SYNTAX, 0);
	expect_long("+", -10, 10, NUM_SYNTAX, 0);
	expect_long("--1", -10, 10, NUM_SYNTAX, 0);
	expect_long("+-1", -10, 10, NUM_SYNTAX, 0);
	expect_long("1x", 0, 10, NUM_SYNTAX, 0);
	expect_long("1.0", 0, 10, NUM_SYNTAX, 0);
	expect_long("1e3", 0, 10000, NUM_SYNTAX, 0);
	expect_long("0x", 0, 10, NUM_SYNTAX, 0);
	expect_long("0x-5", -10, 10, NUM_SYNTAX, 0);
	expect_long("0x 5", -10, 10, NUM_SYNTAX, 0);
	expect_long("0x+5", -10, 10, NUM_SYNTAX, 0);
	expect_long("0xg", 0, 10, NUM_SYNTAX, 0);
	expect_long("0b101", 0, 10, NUM_SYNTAX, 0);
	expect_long("x10", 0, 100, NUM_SYNTAX, 0);
	/* beyond the type: NUM_RANGE, whatever min and max say */
	expect_long("9223372036854775808", LONG_MIN, LONG_MAX, NUM_RANGE, 0);
	expect_long("-9223372036854775809", LONG_MIN, LONG_MAX, NUM_RANGE, 0);
	expect_long("99999999999999999999999", LONG_MIN, LONG_MAX, NUM_RANGE, 0);
	expect_long("0x8000000000000000", LONG_MIN, LONG_MAX, NUM_RANGE, 0);
	/* outside the caller's range */
	expect_long("254", 0, 253, NUM_RANGE, 0);
	expect_long("-1", 0, 253, NUM_RANGE, 0);
	expect_long("253", 0, 253, NUM_OK, 253);
	expect_long("0", 0, 253, NUM_OK, 0);
	expect_long("0", 1, 99, NUM_RANGE, 0);
}

static void test_int(void **state)
{
	(void)state;
	int v = 5;
	assert_int_equal(num_parse_int("2147483647", INT_MIN, INT_MAX, &v), NUM_OK);
	assert_int_equal(v, INT_MAX);
	assert_int_equal(num_parse_int("-2147483648", INT_MIN, INT_MAX, &v), NUM_OK);
	assert_int_equal(v, INT_MIN);
	v = 5;
	/* fits a long, not an int */
	assert_int_equal(num_parse_int("2147483648", INT_MIN, INT_MAX, &v), NUM_RANGE);
	assert_int_equal(num_parse_int("-2147483649", INT_MIN, INT_MAX, &v), NUM_RANGE);
	assert_int_equal(num_parse_int("99", 1, 99, &v), NUM_OK);
	assert_int_equal(v, 99);
	assert_int_equal(num_parse_int("100", 1, 99, &v), NUM_RANGE);
	assert_int_equal(num_parse_int("1.5", 1, 99, &v), NUM_SYNTAX);
	assert_int_equal(num_parse_int("", 1, 99, &v), NUM_EMPTY);
	assert_int_equal(v, 99);
}

static void test_u64(void **state)
{
	(void)state;
	uint64_t v = 3;
	assert_int_equal(num_parse_u64("18446744073709551615", 0, UINT64_MAX, &v), NUM_OK);
	assert_true(v == UINT64_MAX);
	assert_int_equal(num_parse_u64("0xffffffffffffffff", 0, UINT64_MAX, &v), NUM_OK);
	assert_true(v == UINT64_MAX);
	assert_int_equal(num_parse_u64("+7", 0, UINT64_MAX, &v), NUM_OK);
	assert_true(v == 7);
	assert_int_equal(num_parse_u64("010", 0, UINT64_MAX, &v), NUM_OK);
	assert_true(v == 10);
	v = 3;
	assert_int_equal(num_parse_u64("18446744073709551616", 0, UINT64_MAX, &v), NUM_RANGE);
	/* strtoull would wrap "-1" to UINT64_MAX */
	assert_int_equal(num_parse_u64("-1", 0, UINT64_MAX, &v), NUM_RANGE);
	assert_int_equal(num_parse_u64("-0", 0, UINT64_MAX, &v), NUM_RANGE);
	assert_int_equal(num_parse_u64("-x", 0, UINT64_MAX, &v), NUM_SYNTAX);
	assert_int_equal(num_parse_u64("0", 1, UINT64_MAX, &v), NUM_RANGE);
	assert_int_equal(num_parse_u64("11", 1, 10, &v), NUM_RANGE);
	assert_int_equal(num_parse_u64(" 1", 0, 10, &v), NUM_SYNTAX);
	assert_int_equal(num_parse_u64("1 ", 0, 10, &v), NUM_SYNTAX);
	assert_int_equal(num_parse_u64("0x", 0, 10, &v), NUM_SYNTAX);
	assert_int_equal(num_parse_u64(NULL, 0, 10, &v), NUM_EMPTY);
	assert_true(v == 3);
}

static void test_strerror(void **state)
{
	(void)state;
	assert_string_equal(num_strerror(NUM_OK), "ok");
	assert_string_equal(num_strerror(NUM_EMPTY), "empty");
	assert_string_equal(num_strerror(NUM_SYNTAX), "not a number");
	assert_string_equal(num_strerror(NUM_RANGE), "out of range");
	assert_non_null(num_strerror((enum num_status)99));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_double_accepts), cmocka_unit_test(test_double_refuses),
		cmocka_unit_test(test_double_range),   cmocka_unit_test(test_long_accepts),
		cmocka_unit_test(test_long_refuses),   cmocka_unit_test(test_int),
		cmocka_unit_test(test_u64),            cmocka_unit_test(test_strerror),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
