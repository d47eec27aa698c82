/*
 * test_sim_xservo.c — the simulated X-series servo's control-table semantics
 * (sim-bridge/xservo.c), driven with raw instruction bytes and checked byte
 * for byte. The golden packets are typed in from the ROBOTIS e-manual's
 * "DYNAMIXEL Protocol 2.0" page (its worked examples, section by section as
 * each test says), never produced by our encoder: the simulator encodes its
 * replies with protocol/dxl2.c, so a symmetric bug would pass otherwise. The
 * manual's examples run on an XM430-W210 (model 1030, firmware 38): the
 * servo here is an XM430-W350 with those two registers poked, the one
 * difference between them that reaches the wire. The rest: every
 * instruction, every error number, the status return level, the alert bit
 * and the shutdown, the bus watchdog, operating modes and their limits.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "dxl2.h"
#include "dxl2_table.h"
#include "../../sim-bridge/xservo.h"

#define OUT 1024
#define PI 3.14159265358979323846

/* One instruction packet from raw bytes (must be exactly one). */
static void parse(const uint8_t *raw, size_t n, struct dxl2_packet *pkt)
{
	struct dxl2_parser p;
	size_t used = 0;
	dxl2_parser_init(&p, DXL2_PARSE_INSTRUCTION);
	assert_int_equal(dxl2_parser_feed(&p, raw, n, &used, pkt), DXL_FRAME);
	assert_int_equal(used, n);
}

static int send(struct sim_xservo *s, const uint8_t *raw, size_t n, uint8_t *out)
{
	static struct dxl2_packet pkt;
	parse(raw, n, &pkt);
	return sim_xservo_handle(s, &pkt, out, OUT);
}

#define SEND(s, out, ...) \
	send((s), (const uint8_t[]){ __VA_ARGS__ }, sizeof((const uint8_t[]){ __VA_ARGS__ }), (out))

static void expect_bytes(const uint8_t *got, int len, const uint8_t *want, size_t wn)
{
	assert_int_equal(len, (int)wn);
	assert_memory_equal(got, want, wn);
}
#define EXPECT(got, len, ...)                                               \
	do {                                                                \
		static const uint8_t want_[] = { __VA_ARGS__ };             \
		expect_bytes((got), (len), want_, sizeof(want_));          \
	} while (0)
#define HDR 0xFF, 0xFF, 0xFD, 0x00

/* A request built with our encoder, for the cases the manual prints none of
 * (what is checked is the servo's answer, parsed on the controller's side). */
static int req(struct sim_xservo *s, uint8_t id, uint8_t instr, const uint8_t *params, size_t n, uint8_t *out)
{
	uint8_t buf[DXL2_MAX_PACKET];
	int len = dxl2_encode_instruction(buf, sizeof buf, id, instr, params, n);
	assert_true(len > 0);
	return send(s, buf, (size_t)len, out);
}

/* The status packet in out: its ERR field (-1 if none), parameters in *st. */
static int status(const uint8_t *out, int len, uint8_t want_id, struct dxl2_packet *st)
{
	struct dxl2_parser p;
	size_t used = 0;
	if (len <= 0)
		return -1;
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	assert_int_equal(dxl2_parser_feed(&p, out, (size_t)len, &used, st), DXL_FRAME);
	assert_int_equal(used, (size_t)len);
	assert_int_equal(st->id, want_id);
	return st->err;
}

static int wr(struct sim_xservo *s, uint8_t id, uint16_t addr, uint32_t v, size_t size)
{
	uint8_t p[6] = { (uint8_t)addr, (uint8_t)(addr >> 8) }, out[OUT];
	dxl2_put_u32(&p[2], v);
	struct dxl2_packet st;
	return status(out, req(s, id, DXL2_INST_WRITE, p, 2 + size, out), id, &st);
}

static int32_t peek(const struct sim_xservo *s, uint16_t addr)
{
	int32_t v = 0;
	assert_int_equal(sim_xservo_peek(s, addr, &v), DXL_OK);
	return v;
}

/* A servo at rest at `pulses` (present position), 12 V, 25 °C. */
static void sense_at(struct sim_xservo *s, double pulses, double volts, double temp, double dt)
{
	struct sim_xservo_sense in = {
		.angle = (pulses - DXL2_POS_CENTER) * 2.0 * PI / DXL2_POS_PER_REV,
		.stall_torque = 4.1, .voltage = volts, .temperature = temp,
	};
	sim_xservo_sense(s, &in, dt);
}

/* The manual's servo: ID `id`, model 1030 and firmware 38 as its examples give. */
static void manual_servo(struct sim_xservo *s, uint8_t id, double pulses)
{
	sim_xservo_init(s, SIM_MODEL_XM430_W350, NULL, 0.0);
	sim_xservo_poke(s, DXL2_X_ID, id);
	sim_xservo_poke(s, DXL2_X_MODEL_NUMBER, 1030);
	sim_xservo_poke(s, DXL2_X_FIRMWARE_VERSION, 38);
	sense_at(s, pulses, 12.0, 25.0, 0.001);
}

/* ---- the indirect areas (e-manual, "Indirect Address, Indirect Data") ------------- */

/* A READ of n bytes at addr: the ERR field, the bytes in data. */
static int rd(struct sim_xservo *s, uint16_t addr, uint16_t n, uint8_t *data)
{
	uint8_t p[4] = { (uint8_t)addr, (uint8_t)(addr >> 8), (uint8_t)n, (uint8_t)(n >> 8) }, out[OUT];
	struct dxl2_packet st;
	int err = status(out, req(s, 1, DXL2_INST_READ, p, 4, out), 1, &st);
	if (err == 0) {
		assert_int_equal(st.nparams, n);
		memcpy(data, st.params, n);
	}
	return err;
}

/* A WRITE of n raw bytes at addr: the ERR field. */
static int wr_bytes(struct sim_xservo *s, uint16_t addr, const uint8_t *data, size_t n)
{
	uint8_t p[64] = { (uint8_t)addr, (uint8_t)(addr >> 8) }, out[OUT];
	struct dxl2_packet st;
	memcpy(&p[2], data, n);
	return status(out, req(s, 1, DXL2_INST_WRITE, p, 2 + n, out), 1, &st);
}

/* Factory values: Indirect Address n holds Indirect Data n's own address
 * (224.. and 634..), the data bytes read 0 and keep what is written (each
 * points at itself). The SDK's checks read 168 first: no access error. */
static void test_indirect_factory(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t b[56];
	sim_xservo_init(&s, SIM_MODEL_XL430_W250, NULL, 0.0);
	assert_int_equal(rd(&s, DXL2_X_INDIRECT_ADDRESS_1, 56, b), 0);
	for (int n = 0; n < 28; n++)
		assert_int_equal(b[2 * n] | b[2 * n + 1] << 8, 224 + n);
	assert_int_equal(peek(&s, DXL2_X_INDIRECT_ADDRESS_29), 634);
	assert_int_equal(peek(&s, 632), 661);    /* Indirect Address 56 */
	assert_int_equal(rd(&s, DXL2_X_INDIRECT_DATA_1, 28, b), 0);
	for (int n = 0; n < 28; n++)
		assert_int_equal(b[n], 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1 + 3, 0xA5, 1), 0);
	assert_int_equal(rd(&s, DXL2_X_INDIRECT_DATA_1 + 3, 1, b), 0);
	assert_int_equal(b[0], 0xA5);
	assert_int_equal(wr(&s, 1, 661, 0x5A, 1), 0);
	assert_int_equal(peek(&s, 661), 0x5A);
}

/* Mapped: Indirect Data n reads and writes the byte Indirect Address n
 * names, one byte each; the manual's examples (LED, then Goal Position by
 * four consecutive slots), Present Position read through four slots. */
static void test_indirect_read_write_through(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t b[8];
	sim_xservo_init(&s, SIM_MODEL_XM430_W350, NULL, 0.0);
	sense_at(&s, 3000, 12.0, 25.0, 0.001);
	/* Example 1: LED (65) in slot 1 */
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, DXL2_X_LED, 2), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1, 1, 1), 0);
	assert_int_equal(peek(&s, DXL2_X_LED), 1);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1, 0, 1), 0);
	assert_int_equal(peek(&s, DXL2_X_LED), 0);
	/* Example 2: Goal Position (116..119) in slots 2..5, written as one */
	uint8_t map[8] = { 116, 0, 117, 0, 118, 0, 119, 0 };
	assert_int_equal(wr_bytes(&s, DXL2_X_INDIRECT_ADDRESS_1 + 2, map, 8), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1 + 1, 1024, 4), 0);
	assert_int_equal(peek(&s, DXL2_X_GOAL_POSITION), 1024);
	assert_int_equal(rd(&s, DXL2_X_INDIRECT_DATA_1 + 1, 4, b), 0);
	assert_int_equal(dxl2_get_u32(b), 1024);
	/* Present Position (132..135) in slots 29..32: the second block */
	uint8_t pos[8] = { 132, 0, 133, 0, 134, 0, 135, 0 };
	assert_int_equal(wr_bytes(&s, DXL2_X_INDIRECT_ADDRESS_29, pos, 8), 0);
	assert_int_equal(rd(&s, DXL2_X_INDIRECT_DATA_29, 4, b), 0);
	assert_int_equal((int32_t)dxl2_get_u32(b), peek(&s, DXL2_X_PRESENT_POSITION));
	assert_int_equal((int32_t)dxl2_get_u32(b), 3000);
	/* a SYNC_READ of the indirect block answers the mapped bytes too */
	uint8_t sp[5] = { (uint8_t)DXL2_X_INDIRECT_DATA_29, DXL2_X_INDIRECT_DATA_29 >> 8, 4, 0, 1 }, out[OUT];
	struct dxl2_packet st;
	assert_int_equal(status(out, req(&s, DXL2_BROADCAST_ID, DXL2_INST_SYNC_READ, sp, 5, out), 1, &st), 0);
	assert_int_equal((int32_t)dxl2_get_u32(st.params), 3000);
}

/* The rules: an Indirect Address takes 64..661 only (data range error); it
 * is written with the torque off (access error else, as EEPROM, and kept
 * over a REBOOT); a write through Indirect Data obeys the target's own
 * rules: read-only (access), part of a register (data length), its range
 * and limit, EEPROM under torque. */
static void test_indirect_rules(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t b[4], out[OUT];
	sim_xservo_init(&s, SIM_MODEL_XM430_W350, NULL, 0.0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, 63, 2), DXL2_ERRNUM_DATA_RANGE);   /* EEPROM */
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, 662, 2), DXL2_ERRNUM_DATA_RANGE);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, 64, 1), DXL2_ERRNUM_DATA_LENGTH);
	assert_int_equal(peek(&s, DXL2_X_INDIRECT_ADDRESS_1), 224);
	/* read-only target: Present Position's first byte */
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, DXL2_X_PRESENT_POSITION, 2), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1, 0, 1), DXL2_ERRNUM_ACCESS);
	/* one byte of a 4-byte register: data length */
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, DXL2_X_GOAL_POSITION, 2), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1, 0, 1), DXL2_ERRNUM_DATA_LENGTH);
	/* range: Status Return Level takes 0..2 */
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, DXL2_X_STATUS_RETURN_LEVEL, 2), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1, 3, 1), DXL2_ERRNUM_DATA_RANGE);
	assert_int_equal(peek(&s, DXL2_X_STATUS_RETURN_LEVEL), 2);
	/* limit: Goal PWM (2 slots) beyond PWM Limit */
	uint8_t pwm[4] = { 100, 0, 101, 0 };
	assert_int_equal(wr_bytes(&s, DXL2_X_INDIRECT_ADDRESS_1 + 2, pwm, 4), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1 + 1, 900, 2), DXL2_ERRNUM_DATA_LIMIT);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1 + 1, 500, 2), 0);
	assert_int_equal(peek(&s, DXL2_X_GOAL_PWM), 500);
	/* torque on: the Indirect Address registers are locked, the data is not */
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, DXL2_X_LED, 2), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, 224, 2), DXL2_ERRNUM_ACCESS);
	assert_int_equal(peek(&s, DXL2_X_INDIRECT_ADDRESS_1), DXL2_X_LED);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_1, 1, 1), 0);
	assert_int_equal(peek(&s, DXL2_X_LED), 1);
	/* an indirect byte pointing at an Indirect Address register (168..,
	 * inside 64..661) writes it as that register: locked under torque too */
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 0, 1), 0);
	uint8_t ia[4] = { 170, 0, 171, 0 };
	assert_int_equal(wr_bytes(&s, DXL2_X_INDIRECT_ADDRESS_29, ia, 4), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_DATA_29, 65, 2), DXL2_ERRNUM_ACCESS);
	/* REBOOT keeps the mapping (kept as EEPROM) and answers first */
	uint8_t none[1];
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_REBOOT, none, 0, out), 1, &(struct dxl2_packet){ 0 }), 0);
	assert_int_equal(peek(&s, DXL2_X_INDIRECT_ADDRESS_1), DXL2_X_LED);
	assert_int_equal(rd(&s, DXL2_X_INDIRECT_DATA_1, 1, b), 0);
	assert_int_equal(b[0], 0);   /* LED back to its RAM default */
	/* FACTORY_RESET puts the factory mapping back */
	uint8_t all[1] = { DXL2_RESET_ALL };
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_FACTORY_RESET, all, 1, out), 1, &(struct dxl2_packet){ 0 }), 0);
	assert_int_equal(peek(&s, DXL2_X_INDIRECT_ADDRESS_1), 224);
	/* a servo without the areas ([sim] indirect = false): the access error */
	struct sim_xservo_options o;
	sim_xservo_default_options(&o);
	o.no_indirect = true;
	sim_xservo_init(&s, SIM_MODEL_XL430_W250, &o, 0.0);
	assert_int_equal(rd(&s, DXL2_X_INDIRECT_ADDRESS_1, 2, b), DXL2_ERRNUM_ACCESS);
	assert_int_equal(wr(&s, 1, DXL2_X_INDIRECT_ADDRESS_1, DXL2_X_LED, 2), DXL2_ERRNUM_ACCESS);
	assert_int_equal(rd(&s, DXL2_X_PRESENT_TEMPERATURE, 1, b), 0);
}

/* ---- the e-manual's examples --------------------------------------------------- */

static void test_golden_ping(void **state)
{
	(void)state;
	struct sim_xservo s1, s2;
	uint8_t out[OUT];
	manual_servo(&s1, 1, 2048);
	manual_servo(&s2, 2, 2048);
	/* Ping, Example 1 */
	int n = SEND(&s1, out, HDR, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E);
	EXPECT(out, n, HDR, 0x01, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D);
	/* Ping, Example 2: broadcast; each servo answers (the bus orders them) */
	n = SEND(&s1, out, HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42);
	EXPECT(out, n, HDR, 0x01, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D);
	n = SEND(&s2, out, HDR, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42);
	EXPECT(out, n, HDR, 0x02, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x6F, 0x6D);
}

static void test_golden_read(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	manual_servo(&s, 1, 166);   /* Read: "Present Position(132) = 166" */
	int n = SEND(&s, out, HDR, 0x01, 0x07, 0x00, 0x02, 0x84, 0x00, 0x04, 0x00, 0x1D, 0x15);
	EXPECT(out, n, HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0);
}

static void test_golden_write(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	manual_servo(&s, 1, 2048);
	/* Write: 512 to Goal Position(116) */
	int n = SEND(&s, out, HDR, 0x01, 0x09, 0x00, 0x03, 0x74, 0x00, 0x00, 0x02, 0x00, 0x00, 0xCA, 0x89);
	EXPECT(out, n, HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C);
	assert_int_equal(peek(&s, DXL2_X_GOAL_POSITION), 512);
}

static void test_golden_reg_write_action(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	manual_servo(&s, 1, 2048);
	/* Reg Write: 200 to Goal Velocity(104); registered, not yet written */
	int n = SEND(&s, out, HDR, 0x01, 0x09, 0x00, 0x04, 0x68, 0x00, 0xC8, 0x00, 0x00, 0x00, 0xAE, 0x8E);
	EXPECT(out, n, HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C);
	assert_int_equal(peek(&s, DXL2_X_REGISTERED_INSTRUCTION), 1);
	assert_int_equal(peek(&s, DXL2_X_GOAL_VELOCITY), 0);
	/* Action */
	n = SEND(&s, out, HDR, 0x01, 0x03, 0x00, 0x05, 0x02, 0xCE);
	EXPECT(out, n, HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C);
	assert_int_equal(peek(&s, DXL2_X_GOAL_VELOCITY), 200);
	assert_int_equal(peek(&s, DXL2_X_REGISTERED_INSTRUCTION), 0);
	/* a second ACTION has nothing to execute: instruction error (2) */
	n = SEND(&s, out, HDR, 0x01, 0x03, 0x00, 0x05, 0x02, 0xCE);
	struct dxl2_packet st;
	assert_int_equal(status(out, n, 1, &st), DXL2_ERRNUM_INSTRUCTION);
	assert_int_equal(s.count.instruction_errors, 1);
}

static void test_golden_factory_reset(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	manual_servo(&s, 1, 2048);
	assert_int_equal(wr(&s, 1, DXL2_X_RETURN_DELAY_TIME, 0, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_BAUD_RATE, 3, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_LED, 1, 1), 0);
	/* Factory Reset, option 0x01: everything but the ID */
	int n = SEND(&s, out, HDR, 0x01, 0x04, 0x00, 0x06, 0x01, 0xA1, 0xE6);
	EXPECT(out, n, HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C);
	assert_int_equal(peek(&s, DXL2_X_ID), 1);
	assert_int_equal(peek(&s, DXL2_X_RETURN_DELAY_TIME), 250);
	assert_int_equal(peek(&s, DXL2_X_BAUD_RATE), 1);
	assert_int_equal(peek(&s, DXL2_X_MODEL_NUMBER), DXL2_MODEL_XM430_W350);
	assert_int_equal(peek(&s, DXL2_X_LED), 0);   /* it booted: RAM too */
}

static void test_golden_reboot_clear(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	manual_servo(&s, 1, 2048);
	assert_int_equal(wr(&s, 1, DXL2_X_LED, 1, 1), 0);
	/* Reboot */
	int n = SEND(&s, out, HDR, 0x01, 0x03, 0x00, 0x08, 0x2F, 0x4E);
	EXPECT(out, n, HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C);
	assert_int_equal(peek(&s, DXL2_X_LED), 0);
	assert_int_equal(s.count.reboots, 1);
	/* Clear: in Extended Position Control Mode, two turns and a bit out */
	assert_int_equal(wr(&s, 1, DXL2_X_OPERATING_MODE, DXL2_OPMODE_EXTENDED_POSITION, 1), 0);
	sense_at(&s, 2 * 4096 + 300, 12.0, 25.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_PRESENT_POSITION), 2 * 4096 + 300);
	n = SEND(&s, out, HDR, 0x01, 0x08, 0x00, 0x10, 0x01, 0x44, 0x58, 0x4C, 0x22, 0xB1, 0xDC);
	EXPECT(out, n, HDR, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C);
	assert_int_equal(peek(&s, DXL2_X_PRESENT_POSITION), 300);
	sense_at(&s, 2 * 4096 + 310, 12.0, 25.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_PRESENT_POSITION), 310);   /* and stays cleared */
}

static void test_golden_sync_read_write(void **state)
{
	(void)state;
	struct sim_xservo s1, s2;
	uint8_t out[OUT];
	manual_servo(&s1, 1, 166);
	manual_servo(&s2, 2, 2079);
	/* Sync Read: Present Position of IDs 1 and 2 */
#define SYNC_READ HDR, 0xFE, 0x09, 0x00, 0x82, 0x84, 0x00, 0x04, 0x00, 0x01, 0x02, 0xCE, 0xFA
	int n = SEND(&s1, out, SYNC_READ);
	EXPECT(out, n, HDR, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0);
	n = SEND(&s2, out, SYNC_READ);
	EXPECT(out, n, HDR, 0x02, 0x08, 0x00, 0x55, 0x00, 0x1F, 0x08, 0x00, 0x00, 0xBA, 0xBE);
	/* Sync Write: Goal Position 150 to ID 1, 170 to ID 2; no status */
#define SYNC_WRITE HDR, 0xFE, 0x11, 0x00, 0x83, 0x74, 0x00, 0x04, 0x00, 0x01, 0x96, 0x00, 0x00, 0x00, \
	0x02, 0xAA, 0x00, 0x00, 0x00, 0x82, 0x87
	assert_int_equal(SEND(&s1, out, SYNC_WRITE), 0);
	assert_int_equal(SEND(&s2, out, SYNC_WRITE), 0);
	assert_int_equal(peek(&s1, DXL2_X_GOAL_POSITION), 150);
	assert_int_equal(peek(&s2, DXL2_X_GOAL_POSITION), 170);
	/* a servo the list does not name is not addressed */
	struct sim_xservo s3;
	manual_servo(&s3, 3, 2048);
	assert_int_equal(SEND(&s3, out, SYNC_READ), 0);
	assert_int_equal(s3.count.instructions, 0);
}

static void test_golden_bulk_read_write(void **state)
{
	(void)state;
	struct sim_xservo s1, s2;
	uint8_t out[OUT];
	manual_servo(&s1, 1, 2048);
	manual_servo(&s2, 2, 2048);
	sense_at(&s1, 2048, 11.9, 25.0, 0.001);   /* "Present Voltage = 119" */
	sense_at(&s2, 2048, 12.0, 36.0, 0.001);   /* "Present Temperature = 36" */
#define BULK_READ HDR, 0xFE, 0x0D, 0x00, 0x92, 0x01, 0x90, 0x00, 0x02, 0x00, 0x02, 0x92, 0x00, 0x01, 0x00, \
	0x1A, 0x05
	int n = SEND(&s1, out, BULK_READ);
	EXPECT(out, n, HDR, 0x01, 0x06, 0x00, 0x55, 0x00, 0x77, 0x00, 0xC3, 0x69);
	n = SEND(&s2, out, BULK_READ);
	EXPECT(out, n, HDR, 0x02, 0x05, 0x00, 0x55, 0x00, 0x24, 0x8B, 0xA9);
	/* Bulk Write: Max Voltage Limit 160 to ID 1, Temperature Limit 80 to ID 2 */
	assert_int_equal(wr(&s1, 1, DXL2_X_MAX_VOLTAGE_LIMIT, 150, 2), 0);
	assert_int_equal(wr(&s2, 2, DXL2_X_TEMPERATURE_LIMIT, 70, 1), 0);
#define BULK_WRITE HDR, 0xFE, 0x10, 0x00, 0x93, 0x01, 0x20, 0x00, 0x02, 0x00, 0xA0, 0x00, 0x02, 0x1F, 0x00, \
	0x01, 0x00, 0x50, 0xB7, 0x68
	assert_int_equal(SEND(&s1, out, BULK_WRITE), 0);
	assert_int_equal(SEND(&s2, out, BULK_WRITE), 0);
	assert_int_equal(peek(&s1, DXL2_X_MAX_VOLTAGE_LIMIT), 160);
	assert_int_equal(peek(&s2, DXL2_X_TEMPERATURE_LIMIT), 80);
	assert_int_equal(peek(&s1, DXL2_X_TEMPERATURE_LIMIT), 80);   /* its own default, untouched */
}

/* ---- every error number -------------------------------------------------------- */

static void test_error_numbers(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	struct dxl2_packet st;
	sim_xservo_init(&s, SIM_MODEL_XL430_W250, NULL, 0.0);
	sense_at(&s, 2048, 12.0, 25.0, 0.001);
	/* 2 instruction: an instruction the servo does not have */
	assert_int_equal(status(out, req(&s, 1, 0x07, NULL, 0, out), 1, &st), DXL2_ERRNUM_INSTRUCTION);
	/* 4 data range: temperature limit 101 (0..100); a mode the XL430 lacks */
	assert_int_equal(wr(&s, 1, DXL2_X_TEMPERATURE_LIMIT, 101, 1), DXL2_ERRNUM_DATA_RANGE);
	assert_int_equal(peek(&s, DXL2_X_TEMPERATURE_LIMIT), 72);
	assert_int_equal(wr(&s, 1, DXL2_X_OPERATING_MODE, DXL2_OPMODE_CURRENT, 1), DXL2_ERRNUM_DATA_RANGE);
	assert_int_equal(wr(&s, 1, DXL2_X_OPERATING_MODE, DXL2_OPMODE_CURRENT_POSITION, 1), DXL2_ERRNUM_DATA_RANGE);
	assert_int_equal(wr(&s, 1, DXL2_X_OPERATING_MODE, 2, 1), DXL2_ERRNUM_DATA_RANGE);
	/* 5 data length: two bytes of the four-byte Goal Position */
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION, 1000, 2), DXL2_ERRNUM_DATA_LENGTH);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION + 2, 0, 2), DXL2_ERRNUM_DATA_LENGTH);
	assert_int_equal(peek(&s, DXL2_X_GOAL_POSITION), 2048);
	/* 6 data limit: beyond the limit registers */
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION, 4096, 4), DXL2_ERRNUM_DATA_LIMIT);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_VELOCITY, 266, 4), DXL2_ERRNUM_DATA_LIMIT);   /* limit 265 */
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_VELOCITY, (uint32_t)-266, 4), DXL2_ERRNUM_DATA_LIMIT);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_VELOCITY, (uint32_t)-265, 4), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_MIN_POSITION_LIMIT, 1000, 4), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION, 999, 4), DXL2_ERRNUM_DATA_LIMIT);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION, 1000, 4), 0);
	/* ... also beyond the register's widest range: the limits bind here */
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION, 1048576, 4), DXL2_ERRNUM_DATA_LIMIT);
	/* ... in Extended Position Control Mode the limits do not bind */
	assert_int_equal(wr(&s, 1, DXL2_X_OPERATING_MODE, DXL2_OPMODE_EXTENDED_POSITION, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION, 100000, 4), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION, 1048576, 4), DXL2_ERRNUM_DATA_RANGE);
	/* 7 access: read-only, a gap, EEPROM with torque on, past the table */
	assert_int_equal(wr(&s, 1, DXL2_X_MODEL_NUMBER, 12, 2), DXL2_ERRNUM_ACCESS);
	assert_int_equal(wr(&s, 1, DXL2_X_PRESENT_POSITION, 0, 4), DXL2_ERRNUM_ACCESS);
	assert_int_equal(wr(&s, 1, 14, 0, 1), DXL2_ERRNUM_ACCESS);
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_RETURN_DELAY_TIME, 0, 1), DXL2_ERRNUM_ACCESS);
	assert_int_equal(peek(&s, DXL2_X_RETURN_DELAY_TIME), 250);
	uint8_t past[4] = { 0x94, 0x02, 4, 0 };   /* 660..663: the table ends at 661 */
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_READ, past, 4, out), 1, &st), DXL2_ERRNUM_ACCESS);
	/* a write is atomic: one refused byte refuses it all (LED 1, then a read-only byte) */
	uint8_t p[5] = { DXL2_X_LED, 0, 1, 0, 0 };
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_WRITE, p, 5, out), 1, &st), DXL2_ERRNUM_ACCESS);
	assert_int_equal(peek(&s, DXL2_X_LED), 0);
	/* 3 CRC: a packet to this ID with a bad CRC */
	assert_int_equal(status(out, sim_xservo_handle_bad_crc(&s, 1, DXL2_INST_PING, out, OUT), 1, &st), DXL2_ERRNUM_CRC);
	assert_int_equal(sim_xservo_handle_bad_crc(&s, 2, DXL2_INST_PING, out, OUT), 0);
	/* 1 result fail: CLEAR while the servo moves */
	struct sim_xservo_sense moving = { .angle = 0, .speed = 3.0, .stall_torque = 1.5, .voltage = 12, .temperature = 25 };
	sim_xservo_sense(&s, &moving, 0.001);
	static const uint8_t key[5] = { 0x01, 0x44, 0x58, 0x4C, 0x22 };
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_CLEAR, key, 5, out), 1, &st), DXL2_ERRNUM_RESULT_FAIL);
	static const uint8_t wrong_key[5] = { 0x01, 0x44, 0x58, 0x4C, 0x23 };
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_CLEAR, wrong_key, 5, out), 1, &st), DXL2_ERRNUM_DATA_RANGE);
	assert_int_equal(s.count.result_fail, 1);
	assert_true(s.count.access_errors >= 5 && s.count.data_limit_errors == 5 && s.count.data_length_errors == 2);
}

static void test_status_return_level_and_broadcast(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	struct dxl2_packet st;
	uint8_t rd[4] = { DXL2_X_ID, 0, 1, 0 };
	sim_xservo_init(&s, SIM_MODEL_XL430_W250, NULL, 0.0);
	/* broadcast: no status for READ or WRITE (e-manual), PING always */
	assert_int_equal(req(&s, DXL2_BROADCAST_ID, DXL2_INST_READ, rd, 4, out), 0);
	uint8_t led[3] = { DXL2_X_LED, 0, 1 };
	assert_int_equal(req(&s, DXL2_BROADCAST_ID, DXL2_INST_WRITE, led, 3, out), 0);
	assert_int_equal(peek(&s, DXL2_X_LED), 1);
	assert_true(req(&s, DXL2_BROADCAST_ID, DXL2_INST_PING, NULL, 0, out) > 0);
	/* level 1: PING and READ; the write of the level itself is answered */
	assert_int_equal(wr(&s, 1, DXL2_X_STATUS_RETURN_LEVEL, 1, 1), 0);
	assert_int_equal(req(&s, 1, DXL2_INST_WRITE, led, 3, out), 0);
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_READ, rd, 4, out), 1, &st), 0);
	assert_int_equal(st.params[0], 1);
	/* level 0: PING only */
	uint8_t lv0[3] = { DXL2_X_STATUS_RETURN_LEVEL, 0, 0 };
	assert_int_equal(req(&s, 1, DXL2_INST_WRITE, lv0, 3, out), 0);
	assert_int_equal(req(&s, 1, DXL2_INST_READ, rd, 4, out), 0);
	assert_true(req(&s, 1, DXL2_INST_PING, NULL, 0, out) > 0);
	/* an ID write is answered under the old ID */
	uint8_t lv2[3] = { DXL2_X_STATUS_RETURN_LEVEL, 0, 2 };
	assert_int_equal(req(&s, 1, DXL2_INST_WRITE, lv2, 3, out), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_ID, 7, 1), 0);
	assert_int_equal(sim_xservo_id(&s), 7);
	assert_int_equal(req(&s, 1, DXL2_INST_PING, NULL, 0, out), 0);
	/* FACTORY_RESET broadcast with "reset all" does nothing (firmware 42+) */
	uint8_t all = DXL2_RESET_ALL;
	assert_int_equal(req(&s, DXL2_BROADCAST_ID, DXL2_INST_FACTORY_RESET, &all, 1, out), 0);
	assert_int_equal(sim_xservo_id(&s), 7);
	assert_int_equal(status(out, req(&s, 7, DXL2_INST_FACTORY_RESET, &all, 1, out), 7, &st), 0);
	assert_int_equal(sim_xservo_id(&s), 1);
	uint8_t bad = 0x03;
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_FACTORY_RESET, &bad, 1, out), 1, &st), DXL2_ERRNUM_DATA_RANGE);
}

/* ---- hardware errors, the alert bit, the shutdown, REBOOT ------------------------ */

static void test_alert_shutdown_reboot(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	struct dxl2_packet st;
	sim_xservo_init(&s, SIM_MODEL_XL430_W250, NULL, 0.0);
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	/* input voltage is not in the factory Shutdown (52): reported, torque stays */
	sense_at(&s, 2048, 15.0, 25.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_HARDWARE_ERROR_STATUS), DXL2_HWERR_VOLTAGE);
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_PING, NULL, 0, out), 1, &st), DXL2_ERR_ALERT);
	assert_int_equal(peek(&s, DXL2_X_TORQUE_ENABLE), 1);
	sense_at(&s, 2048, 12.0, 25.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_HARDWARE_ERROR_STATUS), 0);
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_PING, NULL, 0, out), 1, &st), 0);
	/* overheating is: torque off, the alert in every status, until REBOOT */
	sense_at(&s, 2048, 12.0, 73.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_TORQUE_ENABLE), 0);
	assert_int_equal(s.count.shutdowns, 1);
	sense_at(&s, 2048, 12.0, 30.0, 0.001);   /* cooled down: still latched */
	assert_int_equal(peek(&s, DXL2_X_HARDWARE_ERROR_STATUS), DXL2_HWERR_OVERHEAT);
	assert_int_equal(wr(&s, 1, DXL2_X_LED, 1, 1), DXL2_ERR_ALERT);
	/* torque on is refused: only REBOOT resets it (result fail, alert) */
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), DXL2_ERR_ALERT | DXL2_ERRNUM_RESULT_FAIL);
	assert_int_equal(peek(&s, DXL2_X_TORQUE_ENABLE), 0);
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_REBOOT, NULL, 0, out), 1, &st), DXL2_ERR_ALERT);
	assert_int_equal(peek(&s, DXL2_X_HARDWARE_ERROR_STATUS), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	/* an injected hardware error (poke) in the mask shuts it down too */
	sim_xservo_poke(&s, DXL2_X_HARDWARE_ERROR_STATUS, DXL2_HWERR_SHOCK);
	assert_int_equal(peek(&s, DXL2_X_TORQUE_ENABLE), 0);
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_PING, NULL, 0, out), 1, &st), DXL2_ERR_ALERT);
	/* overload: the motor at its cap for overload_time (0.5 s) */
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_REBOOT, NULL, 0, out), 1, &st), DXL2_ERR_ALERT);
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	struct sim_xservo_sense pushed = { .stall_torque = 1.5, .torque = 1.5, .voltage = 12, .temperature = 25,
	                                   .overloaded = true };
	for (int i = 0; i < 499; i++)
		sim_xservo_sense(&s, &pushed, 0.001);
	assert_int_equal(peek(&s, DXL2_X_TORQUE_ENABLE), 1);
	sim_xservo_sense(&s, &pushed, 0.002);
	assert_int_equal(peek(&s, DXL2_X_HARDWARE_ERROR_STATUS), DXL2_HWERR_OVERLOAD);
	assert_int_equal(peek(&s, DXL2_X_TORQUE_ENABLE), 0);
}

/* ---- the bus watchdog (e-manual, Bus Watchdog(98), its example) --------------------- */

static void test_bus_watchdog(void **state)
{
	(void)state;
	struct sim_xservo s;
	sim_xservo_init(&s, SIM_MODEL_XL430_W250, NULL, 0.0);
	/* 1-2: velocity mode, torque on, Goal Velocity 50 */
	assert_int_equal(wr(&s, 1, DXL2_X_OPERATING_MODE, DXL2_OPMODE_VELOCITY, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_VELOCITY, 50, 4), 0);
	/* 3: watchdog 100 (2000 ms) */
	assert_int_equal(wr(&s, 1, DXL2_X_BUS_WATCHDOG, 100, 1), 0);
	for (int i = 0; i < 1999; i++)
		sense_at(&s, 2048, 12.0, 25.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_BUS_WATCHDOG), 100);
	/* an instruction restarts the interval */
	assert_int_equal(wr(&s, 1, DXL2_X_LED, 0, 1), 0);
	for (int i = 0; i < 1999; i++)
		sense_at(&s, 2048, 12.0, 25.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_BUS_WATCHDOG), 100);
	/* 4-5: 2000 ms without an instruction: stopped, the register reads -1 */
	sense_at(&s, 2048, 12.0, 25.0, 0.002);
	assert_int_equal(peek(&s, DXL2_X_BUS_WATCHDOG), SIM_XSERVO_WATCHDOG_ERROR);
	assert_int_equal(peek(&s, DXL2_X_GOAL_VELOCITY), 0);
	assert_int_equal(s.count.watchdog_trips, 1);
	struct sim_xdrive_cmd c;
	sim_xservo_drive_cmd(&s, &c);
	assert_true(c.step_profile);
	/* 6: a goal is refused with the data range error; so is another timeout */
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_VELOCITY, 150, 4), DXL2_ERRNUM_DATA_RANGE);
	assert_int_equal(wr(&s, 1, DXL2_X_BUS_WATCHDOG, 50, 1), DXL2_ERRNUM_DATA_RANGE);
	/* 7-8: 0 clears it; then the goal is taken */
	assert_int_equal(wr(&s, 1, DXL2_X_BUS_WATCHDOG, 0, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_VELOCITY, 150, 4), 0);
	/* with torque off the watchdog does not act */
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 0, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_BUS_WATCHDOG, 1, 1), 0);
	for (int i = 0; i < 100; i++)
		sense_at(&s, 2048, 12.0, 25.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_BUS_WATCHDOG), 1);
	/* in position mode a stop holds where the joint stands */
	assert_int_equal(wr(&s, 1, DXL2_X_OPERATING_MODE, DXL2_OPMODE_POSITION, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(wr(&s, 1, DXL2_X_GOAL_POSITION, 3000, 4), 0);
	for (int i = 0; i < 25; i++)
		sense_at(&s, 2100, 12.0, 25.0, 0.001);
	assert_int_equal(peek(&s, DXL2_X_BUS_WATCHDOG), SIM_XSERVO_WATCHDOG_ERROR);
	assert_int_equal(peek(&s, DXL2_X_GOAL_POSITION), 2100);
}

/* ---- operating modes and the registers they reset ------------------------------------- */

static void test_operating_modes(void **state)
{
	(void)state;
	struct sim_xservo xl, xm;
	sim_xservo_init(&xl, SIM_MODEL_XL430_W250, NULL, 0.0);
	sim_xservo_init(&xm, SIM_MODEL_XM430_W350, NULL, 0.0);
	/* the XM430 has every mode, the XL430 no current modes */
	static const uint8_t modes[] = { 0, 1, 3, 4, 5, 16 };
	for (size_t i = 0; i < sizeof modes; i++) {
		assert_int_equal(wr(&xm, 1, DXL2_X_OPERATING_MODE, modes[i], 1), 0);
		int want = modes[i] == 0 || modes[i] == 5 ? DXL2_ERRNUM_DATA_RANGE : 0;
		assert_int_equal(wr(&xl, 1, DXL2_X_OPERATING_MODE, modes[i], 1), want);
	}
	/* a mode change resets the profile, Goal PWM and the gains (e-manual) */
	assert_int_equal(wr(&xl, 1, DXL2_X_OPERATING_MODE, DXL2_OPMODE_POSITION, 1), 0);
	assert_int_equal(wr(&xl, 1, DXL2_X_PROFILE_VELOCITY, 100, 4), 0);
	assert_int_equal(wr(&xl, 1, DXL2_X_PROFILE_ACCELERATION, 10, 4), 0);
	assert_int_equal(wr(&xl, 1, DXL2_X_GOAL_PWM, 300, 2), 0);
	assert_int_equal(wr(&xl, 1, DXL2_X_POSITION_P_GAIN, 100, 2), 0);
	/* beyond +-885 is beyond every PWM Limit: the same mistake as 401 with
	 * limit 400 below, the same error number (data limit, the e-manual's
	 * range of Goal PWM is -PWM Limit..PWM Limit) */
	assert_int_equal(wr(&xl, 1, DXL2_X_GOAL_PWM, 886, 2), DXL2_ERRNUM_DATA_LIMIT);
	assert_int_equal(wr(&xl, 1, DXL2_X_GOAL_PWM, (uint32_t)-886, 2), DXL2_ERRNUM_DATA_LIMIT);
	assert_int_equal(wr(&xl, 1, DXL2_X_OPERATING_MODE, DXL2_OPMODE_VELOCITY, 1), 0);
	assert_int_equal(peek(&xl, DXL2_X_PROFILE_VELOCITY), 0);
	assert_int_equal(peek(&xl, DXL2_X_PROFILE_ACCELERATION), 0);
	assert_int_equal(peek(&xl, DXL2_X_GOAL_PWM), 885);
	assert_int_equal(peek(&xl, DXL2_X_POSITION_P_GAIN), 640);
	/* limits lowered bind the goals: PWM limit 400 refuses Goal PWM 401 */
	assert_int_equal(wr(&xl, 1, DXL2_X_PWM_LIMIT, 400, 2), 0);
	assert_int_equal(wr(&xl, 1, DXL2_X_GOAL_PWM, 401, 2), DXL2_ERRNUM_DATA_LIMIT);
	assert_int_equal(wr(&xl, 1, DXL2_X_GOAL_PWM, (uint32_t)-400, 2), 0);
	/* XM430: Goal Current within Current Limit */
	assert_int_equal(wr(&xm, 1, DXL2_X_GOAL_CURRENT, 1193, 2), 0);
	assert_int_equal(wr(&xm, 1, DXL2_X_CURRENT_LIMIT, 500, 2), 0);
	assert_int_equal(wr(&xm, 1, DXL2_X_GOAL_CURRENT, 501, 2), DXL2_ERRNUM_DATA_LIMIT);
	assert_int_equal(wr(&xm, 1, DXL2_X_GOAL_CURRENT, 1194, 2), DXL2_ERRNUM_DATA_LIMIT);
	/* the limit registers themselves have fixed ranges: data range */
	assert_int_equal(wr(&xm, 1, DXL2_X_CURRENT_LIMIT, 1194, 2), DXL2_ERRNUM_DATA_RANGE);
	struct sim_xdrive_cmd c;
	sim_xservo_drive_cmd(&xm, &c);
	assert_int_equal(c.current_limit, 500);
	sim_xservo_drive_cmd(&xl, &c);
	assert_int_equal(c.current_limit, -1);
	assert_int_equal(c.goal_pwm, -400);
	/* Drive Mode bit 3 (XL430): a goal turns the torque on */
	assert_int_equal(wr(&xl, 1, DXL2_X_DRIVE_MODE, 8, 1), 0);
	assert_int_equal(wr(&xl, 1, DXL2_X_GOAL_VELOCITY, 10, 4), 0);
	assert_int_equal(peek(&xl, DXL2_X_TORQUE_ENABLE), 1);
}

/* ---- present values, Moving, Moving Status, Realtime Tick --------------------------- */

static void test_present_values(void **state)
{
	(void)state;
	struct sim_xservo xl, xm;
	sim_xservo_init(&xl, SIM_MODEL_XL430_W250, NULL, 0.0);
	sim_xservo_init(&xm, SIM_MODEL_XM430_W350, NULL, 0.0);
	struct sim_xservo_sense in = { .angle = 0.5, .speed = -1.0, .torque = 0.75, .stall_torque = 1.5,
	                               .duty = 0.5, .voltage = 11.1, .temperature = 40.4 };
	sim_xservo_sense(&xl, &in, 0.001);
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_POSITION), 2048 + 326);   /* 0.5 rad = 325.95 pulses */
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_VELOCITY), -42);        /* -1 rad/s / 0.02398 */
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_LOAD), 500);            /* 50.0 % */
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_PWM), 443);             /* 885 / 2 */
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_INPUT_VOLTAGE), 111);
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_TEMPERATURE), 40);
	assert_int_equal(peek(&xl, DXL2_X_MOVING), 1);                    /* 42 > threshold 10 */
	/* XM430: Present Current = torque / (4.1 N·m / 2.3 A), 2.69 mA a unit */
	in.torque = 1.0;
	sim_xservo_sense(&xm, &in, 0.001);
	assert_int_equal(peek(&xm, DXL2_X_PRESENT_CURRENT), 209);   /* 0.561 A */
	/* Drive Mode bit 0 reverses every direction */
	assert_int_equal(wr(&xl, 1, DXL2_X_DRIVE_MODE, 1, 1), 0);
	sim_xservo_sense(&xl, &in, 0.001);
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_POSITION), 2048 - 326);
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_VELOCITY), 42);
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_LOAD), -667);
	/* Homing Offset adds to Present Position */
	assert_int_equal(wr(&xl, 1, DXL2_X_HOMING_OFFSET, 1000, 4), 0);
	sim_xservo_sense(&xl, &in, 0.001);
	assert_int_equal(peek(&xl, DXL2_X_PRESENT_POSITION), 2048 - 326 + 1000);
	/* Realtime Tick: ms since the boot, wrapping after 32767 */
	assert_int_equal(peek(&xm, DXL2_X_REALTIME_TICK), 1);
	for (int i = 0; i < 1499; i++)
		sim_xservo_sense(&xm, &in, 0.001);
	assert_int_equal(peek(&xm, DXL2_X_REALTIME_TICK), 1500);
	sim_xservo_sense(&xm, &in, 31.268);
	assert_int_equal(peek(&xm, DXL2_X_REALTIME_TICK), 0);
	/* at rest: not moving */
	struct sim_xservo_sense rest = { .stall_torque = 1.5, .voltage = 12, .temperature = 25 };
	sim_xservo_sense(&xm, &rest, 0.001);
	assert_int_equal(peek(&xm, DXL2_X_MOVING), 0);
	/* power loss: silent, torque off; power on: RAM reset, EEPROM kept */
	assert_int_equal(wr(&xm, 1, DXL2_X_TORQUE_ENABLE, 1, 1), 0);
	assert_int_equal(wr(&xm, 1, DXL2_X_RETURN_DELAY_TIME, 5, 1), DXL2_ERRNUM_ACCESS);
	assert_int_equal(wr(&xm, 1, DXL2_X_TORQUE_ENABLE, 0, 1), 0);
	assert_int_equal(wr(&xm, 1, DXL2_X_RETURN_DELAY_TIME, 5, 1), 0);
	assert_int_equal(wr(&xm, 1, DXL2_X_LED, 1, 1), 0);
	sim_xservo_power_off(&xm);
	uint8_t out[OUT];
	assert_int_equal(req(&xm, 1, DXL2_INST_PING, NULL, 0, out), 0);
	sim_xservo_power_on(&xm, 0.25);
	assert_int_equal(peek(&xm, DXL2_X_LED), 0);
	assert_int_equal(peek(&xm, DXL2_X_RETURN_DELAY_TIME), 5);
	assert_int_equal(peek(&xm, DXL2_X_GOAL_POSITION), peek(&xm, DXL2_X_PRESENT_POSITION));
	assert_int_equal(peek(&xm, DXL2_X_GOAL_CURRENT), 1193);
	assert_int_equal(peek(&xm, DXL2_X_REALTIME_TICK), 0);
}

/* SYNC/BULK packets that do not parse to their end are ignored by all. */
static void test_malformed_multi(void **state)
{
	(void)state;
	struct sim_xservo s;
	uint8_t out[OUT];
	sim_xservo_init(&s, SIM_MODEL_XL430_W250, NULL, 0.0);
	/* SYNC_WRITE addr 65, len 1, then ID 1 and two data bytes (one too many) */
	uint8_t sw[] = { 65, 0, 1, 0, 1, 1, 1 };
	assert_int_equal(req(&s, DXL2_BROADCAST_ID, DXL2_INST_SYNC_WRITE, sw, sizeof sw, out), 0);
	assert_int_equal(peek(&s, DXL2_X_LED), 0);
	assert_int_equal(s.count.instructions, 0);
	/* BULK_READ cut inside its second item */
	uint8_t br[] = { 1, 65, 0, 1, 0, 2, 65 };
	assert_int_equal(req(&s, DXL2_BROADCAST_ID, DXL2_INST_BULK_READ, br, sizeof br, out), 0);
	/* a unicast SYNC_READ: the instruction error */
	uint8_t sr[] = { 65, 0, 1, 0, 1 };
	struct dxl2_packet st;
	assert_int_equal(status(out, req(&s, 1, DXL2_INST_SYNC_READ, sr, sizeof sr, out), 1, &st), DXL2_ERRNUM_INSTRUCTION);
	/* a well-formed BULK_WRITE of the LED */
	uint8_t bw[] = { 2, 65, 0, 1, 0, 1, 1, 65, 0, 1, 0, 1 };
	assert_int_equal(req(&s, DXL2_BROADCAST_ID, DXL2_INST_BULK_WRITE, bw, sizeof bw, out), 0);
	assert_int_equal(peek(&s, DXL2_X_LED), 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_golden_ping),
		cmocka_unit_test(test_golden_read),
		cmocka_unit_test(test_golden_write),
		cmocka_unit_test(test_golden_reg_write_action),
		cmocka_unit_test(test_golden_factory_reset),
		cmocka_unit_test(test_golden_reboot_clear),
		cmocka_unit_test(test_golden_sync_read_write),
		cmocka_unit_test(test_golden_bulk_read_write),
		cmocka_unit_test(test_error_numbers),
		cmocka_unit_test(test_status_return_level_and_broadcast),
		cmocka_unit_test(test_alert_shutdown_reboot),
		cmocka_unit_test(test_bus_watchdog),
		cmocka_unit_test(test_operating_modes),
		cmocka_unit_test(test_present_values),
		cmocka_unit_test(test_malformed_multi),
		cmocka_unit_test(test_indirect_factory),
		cmocka_unit_test(test_indirect_read_write_through),
		cmocka_unit_test(test_indirect_rules),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
