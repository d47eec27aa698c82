/* mdl_collide.h — the collision rule of the paper's model (DESIGN.md, "The
 * contact model"): an instantaneous inelastic impact between two bodies of
 * equal mass, restitution r, and an impact on an immovable wall. Pure code.
 *
 * With equal masses the rule keeps the momentum v_l + v_r and multiplies
 * the relative speed by -r, so the kinetic energy of the relative motion,
 * (v_l - v_r)^2 / 4 per unit mass, is multiplied by r^2: the impact loses
 * (1 - r^2) (v_l - v_r)^2 / 4. test_model_collide holds it to that. */
#ifndef UNDULATE_MODEL_COLLIDE_H
#define UNDULATE_MODEL_COLLIDE_H

/* Speeds after an impact of a left body (speed v_left) on a right one
 * (v_right), restitution r in [0, 1]:
 *   post_left  = ((1 - r) v_left + (1 + r) v_right) / 2
 *   post_right = ((1 - r) v_right + (1 + r) v_left) / 2 */
void collide_pair(double r, double v_left, double v_right, double *post_left, double *post_right);

/* Speed after an impact on a wall that does not move: -r v. */
double collide_wall(double r, double v);

/* Kinetic energy of two bodies of unit mass. */
double collide_energy(double v_left, double v_right);

#endif
