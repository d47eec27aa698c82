/*
 * clock.h — the two clocks every program here reads: wall-clock time as LCM
 * messages carry it (µs since the epoch), and a monotonic clock for waiting
 * and intervals. One place, so that a program which must take its time from
 * elsewhere (a test, a simulation's virtual time) has one seam to change.
 */
#ifndef UNDULATE_COMMON_CLOCK_H
#define UNDULATE_COMMON_CLOCK_H

#include <stdint.h>

/* CLOCK_REALTIME in µs: the utime of LCM messages, signed commands' time. */
int64_t clock_wall_us(void);
/* CLOCK_MONOTONIC in µs and in seconds. */
uint64_t clock_mono_us(void);
double clock_mono_s(void);

#endif
