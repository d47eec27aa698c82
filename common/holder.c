/*
 * holder.c — naming the program that holds a bus (holder.h).
 */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include "holder.h"
#include "text.h"

/* Linux's largest pid (PID_MAX_LIMIT on 64-bit): a lock file's pid beyond it is not a pid. */
#define HOLDER_PID_MAX 4194304L
/* A lock file is one short line; anything longer is not one of ours or UUCP's. */
#define HOLDER_FILE_MAX 512
/* A command line read for the robot's name: undulated's options fit many times over. */
#define HOLDER_CMDLINE_MAX 4096
/* /proc/locks lines are under 100 characters (id, kind, pid, dev:ino, range). */
#define HOLDER_LOCKS_LINE_MAX 256
/* A lock file is taken over when its holder removed it between our open and
 * our lock; each retry means another holder came and went: a few suffice. */
#define HOLDER_TAKE_TRIES 4

bool holder_alive(long pid)
{
	if (pid <= 0 || pid > HOLDER_PID_MAX)
		return false;
	return kill((pid_t)pid, 0) == 0 || errno == EPERM;
}

/* Read at most cap - 1 bytes of a small file into buf, NUL-terminated. */
static ssize_t holder_slurp(const char *path, char *buf, size_t cap)
{
	int fd = open(path, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
	if (fd < 0)
		return -1;
	ssize_t n = read(fd, buf, cap - 1);
	close(fd);
	if (n < 0)
		return -1;
	buf[n] = '\0';
	return n;
}

/* undulated's robot among the arguments (NUL-separated, as /proc/PID/cmdline):
 * --robot NAME, --robot=NAME, or --set robot.name=NAME. */
static void holder_robot_from_args(const char *args, size_t n, char *robot, size_t cap)
{
	const char *prev = "";
	for (size_t off = 0; off < n; off += strlen(args + off) + 1) {
		const char *a = args + off, *name = NULL;
		if (strcmp(prev, "--robot") == 0)
			name = a;
		else if (strncmp(a, "--robot=", 8) == 0)
			name = a + 8;
		else if (strncmp(a, "robot.name=", 11) == 0)
			name = a + 11;
		else if (strncmp(a, "--set=robot.name=", 17) == 0)
			name = a + 17;
		if (name != NULL && text_is_name(name, cap - 1))
			snprintf(robot, cap, "%s", name);
		prev = a;
	}
}

bool holder_from_pid(long pid, struct holder *h)
{
	char path[64], buf[HOLDER_CMDLINE_MAX];
	memset(h, 0, sizeof *h);
	snprintf(path, sizeof path, "/proc/%ld/comm", pid);
	if (pid <= 0 || holder_slurp(path, buf, sizeof buf) <= 0)
		return false;
	buf[strcspn(buf, "\n")] = '\0';
	h->pid = pid;
	text_line(h->program, sizeof h->program, buf);
	snprintf(path, sizeof path, "/proc/%ld/cmdline", pid);
	ssize_t n = holder_slurp(path, buf, sizeof buf);
	if (n <= 0)
		return true;
	holder_robot_from_args(buf, (size_t)n, h->robot, sizeof h->robot);
	if (h->robot[0] != '\0') {
		snprintf(h->detail, sizeof h->detail, "robot %s", h->robot);
		return true;
	}
	/* no robot: what it was started with says what it is doing (argv[0] is the program) */
	size_t first = strlen(buf) + 1;
	for (ssize_t i = (ssize_t)first; i < n - 1; i++)
		if (buf[i] == '\0')
			buf[i] = ' ';
	if ((ssize_t)first < n)
		text_line(h->detail, sizeof h->detail, buf + first);
	return true;
}

/* One /proc/locks line: "1: FLOCK  ADVISORY  WRITE 812 00:19:5 0 EOF"; a
 * waiter's has "->" after the id and holds nothing. */
static bool holder_locks_line(char *line, dev_t dev, ino_t ino, long *pid)
{
	char *save = NULL, *tok[8];
	size_t n = 0;
	for (char *t = strtok_r(line, " \t\n", &save); t != NULL && n < 8; t = strtok_r(NULL, " \t\n", &save))
		tok[n++] = t;
	if (n < 6 || strcmp(tok[1], "FLOCK") != 0)
		return false;
	unsigned maj, min;
	unsigned long long node;
	char *end;
	long p = strtol(tok[4], &end, 10);
	if (*end != '\0' || sscanf(tok[5], "%x:%x:%llu", &maj, &min, &node) != 3)
		return false;
	if (maj != major(dev) || min != minor(dev) || node != (unsigned long long)ino)
		return false;
	*pid = p;
	return p > 0;
}

bool holder_flock_pid(dev_t dev, ino_t ino, long *pid)
{
	FILE *f = fopen("/proc/locks", "re");
	char line[HOLDER_LOCKS_LINE_MAX];
	bool found = false;
	if (f == NULL)
		return false;
	while (!found && fgets(line, sizeof line, f) != NULL)
		found = holder_locks_line(line, dev, ino, pid);
	fclose(f);
	return found;
}

void holder_format(const struct holder *h, char *out, size_t cap)
{
	const char *program = h->program[0] ? h->program : "a process";
	if (h->pid <= 0)
		snprintf(out, cap, "%s", h->program[0] ? h->program : "another program");
	else if (h->detail[0] != '\0')
		snprintf(out, cap, "%s (pid %ld, %s)", program, h->pid, h->detail);
	else
		snprintf(out, cap, "%s (pid %ld)", program, h->pid);
}

void holder_self_program(char *out, size_t cap)
{
	char buf[HOLDER_PROGRAM_MAX];
	if (holder_slurp("/proc/self/comm", buf, sizeof buf) <= 0) {
		snprintf(out, cap, "?");
		return;
	}
	buf[strcspn(buf, "\n")] = '\0';
	text_line(out, cap, buf);
}

int holder_line(const struct holder *h, char *out, size_t cap)
{
	int n = snprintf(out, cap, "%10ld %s%s%s\n", h->pid, h->program[0] ? h->program : "?", h->detail[0] ? " " : "",
	                 h->detail);
	return n > 0 && (size_t)n < cap ? n : -1;
}

bool holder_parse(const char *text, struct holder *h)
{
	memset(h, 0, sizeof *h);
	const char *p = text;
	while (*p == ' ')
		p++;
	if (!isdigit((unsigned char)*p))
		return false;
	char *end;
	errno = 0;
	long pid = strtol(p, &end, 10);
	if (errno != 0 || pid <= 0 || pid > HOLDER_PID_MAX || (*end != ' ' && *end != '\n' && *end != '\0'))
		return false;
	h->pid = pid;
	p = end;
	while (*p == ' ')
		p++;
	size_t len = strcspn(p, " \n");
	char word[HOLDER_PROGRAM_MAX];
	snprintf(word, sizeof word, "%.*s", (int)(len < sizeof word ? len : sizeof word - 1), p);
	text_line(h->program, sizeof h->program, word);
	p += len;
	while (*p == ' ')
		p++;
	char rest[HOLDER_DETAIL_MAX];
	len = strcspn(p, "\n");
	snprintf(rest, sizeof rest, "%.*s", (int)(len < sizeof rest ? len : sizeof rest - 1), p);
	text_line(h->detail, sizeof h->detail, rest);
	if (strncmp(h->detail, "robot ", 6) == 0 && text_is_name(h->detail + 6, sizeof h->robot - 1))
		snprintf(h->robot, sizeof h->robot, "%s", h->detail + 6);
	return true;
}

bool holder_read_file(const char *path, struct holder *h)
{
	char buf[HOLDER_FILE_MAX + 1];
	int fd = open(path, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
	struct stat st;
	memset(h, 0, sizeof *h);
	if (fd < 0)
		return false;
	bool regular = fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
	ssize_t n = regular ? read(fd, buf, HOLDER_FILE_MAX) : -1;
	close(fd);
	if (n <= 0)
		return false;
	buf[n] = '\0';
	return holder_parse(buf, h);
}

/* ---- a lock file that is itself the lock ----------------------------------------- */

/* Who holds the lock file on fd (its text, else the kernel's table of locks). */
static void holder_of_lockfile(int fd, const struct stat *st, struct holder *who)
{
	char buf[HOLDER_FILE_MAX + 1];
	ssize_t n = pread(fd, buf, HOLDER_FILE_MAX, 0);
	buf[n > 0 ? n : 0] = '\0';
	long pid = 0;
	/* its holder may be between taking the lock and writing the file */
	if (!holder_parse(buf, who) || !holder_alive(who->pid)) {
		memset(who, 0, sizeof *who);
		if (holder_flock_pid(st->st_dev, st->st_ino, &pid))
			holder_from_pid(pid, who);
	}
}

/* Replace the text of the lock file on fd by "PID PROGRAM DETAIL" for this process. */
static bool holder_write_self(int fd, const char *detail)
{
	struct holder me = { .pid = (long)getpid() };
	char line[HOLDER_PROGRAM_MAX + HOLDER_DETAIL_MAX + 16];
	holder_self_program(me.program, sizeof me.program);
	text_line(me.detail, sizeof me.detail, detail != NULL ? detail : "");
	int n = holder_line(&me, line, sizeof line);
	return n > 0 && ftruncate(fd, 0) == 0 && pwrite(fd, line, (size_t)n, 0) == n;
}

/* Open (or create) the lock file and lock it: its fd, HOLDER_HELD, HOLDER_ERROR,
 * or -3 when the file at path changed under us (try again). */
static int holder_lockfile_try(const char *path, struct holder *who, char *err, size_t errcap)
{
	struct stat st, now;
	int fd = open(path, O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
	if (fd < 0) {
		snprintf(err, errcap, "cannot open the lock file %s: %s", path,
		         errno == ELOOP ? "it is a symbolic link" : strerror(errno));
		return HOLDER_ERROR;
	}
	if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
		snprintf(err, errcap, "the lock file %s is not a regular file: refusing to use it", path);
		close(fd);
		return HOLDER_ERROR;
	}
	if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
		int e = errno;
		if (e == EWOULDBLOCK)
			holder_of_lockfile(fd, &st, who);
		else
			snprintf(err, errcap, "cannot lock %s: %s", path, strerror(e));
		close(fd);
		return e == EWOULDBLOCK ? HOLDER_HELD : HOLDER_ERROR;
	}
	/* Its last holder removes it before letting go: the file we locked may
	 * no longer be the one at path, and a lock on that one locks nothing. */
	if (stat(path, &now) != 0 || now.st_dev != st.st_dev || now.st_ino != st.st_ino) {
		close(fd);
		return -3;
	}
	return fd;
}

int holder_lockfile_take(const char *path, const char *detail, struct holder *who, char *err, size_t errcap)
{
	memset(who, 0, sizeof *who);
	for (int i = 0; i < HOLDER_TAKE_TRIES; i++) {
		int fd = holder_lockfile_try(path, who, err, errcap);
		if (fd == -3)
			continue;
		if (fd < 0)
			return fd;
		/* the text only names the holder, the flock is the lock: a text
		 * that could not be written costs the name, not the lock */
		(void)holder_write_self(fd, detail);
		return fd;
	}
	snprintf(err, errcap, "cannot lock %s: it keeps being replaced", path);
	return HOLDER_ERROR;
}

void holder_lockfile_drop(const char *path, int fd)
{
	if (fd < 0)
		return;
	/* removed while still locked: whoever opened it meanwhile sees the
	 * path changed once it has the lock, and opens it again */
	unlink(path);
	close(fd);
}
