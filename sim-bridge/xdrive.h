/*
 * xdrive.h — the controllers inside a simulated X-series servo (XL430-W250,
 * XM430-W350): the profile generator, the position PID and velocity PI
 * loops, the PWM and current drives, as the e-manual's block diagrams draw
 * them (Operating Mode, Position PID Gain, Velocity PI Gain, Goal PWM, Goal
 * Current, Profile Velocity/Acceleration). Each step turns the servo's
 * registers (struct sim_xdrive_cmd, decoded by xservo.c) and the joint's
 * state into the motor's drive line for motor.c. Pure: stepped with dt.
 *
 * Units inside: positions in pulses (4096 a turn) in the servo's own
 * coordinates (Drive Mode's direction and the offsets applied: what Present
 * Position reads), speeds in pulses/s, output as a share of full PWM. Where
 * the manual gives no unit for a gain's input, the choice is in PHYSICS.md §5.
 */
#ifndef UNDULATE_SIM_XDRIVE_H
#define UNDULATE_SIM_XDRIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "motor.h"

/* Pulses a second of one Profile Velocity / Goal Velocity unit (0.229 rpm),
 * and of one Profile Acceleration unit (214.577 rev/min²) per second. */
#define SIM_XDRIVE_PULSES_PER_VEL_UNIT (0.229 * 4096.0 / 60.0)
#define SIM_XDRIVE_PULSES_PER_ACC_UNIT (214.577 * 4096.0 / 3600.0)
/* Full scale of Goal PWM / Present PWM (e-manual: 885 = 100 %). */
#define SIM_XDRIVE_PWM_FULL 885.0
/* One Goal/Present Current unit, A (XM430). */
#define SIM_XDRIVE_AMPS_PER_UNIT 0.00269

/* Moving Status (123) profile bits 4-5 (e-manual). */
enum sim_xdrive_profile {
	SIM_XDRIVE_PROFILE_STEP = 0,
	SIM_XDRIVE_PROFILE_RECTANGULAR = 1,
	SIM_XDRIVE_PROFILE_TRIANGULAR = 2,
	SIM_XDRIVE_PROFILE_TRAPEZOIDAL = 3,
};

/* What the registers ask (xservo.c fills it). */
struct sim_xdrive_cmd {
	bool torque_enable;
	uint8_t mode;                  /* Operating Mode (11) */
	int dir;                       /* +1, or -1 with Drive Mode bit 0 (reverse) */
	double offset;                 /* pulses: present = offset + dir * angle / pulse */
	bool time_profile;             /* Drive Mode bit 2: profiles given in ms */
	bool step_profile;             /* profiles apply as 0 (a bus watchdog stop) */
	int32_t goal_position;         /* pulses, servo coordinates */
	int32_t min_position, max_position;   /* position limits (Position Control Mode only) */
	int32_t goal_velocity;         /* 0.229 rpm units */
	int32_t goal_pwm;              /* 885 = 100 %; also the PWM limit in every mode */
	int32_t goal_current;          /* 2.69 mA units (current modes) */
	int32_t current_limit;         /* 2.69 mA units; < 0: no current register (XL430) */
	uint32_t profile_acceleration, profile_velocity;
	uint16_t pos_p, pos_i, pos_d, ff1, ff2;   /* Position PID Gain, Feedforward (raw table values) */
	uint16_t vel_p, vel_i;         /* Velocity PI Gain (raw) */
	double torque_constant;        /* N·m/A */
	uint32_t goal_seq;             /* bumped on every write of a goal: a new profile */
	uint32_t reset_seq;            /* bumped when the loops restart (mode, torque, reboot) */
};

/* The controllers' state (the firmware's memory). */
struct sim_xdrive {
	bool active;                   /* torque on at the last step */
	uint32_t goal_seq, reset_seq;  /* the last ones acted on */
	double traj_pos;               /* pulses: Position Trajectory (140) */
	double traj_vel;               /* pulses/s: Velocity Trajectory (136) */
	double traj_acc;               /* pulses/s²: the profile's acceleration now */
	double target;                 /* pulses: where the running profile ends */
	double prof_v, prof_a;         /* the running profile's limits; 0 = none */
	enum sim_xdrive_profile profile;
	bool profile_ongoing;
	double pos_integral;           /* pulse·ms */
	double vel_integral;           /* pulse/s·ms */
	double duty;                   /* share of full PWM commanded, servo coordinates */
	double torque_cmd;             /* N·m asked of a current loop (current modes) */
};

void sim_xdrive_init(struct sim_xdrive *d);
/* One step: the drive line for sim_motor_step_drive() (physical sign). */
void sim_xdrive_step(struct sim_xdrive *d, const struct sim_xdrive_cmd *c, const struct sim_motor *m,
                     const struct sim_motor_params *p, double dt, struct sim_motor_drive *out);
/* The driver's torque cap (N·m) at a supply whose stall torque is `stall`:
 * the stall torque, and on the XM430 Current Limit(38) in every mode. */
double sim_xdrive_cap(const struct sim_xdrive_cmd *c, double stall);
/* Present Position as the servo reads it (whole pulses). */
double sim_xdrive_present(const struct sim_xdrive_cmd *c, double angle);

#endif
