/*
 * control.h — one robot's controller between the bus and the control laws:
 * modes and their transitions, blending, stale and silent joints, servo
 * faults and their recovery, what the servos report about themselves (read
 * back), latched faults, and the safety clamp. No I/O and no clock: the
 * cycle (cycle.h) hands in measurements and times and takes out goals and
 * register writes through the calls below; nothing else touches the queue of
 * writes or the events. That keeps mode switches, faults and the write
 * rules unit-testable.
 *
 * Angles: `angle`/`goal` are absolute servo radians (0 = raw 512); the
 * oscillator works in x = angle − neutral.
 *
 * Faults latch (as a CiA 402 drive's do): a joint silent for longer than
 * silent_s, a servo fault that persists through its recovery attempts, a
 * servo that keeps resetting, and a joint that left its limits under torque
 * actuation put the robot in its fault action (HOLD or LIMP) and keep it
 * there. Only LIMP, HOLD and `clear` are accepted then; `clear` succeeds only
 * once the cause is gone.
 */
#ifndef UNDULATE_DAEMON_CONTROL_H
#define UNDULATE_DAEMON_CONTROL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "osc.h"
#include "safety.h"
#include "writeq.h"

/* Events (faults, recoveries, mode changes) queued per cycle for LCM; more
 * in one cycle are counted in events_dropped. */
#define CTL_MAX_EVENTS 16
#define CTL_EVENT_TEXT 160
#define CTL_LATCH_TEXT 128

/* The RAM block read back in the slow round-robin: torque enable (24)
 * through present temperature (43). */
#define CTL_READBACK_ADDR 24
#define CTL_READBACK_LEN 20

enum ctl_fault { CTL_FAULT_NONE, CTL_FAULT_BACKOFF, CTL_FAULT_CHECK, CTL_FAULT_FAILED };

/* What this cycle's SYNC_WRITE carries. */
enum ctl_sync {
	CTL_SYNC_GOAL,       /* goal position (30) of the joints with write_goal */
	CTL_SYNC_DUTY,       /* torque actuation, wheel mode: moving speed (32) = duty of every joint */
	CTL_SYNC_GOAL_STOP,  /* leaving wheel mode: goal (30) and moving speed 0 (32) of every joint
	                        with a reading; the angle-limit writes that follow restore joint mode */
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
	/* read back (slow round-robin); -1 until read */
	int torque_read;            /* torque enable (24) */
	int torque_limit_read;      /* torque limit (34) */
	long long resets;           /* found reset (torque off, RAM at its defaults) since the last clear */
	/* command */
	double goal;                /* rad absolute, last sent (NaN: none yet) */
	bool write_goal;            /* include in this cycle's SYNC_WRITE */
	double duty;                /* torque actuation: signed output ratio sent this cycle (NaN: none) */
	double torque_cmd;          /* N·m the duty stands for (NaN: none) */
	bool torque;                /* torque wanted on (what the writes make it) */
	unsigned clamp_flags;       /* SAFETY_* of this cycle */
	/* faults */
	enum ctl_fault fault;
	double fault_since;         /* s, controller time */
	double fault_hold;          /* rad absolute: where it backs off to */
	int retries;
	long long faults;
};

struct ctl {
	struct cfg *cfg;            /* parameters (accepted commands change the documented ones) */
	size_t n;
	struct ctl_joint j[CFG_MAX_JOINTS];
	enum cfg_mode mode;
	char reason[96];
	double t;                   /* s, monotonic controller time of this cycle */
	/* a latched fault: the robot stays in its fault action until cleared */
	bool latched;
	char latch[CTL_LATCH_TEXT];
	/* per joint: blend from `blend_from` (NaN: not blending) to the mode's
	 * target over cfg->ramp_s, starting at blend_t0 */
	double blend_t0[CFG_MAX_JOINTS];
	double blend_from[CFG_MAX_JOINTS];
	/* cross-fade between moving modes: from fade_mode's target (CFG_NMODES: none) */
	int fade_mode;
	double fade_t0;
	double hold[CFG_MAX_JOINTS];    /* HOLD targets, rad absolute */
	/* outputs: register writes (owned here; the cycle takes them one at a
	 * time) and events */
	struct wq wq;
	struct ctl_event events[CTL_MAX_EVENTS];
	size_t nevents;
	long long events_dropped;
	int rest_cycles;                /* cycles a running oscillator has been still */
	int still_cycles;               /* cycles every joint has been still (any mode) */
	/* torque actuation (torque.c): the servos are in wheel mode (as far as our
	 * writes went), and what this cycle's SYNC_WRITE carries */
	bool wheel;
	enum ctl_sync sync;
	bool starter_active;            /* OSCILLATOR runs the sinusoid starter ... */
	double starter_offset;          /* rad added to its phase after a stall */
	double starter_until;           /* ... until then */
	/* counters */
	long long faults, clamps, nonfinite, starts;
	long long limit_trips;          /* torque actuation: a joint left its limits */
	long long write_failures;       /* register writes given up after WQ_TRIES sends */
	long long readback_mismatches;  /* a register read back differed from what we wrote */
	long long resets;               /* servos found reset */
};

void ctl_init(struct ctl *c, struct cfg *cfg);
/* After start-up checks (again after every reconnect): the servo's limits and
 * settings. False (with *why) if the configured limits and the servo's have
 * no angle in common or the servo is in wheel mode. */
bool ctl_set_servo(struct ctl *c, size_t joint, const struct ctl_servo_info *info, char *why, size_t cap);
/* The servo angle limits that put a joint back in joint mode after wheel mode
 * (torque actuation): the servo's own. Packed as the 4 bytes at register 6. */
uint32_t ctl_joint_mode_limits(const struct ctl *c, size_t joint);
/* Called once the bus is (re)connected and every joint has a reading: enable
 * torque (unless LIMP or a LIMP fault action is latched) and ramp in from the
 * present positions. */
void ctl_start(struct ctl *c, double t, const char *reason);
/* The bus went away: every joint is stale, torque state unknown, queued
 * writes forgotten (the start-up sequence rewrites what matters). */
void ctl_bus_lost(struct ctl *c);

/* ---- inputs ------------------------------------------------------------------------- */
/* This cycle's reading of joint j (raw registers 36..41 and the error byte). */
void ctl_measure(struct ctl *c, size_t j, uint16_t pos_raw, uint16_t speed_raw, uint16_t load_raw,
                 uint8_t errbits, double dt);
/* A voltage/temperature reading (registers 42, 43). */
void ctl_measure_slow(struct ctl *c, size_t j, uint8_t voltage_raw, uint8_t temperature_raw, uint8_t errbits);
/* The RAM block CTL_READBACK_ADDR.. (CTL_READBACK_LEN bytes) of joint j as the
 * servo reports it: torque enable, margins, torque limit, voltage,
 * temperature. Compared with what the controller wrote; a servo found reset
 * or shut down is reported and brought back (or the fault latches). */
void ctl_readback(struct ctl *c, size_t j, const uint8_t *ram, uint8_t errbits);

/* One control step at controller time t (s) with measured period dt (s) and
 * wall-clock time t_real (s, for SINUSOID's shared clock). Fills goals,
 * writes and events. Call after ctl_measure() for every joint that answered. */
void ctl_step(struct ctl *c, double t, double dt, double t_real);

/* ---- commands (applied by the daemon at the cycle boundary) ------------------------- */
/* May the robot go to `mode` now? False with *why while a fault is latched
 * and `mode` is neither LIMP nor the fault action. */
bool ctl_mode_allowed(const struct ctl *c, enum cfg_mode mode, char *why, size_t cap);
/* Mode change (commands, faults, signals). Continuous in commanded angle. */
void ctl_set_mode(struct ctl *c, enum cfg_mode mode, const char *reason);
/* Parameters changed (a command): SINUSOID re-blends so its new phase/frequency
 * cannot jump. */
void ctl_params_changed(struct ctl *c);
/* Torque on/off command: off = LIMP; on = HOLD where the joints are. */
void ctl_torque(struct ctl *c, bool on);
/* Clear latched faults. False (with *why) if the cause is still there: a
 * joint still silent. The robot stays in its mode; the operator chooses the
 * next one. */
bool ctl_clear_faults(struct ctl *c, char *why, size_t cap);

/* ---- outputs (taken by the cycle) ---------------------------------------------------- */
/* The next register write to send, NULL when none. It is on the wire until
 * ctl_write_result() says how it went; nothing changes it meanwhile. */
const struct wq_write *ctl_take_write(struct ctl *c);
/* ok: the servo acknowledged it (or no reply was due). A failed write is
 * sent again, up to WQ_TRIES times; then it is reported as an event. */
void ctl_write_result(struct ctl *c, bool ok);
/* This cycle's SYNC_WRITE: register, bytes per servo, and per servo its ID
 * and data (little-endian). Returns the number of servos (0: nothing to send). */
size_t ctl_sync(const struct ctl *c, uint8_t *addr, uint8_t *width, uint8_t *ids, uint8_t *data);
/* The next queued event; false when none is left. */
bool ctl_next_event(struct ctl *c, struct ctl_event *out);

#endif
