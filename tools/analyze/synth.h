/* synth.h — a synthetic LCM log with known content: four robots whose phases,
 * collisions and return map are set by construction. Used by the tests and
 * by `undulate-analyze --synth` to check an installation end to end.
 *
 * Robots r1..r4, two joints each (servo ids 2i-1, 2i), joint 1 lagging joint
 * 0 by 2*pi/3; angle = A cos(phi), speed = -A w sin(phi).
 *   r1:r2  d~ = 0.3, constant phase difference 0.4 rad, no contact (compatible).
 *   r2:r3  d~ = 0.6, phase difference pi, one collision per period (anti-phase).
 *   r3:r4  d~ = 0; phase difference delta0 at start, then at each of ncoll
 *          collisions (every coll_period_s) the d~ = 0 return map
 *          delta_n = 2 atan((-r)^n tan(delta0/2)); no contact afterwards.
 *          Only r4's phase jumps, as if r3 were much heavier.
 * With stop_after_s >= 0 the robots in stop_mask (default r3 and r4) stand
 * still from that time on: angle held at its value then, speed 0, the daemon's
 * frequency still reported (as a daemon whose joints stalled would), and no
 * collision involving them. r2:r3 then has one stopped robot, r3:r4 two.
 * SIM.TRUTH at every cycle carries the bodies and the collisions, which are
 * also sent on SIM.COLLISION (the analyser must count each once); the
 * copies in SIM.TRUTH carry the truth message's time, as the simulator's do.
 * With plane set, SIM.TRUTH is the plane world's: every robot three links of
 * SYNTH_LINK_M bent by its two joints' angles (synth_plane_links), its centre
 * at x = its neutral position moving along +y at SYNTH_PLANE_SPEED, and two
 * side walls at x = -1 and +1 m. */
#ifndef UNDULATE_ANALYZE_SYNTH_H
#define UNDULATE_ANALYZE_SYNTH_H

#include <stddef.h>
#include <stdbool.h>
#include <stdint.h>

#define SYNTH_ROBOTS 4
#define SYNTH_COMPAT_DELTA 0.4
#define SYNTH_DSEP_12 0.3
#define SYNTH_DSEP_23 0.6

struct synth_spec {
	double duration_s;
	double dt_s;           /* control period */
	double freq_hz;
	double amplitude;      /* rad */
	double lever;          /* m/rad: lateral = neutral + lever * angle */
	double restitution;
	double delta0;         /* r3:r4 phase difference before the first collision */
	double coll_period_s;  /* between r3:r4 collisions */
	int ncoll;             /* r3:r4 collisions */
	int64_t start_utime;   /* µs */
	bool truth;            /* publish SIM.TRUTH / SIM.COLLISION */
	bool report_frequency; /* fill joint_state_t.frequency (else 0: unknown) */
	int burst;             /* each r3:r4 contact reported as this many collisions, 1 ms apart */
	double stop_after_s;   /* robots in stop_mask stand still from here on; < 0: never */
	unsigned stop_mask;    /* bit i: robot i (r1 = bit 0) */
	bool plane;            /* SIM.TRUTH of the plane world: links and walls */
};

#define SYNTH_LINKS 3             /* links of a plane robot (two joints) */
#define SYNTH_LINK_M 0.1865       /* m, the paper's link */
#define SYNTH_PLANE_SPEED 0.01    /* m/s: every robot's centre along +y */

/* Robots that stop by default: r3 and r4. */
#define SYNTH_STOP_DEFAULT_MASK 0xCu

void synth_default(struct synth_spec *s);
/* r3:r4 phase difference in force at time T (s from the start). */
double synth_delta34(const struct synth_spec *s, double t);
/* The impulse (N*s) of collision number K (0-based) of the log. */
double synth_impulse(int k);
/* Robot I's links at time T in the plane log: centre (x, y) and direction
 * (rad, rear to front; link 0 the head), each joint's angle being the next
 * link's direction less its own; the links' centres average to the robot's
 * centre (its neutral position, SYNTH_PLANE_SPEED * T), and the sum of their
 * directions' unit vectors points along +y. */
void synth_plane_links(const struct synth_spec *s, int i, double t, double x[SYNTH_LINKS],
		       double y[SYNTH_LINKS], double angle[SYNTH_LINKS]);
/* Writes the log (alog_writer_open: PATH's directory must be ours alone; what
 * has its name is replaced); returns the number of collisions written, or -1
 * with a one-line reason in ERR. */
int synth_write(const struct synth_spec *s, const char *path, char *err, size_t errlen);

#endif
