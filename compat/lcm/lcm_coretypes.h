/*
 * compat/lcm/lcm_coretypes.h — LCM 1.3.1's core types with decoders that do
 * not trust the wire.
 *
 * lcm-gen's generated decoders trust every length a message states:
 *  - a string's length is malloc'd and copied as given (negative, huge);
 *  - an array's count n reaches lcm_malloc(sizeof(T) * n) before anything
 *    checks it: n = 0x7fffffff fails the malloc and the decoder writes into
 *    the NULL it got; n = 200000 mallocs megabytes that a failed decode never
 *    frees;
 *  - the primitive decoders check `maxlen < sizeof(T) * n` in int, which
 *    wraps (8 * 0x20000001 == 8) and lets them read far past the packet, and
 *    a negative n becomes a huge memcpy.
 * Only the generated code (liblcmtypes) is compiled with this directory first
 * on the include path. This header wraps the packaged one and replaces those
 * functions with checked ones: counts must be >= 0 and fit in what is left of
 * the buffer (in 64-bit arithmetic); a string must be >= 1 long, fit, and end
 * in the NUL the encoder writes; every allocation goes through lcmdec_alloc()
 * (compat/lcm/lcmdec.c), which, inside lcmdec_decode(), bounds the bytes one
 * message may allocate by its length and remembers them, so a decode that
 * fails frees everything it took, and one that would allocate past the bound
 * is abandoned before the allocation. Programs decode through lcmdec_decode()
 * (compat/lcm/lcmdec.h), never the generated *_decode or *_subscribe.
 */
#ifndef UNDULATE_COMPAT_LCM_CORETYPES_H
#define UNDULATE_COMPAT_LCM_CORETYPES_H

#define lcm_malloc lcm_malloc_unchecked
#define __byte_decode_array __byte_decode_array_unchecked
#define __int8_t_decode_array __int8_t_decode_array_unchecked
#define __int16_t_decode_array __int16_t_decode_array_unchecked
#define __int32_t_decode_array __int32_t_decode_array_unchecked
#define __int64_t_decode_array __int64_t_decode_array_unchecked
#define __float_decode_array __float_decode_array_unchecked
#define __double_decode_array __double_decode_array_unchecked
#define __string_decode_array __string_decode_array_unchecked
#include_next <lcm/lcm_coretypes.h>
#undef lcm_malloc
#undef __byte_decode_array
#undef __int8_t_decode_array
#undef __int16_t_decode_array
#undef __int32_t_decode_array
#undef __int64_t_decode_array
#undef __float_decode_array
#undef __double_decode_array
#undef __string_decode_array

/* compat/lcm/lcmdec.c: zeroed memory, bounded and remembered inside a decode */
void *lcmdec_alloc(size_t size);

static inline void *lcm_malloc(size_t sz)
{
	return sz != 0 ? lcmdec_alloc(sz) : NULL;
}

/* elements of `size` bytes each fit in maxlen (no int overflow, none negative) */
static inline int lcmdec_fits(int maxlen, int elements, int size)
{
	return elements >= 0 && maxlen >= 0 && (int64_t)elements * size <= (int64_t)maxlen;
}

#define LCMDEC_CHECKED(T, unchecked, size)                                                            \
	static inline int __##T##_decode_array(const void *_buf, int offset, int maxlen, T *p, int elements) \
	{                                                                                             \
		if (!lcmdec_fits(maxlen, elements, size))                                             \
			return -1;                                                                    \
		return unchecked(_buf, offset, maxlen, p, elements);                                  \
	}
LCMDEC_CHECKED(uint8_t, __byte_decode_array_unchecked, 1)
LCMDEC_CHECKED(int8_t, __int8_t_decode_array_unchecked, 1)
LCMDEC_CHECKED(int16_t, __int16_t_decode_array_unchecked, 2)
LCMDEC_CHECKED(int32_t, __int32_t_decode_array_unchecked, 4)
LCMDEC_CHECKED(int64_t, __int64_t_decode_array_unchecked, 8)
LCMDEC_CHECKED(float, __float_decode_array_unchecked, 4)
LCMDEC_CHECKED(double, __double_decode_array_unchecked, 8)
#undef LCMDEC_CHECKED
/* lcm-gen calls the byte decoder __byte_decode_array */
#define __byte_decode_array __uint8_t_decode_array

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
		p[element] = (char *)lcm_malloc((size_t)length);
		if (p[element] == NULL)
			return -1;
		memcpy(p[element], (const char *)_buf + offset + pos, (size_t)length);
		pos += length;
	}
	return pos;
}

#endif
