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
/* Slope of the return map at the anti-phase fixed point pi (theory.md):
 * f'(pi) = -(r(d~^2 - 1) + d~^2) / (r^2(d~^2 - 1) - d~^2). Anti-phase is
 * stable where |f'(pi)| < 1. NAN outside 0 <= d~ <= 1, 0 < r <= 1. */
double theory_antiphase_slope(double dsep, double r);
/* Critical separation d~_c = sqrt(r(r - 1) / (r^2 - r - 2)), where
 * f'(pi) = -1: anti-phase is stable above it. NAN outside 0 < r <= 1. */
double theory_critical_dsep(double r);
/* The third fixed point, between the compatibility limit and pi: the phase
 * difference whose size a collision keeps, |f(delta)| = delta (its sign may
 * alternate). It bounds the basins: from a larger |delta| the pair goes to
 * anti-phase, from a smaller one to the compatible set. NAN where there is
 * none (below d~_c, anti-phase repels every |delta| < pi). */
double theory_third_fixed_point(double dsep, double r);

/* Where the map leads from delta0: iterated collision to collision until the
 * pair no longer touches (|delta| below the compatibility limit, or at it:
 * grazing), comes within THEORY_SETTLED of pi or of 0 (d~ = 0), or after
 * max_n collisions. Returns the last delta; *n gets the collisions. */
#define THEORY_SETTLED 1e-9
double theory_iterate(double delta0, double dsep, double r, int max_n, int *n);

#endif
