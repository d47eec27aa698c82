/*
 * dxl_lex.c — the feeding and resynchronisation both parsers share
 * (dxl_lex.h). Pure code: no I/O, no clock, no allocation.
 */
#include "dxl_lex.h"

#include <string.h>

#include "dxl.h"

void dxl_lex_drop(uint8_t *buf, size_t *have, size_t n)
{
	memmove(buf, buf + n, *have - n);
	*have -= n;
}

bool dxl_lex_sync(uint8_t *buf, size_t *have, const uint8_t *lead, size_t nlead, uint32_t *dropped)
{
	size_t i = 0;
	while (i < nlead && i < *have) {
		if (buf[i] == lead[i]) {
			i++;
			continue;
		}
		/* not a header start: plain garbage, dropped silently but counted */
		(*dropped)++;
		dxl_lex_drop(buf, have, 1);
		i = 0;
	}
	return *have >= nlead;
}

int dxl_lex_feed(void *parser, uint8_t *buf, size_t *have, dxl_lex_scan_fn scan, void *out,
                 const uint8_t *data, size_t n, size_t *used)
{
	size_t i = 0;
	if (data == NULL)
		n = 0;
	for (;;) {
		int r = scan(parser, out);
		if (r != DXL_NEED_MORE || i == n) {
			if (used)
				*used = i;
			return r;
		}
		buf[(*have)++] = data[i++];
	}
}
