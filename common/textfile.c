/* textfile.c — see textfile.h. */
#include "textfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *textfile_kind(mode_t m)
{
	if (S_ISDIR(m))
		return "a directory";
	if (S_ISFIFO(m))
		return "a FIFO";
	if (S_ISCHR(m))
		return "a character device";
	if (S_ISBLK(m))
		return "a block device";
	if (S_ISSOCK(m))
		return "a socket";
	return "not a plain file";
}

/* Reads at most TEXTFILE_MAX_BYTES + 1 bytes (one more tells a file that grew). */
static int textfile_slurp(int fd, char *buf, size_t *len)
{
	size_t n = 0;
	while (n <= TEXTFILE_MAX_BYTES) {
		ssize_t r = read(fd, buf + n, TEXTFILE_MAX_BYTES + 1 - n);
		if (r < 0 && errno == EINTR)
			continue;
		if (r < 0)
			return errno;
		if (r == 0)
			break;
		n += (size_t)r;
	}
	*len = n;
	return 0;
}

char *textfile_read(const char *path, const char *what, size_t *len, char *err, size_t errcap)
{
	struct stat st;
	if (stat(path, &st) != 0) {
		snprintf(err, errcap, "%s: cannot open: %s", path, strerror(errno));
		return NULL;
	}
	if (!S_ISREG(st.st_mode)) {
		snprintf(err, errcap, "%s: not a regular file (%s): %s is a text file", path,
		         textfile_kind(st.st_mode), what);
		return NULL;
	}
	if (st.st_size > TEXTFILE_MAX_BYTES) {
		snprintf(err, errcap, "%s: larger than 1 MiB (%lld bytes): not %s", path, (long long)st.st_size, what);
		return NULL;
	}
	int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
	if (fd < 0) {
		snprintf(err, errcap, "%s: cannot open: %s", path, strerror(errno));
		return NULL;
	}
	if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
		close(fd);
		snprintf(err, errcap, "%s: not a regular file: %s is a text file", path, what);
		return NULL;
	}
	char *text = malloc(TEXTFILE_MAX_BYTES + 2);
	if (text == NULL) {
		close(fd);
		snprintf(err, errcap, "%s: out of memory", path);
		return NULL;
	}
	size_t n = 0;
	int rerr = textfile_slurp(fd, text, &n);
	close(fd);
	const char *nul = rerr == 0 ? memchr(text, '\0', n) : NULL;
	if (rerr != 0) {
		snprintf(err, errcap, "%s: cannot read: %s", path, strerror(rerr));
	} else if (n > TEXTFILE_MAX_BYTES) {
		snprintf(err, errcap, "%s: larger than 1 MiB: not %s", path, what);
	} else if (nul != NULL) {
		int line = 1;
		for (const char *q = text; q < nul; q++)
			line += *q == '\n';
		snprintf(err, errcap, "%s:%d: a NUL byte: %s is a text file", path, line, what);
	} else {
		text[n] = '\0';
		*len = n;
		return text;
	}
	free(text);
	return NULL;
}
