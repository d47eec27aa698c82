/*
 * test_daemon_cycle.c — the cycle's bus work (cycle.h) through the seam it was
 * designed with: a fake transport with a fake clock (bus_io), and behind it a
 * small plant of AX-12 control tables that answers READ, WRITE and
 * SYNC_WRITE with the wire time a real bus takes. The loop that drives it is
 * the daemon's, reduced: a tick every 10 ms starts a cycle (cutting one still
 * on the bus), the transport's next byte or the deadline wakes the cycle, and
 * at CYC_CONTROL the controller steps. Faults are the plant's: lost, damaged
 * and late replies, a servo that resets, a bus that goes away, replies so
 * slow that the writes do not fit in the period.
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
#include "dxl.h"
#include "dxl_table.h"

#define PERIOD_US 10000
#define NSERVO_MAX 18
#define RX_CAP 8192

/* ---- the plant: AX-12 control tables ---------------------------------------------------------- */
struct servo {
	uint8_t id;
	uint8_t mem[DXL_AX_TABLE_SIZE];
	bool powered;
	int drop;              /* replies to lose */
	int corrupt;           /* replies to send with a bad checksum */
	uint64_t late_us;      /* the next READ(36)'s reply this much later than due */
	uint64_t slow_us;      /* every reply this much later (a slow servo) */
	uint8_t err;           /* error bits in every status (overload: the servo's fault) */
	unsigned writes[DXL_AX_TABLE_SIZE];   /* WRITE instructions per start address */
};

struct fake {
	uint64_t now;
	uint8_t rx[RX_CAP];
	uint64_t rx_at[RX_CAP];
	size_t head, tail;
	struct dxl_parser parser;
	int write_error;       /* the transport fails: DXL_E_DISCONNECTED */
	unsigned sync_writes;
};

static struct fake f;
static struct servo sv[NSERVO_MAX];
static size_t nsv;
static struct cfg cfg;
static struct ctl c;
static struct bus bus;
static struct cyc y;
static uint64_t next_tick;
static unsigned cuts;
static void (*at_control)(void);   /* run at the cycle boundary, before the step */
static void (*on_write_sent)(void);   /* run when a WRITE goes out (mid-cycle) */

static struct servo *servo_by_id(uint8_t id)
{
	for (size_t i = 0; i < nsv; i++)
		if (sv[i].id == id)
			return &sv[i];
	return NULL;
}

static void servo_ram_defaults(struct servo *s)
{
	memset(s->mem + DXL_AX_EEPROM_END, 0, sizeof s->mem - DXL_AX_EEPROM_END);
	s->mem[DXL_AX_CW_COMPLIANCE_MARGIN] = s->mem[DXL_AX_CCW_COMPLIANCE_MARGIN] = 1;
	s->mem[DXL_AX_CW_COMPLIANCE_SLOPE] = s->mem[DXL_AX_CCW_COMPLIANCE_SLOPE] = 32;
	dxl_put_u16(&s->mem[DXL_AX_TORQUE_LIMIT], 1023);
	dxl_put_u16(&s->mem[DXL_AX_PRESENT_POSITION], 512);
	dxl_put_u16(&s->mem[DXL_AX_GOAL_POSITION], 512);
	s->mem[DXL_AX_PRESENT_VOLTAGE] = 120;
	s->mem[DXL_AX_PRESENT_TEMPERATURE] = 30;
}

static void servo_init(struct servo *s, uint8_t id)
{
	memset(s, 0, sizeof *s);
	s->id = id;
	s->powered = true;
	dxl_put_u16(&s->mem[DXL_AX_MODEL_NUMBER], 12);
	s->mem[DXL_AX_ID] = id;
	dxl_put_u16(&s->mem[DXL_AX_CCW_ANGLE_LIMIT], 1023);
	dxl_put_u16(&s->mem[DXL_AX_MAX_TORQUE], 1023);
	s->mem[DXL_AX_STATUS_RETURN_LEVEL] = 2;
	servo_ram_defaults(s);
	/* as the daemon's start-up checks leave it (setup.c) */
	s->mem[DXL_AX_CW_COMPLIANCE_MARGIN] = s->mem[DXL_AX_CCW_COMPLIANCE_MARGIN] = 0;
}

static uint32_t wire_us(size_t bytes) { return (uint32_t)(bytes * 10); }   /* 1 Mbps, 8N1 */

static void push(const uint8_t *d, size_t n, uint64_t at)
{
	if (f.tail + n > RX_CAP && f.head > 0) {
		/* what was read is gone: room for long runs */
		memmove(f.rx, f.rx + f.head, f.tail - f.head);
		memmove(f.rx_at, f.rx_at + f.head, (f.tail - f.head) * sizeof f.rx_at[0]);
		f.tail -= f.head;
		f.head = 0;
	}
	assert_true(f.tail + n <= RX_CAP);
	for (size_t i = 0; i < n; i++) {
		f.rx[f.tail] = d[i];
		f.rx_at[f.tail++] = at;
	}
}

static void reply(struct servo *s, const uint8_t *params, size_t n, uint64_t at, bool is_read36)
{
	if (!s->powered)
		return;
	if (s->drop > 0) {
		s->drop--;
		return;
	}
	uint8_t pkt[DXL_MAX_PACKET];
	int len = dxl_encode_status(pkt, sizeof pkt, s->id, s->err, params, n);
	assert_true(len > 0);
	if (s->corrupt > 0) {
		s->corrupt--;
		pkt[len - 1] ^= 0xFF;
	}
	at += s->slow_us;
	if (is_read36 && s->late_us) {
		at += s->late_us;
		s->late_us = 0;
	}
	push(pkt, (size_t)len, at + wire_us((size_t)len));
}

static void (*on_plant_write)(const struct servo *s, uint8_t addr, size_t n);

static void plant_write(struct servo *s, uint8_t addr, const uint8_t *data, size_t n)
{
	if (s->powered && on_plant_write != NULL)
		on_plant_write(s, addr, n);
	if (!s->powered || addr + n > DXL_AX_TABLE_SIZE)
		return;
	memcpy(&s->mem[addr], data, n);
	s->writes[addr]++;
}

static void plant(const struct dxl_packet *p, uint64_t done)
{
	if (p->code == DXL_INST_SYNC_WRITE) {
		f.sync_writes++;
		uint8_t addr = p->params[0], len = p->params[1];
		for (size_t k = 2; k + 1 + len <= p->nparams; k += 1u + len) {
			struct servo *s = servo_by_id(p->params[k]);
			if (s != NULL)
				plant_write(s, addr, &p->params[k + 1], len);
		}
		return;
	}
	struct servo *s = servo_by_id(p->id);
	if (s == NULL)
		return;
	if (p->code == DXL_INST_READ) {
		uint8_t addr = p->params[0], len = p->params[1];
		assert_true(addr + len <= DXL_AX_TABLE_SIZE);
		reply(s, &s->mem[addr], len, done, addr == DXL_AX_PRESENT_POSITION);
	} else if (p->code == DXL_INST_WRITE) {
		plant_write(s, p->params[0], &p->params[1], p->nparams - 1u);
		if (on_write_sent != NULL)
			on_write_sent();
		reply(s, NULL, 0, done, false);
	}
}

/* ---- the transport ------------------------------------------------------------------------------ */
static int fake_write(void *ctx, const uint8_t *buf, size_t n)
{
	(void)ctx;
	if (f.write_error)
		return f.write_error;
	uint64_t done = f.now + wire_us(n);
	size_t off = 0;
	while (off < n) {
		size_t used = 0;
		struct dxl_packet p;
		int r = dxl_parser_feed(&f.parser, buf + off, n - off, &used, &p);
		off += used;
		if (r == DXL_FRAME)
			plant(&p, done);
		else if (r == DXL_NEED_MORE)
			break;
	}
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

/* bytes already due are stale input before a request */
static void fake_flush(void *ctx)
{
	(void)ctx;
	while (f.head < f.tail && f.rx_at[f.head] <= f.now)
		f.head++;
}

/* ---- the loop ------------------------------------------------------------------------------------ */
static long long bus_error_count;
static void on_bus_error(void *ctx, uint8_t id, const char *what, int status)
{
	(void)ctx; (void)id; (void)what; (void)status;
	bus_error_count++;
}

static void drive(enum cyc_status st)
{
	for (;;) {
		if (st == CYC_CONTROL) {
			if (at_control != NULL)
				at_control();
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
			return;   /* the tick comes first */
		if (wake > f.now)
			f.now = wake;
		st = cyc_step(&y);
	}
}

/* One tick: a cycle still on the bus is cut off, the events taken (true if
 * one of kind `kind` was among them or comes out of this cycle), a cycle run. */
static bool tick(const char *kind)
{
	bool seen = false;
	f.now = next_tick;
	next_tick += PERIOD_US;
	if (cyc_busy(&y)) {
		cyc_cut(&y);
		cuts++;
	}
	struct ctl_event e;
	while (ctl_next_event(&c, &e))
		seen = seen || (kind != NULL && strcmp(e.kind, kind) == 0);
	drive(cyc_start(&y));
	for (size_t k = 0; k < c.nevents && kind != NULL; k++)
		seen = seen || strcmp(c.events[k].kind, kind) == 0;
	return seen;
}

static void run(int cycles)
{
	for (int i = 0; i < cycles; i++)
		(void)tick(NULL);
}

static bool saw_event;
static void run_watching(int cycles, const char *kind)
{
	saw_event = false;
	for (int i = 0; i < cycles && !saw_event; i++)
		saw_event = tick(kind);
}

static void setup_n(size_t n, enum cfg_mode mode, uint32_t margin_us)
{
	struct cfg_errors e = { 0 };
	char ids[128] = "robot.ids=";
	memset(&f, 0, sizeof f);
	dxl_parser_init(&f.parser, DXL_PARSE_INSTRUCTION);
	nsv = n;
	for (size_t i = 0; i < n; i++) {
		servo_init(&sv[i], (uint8_t)(i + 1));
		snprintf(ids + strlen(ids), sizeof ids - strlen(ids), "%s%zu", i ? "," : "", i + 1);
	}
	cfg_defaults(&cfg);
	assert_true(cfg_override(&cfg, "robot.port=/dev/null", &e));
	assert_true(cfg_override(&cfg, ids, &e));
	cfg.mode = mode;
	assert_true(cfg_finish(&cfg, &e));
	ctl_init(&c, &cfg);
	char why[256];
	struct ctl_servo_info info = { .cw_limit = 0, .ccw_limit = 1023, .max_torque = 1023, .status_return_level = 2 };
	for (size_t j = 0; j < n; j++) {
		assert_true(ctl_set_servo(&c, j, &info, why, sizeof why));
		ctl_measure(&c, j, 512, 0, 0, 0, 0.01);
	}
	struct bus_io io = { .ctx = &f, .write = fake_write, .read = fake_read, .wait = fake_wait, .now_us = fake_now,
	                     .flush_input = fake_flush };
	struct bus_timing tm = { .baud = 1000000, .return_delay_us = 0, .adapter_latency_us = 0, .margin_us = margin_us };
	bus_init(&bus, &io, &tm, false);
	struct cyc_hooks hooks = { .bus_error = on_bus_error };
	cyc_init(&y, &bus, &c, PERIOD_US, &hooks);
	next_tick = 1000000;
	f.now = next_tick - PERIOD_US;
	cuts = 0;
	bus_error_count = 0;
	at_control = NULL;
	on_write_sent = NULL;
	on_plant_write = NULL;
	ctl_start(&c, 1e-6 * (double)f.now, "test");
}

static void setup(enum cfg_mode mode) { setup_n(2, mode, 500); }

/* ---- tests ------------------------------------------------------------------------------------ */
static void test_normal_cycles(void **state)
{
	(void)state;
	setup(CFG_MODE_HOLD);
	run(100);
	assert_int_equal(cuts, 0);
	assert_int_equal(y.errors, 0);
	assert_int_equal(f.sync_writes, 100);
	for (size_t i = 0; i < nsv; i++) {
		/* start-up: torque limit then torque on, each written exactly once */
		assert_int_equal(sv[i].mem[DXL_AX_TORQUE_ENABLE], 1);
		assert_int_equal(sv[i].writes[DXL_AX_TORQUE_ENABLE], 1);
		assert_int_equal(sv[i].writes[DXL_AX_TORQUE_LIMIT], 1);
		assert_int_equal(dxl_get_u16(&sv[i].mem[DXL_AX_GOAL_POSITION]), 512);
		/* read back, and seen to be on */
		assert_int_equal(c.j[i].torque_read, 1);
		assert_int_equal(c.j[i].torque_limit_read, 1023);
		assert_int_equal(c.j[i].stale_cycles, 0);
	}
	/* every 5 cycles one joint read back: 20 in 100 cycles */
	assert_int_equal(y.readbacks, 20);
	/* and the cycle's bus time is the wire time, far inside the period */
	assert_true(y.bus_us > 400 && y.bus_us < 2000);
	assert_int_equal(wq_pending(&c.wq), 0);
}

static void test_lost_and_damaged_replies(void **state)
{
	(void)state;
	setup(CFG_MODE_HOLD);
	run(10);
	sv[1].drop = 1;
	run(1);
	assert_int_equal(c.j[1].stale_cycles, 1);   /* this cycle joint 2 had no reading */
	assert_int_equal(c.j[0].stale_cycles, 0);   /* joint 1 did */
	assert_int_equal(y.errors, 1);
	sv[0].corrupt = 1;
	run(1);
	assert_int_equal(c.j[0].stale_cycles, 1);
	assert_int_equal(c.j[1].stale_cycles, 0);
	assert_int_equal(y.errors, 2);
	assert_int_equal(bus.servo[1].checksum_errors, 1);
	run(5);
	assert_int_equal(c.j[0].stale_cycles + c.j[1].stale_cycles, 0);
	assert_int_equal(cuts, 0);
}

/* A reply a whole period late must never be taken for the next cycle's
 * reading: the servo has moved since. */
static void test_reply_one_period_late(void **state)
{
	(void)state;
	setup(CFG_MODE_HOLD);
	run(11);   /* an odd count: the next READ asks for 6 bytes, the one after for 8 */
	dxl_put_u16(&sv[0].mem[DXL_AX_PRESENT_POSITION], 600);
	/* arrives 100 µs into the next cycle, before that cycle's own reply */
	sv[0].late_us = PERIOD_US - 220 + 100;
	run(1);
	assert_int_equal(c.j[0].stale_cycles, 1);   /* lost to the timeout in its own cycle */
	/* the servo moves on; the next cycle's READ must see 700, or nothing */
	dxl_put_u16(&sv[0].mem[DXL_AX_PRESENT_POSITION], 700);
	run(1);
	if (c.j[0].stale_cycles == 0 && dxl_rad_to_pos(c.j[0].angle) != 700)
		fail_msg("the late reply (600) was taken as this cycle's reading (%u)", dxl_rad_to_pos(c.j[0].angle));
	run(2);
	assert_int_equal(dxl_rad_to_pos(c.j[0].angle), 700);
	assert_int_equal(c.j[0].stale_cycles, 0);
}

/* 18 servos whose replies are slow: the writes of a start do not fit after
 * the reads; the rest wait for the next cycle and each is sent once. */
static void test_writes_that_do_not_fit(void **state)
{
	(void)state;
	setup_n(18, CFG_MODE_HOLD, 500);
	for (size_t i = 0; i < nsv; i++)
		sv[i].slow_us = 150;
	run(30);
	assert_true(y.deferred > 0);   /* they did not fit at once */
	for (size_t i = 0; i < nsv; i++) {
		assert_int_equal(sv[i].mem[DXL_AX_TORQUE_ENABLE], 1);
		assert_int_equal(sv[i].writes[DXL_AX_TORQUE_ENABLE], 1);
		assert_int_equal(sv[i].writes[DXL_AX_TORQUE_LIMIT], 1);
	}
	assert_int_equal(cuts, 0);
	assert_int_equal(wq_pending(&c.wq), 0);
}

/* Replies so slow that a cycle is still on the bus at the next tick: it is
 * cut off; a write cut off on the wire is sent again, none is lost. */
static void test_overrun_cut_off(void **state)
{
	(void)state;
	/* a long timeout (6.5 ms of margin), and servo 2 answering 6 ms late for
	 * one cycle: its READ ends at 6.4 ms, servo 1's two writes follow, and
	 * servo 2's torque limit write begins before 7 ms, waiting past the tick */
	setup_n(2, CFG_MODE_LIMP, 6500);
	run(10);
	sv[1].slow_us = 6000;
	ctl_set_mode(&c, CFG_MODE_HOLD, "test");
	run(1);
	assert_true(cyc_busy(&y));
	sv[1].slow_us = 0;
	run(10);
	assert_int_equal(cuts, 1);
	for (size_t i = 0; i < nsv; i++) {
		assert_int_equal(sv[i].mem[DXL_AX_TORQUE_ENABLE], 1);
		assert_int_equal(dxl_get_u16(&sv[i].mem[DXL_AX_TORQUE_LIMIT]), 1023);
	}
	/* the write cut off was sent again: servo 2's torque limit twice */
	assert_int_equal(sv[1].writes[DXL_AX_TORQUE_LIMIT], 2);
	assert_int_equal(sv[0].writes[DXL_AX_TORQUE_LIMIT], 1);
	assert_int_equal(c.write_failures, 0);
	assert_int_equal(wq_pending(&c.wq), 0);
}

/* A bus so slow that the reads alone take past 70 % of every period: the
 * writes would wait forever behind them; a LIMP's torque-off must still get
 * out, one write before the reads once they have waited two cycles. */
static void test_writes_never_starve(void **state)
{
	(void)state;
	setup_n(2, CFG_MODE_HOLD, 6000);
	run(10);
	for (size_t i = 0; i < nsv; i++)
		sv[i].slow_us = 3500;   /* two READs: 7.4 ms */
	run(5);
	ctl_set_mode(&c, CFG_MODE_LIMP, "test");
	run(12);
	for (size_t i = 0; i < nsv; i++)
		assert_int_equal(sv[i].mem[DXL_AX_TORQUE_ENABLE], 0);
	assert_true(y.writes_first >= 2);
	assert_int_equal(c.write_failures, 0);
	assert_int_equal(wq_pending(&c.wq), 0);
}

/* LIMP applied while HOLD's torque-on is on the wire (as a command applied
 * mid-cycle once could be): the torque-off is queued behind it, never
 * merged into it and dropped. */
static int limp_after_writes = -1;
static void limp_mid_write(void)
{
	if (limp_after_writes > 0 && --limp_after_writes == 0)
		ctl_set_mode(&c, CFG_MODE_LIMP, "test: mid-cycle");
}

static void test_torque_off_never_lost(void **state)
{
	(void)state;
	for (int k = 1; k <= 4; k++) {
		setup(CFG_MODE_LIMP);
		run(5);
		ctl_set_mode(&c, CFG_MODE_HOLD, "test");   /* queues torque limit + torque on per servo */
		limp_after_writes = k;                      /* LIMP after the k-th of those writes is sent */
		on_write_sent = limp_mid_write;
		run(5);
		on_write_sent = NULL;
		assert_int_equal(c.mode, CFG_MODE_LIMP);
		for (size_t i = 0; i < nsv; i++)
			if (sv[i].mem[DXL_AX_TORQUE_ENABLE] != 0)
				fail_msg("LIMP after write %d: servo %u torque on", k, sv[i].id);
	}
}

/* A servo that lost power comes back with torque off and factory RAM: the
 * read-back finds it, it is reported and set up again. */
static void test_servo_reset_found(void **state)
{
	(void)state;
	setup(CFG_MODE_HOLD);
	run(50);
	assert_int_equal(sv[1].mem[DXL_AX_CW_COMPLIANCE_MARGIN], 0);
	servo_ram_defaults(&sv[1]);   /* torque 0, margins 1 */
	run_watching(12, "servo-reset");
	assert_true(saw_event);
	run(5);
	assert_int_equal(sv[1].mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(sv[1].mem[DXL_AX_CW_COMPLIANCE_MARGIN], 0);
	assert_int_equal(sv[1].mem[DXL_AX_CCW_COMPLIANCE_MARGIN], 0);
	assert_int_equal(c.j[1].resets, 1);
	run(10);
	assert_int_equal(c.j[1].torque_read, 1);
	assert_false(c.latched);
}

/* A write the servo never acknowledges is sent WQ_TRIES times, then given up
 * and reported. */
static void test_write_given_up(void **state)
{
	(void)state;
	setup(CFG_MODE_HOLD);
	run(10);
	unsigned before = sv[0].writes[DXL_AX_TORQUE_ENABLE];
	sv[0].drop = 100;   /* its replies are lost (it still executes: the write lands) */
	ctl_set_mode(&c, CFG_MODE_LIMP, "test");
	run_watching(10, "write-failed");
	assert_true(saw_event);

	assert_int_equal(sv[0].writes[DXL_AX_TORQUE_ENABLE] - before, WQ_TRIES);
	assert_int_equal(c.write_failures, 1);
	assert_int_equal(sv[0].mem[DXL_AX_TORQUE_ENABLE], 0);
}

/* The port goes away: the cycle reports it lost, with nothing left pending. */
static void test_bus_lost(void **state)
{
	(void)state;
	setup(CFG_MODE_HOLD);
	run(10);
	f.write_error = DXL_E_DISCONNECTED;
	f.now = next_tick;
	next_tick += PERIOD_US;
	enum cyc_status st = cyc_start(&y);
	assert_int_equal(st, CYC_LOST);
	assert_int_equal(y.lost, DXL_E_DISCONNECTED);
	assert_false(cyc_busy(&y));
	assert_false(bus_is_pending(&bus));
}

/* ---- every register written is the model's ----------------------------------------------------
 * What undulated writes on an AX-12A, by the manual's names (dxl_table.c):
 * torque, the torque limit, the goal (with moving speed), moving speed, the
 * compliance margins and slopes (CW and CCW in one write), and with torque
 * off the angle limits (both in one write). A write may span consecutive
 * registers, each of them one of these. */
static const char *const ax_written[] = {
	"torque_enable", "torque_limit", "goal_position", "moving_speed", "cw_compliance_margin",
	"ccw_compliance_margin", "cw_compliance_slope", "ccw_compliance_slope", "cw_angle_limit", "ccw_angle_limit",
	NULL,
};
static char bad_write[160];
static unsigned writes_seen;

static bool ax_ours(const struct dxl_reg *r)
{
	for (size_t i = 0; r != NULL && ax_written[i] != NULL; i++)
		if (strcmp(r->name, ax_written[i]) == 0)
			return r->access == DXL_ACCESS_RW;
	return false;
}

static void check_write(const struct servo *s, uint8_t addr, size_t n)
{
	writes_seen++;
	size_t at = addr;
	const struct dxl_reg *r = NULL;
	while (at < addr + n && ax_ours(r = dxl_reg_at((uint8_t)at)))
		at += r->size;
	if (at == addr + n || bad_write[0] != '\0')
		return;
	snprintf(bad_write, sizeof bad_write, "servo %u (AX-12A): %zu byte(s) written at %u (%s at %zu)", s->id, n,
	         addr, r != NULL ? r->name : "no register", at);
}

/* The AX-12A through the fault paths and LIMP, as test_daemon_cycle2.c takes
 * each X model: an overload whose back-off ends in LIMP, one that persists
 * and latches, 'clear', HOLD and LIMP again; every write checked against
 * the AX-12's table. */
static void test_writes_are_the_models(void **state)
{
	(void)state;
	setup(CFG_MODE_HOLD);
	cfg.fault_backoff_s = 0.205;
	on_plant_write = check_write;
	bad_write[0] = '\0';
	writes_seen = 0;
	run(20);
	sv[1].err = DXL_ERRBIT_OVERLOAD;
	for (int i = 0; i < 20 && c.j[1].fault == CTL_FAULT_NONE; i++)
		run(1);
	assert_int_equal(c.j[1].fault, CTL_FAULT_BACKOFF);
	assert_int_equal(dxl_get_u16(&sv[1].mem[DXL_AX_TORQUE_LIMIT]), 512);   /* backing off at half */
	run(20);
	sv[1].err = 0;
	ctl_set_mode(&c, CFG_MODE_LIMP, "test");
	run(60);
	assert_int_equal(c.j[1].fault, CTL_FAULT_NONE);
	assert_int_equal(dxl_get_u16(&sv[1].mem[DXL_AX_TORQUE_LIMIT]), 1023);
	/* an overload that persists: latched, then 'clear' */
	ctl_set_mode(&c, CFG_MODE_HOLD, "test");
	run(20);
	sv[0].err = DXL_ERRBIT_OVERLOAD;
	run(200);
	assert_true(c.latched);
	ctl_set_mode(&c, CFG_MODE_LIMP, "test");
	run(20);
	sv[0].err = 0;
	char why[128];
	assert_true(ctl_clear_faults(&c, why, sizeof why));
	ctl_set_mode(&c, CFG_MODE_HOLD, "test");
	run(60);
	assert_int_equal(sv[0].mem[DXL_AX_TORQUE_ENABLE], 1);
	if (bad_write[0] != '\0')
		fail_msg("%s", bad_write);
	assert_true(writes_seen > 10);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_normal_cycles),
		cmocka_unit_test(test_lost_and_damaged_replies),
		cmocka_unit_test(test_reply_one_period_late),
		cmocka_unit_test(test_writes_that_do_not_fit),
		cmocka_unit_test(test_overrun_cut_off),
		cmocka_unit_test(test_writes_never_starve),
		cmocka_unit_test(test_torque_off_never_lost),
		cmocka_unit_test(test_servo_reset_found),
		cmocka_unit_test(test_write_given_up),
		cmocka_unit_test(test_bus_lost),
		cmocka_unit_test(test_writes_are_the_models),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
