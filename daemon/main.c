/*
 * main.c — undulated: command line, configuration, then the loop (daemon.c).
 */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "auth.h"
#include "cmdin.h"
#include "config.h"
#include "daemon.h"
#include "log.h"
#include "outdir.h"
#include "tune.h"

/* Command-line overrides are applied in order after the file. */
#define MAIN_MAX_OVERRIDES 64

static void main_usage(FILE *f)
{
	fprintf(f,
	        "usage: undulated [CONFIG.conf] [options]\n"
	        "       undulated --command 'TEXT' --robot NAME|'*' [--lcm-url URL] [--timeout S]\n"
	        "                 [--key FILE] [--source NAME]\n"
	        "       undulated --gen-key FILE\n"
	        "       undulated --watch NAME|'*' [--rate HZ] [--raw] [--lcm-url URL] [--timeout S]\n"
	        "       undulated --tune [CONFIG.conf] --port PATH --ids 1,2 [--robot NAME]\n"
	        "                 [--target-freq HZ] [--target-amp RAD] [--out FILE]\n"
	        "\n"
	        "Runs one robot: reads its joints at 100 Hz over the Dynamixel bus, integrates\n"
	        "the limit-cycle oscillator from the measured state, writes goal positions and\n"
	        "publishes <robot>.STATE / .BUS / .PARAMS / .EVENT on LCM. See daemon/README.md.\n"
	        "\n"
	        "  -c, --config FILE      INI configuration (also accepted as the first argument)\n"
	        "      --set S.KEY=VALUE  override any key, e.g. --set joint.1.k=0.06 (repeatable)\n"
	        "      --port PATH        = --set robot.port=PATH\n"
	        "      --ids 1,2          = --set robot.ids=1,2\n"
	        "      --baud BPS         = --set robot.baud=BPS\n"
	        "      --protocol 1|2|auto = --set robot.protocol=...: Dynamixel 1.0 (AX-12) or 2.0\n"
	        "                         (XL430/XM430); auto (default) PINGs 1.0, then 2.0\n"
	        "      --robot NAME       = --set robot.name=NAME\n"
	        "      --mode MODE        = --set robot.mode=MODE (limp|hold|sinusoid|oscillator)\n"
	        "      --lcm-url URL      = --set robot.lcm_url=URL\n"
	        "      --lockstep SOCKET  = --set robot.lockstep=SOCKET: run in the simulator's virtual\n"
	        "                         time (undulate-sim --lockstep SOCKET), as fast as it goes\n"
	        "      --check-config     validate the configuration, print it with -v, and exit\n"
	        "  -v, --verbose          more log output (repeat for debug)\n"
	        "  -q, --quiet            warnings and errors only\n"
	        "      --log-level L      error|warn|info|debug\n"
	        "      --command TEXT     send one command and print the answer: 'mode oscillator',\n"
	        "                         'param k 0.06 [joint]', 'torque on|off', 'clear'; exit 0 if\n"
	        "                         accepted. Goes to the robot's local command socket; with\n"
	        "                         --key FILE it is signed and sent over LCM instead (robots\n"
	        "                         with commands = network)\n"
	        "      --key FILE         the robot's shared command key (64 hex digits, mode 600)\n"
	        "      --source NAME      who sends, as the robot logs it (default undulated@HOST:PID)\n"
	        "      --gen-key FILE     write a new random command key (mode 600) and exit\n"
	        "      --timeout S        how long --command waits for answers (default 1)\n"
	        "      --watch NAME|'*'   print what a robot publishes, in words: its state a few times\n"
	        "                         a second (mode by name, each joint's values with units),\n"
	        "                         every event, the bus once a second, the parameters when they\n"
	        "                         change (with --timeout S: for S seconds)\n"
	        "      --rate HZ          --watch: at most HZ states a second per robot (default 4;\n"
	        "                         a change of mode or fault is shown at once)\n"
	        "      --raw              --watch: every message as one key=value line, for scripts\n"
	        "                         (every state, 100 a second, unless --rate is given)\n"
	        "      --tune             run the oscillator on the connected robot and adjust k and mu until\n"
	        "                         every joint is within 5 %% of the target frequency and amplitude;\n"
	        "                         then write a complete configuration (with the SINUSOID baseline\n"
	        "                         set to the gait measured) to --out FILE (default NAME.conf)\n"
	        "      --target-freq HZ   --tune's frequency (default 0.8)\n"
	        "      --target-amp RAD   --tune's amplitude, each joint's half peak-to-peak (default 0.8)\n"
	        "      --tune-time S      --tune gives up after S seconds (default 90)\n"
	        "      --out FILE         where --tune writes the configuration ('-': standard output)\n"
	        "  -h, --help             this text\n");
}

enum {
	OPT_SET = 256, OPT_PORT, OPT_IDS, OPT_BAUD, OPT_ROBOT, OPT_MODE, OPT_LCM, OPT_CHECK, OPT_LOGLEVEL,
	OPT_COMMAND, OPT_TIMEOUT, OPT_WATCH, OPT_KEY, OPT_SOURCE, OPT_GENKEY, OPT_TUNE, OPT_TFREQ, OPT_TAMP,
	OPT_TTIME, OPT_OUT, OPT_LOCKSTEP, OPT_PROTOCOL, OPT_RATE, OPT_RAW,
};

struct main_args {
	const char *config;
	const char *overrides[MAIN_MAX_OVERRIDES];
	char owned[MAIN_MAX_OVERRIDES][CFG_PATH_MAX + 32];
	size_t noverrides;
	bool check;
	const char *command;
	const char *watch;
	double watch_rate_hz;   /* 0: not given */
	bool watch_raw;
	bool timeout_set;
	const char *robot;
	const char *lcm_url;
	double timeout_s;
	const char *key_file;
	const char *source;
	const char *gen_key;
	/* --tune */
	bool tune;
	struct tune_opts tune_opts;
	const char *out;
};

static bool main_add(struct main_args *a, const char *key, const char *value)
{
	if (a->noverrides == MAIN_MAX_OVERRIDES) {
		fprintf(stderr, "undulated: too many overrides (max %d)\n", MAIN_MAX_OVERRIDES);
		return false;
	}
	if (key == NULL) {
		a->overrides[a->noverrides++] = value;
		return true;
	}
	snprintf(a->owned[a->noverrides], sizeof a->owned[0], "robot.%s=%s", key, value);
	a->overrides[a->noverrides] = a->owned[a->noverrides];
	a->noverrides++;
	return true;
}

/* --timeout S: a finite number of seconds, 0 .. one day (0: --watch runs until
 * a signal, --command waits its default). */
#define MAIN_TIMEOUT_MAX_S 86400.0
static bool main_timeout(const char *text, double *s)
{
	char *end;
	double v = strtod(text, &end);
	if (end == text || *end != '\0' || !isfinite(v) || v < 0 || v > MAIN_TIMEOUT_MAX_S) {
		fprintf(stderr, "undulated: --timeout: '%s' is not a number of seconds (0..%.0f)\n", text,
		        MAIN_TIMEOUT_MAX_S);
		return false;
	}
	*s = v;
	return true;
}

/* NAME TEXT: a finite number in [lo, hi]. */
static bool main_number(const char *name, const char *text, double lo, double hi, const char *unit, double *out)
{
	char *end;
	double v = strtod(text, &end);
	if (end == text || *end != '\0' || !isfinite(v) || v < lo || v > hi) {
		fprintf(stderr, "undulated: %s: '%s' is not a number of %s from %g to %g\n", name, text, unit, lo, hi);
		return false;
	}
	*out = v;
	return true;
}

/* Returns -1 to continue, else an exit status. */
static int main_parse(int argc, char **argv, struct main_args *a)
{
	static const struct option opts[] = {
		{ "config", required_argument, NULL, 'c' }, { "set", required_argument, NULL, OPT_SET },
		{ "port", required_argument, NULL, OPT_PORT }, { "ids", required_argument, NULL, OPT_IDS },
		{ "baud", required_argument, NULL, OPT_BAUD }, { "robot", required_argument, NULL, OPT_ROBOT },
		{ "mode", required_argument, NULL, OPT_MODE }, { "lcm-url", required_argument, NULL, OPT_LCM },
		{ "lockstep", required_argument, NULL, OPT_LOCKSTEP }, { "protocol", required_argument, NULL, OPT_PROTOCOL },
		{ "check-config", no_argument, NULL, OPT_CHECK }, { "verbose", no_argument, NULL, 'v' },
		{ "quiet", no_argument, NULL, 'q' }, { "log-level", required_argument, NULL, OPT_LOGLEVEL },
		{ "command", required_argument, NULL, OPT_COMMAND }, { "timeout", required_argument, NULL, OPT_TIMEOUT },
		{ "watch", required_argument, NULL, OPT_WATCH }, { "rate", required_argument, NULL, OPT_RATE },
		{ "raw", no_argument, NULL, OPT_RAW }, { "key", required_argument, NULL, OPT_KEY },
		{ "source", required_argument, NULL, OPT_SOURCE }, { "gen-key", required_argument, NULL, OPT_GENKEY },
		{ "tune", no_argument, NULL, OPT_TUNE }, { "target-freq", required_argument, NULL, OPT_TFREQ },
		{ "target-amp", required_argument, NULL, OPT_TAMP }, { "tune-time", required_argument, NULL, OPT_TTIME },
		{ "out", required_argument, NULL, OPT_OUT },
		{ "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 },
	};
	int o;
	enum log_level lv;
	bool ok = true;
	a->timeout_s = 1.0;
	a->tune_opts = (struct tune_opts){ .target_freq = 0.8, .target_amp = 0.8, .max_s = TUNE_DEFAULT_MAX_S };
	while ((o = getopt_long(argc, argv, "c:vqh", opts, NULL)) != -1) {
		switch (o) {
		case 'c': a->config = optarg; break;
		case OPT_SET: ok = ok && main_add(a, NULL, optarg); break;
		case OPT_PORT: ok = ok && main_add(a, "port", optarg); break;
		case OPT_IDS: ok = ok && main_add(a, "ids", optarg); break;
		case OPT_BAUD: ok = ok && main_add(a, "baud", optarg); break;
		case OPT_ROBOT: a->robot = optarg; ok = ok && main_add(a, "name", optarg); break;
		case OPT_MODE: ok = ok && main_add(a, "mode", optarg); break;
		case OPT_LCM: a->lcm_url = optarg; ok = ok && main_add(a, "lcm_url", optarg); break;
		case OPT_LOCKSTEP: ok = ok && main_add(a, "lockstep", optarg); break;
		case OPT_PROTOCOL: ok = ok && main_add(a, "protocol", optarg); break;
		case OPT_CHECK: a->check = true; break;
		case 'v': log_set_level(log_get_level() < LOG_LVL_DEBUG ? log_get_level() + 1 : LOG_LVL_DEBUG); break;
		case 'q': log_set_level(LOG_LVL_WARN); break;
		case OPT_LOGLEVEL:
			if (!log_level_parse(optarg, &lv)) {
				fprintf(stderr, "undulated: --log-level: '%s' is not error, warn, info or debug\n", optarg);
				return 2;
			}
			log_set_level(lv);
			break;
		case OPT_COMMAND: a->command = optarg; break;
		case OPT_TIMEOUT:
			if (!main_timeout(optarg, &a->timeout_s))
				return 2;
			a->timeout_set = true;
			break;
		case OPT_WATCH: a->watch = optarg; break;
		case OPT_RATE:
			if (!main_number("--rate", optarg, 0.1, WATCH_RATE_MAX_HZ, "Hz", &a->watch_rate_hz))
				return 2;
			break;
		case OPT_RAW: a->watch_raw = true; break;
		case OPT_KEY: a->key_file = optarg; break;
		case OPT_SOURCE: a->source = optarg; break;
		case OPT_GENKEY: a->gen_key = optarg; break;
		case OPT_TUNE: a->tune = true; break;
		case OPT_TFREQ:
			if (!main_number("--target-freq", optarg, 0.1, 3.0, "Hz", &a->tune_opts.target_freq))
				return 2;
			break;
		case OPT_TAMP:
			if (!main_number("--target-amp", optarg, 0.05, 2.0, "rad", &a->tune_opts.target_amp))
				return 2;
			break;
		case OPT_TTIME:
			if (!main_number("--tune-time", optarg, 10.0, 600.0, "s", &a->tune_opts.max_s))
				return 2;
			break;
		case OPT_OUT: a->out = optarg; break;
		case 'h': main_usage(stdout); return 0;
		default: main_usage(stderr); return 2;
		}
	}
	if (!ok)
		return 2;
	if (!a->tune && (a->out || a->tune_opts.target_freq != 0.8 || a->tune_opts.target_amp != 0.8 ||
	                 a->tune_opts.max_s != TUNE_DEFAULT_MAX_S)) {
		fprintf(stderr, "undulated: --out, --target-freq, --target-amp and --tune-time go with --tune\n");
		return 2;
	}
	if (optind < argc && a->config == NULL)
		a->config = argv[optind++];
	if (optind < argc) {
		fprintf(stderr, "undulated: unexpected argument '%s' (see --help)\n", argv[optind]);
		return 2;
	}
	return -1;
}

static void main_print_errors(const struct cfg_errors *e)
{
	size_t shown = e->count < CFG_MAX_ERRORS ? e->count : CFG_MAX_ERRORS;
	for (size_t i = 0; i < shown; i++)
		fprintf(stderr, "undulated: config: %s\n", e->line[i]);
	if (e->count > shown)
		fprintf(stderr, "undulated: config: ... and %zu more error(s)\n", e->count - shown);
}

/* --tune --out FILE: the directory FILE is in must be ours, and no one
 * else's to write (outdir.h): the daemon runs as root, and a configuration
 * another user could swap decides where the joints go. The file is made
 * there under a temporary name (0666 less the umask: the service user reads
 * it) and renamed over FILE at the end, so a link at FILE is replaced, never
 * followed. 0, or 2 with a message (*dirfd closed). */
static int main_tune_out(const char *out, int *dirfd, struct outdir_file *of)
{
	char name[NAME_MAX + 1], err[1024];
	*dirfd = outdir_open_parent(out, name, sizeof name, err, sizeof err);
	if (*dirfd < 0) {
		fprintf(stderr, "undulated --tune: --out %s: %s\n", out, err);
		return 2;
	}
	if (outdir_file_create(of, *dirfd, name, err, sizeof err) < 0) {
		fprintf(stderr, "undulated --tune: cannot write next to %s: %s\n", out, err);
		close(*dirfd);
		return 2;
	}
	return 0;
}

/* --tune: run the tuner on the robot, then write what it found. Exit 0 done,
 * 1 start-up failed, 2 usage or configuration, 3 the targets were not
 * reached (nothing written), 130 stopped by a signal (nothing written). */
static int main_tune(const struct main_args *a, struct cfg *cfg)
{
	cfg->mode = CFG_MODE_OSCILLATOR;
	cfg->mode_given = true;
	static struct tune t;
	char why[TUNE_TEXT];
	if (!tune_init(&t, &a->tune_opts, cfg, NULL, why, sizeof why)) {
		fprintf(stderr, "undulated --tune: %s\n", why);
		return 2;
	}
	/* where the result goes, made before tuning: a minute on the robot is not
	 * lost to a directory that cannot be written */
	char def[CFG_NAME_MAX + 8];
	snprintf(def, sizeof def, "%s.conf", cfg->name);
	const char *out = a->out ? a->out : def;
	bool to_stdout = strcmp(out, "-") == 0;
	if (!a->out && access(def, F_OK) == 0) {
		fprintf(stderr, "undulated --tune: %s exists: name the file to write with --out FILE (it is replaced)\n",
		        def);
		return 2;
	}
	int dirfd = -1;
	struct outdir_file of = { .fd = -1 };
	if (!to_stdout) {
		int rc = main_tune_out(out, &dirfd, &of);
		if (rc != 0)
			return rc;
	}
	printf("tune: robot %s, joint(s) ", cfg->name);
	for (size_t j = 0; j < cfg->njoints; j++)
		printf("%s%u", j ? "," : "", cfg->ids[j]);
	printf(" on %s: target %.2f Hz, %.2f rad, every joint within %.0f %%; gives up after %.0f s; Ctrl-C stops "
	       "with the joints %s\n", cfg->port[0] ? cfg->port : cfg->usb_serial, t.opts.target_freq,
	       t.opts.target_amp, 100.0 * TUNE_TOLERANCE, t.opts.max_s,
	       cfg->safe_stop == CFG_SAFE_LIMP ? "limp" : "holding");
	fflush(stdout);
	struct timespec t0, t1;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	int rc = dmn_run_tune(cfg, &t, stdout);
	clock_gettime(CLOCK_MONOTONIC, &t1);
	double took = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
	if (rc != 0 || t.state != TUNE_DONE) {
		if (dirfd >= 0) {
			outdir_file_abandon(&of, false);
			close(dirfd);
		}
		if (rc != 0)
			return rc;
		if (t.state == TUNE_FAILED) {
			printf("tune: %s; nothing written\n", t.why);
			return 3;
		}
		printf("tune: stopped after %.0f s; nothing written\n", took);
		return 130;
	}
	char when[32];
	time_t now = time(NULL);
	strftime(when, sizeof when, "%Y-%m-%d %H:%M UTC", gmtime(&now));
	FILE *f = to_stdout ? stdout : fdopen(of.fd, "w");
	if (f == NULL) {
		fprintf(stderr, "undulated --tune: %s: %s\n", out, strerror(errno));
		outdir_file_abandon(&of, false);
		close(dirfd);
		return 1;
	}
	tune_write_config(&t, cfg, when, took, f);
	if (!to_stdout) {
		char err[512];
		bool ok = fflush(f) == 0 && fsync(fileno(f)) == 0;
		int werr = ok ? 0 : errno;
		ok = fclose(f) == 0 && ok;
		if (!ok) {
			fprintf(stderr, "undulated --tune: writing %s: %s\n", out, strerror(werr ? werr : errno));
			outdir_file_abandon(&of, true);
		} else if (outdir_file_commit(&of, true, err, sizeof err) != 0) {
			fprintf(stderr, "undulated --tune: writing %s: %s\n", out, err);
			ok = false;
		}
		close(dirfd);
		if (!ok)
			return 1;
	}
	printf("tune: done in %.0f s (%d windows): k x%.3f, mu ", took, t.iterations, t.result.k);
	for (size_t j = 0; j < cfg->njoints; j++)
		printf("%s%.4g", j ? "/" : "", t.result.mu[j]);
	printf(", lead %.3f s%s%s\n", t.result.lead, to_stdout ? "" : "; written to ", to_stdout ? "" : out);
	if (!to_stdout)
		printf("tune: run it with: undulated %s\n", out);
	return 0;
}

int main(int argc, char **argv)
{
	static struct main_args a;
	int rc = main_parse(argc, argv, &a);
	if (rc >= 0)
		return rc;
	if (a.gen_key != NULL) {
		char why[256];
		if (!auth_key_generate(a.gen_key, why, sizeof why)) {
			fprintf(stderr, "undulated --gen-key: %s\n", why);
			return 1;
		}
		printf("%s: a new command key (mode 600); give it to the robot (command_key = %s) and to whoever "
		       "commands it over the network (--key)\n", a.gen_key, a.gen_key);
		return 0;
	}
	if (a.watch != NULL) {
		struct watch_opts w = {
			.lcm_url = a.lcm_url, .robot = a.watch, .duration_s = a.timeout_set ? a.timeout_s : 0.0,
			.raw = a.watch_raw,
			/* words: a few a second by default; raw: every state unless asked */
			.rate_hz = a.watch_rate_hz > 0 ? a.watch_rate_hz : a.watch_raw ? 0.0 : WATCH_RATE_DEFAULT_HZ,
		};
		return dmn_watch(&w);
	}
	if (a.command != NULL) {
		if (a.robot == NULL) {
			fprintf(stderr, "undulated: --command needs --robot NAME (or '*' for every robot)\n");
			return 2;
		}
		struct send_opts o = {
			.lcm_url = a.lcm_url, .robot = a.robot, .text = a.command,
			.timeout_s = a.timeout_s > 0 ? a.timeout_s : 1.0, .key_file = a.key_file, .source = a.source,
		};
		return dmn_send_command(&o);
	}
	static struct cfg cfg;
	struct cfg_errors errors = { 0 };
	cfg_defaults(&cfg);
	if (a.config != NULL)
		cfg_load_file(&cfg, a.config, &errors);
	for (size_t i = 0; i < a.noverrides; i++)
		cfg_override(&cfg, a.overrides[i], &errors);
	if (errors.count == 0)
		cfg_finish(&cfg, &errors);
	if (errors.count > 0) {
		main_print_errors(&errors);
		/* a path that is no configuration file at all is a usage error, even
		 * for --check-config (which otherwise reports a config's errors with 1) */
		return a.check && !errors.file_refused ? 1 : 2;
	}
	if (a.check) {
		char why[512], note[512];
		const char *src = cfg.source[0] ? cfg.source : "command line";
		bool key_ok = cin_check_key(&cfg, why, sizeof why, note, sizeof note);
		if (!key_ok) {
			/* as the daemon would refuse it at start */
			fprintf(stderr, "undulated: config: %s: [robot] %s\n", src, why);
			return 1;
		}
		if (note[0] != '\0')
			printf("%s: note: [robot] %s\n", src, note);
		if (log_get_level() > LOG_LVL_INFO)
			cfg_print(&cfg, stdout);
		printf("%s: ok (robot %s, %zu joint(s), mode %s)\n", a.config ? a.config : "command line", cfg.name,
		       cfg.njoints, cfg_mode_name(cfg.mode));
		return 0;
	}
	if (a.tune)
		return main_tune(&a, &cfg);
	return dmn_run(&cfg);
}
