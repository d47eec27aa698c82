/* keys.h — terminal key decoding and the commands keys send (pure code, so
 * tests can check what a key sends without a terminal or a network). */
#ifndef UNDULATE_TOP_KEYS_H
#define UNDULATE_TOP_KEYS_H

#include <stddef.h>
#include <stdint.h>

#include "model.h"
#include "undulate_command_t.h"

enum top_key { TOP_KEY_NONE, TOP_KEY_UP, TOP_KEY_DOWN, TOP_KEY_PGUP, TOP_KEY_PGDN, TOP_KEY_HOME,
	       TOP_KEY_END, TOP_KEY_CHAR };

/* Longest escape sequence we decode (ESC [ 5 ~ and friends). */
#define TOP_KEYSEQ_MAX 8

struct top_keyparser {
	unsigned char seq[TOP_KEYSEQ_MAX];
	int n;
};

/* Feeds one byte; returns a key when one is complete (TOP_KEY_CHAR with the
 * byte in *CH), TOP_KEY_NONE while inside an escape sequence. Unknown
 * sequences are dropped. */
enum top_key top_key_feed(struct top_keyparser *kp, unsigned char byte, int *ch);

#define TOP_NUDGE_FRACTION 0.1   /* +/- scale the oscillator's c by 10 % */
#define TOP_CHANNEL_MAX 80

/* A command ready to publish. The strings live in the struct. */
struct top_command {
	char channel[TOP_CHANNEL_MAX];
	char robot[TOP_NAME_MAX];
	char param[16];
	char source[64];
	undulate_command_t msg;
};

/* Mode change for ROBOT ("*" = every robot, sent on UNDULATE.CMD). */
int top_command_mode(struct top_command *c, const char *robot, int mode, int64_t seq, const char *source);
/* +1/-1 nudge of the parameter that drives robot R's current mode: c of
 * every joint (one command per joint) in OSCILLATOR, the amplitude in
 * SINUSOID, each kept inside the range the daemon accepts (common/params.h). Returns the number of commands (<= TOP_MAX_JOINTS), or -1 with
 * the reason in WHY (no parameters known yet, nothing to nudge in LIMP/HOLD,
 * out of range). A description of what is sent goes in WHY otherwise. */
int top_command_nudge(struct top_command out[TOP_MAX_JOINTS], const struct top_robot *r, int dir, int64_t seq,
		      const char *source, char *why, size_t whylen);

#endif
