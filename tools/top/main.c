/* undulate-top — live monitor of every robot on the LCM network.
 * See tools/top/README.md. */
#include "clock.h"
#include "compat/lcm/lcmdec.h"
#include "csock.h"
#include "feed.h"
#include "keys.h"
#include "model.h"
#include "modes.h"
#include "num.h"
#include "render.h"
#include "term.h"
#include "text.h"

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
	const char *banner_file;    /* --banner-file: its first line is shown under the title */
	int64_t first_seq, next_seq;
	char source[64];
	/* The last command to every robot: how many sockets it went to and how
	 * many robots answered, so the status line says "N of M accepted". */
	struct {
		int64_t seq;
		char what[64];
		int sent, accepted, rejected;
		/* robots already counted: each answers twice (its local socket
		 * and its EVENT channel) */
		char counted[TOP_MAX_ROBOTS][TOP_NAME_MAX];
		int ncounted;
		char first_reject[TOP_STATUS_MAX];
		double sent_at;
		bool showing;        /* the status line shows this count (refreshed) */
	} all;
	char *screen;
	struct top_keyparser kp;
	bool quit;
	bool interrupted;           /* Ctrl-C (a key in raw mode): exit 130, not 0 */
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
	a->all.showing = false;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(a->view.status, sizeof(a->view.status), fmt, ap);
	va_end(ap);
}

/* ---- LCM ------------------------------------------------------------------------ */

/* Seconds after a command to every robot before the ones that did not
 * answer are counted as such. */
#define TOP_ALL_ANSWER_S 2.0

static void clock_text(char *out, size_t n)
{
	time_t t = time(NULL);
	struct tm tm;
	localtime_r(&t, &tm);
	strftime(out, n, "%H:%M:%S", &tm);
}

static void show_all_status(struct top_app *a, double now)
{
	int silent = a->all.sent - a->all.accepted - a->all.rejected;
	char tail[TOP_STATUS_MAX] = "";
	if (silent > 0 && now - a->all.sent_at >= TOP_ALL_ANSWER_S)
		snprintf(tail, sizeof tail, ", %d did not answer", silent);
	else if (silent > 0)
		snprintf(tail, sizeof tail, ", waiting for %d", silent);
	set_status(a, "all robots %s: %d of %d accepted%s%s%s", a->all.what, a->all.accepted, a->all.sent, tail,
		   a->all.rejected ? "; " : "", a->all.rejected ? a->all.first_reject : "");
	a->all.showing = true;
}

static void show_event(struct top_app *a, const undulate_event_t *e)
{
	if (e->seq < a->first_seq || e->seq >= a->next_seq)
		return;
	if (e->seq == a->all.seq && a->all.sent > 0) {
		for (int i = 0; i < a->all.ncounted; i++)
			if (strcmp(a->all.counted[i], e->robot) == 0)
				return;
		if (a->all.ncounted < TOP_MAX_ROBOTS)
			snprintf(a->all.counted[a->all.ncounted++], TOP_NAME_MAX, "%s", e->robot);
		if (strcmp(e->kind, "command-accepted") == 0)
			a->all.accepted++;
		else if (strcmp(e->kind, "command-rejected") == 0 && a->all.rejected++ == 0)
			snprintf(a->all.first_reject, sizeof a->all.first_reject, "%s: %s", e->robot, e->text);
		show_all_status(a, clock_mono_s());
		return;
	}
	char t[16];
	clock_text(t, sizeof t);
	set_status(a, "%s %s: %s: %s", t, e->robot, e->kind, e->text);
}

static void top_feed_event(const undulate_event_t *e, void *user)
{
	show_event(user, e);
}

/* A message that does not decode is counted in the model (shown in --json and
 * the footer): the screen is ours, so nothing is printed. */
static void on_message(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
	struct top_app *a = user;
	const struct top_feed_hooks hooks = { .on_event = top_feed_event, .user = a };
	char why[160];
	top_feed(&a->model, channel, rbuf->data, rbuf->data_size, clock_mono_s(), &hooks, why, sizeof why);
}

static int top_subscribe(struct top_app *a)
{
	for (size_t i = 0; i < top_feed_nchannels; i++)
		if (!lcm_subscribe(a->lcm, top_feed_channels[i], on_message, a))
			return -1;
	return 0;
}

/* ---- commands ------------------------------------------------------------------- */

/* Commands go to the robots' local command sockets on this computer (never
 * over the network: a robot takes those only signed); the answers come back
 * on ours and show in the status line. */
#define TOP_MAX_SOCKETS 64
static int publish(struct top_app *a, const struct top_command *c)
{
	static char paths[TOP_MAX_SOCKETS][CSOCK_PATH_MAX];
	uint8_t buf[1024];
	char why[256];
	int n = undulate_command_t_encoded_size(&c->msg);
	if (a->cmd_fd < 0 || n <= 0 || n > (int)sizeof(buf) || undulate_command_t_encode(buf, 0, n, &c->msg) != n) {
		set_status(a, "cannot send commands (%s)", a->cmd_fd < 0 ? "no local socket" : "encoding failed");
		return 0;
	}
	size_t np = csock_find(c->msg.robot, a->url, paths, TOP_MAX_SOCKETS);
	if (np == 0) {
		set_status(a, "nothing sent: no robot %s runs on this computer with %s (commands go to "
			   "local robots only)", strcmp(c->msg.robot, "*") == 0 ? "at all" : c->msg.robot,
			   a->url ? a->url : "the default LCM URL");
		return 0;
	}
	size_t sent = 0;
	for (size_t i = 0; i < np; i++) {
		if (csock_send(a->cmd_fd, paths[i], buf, (size_t)n, why, sizeof(why)))
			sent++;
		else
			set_status(a, "%s", why);
	}
	return (int)sent;
}

static void read_answers(struct top_app *a)
{
	uint8_t buf[2048];
	for (int i = 0; i < 64; i++) {
		ssize_t n = recv(a->cmd_fd, buf, sizeof(buf), MSG_DONTWAIT);
		if (n <= 0)
			return;
		undulate_event_t e;
		if (lcmdec_decode(&lcmdec_event_t, buf, (size_t)n, &e) != LCMDEC_OK) {
			a->model.decode_errors++;
			continue;
		}
		top_on_event(&a->model, &e);
		show_event(a, &e);
		lcmdec_free(&lcmdec_event_t, &e);
	}
}

static void send_mode(struct top_app *a, int mode, bool all)
{
	const struct top_model *m = &a->model;
	if (!all && m->nrobots == 0) {
		set_status(a, "no robot selected: none heard yet");
		return;
	}
	const char *robot = all ? "*" : m->robots[m->order[a->view.selected]].name;
	struct top_command c;
	if (top_command_mode(&c, robot, mode, a->next_seq, a->source) != 0)
		return;
	int sent = publish(a, &c);
	if (sent > 0 && all) {
		a->all.seq = a->next_seq;
		a->all.sent = sent;
		a->all.accepted = a->all.rejected = 0;
		a->all.ncounted = 0;
		a->all.first_reject[0] = '\0';
		a->all.sent_at = clock_mono_s();
		snprintf(a->all.what, sizeof a->all.what, "mode %s", mode_name(mode));
		show_all_status(a, a->all.sent_at);
	} else if (sent > 0) {
		char t[16];
		clock_text(t, sizeof t);
		set_status(a, "%s sent %s mode %s, waiting for the answer", t, robot, mode_name(mode));
	}
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
		ok = publish(a, &c[i]) > 0 && ok;
	if (ok) {
		char t[16];
		clock_text(t, sizeof t);
		set_status(a, "%s sent %s", t, what);
	}
	a->next_seq += n;
}

/* ---- keys ----------------------------------------------------------------------- */

static int mode_of_key(int ch)
{
	switch (ch) {
	case 'l': return MODE_LIMP;
	case 'h': return MODE_HOLD;
	case 's': return MODE_SINUSOID;
	case 'o': return MODE_OSCILLATOR;
	default: return -1;
	}
}

/* A mode change takes two keys, `m` (selected robot) or `M` (every robot)
 * and then l/h/s/o: no key of navigation (vi's h j k l, the arrows) can turn
 * a robot's torque off by itself. */
static void on_char(struct top_app *a, int ch)
{
	/* Ctrl-C and Ctrl-D quit from any state (the legend, a half-typed mode) */
	if (ch == 3 || ch == 4) {
		a->quit = true;
		a->interrupted = ch == 3;
		return;
	}
	if (a->view.help) {
		a->view.help = false;
		return;
	}
	if (a->view.prefix) {
		int prefix = a->view.prefix;
		a->view.prefix = 0;
		if (mode_of_key(ch) >= 0)
			send_mode(a, mode_of_key(ch), prefix == 'M');
		else
			set_status(a, "mode change cancelled");
		return;
	}
	if (ch == 'q' || ch == 'Q' || ch == 3 /* Ctrl-C */ || ch == 4 /* Ctrl-D */) {
		a->quit = true;
		a->interrupted = ch == 3;
	} else if (ch == '?') {
		a->view.help = true;
	} else if (ch >= '1' && ch <= '9') {
		a->view.selected = ch - '1';
		top_view_move(&a->view, &a->model, 0);
	} else if (ch == 'k' || ch == 'j') {
		top_view_move(&a->view, &a->model, ch == 'k' ? -1 : 1);
	} else if (ch == 'v') {
		a->view.kind = (enum top_view_kind)((a->view.kind + 1) % 3);
		set_status(a, "view: %s",
			 a->view.kind == TOP_VIEW_AUTO ? "auto" : a->view.kind == TOP_VIEW_DETAIL ? "detail" : "compact");
	} else if (ch == 'm' || ch == 'M' || ch == '+' || ch == '=' || ch == '-') {
		if (a->read_only)
			set_status(a, "read-only: commands are disabled");
		else if (ch == 'm' || ch == 'M')
			a->view.prefix = ch;
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
		enum top_key key = top_key_feed(&a->kp, buf[i], &ch);
		/* a navigation key closes the help and cancels a half-typed mode change */
		if (key != TOP_KEY_NONE && key != TOP_KEY_CHAR && (a->view.help || a->view.prefix)) {
			if (a->view.prefix)
				set_status(a, "mode change cancelled");
			a->view.help = false;
			a->view.prefix = 0;
		}
		switch (key) {
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

/* The banner: the first line of --banner-file, read every frame (whoever
 * runs the show rewrites it; a missing or empty file shows nothing). */
static void read_banner(struct top_app *a)
{
	a->view.banner[0] = '\0';
	if (a->banner_file == NULL)
		return;
	FILE *f = fopen(a->banner_file, "r");
	if (f == NULL)
		return;
	char line[TOP_STATUS_MAX];
	if (fgets(line, sizeof line, f) != NULL) {
		line[strcspn(line, "\r\n")] = '\0';
		/* printable ASCII only: the screen must not take escapes from a file */
		text_line(a->view.banner, sizeof a->view.banner, line);
	}
	fclose(f);
}

static void draw(struct top_app *a, double now)
{
	read_banner(a);
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
		if (a->all.showing && now - a->all.sent_at < TOP_ALL_ANSWER_S + 2 * TOP_FRAME_S)
			show_all_status(a, now);
		if (now >= next) {
			draw(a, now);
			next = now + TOP_FRAME_S;
		}
		pump(a, next - now, true);
	}
	term_leave();
	/* 130: interrupted, as a shell reports SIGINT; whoever started us (the
	 * demo) stops instead of going on as after q */
	return a->interrupted ? 130 : 0;
}

/* ---- options -------------------------------------------------------------------- */

static void usage(FILE *f)
{
	fputs("usage: undulate-top [--lcm-url URL] [--read-only] [--banner-file FILE] [--once [--wait S]]\n"
	      "                    [--json [--interval S]] [-v]\n"
	      "Live view of every robot publishing <robot>.STATE on the LCM network.\n"
	      "  --once        collect for --wait S (default 1.5), print one snapshot, exit\n"
	      "  --json        JSON snapshots, one object per line (with --once exactly one)\n"
	      "  --interval S  seconds between --json snapshots (default 1)\n"
	      "  --read-only   no commands (keys only navigate)\n"
	      "  --banner-file FILE  show FILE's first line under the title, re-read every frame\n"
	      "  --lcm-url URL LCM provider (default: $LCM_DEFAULT_URL or udpm ttl=0)\n"
	      "keys: up/down j/k 1-9 select; m then l h s o = LIMP HOLD SINUSOID OSCILLATOR for\n"
	      "the selected robot, M then l h s o for every robot; +/- nudge c (OSCILLATOR) or\n"
	      "the amplitude (SINUSOID); v detail/compact view; ? help; q or Ctrl-C quit\n",
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
	enum { O_URL = 256, O_RO, O_ONCE, O_JSON, O_WAIT, O_INTERVAL, O_BANNER };
	static const struct option opts[] = {
		{ "lcm-url", required_argument, NULL, O_URL }, { "read-only", no_argument, NULL, O_RO },
		{ "once", no_argument, NULL, O_ONCE },          { "json", no_argument, NULL, O_JSON },
		{ "wait", required_argument, NULL, O_WAIT },    { "interval", required_argument, NULL, O_INTERVAL },
		{ "help", no_argument, NULL, 'h' },             { "verbose", no_argument, NULL, 'v' },
		{ "banner-file", required_argument, NULL, O_BANNER },
		{ NULL, 0, NULL, 0 },
	};
	int c;
	while ((c = getopt_long(argc, argv, "hv", opts, NULL)) != -1) {
		switch (c) {
		case O_URL: a->url = optarg; break;
		case O_RO: a->read_only = true; break;
		case O_BANNER: a->banner_file = optarg; break;
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
	a->view.url = a->url;
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
