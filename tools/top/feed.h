/*
 * feed.h — one LCM message into the monitors' model: what undulate-top and
 * undulate-web do with everything robots and the simulator publish.
 *
 * The channel names the type (<robot>.STATE, .BUS, .PARAMS, .EVENT,
 * SIM.TRUTH, SIM.COLLISION); the bytes are decoded through lcmdec (bounded,
 * checked: compat/lcm/lcmdec.h), since anyone on the LCM group can send them.
 * A message that does not decode is counted in the model's decode_errors and
 * described in `why`; the program decides whether to say so (undulate-top
 * owns a full-screen terminal and only counts).
 */
#ifndef UNDULATE_TOP_FEED_H
#define UNDULATE_TOP_FEED_H

#include <stdbool.h>
#include <stddef.h>

#include "model.h"

struct top_feed_hooks {
	/* an event, after the model took it (status lines, command answers) */
	void (*on_event)(const undulate_event_t *e, void *user);
	/* a collision on SIM.COLLISION, after the model took it */
	void (*on_collision)(const undulate_sim_collision_t *c, double now, void *user);
	/* a SIM.TRUTH, after the model took it (its world: m->world) */
	void (*on_truth)(const struct top_model *m, double now, void *user);
	void *user;
};

/* The channels top_feed understands, as LCM subscription patterns. */
extern const char *const top_feed_channels[];
extern const size_t top_feed_nchannels;

/* false: the message did not decode (counted; why says what was wrong), or
 * the channel is not one of ours (why empty). hooks may be NULL. */
bool top_feed(struct top_model *m, const char *channel, const void *data, size_t len, double now,
              const struct top_feed_hooks *hooks, char *why, size_t cap);

#endif
