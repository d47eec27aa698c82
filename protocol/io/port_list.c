/*
 * port_list.c — serial port enumeration through libserialport, with the
 * Dynamixel USB adapters named so a user can tell which port is the bus.
 */
#include <libserialport.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "port.h"

/* USB IDs of the adapters people put on a Dynamixel bus. The FTDI IDs are
 * shared with many other FTDI gadgets: a match means "probably". */
static const struct {
	int vid, pid;
	const char *name;
} port_adapters[] = {
	{ 0x0403, 0x6014, "U2D2" },          /* FTDI FT232H */
	{ 0x0403, 0x6001, "USB2Dynamixel" }, /* FTDI FT232R */
	{ 0x16d0, 0x06a7, "USB2AX" },        /* CDC-ACM, no latency timer */
};

const char *port_adapter_name(int vid, int pid)
{
	for (size_t i = 0; i < sizeof port_adapters / sizeof port_adapters[0]; i++)
		if (port_adapters[i].vid == vid && port_adapters[i].pid == pid)
			return port_adapters[i].name;
	return NULL;
}

static void port_info_fill(struct sp_port *sp, struct port_info *info)
{
	const char *name = sp_get_port_name(sp);
	const char *desc = sp_get_port_description(sp);
	int vid = -1, pid = -1;

	memset(info, 0, sizeof *info);
	snprintf(info->path, sizeof info->path, "%s", name != NULL ? name : "");
	snprintf(info->description, sizeof info->description, "%s", desc != NULL ? desc : "");
	info->usb_vid = -1;
	info->usb_pid = -1;
	if (sp_get_port_transport(sp) != SP_TRANSPORT_USB)
		return;
	if (sp_get_port_usb_vid_pid(sp, &vid, &pid) == SP_OK) {
		info->usb_vid = vid;
		info->usb_pid = pid;
		info->adapter = port_adapter_name(vid, pid);
	}
	const char *serial = sp_get_port_usb_serial(sp);
	snprintf(info->serial, sizeof info->serial, "%s", serial != NULL ? serial : "");
}

/* Room for "<root>/class/tty". */
#define PORT_TTY_CLASS_PATH_MAX 512

/* libserialport fails the whole listing when it cannot open /sys/class/tty;
 * a system without that directory has no tty the kernel could name to us. */
static bool port_have_tty_class(void)
{
	char dir[PORT_TTY_CLASS_PATH_MAX];
	struct stat st;
	int len = snprintf(dir, sizeof dir, "%s/class/tty", port_sysfs_root());

	if (len < 0 || (size_t)len >= sizeof dir)
		return true; /* a root we cannot name: let libserialport report */
	return stat(dir, &st) == 0 && S_ISDIR(st.st_mode);
}

int port_list(struct port_info *out, size_t cap)
{
	struct sp_port **ports = NULL;
	int n = 0;

	if (!port_have_tty_class())
		return 0;
	if (sp_list_ports(&ports) != SP_OK)
		return DXL_E_IO;
	for (; ports[n] != NULL; n++)
		if ((size_t)n < cap)
			port_info_fill(ports[n], &out[n]);
	sp_free_port_list(ports);
	return n;
}
