/* wcmd.h — undulate-web's command path: exactly the paths undulate-top and
 * `undulated --command` use. Without a key, the robots' local command sockets
 * on this computer (common/csock.h: the socket's permissions decide who may
 * command, and the robot sees this process's uid and pid); with --key FILE,
 * signed with the shared key (common/auth.h) and published on "<robot>.CMD"
 * or "UNDULATE.CMD" for robots configured with commands = network. The robot
 * validates and answers with an event_t (command-accepted / -rejected) that
 * echoes the sequence number; wcmd remembers which browser sent which seq so
 * the answer is shown to it. */
#ifndef UNDULATE_WEB_WCMD_H
#define UNDULATE_WEB_WCMD_H

#include <lcm/lcm.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "auth.h"
#include "daemon/command.h"
#include "undulate_event_t.h"

#define WCMD_PENDING 128    /* commands whose answers are still routed to their browser */
#define WCMD_MAX_SOCKETS 64 /* robots one command reaches on this computer */

struct wcmd_sent {
	int64_t seq;
	unsigned client;      /* the browser's connection number */
	long long id;         /* the page's number for the command */
};

struct wcmd {
	lcm_t *lcm;
	const char *url;
	int fd;               /* our end of the local command sockets; -1 with a key */
	bool signed_lcm;
	struct auth_key key;
	char source[AUTH_SOURCE_MAX];
	int64_t next_seq;
	struct wcmd_sent sent[WCMD_PENDING];
	unsigned nsent;
	int64_t commands, robots_reached, refused_send;
};

/* key_file NULL: local sockets. False with *why (a key that cannot be loaded,
 * no local socket). */
bool wcmd_init(struct wcmd *w, lcm_t *lcm, const char *url, const char *key_file, char *why, size_t cap);
void wcmd_close(struct wcmd *w);
/* Sends r (validated, robot and text set) for browser `client`. Returns the
 * seq it carries (> 0) and *reached (sockets it went to; 1 for a signed
 * message), or 0 with *why. */
int64_t wcmd_send(struct wcmd *w, struct cmd_request *r, unsigned client, long long id, int *reached, char *why,
                  size_t cap);
/* The browser that sent seq; false if none (another program's command). */
bool wcmd_client_of(const struct wcmd *w, int64_t seq, unsigned *client, long long *id);
/* Reads the answers waiting on the local socket; each decoded event to fn. */
void wcmd_read_local(struct wcmd *w, void (*fn)(void *ctx, const undulate_event_t *e), void *ctx);

#endif
