/*
 * test_daemon_cycle.c — the cycle's bus work (cycle.h) and the controller
 * through the seam they were designed with: a fake transport with a fake
 * clock (bus_io), and behind it one of two fake buses, each with the wire
 * time a real bus takes at 1 Mbps:
 *  - AX-12A: a small plant of AX-12 control tables on Protocol 1.0 that
 *    answers READ, WRITE and SYNC_WRITE;
 *  - X series: the fake X servos of xfake.h (their own CRC and stuffing;
 *    the e-manual's refusals) on Protocol 2.0.
 * The loop that drives it is the daemon's, reduced: a tick every 10 ms
 * starts a cycle (cutting one still on the bus), the transport's next byte
 * or the deadline wakes the cycle, and at CYC_CONTROL the controller steps.
 *
 * What both families must do is one test body run on each bus (struct
 * backend: the servos' registers and how each bus loses or delays a reply):
 * normal cycles, a lost and a damaged reply, a reply a period late, LIMP
 * racing HOLD's writes. What only one family has is tested on its bus: on
 * the AX-12's, writes that do not fit, a cycle cut off by the tick, writes
 * that never starve, a servo reset, a write given up, the port going away;
 * on the X series', a hardware-error shutdown found through the alert and
 * recovered by one REBOOT or latched, a tripped bus watchdog, a power loss,
 * an Operating Mode changed behind the controller's back, torque actuation
 * switching into current control and back, and a switch that stops
 * half-way. Each model's fault and LIMP paths are checked write by write
 * against its control table (writes_are_the_models).
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
#include "../../daemon/setup.h"
#include "bus.h"
#include "dxl.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "dxl_table.h"
#include "xfake.h"

#define PERIOD_US 10000
#define NSERVO_MAX 18
#define RX_CAP 16384
#define WATCHDOG_UNITS 5   /* the default 100 ms */

/* ---- the transport and the clock, over either bus --------------------------------------------- */
struct fake {
	bool x;                    /* the X series' bus (xfake.h), else the AX-12 plant */
	uint64_t now;
	uint8_t rx[RX_CAP];
	uint64_t rx_at[RX_CAP];
	size_t head, tail;
	int write_error;           /* the transport fails: DXL_E_DISCONNECTED */
	/* the AX-12 plant */
	struct dxl_parser parser;
	unsigned sync_writes;
	/* the X bus */
	uint64_t request_end;      /* when the request being answered ended on the wire */
	uint64_t line_free;        /* when the last reply queued ends */
	uint64_t late_us;          /* the next reply this much later */
	int corrupt;               /* replies to damage (a bit of their CRC) */
	uint64_t bytes_out, bytes_in;   /* on the wire: the controller's, the servos' */
};

static struct fake f;
static struct cfg cfg;
static struct ctl c;
static struct bus bus;
static struct cyc y;
static uint64_t next_tick;
/* the period of the test's cycle: the configuration's (robot.period_ms, 10 ms unless set) */
static uint64_t period_us = PERIOD_US;
static unsigned cuts;
static void (*at_control)(void);   /* run at the cycle boundary, before the step */
static void (*on_write_sent)(void);   /* run when a WRITE goes out (mid-cycle) */

static uint64_t wire_us(size_t bytes) { return bytes * 10; }   /* 1 Mbps, 8N1 */

/* Room for n more bytes of replies on the fake line, either bus's. */
static void rx_room(size_t n)
{
	if (f.tail + n > RX_CAP && f.head > 0) {
		/* what was read is gone: room for long runs */
		memmove(f.rx, f.rx + f.head, f.tail - f.head);
		memmove(f.rx_at, f.rx_at + f.head, (f.tail - f.head) * sizeof f.rx_at[0]);
		f.tail -= f.head;
		f.head = 0;
	}
	assert_true(f.tail + n <= RX_CAP);
}

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

static struct servo sv[NSERVO_MAX];
static size_t nsv;

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

static void push(const uint8_t *d, size_t n, uint64_t at)
{
	rx_room(n);
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

/* ---- the X bus: xfake.h's servos ------------------------------------------------------------ */
static struct xfake xb;

/* Replies follow one another on the line, each after its servo's return delay. */
static void emit(void *ctx, const uint8_t *pkt, size_t n, unsigned delay_us)
{
	(void)ctx;
	uint64_t start = (f.request_end > f.line_free ? f.request_end : f.line_free) + delay_us + f.late_us;
	f.late_us = 0;
	f.bytes_in += n;
	rx_room(n);
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

/* ---- the transport ------------------------------------------------------------------------------ */
static void fake_write_ax(const uint8_t *buf, size_t n)
{
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
}

static void fake_write_x(const uint8_t *buf, size_t n)
{
	f.request_end = f.now + wire_us(n);
	f.line_free = f.request_end;
	f.bytes_out += n;
	unsigned writes = atomic_load(&xb.writes) + atomic_load(&xb.reboots);
	xfake_feed(&xb, buf, n);
	if (on_write_sent != NULL && atomic_load(&xb.writes) + atomic_load(&xb.reboots) != writes)
		on_write_sent();
}

static int fake_write(void *ctx, const uint8_t *buf, size_t n)
{
	(void)ctx;
	if (f.write_error)
		return f.write_error;
	if (f.x)
		fake_write_x(buf, n);
	else
		fake_write_ax(buf, n);
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
			ctl_step(&c, 1e-6 * (double)f.now, 1e-6 * (double)period_us, 1e-6 * (double)f.now);
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

/* The controller's events as they come, "kind: text" (the first 64). */
static char events[64][CTL_EVENT_TEXT + 32];
static size_t nevents;

/* Takes the events; true if one of kind `kind` was among them. */
static bool take_events(const char *kind)
{
	struct ctl_event e;
	bool seen = false;
	while (ctl_next_event(&c, &e)) {
		seen = seen || (kind != NULL && strcmp(e.kind, kind) == 0);
		if (nevents < 64)
			snprintf(events[nevents++], sizeof events[0], "%s: %s", e.kind, e.text);
	}
	return seen;
}

static const char *find_event(const char *needle)
{
	for (size_t i = 0; i < nevents; i++)
		if (strstr(events[i], needle) != NULL)
			return events[i];
	return NULL;
}

/* One tick: a cycle still on the bus is cut off, a cycle run; true if an
 * event of kind `kind` came since the last tick or out of this cycle. */
static bool tick(const char *kind)
{
	f.now = next_tick;
	next_tick += period_us;
	if (cyc_busy(&y)) {
		cyc_cut(&y);
		cuts++;
	}
	bool seen = take_events(kind);
	drive(cyc_start(&y));
	return take_events(kind) || seen;
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

/* What both set-ups share: the configuration (with `sets`), the bus over
 * the fake transport, the cycle, the clock. */
static void setup_common(size_t n, enum cfg_mode mode, const char *const *sets)
{
	struct cfg_errors e = { 0 };
	char ids[128] = "robot.ids=";
	for (size_t i = 0; i < n; i++)
		snprintf(ids + strlen(ids), sizeof ids - strlen(ids), "%s%zu", i ? "," : "", i + 1);
	cfg_defaults(&cfg);
	assert_true(cfg_override(&cfg, "robot.port=/dev/null", &e));
	assert_true(cfg_override(&cfg, ids, &e));
	for (size_t i = 0; sets != NULL && sets[i] != NULL; i++)
		assert_true(cfg_override(&cfg, sets[i], &e));
	cfg.mode = mode;
	assert_true(cfg_finish(&cfg, &e));
	ctl_init(&c, &cfg);
}

/* the cycle's notices (a change of how it reads): the last one, and how many */
static char last_notice[256];
static int notices;
static void on_notice(void *ctx, const char *text)
{
	(void)ctx;
	snprintf(last_notice, sizeof last_notice, "%s", text);
	notices++;
}

static void setup_start(uint32_t margin_us, enum bus_protocol protocol)
{
	struct bus_io io = { .ctx = &f, .write = fake_write, .read = fake_read, .wait = fake_wait, .now_us = fake_now,
	                     .flush_input = fake_flush };
	struct bus_timing tm = { .baud = 1000000, .return_delay_us = 0, .adapter_latency_us = 0, .margin_us = margin_us };
	bus_init(&bus, &io, &tm, false);
	assert_int_equal(bus_set_protocol(&bus, protocol), DXL_OK);
	struct cyc_hooks hooks = { .bus_error = on_bus_error, .notice = on_notice };
	period_us = (uint64_t)(cfg.period_ms * 1000.0 + 0.5);
	cyc_init(&y, &bus, &c, period_us, &hooks);
	next_tick = 1000000;
	f.now = next_tick - period_us;
	cuts = 0;
	nevents = 0;
	bus_error_count = 0;
	at_control = NULL;
	on_write_sent = NULL;
	ctl_start(&c, 1e-6 * (double)f.now, "test");
}

/* n AX-12As as undulated's start-up leaves them. */
static void setup_n(size_t n, enum cfg_mode mode, uint32_t margin_us)
{
	memset(&f, 0, sizeof f);
	dxl_parser_init(&f.parser, DXL_PARSE_INSTRUCTION);
	nsv = n;
	for (size_t i = 0; i < n; i++)
		servo_init(&sv[i], (uint8_t)(i + 1));
	on_plant_write = NULL;
	setup_common(n, mode, NULL);
	char why[256];
	struct ctl_servo_info info = { .cw_limit = 0, .ccw_limit = 1023, .max_torque = 1023, .status_return_level = 2 };
	for (size_t j = 0; j < n; j++) {
		assert_true(ctl_set_servo(&c, j, &info, why, sizeof why));
		ctl_measure(&c, j, 512, 0, 0, 0, 0.01);
	}
	setup_start(margin_us, BUS_PROTOCOL_1);
}

static void setup(enum cfg_mode mode) { setup_n(2, mode, 500); }

static struct xfake_servo *xs(uint8_t id) { return xfake_servo_by_id(&xb, id); }
static uint32_t xreg(uint8_t id, uint16_t addr, int size) { return xfake_get(xs(id)->mem, addr, size); }

/* Two X servos (or the models given) as undulated's start-up leaves them:
 * 1 Mbps, return delay 0, position control, the watchdog set, torque off. */
static void setup_x(const uint16_t *models, size_t n, enum cfg_mode mode, const char *const *sets)
{
	memset(&f, 0, sizeof f);
	f.x = true;
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
	}
	setup_common(n, mode, sets);
	char why[256];
	for (size_t j = 0; j < n; j++) {
		struct ctl_servo_info info = { .cw_limit = 2048 - 1700, .ccw_limit = 2048 + 1700, .max_torque = 885,
		                               .status_return_level = 2, .model = sm_by_number(2, models[j]),
		                               .current_limit = 1193 };
		assert_true(ctl_set_servo(&c, j, &info, why, sizeof why));
		struct sm_present p = { .pos_raw = 2048, .angle = 0, .voltage = NAN, .temperature = NAN };
		ctl_measure_present(&c, j, &p, 0, 0.01);
	}
	setup_start(500, BUS_PROTOCOL_2);
}

static const uint16_t xm2[] = { DXL2_MODEL_XM430_W350, DXL2_MODEL_XM430_W350 };
static const uint16_t xl_xm[] = { DXL2_MODEL_XL430_W250, DXL2_MODEL_XM430_W350 };

/* ---- the two buses, as the tests that run on both see them ------------------------------------ */
struct backend {
	const char *name;
	void (*setup)(size_t n, enum cfg_mode mode);
	uint32_t (*reg)(uint8_t id, uint16_t addr, int size);
	void (*put)(uint8_t id, uint16_t addr, uint32_t v, int size);
	uint16_t torque_enable, present_position;
	int pos_size;
	int32_t centre;
	/* a reply a whole period late: how late, and on a bus of how many servos */
	uint64_t late_us;
	size_t late_servos;
	void (*late_next)(uint8_t id, uint64_t us);
	void (*lose_next)(uint8_t id);       /* the servo's next reply lost ... */
	void (*found_again)(uint8_t id);     /* ... and it answers again */
	void (*damage_next)(uint8_t id);     /* its next reply damaged */
	unsigned (*sync_writes)(void);
	uint64_t bus_us_min, bus_us_max;     /* a normal cycle's bus time */
	void (*normal_servo)(uint8_t id);    /* what else normal cycles leave on the family's servo */
};

static void ax_setup(size_t n, enum cfg_mode mode) { setup_n(n, mode, 500); }
static uint32_t ax_reg(uint8_t id, uint16_t addr, int size)
{
	return size == 1 ? sv[id - 1].mem[addr] : dxl_get_u16(&sv[id - 1].mem[addr]);
}
static void ax_put(uint8_t id, uint16_t addr, uint32_t v, int size)
{
	if (size == 1)
		sv[id - 1].mem[addr] = (uint8_t)v;
	else
		dxl_put_u16(&sv[id - 1].mem[addr], (uint16_t)v);
}
static void ax_late_next(uint8_t id, uint64_t us) { sv[id - 1].late_us = us; }
static void ax_lose_next(uint8_t id) { sv[id - 1].drop = 1; }
static void ax_found_again(uint8_t id) { (void)id; }
static void ax_damage_next(uint8_t id) { sv[id - 1].corrupt = 1; }
static unsigned ax_sync_writes(void) { return f.sync_writes; }
static void ax_normal_servo(uint8_t id)
{
	/* start-up: torque limit then torque on, each written exactly once */
	assert_int_equal(sv[id - 1].writes[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(sv[id - 1].writes[DXL_AX_TORQUE_LIMIT], 1);
	assert_int_equal(dxl_get_u16(&sv[id - 1].mem[DXL_AX_GOAL_POSITION]), 512);
	assert_int_equal(c.j[id - 1].torque_limit_read, 1023);
}

static void x_setup(size_t n, enum cfg_mode mode) { setup_x(xm2, n, mode, NULL); }
static void x_put(uint8_t id, uint16_t addr, uint32_t v, int size) { xfake_put(xs(id)->mem, addr, v, size); }
/* the next reply on the line, whichever servo sends it */
static void x_late_next(uint8_t id, uint64_t us) { (void)id; f.late_us = us; }
static void x_lose_next(uint8_t id) { xs(id)->powered = false; }
static void x_found_again(uint8_t id) { xs(id)->powered = true; }
/* the next reply on the line: servo 1's comes first in the SYNC_READ */
static void x_damage_next(uint8_t id) { (void)id; f.corrupt = 1; }
static unsigned x_sync_writes(void) { return atomic_load(&xb.sync_writes); }
static void x_normal_servo(uint8_t id)
{
	assert_int_equal(atomic_load(&xb.sync_reads), 100);   /* one SYNC_READ a cycle */
	assert_int_equal(xreg(id, 100, 2), 885);              /* Goal PWM at PWM Limit */
	assert_int_equal(xreg(id, 116, 4), 2048);             /* holding where it stands */
	const struct ctl_joint *jt = &c.j[id - 1];
	assert_int_equal(jt->opmode_read, 3);
	assert_int_equal(jt->watchdog_read, WATCHDOG_UNITS);
	assert_int_equal(jt->hwerr, 0);
	/* the slow read every other cycle brings voltage and temperature */
	assert_true(fabs(jt->voltage - 12.0) < 1e-9 && fabs(jt->temperature - 36) < 1e-9);
	assert_int_equal(c.readback_mismatches, 0);
}

/* The AX-12's READ(36) reply 100 µs into the next cycle, before that
 * cycle's own; on the X bus the SYNC_READ's reply late by as much. */
static struct backend ax_bus = {
	.name = "AX-12A", .setup = ax_setup, .reg = ax_reg, .put = ax_put,
	.torque_enable = DXL_AX_TORQUE_ENABLE, .present_position = DXL_AX_PRESENT_POSITION, .pos_size = 2, .centre = 512,
	.late_us = PERIOD_US - 220 + 100, .late_servos = 2, .late_next = ax_late_next,
	.lose_next = ax_lose_next, .found_again = ax_found_again, .damage_next = ax_damage_next,
	.sync_writes = ax_sync_writes, .bus_us_min = 400, .bus_us_max = 2000, .normal_servo = ax_normal_servo,
};
/* SYNC_READ of 21 bytes from two servos and the goals' SYNC_WRITE: 16 + 2 x
 * 32 + 24 bytes at 1 Mbps, about 1 ms */
#define X_BUS(bus_name, setup_fn) { \
	.name = bus_name, .setup = setup_fn, .reg = xreg, .put = x_put, \
	.torque_enable = 64, .present_position = 132, .pos_size = 4, .centre = 2048, \
	.late_us = PERIOD_US - 100, .late_servos = 1, .late_next = x_late_next, \
	.lose_next = x_lose_next, .found_again = x_found_again, .damage_next = x_damage_next, \
	.sync_writes = x_sync_writes, .bus_us_min = 500, .bus_us_max = 2500, .normal_servo = x_normal_servo, \
}
static struct backend x_bus = X_BUS("XM430-W350", x_setup);
/* an XL430 beside an XM430: two models on one bus */
static void x_setup_mixed(size_t n, enum cfg_mode mode) { setup_x(xl_xm, n, mode, NULL); }
static struct backend x_mixed_bus = X_BUS("XL430-W250 + XM430-W350", x_setup_mixed);

/* ---- tests on both buses ---------------------------------------------------------------------- */
static void test_normal_cycles(void **state)
{
	const struct backend *b = *state;
	b->setup(2, CFG_MODE_HOLD);
	run(100);
	assert_int_equal(cuts, 0);
	assert_int_equal(y.errors, 0);
	assert_int_equal(b->sync_writes(), 100);
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(b->reg(id, b->torque_enable, 1), 1);
		/* read back, and seen to be on */
		assert_int_equal(c.j[id - 1].torque_read, 1);
		assert_int_equal(c.j[id - 1].stale_cycles, 0);
		b->normal_servo(id);
	}
	/* every 5 cycles one joint read back: 20 in 100 cycles */
	assert_int_equal(y.readbacks, 20);
	/* and the cycle's bus time is the wire time, far inside the period */
	assert_true(y.bus_us > b->bus_us_min && y.bus_us < b->bus_us_max);
	assert_int_equal(wq_pending(&c.wq), 0);
}

/* A lost reply (on the X bus: a servo missing from the SYNC_READ, the others
 * read) and a damaged one: that joint stale for a cycle, the bus names it. */
static void test_lost_and_damaged_replies(void **state)
{
	const struct backend *b = *state;
	b->setup(2, CFG_MODE_HOLD);
	run(10);
	b->lose_next(2);
	run(1);
	b->found_again(2);
	assert_int_equal(c.j[1].stale_cycles, 1);   /* this cycle joint 2 had no reading */
	assert_int_equal(c.j[0].stale_cycles, 0);   /* joint 1 did */
	assert_int_equal(y.errors, 1);
	assert_int_equal(bus.servo[2].timeouts, 1);
	b->damage_next(1);
	run(1);
	assert_int_equal(c.j[0].stale_cycles, 1);
	assert_int_equal(c.j[1].stale_cycles, 0);
	assert_int_equal(bus.servo[1].checksum_errors, 1);
	run(5);
	assert_int_equal(c.j[0].stale_cycles + c.j[1].stale_cycles, 0);
	assert_int_equal(cuts, 0);
}

/* A reply a whole period late must never be taken for the next cycle's
 * reading: the servo has moved since. */
static void test_reply_one_period_late(void **state)
{
	const struct backend *b = *state;
	b->setup(b->late_servos, CFG_MODE_HOLD);
	run(11);   /* an odd count: the next read is the short one */
	int32_t moved = b->centre + (b->pos_size == 2 ? 88 : 552), on = moved + 100;
	b->put(1, b->present_position, (uint32_t)moved, b->pos_size);
	b->late_next(1, b->late_us);
	run(1);
	assert_int_equal(c.j[0].stale_cycles, 1);   /* lost to the timeout in its own cycle */
	/* the servo moves on; the next cycle's read must see it, or nothing */
	b->put(1, b->present_position, (uint32_t)on, b->pos_size);
	run(1);
	int32_t got = sm_rad_to_pos(ctl_model(&c, 0), c.j[0].angle);
	if (c.j[0].stale_cycles == 0 && got != on)
		fail_msg("the late reply (%d) was taken as this cycle's reading (%d)", moved, got);
	run(2);
	assert_int_equal(sm_rad_to_pos(ctl_model(&c, 0), c.j[0].angle), on);
	assert_int_equal(c.j[0].stale_cycles, 0);
}

/* LIMP applied while HOLD's writes are on the wire (as a command applied
 * mid-cycle once could be): the torque-off is queued behind them, never
 * merged into one and dropped; whatever was sent, torque ends off. */
static int limp_after_writes = -1;
static void limp_mid_write(void)
{
	if (limp_after_writes > 0 && --limp_after_writes == 0)
		ctl_set_mode(&c, CFG_MODE_LIMP, "test: mid-cycle");
}

static void test_torque_off_never_lost(void **state)
{
	const struct backend *b = *state;
	for (int k = 1; k <= 4; k++) {
		b->setup(2, CFG_MODE_LIMP);
		run(5);
		ctl_set_mode(&c, CFG_MODE_HOLD, "test");   /* queues HOLD's writes per servo */
		limp_after_writes = k;                      /* LIMP after the k-th of those writes is sent */
		on_write_sent = limp_mid_write;
		run(5);
		on_write_sent = NULL;
		assert_int_equal(c.mode, CFG_MODE_LIMP);
		for (uint8_t id = 1; id <= 2; id++)
			if (b->reg(id, b->torque_enable, 1) != 0)
				fail_msg("%s, LIMP after write %d: servo %u torque on", b->name, k, id);
	}
}

/* ---- the AX-12's bus ---------------------------------------------------------------------------- */
/* ---- every register written is the model's: what each bus's tests collect -------------------- */
static char bad_write[160];
static unsigned writes_seen;

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

static bool ax_ours(const struct dxl_reg *r)
{
	for (size_t i = 0; r != NULL && ax_written[i] != NULL; i++)
		if (strcmp(r->name, ax_written[i]) == 0)
			return r->access == DXL_ACCESS_RW;
	return false;
}

static void ax_check_write(const struct servo *s, uint8_t addr, size_t n)
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

/* The AX-12A through the fault paths and LIMP, as test_writes_are_the_models_x
 * takes each X model: an overload whose back-off ends in LIMP, one that persists
 * and latches, 'clear', HOLD and LIMP again; every write checked against
 * the AX-12's table. */
static void test_writes_are_the_models_ax(void **state)
{
	(void)state;
	setup(CFG_MODE_HOLD);
	cfg.fault_backoff_s = 0.205;
	on_plant_write = ax_check_write;
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

/* ---- the X series' bus --------------------------------------------------------------------------- */
/* Two XM430s holding for 0.2 s, then servo `id` shut down by `cause`
 * (Hardware Error Status, torque off), backing off 0.2 s. */
static void x_shut_down(uint8_t id, uint8_t cause)
{
	const char *sets[] = { "robot.fault_backoff_s=0.2", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	run(20);
	xs(id)->mem[70] = cause;
	xs(id)->mem[64] = 0;
}

/* An overload shuts servo 2 down: the alert in its status has its RAM block
 * read at once, the fault backs off, one REBOOT (fault_reboots 1) and the
 * set-up chain bring it back. */
static void test_shutdown_recovered_by_reboot(void **state)
{
	(void)state;
	x_shut_down(2, DXL2_HWERR_OVERLOAD);
	run(3);
	assert_int_equal(c.j[1].hwerr, DXL2_HWERR_OVERLOAD);
	assert_non_null(find_event("servo 2: overload (shut down: torque off): backing off"));
	assert_int_equal(atomic_load(&xb.reboots), 0);
	/* back-off 0.2 s, the boot's 0.3 s, the check's 0.3 s */
	run(100);
	assert_non_null(find_event("servo 2: overload shut it down: REBOOT 1 of 1"));
	assert_int_equal(atomic_load(&xb.reboots), 1);
	assert_non_null(find_event("servo 2: recovered"));
	assert_int_equal(xs(2)->mem[64], 1);
	assert_int_equal(xs(2)->mem[98], WATCHDOG_UNITS);   /* the boot cleared it; set again */
	assert_int_equal(xreg(2, 100, 2), 885);
	assert_false(c.latched);
	assert_int_equal(c.j[1].fault, CTL_FAULT_NONE);
}

/* The cause is still there after the REBOOT: the fault latches (HOLD), and
 * the servo's torque is never turned on while its error stands. */
static void test_shutdown_latches_when_reboot_does_not_help(void **state)
{
	(void)state;
	x_shut_down(2, DXL2_HWERR_OVERHEAT);
	xs(2)->hwerr_after_reboot = DXL2_HWERR_OVERHEAT;
	for (int i = 0; i < 150; i++) {
		(void)tick(NULL);
		if (xs(2)->mem[70] != 0 && xs(2)->mem[64] != 0)
			fail_msg("torque on with a hardware error standing");
	}
	assert_int_equal(atomic_load(&xb.reboots), 1);
	assert_true(c.latched);
	assert_non_null(strstr(c.latch, "servo 2 overheating"));
	assert_int_equal(c.mode, CFG_MODE_HOLD);
	/* the other joint holds on */
	assert_int_equal(xs(1)->mem[64], 1);
	/* 'clear' is the operator's REBOOT; cooled down, it comes back */
	xs(2)->hwerr_after_reboot = 0;
	char why[128];
	assert_true(ctl_clear_faults(&c, why, sizeof why));
	run(60);
	assert_int_equal(atomic_load(&xb.reboots), 2);
	assert_int_equal(xs(2)->mem[64], 1);
	assert_false(c.latched);
}

/* The servo's bus watchdog stopped it (this controller was late): found by
 * the read-back, cleared (0 first: only 0 is taken), set again, counted. */
static void test_watchdog_trip_recovered(void **state)
{
	(void)state;
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	run(20);
	xs(1)->mem[98] = SM_WATCHDOG_TRIPPED;
	run(25);
	assert_non_null(find_event("servo 1: its bus watchdog stopped it"));
	assert_int_equal(xs(1)->mem[98], WATCHDOG_UNITS);
	assert_int_equal(xs(1)->mem[64], 1);
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
	xfake_boot(xs(2));
	run(25);
	assert_non_null(find_event("servo-reset: servo 2 found with torque off"));
	assert_int_equal(xs(2)->mem[64], 1);
	assert_int_equal(xs(2)->mem[98], WATCHDOG_UNITS);
	assert_int_equal(c.j[1].resets, 1);
}

/* Another program switched servo 1 to velocity control (EEPROM, torque off
 * for it): found in the EEPROM block, put back in position control. */
static void test_operating_mode_changed(void **state)
{
	(void)state;
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	run(20);
	xs(1)->mem[11] = 1;
	run(45);
	assert_non_null(find_event("servo 1: operating mode changed"));
	assert_int_equal(xs(1)->mem[11], 3);
	assert_int_equal(xs(1)->mem[64], 1);
	assert_int_equal(c.j[0].opmode_read, 3);
}

/* Under torque actuation: both joints resting away from neutral (the law
 * starts them, no starter), then OSCILLATOR for `cycles`: in the drive. */
static void x_oscillate_in_drive(int cycles)
{
	for (uint8_t id = 1; id <= 2; id++)
		xfake_put(xs(id)->mem, 132, 2048 + 250, 4);
	run(10);
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	run(cycles);
	assert_true(c.wheel);
}

/* Torque actuation on the XM430: into current control and out of it, each
 * a chain per servo; the drive goes only to servos whose switch went
 * through, within Current Limit. */
static void test_current_control_switch(void **state)
{
	(void)state;
	const char *sets[] = { "robot.actuation=torque", "robot.torque_drive=current", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	x_oscillate_in_drive(5);
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(xs(id)->mem[11], 0);          /* current control */
		assert_int_equal(xs(id)->mem[64], 1);
		assert_true(c.j[id - 1].drive_ready);
		int16_t cur = (int16_t)xreg(id, 102, 2);
		/* -k x at 0.37 rad out: a pull back towards neutral */
		assert_true(cur < 0 && cur >= -1193);
	}
	ctl_set_mode(&c, CFG_MODE_LIMP, "test");
	run(5);
	assert_false(c.wheel);
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(xs(id)->mem[11], 3);          /* back in position control */
		assert_int_equal(xs(id)->mem[64], 0);          /* and limp */
		assert_int_equal(xreg(id, 102, 2), 0);          /* the drive stopped */
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
		assert_int_equal(xs(id)->mem[11], 0);
		assert_true(jt->drive_ready);
		chain[id - 1] = jt->drive_chain;
		double tau = c.p.sin_stiffness * (osc_sinusoid(c.p.amplitude, c.p.frequency, c.p.phase, id - 1u, c.t) -
		                                  (jt->angle - cfg.joint[id - 1].neutral));
		assert_true(fabs(jt->torque_cmd - tau) < 1e-9);
		int16_t cur = (int16_t)xreg(id, 102, 2);
		assert_true(cur != 0 && (cur > 0) == (tau > 0.0));
	}
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	for (int i = 0; i < 50; i++) {
		(void)tick(NULL);
		for (uint8_t id = 1; id <= 2; id++)
			if (!c.wheel || xs(id)->mem[11] != 0 || xs(id)->mem[64] != 1 || !c.j[id - 1].drive_ready ||
			    c.j[id - 1].drive_chain != chain[id - 1])
				fail_msg("cycle %d after the switch, servo %u: wheel %d, mode %u, torque %u, chain %u (was %u)", i,
				         id, c.wheel, xs(id)->mem[11], xs(id)->mem[64], c.j[id - 1].drive_chain, chain[id - 1]);
	}
	assert_null(find_event("back in joint mode"));
	ctl_set_mode(&c, CFG_MODE_HOLD, "test");
	run(5);
	assert_false(c.wheel);
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(xs(id)->mem[11], 3);
		assert_int_equal(xs(id)->mem[64], 1);
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
		xfake_put(xs(id)->mem, 132, 2048 + 250, 4);
	run(10);
	xs(2)->refuse_writes = true;
	ctl_set_mode(&c, CFG_MODE_OSCILLATOR, "test");
	run(20);
	assert_non_null(find_event("servo 2: the switch to current control stopped"));
	assert_int_equal(xs(2)->drive_parts, 0);
	assert_int_equal(xs(2)->mem[11], 3);
	assert_false(c.j[1].drive_ready);
	assert_true(c.latched);                /* fault_retries 0: the first failed switch latches */
	assert_false(c.wheel);
	assert_int_equal(xs(1)->mem[11], 3);   /* servo 1 back in position control too */
	assert_int_equal(xs(1)->mem[64], 1);
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

static void x_check_write(void *ctx, const struct xfake_servo *s, uint16_t addr, size_t len)
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
static void test_writes_are_the_models_x(void **state)
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
		xb.on_write = x_check_write;
		bad_write[0] = '\0';
		writes_seen = 0;
		run(20);
		/* an overload the servo does not shut down for: torque stays on */
		xs(2)->mem[70] = DXL2_HWERR_OVERLOAD;
		for (int i = 0; i < 20 && c.j[1].fault == CTL_FAULT_NONE; i++)
			(void)tick(NULL);
		assert_int_equal(c.j[1].fault, CTL_FAULT_BACKOFF);
		run(20);
		xs(2)->mem[70] = 0;
		/* LIMP at the cycle whose step ends the back-off: the recovery is
		 * LIMP's (the output limit back, torque off), not a REBOOT */
		ctl_set_mode(&c, CFG_MODE_LIMP, "test");
		run(60);
		assert_int_equal(atomic_load(&xb.reboots), 0);
		assert_non_null(find_event("servo 2: recovered"));
		for (uint8_t id = 1; id <= 2; id++)
			assert_int_equal(xs(id)->mem[64], 0);
		/* a shutdown in HOLD: REBOOT and set-up */
		ctl_set_mode(&c, CFG_MODE_HOLD, "test");
		run(20);
		xs(1)->mem[70] = DXL2_HWERR_OVERHEAT;
		xs(1)->mem[64] = 0;
		xs(1)->hwerr_after_reboot = DXL2_HWERR_OVERHEAT;
		run(150);
		assert_true(c.latched);
		/* LIMP while latched, then 'clear' (the operator's REBOOT) and HOLD */
		ctl_set_mode(&c, CFG_MODE_LIMP, "test");
		run(20);
		xs(1)->hwerr_after_reboot = 0;
		char why[128];
		assert_true(ctl_clear_faults(&c, why, sizeof why));
		run(60);
		ctl_set_mode(&c, CFG_MODE_HOLD, "test");
		run(60);
		assert_int_equal(xs(1)->mem[64], 1);
		if (bad_write[0] != '\0')
			fail_msg("%s", bad_write);
		assert_true(writes_seen > 20);
		/* nothing written where the X servos keep their supply limits */
		for (uint8_t id = 1; id <= 2; id++)
			assert_int_equal(xreg(id, 34, 2), dxl2_reg_at(dxl2_model_by_number(models[k][0]), 34)->def);
	}
	/* torque actuation (XL430: PWM control, XM430: current control): into
	 * the drive, a fault there, LIMP out of it */
	const char *drive[][4] = {
		{ "robot.actuation=torque", "robot.torque_drive=pwm", "robot.fault_backoff_s=0.2", NULL },
		{ "robot.actuation=torque", "robot.torque_drive=current", "robot.fault_backoff_s=0.2", NULL },
	};
	for (size_t k = 0; k < sizeof models / sizeof models[0]; k++) {
		setup_x(models[k], 2, CFG_MODE_HOLD, drive[k]);
		xb.on_write = x_check_write;
		bad_write[0] = '\0';
		x_oscillate_in_drive(10);
		xs(2)->mem[70] = DXL2_HWERR_OVERLOAD;
		run(10);
		xs(2)->mem[70] = 0;
		run(60);
		ctl_set_mode(&c, CFG_MODE_LIMP, "test");
		run(20);
		assert_false(c.wheel);
		if (bad_write[0] != '\0')
			fail_msg("%s", bad_write);
	}
}

/* Fast Sync Read: where every servo answers it (model and firmware, as read
 * at start-up), one a cycle in place of the SYNC_READ, the same readings in
 * a shorter bus time; a servo on firmware 44 keeps the SYNC_READ. A servo
 * lost takes every joint's reading with it (the chain stops at its part),
 * until after CYC_FAST_FAILS_MAX cycles the SYNC_READ reads the others
 * again, said once. */
static void test_fast_sync_read(void **state)
{
	(void)state;
	char why[256];
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	run(20);
	double sync_bus_us = y.bus_us;
	c.j[0].servo.firmware = 46;
	c.j[1].servo.firmware = 44;
	assert_false(setup_fast_read(&bus, &c, why, sizeof why));
	assert_non_null(strstr(why, "servo 2 (XM430-W350, firmware 44)"));
	c.j[1].servo.firmware = 45;
	assert_true(setup_fast_read(&bus, &c, why, sizeof why));
	cyc_set_fast_read(&y, true);
	unsigned before = atomic_load(&xb.sync_reads);
	run(100);
	assert_int_equal(atomic_load(&xb.fast_reads), 100);
	assert_int_equal(atomic_load(&xb.sync_reads), before);
	assert_int_equal(y.errors, 0);
	assert_int_equal(cuts, 0);
	for (size_t j = 0; j < 2; j++) {
		assert_int_equal(c.j[j].stale_cycles, 0);
		assert_true(fabs(c.j[j].voltage - 12.0) < 1e-9 && fabs(c.j[j].temperature - 36) < 1e-9);
	}
	/* one header and one return delay fewer per servo: 2 x 11 bytes less */
	print_message("# bus time: SYNC_READ cycle %.0f us, Fast Sync Read cycle %.0f us\n", sync_bus_us, y.bus_us);
	assert_true(y.bus_us < sync_bus_us);
	/* servo 1 lost: neither joint is read, three cycles; then SYNC_READ */
	xs(1)->powered = false;
	run(CYC_FAST_FAILS_MAX);
	assert_int_equal(y.fast_fallbacks, 1);
	assert_false(y.fast_read);
	assert_int_equal(c.j[1].stale_cycles, CYC_FAST_FAILS_MAX);
	run(2);
	assert_int_equal(c.j[1].stale_cycles, 0);   /* read again */
	assert_int_equal(c.j[0].stale_cycles, CYC_FAST_FAILS_MAX + 2);
	assert_int_equal(atomic_load(&xb.fast_reads), 100 + CYC_FAST_FAILS_MAX);
	/* tried again every CYC_FAST_RETRY_US while the plain read reads every
	 * servo: with servo 1 still silent, never; back, at the next try, and
	 * kept (said: the notice) */
	run(CYC_FAST_RETRY_US / PERIOD_US + 5);
	assert_false(y.fast_read);
	assert_int_equal(atomic_load(&xb.fast_reads), 100 + CYC_FAST_FAILS_MAX);
	xs(1)->powered = true;
	notices = 0;
	run(CYC_FAST_RETRY_US / PERIOD_US + 5);
	assert_true(y.fast_read);
	assert_int_equal(y.fast_retries, 1);
	assert_int_equal(notices, 1);
	assert_non_null(strstr(last_notice, "Fast Sync Read read every servo again"));
	unsigned fast_now = atomic_load(&xb.fast_reads);
	run(10);
	assert_int_equal(atomic_load(&xb.fast_reads), fast_now + 10);
	assert_int_equal(c.j[0].stale_cycles, 0);
	assert_int_equal(c.j[1].stale_cycles, 0);
	/* not on a 1.0 bus */
	cyc_set_fast_read(&y, true);
	assert_int_equal(bus_set_protocol(&bus, BUS_PROTOCOL_1), DXL_OK);
	cyc_set_fast_read(&y, true);
	assert_false(y.fast_read);
	assert_false(setup_fast_read(&bus, &c, why, sizeof why));
}

/* Two AX-12As, a robot on two buses ([robot] ids = 1,b:2), both set up
 * and read at 512 (the fake line carries both: a test says which bus's
 * cycle it runs, cyc_set_bus). */
static void setup_two_buses(void)
{
	memset(&f, 0, sizeof f);
	dxl_parser_init(&f.parser, DXL_PARSE_INSTRUCTION);
	nsv = 2;
	servo_init(&sv[0], 1);
	servo_init(&sv[1], 2);
	on_plant_write = NULL;
	static const char *const sets[] = { "robot.ids=1,b:2", "bus.b.port=/dev/zero", NULL };
	setup_common(2, CFG_MODE_HOLD, sets);
	char why[256];
	struct ctl_servo_info info = { .cw_limit = 0, .ccw_limit = 1023, .max_torque = 1023, .status_return_level = 2 };
	for (size_t j = 0; j < 2; j++) {
		assert_true(ctl_set_servo(&c, j, &info, why, sizeof why));
		ctl_measure(&c, j, 512, 0, 0, 0, 0.01);
	}
	setup_start(500, BUS_PROTOCOL_1);
}

/* A robot on two buses ([robot] ids = 1,b:2): the cycle of bus 0 reads,
 * writes and reads back servo 1 only, sends only servo 1's slot of the
 * SYNC_WRITE and leaves servo 2's register writes queued for bus b's cycle
 * (here the fake line carries both servos: whatever reaches servo 2 went to
 * the wrong bus). */
static void test_one_bus_of_two(void **state)
{
	(void)state;
	setup_two_buses();
	assert_int_equal(cfg.joint_bus[1], 1);
	cyc_set_bus(&y, 0);
	assert_int_equal(y.n, 1);
	run(60);
	assert_int_equal(cuts, 0);
	assert_int_equal(y.errors, 0);
	/* servo 1: torque on, goals every cycle, read every cycle, read back */
	assert_int_equal(sv[0].mem[DXL_AX_TORQUE_ENABLE], 1);
	assert_int_equal(sv[0].writes[DXL_AX_GOAL_POSITION], 60);
	assert_int_equal(c.j[0].stale_cycles, 0);
	assert_int_equal(y.readbacks, 12);
	/* servo 2: nothing at all from this bus; its writes wait for its own */
	for (size_t a = 0; a < DXL_AX_TABLE_SIZE; a++)
		assert_int_equal(sv[1].writes[a], 0);
	assert_true(c.j[1].stale_cycles >= 59);
	assert_int_equal(wq_pending(&c.wq), 2);
	const struct wq_write *next = ctl_next_write(&c);
	assert_non_null(next);
	assert_int_equal(next->id, 2);
}

/* The indirect block (setup_indirect, cyc_set_indirect): start-up maps
 * Indirect Address 1..13 to 126..135 and 144..146 on every servo and reads
 * the map back; the cycle's SYNC_READ then asks for 224, 10 or 13 bytes,
 * decoded as the direct block's 10 or 21 were (the same values), and the
 * servos send 8 bytes fewer every other cycle. A servo without the areas,
 * or one that reads back another map, leaves the direct read, said why;
 * a map in place is kept (nothing written); a REBOOT ends the indirect read. */
static void test_indirect_block(void **state)
{
	(void)state;
	char why[256];
	const char *sets[] = { "robot.fault_backoff_s=0.2", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	run(10);
	uint64_t in0 = f.bytes_in, out0 = f.bytes_out;
	run(100);
	uint64_t direct_in = f.bytes_in - in0, direct_out = f.bytes_out - out0;
	/* mapped: torque off for it, the map in both servos, read back */
	assert_true(setup_indirect(&bus, &c, why, sizeof why));
	assert_string_equal(why, "Indirect Address 1..13 on every servo read back as mapped (2 written, 0 kept)");
	for (uint8_t id = 1; id <= 2; id++) {
		assert_int_equal(xreg(id, 168, 2), 126);
		assert_int_equal(xreg(id, 186, 2), 135);
		assert_int_equal(xreg(id, 188, 2), 144);
		assert_int_equal(xreg(id, 192, 2), 146);
		assert_int_equal(xreg(id, 194, 2), 237);   /* slot 14: its factory value */
		assert_int_equal(xs(id)->mem[64], 0);
		xs(id)->mem[64] = 1;   /* ctl_start's torque on, as the daemon's next step */
	}
	cyc_set_indirect(&y, true);
	struct sm_read rd = cyc_read_of(&y);
	assert_int_equal(rd.addr, 224);
	assert_int_equal(rd.len, 10);
	assert_int_equal(rd.len_slow, 13);
	x_put(2, 132, 2048 + 300, 4);
	x_put(2, 144, 118, 2);
	run(10);
	in0 = f.bytes_in;
	out0 = f.bytes_out;
	unsigned reads0 = atomic_load(&xb.sync_reads);
	run(100);
	uint64_t ind_in = f.bytes_in - in0, ind_out = f.bytes_out - out0;
	assert_int_equal(atomic_load(&xb.sync_reads) - reads0, 100);
	assert_int_equal(y.errors, 0);
	for (size_t j = 0; j < 2; j++)
		assert_int_equal(c.j[j].stale_cycles, 0);
	assert_true(fabs(c.j[1].angle - 300 * DXL2_POS_RAD_PER_UNIT) < 1e-9);
	assert_true(fabs(c.j[1].voltage - 11.8) < 1e-9 && fabs(c.j[1].temperature - 36) < 1e-9);
	assert_true(fabs(c.j[0].voltage - 12.0) < 1e-9);
	/* 8 bytes a servo fewer on each of the 50 slow cycles; the requests the same */
	print_message("# 100 cycles, 2 servos: servo bytes %llu direct, %llu indirect; controller bytes %llu, %llu\n",
	              (unsigned long long)direct_in, (unsigned long long)ind_in, (unsigned long long)direct_out,
	              (unsigned long long)ind_out);
	assert_int_equal(direct_in - ind_in, 50 * 2 * 8);
	assert_int_equal(direct_out, ind_out);
	/* a second start: the map is there, nothing written, torque untouched */
	unsigned writes0 = atomic_load(&xb.writes);
	assert_true(setup_indirect(&bus, &c, why, sizeof why));
	assert_non_null(strstr(why, "(0 written, 2 kept)"));
	assert_int_equal(atomic_load(&xb.writes), writes0);
	assert_int_equal(xs(1)->mem[64], 1);
	/* a REBOOT ends the indirect read, said */
	xs(2)->mem[70] = DXL2_HWERR_OVERLOAD;   /* shut down: torque off until REBOOT */
	xs(2)->mem[64] = 0;
	run(100);
	assert_int_equal(atomic_load(&xb.reboots), 1);
	assert_false(y.indirect);
	assert_int_equal(y.indirect_fallbacks, 1);
	assert_non_null(strstr(last_notice, "servo 2 is rebooted and may come back without its indirect map"));
	assert_int_equal(cyc_read_of(&y).addr, 126);
	assert_non_null(find_event("servo 2: recovered"));
	assert_int_equal(c.j[1].stale_cycles, 0);
}

/* A servo that keeps slot 7 at its factory value: the read-back says so,
 * false; one without the areas: the READ refused, false. */
static void test_indirect_refused(void **state)
{
	(void)state;
	char why[256];
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	xs(2)->ind_stuck = 7;
	assert_false(setup_indirect(&bus, &c, why, sizeof why));
	assert_string_equal(why, "servo 2 (XM430-W350): Indirect Address 7 reads 230 where 132 was written");
	xs(2)->ind_stuck = 0;
	xs(1)->no_indirect = true;
	assert_false(setup_indirect(&bus, &c, why, sizeof why));
	assert_non_null(strstr(why, "servo 1 (XM430-W350): reading Indirect Address 1..13 failed"));
	assert_non_null(strstr(why, "(answered without the data: refused, no indirect area?)"));
	/* the cycle reads the registers where they lie */
	assert_int_equal(cyc_read_of(&y).addr, 126);
	run(20);
	assert_int_equal(y.errors, 0);
}

/* Two XM430s read through their indirect blocks: mapped, torque on (as
 * ctl_start's), the cycle told. */
static void setup_indirect_xm2(void)
{
	char why[256];
	setup_x(xm2, 2, CFG_MODE_HOLD, NULL);
	run(10);
	assert_true(setup_indirect(&bus, &c, why, sizeof why));
	for (uint8_t id = 1; id <= 2; id++)
		xs(id)->mem[64] = 1;
	cyc_set_indirect(&y, true);
}

/* A power loss (no REBOOT sent) puts a real servo's Indirect Address back at
 * its factory values, each Indirect Data byte then reading itself (0): a
 * block of zeros is a map gone, not a reading (raw position 0 is -pi, far
 * outside any joint's limits). The cycle leaves the indirect read at once,
 * keeps the zeros from the controller, and the servo, found reset, is set up
 * again where it really stands. (Found by review: the zeros were taken for
 * -pi and the servo set up again to its lower limit, 100 degrees away.) */
static void test_indirect_map_lost_to_power_loss(void **state)
{
	(void)state;
	setup_indirect_xm2();
	x_put(2, 132, 2048 + 300, 4);
	run(20);
	assert_true(fabs(c.j[1].angle - 300 * DXL2_POS_RAD_PER_UNIT) < 1e-9);
	xfake_boot(xs(2));   /* power loss of servo 2: RAM (and the map) at factory values */
	double min_angle = 1e9;
	int32_t min_goal = 1 << 30;
	for (int i = 0; i < 240; i++) {
		run(1);
		if (c.j[1].have_reading && c.j[1].angle < min_angle)
			min_angle = c.j[1].angle;
		int32_t g = (int32_t)xreg(2, 116, 4);
		if (xs(2)->mem[64] && g < min_goal)
			min_goal = g;
	}
	print_message("# power loss under the indirect read: lowest angle %.3f rad (truth %.3f), lowest goal with "
	              "torque on %d (stands at %d)\n", min_angle, 300 * DXL2_POS_RAD_PER_UNIT, min_goal, 2048 + 300);
	assert_true(fabs(min_angle - 300 * DXL2_POS_RAD_PER_UNIT) < 0.05);
	assert_false(y.indirect);
	assert_int_equal(y.indirect_fallbacks, 1);
	assert_non_null(strstr(last_notice, "servo 2's indirect block read all zeros"));
	assert_int_equal(xs(2)->mem[64], 1);                 /* set up again ... */
	assert_true(fabs((double)(min_goal - (2048 + 300))) < 60);   /* ... where it stands */
}

/* A read-back asked for at once (an alert, a fault's check) obeys the fit
 * rule too: at 1 ms the RAM block of two XM430s never fits, and begun
 * anyway it was cut at every tick and, never answered, stayed due: a cut
 * every cycle (found by review: 749 cuts in 1500 cycles, 0 read-backs). It
 * waits for room, and after CYC_READBACK_WAIT_US is sent anyway — where the
 * block can never fit in the period, as here, that one is cut too, as the
 * round-robin's are: a cut a second, not every cycle. */
static void test_due_readback_fits_too(void **state)
{
	(void)state;
	static const char *const at1ms[] = { "robot.period_ms=1", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, at1ms);
	run(20);
	cuts = 0;
	y.readbacks = 0;
	c.j[0].readback_due = true;   /* as ctl_x_status sets it on an alert */
	run(1500);
	print_message("# due read-back at 1 ms: %u cuts in 1500 cycles, %lld read-backs (%lld forced), still due %d\n",
	              cuts, y.readbacks, y.readbacks_forced, (int)c.j[0].readback_due);
	assert_true(cuts <= 2);
	assert_true(y.readbacks_forced >= 1);
	/* where it fits (10 ms), it goes at once */
	static const char *const at10ms[] = { "robot.period_ms=10", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, at10ms);
	run(20);
	y.readbacks = 0;
	c.j[0].readback_due = true;
	run(1);
	assert_false(c.j[0].readback_due);
	assert_int_equal(y.readbacks, 1);
}

/* A robot on two buses: each bus's cycle reads back its own due joints,
 * whatever the other bus's (ctl_readback_due gave the robot's first due
 * joint, and bus b never saw its own behind bus 0's: found by review). */
static void test_due_readback_of_its_own_bus(void **state)
{
	(void)state;
	static const char *const sets[] = { "robot.ids=1,b:2", "bus.b.port=/dev/zero", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, sets);
	cyc_set_bus(&y, 1);
	assert_int_equal(y.n, 1);
	run(20);
	y.readbacks = 0;
	c.j[0].readback_due = true;   /* bus 0's joint: its own cycle's (not run here) */
	c.j[1].readback_due = true;   /* bus b's joint: this cycle's */
	run(3);
	assert_false(c.j[1].readback_due);
	assert_true(c.j[0].readback_due);
}

/* A REBOOT sent before the reads (a starved cycle) ends the indirect read
 * after the cycle chose its read's length from the indirect block: the read
 * then asks the registers where they lie for their own length, and every
 * servo is read (it asked 13 bytes at 126, refused: found by review). */
static void test_reboot_first_reads_direct(void **state)
{
	(void)state;
	setup_indirect_xm2();
	run(10);
	if ((y.count + 1) % 2 == 0)
		run(1);   /* the next cycle is a slow one (13 bytes) */
	assert_true(wq_put_chain(&c.wq, wq_chain(&c.wq), 2, 0, 0, 0));
	y.starved = CYC_STARVED_CYCLES;
	run(1);
	assert_false(y.indirect);
	assert_int_equal(c.j[0].stale_cycles, 0);
}

/* A robot on two buses, both lost; LIMP commanded meanwhile (its torque-off
 * writes dropped with the lost servos'); bus 0 back first: its servo goes
 * limp at once, not when the read-back finds it torqued (found by review:
 * the reconnect sent nothing until every bus was back). */
static void test_limp_reaches_a_bus_back_first(void **state)
{
	(void)state;
	setup_two_buses();
	cyc_set_bus(&y, 0);
	run(20);
	assert_int_equal(sv[0].mem[DXL_AX_TORQUE_ENABLE], 1);
	ctl_bus_lost_on(&c, 0);
	ctl_bus_lost_on(&c, 1);
	ctl_set_mode(&c, CFG_MODE_LIMP, "test: while both buses are lost");
	wq_drop_id(&c.wq, 1);   /* what the lost buses' writes come to */
	wq_drop_id(&c.wq, 2);
	assert_int_equal(sv[0].mem[DXL_AX_TORQUE_ENABLE], 1);
	ctl_bus_back_on(&c, 0);   /* bus 0 back, bus b still lost */
	run(1);
	assert_int_equal(sv[0].mem[DXL_AX_TORQUE_ENABLE], 0);
}

/* The read-back's pace is a time, not a count of cycles: one joint every
 * 50 ms (5 cycles at 100 Hz). Counted in cycles it read back ten times as
 * often at 1 kHz, 200 transactions a second on the bus, each a cut cycle
 * when it did not fit (make bench, section rate). */
static void test_readback_pace_is_a_time(void **state)
{
	(void)state;
	static const char *const at5ms[] = { "robot.period_ms=5", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, at5ms);
	run(200);   /* 1 s */
	assert_int_equal(cuts, 0);
	assert_int_equal(y.readbacks, 20);
	for (size_t j = 0; j < 2; j++)
		assert_int_equal(c.j[j].torque_read, 1);   /* both joints still read back */
}

/* Fast Sync Read is given up after 30 ms of cycles that read nobody (three
 * cycles at 100 Hz), not after three cycles whatever the period: at 1 kHz,
 * three cycles are one stall of a busy machine, and the fast read was lost
 * for good after it (make bench, section rate). */
static void test_fast_read_kept_through_a_short_stall(void **state)
{
	(void)state;
	static const char *const at2ms[] = { "robot.period_ms=2", NULL };
	char why[256];
	setup_x(xm2, 2, CFG_MODE_HOLD, at2ms);
	c.j[0].servo.firmware = 46;
	c.j[1].servo.firmware = 46;
	assert_true(setup_fast_read(&bus, &c, why, sizeof why));
	cyc_set_fast_read(&y, true);
	run(20);
	xs(1)->powered = false;
	run(5);   /* 10 ms */
	assert_true(y.fast_read);
	assert_int_equal(y.fast_fallbacks, 0);
	xs(1)->powered = true;
	run(2);
	assert_int_equal(c.j[1].stale_cycles, 0);
	assert_true(y.fast_read);
	xs(1)->powered = false;
	run(14);   /* 28 ms: still kept */
	assert_true(y.fast_read);
	run(1);    /* 30 ms */
	assert_false(y.fast_read);
	assert_int_equal(y.fast_fallbacks, 1);
	xs(1)->powered = true;
}

/* A read-back that cannot end on the wire before CYC_LATE_SHARE of the
 * period is not begun: it waits for a cycle with room, at most
 * CYC_READBACK_WAIT_US, and is then sent anyway (a servo reset must still be
 * found). Begun by the old rule (before 70 % of the period) it ran past the
 * next tick, was cut off, and its reply met the next cycle's request on the
 * line. Two XM430s at 1 Mbps, 1 ms: the SYNC_READ and SYNC_WRITE fit (580 to
 * 800 µs), a read-back of the RAM block (770 µs on the wire) never does:
 * one cut a second instead of one every 50 ms. */
static void test_readback_only_where_it_fits(void **state)
{
	(void)state;
	static const char *const at1ms[] = { "robot.period_ms=1", NULL };
	setup_x(xm2, 2, CFG_MODE_HOLD, at1ms);
	run(20);    /* the start's torque-on writes go first and may cost a cycle or two */
	cuts = 0;
	y.readbacks = 0;
	y.readbacks_waiting = 0;
	run(500);   /* 0.5 s: ten read-backs due, none with room */
	assert_int_equal(cuts, 0);
	assert_int_equal(y.readbacks, 0);
	assert_true(y.readbacks_waiting > 0);
	run(600);   /* past a second of waiting: one is sent anyway, and costs its cycle */
	assert_int_equal(y.readbacks_forced, 1);
	assert_true(cuts <= 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_readback_pace_is_a_time),
		cmocka_unit_test(test_fast_read_kept_through_a_short_stall),
		cmocka_unit_test(test_readback_only_where_it_fits),
		{ "normal_cycles (AX-12A)", test_normal_cycles, NULL, NULL, (void *)&ax_bus },
		{ "normal_cycles (XL430-W250 + XM430-W350)", test_normal_cycles, NULL, NULL, (void *)&x_mixed_bus },
		{ "lost_and_damaged_replies (AX-12A)", test_lost_and_damaged_replies, NULL, NULL, (void *)&ax_bus },
		{ "lost_and_damaged_replies (XM430-W350)", test_lost_and_damaged_replies, NULL, NULL, (void *)&x_bus },
		{ "reply_one_period_late (AX-12A)", test_reply_one_period_late, NULL, NULL, (void *)&ax_bus },
		{ "reply_one_period_late (XM430-W350)", test_reply_one_period_late, NULL, NULL, (void *)&x_bus },
		{ "torque_off_never_lost (AX-12A)", test_torque_off_never_lost, NULL, NULL, (void *)&ax_bus },
		{ "torque_off_never_lost (XM430-W350)", test_torque_off_never_lost, NULL, NULL, (void *)&x_bus },
		cmocka_unit_test(test_writes_that_do_not_fit),
		cmocka_unit_test(test_overrun_cut_off),
		cmocka_unit_test(test_writes_never_starve),
		cmocka_unit_test(test_servo_reset_found),
		cmocka_unit_test(test_write_given_up),
		cmocka_unit_test(test_bus_lost),
		cmocka_unit_test(test_writes_are_the_models_ax),
		cmocka_unit_test(test_shutdown_recovered_by_reboot),
		cmocka_unit_test(test_shutdown_latches_when_reboot_does_not_help),
		cmocka_unit_test(test_watchdog_trip_recovered),
		cmocka_unit_test(test_power_loss_set_up_again),
		cmocka_unit_test(test_operating_mode_changed),
		cmocka_unit_test(test_clock_in_current_control),
		cmocka_unit_test(test_current_control_switch),
		cmocka_unit_test(test_switch_stops_half_way),
		cmocka_unit_test(test_drive_only_where_ready),
		cmocka_unit_test(test_writes_are_the_models_x),
		cmocka_unit_test(test_fast_sync_read),
		cmocka_unit_test(test_one_bus_of_two),
		cmocka_unit_test(test_indirect_block),
		cmocka_unit_test(test_indirect_refused),
		cmocka_unit_test(test_indirect_map_lost_to_power_loss),
		cmocka_unit_test(test_due_readback_fits_too),
		cmocka_unit_test(test_due_readback_of_its_own_bus),
		cmocka_unit_test(test_reboot_first_reads_direct),
		cmocka_unit_test(test_limp_reaches_a_bus_back_first),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
