/* foxsrv.h — undulate-web's Foxglove WebSocket (foxglove.websocket.v1,
 * read-only): the channels heard on LCM, each Foxglove client's
 * subscriptions and what waits to be sent to it. Owns that state; the
 * server (server.c) owns the connections, admits a client through the same
 * Host check, Origin rule, RFC 6455 guard and limits as every WebSocket,
 * and calls in here. The pure parts (types, schemas, JSON, frames, ops) are
 * fox.h.
 *
 * A channel is advertised to every client when its first message is heard,
 * and unadvertised after FOXSRV_QUIET_S without one. A message is decoded
 * and written as JSON only when some client subscribes to its channel, once
 * for all of them, and queued per client (FOXSRV_QUEUE bytes: a client that
 * reads slower than its topics come loses messages, counted, and one that
 * takes nothing for FOXSRV_STALL_S is closed). What the server says of
 * itself (serverInfo, advertise, unadvertise, status) is written when the
 * socket can take it, from the state, never queued. */
#ifndef UNDULATE_WEB_FOXSRV_H
#define UNDULATE_WEB_FOXSRV_H

#include <libwebsockets.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "fox.h"

/* Channels at once: 64 robots' four (STATE, BUS, PARAMS, EVENT) and the
 * simulator's four; names beyond are refused (counted). */
#define FOXSRV_CHANNELS 264
#define FOXSRV_TOPIC_MAX 64           /* an LCM channel name as advertised (longer: refused) */
#define FOXSRV_QUIET_S 10.0           /* a channel silent this long is unadvertised */
/* Bytes queued per client: ~1 s of one robot's STATE at 100 Hz as JSON
 * (about 1 kB a message with two joints), more than a second of SIM.TRUTH. */
#define FOXSRV_QUEUE (256 * 1024)
#define FOXSRV_STALL_S 30.0           /* a client that takes nothing for this long is closed */
/* One message's JSON: a SIM.TRUTH of 64 robots, their links and contacts is
 * ~100 kB; larger ones are dropped (counted). */
#define FOXSRV_MSG_MAX (512 * 1024)
#define FOXSRV_OP_MAX 4096            /* one client operation (64 subscriptions are ~2 kB) */
#define FOXSRV_STATUS 8               /* status messages waiting per client; the oldest goes */
#define FOXSRV_STATUS_TEXT 200
#define FOXSRV_ADVERTISE_BATCH 8      /* channels per advertise message */
/* Bytes of queued messages sent in one go (foxsrv_write): about a burst of
 * 20 robots' STATE and a SIM.TRUTH; the protocol's tx_packet_size
 * (server.c) lets it out in one send(). */
#define FOXSRV_BATCH (64 * 1024)

struct foxsrv_sub {
	uint32_t id, channel;
};

/* One Foxglove client (libwebsockets' per-session data of the protocol). */
struct fox_client {
	struct lws *wsi;
	unsigned id;
	bool info_sent;
	uint32_t advertised[FOXSRV_CHANNELS];   /* per channel slot: the id it knows there (0 none) */
	struct foxsrv_sub subs[FOX_OP_ITEMS];
	int nsubs;
	unsigned char *queue;                   /* FOXSRV_QUEUE bytes: [u32 len][frame] ... */
	size_t qhead, qtail;
	char status[FOXSRV_STATUS][FOXSRV_STATUS_TEXT];
	int nstatus;
	double last_write;
	bool dropping;                          /* the rest of an oversized message */
	bool failed;                            /* closed for what it sent */
	bool gone;                              /* closed for not reading */
};

struct foxsrv_counters {
	long long clients,          /* connected now */
	          refused,          /* operations and frames refused (each answered with a status) */
	          sent,             /* messageData frames sent */
	          batches,          /* sends that carried them (several frames each) */
	          dropped,          /* messages not queued: the client was behind */
	          channels_refused, /* channels not advertised: too many, or a name not printable */
	          too_large,        /* messages whose JSON exceeded FOXSRV_MSG_MAX */
	          stalled;          /* clients closed for taking nothing */
};

bool foxsrv_init(void);
void foxsrv_fini(void);
const struct foxsrv_counters *foxsrv_counters(void);

/* An LCM message heard (any channel; those of no type are ignored). */
void foxsrv_heard(const char *channel, const void *data, size_t len, uint64_t wall_ns, double now);

/* A client's WebSocket is open / closed. false: no memory for its queue. */
bool foxsrv_open(struct fox_client *c, struct lws *wsi, unsigned id, double now);
void foxsrv_close(struct fox_client *c);

/* One message (or a fragment: first/last) from the client. A refusal is
 * answered with a status and counted; why says it for the log (empty if
 * nothing was refused). */
void foxsrv_receive(struct fox_client *c, const char *in, size_t len, bool binary, bool first, bool last,
                    char *why, size_t cap);

/* The socket can take more: the next thing due (serverInfo, unadvertise,
 * advertise, status, in that order, one a call), else the queued messages,
 * up to FOXSRV_BATCH bytes at once. -1: close it. */
int foxsrv_write(struct fox_client *c, double now);

/* Unadvertises quiet channels, closes clients that take nothing. */
void foxsrv_tick(double now);

#endif
