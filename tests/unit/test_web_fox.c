/* test_web_fox.c — the pure parts of undulate-web's Foxglove WebSocket
 * (tools/web/fox.h): which type each channel carries; the JSON Schema of each
 * type names every field of its .lcm file, in order, and parses; each
 * message's JSON holds its values (NaN as null, hostile strings escaped,
 * arrays by their counts) with the schema's keys; the messageData header's
 * bytes as the spec lays them out; the client's operations, and every way
 * one can be wrong. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../tools/web/fox.h"

/* What fn wrote into a string (freed by the caller). */
static char *written(bool (*fn)(const struct fox_type *, const void *, FILE *), const struct fox_type *t,
                     const void *msg)
{
	char *s = NULL;
	size_t n = 0;
	FILE *f = open_memstream(&s, &n);
	assert_non_null(f);
	assert_true(fn(t, msg, f));
	fclose(f);
	return s;
}
static bool schema_of(const struct fox_type *t, const void *msg, FILE *f)
{
	(void)msg;
	return fox_schema(t, f);
}
static char *schema(const char *channel)
{
	const struct fox_type *t = fox_kind_of(channel);
	assert_non_null(t);
	return written(schema_of, t, NULL);
}
/* Through the FILE; the server's buffer sink must give the same bytes, and
 * 0 (not a cut document) when the buffer is one byte short. */
static char *encode(const char *channel, const void *msg)
{
	const struct fox_type *t = fox_kind_of(channel);
	assert_non_null(t);
	char *s = written(fox_encode, t, msg);
	static char buf[8192];
	size_t n = fox_encode_buf(t, msg, buf, sizeof buf);
	assert_int_equal(n, strlen(s));
	assert_string_equal(buf, s);
	assert_int_equal(fox_encode_buf(t, msg, buf, n), 0);
	assert_int_equal(fox_encode_buf(t, msg, buf, n + 1), n);
	return s;
}

/* A document is one JSON value, whole (RFC 8259's grammar; a checker of
 * our own: lejp 4.1 refuses more than five arrays of numbers in one object). */
static const char *json_value(const char *p);
static const char *json_ws(const char *p)
{
	while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')
		p++;
	return p;
}
static const char *json_string_end(const char *p)
{
	for (p++; *p && *p != '"'; p++) {
		if ((unsigned char)*p < 0x20)
			return NULL;
		if (*p == '\\' && *++p == 'u') {
			for (int i = 0; i < 4; i++)
				if (!strchr("0123456789abcdefABCDEF", *++p) || !*p)
					return NULL;
		} else if (*p == '\\' && !strchr("\"\\/bfnrt", *p)) {
			return NULL;
		}
	}
	return *p == '"' ? p + 1 : NULL;
}
static const char *json_items(const char *p, char close, bool keyed)
{
	p = json_ws(p + 1);
	if (*p == close)
		return p + 1;
	for (;;) {
		if (keyed) {
			if (*p != '"' || (p = json_string_end(p)) == NULL || *(p = json_ws(p)) != ':')
				return NULL;
			p++;
		}
		if ((p = json_value(p)) == NULL)
			return NULL;
		p = json_ws(p);
		if (*p == close)
			return p + 1;
		if (*p != ',')
			return NULL;
		p = json_ws(p + 1);
	}
}
static const char *json_value(const char *p)
{
	p = json_ws(p);
	if (*p == '{')
		return json_items(p, '}', true);
	if (*p == '[')
		return json_items(p, ']', false);
	if (*p == '"')
		return json_string_end(p);
	static const char *const words[] = { "true", "false", "null" };
	for (size_t i = 0; i < 3; i++)
		if (strncmp(p, words[i], strlen(words[i])) == 0)
			return p + strlen(words[i]);
	char *end;
	if (*p != '-' && (*p < '0' || *p > '9'))
		return NULL;
	strtod(p, &end);
	return end > p ? end : NULL;
}
static bool parses(const char *s)
{
	const char *end = json_value(s);
	return end != NULL && *json_ws(end) == '\0';
}

static void test_kinds(void **state)
{
	(void)state;
	static const struct { const char *channel, *type; } rows[] = {
		{ "left.STATE", "undulate.robot_state_t" },  { "r1.BUS", "undulate.bus_stats_t" },
		{ "r1.PARAMS", "undulate.osc_params_t" },    { "r1.EVENT", "undulate.event_t" },
		{ "SIM.TRUTH", "undulate.sim_truth_t" },     { "SIM.COLLISION", "undulate.sim_collision_t" },
		{ "SIM.WORLD", "undulate.sim_world_t" },     { "SIM.REPLY", "undulate.sim_reply_t" },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		const struct fox_type *t = fox_kind_of(rows[i].channel);
		assert_non_null(t);
		assert_string_equal(t->name, rows[i].type);
		assert_non_null(t->dec);
	}
	/* commands are not served (read-only), nor what names no type */
	static const char *const none[] = { "left.CMD", "UNDULATE.CMD", "SIM.CMD", ".STATE", "STATE", "x", "" };
	for (size_t i = 0; i < sizeof none / sizeof none[0]; i++)
		assert_null(fox_kind_of(none[i]));
}

/* The field names of lcmtypes/NAME.lcm, in order ("a b c "), with typed
 * each one's type before it ("int64_t utime double[] k joint_state_t[]
 * joints "). The test runs from the source tree (tests/run.sh) or its build
 * directory's parent. */
static void lcm_fields(const char *name, bool typed, char *out, size_t cap)
{
	char path[256];
	FILE *f = NULL;
	static const char *const dirs[] = { "lcmtypes", "../lcmtypes", "../../lcmtypes" };
	for (size_t i = 0; i < 3 && f == NULL; i++) {
		snprintf(path, sizeof path, "%s/%s.lcm", dirs[i], name);
		f = fopen(path, "r");
	}
	if (f == NULL)
		skip();
	char line[512], type[64], field[64];
	out[0] = '\0';
	while (fgets(line, sizeof line, f)) {
		char *c = strstr(line, "//");
		if (c)
			*c = '\0';
		if (strstr(line, "const ") || strstr(line, "struct ") || strstr(line, "package "))
			continue;
		if (sscanf(line, " %63s %63[A-Za-z0-9_]", type, field) == 2 && strchr(line, ';')) {
			if (typed) {
				strncat(out, type, cap - strlen(out) - 4);
				strncat(out, strchr(line, '[') ? "[] " : " ", cap - strlen(out) - 1);
			}
			strncat(out, field, cap - strlen(out) - 2);
			strncat(out, " ", cap - strlen(out) - 1);
		}
	}
	fclose(f);
}

/* The schema's property names at the top of its object, in order. */
static void schema_fields(const char *s, char *out, size_t cap)
{
	out[0] = '\0';
	const char *p = strstr(s, "\"properties\":{");
	assert_non_null(p);
	p += strlen("\"properties\":{");
	int depth = 0;
	for (; *p && depth >= 0; p++) {
		if (*p == '{' || *p == '[')
			depth++;
		else if (*p == '}' || *p == ']')
			depth--;
		else if (*p == '"' && depth == 0) {
			const char *e = strchr(p + 1, '"');
			strncat(out, p + 1, (size_t)(e - p - 1) < cap - strlen(out) - 2 ? (size_t)(e - p - 1) : 0);
			strncat(out, " ", cap - strlen(out) - 1);
			p = e + 1; /* the ':' */
		}
	}
}

static void test_schemas_name_every_field(void **state)
{
	(void)state;
	static const struct { const char *channel, *lcm; } rows[] = {
		{ "x.STATE", "robot_state_t" }, { "x.BUS", "bus_stats_t" },   { "x.PARAMS", "osc_params_t" },
		{ "x.EVENT", "event_t" },       { "SIM.TRUTH", "sim_truth_t" }, { "SIM.COLLISION", "sim_collision_t" },
		{ "SIM.WORLD", "sim_world_t" }, { "SIM.REPLY", "sim_reply_t" },
	};
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		char *s = schema(rows[i].channel);
		char want[1024], got[1024];
		assert_true(parses(s));
		lcm_fields(rows[i].lcm, false, want, sizeof want);
		schema_fields(s, got, sizeof got);
		assert_string_equal(got, want);
		free(s);
	}
}

/* The table's fields as lcm_fields writes them typed. */
static void table_fields(const struct fox_type *t, char *out, size_t cap)
{
	static const char *const lcm[] = { [FOX_I8] = "int8_t", [FOX_I16] = "int16_t", [FOX_I32] = "int32_t",
	                                   [FOX_I64] = "int64_t", [FOX_F64] = "double", [FOX_BOOL] = "boolean",
	                                   [FOX_STRING] = "string", [FOX_F64_ARRAY] = "double[]" };
	out[0] = '\0';
	for (size_t i = 0; i < t->nfields; i++) {
		const struct fox_field *f = &t->fields[i];
		char type[80];
		if (f->kind == FOX_STRUCT_ARRAY)
			snprintf(type, sizeof type, "%s[]", f->item->name + strlen("undulate."));
		else
			snprintf(type, sizeof type, "%s", lcm[f->kind]);
		size_t n = strlen(out);
		snprintf(out + n, cap - n, "%s %s ", type, f->name);
	}
}

/* Each table (and the tables of its arrays' elements) is its .lcm file:
 * names, order and C types, so no field is read at a wrong width. */
static void check_table(const struct fox_type *t)
{
	char want[1024], got[1024];
	lcm_fields(t->name + strlen("undulate."), true, want, sizeof want);
	table_fields(t, got, sizeof got);
	assert_string_equal(got, want);
	for (size_t i = 0; i < t->nfields; i++)
		if (t->fields[i].kind == FOX_STRUCT_ARRAY)
			check_table(t->fields[i].item);
}

static void test_tables_are_the_lcm_files(void **state)
{
	(void)state;
	static const char *const channels[] = { "x.STATE", "x.BUS", "x.PARAMS", "x.EVENT",
	                                        "SIM.TRUTH", "SIM.COLLISION", "SIM.WORLD", "SIM.REPLY" };
	for (size_t i = 0; i < sizeof channels / sizeof channels[0]; i++)
		check_table(fox_kind_of(channels[i]));
}

static void test_schema_text(void **state)
{
	(void)state;
	char *s = schema("left.STATE");
	assert_non_null(strstr(s, "{\"title\":\"undulate.robot_state_t\",\"type\":\"object\",\"properties\":"
	                          "{\"utime\":{\"type\":\"integer\"},\"robot\":{\"type\":\"string\"},"));
	assert_non_null(strstr(s, "\"joints\":{\"type\":\"array\",\"items\":{\"title\":\"undulate.joint_state_t\","
	                          "\"type\":\"object\",\"properties\":{\"servo_id\":{\"type\":\"integer\"},"
	                          "\"angle\":{\"type\":\"number\"}"));
	assert_non_null(strstr(s, "\"torque\":{\"type\":\"boolean\"}"));
	free(s);
	s = schema("r.PARAMS");
	assert_non_null(strstr(s, "\"k\":{\"type\":\"array\",\"items\":{\"type\":\"number\"}}"));
	free(s);
	s = schema("SIM.TRUTH");
	assert_true(parses(s));
	assert_non_null(strstr(s, "\"contacts\":{\"type\":\"array\",\"items\":{\"title\":\"undulate.sim_contact_t\""));
	free(s);
}

static void test_encode_state(void **state)
{
	(void)state;
	undulate_joint_state_t j[2] = {
		{ .servo_id = 1, .angle = 0.25, .speed = -1.5, .goal = NAN, .temperature = INFINITY, .torque = 1,
		  .torque_read = -1, .stale_cycles = 3 },
		{ .servo_id = 2, .angle = -0.125 },
	};
	undulate_robot_state_t m = { .utime = 1764000000123456, .robot = (char *)"left", .cycle = 42, .mode = 3,
	                             .mode_reason = (char *)"command \"x\"\n", .fault = (char *)"",
	                             .period_us = 10000.5, .njoints = 2, .joints = j };
	char *s = encode("left.STATE", &m);
	assert_true(parses(s));
	assert_string_equal(s, "{\"utime\":1764000000123456,\"robot\":\"left\",\"cycle\":42,\"mode\":3,"
	                       "\"mode_reason\":\"command \\\"x\\\"\\u000a\",\"fault\":\"\",\"period_us\":10000.5,"
	                       "\"jitter_us\":0,\"bus_us\":0,\"control_us\":0,\"overruns\":0,\"bus_errors\":0,"
	                       "\"bad_commands\":0,\"njoints\":2,\"joints\":["
	                       "{\"servo_id\":1,\"angle\":0.25,\"speed\":-1.5,\"load\":0,\"goal\":null,\"drive\":0,"
	                       "\"phase\":0,\"amplitude\":0,\"frequency\":0,\"voltage\":0,\"temperature\":null,"
	                       "\"error_bits\":0,\"stale_cycles\":3,\"torque\":true,\"torque_read\":-1,"
	                       "\"torque_limit\":0},"
	                       "{\"servo_id\":2,\"angle\":-0.125,\"speed\":0,\"load\":0,\"goal\":0,\"drive\":0,"
	                       "\"phase\":0,\"amplitude\":0,\"frequency\":0,\"voltage\":0,\"temperature\":0,"
	                       "\"error_bits\":0,\"stale_cycles\":0,\"torque\":false,\"torque_read\":0,"
	                       "\"torque_limit\":0}]}");
	free(s);
}

static void test_encode_others(void **state)
{
	(void)state;
	undulate_servo_stats_t sv = { .servo_id = 7, .timeouts = 9, .rtt_max_us = 812.5 };
	undulate_bus_stats_t b = { .robot = (char *)"r1", .port = (char *)"/dev/ttyUSB0", .baud = 1000000,
	                           .connected = 1, .nservos = 1, .servos = &sv };
	char *s = encode("r1.BUS", &b);
	assert_true(parses(s));
	assert_non_null(strstr(s, "\"connected\":true"));
	assert_non_null(strstr(s, "\"servos\":[{\"servo_id\":7,\"transactions\":0,\"replies\":0,\"timeouts\":9,"));
	assert_non_null(strstr(s, "\"rtt_max_us\":812.5}]}"));
	free(s);

	double k[2] = { 1.5, 2 }, z[2] = { 0, 0 };
	undulate_osc_params_t p = { .robot = (char *)"r1", .njoints = 2, .k = k, .c = z, .mu = z, .lambda = z,
	                            .inertia = z, .friction = z, .neutral = z, .limit_min = z, .limit_max = z,
	                            .frequency = 0.8 };
	s = encode("r1.PARAMS", &p);
	assert_true(parses(s));
	assert_non_null(strstr(s, "\"njoints\":2,\"k\":[1.5,2],\"c\":[0,0],"));
	assert_non_null(strstr(s, "\"frequency\":0.8,"));
	free(s);

	/* a count the arrays do not have (never after lcmdec) is not walked past NULL */
	undulate_osc_params_t empty = { .njoints = 5 };
	s = encode("r1.PARAMS", &empty);
	assert_true(parses(s));
	assert_non_null(strstr(s, "\"k\":[],"));
	free(s);

	/* strings from the network: control bytes, quotes, bytes that are not UTF-8 */
	undulate_event_t e = { .robot = (char *)"r1", .seq = 5, .level = 2, .kind = (char *)"fault",
	                       .text = (char *)"servo\x01 \"2\" \xff\xfe" };
	s = encode("r1.EVENT", &e);
	assert_true(parses(s));
	assert_string_equal(s, "{\"utime\":0,\"robot\":\"r1\",\"seq\":5,\"level\":2,\"kind\":\"fault\","
	                       "\"text\":\"servo\\u0001 \\\"2\\\" \\ufffd\\ufffd\"}");
	free(s);
}

static void test_encode_truth(void **state)
{
	(void)state;
	undulate_sim_body_t bodies[2] = { { .robot = (char *)"r1", .lateral = 0.1 }, { .robot = (char *)"r2" } };
	undulate_sim_link_t links[1] = { { .robot = 1, .link = 2, .x = 0.5, .y = -0.25, .length = 0.1865 } };
	undulate_sim_wall_t walls[1] = { { .ax = -1, .bx = 1 } };
	undulate_sim_contact_t contacts[1] = { { .robot_a = 0, .robot_b = -1, .link_b = 3, .force = 2.5, .impact = 1 } };
	undulate_sim_collision_t col[1] = { { .left = 0, .right = 1, .left_robot = (char *)"r1",
	                                      .right_robot = (char *)"r2", .impulse = 0.01 } };
	undulate_sim_truth_t t = { .step = 100, .sim_time = 1, .nbodies = 2, .bodies = bodies, .ncollisions = 1,
	                           .collisions = col, .world = 1, .nlinks = 1, .links = links, .nwalls = 1,
	                           .walls = walls, .ncontacts = 1, .contacts = contacts };
	char *s = encode("SIM.TRUTH", &t);
	assert_true(parses(s));
	assert_non_null(strstr(s, "\"nbodies\":2,\"bodies\":[{\"robot\":\"r1\",\"servo_id\":0,\"angle\":0,"
	                          "\"speed\":0,\"lateral\":0.1,"));
	assert_non_null(strstr(s, "\"collisions\":[{\"utime\":0,\"left\":0,\"right\":1,\"left_robot\":\"r1\","));
	assert_non_null(strstr(s, "\"links\":[{\"robot\":1,\"link\":2,\"x\":0.5,\"y\":-0.25,\"angle\":0,"
	                          "\"length\":0.1865,\"width\":0}]"));
	assert_non_null(strstr(s, "\"walls\":[{\"ax\":-1,\"ay\":0,\"bx\":1,\"by\":0}]"));
	assert_non_null(strstr(s, "\"contacts\":[{\"robot_a\":0,\"link_a\":0,\"robot_b\":-1,\"link_b\":3,"));
	assert_non_null(strstr(s, "\"force\":2.5,\"impact\":true}]"));
	free(s);
}

static void test_data_header(void **state)
{
	(void)state;
	unsigned char h[FOX_DATA_HEADER];
	fox_data_header(h, 0x04030201u, 0x0c0b0a0908070605ull);
	static const unsigned char want[FOX_DATA_HEADER] = { 0x01, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06,
	                                                     0x07, 0x08, 0x09, 0x0a, 0x0b, 0x0c };
	assert_memory_equal(h, want, sizeof want);
	fox_data_header(h, UINT32_MAX, 1764000000123456789ull);
	assert_int_equal(h[0], 1);
	assert_int_equal(h[1] & h[2] & h[3] & h[4], 0xff);
	uint64_t ts = 0;
	for (int i = 7; i >= 0; i--)
		ts = ts << 8 | h[5 + i];
	assert_true(ts == 1764000000123456789ull);
}

/* RFC 6455 5.7's examples of unmasked binary frames (256 bytes, 64 KiB),
 * and each length encoding's edges. */
static void test_ws_header(void **state)
{
	(void)state;
	unsigned char h[FOX_WS_HEADER_MAX];
	static const unsigned char b256[] = { 0x82, 0x7e, 0x01, 0x00 };
	assert_int_equal(fox_ws_header(h, 256), 4);
	assert_memory_equal(h, b256, sizeof b256);
	static const unsigned char b64k[] = { 0x82, 0x7f, 0, 0, 0, 0, 0, 0x01, 0x00, 0x00 };
	assert_int_equal(fox_ws_header(h, 65536), 10);
	assert_memory_equal(h, b64k, sizeof b64k);
	static const unsigned char b0[] = { 0x82, 0x00 }, b125[] = { 0x82, 0x7d }, b126[] = { 0x82, 0x7e, 0x00, 0x7e };
	static const unsigned char b65535[] = { 0x82, 0x7e, 0xff, 0xff };
	assert_int_equal(fox_ws_header(h, 0), 2);
	assert_memory_equal(h, b0, sizeof b0);
	assert_int_equal(fox_ws_header(h, 125), 2);
	assert_memory_equal(h, b125, sizeof b125);
	assert_int_equal(fox_ws_header(h, 126), 4);
	assert_memory_equal(h, b126, sizeof b126);
	assert_int_equal(fox_ws_header(h, 65535), 4);
	assert_memory_equal(h, b65535, sizeof b65535);
}

static void test_ops(void **state)
{
	(void)state;
	struct fox_op op;
	char why[256];
	static const char sub[] = " {\"op\":\"subscribe\",\"subscriptions\":[{\"id\":0,\"channelId\":3},"
	                          "{\"channelId\":4294967295,\"id\":7}]}\n";
	assert_true(fox_op_parse(sub, strlen(sub), &op, why, sizeof why));
	assert_int_equal(op.kind, FOX_OP_SUBSCRIBE);
	assert_int_equal(op.n, 2);
	assert_int_equal(op.subs[0].id, 0);
	assert_int_equal(op.subs[0].channel, 3);
	assert_int_equal(op.subs[1].id, 7);
	assert_true(op.subs[1].channel == UINT32_MAX);
	static const char unsub[] = "{\"subscriptionIds\":[5,6,7],\"op\":\"unsubscribe\"}";
	assert_true(fox_op_parse(unsub, strlen(unsub), &op, why, sizeof why));
	assert_int_equal(op.kind, FOX_OP_UNSUBSCRIBE);
	assert_int_equal(op.n, 3);
	assert_int_equal(op.unsubs[2], 7);
	static const char other[] = "{\"op\":\"advertise\",\"channels\":[{\"id\":1,\"topic\":\"x\"}]}";
	assert_true(fox_op_parse(other, strlen(other), &op, why, sizeof why));
	assert_int_equal(op.kind, FOX_OP_OTHER);
	assert_string_equal(op.name, "advertise");
	static const char empty[] = "{\"op\":\"subscribe\",\"subscriptions\":[]}";
	assert_true(fox_op_parse(empty, strlen(empty), &op, why, sizeof why));
	assert_int_equal(op.n, 0);
}

static void test_bad_ops(void **state)
{
	(void)state;
	static const struct { const char *text, *why; } rows[] = {
		{ "", "not JSON" },
		{ "this is not JSON {", "not JSON" },
		{ "{\"op\":\"subscribe\"", "not JSON" },
		{ "{\"op\":\"subscribe\"} x", "bytes after" },
		{ "[1,2]", "string \"op\"" },
		{ "{\"x\":1}", "string \"op\"" },
		{ "{\"op\":3}", "string \"op\"" },
		{ "{\"op\":null}", "string \"op\"" },
		{ "{\"op\":\"launchMissiles\"}", "unknown op \"launchMissiles\"" },
		{ "{\"op\":\"aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\"}", "string \"op\"" },
		{ "{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":\"x\",\"channelId\":1}]}", "integers" },
		{ "{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":-1,\"channelId\":1}]}", "integers" },
		{ "{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":1.5,\"channelId\":1}]}", "integers" },
		{ "{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":4294967296,\"channelId\":1}]}", "integers" },
		{ "{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":1}]}", "lacks its id or channelId" },
		{ "{\"op\":\"subscribe\",\"subscriptions\":{\"id\":1,\"channelId\":1}}", "want \"subscriptions\"" },
		{ "{\"op\":\"unsubscribe\",\"subscriptionIds\":[true]}", "want \"subscriptionIds\"" },
		{ "{\"op\":\"unsubscribe\",\"subscriptionIds\":7}", "want \"subscriptionIds\"" },
	};
	struct fox_op op;
	char why[256];
	for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
		bool ok = fox_op_parse(rows[i].text, strlen(rows[i].text), &op, why, sizeof why);
		if (ok || strstr(why, rows[i].why) == NULL)
			fail_msg("'%s': %s, want '%s'", rows[i].text, ok ? "accepted" : why, rows[i].why);
	}
	/* more items than one operation may carry */
	char big[8192];
	size_t n = (size_t)snprintf(big, sizeof big, "{\"op\":\"unsubscribe\",\"subscriptionIds\":[");
	for (int i = 0; i <= FOX_OP_ITEMS; i++)
		n += (size_t)snprintf(big + n, sizeof big - n, "%s%d", i ? "," : "", i);
	n += (size_t)snprintf(big + n, sizeof big - n, "]}");
	assert_false(fox_op_parse(big, n, &op, why, sizeof why));
	assert_non_null(strstr(why, "more than 64 items"));
	/* deep nesting is lejp's to refuse, not a crash */
	char deep[4096];
	n = (size_t)snprintf(deep, sizeof deep, "{\"op\":\"subscribe\",\"x\":");
	for (int i = 0; i < 1000; i++)
		deep[n++] = '[';
	deep[n] = '\0';
	assert_false(fox_op_parse(deep, n, &op, why, sizeof why));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_kinds),           cmocka_unit_test(test_schemas_name_every_field),
		cmocka_unit_test(test_tables_are_the_lcm_files),
		cmocka_unit_test(test_schema_text),     cmocka_unit_test(test_encode_state),
		cmocka_unit_test(test_encode_others),   cmocka_unit_test(test_encode_truth),
		cmocka_unit_test(test_ws_header),
		cmocka_unit_test(test_data_header),     cmocka_unit_test(test_ops),
		cmocka_unit_test(test_bad_ops),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
