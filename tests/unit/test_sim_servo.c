/*
 * test_sim_servo.c — the simulated AX-12's control-table semantics, driven
 * with raw instruction bytes (the manual's worked examples written out
 * literally, not produced by our encoder) and checked byte for byte.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "dxl.h"
#include "dxl_table.h"
#include "../../sim-bridge/servo.h"

/* Parse one instruction packet from raw bytes (must be exactly one). */
static struct dxl_packet parse(const uint8_t *raw, size_t n)
{
	struct dxl_parser p;
	struct dxl_packet pkt;
	size_t used = 0;
	dxl_parser_init(&p, DXL_PARSE_INSTRUCTION);
	assert_int_equal(dxl_parser_feed(&p, raw, n, &used, &pkt), DXL_FRAME);
	assert_int_equal(used, n);
	return pkt;
}

/* Send raw bytes to the servo; returns the reply length, reply in out. */
static int send(struct sim_servo *s, const uint8_t *raw, size_t n, uint8_t *out)
{
	struct dxl_packet pkt = parse(raw, n);
	return sim_servo_handle(s, &pkt, out, DXL_MAX_PACKET);
}

#define SEND(s, out, ...) \
	send((s), (const uint8_t[]){ __VA_ARGS__ }, sizeof((const uint8_t[]){ __VA_ARGS__ }), (out))

static void expect_reply(const uint8_t *got, int len, const uint8_t *want, size_t wn)
{
	assert_int_equal(len, (int)wn);
	assert_memory_equal(got, want, wn);
}
#define EXPECT(got, len, ...)                                                             \
	do {                                                                              \
		static const uint8_t want_[] = { __VA_ARGS__ };                           \
		expect_reply((got), (len), want_, sizeof(want_));                        \
	} while (0)

/* Build a request with our encoder (for cases without a manual example). */
static int req(struct sim_servo *s, uint8_t id, uint8_t instr, const uint8_t *params, size_t n, uint8_t *out)
{
	uint8_t buf[DXL_MAX_PACKET];
	int len = dxl_encode_instruction(buf, sizeof(buf), id, instr, params, n);
	assert_true(len > 0);
	return send(s, buf, (size_t)len, out);
}

static int write_u8(struct sim_servo *s, uint8_t id, uint8_t addr, uint8_t v, uint8_t *out)
{
	uint8_t p[2] = { addr, v };
	return req(s, id, DXL_INST_WRITE, p, 2, out);
}

static int write_u16(struct sim_servo *s, uint8_t id, uint8_t addr, uint16_t v, uint8_t *out)
{
	uint8_t p[3] = { addr, (uint8_t)(v & 0xFF), (uint8_t)(v >> 8) };
	return req(s, id, DXL_INST_WRITE, p, 3, out);
}

/* A servo at 32 °C, centred, as the manual's examples assume. */
static void servo_at_32c(struct sim_servo *s)
{
	sim_servo_init(s, NULL, DXL_POS_CENTER);
	struct sim_servo_sense in = { .angle = 0, .voltage = 12.0, .temperature = 32.0 };
	sim_servo_sense(s, &in, 0.001);
}

static void test_golden_ping(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	int n = SEND(&s, out, 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC);
}

static void test_golden_read_temperature(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	int n = SEND(&s, out, 0xFF, 0xFF, 0x01, 0x04, 0x02, 0x2B, 0x01, 0xCC);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB);
}

static void test_golden_write(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	/* The e-manual's checksum example: WRITE id 1, addr 12 (min voltage),
	 * 0x64 0xAA: 10.0 V and 17.0 V. The same manual's range is 50-160: 170
	 * gets the range bit and neither byte is stored. */
	int n = SEND(&s, out, 0xFF, 0xFF, 0x01, 0x05, 0x03, 0x0C, 0x64, 0xAA, 0xDC);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x08, 0xF4);
	assert_int_equal(s.mem[12], 60);
	assert_int_equal(s.mem[13], 140);
	/* WRITE id 1 goal position 512. */
	n = SEND(&s, out, 0xFF, 0xFF, 0x01, 0x05, 0x03, 0x1E, 0x00, 0x02, 0xD6);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_GOAL_POSITION), 512);
}

static void test_golden_broadcast_set_id(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	sim_servo_poke(&s, DXL_AX_ID, 7);
	int n = SEND(&s, out, 0xFF, 0xFF, 0xFE, 0x04, 0x03, 0x03, 0x01, 0xF6);
	assert_int_equal(n, 0);  /* broadcast: no status packet */
	assert_int_equal(sim_servo_id(&s), 1);
}

static void test_golden_sync_write(void **state)
{
	(void)state;
	struct sim_servo s0, s1;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s0);
	servo_at_32c(&s1);
	sim_servo_poke(&s0, DXL_AX_ID, 0);
	static const uint8_t raw[] = { 0xFF, 0xFF, 0xFE, 0x0E, 0x83, 0x1E, 0x04, 0x00, 0x10, 0x00,
	                               0x50, 0x01, 0x01, 0x20, 0x02, 0x60, 0x03, 0x67 };
	assert_int_equal(send(&s0, raw, sizeof(raw), out), 0);
	assert_int_equal(send(&s1, raw, sizeof(raw), out), 0);
	assert_int_equal(sim_servo_peek(&s0, DXL_AX_GOAL_POSITION), 0x010);
	assert_int_equal(sim_servo_peek(&s0, DXL_AX_MOVING_SPEED), 0x150);
	assert_int_equal(sim_servo_peek(&s1, DXL_AX_GOAL_POSITION), 0x220);
	assert_int_equal(sim_servo_peek(&s1, DXL_AX_MOVING_SPEED), 0x360);
}

static void test_golden_reg_write_action(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	uint8_t p[3] = { DXL_AX_GOAL_POSITION, 0x00, 0x03 };
	int n = req(&s, 1, DXL_INST_REG_WRITE, p, 3, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_GOAL_POSITION), DXL_POS_CENTER);
	assert_int_equal(s.mem[DXL_AX_REGISTERED], 1);
	/* ACTION broadcast (manual example): applied, no reply. */
	n = SEND(&s, out, 0xFF, 0xFF, 0xFE, 0x02, 0x05, 0xFA);
	assert_int_equal(n, 0);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_GOAL_POSITION), 0x300);
	assert_int_equal(s.mem[DXL_AX_REGISTERED], 0);
	/* ACTION with nothing registered: instruction error. */
	n = req(&s, 1, DXL_INST_ACTION, NULL, 0, out);
	assert_int_equal(n, 6);
	assert_int_equal(out[4], DXL_ERRBIT_INSTRUCTION);
}

static void test_range_error_not_written(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	int n = write_u8(&s, 1, DXL_AX_STATUS_RETURN_LEVEL, 3, out);
	assert_int_equal(n, 6);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(s.mem[DXL_AX_STATUS_RETURN_LEVEL], 2);
	/* Goal 1024: beyond the register's range. */
	n = write_u16(&s, 1, DXL_AX_GOAL_POSITION, 1024, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_GOAL_POSITION), DXL_POS_CENTER);
	/* Past the end of the table. */
	uint8_t p[3] = { 49, 1, 1 };
	n = req(&s, 1, DXL_INST_WRITE, p, 3, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	/* Atomic: a valid goal with an invalid speed writes neither. */
	uint8_t q[5] = { DXL_AX_GOAL_POSITION, 0x00, 0x01, 0xFF, 0x07 };
	n = req(&s, 1, DXL_INST_WRITE, q, 5, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_GOAL_POSITION), DXL_POS_CENTER);
}

/* The AX-12A e-manual's write ranges, written out here (not read from
 * protocol/dxl_table.c, which the servo enforces): the last value inside is
 * stored, the first outside gets the range bit and changes nothing. */
static void test_emanual_ranges(void **state)
{
	(void)state;
	static const struct {
		uint8_t addr;
		uint16_t inside, outside;
	} rows[] = {
		{ DXL_AX_ID, 253, 254 },
		{ DXL_AX_BAUD_RATE, 254, 255 },
		{ DXL_AX_RETURN_DELAY_TIME, 254, 255 },
		{ DXL_AX_CW_ANGLE_LIMIT, 1023, 1024 },
		{ DXL_AX_TEMPERATURE_LIMIT, 100, 101 },   /* e-manual 0-100 (old manual 0-150) */
		{ DXL_AX_MIN_VOLTAGE_LIMIT, 50, 49 },     /* 50-160 (old manual 50-250) */
		{ DXL_AX_MIN_VOLTAGE_LIMIT, 160, 161 },
		{ DXL_AX_MAX_VOLTAGE_LIMIT, 160, 161 },
		{ DXL_AX_MAX_TORQUE, 1023, 1024 },
		{ DXL_AX_STATUS_RETURN_LEVEL, 2, 3 },
		{ DXL_AX_ALARM_LED, 0x7F, 0x80 },
		{ DXL_AX_ALARM_SHUTDOWN, 0x7F, 0x80 },
		{ DXL_AX_TORQUE_ENABLE, 1, 2 },
		{ DXL_AX_LED, 1, 2 },
		{ DXL_AX_CW_COMPLIANCE_SLOPE, 254, 255 },  /* 0-254, in 7 steps */
		{ DXL_AX_CCW_COMPLIANCE_SLOPE, 0, 255 },
		{ DXL_AX_GOAL_POSITION, 1023, 1024 },
		{ DXL_AX_MOVING_SPEED, 1023, 1024 },       /* joint mode */
		{ DXL_AX_TORQUE_LIMIT, 1023, 1024 },
		{ DXL_AX_PUNCH, 0x20, 0x1F },              /* 0x20-0x3FF (old manual 0-1023) */
		{ DXL_AX_PUNCH, 0x3FF, 0x400 },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		struct sim_servo s;
		uint8_t out[DXL_MAX_PACKET];
		servo_at_32c(&s);
		const struct dxl_reg *r = dxl_reg_at(rows[i].addr);
		assert_non_null(r);
		uint16_t before = sim_servo_peek(&s, rows[i].addr);
		int n = r->size == 2 ? write_u16(&s, 1, rows[i].addr, rows[i].outside, out)
		                     : write_u8(&s, 1, rows[i].addr, (uint8_t)rows[i].outside, out);
		assert_int_equal(n, 6);
		if (out[4] != DXL_ERRBIT_RANGE)
			fail_msg("%s = %u: error 0x%02x, want the range bit", r->name, rows[i].outside, out[4]);
		assert_int_equal(sim_servo_peek(&s, rows[i].addr), before);
		n = r->size == 2 ? write_u16(&s, 1, rows[i].addr, rows[i].inside, out)
		                 : write_u8(&s, 1, rows[i].addr, (uint8_t)rows[i].inside, out);
		if (rows[i].addr == DXL_AX_ID) {
			assert_int_equal(out[2], 1);  /* answered under the old ID */
		}
		if (out[4] != 0)
			fail_msg("%s = %u: error 0x%02x, want none", r->name, rows[i].inside, out[4]);
		assert_int_equal(sim_servo_peek(&s, rows[i].addr), rows[i].inside);
		assert_int_equal(s.count.range_errors, 1);
	}
}

static void test_read_only_registers(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	uint16_t before = sim_servo_peek(&s, DXL_AX_PRESENT_POSITION);
	int n = write_u16(&s, 1, DXL_AX_PRESENT_POSITION, 100, out);
	assert_int_equal(n, 6);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_PRESENT_POSITION), before);
	n = write_u16(&s, 1, DXL_AX_MODEL_NUMBER, 99, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_MODEL_NUMBER), DXL_AX12_MODEL);
	/* Reserved address 10. */
	n = write_u8(&s, 1, 10, 1, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
}

static void test_angle_limit_error(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	write_u16(&s, 1, DXL_AX_CW_ANGLE_LIMIT, 200, out);
	assert_int_equal(out[4], 0);
	write_u16(&s, 1, DXL_AX_CCW_ANGLE_LIMIT, 800, out);
	int n = write_u16(&s, 1, DXL_AX_GOAL_POSITION, 100, out);
	assert_int_equal(n, 6);
	assert_int_equal(out[4], DXL_ERRBIT_ANGLE_LIMIT);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_GOAL_POSITION), DXL_POS_CENTER);
	write_u16(&s, 1, DXL_AX_GOAL_POSITION, 801, out);
	assert_int_equal(out[4], DXL_ERRBIT_ANGLE_LIMIT);
	write_u16(&s, 1, DXL_AX_GOAL_POSITION, 800, out);
	assert_int_equal(out[4], 0);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_GOAL_POSITION), 800);
	assert_int_equal(s.count.angle_limit_errors, 2);
}

/* Present Speed: the measured speed in joint mode, the output share in wheel
 * mode (e-manual: "the unit is about 0.1 %"), whatever the wheel's speed. */
static void test_present_speed_by_mode(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	struct sim_servo_sense in = { .speed = 3.0, .output = 0.5, .voltage = 12.0, .temperature = 32.0 };
	sim_servo_sense(&s, &in, 0.001);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_PRESENT_SPEED), dxl_rad_s_to_speed(3.0));
	write_u16(&s, 1, DXL_AX_CCW_ANGLE_LIMIT, 0, out);   /* wheel mode */
	sim_servo_sense(&s, &in, 0.001);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_PRESENT_SPEED), 512);
	in.output = -0.25;   /* CW: bit 10 */
	in.speed = -5.0;
	sim_servo_sense(&s, &in, 0.001);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_PRESENT_SPEED), 1024 + 256);
	in.output = 0.0;     /* no drive: 0 while the wheel still turns */
	sim_servo_sense(&s, &in, 0.001);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_PRESENT_SPEED), 0);
	write_u16(&s, 1, DXL_AX_CCW_ANGLE_LIMIT, 1023, out);  /* joint mode again */
	sim_servo_sense(&s, &in, 0.001);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_PRESENT_SPEED), dxl_rad_s_to_speed(-5.0));
}

static void test_wheel_mode(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	/* Joint mode: moving speed above 1023 is out of range. */
	write_u16(&s, 1, DXL_AX_MOVING_SPEED, 1500, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	write_u16(&s, 1, DXL_AX_CCW_ANGLE_LIMIT, 0, out);
	assert_int_equal(out[4], 0);
	write_u16(&s, 1, DXL_AX_MOVING_SPEED, 1500, out);  /* CW at 476 */
	assert_int_equal(out[4], 0);
	struct sim_motor_cmd cmd;
	sim_servo_motor_cmd(&s, &cmd);
	assert_int_equal(cmd.cw_limit, 0);
	assert_int_equal(cmd.ccw_limit, 0);
	assert_int_equal(cmd.moving_speed, 1500);
}

static void test_eeprom_vs_ram(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	write_u8(&s, 1, DXL_AX_RETURN_DELAY_TIME, 0, out);
	write_u8(&s, 1, DXL_AX_LED, 1, out);
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 1, out);
	/* AX-12A: EEPROM only with torque off. */
	int n = write_u8(&s, 1, DXL_AX_RETURN_DELAY_TIME, 10, out);
	assert_int_equal(n, 6);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(s.mem[DXL_AX_RETURN_DELAY_TIME], 0);
	/* Power cycle: RAM back to defaults, EEPROM kept. */
	sim_servo_power_off(&s);
	assert_int_equal(SEND(&s, out, 0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB), 0);  /* no power, no reply */
	sim_servo_power_on(&s);
	assert_int_equal(s.mem[DXL_AX_RETURN_DELAY_TIME], 0);
	assert_int_equal(s.mem[DXL_AX_LED], 0);
	assert_int_equal(s.mem[DXL_AX_TORQUE_ENABLE], 0);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_TORQUE_LIMIT), 1023);
	/* The original AX-12 allows EEPROM writes with torque on. */
	struct sim_servo_options o;
	sim_servo_default_options(&o);
	o.eeprom_needs_torque_off = false;
	sim_servo_init(&s, &o, DXL_POS_CENTER);
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 1, out);
	write_u8(&s, 1, DXL_AX_RETURN_DELAY_TIME, 10, out);
	assert_int_equal(out[4], 0);
	assert_int_equal(s.mem[DXL_AX_RETURN_DELAY_TIME], 10);
}

static void test_max_torque_copied_at_power_on(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	write_u16(&s, 1, DXL_AX_MAX_TORQUE, 600, out);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_TORQUE_LIMIT), 1023);
	sim_servo_power_off(&s);
	sim_servo_power_on(&s);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_TORQUE_LIMIT), 600);
}

static void test_status_return_levels(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	uint8_t rd[2] = { DXL_AX_PRESENT_POSITION, 2 };
	servo_at_32c(&s);
	write_u8(&s, 1, DXL_AX_STATUS_RETURN_LEVEL, 1, out);
	assert_int_equal(write_u8(&s, 1, DXL_AX_LED, 1, out), 0);   /* WRITE: silent */
	assert_int_equal(req(&s, 1, DXL_INST_READ, rd, 2, out), 8);  /* READ answers */
	assert_int_equal(req(&s, 1, DXL_INST_PING, NULL, 0, out), 6);
	assert_int_equal(s.mem[DXL_AX_LED], 1);  /* ...and the write happened */
	assert_int_equal(write_u8(&s, 1, DXL_AX_STATUS_RETURN_LEVEL, 0, out), 0);
	assert_int_equal(req(&s, 1, DXL_INST_READ, rd, 2, out), 0);
	assert_int_equal(req(&s, 1, DXL_INST_PING, NULL, 0, out), 6);  /* PING always */
}

static void test_broadcast_behaviour(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	uint8_t rd[2] = { DXL_AX_PRESENT_POSITION, 2 };
	servo_at_32c(&s);
	sim_servo_poke(&s, DXL_AX_ID, 5);
	assert_int_equal(req(&s, DXL_BROADCAST_ID, DXL_INST_READ, rd, 2, out), 0);
	assert_int_equal(write_u8(&s, DXL_BROADCAST_ID, DXL_AX_LED, 1, out), 0);
	assert_int_equal(s.mem[DXL_AX_LED], 1);
	/* Broadcast PING is answered (by every servo: they collide on the bus). */
	int n = req(&s, DXL_BROADCAST_ID, DXL_INST_PING, NULL, 0, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x05, 0x02, 0x00, 0xF8);
	/* Another ID: nothing. */
	assert_int_equal(req(&s, 6, DXL_INST_PING, NULL, 0, out), 0);
}

static void test_factory_reset(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	sim_servo_poke(&s, DXL_AX_ID, 9);
	sim_servo_poke(&s, DXL_AX_BAUD_RATE, 3);
	sim_servo_poke(&s, DXL_AX_RETURN_DELAY_TIME, 0);
	int n = req(&s, 9, DXL_INST_FACTORY_RESET, NULL, 0, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x09, 0x02, 0x00, 0xF4);  /* answered under the old ID */
	assert_int_equal(sim_servo_id(&s), 1);
	assert_int_equal(s.mem[DXL_AX_BAUD_RATE], 1);
	assert_int_equal(s.mem[DXL_AX_RETURN_DELAY_TIME], 250);
}

static void test_lock(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	write_u8(&s, 1, DXL_AX_LOCK, 1, out);
	assert_int_equal(out[4], 0);
	write_u8(&s, 1, DXL_AX_RETURN_DELAY_TIME, 3, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(s.mem[DXL_AX_RETURN_DELAY_TIME], 250);
	write_u8(&s, 1, DXL_AX_LOCK, 0, out);  /* only a power cycle unlocks */
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	write_u8(&s, 1, DXL_AX_LED, 1, out);  /* RAM stays writable */
	assert_int_equal(out[4], 0);
	sim_servo_power_off(&s);
	sim_servo_power_on(&s);
	write_u8(&s, 1, DXL_AX_RETURN_DELAY_TIME, 3, out);
	assert_int_equal(out[4], 0);
}

static void test_alarm_shutdown_and_recovery(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	struct sim_servo_options o;
	sim_servo_default_options(&o);
	o.overload_time_s = 0.1;
	sim_servo_init(&s, &o, DXL_POS_CENTER);
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 1, out);
	struct sim_servo_sense in = { .voltage = 12.0, .temperature = 30.0, .overloaded = true };
	for (int i = 0; i < 50; i++)
		sim_servo_sense(&s, &in, 0.001);
	assert_int_equal(s.mem[DXL_AX_TORQUE_ENABLE], 1);  /* not yet: 50 ms */
	for (int i = 0; i < 60; i++)
		sim_servo_sense(&s, &in, 0.001);
	/* Overload (bit 5) is in the default shutdown mask 36. */
	assert_int_equal(s.mem[DXL_AX_TORQUE_ENABLE], 0);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_TORQUE_LIMIT), 0);
	assert_true(s.alarm_led);
	int n = req(&s, 1, DXL_INST_PING, NULL, 0, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x20, 0xDC);
	/* The load is gone with the torque, but the bit stays latched... */
	in.overloaded = false;
	sim_servo_sense(&s, &in, 0.001);
	n = req(&s, 1, DXL_INST_PING, NULL, 0, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x20, 0xDC);
	/* ...until the torque limit is written back and torque enabled. */
	write_u16(&s, 1, DXL_AX_TORQUE_LIMIT, 1023, out);
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 1, out);
	sim_servo_sense(&s, &in, 0.001);
	n = req(&s, 1, DXL_INST_PING, NULL, 0, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC);
	assert_int_equal(s.mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_TORQUE_LIMIT), 1023);
	assert_int_equal(s.count.shutdowns, 1);
}

static void expect_shut_down(const struct sim_servo *s, unsigned shutdowns)
{
	assert_int_equal(s->mem[DXL_AX_TORQUE_ENABLE], 0);
	assert_int_equal(sim_servo_peek(s, DXL_AX_TORQUE_LIMIT), 0);
	assert_int_equal(s->count.shutdowns, shutdowns);
}

static void torque_back_on(struct sim_servo *s)
{
	uint8_t out[DXL_MAX_PACKET];
	write_u16(s, 1, DXL_AX_TORQUE_LIMIT, 1023, out);
	assert_int_equal(out[4], 0);
	write_u8(s, 1, DXL_AX_TORQUE_ENABLE, 1, out);
	assert_int_equal(out[4], 0);
	assert_int_equal(s->mem[DXL_AX_TORQUE_ENABLE], 1);
}

/* Every bit of Alarm Shutdown acts, the one-packet errors too: the reply
 * carries the bit, torque enable and torque limit go to 0. */
static void test_alarm_shutdown_every_bit(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	write_u16(&s, 1, DXL_AX_CW_ANGLE_LIMIT, 100, out);
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 1, out);
	/* The factory mask (36) leaves a range error alone. */
	write_u8(&s, 1, DXL_AX_LED, 2, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
	assert_int_equal(s.mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(sim_servo_peek(&s, DXL_AX_TORQUE_LIMIT), 1023);
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 0, out);
	write_u8(&s, 1, DXL_AX_ALARM_SHUTDOWN, 0x7F, out);
	assert_int_equal(out[4], 0);
	torque_back_on(&s);
	/* range: LED 2 */
	int n = write_u8(&s, 1, DXL_AX_LED, 2, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x08, 0xF4);
	expect_shut_down(&s, 1);
	torque_back_on(&s);
	/* angle limit: goal 50 below the CW limit 100 */
	n = write_u16(&s, 1, DXL_AX_GOAL_POSITION, 50, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x02, 0xFA);
	expect_shut_down(&s, 2);
	torque_back_on(&s);
	/* instruction: ACTION with nothing registered */
	n = req(&s, 1, DXL_INST_ACTION, NULL, 0, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x40, 0xBC);
	expect_shut_down(&s, 3);
	torque_back_on(&s);
	/* checksum */
	n = sim_servo_handle_bad_checksum(&s, 1, DXL_INST_PING, out, sizeof(out));
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x10, 0xEC);
	expect_shut_down(&s, 4);
	torque_back_on(&s);
	/* a READ past the table: range */
	uint8_t rd[2] = { 45, 10 };
	n = req(&s, 1, DXL_INST_READ, rd, 2, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x08, 0xF4);
	expect_shut_down(&s, 5);
	torque_back_on(&s);
	/* unreported errors act too: a broadcast write out of range, and a
	 * SYNC_WRITE of a goal past the angle limit */
	assert_int_equal(write_u8(&s, DXL_BROADCAST_ID, DXL_AX_LED, 2, out), 0);
	expect_shut_down(&s, 6);
	torque_back_on(&s);
	uint8_t sw[5] = { DXL_AX_GOAL_POSITION, 2, 1, 50, 0 };
	assert_int_equal(req(&s, DXL_BROADCAST_ID, DXL_INST_SYNC_WRITE, sw, 5, out), 0);
	expect_shut_down(&s, 7);
	/* a second error while it is shut down is not another shutdown */
	write_u8(&s, 1, DXL_AX_LED, 2, out);
	expect_shut_down(&s, 7);
	assert_int_equal(s.count.range_errors, 5);   /* the first under mask 36 */
	assert_int_equal(s.count.angle_limit_errors, 2);
	assert_int_equal(s.count.instruction_errors, 1);
	assert_int_equal(s.count.checksum_errors, 1);
}

/* A write is answered under the ID and the status return level the servo had
 * when it arrived (the original AX-12 manual's Examples 7 and 14). */
static void test_answered_before_the_write_acts(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	/* Example 7: ID 1 -> 0, answered by ID 1 */
	int n = SEND(&s, out, 0xFF, 0xFF, 0x01, 0x04, 0x03, 0x03, 0x00, 0xF4);
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC);
	assert_int_equal(sim_servo_id(&s), 0);
	/* Example 14: status return level 0, the write itself answered */
	n = SEND(&s, out, 0xFF, 0xFF, 0x00, 0x04, 0x03, 0x10, 0x00, 0xE8);
	EXPECT(out, n, 0xFF, 0xFF, 0x00, 0x02, 0x00, 0xFD);
	assert_int_equal(s.mem[DXL_AX_STATUS_RETURN_LEVEL], 0);
	uint8_t rd[2] = { DXL_AX_PRESENT_TEMPERATURE, 1 };
	assert_int_equal(req(&s, 0, DXL_INST_READ, rd, 2, out), 0);
	/* back to 2: under the old level 0, not answered; the next one is */
	assert_int_equal(write_u8(&s, 0, DXL_AX_STATUS_RETURN_LEVEL, 2, out), 0);
	assert_int_equal(s.mem[DXL_AX_STATUS_RETURN_LEVEL], 2);
	n = req(&s, 0, DXL_INST_READ, rd, 2, out);
	EXPECT(out, n, 0xFF, 0xFF, 0x00, 0x03, 0x00, 0x20, 0xDC);
}

static void test_overheating_and_masks(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	write_u8(&s, 1, DXL_AX_ALARM_SHUTDOWN, 0, out);  /* report, do not shut down */
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 1, out);
	struct sim_servo_sense in = { .voltage = 12.0, .temperature = 75.0 };
	sim_servo_sense(&s, &in, 0.001);
	int n = req(&s, 1, DXL_INST_PING, NULL, 0, out);
	/* The manual's example status: overload + overheating = 0x24 -> D8;
	 * here only overheating: 0x04. */
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x04, 0xF8);
	assert_int_equal(s.mem[DXL_AX_TORQUE_ENABLE], 1);
	/* Overheating held and torque on: the shutdown mask cuts it. */
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 0, out);
	write_u8(&s, 1, DXL_AX_ALARM_SHUTDOWN, DXL_ERRBIT_OVERHEAT, out);
	write_u8(&s, 1, DXL_AX_TORQUE_ENABLE, 1, out);
	assert_int_equal(s.mem[DXL_AX_TORQUE_ENABLE], 0);  /* refused while hot */
	/* (Injected stuck-error bits are added to replies by fault.c:
	 * test_sim_bus.c.) Supply voltage below the limit raises bit 0. */
	in.temperature = 30;
	in.voltage = 5.0;
	sim_servo_sense(&s, &in, 0.001);
	n = req(&s, 1, DXL_INST_PING, NULL, 0, out);
	assert_int_equal(out[4], DXL_ERRBIT_VOLTAGE);
}

static void test_bad_checksum_and_unknown_instruction(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	int n = sim_servo_handle_bad_checksum(&s, 1, DXL_INST_PING, out, sizeof(out));
	EXPECT(out, n, 0xFF, 0xFF, 0x01, 0x02, 0x10, 0xEC);
	assert_int_equal(sim_servo_handle_bad_checksum(&s, 2, DXL_INST_PING, out, sizeof(out)), 0);
	/* REBOOT does not exist on the AX-12. */
	n = req(&s, 1, DXL_INST_REBOOT, NULL, 0, out);
	assert_int_equal(n, 6);
	assert_int_equal(out[4], DXL_ERRBIT_INSTRUCTION);
}

static void test_read_block_and_present_values(void **state)
{
	(void)state;
	struct sim_servo s;
	uint8_t out[DXL_MAX_PACKET];
	servo_at_32c(&s);
	struct sim_servo_sense in = { .angle = 0.5, .speed = -1.0, .load_fraction = 0.25, .voltage = 11.1,
	                              .temperature = 40.4 };
	sim_servo_sense(&s, &in, 0.001);
	uint8_t rd[2] = { DXL_AX_PRESENT_POSITION, 8 };
	int n = req(&s, 1, DXL_INST_READ, rd, 2, out);
	assert_int_equal(n, 14);
	assert_int_equal(dxl_get_u16(&out[5]), dxl_rad_to_pos(0.5));
	assert_int_equal(dxl_get_u16(&out[7]), dxl_rad_s_to_speed(-1.0));
	assert_int_equal(dxl_get_u16(&out[9]), dxl_fraction_to_load(0.25));
	assert_int_equal(out[11], 111);
	assert_int_equal(out[12], 40);
	/* A READ past the table: range error. */
	uint8_t bad[2] = { 45, 10 };
	n = req(&s, 1, DXL_INST_READ, bad, 2, out);
	assert_int_equal(out[4], DXL_ERRBIT_RANGE);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_golden_ping),
		cmocka_unit_test(test_golden_read_temperature),
		cmocka_unit_test(test_golden_write),
		cmocka_unit_test(test_golden_broadcast_set_id),
		cmocka_unit_test(test_golden_sync_write),
		cmocka_unit_test(test_golden_reg_write_action),
		cmocka_unit_test(test_range_error_not_written),
		cmocka_unit_test(test_emanual_ranges),
		cmocka_unit_test(test_read_only_registers),
		cmocka_unit_test(test_angle_limit_error),
		cmocka_unit_test(test_wheel_mode),
		cmocka_unit_test(test_present_speed_by_mode),
		cmocka_unit_test(test_eeprom_vs_ram),
		cmocka_unit_test(test_max_torque_copied_at_power_on),
		cmocka_unit_test(test_status_return_levels),
		cmocka_unit_test(test_broadcast_behaviour),
		cmocka_unit_test(test_factory_reset),
		cmocka_unit_test(test_lock),
		cmocka_unit_test(test_alarm_shutdown_and_recovery),
		cmocka_unit_test(test_alarm_shutdown_every_bit),
		cmocka_unit_test(test_answered_before_the_write_acts),
		cmocka_unit_test(test_overheating_and_masks),
		cmocka_unit_test(test_bad_checksum_and_unknown_instruction),
		cmocka_unit_test(test_read_block_and_present_values),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
