/*
 * control_priv.h — the controller's internals shared by its files:
 * control.c (modes, faults, read-back, the position laws), torque.c
 * (torque actuation through wheel mode) and control_core.c (what both call:
 * events, writes, a joint's model and limits). The calls go one way:
 * control.c -> torque.c -> control_core.c; torque.c reports a fault to
 * latch, control.c latches it. Nothing outside the controller includes this.
 */
#ifndef UNDULATE_DAEMON_CONTROL_PRIV_H
#define UNDULATE_DAEMON_CONTROL_PRIV_H

#include "control.h"

/* ---- control_core.c ------------------------------------------------------------------- */
void ctl_event(struct ctl *c, int level, const char *kind, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* A register's new value (writeq.h's merge rules). */
void ctl_write(struct ctl *c, uint8_t id, uint16_t addr, uint8_t len, uint32_t value);
/* Appended as it is, in order: a sequence that writes one register twice
 * (torque off, EEPROM write, torque on) must not be merged. */
void ctl_write_seq(struct ctl *c, uint8_t id, uint16_t addr, uint8_t len, uint32_t value);
/* A step of a chain (writeq.h): the chain stops at a step given up. len 0:
 * a REBOOT. */
void ctl_write_chain(struct ctl *c, uint16_t chain, uint8_t id, uint16_t addr, uint8_t len, uint32_t value);
/* X series: the writes that make servo j what the controller expects, as one
 * chain (returned): with_mode — torque off and Operating Mode 3 first (the
 * EEPROM takes it only with torque off) — then Goal Position where the joint
 * is (inside its limits), Goal PWM at its limit, the Bus Watchdog (0 first
 * when it had stopped the servo), and torque on when it is wanted. */
uint16_t ctl_x_setup(struct ctl *c, size_t j, bool with_mode);
/* The joint's servo is an X series one. */
/* Joint j's servo has cap (enum sm_cap): what differs between servo
 * families is asked this way, never by protocol or name. */
bool ctl_has(const struct ctl *c, size_t j, unsigned cap);
/* The torque limit a joint should have: the servo's max torque, reduced to
 * backoff_torque while it backs off from a fault or holds after one that
 * persisted. */
uint16_t ctl_torque_limit(const struct ctl *c, const struct ctl_joint *jt);
void ctl_blend_joint(struct ctl *c, size_t j, double from);
/* A goal's register value for rad on model m, never past the joint's limits. */
int32_t ctl_goal_pos(const struct ctl_joint *jt, const struct sm_model *m, double rad);

/* ---- control.c: torque.c never calls these -------------------------------------------- */
void ctl_hold_at_present(struct ctl *c);
/* Put the robot in its fault action and keep it there until cleared. */
void ctl_latch(struct ctl *c, const char *what);
/* ctl_latch with its text formatted (cut at CTL_LATCH_TEXT bytes). */
void ctl_latchf(struct ctl *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* ---- torque.c ------------------------------------------------------------------------- */
/* Under torque actuation `mode` drives the servos' torque: OSCILLATOR, and
 * SINUSOID with a [sinusoid] stiffness (the clock as a torque law). */
bool tq_mode_drives(const struct ctl *c, enum cfg_mode mode);
/* The servos go into wheel mode only for such a mode running (not the
 * oscillator's starter) whose joints are all healthy, torqued and measured. */
bool tq_want_wheel(const struct ctl *c);
/* A joint past its limits under torque: true with what to latch (the
 * caller puts the robot in its fault action, ctl_latch), the event said. */
bool tq_check_limits(struct ctl *c, char *what, size_t cap);
/* The PWM drive scales with the supply each servo reports: in a mode that
 * drives torque (tq_mode_drives) a reading outside the servo's plausible
 * range (sm_supply_plausible) is a fault, named, never a gain: true with
 * what to latch. */
bool tq_check_supply(struct ctl *c, char *what, size_t cap);
/* This cycle's duties from the mode's law (wheel mode); t_real is the
 * SINUSOID's shared clock (ctl_step). */
void tq_duties(struct ctl *c, double dt, double t_real);
/* Wheel-mode switches, queued after this cycle's SYNC_WRITE. */
void tq_enter_wheel(struct ctl *c);
void tq_leave_wheel(struct ctl *c);
/* Leaving wheel mode, the SYNC_WRITE stops every drive and leaves a goal the
 * joint mode can hold. */
void tq_stop_goals(struct ctl *c);
/* The stall torque (N·m at the model's reference supply) and no-load speed
 * torque actuation works with: the configuration's when given, else the
 * joint's model's datasheet line. */
double tq_stall_torque(const struct ctl *c, const struct ctl_joint *jt);
double tq_no_load_speed(const struct ctl *c, const struct ctl_joint *jt);
/* X series: a step of a drive switch's chain was acknowledged (ok) or given
 * up; the joint's drive is ready, or (the caller's part) the robot goes
 * back to joint mode. True with what to latch when the switch failed more
 * than fault_retries times. */
bool tq_chain_result(struct ctl *c, size_t j, const struct wq_write *w, bool ok, char *what, size_t cap);

#endif
