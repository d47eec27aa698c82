/* test_common_holder.c — naming a bus's holder (common/holder.c): lock-file
 * lines written and parsed (UUCP's pid-only format, ours with program and
 * detail, hostile text bounded and made printable, pids out of range), the
 * message's wording, the flock holder found in /proc/locks, a process's name
 * and the robot on its command line, and a lock file that is itself the lock
 * (a simulator's link): taken, refused while held naming the holder, taken
 * over from a dead holder, never through a symlink or into a FIFO. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "holder.h"
#include "scratch.h"

static void scratch_path(char *out, size_t cap, const char *rel)
{
	snprintf(out, cap, "%s/%s", scratch_dir, rel);
}

static void write_text(const char *path, const char *text)
{
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fputs(text, f);
	assert_int_equal(fclose(f), 0);
}

static void test_line_round_trip(void **state)
{
	(void)state;
	struct holder h = { .pid = 812 }, back;
	char line[256];
	snprintf(h.program, sizeof h.program, "undulated");
	snprintf(h.detail, sizeof h.detail, "robot r1");
	assert_int_equal(holder_line(&h, line, sizeof line), 30);
	/* the pid ten wide, as UUCP's lock files (minicom reads the number) */
	assert_string_equal(line, "       812 undulated robot r1\n");
	assert_true(holder_parse(line, &back));
	assert_int_equal(back.pid, 812);
	assert_string_equal(back.program, "undulated");
	assert_string_equal(back.detail, "robot r1");
	assert_string_equal(back.robot, "r1");
	assert_int_equal(holder_line(&h, line, 12), -1);   /* does not fit: nothing half-written */
}

static void test_parse_foreign_and_hostile(void **state)
{
	(void)state;
	struct holder h;
	/* minicom's: pid, program, user */
	assert_true(holder_parse("      4321 minicom alice\n", &h));
	assert_int_equal(h.pid, 4321);
	assert_string_equal(h.program, "minicom");
	assert_string_equal(h.detail, "alice");
	assert_string_equal(h.robot, "");
	/* HDB's ASCII format: the pid alone */
	assert_true(holder_parse("      4321\n", &h));
	assert_int_equal(h.pid, 4321);
	assert_string_equal(h.program, "");
	assert_true(holder_parse("77", &h));
	assert_int_equal(h.pid, 77);
	/* not a pid */
	assert_false(holder_parse("", &h));
	assert_false(holder_parse("minicom 4321\n", &h));
	assert_false(holder_parse("0 x\n", &h));
	assert_false(holder_parse("-5 x\n", &h));
	assert_false(holder_parse("4194305 x\n", &h));
	assert_false(holder_parse("99999999999999999999999 x\n", &h));
	assert_false(holder_parse("12abc x\n", &h));
	/* text from a world-writable directory: printable, bounded, one line */
	assert_true(holder_parse("12 und\x1b[31mulated robot r1\x07\nsecond line\n", &h));
	assert_int_equal(h.pid, 12);
	assert_string_equal(h.program, "und?[31mulated");
	assert_string_equal(h.detail, "robot r1?");
	assert_string_equal(h.robot, "");   /* not a name */
	char big[4096];
	memset(big, 'A', sizeof big);
	memcpy(big, "9 ", 2);
	big[sizeof big - 1] = '\0';
	assert_true(holder_parse(big, &h));
	assert_int_equal(strlen(h.program), sizeof h.program - 1);
	assert_true(holder_parse("9 p robot bad.name\n", &h));
	assert_string_equal(h.robot, "");
}

static void test_format(void **state)
{
	(void)state;
	struct holder h = { .pid = 812 };
	char out[128];
	snprintf(h.program, sizeof h.program, "undulated");
	snprintf(h.detail, sizeof h.detail, "robot r1");
	holder_format(&h, out, sizeof out);
	assert_string_equal(out, "undulated (pid 812, robot r1)");
	h.detail[0] = '\0';
	holder_format(&h, out, sizeof out);
	assert_string_equal(out, "undulated (pid 812)");
	h.program[0] = '\0';
	holder_format(&h, out, sizeof out);
	assert_string_equal(out, "a process (pid 812)");
	h.pid = 0;
	holder_format(&h, out, sizeof out);
	assert_string_equal(out, "another program");
}

static void test_processes(void **state)
{
	(void)state;
	struct holder h;
	char me[HOLDER_PROGRAM_MAX];
	holder_self_program(me, sizeof me);
	assert_true(strncmp(me, "test_common_hol", 15) == 0);
	assert_true(holder_alive((long)getpid()));
	assert_true(holder_alive(1));   /* EPERM or not: it is there */
	long gone = scratch_dead_pid();
	assert_true(gone > 0);
	assert_false(holder_alive(gone));
	assert_false(holder_alive(0));
	assert_false(holder_alive(-1));
	assert_true(holder_from_pid((long)getpid(), &h));
	assert_string_equal(h.program, me);
	assert_int_equal(h.pid, getpid());
	assert_false(holder_from_pid(gone, &h));
}

/* undulated's robot from its command line, as another program sees it: a
 * shell run with those arguments stands in for the daemon. */
static void test_robot_from_command_line(void **state)
{
	(void)state;
	const char *forms[][2] = { { "--robot", "r7" }, { "--robot=r7", "-v" }, { "--set", "robot.name=r7" },
	                           { "--robot", "bad.name" } };
	for (size_t i = 0; i < sizeof forms / sizeof forms[0]; i++) {
		int ready[2], hold[2];
		assert_int_equal(pipe(ready), 0);
		assert_int_equal(pipe(hold), 0);
		pid_t c = fork();
		assert_true(c >= 0);
		if (c == 0) {
			dup2(ready[1], 1);
			dup2(hold[0], 0);
			close(hold[1]);
			/* says so once exec'd, then waits for the test to close its pipe */
			execl("/bin/sh", "sh", "-c", "echo; read x", "undulated", forms[i][0], forms[i][1], (char *)NULL);
			_exit(127);
		}
		close(ready[1]);
		close(hold[0]);
		char b;
		assert_int_equal(read(ready[0], &b, 1), 1);
		struct holder h;
		assert_true(holder_from_pid((long)c, &h));
		assert_string_equal(h.program, "sh");
		if (i < 3) {
			assert_string_equal(h.robot, "r7");
			assert_string_equal(h.detail, "robot r7");
		} else {
			/* no robot: the arguments say what it is doing */
			assert_string_equal(h.robot, "");
			assert_string_equal(h.detail, "-c echo; read x undulated --robot bad.name");
		}
		close(hold[1]);
		close(ready[0]);
		assert_int_equal(waitpid(c, NULL, 0), c);
	}
}

static void test_flock_pid(void **state)
{
	(void)state;
	char path[300];
	struct stat st;
	long pid = 0;
	scratch_path(path, sizeof path, "flocked");
	write_text(path, "x");
	int fd = open(path, O_RDWR);
	assert_true(fd >= 0);
	assert_int_equal(fstat(fd, &st), 0);
	assert_false(holder_flock_pid(st.st_dev, st.st_ino, &pid));
	assert_int_equal(flock(fd, LOCK_EX), 0);
	assert_true(holder_flock_pid(st.st_dev, st.st_ino, &pid));
	assert_int_equal(pid, getpid());
	close(fd);
	assert_false(holder_flock_pid(st.st_dev, st.st_ino, &pid));
}

static void test_lockfile(void **state)
{
	(void)state;
	char path[300], err[400], me[HOLDER_PROGRAM_MAX];
	struct holder who, f;
	holder_self_program(me, sizeof me);
	scratch_path(path, sizeof path, "link.lock");
	int fd = holder_lockfile_take(path, "bus r1", &who, err, sizeof err);
	assert_true(fd >= 0);
	assert_true(holder_read_file(path, &f));
	assert_int_equal(f.pid, getpid());
	assert_string_equal(f.program, me);
	assert_string_equal(f.detail, "bus r1");
	/* a second taker (another open file, as another process would be) is refused with the holder named */
	assert_int_equal(holder_lockfile_take(path, "bus r2", &who, err, sizeof err), HOLDER_HELD);
	assert_int_equal(who.pid, getpid());
	assert_string_equal(who.detail, "bus r1");
	holder_lockfile_drop(path, fd);
	assert_int_equal(access(path, F_OK), -1);
	/* a dead holder's file (no lock on it any more) is taken over */
	char line[64];
	snprintf(line, sizeof line, "%10ld undulate-sim bus r1\n", scratch_dead_pid());
	write_text(path, line);
	fd = holder_lockfile_take(path, "bus r3", &who, err, sizeof err);
	assert_true(fd >= 0);
	assert_true(holder_read_file(path, &f));
	assert_int_equal(f.pid, getpid());
	assert_string_equal(f.detail, "bus r3");
	holder_lockfile_drop(path, fd);
	holder_lockfile_drop(path, -1);   /* nothing held: nothing done */
}

static void test_lockfile_refuses_other_files(void **state)
{
	(void)state;
	char path[300], target[300], err[400];
	struct holder who;
	scratch_path(target, sizeof target, "precious");
	write_text(target, "keep me\n");
	scratch_path(path, sizeof path, "sym.lock");
	assert_int_equal(symlink(target, path), 0);
	assert_int_equal(holder_lockfile_take(path, "x", &who, err, sizeof err), HOLDER_ERROR);
	assert_non_null(strstr(err, "symbolic link"));
	char *kept = scratch_slurp("precious", 64);
	assert_string_equal(kept, "keep me\n");
	free(kept);
	scratch_path(path, sizeof path, "fifo.lock");
	assert_int_equal(mkfifo(path, 0600), 0);
	assert_int_equal(holder_lockfile_take(path, "x", &who, err, sizeof err), HOLDER_ERROR);
	assert_non_null(strstr(err, "not a regular file"));
	assert_false(holder_read_file(path, &who));   /* never blocks on a FIFO */
	scratch_path(path, sizeof path, "no/such/dir/x.lock");
	assert_int_equal(holder_lockfile_take(path, "x", &who, err, sizeof err), HOLDER_ERROR);
	assert_non_null(strstr(err, "No such file"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_line_round_trip),
		cmocka_unit_test(test_parse_foreign_and_hostile),
		cmocka_unit_test(test_format),
		cmocka_unit_test(test_processes),
		cmocka_unit_test(test_robot_from_command_line),
		cmocka_unit_test(test_flock_pid),
		cmocka_unit_test(test_lockfile),
		cmocka_unit_test(test_lockfile_refuses_other_files),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
