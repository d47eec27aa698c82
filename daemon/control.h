/*
 * control.h — one robot's control state between the bus and the control laws:
 * modes and their transitions, blending, stale readings, servo faults and their
 * recovery, and the safety clamp. No I/O and no clock: the daemon hands in
 * measurements and times, and takes out goals and the register writes the
 * controller wants (torque on/off, torque limit). That keeps mode switches and
 * fault handling unit-testable.
 *
 * Angles: `angle`/`goal` are absolute servo radians (0 = raw 512); the
 * oscillator works in x = angle − neutral.
 */
#ifndef UNDULATE_DAEMON_CONTROL_H
#define UNDULATE_DAEMON_CONTROL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "osc.h"
#include "safety.h"

/* Register writes the controller may queue in one cycle: per joint at most a
 * torque limit, a torque enable and the angle limits, plus slack. */
#define CTL_MAX_WRITES (3 * CFG_MAX_JOINTS + 4)
/* Events (faults, recoveries, mode changes) queued per cycle for LCM. */
#define CTL_MAX_EVENTS 8
#define CTL_EVENT_TEXT 160

enum ctl_fault { CTL_FAULT_NONE, CTL_FAULT_BACKOFF, CTL_FAULT_CHECK, CTL_FAULT_FAILED };

/* What this cycle's SYNC_WRITE carries. */
enum ctl_sync {
	CTL_SYNC_GOAL,       /* goal position (30) of the joints with write_goal */
	CTL_SYNC_DUTY,       /* torque actuation, wheel mode: moving speed (32) = duty of every joint */
	CTL_SYNC_GOAL_STOP,  /* leaving wheel mode: goal (30) and moving speed 0 (32) of every joint
	                        with a reading; the angle-limit writes that follow restore joint mode */
};

struct ctl_write {
	uint8_t id;
	uint8_t addr;
	uint8_t len;         /* 1, 2 or 4 (little-endian, as the registers) */
	uint32_t value;
};

struct ctl_event {
	int level;           /* event_t.LEVEL_* */
	char kind[24];
	char text[CTL_EVENT_TEXT];
};

/* What the servo told us at start-up. */
struct ctl_servo_info {
	uint16_t cw_limit, ccw_limit;
	uint16_t max_torque;
	uint8_t return_delay;
	uint8_t status_return_level;
};

struct ctl_joint {
	uint8_t id;
	struct ctl_servo_info servo;
	struct safety_limits limits;
	/* measurement */
	bool fresh;                 /* read this cycle */
	double angle;               /* rad absolute, last good reading */
	double speed;               /* rad/s, per the configured velocity source */
	double load;
	uint8_t errbits;
	uint8_t reported_bits;      /* non-fault error bits already reported */
	double voltage, temperature;
	int32_t stale_cycles;
	bool resumed;               /* fresh again after CTL_RESUME_STALE stale cycles */
	bool have_reading;
	struct osc_velocity_filter vfilter;
	struct osc_estimator estimator;
	double phase;
	/* command */
	double goal;                /* rad absolute, last sent (NaN: none yet) */
	bool write_goal;            /* include in this cycle's SYNC_WRITE */
	double duty;                /* torque actuation: signed output ratio sent this cycle (NaN: none) */
	double torque_cmd;          /* N·m the duty stands for (NaN: none) */
	bool torque;                /* torque enabled as far as we know */
	unsigned clamp_flags;       /* SAFETY_* of this cycle */
	/* faults */
	enum ctl_fault fault;
	double fault_since;         /* s, controller time */
	double fault_hold;          /* rad absolute: where it backs off to */
	int retries;
	long long faults;
};

struct ctl {
	struct cfg *cfg;            /* parameters (commands change them) */
	size_t n;
	struct ctl_joint j[CFG_MAX_JOINTS];
	enum cfg_mode mode;
	char reason[96];
	double t;                   /* s, monotonic controller time of this cycle */
	/* per joint: blend from `blend_from` (NaN: not blending) to the mode's
	 * target over cfg->ramp_s, starting at blend_t0 */
	double blend_t0[CFG_MAX_JOINTS];
	double blend_from[CFG_MAX_JOINTS];
	/* cross-fade between moving modes: from fade_mode's target (CFG_NMODES: none) */
	int fade_mode;
	double fade_t0;
	double hold[CFG_MAX_JOINTS];    /* HOLD targets, rad absolute */
	/* outputs of the current cycle */
	struct ctl_write writes[CTL_MAX_WRITES];
	size_t nwrites;
	struct ctl_event events[CTL_MAX_EVENTS];
	size_t nevents;
	int rest_cycles;                /* cycles a running oscillator has been still */
	int still_cycles;               /* cycles every joint has been still (any mode) */
	/* torque actuation: the servos are in wheel mode (as far as our writes
	 * went), and what this cycle's SYNC_WRITE carries */
	bool wheel;
	enum ctl_sync sync;
	bool starter_active;            /* OSCILLATOR runs the sinusoid starter ... */
	double starter_offset;          /* rad added to its phase after a stall (ctl_check_stall) */
	double starter_until;           /* ... until then */
	/* counters */
	long long faults, clamps, nonfinite, starts;
	long long limit_trips;          /* torque actuation: a joint left its limits */
};

void ctl_init(struct ctl *c, struct cfg *cfg);
/* After start-up checks (again after every reconnect): the servo's limits and
 * settings. False (with *why) if the configured limits and the servo's have
 * no angle in common or the servo is in wheel mode. */
bool ctl_set_servo(struct ctl *c, size_t joint, const struct ctl_servo_info *info, char *why, size_t cap);
/* The servo angle limits that put a joint back in joint mode after wheel mode
 * (torque actuation): the servo's own, or the configured joint limits if the
 * servo was found in wheel mode. Packed as the 4 bytes at register 6. */
uint32_t ctl_joint_mode_limits(const struct ctl *c, size_t joint);
/* Called once the bus is (re)connected and every joint has a reading: enable
 * torque (unless LIMP) and ramp in from the present positions. */
void ctl_start(struct ctl *c, double t, const char *reason);
/* The bus went away: every joint is stale, torque state unknown. */
void ctl_bus_lost(struct ctl *c);

/* Feed this cycle's reading of joint j (raw registers 36..41 and the error byte). */
void ctl_measure(struct ctl *c, size_t j, uint16_t pos_raw, uint16_t speed_raw, uint16_t load_raw,
                 uint8_t errbits, double dt);
/* Feed a voltage/temperature reading (registers 42, 43). */
void ctl_measure_slow(struct ctl *c, size_t j, uint8_t voltage_raw, uint8_t temperature_raw, uint8_t errbits);

/* One control step at controller time t (s) with measured period dt (s) and
 * wall-clock time t_real (s, for SINUSOID's shared clock). Fills goals,
 * writes and events. Call after ctl_measure() for every joint that answered. */
void ctl_step(struct ctl *c, double t, double dt, double t_real);

/* Mode change (commands, faults, signals). Continuous in commanded angle. */
void ctl_set_mode(struct ctl *c, enum cfg_mode mode, const char *reason);
/* Parameters changed (a command): SINUSOID re-blends so its new phase/frequency
 * cannot jump. */
void ctl_params_changed(struct ctl *c);
/* Torque on/off command: off = LIMP; on = HOLD where the joints are. */
void ctl_torque(struct ctl *c, bool on);

/* Consume this cycle's outputs. */
void ctl_clear_outputs(struct ctl *c);

#endif
