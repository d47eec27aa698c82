/*
 * dxl2_table.c — the AX-12A, XL430-W250, XM430-W350 and XC430-W150 control
 * tables and datasheets as data, lookup, write checks, conversions and
 * formatting. The AX-12A's rows are dxl_ax12_rows.h's; the X series' are the
 * ROBOTIS e-manual's (ROBOTIS-GIT/emanual: docs/en/dxl/x/xl430-w250.md and
 * xm430-w350.md, the revisions with Range and Unit columns). Where the
 * printed range cannot be meant literally the row says what was taken.
 */
#include "dxl2_table.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dxl.h"
#include "dxl2.h"
#include "dxl_ax12_rows.h"

#define R   DXL_ACCESS_R
#define RW  DXL_ACCESS_RW
#define EE  DXL_AREA_EEPROM
#define RAM DXL_AREA_RAM
#define U(x) DXL2_UNIT_##x
/* Rows: name, addr, size, signed, access, area, min, max, has_default, def,
 * unit, limit, limit register, description. */
#define NOLIM DXL2_LIMIT_NONE, 0
#define SYM(addr) DXL2_LIMIT_SYMMETRIC, addr
/* Extended Position Control Mode's range (Goal Position, e-manual). */
#define EXT_POS 1048575
/* Read-only rows: the "range" is the type's, for formatting only. */
#define RO_U8   0, 255
#define RO_U16  0, 65535
#define RO_S16  -32768, 32767
#define RO_S32  INT32_MIN, INT32_MAX

/* The first rows, the same on both models but for the model number. */
#define X_COMMON_HEAD(model) \
	{ "model_number",       0, 2, false, R,  EE, RO_U16, true, model, U(RAW), NOLIM, "model number" }, \
	{ "model_information",  2, 4, false, R,  EE, 0, INT32_MAX, false, 0, U(RAW), NOLIM, "model information" }, \
	{ "firmware_version",   6, 1, false, R,  EE, RO_U8, false, 0, U(RAW), NOLIM, "firmware version" }, \
	{ "id",                 7, 1, false, RW, EE, 0, DXL2_MAX_ID, true, 1, U(RAW), NOLIM, \
	    "servo ID, 0-252 (254 is broadcast)" }, \
	{ "baud_rate",          8, 1, false, RW, EE, 0, 7, true, 1, U(BAUD), NOLIM, \
	    "0 9600, 1 57600, 2 115200, 3 1M, 4 2M, 5 3M, 6 4M, 7 4.5M bps" }, \
	{ "return_delay_time",  9, 1, false, RW, EE, 0, 254, true, 250, U(RETURN_DELAY), NOLIM, \
	    "delay before a status packet, 2 us a unit (0 for speed)" }

/* The rows of an X servo without current sensing (XL430-W250, XC430-W150):
 * one layout; what differs between the models' pages is the factory values
 * (Moving Threshold, Temperature Limit, Velocity Limit, the gains) and the
 * highest supply its voltage limits take. */
#define X_PWM_ROWS(model, mov_thr, temp_lim, volt_max, vel_lim, vel_i, pos_d, pos_p) \
	X_COMMON_HEAD(model), \
	{ "drive_mode",        10, 1, false, RW, EE, 0, 13, true, 0, U(RAW), NOLIM, \
	    "bit 0 reverse direction, bit 2 time-based profile, bit 3 torque on by goal update" }, \
	{ "operating_mode",    11, 1, false, RW, EE, 0, 16, true, 3, U(OPMODE), NOLIM, \
	    "1 velocity, 3 position, 4 extended position, 16 PWM" }, \
	/* printed 0-252 with default 255: 253 and above switch it off */ \
	{ "secondary_id",      12, 1, false, RW, EE, 0, 255, true, 255, U(RAW), NOLIM, \
	    "shadow ID, 253-255 = none" }, \
	{ "protocol_type",     13, 1, false, RW, EE, 1, 2, true, 2, U(RAW), NOLIM, "1 or 2" }, \
	{ "homing_offset",     20, 4, true,  RW, EE, -1044479, 1044479, true, 0, U(POSITION), NOLIM, \
	    "added to the present position, pulses" }, \
	{ "moving_threshold",  24, 4, false, RW, EE, 0, 1023, true, mov_thr, U(VELOCITY), NOLIM, \
	    "speed above which the servo counts as moving" }, \
	{ "temperature_limit", 31, 1, false, RW, EE, 0, 100, true, temp_lim, U(TEMPERATURE), NOLIM, \
	    "overheating threshold" }, \
	{ "max_voltage_limit", 32, 2, false, RW, EE, 60, volt_max, true, volt_max, U(VOLTAGE), NOLIM, \
	    "highest input voltage before the voltage error" }, \
	{ "min_voltage_limit", 34, 2, false, RW, EE, 60, volt_max, true, 60, U(VOLTAGE), NOLIM, \
	    "lowest input voltage before the voltage error" }, \
	{ "pwm_limit",         36, 2, false, RW, EE, 0, 885, true, 885, U(PWM), NOLIM, \
	    "largest PWM, the limit of goal_pwm" }, \
	{ "velocity_limit",    44, 4, false, RW, EE, 0, 1023, true, vel_lim, U(VELOCITY), NOLIM, \
	    "largest speed, the limit of goal_velocity" }, \
	{ "max_position_limit", 48, 4, false, RW, EE, 0, 4095, true, 4095, U(POSITION), NOLIM, \
	    "largest goal position in position mode" }, \
	{ "min_position_limit", 52, 4, false, RW, EE, 0, 4095, true, 0, U(POSITION), NOLIM, \
	    "smallest goal position in position mode" }, \
	/* printed range "3": bits 0 and 1 */ \
	{ "startup_configuration", 60, 1, false, RW, EE, 0, 3, true, 0, U(RAW), NOLIM, \
	    "bit 0 torque on at boot, bit 1 restore RAM from backup" }, \
	/* printed range "-": the hardware error bits */ \
	{ "shutdown",          63, 1, false, RW, EE, 0, DXL2_HWERR_MASK, true, 52, U(HWERR), NOLIM, \
	    "hardware errors that switch the torque off" }, \
	{ "torque_enable",     64, 1, false, RW, RAM, 0, 1, true, 0, U(BOOL), NOLIM, \
	    "motor torque on (locks the EEPROM area)" }, \
	{ "led",               65, 1, false, RW, RAM, 0, 1, true, 0, U(BOOL), NOLIM, "LED on" }, \
	{ "status_return_level", 68, 1, false, RW, RAM, 0, 2, true, 2, U(STATUS_LEVEL), NOLIM, \
	    "which instructions are answered: 0 ping, 1 + read, 2 all" }, \
	{ "registered_instruction", 69, 1, false, R, RAM, RO_U8, true, 0, U(BOOL), NOLIM, \
	    "a REG_WRITE is waiting for ACTION" }, \
	{ "hardware_error_status", 70, 1, false, R, RAM, RO_U8, true, 0, U(HWERR), NOLIM, \
	    "hardware errors now (the status packet's alert bit)" }, \
	{ "velocity_i_gain",   76, 2, false, RW, RAM, 0, 16383, true, vel_i, U(RAW), NOLIM, "velocity I gain" }, \
	{ "velocity_p_gain",   78, 2, false, RW, RAM, 0, 16383, true, 100, U(RAW), NOLIM, "velocity P gain" }, \
	{ "position_d_gain",   80, 2, false, RW, RAM, 0, 16383, true, pos_d, U(RAW), NOLIM, "position D gain" }, \
	{ "position_i_gain",   82, 2, false, RW, RAM, 0, 16383, true, 0, U(RAW), NOLIM, "position I gain" }, \
	{ "position_p_gain",   84, 2, false, RW, RAM, 0, 16383, true, pos_p, U(RAW), NOLIM, "position P gain" }, \
	{ "feedforward_2nd_gain", 88, 2, false, RW, RAM, 0, 16383, true, 0, U(RAW), NOLIM, \
	    "feedforward acceleration gain" }, \
	{ "feedforward_1st_gain", 90, 2, false, RW, RAM, 0, 16383, true, 0, U(RAW), NOLIM, \
	    "feedforward velocity gain" }, \
	/* printed 1-127 with default 0: 0 switches the watchdog off */ \
	{ "bus_watchdog",      98, 1, false, RW, RAM, 0, 127, true, 0, U(WATCHDOG), NOLIM, \
	    "stop when no packet came for this long, 20 ms a unit, 0 = off" }, \
	{ "goal_pwm",         100, 2, true,  RW, RAM, -885, 885, false, 0, U(PWM), SYM(36), \
	    "target PWM (PWM mode), within +-pwm_limit" }, \
	{ "goal_velocity",    104, 4, true,  RW, RAM, -1023, 1023, false, 0, U(VELOCITY), SYM(44), \
	    "target speed (velocity mode), within +-velocity_limit" }, \
	/* printed "0-32767 / 0-32737" (velocity / time-based profile): the wider */ \
	{ "profile_acceleration", 108, 4, false, RW, RAM, 0, 32767, true, 0, U(ACCELERATION), NOLIM, \
	    "profile acceleration, 0 = none" }, \
	{ "profile_velocity", 112, 4, false, RW, RAM, 0, 32767, true, 0, U(VELOCITY), NOLIM, \
	    "profile speed, 0 = none" }, \
	{ "goal_position",    116, 4, true,  RW, RAM, -EXT_POS, EXT_POS, false, 0, U(POSITION), \
	    DXL2_LIMIT_POSITION, 0, "target position, within the position limits in position mode" }, \
	{ "realtime_tick",    120, 2, false, R,  RAM, RO_U16, false, 0, U(MS), NOLIM, \
	    "servo clock, 0-32767 ms, wraps" }, \
	{ "moving",           122, 1, false, R,  RAM, RO_U8, true, 0, U(BOOL), NOLIM, "moving now" }, \
	{ "moving_status",    123, 1, false, R,  RAM, RO_U8, true, 0, U(RAW), NOLIM, "profile and arrival bits" }, \
	{ "present_pwm",      124, 2, true,  R,  RAM, RO_S16, false, 0, U(PWM), NOLIM, "PWM now" }, \
	{ "present_load",     126, 2, true,  R,  RAM, RO_S16, false, 0, U(LOAD), NOLIM, \
	    "load, 0.1 % of the maximum, -1000..1000" }, \
	{ "present_velocity", 128, 4, true,  R,  RAM, RO_S32, false, 0, U(VELOCITY), NOLIM, "speed now" }, \
	{ "present_position", 132, 4, true,  R,  RAM, RO_S32, false, 0, U(POSITION), NOLIM, "position now" }, \
	{ "velocity_trajectory", 136, 4, true, R, RAM, RO_S32, false, 0, U(VELOCITY), NOLIM, \
	    "speed the profile asks for now" }, \
	{ "position_trajectory", 140, 4, true, R, RAM, RO_S32, false, 0, U(POSITION), NOLIM, \
	    "position the profile asks for now" }, \
	{ "present_input_voltage", 144, 2, false, R, RAM, RO_U16, false, 0, U(VOLTAGE), NOLIM, "supply voltage" }, \
	{ "present_temperature", 146, 1, false, R, RAM, RO_U8, false, 0, U(TEMPERATURE), NOLIM, \
	    "internal temperature" }, \
	{ "backup_ready",     147, 1, false, R,  RAM, RO_U8, false, 0, U(BOOL), NOLIM, \
	    "a RAM backup is stored" }, \
	X_IND_ROWS

/* The indirect areas (e-manual, "Indirect Address, Indirect Data", the
 * XL430-W250/XM430-W350 pages: rows 168-251 and 578-661): Indirect Address n
 * (2 bytes) holds the address of the byte Indirect Data n (1 byte) stands
 * for; the factory value is Indirect Data n's own address. The page prints
 * the range of an Indirect Address as 64 ~ 661 ("EEPROM address can't be
 * assigned to Indirect Address") and lists both in its RAM table; ROBOTIS's
 * DynamixelSDK indirect example turns the torque off first because
 * "Indirect address would not accessible when the torque is already
 * enabled": the address rows are kept here as EEPROM (written with torque
 * off, kept over a reboot, sim-bridge/README.md says the choice). */
#define X_IND_ADDR(n, addr, def) \
	{ "indirect_address_" #n, addr, 2, false, RW, EE, DXL2_X_INDIRECT_MIN, DXL2_X_INDIRECT_MAX, true, def, \
	  U(RAW), NOLIM, "address of the byte indirect_data_" #n " stands for (64-661)" }
#define X_IND_DATA(n, addr) \
	{ "indirect_data_" #n, addr, 1, false, RW, RAM, 0, 255, true, 0, U(RAW), NOLIM, \
	  "the byte at indirect_address_" #n }
#define X_IND_ADDR_1 \
	X_IND_ADDR(1, 168, 224), X_IND_ADDR(2, 170, 225), X_IND_ADDR(3, 172, 226), X_IND_ADDR(4, 174, 227), \
	X_IND_ADDR(5, 176, 228), X_IND_ADDR(6, 178, 229), X_IND_ADDR(7, 180, 230), X_IND_ADDR(8, 182, 231), \
	X_IND_ADDR(9, 184, 232), X_IND_ADDR(10, 186, 233), X_IND_ADDR(11, 188, 234), X_IND_ADDR(12, 190, 235), \
	X_IND_ADDR(13, 192, 236), X_IND_ADDR(14, 194, 237), X_IND_ADDR(15, 196, 238), X_IND_ADDR(16, 198, 239), \
	X_IND_ADDR(17, 200, 240), X_IND_ADDR(18, 202, 241), X_IND_ADDR(19, 204, 242), X_IND_ADDR(20, 206, 243), \
	X_IND_ADDR(21, 208, 244), X_IND_ADDR(22, 210, 245), X_IND_ADDR(23, 212, 246), X_IND_ADDR(24, 214, 247), \
	X_IND_ADDR(25, 216, 248), X_IND_ADDR(26, 218, 249), X_IND_ADDR(27, 220, 250), X_IND_ADDR(28, 222, 251)
#define X_IND_DATA_1 \
	X_IND_DATA(1, 224), X_IND_DATA(2, 225), X_IND_DATA(3, 226), X_IND_DATA(4, 227), \
	X_IND_DATA(5, 228), X_IND_DATA(6, 229), X_IND_DATA(7, 230), X_IND_DATA(8, 231), \
	X_IND_DATA(9, 232), X_IND_DATA(10, 233), X_IND_DATA(11, 234), X_IND_DATA(12, 235), \
	X_IND_DATA(13, 236), X_IND_DATA(14, 237), X_IND_DATA(15, 238), X_IND_DATA(16, 239), \
	X_IND_DATA(17, 240), X_IND_DATA(18, 241), X_IND_DATA(19, 242), X_IND_DATA(20, 243), \
	X_IND_DATA(21, 244), X_IND_DATA(22, 245), X_IND_DATA(23, 246), X_IND_DATA(24, 247), \
	X_IND_DATA(25, 248), X_IND_DATA(26, 249), X_IND_DATA(27, 250), X_IND_DATA(28, 251)
#define X_IND_ADDR_29 \
	X_IND_ADDR(29, 578, 634), X_IND_ADDR(30, 580, 635), X_IND_ADDR(31, 582, 636), X_IND_ADDR(32, 584, 637), \
	X_IND_ADDR(33, 586, 638), X_IND_ADDR(34, 588, 639), X_IND_ADDR(35, 590, 640), X_IND_ADDR(36, 592, 641), \
	X_IND_ADDR(37, 594, 642), X_IND_ADDR(38, 596, 643), X_IND_ADDR(39, 598, 644), X_IND_ADDR(40, 600, 645), \
	X_IND_ADDR(41, 602, 646), X_IND_ADDR(42, 604, 647), X_IND_ADDR(43, 606, 648), X_IND_ADDR(44, 608, 649), \
	X_IND_ADDR(45, 610, 650), X_IND_ADDR(46, 612, 651), X_IND_ADDR(47, 614, 652), X_IND_ADDR(48, 616, 653), \
	X_IND_ADDR(49, 618, 654), X_IND_ADDR(50, 620, 655), X_IND_ADDR(51, 622, 656), X_IND_ADDR(52, 624, 657), \
	X_IND_ADDR(53, 626, 658), X_IND_ADDR(54, 628, 659), X_IND_ADDR(55, 630, 660), X_IND_ADDR(56, 632, 661)
#define X_IND_DATA_29 \
	X_IND_DATA(29, 634), X_IND_DATA(30, 635), X_IND_DATA(31, 636), X_IND_DATA(32, 637), \
	X_IND_DATA(33, 638), X_IND_DATA(34, 639), X_IND_DATA(35, 640), X_IND_DATA(36, 641), \
	X_IND_DATA(37, 642), X_IND_DATA(38, 643), X_IND_DATA(39, 644), X_IND_DATA(40, 645), \
	X_IND_DATA(41, 646), X_IND_DATA(42, 647), X_IND_DATA(43, 648), X_IND_DATA(44, 649), \
	X_IND_DATA(45, 650), X_IND_DATA(46, 651), X_IND_DATA(47, 652), X_IND_DATA(48, 653), \
	X_IND_DATA(49, 654), X_IND_DATA(50, 655), X_IND_DATA(51, 656), X_IND_DATA(52, 657), \
	X_IND_DATA(53, 658), X_IND_DATA(54, 659), X_IND_DATA(55, 660), X_IND_DATA(56, 661)
#define X_IND_ROWS X_IND_ADDR_1, X_IND_DATA_1, X_IND_ADDR_29, X_IND_DATA_29

/* The AX-12A's rows: dxl_ax12_rows.h's, in the units of Protocol 1.0's
 * servo; Moving Speed narrower in joint mode. */
#define NODEF (-1)
#define AXU_RAW          U(RAW)
#define AXU_POSITION     U(AX_POSITION)
#define AXU_SPEED        U(AX_SPEED)
#define AXU_MOVING_SPEED U(AX_MOVING_SPEED)
#define AXU_LOAD         U(AX_LOAD)
#define AXU_TORQUE       U(AX_TORQUE)
#define AXU_VOLTAGE      U(VOLTAGE)
#define AXU_TEMPERATURE  U(TEMPERATURE)
#define AXU_BAUD         U(AX_BAUD)
#define AXU_RETURN_DELAY U(RETURN_DELAY)
#define AXU_BOOL         U(BOOL)
#define AXU_ERRMASK      U(AX_ERRMASK)
#define AXU_STATUS_LEVEL U(STATUS_LEVEL)
#define AX_ROW(name, addr, size, access, area, min, max, def, unit, desc) \
	{ name, addr, size, false, access, area, min, max, (def) >= 0, (def) >= 0 ? (def) : 0, AXU_##unit, \
	  (addr) == DXL_AX_MOVING_SPEED ? DXL2_LIMIT_JOINT_MODE : DXL2_LIMIT_NONE, 0, desc },
static const struct dxl2_reg ax12a_regs[] = {
	DXL_AX12_ROWS(AX_ROW)
};

static const struct dxl2_reg xl430_regs[] = {
	/*                               threshold  temp  volts  velocity  vel I  pos D  pos P */
	X_PWM_ROWS(DXL2_MODEL_XL430_W250, 10,       72,   140,   265,      1000,  4000,  640),
};

/* The XC430-W150's page (docs/en/dxl/x/xc430-w150.md): the XL430's layout
 * with its own factory values and a supply up to 16.0 V. */
static const struct dxl2_reg xc430_regs[] = {
	X_PWM_ROWS(DXL2_MODEL_XC430_W150, 20,       80,   160,   460,      1920,  0,     460),
};

static const struct dxl2_reg xm430_regs[] = {
	X_COMMON_HEAD(DXL2_MODEL_XM430_W350),
	{ "drive_mode",        10, 1, false, RW, EE, 0, 1, true, 0, U(RAW), NOLIM,
	    "bit 0 reverse direction" },
	{ "operating_mode",    11, 1, false, RW, EE, 0, 16, true, 3, U(OPMODE), NOLIM,
	    "0 current, 1 velocity, 3 position, 4 extended position, 5 current-based position, 16 PWM" },
	{ "secondary_id",      12, 1, false, RW, EE, 0, 255, true, 255, U(RAW), NOLIM,
	    "shadow ID, 253-255 = none" },
	{ "protocol_type",     13, 1, false, RW, EE, 1, 2, true, 2, U(RAW), NOLIM, "1 or 2" },
	{ "homing_offset",     20, 4, true,  RW, EE, -1044479, 1044479, true, 0, U(POSITION), NOLIM,
	    "added to the present position, pulses" },
	{ "moving_threshold",  24, 4, false, RW, EE, 0, 1023, true, 10, U(VELOCITY), NOLIM,
	    "speed above which the servo counts as moving" },
	{ "temperature_limit", 31, 1, false, RW, EE, 0, 100, true, 80, U(TEMPERATURE), NOLIM,
	    "overheating threshold" },
	/* the XM430-W350 page prints 110-300 beside a default of 95; the
	 * XM430-W210 page (same electronics) prints 95-160: taken */
	{ "max_voltage_limit", 32, 2, false, RW, EE, 95, 160, true, 160, U(VOLTAGE), NOLIM,
	    "highest input voltage before the voltage error" },
	{ "min_voltage_limit", 34, 2, false, RW, EE, 95, 160, true, 95, U(VOLTAGE), NOLIM,
	    "lowest input voltage before the voltage error" },
	{ "pwm_limit",         36, 2, false, RW, EE, 0, 885, true, 885, U(PWM), NOLIM,
	    "largest PWM, the limit of goal_pwm" },
	{ "current_limit",     38, 2, false, RW, EE, 0, 1193, true, 1193, U(CURRENT), NOLIM,
	    "largest current, the limit of goal_current" },
	{ "velocity_limit",    44, 4, false, RW, EE, 0, 1023, true, 200, U(VELOCITY), NOLIM,
	    "largest speed, the limit of goal_velocity" },
	{ "max_position_limit", 48, 4, false, RW, EE, 0, 4095, true, 4095, U(POSITION), NOLIM,
	    "largest goal position in position mode" },
	{ "min_position_limit", 52, 4, false, RW, EE, 0, 4095, true, 0, U(POSITION), NOLIM,
	    "smallest goal position in position mode" },
	{ "shutdown",          63, 1, false, RW, EE, 0, DXL2_HWERR_MASK, true, 52, U(HWERR), NOLIM,
	    "hardware errors that switch the torque off" },
	{ "torque_enable",     64, 1, false, RW, RAM, 0, 1, true, 0, U(BOOL), NOLIM,
	    "motor torque on (locks the EEPROM area)" },
	{ "led",               65, 1, false, RW, RAM, 0, 1, true, 0, U(BOOL), NOLIM, "LED on" },
	{ "status_return_level", 68, 1, false, RW, RAM, 0, 2, true, 2, U(STATUS_LEVEL), NOLIM,
	    "which instructions are answered: 0 ping, 1 + read, 2 all" },
	{ "registered_instruction", 69, 1, false, R, RAM, RO_U8, true, 0, U(BOOL), NOLIM,
	    "a REG_WRITE is waiting for ACTION" },
	{ "hardware_error_status", 70, 1, false, R, RAM, RO_U8, true, 0, U(HWERR), NOLIM,
	    "hardware errors now (the status packet's alert bit)" },
	{ "velocity_i_gain",   76, 2, false, RW, RAM, 0, 16383, true, 1920, U(RAW), NOLIM, "velocity I gain" },
	{ "velocity_p_gain",   78, 2, false, RW, RAM, 0, 16383, true, 100, U(RAW), NOLIM, "velocity P gain" },
	{ "position_d_gain",   80, 2, false, RW, RAM, 0, 16383, true, 0, U(RAW), NOLIM, "position D gain" },
	{ "position_i_gain",   82, 2, false, RW, RAM, 0, 16383, true, 0, U(RAW), NOLIM, "position I gain" },
	{ "position_p_gain",   84, 2, false, RW, RAM, 0, 16383, true, 800, U(RAW), NOLIM, "position P gain" },
	{ "feedforward_2nd_gain", 88, 2, false, RW, RAM, 0, 16383, true, 0, U(RAW), NOLIM,
	    "feedforward acceleration gain" },
	{ "feedforward_1st_gain", 90, 2, false, RW, RAM, 0, 16383, true, 0, U(RAW), NOLIM,
	    "feedforward velocity gain" },
	/* the W350 page prints the unit as 20 us; the XL430 and XM430-W210
	 * pages 20 ms: ms taken */
	{ "bus_watchdog",      98, 1, false, RW, RAM, 0, 127, true, 0, U(WATCHDOG), NOLIM,
	    "stop when no packet came for this long, 20 ms a unit, 0 = off" },
	{ "goal_pwm",         100, 2, true,  RW, RAM, -885, 885, false, 0, U(PWM), SYM(36),
	    "target PWM (PWM mode), within +-pwm_limit" },
	{ "goal_current",     102, 2, true,  RW, RAM, -1193, 1193, false, 0, U(CURRENT), SYM(38),
	    "target current (current modes), within +-current_limit" },
	{ "goal_velocity",    104, 4, true,  RW, RAM, -1023, 1023, false, 0, U(VELOCITY), SYM(44),
	    "target speed (velocity mode), within +-velocity_limit" },
	{ "profile_acceleration", 108, 4, false, RW, RAM, 0, 32767, true, 0, U(ACCELERATION), NOLIM,
	    "profile acceleration, 0 = none" },
	{ "profile_velocity", 112, 4, false, RW, RAM, 0, 32767, true, 0, U(VELOCITY), NOLIM,
	    "profile speed, 0 = none" },
	{ "goal_position",    116, 4, true,  RW, RAM, -EXT_POS, EXT_POS, false, 0, U(POSITION),
	    DXL2_LIMIT_POSITION, 0, "target position, within the position limits in position mode" },
	{ "realtime_tick",    120, 2, false, R,  RAM, RO_U16, false, 0, U(MS), NOLIM,
	    "servo clock, 0-32767 ms, wraps" },
	{ "moving",           122, 1, false, R,  RAM, RO_U8, true, 0, U(BOOL), NOLIM, "moving now" },
	{ "moving_status",    123, 1, false, R,  RAM, RO_U8, true, 0, U(RAW), NOLIM, "profile and arrival bits" },
	{ "present_pwm",      124, 2, true,  R,  RAM, RO_S16, false, 0, U(PWM), NOLIM, "PWM now" },
	{ "present_current",  126, 2, true,  R,  RAM, RO_S16, false, 0, U(CURRENT), NOLIM, "current now" },
	{ "present_velocity", 128, 4, true,  R,  RAM, RO_S32, false, 0, U(VELOCITY), NOLIM, "speed now" },
	{ "present_position", 132, 4, true,  R,  RAM, RO_S32, false, 0, U(POSITION), NOLIM, "position now" },
	{ "velocity_trajectory", 136, 4, true, R, RAM, RO_S32, false, 0, U(VELOCITY), NOLIM,
	    "speed the profile asks for now" },
	{ "position_trajectory", 140, 4, true, R, RAM, RO_S32, false, 0, U(POSITION), NOLIM,
	    "position the profile asks for now" },
	{ "present_input_voltage", 144, 2, false, R, RAM, RO_U16, false, 0, U(VOLTAGE), NOLIM, "supply voltage" },
	{ "present_temperature", 146, 1, false, R, RAM, RO_U8, false, 0, U(TEMPERATURE), NOLIM,
	    "internal temperature" },
	X_IND_ROWS,
};

#define OPMODE_BIT(m) (1u << (m))
#define ROWS(a) .regs = (a), .nregs = sizeof (a) / sizeof (a)[0]
/* What every X servo here can do beyond its table. */
#define X_CAPS (DXL2_CAP_HWERR_STATUS | DXL2_CAP_WATCHDOG | DXL2_CAP_REBOOT | DXL2_CAP_OPMODE | \
                DXL2_CAP_FACTORY_RESET_KEEP | DXL2_CAP_INDIRECT)
/* e-manual, Protocol 2.0, "Fast Sync Read (0x8A)" and "Fast Bulk Read
 * (0x9A)": "X430/540 Series (Fw v45 or above, 2XL/2XC Not Supported)". */
#define X430_FAST_READ_FIRMWARE 45
static const struct dxl2_model dxl2_models[] = {
	/* e-manual (docs/en/dxl/ax/ax-12a.md): 1.5 N·m at 12 V (1.5 A), 59 rpm
	 * at 12 V, 254:1, 9-12 V (11.1 recommended); rotor 4.6e-8 kg·m², the
	 * simulator's estimate (sim-bridge/PHYSICS.md §5). Factory 1 Mbps; the
	 * simulated one reports firmware 24. */
	{ .protocol = 1, .number = DXL_AX12_MODEL, .name = "AX-12A", ROWS(ax12a_regs),
	  .caps = DXL2_CAP_WHEEL_BY_ANGLE_LIMITS,
	  .opmodes = 0, .current_sensing = false,
	  .sheet = { .stall_torque_nm = 1.5, .stall_current_a = 1.5, .no_load_speed_rpm = 59.0, .gear_ratio = 254.0,
	             .rotor_inertia = 4.6e-8, .rated_min_v = 9.0, .rated_rec_v = 11.1, .rated_max_v = 12.0 },
	  .factory_baud = 1000000, .firmware = 24 },
	/* 1.5 N·m at 12 V (1.4 A), 61 rpm at 12 V, 258.5:1, 6.5-12.0 V (11.1
	 * recommended); a cored motor: its rotor taken as the AX-12A's */
	{ .protocol = 2, .number = DXL2_MODEL_XL430_W250, .name = "XL430-W250", ROWS(xl430_regs),
	  .caps = X_CAPS,
	  .opmodes = OPMODE_BIT(1) | OPMODE_BIT(3) | OPMODE_BIT(4) | OPMODE_BIT(16), .current_sensing = false,
	  .sheet = { .stall_torque_nm = 1.5, .stall_current_a = 1.4, .no_load_speed_rpm = 61.0, .gear_ratio = 258.5,
	             .rotor_inertia = 4.6e-8, .rated_min_v = 6.5, .rated_rec_v = 11.1, .rated_max_v = 12.0 },
	  .factory_baud = 57600, .firmware = 46, .fast_read_firmware = X430_FAST_READ_FIRMWARE },
	/* 4.1 N·m at 12 V (2.3 A), 46 rpm at 12 V, 353.5:1, 10.0-14.8 V (12.0
	 * recommended); a coreless (Maxon) motor: 0.5 g·cm² taken for its rotor */
	{ .protocol = 2, .number = DXL2_MODEL_XM430_W350, .name = "XM430-W350", ROWS(xm430_regs),
	  .caps = X_CAPS,
	  .opmodes = OPMODE_BIT(0) | OPMODE_BIT(1) | OPMODE_BIT(3) | OPMODE_BIT(4) | OPMODE_BIT(5) | OPMODE_BIT(16),
	  .current_sensing = true,
	  .sheet = { .stall_torque_nm = 4.1, .stall_current_a = 2.3, .no_load_speed_rpm = 46.0, .gear_ratio = 353.5,
	             .rotor_inertia = 5.0e-8, .rated_min_v = 10.0, .rated_rec_v = 12.0, .rated_max_v = 14.8 },
	  .factory_baud = 57600, .firmware = 46, .fast_read_firmware = X430_FAST_READ_FIRMWARE },
	/* docs/en/dxl/x/xc430-w150.md: 1.6 N·m at 12 V (1.4 A), 106 rpm at
	 * 12 V, 159.59:1, 6.5-14.8 V (12.0 recommended); velocity, position,
	 * extended position and PWM control, Present Load (no current sensing);
	 * a coreless motor: its rotor taken as the XM430's */
	{ .protocol = 2, .number = DXL2_MODEL_XC430_W150, .name = "XC430-W150", ROWS(xc430_regs),
	  .caps = X_CAPS,
	  .opmodes = OPMODE_BIT(1) | OPMODE_BIT(3) | OPMODE_BIT(4) | OPMODE_BIT(16), .current_sensing = false,
	  .sheet = { .stall_torque_nm = 1.6, .stall_current_a = 1.4, .no_load_speed_rpm = 106.0, .gear_ratio = 159.59,
	             .rotor_inertia = 5.0e-8, .rated_min_v = 6.5, .rated_rec_v = 12.0, .rated_max_v = 14.8 },
	  .factory_baud = 57600, .firmware = 46, .fast_read_firmware = X430_FAST_READ_FIRMWARE },
};
#define NMODELS (sizeof dxl2_models / sizeof dxl2_models[0])

/* Short names people type at a prompt; an alias names the first of its
 * registers the model has ("speed": present_velocity on an X servo,
 * present_speed on the AX-12A). */
static const struct {
	const char *alias, *name;
} dxl2_aliases[] = {
	{ "model", "model_number" },
	{ "firmware", "firmware_version" },
	{ "baud", "baud_rate" },
	{ "return_delay", "return_delay_time" },
	{ "cw_limit", "cw_angle_limit" },
	{ "ccw_limit", "ccw_angle_limit" },
	{ "max_temperature", "temperature_limit" },
	{ "min_voltage", "min_voltage_limit" },
	{ "max_voltage", "max_voltage_limit" },
	{ "mode", "operating_mode" },
	{ "torque", "torque_enable" },
	{ "return_level", "status_return_level" },
	{ "hardware_error", "hardware_error_status" },
	{ "watchdog", "bus_watchdog" },
	{ "goal", "goal_position" },
	{ "position", "present_position" },
	{ "velocity", "present_velocity" },
	{ "speed", "present_velocity" },
	{ "speed", "present_speed" },
	{ "current", "present_current" },
	{ "load", "present_load" },
	{ "voltage", "present_input_voltage" },
	{ "voltage", "present_voltage" },
	{ "temperature", "present_temperature" },
};

const char *dxl2_opmode_name(uint8_t mode)
{
	switch (mode) {
	case DXL2_OPMODE_CURRENT:           return "current";
	case DXL2_OPMODE_VELOCITY:          return "velocity";
	case DXL2_OPMODE_POSITION:          return "position";
	case DXL2_OPMODE_EXTENDED_POSITION: return "extended position";
	case DXL2_OPMODE_CURRENT_POSITION:  return "current-based position";
	case DXL2_OPMODE_PWM:               return "PWM";
	default:                            return NULL;
	}
}

static const char *dxl2_hwerr_name(uint8_t bit)
{
	switch (bit) {
	case DXL2_HWERR_VOLTAGE:  return "input voltage";
	case DXL2_HWERR_OVERHEAT: return "overheating";
	case DXL2_HWERR_ENCODER:  return "motor encoder";
	case DXL2_HWERR_SHOCK:    return "electrical shock";
	case DXL2_HWERR_OVERLOAD: return "overload";
	default:                  return NULL;
	}
}

char *dxl2_hwerr_format(uint8_t bits, char *buf, size_t cap)
{
	return dxl_bits_format(bits, dxl2_hwerr_name, buf, cap);
}

static bool name_eq(const char *a, const char *b)
{
	for (;; a++, b++) {
		int ca = (*a == '-') ? '_' : tolower((unsigned char)*a);
		int cb = (*b == '-') ? '_' : tolower((unsigned char)*b);
		if (ca != cb)
			return false;
		if (ca == '\0')
			return true;
	}
}

const struct dxl2_model *dxl2_model_by_number(uint16_t number)
{
	for (size_t i = 0; i < NMODELS; i++)
		if (dxl2_models[i].number == number)
			return &dxl2_models[i];
	return NULL;
}

const struct dxl2_model *dxl2_model_find(int protocol, uint16_t number)
{
	const struct dxl2_model *m = dxl2_model_by_number(number);
	return m != NULL && m->protocol == protocol ? m : NULL;
}

const struct dxl2_model *dxl2_model_first(int protocol)
{
	for (size_t i = 0; i < dxl2_model_count(); i++)
		if (dxl2_model_at(i)->protocol == protocol)
			return dxl2_model_at(i);
	return NULL;
}

bool dxl2_model_fast_read(const struct dxl2_model *m, uint8_t firmware)
{
	return m != NULL && m->fast_read_firmware != 0 && firmware >= m->fast_read_firmware;
}

bool dxl2_model_can(const struct dxl2_model *m, enum dxl2_cap cap)
{
	return m != NULL && (m->caps & (uint32_t)cap) == (uint32_t)cap;
}

double dxl2_sheet_no_load_rad_s(const struct dxl2_datasheet *s)
{
	return s->no_load_speed_rpm * 2.0 * DXL2_PI / 60.0;
}

size_t dxl2_model_count(void)
{
	return NMODELS;
}

const struct dxl2_model *dxl2_model_at(size_t i)
{
	return i < NMODELS ? &dxl2_models[i] : NULL;
}

char *dxl2_model_names(int protocol, char *buf, size_t cap)
{
	size_t off = 0;
	if (cap == 0)
		return buf;
	buf[0] = '\0';
	for (size_t i = 0; i < NMODELS; i++) {
		if (protocol != 0 && dxl2_models[i].protocol != protocol)
			continue;
		int w = snprintf(buf + off, cap - off, "%s%s", off ? ", " : "", dxl2_models[i].name);
		if (w < 0 || (size_t)w >= cap - off)
			break;
		off += (size_t)w;
	}
	return buf;
}

const struct dxl2_model *dxl2_model_by_name(const char *name)
{
	if (name == NULL)
		return NULL;
	for (size_t i = 0; i < NMODELS; i++)
		if (name_eq(dxl2_models[i].name, name))
			return &dxl2_models[i];
	return NULL;
}

const struct dxl2_reg *dxl2_reg_at(const struct dxl2_model *m, uint16_t addr)
{
	if (m == NULL)
		return NULL;
	for (size_t i = 0; i < m->nregs; i++)
		if (m->regs[i].addr == addr)
			return &m->regs[i];
	return NULL;
}

static const struct dxl2_reg *dxl2_reg_by_name(const struct dxl2_model *m, const char *name)
{
	for (size_t i = 0; i < m->nregs; i++)
		if (name_eq(m->regs[i].name, name))
			return &m->regs[i];
	for (size_t i = 0; i < sizeof dxl2_aliases / sizeof dxl2_aliases[0]; i++) {
		if (!name_eq(dxl2_aliases[i].alias, name))
			continue;
		for (size_t k = 0; k < m->nregs; k++)
			if (name_eq(m->regs[k].name, dxl2_aliases[i].name))
				return &m->regs[k];
	}
	return NULL;
}

const struct dxl2_reg *dxl2_reg_lookup(const struct dxl2_model *m, const char *name_or_addr)
{
	if (m == NULL || name_or_addr == NULL || *name_or_addr == '\0')
		return NULL;
	if (isdigit((unsigned char)name_or_addr[0])) {
		/* decimal, or hex with 0x; a leading 0 is not octal (the manual
		 * writes addresses in decimal) */
		bool hex = name_or_addr[0] == '0' && (name_or_addr[1] == 'x' || name_or_addr[1] == 'X');
		char *end;
		errno = 0;
		unsigned long v = strtoul(name_or_addr, &end, hex ? 16 : 10);
		if (errno || *end != '\0' || v > 65535)
			return NULL;
		return dxl2_reg_at(m, (uint16_t)v);
	}
	return dxl2_reg_by_name(m, name_or_addr);
}

int dxl2_indirect_slot(uint16_t addr)
{
	if (addr >= DXL2_X_INDIRECT_DATA_1 && addr < DXL2_X_INDIRECT_DATA_1 + DXL2_X_INDIRECT_PER_BLOCK)
		return addr - DXL2_X_INDIRECT_DATA_1 + 1;
	if (addr >= DXL2_X_INDIRECT_DATA_29 && addr < DXL2_X_INDIRECT_DATA_29 + DXL2_X_INDIRECT_PER_BLOCK)
		return addr - DXL2_X_INDIRECT_DATA_29 + DXL2_X_INDIRECT_PER_BLOCK + 1;
	return 0;
}

uint16_t dxl2_indirect_address_reg(int n)
{
	if (n < 1 || n > DXL2_X_INDIRECT_COUNT)
		return 0;
	return n <= DXL2_X_INDIRECT_PER_BLOCK ? (uint16_t)(DXL2_X_INDIRECT_ADDRESS_1 + 2 * (n - 1))
	                                      : (uint16_t)(DXL2_X_INDIRECT_ADDRESS_29 + 2 * (n - 29));
}

uint16_t dxl2_indirect_data_addr(int n)
{
	if (n < 1 || n > DXL2_X_INDIRECT_COUNT)
		return 0;
	return n <= DXL2_X_INDIRECT_PER_BLOCK ? (uint16_t)(DXL2_X_INDIRECT_DATA_1 + n - 1)
	                                      : (uint16_t)(DXL2_X_INDIRECT_DATA_29 + n - 29);
}

int32_t dxl2_reg_decode(const struct dxl2_reg *r, const uint8_t *b)
{
	switch (r->size) {
	case 1:
		return r->is_signed ? (int32_t)(int8_t)b[0] : (int32_t)b[0];
	case 2: {
		uint16_t v = (uint16_t)(b[0] | (b[1] << 8));
		return r->is_signed ? (int32_t)(int16_t)v : (int32_t)v;
	}
	default:
		return (int32_t)dxl2_get_u32(b);
	}
}

void dxl2_reg_encode(const struct dxl2_reg *r, int32_t value, uint8_t *b)
{
	uint32_t u = (uint32_t)value;
	for (unsigned i = 0; i < r->size; i++)
		b[i] = (uint8_t)(u >> (8 * i));
}

int dxl2_reg_check_write(const struct dxl2_model *m, const struct dxl2_reg *r, long value)
{
	if (m == NULL || r == NULL || r->access != DXL_ACCESS_RW)
		return DXL_E_ARG;
	if (value < (long)r->min || value > (long)r->max)
		return DXL_E_ARG;
	if (r->unit == DXL2_UNIT_OPMODE && !(m->opmodes & (1u << value)))
		return DXL_E_ARG;
	return DXL_OK;
}

/* The value of the register at addr in a table image; false if the image is
 * too short or the model has no such register. */
static bool image_value(const struct dxl2_model *m, uint16_t addr, const uint8_t *table, size_t len,
                        int32_t *v)
{
	const struct dxl2_reg *r = dxl2_reg_at(m, addr);
	if (r == NULL || table == NULL || (size_t)addr + r->size > len)
		return false;
	*v = dxl2_reg_decode(r, table + addr);
	return true;
}

int dxl2_reg_range(const struct dxl2_model *m, const struct dxl2_reg *r, const uint8_t *table,
                   size_t len, int32_t *lo, int32_t *hi)
{
	if (m == NULL || r == NULL || lo == NULL || hi == NULL)
		return DXL_E_ARG;
	*lo = r->min;
	*hi = r->max;
	int32_t a, b, mode;
	switch (r->limit) {
	case DXL2_LIMIT_SYMMETRIC:
		if (image_value(m, r->lim_addr, table, len, &a) && a >= 0 && a < *hi) {
			*lo = -a;
			*hi = a;
		}
		break;
	case DXL2_LIMIT_POSITION:
		/* e-manual, Goal Position: the limits bind in position control
		 * mode; extended and current-based position use the full range */
		if (image_value(m, DXL2_X_OPERATING_MODE, table, len, &mode) && mode == DXL2_OPMODE_POSITION &&
		    image_value(m, DXL2_X_MIN_POSITION_LIMIT, table, len, &a) &&
		    image_value(m, DXL2_X_MAX_POSITION_LIMIT, table, len, &b)) {
			*lo = a;
			*hi = b;
		}
		break;
	case DXL2_LIMIT_JOINT_MODE:
		if (image_value(m, DXL_AX_CW_ANGLE_LIMIT, table, len, &a) &&
		    image_value(m, DXL_AX_CCW_ANGLE_LIMIT, table, len, &b) && !dxl_is_wheel_mode((uint16_t)a, (uint16_t)b))
			*hi = DXL_POS_MAX;
		break;
	case DXL2_LIMIT_NONE:
	default:
		break;
	}
	return DXL_OK;
}

bool dxl2_reg_limit_binds(const struct dxl2_model *m, const struct dxl2_reg *r, const uint8_t *table, size_t len)
{
	int32_t v;
	if (m == NULL || r == NULL)
		return false;
	switch (r->limit) {
	case DXL2_LIMIT_SYMMETRIC:
		return image_value(m, r->lim_addr, table, len, &v);
	case DXL2_LIMIT_POSITION:
		return image_value(m, DXL2_X_OPERATING_MODE, table, len, &v) && v == DXL2_OPMODE_POSITION &&
		       image_value(m, DXL2_X_MIN_POSITION_LIMIT, table, len, &v) &&
		       image_value(m, DXL2_X_MAX_POSITION_LIMIT, table, len, &v);
	case DXL2_LIMIT_JOINT_MODE:   /* Protocol 1.0 has no data limit error */
	case DXL2_LIMIT_NONE:
	default:
		return false;
	}
}

int dxl2_reg_check_write_live(const struct dxl2_model *m, const struct dxl2_reg *r, long value,
                              const uint8_t *table, size_t len)
{
	int32_t lo, hi;
	if (dxl2_reg_check_write(m, r, value) != DXL_OK)
		return DXL_E_ARG;
	if (dxl2_reg_range(m, r, table, len, &lo, &hi) != DXL_OK)
		return DXL_E_ARG;
	return (value < lo || value > hi) ? DXL_E_ARG : DXL_OK;
}

/* Bit 10 of the AX-12A's speed and load: the direction, none at 0. */
static const char *ax_direction(int32_t raw)
{
	if ((raw & 0x3FF) == 0)
		return "";
	return (raw & DXL_DIRECTION_BIT) ? " CW" : " CCW";
}

/* The AX-12A's units; false for another unit. */
static bool ax_format(enum dxl2_unit unit, int32_t raw, char *buf, size_t cap)
{
	char bits[96];
	unsigned u = (unsigned)raw & 0xFFFFu, mag = u & 0x3FFu;
	switch (unit) {
	case DXL2_UNIT_AX_POSITION:
		snprintf(buf, cap, "%u (%.1f deg)", u, u * DXL_POS_RANGE_DEG / DXL_POS_MAX);
		return true;
	case DXL2_UNIT_AX_SPEED:
		snprintf(buf, cap, "%u (%.1f rpm%s)", u, mag * DXL_SPEED_RPM_PER_UNIT, ax_direction(raw));
		return true;
	case DXL2_UNIT_AX_MOVING_SPEED:
		if (u == 0)
			snprintf(buf, cap, "0 (maximum)");
		else if (u > DXL_POS_MAX) /* wheel mode: direction bit */
			snprintf(buf, cap, "%u (%.1f rpm%s)", u, mag * DXL_SPEED_RPM_PER_UNIT, ax_direction(raw));
		else
			snprintf(buf, cap, "%u (%.1f rpm)", u, u * DXL_SPEED_RPM_PER_UNIT);
		return true;
	case DXL2_UNIT_AX_LOAD:
		snprintf(buf, cap, "%u (%.1f %%%s)", u, mag * 0.1, ax_direction(raw));
		return true;
	case DXL2_UNIT_AX_TORQUE:
		snprintf(buf, cap, "%u (%.1f %%)", u, u * 0.1);
		return true;
	case DXL2_UNIT_AX_BAUD:
		snprintf(buf, cap, "%u (%ld bps)", u, dxl_baud_from_reg((uint8_t)u));
		return true;
	case DXL2_UNIT_AX_ERRMASK:
		snprintf(buf, cap, "%u (%s)", u, dxl_errbits_format((uint8_t)u, bits, sizeof bits));
		return true;
	default:
		return false;
	}
}

char *dxl2_reg_format(const struct dxl2_reg *r, int32_t raw, char *buf, size_t cap)
{
	char bits[96];
	if (buf == NULL || cap == 0)
		return buf;
	if (r == NULL) {
		snprintf(buf, cap, "%ld", (long)raw);
		return buf;
	}
	long v = raw;
	const char *name;
	switch (r->unit) {
	case DXL2_UNIT_POSITION:
		snprintf(buf, cap, "%ld (%.1f deg)", v, raw * 360.0 / DXL2_POS_PER_REV);
		break;
	case DXL2_UNIT_VELOCITY:
		snprintf(buf, cap, "%ld (%.1f rpm)", v, raw * DXL2_VELOCITY_RPM_PER_UNIT);
		break;
	case DXL2_UNIT_CURRENT:
		snprintf(buf, cap, "%ld (%.0f mA)", v, raw * DXL2_CURRENT_A_PER_UNIT * 1000.0);
		break;
	case DXL2_UNIT_LOAD:
		snprintf(buf, cap, "%ld (%.1f %%)", v, raw * 0.1);
		break;
	case DXL2_UNIT_PWM:
		snprintf(buf, cap, "%ld (%.1f %%)", v, raw * DXL2_PWM_PER_UNIT * 100.0);
		break;
	case DXL2_UNIT_VOLTAGE:
		snprintf(buf, cap, "%ld (%.1f V)", v, raw * 0.1);
		break;
	case DXL2_UNIT_TEMPERATURE:
		snprintf(buf, cap, "%ld (%ld C)", v, v);
		break;
	case DXL2_UNIT_BAUD:
		snprintf(buf, cap, "%ld (%ld bps)", v, dxl2_baud_from_reg((uint8_t)raw));
		break;
	case DXL2_UNIT_RETURN_DELAY:
		snprintf(buf, cap, "%ld (%u us)", v, dxl2_return_delay_us((uint8_t)raw));
		break;
	case DXL2_UNIT_WATCHDOG:
		if (raw == 0)
			snprintf(buf, cap, "0 (off)");
		else
			snprintf(buf, cap, "%ld (%u ms)", v, dxl2_watchdog_ms((uint8_t)raw));
		break;
	case DXL2_UNIT_ACCELERATION:
		snprintf(buf, cap, "%ld (%.0f rev/min2)", v, raw * 214.577);
		break;
	case DXL2_UNIT_MS:
		snprintf(buf, cap, "%ld (%ld ms)", v, v);
		break;
	case DXL2_UNIT_BOOL:
		snprintf(buf, cap, "%ld (%s)", v, raw ? "on" : "off");
		break;
	case DXL2_UNIT_HWERR:
		snprintf(buf, cap, "%ld (%s)", v, dxl2_hwerr_format((uint8_t)raw, bits, sizeof bits));
		break;
	case DXL2_UNIT_STATUS_LEVEL:
		snprintf(buf, cap, "%ld (%s)", v, raw == 0 ? "ping only" : raw == 1 ? "ping + read" :
		                                  raw == 2 ? "all" : "invalid");
		break;
	case DXL2_UNIT_OPMODE:
		name = dxl2_opmode_name((uint8_t)raw);
		snprintf(buf, cap, "%ld (%s)", v, name ? name : "invalid");
		break;
	case DXL2_UNIT_RAW:
	default:
		if (!ax_format(r->unit, raw, buf, cap))
			snprintf(buf, cap, "%ld", v);
		break;
	}
	return buf;
}

/* ---- conversions ------------------------------------------------------------ */

double dxl2_pos_to_rad(int32_t raw)
{
	return ((double)raw - DXL2_POS_CENTER) * DXL2_POS_RAD_PER_UNIT;
}

int32_t dxl2_rad_to_pos(double rad)
{
	if (isnan(rad))
		return DXL2_POS_CENTER;
	double units = rad / DXL2_POS_RAD_PER_UNIT + DXL2_POS_CENTER;
	if (units <= 0.0)
		return 0;
	if (units >= DXL2_POS_MAX)
		return DXL2_POS_MAX;
	return (int32_t)lround(units);
}

/* Nearest integer of x within +-limit (limit >= 0); NaN gives 0. */
static int32_t clamp_round(double x, int32_t limit)
{
	if (isnan(x) || limit < 0)
		return 0;
	if (x >= limit)
		return limit;
	if (x <= -limit)
		return -limit;
	return (int32_t)lround(x);
}

double dxl2_velocity_to_rad_s(int32_t raw)
{
	return raw * DXL2_VELOCITY_RAD_S_PER_UNIT;
}

int32_t dxl2_rad_s_to_velocity(double rad_s, int32_t limit)
{
	return clamp_round(rad_s / DXL2_VELOCITY_RAD_S_PER_UNIT, limit);
}

double dxl2_current_to_amps(int32_t raw)
{
	return raw * DXL2_CURRENT_A_PER_UNIT;
}

int32_t dxl2_amps_to_current(double amps, int32_t limit)
{
	return clamp_round(amps / DXL2_CURRENT_A_PER_UNIT, limit);
}

double dxl2_load_to_fraction(int32_t raw)
{
	return raw * 0.001;
}

double dxl2_pwm_to_fraction(int32_t raw)
{
	return raw * DXL2_PWM_PER_UNIT;
}

double dxl2_voltage_to_volts(int32_t raw)
{
	return raw * 0.1;
}

/* e-manual, X series Baud Rate (8). */
static const long dxl2_bauds[] = { 9600, 57600, 115200, 1000000, 2000000, 3000000, 4000000, 4500000 };
#define NBAUDS (sizeof dxl2_bauds / sizeof dxl2_bauds[0])
/* A UART's tolerance to a rate mismatch (as dxl_baud_to_reg). */
#define DXL2_BAUD_TOLERANCE 0.03

long dxl2_baud_from_reg(uint8_t v)
{
	return v < NBAUDS ? dxl2_bauds[v] : -1;
}

int dxl2_baud_to_reg(long bps, uint8_t *v)
{
	if (bps <= 0 || v == NULL)
		return DXL_E_ARG;
	for (size_t i = 0; i < NBAUDS; i++) {
		if (fabs((double)dxl2_bauds[i] - (double)bps) <= DXL2_BAUD_TOLERANCE * (double)bps) {
			*v = (uint8_t)i;
			return DXL_OK;
		}
	}
	return DXL_E_ARG;
}

unsigned dxl2_return_delay_us(uint8_t v)
{
	return 2u * v;
}

unsigned dxl2_watchdog_ms(uint8_t v)
{
	return 20u * v;
}
