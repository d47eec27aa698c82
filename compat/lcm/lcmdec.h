/*
 * lcmdec.h — decoding LCM messages that anyone on the group may have sent.
 *
 * The only way our programs decode an undulate message: lcmdec_decode() runs
 * lcm-gen's decoder (compiled against compat/lcm/lcm_coretypes.h, whose
 * primitive and string decoders check every length) inside a frame that
 *  - refuses a message longer than its type's maximum (LCMDEC_MAX_*),
 *  - bounds what the decode may allocate by the message's own length
 *    (LCMDEC_BUDGET), so a count that lies is refused before its malloc,
 *  - frees everything a failed decode allocated (lcm-gen's code returns -1
 *    with the arrays and strings it has so far still allocated), and
 *  - wants the whole message consumed (trailing bytes are malformed).
 * A decoded message is freed with lcmdec_free(). Not reentrant across
 * threads' frames: each thread has its own (thread-local).
 */
#ifndef UNDULATE_COMPAT_LCMDEC_H
#define UNDULATE_COMPAT_LCMDEC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "undulate_bus_stats_t.h"
#include "undulate_command_t.h"
#include "undulate_event_t.h"
#include "undulate_osc_params_t.h"
#include "undulate_robot_state_t.h"
#include "undulate_sim_collision_t.h"
#include "undulate_sim_command_t.h"
#include "undulate_sim_reply_t.h"
#include "undulate_sim_truth_t.h"
#include "undulate_sim_world_t.h"

/* One message type: its name, its C size, the longest message accepted, and
 * lcm-gen's decode and cleanup behind thunks with one signature. */
struct lcmdec_type {
	const char *name;
	size_t size;
	size_t max_len;
	int (*decode)(const void *buf, int len, void *out);
	int (*cleanup)(void *msg);
};

/* The longest message of each kind we accept (bytes). Far above what any
 * robot or simulator sends (a two-joint state is ~300 bytes; a ten-robot
 * SIM.TRUTH ~2 kB), far below what a lie could make a program allocate. */
#define LCMDEC_MAX_ROBOT   (64 * 1024)   /* robot_state_t, bus_stats_t, osc_params_t, event_t */
#define LCMDEC_MAX_SIM     (1024 * 1024) /* sim_truth_t: bodies and collisions of a whole world */
#define LCMDEC_MAX_SMALL   (16 * 1024)   /* commands, replies, one collision, the world */
/* What one decode may allocate: 16 bytes of C struct per byte of message
 * covers any lcm-gen layout (each field takes >= 1 byte on the wire and <= 16
 * in memory, padding included), plus a page for the strings' slack. */
#define LCMDEC_BUDGET(len) (16 * (size_t)(len) + 4096)
/* Allocations one decode may hold (strings and arrays): a SIM.TRUTH with 1000
 * bodies and collisions stays far below. */
#define LCMDEC_MAX_ALLOCS 8192

extern const struct lcmdec_type lcmdec_robot_state_t, lcmdec_bus_stats_t, lcmdec_osc_params_t,
	lcmdec_event_t, lcmdec_command_t, lcmdec_sim_truth_t, lcmdec_sim_collision_t, lcmdec_sim_world_t,
	lcmdec_sim_command_t, lcmdec_sim_reply_t;

/* Room for any one decoded message, whatever its type (a program that
 * decodes by channel decodes into one of these). */
union lcmdec_any {
	undulate_robot_state_t state;
	undulate_bus_stats_t bus;
	undulate_osc_params_t params;
	undulate_event_t event;
	undulate_command_t command;
	undulate_sim_truth_t truth;
	undulate_sim_collision_t collision;
	undulate_sim_world_t world;
	undulate_sim_command_t sim_command;
	undulate_sim_reply_t reply;
};

enum lcmdec_status {
	LCMDEC_OK = 0,
	LCMDEC_TOO_LONG,     /* longer than the type's maximum */
	LCMDEC_MALFORMED,    /* wrong fingerprint, a length past the end, a string without its NUL */
	LCMDEC_TRAILING,     /* decoded, but bytes were left over */
	LCMDEC_OVER_BUDGET,  /* a count that would allocate more than the message could hold */
};

/* Decode len bytes as type t into out (a struct of t->size bytes, zeroed
 * first). On LCMDEC_OK free it with lcmdec_free(); on any other status out
 * holds nothing to free. */
enum lcmdec_status lcmdec_decode(const struct lcmdec_type *t, const void *buf, size_t len, void *out);
void lcmdec_free(const struct lcmdec_type *t, void *msg);
/* "robot_state_t: 309 bytes do not decode (a length past the end of the message)" */
const char *lcmdec_describe(char *out, size_t cap, const struct lcmdec_type *t, size_t len, enum lcmdec_status s);

#endif
