/*
 * test_protocol_table2.c — the X-series control tables: every address, size,
 * access and default below is typed in from the e-manual's XL430-W250 and
 * XM430-W350 pages (ROBOTIS-GIT/emanual docs/en/dxl/x/), not read back from
 * the table; conversions against the manual's units; write checks.
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

static void test_manual_rows(void **state)
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

/* Every row: inside the described table, sorted, non-overlapping, findable
 * by name and address, defaults writable, signed where the manual's range is. */
static void test_table_shape(void **state)
{
	(void)state;
	const uint16_t models[2] = { 1060, 1020 };
	for (int k = 0; k < 2; k++) {
		const struct dxl2_model *m = dxl2_model_by_number(models[k]);
		int next_free = 0;
		for (size_t i = 0; i < m->nregs; i++) {
			const struct dxl2_reg *r = &m->regs[i];
			assert_true(r->size == 1 || r->size == 2 || r->size == 4);
			assert_true(r->addr >= next_free);
			assert_true(r->addr + r->size <= DXL2_X_TABLE_SIZE);
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

static void test_lookup(void **state)
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
	assert_null(dxl2_reg_lookup(m, "168"));     /* indirect area: not described */
	assert_null(dxl2_reg_lookup(m, "65536"));
	assert_null(dxl2_reg_lookup(m, "nonsense"));
	assert_null(dxl2_reg_lookup(m, ""));
	assert_null(dxl2_reg_lookup(NULL, "id"));
}

static void test_decode_encode(void **state)
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

static void test_write_checks(void **state)
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
}

static void test_conversions(void **state)
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

static void test_format(void **state)
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
		cmocka_unit_test(test_manual_rows),
		cmocka_unit_test(test_table_shape),
		cmocka_unit_test(test_lookup),
		cmocka_unit_test(test_decode_encode),
		cmocka_unit_test(test_write_checks),
		cmocka_unit_test(test_conversions),
		cmocka_unit_test(test_format),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
