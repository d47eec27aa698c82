/*
 * joint.h — a simulated joint's servo, whatever its model: what the
 * simulator's physics, its bus and its commands ask of a servo, as one table
 * of operations per servo family — the AX-12A on Protocol 1.0 (servo.c, its
 * motor through motor.c) and the X series on 2.0 (xservo.c, its controllers
 * in xdrive.c). sim.c and simbus.c call these and never ask which family a
 * joint is; a joint gets its table from its model (sim_joint_place). The
 * packets themselves go by the bus's protocol (simbus.c).
 */
#ifndef UNDULATE_SIM_JOINT_H
#define UNDULATE_SIM_JOINT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl_proto.h"
#include "fault.h"
#include "model.h"
#include "motor.h"

struct sim_joint;

/* How a scenario sets a servo up: its ID, Baud Rate register, return delay
 * (µs, < 0: the factory's) and the family's options. */
struct sim_joint_place {
	uint8_t id;
	uint8_t baud_reg;
	int delay_us;
	bool eeprom_needs_torque_off;   /* AX-12A */
	double overload_time_s;
	int firmware;                   /* X series: the version it reports and acts as; 0 the model's */
	bool no_indirect;               /* X series: without the indirect areas (sim_xservo_options) */
};

/* A register by name for the simulator's poke and peek: its address, its
 * table name, and the values its bytes can hold. */
struct sim_joint_reg {
	const char *name;
	uint16_t addr;
	long lo, hi;
};

struct sim_joint_ops {
	const struct dxl_proto *proto;                     /* the protocol it speaks */
	const char *family;                                /* "AX-12A", "X series" */
	void (*place)(struct sim_joint *j, enum sim_model m, const struct sim_joint_place *p);
	uint8_t (*id)(const struct sim_joint *j);
	bool (*powered)(const struct sim_joint *j);
	bool (*torque)(const struct sim_joint *j);        /* powered, torque on */
	long (*baud)(const struct sim_joint *j);          /* bps its Baud Rate register names; 0 none */
	/* the servo's view of the last step (faults applied): present values */
	void (*sense)(struct sim_joint *j, double dt);
	/* one step of the joint alone (the line world) */
	void (*step)(struct sim_joint *j, double dt);
	/* its drive over the next step (the plane world integrates it) */
	void (*drive)(struct sim_joint *j, double dt, struct sim_motor_drive *d);
	/* present values before the first step; the goal where it stands */
	void (*power_up)(struct sim_joint *j);
	/* power back after power_off: boots as the real one does */
	void (*power_on)(struct sim_joint *j);
	void (*power_off)(struct sim_joint *j);
	/* NULL with err set ("unknown register 'x'") when the table has none */
	bool (*reg)(const struct sim_joint *j, const char *name, struct sim_joint_reg *r, char *err, size_t cap);
	void (*poke)(struct sim_joint *j, uint16_t addr, long v);   /* no write rules */
	long (*peek)(const struct sim_joint *j, uint16_t addr);
	/* "id=... power=... ... " up to (not including) "faults=" */
	int (*describe)(const struct sim_joint *j, char *buf, size_t cap);
	/* a stuck-error fault this servo's status can carry; else why not */
	bool (*error_fits)(const struct sim_fault *f, const char **why);

	/* On the bus: a request of its protocol answered, the status packet in
	 * out (its length; 0: no reply); a damaged request's ID and instruction
	 * answered with the checksum error if it was addressed. */
	int (*handle)(struct sim_joint *j, const struct dxl_frame *req, uint8_t *out, size_t cap);
	int (*handle_damaged)(struct sim_joint *j, uint8_t id, uint8_t instr, uint8_t *out, size_t cap);
	/* the reply faults (fault.h) on one of its status packets, cap bytes of room */
	bool (*reply_faults)(struct sim_joint *j, uint64_t *rng, uint8_t *pkt, size_t *len, size_t cap,
	                     uint8_t *garbage, size_t *ngarbage, int64_t *extra_delay_ns);
	int64_t (*return_delay_ns)(const struct sim_joint *j);

	/* Configuration: the Baud Rate register for bps (DXL_OK, or not one of
	 * rate_names); the largest ID and Baud Rate register value. */
	int (*baud_reg)(long bps, uint8_t *reg);
	const char *rate_names;
	uint8_t max_id;
	int max_baud_reg;
	/* The configuration's [motor] section is its motor as given (the
	 * AX-12A's, measured first); else its model's datasheet, overridden by
	 * what the section sets. */
	bool motor_from_config;
	/* Its bus's summary names the protocol and its word is followed by
	 * NAME.model=: the AX-12A's outputs predate the other families and stay
	 * as they were. */
	bool says_family;
};

/* The table of model m's family. */
const struct sim_joint_ops *sim_joint_ops_of(enum sim_model m);
/* Set the joint up as model m with its family's table (j->ops). */
void sim_joint_place(struct sim_joint *j, enum sim_model m, const struct sim_joint_place *p);

#endif
