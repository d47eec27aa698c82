/*
 * test_daemon_cycle2.c — the cycle and the controller on a Protocol 2.0 bus
 * (X series), through the seam they were designed with: a fake transport
 * and a fake clock (bus_io), and behind it the fake X servos of xfake.h
 * (their own CRC and stuffing; the e-manual's refusals), answering with the
 * wire time a real bus takes at 1 Mbps. The loop is the daemon's, reduced,
 * as in test_daemon_cycle.c: a tick every 10 ms starts a cycle, the next
 * byte or the deadline wakes it, the controller steps at CYC_CONTROL.
 * Checked: one SYNC_READ and one SYNC_WRITE a cycle; a servo missing from
 * the SYNC_READ (the others read), a damaged reply, a reply a period late
 * refused; the read-back of both blocks; a hardware-error shutdown found
 * through the alert and recovered by one REBOOT, or latched when it comes
 * back; a tripped bus watchdog; a power loss; an Operating Mode changed
 * behind the controller's back; LIMP racing HOLD's writes; torque actuation
 * switching an XM430 into current control and back, and a switch that stops
 * half-way.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../../daemon/control.h"
#include "../../daemon/cycle.h"
#include "bus.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "xfake.h"

#define PERIOD_US 10000
#define RX_CAP 16384
#define WATCHDOG_UNITS 5   /* the default 100 ms */

/* ---- the transport and the clock --------------------------------------------------------------- */
struct fake {
	uint64_t now;
	uint8_t rx[RX_CAP];
	uint64_t rx_at[RX_CAP];
	size_t head, tail;
	uint64_t request_end;      /* when the request being answered ended on the wire */
	uint64_t line_free;        /* when the last reply queued ends */
	uint64_t late_us;          /* the next reply this much later */
	int corrupt;               /* replies to damage (a bit of their CRC) */
	int write_error;
};

static struct fake f;
static struct xfake xb;
static struct cfg cfg;
static struct ctl c;
static struct bus bus;
static struct cyc y;
static uint64_t next_tick;
static unsigned cuts;
static void (*on_write_sent)(void);

static uint64_t wire_us(size_t bytes) { return bytes * 10; }   /* 1 Mbps, 8N1 */

/* Replies follow one another on the line, each after its servo's return delay. */
static void emit(void *ctx, const uint8_t *pkt, size_t n, unsigned delay_us)
{
	(void)ctx;
	uint64_t start = (f.request_end > f.line_free ? f.request_end : f.line_free) + delay_us + f.late_us;
	f.late_us = 0;
	if (f.tail + n > RX_CAP && f.head > 0) {
		/* what was read is gone: room for long runs */
		memmove(f.rx, f.rx + f.head, f.tail - f.head);
		memmove(f.rx_at, f.rx_at + f.head, (f.tail - f.head) * sizeof f.rx_at[0]);
		f.tail -= f.head;
		f.head = 0;
	}
	assert_true(f.tail + n <= RX_CAP);
	for (size_t i = 0; i < n; i++) {
		f.rx[f.tail] = pkt[i];
		if (f.corrupt > 0 && i == n - 1)
			f.rx[f.tail] ^= 0x01;
		f.rx_at[f.tail++] = start + wire_us(i + 1);
	}
	if (f.corrupt > 0)
		f.corrupt--;
	f.line_free = start + wire_us(n);
}

static int fake_write(void *ctx, const uint8_t *buf, size_t n)
{
	(void)ctx;
	if (f.write_error)
		return f.write_error;
	f.request_end = f.now + wire_us(n);
	f.line_free = f.request_end;
	unsigned writes = atomic_load(&xb.writes) + atomic_load(&xb.reboots);
	xfake_feed(&xb, buf, n);
	if (on_write_sent != NULL && atomic_load(&xb.writes) + atomic_load(&xb.reboots) != writes)
		on_write_sent();
	return DXL_OK;
}

static long fake_read(void *ctx, uint8_t *buf, size_t cap)
{
	(void)ctx;
	size_t n = 0;
	while (f.head + n < f.tail && f.rx_at[f.head + n] <= f.now && n < cap)
		n++;
	memcpy(buf, f.rx + f.head, n);
	f.head += n;
	return (long)n;
}

static int fake_wait(void *ctx, uint32_t timeout_us)
{
	(void)ctx;
	f.now += timeout_us;
	return 0;
}

static uint64_t fake_now(void *ctx) { (void)ctx; return f.now; }

static void fake_flush(void *ctx)
{
	(void)ctx;
	while (f.head < f.tail && f.rx_at[f.head] <= f.now)
		f.head++;
}

/* ---- the loop ------------------------------------------------------------------------------------ */
static void drive(enum cyc_status st)
{
	for (;;) {
		if (st == CYC_CONTROL) {
			ctl_step(&c, 1e-6 * (double)f.now, 1e-6 * PERIOD_US, 1e-6 * (double)f.now);
			st = cyc_resume(&y);
			continue;
		}
		if (st != CYC_PENDING)
			return;
		uint64_t wake = cyc_deadline_us(&y);
		if (f.head < f.tail && f.rx_at[f.head] < wake)
			wake = f.rx_at[f.head];
		if (wake >= next_tick)
			return;
		if (wake > f.now)
			f.now = wake;
		st = cyc_step(&y);
	}
}

static char events[64][CTL_EVENT_TEXT + 32];
static size_t nevents;

static void take_events(void)
{
	struct ctl_event e;
	while (ctl_next_event(&c, &e))
		if (nevents < 64)
			snprintf(events[nevents++], sizeof events[0], "%s: %s", e.kind, e.text);
}

static const char *find_event(const char *needle)
{
	for (size_t i = 0; i < nevents; i++)
		if (strstr(events[i], needle) != NULL)
			return events[i];
	return NULL;
}

static void tick(void)
{
	f.now = next_tick;
	next_tick += PERIOD_US;
	if (cyc_busy(&y)) {
		cyc_cut(&y);
		cuts++;
	}
	take_events();
	drive(cyc_start(&y));
	take_events();
}

static void run(int cycles)
{
	for (int i = 0; i < cycles; i++)
		tick();
}

static struct xfake_servo *sv(uint8_t id) { return xfake_servo_by_id(&xb, id); }
static uint32_t reg(uint8_t id, uint16_t addr, int size) { return xfake_get(sv(id)->mem, addr, size); }

/* Two servos (or the models given) as undulated's start-up leaves them:
 * 1 Mbps, return delay 0, position control, the watchdog set, torque off. */
static void setup_x(const uint16_t *models, size_t n, enum cfg_mode mode, const char *const *sets)
{
	struct cfg_errors e = { 0 };
	char ids[64] = "robot.ids=";
	memset(&f, 0, sizeof f);
	memset(&xb, 0, sizeof xb);
	xb.emit = emit;
	xb.alert_from_hwerr = true;
	for (size_t i = 0; i < n; i++) {
		xfake_servo_defaults(&xb.servo[xb.nservos++], (uint8_t)(i + 1), models[i]);
		struct xfake_servo *s = &xb.servo[i];
		s->mem[8] = 3;
		s->mem[9] = 0;
		s->mem[98] = WATCHDOG_UNITS;
		xfake_put(s->mem, 48, 2048 + 1700, 4);
		xfake_put(s->mem, 52, 2048 - 1700, 4);
		xfake_put(s->mem, 128, 0, 4);
		snprintf(ids + strlen(ids), sizeof ids - strlen(ids), "%s%zu", i ? "," : "", i + 1);
	}
	cfg_defaults(&cfg);
	assert_true(cfg_override(&cfg, "robot.port=/dev/null", &e));
	assert_true(cfg_override(&cfg, ids, &e));
	for (size_t i = 0; sets != NULL && sets[i] != NULL; i++)
		assert_true(cfg_override(&cfg, sets[i], &e));
	cfg.mode = mode;
	assert_true(cfg_finish(&cfg, &e));
	ctl_init(&c, &cfg);
	char why[256];
	for (size_t j = 0; j < n; j++) {
		struct ctl_servo_info info = { .cw_limit = 2048 - 1700, .ccw_limit = 2048 + 1700, .max_torque = 885,
		                               .status_return_level = 2, .model = sm_by_number(2, models[j]),
		                               .current_limit = 1193 };
		assert_true(ctl_set_servo(&c, j, &info, why, sizeof why));
		struct sm_present p = { .pos_raw = 2048, .angle = 0, .voltage = NAN, .temperature = NAN };
		ctl_measure_present(&c, j, &p, 0, 0.01);
	}
	struct bus_io io = { .ctx = &f, .write = fake_write, .read = fake_read, .wait = fake_wait, .now_us = fake_now,
	                     .flush_input = fake_flush };
	struct bus_timing tm = { .baud = 1000000, .return_delay_us = 0, .adapter_latency_us = 0, .margin_us = 500 };
	bus_init(&bus, &io, &tm, false);
	assert_int_equal(bus_set_protocol(&bus, BUS_PROTOCOL_2), DXL_OK);
	cyc_init(&y, &bus, &c, PERIOD_US, NULL);
	next_tick = 1000000;
	f.now = next_tick - PERIOD_US;
	cuts = 0;
	nevents = 0;
	on_write_sent = NULL;
	ctl_start(&c, 1e-6 * (double)f.now, "test");
}

static const uint16_t xm2[] = { DXL2_MODEL_XM430_W350, DXL2_MODEL_XM430_W350 };
static const uint16_t xl_xm[] = { DXL2_MODEL_XL430_W250, DXL2_MODEL_XM430_W350 };

/* ---- tests ------------------------------------------------------------------------------------- */
static void test_one_sync_read_one_sync_write(void **state)
{
	(void)state;
	setup_x(xl_xm, 2, CFG_MODE_HOLD, NULL);
	run(100);
	assert_int_equal(cuts, 0);
	assert_int_equal(y.errors, 0);
	assert_int_equal(atomic_load(&xb.sync_reads), 100);
	assert_int_equal(atomic_load(&xb.sync_writes), 100);
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(sv(id)->mem[64], 1);             /* torque on */
		assert_int_equal(reg(id, 100, 2), 885);           /* Goal PWM at PWM Limit */
		assert_int_equal(reg(id, 116, 4), 2048);          /* holding where it stands */
		const struct ctl_joint *jt = &c.j[id - 1];
		assert_int_equal(jt->torque_read, 1);
		assert_int_equal(jt->opmode_read, 3);
		assert_int_equal(jt->watchdog_read, WATCHDOG_UNITS);
		assert_int_equal(jt->hwerr, 0);
		assert_int_equal(jt->stale_cycles, 0);
		/* the slow read every other cycle brings voltage and temperature */
		assert_true(fabs(jt->voltage - 12.0) < 1e-9 && fabs(jt->temperature - 36) < 1e-9);
	}
	assert_int_equal(y.readbacks, 20);
	assert_int_equal(c.readback_mismatches, 0);
	assert_int_equal(wq_pending(&c.wq), 0);
	/* SYNC_READ of 21 bytes from two servos and the goals' SYNC_WRITE: 16 +
	 * 2 x 32 + 24 bytes at 1 Mbps, about 1 ms, far inside the period */
	assert_true(y.bus_us > 500 && y.bus_us < 2500);
}

static void test_servo_missing_from_sync_read(void **state)
{
	(void)state;
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	run(10);
	sv(2)->powered = false;
	run(1);
	assert_int_equal(c.j[1].stale_cycles, 1);   /* the missing one is stale ... */
	assert_int_equal(c.j[0].stale_cycles, 0);   /* ... the other read */
	assert_int_equal(y.errors, 1);
	assert_int_equal(bus.servo[2].timeouts, 1);  /* and the bus names it */
	sv(2)->powered = true;
	f.corrupt = 1;                               /* servo 1's next reply damaged */
	run(1);
	assert_int_equal(c.j[0].stale_cycles, 1);
	assert_int_equal(c.j[1].stale_cycles, 0);
	assert_int_equal(bus.servo[1].checksum_errors, 1);
	run(5);
	assert_int_equal(c.j[0].stale_cycles + c.j[1].stale_cycles, 0);
	assert_int_equal(cuts, 0);
}

/* A reply a whole period late is refused by its length, never taken for the
 * next cycle's reading. */
static void test_reply_one_period_late(void **state)
{
	(void)state;
	setup_x(xm2, 1, CFG_MODE_HOLD, NULL);
	run(11);
	xfake_put(sv(1)->mem, 132, 2600, 4);
	f.late_us = PERIOD_US - 100;
	run(1);
	assert_int_equal(c.j[0].stale_cycles, 1);
	xfake_put(sv(1)->mem, 132, 2700, 4);
	run(1);
	if (c.j[0].stale_cycles == 0 && sm_rad_to_pos(ctl_model(&c, 0), c.j[0].angle) != 2700)
		fail_msg("the late reply (2600) was taken as this cycle's reading (%d)",
		         sm_rad_to_pos(ctl_model(&c, 0), c.j[0].angle));
	run(2);
	assert_int_equal(sm_rad_to_pos(ctl_model(&c, 0), c.j[0].angle), 2700);
}

/* An overload shuts servo 2 down: the alert in its status has its RAM block
 * read at once, the fault backs off, one REBOOT (fault_reboots 1) and the
 * set-up chain bring it back. */
static void test_shutdown_recovered_by_reboot(void **state)
{
	(void)state;
	const char *sets[] = { "robot.fault_backoff_s=0.2", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	run(20);
	sv(2)->mem[70] = DXL2_HWERR_OVERLOAD;
	sv(2)->mem[64] = 0;
	run(3);
	assert_int_equal(c.j[1].hwerr, DXL2_HWERR_OVERLOAD);
	assert_non_null(find_event("servo 2: overload (shut down: torque off): backing off"));
	assert_int_equal(atomic_load(&xb.reboots), 0);
	/* back-off 0.2 s, the boot's 0.3 s, the check's 0.3 s */
	run(100);
	assert_non_null(find_event("servo 2: overload shut it down: REBOOT 1 of 1"));
	assert_int_equal(atomic_load(&xb.reboots), 1);
	assert_non_null(find_event("servo 2: recovered"));
	assert_int_equal(sv(2)->mem[64], 1);
	assert_int_equal(sv(2)->mem[98], WATCHDOG_UNITS);   /* the boot cleared it; set again */
	assert_int_equal(reg(2, 100, 2), 885);
	assert_false(c.latched);
	assert_int_equal(c.j[1].fault, CTL_FAULT_NONE);
}

/* The cause is still there after the REBOOT: the fault latches (HOLD), and
 * the servo's torque is never turned on while its error stands. */
static void test_shutdown_latches_when_reboot_does_not_help(void **state)
{
	(void)state;
	const char *sets[] = { "robot.fault_backoff_s=0.2", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	run(20);
	sv(2)->mem[70] = DXL2_HWERR_OVERHEAT;
	sv(2)->mem[64] = 0;
	sv(2)->hwerr_after_reboot = DXL2_HWERR_OVERHEAT;
	for (int i = 0; i < 150; i++) {
		tick();
		if (sv(2)->mem[70] != 0 && sv(2)->mem[64] != 0)
			fail_msg("torque on with a hardware error standing");
	}
	assert_int_equal(atomic_load(&xb.reboots), 1);
	assert_true(c.latched);
	assert_non_null(strstr(c.latch, "servo 2 overheating"));
	assert_int_equal(c.mode, CFG_MODE_HOLD);
	/* the other joint holds on */
	assert_int_equal(sv(1)->mem[64], 1);
	/* 'clear' is the operator's REBOOT; cooled down, it comes back */
	sv(2)->hwerr_after_reboot = 0;
	char why[128];
	assert_true(ctl_clear_faults(&c, why, sizeof why));
	run(60);
	assert_int_equal(atomic_load(&xb.reboots), 2);
	assert_int_equal(sv(2)->mem[64], 1);
	assert_false(c.latched);
}

/* The servo's bus watchdog stopped it (this controller was late): found by
 * the read-back, cleared (0 first: only 0 is taken), set again, counted. */
static void test_watchdog_trip_recovered(void **state)
{
	(void)state;
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	run(20);
	sv(1)->mem[98] = SM_WATCHDOG_TRIPPED;
	run(25);
	assert_non_null(find_event("servo 1: its bus watchdog stopped it"));
	assert_int_equal(sv(1)->mem[98], WATCHDOG_UNITS);
	assert_int_equal(sv(1)->mem[64], 1);
	assert_int_equal(c.watchdog_trips, 1);
	assert_int_equal(c.j[0].resets, 1);
	assert_false(c.latched);
}

/* A power loss: the servo boots, torque off, RAM at its defaults. */
static void test_power_loss_set_up_again(void **state)
{
	(void)state;
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	run(20);
	xfake_boot(sv(2));
	run(25);
	assert_non_null(find_event("servo-reset: servo 2 found with torque off"));
	assert_int_equal(sv(2)->mem[64], 1);
	assert_int_equal(sv(2)->mem[98], WATCHDOG_UNITS);
	assert_int_equal(c.j[1].resets, 1);
}

/* Another program switched servo 1 to velocity control (EEPROM, torque off
 * for it): found in the EEPROM block, put back in position control. */
static void test_operating_mode_changed(void **state)
{
	(void)state;
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	run(20);
	sv(1)->mem[11] = 1;
	run(45);
	assert_non_null(find_event("servo 1: operating mode changed"));
	assert_int_equal(sv(1)->mem[11], 3);
	assert_int_equal(sv(1)->mem[64], 1);
	assert_int_equal(c.j[0].opmode_read, 3);
}

/* LIMP applied while HOLD's writes are on the wire: whatever was sent, the
 * servos end with torque off. */
static int limp_after = -1;
static void limp_mid_write(void)
{
	if (limp_after > 0 && --limp_after == 0)
		ctl_set_mode(&c, CFG_MODE_LIMP, "test: mid-cycle");
}

static void test_torque_off_never_lost(void **state)
{
	(void)state;
	for (int k = 1; k <= 4; k++) {
		setup_x(xm2, 2, CFG_MODE_LIMP, NULL);
		run(5);
		ctl_set_mode(&c, CFG_MODE_HOLD, "test");
		limp_after = k;
		on_write_sent = limp_mid_write;
		run(5);
		on_write_sent = NULL;
		assert_int_equal(c.mode, CFG_MODE_LIMP);
		for (uint8_t id = 1; id <= 2; id++)
			if (sv(id)->mem[64] != 0)
				fail_msg("LIMP after write %d: servo %u torque on", k, id);
	}
}

/* Torque actuation on the XM430: into current control and out of it, each
 * a chain per servo; the drive goes only to servos whose switch went
 * through, within Current Limit. */
static void test_current_control_switch(void **state)
{
	(void)state;
	const char *sets[] = { "robot.actuation=torque", "robot.torque_drive=current", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	/* resting away from neutral: the law starts it, no starter */
	for (uint8_t id = 1; id <= 2; id++)
		xfake_put(sv(id)->mem, 132, 2048 + 250, 4);
	run(10);
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	run(5);
	assert_true(c.wheel);
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(sv(id)->mem[11], 0);          /* current control */
		assert_int_equal(sv(id)->mem[64], 1);
		assert_true(c.j[id - 1].drive_ready);
		int16_t cur = (int16_t)reg(id, 102, 2);
		/* -k x at 0.37 rad out: a pull back towards neutral */
		assert_true(cur < 0 && cur >= -1193);
	}
	ctl_set_mode(&c, CFG_MODE_LIMP, "test");
	run(5);
	assert_false(c.wheel);
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(sv(id)->mem[11], 3);          /* back in position control */
		assert_int_equal(sv(id)->mem[64], 0);          /* and limp */
		assert_int_equal(reg(id, 102, 2), 0);          /* the drive stopped */
		assert_false(c.j[id - 1].drive_ready);
	}
}

/* The clock as a torque law ([sinusoid] stiffness) on the XM430: SINUSOID
 * switches the servos into current control as OSCILLATOR does, the drive is
 * the clock's torque, and at the switch to OSCILLATOR (the experiment: the
 * clock, then the oscillator) they stay there: no new chain, no torque off,
 * Operating Mode 0 all along. HOLD brings them back to position control. */
static void test_clock_in_current_control(void **state)
{
	(void)state;
	const char *sets[] = { "robot.actuation=torque", "robot.torque_drive=current", "sinusoid.stiffness=0.135",
	                       NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	run(10);
	ctl_set_mode(&c, CFG_MODE_SINUSOID, "test");
	run(5);
	assert_true(c.wheel);
	uint16_t chain[2];
	for (uint8_t id = 1; id <= 2; id++) {
		const struct ctl_joint *jt = &c.j[id - 1];
		assert_int_equal(sv(id)->mem[11], 0);
		assert_true(jt->drive_ready);
		chain[id - 1] = jt->drive_chain;
		double tau = c.p.sin_stiffness * (osc_sinusoid(c.p.amplitude, c.p.frequency, c.p.phase, id - 1u, c.t) -
		                                  (jt->angle - cfg.joint[id - 1].neutral));
		assert_true(fabs(jt->torque_cmd - tau) < 1e-9);
		int16_t cur = (int16_t)reg(id, 102, 2);
		assert_true(cur != 0 && (cur > 0) == (tau > 0.0));
	}
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	for (int i = 0; i < 50; i++) {
		tick();
		for (uint8_t id = 1; id <= 2; id++)
			if (!c.wheel || sv(id)->mem[11] != 0 || sv(id)->mem[64] != 1 || !c.j[id - 1].drive_ready ||
			    c.j[id - 1].drive_chain != chain[id - 1])
				fail_msg("cycle %d after the switch, servo %u: wheel %d, mode %u, torque %u, chain %u (was %u)", i,
				         id, c.wheel, sv(id)->mem[11], sv(id)->mem[64], c.j[id - 1].drive_chain, chain[id - 1]);
	}
	assert_null(find_event("back in joint mode"));
	ctl_set_mode(&c, CFG_MODE_HOLD, "test");
	run(5);
	assert_false(c.wheel);
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(sv(id)->mem[11], 3);
		assert_int_equal(sv(id)->mem[64], 1);
	}
}

/* Servo 2 refuses every write (the access error, nothing written): its
 * switch stops at the first step, it is never sent a drive, and the robot
 * goes back to joint mode. */
static void test_switch_stops_half_way(void **state)
{
	(void)state;
	const char *sets[] = { "robot.actuation=torque", "robot.torque_drive=current", "robot.fault_retries=0", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	for (uint8_t id = 1; id <= 2; id++)
		xfake_put(sv(id)->mem, 132, 2048 + 250, 4);
	run(10);
	sv(2)->refuse_writes = true;
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	run(20);
	assert_non_null(find_event("servo 2: the switch to current control stopped"));
	assert_int_equal(sv(2)->drive_parts, 0);
	assert_int_equal(sv(2)->mem[11], 3);
	assert_false(c.j[1].drive_ready);
	assert_true(c.latched);                /* fault_retries 0: the first failed switch latches */
	assert_false(c.wheel);
	assert_int_equal(sv(1)->mem[11], 3);   /* servo 1 back in position control too */
	assert_int_equal(sv(1)->mem[64], 1);
}

/* The guard itself: under torque actuation a SYNC_WRITE carries the drive of
 * the joints whose switch went through, and of no other. */
static void test_drive_only_where_ready(void **state)
{
	(void)state;
	const char *sets[] = { "robot.actuation=torque", "robot.torque_drive=current", NULL };
	setup_x(xm2, 2, CFG_MODE_OSCILLATOR, sets);
	c.wheel = true;
	c.sync = CTL_SYNC_DUTY;
	c.j[0].duty = 0.5;
	c.j[1].duty = -0.5;
	c.j[0].drive_ready = true;
	c.j[1].drive_ready = false;
	uint16_t addr;
	uint8_t width, ids[CFG_MAX_JOINTS], data[CTL_SYNC_MAX_WIDTH * CFG_MAX_JOINTS];
	assert_int_equal(ctl_sync(&c, &addr, &width, ids, data), 1);
	assert_int_equal(addr, 102);
	assert_int_equal(width, 2);
	assert_int_equal(ids[0], 1);
	assert_int_equal((int16_t)(data[0] | data[1] << 8), 428);   /* half the stall current, 2.69 mA a unit */
	/* leaving it: every drive 0 */
	c.sync = CTL_SYNC_GOAL_STOP;
	assert_int_equal(ctl_sync(&c, &addr, &width, ids, data), 2);
	assert_int_equal(addr, 102);
	assert_int_equal(data[0] | data[1] | data[2] | data[3], 0);
}

/* ---- every register written is the model's ---------------------------------------------------
 * What undulated writes on an X servo, by the e-manual's names (dxl2_table.c,
 * not our constants): torque, the output limit (Goal PWM), the drives, the
 * goal, the watchdog, the profiles, and with torque off the Operating Mode
 * and position limits the configuration decides. Any other address is
 * another model's register on this one: the AX-12's Torque Limit (34) is an
 * X servo's Min Voltage Limit, EEPROM, which it takes once torque is off. */
static const char *const x_written[] = {
	"torque_enable", "goal_pwm", "goal_current", "goal_position", "bus_watchdog", "profile_acceleration",
	"profile_velocity", "operating_mode", "min_position_limit", "max_position_limit", NULL,
};
static char bad_write[160];
static unsigned writes_seen;

static void check_write(void *ctx, const struct xfake_servo *s, uint16_t addr, size_t len)
{
	(void)ctx;
	const struct dxl2_model *m = dxl2_model_by_number((uint16_t)xfake_get(s->mem, 0, 2));
	const struct dxl2_reg *r = dxl2_reg_at(m, addr);
	bool ours = false;
	for (size_t i = 0; r != NULL && x_written[i] != NULL; i++)
		ours = ours || strcmp(r->name, x_written[i]) == 0;
	writes_seen++;
	if (ours && r->access == DXL_ACCESS_RW && r->size == len)
		return;
	if (bad_write[0] == '\0')
		snprintf(bad_write, sizeof bad_write, "servo %u (%s): %zu byte(s) written at %u (%s%s)", s->mem[7],
		         m != NULL ? m->name : "?", len, addr, r != NULL ? r->name : "no register",
		         r != NULL && r->area == DXL_AREA_EEPROM ? ", EEPROM" : "");
}

/* Each model through the fault paths and LIMP: a fault that leaves torque on
 * (the servo's Shutdown without its bit) whose back-off ends in LIMP, a
 * shutdown recovered by REBOOT, one that latches and 'clear', LIMP and HOLD
 * again; every write the servos heard is checked against their table. */
static void test_writes_are_the_models(void **state)
{
	(void)state;
	static const uint16_t models[][2] = {
		{ DXL2_MODEL_XL430_W250, DXL2_MODEL_XL430_W250 },
		{ DXL2_MODEL_XM430_W350, DXL2_MODEL_XM430_W350 },
	};
	/* 20.5 periods: the back-off ends at the 21st step after the one that
	 * found the fault, 5 ms from either step */
	const char *sets[] = { "robot.fault_backoff_s=0.205", "robot.fault_reboots=1", NULL };
	for (size_t k = 0; k < sizeof models / sizeof models[0]; k++) {
		setup_x(models[k], 2, CFG_MODE_HOLD, sets);
		xb.on_write = check_write;
		bad_write[0] = '\0';
		writes_seen = 0;
		run(20);
		/* an overload the servo does not shut down for: torque stays on */
		sv(2)->mem[70] = DXL2_HWERR_OVERLOAD;
		for (int i = 0; i < 20 && c.j[1].fault == CTL_FAULT_NONE; i++)
			tick();
		assert_int_equal(c.j[1].fault, CTL_FAULT_BACKOFF);
		run(20);
		sv(2)->mem[70] = 0;
		/* LIMP at the cycle whose step ends the back-off: the recovery is
		 * LIMP's (the output limit back, torque off), not a REBOOT */
		ctl_set_mode(&c, CFG_MODE_LIMP, "test");
		run(60);
		assert_int_equal(atomic_load(&xb.reboots), 0);
		assert_non_null(find_event("servo 2: recovered"));
		for (uint8_t id = 1; id <= 2; id++)
			assert_int_equal(sv(id)->mem[64], 0);
		/* a shutdown in HOLD: REBOOT and set-up */
		ctl_set_mode(&c, CFG_MODE_HOLD, "test");
		run(20);
		sv(1)->mem[70] = DXL2_HWERR_OVERHEAT;
		sv(1)->mem[64] = 0;
		sv(1)->hwerr_after_reboot = DXL2_HWERR_OVERHEAT;
		run(150);
		assert_true(c.latched);
		/* LIMP while latched, then 'clear' (the operator's REBOOT) and HOLD */
		ctl_set_mode(&c, CFG_MODE_LIMP, "test");
		run(20);
		sv(1)->hwerr_after_reboot = 0;
		char why[128];
		assert_true(ctl_clear_faults(&c, why, sizeof why));
		run(60);
		ctl_set_mode(&c, CFG_MODE_HOLD, "test");
		run(60);
		assert_int_equal(sv(1)->mem[64], 1);
		if (bad_write[0] != '\0')
			fail_msg("%s", bad_write);
		assert_true(writes_seen > 20);
		/* nothing written where the X servos keep their supply limits */
		for (uint8_t id = 1; id <= 2; id++)
			assert_int_equal(reg(id, 34, 2), dxl2_reg_at(dxl2_model_by_number(models[k][0]), 34)->def);
	}
	/* torque actuation (XL430: PWM control, XM430: current control): into
	 * the drive, a fault there, LIMP out of it */
	const char *drive[][4] = {
		{ "robot.actuation=torque", "robot.torque_drive=pwm", "robot.fault_backoff_s=0.2", NULL },
		{ "robot.actuation=torque", "robot.torque_drive=current", "robot.fault_backoff_s=0.2", NULL },
	};
	for (size_t k = 0; k < sizeof models / sizeof models[0]; k++) {
		setup_x(models[k], 2, CFG_MODE_HOLD, drive[k]);
		xb.on_write = check_write;
		bad_write[0] = '\0';
		for (uint8_t id = 1; id <= 2; id++)
			xfake_put(sv(id)->mem, 132, 2048 + 250, 4);
		run(10);
		ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
		run(10);
		assert_true(c.wheel);
		sv(2)->mem[70] = DXL2_HWERR_OVERLOAD;
		run(10);
		sv(2)->mem[70] = 0;
		run(60);
		ctl_set_mode(&c, CFG_MODE_LIMP, "test");
		run(20);
		assert_false(c.wheel);
		if (bad_write[0] != '\0')
			fail_msg("%s", bad_write);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_one_sync_read_one_sync_write),
		cmocka_unit_test(test_servo_missing_from_sync_read),
		cmocka_unit_test(test_reply_one_period_late),
		cmocka_unit_test(test_shutdown_recovered_by_reboot),
		cmocka_unit_test(test_shutdown_latches_when_reboot_does_not_help),
		cmocka_unit_test(test_watchdog_trip_recovered),
		cmocka_unit_test(test_power_loss_set_up_again),
		cmocka_unit_test(test_operating_mode_changed),
		cmocka_unit_test(test_torque_off_never_lost),
		cmocka_unit_test(test_clock_in_current_control),
		cmocka_unit_test(test_current_control_switch),
		cmocka_unit_test(test_switch_stops_half_way),
		cmocka_unit_test(test_drive_only_where_ready),
		cmocka_unit_test(test_writes_are_the_models),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
