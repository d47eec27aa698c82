/*
 * undulate-sim — simulated AX-12 buses on pseudo-terminals, with motor
 * physics, a contact world, fault injection and ground truth on LCM.
 *
 *   undulate-sim --link PATH --ids 1,2 [options]      one bus (quick form)
 *   undulate-sim --scenario FILE [--set sec.key=val]   robots, world, faults
 *
 * One single-threaded loop (pselect) owns everything: the physics runs on an
 * absolute schedule at rate_hz, replies leave each bus's line queue when
 * their wire time has come, LCM and the control socket are served in
 * between. Its clock is the system's, or with --lockstep the virtual time
 * this process owns (struct sim_clock): one loop either way. See
 * sim-bridge/README.md.
 */
#include <errno.h>
#include <getopt.h>
#include <lcm/lcm.h>
#include <limits.h>
#include <math.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "clock.h"
#include "sim.h"
#include "text.h"
#include "vtime.h"
#include "compat/lcm/lcmdec.h"
#include "wire.h"
#include "undulate_sim_collision_t.h"
#include "undulate_sim_command_t.h"
#include "undulate_sim_reply_t.h"
#include "undulate_sim_truth_t.h"
#include "undulate_sim_contact_t.h"
#include "undulate_sim_link_t.h"
#include "undulate_sim_wall_t.h"
#include "undulate_sim_world_t.h"

/* Physics steps run back to back after a stall before the schedule is
 * reset (a stalled machine should not replay seconds of physics at once). */
#define MAIN_MAX_CATCHUP 50
/* Control-socket clients served at once; one command line's length. */
#define MAIN_MAX_CLIENTS 8
#define MAIN_LINE_MAX SIM_CMD_MAX
/* Collisions buffered between two SIM.TRUTH messages (more are counted). */
#define MAIN_TRUTH_MAX_COLLISIONS 256
/* Encoded SIM.TRUTH: 64 bodies × ~100 B + 256 collisions × ~140 B, with room. */
#define MAIN_TRUTH_BUF (128 * 1024)
#define MAIN_MAX_FDS (SIM_MAX_BUSES + MAIN_MAX_CLIENTS + 2 + VT_MAX_CLIENTS + 1)
/* pollset tags below the control socket's (-3 - client): the lockstep socket
 * and its daemons */
#define MAIN_TAG_VT_LISTEN (-1000)
/* Lockstep: reply bytes are handed over in chunks of this much wire time (in
 * real time, --tx-slice-us). A whole reply (READ(24,20): 26 bytes, 260 µs at
 * 1 Mbps) is then one chunk and one wake-up of its daemon, not two or three;
 * the daemon acts on whole packets only, and the chunk is released at its
 * last byte's wire time, never earlier. Measured on the pair rig: 3.6 wake-ups
 * a daemon per cycle with 100 µs chunks. */
#define MAIN_LOCKSTEP_SLICE_NS 500000
#define MAIN_TAG_VT_CLIENT (-2000)
/* Step lateness histogram for percentiles: 10 µs bins up to 20 ms (the last
 * bin holds everything later). */
#define MAIN_LATE_BIN_US 10
#define MAIN_LATE_BINS 2000

static volatile sig_atomic_t stop_signal;

static void on_signal(int sig) { stop_signal = sig; }

static int64_t mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}


struct client {
	int fd;
	size_t have;
	bool skipping;             /* inside an over-long line: drop up to its newline */
	char buf[MAIN_LINE_MAX];
};

struct sim_clock;

struct app {
	struct sim *sim;
	const struct sim_clock *clock;   /* what paces the loop (run) */
	lcm_t *lcm;
	bool lcm_listen;                 /* SIM.CMD is read (never in lockstep: main) */
	int listen_fd;
	char control_path[SIM_PATH_MAX];
	struct client clients[MAIN_MAX_CLIENTS];
	int64_t t0, step_ns, tx_slice_ns;
	/* timing */
	double worst_late_us, period_worst_late_us, late_sum_us;
	uint64_t late_samples, overruns;
	uint64_t late_hist[MAIN_LATE_BINS];
	/* real time the physics gave up (overruns), said at most once a second */
	int64_t lost_ns, lost_said_ns, last_said;
	uint64_t overruns_said;
	/* truth */
	struct sim_collision pending[MAIN_TRUTH_MAX_COLLISIONS];
	int64_t pending_utime[MAIN_TRUTH_MAX_COLLISIONS];   /* when each impact was seen */
	int pending_bus[MAIN_TRUTH_MAX_COLLISIONS][2];
	size_t npending;
	uint64_t truth_sent, truth_failed, collisions_unreported;
	uint64_t contacts_steps_at;   /* the step of the last SIM.TRUTH: its contacts' period */
	uint8_t *truth_buf;
	bool bench, quiet;
	/* real time: the descriptors were served since the last work; --bench's figures */
	bool served;
	int64_t next_bench, bench_at;
	double bench_cpu;
	/* bad input already reported, per bus (reported at most once a second) */
	uint64_t reported_bad[SIM_MAX_BUSES];
	/* lockstep: virtual time, owned here and shared with the daemons */
	bool lockstep;
	struct vt vt;
	int64_t lockstep_grace_ns;
	int64_t wall_end;             /* when the run ended (wall clock) */
	int64_t first_step_wall;      /* when simulated time first moved */
	int64_t start_wall;           /* when the loop started (the daemons' join grace) */
};

/* The simulation's "now" (ns) for the bus and the command language: the
 * monotonic clock, or in lockstep the virtual time. */
static int64_t app_now(const struct app *a)
{
	return a->lockstep ? (int64_t)a->vt.t_ns : mono_ns();
}

/* ---- options ---------------------------------------------------------------- */

/* Settings from the command line: a --set for each scheduled event of a
 * long run (scripts/demo.sh --lockstep samples every 5 s: 62 for 300 s) and
 * the options that are scenario keys. */
#define MAIN_MAX_SETS (SIM_MAX_EVENTS + 64)
#define MAIN_MAX_KEYS 64

struct options {
	const char *scenario;
	const char *link, *ids, *name;
	const char *sets[MAIN_MAX_SETS];
	int nsets;
	int nkeys;              /* of them, options stored as SECTION.KEY=VALUE (set_store) */
	bool bench, quiet;
	double tx_slice_us;
	const char *send_cmd;   /* --cmd: publish one SIM.CMD and exit */
	int realtime;           /* SCHED_FIFO priority, 0 = normal scheduling */
	const char *lcm_url;
	int nsim_opts;          /* options other than --cmd/--lcm-url (--cmd takes none) */
	const char *lockstep;   /* the lockstep socket: virtual time */
	double lockstep_grace_s;
	bool lockstep_pty;      /* the bus bytes through the ptys, not in the clock's messages */
};

static void usage(FILE *f)
{
	fprintf(f,
	        "usage: undulate-sim --link PATH --ids 1,2 [options]\n"
	        "       undulate-sim --scenario FILE [--set section.key=value ...] [options]\n"
	        "options (each is also a [sim] key; the command line wins):\n"
	        "  --link PATH          the bus's pty appears at PATH (quick form)\n"
	        "  --ids LIST           servo IDs on that bus, e.g. 1,2 or 1-4\n"
	        "  --model MODEL        ax12a (default, Protocol 1.0) or an X model on Protocol 2.0\n"
	        "                       (%s); a list gives one model per ID\n"
	        "  --name NAME          robot name of the quick-form bus (default: the link's basename)\n"
	        "  --scenario FILE      robots, world, motors and timed faults (README: scenario format)\n"
	        "  --set SEC.KEY=VAL    override any scenario key, e.g. world.separation=0.4\n"
	        "  --link-dir DIR       where scenario robots without a link appear (DIR/NAME)\n"
	        "  --lcm-url URL        LCM provider for SIM.TRUTH/SIM.COLLISION/SIM.CMD\n"
	        "  --control PATH       unix socket for run-time commands (one per line)\n"
	        "  --seed N             initial angles and random faults (deterministic runs)\n"
	        "  --duration S         exit after S seconds (0: run until SIGINT/SIGTERM)\n"
	        "  --baud BPS           the controller's rate on every bus (default: the servos'\n"
	        "                       factory rate, 1000000 for the AX-12A, 57600 for X servos)\n"
	        "  --return-delay US    initial return delay of every servo (default: factory 500)\n"
	        "  --firmware N         X series: the firmware every servo reports and acts as\n"
	        "                       (default 46; below 45 no Fast Sync/Bulk Read)\n"
	        "  --latency-ms MS      USB adapter hold time toward the controller (FTDI: 16)\n"
	        "  --echo               single-wire adapter: requests come back before replies\n"
	        "  --rate-hz HZ         physics steps per second (default 1000)\n"
	        "  --truth-hz HZ        SIM.TRUTH messages per second (default 100)\n"
	        "  --temperature C      ambient (and initial) servo temperature\n"
	        "  --voltage V          supply voltage (default 12)\n"
	        "  --tx-slice-us US     reply pacing granularity (default 100)\n"
	        "  --bench              print CPU and step lateness every second\n"
	        "  --realtime PRIO      run under SCHED_FIFO at PRIO (1-99) for steadier steps\n"
	        "  --quiet              only the ready line, errors and the exit summary\n"
	        "  --lockstep SOCKET    virtual time: every bus's daemon joins at SOCKET (undulated\n"
	        "                       --lockstep SOCKET) and the run goes as fast as they take turns;\n"
	        "                       --duration is simulated seconds (README: Lockstep)\n"
	        "  --lockstep-grace S   wall-clock seconds a daemon may take to join or to answer before\n"
	        "                       the run is ended as stalled (default 10)\n"
	        "  --lockstep-pty       the bus bytes through the ptys, not in the clock's messages (the\n"
	        "                       earlier transport, kept one release to compare the two; also\n"
	        "                       UNDULATE_LOCKSTEP_PTY=1 in the environment)\n"
	        "  --cmd 'VERB ARGS'    send one command to a running simulator on SIM.CMD and exit\n",
	        sim_model_names() + strlen("ax12a, "));
}

enum {
	OPT_LINK = 256, OPT_IDS, OPT_NAME, OPT_SCENARIO, OPT_SET, OPT_LINK_DIR, OPT_LCM_URL, OPT_CONTROL,
	OPT_SEED, OPT_DURATION, OPT_BAUD, OPT_RETURN_DELAY, OPT_LATENCY, OPT_ECHO, OPT_RATE, OPT_TRUTH,
	OPT_TEMP, OPT_VOLTAGE, OPT_TX_SLICE, OPT_BENCH, OPT_QUIET, OPT_HELP, OPT_CMD, OPT_REALTIME,
	OPT_LOCKSTEP, OPT_LOCKSTEP_GRACE, OPT_LOCKSTEP_PTY, OPT_MODEL, OPT_FIRMWARE,
};

/* Options that are [sim] keys go through the same parser as the file. */
static const struct {
	int opt;
	const char *key;
} sim_keys[] = {
	{ OPT_LINK_DIR, "sim.link_dir" }, { OPT_LCM_URL, "sim.lcm_url" }, { OPT_CONTROL, "sim.control" },
	{ OPT_SEED, "sim.seed" }, { OPT_DURATION, "sim.duration" }, { OPT_BAUD, "sim.baud" },
	{ OPT_RETURN_DELAY, "sim.return_delay_us" }, { OPT_LATENCY, "sim.latency_ms" },
	{ OPT_RATE, "sim.rate_hz" }, { OPT_TRUTH, "sim.truth_hz" }, { OPT_TEMP, "sim.temperature" },
	{ OPT_VOLTAGE, "sim.voltage" }, { OPT_MODEL, "sim.model" }, { OPT_FIRMWARE, "sim.firmware" },
};

static char set_store[MAIN_MAX_KEYS][SIM_CMD_MAX + SIM_PATH_MAX];

/* An option's number in lo..hi; else what it takes (`what`) on stderr. */
static bool opt_number(const char *arg, double lo, double hi, double *out, const char *what)
{
	char *end;
	*out = strtod(arg, &end);
	if (end == arg || *end != '\0' || !(*out >= lo && *out <= hi)) {
		fprintf(stderr, "undulate-sim: %s\n", what);
		return false;
	}
	return true;
}

static int parse_args(int argc, char **argv, struct options *o)
{
	static const struct option longopts[] = {
		{ "link", required_argument, 0, OPT_LINK }, { "ids", required_argument, 0, OPT_IDS },
		{ "name", required_argument, 0, OPT_NAME }, { "scenario", required_argument, 0, OPT_SCENARIO },
		{ "set", required_argument, 0, OPT_SET }, { "link-dir", required_argument, 0, OPT_LINK_DIR },
		{ "lcm-url", required_argument, 0, OPT_LCM_URL }, { "control", required_argument, 0, OPT_CONTROL },
		{ "seed", required_argument, 0, OPT_SEED }, { "duration", required_argument, 0, OPT_DURATION },
		{ "baud", required_argument, 0, OPT_BAUD }, { "return-delay", required_argument, 0, OPT_RETURN_DELAY },
		{ "latency-ms", required_argument, 0, OPT_LATENCY }, { "echo", no_argument, 0, OPT_ECHO },
		{ "rate-hz", required_argument, 0, OPT_RATE }, { "truth-hz", required_argument, 0, OPT_TRUTH },
		{ "temperature", required_argument, 0, OPT_TEMP }, { "voltage", required_argument, 0, OPT_VOLTAGE },
		{ "tx-slice-us", required_argument, 0, OPT_TX_SLICE }, { "bench", no_argument, 0, OPT_BENCH },
		{ "quiet", no_argument, 0, OPT_QUIET }, { "help", no_argument, 0, OPT_HELP },
		{ "cmd", required_argument, 0, OPT_CMD }, { "realtime", required_argument, 0, OPT_REALTIME },
		{ "lockstep", required_argument, 0, OPT_LOCKSTEP },
		{ "lockstep-grace", required_argument, 0, OPT_LOCKSTEP_GRACE },
		{ "lockstep-pty", no_argument, 0, OPT_LOCKSTEP_PTY },
		{ "model", required_argument, 0, OPT_MODEL },
		{ "firmware", required_argument, 0, OPT_FIRMWARE },
		{ 0, 0, 0, 0 },
	};
	memset(o, 0, sizeof(*o));
	o->tx_slice_us = 100;
	o->lockstep_grace_s = 10;
	int c;
	char *end;
	long prio;
	while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		const char *key = NULL;
		for (size_t i = 0; i < sizeof(sim_keys) / sizeof(sim_keys[0]); i++)
			if (sim_keys[i].opt == c)
				key = sim_keys[i].key;
		if ((o->nsets >= MAIN_MAX_SETS && (key || c == OPT_SET || c == OPT_ECHO)) ||
		    (o->nkeys >= MAIN_MAX_KEYS && key)) {
			fprintf(stderr, "undulate-sim: too many settings (at most %d, %d of them options other than --set)\n",
			        MAIN_MAX_SETS, MAIN_MAX_KEYS);
			return -1;
		}
		if (c == OPT_LCM_URL)
			o->lcm_url = optarg;
		else if (c != OPT_CMD && c != OPT_HELP && c != 'h')
			o->nsim_opts++;
		if (key) {
			snprintf(set_store[o->nkeys], sizeof(set_store[0]), "%s=%s", key, optarg);
			o->sets[o->nsets++] = set_store[o->nkeys++];
			continue;
		}
		switch (c) {
		case OPT_LINK: o->link = optarg; break;
		case OPT_IDS: o->ids = optarg; break;
		case OPT_NAME: o->name = optarg; break;
		case OPT_SCENARIO: o->scenario = optarg; break;
		case OPT_SET: o->sets[o->nsets++] = optarg; break;
		case OPT_ECHO: o->sets[o->nsets++] = "sim.echo=true"; break;
		case OPT_TX_SLICE:
			if (!opt_number(optarg, 0, 10000, &o->tx_slice_us, "--tx-slice-us: 0..10000"))
				return -1;
			break;
		case OPT_BENCH: o->bench = true; break;
		case OPT_CMD: o->send_cmd = optarg; break;
		case OPT_REALTIME:
			prio = strtol(optarg, &end, 10);
			o->realtime = prio >= 1 && prio <= 99 ? (int)prio : 0;
			if (end == optarg || *end != '\0' || o->realtime == 0) {
				fprintf(stderr, "undulate-sim: --realtime: priority 1..99\n");
				return -1;
			}
			break;
		case OPT_QUIET: o->quiet = true; break;
		case OPT_LOCKSTEP:
			if (optarg[0] == '\0' || strlen(optarg) >= sizeof(((struct vt *)0)->path)) {
				fprintf(stderr, "undulate-sim: --lockstep: a socket path of 1..%zu bytes\n",
				        sizeof(((struct vt *)0)->path) - 1);
				return -1;
			}
			o->lockstep = optarg;
			break;
		case OPT_LOCKSTEP_GRACE:
			if (!opt_number(optarg, 0.1, 3600, &o->lockstep_grace_s, "--lockstep-grace: seconds, 0.1..3600"))
				return -1;
			break;
		case OPT_LOCKSTEP_PTY:
			o->lockstep_pty = true;
			break;
		case OPT_HELP: case 'h': usage(stdout); exit(0);
		default: usage(stderr); return -1;
		}
	}
	if (optind < argc) {
		fprintf(stderr, "undulate-sim: unexpected argument '%s'\n", argv[optind]);
		return -1;
	}
	if ((o->link != NULL) != (o->ids != NULL)) {
		fprintf(stderr, "undulate-sim: --link and --ids go together\n");
		return -1;
	}
	if (o->send_cmd && o->nsim_opts > 0) {
		/* client mode runs no simulator: its options would be silently ignored */
		fprintf(stderr, "undulate-sim: --cmd takes only --lcm-url\n");
		return -1;
	}
	if (o->send_cmd)
		return 0;
	if (!o->link && !o->scenario) {
		usage(stderr);
		return -1;
	}
	return 0;
}

static int build_config(const struct options *o, struct sim_config *c)
{
	char err[400];
	sim_config_defaults(c);
	if (o->scenario && sim_config_load(c, o->scenario, err, sizeof(err)) != 0)
		goto fail;
	if (o->link) {
		const char *base = strrchr(o->link, '/');
		const char *name = o->name ? o->name : (base ? base + 1 : o->link);
		if (sim_config_add_robot(c, name, o->link, o->ids, err, sizeof(err)) != 0)
			goto fail;
	}
	for (int i = 0; i < o->nsets; i++)
		if (sim_config_set(c, o->sets[i], err, sizeof(err)) != 0)
			goto fail;
	if (sim_config_finish(c, err, sizeof(err)) != 0)
		goto fail;
	return 0;
fail:
	fprintf(stderr, "undulate-sim: %s\n", err);
	return -1;
}

/* ---- LCM ------------------------------------------------------------------- */

/* SIM.CMD is decoded here (common/wire.h), not by the generated code: LCM
 * 1.3.1's decoder mallocs whatever length a string claims (a zero length
 * leaves it without its NUL, a huge one allocates gigabytes). sim_command_t is
 * the fingerprint, utime and seq (int64), verb and args (LCM strings). */
static void on_sim_cmd(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
	(void)channel;
	struct app *a = user;
	struct wire_reader w;
	char verb[SIM_CMD_MAX], args[SIM_CMD_MAX];
	bool cut_verb = false, cut_args = false;
	wire_reader_init(&w, rbuf->data, rbuf->data_size);
	bool ours = (int64_t)wire_take(&w, 8) == __undulate_sim_command_t_get_hash();
	(void)wire_take(&w, 8);
	long long seq = (long long)wire_take(&w, 8);
	wire_take_string(&w, verb, sizeof verb, &cut_verb);
	wire_take_string(&w, args, sizeof args, &cut_args);
	if (!ours || w.bad) {
		a->sim->bad_commands++;
		fprintf(stderr, "undulate-sim: SIM.CMD: not a well-formed sim_command_t (%u bytes)\n", rbuf->data_size);
		return;
	}
	char line[SIM_CMD_MAX], reply[512], shown[SIM_CMD_MAX + 64], shown_reply[600];
	if (cut_verb || cut_args || snprintf(line, sizeof(line), "%s %s", verb, args) >= (int)sizeof(line)) {
		a->sim->bad_commands++;
		fprintf(stderr, "undulate-sim: SIM.CMD seq %lld: command too long (or a NUL inside)\n", seq);
		/* still answered: the sender must not think nobody heard it */
		char v[44];
		snprintf(shown, sizeof shown, "%s...", text_sanitize(v, sizeof v, verb));
		snprintf(shown_reply, sizeof shown_reply, "error: command too long (at most %d bytes) or a NUL inside",
		         SIM_CMD_MAX - 1);
	} else {
		sim_command(a->sim, line, app_now(a), reply, sizeof(reply));
		/* whatever came from the network is one printable line in the log */
		fprintf(stderr, "undulate-sim: SIM.CMD seq %lld '%s': %s\n", seq, text_sanitize(shown, sizeof shown, line),
		        text_sanitize(shown_reply, sizeof shown_reply, reply));
	}
	/* The sender learns it was heard, and what came of it. Encoded on the
	 * stack: commands are rare and the reply is bounded. */
	uint8_t buf[sizeof shown + sizeof shown_reply + 64];
	undulate_sim_reply_t m = { .utime = clock_wall_us(), .seq = seq, .command = shown, .reply = shown_reply };
	int n = undulate_sim_reply_t_encode(buf, 0, (int)sizeof buf, &m);
	if (n > 0)
		lcm_publish(a->lcm, "SIM.REPLY", buf, (unsigned)n);
}

static void fill_collision(struct app *a, const struct sim_collision *c, int64_t utime,
                           undulate_sim_collision_t *m)
{
	struct sim *s = a->sim;
	static char wall[] = "wall";
	m->utime = utime;
	m->left = c->left;
	m->right = c->right;
	m->left_robot = c->left >= 0 ? s->buses[s->body_bus[c->left]].name : wall;
	m->right_robot = c->right >= 0 ? s->buses[s->body_bus[c->right]].name : wall;
	m->pre_left = c->pre_left;
	m->pre_right = c->pre_right;
	m->post_left = c->post_left;
	m->post_right = c->post_right;
	m->impulse = c->impulse;
}

/* Each impact of the last step: on SIM.COLLISION now, into SIM.TRUTH later.
 * Resting contact is resolved every step while bodies stay pressed together
 * (1000 a second per pair): it is a force, not an event, so it is only summed. */
static void report_collisions(struct app *a)
{
	struct sim *s = a->sim;
	int64_t now = clock_wall_us();
	for (size_t i = 0; i < s->nstep_collisions; i++) {
		const struct sim_collision *c = &s->step_collisions[i];
		if (c->resting)
			continue;
		if (a->lcm) {
			undulate_sim_collision_t m;
			fill_collision(a, c, now, &m);
			int n = undulate_sim_collision_t_encode(a->truth_buf, 0, MAIN_TRUTH_BUF, &m);
			if (n > 0)
				lcm_publish(a->lcm, "SIM.COLLISION", a->truth_buf, (unsigned)n);
		}
		if (a->npending < MAIN_TRUTH_MAX_COLLISIONS) {
			a->pending_utime[a->npending] = now;
			a->pending[a->npending++] = *c;
		}
		else
			a->collisions_unreported++;
	}
}

/* Every pair touching since the last message (either world), into t. */
static void fill_contacts(struct app *a, undulate_sim_truth_t *t)
{
	static undulate_sim_contact_t contacts[PLANE_MAX_CONTACTS];
	static struct plane_contact c[PLANE_MAX_CONTACTS];
	struct sim *s = a->sim;
	size_t nc = sim_contacts_drain(s, c, PLANE_MAX_CONTACTS);
	if (nc > PLANE_MAX_CONTACTS)
		nc = PLANE_MAX_CONTACTS;
	/* the period these impulses were summed over */
	double period = (double)(s->steps - a->contacts_steps_at) * s->dt;
	a->contacts_steps_at = s->steps;
	for (size_t i = 0; i < nc; i++)
		contacts[i] = (undulate_sim_contact_t){
			.robot_a = (int16_t)c[i].robot_a, .link_a = (int8_t)c[i].link_a, .robot_b = (int16_t)c[i].robot_b,
			.link_b = (int8_t)c[i].link_b, .x = c[i].x, .y = c[i].y, .nx = c[i].nx, .ny = c[i].ny,
			.impulse = c[i].impulse, .normal_impulse = c[i].normal_impulse,
			.force = period > 0 ? c[i].impulse / period : 0, .impact = c[i].impact,
		};
	t->ncontacts = (int32_t)nc;
	t->contacts = contacts;
}

/* The plane world's links and walls, into t. */
static void fill_plane(struct app *a, undulate_sim_truth_t *t)
{
	static undulate_sim_link_t links[PLANE_MAX_ROBOTS * PLANE_MAX_LINKS];
	static undulate_sim_wall_t walls[PLANE_MAX_WALLS];
	struct sim *s = a->sim;
	const struct plane_params *pp = &s->cfg.plane;
	t->world = UNDULATE_SIM_TRUTH_T_WORLD_PLANE;
	int nl = 0;
	for (int r = 0; r < plane_robots(s->plane); r++)
		for (int k = 0; k <= plane_joints(s->plane, r); k++) {
			struct plane_link_pose p;
			plane_link(s->plane, r, k, &p);
			links[nl++] = (undulate_sim_link_t){ .robot = (int16_t)r, .link = (int8_t)k, .x = p.x, .y = p.y,
							     .angle = p.angle, .length = pp->link_length,
							     .width = pp->link_width };
		}
	int nw = plane_walls(s->plane);
	for (int w = 0; w < nw; w++)
		plane_wall(s->plane, w, &walls[w].ax, &walls[w].ay, &walls[w].bx, &walls[w].by);
	t->nlinks = nl;
	t->links = links;
	t->nwalls = nw;
	t->walls = walls;
}

static void publish_truth(struct app *a)
{
	static undulate_sim_body_t bodies[SIM_MAX_BODIES];
	static undulate_sim_collision_t colls[MAIN_TRUTH_MAX_COLLISIONS];
	struct sim *s = a->sim;
	int64_t now = clock_wall_us();
	undulate_sim_truth_t t = {
		.utime = now, .step = (int64_t)s->steps, .sim_time = (double)s->steps * s->dt,
		.wall_left = s->world.params.wall_left, .wall_right = s->world.params.wall_right,
		.total_collisions = (int64_t)(s->world.total_collisions - s->world.resting_contacts),
		.total_impulse = s->world.total_impulse,
		.total_resting_steps = (int64_t)s->world.resting_contacts,
		.total_resting_impulse = s->world.resting_impulse,
		.worst_lateness_us = a->period_worst_late_us, .nbodies = (int32_t)s->world.nbodies, .bodies = bodies,
		.ncollisions = (int32_t)a->npending, .collisions = colls,
	};
	for (size_t i = 0; i < s->world.nbodies; i++) {
		struct sim_joint *j = &s->buses[s->body_bus[i]].joints[s->body_joint[i]];
		bodies[i] = (undulate_sim_body_t){
			.robot = s->buses[s->body_bus[i]].name, .servo_id = sim_joint_id(j),
			.angle = j->motor.angle, .speed = j->motor.speed, .lateral = sim_world_lateral(&s->world, i),
			.neutral = s->world.bodies[i].neutral, .load = sim_motor_load_fraction(&j->motor, &j->params),
			.temperature = j->motor.temperature,
		};
	}
	for (size_t i = 0; i < a->npending; i++)
		fill_collision(a, &a->pending[i], a->pending_utime[i], &colls[i]);
	fill_contacts(a, &t);
	if (s->plane != NULL) {
		fill_plane(a, &t);
		/* where the walls stand: a crowd may hold them short of the motion */
		t.wall_left = s->wall_face[0];
		t.wall_right = s->wall_face[1];
		t.escaped_links = (int64_t)s->escaped;
		t.wall_force_left = s->wall_force[0];
		t.wall_force_right = s->wall_force[1];
	}
	a->npending = 0;
	a->period_worst_late_us = 0;
	int n = undulate_sim_truth_t_encode(a->truth_buf, 0, MAIN_TRUTH_BUF, &t);
	if (n < 0 || lcm_publish(a->lcm, "SIM.TRUTH", a->truth_buf, (unsigned)n) != 0)
		a->truth_failed++;
	else
		a->truth_sent++;
}

/* The world's constants (SIM.WORLD): rare, small, into the truth buffer. */
static void publish_world(struct app *a)
{
	const struct sim_world_params *w = &a->sim->world.params;
	undulate_sim_world_t m = {
		.utime = clock_wall_us(), .restitution = w->restitution, .wall_restitution = w->wall_restitution,
		.beta = w->beta, .wall_left = w->wall_left, .wall_right = w->wall_right,
	};
	int n = undulate_sim_world_t_encode(a->truth_buf, 0, MAIN_TRUTH_BUF, &m);
	if (n > 0)
		lcm_publish(a->lcm, "SIM.WORLD", a->truth_buf, (unsigned)n);
}

/* ---- control socket ---------------------------------------------------------- */

/* Whether a simulator listens on the socket at addr (a killed one's is dead). */
static bool control_alive(const struct sockaddr_un *addr)
{
	int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
	bool alive = fd >= 0 && connect(fd, (const struct sockaddr *)addr, sizeof(*addr)) == 0;
	if (fd >= 0)
		close(fd);
	return alive;
}

static int control_open(struct app *a, const char *path)
{
	struct sockaddr_un addr = { .sun_family = AF_UNIX };
	if (strlen(path) >= sizeof(addr.sun_path)) {
		fprintf(stderr, "undulate-sim: --control %s: path too long\n", path);
		return -1;
	}
	strcpy(addr.sun_path, path);
	struct stat st;
	if (lstat(path, &st) == 0) {
		if (!S_ISSOCK(st.st_mode)) {
			fprintf(stderr, "undulate-sim: --control %s exists and is not a socket: refusing to replace it\n", path);
			return -1;
		}
		if (control_alive(&addr)) {
			fprintf(stderr, "undulate-sim: --control %s: another simulator listens on it\n", path);
			return -1;
		}
		unlink(path);  /* a stale socket from a killed run */
	}
	int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (fd < 0 || bind(fd, (struct sockaddr *)&addr, sizeof(addr)) != 0 || listen(fd, 4) != 0) {
		fprintf(stderr, "undulate-sim: --control %s: %s\n", path, strerror(errno));
		if (fd >= 0)
			close(fd);
		return -1;
	}
	a->listen_fd = fd;
	snprintf(a->control_path, sizeof(a->control_path), "%s", path);
	return 0;
}

static void control_accept(struct app *a)
{
	int fd = accept(a->listen_fd, NULL, NULL);
	if (fd < 0)
		return;
	for (int i = 0; i < MAIN_MAX_CLIENTS; i++)
		if (a->clients[i].fd < 0) {
			a->clients[i].fd = fd;
			a->clients[i].have = 0;
			a->clients[i].skipping = false;
			return;
		}
	static const char busy[] = "error: too many control clients\n";
	(void)!write(fd, busy, sizeof(busy) - 1);
	close(fd);
}

static void client_reply(struct client *c, const char *reply)
{
	char out[600];
	int n = snprintf(out, sizeof(out), "%s\n", reply);
	/* Replies are short; a client that does not read them loses them. */
	if (n > 0)
		(void)!write(c->fd, out, (size_t)n < sizeof(out) ? (size_t)n : sizeof(out) - 1);
}

static void control_read(struct app *a, struct client *c)
{
	ssize_t n = read(c->fd, c->buf + c->have, sizeof(c->buf) - 1 - c->have);
	if (n <= 0) {
		if (n < 0 && (errno == EAGAIN || errno == EINTR))
			return;
		close(c->fd);
		c->fd = -1;
		return;
	}
	c->have += (size_t)n;
	c->buf[c->have] = '\0';
	char *line = c->buf, *nl;
	if (c->skipping) {
		nl = strchr(line, '\n');
		if (!nl) {
			c->have = 0;
			return;
		}
		c->skipping = false;
		line = nl + 1;
	}
	while ((nl = strchr(line, '\n')) != NULL) {
		char reply[512];
		*nl = '\0';
		if (nl > line && nl[-1] == '\r')
			nl[-1] = '\0';
		if (*line)
			sim_command(a->sim, line, app_now(a), reply, sizeof(reply));
		else
			snprintf(reply, sizeof(reply), "error: empty command (try help)");
		client_reply(c, reply);
		line = nl + 1;
	}
	c->have = strlen(line);
	memmove(c->buf, line, c->have);
	if (c->have >= sizeof(c->buf) - 1) {
		a->sim->bad_commands++;
		client_reply(c, "error: line too long");
		c->have = 0;
		c->skipping = true;
	}
}

/* How long --cmd waits for a simulator's answer: a busy simulator serves LCM
 * between physics steps, within milliseconds; seconds mean nobody is there. */
#define SEND_WAIT_MS 3000

struct send_wait {
	int64_t seq;
	bool answered;
	bool refused;
};

static void on_sim_reply(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
	(void)channel;
	struct send_wait *w = user;
	undulate_sim_reply_t m;
	char shown[700];

	/* Our own small fixed message type from a simulator; still, the decoded
	 * text is printed sanitized and only when it answers our seq. */
	if (w->answered || lcmdec_decode(&lcmdec_sim_reply_t, rbuf->data, rbuf->data_size, &m) != LCMDEC_OK)
		return;
	if (m.seq == w->seq) {
		w->answered = true;
		w->refused = strncmp(m.reply, "ok", 2) != 0;
		printf("%s\n", text_sanitize(shown, sizeof shown, m.reply));
		fflush(stdout);
	}
	lcmdec_free(&lcmdec_sim_reply_t, &m);
}

/* --cmd: split "VERB ARGS" into a sim_command_t, publish it, and print the
 * simulator's answer. Exit 0: done; 1: the simulator refused it (its error
 * is printed); 3: no simulator answered; 2: usage. */
static int send_command(const struct options *o)
{
	char verb[64];
	const char *args = o->send_cmd;
	const char *url = o->lcm_url ? o->lcm_url : "LCM's default";
	size_t n = strcspn(args, " \t");
	if (n == 0 || n >= sizeof(verb)) {
		fprintf(stderr, "undulate-sim: --cmd: want 'VERB ARGS'\n");
		return 2;
	}
	memcpy(verb, args, n);
	verb[n] = '\0';
	args += n;
	args += strspn(args, " \t");
	lcm_t *lcm = lcm_create(o->lcm_url);
	if (!lcm) {
		fprintf(stderr, "undulate-sim: --cmd: LCM (%s) unavailable\n", url);
		return 1;
	}
	/* seq tells our answer from another client's: pid and time together. */
	struct send_wait w = { .seq = ((int64_t)getpid() << 32) ^ (mono_ns() & 0xFFFFFFFF) };
	lcm_subscription_t *sub = lcm_subscribe(lcm, "SIM.REPLY", on_sim_reply, &w);
	char argbuf[SIM_CMD_MAX];
	if (snprintf(argbuf, sizeof(argbuf), "%s", args) >= (int)sizeof(argbuf)) {
		fprintf(stderr, "undulate-sim: --cmd: the command is longer than %zu bytes\n", sizeof argbuf - 1);
		lcm_unsubscribe(lcm, sub);
		lcm_destroy(lcm);
		return 2;
	}
	undulate_sim_command_t m = { .utime = clock_wall_us(), .seq = w.seq, .verb = verb, .args = argbuf };
	int r = undulate_sim_command_t_publish(lcm, "SIM.CMD", &m);
	if (r != 0) {
		fprintf(stderr, "undulate-sim: --cmd: publish on %s failed\n", url);
		lcm_unsubscribe(lcm, sub);
		lcm_destroy(lcm);
		return 1;
	}
	int64_t deadline = mono_ns() + (int64_t)SEND_WAIT_MS * 1000000;
	while (!w.answered) {
		int64_t left_ms = (deadline - mono_ns()) / 1000000;
		if (left_ms <= 0)
			break;
		if (lcm_handle_timeout(lcm, (int)left_ms) < 0)
			break;
	}
	lcm_unsubscribe(lcm, sub);
	lcm_destroy(lcm);
	if (!w.answered) {
		fprintf(stderr, "undulate-sim: --cmd: no simulator answered on %s within %d s (is one "
		        "running with this --lcm-url?)\n", url, SEND_WAIT_MS / 1000);
		return 3;
	}
	return w.refused ? 1 : 0;
}

/* ---- the loop ------------------------------------------------------------------ */

static double cpu_seconds(void)
{
	struct rusage ru;
	getrusage(RUSAGE_SELF, &ru);
	return (double)ru.ru_utime.tv_sec + (double)ru.ru_stime.tv_sec +
	       ((double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_usec) / 1e6;
}

/* The physics steps due by now. In real time a step runs late by however
 * long the loop took to come round, and a stall is given up rather than
 * replayed; in lockstep time stops at every step (now == *next_step): never
 * late, never behind. */
static void physics(struct app *a, int64_t now, int64_t *next_step)
{
	struct sim *s = a->sim;
	int n = 0;
	while (now >= *next_step && n < MAIN_MAX_CATCHUP) {
		double late = (double)(now - *next_step) / 1000.0;
		if (late > a->worst_late_us)
			a->worst_late_us = late;
		if (late > a->period_worst_late_us)
			a->period_worst_late_us = late;
		a->late_sum_us += late;
		a->late_samples++;
		size_t bin = (size_t)(late / MAIN_LATE_BIN_US);
		a->late_hist[bin < MAIN_LATE_BINS ? bin : MAIN_LATE_BINS - 1]++;
		sim_step(s);
		report_collisions(a);
		sim_run_events(s, (double)s->steps * s->dt, now);
		*next_step += a->step_ns;
		n++;
	}
	if (now - *next_step > MAIN_MAX_CATCHUP * a->step_ns) {
		/* Too far behind to catch up step by step: the simulated time
		 * stops for what was lost, and the servos with it. A controller
		 * then sees slow servos; say so, so that nobody takes it for
		 * the controller's doing. */
		a->overruns++;
		a->lost_ns += now - *next_step + a->step_ns;
		*next_step = now + a->step_ns;
		if (now - a->last_said >= 1000000000) {
			fprintf(stderr, "undulate-sim: warning: fell behind real time: simulated time stopped for %.1f ms "
			        "(%llu time(s) since the last warning; %.1f ms in all): the machine is too busy for "
			        "the simulated servos to keep up\n", (double)(a->lost_ns - a->lost_said_ns) / 1e6,
			        (unsigned long long)(a->overruns - a->overruns_said), (double)a->lost_ns / 1e6);
			a->last_said = now;
			a->lost_said_ns = a->lost_ns;
			a->overruns_said = a->overruns;
		}
	}
}

static int build_pollset(struct app *a, struct pollfd *fds, int *bus_of)
{
	int n = 0;
	for (size_t i = 0; i < a->sim->nbuses; i++)
		if (sim_bus_connected(&a->sim->buses[i])) {
			bus_of[n] = (int)i;
			fds[n++] = (struct pollfd){ .fd = a->sim->buses[i].master, .events = POLLIN };
		}
	if (a->lcm_listen) {
		bus_of[n] = -1;
		fds[n++] = (struct pollfd){ .fd = lcm_get_fileno(a->lcm), .events = POLLIN };
	}
	if (a->listen_fd >= 0) {
		bus_of[n] = -2;
		fds[n++] = (struct pollfd){ .fd = a->listen_fd, .events = POLLIN };
	}
	for (int i = 0; i < MAIN_MAX_CLIENTS; i++)
		if (a->clients[i].fd >= 0) {
			bus_of[n] = -3 - i;
			fds[n++] = (struct pollfd){ .fd = a->clients[i].fd, .events = POLLIN };
		}
	if (a->lockstep) {
		bus_of[n] = MAIN_TAG_VT_LISTEN;
		fds[n++] = (struct pollfd){ .fd = a->vt.listen_fd, .events = POLLIN };
		for (int i = 0; i < VT_MAX_CLIENTS; i++)
			if (a->vt.c[i].fd >= 0) {
				bus_of[n] = MAIN_TAG_VT_CLIENT - i;
				fds[n++] = (struct pollfd){ .fd = a->vt.c[i].fd, .events = POLLIN };
			}
	}
	return n;
}

/* pselect(): POSIX, ns timeout, atomic signal mask (ppoll is GNU-only). The
 * pollfd array stays the bookkeeping; fds are few and small. */
static int wait_fds(struct pollfd *fds, int n, const struct timespec *ts, const sigset_t *mask)
{
	fd_set rd;
	int maxfd = -1;
	FD_ZERO(&rd);
	for (int i = 0; i < n; i++) {
		fds[i].revents = 0;
		if (fds[i].fd >= 0 && fds[i].fd < FD_SETSIZE) {
			FD_SET(fds[i].fd, &rd);
			maxfd = fds[i].fd > maxfd ? fds[i].fd : maxfd;
		}
	}
	int r = pselect(maxfd + 1, &rd, NULL, NULL, ts, mask);
	if (r <= 0)
		return r;
	for (int i = 0; i < n; i++)
		if (fds[i].fd >= 0 && fds[i].fd < FD_SETSIZE && FD_ISSET(fds[i].fd, &rd))
			fds[i].revents = POLLIN;
	return r;
}

static void serve(struct app *a, struct pollfd *fds, const int *bus_of, int n)
{
	for (int i = 0; i < n; i++) {
		if (!fds[i].revents)
			continue;
		if (bus_of[i] >= 0)
			sim_bus_read(&a->sim->buses[bus_of[i]], app_now(a));
		else if (bus_of[i] == MAIN_TAG_VT_LISTEN)
			vt_accept(&a->vt);
		else if (bus_of[i] <= MAIN_TAG_VT_CLIENT)
			vt_on_client(&a->vt, a->sim, (size_t)(MAIN_TAG_VT_CLIENT - bus_of[i]), mono_ns());
		else if (bus_of[i] == -1)
			lcm_handle_timeout(a->lcm, 0);
		else if (bus_of[i] == -2)
			control_accept(a);
		else if (a->clients[-3 - bus_of[i]].fd >= 0)
			control_read(a, &a->clients[-3 - bus_of[i]]);
	}
}

/* Upper edge of the bin holding the q-quantile of step lateness (µs). */
static double late_quantile(const struct app *a, double q)
{
	uint64_t want = (uint64_t)ceil(q * (double)a->late_samples), seen = 0;
	for (size_t i = 0; i < MAIN_LATE_BINS; i++) {
		seen += a->late_hist[i];
		if (seen >= want && seen > 0)
			return (double)((i + 1) * MAIN_LATE_BIN_US);
	}
	return 0;
}

static void bench_line(struct app *a, int64_t now, double *cpu_prev, int64_t *bench_prev)
{
	double cpu = cpu_seconds();
	double wall = (double)(now - *bench_prev) / 1e9;
	fprintf(stderr, "undulate-sim: bench: t=%.1f cpu=%.1f%% worst_late_us=%.0f p99_late_us=%.0f mean_late_us=%.1f overruns=%llu\n",
	        (double)(now - a->t0) / 1e9, 100.0 * (cpu - *cpu_prev) / wall, a->worst_late_us, late_quantile(a, 0.99),
	        a->late_samples ? a->late_sum_us / (double)a->late_samples : 0.0, (unsigned long long)a->overruns);
	*cpu_prev = cpu;
	*bench_prev = now;
}

/* Whether a bus's lines name its protocol and models: the AX-12A's lines
 * predate the other families and stay as they were (no protocol named, no
 * stuffing column: 1.0 has none, no NAME.model= word). */
static bool bus_says_family(const struct sim_bus *b)
{
	return b->njoints > 0 && b->joints[0].ops->says_family;
}

/* Bad bytes from a controller are counted by the bus; tell people about them
 * at most once a second per bus, as a sum since the last report. */
static void report_bad_input(struct app *a)
{
	for (size_t i = 0; i < a->sim->nbuses; i++) {
		const struct sim_bus *b = &a->sim->buses[i];
		const struct sim_bus_counters *c = &b->count;
		uint64_t bad = c->checksum_errors + c->header_errors + c->stuffing_errors + c->tx_dropped;
		if (bad == a->reported_bad[i])
			continue;
		a->reported_bad[i] = bad;
		struct dxl_parser_counts pc;
		b->proto->parser_counts(&b->parser, &pc);
		fprintf(stderr, "undulate-sim: bus %s: bad input so far: %llu bad %ss, ", b->name,
		        (unsigned long long)c->checksum_errors, b->proto->check_name);
		if (bus_says_family(b))
			fprintf(stderr, "%llu bad stuffing, ", (unsigned long long)c->stuffing_errors);
		fprintf(stderr, "%llu bad headers (%llu bytes skipped); %llu reply bytes nobody read\n",
		        (unsigned long long)c->header_errors, (unsigned long long)pc.bytes_dropped,
		        (unsigned long long)c->tx_dropped);
	}
}

/* ---- one loop, two clocks ------------------------------------------------------------ */

/* What is due and when, on the clock's time line (ns): the monotonic clock
 * from t0 in real time, virtual time from 0 in lockstep. */
struct sched {
	int64_t next_step, next_truth, next_world, end, truth_ns;
};

/* The loop's next move, as the clock decides it. */
enum clk_next {
	CLK_NOW,    /* time is *now: do what is due by then */
	CLK_WAIT,   /* serve the descriptors for up to *wait */
	CLK_END,    /* the run is over */
};

/* What paces the loop: the system's monotonic clock, or in lockstep the
 * virtual time this process owns and shares with the daemons (vtime.h). The
 * loop, the physics, the messages, the buses' replies and the descriptors
 * served are the same for both; as in the daemon, the clock is a source of
 * time, not a second loop. */
struct sim_clock {
	int64_t (*start)(struct app *a);           /* the time line's 0: the run's start */
	enum clk_next (*next)(struct app *a, const struct sched *sc, int64_t *now, struct timespec *wait);
	void (*served)(struct app *a);             /* after a CLK_WAIT */
	void (*moved)(struct app *a, int64_t now); /* after the work due by now */
};

/* The earliest thing the simulation itself has due: a physics step, a truth
 * or world message, a reply's bytes. */
static int64_t sched_next(const struct app *a, const struct sched *sc)
{
	const struct sim *s = a->sim;
	int64_t t = sc->next_step;
	if (a->lcm && sc->next_truth < t)
		t = sc->next_truth;
	if (a->lcm && sc->next_world < t)
		t = sc->next_world;
	for (size_t i = 0; i < s->nbuses; i++) {
		int64_t tx = sim_bus_next_tx(&s->buses[i], a->tx_slice_ns);
		if (tx < t)
			t = tx;
	}
	return t;
}

/* Time is now: physics, messages, replies due by then, then the clock's own. */
static void advance(struct app *a, struct sched *sc, int64_t now)
{
	struct sim *s = a->sim;
	physics(a, now, &sc->next_step);
	if (now >= sc->next_truth) {
		if (a->lcm)
			publish_truth(a);
		sc->next_truth += sc->truth_ns;
		if (sc->next_truth <= now)
			sc->next_truth = now + sc->truth_ns;
	}
	if (now >= sc->next_world) {
		if (a->lcm)
			publish_world(a);
		if (!a->quiet)
			report_bad_input(a);
		sc->next_world += 1000000000;
	}
	if (a->lockstep && a->vt.inband)
		vt_hand_over(&a->vt, s, now);
	else
		for (size_t i = 0; i < s->nbuses; i++)
			sim_bus_flush(&s->buses[i], now);
	a->clock->moved(a, now);
}

/* Serve what is readable (the buses, LCM, the control socket, in lockstep
 * the daemons) for up to *wait; signals come in only here. */
static void serve_for(struct app *a, const struct timespec *wait)
{
	static struct pollfd fds[MAIN_MAX_FDS];
	static int bus_of[MAIN_MAX_FDS];
	sigset_t unblocked;
	sigemptyset(&unblocked);
	int n = build_pollset(a, fds, bus_of);
	if (wait_fds(fds, n, wait, &unblocked) > 0)
		serve(a, fds, bus_of, n);
}

static void run(struct app *a)
{
	struct sim *s = a->sim;
	int64_t t0 = a->clock->start(a);
	struct sched sc = { .truth_ns = (int64_t)llround(1e9 / s->cfg.truth_hz) };
	sc.next_step = t0 + a->step_ns;
	sc.next_truth = t0 + sc.truth_ns;
	sc.next_world = t0 + 1000000000;
	sc.end = s->cfg.duration_s > 0 ? t0 + (int64_t)llround(s->cfg.duration_s * 1e9) : INT64_MAX;
	sim_run_events(s, 0.0, t0);
	if (a->lcm)
		publish_world(a);
	for (;;) {
		int64_t now;
		struct timespec wait;
		enum clk_next next = a->clock->next(a, &sc, &now, &wait);
		if (next == CLK_END)
			break;
		if (next == CLK_WAIT) {
			serve_for(a, &wait);
			a->clock->served(a);
			continue;
		}
		advance(a, &sc, now);
	}
	a->wall_end = mono_ns();
}

/* ---- the system's clock ------------------------------------------------------------- */

static int64_t rt_start(struct app *a)
{
	a->served = true;   /* the first move is work at now */
	a->bench_cpu = cpu_seconds();
	a->bench_at = a->t0;
	a->next_bench = a->t0 + 1000000000;
	return a->t0;
}

/* Work at the clock's now and a wait until the next thing due take turns:
 * the descriptors are served once between two rounds of work even when
 * something is due at once. */
static enum clk_next rt_next(struct app *a, const struct sched *sc, int64_t *now, struct timespec *wait)
{
	if (!a->served) {
		int64_t deadline = sched_next(a, sc);
		if (sc->end < deadline)
			deadline = sc->end;
		int64_t left = deadline - mono_ns();
		*wait = left > 0 ? (struct timespec){ (time_t)(left / 1000000000), (long)(left % 1000000000) }
		                 : (struct timespec){ 0, 0 };
		return CLK_WAIT;
	}
	a->served = false;
	if (stop_signal)
		return CLK_END;
	*now = mono_ns();
	return *now >= sc->end ? CLK_END : CLK_NOW;
}

static void rt_served(struct app *a) { a->served = true; }

/* --bench: CPU and step lateness, once a second. */
static void rt_moved(struct app *a, int64_t now)
{
	if (!a->bench || now < a->next_bench)
		return;
	bench_line(a, now, &a->bench_cpu, &a->bench_at);
	a->next_bench += 1000000000;
}

static const struct sim_clock clock_real = {
	.start = rt_start, .next = rt_next, .served = rt_served, .moved = rt_moved,
};

/* ---- lockstep: virtual time ---------------------------------------------------------- */

/* The robots' daemons take commands from the schedule (sim.h robot_command). */
static int lockstep_robot_command(void *ctx, int bus, const char *text, char *why, size_t cap)
{
	return vt_command(&((struct app *)ctx)->vt, bus, text, why, cap);
}

/* Virtual time is t (ns): the clocks of this process follow (LCM utimes). */
static void lockstep_set_time(struct app *a, uint64_t t)
{
	a->vt.t_ns = t;
	clock_set_virtual(a->vt.mono0_us + t / 1000u, a->vt.wall0_us + (int64_t)(t / 1000u));
}

static int64_t lockstep_start(struct app *a)
{
	a->start_wall = mono_ns();
	lockstep_set_time(a, 0);
	return 0;
}

/* Time moves only while every daemon is blocked, to the earliest thing that
 * happens after now: what the simulation has due, a daemon's wake-up, the
 * end. Until then the descriptors are served, 100 ms of wall time at a time
 * (the stall watch runs in between). A signal, or the end, ends the run for
 * the daemons first: they make their safe stop in virtual time, and the
 * loop ends when they have left. */
static enum clk_next lockstep_next(struct app *a, const struct sched *sc, int64_t *now, struct timespec *wait)
{
	if (stop_signal && !a->vt.ending)
		vt_end(&a->vt, false, "the simulator was stopped (signal)");
	if (a->vt.ending && vt_clients(&a->vt) == 0)
		return CLK_END;
	if (!vt_all_blocked(&a->vt, a->sim)) {
		*wait = (struct timespec){ 0, 100000000 };
		return CLK_WAIT;
	}
	if (!a->vt.ending && (int64_t)a->vt.t_ns >= sc->end) {
		char why[80];
		snprintf(why, sizeof why, "the run's %.3f s are over", a->sim->cfg.duration_s);
		vt_end(&a->vt, false, why);
	}
	int64_t t = sched_next(a, sc);
	if (!a->vt.ending && sc->end < t)
		t = sc->end;
	uint64_t w = vt_next_wake(&a->vt, a->sim);
	if (w != LKS_NEVER && (int64_t)w < t)
		t = (int64_t)w;
	if (t < (int64_t)a->vt.t_ns)
		t = (int64_t)a->vt.t_ns;
	if (a->first_step_wall == 0 && t > 0)
		a->first_step_wall = mono_ns();
	lockstep_set_time(a, (uint64_t)t);
	*now = t;
	return CLK_NOW;
}

/* A daemon that stalls ends the run. */
static void lockstep_served(struct app *a)
{
	char why[VT_WHY_MAX];
	if (!vt_stalled(&a->vt, a->sim, mono_ns(), a->start_wall, a->lockstep_grace_ns, why, sizeof why))
		return;
	fprintf(stderr, "undulate-sim: %s: ending the run\n", why);
	if (a->vt.ending) {
		/* a daemon that does not finish its safe stop is left behind */
		for (size_t i = 0; i < VT_MAX_CLIENTS; i++)
			if (a->vt.c[i].fd >= 0) {
				close(a->vt.c[i].fd);
				a->vt.c[i].fd = -1;
			}
	}
	vt_end(&a->vt, true, why);
}

/* The daemons due are woken with the new time. */
static void lockstep_moved(struct app *a, int64_t now)
{
	vt_release(&a->vt, a->sim, (uint64_t)now, mono_ns());
}

static const struct sim_clock clock_lockstep = {
	.start = lockstep_start, .next = lockstep_next, .served = lockstep_served, .moved = lockstep_moved,
};

/* ---- start and stop ---------------------------------------------------------- */

/* After an X-series bus's word, one more: NAME.model=XL430-W250[,...] (one
 * model, or one per ID); an AX-12A bus's word stands alone, as before. */
static void print_models(const struct sim_bus *b)
{
	if (!bus_says_family(b))
		return;
	bool same = true;
	for (size_t k = 1; k < b->njoints; k++)
		same &= b->joints[k].model == b->joints[0].model;
	printf(" %s.model=", b->name);
	for (size_t k = 0; k < (same ? 1 : b->njoints); k++)
		printf("%s%s", k ? "," : "", sim_model_info(b->joints[k].model)->label);
}

static void print_ready(const struct sim *s, const char *url)
{
	printf("undulate-sim: ready: %zu bus%s:", s->nbuses, s->nbuses == 1 ? "" : "es");
	for (size_t i = 0; i < s->nbuses; i++) {
		printf(" %s=%s[", s->buses[i].name, s->buses[i].link);
		for (size_t k = 0; k < s->buses[i].njoints; k++)
			printf("%s%u", k ? "," : "", sim_joint_id(&s->buses[i].joints[k]));
		printf("]");
		print_models(&s->buses[i]);
	}
	printf(" bodies=%zu world=%s rate=%.0fHz lcm=%s\n", s->world.nbodies, s->plane ? "plane" : "row", s->cfg.rate_hz,
	       url[0] ? url : "default");
	fflush(stdout);
}

static void print_bus_summary(const struct app *a);

/* In lockstep the exit line holds only what the simulation decided (the same
 * seed prints the same line); the wall clock's figures have a line of their
 * own. The speed is taken from the first step: before it, the simulator only
 * waited for the daemons to join. */
static void print_summary_lockstep(const struct app *a, int64_t now)
{
	const struct sim *s = a->sim;
	double virt = 1e-9 * (double)a->vt.t_ns;
	double run = a->first_step_wall > 0 ? (double)(a->wall_end - a->first_step_wall) / 1e9 : 0.0;
	double joining = a->first_step_wall > 0 ? (double)(a->first_step_wall - a->t0) / 1e9 : 0.0;
	printf("undulate-sim: exit: %.3f s simulated, %llu steps, %llu collisions, total impulse %.6f N*s "
	       "(resting contact %.6f N*s over %llu pair-steps), %llu bad commands, %llu truth messages\n",
	       virt, (unsigned long long)s->steps, s->world.total_collisions - s->world.resting_contacts,
	       s->world.total_impulse, s->world.resting_impulse, s->world.resting_contacts,
	       (unsigned long long)s->bad_commands, (unsigned long long)a->truth_sent);
	printf("undulate-sim: lockstep: %.3f s of simulated time in %.3f s (%.1fx real time; %.3f s before it waiting "
	       "for the daemons to join, %.3f s in all, cpu %.1f%%); %llu daemon(s) joined, %llu wake-up(s), %llu "
	       "command(s) sent, bus bytes %s; ended: %s%s\n",
	       virt, run, run > 0 ? virt / run : 0.0, joining, (double)(now - a->t0) / 1e9,
	       now > a->t0 ? 100.0 * cpu_seconds() / ((double)(now - a->t0) / 1e9) : 0.0,
	       (unsigned long long)a->vt.joined, (unsigned long long)a->vt.wakes, (unsigned long long)a->vt.commands,
	       a->vt.inband ? "in-band" : "through the ptys", a->vt.end_why[0] ? a->vt.end_why : "-",
	       a->vt.failed ? " (FAILED)" : "");
	if (a->vt.bytes_lost > 0 || a->vt.bytes_dropped > 0 || a->vt.bad_messages > 0)
		printf("undulate-sim: lockstep: %llu bus byte(s) from daemons dropped (a port gone, or sent in a message "
		       "on the pty transport), %llu toward daemons dropped (more than a message carries), %llu bad "
		       "message(s)\n", (unsigned long long)a->vt.bytes_lost, (unsigned long long)a->vt.bytes_dropped,
		       (unsigned long long)a->vt.bad_messages);
	print_bus_summary(a);
}

static void print_summary(const struct app *a, int64_t now)
{
	const struct sim *s = a->sim;
	double wall = (double)(now - a->t0) / 1e9;
	if (a->lockstep) {
		print_summary_lockstep(a, now);
		return;
	}
	printf("undulate-sim: exit: %.1f s, %llu steps, %llu collisions, total impulse %.6f N*s "
	       "(resting contact %.6f N*s over %llu pair-steps), "
	       "worst step lateness %.0f us (p99 %.0f us, mean %.1f us), %llu overruns (simulated time stopped %.1f ms), cpu %.1f%%, "
	       "%llu bad commands, %llu truth messages\n",
	       wall, (unsigned long long)s->steps, s->world.total_collisions - s->world.resting_contacts,
	       s->world.total_impulse, s->world.resting_impulse, s->world.resting_contacts,
	       a->worst_late_us, late_quantile(a, 0.99), a->late_samples ? a->late_sum_us / (double)a->late_samples : 0.0,
	       (unsigned long long)a->overruns, (double)a->lost_ns / 1e6, wall > 0 ? 100.0 * cpu_seconds() / wall : 0.0,
	       (unsigned long long)s->bad_commands, (unsigned long long)a->truth_sent);
	print_bus_summary(a);
}

static void print_bus_summary(const struct app *a)
{
	const struct sim *s = a->sim;
	for (size_t i = 0; i < s->nbuses && !a->quiet; i++) {
		const struct sim_bus *b = &s->buses[i];
		const struct sim_bus_counters *c = &b->count;
		bool says = bus_says_family(b);
		printf("undulate-sim: bus %s%s%s%s: %llu packets, %llu replies, %llu bad %ss, ", b->name,
		       says ? " (Protocol " : "", says ? b->proto->name : "", says ? ")" : "",
		       (unsigned long long)c->packets, (unsigned long long)c->replies,
		       (unsigned long long)c->checksum_errors, b->proto->check_name);
		if (says)
			printf("%llu bad stuffing, ", (unsigned long long)c->stuffing_errors);
		printf("%llu header errors, %llu wrong-baud, %llu bytes dropped, %llu collisions on the line\n",
		       (unsigned long long)c->header_errors, (unsigned long long)c->wrong_baud,
		       (unsigned long long)c->tx_dropped, (unsigned long long)b->line.collisions);
	}
	fflush(stdout);
}

static void setup_signals(void)
{
	struct sigaction sa = { .sa_handler = on_signal };
	sigemptyset(&sa.sa_mask);
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
	signal(SIGPIPE, SIG_IGN);
	/* Signals arrive only inside pselect(): no half-done step is interrupted. */
	sigset_t block;
	sigemptyset(&block);
	sigaddset(&block, SIGINT);
	sigaddset(&block, SIGTERM);
	sigprocmask(SIG_BLOCK, &block, NULL);
}

int main(int argc, char **argv)
{
	static struct sim sim;      /* a few MB: static, allocated once */
	static struct app app;
	static struct sim_config cfg;
	struct options opt;
	char err[400] = "";
	if (parse_args(argc, argv, &opt) != 0)
		return 2;
	if (opt.send_cmd)
		return send_command(&opt);
	if (build_config(&opt, &cfg) != 0)
		return 2;
	if (sim_init(&sim, &cfg, err, sizeof(err)) != 0) {
		fprintf(stderr, "undulate-sim: %s\n", err);
		return 2;
	}
	app.sim = &sim;
	app.listen_fd = -1;
	app.bench = opt.bench;
	app.quiet = opt.quiet;
	for (int i = 0; i < MAIN_MAX_CLIENTS; i++)
		app.clients[i].fd = -1;
	app.step_ns = (int64_t)llround(1e9 / cfg.rate_hz);
	app.tx_slice_ns = (int64_t)llround(opt.tx_slice_us * 1000.0);
	app.truth_buf = malloc(MAIN_TRUTH_BUF);
	if (!app.truth_buf)
		snprintf(err, sizeof(err), "out of memory");
	setup_signals();
	if (opt.realtime) {
		struct sched_param sp = { .sched_priority = opt.realtime };
		if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
			fprintf(stderr, "undulate-sim: --realtime %d: %s (running with normal scheduling)\n", opt.realtime,
			        strerror(errno));
	}
	/* Default timer slack (50 µs) would smear reply times at 1 Mbps. */
	prctl(PR_SET_TIMERSLACK, 1000UL, 0, 0, 0);
	app.lcm = lcm_create(cfg.lcm_url[0] ? cfg.lcm_url : NULL);
	if (!app.lcm)
		fprintf(stderr, "undulate-sim: LCM (%s) unavailable: no ground truth, no SIM.CMD\n",
		        cfg.lcm_url[0] ? cfg.lcm_url : "default");
	/* In lockstep the simulator does not listen on LCM. A SIM.CMD comes at a
	 * wall-clock moment, which in virtual time is any moment, and a lockstep
	 * run is the same run for the same seed: its commands go in the
	 * scenario's [events]. Not listening also spares liblcm's receive
	 * thread (started by the first subscribe or lcm_get_fileno), which woke
	 * for every message on the group and dropped it: 69 000 wake-ups in a
	 * 45 s run of ten plane robots, a third of them the simulator's own
	 * collisions (measured: 4 % of the run's CPU). */
	app.lcm_listen = app.lcm != NULL && !opt.lockstep;
	lcm_subscription_t *sub = app.lcm_listen ? lcm_subscribe(app.lcm, "SIM.CMD", on_sim_cmd, &app) : NULL;
	if (app.lcm && opt.lockstep)
		printf("undulate-sim: lockstep: SIM.CMD is not listened to (a command from the network would land "
		       "at any simulated time): a run's commands go in its scenario's [events]\n");
	/* the links first: a simulator refused its links (another one serves
	 * them) must not have touched that one's control socket either */
	bool opened = app.truth_buf && sim_open(&sim, err, sizeof(err)) == 0;
	if (!opened || (cfg.control[0] && control_open(&app, cfg.control) != 0)) {
		if (err[0])
			fprintf(stderr, "undulate-sim: %s\n", err);
		if (opened)
			sim_close(&sim);
		return 1;
	}
	app.t0 = mono_ns();
	if (opt.lockstep) {
		if (vt_open(&app.vt, opt.lockstep, sim.nbuses, LKS_MONO0_US, LKS_WALL0_US, err, sizeof(err)) != 0) {
			fprintf(stderr, "undulate-sim: %s\n", err);
			sim_close(&sim);
			return 1;
		}
		/* the environment reaches runs started by scripts (figures, demo) */
		const char *env_pty = getenv("UNDULATE_LOCKSTEP_PTY");
		app.vt.inband = !opt.lockstep_pty && !(env_pty && !strcmp(env_pty, "1"));
		app.lockstep = true;
		app.lockstep_grace_ns = (int64_t)llround(opt.lockstep_grace_s * 1e9);
		if (app.tx_slice_ns < MAIN_LOCKSTEP_SLICE_NS)
			app.tx_slice_ns = MAIN_LOCKSTEP_SLICE_NS;
		sim.robot_command = lockstep_robot_command;
		sim.robot_command_ctx = &app;
	}
	print_ready(&sim, cfg.lcm_url);
	app.clock = app.lockstep ? &clock_lockstep : &clock_real;
	run(&app);
	int64_t now = mono_ns();
	sim_close(&sim);
	sim_free(&sim);
	if (app.lockstep)
		vt_close(&app.vt);
	if (app.listen_fd >= 0) {
		close(app.listen_fd);
		unlink(app.control_path);
	}
	print_summary(&app, now);
	if (app.lcm) {
		if (sub)
			lcm_unsubscribe(app.lcm, sub);
		lcm_destroy(app.lcm);
	}
	free(app.truth_buf);
	return app.lockstep && app.vt.failed ? 1 : 0;
}
