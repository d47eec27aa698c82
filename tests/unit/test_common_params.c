/* test_common_params.c — the one table of parameter ranges: the documented
 * values (daemon/README.md, "Commands"), open and closed ends, NaN never
 * inside, and no name that is not a parameter. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "params.h"

static void test_documented_ranges(void **state)
{
	(void)state;
	static const struct { const char *key; double min, max; bool joint, commandable; } doc[] = {
		{ "k", 1e-4, 10, true, true },          { "c", -1, 1, true, true },
		{ "mu", 0, 100, true, true },           { "lambda", -10, 10, true, true },
		{ "inertia", 1e-5, 1, true, true },     { "friction", 0, 1, true, true },
		{ "amplitude", 0, 2.618, false, true }, { "frequency", 0, 5, false, true },
		{ "stiffness", 0, 10, false, true },    { "damping", 0, 1, false, true },
		{ "max_step", 0, 0.5, true, false },
	};
	for (size_t i = 0; i < sizeof doc / sizeof doc[0]; i++) {
		const struct param_def *d = param_find(doc[i].key);
		assert_non_null(d);
		assert_true(fabs(d->range.min - doc[i].min) < 1e-12);
		assert_true(fabs(d->range.max - doc[i].max) < 5e-4);   /* 2.618 is 150 degrees */
		assert_int_equal(d->joint, doc[i].joint);
		assert_int_equal(d->commandable, doc[i].commandable);
	}
	assert_true(fabs(param_find("coupling_phase")->range.max - PARAM_PI) < 1e-12);
	assert_true(fabs(param_find("phase")->range.min + 2 * PARAM_PI) < 1e-12);
	assert_false(param_find("neutral")->commandable);
	assert_false(param_find("limit_min")->commandable || param_find("limit_max")->commandable);
	assert_null(param_find("servo_lead_s"));   /* the file's and the tuner's, not a command's */
	assert_null(param_find(""));
	assert_null(param_find("K"));
}

static void test_in_range(void **state)
{
	(void)state;
	const struct param_range *a = &param_find("amplitude")->range;
	assert_true(param_in_range(a, 0.0));
	assert_true(param_in_range(a, PARAM_SERVO_HALF_RANGE));
	assert_false(param_in_range(a, 2.62));
	assert_false(param_in_range(a, -1e-12));
	assert_false(param_in_range(a, NAN));
	const struct param_range *s = &param_find("max_step")->range;   /* open at 0 */
	assert_false(param_in_range(s, 0.0));
	assert_true(param_in_range(s, 1e-9));
	assert_true(param_in_range(s, 0.5));
	assert_false(param_in_range(s, INFINITY));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_documented_ranges),
		cmocka_unit_test(test_in_range),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
