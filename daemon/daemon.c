/*
 * daemon.c — see daemon.h. The loop and what ties the modules together:
 *
 *   timer tick ─→ cycle.c drives the cycle's bus work; when the readings are
 *   in, commands queued since the last cycle are applied (cmdin.c) and the
 *   controller steps (control.c) ─→ its goals and writes go out ─→ the
 *   state is published (publish.c).
 *
 * A robot on several buses ([bus.NAME]) has a cycle per bus (struct
 * dmn_bus), all begun at the tick and driven in parallel; the control step
 * runs once, when every connected bus's readings are in, and each bus then
 * sends its joints' share (dmn_maybe_control). One bus has one dmn_bus, and
 * runs as it always did.
 *
 * One thread, one loop, one poll() over the command sockets, signals and the
 * clock's descriptors: the control timer, every bus and the deadline timer in
 * real time, the simulator's socket in lockstep (struct dmn_clock: the clock
 * is a source of ticks, not a second loop). Start-up checks and the safe stop
 * (setup.c) block; nothing else does. Nothing here writes the controller's
 * state: it calls the controller.
 */
#include "clock.h"
#include "daemon.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/signalfd.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include "bus.h"
#include "cmdin.h"
#include "control.h"
#include "cycle.h"
#include "dxl.h"
#include "lockstep.h"
#include "log.h"
#include "notify.h"
#include "port.h"
#include "publish.h"
#include "setup.h"
#include "stats.h"
#include "tune.h"
#include "undulate_command_t.h"

/* Reconnect back-off: 100 ms doubling to 2 s. */
#define DMN_BACKOFF_MIN_MS 100
#define DMN_BACKOFF_MAX_MS 2000
/* Assumed until the servos are read: the AX-12's factory return delay. */
#define DMN_DEFAULT_RETURN_DELAY_US 500

struct dmn;

/* What a wake-up of the loop brought (filled by the clock, below). */
struct dmn_wake {
	bool bus_hup[CFG_MAX_BUSES];   /* the port hung up */
	bool bus_in[CFG_MAX_BUSES];    /* reply bytes may be there */
	bool bus_deadline;   /* a bus's deadline passed */
	uint64_t ticks;      /* periods since the last tick: 0 none, more than 1 some were missed */
	uint64_t now;        /* the tick's time */
};

/* Descriptors a clock adds to the loop's poll(), at most: two timers and
 * every bus's port. */
#define DMN_CLOCK_FDS (2 + CFG_MAX_BUSES)

/* What paces the loop: the system's clock (timerfds, the bus fd) or, in
 * lockstep, the simulator's (common/lockstep.h). The loop and everything
 * done at a tick or a bus event are one; a clock only arms the tick and the
 * bus deadline, waits, and says what the wake-up brought — as chrony's one
 * scheduler serves every module whatever its time source. */
struct dmn_clock {
	/* the ticks start at d->first_tick_us, one period apart */
	void (*start)(struct dmn *d);
	/* the buses' deadline is now the earliest of their cycles' (0: none) */
	void (*arm_deadline)(struct dmn *d);
	/* about to block: may end the run (d->stop) when the clock is gone */
	void (*before_wait)(struct dmn *d);
	/* its descriptors into pfd: how many (<= DMN_CLOCK_FDS) */
	nfds_t (*fds)(struct dmn *d, struct pollfd *pfd);
	/* poll() returned: what came, from its descriptors' revents */
	void (*woke)(struct dmn *d, const struct pollfd *pfd, struct dmn_wake *w);
};

/* One port of the robot and the cycle's work on it: one for most robots,
 * one per [bus.NAME] on a robot whose joints are on several (config.h).
 * Each is driven on its own, in parallel, within the robot's one cycle. */
struct dmn_bus {
	size_t index;                 /* the configuration's bus: cfg->bus[index] */
	const struct cfg_bus *cb;
	struct cyc cyc;
	struct port *port;
	struct bus bus;
	char port_path[CFG_PATH_MAX];
	bool connected;
	bool at_control;              /* its reads are in: waiting for the robot's control step */
	uint64_t reconnect_at_us;
	uint32_t backoff_ms;
	long long reconnects;
	double adapter_latency_ms;
	int max_return_delay_us;
	struct stats_window w_bus;
};

struct dmn {
	const struct cfg *cfg;        /* never written: the live parameters are the controller's */
	struct ctl ctl;
	struct cin cin;
	struct pub pub;
	struct notify notify;
	/* the ports: the buses that carry joints, in the configuration's order */
	struct dmn_bus buses[CFG_MAX_BUSES];
	size_t nbuses;
	bool cycle_open;              /* a cycle started at the tick has not been published yet */
	bool in_control;              /* the control step and the resumes are under way */
	bool wiring_refused;          /* the port refused the configured rs485 mode */
	enum bus_protocol protocol;   /* found (or configured) at the first connect; 0 until then */
	/* timing */
	int timer_fd, deadline_fd, signal_fd;
	uint64_t period_us;
	uint64_t epoch_us;            /* the controller's time 0 */
	uint64_t first_tick_us;       /* the timer's first expiry (jitter is against its grid) */
	uint64_t ticks;               /* timer expirations since start */
	uint64_t cycle;               /* cycles run */
	uint64_t cycle_start_us, last_cycle_start_us;
	double period_meas_us, jitter_us;
	long long overruns;
	/* why (the exit line, so that a user can tell the machine from the bus):
	 * periods skipped because the loop woke a whole period late or more;
	 * cycles still on the bus at the next tick, and of those the ones that
	 * had begun over half a period late (the loop woke late, not the bus) */
	long long overruns_skipped, overruns_cut, overruns_cut_late;
	uint64_t state_every;         /* STATE every this many cycles (pub_state_every) */
	enum cfg_mode state_mode;     /* the mode and fault of the last STATE published */
	bool state_latched, state_sent;
	struct stats_window w_period, w_jitter, w_bus;   /* w_bus: the cycle's, the slowest bus's */
	uint64_t second_start_us;
	struct rusage ru_last;
	bool params_dirty;
	/* systemd */
	uint64_t watchdog_interval_us, last_watchdog_us, watchdog_cycle;
	bool stop;
	const struct dmn_clock *clock;
	/* lockstep: the simulator's clock paces the loop (common/lockstep.h) */
	bool lockstep;
	struct lks_client lks;
	struct port_lockstep lks_port[CFG_MAX_BUSES];   /* bus i's, clock bus i */
	uint64_t next_tick_us;        /* lockstep: the next tick on the period's grid */
	bool clock_lost;              /* lockstep: the simulator went away mid-run */
	/* --tune: the tuner, fed every cycle (NULL in normal runs) */
	struct tune *tune;
	FILE *tune_out;
	struct log_limit lim_bus, lim_overrun, lim_events;
};

static uint64_t now_us(void) { return port_now_us(); }


/* ---- events ---------------------------------------------------------------------------------- */
static void dmn_event(struct dmn *d, int64_t seq, int level, const char *kind, const char *text)
{
	pub_event(&d->pub, seq, level, kind, text);
	enum log_level lv = level >= 2 ? LOG_LVL_ERROR : level == 1 ? LOG_LVL_WARN : LOG_LVL_INFO;
	log_msg(lv, "%s: %s", kind, text);
}

/* The controller's events: published and logged, within a rate limit (a
 * servo that misbehaves every cycle must not flood the journal or the
 * network); how many were left out is said with the next one. */
static void dmn_flush_ctl_events(struct dmn *d)
{
	struct ctl_event e;
	while (ctl_next_event(&d->ctl, &e)) {
		uint32_t dropped;
		if (!log_limit_allow(&d->lim_events, now_us(), &dropped))
			continue;
		if (dropped > 0) {
			char text[CTL_EVENT_TEXT + 48];
			snprintf(text, sizeof text, "%s (%u earlier event(s) not sent)", e.text, dropped);
			dmn_event(d, 0, e.level, e.kind, text);
		} else {
			dmn_event(d, 0, e.level, e.kind, e.text);
		}
	}
}

static void cin_event_hook(void *ctx, int64_t seq, int level, const char *kind, const char *text)
{
	pub_event(&((struct dmn *)ctx)->pub, seq, level, kind, text);
}
static int64_t cin_wall_hook(void *ctx) { (void)ctx; return clock_wall_us(); }
static uint64_t cin_mono_hook(void *ctx) { (void)ctx; return now_us(); }

static void dmn_bus_error_hook(void *ctx, uint8_t id, const char *what, int status)
{
	struct dmn *d = ctx;
	log_limited(&d->lim_bus, now_us(), LOG_LVL_WARN, "servo %u: %s%s%s", id, what, status != DXL_OK ? ": " : "",
	            status != DXL_OK ? dxl_strerror(status) : "");
}

static void dmn_notice_hook(void *ctx, const char *text)
{
	(void)ctx;
	log_warn("%s", text);
}

/* ---- the buses, as a whole ------------------------------------------------------------------------ */
/* Every bus connected: the robot runs whole (notify, --tune, the state's bus time). */
static bool dmn_connected(const struct dmn *d)
{
	for (size_t b = 0; b < d->nbuses; b++)
		if (!d->buses[b].connected)
			return false;
	return true;
}

static bool dmn_any_connected(const struct dmn *d)
{
	for (size_t b = 0; b < d->nbuses; b++)
		if (d->buses[b].connected)
			return true;
	return false;
}

/* The buses work in parallel: the cycle's bus time is the slowest one's,
 * and its control time the longest any bus's cycle measured. */
static void dmn_cycle_times(const struct dmn *d, double *bus_us, double *control_us)
{
	*bus_us = *control_us = 0.0;
	for (size_t b = 0; b < d->nbuses; b++) {
		const struct cyc *y = &d->buses[b].cyc;
		if (!d->buses[b].connected)
			continue;
		*bus_us = fmax(*bus_us, y->bus_us);
		*control_us = fmax(*control_us, y->control_us);
	}
}

static double dmn_cycle_bus_us(const struct dmn *d)
{
	double bus_us, control_us;
	dmn_cycle_times(d, &bus_us, &control_us);
	return bus_us;
}

/* ---- publishing --------------------------------------------------------------------------------- */
static long long dmn_bus_errors(const struct dmn *d)
{
	long long n = 0;
	for (size_t b = 0; b < d->nbuses; b++)
		n += d->buses[b].cyc.errors;
	return n;
}

/* Every state_every-th cycle, and at once when the mode or the fault changed
 * (a monitor sees a LIMP or a fault in the cycle it happened). */
static bool dmn_state_due(const struct dmn *d)
{
	return d->cycle % d->state_every == 0 || !d->state_sent || d->ctl.mode != d->state_mode ||
	       d->ctl.latched != d->state_latched;
}

static void dmn_publish_state(struct dmn *d)
{
	if (!dmn_state_due(d))
		return;
	d->state_sent = true;
	d->state_mode = d->ctl.mode;
	d->state_latched = d->ctl.latched;
	double bus_us, control_us;
	dmn_cycle_times(d, &bus_us, &control_us);
	struct pub_cycle f = {
		.cycle = (int64_t)d->cycle, .period_us = d->period_meas_us, .jitter_us = d->jitter_us,
		.bus_us = bus_us, .control_us = control_us,
		.overruns = d->overruns, .bus_errors = dmn_bus_errors(d), .bad_commands = cin_refused(&d->cin),
	};
	pub_state(&d->pub, &d->ctl, &f);
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

/* A robot on several buses: each bus's own figures on "<robot>.BUS.<bus>"
 * (its port, connection, reconnects, bus time, its servos), beside the
 * robot's message on "<robot>.BUS" (every servo, the slowest bus's time): the
 * message is the one monitors and logs know, on a channel of its own. */
static void dmn_publish_each_bus(struct dmn *d, const struct pub_bus *robot)
{
	for (size_t b = 0; b < d->nbuses; b++) {
		struct dmn_bus *db = &d->buses[b];
		struct stats_summary sb;
		stats_summarize(&db->w_bus, &sb);
		struct pub_bus f = *robot;
		f.port = db->port_path;
		f.connected = db->connected;
		f.reconnects = db->reconnects;
		f.adapter_latency_ms = db->adapter_latency_ms;
		f.return_delay_us = db->max_return_delay_us;
		f.bus_p99_us = sb.p99;
		const struct bus *bus_of[CFG_MAX_JOINTS];
		for (size_t j = 0; j < d->ctl.n; j++)
			bus_of[j] = ctl_on_bus(&d->ctl, j, db->index) ? &db->bus : NULL;
		struct pub_bus_lines lines = { .stray_packets = db->bus.stray_packets, .io_errors = db->bus.io_errors,
		                               .baud = (int32_t)db->cb->baud };
		char channel[PUB_CHANNEL_MAX + CFG_NAME_MAX];
		snprintf(channel, sizeof channel, "%s.%s", d->pub.ch_bus, db->cb->name);
		pub_bus_joints(&d->pub, &f, &lines, bus_of, &d->ctl, channel);
		stats_reset(&db->w_bus);
	}
}

static void dmn_publish_bus(struct dmn *d, double wall_s)
{
	struct stats_summary sp, sj, sb;
	stats_summarize(&d->w_period, &sp);
	stats_summarize(&d->w_jitter, &sj);
	stats_summarize(&d->w_bus, &sb);
	const struct dmn_bus *first = &d->buses[0];
	struct pub_bus f = {
		.port = first->port_path, .connected = dmn_connected(d), .reconnects = first->reconnects,
		.overruns = d->overruns, .adapter_latency_ms = first->adapter_latency_ms,
		.return_delay_us = first->max_return_delay_us, .period_p50_us = sp.p50, .period_p99_us = sp.p99,
		.period_max_us = sp.max, .jitter_p99_us = sj.p99, .bus_p99_us = sb.p99,
		.cpu_percent = dmn_cpu_percent(d, wall_s),
	};
	if (d->nbuses == 1) {
		pub_bus(&d->pub, &f, &first->bus, &d->ctl);
	} else {
		/* the robot's: every port named, every servo from its own bus */
		char ports[CFG_PATH_MAX];
		size_t used = 0;
		const struct bus *bus_of[CFG_MAX_JOINTS] = { NULL };
		struct pub_bus_lines lines = { .baud = (int32_t)d->cfg->baud };
		f.reconnects = 0;
		for (size_t b = 0; b < d->nbuses; b++) {
			const struct dmn_bus *db = &d->buses[b];
			int w = snprintf(ports + used, sizeof ports - used, "%s%s", b ? "," : "", db->port_path);
			used = w > 0 && used + (size_t)w < sizeof ports ? used + (size_t)w : used;
			f.reconnects += db->reconnects;
			if (db->max_return_delay_us > f.return_delay_us)
				f.return_delay_us = db->max_return_delay_us;
			if (db->adapter_latency_ms > f.adapter_latency_ms)
				f.adapter_latency_ms = db->adapter_latency_ms;
			lines.stray_packets += db->bus.stray_packets;
			lines.io_errors += db->bus.io_errors;
			for (size_t j = 0; j < d->ctl.n; j++)
				if (ctl_on_bus(&d->ctl, j, db->index))
					bus_of[j] = &db->bus;
		}
		f.port = ports;
		pub_bus_joints(&d->pub, &f, &lines, bus_of, &d->ctl, d->pub.ch_bus);
		dmn_publish_each_bus(d, &f);
	}
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
		.njoints = d->ctl.n, .bus_connected = dmn_connected(d), .overruns = d->overruns,
		.bus_errors = dmn_bus_errors(d), .faults = d->ctl.faults, .bad_commands = cin_refused(&d->cin),
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

/* ---- the port --------------------------------------------------------------------------------- */
static void dmn_close_port(struct dmn_bus *b)
{
	cyc_cut(&b->cyc);
	b->at_control = false;
	if (b->port != NULL) {
		bus_abort(&b->bus);
		port_close(b->port);
	}
	b->port = NULL;
	b->connected = false;
}

/* The bus timeouts: the adapter's latency (the FTDI latency timer, read and
 * lowered by port_open() on the fd it holds, or as configured), the servos'
 * return delay. `dxl doctor` derives them the same way (port.h). */
static void dmn_latency(struct dmn *d, struct dmn_bus *b)
{
	struct port_latency lat;
	long configured = d->cfg->adapter_latency_us;
	long us = port_adapter_latency_us(b->port, configured, &lat);
	b->adapter_latency_ms = configured >= 0 ? 1e-3 * (double)us : lat.known ? (double)lat.timer_ms : -1.0;
	if (lat.known && lat.timer_ms > 1)
		log_warn("%s: adapter latency timer %d ms (%s): replies wait that long, 100 Hz is out of "
		         "reach; set it to 1 ms (`dxl --port PATH setup`, or the udev rule in systemd/)", b->port_path,
		         lat.timer_ms, lat.note);
	if (configured > 1000)
		log_warn("adapter_latency_us = %ld: replies wait that long, 100 Hz needs <= 1000 µs "
		         "(`dxl --port PATH setup`)", configured);
	struct bus_timing tm = {
		.baud = b->cb->baud, .return_delay_us = (uint32_t)b->max_return_delay_us,
		.adapter_latency_us = (uint32_t)us, .margin_us = (uint32_t)d->cfg->bus_margin_us,
	};
	bus_set_timing(&b->bus, &tm);
}

/* usb_serial = ...: the adapter with that USB serial number, wherever it is
 * enumerated now (ttyUSB numbers change on replugging). */
static bool dmn_find_port(struct dmn_bus *b, char *err, size_t cap)
{
	if (b->cb->usb_serial[0] == '\0')
		return true;
	int n = 0;
	if (port_find_by_serial(b->cb->usb_serial, b->port_path, sizeof b->port_path, &n))
		return true;
	snprintf(err, cap, "no serial port with USB serial number '%s' (%d port(s) found; `dxl ports` lists them)",
	         b->cb->usb_serial, n);
	return false;
}

static double dmn_ctl_time(const struct dmn *d, uint64_t t_us)
{
	return 1e-6 * (double)(t_us - d->epoch_us);
}

_Static_assert(CFG_MAX_BUSES <= LKS_BUSES_MAX, "the clock carries every bus a robot may have");
_Static_assert((int)CFG_PROTO_1 == (int)BUS_PROTOCOL_1 && (int)CFG_PROTO_2 == (int)BUS_PROTOCOL_2,
               "a configured protocol is the bus's by its number");

/* The bus's protocol: configured, or found by PINGs at the first connect
 * (setup_protocol) and kept for every reconnect. */
static bool dmn_protocol(struct dmn *d, struct dmn_bus *b, char *err, size_t cap)
{
	/* The daemon's two branches on the protocol, both choosing the backend
	 * at start-up; everything after asks the servo's model. 1: a configured
	 * protocol is the bus's, by its number (config.h's CFG_PROTO_n are
	 * bus.h's BUS_PROTOCOL_n). */
	if (d->protocol == 0 && d->cfg->protocol != CFG_PROTO_AUTO)
		d->protocol = (enum bus_protocol)d->cfg->protocol;
	/* 2: protocol = auto, none found yet: PINGs find it (setup_protocol,
	 * its backends in a table, the AX-12's first) */
	if (d->protocol == 0 && !setup_protocol(&b->bus, d->cfg, b->port_path, &d->protocol, err, cap))
		return false;
	bus_set_protocol(&b->bus, d->protocol);
	return true;
}

/* Torque actuation's default parameters are an AX-12A joint's: on another
 * servo the joint's inertia differs, and the defaults scale with it (the
 * same gait: CONTROL.md). Once, at the first connect, when the models are
 * known; parameters given in the configuration are left as they are. */
static void dmn_torque_defaults(struct dmn *d)
{
	if (d->cfg->actuation != CFG_ACT_TORQUE)
		return;
	for (size_t j = 0; j < d->ctl.n; j++) {
		double scale = sm_torque_scale(ctl_model(&d->ctl, j));
		if (d->cfg->joint[j].torque_defaults != 0 && scale != 1.0) {
			log_info("joint %zu: torque actuation's default k, c, mu, inertia, friction scaled x%.3f for the %s's "
			         "joint (its rotor through the gearbox)", j + 1, scale, ctl_model(&d->ctl, j)->name);
			ctl_torque_defaults(&d->ctl, j, scale);
		}
	}
}

/* Position actuation's defaults are the AX-12A's (osc.h): on a servo whose
 * position loop lags more they run down, and the model's own stand in for
 * the k and μ the configuration did not give, and for servo_lead_s when
 * every joint is of that model (the lead is the robot's). Once, at the first
 * connect, as the torque defaults above. */
static void dmn_position_defaults(struct dmn *d)
{
	const struct cfg *cfg = d->cfg;
	if (cfg->actuation != CFG_ACT_POSITION)
		return;
	const struct sm_model *first = ctl_model(&d->ctl, 0);
	bool same = true, kept = false;
	double k, mu, lead = 0.0;
	for (size_t j = 0; j < d->ctl.n; j++) {
		const struct sm_model *m = ctl_model(&d->ctl, j);
		same = same && m == first;
		if (!sm_position_defaults(m, j, d->ctl.n, &k, &mu, &lead)) {
			kept = kept || m != sm_ax12();   /* the AX-12A's own are osc.h's */
			continue;
		}
		double k0 = cfg->joint[j].osc.k, mu0 = cfg->joint[j].osc.mu;
		if (ctl_position_defaults(&d->ctl, j, k, mu))
			log_info("joint %zu: position actuation's default k %.4g, mu %.4g are the %s's (the AX-12A's: "
			         "k %.4g, mu %.4g; daemon/CONTROL.md, \"X-series servos\")%s", j + 1, d->ctl.p.osc[j].k,
			         d->ctl.p.osc[j].mu, m->position_from, k0, mu0,
			         strcmp(m->position_from, m->name) != 0 ? ": nobody tuned them on this model yet, "
			         "undulated --tune finds its own" : "");
	}
	char why[160];
	if (same && lead > 0.0 && cfg->servo_lead_default) {
		if (ctl_set_param(&d->ctl, "servo_lead_s", -1, lead, why, sizeof why))
			log_info("servo_lead_s %.3f s, the %s's default (the AX-12A's: %.3f s)", lead, first->position_from,
			         cfg->servo_lead_s);
		else
			log_warn("the %s's default %s: kept the AX-12A's", first->position_from, why);
	} else if (!same && cfg->servo_lead_default) {   /* models mixed: whose lead? */
		kept = true;
	}
	if (kept)
		log_info("some defaults stay the AX-12A's (servos of more than one model, or one without its own): "
		         "undulated --tune finds this robot's (daemon/CONTROL.md, \"X-series servos\")");
}

/* --tune: the tuner began from the configuration as loaded; the model's
 * defaults (above) may have changed k, mu and the lead since. It starts
 * again from what the robot will run, so that the factors it finds and the
 * file it writes are on those (on the simulated XL430 it wrote the AX-12A's
 * k and lead beside a gait measured on the XL430's). When the target is out
 * of reach there the run stops before it starts, saying why. */
static void dmn_tune_rebase(struct dmn *d)
{
	if (d->tune == NULL)
		return;
	struct tune_opts o = d->tune->opts;
	char why[sizeof d->tune->why];
	if (!tune_init(d->tune, &o, d->cfg, &d->ctl.p, why, sizeof why)) {
		snprintf(d->tune->why, sizeof d->tune->why, "%s", why);
		d->tune->state = TUNE_FAILED;
		d->stop = true;
	}
}

/* "/dev/ttyUSB0 at 1000000 bps", or with several buses "bus robot
 * /dev/ttyUSB0 at 1000000 bps (joints 1,2), bus tail ..." */
static void dmn_ports_text(const struct dmn *d, char *out, size_t cap)
{
	size_t used = 0;
	out[0] = '\0';
	for (size_t b = 0; b < d->nbuses && used + 1 < cap; b++) {
		const struct dmn_bus *db = &d->buses[b];
		int w;
		if (d->nbuses == 1) {
			w = snprintf(out + used, cap - used, "%s at %ld bps", db->port_path, db->cb->baud);
		} else {
			w = snprintf(out + used, cap - used, "%sbus %s %s at %ld bps (joint%s", b ? ", " : "", db->cb->name,
			             db->port_path, db->cb->baud, db->cb->njoints > 1 ? "s " : " ");
			for (size_t i = 0; w > 0 && i < db->cb->njoints && used + (size_t)w + 1 < cap; i++) {
				int k = snprintf(out + used + (size_t)w, cap - used - (size_t)w, "%s%zu", i ? "," : "",
				                 db->cb->joints[i] + 1);
				w += k > 0 ? k : 0;
			}
			if (w > 0 && used + (size_t)w + 1 < cap)
				w += snprintf(out + used + (size_t)w, cap - used - (size_t)w, ")");
		}
		used += w > 0 && used + (size_t)w < cap ? (size_t)w : cap - used - 1;
	}
}

/* "AX-12A" or "XL430-W250, XM430-W350": the models found. */
static void dmn_models(const struct dmn *d, char *out, size_t cap)
{
	size_t used = 0;
	out[0] = '\0';
	for (size_t j = 0; j < d->ctl.n && used + 1 < cap; j++) {
		const char *name = ctl_model(&d->ctl, j)->name;
		if (j > 0 && strcmp(name, ctl_model(&d->ctl, j - 1)->name) == 0)
			continue;
		int w = snprintf(out + used, cap - used, "%s%s", used ? ", " : "", name);
		used += w > 0 ? (size_t)w : 0;
	}
}

/* The cycle's read on a bus that can read every servo with one request:
 * a Fast Sync Read when every servo answers it (model and firmware, read
 * at start-up), the plain SYNC_READ otherwise; said either way. */
static void dmn_fast_read(struct dmn *d, struct dmn_bus *b)
{
	char why[CFG_MAX_JOINTS * 48 + 160];
	if (!dxl_proto_can(bus_proto(&b->bus), DXL_CAP_SYNC_READ))
		return;
	bool fast = setup_fast_read_on(&b->bus, &d->ctl, b->index, why, sizeof why);
	cyc_set_fast_read(&b->cyc, fast);
	if (fast)
		log_info("bus: the cycle reads by Fast Sync Read, one status packet for all servos (%s)", why);
	else
		log_info("bus: the cycle reads by SYNC_READ, a status packet per servo: no Fast Sync Read, as %s", why);
}

/* The cycle's read on bus b through the indirect block where every servo
 * on it has one and reads its map back (indirect = on, the default); else,
 * said why, the present registers where they lie. Either way the log says
 * which. */
static void dmn_indirect(struct dmn *d, struct dmn_bus *b)
{
	char why[256];
	size_t j0 = 0;
	while (j0 + 1 < d->ctl.n && !ctl_on_bus(&d->ctl, j0, b->index))
		j0++;
	const struct sm_model *m = ctl_model(&d->ctl, j0);
	struct sm_read direct = sm_direct_read(m);
	bool on = false;
	if (!d->cfg->indirect)
		snprintf(why, sizeof why, "indirect = off");
	else if (m->indirect.len == 0)
		snprintf(why, sizeof why, "the %s has no indirect area", m->name);
	else
		on = setup_indirect_on(&b->bus, &d->ctl, b->index, why, sizeof why);
	cyc_set_indirect(&b->cyc, on);
	if (on)
		log_info("bus: the cycle reads the indirect block at %u, %u or %u bytes a servo where the present "
		         "registers at %u take %u or %u (%s)", m->indirect.addr, m->indirect.len, m->indirect.len_slow,
		         direct.addr, direct.len, direct.len_slow, why);
	else if (dxl_proto_can(bus_proto(&b->bus), DXL_CAP_SYNC_READ))
		log_info("bus: the cycle reads the present registers at %u, %u or %u bytes a servo: no indirect block, "
		         "as %s", direct.addr, direct.len, direct.len_slow, why);
}

/* Open one bus's port and run its start-up checks; the controller starts
 * (ctl_start) once every bus is in (dmn_connect, dmn_try_reconnect). On
 * failure *err says why. */
static bool dmn_connect_bus(struct dmn *d, struct dmn_bus *b, char *err, size_t cap)
{
	if (!dmn_find_port(b, err, cap))
		return false;
	/* the port is this robot's alone (protocol/io/port_lock.c): what the
	 * lock names, so that a program refused beside us can say who holds it */
	char owner[CFG_NAME_MAX + 8];
	struct holder held;
	snprintf(owner, sizeof owner, "robot %s", d->cfg->name);
	struct port_options opt = { .baud = b->cb->baud, .force_termios = false, .low_latency = true,
	                            .owner = owner, .holder = &held };
	b->port = port_open(b->port_path, &opt, err, cap);
	if (b->port == NULL) {
		size_t len = strlen(err);
		if ((held.pid > 0 || held.program[0] != '\0') && len < cap)
			snprintf(err + len, cap - len, ": one program drives a bus at a time; stop that one first, or give "
			         "this robot a port of its own");
		return false;
	}
	/* A UART behind a half-duplex buffer: the kernel switches the direction
	 * around every packet. A device that cannot (a USB adapter, a pty) must
	 * not run with the wiring silently wrong: one error, and no start. */
	if (port_set_rs485(b->port, d->cfg->rs485, err, cap) != DXL_OK) {
		d->wiring_refused = true;
		dmn_close_port(b);
		return false;
	}
	struct bus_io io;
	if (d->lockstep) {
		size_t i = (size_t)(b - d->buses);
		port_bus_io_lockstep(&d->lks_port[i], b->port, &d->lks, i, &io);
	} else {
		port_bus_io(b->port, &io);
	}
	struct bus_timing tm = {
		.baud = b->cb->baud, .return_delay_us = DMN_DEFAULT_RETURN_DELAY_US,
		.adapter_latency_us = d->cfg->adapter_latency_us > 0 ? (uint32_t)d->cfg->adapter_latency_us : 0,
		.margin_us = (uint32_t)d->cfg->bus_margin_us,
	};
	bus_init(&b->bus, &io, &tm, d->cfg->echo);
	bool ok = dmn_protocol(d, b, err, cap) &&
	          setup_servos(&b->bus, &d->ctl, d->cfg, b->index, b->port_path, &b->max_return_delay_us, err, cap);
	if (ok) {
		dmn_latency(d, b);
		ok = setup_read_present(&b->bus, &d->ctl, b->index, 1e-6 * (double)d->period_us, err, cap);
	}
	if (!ok) {
		dmn_close_port(b);
		return false;
	}
	b->connected = true;
	b->backoff_ms = DMN_BACKOFF_MIN_MS;
	dmn_indirect(d, b);
	dmn_fast_read(d, b);
	return true;
}

/* A message about one bus names it when the robot has several. */
static void dmn_bus_prefix(const struct dmn *d, const struct dmn_bus *b, char *out, size_t cap)
{
	if (d->nbuses > 1)
		snprintf(out, cap, "bus %s, %s", b->cb->name, b->port_path);
	else
		snprintf(out, cap, "%s", b->port_path);
}

/* Every bus, then the controller: at start-up. */
static bool dmn_connect(struct dmn *d, const char *reason, char *err, size_t cap)
{
	for (size_t i = 0; i < d->nbuses; i++) {
		struct dmn_bus *b = &d->buses[i];
		if (dmn_connect_bus(d, b, err, cap))
			continue;
		if (d->nbuses > 1) {
			/* "bus tail, /dev/ttyUSB1: " before the reason, when it fits */
			char what[CFG_PATH_MAX + 64];
			dmn_bus_prefix(d, b, what, sizeof what);
			size_t pl = strlen(what) + 2, el = strlen(err);
			if (pl + el < cap) {
				memmove(err + pl, err, el + 1);
				memcpy(err, what, pl - 2);
				memcpy(err + pl - 2, ": ", 2);
			}
		}
		for (size_t k = 0; k < i; k++)
			dmn_close_port(&d->buses[k]);
		return false;
	}
	ctl_start(&d->ctl, dmn_ctl_time(d, now_us()), reason);
	return true;
}

static void dmn_bus_lost(struct dmn *d, struct dmn_bus *b, int why)
{
	char text[CFG_PATH_MAX + 256], what[CFG_PATH_MAX + 64];
	dmn_bus_prefix(d, b, what, sizeof what);
	if (d->nbuses > 1)
		snprintf(text, sizeof text, "%s: %s: bus lost, its joints hold and so do the other buses' (the robot's "
		         "joints move together or not at all); reconnecting every %.1f..%.1f s", what, dxl_strerror(why),
		         1e-3 * DMN_BACKOFF_MIN_MS, 1e-3 * DMN_BACKOFF_MAX_MS);
	else
		snprintf(text, sizeof text, "%s: %s: bus lost, joints hold; reconnecting every %.1f..%.1f s", what,
		         dxl_strerror(why), 1e-3 * DMN_BACKOFF_MIN_MS, 1e-3 * DMN_BACKOFF_MAX_MS);
	dmn_close_port(b);
	if (d->nbuses > 1)
		ctl_bus_lost_on(&d->ctl, b->index);
	else
		ctl_bus_lost(&d->ctl);
	b->backoff_ms = DMN_BACKOFF_MIN_MS;
	b->reconnect_at_us = now_us() + 1000ULL * b->backoff_ms;
	dmn_event(d, 0, 2, "bus-lost", text);
	dmn_notify_status(d);
}

static void dmn_try_reconnect(struct dmn *d, struct dmn_bus *b, uint64_t now)
{
	if (b->connected || now < b->reconnect_at_us)
		return;
	char err[512], what[CFG_PATH_MAX + 64];
	dmn_bus_prefix(d, b, what, sizeof what);
	if (dmn_connect_bus(d, b, err, sizeof err)) {
		b->reconnects++;
		char text[CFG_PATH_MAX + 512];
		bool whole = dmn_connected(d);
		snprintf(text, sizeof text, "%s: bus back (reconnect %lld), start-up checks passed%s", what, b->reconnects,
		         whole ? "" : "; the robot holds until its other buses are back");
		/* the robot moves again when every bus is back: ramped in from
		 * where the joints are */
		if (whole)
			ctl_start(&d->ctl, dmn_ctl_time(d, now_us()), "reconnected");
		else
			ctl_bus_back_on(&d->ctl, b->index);   /* a LIMP meanwhile reaches it now */
		dmn_event(d, 0, 0, "bus-back", text);
		dmn_notify_status(d);
		return;
	}
	log_limited(&d->lim_bus, now, LOG_LVL_WARN, "%s%sreconnect failed: %s (next try in %.1f s)",
	            d->nbuses > 1 ? what : "", d->nbuses > 1 ? ": " : "", err, 1e-3 * b->backoff_ms);
	b->reconnect_at_us = now + 1000ULL * b->backoff_ms;
	b->backoff_ms = b->backoff_ms * 2 > DMN_BACKOFF_MAX_MS ? DMN_BACKOFF_MAX_MS : b->backoff_ms * 2;
}

/* ---- the cycle ---------------------------------------------------------------------------------- */
static void dmn_arm_deadline(struct dmn *d) { d->clock->arm_deadline(d); }

/* The cycle boundary: the commands that came in since the last cycle are
 * applied now, before the control step, never while a cycle's writes are on
 * the bus. */
static void dmn_control(struct dmn *d)
{
	if (cin_pending(&d->cin) > 0) {
		cin_apply(&d->cin, &d->ctl);
		d->params_dirty = true;
	}
	if (d->tune && d->tune->changed) {
		if (!tune_apply(d->tune, &d->ctl))
			d->stop = true;   /* refused: the tuner failed, and says why */
		d->params_dirty = true;
	}
	double dt = 1e-6 * (double)(d->cycle_start_us - d->last_cycle_start_us);
	ctl_step(&d->ctl, dmn_ctl_time(d, d->cycle_start_us), dt, 1e-6 * (double)clock_wall_us());
}

/* --tune: this cycle's measurement to the tuner. It stops the run when it
 * is done or gives up, and when the robot left OSCILLATOR (a fault latched,
 * a LIMP command): it only knows how to tune a running oscillator. */
static void dmn_tune_cycle(struct dmn *d)
{
	struct tune *t = d->tune;
	if (d->ctl.mode != CFG_MODE_OSCILLATOR || d->ctl.latched) {
		snprintf(t->why, sizeof t->why, "the robot left OSCILLATOR (%s%s%s): stopped", cfg_mode_name(d->ctl.mode),
		         d->ctl.latched ? ", fault: " : "", d->ctl.latched ? d->ctl.latch : "");
		t->state = TUNE_FAILED;
		d->stop = true;
		return;
	}
	double x[CFG_MAX_JOINTS], v[CFG_MAX_JOINTS];
	for (size_t j = 0; j < d->ctl.n; j++) {
		const struct ctl_joint *jt = &d->ctl.j[j];
		bool ok = jt->have_reading && jt->stale_cycles == 0;   /* read this cycle */
		x[j] = ok ? jt->angle - d->cfg->joint[j].neutral : NAN;
		v[j] = ok ? jt->speed : NAN;
	}
	double volts = NAN;
	for (size_t j = 0; j < d->ctl.n; j++)
		if (d->ctl.j[j].voltage > 0 && !(d->ctl.j[j].voltage >= volts))
			volts = d->ctl.j[j].voltage;   /* the lowest: the weakest servo sets the pace */
	tune_supply(t, volts);
	t->ran = d->ctl.p;   /* the file it writes holds what the robot ran with, commands' changes too */
	tune_sample(t, d->ctl.t, x, v, d->ctl.starter_active);
	if (t->progress[0]) {
		fprintf(d->tune_out, "tune: %5.1f s  %s\n", d->ctl.t, t->progress);
		fflush(d->tune_out);
	}
	if (t->state == TUNE_DONE || t->state == TUNE_FAILED)
		d->stop = true;
}

static void dmn_cycle_done(struct dmn *d)
{
	d->cycle_open = false;
	if (dmn_any_connected(d))
		stats_add(&d->w_bus, dmn_cycle_bus_us(d));
	for (size_t b = 0; b < d->nbuses; b++)
		if (d->buses[b].connected)
			stats_add(&d->buses[b].w_bus, d->buses[b].cyc.bus_us);
	dmn_flush_ctl_events(d);
	dmn_publish_state(d);
	if (d->tune && dmn_connected(d))
		dmn_tune_cycle(d);
	d->cycle++;
}

/* What a lost bus's joints would have written is forgotten, every cycle (the
 * start-up sequence writes what matters): it would wait at the head of the
 * robot's write queue for a bus that is not there. */
static void dmn_forget_lost(struct dmn *d)
{
	if (d->nbuses == 1) {
		if (!d->buses[0].connected)
			ctl_bus_lost(&d->ctl);
		return;
	}
	for (size_t b = 0; b < d->nbuses; b++)
		if (!d->buses[b].connected)
			ctl_bus_lost_on(&d->ctl, d->buses[b].index);
}

/* The cycle is over when every bus's part of it is. */
static void dmn_maybe_done(struct dmn *d)
{
	if (!d->cycle_open || d->in_control)
		return;
	for (size_t b = 0; b < d->nbuses; b++)
		if (d->buses[b].connected && cyc_busy(&d->buses[b].cyc))
			return;
	dmn_cycle_done(d);
}

static void dmn_drive(struct dmn *d, struct dmn_bus *b, enum cyc_status st);

/* The control step runs once a cycle, when every connected bus's reads are
 * in (or timed out: a cycle reaches CYC_CONTROL either way); then each bus
 * sends its share of the outputs. */
static void dmn_maybe_control(struct dmn *d)
{
	if (d->in_control)
		return;
	bool waiting = false;
	for (size_t i = 0; i < d->nbuses; i++) {
		const struct dmn_bus *b = &d->buses[i];
		if (b->connected && cyc_busy(&b->cyc) && !b->at_control)
			return;   /* still reading */
		waiting = waiting || b->at_control;
	}
	if (!waiting)
		return;
	d->in_control = true;
	dmn_control(d);
	dmn_forget_lost(d);
	for (size_t i = 0; i < d->nbuses; i++) {
		struct dmn_bus *b = &d->buses[i];
		if (!b->at_control)
			continue;
		b->at_control = false;
		dmn_drive(d, b, cyc_resume(&b->cyc));
	}
	d->in_control = false;
	dmn_maybe_done(d);
}

/* Follow a bus's cycle until it waits for the bus, for the control step, or
 * ends. */
static void dmn_drive(struct dmn *d, struct dmn_bus *b, enum cyc_status st)
{
	switch (st) {
	case CYC_PENDING:
		dmn_arm_deadline(d);
		return;
	case CYC_CONTROL:
		b->at_control = true;
		dmn_maybe_control(d);
		return;
	case CYC_DONE:
		dmn_arm_deadline(d);
		dmn_maybe_done(d);
		return;
	case CYC_LOST:
		dmn_bus_lost(d, b, b->cyc.lost);
		dmn_arm_deadline(d);
		dmn_maybe_control(d);   /* the others may be waiting for it */
		dmn_maybe_done(d);
		return;
	}
}

static void dmn_bus_event(struct dmn *d, struct dmn_bus *b)
{
	if (!b->connected || !cyc_busy(&b->cyc) || b->at_control)
		return;
	dmn_drive(d, b, cyc_step(&b->cyc));
}

/* The previous cycle's bus work is still going at the tick: it ends here (a
 * write cut off is sent again next cycle). */
static void dmn_cut_cycle(struct dmn *d, uint64_t now)
{
	bool busy = false;
	for (size_t b = 0; b < d->nbuses; b++) {
		struct dmn_bus *db = &d->buses[b];
		if (!cyc_busy(&db->cyc))
			continue;
		busy = true;
		cyc_cut(&db->cyc);
		db->at_control = false;
	}
	if (!busy)
		return;
	d->overruns++;
	d->overruns_cut++;
	if (d->jitter_us > 0.5 * (double)d->period_us)
		d->overruns_cut_late++;
	log_limited(&d->lim_overrun, now, LOG_LVL_WARN, "cycle %" PRIu64 " still on the bus at the next tick", d->cycle);
	dmn_arm_deadline(d);
	dmn_cycle_done(d);
}

/* A tick at now; exp periods have passed since the last (more than one:
 * whole periods were missed). */
static void dmn_tick_at(struct dmn *d, uint64_t exp, uint64_t now)
{
	d->ticks += exp;
	if (exp > 1) {
		/* whole periods were missed: skip them, keep the phase */
		d->overruns += (long long)(exp - 1);
		d->overruns_skipped += (long long)(exp - 1);
		log_limited(&d->lim_overrun, now, LOG_LVL_WARN, "overrun: %" PRIu64 " period(s) skipped", exp - 1);
	}
	uint64_t scheduled = d->first_tick_us + (d->ticks - 1) * d->period_us;
	dmn_cut_cycle(d, now);
	d->last_cycle_start_us = d->cycle_start_us ? d->cycle_start_us : now - d->period_us;
	d->cycle_start_us = now;
	d->jitter_us = (double)(now - scheduled);
	d->period_meas_us = (double)(now - d->last_cycle_start_us);
	stats_add(&d->w_period, d->period_meas_us);
	stats_add(&d->w_jitter, d->jitter_us);

	for (size_t b = 0; b < d->nbuses; b++)
		dmn_try_reconnect(d, &d->buses[b], now);
	if (now - d->second_start_us >= 1000000) {
		dmn_publish_bus(d, 1e-6 * (double)(now - d->second_start_us));
		pub_params(&d->pub);
		d->params_dirty = false;
		dmn_notify_status(d);
		d->second_start_us = now;
	} else if (d->params_dirty) {
		pub_params(&d->pub);
		d->params_dirty = false;
	}
	dmn_watchdog(d, now);

	if (!dmn_any_connected(d)) {
		/* no bus: the controller still runs (joints stale: they go silent,
		 * and the state keeps flowing at the period), and what it would
		 * write is forgotten: the start-up sequence writes what matters */
		dmn_control(d);
		dmn_forget_lost(d);
		dmn_cycle_done(d);
		return;
	}
	/* every bus's cycle begun before any is followed: the control step
	 * waits for the reads of every bus that is under way */
	enum cyc_status st[CFG_MAX_BUSES];
	d->cycle_open = true;
	for (size_t b = 0; b < d->nbuses; b++)
		if (d->buses[b].connected)
			st[b] = cyc_start(&d->buses[b].cyc);
	for (size_t b = 0; b < d->nbuses; b++)
		if (d->buses[b].connected)
			dmn_drive(d, &d->buses[b], st[b]);
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

static void dmn_close_fds(struct dmn *d)
{
	int *fds[] = { &d->signal_fd, &d->timer_fd, &d->deadline_fd };
	for (size_t i = 0; i < sizeof fds / sizeof fds[0]; i++) {
		if (*fds[i] >= 0)
			close(*fds[i]);
		*fds[i] = -1;
	}
}

static void dmn_start_timer(struct dmn *d)
{
	d->first_tick_us = now_us() + d->period_us;
	d->next_tick_us = d->first_tick_us;
	d->second_start_us = now_us();
	d->clock->start(d);
}

static bool dmn_signal(struct dmn *d)
{
	struct signalfd_siginfo si;
	if (read(d->signal_fd, &si, sizeof si) != (ssize_t)sizeof si)
		return false;
	log_info("signal %u: stopping", si.ssi_signo);
	d->stop = true;
	return true;
}

/* What the loop waits on besides its clock: signals and the two command
 * doors, in pfd[0..2]; the clock's descriptors follow. */
enum { DMN_P_SIGNAL, DMN_P_LOCAL, DMN_P_NET, DMN_P_COMMON };

/* poll() the common descriptors and the clock's (after them); false when
 * the loop must end (a poll error, or a signal that stops the daemon). *again
 * is set when poll was interrupted and nothing happened. */
static bool dmn_poll(struct dmn *d, struct pollfd *pfd, nfds_t n, bool *again)
{
	pfd[DMN_P_SIGNAL] = (struct pollfd){ .fd = d->signal_fd, .events = POLLIN };
	pfd[DMN_P_LOCAL] = (struct pollfd){ .fd = cin_local_fd(&d->cin), .events = POLLIN };
	pfd[DMN_P_NET] = (struct pollfd){ .fd = cin_net_fd(&d->cin), .events = POLLIN };
	*again = false;
	if (poll(pfd, n, -1) < 0) {
		if (errno == EINTR) {
			*again = true;
			return true;
		}
		log_error("poll: %s", strerror(errno));
		return false;
	}
	return !((pfd[DMN_P_SIGNAL].revents & POLLIN) && dmn_signal(d));
}

/* Commands that arrived: queued, applied at the next cycle boundary. */
static void dmn_take_commands(struct dmn *d, const struct pollfd *pfd)
{
	if (pfd[DMN_P_LOCAL].revents & POLLIN)
		cin_on_local(&d->cin);
	if (pfd[DMN_P_NET].revents & POLLIN)
		cin_on_network(&d->cin);
}

/* What a wake-up brought, the bus first: a cycle whose last reply came with
 * the tick ends whole instead of being cut by it. */
static void dmn_woke(struct dmn *d, const struct dmn_wake *w)
{
	for (size_t i = 0; i < d->nbuses; i++) {
		struct dmn_bus *b = &d->buses[i];
		if (w->bus_hup[i]) {
			if (b->connected && bus_is_pending(&b->bus))
				dmn_bus_event(d, b);   /* reads the remaining bytes, then reports the loss */
			if (b->connected) {
				dmn_bus_lost(d, b, DXL_E_DISCONNECTED);
				dmn_maybe_control(d);   /* the others may be waiting for it */
				dmn_maybe_done(d);
			}
		} else if (w->bus_in[i]) {
			dmn_bus_event(d, b);
		}
	}
	/* one deadline timer for every bus: each looks whether its own passed */
	if (w->bus_deadline)
		for (size_t i = 0; i < d->nbuses; i++)
			dmn_bus_event(d, &d->buses[i]);
	if (w->ticks > 0)
		dmn_tick_at(d, w->ticks, w->now);
}

/* The loop, whatever the clock: wait for it, signals and commands; act on
 * what came. A signal ends it here (the safe stop follows in dmn_run_with),
 * so does the clock when it ends the run or goes away. */
static void dmn_loop(struct dmn *d)
{
	while (!d->stop) {
		struct pollfd pfd[DMN_P_COMMON + DMN_CLOCK_FDS];
		bool again;
		d->clock->before_wait(d);
		if (d->stop)
			return;
		nfds_t n = DMN_P_COMMON + d->clock->fds(d, pfd + DMN_P_COMMON);
		if (!dmn_poll(d, pfd, n, &again))
			return;
		if (again)
			continue;
		dmn_take_commands(d, pfd);
		struct dmn_wake w = { 0 };
		d->clock->woke(d, pfd + DMN_P_COMMON, &w);
		dmn_woke(d, &w);
	}
}

/* ---- the system's clock: a periodic timerfd, a deadline timerfd, the bus fd ------------------- */
enum { DMN_RT_TIMER, DMN_RT_DEADLINE, DMN_RT_BUS };   /* DMN_RT_BUS + i: bus i */

static struct timespec dmn_timespec(uint64_t us)
{
	return (struct timespec){ .tv_sec = (time_t)(us / 1000000), .tv_nsec = (long)(us % 1000000) * 1000 };
}

static void dmn_rt_start(struct dmn *d)
{
	struct itimerspec its = { .it_interval = dmn_timespec(d->period_us), .it_value = dmn_timespec(d->first_tick_us) };
	timerfd_settime(d->timer_fd, TFD_TIMER_ABSTIME, &its, NULL);
}

/* The earliest deadline of the buses' pending transactions (0: none). */
static uint64_t dmn_deadline_us(const struct dmn *d)
{
	uint64_t dl = 0;
	for (size_t b = 0; b < d->nbuses; b++) {
		uint64_t t = d->buses[b].connected ? cyc_deadline_us(&d->buses[b].cyc) : 0;
		if (t != 0 && (dl == 0 || t < dl))
			dl = t;
	}
	return dl;
}

static void dmn_rt_arm_deadline(struct dmn *d)
{
	struct itimerspec its = { 0 };
	uint64_t dl = dmn_deadline_us(d);
	if (dl != 0) {
		its.it_value = dmn_timespec(dl);
		if (its.it_value.tv_sec == 0 && its.it_value.tv_nsec == 0)
			its.it_value.tv_nsec = 1;   /* all zero would disarm it */
	}
	timerfd_settime(d->deadline_fd, TFD_TIMER_ABSTIME, &its, NULL);
}

static void dmn_rt_before_wait(struct dmn *d) { (void)d; }

static nfds_t dmn_rt_fds(struct dmn *d, struct pollfd *pfd)
{
	pfd[DMN_RT_TIMER] = (struct pollfd){ .fd = d->timer_fd, .events = POLLIN };
	pfd[DMN_RT_DEADLINE] = (struct pollfd){ .fd = d->deadline_fd, .events = POLLIN };
	/* bus fds: readable only matters while a reply is awaited; HUP/ERR always */
	for (size_t i = 0; i < d->nbuses; i++) {
		const struct dmn_bus *b = &d->buses[i];
		pfd[DMN_RT_BUS + i] = (struct pollfd){ .fd = b->connected ? port_fd(b->port) : -1,
		                                       .events = (short)(b->connected && bus_is_pending(&b->bus) ? POLLIN : 0) };
	}
	return DMN_RT_BUS + d->nbuses;
}

static void dmn_rt_woke(struct dmn *d, const struct pollfd *pfd, struct dmn_wake *w)
{
	for (size_t i = 0; i < d->nbuses; i++) {
		w->bus_hup[i] = (pfd[DMN_RT_BUS + i].revents & (POLLHUP | POLLERR | POLLNVAL)) != 0;
		w->bus_in[i] = (pfd[DMN_RT_BUS + i].revents & POLLIN) != 0;
	}
	if (pfd[DMN_RT_DEADLINE].revents & POLLIN) {
		uint64_t x;
		if (read(d->deadline_fd, &x, sizeof x) < 0 && errno != EAGAIN)
			log_debug("deadline timer: %s", strerror(errno));
		w->bus_deadline = true;
	}
	uint64_t exp = 0;
	if ((pfd[DMN_RT_TIMER].revents & POLLIN) && read(d->timer_fd, &exp, sizeof exp) == (ssize_t)sizeof exp &&
	    exp > 0) {
		w->ticks = exp;   /* more than one: whole periods were missed */
		w->now = now_us();
	}
}

static const struct dmn_clock dmn_clock_real = {
	.start = dmn_rt_start, .arm_deadline = dmn_rt_arm_deadline, .before_wait = dmn_rt_before_wait,
	.fds = dmn_rt_fds, .woke = dmn_rt_woke,
};

/* ---- lockstep: the simulator's clock over its socket ------------------------------------------ */
static void dmn_clock_lost(struct dmn *d, const char *why)
{
	log_error("%s: stopping, without a safe stop (the simulated servos went with the simulator)", why);
	d->clock_lost = true;
	d->stop = true;
}

/* Commands the clock delivered: applied at the next cycle boundary, as the
 * local socket's are. */
static void dmn_clock_commands(struct dmn *d)
{
	char text[LKS_TEXT_MAX];
	while (lks_client_next_cmd(&d->lks, text, sizeof text))
		cin_clock_command(&d->cin, text);
}

/* The ticks are virtual: d->next_tick_us, told to the simulator in the WAIT. */
static void dmn_lks_start(struct dmn *d) { (void)d; }
/* The deadline goes out with the next WAIT. */
static void dmn_lks_arm_deadline(struct dmn *d) { (void)d; }

/* Tell the simulator until when there is nothing to do (the next tick, the
 * earliest bus deadline) and which buses await a reply (bit i: bus i, the
 * clock's bus i): time moves only while every daemon has said so. */
static void dmn_lks_before_wait(struct dmn *d)
{
	unsigned want = 0;
	for (size_t i = 0; i < d->nbuses; i++)
		if (d->buses[i].connected && bus_is_pending(&d->buses[i].bus))
			want |= 1u << i;
	uint64_t wake = d->next_tick_us;
	uint64_t dl = dmn_deadline_us(d);
	if (dl != 0 && dl < wake)
		wake = dl;
	if (lks_client_wait(&d->lks, wake, want) != 0)
		dmn_clock_lost(d, "lockstep: the simulator is gone");
}

static nfds_t dmn_lks_fds(struct dmn *d, struct pollfd *pfd)
{
	pfd[0] = (struct pollfd){ .fd = d->lks.fd, .events = POLLIN };
	return 1;
}

/* The simulator's message: commands, the end of the run, or TIME. When
 * virtual time moved, the bus may have its reply or deadline, and the tick
 * may have come. */
static void dmn_lks_woke(struct dmn *d, const struct pollfd *pfd, struct dmn_wake *w)
{
	char why[256];
	if (!(pfd[0].revents & (POLLIN | POLLHUP | POLLERR)))
		return;
	int r = lks_client_read(&d->lks, why, sizeof why);
	if (r <= 0) {
		dmn_clock_lost(d, r == 0 ? "lockstep: the simulator closed the clock" : why);
		return;
	}
	dmn_clock_commands(d);
	if (d->lks.stop) {
		log_info("lockstep: the simulator ended the run (%s): stopping", d->lks.stop_why);
		d->stop = true;
		return;
	}
	if (!lks_client_take_time(&d->lks))
		return;
	uint64_t now = now_us();
	for (size_t i = 0; i < d->nbuses; i++)
		w->bus_in[i] = d->buses[i].connected && bus_is_pending(&d->buses[i].bus);
	if (now >= d->next_tick_us) {
		w->ticks = 1 + (now - d->next_tick_us) / d->period_us;
		w->now = now;
		d->next_tick_us += w->ticks * d->period_us;
	}
}

static const struct dmn_clock dmn_clock_lockstep = {
	.start = dmn_lks_start, .arm_deadline = dmn_lks_arm_deadline, .before_wait = dmn_lks_before_wait,
	.fds = dmn_lks_fds, .woke = dmn_lks_woke,
};

static bool dmn_open(struct dmn *d, int *status)
{
	char why[512];
	*status = 1;
	if (!dmn_fds(d))
		return false;
	if (!pub_open(&d->pub, d->cfg, &d->ctl.p, why, sizeof why)) {
		log_error("%s", why);
		return false;
	}
	struct cin_hooks hooks = { .ctx = d, .event = cin_event_hook, .wall_us = cin_wall_hook, .mono_us = cin_mono_hook };
	if (!cin_open(&d->cin, d->cfg, &d->ctl, &hooks, __undulate_command_t_get_hash(), why, sizeof why)) {
		log_error("%s", why);
		/* a key file or socket directory that is wrong stays wrong: a
		 * configuration error, not worth restarting for */
		*status = 2;
		return false;
	}
	return true;
}

static int dmn_run_with(const struct cfg *cfg, struct tune *tune, FILE *tune_out);

/* The configuration lets buses reuse servo IDs (each is its own wire); the
 * controller still keys its register writes and its reports by servo ID, so
 * this daemon refuses a robot whose IDs repeat, saying so. */
static bool dmn_ids_unique(const struct cfg *cfg, char *why, size_t cap)
{
	for (size_t j = 0; j < cfg->njoints; j++) {
		for (size_t k = j + 1; k < cfg->njoints; k++) {
			if (cfg->ids[j] != cfg->ids[k])
				continue;
			snprintf(why, cap, "servo ID %u is joint %zu (bus %s) and joint %zu (bus %s): the configuration "
			         "allows it, but undulated needs each servo of a robot to have an ID of its own (set one with "
			         "`dxl --port PATH set-id OLD NEW`)", cfg->ids[j], j + 1, cfg->bus[cfg->joint_bus[j]].name, k + 1,
			         cfg->bus[cfg->joint_bus[k]].name);
			return false;
		}
	}
	return true;
}

int dmn_run(const struct cfg *cfg) { return dmn_run_with(cfg, NULL, NULL); }

int dmn_run_tune(const struct cfg *cfg, struct tune *t, void *progress)
{
	return dmn_run_with(cfg, t, progress ? progress : stdout);
}

static int dmn_run_with(const struct cfg *cfg, struct tune *tune, FILE *tune_out)
{
	static struct dmn dmn;   /* large (bus stats per ID): not on the stack */
	struct dmn *d = &dmn;
	char why[512];
	if (!dmn_ids_unique(cfg, why, sizeof why)) {
		log_error("%s", why);
		return 2;
	}
	memset(d, 0, sizeof *d);
	d->lks.fd = -1;
	d->cfg = cfg;
	d->tune = tune;
	d->tune_out = tune_out;
	d->lim_bus = (struct log_limit)LOG_LIMIT_INIT(5, 2000000);
	d->lim_overrun = (struct log_limit)LOG_LIMIT_INIT(5, 5000000);
	d->lim_events = (struct log_limit)LOG_LIMIT_INIT(30, 100000);
	d->period_us = (uint64_t)llround(cfg->period_ms * 1000.0);
	d->state_every = pub_state_every(d->period_us);
	d->timer_fd = d->deadline_fd = d->signal_fd = -1;
	d->clock = &dmn_clock_real;
	ctl_init(&d->ctl, cfg);
	struct cyc_hooks ch = { .ctx = d, .bus_error = dmn_bus_error_hook, .notice = dmn_notice_hook };
	for (size_t i = 0; i < cfg->nbuses; i++) {
		if (cfg->bus[i].njoints == 0)
			continue;   /* every joint on a [bus.NAME]: the [robot] port carries none */
		struct dmn_bus *b = &d->buses[d->nbuses++];
		b->index = i;
		b->cb = &cfg->bus[i];
		snprintf(b->port_path, sizeof b->port_path, "%s", b->cb->port);
		cyc_init(&b->cyc, &b->bus, &d->ctl, d->period_us, &ch);
		/* one bus: every joint, as ever; several: each cycle its own */
		if (cfg_buses_used(cfg) > 1)
			cyc_set_bus(&b->cyc, i);
	}
	notify_init(&d->notify);
	d->watchdog_interval_us = notify_watchdog_interval_us(&d->notify);
	int status;
	if (!dmn_open(d, &status)) {
		cin_close(&d->cin);
		pub_close(&d->pub);
		dmn_close_fds(d);
		return status;
	}
	getrusage(RUSAGE_SELF, &d->ru_last);

	char err[512];
	if (cfg->lockstep[0] != '\0') {
		/* from here on the clock is the simulator's: before the start-up
		 * checks, whose bus transactions take virtual time too */
		const char *ports[CFG_MAX_BUSES];
		for (size_t i = 0; i < d->nbuses; i++)
			ports[i] = d->buses[i].port_path;
		if (lks_client_open_buses(&d->lks, cfg->lockstep, ports, d->nbuses, cfg->name, err, sizeof err) != 0) {
			log_error("%s", err);
			cin_close(&d->cin);
			pub_close(&d->pub);
			dmn_close_fds(d);
			return 1;
		}
		d->lockstep = true;
		d->clock = &dmn_clock_lockstep;
	}
	d->epoch_us = now_us();
	if (!dmn_connect(d, "start", err, sizeof err)) {
		log_error("%s", err);
		pub_event(&d->pub, 0, 2, "start-failed", err);
		lks_client_close(&d->lks);
		cin_close(&d->cin);
		pub_close(&d->pub);
		dmn_close_fds(d);
		/* a wiring the device cannot do stays wrong: not worth a restart */
		return d->wiring_refused ? 2 : 1;
	}
	char models[96];
	dmn_models(d, models, sizeof models);
	dmn_torque_defaults(d);
	dmn_position_defaults(d);
	dmn_tune_rebase(d);
	char ports[CFG_MAX_BUSES * (CFG_PATH_MAX + 64)];
	dmn_ports_text(d, ports, sizeof ports);
	log_info("robot %s: %zu joint(s) on %s, Protocol %s (%s), mode %s, LCM %s", cfg->name, cfg->njoints, ports,
	         bus_proto(&d->buses[0].bus)->name, models, cfg_mode_name(d->ctl.mode),
	         cfg->lcm_url[0] ? cfg->lcm_url : "default");
	log_info("commands: %s (local socket %s%s)", cfg_commands_name(cfg->commands), cin_local_path(&d->cin),
	         cfg->commands == CFG_CMD_NETWORK ? "; signed commands from the LCM group" : "");
	if (!cfg->mode_given)
		log_info("no mode given: holding where it stands (the first-run default). Once the robot answers as "
		         "it should, swing the joints with: undulated --command 'mode oscillator' --robot %s%s%s "
		         "(or start with --mode oscillator, or mode = oscillator in the configuration)", cfg->name,
		         cfg->lcm_url[0] ? " --lcm-url " : "", cfg->lcm_url[0] ? cfg->lcm_url : "");
	dmn_realtime(cfg);
	dmn_start_timer(d);
	if (d->lockstep)
		log_info("lockstep: virtual time from the simulator at %s", cfg->lockstep);
	dmn_flush_ctl_events(d);
	pub_params(&d->pub);
	notify_send(&d->notify, "READY=1");
	dmn_notify_status(d);
	if (d->state_every > 1)
		log_info("ready: %s, %.0f Hz (STATE every %" PRIu64 "th cycle: %.0f a second)", d->pub.ch_state,
		         1e6 / (double)d->period_us, d->state_every, 1e6 / (double)(d->period_us * d->state_every));
	else
		log_info("ready: %s, %.0f Hz", d->pub.ch_state, 1e6 / (double)d->period_us);

	dmn_loop(d);

	notify_send(&d->notify, "STOPPING=1");
	for (size_t b = 0; b < d->nbuses; b++) {
		struct dmn_bus *db = &d->buses[b];
		cyc_cut(&db->cyc);
		if (db->connected && !d->clock_lost)
			setup_safe_stop(&db->bus, &d->ctl, cfg, db->index);
	}
	char text[96];
	snprintf(text, sizeof text, "%s",
	         cfg->safe_stop == CFG_SAFE_LIMP || d->ctl.mode == CFG_MODE_LIMP ? "joints limp (torque off)"
	                                                                         : "joints holding (torque on)");
	dmn_event(d, 0, 0, "stop", text);
	for (size_t b = 0; b < d->nbuses; b++)
		dmn_close_port(&d->buses[b]);
	if (d->overruns > 0)
		log_info("overruns: %lld in %" PRIu64 " cycles: %lld period(s) skipped (the loop woke a period or more "
		         "late), %lld cycle(s) still on the bus at the next tick (%lld of them had begun over half a "
		         "period late)",
		         d->overruns, d->cycle, d->overruns_skipped, d->overruns_cut, d->overruns_cut_late);
	long long too_long = 0, in_dropped = 0;
	for (size_t b = 0; b < LKS_BUSES_MAX; b++) {
		too_long += d->lks.bus[b].too_long;
		in_dropped += d->lks.bus[b].in_dropped;
	}
	if (d->lks.resyncs > 0 || d->lks.cmds_dropped > 0 || too_long > 0 || in_dropped > 0 || d->lks.bad_parts > 0)
		log_warn("lockstep: %lld announced bus byte count(s) set right, %lld clock command(s) dropped, %lld bus "
		         "write(s) refused as longer than a clock message carries, %lld delivered bus byte(s) dropped "
		         "unread, %lld message(s) for a bus not named", d->lks.resyncs, d->lks.cmds_dropped, too_long,
		         in_dropped, d->lks.bad_parts);
	lks_client_close(&d->lks);
	cin_close(&d->cin);
	pub_close(&d->pub);
	notify_close(&d->notify);
	dmn_close_fds(d);
	return d->clock_lost ? 1 : 0;
}
