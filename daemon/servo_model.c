/* servo_model.c — see servo_model.h. */
#include "servo_model.h"

#include <math.h>
#include <string.h>

#include "dxl.h"
#include "dxl2.h"
#include "dxl_table.h"
#include "osc.h"

#define SM_RPM_TO_RAD_S (2.0 * 3.14159265358979323846 / 60.0)

/* The AX-12's cycle reads 36..41 (position, speed, load), and every other
 * cycle 36..43 (voltage and temperature too); its read-back the RAM block
 * from torque enable (24) to present temperature (43). */
#define SM_AX_READBACK_ADDR 24
#define SM_AX_READBACK_LEN 20

/* The X series' cycle reads 126..135 (present current or load, velocity,
 * position), and every other cycle 126..146 (trajectories, input voltage and
 * temperature too): 10 or 21 bytes, so that a reply a whole period late has
 * the wrong length, as on 1.0. Read back: the RAM block from Torque Enable
 * (64) to Profile Velocity (112..115) — torque, Hardware Error Status, Bus
 * Watchdog, Goal PWM, the profiles — and the EEPROM block from Operating
 * Mode (11) to Min Position Limit (52..55): the mode and the limits. */
#define SM_X_PRESENT_LEN 10
#define SM_X_PRESENT_LEN_SLOW 21
/* The same values through the indirect areas (start-up maps them,
 * setup_indirect): Present Current/Load, Velocity, Position (126..135) in
 * Indirect Data 1..10, Present Input Voltage and Temperature (144..146) in
 * 11..13 — the slow read without the 8 bytes of trajectories it does not
 * use: 13 bytes, not 21, still unlike the fast 10 so a late reply is
 * refused for its length. */
static const uint16_t sm_x_indirect_src[] = {
	126, 127, 128, 129, 130, 131, 132, 133, 134, 135, 144, 145, 146,
};
#define SM_X_INDIRECT_SLOW (sizeof sm_x_indirect_src / sizeof sm_x_indirect_src[0])
_Static_assert(SM_X_INDIRECT_SLOW <= SM_READ_MAX && SM_X_INDIRECT_SLOW <= DXL2_X_INDIRECT_PER_BLOCK,
               "the indirect block fits one block of slots and setup_indirect's buffers");
#define SM_X_RAM_ADDR DXL2_X_TORQUE_ENABLE
#define SM_X_RAM_LEN (DXL2_X_PROFILE_VELOCITY + 4 - DXL2_X_TORQUE_ENABLE)
#define SM_X_EEPROM_ADDR DXL2_X_OPERATING_MODE
#define SM_X_EEPROM_LEN (DXL2_X_MIN_POSITION_LIMIT + 4 - DXL2_X_OPERATING_MODE)
/* Rotor inertia (kg·m²) × gear ratio²: the gear ratios are the datasheets';
 * the rotors are the simulator's assumptions (sim-bridge/PHYSICS.md §5: the
 * AX-12A's 4.6e-8, the XL430's taken as the AX-12A's, the XM430's coreless
 * motor 5.0e-8, not published). */
#define SM_REFLECTED(rotor, ratio) ((rotor) * (ratio) * (ratio))
/* Goal PWM's 100 % (PWM Limit's factory value). */
#define SM_X_PWM_FULL 885

/* Position actuation's defaults on the X servos: what `undulated --tune` found
 * on the simulator's servos for the paper's gait, 0.8 Hz and 0.8 rad
 * (daemon/CONTROL.md, "X-series servos", 2026-11-27: two joints and one).
 * They are the simulated servos': a real one has its own lag; tune on it. */
#define SM_XM430_POSITION \
	{ .k_pair = 0.0304, .mu_even = 0.0757, .mu_odd = 0.0571, .lead_pair = 0.047, \
	  .k_single = 0.0338, .mu_single = 0.0432, .lead_single = 0.047 }
/* The XC430-W150 (2026-11-28): one joint tuned from the XL430's values (k
 * x2.385); two joints from the one-joint values (k 0.025, mu 0.12/0.07,
 * lead 0.117: from the XL430's the search box ends short, mu needs 10x):
 * 0.807 Hz, 0.799/0.798 rad, lag 96 deg. */
#define SM_XC430_POSITION \
	{ .k_pair = 0.0234, .mu_even = 0.2838, .mu_odd = 0.2410, .lead_pair = 0.117, \
	  .k_single = 0.0250, .mu_single = 0.2256, .lead_single = 0.117 }
#define SM_XL430_POSITION \
	{ .k_pair = 0.0179, .mu_even = 0.0298, .mu_odd = 0.0166, .lead_pair = 0.086, \
	  .k_single = 0.0105, .mu_single = 0.0360, .lead_single = 0.117 }

/* Which tuned defaults a model takes: its own where --tune ran on it, else
 * the XL430-W250's (the PWM-driven X servo whose position loop the others'
 * resemble most) until someone tunes it: `undulated --tune` prints the
 * values to add here. */
static const struct {
	uint16_t number;
	struct sm_position_defaults position;
} sm_tuned[] = {
	{ DXL2_MODEL_XM430_W350, SM_XM430_POSITION },
	{ DXL2_MODEL_XC430_W150, SM_XC430_POSITION },
	{ DXL2_MODEL_XL430_W250, SM_XL430_POSITION },
};

static const struct sm_setup sm_ax_setup = {
	.family = "AX-12", .dxl_opt = "", .factory_baud = 0, .strict = false,
	.settings_len = DXL_AX_STATUS_RETURN_LEVEL + 1,
	.return_delay = DXL_AX_RETURN_DELAY_TIME, .status_return_level = DXL_AX_STATUS_RETURN_LEVEL,
	.firmware = DXL_AX_FIRMWARE_VERSION,
	.output_limit = DXL_AX_MAX_TORQUE, .output_limit_name = "max torque", .position = DXL_AX_PRESENT_POSITION,
	.angle_limits = DXL_AX_CW_ANGLE_LIMIT,
	.compliance_margin = DXL_AX_CW_COMPLIANCE_MARGIN, .compliance_slope = DXL_AX_CW_COMPLIANCE_SLOPE,
	.ramp = DXL_AX_MOVING_SPEED, .ramp_size = 2, .nramp = 1, .ramp_name = "moving speed",
};

/* The X series' one READ at start-up covers the model (0) to the Bus
 * Watchdog (98): mode, limits, shutdown, torque, status return level,
 * hardware error. */
static const struct sm_setup sm_x_setup = {
	.family = "X series", .dxl_opt = "--protocol 2 ", .factory_baud = 57600, .strict = true,
	.settings_len = DXL2_X_BUS_WATCHDOG + 1,
	.return_delay = DXL2_X_RETURN_DELAY_TIME, .status_return_level = DXL2_X_STATUS_RETURN_LEVEL,
	.firmware = DXL2_X_FIRMWARE_VERSION,
	.output_limit = DXL2_X_PWM_LIMIT, .output_limit_name = "PWM Limit", .current_limit = DXL2_X_CURRENT_LIMIT,
	.position = DXL2_X_PRESENT_POSITION,
	.opmode = DXL2_X_OPERATING_MODE, .pos_limit_min = DXL2_X_MIN_POSITION_LIMIT,
	.pos_limit_max = DXL2_X_MAX_POSITION_LIMIT,
	.ramp = DXL2_X_PROFILE_ACCELERATION, .ramp_size = 4, .nramp = 2, .ramp_name = "profile acceleration, velocity",
	.watchdog = DXL2_X_BUS_WATCHDOG, .hwerr = DXL2_X_HARDWARE_ERROR_STATUS, .shutdown = DXL2_X_SHUTDOWN,
};

_Static_assert(DXL_AX_STATUS_RETURN_LEVEL + 1 <= SM_SETTINGS_MAX && DXL2_X_BUS_WATCHDOG + 1 <= SM_SETTINGS_MAX,
               "start-up's settings READ fits its buffer");

/* Each family's decoders and drive units (below): the model table names
 * them, the calls never ask which family. */
static void sm_ax_present(const struct sm_model *m, const struct sm_read *rd, const uint8_t *b,
                          struct sm_present *out);
static void sm_x_present(const struct sm_model *m, const struct sm_read *rd, const uint8_t *b,
                         struct sm_present *out);
static void sm_ax_readback(const struct sm_model *m, const uint8_t *ram, struct sm_state *s);
static void sm_x_ram(const struct sm_model *m, const uint8_t *b, struct sm_state *s);
static void sm_x_eeprom(const struct sm_model *m, const uint8_t *b, struct sm_state *s);
static uint16_t sm_ax_drive_raw(const struct sm_model *m, bool current, double ratio, int32_t limit);
static uint16_t sm_x_drive_raw(const struct sm_model *m, bool current, double ratio, int32_t limit);

/* The AX-12A's positions are 0..1023: a raw value outside is taken as the
 * nearest end. */
static double sm_ax_pos_to_rad(int32_t raw)
{
	return dxl_pos_to_rad((uint16_t)(raw < 0 ? 0 : raw > DXL_POS_MAX ? DXL_POS_MAX : raw));
}

static int32_t sm_ax_rad_to_pos(double rad)
{
	return dxl_rad_to_pos(rad);
}

/* The AX-12A: its registers here, its datasheet its descriptor's
 * (protocol/dxl2_table.c), filled in at the first sm_ax12(). */
static struct sm_model sm_ax = {
	.name = "AX-12A", .protocol = 1, .number = DXL_AX12_MODEL,
	.torque_enable = DXL_AX_TORQUE_ENABLE, .torque_limit = DXL_AX_TORQUE_LIMIT,
	.goal = DXL_AX_GOAL_POSITION, .goal_size = 2,
	.present = DXL_AX_PRESENT_POSITION, .present_len = 6, .present_len_slow = 8,
	.readback = { { SM_AX_READBACK_ADDR, SM_AX_READBACK_LEN, "RAM", sm_ax_readback } }, .nreadback = 1,
	.decode_present = sm_ax_present, .drive_raw = sm_ax_drive_raw,
	.pos_max = DXL_POS_MAX, .pos_to_rad = sm_ax_pos_to_rad, .rad_to_pos = sm_ax_rad_to_pos,
	.status_faults = DXL_ERRBIT_OVERLOAD | DXL_ERRBIT_OVERHEAT, .status_alert = 0,
	.status_refused = DXL_ERRBIT_RANGE | DXL_ERRBIT_INSTRUCTION | DXL_ERRBIT_CHECKSUM,
	.drive = DXL_AX_MOVING_SPEED, .drive_current = DXL_AX_MOVING_SPEED,
	.torque_full = 1023, .ref_voltage = DXL2_REF_VOLTAGE, .position_from = "AX-12A", .caps = 0, .limits_name = "angle", .setup = &sm_ax_setup,
};
static bool sm_ax_made;

/* The X models, made once from protocol/dxl2_table.c's descriptors: every
 * X servo is read and driven through the same registers; what differs is
 * its descriptor's data. */
#define SM_MAX_X 32
static struct sm_model sm_x[SM_MAX_X];
static bool sm_x_made[SM_MAX_X];

static const struct sm_model *sm_x_model(size_t i)
{
	const struct dxl2_model *d = dxl2_model_at(i);
	if (d == NULL || i >= SM_MAX_X)
		return NULL;
	if (sm_x_made[i])
		return &sm_x[i];
	struct sm_model *m = &sm_x[i];
	*m = (struct sm_model){
		.name = d->name, .protocol = 2, .number = d->number, .desc = d, .caps = SM_CAP_HWERR | SM_CAP_OPMODE,
		.limits_name = "position", .setup = &sm_x_setup,
		.torque_enable = DXL2_X_TORQUE_ENABLE, .torque_limit = DXL2_X_GOAL_PWM,
		.goal = DXL2_X_GOAL_POSITION, .goal_size = 4,
		/* Present Current where it senses current, Present Load else: 126 */
		.present = DXL2_X_PRESENT_LOAD, .present_len = SM_X_PRESENT_LEN, .present_len_slow = SM_X_PRESENT_LEN_SLOW,
		.indirect = { DXL2_X_INDIRECT_DATA_1, SM_X_PRESENT_LEN, (uint8_t)SM_X_INDIRECT_SLOW, sm_x_indirect_src },
		.readback = { { SM_X_RAM_ADDR, SM_X_RAM_LEN, "RAM", sm_x_ram },
		              { SM_X_EEPROM_ADDR, SM_X_EEPROM_LEN, "EEPROM", sm_x_eeprom } },
		.decode_present = sm_x_present, .drive_raw = sm_x_drive_raw,
		.nreadback = 2, .pos_max = DXL2_POS_MAX, .pos_to_rad = dxl2_pos_to_rad, .rad_to_pos = dxl2_rad_to_pos,
		.status_faults = 0, .status_alert = DXL2_ERR_ALERT, .status_refused = DXL2_ERR_NUMBER_MASK,
		.drive = DXL2_X_GOAL_PWM, .drive_current = DXL2_X_GOAL_CURRENT, .torque_full = SM_X_PWM_FULL,
		.ref_voltage = DXL2_REF_VOLTAGE, .stall_torque_nm = d->sheet.stall_torque_nm,
		.no_load_speed_rad_s = d->sheet.no_load_speed_rpm * SM_RPM_TO_RAD_S,
		.stall_current_a = d->sheet.stall_current_a, .current_control = d->current_sensing,
		.rated_min_v = d->sheet.rated_min_v, .rated_max_v = d->sheet.rated_max_v,
		.reflected_inertia = SM_REFLECTED(d->sheet.rotor_inertia, d->sheet.gear_ratio),
		.position = SM_XL430_POSITION,
	};
	if (!dxl2_model_can(d, DXL2_CAP_INDIRECT))
		m->indirect = (struct sm_read){ 0 };
	m->position_from = "XL430-W250";
	for (size_t t = 0; t < sizeof sm_tuned / sizeof sm_tuned[0]; t++)
		if (sm_tuned[t].number == d->number) {
			m->position = sm_tuned[t].position;
			m->position_from = d->name;
		}
	sm_x_made[i] = true;
	return m;
}

const struct sm_model *sm_ax12(void)
{
	if (!sm_ax_made) {
		const struct dxl2_model *d = dxl2_model_find(1, DXL_AX12_MODEL);
		sm_ax.stall_torque_nm = d->sheet.stall_torque_nm;
		sm_ax.no_load_speed_rad_s = dxl2_sheet_no_load_rad_s(&d->sheet);
		sm_ax.stall_current_a = d->sheet.stall_current_a;
		sm_ax.rated_min_v = d->sheet.rated_min_v;
		sm_ax.rated_max_v = d->sheet.rated_max_v;
		sm_ax.reflected_inertia = SM_REFLECTED(d->sheet.rotor_inertia, d->sheet.gear_ratio);
		sm_ax_made = true;
	}
	return &sm_ax;
}

const struct sm_model *sm_by_number(int protocol, uint16_t number)
{
	if (protocol == 1)
		return number == sm_ax.number ? sm_ax12() : NULL;
	for (size_t i = 0; i < dxl2_model_count(); i++)
		if (dxl2_model_at(i)->protocol == 2 && dxl2_model_at(i)->number == number)
			return sm_x_model(i);
	return NULL;
}

const struct sm_model *sm_family(int protocol)
{
	if (protocol == 1)
		return sm_ax12();
	for (size_t i = 0; protocol == 2 && i < dxl2_model_count(); i++)
		if (dxl2_model_at(i)->protocol == 2)
			return sm_x_model(i);   /* the first X model: the family's registers are every X model's */
	return NULL;
}

/* The table's row: the X series' registers are read with dxl2_table's sizes
 * and signs, never restated here. */
static int32_t sm_x_get(const struct sm_model *m, const uint8_t *block, uint16_t block_addr, uint16_t addr)
{
	const struct dxl2_reg *r = dxl2_reg_at(dxl2_model_by_number(m->number), addr);
	return r != NULL ? dxl2_reg_decode(r, &block[addr - block_addr]) : 0;
}

/* A present register's value from the cycle's block, wherever rd puts it:
 * at its offset from the block's start (the direct read), or where its
 * first byte's slot is in the indirect block (its bytes are mapped in
 * order, setup_indirect). 0 when the block does not hold it. */
static int32_t sm_x_read_get(const struct sm_model *m, const struct sm_read *rd, const uint8_t *b, uint16_t addr)
{
	if (rd->src == NULL)
		return sm_x_get(m, b, rd->addr, addr);
	for (size_t k = 0; k < rd->len_slow; k++)
		if (rd->src[k] == addr)
			return sm_x_get(m, b + k, addr, addr);
	return 0;
}

/* ---- units ------------------------------------------------------------------------------------- */
double sm_pos_to_rad(const struct sm_model *m, int32_t raw)
{
	return m->pos_to_rad(raw);
}

int32_t sm_rad_to_pos(const struct sm_model *m, double rad)
{
	return m->rad_to_pos(rad);
}

void sm_joint_range(const struct sm_model *m, double lo_rad, double hi_rad, int32_t *lo, int32_t *hi)
{
	*lo = sm_rad_to_pos(m, lo_rad);
	*hi = sm_rad_to_pos(m, hi_rad);
	if (sm_pos_to_rad(m, *lo) < lo_rad && *lo < m->pos_max)
		(*lo)++;
	if (sm_pos_to_rad(m, *hi) > hi_rad && *hi > 0)
		(*hi)--;
}

const char *sm_register_name(const struct sm_model *m, uint16_t addr)
{
	if (m->desc != NULL) {
		const struct dxl2_reg *r = dxl2_reg_at(m->desc, addr);
		return r != NULL ? r->name : "register";
	}
	switch (addr) {
	case DXL_AX_TORQUE_ENABLE: return "torque enable";
	case DXL_AX_TORQUE_LIMIT: return "torque limit";
	case DXL_AX_CW_ANGLE_LIMIT: return "angle limits";
	case DXL_AX_CW_COMPLIANCE_MARGIN: return "compliance margins";
	case DXL_AX_CW_COMPLIANCE_SLOPE: return "compliance slopes";
	case DXL_AX_MOVING_SPEED: return "moving speed";
	default: return "register";
	}
}

bool sm_limit_is_pwm_drive(const struct sm_model *m)
{
	return m->torque_limit == sm_drive_register(m, false);
}

static void sm_ax_present(const struct sm_model *m, const struct sm_read *rd, const uint8_t *b,
                          struct sm_present *out)
{
	(void)m;
	(void)rd;   /* no indirect areas: the registers where they lie */
	out->pos_raw = dxl_get_u16(b);
	out->angle = dxl_pos_to_rad(dxl_get_u16(b));
	out->speed = dxl_speed_to_rad_s(dxl_get_u16(b + 2));
	out->load = dxl_load_to_fraction(dxl_get_u16(b + 4));
	if (out->slow) {
		out->voltage = dxl_voltage_to_volts(b[6]);
		out->temperature = b[7];
	}
}

static void sm_x_present(const struct sm_model *m, const struct sm_read *rd, const uint8_t *b,
                         struct sm_present *out)
{
	int32_t load = sm_x_read_get(m, rd, b, DXL2_X_PRESENT_LOAD);
	out->pos_raw = sm_x_read_get(m, rd, b, DXL2_X_PRESENT_POSITION);
	out->angle = dxl2_pos_to_rad(out->pos_raw);
	out->speed = dxl2_velocity_to_rad_s(sm_x_read_get(m, rd, b, DXL2_X_PRESENT_VELOCITY));
	out->load = m->current_control ? dxl2_current_to_amps(load) / m->stall_current_a : dxl2_load_to_fraction(load);
	if (out->slow) {
		out->voltage = dxl2_voltage_to_volts(sm_x_read_get(m, rd, b, DXL2_X_PRESENT_INPUT_VOLTAGE));
		out->temperature = sm_x_read_get(m, rd, b, DXL2_X_PRESENT_TEMPERATURE);
	}
}

struct sm_read sm_direct_read(const struct sm_model *m)
{
	return (struct sm_read){ m->present, m->present_len, m->present_len_slow, NULL };
}

bool sm_decode_read(const struct sm_model *m, const struct sm_read *rd, const uint8_t *b, size_t n,
                    struct sm_present *out)
{
	if (n != rd->len && n != rd->len_slow)
		return false;
	out->slow = n == rd->len_slow;
	out->voltage = out->temperature = NAN;
	m->decode_present(m, rd, b, out);
	return true;
}

bool sm_decode_present(const struct sm_model *m, const uint8_t *b, size_t n, struct sm_present *out)
{
	struct sm_read direct = sm_direct_read(m);
	return sm_decode_read(m, &direct, b, n, out);
}

void sm_state_unknown(struct sm_state *s)
{
	*s = (struct sm_state){
		.torque = -1, .torque_limit = -1, .margin_cw = -1, .margin_ccw = -1, .slope_cw = -1, .slope_ccw = -1,
		.hwerr = -1, .watchdog = -1,
		.opmode = -1, .profile_velocity = -1, .profile_acceleration = -1, .pos_min = -1, .pos_max = -1,
		.pwm_limit = -1, .current_limit = -1, .voltage = NAN, .temperature = NAN,
	};
}

static void sm_ax_readback(const struct sm_model *m, const uint8_t *ram, struct sm_state *s)
{
	(void)m;
#define REG(addr) ram[(addr) - SM_AX_READBACK_ADDR]
	s->torque = REG(DXL_AX_TORQUE_ENABLE);
	s->torque_limit = dxl_get_u16(&REG(DXL_AX_TORQUE_LIMIT));
	s->margin_cw = REG(DXL_AX_CW_COMPLIANCE_MARGIN);
	s->margin_ccw = REG(DXL_AX_CCW_COMPLIANCE_MARGIN);
	s->slope_cw = REG(DXL_AX_CW_COMPLIANCE_SLOPE);
	s->slope_ccw = REG(DXL_AX_CCW_COMPLIANCE_SLOPE);
	s->voltage = dxl_voltage_to_volts(REG(DXL_AX_PRESENT_VOLTAGE));
	s->temperature = REG(DXL_AX_PRESENT_TEMPERATURE);
#undef REG
}

static void sm_x_ram(const struct sm_model *m, const uint8_t *b, struct sm_state *s)
{
#define GET(addr) sm_x_get(m, b, SM_X_RAM_ADDR, (addr))
	s->torque = GET(DXL2_X_TORQUE_ENABLE);
	s->hwerr = GET(DXL2_X_HARDWARE_ERROR_STATUS);
	/* a byte: −1 (tripped) reads 255 */
	s->watchdog = b[DXL2_X_BUS_WATCHDOG - SM_X_RAM_ADDR];
	s->torque_limit = GET(DXL2_X_GOAL_PWM);
	s->profile_acceleration = GET(DXL2_X_PROFILE_ACCELERATION);
	s->profile_velocity = GET(DXL2_X_PROFILE_VELOCITY);
#undef GET
}

static void sm_x_eeprom(const struct sm_model *m, const uint8_t *b, struct sm_state *s)
{
#define GET(addr) sm_x_get(m, b, SM_X_EEPROM_ADDR, (addr))
	s->opmode = GET(DXL2_X_OPERATING_MODE);
	s->pwm_limit = GET(DXL2_X_PWM_LIMIT);
	s->current_limit = m->current_control ? GET(DXL2_X_CURRENT_LIMIT) : -1;
	s->pos_max = GET(DXL2_X_MAX_POSITION_LIMIT);
	s->pos_min = GET(DXL2_X_MIN_POSITION_LIMIT);
#undef GET
}

bool sm_decode_readback(const struct sm_model *m, size_t block, const uint8_t *bytes, size_t n, struct sm_state *s)
{
	if (block >= m->nreadback || n != m->readback[block].len)
		return false;
	m->readback[block].decode(m, bytes, s);
	return true;
}

/* ---- status ----------------------------------------------------------------------------------- */
uint8_t sm_status_faults(const struct sm_model *m, uint8_t status)
{
	return (uint8_t)(status & m->status_faults);
}

bool sm_alert(const struct sm_model *m, uint8_t status)
{
	return (status & m->status_alert) != 0;
}

bool sm_write_refused(const struct sm_model *m, uint8_t status)
{
	return (status & m->status_refused) != 0;
}

/* ---- the supply ------------------------------------------------------------------------------- */
void sm_supply_range(const struct sm_model *m, double *lo, double *hi)
{
	*lo = m->rated_min_v * (1.0 - SM_SUPPLY_TOLERANCE);
	*hi = m->rated_max_v * (1.0 + SM_SUPPLY_TOLERANCE);
}

bool sm_supply_plausible(const struct sm_model *m, double volts)
{
	double lo, hi;
	sm_supply_range(m, &lo, &hi);
	/* the reading is in 0.1 V: 12.6 must not fail on 12.6000000001 */
	return volts >= lo - 1e-6 && volts <= hi + 1e-6;
}

/* ---- torque actuation --------------------------------------------------------------------------- */
uint16_t sm_drive_register(const struct sm_model *m, bool current)
{
	return current ? m->drive_current : m->drive;
}

double sm_torque_scale(const struct sm_model *m)
{
	double link = OSC_TORQUE_JOINT_INERTIA - sm_ax12()->reflected_inertia;
	return (link + m->reflected_inertia) / OSC_TORQUE_JOINT_INERTIA;
}

bool sm_position_defaults(const struct sm_model *m, size_t j, size_t njoints, double *k, double *mu, double *lead)
{
	const struct sm_position_defaults *p = &m->position;
	if (p->k_pair <= 0.0)
		return false;
	bool single = njoints < 2;
	*k = single ? p->k_single : p->k_pair;
	*mu = single ? p->mu_single : (j % 2 == 0 ? p->mu_even : p->mu_odd);
	*lead = single ? p->lead_single : p->lead_pair;
	return true;
}

uint8_t sm_drive_opmode(bool current)
{
	return current ? DXL2_OPMODE_CURRENT : DXL2_OPMODE_PWM;
}

uint16_t sm_drive_raw(const struct sm_model *m, bool current, double ratio, int32_t limit)
{
	return m->drive_raw(m, current, ratio, limit);
}

/* The AX-12A's wheel mode: Moving Speed as a PWM duty, bit 10 the direction. */
static uint16_t sm_ax_drive_raw(const struct sm_model *m, bool current, double ratio, int32_t limit)
{
	(void)m, (void)current, (void)limit;
	return dxl_duty_to_wheel(ratio);
}

static uint16_t sm_x_drive_raw(const struct sm_model *m, bool current, double ratio, int32_t limit)
{
	if (!isfinite(ratio))
		return 0;
	if (limit < 0)
		limit = 0;
	double raw = current ? ratio * m->stall_current_a / DXL2_CURRENT_A_PER_UNIT : ratio * SM_X_PWM_FULL;
	raw = fmax(-(double)limit, fmin((double)limit, round(raw)));
	return (uint16_t)(int16_t)raw;
}
