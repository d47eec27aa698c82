/*
 * clock.h — the two clocks every program here reads: wall-clock time as LCM
 * messages carry it (µs since the epoch), and a monotonic clock for waiting
 * and intervals. One place, so that a program which must take its time from
 * elsewhere (a test, a simulation's virtual time) has one seam to change.
 *
 * Lockstep (common/lockstep.h): a program whose time is the simulator's
 * calls clock_set_virtual() each time that time moves; from the first call
 * on, both clocks read the virtual time and nothing here reads the system's.
 * It is process-wide on purpose: every reader of "now" in the program must
 * agree, and a program runs in one time or the other, never both.
 */
#ifndef UNDULATE_COMMON_CLOCK_H
#define UNDULATE_COMMON_CLOCK_H

#include <stdbool.h>
#include <stdint.h>

/* CLOCK_REALTIME in µs: the utime of LCM messages, signed commands' time. */
int64_t clock_wall_us(void);
/* CLOCK_MONOTONIC in µs and in seconds. */
uint64_t clock_mono_us(void);
double clock_mono_s(void);

/* From now on both clocks read virtual time: monotonic mono_us, wall wall_us.
 * Virtual time never goes back: a smaller value than the last is ignored. */
void clock_set_virtual(uint64_t mono_us, int64_t wall_us);
bool clock_is_virtual(void);

#endif
