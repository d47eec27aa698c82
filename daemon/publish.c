/* publish.c — see publish.h. */
#include "clock.h"
#include "publish.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "port.h"
#include "text.h"
#include "undulate_bus_stats_t.h"
#include "undulate_event_t.h"
#include "undulate_osc_params_t.h"
#include "undulate_robot_state_t.h"

#define PUB_SEND(p, type, channel, msg)                                                          \
	do {                                                                                     \
		int n_ = type##_encoded_size(msg);                                               \
		if (n_ > 0 && n_ <= PUB_ENCODE_CAP && type##_encode((p)->buf, 0, n_, msg) == n_) {  \
			lcm_publish((p)->lcm, channel, (p)->buf, (unsigned)n_);                  \
		} else {                                                                         \
			(p)->encode_failures++;                                                  \
			log_limited(&(p)->lim_encode, port_now_us(), LOG_LVL_ERROR,            \
			            "cannot encode %s (%d bytes)", channel, n_);                  \
		}                                                                                \
	} while (0)

bool pub_open(struct pub *p, const struct cfg *cfg, const struct cfg_params *live, char *why, size_t cap)
{
	memset(p, 0, sizeof *p);
	p->cfg = cfg;
	p->live = live;
	p->lim_encode = (struct log_limit)LOG_LIMIT_INIT(3, 10000000);
	p->buf = malloc(PUB_ENCODE_CAP);
	if (p->buf == NULL) {
		snprintf(why, cap, "out of memory");
		return false;
	}
	const char *url = cfg->lcm_url[0] ? cfg->lcm_url : NULL;
	p->lcm = lcm_create(url);
	if (p->lcm == NULL) {
		snprintf(why, cap, "cannot create LCM (url %s): check the URL and that multicast works "
		         "(e.g. a route for 239.255.76.67)", url ? url : "default");
		pub_close(p);
		return false;
	}
	snprintf(p->ch_state, sizeof p->ch_state, "%s.STATE", cfg->name);
	snprintf(p->ch_bus, sizeof p->ch_bus, "%s.BUS", cfg->name);
	snprintf(p->ch_params, sizeof p->ch_params, "%s.PARAMS", cfg->name);
	snprintf(p->ch_event, sizeof p->ch_event, "%s.EVENT", cfg->name);
	return true;
}

void pub_close(struct pub *p)
{
	if (p->lcm != NULL)
		lcm_destroy(p->lcm);
	free(p->buf);
	p->lcm = NULL;
	p->buf = NULL;
}

void pub_event(struct pub *p, int64_t seq, int level, const char *kind, const char *text)
{
	/* the generated struct wants mutable strings; and whatever the text
	 * quotes, it stays one printable line */
	char robot[CFG_NAME_MAX], kind_buf[32], text_buf[512];
	snprintf(robot, sizeof robot, "%s", p->cfg->name);
	text_line(kind_buf, sizeof kind_buf, kind);
	text_line(text_buf, sizeof text_buf, text);
	undulate_event_t e = {
		.utime = clock_wall_us(), .robot = robot, .seq = seq, .level = (int8_t)level,
		.kind = kind_buf, .text = text_buf,
	};
	p->events++;
	PUB_SEND(p, undulate_event_t, p->ch_event, &e);
}

void pub_state(struct pub *p, const struct ctl *c, const struct pub_cycle *f)
{
	for (size_t j = 0; j < c->n; j++) {
		const struct ctl_joint *jt = &c->j[j];
		double neutral = p->cfg->joint[j].neutral;
		p->js[j] = (undulate_joint_state_t){
			.servo_id = jt->id, .angle = jt->angle - neutral, .speed = jt->speed, .load = jt->load,
			.goal = jt->goal - neutral, .drive = jt->duty, .phase = jt->phase,
			.amplitude = jt->estimator.amplitude, .frequency = jt->estimator.frequency,
			.voltage = jt->voltage, .temperature = jt->temperature,
			.error_bits = (int16_t)(jt->errbits | (sm_has(ctl_model(c, j), SM_CAP_HWERR) ? UNDULATE_JOINT_STATE_T_ERROR_BITS_X : 0)),
			.stale_cycles = jt->stale_cycles, .torque = jt->torque, .torque_read = (int8_t)jt->torque_read,
			.torque_limit = (int16_t)jt->torque_limit_read,
		};
	}
	char robot[CFG_NAME_MAX], reason[sizeof c->reason], fault[sizeof c->latch];
	snprintf(robot, sizeof robot, "%s", p->cfg->name);
	snprintf(reason, sizeof reason, "%s", c->reason);
	snprintf(fault, sizeof fault, "%s", c->latched ? c->latch : "");
	undulate_robot_state_t m = {
		.utime = clock_wall_us(), .robot = robot, .cycle = f->cycle, .mode = (int8_t)c->mode,
		.mode_reason = reason, .fault = fault, .period_us = f->period_us, .jitter_us = f->jitter_us,
		.bus_us = f->bus_us, .control_us = f->control_us, .overruns = f->overruns, .bus_errors = f->bus_errors,
		.bad_commands = f->bad_commands, .njoints = (int32_t)c->n, .joints = p->js,
	};
	PUB_SEND(p, undulate_robot_state_t, p->ch_state, &m);
}

void pub_params(struct pub *p)
{
	double v[9][CFG_MAX_JOINTS];
	const struct cfg *c = p->cfg;
	const struct cfg_params *live = p->live;
	for (size_t j = 0; j < c->njoints; j++) {
		const struct cfg_joint *jt = &c->joint[j];
		const struct osc_joint_params *o = &live->osc[j];
		v[0][j] = o->k;
		v[1][j] = o->c;
		v[2][j] = o->mu;
		v[3][j] = o->lambda;
		v[4][j] = o->inertia;
		v[5][j] = o->friction;
		v[6][j] = jt->neutral;
		v[7][j] = jt->limit_min;
		v[8][j] = jt->limit_max;
	}
	char robot[CFG_NAME_MAX];
	snprintf(robot, sizeof robot, "%s", c->name);
	undulate_osc_params_t m = {
		.utime = clock_wall_us(), .robot = robot, .njoints = (int32_t)c->njoints,
		.k = v[0], .c = v[1], .mu = v[2], .lambda = v[3], .inertia = v[4], .friction = v[5],
		.neutral = v[6], .limit_min = v[7], .limit_max = v[8],
		.amplitude = live->amplitude, .frequency = live->frequency, .phase = live->phase,
	};
	PUB_SEND(p, undulate_osc_params_t, p->ch_params, &m);
}

void pub_bus_joints(struct pub *p, const struct pub_bus *f, const struct pub_bus_lines *lines,
                    const struct bus *const *bus_of, const struct ctl *c, const char *channel)
{
	size_t n = 0;
	for (size_t j = 0; j < c->n; j++) {
		if (bus_of[j] == NULL)
			continue;
		const struct bus_servo_stats *s = &bus_of[j]->servo[c->j[j].id];
		p->ss[n++] = (undulate_servo_stats_t){
			.servo_id = c->j[j].id, .transactions = s->transactions, .replies = s->replies,
			.timeouts = s->timeouts, .checksum_errors = s->checksum_errors, .resyncs = s->resyncs,
			.wrong_id = s->wrong_id, .wrong_length = s->wrong_length, .error_replies = s->error_replies,
			.errbits_seen = s->errbits_seen,
			.rtt_mean_us = s->replies ? (double)s->rtt_sum_us / s->replies : 0.0,
			.rtt_max_us = s->rtt_max_us,
		};
	}
	char robot[CFG_NAME_MAX], port[CFG_PATH_MAX];
	snprintf(robot, sizeof robot, "%s", p->cfg->name);
	snprintf(port, sizeof port, "%s", f->port);
	undulate_bus_stats_t m = {
		.utime = clock_wall_us(), .robot = robot, .port = port, .baud = lines->baud,
		.connected = f->connected, .reconnects = f->reconnects, .adapter_latency_ms = f->adapter_latency_ms,
		.return_delay_us = f->return_delay_us, .period_p50_us = f->period_p50_us,
		.period_p99_us = f->period_p99_us, .period_max_us = f->period_max_us, .jitter_p99_us = f->jitter_p99_us,
		.bus_p99_us = f->bus_p99_us, .cpu_percent = f->cpu_percent, .overruns = f->overruns,
		.stray_packets = lines->stray_packets, .io_errors = lines->io_errors, .nservos = (int32_t)n,
		.servos = p->ss,
	};
	PUB_SEND(p, undulate_bus_stats_t, channel, &m);
}

void pub_bus(struct pub *p, const struct pub_bus *f, const struct bus *bus, const struct ctl *c)
{
	const struct bus *bus_of[CFG_MAX_JOINTS];
	for (size_t j = 0; j < c->n; j++)
		bus_of[j] = bus;
	struct pub_bus_lines lines = { .stray_packets = bus->stray_packets, .io_errors = bus->io_errors,
	                               .baud = (int32_t)p->cfg->baud };
	pub_bus_joints(p, f, &lines, bus_of, c, p->ch_bus);
}

uint64_t pub_state_every(uint64_t period_us)
{
	if (period_us == 0 || period_us >= PUB_STATE_MIN_US)
		return 1;
	return (PUB_STATE_MIN_US + period_us - 1) / period_us;
}
