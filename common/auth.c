/* auth.c — see auth.h. */
#include "auth.h"

#include <errno.h>
#include <fcntl.h>
#include <sodium.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static bool auth_ready(void)
{
	/* idempotent and thread-safe; -1 only when the system has no entropy source */
	return sodium_init() >= 0;
}

static int hexval(char c)
{
	if (c >= '0' && c <= '9')
		return c - '0';
	if (c >= 'a' && c <= 'f')
		return c - 'a' + 10;
	if (c >= 'A' && c <= 'F')
		return c - 'A' + 10;
	return -1;
}

static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

bool auth_key_parse(struct auth_key *k, const char *text, char *why, size_t cap)
{
	while (is_space(*text))
		text++;
	size_t n = 0;
	while (text[n] && !is_space(text[n]))
		n++;
	for (size_t i = n; text[i]; i++) {
		if (!is_space(text[i])) {
			snprintf(why, cap, "more than one word: a key is 64 hex digits");
			return false;
		}
	}
	if (n != 2 * AUTH_KEY_BYTES) {
		snprintf(why, cap, "%zu characters: a key is 64 hex digits (undulated --gen-key FILE makes one)", n);
		return false;
	}
	for (size_t i = 0; i < AUTH_KEY_BYTES; i++) {
		int hi = hexval(text[2 * i]), lo = hexval(text[2 * i + 1]);
		if (hi < 0 || lo < 0) {
			snprintf(why, cap, "not a hex digit at position %zu", 2 * i + (hi < 0 ? 1 : 2));
			sodium_memzero(k, sizeof *k);
			return false;
		}
		k->bytes[i] = (uint8_t)(hi << 4 | lo);
	}
	return true;
}

bool auth_key_load(struct auth_key *k, const char *path, bool private_only, char *why, size_t cap)
{
	return auth_key_load_as(k, path, private_only, geteuid(), why, cap);
}

bool auth_key_load_as(struct auth_key *k, const char *path, bool private_only, uid_t owner, char *why, size_t cap)
{
	int fd = open(path, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
	if (fd < 0) {
		snprintf(why, cap, "%s: %s", path, errno == ELOOP ? "is a symbolic link (give the file itself)"
		                                                  : strerror(errno));
		return false;
	}
	struct stat st;
	char text[AUTH_KEY_FILE_MAX + 1];
	bool ok = false;
	if (fstat(fd, &st) != 0) {
		snprintf(why, cap, "%s: %s", path, strerror(errno));
	} else if (!S_ISREG(st.st_mode)) {
		snprintf(why, cap, "%s: not a regular file", path);
	} else if (st.st_uid != owner && st.st_uid != 0) {
		snprintf(why, cap, "%s: owned by uid %u, neither this user (%u) nor root", path, (unsigned)st.st_uid,
		         (unsigned)owner);
	} else if (private_only && (st.st_mode & 077) != 0) {
		snprintf(why, cap, "%s: mode %04o lets others read the key: chmod 600 (or 400) it", path,
		         (unsigned)(st.st_mode & 07777));
	} else if (st.st_size > AUTH_KEY_FILE_MAX) {
		snprintf(why, cap, "%s: %lld bytes, a key file is 64 hex digits", path, (long long)st.st_size);
	} else {
		ssize_t n = read(fd, text, AUTH_KEY_FILE_MAX);
		if (n < 0) {
			snprintf(why, cap, "%s: %s", path, strerror(errno));
		} else {
			text[n] = '\0';
			char inner[160];
			ok = auth_key_parse(k, text, inner, sizeof inner);
			if (!ok)
				snprintf(why, cap, "%s: %s", path, inner);
		}
	}
	sodium_memzero(text, sizeof text);
	close(fd);
	return ok;
}

bool auth_key_generate(const char *path, char *why, size_t cap)
{
	if (!auth_ready()) {
		snprintf(why, cap, "libsodium could not be initialised (no entropy source)");
		return false;
	}
	uint8_t key[AUTH_KEY_BYTES];
	char hex[2 * AUTH_KEY_BYTES + 2];
	randombytes_buf(key, sizeof key);
	sodium_bin2hex(hex, sizeof hex - 1, key, sizeof key);
	size_t len = strlen(hex);
	hex[len] = '\n';
	int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
	bool ok = false;
	if (fd < 0) {
		snprintf(why, cap, "%s: %s", path, errno == EEXIST ? "exists already (not overwritten)" : strerror(errno));
	} else {
		ok = write(fd, hex, len + 1) == (ssize_t)(len + 1) && fsync(fd) == 0;
		if (!ok)
			snprintf(why, cap, "%s: %s", path, strerror(errno));
		close(fd);
	}
	sodium_memzero(key, sizeof key);
	sodium_memzero(hex, sizeof hex);
	return ok;
}

void auth_mac(const struct auth_key *k, const void *data, size_t n, uint8_t mac[AUTH_MAC_BYTES])
{
	if (!auth_ready()) {
		memset(mac, 0, AUTH_MAC_BYTES);
		return;
	}
	crypto_auth_hmacsha256(mac, data, n, k->bytes);
}

bool auth_mac_ok(const struct auth_key *k, const void *data, size_t n, const uint8_t mac[AUTH_MAC_BYTES])
{
	return auth_ready() && crypto_auth_hmacsha256_verify(mac, data, n, k->bytes) == 0;
}

/* ---- replay ------------------------------------------------------------------------------ */
void auth_replay_init(struct auth_replay *g, int64_t window_us, int64_t now_us)
{
	memset(g, 0, sizeof *g);
	g->window_us = window_us;
	g->floor_us = now_us - 1;
}

static ptrdiff_t auth_find(const struct auth_replay *g, const char *source)
{
	for (size_t i = 0; i < g->n; i++)
		if (strncmp(g->seen[i].source, source, AUTH_SOURCE_MAX - 1) == 0)
			return (ptrdiff_t)i;
	return -1;
}

enum auth_fresh auth_replay_check(const struct auth_replay *g, const char *source, int64_t utime, int64_t seq,
                                  int64_t now_us)
{
	/* |utime - now_us| < window_us (auth.h): the window's edge is outside */
	if (utime <= g->floor_us || utime <= now_us - g->window_us)
		return AUTH_TOO_OLD;
	if (utime >= now_us + g->window_us)
		return AUTH_TOO_NEW;
	ptrdiff_t i = auth_find(g, source);
	const struct auth_seen *s = i >= 0 ? &g->seen[i] : NULL;
	if (s != NULL && (utime < s->utime || (utime == s->utime && seq <= s->seq)))
		return AUTH_REPLAYED;
	return AUTH_FRESH;
}

void auth_replay_accept(struct auth_replay *g, const char *source, int64_t utime, int64_t seq)
{
	ptrdiff_t i = auth_find(g, source);
	struct auth_seen *s = i >= 0 ? &g->seen[i] : NULL;
	if (s == NULL) {
		if (g->n < AUTH_SOURCES) {
			s = &g->seen[g->n++];
		} else {
			/* forget the source heard from longest ago; nothing it sent may pass again */
			s = &g->seen[0];
			for (size_t k = 1; k < g->n; k++)
				if (g->seen[k].utime < s->utime)
					s = &g->seen[k];
			if (s->utime > g->floor_us)
				g->floor_us = s->utime;
		}
		snprintf(s->source, sizeof s->source, "%s", source);
	}
	s->utime = utime;
	s->seq = seq;
}

const char *auth_fresh_text(enum auth_fresh f)
{
	switch (f) {
	case AUTH_FRESH: return "fresh";
	case AUTH_TOO_OLD: return "too old (sent before the robot started, or its clock is behind: synchronise the clocks)";
	case AUTH_TOO_NEW: return "from the future (the sender's clock is ahead: synchronise the clocks)";
	case AUTH_REPLAYED: return "replayed (this source already sent this sequence number or a later one)";
	}
	return "?";
}
