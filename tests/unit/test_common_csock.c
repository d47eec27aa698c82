/* test_common_csock.c — the local command socket in a scratch directory
 * ($UNDULATE_RUN_DIR): its path and the socket address limit, a listener's
 * file (mode 0660; a non-socket refused; a stale socket replaced; a live one
 * refused), a datagram from a client with the kernel's credentials, a cut
 * datagram, the answer back to the client's autobound address, and finding
 * sockets by robot and LCM network. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include "csock.h"
#include "scratch.h"

#define URL_A "udpm://239.255.76.67:7667?ttl=0"
#define NET_A "239.255.76.67-7667"
#define URL_B "udpm://239.255.76.67:7668?ttl=1"

static int group_setup(void **state)
{
	(void)state;
	if (scratch_make("csock") != 0)
		return -1;
	/* only the directories this test names */
	unsetenv("RUNTIME_DIRECTORY");
	unsetenv("XDG_RUNTIME_DIR");
	return setenv("UNDULATE_RUN_DIR", scratch_dir, 1);
}

static int group_teardown(void **state)
{
	(void)state;
	unsetenv("UNDULATE_RUN_DIR");
	return scratch_remove();
}

/* "<scratch>/<robot>@<net of url>.cmd" */
static const char *sock_path(const char *robot, const char *url)
{
	static char p[CSOCK_PATH_MAX];
	assert_true(csock_path(p, sizeof p, scratch_dir, robot, url));
	return p;
}

static void test_path(void **state)
{
	(void)state;
	char p[CSOCK_PATH_MAX + 20];
	assert_true(csock_path(p, sizeof p, "/run/undulate", "robot1", URL_A));
	assert_string_equal(p, "/run/undulate/robot1@" NET_A ".cmd");
	assert_true(csock_path(p, sizeof p, "/d", "r", "udpm://239.1.2.3"));
	assert_string_equal(p, "/d/r@239.1.2.3-7667.cmd");
	/* a path that fills sun_path exactly with its NUL fits, one byte more not:
	 * "/" + dir + "/r@" NET_A ".cmd" = dir + 25 bytes */
	char dir[CSOCK_PATH_MAX];
	memset(dir, 'd', sizeof dir);
	dir[0] = '/';
	dir[CSOCK_PATH_MAX - 1 - 25] = '\0';
	assert_true(csock_path(p, sizeof p, dir, "r", URL_A));
	assert_int_equal(strlen(p), CSOCK_PATH_MAX - 1);
	dir[CSOCK_PATH_MAX - 1 - 25] = 'd';
	dir[CSOCK_PATH_MAX - 25] = '\0';
	assert_false(csock_path(p, sizeof p, dir, "r", URL_A));
	/* and the caller's smaller buffer is a limit too */
	assert_false(csock_path(p, 20, "/run/undulate", "robot1", URL_A));
	assert_true(csock_path(p, 40, "/d", "r", URL_A));
	/* a listener refuses what does not fit a socket address */
	char longp[CSOCK_PATH_MAX + 8], why[300] = "";
	memset(longp, 'x', sizeof longp);
	longp[0] = '/';
	longp[CSOCK_PATH_MAX] = '\0';
	assert_int_equal(csock_listen(longp, why, sizeof why), -1);
	assert_non_null(strstr(why, "longer than a socket address"));
	int c = csock_client_open(why, sizeof why);
	assert_true(c >= 0);
	assert_false(csock_send(c, longp, "x", 1, why, sizeof why));
	close(c);
}

static void test_dirs(void **state)
{
	(void)state;
	char out[CSOCK_DIRS][CSOCK_PATH_MAX], d[CSOCK_PATH_MAX], why[300];
	/* $UNDULATE_RUN_DIR alone when set */
	assert_int_equal(csock_client_dirs(out), 1);
	assert_string_equal(out[0], scratch_dir);
	assert_true(csock_daemon_dir(d, sizeof d, "", why, sizeof why));
	assert_string_equal(d, scratch_dir);
	/* the configured run_dir first */
	assert_true(csock_daemon_dir(d, sizeof d, "/srv/robots", why, sizeof why));
	assert_string_equal(d, "/srv/robots");
	/* a directory too long for any socket in it: refused with a reason */
	char longdir[200];
	memset(longdir, 'd', sizeof longdir);
	longdir[0] = '/';
	longdir[150] = '\0';
	snprintf(why, sizeof why, "unset");
	assert_false(csock_daemon_dir(d, sizeof d, longdir, why, sizeof why));
	if (strstr(why, "too long") == NULL)
		fail_msg("why '%s'", why);
	setenv("UNDULATE_RUN_DIR", longdir, 1);
	snprintf(why, sizeof why, "unset");
	assert_false(csock_daemon_dir(d, sizeof d, "", why, sizeof why));
	assert_non_null(strstr(why, "too long"));
	/* systemd's RUNTIME_DIRECTORY: the first of a list */
	unsetenv("UNDULATE_RUN_DIR");
	setenv("RUNTIME_DIRECTORY", "/run/undulate-a:/run/undulate-b", 1);
	assert_true(csock_daemon_dir(d, sizeof d, NULL, why, sizeof why));
	assert_string_equal(d, "/run/undulate-a");
	/* ... not cut short when it is too long */
	longdir[150] = ':';
	memcpy(longdir + 151, "/run/b", 7);
	setenv("RUNTIME_DIRECTORY", longdir, 1);
	snprintf(why, sizeof why, "unset");
	bool ok = csock_daemon_dir(d, sizeof d, NULL, why, sizeof why);
	if (ok)
		fail_msg("RUNTIME_DIRECTORY's 150-byte first entry gave '%s'", d);
	assert_non_null(strstr(why, "RUNTIME_DIRECTORY"));
	unsetenv("RUNTIME_DIRECTORY");
	/* $XDG_RUNTIME_DIR/undulate, made private */
	char xdg[sizeof scratch_dir + 8];
	snprintf(xdg, sizeof xdg, "%s/xdg", scratch_dir);
	assert_int_equal(mkdir(xdg, 0700), 0);
	setenv("XDG_RUNTIME_DIR", xdg, 1);
	assert_true(csock_daemon_dir(d, sizeof d, NULL, why, sizeof why));
	char want[sizeof xdg + 16];
	snprintf(want, sizeof want, "%s/undulate", xdg);
	assert_string_equal(d, want);
	struct stat st;
	assert_int_equal(stat(d, &st), 0);
	assert_true(S_ISDIR(st.st_mode));
	assert_int_equal(st.st_mode & 0077, 0);
	/* clients search every candidate, without duplicates */
	size_t n = csock_client_dirs(out);
	assert_int_equal(n, 3);
	assert_string_equal(out[0], want);
	assert_string_equal(out[1], "/run/undulate");
	snprintf(want, sizeof want, "/tmp/undulate-%u", (unsigned)geteuid());
	assert_string_equal(out[2], want);
	unsetenv("XDG_RUNTIME_DIR");
	setenv("UNDULATE_RUN_DIR", scratch_dir, 1);
}

static void test_listen_file(void **state)
{
	(void)state;
	char why[300] = "";
	const char *p = sock_path("mode", URL_A);
	mode_t old = umask(0);   /* the mode must not come from the caller's umask */
	int fd = csock_listen(p, why, sizeof why);
	umask(old);
	assert_true(fd >= 0);
	struct stat st;
	assert_int_equal(lstat(p, &st), 0);
	assert_true(S_ISSOCK(st.st_mode));
	assert_int_equal(st.st_mode & 07777, 0660);
	/* non-blocking: nothing waiting is 0, not a wait */
	assert_true(fcntl(fd, F_GETFL) & O_NONBLOCK);
	uint8_t buf[16];
	struct csock_peer peer;
	bool truncated = true;
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), 0);
	/* closing removes the file */
	csock_close(fd, p);
	assert_int_equal(lstat(p, &st), -1);
	assert_int_equal(errno, ENOENT);
}

static void test_listen_refuses_non_socket(void **state)
{
	(void)state;
	char why[300] = "", p[CSOCK_PATH_MAX];
	/* a regular file: refused and left as it was */
	snprintf(p, sizeof p, "%s", sock_path("file", URL_A));
	FILE *f = fopen(p, "w");
	assert_non_null(f);
	fputs("keep me\n", f);
	fclose(f);
	assert_int_equal(csock_listen(p, why, sizeof why), -1);
	assert_non_null(strstr(why, "not a socket"));
	char rel[CSOCK_PATH_MAX];
	snprintf(rel, sizeof rel, "%s", p + strlen(scratch_dir) + 1);
	char *text = scratch_slurp(rel, 64);
	assert_string_equal(text, "keep me\n");
	free(text);
	/* a directory */
	snprintf(p, sizeof p, "%s", sock_path("dir", URL_A));
	assert_int_equal(mkdir(p, 0700), 0);
	why[0] = '\0';
	assert_int_equal(csock_listen(p, why, sizeof why), -1);
	assert_non_null(strstr(why, "not a socket"));
	struct stat st;
	assert_int_equal(lstat(p, &st), 0);
	assert_true(S_ISDIR(st.st_mode));
	/* a symbolic link, even to a socket */
	char target[CSOCK_PATH_MAX];
	snprintf(target, sizeof target, "%s", sock_path("target", URL_A));
	int t = csock_listen(target, why, sizeof why);
	assert_true(t >= 0);
	snprintf(p, sizeof p, "%s", sock_path("link", URL_A));
	assert_int_equal(symlink(target, p), 0);
	why[0] = '\0';
	assert_int_equal(csock_listen(p, why, sizeof why), -1);
	assert_non_null(strstr(why, "not a socket"));
	assert_int_equal(lstat(p, &st), 0);
	assert_true(S_ISLNK(st.st_mode));
	unlink(p);
	csock_close(t, target);
}

static void test_listen_stale_and_live(void **state)
{
	(void)state;
	char why[300] = "";
	const char *p = sock_path("stale", URL_A);
	/* a socket file whose daemon died: bound, then closed without unlink */
	int old = socket(AF_UNIX, SOCK_DGRAM, 0);
	struct sockaddr_un sa = { .sun_family = AF_UNIX };
	snprintf(sa.sun_path, sizeof sa.sun_path, "%s", p);
	assert_int_equal(bind(old, (struct sockaddr *)&sa, sizeof sa), 0);
	close(old);
	struct stat st;
	assert_int_equal(lstat(p, &st), 0);
	int fd = csock_listen(p, why, sizeof why);
	if (fd < 0)
		fail_msg("stale socket not replaced: %s", why);
	/* the new one is the one that answers */
	int c = csock_client_open(why, sizeof why);
	assert_true(c >= 0);
	assert_true(csock_send(c, p, "hi", 2, why, sizeof why));
	uint8_t buf[8];
	struct csock_peer peer;
	bool truncated;
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), 2);
	/* a second daemon for the same robot and network: refused, the first
	 * keeps its socket */
	why[0] = '\0';
	assert_int_equal(csock_listen(p, why, sizeof why), -1);
	assert_non_null(strstr(why, "another undulated"));
	assert_true(csock_send(c, p, "again", 5, why, sizeof why));
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), 5);
	assert_memory_equal(buf, "again", 5);
	close(c);
	csock_close(fd, p);
}

static void test_send_recv_reply(void **state)
{
	(void)state;
	char why[300] = "";
	const char *p = sock_path("talk", URL_A);
	int fd = csock_listen(p, why, sizeof why);
	assert_true(fd >= 0);
	int c = csock_client_open(why, sizeof why);
	assert_true(c >= 0);
	const uint8_t msg[] = { 1, 2, 0, 3, 0xff };
	assert_true(csock_send(c, p, msg, sizeof msg, why, sizeof why));
	uint8_t buf[CSOCK_DGRAM_MAX];
	struct csock_peer peer;
	bool truncated = true;
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), sizeof msg);
	assert_memory_equal(buf, msg, sizeof msg);
	assert_false(truncated);
	/* the kernel's word for who sent it: this process */
	assert_true(peer.cred);
	assert_int_equal(peer.uid, getuid());
	assert_int_equal(peer.gid, getgid());
	assert_int_equal(peer.pid, getpid());
	/* an autobound (abstract) address to answer */
	assert_true(peer.addr_len > sizeof(sa_family_t));
	assert_int_equal(peer.addr.sun_path[0], '\0');
	assert_true(csock_reply(fd, &peer, "answer", 6));
	char got[16];
	assert_int_equal(recv(c, got, sizeof got, MSG_DONTWAIT), 6);
	assert_memory_equal(got, "answer", 6);
	/* nothing more for either */
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), 0);
	assert_int_equal(recv(c, got, sizeof got, MSG_DONTWAIT), -1);

	/* a sender without an address of its own cannot be answered */
	int anon = socket(AF_UNIX, SOCK_DGRAM, 0);
	struct sockaddr_un sa = { .sun_family = AF_UNIX };
	snprintf(sa.sun_path, sizeof sa.sun_path, "%s", p);
	assert_int_equal(sendto(anon, "x", 1, 0, (struct sockaddr *)&sa, sizeof sa), 1);
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), 1);
	assert_true(peer.cred);
	assert_int_equal(peer.pid, getpid());
	assert_false(csock_reply(fd, &peer, "answer", 6));
	close(anon);
	/* a client that went away loses its answer; the daemon does not block */
	assert_true(csock_send(c, p, msg, sizeof msg, why, sizeof why));
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), sizeof msg);
	close(c);
	assert_false(csock_reply(fd, &peer, "answer", 6));
	csock_close(fd, p);
}

static void test_truncated(void **state)
{
	(void)state;
	char why[300] = "";
	const char *p = sock_path("big", URL_A);
	int fd = csock_listen(p, why, sizeof why);
	assert_true(fd >= 0);
	int c = csock_client_open(why, sizeof why);
	assert_true(c >= 0);
	static uint8_t big[CSOCK_DGRAM_MAX + 100], buf[CSOCK_DGRAM_MAX];
	for (size_t i = 0; i < sizeof big; i++)
		big[i] = (uint8_t)(i * 7);
	assert_true(csock_send(c, p, big, sizeof big, why, sizeof why));
	struct csock_peer peer;
	bool truncated = false;
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), sizeof buf);
	assert_true(truncated);
	assert_memory_equal(buf, big, sizeof buf);
	/* the rest of it is gone, not read as a second datagram */
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), 0);
	/* exactly the buffer: not cut */
	assert_true(csock_send(c, p, big, sizeof buf, why, sizeof why));
	truncated = true;
	assert_int_equal(csock_recv(fd, buf, sizeof buf, &peer, &truncated), sizeof buf);
	assert_false(truncated);
	close(c);
	csock_close(fd, p);
}

static void test_send_errors(void **state)
{
	(void)state;
	char why[300] = "";
	int c = csock_client_open(why, sizeof why);
	assert_true(c >= 0);
	const char *p = sock_path("nobody", URL_A);
	assert_false(csock_send(c, p, "x", 1, why, sizeof why));
	assert_non_null(strstr(why, p));
	/* a socket file nobody listens on any more */
	int fd = csock_listen(p, why, sizeof why);
	assert_true(fd >= 0);
	close(fd);
	why[0] = '\0';
	assert_false(csock_send(c, p, "x", 1, why, sizeof why));
	assert_non_null(strstr(why, "no daemon listens"));
	unlink(p);
	close(c);
}

static void test_find(void **state)
{
	(void)state;
	char why[300];
	int fds[4];
	char made[4][CSOCK_PATH_MAX];
	const char *robots[4] = { "r1", "r2", "r3", "r10" };
	const char *urls[4] = { URL_A, URL_A, URL_B, URL_A };
	for (size_t i = 0; i < 4; i++) {
		snprintf(made[i], sizeof made[i], "%s", sock_path(robots[i], urls[i]));
		fds[i] = csock_listen(made[i], why, sizeof why);
		assert_true(fds[i] >= 0);
	}
	/* a regular file with a socket's name is no socket */
	FILE *f = fopen(sock_path("r4", URL_A), "w");
	assert_non_null(f);
	fclose(f);
	char paths[8][CSOCK_PATH_MAX];
	/* one robot */
	assert_int_equal(csock_find("r1", URL_A, paths, 8), 1);
	assert_string_equal(paths[0], made[0]);
	assert_int_equal(csock_find("r3", URL_B, paths, 8), 1);
	assert_string_equal(paths[0], made[2]);
	assert_int_equal(csock_find("r3", URL_A, paths, 8), 0);   /* another network */
	assert_int_equal(csock_find("r4", URL_A, paths, 8), 0);   /* not a socket */
	assert_int_equal(csock_find("r", URL_A, paths, 8), 0);    /* no prefix match */
	assert_int_equal(csock_find("r1", URL_A, paths, 0), 0);
	/* every robot of a network, and only of that one */
	size_t n = csock_find("*", URL_A, paths, 8);
	assert_int_equal(n, 3);
	bool seen[4] = { false };
	for (size_t i = 0; i < n; i++) {
		bool known = false;
		for (size_t k = 0; k < 4; k++) {
			if (strcmp(paths[i], made[k]) == 0) {
				assert_false(seen[k]);
				seen[k] = known = true;
			}
		}
		if (!known)
			fail_msg("found '%s'", paths[i]);
	}
	assert_true(seen[0] && seen[1] && seen[3] && !seen[2]);
	assert_int_equal(csock_find("*", URL_B, paths, 8), 1);
	assert_string_equal(paths[0], made[2]);
	assert_int_equal(csock_find("*", "udpm://239.255.76.67:7669", paths, 8), 0);
	/* at most max */
	assert_int_equal(csock_find("*", URL_A, paths, 2), 2);
	for (size_t i = 0; i < 4; i++)
		csock_close(fds[i], made[i]);
	assert_int_equal(csock_find("*", URL_A, paths, 8), 0);
}

static void test_robot_of(void **state)
{
	(void)state;
	char out[CSOCK_PATH_MAX];
	csock_robot_of("/run/undulate/r1@" NET_A ".cmd", out, sizeof out);
	assert_string_equal(out, "r1");
	csock_robot_of("robot_2@" NET_A ".cmd", out, sizeof out);
	assert_string_equal(out, "robot_2");
	/* only the last component counts */
	csock_robot_of("/odd@dir/r3@" NET_A ".cmd", out, sizeof out);
	assert_string_equal(out, "r3");
	csock_robot_of("/a/noat.cmd", out, sizeof out);
	assert_string_equal(out, "noat.cmd");
	csock_robot_of("/a/@x.cmd", out, sizeof out);
	assert_string_equal(out, "");
	/* cut to the caller's buffer */
	csock_robot_of("/a/abcdefgh@x.cmd", out, 4);
	assert_string_equal(out, "abc");
	/* round trip with csock_path */
	char p[CSOCK_PATH_MAX];
	assert_true(csock_path(p, sizeof p, scratch_dir, "snake-7", URL_B));
	csock_robot_of(p, out, sizeof out);
	assert_string_equal(out, "snake-7");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_path),
		cmocka_unit_test(test_dirs),
		cmocka_unit_test(test_listen_file),
		cmocka_unit_test(test_listen_refuses_non_socket),
		cmocka_unit_test(test_listen_stale_and_live),
		cmocka_unit_test(test_send_recv_reply),
		cmocka_unit_test(test_truncated),
		cmocka_unit_test(test_send_errors),
		cmocka_unit_test(test_find),
		cmocka_unit_test(test_robot_of),
	};
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
