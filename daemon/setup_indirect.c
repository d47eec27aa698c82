/*
 * setup_indirect.c — the indirect block the cycle reads (setup.h,
 * setup_indirect): every servo's Indirect Address 1.. set to the present
 * registers the cycle decodes (servo_model.h, sm_model.indirect), then read
 * back. A servo that refuses, answers otherwise or reads back another map
 * leaves the cycle on the direct read: said, never a failed start.
 */
#include "setup_priv.h"

#include <stdio.h>
#include <string.h>

#include "dxl.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "servo_model.h"

/* The map as the Indirect Address registers hold it: 2 bytes a slot,
 * little-endian, slots 1.. from 168. */
static size_t ind_map_bytes(const struct sm_read *rd, uint8_t *out)
{
	for (size_t k = 0; k < rd->len_slow; k++) {
		out[2 * k] = (uint8_t)(rd->src[k] & 0xFF);
		out[2 * k + 1] = (uint8_t)(rd->src[k] >> 8);
	}
	return 2u * rd->len_slow;
}

/* The first slot whose address differs from the map (1-based), 0 if none. */
static int ind_first_difference(const uint8_t *got, const uint8_t *want, size_t n)
{
	for (size_t b = 0; b < n; b++)
		if (got[b] != want[b])
			return (int)(b / 2) + 1;
	return 0;
}

/* The Indirect Address register of the block's first slot (168 for the
 * block at 224). */
static uint16_t ind_map_addr(const struct sm_read *rd)
{
	return dxl2_indirect_address_reg(dxl2_indirect_slot(rd->addr));
}

/* READ of the map. */
static int ind_read(struct bus *bus, uint8_t id, const struct sm_read *rd, size_t n, uint8_t *got, uint8_t *eb)
{
	return setup_read(bus, id, ind_map_addr(rd), (uint16_t)n, got, eb);
}

/* What a failed transaction was: the servo's error number, else ours. A
 * READ refused comes back as a status without its data, which the bus
 * takes for the wrong length: said as what it most likely is. */
static const char *ind_failure(int r, uint8_t eb)
{
	if (eb & DXL2_ERR_NUMBER_MASK)
		return dxl2_error_name(eb & DXL2_ERR_NUMBER_MASK);
	if (r == DXL_E_WRONG_LENGTH)
		return "answered without the data: refused, no indirect area?";
	return dxl_strerror(r);
}

/* One servo: read the map; if another is there, torque off (the registers
 * are written with torque off: ROBOTIS's SDK example says they are not
 * accessible with torque on), write it, read it back. */
static bool ind_servo(struct bus *bus, const struct ctl_joint *jt, const struct sm_model *m,
                      const struct sm_read *rd, bool *wrote, char *why, size_t cap)
{
	uint8_t want[2 * SM_READ_MAX], got[2 * SM_READ_MAX], eb = 0, off = 0;
	size_t n = ind_map_bytes(rd, want);
	bool reply = jt->servo.status_return_level >= 2;
	int r = ind_read(bus, jt->id, rd, n, got, &eb);
	if (r != DXL_OK || eb != 0) {
		snprintf(why, cap, "servo %u (%s): reading Indirect Address 1..%u failed (%s)", jt->id, m->name,
		         rd->len_slow, ind_failure(r, eb));
		return false;
	}
	*wrote = ind_first_difference(got, want, n) != 0;
	if (*wrote) {
		r = setup_write(bus, jt->id, m->torque_enable, &off, 1, reply, &eb);
		if (r == DXL_OK && (!reply || eb == 0))
			r = setup_write(bus, jt->id, ind_map_addr(rd), want, n, reply, &eb);
		if (r != DXL_OK || (reply && eb != 0)) {
			snprintf(why, cap, "servo %u (%s): writing Indirect Address 1..%u failed (%s)", jt->id, m->name,
			         rd->len_slow, ind_failure(r, eb));
			return false;
		}
		r = ind_read(bus, jt->id, rd, n, got, &eb);
	}
	int slot = r == DXL_OK && eb == 0 ? ind_first_difference(got, want, n) : 1;
	if (r != DXL_OK || eb != 0 || slot != 0) {
		if (r == DXL_OK && eb == 0)
			snprintf(why, cap, "servo %u (%s): Indirect Address %d reads %u where %u was written", jt->id,
			         m->name, slot, (unsigned)(got[2 * slot - 2] | got[2 * slot - 1] << 8), rd->src[slot - 1]);
		else
			snprintf(why, cap, "servo %u (%s): reading Indirect Address 1..%u back failed (%s)", jt->id,
			         m->name, rd->len_slow, ind_failure(r, eb));
		return false;
	}
	return true;
}

bool setup_indirect_on(struct bus *bus, const struct ctl *ctl, size_t on_bus, char *why, size_t cap)
{
	size_t wrote_n = 0, n = 0, j0 = 0;
	while (j0 < ctl->n && !ctl_on_bus(ctl, j0, on_bus))
		j0++;
	if (j0 == ctl->n) {
		snprintf(why, cap, "no servos");
		return false;
	}
	const struct sm_read *rd = &ctl_model(ctl, j0)->indirect;
	if (rd->len_slow > SM_READ_MAX || ind_map_addr(rd) == 0) {
		snprintf(why, cap, "the %s's indirect block is not one this daemon can map", ctl_model(ctl, j0)->name);
		return false;
	}
	for (size_t j = j0; j < ctl->n; j++) {
		if (!ctl_on_bus(ctl, j, on_bus))
			continue;
		const struct sm_model *m = ctl_model(ctl, j);
		/* one SYNC_READ asks every servo for one address and length */
		if (m->indirect.len == 0 || m->indirect.addr != rd->addr || m->indirect.len_slow != rd->len_slow) {
			snprintf(why, cap, "servo %u (%s) has no indirect area", ctl->j[j].id, m->name);
			return false;
		}
		bool wrote = false;
		if (!ind_servo(bus, &ctl->j[j], m, rd, &wrote, why, cap))
			return false;
		wrote_n += wrote;
		n++;
	}
	snprintf(why, cap, "Indirect Address 1..%u on every servo read back as mapped (%zu written, %zu kept)",
	         rd->len_slow, wrote_n, n - wrote_n);
	return true;
}

bool setup_indirect(struct bus *bus, const struct ctl *ctl, char *why, size_t cap)
{
	return setup_indirect_on(bus, ctl, CFG_BUS_ROBOT, why, cap);
}
