/*
 * xservo.c — X-series control-table semantics (see xservo.h for the rules and
 * sim-bridge/README.md for the choices). The registers (addresses, sizes,
 * ranges, defaults, access, EEPROM/RAM, which limit register bounds a goal)
 * come from protocol/dxl2_table.c, so the simulator and the tools agree on
 * the table; this file adds what the servo does with them.
 */
#include "xservo.h"

#include <math.h>
#include <string.h>

#define A_TORQUE   DXL2_X_TORQUE_ENABLE
#define A_MODE     DXL2_X_OPERATING_MODE
#define A_DRIVE    DXL2_X_DRIVE_MODE
#define A_WATCHDOG DXL2_X_BUS_WATCHDOG
#define A_HWERR    DXL2_X_HARDWARE_ERROR_STATUS
#define A_LEVEL    DXL2_X_STATUS_RETURN_LEVEL

/* Drive Mode (10) bits (e-manual). */
#define DRIVE_REVERSE        0x01u
#define DRIVE_TIME_PROFILE   0x04u
#define DRIVE_TORQUE_ON_GOAL 0x08u
/* Startup Configuration (60, XL430) bit 0: torque on at boot. */
#define STARTUP_TORQUE_ON    0x01u
/* CLEAR's option 1 and its fixed key (e-manual, Clear). */
#define CLEAR_MULTI_TURN     0x01u
static const uint8_t clear_key[4] = { 0x44, 0x58, 0x4C, 0x22 };
/* Bus Watchdog (98): a unit is 20 ms; 1..127 arm it. */
#define WATCHDOG_UNIT_S      0.020
#define WATCHDOG_MAX         127
/* Realtime Tick (120) wraps after 32767 ms. */
#define TICK_WRAP_MS         32768u

static const double pulses_per_rad = DXL2_POS_PER_REV / (2.0 * DXL2_PI);

void sim_xservo_default_options(struct sim_xservo_options *o)
{
	o->overload_time_s = 0.5;
	o->firmware = 0;
	o->no_indirect = false;
}

/* The end of the table this servo answers: without the indirect areas,
 * the registers before them. */
static size_t xservo_table_end(const struct sim_xservo *s)
{
	return s->opt.no_indirect ? DXL2_X_PRESENT_END : DXL2_X_TABLE_SIZE;
}

/* ---- the table ------------------------------------------------------------------ */

/* The register holding byte addr; NULL in a gap or past the table. */
static const struct dxl2_reg *xservo_reg_covering(const struct sim_xservo *s, uint16_t addr)
{
	for (size_t i = 0; i < s->table->nregs; i++) {
		const struct dxl2_reg *r = &s->table->regs[i];
		if (addr >= r->addr && addr < r->addr + r->size)
			return r;
	}
	return NULL;
}

static int32_t get(const struct sim_xservo *s, uint16_t addr)
{
	const struct dxl2_reg *r = dxl2_reg_at(s->table, addr);
	return r ? dxl2_reg_decode(r, &s->mem[addr]) : 0;
}

static void put(struct sim_xservo *s, uint16_t addr, int32_t v)
{
	const struct dxl2_reg *r = dxl2_reg_at(s->table, addr);
	if (r)
		dxl2_reg_encode(r, v, &s->mem[addr]);
}

static bool has_reg(const struct sim_xservo *s, uint16_t addr)
{
	return dxl2_reg_at(s->table, addr) != NULL;
}

uint8_t sim_xservo_id(const struct sim_xservo *s) { return s->mem[DXL2_X_ID]; }

static bool is_goal(uint16_t addr)
{
	return addr == DXL2_X_GOAL_PWM || addr == DXL2_X_GOAL_CURRENT || addr == DXL2_X_GOAL_VELOCITY ||
	       addr == DXL2_X_GOAL_POSITION;
}

uint8_t sim_xservo_alert(const struct sim_xservo *s)
{
	return s->mem[A_HWERR] ? DXL2_ERR_ALERT : 0;
}

int sim_xservo_peek(const struct sim_xservo *s, uint16_t addr, int32_t *value)
{
	const struct dxl2_reg *r = dxl2_reg_at(s->table, addr);
	*value = r ? dxl2_reg_decode(r, &s->mem[addr]) : 0;
	return r ? DXL_OK : DXL_E_ARG;
}

/* A hardware error in Shutdown (63) turns the torque off and stays until
 * REBOOT (e-manual, Shutdown: "A REBOOT is the only method to reset Torque
 * Enable to 1 after a shutdown"). Counted once per shutdown. */
static void xservo_hw_errors(struct sim_xservo *s, uint8_t detected)
{
	uint8_t shut = detected & s->mem[DXL2_X_SHUTDOWN] & DXL2_HWERR_MASK;
	if (shut & (uint8_t)~s->latched)
		s->count.shutdowns++;
	s->latched |= shut;
	if (s->latched && s->mem[A_TORQUE]) {
		s->mem[A_TORQUE] = 0;
		s->reset_seq++;
	}
	s->mem[A_HWERR] = (uint8_t)((s->latched | s->conditions) & DXL2_HWERR_MASK);
}

int sim_xservo_poke(struct sim_xservo *s, uint16_t addr, int32_t value)
{
	const struct dxl2_reg *r = dxl2_reg_at(s->table, addr);
	if (!r)
		return DXL_E_ARG;
	if (addr == A_HWERR) {
		/* an injected hardware error: reported until REBOOT (0 clears) */
		s->latched = (uint8_t)(value & DXL2_HWERR_MASK);
		if (value == 0)
			s->conditions = 0;
		s->count.shutdowns += (s->latched & s->mem[DXL2_X_SHUTDOWN]) != 0;
		if (s->latched & s->mem[DXL2_X_SHUTDOWN] && s->mem[A_TORQUE]) {
			s->mem[A_TORQUE] = 0;
			s->reset_seq++;
		}
		s->mem[A_HWERR] = (uint8_t)((s->latched | s->conditions) & DXL2_HWERR_MASK);
		return DXL_OK;
	}
	dxl2_reg_encode(r, value, &s->mem[addr]);
	if (is_goal(addr))
		s->goal_seq++;   /* a poked goal starts a profile as a written one */
	if (addr == A_TORQUE || addr == A_MODE)
		s->reset_seq++;
	return DXL_OK;
}

/* ---- boot ------------------------------------------------------------------------- */

static int dir_of(const struct sim_xservo *s)
{
	return (s->mem[A_DRIVE] & DRIVE_REVERSE) ? -1 : 1;
}

/* Present Position of a joint at angle: the encoder's whole pulses in the
 * servo's direction, the turn offset, then Homing Offset (20). */
static int32_t xservo_present(const struct sim_xservo *s, double angle)
{
	double raw = floor(DXL2_POS_CENTER + dir_of(s) * angle * pulses_per_rad + 0.5) + s->turn_offset;
	double v = raw + get(s, DXL2_X_HOMING_OFFSET);
	if (!(v > INT32_MIN && v < INT32_MAX))
		v = DXL2_POS_CENTER;
	return (int32_t)v;
}

/* Bring Present Position back within one turn (0..4095 before the homing
 * offset): at power-on, on a switch to Extended Position Control Mode, and on
 * CLEAR (e-manual, Goal Position and Clear). */
static void xservo_one_turn(struct sim_xservo *s)
{
	int32_t homing = get(s, DXL2_X_HOMING_OFFSET);
	int64_t raw = (int64_t)get(s, DXL2_X_PRESENT_POSITION) - homing;
	int64_t turns = raw >= 0 ? raw / DXL2_POS_PER_REV : -((-raw + DXL2_POS_PER_REV - 1) / DXL2_POS_PER_REV);
	s->turn_offset -= (int32_t)(turns * DXL2_POS_PER_REV);
	put(s, DXL2_X_PRESENT_POSITION, (int32_t)(raw - turns * DXL2_POS_PER_REV + homing));
}

/* Defaults of one area from the table's rows. */
static void xservo_load_defaults(struct sim_xservo *s, enum dxl_area area)
{
	for (size_t i = 0; i < s->table->nregs; i++) {
		const struct dxl2_reg *r = &s->table->regs[i];
		if (r->area == area && r->has_default)
			dxl2_reg_encode(r, r->def, &s->mem[r->addr]);
	}
	if (area == DXL_AREA_EEPROM)
		s->mem[DXL2_X_FIRMWARE_VERSION] = s->opt.firmware > 0 ? (uint8_t)s->opt.firmware
		                                                      : sim_model_info(s->model)->firmware;
}

/* The gains the manual resets when the Operating Mode changes (the table's
 * defaults: the manual prints one set for every mode). */
static void xservo_load_gains(struct sim_xservo *s)
{
	static const uint16_t gains[] = {
		DXL2_X_VELOCITY_I_GAIN, DXL2_X_VELOCITY_P_GAIN, DXL2_X_POSITION_D_GAIN, DXL2_X_POSITION_I_GAIN,
		DXL2_X_POSITION_P_GAIN, DXL2_X_FEEDFORWARD_2ND_GAIN, DXL2_X_FEEDFORWARD_1ST_GAIN,
	};
	for (size_t i = 0; i < sizeof gains / sizeof gains[0]; i++) {
		const struct dxl2_reg *r = dxl2_reg_at(s->table, gains[i]);
		if (r && r->has_default)
			dxl2_reg_encode(r, r->def, &s->mem[r->addr]);
	}
}

/* A boot (power-on, REBOOT, after FACTORY_RESET): RAM to its defaults, the
 * goals where the servo stands (Goal PWM and Goal Current at their limits:
 * the manual's initial values), errors and the watchdog cleared. */
static void xservo_boot(struct sim_xservo *s, double angle)
{
	xservo_load_defaults(s, DXL_AREA_RAM);
	s->conditions = s->latched = 0;
	s->mem[A_HWERR] = 0;
	s->overload_s = s->since_packet_s = s->uptime_s = 0;
	put(s, DXL2_X_REALTIME_TICK, 0);
	s->reg_pending = false;
	s->turn_offset = 0;
	put(s, DXL2_X_PRESENT_POSITION, xservo_present(s, angle));
	xservo_one_turn(s);
	put(s, DXL2_X_GOAL_POSITION, get(s, DXL2_X_PRESENT_POSITION));
	put(s, DXL2_X_GOAL_VELOCITY, 0);
	put(s, DXL2_X_GOAL_PWM, get(s, DXL2_X_PWM_LIMIT));
	if (has_reg(s, DXL2_X_GOAL_CURRENT))
		put(s, DXL2_X_GOAL_CURRENT, get(s, DXL2_X_CURRENT_LIMIT));
	if (has_reg(s, DXL2_X_STARTUP_CONFIGURATION) && (s->mem[DXL2_X_STARTUP_CONFIGURATION] & STARTUP_TORQUE_ON))
		s->mem[A_TORQUE] = 1;
	s->goal_seq++;
	s->reset_seq++;
}

void sim_xservo_init(struct sim_xservo *s, enum sim_model m, const struct sim_xservo_options *o, double angle)
{
	memset(s, 0, sizeof(*s));
	s->model = m;
	s->table = sim_model_table(m);
	if (!s->table) {   /* not an X model: an XL430 rather than nothing */
		s->model = SIM_MODEL_XL430_W250;
		s->table = sim_model_table(s->model);
	}
	if (o)
		s->opt = *o;
	else
		sim_xservo_default_options(&s->opt);
	xservo_load_defaults(s, DXL_AREA_EEPROM);
	xservo_boot(s, angle);
	s->powered = true;
}

void sim_xservo_power_off(struct sim_xservo *s)
{
	s->powered = false;
	s->mem[A_TORQUE] = 0;
	s->reset_seq++;
}

void sim_xservo_power_on(struct sim_xservo *s, double angle)
{
	xservo_boot(s, angle);
	s->powered = true;
}

/* ---- replies ---------------------------------------------------------------------- */

/* PING always answers; the reads need level 1; everything else level 2. */
static bool xservo_level_allows(const struct sim_xservo *s, uint8_t instr)
{
	uint8_t level = s->mem[A_LEVEL];
	if (instr == DXL2_INST_PING)
		return true;
	if (instr == DXL2_INST_READ || instr == DXL2_INST_SYNC_READ || instr == DXL2_INST_BULK_READ ||
	    instr == DXL2_INST_FAST_SYNC_READ || instr == DXL2_INST_FAST_BULK_READ)
		return level >= 1;
	return level >= 2;
}

static int xservo_reply(struct sim_xservo *s, uint8_t id, uint8_t errnum, const uint8_t *params, size_t n,
                        uint8_t *out, size_t cap)
{
	int len = dxl2_encode_status(out, cap, id, (uint8_t)(errnum | sim_xservo_alert(s)), params, n);
	if (len > 0)
		s->count.replies++;
	return len;
}

static void xservo_count(struct sim_xservo *s, uint8_t errnum)
{
	switch (errnum) {
	case DXL2_ERRNUM_RESULT_FAIL: s->count.result_fail++; break;
	case DXL2_ERRNUM_INSTRUCTION: s->count.instruction_errors++; break;
	case DXL2_ERRNUM_CRC:         s->count.crc_errors++; break;
	case DXL2_ERRNUM_DATA_RANGE:  s->count.data_range_errors++; break;
	case DXL2_ERRNUM_DATA_LENGTH: s->count.data_length_errors++; break;
	case DXL2_ERRNUM_DATA_LIMIT:  s->count.data_limit_errors++; break;
	case DXL2_ERRNUM_ACCESS:      s->count.access_errors++; break;
	default: break;
	}
}

/* ---- writes ----------------------------------------------------------------------- */

/* The byte a table address stands for: Indirect Data n stands for the byte
 * Indirect Address n holds (e-manual, "Indirect Address, Indirect Data":
 * "Indirect Data 1(224) can perform exactly same as LED(65)"), one byte
 * each; every other address for itself. One level only: a slot naming
 * another Indirect Data byte (or itself, the factory value) is that byte's
 * own storage. An address outside 64..661 (only a poke puts one there: the
 * write is refused) leaves the slot its own byte. */
static uint16_t xservo_target(const struct sim_xservo *s, uint16_t addr)
{
	int n = dxl2_indirect_slot(addr);
	if (n == 0 || !dxl2_model_can(s->table, DXL2_CAP_INDIRECT) || s->opt.no_indirect)
		return addr;
	const uint8_t *p = &s->mem[dxl2_indirect_address_reg(n)];
	uint16_t to = (uint16_t)(p[0] | p[1] << 8);
	return to >= DXL2_X_INDIRECT_MIN && to <= DXL2_X_INDIRECT_MAX ? to : addr;
}

uint8_t sim_xservo_byte(const struct sim_xservo *s, uint16_t addr)
{
	return addr < DXL2_X_TABLE_SIZE ? s->mem[xservo_target(s, addr)] : 0;
}

/* A write as the bytes it reaches: the new table image and which bytes of
 * it were written (through the indirect slots, each at its target). */
struct xservo_wr {
	uint8_t img[DXL2_X_TABLE_SIZE];
	bool hit[DXL2_X_TABLE_SIZE];
};

/* Every byte written in a register the servo lets be written now:
 * read-only, undefined, or EEPROM with torque on is the access error. */
static uint8_t xservo_access_error(const struct sim_xservo *s, const struct xservo_wr *w)
{
	for (size_t a = 0; a < DXL2_X_TABLE_SIZE; a++) {
		if (!w->hit[a])
			continue;
		const struct dxl2_reg *r = xservo_reg_covering(s, (uint16_t)a);
		if (!r || r->access != DXL_ACCESS_RW)
			return DXL2_ERRNUM_ACCESS;
		if (r->area == DXL_AREA_EEPROM && s->mem[A_TORQUE])
			return DXL2_ERRNUM_ACCESS;
	}
	return 0;
}

/* A register written in part: the data length error (e-manual: "only 2
 * bytes of a item that has been defined as 4 bytes"); through the indirect
 * slots too (e-manual: a register longer than a byte needs all its
 * addresses allocated). */
static uint8_t xservo_length_error(const struct sim_xservo *s, const struct xservo_wr *w)
{
	for (size_t a = 0; a < DXL2_X_TABLE_SIZE; a++) {
		if (!w->hit[a])
			continue;
		const struct dxl2_reg *r = xservo_reg_covering(s, (uint16_t)a);
		for (size_t k = r->addr; k < (size_t)r->addr + r->size; k++)
			if (!w->hit[k])
				return DXL2_ERRNUM_DATA_LENGTH;
	}
	return 0;
}

/* The values of every register written, checked against the new image: its
 * row's range (data range), its limit register (data limit), and the states
 * that refuse a value (the watchdog's error, a shutdown). One mistake, one
 * number: the e-manual defines 0x04 as a value outside the range of the
 * control table and 0x06 as one that "exceeds the limit value", and its
 * table prints a goal's range as its limit register's (Goal PWM: -PWM
 * Limit(36) ~ PWM Limit(36)). So a goal outside the range its limit register
 * sets is the data limit error even when it is also beyond the largest
 * value that register takes (Goal PWM 886 exceeds every PWM Limit, as 600
 * exceeds a PWM Limit of 500); the data range error is for a register whose
 * range is printed as numbers (PWM Limit itself, Operating Mode, Goal
 * Position in Extended Position Control Mode). */
static uint8_t xservo_value_error(const struct sim_xservo *s, const struct xservo_wr *w)
{
	uint8_t err = 0;
	const uint8_t *img = w->img;
	for (size_t a = 0; a < DXL2_X_TABLE_SIZE; a++) {
		const struct dxl2_reg *r = w->hit[a] ? dxl2_reg_at(s->table, (uint16_t)a) : NULL;
		if (!r)
			continue;
		int32_t v = dxl2_reg_decode(r, &img[a]);
		/* after a watchdog stop the goals are read-only and the register
		 * takes only 0 (e-manual, Bus Watchdog): the data range error */
		if (s->mem[A_WATCHDOG] == SIM_XSERVO_WATCHDOG_ERROR && (is_goal(r->addr) || (a == A_WATCHDOG && v != 0)))
			return DXL2_ERRNUM_DATA_RANGE;
		bool limited = dxl2_reg_limit_binds(s->table, r, img, DXL2_X_TABLE_SIZE);
		if (!limited && dxl2_reg_check_write(s->table, r, v) != DXL_OK)
			return DXL2_ERRNUM_DATA_RANGE;
		if (!err && limited && dxl2_reg_check_write_live(s->table, r, v, img, DXL2_X_TABLE_SIZE) != DXL_OK)
			err = DXL2_ERRNUM_DATA_LIMIT;
		if (!err && a == A_TORQUE && v && s->latched)
			err = DXL2_ERRNUM_RESULT_FAIL;   /* only REBOOT turns it on again */
	}
	return err;
}

/* Whether a write of n bytes at addr would be taken; what it writes in *w.
 * Through an indirect slot the target's own rules apply (e-manual: the
 * slot "inherits features and properties" of the address it holds: size,
 * value range, access). */
static uint8_t xservo_check_write(const struct sim_xservo *s, uint16_t addr, const uint8_t *data, size_t n,
                                  struct xservo_wr *w)
{
	if (n == 0)
		return DXL2_ERRNUM_DATA_LENGTH;
	if ((size_t)addr + n > xservo_table_end(s))
		return DXL2_ERRNUM_ACCESS;
	memcpy(w->img, s->mem, DXL2_X_TABLE_SIZE);
	memset(w->hit, 0, sizeof w->hit);
	for (size_t i = 0; i < n; i++) {
		uint16_t to = xservo_target(s, (uint16_t)(addr + i));
		w->img[to] = data[i];
		w->hit[to] = true;
	}
	uint8_t err = xservo_access_error(s, w);
	if (!err)
		err = xservo_length_error(s, w);
	return err ? err : xservo_value_error(s, w);
}

/* A new Operating Mode (e-manual, Operating Mode): the gains back to the
 * mode's values, Profile Velocity/Acceleration 0, Goal PWM at PWM Limit; into
 * Extended Position Control Mode, Present Position back within a turn. */
static void xservo_mode_changed(struct sim_xservo *s)
{
	xservo_load_gains(s);
	put(s, DXL2_X_PROFILE_VELOCITY, 0);
	put(s, DXL2_X_PROFILE_ACCELERATION, 0);
	put(s, DXL2_X_GOAL_PWM, get(s, DXL2_X_PWM_LIMIT));
	if (s->mem[A_MODE] == DXL2_OPMODE_EXTENDED_POSITION)
		xservo_one_turn(s);
}

/* Commit a checked write and act on what changed. */
static void xservo_commit(struct sim_xservo *s, const struct xservo_wr *w)
{
	uint8_t torque0 = s->mem[A_TORQUE], mode0 = s->mem[A_MODE];
	memcpy(s->mem, w->img, DXL2_X_TABLE_SIZE);
	bool goal = w->hit[DXL2_X_GOAL_PWM] || w->hit[DXL2_X_GOAL_VELOCITY] || w->hit[DXL2_X_GOAL_POSITION] ||
	            (has_reg(s, DXL2_X_GOAL_CURRENT) && w->hit[DXL2_X_GOAL_CURRENT]);
	if (goal) {
		s->goal_seq++;
		/* Drive Mode bit 3 (firmware 45): a goal turns the torque on */
		if ((s->mem[A_DRIVE] & DRIVE_TORQUE_ON_GOAL) && !s->mem[A_TORQUE] && !s->latched)
			s->mem[A_TORQUE] = 1;
	}
	if (s->mem[A_MODE] != mode0) {
		xservo_mode_changed(s);
		s->reset_seq++;
	}
	if (s->mem[A_TORQUE] != torque0)
		s->reset_seq++;
}

/* A WRITE (or an executed REG_WRITE): all of it or none. Returns the error number. */
static uint8_t xservo_write(struct sim_xservo *s, uint16_t addr, const uint8_t *data, size_t n)
{
	struct xservo_wr w;
	uint8_t err = xservo_check_write(s, addr, data, n, &w);
	if (!err)
		xservo_commit(s, &w);
	return err;
}

/* ---- instructions ------------------------------------------------------------------ */

/* READ's range: within the table the simulator describes (0-661); reserved
 * bytes inside it read 0. */
static uint8_t xservo_read_error(const struct sim_xservo *s, uint16_t addr, uint16_t len)
{
	if (len == 0)
		return DXL2_ERRNUM_DATA_LENGTH;
	if ((size_t)addr + len > xservo_table_end(s))
		return DXL2_ERRNUM_ACCESS;
	return 0;
}

static int xservo_read_reply(struct sim_xservo *s, uint8_t id, uint16_t addr, uint16_t len, bool answer,
                             uint8_t *out, size_t cap)
{
	uint8_t err = xservo_read_error(s, addr, len);
	xservo_count(s, err);
	if (!answer)
		return 0;
	if (err)
		return xservo_reply(s, id, err, NULL, 0, out, cap);
	uint8_t data[DXL2_X_TABLE_SIZE];
	for (size_t i = 0; i < len; i++)
		data[i] = sim_xservo_byte(s, (uint16_t)(addr + i));
	return xservo_reply(s, id, 0, data, len, out, cap);
}

static uint16_t le16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }

static uint8_t xservo_reg_write(struct sim_xservo *s, const struct dxl2_packet *req)
{
	struct xservo_wr w;
	if (req->nparams < 2)
		return DXL2_ERRNUM_INSTRUCTION;
	uint16_t addr = le16(req->params);
	size_t n = req->nparams - 2u;
	/* checked now, so its reply tells; checked again at ACTION */
	uint8_t err = xservo_check_write(s, addr, &req->params[2], n, &w);
	if (err)
		return err;
	s->reg_addr = addr;
	s->reg_len = (uint16_t)n;
	memcpy(s->reg_data, &req->params[2], n);
	s->reg_pending = true;
	s->mem[DXL2_X_REGISTERED_INSTRUCTION] = 1;
	return 0;
}

static uint8_t xservo_action(struct sim_xservo *s)
{
	if (!s->reg_pending)
		return DXL2_ERRNUM_INSTRUCTION;
	s->reg_pending = false;
	s->mem[DXL2_X_REGISTERED_INSTRUCTION] = 0;
	return xservo_write(s, s->reg_addr, s->reg_data, s->reg_len);
}

/* FACTORY_RESET's option (e-manual): 0xFF all, 0x01 all but the ID, 0x02 all
 * but the ID and the baud rate. */
static uint8_t xservo_reset_error(const struct sim_xservo *s, const struct dxl2_packet *req)
{
	if (req->nparams != 1)
		return DXL2_ERRNUM_INSTRUCTION;
	uint8_t o = req->params[0];
	if (o != DXL2_RESET_ALL && o != DXL2_RESET_KEEP_ID && o != DXL2_RESET_KEEP_ID_BAUD)
		return DXL2_ERRNUM_DATA_RANGE;
	/* the EEPROM is written: locked with torque on, as for a WRITE */
	if (s->mem[A_TORQUE])
		return DXL2_ERRNUM_ACCESS;
	return 0;
}

static void xservo_factory_reset(struct sim_xservo *s, uint8_t option)
{
	uint8_t id = s->mem[DXL2_X_ID], baud = s->mem[DXL2_X_BAUD_RATE];
	xservo_load_defaults(s, DXL_AREA_EEPROM);
	if (option != DXL2_RESET_ALL)
		s->mem[DXL2_X_ID] = id;
	if (option == DXL2_RESET_KEEP_ID_BAUD)
		s->mem[DXL2_X_BAUD_RATE] = baud;
}

/* The joint's angle from the present position the servo last measured (a
 * boot from the registers: REBOOT, FACTORY_RESET). */
static double xservo_angle(const struct sim_xservo *s)
{
	int32_t raw = get(s, DXL2_X_PRESENT_POSITION) - get(s, DXL2_X_HOMING_OFFSET) - s->turn_offset;
	return dir_of(s) * ((double)raw - DXL2_POS_CENTER) / pulses_per_rad;
}

/* CLEAR option 1 with its key: Present Position back within one turn, only
 * while the servo stands still (else Result Fail, e-manual). */
static uint8_t xservo_clear(struct sim_xservo *s, const struct dxl2_packet *req)
{
	if (req->nparams != 5)
		return DXL2_ERRNUM_INSTRUCTION;
	if (req->params[0] != CLEAR_MULTI_TURN || memcmp(&req->params[1], clear_key, sizeof clear_key) != 0)
		return DXL2_ERRNUM_DATA_RANGE;
	if (s->mem[DXL2_X_MOVING])
		return DXL2_ERRNUM_RESULT_FAIL;
	xservo_one_turn(s);
	return 0;
}

/* ---- SYNC and BULK instructions: finding this servo's part ------------------------- */

struct xservo_part {
	uint16_t addr, len;
	const uint8_t *data;   /* writes only */
};

/* SYNC_READ: addr, len, IDs. SYNC_WRITE: addr, len, (ID, len bytes)... A
 * packet that does not parse to its end is ignored by every servo (none can
 * tell where its part is). */
static bool xservo_sync_part(const struct sim_xservo *s, const struct dxl2_packet *req, struct xservo_part *part)
{
	if (req->nparams < 5)
		return false;
	part->addr = le16(req->params);
	part->len = le16(req->params + 2);
	size_t stride = req->instr == DXL2_INST_SYNC_WRITE ? (size_t)part->len + 1 : 1;
	if ((req->instr == DXL2_INST_SYNC_WRITE && part->len == 0) || (req->nparams - 4u) % stride != 0)
		return false;
	for (size_t off = 4; off < req->nparams; off += stride)
		if (req->params[off] == sim_xservo_id(s)) {
			part->data = &req->params[off + 1];
			return true;
		}
	return false;
}

/* BULK_READ: (ID, addr, len)... BULK_WRITE: (ID, addr, len, len bytes)...
 * The first part naming this servo (the manual allows one per servo). */
static bool xservo_bulk_part(const struct sim_xservo *s, const struct dxl2_packet *req, struct xservo_part *part)
{
	bool write = req->instr == DXL2_INST_BULK_WRITE, found = false;
	size_t off = 0;
	while (off < req->nparams) {
		if (req->nparams - off < 5)
			return false;
		const uint8_t *p = &req->params[off];
		uint16_t addr = le16(p + 1), len = le16(p + 3);
		size_t size = 5u + (write ? len : 0u);
		if (req->nparams - off < size || (write && len == 0))
			return false;
		if (!found && p[0] == sim_xservo_id(s)) {
			*part = (struct xservo_part){ addr, len, p + 5 };
			found = true;
		}
		off += size;
	}
	return found;
}

static bool xservo_part(const struct sim_xservo *s, const struct dxl2_packet *req, struct xservo_part *part)
{
	if (req->instr == DXL2_INST_SYNC_READ || req->instr == DXL2_INST_SYNC_WRITE ||
	    req->instr == DXL2_INST_FAST_SYNC_READ)
		return xservo_sync_part(s, req, part);
	return xservo_bulk_part(s, req, part);
}

static bool is_fast(uint8_t instr)
{
	return instr == DXL2_INST_FAST_SYNC_READ || instr == DXL2_INST_FAST_BULK_READ;
}

static bool is_multi(uint8_t instr)
{
	return instr == DXL2_INST_SYNC_READ || instr == DXL2_INST_SYNC_WRITE || instr == DXL2_INST_BULK_READ ||
	       instr == DXL2_INST_BULK_WRITE || is_fast(instr);
}

bool sim_xservo_fast_read(const struct sim_xservo *s)
{
	const struct dxl2_model *m = dxl2_model_by_number(sim_model_info(s->model)->model_number);
	return dxl2_model_fast_read(m, s->mem[DXL2_X_FIRMWARE_VERSION]);
}

bool sim_xservo_addressed(const struct sim_xservo *s, const struct dxl2_packet *req)
{
	struct xservo_part part;
	if (!s->powered)
		return false;
	if (req->id == sim_xservo_id(s))
		return true;
	if (req->id != DXL2_BROADCAST_ID)
		return false;
	return !is_multi(req->instr) || xservo_part(s, req, &part);
}

/* ---- dispatch ------------------------------------------------------------------------ */

/* SYNC/BULK to this servo (broadcast only: the manual's Packet ID is 0xFE). */
static int xservo_multi(struct sim_xservo *s, const struct dxl2_packet *req, uint8_t id, uint8_t *out, size_t cap)
{
	struct xservo_part part;
	bool read = req->instr == DXL2_INST_SYNC_READ || req->instr == DXL2_INST_BULK_READ || is_fast(req->instr);
	if (is_fast(req->instr) && !sim_xservo_fast_read(s)) {
		/* an instruction this firmware does not know (below 45): sent to
		 * broadcast, it gets no status */
		xservo_count(s, DXL2_ERRNUM_INSTRUCTION);
		return 0;
	}
	if (req->id != DXL2_BROADCAST_ID) {
		xservo_count(s, DXL2_ERRNUM_INSTRUCTION);
		return xservo_level_allows(s, req->instr) ? xservo_reply(s, id, DXL2_ERRNUM_INSTRUCTION, NULL, 0, out, cap) : 0;
	}
	if (!xservo_part(s, req, &part))
		return 0;
	if (read)
		return xservo_read_reply(s, id, part.addr, part.len, xservo_level_allows(s, req->instr), out, cap);
	xservo_count(s, xservo_write(s, part.addr, part.data, part.len));
	return 0;
}

/* PING: model number and firmware version, to broadcast too (the bus orders
 * the replies by ID). */
static int xservo_ping(struct sim_xservo *s, uint8_t id, uint8_t *out, size_t cap)
{
	uint8_t p[3] = { s->mem[DXL2_X_MODEL_NUMBER], s->mem[DXL2_X_MODEL_NUMBER + 1], s->mem[DXL2_X_FIRMWARE_VERSION] };
	return xservo_reply(s, id, 0, p, sizeof p, out, cap);
}

/* REBOOT and FACTORY_RESET answer first, then boot. */
static int xservo_boot_instruction(struct sim_xservo *s, const struct dxl2_packet *req, uint8_t id, bool answer,
                                   uint8_t *out, size_t cap)
{
	uint8_t err = 0;
	if (req->instr == DXL2_INST_FACTORY_RESET) {
		err = xservo_reset_error(s, req);
		/* broadcast + reset all does nothing (firmware 42 and later) */
		if (!err && req->id == DXL2_BROADCAST_ID && req->params[0] == DXL2_RESET_ALL)
			return 0;
	}
	xservo_count(s, err);
	int len = answer ? xservo_reply(s, id, err, NULL, 0, out, cap) : 0;
	if (err)
		return len;
	double angle = xservo_angle(s);
	if (req->instr == DXL2_INST_FACTORY_RESET)
		xservo_factory_reset(s, req->params[0]);
	xservo_boot(s, angle);
	s->count.reboots++;
	return len;
}

int sim_xservo_handle(struct sim_xservo *s, const struct dxl2_packet *req, uint8_t *out, size_t cap)
{
	if (!sim_xservo_addressed(s, req))
		return 0;
	s->count.instructions++;
	s->since_packet_s = 0;   /* the bus watchdog hears an instruction */
	uint8_t id = sim_xservo_id(s);
	bool broadcast = req->id == DXL2_BROADCAST_ID;
	bool answer = !broadcast && xservo_level_allows(s, req->instr);
	uint8_t err = 0;
	switch (req->instr) {
	case DXL2_INST_PING:
		return xservo_ping(s, id, out, cap);
	case DXL2_INST_READ:
		if (broadcast)
			return 0;   /* e-manual: no status for a broadcast READ */
		if (req->nparams != 4) {
			err = DXL2_ERRNUM_INSTRUCTION;
			break;
		}
		return xservo_read_reply(s, id, le16(req->params), le16(req->params + 2), answer, out, cap);
	case DXL2_INST_WRITE:
		err = req->nparams < 2 ? DXL2_ERRNUM_INSTRUCTION
		                       : xservo_write(s, le16(req->params), &req->params[2], req->nparams - 2u);
		break;
	case DXL2_INST_REG_WRITE:
		err = xservo_reg_write(s, req);
		break;
	case DXL2_INST_ACTION:
		err = xservo_action(s);
		break;
	case DXL2_INST_FACTORY_RESET:
	case DXL2_INST_REBOOT:
		return xservo_boot_instruction(s, req, id, answer, out, cap);
	case DXL2_INST_CLEAR:
		err = xservo_clear(s, req);
		break;
	case DXL2_INST_SYNC_READ:
	case DXL2_INST_SYNC_WRITE:
	case DXL2_INST_BULK_READ:
	case DXL2_INST_BULK_WRITE:
	case DXL2_INST_FAST_SYNC_READ:
	case DXL2_INST_FAST_BULK_READ:
		return xservo_multi(s, req, id, out, cap);
	default:
		err = DXL2_ERRNUM_INSTRUCTION;
		break;
	}
	xservo_count(s, err);
	return answer ? xservo_reply(s, id, err, NULL, 0, out, cap) : 0;
}

int sim_xservo_handle_bad_crc(struct sim_xservo *s, uint8_t id, uint8_t instr, uint8_t *out, size_t cap)
{
	if (!s->powered || id != sim_xservo_id(s))
		return 0;
	xservo_count(s, DXL2_ERRNUM_CRC);
	if (!xservo_level_allows(s, instr))
		return 0;
	return xservo_reply(s, id, DXL2_ERRNUM_CRC, NULL, 0, out, cap);
}

/* ---- physics side ---------------------------------------------------------------------- */

void sim_xservo_drive_cmd(const struct sim_xservo *s, struct sim_xdrive_cmd *c)
{
	bool xm = has_reg(s, DXL2_X_GOAL_CURRENT);
	int32_t pwm_limit = get(s, DXL2_X_PWM_LIMIT), goal_pwm = get(s, DXL2_X_GOAL_PWM);
	*c = (struct sim_xdrive_cmd){
		.torque_enable = s->powered && s->mem[A_TORQUE] != 0,
		.mode = s->mem[A_MODE],
		.dir = dir_of(s),
		.offset = DXL2_POS_CENTER + (double)s->turn_offset + get(s, DXL2_X_HOMING_OFFSET),
		.time_profile = (s->mem[A_DRIVE] & DRIVE_TIME_PROFILE) != 0,
		.step_profile = s->mem[A_WATCHDOG] == SIM_XSERVO_WATCHDOG_ERROR,
		.goal_position = get(s, DXL2_X_GOAL_POSITION),
		.min_position = get(s, DXL2_X_MIN_POSITION_LIMIT),
		.max_position = get(s, DXL2_X_MAX_POSITION_LIMIT),
		.goal_velocity = get(s, DXL2_X_GOAL_VELOCITY),
		/* a limit lowered after the goal was written still binds */
		.goal_pwm = goal_pwm > pwm_limit ? pwm_limit : (goal_pwm < -pwm_limit ? -pwm_limit : goal_pwm),
		.goal_current = xm ? get(s, DXL2_X_GOAL_CURRENT) : 0,
		.current_limit = xm ? get(s, DXL2_X_CURRENT_LIMIT) : -1,
		.profile_acceleration = (uint32_t)get(s, DXL2_X_PROFILE_ACCELERATION),
		.profile_velocity = (uint32_t)get(s, DXL2_X_PROFILE_VELOCITY),
		.pos_p = (uint16_t)get(s, DXL2_X_POSITION_P_GAIN),
		.pos_i = (uint16_t)get(s, DXL2_X_POSITION_I_GAIN),
		.pos_d = (uint16_t)get(s, DXL2_X_POSITION_D_GAIN),
		.ff1 = (uint16_t)get(s, DXL2_X_FEEDFORWARD_1ST_GAIN),
		.ff2 = (uint16_t)get(s, DXL2_X_FEEDFORWARD_2ND_GAIN),
		.vel_p = (uint16_t)get(s, DXL2_X_VELOCITY_P_GAIN),
		.vel_i = (uint16_t)get(s, DXL2_X_VELOCITY_I_GAIN),
		.torque_constant = sim_model_torque_constant(s->model),
		.goal_seq = s->goal_seq,
		.reset_seq = s->reset_seq,
	};
}

static int32_t clamp_i32(double v, double lo, double hi)
{
	if (!(v > lo))
		return (int32_t)lo;
	if (v > hi)
		return (int32_t)hi;
	return (int32_t)floor(v + 0.5);
}

/* Present PWM, Load (XL430) or Current (XM430), Velocity, Position, Input
 * Voltage, Temperature and the trajectories. */
static void xservo_present_values(struct sim_xservo *s, const struct sim_xservo_sense *in)
{
	int dir = dir_of(s);
	int32_t pos = xservo_present(s, in->angle);
	put(s, DXL2_X_PRESENT_POSITION, pos);
	put(s, DXL2_X_PRESENT_VELOCITY, clamp_i32(dir * in->speed / DXL2_VELOCITY_RAD_S_PER_UNIT, -1e9, 1e9));
	put(s, DXL2_X_PRESENT_PWM, clamp_i32(dir * in->duty * SIM_XDRIVE_PWM_FULL, -SIM_XDRIVE_PWM_FULL, SIM_XDRIVE_PWM_FULL));
	if (has_reg(s, DXL2_X_GOAL_CURRENT)) {
		double amps = in->torque / sim_model_torque_constant(s->model);
		put(s, DXL2_X_PRESENT_CURRENT, clamp_i32(dir * amps / SIM_XDRIVE_AMPS_PER_UNIT, -32768, 32767));
	} else {
		double frac = in->stall_torque > 0 ? in->torque / in->stall_torque : 0;
		put(s, DXL2_X_PRESENT_LOAD, clamp_i32(dir * frac * 1000.0, -1000, 1000));
	}
	put(s, DXL2_X_PRESENT_INPUT_VOLTAGE, clamp_i32(in->voltage * 10.0, 0, 65535));
	put(s, DXL2_X_PRESENT_TEMPERATURE, clamp_i32(in->temperature, 0, 255));
	const struct sim_xdrive *d = in->drive;
	put(s, DXL2_X_POSITION_TRAJECTORY, d && d->active ? clamp_i32(d->traj_pos, -1e9, 1e9) : pos);
	put(s, DXL2_X_VELOCITY_TRAJECTORY,
	    d && d->active ? clamp_i32(d->traj_vel / SIM_XDRIVE_PULSES_PER_VEL_UNIT, -1e9, 1e9) : 0);
}

static bool position_mode(uint8_t mode)
{
	return mode == DXL2_OPMODE_POSITION || mode == DXL2_OPMODE_EXTENDED_POSITION ||
	       mode == DXL2_OPMODE_CURRENT_POSITION;
}

/* Moving (122) and Moving Status (123), e-manual. */
static void xservo_motion(struct sim_xservo *s, const struct sim_xdrive *d)
{
	bool active = d && d->active;
	bool ongoing = active && d->profile_ongoing;
	int32_t vel = get(s, DXL2_X_PRESENT_VELOCITY);
	int32_t threshold = get(s, DXL2_X_MOVING_THRESHOLD);
	s->mem[DXL2_X_MOVING] = (vel > threshold || -vel > threshold || ongoing) ? 1 : 0;
	uint8_t st = 0;
	if (active) {
		st |= (uint8_t)(d->profile << 4);
		st |= ongoing ? 0x02 : 0;
		if (position_mode(s->mem[A_MODE])) {
			int32_t pos = get(s, DXL2_X_PRESENT_POSITION);
			if (!ongoing && fabs(d->target - pos) <= SIM_XSERVO_IN_POSITION_PULSES)
				st |= 0x01;
			if (fabs(d->traj_pos - pos) > SIM_XSERVO_FOLLOWING_PULSES)
				st |= 0x08;
		}
	}
	s->mem[DXL2_X_MOVING_STATUS] = st;
}

/* The hardware errors the servo detects (e-manual, Shutdown): input voltage
 * outside its limits, temperature above its limit, overload (the motor at
 * its cap for overload_time). */
static void xservo_conditions(struct sim_xservo *s, const struct sim_xservo_sense *in, double dt)
{
	double v10 = in->voltage * 10.0;
	uint8_t c = 0;
	if (v10 < get(s, DXL2_X_MIN_VOLTAGE_LIMIT) || v10 > get(s, DXL2_X_MAX_VOLTAGE_LIMIT))
		c |= DXL2_HWERR_VOLTAGE;
	if (s->mem[DXL2_X_PRESENT_TEMPERATURE] > s->mem[DXL2_X_TEMPERATURE_LIMIT])
		c |= DXL2_HWERR_OVERHEAT;
	if (in->overloaded && s->mem[A_TORQUE])
		s->overload_s += dt;
	else
		s->overload_s = 0;
	if (s->overload_s >= s->opt.overload_time_s && s->overload_s > 0)
		c |= DXL2_HWERR_OVERLOAD;
	s->conditions = c;
	xservo_hw_errors(s, c);
}

/* Bus Watchdog (98): with torque on, an instruction-free interval longer than
 * the set time stops the servo (e-manual). The stop is written into the goal
 * the mode acts on, so a READ shows what the servo does. */
static void xservo_watchdog(struct sim_xservo *s, double dt)
{
	uint8_t wd = s->mem[A_WATCHDOG];
	s->since_packet_s += dt;
	if (!s->mem[A_TORQUE] || wd == 0 || wd > WATCHDOG_MAX || s->since_packet_s < wd * WATCHDOG_UNIT_S)
		return;
	s->mem[A_WATCHDOG] = SIM_XSERVO_WATCHDOG_ERROR;
	s->count.watchdog_trips++;
	switch (s->mem[A_MODE]) {
	case DXL2_OPMODE_VELOCITY: put(s, DXL2_X_GOAL_VELOCITY, 0); break;
	case DXL2_OPMODE_PWM:      put(s, DXL2_X_GOAL_PWM, 0); break;
	case DXL2_OPMODE_CURRENT:  put(s, DXL2_X_GOAL_CURRENT, 0); break;
	default:                   put(s, DXL2_X_GOAL_POSITION, get(s, DXL2_X_PRESENT_POSITION)); break;
	}
	s->goal_seq++;
}

void sim_xservo_sense(struct sim_xservo *s, const struct sim_xservo_sense *in, double dt)
{
	if (!s->powered)
		return;
	s->uptime_s += dt;
	xservo_present_values(s, in);
	put(s, DXL2_X_REALTIME_TICK, (int32_t)((uint64_t)llround(s->uptime_s * 1000.0) % TICK_WRAP_MS));
	xservo_motion(s, in->drive);
	xservo_conditions(s, in, dt);
	xservo_watchdog(s, dt);
}
