/* test_web_wtok.c — the dashboard's token: made at random, written where only
 * its user reads it without following a planted link, and read back from a
 * --token-file only if nobody else may read that file. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../tools/web/wtok.h"
#include "scratch.h"

static void put(const char *name, const char *text, mode_t mode)
{
	char path[512];
	snprintf(path, sizeof path, "%s/%s", scratch_dir, name);
	FILE *f = fopen(path, "w");
	assert_non_null(f);
	fputs(text, f);
	fclose(f);
	assert_int_equal(chmod(path, mode), 0);
}

static void test_make(void **state)
{
	(void)state;
	char a[REQ_TOKEN_MAX], b[REQ_TOKEN_MAX];
	assert_true(wtok_make(a));
	assert_true(wtok_make(b));
	assert_int_equal(strlen(a), 32);
	assert_int_equal(strspn(a, REQ_TOKEN_CHARS), 32);
	assert_string_not_equal(a, b);
}

/* A link planted at the path is removed, not followed: the file it names
 * keeps its content, and the token file is a regular file of mode 0600. */
static void test_write_no_follow(void **state)
{
	(void)state;
	char victim[512], link[512], path[512], why[256];
	put("victim", "keep\n", 0644);
	snprintf(victim, sizeof victim, "%s/victim", scratch_dir);
	snprintf(link, sizeof link, "%s/undulate-web-8080.token", scratch_dir);
	assert_int_equal(symlink(victim, link), 0);
	assert_true(wtok_write(scratch_dir, 8080, "s3cret-token", path, sizeof path, why, sizeof why));
	assert_string_equal(path, link);
	char *v = scratch_slurp("victim", 100);
	assert_string_equal(v, "keep\n");
	free(v);
	assert_true(scratch_private_file(path, 0600));
	char *t = scratch_slurp("undulate-web-8080.token", 100);
	assert_string_equal(t, "s3cret-token\n");
	free(t);
	/* written again (a restart on the same port): replaced */
	assert_true(wtok_write(scratch_dir, 8080, "another-one", path, sizeof path, why, sizeof why));
	t = scratch_slurp("undulate-web-8080.token", 100);
	assert_string_equal(t, "another-one\n");
	free(t);
	char missing[600];
	snprintf(missing, sizeof missing, "%s/no/such/dir", scratch_dir);
	assert_false(wtok_write(missing, 8080, "x", path, sizeof path, why, sizeof why));
}

static void test_read(void **state)
{
	(void)state;
	char t[REQ_TOKEN_MAX], why[256], path[512];
	snprintf(path, sizeof path, "%s/tok", scratch_dir);
	put("tok", "abcd-EFGH_1234.~\n", 0600);
	assert_true(wtok_read(path, t, why, sizeof why));
	assert_string_equal(t, "abcd-EFGH_1234.~");
	put("tok", "abcd-EFGH_1234\n", 0640);
	assert_false(wtok_read(path, t, why, sizeof why));
	assert_non_null(strstr(why, "chmod 600"));
	put("tok", "short\n", 0600);
	assert_false(wtok_read(path, t, why, sizeof why));
	put("tok", "has space in it\n", 0600);
	assert_false(wtok_read(path, t, why, sizeof why));
	char longer[REQ_TOKEN_MAX + 2];
	memset(longer, 'a', REQ_TOKEN_MAX);
	longer[REQ_TOKEN_MAX] = '\n';
	longer[REQ_TOKEN_MAX + 1] = '\0';
	put("tok", longer, 0600);
	assert_false(wtok_read(path, t, why, sizeof why));
	longer[REQ_TOKEN_MAX - 1] = '\n';
	longer[REQ_TOKEN_MAX] = '\0';
	put("tok", longer, 0600);
	assert_true(wtok_read(path, t, why, sizeof why));
	assert_int_equal(strlen(t), REQ_TOKEN_MAX - 1);
	assert_false(wtok_read(scratch_dir, t, why, sizeof why)); /* a directory */
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_make),
		cmocka_unit_test(test_write_no_follow),
		cmocka_unit_test(test_read),
	};
	return cmocka_run_group_tests(tests, scratch_group_setup, scratch_group_teardown);
}
