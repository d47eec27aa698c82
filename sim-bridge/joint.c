/* joint.c — a simulated joint's servo by its family's table (joint.h). */
#include "joint.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dxl.h"
#include "dxl2.h"
#include "dxl2_table.h"
#include "dxl_table.h"
#include "simbus.h"

/* The supply and temperature a servo reads: a fault's value while it lasts. */
static double sensed_voltage(const struct sim_joint *j)
{
	const struct sim_fault *f = &j->faults.f[SIM_FAULT_VOLTAGE];
	return f->active ? f->arg : j->params.supply_voltage;
}

static double sensed_temperature(const struct sim_joint *j)
{
	const struct sim_fault *f = &j->faults.f[SIM_FAULT_TEMPERATURE];
	return f->active ? f->arg : j->motor.temperature;
}

/* ---- the AX-12A on Protocol 1.0 ------------------------------------------------------ */

static void ax_place(struct sim_joint *j, enum sim_model m, const struct sim_joint_place *p)
{
	(void)m;
	struct sim_servo_options so = { p->eeprom_needs_torque_off, p->overload_time_s };
	sim_servo_init(&j->servo, &so, DXL_POS_CENTER);
	sim_servo_poke(&j->servo, DXL_AX_ID, p->id);
	sim_servo_poke(&j->servo, DXL_AX_BAUD_RATE, p->baud_reg);
	if (p->delay_us >= 0)
		sim_servo_poke(&j->servo, DXL_AX_RETURN_DELAY_TIME, (uint16_t)(p->delay_us / 2));
}

static uint8_t ax_id(const struct sim_joint *j) { return sim_servo_id(&j->servo); }
static bool ax_powered(const struct sim_joint *j) { return j->servo.powered; }
static bool ax_torque(const struct sim_joint *j) { return j->servo.powered && j->servo.mem[DXL_AX_TORQUE_ENABLE]; }
static long ax_baud(const struct sim_joint *j) { return dxl_baud_from_reg(j->servo.mem[DXL_AX_BAUD_RATE]); }

static void ax_sense(struct sim_joint *j, double dt)
{
	struct sim_motor_cmd cmd;
	sim_servo_motor_cmd(&j->servo, &cmd);
	struct sim_servo_sense in = {
		.angle = j->motor.angle,
		.speed = j->motor.speed,
		.load_fraction = cmd.torque_enable ? sim_motor_load_fraction(&j->motor, &j->params) : 0,
		.output = cmd.torque_enable ? j->motor.drive : 0,
		.voltage = sensed_voltage(j),
		.temperature = sensed_temperature(j),
		.overloaded = cmd.torque_enable && sim_motor_overloaded(&j->motor, &j->params, &cmd),
	};
	sim_servo_sense(&j->servo, &in, dt);
}

static void ax_step(struct sim_joint *j, double dt)
{
	struct sim_motor_cmd cmd;
	sim_servo_motor_cmd(&j->servo, &cmd);
	sim_motor_step(&j->motor, &j->params, &cmd, 0.0, dt);
}

static void ax_drive(struct sim_joint *j, double dt, struct sim_motor_drive *d)
{
	struct sim_motor_cmd cmd;
	sim_servo_motor_cmd(&j->servo, &cmd);
	sim_motor_drive_for(&j->motor, &j->params, &cmd, dt, d);
}

static void ax_power_up(struct sim_joint *j)
{
	ax_sense(j, 0);
	dxl_put_u16(&j->servo.mem[DXL_AX_GOAL_POSITION], dxl_get_u16(&j->servo.mem[DXL_AX_PRESENT_POSITION]));
}

static void ax_power_on(struct sim_joint *j)
{
	sim_servo_power_on(&j->servo);
	ax_power_up(j);
}

static void ax_power_off(struct sim_joint *j) { sim_servo_power_off(&j->servo); }

static bool ax_reg(const struct sim_joint *j, const char *name, struct sim_joint_reg *r, char *err, size_t cap)
{
	(void)j;
	const struct dxl_reg *d = dxl_reg_lookup(name);
	if (d == NULL) {
		snprintf(err, cap, "unknown register '%s'", name);
		return false;
	}
	*r = (struct sim_joint_reg){ d->name, d->addr, 0, d->size == 2 ? 65535 : 255 };
	return true;
}

static void ax_poke(struct sim_joint *j, uint16_t addr, long v) { sim_servo_poke(&j->servo, (uint8_t)addr, (uint16_t)v); }
static long ax_peek(const struct sim_joint *j, uint16_t addr) { return sim_servo_peek(&j->servo, (uint8_t)addr); }

static int ax_describe(const struct sim_joint *j, char *buf, size_t cap)
{
	const struct sim_servo *sv = &j->servo;
	return snprintf(buf, cap, "id=%u power=%s torque=%u errbits=0x%02x angle=%.4f speed=%.4f temp=%.1f "
	                          "instructions=%u replies=%u range=%u angle_limit=%u instruction=%u checksum=%u "
	                          "shutdowns=%u ",
	                sim_servo_id(sv), sv->powered ? "on" : "off", sv->mem[DXL_AX_TORQUE_ENABLE],
	                sim_servo_condition_bits(sv), j->motor.angle, j->motor.speed, j->motor.temperature,
	                sv->count.instructions, sv->count.replies, sv->count.range_errors, sv->count.angle_limit_errors,
	                sv->count.instruction_errors, sv->count.checksum_errors, sv->count.shutdowns);
}

static bool ax_error_fits(const struct sim_fault *f, const char **why)
{
	*why = "speaks Protocol 1.0: its error bits are voltage, angle-limit, overheating, range, checksum, overload, "
	       "instruction (or 0..127)";
	return f->arg >= 0;
}

static int ax_handle(struct sim_joint *j, const struct dxl_frame *req, uint8_t *out, size_t cap)
{
	/* a 1.0 frame (its parser's) always fits the 1.0 packet */
	struct dxl_packet pkt;
	pkt.id = req->id;
	pkt.code = req->instr;
	pkt.nparams = (uint8_t)req->nparams;
	memcpy(pkt.params, req->params, pkt.nparams);
	return sim_servo_handle(&j->servo, &pkt, out, cap);
}

static int ax_handle_damaged(struct sim_joint *j, uint8_t id, uint8_t instr, uint8_t *out, size_t cap)
{
	return sim_servo_handle_bad_checksum(&j->servo, id, instr, out, cap);
}

static bool ax_reply_faults(struct sim_joint *j, uint64_t *rng, uint8_t *pkt, size_t *len, size_t cap,
                            uint8_t *garbage, size_t *ngarbage, int64_t *extra_delay_ns)
{
	(void)cap;   /* a 1.0 fault never lengthens the packet */
	return sim_faults_apply(&j->faults, rng, pkt, len, garbage, ngarbage, extra_delay_ns);
}

static int64_t ax_return_delay_ns(const struct sim_joint *j)
{
	return (int64_t)dxl_return_delay_us(j->servo.mem[DXL_AX_RETURN_DELAY_TIME]) * 1000;
}

static const struct sim_joint_ops ax_ops = {
	.proto = &dxl_proto_v1, .family = "AX-12A", .place = ax_place, .id = ax_id, .powered = ax_powered, .torque = ax_torque, .baud = ax_baud,
	.sense = ax_sense, .step = ax_step, .drive = ax_drive, .power_up = ax_power_up, .power_on = ax_power_on,
	.power_off = ax_power_off, .reg = ax_reg, .poke = ax_poke, .peek = ax_peek, .describe = ax_describe,
	.error_fits = ax_error_fits,
	.handle = ax_handle, .handle_damaged = ax_handle_damaged, .reply_faults = ax_reply_faults,
	.return_delay_ns = ax_return_delay_ns,
	.baud_reg = dxl_baud_to_reg, .rate_names = "AX-12 rate", .max_id = DXL_MAX_ID, .max_baud_reg = 254,
	.motor_from_config = true, .says_family = false,
};

/* ---- the X series on Protocol 2.0 ---------------------------------------------------- */

static void x_place(struct sim_joint *j, enum sim_model m, const struct sim_joint_place *p)
{
	struct sim_xservo_options xo = { p->overload_time_s, p->firmware, p->no_indirect };
	sim_xservo_init(&j->xservo, m, &xo, 0.0);
	sim_xservo_poke(&j->xservo, DXL2_X_ID, p->id);
	sim_xservo_poke(&j->xservo, DXL2_X_BAUD_RATE, p->baud_reg);
	if (p->delay_us >= 0)
		sim_xservo_poke(&j->xservo, DXL2_X_RETURN_DELAY_TIME, p->delay_us / 2);
	sim_xdrive_init(&j->xdrive);
}

static uint8_t x_id(const struct sim_joint *j) { return sim_xservo_id(&j->xservo); }
static bool x_powered(const struct sim_joint *j) { return j->xservo.powered; }
static bool x_torque(const struct sim_joint *j) { return j->xservo.powered && j->xservo.mem[DXL2_X_TORQUE_ENABLE]; }
static long x_baud(const struct sim_joint *j) { return dxl2_baud_from_reg(j->xservo.mem[DXL2_X_BAUD_RATE]); }

static void x_sense(struct sim_joint *j, double dt)
{
	bool torque = x_torque(j);
	struct sim_xdrive_cmd xc;
	sim_xservo_drive_cmd(&j->xservo, &xc);
	double cap = sim_xdrive_cap(&xc, sim_motor_stall_torque(&j->params));
	struct sim_xservo_sense in = {
		.angle = j->motor.angle,
		.speed = j->motor.speed,
		.torque = torque ? j->motor.motor_torque : 0,
		.stall_torque = sim_motor_stall_torque(&j->params),
		.duty = torque ? j->motor.drive : 0,
		.voltage = sensed_voltage(j),
		.temperature = sensed_temperature(j),
		.drive = &j->xdrive,
	};
	/* the overload's cause: the delivered torque at the driver's cap (as
	 * the AX-12A's, within 2 % of it) */
	in.overloaded = torque && cap > 0 && fabs(j->motor.motor_torque) >= 0.98 * cap;
	sim_xservo_sense(&j->xservo, &in, dt);
}

static void x_drive(struct sim_joint *j, double dt, struct sim_motor_drive *d)
{
	struct sim_xdrive_cmd xc;
	sim_xservo_drive_cmd(&j->xservo, &xc);
	sim_xdrive_step(&j->xdrive, &xc, &j->motor, &j->params, dt, d);
}

static void x_step(struct sim_joint *j, double dt)
{
	struct sim_motor_drive d;
	x_drive(j, dt, &d);
	sim_motor_step_drive(&j->motor, &j->params, &d, 0.0, dt);
}

/* An X servo boots: RAM reset as on the real one. */
static void x_power_up(struct sim_joint *j)
{
	sim_xservo_power_on(&j->xservo, j->motor.angle);
	x_sense(j, 0);
}

static void x_power_off(struct sim_joint *j) { sim_xservo_power_off(&j->xservo); }

static bool x_reg(const struct sim_joint *j, const char *name, struct sim_joint_reg *r, char *err, size_t cap)
{
	const struct dxl2_reg *d = dxl2_reg_lookup(j->xservo.table, name);
	if (d == NULL) {
		snprintf(err, cap, "unknown register '%s' (the %s's table)", name, sim_model_info(j->model)->label);
		return false;
	}
	/* any value the register's bytes can hold */
	int bits = 8 * d->size;
	long lo = d->is_signed ? -(1L << (bits - 1)) : 0;
	long hi = d->is_signed ? (1L << (bits - 1)) - 1 : (long)((1ULL << bits) - 1);
	*r = (struct sim_joint_reg){ d->name, d->addr, lo, hi };
	return true;
}

static void x_poke(struct sim_joint *j, uint16_t addr, long v) { sim_xservo_poke(&j->xservo, addr, (int32_t)(uint32_t)v); }

static long x_peek(const struct sim_joint *j, uint16_t addr)
{
	int32_t v = 0;
	sim_xservo_peek(&j->xservo, addr, &v);
	return v;
}

/* its model, mode, hardware errors, watchdog and the status ERR field's
 * error numbers as counters */
static int x_describe(const struct sim_joint *j, char *buf, size_t cap)
{
	const struct sim_xservo *sv = &j->xservo;
	const struct sim_xservo_counters *c = &sv->count;
	return snprintf(buf, cap, "id=%u model=%s power=%s torque=%u mode=%u hwerr=0x%02x watchdog=%u "
	                          "angle=%.4f speed=%.4f temp=%.1f instructions=%u replies=%u result_fail=%u "
	                          "instruction=%u crc=%u data_range=%u data_length=%u data_limit=%u access=%u "
	                          "shutdowns=%u watchdog_trips=%u reboots=%u ",
	                sim_xservo_id(sv), sim_model_info(j->model)->name, sv->powered ? "on" : "off",
	                sv->mem[DXL2_X_TORQUE_ENABLE], sv->mem[DXL2_X_OPERATING_MODE], sv->mem[DXL2_X_HARDWARE_ERROR_STATUS],
	                sv->mem[DXL2_X_BUS_WATCHDOG], j->motor.angle, j->motor.speed, j->motor.temperature, c->instructions,
	                c->replies, c->result_fail, c->instruction_errors, c->crc_errors, c->data_range_errors,
	                c->data_length_errors, c->data_limit_errors, c->access_errors, c->shutdowns, c->watchdog_trips,
	                c->reboots);
}

static bool x_error_fits(const struct sim_fault *f, const char **why)
{
	*why = "speaks Protocol 2.0: its ERR field is alert and/or one of result-fail, instruction, crc, data-range, "
	       "data-length, data-limit, access (or 0..255)";
	return f->err2 >= 0;
}

static int x_handle(struct sim_joint *j, const struct dxl_frame *req, uint8_t *out, size_t cap)
{
	struct dxl2_packet pkt;   /* fields assigned, not the whole kilobyte zeroed */
	dxl_frame_to_packet2(req, &pkt);
	return sim_xservo_handle(&j->xservo, &pkt, out, cap);
}

static int x_handle_damaged(struct sim_joint *j, uint8_t id, uint8_t instr, uint8_t *out, size_t cap)
{
	return sim_xservo_handle_bad_crc(&j->xservo, id, instr, out, cap);
}

static bool x_reply_faults(struct sim_joint *j, uint64_t *rng, uint8_t *pkt, size_t *len, size_t cap,
                           uint8_t *garbage, size_t *ngarbage, int64_t *extra_delay_ns)
{
	return sim_faults_apply2(&j->faults, rng, pkt, len, cap, garbage, ngarbage, extra_delay_ns);
}

static int64_t x_return_delay_ns(const struct sim_joint *j)
{
	return (int64_t)dxl2_return_delay_us(j->xservo.mem[DXL2_X_RETURN_DELAY_TIME]) * 1000;
}

static const struct sim_joint_ops x_ops = {
	.proto = &dxl_proto_v2, .family = "X series", .place = x_place, .id = x_id, .powered = x_powered, .torque = x_torque, .baud = x_baud,
	.sense = x_sense, .step = x_step, .drive = x_drive, .power_up = x_power_up, .power_on = x_power_up,
	.power_off = x_power_off, .reg = x_reg, .poke = x_poke, .peek = x_peek, .describe = x_describe,
	.error_fits = x_error_fits,
	.handle = x_handle, .handle_damaged = x_handle_damaged, .reply_faults = x_reply_faults,
	.return_delay_ns = x_return_delay_ns,
	.baud_reg = dxl2_baud_to_reg,
	.rate_names = "X-series rate (9600, 57600, 115200, 1000000, 2000000, 3000000, 4000000, 4500000)",
	.max_id = DXL2_MAX_ID, .max_baud_reg = 7, .motor_from_config = false, .says_family = true,
};

/* The one place a model's family is chosen: by the protocol its model
 * speaks, one family per protocol so far. */
const struct sim_joint_ops *sim_joint_ops_of(enum sim_model m)
{
	return sim_model_info(m)->protocol == 2 ? &x_ops : &ax_ops;
}

void sim_joint_place(struct sim_joint *j, enum sim_model m, const struct sim_joint_place *p)
{
	j->model = m;
	j->ops = sim_joint_ops_of(m);
	j->ops->place(j, m, p);
}
