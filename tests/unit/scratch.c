/* scratch.c — see scratch.h. */
#include "scratch.h"

#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

char scratch_dir[256];

int scratch_make(const char *tag)
{
	const char *base = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
	snprintf(scratch_dir, sizeof scratch_dir, "%s/undulate-%s-XXXXXX", base, tag);
	return mkdtemp(scratch_dir) ? 0 : -1;
}

int scratch_group_setup(void **state)
{
	(void)state;
	char exe[256];
	ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
	if (n <= 0)
		return scratch_make("unit");
	exe[n] = '\0';
	const char *slash = strrchr(exe, '/');
	return scratch_make(slash ? slash + 1 : exe);
}

int scratch_group_teardown(void **state)
{
	(void)state;
	return scratch_remove();
}

bool scratch_private_file(const char *path, unsigned mode)
{
	struct stat st;
	if (lstat(path, &st) != 0) {
		fprintf(stderr, "%s: cannot lstat\n", path);
		return false;
	}
	if (!S_ISREG(st.st_mode) || (st.st_mode & 07777) != mode || st.st_uid != geteuid()) {
		fprintf(stderr, "%s: type/mode %06o, owner %u; want a regular file, %04o, %u\n", path,
		        (unsigned)st.st_mode, (unsigned)st.st_uid, mode, (unsigned)geteuid());
		return false;
	}
	return true;
}

static int scratch_unlink(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
	(void)st; (void)type; (void)ftw;
	return remove(path);
}

int scratch_remove(void)
{
	if (scratch_dir[0] == '\0')
		return 0;
	/* depth first, no symlinks followed: only what the test wrote goes */
	return nftw(scratch_dir, scratch_unlink, 16, FTW_DEPTH | FTW_PHYS);
}

char *scratch_slurp(const char *rel, size_t cap)
{
	char p[512];
	snprintf(p, sizeof p, "%s/%s", scratch_dir, rel);
	FILE *f = fopen(p, "rb");
	if (!f)
		return NULL;
	char *buf = calloc(1, cap + 1);
	size_t n = buf ? fread(buf, 1, cap, f) : 0;
	if (buf)
		buf[n] = '\0';
	fclose(f);
	return buf;
}

long scratch_dead_pid(void)
{
	pid_t c = fork();
	if (c < 0)
		return -1;
	if (c == 0)
		_exit(0);
	return waitpid(c, NULL, 0) == c ? (long)c : -1;
}
