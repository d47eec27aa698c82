/*
 * json.h — a streaming JSON writer for the tools' machine-readable output
 * (undulate-top --json, undulate-analyze's summary.json). It owns the three
 * things hand-written fprintf gets wrong: commas between items, string
 * escaping, and numbers JSON cannot hold.
 *
 * Output rules:
 *   strings  '"' and '\' are escaped, control bytes (< 0x20) become \u00XX,
 *            and bytes that are not valid UTF-8 (names and event texts come
 *            from the network) become \ufffd, so the document always parses.
 *            A NULL string is written as "".
 *   numbers  "%.*g" with the writer's significant digits; NaN and ±inf, which
 *            JSON has no spelling for, are written as null.
 *   layout   one line, no spaces; the caller adds a newline after the value.
 *
 * Two sinks, the same bytes: a FILE (json_init), or a caller's buffer
 * (json_init_buf), which spares stdio's per-call cost where a document is
 * written thousands of times a second (undulate-web's Foxglove messages and
 * frames). A buffer too small for the document stops the output there, and
 * json_end says so, as a FILE's write error does.
 *
 * No allocation: nesting is tracked in a fixed array (JSON_MAX_DEPTH). Misuse
 * (a value in an object without a key, a key in an array, closing what is not
 * open, nesting too deep) stops all further output and is reported by
 * json_end; it is a bug of the caller, found by its tests.
 */
#ifndef UNDULATE_COMMON_JSON_H
#define UNDULATE_COMMON_JSON_H

#include <stdbool.h>
#include <stdio.h>

/* Deepest nesting of objects and arrays; top's snapshot needs 5. */
#define JSON_MAX_DEPTH 8
/* Significant digits when json_init is given 0: more than any measurement
 * here resolves, few enough that 0.1 prints as 0.1. */
#define JSON_DEFAULT_DIGITS 12

struct json {
	FILE *f;                                /* NULL: the buffer below */
	char *buf;
	size_t cap, len;                        /* the buffer's size, the bytes in it */
	bool full;                              /* something did not fit in the buffer */
	int digits;
	int depth;                              /* open containers */
	bool ok;                                /* false after a misuse */
	bool after_key;                         /* a key waits for its value */
	bool in_object[JSON_MAX_DEPTH + 1];     /* per level: object (else array) */
	bool has_items[JSON_MAX_DEPTH + 1];     /* per level: a comma goes first */
};

/* Starts one document on f. digits: significant digits of numbers (1..17;
 * 0: JSON_DEFAULT_DIGITS). */
void json_init(struct json *j, FILE *f, int digits);

/* Starts one document in buf (cap bytes), kept NUL-terminated: it holds at
 * most cap - 1 bytes of the document (what fmemopen's "w" mode holds). */
void json_init_buf(struct json *j, char *buf, size_t cap, int digits);

/* Bytes written into the buffer so far (0 for a FILE). */
size_t json_len(const struct json *j);

/* True when exactly one complete value was written, every container was
 * closed, nothing was misused and the sink took all of it (no write error on
 * f, nothing left out of the buffer). Writes nothing. */
bool json_end(const struct json *j);

void json_object_begin(struct json *j);
void json_object_end(struct json *j);
void json_array_begin(struct json *j);
void json_array_end(struct json *j);

/* The key of the next value; only inside an object. */
void json_key(struct json *j, const char *key);

/* Values: after a key, inside an array, or as the whole document. */
void json_string(struct json *j, const char *s);
void json_number(struct json *j, double v);
void json_int(struct json *j, long long v);
void json_bool(struct json *j, bool v);
void json_null(struct json *j);

/* key and value in one call, the common case in an object. */
void json_field_string(struct json *j, const char *key, const char *s);
void json_field_number(struct json *j, const char *key, double v);
void json_field_int(struct json *j, const char *key, long long v);
void json_field_bool(struct json *j, const char *key, bool v);

/* Writes s as a quoted JSON string (the rules above) outside any writer. */
void json_write_string(FILE *f, const char *s);

#endif
