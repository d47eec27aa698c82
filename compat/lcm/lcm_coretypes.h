/*
 * compat/lcm/lcm_coretypes.h — LCM 1.3.1's core types with a string decoder
 * that does not trust the wire.
 *
 * lcm-gen's generated decoders call __string_decode_array(), which in LCM
 * 1.3.1 mallocs whatever length a string claims and copies that many bytes:
 * one malformed message (a negative or huge length) crashes any program that
 * decodes it. Only the generated code (liblcmtypes) is compiled with this
 * directory first on the include path; it wraps the packaged header and
 * replaces that one function with a checked one: the length must be >= 1,
 * fit in what is left of the buffer, and end in the NUL the encoder writes.
 * A bad string fails the decode (-1) like any other short buffer.
 */
#ifndef UNDULATE_COMPAT_LCM_CORETYPES_H
#define UNDULATE_COMPAT_LCM_CORETYPES_H

#define __string_decode_array __string_decode_array_unchecked
#include_next <lcm/lcm_coretypes.h>
#undef __string_decode_array

static inline int __string_decode_array(const void *_buf, int offset, int maxlen, char **p, int elements)
{
	int pos = 0, thislen;
	for (int element = 0; element < elements; element++) {
		int32_t length;
		thislen = __int32_t_decode_array(_buf, offset + pos, maxlen - pos, &length, 1);
		if (thislen < 0)
			return thislen;
		pos += thislen;
		p[element] = NULL;
		if (length < 1 || length > maxlen - pos || ((const char *)_buf)[offset + pos + length - 1] != '\0')
			return -1;
		p[element] = (char *)malloc((size_t)length);
		if (p[element] == NULL)
			return -1;
		memcpy(p[element], (const char *)_buf + offset + pos, (size_t)length);
		pos += length;
	}
	return pos;
}

#endif
