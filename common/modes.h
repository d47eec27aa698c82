/*
 * modes.h — the robot's control modes and their names: one table for the
 * daemon (config files, `mode NAME` commands, its events and status line),
 * undulate-top (display, JSON, the commands it sends) and the analyser. The
 * numbers are the wire's: robot_state_t.MODE_* and command_t.mode carry them
 * (modes.c checks the two agree at compile time).
 */
#ifndef UNDULATE_COMMON_MODES_H
#define UNDULATE_COMMON_MODES_H

#include <stdbool.h>

enum mode { MODE_LIMP = 0, MODE_HOLD = 1, MODE_SINUSOID = 2, MODE_OSCILLATOR = 3 };
#define MODE_COUNT 4

/* True for the four modes; a mode read from the network may be anything. */
bool mode_is_valid(int mode);

/* "LIMP", "HOLD", "SINUSOID", "OSCILLATOR"; "UNKNOWN" for anything else. */
const char *mode_name(int mode);

/* At most four characters for narrow columns: "LIMP", "HOLD", "SIN", "OSC";
 * "?" for anything else. */
const char *mode_short(int mode);

/* A mode's full name in any case ("oscillator", "Hold"); writes *out only on
 * success. Short names are not accepted: a command or a config line should
 * say what it means. */
bool mode_parse(const char *s, enum mode *out);

#endif
