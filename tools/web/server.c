/* server.c — see server.h. */
#include "server.h"

#include <errno.h>
#include <inttypes.h>
#include <libwebsockets.h>
#include <math.h>
#include <signal.h>
#include <sodium.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "clock.h"
#include "csock.h"
#include "tools/top/feed.h"
#include "foxsrv.h"
#include "frame.h"
#include "hist.h"
#include "req.h"
#include "params.h"
#include "text.h"
#include "wcmd.h"
#include "wlcm.h"
#include "wsrecv.h"
#include "wtok.h"

/* One browser on the WebSocket (libwebsockets' per-session data). */
struct web_client {
	struct lws *wsi;
	unsigned id;
	struct frame_cursor cur;
	bool want;              /* a frame is due: asked for writable, not written yet */
	double want_since;
	bool authed;            /* holds the token: may command */
	bool wrong_token;       /* offered one at the handshake, not ours */
	bool dropping;          /* the rest of an oversized message */
	bool failed;            /* closed for what its client sent: nothing more from it counts */
	struct frame_note notes[WEB_NOTES];
	int nnotes;
};

/* One HTTP request (GET /api/snapshot's body while it is written). */
struct web_http {
	char *body;
	size_t len, off;
};

/* One TCP connection, from its adoption to its end (the crowd's rules, server.h). */
enum web_conn_state {
	WEB_CONN_WAITING,       /* no request being served: just accepted, or idle after an answer */
	WEB_CONN_BUSY,          /* a request arrived whole and is being answered */
	WEB_CONN_WS,            /* a WebSocket (counted apart: WEB_MAX_CLIENTS) */
	WEB_CONN_EVICTED,       /* closed to make room; gone at its WSI_DESTROY */
};
struct web_conn {
	struct lws *wsi;
	double since;           /* when it started waiting */
	enum web_conn_state state;
};

#define WEB_TAG_LCM ((void *)1)
#define WEB_TAG_CMD ((void *)2)
#define WEB_LOG_FIRST 5      /* messages of one kind printed before one in every WEB_LOG_EVERY */
#define WEB_LOG_EVERY 100

static struct web_app {
	struct web_opts o;
	struct lws_context *ctx;
	struct lws_vhost *vh;
	lcm_t *lcm;                 /* publishing; receiving too when wlcm cannot (not udpm) */
	struct wlcm rx;             /* the group read in this loop (wlcm.h) */
	bool own_rx;
	struct top_model model;
	struct hist hist;
	struct wcmd cmd;
	bool cmd_ok;
	char cmd_why[256];
	struct web_conn conns[WEB_FD_LIMIT];
	int nconns, nevicted;
	struct web_client *clients[WEB_MAX_CLIENTS];
	int nclients;
	int nwatchers;              /* of them without the token */
	char token[REQ_TOKEN_MAX];  /* made at start (wtok.h) */
	char token_path[CSOCK_PATH_MAX + 64];
	unsigned next_client;
	lws_sorted_usec_list_t sul;
	uint64_t ticks;
	unsigned char *frame;       /* LWS_PRE + WEB_FRAME_MAX */
	struct frame_counters n;
} app;

static volatile sig_atomic_t web_stop;

static void web_on_signal(int sig)
{
	(void)sig;
	web_stop = 1;
	if (app.ctx != NULL)
		lws_cancel_service(app.ctx);
}

/* A message about bad input: the first few, then one in WEB_LOG_EVERY (each
 * kind is counted on the page either way). */
static void web_log(long long count, const char *fmt, ...)
{
	if (count > WEB_LOG_FIRST && count % WEB_LOG_EVERY != 0)
		return;
	va_list ap;
	va_start(ap, fmt);
	fputs("undulate-web: ", stderr);
	vfprintf(stderr, fmt, ap);
	if (count > WEB_LOG_FIRST)
		fprintf(stderr, " (%lld so far)", count);
	fputc('\n', stderr);
	va_end(ap);
}

/* ---- LCM ------------------------------------------------------------------------ */

static struct web_client *web_client_by_id(unsigned id)
{
	for (int i = 0; i < app.nclients; i++)
		if (app.clients[i]->id == id)
			return app.clients[i];
	return NULL;
}

static void web_note(struct web_client *c, long long id, int64_t seq, const char *robot, const char *kind,
                     const char *text)
{
	/* full: the oldest answer goes (the page also shows the robot's last event) */
	if (c->nnotes == WEB_NOTES) {
		memmove(c->notes, c->notes + 1, sizeof c->notes[0] * (WEB_NOTES - 1));
		c->nnotes--;
	}
	struct frame_note *n = &c->notes[c->nnotes++];
	n->id = id;
	n->seq = seq;
	snprintf(n->robot, sizeof n->robot, "%s", robot);
	snprintf(n->kind, sizeof n->kind, "%s", kind);
	snprintf(n->text, sizeof n->text, "%s", text);
}

/* A robot's answer (EVENT channel or local socket): to the browser that sent
 * the command, once (it comes on both). */
static void web_on_answer(void *ctx, const undulate_event_t *e)
{
	(void)ctx;
	unsigned client;
	long long id;
	if (e->seq == 0 || !wcmd_client_of(&app.cmd, e->seq, &client, &id))
		return;
	struct web_client *c = web_client_by_id(client);
	if (c == NULL)
		return;
	for (int i = 0; i < c->nnotes; i++)
		if (c->notes[i].seq == e->seq && strcmp(c->notes[i].robot, e->robot) == 0 &&
		    strcmp(c->notes[i].kind, e->kind) == 0)
			return;
	web_note(c, id, e->seq, e->robot, e->kind, e->text);
}

/* the last SIM.COLLISION's robots, for the pairs' end state */
static void web_collision(const undulate_sim_collision_t *c, double now)
{
	if (c->left >= 0 && c->right >= 0)
		hist_on_collision(&app.hist, &app.model, c->left_robot, c->right_robot, now);
}

static void web_feed_event(const undulate_event_t *e, void *user)
{
	(void)user;
	web_on_answer(NULL, e);
}

static void web_feed_collision(const undulate_sim_collision_t *c, double now, void *user)
{
	(void)user;
	web_collision(c, now);
}

/* every SIM.TRUTH's contacts, summed until the next frame (wcontact.h) */
static void web_feed_truth(const struct top_model *m, double now, void *user)
{
	(void)now;
	(void)user;
	wct_add(&app.hist.contacts, m);
}

/* A message that does not decode is counted (the page shows decode_errors)
 * and said, at most WEB_DECODE_LOG_N times, then once a minute. */
#define WEB_DECODE_LOG_N 5
#define WEB_DECODE_LOG_EVERY_S 60.0
static void web_heard(const char *channel, const uint8_t *data, size_t n)
{
	static const struct top_feed_hooks hooks = { .on_event = web_feed_event, .on_collision = web_feed_collision,
	                                             .on_truth = web_feed_truth };
	static double last_said;
	double now = clock_mono_s();
	char why[160];
	foxsrv_heard(channel, data, n, (uint64_t)clock_wall_us() * 1000u, now);
	if (top_feed(&app.model, channel, data, n, now, &hooks, why, sizeof why) || !why[0])
		return;
	if (app.model.decode_errors <= WEB_DECODE_LOG_N || now - last_said >= WEB_DECODE_LOG_EVERY_S) {
		char ch[64];
		fprintf(stderr, "undulate-web: message on %s skipped: %s (%" PRId64 " so far)\n",
		        text_line(ch, sizeof ch, channel), why, app.model.decode_errors);
		last_said = now;
	}
}

/* the channels only Foxglove clients are served (foxsrv.h) */
static void web_heard_fox(const char *channel, const uint8_t *data, size_t n)
{
	foxsrv_heard(channel, data, n, (uint64_t)clock_wall_us() * 1000u, clock_mono_s());
}

/* LCM's own path, where the URL is not a multicast group (memq://, file://) */
static void web_on_lcm(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
	(void)user;
	web_heard(channel, rbuf->data, rbuf->data_size);
}

static void web_on_lcm_fox(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
	(void)user;
	web_heard_fox(channel, rbuf->data, rbuf->data_size);
}

/* The feeds: read in this loop where the URL is a udpm group (wlcm.h), else
 * through LCM. */
static int web_subscribe(void)
{
	char why[200];
	app.own_rx = wlcm_open(&app.rx, app.o.lcm_url, why, sizeof why);
	for (size_t i = 0; i < top_feed_nchannels; i++)
		if (app.own_rx ? !wlcm_subscribe(&app.rx, top_feed_channels[i], web_heard)
		               : !lcm_subscribe(app.lcm, top_feed_channels[i], web_on_lcm, NULL))
			return -1;
	for (size_t i = 0; i < fox_extra_nchannels; i++)
		if (app.own_rx ? !wlcm_subscribe(&app.rx, fox_extra_channels[i], web_heard_fox)
		               : !lcm_subscribe(app.lcm, fox_extra_channels[i], web_on_lcm_fox, NULL))
			return -1;
	return 0;
}

/* ---- connections: room for one more ------------------------------------------------ */

static struct web_conn *web_conn_of(struct lws *wsi)
{
	for (int i = 0; i < app.nconns; i++)
		if (app.conns[i].wsi == wsi)
			return &app.conns[i];
	return NULL;
}

static void web_conn_set(struct lws *wsi, enum web_conn_state state)
{
	struct web_conn *k = web_conn_of(wsi);
	if (k == NULL || k->state == WEB_CONN_EVICTED)
		return;
	k->state = state;
	if (state == WEB_CONN_WAITING)
		k->since = clock_mono_s();
}

/* The connection to close for a new one: the one waiting longest, else the
 * longest busy one; never a WebSocket. NULL if none. */
static struct web_conn *web_conn_victim(void)
{
	struct web_conn *best = NULL;
	for (int i = 0; i < app.nconns; i++) {
		struct web_conn *k = &app.conns[i];
		if (k->state != WEB_CONN_WAITING && k->state != WEB_CONN_BUSY)
			continue;
		if (best == NULL || (k->state == WEB_CONN_WAITING && best->state == WEB_CONN_BUSY) ||
		    (k->state == best->state && k->since < best->since))
			best = k;
	}
	return best;
}

/* A connection was accepted (its descriptor is in libwebsockets' table):
 * kept, after another made room if the table of live ones is full. */
static int web_conn_add(struct lws *wsi)
{
	if (app.nconns - app.nevicted >= WEB_MAX_CONNECTIONS) {
		struct web_conn *v = web_conn_victim();
		if (v != NULL) {
			v->state = WEB_CONN_EVICTED;
			app.nevicted++;
			app.n.conns_evicted++;
			web_log(app.n.conns_evicted, "%d connections: closed the one that waited longest for a request "
			        "(%.1f s)", WEB_MAX_CONNECTIONS, clock_mono_s() - v->since);
			lws_set_timeout(v->wsi, PENDING_TIMEOUT_USER_OK, LWS_TO_KILL_ASYNC);
		}
	}
	if (app.nconns - app.nevicted >= WEB_MAX_CONNECTIONS || app.nconns >= WEB_FD_LIMIT) {
		app.n.http_refused++;
		web_log(app.n.http_refused, "refused a connection: %d open, none of them can give way",
		        WEB_MAX_CONNECTIONS);
		return 1;
	}
	app.conns[app.nconns++] = (struct web_conn){ .wsi = wsi, .since = clock_mono_s(), .state = WEB_CONN_WAITING };
	return 0;
}

static void web_conn_drop(struct lws *wsi)
{
	struct web_conn *k = web_conn_of(wsi);
	if (k == NULL)
		return;
	app.nevicted -= k->state == WEB_CONN_EVICTED;
	*k = app.conns[--app.nconns];
}

/* ---- HTTP ----------------------------------------------------------------------- */

static const char *web_method(struct lws *wsi)
{
	static const struct { enum lws_token_indexes tok; const char *name; } methods[] = {
		{ WSI_TOKEN_GET_URI, "GET" },         { WSI_TOKEN_POST_URI, "POST" },
		{ WSI_TOKEN_OPTIONS_URI, "OPTIONS" }, { WSI_TOKEN_PUT_URI, "PUT" },
		{ WSI_TOKEN_PATCH_URI, "PATCH" },     { WSI_TOKEN_DELETE_URI, "DELETE" },
		{ WSI_TOKEN_HEAD_URI, "HEAD" },
	};
	for (size_t i = 0; i < sizeof methods / sizeof methods[0]; i++)
		if (lws_hdr_total_length(wsi, methods[i].tok) > 0)
			return methods[i].name;
	return "?";
}

/* An answer went out whole: the connection waits for its next request. */
static int web_http_done(struct lws *wsi)
{
	web_conn_set(wsi, WEB_CONN_WAITING);
	return lws_http_transaction_completed(wsi) ? -1 : 0;
}

static int web_http_status(struct lws *wsi, unsigned code, const char *why)
{
	app.n.http_refused++;
	if (lws_return_http_status(wsi, code, why))
		return -1;
	return web_http_done(wsi);
}

static int web_serve_file(struct lws *wsi, const char *dir, const char *name, const char *mime)
{
	char path[1024];
	if (dir != NULL)
		snprintf(path, sizeof path, "%s/%s", dir, name);
	else
		snprintf(path, sizeof path, "%s", name);
	int n = lws_serve_http_file(wsi, path, mime, "cache-control: no-cache\x0d\x0a", 0);
	if (n < 0)
		return -1;
	return n > 0 ? web_http_done(wsi) : 0;
}

/* A JSON answer: the body written by what (the snapshot, the parameters). */
enum web_json_kind { WEB_JSON_SNAPSHOT, WEB_JSON_PARAMS };

static int web_json(struct lws *wsi, struct web_http *h, enum web_json_kind what)
{
	FILE *f = open_memstream(&h->body, &h->len);
	if (f == NULL)
		return web_http_status(wsi, HTTP_STATUS_INTERNAL_SERVER_ERROR, "out of memory");
	if (what == WEB_JSON_PARAMS)
		param_table_json(f);
	else
		top_json(&app.model, clock_mono_s(), clock_wall_us(), f);
	fclose(f);
	h->off = 0;
	unsigned char hdr[LWS_PRE + 512], *start = hdr + LWS_PRE, *p = start, *end = hdr + sizeof hdr - 1;
	if (lws_add_http_common_headers(wsi, HTTP_STATUS_OK, "application/json", h->len, &p, end) ||
	    lws_add_http_header_by_token(wsi, WSI_TOKEN_HTTP_CACHE_CONTROL, (const unsigned char *)"no-store", 8,
	                                 &p, end) ||
	    lws_finalize_write_http_header(wsi, start, &p, end))
		return -1;
	lws_callback_on_writable(wsi);
	return 0;
}

static int web_http_write(struct lws *wsi, struct web_http *h)
{
	if (h->body == NULL)
		return 0;
	/* a chunk at a time: libwebsockets keeps what the socket did not take */
	enum { CHUNK = 16384 };
	static unsigned char buf[LWS_PRE + CHUNK];
	size_t n = h->len - h->off < CHUNK ? h->len - h->off : CHUNK;
	memcpy(buf + LWS_PRE, h->body + h->off, n);
	h->off += n;
	bool last = h->off == h->len;
	if (lws_write(wsi, buf + LWS_PRE, n, last ? LWS_WRITE_HTTP_FINAL : LWS_WRITE_HTTP) != (int)n)
		return -1;
	if (!last) {
		lws_callback_on_writable(wsi);
		return 0;
	}
	free(h->body);
	h->body = NULL;
	return web_http_done(wsi);
}

/* The request's Host header (empty when missing or longer than cap). */
static void web_host(struct lws *wsi, char *host, size_t cap)
{
	host[0] = '\0';
	int n = lws_hdr_total_length(wsi, WSI_TOKEN_HOST);
	if (n > 0 && n < (int)cap)
		lws_hdr_copy(wsi, host, (int)cap, WSI_TOKEN_HOST);
}

static int web_http(struct lws *wsi, struct web_http *h, const char *uri)
{
	app.n.http_requests++;
	web_conn_set(wsi, WEB_CONN_BUSY);
	const char *method = web_method(wsi);
	char quoted[80], host[256];
	text_sanitize(quoted, sizeof quoted, uri);
	if (app.o.verbose)
		fprintf(stderr, "undulate-web: %s %s\n", method, quoted);
	web_host(wsi, host, sizeof host);
	if (!req_host_ok(&app.o.hosts, host)) {
		char qhost[80];
		web_log(app.n.http_refused + 1, "refused %s %s: Host '%s' does not name this server (a page of another "
		        "site whose name points here: DNS rebinding; --allow-host NAME for a name of this computer)",
		        method, quoted, text_sanitize(qhost, sizeof qhost, host));
		return web_http_status(wsi, HTTP_STATUS_FORBIDDEN, "this Host does not name this server");
	}
	switch (req_route(method, uri)) {
	case REQ_PAGE: return web_serve_file(wsi, app.o.page_dir, "index.html", "text/html");
	case REQ_ASSET_JS: return web_serve_file(wsi, app.o.page_dir, "app.js", "application/javascript");
	case REQ_ASSET_CSS: return web_serve_file(wsi, app.o.page_dir, "style.css", "text/css");
	case REQ_CHARTJS: return web_serve_file(wsi, NULL, app.o.chartjs, "application/javascript");
	case REQ_SNAPSHOT: return web_json(wsi, h, WEB_JSON_SNAPSHOT);
	case REQ_PARAMS: return web_json(wsi, h, WEB_JSON_PARAMS);
	case REQ_BAD_METHOD:
		web_log(app.n.http_refused + 1, "refused %s %s: method not allowed", method, quoted);
		return web_http_status(wsi, HTTP_STATUS_METHOD_NOT_ALLOWED, "method not allowed");
	case REQ_NOT_FOUND:
	default:
		web_log(app.n.http_refused + 1, "refused %s %s: not found", method, quoted);
		return web_http_status(wsi, HTTP_STATUS_NOT_FOUND, "not found");
	}
}

static int web_http_cb(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
	struct web_http *h = user;
	switch (reason) {
	case LWS_CALLBACK_FILTER_NETWORK_CONNECTION:
		/* a new connection: what its client sends is watched from its first byte */
		return wsr_watch((int)(intptr_t)in) ? 0 : 1;
	case LWS_CALLBACK_SERVER_NEW_CLIENT_INSTANTIATED:
		return web_conn_add(wsi);
	case LWS_CALLBACK_WSI_DESTROY:
		web_conn_drop(wsi);
		return 0;
	case LWS_CALLBACK_HTTP_FILE_COMPLETION:
		return web_http_done(wsi);
	case LWS_CALLBACK_HTTP:
		return web_http(wsi, h, in != NULL ? (const char *)in : "");
	case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
		/* a WebSocket that named no protocol, or "http": libwebsockets
		 * would give it to this callback, past every check of "undulate" */
		web_log(++app.n.ws_refused, "refused a WebSocket without the protocol 'undulate' or '" FOX_SUBPROTOCOL "'");
		return 1;
	case LWS_CALLBACK_HTTP_BODY:
		return 0; /* no request has a body worth reading: it was answered already */
	case LWS_CALLBACK_HTTP_WRITEABLE:
		return web_http_write(wsi, h);
	case LWS_CALLBACK_CLOSED_HTTP:
	case LWS_CALLBACK_HTTP_DROP_PROTOCOL:
		if (h != NULL) {
			free(h->body);
			h->body = NULL;
		}
		return 0;
	default:
		return lws_callback_http_dummy(wsi, reason, user, in, len);
	}
}

/* ---- WebSocket -------------------------------------------------------------------- */

/* An origin given with --allow-origin (the Foxglove protocol only). */
static bool web_fox_origin_ok(const char *origin)
{
	for (int i = 0; i < app.o.nfox_origins; i++)
		if (strcmp(origin, app.o.fox_origins[i]) == 0)
			return true;
	return false;
}

/* fox: a Foxglove client, which may also come from an --allow-origin page */
static bool web_ws_allowed(struct lws *wsi, bool fox)
{
	char origin[256] = "", host[256], qo[80], qh[80];
	if (lws_hdr_total_length(wsi, WSI_TOKEN_ORIGIN) >= (int)sizeof origin) {
		web_log(++app.n.ws_refused, "refused a WebSocket: Origin longer than %zu bytes", sizeof origin - 1);
		return false;
	}
	lws_hdr_copy(wsi, origin, sizeof origin, WSI_TOKEN_ORIGIN);
	web_host(wsi, host, sizeof host);
	if (!req_host_ok(&app.o.hosts, host)) {
		web_log(++app.n.ws_refused, "refused a WebSocket for Host '%s': not a name of this server (DNS "
		        "rebinding?)", text_sanitize(qh, sizeof qh, host));
		return false;
	}
	if (!req_origin_ok(origin, host) && !(fox && web_fox_origin_ok(origin))) {
		web_log(++app.n.ws_refused, "refused a WebSocket from origin '%s' (this is http://%s)",
		        text_sanitize(qo, sizeof qo, origin), text_sanitize(qh, sizeof qh, host));
		return false;
	}
	return true;
}

static void web_refuse_msg(struct web_client *c, long long id, const char *why)
{
	app.n.msgs_refused++;
	web_log(app.n.msgs_refused, "browser %u: refused a message: %s", c->id, why);
	web_note(c, id, 0, "", "refused", why);
}

/* The token offered at the handshake (the page's subprotocol "undulate-token.T"). */
static void web_ws_token(struct lws *wsi, struct web_client *c)
{
	char list[256], token[REQ_TOKEN_MAX];
	int n = lws_hdr_total_length(wsi, WSI_TOKEN_PROTOCOL);
	if (app.o.token == NULL || n <= 0 || n >= (int)sizeof list)
		return;
	lws_hdr_copy(wsi, list, sizeof list, WSI_TOKEN_PROTOCOL);
	if (!req_ws_token(list, token, sizeof token))
		return;
	c->authed = req_token_ok(app.o.token, token);
	c->wrong_token = !c->authed;
}

/* Room for it: watchers may not take the places kept for the token's
 * holders. Foxglove clients are watchers (they never command) and count
 * among the browsers. */
static bool web_ws_room(bool authed)
{
	int nfox = (int)foxsrv_counters()->clients;
	if (req_ws_room(app.nclients + nfox, app.nwatchers + nfox, authed, WEB_MAX_CLIENTS, WEB_MAX_WATCHERS))
		return true;
	web_log(++app.n.ws_refused, "refused a WebSocket%s: %d browsers connected (%d of them Foxglove), %d of them "
	        "without the token (at most %d; the rest is kept for the token's holders)",
	        authed ? " with the token" : "", app.nclients + nfox, nfox, app.nwatchers + nfox, WEB_MAX_WATCHERS);
	return false;
}

static void web_ws_open(struct lws *wsi, struct web_client *c)
{
	/* authed and wrong_token were set at the handshake (FILTER_PROTOCOL_CONNECTION), id at ESTABLISHED */
	int sndbuf = WEB_SNDBUF;
	setsockopt(lws_get_socket_fd(wsi), SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
	c->wsi = wsi;
	frame_cursor_init(&c->cur, &app.hist);
	app.clients[app.nclients++] = c;
	app.nwatchers += !c->authed;
	app.n.clients = app.nclients;
	web_note(c, 0, 0, "", "hello", app.o.read_only ? "read-only" : c->authed ? "commands" : "watch");
	if (c->wrong_token)
		web_refuse_msg(c, 0, "wrong token: this page only watches (open the URL undulate-web printed)");
	c->want = true;
	c->want_since = clock_mono_s();
	lws_callback_on_writable(wsi);
}

static void web_ws_close(struct web_client *c)
{
	for (int i = 0; i < app.nclients; i++)
		if (app.clients[i] == c) {
			app.clients[i] = app.clients[--app.nclients];
			app.nwatchers -= !c->authed;
			break;
		}
	app.n.clients = app.nclients;
}

static int web_ws_write(struct lws *wsi, struct web_client *c)
{
	if (!c->want)
		return 0; /* libwebsockets may call again: a frame goes out only when one is due */
	unsigned char *buf = app.frame + LWS_PRE;
	size_t n = frame_write(&app.hist, &app.model, clock_mono_s(), &c->cur, &app.n, c->notes, c->nnotes,
	                       (char *)buf, WEB_FRAME_MAX);
	c->want = false;
	if (n == 0)
		return 0;
	c->nnotes = 0;
	app.n.frames_sent++;
	return lws_write(wsi, buf, n, LWS_WRITE_TEXT) < (int)n ? -1 : 0;
}

static void web_command(struct web_client *c, struct req_msg *m)
{
	char why[256];
	if (app.o.read_only) {
		app.n.commands_refused++;
		return web_refuse_msg(c, m->id, "read-only: undulate-web sends no commands (--read-only)");
	}
	if (!c->authed) {
		app.n.commands_refused++;
		return web_refuse_msg(c, m->id, "commands need the dashboard's token: open the URL undulate-web printed "
		                      "(with #token=...); without it this page only watches");
	}
	if (!app.cmd_ok) {
		app.n.commands_refused++;
		return web_refuse_msg(c, m->id, app.cmd_why);
	}
	int reached = 0;
	int64_t seq = wcmd_send(&app.cmd, &m->cmd, c->id, m->id, &reached, why, sizeof why);
	if (seq == 0) {
		app.n.commands_refused++;
		return web_note(c, m->id, 0, m->robot, "not-sent", why);
	}
	app.n.commands_sent++;
	/* the robot logs this process; this log says which browser it was for */
	char peer[64] = "?", quoted[128];
	lws_get_peer_simple(c->wsi, peer, sizeof peer);
	fprintf(stderr, "undulate-web: browser %u (%s, with the token): command %" PRId64 " '%s' to %s, %d reached\n",
	        c->id, peer, seq, text_sanitize(quoted, sizeof quoted, m->text), m->robot, reached);
	char what[FRAME_NOTE_TEXT];
	snprintf(what, sizeof what, "'%.60s' sent to %d robot%s%s, waiting for the answer", m->text, reached,
	         reached == 1 ? "" : "s", app.cmd.signed_lcm ? " (signed, over LCM)" : "");
	web_note(c, m->id, seq, m->robot, "sent", what);
}

static void web_ws_receive(struct lws *wsi, struct web_client *c, const char *in, size_t len)
{
	bool first = lws_is_first_fragment(wsi), last = lws_is_final_fragment(wsi);
	if (c->dropping || !first || !last || lws_remaining_packet_payload(wsi) > 0) {
		/* longer than REQ_MSG_MAX: libwebsockets hands it over in pieces */
		if (first)
			web_refuse_msg(c, 0, "message longer than 511 bytes");
		c->dropping = !last;
		return;
	}
	static struct req_msg m;
	char why[256];
	int njoints = 0;
	/* the robot's joints as last heard, for the joint index check */
	if (len > 4 && memcmp(in, "cmd ", 4) == 0) {
		char robot[CFG_NAME_MAX] = "";
		sscanf(in, "cmd %*s %47s", robot);
		int r = top_robot_index(&app.model, robot);
		njoints = r >= 0 ? app.model.robots[r].njoints : 0;
	}
	if (!req_msg_parse(in, len, njoints, &m, why, sizeof why)) {
		if (len > 4 && memcmp(in, "cmd ", 4) == 0)
			app.n.commands_refused++;
		return web_refuse_msg(c, m.id, why);
	}
	if (m.kind == REQ_MSG_AUTH) {
		bool ok = app.o.token != NULL && req_token_ok(app.o.token, m.token);
		if (!ok)
			return web_refuse_msg(c, 0, "wrong token: this page only watches");
		app.nwatchers -= !c->authed;
		c->authed = true;
		web_note(c, 0, 0, "", "auth", "token accepted: commands enabled");
		return;
	}
	web_command(c, &m);
}

/* What a client sent breaks RFC 6455 where libwebsockets 4.1 lets it
 * through (wsguard.h): close with 1002 before acting on anything. who and
 * id name it in the log ("browser 3", "Foxglove client 4"). */
static bool web_guard(struct lws *wsi, bool *failed, const char *who, unsigned id, enum wsg_verdict v)
{
	if (*failed)
		return true;
	if (v == WSG_OK)
		return false;
	*failed = true;
	app.n.ws_bad_frames++;
	if (!wsr_interposed())
		web_log(app.n.ws_bad_frames, "cannot see what browsers send (recv() is not this program's): "
		        "every WebSocket is refused");
	else
		web_log(app.n.ws_bad_frames, "%s %u: closed: %s", who, id, wsg_why(v));
	const char *why = wsg_why(v);
	lws_close_reason(wsi, LWS_CLOSE_STATUS_PROTOCOL_ERR, (unsigned char *)(uintptr_t)why, strlen(why));
	return true;
}

static bool web_ws_bad(struct lws *wsi, struct web_client *c, enum wsg_verdict v)
{
	return web_guard(wsi, &c->failed, "browser", c->id, v);
}

/* The protocol is text (JSON out, "cmd ..." in): a binary frame is not ours
 * to guess at (RFC 6455 7.4.1: 1003, a type it cannot accept). */
static bool web_ws_binary(struct lws *wsi, struct web_client *c)
{
	static const char why[] = "the undulate protocol is text only";
	if (!lws_frame_is_binary(wsi))
		return false;
	c->failed = true;
	app.n.ws_bad_frames++;
	web_log(app.n.ws_bad_frames, "browser %u: closed: a binary frame (%s)", c->id, why);
	lws_close_reason(wsi, LWS_CLOSE_STATUS_UNACCEPTABLE_OPCODE, (unsigned char *)(uintptr_t)why, sizeof why - 1);
	return true;
}

static int web_ws_cb(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
	struct web_client *c = user;
	int fd = lws_get_socket_fd(wsi);
	switch (reason) {
	case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
		web_conn_set(wsi, WEB_CONN_BUSY);
		if (!web_ws_allowed(wsi, false))
			return 1;
		web_ws_token(wsi, c);
		return web_ws_room(c->authed) ? 0 : 1;
	case LWS_CALLBACK_ESTABLISHED:
		c->id = ++app.next_client;
		if (web_ws_bad(wsi, c, wsr_upgraded(fd)))
			return -1;
		web_ws_open(wsi, c);
		web_conn_set(wsi, WEB_CONN_WS);
		return 0;
	case LWS_CALLBACK_SERVER_WRITEABLE:
		/* also what came in control frames, which reach no callback */
		if (web_ws_bad(wsi, c, wsr_verdict(fd)))
			return -1;
		return web_ws_write(wsi, c);
	case LWS_CALLBACK_RECEIVE:
		if (web_ws_bad(wsi, c, wsr_verdict(fd)) || web_ws_binary(wsi, c))
			return -1;
		web_ws_receive(wsi, c, in, len);
		return 0;
	case LWS_CALLBACK_CLOSED:
		wsr_forget(fd);
		web_ws_close(c);
		return 0;
	default:
		return 0;
	}
}

/* ---- Foxglove's WebSocket protocol (foxsrv.h), through the same gate ---------------- */

static void web_fox_receive(struct lws *wsi, struct fox_client *c, const char *in, size_t len)
{
	char why[256];
	bool first = lws_is_first_fragment(wsi);
	bool last = lws_is_final_fragment(wsi) && lws_remaining_packet_payload(wsi) == 0;
	foxsrv_receive(c, in, len, lws_frame_is_binary(wsi), first, last, why, sizeof why);
	if (why[0] != '\0')
		web_log(foxsrv_counters()->refused, "Foxglove client %u: refused: %s", c->id, why);
}

static int web_fox_cb(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
	struct fox_client *c = user;
	int fd = lws_get_socket_fd(wsi);
	switch (reason) {
	case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
		web_conn_set(wsi, WEB_CONN_BUSY);
		return web_ws_allowed(wsi, true) && web_ws_room(false) ? 0 : 1;
	case LWS_CALLBACK_ESTABLISHED: {
		unsigned id = ++app.next_client;
		if (web_guard(wsi, &c->failed, "Foxglove client", id, wsr_upgraded(fd)))
			return -1;
		if (!foxsrv_open(c, wsi, id, clock_mono_s())) {
			web_log(++app.n.ws_refused, "refused a Foxglove client: no memory for its queue");
			return -1;
		}
		web_conn_set(wsi, WEB_CONN_WS);
		return 0;
	}
	case LWS_CALLBACK_SERVER_WRITEABLE:
		if (web_guard(wsi, &c->failed, "Foxglove client", c->id, wsr_verdict(fd)))
			return -1;
		return foxsrv_write(c, clock_mono_s());
	case LWS_CALLBACK_RECEIVE:
		if (web_guard(wsi, &c->failed, "Foxglove client", c->id, wsr_verdict(fd)))
			return -1;
		web_fox_receive(wsi, c, in, len);
		return 0;
	case LWS_CALLBACK_CLOSED:
		wsr_forget(fd);
		if (c->queue != NULL)
			foxsrv_close(c);
		return 0;
	default:
		return 0;
	}
}

/* ---- the LCM and command sockets, in the same loop -------------------------------- */

static int web_raw_cb(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len)
{
	(void)user;
	(void)in;
	(void)len;
	if (reason == LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION) {
		web_log(++app.n.ws_refused, "refused a WebSocket asking for the internal protocol 'undulate-raw'");
		return 1;
	}
	if (reason != LWS_CALLBACK_RAW_RX_FILE)
		return 0;
	void *tag = lws_get_opaque_user_data(wsi);
	if (tag == WEB_TAG_LCM) {
		/* what has come, not one message a wakeup: the Foxglove clients'
		 * frames of a burst then go out in one send (foxsrv_write) */
		if (app.own_rx)
			wlcm_drain(&app.rx, WEB_LCM_DRAIN / WLCM_BATCH);
		else
			for (int i = 0; i < WEB_LCM_DRAIN && lcm_handle_timeout(app.lcm, 0) > 0; i++)
				;
	}
	else if (tag == WEB_TAG_CMD)
		wcmd_read_local(&app.cmd, web_on_answer, NULL);
	return 0;
}

/* libwebsockets closes what it adopted: give it a copy of the descriptor. */
static int web_adopt(int fd, void *tag)
{
	lws_sock_file_fd_type d;
	d.filefd = dup(fd);
	if (d.filefd < 0)
		return -1;
	struct lws *wsi = lws_adopt_descriptor_vhost(app.vh, LWS_ADOPT_RAW_FILE_DESC, d, "undulate-raw", NULL);
	if (wsi == NULL)
		return -1;
	lws_set_opaque_user_data(wsi, tag);
	return 0;
}

/* ---- the clock: samples at HIST_HZ, a frame to each browser every WEB_FRAME_EVERY --- */

static void web_frames_due(double now)
{
	for (int i = 0; i < app.nclients; i++) {
		struct web_client *c = app.clients[i];
		if (c->want) {
			/* its socket has not taken the last frame: skip this one, it gets
			 * everything new in the next (frame.h) */
			app.n.frames_skipped++;
			if (now - c->want_since > WEB_STALL_S) {
				app.n.clients_stalled++;
				web_log(app.n.clients_stalled, "browser %u took no frame for %.0f s: closed", c->id,
				        WEB_STALL_S);
				lws_set_timeout(c->wsi, PENDING_TIMEOUT_USER_OK, LWS_TO_KILL_ASYNC);
			}
			continue;
		}
		c->want = true;
		c->want_since = now;
		lws_callback_on_writable(c->wsi);
	}
}

/* What SIM.TRUTH carried that the world view could not take (the page shows
 * the counts): said when it grows, the first few times, then rarely. */
static void web_world_refusals(void)
{
	static int64_t said, times;
	const struct top_world *w = &app.model.world;
	int64_t n = w->bad_index + w->bad_number + w->overflow + app.hist.contacts.overflow;
	if (n == said)
		return;
	said = n;
	web_log(++times, "SIM.TRUTH: %" PRId64 " links, walls or contacts refused so far (%" PRId64 " naming a "
	        "body, link or wall the message does not hold, %" PRId64 " with a number no arena has, %" PRId64
	        " beyond what is kept)", n, w->bad_index, w->bad_number, w->overflow + app.hist.contacts.overflow);
}

static void web_tick(lws_sorted_usec_list_t *sul)
{
	double now = clock_mono_s();
	hist_sample(&app.hist, &app.model, now);
	if (++app.ticks % WEB_FRAME_EVERY == 0) {
		/* the contacts since the last frame become its marks */
		hist_close_contacts(&app.hist, now);
		web_world_refusals();
		web_frames_due(now);
		foxsrv_tick(now);
	}
	lws_sul_schedule(app.ctx, 0, sul, web_tick, LWS_US_PER_SEC / HIST_HZ);
}

/* ---- start and run ------------------------------------------------------------------ */

static const struct lws_protocols web_protocols[] = {
	{ "http", web_http_cb, sizeof(struct web_http), 0, 0, NULL, 0 },
	/* tx_packet_size: without it libwebsockets 4.1 sends at most rx_buffer_size
	 * (+ LWS_PRE + 4) bytes a send() and copies the rest aside, a poll round
	 * each: a 10 kB frame took twenty sends of 532 bytes */
	{ "undulate", web_ws_cb, sizeof(struct web_client), REQ_MSG_MAX, 0, NULL, WEB_TX_PACKET },
	{ FOX_SUBPROTOCOL, web_fox_cb, sizeof(struct fox_client), FOXSRV_OP_MAX, 0, NULL, WEB_TX_PACKET },
	{ "undulate-raw", web_raw_cb, 0, 0, 0, NULL, 0 },
	{ NULL, NULL, 0, 0, 0, NULL, 0 },
};

static int web_start(void)
{
	struct lws_context_creation_info info;
	memset(&info, 0, sizeof info);
	info.port = app.o.port;
	info.iface = app.o.addr;
	info.protocols = web_protocols;
	info.vhost_name = "undulate-web";
	info.options = LWS_SERVER_OPTION_VALIDATE_UTF8 | LWS_SERVER_OPTION_EXPLICIT_VHOSTS;
	if (strchr(app.o.addr, ':') == NULL)
		info.options |= LWS_SERVER_OPTION_DISABLE_IPV6;
	info.max_http_header_data = WEB_HEADER_MAX;
	/* a header buffer for every connection that may be waiting for its request */
	info.max_http_header_pool = WEB_MAX_CONNECTIONS;
	info.fd_limit_per_thread = WEB_FD_LIMIT;
	info.timeout_secs = WEB_HTTP_TIMEOUT_S;
	info.timeout_secs_ah_idle = WEB_HTTP_TIMEOUT_S;
	info.keepalive_timeout = 5;
	app.ctx = lws_create_context(&info);
	if (app.ctx == NULL)
		return -1;
	app.vh = lws_create_vhost(app.ctx, &info);
	if (app.vh == NULL)
		return -1;
	return 0;
}

/* No --token-file, commands on: a token of our own, in a file only this
 * user reads (wtok.h), and the URL that carries it. Without a file (the run
 * directory not ours) the printed URL is the only copy. */
static int web_make_token(int port)
{
	char dir[CSOCK_PATH_MAX], why[256];
	if (!wtok_make(app.token)) {
		fprintf(stderr, "undulate-web: cannot make a token (libsodium has no entropy source)\n");
		return -1;
	}
	app.o.token = app.token;
	if (!csock_daemon_dir(dir, sizeof dir, "", why, sizeof why) ||
	    !wtok_write(dir, port, app.token, app.token_path, sizeof app.token_path, why, sizeof why)) {
		app.token_path[0] = '\0';
		fprintf(stderr, "undulate-web: the token is not written to a file: %s\n", why);
	}
	bool v6 = strchr(app.o.addr, ':') != NULL;
	printf("undulate-web: open http://%s%s%s:%d/#token=%s to command (without the token the page only watches)%s%s\n",
	       v6 ? "[" : "", app.o.addr, v6 ? "]" : "", port, app.token, app.token_path[0] ? "; the token is in " : "",
	       app.token_path);
	return 0;
}

int web_run(const struct web_opts *o)
{
	app.o = *o;
	top_model_init(&app.model);
	hist_init(&app.hist, clock_mono_s());
	app.frame = malloc(LWS_PRE + WEB_FRAME_MAX);
	app.lcm = lcm_create(o->lcm_url);
	if (app.frame == NULL || !foxsrv_init() || app.lcm == NULL || web_subscribe() != 0) {
		fprintf(stderr, "undulate-web: cannot start LCM on %s\n", o->lcm_url ? o->lcm_url : "the default URL");
		return 1;
	}
	if (!o->read_only) {
		app.cmd_ok = wcmd_init(&app.cmd, app.lcm, o->lcm_url, o->key_file, app.cmd_why, sizeof app.cmd_why);
		if (!app.cmd_ok && o->key_file != NULL) {
			fprintf(stderr, "undulate-web: --key: %s\n", app.cmd_why);
			return 1;
		}
		if (!app.cmd_ok)
			fprintf(stderr, "undulate-web: commands disabled: %s\n", app.cmd_why);
	} else {
		app.cmd.fd = -1;
	}
	lws_set_log_level(LLL_ERR, NULL);
	if (web_start() != 0) {
		fprintf(stderr, "undulate-web: cannot listen on %s:%d (in use, or not an address of this computer)\n",
		        o->addr, o->port);
		return 1;
	}
	if (web_adopt(app.own_rx ? app.rx.fd : lcm_get_fileno(app.lcm), WEB_TAG_LCM) != 0 ||
	    (app.cmd.fd >= 0 && web_adopt(app.cmd.fd, WEB_TAG_CMD) != 0)) {
		fprintf(stderr, "undulate-web: cannot watch the LCM socket\n");
		return 1;
	}
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sa.sa_handler = web_on_signal; /* no SA_RESTART: the loop's poll returns */
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
	signal(SIGPIPE, SIG_IGN);
	lws_sul_schedule(app.ctx, 0, &app.sul, web_tick, LWS_US_PER_SEC / HIST_HZ);
	int port = lws_get_vhost_listen_port(app.vh);
	bool v6 = strchr(o->addr, ':') != NULL;
	printf("undulate-web: listening on http://%s%s%s:%d/ (LCM %s%s)\n", v6 ? "[" : "", o->addr, v6 ? "]" : "",
	       port, o->lcm_url ? o->lcm_url : "default URL", o->read_only ? ", read-only" : ", commands need the token");
	if (o->make_token && web_make_token(port) != 0)
		return 1;
	fflush(stdout);
	while (!web_stop && lws_service(app.ctx, 0) >= 0)
		;
	fprintf(stderr, "undulate-web: exit: %lld HTTP requests (%lld refused), %lld WebSocket refused, %lld messages "
	        "refused, %lld commands sent (%lld refused), %lld frames sent, %lld skipped, %lld browsers stalled, "
	        "%lld closed for their frames, %lld connections closed to make room\n",
	        app.n.http_requests, app.n.http_refused, app.n.ws_refused, app.n.msgs_refused, app.n.commands_sent,
	        app.n.commands_refused, app.n.frames_sent, app.n.frames_skipped, app.n.clients_stalled,
	        app.n.ws_bad_frames, app.n.conns_evicted);
	const struct foxsrv_counters *fx = foxsrv_counters();
	fprintf(stderr, "undulate-web: exit: Foxglove: %lld messages sent (in %lld sends), %lld dropped for clients "
	        "behind, %lld Foxglove messages refused, %lld channels not advertised, %lld messages too large, %lld "
	        "clients closed for taking nothing\n", fx->sent, fx->batches, fx->dropped, fx->refused,
	        fx->channels_refused, fx->too_large, fx->stalled);
	if (app.own_rx)
		fprintf(stderr, "undulate-web: exit: LCM group read in the loop: %lld datagrams, %lld messages taken, "
		        "%lld not LCM small messages (fragments included), %lld over %d bytes\n", app.rx.n.datagrams,
		        app.rx.n.messages, app.rx.n.not_lcm, app.rx.n.truncated, WLCM_DGRAM_MAX);
	lws_context_destroy(app.ctx);
	wlcm_close(&app.rx);
	foxsrv_fini();
	if (app.token_path[0] != '\0')
		unlink(app.token_path);
	sodium_memzero(app.token, sizeof app.token);
	wcmd_close(&app.cmd);
	lcm_destroy(app.lcm);
	free(app.frame);
	return 0;
}
