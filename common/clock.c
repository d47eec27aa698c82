/* clock.c — see clock.h. */
#include "clock.h"

#include <time.h>

/* The virtual clock (lockstep). The only mutable state of this module: the
 * seam clock.h describes, set by one caller (the lockstep client). */
static bool virt;
static uint64_t virt_mono_us;
static int64_t virt_wall_us;

void clock_set_virtual(uint64_t mono_us, int64_t wall_us)
{
	if (virt && mono_us < virt_mono_us)
		return;
	virt = true;
	virt_mono_us = mono_us;
	virt_wall_us = wall_us;
}

bool clock_is_virtual(void) { return virt; }

int64_t clock_wall_us(void)
{
	if (virt)
		return virt_wall_us;
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

uint64_t clock_mono_us(void)
{
	if (virt)
		return virt_mono_us;
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

double clock_mono_s(void)
{
	if (virt)
		return 1e-6 * (double)virt_mono_us;
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
