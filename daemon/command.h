/*
 * command.h — validating LCM commands (command_t) before anything is applied.
 * Pure: the caller decodes the message, asks cmd_check(), and on CMD_ACCEPT
 * applies it at the next cycle boundary. Every reason is one line that the
 * daemon logs (rate-limited) and answers with an event_t "command-rejected".
 */
#ifndef UNDULATE_DAEMON_COMMAND_H
#define UNDULATE_DAEMON_COMMAND_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "config.h"

/* command_t.KIND_* */
enum cmd_kind { CMD_KIND_MODE = 1, CMD_KIND_PARAM = 2, CMD_KIND_TORQUE = 3 };

/* The fields of a command_t that matter (strings may be NULL: treated as ""). */
struct cmd_request {
	int64_t seq;
	const char *source;
	const char *robot;
	int kind;
	int mode;
	const char *param;
	int joint;
	double value;
	bool torque;
};

enum cmd_verdict {
	CMD_ACCEPT,
	CMD_REJECT,
	CMD_IGNORE,   /* addressed to another robot on the shared channel: not ours to answer */
};

/* A command_t decoded without allocation (the daemon's loop allocates nothing
 * after start-up) and without trusting the message: LCM 1.3.1's generated
 * decoder mallocs whatever length a string claims (a negative one yields a
 * NULL or unterminated string, a huge one a leaked gigabyte). Strings longer
 * than CMD_STR_MAX - 1 are cut: a cut robot name is longer than any robot's
 * name (CFG_NAME_MAX) and a cut parameter name is no parameter, so a cut never
 * turns a command into one for us. */
#define CMD_STR_MAX (CFG_NAME_MAX + 16)
struct cmd_wire {
	struct cmd_request req;   /* its strings point into the arrays below */
	char source[CMD_STR_MAX];
	char robot[CMD_STR_MAX];
	char param[CMD_STR_MAX];
};

/* Decodes one encoded command_t (fingerprint first, big-endian fields in the
 * order of command_t.lcm, as lcm-gen encodes them) into w. fingerprint is
 * __undulate_command_t_get_hash(). False with a reason when the message is
 * short, has another fingerprint, or a string length that is not 1.. the bytes
 * left or a string without its terminating NUL. */
bool cmd_decode(const void *data, size_t len, int64_t fingerprint, struct cmd_wire *w, char *why, size_t cap);

/* `direct` is true when the command came on "<robot>.CMD" (so another robot
 * name there is a mistake worth answering), false for "UNDULATE.CMD". */
enum cmd_verdict cmd_check(const struct cmd_request *r, const struct cfg *cfg, bool direct,
                           char *why, size_t cap);

/* Apply an accepted KIND_PARAM to cfg (joint -1 = every joint). */
void cmd_apply_param(struct cfg *cfg, const struct cmd_request *r);

/* Parse the text of `undulated --command`: "mode oscillator", "mode 2",
 * "param k 0.5 [joint]", "torque on|off". Unchecked values are passed through
 * on purpose (the daemon is the one that validates). */
bool cmd_parse_text(const char *text, struct cmd_request *r, char *param_buf, size_t param_cap,
                    char *why, size_t cap);

#endif
