/*
 * record.h — `undulate-analyze --record`: the LCM group into a log file, as
 * lcm-logger writes it (lcm_eventlog format: the analyser, lcm-logplayer and
 * lcm-spy read it), but without losing messages when the recorder falls
 * behind. LCM 1.3.1 queues at most 30 messages per subscription and drops the
 * rest silently; lcm-logger keeps that default, and a lockstep run on two
 * busy cores (ten robots publishing seven times faster than in real time)
 * lost about one message in a thousand to it.
 *
 * A udpm group is read here without liblcm: one socket on the group, read
 * with recvmmsg() in batches in the recorder's own poll() loop, LCM's
 * datagrams parsed (common/wire.h) and fragmented messages reassembled per
 * sender, events written through a large buffer. liblcm's receive thread cost
 * about seven system calls a message (its select, recvmsg, notify pipe and
 * futexes, and the main thread's poll, pipe read and futex, and a write per
 * event): a third of a lockstep run's system calls. Other URLs (file://,
 * memq://) go through liblcm, its queue bounded only by REC_QUEUE.
 */
#ifndef UNDULATE_ANALYZE_RECORD_H
#define UNDULATE_ANALYZE_RECORD_H

/* Messages the subscription may queue while the recorder waits for a core:
 * minutes of a twenty-robot run, a few hundred MB at most. */
#define REC_QUEUE 1000000
/* Kernel receive buffer asked for (bytes; the kernel caps it at
 * net.core.rmem_max) when the URL does not say recv_buf_size. */
#define REC_RCVBUF 4194304

/* A udpm message is at most this large (bytes of payload); a larger one is
 * refused and counted. LCM 1.3.1 allows 256 MB; undulate's messages are a few
 * kB, and a sender may hold one message in reassembly at a time. */
#define REC_MSG_MAX (4 << 20)
/* Senders (address and port) whose fragmented messages are reassembled at
 * once: a run has one process per robot and a few tools. One more evicts
 * the sender heard from least recently (its message in progress is lost). */
#define REC_SENDERS 32
/* Datagrams read by one recvmmsg(). */
#define REC_BATCH 64
/* Events reach the file at most this long (ms) after they arrive, the
 * socket drained first. */
#define REC_FLUSH_MS 100
/* After a read that found messages, the recorder waits this long before it
 * looks again, so the next read takes all that came meanwhile: a lockstep
 * run publishes thousands of small bursts a second, and a recorder woken by
 * each (2.8 datagrams a read, measured) paid a context switch for each, the
 * dearest thing on a paravirtualised machine. 5 ms is nothing to a log
 * (each event keeps its kernel receive time) and a few hundred kB of
 * datagrams at the fastest run measured, inside the 4 MB receive buffer. */
#define REC_GATHER_MS 5

/* Record until SIGINT or SIGTERM. Prints a readiness line ("recording ...")
 * on stdout once subscribed, and a summary at the end. Returns an
 * AN_EXIT_* status. */
int rec_run(const char *path, const char *url);

#endif
