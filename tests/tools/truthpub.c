/*
 * truthpub — a forger of SIM.TRUTH for the monitors' tests: plane-world
 * messages whose links, walls and contacts name what the message does not
 * hold or carry numbers no arena has, as anyone on the LCM group could send.
 * Each message names the bodies NAMES (those of the run under test, so that
 * no new robot appears) and cycles through the hostile kinds below; then it
 * says how many it sent.
 *
 *   truthpub URL COUNT NAME...
 *
 * Kinds (message i uses kind i % TP_KINDS): links of a robot beyond bodies[],
 * negative, a link index beyond a robot's; NaN, inf, 1e300 coordinates, zero
 * and huge sizes; walls with NaN ends and more walls than any monitor keeps;
 * contacts naming robots beyond bodies[] or negative, a wall beyond walls[],
 * NaN points, negative or infinite force and impulse. Sent back to back: a
 * receiver may drop some (UDP), a test counts what arrived. Exit 0 when all
 * were published, 2 on bad arguments.
 */
#include <lcm/lcm.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "undulate_sim_truth_t.h"

#define TP_MAX_BODIES 64
#define TP_WALLS 40
#define TP_KINDS 4

static void tp_links(undulate_sim_link_t *l, int n, int nbodies, int kind)
{
	for (int i = 0; i < n; i++) {
		l[i] = (undulate_sim_link_t){ .robot = (int16_t)(i % nbodies), .link = (int8_t)(i % 3), .x = 0.1 * i,
			.y = 0.05, .angle = 1.5, .length = 0.1865, .width = 0.032 };
		switch ((i + kind) % 8) {
		case 0: l[i].robot = (int16_t)(nbodies + 7); break;
		case 1: l[i].robot = -3; break;
		case 2: l[i].link = 99; break;
		case 3: l[i].x = NAN; break;
		case 4: l[i].y = -INFINITY; break;
		case 5: l[i].x = 1e300; break;
		case 6: l[i].length = 0; break;
		default: l[i].width = 1e30; break;
		}
	}
}

static void tp_contacts(undulate_sim_contact_t *c, int n, int nbodies, int kind)
{
	for (int i = 0; i < n; i++) {
		c[i] = (undulate_sim_contact_t){ .robot_a = 0, .link_a = 0, .robot_b = 1, .link_b = 0, .x = 0, .y = 0,
			.impulse = 0.01, .force = 1 };
		switch ((i + kind) % 7) {
		case 0: c[i].robot_a = (int16_t)(nbodies + 100); break;
		case 1: c[i].robot_b = -9; break;
		case 2: c[i].robot_b = -1; c[i].link_b = 120; break;
		case 3: c[i].y = NAN; break;
		case 4: c[i].force = -5; break;
		case 5: c[i].impulse = INFINITY; break;
		default: c[i].link_a = -2; break;
		}
	}
}

int main(int argc, char **argv)
{
	if (argc < 4 || atoi(argv[2]) < 1 || argc - 3 > TP_MAX_BODIES) {
		fprintf(stderr, "usage: truthpub URL COUNT NAME... (at most %d names)\n", TP_MAX_BODIES);
		return 2;
	}
	lcm_t *lcm = lcm_create(argv[1]);
	if (lcm == NULL) {
		fprintf(stderr, "truthpub: no LCM on %s\n", argv[1]);
		return 2;
	}
	int count = atoi(argv[2]), nbodies = argc - 3;
	static undulate_sim_body_t bodies[TP_MAX_BODIES];
	for (int i = 0; i < nbodies; i++)
		bodies[i] = (undulate_sim_body_t){ .robot = argv[3 + i], .servo_id = 1, .neutral = NAN, .lateral = NAN };
	static undulate_sim_link_t links[3 * TP_MAX_BODIES];
	static undulate_sim_wall_t walls[TP_WALLS];
	static undulate_sim_contact_t contacts[64];
	for (int i = 0; i < TP_WALLS; i++)
		walls[i] = (undulate_sim_wall_t){ i == 0 ? NAN : -1, -0.3, -1, 0.3 };
	int sent = 0;
	for (int k = 0; k < count; k++) {
		int kind = k % TP_KINDS;
		tp_links(links, 3 * nbodies, nbodies, kind);
		tp_contacts(contacts, 64, nbodies, kind);
		undulate_sim_truth_t t = { .utime = k, .step = k, .sim_time = 0.01 * k, .wall_left = NAN, .wall_right = 1,
			.world = UNDULATE_SIM_TRUTH_T_WORLD_PLANE, .nbodies = nbodies, .bodies = bodies,
			.nlinks = 3 * nbodies, .links = links, .nwalls = kind == 3 ? TP_WALLS : 2, .walls = walls,
			.ncontacts = 64, .contacts = contacts };
		if (undulate_sim_truth_t_publish(lcm, "SIM.TRUTH", &t) == 0)
			sent++;
	}
	printf("truthpub: sent %d of %d\n", sent, count);
	lcm_destroy(lcm);
	return sent == count ? 0 : 1;
}
