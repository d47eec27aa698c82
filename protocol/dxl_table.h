/*
 * dxl_table.h — the AX-12(A)'s addresses and unit conversions, and a view of
 * its control table as struct dxl_reg rows (8-bit addresses). The AX-12A's
 * model descriptor — rows, datasheet, capabilities — is in dxl2_table.h's
 * model list beside the X series'; the rows are written once, in
 * dxl_ax12_rows.h, and this view's lookup and checks are the descriptor's.
 */
#ifndef UNDULATE_DXL_TABLE_H
#define UNDULATE_DXL_TABLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Addresses (AX-12 manual). 16-bit values are little-endian; write both bytes
 * in one packet. */
enum dxl_ax12_addr {
	DXL_AX_MODEL_NUMBER        = 0,
	DXL_AX_FIRMWARE_VERSION    = 2,
	DXL_AX_ID                  = 3,
	DXL_AX_BAUD_RATE           = 4,
	DXL_AX_RETURN_DELAY_TIME   = 5,
	DXL_AX_CW_ANGLE_LIMIT      = 6,
	DXL_AX_CCW_ANGLE_LIMIT     = 8,
	DXL_AX_TEMPERATURE_LIMIT   = 11,
	DXL_AX_MIN_VOLTAGE_LIMIT   = 12,
	DXL_AX_MAX_VOLTAGE_LIMIT   = 13,
	DXL_AX_MAX_TORQUE          = 14,
	DXL_AX_STATUS_RETURN_LEVEL = 16,
	DXL_AX_ALARM_LED           = 17,
	DXL_AX_ALARM_SHUTDOWN      = 18,
	DXL_AX_TORQUE_ENABLE       = 24,
	DXL_AX_LED                 = 25,
	DXL_AX_CW_COMPLIANCE_MARGIN  = 26,
	DXL_AX_CCW_COMPLIANCE_MARGIN = 27,
	DXL_AX_CW_COMPLIANCE_SLOPE   = 28,
	DXL_AX_CCW_COMPLIANCE_SLOPE  = 29,
	DXL_AX_GOAL_POSITION       = 30,
	DXL_AX_MOVING_SPEED        = 32,
	DXL_AX_TORQUE_LIMIT        = 34,
	DXL_AX_PRESENT_POSITION    = 36,
	DXL_AX_PRESENT_SPEED       = 38,
	DXL_AX_PRESENT_LOAD        = 40,
	DXL_AX_PRESENT_VOLTAGE     = 42,
	DXL_AX_PRESENT_TEMPERATURE = 43,
	DXL_AX_REGISTERED          = 44,
	DXL_AX_MOVING              = 46,
	DXL_AX_LOCK                = 47,
	DXL_AX_PUNCH               = 48,
};
#define DXL_AX_TABLE_SIZE   50   /* bytes 0..49 */
#define DXL_AX_EEPROM_END   24   /* addresses below are EEPROM */
#define DXL_AX12_MODEL      12   /* model number of AX-12/AX-12+/AX-12A */
/* Its datasheet (stall torque, speed, rated supply) is its descriptor's:
 * dxl2_model_find(1, DXL_AX12_MODEL)->sheet (dxl2_table.c). */

enum dxl_access { DXL_ACCESS_R, DXL_ACCESS_RW };
enum dxl_area { DXL_AREA_EEPROM, DXL_AREA_RAM };

/* How a raw value is shown in physical units. */
enum dxl_unit {
	DXL_UNIT_RAW,          /* plain number */
	DXL_UNIT_POSITION,     /* 0.293°/unit, 512 = centre */
	DXL_UNIT_SPEED,        /* present speed: 0.111 rpm/unit, bit 10 = CW */
	DXL_UNIT_MOVING_SPEED, /* goal speed: 0.111 rpm/unit, 0 = maximum */
	DXL_UNIT_LOAD,         /* 0.1 %/unit of max torque, bit 10 = CW */
	DXL_UNIT_TORQUE,       /* 0.1 %/unit of max torque (limits) */
	DXL_UNIT_VOLTAGE,      /* 0.1 V/unit */
	DXL_UNIT_TEMPERATURE,  /* °C */
	DXL_UNIT_BAUD,         /* bps = 2e6 / (v + 1) */
	DXL_UNIT_RETURN_DELAY, /* 2 µs/unit */
	DXL_UNIT_BOOL,
	DXL_UNIT_ERRMASK,      /* error-bit mask: named bits */
	DXL_UNIT_STATUS_LEVEL, /* 0 ping only, 1 read, 2 all */
};

struct dxl_reg {
	const char *name;      /* lower_snake_case, e.g. "goal_position" */
	uint8_t addr;
	uint8_t size;          /* 1 or 2 bytes */
	enum dxl_access access;
	enum dxl_area area;
	uint16_t min, max;     /* valid range for writes (inclusive) */
	int32_t def;           /* factory default, or -1 when none (read-only/measured) */
	enum dxl_unit unit;
	const char *desc;      /* one line for `dxl dump` */
};

extern const struct dxl_reg dxl_ax12_regs[];
extern const size_t dxl_ax12_nregs;

/* Look up a register by name ("goal_position", case-insensitive, '-' == '_')
 * or by address given as a decimal/0x number string. NULL if unknown. */
const struct dxl_reg *dxl_reg_lookup(const char *name_or_addr);
/* The register that starts at addr, NULL if none (e.g. the high byte of a word). */
const struct dxl_reg *dxl_reg_at(uint8_t addr);
/* DXL_OK if value is writable into reg in some mode, else DXL_E_ARG
 * (read-only or out of range): the descriptor's dxl2_reg_check_write. */
int dxl_reg_check_write(const struct dxl_reg *reg, long value);
/* The same for a servo known to be in wheel mode (wheel) or joint mode: a few
 * registers have a narrower range in joint mode (moving speed: 0-1023 there,
 * 0-2047 in wheel mode). */
int dxl_reg_check_write_mode(const struct dxl_reg *reg, long value, bool wheel);
/* "512 (150.1 deg)"-style text for a raw value, with units. Returns buf. */
char *dxl_reg_format(const struct dxl_reg *reg, uint16_t raw, char *buf, size_t cap);

/* ---- unit conversions -------------------------------------------------------
 * Angles are radians relative to the centre (raw 512); positive is CCW, i.e.
 * towards larger raw positions. Speeds are rad/s, positive CCW. */
#define DXL_POS_CENTER      512
#define DXL_POS_MAX         1023
#define DXL_POS_RANGE_DEG   300.0                       /* 0..1023 spans 300° */
#define DXL_POS_RAD_PER_UNIT (DXL_POS_RANGE_DEG / 1023.0 * 3.14159265358979323846 / 180.0)
#define DXL_SPEED_RPM_PER_UNIT 0.111
#define DXL_SPEED_RAD_S_PER_UNIT (DXL_SPEED_RPM_PER_UNIT * 2.0 * 3.14159265358979323846 / 60.0)
#define DXL_DIRECTION_BIT   0x400u                     /* bit 10 of speed/load: CW */

double dxl_pos_to_rad(uint16_t raw);
/* Nearest raw position, clamped to 0..1023; non-finite input gives the centre. */
uint16_t dxl_rad_to_pos(double rad);
/* Present speed (raw with direction bit) <-> signed units / rad/s. */
int dxl_speed_to_units(uint16_t raw);       /* -1023..1023, positive CCW */
uint16_t dxl_units_to_speed(int units);     /* clamps magnitude to 1023 */
double dxl_speed_to_rad_s(uint16_t raw);
uint16_t dxl_rad_s_to_speed(double rad_s);
/* Goal moving speed (joint mode): rad/s magnitude -> 1..1023, 0 means "maximum". */
uint16_t dxl_rad_s_to_moving_speed(double rad_s);
/* Wheel mode's moving speed: signed output ratio in [-1, 1] (positive CCW)
 * -> 0..1023 with bit 10 for CW. Clamped; non-finite gives 0 (no drive). */
uint16_t dxl_duty_to_wheel(double duty);
/* Present load: signed fraction of max torque in [-1, 1], positive CCW. */
double dxl_load_to_fraction(uint16_t raw);
uint16_t dxl_fraction_to_load(double fraction);
double dxl_voltage_to_volts(uint8_t raw);
/* Baud register <-> bps: bps = 2 000 000 / (v + 1). */
long dxl_baud_from_reg(uint8_t v);
/* Register value whose rate is within 3 % of bps; DXL_E_ARG if none. */
int dxl_baud_to_reg(long bps, uint8_t *v);
/* Return delay register -> microseconds (2 µs/unit). */
unsigned dxl_return_delay_us(uint8_t v);
/* Both angle limits 0 means wheel mode (endless rotation). */
bool dxl_is_wheel_mode(uint16_t cw_limit, uint16_t ccw_limit);

#endif
