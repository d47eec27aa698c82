/* alog.c — see alog.h. */
#define _GNU_SOURCE   /* fopencookie: an xz log read as a stream */
#include "alog.h"

#include "outdir.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <lzma.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* xz's stream header magic (its file format, section 2.1.1.1). */
static const uint8_t alog_xz_magic[6] = { 0xFD, '7', 'z', 'X', 'Z', 0x00 };
/* Bytes read from the compressed file at a time. */
#define ALOG_XZ_CHUNK 65536
/* Decompressed bytes kept behind the position: liblcm 1.3.1's reader seeks
 * back once per event (by up to its stdio buffer, 8 KiB, and a few bytes). */
#define ALOG_XZ_BACK (64 * 1024)

/* An xz-compressed log, read through a stdio stream of its decompressed
 * bytes (fopencookie), so that liblcm's reader takes it as it takes a file:
 * make demo keeps its logs compressed (a third of the size). The stream
 * goes forward, and back as far as ALOG_XZ_BACK. */
struct alog_xz {
	FILE *raw;
	lzma_stream s;
	bool raw_end;
	bool stream_end;
	int64_t decoded;   /* decompressed bytes so far: the end of back[] */
	int64_t pos;       /* where the reader is (<= decoded) */
	uint8_t in[ALOG_XZ_CHUNK];
	uint8_t back[ALOG_XZ_BACK];   /* the last bytes decoded, a ring indexed by offset */
};

/* Decodes up to n more bytes into out, kept in back[] too; 0 at the end. */
static size_t alog_xz_decode(struct alog_xz *x, uint8_t *out, size_t n)
{
	x->s.next_out = out;
	x->s.avail_out = n;
	while (x->s.avail_out > 0 && !x->stream_end) {
		if (x->s.avail_in == 0 && !x->raw_end) {
			size_t got = fread(x->in, 1, sizeof x->in, x->raw);
			x->raw_end = got == 0;
			x->s.next_in = x->in;
			x->s.avail_in = got;
		}
		lzma_ret r = lzma_code(&x->s, x->raw_end ? LZMA_FINISH : LZMA_RUN);
		if (r == LZMA_STREAM_END)
			x->stream_end = true;
		else if (r != LZMA_OK)
			break;   /* damaged or cut short: what came before is the log's */
	}
	size_t got = n - x->s.avail_out;
	for (size_t k = 0; k < got;) {
		size_t at = (size_t)(x->decoded % ALOG_XZ_BACK), m = ALOG_XZ_BACK - at < got - k ? ALOG_XZ_BACK - at : got - k;
		memcpy(x->back + at, out + k, m);
		k += m;
		x->decoded += (int64_t)m;
	}
	return got;
}

static ssize_t alog_xz_read(void *cookie, char *buf, size_t size)
{
	struct alog_xz *x = cookie;
	size_t done = 0;
	while (done < size) {
		if (x->pos < x->decoded) {   /* after a seek back: from the ring */
			size_t at = (size_t)(x->pos % ALOG_XZ_BACK);
			size_t m = size - done;
			if (m > (size_t)(x->decoded - x->pos))
				m = (size_t)(x->decoded - x->pos);
			if (m > ALOG_XZ_BACK - at)
				m = ALOG_XZ_BACK - at;
			memcpy(buf + done, x->back + at, m);
			done += m;
			x->pos += (int64_t)m;
			continue;
		}
		size_t got = alog_xz_decode(x, (uint8_t *)buf + done, size - done);
		if (got == 0)
			break;
		done += got;
		x->pos += (int64_t)got;
	}
	return (ssize_t)done;
}

static int alog_xz_seek(void *cookie, off64_t *off, int whence)
{
	struct alog_xz *x = cookie;
	int64_t to = whence == SEEK_SET ? (int64_t)*off : whence == SEEK_CUR ? x->pos + (int64_t)*off : -1;
	int64_t oldest = x->decoded > ALOG_XZ_BACK ? x->decoded - ALOG_XZ_BACK : 0;
	uint8_t skip[4096];
	while (to > x->decoded && alog_xz_decode(x, skip, to - x->decoded < (int64_t)sizeof skip
	                                                    ? (size_t)(to - x->decoded) : sizeof skip) > 0)
		;
	if (to < oldest || to > x->decoded) {
		errno = ESPIPE;
		return -1;
	}
	x->pos = to;
	*off = to;
	return 0;
}

static int alog_xz_close(void *cookie)
{
	struct alog_xz *x = cookie;
	lzma_end(&x->s);
	int rc = fclose(x->raw);
	free(x);
	return rc;
}

/* A plain log, read through a stdio stream of our own (fopencookie) over a
 * window of the file. liblcm 1.3's reader seeks back 4 bytes after every
 * event (fseeko), and glibc turns that seek into a system call (lseek to
 * where the descriptor already is), as it did ftello (alog_next): two an
 * event, 151 k for a 10-robot run's 75 k events; glibc also drops its buffer
 * at every seek of a cookie stream, which refills from the window here by
 * copying. The file is read in ALOG_WIN pieces; a seek within the window
 * costs no system call; one outside it (never, reading a log) seeks the
 * descriptor. A log read while it is recorded reads on as before. */
#define ALOG_WIN (256 * 1024)
/* Bytes kept before the read position when the window moves on: liblcm
 * seeks back 4 bytes, glibc by up to its buffer (8 KiB). */
#define ALOG_WIN_BACK (16 * 1024)
struct alog_plain {
	int fd;
	int64_t base;   /* the file offset of win[0] */
	size_t len;     /* bytes of the file in win[] */
	int64_t pos;    /* the stream's position */
	uint8_t win[ALOG_WIN];
};

/* More of the file into the window at pos: 0 at its end, -1 on an error. */
static ssize_t alog_plain_fill(struct alog_plain *p)
{
	if (p->pos < p->base || p->pos > p->base + (int64_t)p->len) {
		if (lseek(p->fd, (off_t)p->pos, SEEK_SET) < 0)
			return -1;
		p->base = p->pos;
		p->len = 0;
	} else if (p->len == ALOG_WIN) {
		size_t keep = (size_t)(p->base + (int64_t)p->len - p->pos) + ALOG_WIN_BACK;
		if (keep > p->len)
			keep = p->len;
		memmove(p->win, p->win + p->len - keep, keep);
		p->base += (int64_t)(p->len - keep);
		p->len = keep;
	}
	ssize_t n;
	do
		n = read(p->fd, p->win + p->len, ALOG_WIN - p->len);
	while (n < 0 && errno == EINTR);
	if (n > 0)
		p->len += (size_t)n;
	return n;
}

static ssize_t alog_plain_read(void *cookie, char *buf, size_t size)
{
	struct alog_plain *p = cookie;
	if (p->pos < p->base || p->pos >= p->base + (int64_t)p->len) {
		ssize_t n = alog_plain_fill(p);
		if (n <= 0)
			return n;
	}
	size_t m = (size_t)(p->base + (int64_t)p->len - p->pos);
	if (m > size)
		m = size;
	memcpy(buf, p->win + (p->pos - p->base), m);
	p->pos += (int64_t)m;
	return (ssize_t)m;
}

static int alog_plain_seek(void *cookie, off64_t *off, int whence)
{
	struct alog_plain *p = cookie;
	int64_t to;
	if (whence == SEEK_SET)
		to = (int64_t)*off;
	else if (whence == SEEK_CUR)
		to = p->pos + (int64_t)*off;
	else {
		struct stat st;
		if (fstat(p->fd, &st) != 0)
			return -1;
		to = (int64_t)st.st_size + (int64_t)*off;
	}
	if (to < 0) {
		errno = EINVAL;
		return -1;
	}
	p->pos = to;
	*off = to;
	return 0;
}

static int alog_plain_close(void *cookie)
{
	struct alog_plain *p = cookie;
	int rc = close(p->fd);
	free(p);
	return rc;
}

/* F (a plain file) as such a stream, from its start; F itself when that
 * cannot be made (it reads the same, with more system calls). */
static FILE *alog_plain_stream(FILE *f)
{
	struct alog_plain *p = malloc(sizeof *p);
	int fd = p ? dup(fileno(f)) : -1;
	if (fd < 0) {
		free(p);
		return f;
	}
	p->fd = fd;
	p->base = -1;   /* nothing in the window: the first read seeks to 0 */
	p->len = 0;
	p->pos = 0;
	cookie_io_functions_t io = { .read = alog_plain_read, .seek = alog_plain_seek, .close = alog_plain_close };
	FILE *c = fopencookie(p, "rb", io);
	if (c == NULL) {
		alog_plain_close(p);
		return f;
	}
	fclose(f);
	return c;
}

/* PATH for reading: the file itself, or its decompressed bytes when it is an
 * xz file (*xz set). NULL with errno on failure. */
static FILE *alog_fopen(const char *path, bool *xz, void **state)
{
	FILE *f = fopen(path, "rb");
	uint8_t head[sizeof alog_xz_magic];
	*xz = false;
	if (f == NULL)
		return NULL;
	size_t n = fread(head, 1, sizeof head, f);
	*xz = n == sizeof head && memcmp(head, alog_xz_magic, sizeof head) == 0;
	rewind(f);
	if (!*xz)
		return state != NULL ? alog_plain_stream(f) : f;
	struct alog_xz *x = calloc(1, sizeof *x);
	lzma_stream init = LZMA_STREAM_INIT;
	if (x == NULL) {
		fclose(f);
		return NULL;
	}
	x->raw = f;
	x->s = init;
	/* no memory limit of our own: a log's dictionary is what xz -1..-9 makes (<= 64 MiB) */
	if (lzma_stream_decoder(&x->s, UINT64_MAX, 0) != LZMA_OK) {
		fclose(f);
		free(x);
		errno = ENOMEM;
		return NULL;
	}
	cookie_io_functions_t io = { .read = alog_xz_read, .seek = alog_xz_seek, .close = alog_xz_close };
	FILE *z = fopencookie(x, "rb", io);
	if (z == NULL)
		alog_xz_close(x);
	else if (state != NULL)
		*state = x;
	return z;
}

/* Checks the file's first word before handing it to liblcm: its reader scans
 * for a sync word byte by byte and would call any foreign file "0 events". */
static int alog_check_header(const char *path, char *err, size_t errlen)
{
	unsigned char head[4];
	bool xz;
	FILE *f = alog_fopen(path, &xz, NULL);
	if (!f) {
		snprintf(err, errlen, "%s: %s", path, strerror(errno));
		return -1;
	}
	size_t n = fread(head, 1, sizeof(head), f);
	fclose(f);
	if (n == 0) {
		snprintf(err, errlen, "%s: empty %s, not an LCM log", path, xz ? "xz stream" : "file");
		return -1;
	}
	uint32_t magic = (uint32_t)head[0] << 24 | (uint32_t)head[1] << 16 |
			 (uint32_t)head[2] << 8 | (uint32_t)head[3];
	if (n < sizeof(head) || magic != ALOG_MAGIC) {
		snprintf(err, errlen,
			 "%s: not an LCM log%s (no lcm_eventlog sync word 0x%08X at the start)",
			 path, xz ? " inside the xz stream" : "", ALOG_MAGIC);
		return -1;
	}
	return 0;
}

int alog_open(struct alog_reader *r, const char *path, char *err, size_t errlen)
{
	struct stat st;
	memset(r, 0, sizeof(*r));
	r->path = path;
	if (stat(path, &st) != 0) {
		snprintf(err, errlen, "%s: %s", path, strerror(errno));
		return -1;
	}
	if (!S_ISREG(st.st_mode)) {
		snprintf(err, errlen, "%s: not a regular file", path);
		return -1;
	}
	if (alog_check_header(path, err, errlen) != 0)
		return -1;
	r->file_size = (int64_t)st.st_size;
	/* liblcm's lcm_eventlog_create() can only fopen() a path: its handle is
	 * the public {FILE *f; eventcount}, which lcm_eventlog_destroy() fcloses
	 * and frees; one is made here around the stream (the writer's way) */
	FILE *f = alog_fopen(path, &r->xz, &r->xz_state);
	r->log = f ? calloc(1, sizeof(*r->log)) : NULL;
	if (!r->log) {
		snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
		if (f)
			fclose(f);
		return -1;
	}
	r->log->f = f;
	return 0;
}

lcm_eventlog_event_t *alog_next(struct alog_reader *r)
{
	if (r->ended)
		return NULL;
	lcm_eventlog_event_t *ev = lcm_eventlog_read_next_event(r->log);
	if (!ev) {
		r->ended = true;
		/* an xz log's decompressed size is known at its end: what follows
		 * the last complete event, counted */
		if (r->xz) {
			int64_t at = (int64_t)ftello(r->log->f), rest = 0;
			char skip[4096];
			size_t n;
			while ((n = fread(skip, 1, sizeof skip, r->log->f)) > 0)
				rest += (int64_t)n;
			r->file_size = (at > r->good_end ? at : r->good_end) + rest;
			/* an xz stream cut short (a recording stopped mid-write) is
			 * a damaged log even where it ends between two events */
			if (!((const struct alog_xz *)r->xz_state)->stream_end)
				r->file_size++;
		}
		return NULL;
	}
	r->events++;
	r->good_end = (int64_t)ftello(r->log->f);
	return ev;
}

bool alog_damaged(const struct alog_reader *r)
{
	return r->good_end < r->file_size;
}

void alog_close(struct alog_reader *r)
{
	if (r->log)
		lcm_eventlog_destroy(r->log);
	r->log = NULL;
}

int alog_writer_open(struct alog_writer *w, const char *path, char *err, size_t errlen)
{
	memset(w, 0, sizeof(*w));
	char name[NAME_MAX + 1];
	int dirfd = outdir_open_parent(path, name, sizeof name, err, errlen);
	if (dirfd < 0)
		return -1;
	/* in place, not renamed at the end: a recording is read while it grows */
	int fd = outdir_create_in_place(dirfd, name, err, errlen);
	close(dirfd);
	FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
	/* lcm_eventlog_create() can only fopen() a path; its handle is the
	 * public {FILE *f; eventcount} that lcm_eventlog_destroy() fcloses and
	 * frees, so one is made here around the file created above */
	w->log = f ? calloc(1, sizeof(*w->log)) : NULL;
	if (w->log == NULL) {
		if (fd >= 0)
			snprintf(err, errlen, "%s: %s", path, strerror(errno));
		if (f)
			fclose(f);
		else if (fd >= 0)
			close(fd);
		return -1;
	}
	w->log->f = f;
	return 0;
}

void alog_writer_buffer(struct alog_writer *w)
{
	/* glibc takes setvbuf's size only with a buffer: given none, it
	 * allocates st_blksize (4 kB, a write() every 4 kB: 6 400 in a run) */
	w->buf = malloc(ALOG_WRITE_BUFFER);
	w->buffered = w->buf != NULL && setvbuf(w->log->f, w->buf, _IOFBF, ALOG_WRITE_BUFFER) == 0;
	if (!w->buffered) {
		free(w->buf);
		w->buf = NULL;
	}
}

int alog_flush(struct alog_writer *w)
{
	w->unflushed = 0;
	return fflush(w->log->f) == 0 ? 0 : -1;
}

static void alog_put_be(uint8_t *p, uint64_t v, int n)
{
	for (int i = n - 1; i >= 0; i--, v >>= 8)
		p[i] = (uint8_t)v;
}

/* lcm_eventlog_write_event's bytes (uint32 sync, int64 event number, int64
 * timestamp, int32 channel length, int32 data length, channel, data, all
 * big-endian), without its fflush. */
static int alog_write_buffered(struct alog_writer *w, const char *channel, int64_t timestamp, const void *data,
			       int32_t len)
{
	uint8_t head[28];
	size_t clen = strlen(channel);
	alog_put_be(head, ALOG_MAGIC, 4);
	alog_put_be(head + 4, (uint64_t)w->events, 8);
	alog_put_be(head + 12, (uint64_t)timestamp, 8);
	alog_put_be(head + 20, clen, 4);
	alog_put_be(head + 24, (uint32_t)len, 4);
	FILE *f = w->log->f;
	if (fwrite(head, 1, sizeof head, f) != sizeof head || fwrite(channel, 1, clen, f) != clen ||
	    (len > 0 && fwrite(data, 1, (size_t)len, f) != (size_t)len))
		return -1;
	w->events++;
	w->unflushed++;
	return 0;
}

int alog_write(struct alog_writer *w, const char *channel, int64_t timestamp,
	       const void *data, int32_t len)
{
	if (w->buffered)
		return alog_write_buffered(w, channel, timestamp, data, len);
	lcm_eventlog_event_t ev = {
		.eventnum = w->events,
		.timestamp = timestamp,
		.channellen = (int32_t)strlen(channel),
		.datalen = len,
		/* liblcm's writer takes non-const pointers but only reads them. */
		.channel = (char *)(uintptr_t)channel,
		.data = (void *)(uintptr_t)data,
	};
	if (lcm_eventlog_write_event(w->log, &ev) != 0)
		return -1;
	w->events++;
	return 0;
}

int alog_writer_close(struct alog_writer *w)
{
	if (!w->log)
		return -1;
	int rc = fflush(w->log->f) == 0 ? 0 : -1;
	lcm_eventlog_destroy(w->log);
	w->log = NULL;
	free(w->buf);
	w->buf = NULL;
	return rc;
}
