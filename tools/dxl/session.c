/*
 * session.c — what every `dxl` command stands on: the port opened as one
 * bus, its reply timeouts, the transactions that remember each reply's
 * error bits, and the argument helpers. commands.c, registers.c, commands2.c and
 * doctor.c call down into it; it calls none of them.
 */
#include <errno.h>
#include <string.h>
#include <time.h>

#include "dxlt_priv.h"

void dxlt_sleep_us(long us)
{
	struct timespec ts = { us / 1000000L, (us % 1000000L) * 1000L };

	while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
	}
}

/* Servos dxl names but has no table of (their tables differ from the AX-12A's). */
static const struct {
	int protocol;
	uint16_t number;
	const char *name;
} dxlt_untabled[] = { { 1, 18, "AX-18" }, { 1, 300, "AX-12W" } };

const char *dxlt_model_name(int protocol, uint16_t model)
{
	const struct dxl2_model *m = dxl2_model_find(protocol, model);

	if (m != NULL)
		return m->name;
	for (size_t i = 0; i < sizeof dxlt_untabled / sizeof dxlt_untabled[0]; i++)
		if (dxlt_untabled[i].protocol == protocol && dxlt_untabled[i].number == model)
			return dxlt_untabled[i].name;
	return "not in dxl's tables";
}

void dxlt_apply_timing(struct dxlt *t)
{
	struct bus_timing timing = { .baud = port_baud(t->port) };

	if (t->a.timeout_ms > 0) {
		timing.margin_us = (uint32_t)(t->a.timeout_ms * 1000);
	} else {
		/* The servo's return delay is unknown until read: allow the largest
		 * (254 × 2 µs). */
		timing.return_delay_us = 254u * 2u;
		timing.margin_us = DXLT_DEFAULT_SLACK_MS * 1000u;
		if (t->a.latency_us >= 0)
			timing.adapter_latency_us = (uint32_t)t->a.latency_us;
		else if (t->latency.known)
			timing.adapter_latency_us = (uint32_t)t->latency.timer_ms * 1000u;
		/* one-shot commands: at least DXLT_ONESHOT_WAIT_MS, or what the
		 * adapter needs if that is longer (dxlt.h) */
		uint32_t derived = timing.return_delay_us + timing.adapter_latency_us + timing.margin_us;
		if (!t->scanning && derived < DXLT_ONESHOT_WAIT_MS * 1000u)
			timing.margin_us += DXLT_ONESHOT_WAIT_MS * 1000u - derived;
	}
	bus_set_timing(&t->bus, &timing);
}

int dxlt_set_baud(struct dxlt *t, long baud)
{
	if (port_set_baud(t->port, baud) != DXL_OK) {
		fprintf(t->err, "dxl: cannot set %s to %ld bps\n", port_path(t->port), baud);
		return DXLT_EXIT_PORT;
	}
	dxlt_apply_timing(t);
	return DXLT_EXIT_OK;
}

/* A --timeout-ms that would have taken a reply that came after_us after a
 * deadline of waited_us: twice that, in whole 10 ms, within --timeout-ms's
 * bounds. */
static long dxlt_timeout_hint_ms(const struct bus_late *late)
{
	long ms = ((long)late->waited_us + (long)late->after_us) * 2 / 1000;
	ms = (ms + 9) / 10 * 10;
	return ms < 10 ? 10 : ms > 10000 ? 10000 : ms;
}

/* A request to id timed out: listen on a moment (DXLT_LATE_LISTEN_MS) and
 * say whether its reply came late — the servo is there, the wait was too
 * short — or nothing came (wrong baud, wrong ID, no power, wiring). */
static void dxlt_timeout_fail(struct dxlt *t, uint8_t id)
{
	struct bus_late late = { .id = -1 };

	if (id == DXL_BROADCAST_ID || bus_listen_late(&t->bus, DXLT_LATE_LISTEN_MS * 1000u, &late) != DXL_OK)
		late.bytes = 0;
	if (late.bytes > 0 && late.id == id) {
		fprintf(t->err,
		        "dxl: a reply from ID %u came %.1f ms after dxl stopped waiting (%.1f ms): it is late, not missing "
		        "(a loaded machine, or an adapter holding bytes); wait longer: dxl --port %s --timeout-ms %ld ...\n",
		        id, late.after_us / 1000.0, late.waited_us / 1000.0, port_path(t->port), dxlt_timeout_hint_ms(&late));
		return;
	}
	fprintf(t->err, "dxl: no reply from ID %u at %ld bps", id, port_baud(t->port));
	if (late.bytes > 0)
		fprintf(t->err, " (%ld byte%s came %.1f ms after dxl stopped waiting, no status packet from ID %u among them)",
		        late.bytes, late.bytes == 1 ? "" : "s", late.after_us / 1000.0, id);
	fprintf(t->err, "; wrong baud or ID? try: dxl --port %s scan --bauds all\n", port_path(t->port));
}

int dxlt_bus_fail(struct dxlt *t, uint8_t id, int status)
{
	switch (status) {
	case DXL_E_TIMEOUT:
		dxlt_timeout_fail(t, id);
		return DXLT_EXIT_BUS;
	case DXL_E_DISCONNECTED:
		fprintf(t->err, "dxl: %s went away (adapter unplugged or simulator stopped)\n",
		        port_path(t->port));
		return DXLT_EXIT_PORT;
	case DXL_E_IO:
		fprintf(t->err, "dxl: I/O error on %s: %s\n", port_path(t->port), strerror(errno));
		return DXLT_EXIT_PORT;
	case DXL_E_ECHO:
		fprintf(t->err, "dxl: bytes read back differ from those sent (is --echo right for "
		        "this wiring?)\n");
		return DXLT_EXIT_BUS;
	case DXL_E_WRONG_LENGTH:
		fprintf(t->err, "dxl: bad reply from ID %u: %s%s\n", id, dxl_strerror(status),
		        t->a.echo ? "" : " (single-wire wiring? try --echo)");
		return DXLT_EXIT_BUS;
	default:
		fprintf(t->err, "dxl: bad reply from ID %u: %s\n", id, dxl_strerror(status));
		return DXLT_EXIT_BUS;
	}
}

/* Where a reply's error field is remembered: the bus's protocol's row. */
static uint8_t *dxlt_errseen(struct dxlt *t, uint8_t id)
{
	return &t->errseen[bus_proto(&t->bus)->number - 1][id];
}

uint8_t dxlt_errors(const struct dxlt *t, uint8_t id)
{
	return t->errseen[bus_proto(&t->bus)->number - 1][id];
}

void dxlt_seen(struct dxlt *t, uint8_t id, uint8_t e)
{
	*dxlt_errseen(t, id) |= e;
}

int dxlt_ping(struct dxlt *t, uint8_t id)
{
	uint8_t e = 0;
	int r = bus_ping(&t->bus, id, &e);

	if (r == DXL_OK)
		*dxlt_errseen(t, id) |= e;
	return r;
}

int dxlt_ping_model(struct dxlt *t, uint8_t id, uint16_t *model)
{
	uint8_t e = 0;
	int r = bus_ping_model(&t->bus, id, model, NULL, &e);

	/* a backend whose PING carries no model sends nothing for that */
	if (r == DXL_E_UNSUPPORTED)
		return dxlt_ping(t, id);
	if (r == DXL_OK)
		*dxlt_errseen(t, id) |= e;
	return r;
}

int dxlt_read(struct dxlt *t, uint8_t id, uint16_t addr, uint16_t len, uint8_t *out)
{
	uint8_t e = 0;
	int r = bus_read(&t->bus, id, addr, len, out, &e);

	if (r == DXL_OK)
		*dxlt_errseen(t, id) |= e;
	return r;
}

int dxlt_write(struct dxlt *t, uint8_t id, uint16_t addr, const uint8_t *data, size_t n, bool expect_reply)
{
	uint8_t e = 0;
	int r = bus_write(&t->bus, id, addr, data, n, expect_reply, &e);

	if (r == DXL_OK)
		*dxlt_errseen(t, id) |= e;
	return r;
}

uint16_t dxlt_addr(const struct dxlt *t, const char *name)
{
	return dxl2_reg_lookup(t->fam_model, name)->addr;
}

int dxlt_arg_servo_id(struct dxlt *t, const char *s, uint8_t *id)
{
	int rc = dxlt_arg_id(t, s, false, id);
	if (rc != DXLT_EXIT_OK)
		return rc;
	if (*id > t->fam->max_id) {
		fprintf(t->err, "dxl: bad ID '%s' (0-%u on %s)\n", s, t->fam->max_id, t->fam->label);
		return DXLT_EXIT_USAGE;
	}
	return DXLT_EXIT_OK;
}

int dxlt_verify_ping(struct dxlt *t, uint8_t id)
{
	int r = DXL_E_TIMEOUT;

	dxlt_sleep_us(t->fam->settle_us);
	for (int attempt = 0; attempt < 3 && r == DXL_E_TIMEOUT; attempt++)
		r = dxlt_ping(t, id);
	return r;
}

int dxlt_need_args(struct dxlt *t, int n, const char *form)
{
	if (t->a.npos == n)
		return DXLT_EXIT_OK;
	fprintf(t->err, "dxl: usage: dxl --port PATH %s\n", form);
	return DXLT_EXIT_USAGE;
}

int dxlt_need_form(struct dxlt *t, int n, const char *form)
{
	char line[96];
	snprintf(line, sizeof line, "%s%s", t->fam->opt, form);
	return dxlt_need_args(t, n, line);
}

int dxlt_arg_id(struct dxlt *t, const char *s, bool allow_broadcast, uint8_t *id)
{
	if (dxlt_parse_id(s, allow_broadcast, id) == 0)
		return DXLT_EXIT_OK;
	fprintf(t->err, "dxl: bad ID '%s' (0-253%s)\n", s, allow_broadcast ? ", 254 broadcast" : "");
	return DXLT_EXIT_USAGE;
}

/* What to do instead when another program holds the bus: dxl's packets
 * would collide with its own. A robot's daemon is watched through the
 * daemon (read-only, LCM), or stopped first. */
static void dxlt_held(struct dxlt *t, const char *why, const struct holder *h)
{
	const char *robot = h->robot[0] != '\0' ? h->robot : NULL;

	if (strcmp(h->program, "undulated") == 0)
		fprintf(t->err, "dxl: %s: a robot's daemon drives this bus, and dxl's packets would collide with its cycle; "
		        "watch its servos (angles, speeds, loads, voltages, temperatures, error bits) through the daemon: "
		        "undulated --watch %s; or stop the robot first (systemctl stop undulated@%s if that is its service, or "
		        "kill %ld), then run dxl\n", why, robot != NULL ? robot : "'*'", robot != NULL ? robot : "ROBOT", h->pid);
	else if (strcmp(h->program, "dxl") == 0)
		fprintf(t->err, "dxl: %s: another dxl is using this bus; run this one when it is done\n", why);
	else
		fprintf(t->err, "dxl: %s: one program drives a bus at a time; stop that one first\n", why);
}

int dxlt_open(struct dxlt *t, const char *path, bool low_latency)
{
	char owner[64];
	struct holder held;
	struct port_options opt = { .baud = t->a.baud, .low_latency = low_latency, .owner = owner, .holder = &held };
	struct bus_io io;
	char why[512];

	snprintf(owner, sizeof owner, "command %s", t->a.command != NULL ? t->a.command : "?");
	t->port = port_open(path, &opt, why, sizeof why);
	if (t->port == NULL) {
		if (held.pid > 0 || held.program[0] != '\0')
			dxlt_held(t, why, &held);
		else
			fprintf(t->err, "dxl: %s\n", why);
		return DXLT_EXIT_PORT;
	}
	/* A UART behind a half-duplex buffer: the kernel switches the direction
	 * around every packet, or nothing we send reaches a servo. */
	if (port_set_rs485(t->port, t->a.rs485, why, sizeof why) != DXL_OK) {
		fprintf(t->err, "dxl: %s\n", why);
		return DXLT_EXIT_PORT;
	}
	/* Look, do not touch (unless asked): only setup and doctor change the adapter. */
	const struct port_latency *checked = port_get_latency(t->port);
	if (checked != NULL)
		t->latency = *checked;
	else
		port_latency_check_fd(path, port_fd(t->port), false, &t->latency);
	port_bus_io(t->port, &io);
	bus_init(&t->bus, &io, NULL, t->a.echo);
	bus_set_protocol(&t->bus, t->fam->bus);
	dxlt_apply_timing(t);
	return DXLT_EXIT_OK;
}

int dxlt2_ping(struct dxlt *t, uint8_t id, uint16_t *model, uint8_t *firmware)
{
	uint8_t e = 0;
	int r = bus_ping_model(&t->bus, id, model, firmware, &e);
	if (r == DXL_OK)
		*dxlt_errseen(t, id) |= e;
	return r;
}
