/*
 * udpm.h — LCM's udpm provider seen from outside LCM: its URL, and a receive
 * socket of our own on its multicast group. A daemon that takes (signed)
 * commands from the network reads them here instead of through
 * lcm_subscribe(): LCM 1.3.1 caches every channel name it ever hears in a
 * table that never shrinks (300 k invented names grew a daemon from 4 to 32
 * MB) and runs a thread that allocates per message. This socket is read in
 * the caller's poll() loop, one datagram at a time, into a fixed buffer.
 */
#ifndef UNDULATE_COMMON_UDPM_H
#define UNDULATE_COMMON_UDPM_H

#include <netinet/in.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* LCM's default when no URL is given and LCM_DEFAULT_URL is unset. */
#define UDPM_DEFAULT_URL "udpm://239.255.76.67:7667?ttl=0"

struct udpm_url {
	char provider[16];          /* "udpm", "file", "memq", "tcpq" */
	struct in_addr group;       /* udpm only */
	uint16_t port;
	int ttl;                    /* -1 when not given */
	long recv_buf_size;         /* bytes; 0 when not given */
};

/* The URL a program with `url` (NULL or "": LCM's default, $LCM_DEFAULT_URL
 * first) talks to. */
const char *udpm_effective_url(const char *url);
/* Checks a URL the way a configuration must be checked: a known provider,
 * and for udpm a multicast IPv4 group, a port 1..65535 and only the options
 * LCM 1.3.1 knows (ttl 0..255, recv_buf_size). False with *why. */
bool udpm_parse_url(const char *url, struct udpm_url *out, char *why, size_t cap);
/* A file-name-safe name of the network: "239.255.76.67-7667" for udpm, the
 * URL with other characters replaced by '_' otherwise. */
void udpm_net_name(const char *url, char *out, size_t cap);

/* A non-blocking socket receiving the udpm group's datagrams (SO_REUSEADDR,
 * as LCM's own sockets, so both hear every message). -1 with *why. */
int udpm_open_recv(const char *url, char *why, size_t cap);

#endif
