/*
 * port_baud.c — any bit rate on a Linux tty through termios2/BOTHER.
 *
 * Dynamixel rates are 2 000 000 / (v + 1): 1 Mbps and 500 kbps have POSIX
 * constants, 117 647 or 57 143 do not. termios2 carries the rate as a number
 * (c_ospeed with BOTHER). port.c uses the standard constant when there is
 * one (a pty keeps BOTHER as given, and old drivers know only constants).
 * The simulator reads a pty's rate back the same way: whatever its
 * controller set on the other end, standard constant or BOTHER, termios2
 * reports as a number.
 *
 * This file includes the kernel's <asm/termbits.h>, whose struct termios
 * clashes with glibc's <termios.h>: that is why it is on its own.
 */
#include <asm/termbits.h>
#include <errno.h>
#include <sys/ioctl.h>

#include "port.h"

int port_termios2_set_baud(int fd, long baud)
{
	struct termios2 tio;

	if (baud <= 0 || baud > 0x7FFFFFFFL)
		return DXL_E_ARG;
	if (ioctl(fd, TCGETS2, &tio) != 0)
		return DXL_E_IO;
	tio.c_cflag &= ~(tcflag_t)CBAUD;
	tio.c_cflag |= BOTHER;
	/* Input speed bits zero: the input rate follows the output rate. */
	tio.c_cflag &= ~(tcflag_t)(CBAUD << IBSHIFT);
	tio.c_ospeed = (speed_t)baud;
	tio.c_ispeed = (speed_t)baud;
	if (ioctl(fd, TCSETSW2, &tio) != 0) /* W: after queued output drained */
		return DXL_E_IO;
	return DXL_OK;
}

long port_termios2_get_baud(int fd)
{
	struct termios2 tio;

	if (ioctl(fd, TCGETS2, &tio) != 0)
		return DXL_E_IO;
	/* With a Bxxx constant the kernel fills c_ospeed with its rate too. */
	return (long)tio.c_ospeed;
}
