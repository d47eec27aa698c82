/*
 * text.h — text that came from outside (a command's source or parameter name,
 * a robot name on the network) made safe to log and to publish: one line of
 * printable ASCII, bounded. A newline followed by "<0>" in a journal stream
 * would otherwise forge a line at emergency priority.
 */
#ifndef UNDULATE_COMMON_TEXT_H
#define UNDULATE_COMMON_TEXT_H

#include <stdbool.h>
#include <stddef.h>

/* Copies src (NULL: "") into dst, cap bytes with the NUL (cap >= 8). Bytes
 * outside 0x20..0x7e, and the backslash, become \xNN; a result that does not
 * fit is cut at a character boundary and ends with "...". Returns dst. */
char *text_sanitize(char *dst, size_t cap, const char *src);

/* One printable line for a text that is ours but may quote text from outside
 * (already sanitized, or not): bytes outside 0x20..0x7e become '?', nothing
 * is escaped a second time; cut to cap - 1 bytes. Returns dst. */
char *text_line(char *dst, size_t cap, const char *src);

/* True when s is non-empty, at most max bytes, and only [A-Za-z0-9_-]: the
 * names that may become file names and LCM channel prefixes. */
bool text_is_name(const char *s, size_t max);

#endif
