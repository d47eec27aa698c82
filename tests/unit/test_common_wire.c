/* test_common_wire.c — LCM's wire format without trust: big-endian golden
 * bytes, writer/reader round trips, every short read marks the reader bad
 * and it stays bad, every string a sender can forge (length 0, negative,
 * past the end, no NUL, a NUL inside, longer than the caller's array), a
 * writer that runs out of room, the udpm small message both ways, and the
 * udpm fragment header (LC03) read. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "wire.h"

static void test_put_golden(void **state)
{
	(void)state;
	uint8_t buf[64];
	struct wire_writer w;
	wire_writer_init(&w, buf, sizeof buf);
	wire_put(&w, 0xab, 1);
	wire_put(&w, 0x0102, 2);
	wire_put(&w, 0x03040506, 4);
	wire_put(&w, 0x0708090a0b0c0d0eull, 8);
	wire_put_string(&w, "ab");
	wire_put_string(&w, NULL);
	wire_put_double(&w, 1.0);
	const uint8_t want[] = {
		0xab, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06,
		0x07, 0x08, 0x09, 0x0a, 0x0b, 0x0c, 0x0d, 0x0e,
		0, 0, 0, 3, 'a', 'b', 0,          /* the length counts the NUL (lcm-gen) */
		0, 0, 0, 1, 0,                    /* NULL is "" */
		0x3f, 0xf0, 0, 0, 0, 0, 0, 0,     /* IEEE 754 1.0, big-endian */
	};
	assert_false(w.bad);
	assert_int_equal(w.len, sizeof want);
	assert_memory_equal(buf, want, sizeof want);
	/* only the low n bytes of a wider value */
	wire_writer_init(&w, buf, sizeof buf);
	wire_put(&w, 0x11223344, 2);
	assert_int_equal(w.len, 2);
	assert_int_equal(buf[0], 0x33);
	assert_int_equal(buf[1], 0x44);
}

static void test_round_trip(void **state)
{
	(void)state;
	uint8_t buf[256], raw[5] = { 9, 0, 255, 1, 2 };
	const double doubles[] = { 0.0, -0.0, 1.5, -2.25e-300, INFINITY, -INFINITY, 1.7976931348623157e308 };
	struct wire_writer w;
	wire_writer_init(&w, buf, sizeof buf);
	wire_put(&w, 0xfe, 1);
	wire_put(&w, 0xfffe, 2);
	wire_put(&w, 0x80000001u, 4);
	wire_put(&w, UINT64_MAX - 1, 8);
	wire_put(&w, (uint64_t)(int64_t)-5, 8);
	for (size_t i = 0; i < sizeof doubles / sizeof doubles[0]; i++)
		wire_put_double(&w, doubles[i]);
	wire_put_double(&w, NAN);
	wire_put_string(&w, "robot1.CMD");
	wire_put_string(&w, "");
	wire_put_bytes(&w, raw, sizeof raw);
	assert_false(w.bad);

	struct wire_reader r;
	wire_reader_init(&r, buf, w.len);
	assert_int_equal(wire_take(&r, 1), 0xfe);
	assert_int_equal(wire_take(&r, 2), 0xfffe);
	assert_int_equal(wire_take(&r, 4), 0x80000001u);
	assert_true(wire_take(&r, 8) == UINT64_MAX - 1);
	assert_int_equal((int64_t)wire_take(&r, 8), -5);
	for (size_t i = 0; i < sizeof doubles / sizeof doubles[0]; i++) {
		double d = wire_take_double(&r);
		assert_memory_equal(&d, &doubles[i], sizeof d);   /* bit for bit: -0.0 stays -0.0 */
	}
	assert_true(isnan(wire_take_double(&r)));
	char s[32];
	bool cut = true;
	wire_take_string(&r, s, sizeof s, &cut);
	assert_string_equal(s, "robot1.CMD");
	assert_false(cut);
	cut = true;
	wire_take_string(&r, s, sizeof s, &cut);
	assert_string_equal(s, "");
	assert_false(cut);
	uint8_t back[5];
	wire_take_bytes(&r, back, sizeof back);
	assert_memory_equal(back, raw, sizeof raw);
	assert_false(r.bad);
	assert_int_equal(r.left, 0);
}

/* A reader over exactly `have` bytes of 0xff. */
static struct wire_reader short_reader(const uint8_t *ff, size_t have)
{
	struct wire_reader r;
	wire_reader_init(&r, ff, have);
	return r;
}

/* After a failed take: bad, and every further take gives 0 / "" / zeros. */
static void expect_stays_bad(struct wire_reader *r)
{
	assert_true(r->bad);
	assert_int_equal(wire_take(r, 1), 0);
	assert_true(r->bad);
	double d = wire_take_double(r);
	assert_true(d == 0.0 && !signbit(d));
	char s[8] = "xxxxxxx";
	bool cut = true;
	wire_take_string(r, s, sizeof s, &cut);
	assert_string_equal(s, "");
	assert_false(cut);
	uint8_t b[3] = { 7, 7, 7 };
	wire_take_bytes(r, b, sizeof b);
	assert_int_equal(b[0] | b[1] | b[2], 0);
	assert_true(r->bad);
}

static void test_short_reads(void **state)
{
	(void)state;
	uint8_t ff[16];
	memset(ff, 0xff, sizeof ff);
	const size_t widths[] = { 1, 2, 4, 8 };
	for (size_t i = 0; i < 4; i++) {
		for (size_t have = 0; have < widths[i]; have++) {
			struct wire_reader r = short_reader(ff, have);
			assert_int_equal(wire_take(&r, widths[i]), 0);
			expect_stays_bad(&r);
		}
	}
	for (size_t have = 0; have < 8; have++) {
		struct wire_reader r = short_reader(ff, have);
		assert_true(wire_take_double(&r) == 0.0);
		expect_stays_bad(&r);
	}
	for (size_t have = 0; have < 4; have++) {
		/* not even the string's length */
		struct wire_reader r = short_reader((const uint8_t *)"\0\0\0\1", have);
		char s[8] = "xxxxxxx";
		wire_take_string(&r, s, sizeof s, NULL);
		assert_string_equal(s, "");
		expect_stays_bad(&r);
	}
	{
		struct wire_reader r = short_reader(ff, 4);
		uint8_t b[5] = { 1, 2, 3, 4, 5 };
		wire_take_bytes(&r, b, sizeof b);
		assert_memory_equal(b, "\0\0\0\0\0", 5);
		expect_stays_bad(&r);
	}
	/* a take that would fit after a failed one still gives nothing */
	{
		const uint8_t d[6] = { 0, 0, 0, 42, 0, 7 };
		struct wire_reader r = short_reader(d, sizeof d);
		assert_int_equal(wire_take(&r, 4), 42);
		assert_int_equal(wire_take(&r, 4), 0);   /* 2 left */
		assert_int_equal(wire_take(&r, 2), 0);   /* would fit */
		expect_stays_bad(&r);
	}
	/* no data at all */
	{
		struct wire_reader r;
		wire_reader_init(&r, NULL, 100);
		assert_int_equal(r.left, 0);
		assert_int_equal(wire_take(&r, 1), 0);
		expect_stays_bad(&r);
	}
}

/* Reads one string from `len` bytes; returns whether the reader went bad. */
static bool take_one(const uint8_t *d, size_t len, char *dst, size_t cap, bool *cut, size_t *left)
{
	struct wire_reader r;
	wire_reader_init(&r, d, len);
	wire_take_string(&r, dst, cap, cut);
	*left = r.left;
	return r.bad;
}

static void test_strings_forged(void **state)
{
	(void)state;
	char s[8];
	bool cut;
	size_t left;
	/* length 0: lcm-gen's length counts the NUL, so 0 is no string */
	const uint8_t zero[] = { 0, 0, 0, 0, 'a', 0 };
	assert_true(take_one(zero, sizeof zero, s, sizeof s, &cut, &left));
	assert_string_equal(s, "");
	/* negative lengths */
	const uint8_t minus1[] = { 0xff, 0xff, 0xff, 0xff, 'a', 0 };
	assert_true(take_one(minus1, sizeof minus1, s, sizeof s, &cut, &left));
	const uint8_t minmax[] = { 0x80, 0, 0, 0, 'a', 0 };
	assert_true(take_one(minmax, sizeof minmax, s, sizeof s, &cut, &left));
	assert_string_equal(s, "");
	/* past the end: 3 bytes claimed, 2 there; and a huge claim */
	const uint8_t past[] = { 0, 0, 0, 3, 'a', 0 };
	assert_true(take_one(past, sizeof past, s, sizeof s, &cut, &left));
	const uint8_t huge[] = { 0x7f, 0xff, 0xff, 0xff, 'a', 0 };
	assert_true(take_one(huge, sizeof huge, s, sizeof s, &cut, &left));
	/* the last byte is not a NUL */
	const uint8_t nonul[] = { 0, 0, 0, 3, 'a', 'b', 'c' };
	assert_true(take_one(nonul, sizeof nonul, s, sizeof s, &cut, &left));
	assert_string_equal(s, "");
	const uint8_t nonul_then[] = { 0, 0, 0, 2, 'a', 'b', 0 };   /* the NUL is one byte too far */
	assert_true(take_one(nonul_then, sizeof nonul_then, s, sizeof s, &cut, &left));
	/* exactly the bytes left: good */
	const uint8_t exact[] = { 0, 0, 0, 3, 'a', 'b', 0 };
	cut = true;
	assert_false(take_one(exact, sizeof exact, s, sizeof s, &cut, &left));
	assert_string_equal(s, "ab");
	assert_false(cut);
	assert_int_equal(left, 0);
	/* a NUL inside: read as far as it, marked cut, the whole string consumed */
	const uint8_t inner[] = { 0, 0, 0, 5, 'a', 0, 'b', 'c', 0, 0x42 };
	cut = false;
	assert_false(take_one(inner, sizeof inner, s, sizeof s, &cut, &left));
	assert_string_equal(s, "a");
	assert_true(cut);
	assert_int_equal(left, 1);
	const uint8_t lead[] = { 0, 0, 0, 3, 0, 'x', 0 };
	cut = false;
	assert_false(take_one(lead, sizeof lead, s, sizeof s, &cut, &left));
	assert_string_equal(s, "");
	assert_true(cut);
	/* the empty string: not cut */
	const uint8_t empty[] = { 0, 0, 0, 1, 0 };
	cut = true;
	assert_false(take_one(empty, sizeof empty, s, sizeof s, &cut, &left));
	assert_string_equal(s, "");
	assert_false(cut);
	/* cut may be NULL */
	assert_false(take_one(inner, sizeof inner, s, sizeof s, NULL, &left));
	assert_string_equal(s, "a");
}

static void test_strings_cap(void **state)
{
	(void)state;
	const uint8_t d[] = { 0, 0, 0, 7, 'r', 'o', 'b', 'o', 't', '1', 0, 0xee };
	char s[16];
	bool cut;
	size_t left;
	/* cap - 1 == length: whole */
	memset(s, 'z', sizeof s);
	cut = true;
	assert_false(take_one(d, sizeof d, s, 7, &cut, &left));
	assert_string_equal(s, "robot1");
	assert_false(cut);
	/* longer than cap - 1: cut, terminated inside cap, the rest consumed */
	for (size_t cap = 1; cap < 7; cap++) {
		memset(s, 'z', sizeof s);
		cut = false;
		assert_false(take_one(d, sizeof d, s, cap, &cut, &left));
		assert_true(cut);
		assert_int_equal(strlen(s), cap - 1);
		assert_memory_equal(s, "robot1", cap - 1);
		assert_int_equal((unsigned char)s[cap], 'z');
		assert_int_equal(left, 1);
	}
}

static void test_writer_full(void **state)
{
	(void)state;
	uint8_t buf[12];
	struct wire_writer w;
	/* every put that does not fit: bad, nothing written past cap, len kept */
	for (size_t cap = 0; cap < 8; cap++) {
		memset(buf, 0xcc, sizeof buf);
		wire_writer_init(&w, buf, cap);
		wire_put(&w, 0x0102030405060708ull, 8);
		assert_true(w.bad);
		assert_int_equal(w.len, 0);
		for (size_t i = 0; i < sizeof buf; i++)
			assert_int_equal(buf[i], 0xcc);
	}
	wire_writer_init(&w, buf, 6);
	wire_put_string(&w, "ab");   /* 4 + 3 bytes */
	assert_true(w.bad);
	assert_true(w.len <= 6);
	/* stays bad: a put that would fit now writes nothing */
	wire_writer_init(&w, buf, 4);
	wire_put_bytes(&w, (const uint8_t *)"abcde", 5);
	assert_true(w.bad);
	size_t len = w.len;
	wire_put(&w, 1, 1);
	wire_put_double(&w, 2.0);
	wire_put_string(&w, "");
	assert_true(w.bad);
	assert_int_equal(w.len, len);
	/* exactly full is not bad */
	wire_writer_init(&w, buf, 12);
	wire_put(&w, 1, 4);
	wire_put_double(&w, 3.0);
	assert_false(w.bad);
	assert_int_equal(w.len, 12);
	wire_put(&w, 0, 1);
	assert_true(w.bad);
	assert_int_equal(w.len, 12);
	/* no buffer */
	wire_writer_init(&w, NULL, 100);
	wire_put(&w, 1, 1);
	assert_true(w.bad);
	assert_int_equal(w.len, 0);
}

/* ---- udpm small messages ------------------------------------------------------------------- */
static const uint8_t payload[] = { 0x12, 0, 0x34, 'L', 'C', '0', '2', 0 };   /* NULs inside stay payload */

static void test_udpm_build_golden(void **state)
{
	(void)state;
	uint8_t buf[64];
	size_t n = wire_udpm_build(buf, sizeof buf, 0x01020304, "r1.CMD", payload, sizeof payload);
	const uint8_t want[] = { 'L', 'C', '0', '2', 1, 2, 3, 4, 'r', '1', '.', 'C', 'M', 'D', 0,
		                 0x12, 0, 0x34, 'L', 'C', '0', '2', 0 };
	assert_int_equal(n, sizeof want);
	assert_memory_equal(buf, want, sizeof want);
	/* too small a buffer, by any amount: 0 */
	for (size_t cap = 0; cap < sizeof want; cap++)
		assert_int_equal(wire_udpm_build(buf, cap, 1, "r1.CMD", payload, sizeof payload), 0);
	assert_int_equal(wire_udpm_build(buf, sizeof want, 1, "r1.CMD", payload, sizeof payload), sizeof want);
	/* channel names: empty and WIRE_CHANNEL_MAX with the NUL are refused */
	char ch[WIRE_CHANNEL_MAX + 1];
	memset(ch, 'c', sizeof ch);
	ch[WIRE_CHANNEL_MAX] = '\0';
	assert_int_equal(wire_udpm_build(buf, sizeof buf, 1, "", payload, 1), 0);
	uint8_t big[256];
	assert_int_equal(wire_udpm_build(big, sizeof big, 1, ch, payload, 1), 0);
	ch[WIRE_CHANNEL_MAX - 1] = '\0';   /* 63 bytes + NUL: the longest */
	assert_int_equal(wire_udpm_build(big, sizeof big, 1, ch, payload, 1), 8 + WIRE_CHANNEL_MAX + 1);
}

static void expect_parse_fails(const uint8_t *d, size_t n, const char *needle)
{
	struct wire_udpm m;
	const char *why = NULL;
	if (wire_udpm_parse(d, n, &m, &why))
		fail_msg("a %zu-byte datagram parsed (expected '%s')", n, needle);
	assert_non_null(why);
	if (strstr(why, needle) == NULL)
		fail_msg("why '%s' does not contain '%s'", why, needle);
}

static void test_udpm_parse(void **state)
{
	(void)state;
	uint8_t d[256];
	size_t n = wire_udpm_build(d, sizeof d, 0xfffffffe, "UNDULATE.CMD", payload, sizeof payload);
	struct wire_udpm m;
	const char *why = NULL;
	assert_true(wire_udpm_parse(d, n, &m, &why));
	assert_int_equal(m.seqno, 0xfffffffe);
	assert_string_equal(m.channel, "UNDULATE.CMD");
	assert_ptr_equal(m.channel, (const char *)d + 8);
	assert_ptr_equal(m.payload, d + 8 + 13);
	assert_int_equal(m.payload_len, sizeof payload);
	assert_memory_equal(m.payload, payload, sizeof payload);
	/* no payload at all is a message (of 0 bytes) */
	n = wire_udpm_build(d, sizeof d, 5, "X", payload, 0);
	assert_int_equal(n, 10);
	assert_true(wire_udpm_parse(d, n, &m, &why));
	assert_string_equal(m.channel, "X");
	assert_int_equal(m.payload_len, 0);
	assert_ptr_equal(m.payload, d + 10);
}

static void test_udpm_parse_refuses(void **state)
{
	(void)state;
	uint8_t d[256];
	/* shorter than the two header words */
	const uint8_t hdr[] = { 'L', 'C', '0', '2', 0, 0, 0, 1, 'a', 0 };
	for (size_t n = 0; n < 8; n++)
		expect_parse_fails(hdr, n, "shorter");
	expect_parse_fails(NULL, 0, "shorter");
	/* magic: a fragment ("LC03") and anything else */
	memcpy(d, hdr, sizeof hdr);
	d[3] = '3';
	expect_parse_fails(d, sizeof hdr, "magic");
	d[3] = '2';
	d[0] = 'l';
	expect_parse_fails(d, sizeof hdr, "magic");
	/* the channel: empty, unterminated, too long */
	expect_parse_fails(hdr, 8, "channel");                 /* nothing after the header */
	const uint8_t empty[] = { 'L', 'C', '0', '2', 0, 0, 0, 1, 0, 'p' };
	expect_parse_fails(empty, sizeof empty, "channel");
	const uint8_t unterminated[] = { 'L', 'C', '0', '2', 0, 0, 0, 1, 'a', 'b', 'c' };
	expect_parse_fails(unterminated, sizeof unterminated, "channel");
	memcpy(d, hdr, 8);
	memset(d + 8, 'c', 200);
	d[8 + WIRE_CHANNEL_MAX] = '\0';                        /* 64 bytes, then the NUL */
	expect_parse_fails(d, 8 + WIRE_CHANNEL_MAX + 1 + 4, "channel");
	memset(d + 8, 'c', 200);                               /* no NUL within 200 bytes */
	expect_parse_fails(d, 208, "channel");
	/* the longest: 63 bytes and the NUL */
	d[8 + WIRE_CHANNEL_MAX - 1] = '\0';
	struct wire_udpm m;
	const char *why;
	assert_true(wire_udpm_parse(d, 8 + WIRE_CHANNEL_MAX + 3, &m, &why));
	assert_int_equal(strlen(m.channel), WIRE_CHANNEL_MAX - 1);
	assert_int_equal(m.payload_len, 3);
	/* the channel's NUL exactly at the datagram's end: an empty payload */
	assert_true(wire_udpm_parse(d, 8 + WIRE_CHANNEL_MAX, &m, &why));
	assert_int_equal(m.payload_len, 0);
	/* ... one byte short of it: unterminated */
	expect_parse_fails(d, 8 + WIRE_CHANNEL_MAX - 1, "channel");
}

/* ---- udpm fragments ------------------------------------------------------------------------ */

/* LCM 1.3.1's lcm2_header_long_t, written out by hand (lcm_udpm.c): magic
 * "LC03", seqno 7, msg_size 70000, offset 0, fragment 0 of 2, "CH\0", data. */
static const uint8_t frag0[] = { 0x4c, 0x43, 0x30, 0x33, 0, 0, 0, 7, 0, 1, 0x11, 0x70, 0, 0, 0, 0,
				 0, 0, 0, 2, 'C', 'H', 0, 0xaa, 0xbb };

static void test_udpm_frag_parse(void **state)
{
	(void)state;
	struct wire_udpm_frag f;
	const char *why = NULL;
	assert_true(wire_udpm_frag_parse(frag0, sizeof frag0, &f, &why));
	assert_int_equal(f.seqno, 7);
	assert_int_equal(f.msg_size, 70000);
	assert_int_equal(f.offset, 0);
	assert_int_equal(f.fragment_no, 0);
	assert_int_equal(f.fragments, 2);
	assert_string_equal(f.channel, "CH");
	assert_int_equal(f.data_len, 2);
	assert_int_equal(f.data[0], 0xaa);
	/* fragment 1 at offset 65000: no channel, the rest is data */
	uint8_t d[sizeof frag0];
	memcpy(d, frag0, sizeof d);
	d[14] = 0xfd, d[15] = 0xe8; /* offset 0x0000fde8 = 65000 */
	d[17] = 1;
	assert_true(wire_udpm_frag_parse(d, sizeof d, &f, &why));
	assert_int_equal(f.offset, 65000);
	assert_int_equal(f.fragment_no, 1);
	assert_null(f.channel);
	assert_int_equal(f.data_len, sizeof d - WIRE_UDPM_FRAG_HEADER);
}

static void test_udpm_frag_refuses(void **state)
{
	(void)state;
	struct wire_udpm_frag f;
	const char *why = NULL;
	uint8_t d[sizeof frag0];
	assert_false(wire_udpm_frag_parse(frag0, WIRE_UDPM_FRAG_HEADER - 1, &f, &why));
	assert_non_null(strstr(why, "shorter"));
	memcpy(d, frag0, sizeof d);
	d[3] = 0x32; /* LC02 */
	assert_false(wire_udpm_frag_parse(d, sizeof d, &f, &why));
	assert_non_null(strstr(why, "magic"));
	memcpy(d, frag0, sizeof d);
	d[17] = 2; /* fragment 2 of 2 */
	assert_false(wire_udpm_frag_parse(d, sizeof d, &f, &why));
	assert_non_null(strstr(why, "beyond"));
	d[19] = 0; d[17] = 0; /* fragment 0 of 0 */
	assert_false(wire_udpm_frag_parse(d, sizeof d, &f, &why));
	/* fragment 0 whose channel is not ended, or empty */
	assert_false(wire_udpm_frag_parse(frag0, WIRE_UDPM_FRAG_HEADER + 2, &f, &why));
	assert_non_null(strstr(why, "channel"));
	memcpy(d, frag0, sizeof d);
	d[20] = 0;
	assert_false(wire_udpm_frag_parse(d, sizeof d, &f, &why));
	assert_non_null(strstr(why, "channel"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_put_golden),
		cmocka_unit_test(test_round_trip),
		cmocka_unit_test(test_short_reads),
		cmocka_unit_test(test_strings_forged),
		cmocka_unit_test(test_strings_cap),
		cmocka_unit_test(test_writer_full),
		cmocka_unit_test(test_udpm_build_golden),
		cmocka_unit_test(test_udpm_parse),
		cmocka_unit_test(test_udpm_parse_refuses),
		cmocka_unit_test(test_udpm_frag_parse),
		cmocka_unit_test(test_udpm_frag_refuses),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
