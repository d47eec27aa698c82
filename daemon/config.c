/* config.c — see config.h. */
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "dxl2_table.h"
#include "dxl_table.h"
#include "text.h"
#include "textfile.h"
#include "udpm.h"

#define CFG_PI PARAM_PI
/* LCM's longest channel name (lcm.h LCM_MAX_CHANNEL_NAME_LENGTH). */
#define CFG_LCM_CHANNEL_MAX 63
/* The AX-12 turns 300°: ±150° = ±2.618 rad around its centre. */
#define CFG_SERVO_HALF_RANGE PARAM_SERVO_HALF_RANGE

static void cfg_error(struct cfg_errors *e, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void cfg_error(struct cfg_errors *e, const char *fmt, ...)
{
	if (e == NULL)
		return;
	if (e->count < CFG_MAX_ERRORS) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(e->line[e->count], CFG_ERR_MAX, fmt, ap);
		va_end(ap);
	}
	e->count++;
}

/* ---- modes and enums ------------------------------------------------------------ */
static const char *const cfg_mode_names[CFG_NMODES] = { "LIMP", "HOLD", "SINUSOID", "OSCILLATOR" };

const char *cfg_commands_name(enum cfg_commands c)
{
	return c == CFG_CMD_OFF ? "off" : c == CFG_CMD_NETWORK ? "network" : "local";
}

const char *cfg_protocol_name(enum cfg_protocol p)
{
	return p == CFG_PROTO_1 ? "1" : p == CFG_PROTO_2 ? "2" : "auto";
}

uint8_t cfg_watchdog_units(const struct cfg *c)
{
	return c->bus_watchdog_ms > 0 ? (uint8_t)((c->bus_watchdog_ms + 19) / 20) : 0;
}

const char *cfg_mode_name(enum cfg_mode m)
{
	return (unsigned)m < CFG_NMODES ? cfg_mode_names[m] : "UNKNOWN";
}

bool cfg_mode_parse(const char *s, enum cfg_mode *out)
{
	for (int m = 0; m < CFG_NMODES; m++) {
		if (strcasecmp(s, cfg_mode_names[m]) == 0) {
			*out = (enum cfg_mode)m;
			return true;
		}
	}
	return false;
}

/* ---- value parsers: each writes a reason on failure ------------------------------- */
static bool parse_double(const char *s, double *out)
{
	char *end;
	errno = 0;
	double v = strtod(s, &end);
	while (*end == ' ' || *end == '\t')
		end++;
	if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v))
		return false;
	*out = v;
	return true;
}

static bool parse_long(const char *s, long *out)
{
	char *end;
	errno = 0;
	long v = strtol(s, &end, 10);
	while (*end == ' ' || *end == '\t')
		end++;
	if (end == s || *end != '\0' || errno == ERANGE)
		return false;
	*out = v;
	return true;
}

static bool parse_bool(const char *s, bool *out)
{
	static const char *const yes[] = { "on", "yes", "true", "1" };
	static const char *const no[] = { "off", "no", "false", "0" };
	for (size_t i = 0; i < 4; i++) {
		if (strcasecmp(s, yes[i]) == 0) { *out = true; return true; }
		if (strcasecmp(s, no[i]) == 0) { *out = false; return true; }
	}
	return false;
}

static struct cfg_bus *cfg_bus_named(struct cfg *c, const char *name, size_t len, char *why, size_t cap);

/* "1,2" or "1 2": servo IDs 0..253, in the robot's joint order; "NAME:3" is
 * servo 3 on the bus of [bus.NAME] (without a name: the [robot] port). An ID
 * twice on one bus is refused; different buses may reuse IDs. */
/* Parses into lists of its own and copies them out only when the whole list
 * is good: a refused value leaves the configured IDs as they were. */
static bool parse_ids(struct cfg *c, const char *s, char *why, size_t cap)
{
	uint8_t ids[CFG_MAX_JOINTS];
	size_t bus[CFG_MAX_JOINTS];
	size_t count = 0;
	const char *p = s;
	while (*p) {
		while (*p == ' ' || *p == ',' || *p == '\t')
			p++;
		if (!*p)
			break;
		size_t b = CFG_BUS_ROBOT;
		const char *colon = p;
		while (*colon && *colon != ':' && *colon != ',' && *colon != ' ' && *colon != '\t')
			colon++;
		if (*colon == ':') {
			const struct cfg_bus *named = cfg_bus_named(c, p, (size_t)(colon - p), why, cap);
			if (named == NULL)
				return false;
			b = (size_t)(named - c->bus);
			p = colon + 1;
		}
		char *end;
		errno = 0;
		long v = strtol(p, &end, 10);
		if (end == p || (*end && *end != ',' && *end != ' ' && *end != '\t')) {
			snprintf(why, cap, "not a list of servo IDs '%s'", s);
			return false;
		}
		if (v < 0 || v > 253) {
			snprintf(why, cap, "servo ID %ld out of range 0..253", v);
			return false;
		}
		if (count == CFG_MAX_JOINTS) {
			snprintf(why, cap, "more than %d servo IDs", CFG_MAX_JOINTS);
			return false;
		}
		for (size_t i = 0; i < count; i++) {
			if (ids[i] == v && bus[i] == b) {
				if (b == CFG_BUS_ROBOT)
					snprintf(why, cap, "servo ID %ld listed twice", v);
				else
					snprintf(why, cap, "servo ID %ld listed twice on bus %s (an ID may repeat only on "
					         "different buses)", v, c->bus[b].name);
				return false;
			}
		}
		bus[count] = b;
		ids[count++] = (uint8_t)v;
		p = end;
	}
	if (count == 0) {
		snprintf(why, cap, "no servo IDs in '%s'", s);
		return false;
	}
	memcpy(c->ids, ids, count);
	memcpy(c->joint_bus, bus, count * sizeof bus[0]);
	c->njoints = count;
	return true;
}

/* ---- parameter ranges: common/params.h, one table with the programs that send commands ---- */
bool cfg_param_range(const char *key, struct param_range *out)
{
	const struct param_def *d = param_find(key);
	if (d == NULL)
		return false;
	*out = d->range;
	return true;
}

bool cfg_param_commandable(const char *key)
{
	const struct param_def *d = param_find(key);
	return d != NULL && d->commandable;
}

const char *cfg_param_commandable_list(void)
{
	return "k, c, mu, lambda, coupling_phase, inertia, friction (per joint), amplitude, frequency, phase, "
	       "stiffness, damping (sinusoid)";
}

double *cfg_robot_param(struct cfg *c, const char *key)
{
	if (strcmp(key, "amplitude") == 0) return &c->amplitude;
	if (strcmp(key, "frequency") == 0) return &c->frequency;
	if (strcmp(key, "phase") == 0) return &c->phase;
	if (strcmp(key, "stiffness") == 0) return &c->sin_stiffness;
	if (strcmp(key, "damping") == 0) return &c->sin_damping;
	return NULL;
}

bool cfg_robot_param_check(const struct cfg *c, const char *key, double value, char *why, size_t cap)
{
	if (strcmp(key, "stiffness") == 0 && value > 0.0 && c->actuation != CFG_ACT_TORQUE) {
		snprintf(why, cap, "stiffness %g drives the clock as a torque: it needs [robot] actuation = torque "
		         "(with position actuation SINUSOID follows the clock with the servo's position loop)", value);
		return false;
	}
	return true;
}

bool cfg_joint_check(const struct cfg_joint *j, char *why, size_t cap)
{
	double hz = sqrt(j->osc.k / j->osc.inertia) / (2.0 * CFG_PI);
	if (!(hz <= CFG_MAX_NATURAL_HZ)) {
		snprintf(why, cap, "k %g and inertia %g give a natural frequency of %.3g Hz, above %g Hz", j->osc.k,
		         j->osc.inertia, hz, CFG_MAX_NATURAL_HZ);
		return false;
	}
	return true;
}

bool cfg_param_is_joint(const char *key)
{
	const struct param_def *d = param_find(key);
	return d != NULL && d->joint;
}

bool cfg_param_is_robot(const char *key)
{
	const struct param_def *d = param_find(key);
	return d != NULL && !d->joint;
}

/* A joint's oscillator parameter by name: the commandable ones. */
static double *cfg_osc_param(struct osc_joint_params *o, const char *key)
{
	if (strcmp(key, "k") == 0) return &o->k;
	if (strcmp(key, "c") == 0) return &o->c;
	if (strcmp(key, "mu") == 0) return &o->mu;
	if (strcmp(key, "lambda") == 0) return &o->lambda;
	if (strcmp(key, "coupling_phase") == 0) return &o->coupling_phase;
	if (strcmp(key, "inertia") == 0) return &o->inertia;
	if (strcmp(key, "friction") == 0) return &o->friction;
	return NULL;
}

double *cfg_joint_param(struct cfg_joint *j, const char *key)
{
	double *osc = cfg_osc_param(&j->osc, key);
	if (osc != NULL)
		return osc;
	if (strcmp(key, "neutral") == 0) return &j->neutral;
	if (strcmp(key, "limit_min") == 0) return &j->limit_min;
	if (strcmp(key, "limit_max") == 0) return &j->limit_max;
	if (strcmp(key, "max_step") == 0) return &j->max_step;
	return NULL;
}

void cfg_params_init(struct cfg_params *p, const struct cfg *c)
{
	memset(p, 0, sizeof *p);
	for (size_t j = 0; j < c->njoints && j < CFG_MAX_JOINTS; j++)
		p->osc[j] = c->joint[j].osc;
	p->servo_lead_s = c->servo_lead_s;
	p->amplitude = c->amplitude;
	p->frequency = c->frequency;
	p->phase = c->phase;
	p->sin_stiffness = c->sin_stiffness;
	p->sin_damping = c->sin_damping;
}

void cfg_params_put(struct cfg *c, const struct cfg_params *p)
{
	for (size_t j = 0; j < c->njoints && j < CFG_MAX_JOINTS; j++)
		c->joint[j].osc = p->osc[j];
	c->servo_lead_s = p->servo_lead_s;
	c->amplitude = p->amplitude;
	c->frequency = p->frequency;
	c->phase = p->phase;
	c->sin_stiffness = p->sin_stiffness;
	c->sin_damping = p->sin_damping;
}

double *cfg_params_field(struct cfg_params *p, const char *key, size_t j)
{
	if (strcmp(key, "amplitude") == 0) return &p->amplitude;
	if (strcmp(key, "frequency") == 0) return &p->frequency;
	if (strcmp(key, "phase") == 0) return &p->phase;
	if (strcmp(key, "stiffness") == 0) return &p->sin_stiffness;
	if (strcmp(key, "damping") == 0) return &p->sin_damping;
	if (strcmp(key, "servo_lead_s") == 0) return &p->servo_lead_s;
	return j < CFG_MAX_JOINTS ? cfg_osc_param(&p->osc[j], key) : NULL;
}

bool cfg_params_check(const struct cfg *c, const struct cfg_params *live, const char *key, int joint, double value,
                      char *why, size_t cap)
{
	struct param_range range = { 0.0, CFG_LEAD_MAX_S, false };
	bool lead = strcmp(key, "servo_lead_s") == 0;
	if (!lead && (!cfg_param_range(key, &range) || !cfg_param_commandable(key))) {
		snprintf(why, cap, "parameter %s cannot be changed while the robot runs", key);
		return false;
	}
	if (!isfinite(value)) {
		snprintf(why, cap, "parameter %s: value is not finite", key);
		return false;
	}
	bool robot = lead || cfg_param_is_robot(key);
	if (robot && joint != -1) {
		snprintf(why, cap, "parameter %s is per robot: joint must be -1, not %d", key, joint);
		return false;
	}
	if (!robot && (joint < -1 || joint >= (int)c->njoints)) {
		snprintf(why, cap, "parameter %s: joint %d does not exist (0..%zu, or -1 for all)", key, joint,
		         c->njoints - 1);
		return false;
	}
	if (!param_in_range(&range, value)) {
		char shown[48];
		snprintf(why, cap, "parameter %s: %g out of range %s", key, value,
		         param_range_format(&range, shown, sizeof shown));
		return false;
	}
	if (lead)
		return true;
	char inner[200];
	if (robot) {
		if (cfg_robot_param_check(c, key, value, inner, sizeof inner))
			return true;
		snprintf(why, cap, "parameter %s: %s", key, inner);
		return false;
	}
	/* what the range table cannot express: the joint's parameters together */
	size_t first = joint < 0 ? 0 : (size_t)joint;
	size_t last = joint < 0 ? c->njoints : first + 1;
	for (size_t j = first; j < last; j++) {
		struct cfg_joint jt = c->joint[j];
		jt.osc = live->osc[j];
		*cfg_osc_param(&jt.osc, key) = value;
		if (!cfg_joint_check(&jt, inner, sizeof inner)) {
			snprintf(why, cap, "parameter %s: joint %zu: %s", key, j, inner);
			return false;
		}
	}
	return true;
}


/* ---- defaults ----------------------------------------------------------------------- */
void cfg_defaults(struct cfg *c)
{
	memset(c, 0, sizeof *c);
	snprintf(c->name, sizeof c->name, "robot");
	snprintf(c->bus[CFG_BUS_ROBOT].name, sizeof c->bus[CFG_BUS_ROBOT].name, "robot");
	c->nbuses = 1;
	c->baud = 1000000;
	/* A robot started without a mode (the first `undulated --port ... --ids
	 * ...` on new hardware) holds where it stands: nothing swings before the
	 * person at the robot has seen it answer and asked for it. */
	c->mode = CFG_MODE_HOLD;
	c->safe_stop = CFG_SAFE_HOLD;
	c->fault_action = CFG_SAFE_HOLD;
	c->velocity_source = CFG_VEL_FILTERED;
	c->velocity_cutoff_hz = OSC_VELOCITY_CUTOFF_HZ;
	/* Margin 0: with the factory dead band of 1 unit (5 mrad), a joint that
	 * comes to rest near neutral stays there, each predicted step being inside
	 * the dead band (CONTROL.md). The lead then follows the margin. */
	c->compliance_margin = 0;
	/* The servo's own slope (factory 32) unless the file sets one. */
	c->compliance_slope = -1;
	c->servo_lead_s = NAN;
	c->actuation = CFG_ACT_POSITION;
	c->torque_drive = CFG_DRIVE_PWM;
	/* The AX-12A's datasheet line at 12 V. */
	const struct dxl2_datasheet *ax = &dxl2_model_find(1, DXL_AX12_MODEL)->sheet;
	c->stall_torque = ax->stall_torque_nm;
	c->no_load_speed = dxl2_sheet_no_load_rad_s(ax);
	/* Replies on a loaded 2-core machine (simulator, tests) come up to ~3 ms
	 * late; a real adapter with return delay 0 needs far less. */
	c->bus_margin_us = 3000;
	c->commands = CFG_CMD_LOCAL;
	c->command_window_s = 2.0;
	/* Five periods of 10 ms stale are a hold; half a second is a servo gone
	 * (a bus reconnect takes 0.01-0.15 s, tests/integration/daemon_bus.sh). */
	c->silent_s = 0.5;
	/* An X servo stops by itself when nothing reached it for 100 ms: ten
	 * periods of 10 ms, longer than a late cycle on a loaded machine (tens of
	 * ms), short enough that a joint at the gait's peak speed (≈ 4 rad/s)
	 * moves at most about 0.4 rad under a controller that went quiet. */
	c->bus_watchdog_ms = CFG_WATCHDOG_UNSET;   /* CFG_WATCHDOG_DEFAULT, or ten periods: cfg_finish */
	/* One REBOOT after a hardware-error shutdown: a transient (a collision's
	 * overload, a supply dip) recovers without the operator; a second
	 * shutdown means the cause is still there, and the fault latches. */
	c->fault_reboots = 1;
	c->indirect = true;   /* 8 bytes a servo less every other cycle (daemon/CONTROL.md) */
	c->adapter_latency_us = -1;
	c->period_ms = 10.0;
	c->ramp_s = 1.5;
	c->backoff_torque = 0.5;
	c->fault_backoff_s = 1.0;
	c->fault_retries = 3;
	c->stale_limit = 10;
	/* Joint values stay NaN until cfg_finish() knows how many joints there are:
	 * the oscillator's defaults depend on it (coupling λ). */
	for (size_t j = 0; j < CFG_MAX_JOINTS; j++) {
		struct cfg_joint *jt = &c->joint[j];
		jt->osc.k = jt->osc.c = jt->osc.mu = jt->osc.lambda = NAN;
		jt->osc.inertia = jt->osc.friction = jt->osc.coupling_phase = NAN;
		jt->neutral = NAN;
		jt->limit_min = NAN;
		jt->limit_max = NAN;
		jt->max_step = NAN;
	}
	/* The paper's baseline: 0.8 rad at 0.8 Hz. */
	c->amplitude = 0.8;
	c->frequency = 0.8;
	c->phase = 0.0;
	/* SINUSOID through the servo's position loop unless a stiffness is given */
	c->sin_stiffness = 0.0;
	c->sin_damping = 0.0;
}

/* ---- [robot] keys --------------------------------------------------------------------- */
enum cfg_type { T_STR, T_LONG, T_DOUBLE, T_BOOL, T_IDS, T_MODE, T_SAFE, T_VEL, T_ACT, T_DRIVE, T_CMDS, T_RS485,
                T_PROTO };
struct cfg_key {
	const char *key;
	enum cfg_type type;
	size_t offset;
	size_t size;          /* strings: buffer size */
	double min, max;      /* numbers */
};
#define K(name, type, field, min, max) \
	{ name, type, offsetof(struct cfg, field), sizeof(((struct cfg *)0)->field), min, max }
static const struct cfg_key cfg_robot_keys[] = {
	K("name", T_STR, name, 0, 0),
	K("port", T_STR, port, 0, 0),
	K("usb_serial", T_STR, usb_serial, 0, 0),
	K("baud", T_LONG, baud, 9600, 4500000),
	K("protocol", T_PROTO, protocol, 0, 0),
	K("ids", T_IDS, ids, 0, 0),
	K("mode", T_MODE, mode, 0, 0),
	K("lcm_url", T_STR, lcm_url, 0, 0),
	K("priority", T_LONG, priority, 0, 99),
	K("mlockall", T_BOOL, mlockall, 0, 0),
	K("safe_stop", T_SAFE, safe_stop, 0, 0),
	K("fault_action", T_SAFE, fault_action, 0, 0),
	K("velocity_source", T_VEL, velocity_source, 0, 0),
	K("velocity_cutoff_hz", T_DOUBLE, velocity_cutoff_hz, 0.5, 50),
	K("commands", T_CMDS, commands, 0, 0),
	K("command_key", T_STR, command_key, 0, 0),
	K("command_window_s", T_DOUBLE, command_window_s, 0.05, 60),
	K("run_dir", T_STR, run_dir, 0, 0),
	K("echo", T_BOOL, echo, 0, 0),
	K("rs485", T_RS485, rs485, 0, 0),
	K("adapter_latency_us", T_LONG, adapter_latency_us, -1, 100000),
	K("period_ms", T_DOUBLE, period_ms, 1, 100),
	K("servo_lead_s", T_DOUBLE, servo_lead_s, 0, CFG_LEAD_MAX_S),
	K("compliance_margin", T_LONG, compliance_margin, -1, 255),
	K("compliance_slope", T_LONG, compliance_slope, -1, 254),
	K("actuation", T_ACT, actuation, 0, 0),
	K("torque_drive", T_DRIVE, torque_drive, 0, 0),
	K("stall_torque", T_DOUBLE, stall_torque, 0.01, 100),
	K("no_load_speed", T_DOUBLE, no_load_speed, 0.01, 1000),
	K("bus_margin_us", T_LONG, bus_margin_us, 0, 100000),
	K("lockstep", T_STR, lockstep, 0, 0),
	K("ramp_s", T_DOUBLE, ramp_s, 0, 10),
	K("backoff_torque", T_DOUBLE, backoff_torque, 0, 1),
	K("fault_backoff_s", T_DOUBLE, fault_backoff_s, 0.05, 600),
	K("fault_retries", T_LONG, fault_retries, 0, 100),
	K("stale_limit", T_LONG, stale_limit, 1, 1000),
	K("silent_s", T_DOUBLE, silent_s, 0.05, 60),
	K("bus_watchdog_ms", T_LONG, bus_watchdog_ms, -1, 2540),
	K("fault_reboots", T_LONG, fault_reboots, 0, 100),
	K("indirect", T_BOOL, indirect, 0, 0),
};
#undef K
#define CFG_NROBOT_KEYS (sizeof cfg_robot_keys / sizeof cfg_robot_keys[0])

static bool cfg_set_robot(struct cfg *c, const char *where, const char *key, const char *value,
                          struct cfg_errors *e)
{
	const struct cfg_key *k = NULL;
	for (size_t i = 0; i < CFG_NROBOT_KEYS; i++)
		if (strcmp(key, cfg_robot_keys[i].key) == 0)
			k = &cfg_robot_keys[i];
	if (k == NULL) {
		cfg_error(e, "%s: [robot] %s: unknown key", where, key);
		return false;
	}
	void *field = (char *)c + k->offset;
	char why[128];
	long lv;
	double dv;
	bool bv;
	switch (k->type) {
	case T_STR:
		if (strlen(value) >= k->size) {
			cfg_error(e, "%s: [robot] %s: longer than %zu characters", where, key, k->size - 1);
			return false;
		}
		/* The monitors make robots only of such names (text_is_name): a
		 * robot named otherwise would run unseen, or prefix channels with '/'. */
		if (strcmp(key, "name") == 0 && !text_is_name(value, CFG_NAME_MAX - 1)) {
			char shown[CFG_NAME_MAX];
			cfg_error(e, "%s: [robot] name: '%s' must be letters, digits, '_' or '-' "
			          "(it prefixes LCM channels)", where, text_line(shown, sizeof shown, value));
			return false;
		}
		memcpy(field, value, strlen(value) + 1);
		return true;
	case T_LONG:
		if (!parse_long(value, &lv)) {
			cfg_error(e, "%s: [robot] %s: not an integer '%s'", where, key, value);
			return false;
		}
		if (lv < k->min || lv > k->max) {
			cfg_error(e, "%s: [robot] %s: %ld out of range %.0f..%.0f", where, key, lv, k->min, k->max);
			return false;
		}
		if (k->size == sizeof(int))
			*(int *)field = (int)lv;
		else
			*(long *)field = lv;
		return true;
	case T_DOUBLE:
		if (!parse_double(value, &dv)) {
			cfg_error(e, "%s: [robot] %s: not a number '%s'", where, key, value);
			return false;
		}
		if (dv < k->min || dv > k->max) {
			cfg_error(e, "%s: [robot] %s: %g out of range %g..%g", where, key, dv, k->min, k->max);
			return false;
		}
		*(double *)field = dv;
		if (strcmp(key, "stall_torque") == 0)
			c->stall_torque_given = true;
		if (strcmp(key, "no_load_speed") == 0)
			c->no_load_speed_given = true;
		return true;
	case T_BOOL:
		if (!parse_bool(value, &bv)) {
			cfg_error(e, "%s: [robot] %s: not on/off '%s'", where, key, value);
			return false;
		}
		*(bool *)field = bv;
		return true;
	case T_IDS:
		if (!parse_ids(c, value, why, sizeof why)) {
			cfg_error(e, "%s: [robot] ids: %s", where, why);
			return false;
		}
		return true;
	case T_MODE:
		if (!cfg_mode_parse(value, &c->mode)) {
			cfg_error(e, "%s: [robot] mode: '%s' is not limp, hold, sinusoid or oscillator", where, value);
			return false;
		}
		c->mode_given = true;
		return true;
	case T_SAFE:
		if (strcasecmp(value, "hold") == 0)
			*(enum cfg_safe *)field = CFG_SAFE_HOLD;
		else if (strcasecmp(value, "limp") == 0)
			*(enum cfg_safe *)field = CFG_SAFE_LIMP;
		else {
			cfg_error(e, "%s: [robot] %s: '%s' is not hold or limp", where, key, value);
			return false;
		}
		return true;
	case T_VEL:
		if (strcasecmp(value, "servo") == 0)
			c->velocity_source = CFG_VEL_SERVO;
		else if (strcasecmp(value, "filtered") == 0)
			c->velocity_source = CFG_VEL_FILTERED;
		else {
			cfg_error(e, "%s: [robot] velocity_source: '%s' is not servo or filtered", where, value);
			return false;
		}
		return true;
	case T_ACT:
		if (strcasecmp(value, "position") == 0)
			c->actuation = CFG_ACT_POSITION;
		else if (strcasecmp(value, "torque") == 0)
			c->actuation = CFG_ACT_TORQUE;
		else {
			cfg_error(e, "%s: [robot] actuation: '%s' is not position or torque", where, value);
			return false;
		}
		return true;
	case T_CMDS:
		/* "on" is what this key took before commands left the network */
		if (strcasecmp(value, "local") == 0 || strcasecmp(value, "on") == 0)
			c->commands = CFG_CMD_LOCAL;
		else if (strcasecmp(value, "network") == 0)
			c->commands = CFG_CMD_NETWORK;
		else if (strcasecmp(value, "off") == 0)
			c->commands = CFG_CMD_OFF;
		else {
			cfg_error(e, "%s: [robot] commands: '%s' is not off, local or network", where, value);
			return false;
		}
		return true;
	case T_RS485:
		if (!port_rs485_parse(value, &c->rs485)) {
			cfg_error(e, "%s: [robot] rs485: '%s' is not off, rts-on-send (or rts) or rts-after-send", where,
			          value);
			return false;
		}
		return true;
	case T_PROTO:
		if (strcmp(value, "1") == 0 || strcmp(value, "1.0") == 0)
			c->protocol = CFG_PROTO_1;
		else if (strcmp(value, "2") == 0 || strcmp(value, "2.0") == 0)
			c->protocol = CFG_PROTO_2;
		else if (strcasecmp(value, "auto") == 0)
			c->protocol = CFG_PROTO_AUTO;
		else {
			cfg_error(e, "%s: [robot] protocol: '%s' is not 1, 2 or auto", where, value);
			return false;
		}
		return true;
	case T_DRIVE:
		if (strcasecmp(value, "pwm") == 0)
			c->torque_drive = CFG_DRIVE_PWM;
		else if (strcasecmp(value, "current") == 0)
			c->torque_drive = CFG_DRIVE_CURRENT;
		else {
			cfg_error(e, "%s: [robot] torque_drive: '%s' is not pwm or current", where, value);
			return false;
		}
		return true;
	}
	return false;
}

static bool cfg_set_param(double *field, const char *where, const char *section, const char *key,
                          const char *value, struct cfg_errors *e)
{
	const struct param_def *d = param_find(key);
	double v;
	if (!parse_double(value, &v)) {
		cfg_error(e, "%s: [%s] %s: not a number '%s'", where, section, key, value);
		return false;
	}
	if (!param_in_range(&d->range, v)) {
		char shown[48];
		cfg_error(e, "%s: [%s] %s: %g out of range %s", where, section, key, v,
		          param_range_format(&d->range, shown, sizeof shown));
		return false;
	}
	*field = v;
	return true;
}

/* ---- [bus.NAME]: a port of its own for some of the robot's joints ------------------------- */
/* The bus named `name` (len characters): found, or a new one (at most
 * CFG_MAX_BUSES - 1 beside the [robot] port), named in [robot] ids before
 * its section or by its section. NULL with *why. */
static struct cfg_bus *cfg_bus_named(struct cfg *c, const char *name, size_t len, char *why, size_t cap)
{
	char own[CFG_NAME_MAX];
	if (len == 0 || len >= sizeof own) {
		snprintf(why, cap, "a bus name is 1..%d characters", CFG_NAME_MAX - 1);
		return NULL;
	}
	memcpy(own, name, len);
	own[len] = '\0';
	if (!text_is_name(own, CFG_NAME_MAX - 1) || strcmp(own, "robot") == 0) {
		char shown[CFG_NAME_MAX];
		snprintf(why, cap, "bus '%s': a bus is named by letters, digits, '_' or '-', and not 'robot' (the [robot] "
		         "section's own port)", text_line(shown, sizeof shown, own));
		return NULL;
	}
	for (size_t b = 1; b < c->nbuses; b++)
		if (strcmp(c->bus[b].name, own) == 0)
			return &c->bus[b];
	if (c->nbuses >= CFG_MAX_BUSES) {
		snprintf(why, cap, "bus %s: more than %d buses: a robot has at most %d ports (the [robot] port and %d "
		         "[bus.NAME] sections)", own, CFG_MAX_BUSES, CFG_MAX_BUSES, CFG_MAX_BUSES - 1);
		return NULL;
	}
	struct cfg_bus *bus = &c->bus[c->nbuses++];
	memset(bus, 0, sizeof *bus);
	snprintf(bus->name, sizeof bus->name, "%s", own);
	return bus;
}

static bool cfg_bus_string(char *field, size_t size, const char *where, const char *section, const char *key,
                           const char *value, struct cfg_errors *e)
{
	if (strlen(value) >= size) {
		cfg_error(e, "%s: [%s] %s: longer than %zu characters", where, section, key, size - 1);
		return false;
	}
	memcpy(field, value, strlen(value) + 1);
	return true;
}

static bool cfg_set_bus(struct cfg *c, const char *where, const char *section, const char *key, const char *value,
                        struct cfg_errors *e)
{
	char why[200];
	struct cfg_bus *bus = cfg_bus_named(c, section + 4, strlen(section + 4), why, sizeof why);
	if (bus == NULL) {
		char shown[CFG_NAME_MAX + 8];
		cfg_error(e, "%s: [%s]: %s", where, text_line(shown, sizeof shown, section), why);
		return false;
	}
	long lv;
	if (strcmp(key, "port") == 0)
		return cfg_bus_string(bus->port, sizeof bus->port, where, section, key, value, e);
	if (strcmp(key, "usb_serial") == 0)
		return cfg_bus_string(bus->usb_serial, sizeof bus->usb_serial, where, section, key, value, e);
	if (strcmp(key, "baud") == 0) {
		if (!parse_long(value, &lv)) {
			cfg_error(e, "%s: [%s] baud: not an integer '%s'", where, section, value);
			return false;
		}
		if (lv < 9600 || lv > 4500000) {
			cfg_error(e, "%s: [%s] baud: %ld out of range 9600..4500000", where, section, lv);
			return false;
		}
		bus->baud = lv;
		return true;
	}
	cfg_error(e, "%s: [%s] %s: unknown key (port, usb_serial, baud; its joints are named in [robot] ids, "
	          "e.g. ids = 1, 2, %s:1, %s:2)", where, section, key, bus->name, bus->name);
	return false;
}

bool cfg_set(struct cfg *c, const char *where, const char *section, const char *key,
             const char *value, struct cfg_errors *e)
{
	if (strcmp(section, "robot") == 0)
		return cfg_set_robot(c, where, key, value, e);
	if (strcmp(section, "sinusoid") == 0) {
		double *f = cfg_robot_param(c, key);
		if (f == NULL) {
			cfg_error(e, "%s: [sinusoid] %s: unknown key (amplitude, frequency, phase, stiffness, damping)",
			          where, key);
			return false;
		}
		return cfg_set_param(f, where, section, key, value, e);
	}
	if (strncmp(section, "joint.", 6) == 0) {
		long n;
		if (!parse_long(section + 6, &n) || n < 1 || n > CFG_MAX_JOINTS) {
			cfg_error(e, "%s: [%s]: joint sections are [joint.1] .. [joint.%d]", where, section,
			          CFG_MAX_JOINTS);
			return false;
		}
		double *f = cfg_joint_param(&c->joint[n - 1], key);
		if (f == NULL) {
			cfg_error(e, "%s: [%s] %s: unknown key", where, section, key);
			return false;
		}
		return cfg_set_param(f, where, section, key, value, e);
	}
	if (strncmp(section, "bus.", 4) == 0)
		return cfg_set_bus(c, where, section, key, value, e);
	cfg_error(e, "%s: [%s]: unknown section (robot, joint.N, sinusoid)", where, section);
	return false;
}

/* ---- INI parsing: a line-counting reader so every handler call knows its line ---------- */
/* A key or section given twice is an error: inih hands every occurrence to
 * the handler, and the last would silently win (a second limit_max widening
 * a joint). Names are inih's at most 49 characters. A valid file names at
 * most CFG_NROBOT_KEYS + 3 + CFG_MAX_JOINTS × 10 keys (282) in at most
 * 2 + CFG_MAX_JOINTS sections: a file that fills these tables has errors
 * already, whatever is not recorded. */
#define CFG_INI_NAME 52
#define CFG_SEEN_SECTIONS 64
#define CFG_SEEN_KEYS 512
struct cfg_seen_key {
	int section;              /* index in cfg_parse.sections */
	char name[CFG_INI_NAME];
	int line;
};

struct cfg_parse {
	struct cfg *cfg;
	struct cfg_errors *errors;
	const char *name;
	const char *text;   /* what is left to read */
	int line;
	int long_line;   /* first physical line too long for inih, 0 if none */
	int line_cap;    /* the longest line inih reads (its buffer less the NUL) */
	/* the physical line inih is handed, as inih will read it (cfg_note_line) */
	bool continuation;  /* an indented line after a key: inih's multi-line value */
	bool key_since_header;
	int section;        /* the current section's index in sections, -1 before the first */
	int key_line;       /* the last key's line */
	struct { char name[CFG_INI_NAME]; int line; } sections[CFG_SEEN_SECTIONS];
	size_t nsections;
	struct cfg_seen_key keys[CFG_SEEN_KEYS];
	size_t nkeys;
};

/* A section header at `line`: recorded, or refused when given before. */
static void cfg_note_section(struct cfg_parse *p, const char *name, size_t len)
{
	if (len >= CFG_INI_NAME)
		len = CFG_INI_NAME - 1;
	for (size_t i = 0; i < p->nsections; i++) {
		if (strlen(p->sections[i].name) == len && strncmp(p->sections[i].name, name, len) == 0) {
			cfg_error(p->errors, "%s:%d: [%s]: section given twice (first at line %d): give each section once",
			          p->name, p->line, p->sections[i].name, p->sections[i].line);
			p->section = (int)i;   /* its keys are the first one's: a key in both is given twice */
			return;
		}
	}
	if (p->nsections == CFG_SEEN_SECTIONS) {
		p->section = -1;
		return;
	}
	memcpy(p->sections[p->nsections].name, name, len);
	p->sections[p->nsections].name[len] = '\0';
	p->sections[p->nsections].line = p->line;
	p->section = (int)p->nsections++;
}

/* What inih will make of the physical line it is handed next (ini.c's own
 * rules): a UTF-8 BOM at the start of the file skipped; blank and comment
 * lines (';', '#') nothing; an indented line after a key the key's value
 * continued; '[' a section header when a ']' closes it; anything else a key. */
static void cfg_note_line(struct cfg_parse *p, const char *line)
{
	const char *s = line;
	if (p->line == 1 && strncmp(s, "\xEF\xBB\xBF", 3) == 0)
		s += 3;
	const char *start = s;
	while (*start != '\0' && isspace((unsigned char)*start))
		start++;
	p->continuation = false;
	if (*start == '\0' || *start == ';' || *start == '#')
		return;
	if (start > s && p->key_since_header) {
		p->continuation = true;
		return;
	}
	if (*start == '[') {
		const char *end = strchr(start + 1, ']');
		if (end != NULL) {
			cfg_note_section(p, start + 1, (size_t)(end - start - 1));
			p->key_since_header = false;
		}
		return;
	}
	p->key_since_header = strpbrk(start, "=:") != NULL;
}

/* A key of the current section: true when it is its first occurrence. */
static bool cfg_note_key(struct cfg_parse *p, const char *section, const char *key, const char *where)
{
	if (p->section < 0)
		return true;
	for (size_t i = 0; i < p->nkeys; i++) {
		if (p->keys[i].section == p->section && strcmp(p->keys[i].name, key) == 0) {
			cfg_error(p->errors, "%s: [%s] %s: given twice (first at line %d): give each key once", where, section,
			          key, p->keys[i].line);
			return false;
		}
	}
	if (p->nkeys < CFG_SEEN_KEYS) {
		struct cfg_seen_key *k = &p->keys[p->nkeys++];
		k->section = p->section;
		snprintf(k->name, sizeof k->name, "%s", key);
		k->line = p->line;
	}
	return true;
}

/* Drops the rest of a physical line that did not fit inih's buffer, so that
 * inih sees one line per physical line (its own line numbers stay right) and
 * the tail of a long line is never parsed as a key of its own. */
static void cfg_skip_rest_of_line(struct cfg_parse *p)
{
	while (*p->text != '\0' && *p->text++ != '\n')
		;
}

static char *cfg_reader(char *str, int num, void *stream)
{
	struct cfg_parse *p = stream;
	if (*p->text == '\0')
		return NULL;
	int i = 0;
	while (i < num - 1 && p->text[0] != '\0') {
		str[i++] = *p->text++;
		if (str[i - 1] == '\n')
			break;
	}
	str[i] = '\0';
	p->line++;
	cfg_note_line(p, str);
	/* a read that fills the buffer without a newline is a line too long for
	 * inih, unless the line ends right there: num - 1 characters fit (the
	 * README's 199), handed over without their newline */
	bool full = i > 0 && i == num - 1 && str[i - 1] != '\n';
	if (full && (*p->text == '\n' || *p->text == '\0')) {
		p->text += *p->text == '\n';
	} else if (full) {
		cfg_skip_rest_of_line(p);
		if (p->long_line == 0) {
			p->long_line = p->line;
			p->line_cap = num - 1;
		}
	}
	return str;
}

static int cfg_handler(void *user, const char *section, const char *name, const char *value)
{
	struct cfg_parse *p = user;
	char where[CFG_PATH_MAX + 16];
	snprintf(where, sizeof where, "%s:%d", p->name, p->line);
	if (section[0] == '\0') {
		cfg_error(p->errors, "%s: %s: key outside any section (start with [robot])", where, name);
		return 1;
	}
	if (p->continuation) {
		cfg_error(p->errors, "%s: [%s] %s: an indented line continues the value of line %d: a value is one line "
		          "(remove the indentation)", where, section, name, p->key_line);
		return 1;
	}
	p->key_line = p->line;
	if (cfg_note_key(p, section, name, where))
		cfg_set(p->cfg, where, section, name, value, p->errors);
	return 1;   /* keep going: report every error in one run */
}

static bool cfg_parse_run(struct cfg_parse *p)
{
	int rc = ini_parse_stream(cfg_reader, p, cfg_handler, p);
	if (p->long_line > 0)
		cfg_error(p->errors, "%s:%d: line too long (the parser reads at most %d characters of a line)",
		          p->name, p->long_line, p->line_cap);
	/* our handler never stops the parser, so rc > 0 is inih's own first syntax
	 * error: name it even when the keys after it gave errors of their own
	 * (a "[robot" header makes every key below it "outside any section");
	 * a long line is reported above, with a better reason */
	if (rc > 0 && rc != p->long_line)
		cfg_error(p->errors, "%s:%d: syntax error (expected [section] or key = value)", p->name, rc);
	else if (rc < 0)
		cfg_error(p->errors, "%s: cannot parse (out of memory)", p->name);
	return p->errors->count == 0;
}

bool cfg_load_string(struct cfg *c, const char *name, const char *text, struct cfg_errors *errors)
{
	struct cfg_parse p = { .cfg = c, .errors = errors, .name = name, .text = text, .section = -1 };
	return cfg_parse_run(&p);
}

bool cfg_load_file(struct cfg *c, const char *path, struct cfg_errors *errors)
{
	/* only a regular file, read whole: a FIFO blocked here, /dev/zero never ended */
	char why[CFG_ERR_MAX];
	size_t len;
	char *text = textfile_read(path, "a configuration", &len, why, sizeof why);
	if (text == NULL) {
		cfg_error(errors, "%s", why);
		errors->file_refused = true;
		return false;
	}
	/* Messages name the file as given, without directories clutter removed:
	 * users copy that path into their editor. */
	struct cfg_parse p = { .cfg = c, .errors = errors, .name = path, .text = text, .section = -1 };
	bool ok = cfg_parse_run(&p);
	free(text);
	snprintf(c->source, sizeof c->source, "%s", path);
	return ok;
}

bool cfg_override(struct cfg *c, const char *assignment, struct cfg_errors *errors)
{
	char buf[CFG_PATH_MAX + 64];
	if (strlen(assignment) >= sizeof buf) {
		cfg_error(errors, "command line: '%.40s...': too long", assignment);
		return false;
	}
	strcpy(buf, assignment);
	char *eq = strchr(buf, '=');
	char *dot = eq ? memchr(buf, '.', (size_t)(eq - buf)) : NULL;
	/* "joint.1.k=..." has its key after the last dot before '=' */
	char *last_dot = NULL;
	for (char *q = buf; eq && q < eq; q++)
		if (*q == '.')
			last_dot = q;
	if (eq == NULL || dot == NULL || last_dot == buf) {
		cfg_error(errors, "command line: '%s': expected section.key=value (e.g. joint.1.k=0.5)",
		          assignment);
		return false;
	}
	*eq = '\0';
	*last_dot = '\0';
	const char *section = buf, *key = last_dot + 1, *value = eq + 1;
	return cfg_set(c, "command line", section, key, value, errors);
}

/* ---- whole-config checks ------------------------------------------------------------------ */
static void cfg_fill_joint_defaults(struct cfg *c)
{
	for (size_t j = 0; j < c->njoints; j++) {
		struct cfg_joint *jt = &c->joint[j];
		struct osc_joint_params d;
		if (c->actuation == CFG_ACT_TORQUE)
			osc_default_torque_params(&d, j, c->njoints, c->torque_drive == CFG_DRIVE_PWM);
		else
			osc_default_params(&d, j, c->njoints);
		if (c->actuation == CFG_ACT_TORQUE)
			jt->torque_defaults = (isnan(jt->osc.k) ? CFG_TQ_K : 0) | (isnan(jt->osc.c) ? CFG_TQ_C : 0) |
			                      (isnan(jt->osc.mu) ? CFG_TQ_MU : 0) | (isnan(jt->osc.inertia) ? CFG_TQ_INERTIA : 0) |
			                      (isnan(jt->osc.friction) ? CFG_TQ_FRICTION : 0);
		else
			jt->position_defaults = (isnan(jt->osc.k) ? CFG_TQ_K : 0) | (isnan(jt->osc.mu) ? CFG_TQ_MU : 0);
		if (isnan(jt->osc.k)) jt->osc.k = d.k;
		if (isnan(jt->osc.c)) jt->osc.c = d.c;
		if (isnan(jt->osc.mu)) jt->osc.mu = d.mu;
		if (isnan(jt->osc.lambda)) jt->osc.lambda = d.lambda;
		if (isnan(jt->osc.coupling_phase)) jt->osc.coupling_phase = d.coupling_phase;
		if (isnan(jt->osc.inertia)) jt->osc.inertia = d.inertia;
		if (isnan(jt->osc.friction)) jt->osc.friction = d.friction;
		if (isnan(jt->neutral)) jt->neutral = 0.0;
		/* ±1.3 rad: room for the 0.8 rad limit cycle and its overshoot, short
		 * of links folding onto each other on the paper's robot. */
		if (isnan(jt->limit_min)) jt->limit_min = -1.3;
		if (isnan(jt->limit_max)) jt->limit_max = 1.3;
		/* 10 rad/s (0.1 rad a cycle at 10 ms): above what an AX-12 can follow
		 * (≈6 rad/s), so it never limits a healthy gait, only jumps; the
		 * same speed at every period_ms (a set max_step is per cycle), within
		 * the key's range (0.5 rad: 5 rad/s at 100 ms, still above the gait's). */
		if (isnan(jt->max_step)) jt->max_step = fmin(CFG_MAX_STEP_SPEED * c->period_ms * 1e-3, 0.5);
	}
}

void cfg_params_scale_torque_defaults(struct cfg_params *p, const struct cfg *c, size_t j, double scale)
{
	struct osc_joint_params *o = &p->osc[j];
	unsigned d = c->joint[j].torque_defaults;
	if (d & CFG_TQ_K) o->k *= scale;
	if (d & CFG_TQ_C) o->c *= scale;
	if (d & CFG_TQ_MU) o->mu *= scale;
	if (d & CFG_TQ_INERTIA) o->inertia *= scale;
	if (d & CFG_TQ_FRICTION) o->friction *= scale;
}

bool cfg_params_position_defaults(struct cfg_params *p, const struct cfg *c, size_t j, double k, double mu)
{
	unsigned d = c->joint[j].position_defaults;
	if (d & CFG_TQ_K) p->osc[j].k = k;
	if (d & CFG_TQ_MU) p->osc[j].mu = mu;
	return d != 0;
}

/* What is counted in time must span a few periods (CFG_MIN_PERIODS): the bus
 * watchdog (the default, 100 ms, stretched to ten periods above 10 ms) and
 * silent_s. At 1 ms both keep their times: safety is said in seconds. */
static void cfg_check_rate(struct cfg *c, struct cfg_errors *e)
{
	const char *src = c->source[0] ? c->source : "command line";
	if (c->bus_watchdog_ms == CFG_WATCHDOG_UNSET)
		c->bus_watchdog_ms = c->period_ms * 10 > CFG_WATCHDOG_DEFAULT ? (long)ceil(c->period_ms * 10)
		                                                            : CFG_WATCHDOG_DEFAULT;
	if (c->bus_watchdog_ms > 0 && c->bus_watchdog_ms < CFG_MIN_PERIODS * c->period_ms)
		cfg_error(e, "%s: [robot] bus_watchdog_ms = %ld is shorter than %d periods of %g ms: one late cycle "
		          "would stop the servos (raise it, or 0 to leave the watchdog off)", src, c->bus_watchdog_ms,
		          CFG_MIN_PERIODS, c->period_ms);
	if (c->silent_s < CFG_MIN_PERIODS * c->period_ms * 1e-3)
		cfg_error(e, "%s: [robot] silent_s = %g is shorter than %d periods of %g ms: one missed reply would "
		          "latch a fault", src, c->silent_s, CFG_MIN_PERIODS, c->period_ms);
}

size_t cfg_buses_used(const struct cfg *c)
{
	size_t n = 0;
	for (size_t b = 0; b < c->nbuses; b++)
		n += c->bus[b].njoints > 0;
	return n;
}

bool cfg_bus_has_joint(const struct cfg *c, size_t bus, size_t joint)
{
	/* a configuration built without cfg_defaults (nbuses 0) has one bus */
	if (c->nbuses <= 1)
		return bus == CFG_BUS_ROBOT && joint < c->njoints;
	return bus < c->nbuses && joint < c->njoints && c->joint_bus[joint] == bus;
}

/* Each bus's joints, from [robot] ids (a joint is on one bus by
 * construction); a bus without a port or without joints is an error. */
static void cfg_assign_buses(struct cfg *c, struct cfg_errors *e)
{
	const char *src = c->source[0] ? c->source : "command line";
	struct cfg_bus *robot = &c->bus[CFG_BUS_ROBOT];
	snprintf(robot->port, sizeof robot->port, "%s", c->port);
	snprintf(robot->usb_serial, sizeof robot->usb_serial, "%s", c->usb_serial);
	robot->baud = c->baud;
	for (size_t b = 0; b < c->nbuses; b++)
		c->bus[b].njoints = 0;
	for (size_t j = 0; j < c->njoints; j++) {
		struct cfg_bus *bus = &c->bus[c->joint_bus[j]];
		bus->joints[bus->njoints++] = j;
	}
	for (size_t b = 1; b < c->nbuses; b++) {
		struct cfg_bus *bus = &c->bus[b];
		if (bus->njoints == 0)
			cfg_error(e, "%s: [bus.%s]: no joint is on it: name its servos in [robot] ids (e.g. ids = 1, 2, "
			          "%s:1, %s:2)", src, bus->name, bus->name, bus->name);
		if (bus->port[0] == '\0' && bus->usb_serial[0] == '\0')
			cfg_error(e, "%s: [bus.%s] port: no port configured (a [bus.%s] section with port = /dev/ttyUSB1 or "
			          "usb_serial = ..., or --set bus.%s.port=PATH)", src, bus->name, bus->name, bus->name);
		if (bus->baud == 0)
			bus->baud = c->baud;
	}
}

/* Every bus a port of its own. */
static void cfg_check_buses(struct cfg *c, struct cfg_errors *e)
{
	const char *src = c->source[0] ? c->source : "command line";
	for (size_t a = 0; a < c->nbuses; a++) {
		const struct cfg_bus *x = &c->bus[a];
		for (size_t b = a + 1; b < c->nbuses && x->njoints > 0; b++) {
			const struct cfg_bus *y = &c->bus[b];
			if (x->port[0] != '\0' && strcmp(x->port, y->port) == 0)
				cfg_error(e, "%s: [bus.%s] port: %s is bus %s's port too: each bus is a port of its own", src,
				          y->name, y->port, x->name);
			if (x->usb_serial[0] != '\0' && strcmp(x->usb_serial, y->usb_serial) == 0)
				cfg_error(e, "%s: [bus.%s] usb_serial: %s is bus %s's adapter too: each bus is a port of its own",
				          src, y->name, y->usb_serial, x->name);
		}
	}
	/* each bus of several publishes on "<robot>.BUS.<bus>": LCM takes
	 * channel names of at most CFG_LCM_CHANNEL_MAX characters */
	for (size_t b = 0; b < c->nbuses && cfg_buses_used(c) > 1; b++) {
		size_t len = strlen(c->name) + strlen(".BUS.") + strlen(c->bus[b].name);
		if (c->bus[b].njoints > 0 && len > CFG_LCM_CHANNEL_MAX)
			cfg_error(e, "%s: [bus.%s]: its channel %s.BUS.%s is %zu characters, LCM takes at most %d: give the "
			          "bus or the robot a shorter name", src, c->bus[b].name, c->name, c->bus[b].name, len,
			          CFG_LCM_CHANNEL_MAX);
	}
	/* On a bus lost the other buses' joints hold by their goals (the
	 * oscillators are one chain); torque actuation sends no goal, so they
	 * would go on being driven against a stale reading. */
	if (cfg_buses_used(c) > 1 && c->actuation == CFG_ACT_TORQUE)
		cfg_error(e, "%s: [robot] actuation: torque actuation on several buses is refused: a lost bus holds the "
		          "other buses' joints by their goals, which torque actuation does not send; run it on one bus, "
		          "or in position actuation", src);
}

bool cfg_finish(struct cfg *c, struct cfg_errors *e)
{
	size_t before = e->count;
	if (c->njoints == 0)
		cfg_error(e, "%s: [robot] ids: no servo IDs configured (e.g. ids = 1,2 or --ids 1,2)",
		          c->source[0] ? c->source : "command line");
	cfg_assign_buses(c, e);
	if (c->port[0] == '\0' && c->usb_serial[0] == '\0' && (c->nbuses == 1 || c->bus[CFG_BUS_ROBOT].njoints > 0))
		cfg_error(e, "%s: [robot] port: no port configured (port = /dev/ttyUSB0, usb_serial = ..., "
		          "or --port PATH)", c->source[0] ? c->source : "command line");
	if (c->nbuses > 1 && c->njoints > 0 && c->bus[CFG_BUS_ROBOT].njoints == 0 &&
	    (c->port[0] != '\0' || c->usb_serial[0] != '\0'))
		cfg_error(e, "%s: [robot] port: no joint is left on it (each is on a [bus.NAME]): remove it, or leave "
		          "some joints out of the [bus.NAME] sections", c->source[0] ? c->source : "command line");
	cfg_check_buses(c, e);
	for (size_t j = c->njoints; j < CFG_MAX_JOINTS; j++) {
		const struct cfg_joint *jt = &c->joint[j];
		if (!isnan(jt->osc.k) || !isnan(jt->osc.c) || !isnan(jt->osc.mu) || !isnan(jt->osc.lambda) ||
		    !isnan(jt->osc.inertia) || !isnan(jt->osc.friction) || !isnan(jt->osc.coupling_phase) ||
		    !isnan(jt->neutral) ||
		    !isnan(jt->limit_min) || !isnan(jt->limit_max) || !isnan(jt->max_step))
			cfg_error(e, "%s: [joint.%zu]: the robot has only %zu joint(s) (ids)",
			          c->source[0] ? c->source : "command line", j + 1, c->njoints);
	}
	cfg_fill_joint_defaults(c);
	cfg_check_rate(c, e);
	c->servo_lead_default = isnan(c->servo_lead_s);
	if (isnan(c->servo_lead_s))
		c->servo_lead_s = c->compliance_margin == 0 ? OSC_SERVO_LEAD_MARGIN0_S : OSC_SERVO_LEAD_S;
	for (size_t j = 0; j < c->njoints; j++) {
		const struct cfg_joint *jt = &c->joint[j];
		if (!(jt->limit_min < jt->limit_max))
			cfg_error(e, "%s: [joint.%zu] limit_min: %g is not below limit_max %g",
			          c->source[0] ? c->source : "command line", j + 1, jt->limit_min, jt->limit_max);
		else if (!(jt->limit_min <= 0.0 && jt->limit_max >= 0.0))
			cfg_error(e, "%s: [joint.%zu] limit_min/limit_max: [%g, %g] must contain the neutral angle 0",
			          c->source[0] ? c->source : "command line", j + 1, jt->limit_min, jt->limit_max);
		if (jt->neutral + jt->limit_min < -CFG_SERVO_HALF_RANGE - 1e-9 ||
		    jt->neutral + jt->limit_max > CFG_SERVO_HALF_RANGE + 1e-9)
			cfg_error(e, "%s: [joint.%zu] limit_min/limit_max: neutral %+g + [%g, %g] leaves the servo's "
			          "±2.618 rad (300°) range", c->source[0] ? c->source : "command line", j + 1,
			          jt->neutral, jt->limit_min, jt->limit_max);
		char jwhy[160];
		if (!cfg_joint_check(jt, jwhy, sizeof jwhy))
			cfg_error(e, "%s: [joint.%zu] k/inertia: %s", c->source[0] ? c->source : "command line", j + 1, jwhy);
	}
	struct udpm_url url;
	char why[200];
	if (c->lcm_url[0] != '\0' && !udpm_parse_url(c->lcm_url, &url, why, sizeof why))
		cfg_error(e, "%s: [robot] lcm_url: %s", c->source[0] ? c->source : "command line", why);
	/* Torque actuation reads the joint's speed every cycle while the servos
	 * are in wheel mode, where the AX-12A's present-speed register holds the
	 * output share (e-manual, Present Speed), not a speed: the law would be
	 * fed its own last command. Refused rather than overridden, so that what
	 * the file says is what runs. */
	if (c->actuation == CFG_ACT_TORQUE && c->velocity_source == CFG_VEL_SERVO)
		cfg_error(e, "%s: [robot] velocity_source = servo cannot be used with actuation = torque: in wheel "
		          "mode the AX-12's present speed is its output, not a speed; use velocity_source = filtered",
		          c->source[0] ? c->source : "command line");
	char pwhy[200];
	if (!cfg_robot_param_check(c, "stiffness", c->sin_stiffness, pwhy, sizeof pwhy))
		cfg_error(e, "%s: [sinusoid] %s", c->source[0] ? c->source : "command line", pwhy);
	if (c->commands == CFG_CMD_NETWORK && c->command_key[0] == '\0')
		cfg_error(e, "%s: [robot] commands = network needs command_key = FILE (the shared key: "
		          "`undulated --gen-key FILE` makes one)", c->source[0] ? c->source : "command line");
	return e->count == before;
}

bool cfg_only_bus(struct cfg *c, const char *name, char *why, size_t cap)
{
	size_t b = 0;
	while (b < c->nbuses && (strcmp(c->bus[b].name, name) != 0 || c->bus[b].njoints == 0))
		b++;
	if (b == c->nbuses) {
		size_t used = (size_t)snprintf(why, cap, "no bus '%.48s' with joints; the robot's buses: ", name);
		for (size_t i = 0, n = 0; i < c->nbuses && used < cap; i++) {
			if (c->bus[i].njoints == 0)
				continue;
			int w = snprintf(why + used, cap - used, "%s%s (%s)", n++ ? ", " : "", c->bus[i].name,
			                 c->bus[i].port[0] ? c->bus[i].port : c->bus[i].usb_serial);
			used += w > 0 ? (size_t)w : 0;
		}
		return false;
	}
	struct cfg_bus keep = c->bus[b];
	struct cfg_joint joints[CFG_MAX_JOINTS];
	uint8_t ids[CFG_MAX_JOINTS];
	for (size_t k = 0; k < keep.njoints; k++) {
		joints[k] = c->joint[keep.joints[k]];
		ids[k] = c->ids[keep.joints[k]];
	}
	memcpy(c->joint, joints, keep.njoints * sizeof joints[0]);
	memcpy(c->ids, ids, keep.njoints);
	c->njoints = keep.njoints;
	snprintf(c->port, sizeof c->port, "%s", keep.port);
	snprintf(c->usb_serial, sizeof c->usb_serial, "%s", keep.usb_serial);
	c->baud = keep.baud;
	c->nbuses = 1;
	c->bus[CFG_BUS_ROBOT] = keep;
	snprintf(c->bus[CFG_BUS_ROBOT].name, sizeof c->bus[CFG_BUS_ROBOT].name, "robot");
	for (size_t k = 0; k < keep.njoints; k++) {
		c->bus[CFG_BUS_ROBOT].joints[k] = k;
		c->joint_bus[k] = CFG_BUS_ROBOT;
	}
	return true;
}

void cfg_print(const struct cfg *c, void *file)
{
	FILE *f = file;
	static const char *const safe[] = { "hold", "limp" };
	fprintf(f, "[robot]\nname = %s\nport = %s\nusb_serial = %s\nbaud = %ld\nids = ", c->name, c->port,
	        c->usb_serial, c->baud);
	for (size_t j = 0; j < c->njoints; j++)
		fprintf(f, "%s%s%s%u", j ? "," : "", c->joint_bus[j] != CFG_BUS_ROBOT ? c->bus[c->joint_bus[j]].name : "",
		        c->joint_bus[j] != CFG_BUS_ROBOT ? ":" : "", c->ids[j]);
	fprintf(f, "\nprotocol = %s\nbus_watchdog_ms = %ld\nfault_reboots = %d\nindirect = %s\n",
	        cfg_protocol_name(c->protocol), c->bus_watchdog_ms, c->fault_reboots, c->indirect ? "on" : "off");
	if (c->stall_torque_given)
		fprintf(f, "stall_torque = %g\n", c->stall_torque);
	if (c->no_load_speed_given)
		fprintf(f, "no_load_speed = %g\n", c->no_load_speed);
	fprintf(f, "mode = %s\nlcm_url = %s\npriority = %d\nmlockall = %s\nsafe_stop = %s\n"
	        "fault_action = %s\nvelocity_source = %s\nvelocity_cutoff_hz = %g\ncommands = %s\n"
	        "echo = %s\nrs485 = %s\nadapter_latency_us = %ld\nperiod_ms = %g\nservo_lead_s = %g\ncompliance_margin = %ld\n"
	        "compliance_slope = %ld\n"
	        "actuation = %s\ntorque_drive = %s\n"
	        "bus_margin_us = %ld\nramp_s = %g\nbackoff_torque = %g\n"
	        "fault_backoff_s = %g\nfault_retries = %d\nstale_limit = %d\nsilent_s = %g\n"
	        "command_key = %s\ncommand_window_s = %g\nrun_dir = %s\nlockstep = %s\n",
	        cfg_mode_name(c->mode), c->lcm_url, c->priority, c->mlockall ? "on" : "off",
	        safe[c->safe_stop], safe[c->fault_action],
	        c->velocity_source == CFG_VEL_SERVO ? "servo" : "filtered", c->velocity_cutoff_hz,
	        cfg_commands_name(c->commands), c->echo ? "on" : "off", port_rs485_name(c->rs485), c->adapter_latency_us, c->period_ms,
	        c->servo_lead_s, c->compliance_margin, c->compliance_slope, c->actuation == CFG_ACT_TORQUE ? "torque" : "position",
	        c->torque_drive == CFG_DRIVE_CURRENT ? "current" : "pwm",
	        c->bus_margin_us,
	        c->ramp_s, c->backoff_torque, c->fault_backoff_s, c->fault_retries, c->stale_limit, c->silent_s,
	        c->command_key, c->command_window_s, c->run_dir, c->lockstep);
	for (size_t b = 1; b < c->nbuses; b++) {
		const struct cfg_bus *bus = &c->bus[b];
		fprintf(f, "\n[bus.%s]\nport = %s\nusb_serial = %s\nbaud = %ld\n", bus->name, bus->port, bus->usb_serial,
		        bus->baud ? bus->baud : c->baud);
	}
	for (size_t j = 0; j < c->njoints; j++) {
		const struct cfg_joint *jt = &c->joint[j];
		fprintf(f, "\n[joint.%zu]\nk = %g\nc = %g\nmu = %g\nlambda = %g\ncoupling_phase = %g\ninertia = %g\n"
		        "friction = %g\nneutral = %g\nlimit_min = %g\nlimit_max = %g\nmax_step = %g\n", j + 1, jt->osc.k,
		        jt->osc.c, jt->osc.mu, jt->osc.lambda, jt->osc.coupling_phase, jt->osc.inertia, jt->osc.friction,
		        jt->neutral,
		        jt->limit_min, jt->limit_max, jt->max_step);
	}
	fprintf(f, "\n[sinusoid]\namplitude = %g\nfrequency = %g\nphase = %g\nstiffness = %g\ndamping = %g\n",
	        c->amplitude, c->frequency, c->phase, c->sin_stiffness, c->sin_damping);
}
