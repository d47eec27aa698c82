/*
 * cmdin.h — where a robot's commands come in, and the queue they wait in
 * until the cycle boundary.
 *
 * Two doors, both read in the daemon's poll() loop, one datagram at a time,
 * into fixed buffers:
 *  - the local command socket (common/csock.h): programs on this computer
 *    whose user may write the socket file (the daemon's user and group).
 *    The kernel names the sender (uid, pid); that is what is logged.
 *  - with `commands = network` only: the LCM group, read on a socket of our
 *    own bound to the group (common/udpm.h), never through LCM's own receive
 *    (which caches every channel name it hears and listens on every address).
 *    Such a command counts only if it is signed with the robot's shared key
 *    (HMAC-SHA256, common/auth.h), its time is within command_window_s of
 *    ours, and its (time, sequence number) is newer than anything its
 *    source sent before (no replay).
 * A command that fails validation (command.h) is answered at once; one that
 * passes waits in the queue and is applied by cin_apply() at the next cycle
 * boundary, in arrival order, each answered then (it may still be refused:
 * a mode a latched fault forbids). Everything from outside that reaches the
 * log or the event channel is sanitized (common/text.h) and rate-limited.
 */
#ifndef UNDULATE_DAEMON_CMDIN_H
#define UNDULATE_DAEMON_CMDIN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "auth.h"
#include "command.h"
#include "config.h"
#include "control.h"
#include "csock.h"
#include "log.h"

/* Commands waiting for the cycle boundary: more than a person or a script
 * sends in 10 ms; a flood beyond it is refused ("busy"), not buffered. */
#define CIN_QUEUE 16
/* Datagrams read per readable event, so a flood cannot hold the loop. */
#define CIN_BURST 64
#define CIN_WHO_MAX 96
/* Network datagrams: a command_t is ~150 bytes; anything on the group
 * longer than this is not one (and is dropped unread). */
#define CIN_DGRAM_MAX 2048

struct cin_hooks {
	void *ctx;
	/* publish an event_t on "<robot>.EVENT" */
	void (*event)(void *ctx, int64_t seq, int level, const char *kind, const char *text);
	/* wall clock (µs since the epoch: signed commands' time window) and a
	 * monotonic one (rate limits) */
	int64_t (*wall_us)(void *ctx);
	uint64_t (*mono_us)(void *ctx);
};

struct cin_cmd {
	struct cmd_wire w;
	bool direct;                     /* to this robot, not "*" on the shared channel */
	bool local;                      /* from the local socket: answer there too */
	struct csock_peer peer;
	char who[CIN_WHO_MAX];           /* "uid 1000 pid 4242 'undulated-command@lab1'" */
};

struct cin {
	const struct cfg *cfg;
	const struct ctl *ctl;           /* a command's value is judged against its live parameters */
	struct cin_hooks hooks;
	int64_t fingerprint;             /* command_t's */
	int local_fd, net_fd;
	char local_path[CSOCK_PATH_MAX];
	char ch_cmd[CFG_NAME_MAX + 8];   /* "<robot>.CMD" */
	struct auth_key key;
	struct auth_replay replay;
	struct cin_cmd q[CIN_QUEUE];
	size_t nq;
	uint8_t buf[CIN_DGRAM_MAX];
	/* counters */
	long long received, accepted, rejected, unauthenticated, busy;
	/* what may reach the log and the event channel: the answers to
	 * authentic senders (local, or signed) apart from the refusals of
	 * unauthenticated network traffic, so a flood of the latter cannot
	 * silence the former */
	struct log_limit lim_log_reject, lim_log_accept, lim_event_reject, lim_event_accept;
	struct log_limit lim_log_unauth, lim_event_unauth;
};

/* Opens the doors the configuration asks for. cfg is read each time (its
 * name, its commands setting), and a parameter's value is judged against
 * ctl's live parameters when it arrives (NULL: the configuration's). False
 * with *why (a config error, or the socket taken by another daemon for this
 * robot). */
bool cin_open(struct cin *in, const struct cfg *cfg, const struct ctl *ctl, const struct cin_hooks *hooks,
              int64_t fingerprint, char *why, size_t cap);
void cin_close(struct cin *in);
/* --check-config: the command key (with commands = network) judged as
 * cin_open() judges it at start: false with the same refusal in *why. Run
 * by root, a key owned by another user is judged for a daemon running as
 * that user (User= in its unit), and *note says so ("" otherwise). */
bool cin_check_key(const struct cfg *cfg, char *why, size_t cap, char *note, size_t note_cap);
/* The descriptors to poll (-1: not open). */
int cin_local_fd(const struct cin *in);
int cin_net_fd(const struct cin *in);
const char *cin_local_path(const struct cin *in);
/* A descriptor is readable: take what waits there (up to CIN_BURST). */
void cin_on_local(struct cin *in);
void cin_on_network(struct cin *in);
/* One datagram from either door, as the two calls above hand it on (tests
 * and fuzzers call these directly). */
void cin_local_datagram(struct cin *in, const uint8_t *d, size_t n, bool truncated, const struct csock_peer *peer);
void cin_network_datagram(struct cin *in, const uint8_t *d, size_t n, bool truncated);
/* A command the lockstep clock delivered (common/lockstep.h): the text of
 * `undulated --command`, parsed and checked as a local one and queued for the
 * cycle boundary like any other; answered in the log and on the event
 * channel (the simulator that sent it reads neither). */
void cin_clock_command(struct cin *in, const char *text);
/* The cycle boundary: apply the queued commands to the controller (a
 * parameter through ctl_set_param), answer each. */
void cin_apply(struct cin *in, struct ctl *ctl);
size_t cin_pending(const struct cin *in);
/* Commands refused so far, for the state message (bad_commands). */
long long cin_refused(const struct cin *in);

#endif
