/*
 * config.h — the robot's configuration: an INI file (libinih) plus command-line
 * overrides, validated as a whole. Every error names where it came from:
 *     robot1.conf:12: [joint.1] k: not a number 'abc'
 * Unknown sections and keys are errors: a typo on a robot must not silently
 * leave a default in place.
 */
#ifndef UNDULATE_DAEMON_CONFIG_H
#define UNDULATE_DAEMON_CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "osc.h"
#include "params.h"
#include "port.h"

#define CFG_MAX_JOINTS   OSC_MAX_JOINTS   /* joints per robot: the oscillator's bound */
#define CFG_NAME_MAX     48               /* robot name; channels are "<name>.STATE" */
#define CFG_PATH_MAX     256              /* port path, LCM URL */
#define CFG_ERR_MAX      256              /* one error line */
#define CFG_MAX_ERRORS   16               /* errors kept for reporting (all are counted) */
/* Ports (buses) per robot, the [robot] section's own included: each is a
 * cycle of its own on the one loop (daemon/README.md, "Several buses"). Four
 * covers a 24-joint robot at 6 servos a bus, and keeps the loop's poll()
 * small. */
#define CFG_MAX_BUSES    4
#define CFG_BUS_ROBOT    0                /* bus index of the [robot] section's port */

enum cfg_mode { CFG_MODE_LIMP = 0, CFG_MODE_HOLD = 1, CFG_MODE_SINUSOID = 2, CFG_MODE_OSCILLATOR = 3 };
#define CFG_NMODES 4
enum cfg_safe { CFG_SAFE_HOLD, CFG_SAFE_LIMP };
enum cfg_velocity { CFG_VEL_SERVO, CFG_VEL_FILTERED };
/* How OSCILLATOR drives a joint: position goals integrated from the measured
 * state (the paper's robots), or the law's torque itself through the servo's
 * wheel mode (the paper's torque-controlled pair rig; CONTROL.md). */
enum cfg_actuation { CFG_ACT_POSITION, CFG_ACT_TORQUE };
/* What the wheel-mode register drives: the AX-12's PWM duty (the controller
 * adds the back-EMF it loses) or a current-controlled drive's torque. */
enum cfg_drive { CFG_DRIVE_PWM, CFG_DRIVE_CURRENT };
/* Where commands may come from (README, "Safety"): nowhere; this computer
 * only (the local command socket, whose file permissions decide who); or
 * also the LCM network, each command signed with the shared key. */
enum cfg_commands { CFG_CMD_OFF, CFG_CMD_LOCAL, CFG_CMD_NETWORK };
/* The bus's protocol: Dynamixel 1.0 (AX-12), 2.0 (X series), or found at
 * start-up by PINGs (daemon/README.md, "Protocol"). */
/* CFG_PROTO_n is the bus's protocol number n (bus.h BUS_PROTOCOL_n): the
 * daemon takes a configured protocol as it is. */
enum cfg_protocol { CFG_PROTO_AUTO = 0, CFG_PROTO_1 = 1, CFG_PROTO_2 = 2 };

struct cfg_joint {
	struct osc_joint_params osc;
	double neutral;        /* rad from the servo centre that is x = 0 */
	double limit_min;      /* rad relative to neutral */
	double limit_max;
	double max_step;       /* rad a goal may move per cycle */
	/* torque actuation: the physical parameters that took their defaults
	 * (CFG_TQ_* bits), scaled once the servo model is known */
	unsigned torque_defaults;
	/* position actuation: k and μ if they took osc.h's defaults (CFG_TQ_K,
	 * CFG_TQ_MU), replaced by the servo model's once it is known */
	unsigned position_defaults;
};
#define CFG_TQ_K        (1u << 0)
#define CFG_TQ_C        (1u << 1)
#define CFG_TQ_MU       (1u << 2)
#define CFG_TQ_INERTIA  (1u << 3)
#define CFG_TQ_FRICTION (1u << 4)

/* One port of the robot. Bus CFG_BUS_ROBOT is the [robot] section's port
 * (filled by cfg_finish); the others are [bus.NAME] sections. Which joint is
 * on which bus says [robot] ids ("1, 2, tail:1, tail:2": joints 3 and 4 are
 * servos 1 and 2 on bus tail), so joint numbers stay the robot's whatever the
 * bus, and IDs may repeat on different buses. */
struct cfg_bus {
	char name[CFG_NAME_MAX];       /* "robot" for the [robot] port, else NAME of [bus.NAME] */
	char port[CFG_PATH_MAX];
	char usb_serial[64];
	long baud;                     /* 0 until cfg_finish: the robot's */
	size_t joints[CFG_MAX_JOINTS]; /* cfg_finish: the robot's joint indices on it, in the robot's order */
	size_t njoints;
};

struct cfg {
	/* [robot] */
	char name[CFG_NAME_MAX];
	char port[CFG_PATH_MAX];
	char usb_serial[64];
	long baud;
	enum cfg_protocol protocol;    /* 1, 2, or auto (found at start-up) */
	uint8_t ids[CFG_MAX_JOINTS];
	size_t njoints;
	enum cfg_mode mode;            /* the start mode; HOLD when none is given (mode_given) */
	bool mode_given;               /* `mode` in the file or --mode/--set: else the first-run default */
	char lcm_url[CFG_PATH_MAX];
	int priority;                  /* SCHED_FIFO priority, 0 = normal scheduling */
	bool mlockall;
	enum cfg_safe safe_stop;       /* what SIGTERM leaves behind */
	enum cfg_safe fault_action;    /* what a persistent servo fault leaves behind */
	enum cfg_velocity velocity_source;
	double velocity_cutoff_hz;     /* low-pass of the filtered position difference */
	enum cfg_commands commands;    /* where commands are accepted from */
	char command_key[CFG_PATH_MAX];/* commands = network: the shared key's file (root-only) */
	double command_window_s;       /* commands = network: a signed command's time must be this close */
	char run_dir[CFG_PATH_MAX];    /* the local command socket's directory ("": the default) */
	bool echo;                     /* single-wire adapter echoes our bytes */
	enum port_rs485 rs485;         /* a UART's half-duplex buffer switched by RTS (port.h) */
	long adapter_latency_us;       /* -1: measure (FTDI latency timer) */
	double period_ms;              /* control period */
	double servo_lead_s;           /* oscillator horizon beyond the period (CONTROL.md);
	                                  NaN until cfg_finish(): then chosen by compliance_margin */
	bool servo_lead_default;       /* servo_lead_s took its default (cfg_finish) */
	long compliance_margin;        /* written to both margins at start-up; -1: leave the servo's */
	long compliance_slope;         /* written to both slopes at start-up; -1: leave the servo's (the
	                                  position loop's stiffness: PHYSICS.md, daemon/README.md) */
	enum cfg_actuation actuation;  /* OSCILLATOR through goals or through torque (wheel mode) */
	enum cfg_drive torque_drive;   /* torque actuation: pwm (AX-12) or current */
	double stall_torque;           /* N·m at 12 V and full output (AX-12A: 1.5) */
	double no_load_speed;          /* rad/s at 12 V and full output (AX-12A: 59 rpm = 6.18) */
	bool stall_torque_given, no_load_speed_given;   /* else the servo model's datasheet line */
	long bus_watchdog_ms;          /* X series: Bus Watchdog (98), 0 = off, in 20 ms steps; -1 = the servo's own */
	int fault_reboots;             /* X series: REBOOTs of one servo after a shutdown, per 'clear' */
	/* X series: the cycle reads the present values through the indirect
	 * block start-up maps (setup_indirect: 13 bytes on slow cycles where
	 * the direct block is 21); off: the registers where they lie */
	bool indirect;
	long bus_margin_us;            /* slack added to every bus timeout */
	char lockstep[CFG_PATH_MAX];   /* the simulator's lockstep socket: virtual time ("": real time) */
	double ramp_s;                 /* blend time for start-up and mode switches */
	double backoff_torque;         /* torque limit (fraction of max) while a joint backs off */
	double fault_backoff_s;        /* wait before a recovery attempt */
	int fault_retries;             /* recovery attempts before fault_action */
	int stale_limit;               /* stale cycles before a joint is reported lost */
	double silent_s;               /* a joint without a valid reading this long latches the fault action */
	/* [joint.N], N = 1..njoints */
	struct cfg_joint joint[CFG_MAX_JOINTS];
	/* the ports: bus[CFG_BUS_ROBOT] is [robot]'s (complete after cfg_finish),
	 * bus[1..nbuses-1] the [bus.NAME] sections in the order they came */
	struct cfg_bus bus[CFG_MAX_BUSES];
	size_t nbuses;                 /* 1 + the [bus.NAME] sections */
	size_t joint_bus[CFG_MAX_JOINTS];   /* each joint's bus index ([robot] ids: "NAME:ID") */
	/* [sinusoid] */
	double amplitude, frequency, phase;
	/* torque actuation: the clock as a torque law (osc_clock_torque); 0: the
	 * servo's own position loop follows the clock, in joint mode */
	double sin_stiffness;          /* k_s, N·m/rad */
	double sin_damping;            /* d_s, N·m·s/rad */

	/* where a config came from, for messages */
	char source[CFG_PATH_MAX];
};

/* The result of parsing: every error, formatted. */
struct cfg_errors {
	size_t count;                              /* all errors seen */
	char line[CFG_MAX_ERRORS][CFG_ERR_MAX];    /* the first CFG_MAX_ERRORS of them */
	bool file_refused;                         /* cfg_load_file() read nothing: not a config file */
};

/* Defaults: robot "robot", no port, 1 Mbps, OSCILLATOR, safe_stop hold, ... */
void cfg_defaults(struct cfg *c);
/* Parse an INI file into c (on top of what is there). Returns errors->count == 0.
 * Only a regular file of at most 1 MiB with no NUL byte is read (common/textfile.h);
 * anything else (a FIFO, a device, a directory, a missing path) is one error
 * "PATH: why", at once, sets errors->file_refused and leaves c as it was. */
bool cfg_load_file(struct cfg *c, const char *path, struct cfg_errors *errors);
/* Same, from a string; `name` is used in messages in place of a file name. */
bool cfg_load_string(struct cfg *c, const char *name, const char *text, struct cfg_errors *errors);
/* Apply one "section.key=value" override (section "joint.N" allowed). */
bool cfg_override(struct cfg *c, const char *assignment, struct cfg_errors *errors);
/* Set one key; `where` prefixes error messages ("file:line"). */
bool cfg_set(struct cfg *c, const char *where, const char *section, const char *key,
             const char *value, struct cfg_errors *errors);
/* Fill unset joint parameters from osc_default_params() and check the whole
 * (ids present, limits ordered, ...). Call once after all sources. */
bool cfg_finish(struct cfg *c, struct cfg_errors *errors);

/* Documented ranges of the per-joint and sinusoid parameters (common/params.h:
 * one table for the file, commands and the programs that send them). Returns
 * false for an unknown name. */
bool cfg_param_range(const char *key, struct param_range *out);
/* May a command change it? Only the configuration decides where a joint may
 * go: neutral, the limits and max_step are not commandable. */
bool cfg_param_commandable(const char *key);
/* The commandable parameters' names, for messages ("k, c, mu, ..."). */
const char *cfg_param_commandable_list(void);
/* Cross-checks a joint's oscillator parameters as a whole (the range table
 * cannot): its natural frequency sqrt(k/I)/2π at most CFG_MAX_NATURAL_HZ, so
 * that one control period integrates it accurately. False with *why. */
#define CFG_MAX_NATURAL_HZ 5.0
bool cfg_joint_check(const struct cfg_joint *j, char *why, size_t cap);
const char *cfg_commands_name(enum cfg_commands c);
const char *cfg_protocol_name(enum cfg_protocol p);   /* "1", "2", "auto" */
/* Bus Watchdog (98) units (20 ms each) for bus_watchdog_ms, rounded up: the
 * servo never stops sooner than configured. */
uint8_t cfg_watchdog_units(const struct cfg *c);
bool cfg_param_is_joint(const char *key);   /* k, c, ..., max_step */
bool cfg_param_is_robot(const char *key);   /* amplitude, frequency, phase, stiffness, damping */
/* A robot parameter's value in the context of the whole configuration (the
 * range table cannot say it): [sinusoid] stiffness > 0 needs torque
 * actuation. False with *why. */
bool cfg_robot_param_check(const struct cfg *c, const char *key, double value, char *why, size_t cap);
/* Value of a per-robot parameter by name (the file's [sinusoid]); NULL if unknown. */
double *cfg_robot_param(struct cfg *c, const char *key);
/* Value of a per-joint parameter by name (the file's [joint.N]); NULL if unknown. */
double *cfg_joint_param(struct cfg_joint *j, const char *key);

/* The parameters that may change while the robot runs — by command, or by
 * the tuner (which also moves the horizon's lead). The configuration gives
 * their initial values; the controller (control.h) holds the live ones and
 * is the only one that changes them, so a struct cfg is never written once
 * the robot runs. */
struct cfg_params {
	struct osc_joint_params osc[CFG_MAX_JOINTS];
	double servo_lead_s;
	double amplitude, frequency, phase;   /* [sinusoid] */
	double sin_stiffness, sin_damping;
};
/* servo_lead_s's range, one for the file and the tuner (CONTROL.md). */
#define CFG_LEAD_MAX_S 0.2
/* A joint's default step limit as a speed (rad/s): max_step's default is
 * this times period_ms, 0.1 rad at 10 ms. */
#define CFG_MAX_STEP_SPEED 10.0
/* The bus watchdog and silent_s against the period: each at least this many
 * periods, or one late cycle trips them (CONTROL.md, "Other rates"). */
#define CFG_MIN_PERIODS 3
/* bus_watchdog_ms when not set (ms); above a period of 10 ms, ten periods.
 * Until cfg_finish an unset one holds CFG_WATCHDOG_UNSET, so that a file's
 * own 100 is kept as it says. */
#define CFG_WATCHDOG_DEFAULT 100
#define CFG_WATCHDOG_UNSET (-2)
/* The one check of a change to a live parameter, by a command or the tuner:
 * `key` is a commandable parameter (cfg_param_commandable) or servo_lead_s;
 * joint -1 is every joint (a robot parameter takes -1 only); the value is
 * finite, inside the parameter's range (cfg_param_range; servo_lead_s
 * 0..CFG_LEAD_MAX_S) and passes the cross-checks (cfg_robot_param_check,
 * cfg_joint_check) with the other parameters' `live` values. False with *why
 * ("parameter k: 20 out of range 0.0001..10"). */
bool cfg_params_check(const struct cfg *c, const struct cfg_params *live, const char *key, int joint, double value,
                      char *why, size_t cap);
/* The initial values: the configuration's. */
void cfg_params_init(struct cfg_params *p, const struct cfg *c);
/* c with the values of p in place of its own (a file of what ran). */
void cfg_params_put(struct cfg *c, const struct cfg_params *p);
/* The live value of a commandable parameter by name (amplitude ... for the
 * robot, k ... of joint j), or of servo_lead_s; NULL if unknown or j is out
 * of range for a joint's parameter. */
double *cfg_params_field(struct cfg_params *p, const char *key, size_t joint);

const char *cfg_mode_name(enum cfg_mode m);     /* "OSCILLATOR" */
bool cfg_mode_parse(const char *s, enum cfg_mode *out);   /* case-insensitive */

/* Torque actuation's defaults are an AX-12A joint's: a joint on another
 * servo has `scale` times its inertia, and the parameters of p that took the
 * defaults in c (not those given) scale with it. Once: the caller's
 * (ctl_model_defaults). */
void cfg_params_scale_torque_defaults(struct cfg_params *p, const struct cfg *c, size_t joint, double scale);
/* Position actuation on a servo whose defaults are not osc.h's: k and μ of
 * the joint in p, where they took the defaults in c, become these. True when
 * anything changed. */
bool cfg_params_position_defaults(struct cfg_params *p, const struct cfg *c, size_t joint, double k, double mu);

/* Buses that carry joints (after cfg_finish): 1 for a one-port robot.
 * Bus CFG_BUS_ROBOT may carry none when every joint is on a [bus.NAME]. */
size_t cfg_buses_used(const struct cfg *c);
/* Joint `joint` is on bus `bus` (after cfg_finish). */
bool cfg_bus_has_joint(const struct cfg *c, size_t bus, size_t joint);

/* The robot reduced to one of its buses, as if it had only that one: its
 * joints (in the robot's order, their [joint.N] with them), its IDs, its
 * port and baud on the [robot] section; `dxl doctor --bus NAME` checks a bus
 * at a time. After cfg_finish. The bus is named (its [bus.NAME], or "robot");
 * false with *why (the buses there are) when there is none of that name or
 * it has no joint. */
bool cfg_only_bus(struct cfg *c, const char *name, char *why, size_t cap);

/* Print every key with its current value as INI (for --check-config -v). */
void cfg_print(const struct cfg *c, void *file);

#endif
