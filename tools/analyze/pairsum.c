/* pairsum.c — see pairsum.h. */
#include "pairsum.h"
#include "theory.h"

void pairsum_json(struct json *j, const struct pairsum *s)
{
	json_object_begin(j);
	json_field_string(j, "pair", s->name);
	json_field_string(j, "kind", s->kind);
	json_field_string(j, "class", s->cls);
	json_field_number(j, "mean_abs_delta", win_circ_mean_abs(s->win));
	json_field_number(j, "mean_delta", win_circ_mean(s->win));
	json_field_number(j, "spread", win_circ_spread(s->win));
	json_field_int(j, "window_samples", s->win->n);
	json_field_int(j, "collisions", s->collisions);
	json_field_int(j, "contacts", s->contacts);
	json_field_int(j, "window_collisions", s->win_collisions);
	json_field_number(j, "window_impulse", s->win_impulse);
	json_field_number(j, "window_contact_impulse", s->win_contact_impulse);
	json_field_number(j, "impulse", s->impulse);
	json_field_number(j, "distance_m", s->distance);
	json_field_number(j, "amplitude_m", s->amplitude);
	json_field_number(j, "dsep", s->dsep);
	json_field_number(j, "compat_limit", theory_compat_limit(s->dsep));
	json_field_int(j, "return_map_points", s->return_map_points);
	json_field_number(j, "swing_a", s->swing_a);
	json_field_number(j, "swing_b", s->swing_b);
	json_object_end(j);
}
