/* cmdin.c — see cmdin.h. */
#include "cmdin.h"

#include <errno.h>
#include <inttypes.h>
#include <pwd.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "text.h"
#include "udpm.h"
#include "undulate_event_t.h"
#include "wire.h"

#define CIN_SHARED_CHANNEL "UNDULATE.CMD"
/* An answer on the local socket: an encoded event_t. */
#define CIN_ANSWER_MAX 1024

static int64_t cin_wall(const struct cin *in) { return in->hooks.wall_us(in->hooks.ctx); }
static uint64_t cin_mono(const struct cin *in) { return in->hooks.mono_us(in->hooks.ctx); }

/* The shared key, private to the user the daemon runs as (auth.h): one rule
 * for the start and for --check-config. */
static bool cin_key_load(struct auth_key *key, const struct cfg *cfg, uid_t as, char *why, size_t cap)
{
	char inner[256];
	if (auth_key_load_as(key, cfg->command_key, true, as, inner, sizeof inner))
		return true;
	snprintf(why, cap, "command_key: %s", inner);
	return false;
}

bool cin_check_key(const struct cfg *cfg, char *why, size_t cap, char *note, size_t note_cap)
{
	note[0] = '\0';
	if (cfg->commands != CFG_CMD_NETWORK)
		return true;
	uid_t as = geteuid();
	struct stat st;
	if (as == 0 && lstat(cfg->command_key, &st) == 0 && S_ISREG(st.st_mode) && st.st_uid != 0) {
		as = st.st_uid;
		const struct passwd *pw = getpwuid(as);
		snprintf(note, note_cap, "command_key: %s is owned by uid %u%s%s%s, not root: judged for a daemon that "
		         "runs as that user (User= in its unit)", cfg->command_key, (unsigned)as, pw ? " (" : "",
		         pw ? pw->pw_name : "", pw ? ")" : "");
	}
	struct auth_key key;
	bool ok = cin_key_load(&key, cfg, as, why, cap);
	memset(&key, 0, sizeof key);
	return ok;
}

bool cin_open(struct cin *in, const struct cfg *cfg, const struct ctl *ctl, const struct cin_hooks *hooks,
              int64_t fingerprint, char *why, size_t cap)
{
	memset(in, 0, sizeof *in);
	in->cfg = cfg;
	in->ctl = ctl;
	in->hooks = *hooks;
	in->fingerprint = fingerprint;
	in->local_fd = in->net_fd = -1;
	/* refused, from an authentic sender (local, or signed): 10 lines and 20
	 * events, then a line per 0.2 s and an event per 0.1 s, each with the
	 * count of those left out; refused unauthenticated network traffic: 5 of
	 * each, then one a second; accepted: more, as an operator's script may
	 * send bursts */
	in->lim_log_reject = (struct log_limit)LOG_LIMIT_INIT(10, 200000);
	in->lim_event_reject = (struct log_limit)LOG_LIMIT_INIT(20, 100000);
	in->lim_log_accept = (struct log_limit)LOG_LIMIT_INIT(20, 200000);
	in->lim_event_accept = (struct log_limit)LOG_LIMIT_INIT(50, 20000);
	in->lim_log_unauth = (struct log_limit)LOG_LIMIT_INIT(5, 1000000);
	in->lim_event_unauth = (struct log_limit)LOG_LIMIT_INIT(5, 1000000);
	snprintf(in->ch_cmd, sizeof in->ch_cmd, "%s.CMD", cfg->name);
	auth_replay_init(&in->replay, (int64_t)(cfg->command_window_s * 1e6), cin_wall(in));

	char dir[CSOCK_PATH_MAX], inner[256];
	if (!csock_daemon_dir(dir, sizeof dir, cfg->run_dir, inner, sizeof inner)) {
		snprintf(why, cap, "local command socket: %s", inner);
		return false;
	}
	if (!csock_path(in->local_path, sizeof in->local_path, dir, cfg->name, cfg->lcm_url)) {
		snprintf(why, cap, "local command socket: '%s/%s@...' does not fit a socket address (%d bytes): "
		         "a shorter run_dir or robot name", dir, cfg->name, CSOCK_PATH_MAX - 1);
		return false;
	}
	in->local_fd = csock_listen(in->local_path, inner, sizeof inner);
	if (in->local_fd < 0) {
		snprintf(why, cap, "local command socket: %s", inner);
		in->local_path[0] = '\0';
		return false;
	}
	if (cfg->commands != CFG_CMD_NETWORK)
		return true;
	if (!cin_key_load(&in->key, cfg, geteuid(), why, cap)) {
		cin_close(in);
		return false;
	}
	in->net_fd = udpm_open_recv(udpm_effective_url(cfg->lcm_url), inner, sizeof inner);
	if (in->net_fd < 0) {
		snprintf(why, cap, "commands = network: %s", inner);
		cin_close(in);
		return false;
	}
	return true;
}

void cin_close(struct cin *in)
{
	if (in->local_fd >= 0)
		csock_close(in->local_fd, in->local_path);
	if (in->net_fd >= 0)
		close(in->net_fd);
	in->local_fd = in->net_fd = -1;
	in->local_path[0] = '\0';
	memset(&in->key, 0, sizeof in->key);
}

int cin_local_fd(const struct cin *in) { return in->local_fd; }
int cin_net_fd(const struct cin *in) { return in->net_fd; }
const char *cin_local_path(const struct cin *in) { return in->local_path; }
size_t cin_pending(const struct cin *in) { return in->nq; }
long long cin_refused(const struct cin *in) { return in->rejected + in->unauthenticated + in->busy; }

/* ---- answers ------------------------------------------------------------------------------- */
static void cin_reply_local(struct cin *in, const struct cin_cmd *c, int level, const char *kind, const char *text)
{
	if (!c->local || in->local_fd < 0)
		return;
	char robot[CFG_NAME_MAX], kind_buf[32], text_buf[512];
	snprintf(robot, sizeof robot, "%s", in->cfg->name);
	snprintf(kind_buf, sizeof kind_buf, "%s", kind);
	snprintf(text_buf, sizeof text_buf, "%s", text);
	undulate_event_t e = {
		.utime = cin_wall(in), .robot = robot, .seq = c->w.req.seq, .level = (int8_t)level,
		.kind = kind_buf, .text = text_buf,
	};
	uint8_t buf[CIN_ANSWER_MAX];
	int n = undulate_event_t_encoded_size(&e);
	if (n > 0 && n <= (int)sizeof buf && undulate_event_t_encode(buf, 0, n, &e) == n)
		(void)csock_reply(in->local_fd, &c->peer, buf, (size_t)n);
}

/* A refusal: counted, answered to a local sender, logged and published
 * within the rate limits (a flood of bad commands must not become a flood
 * of lines and multicast events). */
static void cin_refuse_as(struct cin *in, const struct cin_cmd *c, const char *why, bool authentic)
{
	uint64_t now = cin_mono(in);
	cin_reply_local(in, c, 1, "command-rejected", why);
	log_limited(authentic ? &in->lim_log_reject : &in->lim_log_unauth, now, LOG_LVL_WARN,
	            "command %" PRId64 " from %s rejected: %s", c->w.req.seq, c->who, why);
	uint32_t dropped;
	if (log_limit_allow(authentic ? &in->lim_event_reject : &in->lim_event_unauth, now, &dropped)) {
		char text[400];
		if (dropped > 0)
			snprintf(text, sizeof text, "%s (and %u more refused since)", why, dropped);
		else
			snprintf(text, sizeof text, "%s", why);
		in->hooks.event(in->hooks.ctx, c->w.req.seq, 1, "command-rejected", text);
	}
}

/* From a sender whose identity is known (the local socket, a valid signature). */
static void cin_refuse(struct cin *in, const struct cin_cmd *c, const char *why)
{
	cin_refuse_as(in, c, why, true);
}

/* From the network, not (yet) authenticated. */
static void cin_refuse_unauth(struct cin *in, const struct cin_cmd *c, const char *why)
{
	in->unauthenticated++;
	cin_refuse_as(in, c, why, false);
}

static void cin_reject(struct cin *in, const struct cin_cmd *c, const char *why)
{
	in->rejected++;
	cin_refuse(in, c, why);
}

static void cin_accepted(struct cin *in, const struct cin_cmd *c, const char *what)
{
	uint64_t now = cin_mono(in);
	in->accepted++;
	cin_reply_local(in, c, 0, "command-accepted", what);
	log_limited(&in->lim_log_accept, now, LOG_LVL_INFO, "command %" PRId64 " from %s: %s", c->w.req.seq, c->who,
	            what);
	uint32_t dropped;
	if (log_limit_allow(&in->lim_event_accept, now, &dropped))
		in->hooks.event(in->hooks.ctx, c->w.req.seq, 0, "command-accepted", what);
}

/* ---- intake ----------------------------------------------------------------------------------- */
static void cin_who_local(struct cin_cmd *c)
{
	char source[48];
	text_sanitize(source, sizeof source, c->w.req.source);
	if (c->peer.cred)
		snprintf(c->who, sizeof c->who, "uid %u pid %d '%s'", (unsigned)c->peer.uid, (int)c->peer.pid, source);
	else
		snprintf(c->who, sizeof c->who, "local '%s'", source);
}

/* Validated: queued for the cycle boundary, or refused now. */
static void cin_take(struct cin *in, struct cin_cmd *c)
{
	char why[256];
	if (in->cfg->commands == CFG_CMD_OFF) {
		cin_reject(in, c, "commands are disabled in this robot's configuration (commands = off)");
		return;
	}
	enum cmd_verdict v = cmd_check_live(&c->w.req, in->cfg, in->ctl != NULL ? &in->ctl->p : NULL, c->direct, why,
	                                    sizeof why);
	if (v == CMD_IGNORE)
		return;
	if (v == CMD_REJECT) {
		cin_reject(in, c, why);
		return;
	}
	if (in->nq == CIN_QUEUE) {
		in->busy++;
		cin_refuse(in, c, "busy: too many commands within one control period; send fewer");
		return;
	}
	in->q[in->nq] = *c;
	cmd_wire_rebase(&in->q[in->nq].w);
	in->nq++;
}

void cin_local_datagram(struct cin *in, const uint8_t *d, size_t n, bool truncated, const struct csock_peer *peer)
{
	struct cin_cmd c = { .local = true, .direct = true, .peer = *peer };
	char why[160];
	in->received++;
	if (truncated) {
		snprintf(why, sizeof why, "a datagram longer than a command_t (more than %zu bytes)", sizeof in->buf);
		cin_who_local(&c);
		cin_reject(in, &c, why);
		return;
	}
	if (!cmd_decode(d, n, in->fingerprint, &c.w, why, sizeof why)) {
		cin_who_local(&c);
		char text[200];
		snprintf(text, sizeof text, "undecodable command_t (%zu bytes): %s", n, why);
		cin_reject(in, &c, text);
		return;
	}
	cin_who_local(&c);
	cin_take(in, &c);
}

void cin_clock_command(struct cin *in, const char *text)
{
	struct cin_cmd c = { .local = false, .direct = true };
	char why[256];
	in->received++;
	snprintf(c.who, sizeof c.who, "the lockstep clock (the simulator's schedule)");
	snprintf(c.w.source, sizeof c.w.source, "lockstep");
	snprintf(c.w.robot, sizeof c.w.robot, "%s", in->cfg->name);
	if (!cmd_parse_text(text, &c.w.req, c.w.param, sizeof c.w.param, why, sizeof why)) {
		cin_reject(in, &c, why);
		return;
	}
	c.w.req.source = c.w.source;
	c.w.req.robot = c.w.robot;
	c.w.req.utime = cin_wall(in);
	cin_take(in, &c);
}

/* A signed command from the network: authentic, fresh, never seen. */
static bool cin_authentic(struct cin *in, struct cin_cmd *c, const uint8_t *payload, char *why, size_t cap)
{
	const struct cmd_request *r = &c->w.req;
	if (!auth_mac_ok(&in->key, payload, c->w.signed_len, c->w.mac)) {
		snprintf(why, cap, "not signed with this robot's command key (unauthenticated commands from the "
		         "network are refused)");
		return false;
	}
	enum auth_fresh f = auth_replay_check(&in->replay, r->source, r->utime, r->seq, cin_wall(in));
	if (f != AUTH_FRESH) {
		snprintf(why, cap, "signed, but %s", auth_fresh_text(f));
		return false;
	}
	auth_replay_accept(&in->replay, r->source, r->utime, r->seq);
	return true;
}

void cin_network_datagram(struct cin *in, const uint8_t *d, size_t n, bool truncated)
{
	struct wire_udpm m;
	const char *bad;
	/* the group carries every robot's state: only our command channels count,
	 * and a datagram that is not LCM at all is not ours to judge */
	if (!wire_udpm_parse(d, n, &m, &bad))
		return;
	bool direct = strcmp(m.channel, in->ch_cmd) == 0;
	if (!direct && strcmp(m.channel, CIN_SHARED_CHANNEL) != 0)
		return;
	in->received++;
	struct cin_cmd c = { .local = false, .direct = direct };
	char why[256];
	if (truncated) {
		snprintf(c.who, sizeof c.who, "the network");
		cin_refuse_unauth(in, &c, "a datagram on a command channel longer than any command_t: not read");
		return;
	}
	if (!cmd_decode(m.payload, m.payload_len, in->fingerprint, &c.w, why, sizeof why)) {
		snprintf(c.who, sizeof c.who, "the network");
		char text[400];
		snprintf(text, sizeof text, "undecodable command_t on %s (%zu bytes): %s", direct ? in->ch_cmd
		         : CIN_SHARED_CHANNEL, m.payload_len, why);
		cin_refuse_unauth(in, &c, text);
		return;
	}
	char source[48];
	snprintf(c.who, sizeof c.who, "the network '%s'", text_sanitize(source, sizeof source, c.w.req.source));
	/* not ours (another robot's name on the shared channel): not ours to
	 * judge either, signed or not */
	if (!direct && strcmp(c.w.req.robot, "*") != 0 && strcmp(c.w.req.robot, in->cfg->name) != 0)
		return;
	if (!cin_authentic(in, &c, m.payload, why, sizeof why)) {
		cin_refuse_unauth(in, &c, why);
		return;
	}
	cin_take(in, &c);
}

void cin_on_local(struct cin *in)
{
	for (int i = 0; i < CIN_BURST && in->local_fd >= 0; i++) {
		struct csock_peer peer;
		bool truncated = false;
		ssize_t n = csock_recv(in->local_fd, in->buf, sizeof in->buf, &peer, &truncated);
		if (n <= 0)
			return;
		cin_local_datagram(in, in->buf, (size_t)n, truncated, &peer);
	}
}

void cin_on_network(struct cin *in)
{
	for (int i = 0; i < CIN_BURST && in->net_fd >= 0; i++) {
		ssize_t n = recv(in->net_fd, in->buf, sizeof in->buf, MSG_DONTWAIT | MSG_TRUNC);
		if (n < 0)
			return;
		/* longer than the buffer (MSG_TRUNC gives the real length): its channel
		 * is in what was read, the rest is no command */
		bool truncated = (size_t)n > sizeof in->buf;
		cin_network_datagram(in, in->buf, truncated ? sizeof in->buf : (size_t)n, truncated);
	}
}

/* ---- the cycle boundary ------------------------------------------------------------------------ */
static bool cin_apply_one(struct cin_cmd *c, struct ctl *ctl, char *text, size_t cap)
{
	const struct cmd_request *r = &c->w.req;
	char reason[sizeof ctl->reason];
	/* an earlier command of this batch may have changed what is valid */
	if (cmd_check_live(r, ctl->cfg, &ctl->p, c->direct, text, cap) != CMD_ACCEPT)
		return false;
	switch (r->kind) {
	case CMD_KIND_MODE:
		if (!ctl_mode_allowed(ctl, (enum cfg_mode)r->mode, text, cap))
			return false;
		snprintf(reason, sizeof reason, "command from %.80s", c->who);
		ctl_set_mode(ctl, (enum cfg_mode)r->mode, reason);
		break;
	case CMD_KIND_TORQUE:
		if (r->torque && ctl->mode == CFG_MODE_LIMP && !ctl_mode_allowed(ctl, CFG_MODE_HOLD, text, cap))
			return false;
		ctl_torque(ctl, r->torque);
		break;
	case CMD_KIND_CLEAR:
		if (!ctl_clear_faults(ctl, text, cap))
			return false;
		break;
	case CMD_KIND_PARAM:
		if (!ctl_set_param(ctl, r->param, r->joint, r->value, text, cap))
			return false;
		break;
	}
	cmd_describe(r, text, cap);
	return true;
}

void cin_apply(struct cin *in, struct ctl *ctl)
{
	for (size_t i = 0; i < in->nq; i++) {
		struct cin_cmd *c = &in->q[i];
		char text[256];
		if (cin_apply_one(c, ctl, text, sizeof text))
			cin_accepted(in, c, text);
		else
			cin_reject(in, c, text);
	}
	in->nq = 0;
}
