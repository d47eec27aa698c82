/*
 * test_protocol_table.c — the model descriptors (dxl2_table.h): the
 * AX-12A's control table (through its dxl_reg view) against the manual's
 * numbers (ax12.md), the X series' against the e-manual's XL430-W250 and
 * XM430-W350 pages (ROBOTIS-GIT/emanual docs/en/dxl/x/) — every address,
 * size, access and default typed in from the manuals, not read back from the
 * tables — one shape check run for every model in the list, lookup, write
 * checks, conversions and formatting.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

#include <cmocka.h>

#include "dxl.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "dxl_table.h"

#define PI 3.14159265358979323846

/* The AX-12A is a descriptor in the one model list, beside the X series:
 * protocol 1, its rows those of the dxl_reg view (the same numbers, one
 * written place), its datasheet the e-manual's, its capabilities asked of
 * the descriptor. */
static void test_ax12a_descriptor(void **state)
{
	(void)state;
	const struct dxl2_model *m = dxl2_model_by_number(DXL_AX12_MODEL);
	assert_non_null(m);
	assert_ptr_equal(dxl2_model_at(0), m);
	assert_ptr_equal(dxl2_model_by_name("ax-12a"), m);
	assert_ptr_equal(dxl2_model_find(1, DXL_AX12_MODEL), m);
	assert_null(dxl2_model_find(2, DXL_AX12_MODEL));
	assert_int_equal(m->protocol, 1);
	assert_string_equal(m->name, "AX-12A");
	assert_int_equal(m->nregs, dxl_ax12_nregs);
	for (size_t i = 0; i < m->nregs; i++) {
		const struct dxl_reg *v = &dxl_ax12_regs[i];
		const struct dxl2_reg *r = &m->regs[i];
		assert_string_equal(r->name, v->name);
		assert_int_equal(r->addr, v->addr);
		assert_int_equal(r->size, v->size);
		assert_false(r->is_signed);
		assert_int_equal(r->min, v->min);
		assert_int_equal(r->max, v->max);
		assert_int_equal(r->has_default, v->def >= 0);
		assert_ptr_equal(dxl2_reg_lookup(m, r->name), r);
	}
	/* aliases resolve to the model's own register */
	assert_int_equal(dxl2_reg_lookup(m, "speed")->addr, DXL_AX_PRESENT_SPEED);
	assert_int_equal(dxl2_reg_lookup(m, "voltage")->addr, DXL_AX_PRESENT_VOLTAGE);
	assert_null(dxl2_reg_lookup(m, "hardware_error_status"));
	/* datasheet: 1.5 N·m and 59 rpm at 12 V, 254:1, rated 9..12 V (11.1) */
	assert_true(m->sheet.stall_torque_nm == 1.5 && m->sheet.stall_current_a == 1.5);
	assert_true(m->sheet.no_load_speed_rpm == 59.0 && m->sheet.gear_ratio == 254.0);
	assert_true(m->sheet.rated_min_v == 9.0 && m->sheet.rated_rec_v == 11.1 && m->sheet.rated_max_v == 12.0);
	assert_true(fabs(dxl2_sheet_no_load_rad_s(&m->sheet) - 59.0 * 2.0 * PI / 60.0) < 1e-12);
	assert_int_equal(m->factory_baud, 1000000);
	/* capabilities: a wheel by its angle limits; no hardware error status,
	 * watchdog, reboot or operating mode */
	assert_true(dxl2_model_can(m, DXL2_CAP_WHEEL_BY_ANGLE_LIMITS));
	assert_false(dxl2_model_can(m, DXL2_CAP_HWERR_STATUS));
	assert_false(dxl2_model_can(m, DXL2_CAP_WATCHDOG));
	assert_false(dxl2_model_can(m, DXL2_CAP_REBOOT));
	assert_false(dxl2_model_can(m, DXL2_CAP_OPMODE));
	assert_int_equal(m->opmodes, 0);
	/* units: speed with its direction bit, 300 degrees, baud 2e6/(v+1) */
	char buf[64];
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 38), 0x400 | 100, buf, sizeof buf), "1124 (11.1 rpm CW)");
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 36), 1023, buf, sizeof buf), "1023 (300.0 deg)");
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 4), 1, buf, sizeof buf), "1 (1000000 bps)");
	/* Moving Speed: 0..1023 in joint mode, bit 10 allowed in wheel mode */
	const struct dxl2_reg *ms = dxl2_reg_at(m, DXL_AX_MOVING_SPEED);
	uint8_t joint[DXL_AX_TABLE_SIZE] = { 0 }, wheel[DXL_AX_TABLE_SIZE] = { 0 };
	joint[DXL_AX_CCW_ANGLE_LIMIT] = 0xFF;
	joint[DXL_AX_CCW_ANGLE_LIMIT + 1] = 3;
	assert_int_equal(dxl2_reg_check_write_live(m, ms, 1500, joint, sizeof joint), DXL_E_ARG);
	assert_int_equal(dxl2_reg_check_write_live(m, ms, 1023, joint, sizeof joint), DXL_OK);
	assert_int_equal(dxl2_reg_check_write_live(m, ms, 1500, wheel, sizeof wheel), DXL_OK);
	/* the X series' names leave it out */
	char names[128];
	assert_string_equal(dxl2_model_names(2, names, sizeof names), "XL430-W250, XM430-W350, XC430-W150");
	assert_string_equal(dxl2_model_names(1, names, sizeof names), "AX-12A");
}

static void test_lookup(void **state)
{
	(void)state;
	const struct dxl_reg *r = dxl_reg_lookup("goal_position");
	assert_non_null(r);
	assert_int_equal(r->addr, 30);
	assert_int_equal(r->size, 2);
	assert_ptr_equal(dxl_reg_lookup("Goal-Position"), r);
	assert_ptr_equal(dxl_reg_lookup("GOAL_POSITION"), r);
	assert_ptr_equal(dxl_reg_lookup("30"), r);
	assert_ptr_equal(dxl_reg_lookup("0x1e"), r);
	assert_ptr_equal(dxl_reg_lookup("0X1E"), r);
	assert_ptr_equal(dxl_reg_lookup("goal"), r);
	assert_ptr_equal(dxl_reg_at(30), r);
	/* aliases */
	assert_int_equal(dxl_reg_lookup("temperature")->addr, 43);
	assert_int_equal(dxl_reg_lookup("position")->addr, 36);
	assert_int_equal(dxl_reg_lookup("baud")->addr, 4);
	assert_int_equal(dxl_reg_lookup("return-delay")->addr, 5);
	assert_int_equal(dxl_reg_lookup("torque")->addr, 24);
	/* a leading zero is decimal, not octal */
	assert_int_equal(dxl_reg_lookup("030")->addr, 30);
	/* unknowns: a word's high byte, a gap, garbage, out of range */
	assert_null(dxl_reg_lookup("31"));
	assert_null(dxl_reg_at(31));
	assert_null(dxl_reg_lookup("10"));
	assert_null(dxl_reg_lookup("45"));
	assert_null(dxl_reg_lookup("nonsense"));
	assert_null(dxl_reg_lookup("30x"));
	assert_null(dxl_reg_lookup("256"));
	assert_null(dxl_reg_lookup(""));
	assert_null(dxl_reg_lookup(NULL));
	assert_null(dxl_reg_lookup("goal_positio"));
}

/* The table itself: every row inside the table, sorted, non-overlapping,
 * RAM from address 24, and every row findable by its own name. */
static void test_table_shape(void **state)
{
	(void)state;
	assert_int_equal(dxl_ax12_nregs, 32);
	int next_free = 0;
	for (size_t i = 0; i < dxl_ax12_nregs; i++) {
		const struct dxl_reg *r = &dxl_ax12_regs[i];
		assert_true(r->size == 1 || r->size == 2);
		assert_true(r->addr >= next_free);
		assert_true(r->addr + r->size <= DXL_AX_TABLE_SIZE);
		next_free = r->addr + r->size;
		assert_int_equal(r->area, r->addr < DXL_AX_EEPROM_END ? DXL_AREA_EEPROM : DXL_AREA_RAM);
		assert_ptr_equal(dxl_reg_lookup(r->name), r);
		assert_ptr_equal(dxl_reg_at(r->addr), r);
		assert_non_null(r->desc);
		assert_true(r->min <= r->max);
		if (r->size == 1)
			assert_true(r->max <= 255);
		if (r->def >= 0 && r->access == DXL_ACCESS_RW)
			assert_int_equal(dxl_reg_check_write(r, r->def), DXL_OK);
	}
}

/* Defaults and ranges from the manual. */
static void test_table_values(void **state)
{
	(void)state;
	static const struct {
		const char *name;
		uint8_t addr, size;
		enum dxl_access access;
		int32_t def;
	} rows[] = {
		{ "model_number", 0, 2, DXL_ACCESS_R, 12 },
		{ "id", 3, 1, DXL_ACCESS_RW, 1 },
		{ "baud_rate", 4, 1, DXL_ACCESS_RW, 1 },
		{ "return_delay_time", 5, 1, DXL_ACCESS_RW, 250 },
		{ "cw_angle_limit", 6, 2, DXL_ACCESS_RW, 0 },
		{ "ccw_angle_limit", 8, 2, DXL_ACCESS_RW, 1023 },
		{ "temperature_limit", 11, 1, DXL_ACCESS_RW, 70 },
		{ "min_voltage_limit", 12, 1, DXL_ACCESS_RW, 60 },
		{ "max_voltage_limit", 13, 1, DXL_ACCESS_RW, 140 },
		{ "max_torque", 14, 2, DXL_ACCESS_RW, 1023 },
		{ "status_return_level", 16, 1, DXL_ACCESS_RW, 2 },
		{ "alarm_led", 17, 1, DXL_ACCESS_RW, 36 },
		{ "alarm_shutdown", 18, 1, DXL_ACCESS_RW, 36 },
		{ "torque_enable", 24, 1, DXL_ACCESS_RW, 0 },
		{ "cw_compliance_slope", 28, 1, DXL_ACCESS_RW, 32 },
		{ "present_position", 36, 2, DXL_ACCESS_R, -1 },
		{ "present_load", 40, 2, DXL_ACCESS_R, -1 },
		{ "present_temperature", 43, 1, DXL_ACCESS_R, -1 },
		{ "registered", 44, 1, DXL_ACCESS_R, 0 },
		{ "lock", 47, 1, DXL_ACCESS_RW, 0 },
		{ "punch", 48, 2, DXL_ACCESS_RW, 32 },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		const struct dxl_reg *r = dxl_reg_lookup(rows[i].name);
		assert_non_null(r);
		assert_int_equal(r->addr, rows[i].addr);
		assert_int_equal(r->size, rows[i].size);
		assert_int_equal(r->access, rows[i].access);
		assert_int_equal(r->def, rows[i].def);
	}
}

static void test_check_write(void **state)
{
	(void)state;
	const struct dxl_reg *goal = dxl_reg_lookup("goal_position");
	assert_int_equal(dxl_reg_check_write(goal, 0), DXL_OK);
	assert_int_equal(dxl_reg_check_write(goal, 1023), DXL_OK);
	assert_int_equal(dxl_reg_check_write(goal, 1024), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(goal, -1), DXL_E_ARG);
	/* read-only registers refuse any value */
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("present_position"), 512), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("model_number"), 12), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("present_temperature"), 30), DXL_E_ARG);
	/* IDs: 253 is the largest, 254 is broadcast */
	const struct dxl_reg *id = dxl_reg_lookup("id");
	assert_int_equal(dxl_reg_check_write(id, 253), DXL_OK);
	assert_int_equal(dxl_reg_check_write(id, 254), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("status_return_level"), 3), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("torque_enable"), 2), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("alarm_shutdown"), 0x80), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("min_voltage_limit"), 49), DXL_E_ARG);
	/* the AX-12A e-manual's ranges where the original manual's were wider */
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("max_voltage_limit"), 160), DXL_OK);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("max_voltage_limit"), 161), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("temperature_limit"), 100), DXL_OK);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("temperature_limit"), 101), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("punch"), 0x1F), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("punch"), 0x20), DXL_OK);
	assert_int_equal(dxl_reg_check_write(dxl_reg_lookup("cw_compliance_slope"), 0), DXL_OK);
	/* moving speed: 0-2047 in wheel mode, 0-1023 in joint mode */
	const struct dxl_reg *ms = dxl_reg_lookup("moving_speed");
	assert_int_equal(dxl_reg_check_write(ms, 2047), DXL_OK);
	assert_int_equal(dxl_reg_check_write_mode(ms, 2047, true), DXL_OK);
	assert_int_equal(dxl_reg_check_write_mode(ms, 2048, true), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write_mode(ms, 1023, false), DXL_OK);
	assert_int_equal(dxl_reg_check_write_mode(ms, 1024, false), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write_mode(goal, 1023, false), DXL_OK);
	assert_int_equal(dxl_reg_check_write_mode(goal, 1024, true), DXL_E_ARG);
	assert_int_equal(dxl_reg_check_write(NULL, 0), DXL_E_ARG);
}

static void test_position(void **state)
{
	(void)state;
	assert_true(fabs(dxl_pos_to_rad(512)) < 1e-12);
	/* 0..1023 spans 300°: 0 is -512 units, 1023 is +511 units */
	assert_true(fabs(dxl_pos_to_rad(0) - (-512.0 * 300.0 / 1023.0 * PI / 180.0)) < 1e-12);
	assert_true(fabs(dxl_pos_to_rad(1023) - (511.0 * 300.0 / 1023.0 * PI / 180.0)) < 1e-12);
	assert_true(fabs(dxl_pos_to_rad(0) - (-2.6205)) < 1e-3);
	assert_int_equal(dxl_rad_to_pos(0.0), 512);
	for (unsigned raw = 0; raw <= 1023; raw++)
		assert_int_equal(dxl_rad_to_pos(dxl_pos_to_rad((uint16_t)raw)), raw);
	assert_int_equal(dxl_rad_to_pos(100.0), 1023);
	assert_int_equal(dxl_rad_to_pos(-100.0), 0);
	assert_int_equal(dxl_rad_to_pos(NAN), 512);
	assert_int_equal(dxl_rad_to_pos(INFINITY), 512);
	/* positive is CCW, toward larger raw values */
	assert_true(dxl_rad_to_pos(0.1) > 512);
}

static void test_speed_and_load(void **state)
{
	(void)state;
	/* bit 10 is the direction: set = CW = negative */
	assert_int_equal(dxl_speed_to_units(100), 100);
	assert_int_equal(dxl_speed_to_units(0x400 | 100), -100);
	assert_int_equal(dxl_speed_to_units(0x400), 0);
	assert_int_equal(dxl_units_to_speed(-100), 0x400 | 100);
	assert_int_equal(dxl_units_to_speed(100), 100);
	assert_int_equal(dxl_units_to_speed(5000), 1023);
	assert_int_equal(dxl_units_to_speed(-5000), 0x400 | 1023);
	assert_int_equal(dxl_units_to_speed(-2147483647 - 1), 0x400 | 1023);
	double rpm_unit = 0.111 * 2.0 * PI / 60.0;
	assert_true(fabs(dxl_speed_to_rad_s(1023) - 1023 * rpm_unit) < 1e-9);
	assert_true(fabs(dxl_speed_to_rad_s(0x400 | 1023) + 1023 * rpm_unit) < 1e-9);
	assert_int_equal(dxl_rad_s_to_speed(-100 * rpm_unit), 0x400 | 100);
	assert_int_equal(dxl_rad_s_to_speed(NAN), 0);
	/* moving speed: never 0 (= maximum) by rounding a slow request */
	assert_int_equal(dxl_rad_s_to_moving_speed(0.0), 1);
	assert_int_equal(dxl_rad_s_to_moving_speed(200 * rpm_unit), 200);
	assert_int_equal(dxl_rad_s_to_moving_speed(-200 * rpm_unit), 200);
	assert_int_equal(dxl_rad_s_to_moving_speed(1e9), 1023);
	assert_int_equal(dxl_rad_s_to_moving_speed(NAN), 1);
	/* wheel mode output ratio: bit 10 = CW = negative, clamped, NaN = no drive */
	assert_int_equal(dxl_duty_to_wheel(0.5), 512);
	assert_int_equal(dxl_duty_to_wheel(-0.5), 0x400 | 512);
	assert_int_equal(dxl_duty_to_wheel(3.0), 1023);
	assert_int_equal(dxl_duty_to_wheel(-3.0), 0x400 | 1023);
	assert_int_equal(dxl_duty_to_wheel(NAN), 0);
	assert_int_equal(dxl_duty_to_wheel(-INFINITY), 0);
	/* load: 0.1 % a unit, bit 10 = CW */
	assert_true(fabs(dxl_load_to_fraction(500) - 0.5) < 1e-12);
	assert_true(fabs(dxl_load_to_fraction(0x400 | 500) + 0.5) < 1e-12);
	assert_int_equal(dxl_fraction_to_load(-0.25), 0x400 | 250);
	assert_int_equal(dxl_fraction_to_load(2.0), 1023);
	assert_int_equal(dxl_fraction_to_load(NAN), 0);
}

static void test_voltage_baud_delay(void **state)
{
	(void)state;
	assert_true(fabs(dxl_voltage_to_volts(120) - 12.0) < 1e-9);
	assert_true(fabs(dxl_voltage_to_volts(95) - 9.5) < 1e-9);
	assert_int_equal(dxl_baud_from_reg(1), 1000000);
	assert_int_equal(dxl_baud_from_reg(3), 500000);
	assert_int_equal(dxl_baud_from_reg(16), 117647);
	assert_int_equal(dxl_baud_from_reg(34), 57143);
	assert_int_equal(dxl_baud_from_reg(103), 19231);
	assert_int_equal(dxl_baud_from_reg(207), 9615);
	uint8_t v = 0;
	assert_int_equal(dxl_baud_to_reg(1000000, &v), DXL_OK);
	assert_int_equal(v, 1);
	assert_int_equal(dxl_baud_to_reg(57600, &v), DXL_OK);
	assert_int_equal(v, 34);
	assert_int_equal(dxl_baud_to_reg(115200, &v), DXL_OK);
	assert_int_equal(v, 16);
	assert_int_equal(dxl_baud_to_reg(9600, &v), DXL_OK);
	assert_int_equal(v, 207);
	assert_int_equal(dxl_baud_to_reg(2000000, &v), DXL_OK);
	assert_int_equal(v, 0);
	/* no register value within 3 % */
	assert_int_equal(dxl_baud_to_reg(750000, &v), DXL_E_ARG);
	assert_int_equal(dxl_baud_to_reg(3000000, &v), DXL_E_ARG);
	assert_int_equal(dxl_baud_to_reg(0, &v), DXL_E_ARG);
	assert_int_equal(dxl_baud_to_reg(100, &v), DXL_E_ARG);
	assert_int_equal(dxl_return_delay_us(250), 500);
	assert_int_equal(dxl_return_delay_us(0), 0);
	assert_true(dxl_is_wheel_mode(0, 0));
	assert_false(dxl_is_wheel_mode(0, 1023));
}

static void test_format(void **state)
{
	(void)state;
	char buf[96];
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("goal_position"), 512, buf, sizeof buf),
	                    "512 (150.1 deg)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("baud_rate"), 34, buf, sizeof buf),
	                    "34 (57143 bps)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("return_delay_time"), 250, buf, sizeof buf),
	                    "250 (500 us)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("present_voltage"), 121, buf, sizeof buf),
	                    "121 (12.1 V)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("present_speed"), 0x400 | 100, buf,
	                                   sizeof buf), "1124 (11.1 rpm CW)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("present_load"), 250, buf, sizeof buf),
	                    "250 (25.0 % CCW)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("moving_speed"), 0, buf, sizeof buf),
	                    "0 (maximum)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("alarm_shutdown"), 36, buf, sizeof buf),
	                    "36 (overheating|overload)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("status_return_level"), 1, buf, sizeof buf),
	                    "1 (ping + read)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("torque_enable"), 1, buf, sizeof buf),
	                    "1 (on)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("present_temperature"), 32, buf,
	                                   sizeof buf), "32 (32 C)");
	assert_string_equal(dxl_reg_format(dxl_reg_lookup("id"), 7, buf, sizeof buf), "7");
	/* a short buffer stays terminated */
	dxl_reg_format(dxl_reg_lookup("goal_position"), 512, buf, 5);
	assert_string_equal(buf, "512 ");
}

struct row {
	const char *name;
	uint16_t addr;
	uint8_t size;
	enum dxl_access access;
	int32_t def;       /* INT32_MIN: none printed */
	int32_t min, max;  /* write range; unused for R */
};
#define NONE INT32_MIN

/* The registers the daemon, the simulator and `dxl` will use. */
static const struct row xl430[] = {
	{ "model_number", 0, 2, DXL_ACCESS_R, 1060, 0, 0 },
	{ "firmware_version", 6, 1, DXL_ACCESS_R, NONE, 0, 0 },
	{ "id", 7, 1, DXL_ACCESS_RW, 1, 0, 252 },
	{ "baud_rate", 8, 1, DXL_ACCESS_RW, 1, 0, 7 },
	{ "return_delay_time", 9, 1, DXL_ACCESS_RW, 250, 0, 254 },
	{ "operating_mode", 11, 1, DXL_ACCESS_RW, 3, 0, 16 },
	{ "temperature_limit", 31, 1, DXL_ACCESS_RW, 72, 0, 100 },
	{ "max_voltage_limit", 32, 2, DXL_ACCESS_RW, 140, 60, 140 },
	{ "min_voltage_limit", 34, 2, DXL_ACCESS_RW, 60, 60, 140 },
	{ "pwm_limit", 36, 2, DXL_ACCESS_RW, 885, 0, 885 },
	{ "velocity_limit", 44, 4, DXL_ACCESS_RW, 265, 0, 1023 },
	{ "max_position_limit", 48, 4, DXL_ACCESS_RW, 4095, 0, 4095 },
	{ "min_position_limit", 52, 4, DXL_ACCESS_RW, 0, 0, 4095 },
	{ "shutdown", 63, 1, DXL_ACCESS_RW, 52, 0, 0x3D },
	{ "torque_enable", 64, 1, DXL_ACCESS_RW, 0, 0, 1 },
	{ "led", 65, 1, DXL_ACCESS_RW, 0, 0, 1 },
	{ "status_return_level", 68, 1, DXL_ACCESS_RW, 2, 0, 2 },
	{ "hardware_error_status", 70, 1, DXL_ACCESS_R, 0, 0, 0 },
	{ "position_p_gain", 84, 2, DXL_ACCESS_RW, 640, 0, 16383 },
	{ "bus_watchdog", 98, 1, DXL_ACCESS_RW, 0, 0, 127 },
	{ "goal_pwm", 100, 2, DXL_ACCESS_RW, NONE, -885, 885 },
	{ "goal_velocity", 104, 4, DXL_ACCESS_RW, NONE, -1023, 1023 },
	{ "profile_velocity", 112, 4, DXL_ACCESS_RW, 0, 0, 32767 },
	{ "goal_position", 116, 4, DXL_ACCESS_RW, NONE, -1048575, 1048575 },
	{ "moving", 122, 1, DXL_ACCESS_R, 0, 0, 0 },
	{ "present_pwm", 124, 2, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_load", 126, 2, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_velocity", 128, 4, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_position", 132, 4, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_input_voltage", 144, 2, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_temperature", 146, 1, DXL_ACCESS_R, NONE, 0, 0 },
};
static const struct row xm430[] = {
	{ "model_number", 0, 2, DXL_ACCESS_R, 1020, 0, 0 },
	{ "id", 7, 1, DXL_ACCESS_RW, 1, 0, 252 },
	{ "return_delay_time", 9, 1, DXL_ACCESS_RW, 250, 0, 254 },
	{ "operating_mode", 11, 1, DXL_ACCESS_RW, 3, 0, 16 },
	{ "temperature_limit", 31, 1, DXL_ACCESS_RW, 80, 0, 100 },
	{ "max_voltage_limit", 32, 2, DXL_ACCESS_RW, 160, 95, 160 },
	{ "min_voltage_limit", 34, 2, DXL_ACCESS_RW, 95, 95, 160 },
	{ "pwm_limit", 36, 2, DXL_ACCESS_RW, 885, 0, 885 },
	{ "current_limit", 38, 2, DXL_ACCESS_RW, 1193, 0, 1193 },
	{ "velocity_limit", 44, 4, DXL_ACCESS_RW, 200, 0, 1023 },
	{ "max_position_limit", 48, 4, DXL_ACCESS_RW, 4095, 0, 4095 },
	{ "min_position_limit", 52, 4, DXL_ACCESS_RW, 0, 0, 4095 },
	{ "shutdown", 63, 1, DXL_ACCESS_RW, 52, 0, 0x3D },
	{ "torque_enable", 64, 1, DXL_ACCESS_RW, 0, 0, 1 },
	{ "status_return_level", 68, 1, DXL_ACCESS_RW, 2, 0, 2 },
	{ "hardware_error_status", 70, 1, DXL_ACCESS_R, 0, 0, 0 },
	{ "position_p_gain", 84, 2, DXL_ACCESS_RW, 800, 0, 16383 },
	{ "bus_watchdog", 98, 1, DXL_ACCESS_RW, 0, 0, 127 },
	{ "goal_pwm", 100, 2, DXL_ACCESS_RW, NONE, -885, 885 },
	{ "goal_current", 102, 2, DXL_ACCESS_RW, NONE, -1193, 1193 },
	{ "goal_velocity", 104, 4, DXL_ACCESS_RW, NONE, -1023, 1023 },
	{ "goal_position", 116, 4, DXL_ACCESS_RW, NONE, -1048575, 1048575 },
	{ "present_current", 126, 2, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_velocity", 128, 4, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_position", 132, 4, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_input_voltage", 144, 2, DXL_ACCESS_R, NONE, 0, 0 },
	{ "present_temperature", 146, 1, DXL_ACCESS_R, NONE, 0, 0 },
};

static void check_rows(const struct dxl2_model *m, const struct row *rows, size_t n)
{
	assert_non_null(m);
	for (size_t i = 0; i < n; i++) {
		const struct row *w = &rows[i];
		const struct dxl2_reg *r = dxl2_reg_lookup(m, w->name);
		print_message("# %s %s\n", m->name, w->name);
		assert_non_null(r);
		assert_int_equal(r->addr, w->addr);
		assert_int_equal(r->size, w->size);
		assert_int_equal(r->access, w->access);
		assert_int_equal(r->has_default, w->def != NONE);
		if (w->def != NONE)
			assert_int_equal(r->def, w->def);
		assert_int_equal(r->area, w->addr < 64 ? DXL_AREA_EEPROM : DXL_AREA_RAM);
		if (w->access == DXL_ACCESS_RW) {
			assert_int_equal(r->min, w->min);
			assert_int_equal(r->max, w->max);
		}
	}
}

static void test_x_manual_rows(void **state)
{
	(void)state;
	check_rows(dxl2_model_by_number(1060), xl430, sizeof xl430 / sizeof xl430[0]);
	check_rows(dxl2_model_by_number(1020), xm430, sizeof xm430 / sizeof xm430[0]);
	/* what one model has and the other has not */
	const struct dxl2_model *xl = dxl2_model_by_name("xl430-w250");
	const struct dxl2_model *xm = dxl2_model_by_name("XM430-W350");
	assert_null(dxl2_reg_lookup(xl, "goal_current"));
	assert_null(dxl2_reg_lookup(xl, "current_limit"));
	assert_null(dxl2_reg_lookup(xm, "present_load"));
	assert_string_equal(dxl2_reg_at(xl, 126)->name, "present_load");
	assert_string_equal(dxl2_reg_at(xm, 126)->name, "present_current");
	/* the AX-12A (12) is in the list, but no X model */
	assert_null(dxl2_model_find(2, 12));
	assert_null(dxl2_model_by_name("AX-12"));
}

/* Every model's rows, one body for the whole list (the AX-12A and the X
 * series): inside the described table, sorted, non-overlapping, findable by
 * name and address, defaults writable, unsigned ranges within their bytes. */
static const struct {
	uint16_t number;
	int protocol;
	size_t table_size;
} described[] = {
	{ 12, 1, DXL_AX_TABLE_SIZE },
	{ DXL2_MODEL_XL430_W250, 2, DXL2_X_TABLE_SIZE },
	{ DXL2_MODEL_XM430_W350, 2, DXL2_X_TABLE_SIZE },
	{ DXL2_MODEL_XC430_W150, 2, DXL2_X_TABLE_SIZE },
};

static void test_table_shape_every_model(void **state)
{
	(void)state;
	assert_int_equal(dxl2_model_count(), sizeof described / sizeof described[0]);
	for (size_t k = 0; k < dxl2_model_count(); k++) {
		const struct dxl2_model *m = dxl2_model_at(k);
		print_message("# %s\n", m->name);
		assert_int_equal(m->number, described[k].number);
		assert_int_equal(m->protocol, described[k].protocol);
		assert_ptr_equal(dxl2_model_find(m->protocol, m->number), m);
		int next_free = 0;
		for (size_t i = 0; i < m->nregs; i++) {
			const struct dxl2_reg *r = &m->regs[i];
			assert_true(r->size == 1 || r->size == 2 || r->size == 4);
			assert_true(r->addr >= next_free);
			assert_true(r->addr + r->size <= described[k].table_size);
			next_free = r->addr + r->size;
			assert_ptr_equal(dxl2_reg_lookup(m, r->name), r);
			assert_ptr_equal(dxl2_reg_at(m, r->addr), r);
			assert_non_null(r->desc);
			assert_true(r->min <= r->max);
			if (r->access == DXL_ACCESS_RW && r->has_default)
				assert_int_equal(dxl2_reg_check_write(m, r, r->def), DXL_OK);
			if (r->access == DXL_ACCESS_RW && r->size < 4 && !r->is_signed)
				assert_true(r->max < (1L << (8 * r->size)));
		}
	}
}

static void test_x_lookup(void **state)
{
	(void)state;
	const struct dxl2_model *m = dxl2_model_by_number(DXL2_MODEL_XM430_W350);
	const struct dxl2_reg *r = dxl2_reg_lookup(m, "present_position");
	assert_int_equal(r->addr, 132);
	assert_ptr_equal(dxl2_reg_lookup(m, "Present-Position"), r);
	assert_ptr_equal(dxl2_reg_lookup(m, "132"), r);
	assert_ptr_equal(dxl2_reg_lookup(m, "0x84"), r);
	assert_ptr_equal(dxl2_reg_lookup(m, "position"), r);
	assert_int_equal(dxl2_reg_lookup(m, "goal")->addr, 116);
	assert_int_equal(dxl2_reg_lookup(m, "current")->addr, 126);
	assert_int_equal(dxl2_reg_lookup(m, "torque")->addr, 64);
	assert_int_equal(dxl2_reg_lookup(m, "watchdog")->addr, 98);
	assert_int_equal(dxl2_reg_lookup(m, "0116")->addr, 116);  /* decimal, not octal */
	assert_null(dxl2_reg_lookup(m, "133"));     /* inside a register */
	assert_null(dxl2_reg_lookup(m, "14"));      /* a gap */
	/* the indirect areas (e-manual): addresses 168.. and 578.., 64..661,
	 * each Indirect Data n's own address at the factory; data 224.., 634.. */
	r = dxl2_reg_lookup(m, "168");
	assert_non_null(r);
	assert_string_equal(r->name, "indirect_address_1");
	assert_int_equal(r->size, 2);
	assert_int_equal(r->def, 224);
	assert_int_equal(r->min, 64);
	assert_int_equal(r->max, 661);
	assert_int_equal(r->area, DXL_AREA_EEPROM);
	assert_int_equal(dxl2_reg_lookup(m, "indirect_address_29")->addr, 578);
	assert_int_equal(dxl2_reg_lookup(m, "indirect_address_29")->def, 634);
	assert_int_equal(dxl2_reg_lookup(m, "indirect_data_28")->addr, 251);
	assert_int_equal(dxl2_reg_lookup(m, "661")->size, 1);
	assert_string_equal(dxl2_reg_lookup(m, "661")->name, "indirect_data_56");
	assert_null(dxl2_reg_lookup(m, "252"));     /* a gap between the blocks */
	assert_null(dxl2_reg_lookup(m, "662"));
	assert_true(dxl2_model_can(m, DXL2_CAP_INDIRECT));
	assert_int_equal(dxl2_indirect_slot(224), 1);
	assert_int_equal(dxl2_indirect_slot(251), 28);
	assert_int_equal(dxl2_indirect_slot(634), 29);
	assert_int_equal(dxl2_indirect_slot(661), 56);
	assert_int_equal(dxl2_indirect_slot(223), 0);
	assert_int_equal(dxl2_indirect_slot(252), 0);
	assert_int_equal(dxl2_indirect_address_reg(29), 578);
	assert_int_equal(dxl2_indirect_data_addr(56), 661);
	assert_int_equal(dxl2_indirect_data_addr(57), 0);
	assert_null(dxl2_reg_lookup(m, "65536"));
	assert_null(dxl2_reg_lookup(m, "nonsense"));
	assert_null(dxl2_reg_lookup(m, ""));
	assert_null(dxl2_reg_lookup(NULL, "id"));
}

static void test_x_decode_encode(void **state)
{
	(void)state;
	const struct dxl2_model *m = dxl2_model_by_number(DXL2_MODEL_XM430_W350);
	uint8_t b[4];
	const struct dxl2_reg *vel = dxl2_reg_at(m, 128), *cur = dxl2_reg_at(m, 126), *volt = dxl2_reg_at(m, 144);
	/* e-manual Read example: Present Position 166 = A6 00 00 00 */
	const uint8_t pos166[4] = { 0xA6, 0x00, 0x00, 0x00 };
	assert_int_equal(dxl2_reg_decode(dxl2_reg_at(m, 132), pos166), 166);
	dxl2_reg_encode(vel, -100, b);
	assert_memory_equal(b, ((const uint8_t[]){ 0x9C, 0xFF, 0xFF, 0xFF }), 4);
	assert_int_equal(dxl2_reg_decode(vel, b), -100);
	dxl2_reg_encode(cur, -1193, b);
	assert_int_equal(b[0] | (b[1] << 8), 0x10000 - 1193);
	assert_int_equal(dxl2_reg_decode(cur, b), -1193);
	/* unsigned 2-byte: 0xFFFF stays 65535 */
	b[0] = b[1] = 0xFF;
	assert_int_equal(dxl2_reg_decode(volt, b), 65535);
}

static void test_x_write_checks(void **state)
{
	(void)state;
	const struct dxl2_model *xl = dxl2_model_by_number(DXL2_MODEL_XL430_W250);
	const struct dxl2_model *xm = dxl2_model_by_number(DXL2_MODEL_XM430_W350);
	const struct dxl2_reg *mode_xl = dxl2_reg_at(xl, 11), *mode_xm = dxl2_reg_at(xm, 11);
	/* read-only, out of range */
	assert_int_equal(dxl2_reg_check_write(xm, dxl2_reg_at(xm, 132), 0), DXL_E_ARG);
	assert_int_equal(dxl2_reg_check_write(xm, dxl2_reg_at(xm, 7), 252), DXL_OK);
	assert_int_equal(dxl2_reg_check_write(xm, dxl2_reg_at(xm, 7), 253), DXL_E_ARG);
	assert_int_equal(dxl2_reg_check_write(xm, dxl2_reg_at(xm, 8), 8), DXL_E_ARG);
	assert_int_equal(dxl2_reg_check_write(xm, dxl2_reg_at(xm, 32), 94), DXL_E_ARG);
	/* operating modes: the XL430 has no current modes */
	static const struct { uint8_t mode; int xl, xm; } modes[] = {
		{ 0, DXL_E_ARG, DXL_OK }, { 1, DXL_OK, DXL_OK }, { 2, DXL_E_ARG, DXL_E_ARG },
		{ 3, DXL_OK, DXL_OK }, { 4, DXL_OK, DXL_OK }, { 5, DXL_E_ARG, DXL_OK },
		{ 15, DXL_E_ARG, DXL_E_ARG }, { 16, DXL_OK, DXL_OK },
	};
	for (size_t i = 0; i < sizeof modes / sizeof modes[0]; i++) {
		assert_int_equal(dxl2_reg_check_write(xl, mode_xl, modes[i].mode), modes[i].xl);
		assert_int_equal(dxl2_reg_check_write(xm, mode_xm, modes[i].mode), modes[i].xm);
	}
	/* live ranges from an image of the control table */
	uint8_t table[DXL2_X_TABLE_SIZE] = { 0 };
	table[DXL2_X_OPERATING_MODE] = DXL2_OPMODE_POSITION;
	dxl2_put_u32(table + DXL2_X_MIN_POSITION_LIMIT, 1024);
	dxl2_put_u32(table + DXL2_X_MAX_POSITION_LIMIT, 3072);
	table[DXL2_X_CURRENT_LIMIT] = 0xF4;   /* 500 */
	table[DXL2_X_CURRENT_LIMIT + 1] = 0x01;
	const struct dxl2_reg *goal = dxl2_reg_at(xm, 116), *gcur = dxl2_reg_at(xm, 102);
	int32_t lo, hi;
	assert_int_equal(dxl2_reg_range(xm, goal, table, sizeof table, &lo, &hi), DXL_OK);
	assert_int_equal(lo, 1024);
	assert_int_equal(hi, 3072);
	assert_int_equal(dxl2_reg_check_write_live(xm, goal, 3072, table, sizeof table), DXL_OK);
	assert_int_equal(dxl2_reg_check_write_live(xm, goal, 3073, table, sizeof table), DXL_E_ARG);
	assert_int_equal(dxl2_reg_check_write_live(xm, goal, 1023, table, sizeof table), DXL_E_ARG);
	/* extended position mode: the limits do not bind */
	table[DXL2_X_OPERATING_MODE] = DXL2_OPMODE_EXTENDED_POSITION;
	assert_int_equal(dxl2_reg_check_write_live(xm, goal, -5000, table, sizeof table), DXL_OK);
	assert_int_equal(dxl2_reg_check_write_live(xm, goal, 1048576, table, sizeof table), DXL_E_ARG);
	assert_int_equal(dxl2_reg_check_write_live(xm, gcur, -500, table, sizeof table), DXL_OK);
	assert_int_equal(dxl2_reg_check_write_live(xm, gcur, 501, table, sizeof table), DXL_E_ARG);
	/* an image too short for the limit: the static range */
	assert_int_equal(dxl2_reg_check_write_live(xm, gcur, 1193, table, 38), DXL_OK);
	assert_int_equal(dxl2_reg_check_write_live(xm, gcur, 1194, table, 38), DXL_E_ARG);
	/* which refusals are the limit's (data limit) and which the row's own
	 * range (data range): a goal whose limit register is in the image */
	assert_true(dxl2_reg_limit_binds(xm, gcur, table, sizeof table));
	assert_false(dxl2_reg_limit_binds(xm, gcur, table, 38));
	assert_false(dxl2_reg_limit_binds(xm, goal, table, sizeof table));   /* extended mode */
	table[DXL2_X_OPERATING_MODE] = DXL2_OPMODE_POSITION;
	assert_true(dxl2_reg_limit_binds(xm, goal, table, sizeof table));
	assert_false(dxl2_reg_limit_binds(xm, dxl2_reg_at(xm, DXL2_X_CURRENT_LIMIT), table, sizeof table));
}

static void test_x_conversions(void **state)
{
	(void)state;
	const double pi = DXL2_PI;
	assert_float_equal(dxl2_pos_to_rad(2048), 0.0, 1e-12);
	assert_float_equal(dxl2_pos_to_rad(3072), pi / 2, 1e-12);   /* 1024 pulses = 90 deg */
	assert_float_equal(dxl2_pos_to_rad(0), -pi, 1e-12);
	assert_int_equal(dxl2_rad_to_pos(0.0), 2048);
	assert_int_equal(dxl2_rad_to_pos(-pi / 2), 1024);
	assert_int_equal(dxl2_rad_to_pos(10.0), 4095);
	assert_int_equal(dxl2_rad_to_pos(-10.0), 0);
	assert_int_equal(dxl2_rad_to_pos(NAN), 2048);
	for (int32_t raw = 0; raw <= 4095; raw += 7)
		assert_int_equal(dxl2_rad_to_pos(dxl2_pos_to_rad(raw)), raw);
	/* 0.229 rpm a unit: 100 units = 22.9 rpm = 2.398 rad/s */
	assert_float_equal(dxl2_velocity_to_rad_s(100), 22.9 * 2 * pi / 60, 1e-9);
	assert_float_equal(dxl2_velocity_to_rad_s(-100), -22.9 * 2 * pi / 60, 1e-9);
	assert_int_equal(dxl2_rad_s_to_velocity(22.9 * 2 * pi / 60, 1023), 100);
	assert_int_equal(dxl2_rad_s_to_velocity(1e6, 200), 200);
	assert_int_equal(dxl2_rad_s_to_velocity(-1e6, 200), -200);
	assert_int_equal(dxl2_rad_s_to_velocity(NAN, 200), 0);
	/* 2.69 mA a unit: 1193 = 3.209 A */
	assert_float_equal(dxl2_current_to_amps(1193), 3.20917, 1e-5);
	assert_int_equal(dxl2_amps_to_current(-1.0, 1193), -372);
	assert_int_equal(dxl2_amps_to_current(100.0, 1193), 1193);
	assert_float_equal(dxl2_load_to_fraction(-1000), -1.0, 1e-12);
	assert_float_equal(dxl2_pwm_to_fraction(885), 1.00005, 1e-9);
	assert_float_equal(dxl2_voltage_to_volts(119), 11.9, 1e-9);   /* Bulk Read example */
	assert_int_equal(dxl2_baud_from_reg(1), 57600);
	assert_int_equal(dxl2_baud_from_reg(3), 1000000);
	assert_int_equal(dxl2_baud_from_reg(7), 4500000);
	assert_int_equal(dxl2_baud_from_reg(8), -1);
	uint8_t v = 99;
	assert_int_equal(dxl2_baud_to_reg(1000000, &v), DXL_OK);
	assert_int_equal(v, 3);
	assert_int_equal(dxl2_baud_to_reg(57142, &v), DXL_OK);   /* within 3 % of 57600 */
	assert_int_equal(v, 1);
	assert_int_equal(dxl2_baud_to_reg(500000, &v), DXL_E_ARG);
	assert_int_equal(dxl2_return_delay_us(250), 500);
	assert_int_equal(dxl2_watchdog_ms(5), 100);
}

static void test_x_format(void **state)
{
	(void)state;
	const struct dxl2_model *m = dxl2_model_by_number(DXL2_MODEL_XM430_W350);
	char buf[96];
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 132), 2048, buf, sizeof buf), "2048 (180.0 deg)");
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 128), -100, buf, sizeof buf), "-100 (-22.9 rpm)");
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 126), 100, buf, sizeof buf), "100 (269 mA)");
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 8), 3, buf, sizeof buf), "3 (1000000 bps)");
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 11), 3, buf, sizeof buf), "3 (position)");
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 98), 0, buf, sizeof buf), "0 (off)");
	assert_string_equal(dxl2_reg_format(dxl2_reg_at(m, 63), 52, buf, sizeof buf),
	                    "52 (overheating|electrical shock|overload)");
	assert_string_equal(dxl2_hwerr_format(0x09, buf, sizeof buf), "input voltage|motor encoder");
	assert_string_equal(dxl2_hwerr_format(0x42, buf, sizeof buf), "bit1|bit6");
	assert_string_equal(dxl2_hwerr_format(0, buf, sizeof buf), "none");
	assert_null(dxl2_opmode_name(2));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ax12a_descriptor),
		cmocka_unit_test(test_lookup),
		cmocka_unit_test(test_table_shape),
		cmocka_unit_test(test_table_values),
		cmocka_unit_test(test_check_write),
		cmocka_unit_test(test_position),
		cmocka_unit_test(test_speed_and_load),
		cmocka_unit_test(test_voltage_baud_delay),
		cmocka_unit_test(test_format),
		cmocka_unit_test(test_x_manual_rows),
		cmocka_unit_test(test_table_shape_every_model),
		cmocka_unit_test(test_x_lookup),
		cmocka_unit_test(test_x_decode_encode),
		cmocka_unit_test(test_x_write_checks),
		cmocka_unit_test(test_x_conversions),
		cmocka_unit_test(test_x_format),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
