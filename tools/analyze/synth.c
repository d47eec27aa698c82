/* synth.c — see synth.h. */
#include "synth.h"
#include "alog.h"
#include "modes.h"
#include "phase.h"
#include "theory.h"

#include "undulate_bus_stats_t.h"
#include "undulate_event_t.h"
#include "undulate_osc_params_t.h"
#include "undulate_robot_state_t.h"
#include "undulate_sim_collision_t.h"
#include "undulate_sim_truth_t.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

ALOG_DEFINE_WRITER(robot_state_t)
ALOG_DEFINE_WRITER(sim_truth_t)
ALOG_DEFINE_WRITER(sim_collision_t)
ALOG_DEFINE_WRITER(bus_stats_t)
ALOG_DEFINE_WRITER(event_t)
ALOG_DEFINE_WRITER(osc_params_t)

/* Collisions per cycle at most (one r1:r2 and one r3:r4). */
#define SYNTH_MAX_COLL 2
/* SIM.TRUTH's copy of a collision is stamped this much later (µs). */
#define SYNTH_TRUTH_STAMP_US 7
/* Lateness of a message in the log behind its utime (µs), like a real logger. */
#define SYNTH_LOG_LAG_US 200

static const char *const synth_names[SYNTH_ROBOTS] = { "r1", "r2", "r3", "r4" };

void synth_default(struct synth_spec *s)
{
	*s = (struct synth_spec){
		.duration_s = 45.0, .dt_s = 0.01, .freq_hz = 0.8, .amplitude = 0.8, .lever = 0.1,
		.restitution = 0.67, .delta0 = 2.0, .coll_period_s = 4.0, .ncoll = 8,
		.start_utime = 1700000000000000LL, .truth = true, .report_frequency = true, .burst = 1,
		.stop_after_s = -1.0, .stop_mask = SYNTH_STOP_DEFAULT_MASK,
	};
}

double synth_delta34(const struct synth_spec *s, double t)
{
	int n = (int)floor(t / s->coll_period_s + 1e-9); /* t is a multiple of dt */
	if (n > s->ncoll)
		n = s->ncoll;
	if (n < 0)
		n = 0;
	return theory_return_map_d0(s->delta0, s->restitution, n);
}

double synth_impulse(int k)
{
	return 0.001 * (double)(k % 7 + 1);
}

/* Robot I stands still at time T. */
static bool synth_stopped(const struct synth_spec *s, int i, double t)
{
	return s->stop_after_s >= 0 && t > s->stop_after_s && (s->stop_mask >> i & 1u);
}

static void synth_phases_at(const struct synth_spec *s, double t, double phi[SYNTH_ROBOTS])
{
	phi[0] = 2.0 * M_PI * s->freq_hz * t;
	phi[1] = phi[0] + SYNTH_COMPAT_DELTA;
	phi[2] = phi[1] + M_PI;
	phi[3] = phi[2] + synth_delta34(s, t);
}

/* Phases at T; a stopped robot keeps the phase it had when it stopped. */
static void synth_phases(const struct synth_spec *s, double t, double phi[SYNTH_ROBOTS])
{
	synth_phases_at(s, t, phi);
	double held[SYNTH_ROBOTS];
	synth_phases_at(s, s->stop_after_s, held);
	for (int i = 0; i < SYNTH_ROBOTS; i++)
		if (synth_stopped(s, i, t))
			phi[i] = held[i];
}

static double synth_neutral(const struct synth_spec *s, int i)
{
	double two_a = 2.0 * s->lever * s->amplitude;
	double n[SYNTH_ROBOTS] = { 0.0, SYNTH_DSEP_12 * two_a, (SYNTH_DSEP_12 + SYNTH_DSEP_23) * two_a,
				   (SYNTH_DSEP_12 + SYNTH_DSEP_23) * two_a };
	return n[i];
}

void synth_plane_links(const struct synth_spec *s, int i, double t, double x[SYNTH_LINKS],
		       double y[SYNTH_LINKS], double angle[SYNTH_LINKS])
{
	double phi[SYNTH_ROBOTS];
	synth_phases(s, t, phi);
	/* the joints' angles as synth_state publishes them */
	double a1 = s->amplitude * cos(phi[i]), a2 = s->amplitude * cos(phi[i] - 2.0 * M_PI / 3.0);
	double rel[SYNTH_LINKS] = { 0.0, a1, a1 + a2 }, sx = 0.0, sy = 0.0;
	for (int k = 0; k < SYNTH_LINKS; k++) {
		sx += cos(rel[k]);
		sy += sin(rel[k]);
	}
	/* turned so that the links' mean direction is +y */
	double head = M_PI / 2.0 - atan2(sy, sx);
	double fx = 0.0, fy = 0.0, mx = 0.0, my = 0.0;
	for (int k = 0; k < SYNTH_LINKS; k++) {
		angle[k] = head + rel[k];
		/* link k's front end is link k-1's rear end */
		x[k] = fx - 0.5 * SYNTH_LINK_M * cos(angle[k]);
		y[k] = fy - 0.5 * SYNTH_LINK_M * sin(angle[k]);
		fx -= SYNTH_LINK_M * cos(angle[k]);
		fy -= SYNTH_LINK_M * sin(angle[k]);
		mx += x[k] / SYNTH_LINKS;
		my += y[k] / SYNTH_LINKS;
	}
	for (int k = 0; k < SYNTH_LINKS; k++) {
		x[k] += synth_neutral(s, i) - mx;
		y[k] += SYNTH_PLANE_SPEED * t - my;
	}
}

static int synth_state(const struct synth_spec *s, struct alog_writer *w, int i, int64_t cycle,
		       int64_t utime, double phi, bool stopped)
{
	/* a stopped joint has speed 0 and its goal where it stands */
	double omega = stopped ? 0.0 : 2.0 * M_PI * s->freq_hz;
	undulate_joint_state_t j[2];
	memset(j, 0, sizeof(j));
	for (int k = 0; k < 2; k++) {
		double ph = phi - k * 2.0 * M_PI / 3.0;
		j[k].servo_id = (int16_t)(2 * i + 1 + k);
		j[k].angle = s->amplitude * cos(ph);
		j[k].speed = -s->amplitude * omega * sin(ph);
		j[k].goal = s->amplitude * cos(ph + omega * s->dt_s);
		j[k].load = 0.1 * sin(ph);
		j[k].phase = phase_wrap(ph);
		j[k].amplitude = s->amplitude;
		j[k].frequency = s->report_frequency ? s->freq_hz : 0.0;
		j[k].voltage = 12.0;
		j[k].temperature = 35.0;
		j[k].torque = true;
	}
	char name[16], chan[32];
	snprintf(name, sizeof(name), "%s", synth_names[i]);
	snprintf(chan, sizeof(chan), "%s.STATE", synth_names[i]);
	char reason[] = "command";
	undulate_robot_state_t m = {
		.utime = utime, .robot = name, .cycle = cycle, .mode = MODE_OSCILLATOR,
		.mode_reason = reason, .fault = "", .period_us = s->dt_s * 1e6,
		/* jitter 50..140 µs in a known pattern: its maximum is 140 */
		.jitter_us = 50.0 + 10.0 * (double)(cycle % 10), .bus_us = 600.0, .control_us = 20.0,
		.overruns = 0, .bus_errors = 3 * i, .bad_commands = 0, .njoints = 2, .joints = j,
	};
	return alog_write_robot_state_t(w, chan, utime + SYNTH_LOG_LAG_US, &m);
}

/* Collisions in (t - dt, t]: r3:r4 at multiples of coll_period_s up to
 * ncoll; r2:r3 once a period, a quarter period in. */
static int synth_collisions(const struct synth_spec *s, double t, int64_t utime, int *count,
			    undulate_sim_collision_t out[SYNTH_MAX_COLL], char names[SYNTH_MAX_COLL][2][8])
{
	int n = 0;
	double per = 1.0 / s->freq_hz;
	double tq = t - 0.25 * per;
	if (tq >= 0 && fmod(tq, per) < s->dt_s - 1e-9 && !synth_stopped(s, 1, t) && !synth_stopped(s, 2, t)) {
		out[n] = (undulate_sim_collision_t){ .utime = utime, .left = 1, .right = 2, .pre_left = 0.2,
			.pre_right = -0.2, .post_left = -0.134, .post_right = 0.134, .impulse = synth_impulse(*count) };
		snprintf(names[n][0], 8, "r2");
		snprintf(names[n][1], 8, "r3");
		(*count)++;
		n++;
	}
	int k = (int)floor(t / s->coll_period_s + 1e-9);
	if (k >= 1 && k <= s->ncoll && t - k * s->coll_period_s < s->dt_s - 1e-9 && !synth_stopped(s, 2, t) &&
	    !synth_stopped(s, 3, t)) {
		out[n] = (undulate_sim_collision_t){ .utime = utime, .left = 2, .right = 3, .pre_left = 0.1,
			.pre_right = -0.1, .post_left = -0.067, .post_right = 0.067, .impulse = synth_impulse(*count) };
		snprintf(names[n][0], 8, "r3");
		snprintf(names[n][1], 8, "r4");
		(*count)++;
		n++;
	}
	for (int i = 0; i < n; i++) {
		out[i].left_robot = names[i][0];
		out[i].right_robot = names[i][1];
	}
	return n;
}

static int synth_truth(const struct synth_spec *s, struct alog_writer *w, int64_t step, double t,
		       int64_t utime, const double phi[SYNTH_ROBOTS], int *count, double *impulse)
{
	undulate_sim_body_t bodies[SYNTH_ROBOTS];
	char bnames[SYNTH_ROBOTS][8];
	double omega = 2.0 * M_PI * s->freq_hz;
	for (int i = 0; i < SYNTH_ROBOTS; i++) {
		snprintf(bnames[i], sizeof(bnames[i]), "%s", synth_names[i]);
		double angle = s->amplitude * cos(phi[i]);
		double speed = synth_stopped(s, i, t) ? 0.0 : -s->amplitude * omega * sin(phi[i]);
		bodies[i] = (undulate_sim_body_t){ .robot = bnames[i], .servo_id = (int16_t)(2 * i + 1),
			.angle = angle, .speed = speed,
			.neutral = synth_neutral(s, i), .lateral = synth_neutral(s, i) + s->lever * angle,
			.load = 0.1, .temperature = 35.0 };
	}
	undulate_sim_collision_t coll[SYNTH_MAX_COLL];
	char cnames[SYNTH_MAX_COLL][2][8];
	int nc = synth_collisions(s, t, utime, count, coll, cnames);
	for (int i = 0; i < nc; i++) {
		/* a contact reported as a burst: the same touch, 1 ms apart */
		int copies = coll[i].left == 2 && s->burst > 1 ? s->burst : 1;
		for (int k = 0; k < copies; k++) {
			undulate_sim_collision_t one = coll[i];
			one.utime += 1000 * k;
			if (k > 0)
				one.impulse = synth_impulse((*count)++);
			*impulse += one.impulse;
			if (alog_write_sim_collision_t(w, "SIM.COLLISION", one.utime + SYNTH_LOG_LAG_US, &one) != 0)
				return -1;
		}
		/* SIM.TRUTH carries its copy stamped with its own time (as the
		 * simulator does), so it cannot be matched by time */
		coll[i].utime = utime + SYNTH_TRUTH_STAMP_US;
	}
	undulate_sim_truth_t m = {
		.utime = utime, .step = step, .sim_time = t, .wall_left = -1.0, .wall_right = 1.0,
		.total_collisions = *count, .total_impulse = *impulse, .worst_lateness_us = 5.0,
		.nbodies = SYNTH_ROBOTS, .bodies = bodies, .ncollisions = nc, .collisions = coll,
	};
	undulate_sim_link_t links[SYNTH_ROBOTS * SYNTH_LINKS];
	undulate_sim_wall_t walls[2] = { { .ax = -1.0, .ay = -1.0, .bx = -1.0, .by = 1.0 },
					 { .ax = 1.0, .ay = -1.0, .bx = 1.0, .by = 1.0 } };
	if (s->plane) {
		for (int i = 0; i < SYNTH_ROBOTS; i++) {
			double x[SYNTH_LINKS], y[SYNTH_LINKS], a[SYNTH_LINKS];
			synth_plane_links(s, i, t, x, y, a);
			for (int k = 0; k < SYNTH_LINKS; k++)
				links[i * SYNTH_LINKS + k] = (undulate_sim_link_t){ .robot = (int16_t)i,
					.link = (int8_t)k, .x = x[k], .y = y[k], .angle = a[k],
					.length = SYNTH_LINK_M, .width = 0.032 };
		}
		m.world = UNDULATE_SIM_TRUTH_T_WORLD_PLANE;
		m.nlinks = SYNTH_ROBOTS * SYNTH_LINKS;
		m.links = links;
		m.nwalls = 2;
		m.walls = walls;
	}
	return alog_write_sim_truth_t(w, "SIM.TRUTH", utime + SYNTH_LOG_LAG_US + 10, &m);
}

static int synth_bus_and_event(struct alog_writer *w, int i, int64_t utime, int64_t second)
{
	char name[8], port[] = "/dev/pts/sim", chan[32], kind[] = "mode", text[64];
	snprintf(name, sizeof(name), "%s", synth_names[i]);
	undulate_servo_stats_t sv[2];
	memset(sv, 0, sizeof(sv));
	for (int k = 0; k < 2; k++) {
		sv[k].servo_id = (int16_t)(2 * i + 1 + k);
		sv[k].transactions = 100 * (second + 1);
		sv[k].replies = 100 * (second + 1);
		sv[k].timeouts = second;
	}
	undulate_bus_stats_t b = {
		.utime = utime, .robot = name, .port = port, .baud = 1000000, .connected = 1,
		.adapter_latency_ms = 1.0, .return_delay_us = 0, .period_p50_us = 10000.0,
		.period_p99_us = 10100.0, .period_max_us = 10200.0, .jitter_p99_us = 140.0,
		.bus_p99_us = 650.0, .cpu_percent = 1.5, .nservos = 2, .servos = sv,
	};
	snprintf(chan, sizeof(chan), "%s.BUS", name);
	if (alog_write_bus_stats_t(w, chan, utime + SYNTH_LOG_LAG_US, &b) != 0)
		return -1;
	double k[2] = { 0.5, 0.5 }, c[2] = { 0.02, 0.02 }, mu[2] = { 0.125, 0.125 }, lam[2] = { 1.5, -0.5 },
	       inertia[2] = { 0.02, 0.02 }, fr[2] = { 0, 0 }, neutral[2] = { 0, 0 }, lo[2] = { -1.3, -1.3 },
	       hi[2] = { 1.3, 1.3 };
	undulate_osc_params_t p = { .utime = utime, .robot = name, .njoints = 2, .k = k, .c = c, .mu = mu,
		.lambda = lam, .inertia = inertia, .friction = fr, .neutral = neutral, .limit_min = lo,
		.limit_max = hi, .amplitude = 0.8, .frequency = 0.8, .phase = 0.0 };
	snprintf(chan, sizeof(chan), "%s.PARAMS", name);
	if (alog_write_osc_params_t(w, chan, utime + SYNTH_LOG_LAG_US, &p) != 0)
		return -1;
	if (second != 0)
		return 0;
	snprintf(text, sizeof(text), "mode %s, \"start\"", mode_name(MODE_OSCILLATOR));
	undulate_event_t e = { .utime = utime, .robot = name, .seq = 0, .level = 0, .kind = kind, .text = text };
	snprintf(chan, sizeof(chan), "%s.EVENT", name);
	return alog_write_event_t(w, chan, utime + SYNTH_LOG_LAG_US, &e);
}

int synth_write(const struct synth_spec *s, const char *path, char *err, size_t errlen)
{
	struct alog_writer w;
	if (alog_writer_open(&w, path, err, errlen) != 0)
		return -1;
	int count = 0, rc = 0;
	double impulse = 0.0;
	int64_t ncycles = (int64_t)llround(s->duration_s / s->dt_s);
	int64_t per_second = (int64_t)llround(1.0 / s->dt_s);
	for (int64_t cyc = 0; cyc <= ncycles && rc == 0; cyc++) {
		double t = (double)cyc * s->dt_s;
		int64_t utime = s->start_utime + (int64_t)llround(t * 1e6);
		double phi[SYNTH_ROBOTS];
		synth_phases(s, t, phi);
		for (int i = 0; i < SYNTH_ROBOTS && rc == 0; i++) {
			rc = synth_state(s, &w, i, cyc, utime, phi[i], synth_stopped(s, i, t));
			if (rc == 0 && cyc % per_second == 0)
				rc = synth_bus_and_event(&w, i, utime, cyc / per_second);
		}
		if (rc == 0 && s->truth)
			rc = synth_truth(s, &w, cyc, t, utime, phi, &count, &impulse);
	}
	if (alog_writer_close(&w) != 0 || rc != 0) {
		snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
		return -1;
	}
	return count;
}
