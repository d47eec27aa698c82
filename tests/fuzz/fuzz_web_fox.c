/*
 * fuzz_web_fox.c — libFuzzer target for what a Foxglove client of
 * undulate-web sends and what the network sends it (tools/web/fox.h):
 *
 * Input: one byte; bit 0 clear: the rest is a client's text operation,
 * parsed by fox_op_parse (lejp); set: bits 1-3 pick a channel type, the rest
 * is an LCM payload on that channel, decoded through lcmdec and written as
 * JSON by fox_encode (as foxsrv.c does for a subscription).
 * Invariants (abort() on violation): a parsed op never holds more than
 * FOX_OP_ITEMS items and a refused one says why; a message that decodes is
 * always written whole, as one object. ASan/UBSan find the rest.
 *
 *   make fuzz-build && build/fuzz/fuzz_web_fox tests/fuzz/seeds/fuzz_web_fox
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tools/web/fox.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define CHECK(cond) do { if (!(cond)) abort(); } while (0)

static void fuzz_op(const uint8_t *data, size_t size)
{
	static struct fox_op op;
	char why[256] = "";
	if (fox_op_parse((const char *)data, size, &op, why, sizeof why))
		CHECK(op.n >= 0 && op.n <= FOX_OP_ITEMS && op.kind <= FOX_OP_OTHER);
	else
		CHECK(why[0] != '\0');
}

static void fuzz_message(unsigned which, const uint8_t *data, size_t size)
{
	static const char *const channels[] = { "r.STATE", "r.BUS", "r.PARAMS", "r.EVENT",
	                                        "SIM.TRUTH", "SIM.COLLISION", "SIM.WORLD", "SIM.REPLY" };
	const struct fox_type *t = fox_kind_of(channels[which % 8]);
	static union lcmdec_any u;
	if (lcmdec_decode(t->dec, data, size, &u) != LCMDEC_OK)
		return;
	char *out = NULL;
	size_t n = 0;
	FILE *f = open_memstream(&out, &n);
	CHECK(f != NULL);
	CHECK(fox_encode(t, &u, f));
	fclose(f);
	CHECK(n >= 2 && out[0] == '{' && out[n - 1] == '}' && strlen(out) == n);
	free(out);
	lcmdec_free(t->dec, &u);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size == 0)
		return 0;
	if (data[0] & 1)
		fuzz_message(data[0] >> 1, data + 1, size - 1);
	else
		fuzz_op(data + 1, size - 1);
	return 0;
}
