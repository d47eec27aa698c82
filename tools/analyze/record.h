/*
 * record.h — `undulate-analyze --record`: the LCM group into a log file, as
 * lcm-logger writes it (lcm_eventlog format: the analyser, lcm-logplayer and
 * lcm-spy read it), but without losing messages when the recorder falls
 * behind. LCM 1.3.1 queues at most 30 messages per subscription and drops the
 * rest silently; lcm-logger keeps that default, and a lockstep run on two
 * busy cores (ten robots publishing seven times faster than in real time)
 * lost about one message in a thousand to it. Here the queue is bounded only
 * by REC_QUEUE and the kernel's receive buffer is asked for REC_RCVBUF.
 */
#ifndef UNDULATE_ANALYZE_RECORD_H
#define UNDULATE_ANALYZE_RECORD_H

/* Messages the subscription may queue while the recorder waits for a core:
 * minutes of a twenty-robot run, a few hundred MB at most. */
#define REC_QUEUE 1000000
/* Kernel receive buffer asked for (bytes; the kernel caps it at
 * net.core.rmem_max) when the URL does not say recv_buf_size. */
#define REC_RCVBUF 4194304

/* Record until SIGINT or SIGTERM. Prints a readiness line ("recording ...")
 * on stdout once subscribed, and a summary at the end. Returns an
 * AN_EXIT_* status. */
int rec_run(const char *path, const char *url);

#endif
