/*
 * scenario.h — what undulate-sim simulates: the [sim] settings, the contact
 * world, the motor parameters, the robots (one bus each) and timed events.
 * Read from an INI file (sim-bridge/README.md documents every key), from the
 * quick command-line form, and from "section.key=value" overrides (--set).
 */
#ifndef UNDULATE_SIM_SCENARIO_H
#define UNDULATE_SIM_SCENARIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "model.h"
#include "motor.h"
#include "plane.h"
#include "simbus.h"
#include "textfile.h"
#include "world.h"

#define SIM_MAX_BUSES 32     /* robots (one bus each); the benchmark runs 20 */
#define SIM_MAX_EVENTS 512   /* timed commands in a scenario (a long run samples every few s) */
#define SIM_CMD_MAX 256      /* one command line */
#define SIM_URL_MAX 256
/* Longest --duration: about 31 years (as int64 ns it stays far from overflow). */
#define SIM_MAX_DURATION_S 1e9
/* A scenario file larger than this is refused (the presets are ~1 kB). */
#define SIM_SCENARIO_MAX_BYTES TEXTFILE_MAX_BYTES

struct sim_robot_config {
	char name[SIM_NAME_MAX];
	char link[SIM_PATH_MAX];     /* empty: <link_dir>/<name> */
	uint8_t ids[SIM_BUS_MAX_SERVOS];
	size_t nids;
	int contact_id;              /* servo carrying the contact body; -1 none, -2 = last id */
	bool neutral_set;
	double neutral;              /* m */
	long baud;                   /* 0: the [sim] baud */
	double latency_ms;           /* < 0: the [sim] value */
	int echo;                    /* -1: the [sim] value */
	int return_delay_us;         /* < 0: the [sim] value */
	int servo_baud_reg;          /* < 0: the register matching the bus baud */
	int firmware;                /* X series' firmware version; 0: the model's (46) */
	bool mirror;                 /* the body moves left for a positive angle (facing rigs) */
	bool beta_set;               /* the robot's own mobility, in place of world.beta */
	double beta;                 /* s */
	/* the plane world: where the robot's chain is centred and where its head
	 * points (unset: in a row along x, heads towards +y) */
	bool position_set, heading_set;
	double x, y;                 /* m */
	double heading;              /* rad (the key is in degrees) */
	/* Servo models: one for every ID, or one per ID in ids' order; none:
	 * the [sim] model. sim_config_finish() leaves one per ID. */
	enum sim_model models[SIM_BUS_MAX_SERVOS];
	size_t nmodels;
};

struct sim_event {
	double at;                   /* s after start */
	char command[SIM_CMD_MAX];   /* control-socket syntax */
};

struct sim_config {
	/* [sim] */
	double rate_hz;              /* physics steps per second (>= 1000) */
	double truth_hz;             /* SIM.TRUTH messages per second */
	double duration_s;           /* 0 = until a signal */
	uint64_t seed;
	char lcm_url[SIM_URL_MAX];   /* empty: LCM's default */
	char link_dir[SIM_PATH_MAX];
	char control[SIM_PATH_MAX];  /* control socket path, empty = none */
	long baud;                   /* the pty's initial rate; 0: the servos' factory rate */
	bool baud_follows_tty;       /* the bus runs at the rate the controller sets */
	double latency_ms;
	bool echo;
	int return_delay_us;         /* initial EEPROM value of every servo; < 0 = factory 500 µs */
	int firmware;                /* X series' firmware version of every servo; 0: the model's (46) */
	/* X series: the servos have no indirect areas (168-661 answer the
	 * access error): a firmware or clone without them, for the daemon's
	 * fallback to the direct read */
	bool no_indirect;
	double ambient_c;
	double initial_spread;       /* rad: initial angles uniform in ±spread (seeded) */
	bool eeprom_needs_torque_off;
	double overload_time_s;
	/* [world] */
	int world_kind;              /* SIM_WORLD_ROW (the theory's line) or SIM_WORLD_PLANE */
	struct sim_world_params world;
	/* the plane world's links, contact, drag (restitution: world's) */
	struct plane_params plane;
	bool ends_set;               /* walls across the robots' length at y = ends_back, ends_front */
	double ends_back, ends_front;
	double wall_force_max;       /* N: a closing side wall holds while the robots push it harder (0: never) */
	double separation;           /* d̃ between neighbours' neutral positions */
	double amplitude;            /* rad: A in d̃ = d / (2·lever·A) */
	double spacing;              /* m: if > 0, neighbour distance (overrides separation) */
	double lever;                /* m per rad */
	double half_width;           /* m */
	double effective_mass;       /* kg; <= 0: motor inertia / lever² */
	int walls;                   /* SIM_WALLS_* */
	/* the servo model of every robot without its own (one, or one per ID) */
	enum sim_model models[SIM_BUS_MAX_SERVOS];
	size_t nmodels;
	/* [motor] */
	struct sim_motor_params motor;
	unsigned motor_set;          /* SIM_MOTOR_SET_* bits: the [motor] keys given */
	/* robots, left to right */
	struct sim_robot_config robots[SIM_MAX_BUSES];
	size_t nrobots;
	struct sim_event events[SIM_MAX_EVENTS];
	size_t nevents;
};

enum { SIM_WALLS_NONE, SIM_WALLS_AUTO, SIM_WALLS_FIXED };
enum { SIM_WORLD_ROW, SIM_WORLD_PLANE };

/* [motor] keys given in the scenario or with --set: they apply to every
 * model; the others keep each model's own values (model.c). */
enum {
	SIM_MOTOR_SET_INERTIA = 1u << 0,
	SIM_MOTOR_SET_VISCOUS = 1u << 1,
	SIM_MOTOR_SET_COULOMB = 1u << 2,
	SIM_MOTOR_SET_STALL_TORQUE = 1u << 3,
	SIM_MOTOR_SET_NO_LOAD_SPEED = 1u << 4,
	SIM_MOTOR_SET_THERMAL_TAU = 1u << 5,
	SIM_MOTOR_SET_HEAT_GAIN = 1u << 6,
	SIM_MOTOR_SET_DRIVE = 1u << 7,
};

/* The motor parameters of a servo of model m under this configuration: the
 * AX-12A's are c->motor; another model's are its own with the [motor] keys
 * given, the supply voltage and the ambient temperature on top. */
void sim_config_motor_params(const struct sim_config *c, enum sim_model m, struct sim_motor_params *p);
/* The protocol a robot's bus speaks (1 or 2), after sim_config_finish(). */
int sim_config_robot_protocol(const struct sim_robot_config *r);

void sim_config_defaults(struct sim_config *c);
/* Read an INI file on top of c. Only a regular file of at most
 * SIM_SCENARIO_MAX_BYTES is read (a FIFO, a device, a directory is refused
 * without blocking). 0, or -1 with "file:line: why" or "file: why" in err. */
int sim_config_load(struct sim_config *c, const char *path, char *err, size_t errcap);
/* The same from len bytes of text (no NUL needed; a NUL byte is an error);
 * name is the file name used in messages. */
int sim_config_load_text(struct sim_config *c, const char *name, const char *text, size_t len, char *err,
                         size_t errcap);
/* Apply one "section.key=value" (e.g. world.separation=0.4,
 * "robot left.ids=1,2"). 0 or -1 with err. */
int sim_config_set(struct sim_config *c, const char *assignment, char *err, size_t errcap);
/* Add one robot (the quick form): link path and an ID list "1,2". */
int sim_config_add_robot(struct sim_config *c, const char *name, const char *link, const char *ids,
                         char *err, size_t errcap);
/* Fill derived values (links from link_dir) and check the whole. */
int sim_config_finish(struct sim_config *c, char *err, size_t errcap);
/* Parse an ID list "1,2,5-7" into ids; returns the count or -1. */
int sim_parse_ids(const char *text, uint8_t *ids, size_t cap);

#endif
