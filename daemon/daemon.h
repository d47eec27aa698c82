/*
 * daemon.h — undulated's event loop: one thread, one poll() over the control
 * timer, the bus, the bus-deadline timer, LCM and signals. Owns the port, the
 * bus state machine of each cycle, reconnecting, LCM publishing and commands.
 */
#ifndef UNDULATE_DAEMON_DAEMON_H
#define UNDULATE_DAEMON_DAEMON_H

#include "config.h"

/* Run the robot until SIGTERM/SIGINT. Returns the process exit status:
 * 0 after a clean safe stop, 1 when start-up failed. */
int dmn_run(struct cfg *cfg);

/* `undulated --command TEXT`: publish one command_t to robot (or "*") and
 * print the answering events within timeout_s. 0 if accepted (by every robot
 * that answered), 1 if rejected or unanswered, 2 on a usage error. */
int dmn_send_command(const char *lcm_url, const char *robot, const char *text, double timeout_s);

/* `undulated --watch ROBOT`: print the robot's STATE/EVENT/BUS/PARAMS
 * messages as text lines (robot "*": every robot) until a signal or for
 * duration_s seconds (0: until a signal). */
int dmn_watch(const char *lcm_url, const char *robot, double duration_s);

#endif
