/*
 * test_dxl_doctor2.c — `dxl doctor`'s verdicts for the X series (Protocol
 * 2.0, tools/dxl/doctor_checks2.c): each check's thresholds on both sides,
 * the level, the value shown and the fix named. test_dxl_fakeservo2.c runs
 * the whole doctor on a fake X bus.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "../../tools/dxl/doctor.h"
#include "../../daemon/servo_model.h"
#include "../../daemon/setup.h"
#include "dxl2.h"
#include "dxl2_table.h"

#define PORT "/dev/ttyUSB0"

static const struct dr_context ctx = { .port = PORT, .ids = "1 2", .baud = 1000000, .period_ms = 10.0,
                                       .protocol = 2, .read_len2 = DR2_READ_LEN };

static void expect(const struct dr_verdict *v, enum dr_level lv, ...)
{
	va_list ap;
	if (v->level != lv)
		fail_msg("level %s, expected %s: %s", dr_level_name(v->level), dr_level_name(lv), v->text);
	va_start(ap, lv);
	for (const char *want = va_arg(ap, const char *); want != NULL; want = va_arg(ap, const char *))
		if (strstr(v->text, want) == NULL)
			fail_msg("'%s' not in: %s", want, v->text);
	va_end(ap);
}

/* An XL430-W250 at its factory settings, return delay 0, at 11.1 V. */
static struct dr2_servo xl430(uint8_t id)
{
	struct dr2_servo s = {
		.id = id, .model = DXL2_MODEL_XL430_W250, .firmware = 46, .return_delay = 0, .operating_mode = 3,
		.temperature_limit = 72, .temperature = 30, .max_voltage = 140, .min_voltage = 60, .voltage = 111,
		.max_position = 4095, .min_position = 0, .shutdown = 52, .torque_enable = 0, .status_return_level = 2,
		.hwerr = 0, .bus_watchdog = 0, .err = 0,
	};
	return s;
}

/* The image as the e-manual's control table lays it out, byte by byte. */
static void test_decode(void **state)
{
	(void)state;
	uint8_t mem[DR2_IMAGE_LEN] = { 0 };
	mem[0] = 0x24, mem[1] = 0x04;          /* model number 1060 */
	mem[6] = 46, mem[9] = 250, mem[11] = 3, mem[31] = 72;
	mem[32] = 140, mem[34] = 60;           /* max / min voltage limit */
	mem[48] = 0xFF, mem[49] = 0x0F;        /* max position limit 4095 */
	mem[52] = 0x00;                        /* min position limit 0 */
	mem[63] = 52, mem[64] = 1, mem[68] = 2, mem[70] = 0x20, mem[98] = 0xFF;
	mem[144] = 119, mem[146] = 37;
	struct dr2_servo s;
	dr2_servo_decode(&s, mem);
	assert_int_equal(s.model, 1060);
	assert_int_equal(s.return_delay, 250);
	assert_int_equal(s.max_voltage, 140);
	assert_int_equal(s.max_position, 4095);
	assert_int_equal(s.torque_enable, 1);
	assert_int_equal(s.hwerr, DXL2_HWERR_OVERLOAD);
	assert_int_equal(s.bus_watchdog, 0xFF);
	assert_int_equal(s.voltage, 119);
	assert_int_equal(s.temperature, 37);
}

static void test_model_delay_level(void **state)
{
	(void)state;
	struct dr2_servo s = xl430(1);
	struct dr_verdict v;
	dr2_check_model(&s, &ctx, &v);
	expect(&v, DR_OK, "1060 (XL430-W250), firmware 46", NULL);
	s.model = 1200;
	dr2_check_model(&s, &ctx, &v);
	expect(&v, DR_WARN, "not in dxl's tables", "dump 1", NULL);
	s = xl430(1);
	dr2_check_return_delay(&s, &ctx, &v);
	expect(&v, DR_OK, "0 us", NULL);
	s.return_delay = 1;
	dr2_check_return_delay(&s, &ctx, &v);
	expect(&v, DR_WARN, "2 us before every reply", "dxl --protocol 2 --port " PORT " setup 1 2 --yes", NULL);
	dr2_check_status_level(&s, &ctx, &v);
	expect(&v, DR_OK, "2", NULL);
	s.status_return_level = 1;
	dr2_check_status_level(&s, &ctx, &v);
	expect(&v, DR_WARN, "WRITEs not", NULL);
	s.status_return_level = 0;
	dr2_check_status_level(&s, &ctx, &v);
	expect(&v, DR_FAIL, "SYNC_READ goes unanswered", "status_return_level 2", NULL);
}

static void test_voltage(void **state)
{
	(void)state;
	struct dr2_servo s = xl430(1);
	struct dr_verdict v;
	dr2_check_voltage(&s, &v);
	expect(&v, DR_OK, "11.1 V (servo's limits 6.0..14.0 V)", NULL);
	s.voltage = 101;          /* the recommended 11.1 V less 1 V: still OK */
	dr2_check_voltage(&s, &v);
	expect(&v, DR_OK, "10.1 V", NULL);
	s.voltage = 100;
	dr2_check_voltage(&s, &v);
	expect(&v, DR_WARN, "10.0 V", "recommended 11.1 V", NULL);
	s.voltage = 65;           /* the XL430's lowest */
	dr2_check_voltage(&s, &v);
	expect(&v, DR_WARN, "6.5 V", NULL);
	s.voltage = 64;
	dr2_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "outside the XL430-W250's 6.5..12.0 V", NULL);
	s.voltage = 59;           /* below its own limit register */
	dr2_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "raises an input voltage error", "charge", NULL);
	s.voltage = 121;
	dr2_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "outside the XL430-W250's", NULL);
	s.model = DXL2_MODEL_XM430_W350;
	s.max_voltage = 160, s.min_voltage = 95, s.voltage = 120;
	dr2_check_voltage(&s, &v);
	expect(&v, DR_OK, "12.0 V", NULL);
	s.voltage = 99;
	dr2_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "outside the XM430-W350's 10.0..14.8 V", NULL);
}

static void test_temperature_mode_torque(void **state)
{
	(void)state;
	struct dr2_servo s = xl430(1);
	struct dr_verdict v;
	dr2_check_temperature(&s, &v);
	expect(&v, DR_OK, "30 C (limit 72 C)", NULL);
	s.temperature = 62;
	dr2_check_temperature(&s, &v);
	expect(&v, DR_WARN, "within 10 C", NULL);
	s.temperature = 61;
	dr2_check_temperature(&s, &v);
	expect(&v, DR_OK, NULL);
	s.temperature = 72;
	dr2_check_temperature(&s, &v);
	expect(&v, DR_FAIL, "its shutdown switches torque off", NULL);
	dr2_check_mode(&s, &ctx, &v);
	expect(&v, DR_OK, "3 (position)", NULL);
	s.operating_mode = 1;
	dr2_check_mode(&s, &ctx, &v);
	expect(&v, DR_WARN, "1 (velocity)", "write 1 operating_mode 3", NULL);
	dr2_check_torque(&s, &v);
	expect(&v, DR_OK, "off", NULL);
}

static void test_limits(void **state)
{
	(void)state;
	struct cfg cfg;
	memset(&cfg, 0, sizeof cfg);
	cfg.njoints = 1;
	cfg.joint[0].neutral = 0.0;
	cfg.joint[0].limit_min = -1.3;
	cfg.joint[0].limit_max = 1.3;
	struct dr2_servo s = xl430(1);
	struct dr_verdict v;
	/* ±1.3 rad at 4096 a turn around 2048: 1201..2895 */
	dr2_check_limits(&s, &cfg, 0, &ctx, &v);
	expect(&v, DR_OK, "0..4095, around the configuration's 1201..2895", NULL);
	s.min_position = 1201, s.max_position = 2895;
	dr2_check_limits(&s, &cfg, 0, &ctx, &v);
	expect(&v, DR_OK, NULL);
	s.min_position = 1500;
	dr2_check_limits(&s, &cfg, 0, &ctx, &v);
	expect(&v, DR_WARN, "narrower", "write 1 min_position_limit 1201", NULL);
	s.min_position = 3000, s.max_position = 4095;
	s.torque_enable = 1;
	dr2_check_limits(&s, &cfg, 0, &ctx, &v);
	expect(&v, DR_FAIL, "no position in common", "torque off first", NULL);
	/* What undulated writes is what the doctor expects: the joint limits
	 * rounded inward to whole units (setup rounds +-0.5 rad to 1723..2373;
	 * rounding to the nearest unit made the doctor expect 1722..2374 and
	 * warn that the servo undulated had just set up was "narrower") */
	const double lims[] = { 0.5, 0.8, 1.0, 1.3 };
	for (size_t i = 0; i < sizeof lims / sizeof lims[0]; i++) {
		cfg.joint[0].limit_min = -lims[i];
		cfg.joint[0].limit_max = lims[i];
		int32_t lo, hi;
		setup_joint_limits_model(sm_by_number(2, DXL2_MODEL_XL430_W250), &cfg.joint[0], &lo, &hi);
		s.min_position = lo, s.max_position = hi;
		s.torque_enable = 0;
		dr2_check_limits(&s, &cfg, 0, &ctx, &v);
		expect(&v, DR_OK, NULL);
	}
	s.min_position = 1723, s.max_position = 2373;
	cfg.joint[0].limit_min = -0.5, cfg.joint[0].limit_max = 0.5;
	dr2_check_limits(&s, &cfg, 0, &ctx, &v);
	expect(&v, DR_OK, "1723..2373, around the configuration's 1723..2373", NULL);
}

static void test_hwerr_watchdog_err(void **state)
{
	(void)state;
	struct dr2_servo s = xl430(2);
	struct dr_verdict v;
	dr2_check_hwerr(&s, &ctx, &v);
	expect(&v, DR_OK, "none", NULL);
	s.hwerr = DXL2_HWERR_OVERHEAT;
	dr2_check_hwerr(&s, &ctx, &v);
	expect(&v, DR_FAIL, "4 (overheating)", "switched its torque off", "reboot 2", NULL);
	s.hwerr = DXL2_HWERR_ENCODER;   /* not in the factory shutdown mask 52 */
	dr2_check_hwerr(&s, &ctx, &v);
	expect(&v, DR_FAIL, "flags every reply with the alert", NULL);
	dr2_check_watchdog(&s, &ctx, &v);
	expect(&v, DR_OK, "off", NULL);
	s.bus_watchdog = 1;            /* 20 ms: two 10 ms periods is the line */
	dr2_check_watchdog(&s, &ctx, &v);
	expect(&v, DR_OK, "20 ms", NULL);
	const struct dr_context slow = { .port = PORT, .ids = "2", .period_ms = 20.0 };
	dr2_check_watchdog(&s, &slow, &v);
	expect(&v, DR_WARN, "20 ms, less than two 20 ms periods", "bus_watchdog 5 (100 ms)", NULL);
	s.bus_watchdog = 0xFF;
	dr2_check_watchdog(&s, &ctx, &v);
	expect(&v, DR_FAIL, "fired", "bus_watchdog 0", NULL);
	assert_false(dr2_check_err(&s, &v));
	s.err = DXL2_ERRNUM_DATA_RANGE;
	assert_true(dr2_check_err(&s, &v));
	expect(&v, DR_WARN, "0x04 (data range)", NULL);
	s.err = 0x80;
	assert_true(dr2_check_err(&s, &v));
	expect(&v, DR_FAIL, "0x80 (alert)", NULL);
}

/* The 2.0 cycle's wire floor and the baud line that prices it. */
static void test_cycle_and_baud(void **state)
{
	(void)state;
	struct dr_verdict v;
	/* 2 servos, 8 bytes: (14+2) + 2·19 + (14+10) = 78 bytes = 780 µs at 1 Mbps */
	assert_float_equal(dr2_cycle_wire_us(2, DR2_READ_LEN, 1000000), 780.0, 1e-9);
	assert_float_equal(dr2_cycle_wire_us(2, DR2_READ_LEN_CURRENT, 1000000), 820.0, 1e-9);
	assert_float_equal(dr2_cycle_wire_us(0, DR2_READ_LEN, 1000000), 0.0, 1e-9);
	dr_check_baud(&ctx, 2, 2, &v);
	expect(&v, DR_OK, "0.78 ms on the wire", NULL);
	struct dr_context c = ctx;
	c.baud = 57600;
	dr_check_baud(&c, 2, 2, &v);
	expect(&v, DR_FAIL, "13.54 ms on the wire, more than the 10 ms period",
	       "dxl --protocol 2 --port " PORT " setup 1 2", NULL);
	c.baud = 115200;   /* 6.77 ms: inside the period, over half of it */
	dr_check_baud(&c, 2, 2, &v);
	expect(&v, DR_WARN, "6.77 ms", "dxl --protocol 2 --port", NULL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_decode),          cmocka_unit_test(test_model_delay_level),
		cmocka_unit_test(test_voltage),         cmocka_unit_test(test_temperature_mode_torque),
		cmocka_unit_test(test_limits),          cmocka_unit_test(test_hwerr_watchdog_err),
		cmocka_unit_test(test_cycle_and_baud),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
