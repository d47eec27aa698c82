/*
 * servo.h — one simulated AX-12(A): its control table and the manual's
 * semantics for every instruction. Pure: instruction packets in, status
 * packet bytes out, no I/O and no clock (the bus decides *when* a reply goes
 * out; the physics feeds the present-value registers through sim_servo_sense).
 *
 * Choices where the manuals are silent or disagree (documented in
 * sim-bridge/README.md):
 *  - a WRITE/REG_WRITE is atomic: if any byte is out of the table, hits a
 *    read-only/reserved byte, a locked or (optionally) torque-on EEPROM byte,
 *    or a value out of range, nothing is written and the reply carries the
 *    range error bit;
 *  - a goal position outside [CW, CCW angle limit] in joint mode is not
 *    written and the reply carries the angle-limit error bit;
 *  - the range/angle-limit/checksum/instruction bits belong to the reply of
 *    the offending instruction; voltage, overheating and overload are
 *    conditions reported in every status packet while they last;
 *  - an alarm shutdown (any error whose bit is set in Alarm Shutdown, the
 *    one-packet errors included) clears Torque Enable as well as the
 *    Torque Limit the manual names;
 *  - a READ past address 49 and an EEPROM write with torque on get the
 *    range bit; a baud change is answered at the old rate (simbus.c).
 */
#ifndef UNDULATE_SIM_SERVO_H
#define UNDULATE_SIM_SERVO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl.h"
#include "dxl_table.h"
#include "motor.h"

/* Firmware version reported at address 2 (the AX-12A ships with 24 or later). */
#define SIM_SERVO_FIRMWARE 24

struct sim_servo_options {
	/* The AX-12A e-manual: the EEPROM area is writable only with torque off.
	 * The original AX-12 manual has no such rule. Default true. */
	bool eeprom_needs_torque_off;
	/* How long (s) the load must sit at the torque limit before the overload
	 * bit rises (the manual gives no figure; default 0.5 s). */
	double overload_time_s;
};

struct sim_servo_counters {
	uint32_t instructions;     /* packets addressed to this servo (incl. broadcast) */
	uint32_t replies;          /* status packets produced */
	uint32_t range_errors;
	uint32_t angle_limit_errors;
	uint32_t instruction_errors;
	uint32_t checksum_errors;
	uint32_t shutdowns;        /* alarm shutdowns (torque cut by the shutdown mask) */
};

struct sim_servo {
	uint8_t mem[DXL_AX_TABLE_SIZE];  /* the control table, as on the wire */
	bool powered;
	uint8_t conditions;        /* voltage/overheat/overload bits while they last */
	bool alarm_led;            /* an alarm-LED-mask condition is active */
	double overload_s;         /* time spent at the torque limit */
	/* REG_WRITE waiting for ACTION */
	bool reg_pending;
	uint8_t reg_addr, reg_len;
	uint8_t reg_data[DXL_MAX_PARAMS];
	struct sim_servo_options opt;
	struct sim_servo_counters count;
};

void sim_servo_default_options(struct sim_servo_options *o);
/* Factory state (EEPROM defaults, ID 1) and powered on with RAM defaults.
 * The goal position starts at present_position. */
void sim_servo_init(struct sim_servo *s, const struct sim_servo_options *o, uint16_t present_position);
/* Set a register without the write rules (scenario set-up, e.g. ID, baud,
 * return delay). Returns DXL_OK or DXL_E_ARG for an unknown register. */
int sim_servo_poke(struct sim_servo *s, uint8_t addr, uint16_t value);
uint16_t sim_servo_peek(const struct sim_servo *s, uint8_t addr);  /* 1 or 2 bytes per register */
uint8_t sim_servo_id(const struct sim_servo *s);

/* Power: off ignores every packet (torque off); on resets RAM to its
 * defaults (torque off, torque limit = max torque, goal = present, lock 0). */
void sim_servo_power_off(struct sim_servo *s);
void sim_servo_power_on(struct sim_servo *s);

/*
 * Handle one instruction packet seen on the bus. Returns the number of status
 * bytes written into out (0: no reply, e.g. broadcast, status return level,
 * not addressed), or DXL_E_BUFFER when cap is too small.
 * reply_id is the ID to answer with (the servo's, before any ID change).
 */
int sim_servo_handle(struct sim_servo *s, const struct dxl_packet *req, uint8_t *out, size_t cap);
/* Whether the packet is addressed to this servo (its ID, broadcast, or a
 * SYNC_WRITE naming it). */
bool sim_servo_addressed(const struct sim_servo *s, const struct dxl_packet *req);
/* A packet to `id` arrived with a bad checksum: the servo answers with the
 * checksum bit (if addressed, unicast, and the level allows `instr`). */
int sim_servo_handle_bad_checksum(struct sim_servo *s, uint8_t id, uint8_t instr, uint8_t *out, size_t cap);

/* The registers the motor model acts on. */
void sim_servo_motor_cmd(const struct sim_servo *s, struct sim_motor_cmd *cmd);

/* What the physics measured over the last dt. */
struct sim_servo_sense {
	double angle;          /* rad from centre */
	double speed;          /* rad/s */
	double load_fraction;  /* signed, of max torque */
	double output;         /* signed share of full output the servo drives (its PWM duty), -1..1,
	                          positive CCW: wheel mode's present speed */
	double voltage;        /* V */
	double temperature;    /* °C */
	bool overloaded;       /* delivered torque at the torque limit */
};
/* Update present position/speed/load/voltage/temperature/moving, the error
 * conditions and the alarm shutdown. Present speed is in->speed in joint mode
 * and in->output in wheel mode, as on the AX-12A (e-manual, Present Speed). */
void sim_servo_sense(struct sim_servo *s, const struct sim_servo_sense *in, double dt);
/* Error conditions a status packet carries now (voltage, overheating,
 * overload). Injected stuck-error bits are added on the way out (fault.c). */
uint8_t sim_servo_condition_bits(const struct sim_servo *s);

#endif
