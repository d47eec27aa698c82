/* wsrecv.h — the bytes libwebsockets reads from each connection, through
 * wsguard.h. libwebsockets 4.1 reads its sockets with recv() and offers no
 * hook between that read and its frame parser (nor a way to ask whether a
 * frame was masked), so this program defines recv() itself: the executable's
 * definition comes first in the dynamic lookup, as an LD_PRELOAD library's
 * would, and libwebsockets' calls reach it. It reads with recvfrom(), exactly
 * what recv() is, and feeds what it read on a watched descriptor to that
 * connection's guard; every other descriptor (LCM's, the command socket's)
 * passes untouched. Single-threaded use: the server's loop watches and asks. */
#ifndef UNDULATE_WEB_WSRECV_H
#define UNDULATE_WEB_WSRECV_H

#include <stdbool.h>

#include "wsguard.h"

/* Descriptors watched: libwebsockets' limit (server.h) is far below. */
#define WSR_FDS 1024

/* A connection just accepted on fd: its guard starts afresh. False if fd is
 * beyond the table (the connection must be refused). */
bool wsr_watch(int fd);
/* Its WebSocket handshake was answered: frames from now (wsg_upgraded). */
enum wsg_verdict wsr_upgraded(int fd);
/* What its client sent so far (WSG_OK for a descriptor not watched). */
enum wsg_verdict wsr_verdict(int fd);
/* Closed: fd is no longer watched. */
void wsr_forget(int fd);
/* Whether recv() reaches this guard: false if the dynamic linker bound
 * libwebsockets elsewhere (then the server must not start). */
bool wsr_interposed(void);

#endif
