/*
 * xservo.h — one simulated X-series servo (XL430-W250, XM430-W350) on a
 * Protocol 2.0 bus: its control table (protocol/dxl2_table.c, as data) and
 * the e-manual's semantics for every instruction. Pure: decoded instruction
 * packets in, status packet bytes out, no I/O and no clock (the bus decides
 * when a reply goes out; the physics feeds the present values and the time
 * through sim_xservo_sense). The AX-12A beside it is servo.c.
 *
 * What the manuals say and where the simulator chose is in
 * sim-bridge/README.md, "X-series servos"; in short:
 *  - the status ERR field: the error number of the offending instruction
 *    (result fail, instruction, CRC, data range, data length, data limit,
 *    access) and the alert bit (7) whenever Hardware Error Status is not 0;
 *  - a write is atomic: any byte refused refuses all of it;
 *  - EEPROM (below 64) only with torque off (access error), read-only and
 *    undefined addresses refuse a write (access error), a write covering part
 *    of a register is a data length error, a value outside its row's range a
 *    data range error, outside its limit register (Goal PWM/Current/Velocity,
 *    Goal Position in Position Control Mode) a data limit error;
 *  - a hardware error whose bit is in Shutdown (63) turns the torque off and
 *    stays, with the alert bit in every status packet, until REBOOT;
 *  - the bus watchdog (98): with torque on, no instruction for the set time
 *    stops the servo, the register reads -1 (0xFF) and the goal registers
 *    refuse writes (data range error) until 0 is written;
 *  - the indirect areas (168-251, 578-661): Indirect Data n reads and writes
 *    the byte Indirect Address n holds (64..661, else data range), under
 *    that byte's own rules (access, part of a register, range, limit);
 *    the Indirect Address registers are written only with torque off and
 *    kept over a REBOOT, as EEPROM.
 */
#ifndef UNDULATE_SIM_XSERVO_H
#define UNDULATE_SIM_XSERVO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl2.h"
#include "dxl2_table.h"
#include "model.h"
#include "xdrive.h"

/* Bus Watchdog (98) after it tripped: the manual's "-1". */
#define SIM_XSERVO_WATCHDOG_ERROR 0xFF
/* Moving Status (123): In-Position when the profile is done and the joint is
 * within this many pulses of Goal Position; Following Error when it is more
 * than this many pulses from Position Trajectory (the manual names both
 * thresholds without values: README). */
#define SIM_XSERVO_IN_POSITION_PULSES 20
#define SIM_XSERVO_FOLLOWING_PULSES   256

struct sim_xservo_options {
	/* How long (s) the motor must sit at its torque cap before the overload
	 * error (the manual gives no figure; default 0.5 s, as the AX-12A's). */
	double overload_time_s;
	/* The firmware version it reports (register 6, PING) and acts as: Fast
	 * Sync/Bulk Read from the model's first (X430: 45). 0: the model's
	 * (dxl2_model.firmware, 46). */
	int firmware;
	/* No indirect areas: 168-661 answer the access error, as an X firmware
	 * (or clone) without them would, and as this simulator did before it
	 * had them (the [sim] key indirect = false). */
	bool no_indirect;
};

struct sim_xservo_counters {
	uint32_t instructions;     /* packets addressed to this servo */
	uint32_t replies;          /* status packets produced */
	/* the error numbers of the status ERR field, by instruction refused */
	uint32_t result_fail, instruction_errors, crc_errors, data_range_errors,
	         data_length_errors, data_limit_errors, access_errors;
	uint32_t shutdowns;        /* hardware errors that turned the torque off */
	uint32_t watchdog_trips;
	uint32_t reboots;
};

struct sim_xservo {
	enum sim_model model;
	const struct dxl2_model *table;
	uint8_t mem[DXL2_X_TABLE_SIZE];  /* the control table, as on the wire */
	bool powered;
	uint8_t conditions;        /* hardware errors the servo detects now */
	uint8_t latched;           /* hardware errors that shut it down (until REBOOT) */
	double overload_s;         /* time spent at the torque cap */
	double since_packet_s;     /* time since the last instruction addressed to it */
	double uptime_s;           /* since power-on or reboot: Realtime Tick */
	int32_t turn_offset;       /* pulses: keeps Present Position within a turn (CLEAR, power-on) */
	uint32_t goal_seq;         /* bumped on every goal write (xdrive: a new profile) */
	uint32_t reset_seq;        /* bumped when the loops restart */
	/* REG_WRITE waiting for ACTION (only ever within the table) */
	bool reg_pending;
	uint16_t reg_addr, reg_len;
	uint8_t reg_data[DXL2_X_TABLE_SIZE];
	struct sim_xservo_options opt;
	struct sim_xservo_counters count;
};

void sim_xservo_default_options(struct sim_xservo_options *o);
/* Factory state (ID 1) for an X model, powered on with RAM defaults, the
 * joint at angle (rad from centre). */
void sim_xservo_init(struct sim_xservo *s, enum sim_model m, const struct sim_xservo_options *o, double angle);
uint8_t sim_xservo_id(const struct sim_xservo *s);
/* A register's value by its address (sign-extended); DXL_E_ARG and 0 when no
 * register starts there. */
int sim_xservo_peek(const struct sim_xservo *s, uint16_t addr, int32_t *value);
/* The byte a READ answers at addr (< DXL2_X_TABLE_SIZE): through an
 * indirect slot, the byte its Indirect Address holds. */
uint8_t sim_xservo_byte(const struct sim_xservo *s, uint16_t addr);
/* Set a register without the write rules (set-up, the poke command). Hardware
 * Error Status (70) poked non-zero is a hardware error the servo detected
 * (shutdown if in the mask). DXL_E_ARG for no register at addr. */
int sim_xservo_poke(struct sim_xservo *s, uint16_t addr, int32_t value);

/* Power: off ignores every packet, torque off; on is a boot: RAM defaults,
 * hardware errors and the watchdog cleared, EEPROM kept (REBOOT does the same). */
void sim_xservo_power_off(struct sim_xservo *s);
void sim_xservo_power_on(struct sim_xservo *s, double angle);

/* Whether the packet is for this servo: its ID, broadcast, or a SYNC/BULK
 * instruction that lists it. */
bool sim_xservo_addressed(const struct sim_xservo *s, const struct dxl2_packet *req);
/*
 * Handle one instruction packet seen on the bus. Returns the number of status
 * bytes written into out (0: no reply — broadcast, status return level, not
 * addressed), or DXL_E_BUFFER when cap is too small. The reply is decided
 * (and built) before the instruction acts: a write of the ID is answered
 * under the old ID, REBOOT and FACTORY_RESET answer before they boot the
 * servo. SYNC_READ and BULK_READ are answered as a READ; the bus orders the
 * replies of several servos. FAST_SYNC_READ and FAST_BULK_READ too (the
 * servo's part as an ordinary status packet: the bus builds the one packet
 * of all parts, dxl2_encode_fast_status), when the firmware has them
 * (sim_xservo_fast_read); below that the servo does not answer them.
 */
int sim_xservo_handle(struct sim_xservo *s, const struct dxl2_packet *req, uint8_t *out, size_t cap);
/* Whether this servo answers Fast Sync/Bulk Read: its model's, from its
 * firmware (register 6). */
bool sim_xservo_fast_read(const struct sim_xservo *s);
/* A packet to `id` with instruction `instr` arrived with a bad CRC: the
 * servo answers with the CRC error (3) where it would answer instr. */
int sim_xservo_handle_bad_crc(struct sim_xservo *s, uint8_t id, uint8_t instr, uint8_t *out, size_t cap);
/* The alert bit (0x80) when Hardware Error Status is not 0, else 0. */
uint8_t sim_xservo_alert(const struct sim_xservo *s);

/* The registers the controllers act on. */
void sim_xservo_drive_cmd(const struct sim_xservo *s, struct sim_xdrive_cmd *cmd);

/* What the physics measured over the last dt (physical signs: positive CCW). */
struct sim_xservo_sense {
	double angle;          /* rad from centre */
	double speed;          /* rad/s */
	double torque;         /* N·m the motor delivered */
	double stall_torque;   /* N·m at this supply: 100 % of Present Load */
	double duty;           /* share of full PWM driven, -1..1 */
	double voltage;        /* V */
	double temperature;    /* °C */
	bool overloaded;       /* delivered torque at the driver's cap */
	const struct sim_xdrive *drive;   /* trajectories and profile state; NULL: none */
};
/* Update the present values, Moving, Moving Status, Realtime Tick, the
 * hardware errors and the shutdown, and the bus watchdog. */
void sim_xservo_sense(struct sim_xservo *s, const struct sim_xservo_sense *in, double dt);

#endif
