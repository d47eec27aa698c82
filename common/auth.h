/*
 * auth.h — authenticated commands: a shared key, an HMAC-SHA256 tag over the
 * encoded message (libsodium), and a guard against replay.
 *
 * LCM has no sender address worth trusting and its udpm socket listens on
 * every interface, so a command that arrives over the network proves where it
 * came from only by its tag: HMAC-SHA256 under a 32-byte key that only the
 * robot and its operators hold. The tag covers the whole message before it
 * (fingerprint, time, sequence number, source, target, and what to do), so
 * nothing in it can be changed. A recorded command sent again is refused:
 * the sender's time must be within a window of the robot's clock, and per
 * source (time, sequence number) must grow.
 */
#ifndef UNDULATE_COMMON_AUTH_H
#define UNDULATE_COMMON_AUTH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#define AUTH_KEY_BYTES 32
#define AUTH_MAC_BYTES 32
/* A key file: the key as 64 hex digits (surrounding white space allowed). */
#define AUTH_KEY_FILE_MAX 256

struct auth_key {
	uint8_t bytes[AUTH_KEY_BYTES];
};

/* 64 hex digits -> key. False with *why otherwise. */
bool auth_key_parse(struct auth_key *k, const char *text, char *why, size_t cap);
/* Reads a key file. It must be a regular file (symlinks are not followed),
 * owned by this user or root, and — when `private_only` — readable by its
 * owner only (mode without group/other bits): a key others can read is no
 * key. Never blocks on a FIFO or device. */
bool auth_key_load(struct auth_key *k, const char *path, bool private_only, char *why, size_t cap);
/* The same checks for a program that will run as `owner`: the file owned by
 * `owner` or root (root checking a service user's configuration). */
bool auth_key_load_as(struct auth_key *k, const char *path, bool private_only, uid_t owner, char *why,
                      size_t cap);
/* Creates a new random key file (mode 0600, refuses to overwrite). */
bool auth_key_generate(const char *path, char *why, size_t cap);

void auth_mac(const struct auth_key *k, const void *data, size_t n, uint8_t mac[AUTH_MAC_BYTES]);
/* Constant-time comparison. */
bool auth_mac_ok(const struct auth_key *k, const void *data, size_t n, const uint8_t mac[AUTH_MAC_BYTES]);

/* ---- replay ------------------------------------------------------------------------------ */
/* Sources remembered. When a new source finds the table full, the one heard
 * from longest ago is forgotten and the floor rises to its last time: a
 * recording of anything it ever sent is then too old. */
#define AUTH_SOURCES 32
#define AUTH_SOURCE_MAX 48

struct auth_seen {
	char source[AUTH_SOURCE_MAX];
	int64_t utime, seq;
};

struct auth_replay {
	int64_t window_us;      /* |sender time - our time| must be below this */
	int64_t floor_us;       /* sender times at or before this are refused */
	size_t n;
	struct auth_seen seen[AUTH_SOURCES];
};

enum auth_fresh {
	AUTH_FRESH,
	AUTH_TOO_OLD,       /* outside the window, or before the floor (sent before we started) */
	AUTH_TOO_NEW,       /* ahead of our clock by more than the window */
	AUTH_REPLAYED,      /* this source already sent (time, seq) or later */
};

/* now_us: wall-clock µs. Commands signed before this instant are refused,
 * so a recording made before a restart cannot be played after it. */
void auth_replay_init(struct auth_replay *g, int64_t window_us, int64_t now_us);
enum auth_fresh auth_replay_check(const struct auth_replay *g, const char *source, int64_t utime, int64_t seq,
                                  int64_t now_us);
/* Remember an accepted command (only after its tag was checked). */
void auth_replay_accept(struct auth_replay *g, const char *source, int64_t utime, int64_t seq);
const char *auth_fresh_text(enum auth_fresh f);

#endif
