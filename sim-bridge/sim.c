/*
 * sim.c — the simulator's state and its command language (see sim.h and
 * sim-bridge/README.md, "Commands").
 */
#include "sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dxl_table.h"
#include "num.h"

/* Words in one command line. */
#define SIM_CMD_MAX_WORDS 16
/* Longest wall motion a command may ask for: a day of simulated time. */
#define SIM_WALL_SPAN_MAX_S 86400.0
/* Largest kick (rad/s): three times an AX-12A's no-load speed at 12 V; a
 * link swinging 0.8 rad at 0.8 Hz peaks at 4 rad/s. */
#define SIM_KICK_MAX 20.0

/* ---- set-up ------------------------------------------------------------------- */

static double config_spacing(const struct sim_config *c)
{
	return c->spacing > 0 ? c->spacing : c->separation * 2.0 * c->lever * c->amplitude;
}

static void sim_layout_world(struct sim *s)
{
	const struct sim_config *c = &s->cfg;
	struct sim_world_params wp = c->world;
	size_t n = s->world.nbodies;
	double d = config_spacing(c);
	if (c->walls == SIM_WALLS_NONE) {
		wp.wall_left = wp.wall_right = 0;
	} else if (c->walls == SIM_WALLS_AUTO && n > 0) {
		/* A wall stands where a mirrored neighbour would touch. */
		double lo = s->world.bodies[0].neutral, hi = s->world.bodies[n - 1].neutral;
		double gap = d > 0 ? d / 2 : c->lever * c->amplitude;
		wp.wall_left = lo - gap;
		wp.wall_right = hi + gap;
	}
	s->world.params = wp;
}

/* Initial joint angles from the seed, then nudged so no contact body starts
 * inside its left neighbour. */
static void sim_initial_angles(struct sim *s)
{
	for (size_t i = 0; i < s->nbuses; i++)
		for (size_t k = 0; k < s->buses[i].njoints; k++) {
			struct sim_joint *j = &s->buses[i].joints[k];
			double a = (2.0 * sim_rand_uniform(&s->rng) - 1.0) * s->cfg.initial_spread;
			sim_motor_init(&j->motor, &j->params, a);
		}
	for (size_t b = 1; b < s->world.nbodies; b++) {
		struct sim_body *l = &s->world.bodies[b - 1], *r = &s->world.bodies[b];
		double min_x = sim_world_lateral(&s->world, b - 1) + l->half_width + r->half_width;
		if (sim_world_lateral(&s->world, b) < min_x)
			r->motor->angle = (min_x - r->neutral) / r->lever + 1e-6;
	}
}

/* The model of a robot's k-th servo (one per ID after sim_config_finish()). */
static enum sim_model robot_model(const struct sim_robot_config *rc, size_t k)
{
	if (rc->nmodels == 0)
		return SIM_MODEL_AX12A;
	return rc->models[rc->nmodels == rc->nids ? k : 0];
}

/* The Baud Rate register value of the robot's servos (ops: their family's). */
static int robot_baud_reg(const struct sim_robot_config *rc, long baud, const struct sim_joint_ops *ops,
                          uint8_t *reg, char *err, size_t errcap)
{
	if (rc->servo_baud_reg >= 0) {
		*reg = (uint8_t)rc->servo_baud_reg;
		return 0;
	}
	if (ops->baud_reg(baud, reg) != DXL_OK)
		return snprintf(err, errcap, "robot %s: %ld bps is no %s; set servo_baud", rc->name, baud,
		                ops->rate_names), -1;
	return 0;
}

static int sim_add_robot(struct sim *s, const struct sim_robot_config *rc, char *err, size_t errcap)
{
	const struct sim_config *c = &s->cfg;
	struct sim_bus *b = &s->buses[s->nbuses];
	const struct sim_model_info *mi = sim_model_info(robot_model(rc, 0));
	long baud = rc->baud > 0 ? rc->baud : c->baud > 0 ? c->baud : mi->default_baud;
	double latency_ms = rc->latency_ms >= 0 ? rc->latency_ms : c->latency_ms;
	bool echo = rc->echo >= 0 ? rc->echo != 0 : c->echo;
	sim_bus_init(b, rc->name, rc->link, baud, latency_ms / 1000.0, echo, c->seed * 1000003u + s->nbuses + 1);
	b->follow_tty = c->baud_follows_tty;
	/* the bus speaks its servos' protocol: the choice made here, once */
	sim_bus_set_protocol(b, mi->protocol);
	uint8_t baud_reg;
	if (robot_baud_reg(rc, baud, sim_joint_ops_of(robot_model(rc, 0)), &baud_reg, err, errcap) != 0)
		return -1;
	int delay_us = rc->return_delay_us >= 0 ? rc->return_delay_us : c->return_delay_us;
	for (size_t k = 0; k < rc->nids; k++) {
		struct sim_joint *j = &b->joints[b->njoints++];
		struct sim_joint_place place = {
			.id = rc->ids[k], .baud_reg = baud_reg, .delay_us = delay_us,
			.eeprom_needs_torque_off = c->eeprom_needs_torque_off, .overload_time_s = c->overload_time_s,
			.firmware = rc->firmware > 0 ? rc->firmware : c->firmware, .no_indirect = c->no_indirect,
		};
		sim_joint_place(j, robot_model(rc, k), &place);
		sim_config_motor_params(c, j->model, &j->params);
		if (rc->ids[k] != rc->contact_id)
			continue;
		size_t body = s->world.nbodies;
		struct sim_body sb = {
			.motor = &j->motor, .lever = rc->mirror ? -c->lever : c->lever, .half_width = c->half_width, .robot = (int)s->nbuses,
			.effective_mass = c->effective_mass > 0 ? c->effective_mass : j->params.inertia / (c->lever * c->lever),
			.neutral = rc->neutral_set ? rc->neutral : 0,
			.own_beta = rc->beta_set, .beta = rc->beta,
		};
		if (sim_world_add_body(&s->world, &sb) < 0)
			return snprintf(err, errcap, "robot %s: the world refused its contact body", rc->name), -1;
		s->body_bus[body] = (int)s->nbuses;
		s->body_joint[body] = (int)k;
	}
	s->nbuses++;
	return 0;
}

/* Robots without an explicit neutral position sit in a row centred on 0. */
static void sim_place_bodies(struct sim *s)
{
	size_t n = s->world.nbodies;
	double d = config_spacing(&s->cfg);
	for (size_t i = 0; i < n; i++) {
		const struct sim_robot_config *rc = &s->cfg.robots[s->body_bus[i]];
		if (!rc->neutral_set)
			s->world.bodies[i].neutral = ((double)i - (double)(n - 1) / 2.0) * d;
	}
}

static void sim_sync_present(struct sim *s);

/* ---- the plane world: set-up ----------------------------------------------------- */

static double plane_robot_length(const struct sim_config *c, size_t njoints)
{
	return (double)(njoints + 1) * c->plane.link_length;
}

/* Robots without a position stand in a row along x, heads towards +y. */
static void sim_plane_place(struct sim *s, size_t i, double *x, double *y, double *heading)
{
	const struct sim_robot_config *rc = &s->cfg.robots[i];
	double d = config_spacing(&s->cfg);
	*x = rc->position_set ? rc->x : ((double)i - (double)(s->nbuses - 1) / 2.0) * d;
	*y = rc->position_set ? rc->y : 0.0;
	*heading = rc->heading_set ? rc->heading : M_PI / 2;
}

/* The walls: sides at x = wall_left, wall_right along the robots' length,
 * ends at y = back, front across it. */
static int sim_plane_walls(struct sim *s, char *err, size_t errcap)
{
	const struct sim_config *c = &s->cfg;
	double lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
	for (size_t i = 0; i < s->nbuses; i++) {
		double x, y, h, half = 0.5 * plane_robot_length(c, s->buses[i].njoints);
		sim_plane_place(s, i, &x, &y, &h);
		lo_x = i == 0 || x - half < lo_x ? x - half : lo_x;
		hi_x = i == 0 || x + half > hi_x ? x + half : hi_x;
		lo_y = i == 0 || y - half < lo_y ? y - half : lo_y;
		hi_y = i == 0 || y + half > hi_y ? y + half : hi_y;
	}
	const struct sim_world_params *w = &s->world.params;
	bool sides = w->wall_left < w->wall_right;
	double back = c->ends_set ? c->ends_back : lo_y - 0.25, front = c->ends_set ? c->ends_front : hi_y + 0.25;
	double left = sides ? w->wall_left : lo_x - 0.5, right = sides ? w->wall_right : hi_x + 0.5;
	s->wall_face[0] = left;
	s->wall_face[1] = right;
	/* the coordinates are the walls' faces: each segment stands its half
	 * thickness further out */
	const double r = PLANE_WALL_RADIUS, e = 2 * r;
	const double seg[4][4] = { { left - r, back - e, left - r, front + e }, { right + r, back - e, right + r, front + e },
				   { left - e, back - r, right + e, back - r }, { left - e, front + r, right + e, front + r } };
	for (int k = 0; k < 4; k++) {
		s->plane_wall[k] = -1;
		if (k < 2 ? !sides : !c->ends_set)
			continue;
		s->plane_wall[k] = plane_add_wall(s->plane, seg[k][0], seg[k][1], seg[k][2], seg[k][3], err, errcap);
		if (s->plane_wall[k] < 0)
			return -1;
	}
	return 0;
}

static int sim_plane_robot(struct sim *s, size_t i, char *err, size_t errcap)
{
	const struct sim_config *c = &s->cfg;
	struct sim_bus *b = &s->buses[i];
	double angles[PLANE_MAX_JOINTS], rotor[PLANE_MAX_JOINTS], x, y, heading;
	for (size_t k = 0; k < b->njoints; k++) {
		angles[k] = b->joints[k].motor.angle;
		rotor[k] = sim_motor_rotor_inertia(&b->joints[k].params);
	}
	sim_plane_place(s, i, &x, &y, &heading);
	char why[160];
	if (plane_add_robot(s->plane, x, y, heading, (int)b->njoints, angles, rotor, why, sizeof why) < 0)
		return snprintf(err, errcap, "robot %s: %s", b->name, why), -1;
	if (c->ends_set && !c->robots[i].heading_set &&
	    plane_robot_length(c, b->njoints) + c->plane.link_width > c->ends_front - c->ends_back)
		return snprintf(err, errcap, "world.ends: the channel is %g m long, robot %s %g m (%zu links of %g m, "
		                "%g m wide): it cannot fit", c->ends_front - c->ends_back, b->name,
		                plane_robot_length(c, b->njoints) + c->plane.link_width, b->njoints + 1,
		                c->plane.link_length, c->plane.link_width), -1;
	return 0;
}

/* The plane world: the robots' chains from their joints' initial angles, the
 * walls, and no overlap at the start. */
#define SIM_PLANE_STRAIGHTEN 6
static int sim_plane_build(struct sim *s, char *err, size_t errcap)
{
	const struct sim_config *c = &s->cfg;
	struct plane_params pp = c->plane;
	pp.restitution = c->world.restitution;
	pp.wall_restitution = c->world.wall_restitution;
	if (c->world.beta > 0)
		return snprintf(err, errcap, "world.beta = %g: beta is the row world's mobility; in the plane the "
		                "robots' bases move by contact and drag (remove it)", c->world.beta), -1;
	for (size_t i = 0; i < c->nrobots; i++)
		if (c->robots[i].beta_set)
			return snprintf(err, errcap, "robot %s: beta is the row world's mobility; in the plane the "
			                "robots' bases move by contact and drag (remove it)", c->robots[i].name), -1;
	if (s->nbuses > PLANE_MAX_ROBOTS || s->world.nbodies != s->nbuses)
		return snprintf(err, errcap, "world.kind = plane: at most %d robots, each with a contact joint "
		                "(contact = none has no meaning: any link touches)", PLANE_MAX_ROBOTS), -1;
	for (size_t i = 0; i < s->nbuses; i++)
		if (s->buses[i].njoints > PLANE_MAX_JOINTS || s->body_bus[i] != (int)i)
			return snprintf(err, errcap, "robot %s: a plane robot has 1 to %d servos", s->buses[i].name,
			                PLANE_MAX_JOINTS), -1;
	char why[160];
	int ra, la, rb, lb;
	/* Robots whose seeded bends make them start inside each other (or a
	 * wall) are straightened, halving their joints' angles, up to
	 * SIM_PLANE_STRAIGHTEN times (the row nudges its bodies apart the same
	 * way); what still overlaps then is refused. Deterministic per seed. */
	for (int tries = 0;; tries++) {
		s->plane = plane_new(&pp, why, sizeof why);
		if (s->plane == NULL)
			return snprintf(err, errcap, "%s", why), -1;
		for (size_t i = 0; i < s->nbuses; i++)
			if (sim_plane_robot(s, i, err, errcap) != 0)
				return -1;
		if (sim_plane_walls(s, why, sizeof why) != 0)
			return snprintf(err, errcap, "world: %s", why), -1;
		if (!plane_overlap(s->plane, &ra, &la, &rb, &lb) || tries == SIM_PLANE_STRAIGHTEN)
			break;
		plane_free(s->plane);
		s->plane = NULL;
		for (int r = 0; r < 2; r++) {
			int bus = r == 0 ? ra : rb;
			if (bus == PLANE_WALL)
				continue;
			for (size_t k = 0; k < s->buses[bus].njoints; k++)
				s->buses[bus].joints[k].motor.angle *= 0.5;
		}
	}
	if (plane_overlap(s->plane, &ra, &la, &rb, &lb)) {
		static const char *const wall[4] = { "the left wall", "the right wall", "the back wall", "the front wall" };
		char other[80];
		if (rb == PLANE_WALL) {
			int k = 0;
			while (k < 3 && s->plane_wall[k] != lb)
				k++;
			snprintf(other, sizeof other, "%s", wall[k]);
		} else {
			snprintf(other, sizeof other, "robot %s's link %d", s->buses[rb].name, lb + 1);
		}
		return snprintf(err, errcap, "world: at the start robot %s's link %d overlaps %s (robots %g m apart, "
		                "joints within +-%g rad): set world.spacing wider, positions apart, or sim.initial_spread "
		                "lower", s->buses[ra].name, la + 1, other, config_spacing(c), c->initial_spread), -1;
	}
	return 0;
}

/* The row world's view of the plane's robots: each body's neutral position
 * is its robot's centre (x). */
static void sim_plane_view(struct sim *s)
{
	for (size_t i = 0; i < s->world.nbodies; i++) {
		double x, y, vx, vy;
		plane_robot_centre(s->plane, (int)i, &x, &y, &vx, &vy);
		s->world.bodies[i].neutral = x;
	}
}

int sim_init(struct sim *s, const struct sim_config *cfg, char *err, size_t errcap)
{
	memset(s, 0, sizeof(*s));
	s->cfg = *cfg;
	s->dt = 1.0 / cfg->rate_hz;
	s->rng = cfg->seed ? cfg->seed : 1;
	sim_world_init(&s->world, &cfg->world);
	for (size_t i = 0; i < cfg->nrobots; i++)
		if (sim_add_robot(s, &cfg->robots[i], err, errcap) != 0)
			return -1;
	if (cfg->world_kind == SIM_WORLD_PLANE) {
		/* the row's view: bodies where the robots stand, walls from them */
		for (size_t i = 0; i < s->world.nbodies; i++) {
			double x, y, h;
			sim_plane_place(s, (size_t)s->body_bus[i], &x, &y, &h);
			s->world.bodies[i].neutral = x;
		}
		sim_layout_world(s);
		for (size_t i = 0; i < s->nbuses; i++)
			for (size_t k = 0; k < s->buses[i].njoints; k++) {
				struct sim_joint *j = &s->buses[i].joints[k];
				double a = (2.0 * sim_rand_uniform(&s->rng) - 1.0) * s->cfg.initial_spread;
				sim_motor_init(&j->motor, &j->params, a);
			}
		if (sim_plane_build(s, err, errcap) != 0)
			return -1;
		sim_plane_view(s);
		sim_sync_present(s);
		return 0;
	}
	sim_place_bodies(s);
	sim_layout_world(s);
	sim_initial_angles(s);
	sim_sync_present(s);
	return 0;
}

void sim_free(struct sim *s)
{
	plane_free(s->plane);
	s->plane = NULL;
}

int sim_open(struct sim *s, char *err, size_t errcap)
{
	for (size_t i = 0; i < s->nbuses; i++)
		if (sim_bus_open(&s->buses[i], err, errcap) != 0) {
			sim_close(s);
			return -1;
		}
	return 0;
}

void sim_close(struct sim *s)
{
	for (size_t i = 0; i < s->nbuses; i++)
		sim_bus_release(&s->buses[i]);
}

/* ---- physics ------------------------------------------------------------------ */

static void sim_sense_joint(struct sim_joint *j, double dt)
{
	j->ops->sense(j, dt);
}

static void sim_sync_present(struct sim *s)
{
	for (size_t i = 0; i < s->nbuses; i++)
		for (size_t k = 0; k < s->buses[i].njoints; k++)
			s->buses[i].joints[k].ops->power_up(&s->buses[i].joints[k]);
}

static void sim_step_joint(struct sim_joint *j, double dt)
{
	j->ops->step(j, dt);
}

/* The walls of a "walls ... over S" at simulated time t (s). */
static void sim_walls_follow(struct sim *s, double t)
{
	struct sim_wall_motion *m = &s->wall_motion;
	if (!m->active)
		return;
	double u = t >= m->t1 ? 1.0 : (t - m->t0) / (m->t1 - m->t0);
	if (u < 0)
		u = 0;
	s->world.params.wall_left = m->from_left + u * (m->to_left - m->from_left);
	s->world.params.wall_right = m->from_right + u * (m->to_right - m->from_right);
	if (u >= 1.0)
		m->active = false;
}

/* ---- the plane world: a step ------------------------------------------------------ */

/* A joint's drive over the next step, whatever its model. */
static void sim_joint_drive(struct sim_joint *j, double dt, struct sim_motor_drive *d)
{
	j->ops->drive(j, dt, d);
	/* a controller's arithmetic on a repaired state is not trusted */
	if (!isfinite(d->a) || !isfinite(d->c) || !isfinite(d->cap) || !isfinite(d->duty)) {
		*d = (struct sim_motor_drive){ 0, 0, 0, 0 };
		j->motor.bad_input++;
	}
	if (d->cap < 0)
		d->cap = 0;
}

/* The side walls towards where "walls ... over S" puts them (wall_left,
 * wall_right), at no more than the motion's own speed, and never inwards
 * while the robots push a wall harder than wall_force_max: a crowd denser
 * than its links allow would otherwise be crushed through each other (the
 * paper's arena closes to 0.3 m; ten of these robots lying side by side take
 * 0.32 m). The faces reported (SIM.TRUTH's wall_left, wall_right) are where
 * the walls stand. */
static void sim_plane_walls_follow(struct sim *s)
{
	struct sim_world_params *w = &s->world.params;
	const struct sim_wall_motion *m = &s->wall_motion;
	double speed = m->t1 > m->t0 ? fmax(fabs(m->to_left - m->from_left), fabs(m->to_right - m->from_right)) /
	                                   (m->t1 - m->t0)
	                             : INFINITY;
	double step = speed * s->dt;
	for (int k = 0; k < 2; k++) {
		int wall = s->plane_wall[k];
		if (wall < 0)
			continue;
		double want = k == 0 ? w->wall_left : w->wall_right, now = s->wall_face[k];
		double move = fmax(-step, fmin(step, want - now));
		bool inwards = k == 0 ? move > 0 : move < 0;
		if (inwards && s->cfg.wall_force_max > 0 && s->wall_force[k] > s->cfg.wall_force_max) {
			move = 0;
			s->held_steps++;
		}
		if (move == 0)
			continue;
		s->wall_face[k] = now + move;
		double ax, ay, bx, by, x = s->wall_face[k] + (k == 0 ? -PLANE_WALL_RADIUS : PLANE_WALL_RADIUS);
		plane_wall(s->plane, wall, &ax, &ay, &bx, &by);
		plane_move_wall(s->plane, wall, x, ay, x, by, s->dt);
	}
}

/* The force on each wall in the last step, and links that ended up outside
 * the walls (a world the solver could not hold together: said, counted). */
static void sim_plane_walls_check(struct sim *s, const struct plane_contact *c, size_t n)
{
	for (int k = 0; k < 4; k++)
		s->wall_force[k] = 0;
	for (size_t i = 0; i < n; i++)
		if (c[i].robot_b == PLANE_WALL)
			for (int k = 0; k < 4; k++)
				if (s->plane_wall[k] == c[i].link_b)
					s->wall_force[k] += c[i].normal_impulse / s->dt;
	const struct sim_config *cfg = &s->cfg;
	bool sides = s->plane_wall[0] >= 0, ends = s->plane_wall[2] >= 0;
	double slack = cfg->plane.link_width;
	for (int r = 0; r < plane_robots(s->plane); r++)
		for (int l = 0; l <= plane_joints(s->plane, r); l++) {
			struct plane_link_pose p;
			plane_link(s->plane, r, l, &p);
			bool out = (sides && (p.x < s->wall_face[0] - slack || p.x > s->wall_face[1] + slack)) ||
			           (ends && (p.y < cfg->ends_back - slack || p.y > cfg->ends_front + slack)) ||
			           !isfinite(p.x) || !isfinite(p.y);
			if (out && s->escaped++ % 1000 == 0)
				fprintf(stderr, "undulate-sim: the plane world broke: robot %s's link %d is outside the walls "
				        "at (%.3f, %.3f) m, t = %.3f s (%llu link-steps so far)\n", s->buses[r].name, l + 1,
				        p.x, p.y, (double)s->steps * s->dt, s->escaped);
		}
}

/* Impulses summed per pair of links until sim_contacts_drain(). */
static void sim_contact_accumulate(struct sim *s, const struct plane_contact *c)
{
	for (size_t i = 0; i < s->ncontact_acc; i++) {
		struct plane_contact *a = &s->contact_acc[i];
		if (a->robot_a == c->robot_a && a->link_a == c->link_a && a->robot_b == c->robot_b && a->link_b == c->link_b) {
			double imp = a->impulse + c->impulse, nimp = a->normal_impulse + c->normal_impulse;
			bool impact = a->impact || c->impact;
			*a = *c;
			a->impulse = imp;
			a->normal_impulse = nimp;
			a->impact = impact;
			return;
		}
	}
	if (s->ncontact_acc < PLANE_MAX_CONTACTS)
		s->contact_acc[s->ncontact_acc++] = *c;
	else
		s->contact_acc_dropped++;
}

/* The step's contacts as the row world's collisions and totals: an impact is
 * a collision, a pair still touching is resting contact. */
static void sim_plane_collisions(struct sim *s)
{
	static struct plane_contact c[PLANE_MAX_CONTACTS];
	size_t n = plane_contacts(s->plane, c, PLANE_MAX_CONTACTS);
	if (n > PLANE_MAX_CONTACTS)
		n = PLANE_MAX_CONTACTS;
	s->nstep_collisions = 0;
	sim_plane_walls_check(s, c, n);
	for (size_t i = 0; i < n; i++) {
		bool resting = !c[i].impact;
		s->world.total_collisions++;
		s->world.total_impulse += c[i].impulse;
		if (resting) {
			s->world.resting_contacts++;
			s->world.resting_impulse += c[i].impulse;
		}
		sim_contact_accumulate(s, &c[i]);
		if (s->nstep_collisions == SIM_MAX_COLLISIONS_PER_STEP)
			continue;
		s->step_collisions[s->nstep_collisions++] = (struct sim_collision){
			.time = (double)(s->steps + 1) * s->dt, .left = c[i].robot_a,
			.right = c[i].robot_b == PLANE_WALL ? -1 : c[i].robot_b,
			.pre_left = c[i].approach, .post_left = -c[i].separation,
			.impulse = c[i].impulse, .resting = resting,
		};
	}
}

static void sim_plane_step(struct sim *s)
{
	struct sim_motor_drive d[PLANE_MAX_ROBOTS][PLANE_MAX_JOINTS];
	for (size_t i = 0; i < s->nbuses; i++)
		for (size_t k = 0; k < s->buses[i].njoints; k++) {
			struct sim_joint *j = &s->buses[i].joints[k];
			struct plane_drive *pd = &s->plane_drives[i * PLANE_MAX_JOINTS + k];
			sim_joint_drive(j, s->dt, &d[i][k]);
			*pd = (struct plane_drive){ .a = d[i][k].a, .c = d[i][k].c, .cap = d[i][k].cap };
			sim_motor_loss(&j->params, &d[i][k], &pd->viscous, &pd->coulomb);
		}
	sim_walls_follow(s, (double)(s->steps + 1) * s->dt);
	sim_plane_walls_follow(s);
	plane_step(s->plane, s->dt, s->plane_drives, s->plane_joints);
	for (size_t i = 0; i < s->nbuses; i++)
		for (size_t k = 0; k < s->buses[i].njoints; k++) {
			struct sim_joint *j = &s->buses[i].joints[k];
			const struct plane_joint *pj = &s->plane_joints[i * PLANE_MAX_JOINTS + k];
			sim_motor_moved(&j->motor, &j->params, &d[i][k], pj->angle, pj->speed, pj->torque, s->dt);
		}
	sim_plane_view(s);
	sim_plane_collisions(s);
	for (size_t i = 0; i < s->nbuses; i++)
		for (size_t k = 0; k < s->buses[i].njoints; k++)
			sim_sense_joint(&s->buses[i].joints[k], s->dt);
	s->steps++;
}

/* The row's step collisions, impacts and resting contact, as contacts per
 * pair of bodies: a point on the line where they touch, the normal along it. */
static void sim_row_contacts(struct sim *s)
{
	for (size_t i = 0; i < s->nstep_collisions; i++) {
		const struct sim_collision *c = &s->step_collisions[i];
		int a = c->left >= 0 ? c->left : c->right, b = c->left >= 0 ? c->right : -1;
		if (a < 0)
			continue;
		double x = sim_world_lateral(&s->world, (size_t)a);
		struct plane_contact pc = {
			.robot_a = a, .robot_b = b >= 0 ? b : PLANE_WALL, .link_b = -1, .impulse = c->impulse,
			.normal_impulse = c->impulse, .x = x, .nx = c->left >= 0 ? 1.0 : -1.0,
			.approach = c->pre_left - c->pre_right, .separation = c->post_right - c->post_left,
			.impact = !c->resting,
		};
		sim_contact_accumulate(s, &pc);
	}
}

size_t sim_contacts_drain(struct sim *s, struct plane_contact *out, size_t cap)
{
	size_t n = s->ncontact_acc < cap ? s->ncontact_acc : cap;
	if (out != NULL && n > 0)
		memcpy(out, s->contact_acc, n * sizeof *out);
	size_t had = s->ncontact_acc;
	s->ncontact_acc = 0;
	return had;
}

void sim_step(struct sim *s)
{
	if (s->plane != NULL) {
		sim_plane_step(s);
		return;
	}
	for (size_t i = 0; i < s->nbuses; i++)
		for (size_t k = 0; k < s->buses[i].njoints; k++)
			sim_step_joint(&s->buses[i].joints[k], s->dt);
	sim_walls_follow(s, (double)(s->steps + 1) * s->dt);
	s->nstep_collisions = sim_world_resolve(&s->world, s->dt, s->step_collisions, SIM_MAX_COLLISIONS_PER_STEP);
	if (s->nstep_collisions > SIM_MAX_COLLISIONS_PER_STEP)
		s->nstep_collisions = SIM_MAX_COLLISIONS_PER_STEP;
	sim_row_contacts(s);
	for (size_t i = 0; i < s->nbuses; i++)
		for (size_t k = 0; k < s->buses[i].njoints; k++)
			sim_sense_joint(&s->buses[i].joints[k], s->dt);
	s->steps++;
}

/* ---- commands --------------------------------------------------------------- */

struct sim_cmd_ctx {
	struct sim *s;
	int argc;
	char **argv;
	int64_t now;
	char *reply;
	size_t cap;
};

#define REPLY(x, ...) (snprintf((x)->reply, (x)->cap, __VA_ARGS__))
#define FAIL(x, ...) (REPLY(x, "error: " __VA_ARGS__), -1)

struct sim_bus *sim_find_bus(struct sim *s, const char *name_or_link)
{
	for (size_t i = 0; i < s->nbuses; i++)
		if (!strcmp(s->buses[i].name, name_or_link) || !strcmp(s->buses[i].link, name_or_link))
			return &s->buses[i];
	return NULL;
}

struct sim_joint *sim_find_joint(struct sim_bus *b, uint8_t id)
{
	/* Look up by the configured wiring slot's current ID. */
	for (size_t k = 0; k < b->njoints; k++)
		if (sim_joint_id(&b->joints[k]) == id)
			return &b->joints[k];
	return NULL;
}

/* Every joint selected by BUS ('*' = all) and ID ('*' = all). Calls fn on each;
 * returns how many matched, -1 on a bad selector. */
static int sim_each_joint(struct sim_cmd_ctx *x, const char *bus, const char *id,
                          int (*fn)(struct sim_cmd_ctx *, struct sim_bus *, struct sim_joint *, void *), void *arg)
{
	struct sim *s = x->s;
	long want = -1;
	if (strcmp(id, "*") && num_parse_long(id, 0, DXL_MAX_ID, &want) != NUM_OK)
		return FAIL(x, "bad servo id '%s' (0..253 or *)", id);
	int matched = 0;
	for (size_t i = 0; i < s->nbuses; i++) {
		struct sim_bus *b = &s->buses[i];
		if (strcmp(bus, "*") && strcmp(bus, b->name) && strcmp(bus, b->link))
			continue;
		for (size_t k = 0; k < b->njoints; k++) {
			/* Faults follow the wiring slot: the ID it was configured with
			 * or has now. */
			bool hit = want < 0 || sim_joint_id(&b->joints[k]) == want ||
			           s->cfg.robots[i].ids[k] == want;
			if (!hit)
				continue;
			if (fn(x, b, &b->joints[k], arg) != 0)
				return -1;
			matched++;
		}
	}
	if (matched == 0)
		return FAIL(x, "no servo matches '%s %s'", bus, id);
	return matched;
}

/* stuck-error's ARG must mean something in the servo's protocol: 1.0's
 * error bits or 2.0's ERR field. */
static int fault_fits(struct sim_cmd_ctx *x, struct sim_bus *b, struct sim_joint *j, const struct sim_fault *f,
                      enum sim_fault_kind kind)
{
	if (kind != SIM_FAULT_STUCK_ERROR)
		return 0;
	const char *why;
	if (!j->ops->error_fits(f, &why))
		return FAIL(x, "stuck-error: servo %u on %s %s", sim_joint_id(j), b->name, why);
	return 0;
}

struct fault_cmd {
	struct sim_fault f;
	enum sim_fault_kind kind;
	bool apply;              /* false: only check that it fits every servo */
};

static int do_fault_one(struct sim_cmd_ctx *x, struct sim_bus *b, struct sim_joint *j, void *arg)
{
	const struct fault_cmd *fc = arg;
	if (!fc->apply)
		return fault_fits(x, b, j, &fc->f, fc->kind);
	j->faults.f[fc->kind] = fc->f;
	return 0;
}

static int cmd_fault(struct sim_cmd_ctx *x)
{
	char why[200];
	struct fault_cmd fc = { .apply = false };
	if (x->argc < 4)
		return FAIL(x, "usage: fault BUS ID|* KIND [ARG] [count=N] [prob=P]");
	if (sim_fault_parse(x->argc - 3, x->argv + 3, &fc.kind, &fc.f, why, sizeof(why)) != 0)
		return FAIL(x, "%s", why);
	/* every servo it names first, so that a refusal changes nothing */
	if (sim_each_joint(x, x->argv[1], x->argv[2], do_fault_one, &fc) < 0)
		return -1;
	fc.apply = true;
	int n = sim_each_joint(x, x->argv[1], x->argv[2], do_fault_one, &fc);
	return n < 0 ? -1 : (REPLY(x, "ok %d servo(s): %s", n, sim_fault_name(fc.kind)), 0);
}

static int do_clear_one(struct sim_cmd_ctx *x, struct sim_bus *b, struct sim_joint *j, void *arg)
{
	(void)x;
	(void)b;
	int kind = *(int *)arg;
	if (kind < 0)
		sim_faults_clear(&j->faults);
	else
		memset(&j->faults.f[kind], 0, sizeof(j->faults.f[kind]));
	return 0;
}

static int cmd_clear(struct sim_cmd_ctx *x)
{
	if (x->argc < 2 || x->argc > 4)
		return FAIL(x, "usage: clear BUS|* [ID|*] [KIND]");
	int kind = -1;
	if (x->argc == 4) {
		for (int k = 0; k < SIM_FAULT_KINDS; k++)
			if (!strcmp(x->argv[3], sim_fault_name((enum sim_fault_kind)k)))
				kind = k;
		if (kind < 0)
			return FAIL(x, "unknown fault '%s'", x->argv[3]);
	}
	int n = sim_each_joint(x, x->argv[1], x->argc >= 3 ? x->argv[2] : "*", do_clear_one, &kind);
	return n < 0 ? -1 : (REPLY(x, "ok %d servo(s)", n), 0);
}

static int do_power_one(struct sim_cmd_ctx *x, struct sim_bus *b, struct sim_joint *j, void *arg)
{
	(void)x;
	(void)b;
	if (*(bool *)arg) {
		if (!sim_joint_powered(j))
			j->ops->power_on(j);
	} else {
		j->ops->power_off(j);
	}
	return 0;
}

static int cmd_power(struct sim_cmd_ctx *x)
{
	bool on;
	if (x->argc != 4 || (strcmp(x->argv[3], "on") && strcmp(x->argv[3], "off")))
		return FAIL(x, "usage: power BUS|* ID|* on|off");
	on = !strcmp(x->argv[3], "on");
	int n = sim_each_joint(x, x->argv[1], x->argv[2], do_power_one, &on);
	return n < 0 ? -1 : (REPLY(x, "ok %d servo(s) %s", n, on ? "on" : "off"), 0);
}

static struct sim_bus *cmd_bus(struct sim_cmd_ctx *x, const char *usage)
{
	struct sim_bus *b = x->argc >= 2 ? sim_find_bus(x->s, x->argv[1]) : NULL;
	if (!b) {
		if (x->argc < 2)
			REPLY(x, "error: usage: %s", usage);
		else
			REPLY(x, "error: no bus '%s'", x->argv[1]);
	}
	return b;
}

static int cmd_disconnect(struct sim_cmd_ctx *x)
{
	struct sim_bus *b = cmd_bus(x, "disconnect BUS");
	if (!b)
		return -1;
	if (!sim_bus_connected(b))
		return FAIL(x, "%s is already disconnected", b->name);
	sim_bus_close(b);
	b->count.disconnects++;
	return REPLY(x, "ok %s disconnected", b->name), 0;
}

static int cmd_reconnect(struct sim_cmd_ctx *x)
{
	char why[300];
	struct sim_bus *b = cmd_bus(x, "reconnect BUS");
	if (!b)
		return -1;
	if (sim_bus_connected(b))
		return FAIL(x, "%s is connected", b->name);
	if (sim_bus_open(b, why, sizeof(why)) != 0)
		return FAIL(x, "%s", why);
	return REPLY(x, "ok %s -> %s", b->link, b->slave_path), 0;
}

static int cmd_garbage(struct sim_cmd_ctx *x)
{
	uint8_t bytes[SIM_FAULT_MAX_GARBAGE];
	struct sim_bus *b = cmd_bus(x, "garbage BUS [N]");
	if (!b)
		return -1;
	long n = 8;
	if (x->argc > 3 || (x->argc == 3 && num_parse_long(x->argv[2], 1, SIM_FAULT_MAX_GARBAGE, &n) != NUM_OK))
		return FAIL(x, "garbage: N in 1..%d", SIM_FAULT_MAX_GARBAGE);
	for (long i = 0; i < n; i++)
		bytes[i] = (uint8_t)sim_rand_next(&b->rng);
	sim_bus_inject(b, bytes, (size_t)n, x->now);
	return REPLY(x, "ok %ld bytes", n), 0;
}

/* The servo with ID text on b; NULL with the reply set. (atoi() wrapped
 * "257" onto servo 1.) */
static struct sim_joint *cmd_joint(struct sim_cmd_ctx *x, struct sim_bus *b, const char *text)
{
	int id;
	if (num_parse_int(text, 0, DXL_MAX_ID, &id) != NUM_OK) {
		REPLY(x, "error: bad servo id '%s' (0..253)", text);
		return NULL;
	}
	struct sim_joint *j = sim_find_joint(b, (uint8_t)id);
	if (!j)
		REPLY(x, "error: no servo %d on %s", id, b->name);
	return j;
}

/* A register of j's table by name (its aliases too); false with the reply set. */
static bool cmd_reg(struct sim_cmd_ctx *x, const struct sim_joint *j, const char *name, struct sim_joint_reg *r)
{
	char why[128];
	if (j->ops->reg(j, name, r, why, sizeof why))
		return true;
	REPLY(x, "error: %s", why);
	return false;
}

/* poke BUS ID REG VALUE: set a register without the write rules (any value
 * its bytes can hold). */
static int cmd_poke(struct sim_cmd_ctx *x)
{
	struct sim_bus *b = cmd_bus(x, "poke BUS ID REG VALUE");
	if (!b)
		return -1;
	if (x->argc != 5)
		return FAIL(x, "usage: poke BUS ID REG VALUE");
	struct sim_joint *j = cmd_joint(x, b, x->argv[2]);
	struct sim_joint_reg r;
	if (!j || !cmd_reg(x, j, x->argv[3], &r))
		return -1;
	long v;
	if (num_parse_long(x->argv[4], r.lo, r.hi, &v) != NUM_OK)
		return FAIL(x, "bad value '%s' (%ld..%ld)", x->argv[4], r.lo, r.hi);
	j->ops->poke(j, r.addr, v);
	return REPLY(x, "ok %s=%ld", r.name, v), 0;
}

static int cmd_peek(struct sim_cmd_ctx *x)
{
	struct sim_bus *b = cmd_bus(x, "peek BUS ID REG");
	if (!b)
		return -1;
	if (x->argc != 4)
		return FAIL(x, "usage: peek BUS ID REG");
	struct sim_joint *j = cmd_joint(x, b, x->argv[2]);
	struct sim_joint_reg r;
	if (!j || !cmd_reg(x, j, x->argv[3], &r))
		return -1;
	return REPLY(x, "ok %ld", j->ops->peek(j, r.addr)), 0;
}

/* The active faults' names after "faults=", or "none". */
static void cmd_fault_names(struct sim_cmd_ctx *x, const struct sim_joint *j, size_t off)
{
	bool any = false;
	for (int k = 0; k < SIM_FAULT_KINDS && off < x->cap; k++)
		if (j->faults.f[k].active) {
			off += (size_t)snprintf(x->reply + off, x->cap - off, "%s%s", any ? "," : "",
			                        sim_fault_name((enum sim_fault_kind)k));
			any = true;
		}
	if (!any && off < x->cap)
		snprintf(x->reply + off, x->cap - off, "none");
}

/* servo BUS ID: one line of state, faults and counters (for people and tests). */
static int cmd_servo(struct sim_cmd_ctx *x)
{
	struct sim_bus *b = cmd_bus(x, "servo BUS ID");
	if (!b)
		return -1;
	if (x->argc != 3)
		return FAIL(x, "usage: servo BUS ID");
	struct sim_joint *j = cmd_joint(x, b, x->argv[2]);
	if (!j)
		return -1;
	char line[640];
	j->ops->describe(j, line, sizeof line);
	size_t off = (size_t)REPLY(x, "ok %sfaults=", line);
	cmd_fault_names(x, j, off);
	return 0;
}

/* walls none | walls LEFT RIGHT [over S]: at once, or moving on a straight
 * line from where they stand to LEFT RIGHT over S simulated seconds (the
 * paper's arena closes from 2.0 m to 0.3 m in 90 s). */
static int cmd_walls(struct sim_cmd_ctx *x)
{
	struct sim *s = x->s;
	struct sim_world_params *p = &s->world.params;
	if (x->argc == 2 && !strcmp(x->argv[1], "none")) {
		s->wall_motion.active = false;
		p->wall_left = p->wall_right = 0;
		return REPLY(x, "ok no walls"), 0;
	}
	double l = 0, r = 0, span = 0;
	bool over = x->argc == 5 && !strcmp(x->argv[3], "over");
	if ((x->argc != 3 && !over) || num_parse_double(x->argv[1], &l) != NUM_OK ||
	    num_parse_double(x->argv[2], &r) != NUM_OK || !(l < r))
		return FAIL(x, "usage: walls none | walls LEFT RIGHT [over S] (m, LEFT < RIGHT; S seconds)");
	if (over && (num_parse_double(x->argv[4], &span) != NUM_OK || !(span > 0) || span > SIM_WALL_SPAN_MAX_S))
		return FAIL(x, "walls ... over S: S is seconds of simulated time, > 0 and at most %g, not '%s'",
		            SIM_WALL_SPAN_MAX_S, x->argv[4]);
	if (over && !(p->wall_left < p->wall_right))
		return FAIL(x, "walls ... over S: there are no walls to move (place them first: walls LEFT RIGHT)");
	s->wall_motion.active = false;
	if (!over) {
		p->wall_left = l;
		p->wall_right = r;
		return REPLY(x, "ok walls %g %g", l, r), 0;
	}
	double now = (double)s->steps * s->dt;
	s->wall_motion = (struct sim_wall_motion){
		.active = true, .from_left = p->wall_left, .from_right = p->wall_right, .to_left = l, .to_right = r,
		.t0 = now, .t1 = now + span,
	};
	return REPLY(x, "ok walls %g %g -> %g %g over %g s (simulated t = %.3f .. %.3f s)", p->wall_left,
	             p->wall_right, l, r, span, now, now + span), 0;
}

/* kick BUS ID DW: a tap on the link, DW rad/s added to the joint's true
 * speed before the next physics step — the paper's perturbation of a locked
 * pair ("anti-phase is stable against perturbation"), made through the
 * body as a hand would, so the daemon senses it only through the servo's
 * readings. An event at a simulated time kicks the same way in real time and
 * in lockstep. The row world only: the plane's bodies keep their speeds
 * in the physics library, which takes no such impulse from here yet. */
static int cmd_kick(struct sim_cmd_ctx *x)
{
	struct sim *s = x->s;
	struct sim_bus *b = cmd_bus(x, "kick BUS ID DW");
	if (!b)
		return -1;
	double dw = 0;
	if (x->argc != 4)
		return FAIL(x, "usage: kick BUS ID DW (rad/s added to the joint's speed, |DW| <= %g)", SIM_KICK_MAX);
	struct sim_joint *j = cmd_joint(x, b, x->argv[2]);
	if (!j)
		return -1;
	if (num_parse_double(x->argv[3], &dw) != NUM_OK || !(fabs(dw) <= SIM_KICK_MAX))
		return FAIL(x, "kick: DW is rad/s added to the joint's speed, |DW| <= %g, not '%s'", SIM_KICK_MAX,
		            x->argv[3]);
	if (s->plane)
		return FAIL(x, "kick: the plane world takes no kick (its bodies' speeds are the physics library's); "
		            "kick in the row world");
	double before = j->motor.speed;
	j->motor.speed += dw;
	return REPLY(x, "ok %s %u speed %.4f -> %.4f rad/s (simulated t = %.3f s)", b->name, sim_joint_id(j), before,
	             j->motor.speed, (double)s->steps * s->dt), 0;
}

static int cmd_stats(struct sim_cmd_ctx *x)
{
	struct sim *s = x->s;
	uint64_t packets = 0, replies = 0, rx = 0, tx = 0;
	for (size_t i = 0; i < s->nbuses; i++) {
		packets += s->buses[i].count.packets, replies += s->buses[i].count.replies;
		rx += s->buses[i].count.rx_bytes, tx += s->buses[i].count.tx_bytes;
	}
	/* rx_bytes, tx_bytes: the bytes the controllers sent and the servos
	 * answered, every bus (what a change of the daemon's reads costs) */
	return REPLY(x, "ok steps=%llu time=%.3f collisions=%llu impulse=%.6f resting_impulse=%.6f packets=%llu replies=%llu commands=%llu bad_commands=%llu rx_bytes=%llu tx_bytes=%llu",
	             (unsigned long long)s->steps, (double)s->steps * s->dt,
	             s->world.total_collisions - s->world.resting_contacts,
	             s->world.total_impulse, s->world.resting_impulse, (unsigned long long)packets, (unsigned long long)replies,
	             (unsigned long long)s->commands, (unsigned long long)s->bad_commands, (unsigned long long)rx,
	             (unsigned long long)tx), 0;
}

/* command ROBOT|* TEXT...: to the robots' daemons, at this simulated time
 * (lockstep only: in real time, send it with undulated --command). */
static int cmd_robot_command(struct sim_cmd_ctx *x)
{
	struct sim *s = x->s;
	if (x->argc < 3)
		return FAIL(x, "usage: command ROBOT|* TEXT (e.g. command * mode oscillator)");
	if (!s->robot_command)
		return FAIL(x, "command: robots take commands from the simulator only in lockstep (--lockstep); in real "
		            "time send them with undulated --command");
	int bus = -1;
	if (strcmp(x->argv[1], "*") != 0) {
		struct sim_bus *b = cmd_bus(x, "command ROBOT|* TEXT");
		if (!b)
			return -1;
		bus = (int)(b - s->buses);
	}
	char text[SIM_CMD_MAX], why[200];
	size_t off = 0;
	text[0] = '\0';
	for (int i = 2; i < x->argc && off < sizeof text; i++)
		off += (size_t)snprintf(text + off, sizeof text - off, "%s%s", i > 2 ? " " : "", x->argv[i]);
	int n = s->robot_command(s->robot_command_ctx, bus, text, why, sizeof why);
	if (n < 0)
		return FAIL(x, "command: %s", why);
	return REPLY(x, "ok '%s' to %d daemon(s)", text, n), 0;
}

static int cmd_list(struct sim_cmd_ctx *x)
{
	size_t off = (size_t)REPLY(x, "ok");
	for (size_t i = 0; i < x->s->nbuses && off < x->cap; i++) {
		const struct sim_bus *b = &x->s->buses[i];
		off += (size_t)snprintf(x->reply + off, x->cap - off, " %s=%s%s", b->name, b->link,
		                        sim_bus_connected(b) ? "" : "(disconnected)");
	}
	return 0;
}

static int cmd_help(struct sim_cmd_ctx *x)
{
	return REPLY(x, "ok commands: fault BUS ID KIND [ARG] [count=N] [prob=P] | clear BUS [ID] [KIND] | "
	                "power BUS ID on|off | disconnect BUS | reconnect BUS | garbage BUS [N] | "
	                "poke BUS ID REG VALUE | peek BUS ID REG | servo BUS ID | walls none|LEFT RIGHT [over S] | kick BUS ID DW | "
	                "stats | list | "
	                "command ROBOT|* TEXT (lockstep) | help"), 0;
}

static const struct {
	const char *verb;
	int (*fn)(struct sim_cmd_ctx *);
} sim_verbs[] = {
	{ "fault", cmd_fault }, { "clear", cmd_clear }, { "power", cmd_power },
	{ "disconnect", cmd_disconnect }, { "reconnect", cmd_reconnect }, { "garbage", cmd_garbage },
	{ "poke", cmd_poke }, { "peek", cmd_peek }, { "servo", cmd_servo }, { "walls", cmd_walls }, { "kick", cmd_kick }, { "stats", cmd_stats },
	{ "list", cmd_list }, { "command", cmd_robot_command }, { "help", cmd_help },
};

int sim_command(struct sim *s, const char *line, int64_t now, char *reply, size_t cap)
{
	char buf[SIM_CMD_MAX];
	char *argv[SIM_CMD_MAX_WORDS];
	int argc = 0;
	struct sim_cmd_ctx x = { s, 0, argv, now, reply, cap };
	s->commands++;
	if (strlen(line) >= sizeof(buf)) {
		s->bad_commands++;
		return FAIL(&x, "command too long (max %d bytes)", SIM_CMD_MAX - 1);
	}
	strcpy(buf, line);
	for (char *save = NULL, *w = strtok_r(buf, " \t\r\n", &save); w; w = strtok_r(NULL, " \t\r\n", &save)) {
		if (argc >= SIM_CMD_MAX_WORDS) {
			s->bad_commands++;
			return FAIL(&x, "too many words");
		}
		argv[argc++] = w;
	}
	x.argc = argc;
	if (argc == 0) {
		s->bad_commands++;
		return FAIL(&x, "empty command (try help)");
	}
	for (size_t i = 0; i < sizeof(sim_verbs) / sizeof(sim_verbs[0]); i++)
		if (!strcmp(argv[0], sim_verbs[i].verb)) {
			int r = sim_verbs[i].fn(&x);
			if (r != 0)
				s->bad_commands++;
			return r;
		}
	s->bad_commands++;
	return FAIL(&x, "unknown command '%s' (try help)", argv[0]);
}

void sim_run_events(struct sim *s, double t, int64_t now)
{
	char reply[512];
	while (s->next_event < s->cfg.nevents && s->cfg.events[s->next_event].at <= t) {
		const struct sim_event *e = &s->cfg.events[s->next_event++];
		int r = sim_command(s, e->command, now, reply, sizeof(reply));
		fprintf(stderr, "undulate-sim: t=%.3f event '%s': %s\n", t, e->command, reply);
		(void)r;
	}
}
