/* alog.h — reading and writing LCM log files (lcm-logger's lcm_eventlog
 * format) with the checks the analyser needs: a missing file, a file that is
 * not an LCM log, and a log cut short are told apart. */
#ifndef UNDULATE_ANALYZE_ALOG_H
#define UNDULATE_ANALYZE_ALOG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <lcm/eventlog.h>

/* Every lcm_eventlog event starts with this sync word (big-endian). */
#define ALOG_MAGIC 0xEDA1DA01u

struct alog_reader {
	lcm_eventlog_t *log;
	const char *path;
	bool xz;            /* an xz-compressed log (PATH.xz, as make demo keeps it) */
	void *xz_state;     /* its decoder (alog.c), owned by the stream */
	int64_t file_size;  /* bytes (of the decompressed log, for xz: known at its end) */
	int64_t good_end;   /* offset just past the last complete event */
	int64_t events;     /* complete events read so far */
	bool ended;
};

/* Opens PATH for reading: an LCM log, or one compressed by xz (read as it
 * is decompressed, never written out). Returns 0, or -1 with a one-line
 * reason in ERR (missing, unreadable, empty, not an LCM log). */
int alog_open(struct alog_reader *r, const char *path, char *err, size_t errlen);
/* The next complete event (free with lcm_eventlog_free_event), or NULL at the
 * end of the file or at the first damaged/incomplete event. */
lcm_eventlog_event_t *alog_next(struct alog_reader *r);
/* After alog_next returned NULL: true if bytes were left that did not form a
 * complete event (a truncated or damaged log). */
bool alog_damaged(const struct alog_reader *r);
void alog_close(struct alog_reader *r);

struct alog_writer {
	lcm_eventlog_t *log;
	int64_t events;
	bool buffered;      /* alog_writer_buffer(): events wait for alog_flush */
	int64_t unflushed;  /* events written since the last flush (buffered) */
	char *buf;          /* the stream's buffer (buffered), freed after it */
};
/* Creates PATH for writing (--record, --synth). Its directory must be ours
 * and no one else's to write (common/outdir.h); what has its name (a file, a
 * link, a FIFO) is replaced, never written through or opened. Returns 0, or
 * -1 with a one-line reason in ERR. */
int alog_writer_open(struct alog_writer *w, const char *path, char *err, size_t errlen);
/* Appends one event; TIMESTAMP in µs (the receive time lcm-logger records). */
int alog_write(struct alog_writer *w, const char *channel, int64_t timestamp,
	       const void *data, int32_t len);
int alog_writer_close(struct alog_writer *w);
/* From now on events gather in an ALOG_WRITE_BUFFER-byte buffer and reach the
 * file when it is full, at alog_flush() and at alog_writer_close(), instead of
 * one write() each (liblcm's writer flushes every event: at 70 000 events a
 * run, one system call in seven of a lockstep run's recorder). Call it right
 * after alog_writer_open, before any event. */
void alog_writer_buffer(struct alog_writer *w);
/* Writes out what is buffered. 0, or -1 with errno. */
int alog_flush(struct alog_writer *w);
#define ALOG_WRITE_BUFFER (1 << 20)

/* ALOG_DEFINE_WRITER(robot_state_t) defines
 *   static int alog_write_robot_state_t(struct alog_writer *, const char *channel,
 *                                       int64_t timestamp, const undulate_robot_state_t *)
 * which encodes with the lcm-gen code and appends the event. */
#define ALOG_DEFINE_WRITER(T)                                                             \
	static int alog_write_##T(struct alog_writer *w, const char *channel, int64_t ts, \
				  const undulate_##T *msg)                                \
	{                                                                                 \
		int size = undulate_##T##_encoded_size(msg);                              \
		void *buf = malloc((size_t)size);                                         \
		if (!buf)                                                                 \
			return -1;                                                        \
		int rc = undulate_##T##_encode(buf, 0, size, msg) == size                 \
				 ? alog_write(w, channel, ts, buf, size)                  \
				 : -1;                                                    \
		free(buf);                                                                \
		return rc;                                                                \
	}

#endif
