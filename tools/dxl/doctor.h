/*
 * doctor.h — `dxl doctor`, the first-run hardware check: what decides whether
 * undulated's 100 Hz loop works on this bus, one line per check — OK, WARN or
 * FAIL, the measured value, and for anything not OK the fix in words.
 *
 * The verdicts are pure (doctor_checks.c): values in, one line out, so every
 * threshold is unit-tested (tests/unit/test_dxl_doctor.c). The bus work that
 * gathers the values and times undulated's own cycle is doctor.c.
 */
#ifndef UNDULATE_DXL_DOCTOR_H
#define UNDULATE_DXL_DOCTOR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "bus.h"
#include "daemon/config.h"
#include "port.h"

/* SKIP: a check that could not run (nothing to time); counted apart, it
 * neither passes nor fails. */
enum dr_level { DR_OK, DR_WARN, DR_FAIL, DR_SKIP };
const char *dr_level_name(enum dr_level level);

/* One line's text: the value, the why and the fix of a long check fit. */
#define DR_TEXT_MAX 640
struct dr_verdict {
	enum dr_level level;
	char text[DR_TEXT_MAX];
};
/* Set a verdict; dr_add appends (a line cut at DR_TEXT_MAX stays terminated).
 * The checks of both protocols (doctor_checks.c, doctor_checks2.c) use them. */
__attribute__((format(printf, 3, 4)))
void dr_set(struct dr_verdict *v, enum dr_level level, const char *fmt, ...);
__attribute__((format(printf, 2, 3)))
void dr_add(struct dr_verdict *v, const char *fmt, ...);

/* The two blocks read from every servo: EEPROM 0..18 (model .. alarm
 * shutdown) and RAM 24..43 (torque enable .. present temperature; the same
 * block undulated reads back in its slow round-robin). */
#define DR_EEPROM_LEN 19
#define DR_RAM_ADDR 24
#define DR_RAM_LEN 20

/* What one servo reported. */
struct dr_servo {
	uint8_t id;
	bool answered;               /* a PING */
	int ping_status;             /* the last PING's dxl_status (DXL_OK when answered) */
	bool read;                   /* both blocks (status return level >= 1) */
	uint16_t model;
	uint8_t firmware;
	uint8_t return_delay;        /* register value, 2 us a unit */
	uint16_t cw_limit, ccw_limit;
	uint8_t temperature_limit;   /* °C */
	uint8_t min_voltage, max_voltage;   /* 0.1 V */
	uint16_t max_torque;
	uint8_t status_return_level;
	uint8_t alarm_led, alarm_shutdown;
	uint8_t torque_enable;
	uint16_t torque_limit;
	uint8_t voltage;             /* present, 0.1 V */
	uint8_t temperature;         /* present, °C */
	uint8_t errbits;             /* OR of the error bytes of its replies */
};
void dr_servo_decode(struct dr_servo *s, const uint8_t eeprom[DR_EEPROM_LEN], const uint8_t ram[DR_RAM_LEN]);

/* What the fixes name. */
struct dr_context {
	const char *port;            /* for "dxl --port PORT ..." */
	const char *ids;             /* the servos a `dxl setup` should name: "1 2" */
	bool any_torque_on;          /* a servo had torque on (setup --yes makes it limp) */
	long baud;
	double period_ms;
	int protocol;                /* 1 or 2: which cycle the baud line prices */
	unsigned read_len2;          /* 2.0: the SYNC_READ's bytes a servo (DR2_READ_LEN...) */
};

/* ---- the bus ------------------------------------------------------------------------ */
struct dr_adapter {
	const char *tty;             /* the device's name below /dev: "ttyUSB0", "pts/3" */
	bool is_pty;
	bool listed;                 /* found by port enumeration (info valid) */
	struct port_info info;
	struct port_latency lat;     /* after port_open()'s check, which lowers as undulated does */
	const char *sysfs_root;      /* where latency_timer is, for the fix */
	enum port_rs485 rs485;
	bool echo;
};
void dr_check_adapter(const struct dr_adapter *a, struct dr_verdict *v);

/* Replies' lateness (bus_reply_lateness) against what undulated's timeouts
 * allow for it: the adapter latency they assume plus bus_margin_us. */
struct dr_latency {
	bool measured;
	uint8_t id;
	struct bus_lateness late;
	long allowed_us;
	bool ftdi;                   /* the adapter has a latency timer (the fix is there) */
	unsigned njoints;
};
/* Lateness that costs nothing worth a word: an FTDI adapter at 1 ms shows
 * about 1 ms; a pty on a busy machine a few hundred µs. */
#define DR_LATE_WARN_US 1500
/* Past this a READ per joint per cycle eats the period: two joints at 3 ms
 * are 6 of the 10 ms. */
#define DR_LATE_FAIL_US 3000
void dr_check_latency(const struct dr_latency *l, struct dr_verdict *v);

/* The wiring against the echo setting: our own requests read back with echo
 * cancelling off (a single-wire wiring taken for replies), or bytes that are
 * not our request where an echo is expected. False (no line) when neither. */
bool dr_check_echo(bool echo, uint32_t unexpected_echoes, uint32_t echo_errors, struct dr_verdict *v);

/* The wire time of one cycle of undulated's for n servos at baud: a READ of
 * 8 bytes (answered by 14) per servo and a SYNC_WRITE of the goals, in µs. */
double dr_cycle_wire_us(unsigned nservos, long baud);
/* Protocol 2.0's cycle (the X series): one SYNC_READ of read_len bytes from
 * every servo — present velocity and position (128, 8 bytes), with the
 * present current before them on the XM430 (126, 10 bytes) — and one
 * SYNC_WRITE of 4-byte goal positions: (14 + N) + N·(11 + read_len) +
 * (14 + 5·N) bytes, stuffing not counted (the floor). In µs. */
#define DR2_READ_LEN 8
#define DR2_READ_LEN_CURRENT 10
double dr2_cycle_wire_us(unsigned nservos, unsigned read_len, long baud);
void dr_check_baud(const struct dr_context *c, unsigned asked, unsigned answered, struct dr_verdict *v);

/* ---- each servo ------------------------------------------------------------------------ */
void dr_check_model(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* Appends the fix `dxl [PROTOCOL_OPT]--port P setup IDS --yes (WHAT)`:
 * PROTOCOL_OPT "" for the AX-12, "--protocol 2 " for the X series. */
void dr_setup_fix(struct dr_verdict *v, const struct dr_context *c, const char *protocol_opt, const char *what);
void dr_check_return_delay(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
void dr_check_status_level(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* The AX-12A runs on 9..12 V (ROBOTIS: recommended 11.1 V); torque and speed
 * scale with it. In the register's 0.1 V, so that 12.6 V is 126, not a
 * rounding away from a warning. A full 3S battery is 12.6 V. */
#define DR_DECIVOLTS_MIN 90
#define DR_DECIVOLTS_LOW 100
#define DR_DECIVOLTS_MAX 126
void dr_check_voltage(const struct dr_servo *s, struct dr_verdict *v);
/* Within this many °C of its limit a servo is warned about: a gait heats it
 * further, and at the limit it shuts down (if the alarm says so). */
#define DR_TEMP_MARGIN_C 10
void dr_check_temperature(const struct dr_servo *s, struct dr_verdict *v);
/* The servo's angle limits against the configured joint's (neutral + limits,
 * as setup_joint_limits converts them). */
void dr_check_limits(const struct dr_servo *s, const struct cfg *cfg, size_t joint, const struct dr_context *c,
                     struct dr_verdict *v);
/* Alarm shutdown: overheating and overload protect the motor (the factory's
 * 36); voltage, angle-limit, range, checksum or instruction switch torque
 * off for a sagging battery or one damaged packet. */
#define DR_SHUTDOWN_WANT (DXL_ERRBIT_OVERHEAT | DXL_ERRBIT_OVERLOAD)
void dr_check_alarms(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
void dr_check_torque(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* False (no line) when its replies carried no error bit. */
bool dr_check_errbits(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);

/* ---- each servo, Protocol 2.0 (doctor_checks2.c) -------------------------------------------
 * One READ of addresses 0..147 (model number .. present temperature) per servo. */
#define DR2_IMAGE_LEN 148
struct dr2_servo {
	uint8_t id;
	uint16_t model;
	uint8_t firmware;
	uint8_t return_delay;        /* 2 us a unit */
	uint8_t operating_mode;
	uint8_t temperature_limit, temperature;   /* °C */
	uint16_t max_voltage, min_voltage, voltage;   /* 0.1 V */
	int32_t max_position, min_position;
	uint8_t shutdown;            /* hardware error bits that switch torque off */
	uint8_t torque_enable;
	uint8_t status_return_level;
	uint8_t hwerr;               /* Hardware Error Status (70) */
	uint8_t bus_watchdog;        /* 20 ms a unit; 0 off; 255 (-1): it fired */
	uint16_t pwm_limit;          /* PWM Limit (36): Goal PWM's ceiling, undulated's torque limit */
	uint8_t err;                 /* OR of the ERR fields of its replies */
};
void dr2_servo_decode(struct dr2_servo *s, const uint8_t mem[DR2_IMAGE_LEN]);
/* The supply each model is made for (e-manual, "Specifications"): the
 * XL430-W250 6.5..12.0 V (recommended 11.1 V), the XM430-W350 10.0..14.8 V
 * (recommended 12.0 V). False for a model not in the tables. */
bool dr2_model_volts(uint16_t model, double *lo, double *rec, double *hi);
void dr2_check_model(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v);
void dr2_check_return_delay(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v);
void dr2_check_status_level(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v);
void dr2_check_voltage(const struct dr2_servo *s, struct dr_verdict *v);
void dr2_check_temperature(const struct dr2_servo *s, struct dr_verdict *v);
/* Operating mode 3 (position): the servo holds its limits and takes goal positions. */
void dr2_check_mode(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* Position limits (52, 48) against the configured joint's, in the X
 * series' 4096 a turn. */
void dr2_check_limits(const struct dr2_servo *s, const struct cfg *cfg, size_t joint, const struct dr_context *c,
                      struct dr_verdict *v);
void dr2_check_hwerr(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v);
void dr2_check_torque(const struct dr2_servo *s, struct dr_verdict *v);
/* A watchdog shorter than two periods fires at the first late cycle. */
void dr2_check_watchdog(const struct dr2_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* False (no line) when its replies carried no ERR field. */
bool dr2_check_err(const struct dr2_servo *s, struct dr_verdict *v);

/* ---- undulated's cycle, timed ------------------------------------------------------------- */
struct dr_budget {
	unsigned cycles, joints;
	double p50_ms, p99_ms, max_ms;   /* bus time per cycle, as undulated measures it */
	double floor_ms;                 /* median wire floor: the cycles' bytes and return delays */
	double period_ms;
	long long cut_off;               /* cycles still on the bus at the next tick */
	long long errors, transactions;  /* failed transactions (timeouts, bad replies) of all begun */
	const char *skipped;             /* not timed, and why (NULL: timed) */
};
/* Share of transactions failed or cycles cut off that is a warning, and a
 * failure: one in a hundred is a joint holding for a period now and then. */
#define DR_BUDGET_WARN_SHARE 0.01
#define DR_BUDGET_FAIL_SHARE 0.10
void dr_check_budget(const struct dr_budget *b, struct dr_verdict *v);

#endif
