/* test_web_wsguard.c — what a WebSocket client may send, by RFC 6455 and
 * beyond what libwebsockets 4.1 checks: every frame masked (5.1), nothing
 * after the handshake before the server's 101 (4.1), lengths that fit 63
 * bits (5.2). Frames whole, byte by byte, and split at every offset. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "../../tools/web/wsguard.h"

static const char handshake[] = "GET / HTTP/1.1\r\nHost: localhost:8080\r\nUpgrade: websocket\r\n"
                                "Connection: Upgrade\r\nSec-WebSocket-Version: 13\r\n\r\n";

/* A frame as a client sends it: FIN, opcode, masked (key 1 2 3 4) or not. */
static size_t frame(uint8_t *out, int opcode, bool masked, const uint8_t *payload, size_t n)
{
	size_t k = 0;
	out[k++] = (uint8_t)(0x80 | opcode);
	uint8_t m = masked ? 0x80 : 0;
	if (n < 126) {
		out[k++] = (uint8_t)(m | n);
	} else if (n < 65536) {
		out[k++] = m | 126;
		out[k++] = (uint8_t)(n >> 8);
		out[k++] = (uint8_t)n;
	} else {
		out[k++] = m | 127;
		for (int i = 7; i >= 0; i--)
			out[k++] = (uint8_t)((uint64_t)n >> (8 * i));
	}
	static const uint8_t key[4] = { 1, 2, 3, 4 };
	if (masked)
		for (int i = 0; i < 4; i++)
			out[k++] = key[i];
	for (size_t i = 0; i < n; i++)
		out[k++] = masked ? payload[i] ^ key[i % 4] : payload[i];
	return k;
}

/* The handshake fed, the 101 sent, then the frames in one buffer. */
static enum wsg_verdict run(const uint8_t *frames, size_t n, size_t piece)
{
	struct wsg g;
	wsg_init(&g);
	wsg_feed(&g, (const uint8_t *)handshake, strlen(handshake));
	enum wsg_verdict v = wsg_upgraded(&g);
	if (v != WSG_OK)
		return v;
	for (size_t off = 0; off < n; off += piece)
		wsg_feed(&g, frames + off, n - off < piece ? n - off : piece);
	return wsg_verdict(&g);
}

static void test_masked_frames_pass(void **state)
{
	(void)state;
	static uint8_t buf[200000], big[70000];
	const uint8_t hello[] = "cmd 1 left mode hold";
	memset(big, 0x81, sizeof big); /* a payload full of what looks like frame headers */
	size_t n = frame(buf, 1, true, hello, sizeof hello - 1);
	n += frame(buf + n, 9, true, NULL, 0);              /* a ping */
	n += frame(buf + n, 1, true, big, 300);             /* 16-bit length */
	n += frame(buf + n, 2, true, big, sizeof big);      /* 64-bit length (binary: the server's business) */
	n += frame(buf + n, 8, true, (const uint8_t *)"\x03\xe8", 2);
	assert_int_equal(run(buf, n, n), WSG_OK);
	assert_int_equal(run(buf, n, 1), WSG_OK);
	assert_int_equal(run(buf, n, 7), WSG_OK);
	struct wsg g;
	wsg_init(&g);
	wsg_feed(&g, (const uint8_t *)handshake, strlen(handshake));
	assert_int_equal(wsg_upgraded(&g), WSG_OK);
	wsg_feed(&g, buf, n);
	assert_int_equal(wsg_frames(&g), 5);
}

static void test_unmasked_frame(void **state)
{
	(void)state;
	static uint8_t buf[1000];
	const uint8_t cmd[] = "cmd 1 left mode hold";
	size_t n = frame(buf, 1, true, cmd, sizeof cmd - 1);
	size_t first = n;
	n += frame(buf + n, 1, false, cmd, sizeof cmd - 1);
	for (size_t piece = 1; piece <= n; piece++)
		assert_int_equal(run(buf, n, piece), WSG_UNMASKED);
	/* an unmasked control frame too */
	n = first + frame(buf + first, 9, false, NULL, 0);
	assert_int_equal(run(buf, n, n), WSG_UNMASKED);
	/* and it stays said: what follows does not clear it */
	struct wsg g;
	wsg_init(&g);
	wsg_feed(&g, (const uint8_t *)handshake, strlen(handshake));
	wsg_upgraded(&g);
	wsg_feed(&g, buf + first, n - first);
	wsg_feed(&g, buf, first);
	assert_int_equal(wsg_verdict(&g), WSG_UNMASKED);
	assert_non_null(strstr(wsg_why(WSG_UNMASKED), "masked"));
}

/* RFC 6455 4.1: the client waits for the server's 101 before it sends a
 * frame; bytes before it would be parsed where the guard did not look. */
static void test_early_bytes(void **state)
{
	(void)state;
	uint8_t buf[600];
	const uint8_t cmd[] = "cmd 1 left mode hold";
	memcpy(buf, handshake, strlen(handshake));
	size_t n = strlen(handshake) + frame(buf + strlen(handshake), 1, false, cmd, sizeof cmd - 1);
	struct wsg g;
	wsg_init(&g);
	wsg_feed(&g, buf, n);
	assert_int_equal(wsg_upgraded(&g), WSG_EARLY);
	/* split anywhere, the same */
	for (size_t cut = 1; cut < n; cut++) {
		wsg_init(&g);
		wsg_feed(&g, buf, cut);
		wsg_feed(&g, buf + cut, n - cut);
		assert_int_equal(wsg_upgraded(&g), WSG_EARLY);
	}
	/* a frame whose payload ends in CRLF CRLF does not hide itself */
	const uint8_t crlf[] = "x\r\n\r\n";
	n = strlen(handshake) + frame(buf + strlen(handshake), 1, false, crlf, sizeof crlf - 1);
	wsg_init(&g);
	wsg_feed(&g, buf, n);
	assert_int_equal(wsg_upgraded(&g), WSG_EARLY);
	/* an earlier request on the same connection: the upgrade was not first */
	static const char two[] = "GET / HTTP/1.1\r\nHost: localhost\r\n\r\n";
	wsg_init(&g);
	wsg_feed(&g, (const uint8_t *)two, strlen(two));
	wsg_feed(&g, (const uint8_t *)handshake, strlen(handshake));
	assert_int_equal(wsg_upgraded(&g), WSG_EARLY);
	/* the handshake alone, in pieces: fine */
	wsg_init(&g);
	wsg_feed(&g, (const uint8_t *)handshake, 10);
	wsg_feed(&g, (const uint8_t *)handshake + 10, strlen(handshake) - 10);
	assert_int_equal(wsg_upgraded(&g), WSG_OK);
}

static void test_bad_length(void **state)
{
	(void)state;
	const uint8_t bad[] = { 0x81, 0xff, 0x80, 0, 0, 0, 0, 0, 0, 1, 1, 2, 3, 4 };
	assert_int_equal(run(bad, sizeof bad, 1), WSG_BAD_LENGTH);
	/* 16-bit lengths below 126 and 64-bit ones below 65536 are not minimal (5.2): lws takes them, so do we */
	const uint8_t ok[] = { 0x81, 0xfe, 0, 1, 1, 2, 3, 4, 'x' ^ 1 };
	assert_int_equal(run(ok, sizeof ok, 1), WSG_OK);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_masked_frames_pass),
		cmocka_unit_test(test_unmasked_frame),
		cmocka_unit_test(test_early_bytes),
		cmocka_unit_test(test_bad_length),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
