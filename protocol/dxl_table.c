/*
 * dxl_table.c — the AX-12(A) control table as data, lookup, write checks,
 * unit conversions and formatting. Values from the ROBOTIS e-Manual (AX-12A)
 * and the original AX-12 manual; where they differ the desc says so. The
 * write ranges (min, max, and joint mode's narrower ones) are the AX-12A e-manual's: the simulated
 * servo answers a value outside them with the range bit, and `dxl write`
 * refuses it before the bus, so both enforce this one table.
 */
#include "dxl_table.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dxl.h"

#define R  DXL_ACCESS_R
#define RW DXL_ACCESS_RW
#define EE DXL_AREA_EEPROM
#define RAM DXL_AREA_RAM
/* def value of a register with no factory default (measured / copied at power-on) */
#define NODEF (-1)

const struct dxl_reg dxl_ax12_regs[] = {
	{ "model_number",         0, 2, R,  EE,  0, 65535, 12, DXL_UNIT_RAW,
	  "model number (12 for AX-12/AX-12+/AX-12A)" },
	{ "firmware_version",     2, 1, R,  EE,  0, 255, NODEF, DXL_UNIT_RAW, "firmware version" },
	{ "id",                   3, 1, RW, EE,  0, DXL_MAX_ID, 1, DXL_UNIT_RAW,
	  "servo ID, 0-253 (254 is broadcast)" },
	{ "baud_rate",            4, 1, RW, EE,  0, 254, 1, DXL_UNIT_BAUD,
	  "baud rate: bps = 2000000 / (value + 1)" },
	{ "return_delay_time",    5, 1, RW, EE,  0, 254, 250, DXL_UNIT_RETURN_DELAY,
	  "delay before a status packet, 2 us a unit (0 for speed)" },
	{ "cw_angle_limit",       6, 2, RW, EE,  0, 1023, 0, DXL_UNIT_POSITION,
	  "clockwise angle limit (both limits 0: wheel mode)" },
	{ "ccw_angle_limit",      8, 2, RW, EE,  0, 1023, 1023, DXL_UNIT_POSITION,
	  "counter-clockwise angle limit" },
	{ "temperature_limit",   11, 1, RW, EE,  0, 100, 70, DXL_UNIT_TEMPERATURE,
	  "overheating threshold, 0-100 (old manual: default 85, range 0-150)" },
	{ "min_voltage_limit",   12, 1, RW, EE, 50, 160, 60, DXL_UNIT_VOLTAGE,
	  "lowest supply voltage before the voltage error, 50-160 (old manual: 50-250)" },
	{ "max_voltage_limit",   13, 1, RW, EE, 50, 160, 140, DXL_UNIT_VOLTAGE,
	  "highest supply voltage before the voltage error, 50-160 (old manual: default 190, 50-250)" },
	{ "max_torque",          14, 2, RW, EE,  0, 1023, 1023, DXL_UNIT_TORQUE,
	  "maximum torque, copied to torque_limit at power-on" },
	{ "status_return_level", 16, 1, RW, EE,  0, 2, 2, DXL_UNIT_STATUS_LEVEL,
	  "which instructions are answered: 0 ping, 1 + read, 2 all" },
	{ "alarm_led",           17, 1, RW, EE,  0, DXL_ERRBIT_MASK, 36, DXL_UNIT_ERRMASK,
	  "error bits that blink the LED (old manual: default 4)" },
	{ "alarm_shutdown",      18, 1, RW, EE,  0, DXL_ERRBIT_MASK, 36, DXL_UNIT_ERRMASK,
	  "error bits that switch the torque off (old manual: default 4)" },
	{ "torque_enable",       24, 1, RW, RAM, 0, 1, 0, DXL_UNIT_BOOL, "motor torque on" },
	{ "led",                 25, 1, RW, RAM, 0, 1, 0, DXL_UNIT_BOOL, "LED on" },
	{ "cw_compliance_margin",  26, 1, RW, RAM, 0, 255, 1, DXL_UNIT_RAW,
	  "dead band in position units, CW side (old manual: default 0)" },
	{ "ccw_compliance_margin", 27, 1, RW, RAM, 0, 255, 1, DXL_UNIT_RAW,
	  "dead band in position units, CCW side (old manual: default 0)" },
	{ "cw_compliance_slope",   28, 1, RW, RAM, 0, 254, 32, DXL_UNIT_RAW,
	  "error over which torque ramps up, CW side (steps 2,4,...,128; 0-3 act as 2; old manual: 1-254)" },
	{ "ccw_compliance_slope",  29, 1, RW, RAM, 0, 254, 32, DXL_UNIT_RAW,
	  "error over which torque ramps up, CCW side (steps 2,4,...,128; 0-3 act as 2; old manual: 1-254)" },
	{ "goal_position",       30, 2, RW, RAM, 0, 1023, NODEF, DXL_UNIT_POSITION,
	  "target position (starts as the present position)" },
	{ "moving_speed",        32, 2, RW, RAM, 0, 2047, 0, DXL_UNIT_MOVING_SPEED,
	  "joint mode: 1-1023 x 0.111 rpm, 0 = maximum; wheel mode: bit 10 = CW" },
	{ "torque_limit",        34, 2, RW, RAM, 0, 1023, 1023, DXL_UNIT_TORQUE,
	  "torque limit (max_torque at power-on; 0 after an alarm shutdown)" },
	{ "present_position",    36, 2, R,  RAM, 0, 1023, NODEF, DXL_UNIT_POSITION,
	  "measured position, 0-1023 over 300 deg" },
	{ "present_speed",       38, 2, R,  RAM, 0, 2047, NODEF, DXL_UNIT_SPEED,
	  "joint mode: measured speed; wheel mode: the output, 0.1 % a unit; bit 10 = CW" },
	{ "present_load",        40, 2, R,  RAM, 0, 2047, NODEF, DXL_UNIT_LOAD,
	  "load in 0.1 % of max torque, bit 10 = CW" },
	{ "present_voltage",     42, 1, R,  RAM, 0, 255, NODEF, DXL_UNIT_VOLTAGE, "supply voltage" },
	{ "present_temperature", 43, 1, R,  RAM, 0, 255, NODEF, DXL_UNIT_TEMPERATURE,
	  "internal temperature" },
	{ "registered",          44, 1, R,  RAM, 0, 1, 0, DXL_UNIT_BOOL,
	  "a REG_WRITE is waiting for ACTION" },
	{ "moving",              46, 1, R,  RAM, 0, 1, 0, DXL_UNIT_BOOL, "goal not reached yet" },
	{ "lock",                47, 1, RW, RAM, 0, 1, 0, DXL_UNIT_BOOL,
	  "1 locks the EEPROM area until power-cycle" },
	{ "punch",               48, 2, RW, RAM, 32, 1023, 32, DXL_UNIT_RAW,
	  "minimum drive current, 0x20-0x3FF (old manual: 0-1023)" },
};
const size_t dxl_ax12_nregs = sizeof dxl_ax12_regs / sizeof dxl_ax12_regs[0];

/* Registers whose range is narrower in joint mode than the table's max, which
 * is the wheel-mode range (e-manual, Moving Speed: 0-1023 in joint mode,
 * 0-2047 with bit 10 the direction in wheel mode). */
static const struct {
	uint8_t addr;
	uint16_t max;
} dxl_joint_mode_max[] = {
	{ DXL_AX_MOVING_SPEED, 1023 },
};

/* Short names people type at a prompt. */
static const struct {
	const char *alias, *name;
} dxl_reg_aliases[] = {
	{ "model", "model_number" },
	{ "firmware", "firmware_version" },
	{ "baud", "baud_rate" },
	{ "return_delay", "return_delay_time" },
	{ "cw_limit", "cw_angle_limit" },
	{ "ccw_limit", "ccw_angle_limit" },
	{ "max_temperature", "temperature_limit" },
	{ "min_voltage", "min_voltage_limit" },
	{ "max_voltage", "max_voltage_limit" },
	{ "return_level", "status_return_level" },
	{ "torque", "torque_enable" },
	{ "goal", "goal_position" },
	{ "speed", "present_speed" },
	{ "position", "present_position" },
	{ "load", "present_load" },
	{ "voltage", "present_voltage" },
	{ "temperature", "present_temperature" },
};

/* Names compare case-insensitively with '-' equal to '_'. */
static bool dxl_name_eq(const char *a, const char *b)
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

static const struct dxl_reg *dxl_reg_by_name(const char *name)
{
	for (size_t i = 0; i < dxl_ax12_nregs; i++)
		if (dxl_name_eq(dxl_ax12_regs[i].name, name))
			return &dxl_ax12_regs[i];
	for (size_t i = 0; i < sizeof dxl_reg_aliases / sizeof dxl_reg_aliases[0]; i++)
		if (dxl_name_eq(dxl_reg_aliases[i].alias, name))
			return dxl_reg_by_name(dxl_reg_aliases[i].name);
	return NULL;
}

const struct dxl_reg *dxl_reg_at(uint8_t addr)
{
	for (size_t i = 0; i < dxl_ax12_nregs; i++)
		if (dxl_ax12_regs[i].addr == addr)
			return &dxl_ax12_regs[i];
	return NULL;
}

const struct dxl_reg *dxl_reg_lookup(const char *name_or_addr)
{
	if (name_or_addr == NULL || *name_or_addr == '\0')
		return NULL;
	if (isdigit((unsigned char)name_or_addr[0])) {
		/* decimal, or hex with 0x; a leading 0 is not octal (addresses are
		 * written in decimal in the manual) */
		bool hex = name_or_addr[0] == '0' && (name_or_addr[1] == 'x' || name_or_addr[1] == 'X');
		char *end;
		errno = 0;
		unsigned long v = strtoul(name_or_addr, &end, hex ? 16 : 10);
		if (errno || *end != '\0' || v > 255)
			return NULL;
		return dxl_reg_at((uint8_t)v);
	}
	return dxl_reg_by_name(name_or_addr);
}

int dxl_reg_check_write(const struct dxl_reg *reg, long value)
{
	if (reg == NULL || reg->access != DXL_ACCESS_RW)
		return DXL_E_ARG;
	if (value < (long)reg->min || value > (long)reg->max)
		return DXL_E_ARG;
	return DXL_OK;
}

int dxl_reg_check_write_mode(const struct dxl_reg *reg, long value, bool wheel)
{
	if (dxl_reg_check_write(reg, value) != DXL_OK)
		return DXL_E_ARG;
	if (wheel)
		return DXL_OK;
	for (size_t i = 0; i < sizeof dxl_joint_mode_max / sizeof dxl_joint_mode_max[0]; i++)
		if (dxl_joint_mode_max[i].addr == reg->addr && value > (long)dxl_joint_mode_max[i].max)
			return DXL_E_ARG;
	return DXL_OK;
}

static const char *dxl_direction(uint16_t raw)
{
	if ((raw & 0x3FFu) == 0)
		return "";
	return (raw & DXL_DIRECTION_BIT) ? " CW" : " CCW";
}

static const char *dxl_status_level_name(uint16_t raw)
{
	switch (raw) {
	case 0:  return "ping only";
	case 1:  return "ping + read";
	case 2:  return "all";
	default: return "invalid";
	}
}

char *dxl_reg_format(const struct dxl_reg *reg, uint16_t raw, char *buf, size_t cap)
{
	if (buf == NULL || cap == 0)
		return buf;
	if (reg == NULL) {
		snprintf(buf, cap, "%u", raw);
		return buf;
	}
	char bits[96];
	unsigned mag = raw & 0x3FFu;
	switch (reg->unit) {
	case DXL_UNIT_POSITION:
		snprintf(buf, cap, "%u (%.1f deg)", raw, raw * DXL_POS_RANGE_DEG / DXL_POS_MAX);
		break;
	case DXL_UNIT_SPEED:
		snprintf(buf, cap, "%u (%.1f rpm%s)", raw, mag * DXL_SPEED_RPM_PER_UNIT, dxl_direction(raw));
		break;
	case DXL_UNIT_MOVING_SPEED:
		if (raw == 0)
			snprintf(buf, cap, "0 (maximum)");
		else if (raw > DXL_POS_MAX) /* wheel mode: direction bit */
			snprintf(buf, cap, "%u (%.1f rpm%s)", raw, mag * DXL_SPEED_RPM_PER_UNIT,
			         dxl_direction(raw));
		else
			snprintf(buf, cap, "%u (%.1f rpm)", raw, raw * DXL_SPEED_RPM_PER_UNIT);
		break;
	case DXL_UNIT_LOAD:
		snprintf(buf, cap, "%u (%.1f %%%s)", raw, mag * 0.1, dxl_direction(raw));
		break;
	case DXL_UNIT_TORQUE:
		snprintf(buf, cap, "%u (%.1f %%)", raw, raw * 0.1);
		break;
	case DXL_UNIT_VOLTAGE:
		snprintf(buf, cap, "%u (%.1f V)", raw, raw * 0.1);
		break;
	case DXL_UNIT_TEMPERATURE:
		snprintf(buf, cap, "%u (%u C)", raw, raw);
		break;
	case DXL_UNIT_BAUD:
		snprintf(buf, cap, "%u (%ld bps)", raw, dxl_baud_from_reg((uint8_t)raw));
		break;
	case DXL_UNIT_RETURN_DELAY:
		snprintf(buf, cap, "%u (%u us)", raw, dxl_return_delay_us((uint8_t)raw));
		break;
	case DXL_UNIT_BOOL:
		snprintf(buf, cap, "%u (%s)", raw, raw ? "on" : "off");
		break;
	case DXL_UNIT_ERRMASK:
		snprintf(buf, cap, "%u (%s)", raw, dxl_errbits_format((uint8_t)raw, bits, sizeof bits));
		break;
	case DXL_UNIT_STATUS_LEVEL:
		snprintf(buf, cap, "%u (%s)", raw, dxl_status_level_name(raw));
		break;
	case DXL_UNIT_RAW:
	default:
		snprintf(buf, cap, "%u", raw);
		break;
	}
	return buf;
}

/* ---- unit conversions ------------------------------------------------------ */

double dxl_pos_to_rad(uint16_t raw)
{
	return ((int)raw - DXL_POS_CENTER) * DXL_POS_RAD_PER_UNIT;
}

uint16_t dxl_rad_to_pos(double rad)
{
	if (!isfinite(rad))
		return DXL_POS_CENTER;
	double units = rad / DXL_POS_RAD_PER_UNIT + DXL_POS_CENTER;
	if (units <= 0.0)
		return 0;
	if (units >= DXL_POS_MAX)
		return DXL_POS_MAX;
	return (uint16_t)lround(units);
}

int dxl_speed_to_units(uint16_t raw)
{
	int mag = (int)(raw & 0x3FFu);
	return (raw & DXL_DIRECTION_BIT) ? -mag : mag;
}

uint16_t dxl_units_to_speed(int units)
{
	/* clamp before negating: -INT_MIN overflows */
	int mag = units < -1023 ? 1023 : units > 1023 ? 1023 : (units < 0 ? -units : units);
	return (uint16_t)(mag | (units < 0 ? DXL_DIRECTION_BIT : 0));
}

double dxl_speed_to_rad_s(uint16_t raw)
{
	return dxl_speed_to_units(raw) * DXL_SPEED_RAD_S_PER_UNIT;
}

uint16_t dxl_rad_s_to_speed(double rad_s)
{
	if (!isfinite(rad_s))
		return 0;
	double units = rad_s / DXL_SPEED_RAD_S_PER_UNIT;
	if (units > 1023.0)
		units = 1023.0;
	if (units < -1023.0)
		units = -1023.0;
	return dxl_units_to_speed((int)lround(units));
}

uint16_t dxl_duty_to_wheel(double duty)
{
	if (!isfinite(duty))
		return 0;
	return dxl_units_to_speed((int)lround(fmax(-1.0, fmin(1.0, duty)) * 1023.0));
}

uint16_t dxl_rad_s_to_moving_speed(double rad_s)
{
	/* 0 would mean "as fast as possible" — never produce it by rounding a slow
	 * request; NaN also gets the slowest speed, the safe side */
	if (isnan(rad_s))
		return 1;
	double units = fabs(rad_s) / DXL_SPEED_RAD_S_PER_UNIT;
	if (units >= 1023.0)
		return 1023;
	long v = lround(units);
	return (uint16_t)(v < 1 ? 1 : v);
}

double dxl_load_to_fraction(uint16_t raw)
{
	return dxl_speed_to_units(raw) * 0.001;
}

uint16_t dxl_fraction_to_load(double fraction)
{
	if (!isfinite(fraction))
		return 0;
	double units = fraction * 1000.0;
	if (units > 1023.0)
		units = 1023.0;
	if (units < -1023.0)
		units = -1023.0;
	return dxl_units_to_speed((int)lround(units));
}

double dxl_voltage_to_volts(uint8_t raw)
{
	return raw * 0.1;
}

/* The servo's clock divides 2 MHz by (v + 1); rounded to the nearest bps. */
#define DXL_BAUD_CLOCK 2000000L
/* Tolerance of a UART to a rate mismatch (the e-Manual's figure for 8N1). */
#define DXL_BAUD_TOLERANCE 0.03

long dxl_baud_from_reg(uint8_t v)
{
	long div = (long)v + 1;
	return (DXL_BAUD_CLOCK + div / 2) / div;
}

int dxl_baud_to_reg(long bps, uint8_t *v)
{
	if (bps <= 0 || v == NULL)
		return DXL_E_ARG;
	long guess = lround((double)DXL_BAUD_CLOCK / (double)bps) - 1;
	long best = -1;
	double best_err = 1e9;
	for (long c = guess - 1; c <= guess + 1; c++) {
		if (c < 0 || c > 254)
			continue;
		double err = fabs((double)dxl_baud_from_reg((uint8_t)c) - (double)bps) / (double)bps;
		if (err < best_err) {
			best_err = err;
			best = c;
		}
	}
	if (best < 0 || best_err > DXL_BAUD_TOLERANCE)
		return DXL_E_ARG;
	*v = (uint8_t)best;
	return DXL_OK;
}

unsigned dxl_return_delay_us(uint8_t v)
{
	return 2u * v;
}

bool dxl_is_wheel_mode(uint16_t cw_limit, uint16_t ccw_limit)
{
	return cw_limit == 0 && ccw_limit == 0;
}
