/*
 * sim.h — the simulator: buses with their servos and motors, the contact
 * world, timed events and the command language shared by the scenario's
 * [events], the control socket and LCM SIM.CMD. No event loop here (main.c
 * owns it): sim_step() advances the physics by one step, sim_command()
 * executes one text command.
 */
#ifndef UNDULATE_SIM_SIM_H
#define UNDULATE_SIM_SIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "plane.h"
#include "scenario.h"
#include "simbus.h"
#include "world.h"

/* Walls on their way to a target ("walls LEFT RIGHT over S"): placed on the
 * straight line between from and to at every physics step, by simulated
 * time, so the same run moves them the same way whatever the wall clock. */
struct sim_wall_motion {
	bool active;
	double from_left, from_right, to_left, to_right;  /* m */
	double t0, t1;                                    /* s of simulated time */
};

struct sim {
	struct sim_config cfg;
	struct sim_bus buses[SIM_MAX_BUSES];
	size_t nbuses;
	/* The row world, or for world.kind = plane its view of the robots: one
	 * body per robot on its contact joint, its neutral position the robot's
	 * centre (x), with the totals and the step's collisions as the row's. */
	struct sim_world world;
	struct plane *plane;           /* the plane world (NULL: the row) */
	int plane_wall[4];             /* its walls: left, right, back, front (-1: none) */
	struct plane_drive plane_drives[PLANE_MAX_ROBOTS * PLANE_MAX_JOINTS];
	struct plane_joint plane_joints[PLANE_MAX_ROBOTS * PLANE_MAX_JOINTS];
	/* contacts since the last sim_contacts_drain(), either world: impulses
	 * summed per pair (the row: its bodies, link 0, a wall's index -1) */
	struct plane_contact contact_acc[PLANE_MAX_CONTACTS];
	size_t ncontact_acc;
	unsigned long long contact_acc_dropped;
	/* which joint each contact body rides on */
	int body_bus[SIM_MAX_BODIES];
	int body_joint[SIM_MAX_BODIES];
	double dt;
	uint64_t steps;
	/* collisions of the last step */
	struct sim_collision step_collisions[SIM_MAX_COLLISIONS_PER_STEP];
	size_t nstep_collisions;
	size_t next_event;
	uint64_t commands, bad_commands;
	uint64_t rng;
	struct sim_wall_motion wall_motion;
	/* "command ROBOT|* TEXT": a command for the robots' daemons, which only
	 * lockstep can deliver at a simulated time (main.c sets this then);
	 * NULL: refused. bus -1 = every robot. Returns daemons reached or -1. */
	int (*robot_command)(void *ctx, int bus, const char *text, char *why, size_t cap);
	void *robot_command_ctx;
};

/* Build everything from cfg (no I/O). 0 or -1 with err; sim_free() after
 * either (the plane world holds memory). */
int sim_init(struct sim *s, const struct sim_config *cfg, char *err, size_t errcap);
void sim_free(struct sim *s);
/* The contacts since the last call, impulses summed per pair of links (the
 * row world: of bodies, link 0; a wall's link_b its index, -1 for the row's
 * walls) and whether any began then; at most cap written, returns how many
 * there were. */
size_t sim_contacts_drain(struct sim *s, struct plane_contact *out, size_t cap);
/* Open every bus's pty and link. 0 or -1 with err (opened ones are closed). */
int sim_open(struct sim *s, char *err, size_t errcap);
/* Close every bus and let its link go (sim_bus_release). */
void sim_close(struct sim *s);
/* One physics step of s->dt: motors from the servo registers, contacts,
 * then the servos' present values and alarms. */
void sim_step(struct sim *s);
/* Execute one command line; the reply ("ok ..." / "error: ...") goes into
 * reply. now is the monotonic time in ns (for injected bytes). 0 or -1. */
int sim_command(struct sim *s, const char *line, int64_t now, char *reply, size_t cap);
/* Run the scenario events due at sim time t (s). */
void sim_run_events(struct sim *s, double t, int64_t now);
struct sim_bus *sim_find_bus(struct sim *s, const char *name_or_link);
struct sim_joint *sim_find_joint(struct sim_bus *b, uint8_t id);

#endif
