/* req.c — see req.h. */
#include "req.h"

#include <arpa/inet.h>
#include <sodium.h>
#include <strings.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "daemon/config.h"
#include "text.h"

static bool req_path_is(const char *path, const char *want)
{
	size_t n = strcspn(path, "?");
	return strlen(want) == n && strncmp(path, want, n) == 0;
}

enum req_route req_route(const char *method, const char *path)
{
	static const struct { const char *path; enum req_route route; } assets[] = {
		{ "/", REQ_PAGE }, { "/index.html", REQ_PAGE }, { "/app.js", REQ_ASSET_JS },
		{ "/style.css", REQ_ASSET_CSS }, { "/chart.js", REQ_CHARTJS },
	};
	bool get = strcmp(method, "GET") == 0, head = strcmp(method, "HEAD") == 0;
	if (req_path_is(path, "/api/snapshot"))
		return get ? REQ_SNAPSHOT : REQ_BAD_METHOD;
	if (req_path_is(path, "/api/params"))
		return get ? REQ_PARAMS : REQ_BAD_METHOD;
	for (size_t i = 0; i < sizeof assets / sizeof assets[0]; i++)
		if (req_path_is(path, assets[i].path))
			return get || head ? assets[i].route : REQ_BAD_METHOD;
	return REQ_NOT_FOUND;
}

/* A robot's name (the monitors' rule, common/text.h), or "*": every robot. */
static bool req_name_ok(const char *s)
{
	return strcmp(s, "*") == 0 || text_is_name(s, CFG_NAME_MAX - 1);
}

/* The next space-separated word of *p into out (cap); false if none or too long. */
static bool req_word(const char **p, char *out, size_t cap)
{
	while (**p == ' ')
		(*p)++;
	size_t n = strcspn(*p, " ");
	if (n == 0 || n >= cap)
		return false;
	memcpy(out, *p, n);
	out[n] = '\0';
	*p += n;
	return true;
}

static bool req_fail(char *why, size_t cap, const char *text)
{
	snprintf(why, cap, "%s", text);
	return false;
}

static bool req_cmd_validate(struct req_msg *m, int njoints, char *why, size_t cap)
{
	char inner[200];
	memset(&m->cmd, 0, sizeof m->cmd);
	if (!cmd_parse_text(m->text, &m->cmd, m->param, sizeof m->param, inner, sizeof inner)) {
		snprintf(why, cap, "%s", inner);
		return false;
	}
	m->cmd.robot = m->robot;
	m->cmd.param = m->param;
	/* the daemon's defaults for a robot of this many joints */
	struct cfg c;
	struct cfg_errors e;
	cfg_defaults(&c);
	memset(&e, 0, sizeof e);
	static const char *const ids[] = { "robot.ids=1", "robot.ids=1,2", "robot.ids=1,2,3", "robot.ids=1,2,3,4" };
	int nj = njoints >= 1 && njoints <= 4 && njoints <= (int)CFG_MAX_JOINTS ? njoints : 2;
	/* a port only because a configuration needs one; nothing is opened */
	if (!cfg_override(&c, ids[nj - 1], &e) || !cfg_override(&c, "robot.port=/dev/null", &e) ||
	    !cfg_finish(&c, &e))
		return req_fail(why, cap, "internal: the default configuration does not validate");
	if (strcmp(m->robot, "*") != 0)
		snprintf(c.name, sizeof c.name, "%s", m->robot);
	if (cmd_check(&m->cmd, &c, true, inner, sizeof inner) != CMD_ACCEPT) {
		snprintf(why, cap, "%s", inner);
		return false;
	}
	return true;
}

bool req_msg_parse(const char *data, size_t len, int njoints, struct req_msg *m, char *why, size_t cap)
{
	memset(m, 0, sizeof *m);
	if (len == 0 || len >= REQ_MSG_MAX)
		return req_fail(why, cap, "message empty or longer than 511 bytes");
	char buf[REQ_MSG_MAX];
	for (size_t i = 0; i < len; i++) {
		if (data[i] < 0x20 || data[i] > 0x7e)
			return req_fail(why, cap, "message has a byte that is not printable ASCII");
		buf[i] = data[i];
	}
	buf[len] = '\0';
	const char *p = buf;
	char word[16];
	if (!req_word(&p, word, sizeof word))
		return req_fail(why, cap, "message has no kind (auth, cmd)");
	if (strcmp(word, "auth") == 0) {
		m->kind = REQ_MSG_AUTH;
		if (!req_word(&p, m->token, sizeof m->token) || *p != '\0')
			return req_fail(why, cap, "auth: one token of at most 64 characters");
		return true;
	}
	if (strcmp(word, "cmd") != 0)
		return req_fail(why, cap, "unknown message kind (auth, cmd)");
	m->kind = REQ_MSG_CMD;
	char id[16];
	char *end;
	if (!req_word(&p, id, sizeof id) || strspn(id, "0123456789") != strlen(id) ||
	    (m->id = strtoll(id, &end, 10)) <= 0)
		return req_fail(why, cap, "cmd: ID must be a number of 1 to 15 digits");
	if (!req_word(&p, m->robot, sizeof m->robot) || !req_name_ok(m->robot))
		return req_fail(why, cap, "cmd: ROBOT must be a robot name (letters, digits, _ -) or *");
	while (*p == ' ')
		p++;
	if (*p == '\0')
		return req_fail(why, cap, "cmd: no command text");
	snprintf(m->text, sizeof m->text, "%s", p);
	return req_cmd_validate(m, njoints, why, cap);
}

bool req_token_ok(const char *expected, const char *given)
{
	unsigned char a[crypto_generichash_BYTES], b[crypto_generichash_BYTES];
	crypto_generichash(a, sizeof a, (const unsigned char *)expected, strlen(expected), NULL, 0);
	crypto_generichash(b, sizeof b, (const unsigned char *)given, strlen(given), NULL, 0);
	return expected[0] != '\0' && sodium_memcmp(a, b, sizeof a) == 0;
}

bool req_origin_ok(const char *origin, const char *host)
{
	if (origin == NULL || origin[0] == '\0')
		return true;
	static const char scheme[] = "http://";
	return host != NULL && host[0] != '\0' && strncmp(origin, scheme, sizeof scheme - 1) == 0 &&
	       strcmp(origin + sizeof scheme - 1, host) == 0;
}

/* host without its port into name (cap); false if the syntax is wrong. */
static bool req_host_name(const char *host, char *name, size_t cap, bool *bracketed)
{
	const char *end, *port;
	*bracketed = host[0] == '[';
	if (*bracketed) {
		end = strchr(host, ']');
		if (end == NULL)
			return false;
		host++;
		port = end + 1;
	} else {
		end = host + strcspn(host, ":");
		port = end;
	}
	size_t n = (size_t)(end - host);
	if (n == 0 || n >= cap)
		return false;
	if (*port == ':') {
		port++;
		size_t digits = strspn(port, "0123456789");
		if (digits == 0 || digits > 5 || port[digits] != '\0')
			return false;
	} else if (*port != '\0') {
		return false;
	}
	memcpy(name, host, n);
	name[n] = '\0';
	return true;
}

/* An address literal: its family and bytes; 0 if name is not one. */
static int req_addr(const char *name, unsigned char addr[16])
{
	if (inet_pton(AF_INET, name, addr) == 1)
		return AF_INET;
	if (inet_pton(AF_INET6, name, addr) == 1)
		return AF_INET6;
	return 0;
}

static bool req_addr_loopback(int family, const unsigned char *a)
{
	static const unsigned char v6_loopback[16] = { [15] = 1 };
	return family == AF_INET ? a[0] == 127 : memcmp(a, v6_loopback, 16) == 0;
}

static bool req_addr_wildcard(int family, const unsigned char *a)
{
	static const unsigned char zero[16];
	return memcmp(a, zero, family == AF_INET ? 4 : 16) == 0;
}

bool req_host_ok(const struct req_hosts *h, const char *host)
{
	char name[256];
	bool bracketed;
	if (host == NULL || !req_host_name(host, name, sizeof name, &bracketed))
		return false;
	unsigned char addr[16], listen[16];
	int family = req_addr(name, addr);
	/* [..] holds an IPv6 literal and nothing else; a bare name holds no ':' */
	if (bracketed != (family == AF_INET6))
		return false;
	if (family == 0) {
		if (strcasecmp(name, "localhost") == 0)
			return true;
		for (int i = 0; i < h->nnames; i++)
			if (h->names[i] != NULL && strcasecmp(name, h->names[i]) == 0)
				return true;
		return false;
	}
	if (req_addr_loopback(family, addr))
		return true;
	int lfamily = h->listen != NULL ? req_addr(h->listen, listen) : 0;
	if (lfamily == 0)
		return false;
	if (req_addr_wildcard(lfamily, listen))
		return true;
	return lfamily == family && memcmp(addr, listen, family == AF_INET ? 4 : 16) == 0;
}

bool req_ws_token(const char *protocols, char *out, size_t cap)
{
	static const char prefix[] = REQ_TOKEN_PROTOCOL;
	const char *p = protocols;
	while (p != NULL && *p != '\0') {
		p += strspn(p, " \t,");
		size_t n = strcspn(p, " \t,");
		if (n > sizeof prefix - 1 && strncmp(p, prefix, sizeof prefix - 1) == 0) {
			const char *t = p + sizeof prefix - 1;
			size_t tn = n - (sizeof prefix - 1);
			if (tn >= cap || tn >= REQ_TOKEN_MAX || strspn(t, REQ_TOKEN_CHARS) < tn)
				return false;
			memcpy(out, t, tn);
			out[tn] = '\0';
			return true;
		}
		p += n;
	}
	return false;
}

bool req_ws_room(int clients, int watchers, bool token, int max_clients, int max_watchers)
{
	if (clients >= max_clients)
		return false;
	return token || watchers < max_watchers;
}
