/*
 * fuzz_sim_serial.c — libFuzzer target for undulate-sim's serial side: the
 * bytes a controller writes, fed into a simulated bus with three servos
 * through the pure cores (sim_bus_feed() of simbus.c, the parser of
 * protocol/dxl.c, the instruction semantics of servo.c, the reply faults of
 * fault.c, the wire queue of line.c). No pty, no clock: time is a number the
 * input advances.
 *
 * With bit 4 of the flags the bus speaks Protocol 2.0 to three X-series
 * servos (XL430-W250, XM430-W350, XL430-W250; sim-bridge/xservo.c, the 2.0
 * parser of protocol/dxl2.c, fault.c's 2.0 layout) and the same model runs
 * beside it with 2.0's rules (see model_handle2 below).
 *
 * Input: 4 header bytes, then the byte stream.
 *   [0] flags: bit 0 echo, bit 1 a 16 ms adapter latency, bit 2 EEPROM
 *       writable with torque on (the original AX-12), bit 3 reply faults on,
 *       bit 4 a Protocol 2.0 bus of X servos
 *   [1] [2] [3] the fault of servo 1 when bit 3 is set: kind, ARG, count/prob
 *   the rest: the stream, cut into reads of 1..16 bytes with gaps between
 *   them (now and then over 100 ms: the servo drops a half-read packet), by
 *   a small generator seeded from the header.
 *
 * The same stream also goes, one byte at a time, through a model: our own
 * instruction parser (called until it needs more, as its contract says) and
 * three more servos the frames are handed to directly. Invariants, checked
 * with abort():
 *  - the bus sees exactly the model's frames, checksum and header errors, and
 *    its servos' control tables equal the model's after every read, however
 *    the stream is cut (nothing lost or delayed by the bus's loop);
 *  - a read that completes no frame changes no control table: a packet with
 *    a bad checksum, a broken header or half a packet writes nothing — but
 *    a bad checksum to a servo whose Alarm Shutdown has bit 4 cuts its torque
 *    (torque enable and torque limit 0, and nothing else);
 *  - every servo's table stays in its documented ranges (protocol/
 *    dxl_table.c), read-only and reserved bytes keep their values, a refused
 *    write (range, angle-limit or instruction error) writes nothing but the
 *    torque cut of an alarm shutdown when the error's bit is in the mask,
 *    lock and torque-on protect the EEPROM, lock stays on until a reset;
 *  - every reply is one well-formed status packet from the servo's ID (the
 *    one before the instruction), only where the manual allows one (a
 *    broadcast gets none but PING; the status return level), and a READ
 *    reply carries the requested bytes of the table;
 *  - the wire queue stays ordered by time, within its capacity.
 *
 *   make fuzz-build && build/fuzz/fuzz_sim_serial tests/fuzz/seeds/fuzz_sim_serial
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dxl.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "dxl_table.h"
#include "../../sim-bridge/fault.h"
#include "../../sim-bridge/line.h"
#include "../../sim-bridge/servo.h"
#include "../../sim-bridge/simbus.h"
#include "../../sim-bridge/xservo.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

#define NSERVOS 3
#define HEADER 4
#define MS 1000000LL
/* the bus's rule (simbus.c): a gap this long drops a half-read packet */
#define GAP_NS (100 * MS)

static struct sim_bus bus;
static struct sim_servo model[NSERVOS];
static uint8_t table0[NSERVOS][DXL_AX_TABLE_SIZE];  /* each table after set-up */

static uint32_t next_rand(uint32_t *s)
{
	*s = *s * 1103515245u + 12345u;
	return *s >> 16;
}

static uint16_t reg_value(const uint8_t *mem, const struct dxl_reg *r)
{
	return r->size == 2 ? dxl_get_u16(&mem[r->addr]) : mem[r->addr];
}

/* Bytes no register covers (10, 19-23, 45; 49 is punch's high byte), found once. */
static bool is_reserved[DXL_AX_TABLE_SIZE];

static void find_reserved(void)
{
	for (size_t a = 0; a < DXL_AX_TABLE_SIZE; a++) {
		is_reserved[a] = true;
		for (size_t i = 0; i < dxl_ax12_nregs; i++)
			if (a >= dxl_ax12_regs[i].addr && a < (size_t)dxl_ax12_regs[i].addr + dxl_ax12_regs[i].size)
				is_reserved[a] = false;
	}
	CHECK(is_reserved[10] && is_reserved[19] && is_reserved[23] && is_reserved[45] && !is_reserved[49]);
}

/* The table of one servo is within its documented ranges. */
static void check_table(const struct sim_servo *s, int k)
{
	const uint8_t *m = s->mem;
	for (size_t i = 0; i < dxl_ax12_nregs; i++) {
		const struct dxl_reg *r = &dxl_ax12_regs[i];
		if (r->access == DXL_ACCESS_RW)
			CHECK(reg_value(m, r) >= r->min && reg_value(m, r) <= r->max);
	}
	CHECK(dxl_get_u16(&m[DXL_AX_MODEL_NUMBER]) == DXL_AX12_MODEL);
	CHECK(m[DXL_AX_FIRMWARE_VERSION] == SIM_SERVO_FIRMWARE);
	CHECK(m[DXL_AX_REGISTERED] == (s->reg_pending ? 1 : 0));
	CHECK(s->reg_len <= DXL_MAX_PARAMS);
	/* no physics here: the measured values keep what set-up put there */
	for (size_t a = DXL_AX_PRESENT_POSITION; a <= DXL_AX_PRESENT_TEMPERATURE; a++)
		CHECK(m[a] == table0[k][a]);
	CHECK(m[DXL_AX_MOVING] == table0[k][DXL_AX_MOVING]);
	for (size_t a = 0; a < DXL_AX_TABLE_SIZE; a++)
		if (is_reserved[a])
			CHECK(m[a] == table0[k][a]);
}

/* One well-formed status packet of len bytes from id; its parameters. */
static void check_reply(const uint8_t *out, int len, uint8_t id, struct dxl_packet *pkt)
{
	struct dxl_parser p;
	size_t used = 0;
	dxl_parser_init(&p, DXL_PARSE_STATUS);
	CHECK(len >= 6 && len <= DXL_MAX_PACKET);
	CHECK(dxl_parser_feed(&p, out, (size_t)len, &used, pkt) == DXL_FRAME);
	CHECK(used == (size_t)len);
	CHECK(pkt->id == id);
	CHECK(pkt->code <= DXL_ERRBIT_MASK);
}

/* An alarm shutdown since `before` (servo.c: every error bit in Alarm
 * Shutdown cuts the torque): torque enable and torque limit are 0. */
static bool shut_down_since(const struct sim_servo *before, const struct sim_servo *s)
{
	if (s->count.shutdowns == before->count.shutdowns)
		return false;
	CHECK(s->count.shutdowns == before->count.shutdowns + 1);
	CHECK(s->mem[DXL_AX_TORQUE_ENABLE] == 0 && dxl_get_u16(&s->mem[DXL_AX_TORQUE_LIMIT]) == 0);
	return true;
}

/* The table of `after` equals `before` but for the bytes a shutdown cuts. */
static void check_only_shutdown(const uint8_t *before, const uint8_t *after, bool shut)
{
	uint8_t a[DXL_AX_TABLE_SIZE], b[DXL_AX_TABLE_SIZE];
	memcpy(a, before, sizeof(a));
	memcpy(b, after, sizeof(b));
	if (shut) {
		a[DXL_AX_TORQUE_ENABLE] = b[DXL_AX_TORQUE_ENABLE];
		memcpy(&a[DXL_AX_TORQUE_LIMIT], &b[DXL_AX_TORQUE_LIMIT], 2);
	}
	CHECK(memcmp(a, b, sizeof(a)) == 0);
}

/* Hand one frame to a model servo and check what it did. */
static void model_handle(int k, const struct dxl_packet *req)
{
	struct sim_servo *s = &model[k];
	struct sim_servo before;
	memcpy(&before, s, sizeof(before));   /* bytewise: compared with memcmp below */
	uint8_t out[DXL_MAX_PACKET];
	if (!sim_bus_baud_matches(&bus, s->mem[DXL_AX_BAUD_RATE]))
		return;   /* at another rate it hears nothing (as bus_dispatch) */
	int len = sim_servo_handle(s, req, out, sizeof(out));
	CHECK(len >= 0);
	bool addressed = sim_servo_addressed(&before, req);
	uint8_t id = sim_servo_id(&before), level = before.mem[DXL_AX_STATUS_RETURN_LEVEL];
	bool broadcast = req->id == DXL_BROADCAST_ID;
	if (!addressed) {
		CHECK(len == 0);
		CHECK(memcmp(&before, s, sizeof(*s)) == 0);
		return;
	}
	check_table(s, k);
	/* replies: where the manual gives one, and only there */
	if (req->code == DXL_INST_PING)
		CHECK(len > 0);
	else if (broadcast)
		CHECK(len == 0);
	else
		CHECK((len > 0) == (req->code == DXL_INST_READ ? level >= 1 : level >= 2));
	struct dxl_packet reply;
	if (len > 0) {
		check_reply(out, len, id, &reply);
		if (req->code == DXL_INST_PING)
			CHECK(reply.nparams == 0 && reply.code == sim_servo_condition_bits(&before));
		if (req->code == DXL_INST_READ && reply.code == 0) {
			CHECK(req->nparams == 2 && reply.nparams == req->params[1]);
			CHECK(memcmp(reply.params, &s->mem[req->params[0]], reply.nparams) == 0);
		}
	}
	if (req->code == DXL_INST_FACTORY_RESET)
		return;   /* EEPROM and RAM back to the factory: any change is right */
	/* a refused write writes nothing (ACTION has cleared `registered` first) */
	uint32_t errs = s->count.range_errors + s->count.angle_limit_errors + s->count.instruction_errors;
	uint32_t errs0 = before.count.range_errors + before.count.angle_limit_errors + before.count.instruction_errors;
	bool shut = shut_down_since(&before, s);
	if (shut)
		CHECK(errs != errs0);   /* no frame cuts the torque without an error */
	if (errs != errs0) {
		uint8_t a[DXL_AX_TABLE_SIZE];
		memcpy(a, before.mem, sizeof(a));
		if (req->code == DXL_INST_ACTION)
			a[DXL_AX_REGISTERED] = s->mem[DXL_AX_REGISTERED];
		check_only_shutdown(a, s->mem, shut);
	}
	/* the EEPROM is locked, or (AX-12A) writable only with torque off */
	if (before.mem[DXL_AX_LOCK] || (before.opt.eeprom_needs_torque_off && before.mem[DXL_AX_TORQUE_ENABLE]))
		CHECK(memcmp(before.mem, s->mem, DXL_AX_EEPROM_END) == 0);
	if (before.mem[DXL_AX_LOCK])
		CHECK(s->mem[DXL_AX_LOCK] == 1);
}

/* The model's side of one read: the parser called until it needs more. */
struct model_counts {
	uint64_t frames, checksum_errors, header_errors;
};

/* The bytes a model consumed, the last packet's worth (cap) of them: where a
 * packet with a bad checksum ended, to find whom it was for. */
struct byte_hist {
	uint8_t b[DXL2_MAX_PACKET];
	size_t n, cap;
};
static struct byte_hist hist1 = { .cap = DXL_MAX_PACKET }, hist2 = { .cap = DXL2_MAX_PACKET };

static void hist_push(struct byte_hist *h, const uint8_t *d, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		if (h->n == h->cap) {
			memmove(h->b, h->b + 1, h->cap - 1);
			h->n--;
		}
		h->b[h->n++] = d[i];
	}
}

/* A packet with a bad checksum just ended: the one whose header and LEN
 * span exactly the bytes up to here, the latest such (as a servo sees it:
 * its ID and instruction). Its servo answers with bit 4 where the level
 * allows, and cuts its torque if bit 4 is in its Alarm Shutdown. */
static void model_bad_checksum(void)
{
	const uint8_t *mhist = hist1.b;
	size_t mhist_n = hist1.n;
	for (size_t p = mhist_n >= 6 ? mhist_n - 5 : 0; p-- > 0;) {
		if (mhist[p] != 0xFF || mhist[p + 1] != 0xFF || p + 4 >= mhist_n ||
		    (size_t)mhist[p + 3] + 4 != mhist_n - p)
			continue;
		for (int k = 0; k < NSERVOS; k++) {
			struct sim_servo *s = &model[k];
			struct sim_servo before = *s;
			if (!sim_bus_baud_matches(&bus, s->mem[DXL_AX_BAUD_RATE]))
				continue;
			uint8_t out[DXL_MAX_PACKET];
			int len = sim_servo_handle_bad_checksum(s, mhist[p + 2], mhist[p + 4], out, sizeof(out));
			CHECK(len >= 0);
			bool shut = shut_down_since(&before, s);
			check_only_shutdown(before.mem, s->mem, shut);
			if (len > 0) {
				struct dxl_packet reply;
				check_reply(out, len, mhist[p + 2], &reply);
				CHECK(reply.nparams == 0 && (reply.code & DXL_ERRBIT_CHECKSUM));
			}
		}
		return;
	}
}

static void model_feed(struct dxl_parser *p, const uint8_t *d, size_t n, struct model_counts *mc)
{
	size_t off = 0;
	for (;;) {
		size_t used = 0;
		struct dxl_packet pkt;
		int r = dxl_parser_feed(p, d + off, n - off, &used, &pkt);
		CHECK(used <= n - off);
		hist_push(&hist1, d + off, used);
		off += used;
		if (r == DXL_FRAME) {
			mc->frames++;
			for (int k = 0; k < NSERVOS; k++)
				model_handle(k, &pkt);
		} else if (r == DXL_E_CHECKSUM) {
			mc->checksum_errors++;
			model_bad_checksum();
		} else if (r < 0) {
			mc->header_errors++;
		} else {
			CHECK(off == n);
			return;
		}
	}
}

/* ---- Protocol 2.0: the same checks with the X series' rules ------------------------ */

static struct sim_xservo xmodel[NSERVOS];
static uint8_t xtable0[NSERVOS][DXL2_X_TABLE_SIZE];

/* Every RW register within its row's static range (the watchdog may read
 * its error value), the model and firmware as set up, REG_WRITE's flag. */
static void check_xtable(const struct sim_xservo *s, int k)
{
	const struct dxl2_model *m = s->table;
	for (size_t i = 0; i < m->nregs; i++) {
		const struct dxl2_reg *r = &m->regs[i];
		int32_t v = dxl2_reg_decode(r, &s->mem[r->addr]);
		if (r->access != DXL_ACCESS_RW)
			continue;
		if (r->addr == DXL2_X_BUS_WATCHDOG && v == SIM_XSERVO_WATCHDOG_ERROR)
			continue;
		CHECK(dxl2_reg_check_write(m, r, v) == DXL_OK);
	}
	CHECK(memcmp(s->mem, xtable0[k], 7) == 0);   /* model number, information, firmware */
	CHECK(s->mem[DXL2_X_REGISTERED_INSTRUCTION] == (s->reg_pending ? 1 : 0));
	CHECK(s->reg_len <= DXL2_X_TABLE_SIZE && (size_t)s->reg_addr + s->reg_len <= DXL2_X_TABLE_SIZE);
}

/* One well-formed 2.0 status packet of len bytes from id. */
static void check_reply2(const uint8_t *out, int len, uint8_t id, struct dxl2_packet *pkt)
{
	static struct dxl2_parser p;
	size_t used = 0;
	dxl2_parser_init(&p, DXL2_PARSE_STATUS);
	CHECK(len >= 11 && len <= DXL2_MAX_PACKET);
	CHECK(dxl2_parser_feed(&p, out, (size_t)len, &used, pkt) == DXL_FRAME);
	CHECK(used == (size_t)len);
	CHECK(pkt->id == id);
}

static uint32_t xerrors(const struct sim_xservo *s)
{
	const struct sim_xservo_counters *c = &s->count;
	return c->result_fail + c->instruction_errors + c->data_range_errors + c->data_length_errors +
	       c->data_limit_errors + c->access_errors;
}

/* What the manual lets a servo answer: PING always, the reads at level 1,
 * the rest at level 2; to broadcast only PING and the SYNC/BULK reads. */
static bool may_answer2(const struct dxl2_packet *req, uint8_t level)
{
	bool read = req->instr == DXL2_INST_READ || req->instr == DXL2_INST_SYNC_READ || req->instr == DXL2_INST_BULK_READ;
	if (req->instr == DXL2_INST_PING)
		return true;
	if (req->id == DXL2_BROADCAST_ID && req->instr != DXL2_INST_SYNC_READ && req->instr != DXL2_INST_BULK_READ)
		return false;
	return read ? level >= 1 : level >= 2;
}

static void model_handle2(int k, const struct dxl2_packet *req)
{
	struct sim_xservo *s = &xmodel[k];
	static struct sim_xservo before;
	memcpy(&before, s, sizeof(before));
	uint8_t out[DXL2_MAX_PACKET];
	long bps = dxl2_baud_from_reg(s->mem[DXL2_X_BAUD_RATE]);
	if (bps != bus.baud)
		return;   /* at another rate it hears nothing */
	int len = sim_xservo_handle(s, req, out, sizeof(out));
	CHECK(len >= 0);
	if (!sim_xservo_addressed(&before, req)) {
		CHECK(len == 0);
		CHECK(memcmp(&before, s, sizeof(*s)) == 0);
		return;
	}
	check_xtable(s, k);
	if (len > 0) {
		static struct dxl2_packet reply;
		CHECK(may_answer2(req, before.mem[DXL2_X_STATUS_RETURN_LEVEL]));
		check_reply2(out, len, sim_xservo_id(&before), &reply);
		if (req->instr == DXL2_INST_PING)
			CHECK(reply.nparams == 3 && dxl2_err_number(reply.err) == 0);
		if (req->instr == DXL2_INST_READ && reply.err == sim_xservo_alert(&before)) {
			uint16_t addr = (uint16_t)(req->params[0] | (req->params[1] << 8));
			CHECK(reply.nparams == (uint16_t)(req->params[2] | (req->params[3] << 8)));
			/* what the table holds there, through the indirect slots */
			for (uint16_t i = 0; i < reply.nparams; i++)
				CHECK(reply.params[i] == sim_xservo_byte(s, (uint16_t)(addr + i)));
		}
	} else if (req->instr == DXL2_INST_PING) {
		CHECK(0);   /* PING is always answered */
	}
	if (req->instr == DXL2_INST_FACTORY_RESET || req->instr == DXL2_INST_REBOOT)
		return;   /* a boot: RAM (and the EEPROM) back to the factory's */
	/* a refused instruction writes nothing (ACTION clears the registration first) */
	if (xerrors(s) != xerrors(&before)) {
		uint8_t a[DXL2_X_TABLE_SIZE];
		memcpy(a, before.mem, sizeof(a));
		if (req->instr == DXL2_INST_ACTION)
			a[DXL2_X_REGISTERED_INSTRUCTION] = s->mem[DXL2_X_REGISTERED_INSTRUCTION];
		CHECK(memcmp(a, s->mem, sizeof(a)) == 0);
	}
	/* torque on locks the EEPROM */
	if (before.mem[DXL2_X_TORQUE_ENABLE]) {
		CHECK(memcmp(before.mem, s->mem, DXL2_X_EEPROM_END) == 0);
		/* and the Indirect Address registers (kept as EEPROM) */
		CHECK(memcmp(&before.mem[DXL2_X_INDIRECT_ADDRESS_1], &s->mem[DXL2_X_INDIRECT_ADDRESS_1],
		             2 * DXL2_X_INDIRECT_PER_BLOCK) == 0);
		CHECK(memcmp(&before.mem[DXL2_X_INDIRECT_ADDRESS_29], &s->mem[DXL2_X_INDIRECT_ADDRESS_29],
		             2 * DXL2_X_INDIRECT_PER_BLOCK) == 0);
	}
}

/* A packet with a bad CRC just ended: its header and LEN span the bytes up
 * to here; its servo answers with the CRC error where it would answer. */
static void model_bad_crc2(void)
{
	const uint8_t *mhist2 = hist2.b;
	size_t mhist2_n = hist2.n;
	for (size_t p = mhist2_n >= 10 ? mhist2_n - 9 : 0; p-- > 0;) {
		const uint8_t *h = &mhist2[p];
		if (h[0] != 0xFF || h[1] != 0xFF || h[2] != 0xFD || h[3] != 0 ||
		    p + 7 + ((size_t)h[5] | ((size_t)h[6] << 8)) != mhist2_n)
			continue;
		for (int k = 0; k < NSERVOS; k++) {
			struct sim_xservo *s = &xmodel[k];
			if (dxl2_baud_from_reg(s->mem[DXL2_X_BAUD_RATE]) != bus.baud)
				continue;
			static uint8_t before[DXL2_X_TABLE_SIZE];
			memcpy(before, s->mem, sizeof(before));
			uint8_t out[DXL2_MAX_PACKET];
			int len = sim_xservo_handle_bad_crc(s, h[4], h[7], out, sizeof(out));
			CHECK(len >= 0 && memcmp(before, s->mem, sizeof(before)) == 0);
			if (len > 0) {
				static struct dxl2_packet reply;
				check_reply2(out, len, h[4], &reply);
				CHECK(dxl2_err_number(reply.err) == DXL2_ERRNUM_CRC && reply.nparams == 0);
			}
		}
		return;
	}
}

struct model_counts2 {
	uint64_t frames, crc_errors, header_errors, stuffing_errors;
};

static void model_feed2(struct dxl2_parser *p, const uint8_t *d, size_t n, struct model_counts2 *mc)
{
	size_t off = 0;
	for (;;) {
		size_t used = 0;
		static struct dxl2_packet pkt;
		int r = dxl2_parser_feed(p, d + off, n - off, &used, &pkt);
		CHECK(used <= n - off);
		hist_push(&hist2, d + off, used);
		off += used;
		if (r == DXL_FRAME) {
			mc->frames++;
			for (int k = 0; k < NSERVOS; k++)
				model_handle2(k, &pkt);
		} else if (r == DXL_E_CHECKSUM) {
			mc->crc_errors++;
			model_bad_crc2();
		} else if (r == DXL_E_STUFFING) {
			mc->stuffing_errors++;
		} else if (r < 0) {
			mc->header_errors++;
		} else {
			CHECK(off == n);
			return;
		}
	}
}

static void check_line(const struct sim_line *l)
{
	CHECK(l->n <= SIM_LINE_CAP && l->head + l->n <= SIM_LINE_CAP);
	for (size_t i = l->head + 1; i < l->head + l->n; i++)
		CHECK(l->q[i - 1].t <= l->q[i].t);
}

static void setup_x(void)
{
	sim_bus_set_protocol(&bus, 2);
	for (int k = 0; k < NSERVOS; k++) {
		struct sim_joint *j = &bus.joints[bus.njoints++];
		memset(j, 0, sizeof(*j));
		j->model = k == 1 ? SIM_MODEL_XM430_W350 : SIM_MODEL_XL430_W250;
		j->ops = sim_joint_ops_of(j->model);
		sim_xservo_init(&j->xservo, j->model, NULL, 0.1 * k);
		sim_xservo_poke(&j->xservo, DXL2_X_ID, k + 1);
		sim_xservo_poke(&j->xservo, DXL2_X_BAUD_RATE, 3);   /* the bus's 1 Mbps */
		sim_xservo_poke(&j->xservo, DXL2_X_RETURN_DELAY_TIME, k * 20);
		if (k == 2)
			sim_xservo_poke(&j->xservo, DXL2_X_STATUS_RETURN_LEVEL, 1);
		xmodel[k] = j->xservo;
		memcpy(xtable0[k], j->xservo.mem, DXL2_X_TABLE_SIZE);
	}
}

static void setup(uint8_t flags, const uint8_t *fault)
{
	struct sim_servo_options o;
	sim_servo_default_options(&o);
	o.eeprom_needs_torque_off = !(flags & 4);
	sim_bus_init(&bus, "fuzz", "/nonexistent/fuzz", 1000000, (flags & 2) ? 0.016 : 0, (flags & 1) != 0, 7);
	if (flags & 16)
		setup_x();
	for (int k = 0; k < NSERVOS && !(flags & 16); k++) {
		struct sim_joint *j = &bus.joints[bus.njoints++];
		memset(j, 0, sizeof(*j));
		j->ops = sim_joint_ops_of(SIM_MODEL_AX12A);
		sim_servo_init(&j->servo, &o, (uint16_t)(DXL_POS_CENTER + 100 * k));
		sim_servo_poke(&j->servo, DXL_AX_ID, (uint16_t)(k + 1));
		/* different return delays: fewer collisions on the line */
		sim_servo_poke(&j->servo, DXL_AX_RETURN_DELAY_TIME, (uint16_t)(k * 20));
		if (k == 2)
			sim_servo_poke(&j->servo, DXL_AX_STATUS_RETURN_LEVEL, 1);
		model[k] = j->servo;
		memcpy(table0[k], j->servo.mem, DXL_AX_TABLE_SIZE);
	}
	if (flags & 8) {
		/* A fault set directly, ARG unchecked: fault.c must cope with any. */
		struct sim_fault *f = &bus.joints[0].faults.f[fault[0] % SIM_FAULT_KINDS];
		f->active = true;
		f->has_arg = fault[1] & 1;
		f->arg = (double)(int8_t)fault[1] * 3.0;
		f->remaining = (fault[2] & 3) ? (long)(fault[2] & 3) : -1;
		f->prob = (double)(fault[2] >> 2) / 63.0;
	}
}

/* The stream on a 2.0 bus, the model beside it (as the 1.0 loop below). */
/* One protocol's side of a run: its model's parser (pending bytes, dropped
 * after a long gap as the bus does), one byte into the model, and the bus
 * held against the model before and after each chunk. */
struct run_side {
	size_t (*have)(void);
	void (*reset)(void);
	void (*feed)(const uint8_t *byte);
	void (*before)(void);
	void (*after)(unsigned chunk);
};

/* The input after its header, in chunks of 1..16 bytes at times that are
 * mostly back to back, sometimes a pause, now and then a long one; each
 * chunk into the bus and, byte by byte, into the model. */
static int run(const uint8_t *data, size_t size, const struct run_side *side)
{
	uint32_t seed = (uint32_t)data[0] << 24 | (uint32_t)data[1] << 16 | (uint32_t)data[2] << 8 | data[3];
	int64_t now = MS, last_rx = 0;
	uint8_t drained[SIM_LINE_CAP];
	size_t off = HEADER;
	unsigned chunks = 0;
	while (off < size) {
		uint32_t r = next_rand(&seed);
		size_t n = 1 + r % 16;
		if (n > size - off)
			n = size - off;
		r = next_rand(&seed);
		now += (r & 7) == 0 ? 150 * MS : (r & 7) == 1 ? 2 * MS : 20000;
		if (side->have() > 0 && now - last_rx > GAP_NS)
			side->reset();
		last_rx = now;
		side->before();
		sim_bus_feed(&bus, data + off, n, now);
		for (size_t i = 0; i < n; i++)
			side->feed(data + off + i);
		off += n;
		side->after(++chunks);
		CHECK(bus.line.n <= SIM_LINE_CAP && bus.line.head + bus.line.n <= SIM_LINE_CAP);
		/* what is due goes to the controller */
		sim_line_take(&bus.line, now, drained, sizeof(drained));
	}
	check_line(&bus.line);
	CHECK(bus.count.rx_bytes == size - HEADER);
	return 0;
}

/* ---- Protocol 1.0's side ---- */
static struct dxl_parser mp1;
static struct model_counts mc1;
static uint8_t mem_before[NSERVOS][DXL_AX_TABLE_SIZE];
static uint32_t shutdowns_before[NSERVOS];
static uint64_t packets_before;

static size_t v1_have(void) { return mp1.have; }
static void v1_reset(void) { dxl_parser_reset(&mp1); }
static void v1_feed(const uint8_t *b) { model_feed(&mp1, b, 1, &mc1); }
static void v1_before(void)
{
	for (int k = 0; k < NSERVOS; k++) {
		memcpy(mem_before[k], bus.joints[k].servo.mem, DXL_AX_TABLE_SIZE);
		shutdowns_before[k] = bus.joints[k].servo.count.shutdowns;
	}
	packets_before = bus.count.packets;
}

/* the bus saw what the model saw, and its servos agree */
static void v1_after(unsigned chunk)
{
	CHECK(bus.count.packets == mc1.frames);
	CHECK(bus.count.checksum_errors == mc1.checksum_errors);
	CHECK(bus.count.header_errors == mc1.header_errors);
	CHECK(bus.parser.v1.have == mp1.have);
	for (int k = 0; k < NSERVOS; k++) {
		const struct sim_servo *s = &bus.joints[k].servo;
		CHECK(memcmp(s->mem, model[k].mem, DXL_AX_TABLE_SIZE) == 0);
		CHECK(s->reg_pending == model[k].reg_pending);
		if (bus.count.packets == packets_before)
			check_only_shutdown(mem_before[k], s->mem, s->count.shutdowns != shutdowns_before[k]);
	}
	/* the whole queue now and then (it holds up to 4096 bytes: every read
	 * would make long inputs slow), its bounds always (run) */
	if ((chunk & 7) == 0)
		check_line(&bus.line);
}

static const struct run_side side_v1 = { v1_have, v1_reset, v1_feed, v1_before, v1_after };

/* ---- Protocol 2.0's side ---- */
static struct dxl2_parser mp2;
static struct model_counts2 mc2;

static size_t v2_have(void) { return mp2.have; }
static void v2_reset(void) { dxl2_parser_reset(&mp2); }
static void v2_feed(const uint8_t *b) { model_feed2(&mp2, b, 1, &mc2); }
static void v2_before(void) {}

static void v2_after(unsigned chunk)
{
	(void)chunk;
	CHECK(bus.count.packets == mc2.frames);
	CHECK(bus.count.checksum_errors == mc2.crc_errors);
	CHECK(bus.count.header_errors == mc2.header_errors);
	CHECK(bus.count.stuffing_errors == mc2.stuffing_errors);
	CHECK(bus.parser.v2.have == mp2.have);
	for (int k = 0; k < NSERVOS; k++) {
		const struct sim_xservo *s = &bus.joints[k].xservo;
		CHECK(memcmp(s->mem, xmodel[k].mem, DXL2_X_TABLE_SIZE) == 0);
		CHECK(s->reg_pending == xmodel[k].reg_pending);
	}
	check_line(&bus.line);
}

static const struct run_side side_v2 = { v2_have, v2_reset, v2_feed, v2_before, v2_after };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static bool once;
	if (!once) {
		find_reserved();
		once = true;
	}
	if (size < HEADER)
		return 0;
	setup(data[0], data + 1);
	if (data[0] & 16) {
		dxl2_parser_init(&mp2, DXL2_PARSE_INSTRUCTION);
		hist2.n = 0;
		mc2 = (struct model_counts2){ 0, 0, 0, 0 };
		return run(data, size, &side_v2);
	}
	dxl_parser_init(&mp1, DXL_PARSE_INSTRUCTION);
	hist1.n = 0;
	mc1 = (struct model_counts){ 0, 0, 0 };
	return run(data, size, &side_v1);
}
