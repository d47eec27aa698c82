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
};

/* A register by name for the simulator's poke and peek: its address, its
 * table name, and the values its bytes can hold. */
struct sim_joint_reg {
	const char *name;
	uint16_t addr;
	long lo, hi;
};

struct sim_joint_ops {
	int protocol;                                      /* 1 or 2 */
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
};

/* The table of model m's family. */
const struct sim_joint_ops *sim_joint_ops_of(enum sim_model m);
/* Set the joint up as model m with its family's table (j->ops). */
void sim_joint_place(struct sim_joint *j, enum sim_model m, const struct sim_joint_place *p);

#endif
