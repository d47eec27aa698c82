/* alog.c — see alog.h. */
#include "alog.h"

#include "outdir.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Checks the file's first word before handing it to liblcm: its reader scans
 * for a sync word byte by byte and would call any foreign file "0 events". */
static int alog_check_header(const char *path, char *err, size_t errlen)
{
	unsigned char head[4];
	FILE *f = fopen(path, "rb");
	if (!f) {
		snprintf(err, errlen, "%s: %s", path, strerror(errno));
		return -1;
	}
	size_t n = fread(head, 1, sizeof(head), f);
	fclose(f);
	if (n == 0) {
		snprintf(err, errlen, "%s: empty file, not an LCM log", path);
		return -1;
	}
	uint32_t magic = (uint32_t)head[0] << 24 | (uint32_t)head[1] << 16 |
			 (uint32_t)head[2] << 8 | (uint32_t)head[3];
	if (n < sizeof(head) || magic != ALOG_MAGIC) {
		snprintf(err, errlen,
			 "%s: not an LCM log (no lcm_eventlog sync word 0x%08X at the start)",
			 path, ALOG_MAGIC);
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
	r->log = lcm_eventlog_create(path, "r");
	if (!r->log) {
		snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
		return -1;
	}
	return 0;
}

lcm_eventlog_event_t *alog_next(struct alog_reader *r)
{
	if (r->ended)
		return NULL;
	lcm_eventlog_event_t *ev = lcm_eventlog_read_next_event(r->log);
	if (!ev) {
		r->ended = true;
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

int alog_write(struct alog_writer *w, const char *channel, int64_t timestamp,
	       const void *data, int32_t len)
{
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
	return rc;
}
