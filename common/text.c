/* text.c — see text.h. */
#include "text.h"

#include <stdio.h>
#include <string.h>

char *text_sanitize(char *dst, size_t cap, const char *src)
{
	static const char hex[] = "0123456789abcdef";
	const char *ellipsis = "...";
	size_t o = 0;
	if (cap == 0)
		return dst;
	if (src == NULL)
		src = "";
	for (const unsigned char *p = (const unsigned char *)src; *p; p++) {
		char piece[5];
		size_t n;
		if (*p >= 0x20 && *p <= 0x7e && *p != '\\') {
			piece[0] = (char)*p;
			n = 1;
		} else {
			piece[0] = '\\';
			piece[1] = 'x';
			piece[2] = hex[*p >> 4];
			piece[3] = hex[*p & 15];
			n = 4;
		}
		/* keep room for the ellipsis unless this is the last byte */
		size_t room = p[1] ? cap - 1 - strlen(ellipsis) : cap - 1;
		if (cap <= strlen(ellipsis) + 1 || o + n > room) {
			if (cap > strlen(ellipsis) + 1) {
				memcpy(dst + o, ellipsis, strlen(ellipsis));
				o += strlen(ellipsis);
			}
			break;
		}
		memcpy(dst + o, piece, n);
		o += n;
	}
	dst[o] = '\0';
	return dst;
}

char *text_line(char *dst, size_t cap, const char *src)
{
	size_t o = 0;
	if (cap == 0)
		return dst;
	for (const unsigned char *p = (const unsigned char *)(src != NULL ? src : ""); *p && o + 1 < cap; p++)
		dst[o++] = *p >= 0x20 && *p <= 0x7e ? (char)*p : '?';
	dst[o] = '\0';
	return dst;
}

bool text_is_name(const char *s, size_t max)
{
	size_t n = 0;
	if (s == NULL || *s == '\0')
		return false;
	for (; s[n]; n++) {
		char ch = s[n];
		bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
		          ch == '_' || ch == '-';
		if (!ok || n >= max)
			return false;
	}
	return true;
}
