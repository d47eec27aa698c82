/*
 * doctor.c — `dxl doctor`: the first-run hardware check (doctor.h has the
 * verdicts). In order:
 *
 *  1. the robot: undulated's own configuration file (daemon/config.c's
 *     parser, through libdaemon), or the IDs and rate on the command line;
 *  2. the port, opened as undulated opens it (its FTDI latency timer lowered
 *     if it can be, its RS-485 mode set if configured): the adapter line;
 *  3. every servo PINGed with a timeout long enough for any adapter (the
 *     largest FTDI latency timer is 255 ms), then the replies' lateness
 *     measured (bus_reply_lateness): the latency and baud lines;
 *  4. one READ per servo of its control table, model number .. present
 *     temperature, read through its model's descriptor: a line per setting
 *     (doctor_checks.c; a model's own lines where its descriptor says it
 *     has the register or the capability);
 *  5. a few hundred of undulated's own cycles (daemon/cycle.c driving
 *     daemon/control.c, with the daemon's bus timeouts) holding every joint
 *     where it stands, timed as the daemon times them: the budget line.
 *     Torque is put back as it was found.
 *
 * Exit status: 0 all OK, 1 warnings only, 7 a check failed; 2 usage or a bad
 * configuration, 3 the port cannot be opened or went away (nothing to check),
 * 130 interrupted during the timed cycles (torque put back all the same).
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "clock.h"
#include "daemon/config.h"
#include "daemon/control.h"
#include "daemon/cycle.h"
#include "daemon/log.h"
#include "daemon/setup.h"
#include "doctor.h"
#include "dxl.h"
#include "dxl2_table.h"
#include "dxl_table.h"
#include "dxlt_priv.h"

/* The probe's wait for each PING before anything is known about the adapter:
 * longer than the largest FTDI latency timer (255 ms) and a loaded machine. */
#define DR_PROBE_MARGIN_US 300000u
/* PINGs per servo before it is called missing: one may be lost to a busy
 * machine, two are not. */
#define DR_PING_TRIES 2
/* PINGs that measure the replies' lateness: the median of 8 is not moved by
 * a late wake-up or two. */
#define DR_LATENESS_PINGS 8
/* Tries of each READ of the checks. */
#define DR_READ_TRIES 2
/* Slack on the check reads' timeouts once the lateness is known (ms): the
 * tool's own, as for every other dxl command. */
#define DR_CHECK_SLACK_US (DXLT_DEFAULT_SLACK_MS * 1000u)
/* Width of the check-name column. */
#define DR_NAME_WIDTH 19

struct dr {
	struct dxlt *t;
	struct cfg cfg;
	char source[CFG_PATH_MAX + 32];      /* where the robot came from, for the header */
	struct dr_servo servo[CFG_MAX_JOINTS];
	char setup_ids[CFG_MAX_JOINTS * 4 + 1];
	struct dr_context ctx;
	unsigned count[DR_SKIP + 1];
	char tty[96];
	bool is_pty;
	uint32_t lateness_max_us;            /* measured, for the check reads' timeouts */
	bool lateness_known;
	bool interrupted;                    /* SIGINT/SIGTERM during the timed cycles */
};

static void dr_line(struct dr *d, const char *check, const struct dr_verdict *v)
{
	d->count[v->level]++;
	fprintf(d->t->out, "%-5s %-*s %s\n", dr_level_name(v->level), DR_NAME_WIDTH, check, v->text);
	fflush(d->t->out);
}

static void dr_servo_line(struct dr *d, uint8_t id, const char *what, const struct dr_verdict *v)
{
	char check[48];
	snprintf(check, sizeof check, "ID %u %s", id, what);
	dr_line(d, check, v);
}

/* ---- 1. the robot ---------------------------------------------------------------------- */

static int dr_cfg_errors(struct dr *d, const struct cfg_errors *e)
{
	for (size_t i = 0; i < e->count && i < CFG_MAX_ERRORS; i++)
		fprintf(d->t->err, "dxl: %s\n", e->line[i]);
	if (e->count > CFG_MAX_ERRORS)
		fprintf(d->t->err, "dxl: ... and %zu more error(s)\n", e->count - CFG_MAX_ERRORS);
	return DXLT_EXIT_USAGE;
}

/* IDs given on the command line (positional, or --ids A-B) as the config's
 * "ids" value: 1 with them in buf, 0 when there are none, -1 when they do not
 * fit (far more than a robot's CFG_MAX_JOINTS: cut, they would name others). */
static int dr_cli_ids(const struct dxlt_args *a, char *buf, size_t cap)
{
	size_t off = 0;
	buf[0] = '\0';
	for (int i = 0; i < a->npos; i++) {
		int w = snprintf(buf + off, cap - off, "%s%s", i ? "," : "", a->pos[i]);
		if (w < 0 || (size_t)w >= cap - off)
			return -1;
		off += (size_t)w;
	}
	for (unsigned id = a->id_lo; a->npos == 0 && a->ids_given && id <= a->id_hi; id++) {
		int w = snprintf(buf + off, cap - off, "%s%u", off ? "," : "", id);
		if (w < 0 || (size_t)w >= cap - off)
			return -1;
		off += (size_t)w;
	}
	return off > 0;
}

/* A robot on several buses ([bus.NAME]) is checked a bus at a time: --bus
 * NAME picks one, and the doctor sees the robot as that bus alone. */
static int dr_one_bus(struct dr *d)
{
	struct dxlt *t = d->t;
	struct cfg *c = &d->cfg;
	char why[CFG_MAX_BUSES * (CFG_PATH_MAX + CFG_NAME_MAX + 8) + 64];
	if (t->a.bus_name == NULL && cfg_buses_used(c) <= 1)
		return DXLT_EXIT_OK;
	if (t->a.bus_name == NULL) {
		cfg_only_bus(c, "", why, sizeof why);
		fprintf(t->err, "dxl: the robot's joints are on %zu buses: doctor checks one at a time, with --bus NAME "
		        "(%s)\n", cfg_buses_used(c), strstr(why, "buses: ") ? strstr(why, "buses: ") + 7 : why);
		return DXLT_EXIT_USAGE;
	}
	if (!cfg_only_bus(c, t->a.bus_name, why, sizeof why)) {
		fprintf(t->err, "dxl: --bus: %s\n", why);
		return DXLT_EXIT_USAGE;
	}
	return DXLT_EXIT_OK;
}

static int dr_configure(struct dr *d)
{
	struct dxlt *t = d->t;
	struct cfg *c = &d->cfg;
	struct cfg_errors e = { 0 };
	char ids[1024], baud[32];

	cfg_defaults(c);
	if (t->a.config_path != NULL && !cfg_load_file(c, t->a.config_path, &e))
		return dr_cfg_errors(d, &e);
	/* the command line wins over the file, as undulated's does */
	if (t->a.port_path != NULL)
		cfg_set(c, "command line", "robot", "port", t->a.port_path, &e);
	int have_ids = dr_cli_ids(&t->a, ids, sizeof ids);
	if (have_ids < 0) {
		fprintf(t->err, "dxl: more servo IDs on the command line than a robot has (at most %d)\n", CFG_MAX_JOINTS);
		return DXLT_EXIT_USAGE;
	}
	if (have_ids > 0)
		cfg_set(c, "command line", "robot", "ids", ids, &e);
	if (t->a.baud_given) {
		snprintf(baud, sizeof baud, "%ld", t->a.baud);
		cfg_set(c, "command line", "robot", "baud", baud, &e);
	}
	if (e.count > 0)
		return dr_cfg_errors(d, &e);
	if (c->port[0] == '\0' && c->usb_serial[0] == '\0') {
		fprintf(t->err, "dxl: doctor needs --port PATH (see dxl ports) or --config FILE naming the port\n");
		return DXLT_EXIT_USAGE;
	}
	if (c->njoints == 0) {
		fprintf(t->err, "dxl: doctor needs the servos: dxl --port %s doctor 1 2, or --config FILE (ids = 1,2)\n",
		        c->port[0] ? c->port : "PATH");
		return DXLT_EXIT_USAGE;
	}
	if (!cfg_finish(c, &e))
		return dr_cfg_errors(d, &e);
	if (dr_one_bus(d) != DXLT_EXIT_OK)
		return DXLT_EXIT_USAGE;
	if (c->port[0] == '\0') {
		int n = 0;
		if (!port_find_by_serial(c->usb_serial, c->port, sizeof c->port, &n)) {
			fprintf(t->err, "dxl: no serial port with USB serial number '%s' (%d port(s) found; dxl ports lists "
			        "them)\n", c->usb_serial, n);
			return DXLT_EXIT_PORT;
		}
	}
	/* what undulated would use, unless the command line says otherwise */
	t->a.baud = c->baud;
	t->a.echo = t->a.echo || c->echo;
	if (!t->a.rs485_given)
		t->a.rs485 = c->rs485;
	snprintf(d->source, sizeof d->source, "%s", t->a.config_path != NULL ? t->a.config_path : "the command line");
	return DXLT_EXIT_OK;
}

/* ---- 2. the adapter --------------------------------------------------------------------- */

static void dr_name_tty(struct dr *d)
{
	char real[PATH_MAX];
	const char *shown = d->cfg.port;

	if (realpath(d->cfg.port, real) != NULL)
		shown = strncmp(real, "/dev/", 5) == 0 ? real + 5 : real;
	/* a name too long for the line keeps its end, where the device is */
	size_t len = strlen(shown);
	if (len >= sizeof d->tty)
		shown += len - (sizeof d->tty - 1);
	memcpy(d->tty, shown, strlen(shown) + 1);
	d->is_pty = strncmp(d->tty, "pts/", 4) == 0;
}

static void dr_adapter(struct dr *d)
{
	struct dr_adapter a = {
		.tty = d->tty, .is_pty = d->is_pty, .lat = d->t->latency, .sysfs_root = port_sysfs_root(),
		.rs485 = d->t->a.rs485, .echo = d->t->a.echo,
	};
	struct dr_verdict v;

	a.listed = !d->is_pty && port_info_for(d->cfg.port, &a.info);
	dr_check_adapter(&a, &v);
	dr_line(d, "adapter", &v);
}

/* ---- 3. who answers, how late ------------------------------------------------------------- */

static void dr_timing(struct dr *d, uint32_t return_delay_us, uint32_t latency_us, uint32_t margin_us)
{
	struct bus_timing tm = {
		.baud = d->cfg.baud, .return_delay_us = return_delay_us, .adapter_latency_us = latency_us, .margin_us = margin_us,
	};
	/* --timeout-ms: the user's word for every check transaction */
	if (d->t->a.timeout_ms > 0) {
		dxlt_apply_timing(d->t);
		return;
	}
	bus_set_timing(&d->t->bus, &tm);
}

static bool dr_gone(int r)
{
	return r == DXL_E_DISCONNECTED || r == DXL_E_IO;
}

/* PING every configured servo. DXLT_EXIT_OK, or the port's failure. */
static int dr_find(struct dr *d, unsigned *answered)
{
	*answered = 0;
	dr_timing(d, 254u * 2u, 0, DR_PROBE_MARGIN_US);
	for (size_t j = 0; j < d->cfg.njoints; j++) {
		struct dr_servo *s = &d->servo[j];
		int r = DXL_E_TIMEOUT;
		s->id = d->cfg.ids[j];
		for (int k = 0; k < DR_PING_TRIES && r != DXL_OK; k++) {
			/* where the PING says the model (2.0), the baud line prices its
			 * cycle and the READ takes its table */
			r = dxlt_ping_model(d->t, s->id, &s->model);
			if (dr_gone(r))
				return dxlt_bus_fail(d->t, s->id, r);
		}
		s->answered = r == DXL_OK;
		s->ping_status = r;
		*answered += s->answered;
	}
	return DXLT_EXIT_OK;
}

static int dr_latency(struct dr *d)
{
	struct dr_latency l = { .njoints = (unsigned)d->cfg.njoints };
	struct dr_verdict v;
	const struct dr_servo *first = NULL;

	for (size_t j = 0; j < d->cfg.njoints && first == NULL; j++)
		if (d->servo[j].answered)
			first = &d->servo[j];
	if (first != NULL) {
		/* its own return delay is no adapter's doing: read it first */
		uint8_t rd = 0;
		int rr = dxlt_read(d->t, first->id, dxlt_addr(d->t, "return_delay_time"), 1, &rd);
		if (rr != DXL_OK)
			rd = 0;
		int r = bus_reply_lateness(&d->t->bus, first->id, dxl2_return_delay_us(rd), DR_LATENESS_PINGS, &l.late);
		if (dr_gone(r))
			return dxlt_bus_fail(d->t, first->id, r);
		l.measured = r == DXL_OK;
		l.id = first->id;
	}
	l.ftdi = d->t->latency.known;
	l.allowed_us = port_adapter_latency_us(d->t->port, d->cfg.adapter_latency_us, NULL) + d->cfg.bus_margin_us;
	dr_check_latency(&l, &v);
	dr_line(d, "latency", &v);
	if (l.measured) {
		d->lateness_known = true;
		d->lateness_max_us = l.late.max_us;
	}
	return DXLT_EXIT_OK;
}

/* ---- 4. each servo's settings -------------------------------------------------------------- */

static int dr_read(struct dr *d, uint8_t id, uint16_t len, uint8_t *out)
{
	int r = DXL_E_TIMEOUT;
	for (int k = 0; k < DR_READ_TRIES && r != DXL_OK && !dr_gone(r); k++)
		r = dxlt_read(d->t, id, 0, len, out);
	return r;
}

/* One servo's table from address 0: its model's, where the PING named it,
 * else the protocol's first model's (every model of a protocol has the model
 * number at 0); read again through its own model's table when the number
 * names another model whose table reaches further. */
static int dr_read_one(struct dr *d, struct dr_servo *s)
{
	int protocol = d->t->fam->protocol;
	const struct dxl2_model *table = dxl2_model_find(protocol, s->model), *m;
	uint8_t image[DXLT_IMAGE_MAX];

	if (table == NULL)
		table = d->t->fam_model;
	size_t len = dr_image_len(table);
	int r = dr_read(d, s->id, (uint16_t)len, image);
	if (r != DXL_OK)
		return r;
	dr_servo_decode(s, NULL, table, image, len);
	if ((m = dxl2_model_find(protocol, s->model)) != NULL && m != table) {
		table = m;
		if (dr_image_len(m) > len) {
			len = dr_image_len(m);
			if ((r = dr_read(d, s->id, (uint16_t)len, image)) != DXL_OK)
				return r;
		}
	}
	dr_servo_decode(s, m, table, image, len);
	return DXL_OK;
}

/* Read every servo that answered. DXLT_EXIT_OK or the port's failure; a
 * servo that does not answer READ keeps s->read false and its status. */
static int dr_read_all(struct dr *d, int *status)
{
	for (size_t j = 0; j < d->cfg.njoints; j++) {
		struct dr_servo *s = &d->servo[j];
		status[j] = DXL_OK;
		if (!s->answered)
			continue;
		int r = dr_read_one(d, s);
		if (dr_gone(r))
			return dxlt_bus_fail(d->t, s->id, r);
		status[j] = r;
		if (r != DXL_OK)
			continue;
		s->read = true;
		s->errbits = dxlt_errors(d->t, s->id);
	}
	return DXLT_EXIT_OK;
}

/* The servo model undulated's start-up would drive a servo as (its own, or
 * where its family runs an unknown model on its first model's table, that
 * one); NULL where it would refuse it. */
static const struct sm_model *dr_sm_model(const struct dr *d, const struct dr_servo *s)
{
	int protocol = d->t->fam->protocol;
	const struct sm_model *m = sm_by_number(protocol, s->model);
	return m != NULL || sm_family(protocol)->setup->strict ? m : sm_family(protocol);
}

static void dr_context(struct dr *d)
{
	size_t off = 0;
	d->setup_ids[0] = '\0';
	d->ctx = (struct dr_context){ .port = d->cfg.port, .ids = d->setup_ids, .baud = d->cfg.baud,
	                              .period_ms = d->cfg.period_ms, .proto = bus_proto(&d->t->bus) };
	for (size_t j = 0; j < d->cfg.njoints; j++) {
		const struct dr_servo *s = &d->servo[j];
		if (!s->answered)
			continue;
		int w = snprintf(d->setup_ids + off, sizeof d->setup_ids - off, "%s%u", off ? " " : "", s->id);
		if (w > 0 && (size_t)w < sizeof d->setup_ids - off)
			off += (size_t)w;
		d->ctx.any_torque_on = d->ctx.any_torque_on || (s->read && s->torque_enable);
		/* the loop's bytes a servo: the most any of them takes */
		const struct sm_model *m = dr_sm_model(d, s);
		if (m == NULL)
			m = sm_family(d->t->fam->protocol);
		if (m->present_len > d->ctx.read_len)
			d->ctx.read_len = m->present_len;
		if (m->goal_size > d->ctx.write_len)
			d->ctx.write_len = m->goal_size;
	}
}

static void dr_servo_lines(struct dr *d, size_t j, int read_status)
{
	const struct dr_servo *s = &d->servo[j];
	const char *opt = d->t->fam->opt;
	struct dr_verdict v = { DR_OK, "" };
	char what[32];

	if (!s->answered) {
		if (s->ping_status == DXL_E_TIMEOUT)
			snprintf(v.text, sizeof v.text, "no reply to %d PINGs at %ld bps (%u ms each); fix: its power and "
			         "cable, or its ID and rate: dxl %s--port %s scan --bauds all", DR_PING_TRIES, d->cfg.baud,
			         DR_PROBE_MARGIN_US / 1000u, opt, d->cfg.port);
		else
			snprintf(v.text, sizeof v.text, "its PING replies are bad (%s)%s", dxl_strerror(s->ping_status),
			         s->ping_status == DXL_E_ECHO ? ": see the echo line" : "; fix: the cable, a second master on "
			         "the bus, or two servos with this ID (unplug all but one and scan)");
		v.level = DR_FAIL;
		dr_servo_line(d, s->id, "ping", &v);
		return;
	}
	if (!s->read) {
		v.level = DR_FAIL;
		if (read_status == DXL_E_TIMEOUT)
			snprintf(v.text, sizeof v.text, "answers PING but not READ: status return level 0, so the loop's %s "
			         "goes unanswered; fix: dxl %s--port %s write %u status_return_level 2",
			         dxl_proto_can(d->ctx.proto, DXL_CAP_SYNC_READ) ? "SYNC_READ" : "READ of every joint", opt,
			         d->cfg.port, s->id);
		else
			snprintf(v.text, sizeof v.text, "answers PING, but its READ replies are bad (%s)%s",
			         dxl_strerror(read_status), d->t->a.echo ? "" : "; a single-wire wiring? try --echo");
		dr_servo_line(d, s->id, "status level", &v);
		return;
	}
	dr_check_model(s, &d->ctx, &v);
	dr_servo_line(d, s->id, "model", &v);
	dr_check_return_delay(s, &d->ctx, &v);
	dr_servo_line(d, s->id, "return delay", &v);
	dr_check_status_level(s, &d->ctx, &v);
	dr_servo_line(d, s->id, "status level", &v);
	dr_check_voltage(s, &v);
	dr_servo_line(d, s->id, "voltage", &v);
	dr_check_temperature(s, &v);
	dr_servo_line(d, s->id, "temperature", &v);
	if (dxl2_model_can(s->table, DXL2_CAP_OPMODE)) {
		dr_check_mode(s, &d->ctx, &v);
		dr_servo_line(d, s->id, "operating mode", &v);
	}
	dr_check_limits(s, &d->cfg, j, &d->ctx, &v);
	snprintf(what, sizeof what, "%s limits", sm_family(s->table->protocol)->limits_name);
	dr_servo_line(d, s->id, what, &v);
	if (s->has_alarm_led) {
		dr_check_alarms(s, &d->ctx, &v);
		dr_servo_line(d, s->id, "alarms", &v);
	}
	if (dxl2_model_can(s->table, DXL2_CAP_HWERR_STATUS)) {
		dr_check_hwerr(s, &d->ctx, &v);
		dr_servo_line(d, s->id, "hardware error", &v);
	}
	dr_check_torque(s, &d->ctx, &v);
	dr_servo_line(d, s->id, "torque", &v);
	if (dxl2_model_can(s->table, DXL2_CAP_WATCHDOG)) {
		dr_check_watchdog(s, &d->ctx, &v);
		dr_servo_line(d, s->id, "bus watchdog", &v);
	}
	if (dr_check_errbits(s, &d->ctx, &v))
		dr_servo_line(d, s->id, "error bits", &v);
}

/* ---- 5. undulated's cycle, timed ------------------------------------------------------------- */

struct dr_run {
	struct cfg cfg;                 /* the timed joints only, in HOLD */
	struct ctl ctl;
	struct cyc cyc;
	size_t from[CFG_MAX_JOINTS];    /* index into d->servo */
	unsigned rd_us[CFG_MAX_JOINTS];
	double *bus_ms, *floor_ms;
	unsigned done;
	long long events;               /* controller warnings and errors during the run */
	char first_event[CTL_EVENT_TEXT];
	uint64_t epoch_us, last_start_us;
	/* counters at the cycle's start, for its wire floor */
	uint64_t out0, in0;
	uint32_t replies0[CFG_MAX_JOINTS];
	long long transactions;
};

static int dr_cmp(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* The p-quantile of a sorted array (nearest rank). */
static double dr_pct(const double *v, size_t n, double p)
{
	size_t rank = (size_t)ceil(p * (double)n);
	return n ? v[rank ? rank - 1 : 0] : 0.0;
}

/* What start-up hands the controller (daemon/setup.c's setup_servo, one for
 * every model), from the checks' reads; false: undulated would not drive
 * it (a model its family refuses, or no output to move with). */
static bool dr_servo_info(const struct dr *d, size_t j, struct ctl_servo_info *info)
{
	const struct dr_servo *s = &d->servo[j];
	const struct sm_model *m = dr_sm_model(d, s);
	if (m == NULL)
		return false;
	bool in_turn = s->min_limit >= 0 && s->max_limit <= m->pos_max;
	*info = (struct ctl_servo_info){
		.cw_limit = in_turn ? (uint16_t)s->min_limit : 1, .ccw_limit = in_turn ? (uint16_t)s->max_limit : 0,
		/* an output limit of 0: refused, or run at full output (as setup.c does) */
		.max_torque = s->max_output ? s->max_output : m->setup->strict ? 0 : (uint16_t)m->torque_full,
		.return_delay = s->return_delay, .status_return_level = s->status_return_level, .model = m,
		.firmware = s->firmware,
	};
	return info->max_torque != 0;
}

/* Give the controller the joints r->from[0..n) lists; keep those it takes
 * (ctl_set_servo: angle limits with room, not wheel mode — as at undulated's
 * start). Returns how many were kept. */
static size_t dr_set_servos(struct dr *d, struct dr_run *r, size_t n)
{
	struct ctl_servo_info info;
	char why[256];
	size_t kept = 0;

	r->cfg.njoints = n;
	ctl_init(&r->ctl, &r->cfg);
	for (size_t k = 0; k < n; k++) {
		if (!dr_servo_info(d, r->from[k], &info) || !ctl_set_servo(&r->ctl, k, &info, why, sizeof why))
			continue;   /* its angle-limits line says why */
		r->cfg.ids[kept] = r->cfg.ids[k];
		r->cfg.joint[kept] = r->cfg.joint[k];
		r->from[kept] = r->from[k];
		r->rd_us[kept] = dxl2_return_delay_us(info.return_delay);
		kept++;
	}
	return kept;
}

/* The joints the daemon could drive: the servo answered READ at a status
 * return level that lets it, and the controller takes its angle limits. */
static unsigned dr_pick_joints(struct dr *d, struct dr_run *r)
{
	size_t n = 0;
	r->cfg = d->cfg;
	/* never swing a joint in a check: hold where it stands (the daemon's first-run default) */
	r->cfg.mode = CFG_MODE_HOLD;
	/* the servo's own compliance margins: a check leaves them (undulated
	 * writes the configured one at start; the cycle costs the same) */
	r->cfg.compliance_margin = -1;
	/* and the X series' bus watchdog as it is (the servo's own setting);
	 * a check reboots nothing: a shutdown found latches the hold */
	r->cfg.bus_watchdog_ms = -1;
	r->cfg.fault_reboots = 0;
	for (size_t j = 0; j < d->cfg.njoints; j++) {
		const struct dr_servo *s = &d->servo[j];
		if (!s->read || s->status_return_level == 0)
			continue;
		r->cfg.ids[n] = s->id;
		r->cfg.joint[n] = d->cfg.joint[j];
		r->from[n++] = j;
	}
	size_t kept = dr_set_servos(d, r, n);
	/* a second time with the kept joints alone: the controller's joints are
	 * its configuration's, in order */
	if (kept != n)
		kept = dr_set_servos(d, r, kept);
	r->cfg.njoints = kept;
	return (unsigned)kept;
}

static void dr_mark(struct dr_run *r, const struct bus *bus)
{
	r->out0 = bus->bytes_out;
	r->in0 = bus->bytes_in;
	for (size_t k = 0; k < r->cfg.njoints; k++)
		r->replies0[k] = bus->servo[r->cfg.ids[k]].replies;
}

/* A cycle is over (done or cut off): its bus time as undulated measures it,
 * and its wire floor — the bytes that crossed the line (our echo not counted
 * twice) and a return delay per reply. */
static void dr_record(struct dr_run *r, const struct bus *bus)
{
	uint64_t out = bus->bytes_out - r->out0, in = bus->bytes_in - r->in0;
	if (bus->echo)
		in = in > out ? in - out : 0;
	double floor_us = (double)bus_wire_time_us(bus, (size_t)(out + in));
	for (size_t k = 0; k < r->cfg.njoints; k++)
		floor_us += (double)(bus->servo[r->cfg.ids[k]].replies - r->replies0[k]) * r->rd_us[k];
	/* a Fast Sync Read's parts are counted as replies, but only its first
	 * servo waits its return delay: the others send theirs at once */
	const struct bus_multi *m = &r->cyc.multi;
	bool first = true;
	for (size_t k = 0; r->cyc.fast_read && m->fast && k < m->n && k < r->cfg.njoints; k++)
		if (m->status[k] == DXL_OK) {
			if (!first)
				floor_us -= r->rd_us[k];
			first = false;
		}
	r->bus_ms[r->done] = 1e-3 * r->cyc.bus_us;
	r->floor_ms[r->done] = 1e-3 * floor_us;
	r->done++;
}

static void dr_events(struct dr_run *r)
{
	struct ctl_event e;
	while (ctl_next_event(&r->ctl, &e)) {
		if (e.level < 1)
			continue;
		/* the event's own text is at most CTL_EVENT_TEXT: a cut one still says what */
		if (r->events++ == 0 && snprintf(r->first_event, sizeof r->first_event, "%s: %s", e.kind, e.text) < 0)
			r->first_event[0] = '\0';
	}
}

/* Follow the cycle until it waits for the bus or ends, as the daemon's
 * dmn_drive does. False when the port went away. */
static bool dr_drive(struct dr_run *r, struct bus *bus, enum cyc_status st)
{
	for (;;) {
		switch (st) {
		case CYC_PENDING:
			return true;
		case CYC_CONTROL: {
			uint64_t start = r->cyc.start_us;
			double dt = r->last_start_us ? 1e-6 * (double)(start - r->last_start_us) : 1e-6 * (double)r->cyc.period_us;
			ctl_step(&r->ctl, 1e-6 * (double)(start - r->epoch_us), dt, 1e-6 * (double)clock_wall_us());
			r->last_start_us = start;
			dr_events(r);
			st = cyc_resume(&r->cyc);
			continue;
		}
		case CYC_DONE:
			dr_record(r, bus);
			return true;
		case CYC_LOST:
			return false;
		}
	}
}

/* A Ctrl-C while the joints are torqued for the timed cycles ends the run,
 * and torque is still put back as found. Set by the handler, read by the
 * loop: the one state a signal can reach. */
static volatile sig_atomic_t dr_interrupted;

static void dr_on_signal(int sig)
{
	(void)sig;
	dr_interrupted = 1;
}

static void dr_sleep_until(uint64_t t_us)
{
	struct timespec ts = { .tv_sec = (time_t)(t_us / 1000000u), .tv_nsec = (long)(t_us % 1000000u) * 1000L };
	while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR && !dr_interrupted) {
	}
}

/* n cycles on the period's grid, driven like undulated's poll() loop: the
 * bus fd until the transaction's deadline, a cycle still on the bus at the
 * next tick cut off there. The result of the last transaction is the
 * port's: DXL_OK, or why it went away. */
static int dr_cycles(struct dr_run *r, struct dxlt *t, unsigned n)
{
	struct bus *bus = &t->bus;
	uint64_t period = r->cyc.period_us, next = port_now_us() + period;

	while (r->done < n && !dr_interrupted) {
		uint64_t now = port_now_us();
		if (now >= next) {
			if (cyc_busy(&r->cyc)) {
				cyc_cut(&r->cyc);
				dr_record(r, bus);
				if (r->done >= n)
					break;
			}
			/* whole periods missed are skipped, the grid kept (as timerfd does) */
			next += period * (1 + (now - next) / period);
			dr_mark(r, bus);
			if (!dr_drive(r, bus, cyc_start(&r->cyc)))
				return r->cyc.lost;
			continue;
		}
		if (!cyc_busy(&r->cyc) || !bus_is_pending(bus)) {
			dr_sleep_until(next);
			continue;
		}
		uint64_t deadline = cyc_deadline_us(&r->cyc), wake = deadline < next ? deadline : next;
		int w = port_wait(t->port, wake > now ? (uint32_t)(wake - now) : 0);
		if (w < 0 && w != DXL_E_DISCONNECTED)
			return w;
		if (w != 0 || port_now_us() >= deadline) {
			if (!dr_drive(r, bus, cyc_step(&r->cyc)))
				return r->cyc.lost;
		}
	}
	cyc_cut(&r->cyc);
	return DXL_OK;
}

static long long dr_transactions(const struct dr_run *r, const struct bus *bus)
{
	long long n = 0;
	for (size_t k = 0; k < r->cfg.njoints; k++)
		n += bus->servo[r->cfg.ids[k]].transactions;
	return n;
}

/* Put torque back as found: a joint found limp is left limp. */
static void dr_restore(struct dr *d, struct dr_run *r)
{
	for (size_t k = 0; k < r->cfg.njoints; k++) {
		const struct dr_servo *s = &d->servo[r->from[k]];
		if (s->torque_enable)
			continue;   /* found on: it holds where it stood */
		if (!setup_limp(&d->t->bus, &r->ctl.j[k])) {
			struct dr_verdict v = { DR_FAIL, "" };
			snprintf(v.text, sizeof v.text, "found off, turned on for the timed cycles, and turning it off "
			         "again was not confirmed; fix: dxl --port %s torque %u off", d->cfg.port, s->id);
			dr_servo_line(d, s->id, "torque", &v);
		}
	}
}

static void dr_summarize(struct dr_run *r, struct dr_budget *b)
{
	qsort(r->bus_ms, r->done, sizeof *r->bus_ms, dr_cmp);
	qsort(r->floor_ms, r->done, sizeof *r->floor_ms, dr_cmp);
	b->cycles = r->done;
	b->p50_ms = dr_pct(r->bus_ms, r->done, 0.5);
	b->p99_ms = dr_pct(r->bus_ms, r->done, 0.99);
	b->max_ms = r->done ? r->bus_ms[r->done - 1] : 0.0;
	b->floor_ms = dr_pct(r->floor_ms, r->done, 0.5);
	b->cut_off = r->cyc.cut_off;
	b->errors = r->cyc.errors;
}

/* Everything the timed cycles need, or why they cannot run (a static
 * string, or one written into why). */
static const char *dr_budget_prepare(struct dr *d, struct dr_run *r, long n, struct dr_budget *b, char *why,
                                     size_t cap)
{
	char err[256];

	if (n == 0)
		return "--cycles 0";
	if ((r->bus_ms = calloc((size_t)n, sizeof(double))) == NULL ||
	    (r->floor_ms = calloc((size_t)n, sizeof(double))) == NULL)
		return "out of memory";
	if ((b->joints = dr_pick_joints(d, r)) == 0)
		return "no servo passed what the loop needs (a PING, READ, angle limits with room)";
	/* the controller starts from where the joints are, as after start-up */
	if (!setup_read_present(&d->t->bus, &r->ctl, CFG_BUS_ROBOT, 1e-3 * d->cfg.period_ms, err, sizeof err)) {
		snprintf(why, cap, "reading the present positions failed: %s", err);
		return why;
	}
	return NULL;
}

/* The daemon's own timeouts (dmn_latency): the largest return delay, the
 * adapter latency it derives, its margin. */
static void dr_daemon_timing(struct dr *d, const struct dr_run *r)
{
	unsigned rd_max = 0;
	for (size_t k = 0; k < r->cfg.njoints; k++)
		rd_max = r->rd_us[k] > rd_max ? r->rd_us[k] : rd_max;
	struct bus_timing daemon = {
		.baud = d->cfg.baud, .return_delay_us = rd_max,
		.adapter_latency_us = (uint32_t)port_adapter_latency_us(d->t->port, d->cfg.adapter_latency_us, NULL),
		.margin_us = (uint32_t)d->cfg.bus_margin_us,
	};
	bus_set_timing(&d->t->bus, &daemon);
}

/* n cycles of HOLD, then torque back as found, with SIGINT/SIGTERM ending the
 * cycles instead of the tool until then: a second signal (timeout(1) sends
 * its own and the group's; a user presses Ctrl-C twice) must not cut the
 * torque-off short. DXL_OK, or why the port went away. */
static int dr_time(struct dr *d, struct dr_run *r, long n, struct dr_budget *b)
{
	struct sigaction stop = { .sa_handler = dr_on_signal }, old_int, old_term;

	dr_daemon_timing(d, r);
	cyc_init(&r->cyc, &d->t->bus, &r->ctl, (uint64_t)llround(d->cfg.period_ms * 1000.0), NULL);
	/* read as undulated will: by Fast Sync Read where every servo answers
	 * it (daemon/setup.c decides, from the models and firmware read) */
	if (dxl_proto_can(bus_proto(&d->t->bus), DXL_CAP_SYNC_READ)) {
		char why[160];
		bool fast = setup_fast_read(&d->t->bus, &r->ctl, why, sizeof why);
		cyc_set_fast_read(&r->cyc, fast);
		snprintf(b->read_by, sizeof b->read_by, "%s, as undulated reads these servos%s%s",
		         fast ? "Fast Sync Read" : "SYNC_READ", fast ? "" : ": no Fast Sync Read, as ", fast ? "" : why);
	} else {
		snprintf(b->read_by, sizeof b->read_by, "a READ a servo, as undulated reads these servos");
	}
	r->epoch_us = port_now_us();
	ctl_start(&r->ctl, 0.0, "start");
	dr_events(r);
	sigemptyset(&stop.sa_mask);
	dr_interrupted = 0;
	sigaction(SIGINT, &stop, &old_int);
	sigaction(SIGTERM, &stop, &old_term);
	long long before = dr_transactions(r, &d->t->bus);
	int lost = dr_cycles(r, d->t, (unsigned)n);
	b->transactions = dr_transactions(r, &d->t->bus) - before;
	d->interrupted = dr_interrupted != 0;
	if (lost == DXL_OK) {
		/* back to the tool's patient timeouts to put torque back */
		dr_timing(d, 254u * 2u, d->lateness_max_us, DR_CHECK_SLACK_US);
		dr_restore(d, r);
	}
	sigaction(SIGINT, &old_int, NULL);
	sigaction(SIGTERM, &old_term, NULL);
	return lost;
}

/* The budget line. DXLT_EXIT_OK, or the port's failure. */
static int dr_budget(struct dr *d)
{
	struct dr_budget b = { .period_ms = d->cfg.period_ms };
	struct dr_verdict v;
	long n = d->t->a.cycles >= 0 ? d->t->a.cycles : DXLT_DOCTOR_CYCLES;
	struct dr_run *r = calloc(1, sizeof *r);
	int rc = DXLT_EXIT_OK;
	char why[320];

	b.skipped = r == NULL ? "out of memory" : dr_budget_prepare(d, r, n, &b, why, sizeof why);
	if (b.skipped == NULL) {
		int lost = dr_time(d, r, n, &b);
		if (lost != DXL_OK) {
			rc = dxlt_bus_fail(d->t, DXL_BROADCAST_ID, lost);
			goto out;
		}
		dr_summarize(r, &b);
		if (d->interrupted) {
			snprintf(why, sizeof why, "interrupted after %u of %ld cycles", r->done, n);
			b.skipped = why;
		}
	}
	dr_check_budget(&b, &v);
	/* what the controller said while holding (a servo's error bits, a
	 * refused write): the checks above have the detail */
	size_t len = strlen(v.text);
	if (b.skipped == NULL && r->events > 0 && len < sizeof v.text)
		snprintf(v.text + len, sizeof v.text - len, "; %lld controller warning(s), the first: %s", r->events,
		         r->first_event);
	dr_line(d, "budget", &v);
out:
	if (r != NULL) {
		free(r->bus_ms);
		free(r->floor_ms);
	}
	free(r);
	return rc;
}

/* ---- the command --------------------------------------------------------------------------------- */

static int dr_check(struct dr *d)
{
	struct dxlt *t = d->t;
	struct dr_verdict v;
	unsigned answered = 0;
	int rc, status[CFG_MAX_JOINTS];

	fprintf(t->out, "dxl doctor: %s at %ld bps, servo IDs", d->cfg.port, d->cfg.baud);
	for (size_t j = 0; j < d->cfg.njoints; j++)
		fprintf(t->out, "%s%u", j ? "," : " ", d->cfg.ids[j]);
	fprintf(t->out, " (from %s)\n", d->source);
	/* as undulated opens it: the latency timer lowered if it can be */
	if ((rc = dxlt_open(t, d->cfg.port, true)) != DXLT_EXIT_OK)
		return rc;
	dr_name_tty(d);
	dr_adapter(d);
	if ((rc = dr_find(d, &answered)) != DXLT_EXIT_OK || (rc = dr_latency(d)) != DXLT_EXIT_OK)
		return rc;
	/* now the replies' lateness is known: the checks wait for that, no more */
	if (d->lateness_known)
		dr_timing(d, 254u * 2u, d->lateness_max_us > (uint32_t)t->latency.timer_ms * 1000u ? d->lateness_max_us
		          : (uint32_t)t->latency.timer_ms * 1000u, DR_CHECK_SLACK_US);
	dr_context(d);
	dr_check_baud(&d->ctx, (unsigned)d->cfg.njoints, answered, &v);
	dr_line(d, "baud", &v);
	/* the servos' lines, then the timed cycles: undulated's own, holding */
	if ((rc = dr_read_all(d, status)) != DXLT_EXIT_OK)
		return rc;
	dr_context(d);
	for (size_t j = 0; j < d->cfg.njoints; j++)
		dr_servo_lines(d, j, status[j]);
	if (dr_check_echo(t->a.echo, t->bus.unexpected_echoes, t->bus.echo_errors, &v))
		dr_line(d, "echo", &v);
	return dr_budget(d);
}

int dxlt_cmd_doctor(struct dxlt *t)
{
	struct dr *d = calloc(1, sizeof *d);
	int rc;

	if (d == NULL) {
		fprintf(t->err, "dxl: out of memory\n");
		return DXLT_EXIT_PORT;
	}
	d->t = t;
	log_set_program("dxl");
	rc = dr_configure(d);
	if (rc == DXLT_EXIT_OK)
		rc = dr_check(d);
	if (rc == DXLT_EXIT_OK) {
		fprintf(t->out, "summary: %u OK, %u WARN, %u FAIL", d->count[DR_OK], d->count[DR_WARN], d->count[DR_FAIL]);
		if (d->count[DR_SKIP] > 0)
			fprintf(t->out, ", %u SKIP", d->count[DR_SKIP]);
		rc = d->count[DR_FAIL] > 0 ? DXLT_EXIT_FAIL : d->count[DR_WARN] > 0 ? DXLT_EXIT_WARN : DXLT_EXIT_OK;
		/* the shell's convention for a command stopped by SIGINT: not a clean bill */
		if (d->interrupted)
			rc = DXLT_EXIT_INTERRUPTED;
		fprintf(t->out, ": exit %d\n", rc);
	}
	/* every reply's error bits were on the servos' lines */
	memset(t->errseen, 0, sizeof t->errseen);
	free(d);
	return rc;
}
