/*
 * daemon.h — undulated's event loop: one thread, one poll() over the control
 * timer, the bus (every bus, for a robot on several) and the deadline timer,
 * the command sockets and signals.
 * Owns the port and reconnecting; the cycle's bus work is cycle.h's, the
 * control the controller's (control.h), commands cmdin.h's, publishing
 * publish.h's, start-up and the safe stop setup.h's.
 */
#ifndef UNDULATE_DAEMON_DAEMON_H
#define UNDULATE_DAEMON_DAEMON_H

#include "config.h"

/* Run the robot until SIGTERM/SIGINT. Returns the process exit status:
 * 0 after a clean safe stop, 1 when start-up failed (the bus, a servo: worth
 * a retry), 2 when the configuration cannot work (not worth one; also a port
 * that refuses the configured rs485 mode). */
int dmn_run(const struct cfg *cfg);

/* `undulated --tune`: the same loop in OSCILLATOR, with the tuner (tune.h)
 * fed every cycle and its parameters applied at the cycle boundary, until it
 * is done or has given up (or a signal). Then the usual safe stop. Progress
 * lines go to `progress` (a FILE *). Returns as dmn_run(); what the tuner
 * found is in *t, and what the robot ran with in t->ran. */
struct tune;
int dmn_run_tune(const struct cfg *cfg, struct tune *t, void *progress);

/* `undulated --command TEXT`: send one command to robot (or "*") and print
 * the answers within timeout_s. 0 if accepted (by every robot that
 * answered), 1 if rejected or unanswered, 2 on a usage error. */
struct send_opts {
	const char *lcm_url;      /* NULL: LCM's default */
	const char *robot;
	const char *text;
	double timeout_s;
	const char *key_file;     /* NULL: the local command socket; else signed, over LCM */
	const char *source;       /* NULL: "undulated@HOST:PID" */
};
int dmn_send_command(const struct send_opts *o);

/* `undulated --watch ROBOT`: print the robot's STATE/EVENT/BUS/PARAMS
 * messages (robot "*": every robot) until a signal or for duration_s
 * seconds (0: until a signal). In words for a person: at most rate_hz
 * states a second per robot, every event, the bus once a second and the
 * parameters when they change; raw: every message as one key=value line
 * (the format scripts parse), rate_hz 0 meaning every state. */
struct watch_opts {
	const char *lcm_url;
	const char *robot;
	double duration_s;
	double rate_hz;   /* 0: every state */
	bool raw;
};
#define WATCH_RATE_DEFAULT_HZ 4.0
#define WATCH_RATE_MAX_HZ 1000.0
int dmn_watch(const struct watch_opts *o);

#endif
