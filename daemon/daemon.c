/*
 * daemon.c — see daemon.h.
 *
 * A cycle, started by the 10 ms timer:
 *   READ(36, 6) of every joint → control step → SYNC_WRITE of the goals →
 *   queued register writes (torque, recovery) → every SLOW_EVERY cycles one
 *   READ(42, 2) (voltage, temperature) round-robin → publish the state.
 * Each transaction is begun with bus_begin() and driven by bus_step() when
 * the bus fd is readable or its deadline timer fires, so the loop never
 * blocks on the bus and LCM and signals are served in between.
 */
#include "daemon.h"

#include <errno.h>
#include <inttypes.h>
#include <lcm/lcm.h>
#include <math.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include "bus.h"
#include "command.h"
#include "control.h"
#include "dxl.h"
#include "dxl_table.h"
#include "log.h"
#include "notify.h"
#include "port.h"
#include "stats.h"
#include "undulate_bus_stats_t.h"
#include "undulate_command_t.h"
#include "undulate_event_t.h"
#include "undulate_osc_params_t.h"
#include "undulate_robot_state_t.h"

/* Voltage and temperature change slowly: one joint every SLOW_EVERY cycles
 * (each joint refreshed every SLOW_EVERY × njoints × 10 ms = 0.2 s for two). */
#define DMN_SLOW_EVERY 10
/* LCM encode buffer, allocated once: a robot_state_t with 8 joints is ~1 kB,
 * a bus_stats_t ~1.2 kB. */
#define DMN_ENCODE_CAP 16384
/* Reconnect back-off: 100 ms doubling to 2 s. */
#define DMN_BACKOFF_MIN_MS 100
#define DMN_BACKOFF_MAX_MS 2000
/* PINGs per servo at start-up before calling it missing. */
#define DMN_PING_TRIES 3
/* Assumed until the servos are read: the AX-12's factory return delay. */
#define DMN_DEFAULT_RETURN_DELAY_US 500
#define DMN_CHANNEL_MAX (CFG_NAME_MAX + 16)
/* Serial ports looked at when searching by USB serial number. */
#define DMN_MAX_PORTS 32

enum dmn_phase { PH_IDLE, PH_READ, PH_SYNC, PH_WRITES, PH_SLOW };

struct dmn {
	struct cfg *cfg;
	struct ctl ctl;
	/* bus */
	struct port *port;
	struct bus bus;
	char port_path[CFG_PATH_MAX];
	bool connected;
	uint64_t reconnect_at_us;
	uint32_t backoff_ms;
	long long reconnects;
	double adapter_latency_ms;
	int max_return_delay_us;
	/* the cycle's bus state machine */
	enum dmn_phase phase;
	size_t idx;
	size_t slow_joint;
	uint64_t read_at_us[CFG_MAX_JOINTS];   /* when each joint's last reply arrived */
	uint64_t bus_start_us;
	double bus_us;
	double control_us;
	/* timing */
	int timer_fd, deadline_fd, signal_fd;
	uint64_t period_us;
	uint64_t first_tick_us;
	uint64_t ticks;               /* timer expirations since start */
	uint64_t cycle;               /* cycles run */
	uint64_t cycle_start_us, last_cycle_start_us;
	double period_meas_us, jitter_us;
	long long overruns;
	long long bus_errors;
	long long bad_commands;
	struct stats_window w_period, w_jitter, w_bus;
	uint64_t second_start_us;
	struct rusage ru_last;
	double cpu_percent;
	/* LCM */
	lcm_t *lcm;
	int64_t cmd_fingerprint;   /* command_t's, for cmd_decode() */
	char ch_state[DMN_CHANNEL_MAX], ch_bus[DMN_CHANNEL_MAX], ch_params[DMN_CHANNEL_MAX],
	     ch_event[DMN_CHANNEL_MAX], ch_cmd[DMN_CHANNEL_MAX];
	uint8_t *encode_buf;
	undulate_joint_state_t js[CFG_MAX_JOINTS];
	undulate_servo_stats_t ss[CFG_MAX_JOINTS];
	bool params_dirty;
	/* systemd */
	struct notify notify;
	uint64_t watchdog_interval_us, last_watchdog_us, watchdog_cycle;
	/* stop */
	bool stop;
	struct log_limit lim_bus, lim_cmd, lim_overrun, lim_lcm;
};

static uint64_t now_us(void) { return port_now_us(); }

static int64_t wall_us(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* ---- LCM publishing (encode buffer allocated once) -------------------------------------- */
#define DMN_PUBLISH(d, type, channel, msg)                                                        \
	do {                                                                                      \
		int n_ = type##_encoded_size(msg);                                                \
		if (n_ > 0 && n_ <= DMN_ENCODE_CAP && type##_encode((d)->encode_buf, 0, n_, msg) == n_) \
			lcm_publish((d)->lcm, channel, (d)->encode_buf, (unsigned)n_);            \
		else                                                                              \
			log_limited(&(d)->lim_lcm, now_us(), LOG_LVL_ERROR,                     \
			            "cannot encode %s (%d bytes)", channel, n_);                   \
	} while (0)

/* Publish an event without logging it (the caller logs, rate-limited). */
static void dmn_event_quiet(struct dmn *d, int64_t seq, int level, const char *kind, const char *text)
{
	/* the generated struct wants mutable strings */
	char kind_buf[32], text_buf[512];
	snprintf(kind_buf, sizeof kind_buf, "%s", kind);
	snprintf(text_buf, sizeof text_buf, "%s", text);
	undulate_event_t e = {
		.utime = wall_us(), .robot = d->cfg->name, .seq = seq, .level = (int8_t)level,
		.kind = kind_buf, .text = text_buf,
	};
	DMN_PUBLISH(d, undulate_event_t, d->ch_event, &e);
}

static void dmn_event(struct dmn *d, int64_t seq, int level, const char *kind, const char *text)
{
	dmn_event_quiet(d, seq, level, kind, text);
	enum log_level lv = level >= 2 ? LOG_LVL_ERROR : level == 1 ? LOG_LVL_WARN : LOG_LVL_INFO;
	log_msg(lv, "%s: %s", kind, text);
}

static void dmn_flush_ctl_events(struct dmn *d)
{
	for (size_t i = 0; i < d->ctl.nevents; i++)
		dmn_event(d, 0, d->ctl.events[i].level, d->ctl.events[i].kind, d->ctl.events[i].text);
	d->ctl.nevents = 0;
}

static void dmn_publish_state(struct dmn *d)
{
	const struct ctl *c = &d->ctl;
	for (size_t j = 0; j < c->n; j++) {
		const struct ctl_joint *jt = &c->j[j];
		double neutral = d->cfg->joint[j].neutral;
		undulate_joint_state_t *s = &d->js[j];
		s->servo_id = jt->id;
		s->angle = jt->angle - neutral;
		s->speed = jt->speed;
		s->load = jt->load;
		s->goal = jt->goal - neutral;
		s->drive = jt->duty;
		s->phase = jt->phase;
		s->amplitude = jt->estimator.amplitude;
		s->frequency = jt->estimator.frequency;
		s->voltage = jt->voltage;
		s->temperature = jt->temperature;
		s->error_bits = jt->errbits;
		s->stale_cycles = jt->stale_cycles;
		s->torque = jt->torque;
	}
	undulate_robot_state_t m = {
		.utime = wall_us(), .robot = d->cfg->name, .cycle = (int64_t)d->cycle, .mode = (int8_t)c->mode,
		.mode_reason = d->ctl.reason, .period_us = d->period_meas_us, .jitter_us = d->jitter_us,
		.bus_us = d->bus_us, .control_us = d->control_us, .overruns = d->overruns,
		.bus_errors = d->bus_errors, .bad_commands = d->bad_commands, .njoints = (int32_t)c->n,
		.joints = d->js,
	};
	DMN_PUBLISH(d, undulate_robot_state_t, d->ch_state, &m);
}

static void dmn_publish_params(struct dmn *d)
{
	double v[9][CFG_MAX_JOINTS];
	const struct cfg *c = d->cfg;
	for (size_t j = 0; j < c->njoints; j++) {
		const struct cfg_joint *jt = &c->joint[j];
		v[0][j] = jt->osc.k;
		v[1][j] = jt->osc.c;
		v[2][j] = jt->osc.mu;
		v[3][j] = jt->osc.lambda;
		v[4][j] = jt->osc.inertia;
		v[5][j] = jt->osc.friction;
		v[6][j] = jt->neutral;
		v[7][j] = jt->limit_min;
		v[8][j] = jt->limit_max;
	}
	undulate_osc_params_t m = {
		.utime = wall_us(), .robot = d->cfg->name, .njoints = (int32_t)c->njoints,
		.k = v[0], .c = v[1], .mu = v[2], .lambda = v[3], .inertia = v[4], .friction = v[5],
		.neutral = v[6], .limit_min = v[7], .limit_max = v[8],
		.amplitude = c->amplitude, .frequency = c->frequency, .phase = c->phase,
	};
	DMN_PUBLISH(d, undulate_osc_params_t, d->ch_params, &m);
	d->params_dirty = false;
}

static double dmn_cpu_percent(struct dmn *d, double wall_s)
{
	struct rusage ru;
	if (getrusage(RUSAGE_SELF, &ru) != 0 || wall_s <= 0)
		return 0.0;
	double used = (double)(ru.ru_utime.tv_sec - d->ru_last.ru_utime.tv_sec) +
	              (double)(ru.ru_stime.tv_sec - d->ru_last.ru_stime.tv_sec) +
	              1e-6 * (double)(ru.ru_utime.tv_usec - d->ru_last.ru_utime.tv_usec) +
	              1e-6 * (double)(ru.ru_stime.tv_usec - d->ru_last.ru_stime.tv_usec);
	d->ru_last = ru;
	return 100.0 * used / wall_s;
}

static void dmn_publish_bus_stats(struct dmn *d, double wall_s)
{
	struct stats_summary sp, sj, sb;
	stats_summarize(&d->w_period, &sp);
	stats_summarize(&d->w_jitter, &sj);
	stats_summarize(&d->w_bus, &sb);
	d->cpu_percent = dmn_cpu_percent(d, wall_s);
	for (size_t j = 0; j < d->ctl.n; j++) {
		const struct bus_servo_stats *s = &d->bus.servo[d->ctl.j[j].id];
		d->ss[j] = (undulate_servo_stats_t){
			.servo_id = d->ctl.j[j].id, .transactions = s->transactions, .replies = s->replies,
			.timeouts = s->timeouts, .checksum_errors = s->checksum_errors, .resyncs = s->resyncs,
			.wrong_id = s->wrong_id, .wrong_length = s->wrong_length, .error_replies = s->error_replies,
			.errbits_seen = s->errbits_seen,
			.rtt_mean_us = s->replies ? (double)s->rtt_sum_us / s->replies : 0.0,
			.rtt_max_us = s->rtt_max_us,
		};
	}
	undulate_bus_stats_t m = {
		.utime = wall_us(), .robot = d->cfg->name, .port = d->port_path, .baud = (int32_t)d->cfg->baud,
		.connected = d->connected, .reconnects = d->reconnects,
		.adapter_latency_ms = d->adapter_latency_ms, .return_delay_us = d->max_return_delay_us,
		.period_p50_us = sp.p50, .period_p99_us = sp.p99, .period_max_us = sp.max,
		.jitter_p99_us = sj.p99, .bus_p99_us = sb.p99, .cpu_percent = d->cpu_percent,
		.overruns = d->overruns, .stray_packets = d->bus.stray_packets, .io_errors = d->bus.io_errors,
		.nservos = (int32_t)d->ctl.n, .servos = d->ss,
	};
	DMN_PUBLISH(d, undulate_bus_stats_t, d->ch_bus, &m);
	stats_reset(&d->w_period);
	stats_reset(&d->w_jitter);
	stats_reset(&d->w_bus);
}

/* ---- systemd --------------------------------------------------------------------------------- */
static void dmn_notify_status(struct dmn *d)
{
	if (!notify_enabled(&d->notify))
		return;
	char buf[256];
	struct notify_status s = {
		.mode = cfg_mode_name(d->ctl.mode),
		.rate_hz = 1e6 / (d->period_meas_us > 0 ? d->period_meas_us : (double)d->period_us),
		.njoints = d->ctl.n, .bus_connected = d->connected, .overruns = d->overruns,
		.bus_errors = d->bus_errors, .faults = d->ctl.faults, .bad_commands = d->bad_commands,
	};
	notify_format_status(buf, sizeof buf, &s);
	notify_send(&d->notify, buf);
}

/* Only a loop that completes cycles feeds the watchdog: a stall stops it. */
static void dmn_watchdog(struct dmn *d, uint64_t now)
{
	if (d->watchdog_interval_us == 0 || now - d->last_watchdog_us < d->watchdog_interval_us)
		return;
	if (d->cycle == d->watchdog_cycle)
		return;
	d->watchdog_cycle = d->cycle;
	d->last_watchdog_us = now;
	notify_send(&d->notify, "WATCHDOG=1");
}

/* ---- start-up checks (blocking; also after every reconnect) ----------------------------------- */
static void dmn_close_port(struct dmn *d)
{
	if (d->port != NULL) {
		bus_abort(&d->bus);
		port_close(d->port);
	}
	d->port = NULL;
	d->connected = false;
}

static bool dmn_find_servos(struct dmn *d, char *err, size_t cap)
{
	char missing[128] = "";
	size_t nmissing = 0;
	for (size_t j = 0; j < d->ctl.n; j++) {
		uint8_t id = d->ctl.j[j].id, eb = 0;
		int r = DXL_E_TIMEOUT;
		for (int t = 0; t < DMN_PING_TRIES && r != DXL_OK; t++) {
			r = bus_ping(&d->bus, id, &eb);
			if (r == DXL_E_DISCONNECTED || r == DXL_E_IO) {
				snprintf(err, cap, "%s: %s while pinging servo %u", d->port_path, dxl_strerror(r), id);
				return false;
			}
		}
		if (r != DXL_OK) {
			size_t len = strlen(missing);
			snprintf(missing + len, sizeof missing - len, "%s%u", nmissing ? ", " : "", id);
			nmissing++;
		}
	}
	if (nmissing == 0)
		return true;
	snprintf(err, cap, "servo ID%s %s did not answer a PING on %s at %ld bps (%d tries each): check power, "
	         "wiring, the IDs and the baud rate (`dxl --port PATH scan --bauds all`)", nmissing > 1 ? "s" : "", missing,
	         d->port_path, d->cfg->baud, DMN_PING_TRIES);
	return false;
}

/* A start-up read that meets a lost or damaged reply is tried again: one
 * timeout on a loaded machine must not abort the start (a cycle read simply
 * holds the joint for a period, but start-up has no next period). The port
 * going away is not retried. */
static int dmn_read_retry(struct dmn *d, uint8_t id, uint8_t addr, uint8_t len, uint8_t *out, uint8_t *eb)
{
	int r = DXL_E_TIMEOUT;
	for (int t = 0; t < DMN_PING_TRIES; t++) {
		r = bus_read(&d->bus, id, addr, len, out, eb);
		if (r == DXL_OK || r == DXL_E_DISCONNECTED || r == DXL_E_IO)
			break;
	}
	return r;
}

/* The same for a start-up write (writing the same bytes twice is harmless). */
static int dmn_write_retry(struct dmn *d, uint8_t id, uint8_t addr, const uint8_t *data, size_t n,
                           bool expect_reply, uint8_t *eb)
{
	int r = DXL_E_TIMEOUT;
	for (int t = 0; t < DMN_PING_TRIES; t++) {
		r = bus_write(&d->bus, id, addr, data, n, expect_reply, eb);
		if (r == DXL_OK || r == DXL_E_DISCONNECTED || r == DXL_E_IO)
			break;
	}
	return r;
}

/* Torque actuation found a servo in wheel mode (the daemon was stopped
 * without its safe stop, or the bus went away while the law drove it): stop
 * the drive, make the present position the goal, and give it angle limits
 * again — the configured joint limits — so joint mode holds it. */
static bool dmn_restore_joint_mode(struct dmn *d, size_t j, struct ctl_servo_info *info, char *err, size_t cap)
{
	const struct cfg_joint *cj = &d->cfg->joint[j];
	uint8_t id = d->ctl.j[j].id, eb = 0, raw[2];
	bool reply = info->status_return_level >= 2;
	int r = dmn_read_retry(d, id, DXL_AX_PRESENT_POSITION, 2, raw, &eb);
	uint8_t stop[4] = { raw[0], raw[1], 0, 0 }, off = 0;
	if (r == DXL_OK)
		r = dmn_write_retry(d, id, DXL_AX_GOAL_POSITION, stop, 4, reply, &eb);
	/* EEPROM: the AX-12A takes it only with torque off; ctl_start() turns
	 * torque on again */
	if (r == DXL_OK)
		r = dmn_write_retry(d, id, DXL_AX_TORQUE_ENABLE, &off, 1, reply, &eb);
	uint16_t cw = dxl_rad_to_pos(cj->neutral + cj->limit_min);
	uint16_t ccw = dxl_rad_to_pos(cj->neutral + cj->limit_max);
	/* whole units inside the configured limits */
	if (dxl_pos_to_rad(cw) < cj->neutral + cj->limit_min && cw < DXL_POS_MAX)
		cw++;
	if (dxl_pos_to_rad(ccw) > cj->neutral + cj->limit_max && ccw > 0)
		ccw--;
	uint8_t limits[4];
	dxl_put_u16(limits, cw);
	dxl_put_u16(limits + 2, ccw);
	if (r == DXL_OK)
		r = dmn_write_retry(d, id, DXL_AX_CW_ANGLE_LIMIT, limits, 4, reply, &eb);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: in wheel mode, and putting it back in joint mode failed: %s", id,
		         dxl_strerror(r));
		return false;
	}
	log_warn("servo %u was in wheel mode: drive stopped, angle limits set to the joint's %u..%u", id, cw, ccw);
	info->cw_limit = cw;
	info->ccw_limit = ccw;
	return true;
}

static bool dmn_read_servo(struct dmn *d, size_t j, char *err, size_t cap)
{
	uint8_t id = d->ctl.j[j].id, eb = 0;
	uint8_t t[DXL_AX_STATUS_RETURN_LEVEL + 1];
	int r = dmn_read_retry(d, id, 0, sizeof t, t, &eb);
	if (r != DXL_OK) {
		snprintf(err, cap, "servo %u: reading its settings failed: %s", id, dxl_strerror(r));
		return false;
	}
	uint16_t model = dxl_get_u16(&t[DXL_AX_MODEL_NUMBER]);
	if (model != DXL_AX12_MODEL)
		log_warn("servo %u: model number %u is not an AX-12 (%u); continuing with the AX-12 table", id,
		         model, DXL_AX12_MODEL);
	struct ctl_servo_info info = {
		.cw_limit = dxl_get_u16(&t[DXL_AX_CW_ANGLE_LIMIT]),
		.ccw_limit = dxl_get_u16(&t[DXL_AX_CCW_ANGLE_LIMIT]),
		.max_torque = dxl_get_u16(&t[DXL_AX_MAX_TORQUE]),
		.return_delay = t[DXL_AX_RETURN_DELAY_TIME],
		.status_return_level = t[DXL_AX_STATUS_RETURN_LEVEL],
	};
	if (info.status_return_level == 0) {
		snprintf(err, cap, "servo %u: status return level 0 (answers PING only): set it to 2 "
		         "(`dxl --port %s write %u status_return_level 2`)", id, d->port_path, id);
		return false;
	}
	if (d->cfg->actuation == CFG_ACT_TORQUE && dxl_is_wheel_mode(info.cw_limit, info.ccw_limit) &&
	    !dmn_restore_joint_mode(d, j, &info, err, cap))
		return false;
	if (info.max_torque == 0) {
		log_warn("servo %u: max torque (EEPROM) is 0: it cannot move; using 1023 as torque limit", id);
		info.max_torque = 1023;
	}
	unsigned delay_us = dxl_return_delay_us(info.return_delay);
	if (delay_us > 0)
		log_warn("servo %u: return delay %u µs costs %.1f ms a cycle on the bus; set it to 0 with "
		         "`dxl --port %s setup %u`", id, delay_us, 1e-3 * delay_us, d->port_path, id);
	if ((int)delay_us > d->max_return_delay_us)
		d->max_return_delay_us = (int)delay_us;
	/* Compliance margins are RAM: written again at every (re)connect, since
	 * a power loss resets them to the factory value. */
	if (d->cfg->compliance_margin >= 0) {
		uint8_t m = (uint8_t)d->cfg->compliance_margin;
		int wr = dmn_write_retry(d, id, DXL_AX_CW_COMPLIANCE_MARGIN, (const uint8_t[2]){ m, m }, 2,
		                         info.status_return_level >= 2, &eb);
		if (wr != DXL_OK) {
			snprintf(err, cap, "servo %u: setting compliance margin %u failed: %s", id, m, dxl_strerror(wr));
			return false;
		}
	}
	/* A moving speed left by another program would make every goal a slow
	 * ramp and the oscillator sluggish: 0 is "as fast as possible". */
	uint8_t ms[2];
	uint16_t moving_speed = 0;
	if (dmn_read_retry(d, id, DXL_AX_MOVING_SPEED, 2, ms, &eb) == DXL_OK)
		moving_speed = dxl_get_u16(ms);
	if (moving_speed != 0) {
		log_warn("servo %u: moving speed was %u (%.2f rad/s); setting 0 (maximum)", id, moving_speed,
		         moving_speed * DXL_SPEED_RAD_S_PER_UNIT);
		int wr = dmn_write_retry(d, id, DXL_AX_MOVING_SPEED, (const uint8_t[2]){ 0, 0 }, 2,
		                         info.status_return_level >= 2, &eb);
		if (wr != DXL_OK) {
			snprintf(err, cap, "servo %u: setting moving speed 0 failed: %s", id, dxl_strerror(wr));
			return false;
		}
	}
	return ctl_set_servo(&d->ctl, j, &info, err, cap);
}

static bool dmn_read_present(struct dmn *d, char *err, size_t cap)
{
	for (size_t j = 0; j < d->ctl.n; j++) {
		uint8_t id = d->ctl.j[j].id, eb = 0, p[6];
		int r = dmn_read_retry(d, id, DXL_AX_PRESENT_POSITION, 6, p, &eb);
		if (r != DXL_OK) {
			snprintf(err, cap, "servo %u: reading its position failed: %s", id, dxl_strerror(r));
			return false;
		}
		ctl_measure(&d->ctl, j, dxl_get_u16(p), dxl_get_u16(p + 2), dxl_get_u16(p + 4), eb,
		            d->period_us * 1e-6);
		d->read_at_us[j] = now_us();
	}
	return true;
}

static void dmn_latency(struct dmn *d)
{
	long us = d->cfg->adapter_latency_us;
	d->adapter_latency_ms = -1.0;
	if (us < 0) {
		/* port_open() already checked (and tried to lower) the latency timer on
		 * the fd it holds; opening the device again would fail with EBUSY on an
		 * exclusively held real port and lose the ASYNC_LOW_LATENCY fallback. */
		struct port_latency lat = { 0 };
		const struct port_latency *opened = d->port ? port_get_latency(d->port) : NULL;
		if (opened)
			lat = *opened;
		else
			port_latency_check_fd(d->port_path, d->port ? port_fd(d->port) : -1, true, &lat);
		if (lat.known) {
			us = 1000L * lat.timer_ms;
			d->adapter_latency_ms = lat.timer_ms;
		}
		if (lat.known && lat.timer_ms > 1)
			log_warn("%s: adapter latency timer %d ms (%s): replies wait that long, 100 Hz is out of "
			         "reach; set it to 1 ms (`dxl --port PATH setup`, or the udev rule in systemd/)", d->port_path,
			         lat.timer_ms, lat.note);
		if (us < 0)
			us = 0;
	} else {
		d->adapter_latency_ms = 1e-3 * (double)us;
		if (us > 1000)
			log_warn("adapter_latency_us = %ld: replies wait that long, 100 Hz needs <= 1000 µs "
			         "(`dxl --port PATH setup`)", us);
	}
	struct bus_timing tm = {
		.baud = d->cfg->baud, .return_delay_us = (uint32_t)d->max_return_delay_us,
		.adapter_latency_us = (uint32_t)us, .margin_us = (uint32_t)d->cfg->bus_margin_us,
	};
	bus_set_timing(&d->bus, &tm);
}

/* usb_serial = ...: the adapter with that USB serial number, wherever it is
 * enumerated now (ttyUSB numbers change on replugging). */
static bool dmn_find_port(struct dmn *d, char *err, size_t cap)
{
	if (d->cfg->usb_serial[0] == '\0')
		return true;
	static struct port_info ports[DMN_MAX_PORTS];
	int n = port_list(ports, DMN_MAX_PORTS);
	for (int i = 0; i < n && i < DMN_MAX_PORTS; i++) {
		if (strcmp(ports[i].serial, d->cfg->usb_serial) == 0) {
			snprintf(d->port_path, sizeof d->port_path, "%s", ports[i].path);
			return true;
		}
	}
	snprintf(err, cap, "no serial port with USB serial number '%s' (%d port(s) found; `dxl ports` lists them)",
	         d->cfg->usb_serial, n < 0 ? 0 : n);
	return false;
}

/* Open the port and run every start-up check. On failure *err says why. */
static bool dmn_connect(struct dmn *d, const char *reason, char *err, size_t cap)
{
	if (!dmn_find_port(d, err, cap))
		return false;
	struct port_options opt = { .baud = d->cfg->baud, .force_termios = false, .low_latency = true };
	d->port = port_open(d->port_path, &opt, err, cap);
	if (d->port == NULL)
		return false;
	struct bus_io io;
	port_bus_io(d->port, &io);
	struct bus_timing tm = {
		.baud = d->cfg->baud, .return_delay_us = DMN_DEFAULT_RETURN_DELAY_US,
		.adapter_latency_us = d->cfg->adapter_latency_us > 0 ? (uint32_t)d->cfg->adapter_latency_us : 0,
		.margin_us = (uint32_t)d->cfg->bus_margin_us,
	};
	bus_init(&d->bus, &io, &tm, d->cfg->echo);
	d->max_return_delay_us = 0;
	bool ok = dmn_find_servos(d, err, cap);
	for (size_t j = 0; ok && j < d->ctl.n; j++)
		ok = dmn_read_servo(d, j, err, cap);
	if (ok) {
		dmn_latency(d);
		ok = dmn_read_present(d, err, cap);
	}
	if (!ok) {
		dmn_close_port(d);
		return false;
	}
	d->connected = true;
	d->phase = PH_IDLE;
	d->backoff_ms = DMN_BACKOFF_MIN_MS;
	ctl_start(&d->ctl, 1e-6 * (double)(now_us() - d->first_tick_us), reason);
	return true;
}

static void dmn_bus_lost(struct dmn *d, int why)
{
	char text[CFG_PATH_MAX + 96];
	snprintf(text, sizeof text, "%s: %s: bus lost, joints hold; reconnecting every %.1f..%.1f s",
	         d->port_path, dxl_strerror(why), 1e-3 * DMN_BACKOFF_MIN_MS, 1e-3 * DMN_BACKOFF_MAX_MS);
	dmn_close_port(d);
	ctl_bus_lost(&d->ctl);
	d->backoff_ms = DMN_BACKOFF_MIN_MS;
	d->reconnect_at_us = now_us() + 1000ULL * d->backoff_ms;
	dmn_event(d, 0, 2, "bus-lost", text);
	dmn_notify_status(d);
}

static void dmn_try_reconnect(struct dmn *d, uint64_t now)
{
	if (d->connected || now < d->reconnect_at_us)
		return;
	char err[512];
	if (dmn_connect(d, "reconnected", err, sizeof err)) {
		d->reconnects++;
		char text[CFG_PATH_MAX + 96];
		snprintf(text, sizeof text, "%s: bus back (reconnect %lld), start-up checks passed", d->port_path,
		         d->reconnects);
		dmn_event(d, 0, 0, "bus-back", text);
		dmn_notify_status(d);
		return;
	}
	log_limited(&d->lim_bus, now, LOG_LVL_WARN, "reconnect failed: %s (next try in %.1f s)", err,
	            1e-3 * d->backoff_ms);
	d->reconnect_at_us = now + 1000ULL * d->backoff_ms;
	d->backoff_ms = d->backoff_ms * 2 > DMN_BACKOFF_MAX_MS ? DMN_BACKOFF_MAX_MS : d->backoff_ms * 2;
}

/* ---- the cycle's bus state machine -------------------------------------------------------------- */
static void dmn_arm_deadline(struct dmn *d)
{
	struct itimerspec its = { 0 };
	if (bus_is_pending(&d->bus)) {
		uint64_t dl = bus_deadline_us(&d->bus);
		its.it_value.tv_sec = (time_t)(dl / 1000000);
		its.it_value.tv_nsec = (long)(dl % 1000000) * 1000;
		if (its.it_value.tv_sec == 0 && its.it_value.tv_nsec == 0)
			its.it_value.tv_nsec = 1;
	}
	timerfd_settime(d->deadline_fd, TFD_TIMER_ABSTIME, &its, NULL);
}

static void dmn_bus_error(struct dmn *d, uint8_t id, const char *what, int r)
{
	d->bus_errors++;
	log_limited(&d->lim_bus, now_us(), LOG_LVL_WARN, "servo %u: %s: %s", id, what, dxl_strerror(r));
}

static int dmn_begin_read(struct dmn *d, size_t j, uint8_t addr, uint8_t len)
{
	uint8_t params[2] = { addr, len };
	return bus_begin(&d->bus, d->ctl.j[j].id, DXL_INST_READ, params, 2, len);
}

static int dmn_begin_write(struct dmn *d, const struct ctl_write *w)
{
	uint8_t params[5] = { w->addr, (uint8_t)(w->value & 0xFF), (uint8_t)(w->value >> 8),
	                      (uint8_t)(w->value >> 16), (uint8_t)(w->value >> 24) };
	int reply = -1;
	for (size_t j = 0; j < d->ctl.n; j++)
		if (d->ctl.j[j].id == w->id && d->ctl.j[j].servo.status_return_level >= 2)
			reply = 0;
	return bus_begin(&d->bus, w->id, DXL_INST_WRITE, params, (size_t)w->len + 1, reply);
}

/* The cycle's SYNC_WRITE: goals, wheel-mode duties, or (leaving wheel mode)
 * goals with moving speed 0, which stops the drive and is joint mode's
 * "as fast as possible" again. */
static int dmn_send_goals(struct dmn *d)
{
	uint8_t ids[CFG_MAX_JOINTS], data[4 * CFG_MAX_JOINTS];
	uint8_t pkt[DXL_MAX_PACKET];
	size_t n = 0;
	enum ctl_sync sync = d->ctl.sync;
	size_t width = sync == CTL_SYNC_GOAL_STOP ? 4 : 2;
	for (size_t j = 0; j < d->ctl.n; j++) {
		const struct ctl_joint *jt = &d->ctl.j[j];
		if (sync == CTL_SYNC_DUTY) {
			/* the conversion clamps and turns a non-finite duty into 0 */
			ids[n] = jt->id;
			dxl_put_u16(&data[2 * n], dxl_duty_to_wheel(jt->duty));
			n++;
			continue;
		}
		/* safety_clamp() made goal finite and inside the limits; the
		 * conversion clamps to 0..1023 as a last line. */
		if (!jt->write_goal || !isfinite(jt->goal))
			continue;
		ids[n] = jt->id;
		dxl_put_u16(&data[width * n], dxl_rad_to_pos(jt->goal));
		if (width == 4)
			dxl_put_u16(&data[width * n + 2], 0);
		n++;
	}
	if (n == 0)
		return DXL_OK;
	uint8_t addr = sync == CTL_SYNC_DUTY ? DXL_AX_MOVING_SPEED : DXL_AX_GOAL_POSITION;
	int len = dxl_encode_sync_write(pkt, sizeof pkt, addr, (uint8_t)width, ids, data, n);
	if (len < 0)
		return len;
	return bus_send_raw(&d->bus, pkt, (size_t)len);
}

static void dmn_cycle_done(struct dmn *d);
static void dmn_advance(struct dmn *d);

/* Register writes are queued commands (torque on, recovery, mode switches):
 * one that was sent is done. Those not sent yet move to the front of the
 * queue for the next cycle, where ctl_step() may add to them. Without this a
 * queue longer than what fits after the reads (torque on for 16+ servos at
 * start-up) was sent again from its start every cycle and never finished. */
static void dmn_defer_writes(struct dmn *d)
{
	struct ctl *c = &d->ctl;
	size_t sent = d->idx < c->nwrites ? d->idx : c->nwrites;
	memmove(c->writes, c->writes + sent, (c->nwrites - sent) * sizeof c->writes[0]);
	c->nwrites -= sent;
	d->idx = 0;
}

/* Past this share of the period no new write is begun: a transaction cut off
 * by the next tick leaves its reply on the line to collide with the next
 * cycle's first READ. */
#define DMN_WRITES_UNTIL 0.7
static bool dmn_late_in_cycle(const struct dmn *d)
{
	return (double)(now_us() - d->cycle_start_us) > DMN_WRITES_UNTIL * (double)d->period_us;
}

static void dmn_control(struct dmn *d)
{
	uint64_t t0 = now_us();
	double dt = 1e-6 * (double)(d->cycle_start_us - d->last_cycle_start_us);
	ctl_step(&d->ctl, 1e-6 * (double)(d->cycle_start_us - d->first_tick_us), dt, 1e-6 * (double)wall_us());
	d->control_us = (double)(now_us() - t0);
}

/* Start the next transaction of the cycle, skipping phases with nothing to do.
 * Returns when one is pending or the cycle is done. */
static void dmn_advance(struct dmn *d)
{
	for (;;) {
		if (!d->connected) {
			dmn_cycle_done(d);
			return;
		}
		int r = DXL_OK;
		switch (d->phase) {
		case PH_IDLE:
			return;
		case PH_READ:
			if (d->idx < d->ctl.n) {
				r = dmn_begin_read(d, d->idx, DXL_AX_PRESENT_POSITION, 6);
				break;
			}
			dmn_control(d);
			d->phase = PH_SYNC;
			continue;
		case PH_SYNC:
			r = dmn_send_goals(d);
			d->phase = PH_WRITES;
			d->idx = 0;
			if (r != DXL_OK)
				break;
			continue;
		case PH_WRITES:
			if (d->idx < d->ctl.nwrites && dmn_late_in_cycle(d)) {
				/* the rest waits for the next cycle: the reads come first */
				dmn_defer_writes(d);
				dmn_cycle_done(d);
				return;
			}
			if (d->idx < d->ctl.nwrites) {
				r = dmn_begin_write(d, &d->ctl.writes[d->idx]);
				break;
			}
			d->ctl.nwrites = 0;
			d->phase = PH_SLOW;
			if (d->cycle % DMN_SLOW_EVERY != 0 || d->ctl.n == 0) {
				dmn_cycle_done(d);
				return;
			}
			d->slow_joint = (d->slow_joint + 1) % d->ctl.n;
			r = dmn_begin_read(d, d->slow_joint, DXL_AX_PRESENT_VOLTAGE, 2);
			break;
		case PH_SLOW:
			dmn_cycle_done(d);
			return;
		}
		if (r == DXL_E_DISCONNECTED || r == DXL_E_IO) {
			dmn_bus_lost(d, r);
			dmn_cycle_done(d);
			return;
		}
		if (r != DXL_OK) {
			dmn_bus_error(d, d->phase == PH_READ ? d->ctl.j[d->idx].id : 0xFE, "request", r);
			d->idx++;
			continue;
		}
		if (bus_is_pending(&d->bus)) {
			dmn_arm_deadline(d);
			return;
		}
		/* no reply expected: next */
		if (d->phase == PH_READ || d->phase == PH_WRITES)
			d->idx++;
	}
}

static void dmn_reply(struct dmn *d, const struct dxl_packet *p)
{
	switch (d->phase) {
	case PH_READ:
		if (p->nparams == 6) {
			/* the position difference is over the time between this joint's
			 * own replies: a timeout earlier in the cycle shifts them */
			uint64_t now = now_us();
			uint64_t last = d->read_at_us[d->idx];
			double dt = last != 0 && now > last ? 1e-6 * (double)(now - last)
			                                    : 1e-6 * (double)d->period_us;
			d->read_at_us[d->idx] = now;
			ctl_measure(&d->ctl, d->idx, dxl_get_u16(p->params), dxl_get_u16(p->params + 2),
			            dxl_get_u16(p->params + 4), p->code, dt);
		}
		d->idx++;
		break;
	case PH_WRITES:
		d->idx++;
		break;
	case PH_SLOW:
		if (p->nparams == 2)
			ctl_measure_slow(&d->ctl, d->slow_joint, p->params[0], p->params[1], p->code);
		break;
	default:
		break;
	}
}

/* Input on the bus fd or its deadline passed. */
static void dmn_bus_event(struct dmn *d)
{
	if (!bus_is_pending(&d->bus))
		return;
	struct dxl_packet reply;
	int r = bus_step(&d->bus, &reply);
	if (r == BUS_PENDING) {
		dmn_arm_deadline(d);
		return;
	}
	if (r == DXL_OK) {
		dmn_reply(d, &reply);
	} else if (r == DXL_E_DISCONNECTED || r == DXL_E_IO) {
		dmn_bus_lost(d, r);
		dmn_cycle_done(d);
		return;
	} else {
		uint8_t id = d->phase == PH_SLOW ? d->ctl.j[d->slow_joint].id
		           : d->idx < d->ctl.n && d->phase == PH_READ ? d->ctl.j[d->idx].id : 0xFE;
		dmn_bus_error(d, id, d->phase == PH_READ ? "READ" : d->phase == PH_SLOW ? "READ(42)" : "WRITE", r);
		if (d->phase == PH_READ || d->phase == PH_WRITES)
			d->idx++;
	}
	dmn_advance(d);
}

static void dmn_cycle_done(struct dmn *d)
{
	if (d->phase == PH_IDLE)
		return;
	d->phase = PH_IDLE;
	dmn_arm_deadline(d);
	if (d->connected) {
		d->bus_us = (double)(now_us() - d->bus_start_us) - d->control_us;
		stats_add(&d->w_bus, d->bus_us);
	}
	dmn_flush_ctl_events(d);
	dmn_publish_state(d);
	d->cycle++;
}

/* ---- the timer ------------------------------------------------------------------------------- */
static void dmn_tick(struct dmn *d)
{
	uint64_t exp = 0;
	if (read(d->timer_fd, &exp, sizeof exp) != (ssize_t)sizeof exp || exp == 0)
		return;
	uint64_t now = now_us();
	d->ticks += exp;
	if (exp > 1) {
		/* whole periods were missed: skip them, keep the phase */
		d->overruns += (long long)(exp - 1);
		log_limited(&d->lim_overrun, now, LOG_LVL_WARN, "overrun: %" PRIu64 " period(s) skipped",
		            exp - 1);
	}
	uint64_t scheduled = d->first_tick_us + (d->ticks - 1) * d->period_us;
	if (d->phase != PH_IDLE) {
		/* the previous cycle's bus work is still going: give it up (a write
		 * cut off is sent again next cycle) */
		if (d->phase == PH_WRITES)
			dmn_defer_writes(d);
		bus_abort(&d->bus);
		d->bus_errors++;
		d->overruns++;
		log_limited(&d->lim_overrun, now, LOG_LVL_WARN, "cycle %" PRIu64 " still on the bus at the next tick",
		            d->cycle);
		dmn_cycle_done(d);
	}
	d->last_cycle_start_us = d->cycle_start_us ? d->cycle_start_us : now - d->period_us;
	d->cycle_start_us = now;
	d->jitter_us = (double)(now - scheduled);
	d->period_meas_us = (double)(now - d->last_cycle_start_us);
	stats_add(&d->w_period, d->period_meas_us);
	stats_add(&d->w_jitter, d->jitter_us);

	if (!d->connected)
		dmn_try_reconnect(d, now);
	if (now - d->second_start_us >= 1000000) {
		dmn_publish_bus_stats(d, 1e-6 * (double)(now - d->second_start_us));
		dmn_publish_params(d);
		dmn_notify_status(d);
		d->second_start_us = now;
	} else if (d->params_dirty) {
		dmn_publish_params(d);
	}
	dmn_watchdog(d, now);

	d->bus_start_us = now_us();
	d->bus_us = 0.0;
	d->idx = 0;
	d->phase = PH_READ;
	if (!d->connected) {
		/* no bus: still run the controller (joints stale, nothing written) so
		 * the state keeps flowing and the period is kept */
		dmn_control(d);
		d->ctl.nwrites = 0;
		dmn_cycle_done(d);
		return;
	}
	dmn_advance(d);
}

/* ---- commands --------------------------------------------------------------------------------- */
static void dmn_reject(struct dmn *d, int64_t seq, const char *why)
{
	d->bad_commands++;
	log_limited(&d->lim_cmd, now_us(), LOG_LVL_WARN, "command %" PRId64 " rejected: %s", seq, why);
	dmn_event_quiet(d, seq, 1, "command-rejected", why);
}

static void dmn_apply(struct dmn *d, const struct cmd_request *r, char *text, size_t cap)
{
	switch (r->kind) {
	case CMD_KIND_MODE: {
		char reason[64];
		snprintf(reason, sizeof reason, "command from %.40s", r->source && r->source[0] ? r->source : "?");
		ctl_set_mode(&d->ctl, (enum cfg_mode)r->mode, reason);
		snprintf(text, cap, "mode %s", cfg_mode_name((enum cfg_mode)r->mode));
		break;
	}
	case CMD_KIND_PARAM:
		cmd_apply_param(d->cfg, r);
		ctl_params_changed(&d->ctl);
		d->params_dirty = true;
		snprintf(text, cap, "param %s = %g (joint %d)", r->param, r->value, r->joint);
		break;
	case CMD_KIND_TORQUE:
		ctl_torque(&d->ctl, r->torque);
		snprintf(text, cap, "torque %s", r->torque ? "on" : "off");
		break;
	}
	dmn_flush_ctl_events(d);
	dmn_notify_status(d);
}

static void dmn_on_command(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
	struct dmn *d = user;
	bool direct = strcmp(channel, d->ch_cmd) == 0;
	/* our own decoder: no allocation, and no trust in string lengths (command.h) */
	static struct cmd_wire w;
	char why[256];
	if (!cmd_decode(rbuf->data, rbuf->data_size, d->cmd_fingerprint, &w, why, sizeof why)) {
		char text[320];
		snprintf(text, sizeof text, "undecodable command_t on %s (%u bytes): %s", channel, rbuf->data_size, why);
		dmn_reject(d, 0, text);
		return;
	}
	const struct cmd_request *r = &w.req;
	enum cmd_verdict v = cmd_check(r, d->cfg, direct, why, sizeof why);
	if (v == CMD_REJECT) {
		dmn_reject(d, r->seq, why);
	} else if (v == CMD_ACCEPT) {
		char text[160];
		dmn_apply(d, r, text, sizeof text);
		dmn_event_quiet(d, r->seq, 0, "command-accepted", text);
		log_info("command %" PRId64 " from %s: %s", r->seq, r->source, text);
	}
}

/* ---- set-up and the loop ----------------------------------------------------------------------- */
static void dmn_realtime(const struct cfg *cfg)
{
	if (cfg->mlockall && mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
		log_warn("mlockall: %s (needs CAP_IPC_LOCK or LimitMEMLOCK=infinity); continuing unlocked",
		         strerror(errno));
	if (cfg->priority > 0) {
		struct sched_param sp = { .sched_priority = cfg->priority };
		if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
			log_warn("SCHED_FIFO priority %d: %s (needs CAP_SYS_NICE or LimitRTPRIO); continuing with "
			         "normal scheduling", cfg->priority, strerror(errno));
	}
}

static bool dmn_fds(struct dmn *d)
{
	sigset_t set;
	sigemptyset(&set);
	sigaddset(&set, SIGTERM);
	sigaddset(&set, SIGINT);
	sigprocmask(SIG_BLOCK, &set, NULL);
	signal(SIGPIPE, SIG_IGN);
	d->signal_fd = signalfd(-1, &set, SFD_NONBLOCK | SFD_CLOEXEC);
	d->timer_fd = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
	d->deadline_fd = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
	if (d->signal_fd < 0 || d->timer_fd < 0 || d->deadline_fd < 0) {
		log_error("signalfd/timerfd: %s", strerror(errno));
		return false;
	}
	return true;
}

static void dmn_start_timer(struct dmn *d)
{
	d->first_tick_us = now_us() + d->period_us;
	struct itimerspec its = {
		.it_interval = { .tv_sec = (time_t)(d->period_us / 1000000),
		                 .tv_nsec = (long)(d->period_us % 1000000) * 1000 },
		.it_value = { .tv_sec = (time_t)(d->first_tick_us / 1000000),
		              .tv_nsec = (long)(d->first_tick_us % 1000000) * 1000 },
	};
	timerfd_settime(d->timer_fd, TFD_TIMER_ABSTIME, &its, NULL);
	d->second_start_us = now_us();
}

static bool dmn_lcm(struct dmn *d)
{
	const char *url = d->cfg->lcm_url[0] ? d->cfg->lcm_url : NULL;
	d->lcm = lcm_create(url);
	if (d->lcm == NULL) {
		log_error("cannot create LCM (url %s): check the URL and that multicast works "
		          "(e.g. a route for 239.255.76.67)", url ? url : "default");
		return false;
	}
	snprintf(d->ch_state, sizeof d->ch_state, "%s.STATE", d->cfg->name);
	snprintf(d->ch_bus, sizeof d->ch_bus, "%s.BUS", d->cfg->name);
	snprintf(d->ch_params, sizeof d->ch_params, "%s.PARAMS", d->cfg->name);
	snprintf(d->ch_event, sizeof d->ch_event, "%s.EVENT", d->cfg->name);
	snprintf(d->ch_cmd, sizeof d->ch_cmd, "%s.CMD", d->cfg->name);
	d->cmd_fingerprint = __undulate_command_t_get_hash();
	lcm_subscribe(d->lcm, d->ch_cmd, dmn_on_command, d);
	lcm_subscribe(d->lcm, "UNDULATE.CMD", dmn_on_command, d);
	return true;
}

/* Torque actuation at exit: no servo may be left driving in wheel mode. Stop
 * every drive first (one packet), then goals at the present positions, then
 * the angle limits back; the safe state below then holds or goes limp. */
static void dmn_stop_wheel(struct dmn *d, bool limp)
{
	uint8_t ids[CFG_MAX_JOINTS], zero[2 * CFG_MAX_JOINTS] = { 0 };
	for (size_t j = 0; j < d->ctl.n; j++)
		ids[j] = d->ctl.j[j].id;
	bus_sync_write(&d->bus, DXL_AX_MOVING_SPEED, 2, ids, zero, d->ctl.n);
	for (size_t j = 0; j < d->ctl.n; j++) {
		struct ctl_joint *jt = &d->ctl.j[j];
		bool reply = jt->servo.status_return_level >= 2;
		uint8_t eb, raw[2], limits[4];
		const uint8_t off = 0, on = 1;
		int r = dmn_read_retry(d, jt->id, DXL_AX_PRESENT_POSITION, 2, raw, &eb);
		if (r == DXL_OK) {
			double hold = safety_clamp(&jt->limits, dxl_pos_to_rad(dxl_get_u16(raw)), NAN, NAN, NULL);
			dxl_put_u16(raw, dxl_rad_to_pos(hold));
			r = dmn_write_retry(d, jt->id, DXL_AX_GOAL_POSITION, raw, 2, reply, &eb);
		}
		uint32_t lim = ctl_joint_mode_limits(&d->ctl, j);
		dxl_put_u16(limits, (uint16_t)(lim & 0xFFFF));
		dxl_put_u16(limits + 2, (uint16_t)(lim >> 16));
		/* EEPROM: written with torque off (AX-12A) */
		if (r == DXL_OK)
			r = dmn_write_retry(d, jt->id, DXL_AX_TORQUE_ENABLE, &off, 1, reply, &eb);
		if (r == DXL_OK)
			r = dmn_write_retry(d, jt->id, DXL_AX_CW_ANGLE_LIMIT, limits, 4, reply, &eb);
		if (r == DXL_OK && !limp)
			r = dmn_write_retry(d, jt->id, DXL_AX_TORQUE_ENABLE, &on, 1, reply, &eb);
		if (r != DXL_OK)
			log_error("safe stop: servo %u: back to joint mode failed (%s); its drive was stopped",
			          jt->id, dxl_strerror(r));
	}
	d->ctl.wheel = false;
	log_info("safe stop: torque actuation ended, servos back in joint mode");
}

/* Leave the configured safe state on the bus (blocking: we are exiting). */
static void dmn_safe_stop(struct dmn *d)
{
	if (!d->connected)
		return;
	bus_abort(&d->bus);
	d->phase = PH_IDLE;
	/* a robot that is limp stays limp: writing goals could bring torque back */
	bool limp = d->cfg->safe_stop == CFG_SAFE_LIMP || d->ctl.mode == CFG_MODE_LIMP;
	if (d->ctl.wheel)
		dmn_stop_wheel(d, limp);
	uint8_t ids[CFG_MAX_JOINTS], data[2 * CFG_MAX_JOINTS];
	size_t n = 0;
	for (size_t j = 0; j < d->ctl.n; j++) {
		struct ctl_joint *jt = &d->ctl.j[j];
		uint8_t eb;
		if (limp) {
			bool reply = jt->servo.status_return_level >= 2;
			const uint8_t off = 0;
			int r = dmn_write_retry(d, jt->id, DXL_AX_TORQUE_ENABLE, &off, 1, reply, &eb);
			if (r != DXL_OK)
				log_error("safe stop: servo %u torque off failed: %s", jt->id, dxl_strerror(r));
			continue;
		}
		uint8_t raw[2];
		if (dmn_read_retry(d, jt->id, DXL_AX_PRESENT_POSITION, 2, raw, &eb) != DXL_OK) {
			log_error("safe stop: servo %u did not answer; it keeps its last goal", jt->id);
			continue;
		}
		uint16_t pos = dxl_get_u16(raw);
		double hold = isfinite(jt->limits.lo) && jt->limits.max_step > 0
		            ? safety_clamp(&jt->limits, dxl_pos_to_rad(pos), NAN, NAN, NULL) : dxl_pos_to_rad(pos);
		ids[n] = jt->id;
		dxl_put_u16(&data[2 * n], dxl_rad_to_pos(hold));
		n++;
	}
	if (n > 0)
		bus_sync_write(&d->bus, DXL_AX_GOAL_POSITION, 2, ids, data, n);
	log_info("safe stop: %s", limp ? "torque off (limp)" : "holding present positions, torque on");
}

static void dmn_loop(struct dmn *d)
{
	while (!d->stop) {
		struct pollfd pfd[5];
		int lcm_fd = lcm_get_fileno(d->lcm);
		pfd[0] = (struct pollfd){ .fd = d->timer_fd, .events = POLLIN };
		pfd[1] = (struct pollfd){ .fd = d->deadline_fd, .events = POLLIN };
		pfd[2] = (struct pollfd){ .fd = lcm_fd, .events = POLLIN };
		pfd[3] = (struct pollfd){ .fd = d->signal_fd, .events = POLLIN };
		/* bus fd: readable only matters while a reply is awaited; HUP/ERR always */
		pfd[4] = (struct pollfd){ .fd = d->connected ? port_fd(d->port) : -1,
		                          .events = (short)(bus_is_pending(&d->bus) ? POLLIN : 0) };
		int n = poll(pfd, 5, -1);
		if (n < 0) {
			if (errno == EINTR)
				continue;
			log_error("poll: %s", strerror(errno));
			return;
		}
		if (pfd[3].revents & POLLIN) {
			struct signalfd_siginfo si;
			if (read(d->signal_fd, &si, sizeof si) == (ssize_t)sizeof si) {
				log_info("signal %u: stopping", si.ssi_signo);
				d->stop = true;
				return;
			}
		}
		if (pfd[4].revents & (POLLHUP | POLLERR | POLLNVAL)) {
			if (bus_is_pending(&d->bus))
				dmn_bus_event(d);   /* reads the remaining bytes, then reports the loss */
			if (d->connected) {
				dmn_bus_lost(d, DXL_E_DISCONNECTED);
				dmn_cycle_done(d);
			}
		} else if (pfd[4].revents & POLLIN) {
			dmn_bus_event(d);
		}
		if (pfd[1].revents & POLLIN) {
			uint64_t x;
			if (read(d->deadline_fd, &x, sizeof x) < 0 && errno != EAGAIN)
				log_debug("deadline timer: %s", strerror(errno));
			dmn_bus_event(d);
		}
		if (pfd[0].revents & POLLIN)
			dmn_tick(d);
		if (pfd[2].revents & POLLIN)
			lcm_handle_timeout(d->lcm, 0);
	}
}

int dmn_run(struct cfg *cfg)
{
	static struct dmn dmn;   /* large (bus stats per ID): not on the stack */
	struct dmn *d = &dmn;
	memset(d, 0, sizeof *d);
	d->cfg = cfg;
	d->lim_bus = (struct log_limit)LOG_LIMIT_INIT(5, 2000000);
	d->lim_cmd = (struct log_limit)LOG_LIMIT_INIT(5, 1000000);
	d->lim_overrun = (struct log_limit)LOG_LIMIT_INIT(5, 5000000);
	d->lim_lcm = (struct log_limit)LOG_LIMIT_INIT(3, 10000000);
	d->period_us = (uint64_t)llround(cfg->period_ms * 1000.0);
	d->timer_fd = d->deadline_fd = d->signal_fd = -1;
	snprintf(d->port_path, sizeof d->port_path, "%s", cfg->port);
	ctl_init(&d->ctl, cfg);
	notify_init(&d->notify);
	d->watchdog_interval_us = notify_watchdog_interval_us(&d->notify);
	d->encode_buf = malloc(DMN_ENCODE_CAP);
	if (d->encode_buf == NULL || !dmn_fds(d) || !dmn_lcm(d))
		return 1;
	getrusage(RUSAGE_SELF, &d->ru_last);

	char err[512];
	d->first_tick_us = now_us();
	if (!dmn_connect(d, "start", err, sizeof err)) {
		log_error("%s", err);
		dmn_event_quiet(d, 0, 2, "start-failed", err);
		return 1;
	}
	log_info("robot %s: %zu joint(s) on %s at %ld bps, mode %s, LCM %s", cfg->name, cfg->njoints,
	         d->port_path, cfg->baud, cfg_mode_name(d->ctl.mode), cfg->lcm_url[0] ? cfg->lcm_url : "default");
	dmn_realtime(cfg);
	dmn_start_timer(d);
	/* the ramp's clock starts with the timer */
	for (size_t j = 0; j < d->ctl.n; j++)
		d->ctl.blend_t0[j] = 0.0;
	dmn_flush_ctl_events(d);
	dmn_publish_params(d);
	notify_send(&d->notify, "READY=1");
	dmn_notify_status(d);
	log_info("ready: %s, %s, %.0f Hz", d->ch_state, d->ch_cmd, 1e6 / (double)d->period_us);

	dmn_loop(d);

	notify_send(&d->notify, "STOPPING=1");
	dmn_safe_stop(d);
	char text[96];
	snprintf(text, sizeof text, "stopped: %s", cfg->safe_stop == CFG_SAFE_LIMP ? "limp" : "holding");
	dmn_event(d, 0, 0, "stop", text);
	dmn_close_port(d);
	lcm_destroy(d->lcm);
	notify_close(&d->notify);
	free(d->encode_buf);
	return 0;
}
