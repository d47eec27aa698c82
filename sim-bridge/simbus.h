/*
 * simbus.h — one simulated Dynamixel bus: a pseudo-terminal exposed at a
 * stable path (a symlink), the servos wired to it with their motors and
 * faults, and the wire timing (see sim-bridge/README.md, "Timing model").
 *
 * sim_bus_feed() is the pure part (bytes in at a time, replies scheduled on
 * the line); sim_bus_open/poll/flush do the pty I/O around it.
 */
#ifndef UNDULATE_SIM_SIMBUS_H
#define UNDULATE_SIM_SIMBUS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dxl.h"
#include "dxl2.h"
#include "fault.h"
#include "joint.h"
#include "line.h"
#include "model.h"
#include "motor.h"
#include "servo.h"
#include "xdrive.h"
#include "xservo.h"

/* Servos on one bus: robots have two; test rigs and ID scans use a few more. */
#define SIM_BUS_MAX_SERVOS 32
#define SIM_NAME_MAX 32        /* robot / bus names */
#define SIM_PATH_MAX 256       /* link paths */

/* One servo with its joint physics and its injected faults. An AX-12A
 * (model 0, SIM_MODEL_AX12A) lives in `servo`; an X-series servo in `xservo`
 * with its controllers in `xdrive`. */
struct sim_joint {
	enum sim_model model;
	const struct sim_joint_ops *ops;   /* its family's (joint.h): set by sim_joint_place */
	struct sim_servo servo;
	struct sim_xservo xservo;
	struct sim_xdrive xdrive;
	struct sim_motor motor;
	struct sim_motor_params params;
	struct sim_faults faults;
};

struct sim_bus_counters {
	uint64_t rx_bytes, tx_bytes;
	uint64_t packets;          /* good instruction packets seen */
	uint64_t checksum_errors;  /* instruction packets with a bad checksum (2.0: CRC) */
	uint64_t header_errors;
	uint64_t stuffing_errors;  /* Protocol 2.0: a header inside a packet's body */
	uint64_t wrong_baud;       /* packets a servo missed because of its baud */
	uint64_t stale_drops;      /* partial packets dropped after a 100 ms gap */
	uint64_t tx_dropped;       /* bytes the pty would not take (nobody reading) */
	uint64_t replies;
	uint64_t disconnects;
};

struct sim_bus {
	char name[SIM_NAME_MAX];
	char link[SIM_PATH_MAX];
	char slave_path[SIM_PATH_MAX];
	long baud;                 /* the controller's rate on this bus, bps */
	long initial_baud;         /* the pty's rate when created (and re-created) */
	bool follow_tty;           /* baud = the rate the controller set on the pty */
	int64_t byte_ns;           /* 10 bits a byte at baud */
	int64_t latency_ns;        /* USB adapter hold time toward the controller */
	bool echo;                 /* single-wire adapter: the request comes back */
	const struct dxl_proto *proto;   /* what the bus speaks: 1.0 (AX-12A) or 2.0 (X series) */
	int master, slave;         /* -1 when disconnected */
	int link_lock;             /* the lock on the link (LINK.lock), held from the first open to release; -1 none */
	uint64_t opens;            /* ptys opened so far: which one a lockstep daemon's port is on */
	union dxl_proto_parser parser;   /* proto's, instruction side */
	struct dxl_frame frame;          /* the request parsed last */
	struct sim_line line;
	int64_t rx_free_at;        /* ns: when the request bytes so far end on the wire */
	int64_t last_rx;           /* ns: when the last byte came in */
	/* The last bytes the parser consumed, to find a bad packet's ID: the
	 * longest packet of either protocol. */
	uint8_t hist[DXL2_MAX_PACKET];
	size_t hist_n;
	struct sim_joint joints[SIM_BUS_MAX_SERVOS];
	size_t njoints;
	uint64_t rng;
	struct sim_bus_counters count;
};

/* Set up the bus (no I/O): name, link path, baud, latency (s), echo. */
void sim_bus_init(struct sim_bus *b, const char *name, const char *link, long baud, double latency_s,
                  bool echo, uint64_t seed);
/* The bus's protocol by number (1 or 2; 1 for anything else): the one
 * choice of protocol, made when the bus is set up; the bus parses and
 * answers that protocol's packets through its table (dxl_proto.h) and its
 * servos through their family's (joint.h). Its joints must all speak it
 * (the configuration checks). */
void sim_bus_set_protocol(struct sim_bus *b, int protocol);
/* The controller now talks at bps (byte time and pacing follow). */
void sim_bus_set_baud(struct sim_bus *b, long bps);
/* Whether a servo set to baud register value reg hears this bus (within 3 %). */
bool sim_bus_baud_matches(const struct sim_bus *b, uint8_t reg);
/* Whether the joint's servo is powered and set to this bus's rate. */
bool sim_joint_hears(const struct sim_bus *b, const struct sim_joint *j);

/* The joint's servo, whatever its model: ID, power, torque. */
uint8_t sim_joint_id(const struct sim_joint *j);
bool sim_joint_powered(const struct sim_joint *j);
bool sim_joint_torque(const struct sim_joint *j);

/* The pure core: n bytes from the controller, read at time now (ns).
 * Replies (and echo) are scheduled on b->line. */
void sim_bus_feed(struct sim_bus *b, const uint8_t *data, size_t n, int64_t now);
/* Put n bytes on the line right away (the "garbage" command). */
void sim_bus_inject(struct sim_bus *b, const uint8_t *data, size_t n, int64_t now);

/* ---- pty I/O ------------------------------------------------------------------ */
/* Create the pty (raw on both sides, a slave fd kept open so the pty survives
 * the controller closing it) and point the link at it. 0 or -1 with err.
 * The first open takes the link for this process (a lock file LINK.lock):
 * a link another live simulator holds is refused ("LINK: held by
 * undulate-sim (pid N, bus r1)"); one a killed simulator left is replaced. */
int sim_bus_open(struct sim_bus *b, char *err, size_t errcap);
/* Close the pty and remove the link (if it still points at our pty); the
 * link stays ours (the disconnect fault: a reconnect re-points it). */
void sim_bus_close(struct sim_bus *b);
/* sim_bus_close, and let the link go (its lock file removed). */
void sim_bus_release(struct sim_bus *b);
bool sim_bus_connected(const struct sim_bus *b);
/* Read whatever the controller wrote and feed it. */
void sim_bus_read(struct sim_bus *b, int64_t now);
/* Lockstep's in-band transport (common/lockstep.h): the controller's bytes
 * come in its clock message instead of the pty, into the same input path.
 * rate_may_differ: the controller opened its port or set its rate since its
 * last bytes: the rate on the pty is followed first, as sim_bus_read does
 * before every read (only then can it have changed). */
void sim_bus_receive(struct sim_bus *b, const uint8_t *data, size_t n, int64_t now, bool rate_may_differ);
/* ... and the bytes due at now go to out (up to cap) instead of the pty:
 * counted as sent; what does not fit, or finds the bus disconnected, is
 * dropped and counted as the pty's would be. The count copied. */
size_t sim_bus_hand_over(struct sim_bus *b, int64_t now, uint8_t *out, size_t cap);
/* Write the bytes due at now to the pty. */
void sim_bus_flush(struct sim_bus *b, int64_t now);
/* Next time (ns) to release bytes, in chunks of up to slice_ns (see
 * sim_line_chunk_end), INT64_MAX if none. */
int64_t sim_bus_next_tx(const struct sim_bus *b, int64_t slice_ns);

#endif
