/* req.h — what undulate-web accepts from a browser, decided before anything
 * is done with it: which HTTP requests are served (method and path), and
 * whether a command message from the page is well-formed, allowed and valid.
 * Pure: no I/O.
 *
 * Commands are validated by the daemon's own code (daemon/command.h):
 * cmd_parse_text reads the text as `undulated --command` does, cmd_check
 * validates it against a robot configured with the defaults and the robot's
 * joint count — kind, mode, parameter name, commandable or not, joint index,
 * range, natural frequency. The robot validates it again against its own
 * configuration and answers; this check only keeps what it would refuse for
 * any robot off the command path. */
#ifndef UNDULATE_WEB_REQ_H
#define UNDULATE_WEB_REQ_H

#include <stdbool.h>
#include <stddef.h>

#include "daemon/command.h"

enum req_route {
	REQ_PAGE,          /* GET/HEAD / or /index.html */
	REQ_ASSET_JS,      /* GET/HEAD /app.js */
	REQ_ASSET_CSS,     /* GET/HEAD /style.css */
	REQ_CHARTJS,       /* GET/HEAD /chart.js: Debian's libjs-chart.js */
	REQ_SNAPSHOT,      /* GET /api/snapshot */
	REQ_PARAMS,        /* GET /api/params: the commandable parameters (common/params.h) */
	REQ_NOT_FOUND,     /* 404 */
	REQ_BAD_METHOD,    /* 405: a path we serve, another method */
};

/* method: "GET", "HEAD", "POST", ...; path: the URI, "?query" allowed. */
enum req_route req_route(const char *method, const char *path);

/* Longest message a browser may send on the WebSocket (bytes); longer ones
 * are refused and counted. A command is under 100 bytes. */
#define REQ_MSG_MAX 512
/* A token: 8 to 64 of [A-Za-z0-9-_.~]. The page offers it as a WebSocket
 * subprotocol, and libwebsockets 4.1 refuses a Sec-WebSocket-Protocol list
 * longer than 127 bytes (its copy in lws_process_ws_upgrade). */
#define REQ_TOKEN_MAX 65
#define REQ_TOKEN_CHARS "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_.~"
#define REQ_TOKEN_PROTOCOL "undulate-token." /* the subprotocol that carries it: "undulate-token.TOKEN" */

/* A message from the page, one of
 *   "auth TOKEN"               the token (kept for the connection), for a client
 *                              that did not offer it at the handshake
 *   "cmd ID ROBOT TEXT"        ID: the page's number for it (echoed), 1..15 digits;
 *                              ROBOT: a robot name or "*" (every robot);
 *                              TEXT: as `undulated --command` takes it */
enum req_msg_kind { REQ_MSG_AUTH, REQ_MSG_CMD };

struct req_msg {
	enum req_msg_kind kind;
	long long id;
	char robot[CFG_NAME_MAX];
	char token[REQ_TOKEN_MAX];
	char text[REQ_MSG_MAX];
	struct cmd_request cmd;        /* REQ_MSG_CMD, validated; its strings point into this struct */
	char param[CMD_STR_MAX];
};

/* Parses and validates one message (len bytes, not NUL-terminated). njoints:
 * the robot's joints as last heard (0 unknown: 2, ours). False with *why. */
bool req_msg_parse(const char *data, size_t len, int njoints, struct req_msg *m, char *why, size_t cap);

/* Constant-time comparison of a given token with the expected secret (both
 * hashed first, so neither the content nor the length leaks through timing). */
bool req_token_ok(const char *expected, const char *given);

/* A WebSocket upgrade from a browser carries Origin; a page from another
 * site (cross-site WebSocket hijacking) has an Origin that is not this
 * server. Allowed: no Origin (not a browser), or "http://" + host exactly
 * (and host must pass req_host_ok). */
bool req_origin_ok(const char *origin, const char *host);

/* The names that reach this server. DNS rebinding: a page of evil.example,
 * whose name the attacker then points at 127.0.0.1, is same-origin with
 * whatever answers there, and its requests carry Host: evil.example. So a
 * request's Host must name this server:
 *  - "localhost", or an address literal that is loopback (a tunnel such as
 *    ssh -L ends there) or the listening address;
 *  - with a wildcard listening address (0.0.0.0, ::), any address literal:
 *    a browser sends an address only when it connected to that address, and
 *    a rebinding attack always carries a name;
 *  - a name given (--allow-host; this computer's name when it listens
 *    beyond loopback), case-insensitively.
 * The port is not compared (a tunnel may change it; the name is what an
 * attacker controls), but must be digits. Pure: the literals are parsed,
 * nothing is resolved. */
#define REQ_HOSTS_MAX 8
struct req_hosts {
	const char *listen;                     /* the listening address, as given */
	const char *names[REQ_HOSTS_MAX];
	int nnames;
};
bool req_host_ok(const struct req_hosts *h, const char *host);

/* The token in a Sec-WebSocket-Protocol list ("undulate, undulate-token.T"):
 * true with T in out (cap >= REQ_TOKEN_MAX) if one is there and well-formed. */
bool req_ws_token(const char *protocols, char *out, size_t cap);

/* Whether a WebSocket may open: browsers without the token ("watchers") may
 * take max_watchers of the max_clients places; the rest is kept for the
 * token's holders, so token-less connections cannot lock the operator out. */
bool req_ws_room(int clients, int watchers, bool token, int max_clients, int max_watchers);

#endif
