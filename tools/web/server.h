/* server.h — undulate-web's server: one libwebsockets event loop serving the
 * page, its assets, GET /api/snapshot and the WebSocket the frames go out on,
 * with the LCM socket and the local command socket adopted into the same
 * loop (single-threaded, like the rest of the project). Owns the model
 * (tools/top/model.h), the history (hist.h), the browsers and the command
 * path (wcmd.h). See README.md for the limits. */
#ifndef UNDULATE_WEB_SERVER_H
#define UNDULATE_WEB_SERVER_H

#include <stdbool.h>

#include "req.h"

#define WEB_MAX_CLIENTS 32          /* WebSocket browsers at once; more are refused */
#define WEB_MAX_WATCHERS 24         /* of them without the token: the rest is kept for its holders */
/* Connections at once (HTTP and WebSocket). One more is taken by closing the
 * connection that has waited longest without a request being served (half
 * open, or idle between requests): a crowd that connects and sends nothing
 * only pushes its own out, and a client that sends its request at once (a
 * browser, the operator) is served. */
#define WEB_MAX_CONNECTIONS 128
/* libwebsockets' descriptors: the connections, those being closed to make
 * room, the listening socket, LCM's and the command socket, its own pipe */
#define WEB_FD_LIMIT (WEB_MAX_CONNECTIONS + 64)
#define WEB_HEADER_MAX 4096         /* bytes of request headers; beyond: refused */
#define WEB_FRAME_MAX (2 * 1024 * 1024) /* one frame; a larger catch-up keeps the newest samples */
#define WEB_FRAME_EVERY 2           /* samples (HIST_HZ) per frame: 12.5 frames per second */
#define WEB_STALL_S 30.0            /* a browser that takes no frame for this long is closed */
#define WEB_HTTP_TIMEOUT_S 5        /* a request must arrive whole within this; idle keep-alive as long */
/* Kernel send buffer per browser (the kernel doubles it): with libwebsockets'
 * one partial frame, all a browser that stops reading can hold of ours. A
 * frame of 20 robots is ~6 kB; a browser that reads keeps it nearly empty. */
#define WEB_SNDBUF (16 * 1024)
/* Bytes a WebSocket hands the kernel in one send(): a frame of the page
 * (~11 kB for 20 robots) or a Foxglove batch (FOXSRV_BATCH) at once. */
#define WEB_TX_PACKET (64 * 1024 + 16)
/* LCM messages handled a wakeup at most, so a flood cannot starve HTTP:
 * three bursts of 20 robots' STATE and a SIM.TRUTH. */
#define WEB_LCM_DRAIN 64
#define WEB_NOTES 16                /* answers waiting for a browser's next frame */
#define WEB_FOX_ORIGINS 8           /* --allow-origin, at most */

struct web_opts {
	const char *addr;           /* "127.0.0.1" */
	struct req_hosts hosts;     /* what a request's Host may name (req_host_ok) */
	int port;                   /* 0: any free port (printed) */
	const char *lcm_url;        /* NULL: LCM's default */
	bool read_only;
	const char *token;          /* --token-file's: commands need it */
	bool make_token;            /* no token given, commands on: make one at start (wtok.h) */
	const char *key_file;       /* signed LCM commands instead of local sockets */
	const char *page_dir;       /* index.html, app.js, style.css */
	const char *chartjs;        /* Chart.js from libjs-chart.js */
	/* --allow-origin: pages of other origins that may open the read-only
	 * Foxglove WebSocket (https://app.foxglove.dev); never the page's own */
	const char *fox_origins[WEB_FOX_ORIGINS];
	int nfox_origins;
	bool verbose;
};

/* Runs until SIGINT/SIGTERM; the exit status. */
int web_run(const struct web_opts *o);

#endif
