/*
 * fault.h — per-servo fault injection: what happens to a status packet on its
 * way to the controller, and conditions the servo reports. Pure: the random
 * numbers come from the caller's generator state.
 *
 * Text form (scenario [events], control socket, SIM.CMD):
 *   KIND [ARG] [count=N] [prob=P]
 * KIND            ARG (default)        effect
 * no-reply        -                    the servo executes the instruction, its reply is lost
 * bad-checksum    -                    the reply's checksum byte is inverted
 * truncate        bytes cut (half)     the reply loses its last ARG bytes
 * garbage         bytes (8)            ARG random bytes go out just before the reply
 * wrong-id        ID (id + 1)          the reply carries ID ARG (valid checksum)
 * stuck-error     bits (overload=32)   ARG is OR-ed into the reply's error byte (report
 *                                      only: the servo itself does not act on them).
 *                                      On a Protocol 2.0 servo ARG is the ERR field:
 *                                      alert (default) and/or one error number
 *                                      (result-fail, instruction, crc, data-range,
 *                                      data-length, data-limit, access) or 0..255
 * slow            ms (5)               the reply leaves ARG ms late
 * temperature     °C                   the servo measures ARG (can raise overheating)
 * voltage         V                    the servo measures ARG (can raise the voltage bit)
 * count=N limits a reply fault (all but temperature and voltage, which are
 * measurements) to the next N replies, prob=P applies it to a fraction P of
 * replies.
 */
#ifndef UNDULATE_SIM_FAULT_H
#define UNDULATE_SIM_FAULT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

enum sim_fault_kind {
	SIM_FAULT_NO_REPLY,
	SIM_FAULT_BAD_CHECKSUM,
	SIM_FAULT_TRUNCATE,
	SIM_FAULT_GARBAGE,
	SIM_FAULT_WRONG_ID,
	SIM_FAULT_STUCK_ERROR,
	SIM_FAULT_SLOW,
	SIM_FAULT_TEMPERATURE,
	SIM_FAULT_VOLTAGE,
	SIM_FAULT_KINDS
};

struct sim_fault {
	bool active;
	bool has_arg;
	double arg;
	/* stuck-error on a Protocol 2.0 servo: the ERR field to report (bit 7
	 * alert, bits 0-6 an error number), -1 when ARG names 1.0 bits only
	 * (and arg < 0 when it names 2.0 errors only). */
	int err2;
	long remaining;    /* replies left; < 0 = until cleared */
	double prob;       /* 0..1 */
};

struct sim_faults {
	struct sim_fault f[SIM_FAULT_KINDS];
	uint64_t applied;  /* replies altered */
};

/* Most garbage bytes one fault may add before a reply. */
#define SIM_FAULT_MAX_GARBAGE 64
/* Longest slow-reply delay (ms) and count=N. */
#define SIM_FAULT_MAX_SLOW_MS 60000
#define SIM_FAULT_MAX_COUNT 1000000000L

const char *sim_fault_name(enum sim_fault_kind k);
/* Parse "KIND [ARG] [count=N] [prob=P]" (already split into words).
 * Returns 0 or -1 with a message in err. */
int sim_fault_parse(int argc, char **argv, enum sim_fault_kind *kind, struct sim_fault *out,
                    char *err, size_t errcap);
/* Parse an error-bit mask: a number or names joined by '|' or ','
 * ("overload|overheating"). -1 if invalid. */
int sim_fault_parse_bits(const char *text);
/* Parse a Protocol 2.0 ERR field: a number 0..255, or "alert" and/or one
 * error number's name joined by '|' ("alert|data-range"). -1 if invalid. */
int sim_fault_parse_err2(const char *text);
void sim_faults_clear(struct sim_faults *fs);

/* xorshift64* — small, seedable, deterministic across runs. */
uint64_t sim_rand_next(uint64_t *state);
double sim_rand_uniform(uint64_t *state);  /* [0, 1) */

/*
 * Apply the reply faults to one status packet in pkt[0..*len) (cap bytes of
 * room). May shorten, alter or empty it, and may fill garbage[0..*ngarbage)
 * to send first. *extra_delay_ns gets the slow fault's delay. Returns true
 * when any fault changed something.
 */
bool sim_faults_apply(struct sim_faults *fs, uint64_t *rng, uint8_t *pkt, size_t *len,
                      uint8_t *garbage, size_t *ngarbage, int64_t *extra_delay_ns);
/* The same for a Protocol 2.0 status packet (its ERR field, ID and CRC);
 * a changed ERR field is stuffed again, so pkt has cap bytes of room. */
bool sim_faults_apply2(struct sim_faults *fs, uint64_t *rng, uint8_t *pkt, size_t *len, size_t cap,
                       uint8_t *garbage, size_t *ngarbage, int64_t *extra_delay_ns);

#endif
