/* modes.c — see modes.h. */
#include "modes.h"

#include <stddef.h>
#include <strings.h>

#include "undulate_robot_state_t.h"

/* The table is indexed by the wire's numbers: a change on either side must
 * fail the build, not mislabel every robot. */
_Static_assert(MODE_LIMP == UNDULATE_ROBOT_STATE_T_MODE_LIMP, "mode numbers differ from robot_state_t");
_Static_assert(MODE_HOLD == UNDULATE_ROBOT_STATE_T_MODE_HOLD, "mode numbers differ from robot_state_t");
_Static_assert(MODE_SINUSOID == UNDULATE_ROBOT_STATE_T_MODE_SINUSOID, "mode numbers differ from robot_state_t");
_Static_assert(MODE_OSCILLATOR == UNDULATE_ROBOT_STATE_T_MODE_OSCILLATOR,
               "mode numbers differ from robot_state_t");

static const struct {
	const char *name, *short_name;
} mode_table[MODE_COUNT] = {
	[MODE_LIMP] = { "LIMP", "LIMP" },
	[MODE_HOLD] = { "HOLD", "HOLD" },
	[MODE_SINUSOID] = { "SINUSOID", "SIN" },
	[MODE_OSCILLATOR] = { "OSCILLATOR", "OSC" },
};

bool mode_is_valid(int mode)
{
	return mode >= 0 && mode < MODE_COUNT;
}

const char *mode_name(int mode)
{
	return mode_is_valid(mode) ? mode_table[mode].name : "UNKNOWN";
}

const char *mode_short(int mode)
{
	return mode_is_valid(mode) ? mode_table[mode].short_name : "?";
}

bool mode_parse(const char *s, enum mode *out)
{
	if (s == NULL)
		return false;
	for (int m = 0; m < MODE_COUNT; m++) {
		if (strcasecmp(s, mode_table[m].name) == 0) {
			*out = (enum mode)m;
			return true;
		}
	}
	return false;
}
