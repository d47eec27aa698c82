/*
 * feed.c — one LCM message into the monitors' model (feed.h).
 */
#include "feed.h"

#include <string.h>

#include "compat/lcm/lcmdec.h"

const char *const top_feed_channels[] = { ".*\\.STATE", ".*\\.BUS", ".*\\.PARAMS", ".*\\.EVENT",
					  "SIM\\.TRUTH", "SIM\\.COLLISION" };
const size_t top_feed_nchannels = sizeof top_feed_channels / sizeof top_feed_channels[0];

static bool feed_ends_with(const char *s, const char *suffix)
{
	size_t n = strlen(s), k = strlen(suffix);
	return n > k && strcmp(s + n - k, suffix) == 0;
}

static const struct lcmdec_type *feed_type(const char *channel)
{
	if (strcmp(channel, "SIM.TRUTH") == 0)
		return &lcmdec_sim_truth_t;
	if (strcmp(channel, "SIM.COLLISION") == 0)
		return &lcmdec_sim_collision_t;
	if (feed_ends_with(channel, ".STATE"))
		return &lcmdec_robot_state_t;
	if (feed_ends_with(channel, ".BUS"))
		return &lcmdec_bus_stats_t;
	if (feed_ends_with(channel, ".PARAMS"))
		return &lcmdec_osc_params_t;
	if (feed_ends_with(channel, ".EVENT"))
		return &lcmdec_event_t;
	return NULL;
}

static void feed_apply(struct top_model *m, const struct lcmdec_type *t, const union lcmdec_any *u, double now,
                       const struct top_feed_hooks *h)
{
	if (t == &lcmdec_robot_state_t) {
		top_on_state(m, &u->state, now);
	} else if (t == &lcmdec_bus_stats_t) {
		top_on_bus(m, &u->bus);
	} else if (t == &lcmdec_osc_params_t) {
		top_on_params(m, &u->params);
	} else if (t == &lcmdec_sim_truth_t) {
		top_on_truth(m, &u->truth, now);
		if (h != NULL && h->on_truth != NULL)
			h->on_truth(m, now, h->user);
	} else if (t == &lcmdec_sim_collision_t) {
		top_on_sim_collision(m, &u->collision, now);
		if (h != NULL && h->on_collision != NULL)
			h->on_collision(&u->collision, now, h->user);
	} else if (t == &lcmdec_event_t) {
		top_on_event(m, &u->event);
		if (h != NULL && h->on_event != NULL)
			h->on_event(&u->event, h->user);
	}
}

bool top_feed(struct top_model *m, const char *channel, const void *data, size_t len, double now,
              const struct top_feed_hooks *hooks, char *why, size_t cap)
{
	if (cap > 0)
		why[0] = '\0';
	const struct lcmdec_type *t = feed_type(channel);
	if (t == NULL)
		return false;
	union lcmdec_any u;
	enum lcmdec_status s = lcmdec_decode(t, data, len, &u);
	if (s != LCMDEC_OK) {
		m->decode_errors++;
		lcmdec_describe(why, cap, t, len, s);
		return false;
	}
	feed_apply(m, t, &u, now, hooks);
	lcmdec_free(t, &u);
	return true;
}
