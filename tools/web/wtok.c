/* wtok.c — see wtok.h. */
#include "wtok.h"

#include <errno.h>
#include <fcntl.h>
#include <sodium.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

bool wtok_read(const char *path, char out[REQ_TOKEN_MAX], char *why, size_t why_cap)
{
	char line[REQ_TOKEN_MAX + 2];
	int fd = open(path, O_RDONLY | O_CLOEXEC);
	FILE *f = fd >= 0 ? fdopen(fd, "r") : NULL;
	struct stat st;
	if (f == NULL || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
		snprintf(why, why_cap, "cannot read it as a file");
		if (f != NULL)
			fclose(f);
		else if (fd >= 0)
			close(fd);
		return false;
	}
	if (st.st_mode & 077) {
		snprintf(why, why_cap, "readable by others (mode %03o): chmod 600 %s", (unsigned)(st.st_mode & 0777), path);
		fclose(f);
		return false;
	}
	if (fgets(line, sizeof line, f) == NULL)
		line[0] = '\0';
	fclose(f);
	line[strcspn(line, "\r\n")] = '\0';
	size_t n = strlen(line);
	bool ok = n >= 8 && n < REQ_TOKEN_MAX && strspn(line, REQ_TOKEN_CHARS) == n;
	if (ok)
		memcpy(out, line, n + 1);
	else
		snprintf(why, why_cap, "want one line of 8 to %d letters, digits or -_.~ (e.g. head -c 24 /dev/urandom "
		         "| base64 | tr '+/' '-_' > %s)", REQ_TOKEN_MAX - 1, path);
	sodium_memzero(line, sizeof line);
	return ok;
}

bool wtok_make(char out[REQ_TOKEN_MAX])
{
	unsigned char raw[WTOK_RANDOM_BYTES];
	if (sodium_init() < 0)
		return false;
	randombytes_buf(raw, sizeof raw);
	sodium_bin2base64(out, REQ_TOKEN_MAX, raw, sizeof raw, sodium_base64_VARIANT_URLSAFE_NO_PADDING);
	sodium_memzero(raw, sizeof raw);
	return true;
}

bool wtok_write(const char *dir, int port, const char *token, char *path_out, size_t path_cap, char *why,
                size_t why_cap)
{
	int n = snprintf(path_out, path_cap, "%s/undulate-web-%d.token", dir, port);
	if (n < 0 || (size_t)n >= path_cap) {
		snprintf(why, why_cap, "%s: too long a directory", dir);
		return false;
	}
	/* a file left by a run that died on this port, or a link someone put
	 * there: removed, never opened (the directory is ours, csock.h) */
	if (unlink(path_out) != 0 && errno != ENOENT) {
		snprintf(why, why_cap, "%s: %s", path_out, strerror(errno));
		return false;
	}
	int fd = open(path_out, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
	if (fd < 0) {
		snprintf(why, why_cap, "%s: %s", path_out, strerror(errno));
		return false;
	}
	size_t len = strlen(token);
	bool ok = write(fd, token, len) == (ssize_t)len && write(fd, "\n", 1) == 1;
	if (!ok)
		snprintf(why, why_cap, "%s: %s", path_out, strerror(errno));
	close(fd);
	if (!ok)
		unlink(path_out);
	return ok;
}
