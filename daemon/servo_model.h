/*
 * servo_model.h — what the controller and the cycle need to know about one
 * servo family: its protocol, the registers they write and read, the blocks
 * they read back, its units and its datasheet line. Pure: no I/O, no clock.
 *
 * The AX-12A on Protocol 1.0 (protocol/dxl_table.h) and every X-series model
 * protocol/dxl2_table.c describes (XL430-W250, XM430-W350, XC430-W150): an
 * X model here is made from its descriptor there (datasheet, current
 * sensing), so a new X model is data in that file and nothing here but,
 * once `undulated --tune` ran on it, its tuned defaults (sm_tuned). Only
 * which registers the daemon uses, and why, is said here. Everything that
 * differs between models is answered here, so that control.c keeps one set
 * of rules (modes, blending, faults, latches, the clamp, the write queue's
 * guarantees) over all of them.
 *
 * How the X series stands in for the AX-12's registers:
 *  - torque limit: the AX-12's Torque Limit (34, 0..1023 of Max Torque) caps
 *    its output; on the X series Goal PWM (100, 0..PWM Limit, 885 = 100 %)
 *    caps the output of every mode but PWM control (e-manual, Goal PWM), so a
 *    fault's back-off lowers Goal PWM, and recovery writes PWM Limit back;
 *  - joint mode: the AX-12's angle limits not both 0; on the X series
 *    Operating Mode 3 (position control), where the servo itself keeps Goal
 *    Position within Min/Max Position Limit (52, 48) — extended position
 *    control (4) would not: its goals are multi-turn and unbounded, and no
 *    configured joint needs more than the ±2.618 rad of one turn;
 *  - torque actuation: the AX-12's wheel mode (Moving Speed 32 as a PWM duty);
 *    on the XM430 current control (mode 0, Goal Current 102 — the paper's rig
 *    drove currents), on the XL430, which has no current sensing, PWM control
 *    (mode 16, Goal PWM 100) with the back-EMF added back as on the AX-12;
 *  - faults: the AX-12's status error byte shows overload and overheating in
 *    every reply; an X servo's status carries only the alert bit, and the
 *    cause is Hardware Error Status (70), read back (sm_state.hwerr).
 */
#ifndef UNDULATE_DAEMON_SERVO_MODEL_H
#define UNDULATE_DAEMON_SERVO_MODEL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl2_table.h"


/* What a family has, asked instead of its protocol or its name (sm_has). */
enum sm_cap {
	/* Its faults are in a Hardware Error Status register (70), its status
	 * only raises an alert; a fault shuts it down until a REBOOT (X). An
	 * AX-12's status byte carries its overload and overheating itself. */
	SM_CAP_HWERR = 1u << 0,
	/* It is set up and switched by its Operating Mode (11): position
	 * control with Min/Max Position Limit and the Bus Watchdog at start,
	 * each switch of torque actuation a chain of writes acknowledged per
	 * servo, and leaving it zeroes the drive registers (X). Without it,
	 * joint mode is angle limits not both 0, wheel mode both 0, and its
	 * position loop is set by compliance margins and slopes (AX-12). */
	SM_CAP_OPMODE = 1u << 1,
};

struct sm_model;
struct sm_state;
struct sm_present;
/* Where the cycle reads the present values: a block of the control table,
 * len bytes (fast) or len_slow (slow: voltage and temperature too). The
 * model's own present registers where they lie (src NULL), or the indirect
 * block start-up maps (setup_indirect): Indirect Data 1.. at addr, byte k
 * standing for the address src[k] (the value Indirect Address k+1 holds).
 * One decoder reads both (sm_decode_read). */
#define SM_READ_MAX 32
struct sm_read {
	uint16_t addr;
	uint8_t len, len_slow;
	const uint16_t *src;
};
/* A register block read in one READ, and what fills sm_state from it. */
struct sm_block {
	uint16_t addr, len;
	const char *what;          /* "RAM", for messages */
	void (*decode)(const struct sm_model *m, const uint8_t *b, struct sm_state *s);
};
/* Read-back blocks of one family (the AX-12 has one, the X series two). */
#define SM_MAX_BLOCKS 2

/* The law's k and μ and the horizon's lead (servo_lead_s) that give the
 * paper's gait (0.8 Hz, 0.8 rad) through a servo's position loop: for a robot
 * of two or more joints (μ by the joint's parity, as osc_default_params) and
 * for a single joint. An X servo's position loop lags the goal more than the
 * AX-12A's compliance does, and the AX-12A's values run down on it
 * (daemon/CONTROL.md, "X-series servos"). */
struct sm_position_defaults {
	double k_pair, mu_even, mu_odd, lead_pair;
	double k_single, mu_single, lead_single;
};

/* What start-up and the safe stop (daemon/setup.c) read and write besides
 * the cycle's registers, and how they judge what they find: one start-up
 * over every family, its differences here. A register 0 is one the family
 * does not have. (AX-12A | X series.) */
#define SM_SETTINGS_MAX 128
struct sm_setup {
	const char *family;             /* what a protocol found at start is said to run: "AX-12" | "X series" */
	const char *dxl_opt;            /* the `dxl` options that speak to it, for the fixes said: "" | "--protocol 2 " */
	long factory_baud;              /* said when servos are missing at another rate; 0: not said (the AX-12's
	                                   1 Mbps is the rate undulated uses) | 57600 */
	/* A surprise at start-up — an unknown model number, an output limit of
	 * 0 — is refused (X: the models' tables differ, and undulated would
	 * guess), or said and run on the AX-12's table and full output (the
	 * AX-12A, as undulated always did). */
	bool strict;
	uint16_t settings_len;          /* start-up's one READ from register 0: to Status Return Level (17 bytes) |
	                                   to the Bus Watchdog (99); at most SM_SETTINGS_MAX */
	uint16_t return_delay;          /* 5 | 9, 2 µs a unit on both */
	uint16_t status_return_level;   /* 16 | 68 */
	uint16_t firmware;              /* Version of Firmware: 2 | 6 */
	uint16_t output_limit;          /* the torque limit's ceiling, 2 bytes: Max Torque 14 | PWM Limit 36 */
	const char *output_limit_name;  /* "max torque" | "PWM Limit" */
	uint16_t current_limit;         /* 0 | Current Limit 38 (read where current_control) */
	uint16_t position;              /* Present Position, goal_size bytes: 36 | 132 */
	/* joint mode: angle limits not both 0 (CW, CCW Angle Limit 6, 8) | Operating
	 * Mode 11 position control within Min/Max Position Limit 52, 48 (SM_CAP_OPMODE) */
	uint16_t angle_limits;
	uint16_t opmode, pos_limit_min, pos_limit_max;
	/* the position loop's stiffness, each CW register followed by its CCW one:
	 * Compliance Margin 26, Slope 28 | 0 */
	uint16_t compliance_margin, compliance_slope;
	/* What makes every goal a slow ramp when another program left it non-zero,
	 * set to 0 at start: Moving Speed 32 (one of 2 bytes) | Profile Acceleration
	 * 108 and Velocity 112 (two of 4). */
	uint16_t ramp;
	uint8_t ramp_size, nramp;
	const char *ramp_name;          /* "moving speed" | "profile acceleration, velocity" */
	uint16_t watchdog;              /* 0 | Bus Watchdog 98 */
	uint16_t hwerr, shutdown;       /* Hardware Error Status 70, Shutdown 63 (SM_CAP_HWERR) | 0 */
};

struct sm_model {
	const char *name;               /* "XM430-W350" */
	int protocol;                   /* 1 or 2 */
	uint16_t number;                /* model number (register 0) */
	const struct dxl2_model *desc;  /* Protocol 2.0: its descriptor (control table, datasheet); NULL on 1.0 */
	unsigned caps;                  /* enum sm_cap */
	const char *limits_name;        /* what its own limits are called: "angle" | "position" */
	const struct sm_setup *setup;   /* start-up's and the safe stop's registers */
	/* registers the controller writes */
	uint16_t torque_enable;         /* 24 | 64 */
	uint16_t torque_limit;          /* Torque Limit 34 | Goal PWM 100, 2 bytes */
	uint16_t goal;                  /* Goal Position 30 | 116 */
	uint8_t goal_size;              /* 2 | 4 */
	/* the cycle's read: position, speed and load (fast), with voltage and
	 * temperature (slow) */
	uint16_t present;               /* 36 | 126 */
	uint8_t present_len, present_len_slow;
	/* the same values through the indirect areas (DXL2_CAP_INDIRECT): the
	 * block start-up maps (len 0: the model has none | Indirect Data 1 at
	 * 224, 10 or 13 bytes: the present block without its trajectories) */
	struct sm_read indirect;
	struct sm_block readback[SM_MAX_BLOCKS];
	size_t nreadback;
	int32_t pos_max;                /* 1023 | 4095 */
	/* raw position <-> radians from its centre (512 | 2048), the servo's units */
	double (*pos_to_rad)(int32_t raw);
	int32_t (*rad_to_pos)(double rad);
	/* What a status packet's error field says of it (the field is its
	 * protocol's): the bits that are a fault of its own (overload and
	 * overheating | none: the X series raises the alert and Hardware Error
	 * Status names the cause), the alert bit (0 | 0x80), and what says a write
	 * was refused (range, instruction, checksum bits | any error number). */
	uint8_t status_faults, status_alert, status_refused;
	/* torque actuation's drive register: Moving Speed 32 (wheel mode) | Goal
	 * PWM 100, or Goal Current 102 where current-controlled */
	uint16_t drive, drive_current;
	/* the family's decoders and the drive's units (sm_decode_present,
	 * sm_drive_raw: their contracts) */
	void (*decode_present)(const struct sm_model *m, const struct sm_read *rd, const uint8_t *b,
	                       struct sm_present *out);
	uint16_t (*drive_raw)(const struct sm_model *m, bool current, double ratio, int32_t limit);
	uint32_t torque_full;           /* full output in torque-limit units: 1023 | 885 */
	/* the datasheet's line at ref_voltage (the simulator's motors use the same) */
	double ref_voltage, stall_torque_nm, no_load_speed_rad_s, stall_current_a;
	/* the supply it is rated for (V): what it can be running at (sm_supply_plausible) */
	double rated_min_v, rated_max_v;
	bool current_control;           /* has a current-controlled drive (XM430: mode 0) */
	/* the motor's rotor seen through the gearbox, rotor inertia × ratio²
	 * (kg·m²): what a joint's inertia has besides its link */
	double reflected_inertia;
	/* Position actuation's defaults through this servo's own position loop
	 * (k 0: osc.h's, the AX-12A's, stand; an X model nobody tuned yet has the
	 * XL430-W250's, and position_from says so). */
	struct sm_position_defaults position;
	const char *position_from;      /* the model `position` was tuned on: its own name once tuned on it */
};

static inline bool sm_has(const struct sm_model *m, unsigned cap)
{
	return (m->caps & cap) == cap;
}

/* The AX-12A (what undulated assumed before it knew of others). */
const struct sm_model *sm_ax12(void);
/* The family a PING's model number names on that protocol; NULL when this
 * daemon does not know it. */
/* The model start-up reads a servo's settings with before its model number
 * is known (every model of a protocol shares those registers): the AX-12A
 * on 1, an X model on 2; NULL on another. */
const struct sm_model *sm_family(int protocol);
const struct sm_model *sm_by_number(int protocol, uint16_t number);

/* ---- units ---------------------------------------------------------------------------------- */
/* Angles: radians from the servo's centre (AX-12 512, X 2048), positive
 * towards larger raw values. sm_rad_to_pos() rounds to the nearest unit
 * within 0..pos_max, so sm_rad_to_pos(sm_pos_to_rad(n)) == n. */
double sm_pos_to_rad(const struct sm_model *m, int32_t raw);
int32_t sm_rad_to_pos(const struct sm_model *m, double rad);

/* A joint's range [lo_rad, hi_rad] (neutral included) as the model's
 * position registers, in whole units inside it: the nearest unit, moved one
 * inward when the nearest lies outside (never past 0..pos_max). The one rule
 * for every program that writes or checks a servo's own limits: undulated's
 * start-up (angle limits, Min/Max Position Limit) and `dxl doctor`'s
 * expectation of them; two roundings drifted apart once (the X doctor
 * rounded to the nearest and expected 1722..2374 where undulated wrote
 * 1723..2373 for +-0.5 rad). */
void sm_joint_range(const struct sm_model *m, double lo_rad, double hi_rad, int32_t *lo, int32_t *hi);

/* What one cycle read: the present block, present_len bytes (fast) or
 * present_len_slow (slow: voltage and temperature too). */
struct sm_present {
	int32_t pos_raw;
	double angle;                   /* rad, sm_pos_to_rad */
	double speed;                   /* rad/s, the servo's own Present Speed/Velocity */
	double load;                    /* signed fraction of full output (XM430: of the stall current) */
	bool slow;
	double voltage, temperature;    /* V, °C; NaN unless slow */
};
/* False (nothing decoded) when n is neither length. */
bool sm_decode_present(const struct sm_model *m, const uint8_t *bytes, size_t n, struct sm_present *out);
/* The model's direct read: its present registers where they lie. */
struct sm_read sm_direct_read(const struct sm_model *m);
/* The same from a block read as rd says (the direct read or the indirect
 * block); false when n is neither of rd's lengths. */
bool sm_decode_read(const struct sm_model *m, const struct sm_read *rd, const uint8_t *bytes, size_t n,
                    struct sm_present *out);

/* What a read-back says about the servo; -1 (NaN) for what the block did not
 * hold. Each family fills what it has. */
struct sm_state {
	int torque;                     /* Torque Enable */
	int torque_limit;               /* AX Torque Limit | X Goal PWM */
	int margin_cw, margin_ccw;      /* AX compliance margins */
	int slope_cw, slope_ccw;        /* AX compliance slopes (the position loop's stiffness) */
	int hwerr;                      /* X Hardware Error Status (70) */
	int watchdog;                   /* X Bus Watchdog (98): 0 off, 1..127 × 20 ms, 255 tripped */
	int opmode;                     /* X Operating Mode (11) */
	int profile_velocity, profile_acceleration;   /* X (112, 108): 0 = none */
	int32_t pos_min, pos_max;       /* X Min/Max Position Limit (52, 48) */
	int pwm_limit, current_limit;   /* X (36, 38) */
	double voltage, temperature;
};
void sm_state_unknown(struct sm_state *s);
/* Decode read-back block `block` (len bytes of it) into *s, leaving what it
 * does not hold as it was. False when block or n is not the model's. */
bool sm_decode_readback(const struct sm_model *m, size_t block, const uint8_t *bytes, size_t n,
                        struct sm_state *s);

/* ---- the status a servo sent ------------------------------------------------------------------
 * AX-12: the error byte (DXL_ERRBIT_*). X series: the ERR field (alert bit
 * 7, an error number in bits 0-6). */
/* The fault bits in the AX-12's layout this status shows by itself:
 * overload and overheating on the AX-12; none on the X series, whose status
 * only raises the alert (sm_alert) and whose causes are read back. */
uint8_t sm_status_faults(const struct sm_model *m, uint8_t status);
bool sm_alert(const struct sm_model *m, uint8_t status);
/* A write's acknowledgement that says the servo did not take it: AX-12 range,
 * instruction or checksum bits; X series any error number. */
bool sm_write_refused(const struct sm_model *m, uint8_t status);

/* ---- Hardware Error Status (X series) -----------------------------------------------------------
 * The bits that are a fault of the servo (it may have shut down: Shutdown,
 * 63, decides): overheating, motor encoder, electrical shock, overload. An
 * input voltage outside the limits is reported, as the AX-12's voltage bit. */
#define SM_HWERR_FAULTS (DXL2_HWERR_OVERHEAT | DXL2_HWERR_ENCODER | DXL2_HWERR_SHOCK | DXL2_HWERR_OVERLOAD)
/* The Bus Watchdog's value after it stopped the servo (−1 as a byte). */
#define SM_WATCHDOG_TRIPPED 0xFF

/* ---- the supply ----------------------------------------------------------------------------
 * A supply reading the servo can be running at: its rated range, widened by
 * SM_SUPPLY_TOLERANCE either side for a supply's regulation and the 0.1 V
 * reading (the AX-12A's 12 V top then admits a full 3S battery, 12.6 V).
 * Anything else is a servo (or a reading) that must not be believed: the PWM
 * drive scales with the supply, so such a reading would be a gain. */
#define SM_SUPPLY_TOLERANCE 0.05
bool sm_supply_plausible(const struct sm_model *m, double volts);
/* The plausible range itself, for messages and bounds. */
void sm_supply_range(const struct sm_model *m, double *lo, double *hi);

/* A register's name for messages ("torque limit", "goal_pwm"); "register"
 * when the model's table has none at addr. */
const char *sm_register_name(const struct sm_model *m, uint16_t addr);
/* Its torque-limit register is its PWM drive too (X: Goal PWM caps position
 * control and is PWM control's drive): under the PWM drive only the drive's
 * SYNC_WRITE may set it. */
bool sm_limit_is_pwm_drive(const struct sm_model *m);

/* ---- torque actuation ----------------------------------------------------------------------
 * The register torque actuation's SYNC_WRITE carries, 2 bytes: AX-12 Moving
 * Speed (32, wheel mode); X Goal Current (102, current) or Goal PWM (100). */
uint16_t sm_drive_register(const struct sm_model *m, bool current);
/* The operating mode of that drive on the X series (0 current, 16 PWM); 3,
 * position control, is joint mode. */
#define SM_OPMODE_POSITION DXL2_OPMODE_POSITION
uint8_t sm_drive_opmode(bool current);
/* A signed output ratio in [-1, 1] as that register's raw value: a PWM
 * duty (AX-12: 0..1023 with bit 10 CW; X: 885 = 100 %), or the share of the
 * datasheet's stall current (XM430, 2.69 mA a unit). X values are kept
 * within ±limit (PWM Limit or Current Limit, the servo refuses more); a
 * non-finite ratio gives 0. */
uint16_t sm_drive_raw(const struct sm_model *m, bool current, double ratio, int32_t limit);
/* Torque actuation's defaults (osc_default_torque_params) are for the AX-12A's
 * joint: the same link on this model's servo has this many times its
 * inertia (the AX-12A: 1). */
double sm_torque_scale(const struct sm_model *m);
/* Position actuation's default k, μ (*k, *mu) for joint j of njoints, and the
 * robot's lead (*lead), on this model; false when osc.h's (the AX-12A's) stand. */
bool sm_position_defaults(const struct sm_model *m, size_t j, size_t njoints, double *k, double *mu, double *lead);

#endif
