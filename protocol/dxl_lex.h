/*
 * dxl_lex.h — what the Protocol 1.0 and 2.0 parsers share (internal to
 * protocol/). Both take one byte at a time and rescan their buffer after
 * each, so a packet is reported the moment its last byte arrives and *used
 * never runs past it; both resynchronise the same way (gpsd's rule: on an
 * unexpected byte, drop it and go back to the start state). Only the header
 * and the checks on it differ, and those stay in dxl.c and dxl2.c.
 */
#ifndef UNDULATE_DXL_LEX_H
#define UNDULATE_DXL_LEX_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Remove the first n of *have buffered bytes. */
void dxl_lex_drop(uint8_t *buf, size_t *have, size_t n);

/* Drop bytes, one at a time, until the buffer starts with as much of the
 * protocol's header `lead` as it holds; each counts in *dropped. Returns
 * true when the whole of `lead` is buffered (else the caller needs more). */
bool dxl_lex_sync(uint8_t *buf, size_t *have, const uint8_t *lead, size_t nlead, uint32_t *dropped);

/* A parser's look at what it has buffered: DXL_NEED_MORE (only while the
 * buffer is shorter than the packet it expects), DXL_FRAME (into out), or a
 * negative dxl_status after dropping one byte. */
typedef int (*dxl_lex_scan_fn)(void *parser, void *out);

/* The feeding loop of dxl_parser_feed and dxl2_parser_feed: scan before
 * taking each byte, because bytes left over from an earlier error may
 * already hold a whole packet. scan() asks for more only while the buffer is
 * shorter than the packet it expects, so there is always room in buf. */
int dxl_lex_feed(void *parser, uint8_t *buf, size_t *have, dxl_lex_scan_fn scan, void *out,
                 const uint8_t *data, size_t n, size_t *used);

#endif
