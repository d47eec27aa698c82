/*
 * model.h — the servo models undulate-sim simulates, and the facts about each
 * that the simulator needs beyond its control table: the protocol it speaks,
 * its default baud rate, and its motor's datasheet line (stall torque and
 * no-load speed at 12 V, stall current, gear ratio). The control tables
 * and datasheets themselves are protocol/dxl2_table.c's model descriptors
 * (AX-12A and X series, one list); the sources of every number are in sim-bridge/PHYSICS.md.
 */
#ifndef UNDULATE_SIM_MODEL_H
#define UNDULATE_SIM_MODEL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl2_table.h"
#include "motor.h"

/* Model m is protocol/dxl2_table.c's descriptor m: 0 the AX-12A, 1.. the X models
 * (sim_model_count() in all); the two named here are the first two there. */
enum sim_model {
	SIM_MODEL_AX12A = 0,
	SIM_MODEL_XL430_W250 = 1,
	SIM_MODEL_XM430_W350 = 2,
};
int sim_model_count(void);

struct sim_model_info {
	const char *name;            /* "xl430-w250": the option and scenario value */
	const char *label;           /* "XL430-W250": for people */
	int protocol;                /* 1 or 2 */
	long default_baud;           /* bps of a new servo (factory baud register) */
	uint8_t firmware;            /* the version the simulated servo reports */
	/* The datasheet line at 12 V (e-manual specifications). */
	double stall_torque_nm;
	double no_load_speed_rpm;
	double stall_current_a;
	double gear_ratio;
	/* The motor rotor's own inertia (kg·m²): not in the datasheets, an
	 * estimate for the motor's class (PHYSICS.md); seen through the gearbox
	 * as rotor · ratio². */
	double rotor_inertia;
	uint16_t model_number;       /* register 0 */
};

const struct sim_model_info *sim_model_info(enum sim_model m);
/* "ax12a", "xl430-w250", "xm430-w350", ... (case-insensitive; "AX-12A" too).
 * Returns 0 and *m, or -1. */
int sim_model_parse(const char *name, enum sim_model *m);
/* The names accepted, for messages: "ax12a, xl430-w250, xm430-w350, ...". */
const char *sim_model_names(void);
/* The X table of a Protocol 2.0 model; NULL for the AX-12A. */
const struct dxl2_model *sim_model_table(enum sim_model m);

/* Motor parameters of one joint of this model. The AX-12A's are
 * sim_motor_default_params(); an X servo's are the same but for its motor
 * line (stall torque, no-load speed) and its inertia: the same link plus its
 * own rotor through its own gearbox. */
void sim_model_motor_params(enum sim_model m, struct sim_motor_params *p);
/* Torque constant (N·m/A): stall torque / stall current at 12 V. */
double sim_model_torque_constant(enum sim_model m);

#endif
