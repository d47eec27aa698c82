/*
 * wlcm.h — undulate-web's LCM receive path: the udpm group read in the
 * server's own loop, without LCM.
 *
 * LCM 1.3.1 reads each datagram in a thread of its own and hands it to the
 * loop through a pipe, so every message cost the loop a wakeup, a select, a
 * pipe read and a pipe write: half of undulate-web's CPU with 20 robots at
 * 100 Hz (bench/README.md, undulate-web). Here the group's socket is adopted
 * by the loop and drained with recvmmsg, up to WLCM_BATCH datagrams a call,
 * each a udpm small message ("LC02", common/wire.h) on a channel that matches
 * one of the subscriptions (POSIX extended regular expressions matched whole,
 * as LCM matches its own). Publishing (commands) stays with LCM.
 *
 * Fragmented messages ("LC03", over 64 kB: nothing undulate publishes is that
 * large) and datagrams that are not LCM are counted, not read. Another
 * provider than udpm (memq://, file://) keeps LCM's own path: wlcm_open says
 * so and the caller subscribes through LCM.
 */
#ifndef UNDULATE_WEB_WLCM_H
#define UNDULATE_WEB_WLCM_H

#include <regex.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define WLCM_MAX_SUBS 16
/* Datagrams taken by one recvmmsg, each up to 64 kB (a udpm small message). */
#define WLCM_BATCH 16
#define WLCM_DGRAM_MAX 65536

typedef void (*wlcm_handler)(const char *channel, const uint8_t *data, size_t n);

struct wlcm_counters {
	long long datagrams;        /* read from the group */
	long long messages;         /* on a subscribed channel, handed on */
	long long not_lcm;          /* not a udpm small message (LC03 fragments included) */
	long long truncated;        /* longer than WLCM_DGRAM_MAX */
};

struct wlcm {
	int fd;
	size_t nsubs;
	regex_t re[WLCM_MAX_SUBS];
	wlcm_handler handler[WLCM_MAX_SUBS];
	struct wlcm_counters n;
};

/* Opens the group of url for reading. False with *why when url is not a
 * udpm:// URL or the socket cannot be opened (the caller then uses LCM). */
bool wlcm_open(struct wlcm *w, const char *url, char *why, size_t cap);
void wlcm_close(struct wlcm *w);
/* Messages on channels matching pattern (whole) go to h; the first
 * subscription that matches takes a message. False when the pattern does
 * not compile or there is no room. */
bool wlcm_subscribe(struct wlcm *w, const char *pattern, wlcm_handler h);
/* Reads what has come (up to `rounds` recvmmsg calls) and hands each message
 * on; returns the datagrams read. */
int wlcm_drain(struct wlcm *w, int rounds);
/* The handler for a channel, or NULL: the matching rule alone (tests). */
wlcm_handler wlcm_match(const struct wlcm *w, const char *channel);
/* One datagram, as wlcm_drain takes it (tests, fuzzing). */
void wlcm_datagram(struct wlcm *w, const uint8_t *d, size_t n, bool truncated);

#endif
