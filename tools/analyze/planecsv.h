/* planecsv.h — the plane world's poses for plane.csv (README.md, "The plane
 * world"): which SIM.TRUTH messages are sampled, and a robot's centre and
 * heading from its links. Pure: no I/O, no clock. */
#ifndef UNDULATE_ANALYZE_PLANECSV_H
#define UNDULATE_ANALYZE_PLANECSV_H

#include <stdbool.h>

#include "undulate_sim_link_t.h"

/* Takes one message per EVERY seconds on a fixed grid (0, EVERY, 2 EVERY,
 * ...: the first message at or after each mark), so the samples do not drift
 * with the messages' own spacing; EVERY = 0 takes every message. */
struct pcsv_sampler {
	double every_s;
	double next_t;
};

void pcsv_sampler_init(struct pcsv_sampler *s, double every_s);
/* Whether the message at T (s) is taken; advances the grid when it is. */
bool pcsv_take(struct pcsv_sampler *s, double t);

/* Robot ROBOT's centre and heading from the N links of one message: the
 * centre is the mean of its links' centres (the simulator's robot centre,
 * whose x is the row view's neutral position: equal links, equal masses);
 * the heading the direction of the sum of its links' unit vectors (the mean
 * direction of the body), continuous like the links' angles (taken within
 * pi of the first link's). False when the message has no link of ROBOT. */
bool pcsv_robot_pose(const undulate_sim_link_t *links, int n, int robot, double *cx, double *cy,
		     double *heading);

#endif
