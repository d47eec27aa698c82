/*
 * dxlt.h — the `dxl` bus tool as a library, so its tests can run every
 * command in-process against a fake servo and read what it printed.
 */
#ifndef UNDULATE_DXLT_H
#define UNDULATE_DXLT_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "bus.h"
#include "port.h"

/* Exit codes (documented in tools/dxl/README.md). */
enum dxlt_exit {
	DXLT_EXIT_OK = 0,
	DXLT_EXIT_WARN = 1,      /* doctor: warnings, no failure (100 Hz works, with a cost) */
	DXLT_EXIT_USAGE = 2,     /* bad arguments: unknown register, value out of range ... */
	DXLT_EXIT_PORT = 3,      /* cannot open/configure the port, it went away, latency too high */
	DXLT_EXIT_BUS = 4,       /* no reply, bad reply, verification after a write failed */
	DXLT_EXIT_SERVO = 5,     /* the servo answered with error bits set */
	DXLT_EXIT_REFUSED = 6,   /* refused to act: ID taken, torque on during an EEPROM write */
	DXLT_EXIT_FAIL = 7,      /* doctor: at least one check failed */
	DXLT_EXIT_INTERRUPTED = 130, /* doctor: SIGINT/SIGTERM during the timed cycles (128 + SIGINT) */
};

/* Most IDs/bauds a command takes on its command line. */
#define DXLT_MAX_IDS   (DXL_MAX_ID + 1)
#define DXLT_MAX_BAUDS 24
/* Largest rate a command line may name, bps: the X series' top rate (4.5
 * Mbps, baud register 7), so a typo's extra digit is caught here. */
#define DXLT_MAX_BAUD 4500000L
/* The AX-12 factory rate. */
#define DXLT_DEFAULT_BAUD 1000000L
/* Scheduling slack on top of the derived reply timeout (ms): the tool is
 * interactive, a few ms more per missing servo cost nothing, a false "no
 * reply" on a loaded machine costs the user's trust. */
#define DXLT_DEFAULT_SLACK_MS 5
/* The least a one-shot command (ping, read, write, dump ...) waits for its
 * reply, ms: a person asked one servo once, and 50 ms is nothing to them,
 * while a reply held by an adapter (16 ms on an FTDI chip at its default)
 * or by a loaded machine's scheduler (a pty's reader woken late) is still
 * taken. `scan` keeps the derived deadline + DXLT_DEFAULT_SLACK_MS: it asks
 * up to 253 IDs at up to 12 rates, and absent IDs are most of them. */
#define DXLT_ONESHOT_WAIT_MS 50
/* After a one-shot command's reply timed out, how long dxl listens on to
 * tell a late reply (bytes after the deadline: said, with how late) from
 * none (ms): a quarter of a second more before "no reply" costs a person
 * little. */
#define DXLT_LATE_LISTEN_MS 250
/* Cycles `dxl doctor` times by default: 300 at 10 ms are 3 s, enough for a
 * p99 that means something (3 cycles above it). */
#define DXLT_DOCTOR_CYCLES 300
/* At most: 10 000 cycles are 100 s, and their figures are kept in memory. */
#define DXLT_DOCTOR_MAX_CYCLES 10000
/* Settling time after an EEPROM write before talking to the servo again: the
 * AX-12 is busy ≈6 ms per EEPROM byte. */
#define DXLT_EEPROM_SETTLE_US 15000

struct dxlt_args {
	const char *port_path;
	int protocol;            /* --protocol 1|2; 0: not given (1, and scan tries both) */
	int size;                /* --size 1|2|4: a raw address's bytes on a model not in our tables; 0: 1 */
	int keep;                /* --keep for a 2.0 reset: DXL2_RESET_ALL (default), _KEEP_ID, _KEEP_ID_BAUD */
	long baud;               /* --baud, bps */
	bool baud_given;         /* --baud was on the command line (doctor: over the configuration's) */
	bool echo;               /* --echo: single-wire wiring, our bytes come back */
	enum port_rs485 rs485;   /* --rs485: a UART's half-duplex buffer on RTS (port.h) */
	bool rs485_given;
	long latency_us;         /* --latency-us; -1: from the adapter's latency timer */
	long timeout_ms;         /* --timeout-ms; -1: derived + DXLT_DEFAULT_SLACK_MS, at least
	                          * DXLT_ONESHOT_WAIT_MS outside scan */
	bool units;              /* --units */
	bool fast;               /* --fast: sync-read as a Fast Sync Read */
	bool yes;                /* --yes */
	int status_level;        /* --status-level for setup; -1: default */
	uint8_t id_lo, id_hi;    /* --ids A-B */
	bool ids_given;
	const char *config_path; /* --config FILE: undulated's configuration (doctor) */
	const char *bus_name;    /* --bus NAME: the configuration's bus to check (doctor; several buses) */
	long cycles;             /* --cycles N (doctor); -1: DXLT_DOCTOR_CYCLES */
	long bauds[DXLT_MAX_BAUDS];
	size_t nbauds;           /* --bauds LIST; 0: just --baud */
	bool bauds_all;          /* --bauds all: each protocol its own rates */
	bool help;
	const char *command;
	char **pos;              /* the command's positional arguments */
	int npos;
};

/* Parsers for command-line values; each returns 0 or -1 (bad input). Numbers
 * are read by num_parse_long (common/num.h): decimal or 0x hex, never octal. */
int dxlt_parse_id(const char *s, bool allow_broadcast, uint8_t *id);
int dxlt_parse_id_range(const char *s, uint8_t *lo, uint8_t *hi);
/* "1000000,57600", or "all" for every rate either protocol's servos can
 * run at: the AX-12 manual's list, then the X series' (dxlt_bauds_for). */
int dxlt_parse_bauds(const char *s, long *out, size_t cap, size_t *n);
/* The rates `--bauds all` tries on one protocol (1: the AX-12's, 2: the X
 * series'). Returns how many were written (at most cap). */
size_t dxlt_bauds_for(int protocol, long *out, size_t cap);

/* Parse argv (options may come before or after the command). On failure
 * writes one line to err and returns DXLT_EXIT_USAGE. */
int dxlt_parse_args(int argc, char **argv, struct dxlt_args *a, FILE *err);
void dxlt_usage(FILE *f);
void dxlt_help(FILE *f);

/* The whole program: what main() calls. Returns the exit code. */
int dxlt_main(int argc, char **argv, FILE *out, FILE *err);

#endif
