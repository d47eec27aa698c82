/* outdir.c — see outdir.h. */
#include "outdir.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <grp.h>
#include <limits.h>
#include <pwd.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* Attempts at a free random name before giving up (as mkstemp's TMP_MAX is
 * far more than ever needed: a clash means someone is guessing). */
#define OUTDIR_NAME_TRIES 100
/* Letters of the random suffix: 36^6, two billion names. */
#define OUTDIR_SUFFIX_LEN 6

struct outdir_walk {
	const char *path;   /* as the user gave it, for messages */
	char *err;
	size_t errcap;
	int links;          /* symbolic links followed so far */
	bool create;
};

/* "nobody (uid 65534)", or "uid 65534" for a user without a name. */
static void outdir_user(uid_t uid, char *out, size_t cap)
{
	const struct passwd *pw = getpwuid(uid);
	if (pw != NULL)
		snprintf(out, cap, "%s (uid %lu)", pw->pw_name, (unsigned long)uid);
	else
		snprintf(out, cap, "uid %lu", (unsigned long)uid);
}

/* The group is ours alone: our own primary group, named as we are, with no
 * other member listed (Debian's user private groups). */
static bool outdir_group_private(gid_t gid)
{
	if (gid != getegid())
		return false;
	const struct passwd *pw = getpwuid(geteuid());
	if (pw == NULL)
		return false;
	char me[256];
	snprintf(me, sizeof me, "%s", pw->pw_name);
	const struct group *gr = getgrgid(gid);
	if (gr == NULL || strcmp(gr->gr_name, me) != 0)
		return false;
	for (char *const *m = gr->gr_mem; *m != NULL; m++)
		if (strcmp(*m, me) != 0)
			return false;
	return true;
}

/* Who runs this, for "not by you (root)": the name, or "uid N". */
static void outdir_me(char *out, size_t cap)
{
	const struct passwd *pw = getpwuid(geteuid());
	if (pw != NULL)
		snprintf(out, cap, "%s", pw->pw_name);
	else
		snprintf(out, cap, "uid %lu", (unsigned long)geteuid());
}

/* A link we may follow: ours, or root's (root can write anywhere anyway). */
static bool outdir_link_trusted(const struct stat *st)
{
	return st->st_uid == 0 || st->st_uid == geteuid();
}

/* Why the directory reached is refused, into err; 0 when it is fine. */
static int outdir_check_dir(const struct outdir_walk *w, const struct stat *st)
{
	char who[128], me[128];
	if (st->st_uid != geteuid()) {
		outdir_user(st->st_uid, who, sizeof who);
		outdir_me(me, sizeof me);
		snprintf(w->err, w->errcap, "%s: owned by %s, not by you (%s): another user could put links or FIFOs "
		         "in it under the names written there; choose a directory of yours (a new one is made)",
		         w->path, who, me);
		return -1;
	}
	if (st->st_mode & S_ISVTX)
		return 0;
	bool other = (st->st_mode & S_IWOTH) != 0;
	bool group = (st->st_mode & S_IWGRP) != 0 && !outdir_group_private(st->st_gid);
	if (other || group) {
		snprintf(w->err, w->errcap, "%s: writable by %s (mode %04o): another user could put links or FIFOs in "
		         "it under the names written there; chmod %s %s, or choose another directory",
		         w->path, other ? "other users" : "its group, which is not yours alone",
		         (unsigned)(st->st_mode & 07777), other ? "go-w" : "g-w", w->path);
		return -1;
	}
	return 0;
}

static int outdir_walk_from(struct outdir_walk *w, int at, const char *rel, bool last_of_path);

/* Component `name` of directory cur is not a directory: a link we may
 * follow (followed: returns the directory it leads to), or a refusal. */
static int outdir_through_link(struct outdir_walk *w, int cur, const char *name, bool last)
{
	struct stat st;
	if (fstatat(cur, name, &st, AT_SYMLINK_NOFOLLOW) != 0) {
		snprintf(w->err, w->errcap, "%s: cannot open %s: %s", w->path, name, strerror(errno));
		return -1;
	}
	if (!S_ISLNK(st.st_mode)) {
		snprintf(w->err, w->errcap, "%s: %s is not a directory", w->path, name);
		return -1;
	}
	if (!outdir_link_trusted(&st)) {
		char who[128];
		outdir_user(st.st_uid, who, sizeof who);
		snprintf(w->err, w->errcap, "%s: the symbolic link %s on the way is owned by %s, not by you or root: "
		         "another user chooses where it leads; give the directory itself", w->path, name, who);
		return -1;
	}
	if (++w->links > OUTDIR_MAX_LINKS) {
		snprintf(w->err, w->errcap, "%s: %s", w->path, strerror(ELOOP));
		return -1;
	}
	char target[PATH_MAX];
	ssize_t n = readlinkat(cur, name, target, sizeof target - 1);
	if (n < 0) {
		snprintf(w->err, w->errcap, "%s: cannot read the link %s: %s", w->path, name, strerror(errno));
		return -1;
	}
	target[n] = '\0';
	return outdir_walk_from(w, cur, target, last);
}

/* One name: the directory it opens (made first when it is the path's last
 * and missing, with create), following a trusted link. */
static int outdir_step(struct outdir_walk *w, int cur, const char *name, bool last)
{
	int flags = O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC;
	int fd = openat(cur, name, flags);
	if (fd < 0 && errno == ENOENT && last && w->create) {
		if (mkdirat(cur, name, 0755) != 0 && errno != EEXIST) {
			snprintf(w->err, w->errcap, "%s: cannot create: %s", w->path, strerror(errno));
			return -1;
		}
		fd = openat(cur, name, flags);
	}
	if (fd >= 0)
		return fd;
	if (errno == ELOOP || errno == ENOTDIR)
		return outdir_through_link(w, cur, name, last);
	if (strcmp(name, w->path) == 0)
		snprintf(w->err, w->errcap, "%s: cannot open: %s", w->path, strerror(errno));
	else
		snprintf(w->err, w->errcap, "%s: cannot open %s: %s", w->path, name, strerror(errno));
	return -1;
}

/* Walks rel from directory at (AT_FDCWD: the working directory) name by
 * name. last_of_path: rel's last name is the last of the whole path. */
static int outdir_walk_from(struct outdir_walk *w, int at, const char *rel, bool last_of_path)
{
	char buf[PATH_MAX];
	if (snprintf(buf, sizeof buf, "%s", rel) >= (int)sizeof buf) {
		snprintf(w->err, w->errcap, "%s: %s", w->path, strerror(ENAMETOOLONG));
		return -1;
	}
	int cur = buf[0] == '/' ? open("/", O_RDONLY | O_DIRECTORY | O_CLOEXEC)
	        : at == AT_FDCWD ? open(".", O_RDONLY | O_DIRECTORY | O_CLOEXEC)
	        : fcntl(at, F_DUPFD_CLOEXEC, 0);
	if (cur < 0) {
		snprintf(w->err, w->errcap, "%s: cannot open: %s", w->path, strerror(errno));
		return -1;
	}
	char *save = NULL;
	char *name = strtok_r(buf, "/", &save);
	while (name != NULL) {
		char *next = strtok_r(NULL, "/", &save);
		if (strcmp(name, ".") != 0) {
			int fd = outdir_step(w, cur, name, last_of_path && next == NULL);
			close(cur);
			if (fd < 0)
				return -1;
			cur = fd;
		}
		name = next;
	}
	return cur;
}

int outdir_open(const char *path, bool create, char *err, size_t errcap)
{
	struct outdir_walk w = { .path = path, .err = err, .errcap = errcap, .create = create };
	if (path == NULL || path[0] == '\0') {
		snprintf(err, errcap, "an empty directory name");
		return -1;
	}
	int fd = outdir_walk_from(&w, AT_FDCWD, path, true);
	if (fd < 0)
		return -1;
	struct stat st;
	if (fstat(fd, &st) != 0) {
		snprintf(err, errcap, "%s: %s", path, strerror(errno));
		close(fd);
		return -1;
	}
	if (outdir_check_dir(&w, &st) != 0) {
		close(fd);
		return -1;
	}
	return fd;
}

int outdir_open_parent(const char *path, char *name, size_t namecap, char *err, size_t errcap)
{
	char dir[PATH_MAX];
	const char *slash = strrchr(path, '/');
	const char *base = slash ? slash + 1 : path;
	if (*base == '\0' || strcmp(base, ".") == 0 || strcmp(base, "..") == 0) {
		snprintf(err, errcap, "%s: names a directory; give the file to write", path);
		return -1;
	}
	if (snprintf(name, namecap, "%s", base) >= (int)namecap || (slash && (size_t)(slash - path) >= sizeof dir)) {
		snprintf(err, errcap, "%s: %s", path, strerror(ENAMETOOLONG));
		return -1;
	}
	if (slash == NULL) {
		/* the working directory by its name, which a refusal then shows */
		if (getcwd(dir, sizeof dir) == NULL)
			snprintf(dir, sizeof dir, ".");
	} else if (slash == path)
		snprintf(dir, sizeof dir, "/");
	else
		snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
	return outdir_open(dir, false, err, errcap);
}

int outdir_create_in_place(int dirfd, const char *name, char *err, size_t errcap)
{
	if (unlinkat(dirfd, name, 0) != 0 && errno != ENOENT) {
		snprintf(err, errcap, "%s: cannot replace it: %s", name, strerror(errno));
		return -1;
	}
	int fd = openat(dirfd, name, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
	if (fd < 0)
		snprintf(err, errcap, "%s: cannot create: %s", name, strerror(errno));
	return fd;
}

/* PREFIX followed by a random suffix, into out (cap bytes). */
static void outdir_random_name(const char *prefix, char *out, size_t cap)
{
	static const char letters[] = "abcdefghijklmnopqrstuvwxyz0123456789";
	unsigned char r[OUTDIR_SUFFIX_LEN];
	if (getrandom(r, sizeof r, GRND_NONBLOCK) != (ssize_t)sizeof r) {
		/* no entropy yet (early boot): unpredictable enough, and O_EXCL
		 * makes a guessed name a failed attempt, never a takeover */
		struct timespec ts;
		clock_gettime(CLOCK_MONOTONIC, &ts);
		uint64_t x = (uint64_t)ts.tv_nsec ^ ((uint64_t)getpid() << 32) ^ (uint64_t)(uintptr_t)out;
		for (size_t i = 0; i < sizeof r; i++, x = x * 6364136223846793005u + 1442695040888963407u)
			r[i] = (unsigned char)(x >> 56);
	}
	char suffix[OUTDIR_SUFFIX_LEN + 1];
	for (size_t i = 0; i < sizeof r; i++)
		suffix[i] = letters[r[i] % (sizeof letters - 1)];
	suffix[OUTDIR_SUFFIX_LEN] = '\0';
	snprintf(out, cap, "%s.%s", prefix, suffix);
}

int outdir_stage(int dirfd, const char *prefix, char *name, size_t namecap, char *err, size_t errcap)
{
	for (int i = 0; i < OUTDIR_NAME_TRIES; i++) {
		outdir_random_name(prefix, name, namecap);
		if (mkdirat(dirfd, name, 0700) == 0) {
			int fd = openat(dirfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
			if (fd >= 0)
				return fd;
			snprintf(err, errcap, "%s: cannot open: %s", name, strerror(errno));
			unlinkat(dirfd, name, AT_REMOVEDIR);
			return -1;
		}
		if (errno != EEXIST) {
			snprintf(err, errcap, "cannot make a directory in it: %s", strerror(errno));
			return -1;
		}
	}
	snprintf(err, errcap, "cannot make a directory in it: every name tried was taken");
	return -1;
}

/* Calls fn on every entry of directory fd but . and .., with its type (from
 * fstatat, not trusting d_type). Returns the first non-zero fn returned. */
static int outdir_each(int fd, int (*fn)(int fd, const char *name, const struct stat *st, void *arg), void *arg)
{
	int dfd = fcntl(fd, F_DUPFD_CLOEXEC, 0);
	DIR *d = dfd >= 0 ? fdopendir(dfd) : NULL;
	if (d == NULL) {
		if (dfd >= 0)
			close(dfd);
		return -1;
	}
	rewinddir(d);
	int rc = 0;
	const struct dirent *e;
	while ((e = readdir(d)) != NULL) {
		if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
			continue;
		struct stat st;
		if (fstatat(fd, e->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0)
			continue;
		int r = fn(fd, e->d_name, &st, arg);
		if (r != 0 && rc == 0)
			rc = r;
	}
	closedir(d);
	return rc;
}

static int outdir_remove_one(int fd, const char *name, const struct stat *st, void *arg)
{
	(void)arg;
	unlinkat(fd, name, S_ISDIR(st->st_mode) ? AT_REMOVEDIR : 0);
	return 0;
}

struct outdir_move {
	int dirfd;
	char *err;
	size_t errcap;
	bool failed;
};

static int outdir_move_one(int fd, const char *name, const struct stat *st, void *arg)
{
	struct outdir_move *m = arg;
	if (!S_ISREG(st->st_mode))
		return 0;
	if (renameat(fd, name, m->dirfd, name) != 0 && !m->failed) {
		snprintf(m->err, m->errcap, "%s: cannot replace it: %s", name, strerror(errno));
		m->failed = true;
	}
	return 0;
}

void outdir_discard(int dirfd, int stagefd, const char *stagename)
{
	outdir_each(stagefd, outdir_remove_one, NULL);
	unlinkat(dirfd, stagename, AT_REMOVEDIR);
}

int outdir_publish(int dirfd, int stagefd, const char *stagename, char *err, size_t errcap)
{
	struct outdir_move m = { .dirfd = dirfd, .err = err, .errcap = errcap };
	if (outdir_each(stagefd, outdir_move_one, &m) != 0 && !m.failed) {
		snprintf(err, errcap, "cannot list %s: %s", stagename, strerror(errno));
		m.failed = true;
	}
	outdir_discard(dirfd, stagefd, stagename);
	return m.failed ? -1 : 0;
}

int outdir_file_create(struct outdir_file *f, int dirfd, const char *name, char *err, size_t errcap)
{
	f->dirfd = dirfd;
	f->fd = -1;
	if (name[0] == '\0' || strchr(name, '/') != NULL || strcmp(name, ".") == 0 || strcmp(name, "..") == 0 ||
	    snprintf(f->name, sizeof f->name, "%s", name) >= (int)sizeof f->name) {
		snprintf(err, errcap, "%s: not a file name", name);
		return -1;
	}
	char prefix[sizeof f->name + 1];
	snprintf(prefix, sizeof prefix, ".%s", name);
	for (int i = 0; i < OUTDIR_NAME_TRIES; i++) {
		outdir_random_name(prefix, f->tmp, sizeof f->tmp);
		f->fd = openat(dirfd, f->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
		if (f->fd >= 0)
			return f->fd;
		if (errno != EEXIST) {
			snprintf(err, errcap, "cannot create a file beside %s: %s", name, strerror(errno));
			return -1;
		}
	}
	snprintf(err, errcap, "cannot create a file beside %s: every name tried was taken", name);
	return -1;
}

int outdir_file_commit(struct outdir_file *f, bool closed, char *err, size_t errcap)
{
	int bad = 0;
	if (!closed) {
		if (fsync(f->fd) != 0)
			bad = errno;
		if (close(f->fd) != 0 && bad == 0)
			bad = errno;
	}
	f->fd = -1;
	if (bad == 0 && renameat(f->dirfd, f->tmp, f->dirfd, f->name) != 0)
		bad = errno;
	if (bad != 0) {
		snprintf(err, errcap, "%s: %s", f->name, strerror(bad));
		unlinkat(f->dirfd, f->tmp, 0);
		return -1;
	}
	return 0;
}

void outdir_file_abandon(struct outdir_file *f, bool closed)
{
	if (!closed && f->fd >= 0)
		close(f->fd);
	f->fd = -1;
	unlinkat(f->dirfd, f->tmp, 0);
}

FILE *outdir_stage_fopen(int stagefd, const char *name)
{
	int fd = openat(stagefd, name, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
	FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
	if (!f && fd >= 0) {
		int e = errno;   /* fdopen's reason, for the caller's message */
		close(fd);
		errno = e;
	}
	return f;
}

int outdir_stage_fclose(FILE **f)
{
	if (!*f)
		return 0;
	int bad = ferror(*f) | fclose(*f);
	*f = NULL;
	return bad ? -1 : 0;
}
