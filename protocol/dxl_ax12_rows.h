/*
 * dxl_ax12_rows.h — the AX-12(A)'s control table, its one written place:
 * DXL_AX12_ROWS(ROW) calls ROW(name, addr, size, access, area, min, max,
 * def, unit, desc) once a register. dxl2_table.c makes the AX-12A's model
 * descriptor's rows from it (struct dxl2_reg, the row type every model
 * shares); dxl_table.c the older struct dxl_reg view the simulator's servo
 * walks. Values from the ROBOTIS e-Manual (AX-12A) and the original AX-12
 * manual; where they differ the desc says so. The write ranges are the
 * e-manual's (Moving Speed's joint-mode 0-1023 is the descriptor's
 * DXL2_LIMIT_JOINT_MODE): the simulated servo answers a value outside them
 * with the range bit, and `dxl write` refuses it before the bus.
 * access R/RW, area EE/RAM, unit a DXL_UNIT_ suffix, def NODEF when the
 * register has no factory default (measured, or copied at power-on).
 */
#ifndef UNDULATE_DXL_AX12_ROWS_H
#define UNDULATE_DXL_AX12_ROWS_H

#define DXL_AX12_ROWS(ROW) \
	ROW("model_number",         0, 2, R,  EE,  0, 65535, 12, RAW, \
	    "model number (12 for AX-12/AX-12+/AX-12A)") \
	ROW("firmware_version",     2, 1, R,  EE,  0, 255, NODEF, RAW, "firmware version") \
	ROW("id",                   3, 1, RW, EE,  0, DXL_MAX_ID, 1, RAW, \
	    "servo ID, 0-253 (254 is broadcast)") \
	ROW("baud_rate",            4, 1, RW, EE,  0, 254, 1, BAUD, \
	    "baud rate: bps = 2000000 / (value + 1)") \
	ROW("return_delay_time",    5, 1, RW, EE,  0, 254, 250, RETURN_DELAY, \
	    "delay before a status packet, 2 us a unit (0 for speed)") \
	ROW("cw_angle_limit",       6, 2, RW, EE,  0, 1023, 0, POSITION, \
	    "clockwise angle limit (both limits 0: wheel mode)") \
	ROW("ccw_angle_limit",      8, 2, RW, EE,  0, 1023, 1023, POSITION, \
	    "counter-clockwise angle limit") \
	ROW("temperature_limit",   11, 1, RW, EE,  0, 100, 70, TEMPERATURE, \
	    "overheating threshold, 0-100 (old manual: default 85, range 0-150)") \
	ROW("min_voltage_limit",   12, 1, RW, EE, 50, 160, 60, VOLTAGE, \
	    "lowest supply voltage before the voltage error, 50-160 (old manual: 50-250)") \
	ROW("max_voltage_limit",   13, 1, RW, EE, 50, 160, 140, VOLTAGE, \
	    "highest supply voltage before the voltage error, 50-160 (old manual: default 190, 50-250)") \
	ROW("max_torque",          14, 2, RW, EE,  0, 1023, 1023, TORQUE, \
	    "maximum torque, copied to torque_limit at power-on") \
	ROW("status_return_level", 16, 1, RW, EE,  0, 2, 2, STATUS_LEVEL, \
	    "which instructions are answered: 0 ping, 1 + read, 2 all") \
	ROW("alarm_led",           17, 1, RW, EE,  0, DXL_ERRBIT_MASK, 36, ERRMASK, \
	    "error bits that blink the LED (old manual: default 4)") \
	ROW("alarm_shutdown",      18, 1, RW, EE,  0, DXL_ERRBIT_MASK, 36, ERRMASK, \
	    "error bits that switch the torque off (old manual: default 4)") \
	ROW("torque_enable",       24, 1, RW, RAM, 0, 1, 0, BOOL, "motor torque on") \
	ROW("led",                 25, 1, RW, RAM, 0, 1, 0, BOOL, "LED on") \
	ROW("cw_compliance_margin",  26, 1, RW, RAM, 0, 255, 1, RAW, \
	    "dead band in position units, CW side (old manual: default 0)") \
	ROW("ccw_compliance_margin", 27, 1, RW, RAM, 0, 255, 1, RAW, \
	    "dead band in position units, CCW side (old manual: default 0)") \
	ROW("cw_compliance_slope",   28, 1, RW, RAM, 0, 254, 32, RAW, \
	    "error over which torque ramps up, CW side (steps 2,4,...,128; 0-3 act as 2; old manual: 1-254)") \
	ROW("ccw_compliance_slope",  29, 1, RW, RAM, 0, 254, 32, RAW, \
	    "error over which torque ramps up, CCW side (steps 2,4,...,128; 0-3 act as 2; old manual: 1-254)") \
	ROW("goal_position",       30, 2, RW, RAM, 0, 1023, NODEF, POSITION, \
	    "target position (starts as the present position)") \
	ROW("moving_speed",        32, 2, RW, RAM, 0, 2047, 0, MOVING_SPEED, \
	    "joint mode: 1-1023 x 0.111 rpm, 0 = maximum; wheel mode: bit 10 = CW") \
	ROW("torque_limit",        34, 2, RW, RAM, 0, 1023, 1023, TORQUE, \
	    "torque limit (max_torque at power-on; 0 after an alarm shutdown)") \
	ROW("present_position",    36, 2, R,  RAM, 0, 1023, NODEF, POSITION, \
	    "measured position, 0-1023 over 300 deg") \
	ROW("present_speed",       38, 2, R,  RAM, 0, 2047, NODEF, SPEED, \
	    "joint mode: measured speed; wheel mode: the output, 0.1 % a unit; bit 10 = CW") \
	ROW("present_load",        40, 2, R,  RAM, 0, 2047, NODEF, LOAD, \
	    "load in 0.1 % of max torque, bit 10 = CW") \
	ROW("present_voltage",     42, 1, R,  RAM, 0, 255, NODEF, VOLTAGE, "supply voltage") \
	ROW("present_temperature", 43, 1, R,  RAM, 0, 255, NODEF, TEMPERATURE, \
	    "internal temperature") \
	ROW("registered",          44, 1, R,  RAM, 0, 1, 0, BOOL, \
	    "a REG_WRITE is waiting for ACTION") \
	ROW("moving",              46, 1, R,  RAM, 0, 1, 0, BOOL, "goal not reached yet") \
	ROW("lock",                47, 1, RW, RAM, 0, 1, 0, BOOL, \
	    "1 locks the EEPROM area until power-cycle") \
	ROW("punch",               48, 2, RW, RAM, 32, 1023, 32, RAW, \
	    "minimum drive current, 0x20-0x3FF (old manual: 0-1023)")

#endif
