/*
 * plane.c — the plane world on Chipmunk2D (plane.h says what acts on what;
 * PHYSICS.md section 6 gives the numbers and the checks).
 */
#include "plane.h"

#include <chipmunk/chipmunk.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Chipmunk's defaults are for pixels (a collision slop of 0.1 would be
 * 10 cm here) and correct overlap over about a second. Ours: a link may sink
 * 0.2 mm into another before the solver pushes back, and an overlap or a
 * joint's separation is 90 % corrected within about 10 ms. */
#define PLANE_SLOP_M 2e-4
#define PLANE_BIAS_LEFT_AFTER_1S 1e-100
#define PLANE_ITERATIONS 20

enum { PLANE_CT_LINK = 1, PLANE_CT_WALL = 2 };

struct plane_tag {
	int robot, link;            /* robot PLANE_WALL: link is the wall's index */
};

struct plane_robot {
	int njoints;
	cpBody *link[PLANE_MAX_LINKS];
	cpShape *shape[PLANE_MAX_LINKS];
	struct plane_tag tag[PLANE_MAX_LINKS];
	cpConstraint *pivot[PLANE_MAX_JOINTS];
	cpConstraint *friction[PLANE_MAX_JOINTS];
};

struct plane {
	struct plane_params p;
	cpSpace *space;
	struct plane_robot robots[PLANE_MAX_ROBOTS];
	int nrobots;
	cpBody *wall_body[PLANE_MAX_WALLS];
	cpShape *wall_shape[PLANE_MAX_WALLS];
	struct plane_tag wall_tag[PLANE_MAX_WALLS];
	int nwalls;
	/* the contacts of the current step, merged per pair of shapes */
	struct plane_contact contacts[PLANE_MAX_CONTACTS];
	size_t ncontacts;
	unsigned long long dropped;
	/* every link's velocity at the step's start (approach speeds) */
	cpVect v0[PLANE_MAX_ROBOTS][PLANE_MAX_LINKS];
	double w0[PLANE_MAX_ROBOTS][PLANE_MAX_LINKS];
	cpVect wall_v0[PLANE_MAX_WALLS];
};

static bool plane_finite_pos(double v)
{
	return isfinite(v) && v > 0;
}

static bool plane_check(const struct plane_params *p, char *err, size_t cap)
{
	const struct { const char *name; double v; bool positive; double max; } k[] = {
		{ "link_length", p->link_length, true, 10 },  { "link_width", p->link_width, true, 1 },
		{ "link_mass", p->link_mass, true, 100 },      { "restitution", p->restitution, false, 1 },
		{ "wall_restitution", p->wall_restitution, false, 1 }, { "friction", p->friction, false, 10 },
		{ "drag_tangent", p->drag_tangent, false, 1e4 }, { "drag_normal", p->drag_normal, false, 1e4 },
	};
	for (size_t i = 0; i < sizeof k / sizeof k[0]; i++) {
		bool ok = k[i].positive ? plane_finite_pos(k[i].v) : (isfinite(k[i].v) && k[i].v >= 0);
		if (!ok || k[i].v > k[i].max) {
			snprintf(err, cap, "world.%s = %g: must be %s and at most %g", k[i].name, k[i].v,
			         k[i].positive ? "positive" : "finite and >= 0", k[i].max);
			return false;
		}
	}
	if (p->link_width >= p->link_length) {
		snprintf(err, cap, "world.link_width = %g m: must be less than the link's length (%g m)", p->link_width,
		         p->link_length);
		return false;
	}
	if (p->substeps < 1 || p->substeps > 64) {
		snprintf(err, cap, "world.substeps = %d: must be 1..64", p->substeps);
		return false;
	}
	return true;
}

/* Restitution and friction by the kind of pair (Chipmunk would multiply the
 * two shapes' values, which cannot give a wall its own r): a link against a
 * wall (the handler's second shape) bounces with the wall's. */
static cpBool plane_presolve(cpArbiter *arb, cpSpace *space, cpDataPointer data)
{
	(void)space;
	const struct plane *pl = data;
	CP_ARBITER_GET_SHAPES(arb, link, other);
	(void)link;
	bool wall = cpShapeGetCollisionType(other) == PLANE_CT_WALL;
	cpArbiterSetRestitution(arb, wall ? pl->p.wall_restitution : pl->p.restitution);
	cpArbiterSetFriction(arb, pl->p.friction);
	return cpTrue;
}

/* Debian's Chipmunk is a debug build: the first cpSpaceNew() of a process
 * prints two lines on stdout, where undulate-sim says "ready" and the tests
 * read TAP. Make that first space with stdout on /dev/null. */
static void plane_hush_banner(void)
{
	static bool done;
	if (done)
		return;
	done = true;
	fflush(stdout);
	int saved = dup(STDOUT_FILENO), null = open("/dev/null", O_WRONLY | O_CLOEXEC);
	if (saved < 0 || null < 0 || dup2(null, STDOUT_FILENO) < 0) {
		if (saved >= 0)
			close(saved);
		if (null >= 0)
			close(null);
		return;
	}
	cpSpaceFree(cpSpaceNew());
	fflush(stdout);
	dup2(saved, STDOUT_FILENO);
	close(saved);
	close(null);
}

struct plane *plane_new(const struct plane_params *p, char *err, size_t cap)
{
	if (!plane_check(p, err, cap))
		return NULL;
	plane_hush_banner();
	struct plane *pl = calloc(1, sizeof *pl);
	if (pl == NULL || (pl->space = cpSpaceNew()) == NULL) {
		free(pl);
		snprintf(err, cap, "out of memory");
		return NULL;
	}
	pl->p = *p;
	cpSpaceSetGravity(pl->space, cpvzero);
	cpSpaceSetDamping(pl->space, 1.0);
	cpSpaceSetIterations(pl->space, PLANE_ITERATIONS);
	cpSpaceSetCollisionSlop(pl->space, PLANE_SLOP_M);
	cpSpaceSetCollisionBias(pl->space, PLANE_BIAS_LEFT_AFTER_1S);
	cpCollisionHandler *h = cpSpaceAddCollisionHandler(pl->space, PLANE_CT_LINK, PLANE_CT_LINK);
	h->preSolveFunc = plane_presolve;
	h->userData = pl;
	h = cpSpaceAddCollisionHandler(pl->space, PLANE_CT_LINK, PLANE_CT_WALL);
	h->preSolveFunc = plane_presolve;
	h->userData = pl;
	return pl;
}

void plane_free(struct plane *pl)
{
	if (pl == NULL)
		return;
	/* Chipmunk frees what a space holds only through its own iterators;
	 * we know every object we added */
	for (int r = 0; r < pl->nrobots; r++) {
		struct plane_robot *rb = &pl->robots[r];
		for (int j = 0; j < rb->njoints; j++) {
			cpSpaceRemoveConstraint(pl->space, rb->pivot[j]);
			cpSpaceRemoveConstraint(pl->space, rb->friction[j]);
			cpConstraintFree(rb->pivot[j]);
			cpConstraintFree(rb->friction[j]);
		}
		for (int k = 0; k <= rb->njoints; k++) {
			cpSpaceRemoveShape(pl->space, rb->shape[k]);
			cpSpaceRemoveBody(pl->space, rb->link[k]);
			cpShapeFree(rb->shape[k]);
			cpBodyFree(rb->link[k]);
		}
	}
	for (int w = 0; w < pl->nwalls; w++) {
		cpSpaceRemoveShape(pl->space, pl->wall_shape[w]);
		cpSpaceRemoveBody(pl->space, pl->wall_body[w]);
		cpShapeFree(pl->wall_shape[w]);
		cpBodyFree(pl->wall_body[w]);
	}
	cpSpaceFree(pl->space);
	free(pl);
}

static cpVect plane_dir(double angle)
{
	return cpv(cos(angle), sin(angle));
}

/* Link centres and angles of a chain at rest: link 0's front at the origin,
 * then shifted so the centres' mean is (x, y). */
static void plane_chain(const struct plane *pl, double x, double y, double heading, int njoints, const double *angles,
                        cpVect *centre, double *theta)
{
	double half = 0.5 * pl->p.link_length;
	cpVect front = cpvzero, sum = cpvzero;
	theta[0] = heading;
	for (int k = 0; k <= njoints; k++) {
		if (k > 0)
			theta[k] = theta[k - 1] + angles[k - 1];
		centre[k] = cpvsub(front, cpvmult(plane_dir(theta[k]), half));
		front = cpvsub(front, cpvmult(plane_dir(theta[k]), 2 * half));
		sum = cpvadd(sum, centre[k]);
	}
	cpVect shift = cpvsub(cpv(x, y), cpvmult(sum, 1.0 / (njoints + 1)));
	for (int k = 0; k <= njoints; k++)
		centre[k] = cpvadd(centre[k], shift);
}

int plane_add_robot(struct plane *pl, double x, double y, double heading, int njoints, const double *angles,
                    const double *rotor_inertia, char *err, size_t cap)
{
	if (pl->nrobots >= PLANE_MAX_ROBOTS || njoints < 1 || njoints > PLANE_MAX_JOINTS) {
		snprintf(err, cap, "%s", pl->nrobots >= PLANE_MAX_ROBOTS ? "too many robots for the plane world"
		                                                          : "a plane robot has 1 to 4 joints");
		return -1;
	}
	if (!isfinite(x) || !isfinite(y) || !isfinite(heading)) {
		snprintf(err, cap, "a robot's position and heading must be finite");
		return -1;
	}
	for (int j = 0; j < njoints; j++)
		if (!isfinite(angles[j]) || (rotor_inertia && !(isfinite(rotor_inertia[j]) && rotor_inertia[j] >= 0))) {
			snprintf(err, cap, "joint %d: angle and rotor inertia must be finite", j + 1);
			return -1;
		}
	int r = pl->nrobots++;
	struct plane_robot *rb = &pl->robots[r];
	rb->njoints = njoints;
	cpVect centre[PLANE_MAX_LINKS];
	double theta[PLANE_MAX_LINKS];
	plane_chain(pl, x, y, heading, njoints, angles, centre, theta);
	double half = 0.5 * pl->p.link_length, radius = 0.5 * pl->p.link_width;
	for (int k = 0; k <= njoints; k++) {
		double m = pl->p.link_mass;
		double moment = cpMomentForSegment(m, cpv(-half, 0), cpv(half, 0), radius);
		/* the rotor of the joint in front of this link turns with it */
		if (k > 0 && rotor_inertia)
			moment += rotor_inertia[k - 1];
		rb->link[k] = cpSpaceAddBody(pl->space, cpBodyNew(m, moment));
		cpBodySetPosition(rb->link[k], centre[k]);
		cpBodySetAngle(rb->link[k], theta[k]);
		rb->shape[k] = cpSpaceAddShape(pl->space, cpSegmentShapeNew(rb->link[k], cpv(-half, 0), cpv(half, 0), radius));
		cpShapeSetCollisionType(rb->shape[k], PLANE_CT_LINK);
		/* a robot's own links never collide (their joints hold them) */
		cpShapeSetFilter(rb->shape[k], cpShapeFilterNew((cpGroup)(r + 1), CP_ALL_CATEGORIES, CP_ALL_CATEGORIES));
		rb->tag[k] = (struct plane_tag){ r, k };
		cpShapeSetUserData(rb->shape[k], &rb->tag[k]);
	}
	for (int j = 0; j < njoints; j++) {
		rb->pivot[j] = cpSpaceAddConstraint(
			pl->space, cpPivotJointNew2(rb->link[j], rb->link[j + 1], cpv(-half, 0), cpv(half, 0)));
		cpConstraintSetErrorBias(rb->pivot[j], PLANE_BIAS_LEFT_AFTER_1S);
		rb->friction[j] = cpSpaceAddConstraint(pl->space, cpSimpleMotorNew(rb->link[j], rb->link[j + 1], 0.0));
		cpConstraintSetMaxForce(rb->friction[j], 0.0);
	}
	return r;
}

int plane_add_wall(struct plane *pl, double ax, double ay, double bx, double by, char *err, size_t cap)
{
	if (pl->nwalls >= PLANE_MAX_WALLS || !isfinite(ax) || !isfinite(ay) || !isfinite(bx) || !isfinite(by)) {
		snprintf(err, cap, "%s", pl->nwalls >= PLANE_MAX_WALLS ? "too many walls" : "a wall's ends must be finite");
		return -1;
	}
	int w = pl->nwalls++;
	cpVect mid = cpv(0.5 * (ax + bx), 0.5 * (ay + by));
	/* kinematic: it moves only as told, and contacts feel its speed */
	pl->wall_body[w] = cpSpaceAddBody(pl->space, cpBodyNewKinematic());
	cpBodySetPosition(pl->wall_body[w], mid);
	pl->wall_shape[w] = cpSpaceAddShape(pl->space, cpSegmentShapeNew(pl->wall_body[w], cpvsub(cpv(ax, ay), mid),
	                                                                  cpvsub(cpv(bx, by), mid), PLANE_WALL_RADIUS));
	cpShapeSetCollisionType(pl->wall_shape[w], PLANE_CT_WALL);
	pl->wall_tag[w] = (struct plane_tag){ PLANE_WALL, w };
	cpShapeSetUserData(pl->wall_shape[w], &pl->wall_tag[w]);
	return w;
}

/* Walls move by translation: the segment keeps its direction and length,
 * its middle goes to the new segment's middle over dt. */
void plane_move_wall(struct plane *pl, int wall, double ax, double ay, double bx, double by, double dt)
{
	if (wall < 0 || wall >= pl->nwalls || !(dt > 0) || !isfinite(ax + ay + bx + by))
		return;
	cpBody *b = pl->wall_body[wall];
	cpVect to = cpv(0.5 * (ax + bx), 0.5 * (ay + by));
	cpBodySetVelocity(b, cpvmult(cpvsub(to, cpBodyGetPosition(b)), 1.0 / dt));
}

bool plane_overlap(const struct plane *pl, int *robot_a, int *link_a, int *robot_b, int *link_b)
{
	for (int r = 0; r < pl->nrobots; r++)
		for (int k = 0; k <= pl->robots[r].njoints; k++)
			cpShapeCacheBB(pl->robots[r].shape[k]);
	for (int w = 0; w < pl->nwalls; w++)
		cpShapeCacheBB(pl->wall_shape[w]);
	for (int r = 0; r < pl->nrobots; r++)
		for (int k = 0; k <= pl->robots[r].njoints; k++) {
			const cpShape *a = pl->robots[r].shape[k];
			*robot_a = r;
			*link_a = k;
			for (int s = r + 1; s < pl->nrobots; s++)
				for (int m = 0; m <= pl->robots[s].njoints; m++)
					if (cpShapesCollide(a, pl->robots[s].shape[m]).count > 0) {
						*robot_b = s;
						*link_b = m;
						return true;
					}
			for (int w = 0; w < pl->nwalls; w++)
				if (cpShapesCollide(a, pl->wall_shape[w]).count > 0) {
					*robot_b = PLANE_WALL;
					*link_b = w;
					return true;
				}
		}
	return false;
}

/* ---- one step ------------------------------------------------------------------ */

static double plane_clamp(double v, double cap)
{
	return v > cap ? cap : (v < -cap ? -cap : v);
}

static void plane_add_torque(cpBody *b, double t)
{
	cpBodySetTorque(b, cpBodyGetTorque(b) + t);
}

/* Resistive-force drag: per unit length -c_t v_t along the link, -c_n v_n
 * across it, with v_n = v_centre . n + w s at s along the link: integrated,
 * a force at the centre and a torque -c_n w L^3 / 12. */
static void plane_drag(const struct plane *pl, cpBody *b)
{
	double L = pl->p.link_length;
	cpVect t = plane_dir(cpBodyGetAngle(b)), n = cpvperp(t), v = cpBodyGetVelocity(b);
	cpVect f = cpvadd(cpvmult(t, -pl->p.drag_tangent * L * cpvdot(v, t)),
	                  cpvmult(n, -pl->p.drag_normal * L * cpvdot(v, n)));
	cpBodySetForce(b, cpvadd(cpBodyGetForce(b), f));
	plane_add_torque(b, -pl->p.drag_normal * cpBodyGetAngularVelocity(b) * L * L * L / 12.0);
}

static double plane_joint_speed(const struct plane_robot *rb, int j)
{
	return cpBodyGetAngularVelocity(rb->link[j + 1]) - cpBodyGetAngularVelocity(rb->link[j]);
}

/* The joints' torques for one engine step; returns nothing, adds each motor's
 * delivered torque to sum[]. */
static void plane_drive_joints(struct plane *pl, const struct plane_drive *drives, double *sum)
{
	for (int r = 0; r < pl->nrobots; r++) {
		struct plane_robot *rb = &pl->robots[r];
		for (int j = 0; j < rb->njoints; j++) {
			const struct plane_drive *d = &drives[r * PLANE_MAX_JOINTS + j];
			double w = plane_joint_speed(rb, j);
			double motor = d->cap > 0 ? plane_clamp(d->a - d->c * w, d->cap) : 0.0;
			double tau = motor - d->viscous * w;
			plane_add_torque(rb->link[j + 1], tau);
			plane_add_torque(rb->link[j], -tau);
			sum[r * PLANE_MAX_JOINTS + j] += motor;
		}
		for (int k = 0; k <= rb->njoints; k++)
			plane_drag(pl, rb->link[k]);
	}
}

static cpVect plane_point_velocity(cpVect v, double w, cpVect centre, cpVect point)
{
	return cpvadd(v, cpvmult(cpvperp(cpvsub(point, centre)), w));
}

static struct plane_contact *plane_contact_slot(struct plane *pl, const struct plane_tag *a, const struct plane_tag *b)
{
	for (size_t i = 0; i < pl->ncontacts; i++) {
		struct plane_contact *c = &pl->contacts[i];
		if (c->robot_a == a->robot && c->link_a == a->link && c->robot_b == b->robot && c->link_b == b->link)
			return c;
	}
	if (pl->ncontacts == PLANE_MAX_CONTACTS) {
		pl->dropped++;
		return NULL;
	}
	struct plane_contact *c = &pl->contacts[pl->ncontacts++];
	*c = (struct plane_contact){ .robot_a = a->robot, .link_a = a->link, .robot_b = b->robot, .link_b = b->link };
	return c;
}

/* The velocity of tag's body at the step's start, at point. */
static cpVect plane_v0_at(const struct plane *pl, const struct plane_tag *t, cpVect point)
{
	if (t->robot == PLANE_WALL)
		return pl->wall_v0[t->link];
	const cpBody *b = pl->robots[t->robot].link[t->link];
	return plane_point_velocity(pl->v0[t->robot][t->link], pl->w0[t->robot][t->link], cpBodyGetPosition(b), point);
}

static cpVect plane_v_at(const struct plane *pl, const struct plane_tag *t, cpVect point)
{
	const cpBody *b = t->robot == PLANE_WALL ? pl->wall_body[t->link] : pl->robots[t->robot].link[t->link];
	return plane_point_velocity(cpBodyGetVelocity(b), cpBodyGetAngularVelocity(b), cpBodyGetPosition(b), point);
}

static void plane_on_arbiter(cpBody *body, cpArbiter *arb, void *data)
{
	(void)body;
	struct plane *pl = data;
	cpShape *sa, *sb;
	cpArbiterGetShapes(arb, &sa, &sb);
	const struct plane_tag *ta = cpShapeGetUserData(sa), *tb = cpShapeGetUserData(sb);
	cpVect n = cpArbiterGetNormal(arb);
	/* each robot-robot pair is seen from both bodies: keep it once, lower robot first */
	if (tb->robot != PLANE_WALL && tb->robot < ta->robot)
		return;
	if (ta->robot == PLANE_WALL)
		return;
	cpVect j = cpArbiterTotalImpulse(arb);
	struct plane_contact *c = plane_contact_slot(pl, ta, tb);
	if (c == NULL || cpArbiterGetCount(arb) == 0)
		return;
	cpVect point = cpvlerp(cpArbiterGetPointA(arb, 0), cpArbiterGetPointB(arb, 0), 0.5);
	if (c->impulse == 0 && !c->impact) {
		/* the first substep that sees the pair: its approach */
		c->approach = cpvdot(cpvsub(plane_v0_at(pl, ta, point), plane_v0_at(pl, tb, point)), n);
	}
	c->impulse += cpvlength(j);
	c->normal_impulse += fabs(cpvdot(j, n));
	c->impact = c->impact || cpArbiterIsFirstContact(arb);
	c->x = point.x;
	c->y = point.y;
	c->nx = n.x;
	c->ny = n.y;
	c->separation = cpvdot(cpvsub(plane_v_at(pl, tb, point), plane_v_at(pl, ta, point)), n);
}

static void plane_collect(struct plane *pl)
{
	for (int r = 0; r < pl->nrobots; r++)
		for (int k = 0; k <= pl->robots[r].njoints; k++)
			cpBodyEachArbiter(pl->robots[r].link[k], plane_on_arbiter, pl);
}

void plane_step(struct plane *pl, double dt, const struct plane_drive *drives, struct plane_joint *joints)
{
	if (!(dt > 0) || !isfinite(dt))
		return;
	pl->ncontacts = 0;
	for (int r = 0; r < pl->nrobots; r++)
		for (int k = 0; k <= pl->robots[r].njoints; k++) {
			pl->v0[r][k] = cpBodyGetVelocity(pl->robots[r].link[k]);
			pl->w0[r][k] = cpBodyGetAngularVelocity(pl->robots[r].link[k]);
		}
	for (int w = 0; w < pl->nwalls; w++)
		pl->wall_v0[w] = cpBodyGetVelocity(pl->wall_body[w]);
	for (int r = 0; r < pl->nrobots; r++)
		for (int j = 0; j < pl->robots[r].njoints; j++)
			cpConstraintSetMaxForce(pl->robots[r].friction[j], drives[r * PLANE_MAX_JOINTS + j].coulomb);
	double sum[PLANE_MAX_ROBOTS * PLANE_MAX_JOINTS] = { 0 };
	double h = dt / pl->p.substeps;
	for (int s = 0; s < pl->p.substeps; s++) {
		plane_drive_joints(pl, drives, sum);
		cpSpaceStep(pl->space, h);
		plane_collect(pl);
	}
	for (int r = 0; r < pl->nrobots; r++) {
		const struct plane_robot *rb = &pl->robots[r];
		for (int j = 0; j < rb->njoints; j++) {
			struct plane_joint *o = &joints[r * PLANE_MAX_JOINTS + j];
			o->angle = cpBodyGetAngle(rb->link[j + 1]) - cpBodyGetAngle(rb->link[j]);
			o->speed = plane_joint_speed(rb, j);
			o->torque = sum[r * PLANE_MAX_JOINTS + j] / pl->p.substeps;
		}
	}
	/* a moving wall stops where it was sent unless told again */
	for (int w = 0; w < pl->nwalls; w++)
		cpBodySetVelocity(pl->wall_body[w], cpvzero);
}

/* ---- reading the world ------------------------------------------------------------------ */

int plane_robots(const struct plane *pl)
{
	return pl->nrobots;
}

int plane_joints(const struct plane *pl, int robot)
{
	return robot >= 0 && robot < pl->nrobots ? pl->robots[robot].njoints : 0;
}

int plane_walls(const struct plane *pl)
{
	return pl->nwalls;
}

void plane_link(const struct plane *pl, int robot, int link, struct plane_link_pose *out)
{
	const cpBody *b = pl->robots[robot].link[link];
	cpVect p = cpBodyGetPosition(b), v = cpBodyGetVelocity(b);
	*out = (struct plane_link_pose){ p.x, p.y, cpBodyGetAngle(b), v.x, v.y, cpBodyGetAngularVelocity(b) };
}

void plane_wall(const struct plane *pl, int wall, double *ax, double *ay, double *bx, double *by)
{
	const cpShape *s = pl->wall_shape[wall];
	cpVect p = cpBodyGetPosition(pl->wall_body[wall]);
	cpVect a = cpvadd(p, cpSegmentShapeGetA(s)), b = cpvadd(p, cpSegmentShapeGetB(s));
	*ax = a.x;
	*ay = a.y;
	*bx = b.x;
	*by = b.y;
}

void plane_robot_centre(const struct plane *pl, int robot, double *x, double *y, double *vx, double *vy)
{
	const struct plane_robot *rb = &pl->robots[robot];
	cpVect p = cpvzero, v = cpvzero;
	for (int k = 0; k <= rb->njoints; k++) {
		p = cpvadd(p, cpBodyGetPosition(rb->link[k]));
		v = cpvadd(v, cpBodyGetVelocity(rb->link[k]));
	}
	double n = rb->njoints + 1;
	*x = p.x / n;
	*y = p.y / n;
	*vx = v.x / n;
	*vy = v.y / n;
}

size_t plane_contacts(const struct plane *pl, struct plane_contact *out, size_t cap)
{
	size_t n = pl->ncontacts < cap ? pl->ncontacts : cap;
	if (out != NULL && n > 0)
		memcpy(out, pl->contacts, n * sizeof *out);
	return pl->ncontacts;
}

double plane_kinetic_energy(const struct plane *pl)
{
	double e = 0;
	for (int r = 0; r < pl->nrobots; r++)
		for (int k = 0; k <= pl->robots[r].njoints; k++) {
			const cpBody *b = pl->robots[r].link[k];
			double w = cpBodyGetAngularVelocity(b);
			e += 0.5 * cpBodyGetMass(b) * cpvlengthsq(cpBodyGetVelocity(b)) + 0.5 * cpBodyGetMoment(b) * w * w;
		}
	return e;
}

void plane_momentum(const struct plane *pl, double *px, double *py)
{
	cpVect p = cpvzero;
	for (int r = 0; r < pl->nrobots; r++)
		for (int k = 0; k <= pl->robots[r].njoints; k++)
			p = cpvadd(p, cpvmult(cpBodyGetVelocity(pl->robots[r].link[k]), cpBodyGetMass(pl->robots[r].link[k])));
	*px = p.x;
	*py = p.y;
}

unsigned long long plane_contacts_dropped(const struct plane *pl)
{
	return pl->dropped;
}
