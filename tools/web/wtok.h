/* wtok.h — the dashboard's token: the authority to command through it.
 *
 * undulate-web forwards a command with its own identity (the robots' command
 * sockets see its uid; a signed one carries its key), so whoever may command
 * through it acts as the user who started it. That must be that user, or
 * someone they gave the token to: a page on the same computer is reachable by
 * every local user (loopback TCP has no permissions), and the robots' sockets
 * (mode 0660) refuse most of them. So commands always need a token: given
 * (--token-file FILE, the first line of a file only its owner may read), or
 * made at start from libsodium's random bytes and written to
 * RUN_DIR/undulate-web-PORT.token, mode 0600, created without following a
 * link, removed at exit; the URL printed at start carries it in its fragment
 * (#token=..., never sent in a request line or logged by a server). */
#ifndef UNDULATE_WEB_WTOK_H
#define UNDULATE_WEB_WTOK_H

#include <stdbool.h>
#include <stddef.h>

#include "req.h"

#define WTOK_RANDOM_BYTES 24       /* 192 bits; 32 characters in base64url */

/* The first line of path: a regular file, not readable or writable by group
 * or others, 8 to REQ_TOKEN_MAX - 1 characters of REQ_TOKEN_CHARS. False
 * with *why (what to do about it). */
bool wtok_read(const char *path, char out[REQ_TOKEN_MAX], char *why, size_t why_cap);

/* A new random token. False only when libsodium has no entropy source. */
bool wtok_make(char out[REQ_TOKEN_MAX]);

/* Writes token to dir/undulate-web-PORT.token (mode 0600, O_EXCL|O_NOFOLLOW:
 * whatever was at that path, a file of an earlier run or a planted link, is
 * removed first and never followed). Its path in path_out. False with *why. */
bool wtok_write(const char *dir, int port, const char *token, char *path_out, size_t path_cap, char *why,
                size_t why_cap);

#endif
