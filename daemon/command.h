/*
 * command.h — commands to a robot (command_t): decoding without trust, the
 * text form of `undulated --command`, and validation. Pure: no I/O, no
 * clock, no controller state. Where a command comes from and whether it is
 * authentic is cmdin.h's business; when it is applied (at the next cycle
 * boundary, never in the middle of a cycle's bus work) is the daemon's.
 *
 * What a command may do (README, "Safety"): change the mode, torque, clear a
 * latched fault, and set the documented oscillator and sinusoid parameters
 * within their documented ranges. Nothing that bounds where a joint may go —
 * neutral, limit_min, limit_max, max_step — can be changed by a command:
 * only the configuration file decides that.
 */
#ifndef UNDULATE_DAEMON_COMMAND_H
#define UNDULATE_DAEMON_COMMAND_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "config.h"

/* command_t.KIND_* */
enum cmd_kind { CMD_KIND_MODE = 1, CMD_KIND_PARAM = 2, CMD_KIND_TORQUE = 3, CMD_KIND_CLEAR = 4 };

/* command_t.mac: HMAC-SHA256 over every byte of the encoded message before
 * it (common/auth.h); zero when the command is not signed. */
#define CMD_MAC_BYTES 32

/* The fields of a command_t that matter (strings may be NULL: treated as ""). */
struct cmd_request {
	int64_t utime;
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
	uint8_t mac[CMD_MAC_BYTES];
	size_t signed_len;        /* the bytes the MAC covers: the message up to the MAC */
};

/* Decodes one encoded command_t (fingerprint first, big-endian fields in the
 * order of command_t.lcm, as lcm-gen encodes them) into w. fingerprint is
 * __undulate_command_t_get_hash(). False with a reason when the message is
 * short or longer than a command_t, has another fingerprint, or a string
 * length that is not 1.. the bytes left or a string without its terminating
 * NUL. */
bool cmd_decode(const void *data, size_t len, int64_t fingerprint, struct cmd_wire *w, char *why, size_t cap);
/* After copying a cmd_wire (a queue keeps commands until the cycle
 * boundary): point its request's strings at the copy's own arrays. */
void cmd_wire_rebase(struct cmd_wire *w);
/* Encodes r into buf as lcm-gen would, with `mac` (NULL: zeros) at the end.
 * Returns the length, 0 if it does not fit. *signed_len (may be NULL) gets
 * the length the MAC covers. */
size_t cmd_encode(const struct cmd_request *r, int64_t fingerprint, const uint8_t *mac, void *buf, size_t cap,
                  size_t *signed_len);

/* `direct` is true when the command was addressed to this robot's own
 * channel or socket (so another robot name there is a mistake worth
 * answering), false for the shared "UNDULATE.CMD". Names quoted in *why are
 * sanitized (they come from outside). A parameter's value is judged with
 * cfg_params_check() against `live`, the values the robot runs with (NULL:
 * the configuration's own); cmd_check() is cmd_check_live() with NULL.
 * Applying an accepted parameter is the controller's (ctl_set_param). */
enum cmd_verdict cmd_check_live(const struct cmd_request *r, const struct cfg *cfg, const struct cfg_params *live,
                                bool direct, char *why, size_t cap);
enum cmd_verdict cmd_check(const struct cmd_request *r, const struct cfg *cfg, bool direct,
                           char *why, size_t cap);

/* Parse the text of `undulated --command`: "mode oscillator", "mode 2",
 * "param k 0.5 [joint]", "torque on|off", "clear". Unchecked values are
 * passed through on purpose (the daemon is the one that validates). */
bool cmd_parse_text(const char *text, struct cmd_request *r, char *param_buf, size_t param_cap,
                    char *why, size_t cap);
/* A one-line description of r for answers and logs, its names sanitized. */
void cmd_describe(const struct cmd_request *r, char *out, size_t cap);

#endif
