/*
 * port_lock.c — one owner per bus: port_open() takes the bus device for its
 * program before it touches the line, and a second program is refused with
 * the name of the first ("held by undulated (pid 812, robot r1)").
 *
 * Three locks, because no one of them is honoured by everybody:
 *  - flock(LOCK_EX | LOCK_NB) on the device decides among our programs, and
 *    against picocom and pyserial (exclusive=True), which take the same lock.
 *    It is the device's inode that is locked, so every path to it (a by-id
 *    name, a simulator's link, the pty itself) meets the one lock; root is
 *    not above it; it dies with its process, so a SIGKILL leaves nothing stale.
 *  - TIOCEXCL (port.c, real ports): the kernel refuses any further open, also
 *    by programs that take no lock at all — except root's.
 *  - a UUCP lock file, /var/lock/LCK..ttyUSB0: minicom and the tools of its
 *    lineage write one and look for one. One naming a live program refuses
 *    the port; ours is written (pid, program, what it does with the bus) so
 *    that the refused program can name us, whoever it runs as.
 * The holder is found through the kernel's table of locks (/proc/locks) and
 * that lock file (common/holder.c). All of it runs in port_open() and
 * port_close(): nothing per cycle.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "holder.h"
#include "port.h"

/* /proc/PID/comm keeps the first 15 characters of a program's name (TASK_COMM_LEN - 1). */
#define PORT_COMM_LEN 15

const char *port_lock_dir(void)
{
	const char *dir = getenv("UNDULATE_LOCK_DIR");

	return (dir != NULL && dir[0] != '\0') ? dir : "/var/lock";
}

/* LOCKDIR/LCK..ttyUSB0 for /dev/ttyUSB0: the name below /dev with '/' made
 * '_' (LCK..pts_3), as minicom names them; the last component elsewhere. */
static void port_lock_file(const char *real, char *out, size_t cap)
{
	char name[PORT_LOCKFILE_MAX];
	const char *below = real, *slash = strrchr(real, '/');

	if (strncmp(real, "/dev/", 5) == 0)
		below = real + 5;
	else if (slash != NULL)
		below = slash + 1;
	snprintf(name, sizeof name, "%s", below);
	for (char *s = name; *s != '\0'; s++)
		if (*s == '/')
			*s = '_';
	int n = snprintf(out, cap, "%s/LCK..%s", port_lock_dir(), name);
	/* a name cut short would be another device's: none then ("" is never read or written) */
	if (n < 0 || (size_t)n >= cap)
		out[0] = '\0';
}

/* Whether a lock file's holder still holds the port: alive, not us (a file
 * of ours left by a port closed without it), and — when the file names its
 * program — still that program (the pid of a killed holder is reused). */
static bool port_lock_file_live(const struct holder *f)
{
	struct holder now;

	if (f->pid == (long)getpid() || !holder_alive(f->pid))
		return false;
	if (f->program[0] == '\0' || !holder_from_pid(f->pid, &now))
		return true;
	return strncmp(now.program, f->program, PORT_COMM_LEN) == 0;
}

/* A live lock file's holder, its detail saying which file (what to remove
 * if it is wrong). */
static bool port_lock_file_holder(const char *file, struct holder *h)
{
	struct holder f, now;

	if (!holder_read_file(file, &f) || !port_lock_file_live(&f))
		return false;
	*h = f;
	/* a pid alone (HDB's format): the process says what it is */
	if (h->program[0] == '\0' && holder_from_pid(f.pid, &now))
		snprintf(h->program, sizeof h->program, "%s", now.program);
	h->robot[0] = '\0';
	snprintf(h->detail, sizeof h->detail, "lock file %s", file);
	return true;
}

bool port_holder(const char *path, struct holder *h)
{
	char real[PATH_MAX], file[PORT_LOCKFILE_MAX];
	struct stat st;
	struct holder f;
	long pid = 0;

	memset(h, 0, sizeof *h);
	if (realpath(path, real) == NULL || stat(real, &st) != 0)
		return false;
	port_lock_file(real, file, sizeof file);
	if (holder_flock_pid(st.st_dev, st.st_ino, &pid)) {
		/* ours write what they do with the bus into the lock file */
		if (holder_read_file(file, &f) && f.pid == pid)
			*h = f;
		else if (!holder_from_pid(pid, h))
			h->pid = pid;
		return true;
	}
	return port_lock_file_holder(file, h);
}

/* "cannot open PATH: held by undulated (pid 812, robot r1)", and *out (may be NULL) = h. */
static int port_claim_refuse(const struct holder *h, struct holder *out, const char *shown, const char *how, char *err,
                             size_t errcap)
{
	char who[HOLDER_PROGRAM_MAX + HOLDER_DETAIL_MAX + 32];

	holder_format(h, who, sizeof who);
	if (out != NULL)
		*out = *h;
	if (err != NULL && errcap > 0)
		snprintf(err, errcap, "cannot open %s: held by %s%s", shown, who, how);
	return DXL_E_BUSY;
}

/* Write our UUCP lock file, as UUCP does: a temporary file linked to the
 * name, so that nobody ever reads half of it. Best effort: a lock directory
 * we may not write (a hardened service, another user's stale file in the
 * sticky /var/lock) costs the name in a refusal, not the lock. */
static void port_lock_file_write(struct port_claim *c, const char *file, const char *owner)
{
	struct holder me = { .pid = (long)getpid() };
	char line[HOLDER_PROGRAM_MAX + HOLDER_DETAIL_MAX + 16], tmp[PORT_LOCKFILE_MAX];

	holder_self_program(me.program, sizeof me.program);
	snprintf(me.detail, sizeof me.detail, "%s", owner != NULL ? owner : "");
	int n = holder_line(&me, line, sizeof line);
	int w = snprintf(tmp, sizeof tmp, "%s/LTMP.%ld", port_lock_dir(), me.pid);
	if (n <= 0 || file[0] == '\0' || w <= 0 || (size_t)w >= sizeof tmp)
		return;
	int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
	if (fd < 0)
		return;
	/* readable by everybody whatever the umask: a pid and a name */
	bool ok = write(fd, line, (size_t)n) == n && fchmod(fd, 0644) == 0;
	ok = close(fd) == 0 && ok;
	/* one there already is a stale one (port_claim_take checked): replaced */
	if (ok && link(tmp, file) != 0)
		ok = errno == EEXIST && unlink(file) == 0 && link(tmp, file) == 0;
	unlink(tmp);
	if (ok)
		snprintf(c->lockfile, sizeof c->lockfile, "%s", file);
}

/* Open the device for the lock alone: the open's errors, with the holder
 * when the kernel's TIOCEXCL refused it. */
static int port_claim_open(struct port_claim *c, const char *real, const char *shown, struct holder *out, char *err,
                           size_t errcap)
{
	struct holder h;

	c->fd = open(real, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
	if (c->fd >= 0)
		return DXL_OK;
	int e = errno;
	if (e == EBUSY) {
		if (port_holder(real, &h))
			return port_claim_refuse(&h, out, shown, " (TIOCEXCL)", err, errcap);
		snprintf(err, errcap, "cannot open %s: in exclusive use by another program (TIOCEXCL; `fuser -v %s` names it)",
		         shown, real);
		return DXL_E_BUSY;
	}
	snprintf(err, errcap, "cannot open %s: %s", shown,
	         e == EACCES ? "permission denied (is the user in the dialout group?)" : strerror(e));
	return e == ENOENT ? DXL_E_ARG : DXL_E_IO;
}

int port_claim_take(struct port_claim *c, const char *real, const char *shown, const char *owner, struct holder *out,
                    char *err, size_t errcap)
{
	char file[PORT_LOCKFILE_MAX];
	struct holder h;
	int rc;

	c->fd = -1;
	c->lockfile[0] = '\0';
	if (out != NULL)
		memset(out, 0, sizeof *out);
	if ((rc = port_claim_open(c, real, shown, out, err, errcap)) != DXL_OK)
		return rc;
	int r;
	do
		r = flock(c->fd, LOCK_EX | LOCK_NB);
	while (r != 0 && errno == EINTR);
	if (r != 0 && errno == EWOULDBLOCK) {
		close(c->fd);
		c->fd = -1;
		if (!port_holder(real, &h))
			memset(&h, 0, sizeof h);   /* gone meanwhile, or in a pid namespace we cannot see */
		return port_claim_refuse(&h, out, shown, "", err, errcap);
	}
	/* flock() cannot fail otherwise on a device we opened (ENOLCK aside):
	 * carry on, the kernel's TIOCEXCL and the lock file still guard it */
	port_lock_file(real, file, sizeof file);
	if (port_lock_file_holder(file, &h)) {
		port_claim_drop(c);
		return port_claim_refuse(&h, out, shown, "", err, errcap);
	}
	port_lock_file_write(c, file, owner);
	return DXL_OK;
}

void port_claim_drop(struct port_claim *c)
{
	struct holder f;

	/* ours only: a file some other program wrote meanwhile stays */
	if (c->lockfile[0] != '\0' && holder_read_file(c->lockfile, &f) && f.pid == (long)getpid())
		unlink(c->lockfile);
	c->lockfile[0] = '\0';
	if (c->fd >= 0)
		close(c->fd);
	c->fd = -1;
}
