/*
 * ttyspeed.c — the bit rate the controller set on its end of a pty.
 *
 * A pty moves bytes instantly, but it keeps the termios the controller gave
 * it: reading the rate back lets a simulated bus run at whatever the
 * controller chose (a servo at another rate then hears nothing, as on a real
 * bus). termios2 reports any rate as a number, including the non-standard
 * Dynamixel ones (57 143, 117 647) set with BOTHER.
 *
 * The kernel's <asm/termbits.h> clashes with glibc's <termios.h>: this file
 * includes only the former (as protocol/io/port_baud.c does).
 */
#include <asm/termbits.h>
#include <sys/ioctl.h>

#include "ttyspeed.h"

long sim_tty_speed(int fd)
{
	struct termios2 tio;
	if (ioctl(fd, TCGETS2, &tio) != 0)
		return -1;
	return (long)tio.c_ospeed;
}

int sim_tty_set_speed(int fd, long bps)
{
	struct termios2 tio;
	if (bps <= 0 || ioctl(fd, TCGETS2, &tio) != 0)
		return -1;
	tio.c_cflag &= ~(tcflag_t)CBAUD;
	tio.c_cflag |= BOTHER;
	tio.c_cflag &= ~(tcflag_t)(CBAUD << IBSHIFT);  /* input rate follows output */
	tio.c_ospeed = (speed_t)bps;
	tio.c_ispeed = (speed_t)bps;
	return ioctl(fd, TCSETS2, &tio) == 0 ? 0 : -1;
}
