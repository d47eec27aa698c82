/*
 * port_list.c — serial port enumeration through libserialport, with the
 * Dynamixel USB adapters named so a user can tell which port is the bus.
 */
#include <libserialport.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
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

/* Ports looked at by the look-ups below: a robot's computer has a few. */
#define PORT_LOOKUP_MAX 64

/* The listing, on the heap: 64 entries are 24 KiB, too much for a stack
 * that a daemon's start-up shares with its own buffers. NULL when out of memory. */
static struct port_info *port_list_all(int *n)
{
	struct port_info *all = calloc(PORT_LOOKUP_MAX, sizeof *all);

	*n = 0;
	if (all == NULL)
		return NULL;
	*n = port_list(all, PORT_LOOKUP_MAX);
	if (*n > PORT_LOOKUP_MAX)
		*n = PORT_LOOKUP_MAX;
	return all;
}

bool port_find_by_serial(const char *serial, char *path, size_t cap, int *nports)
{
	int n = 0;
	bool found = false;
	struct port_info *all = port_list_all(&n);

	*nports = n < 0 ? 0 : n;
	for (int i = 0; all != NULL && serial != NULL && serial[0] != '\0' && i < n && !found; i++) {
		if (strcmp(all[i].serial, serial) == 0 && strlen(all[i].path) < cap) {
			memcpy(path, all[i].path, strlen(all[i].path) + 1);
			found = true;
		}
	}
	free(all);
	return found;
}

bool port_info_for(const char *path, struct port_info *out)
{
	char want[PATH_MAX], have[PATH_MAX];
	int n = 0;
	bool found = false;

	if (path == NULL || realpath(path, want) == NULL)
		return false;
	struct port_info *all = port_list_all(&n);
	for (int i = 0; all != NULL && i < n && !found; i++) {
		if (realpath(all[i].path, have) != NULL && strcmp(have, want) == 0) {
			*out = all[i];
			found = true;
		}
	}
	free(all);
	return found;
}
