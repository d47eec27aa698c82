/* test_web_req.c — undulate-web's request checks: which HTTP requests are
 * served, and which messages from the page become commands. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "../../tools/web/req.h"

static void test_routes(void **state)
{
	(void)state;
	assert_int_equal(req_route("GET", "/"), REQ_PAGE);
	assert_int_equal(req_route("HEAD", "/index.html"), REQ_PAGE);
	assert_int_equal(req_route("GET", "/?token=x"), REQ_PAGE);
	assert_int_equal(req_route("GET", "/app.js"), REQ_ASSET_JS);
	assert_int_equal(req_route("GET", "/style.css"), REQ_ASSET_CSS);
	assert_int_equal(req_route("GET", "/chart.js"), REQ_CHARTJS);
	assert_int_equal(req_route("GET", "/api/snapshot"), REQ_SNAPSHOT);
	assert_int_equal(req_route("GET", "/api/snapshot?pretty"), REQ_SNAPSHOT);
	assert_int_equal(req_route("GET", "/api/params"), REQ_PARAMS);
	assert_int_equal(req_route("POST", "/api/params"), REQ_BAD_METHOD);
	/* the snapshot takes GET only; the page GET and HEAD */
	assert_int_equal(req_route("POST", "/api/snapshot"), REQ_BAD_METHOD);
	assert_int_equal(req_route("HEAD", "/api/snapshot"), REQ_BAD_METHOD);
	assert_int_equal(req_route("PUT", "/api/snapshot"), REQ_BAD_METHOD);
	assert_int_equal(req_route("DELETE", "/"), REQ_BAD_METHOD);
	assert_int_equal(req_route("POST", "/app.js"), REQ_BAD_METHOD);
	/* nothing but the named files: no path walks into the file system */
	assert_int_equal(req_route("GET", "/../etc/passwd"), REQ_NOT_FOUND);
	assert_int_equal(req_route("GET", "/app.js/"), REQ_NOT_FOUND);
	assert_int_equal(req_route("GET", "/api/snapshot/x"), REQ_NOT_FOUND);
	assert_int_equal(req_route("GET", "/chart.js.map"), REQ_NOT_FOUND);
	assert_int_equal(req_route("GET", ""), REQ_NOT_FOUND);
}

static bool parse(const char *s, struct req_msg *m, char *why, size_t cap)
{
	return req_msg_parse(s, strlen(s), 2, m, why, cap);
}

static void test_commands_valid(void **state)
{
	(void)state;
	static struct req_msg m;
	char why[256];
	assert_true(parse("cmd 1 r1 mode hold", &m, why, sizeof why));
	assert_int_equal(m.kind, REQ_MSG_CMD);
	assert_int_equal(m.id, 1);
	assert_string_equal(m.robot, "r1");
	assert_int_equal(m.cmd.kind, CMD_KIND_MODE);
	assert_int_equal(m.cmd.mode, 1);
	assert_true(parse("cmd 42 * mode oscillator", &m, why, sizeof why));
	assert_string_equal(m.robot, "*");
	assert_int_equal(m.cmd.mode, 3);
	assert_true(parse("cmd 7 robot_2-b param c 0.02 1", &m, why, sizeof why));
	assert_int_equal(m.cmd.kind, CMD_KIND_PARAM);
	assert_string_equal(m.cmd.param, "c");
	assert_int_equal(m.cmd.joint, 1);
	assert_true(parse("cmd 8 r1 param amplitude 0.6", &m, why, sizeof why));
	assert_true(parse("cmd 9 r1 clear", &m, why, sizeof why));
	assert_true(parse("cmd 10 r1 torque off", &m, why, sizeof why));
}

/* what the daemon refuses for any robot is refused here, with its words */
static void test_commands_invalid(void **state)
{
	(void)state;
	static struct req_msg m;
	char why[256];
	assert_false(parse("cmd 1 r1 param k 50 0", &m, why, sizeof why));
	assert_non_null(strstr(why, "out of range"));
	assert_false(parse("cmd 1 r1 param neutral 0.1 0", &m, why, sizeof why));
	assert_non_null(strstr(why, "configuration file"));
	assert_false(parse("cmd 1 r1 param limit_max 3 0", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1 param c 0.02 5", &m, why, sizeof why));
	assert_non_null(strstr(why, "does not exist"));
	assert_false(parse("cmd 1 r1 param amplitude 0.5 0", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1 param c nan 0", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1 mode 7", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1 mode fly", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1 reboot", &m, why, sizeof why));
	/* the envelope */
	assert_false(parse("cmd 1 r1;rm mode hold", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1.STATE mode hold", &m, why, sizeof why));
	assert_false(parse("cmd 1 ** mode hold", &m, why, sizeof why));
	assert_false(parse("cmd x r1 mode hold", &m, why, sizeof why));
	assert_false(parse("cmd 0 r1 mode hold", &m, why, sizeof why));
	assert_false(parse("cmd 1234567890123456 r1 mode hold", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1 ", &m, why, sizeof why));
	assert_false(parse("go 1 r1 mode hold", &m, why, sizeof why));
	assert_false(parse("", &m, why, sizeof why));
	assert_false(parse("cmd 1 r1 mode\thold", &m, why, sizeof why));
	assert_false(req_msg_parse("cmd 1 r1 mode hold\0x", 20, 2, &m, why, sizeof why));
	assert_false(parse("cmd 1 r1 mode h\xc3\xa9", &m, why, sizeof why));
	char long_msg[REQ_MSG_MAX + 10];
	memset(long_msg, 'a', sizeof long_msg);
	memcpy(long_msg, "cmd 1 r1 ", 9);
	long_msg[sizeof long_msg - 1] = '\0';
	assert_false(parse(long_msg, &m, why, sizeof why));
	char name[CFG_NAME_MAX + 20] = "cmd 1 ";
	memset(name + 6, 'r', CFG_NAME_MAX);
	strcpy(name + 6 + CFG_NAME_MAX, " mode hold");
	assert_false(parse(name, &m, why, sizeof why));
}

static void test_auth(void **state)
{
	(void)state;
	static struct req_msg m;
	char why[256];
	assert_true(parse("auth s3cret", &m, why, sizeof why));
	assert_int_equal(m.kind, REQ_MSG_AUTH);
	assert_string_equal(m.token, "s3cret");
	assert_false(parse("auth", &m, why, sizeof why));
	assert_false(parse("auth a b", &m, why, sizeof why));
	assert_true(req_token_ok("s3cret", "s3cret"));
	assert_false(req_token_ok("s3cret", "s3cre"));
	assert_false(req_token_ok("s3cret", "s3cret "));
	assert_false(req_token_ok("s3cret", ""));
	assert_false(req_token_ok("", ""));
}

static void test_origin(void **state)
{
	(void)state;
	assert_true(req_origin_ok(NULL, "127.0.0.1:8080"));
	assert_true(req_origin_ok("", "127.0.0.1:8080"));
	assert_true(req_origin_ok("http://127.0.0.1:8080", "127.0.0.1:8080"));
	assert_false(req_origin_ok("http://evil.example", "127.0.0.1:8080"));
	assert_false(req_origin_ok("http://127.0.0.1:8080.evil.example", "127.0.0.1:8080"));
	assert_false(req_origin_ok("https://127.0.0.1:8080", "127.0.0.1:8080"));
	assert_false(req_origin_ok("http://127.0.0.1:8080", NULL));
	assert_false(req_origin_ok("null", "127.0.0.1:8080"));
}

/* DNS rebinding: a page of evil.example whose name now points at this
 * computer reaches the server with Host: evil.example. Only names of this
 * server pass: localhost, a loopback or the listening address, any address
 * when listening on all of them (a browser sends an address only when it
 * connected to that address), and the names given. */
static void test_host(void **state)
{
	(void)state;
	struct req_hosts lo = { .listen = "127.0.0.1" };
	assert_true(req_host_ok(&lo, "127.0.0.1:8080"));
	assert_true(req_host_ok(&lo, "127.0.0.1"));
	assert_true(req_host_ok(&lo, "localhost:8080"));
	assert_true(req_host_ok(&lo, "LocalHost:8080"));
	assert_true(req_host_ok(&lo, "[::1]:8080"));
	assert_true(req_host_ok(&lo, "127.0.0.2:9000")); /* ssh -L 9000:127.0.0.2:8080 on a laptop */
	assert_false(req_host_ok(&lo, "evil.example:8080"));
	assert_false(req_host_ok(&lo, "evil.example"));
	assert_false(req_host_ok(&lo, "localhost.evil.example:8080"));
	assert_false(req_host_ok(&lo, "127.0.0.1.evil.example:8080"));
	assert_false(req_host_ok(&lo, "10.0.0.5:8080"));  /* not an address it listens on */
	assert_false(req_host_ok(&lo, "127.1:8080"));     /* browsers send the dotted quad */
	assert_false(req_host_ok(&lo, ""));
	assert_false(req_host_ok(&lo, NULL));
	assert_false(req_host_ok(&lo, ":8080"));
	assert_false(req_host_ok(&lo, "localhost:"));
	assert_false(req_host_ok(&lo, "localhost:80x"));
	assert_false(req_host_ok(&lo, "localhost:123456"));
	assert_false(req_host_ok(&lo, "localhost:8080:1"));
	assert_false(req_host_ok(&lo, "[::1"));
	assert_false(req_host_ok(&lo, "[::1]x"));
	assert_false(req_host_ok(&lo, "[localhost]:8080"));
	assert_false(req_host_ok(&lo, "local host"));
	assert_false(req_host_ok(&lo, "localhost\r\nX: y"));
	struct req_hosts any = { .listen = "0.0.0.0", .names = { "labpc", "lab.example" }, .nnames = 2 };
	assert_true(req_host_ok(&any, "10.0.0.5:8080"));
	assert_true(req_host_ok(&any, "[fe80::1]:8080"));
	assert_true(req_host_ok(&any, "labpc:8080"));
	assert_true(req_host_ok(&any, "Lab.Example"));
	assert_true(req_host_ok(&any, "localhost:8080"));
	assert_false(req_host_ok(&any, "evil.example:8080"));
	assert_false(req_host_ok(&any, "labpc.evil.example:8080"));
	assert_false(req_host_ok(&any, "xlabpc"));
	struct req_hosts v6any = { .listen = "::" };
	assert_true(req_host_ok(&v6any, "192.168.1.2"));
	assert_false(req_host_ok(&v6any, "labpc"));
	struct req_hosts one = { .listen = "10.0.0.5" };
	assert_true(req_host_ok(&one, "10.0.0.5:8080"));
	assert_false(req_host_ok(&one, "10.0.0.6:8080"));
	assert_true(req_host_ok(&one, "127.0.0.1:8080"));
	struct req_hosts v6 = { .listen = "::1" };
	assert_true(req_host_ok(&v6, "[0:0::1]:8080"));
	assert_false(req_host_ok(&v6, "[::2]:8080"));
}

/* The page offers its token as a subprotocol beside "undulate", so the
 * server knows it at the handshake (and keeps room for it). */
static void test_ws_token(void **state)
{
	(void)state;
	char t[REQ_TOKEN_MAX];
	assert_true(req_ws_token("undulate, undulate-token.abc_DEF-1", t, sizeof t));
	assert_string_equal(t, "abc_DEF-1");
	assert_true(req_ws_token("undulate,undulate-token.x.y~z", t, sizeof t));
	assert_string_equal(t, "x.y~z");
	assert_true(req_ws_token("undulate-token.first , undulate", t, sizeof t));
	assert_string_equal(t, "first");
	assert_false(req_ws_token("undulate", t, sizeof t));
	assert_false(req_ws_token("", t, sizeof t));
	assert_false(req_ws_token(NULL, t, sizeof t));
	assert_false(req_ws_token("undulate, undulate-token.", t, sizeof t));
	assert_false(req_ws_token("undulate, xundulate-token.abc", t, sizeof t));
	assert_false(req_ws_token("undulate, undulate-token.a/b", t, sizeof t));
	char longer[200] = "undulate, undulate-token.";
	memset(longer + strlen(longer), 'a', REQ_TOKEN_MAX);
	assert_false(req_ws_token(longer, t, sizeof t));
}

/* Watchers (no token) may take WEB_MAX_WATCHERS of the places; the rest
 * stays for the token's holders, so a crowd cannot lock them out. */
static void test_ws_room(void **state)
{
	(void)state;
	assert_true(req_ws_room(0, 0, false, 32, 24));
	assert_true(req_ws_room(23, 23, false, 32, 24));
	assert_false(req_ws_room(24, 24, false, 32, 24));
	assert_true(req_ws_room(24, 24, true, 32, 24));
	assert_true(req_ws_room(31, 24, true, 32, 24));
	assert_false(req_ws_room(32, 24, true, 32, 24));
	assert_false(req_ws_room(32, 10, false, 32, 24));
	assert_true(req_ws_room(31, 10, false, 32, 24));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_routes),
		cmocka_unit_test(test_commands_valid),
		cmocka_unit_test(test_commands_invalid),
		cmocka_unit_test(test_auth),
		cmocka_unit_test(test_origin),
		cmocka_unit_test(test_host),
		cmocka_unit_test(test_ws_token),
		cmocka_unit_test(test_ws_room),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
