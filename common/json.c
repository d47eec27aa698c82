/* json.c — see json.h. */
#include "json.h"

#include <math.h>
#include <stddef.h>

/* Length of the well-formed UTF-8 sequence at p (RFC 3629: no overlong forms,
 * no surrogates, nothing above U+10FFFF), or 0 if there is none. */
static size_t json_utf8_len(const unsigned char *p)
{
	unsigned char lo = 0x80, hi = 0xbf;
	size_t n;
	if (p[0] < 0x80)
		return 1;
	if (p[0] >= 0xc2 && p[0] <= 0xdf)
		n = 2;
	else if (p[0] >= 0xe0 && p[0] <= 0xef)
		n = 3;
	else if (p[0] >= 0xf0 && p[0] <= 0xf4)
		n = 4;
	else
		return 0;
	/* the second byte's range is what rules out the forbidden code points */
	if (p[0] == 0xe0)
		lo = 0xa0;
	else if (p[0] == 0xed)
		hi = 0x9f;
	else if (p[0] == 0xf0)
		lo = 0x90;
	else if (p[0] == 0xf4)
		hi = 0x8f;
	if (p[1] < lo || p[1] > hi)
		return 0;
	for (size_t k = 2; k < n; k++)
		if (p[k] < 0x80 || p[k] > 0xbf)
			return 0;
	return n;
}

void json_write_string(FILE *f, const char *s)
{
	fputc('"', f);
	const unsigned char *p = (const unsigned char *)(s != NULL ? s : "");
	while (*p) {
		size_t n = json_utf8_len(p);
		if (n == 0) {
			fputs("\\ufffd", f);
			n = 1;
		} else if (*p == '"' || *p == '\\') {
			fprintf(f, "\\%c", *p);
		} else if (*p < 0x20) {
			fprintf(f, "\\u%04x", *p);
		} else {
			fwrite(p, 1, n, f);
		}
		p += n;
	}
	fputc('"', f);
}

void json_init(struct json *j, FILE *f, int digits)
{
	*j = (struct json){ .f = f, .digits = digits > 0 && digits <= 17 ? digits : JSON_DEFAULT_DIGITS,
	                    .ok = true };
}

bool json_end(const struct json *j)
{
	return j->ok && j->depth == 0 && j->has_items[0] && !j->after_key && !ferror(j->f);
}

/* Before any value: the comma it needs, or false (and the writer stopped)
 * when a value may not go here. */
static bool json_value_prefix(struct json *j)
{
	if (!j->ok)
		return false;
	if (j->after_key) {
		j->after_key = false;
		return true;
	}
	if (j->in_object[j->depth] || (j->depth == 0 && j->has_items[0])) {
		j->ok = false;   /* a value without its key, or a second document */
		return false;
	}
	if (j->has_items[j->depth])
		fputc(',', j->f);
	j->has_items[j->depth] = true;
	return true;
}

void json_key(struct json *j, const char *key)
{
	if (!j->ok)
		return;
	if (!j->in_object[j->depth] || j->after_key) {
		j->ok = false;
		return;
	}
	if (j->has_items[j->depth])
		fputc(',', j->f);
	j->has_items[j->depth] = true;
	json_write_string(j->f, key);
	fputc(':', j->f);
	j->after_key = true;
}

static void json_open(struct json *j, bool object)
{
	if (!json_value_prefix(j))
		return;
	if (j->depth == JSON_MAX_DEPTH) {
		j->ok = false;
		return;
	}
	fputc(object ? '{' : '[', j->f);
	j->depth++;
	j->in_object[j->depth] = object;
	j->has_items[j->depth] = false;
}

static void json_close(struct json *j, bool object)
{
	if (!j->ok)
		return;
	if (j->depth == 0 || j->in_object[j->depth] != object || j->after_key) {
		j->ok = false;
		return;
	}
	fputc(object ? '}' : ']', j->f);
	j->depth--;
}

void json_object_begin(struct json *j)
{
	json_open(j, true);
}

void json_object_end(struct json *j)
{
	json_close(j, true);
}

void json_array_begin(struct json *j)
{
	json_open(j, false);
}

void json_array_end(struct json *j)
{
	json_close(j, false);
}

void json_string(struct json *j, const char *s)
{
	if (json_value_prefix(j))
		json_write_string(j->f, s);
}

void json_number(struct json *j, double v)
{
	if (!json_value_prefix(j))
		return;
	if (isfinite(v))
		fprintf(j->f, "%.*g", j->digits, v);
	else
		fputs("null", j->f);
}

void json_int(struct json *j, long long v)
{
	if (json_value_prefix(j))
		fprintf(j->f, "%lld", v);
}

void json_bool(struct json *j, bool v)
{
	if (json_value_prefix(j))
		fputs(v ? "true" : "false", j->f);
}

void json_null(struct json *j)
{
	if (json_value_prefix(j))
		fputs("null", j->f);
}

void json_field_string(struct json *j, const char *key, const char *s)
{
	json_key(j, key);
	json_string(j, s);
}

void json_field_number(struct json *j, const char *key, double v)
{
	json_key(j, key);
	json_number(j, v);
}

void json_field_int(struct json *j, const char *key, long long v)
{
	json_key(j, key);
	json_int(j, v);
}

void json_field_bool(struct json *j, const char *key, bool v)
{
	json_key(j, key);
	json_bool(j, v);
}
