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
#include "dxl2_table.h"
#include "dxl_proto.h"
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
 * (doctor.c adds to a line the checks set.) */
__attribute__((format(printf, 3, 4)))
void dr_set(struct dr_verdict *v, enum dr_level level, const char *fmt, ...);
__attribute__((format(printf, 2, 3)))
void dr_add(struct dr_verdict *v, const char *fmt, ...);

/* What one servo reported, whatever its model: its control table read
 * from address 0 in one READ and decoded by register name through its model
 * descriptor (dxl2_table.h), so a check asks the descriptor what the servo
 * has (dxl2_model_can, or whether its table has the register), never which
 * protocol it speaks. Where two models name one setting differently (the
 * AX-12A's angle limits, the X series' position limits) the record has one
 * field. */
struct dr_servo {
	uint8_t id;
	bool answered;               /* a PING */
	int ping_status;             /* the last PING's dxl_status (DXL_OK when answered) */
	bool read;                   /* its table (status return level >= 1) */
	uint16_t model;
	/* its descriptor; NULL when not in the tables, and then `table` is the
	 * protocol's first model, whose addresses the checks read it with */
	const struct dxl2_model *m, *table;
	uint8_t firmware;
	uint8_t return_delay;        /* register value, 2 us a unit on every model */
	uint8_t status_return_level;
	uint8_t temperature_limit, temperature;      /* °C */
	uint16_t min_voltage, max_voltage, voltage;  /* 0.1 V: limits, present */
	int32_t min_limit, max_limit;   /* CW/CCW angle limits | min/max position limits, raw */
	/* what switches torque off: Alarm Shutdown | Shutdown. Overheating and
	 * overload are the same bits in both (doctor_checks.c asserts it) */
	uint8_t shutdown;
	bool has_alarm_led;          /* the table has Alarm LED (the AX-12A's alarm pair) */
	uint8_t alarm_led;
	uint16_t max_output;         /* Max Torque | PWM Limit: the torque limit's ceiling */
	bool has_torque_limit;       /* the table has Torque Limit (RAM): an alarm zeroes it */
	uint16_t torque_limit;
	uint8_t torque_enable;
	uint8_t operating_mode;      /* DXL2_CAP_OPMODE */
	uint8_t hwerr;               /* DXL2_CAP_HWERR_STATUS: Hardware Error Status */
	uint8_t bus_watchdog;        /* DXL2_CAP_WATCHDOG: 20 ms a unit; 0 off; 255 (-1): it fired */
	uint8_t errbits;             /* OR of the error fields of its replies (the protocol's) */
};
/* The bytes from address 0 the checks read of a model: every row the
 * record takes (model number .. present temperature). */
size_t dr_image_len(const struct dxl2_model *table);
/* Fill s from table's image (len bytes from address 0): m is the model the
 * image's model number names (NULL: not in the tables), table the one read
 * with. Fields whose register the table lacks stay 0. */
void dr_servo_decode(struct dr_servo *s, const struct dxl2_model *m, const struct dxl2_model *table,
                     const uint8_t *image, size_t len);

/* What the fixes name. */
struct dr_context {
	const char *port;            /* for "dxl --port PORT ..." */
	const char *ids;             /* the servos a `dxl setup` should name: "1 2" */
	bool any_torque_on;          /* a servo had torque on (setup --yes makes it limp) */
	long baud;
	double period_ms;
	/* the bus's protocol (its backend table): how undulated's loop reads
	 * (one SYNC_READ where it can, else a READ a servo), what its replies'
	 * error field means; its family's start-up rules (sm_family) name the
	 * option a fix carries and whether an unknown model is refused */
	const struct dxl_proto *proto;
	/* the cycle's bytes a servo (daemon/servo_model.h): the present block
	 * read, the goal written */
	unsigned read_len, write_len;
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

/* The wire time of one cycle of undulated's for n servos at baud, in µs:
 * the present block of read_len bytes read (one SYNC_READ where the protocol
 * has it, else a READ per servo) and one SYNC_WRITE of write_len bytes a
 * servo, each packet's length from the protocol's own encoders, 10 bits a
 * byte, 2.0's byte stuffing not counted (the floor). */
double dr_cycle_wire_us(const struct dxl_proto *p, unsigned nservos, unsigned read_len, unsigned write_len,
                        long baud);
void dr_check_baud(const struct dr_context *c, unsigned asked, unsigned answered, struct dr_verdict *v);

/* ---- each servo ------------------------------------------------------------------------ */
void dr_check_model(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* Appends the fix `dxl [OPT]--port P setup IDS --yes (WHAT)`, OPT the
 * family's (sm_setup.dxl_opt: "" | "--protocol 2 "). */
void dr_setup_fix(struct dr_verdict *v, const struct dr_context *c, const char *what);
void dr_check_return_delay(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
void dr_check_status_level(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* Against the servo's own limit registers, then its model's datasheet
 * (rated_min_v .. rated_max_v, recommended rated_rec_v): below the rated
 * minimum a FAIL, more than DR_VOLTS_BELOW_REC under the recommended
 * supply a WARN (torque and speed scale with it), above the rated maximum
 * by more than DR_VOLTS_OVER_SHARE a WARN: a full 3S battery (12.6 V) on a
 * 12 V servo is 5 % over and is what the robots run on. */
#define DR_VOLTS_BELOW_REC 1.0
#define DR_VOLTS_OVER_SHARE 1.05
void dr_check_voltage(const struct dr_servo *s, struct dr_verdict *v);
/* Within this many °C of its limit a servo is warned about: a gait heats it
 * further, and at the limit it shuts down (if the alarm says so). */
#define DR_TEMP_MARGIN_C 10
void dr_check_temperature(const struct dr_servo *s, struct dr_verdict *v);
/* The servo's angle (AX-12A) or position (X) limits against the configured
 * joint's, converted as undulated's start-up writes them
 * (setup_joint_limits_model: one rule for every model). */
void dr_check_limits(const struct dr_servo *s, const struct cfg *cfg, size_t joint, const struct dr_context *c,
                     struct dr_verdict *v);
/* Alarm Shutdown and Alarm LED, where the table has the pair (the
 * AX-12A): overheating and overload protect the motor (the factory's 36);
 * voltage, angle-limit, range, checksum or instruction switch torque off
 * for a sagging battery or one damaged packet. (The X series' Shutdown is
 * judged with its Hardware Error Status, dr_check_hwerr.) */
#define DR_SHUTDOWN_WANT (DXL_ERRBIT_OVERHEAT | DXL_ERRBIT_OVERLOAD)
void dr_check_alarms(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* Operating Mode (DXL2_CAP_OPMODE): position control (3) holds its limits
 * and takes goal positions. */
void dr_check_mode(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* Hardware Error Status (DXL2_CAP_HWERR_STATUS). */
void dr_check_hwerr(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
void dr_check_torque(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* Bus Watchdog (DXL2_CAP_WATCHDOG): shorter than two periods fires at the
 * first late cycle. */
void dr_check_watchdog(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);
/* False (no line) when its replies carried no error. */
bool dr_check_errbits(const struct dr_servo *s, const struct dr_context *c, struct dr_verdict *v);

/* ---- undulated's cycle, timed ------------------------------------------------------------- */
struct dr_budget {
	unsigned cycles, joints;
	double p50_ms, p99_ms, max_ms;   /* bus time per cycle, as undulated measures it */
	double floor_ms;                 /* median wire floor: the cycles' bytes and return delays */
	double period_ms;
	long long cut_off;               /* cycles still on the bus at the next tick */
	long long errors, transactions;  /* failed transactions (timeouts, bad replies) of all begun */
	const char *skipped;             /* not timed, and why (NULL: timed) */
	char read_by[320];               /* how the cycles read ("Fast Sync Read, as undulated ...") */
};
/* Share of transactions failed or cycles cut off that is a warning, and a
 * failure: one in a hundred is a joint holding for a period now and then. */
#define DR_BUDGET_WARN_SHARE 0.01
#define DR_BUDGET_FAIL_SHARE 0.10
void dr_check_budget(const struct dr_budget *b, struct dr_verdict *v);

#endif
