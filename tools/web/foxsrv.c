/* foxsrv.c — see foxsrv.h. */
#include "foxsrv.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"
#include "server.h"

struct foxsrv_chan {
	bool used;
	uint32_t id;                /* never reused: a client's old subscription cannot reach a new channel */
	char topic[FOXSRV_TOPIC_MAX];
	const struct fox_type *type;
	double heard;
};

static struct {
	struct foxsrv_chan chan[FOXSRV_CHANNELS];
	uint32_t next_id;
	struct fox_client *clients[WEB_MAX_CLIENTS];
	int nclients;
	unsigned char *msg;         /* FOX_DATA_HEADER + FOXSRV_MSG_MAX: one message's frame */
	unsigned char *out;         /* LWS_PRE + FOXSRV_SEND_MAX: what goes to a socket */
	char *schema;               /* FOXSRV_MSG_MAX: one schema's text */
	struct foxsrv_counters n;
} fs;

#define FOXSRV_OUT_MAX (FOX_DATA_HEADER + FOXSRV_MSG_MAX)
/* one send: a batch, or one message larger than a batch with its frame header */
#define FOXSRV_SEND_MAX (FOX_WS_HEADER_MAX + FOXSRV_OUT_MAX)

bool foxsrv_init(void)
{
	fs.msg = malloc(FOXSRV_OUT_MAX);
	fs.out = malloc(LWS_PRE + FOXSRV_SEND_MAX);
	fs.schema = malloc(FOXSRV_MSG_MAX);
	return fs.msg != NULL && fs.out != NULL && fs.schema != NULL;
}

void foxsrv_fini(void)
{
	free(fs.msg);
	free(fs.out);
	free(fs.schema);
}

const struct foxsrv_counters *foxsrv_counters(void)
{
	return &fs.n;
}

static void foxsrv_wake_all(void)
{
	for (int i = 0; i < fs.nclients; i++)
		lws_callback_on_writable(fs.clients[i]->wsi);
}

/* ---- channels ------------------------------------------------------------------------ */

/* A name as Foxglove shows it: printable ASCII, no space (LCM allows any byte). */
static bool foxsrv_topic_ok(const char *s)
{
	size_t n = strlen(s);
	if (n == 0 || n >= FOXSRV_TOPIC_MAX)
		return false;
	for (size_t i = 0; i < n; i++)
		if ((unsigned char)s[i] <= ' ' || (unsigned char)s[i] >= 0x7f)
			return false;
	return true;
}

static struct foxsrv_chan *foxsrv_chan_of(const char *topic)
{
	for (int i = 0; i < FOXSRV_CHANNELS; i++)
		if (fs.chan[i].used && strcmp(fs.chan[i].topic, topic) == 0)
			return &fs.chan[i];
	return NULL;
}

static struct foxsrv_chan *foxsrv_chan_add(const char *topic, const struct fox_type *t, double now)
{
	if (!foxsrv_topic_ok(topic)) {
		fs.n.channels_refused++;
		return NULL;
	}
	for (int i = 0; i < FOXSRV_CHANNELS; i++) {
		struct foxsrv_chan *c = &fs.chan[i];
		if (c->used)
			continue;
		*c = (struct foxsrv_chan){ .used = true, .id = ++fs.next_id, .type = t, .heard = now };
		snprintf(c->topic, sizeof c->topic, "%s", topic);
		foxsrv_wake_all(); /* to be advertised */
		return c;
	}
	fs.n.channels_refused++;
	return NULL;
}

static bool foxsrv_chan_live(uint32_t id)
{
	for (int i = 0; i < FOXSRV_CHANNELS; i++)
		if (fs.chan[i].used && fs.chan[i].id == id)
			return true;
	return false;
}

static void foxsrv_drop_subs_of(uint32_t channel)
{
	for (int i = 0; i < fs.nclients; i++) {
		struct fox_client *c = fs.clients[i];
		for (int k = 0; k < c->nsubs;)
			if (c->subs[k].channel == channel)
				c->subs[k] = c->subs[--c->nsubs];
			else
				k++;
	}
}

/* ---- queues --------------------------------------------------------------------------- */

static size_t foxsrv_queued(const struct fox_client *c)
{
	return c->qtail - c->qhead;
}

static void foxsrv_enqueue(struct fox_client *c, const unsigned char *frame, size_t len)
{
	uint32_t n = (uint32_t)len;
	if (c->qtail + sizeof n + len > FOXSRV_QUEUE && c->qhead > 0) {
		memmove(c->queue, c->queue + c->qhead, foxsrv_queued(c));
		c->qtail -= c->qhead;
		c->qhead = 0;
	}
	if (c->qtail + sizeof n + len > FOXSRV_QUEUE) {
		fs.n.dropped++;
		return;
	}
	memcpy(c->queue + c->qtail, &n, sizeof n);
	memcpy(c->queue + c->qtail + sizeof n, frame, len);
	c->qtail += sizeof n + len;
	lws_callback_on_writable(c->wsi);
}

/* The message as JSON after its header's room; 0 if it does not decode or fit. */
static size_t foxsrv_encode(const struct fox_type *t, const void *data, size_t len)
{
	static union lcmdec_any u;
	if (t->size > sizeof u || lcmdec_decode(t->dec, data, len, &u) != LCMDEC_OK)
		return 0; /* the monitors' model counts and says what does not decode */
	size_t n = fox_encode_buf(t, &u, (char *)fs.msg + FOX_DATA_HEADER, FOXSRV_MSG_MAX);
	lcmdec_free(t->dec, &u);
	if (n == 0)
		fs.n.too_large++;
	return n;
}

void foxsrv_heard(const char *channel, const void *data, size_t len, uint64_t wall_ns, double now)
{
	const struct fox_type *t = fox_kind_of(channel);
	if (t == NULL)
		return;
	struct foxsrv_chan *ch = foxsrv_chan_of(channel);
	if (ch == NULL && (ch = foxsrv_chan_add(channel, t, now)) == NULL)
		return;
	ch->heard = now;
	size_t n = 0;
	bool encoded = false;
	for (int i = 0; i < fs.nclients; i++) {
		struct fox_client *c = fs.clients[i];
		for (int k = 0; k < c->nsubs; k++) {
			if (c->subs[k].channel != ch->id)
				continue;
			if (!encoded) { /* once, for every subscription to it */
				encoded = true;
				if ((n = foxsrv_encode(t, data, len)) == 0)
					return;
			}
			fox_data_header(fs.msg, c->subs[k].id, wall_ns);
			foxsrv_enqueue(c, fs.msg, FOX_DATA_HEADER + n);
		}
	}
}

/* ---- clients --------------------------------------------------------------------------- */

bool foxsrv_open(struct fox_client *c, struct lws *wsi, unsigned id, double now)
{
	memset(c, 0, sizeof *c);
	c->wsi = wsi;
	c->id = id;
	c->last_write = now;
	c->queue = malloc(FOXSRV_QUEUE);
	if (c->queue == NULL || fs.nclients >= WEB_MAX_CLIENTS) {
		free(c->queue);
		c->queue = NULL;
		return false;
	}
	fs.clients[fs.nclients++] = c;
	fs.n.clients = fs.nclients;
	lws_callback_on_writable(wsi);
	return true;
}

void foxsrv_close(struct fox_client *c)
{
	for (int i = 0; i < fs.nclients; i++)
		if (fs.clients[i] == c) {
			fs.clients[i] = fs.clients[--fs.nclients];
			break;
		}
	fs.n.clients = fs.nclients;
	free(c->queue);
	c->queue = NULL;
}

/* A status for the client (level 2, error) and the same words for the log. */
static void foxsrv_refuse(struct fox_client *c, char *why, size_t cap, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(why, cap, fmt, ap);
	va_end(ap);
	fs.n.refused++;
	if (c->nstatus == FOXSRV_STATUS) {
		memmove(c->status, c->status + 1, sizeof c->status[0] * (FOXSRV_STATUS - 1));
		c->nstatus--;
	}
	snprintf(c->status[c->nstatus++], FOXSRV_STATUS_TEXT, "%s", why);
	lws_callback_on_writable(c->wsi);
}

static int foxsrv_sub_index(const struct fox_client *c, uint32_t id)
{
	for (int k = 0; k < c->nsubs; k++)
		if (c->subs[k].id == id)
			return k;
	return -1;
}

/* Each item taken or refused; one status says the first refusal and how many. */
static void foxsrv_subscribe(struct fox_client *c, const struct fox_op *op, char *why, size_t cap)
{
	char first[FOXSRV_STATUS_TEXT] = "";
	int refused = 0;
	for (int i = 0; i < op->n; i++) {
		const struct fox_sub_item *s = &op->subs[i];
		const char *no = NULL;
		if (!foxsrv_chan_live(s->channel))
			no = "no such channel (not advertised, or unadvertised since)";
		else if (foxsrv_sub_index(c, s->id) >= 0)
			no = "this subscription id is in use";
		else if (c->nsubs >= FOX_OP_ITEMS)
			no = "a client holds at most 64 subscriptions";
		if (no == NULL) {
			c->subs[c->nsubs++] = (struct foxsrv_sub){ .id = s->id, .channel = s->channel };
			continue;
		}
		if (refused++ == 0)
			snprintf(first, sizeof first, "subscription %u to channel %u: %s", s->id, s->channel, no);
	}
	if (refused > 0)
		foxsrv_refuse(c, why, cap, "subscribe: %s%s", first, refused > 1 ? " (and others)" : "");
}

static void foxsrv_unsubscribe(struct fox_client *c, const struct fox_op *op, char *why, size_t cap)
{
	int refused = 0;
	uint32_t first = 0;
	for (int i = 0; i < op->n; i++) {
		int k = foxsrv_sub_index(c, op->unsubs[i]);
		if (k >= 0) {
			c->subs[k] = c->subs[--c->nsubs];
		} else if (refused++ == 0) {
			first = op->unsubs[i];
		}
	}
	if (refused > 0)
		foxsrv_refuse(c, why, cap, "unsubscribe: no subscription %u%s", first, refused > 1 ? " (and others)" : "");
}

void foxsrv_receive(struct fox_client *c, const char *in, size_t len, bool binary, bool first, bool last,
                    char *why, size_t cap)
{
	why[0] = '\0';
	if (c->dropping || !first || !last) {
		/* longer than FOXSRV_OP_MAX: libwebsockets hands it over in pieces */
		if (first)
			foxsrv_refuse(c, why, cap, "message longer than %d bytes: refused", FOXSRV_OP_MAX);
		c->dropping = !last;
		return;
	}
	if (binary) {
		foxsrv_refuse(c, why, cap, "read-only: undulate-web takes no client messages or service calls "
		              "(binary opcode %d refused; no clientPublish)", len > 0 ? (unsigned char)in[0] : -1);
		return;
	}
	static struct fox_op op;
	char bad[FOXSRV_STATUS_TEXT];
	if (!fox_op_parse(in, len, &op, bad, sizeof bad)) {
		foxsrv_refuse(c, why, cap, "%s", bad);
		return;
	}
	if (op.kind == FOX_OP_SUBSCRIBE)
		foxsrv_subscribe(c, &op, why, cap);
	else if (op.kind == FOX_OP_UNSUBSCRIBE)
		foxsrv_unsubscribe(c, &op, why, cap);
	else
		foxsrv_refuse(c, why, cap, "op \"%s\" is not served: undulate-web is read-only (no clientPublish, "
		              "parameters, services or assets); it takes subscribe and unsubscribe", op.name);
}

/* ---- what goes out ------------------------------------------------------------------------ */

/* A JSON text written by fn into the output buffer, sent as one text message. */
static int foxsrv_send_text(struct fox_client *c, void (*fn)(struct json *, struct fox_client *))
{
	struct json j;
	json_init_buf(&j, (char *)fs.out + LWS_PRE, FOXSRV_OUT_MAX, 0);
	fn(&j, c);
	if (!json_end(&j))
		return -1;
	size_t n = json_len(&j);
	return lws_write(c->wsi, fs.out + LWS_PRE, n, LWS_WRITE_TEXT) < (int)n ? -1 : 0;
}

static void foxsrv_server_info(struct json *j, struct fox_client *c)
{
	(void)c;
	json_object_begin(j);
	json_field_string(j, "op", "serverInfo");
	json_field_string(j, "name", "undulate-web (read-only)");
	json_key(j, "capabilities");
	json_array_begin(j); /* none: no clientPublish, parameters, services, time or assets */
	json_array_end(j);
	json_key(j, "supportedEncodings");
	json_array_begin(j);
	json_array_end(j);
	json_key(j, "metadata");
	json_object_begin(j);
	json_field_string(j, "lcm", "one channel per LCM channel heard, its message as JSON");
	json_object_end(j);
	json_object_end(j);
}

/* the slots whose advertised id is no longer there */
static bool foxsrv_stale(const struct fox_client *c, int slot)
{
	return c->advertised[slot] != 0 && (!fs.chan[slot].used || fs.chan[slot].id != c->advertised[slot]);
}

static bool foxsrv_new(const struct fox_client *c, int slot)
{
	return fs.chan[slot].used && c->advertised[slot] != fs.chan[slot].id && !foxsrv_stale(c, slot);
}

static void foxsrv_unadvertise(struct json *j, struct fox_client *c)
{
	json_object_begin(j);
	json_field_string(j, "op", "unadvertise");
	json_key(j, "channelIds");
	json_array_begin(j);
	for (int i = 0; i < FOXSRV_CHANNELS; i++)
		if (foxsrv_stale(c, i)) {
			json_int(j, c->advertised[i]);
			c->advertised[i] = 0;
		}
	json_array_end(j);
	json_object_end(j);
}

static void foxsrv_channel(struct json *j, const struct foxsrv_chan *ch)
{
	FILE *f = fmemopen(fs.schema, FOXSRV_MSG_MAX, "w");
	bool ok = f != NULL && fox_schema(ch->type, f) && fputc('\0', f) != EOF;
	if (f != NULL && fclose(f) != 0)
		ok = false;
	json_object_begin(j);
	json_field_int(j, "id", ch->id);
	json_field_string(j, "topic", ch->topic);
	json_field_string(j, "encoding", "json");
	json_field_string(j, "schemaName", ch->type->name);
	json_field_string(j, "schema", ok ? fs.schema : "{}");
	json_field_string(j, "schemaEncoding", "jsonschema");
	json_object_end(j);
}

static void foxsrv_advertise(struct json *j, struct fox_client *c)
{
	json_object_begin(j);
	json_field_string(j, "op", "advertise");
	json_key(j, "channels");
	json_array_begin(j);
	for (int i = 0, n = 0; i < FOXSRV_CHANNELS && n < FOXSRV_ADVERTISE_BATCH; i++)
		if (foxsrv_new(c, i)) {
			foxsrv_channel(j, &fs.chan[i]);
			c->advertised[i] = fs.chan[i].id;
			n++;
		}
	json_array_end(j);
	json_object_end(j);
}

static void foxsrv_status(struct json *j, struct fox_client *c)
{
	json_object_begin(j);
	json_field_string(j, "op", "status");
	json_field_int(j, "level", 2);
	json_field_string(j, "message", c->status[0]);
	json_object_end(j);
	memmove(c->status, c->status + 1, sizeof c->status[0] * (FOXSRV_STATUS - 1));
	c->nstatus--;
}

static bool foxsrv_any(const struct fox_client *c, bool (*pred)(const struct fox_client *, int))
{
	for (int i = 0; i < FOXSRV_CHANNELS; i++)
		if (pred(c, i))
			return true;
	return false;
}

/* The queued messages, oldest first, as WebSocket frames in one buffer, up
 * to FOXSRV_BATCH bytes (at least one message, however large), handed to
 * libwebsockets as raw bytes: one send and one writeable callback for what
 * came in since the last, not one each (perf: at 2100 messages a second,
 * the send, the poll and the callback per message were a quarter of the
 * server's time). What the socket does not take at once libwebsockets keeps
 * and sends first, as it does for a single lws_write. No extension is ever
 * negotiated (the context offers none), so a frame is header and payload. */
static int foxsrv_send_data(struct fox_client *c)
{
	unsigned char *out = fs.out + LWS_PRE;
	size_t len = 0;
	while (foxsrv_queued(c) > 0) {
		uint32_t n;
		memcpy(&n, c->queue + c->qhead, sizeof n);
		unsigned char head[FOX_WS_HEADER_MAX];
		size_t h = fox_ws_header(head, n);
		if (len > 0 && len + h + n > FOXSRV_BATCH)
			break;
		memcpy(out + len, head, h);
		memcpy(out + len + h, c->queue + c->qhead + sizeof n, n);
		len += h + n;
		c->qhead += sizeof n + n;
		fs.n.sent++;
	}
	if (c->qhead == c->qtail)
		c->qhead = c->qtail = 0;
	fs.n.batches++;
	return lws_write(c->wsi, out, len, LWS_WRITE_RAW) < (int)len ? -1 : 0;
}

int foxsrv_write(struct fox_client *c, double now)
{
	int r = 0;
	if (!c->info_sent) {
		c->info_sent = true;
		r = foxsrv_send_text(c, foxsrv_server_info);
	} else if (foxsrv_any(c, foxsrv_stale)) {
		r = foxsrv_send_text(c, foxsrv_unadvertise);
	} else if (foxsrv_any(c, foxsrv_new)) {
		r = foxsrv_send_text(c, foxsrv_advertise);
	} else if (c->nstatus > 0) {
		r = foxsrv_send_text(c, foxsrv_status);
	} else if (foxsrv_queued(c) > 0) {
		r = foxsrv_send_data(c);
	} else {
		return 0; /* libwebsockets may call again with nothing due */
	}
	c->last_write = now;
	if (foxsrv_any(c, foxsrv_stale) || foxsrv_any(c, foxsrv_new) || c->nstatus > 0 || foxsrv_queued(c) > 0)
		lws_callback_on_writable(c->wsi);
	return r;
}

void foxsrv_tick(double now)
{
	for (int i = 0; i < FOXSRV_CHANNELS; i++) {
		struct foxsrv_chan *ch = &fs.chan[i];
		if (!ch->used || now - ch->heard < FOXSRV_QUIET_S)
			continue;
		ch->used = false;
		foxsrv_drop_subs_of(ch->id);
		foxsrv_wake_all();
	}
	for (int i = 0; i < fs.nclients; i++) {
		struct fox_client *c = fs.clients[i];
		if (c->gone || foxsrv_queued(c) == 0 || now - c->last_write < FOXSRV_STALL_S)
			continue;
		c->gone = true;
		fs.n.stalled++;
		lws_set_timeout(c->wsi, PENDING_TIMEOUT_USER_OK, LWS_TO_KILL_ASYNC);
	}
}
