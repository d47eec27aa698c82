/*
 * outdir.h — where a tool writes its results (undulate-analyze --out DIR,
 * undulated --tune --out FILE). Files go only where they were asked to go.
 *
 * A directory another user can write may hold, under the very names we are
 * about to write, a symbolic link to a file of ours (fopen("w") would
 * truncate the file it points to: as root, any file) or a FIFO (opening it
 * blocks, and a program run on it reads what the other user feeds it). So:
 *
 *  - outdir_open() accepts only a directory that is ours and that no other
 *    user can write, reached through symbolic links that we or root made;
 *  - every file is created new (O_CREAT|O_EXCL|O_NOFOLLOW) under a name no
 *    one chose, and rename()d over its final name at the end: rename replaces
 *    a link or FIFO of that name, it never follows or opens it;
 *  - a program run on what we wrote (gnuplot) runs inside a fresh private
 *    directory (outdir_stage) that only we can write.
 *
 * Messages are one line "PATH: why: what to do", for the caller to prefix
 * with its name and option ("undulate-analyze: --out ").
 */
#ifndef UNDULATE_COMMON_OUTDIR_H
#define UNDULATE_COMMON_OUTDIR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

/* Symbolic links followed on the way to a directory at most (the kernel's
 * own limit, MAXSYMLINKS, is 40). */
#define OUTDIR_MAX_LINKS 40

/* Opens directory PATH to write results in, or refuses it. Walks PATH one
 * name at a time without following links by itself; a symbolic link met on
 * the way is followed only when it is ours or root's (another user's link
 * chooses where our files land). The directory reached must be:
 *   - owned by us (the effective user: root's own when we are root);
 *   - not writable by anyone else: no write bit for others, none for the
 *     group unless the group is ours alone (Debian's user private groups,
 *     umask 002), unless the directory is sticky (then others cannot remove
 *     or rename what we create, and we, its owner, replace whatever they put);
 * With create, a missing last name is made (mode 0755 less the umask; its
 * parent must exist). Returns an O_DIRECTORY descriptor (close() it), or -1
 * with err (errcap bytes with the NUL) saying why, e.g.
 *     /tmp/rig: owned by nobody (uid 65534), not by you (root): another user could put links or FIFOs
 *         in it under the names written there; choose a directory of yours (a new one is made)
 *     /tmp/rig: writable by other users (mode 0777): another user could put links or FIFOs in it under
 *         the names written there; chmod go-w /tmp/rig, or choose another directory
 *     /tmp/rig/run1: the symbolic link rig on the way is owned by nobody (uid 65534), not by you or
 *         root: another user chooses where it leads; give the directory itself
 *     notes.txt/run1: notes.txt is not a directory
 */
int outdir_open(const char *path, bool create, char *err, size_t errcap);

/* For a file PATH to be written (--tune --out FILE, --record FILE): opens
 * the directory it is in with outdir_open() (not made) and puts the file's
 * own name into name (namecap bytes); a bare name's directory is the working
 * one, which messages name by its path. Returns the directory's descriptor,
 * or -1 with err (also for a PATH that names a directory: "", "x/", ".."). */
int outdir_open_parent(const char *path, char *name, size_t namecap, char *err, size_t errcap);

/* Creates NAME in dirfd to write in place, for a file read while it grows (a
 * recording), where a temporary name would hide it until the end: what has
 * that name (a file, a link, a FIFO) is removed, then the file is made
 * O_CREAT|O_EXCL|O_NOFOLLOW (0666 less the umask); in a directory that only
 * we can write nothing can come in between. Returns the descriptor, or -1
 * with err (a directory of that name is not removed). */
int outdir_create_in_place(int dirfd, const char *name, char *err, size_t errcap);

/* Makes a fresh private directory (0700) inside dirfd named PREFIX.XXXXXX
 * (a random suffix, retried if taken). Returns its descriptor and its name in
 * name (namecap bytes), or -1 with err. */
int outdir_stage(int dirfd, const char *prefix, char *name, size_t namecap, char *err, size_t errcap);

/* Moves every regular file of the stage (stagefd, named stagename inside
 * dirfd) into dirfd under its own name, replacing what is there (a file,
 * a link or a FIFO of that name: replaced, never followed or opened), then
 * removes the stage with anything left in it. 0, or -1 with err naming the
 * first file that could not be moved (the others are still moved). Does not
 * close stagefd. */
int outdir_publish(int dirfd, int stagefd, const char *stagename, char *err, size_t errcap);

/* Removes the stage and what it holds, without publishing any of it. */
void outdir_discard(int dirfd, int stagefd, const char *stagename);

/* Creates NAME new in a stage (outdir_stage: only we can write there, so
 * nothing can be there before us; O_CREAT|O_EXCL|O_NOFOLLOW, 0666 less the
 * umask) and opens it to write. NULL with errno set. */
FILE *outdir_stage_fopen(int stagefd, const char *name);
/* Closes *f and sets it NULL (a NULL *f: nothing to do, 0). -1 when a
 * write to it or the close failed: a full disk shows only here. */
int outdir_stage_fclose(FILE **f);

/* One file written into a directory: created under a temporary name
 * ".NAME.XXXXXX" (O_CREAT|O_EXCL|O_NOFOLLOW, mode 0666 less the umask),
 * renamed over NAME by outdir_file_commit(). */
struct outdir_file {
	int dirfd;          /* not owned */
	int fd;             /* -1 when closed */
	char tmp[300];
	char name[256];
};

/* Starts NAME (a plain name, no '/') in dirfd. Returns the descriptor to
 * write (owned by f until commit or abandon), or -1 with err. */
int outdir_file_create(struct outdir_file *f, int dirfd, const char *name, char *err, size_t errcap);
/* Syncs and closes the file, then renames it over NAME. 0, or -1 with err
 * (the temporary file is removed). With a FILE opened on f->fd, fclose() it
 * first and pass closed = true. */
int outdir_file_commit(struct outdir_file *f, bool closed, char *err, size_t errcap);
/* Closes (unless closed) and removes the temporary file. */
void outdir_file_abandon(struct outdir_file *f, bool closed);

#endif
