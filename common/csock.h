/*
 * csock.h — the local command socket: how programs on this computer command a
 * robot without the network.
 *
 * A daemon listens on a unix datagram socket "<dir>/<robot>@<net>.cmd", where
 * <net> names its LCM network ("239.255.76.67-7667": the same robot name on
 * two LCM networks are two robots). Sending to it needs write permission on
 * the socket file (mode 0660: the daemon's user and group) and on its
 * directory; the kernel tells the daemon the sender's uid, gid and pid with
 * every datagram (SO_PASSCRED), which is what it logs — not a name the sender
 * chose. A datagram holds one encoded command_t; the answer (an encoded
 * event_t) goes back to the sender's own, autobound, address.
 *
 * Directories: $UNDULATE_RUN_DIR if set; a daemon under systemd uses its
 * $RUNTIME_DIRECTORY; otherwise $XDG_RUNTIME_DIR/undulate, /run/undulate
 * (root), /tmp/undulate-UID (created 0700, refused if someone else owns it).
 * Clients search $UNDULATE_RUN_DIR alone when it is set, else every one of
 * these that exists.
 */
#ifndef UNDULATE_COMMON_CSOCK_H
#define UNDULATE_COMMON_CSOCK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <sys/un.h>

#define CSOCK_PATH_MAX 108            /* sizeof sun_path */
#define CSOCK_DIRS 4
#define CSOCK_DGRAM_MAX 2048          /* a command_t or event_t is far smaller */

/* The directory a daemon puts its socket in (created if it is one of ours).
 * `configured`: the [robot] run_dir key ("" if unset). */
bool csock_daemon_dir(char *out, size_t cap, const char *configured, char *why, size_t why_cap);
/* The directories a client searches, in order; returns how many. */
size_t csock_client_dirs(char out[CSOCK_DIRS][CSOCK_PATH_MAX]);
/* "<dir>/<robot>@<net>.cmd"; false if it does not fit a socket address. */
bool csock_path(char *out, size_t cap, const char *dir, const char *robot, const char *lcm_url);

/* ---- the daemon's side ------------------------------------------------------------------- */
/* Bind a non-blocking datagram socket at path (mode 0660). A socket file left
 * by a daemon that died is replaced; one a running daemon answers on, or a
 * path that is not a socket, is refused. -1 with *why. */
int csock_listen(const char *path, char *why, size_t cap);

struct csock_peer {
	struct sockaddr_un addr;       /* where to answer (empty: the sender cannot be answered) */
	socklen_t addr_len;
	bool cred;                     /* the kernel's credentials came with the datagram */
	uid_t uid;
	gid_t gid;
	pid_t pid;
};
/* One datagram: its length, 0 when none is waiting, -1 on error. A datagram
 * longer than cap is cut (*truncated set). */
ssize_t csock_recv(int fd, uint8_t *buf, size_t cap, struct csock_peer *peer, bool *truncated);
/* Answer; never blocks (a client that stopped reading loses its answer). */
bool csock_reply(int fd, const struct csock_peer *peer, const void *buf, size_t n);
void csock_close(int fd, const char *path);

/* ---- a client's side ------------------------------------------------------------------------ */
/* A datagram socket with an autobound (abstract) address, so answers reach it. */
int csock_client_open(char *why, size_t cap);
/* Every socket for `robot` ("*": every robot) on the LCM network of lcm_url,
 * in the client directories; returns how many (at most max). */
size_t csock_find(const char *robot, const char *lcm_url, char paths[][CSOCK_PATH_MAX], size_t max);
/* The robot name in a socket path ("…/r1@239.255.76.67-7667.cmd" -> "r1"). */
void csock_robot_of(const char *path, char *out, size_t cap);
bool csock_send(int fd, const char *path, const void *buf, size_t n, char *why, size_t cap);

#endif
