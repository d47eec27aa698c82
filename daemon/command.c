/* command.c — see command.h. */
#include "command.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char *nz(const char *s) { return s != NULL ? s : ""; }

static enum cmd_verdict reject(char *why, size_t cap, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static enum cmd_verdict reject(char *why, size_t cap, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(why, cap, fmt, ap);
	va_end(ap);
	return CMD_REJECT;
}

static enum cmd_verdict cmd_check_param(const struct cmd_request *r, const struct cfg *cfg, char *why,
                                        size_t cap)
{
	const char *name = nz(r->param);
	struct cfg_range range;
	if (!cfg_param_range(name, &range))
		return reject(why, cap, "unknown parameter '%.40s' (k, c, mu, lambda, inertia, friction, neutral, "
		              "limit_min, limit_max, max_step, amplitude, frequency, phase)", name);
	if (!isfinite(r->value))
		return reject(why, cap, "parameter %s: value is not finite", name);
	if (cfg_param_is_robot(name)) {
		if (r->joint != -1)
			return reject(why, cap, "parameter %s is per robot: joint must be -1, not %d", name, r->joint);
	} else if (r->joint < -1 || r->joint >= (int)cfg->njoints) {
		return reject(why, cap, "parameter %s: joint %d does not exist (0..%zu, or -1 for all)", name,
		              r->joint, cfg->njoints - 1);
	}
	bool below = range.min_open ? !(r->value > range.min) : !(r->value >= range.min);
	if (below || r->value > range.max)
		return reject(why, cap, "parameter %s: %g out of range %s%g..%g", name, r->value,
		              range.min_open ? ">" : "", range.min, range.max);
	if (cfg_param_is_robot(name))
		return CMD_ACCEPT;
	/* Cross-checks the range table cannot express: limits stay ordered around 0
	 * and inside the servo's travel. */
	size_t first = r->joint < 0 ? 0 : (size_t)r->joint;
	size_t last = r->joint < 0 ? cfg->njoints : first + 1;
	for (size_t j = first; j < last; j++) {
		struct cfg_joint jt = cfg->joint[j];
		*cfg_joint_param(&jt, name) = r->value;
		if (strcmp(name, "limit_min") == 0 || strcmp(name, "limit_max") == 0 ||
		    strcmp(name, "neutral") == 0) {
			if (!(jt.limit_min <= 0.0 && 0.0 <= jt.limit_max && jt.limit_min < jt.limit_max))
				return reject(why, cap, "parameter %s: joint %zu limits [%g, %g] must contain 0", name, j,
				              jt.limit_min, jt.limit_max);
			if (fabs(jt.neutral + jt.limit_min) > 2.618 || fabs(jt.neutral + jt.limit_max) > 2.618)
				return reject(why, cap, "parameter %s: joint %zu would leave the servo's ±2.618 rad range",
				              name, j);
		}
	}
	return CMD_ACCEPT;
}

enum cmd_verdict cmd_check(const struct cmd_request *r, const struct cfg *cfg, bool direct, char *why,
                           size_t cap)
{
	const char *robot = nz(r->robot);
	why[0] = '\0';
	if (strcmp(robot, "*") != 0 && strcmp(robot, cfg->name) != 0) {
		if (!direct)
			return CMD_IGNORE;
		return reject(why, cap, "addressed to robot '%.40s', this is '%s'", robot, cfg->name);
	}
	if (!cfg->commands)
		return reject(why, cap, "commands are disabled in this robot's configuration (commands = off)");
	switch (r->kind) {
	case CMD_KIND_MODE:
		if (r->mode < 0 || r->mode >= CFG_NMODES)
			return reject(why, cap, "unknown mode %d (0 limp, 1 hold, 2 sinusoid, 3 oscillator)", r->mode);
		return CMD_ACCEPT;
	case CMD_KIND_PARAM:
		return cmd_check_param(r, cfg, why, cap);
	case CMD_KIND_TORQUE:
		return CMD_ACCEPT;
	default:
		return reject(why, cap, "unknown command kind %d (1 mode, 2 param, 3 torque)", r->kind);
	}
}

/* ---- decoding command_t ---------------------------------------------------------------- */
struct cmd_reader {
	const uint8_t *p;
	size_t left;
	bool bad;
};

static uint64_t cmd_take(struct cmd_reader *rd, size_t n)
{
	uint64_t v = 0;
	if (rd->bad || rd->left < n) {
		rd->bad = true;
		return 0;
	}
	for (size_t i = 0; i < n; i++)
		v = v << 8 | rd->p[i];
	rd->p += n;
	rd->left -= n;
	return v;
}

/* An LCM string: int32 length counting the NUL, the bytes, the NUL. */
static void cmd_take_string(struct cmd_reader *rd, char *dst, size_t cap)
{
	int32_t n = (int32_t)(uint32_t)cmd_take(rd, 4);
	dst[0] = '\0';
	if (rd->bad || n < 1 || (size_t)n > rd->left || rd->p[n - 1] != '\0') {
		rd->bad = true;
		return;
	}
	size_t keep = (size_t)n - 1 < cap - 1 ? (size_t)n - 1 : cap - 1;
	memcpy(dst, rd->p, keep);
	dst[keep] = '\0';
	rd->p += n;
	rd->left -= (size_t)n;
}

bool cmd_decode(const void *data, size_t len, int64_t fingerprint, struct cmd_wire *w, char *why, size_t cap)
{
	struct cmd_reader rd = { .p = data, .left = len };
	memset(w, 0, sizeof *w);
	if ((int64_t)cmd_take(&rd, 8) != fingerprint && !rd.bad) {
		snprintf(why, cap, "not a command_t (fingerprint differs)");
		return false;
	}
	struct cmd_request *r = &w->req;
	(void)cmd_take(&rd, 8);   /* utime: not used */
	r->seq = (int64_t)cmd_take(&rd, 8);
	cmd_take_string(&rd, w->source, sizeof w->source);
	cmd_take_string(&rd, w->robot, sizeof w->robot);
	r->kind = (int8_t)cmd_take(&rd, 1);
	r->mode = (int8_t)cmd_take(&rd, 1);
	cmd_take_string(&rd, w->param, sizeof w->param);
	r->joint = (int16_t)cmd_take(&rd, 2);
	uint64_t bits = cmd_take(&rd, 8);
	memcpy(&r->value, &bits, sizeof r->value);
	r->torque = cmd_take(&rd, 1) != 0;
	if (rd.bad) {
		snprintf(why, cap, "malformed command_t (%zu bytes: short, or a bad string length)", len);
		return false;
	}
	r->source = w->source;
	r->robot = w->robot;
	r->param = w->param;
	return true;
}

void cmd_apply_param(struct cfg *cfg, const struct cmd_request *r)
{
	const char *name = nz(r->param);
	if (strcmp(name, "amplitude") == 0) { cfg->amplitude = r->value; return; }
	if (strcmp(name, "frequency") == 0) { cfg->frequency = r->value; return; }
	if (strcmp(name, "phase") == 0) { cfg->phase = r->value; return; }
	size_t first = r->joint < 0 ? 0 : (size_t)r->joint;
	size_t last = r->joint < 0 ? cfg->njoints : first + 1;
	for (size_t j = first; j < last && j < cfg->njoints; j++) {
		double *f = cfg_joint_param(&cfg->joint[j], name);
		if (f != NULL)
			*f = r->value;
	}
}

static bool parse_int(const char *s, long *out)
{
	char *end;
	errno = 0;
	long v = strtol(s, &end, 10);
	if (end == s || *end != '\0' || errno != 0)
		return false;
	*out = v;
	return true;
}

bool cmd_parse_text(const char *text, struct cmd_request *r, char *param_buf, size_t param_cap,
                    char *why, size_t cap)
{
	char buf[256];
	char *word[5] = { 0 };
	int n = 0;
	snprintf(buf, sizeof buf, "%s", text);
	for (char *save = NULL, *t = strtok_r(buf, " \t", &save); t != NULL && n < 5;
	     t = strtok_r(NULL, " \t", &save))
		word[n++] = t;
	r->joint = -1;
	long v;
	if (n == 2 && strcasecmp(word[0], "mode") == 0) {
		enum cfg_mode m;
		r->kind = CMD_KIND_MODE;
		if (cfg_mode_parse(word[1], &m))
			r->mode = (int)m;
		else if (parse_int(word[1], &v) && v >= -128 && v <= 127)
			r->mode = (int)v;
		else {
			snprintf(why, cap, "mode: '%s' is not limp, hold, sinusoid, oscillator or a number", word[1]);
			return false;
		}
		return true;
	}
	if ((n == 3 || n == 4) && strcasecmp(word[0], "param") == 0) {
		r->kind = CMD_KIND_PARAM;
		snprintf(param_buf, param_cap, "%s", word[1]);
		r->param = param_buf;
		char *end;
		r->value = strtod(word[2], &end);
		if (end == word[2] || *end != '\0') {
			snprintf(why, cap, "param: value '%s' is not a number", word[2]);
			return false;
		}
		if (n == 4) {
			if (!parse_int(word[3], &v) || v < -32768 || v > 32767) {
				snprintf(why, cap, "param: joint '%s' is not an integer", word[3]);
				return false;
			}
			r->joint = (int)v;
		}
		return true;
	}
	if (n == 2 && strcasecmp(word[0], "torque") == 0) {
		r->kind = CMD_KIND_TORQUE;
		if (strcasecmp(word[1], "on") == 0)
			r->torque = true;
		else if (strcasecmp(word[1], "off") == 0)
			r->torque = false;
		else {
			snprintf(why, cap, "torque: '%s' is not on or off", word[1]);
			return false;
		}
		return true;
	}
	if (n == 2 && strcasecmp(word[0], "kind") == 0 && parse_int(word[1], &v)) {
		/* raw kind, for testing the daemon's own validation */
		r->kind = (int)v;
		return true;
	}
	snprintf(why, cap, "'%s': expected 'mode NAME', 'param NAME VALUE [JOINT]' or 'torque on|off'", text);
	return false;
}
