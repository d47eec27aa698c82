/*
 * webpub.c — N robots' <robot>.STATE at 100 Hz on LCM, each two joints on a
 * limit cycle of its own phase, and SIM.TRUTH with their bodies: the traffic
 * of a group of robots without the robots, so the benchmark measures what
 * undulate-web costs, not the simulator. Built by bench/run.sh.
 *
 *   webpub URL N SECONDS
 */
#include <lcm/lcm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "undulate_robot_state_t.h"
#include "undulate_sim_truth_t.h"

#define WEBPUB_MAX 64
#define WEBPUB_HZ 100

static double mono_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

int main(int argc, char **argv)
{
	if (argc != 4) {
		fprintf(stderr, "usage: webpub URL N SECONDS\n");
		return 2;
	}
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
	printf("webpub: ready: %d robots at %d Hz\n", n, WEBPUB_HZ);
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
			bodies[i].angle = j[0].angle;
			bodies[i].lateral = bodies[i].neutral + 0.0186 * j[0].angle;
			undulate_robot_state_t_publish(lcm, channels[i], &s);
		}
		undulate_sim_truth_t truth = { .utime = (int64_t)(t * 1e6), .step = cycle * 10, .sim_time = t,
			.nbodies = n, .bodies = bodies };
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
