/* theory.h — the contact theory (theory.md) the analyser compares runs with:
 * the collision-to-collision return map of a pair's phase difference and the
 * separation below which two joints can swing without touching. Pure code. */
#ifndef UNDULATE_ANALYZE_THEORY_H
#define UNDULATE_ANALYZE_THEORY_H

/* theory.md's collision-to-collision return map: delta_{n+1} from delta_n
 * for normalized separation d (d~) and restitution r. NAN where no contact
 * is possible (|sin(delta/2)| < d~). */
double theory_return_map(double delta, double dsep, double r);
/* Closed form at d~ = 0: delta_n = 2 atan((-r)^n tan(delta0/2)), the map
 * iterated n times (see theory.c on theory.md's sign). */
double theory_return_map_d0(double delta0, double r, int n);
/* Compatibility limit 2 asin(d~) (pi for d~ >= 1); NAN for d~ < 0 or NAN. */
double theory_compat_limit(double dsep);

#endif
