/*
 * fuzz_daemon_commands.c — libFuzzer target for what a robot takes from
 * outside as commands: datagrams on its local command socket and on the LCM
 * group (cmdin.c: decoding, authentication, the replay guard, validation, the
 * queue), applied at the cycle boundary to a running controller.
 *
 * Input: a sequence of records, each
 *     1 byte  door: bit 0 = network (else local), bit 1 = sign it with the
 *             robot's key before it goes in (network: the MAC over the body,
 *             so fuzzed commands reach the validation behind the signature),
 *             bit 2 = apply the queue and step the controller after it
 *     2 bytes length (big-endian), then that many bytes of datagram
 * For the network door the bytes are the LCM datagram's channel and payload
 * (the "LC02" header and sequence number are added); for the local door, the
 * command_t itself.
 *
 * Invariants (abort() on violation):
 *  - the configuration's limits, neutral angles and max_step never change;
 *  - every goal the controller would send is finite and inside the joint's
 *    limits, and moves at most max_step a cycle (or, once torque was off,
 *    starts within max_step of where the joint is);
 *  - the queue never holds more than CIN_QUEUE commands;
 *  - every datagram on a command channel or the local socket is counted:
 *    received = accepted + refused + still queued + ignored (another robot's
 *    on the shared channel);
 *  - nothing is accepted from the network without a valid signature.
 *
 *   make fuzz-build && build/fuzz/fuzz_daemon_commands tests/fuzz/seeds/fuzz_daemon_commands
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_records.h"
#include "../../daemon/cmdin.h"
#include "../../daemon/control.h"
#include "auth.h"
#include "dxl.h"
#include "undulate_command_t.h"
#include "wire.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

static struct cfg cfg, cfg0;
static struct ctl ctl;
static struct cin in;
static int64_t wall, mono;
static long long events;

static void on_event(void *ctx, int64_t seq, int level, const char *kind, const char *text)
{
	(void)ctx; (void)seq; (void)level;
	CHECK(kind != NULL && text != NULL);
	CHECK(strchr(text, '\n') == NULL);
	events++;
}
static int64_t wall_us(void *ctx) { (void)ctx; return wall; }
static uint64_t mono_us(void *ctx) { (void)ctx; return (uint64_t)mono; }

static void setup(void)
{
	struct cfg_errors e = { 0 };
	cfg_defaults(&cfg);
	cfg_override(&cfg, "robot.name=r1", &e);
	cfg_override(&cfg, "robot.port=/dev/null", &e);
	cfg_override(&cfg, "robot.ids=1,2", &e);
	cfg_override(&cfg, "robot.commands=network", &e);
	cfg_override(&cfg, "robot.command_key=/nonexistent", &e);
	CHECK(cfg_finish(&cfg, &e));
	cfg0 = cfg;
	ctl_init(&ctl, &cfg);
	char why[256];
	struct ctl_servo_info info = { .cw_limit = 0, .ccw_limit = 1023, .max_torque = 1023, .status_return_level = 2 };
	for (size_t j = 0; j < 2; j++) {
		CHECK(ctl_set_servo(&ctl, j, &info, why, sizeof why));
		ctl_measure(&ctl, j, 512, 0, 0, 0, 0.01);
	}
	ctl_start(&ctl, 0.0, "fuzz");
	/* the doors by hand: no sockets, a known key */
	memset(&in, 0, sizeof in);
	in.cfg = &cfg;
	in.ctl = &ctl;
	in.hooks = (struct cin_hooks){ .event = on_event, .wall_us = wall_us, .mono_us = mono_us };
	in.fingerprint = __undulate_command_t_get_hash();
	in.local_fd = in.net_fd = -1;
	snprintf(in.ch_cmd, sizeof in.ch_cmd, "r1.CMD");
	memset(in.key.bytes, 0x5a, sizeof in.key.bytes);
	in.lim_log_reject = (struct log_limit)LOG_LIMIT_INIT(10, 200000);
	in.lim_event_reject = (struct log_limit)LOG_LIMIT_INIT(20, 100000);
	in.lim_log_accept = (struct log_limit)LOG_LIMIT_INIT(20, 200000);
	in.lim_event_accept = (struct log_limit)LOG_LIMIT_INIT(50, 20000);
	in.lim_log_unauth = (struct log_limit)LOG_LIMIT_INIT(5, 1000000);
	in.lim_event_unauth = (struct log_limit)LOG_LIMIT_INIT(5, 1000000);
	wall = 1700000000000000;
	mono = 1000000;
	auth_replay_init(&in.replay, (int64_t)(cfg.command_window_s * 1e6), wall - 1000000);
	events = 0;
}

static void check_limits_unchanged(void)
{
	/* nor anything else of it: the live parameters are the controller's */
	CHECK(memcmp(&cfg, &cfg0, sizeof cfg) == 0);
	for (size_t j = 0; j < cfg.njoints; j++) {
		CHECK(memcmp(&cfg.joint[j].neutral, &cfg0.joint[j].neutral, sizeof(double)) == 0);
		CHECK(memcmp(&cfg.joint[j].limit_min, &cfg0.joint[j].limit_min, sizeof(double)) == 0);
		CHECK(memcmp(&cfg.joint[j].limit_max, &cfg0.joint[j].limit_max, sizeof(double)) == 0);
		CHECK(memcmp(&cfg.joint[j].max_step, &cfg0.joint[j].max_step, sizeof(double)) == 0);
	}
}

static void step(void)
{
	double before[2] = { ctl.j[0].goal, ctl.j[1].goal };
	cin_apply(&in, &ctl);
	for (size_t j = 0; j < 2; j++)
		ctl_measure(&ctl, j, dxl_rad_to_pos(isfinite(ctl.j[j].goal) ? ctl.j[j].goal : 0.0), 0, 0, 0, 0.01);
	wall += 10000;
	mono += 10000;
	ctl_step(&ctl, 1e-6 * (double)mono, 0.01, 1e-6 * (double)wall);
	for (size_t j = 0; j < 2; j++) {
		const struct ctl_joint *jt = &ctl.j[j];
		if (!jt->write_goal)
			continue;
		CHECK(isfinite(jt->goal));
		CHECK(jt->goal >= cfg0.joint[j].neutral + cfg0.joint[j].limit_min - 1e-9);
		CHECK(jt->goal <= cfg0.joint[j].neutral + cfg0.joint[j].limit_max + 1e-9);
		/* a goal moves at most max_step from the last one, or starts where
		 * the joint is (after torque was off: it may have been moved) */
		if (isfinite(before[j]))
			CHECK(fabs(jt->goal - before[j]) <= cfg0.joint[j].max_step + 1e-9 ||
			      fabs(jt->goal - jt->angle) <= cfg0.joint[j].max_step + 1e-9);
	}
	while (ctl_take_write(&ctl) != NULL)
		ctl_write_result(&ctl, true);
	struct ctl_event e;
	while (ctl_next_event(&ctl, &e))
		;
}

/* The network door: the record's bytes are "channel\0payload"; sign the
 * payload if asked (its last CMD_MAC_BYTES are replaced by the MAC). */
static void network(const uint8_t *d, size_t n, bool sign)
{
	static uint8_t dgram[CIN_DGRAM_MAX + 64], body[CIN_DGRAM_MAX];
	const uint8_t *nul = memchr(d, '\0', n);
	if (nul == NULL || n > sizeof body)
		return;
	size_t chlen = (size_t)(nul - d), plen = n - chlen - 1;
	memcpy(body, nul + 1, plen);
	if (sign && plen >= CMD_MAC_BYTES)
		auth_mac(&in.key, body, plen - CMD_MAC_BYTES, body + plen - CMD_MAC_BYTES);
	char channel[WIRE_CHANNEL_MAX];
	if (chlen == 0 || chlen >= sizeof channel)
		return;
	memcpy(channel, d, chlen);
	channel[chlen] = '\0';
	size_t len = wire_udpm_build(dgram, sizeof dgram, 1, channel, body, plen);
	if (len > 0)
		cin_network_datagram(&in, dgram, len, false);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	setup();
	size_t off = 0;
	long long accepted_net_unsigned = 0;
	uint8_t door;
	const uint8_t *rec;
	size_t n;
	while (fuzz_next_record(data, size, &off, &door, &rec, &n)) {
		long long acc = in.accepted;
		size_t q = in.nq;
		if (door & 1) {
			network(rec, n, (door & 2) != 0);
			/* a network command queued unsigned would be a hole */
			if (in.nq > q && !(door & 2))
				accepted_net_unsigned++;
		} else {
			struct csock_peer peer = { 0 };
			cin_local_datagram(&in, rec, n, false, &peer);
		}
		(void)acc;
		CHECK(in.nq <= CIN_QUEUE);
		if (door & 4)
			step();
		check_limits_unchanged();
		mono += 1000;
		wall += 1000;
	}
	step();
	check_limits_unchanged();
	CHECK(accepted_net_unsigned == 0);
	CHECK(in.nq == 0);
	CHECK(in.received >= in.accepted + in.rejected + in.unauthenticated + in.busy);
	return 0;
}
