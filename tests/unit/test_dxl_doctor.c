/*
 * test_dxl_doctor.c — the verdicts of `dxl doctor` (tools/dxl/doctor.h): each
 * check's thresholds on both sides, the level, the value shown and the fix
 * named, for the AX-12A and the X series (Protocol 2.0): one set of checks
 * (doctor_checks.c) over the record dr_servo_decode fills through each
 * model's descriptor, run here on both families. The bus work around them is
 * tests/integration/dxl_doctor.sh's, on the simulator, and
 * test_dxl_fakeservo*.c's on fake buses.
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
#include "dxl.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "dxl_proto.h"

#define PORT "/dev/ttyUSB0"

/* The AX-12A's bus: a READ of 8 bytes a servo, 2-byte goals (ax12.md's
 * budget table prices that cycle). */
static const struct dr_context ctx = { .port = PORT, .ids = "1 2", .baud = 1000000, .period_ms = 10.0,
                                       .proto = &dxl_proto_v1, .read_len = 8, .write_len = 2 };

/* The line has level lv and contains every string given (NULL-terminated). */
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

static void lacks(const struct dr_verdict *v, const char *what)
{
	if (strstr(v->text, what) != NULL)
		fail_msg("'%s' should not be in: %s", what, v->text);
}

/* An AX-12A as it leaves the factory, set up for 100 Hz (return delay 0). */
static struct dr_servo factory(uint8_t id)
{
	const struct dxl2_model *ax = dxl2_model_find(1, 12);
	struct dr_servo s = {
		.id = id, .answered = true, .read = true, .model = 12, .m = ax, .table = ax, .firmware = 24,
		.return_delay = 0, .min_limit = 0, .max_limit = 1023, .temperature_limit = 70, .min_voltage = 60,
		.max_voltage = 140, .max_output = 1023, .status_return_level = 2, .has_alarm_led = true, .alarm_led = 36,
		.shutdown = 36, .torque_enable = 0, .has_torque_limit = true, .torque_limit = 1023, .voltage = 120,
		.temperature = 32,
	};
	return s;
}

/* The table as the manual lays it out (ax12.md), not through our own
 * encoder: EEPROM 0..18 and RAM 24..43 of a factory AX-12A at 12 V, 32 °C,
 * read in one READ from address 0. */
static void test_decode(void **state)
{
	(void)state;
	const struct dxl2_model *ax = dxl2_model_find(1, 12);
	uint8_t image[44] = { 12, 0, 24, 1, 1, 250, 0, 0, 0xFF, 0x03, 0, 70, 60, 140, 0xFF, 0x03, 2, 36, 4 };
	assert_int_equal(dr_image_len(ax), sizeof image);
	image[24] = 1;                       /* torque enable */
	image[34] = 0x00, image[35] = 0x02;  /* torque limit 512 */
	image[42] = 111;                     /* present voltage */
	image[43] = 32;                      /* present temperature */
	struct dr_servo s = { 0 };
	dr_servo_decode(&s, ax, ax, image, sizeof image);
	assert_ptr_equal(s.m, ax);
	assert_true(s.has_alarm_led);
	assert_true(s.has_torque_limit);
	assert_int_equal(s.hwerr, 0);        /* no such register: 0, and no line (doctor.c asks the caps) */
	assert_int_equal(s.operating_mode, 0);
	assert_int_equal(s.model, 12);
	assert_int_equal(s.firmware, 24);
	assert_int_equal(s.return_delay, 250);
	assert_int_equal(s.min_limit, 0);
	assert_int_equal(s.max_limit, 1023);
	assert_int_equal(s.temperature_limit, 70);
	assert_int_equal(s.min_voltage, 60);
	assert_int_equal(s.max_voltage, 140);
	assert_int_equal(s.max_output, 1023);
	assert_int_equal(s.status_return_level, 2);
	assert_int_equal(s.alarm_led, 36);
	assert_int_equal(s.shutdown, 4);
	assert_int_equal(s.torque_enable, 1);
	assert_int_equal(s.torque_limit, 512);
	assert_int_equal(s.voltage, 111);
	assert_int_equal(s.temperature, 32);
}

static void test_model(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_servo s = factory(1);
	dr_check_model(&s, &ctx, &v);
	expect(&v, DR_OK, "12 (AX-12A)", "firmware 24", NULL);
	s.model = 18, s.m = NULL;   /* an AX-18: not in the tables, read with the AX-12A's */
	dr_check_model(&s, &ctx, &v);
	expect(&v, DR_WARN, "18, firmware 24: not in dxl's tables (AX-12A)", "with the AX-12A's addresses",
	       "undulated drives it with that table", "dxl --port " PORT " dump 1", NULL);
}

static void test_return_delay(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_servo s = factory(1);
	dr_check_return_delay(&s, &ctx, &v);
	expect(&v, DR_OK, "0 us", NULL);
	lacks(&v, "fix");
	s.return_delay = 250;    /* the factory's 500 µs */
	dr_check_return_delay(&s, &ctx, &v);
	expect(&v, DR_WARN, "500 us", "0.50 ms of every 10 ms cycle", "fix: dxl --port " PORT " setup 1 2 --yes "
	       "(writes return delay 0)", NULL);
	lacks(&v, "support the robot");
	s.return_delay = 1;      /* even 2 µs is said: it is one write away */
	struct dr_context held = ctx;
	held.any_torque_on = true;
	dr_check_return_delay(&s, &held, &v);
	expect(&v, DR_WARN, "2 us", "--yes turns torque off first: support the robot", NULL);
}

static void test_status_level(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_servo s = factory(4);
	dr_check_status_level(&s, &ctx, &v);
	expect(&v, DR_OK, "2", NULL);
	s.status_return_level = 1;
	dr_check_status_level(&s, &ctx, &v);
	expect(&v, DR_WARN, "1: READ answered, WRITEs not", "setup 1 2 --yes (writes status return level 2)", NULL);
	s.status_return_level = 0;
	dr_check_status_level(&s, &ctx, &v);
	expect(&v, DR_FAIL, "answers PING only", "READ of every joint", "refuses to start",
	       "fix: dxl --port " PORT " write 4 status_return_level 2", NULL);
}

static void test_voltage(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_servo s = factory(1);
	dr_check_voltage(&s, &v);
	expect(&v, DR_OK, "12.0 V", "(servo's limits 6.0..14.0 V)", NULL);
	s.voltage = 101;         /* 10.1 V, the recommended 11.1 V less 1 V: the lowest that is not a warning */
	dr_check_voltage(&s, &v);
	expect(&v, DR_OK, "10.1 V", NULL);
	s.voltage = 100;         /* the X series' rule, one for every model (the AX-12A's own said OK here) */
	dr_check_voltage(&s, &v);
	expect(&v, DR_WARN, "10.0 V", "recommended 11.1 V", NULL);
	s.voltage = 99;
	dr_check_voltage(&s, &v);
	expect(&v, DR_WARN, "9.9 V", "fix: charge the battery", NULL);
	s.voltage = 96;
	dr_check_voltage(&s, &v);
	expect(&v, DR_WARN, "9.6 V", "80% of the 12 V torque", NULL);
	s.voltage = 90;
	dr_check_voltage(&s, &v);
	expect(&v, DR_WARN, "9.0 V", NULL);
	s.voltage = 89;          /* below the AX-12A's 9 V, inside the servo's own limits */
	dr_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "8.9 V", "below the AX-12A's 9..12 V", "fix: charge or replace the battery", NULL);
	s.voltage = 70;
	dr_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "7.0 V", "58% of its 12 V torque", NULL);
	s.voltage = 55;          /* outside the servo's own limits: its replies say so */
	dr_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "5.5 V", "voltage error", NULL);
	s.voltage = 126;
	dr_check_voltage(&s, &v);
	expect(&v, DR_OK, "12.6 V", NULL);
	s.voltage = 127;
	dr_check_voltage(&s, &v);
	expect(&v, DR_WARN, "12.7 V", "above the AX-12A's 12 V", NULL);
	s.voltage = 141;
	dr_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "14.1 V", "voltage error", NULL);
}

static void test_temperature(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_servo s = factory(1);
	s.temperature = 59;
	dr_check_temperature(&s, &v);
	expect(&v, DR_OK, "59 C (limit 70 C)", NULL);
	s.temperature = 60;
	dr_check_temperature(&s, &v);
	expect(&v, DR_WARN, "60 C, within 10 C of its limit 70 C", "fix: let it cool", NULL);
	s.temperature = 70;
	dr_check_temperature(&s, &v);
	expect(&v, DR_FAIL, "70 C, at or above its limit", "its shutdown switches torque off", "20 minutes", NULL);
	s.shutdown = DXL_ERRBIT_OVERLOAD;
	dr_check_temperature(&s, &v);
	expect(&v, DR_FAIL, "nothing switches its torque off", NULL);
}

/* The configured joint: neutral 0, ±1.3 rad, i.e. raw 259..765 (whole units
 * inside the limits, setup_joint_limits). */
static struct cfg robot(void)
{
	struct cfg c;
	struct cfg_errors e = { 0 };
	cfg_defaults(&c);
	assert_true(cfg_load_string(&c, "t.conf", "[robot]\nport=/dev/null\nids=1,2\n", &e) && cfg_finish(&c, &e));
	return c;
}

static void test_limits(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct cfg c = robot();
	struct dr_servo s = factory(1);
	dr_check_limits(&s, &c, 0, &ctx, &v);
	expect(&v, DR_OK, "0..1023", "259..765", "joint 1", NULL);
	s.min_limit = 259, s.max_limit = 765;     /* exactly the configuration's */
	dr_check_limits(&s, &c, 0, &ctx, &v);
	expect(&v, DR_OK, "259..765", NULL);
	s.min_limit = 350, s.max_limit = 700;
	dr_check_limits(&s, &c, 0, &ctx, &v);
	expect(&v, DR_WARN, "350..700, narrower than the configuration's 259..765", "write 1 cw_angle_limit 259",
	       "write 1 ccw_angle_limit 765", NULL);
	lacks(&v, "torque 1 off");
	s.max_limit = 1023;                      /* one side only: one write */
	s.torque_enable = 1;
	dr_check_limits(&s, &c, 1, &ctx, &v);
	expect(&v, DR_WARN, "350..1023", "joint 2", "dxl --port " PORT " torque 1 off; dxl --port " PORT
	       " write 1 cw_angle_limit 259", NULL);
	lacks(&v, "ccw_angle_limit");
	s.min_limit = 800, s.max_limit = 1023;    /* no angle in common */
	dr_check_limits(&s, &c, 0, &ctx, &v);
	expect(&v, DR_FAIL, "800..1023 have no angle in common", "refuses to start", NULL);
	s.min_limit = 0, s.max_limit = 0;         /* wheel mode */
	s.torque_enable = 0;
	dr_check_limits(&s, &c, 0, &ctx, &v);
	expect(&v, DR_FAIL, "wheel mode", "write 1 cw_angle_limit 259; dxl --port " PORT " write 1 ccw_angle_limit 765",
	       NULL);
	c.actuation = CFG_ACT_TORQUE;            /* the daemon restores joint mode itself */
	dr_check_limits(&s, &c, 0, &ctx, &v);
	expect(&v, DR_WARN, "wheel mode", "puts", NULL);
}

static void test_alarms(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_servo s = factory(2);
	dr_check_alarms(&s, &ctx, &v);
	expect(&v, DR_OK, "shutdown 36 (overheating|overload)", "LED 36", NULL);
	s.shutdown = DXL_ERRBIT_OVERHEAT;  /* the old manual's default 4 */
	dr_check_alarms(&s, &ctx, &v);
	expect(&v, DR_WARN, "overload does not switch torque off", "fix: dxl --port " PORT " write 2 alarm_shutdown 36",
	       NULL);
	s.shutdown = 36 | DXL_ERRBIT_CHECKSUM;
	dr_check_alarms(&s, &ctx, &v);
	expect(&v, DR_WARN, "checksum switches torque off", "one damaged packet", NULL);
	lacks(&v, "does not switch");
	s.torque_enable = 1;
	dr_check_alarms(&s, &ctx, &v);
	expect(&v, DR_WARN, "(torque off first)", NULL);
}

static void test_torque(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_servo s = factory(1);
	dr_check_torque(&s, &ctx, &v);
	expect(&v, DR_OK, "off", "turns it on at start", NULL);
	s.torque_enable = 1;
	dr_check_torque(&s, &ctx, &v);
	expect(&v, DR_OK, "on, torque limit 1023", NULL);
	s.torque_limit = 0;
	dr_check_torque(&s, &ctx, &v);
	expect(&v, DR_WARN, "torque limit 0: an alarm shut it down", "write 1 torque_limit 1023", NULL);
	s.max_output = 0;
	dr_check_torque(&s, &ctx, &v);
	expect(&v, DR_WARN, "max torque 0", "write 1 max_torque 1023", NULL);
}

static void test_errbits(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_servo s = factory(1);
	assert_false(dr_check_errbits(&s, &ctx, &v));
	s.errbits = DXL_ERRBIT_OVERLOAD;
	assert_true(dr_check_errbits(&s, &ctx, &v));
	expect(&v, DR_FAIL, "0x20 (overload)", "free the joint", NULL);
	s.errbits = DXL_ERRBIT_CHECKSUM;
	assert_true(dr_check_errbits(&s, &ctx, &v));
	expect(&v, DR_WARN, "0x10 (checksum)", "a damaged line", NULL);
	assert_int_equal(v.text[strlen(v.text) - 1] == ' ', 0);
}

static void test_adapter(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_adapter a = { .tty = "pts/3", .is_pty = true, .sysfs_root = "/sys" };
	dr_check_adapter(&a, &v);
	expect(&v, DR_OK, "pts/3: a pseudo-terminal", "no latency timer", NULL);
	/* a U2D2 whose timer was 16 ms: lowered for this run, as undulated does */
	struct dr_adapter u = { .tty = "ttyUSB0", .listed = true, .sysfs_root = "/sys" };
	u.info.usb_vid = 0x0403, u.info.usb_pid = 0x6014, u.info.adapter = "U2D2";
	u.lat.known = true, u.lat.found_ms = 16, u.lat.timer_ms = 1, u.lat.lowered = true;
	dr_check_adapter(&u, &v);
	expect(&v, DR_WARN, "ttyUSB0: U2D2 0403:6014", "was 16 ms, lowered to 1 ms", "99-undulate.rules",
	       "echo 1 > /sys/bus/usb-serial/devices/ttyUSB0/latency_timer", NULL);
	u.lat.timer_ms = 16, u.lat.lowered = false;
	snprintf(u.lat.note, sizeof u.lat.note, "Permission denied");
	dr_check_adapter(&u, &v);
	expect(&v, DR_FAIL, "latency timer 16 ms and it could not be lowered (Permission denied)", "as root", NULL);
	u.lat.found_ms = 1, u.lat.timer_ms = 1;
	dr_check_adapter(&u, &v);
	expect(&v, DR_OK, "latency timer 1 ms", NULL);
	/* an on-board UART in RS-485 mode, echoing */
	struct dr_adapter r = { .tty = "ttyAMA0", .sysfs_root = "/sys", .rs485 = PORT_RS485_RTS_ON_SEND, .echo = true };
	dr_check_adapter(&r, &v);
	expect(&v, DR_OK, "ttyAMA0: a serial port", "RS-485 mode rts-on-send", "echo cancelling on", NULL);
}

static void test_latency(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_latency l = { .measured = true, .id = 1, .allowed_us = 3000, .njoints = 2 };
	l.late = (struct bus_lateness){ .pings = 8, .replies = 8, .min_us = 40, .median_us = 80, .max_us = 140 };
	dr_check_latency(&l, &v);
	expect(&v, DR_OK, "0.08 ms after their wire time", "median of 8 PINGs to ID 1", NULL);
	l.late.median_us = DR_LATE_WARN_US;
	dr_check_latency(&l, &v);
	expect(&v, DR_OK, "1.50 ms", NULL);
	l.late.median_us = DR_LATE_WARN_US + 1;
	dr_check_latency(&l, &v);
	expect(&v, DR_WARN, "3.0 ms a cycle for 2 joint(s)", "fix: an adapter that passes replies on at once", NULL);
	l.allowed_us = 20000;
	l.late.median_us = DR_LATE_FAIL_US + 1;
	l.ftdi = true;
	dr_check_latency(&l, &v);
	expect(&v, DR_FAIL, "every READ waits that long", "fix: the latency timer to 1 ms", NULL);
	/* beyond what the daemon's timeouts allow: its READs would all time out */
	l.ftdi = false;
	l.allowed_us = 3000;
	l.late.median_us = 16150, l.late.max_us = 18610;
	dr_check_latency(&l, &v);
	expect(&v, DR_FAIL, "16.15 ms", "every READ of its cycle would time out", "adapter_latency_us = 20000", NULL);
	l.measured = false;
	dr_check_latency(&l, &v);
	expect(&v, DR_SKIP, "no servo answered", NULL);
}

static void test_echo(void **state)
{
	(void)state;
	struct dr_verdict v;
	assert_false(dr_check_echo(false, 0, 0, &v));
	assert_false(dr_check_echo(true, 0, 0, &v));
	assert_false(dr_check_echo(true, 3, 0, &v));   /* with echo on, an echo is expected */
	assert_true(dr_check_echo(false, 15, 0, &v));
	expect(&v, DR_WARN, "came back before the reply 15 time(s)", "fix: echo = true", "--echo", NULL);
	assert_true(dr_check_echo(true, 0, 4, &v));
	expect(&v, DR_FAIL, "4 time(s)", "the wiring does not echo", "fix: echo = false", NULL);
}

static void test_baud(void **state)
{
	(void)state;
	struct dr_verdict v;
	/* ax12.md's budget table: 2 servos 0.58 ms, 6 servos 1.58 ms at 1 Mbps */
	assert_float_equal(dr_cycle_wire_us(&dxl_proto_v1, 2, 8, 2, 1000000), 580.0, 1e-9);
	assert_float_equal(dr_cycle_wire_us(&dxl_proto_v1, 6, 8, 2, 1000000), 1580.0, 1e-9);
	assert_float_equal(dr_cycle_wire_us(&dxl_proto_v1, 0, 8, 2, 1000000), 0.0, 1e-9);
	/* undulated's own AX-12A cycle: READ(36, 6), 2-byte goals: 2·(8 + 12) + 14 bytes */
	assert_float_equal(dr_cycle_wire_us(&dxl_proto_v1, 2, sm_ax12()->present_len, sm_ax12()->goal_size, 1000000),
	                   540.0, 1e-9);
	dr_check_baud(&ctx, 2, 2, &v);
	expect(&v, DR_OK, "1000000 bps: 2 of 2", "0.58 ms on the wire", NULL);
	dr_check_baud(&ctx, 3, 0, &v);
	expect(&v, DR_FAIL, "none of the 3 servo(s) answered", "dxl --port " PORT " scan --bauds all", NULL);
	struct dr_context slow = ctx;
	slow.baud = 57143;
	dr_check_baud(&slow, 6, 6, &v);   /* 158 bytes: 27.6 ms, longer than the period (a WARN on 1.0 once) */
	expect(&v, DR_FAIL, "57143 bps", "(a READ a servo, a SYNC_WRITE) take 27.65 ms", "more than the 10 ms period",
	       "fix: dxl --port " PORT " setup 1 2", NULL);
	slow.baud = 200000;
	dr_check_baud(&slow, 6, 6, &v);   /* 7.9 ms */
	expect(&v, DR_WARN, "200000 bps", "7.90 ms", "more than half", "dxl --port " PORT " set-baud ID 1000000", NULL);
}

static void test_budget(void **state)
{
	(void)state;
	struct dr_verdict v;
	struct dr_budget b = { .cycles = 300, .joints = 2, .p50_ms = 0.65, .p99_ms = 3.84, .max_ms = 4.57,
	                       .floor_ms = 0.58, .period_ms = 10.0, .errors = 2, .transactions = 666 };
	dr_check_budget(&b, &v);
	expect(&v, DR_OK, "p50 0.65 / p99 3.84 / max 4.57 ms", "wire floor 0.58 ms (p50 1.1x it)", "period 10 ms",
	       "300 cycles", "2 of 666 transactions failed", NULL);
	lacks(&v, "fix");
	b.errors = 7;            /* 1.05 % */
	dr_check_budget(&b, &v);
	expect(&v, DR_WARN, "fix: the failed transactions", NULL);
	b.errors = 67;           /* 10.06 % */
	dr_check_budget(&b, &v);
	expect(&v, DR_FAIL, NULL);
	b.errors = 0;
	b.p99_ms = 7.1;          /* writes and read-backs start to wait (CYC_LATE_SHARE) */
	dr_check_budget(&b, &v);
	expect(&v, DR_WARN, NULL);
	b.p99_ms = 6.0, b.p50_ms = 5.1;
	dr_check_budget(&b, &v);
	expect(&v, DR_WARN, "too much bus time", NULL);
	b.p50_ms = 7.1, b.p99_ms = 9.9;
	dr_check_budget(&b, &v);
	expect(&v, DR_FAIL, NULL);
	b.p50_ms = 1.0, b.p99_ms = 2.0, b.cut_off = 4;
	dr_check_budget(&b, &v);
	expect(&v, DR_WARN, "4 cycle(s) cut off", NULL);
	b.skipped = "--cycles 0";
	dr_check_budget(&b, &v);
	expect(&v, DR_SKIP, "not timed: --cycles 0", NULL);
}

/* ---- the X series (Protocol 2.0) ---- */

/* The X series' (Protocol 2.0): the same bus, the cycle's SYNC_READ of 8
 * bytes a servo, 4-byte goals. */
static const struct dr_context ctx2 = { .port = PORT, .ids = "1 2", .baud = 1000000, .period_ms = 10.0,
                                        .proto = &dxl_proto_v2, .read_len = 8, .write_len = 4 };

/* An XL430-W250 at its factory settings, return delay 0, at 11.1 V. */
static struct dr_servo xl430(uint8_t id)
{
	const struct dxl2_model *xl = dxl2_model_find(2, DXL2_MODEL_XL430_W250);
	struct dr_servo s = {
		.id = id, .answered = true, .read = true, .model = DXL2_MODEL_XL430_W250, .m = xl, .table = xl,
		.firmware = 46, .return_delay = 0, .operating_mode = 3, .temperature_limit = 72, .temperature = 30,
		.max_voltage = 140, .min_voltage = 60, .voltage = 111, .max_limit = 4095, .min_limit = 0, .shutdown = 52,
		.max_output = 885, .torque_enable = 0, .status_return_level = 2, .hwerr = 0, .bus_watchdog = 0,
		.errbits = 0,
	};
	return s;
}

/* The image as the e-manual's control table lays it out, byte by byte. */
static void test_x_decode(void **state)
{
	(void)state;
	const struct dxl2_model *xl = dxl2_model_find(2, DXL2_MODEL_XL430_W250);
	uint8_t mem[147] = { 0 };
	assert_int_equal(dr_image_len(xl), sizeof mem);
	mem[0] = 0x24, mem[1] = 0x04;          /* model number 1060 */
	mem[6] = 46, mem[9] = 250, mem[11] = 3, mem[31] = 72;
	mem[32] = 140, mem[34] = 60;           /* max / min voltage limit */
	mem[48] = 0xFF, mem[49] = 0x0F;        /* max position limit 4095 */
	mem[52] = 0x00;                        /* min position limit 0 */
	mem[63] = 52, mem[64] = 1, mem[68] = 2, mem[70] = 0x20, mem[98] = 0xFF;
	mem[144] = 119, mem[146] = 37;
	mem[36] = 0x75, mem[37] = 0x03;        /* PWM Limit 885 */
	struct dr_servo s = { 0 };
	dr_servo_decode(&s, xl, xl, mem, sizeof mem);
	assert_false(s.has_alarm_led);
	assert_false(s.has_torque_limit);
	assert_int_equal(s.max_output, 885);
	assert_int_equal(s.shutdown, 52);
	assert_int_equal(s.operating_mode, 3);
	assert_int_equal(s.model, 1060);
	assert_int_equal(s.return_delay, 250);
	assert_int_equal(s.max_voltage, 140);
	assert_int_equal(s.max_limit, 4095);
	assert_int_equal(s.torque_enable, 1);
	assert_int_equal(s.hwerr, DXL2_HWERR_OVERLOAD);
	assert_int_equal(s.bus_watchdog, 0xFF);
	assert_int_equal(s.voltage, 119);
	assert_int_equal(s.temperature, 37);
}

static void test_x_model_delay_level(void **state)
{
	(void)state;
	struct dr_servo s = xl430(1);
	struct dr_verdict v;
	dr_check_model(&s, &ctx2, &v);
	expect(&v, DR_OK, "1060 (XL430-W250), firmware 46", NULL);
	s.model = 1200, s.m = NULL;
	dr_check_model(&s, &ctx2, &v);
	expect(&v, DR_WARN, "not in dxl's tables", "with the XL430-W250's addresses", "refuses to start with it",
	       "dxl --protocol 2 --port " PORT " dump 1", NULL);
	s = xl430(1);
	dr_check_return_delay(&s, &ctx2, &v);
	expect(&v, DR_OK, "0 us", NULL);
	s.return_delay = 1;
	dr_check_return_delay(&s, &ctx2, &v);
	expect(&v, DR_WARN, "2 us before every reply", "dxl --protocol 2 --port " PORT " setup 1 2 --yes", NULL);
	dr_check_status_level(&s, &ctx2, &v);
	expect(&v, DR_OK, "2", NULL);
	s.status_return_level = 1;
	dr_check_status_level(&s, &ctx2, &v);
	expect(&v, DR_WARN, "SYNC_READ and READ answered, WRITEs not", "dxl --protocol 2 --port " PORT " setup", NULL);
	s.status_return_level = 0;
	dr_check_status_level(&s, &ctx2, &v);
	expect(&v, DR_FAIL, "SYNC_READ goes unanswered", "status_return_level 2", NULL);
}

static void test_x_voltage(void **state)
{
	(void)state;
	struct dr_servo s = xl430(1);
	struct dr_verdict v;
	dr_check_voltage(&s, &v);
	expect(&v, DR_OK, "11.1 V (servo's limits 6.0..14.0 V)", NULL);
	s.voltage = 101;          /* the recommended 11.1 V less 1 V: still OK */
	dr_check_voltage(&s, &v);
	expect(&v, DR_OK, "10.1 V", NULL);
	s.voltage = 100;
	dr_check_voltage(&s, &v);
	expect(&v, DR_WARN, "10.0 V", "recommended 11.1 V", NULL);
	s.voltage = 65;           /* the XL430's lowest */
	dr_check_voltage(&s, &v);
	expect(&v, DR_WARN, "6.5 V", NULL);
	s.voltage = 64;
	dr_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "below the XL430-W250's 6.5..12 V", NULL);
	s.voltage = 59;           /* below its own limit register */
	dr_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "flags every reply with its voltage error", "charge", NULL);
	/* above the rated 12 V: a full 3S battery (12.6 V) is what robots run
	 * on, OK as on the AX-12A (the X rule alone said FAIL at 12.1 V) */
	s.voltage = 126;
	dr_check_voltage(&s, &v);
	expect(&v, DR_OK, "12.6 V", NULL);
	s.voltage = 127;
	dr_check_voltage(&s, &v);
	expect(&v, DR_WARN, "12.7 V", "above the XL430-W250's 12 V", NULL);
	s.model = DXL2_MODEL_XM430_W350;
	s.m = s.table = dxl2_model_find(2, DXL2_MODEL_XM430_W350);
	s.max_voltage = 160, s.min_voltage = 95, s.voltage = 120;
	dr_check_voltage(&s, &v);
	expect(&v, DR_OK, "12.0 V", NULL);
	s.voltage = 99;
	dr_check_voltage(&s, &v);
	expect(&v, DR_FAIL, "below the XM430-W350's 10..14.8 V", NULL);
}

static void test_x_temperature_mode_torque(void **state)
{
	(void)state;
	struct dr_servo s = xl430(1);
	struct dr_verdict v;
	dr_check_temperature(&s, &v);
	expect(&v, DR_OK, "30 C (limit 72 C)", NULL);
	s.temperature = 62;
	dr_check_temperature(&s, &v);
	expect(&v, DR_WARN, "within 10 C", NULL);
	s.temperature = 61;
	dr_check_temperature(&s, &v);
	expect(&v, DR_OK, NULL);
	s.temperature = 72;
	dr_check_temperature(&s, &v);
	expect(&v, DR_FAIL, "its shutdown switches torque off", NULL);
	dr_check_mode(&s, &ctx2, &v);
	expect(&v, DR_OK, "3 (position)", NULL);
	s.operating_mode = 1;
	dr_check_mode(&s, &ctx2, &v);
	expect(&v, DR_WARN, "1 (velocity)", "write 1 operating_mode 3", NULL);
	dr_check_torque(&s, &ctx2, &v);
	expect(&v, DR_OK, "off, PWM Limit 885", "turns it on at start", NULL);
	lacks(&v, "torque limit");
	s.max_output = 0;         /* the X series' start-up refuses a servo that cannot move */
	dr_check_torque(&s, &ctx2, &v);
	expect(&v, DR_WARN, "PWM Limit 0", "refuses to start", "dxl --protocol 2 --port " PORT " write 1 pwm_limit 885",
	       NULL);
}

static void test_x_limits(void **state)
{
	(void)state;
	struct cfg cfg;
	memset(&cfg, 0, sizeof cfg);
	cfg.njoints = 1;
	cfg.joint[0].neutral = 0.0;
	cfg.joint[0].limit_min = -1.3;
	cfg.joint[0].limit_max = 1.3;
	cfg.joint[0].max_step = 0.2;   /* cfg_finish insists on one */
	struct dr_servo s = xl430(1);
	struct dr_verdict v;
	/* ±1.3 rad at 4096 a turn around 2048: 1201..2895 */
	dr_check_limits(&s, &cfg, 0, &ctx2, &v);
	expect(&v, DR_OK, "0..4095, around the configuration's 1201..2895", NULL);
	s.min_limit = 1201, s.max_limit = 2895;
	dr_check_limits(&s, &cfg, 0, &ctx2, &v);
	expect(&v, DR_OK, NULL);
	s.min_limit = 1500;
	dr_check_limits(&s, &cfg, 0, &ctx2, &v);
	expect(&v, DR_WARN, "narrower", "write 1 min_position_limit 1201", NULL);
	s.min_limit = 3000, s.max_limit = 4095;
	s.torque_enable = 1;
	dr_check_limits(&s, &cfg, 0, &ctx2, &v);
	expect(&v, DR_FAIL, "no position in common", "dxl --protocol 2 --port " PORT " torque 1 off; ",
	       "write 1 min_position_limit 1201", "write 1 max_position_limit 2895", NULL);
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
		s.min_limit = lo, s.max_limit = hi;
		s.torque_enable = 0;
		dr_check_limits(&s, &cfg, 0, &ctx2, &v);
		expect(&v, DR_OK, NULL);
	}
	s.min_limit = 1723, s.max_limit = 2373;
	cfg.joint[0].limit_min = -0.5, cfg.joint[0].limit_max = 0.5;
	dr_check_limits(&s, &cfg, 0, &ctx2, &v);
	expect(&v, DR_OK, "1723..2373, around the configuration's 1723..2373", NULL);
}

static void test_x_hwerr_watchdog_err(void **state)
{
	(void)state;
	struct dr_servo s = xl430(2);
	struct dr_verdict v;
	dr_check_hwerr(&s, &ctx2, &v);
	expect(&v, DR_OK, "none", NULL);
	s.hwerr = DXL2_HWERR_OVERHEAT;
	dr_check_hwerr(&s, &ctx2, &v);
	expect(&v, DR_FAIL, "4 (overheating)", "switched its torque off", "reboot 2", NULL);
	s.hwerr = DXL2_HWERR_ENCODER;   /* not in the factory shutdown mask 52 */
	dr_check_hwerr(&s, &ctx2, &v);
	expect(&v, DR_FAIL, "flags every reply with the alert", NULL);
	dr_check_watchdog(&s, &ctx2, &v);
	expect(&v, DR_OK, "off", NULL);
	s.bus_watchdog = 1;            /* 20 ms: two 10 ms periods is the line */
	dr_check_watchdog(&s, &ctx2, &v);
	expect(&v, DR_OK, "20 ms", NULL);
	const struct dr_context slow = { .port = PORT, .ids = "2", .period_ms = 20.0 };
	dr_check_watchdog(&s, &slow, &v);
	expect(&v, DR_WARN, "20 ms, less than two 20 ms periods", "bus_watchdog 5 (100 ms)", NULL);
	s.bus_watchdog = 0xFF;
	dr_check_watchdog(&s, &ctx2, &v);
	expect(&v, DR_FAIL, "fired", "bus_watchdog 0", NULL);
	assert_false(dr_check_errbits(&s, &ctx2, &v));
	s.errbits = DXL2_ERRNUM_DATA_RANGE;
	assert_true(dr_check_errbits(&s, &ctx2, &v));
	expect(&v, DR_WARN, "0x04 (data range)", NULL);
	s.errbits = 0x80;
	assert_true(dr_check_errbits(&s, &ctx2, &v));
	expect(&v, DR_FAIL, "0x80 (alert)", NULL);
}

/* The 2.0 cycle's wire floor and the baud line that prices it. */
static void test_x_cycle_and_baud(void **state)
{
	(void)state;
	struct dr_verdict v;
	/* 2 servos, 8 bytes: (14+2) + 2·19 + (14+10) = 78 bytes = 780 µs at 1 Mbps */
	assert_float_equal(dr_cycle_wire_us(&dxl_proto_v2, 2, 8, 4, 1000000), 780.0, 1e-9);
	assert_float_equal(dr_cycle_wire_us(&dxl_proto_v2, 2, 10, 4, 1000000), 820.0, 1e-9);
	assert_float_equal(dr_cycle_wire_us(&dxl_proto_v2, 0, 8, 4, 1000000), 0.0, 1e-9);
	dr_check_baud(&ctx2, 2, 2, &v);
	expect(&v, DR_OK, "0.78 ms on the wire", NULL);
	struct dr_context c = ctx2;
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
		cmocka_unit_test(test_decode),       cmocka_unit_test(test_model),   cmocka_unit_test(test_return_delay),
		cmocka_unit_test(test_status_level), cmocka_unit_test(test_voltage), cmocka_unit_test(test_temperature),
		cmocka_unit_test(test_limits),       cmocka_unit_test(test_alarms),  cmocka_unit_test(test_torque),
		cmocka_unit_test(test_errbits),      cmocka_unit_test(test_adapter), cmocka_unit_test(test_latency),
		cmocka_unit_test(test_baud),         cmocka_unit_test(test_budget),  cmocka_unit_test(test_echo),
		cmocka_unit_test(test_x_decode),     cmocka_unit_test(test_x_model_delay_level),
		cmocka_unit_test(test_x_voltage),    cmocka_unit_test(test_x_temperature_mode_torque),
		cmocka_unit_test(test_x_limits),     cmocka_unit_test(test_x_hwerr_watchdog_err),
		cmocka_unit_test(test_x_cycle_and_baud),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
