/*
 * sdk_common.h — what sdk_p1.c and sdk_p2.c share: the "ok WHAT" / "not ok
 * WHAT: WHY" lines tests/sdk/run.sh turns into TAP, and the last
 * transaction as the SDK saw it, on the protocol SDK_PROTOCOL (1 or 2),
 * whose status error field is called SDK_ERR_NAME ("error byte", "ERR").
 * Included once, by the one file of each client, after dynamixel_sdk.h.
 */
#ifndef UNDULATE_SDK_COMMON_H
#define UNDULATE_SDK_COMMON_H

#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <unistd.h>

static int port;

static void result(bool ok, const char *what, const char *fmt, ...)
{
	char why[300] = "";
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(why, sizeof why, fmt, ap);
	va_end(ap);
	if (ok)
		printf("ok %s\n", what);
	else
		printf("not ok %s: %s\n", what, why);
	fflush(stdout);
}

/* The last transaction: the SDK's result and the servo's error field. */
static int comm(void) { return getLastTxRxResult(port, SDK_PROTOCOL); }
static uint8_t err(void) { return getLastRxPacketError(port, SDK_PROTOCOL); }
static bool good(void) { return comm() == COMM_SUCCESS && err() == 0; }
static const char *said(void)
{
	static char buf[300];
	snprintf(buf, sizeof buf, "%s %s (" SDK_ERR_NAME " 0x%02x)", getTxRxResult(SDK_PROTOCOL, comm()),
	         comm() == COMM_SUCCESS ? getRxPacketError(SDK_PROTOCOL, err()) : "", err());
	return buf;
}

static void ms(int n) { usleep((useconds_t)n * 1000); }

#endif
