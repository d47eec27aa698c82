/* csvrow.h — the CSV files that undulate-analyze writes from a log and
 * undulate-model writes from its run (states.csv, phase_diff.csv,
 * collisions.csv: README.md, "Output"): their headers, their number and
 * string fields, and the collision row, in one place so that the two
 * programs' files stay the same format and the figures read either. */
#ifndef UNDULATE_ANALYZE_CSVROW_H
#define UNDULATE_ANALYZE_CSVROW_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define CSVROW_STATES_HEADER                                                                                 \
	"utime,t,robot,joint,servo_id,angle,speed,goal,load,mode,phase,amplitude,frequency,error_bits,phase_daemon," \
	"frequency_est,robot_index"
#define CSVROW_PDIFF_HEADER "utime,t,pair,kind,robot_a,joint_a,robot_b,joint_b,delta"
#define CSVROW_COLLISIONS_HEADER                                                                              \
	"utime,t,left,right,left_robot,right_robot,pre_left,pre_right,post_left,post_right,impulse,pair,delta_before," \
	"new_contact"

/* ",NUMBER": %.9g keeps full double-ish precision for the numbers people
 * trust; a number that is not finite is an empty field. */
void csvrow_num(FILE *f, double v);
/* n number fields in a row, each as csvrow_num. */
void csvrow_nums(FILE *f, const double *v, size_t n);
/* A quoted string ("" inside; a line break becomes a space). */
void csvrow_str(FILE *f, const char *s);

/* One row of collisions.csv. */
struct csvrow_collision {
	int64_t utime;
	double t;
	int left, right;                  /* the robots' indices (wall: -1) */
	const char *left_robot, *right_robot;
	double pre_left, pre_right, post_left, post_right, impulse;
	const char *pair;                 /* NULL: no pair (a wall, or one not followed) */
	double delta;                     /* the pair's phase difference before (NAN: unknown) */
	bool new_contact;
};
void csvrow_collision(FILE *f, const struct csvrow_collision *r);

#endif
