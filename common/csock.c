/* csock.c — see csock.h. */
/* struct ucred and SCM_CREDENTIALS are Linux extensions */
#define _GNU_SOURCE
#include "csock.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "udpm.h"

#define CSOCK_SUFFIX ".cmd"

/* Copies a path that is known to fit (both CSOCK_PATH_MAX arrays). */
static void csock_copy(char *dst, const char *src)
{
	size_t n = strnlen(src, CSOCK_PATH_MAX - 1);
	memcpy(dst, src, n);
	dst[n] = '\0';
}

static bool csock_set(char *out, size_t cap, const char *a, const char *b)
{
	int n = snprintf(out, cap, "%s%s", a, b);
	return n > 0 && (size_t)n < cap;
}

/* A directory of our own in a shared place (/tmp): it must be ours and not
 * writable by others, or someone could put a socket there first. */
static bool csock_private_dir(const char *dir, char *why, size_t cap)
{
	if (mkdir(dir, 0700) != 0 && errno != EEXIST) {
		snprintf(why, cap, "%s: %s", dir, strerror(errno));
		return false;
	}
	struct stat st;
	if (lstat(dir, &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != geteuid() || (st.st_mode & 022) != 0) {
		snprintf(why, cap, "%s: not a directory of this user's that only it may write (remove it, or set "
		         "UNDULATE_RUN_DIR)", dir);
		return false;
	}
	return true;
}

/* out = a b, or false with *why. */
static bool csock_set_dir(char *out, size_t cap, const char *a, const char *b, char *why, size_t why_cap)
{
	if (csock_set(out, cap, a, b))
		return true;
	snprintf(why, why_cap, "'%.200s%s': too long for the socket's directory (%zu bytes at most)", a, b, cap - 1);
	return false;
}

bool csock_daemon_dir(char *out, size_t cap, const char *configured, char *why, size_t why_cap)
{
	const char *env;
	if (configured != NULL && configured[0] != '\0')
		return csock_set_dir(out, cap, configured, "", why, why_cap);
	if ((env = getenv("UNDULATE_RUN_DIR")) != NULL && env[0] != '\0')
		return csock_set_dir(out, cap, env, "", why, why_cap);
	if ((env = getenv("RUNTIME_DIRECTORY")) != NULL && env[0] != '\0') {
		/* systemd may list several, separated by ':' — the first is ours */
		char first[CSOCK_PATH_MAX];
		size_t n = strcspn(env, ":");
		if (n >= sizeof first) {
			snprintf(why, why_cap, "RUNTIME_DIRECTORY: its first directory is longer than %zu bytes",
			         sizeof first - 1);
			return false;
		}
		memcpy(first, env, n);
		first[n] = '\0';
		return csock_set_dir(out, cap, first, "", why, why_cap);
	}
	if ((env = getenv("XDG_RUNTIME_DIR")) != NULL && env[0] != '\0') {
		if (!csock_set_dir(out, cap, env, "/undulate", why, why_cap))
			return false;
		if (mkdir(out, 0700) != 0 && errno != EEXIST) {
			snprintf(why, why_cap, "%s: %s", out, strerror(errno));
			return false;
		}
		return true;
	}
	if (geteuid() == 0) {
		if (!csock_set_dir(out, cap, "/run/undulate", "", why, why_cap))
			return false;
		if (mkdir(out, 0750) != 0 && errno != EEXIST) {
			snprintf(why, why_cap, "%s: %s", out, strerror(errno));
			return false;
		}
		return true;
	}
	snprintf(out, cap, "/tmp/undulate-%u", (unsigned)geteuid());
	return csock_private_dir(out, why, why_cap);
}

size_t csock_client_dirs(char out[CSOCK_DIRS][CSOCK_PATH_MAX])
{
	const char *env = getenv("UNDULATE_RUN_DIR");
	if (env != NULL && env[0] != '\0') {
		snprintf(out[0], CSOCK_PATH_MAX, "%s", env);
		return 1;
	}
	char cand[3][CSOCK_PATH_MAX];
	size_t nc = 0, n = 0;
	if ((env = getenv("XDG_RUNTIME_DIR")) != NULL && env[0] != '\0')
		snprintf(cand[nc++], CSOCK_PATH_MAX, "%s/undulate", env);
	snprintf(cand[nc++], CSOCK_PATH_MAX, "/run/undulate");
	snprintf(cand[nc++], CSOCK_PATH_MAX, "/tmp/undulate-%u", (unsigned)geteuid());
	for (size_t i = 0; i < nc; i++) {
		bool dup = false;
		for (size_t k = 0; k < n; k++)
			dup = dup || strcmp(out[k], cand[i]) == 0;
		if (!dup)
			csock_copy(out[n++], cand[i]);
	}
	return n;
}

bool csock_path(char *out, size_t cap, const char *dir, const char *robot, const char *lcm_url)
{
	char net[96];
	udpm_net_name(lcm_url, net, sizeof net);
	size_t limit = cap < CSOCK_PATH_MAX ? cap : CSOCK_PATH_MAX;
	int n = snprintf(out, limit, "%s/%s@%s%s", dir, robot, net, CSOCK_SUFFIX);
	return n > 0 && (size_t)n < limit;
}

static bool csock_addr(struct sockaddr_un *sa, const char *path)
{
	memset(sa, 0, sizeof *sa);
	sa->sun_family = AF_UNIX;
	if (strlen(path) >= sizeof sa->sun_path)
		return false;
	memcpy(sa->sun_path, path, strlen(path) + 1);
	return true;
}

/* Does a daemon answer on this socket file? (connect() to a datagram socket
 * nobody has bound fails with ECONNREFUSED.) */
static bool csock_alive(const char *path)
{
	struct sockaddr_un sa;
	if (!csock_addr(&sa, path))
		return false;
	int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
	if (fd < 0)
		return false;
	bool alive = connect(fd, (struct sockaddr *)&sa, sizeof sa) == 0;
	close(fd);
	return alive;
}

int csock_listen(const char *path, char *why, size_t cap)
{
	struct sockaddr_un sa;
	if (!csock_addr(&sa, path)) {
		snprintf(why, cap, "%s: longer than a socket address (%zu bytes): a shorter run_dir or robot name",
		         path, sizeof sa.sun_path - 1);
		return -1;
	}
	struct stat st;
	if (lstat(path, &st) == 0) {
		if (!S_ISSOCK(st.st_mode)) {
			snprintf(why, cap, "%s exists and is not a socket: not replaced", path);
			return -1;
		}
		if (csock_alive(path)) {
			snprintf(why, cap, "%s: another undulated for this robot runs on this computer and LCM network",
			         path);
			return -1;
		}
		unlink(path);
	}
	int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (fd < 0) {
		snprintf(why, cap, "socket: %s", strerror(errno));
		return -1;
	}
	int one = 1;
	/* bind under a umask that leaves no window with a wider mode */
	mode_t old = umask(0117);
	int rc = bind(fd, (struct sockaddr *)&sa, sizeof sa);
	umask(old);
	if (rc != 0 || setsockopt(fd, SOL_SOCKET, SO_PASSCRED, &one, sizeof one) != 0) {
		snprintf(why, cap, "%s: %s", path, strerror(errno));
		close(fd);
		return -1;
	}
	return fd;
}

ssize_t csock_recv(int fd, uint8_t *buf, size_t cap, struct csock_peer *peer, bool *truncated)
{
	union {
		struct cmsghdr h;
		char space[CMSG_SPACE(sizeof(struct ucred))];
	} ctrl;
	struct iovec iov = { .iov_base = buf, .iov_len = cap };
	memset(peer, 0, sizeof *peer);
	struct msghdr m = {
		.msg_name = &peer->addr, .msg_namelen = sizeof peer->addr, .msg_iov = &iov, .msg_iovlen = 1,
		.msg_control = ctrl.space, .msg_controllen = sizeof ctrl.space,
	};
	ssize_t n = recvmsg(fd, &m, MSG_DONTWAIT | MSG_CMSG_CLOEXEC);
	if (n < 0)
		return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? 0 : -1;
	peer->addr_len = m.msg_namelen;
	*truncated = (m.msg_flags & MSG_TRUNC) != 0;
	for (struct cmsghdr *c = CMSG_FIRSTHDR(&m); c != NULL; c = CMSG_NXTHDR(&m, c)) {
		if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_CREDENTIALS &&
		    c->cmsg_len == CMSG_LEN(sizeof(struct ucred))) {
			struct ucred cr;
			memcpy(&cr, CMSG_DATA(c), sizeof cr);
			peer->cred = true;
			peer->uid = cr.uid;
			peer->gid = cr.gid;
			peer->pid = cr.pid;
		}
	}
	return n;
}

bool csock_reply(int fd, const struct csock_peer *peer, const void *buf, size_t n)
{
	if (peer->addr_len <= sizeof(sa_family_t))
		return false;
	return sendto(fd, buf, n, MSG_DONTWAIT | MSG_NOSIGNAL, (const struct sockaddr *)&peer->addr,
	              peer->addr_len) == (ssize_t)n;
}

void csock_close(int fd, const char *path)
{
	if (fd >= 0)
		close(fd);
	if (path != NULL && path[0] != '\0')
		unlink(path);
}

int csock_client_open(char *why, size_t cap)
{
	int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
	if (fd < 0) {
		snprintf(why, cap, "socket: %s", strerror(errno));
		return -1;
	}
	/* Linux autobind: an address of only the family gets a unique abstract name */
	struct sockaddr_un sa = { .sun_family = AF_UNIX };
	if (bind(fd, (struct sockaddr *)&sa, sizeof(sa_family_t)) != 0) {
		snprintf(why, cap, "bind: %s", strerror(errno));
		close(fd);
		return -1;
	}
	return fd;
}

void csock_robot_of(const char *path, char *out, size_t cap)
{
	const char *base = strrchr(path, '/');
	base = base ? base + 1 : path;
	size_t n = strcspn(base, "@");
	snprintf(out, cap, "%.*s", (int)n, base);
}

size_t csock_find(const char *robot, const char *lcm_url, char paths[][CSOCK_PATH_MAX], size_t max)
{
	char dirs[CSOCK_DIRS][CSOCK_PATH_MAX], net[96], tail[128];
	size_t ndirs = csock_client_dirs(dirs), n = 0;
	udpm_net_name(lcm_url, net, sizeof net);
	snprintf(tail, sizeof tail, "@%s%s", net, CSOCK_SUFFIX);
	bool all = strcmp(robot, "*") == 0;
	for (size_t d = 0; d < ndirs && n < max; d++) {
		if (!all) {
			char p[CSOCK_PATH_MAX];
			struct stat st;
			if (csock_path(p, sizeof p, dirs[d], robot, lcm_url) && stat(p, &st) == 0 && S_ISSOCK(st.st_mode))
				csock_copy(paths[n++], p);
			continue;
		}
		DIR *dp = opendir(dirs[d]);
		if (dp == NULL)
			continue;
		for (struct dirent *e; (e = readdir(dp)) != NULL && n < max;) {
			size_t len = strlen(e->d_name), tl = strlen(tail);
			if (len <= tl || strcmp(e->d_name + len - tl, tail) != 0)
				continue;
			char p[CSOCK_PATH_MAX];
			int w = snprintf(p, sizeof p, "%s/%s", dirs[d], e->d_name);
			struct stat st;
			if (w > 0 && (size_t)w < sizeof p && stat(p, &st) == 0 && S_ISSOCK(st.st_mode))
				csock_copy(paths[n++], p);
		}
		closedir(dp);
	}
	return n;
}

bool csock_send(int fd, const char *path, const void *buf, size_t n, char *why, size_t cap)
{
	struct sockaddr_un sa;
	if (!csock_addr(&sa, path)) {
		snprintf(why, cap, "%s: path too long", path);
		return false;
	}
	if (sendto(fd, buf, n, MSG_NOSIGNAL, (struct sockaddr *)&sa, sizeof sa) != (ssize_t)n) {
		snprintf(why, cap, "%s: %s%s", path, strerror(errno),
		         errno == EACCES ? " (commanding this robot needs its user or group: see the README's safety section)"
		         : errno == ECONNREFUSED ? " (no daemon listens: it stopped)" : "");
		return false;
	}
	return true;
}
