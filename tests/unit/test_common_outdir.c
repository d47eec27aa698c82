/* test_common_outdir.c — where results are written (common/outdir.h):
 * outdir_open() accepts a directory of ours that no one else can write
 * (made when missing, reached through our own links) and refuses, naming
 * the owner or the mode and what to do, one owned by another user, one
 * others may write (unless sticky), a link another user made, a file on the
 * way, a loop of links; outdir_file_*(), outdir_create_in_place() and
 * outdir_stage()/outdir_publish() replace a link or a FIFO under the final
 * name, never write through it or open it, and leave no temporary behind. The cases that need another
 * user's files (chown) run as root only and are skipped otherwise. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "outdir.h"
#include "scratch.h"

/* nobody, on Debian: a user that is not us. */
#define OTHER_UID 65534

static char err[1024];

static int setup(void **state)
{
	(void)state;
	umask(022);
	return scratch_make("outdir");
}

static int teardown(void **state)
{
	(void)state;
	return scratch_remove();
}

/* A path under the scratch directory (one of a few rotating buffers, so
 * that two can be passed to one call). */
static const char *at(const char *rel)
{
	static char buf[4][512];
	static int next;
	char *p = buf[next++ % 4];
	snprintf(p, sizeof buf[0], "%s/%s", scratch_dir, rel);
	return p;
}

static void write_text(const char *path, const char *text)
{
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fputs(text, f);
	assert_int_equal(fclose(f), 0);
}

static void expect_text(const char *path, const char *want)
{
	char got[256] = "";
	FILE *f = fopen(path, "r");
	assert_non_null(f);
	size_t n = fread(got, 1, sizeof got - 1, f);
	got[n] = '\0';
	fclose(f);
	assert_string_equal(got, want);
}

static void expect_refused(const char *path, bool create, const char *want)
{
	memset(err, 0, sizeof err);
	int fd = outdir_open(path, create, err, sizeof err);
	if (fd >= 0) {
		close(fd);
		fail_msg("%s: accepted, want refused with '%s'", path, want);
	}
	if (strstr(err, want) == NULL)
		fail_msg("%s: got '%s', want '%s'", path, err, want);
}

static void expect_accepted(const char *path, bool create)
{
	int fd = outdir_open(path, create, err, sizeof err);
	if (fd < 0)
		fail_msg("%s: refused: %s", path, err);
	struct stat st;
	assert_int_equal(fstat(fd, &st), 0);
	assert_true(S_ISDIR(st.st_mode));
	close(fd);
}

/* Entries of a directory whose name starts with a dot: temporaries left. */
static int dot_entries(const char *dir)
{
	DIR *d = opendir(dir);
	assert_non_null(d);
	int n = 0;
	const struct dirent *e;
	while ((e = readdir(d)) != NULL)
		n += e->d_name[0] == '.' && strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
	closedir(d);
	return n;
}

static bool is_regular(const char *path)
{
	struct stat st;
	return lstat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static void test_ours_accepted_and_made(void **state)
{
	(void)state;
	assert_int_equal(mkdir(at("mine"), 0755), 0);
	expect_accepted(at("mine"), false);
	expect_accepted(at("mine/"), false);
	expect_accepted(at("./mine/./"), false);
	/* missing: made with create (0755 under umask 022), else refused */
	expect_refused(at("fresh"), false, "No such file or directory");
	expect_accepted(at("fresh"), true);
	struct stat st;
	assert_int_equal(stat(at("fresh"), &st), 0);
	assert_int_equal(st.st_mode & 07777, 0755);
	/* only the last name is made */
	expect_refused(at("nope/sub"), true, "No such file or directory");
	/* relative to the working directory, and "." itself */
	char cwd[512];
	assert_non_null(getcwd(cwd, sizeof cwd));
	assert_int_equal(chdir(scratch_dir), 0);
	expect_accepted("mine", false);
	expect_accepted(".", false);
	assert_int_equal(chdir(cwd), 0);
	expect_refused("", true, "empty");
}

static void test_writable_by_others(void **state)
{
	(void)state;
	assert_int_equal(mkdir(at("open"), 0700), 0);
	assert_int_equal(chmod(at("open"), 0777), 0);
	expect_refused(at("open"), true, "writable by other users (mode 0777)");
	expect_refused(at("open"), true, "chmod go-w");
	assert_int_equal(chmod(at("open"), 0757), 0);
	expect_refused(at("open"), true, "writable by other users (mode 0757)");
	/* sticky and ours: others cannot remove or rename what we make */
	assert_int_equal(chmod(at("open"), 01777), 0);
	expect_accepted(at("open"), false);
}

/* Group-writable for a group that is not ours alone (root can give a
 * directory to daemon's group, gid 1). */
static void test_group_not_ours(void **state)
{
	(void)state;
	if (geteuid() != 0)
		skip();
	assert_int_equal(mkdir(at("shared"), 0775), 0);
	assert_int_equal(chown(at("shared"), (uid_t)-1, 1), 0);
	assert_int_equal(chmod(at("shared"), 0775), 0);
	expect_refused(at("shared"), false, "writable by its group, which is not yours alone (mode 0775)");
	expect_refused(at("shared"), false, "chmod g-w");
}

static void test_another_users(void **state)
{
	(void)state;
	if (geteuid() != 0)
		skip();
	assert_int_equal(mkdir(at("theirs"), 0755), 0);
	assert_int_equal(chown(at("theirs"), OTHER_UID, OTHER_UID), 0);
	expect_refused(at("theirs"), true, "owned by nobody (uid 65534), not by you (root)");
	expect_refused(at("theirs"), true, "choose a directory of yours");
	/* a directory of ours inside theirs is ours: they cannot swap it (we
	 * hold it open) nor anything in it */
	assert_int_equal(mkdir(at("theirs/ours"), 0755), 0);
	expect_accepted(at("theirs/ours"), false);
	/* their link to our directory: they choose where our files land */
	assert_int_equal(mkdir(at("target"), 0755), 0);
	assert_int_equal(symlink(at("target"), at("theirlink")), 0);
	assert_int_equal(lchown(at("theirlink"), OTHER_UID, OTHER_UID), 0);
	expect_refused(at("theirlink"), true, "the symbolic link theirlink on the way is owned by nobody");
	expect_refused(at("theirlink/"), true, "owned by nobody");
	/* root's link is followed, as our own */
	assert_int_equal(symlink("target", at("rootlink")), 0);
	expect_accepted(at("rootlink"), false);
}

static void test_links(void **state)
{
	(void)state;
	assert_int_equal(mkdir(at("real"), 0755), 0);
	assert_int_equal(mkdir(at("real/deep"), 0755), 0);
	/* relative targets are read from the link's own directory; a chain */
	assert_int_equal(symlink("real", at("l1")), 0);
	assert_int_equal(symlink("l1/deep", at("l2")), 0);
	assert_int_equal(symlink("../../real", at("real/deep/up")), 0);
	expect_accepted(at("l1"), false);
	expect_accepted(at("l2"), false);
	expect_accepted(at("l2/up/deep"), false);
	/* a link to a missing directory: made, as the path itself would be */
	assert_int_equal(symlink("real/later", at("l3")), 0);
	expect_accepted(at("l3"), true);
	struct stat st;
	assert_int_equal(lstat(at("real/later"), &st), 0);
	assert_true(S_ISDIR(st.st_mode));
	/* a loop, a dangling link without create, a file on the way */
	assert_int_equal(symlink("loop", at("loop")), 0);
	expect_refused(at("loop"), true, "Too many levels of symbolic links");
	assert_int_equal(symlink("nowhere", at("dangling")), 0);
	expect_refused(at("dangling"), false, "No such file or directory");
	write_text(at("file"), "x");
	expect_refused(at("file"), true, "file is not a directory");
	expect_refused(at("file/sub"), true, "file is not a directory");
	assert_int_equal(symlink("file", at("tofile")), 0);
	expect_refused(at("tofile"), true, "file is not a directory");
}

static void test_file_replaces_links_and_fifos(void **state)
{
	(void)state;
	assert_int_equal(mkdir(at("out"), 0755), 0);
	write_text(at("victim"), "precious\n");
	assert_int_equal(symlink(at("victim"), at("out/robot.conf")), 0);
	assert_int_equal(mkfifo(at("out/fifo.txt"), 0644), 0);
	int dirfd = outdir_open(at("out"), false, err, sizeof err);
	assert_true(dirfd >= 0);

	struct outdir_file f;
	int fd = outdir_file_create(&f, dirfd, "robot.conf", err, sizeof err);
	assert_true(fd >= 0);
	assert_int_equal(write(fd, "[robot]\n", 8), 8);
	assert_int_equal(outdir_file_commit(&f, false, err, sizeof err), 0);
	expect_text(at("victim"), "precious\n");
	assert_true(is_regular(at("out/robot.conf")));
	expect_text(at("out/robot.conf"), "[robot]\n");
	struct stat st;
	assert_int_equal(stat(at("out/robot.conf"), &st), 0);
	assert_int_equal(st.st_mode & 07777, 0644);

	/* a FIFO: replaced without being opened (opening it would block) */
	fd = outdir_file_create(&f, dirfd, "fifo.txt", err, sizeof err);
	assert_true(fd >= 0);
	FILE *fp = fdopen(fd, "w");
	assert_non_null(fp);
	fputs("text\n", fp);
	assert_int_equal(fclose(fp), 0);
	assert_int_equal(outdir_file_commit(&f, true, err, sizeof err), 0);
	assert_true(is_regular(at("out/fifo.txt")));
	expect_text(at("out/fifo.txt"), "text\n");

	/* abandoned: nothing left, the old file kept */
	fd = outdir_file_create(&f, dirfd, "robot.conf", err, sizeof err);
	assert_true(fd >= 0);
	outdir_file_abandon(&f, false);
	expect_text(at("out/robot.conf"), "[robot]\n");
	assert_int_equal(dot_entries(at("out")), 0);

	/* a directory under the name: refused at commit, temporary removed */
	assert_int_equal(mkdir(at("out/adir"), 0755), 0);
	fd = outdir_file_create(&f, dirfd, "adir", err, sizeof err);
	assert_true(fd >= 0);
	assert_int_equal(outdir_file_commit(&f, false, err, sizeof err), -1);
	assert_non_null(strstr(err, "adir: Is a directory"));
	assert_int_equal(dot_entries(at("out")), 0);

	/* only a plain name */
	assert_int_equal(outdir_file_create(&f, dirfd, "../x", err, sizeof err), -1);
	assert_non_null(strstr(err, "not a file name"));
	assert_int_equal(outdir_file_create(&f, dirfd, "", err, sizeof err), -1);
	close(dirfd);
}

static void test_parent_and_in_place(void **state)
{
	(void)state;
	assert_int_equal(mkdir(at("rec"), 0755), 0);
	write_text(at("victim3"), "precious\n");
	assert_int_equal(symlink(at("victim3"), at("rec/run.log")), 0);
	char name[256];
	int dirfd = outdir_open_parent(at("rec/run.log"), name, sizeof name, err, sizeof err);
	assert_true(dirfd >= 0);
	assert_string_equal(name, "run.log");
	/* in place: the link removed, a new file made under its name at once */
	int fd = outdir_create_in_place(dirfd, name, err, sizeof err);
	assert_true(fd >= 0);
	assert_true(is_regular(at("rec/run.log")));
	assert_int_equal(write(fd, "log", 3), 3);
	close(fd);
	expect_text(at("victim3"), "precious\n");
	expect_text(at("rec/run.log"), "log");
	/* a directory of that name stays, and says so */
	assert_int_equal(mkdir(at("rec/adir"), 0755), 0);
	assert_int_equal(outdir_create_in_place(dirfd, "adir", err, sizeof err), -1);
	assert_non_null(strstr(err, "adir: cannot replace it: Is a directory"));
	close(dirfd);
	/* a bare name is in the working directory; a path naming a directory is refused */
	char cwd[512];
	assert_non_null(getcwd(cwd, sizeof cwd));
	assert_int_equal(chdir(at("rec")), 0);
	dirfd = outdir_open_parent("x.log", name, sizeof name, err, sizeof err);
	assert_true(dirfd >= 0);
	assert_string_equal(name, "x.log");
	close(dirfd);
	assert_int_equal(chdir(cwd), 0);
	assert_int_equal(outdir_open_parent(at("rec/"), name, sizeof name, err, sizeof err), -1);
	assert_non_null(strstr(err, "names a directory"));
	assert_int_equal(outdir_open_parent(at("rec/.."), name, sizeof name, err, sizeof err), -1);
	/* the directory's rules apply: one others may write */
	assert_int_equal(chmod(at("rec"), 0777), 0);
	assert_int_equal(outdir_open_parent(at("rec/run.log"), name, sizeof name, err, sizeof err), -1);
	assert_non_null(strstr(err, "writable by other users"));
}

static void test_stage_and_publish(void **state)
{
	(void)state;
	assert_int_equal(mkdir(at("res"), 0755), 0);
	write_text(at("victim2"), "precious\n");
	assert_int_equal(symlink(at("victim2"), at("res/summary.txt")), 0);
	assert_int_equal(mkfifo(at("res/plots.gp"), 0644), 0);
	assert_int_equal(mkdir(at("res/states.csv"), 0755), 0);
	write_text(at("res/old.csv"), "kept\n");
	int dirfd = outdir_open(at("res"), false, err, sizeof err);
	assert_true(dirfd >= 0);

	char name[64];
	int stage = outdir_stage(dirfd, ".tool", name, sizeof name, err, sizeof err);
	assert_true(stage >= 0);
	assert_int_equal(strncmp(name, ".tool.", 6), 0);
	assert_int_equal(strlen(name), 6 + 6);
	struct stat st;
	assert_int_equal(fstat(stage, &st), 0);
	assert_int_equal(st.st_mode & 07777, 0700);
	/* a second stage gets another name */
	char name2[64];
	int stage2 = outdir_stage(dirfd, ".tool", name2, sizeof name2, err, sizeof err);
	assert_true(stage2 >= 0);
	assert_string_not_equal(name, name2);
	outdir_discard(dirfd, stage2, name2);
	close(stage2);

	const char *files[] = { "summary.txt", "plots.gp", "states.csv", "new.csv" };
	for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
		int fd = openat(stage, files[i], O_WRONLY | O_CREAT | O_EXCL, 0666);
		assert_true(fd >= 0);
		assert_int_equal(write(fd, files[i], strlen(files[i])), (ssize_t)strlen(files[i]));
		close(fd);
	}
	/* states.csv cannot replace a directory: reported, the others moved */
	assert_int_equal(outdir_publish(dirfd, stage, name, err, sizeof err), -1);
	assert_non_null(strstr(err, "states.csv: cannot replace it: Is a directory"));
	close(stage);
	expect_text(at("victim2"), "precious\n");
	assert_true(is_regular(at("res/summary.txt")));
	expect_text(at("res/summary.txt"), "summary.txt");
	assert_true(is_regular(at("res/plots.gp")));
	expect_text(at("res/plots.gp"), "plots.gp");
	expect_text(at("res/new.csv"), "new.csv");
	expect_text(at("res/old.csv"), "kept\n");
	assert_int_equal(dot_entries(at("res")), 0);

	/* published again over its own files: replaced */
	stage = outdir_stage(dirfd, ".tool", name, sizeof name, err, sizeof err);
	assert_true(stage >= 0);
	int fd = openat(stage, "new.csv", O_WRONLY | O_CREAT | O_EXCL, 0666);
	assert_int_equal(write(fd, "again", 5), 5);
	close(fd);
	assert_int_equal(outdir_publish(dirfd, stage, name, err, sizeof err), 0);
	close(stage);
	expect_text(at("res/new.csv"), "again");
	assert_int_equal(dot_entries(at("res")), 0);
	close(dirfd);
}

/* outdir_stage_fopen: a new file only (a name taken: NULL, EEXIST, and what
 * is there untouched); outdir_stage_fclose: a write that failed shows at the
 * close, and the stream is NULL after. */
static void test_stage_fopen_fclose(void **state)
{
	(void)state;
	assert_int_equal(mkdir(at("st"), 0700), 0);
	int stage = open(at("st"), O_RDONLY | O_DIRECTORY);
	assert_true(stage >= 0);
	FILE *f = outdir_stage_fopen(stage, "a.csv");
	assert_non_null(f);
	fputs("t,x\n", f);
	assert_int_equal(outdir_stage_fclose(&f), 0);
	assert_null(f);
	assert_int_equal(outdir_stage_fclose(&f), 0);   /* nothing open: nothing to do */
	expect_text(at("st/a.csv"), "t,x\n");

	errno = 0;
	assert_null(outdir_stage_fopen(stage, "a.csv"));
	assert_int_equal(errno, EEXIST);
	expect_text(at("st/a.csv"), "t,x\n");
	assert_int_equal(symlink(at("st/a.csv"), at("st/link.csv")), 0);
	assert_null(outdir_stage_fopen(stage, "link.csv"));
	expect_text(at("st/a.csv"), "t,x\n");

	f = fopen("/dev/full", "w");
	if (f != NULL) {   /* a full disk: the write fails at the flush, in the close */
		fputs("lost", f);
		assert_int_equal(outdir_stage_fclose(&f), -1);
		assert_null(f);
	}
	close(stage);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ours_accepted_and_made),
		cmocka_unit_test(test_writable_by_others),
		cmocka_unit_test(test_group_not_ours),
		cmocka_unit_test(test_another_users),
		cmocka_unit_test(test_links),
		cmocka_unit_test(test_file_replaces_links_and_fifos),
		cmocka_unit_test(test_parent_and_in_place),
		cmocka_unit_test(test_stage_and_publish),
		cmocka_unit_test(test_stage_fopen_fclose),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
