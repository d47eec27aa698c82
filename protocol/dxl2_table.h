/*
 * dxl2_table.h — every servo model undulate knows, as data: the AX-12A
 * (Protocol 1.0) and the X series (XL430-W250, XM430-W350, XC430-W150;
 * Protocol 2.0), one descriptor each in one list — protocol, model number,
 * control-table rows, datasheet, capabilities — with lookup, write checks,
 * formatting and the X series' unit conversions (the AX-12's are
 * dxl_table.h's). Pure code: tools address registers by name, the simulator
 * builds its servo memory from the same rows, the daemon converts raw values
 * to SI. (The dxl2_ prefix is the module's, older than the AX-12A's place in
 * it; the types are protocol-neutral.)
 *
 * Values are the ROBOTIS e-manual's control-table pages; where one printed
 * revision disagrees with another, the row's comment in dxl2_table.c says
 * which was taken. Values are little-endian; registers marked signed are
 * two's complement of their size. EEPROM (addresses below 64) is writable
 * only with Torque Enable (64) = 0; the servo answers an access error else.
 * The indirect areas (168-251, 578-661) are rows too: indirect_address_1..56
 * (kept as EEPROM: see dxl2_table.c) and indirect_data_1..56, with
 * dxl2_indirect_* below to find one from the other.
 */
#ifndef UNDULATE_DXL2_TABLE_H
#define UNDULATE_DXL2_TABLE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl_table.h"   /* enum dxl_access, enum dxl_area */

/* Addresses shared by the XL430-W250 and the XM430-W350. */
enum dxl2_x_addr {
	DXL2_X_MODEL_NUMBER          = 0,
	DXL2_X_MODEL_INFORMATION     = 2,
	DXL2_X_FIRMWARE_VERSION      = 6,
	DXL2_X_ID                    = 7,
	DXL2_X_BAUD_RATE             = 8,
	DXL2_X_RETURN_DELAY_TIME     = 9,
	DXL2_X_DRIVE_MODE            = 10,
	DXL2_X_OPERATING_MODE        = 11,
	DXL2_X_SECONDARY_ID          = 12,
	DXL2_X_PROTOCOL_TYPE         = 13,
	DXL2_X_HOMING_OFFSET         = 20,
	DXL2_X_MOVING_THRESHOLD      = 24,
	DXL2_X_TEMPERATURE_LIMIT     = 31,
	DXL2_X_MAX_VOLTAGE_LIMIT     = 32,
	DXL2_X_MIN_VOLTAGE_LIMIT     = 34,
	DXL2_X_PWM_LIMIT             = 36,
	DXL2_X_CURRENT_LIMIT         = 38,   /* XM430 only */
	DXL2_X_VELOCITY_LIMIT        = 44,
	DXL2_X_MAX_POSITION_LIMIT    = 48,
	DXL2_X_MIN_POSITION_LIMIT    = 52,
	DXL2_X_STARTUP_CONFIGURATION = 60,   /* XL430 page only */
	DXL2_X_SHUTDOWN              = 63,
	DXL2_X_TORQUE_ENABLE         = 64,
	DXL2_X_LED                   = 65,
	DXL2_X_STATUS_RETURN_LEVEL   = 68,
	DXL2_X_REGISTERED_INSTRUCTION = 69,
	DXL2_X_HARDWARE_ERROR_STATUS = 70,
	DXL2_X_VELOCITY_I_GAIN       = 76,
	DXL2_X_VELOCITY_P_GAIN       = 78,
	DXL2_X_POSITION_D_GAIN       = 80,
	DXL2_X_POSITION_I_GAIN       = 82,
	DXL2_X_POSITION_P_GAIN       = 84,
	DXL2_X_FEEDFORWARD_2ND_GAIN  = 88,
	DXL2_X_FEEDFORWARD_1ST_GAIN  = 90,
	DXL2_X_BUS_WATCHDOG          = 98,
	DXL2_X_GOAL_PWM              = 100,
	DXL2_X_GOAL_CURRENT          = 102,  /* XM430 only */
	DXL2_X_GOAL_VELOCITY         = 104,
	DXL2_X_PROFILE_ACCELERATION  = 108,
	DXL2_X_PROFILE_VELOCITY      = 112,
	DXL2_X_GOAL_POSITION         = 116,
	DXL2_X_REALTIME_TICK         = 120,
	DXL2_X_MOVING                = 122,
	DXL2_X_MOVING_STATUS         = 123,
	DXL2_X_PRESENT_PWM           = 124,
	DXL2_X_PRESENT_LOAD          = 126,  /* XL430: load; XM430: current */
	DXL2_X_PRESENT_CURRENT       = 126,
	DXL2_X_PRESENT_VELOCITY      = 128,
	DXL2_X_PRESENT_POSITION      = 132,
	DXL2_X_VELOCITY_TRAJECTORY   = 136,
	DXL2_X_POSITION_TRAJECTORY   = 140,
	DXL2_X_PRESENT_INPUT_VOLTAGE = 144,
	DXL2_X_PRESENT_TEMPERATURE   = 146,
	DXL2_X_BACKUP_READY          = 147,  /* XL430 page only */
};
#define DXL2_X_EEPROM_END  64     /* addresses below are EEPROM */
/* The X series' indirect areas (e-manual, "Indirect Address, Indirect
 * Data"): two blocks of 28 two-byte Indirect Address registers, each
 * followed by its 28 one-byte Indirect Data registers. Indirect Address n
 * holds the address (64..661) of the byte Indirect Data n reads and writes;
 * its factory value is Indirect Data n's own address. */
#define DXL2_X_INDIRECT_ADDRESS_1  168
#define DXL2_X_INDIRECT_DATA_1     224
#define DXL2_X_INDIRECT_ADDRESS_29 578
#define DXL2_X_INDIRECT_DATA_29    634
#define DXL2_X_INDIRECT_PER_BLOCK  28
#define DXL2_X_INDIRECT_COUNT      56
#define DXL2_X_INDIRECT_MIN        64    /* the RAM area: no EEPROM address */
#define DXL2_X_INDIRECT_MAX        661
#define DXL2_X_PRESENT_END 148    /* bytes 0..147: the registers before the indirect areas */
#define DXL2_X_TABLE_SIZE  662    /* bytes 0..661 described here */

/* Model numbers (register 0). */
#define DXL2_MODEL_XL430_W250 1060
#define DXL2_MODEL_XM430_W350 1020
#define DXL2_MODEL_XC430_W150 1070
/* The datasheet lines are at this supply (the e-manual's specification
 * tables; torque and speed scale about linearly with it). */
#define DXL2_REF_VOLTAGE               12.0   /* V */

/* Operating Mode (11) values. */
enum dxl2_opmode {
	DXL2_OPMODE_CURRENT          = 0,
	DXL2_OPMODE_VELOCITY         = 1,
	DXL2_OPMODE_POSITION         = 3,
	DXL2_OPMODE_EXTENDED_POSITION = 4,
	DXL2_OPMODE_CURRENT_POSITION = 5,
	DXL2_OPMODE_PWM              = 16,
};
const char *dxl2_opmode_name(uint8_t mode);   /* "position", or NULL */

/* Hardware Error Status (70) and Shutdown (63) bits. */
enum dxl2_hwerr {
	DXL2_HWERR_VOLTAGE  = 1u << 0,  /* input voltage out of the limits */
	DXL2_HWERR_OVERHEAT = 1u << 2,
	DXL2_HWERR_ENCODER  = 1u << 3,  /* motor encoder malfunction */
	DXL2_HWERR_SHOCK    = 1u << 4,  /* electrical shock / insufficient power */
	DXL2_HWERR_OVERLOAD = 1u << 5,
};
#define DXL2_HWERR_MASK 0x3Du
/* "overheating|overload", "none"; unknown bits as "bitN". Returns buf. */
char *dxl2_hwerr_format(uint8_t bits, char *buf, size_t cap);

enum dxl2_unit {
	DXL2_UNIT_RAW,
	DXL2_UNIT_POSITION,     /* 1 pulse = 360/4096 deg, 2048 = centre */
	DXL2_UNIT_VELOCITY,     /* 0.229 rpm */
	DXL2_UNIT_CURRENT,      /* 2.69 mA */
	DXL2_UNIT_LOAD,         /* 0.1 % */
	DXL2_UNIT_PWM,          /* 0.113 % */
	DXL2_UNIT_VOLTAGE,      /* 0.1 V */
	DXL2_UNIT_TEMPERATURE,  /* deg C */
	DXL2_UNIT_BAUD,         /* table: 0 = 9600 ... 7 = 4.5 M */
	DXL2_UNIT_RETURN_DELAY, /* 2 us */
	DXL2_UNIT_WATCHDOG,     /* 20 ms; 0 = off */
	DXL2_UNIT_ACCELERATION, /* 214.577 rev/min^2 */
	DXL2_UNIT_MS,           /* 1 ms */
	DXL2_UNIT_BOOL,
	DXL2_UNIT_HWERR,        /* hardware error bits */
	DXL2_UNIT_STATUS_LEVEL, /* 0 ping, 1 + read, 2 all */
	DXL2_UNIT_OPMODE,
	/* The AX-12A's (Protocol 1.0) own units. */
	DXL2_UNIT_AX_POSITION,  /* 300/1023 deg, 512 = centre */
	DXL2_UNIT_AX_SPEED,     /* present speed: 0.111 rpm, bit 10 = CW */
	DXL2_UNIT_AX_MOVING_SPEED, /* goal speed: 0.111 rpm, 0 = maximum; wheel mode bit 10 = CW */
	DXL2_UNIT_AX_LOAD,      /* 0.1 % of max torque, bit 10 = CW */
	DXL2_UNIT_AX_TORQUE,    /* 0.1 % of max torque (limits) */
	DXL2_UNIT_AX_BAUD,      /* bps = 2e6 / (v + 1) */
	DXL2_UNIT_AX_ERRMASK,   /* Protocol 1.0 error-bit mask: named bits */
};

/* How a register's range depends on another register's value. */
enum dxl2_limit {
	DXL2_LIMIT_NONE,
	DXL2_LIMIT_SYMMETRIC,  /* -value(lim_addr) .. +value(lim_addr) */
	DXL2_LIMIT_POSITION,   /* min .. max position limit (52, 48) in position mode */
	/* The AX-12A's Moving Speed (e-manual): 0..1023 in joint mode; the
	 * static range, bit 10 the direction, in wheel mode (both angle limits
	 * 0, the model's DXL2_CAP_WHEEL_BY_ANGLE_LIMITS) */
	DXL2_LIMIT_JOINT_MODE,
};

struct dxl2_reg {
	const char *name;      /* lower_snake_case */
	uint16_t addr;
	uint8_t size;          /* 1, 2 or 4 bytes */
	bool is_signed;
	enum dxl_access access;
	enum dxl_area area;
	int32_t min, max;      /* static write range (the widest the manual allows) */
	bool has_default;
	int32_t def;           /* factory default when has_default */
	enum dxl2_unit unit;
	enum dxl2_limit limit;
	uint16_t lim_addr;     /* DXL2_LIMIT_SYMMETRIC: the limit register */
	const char *desc;
};

/* A model's datasheet (its e-manual page's specification table): the
 * daemon's torque actuation, its supply check, `dxl doctor` and the
 * simulator's motors all start from these numbers. */
struct dxl2_datasheet {
	double stall_torque_nm;        /* at DXL2_REF_VOLTAGE */
	double stall_current_a;
	double no_load_speed_rpm;
	double gear_ratio;
	/* The motor rotor's own inertia (kg·m²): no page publishes it; the
	 * simulator's estimate for the motor's class (sim-bridge/PHYSICS.md §5),
	 * seen through the gearbox as rotor × ratio². */
	double rotor_inertia;
	double rated_min_v, rated_rec_v, rated_max_v;   /* the supply it is rated for, and the recommended one */
};

/* What a model can do beyond reading and writing its table: asked of the
 * descriptor (dxl2_model_can), never of the protocol or the model number. */
enum dxl2_cap {
	DXL2_CAP_HWERR_STATUS = 1u << 0,  /* Hardware Error Status (70), the status packet's alert bit */
	DXL2_CAP_WATCHDOG     = 1u << 1,  /* Bus Watchdog (98) */
	DXL2_CAP_REBOOT       = 1u << 2,  /* the REBOOT instruction */
	DXL2_CAP_OPMODE       = 1u << 3,  /* Operating Mode (11): the opmodes field */
	/* no operating mode: both angle limits 0 make it a wheel (endless
	 * rotation, Moving Speed the output), else a joint */
	DXL2_CAP_WHEEL_BY_ANGLE_LIMITS = 1u << 4,
	DXL2_CAP_FACTORY_RESET_KEEP = 1u << 5,  /* FACTORY_RESET's keep-ID / keep-ID-and-baud forms */
	DXL2_CAP_INDIRECT     = 1u << 6,  /* the indirect areas (DXL2_X_INDIRECT_*) */
};

/* One servo model: everything a program needs to know of it. A new model
 * is one of these and its control table's rows (dxl2_table.c): what differs
 * between models in the code's behaviour is asked of these fields
 * (protocol, caps, current_sensing, opmodes, the registers the table has),
 * never of the model number. */
struct dxl2_model {
	uint8_t protocol;      /* 1: Protocol 1.0 (AX-12A), 2: Protocol 2.0 (X series) */
	uint16_t number;
	const char *name;      /* "XL430-W250" */
	const struct dxl2_reg *regs;
	size_t nregs;
	uint32_t caps;         /* enum dxl2_cap bits */
	uint32_t opmodes;      /* bit n set: Operating Mode n exists */
	/* Present Current (126), Current Limit (38), Goal Current (102) and
	 * current control (mode 0): the XM series; without it 126 is Present
	 * Load and the only torque drive is PWM control. */
	bool current_sensing;
	struct dxl2_datasheet sheet;
	long factory_baud;     /* Baud Rate 1 */
	uint8_t firmware;      /* the firmware a simulated one reports */
	/* The first firmware that answers Fast Sync/Bulk Read (0 never): a
	 * servo's own property, beside the protocol's DXL_CAP_FAST_READ. */
	uint8_t fast_read_firmware;
};

/* The models known, in a fixed order (0 .. dxl2_model_count() - 1): the
 * AX-12A first, then the X series. */
size_t dxl2_model_count(void);
const struct dxl2_model *dxl2_model_at(size_t i);
/* The names of one protocol's models (0: all) for messages,
 * "XL430-W250, XM430-W350, ..." into buf. */
char *dxl2_model_names(int protocol, char *buf, size_t cap);
bool dxl2_model_can(const struct dxl2_model *m, enum dxl2_cap cap);
/* Whether a servo of this model on this firmware (register 6, or a PING's
 * third byte) answers Fast Sync Read and Fast Bulk Read; false for NULL. */
bool dxl2_model_fast_read(const struct dxl2_model *m, uint8_t firmware);

/* NULL when unknown. Model numbers are unique across ROBOTIS's servos
 * (register 0 on either protocol); names compare case-insensitively
 * ("xm430-w350"). dxl2_model_find: the model of that number speaking that
 * protocol, as a reply on that protocol names it. */
const struct dxl2_model *dxl2_model_by_number(uint16_t number);
const struct dxl2_model *dxl2_model_find(int protocol, uint16_t number);
const struct dxl2_model *dxl2_model_by_name(const char *name);
/* The protocol's first model in the list: the addresses every model of it
 * shares (what a tool reads before it knows the model); NULL for none. */
const struct dxl2_model *dxl2_model_first(int protocol);
/* The no-load speed of a datasheet in rad/s. */
double dxl2_sheet_no_load_rad_s(const struct dxl2_datasheet *s);
/* A register by name ('-' = '_', case-insensitive), a short alias
 * ("position", "velocity", "goal", "torque", ...) or an address ("132",
 * "0x84"). NULL if unknown for this model. */
const struct dxl2_reg *dxl2_reg_lookup(const struct dxl2_model *m, const char *name_or_addr);
/* The register starting at addr; NULL inside a register or in a gap. */
const struct dxl2_reg *dxl2_reg_at(const struct dxl2_model *m, uint16_t addr);

/* The indirect areas: slot n (1..DXL2_X_INDIRECT_COUNT) of an Indirect Data
 * byte's address, 0 for any other address; the addresses of slot n's
 * Indirect Address register and Indirect Data byte (0 for no such slot). */
int dxl2_indirect_slot(uint16_t addr);
uint16_t dxl2_indirect_address_reg(int n);
uint16_t dxl2_indirect_data_addr(int n);

/* Raw bytes <-> value, sign-extended for signed registers. */
int32_t dxl2_reg_decode(const struct dxl2_reg *r, const uint8_t *bytes);
void dxl2_reg_encode(const struct dxl2_reg *r, int32_t value, uint8_t *bytes);

/* DXL_OK if value may be written: RW, within the static range, and (for
 * Operating Mode) a mode this model has. Else DXL_E_ARG. */
int dxl2_reg_check_write(const struct dxl2_model *m, const struct dxl2_reg *r, long value);
/* The range that applies now, given an image of the servo's control table
 * (`table`, `len` bytes from address 0: the simulator's memory, or what the
 * daemon read): Goal PWM/Current/Velocity within +-their limit register,
 * Goal Position within the position limits in position mode. The static
 * range when the image does not reach the limit register. */
int dxl2_reg_range(const struct dxl2_model *m, const struct dxl2_reg *r, const uint8_t *table,
                   size_t len, int32_t *lo, int32_t *hi);
/* Whether the range that applies now is set by a limit register (Goal
 * PWM/Current/Velocity always, Goal Position in position mode), read from
 * the image: the e-manual's control table prints these ranges as "-PWM
 * Limit(36) ~ PWM Limit(36)" and so on, so a value outside them, even one
 * beyond the largest value the limit register takes, "exceeds the limit
 * value": the data limit error (6). A register whose range is printed as
 * numbers answers the data range error (4) instead. */
bool dxl2_reg_limit_binds(const struct dxl2_model *m, const struct dxl2_reg *r, const uint8_t *table, size_t len);
/* dxl2_reg_check_write and that range: the servo would answer a data limit
 * error (6) for a value this refuses where dxl2_reg_limit_binds, else the
 * data range error (4). */
int dxl2_reg_check_write_live(const struct dxl2_model *m, const struct dxl2_reg *r, long value,
                              const uint8_t *table, size_t len);
/* "2048 (180.0 deg)"-style text with units. Returns buf. */
char *dxl2_reg_format(const struct dxl2_reg *r, int32_t raw, char *buf, size_t cap);

/* ---- unit conversions -------------------------------------------------------
 * Angles in radians relative to the centre (2048), positive CCW (towards
 * larger raw values, the servo's default Drive Mode); speeds in rad/s. */
#define DXL2_POS_CENTER     2048
#define DXL2_POS_MAX        4095
#define DXL2_POS_PER_REV    4096
#define DXL2_PI             3.14159265358979323846
#define DXL2_POS_RAD_PER_UNIT (2.0 * DXL2_PI / DXL2_POS_PER_REV)
#define DXL2_VELOCITY_RPM_PER_UNIT 0.229
#define DXL2_VELOCITY_RAD_S_PER_UNIT (DXL2_VELOCITY_RPM_PER_UNIT * 2.0 * DXL2_PI / 60.0)
#define DXL2_CURRENT_A_PER_UNIT 0.00269
#define DXL2_PWM_PER_UNIT   0.00113   /* fraction of full PWM */

double dxl2_pos_to_rad(int32_t raw);
/* Nearest position in 0..4095 (position control mode); NaN gives the centre. */
int32_t dxl2_rad_to_pos(double rad);
double dxl2_velocity_to_rad_s(int32_t raw);
/* Nearest raw velocity clamped to +-limit (Velocity Limit, 44); NaN gives 0. */
int32_t dxl2_rad_s_to_velocity(double rad_s, int32_t limit);
double dxl2_current_to_amps(int32_t raw);
/* Nearest raw current clamped to +-limit (Current Limit, 38); NaN gives 0. */
int32_t dxl2_amps_to_current(double amps, int32_t limit);
double dxl2_load_to_fraction(int32_t raw);    /* XL430 Present Load, 0.1 % */
double dxl2_pwm_to_fraction(int32_t raw);     /* 0.113 %: 885 = 100 % */
double dxl2_voltage_to_volts(int32_t raw);
/* Baud Rate (8) <-> bps: 0 9600, 1 57600, 2 115200, 3 1 M, 4 2 M, 5 3 M,
 * 6 4 M, 7 4.5 M; -1 for other values. */
long dxl2_baud_from_reg(uint8_t v);
/* The register value whose rate is within 3 % of bps; DXL_E_ARG if none. */
int dxl2_baud_to_reg(long bps, uint8_t *v);
unsigned dxl2_return_delay_us(uint8_t v);     /* 2 us a unit */
unsigned dxl2_watchdog_ms(uint8_t v);         /* 20 ms a unit, 0 = off */

#endif
