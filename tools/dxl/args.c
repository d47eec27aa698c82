/*
 * args.c — `dxl` command-line parsing. Hand-written rather than getopt_long
 * so that options may follow the command (`dxl read 1 goal --units`) and the
 * parser holds no global state (the tests call it many times).
 */
#include <ctype.h>
#include <string.h>

#include "dxl2.h"
#include "dxl2_table.h"
#include "dxl_table.h"
#include "dxlt.h"
#include "num.h"

/* Baud register values the AX-12 manual lists; `--bauds all` tries these. */
static const uint8_t dxlt_ax12_baud_regs[] = { 1, 3, 4, 7, 9, 16, 34, 103, 207 };
/* The X series' baud register, factory rate (57600) first: 1, 3 (1 M), ... */
static const uint8_t dxlt_x_baud_regs[] = { 1, 3, 2, 4, 5, 6, 7, 0 };

/* Each protocol's rates, as its register values and their meaning. */
static const struct {
	int protocol;
	const uint8_t *regs;
	size_t nregs;
	long (*from_reg)(uint8_t v);
} dxlt_rate_lists[] = {
	{ 1, dxlt_ax12_baud_regs, sizeof dxlt_ax12_baud_regs, dxl_baud_from_reg },
	{ 2, dxlt_x_baud_regs, sizeof dxlt_x_baud_regs, dxl2_baud_from_reg },
};

size_t dxlt_bauds_for(int protocol, long *out, size_t cap)
{
	size_t n = 0;
	for (size_t l = 0; l < sizeof dxlt_rate_lists / sizeof dxlt_rate_lists[0]; l++) {
		if (dxlt_rate_lists[l].protocol != protocol)
			continue;
		for (size_t i = 0; i < dxlt_rate_lists[l].nregs && n < cap; i++)
			out[n++] = dxlt_rate_lists[l].from_reg(dxlt_rate_lists[l].regs[i]);
	}
	return n;
}

int dxlt_parse_id(const char *s, bool allow_broadcast, uint8_t *id)
{
	long v;

	if (num_parse_long(s, 0, allow_broadcast ? DXL_BROADCAST_ID : DXL_MAX_ID, &v) != NUM_OK)
		return -1;
	*id = (uint8_t)v;
	return 0;
}

int dxlt_parse_id_range(const char *s, uint8_t *lo, uint8_t *hi)
{
	char first[8];
	const char *dash = s != NULL ? strchr(s, '-') : NULL;

	if (s == NULL)
		return -1;
	if (dash == NULL) {
		if (dxlt_parse_id(s, false, lo) != 0)
			return -1;
		*hi = *lo;
		return 0;
	}
	if ((size_t)(dash - s) >= sizeof first || dash == s)
		return -1;
	memcpy(first, s, (size_t)(dash - s));
	first[dash - s] = '\0';
	if (dxlt_parse_id(first, false, lo) != 0 || dxlt_parse_id(dash + 1, false, hi) != 0)
		return -1;
	return *lo <= *hi ? 0 : -1;
}

int dxlt_parse_bauds(const char *s, long *out, size_t cap, size_t *n)
{
	char buf[256];
	char *save = NULL;

	*n = 0;
	if (s == NULL || strlen(s) >= sizeof buf)
		return -1;
	if (strcmp(s, "all") == 0) {
		long x[DXLT_MAX_BAUDS];
		*n = dxlt_bauds_for(1, out, cap);
		size_t nx = dxlt_bauds_for(2, x, sizeof x / sizeof x[0]);
		for (size_t i = 0; i < nx && *n < cap; i++) {
			bool seen = false;
			for (size_t k = 0; k < *n; k++)
				seen = seen || out[k] == x[i];
			if (!seen)
				out[(*n)++] = x[i];
		}
		return 0;
	}
	strcpy(buf, s);
	for (char *tok = strtok_r(buf, ",", &save); tok != NULL; tok = strtok_r(NULL, ",", &save)) {
		long v;
		if (*n >= cap || num_parse_long(tok, 1, DXLT_MAX_BAUD, &v) != NUM_OK)
			return -1;
		out[(*n)++] = v;
	}
	return *n > 0 ? 0 : -1;
}

/* ---- options ---------------------------------------------------------------- */

enum dxlt_opt_kind { OPT_FLAG, OPT_VALUE };

struct dxlt_opt {
	const char *name;
	enum dxlt_opt_kind kind;
};

static const struct dxlt_opt dxlt_opts[] = {
	{ "--port", OPT_VALUE },       { "--baud", OPT_VALUE },    { "--echo", OPT_FLAG },
	{ "--latency-us", OPT_VALUE }, { "--timeout-ms", OPT_VALUE }, { "--units", OPT_FLAG },
	{ "--yes", OPT_FLAG },         { "--ids", OPT_VALUE },     { "--bauds", OPT_VALUE },
	{ "--status-level", OPT_VALUE }, { "--help", OPT_FLAG },   { "-h", OPT_FLAG },
	{ "--rs485", OPT_VALUE },      { "--config", OPT_VALUE },  { "--bus", OPT_VALUE },  { "--cycles", OPT_VALUE },
	{ "--protocol", OPT_VALUE },   { "--size", OPT_VALUE },    { "--keep", OPT_VALUE },
	{ "--fast", OPT_FLAG },
};

static const struct dxlt_opt *dxlt_find_opt(const char *arg, size_t len)
{
	for (size_t i = 0; i < sizeof dxlt_opts / sizeof dxlt_opts[0]; i++)
		if (strlen(dxlt_opts[i].name) == len && strncmp(dxlt_opts[i].name, arg, len) == 0)
			return &dxlt_opts[i];
	return NULL;
}

static int dxlt_bad(FILE *err, const char *what, const char *opt, const char *val)
{
	fprintf(err, "dxl: %s %s '%s'\n", what, opt, val != NULL ? val : "");
	dxlt_usage(err);
	return DXLT_EXIT_USAGE;
}

/* An option's number in [min, max]; on failure says which and why. */
static int dxlt_opt_long(FILE *err, const char *opt, const char *val, long min, long max, long *out)
{
	enum num_status st = num_parse_long(val, min, max, out);
	if (st == NUM_OK)
		return DXLT_EXIT_OK;
	fprintf(err, "dxl: %s '%s' is %s (%ld-%ld)\n", opt, val != NULL ? val : "", num_strerror(st), min, max);
	dxlt_usage(err);
	return DXLT_EXIT_USAGE;
}

static int dxlt_apply_opt(struct dxlt_args *a, const char *name, const char *val, FILE *err)
{
	long v;
	int rc = DXLT_EXIT_OK;

	if (strcmp(name, "--port") == 0) {
		a->port_path = val;
	} else if (strcmp(name, "--baud") == 0) {
		rc = dxlt_opt_long(err, name, val, 1, DXLT_MAX_BAUD, &a->baud);
		a->baud_given = true;
	} else if (strcmp(name, "--echo") == 0) {
		a->echo = true;
	} else if (strcmp(name, "--latency-us") == 0) {
		rc = dxlt_opt_long(err, name, val, 0, 1000000, &a->latency_us);
	} else if (strcmp(name, "--timeout-ms") == 0) {
		rc = dxlt_opt_long(err, name, val, 1, 10000, &a->timeout_ms);
	} else if (strcmp(name, "--units") == 0) {
		a->units = true;
	} else if (strcmp(name, "--fast") == 0) {
		a->fast = true;
	} else if (strcmp(name, "--yes") == 0) {
		a->yes = true;
	} else if (strcmp(name, "--ids") == 0) {
		if (dxlt_parse_id_range(val, &a->id_lo, &a->id_hi) != 0)
			return dxlt_bad(err, "bad ID range (want A-B within 0-253) for", name, val);
		a->ids_given = true;
	} else if (strcmp(name, "--bauds") == 0) {
		if (dxlt_parse_bauds(val, a->bauds, DXLT_MAX_BAUDS, &a->nbauds) != 0)
			return dxlt_bad(err, "bad baud list (want N,N,... or all) for", name, val);
		a->bauds_all = strcmp(val, "all") == 0;
	} else if (strcmp(name, "--protocol") == 0) {
		if (val == NULL || (strcmp(val, "1") != 0 && strcmp(val, "2") != 0 && strcmp(val, "1.0") != 0 &&
		                    strcmp(val, "2.0") != 0))
			return dxlt_bad(err, "bad protocol (want 1 or 2) for", name, val);
		a->protocol = val[0] - '0';
	} else if (strcmp(name, "--size") == 0) {
		if (val == NULL || (strcmp(val, "1") != 0 && strcmp(val, "2") != 0 && strcmp(val, "4") != 0))
			return dxlt_bad(err, "bad register size (want 1, 2 or 4 bytes) for", name, val);
		a->size = val[0] - '0';
	} else if (strcmp(name, "--keep") == 0) {
		if (val != NULL && strcmp(val, "id") == 0)
			a->keep = DXL2_RESET_KEEP_ID;
		else if (val != NULL && strcmp(val, "id-baud") == 0)
			a->keep = DXL2_RESET_KEEP_ID_BAUD;
		else
			return dxlt_bad(err, "bad reset option (want id or id-baud) for", name, val);
	} else if (strcmp(name, "--rs485") == 0) {
		if (!port_rs485_parse(val, &a->rs485))
			return dxlt_bad(err, "bad mode (want rts-on-send, rts or rts-after-send, or off) for", name, val);
		a->rs485_given = true;
	} else if (strcmp(name, "--config") == 0) {
		a->config_path = val;
	} else if (strcmp(name, "--bus") == 0) {
		a->bus_name = val;
	} else if (strcmp(name, "--cycles") == 0) {
		rc = dxlt_opt_long(err, name, val, 0, DXLT_DOCTOR_MAX_CYCLES, &a->cycles);
	} else if (strcmp(name, "--status-level") == 0) {
		rc = dxlt_opt_long(err, name, val, 0, 2, &v);
		a->status_level = rc == DXLT_EXIT_OK ? (int)v : a->status_level;
	} else {
		a->help = true;
	}
	return rc;
}

static void dxlt_defaults(struct dxlt_args *a)
{
	memset(a, 0, sizeof *a);
	a->baud = DXLT_DEFAULT_BAUD;
	a->latency_us = -1;
	a->timeout_ms = -1;
	a->status_level = -1;
	a->cycles = -1;
	a->id_lo = 0;
	a->id_hi = DXL_MAX_ID;
	a->keep = DXL2_RESET_ALL;
}

int dxlt_parse_args(int argc, char **argv, struct dxlt_args *a, FILE *err)
{
	bool options_done = false;

	dxlt_defaults(a);
	/* Positionals are compacted to the front of argv[1..]: pos points there. */
	a->pos = argv + 1;
	for (int i = 1; i < argc; i++) {
		const char *arg = argv[i];
		if (!options_done && strcmp(arg, "--") == 0) {
			options_done = true;
			continue;
		}
		/* A negative number is a value (write 1 goal_pwm -300), never an
		 * option: no option starts with a digit or a point. */
		bool negative = arg[0] == '-' && (isdigit((unsigned char)arg[1]) || arg[1] == '.');
		if (options_done || negative || arg[0] != '-' || arg[1] == '\0') {
			if (a->command == NULL)
				a->command = arg;
			else
				a->pos[a->npos++] = argv[i];
			continue;
		}
		const char *eq = strchr(arg, '=');
		size_t len = eq != NULL ? (size_t)(eq - arg) : strlen(arg);
		const struct dxlt_opt *opt = dxlt_find_opt(arg, len);
		if (opt == NULL)
			return dxlt_bad(err, "unknown option", "", arg);
		const char *val = NULL;
		if (opt->kind == OPT_VALUE) {
			if (eq != NULL)
				val = eq + 1;
			else if (i + 1 < argc)
				val = argv[++i];
			else
				return dxlt_bad(err, "missing value for", opt->name, "");
		} else if (eq != NULL) {
			return dxlt_bad(err, "option takes no value:", opt->name, eq + 1);
		}
		int r = dxlt_apply_opt(a, opt->name, val, err);
		if (r != DXLT_EXIT_OK)
			return r;
	}
	return DXLT_EXIT_OK;
}

void dxlt_usage(FILE *f)
{
	fputs("usage: dxl --port PATH [--protocol 1|2] [--baud N] [--echo] [--rs485 MODE] [--latency-us N] "
	      "[--timeout-ms N] COMMAND [ARGS]   (dxl --help for commands)\n", f);
}

void dxlt_help(FILE *f)
{
	char x[160];
	fprintf(f, "dxl — talk to Dynamixel servos on a serial bus: AX-12 (Protocol 1.0), %s\n"
	        "(Protocol 2.0, --protocol 2)\n\n", dxl2_model_names(2, x, sizeof x));
	dxlt_usage(f);
	fputs("\ncommands:\n"
	      "  ports                      list serial ports with USB IDs, marking Dynamixel adapters\n"
	      "  scan [--ids A-B] [--bauds LIST|all]   find servos at every baud, on both protocols\n"
	      "                             unless --protocol says one; each line names its protocol\n"
	      "  ping ID                    ping one servo: model, firmware, round-trip time\n"
	      "  read ID REG [--units]      print a register's raw value (REG: name or address)\n"
	      "  sync-read REG ID... [--fast] [--units]   one SYNC_READ of REG from every servo listed\n"
	      "                             (2.0), a line each: ID VALUE; --fast: one Fast Sync Read\n"
	      "                             (one status packet for all; X430/X540 firmware 45 and later)\n"
	      "  bulk-read ID:REG... [--fast] [--units]   one BULK_READ, each servo its own register\n"
	      "                             (2.0), a line each: ID REG VALUE; --fast: one Fast Bulk Read\n"
	      "  write ID REG VALUE         write a register (checked against the table first; a negative\n"
	      "                             VALUE is a value) and print what the servo holds, read back\n"
	      "  dump ID                    the whole control table, named, with units\n"
	      "  set-id OLD NEW             change a servo's ID (refused if NEW answers)\n"
	      "  set-baud ID BAUD           change a servo's baud rate (bps) and verify it\n"
	      "  torque ID on|off           switch the motor torque\n"
	      "  reset ID --yes [--keep id|id-baud]   factory reset (1.0: ID 1 at 1 Mbps; 2.0: ID 1\n"
	      "                             at 57600 bps, or keeping the ID, or the ID and the baud)\n"
	      "  reboot ID                  restart a servo (2.0 only): clears its hardware error\n"
	      "  setup ID... [--status-level N] [--yes]   prepare servos and adapter for a 100 Hz\n"
	      "                             loop (--yes: turn torque off first; the joint goes limp)\n"
	      "  doctor [ID...] [--config FILE [--bus NAME]] [--cycles N]   the first-run hardware check: adapter,\n"
	      "                             latency, baud, every servo's settings against the\n"
	      "                             configuration, then N (300) of undulated's own cycles timed,\n"
	      "                             holding each joint where it stands; one line per check\n"
	      "                             (OK/WARN/FAIL) with its fix; a robot on several buses\n"
	      "                             is checked a bus at a time (--bus NAME)\n"
	      "\noptions:\n"
	      "  --port PATH        serial device or pty (e.g. /dev/ttyUSB0, /dev/serial/by-id/...)\n"
	      "  --protocol 1|2     Dynamixel Protocol 1.0 (default; AX-12) or 2.0 (X series); registers\n"
	      "                     are named by the model PING returns\n"
	      "  --size 1|2|4       bytes at a raw address on a 2.0 model not in dxl's tables\n"
	      "  --baud N           bus baud rate in bps (default 1000000; an X servo's factory rate is 57600)\n"
	      "  --echo             single-wire wiring: discard our own bytes read back\n"
	      "  --rs485 MODE       on-board UART with a half-duplex buffer on RTS: the kernel's RS-485\n"
	      "                     mode, rts-on-send (or rts) or rts-after-send\n"
	      "  --latency-us N     adapter latency to allow for (default: read the FTDI timer)\n"
	      "  --timeout-ms N     wait about N ms per reply instead of the derived timeout\n"
	      "\nexit codes: 0 ok, 2 usage, 3 port, 4 no reply / bus error, 5 servo error bits\n"
	      "            (in any reply; the bits are named),\n"
	      "            6 refused (ID taken, torque on, ...);\n"
	      "            doctor: 0 all OK, 1 warnings only, 7 a check failed\n", f);
}
