/*
 * ttyspeed.h — read and set a tty's bit rate as a number (see ttyspeed.c).
 */
#ifndef UNDULATE_SIM_TTYSPEED_H
#define UNDULATE_SIM_TTYSPEED_H

/* The output rate in bps, or -1. */
long sim_tty_speed(int fd);
/* Set both rates to bps (any value, BOTHER). 0 or -1. */
int sim_tty_set_speed(int fd, long bps);

#endif
