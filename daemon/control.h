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
 * Angles: `angle`/`goal` are absolute servo radians (0 = the servo's centre:
 * raw 512 on the AX-12, 2048 on the X series); the oscillator works in
 * x = angle − neutral.
 *
 * Servo families (servo_model.h): registers, units and sequences come from
 * each joint's model; the rules here are one piece of code for all of them.
 * What only the X series has — REBOOT, the Bus Watchdog, Hardware Error
 * Status, Operating Mode — is handled by the same machinery: a shutdown is a
 * fault (backed off, recovered by a REBOOT while fault_reboots allows, else
 * latched), a watchdog that stopped a servo is recovered like a reset, an
 * Operating Mode or position limits found changed are written again.
 *
 * Faults latch (as a CiA 402 drive's do): a joint silent for longer than
 * silent_s, a servo fault that persists through its recovery attempts, a
 * servo that keeps resetting, a joint that left its limits under torque
 * actuation, and under torque actuation's PWM drive a supply reading the
 * servo cannot be running at (the drive scales with it) put the robot in its
 * fault action (HOLD or LIMP) and keep it there. Only LIMP, HOLD and `clear`
 * are accepted then; `clear` succeeds only once a silent joint answers (a
 * supply still misread latches again at the next OSCILLATOR).
 */
#ifndef UNDULATE_DAEMON_CONTROL_H
#define UNDULATE_DAEMON_CONTROL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "osc.h"
#include "phase.h"
#include "safety.h"
#include "servo_model.h"
#include "writeq.h"

/* Events (faults, recoveries, mode changes) queued per cycle for LCM; more
 * in one cycle are counted in events_dropped. */
#define CTL_MAX_EVENTS 16
#define CTL_EVENT_TEXT 160
#define CTL_LATCH_TEXT 128

/* The AX-12's RAM block read back in the slow round-robin: torque enable
 * (24) through present temperature (43). (Each model's blocks: servo_model.h.) */
#define CTL_READBACK_ADDR 24
#define CTL_READBACK_LEN 20

enum ctl_fault {
	CTL_FAULT_NONE,
	CTL_FAULT_BACKOFF,   /* backing off (reduced torque limit) before a recovery attempt */
	CTL_FAULT_REBOOT,    /* X series: a REBOOT sent, waiting for the servo to boot */
	CTL_FAULT_CHECK,     /* recovered: watching that the fault does not come back */
	CTL_FAULT_FAILED,    /* persisted: latched */
};
/* X series: after a REBOOT is acknowledged the servo boots; the set-up
 * writes wait this long (the manual gives no boot time; a real servo is deaf
 * for a moment, the simulator's boot is instantaneous). */
#define CTL_REBOOT_SETTLE_S 0.3

/* What this cycle's SYNC_WRITE carries. */
enum ctl_sync {
	CTL_SYNC_GOAL,       /* goal position (30) of the joints with write_goal */
	CTL_SYNC_DUTY,       /* torque actuation, wheel mode: moving speed (32) = duty of every joint
	                        (X series: Goal Current 102 or Goal PWM 100 of every joint in its drive) */
	CTL_SYNC_GOAL_STOP,  /* leaving wheel mode: goal (30) and moving speed 0 (32) of every joint
	                        with a reading; the angle-limit writes that follow restore joint mode
	                        (X series: the drive register 0; the mode switch's chain follows) */
};

struct ctl_event {
	int level;           /* event_t.LEVEL_* */
	char kind[24];
	char text[CTL_EVENT_TEXT];
};

/* What the servo told us at start-up. */
struct ctl_servo_info {
	uint16_t cw_limit, ccw_limit;   /* X series: Min/Max Position Limit (52, 48) */
	uint16_t max_torque;            /* X series: PWM Limit (36), Goal PWM's ceiling */
	uint8_t return_delay;
	uint8_t status_return_level;
	const struct sm_model *model;   /* NULL: the AX-12A */
	uint16_t current_limit;         /* XM430: Current Limit (38) */
	uint8_t firmware;               /* Version of Firmware (2 | 6), as read at start-up */
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
	uint8_t errbits;            /* AX-12: the status error byte; X: Hardware Error Status, bit 7 the alert */
	uint8_t reported_bits;      /* non-fault error bits already reported */
	bool alert;                 /* X: the last status raised the alert */
	double voltage, temperature;
	int32_t stale_cycles;
	bool resumed;               /* fresh again after CTL_RESUME_STALE stale cycles */
	bool have_reading;
	struct osc_velocity_filter vfilter;
	struct phase_estimator estimator;   /* published frequency and amplitude */
	double phase;               /* rad, NAN while unknown (phase.h) */
	/* read back (slow round-robin); -1 until read */
	int torque_read;            /* torque enable (24) */
	int torque_limit_read;      /* torque limit (34) */
	long long resets;           /* found reset (torque off, RAM at its defaults) since the last clear */
	/* X series, read back; -1 until read */
	int hwerr;                  /* Hardware Error Status (70) */
	double hwerr_at;            /* when it was last read (controller time; -inf never) */
	int watchdog_read;          /* Bus Watchdog (98) */
	int opmode_read;            /* Operating Mode (11) */
	bool readback_due;          /* read its RAM block back at the next chance (an alert, a check) */
	int reboots;                /* REBOOTs sent since the last clear */
	double reboot_at;           /* when the last REBOOT was acknowledged */
	bool watchdog_cleared;      /* the set-up writes the watchdog 0 first (it had stopped the servo) */
	bool limits_wrong;          /* Min/Max Position Limit read back unlike the configuration's */
	/* torque actuation, X series: the drive mode's switch (a chain of writes)
	 * went through, so the SYNC_WRITE may carry this joint's drive */
	bool drive_ready;
	uint16_t drive_chain;       /* the chain that makes it so */
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
	const struct cfg *cfg;      /* the configuration; never written (the live parameters are p) */
	struct cfg_params p;        /* the live parameters: the configuration's at ctl_init, changed
	                               only by ctl_set_param (commands, the tuner) and the model's defaults */
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
	double late_s;                  /* how late the cycles have come lately (torque.c's guard) */
	bool starter_active;            /* OSCILLATOR runs the sinusoid starter ... */
	double starter_offset;          /* rad added to its phase after a stall */
	double starter_until;           /* ... until then */
	/* counters */
	long long faults, clamps, nonfinite, starts;
	long long limit_trips;          /* torque actuation: a joint left its limits */
	long long write_failures;       /* register writes given up after WQ_TRIES sends */
	long long readback_mismatches;  /* a register read back differed from what we wrote */
	long long resets;               /* servos found reset */
	long long watchdog_trips;       /* X series: servos found stopped by their bus watchdog */
	long long reboots;              /* X series: REBOOTs sent */
	bool bus_hold;                  /* a bus of several is lost: every joint holds (ctl_bus_lost_on) */
	unsigned char defaults_done[CFG_MAX_JOINTS];   /* CTL_DEFAULTS_* given to the joint (once) */
};
#define CTL_DEFAULTS_TORQUE   1u
#define CTL_DEFAULTS_POSITION 2u

void ctl_init(struct ctl *c, const struct cfg *cfg);
/* The joint's servo model (the AX-12A until ctl_set_servo says otherwise). */
const struct sm_model *ctl_model(const struct ctl *c, size_t joint);
/* After start-up checks (again after every reconnect): the servo's limits and
 * settings. False (with *why) if the configured limits and the servo's have
 * no angle in common or the servo is in wheel mode. */
bool ctl_set_servo(struct ctl *c, size_t joint, const struct ctl_servo_info *info, char *why, size_t cap);
/* Once the joint's servo model is known (the first connect, before the robot
 * runs): the live parameters that took the AX-12A's defaults (config.h)
 * become the model's — under torque actuation scaled by `scale`
 * (sm_torque_scale), under position actuation k and μ replaced. Once per
 * joint: later calls change nothing. True when anything changed. */
bool ctl_torque_defaults(struct ctl *c, size_t joint, double scale);
bool ctl_position_defaults(struct ctl *c, size_t joint, double k, double mu);
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
/* One bus of several went away (config.h, [bus.NAME]): its joints are as in
 * ctl_bus_lost, their queued writes forgotten; the chain of oscillators is
 * broken, so every other joint holds where its last goal put it (HOLD's
 * target, whatever the mode) until ctl_start() — called when the bus is back
 * — ramps the robot into its mode again (docs/SAFETY.md, "Several buses"). */
void ctl_bus_lost_on(struct ctl *c, size_t bus);
/* Bus `bus` is back while another is still lost (the robot holds until
 * every bus is): its servos get the torque the controller wants now — a LIMP
 * commanded while they were out of reach, whose writes went with the bus,
 * reaches them at once. */
void ctl_bus_back_on(struct ctl *c, size_t bus);
/* The joint is on that bus (the configuration's wiring). */
bool ctl_on_bus(const struct ctl *c, size_t joint, size_t bus);

/* ---- inputs ------------------------------------------------------------------------- */
/* This cycle's reading of joint j (raw registers 36..41 and the error byte:
 * the AX-12's). */
void ctl_measure(struct ctl *c, size_t j, uint16_t pos_raw, uint16_t speed_raw, uint16_t load_raw,
                 uint8_t errbits, double dt);
/* The same from a decoded present block of any model, with the status the
 * reply carried (AX-12 error byte; X ERR field). A slow block's voltage and
 * temperature are taken too. */
void ctl_measure_present(struct ctl *c, size_t j, const struct sm_present *p, uint8_t status, double dt);
/* A voltage/temperature reading (registers 42, 43). */
void ctl_measure_slow(struct ctl *c, size_t j, uint8_t voltage_raw, uint8_t temperature_raw, uint8_t errbits);
/* The RAM block CTL_READBACK_ADDR.. (CTL_READBACK_LEN bytes) of joint j as the
 * servo reports it: torque enable, margins, torque limit, voltage,
 * temperature. Compared with what the controller wrote; a servo found reset
 * or shut down is reported and brought back (or the fault latches). */
void ctl_readback(struct ctl *c, size_t j, const uint8_t *ram, uint8_t errbits);
/* Read-back block `block` of joint j's model (servo_model.h), n bytes, and
 * the status of its reply. Blocks of the wrong length are ignored. */
void ctl_readback_block(struct ctl *c, size_t j, size_t block, const uint8_t *bytes, size_t n, uint8_t status);
/* A joint whose RAM block should be read back now (an alert, a recovery being
 * checked): true with *joint set. */
bool ctl_readback_due(const struct ctl *c, size_t *joint);

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
/* A live parameter: the one door for commands and the tuner. `name` is a
 * commandable parameter or servo_lead_s, joint -1 every joint (a robot's
 * parameter takes -1 only). Checked by cfg_params_check() against the values
 * in force (range, finiteness, joint, natural frequency, stiffness and
 * actuation): false with *why and nothing changed, else applied at once —
 * call it at the cycle boundary — and SINUSOID re-blends so that a new phase
 * or frequency cannot jump. Which names a *command* may set is command.h's
 * (servo_lead_s is the tuner's alone). */
bool ctl_set_param(struct ctl *c, const char *name, int joint, double value, char *why, size_t cap);
/* The same check without the change (a command judged when it arrives). */
bool ctl_check_param(const struct ctl *c, const char *name, int joint, double value, char *why, size_t cap);
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
/* The write ctl_take_write() would give, not taken (NULL: none, or one is on
 * the wire): on a robot of several buses, the servo's bus takes it. */
const struct wq_write *ctl_next_write(const struct ctl *c);
/* ok: the servo acknowledged it (or no reply was due). A failed write is
 * sent again, up to WQ_TRIES times; then it is reported as an event. */
void ctl_write_result(struct ctl *c, bool ok);
/* This cycle's SYNC_WRITE: register, bytes per servo, and per servo its ID
 * and data (little-endian). Returns the number of servos (0: nothing to send). */
#define CTL_SYNC_MAX_WIDTH 4
size_t ctl_sync(const struct ctl *c, uint16_t *addr, uint8_t *width, uint8_t *ids, uint8_t *data);
/* The next queued event; false when none is left. */
bool ctl_next_event(struct ctl *c, struct ctl_event *out);

#endif
