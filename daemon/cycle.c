/* cycle.c — see cycle.h. */
#include "cycle.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "dxl.h"
#include "dxl_table.h"
#include "servo_model.h"

void cyc_init(struct cyc *y, struct bus *bus, struct ctl *ctl, uint64_t period_us, const struct cyc_hooks *hooks)
{
	*y = (struct cyc){ .bus = bus, .ctl = ctl, .period_us = period_us, .phase = CYC_IDLE };
	uint64_t period = period_us > 0 ? period_us : 1;
	y->readback_every = CYC_READBACK_US / period > 0 ? CYC_READBACK_US / period : 1;
	y->fast_fails_max = CYC_FAST_FAILS_US / period > CYC_FAST_FAILS_MAX ? (int)(CYC_FAST_FAILS_US / period)
	                                                                    : CYC_FAST_FAILS_MAX;
	if (hooks != NULL)
		y->hooks = *hooks;
}

void cyc_set_bus(struct cyc *y, size_t bus)
{
	y->own = true;
	y->n = 0;
	for (size_t j = 0; j < y->ctl->n; j++)
		if (ctl_on_bus(y->ctl, j, bus))
			y->joint[y->n++] = j;
}

/* The joints this cycle reads: its bus's (cyc_set_bus), else every one. */
static size_t cyc_count(const struct cyc *y)
{
	return y->own ? y->n : y->ctl->n;
}

static size_t cyc_joint(const struct cyc *y, size_t i)
{
	return y->own ? y->joint[i] : i;
}


static bool cyc_has_id(const struct cyc *y, uint8_t id)
{
	for (size_t i = 0; i < cyc_count(y); i++)
		if (y->ctl->j[cyc_joint(y, i)].id == id)
			return true;
	return false;
}

static uint64_t cyc_now(const struct cyc *y)
{
	return y->bus->io.now_us(y->bus->io.ctx);
}

/* One SYNC_READ for every joint's present block where the protocol has it
 * (2.0); else one READ a joint (1.0). */
static bool cyc_sync_reads(const struct cyc *y)
{
	return dxl_proto_can(bus_proto(y->bus), DXL_CAP_SYNC_READ);
}

void cyc_set_fast_read(struct cyc *y, bool on)
{
	y->fast_read = y->fast_able = on && dxl_proto_can(bus_proto(y->bus), DXL_CAP_FAST_READ);
	y->fast_fails = 0;
	y->fast_trial = false;
}

/* Back on SYNC_READ after a fallback: this cycle tries the Fast Sync Read
 * again when it is time and the last plain read read every servo (a servo
 * still silent would stop the chain again). */
static void cyc_fast_retry(struct cyc *y)
{
	if (!y->fast_able || y->fast_read || y->count < y->fast_retry_at || y->multi.fast ||
	    y->multi.answered != cyc_count(y) || cyc_count(y) == 0)
		return;
	y->fast_read = y->fast_trial = true;
}

void cyc_set_indirect(struct cyc *y, bool on)
{
	y->indirect = on;
}

struct sm_read cyc_read_of(const struct cyc *y)
{
	const struct sm_model *m = ctl_model(y->ctl, cyc_joint(y, 0));
	return y->indirect && m->indirect.len > 0 ? m->indirect : sm_direct_read(m);
}

bool cyc_busy(const struct cyc *y)
{
	return y->phase != CYC_IDLE;
}

uint64_t cyc_deadline_us(const struct cyc *y)
{
	return bus_is_pending(y->bus) ? bus_deadline_us(y->bus) : 0;
}

static void cyc_error(struct cyc *y, uint8_t id, const char *what, int status)
{
	y->errors++;
	if (y->hooks.bus_error != NULL)
		y->hooks.bus_error(y->hooks.ctx, id, what, status);
}

static bool cyc_late(const struct cyc *y)
{
	return (double)(cyc_now(y) - y->start_us) > CYC_LATE_SHARE * (double)y->period_us;
}

static bool cyc_port_gone(int r)
{
	return r == DXL_E_DISCONNECTED || r == DXL_E_IO;
}

static enum cyc_status cyc_finish(struct cyc *y, enum cyc_status st)
{
	y->bus_us = (double)(cyc_now(y) - y->start_us) - y->control_us;
	y->phase = CYC_IDLE;
	y->starved = wq_pending(&y->ctl->wq) > 0 ? y->starved + 1 : 0;
	return st;
}

static void cyc_drop_write(struct cyc *y)
{
	if (!y->write_on_wire)
		return;
	y->write_on_wire = false;
	/* it may or may not have reached the servo: sent again (writes are
	 * idempotent), up to the controller's limit */
	ctl_write_result(y->ctl, false);
}

static enum cyc_status cyc_lost(struct cyc *y, int r)
{
	cyc_drop_write(y);
	bus_abort(y->bus);
	y->lost = r;
	return cyc_finish(y, CYC_LOST);
}

void cyc_cut(struct cyc *y)
{
	if (y->phase == CYC_IDLE)
		return;
	cyc_drop_write(y);
	if (bus_is_pending(y->bus))
		y->errors++;
	bus_abort(y->bus);
	y->cut_off++;
	(void)cyc_finish(y, CYC_DONE);
}

static int cyc_begin_read(struct cyc *y, uint8_t id, uint16_t addr, uint16_t len)
{
	return bus_read_begin(y->bus, id, addr, len);
}

/* A REBOOT ends the indirect read: the servo may boot with the factory map
 * (the e-manual lists the Indirect Address registers in the RAM area), and
 * its indirect block would then read its own bytes, not the present values. */
static void cyc_reboot_ends_indirect(struct cyc *y, uint8_t id)
{
	if (!y->indirect)
		return;
	y->indirect = false;
	y->indirect_fallbacks++;
	/* before this cycle's reads (a starved cycle writes first): they ask
	 * the registers where they lie for their own length */
	struct sm_read rd = cyc_read_of(y);
	y->read_len = (y->count & 1) ? rd.len_slow : rd.len;
	if (y->hooks.notice != NULL) {
		char text[200];
		snprintf(text, sizeof text, "bus: servo %u is rebooted and may come back without its indirect map: the "
		         "cycle reads the present registers where they lie from now on (until the next start or reconnect)",
		         id);
		y->hooks.notice(y->hooks.ctx, text);
	}
}

/* An indirect block read all zeros: the servo's map is gone. A power loss
 * or brown-out puts Indirect Address back at its factory values (the
 * e-manual lists them in the RAM area), each Indirect Data byte then reading
 * itself, 0 — and raw position 0 is -pi, outside any joint's limits, not a
 * reading. The indirect read ends (as after a REBOOT) and the zeros are kept
 * from the controller: the next cycle reads the present registers where they
 * lie, and a servo found reset is set up again where it really stands. */
static bool cyc_map_lost(struct cyc *y, uint8_t id, const uint8_t *bytes, size_t len)
{
	if (!y->indirect)
		return false;
	for (size_t k = 0; k < len; k++)
		if (bytes[k] != 0)
			return false;
	y->indirect = false;
	y->indirect_fallbacks++;
	if (y->hooks.notice != NULL) {
		char text[220];
		snprintf(text, sizeof text, "bus: servo %u's indirect block read all zeros: its map is gone (a power loss "
		         "or brown-out resets it): the cycle reads the present registers where they lie from now on "
		         "(until the next start or reconnect)", id);
		y->hooks.notice(y->hooks.ctx, text);
	}
	return true;
}

/* A queued write; one of no bytes is a REBOOT (the X series' recovery). */
static int cyc_begin_write(struct cyc *y, const struct wq_write *w)
{
	uint8_t data[4] = { (uint8_t)(w->value & 0xFF), (uint8_t)(w->value >> 8), (uint8_t)(w->value >> 16),
	                    (uint8_t)(w->value >> 24) };
	bool reply = false;
	for (size_t i = 0; i < cyc_count(y); i++)
		if (y->ctl->j[cyc_joint(y, i)].id == w->id && y->ctl->j[cyc_joint(y, i)].servo.status_return_level >= 2)
			reply = true;
	if (w->len == 0) {
		cyc_reboot_ends_indirect(y, w->id);
		return bus_reboot_begin(y->bus, w->id, reply);
	}
	return bus_write_begin(y->bus, w->id, w->addr, data, w->len, reply);
}

/* Where the protocol has it: every joint's present block in one SYNC_READ. */
static int cyc_begin_sync_read(struct cyc *y)
{
	uint8_t ids[CFG_MAX_JOINTS];
	size_t n = cyc_count(y);
	for (size_t i = 0; i < n; i++)
		ids[i] = y->ctl->j[cyc_joint(y, i)].id;
	y->multi.data = y->multi_buf;
	y->multi.cap = sizeof y->multi_buf;
	uint16_t addr = cyc_read_of(y).addr;
	if (y->fast_read)
		return bus_fast_sync_read_begin(y->bus, addr, y->read_len, ids, n, &y->multi);
	return bus_sync_read_begin(y->bus, addr, y->read_len, ids, n, &y->multi);
}

/* A Fast Sync Read that read nobody, CYC_FAST_FAILS_MAX times in a row: a
 * servo no longer takes its turn, and with it go the others' parts; the
 * plain SYNC_READ reads those again. */
static void cyc_fast_outcome(struct cyc *y)
{
	if (!y->fast_read)
		return;
	uint64_t retry = CYC_FAST_RETRY_US / (y->period_us > 0 ? y->period_us : 1);
	char text[256];
	if (y->fast_trial) {
		/* a try after a fallback: kept only when it read every servo */
		y->fast_trial = false;
		if (y->multi.answered != cyc_count(y)) {
			y->fast_read = false;
			y->fast_retry_at = y->count + retry;
			return;
		}
		y->fast_fails = 0;
		y->fast_retries++;
		snprintf(text, sizeof text, "bus: Fast Sync Read read every servo again: reading by it from now on");
		if (y->hooks.notice != NULL)
			y->hooks.notice(y->hooks.ctx, text);
		return;
	}
	y->fast_fails = y->multi.answered == 0 ? y->fast_fails + 1 : 0;
	if (y->fast_fails < y->fast_fails_max)
		return;
	y->fast_read = false;
	y->fast_fallbacks++;
	y->fast_retry_at = y->count + retry;
	if (y->hooks.notice == NULL)
		return;
	snprintf(text, sizeof text,
	         "bus: Fast Sync Read read nobody %d cycles in a row (%.0f ms): reading by SYNC_READ from now on, each "
	         "servo's own status packet (trying it again every %.0f s)",
	         y->fast_fails, 1e-3 * (double)((uint64_t)y->fast_fails * y->period_us), 1e-6 * CYC_FAST_RETRY_US);
	y->hooks.notice(y->hooks.ctx, text);
}

/* The read-back of this block would end on the wire before CYC_LATE_SHARE
 * of the period: its request (a READ's, sized as a status packet of its two
 * parameters: never less) and its reply at their largest, the return delay. */
static bool cyc_readback_fits(const struct cyc *y, const struct sm_block *blk)
{
	const struct dxl_proto *p = bus_proto(y->bus);
	size_t bytes = p->status_bytes_max(2u * p->addr_bytes) + p->status_bytes_max(blk->len);
	uint64_t end = cyc_now(y) + bus_wire_time_us(y->bus, bytes) + y->bus->timing.return_delay_us;
	return (double)(end - y->start_us) <= CYC_LATE_SHARE * (double)y->period_us;
}

/* This cycle's read-back, if any: a joint the controller asks for now (its
 * RAM block), else every CYC_READBACK_US the next joint in turn, and after
 * the last joint the model's next block, once it fits the period's rest
 * (or has waited CYC_READBACK_WAIT_US). */
/* A joint of this cycle's whose RAM block is wanted at once (an alert, a
 * fault's check: ctl's readback_due): this bus's own, whatever another
 * bus's. */
static bool cyc_due_joint(const struct cyc *y, size_t *joint)
{
	for (size_t i = 0; i < cyc_count(y); i++)
		if (y->ctl->j[cyc_joint(y, i)].readback_due) {
			*joint = cyc_joint(y, i);
			return true;
		}
	return false;
}

/* Whether read-back block b of joint j may begin now: it ends on the wire
 * before CYC_LATE_SHARE of the period, or it has waited CYC_READBACK_WAIT_US
 * since `since` (a cycle count) and goes anyway, so that a reset servo is
 * still found on a bus too slow for its period. */
static bool cyc_readback_may(struct cyc *y, size_t j, size_t b, uint64_t since)
{
	size_t nblocks = ctl_model(y->ctl, j)->nreadback;
	if (nblocks == 0 || cyc_readback_fits(y, &ctl_model(y->ctl, j)->readback[b]))
		return true;
	if ((y->count - since) * y->period_us < CYC_READBACK_WAIT_US) {
		y->readbacks_waiting++;
		return false;
	}
	y->readbacks_forced++;
	return true;
}

static bool cyc_pick_readback(struct cyc *y)
{
	size_t due;
	if (cyc_due_joint(y, &due)) {
		if (!y->due_waiting) {
			y->due_waiting = true;
			y->due_since = y->count;
		}
		if (cyc_late(y) || !cyc_readback_may(y, due, 0, y->due_since))
			return false;
		y->due_waiting = false;
		y->readback_now_joint = due;
		y->readback_now_block = 0;
		return true;
	}
	y->due_waiting = false;
	if (!y->readback_owed && y->count % y->readback_every == 0) {
		y->readback_owed = true;
		y->readback_owed_at = y->count;
	}
	if (!y->readback_owed || cyc_late(y))
		return false;
	size_t idx = (y->readback_joint + 1) % cyc_count(y);
	size_t block = y->readback_block + (idx == 0);
	size_t joint = cyc_joint(y, idx);
	size_t nblocks = ctl_model(y->ctl, joint)->nreadback;
	size_t b = nblocks > 0 ? block % nblocks : 0;
	if (!cyc_readback_may(y, joint, b, y->readback_owed_at))
		return false;
	y->readback_owed = false;
	y->readback_joint = idx;
	y->readback_block = block;
	y->readback_now_joint = joint;
	y->readback_now_block = b;
	return true;
}

/* Start the next transaction, skipping steps with nothing to do. */
static enum cyc_status cyc_advance(struct cyc *y)
{
	for (;;) {
		int r;
		switch (y->phase) {
		case CYC_IDLE:
			return CYC_DONE;
		case CYC_CONTROL_STEP:
			return CYC_CONTROL;
		case CYC_READ:
			if (y->idx >= cyc_count(y)) {
				y->phase = CYC_CONTROL_STEP;
				y->control_start_us = cyc_now(y);
				return CYC_CONTROL;
			}
			if (cyc_sync_reads(y)) {
				r = cyc_begin_sync_read(y);
				if (cyc_port_gone(r))
					return cyc_lost(y, r);
				if (r == DXL_OK && bus_is_pending(y->bus))
					return CYC_PENDING;
				cyc_error(y, DXL2_BROADCAST_ID, "SYNC_READ", r);
				y->idx = cyc_count(y);
				continue;
			}
			r = cyc_begin_read(y, y->ctl->j[cyc_joint(y, y->idx)].id, DXL_AX_PRESENT_POSITION, y->read_len);
			if (cyc_port_gone(r))
				return cyc_lost(y, r);
			if (r == DXL_OK && bus_is_pending(y->bus))
				return CYC_PENDING;
			cyc_error(y, y->ctl->j[cyc_joint(y, y->idx)].id, "READ", r);
			y->idx++;
			continue;
		case CYC_WRITE_FIRST:
		case CYC_WRITES: {
			if (y->phase == CYC_WRITES && cyc_late(y)) {
				/* the rest waits for the next cycle: the reads come first */
				if (wq_pending(&y->ctl->wq) > 0)
					y->deferred++;
				return cyc_finish(y, CYC_DONE);
			}
			/* another bus's servo: its own cycle sends it */
			const struct wq_write *next = ctl_next_write(y->ctl);
			const struct wq_write *w = next != NULL && cyc_has_id(y, next->id) ? ctl_take_write(y->ctl) : NULL;
			if (w == NULL) {
				y->phase = y->phase == CYC_WRITE_FIRST ? CYC_READ : CYC_READBACK;
				continue;
			}
			uint8_t id = w->id;
			y->write_on_wire = true;
			r = cyc_begin_write(y, w);
			if (cyc_port_gone(r))
				return cyc_lost(y, r);
			if (r == DXL_OK && bus_is_pending(y->bus))
				return CYC_PENDING;
			y->write_on_wire = false;
			if (r != DXL_OK)
				cyc_error(y, id, "WRITE", r);
			/* sent with no reply due (status return level < 2), or not sent */
			ctl_write_result(y->ctl, r == DXL_OK);
			if (y->phase == CYC_WRITE_FIRST)
				y->phase = CYC_READ;
			continue;
		}
		case CYC_READBACK: {
			if (cyc_count(y) == 0 || !cyc_pick_readback(y))
				return cyc_finish(y, CYC_DONE);
			const struct sm_block *blk = &ctl_model(y->ctl, y->readback_now_joint)->readback[y->readback_now_block];
			uint8_t id = y->ctl->j[y->readback_now_joint].id;
			r = cyc_begin_read(y, id, blk->addr, blk->len);
			if (cyc_port_gone(r))
				return cyc_lost(y, r);
			if (r == DXL_OK && bus_is_pending(y->bus))
				return CYC_PENDING;
			cyc_error(y, id, "READ (read-back)", r);
			return cyc_finish(y, CYC_DONE);
		}
		}
	}
}

enum cyc_status cyc_start(struct cyc *y)
{
	if (y->phase != CYC_IDLE)
		cyc_cut(y);
	y->count++;
	y->phase = CYC_READ;
	y->idx = 0;
	y->start_us = cyc_now(y);
	y->control_us = 0.0;
	y->bus_us = 0.0;
	struct sm_read rd = cyc_read_of(y);
	y->read_len = (y->count & 1) ? rd.len_slow : rd.len;
	cyc_fast_retry(y);
	if (y->starved >= CYC_STARVED_CYCLES && wq_pending(&y->ctl->wq) > 0) {
		y->phase = CYC_WRITE_FIRST;
		y->writes_first++;
	}
	return cyc_advance(y);
}

/* Protocol 2.0: the SYNC_READ's replies, one slot per joint. A servo that
 * did not answer well is named and stale; the others are read. */
static void cyc_readings2(struct cyc *y)
{
	uint64_t now = cyc_now(y);
	struct sm_read rd = cyc_read_of(y);
	for (size_t i = 0; i < cyc_count(y) && i < y->multi.n; i++) {
		size_t j = cyc_joint(y, i);
		const uint8_t *bytes = bus_multi_data(&y->multi, i);
		struct sm_present p;
		if (bytes != NULL && cyc_map_lost(y, y->multi.id[i], bytes, y->multi.len[i]))
			continue;   /* stale this cycle: its servo's next reading is direct */
		if (bytes == NULL || !sm_decode_read(ctl_model(y->ctl, j), &rd, bytes, y->multi.len[i], &p)) {
			cyc_error(y, y->multi.id[i], y->multi.fast ? "Fast Sync Read" : "SYNC_READ",
			          y->multi.status[i] != DXL_OK ? y->multi.status[i] : DXL_E_WRONG_LENGTH);
			continue;
		}
		uint64_t last = y->read_at_us[j];
		double dt = last != 0 && now > last ? 1e-6 * (double)(now - last) : 1e-6 * (double)y->period_us;
		y->read_at_us[j] = now;
		ctl_measure_present(y->ctl, j, &p, y->multi.err[i], dt);
	}
}

static void cyc_reading(struct cyc *y, const struct dxl_packet *p)
{
	size_t j = cyc_joint(y, y->idx);
	/* the position difference is over the time between this joint's own
	 * replies: a timeout earlier in the cycle shifts them */
	uint64_t now = cyc_now(y), last = y->read_at_us[j];
	double dt = last != 0 && now > last ? 1e-6 * (double)(now - last) : 1e-6 * (double)y->period_us;
	y->read_at_us[j] = now;
	ctl_measure(y->ctl, j, dxl_get_u16(p->params), dxl_get_u16(p->params + 2), dxl_get_u16(p->params + 4),
	            p->code, dt);
	if (p->nparams == 8)
		ctl_measure_slow(y->ctl, j, p->params[6], p->params[7], p->code);
}

enum cyc_status cyc_step(struct cyc *y)
{
	if (!bus_is_pending(y->bus))
		return y->phase == CYC_IDLE ? CYC_DONE : y->phase == CYC_CONTROL_STEP ? CYC_CONTROL : CYC_PENDING;
	struct dxl_packet reply;
	int r = bus_step(y->bus, &reply);
	if (r == BUS_PENDING)
		return CYC_PENDING;
	if (cyc_port_gone(r))
		return cyc_lost(y, r);
	switch (y->phase) {
	case CYC_READ:
		if (cyc_sync_reads(y)) {
			cyc_readings2(y);
			cyc_fast_outcome(y);
			y->idx = cyc_count(y);
			break;
		}
		if (r == DXL_OK)
			cyc_reading(y, &reply);
		else
			cyc_error(y, y->ctl->j[cyc_joint(y, y->idx)].id, "READ", r);
		y->idx++;
		break;
	case CYC_WRITE_FIRST:
	case CYC_WRITES: {
		uint8_t id = y->bus->req_id;
		const struct sm_model *m = ctl_model(y->ctl, cyc_joint(y, 0));
		bool ok = r == DXL_OK && !sm_write_refused(m, reply.code);
		if (r != DXL_OK)
			cyc_error(y, id, y->bus->req_instr == DXL_INST_REBOOT ? "REBOOT" : "WRITE", r);
		else if (!ok) {
			char said[96], what[128];
			snprintf(what, sizeof what, "WRITE refused by the servo (its status: %s)",
			         bus_proto(y->bus)->err_format(reply.code, said, sizeof said));
			cyc_error(y, id, what, DXL_OK);
		}
		y->write_on_wire = false;
		ctl_write_result(y->ctl, ok);
		if (y->phase == CYC_WRITE_FIRST)
			y->phase = CYC_READ;
		break;
	}
	case CYC_READBACK:
		if (r == DXL_OK) {
			y->readbacks++;
			const struct dxl_frame *got = bus_reply(y->bus);
			ctl_readback_block(y->ctl, y->readback_now_joint, y->readback_now_block, got->params, got->nparams,
			                   reply.code);
		} else {
			cyc_error(y, y->ctl->j[y->readback_now_joint].id, "READ (read-back)", r);
		}
		return cyc_finish(y, CYC_DONE);
	default:
		break;
	}
	return cyc_advance(y);
}

/* The SYNC_WRITE's share of this bus: its servos' slots, in order. */
static size_t cyc_own_sync(const struct cyc *y, uint8_t width, uint8_t *ids, uint8_t *data, size_t n)
{
	size_t kept = 0;
	for (size_t k = 0; k < n; k++) {
		if (!cyc_has_id(y, ids[k]))
			continue;
		ids[kept] = ids[k];
		memmove(data + (size_t)width * kept, data + (size_t)width * k, width);
		kept++;
	}
	return kept;
}

enum cyc_status cyc_resume(struct cyc *y)
{
	if (y->phase != CYC_CONTROL_STEP)
		return y->phase == CYC_IDLE ? CYC_DONE : CYC_PENDING;
	y->control_us = (double)(cyc_now(y) - y->control_start_us);
	y->phase = CYC_WRITES;
	uint16_t addr;
	uint8_t width, ids[CFG_MAX_JOINTS], data[CTL_SYNC_MAX_WIDTH * CFG_MAX_JOINTS];
	size_t n = ctl_sync(y->ctl, &addr, &width, ids, data);
	if (y->own)
		n = cyc_own_sync(y, width, ids, data, n);
	if (n > 0) {
		int r = bus_sync_write(y->bus, addr, width, ids, data, n);
		if (cyc_port_gone(r))
			return cyc_lost(y, r);
		if (r != DXL_OK)
			cyc_error(y, DXL_BROADCAST_ID, "SYNC_WRITE", r);
	}
	return cyc_advance(y);
}
