/*
 * vtime.h — the simulator's side of lockstep (common/lockstep.h): the
 * daemons that drive its buses, what each is waiting for, and the barrier
 * that lets virtual time move only while every one of them is blocked.
 *
 * main.c owns the loop: it polls the listening socket and the daemons'
 * sockets with everything else, and asks vt_all_blocked() before it moves
 * time. Moving time to t is: physics up to t, replies due by t released on
 * the buses, then vt_release(), which wakes every daemon whose wake-up came,
 * whose bus has bytes it has not been told of (when it waits for input), or
 * that has a command or the end of the run to receive.
 *
 * A daemon that does not come back within the wall-clock grace, or leaves
 * before the end, ends the run (vt_stalled, vt_left): never a hang.
 */
#ifndef UNDULATE_SIM_VTIME_H
#define UNDULATE_SIM_VTIME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "lockstep.h"
#include "sim.h"

/* At most one daemon per bus, and a few connections that are not (yet) one. */
#define VT_MAX_CLIENTS (SIM_MAX_BUSES + 4)
#define VT_WHY_MAX 400

/* One bus of a daemon's (its index on the connection: the HELLO's c). */
struct vt_link {
	int bus;                    /* index into sim->buses */
	bool want_input;            /* its last WAIT (PART) asked to be woken by this bus's bytes */
	/* in-band: which of the bus's ptys its port is on (sim_bus.opens; 0:
	 * none yet), and the bytes released toward it since its last TIME */
	uint64_t port_open;
	uint8_t out[LKS_BYTES_MAX];
	size_t nout;
	bool said_lost;             /* bytes for a port gone said once */
	bool rate_unread;           /* in-band: it opened its port or set its rate since its last bytes */
};

/* A daemon: one connection, one barrier entry, one or several buses. */
struct vt_client {
	int fd;                     /* -1: free */
	int bus;                    /* its first bus (l[0].bus); -1 until every HELLO came */
	struct vt_link l[LKS_BUSES_MAX];
	size_t nl;                  /* buses named so far */
	size_t nnamed;              /* buses it said it drives (its first HELLO's b) */
	char robot[LKS_NAME_MAX];
	long pid;
	bool blocked;               /* its WAIT is the last word: it does nothing until woken */
	uint64_t wake_ns;           /* LKS_NEVER: only input or a command wakes it */
	/* the pty transport (one bus): */
	uint64_t written;           /* bus bytes it has written (its last WAIT) */
	uint64_t rx_base, tx_base;  /* the bus's counters when it joined */
	uint64_t told;              /* bus bytes released toward it, as its last TIME said */
	char cmds[LKS_CMD_QUEUE][LKS_TEXT_MAX];
	size_t ncmds;
	bool stop_pending;          /* STOP goes with its next TIME */
	bool stop_sent;
	int64_t running_since_ns;   /* wall clock: when it was last woken (stall watch) */
	uint64_t wakes;
};

struct vt {
	int listen_fd;
	char path[256];
	struct vt_client c[VT_MAX_CLIENTS];
	size_t expected;            /* buses the run waits for daemons on: every one */
	uint64_t t_ns;              /* virtual now */
	uint64_t mono0_us;          /* the daemons' monotonic clock at virtual 0 */
	int64_t wall0_us;           /* and the wall clock */
	bool inband;                /* the bus bytes travel in WAIT and TIME (else through the ptys) */
	bool ending;                /* STOP sent (or to be sent) to everyone */
	bool failed;                /* the run ended because something went wrong */
	char end_why[VT_WHY_MAX];
	uint64_t joined, left, refused, bad_messages, commands, wakes;
	uint64_t bad_parts;         /* PARTs for a bus index the daemon did not name (also in bad_messages) */
	/* in-band: bytes a daemon wrote to a port that is gone (the pty's EIO),
	 * or on the pty transport in a WAIT; bytes toward a daemon its TIME could
	 * not hold */
	uint64_t bytes_lost, bytes_dropped;
};

/* Listen at path for daemons on `expected` buses. mono0_us / wall0_us: the clocks'
 * values at virtual time 0. The bytes go in-band unless v->inband is
 * cleared before the first daemon joins. 0, or -1 with err. */
int vt_open(struct vt *v, const char *path, size_t expected, uint64_t mono0_us, int64_t wall0_us, char *err,
            size_t cap);
/* Close every connection and remove the socket file. */
void vt_close(struct vt *v);
/* A connection waits on the listening socket. */
void vt_accept(struct vt *v);
/* Client i's socket is readable: take one message (HELLO, PART, WAIT, BYE,
 * or its end). In-band, the bytes a WAIT or BYE carries go into its bus now
 * (sim_bus_receive). wall_ns: the wall clock now. */
void vt_on_client(struct vt *v, struct sim *s, size_t i, int64_t wall_ns);
/* Daemons connected and joined (every bus each named). */
size_t vt_clients(const struct vt *v);
/* Buses those daemons cover. */
size_t vt_buses_covered(const struct vt *v);
/* Time may move: daemons on every expected bus have joined (unless the run is
 * ending), every one is blocked, and (pty transport) every byte each has
 * written to its bus has been read by the simulator; in-band they came with
 * its WAIT. */
bool vt_all_blocked(const struct vt *v, const struct sim *s);
/* The earliest virtual time a blocked daemon must be woken at (ns):
 * its wake-up, or now when it has something to receive. LKS_NEVER if none. */
uint64_t vt_next_wake(const struct vt *v, const struct sim *s);
/* In-band: the bytes due at now on every bus go to the bus's daemon, for
 * its next TIME (instead of sim_bus_flush's pty). */
void vt_hand_over(struct vt *v, struct sim *s, int64_t now);
/* Time is t now: wake the daemons that are due (commands, STOP, TIME). */
void vt_release(struct vt *v, const struct sim *s, uint64_t t, int64_t wall_ns);
/* Queue a command for the daemon of bus (or of every bus: -1). 0, or -1 with
 * why (no daemon on that bus, its queue full). */
int vt_command(struct vt *v, int bus, const char *text, char *why, size_t cap);
/* End the run: every daemon gets STOP with its next TIME. failed: something
 * went wrong (the exit status says so). */
void vt_end(struct vt *v, bool failed, const char *why);
/* A daemon has been running (not blocked) for longer than grace_ns of wall
 * time, or the expected ones did not all join within it: true with *why. */
bool vt_stalled(const struct vt *v, const struct sim *s, int64_t wall_ns, int64_t start_wall_ns, int64_t grace_ns,
                char *why, size_t cap);

#endif
