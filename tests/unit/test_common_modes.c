/* test_common_modes.c — the mode table: names by wire number, short names
 * that fit their column, parsing in any case, and out-of-range numbers from
 * the network named as unknown. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "modes.h"
#include "undulate_robot_state_t.h"

static void test_names(void **state)
{
	(void)state;
	assert_string_equal(mode_name(UNDULATE_ROBOT_STATE_T_MODE_LIMP), "LIMP");
	assert_string_equal(mode_name(UNDULATE_ROBOT_STATE_T_MODE_HOLD), "HOLD");
	assert_string_equal(mode_name(UNDULATE_ROBOT_STATE_T_MODE_SINUSOID), "SINUSOID");
	assert_string_equal(mode_name(UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR), "OSCILLATOR");
	assert_string_equal(mode_short(MODE_SINUSOID), "SIN");
	assert_string_equal(mode_short(MODE_OSCILLATOR), "OSC");
	for (int m = 0; m < MODE_COUNT; m++) {
		assert_true(mode_is_valid(m));
		assert_true(strlen(mode_short(m)) <= 4);
		assert_int_equal(strncmp(mode_short(m), mode_name(m), 3), 0);
	}
	/* a mode number from the network may be anything */
	static const int bad[] = { -1, MODE_COUNT, 127, -128 };
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		assert_false(mode_is_valid(bad[i]));
		assert_string_equal(mode_name(bad[i]), "UNKNOWN");
		assert_string_equal(mode_short(bad[i]), "?");
	}
}

static void test_parse(void **state)
{
	(void)state;
	enum mode m = MODE_HOLD;
	for (int k = 0; k < MODE_COUNT; k++) {
		assert_true(mode_parse(mode_name(k), &m));
		assert_int_equal(m, k);
	}
	assert_true(mode_parse("oscillator", &m));
	assert_int_equal(m, MODE_OSCILLATOR);
	assert_true(mode_parse("Limp", &m));
	assert_int_equal(m, MODE_LIMP);
	m = MODE_HOLD;
	assert_false(mode_parse("osc", &m));        /* short names are for display */
	assert_false(mode_parse("SIN", &m));
	assert_false(mode_parse("run", &m));
	assert_false(mode_parse("", &m));
	assert_false(mode_parse(" HOLD", &m));
	assert_false(mode_parse("HOLD ", &m));
	assert_false(mode_parse("UNKNOWN", &m));
	assert_false(mode_parse(NULL, &m));
	assert_int_equal(m, MODE_HOLD);             /* untouched on failure */
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_names),
		cmocka_unit_test(test_parse),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
