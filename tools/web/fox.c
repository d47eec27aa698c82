/* fox.c — see fox.h. */
#include "fox.h"

#include <errno.h>
#include <libwebsockets.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

/* ---- the types, as lcm-gen's structs hold them (order of the .lcm files) ------------ */

#define FOX_F(T, f, k) { #f, k, offsetof(T, f), 0, NULL }
#define FOX_A(T, f, n) { #f, FOX_F64_ARRAY, offsetof(T, f), offsetof(T, n), NULL }
#define FOX_S(T, f, n, item) { #f, FOX_STRUCT_ARRAY, offsetof(T, f), offsetof(T, n), &(item) }
#define FOX_TYPE(var, T, fields, dec) \
	static const struct fox_type var = { "undulate." #T, fields, sizeof fields / sizeof fields[0], \
	                                      sizeof(undulate_##T), dec }

#define T undulate_joint_state_t
static const struct fox_field fox_joint_fields[] = {
	FOX_F(T, servo_id, FOX_I16), FOX_F(T, angle, FOX_F64), FOX_F(T, speed, FOX_F64),
	FOX_F(T, load, FOX_F64), FOX_F(T, goal, FOX_F64), FOX_F(T, drive, FOX_F64),
	FOX_F(T, phase, FOX_F64), FOX_F(T, amplitude, FOX_F64), FOX_F(T, frequency, FOX_F64),
	FOX_F(T, voltage, FOX_F64), FOX_F(T, temperature, FOX_F64), FOX_F(T, error_bits, FOX_I16),
	FOX_F(T, stale_cycles, FOX_I32), FOX_F(T, torque, FOX_BOOL), FOX_F(T, torque_read, FOX_I8),
	FOX_F(T, torque_limit, FOX_I16),
};
#undef T
FOX_TYPE(fox_joint, joint_state_t, fox_joint_fields, NULL);

#define T undulate_robot_state_t
static const struct fox_field fox_state_fields[] = {
	FOX_F(T, utime, FOX_I64), FOX_F(T, robot, FOX_STRING), FOX_F(T, cycle, FOX_I64),
	FOX_F(T, mode, FOX_I8), FOX_F(T, mode_reason, FOX_STRING), FOX_F(T, fault, FOX_STRING),
	FOX_F(T, period_us, FOX_F64), FOX_F(T, jitter_us, FOX_F64), FOX_F(T, bus_us, FOX_F64),
	FOX_F(T, control_us, FOX_F64), FOX_F(T, overruns, FOX_I64), FOX_F(T, bus_errors, FOX_I64),
	FOX_F(T, bad_commands, FOX_I64), FOX_F(T, njoints, FOX_I32), FOX_S(T, joints, njoints, fox_joint),
};
#undef T
FOX_TYPE(fox_state, robot_state_t, fox_state_fields, &lcmdec_robot_state_t);

#define T undulate_servo_stats_t
static const struct fox_field fox_servo_fields[] = {
	FOX_F(T, servo_id, FOX_I16), FOX_F(T, transactions, FOX_I64), FOX_F(T, replies, FOX_I64),
	FOX_F(T, timeouts, FOX_I64), FOX_F(T, checksum_errors, FOX_I64), FOX_F(T, resyncs, FOX_I64),
	FOX_F(T, wrong_id, FOX_I64), FOX_F(T, wrong_length, FOX_I64), FOX_F(T, error_replies, FOX_I64),
	FOX_F(T, errbits_seen, FOX_I16), FOX_F(T, rtt_mean_us, FOX_F64), FOX_F(T, rtt_max_us, FOX_F64),
};
#undef T
FOX_TYPE(fox_servo, servo_stats_t, fox_servo_fields, NULL);

#define T undulate_bus_stats_t
static const struct fox_field fox_bus_fields[] = {
	FOX_F(T, utime, FOX_I64), FOX_F(T, robot, FOX_STRING), FOX_F(T, port, FOX_STRING),
	FOX_F(T, baud, FOX_I32), FOX_F(T, connected, FOX_BOOL), FOX_F(T, reconnects, FOX_I64),
	FOX_F(T, adapter_latency_ms, FOX_F64), FOX_F(T, return_delay_us, FOX_I32),
	FOX_F(T, period_p50_us, FOX_F64), FOX_F(T, period_p99_us, FOX_F64), FOX_F(T, period_max_us, FOX_F64),
	FOX_F(T, jitter_p99_us, FOX_F64), FOX_F(T, bus_p99_us, FOX_F64), FOX_F(T, cpu_percent, FOX_F64),
	FOX_F(T, overruns, FOX_I64), FOX_F(T, stray_packets, FOX_I64), FOX_F(T, io_errors, FOX_I64),
	FOX_F(T, nservos, FOX_I32), FOX_S(T, servos, nservos, fox_servo),
};
#undef T
FOX_TYPE(fox_bus, bus_stats_t, fox_bus_fields, &lcmdec_bus_stats_t);

#define T undulate_osc_params_t
static const struct fox_field fox_params_fields[] = {
	FOX_F(T, utime, FOX_I64), FOX_F(T, robot, FOX_STRING), FOX_F(T, njoints, FOX_I32),
	FOX_A(T, k, njoints), FOX_A(T, c, njoints), FOX_A(T, mu, njoints), FOX_A(T, lambda, njoints),
	FOX_A(T, inertia, njoints), FOX_A(T, friction, njoints), FOX_A(T, neutral, njoints),
	FOX_A(T, limit_min, njoints), FOX_A(T, limit_max, njoints), FOX_F(T, amplitude, FOX_F64),
	FOX_F(T, frequency, FOX_F64), FOX_F(T, phase, FOX_F64),
};
#undef T
FOX_TYPE(fox_params, osc_params_t, fox_params_fields, &lcmdec_osc_params_t);

#define T undulate_event_t
static const struct fox_field fox_event_fields[] = {
	FOX_F(T, utime, FOX_I64), FOX_F(T, robot, FOX_STRING), FOX_F(T, seq, FOX_I64),
	FOX_F(T, level, FOX_I8), FOX_F(T, kind, FOX_STRING), FOX_F(T, text, FOX_STRING),
};
#undef T
FOX_TYPE(fox_event, event_t, fox_event_fields, &lcmdec_event_t);

#define T undulate_sim_body_t
static const struct fox_field fox_body_fields[] = {
	FOX_F(T, robot, FOX_STRING), FOX_F(T, servo_id, FOX_I16), FOX_F(T, angle, FOX_F64),
	FOX_F(T, speed, FOX_F64), FOX_F(T, lateral, FOX_F64), FOX_F(T, neutral, FOX_F64),
	FOX_F(T, load, FOX_F64), FOX_F(T, temperature, FOX_F64),
};
#undef T
FOX_TYPE(fox_body, sim_body_t, fox_body_fields, NULL);

#define T undulate_sim_collision_t
static const struct fox_field fox_collision_fields[] = {
	FOX_F(T, utime, FOX_I64), FOX_F(T, left, FOX_I32), FOX_F(T, right, FOX_I32),
	FOX_F(T, left_robot, FOX_STRING), FOX_F(T, right_robot, FOX_STRING), FOX_F(T, pre_left, FOX_F64),
	FOX_F(T, pre_right, FOX_F64), FOX_F(T, post_left, FOX_F64), FOX_F(T, post_right, FOX_F64),
	FOX_F(T, impulse, FOX_F64),
};
#undef T
FOX_TYPE(fox_collision, sim_collision_t, fox_collision_fields, &lcmdec_sim_collision_t);

#define T undulate_sim_link_t
static const struct fox_field fox_link_fields[] = {
	FOX_F(T, robot, FOX_I16), FOX_F(T, link, FOX_I8), FOX_F(T, x, FOX_F64), FOX_F(T, y, FOX_F64),
	FOX_F(T, angle, FOX_F64), FOX_F(T, length, FOX_F64), FOX_F(T, width, FOX_F64),
};
#undef T
FOX_TYPE(fox_link, sim_link_t, fox_link_fields, NULL);

#define T undulate_sim_wall_t
static const struct fox_field fox_wall_fields[] = {
	FOX_F(T, ax, FOX_F64), FOX_F(T, ay, FOX_F64), FOX_F(T, bx, FOX_F64), FOX_F(T, by, FOX_F64),
};
#undef T
FOX_TYPE(fox_wall, sim_wall_t, fox_wall_fields, NULL);

#define T undulate_sim_contact_t
static const struct fox_field fox_contact_fields[] = {
	FOX_F(T, robot_a, FOX_I16), FOX_F(T, link_a, FOX_I8), FOX_F(T, robot_b, FOX_I16),
	FOX_F(T, link_b, FOX_I8), FOX_F(T, x, FOX_F64), FOX_F(T, y, FOX_F64), FOX_F(T, nx, FOX_F64),
	FOX_F(T, ny, FOX_F64), FOX_F(T, impulse, FOX_F64), FOX_F(T, normal_impulse, FOX_F64),
	FOX_F(T, force, FOX_F64), FOX_F(T, impact, FOX_BOOL),
};
#undef T
FOX_TYPE(fox_contact, sim_contact_t, fox_contact_fields, NULL);

#define T undulate_sim_truth_t
static const struct fox_field fox_truth_fields[] = {
	FOX_F(T, utime, FOX_I64), FOX_F(T, step, FOX_I64), FOX_F(T, sim_time, FOX_F64),
	FOX_F(T, wall_left, FOX_F64), FOX_F(T, wall_right, FOX_F64), FOX_F(T, total_collisions, FOX_I64),
	FOX_F(T, total_impulse, FOX_F64), FOX_F(T, total_resting_steps, FOX_I64),
	FOX_F(T, total_resting_impulse, FOX_F64), FOX_F(T, worst_lateness_us, FOX_F64),
	FOX_F(T, nbodies, FOX_I32), FOX_S(T, bodies, nbodies, fox_body),
	FOX_F(T, ncollisions, FOX_I32), FOX_S(T, collisions, ncollisions, fox_collision),
	FOX_F(T, world, FOX_I8), FOX_F(T, nlinks, FOX_I32), FOX_S(T, links, nlinks, fox_link),
	FOX_F(T, nwalls, FOX_I32), FOX_S(T, walls, nwalls, fox_wall),
	FOX_F(T, ncontacts, FOX_I32), FOX_S(T, contacts, ncontacts, fox_contact),
	FOX_F(T, escaped_links, FOX_I64), FOX_F(T, wall_force_left, FOX_F64), FOX_F(T, wall_force_right, FOX_F64),
};
#undef T
FOX_TYPE(fox_truth, sim_truth_t, fox_truth_fields, &lcmdec_sim_truth_t);

#define T undulate_sim_world_t
static const struct fox_field fox_world_fields[] = {
	FOX_F(T, utime, FOX_I64), FOX_F(T, restitution, FOX_F64), FOX_F(T, wall_restitution, FOX_F64),
	FOX_F(T, beta, FOX_F64), FOX_F(T, wall_left, FOX_F64), FOX_F(T, wall_right, FOX_F64),
};
#undef T
FOX_TYPE(fox_world, sim_world_t, fox_world_fields, &lcmdec_sim_world_t);

#define T undulate_sim_reply_t
static const struct fox_field fox_reply_fields[] = {
	FOX_F(T, utime, FOX_I64), FOX_F(T, seq, FOX_I64), FOX_F(T, command, FOX_STRING),
	FOX_F(T, reply, FOX_STRING),
};
#undef T
FOX_TYPE(fox_reply, sim_reply_t, fox_reply_fields, &lcmdec_sim_reply_t);

/* Commands (<robot>.CMD, UNDULATE.CMD, SIM.CMD) are not advertised: this
 * end is read-only, and a signed command's MAC has no business on a plot. */
const char *const fox_extra_channels[] = { "SIM\\.WORLD", "SIM\\.REPLY" };
const size_t fox_extra_nchannels = sizeof fox_extra_channels / sizeof fox_extra_channels[0];

static bool fox_ends_with(const char *s, const char *suffix)
{
	size_t n = strlen(s), k = strlen(suffix);
	return n > k && strcmp(s + n - k, suffix) == 0;
}

const struct fox_type *fox_kind_of(const char *channel)
{
	static const struct { const char *name; const struct fox_type *t; } exact[] = {
		{ "SIM.TRUTH", &fox_truth }, { "SIM.COLLISION", &fox_collision },
		{ "SIM.WORLD", &fox_world }, { "SIM.REPLY", &fox_reply },
	};
	static const struct { const char *suffix; const struct fox_type *t; } robot[] = {
		{ ".STATE", &fox_state }, { ".BUS", &fox_bus }, { ".PARAMS", &fox_params }, { ".EVENT", &fox_event },
	};
	for (size_t i = 0; i < sizeof exact / sizeof exact[0]; i++)
		if (strcmp(channel, exact[i].name) == 0)
			return exact[i].t;
	for (size_t i = 0; i < sizeof robot / sizeof robot[0]; i++)
		if (fox_ends_with(channel, robot[i].suffix))
			return robot[i].t;
	return NULL;
}

/* ---- schema and message, from the same table ------------------------------------------ */

static const char *fox_json_type(enum fox_field_kind k)
{
	switch (k) {
	case FOX_I8: case FOX_I16: case FOX_I32: case FOX_I64: return "integer";
	case FOX_F64: return "number";
	case FOX_BOOL: return "boolean";
	case FOX_STRING: return "string";
	default: return "array";
	}
}

static void fox_schema_object(struct json *j, const struct fox_type *t)
{
	json_object_begin(j);
	json_field_string(j, "title", t->name);
	json_field_string(j, "type", "object");
	json_key(j, "properties");
	json_object_begin(j);
	for (size_t i = 0; i < t->nfields; i++) {
		const struct fox_field *f = &t->fields[i];
		json_key(j, f->name);
		if (f->kind == FOX_STRUCT_ARRAY) {
			json_object_begin(j);
			json_field_string(j, "type", "array");
			json_key(j, "items");
			fox_schema_object(j, f->item);
			json_object_end(j);
			continue;
		}
		json_object_begin(j);
		json_field_string(j, "type", fox_json_type(f->kind));
		if (f->kind == FOX_F64_ARRAY) {
			json_key(j, "items");
			json_object_begin(j);
			json_field_string(j, "type", "number");
			json_object_end(j);
		}
		json_object_end(j);
	}
	json_object_end(j);
	json_object_end(j);
}

bool fox_schema(const struct fox_type *t, FILE *f)
{
	struct json j;
	json_init(&j, f, 0);
	fox_schema_object(&j, t);
	return json_end(&j);
}

/* lcm-gen keeps a negative count as it came; the decoder refused such a
 * message, but an array is never walked on a count below zero. */
static int32_t fox_count(const void *msg, const struct fox_field *f)
{
	int32_t n;
	memcpy(&n, (const char *)msg + f->count_off, sizeof n);
	return n > 0 ? n : 0;
}

static void fox_encode_object(struct json *j, const struct fox_type *t, const void *msg);

static void fox_encode_field(struct json *j, const struct fox_field *f, const void *msg)
{
	const char *p = (const char *)msg + f->off;
	switch (f->kind) {
	case FOX_I8: json_int(j, *(const int8_t *)p); break;
	case FOX_I16: json_int(j, *(const int16_t *)p); break;
	case FOX_I32: json_int(j, *(const int32_t *)p); break;
	case FOX_I64: json_int(j, *(const int64_t *)p); break;
	case FOX_F64: json_number(j, *(const double *)p); break;
	case FOX_BOOL: json_bool(j, *(const int8_t *)p != 0); break;
	case FOX_STRING: json_string(j, *(char *const *)p); break;
	case FOX_F64_ARRAY: {
		const double *v = *(double *const *)p;
		json_array_begin(j);
		for (int32_t i = 0; v != NULL && i < fox_count(msg, f); i++)
			json_number(j, v[i]);
		json_array_end(j);
		break;
	}
	case FOX_STRUCT_ARRAY: {
		const char *v = *(char *const *)p;
		json_array_begin(j);
		for (int32_t i = 0; v != NULL && i < fox_count(msg, f); i++)
			fox_encode_object(j, f->item, v + (size_t)i * f->item->size);
		json_array_end(j);
		break;
	}
	}
}

static void fox_encode_object(struct json *j, const struct fox_type *t, const void *msg)
{
	json_object_begin(j);
	for (size_t i = 0; i < t->nfields; i++) {
		json_key(j, t->fields[i].name);
		fox_encode_field(j, &t->fields[i], msg);
	}
	json_object_end(j);
}

bool fox_encode(const struct fox_type *t, const void *msg, FILE *f)
{
	struct json j;
	json_init(&j, f, 0);
	fox_encode_object(&j, t, msg);
	return json_end(&j);
}

size_t fox_encode_buf(const struct fox_type *t, const void *msg, char *buf, size_t cap)
{
	struct json j;
	json_init_buf(&j, buf, cap, 0);
	fox_encode_object(&j, t, msg);
	return json_end(&j) ? json_len(&j) : 0;
}

void fox_data_header(unsigned char out[FOX_DATA_HEADER], uint32_t subscription, uint64_t receive_ns)
{
	/* the spec's integers are little-endian whatever this machine is */
	out[0] = FOX_OP_MESSAGE_DATA;
	for (int i = 0; i < 4; i++)
		out[1 + i] = (unsigned char)(subscription >> (8 * i));
	for (int i = 0; i < 8; i++)
		out[5 + i] = (unsigned char)(receive_ns >> (8 * i));
}

size_t fox_ws_header(unsigned char out[FOX_WS_HEADER_MAX], size_t len)
{
	out[0] = 0x80 | 0x2;   /* FIN, binary */
	if (len < 126) {
		out[1] = (unsigned char)len;
		return 2;
	}
	if (len <= 0xffff) {
		out[1] = 126;
		out[2] = (unsigned char)(len >> 8);
		out[3] = (unsigned char)len;
		return 4;
	}
	/* network byte order; the most significant bit must be 0 (and is: len < 2^63) */
	out[1] = 127;
	for (int i = 0; i < 8; i++)
		out[2 + i] = (unsigned char)((uint64_t)len >> (8 * (7 - i)));
	return 10;
}

/* ---- the client's operations ------------------------------------------------------------ */

/* Where a value is, by lejp's path of it (its own path matching misses
 * "subscriptionIds[]" in 4.1, so the paths are compared here). */
enum fox_path { FOX_P_NONE, FOX_P_OP, FOX_P_SUB_ID, FOX_P_SUB_CHANNEL, FOX_P_UNSUB };
static enum fox_path fox_path_of(const char *path)
{
	static const char *const paths[] = { [FOX_P_OP] = "op", [FOX_P_SUB_ID] = "subscriptions[].id",
	                                     [FOX_P_SUB_CHANNEL] = "subscriptions[].channelId",
	                                     [FOX_P_UNSUB] = "subscriptionIds[]" };
	for (int i = FOX_P_OP; i <= FOX_P_UNSUB; i++)
		if (strcmp(path, paths[i]) == 0)
			return (enum fox_path)i;
	return FOX_P_NONE;
}

struct fox_parse {
	struct fox_op *op;
	bool has_op, op_string;
	uint8_t have[FOX_OP_ITEMS];     /* per subscription: 1 id, 2 channelId */
	int nsubs, nunsubs;
	bool too_many, bad_value, bad_shape;
};

/* A JSON integer in 0..UINT32_MAX (lejp hands its text over). */
static bool fox_u32(const char *s, uint32_t *out)
{
	if (*s < '0' || *s > '9')
		return false;
	errno = 0;
	char *end;
	unsigned long long v = strtoull(s, &end, 10);
	if (errno != 0 || *end != '\0' || v > UINT32_MAX)
		return false;
	*out = (uint32_t)v;
	return true;
}

/* The array index of the innermost array the parser is in. */
static int fox_index(const struct lejp_ctx *ctx)
{
	return ctx->ipos > 0 ? ctx->i[ctx->ipos - 1] : -1;
}

static void fox_item(struct fox_parse *p, const struct lejp_ctx *ctx, enum fox_path where, char reason)
{
	int k = fox_index(ctx);
	bool is_int = reason == LEJPCB_VAL_NUM_INT;
	uint32_t v = 0;
	if (k < 0 || k >= FOX_OP_ITEMS) {
		p->too_many = true;
		return;
	}
	if (!is_int || !fox_u32(ctx->buf, &v)) {
		p->bad_value = true;
		return;
	}
	if (where == FOX_P_UNSUB) {
		p->op->unsubs[k] = v;
		p->nunsubs = k + 1 > p->nunsubs ? k + 1 : p->nunsubs;
		return;
	}
	if (where == FOX_P_SUB_ID)
		p->op->subs[k].id = v;
	else
		p->op->subs[k].channel = v;
	p->have[k] |= where == FOX_P_SUB_ID ? 1 : 2;
	p->nsubs = k + 1 > p->nsubs ? k + 1 : p->nsubs;
}

static signed char fox_lejp_cb(struct lejp_ctx *ctx, char reason)
{
	struct fox_parse *p = ctx->user;
	if (!(reason & LEJP_FLAG_CB_IS_VALUE) && reason != LEJPCB_ARRAY_START && reason != LEJPCB_OBJECT_START)
		return 0;
	/* the top-level keys must hold what the protocol says: arrays */
	if ((strcmp(ctx->path, "subscriptions") == 0 || strcmp(ctx->path, "subscriptionIds") == 0) &&
	    reason != LEJPCB_ARRAY_START)
		p->bad_shape = true;
	enum fox_path where = fox_path_of(ctx->path);
	if (where == FOX_P_OP && (reason & LEJP_FLAG_CB_IS_VALUE)) {
		/* a string's chunks: only short names matter (longer ones are no op) */
		p->has_op = true;
		p->op_string = reason == LEJPCB_VAL_STR_END || reason == LEJPCB_VAL_STR_CHUNK;
		if (p->op_string && strlen(ctx->buf) < FOX_OP_NAME_MAX && reason == LEJPCB_VAL_STR_END)
			snprintf(p->op->name, sizeof p->op->name, "%s", ctx->buf);
		else
			p->op->name[0] = '\0';
		return 0;
	}
	if (where >= FOX_P_SUB_ID && (reason & LEJP_FLAG_CB_IS_VALUE) && reason != LEJPCB_VAL_STR_CHUNK)
		fox_item(p, ctx, where, reason);
	return 0;
}

/* Every op of the spec a client may send; those we do not serve get a status. */
static bool fox_op_known(const char *name)
{
	static const char *const ops[] = {
		"advertise", "unadvertise", "getParameters", "setParameters", "subscribeParameterUpdates",
		"unsubscribeParameterUpdates", "subscribeConnectionGraph", "unsubscribeConnectionGraph",
		"fetchAsset",
	};
	for (size_t i = 0; i < sizeof ops / sizeof ops[0]; i++)
		if (strcmp(name, ops[i]) == 0)
			return true;
	return false;
}

static bool fox_op_check(struct fox_parse *p, char *why, size_t cap)
{
	struct fox_op *op = p->op;
	if (!p->has_op || !p->op_string || op->name[0] == '\0') {
		snprintf(why, cap, "not an operation: want a JSON object with a string \"op\"");
		return false;
	}
	if (strcmp(op->name, "subscribe") == 0)
		op->kind = FOX_OP_SUBSCRIBE;
	else if (strcmp(op->name, "unsubscribe") == 0)
		op->kind = FOX_OP_UNSUBSCRIBE;
	else if (fox_op_known(op->name))
		op->kind = FOX_OP_OTHER;
	else {
		snprintf(why, cap, "unknown op \"%s\"", op->name);
		return false;
	}
	op->n = op->kind == FOX_OP_SUBSCRIBE ? p->nsubs : op->kind == FOX_OP_UNSUBSCRIBE ? p->nunsubs : 0;
	if (p->too_many) {
		snprintf(why, cap, "%s: more than %d items in one operation", op->name, FOX_OP_ITEMS);
		return false;
	}
	if (p->bad_shape || p->bad_value) {
		snprintf(why, cap, "%s: %s", op->name, op->kind == FOX_OP_SUBSCRIBE
		         ? "want \"subscriptions\": [{\"id\": N, \"channelId\": N}, ...], N integers 0..4294967295"
		         : "want \"subscriptionIds\": [N, ...], N integers 0..4294967295");
		return false;
	}
	for (int i = 0; op->kind == FOX_OP_SUBSCRIBE && i < op->n; i++)
		if (p->have[i] != 3) {
			snprintf(why, cap, "subscribe: subscription %d lacks its id or channelId", i);
			return false;
		}
	return true;
}

bool fox_op_parse(const char *text, size_t len, struct fox_op *op, char *why, size_t cap)
{
	memset(op, 0, sizeof *op);
	struct fox_parse p = { .op = op };
	struct lejp_ctx ctx;
	lejp_construct(&ctx, fox_lejp_cb, &p, NULL, 0);
	int r = len > INT32_MAX ? LEJP_REJECT_UNKNOWN : lejp_parse(&ctx, (const unsigned char *)text, (int)len);
	lejp_destruct(&ctx);
	if (r < 0) {
		snprintf(why, cap, "not JSON: %s", r == LEJP_CONTINUE ? "it ends too soon" : lejp_error_to_string(r));
		return false;
	}
	/* what follows the object may only be white space */
	for (size_t i = len - (size_t)r; i < len; i++)
		if (strchr(" \t\r\n", text[i]) == NULL) {
			snprintf(why, cap, "not JSON: bytes after the object");
			return false;
		}
	return fox_op_check(&p, why, cap);
}
