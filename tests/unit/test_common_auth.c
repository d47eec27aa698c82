/* test_common_auth.c — the command key and what it signs: parsing (64 hex
 * digits, white space around, nothing else), loading only a private regular
 * file of ours without ever blocking, generating one that is never written
 * over, HMAC-SHA256 against a vector computed elsewhere (Python's hmac), and
 * the replay guard: the window, the floor at start, (time, seq) per source,
 * and eviction that lets nothing an evicted source sent pass again. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "auth.h"
#include "scratch.h"

#define KEY_HEX "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f"

static void expect_key_bytes_0_to_31(const struct auth_key *k)
{
	for (size_t i = 0; i < AUTH_KEY_BYTES; i++)
		assert_int_equal(k->bytes[i], i);
}

/* ---- parsing ---------------------------------------------------------------------------------- */
static void expect_parse_fails(const char *text, const char *needle)
{
	struct auth_key k;
	char why[200] = "";
	if (auth_key_parse(&k, text, why, sizeof why))
		fail_msg("'%s' parsed as a key", text);
	if (strstr(why, needle) == NULL)
		fail_msg("'%s': why '%s' does not contain '%s'", text, why, needle);
}

static void test_key_parse(void **state)
{
	(void)state;
	struct auth_key k;
	char why[200];
	assert_true(auth_key_parse(&k, KEY_HEX, why, sizeof why));
	expect_key_bytes_0_to_31(&k);
	assert_true(auth_key_parse(&k, "  \t\n" KEY_HEX "\r\n \n", why, sizeof why));
	expect_key_bytes_0_to_31(&k);
	char upper[65];
	memcpy(upper, "FFEEDDCCBBAA99887766554433221100ffeeddccbbaa99887766554433221100", 65);
	assert_true(auth_key_parse(&k, upper, why, sizeof why));
	assert_int_equal(k.bytes[0], 0xff);
	assert_int_equal(k.bytes[5], 0xaa);
	assert_int_equal(k.bytes[15], 0x00);
	assert_int_equal(k.bytes[16], 0xff);
	assert_int_equal(k.bytes[31], 0x00);

	/* wrong lengths */
	expect_parse_fails("", "0 characters");
	expect_parse_fails(" \n", "0 characters");
	char text[140];
	snprintf(text, sizeof text, "%.63s", KEY_HEX);
	expect_parse_fails(text, "63 characters");
	snprintf(text, sizeof text, "%s0", KEY_HEX);
	expect_parse_fails(text, "65 characters");
	snprintf(text, sizeof text, "%s%s", KEY_HEX, KEY_HEX);
	expect_parse_fails(text, "128 characters");
	/* more than one word, even when the first is a key */
	snprintf(text, sizeof text, "%s x", KEY_HEX);
	expect_parse_fails(text, "more than one word");
	snprintf(text, sizeof text, "%.32s %.32s", KEY_HEX, KEY_HEX + 32);
	expect_parse_fails(text, "more than one word");
	/* every position of a non-hex character is found (1-based) */
	const char bad[] = { 'g', 'G', 'x', '-', ':', '.', (char)0xc3, '+' };
	for (size_t pos = 0; pos < 64; pos++) {
		memcpy(text, KEY_HEX, 65);
		text[pos] = bad[pos % sizeof bad];
		char needle[32];
		snprintf(needle, sizeof needle, "position %zu", pos + 1);
		expect_parse_fails(text, needle);
	}
	/* a "0x" prefix is not part of the format */
	snprintf(text, sizeof text, "0x%.62s", KEY_HEX);
	expect_parse_fails(text, "not a hex digit");
}

/* ---- loading ---------------------------------------------------------------------------------- */
/* Writes text to scratch_dir/name with exactly `mode` (whatever the umask). */
static const char *put_file(const char *name, const char *text, mode_t mode)
{
	static char path[512];
	snprintf(path, sizeof path, "%s/%s", scratch_dir, name);
	unlink(path);
	int fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0600);
	assert_true(fd >= 0);
	assert_int_equal(write(fd, text, strlen(text)), (ssize_t)strlen(text));
	assert_int_equal(fchmod(fd, mode), 0);
	close(fd);
	return path;
}

static void expect_load_fails(const char *path, bool private_only, const char *needle)
{
	struct auth_key k;
	char why[400] = "";
	if (auth_key_load(&k, path, private_only, why, sizeof why))
		fail_msg("%s loaded (expected '%s')", path, needle);
	if (strstr(why, needle) == NULL)
		fail_msg("why '%s' does not contain '%s'", why, needle);
}

static void test_key_load_good(void **state)
{
	(void)state;
	struct auth_key k;
	char why[400];
	const char *p = put_file("good.key", KEY_HEX "\n", 0600);
	memset(&k, 0, sizeof k);
	assert_true(auth_key_load(&k, p, true, why, sizeof why));
	expect_key_bytes_0_to_31(&k);
	p = put_file("ro.key", "\n  " KEY_HEX "  \n", 0400);
	assert_true(auth_key_load(&k, p, true, why, sizeof why));
	expect_key_bytes_0_to_31(&k);
	/* AUTH_KEY_FILE_MAX bytes is the most, white space included */
	char big[AUTH_KEY_FILE_MAX + 2];
	memset(big, ' ', sizeof big);
	memcpy(big, KEY_HEX, 64);
	big[AUTH_KEY_FILE_MAX] = '\0';
	p = put_file("max.key", big, 0600);
	assert_true(auth_key_load(&k, p, true, why, sizeof why));
	big[AUTH_KEY_FILE_MAX] = '\n';
	big[AUTH_KEY_FILE_MAX + 1] = '\0';
	p = put_file("over.key", big, 0600);
	expect_load_fails(p, true, "257 bytes");
	/* the file's content is checked like any text */
	p = put_file("short.key", "0011\n", 0600);
	expect_load_fails(p, true, "4 characters");
	p = put_file("empty.key", "", 0600);
	expect_load_fails(p, true, "0 characters");
	char missing[512];
	snprintf(missing, sizeof missing, "%s/no-such.key", scratch_dir);
	expect_load_fails(missing, true, "No such file");
}

static void test_key_load_mode(void **state)
{
	(void)state;
	const mode_t open_modes[] = { 0640, 0604, 0644, 0660, 0606, 0610, 0601, 0620, 0602, 0666 };
	struct auth_key k;
	char why[400];
	for (size_t i = 0; i < sizeof open_modes / sizeof open_modes[0]; i++) {
		const char *p = put_file("mode.key", KEY_HEX, open_modes[i]);
		char needle[32];
		snprintf(needle, sizeof needle, "mode %04o", (unsigned)open_modes[i]);
		expect_load_fails(p, true, needle);
		/* not private_only: the mode is the caller's business */
		assert_true(auth_key_load(&k, p, false, why, sizeof why));
		expect_key_bytes_0_to_31(&k);
	}
}

/* Not a regular file: refused, and never a read that waits. The alarm ends
 * the test program if a call blocks. */
static void test_key_load_not_regular(void **state)
{
	(void)state;
	char path[512], target[512];
	alarm(20);
	snprintf(path, sizeof path, "%s/fifo.key", scratch_dir);
	unlink(path);
	assert_int_equal(mkfifo(path, 0600), 0);
	expect_load_fails(path, true, "not a regular file");
	expect_load_fails(path, false, "not a regular file");
	snprintf(path, sizeof path, "%s/dir.key", scratch_dir);
	rmdir(path);
	assert_int_equal(mkdir(path, 0700), 0);
	expect_load_fails(path, true, "not a regular file");
	expect_load_fails("/dev/null", false, "not a regular file");
	/* a symbolic link, even to a good key file, is not followed */
	snprintf(target, sizeof target, "%s", put_file("target.key", KEY_HEX, 0600));
	snprintf(path, sizeof path, "%s/link.key", scratch_dir);
	unlink(path);
	assert_int_equal(symlink(target, path), 0);
	expect_load_fails(path, true, "symbolic link");
	expect_load_fails(path, false, "symbolic link");
	alarm(0);
}

static void test_key_load_owner(void **state)
{
	(void)state;
	const char *p = put_file("owner.key", KEY_HEX, 0600);
	if (geteuid() != 0) {
		/* only root can give a file away; the owner check is for root's files */
		struct auth_key k;
		char why[400];
		assert_true(auth_key_load(&k, p, true, why, sizeof why));
		skip();
	}
	assert_int_equal(chown(p, 54321, 54321), 0);
	expect_load_fails(p, true, "owned by uid 54321");
	expect_load_fails(p, false, "owned by uid 54321");
	/* judged for a program that runs as uid 54321 (--check-config run by
	 * root for a service user): its own file; the mode still counts */
	struct auth_key k;
	char why[400];
	assert_true(auth_key_load_as(&k, p, true, 54321, why, sizeof why));
	assert_false(auth_key_load_as(&k, p, true, 54322, why, sizeof why));
	assert_non_null(strstr(why, "owned by uid 54321, neither this user (54322) nor root"));
	assert_int_equal(chmod(p, 0640), 0);
	assert_false(auth_key_load_as(&k, p, true, 54321, why, sizeof why));
	assert_non_null(strstr(why, "mode 0640"));
	assert_int_equal(chmod(p, 0600), 0);
	assert_int_equal(chown(p, 0, 54321), 0);   /* root's with another group: fine */
	assert_true(auth_key_load(&k, p, true, why, sizeof why));
	assert_true(auth_key_load_as(&k, p, true, 54321, why, sizeof why));
}

/* ---- generating ------------------------------------------------------------------------------- */
static void test_key_generate(void **state)
{
	(void)state;
	char p1[512], p2[512], why[400];
	snprintf(p1, sizeof p1, "%s/gen1.key", scratch_dir);
	snprintf(p2, sizeof p2, "%s/gen2.key", scratch_dir);
	unlink(p1);
	unlink(p2);
	mode_t old = umask(0);   /* the mode must not depend on the caller's umask */
	bool ok = auth_key_generate(p1, why, sizeof why);
	umask(old);
	assert_true(ok);
	assert_true(auth_key_generate(p2, why, sizeof why));
	assert_true(scratch_private_file(p1, 0600));
	/* 64 hex digits and a newline, and it loads as a private key */
	char *text = scratch_slurp("gen1.key", 300);
	assert_non_null(text);
	assert_int_equal(strlen(text), 65);
	assert_int_equal(strspn(text, "0123456789abcdef"), 64);
	assert_int_equal(text[64], '\n');
	struct auth_key k1, k2;
	assert_true(auth_key_load(&k1, p1, true, why, sizeof why));
	assert_true(auth_key_load(&k2, p2, true, why, sizeof why));
	assert_memory_not_equal(k1.bytes, k2.bytes, AUTH_KEY_BYTES);
	/* never written over */
	assert_false(auth_key_generate(p1, why, sizeof why));
	assert_non_null(strstr(why, "exists already"));
	char *again = scratch_slurp("gen1.key", 300);
	assert_string_equal(again, text);
	free(again);
	free(text);
	/* nor through a symbolic link, even a dangling one */
	char link[512], dangling[512];
	snprintf(link, sizeof link, "%s/gen-link.key", scratch_dir);
	snprintf(dangling, sizeof dangling, "%s/gen-nowhere.key", scratch_dir);
	unlink(link);
	assert_int_equal(symlink(dangling, link), 0);
	assert_false(auth_key_generate(link, why, sizeof why));
	assert_int_equal(access(dangling, F_OK), -1);
	/* a directory that does not exist */
	snprintf(link, sizeof link, "%s/no-dir/x.key", scratch_dir);
	assert_false(auth_key_generate(link, why, sizeof why));
	assert_non_null(strstr(why, "No such file"));
}

/* ---- MAC --------------------------------------------------------------------------------------- */
static void hex_to(const char *hex, uint8_t *out, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		unsigned v;
		assert_int_equal(sscanf(hex + 2 * i, "%2x", &v), 1);
		out[i] = (uint8_t)v;
	}
}

static void test_mac(void **state)
{
	(void)state;
	struct auth_key k, other;
	char why[200];
	assert_true(auth_key_parse(&k, KEY_HEX, why, sizeof why));
	/* python3: hmac.new(bytes(range(32)), b'undulate command', hashlib.sha256) */
	uint8_t want[AUTH_MAC_BYTES], mac[AUTH_MAC_BYTES];
	hex_to("e4e71fd68b04945004794b400db2bd7145db883f8fad4625368ecd4c5794ad37", want, sizeof want);
	const char msg[] = "undulate command";
	const size_t n = sizeof msg - 1;
	auth_mac(&k, msg, n, mac);
	assert_memory_equal(mac, want, sizeof want);
	assert_true(auth_mac_ok(&k, msg, n, mac));
	/* ... and of nothing */
	hex_to("d38b42096d80f45f826b44a9d5607de72496a415d3f4a1a8c88e3bb9da8dc1cb", want, sizeof want);
	auth_mac(&k, "", 0, mac);
	assert_memory_equal(mac, want, sizeof want);
	assert_true(auth_mac_ok(&k, "", 0, mac));

	auth_mac(&k, msg, n, mac);
	/* every byte of the message, changed in any bit, breaks the tag */
	char t[sizeof msg];
	for (size_t i = 0; i < n; i++) {
		for (int bit = 0; bit < 8; bit++) {
			memcpy(t, msg, sizeof msg);
			t[i] = (char)(t[i] ^ (1 << bit));
			if (auth_mac_ok(&k, t, n, mac))
				fail_msg("byte %zu bit %d changed, tag still good", i, bit);
		}
	}
	/* every bit of the tag */
	for (size_t i = 0; i < AUTH_MAC_BYTES; i++) {
		for (int bit = 0; bit < 8; bit++) {
			uint8_t m2[AUTH_MAC_BYTES];
			memcpy(m2, mac, sizeof m2);
			m2[i] ^= (uint8_t)(1 << bit);
			if (auth_mac_ok(&k, msg, n, m2))
				fail_msg("tag byte %zu bit %d changed, still good", i, bit);
		}
	}
	/* a message cut or extended */
	assert_false(auth_mac_ok(&k, msg, n - 1, mac));
	assert_false(auth_mac_ok(&k, msg, n + 1, mac));
	/* another key: any one bit of it */
	for (size_t i = 0; i < AUTH_KEY_BYTES; i++) {
		other = k;
		other.bytes[i] ^= 0x80;
		assert_false(auth_mac_ok(&other, msg, n, mac));
	}
}

/* ---- replay ------------------------------------------------------------------------------------ */
#define T0 1700000000000000LL     /* µs since the epoch: the robot started here */
#define WIN 5000000LL             /* 5 s */

static void test_replay_window(void **state)
{
	(void)state;
	struct auth_replay g;
	auth_replay_init(&g, WIN, T0);
	int64_t now = T0 + 60 * 1000000LL;
	assert_int_equal(auth_replay_check(&g, "op", now, 1, now), AUTH_FRESH);
	assert_int_equal(auth_replay_check(&g, "op", now - WIN + 1, 1, now), AUTH_FRESH);
	assert_int_equal(auth_replay_check(&g, "op", now + WIN - 1, 1, now), AUTH_FRESH);
	/* |sender time - our time| must be below the window */
	assert_int_equal(auth_replay_check(&g, "op", now - WIN, 1, now), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "op", now - WIN - 1, 1, now), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "op", 0, 1, now), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "op", INT64_MIN, 1, now), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "op", now + WIN, 1, now), AUTH_TOO_NEW);
	assert_int_equal(auth_replay_check(&g, "op", now + WIN + 1, 1, now), AUTH_TOO_NEW);
	assert_int_equal(auth_replay_check(&g, "op", INT64_MAX, 1, now), AUTH_TOO_NEW);
	/* texts for the answers, one per verdict */
	const char *texts[] = { auth_fresh_text(AUTH_FRESH), auth_fresh_text(AUTH_TOO_OLD),
		                auth_fresh_text(AUTH_TOO_NEW), auth_fresh_text(AUTH_REPLAYED) };
	for (size_t i = 0; i < 4; i++)
		for (size_t j = 0; j < i; j++)
			assert_string_not_equal(texts[i], texts[j]);
	assert_non_null(strstr(texts[3], "replayed"));
}

static void test_replay_floor(void **state)
{
	(void)state;
	struct auth_replay g;
	auth_replay_init(&g, WIN, T0);
	/* signed before the robot started, though inside the window: a recording
	 * made before a restart */
	assert_int_equal(auth_replay_check(&g, "op", T0 - 1, 1, T0), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "op", T0 - 1, 1, T0 + 1000), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "op", T0 - WIN / 2, 1, T0 + 1000), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "op", T0, 1, T0), AUTH_FRESH);
	assert_int_equal(auth_replay_check(&g, "op", T0 + 1, 1, T0 + 1000), AUTH_FRESH);
}

static void test_replay_per_source(void **state)
{
	(void)state;
	struct auth_replay g;
	auth_replay_init(&g, WIN, T0);
	int64_t now = T0 + 1000000, t = now - 100;
	assert_int_equal(auth_replay_check(&g, "alice", t, 5, now), AUTH_FRESH);
	/* checking remembers nothing */
	assert_int_equal(auth_replay_check(&g, "alice", t, 5, now), AUTH_FRESH);
	auth_replay_accept(&g, "alice", t, 5);
	assert_int_equal(auth_replay_check(&g, "alice", t, 5, now), AUTH_REPLAYED);
	assert_int_equal(auth_replay_check(&g, "alice", t, 4, now), AUTH_REPLAYED);
	assert_int_equal(auth_replay_check(&g, "alice", t, INT64_MIN, now), AUTH_REPLAYED);
	assert_int_equal(auth_replay_check(&g, "alice", t - 1, 100, now), AUTH_REPLAYED);
	assert_int_equal(auth_replay_check(&g, "alice", t, 6, now), AUTH_FRESH);
	assert_int_equal(auth_replay_check(&g, "alice", t + 1, 0, now), AUTH_FRESH);
	/* another source has its own order */
	assert_int_equal(auth_replay_check(&g, "bob", t, 5, now), AUTH_FRESH);
	assert_int_equal(auth_replay_check(&g, "bob", t - 50, 1, now), AUTH_FRESH);
	auth_replay_accept(&g, "bob", t - 50, 1);
	assert_int_equal(auth_replay_check(&g, "alice", t, 5, now), AUTH_REPLAYED);
	/* the newest accepted is what counts */
	auth_replay_accept(&g, "alice", t + 10, 0);
	assert_int_equal(auth_replay_check(&g, "alice", t + 5, 99, now), AUTH_REPLAYED);
	assert_int_equal(auth_replay_check(&g, "alice", t + 10, 0, now), AUTH_REPLAYED);
	assert_int_equal(auth_replay_check(&g, "alice", t + 10, 1, now), AUTH_FRESH);
	/* a source name longer than the table keeps: its replays are still caught */
	char longname[AUTH_SOURCE_MAX + 20];
	memset(longname, 'L', sizeof longname - 1);
	longname[sizeof longname - 1] = '\0';
	auth_replay_accept(&g, longname, t, 3);
	assert_int_equal(auth_replay_check(&g, longname, t, 3, now), AUTH_REPLAYED);
	assert_int_equal(auth_replay_check(&g, longname, t, 4, now), AUTH_FRESH);
	assert_int_equal(auth_replay_check(&g, "", t, 1, now), AUTH_FRESH);
}

static void test_replay_eviction(void **state)
{
	(void)state;
	struct auth_replay g;
	auth_replay_init(&g, WIN, T0);
	int64_t now = T0 + 2000000;
	char name[16];
	/* AUTH_SOURCES sources, source i last heard at T0 + 1000 + i */
	for (int i = 0; i < AUTH_SOURCES; i++) {
		snprintf(name, sizeof name, "s%d", i);
		assert_int_equal(auth_replay_check(&g, name, T0 + 1000 + i, 7, now), AUTH_FRESH);
		auth_replay_accept(&g, name, T0 + 1000 + i, 7);
	}
	assert_int_equal(g.n, AUTH_SOURCES);
	/* all remembered: each one's replay refused, the floor untouched */
	for (int i = 0; i < AUTH_SOURCES; i++) {
		snprintf(name, sizeof name, "s%d", i);
		assert_int_equal(auth_replay_check(&g, name, T0 + 1000 + i, 7, now), AUTH_REPLAYED);
	}
	assert_int_equal(auth_replay_check(&g, "new", T0 + 1000, 1, now), AUTH_FRESH);
	/* one more source: s0, heard from longest ago, is forgotten, and the
	 * floor rises to its last time */
	assert_int_equal(auth_replay_check(&g, "new", T0 + 5000, 1, now), AUTH_FRESH);
	auth_replay_accept(&g, "new", T0 + 5000, 1);
	assert_int_equal(g.n, AUTH_SOURCES);
	assert_true(g.floor_us >= T0 + 1000);
	/* nothing s0 sent passes again: neither its last command nor a later
	 * sequence number at that time, nor anything older */
	assert_int_equal(auth_replay_check(&g, "s0", T0 + 1000, 7, now), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "s0", T0 + 1000, 8, now), AUTH_TOO_OLD);
	assert_int_equal(auth_replay_check(&g, "s0", T0 + 999, 100, now), AUTH_TOO_OLD);
	/* the others are still remembered */
	for (int i = 1; i < AUTH_SOURCES; i++) {
		snprintf(name, sizeof name, "s%d", i);
		assert_int_equal(auth_replay_check(&g, name, T0 + 1000 + i, 7, now), AUTH_REPLAYED);
		assert_int_equal(auth_replay_check(&g, name, T0 + 1000 + i, 8, now), AUTH_FRESH);
	}
	assert_int_equal(auth_replay_check(&g, "new", T0 + 5000, 1, now), AUTH_REPLAYED);
	/* s0 may speak again with something new */
	assert_int_equal(auth_replay_check(&g, "s0", T0 + 6000, 1, now), AUTH_FRESH);
}

/* The guard's one promise, checked against every command ever accepted: a
 * random mix of up to 3 * AUTH_SOURCES sources, clocks that drift within the
 * window, time moving on. After each acceptance, none of the commands
 * accepted so far is fresh again. */
static void test_replay_property(void **state)
{
	(void)state;
	enum { ACCEPTS = 3000 };
	static struct { char source[16]; int64_t utime, seq; } done[ACCEPTS];
	struct auth_replay g;
	auth_replay_init(&g, WIN, T0);
	int64_t now = T0, seqs[3 * AUTH_SOURCES] = { 0 };
	unsigned seed = 777;
	size_t nd = 0;
	for (int tries = 0; nd < ACCEPTS && tries < 100000; tries++) {
		seed = seed * 1103515245u + 12345u;
		int src = (int)((seed >> 16) % (3 * AUTH_SOURCES));
		seed = seed * 1103515245u + 12345u;
		now += (seed >> 16) % 3000;
		seed = seed * 1103515245u + 12345u;
		int64_t utime = now - WIN + 1 + (int64_t)((seed >> 8) % (2 * WIN - 1));
		char name[16];
		snprintf(name, sizeof name, "src%d", src);
		int64_t seq = ++seqs[src];
		if (auth_replay_check(&g, name, utime, seq, now) != AUTH_FRESH)
			continue;
		auth_replay_accept(&g, name, utime, seq);
		snprintf(done[nd].source, sizeof done[nd].source, "%s", name);
		done[nd].utime = utime;
		done[nd].seq = seq;
		nd++;
		for (size_t i = 0; i < nd; i++)
			if (auth_replay_check(&g, done[i].source, done[i].utime, done[i].seq, now) == AUTH_FRESH)
				fail_msg("after %zu accepted: %s (%lld, %lld) passes again", nd, done[i].source,
				         (long long)done[i].utime, (long long)done[i].seq);
	}
	/* enough traffic to have evicted sources many times over */
	assert_true(nd > 10 * AUTH_SOURCES);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_key_parse),
		cmocka_unit_test(test_key_load_good),
		cmocka_unit_test(test_key_load_mode),
		cmocka_unit_test(test_key_load_not_regular),
		cmocka_unit_test(test_key_load_owner),
		cmocka_unit_test(test_key_generate),
		cmocka_unit_test(test_mac),
		cmocka_unit_test(test_replay_window),
		cmocka_unit_test(test_replay_floor),
		cmocka_unit_test(test_replay_per_source),
		cmocka_unit_test(test_replay_eviction),
		cmocka_unit_test(test_replay_property),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
