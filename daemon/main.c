/*
 * main.c — undulated: command line, configuration, then the loop (daemon.c).
 */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "auth.h"
#include "config.h"
#include "daemon.h"
#include "log.h"

/* Command-line overrides are applied in order after the file. */
#define MAIN_MAX_OVERRIDES 64

static void main_usage(FILE *f)
{
	fprintf(f,
	        "usage: undulated [CONFIG.conf] [options]\n"
	        "       undulated --command 'TEXT' --robot NAME|'*' [--lcm-url URL] [--timeout S]\n"
	        "                 [--key FILE] [--source NAME]\n"
	        "       undulated --gen-key FILE\n"
	        "       undulated --watch NAME|'*' [--lcm-url URL] [--timeout S]\n"
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
	        "      --robot NAME       = --set robot.name=NAME\n"
	        "      --mode MODE        = --set robot.mode=MODE (limp|hold|sinusoid|oscillator)\n"
	        "      --lcm-url URL      = --set robot.lcm_url=URL\n"
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
	        "      --watch NAME|'*'   print a robot's STATE/EVENT/BUS/PARAMS messages as text\n"
	        "                         lines (with --timeout S: for S seconds)\n"
	        "  -h, --help             this text\n");
}

enum {
	OPT_SET = 256, OPT_PORT, OPT_IDS, OPT_BAUD, OPT_ROBOT, OPT_MODE, OPT_LCM, OPT_CHECK, OPT_LOGLEVEL,
	OPT_COMMAND, OPT_TIMEOUT, OPT_WATCH, OPT_KEY, OPT_SOURCE, OPT_GENKEY,
};

struct main_args {
	const char *config;
	const char *overrides[MAIN_MAX_OVERRIDES];
	char owned[MAIN_MAX_OVERRIDES][CFG_PATH_MAX + 32];
	size_t noverrides;
	bool check;
	const char *command;
	const char *watch;
	bool timeout_set;
	const char *robot;
	const char *lcm_url;
	double timeout_s;
	const char *key_file;
	const char *source;
	const char *gen_key;
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

/* Returns -1 to continue, else an exit status. */
static int main_parse(int argc, char **argv, struct main_args *a)
{
	static const struct option opts[] = {
		{ "config", required_argument, NULL, 'c' }, { "set", required_argument, NULL, OPT_SET },
		{ "port", required_argument, NULL, OPT_PORT }, { "ids", required_argument, NULL, OPT_IDS },
		{ "baud", required_argument, NULL, OPT_BAUD }, { "robot", required_argument, NULL, OPT_ROBOT },
		{ "mode", required_argument, NULL, OPT_MODE }, { "lcm-url", required_argument, NULL, OPT_LCM },
		{ "check-config", no_argument, NULL, OPT_CHECK }, { "verbose", no_argument, NULL, 'v' },
		{ "quiet", no_argument, NULL, 'q' }, { "log-level", required_argument, NULL, OPT_LOGLEVEL },
		{ "command", required_argument, NULL, OPT_COMMAND }, { "timeout", required_argument, NULL, OPT_TIMEOUT },
		{ "watch", required_argument, NULL, OPT_WATCH }, { "key", required_argument, NULL, OPT_KEY },
		{ "source", required_argument, NULL, OPT_SOURCE }, { "gen-key", required_argument, NULL, OPT_GENKEY },
		{ "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 },
	};
	int o;
	enum log_level lv;
	bool ok = true;
	a->timeout_s = 1.0;
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
		case OPT_KEY: a->key_file = optarg; break;
		case OPT_SOURCE: a->source = optarg; break;
		case OPT_GENKEY: a->gen_key = optarg; break;
		case 'h': main_usage(stdout); return 0;
		default: main_usage(stderr); return 2;
		}
	}
	if (!ok)
		return 2;
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
	if (a.watch != NULL)
		return dmn_watch(a.lcm_url, a.watch, a.timeout_set ? a.timeout_s : 0.0);
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
		if (log_get_level() > LOG_LVL_INFO)
			cfg_print(&cfg, stdout);
		printf("%s: ok (robot %s, %zu joint(s), mode %s)\n", a.config ? a.config : "command line", cfg.name,
		       cfg.njoints, cfg_mode_name(cfg.mode));
		return 0;
	}
	return dmn_run(&cfg);
}
