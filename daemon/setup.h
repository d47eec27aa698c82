/*
 * setup.h — the blocking bus work around the loop: start-up checks at every
 * (re)connect, and the safe stop at exit. Blocking is right here: start-up
 * has no cycle to keep yet, and the stop is the last thing the daemon does.
 *
 * Start-up: every servo answers a PING (a missing one is named), its
 * settings are read in one READ and judged (model, status return level,
 * output limit, hardware error, return delay) and handed to the controller
 * (ctl_set_servo); joint mode is made what the loop expects, the RAM it
 * relies on written (a power loss resets it), and every joint's present
 * position is read. Lost replies are retried (a loaded machine); a port
 * that goes away is not.
 *
 * One path for every servo family: what differs is its model's data
 * (servo_model.h, sm_setup: which registers, how strict) and capabilities.
 * Joint mode is angle limits (AX-12: a servo a torque-actuated run left in
 * wheel mode is put back) or Operating Mode 3 with Min/Max Position Limit
 * made the configuration's (SM_CAP_OPMODE: EEPROM, written with torque off,
 * only when they differ; a drive mode of ours is put back, another
 * refused); an unknown model number is refused where the family's models
 * differ; the compliance margins and slopes are written where the servo has
 * them, a ramp another program left (Moving Speed, the profiles) set to 0,
 * a bus watchdog that stopped the servo cleared and the configured one set
 * (bus_watchdog_ms) where it has one.
 *
 * Safe stop: a bus watchdog is cleared first (a robot left holding by a
 * clean stop is not a silent controller), any torque-actuation drive is
 * stopped and joint mode restored, then the robot is left as configured
 * (safe_stop: holding where it is, or limp), and what matters is read back:
 * a torque-off that did not take is said.
 */
#ifndef UNDULATE_DAEMON_SETUP_H
#define UNDULATE_DAEMON_SETUP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "bus.h"
#include "control.h"

/* Tries of a start-up (or safe-stop) transaction before a servo is called
 * missing, and the quiet line waited for before each new try: 10, 20, 30 ms
 * (a missing servo costs about 70 ms), at most 100 ms of a talking line. */
#define SETUP_TRIES 4
#define SETUP_QUIET_US 10000u
#define SETUP_SETTLE_MAX_US 100000u

/* The bus's protocol, protocol = auto: the first configured ID that answers
 * a PING decides — Protocol 1.0 first (the AX-12's), then 2.0 (the X
 * series'), each tried SETUP_TRIES times, ID after ID. False with *err when
 * no servo answers either. *found is set on success; what was found is
 * logged. */
bool setup_protocol(struct bus *bus, const struct cfg *cfg, const char *port_path, enum bus_protocol *found,
                    char *err, size_t cap);
/* Every start-up check; *max_return_delay_us gets the largest return delay
 * found (for the bus timeouts). False with *err (one line, with the command
 * that fixes it where there is one). */
/* on_bus: a robot on several buses (config.h, [bus.NAME]) is set up, read
 * and stopped a bus at a time; these functions touch the joints of bus
 * `on_bus` only (ctl_on_bus: every joint when the robot has one bus). */
bool setup_servos(struct bus *bus, struct ctl *ctl, const struct cfg *cfg, size_t on_bus, const char *port_path,
                  int *max_return_delay_us, char *err, size_t cap);
/* Reads every joint's present position, speed and load into the controller. */
bool setup_read_present(struct bus *bus, struct ctl *ctl, size_t on_bus, double dt, char *err, size_t cap);
/* Leaves the configured safe state on the bus (LIMP when the robot is limp
 * already: writing goals could bring torque back). Logs what it did and
 * what failed. */
void setup_safe_stop(struct bus *bus, const struct ctl *ctl, const struct cfg *cfg, size_t on_bus);
/* One joint limp: torque off, read back (tried SETUP_TRIES times) — a lost
 * write must not leave a robot that says it is limp torqued. False, logged,
 * when it does not read back off. */
bool setup_limp(struct bus *bus, const struct ctl_joint *jt);
/* A joint's configured limits (neutral + [limit_min, limit_max]) as servo
 * angle limits, in whole units inside them: what start-up writes when it
 * puts a servo back in joint mode, and what `dxl doctor` compares the servo's
 * own limits with. */
void setup_joint_limits(const struct cfg_joint *cj, uint16_t *cw, uint16_t *ccw);
/* The same in a model's units (X series: Min/Max Position Limit):
 * sm_joint_range, the one rule. */
void setup_joint_limits_model(const struct sm_model *m, const struct cfg_joint *cj, int32_t *lo, int32_t *hi);

/* Whether every joint's servo answers Fast Sync Read (its model from
 * firmware dxl2_model_fast_read says, on a protocol that has it), for the
 * cycle's read (cyc_set_fast_read); why says which servos, or which one
 * does not and why, for the log. */
bool setup_fast_read(const struct bus *bus, const struct ctl *ctl, char *why, size_t cap);
/* The same for the joints of bus `on_bus` (a robot on several buses). */
bool setup_fast_read_on(const struct bus *bus, const struct ctl *ctl, size_t on_bus, char *why, size_t cap);

/* Map the present values the cycle decodes into every servo's indirect
 * block (servo_model.h, sm_model.indirect: Indirect Address 1..13 set to
 * 126..135 and 144..146) and read the map back, for the cycle's read
 * (cyc_set_indirect). A servo already holding the map is left as it is;
 * else its torque is turned off (ctl_start turns it on again) and the map
 * written. False, with why (which servo, which slot, what it answered),
 * when a servo has no indirect area, refuses, or reads back another map:
 * the cycle then reads the registers where they lie. true: why says how
 * many were written. Never a failed start. */
bool setup_indirect(struct bus *bus, const struct ctl *ctl, char *why, size_t cap);
/* The same for the joints of bus `on_bus` (a robot on several buses). */
bool setup_indirect_on(struct bus *bus, const struct ctl *ctl, size_t on_bus, char *why, size_t cap);

#endif
