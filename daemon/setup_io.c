/*
 * setup_io.c — what the set-up of every servo family uses (setup_priv.h):
 * READ and WRITE tried SETUP_TRIES times after a quiet line, a joint made
 * limp and read back, and the joint limits in a model's units. setup.c
 * calls these; these call nothing of it.
 */
#include "setup_priv.h"

#include "dxl.h"
#include "log.h"

/* Before try t (t > 0) of a transaction: wait for the line to go quiet, a
 * little longer each time. A reply that was late (a busy machine, a slow
 * adapter) lands in the wait; sent at once, the next request would collide
 * with it on the half-duplex line and lose both, as often as it is tried. */
void setup_pause(struct bus *bus, int t, uint8_t id, const char *what, int last)
{
	if (t == 0)
		return;
	int dropped = bus_settle(bus, (uint32_t)t * SETUP_QUIET_US, SETUP_SETTLE_MAX_US);
	log_warn("servo %u: %s: %s; try %d of %d after %u ms of quiet line%s", id, what, dxl_strerror(last), t + 1,
	         SETUP_TRIES, t * SETUP_QUIET_US / 1000, dropped > 0 ? " (a late reply came meanwhile)" : "");
}

/* A start-up read that meets a lost or damaged reply is tried again: one
 * timeout on a loaded machine must not abort the start (a cycle read simply
 * holds the joint for a period, but start-up has no next period). The port
 * going away is not retried. */
int setup_read(struct bus *bus, uint8_t id, uint16_t addr, uint16_t len, uint8_t *out, uint8_t *eb)
{
	int r = DXL_E_TIMEOUT;
	for (int t = 0; t < SETUP_TRIES; t++) {
		setup_pause(bus, t, id, "READ", r);
		r = bus_read(bus, id, addr, len, out, eb);
		if (r == DXL_OK || r == DXL_E_DISCONNECTED || r == DXL_E_IO)
			break;
	}
	return r;
}

/* The same for a write (writing the same bytes twice is harmless). */
int setup_write(struct bus *bus, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply,
                uint8_t *eb)
{
	int r = DXL_E_TIMEOUT;
	for (int t = 0; t < SETUP_TRIES; t++) {
		setup_pause(bus, t, id, "WRITE", r);
		r = bus_write(bus, id, addr, data, n, expect_reply, eb);
		if (r == DXL_OK || r == DXL_E_DISCONNECTED || r == DXL_E_IO)
			break;
	}
	return r;
}

void setup_joint_limits_model(const struct sm_model *m, const struct cfg_joint *cj, int32_t *lo, int32_t *hi)
{
	sm_joint_range(m, cj->neutral + cj->limit_min, cj->neutral + cj->limit_max, lo, hi);
}

void setup_joint_limits(const struct cfg_joint *cj, uint16_t *cw, uint16_t *ccw)
{
	int32_t lo, hi;
	setup_joint_limits_model(sm_ax12(), cj, &lo, &hi);
	*cw = (uint16_t)lo;
	*ccw = (uint16_t)hi;
}

bool setup_limp(struct bus *bus, const struct ctl_joint *jt)
{
	bool reply = jt->servo.status_return_level >= 2;
	uint16_t reg = (jt->servo.model != NULL ? jt->servo.model : sm_ax12())->torque_enable;
	const uint8_t off = 0;
	uint8_t eb, te = 1;
	int r = DXL_E_TIMEOUT;
	for (int t = 0; t < SETUP_TRIES && te != 0; t++) {
		r = setup_write(bus, jt->id, reg, &off, 1, reply, &eb);
		if (r == DXL_E_DISCONNECTED || r == DXL_E_IO)
			break;
		r = setup_read(bus, jt->id, reg, 1, &te, &eb);
		if (r != DXL_OK)
			te = 1;
	}
	if (te != 0)
		log_error("safe stop: servo %u: torque off not confirmed (%s): check it", jt->id,
		          r == DXL_OK ? "it reads back on" : dxl_strerror(r));
	return te == 0;
}
