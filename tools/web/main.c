/* undulate-web — live dashboard of every robot on the LCM network, in a
 * browser. See tools/web/README.md. */
#include <arpa/inet.h>
#include <getopt.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "num.h"
#include "req.h"
#include "server.h"
#include "wtok.h"

#define WEB_DEFAULT_ADDR "127.0.0.1"
#define WEB_DEFAULT_PORT 8080
#define WEB_CHARTJS "/usr/share/javascript/chart.js/chart.min.js"

static void usage(FILE *f)
{
	fputs("usage: undulate-web [--listen ADDR:PORT] [--lcm-url URL] [--read-only] [--allow-remote]\n"
	      "                    [--allow-host NAME]... [--allow-origin URL]... [--token-file FILE]\n"
	      "                    [--key FILE] [--page-dir DIR]\n"
	      "                    [--chartjs FILE] [-v]\n"
	      "A live dashboard of every robot on the LCM network, at http://ADDR:PORT/.\n"
	      "  --listen ADDR:PORT  where to listen (default 127.0.0.1:8080; port 0: any free port, printed)\n"
	      "  --allow-remote      required to listen on an address other than loopback; then commands\n"
	      "                      need --token-file, or use --read-only\n"
	      "  --allow-host NAME   a name by which browsers reach this server (repeatable); always allowed:\n"
	      "                      localhost, its address, and beyond loopback this computer's name\n"
	      "  --allow-origin URL  a web page of another origin that may open the read-only Foxglove\n"
	      "                      WebSocket, e.g. https://app.foxglove.dev (repeatable)\n"
	      "  --token-file FILE   commands need this secret (the file's first line; mode 0600):\n"
	      "                      open the page as http://ADDR:PORT/#token=SECRET. Without it\n"
	      "                      (on loopback) a token is made at start, written to the run\n"
	      "                      directory (mode 0600) and printed in the page's URL; a page\n"
	      "                      without the token watches and never commands\n"
	      "  --read-only         no commands: the page shows no controls, the server refuses them\n"
	      "  --key FILE          send commands signed over LCM (robots with commands = network),\n"
	      "                      as undulated --command --key; default: local command sockets\n"
	      "  --lcm-url URL       LCM provider (default: $LCM_DEFAULT_URL or udpm ttl=0)\n"
	      "  --page-dir DIR      the page's files (default: found beside the program)\n"
	      "  --chartjs FILE      Chart.js (default " WEB_CHARTJS ", Debian libjs-chart.js)\n"
	      "  -v, --verbose       more messages\n",
	      f);
}

/* "ADDR:PORT", "[V6]:PORT" or ":PORT" / "PORT" (loopback). */
static int parse_listen(const char *s, char *addr, size_t cap, int *port)
{
	const char *colon = strrchr(s, ':');
	const char *p = colon ? colon + 1 : s;
	size_t alen = colon ? (size_t)(colon - s) : 0;
	const char *a = s;
	if (alen >= 2 && s[0] == '[' && s[alen - 1] == ']') {
		a++;
		alen -= 2;
	}
	long v;
	if (num_parse_long(p, 0, 65535, &v) != NUM_OK || alen >= cap) {
		fprintf(stderr, "undulate-web: --listen: want ADDR:PORT (e.g. 127.0.0.1:8080), not \"%s\"\n", s);
		return -1;
	}
	if (alen == 0)
		snprintf(addr, cap, "%s", WEB_DEFAULT_ADDR);
	else
		snprintf(addr, cap, "%.*s", (int)alen, a);
	*port = (int)v;
	return 0;
}

static bool is_loopback(const char *addr)
{
	struct in_addr v4;
	struct in6_addr v6;
	if (inet_pton(AF_INET, addr, &v4) == 1)
		return (ntohl(v4.s_addr) >> 24) == 127;
	if (inet_pton(AF_INET6, addr, &v6) == 1)
		return IN6_IS_ADDR_LOOPBACK(&v6);
	return strcmp(addr, "localhost") == 0;
}

/* A name for --allow-host: a DNS name's characters, not an address (those
 * are allowed by what they are, req.h). */
static bool host_name_ok(const char *s)
{
	size_t n = strlen(s);
	return n > 0 && n < 254 && strspn(s, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789.-") == n;
}

/* An origin as a browser sends it: scheme and host[:port], no path. */
static bool origin_ok(const char *s)
{
	const char *rest = strncmp(s, "https://", 8) == 0 ? s + 8 : strncmp(s, "http://", 7) == 0 ? s + 7 : NULL;
	size_t n = rest != NULL ? strlen(rest) : 0;
	return n > 0 && n < 200 && strspn(rest, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789.-:[]") == n;
}

/* Beyond loopback, this computer's own name reaches it (http://labpc:8080/):
 * as gethostname says, and its first label. */
static void add_own_names(struct req_hosts *h)
{
	static char full[256], label[256];
	if (gethostname(full, sizeof full - 1) != 0 || !host_name_ok(full))
		return;
	snprintf(label, sizeof label, "%.*s", (int)strcspn(full, "."), full);
	if (h->nnames < REQ_HOSTS_MAX)
		h->names[h->nnames++] = full;
	if (strcmp(label, full) != 0 && h->nnames < REQ_HOSTS_MAX)
		h->names[h->nnames++] = label;
}

/* The page beside the program: installed (PREFIX/bin -> PREFIX/share/undulate/web)
 * or in the source tree (build/bin -> tools/web/page). */
static const char *find_page_dir(void)
{
	static char dir[PATH_MAX];
	char exe[PATH_MAX];
	ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
	if (n <= 0)
		return NULL;
	exe[n] = '\0';
	char *slash = strrchr(exe, '/');
	if (slash == NULL)
		return NULL;
	*slash = '\0';
	static const char *const rel[] = { "../share/undulate/web", "../../tools/web/page" };
	for (size_t i = 0; i < sizeof rel / sizeof rel[0]; i++) {
		char probe[PATH_MAX + 64];
		if (strlen(exe) + strlen(rel[i]) + 2 > sizeof dir)
			continue;
		memcpy(dir, exe, strlen(exe));
		dir[strlen(exe)] = '/';
		memcpy(dir + strlen(exe) + 1, rel[i], strlen(rel[i]) + 1);
		snprintf(probe, sizeof probe, "%s/index.html", dir);
		if (access(probe, R_OK) == 0)
			return dir;
	}
	return NULL;
}

int main(int argc, char **argv)
{
	enum { O_LISTEN = 256, O_URL, O_RO, O_REMOTE, O_TOKEN, O_KEY, O_PAGE, O_CHARTJS, O_HOST, O_ORIGIN };
	static const struct option opts[] = {
		{ "listen", required_argument, NULL, O_LISTEN },   { "lcm-url", required_argument, NULL, O_URL },
		{ "read-only", no_argument, NULL, O_RO },          { "allow-remote", no_argument, NULL, O_REMOTE },
		{ "allow-host", required_argument, NULL, O_HOST }, { "allow-origin", required_argument, NULL, O_ORIGIN },
		{ "token-file", required_argument, NULL, O_TOKEN }, { "key", required_argument, NULL, O_KEY },
		{ "page-dir", required_argument, NULL, O_PAGE },   { "chartjs", required_argument, NULL, O_CHARTJS },
		{ "help", no_argument, NULL, 'h' },                { "verbose", no_argument, NULL, 'v' },
		{ NULL, 0, NULL, 0 },
	};
	static char addr[128] = WEB_DEFAULT_ADDR;
	struct web_opts o = { .addr = addr, .port = WEB_DEFAULT_PORT, .chartjs = WEB_CHARTJS };
	bool remote = false;
	const char *token_file = NULL;
	int c;
	while ((c = getopt_long(argc, argv, "hv", opts, NULL)) != -1) {
		switch (c) {
		case O_LISTEN: if (parse_listen(optarg, addr, sizeof addr, &o.port)) return 2; break;
		case O_URL: o.lcm_url = optarg; break;
		case O_RO: o.read_only = true; break;
		case O_REMOTE: remote = true; break;
		case O_HOST:
			/* two places stay for this computer's own names */
			if (!host_name_ok(optarg) || o.hosts.nnames >= REQ_HOSTS_MAX - 2) {
				fprintf(stderr, "undulate-web: --allow-host \"%s\": want a host name (letters, digits, "
				        "'.', '-'), at most %d of them\n", optarg, REQ_HOSTS_MAX - 2);
				return 2;
			}
			o.hosts.names[o.hosts.nnames++] = optarg;
			break;
		case O_ORIGIN:
			if (!origin_ok(optarg) || o.nfox_origins >= WEB_FOX_ORIGINS) {
				fprintf(stderr, "undulate-web: --allow-origin \"%s\": want http:// or https:// and a host "
				        "(e.g. https://app.foxglove.dev), at most %d of them\n", optarg, WEB_FOX_ORIGINS);
				return 2;
			}
			o.fox_origins[o.nfox_origins++] = optarg;
			break;
		case O_TOKEN: token_file = optarg; break;
		case O_KEY: o.key_file = optarg; break;
		case O_PAGE: o.page_dir = optarg; break;
		case O_CHARTJS: o.chartjs = optarg; break;
		case 'v': o.verbose = true; break;
		case 'h': usage(stdout); return 0;
		default: usage(stderr); return 2;
		}
	}
	if (optind < argc) {
		fprintf(stderr, "undulate-web: unexpected argument \"%s\" (--help)\n", argv[optind]);
		return 2;
	}
	o.hosts.listen = addr;
	if (!is_loopback(addr))
		add_own_names(&o.hosts);
	if (!is_loopback(addr) && !remote) {
		fprintf(stderr, "undulate-web: --listen %s:%d opens the dashboard to the network; say so with "
		        "--allow-remote (and give --token-file FILE for commands, or --read-only)\n", addr, o.port);
		return 2;
	}
	static char token[REQ_TOKEN_MAX];
	char why[256];
	if (token_file != NULL) {
		if (!wtok_read(token_file, token, why, sizeof why)) {
			fprintf(stderr, "undulate-web: --token-file %s: %s\n", token_file, why);
			return 2;
		}
		o.token = token;
	}
	if (!is_loopback(addr) && !o.read_only && o.token == NULL) {
		fprintf(stderr, "undulate-web: listening on %s, commands would be open to anyone who reaches it: "
		        "give --token-file FILE or --read-only\n", addr);
		return 2;
	}
	/* commands carry this process's identity: on loopback too they need a
	 * token, made now when none was given (wtok.h) */
	o.make_token = !o.read_only && o.token == NULL;
	if (o.page_dir == NULL && (o.page_dir = find_page_dir()) == NULL) {
		fputs("undulate-web: cannot find the page (index.html) beside the program: --page-dir DIR\n", stderr);
		return 2;
	}
	if (access(o.chartjs, R_OK) != 0) {
		fprintf(stderr, "undulate-web: Chart.js not found at %s: install Debian's libjs-chart.js "
		        "(apt-get install libjs-chart.js) or give --chartjs FILE\n", o.chartjs);
		return 2;
	}
	return web_run(&o);
}
