/* What the world's creation and its step share: the events a world
 * records for its caller (cf_world_events) and the errors of the Bullet
 * bridge. */
#ifndef COHFRAC_WORLD_EVENTS_H
#define COHFRAC_WORLD_EVENTS_H

#include "world_impl.h"

/* Append event e (the array grows).  Errors: CF_ERR_NOMEM. */
cf_status cf_world_push_event(cf_world *w, const cf_event *e, cf_error *err);

/* Fragments alive (not dead); *in_fracture (when given) those in fracture
 * mode. */
int cf_world_alive_fragments(const cf_world *w, int *in_fracture);

/* The event of fragments first .. n_frag - 1 being born (none when
 * first >= n_frag).  Errors: CF_ERR_NOMEM. */
cf_status cf_world_fragments_born(cf_world *w, int first, cf_error *err);

/* A failed bridge call `what` as an error: out of memory inside Bullet is
 * CF_ERR_NOMEM, anything else CF_ERR_EXTERNAL. */
cf_status cf_world_bullet_error(cf_error *err, const char *what);

#endif
