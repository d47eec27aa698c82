/* udpm.c — see udpm.h. */
#include "udpm.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

const char *udpm_effective_url(const char *url)
{
	if (url != NULL && url[0] != '\0')
		return url;
	const char *env = getenv("LCM_DEFAULT_URL");
	return env != NULL && env[0] != '\0' ? env : UDPM_DEFAULT_URL;
}

static bool udpm_number(const char *s, size_t n, long min, long max, long *out)
{
	long v = 0;
	if (n == 0 || n > 9)
		return false;
	for (size_t i = 0; i < n; i++) {
		if (s[i] < '0' || s[i] > '9')
			return false;
		v = v * 10 + (s[i] - '0');
	}
	if (v < min || v > max)
		return false;
	*out = v;
	return true;
}

/* "ttl=1&recv_buf_size=2097152" */
static bool udpm_options(const char *opts, struct udpm_url *out, char *why, size_t cap)
{
	while (*opts) {
		const char *end = strchr(opts, '&');
		size_t len = end ? (size_t)(end - opts) : strlen(opts);
		const char *eq = memchr(opts, '=', len);
		long v;
		if (eq == NULL) {
			snprintf(why, cap, "option '%.*s' has no value", (int)len, opts);
			return false;
		}
		size_t klen = (size_t)(eq - opts), vlen = len - klen - 1;
		if (klen == 3 && strncmp(opts, "ttl", 3) == 0) {
			if (!udpm_number(eq + 1, vlen, 0, 255, &v)) {
				snprintf(why, cap, "ttl must be 0..255");
				return false;
			}
			out->ttl = (int)v;
		} else if (klen == 13 && strncmp(opts, "recv_buf_size", 13) == 0) {
			if (!udpm_number(eq + 1, vlen, 1, 1L << 28, &v)) {
				snprintf(why, cap, "recv_buf_size must be a byte count");
				return false;
			}
			out->recv_buf_size = v;
		} else {
			snprintf(why, cap, "unknown option '%.*s' (LCM 1.3.1's udpm knows ttl and recv_buf_size)",
			         (int)klen, opts);
			return false;
		}
		opts += len + (end ? 1 : 0);
	}
	return true;
}

bool udpm_parse_url(const char *url, struct udpm_url *out, char *why, size_t cap)
{
	static const char *const providers[] = { "udpm", "file", "memq", "tcpq" };
	memset(out, 0, sizeof *out);
	out->ttl = -1;
	url = udpm_effective_url(url);
	const char *sep = strstr(url, "://");
	size_t plen = sep ? (size_t)(sep - url) : 0;
	bool known = false;
	for (size_t i = 0; sep && i < sizeof providers / sizeof providers[0]; i++)
		known = known || (strlen(providers[i]) == plen && strncmp(url, providers[i], plen) == 0);
	if (!known) {
		snprintf(why, cap, "'%.80s' is not an LCM URL (udpm://GROUP:PORT?ttl=N, file://, memq://, tcpq://)", url);
		return false;
	}
	memcpy(out->provider, url, plen);
	out->provider[plen] = '\0';
	if (strcmp(out->provider, "udpm") != 0)
		return true;
	const char *host = sep + 3;
	const char *colon = strchr(host, ':');
	const char *q = strchr(host, '?');
	size_t hlen = colon ? (size_t)(colon - host) : q ? (size_t)(q - host) : strlen(host);
	char addr[64];
	if (hlen == 0 || hlen >= sizeof addr) {
		snprintf(why, cap, "'%.80s': no multicast group", url);
		return false;
	}
	memcpy(addr, host, hlen);
	addr[hlen] = '\0';
	if (inet_pton(AF_INET, addr, &out->group) != 1 || (ntohl(out->group.s_addr) >> 28) != 0xE) {
		snprintf(why, cap, "'%s' is not an IPv4 multicast group (224.0.0.0/4, e.g. 239.255.76.67)", addr);
		return false;
	}
	long port = 7667;
	if (colon != NULL) {
		size_t n = q ? (size_t)(q - colon - 1) : strlen(colon + 1);
		if (!udpm_number(colon + 1, n, 1, 65535, &port)) {
			snprintf(why, cap, "'%.80s': the port must be 1..65535", url);
			return false;
		}
	}
	out->port = (uint16_t)port;
	if (q != NULL && !udpm_options(q + 1, out, why, cap))
		return false;
	return true;
}

void udpm_net_name(const char *url, char *out, size_t cap)
{
	struct udpm_url u;
	char why[160], addr[INET_ADDRSTRLEN];
	url = udpm_effective_url(url);
	if (udpm_parse_url(url, &u, why, sizeof why) && strcmp(u.provider, "udpm") == 0 &&
	    inet_ntop(AF_INET, &u.group, addr, sizeof addr) != NULL) {
		snprintf(out, cap, "%s-%u", addr, (unsigned)u.port);
		return;
	}
	size_t i = 0;
	for (; url[i] && i + 1 < cap; i++) {
		char c = url[i];
		bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
		          c == '-';
		out[i] = ok ? c : '_';
	}
	if (cap > 0)
		out[i] = '\0';
}

int udpm_open_recv(const char *url, char *why, size_t cap)
{
	struct udpm_url u;
	if (!udpm_parse_url(url, &u, why, cap))
		return -1;
	if (strcmp(u.provider, "udpm") != 0) {
		snprintf(why, cap, "commands from the network need a udpm:// LCM URL, not %s://", u.provider);
		return -1;
	}
	int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (fd < 0) {
		snprintf(why, cap, "socket: %s", strerror(errno));
		return -1;
	}
	int one = 1;
	/* Bound to the group, not INADDR_ANY as LCM binds: a datagram sent to this
	 * host's own address (unicast, from anywhere that routes to it) is not
	 * delivered here, only the group's traffic. */
	struct sockaddr_in sa = { .sin_family = AF_INET, .sin_port = htons(u.port), .sin_addr = u.group };
	struct ip_mreq mreq = { .imr_multiaddr = u.group, .imr_interface.s_addr = htonl(INADDR_ANY) };
	if (setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
	    bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0 ||
	    setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0) {
		snprintf(why, cap, "udpm group %s:%u: %s (is there a multicast route?)", inet_ntoa(u.group),
		         (unsigned)u.port, strerror(errno));
		close(fd);
		return -1;
	}
	return fd;
}
