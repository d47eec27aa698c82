/*
 * publish.h — what a robot tells the LCM network: <robot>.STATE every cycle
 * up to 100 a second (at shorter periods every pub_state_every()-th cycle,
 * and any cycle whose mode or fault changed), .BUS once a second, .PARAMS when they change (and once a second), .EVENT
 * when something happens. Publish only: the daemon never subscribes, so LCM
 * opens no receive socket in it (commands come in through cmdin.h).
 * Messages are encoded into one buffer allocated at start-up (lcm-gen's
 * _publish helpers allocate per message). Text that reaches an event is
 * sanitized here, whatever produced it.
 */
#ifndef UNDULATE_DAEMON_PUBLISH_H
#define UNDULATE_DAEMON_PUBLISH_H

#include <lcm/lcm.h>
#include <stdbool.h>
#include <stdint.h>

#include "bus.h"
#include "config.h"
#include "control.h"
#include "log.h"
#include "undulate_joint_state_t.h"
#include "undulate_servo_stats_t.h"

/* Encode buffer: a robot_state_t of 24 joints is ~2.4 kB, a bus_stats_t ~2 kB. */
#define PUB_ENCODE_CAP 16384
#define PUB_CHANNEL_MAX (CFG_NAME_MAX + 16)

/* STATE at most once every PUB_STATE_MIN_US: 100 a second. Every process on
 * an LCM udpm group receives every datagram sent to it, whatever its
 * channel, so a STATE every cycle at 1 kHz would cost each monitor, logger
 * and the simulator on the group a thousand wake-ups a second; the gait
 * (about 1 Hz) needs far fewer, and .BUS's figures (period, jitter and bus
 * time percentiles, overruns) are over every cycle. */
#define PUB_STATE_MIN_US 10000

/* Publish STATE every this many cycles at this period (µs): 1 up to 10 ms,
 * 10 at 1 ms, the smallest count that keeps to PUB_STATE_MIN_US. */
uint64_t pub_state_every(uint64_t period_us);

/* One cycle's figures for the state message. */
struct pub_cycle {
	int64_t cycle;
	double period_us, jitter_us, bus_us, control_us;
	long long overruns, bus_errors, bad_commands;
};

/* Once a second, for the bus message. */
struct pub_bus {
	const char *port;
	bool connected;
	long long reconnects, overruns;
	double adapter_latency_ms;
	int return_delay_us;
	double period_p50_us, period_p99_us, period_max_us, jitter_p99_us, bus_p99_us, cpu_percent;
};

struct pub {
	lcm_t *lcm;
	const struct cfg *cfg;
	const struct cfg_params *live;   /* the controller's: what .PARAMS reports */
	uint8_t *buf;
	char ch_state[PUB_CHANNEL_MAX], ch_bus[PUB_CHANNEL_MAX], ch_params[PUB_CHANNEL_MAX],
	     ch_event[PUB_CHANNEL_MAX];
	undulate_joint_state_t js[CFG_MAX_JOINTS];
	undulate_servo_stats_t ss[CFG_MAX_JOINTS];
	struct log_limit lim_encode;
	long long events, encode_failures;
};

/* False with *why (LCM could not be created for the URL). `live` is the
 * controller's live parameters (control.h), read at every pub_params(). */
bool pub_open(struct pub *p, const struct cfg *cfg, const struct cfg_params *live, char *why, size_t cap);
void pub_close(struct pub *p);
void pub_event(struct pub *p, int64_t seq, int level, const char *kind, const char *text);
void pub_state(struct pub *p, const struct ctl *c, const struct pub_cycle *f);
void pub_params(struct pub *p);
void pub_bus(struct pub *p, const struct pub_bus *f, const struct bus *bus, const struct ctl *c);
/* A robot on several buses (config.h, [bus.NAME]): the same message with
 * each joint's servo counters from its own bus, bus_of[j] (NULL: the joint
 * is left out), the port and line counters as f says, on `channel` (the
 * robot's ch_bus for all its buses; "<robot>.BUS.<bus>" for one of them). */
struct pub_bus_lines { long long stray_packets, io_errors; int32_t baud; };
void pub_bus_joints(struct pub *p, const struct pub_bus *f, const struct pub_bus_lines *lines,
                    const struct bus *const *bus_of, const struct ctl *c, const char *channel);

#endif
