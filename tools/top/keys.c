/* keys.c — see keys.h. */
#include "keys.h"
#include "modes.h"
#include "params.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define KEY_ESC 0x1b

enum top_key top_key_feed(struct top_keyparser *kp, unsigned char byte, int *ch)
{
	if (kp->n == 0) {
		if (byte == KEY_ESC) {
			kp->seq[kp->n++] = byte;
			return TOP_KEY_NONE;
		}
		*ch = byte;
		return TOP_KEY_CHAR;
	}
	kp->seq[kp->n++] = byte;
	if (kp->n == 2) {
		if (byte == '[' || byte == 'O')
			return TOP_KEY_NONE;
		kp->n = 0; /* ESC + key (Alt-key): ignored */
		return TOP_KEY_NONE;
	}
	/* CSI/SS3 sequences end with a byte in 0x40..0x7E */
	if (byte < 0x40 || byte > 0x7e) {
		if (kp->n >= TOP_KEYSEQ_MAX)
			kp->n = 0;
		return TOP_KEY_NONE;
	}
	enum top_key key = TOP_KEY_NONE;
	if (kp->n == 3) {
		switch (byte) {
		case 'A': key = TOP_KEY_UP; break;
		case 'B': key = TOP_KEY_DOWN; break;
		case 'H': key = TOP_KEY_HOME; break;
		case 'F': key = TOP_KEY_END; break;
		default: break;
		}
	} else if (kp->n == 4 && byte == '~') {
		switch (kp->seq[2]) {
		case '5': key = TOP_KEY_PGUP; break;
		case '6': key = TOP_KEY_PGDN; break;
		case '1': case '7': key = TOP_KEY_HOME; break;
		case '4': case '8': key = TOP_KEY_END; break;
		default: break;
		}
	}
	kp->n = 0;
	return key;
}

static void top_command_base(struct top_command *c, const char *robot, int8_t kind, int64_t seq, const char *source)
{
	memset(c, 0, sizeof(*c));
	snprintf(c->robot, sizeof(c->robot), "%s", robot);
	snprintf(c->source, sizeof(c->source), "%s", source);
	if (strcmp(robot, "*") == 0)
		snprintf(c->channel, sizeof(c->channel), "UNDULATE.CMD");
	else
		snprintf(c->channel, sizeof(c->channel), "%s.CMD", robot);
	c->msg.seq = seq;
	c->msg.source = c->source;
	c->msg.robot = c->robot;
	c->msg.kind = kind;
	c->msg.param = c->param;
	c->msg.joint = -1;
}

int top_command_mode(struct top_command *c, const char *robot, int mode, int64_t seq, const char *source)
{
	if (!mode_is_valid(mode))
		return -1;
	if (!robot[0] || strlen(robot) >= TOP_NAME_MAX)
		return -1;
	top_command_base(c, robot, UNDULATE_COMMAND_T_KIND_MODE, seq, source);
	c->msg.mode = (int8_t)mode;
	return 0;
}

static int nudge_oscillator(struct top_command out[TOP_MAX_JOINTS], const struct top_robot *r, int dir,
			    int64_t seq, const char *source, char *why, size_t whylen)
{
	int n = r->nparams < r->njoints || r->njoints == 0 ? r->nparams : r->njoints;
	const struct param_range *range = &param_find("c")->range;   /* the daemon's */
	/* the daemon's words too: "out of range 0..2.618" in every program */
	int len = snprintf(why, whylen, "%s c:", r->name);
	for (int k = 0; k < n; k++) {
		double v = r->c[k] * (1.0 + dir * TOP_NUDGE_FRACTION);
		if (!isfinite(v) || v <= 0.0) {
			snprintf(why, whylen, "%s: c[%d] = %g cannot be nudged (must stay > 0)", r->name, k, r->c[k]);
			return -1;
		}
		if (!param_in_range(range, v)) {
			char shown[48];
			snprintf(why, whylen, "%s: c[%d] %.4g out of range %s: not sent", r->name, k, v,
				 param_range_format(range, shown, sizeof shown));
			return -1;
		}
		top_command_base(&out[k], r->name, UNDULATE_COMMAND_T_KIND_PARAM, seq + k, source);
		snprintf(out[k].param, sizeof(out[k].param), "c");
		out[k].msg.joint = (int16_t)k;
		out[k].msg.value = v;
		if (len > 0 && (size_t)len < whylen)
			len += snprintf(why + len, whylen - (size_t)len, " [%d] %.4g->%.4g", k, r->c[k], v);
	}
	return n;
}

int top_command_nudge(struct top_command out[TOP_MAX_JOINTS], const struct top_robot *r, int dir, int64_t seq,
		      const char *source, char *why, size_t whylen)
{
	dir = dir > 0 ? 1 : -1;
	if (!r->have_params) {
		snprintf(why, whylen, "%s: no %s.PARAMS heard yet: nothing to nudge from", r->name, r->name);
		return -1;
	}
	if (r->mode == MODE_OSCILLATOR)
		return nudge_oscillator(out, r, dir, seq, source, why, whylen);
	if (r->mode != MODE_SINUSOID) {
		snprintf(why, whylen, "%s is in %s: +/- nudges c (%s) or the amplitude (%s)", r->name,
			 mode_name(r->mode), mode_name(MODE_OSCILLATOR), mode_name(MODE_SINUSOID));
		return -1;
	}
	/* the daemon's range, not one of our own: a value it accepts is one we may send */
	const struct param_def *amp = param_find("amplitude");
	double v = r->sin_amplitude + dir * amp->step;
	if (!param_in_range(&amp->range, v)) {
		char shown[48];
		snprintf(why, whylen, "%s: amplitude %.3f %s out of range %s %s: not sent", r->name, v, amp->unit,
			 param_range_format(&amp->range, shown, sizeof shown), amp->unit);
		return -1;
	}
	top_command_base(&out[0], r->name, UNDULATE_COMMAND_T_KIND_PARAM, seq, source);
	snprintf(out[0].param, sizeof(out[0].param), "amplitude");
	out[0].msg.value = v;
	snprintf(why, whylen, "%s amplitude %.3f->%.3f rad", r->name, r->sin_amplitude, v);
	return 1;
}
