/*
 * test_daemon_servomodel.c — the servo families (servo_model.h): which
 * model a PING's number names, units both ways, the present block and the
 * read-back blocks decoded from bytes laid out by hand from the e-manual's
 * control tables (not from our encoder), the status field's meaning per
 * protocol, and torque actuation's raw outputs within the servo's limits.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../../daemon/config.h"
#include "../../daemon/control.h"
#include "../../daemon/servo_model.h"
#include "dxl.h"
#include "dxl_table.h"

#define PI 3.14159265358979323846

/* What differs between families is asked as capabilities: the AX-12A has
 * neither, every X model (made from its descriptor) both; the register names
 * come from the model's own table. */
static void test_capabilities(void **state)
{
	(void)state;
	const struct sm_model *ax = sm_ax12();
	assert_false(sm_has(ax, SM_CAP_HWERR));
	assert_false(sm_has(ax, SM_CAP_OPMODE));
	assert_false(sm_limit_is_pwm_drive(ax));     /* Torque Limit 34, wheel-mode drive Moving Speed 32 */
	assert_string_equal(ax->limits_name, "angle");
	assert_string_equal(sm_register_name(ax, 34), "torque limit");
	const uint16_t xs[] = { 1060, 1020, 1070 };
	for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++) {
		const struct sm_model *x = sm_by_number(2, xs[i]);
		assert_non_null(x);
		assert_true(sm_has(x, SM_CAP_HWERR | SM_CAP_OPMODE));
		assert_true(sm_limit_is_pwm_drive(x));   /* Goal PWM 100: the limit and the PWM drive */
		assert_string_equal(x->limits_name, "position");
		assert_string_equal(sm_register_name(x, 100), "goal_pwm");
		assert_string_equal(sm_register_name(x, 101), "register");   /* inside Goal PWM */
		assert_ptr_equal(x->desc, dxl2_model_by_number(xs[i]));
	}
}

static void test_families_by_number(void **state)
{
	(void)state;
	assert_ptr_equal(sm_by_number(1, 12), sm_ax12());
	assert_string_equal(sm_by_number(2, 1060)->name, "XL430-W250");
	assert_string_equal(sm_by_number(2, 1020)->name, "XM430-W350");
	assert_string_equal(sm_by_number(2, 1070)->name, "XC430-W150");
	/* a number is only a model on its own protocol */
	assert_null(sm_by_number(1, 1060));
	assert_null(sm_by_number(2, 12));
	assert_null(sm_by_number(2, 1030));   /* XM430-W210: not one this daemon knows */
	assert_string_equal(sm_by_number(2, 1020)->name, "XM430-W350");
	assert_true(sm_by_number(2, 1020)->current_control);
	assert_false(sm_by_number(2, 1060)->current_control);
	assert_false(sm_ax12()->current_control);
	/* the registers the controller writes, from the manuals' tables */
	assert_int_equal(sm_ax12()->torque_enable, 24);
	assert_int_equal(sm_ax12()->goal, 30);
	assert_int_equal(sm_by_number(2, 1060)->torque_enable, 64);
	assert_int_equal(sm_by_number(2, 1060)->goal, 116);
	assert_int_equal(sm_by_number(2, 1060)->goal_size, 4);
	assert_int_equal(sm_by_number(2, 1020)->torque_limit, 100);   /* Goal PWM caps position control */
	/* the datasheet lines at 12 V */
	assert_true(fabs(sm_by_number(2, 1020)->stall_torque_nm - 4.1) < 1e-12);
	assert_true(fabs(sm_by_number(2, 1020)->no_load_speed_rad_s - 46.0 * 2 * PI / 60) < 1e-12);
	assert_true(fabs(sm_by_number(2, 1060)->stall_current_a - 1.4) < 1e-12);
}

static void test_positions_both_ways(void **state)
{
	(void)state;
	const struct sm_model *x = sm_by_number(2, 1020), *ax = sm_ax12();
	assert_true(fabs(sm_pos_to_rad(x, 2048)) < 1e-12);
	assert_true(fabs(sm_pos_to_rad(x, 3072) - PI / 2) < 1e-12);   /* a quarter turn: 1024 of 4096 */
	assert_true(fabs(sm_pos_to_rad(ax, 512)) < 1e-12);
	assert_true(fabs(sm_pos_to_rad(ax, 1023) - 511 * 300.0 / 1023 * PI / 180) < 1e-12);
	for (int32_t n = 0; n <= 4095; n++)
		if (sm_rad_to_pos(x, sm_pos_to_rad(x, n)) != n)
			fail_msg("X position %d does not come back", n);
	for (int32_t n = 0; n <= 1023; n++)
		if (sm_rad_to_pos(ax, sm_pos_to_rad(ax, n)) != n)
			fail_msg("AX position %d does not come back", n);
	assert_int_equal(sm_rad_to_pos(x, 10.0), 4095);
	assert_int_equal(sm_rad_to_pos(x, -10.0), 0);
	assert_int_equal(sm_rad_to_pos(x, NAN), 2048);
}

/* 126..135: Present Current (XM430; Load on the XL430) 2 bytes, Present
 * Velocity 4, Present Position 4, little-endian, signed (e-manual). */
static void test_present_block_x(void **state)
{
	(void)state;
	/* current -100 (FF9C), velocity -3, position 166 (the manual's READ example) */
	const uint8_t fast[10] = { 0x9C, 0xFF, 0xFD, 0xFF, 0xFF, 0xFF, 0xA6, 0x00, 0x00, 0x00 };
	struct sm_present p;
	const struct sm_model *xm = sm_by_number(2, 1020), *xl = sm_by_number(2, 1060);
	assert_true(sm_decode_present(xm, fast, sizeof fast, &p));
	assert_false(p.slow);
	assert_int_equal(p.pos_raw, 166);
	assert_true(fabs(p.angle - (166 - 2048) * 2 * PI / 4096) < 1e-12);
	assert_true(fabs(p.speed - (-3 * 0.229 * 2 * PI / 60)) < 1e-12);
	assert_true(fabs(p.load - (-100 * 0.00269 / 2.3)) < 1e-12);   /* share of the stall current */
	assert_true(isnan(p.voltage) && isnan(p.temperature));
	/* the XL430's 126 is Present Load, 0.1 % a unit */
	assert_true(sm_decode_present(xl, fast, sizeof fast, &p));
	assert_true(fabs(p.load - (-0.100)) < 1e-12);
	/* the slow read goes on to 146: trajectories (136..143), input voltage
	 * 144 (0.1 V) and temperature 146 */
	uint8_t slow[21] = { 0 };
	memcpy(slow, fast, sizeof fast);
	slow[18] = 118;   /* 11.8 V */
	slow[20] = 41;
	assert_true(sm_decode_present(xm, slow, sizeof slow, &p));
	assert_true(p.slow);
	assert_int_equal(p.pos_raw, 166);
	assert_true(fabs(p.voltage - 11.8) < 1e-9);
	assert_true(fabs(p.temperature - 41) < 1e-12);
	/* any other length is not this block: a late reply to another request */
	assert_false(sm_decode_present(xm, slow, 20, &p));
	assert_false(sm_decode_present(xm, fast, 6, &p));
}

/* The indirect block (Indirect Data 1.. at 224): 126..135 then 144..146, 10
 * or 13 bytes, decoded by the same decoder to the same values as the direct
 * block's 10 or 21; the AX-12A has none. */
static void test_present_block_indirect(void **state)
{
	(void)state;
	const struct sm_model *xm = sm_by_number(2, 1020);
	const struct sm_read *rd = &xm->indirect;
	assert_int_equal(rd->addr, 224);
	assert_int_equal(rd->len, 10);
	assert_int_equal(rd->len_slow, 13);
	assert_int_equal(rd->src[0], 126);
	assert_int_equal(rd->src[9], 135);
	assert_int_equal(rd->src[10], 144);
	assert_int_equal(rd->src[12], 146);
	assert_int_equal(sm_ax12()->indirect.len, 0);
	uint8_t direct[21] = { 0x9C, 0xFF, 0xFD, 0xFF, 0xFF, 0xFF, 0xA6, 0x00, 0x00, 0x00 }, block[13];
	direct[18] = 118;
	direct[20] = 41;
	for (size_t k = 0; k < rd->len_slow; k++)
		block[k] = direct[rd->src[k] - 126];
	struct sm_present a, b;
	struct sm_read dr = sm_direct_read(xm);
	assert_true(sm_decode_read(xm, &dr, direct, 21, &a));
	assert_true(sm_decode_read(xm, rd, block, 13, &b));
	assert_true(a.slow && b.slow);
	assert_int_equal(a.pos_raw, b.pos_raw);
	assert_true(a.speed == b.speed && a.load == b.load && a.voltage == b.voltage && a.temperature == b.temperature);
	assert_true(fabs(b.voltage - 11.8) < 1e-9 && fabs(b.temperature - 41) < 1e-12);
	assert_true(sm_decode_read(xm, rd, block, 10, &b));
	assert_false(b.slow);
	assert_int_equal(b.pos_raw, 166);
	assert_true(isnan(b.voltage));
	/* the direct block's slow length is not the indirect block's */
	assert_false(sm_decode_read(xm, rd, direct, 21, &b));
}

/* The AX-12's 36..43: as control.c always decoded it. */
static void test_present_block_ax(void **state)
{
	(void)state;
	const uint8_t b[8] = { 0x00, 0x02, 0x0A, 0x04, 0x64, 0x00, 0x78, 0x20 };   /* 512, 10 CW, 100 CCW, 12 V, 32 C */
	struct sm_present p;
	assert_true(sm_decode_present(sm_ax12(), b, 6, &p));
	assert_false(p.slow);
	assert_int_equal(p.pos_raw, 512);
	assert_true(fabs(p.speed - dxl_speed_to_rad_s(0x040A)) < 1e-12);
	assert_true(p.speed < 0);
	assert_true(fabs(p.load - 0.1) < 1e-12);
	assert_true(sm_decode_present(sm_ax12(), b, 8, &p));
	assert_true(fabs(p.voltage - 12.0) < 1e-12 && fabs(p.temperature - 32) < 1e-12);
	assert_false(sm_decode_present(sm_ax12(), b, 7, &p));
}

static void test_readback_blocks_x(void **state)
{
	(void)state;
	const struct sm_model *xm = sm_by_number(2, 1020);
	assert_int_equal(xm->nreadback, 2);
	assert_int_equal(xm->readback[0].addr, 64);
	assert_int_equal(xm->readback[0].len, 52);   /* 64 .. 115 (Profile Velocity) */
	assert_int_equal(xm->readback[1].addr, 11);
	assert_int_equal(xm->readback[1].len, 45);   /* 11 .. 55 (Min Position Limit) */
	uint8_t ram[52] = { 0 }, ee[45] = { 0 };
	ram[64 - 64] = 1;                  /* torque on */
	ram[70 - 64] = 0x24;               /* overheating | overload */
	ram[98 - 64] = 0xFF;               /* the watchdog stopped it */
	ram[100 - 64] = 0x75; ram[101 - 64] = 0x03;   /* Goal PWM 885 */
	ram[108 - 64] = 7;                 /* Profile Acceleration 7 */
	ram[112 - 64] = 0x2C; ram[113 - 64] = 0x01;   /* Profile Velocity 300 */
	ee[11 - 11] = 3;                   /* position control */
	ee[36 - 11] = 0x2C; ee[37 - 11] = 0x01;       /* PWM Limit 300 */
	ee[38 - 11] = 0xA9; ee[39 - 11] = 0x04;       /* Current Limit 1193 */
	ee[48 - 11] = 0xAB; ee[49 - 11] = 0x0E;       /* Max Position Limit 3755 */
	ee[52 - 11] = 0x55; ee[53 - 11] = 0x01;       /* Min Position Limit 341 */
	struct sm_state s;
	sm_state_unknown(&s);
	assert_true(sm_decode_readback(xm, 0, ram, sizeof ram, &s));
	assert_int_equal(s.torque, 1);
	assert_int_equal(s.hwerr, 0x24);
	assert_int_equal(s.watchdog, SM_WATCHDOG_TRIPPED);
	assert_int_equal(s.torque_limit, 885);
	assert_int_equal(s.profile_acceleration, 7);
	assert_int_equal(s.profile_velocity, 300);
	assert_int_equal(s.opmode, -1);    /* not in this block */
	assert_true(sm_decode_readback(xm, 1, ee, sizeof ee, &s));
	assert_int_equal(s.opmode, 3);
	assert_int_equal(s.pwm_limit, 300);
	assert_int_equal(s.current_limit, 1193);
	assert_int_equal(s.pos_max, 3755);
	assert_int_equal(s.pos_min, 341);
	assert_int_equal(s.torque, 1);     /* kept from the other block */
	/* the wrong length or block is refused, nothing changed */
	assert_false(sm_decode_readback(xm, 1, ram, sizeof ram, &s));
	assert_false(sm_decode_readback(xm, 2, ee, sizeof ee, &s));
	assert_int_equal(s.opmode, 3);
	/* the XL430 has no Current Limit */
	sm_state_unknown(&s);
	assert_true(sm_decode_readback(sm_by_number(2, 1060), 1, ee, sizeof ee, &s));
	assert_int_equal(s.current_limit, -1);
}

static void test_readback_block_ax(void **state)
{
	(void)state;
	uint8_t ram[20] = { 0 };
	ram[24 - 24] = 1;
	ram[26 - 24] = 0;  ram[27 - 24] = 1;
	ram[34 - 24] = 0xFF; ram[35 - 24] = 0x03;   /* torque limit 1023 */
	ram[42 - 24] = 110; ram[43 - 24] = 40;
	struct sm_state s;
	sm_state_unknown(&s);
	assert_true(sm_decode_readback(sm_ax12(), 0, ram, sizeof ram, &s));
	assert_int_equal(s.torque, 1);
	assert_int_equal(s.torque_limit, 1023);
	assert_int_equal(s.margin_cw, 0);
	assert_int_equal(s.margin_ccw, 1);
	assert_true(fabs(s.voltage - 11.0) < 1e-12 && fabs(s.temperature - 40) < 1e-12);
	assert_int_equal(s.hwerr, -1);
	assert_false(sm_decode_readback(sm_ax12(), 1, ram, sizeof ram, &s));
}

static void test_status_meaning(void **state)
{
	(void)state;
	const struct sm_model *x = sm_by_number(2, 1060), *ax = sm_ax12();
	/* AX-12: overload and overheating show in the status byte itself */
	assert_int_equal(sm_status_faults(ax, 0x24), 0x24);
	assert_int_equal(sm_status_faults(ax, 0x01), 0);
	assert_false(sm_alert(ax, 0x80));
	/* X: the status raises the alert; the cause is read back */
	assert_int_equal(sm_status_faults(x, 0x80), 0);
	assert_true(sm_alert(x, 0x80));
	assert_true(sm_alert(x, 0x84));
	assert_false(sm_alert(x, 0x04));
	/* a write is refused by an error number (X) or the range, instruction,
	 * checksum bits (AX), not by the alert or an overload */
	assert_true(sm_write_refused(x, 0x07));
	assert_true(sm_write_refused(x, 0x81));
	assert_false(sm_write_refused(x, 0x80));
	assert_true(sm_write_refused(ax, DXL_ERRBIT_RANGE));
	assert_false(sm_write_refused(ax, DXL_ERRBIT_OVERLOAD));
}

static int16_t s16(uint16_t v) { return (int16_t)v; }

static void test_drive_outputs(void **state)
{
	(void)state;
	const struct sm_model *xl = sm_by_number(2, 1060), *xm = sm_by_number(2, 1020), *ax = sm_ax12();
	assert_int_equal(sm_drive_register(xl, false), 100);
	assert_int_equal(sm_drive_register(xm, true), 102);
	assert_int_equal(sm_drive_register(ax, false), 32);
	assert_int_equal(sm_drive_opmode(true), 0);
	assert_int_equal(sm_drive_opmode(false), 16);
	/* PWM: 885 = 100 %, within +-PWM Limit */
	assert_int_equal(s16(sm_drive_raw(xl, false, 0.5, 885)), 443);
	assert_int_equal(s16(sm_drive_raw(xl, false, -1.0, 885)), -885);
	assert_int_equal(s16(sm_drive_raw(xl, false, -1.0, 300)), -300);
	assert_int_equal(s16(sm_drive_raw(xl, false, 3.0, 885)), 885);
	/* current: the share of the stall current (2.3 A) in 2.69 mA units,
	 * within +-Current Limit */
	assert_int_equal(s16(sm_drive_raw(xm, true, 1.0, 1193)), 855);
	assert_int_equal(s16(sm_drive_raw(xm, true, -0.1, 1193)), -86);
	assert_int_equal(s16(sm_drive_raw(xm, true, 1.0, 500)), 500);
	assert_int_equal(sm_drive_raw(xm, true, NAN, 1193), 0);
	assert_int_equal(sm_drive_raw(xm, true, INFINITY, 1193), 0);
	/* AX-12 wheel mode: as it always was */
	assert_int_equal(sm_drive_raw(ax, false, -0.5, 0), dxl_duty_to_wheel(-0.5));
}

/* A finished configuration on /dev/null with these assignments
 * ("robot.ids=1,2", ..., NULL). */
static void cfg_with(struct cfg *c, ...)
{
	struct cfg_errors e = { 0 };
	cfg_defaults(c);
	assert_true(cfg_override(c, "robot.port=/dev/null", &e));
	va_list ap;
	va_start(ap, c);
	for (const char *a; (a = va_arg(ap, const char *)) != NULL;)
		assert_true(cfg_override(c, a, &e));
	va_end(ap);
	assert_true(cfg_finish(c, &e));
}

/* Torque actuation's defaults are an AX-12A joint's; on another servo the
 * same link is heavier by the rotor through the gearbox, and the defaults
 * the configuration did not give scale with it, once. */
static void test_torque_defaults_scale(void **state)
{
	(void)state;
	assert_true(fabs(sm_torque_scale(sm_ax12()) - 1.0) < 1e-12);
	double xm = sm_torque_scale(sm_by_number(2, 1020)), xl = sm_torque_scale(sm_by_number(2, 1060));
	/* (1.42e-3 link + 5.0e-8 x 353.5^2) / 4.39e-3 */
	assert_true(fabs(xm - (4.39e-3 - 4.6e-8 * 254 * 254 + 5.0e-8 * 353.5 * 353.5) / 4.39e-3) < 1e-9);
	assert_true(xm > 1.7 && xm < 1.8);
	assert_true(xl > 1.0 && xl < 1.05);
	/* the controller's live parameters take them; the configuration keeps what was configured */
	static struct cfg c;
	static struct ctl ctl;
	cfg_with(&c, "robot.ids=1,2", "robot.actuation=torque", "robot.torque_drive=current", "joint.2.k=0.3", NULL);
	ctl_init(&ctl, &c);
	double k1 = c.joint[0].osc.k, mu1 = c.joint[0].osc.mu, i1 = c.joint[0].osc.inertia, mu2 = c.joint[1].osc.mu;
	assert_true(ctl_torque_defaults(&ctl, 0, xm));
	assert_true(ctl_torque_defaults(&ctl, 1, xm));
	assert_true(fabs(ctl.p.osc[0].k - k1 * xm) < 1e-12);
	assert_true(fabs(ctl.p.osc[0].mu - mu1 * xm) < 1e-12);
	assert_true(fabs(ctl.p.osc[0].inertia - i1 * xm) < 1e-12);
	assert_true(fabs(ctl.p.osc[1].k - 0.3) < 1e-12);        /* given: kept */
	assert_true(fabs(ctl.p.osc[1].mu - mu2 * xm) < 1e-12);  /* not given: scaled */
	assert_true(c.joint[0].osc.k == k1);
	assert_false(ctl_torque_defaults(&ctl, 0, xm));          /* once */
	assert_true(fabs(ctl.p.osc[0].k - k1 * xm) < 1e-12);
	/* position actuation's parameters are a control law's, not a joint's: none */
	cfg_with(&c, "robot.ids=1", NULL);
	ctl_init(&ctl, &c);
	k1 = c.joint[0].osc.k;
	assert_false(ctl_torque_defaults(&ctl, 0, xm));
	assert_true(fabs(ctl.p.osc[0].k - k1) < 1e-12);
}

/* Position actuation's defaults: the AX-12A has none of its own (osc.h's
 * stand); an X model's replace the k and μ the configuration did not give,
 * by the joint's parity and the robot's size, once; torque actuation's are
 * left alone. */
static void test_position_defaults(void **state)
{
	(void)state;
	double k, mu, lead;
	assert_false(sm_position_defaults(sm_ax12(), 0, 2, &k, &mu, &lead));
	const struct sm_model *xm = sm_by_number(2, 1020), *xl = sm_by_number(2, 1060);
	assert_true(sm_position_defaults(xm, 0, 2, &k, &mu, &lead));
	assert_true(fabs(k - 0.0304) < 1e-12 && fabs(mu - 0.0757) < 1e-12 && fabs(lead - 0.047) < 1e-12);
	assert_true(sm_position_defaults(xm, 1, 2, &k, &mu, &lead));
	assert_true(fabs(mu - 0.0571) < 1e-12);
	assert_true(sm_position_defaults(xm, 2, 4, &k, &mu, &lead));   /* a longer chain: by parity */
	assert_true(fabs(mu - 0.0757) < 1e-12);
	assert_true(sm_position_defaults(xl, 0, 1, &k, &mu, &lead));   /* a single joint */
	assert_true(fabs(k - 0.0105) < 1e-12 && fabs(mu - 0.0360) < 1e-12 && fabs(lead - 0.117) < 1e-12);

	static struct cfg c;
	static struct ctl ctl;
	cfg_with(&c, "robot.ids=1,2", "joint.2.mu=0.5", NULL);
	ctl_init(&ctl, &c);
	assert_true(c.servo_lead_default);
	assert_true(ctl_position_defaults(&ctl, 0, 0.03, 0.07));
	assert_true(fabs(ctl.p.osc[0].k - 0.03) < 1e-12 && fabs(ctl.p.osc[0].mu - 0.07) < 1e-12);
	assert_true(ctl_position_defaults(&ctl, 1, 0.03, 0.07));
	assert_true(fabs(ctl.p.osc[1].k - 0.03) < 1e-12);
	assert_true(fabs(ctl.p.osc[1].mu - 0.5) < 1e-12);             /* given: kept */
	assert_false(ctl_position_defaults(&ctl, 0, 0.9, 0.9));         /* once */
	assert_true(fabs(ctl.p.osc[0].k - 0.03) < 1e-12);
	assert_true(fabs(c.joint[0].osc.k - 0.03) > 1e-3);            /* the configuration's own stays */
	/* every one given: nothing to replace */
	cfg_with(&c, "robot.ids=1", "joint.1.k=0.2", "joint.1.mu=0.2", "robot.servo_lead_s=0.03", NULL);
	ctl_init(&ctl, &c);
	assert_false(c.servo_lead_default);
	assert_false(ctl_position_defaults(&ctl, 0, 0.03, 0.07));
	assert_true(fabs(ctl.p.osc[0].k - 0.2) < 1e-12);
	/* torque actuation: its own defaults (scaled), never these */
	cfg_with(&c, "robot.ids=1", "robot.actuation=torque", NULL);
	ctl_init(&ctl, &c);
	k = c.joint[0].osc.k;
	assert_false(ctl_position_defaults(&ctl, 0, 0.03, 0.07));
	assert_true(fabs(ctl.p.osc[0].k - k) < 1e-12);
}

/* The supply each model can be running at: its e-manual's rated range, 5 %
 * either side; the reading's 0.1 V steps at the edges. */
static void test_supply_plausible(void **state)
{
	(void)state;
	static const struct { int protocol; uint16_t number; double lo_in, hi_in, lo_out, hi_out; } cases[] = {
		{ 1, 12, 8.6, 12.6, 8.5, 12.7 },
		{ 2, 1060, 6.2, 12.6, 6.1, 12.7 },
		{ 2, 1020, 9.5, 15.5, 9.4, 15.6 },
		{ 2, 1070, 6.2, 15.5, 6.1, 15.6 },   /* XC430-W150: 6.5 .. 14.8 V */
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		const struct sm_model *m = sm_by_number(cases[i].protocol, cases[i].number);
		assert_true(sm_supply_plausible(m, cases[i].lo_in));
		assert_true(sm_supply_plausible(m, cases[i].hi_in));
		assert_true(sm_supply_plausible(m, 12.0));
		assert_false(sm_supply_plausible(m, cases[i].lo_out));
		assert_false(sm_supply_plausible(m, cases[i].hi_out));
		assert_false(sm_supply_plausible(m, 0.0));
		assert_false(sm_supply_plausible(m, 1.5));
		assert_false(sm_supply_plausible(m, 25.5));
		assert_false(sm_supply_plausible(m, NAN));
	}
	/* the 0.1 V reading of the edge itself: AX-12A 12.6 V is 126 x 0.1 */
	assert_true(sm_supply_plausible(sm_ax12(), dxl_voltage_to_volts(126)));
	assert_false(sm_supply_plausible(sm_ax12(), dxl_voltage_to_volts(85)));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_families_by_number),
		cmocka_unit_test(test_capabilities),
		cmocka_unit_test(test_positions_both_ways),
		cmocka_unit_test(test_present_block_x),
		cmocka_unit_test(test_present_block_indirect),
		cmocka_unit_test(test_present_block_ax),
		cmocka_unit_test(test_readback_blocks_x),
		cmocka_unit_test(test_readback_block_ax),
		cmocka_unit_test(test_status_meaning),
		cmocka_unit_test(test_drive_outputs),
		cmocka_unit_test(test_torque_defaults_scale),
		cmocka_unit_test(test_position_defaults),
		cmocka_unit_test(test_supply_plausible),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
