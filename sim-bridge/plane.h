/*
 * plane.h — the plane world: the paper's robots as rigid links in a plane,
 * stepped by Chipmunk2D (Debian's libchipmunk-dev, 7.0.3), beside the row
 * world of world.h (the theory's line).
 *
 * A robot is a chain of njoints + 1 links of equal length and mass, joined by
 * revolute joints. Link 0 is the head; joint j joins link j's rear end to link
 * j + 1's front end, and its angle is the relative angle of link j + 1 to
 * link j (positive CCW), as the joint's servo reads it. Bases are free: the
 * whole chain moves in the plane, pushed by its own joints through drag and
 * by contact. What acts on the links (PHYSICS.md, section 6):
 *  - each joint's drive as its servo's controller gives it, a line in the
 *    joint's speed clamped to a cap, tau = clamp(a - c w, +-cap) - viscous w,
 *    applied as equal and opposite torques on the two links; the joint's dry
 *    friction as a constraint (Chipmunk's simple motor at rate 0 with its
 *    force capped at the Coulomb torque: it sticks without chattering); the
 *    motor's rotor, seen through the gearbox, adds its inertia to the distal
 *    link;
 *  - resistive-force drag on every link, per unit length: -c_t v_t along the
 *    link, -c_n v_n across it (Hatton's Stokes-like law);
 *  - contact between any two links of different robots and between links and
 *    walls: Chipmunk's rigid contacts with restitution r (per pair kind) and
 *    Coulomb friction, solved iteratively with persistent contacts.
 * Pure but for hushing the library's debug greeting once (plane.c): no
 * clock, no I/O; the caller gives dt and the drives, and reads the
 * joints' angles and speeds and the contacts back.
 */
#ifndef UNDULATE_SIM_PLANE_H
#define UNDULATE_SIM_PLANE_H

#include <stdbool.h>
#include <stddef.h>

#define PLANE_MAX_ROBOTS 32
#define PLANE_MAX_JOINTS 4                   /* per robot; the paper's have 2 */
#define PLANE_MAX_LINKS (PLANE_MAX_JOINTS + 1)
#define PLANE_MAX_WALLS 8
#define PLANE_MAX_CONTACTS 256               /* touching pairs reported per step */
#define PLANE_WALL -1                        /* robot index of a wall in a contact */
/* A wall's half thickness (m): thick enough that links a crowd presses into
 * it are pushed back to its own side, not through it */
#define PLANE_WALL_RADIUS 0.02

struct plane_params {
	double link_length;       /* m (the paper: 0.1865) */
	double link_width;        /* m: a link is a segment with round ends of radius width/2 */
	double link_mass;         /* kg, each link with its share of the servos */
	double restitution;       /* r between links of different robots */
	double wall_restitution;  /* r between a link and a wall */
	double friction;          /* Coulomb coefficient in contacts */
	double drag_tangent;      /* c_t, N·s/m per metre of link */
	double drag_normal;       /* c_n, N·s/m per metre of link */
	int substeps;             /* engine steps per plane_step (>= 1) */
};

/* What one joint's servo asks of the links over the next step (see above). */
struct plane_drive {
	double a, c, cap;         /* motor line: N·m, N·m·s/rad, N·m (cap 0: no drive) */
	double viscous;           /* N·m·s/rad, the joint's own losses */
	double coulomb;           /* N·m, dry friction */
};

/* One joint after the step. */
struct plane_joint {
	double angle, speed;      /* rad, rad/s relative (link j+1 to link j) */
	double torque;            /* N·m the motor delivered (mean over the substeps) */
	double ext_torque;        /* N·m the rest of the world put on the joint (contact, drag, the
				     other joints), mean: what the servo's load reading feels beside its own */
};

struct plane_contact {
	int robot_a, link_a;      /* robot_a < robot_b, or robot_b = PLANE_WALL */
	int robot_b, link_b;      /* link_b: the wall's index when robot_b is PLANE_WALL */
	double impulse;           /* N·s over the step (normal and friction) */
	double normal_impulse;    /* N·s along the contact normal */
	double x, y;              /* m, a contact point */
	double nx, ny;            /* contact normal, from a to b */
	double approach;          /* m/s: speed of approach along the normal at the step's start */
	double separation;        /* m/s: speed apart along the normal at its end */
	bool impact;              /* the pair was not touching before this step */
};

struct plane_link_pose {
	double x, y, angle;       /* m, m, rad: the link's centre and direction (rear to front) */
	double vx, vy, w;
};

struct plane;                 /* opaque: Chipmunk's space and the bodies */

/* NULL with err on a bad parameter (named) or no memory. */
struct plane *plane_new(const struct plane_params *p, char *err, size_t cap);
void plane_free(struct plane *pl);

/* A robot whose chain's centre is at (x, y), its head pointing along heading
 * (rad), with its joints at angles[] (rad) and the rotors' reflected inertia
 * per joint (kg·m², may be NULL). Returns the robot's index or -1 with err. */
int plane_add_robot(struct plane *pl, double x, double y, double heading, int njoints, const double *angles,
                    const double *rotor_inertia, char *err, size_t cap);
/* A wall segment from (ax, ay) to (bx, by); returns its index or -1. */
int plane_add_wall(struct plane *pl, double ax, double ay, double bx, double by, char *err, size_t cap);
/* Move a wall to a new segment over the next step of dt (its speed is what
 * contacts feel). */
void plane_move_wall(struct plane *pl, int wall, double ax, double ay, double bx, double by, double dt);
/* The first pair of links that overlap, a robot's with another's or with a
 * wall (robot_b PLANE_WALL, link_b the wall's index): false when none. */
bool plane_overlap(const struct plane *pl, int *robot_a, int *link_a, int *robot_b, int *link_b);

/* Advance dt under drives[robot * PLANE_MAX_JOINTS + joint]; the joints come
 * back in joints[] (the same indexing). */
void plane_step(struct plane *pl, double dt, const struct plane_drive *drives, struct plane_joint *joints);

int plane_robots(const struct plane *pl);
int plane_joints(const struct plane *pl, int robot);
int plane_walls(const struct plane *pl);
void plane_link(const struct plane *pl, int robot, int link, struct plane_link_pose *out);
void plane_wall(const struct plane *pl, int wall, double *ax, double *ay, double *bx, double *by);
/* The chain's centre of mass and its velocity. */
void plane_robot_centre(const struct plane *pl, int robot, double *x, double *y, double *vx, double *vy);
/* The contacts of the last step (at most cap written; returns how many there were). */
size_t plane_contacts(const struct plane *pl, struct plane_contact *out, size_t cap);
/* Kinetic energy (J) and linear momentum (kg·m/s) of the robots. */
double plane_kinetic_energy(const struct plane *pl);
void plane_momentum(const struct plane *pl, double *px, double *py);
/* Steps whose contacts did not fit PLANE_MAX_CONTACTS (counted, not lost from the totals). */
unsigned long long plane_contacts_dropped(const struct plane *pl);

#endif
