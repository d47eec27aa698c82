/*
 * webpub.c — N robots' <robot>.STATE at 100 Hz on LCM, each two joints on a
 * limit cycle of its own phase, and SIM.TRUTH with their bodies: the traffic
 * of a group of robots without the robots, so the benchmark measures what
 * undulate-web costs, not the simulator. Built by bench/run.sh.
 *
 *   webpub URL N SECONDS [plane]
 *
 * With "plane", SIM.TRUTH is the plane world's: each robot's three links
 * swinging with its joints, four walls, and every other neighbouring pair
 * touching in every message (resting contact, an impact every half second):
 * N/2 contacts a message, more than the plane arena's robots make.
 */
#include <lcm/lcm.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "undulate_robot_state_t.h"
#include "undulate_sim_truth_t.h"

#define WEBPUB_MAX 64
#define WEBPUB_HZ 100
#define WEBPUB_LINK 0.1865      /* m, the paper's link */

static undulate_sim_link_t links[3 * WEBPUB_MAX];
static undulate_sim_contact_t contacts[WEBPUB_MAX];
static undulate_sim_wall_t walls[4];

/* The plane's part of SIM.TRUTH: robot i's links in a chain from its head,
 * bent by its joints' angles a0, a1; neighbours (2k, 2k+1) touching. */
static void webpub_plane(undulate_sim_truth_t *t, int n, const double (*angles)[2], int64_t cycle)
{
	for (int i = 0; i < n; i++) {
		double x = 0.2 * i - 0.1 * (n - 1), y = 0.28, dir = -M_PI / 2;
		for (int k = 0; k < 3; k++) {
			double cx = x + 0.5 * WEBPUB_LINK * cos(dir), cy = y + 0.5 * WEBPUB_LINK * sin(dir);
			links[3 * i + k] = (undulate_sim_link_t){ .robot = (int16_t)i, .link = (int8_t)k, .x = cx, .y = cy,
				.angle = dir + M_PI, .length = WEBPUB_LINK, .width = 0.032 };
			x += WEBPUB_LINK * cos(dir);
			y += WEBPUB_LINK * sin(dir);
			if (k < 2)
				dir += angles[i][k];
		}
	}
	int nc = 0;
	for (int i = 0; i + 1 < n; i += 2)
		contacts[nc++] = (undulate_sim_contact_t){ .robot_a = (int16_t)i, .link_a = 2, .robot_b = (int16_t)(i + 1),
			.link_b = 2, .x = 0.2 * i - 0.1 * (n - 1) + 0.1, .y = -0.2, .nx = 1, .impulse = 0.01,
			.normal_impulse = 0.01, .force = 1.0, .impact = cycle % 50 == 0 };
	/* side walls 0.1 m beyond the outer robots, end walls across them */
	double side = 0.1 * n, end = 0.32;
	walls[0] = (undulate_sim_wall_t){ -side, -end, -side, end };
	walls[1] = (undulate_sim_wall_t){ side, -end, side, end };
	walls[2] = (undulate_sim_wall_t){ -side, -end, side, -end };
	walls[3] = (undulate_sim_wall_t){ -side, end, side, end };
	t->wall_left = -side;
	t->wall_right = side;
	t->world = UNDULATE_SIM_TRUTH_T_WORLD_PLANE;
	t->nlinks = 3 * n;
	t->links = links;
	t->nwalls = 4;
	t->walls = walls;
	t->ncontacts = nc;
	t->contacts = contacts;
}

static double mono_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

int main(int argc, char **argv)
{
	if (argc != 4 && !(argc == 5 && strcmp(argv[4], "plane") == 0)) {
		fprintf(stderr, "usage: webpub URL N SECONDS [plane]\n");
		return 2;
	}
	bool plane = argc == 5;
	lcm_t *lcm = lcm_create(argv[1]);
	int n = atoi(argv[2]);
	double seconds = atof(argv[3]);
	if (lcm == NULL || n < 1 || n > WEBPUB_MAX || !(seconds > 0)) {
		fprintf(stderr, "webpub: bad arguments or no LCM\n");
		return 2;
	}
	static char names[WEBPUB_MAX][16], channels[WEBPUB_MAX][24];
	static undulate_sim_body_t bodies[WEBPUB_MAX];
	char reason[] = "bench", fault[] = "";
	for (int i = 0; i < n; i++) {
		snprintf(names[i], sizeof names[i], "b%02d", i + 1);
		snprintf(channels[i], sizeof channels[i], "b%02d.STATE", i + 1);
		bodies[i] = (undulate_sim_body_t){ .robot = names[i], .servo_id = 1, .neutral = 0.1 * i };
	}
	double t0 = mono_s();
	int64_t cycle = 0;
	static double angles[WEBPUB_MAX][2];
	printf("webpub: ready: %d robots at %d Hz%s\n", n, WEBPUB_HZ, plane ? ", the plane world" : "");
	fflush(stdout);
	for (double t = 0; t < seconds; cycle++) {
		t = (double)cycle / WEBPUB_HZ;
		for (int i = 0; i < n; i++) {
			double ph = remainder(2 * M_PI * 0.8 * t + 0.3 * i, 2 * M_PI);
			undulate_joint_state_t j[2];
			memset(j, 0, sizeof j);
			for (int k = 0; k < 2; k++) {
				double p = ph - 2.1 * k;
				j[k] = (undulate_joint_state_t){ .servo_id = (int16_t)(k + 1), .angle = 0.8 * cos(p),
					.speed = -4.0 * sin(p), .goal = 0.8 * cos(p), .phase = p, .amplitude = 0.8,
					.frequency = 0.8, .temperature = 35, .voltage = 12, .torque = 1 };
			}
			undulate_robot_state_t s = { .utime = (int64_t)(t * 1e6), .robot = names[i], .cycle = cycle,
				.mode = 3, .mode_reason = reason, .fault = fault, .period_us = 10000, .jitter_us = 30,
				.njoints = 2, .joints = j };
			angles[i][0] = j[0].angle;
			angles[i][1] = j[1].angle;
			bodies[i].angle = j[0].angle;
			bodies[i].lateral = bodies[i].neutral + 0.0186 * j[0].angle;
			undulate_robot_state_t_publish(lcm, channels[i], &s);
		}
		undulate_sim_truth_t truth = { .utime = (int64_t)(t * 1e6), .step = cycle * 10, .sim_time = t,
			.nbodies = n, .bodies = bodies };
		if (plane)
			webpub_plane(&truth, n, (const double (*)[2])angles, cycle);
		undulate_sim_truth_t_publish(lcm, "SIM.TRUTH", &truth);
		double wait = t0 + (double)(cycle + 1) / WEBPUB_HZ - mono_s();
		if (wait > 0) {
			struct timespec ts = { .tv_sec = 0, .tv_nsec = (long)(wait * 1e9) };
			nanosleep(&ts, NULL);
		}
	}
	lcm_destroy(lcm);
	return 0;
}
