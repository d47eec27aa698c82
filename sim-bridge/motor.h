/*
 * motor.h — physics of one AX-12A joint: the servo's internal position
 * controller, the DC motor's torque–speed line, the joint's inertia and
 * friction, and a thermal model. Pure: stepped with dt by the caller (>= 1 kHz).
 *
 * Angles here are radians relative to the servo centre (raw 512), positive
 * towards larger raw positions (CCW); speeds rad/s. The models, defaults and
 * where the numbers come from: sim-bridge/PHYSICS.md.
 */
#ifndef UNDULATE_SIM_MOTOR_H
#define UNDULATE_SIM_MOTOR_H

#include <stdbool.h>
#include <stdint.h>

/* Physical parameters of one joint (defaults: sim_motor_default_params()). */
struct sim_motor_params {
	double inertia;            /* kg·m², link + rotor through the gearbox (18.65 cm link) */
	double viscous;            /* N·m·s/rad, what the link adds (gearbox losses are in the motor line) */
	double coulomb;            /* N·m, dry friction the link adds */
	double stall_torque_12v;   /* 1.5 N·m at 12 V */
	double no_load_speed_12v;  /* 59 rpm at 12 V = 6.18 rad/s */
	double supply_voltage;     /* V; torque and speed scale linearly with it */
	/* thermal: dT/dt = heat_gain · (τ / stall_torque_12v)² − (T − ambient_c) / thermal_tau_s */
	double ambient_c;
	double thermal_tau_s;      /* s, cooling time constant */
	double heat_gain;          /* °C/s at full 12 V stall torque */
	/* no drive (torque off, torque limit 0, no supply): back-driving the motor
	 * through the 254:1 gearbox */
	double backdrive_viscous;  /* N·m·s/rad, added to viscous while there is no drive */
	double backdrive_coulomb;  /* N·m, added to coulomb while there is no drive */
	/* Wheel mode's drive. false: the AX-12A's H-bridge, the moving-speed
	 * register is a PWM duty and the motor loses tau_stall/w0 per rad/s to
	 * back-EMF. true: a current-controlled drive (not an AX-12A: the paper's
	 * torque-controlled pair rig), the register commands torque,
	 * duty × stall torque, with no back-EMF loss. Joint mode is unchanged. */
	bool current_drive;
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
	double motor_torque;       /* N·m the motor delivered in the last step (at its start speed) */
	double temperature;        /* °C */
	double ext_torque;         /* N·m applied from outside during the last step (contact) */
	double drive;              /* signed PWM duty the controller commanded, -1..1 */
	unsigned long bad_input;   /* steps refused or repaired: non-finite dt/torque/state */
	double setpoint;           /* position units: the firmware's moving target (moving-speed profile) */
};

/*
 * What a servo's controller asks of the motor over one step: the motor torque
 * as a line in the joint speed w, tau = a - c*w, clamped to +-cap (the driver
 * limits the current; cap 0 = no drive at all: torque off, the joint
 * back-drives the gearbox). duty is the signed share of full output the
 * controller commands (reports only). The AX-12A's compliance controller
 * makes one from its registers inside sim_motor_step(); an X servo's
 * controllers (xdrive.c) make one and call sim_motor_step_drive().
 */
struct sim_motor_drive {
	double a, c, cap;
	double duty;
};

void sim_motor_default_params(struct sim_motor_params *p);
/* The link's own inertia in the defaults (kg·m²): a uniform 18.65 cm rod of
 * 0.12 kg about its end, without any rotor. */
double sim_motor_link_inertia(void);
void sim_motor_init(struct sim_motor *m, const struct sim_motor_params *p, double angle);
/* Advance dt seconds under cmd with an external torque (N·m) acting on the joint. */
void sim_motor_step(struct sim_motor *m, const struct sim_motor_params *p,
                    const struct sim_motor_cmd *cmd, double ext_torque, double dt);
/* The same with the drive given directly (the X servos' controllers). */
void sim_motor_step_drive(struct sim_motor *m, const struct sim_motor_params *p,
                          const struct sim_motor_drive *d, double ext_torque, double dt);
/* The plane world (plane.c) moves the links itself; a joint's motor then
 * gives only its drive and takes back where the joint went:
 * the AX-12A's drive over the next step from its registers (the controller's
 * half of sim_motor_step; an X servo's comes from xdrive.c), */
void sim_motor_drive_for(struct sim_motor *m, const struct sim_motor_params *p, const struct sim_motor_cmd *cmd,
                         double dt, struct sim_motor_drive *d);
/* the rotor's inertia seen through the gearbox: the joint's inertia without
 * the link's own (the plane's links have their own mass), */
double sim_motor_rotor_inertia(const struct sim_motor_params *p);
/* the joint's own losses: the gearbox back-driven while there is no drive
 * (the link's viscous and Coulomb terms are the row world's stand-in for its
 * surroundings, which the plane models as drag), */
void sim_motor_loss(const struct sim_motor_params *p, const struct sim_motor_drive *d, double *viscous,
                    double *coulomb);
/* and after the step: the joint's angle and speed, the torque the motor
 * delivered, its heating. */
void sim_motor_moved(struct sim_motor *m, const struct sim_motor_params *p, const struct sim_motor_drive *d,
                     double angle, double speed, double motor_torque, double dt);
/* Supply-scaled motor line: stall torque (N·m) and no-load speed (rad/s). */
double sim_motor_stall_torque(const struct sim_motor_params *p);
double sim_motor_no_load_speed(const struct sim_motor_params *p);
/* Present load as the servo reports it: signed fraction of max torque in [-1, 1]. */
double sim_motor_load_fraction(const struct sim_motor *m, const struct sim_motor_params *p);
/* Whether the delivered torque has reached the torque limit (the overload bit's cause). */
bool sim_motor_overloaded(const struct sim_motor *m, const struct sim_motor_params *p,
                          const struct sim_motor_cmd *cmd);

#endif
