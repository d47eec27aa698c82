/*
 * motor.h — physics of one AX-12A joint: the servo's internal position
 * controller, the DC motor's torque–speed line, the joint's inertia and
 * friction, and a thermal model. Pure: stepped with dt by the caller (>= 1 kHz).
 *
 * Angles here are radians relative to the servo centre (raw 512), positive
 * towards larger raw positions (CCW); speeds rad/s.
 */
#ifndef UNDULATE_SIM_MOTOR_H
#define UNDULATE_SIM_MOTOR_H

#include <stdbool.h>
#include <stdint.h>

/* Physical parameters of one joint (defaults: sim_motor_default_params()). */
struct sim_motor_params {
	double inertia;            /* kg·m², joint + link about the axis (18.65 cm link) */
	double viscous;            /* N·m·s/rad, joint viscous friction */
	double coulomb;            /* N·m, dry friction */
	double stall_torque_12v;   /* 1.5 N·m at 12 V */
	double no_load_speed_12v;  /* 59 rpm at 12 V = 6.18 rad/s */
	double supply_voltage;     /* V; torque and speed scale linearly with it */
	/* thermal: dT/dt = (heat_per_torque2 · τ² − (T − ambient)/tau) */
	double ambient_c;
	double thermal_tau_s;      /* s, cooling time constant */
	double heat_gain;          /* °C/s per (τ/τ_stall)² at full stall */
};

/* The servo registers the controller acts on (decoded from its RAM/EEPROM). */
struct sim_motor_cmd {
	bool torque_enable;
	uint16_t goal_position;    /* 0..1023 */
	uint16_t moving_speed;     /* 0 = maximum, else × 0.111 rpm (joint mode); wheel mode: bit 10 = CW */
	uint16_t torque_limit;     /* 0..1023 of max torque */
	uint8_t cw_margin, ccw_margin;   /* compliance margin (dead band), position units */
	uint8_t cw_slope, ccw_slope;     /* compliance slope: error (units) over which torque ramps to full */
	uint16_t punch;            /* minimum drive (0..1023 of max torque) outside the dead band */
	uint16_t cw_limit, ccw_limit;    /* angle limits; both 0 = wheel mode */
};

/* State of one joint. */
struct sim_motor {
	double angle;              /* rad, true */
	double speed;              /* rad/s, true */
	double motor_torque;       /* N·m the motor delivered in the last step */
	double temperature;        /* °C */
	double ext_torque;         /* N·m applied from outside during the last step (contact) */
};

void sim_motor_default_params(struct sim_motor_params *p);
void sim_motor_init(struct sim_motor *m, const struct sim_motor_params *p, double angle);
/* Advance dt seconds under cmd with an external torque (N·m) acting on the joint. */
void sim_motor_step(struct sim_motor *m, const struct sim_motor_params *p,
                    const struct sim_motor_cmd *cmd, double ext_torque, double dt);
/* Present load as the servo reports it: signed fraction of max torque in [-1, 1]. */
double sim_motor_load_fraction(const struct sim_motor *m, const struct sim_motor_params *p);
/* Whether the delivered torque has reached the torque limit (the overload bit's cause). */
bool sim_motor_overloaded(const struct sim_motor *m, const struct sim_motor_params *p,
                          const struct sim_motor_cmd *cmd);

#endif
