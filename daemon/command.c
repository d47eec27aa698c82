/* command.c — see command.h. */
#include "command.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "num.h"
#include "text.h"
#include "wire.h"

/* A name from outside, quoted in a message: one safe line. */
#define CMD_QUOTE_MAX 48

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

static enum cmd_verdict cmd_check_param(const struct cmd_request *r, const struct cfg *cfg,
                                        const struct cfg_params *live, char *why, size_t cap)
{
	const char *name = nz(r->param);
	char quoted[CMD_QUOTE_MAX];
	text_sanitize(quoted, sizeof quoted, name);
	struct param_range range;
	if (!cfg_param_range(name, &range))
		return reject(why, cap, "unknown parameter '%s' (%s)", quoted, cfg_param_commandable_list());
	if (!cfg_param_commandable(name))
		return reject(why, cap, "parameter %s bounds where a joint may go: only the configuration file sets it "
		              "(commands may set %s)", name, cfg_param_commandable_list());
	struct cfg_params initial;
	if (live == NULL) {
		cfg_params_init(&initial, cfg);
		live = &initial;
	}
	return cfg_params_check(cfg, live, name, r->joint, r->value, why, cap) ? CMD_ACCEPT : CMD_REJECT;
}

enum cmd_verdict cmd_check_live(const struct cmd_request *r, const struct cfg *cfg, const struct cfg_params *live,
                                bool direct, char *why, size_t cap)
{
	const char *robot = nz(r->robot);
	why[0] = '\0';
	if (strcmp(robot, "*") != 0 && strcmp(robot, cfg->name) != 0) {
		if (!direct)
			return CMD_IGNORE;
		char quoted[CMD_QUOTE_MAX];
		return reject(why, cap, "addressed to robot '%s', this is '%s'", text_sanitize(quoted, sizeof quoted, robot),
		              cfg->name);
	}
	switch (r->kind) {
	case CMD_KIND_MODE:
		if (r->mode < 0 || r->mode >= CFG_NMODES)
			return reject(why, cap, "unknown mode %d (0 limp, 1 hold, 2 sinusoid, 3 oscillator)", r->mode);
		return CMD_ACCEPT;
	case CMD_KIND_PARAM:
		return cmd_check_param(r, cfg, live, why, cap);
	case CMD_KIND_TORQUE:
	case CMD_KIND_CLEAR:
		return CMD_ACCEPT;
	default:
		return reject(why, cap, "unknown command kind %d (1 mode, 2 param, 3 torque, 4 clear)", r->kind);
	}
}

enum cmd_verdict cmd_check(const struct cmd_request *r, const struct cfg *cfg, bool direct, char *why,
                           size_t cap)
{
	return cmd_check_live(r, cfg, NULL, direct, why, cap);
}

/* ---- command_t on the wire ---------------------------------------------------------------- */
static void cmd_take_name(struct wire_reader *rd, char *dst, size_t cap, bool *cut_any)
{
	bool cut = false;
	wire_take_string(rd, dst, cap, &cut);
	*cut_any = *cut_any || cut;
}

bool cmd_decode(const void *data, size_t len, int64_t fingerprint, struct cmd_wire *w, char *why, size_t cap)
{
	struct wire_reader rd;
	wire_reader_init(&rd, data, len);
	memset(w, 0, sizeof *w);
	if ((int64_t)wire_take(&rd, 8) != fingerprint && !rd.bad) {
		snprintf(why, cap, "not a command_t (fingerprint differs)");
		return false;
	}
	struct cmd_request *r = &w->req;
	bool cut = false;
	r->utime = (int64_t)wire_take(&rd, 8);
	r->seq = (int64_t)wire_take(&rd, 8);
	cmd_take_name(&rd, w->source, sizeof w->source, &cut);
	cmd_take_name(&rd, w->robot, sizeof w->robot, &cut);
	r->kind = (int8_t)wire_take(&rd, 1);
	r->mode = (int8_t)wire_take(&rd, 1);
	cmd_take_name(&rd, w->param, sizeof w->param, &cut);
	r->joint = (int16_t)wire_take(&rd, 2);
	r->value = wire_take_double(&rd);
	r->torque = wire_take(&rd, 1) != 0;
	w->signed_len = len - rd.left;
	wire_take_bytes(&rd, w->mac, sizeof w->mac);
	if (rd.bad) {
		snprintf(why, cap, "malformed command_t (%zu bytes: short, or a bad string length)", len);
		return false;
	}
	if (rd.left != 0) {
		snprintf(why, cap, "malformed command_t (%zu bytes after its end)", rd.left);
		return false;
	}
	if (cut) {
		/* a name cut at an embedded NUL or at CMD_STR_MAX would say less than
		 * the sender wrote (and the MAC covers) */
		snprintf(why, cap, "malformed command_t (a name with a NUL inside, or longer than %d bytes)",
		         CMD_STR_MAX - 1);
		return false;
	}
	cmd_wire_rebase(w);
	return true;
}

void cmd_wire_rebase(struct cmd_wire *w)
{
	w->req.source = w->source;
	w->req.robot = w->robot;
	w->req.param = w->param;
}

size_t cmd_encode(const struct cmd_request *r, int64_t fingerprint, const uint8_t *mac, void *buf, size_t cap,
                  size_t *signed_len)
{
	static const uint8_t zeros[CMD_MAC_BYTES];
	struct wire_writer wr;
	wire_writer_init(&wr, buf, cap);
	wire_put(&wr, (uint64_t)fingerprint, 8);
	wire_put(&wr, (uint64_t)r->utime, 8);
	wire_put(&wr, (uint64_t)r->seq, 8);
	wire_put_string(&wr, nz(r->source));
	wire_put_string(&wr, nz(r->robot));
	wire_put(&wr, (uint8_t)(int8_t)r->kind, 1);
	wire_put(&wr, (uint8_t)(int8_t)r->mode, 1);
	wire_put_string(&wr, nz(r->param));
	wire_put(&wr, (uint16_t)(int16_t)r->joint, 2);
	wire_put_double(&wr, r->value);
	wire_put(&wr, r->torque ? 1 : 0, 1);
	if (signed_len != NULL)
		*signed_len = wr.len;
	wire_put_bytes(&wr, mac != NULL ? mac : zeros, CMD_MAC_BYTES);
	return wr.bad ? 0 : wr.len;
}

void cmd_describe(const struct cmd_request *r, char *out, size_t cap)
{
	char param[CMD_QUOTE_MAX];
	switch (r->kind) {
	case CMD_KIND_MODE:
		snprintf(out, cap, "mode %s", r->mode >= 0 && r->mode < CFG_NMODES ? cfg_mode_name((enum cfg_mode)r->mode)
		                                                                    : "?");
		return;
	case CMD_KIND_PARAM:
		text_sanitize(param, sizeof param, r->param);
		snprintf(out, cap, "param %s = %g (joint %d)", param, r->value, r->joint);
		return;
	case CMD_KIND_TORQUE:
		snprintf(out, cap, "torque %s", r->torque ? "on" : "off");
		return;
	case CMD_KIND_CLEAR:
		snprintf(out, cap, "clear");
		return;
	default:
		snprintf(out, cap, "kind %d", r->kind);
		return;
	}
}

/* ---- the text form ------------------------------------------------------------------------ */
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
	int v;
	if (n == 2 && strcasecmp(word[0], "mode") == 0) {
		enum cfg_mode m;
		r->kind = CMD_KIND_MODE;
		if (cfg_mode_parse(word[1], &m))
			r->mode = (int)m;
		else if (num_parse_int(word[1], -128, 127, &v) == NUM_OK)
			r->mode = v;
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
		/* any number, even out of range or not finite: the daemon judges */
		char *end;
		r->value = strtod(word[2], &end);
		if (end == word[2] || *end != '\0') {
			snprintf(why, cap, "param: value '%s' is not a number", word[2]);
			return false;
		}
		if (n == 4) {
			if (num_parse_int(word[3], -32768, 32767, &v) != NUM_OK) {
				snprintf(why, cap, "param: joint '%s' is not an integer", word[3]);
				return false;
			}
			r->joint = v;
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
	if (n == 1 && strcasecmp(word[0], "clear") == 0) {
		r->kind = CMD_KIND_CLEAR;
		return true;
	}
	if (n == 2 && strcasecmp(word[0], "kind") == 0 && num_parse_int(word[1], -128, 127, &v) == NUM_OK) {
		/* raw kind, for testing the daemon's own validation */
		r->kind = v;
		return true;
	}
	snprintf(why, cap, "'%s': expected 'mode NAME', 'param NAME VALUE [JOINT]', 'torque on|off' or 'clear'", text);
	return false;
}
