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
