/*
 * textfile.h — a text file a person named on a command line (a robot's
 * configuration, a simulator scenario), read whole into memory. Only a
 * regular file of at most TEXTFILE_MAX_BYTES with no NUL byte is read;
 * anything else is refused at once with one line "PATH: why", because
 * opening a FIFO blocks until a writer comes, /dev/zero never ends, opening
 * a device can have effects of its own (a serial port raises DTR), and a NUL
 * byte would silently end a line early for a parser of C strings.
 */
#ifndef UNDULATE_COMMON_TEXTFILE_H
#define UNDULATE_COMMON_TEXTFILE_H

#include <stddef.h>

/* 1 MiB: 500 times the largest configuration or scenario we ship (2 kB),
 * small enough to hold in memory at start-up. */
#define TEXTFILE_MAX_BYTES (1024 * 1024)

/* Reads path into a new buffer (free() it): *len bytes followed by a NUL.
 * `what` names the contents in messages ("a scenario"). On failure returns
 * NULL with one of these in err (errcap bytes with the NUL):
 *     PATH: cannot open: No such file or directory
 *     PATH: not a regular file (a FIFO): a scenario is a text file
 *     PATH: larger than 1 MiB (2097152 bytes): not a scenario
 *     PATH:LINE: a NUL byte: a scenario is a text file
 *     PATH: cannot read: Input/output error
 * A symbolic link to a regular file is read. The type is checked before
 * open() (a FIFO would block it) and again on the open descriptor, in case
 * the path was replaced in between; reading stops one byte past the limit,
 * in case the file grew. */
char *textfile_read(const char *path, const char *what, size_t *len, char *err, size_t errcap);

#endif
