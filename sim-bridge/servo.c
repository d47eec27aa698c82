/*
 * servo.c — AX-12(A) control-table semantics (see servo.h for the choices).
 * The register descriptions (defaults, ranges, access, EEPROM/RAM) come from
 * protocol/dxl_table.c, so the simulator and the tools agree on the table.
 */
#include "servo.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Present speed below this (rad/s) and goal reached: "moving" reads 0. */
#define SERVO_MOVING_SPEED_EPS 0.05

void sim_servo_default_options(struct sim_servo_options *o)
{
	o->eeprom_needs_torque_off = true;
	o->overload_time_s = 0.5;
}

/* The register covering addr (the word it belongs to for a high byte). */
static const struct dxl_reg *servo_reg_covering(uint8_t addr)
{
	const struct dxl_reg *r = dxl_reg_at(addr);
	if (r)
		return r;
	if (addr > 0) {
		r = dxl_reg_at((uint8_t)(addr - 1));
		if (r && r->size == 2)
			return r;
	}
	return NULL;
}

static uint16_t mem_get(const uint8_t *mem, const struct dxl_reg *r)
{
	return r->size == 2 ? dxl_get_u16(&mem[r->addr]) : mem[r->addr];
}

static void mem_put(uint8_t *mem, const struct dxl_reg *r, uint16_t v)
{
	if (r->size == 2)
		dxl_put_u16(&mem[r->addr], v);
	else
		mem[r->addr] = (uint8_t)v;
}

uint8_t sim_servo_id(const struct sim_servo *s) { return s->mem[DXL_AX_ID]; }

int sim_servo_poke(struct sim_servo *s, uint8_t addr, uint16_t value)
{
	const struct dxl_reg *r = dxl_reg_at(addr);
	if (!r)
		return DXL_E_ARG;
	mem_put(s->mem, r, value);
	return DXL_OK;
}

uint16_t sim_servo_peek(const struct sim_servo *s, uint8_t addr)
{
	const struct dxl_reg *r = dxl_reg_at(addr);
	if (!r)
		return addr < DXL_AX_TABLE_SIZE ? s->mem[addr] : 0;
	return mem_get(s->mem, r);
}

/* Defaults of one area; measured registers (def < 0) keep their value. */
static void servo_load_defaults(struct sim_servo *s, enum dxl_area area)
{
	for (size_t i = 0; i < dxl_ax12_nregs; i++) {
		const struct dxl_reg *r = &dxl_ax12_regs[i];
		if (r->area != area || r->def < 0)
			continue;
		mem_put(s->mem, r, (uint16_t)r->def);
	}
	if (area == DXL_AREA_EEPROM) {
		dxl_put_u16(&s->mem[DXL_AX_MODEL_NUMBER], DXL_AX12_MODEL);
		s->mem[DXL_AX_FIRMWARE_VERSION] = SIM_SERVO_FIRMWARE;
	}
}

static void servo_ram_reset(struct sim_servo *s)
{
	uint16_t present = dxl_get_u16(&s->mem[DXL_AX_PRESENT_POSITION]);
	servo_load_defaults(s, DXL_AREA_RAM);
	s->mem[DXL_AX_TORQUE_ENABLE] = 0;
	s->mem[DXL_AX_REGISTERED] = 0;
	s->mem[DXL_AX_MOVING] = 0;
	s->mem[DXL_AX_LOCK] = 0;
	/* Max torque is copied to the torque limit at power-on (manual). */
	dxl_put_u16(&s->mem[DXL_AX_TORQUE_LIMIT], dxl_get_u16(&s->mem[DXL_AX_MAX_TORQUE]));
	dxl_put_u16(&s->mem[DXL_AX_GOAL_POSITION], present);
	s->reg_pending = false;
	s->conditions = 0;
	s->overload_s = 0;
	s->alarm_led = false;
}

void sim_servo_init(struct sim_servo *s, const struct sim_servo_options *o, uint16_t present_position)
{
	memset(s, 0, sizeof(*s));
	if (o)
		s->opt = *o;
	else
		sim_servo_default_options(&s->opt);
	servo_load_defaults(s, DXL_AREA_EEPROM);
	dxl_put_u16(&s->mem[DXL_AX_PRESENT_POSITION], present_position);
	servo_ram_reset(s);
	s->powered = true;
}

void sim_servo_power_off(struct sim_servo *s)
{
	s->powered = false;
	s->mem[DXL_AX_TORQUE_ENABLE] = 0;
}

void sim_servo_power_on(struct sim_servo *s)
{
	servo_ram_reset(s);
	s->powered = true;
}

uint8_t sim_servo_condition_bits(const struct sim_servo *s)
{
	return (uint8_t)(s->conditions & DXL_ERRBIT_MASK);
}

/* ---- replies ----------------------------------------------------------------- */

/* PING always answers; READ needs level >= 1; everything else level 2. */
static bool servo_level_allows(const struct sim_servo *s, uint8_t instr)
{
	uint8_t level = s->mem[DXL_AX_STATUS_RETURN_LEVEL];
	if (instr == DXL_INST_PING)
		return true;
	if (instr == DXL_INST_READ)
		return level >= 1;
	return level >= 2;
}

static int servo_reply(struct sim_servo *s, uint8_t id, uint8_t errbits, const uint8_t *params,
                       size_t n, uint8_t *out, size_t cap)
{
	int len = dxl_encode_status(out, cap, id, (uint8_t)((errbits | sim_servo_condition_bits(s)) & DXL_ERRBIT_MASK),
	                            params, n);
	if (len > 0)
		s->count.replies++;
	return len;
}

/* Alarm shutdown (e-manual, Alarm LED/Shutdown and Torque Limit): "the motor
 * output becomes 0 % by resetting the value of Torque Limit(34) to 0". The
 * manual does not say what Torque Enable reads afterwards; the simulator
 * clears it too, so a controller that reads either one back sees the torque
 * gone (README). Counted once per cut, not per error while it is cut. */
static void servo_shutdown(struct sim_servo *s)
{
	if (s->mem[DXL_AX_TORQUE_ENABLE] || dxl_get_u16(&s->mem[DXL_AX_TORQUE_LIMIT]) != 0) {
		s->mem[DXL_AX_TORQUE_ENABLE] = 0;
		dxl_put_u16(&s->mem[DXL_AX_TORQUE_LIMIT], 0);
		s->count.shutdowns++;
	}
}

/* The errors of one instruction (range, angle limit, checksum, instruction):
 * counted, and — as the lasting conditions in servo_alarm() — a shutdown
 * when their bit is set in Alarm Shutdown: the manual's "if errors occur"
 * covers every bit of the register, and its Goal Position page says so of
 * the angle-limit bit in particular. Applied whether or not a status packet
 * reports the error (broadcast, status return level). */
static void servo_error(struct sim_servo *s, uint8_t bits)
{
	if (bits & DXL_ERRBIT_RANGE)
		s->count.range_errors++;
	if (bits & DXL_ERRBIT_ANGLE_LIMIT)
		s->count.angle_limit_errors++;
	if (bits & DXL_ERRBIT_INSTRUCTION)
		s->count.instruction_errors++;
	if (bits & DXL_ERRBIT_CHECKSUM)
		s->count.checksum_errors++;
	if (bits & s->mem[DXL_AX_ALARM_SHUTDOWN])
		servo_shutdown(s);
}

/* ---- writes ------------------------------------------------------------------ */

/* Whether a byte of register r may be written now (access, lock, torque). */
static bool servo_byte_writable(const struct sim_servo *s, const struct dxl_reg *r)
{
	if (!r || r->access != DXL_ACCESS_RW)
		return false;
	if (r->area == DXL_AREA_EEPROM) {
		if (s->mem[DXL_AX_LOCK])
			return false;
		if (s->opt.eeprom_needs_torque_off && s->mem[DXL_AX_TORQUE_ENABLE])
			return false;
	}
	return true;
}

/* Check of one register's new value against the new table image: its range
 * from the one table of protocol/dxl_table.c (the e-manual's, per mode),
 * then the two rules that depend on the servo's state. */
static uint8_t servo_value_error(const struct sim_servo *s, const uint8_t *img, const struct dxl_reg *r)
{
	uint16_t v = mem_get(img, r);
	bool wheel = dxl_is_wheel_mode(dxl_get_u16(&img[DXL_AX_CW_ANGLE_LIMIT]),
	                               dxl_get_u16(&img[DXL_AX_CCW_ANGLE_LIMIT]));
	if (dxl_reg_check_write_mode(r, v, wheel) != DXL_OK)
		return DXL_ERRBIT_RANGE;
	if (r->addr == DXL_AX_LOCK && s->mem[DXL_AX_LOCK] && v == 0)
		return DXL_ERRBIT_RANGE;  /* only a power cycle unlocks */
	if (r->addr == DXL_AX_GOAL_POSITION && !wheel) {
		uint16_t cw = dxl_get_u16(&img[DXL_AX_CW_ANGLE_LIMIT]);
		uint16_t ccw = dxl_get_u16(&img[DXL_AX_CCW_ANGLE_LIMIT]);
		if (v < cw || v > ccw)
			return DXL_ERRBIT_ANGLE_LIMIT;
	}
	return 0;
}

/* Validate a write of n bytes at addr; commit only when all of it is valid.
 * Returns the error bits for the reply (0 on success). */
static uint8_t servo_write(struct sim_servo *s, uint8_t addr, const uint8_t *data, size_t n)
{
	uint8_t img[DXL_AX_TABLE_SIZE];
	uint8_t err = 0;
	if (n == 0 || (size_t)addr + n > DXL_AX_TABLE_SIZE)
		return DXL_ERRBIT_RANGE;
	memcpy(img, s->mem, sizeof(img));
	memcpy(&img[addr], data, n);
	for (size_t a = addr; a < addr + n; a++) {
		const struct dxl_reg *r = servo_reg_covering((uint8_t)a);
		if (!servo_byte_writable(s, r))
			return DXL_ERRBIT_RANGE;
		/* Check each register once, at its first byte touched. */
		if (a == r->addr || a == addr)
			err |= servo_value_error(s, img, r);
	}
	if (err)
		return err;
	memcpy(s->mem, img, sizeof(s->mem));
	if (addr <= DXL_AX_TORQUE_ENABLE && addr + n > DXL_AX_TORQUE_ENABLE && s->mem[DXL_AX_TORQUE_ENABLE]) {
		/* Enabling torque is the manual's recovery: it clears a latched
		 * overload. Overheating and voltage persist physically: with
		 * one of those in the shutdown mask the torque stays off. */
		s->conditions &= (uint8_t)~DXL_ERRBIT_OVERLOAD;
		if (s->conditions & s->mem[DXL_AX_ALARM_SHUTDOWN])
			s->mem[DXL_AX_TORQUE_ENABLE] = 0;
	}
	return 0;
}

/* ---- instructions ------------------------------------------------------------ */

/* A READ's error bits: its two parameters, and the table's end (address 49:
 * where a READ runs past it the manual is silent; the range bit). */
static uint8_t servo_read_error(const struct dxl_packet *req)
{
	if (req->nparams != 2)
		return DXL_ERRBIT_INSTRUCTION;
	if (req->params[1] == 0 || (size_t)req->params[0] + req->params[1] > DXL_AX_TABLE_SIZE)
		return DXL_ERRBIT_RANGE;
	return 0;
}

static int servo_read(struct sim_servo *s, const struct dxl_packet *req, bool answer, uint8_t *out, size_t cap)
{
	uint8_t err = servo_read_error(req);
	servo_error(s, err);
	if (!answer)
		return 0;
	if (err)
		return servo_reply(s, req->id, err, NULL, 0, out, cap);
	return servo_reply(s, req->id, 0, &s->mem[req->params[0]], req->params[1], out, cap);
}

static uint8_t servo_reg_write(struct sim_servo *s, const struct dxl_packet *req)
{
	if (req->nparams < 2)
		return DXL_ERRBIT_INSTRUCTION;
	uint8_t addr = req->params[0];
	size_t n = req->nparams - 1u;
	if ((size_t)addr + n > DXL_AX_TABLE_SIZE)
		return DXL_ERRBIT_RANGE;
	s->reg_addr = addr;
	s->reg_len = (uint8_t)n;
	memcpy(s->reg_data, &req->params[1], n);
	s->reg_pending = true;
	s->mem[DXL_AX_REGISTERED] = 1;
	return 0;
}

static uint8_t servo_action(struct sim_servo *s)
{
	if (!s->reg_pending)
		return DXL_ERRBIT_INSTRUCTION;
	s->reg_pending = false;
	s->mem[DXL_AX_REGISTERED] = 0;
	return servo_write(s, s->reg_addr, s->reg_data, s->reg_len);
}

/* Our chunk of a SYNC_WRITE: addr, L, then (ID, L bytes) per servo. */
static void servo_sync_write(struct sim_servo *s, const struct dxl_packet *req)
{
	if (req->nparams < 2)
		return;
	uint8_t addr = req->params[0], l = req->params[1];
	size_t stride = (size_t)l + 1u;
	if (l == 0 || (req->nparams - 2u) % stride != 0)
		return;  /* malformed: a real servo cannot parse it either */
	for (size_t off = 2; off + stride <= req->nparams; off += stride) {
		if (req->params[off] == sim_servo_id(s)) {
			servo_error(s, servo_write(s, addr, &req->params[off + 1], l));
			return;
		}
	}
}

static void servo_factory_reset(struct sim_servo *s)
{
	servo_load_defaults(s, DXL_AREA_EEPROM);
	servo_ram_reset(s);
}

bool sim_servo_addressed(const struct sim_servo *s, const struct dxl_packet *req)
{
	if (!s->powered)
		return false;
	if (req->id == sim_servo_id(s))
		return true;
	if (req->id != DXL_BROADCAST_ID)
		return false;
	if (req->code != DXL_INST_SYNC_WRITE)
		return true;
	if (req->nparams < 2)
		return false;
	size_t stride = (size_t)req->params[1] + 1u;
	for (size_t off = 2; off < req->nparams; off += stride)
		if (req->params[off] == sim_servo_id(s))
			return true;
	return false;
}

int sim_servo_handle(struct sim_servo *s, const struct dxl_packet *req, uint8_t *out, size_t cap)
{
	if (!sim_servo_addressed(s, req))
		return 0;
	s->count.instructions++;
	/* Whether and under which ID the packet is answered is decided before it
	 * acts: a write of the ID is answered under the old one, and a write of
	 * the status return level under the old level (the original AX-12
	 * manual's Examples 7 and 14; its words: "the Status Packet is not
	 * returned starting with the following instruction"). */
	uint8_t id = sim_servo_id(s);
	bool broadcast = req->id == DXL_BROADCAST_ID;
	bool answer = !broadcast && servo_level_allows(s, req->code);
	uint8_t err = 0;
	switch (req->code) {
	case DXL_INST_PING:
		return servo_reply(s, id, 0, NULL, 0, out, cap);  /* broadcast too: they collide */
	case DXL_INST_READ:
		return broadcast ? 0 : servo_read(s, req, answer, out, cap);
	case DXL_INST_WRITE:
		err = req->nparams < 2 ? DXL_ERRBIT_INSTRUCTION
		                       : servo_write(s, req->params[0], &req->params[1], req->nparams - 1u);
		break;
	case DXL_INST_REG_WRITE:
		err = servo_reg_write(s, req);
		break;
	case DXL_INST_ACTION:
		err = servo_action(s);
		break;
	case DXL_INST_FACTORY_RESET: {
		/* The reply goes out under the old ID (the manual's example: ID 0
		 * answers its reset as ID 0), then the table resets. */
		int len = answer ? servo_reply(s, id, 0, NULL, 0, out, cap) : 0;
		servo_factory_reset(s);
		return len;
	}
	case DXL_INST_SYNC_WRITE:
		if (broadcast)
			servo_sync_write(s, req);
		else
			err = DXL_ERRBIT_INSTRUCTION;  /* SYNC_WRITE must be broadcast */
		break;
	default:
		err = DXL_ERRBIT_INSTRUCTION;  /* REBOOT, BULK_READ, ...: not on the AX-12 */
		break;
	}
	servo_error(s, err);
	return answer ? servo_reply(s, id, err, NULL, 0, out, cap) : 0;
}

int sim_servo_handle_bad_checksum(struct sim_servo *s, uint8_t id, uint8_t instr, uint8_t *out, size_t cap)
{
	if (!s->powered || id != sim_servo_id(s))
		return 0;
	servo_error(s, DXL_ERRBIT_CHECKSUM);
	if (!servo_level_allows(s, instr))
		return 0;
	return servo_reply(s, id, DXL_ERRBIT_CHECKSUM, NULL, 0, out, cap);
}

/* ---- physics side -------------------------------------------------------------- */

void sim_servo_motor_cmd(const struct sim_servo *s, struct sim_motor_cmd *cmd)
{
	const uint8_t *m = s->mem;
	cmd->torque_enable = s->powered && m[DXL_AX_TORQUE_ENABLE] != 0;
	cmd->goal_position = dxl_get_u16(&m[DXL_AX_GOAL_POSITION]);
	cmd->moving_speed = dxl_get_u16(&m[DXL_AX_MOVING_SPEED]);
	cmd->torque_limit = dxl_get_u16(&m[DXL_AX_TORQUE_LIMIT]);
	cmd->cw_margin = m[DXL_AX_CW_COMPLIANCE_MARGIN];
	cmd->ccw_margin = m[DXL_AX_CCW_COMPLIANCE_MARGIN];
	cmd->cw_slope = m[DXL_AX_CW_COMPLIANCE_SLOPE];
	cmd->ccw_slope = m[DXL_AX_CCW_COMPLIANCE_SLOPE];
	cmd->punch = dxl_get_u16(&m[DXL_AX_PUNCH]);
	cmd->cw_limit = dxl_get_u16(&m[DXL_AX_CW_ANGLE_LIMIT]);
	cmd->ccw_limit = dxl_get_u16(&m[DXL_AX_CCW_ANGLE_LIMIT]);
}

static uint8_t clamp_u8(double v)
{
	if (!(v > 0))
		return 0;
	return v > 255 ? 255 : (uint8_t)lround(v);
}

/* The overload bit rises after overload_time_s at the torque limit. It drops
 * when the servo drives again without overload; while the torque is off (e.g.
 * after the alarm shutdown) it stays latched, as the blinking LED does, until
 * the controller enables torque again. */
static void servo_update_overload(struct sim_servo *s, bool overloaded, double dt)
{
	bool driving = s->mem[DXL_AX_TORQUE_ENABLE] && dxl_get_u16(&s->mem[DXL_AX_TORQUE_LIMIT]) > 0;
	if (overloaded && driving) {
		s->overload_s += dt;
		if (s->overload_s >= s->opt.overload_time_s)
			s->conditions |= DXL_ERRBIT_OVERLOAD;
		return;
	}
	s->overload_s = 0;
	if (driving)
		s->conditions &= (uint8_t)~DXL_ERRBIT_OVERLOAD;
}

static void servo_update_conditions(struct sim_servo *s, const struct sim_servo_sense *in)
{
	uint8_t *m = s->mem;
	double v10 = in->voltage * 10.0;
	bool volt_bad = v10 < m[DXL_AX_MIN_VOLTAGE_LIMIT] || v10 > m[DXL_AX_MAX_VOLTAGE_LIMIT];
	bool hot = m[DXL_AX_PRESENT_TEMPERATURE] > m[DXL_AX_TEMPERATURE_LIMIT];
	s->conditions = (uint8_t)((s->conditions & DXL_ERRBIT_OVERLOAD) | (volt_bad ? DXL_ERRBIT_VOLTAGE : 0) |
	                          (hot ? DXL_ERRBIT_OVERHEAT : 0));
}

/* Alarm shutdown for the lasting conditions (voltage, overheating,
 * overload), checked every step: torque off with torque limit 0, again if the
 * controller turns it on while the condition lasts. Injected stuck-error bits
 * never get here (fault.c adds them to replies): they model a servo that
 * *says* it is overloaded, which the controller must handle without the sim
 * acting. */
static void servo_alarm(struct sim_servo *s)
{
	uint8_t active = s->conditions;
	s->alarm_led = (active & s->mem[DXL_AX_ALARM_LED]) != 0;
	if (active & s->mem[DXL_AX_ALARM_SHUTDOWN])
		servo_shutdown(s);
}

void sim_servo_sense(struct sim_servo *s, const struct sim_servo_sense *in, double dt)
{
	uint8_t *m = s->mem;
	if (!s->powered)
		return;
	uint16_t pos = dxl_rad_to_pos(in->angle);
	dxl_put_u16(&m[DXL_AX_PRESENT_POSITION], pos);
	/* Present Speed (e-manual): in joint mode the speed, 0.111 rpm a unit; in
	 * wheel mode "the unit is about 0.1 %" of the output — what the servo
	 * drives, not how fast the wheel turns. Both carry the direction in bit 10. */
	bool wheel = dxl_is_wheel_mode(dxl_get_u16(&m[DXL_AX_CW_ANGLE_LIMIT]), dxl_get_u16(&m[DXL_AX_CCW_ANGLE_LIMIT]));
	dxl_put_u16(&m[DXL_AX_PRESENT_SPEED], wheel ? dxl_duty_to_wheel(in->output) : dxl_rad_s_to_speed(in->speed));
	dxl_put_u16(&m[DXL_AX_PRESENT_LOAD], dxl_fraction_to_load(in->load_fraction));
	m[DXL_AX_PRESENT_VOLTAGE] = clamp_u8(in->voltage * 10.0);
	m[DXL_AX_PRESENT_TEMPERATURE] = clamp_u8(in->temperature);
	uint16_t goal = dxl_get_u16(&m[DXL_AX_GOAL_POSITION]);
	int margin = m[DXL_AX_CW_COMPLIANCE_MARGIN] > m[DXL_AX_CCW_COMPLIANCE_MARGIN] ? m[DXL_AX_CW_COMPLIANCE_MARGIN]
	                                                                                : m[DXL_AX_CCW_COMPLIANCE_MARGIN];
	bool moving = fabs(in->speed) > SERVO_MOVING_SPEED_EPS ||
	              (m[DXL_AX_TORQUE_ENABLE] && abs((int)goal - (int)pos) > margin + 1);
	m[DXL_AX_MOVING] = moving ? 1 : 0;
	servo_update_overload(s, in->overloaded, dt);
	servo_update_conditions(s, in);
	servo_alarm(s);
}
