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
	REQ_NOT_FOUND,     /* 404 */
	REQ_BAD_METHOD,    /* 405: a path we serve, another method */
};

/* method: "GET", "HEAD", "POST", ...; path: the URI, "?query" allowed. */
enum req_route req_route(const char *method, const char *path);

/* Longest message a browser may send on the WebSocket (bytes); longer ones
 * are refused and counted. A command is under 100 bytes. */
#define REQ_MSG_MAX 512
#define REQ_TOKEN_MAX 128

/* A message from the page, one of
 *   "auth TOKEN"               the secret of --token-file (kept for the connection)
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
 * server. Allowed: no Origin (not a browser), or "http://" + host exactly. */
bool req_origin_ok(const char *origin, const char *host);

#endif
