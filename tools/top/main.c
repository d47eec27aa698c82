/* undulate-top — live monitor of every robot on the LCM network.
 * See tools/top/README.md. */
#include "clock.h"
#include "csock.h"
#include "keys.h"
#include "model.h"
#include "modes.h"
#include "num.h"
#include "render.h"
#include "term.h"

#include <errno.h>
#include <getopt.h>
#include <lcm/lcm.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#define TOP_FRAME_S 0.1            /* screen refresh: 10 Hz */
#define TOP_SCREEN_MAX (256 * 1024) /* one frame of a large terminal, escapes included */
#define TOP_PAGE_ROBOTS 10          /* PgUp/PgDn step */
#define TOP_MAX_KEYS_PER_READ 64

struct top_app {
	lcm_t *lcm;
	int cmd_fd;                 /* our end of the robots' local command sockets (-1: none) */
	struct top_model model;
	struct top_view view;
	bool once, json, read_only, verbose;
	double wait_s, interval_s;
	const char *url;
	int64_t first_seq, next_seq;
	char source[64];
	char *screen;
	struct top_keyparser kp;
	bool quit;
	int rows, cols;
};

static volatile sig_atomic_t top_signal;
static volatile sig_atomic_t top_winch;

static void on_signal(int sig)
{
	top_signal = sig;
}

static void on_winch(int sig)
{
	(void)sig;
	top_winch = 1;
}


/* The status line (answers to commands, what was sent, why not). Long
 * texts are cut: the line is as wide as the screen anyway. */
static void set_status(struct top_app *a, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(a->view.status, sizeof(a->view.status), fmt, ap);
	va_end(ap);
}

/* ---- LCM ------------------------------------------------------------------------ */

static bool ends_with(const char *s, const char *suffix)
{
	size_t n = strlen(s), m = strlen(suffix);
	return n > m && strcmp(s + n - m, suffix) == 0;
}

static void show_event(struct top_app *a, const undulate_event_t *e)
{
	if (e->seq >= a->first_seq && e->seq < a->next_seq)
		set_status(a, "#%lld %s: %s: %s", (long long)e->seq, e->robot,
			 e->kind, e->text);
}

/* Decodes BUF as T into a local, runs STMT with `msg`, cleans up. */
#define TOP_DECODE(T, stmt)                                                          \
	do {                                                                         \
		undulate_##T msg;                                                    \
		if (undulate_##T##_decode(rbuf->data, 0, (int)rbuf->data_size, &msg) < 0) { \
			a->model.decode_errors++;                                    \
			return;                                                      \
		}                                                                    \
		stmt;                                                                \
		undulate_##T##_decode_cleanup(&msg);                                 \
	} while (0)

static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
	struct top_app *a = user;
	double now = clock_mono_s();
	if (strcmp(channel, "SIM.TRUTH") == 0)
		TOP_DECODE(sim_truth_t, top_on_truth(&a->model, &msg, now));
	else if (strcmp(channel, "SIM.COLLISION") == 0)
		TOP_DECODE(sim_collision_t, top_on_sim_collision(&a->model, &msg, now));
	else if (ends_with(channel, ".STATE"))
		TOP_DECODE(robot_state_t, top_on_state(&a->model, &msg, now));
	else if (ends_with(channel, ".BUS"))
		TOP_DECODE(bus_stats_t, top_on_bus(&a->model, &msg));
	else if (ends_with(channel, ".PARAMS"))
		TOP_DECODE(osc_params_t, top_on_params(&a->model, &msg));
	else if (ends_with(channel, ".EVENT"))
		TOP_DECODE(event_t, (top_on_event(&a->model, &msg), show_event(a, &msg)));
}

static int top_subscribe(struct top_app *a)
{
	static const char *const channels[] = { ".*\\.STATE", ".*\\.BUS", ".*\\.PARAMS", ".*\\.EVENT",
						"SIM\\.TRUTH", "SIM\\.COLLISION" };
	for (size_t i = 0; i < sizeof(channels) / sizeof(channels[0]); i++)
		if (!lcm_subscribe(a->lcm, channels[i], on_message, a))
			return -1;
	return 0;
}

/* ---- commands ------------------------------------------------------------------- */

/* Commands go to the robots' local command sockets on this computer (never
 * over the network: a robot takes those only signed); the answers come back
 * on ours and show in the status line. */
#define TOP_MAX_SOCKETS 64
static bool publish(struct top_app *a, const struct top_command *c)
{
	static char paths[TOP_MAX_SOCKETS][CSOCK_PATH_MAX];
	uint8_t buf[1024];
	char why[256];
	int n = undulate_command_t_encoded_size(&c->msg);
	if (a->cmd_fd < 0 || n <= 0 || n > (int)sizeof(buf) || undulate_command_t_encode(buf, 0, n, &c->msg) != n) {
		set_status(a, "cannot send commands (%s)", a->cmd_fd < 0 ? "no local socket" : "encoding failed");
		return false;
	}
	size_t np = csock_find(c->msg.robot, a->url, paths, TOP_MAX_SOCKETS);
	if (np == 0) {
		set_status(a, "no robot %s runs on this computer: commands go to local robots only",
			   strcmp(c->msg.robot, "*") == 0 ? "at all" : c->msg.robot);
		return false;
	}
	size_t sent = 0;
	for (size_t i = 0; i < np; i++) {
		if (csock_send(a->cmd_fd, paths[i], buf, (size_t)n, why, sizeof(why)))
			sent++;
		else
			set_status(a, "%s", why);
	}
	return sent > 0;
}

static void read_answers(struct top_app *a)
{
	uint8_t buf[2048];
	for (int i = 0; i < 64; i++) {
		ssize_t n = recv(a->cmd_fd, buf, sizeof(buf), MSG_DONTWAIT);
		if (n <= 0)
			return;
		undulate_event_t e;
		if (undulate_event_t_decode(buf, 0, (int)n, &e) != (int)n)
			continue;
		top_on_event(&a->model, &e);
		show_event(a, &e);
		undulate_event_t_decode_cleanup(&e);
	}
}

static void send_mode(struct top_app *a, int mode, bool all)
{
	const struct top_model *m = &a->model;
	if (!all && m->nrobots == 0)
		return;
	const char *robot = all ? "*" : m->robots[m->order[a->view.selected]].name;
	struct top_command c;
	if (top_command_mode(&c, robot, mode, a->next_seq, a->source) != 0)
		return;
	if (publish(a, &c))
		set_status(a, "#%lld sent %s mode %s, waiting for the answer", (long long)a->next_seq,
			   all ? "all robots" : robot, mode_name(mode));
	a->next_seq++;
}

static void send_nudge(struct top_app *a, int dir)
{
	const struct top_model *m = &a->model;
	if (m->nrobots == 0)
		return;
	const struct top_robot *r = &m->robots[m->order[a->view.selected]];
	struct top_command c[TOP_MAX_JOINTS];
	char what[TOP_STATUS_MAX];
	int n = top_command_nudge(c, r, dir, a->next_seq, a->source, what, sizeof(what));
	if (n < 0) {
		set_status(a, "%s", what);
		return;
	}
	bool ok = true;
	for (int i = 0; i < n; i++)
		ok = publish(a, &c[i]) && ok;
	if (ok)
		set_status(a, "#%lld sent %s", (long long)a->next_seq, what);
	a->next_seq += n;
}

/* ---- keys ----------------------------------------------------------------------- */

static int mode_of_key(int ch)
{
	switch (ch | 0x20) { /* lower case */
	case 'l': return MODE_LIMP;
	case 'h': return MODE_HOLD;
	case 's': return MODE_SINUSOID;
	case 'o': return MODE_OSCILLATOR;
	default: return -1;
	}
}

static void on_char(struct top_app *a, int ch)
{
	if (ch == 'q' || ch == 'Q' || ch == 3 /* Ctrl-C */ || ch == 4 /* Ctrl-D */) {
		a->quit = true;
	} else if (ch >= '1' && ch <= '9') {
		a->view.selected = ch - '1';
		top_view_move(&a->view, &a->model, 0);
	} else if (ch == 'k' || ch == 'j') {
		top_view_move(&a->view, &a->model, ch == 'k' ? -1 : 1);
	} else if (ch == 'v') {
		a->view.kind = (enum top_view_kind)((a->view.kind + 1) % 3);
		set_status(a, "view: %s",
			 a->view.kind == TOP_VIEW_AUTO ? "auto" : a->view.kind == TOP_VIEW_DETAIL ? "detail" : "compact");
	} else if (mode_of_key(ch) >= 0 || ch == '+' || ch == '=' || ch == '-') {
		if (a->read_only)
			set_status(a, "read-only: commands are disabled");
		else if (mode_of_key(ch) >= 0)
			send_mode(a, mode_of_key(ch), ch >= 'A' && ch <= 'Z');
		else
			send_nudge(a, ch == '-' ? -1 : 1);
	}
}

static void read_keys(struct top_app *a)
{
	unsigned char buf[TOP_MAX_KEYS_PER_READ];
	ssize_t n = read(STDIN_FILENO, buf, sizeof(buf));
	for (ssize_t i = 0; i < n; i++) {
		int ch = 0;
		switch (top_key_feed(&a->kp, buf[i], &ch)) {
		case TOP_KEY_UP: top_view_move(&a->view, &a->model, -1); break;
		case TOP_KEY_DOWN: top_view_move(&a->view, &a->model, 1); break;
		case TOP_KEY_PGUP: top_view_move(&a->view, &a->model, -TOP_PAGE_ROBOTS); break;
		case TOP_KEY_PGDN: top_view_move(&a->view, &a->model, TOP_PAGE_ROBOTS); break;
		case TOP_KEY_HOME: top_view_move(&a->view, &a->model, -TOP_MAX_ROBOTS); break;
		case TOP_KEY_END: top_view_move(&a->view, &a->model, TOP_MAX_ROBOTS); break;
		case TOP_KEY_CHAR: on_char(a, ch); break;
		case TOP_KEY_NONE: break;
		}
	}
}

/* ---- output --------------------------------------------------------------------- */

static void draw(struct top_app *a, double now)
{
	time_t t = time(NULL);
	struct tm tm;
	localtime_r(&t, &tm);
	strftime(a->view.clock, sizeof(a->view.clock), "%H:%M:%S", &tm);
	size_t n = top_render(&a->model, &a->view, now, a->rows, a->cols, true, a->screen, TOP_SCREEN_MAX);
	ssize_t off = 0;
	while ((size_t)off < n) {
		ssize_t w = write(STDOUT_FILENO, a->screen + off, n - (size_t)off);
		if (w < 0 && errno == EINTR)
			continue;
		if (w <= 0)
			break;
		off += w;
	}
}

/* Returns -1 once stdout is gone (e.g. `| head` exited). */
static int print_snapshot(struct top_app *a, double now)
{
	if (a->json) {
		top_json(&a->model, now, clock_wall_us(), stdout);
	} else {
		a->view.clock[0] = '\0';
		top_render(&a->model, &a->view, now, 0, 0, false, a->screen, TOP_SCREEN_MAX);
		fputs(a->screen, stdout);
	}
	return fflush(stdout) == 0 && !ferror(stdout) ? 0 : -1;
}

/* ---- loop ----------------------------------------------------------------------- */

/* Waits for LCM traffic and keys until TIMEOUT_S has passed. */
static void pump(struct top_app *a, double timeout_s, bool keys)
{
	struct pollfd fds[3] = { { .fd = lcm_get_fileno(a->lcm), .events = POLLIN },
				 { .fd = a->cmd_fd, .events = POLLIN },
				 { .fd = STDIN_FILENO, .events = POLLIN } };
	int ms = timeout_s > 0 ? (int)ceil(timeout_s * 1000.0) : 0;
	int n = poll(fds, keys ? 3 : 2, ms);
	if (n <= 0)
		return; /* timeout, or EINTR from a signal checked by the caller */
	if (fds[0].revents & POLLIN)
		lcm_handle(a->lcm);
	if (fds[1].revents & POLLIN)
		read_answers(a);
	if (keys && (fds[2].revents & (POLLIN | POLLHUP)))
		read_keys(a);
}

static int run_once(struct top_app *a)
{
	double end = clock_mono_s() + a->wait_s;
	for (double now = clock_mono_s(); now < end && !top_signal; now = clock_mono_s())
		pump(a, end - now, false);
	return print_snapshot(a, clock_mono_s()) == 0 ? 0 : 1;
}

static int run_stream(struct top_app *a)
{
	double next = clock_mono_s() + a->interval_s;
	while (!top_signal) {
		double now = clock_mono_s();
		if (now >= next) {
			if (print_snapshot(a, now) != 0)
				break;
			next += a->interval_s;
			continue;
		}
		pump(a, next - now, false);
	}
	return 0;
}

static int run_interactive(struct top_app *a)
{
	if (term_enter() != 0) {
		fputs("undulate-top: stdin/stdout is not a terminal; use --once or --json\n", stderr);
		return 1;
	}
	atexit(term_leave);
	term_size(&a->rows, &a->cols);
	double next = clock_mono_s();
	while (!a->quit && !top_signal) {
		if (top_winch) {
			top_winch = 0;
			term_size(&a->rows, &a->cols);
			next = 0;
		}
		double now = clock_mono_s();
		if (now >= next) {
			draw(a, now);
			next = now + TOP_FRAME_S;
		}
		pump(a, next - now, true);
	}
	term_leave();
	return 0;
}

/* ---- options -------------------------------------------------------------------- */

static void usage(FILE *f)
{
	fputs("usage: undulate-top [--lcm-url URL] [--read-only] [--once [--wait S]] [--json [--interval S]] [-v]\n"
	      "Live view of every robot publishing <robot>.STATE on the LCM network.\n"
	      "  --once        collect for --wait S (default 1.5), print one snapshot, exit\n"
	      "  --json        JSON snapshots, one object per line (with --once exactly one)\n"
	      "  --interval S  seconds between --json snapshots (default 1)\n"
	      "  --read-only   no commands (keys only navigate)\n"
	      "  --lcm-url URL LCM provider (default: $LCM_DEFAULT_URL or udpm ttl=0)\n"
	      "keys: up/down or 1-9 select; l h s o = LIMP HOLD SINUSOID OSCILLATOR for the\n"
	      "selected robot, L H S O for all; +/- nudge c (OSCILLATOR) or the amplitude\n"
	      "(SINUSOID); v detail/compact view; PgUp/PgDn; q or Ctrl-C quit\n",
	      f);
}

static int parse_seconds(const char *opt, const char *s, double *out)
{
	double v;
	if (num_parse_double(s, &v) != NUM_OK || !(v > 0)) {
		fprintf(stderr, "undulate-top: %s: \"%s\" is not a positive number of seconds\n", opt, s);
		return -1;
	}
	*out = v;
	return 0;
}

static int parse_args(struct top_app *a, int argc, char **argv)
{
	enum { O_URL = 256, O_RO, O_ONCE, O_JSON, O_WAIT, O_INTERVAL };
	static const struct option opts[] = {
		{ "lcm-url", required_argument, NULL, O_URL }, { "read-only", no_argument, NULL, O_RO },
		{ "once", no_argument, NULL, O_ONCE },          { "json", no_argument, NULL, O_JSON },
		{ "wait", required_argument, NULL, O_WAIT },    { "interval", required_argument, NULL, O_INTERVAL },
		{ "help", no_argument, NULL, 'h' },             { "verbose", no_argument, NULL, 'v' },
		{ NULL, 0, NULL, 0 },
	};
	int c;
	while ((c = getopt_long(argc, argv, "hv", opts, NULL)) != -1) {
		switch (c) {
		case O_URL: a->url = optarg; break;
		case O_RO: a->read_only = true; break;
		case O_ONCE: a->once = true; break;
		case O_JSON: a->json = true; break;
		case O_WAIT: if (parse_seconds("--wait", optarg, &a->wait_s)) return -1; break;
		case O_INTERVAL: if (parse_seconds("--interval", optarg, &a->interval_s)) return -1; break;
		case 'v': a->verbose = true; break;
		case 'h': usage(stdout); exit(0);
		default: usage(stderr); return -1;
		}
	}
	if (optind < argc) {
		fprintf(stderr, "undulate-top: unexpected argument \"%s\"\n", argv[optind]);
		return -1;
	}
	return 0;
}

static void install_signals(void)
{
	struct sigaction sa;
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal; /* no SA_RESTART: poll() returns EINTR */
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGHUP, &sa, NULL);
	sa.sa_handler = on_winch;
	sigaction(SIGWINCH, &sa, NULL);
	signal(SIGPIPE, SIG_IGN);
}

int main(int argc, char **argv)
{
	static struct top_app app; /* large (the model): not on the stack */
	struct top_app *a = &app;
	a->wait_s = 1.5;
	a->interval_s = 1.0;
	top_model_init(&a->model);
	if (parse_args(a, argc, argv) != 0)
		return 1;
	a->view.read_only = a->read_only;
	char host[64] = "?";
	gethostname(host, sizeof(host) - 1);
	/* short enough for any robot to take (command.h's CMD_STR_MAX) */
	snprintf(a->source, sizeof(a->source), "undulate-top@%.24s:%ld", host, (long)getpid());
	/* Sequence numbers from the clock: two monitors on one network rarely
	 * pick the same ones, so each shows only answers to its own commands. */
	a->first_seq = a->next_seq = clock_wall_us();
	a->screen = malloc(TOP_SCREEN_MAX);
	a->lcm = lcm_create(a->url);
	if (!a->screen || !a->lcm) {
		fprintf(stderr, "undulate-top: cannot start LCM on %s\n", a->url ? a->url : "the default URL");
		return 1;
	}
	if (top_subscribe(a) != 0) {
		fputs("undulate-top: LCM subscription failed\n", stderr);
		return 1;
	}
	a->cmd_fd = -1;
	if (!a->read_only && !a->once && !a->json) {
		char why[256];
		a->cmd_fd = csock_client_open(why, sizeof(why));
		if (a->cmd_fd < 0)
			fprintf(stderr, "undulate-top: commands disabled: %s\n", why);
	}
	install_signals();
	if (a->verbose)
		fprintf(stderr, "undulate-top: listening on %s\n", a->url ? a->url : "the default LCM URL");
	int rc = a->once ? run_once(a) : a->json ? run_stream(a) : run_interactive(a);
	lcm_destroy(a->lcm);
	if (a->cmd_fd >= 0)
		close(a->cmd_fd);
	free(a->screen);
	return rc;
}
