/*
 * fuzz_records.h — the input of the record-driven fuzz targets
 * (fuzz_daemon_commands, fuzz_web_feed): records of a selector byte, a
 * 16-bit big-endian length and that many bytes, the last one cut at the
 * input's end.
 */
#ifndef UNDULATE_FUZZ_RECORDS_H
#define UNDULATE_FUZZ_RECORDS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The record at *pos: its selector, bytes and length; *pos past it. False
 * when fewer than a header's 3 bytes are left. */
static inline bool fuzz_next_record(const uint8_t *data, size_t size, size_t *pos, uint8_t *sel,
                                    const uint8_t **rec, size_t *len)
{
	if (*pos + 3 > size)
		return false;
	*sel = data[*pos];
	*len = (size_t)data[*pos + 1] << 8 | data[*pos + 2];
	*pos += 3;
	if (*len > size - *pos)
		*len = size - *pos;
	*rec = data + *pos;
	*pos += *len;
	return true;
}

#endif
