/*
 * cycle.h — one control cycle's bus work, a state machine the daemon's
 * poll() loop drives without ever blocking on the bus:
 *
 *   READ(36, n) of every joint ─→ CYC_CONTROL: the daemon applies commands
 *   and runs the control step ─→ SYNC_WRITE of the goals (or duties) ─→ the
 *   controller's register writes, one at a time, while the period allows ─→
 *   every CYC_READBACK_US (50 ms), in a cycle where it ends in time
 *   (CYC_READBACK_WAIT_US at most), one joint's block read back
 *   (ctl_readback) ─→ CYC_DONE. Writes never starve:
 *   when the reads leave no room for them cycle after cycle, one is sent
 *   before the reads (CYC_STARVED_CYCLES).
 *
 * It owns only its progress through those steps. Readings go to the
 * controller (ctl_measure, ctl_readback); writes come from it, one at a time
 * (ctl_take_write), and every one taken is reported back (ctl_write_result):
 * acknowledged, or failed — which includes a write cut off by the next tick,
 * as it may or may not have reached the servo. Time comes only from the
 * bus's clock seam (bus_io.now_us), so tests drive it with a fake transport
 * and a fake clock (tests/unit/test_daemon_cycle.c).
 *
 * Late replies: each cycle asks for n = 6 or 8 bytes, alternately (8 adds
 * voltage and temperature). A reply that arrives a whole period late — its
 * request cut off by the tick — finds the next cycle asking the same servo
 * for the other length and is refused as the wrong length, instead of being
 * taken for this cycle's reading.
 *
 * On a Protocol 2.0 bus (X series) the reads are one SYNC_READ of every
 * joint's present block (servo_model.h: 10 or 21 bytes alternately, for the
 * same reason), answered by one status packet per servo in the request's
 * order; a servo that does not answer is stale as on 1.0 (the bus names it:
 * bus_multi_failed) and the others' readings are used. The goals go out in
 * one SYNC_WRITE, the controller's writes (and REBOOTs) one at a time, and
 * the read-back alternates the model's blocks (RAM, EEPROM); a joint whose
 * status raised the alert has its RAM block read at once (ctl_readback_due).
 *
 * Where every servo answers it (cyc_set_fast_read, decided at start-up from
 * the servos' models and firmware: setup_fast_read), the read is one Fast
 * Sync Read instead: one status packet for all servos, one return delay and
 * one header for the lot. Its parts are read as the SYNC_READ's slots. A
 * servo that stops answering takes the whole packet with it (the chain stops
 * at its part): after CYC_FAST_FAILS_US of cycles in a row without a single
 * reading (at least CYC_FAST_FAILS_MAX) the cycle goes back to SYNC_READ, so
 * the other servos are read again, and says so (the notice hook). Every
 * CYC_FAST_RETRY_US after that, where the plain read read every servo, one
 * cycle tries the Fast Sync Read again: read whole, it is kept (said).
 *
 * Where start-up mapped the present values into every servo's indirect
 * block and read the map back (cyc_set_indirect, setup_indirect), the
 * SYNC_READ or Fast Sync Read asks for that block instead (servo_model.h,
 * sm_read: 10 or 13 bytes at 224 where the direct block is 10 or 21 at
 * 126): the same values, decoded by the same decoder. A REBOOT the cycle
 * sends ends it: the e-manual lists the Indirect Address registers in the
 * RAM area, so a servo may come back with the factory map, and the cycle
 * reads the registers where they lie from then on (said by the notice hook).
 */
#ifndef UNDULATE_DAEMON_CYCLE_H
#define UNDULATE_DAEMON_CYCLE_H

#include <stdbool.h>
#include <stdint.h>

#include "bus.h"
#include "control.h"
#include "dxl2.h"
#include "servo_model.h"

/* Read-back of one joint every CYC_READBACK_US, round-robin: each of two
 * joints every 0.1 s (a servo reset is found within that), for 340 µs of bus
 * time at 1 Mbps; every 5 cycles at 100 Hz, every 50 at 1 kHz. A time, not a
 * count of cycles: at 1 kHz a read-back every 5 cycles was 200 transactions
 * a second, each one a cycle that did not fit the period. */
#define CYC_READBACK_US 50000
/* A read-back is begun only where it ends on the wire (request, reply,
 * return delay) before CYC_LATE_SHARE of the period: begun later it runs
 * past the next tick, is cut off, and its reply meets the next cycle's
 * request on the line. One that has found no room for this long is begun
 * anyway, where the old rule allows (before CYC_LATE_SHARE): a period too
 * short for any read-back still finds a reset servo within about a second. */
#define CYC_READBACK_WAIT_US 1000000
/* Past this share of the period no new write or read-back is begun: a
 * transaction cut off by the next tick leaves its reply on the line. */
#define CYC_LATE_SHARE 0.7

enum cyc_status {
	CYC_PENDING,    /* waiting for the bus: poll its fd until cyc_deadline_us() */
	CYC_CONTROL,    /* the readings are in: run the control step, then cyc_resume() */
	CYC_DONE,       /* the cycle's bus work is over */
	CYC_LOST,       /* the port failed (cyc.lost says how): the cycle is over */
};

enum cyc_phase { CYC_IDLE, CYC_WRITE_FIRST, CYC_READ, CYC_CONTROL_STEP, CYC_WRITES, CYC_READBACK };

/* A bus so slow that the reads fill CYC_LATE_SHARE of every period would
 * starve the writes (a LIMP's torque-off among them): after this many cycles
 * in a row ended with writes waiting, the next cycle sends one write before
 * its reads. */
#define CYC_STARVED_CYCLES 2
/* Fast Sync Reads in a row that read nobody before the plain SYNC_READ is
 * used again: CYC_FAST_FAILS_US of them, at least CYC_FAST_FAILS_MAX cycles.
 * A lost servo then costs the others 30 ms (3 cycles at 100 Hz, 30 at
 * 1 kHz), and a single damaged packet, or a stall of the machine of a few
 * milliseconds at 1 kHz, changes nothing. */
#define CYC_FAST_FAILS_MAX 3
#define CYC_FAST_FAILS_US 30000
/* Back on SYNC_READ, the Fast Sync Read is tried again this often, for one
 * cycle, where the last plain read read every servo (a servo back after a
 * power loss or a loose cable): one cycle's readings at stake every 10 s,
 * and a robot that lost a servo for a moment does not pay a header and a
 * return delay a servo until its next start. */
#define CYC_FAST_RETRY_US 10000000

struct cyc_hooks {
	void *ctx;
	/* a failed transaction (counted here too); the daemon logs it, rate-limited.
	 * status is DXL_OK when the servo answered but refused (`what` says so). */
	void (*bus_error)(void *ctx, uint8_t id, const char *what, int status);
	/* a change of how the cycle reads (Fast Sync Read given up), once: not
	 * rate-limited with the errors (NULL: none) */
	void (*notice)(void *ctx, const char *text);
};

struct cyc {
	struct bus *bus;
	struct ctl *ctl;
	struct cyc_hooks hooks;
	uint64_t period_us;
	enum cyc_phase phase;
	size_t idx;                   /* joint being read */
	bool write_on_wire;           /* a write taken from the controller is pending */
	size_t readback_joint;
	size_t readback_block;        /* the model's read-back block of the round-robin */
	size_t readback_now_joint, readback_now_block;   /* the read-back on the wire */
	bool readback_owed;           /* a read-back of the round-robin is due */
	uint64_t readback_owed_at;    /* since this cycle (count) */
	uint64_t count;               /* cycles started */
	uint8_t read_len;             /* this cycle's READ length, 6 or 8 (2.0: the model's, 10 or 21) */
	/* Protocol 2.0: this cycle's SYNC_READ (or Fast Sync Read) and its replies */
	bool fast_read;               /* the read is a Fast Sync Read (cyc_set_fast_read) */
	bool indirect;                /* the read is of the indirect block (cyc_set_indirect) */
	int fast_fails;               /* Fast Sync Reads in a row that read nobody */
	int fast_fails_max;           /* CYC_FAST_FAILS_US in cycles of this period */
	bool fast_able;               /* every servo answers it (cyc_set_fast_read): worth a try again */
	bool fast_trial;              /* this cycle's Fast Sync Read is a try after a fallback */
	uint64_t fast_retry_at;       /* the cycle count of the next try */
	bool due_waiting;             /* a read-back wanted at once waits for room (cyc_readback_may) */
	uint64_t due_since;           /* since this cycle count */
	uint64_t readback_every;      /* CYC_READBACK_US in cycles of this period, at least 1 */
	struct bus_multi multi;
	uint8_t multi_buf[CFG_MAX_JOINTS * 32];
	uint64_t start_us;            /* this cycle's start (the tick) */
	uint64_t control_start_us;
	uint64_t read_at_us[CFG_MAX_JOINTS];   /* when each joint's last reply arrived */
	int lost;                     /* dxl_status of CYC_LOST */
	/* this cycle's figures (valid at CYC_DONE / CYC_LOST) */
	double bus_us, control_us;
	int starved;                  /* cycles in a row that ended with writes waiting */
	/* counters */
	long long errors, cut_off, deferred, readbacks, writes_first, fast_fallbacks, indirect_fallbacks;
	long long fast_retries;       /* Fast Sync Read taken up again after a fallback */
	long long readbacks_waiting;  /* cycles a read-back due waited for room */
	long long readbacks_forced;   /* read-backs begun without room, after CYC_READBACK_WAIT_US */
	/* a robot on several buses (cyc_set_bus): the joints on this one, in the
	 * robot's order; without it every joint of the controller */
	bool own;
	size_t joint[CFG_MAX_JOINTS];
	size_t n;
};

void cyc_init(struct cyc *y, struct bus *bus, struct ctl *ctl, uint64_t period_us, const struct cyc_hooks *hooks);
/* Start a cycle (the timer ticked). The previous cycle must be over (see
 * cyc_cut). Returns PENDING, CONTROL, DONE or LOST. */
enum cyc_status cyc_start(struct cyc *y);
/* The bus fd is readable, or its deadline passed: drive the pending
 * transaction and whatever follows it. */
enum cyc_status cyc_step(struct cyc *y);
/* After CYC_CONTROL, once the control step ran: send its outputs. */
enum cyc_status cyc_resume(struct cyc *y);
/* Read by Fast Sync Read (on: every servo answers it, and the protocol has
 * it) or by SYNC_READ, from the next cycle on. */
void cyc_set_fast_read(struct cyc *y, bool on);
/* A robot on several buses: this cycle drives the joints of bus `bus` only
 * (ctl_on_bus) — their reads, their share of the SYNC_WRITE, the writes and
 * read-backs of their servos — and leaves the others to their buses' cycles.
 * The control step stays the robot's: the daemon runs it once every bus's
 * cycle has reached CYC_CONTROL. */
void cyc_set_bus(struct cyc *y, size_t bus);
/* Read the present values from every servo's indirect block (on: start-up
 * mapped and verified it on every servo, setup_indirect) or from the
 * registers where they lie, from the next cycle on. */
void cyc_set_indirect(struct cyc *y, bool on);
/* What this cycle's read asks for (its first joint's model: one SYNC_READ,
 * one address and length for every servo on its bus). */
struct sm_read cyc_read_of(const struct cyc *y);
/* A cycle is under way (not idle). */
bool cyc_busy(const struct cyc *y);
/* End the cycle under way now: the next tick came first, or the daemon stops
 * or lost the port. A write on the wire is reported failed (sent again). */
void cyc_cut(struct cyc *y);
/* The deadline of the pending transaction (monotonic µs), 0 if none. */
uint64_t cyc_deadline_us(const struct cyc *y);

#endif
