/* test_common_textfile.c — what textfile_read() reads (a regular file, a
 * symbolic link to one, exactly 1 MiB, an empty file) and what it refuses at
 * once with "PATH: why": a directory, a character device (/dev/zero would
 * never end), a FIFO with no writer (open() would block), a file over 1 MiB,
 * NUL bytes (named by line), a missing path. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scratch.h"
#include "textfile.h"

static char path[512];
static char err[512];

static const char *in_scratch(const char *name)
{
	snprintf(path, sizeof path, "%s/%s", scratch_dir, name);
	return path;
}

static void write_bytes(const char *p, const char *bytes, size_t n)
{
	FILE *f = fopen(p, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(bytes, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
}

/* Refused: NULL, and err is exactly want (or contains it, when partial). */
static void expect_refused(const char *p, const char *want, bool partial)
{
	size_t len = 77;
	memset(err, 'x', sizeof err);
	char *text = textfile_read(p, "a scenario", &len, err, sizeof err);
	assert_null(text);
	assert_int_equal(len, 77);   /* untouched */
	if (partial ? strstr(err, want) == NULL : strcmp(err, want) != 0)
		fail_msg("%s: got '%s', want '%s'", p, err, want);
}

static void test_reads_a_text_file(void **state)
{
	(void)state;
	const char *p = in_scratch("ok.txt");
	write_bytes(p, "[robot a]\nids = 1\n", 18);
	size_t len = 0;
	char *text = textfile_read(p, "a scenario", &len, err, sizeof err);
	assert_non_null(text);
	assert_int_equal(len, 18);
	assert_string_equal(text, "[robot a]\nids = 1\n");
	free(text);
	/* through a symbolic link */
	char link[512];
	snprintf(link, sizeof link, "%s/link.txt", scratch_dir);
	assert_int_equal(symlink(p, link), 0);
	text = textfile_read(link, "a scenario", &len, err, sizeof err);
	assert_non_null(text);
	assert_int_equal(len, 18);
	free(text);
	/* empty */
	p = in_scratch("empty.txt");
	write_bytes(p, "", 0);
	text = textfile_read(p, "a scenario", &len, err, sizeof err);
	assert_non_null(text);
	assert_int_equal(len, 0);
	assert_string_equal(text, "");
	free(text);
}

static void test_refuses_what_is_not_a_file(void **state)
{
	(void)state;
	char want[600];
	snprintf(want, sizeof want, "%s: not a regular file (a directory): a scenario is a text file", scratch_dir);
	expect_refused(scratch_dir, want, false);
	expect_refused("/dev/zero", "/dev/zero: not a regular file (a character device): a scenario is a text file",
	               false);
	const char *p = in_scratch("fifo");
	assert_int_equal(mkfifo(p, 0600), 0);
	snprintf(want, sizeof want, "%s: not a regular file (a FIFO): a scenario is a text file", p);
	expect_refused(p, want, false);
	expect_refused("/nonexistent/x.scenario", "/nonexistent/x.scenario: cannot open: No such file or directory",
	               false);
}

/* 1 MiB is read; one byte more is refused before reading (sparse files:
 * nothing is written). */
static void test_size_limit(void **state)
{
	(void)state;
	const char *p = in_scratch("big.txt");
	write_bytes(p, "a", 1);
	assert_int_equal(truncate(p, TEXTFILE_MAX_BYTES + 1), 0);
	char want[600];
	snprintf(want, sizeof want, "%s: larger than 1 MiB (1048577 bytes): not a scenario", p);
	expect_refused(p, want, false);
	/* exactly 1 MiB of text */
	char *mib = malloc(TEXTFILE_MAX_BYTES);
	assert_non_null(mib);
	memset(mib, '\n', TEXTFILE_MAX_BYTES);
	write_bytes(p, mib, TEXTFILE_MAX_BYTES);
	free(mib);
	size_t len = 0;
	char *text = textfile_read(p, "a scenario", &len, err, sizeof err);
	assert_non_null(text);
	assert_int_equal(len, TEXTFILE_MAX_BYTES);
	assert_int_equal(text[len], '\0');
	free(text);
}

static void test_nul_bytes(void **state)
{
	(void)state;
	const char *p = in_scratch("nul.txt");
	write_bytes(p, "[sim]\nseed = 1\n\0\0[robot a]\n", 27);
	char want[600];
	snprintf(want, sizeof want, "%s:3: a NUL byte: a scenario is a text file", p);
	expect_refused(p, want, false);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_reads_a_text_file),
		cmocka_unit_test(test_refuses_what_is_not_a_file),
		cmocka_unit_test(test_size_limit),
		cmocka_unit_test(test_nul_bytes),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
