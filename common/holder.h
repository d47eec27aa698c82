/*
 * holder.h — who holds a bus: the program behind a lock, named for the
 * message that refuses a second one ("held by undulated (pid 812, robot r1)").
 *
 * One bus has one owner: undulated, dxl and undulate-sim --link take theirs
 * exclusively (protocol/io/port_lock.c for a bus device, holder_lockfile_take
 * below for a simulator's link). What names the holder is read from /proc
 * (the kernel's table of locks, a process's name and command line) and from
 * lock files, whose text is outside input: bounded and made printable.
 * Nothing here runs after start-up.
 */
#ifndef UNDULATE_COMMON_HOLDER_H
#define UNDULATE_COMMON_HOLDER_H

#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

#define HOLDER_PROGRAM_MAX 32   /* a program's name: /proc/PID/comm keeps 15 characters */
#define HOLDER_DETAIL_MAX 192   /* "robot r1", "command scan", "lock file <a path>" */
#define HOLDER_ROBOT_MAX 48     /* a robot's name (daemon/config.h CFG_NAME_MAX) */

struct holder {
	long pid;                          /* 0: not known */
	char program[HOLDER_PROGRAM_MAX];  /* "undulated", "dxl", "minicom"; "" not known */
	char detail[HOLDER_DETAIL_MAX];    /* what it does with the bus; may be "" */
	char robot[HOLDER_ROBOT_MAX];      /* the robot an undulated drives, when known */
};

/* Whether a process with this pid exists (kill(pid, 0): EPERM counts). */
bool holder_alive(long pid);
/* The process pid as it is now: its name (/proc/PID/comm) and, for an
 * undulated, the robot its command line names (--robot NAME, --set
 * robot.name=NAME). False when it is gone. */
bool holder_from_pid(long pid, struct holder *h);
/* The pid holding a flock() on the file (dev, ino), from /proc/locks
 * (world-readable, unlike another user's /proc/PID/fd). False when none. */
bool holder_flock_pid(dev_t dev, ino_t ino, long *pid);
/* "undulated (pid 812, robot r1)", "another program" when nothing is known. */
void holder_format(const struct holder *h, char *out, size_t cap);
/* This process's name (/proc/self/comm), "?" if it cannot be read. */
void holder_self_program(char *out, size_t cap);

/* The line a lock file holds: "%10ld PROGRAM DETAIL\n", the pid first and
 * ten wide as UUCP's (HDB) lock files have it, so minicom and the tools of
 * its lineage read ours. Returns its length, or -1 when it does not fit. */
int holder_line(const struct holder *h, char *out, size_t cap);
/* Parse a lock file's text: the pid (1..4194304), then, when given, the
 * program and the rest of the line (printable ASCII kept, the rest '?').
 * "robot NAME" as the detail gives the robot. False without a pid. */
bool holder_parse(const char *text, struct holder *h);
/* Read the lock file at path (a regular file, not followed if a symlink,
 * at most 512 bytes) and parse it. False when absent or not a lock. */
bool holder_read_file(const char *path, struct holder *h);

/* ---- a lock file that is itself the lock (a simulator's link) ---------------- */
enum { HOLDER_HELD = -2, HOLDER_ERROR = -1 };
/* Take the lock file at path for this process: created if missing (never
 * through a symlink, never anything but a regular file), flock()ed so that
 * the lock dies with the process, and holding "PID PROGRAM DETAIL". Returns
 * its fd (keep it open for as long as the lock is held); HOLDER_HELD with
 * *who filled when a live process holds it; HOLDER_ERROR with one line in
 * err otherwise. A file left by a killed holder is taken over. */
int holder_lockfile_take(const char *path, const char *detail, struct holder *who, char *err, size_t errcap);
/* Remove the lock file and release it (fd from holder_lockfile_take; -1: nothing). */
void holder_lockfile_drop(const char *path, int fd);

#endif
