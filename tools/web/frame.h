/* frame.h — the JSON frames undulate-web sends each browser over its
 * WebSocket: only what is new since that browser's last frame (its cursor),
 * so a browser that was skipped while it could not keep up catches up with
 * one larger frame, never with a queue of them. Pure: history, model, time
 * and notes in, bytes in a caller's buffer out.
 *
 * One frame (one line of JSON; numbers FRAME_DIGITS significant digits,
 * unknown ones null; times in ms after the server's first sample):
 *   {"type":"frame","now_ms":N,
 *    "status":{...}                    every FRAME_STATUS_EVERY-th frame and the first:
 *        "robots":[{"name","mode","mode_reason","stale","age_s","rate_hz","rx_hz",
 *                   "jitter_p99_us","bus":"ok"|"down"|null,"bus_errors","timeouts",
 *                   "silent_joints","fault","last_event",
 *                   "joints":[{"id","status","temperature","voltage","error_bits","stale_cycles","torque"}]}],
 *        "sim":{"present","collisions_10s","impulse_10s","total_collisions","total_impulse"},
 *        "dropped_robots","decode_errors"
 *    "samples":{"t":[ms...],"robots":[{"name","a":[[joint 0 angles],...],"w":[[speeds]...]}]},
 *    "pairs":[{"a","b","class","d":[deltas],"bound":[bounds]}],   the current neighbours, same t
 *    "marks":[{"t","robot","mode"}],   mode switches since the last frame
 *    "bins":{"t":[ms],"coll":[n],"force":[N]},   closed simulator bins since the last frame
 *    "notes":[{"id","seq","robot","kind","text"}],  answers to this browser's commands
 *    "world":{...}}   the simulator's world, when a SIM.TRUTH or a contact came since the last frame:
 *        "kind":"plane"|"row",
 *        "wall_left","wall_right":   m, the row's walls (also sent in the plane); null both: no walls
 *        "walls":[[ax,ay,bx,by],...]  m, the plane's wall segments
 *        "robots":[{"name","lateral","neutral",   every robot of the model, in the order first heard
 *                   "links":[[x,y,angle,length,width] or null,...]}]  (the index is the contact
 *                   marks' a and b); lateral, neutral: m, null without a body; links by link index
 *                   (0 the head: its centre, rad from rear to front, m), null where none, [] on the row
 *        "contacts":{"t":[ms],"a":[robot],"b":[robot, -1 a wall],"x":[m],"y":[m],"f":[N],"imp":[N·s],
 *                    "impact":[0|1]}   touching pairs summed between two frames (wcontact.h),
 *                   new to this browser and at most WCT_SHOW_S old
 *   with server counters (struct frame_counters) in the status as "server":{...}, and the
 *   world's refusals as "world_refused":{"index","number","overflow","marks"} (struct top_world;
 *   marks: pairs not summed, more than WCT_PENDING between two frames)
 */
#ifndef UNDULATE_WEB_FRAME_H
#define UNDULATE_WEB_FRAME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hist.h"
#include "tools/top/model.h"

#define FRAME_DIGITS 5            /* 0.1 mrad on an angle: beyond what the AX-12 resolves */
#define FRAME_STATUS_EVERY 4      /* status at a quarter of the frame rate (>= 5 Hz at 20 Hz) */
#define FRAME_NOTE_TEXT 160

struct frame_cursor {
	uint64_t sample, bin, mark;   /* next index this browser has not seen */
	uint64_t contact;             /* next contact mark (wcontact.h) */
	int64_t truths;               /* the model's world.truths at its last world */
	uint32_t frames;              /* frames sent */
};

/* An answer to show on one browser (the robot's own EVENT for its command). */
struct frame_note {
	long long id;                 /* the page's number for its command (0: none) */
	int64_t seq;                  /* the command's seq, as the robot echoes it (0: not sent) */
	char robot[TOP_NAME_MAX];
	char kind[32];
	char text[FRAME_NOTE_TEXT];
};

/* The server's own counters, shown on the page (bad input is counted). */
struct frame_counters {
	long long clients, http_requests, http_refused, ws_refused, msgs_refused, commands_sent,
	          commands_refused, frames_sent, frames_skipped, clients_stalled,
	          ws_bad_frames,        /* WebSockets closed for a frame RFC 6455 forbids (wsguard.h), or binary */
	          conns_evicted;        /* connections without a whole request closed to make room */
};

/* Starts a browser at the oldest history held: its first frame draws the
 * whole span. */
void frame_cursor_init(struct frame_cursor *c, const struct hist *h);

/* Writes one frame into buf (at most cap bytes, no terminating NUL counted)
 * and advances c past what it holds. When everything new does not fit, the
 * oldest samples are left out (the browser's plot starts later), never the
 * newest. Returns the length, 0 when not even a frame without samples fits. */
size_t frame_write(const struct hist *h, const struct top_model *m, double now, struct frame_cursor *c,
                   const struct frame_counters *srv, const struct frame_note *notes, int nnotes, char *buf,
                   size_t cap);

#endif
