/* text.c — see text.h. */
#include "text.h"

#include <stdio.h>
#include <string.h>

static bool text_printable(unsigned char b)
{
	return b >= 0x20 && b <= 0x7e && b != '\\';
}

char *text_sanitize(char *dst, size_t cap, const char *src)
{
	static const char hex[] = "0123456789abcdef";
	static const char ellipsis[] = "...";
	const size_t elen = sizeof ellipsis - 1;
	size_t o = 0, need = 0;
	if (cap == 0)
		return dst;
	if (src == NULL)
		src = "";
	for (const unsigned char *p = (const unsigned char *)src; *p; p++)
		need += text_printable(*p) ? 1 : 4;
	/* only a text that does not fit is cut, and then room is kept for the ellipsis */
	bool cut = need > cap - 1;
	size_t room = !cut ? cap - 1 : cap - 1 > elen ? cap - 1 - elen : 0;
	for (const unsigned char *p = (const unsigned char *)src; *p; p++) {
		char piece[4];
		size_t n;
		if (text_printable(*p)) {
			piece[0] = (char)*p;
			n = 1;
		} else {
			piece[0] = '\\';
			piece[1] = 'x';
			piece[2] = hex[*p >> 4];
			piece[3] = hex[*p & 15];
			n = 4;
		}
		if (o + n > room)
			break;
		memcpy(dst + o, piece, n);
		o += n;
	}
	if (cut && o + elen < cap) {
		memcpy(dst + o, ellipsis, elen);
		o += elen;
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
