/*
 * scratch.h — a private scratch directory for a unit test that writes files
 * (logs, analyser output), reading a file back whole, and a pid nobody has. Linked into every
 * unit test, like ptypeer.c.
 */
#ifndef UNDULATE_SCRATCH_H
#define UNDULATE_SCRATCH_H

#include <stdbool.h>
#include <stddef.h>

/* The directory made by scratch_make(), "" before. */
extern char scratch_dir[256];

/* Make $TMPDIR/undulate-TAG-XXXXXX (or under /tmp). 0, or -1 on failure:
 * usable as a cmocka group setup through a one-line wrapper. */
int scratch_make(const char *tag);
/* Remove the directory and everything in it. 0, or -1. */
int scratch_remove(void);
/* The two as a cmocka group's setup and teardown, the tag the test
 * program's own name (test_common_auth: $TMPDIR/undulate-test_common_auth-XXXXXX),
 * so that a test needs no wrappers of its own. */
int scratch_group_setup(void **state);
int scratch_group_teardown(void **state);
/* A file under the scratch directory, NUL-terminated, at most cap bytes read
 * (free() it); NULL if it cannot be opened. `rel` is relative to scratch_dir. */
char *scratch_slurp(const char *rel, size_t cap);
/* PATH itself (a link not followed) is a regular file of ours whose mode
 * bits (07777) are MODE: a private file as written. Else false, saying
 * what it is on stderr. */
bool scratch_private_file(const char *path, unsigned mode);
/* A pid nobody has: a child that exited and was reaped (-1 if fork failed). */
long scratch_dead_pid(void);

#endif
