/* The world's events and the Bullet bridge's errors (world_events.h). */
#include "world_events.h"

#include <stdlib.h>
#include <string.h>

/* A failed bridge call as an error: out of memory inside Bullet is
 * CF_ERR_NOMEM, anything else CF_ERR_EXTERNAL. */
cf_status cf_world_bullet_error(cf_error *err, const char *what)
{
    const char *why = cfb_last_error();
    return cf_error_set(err, strstr(why, "out of memory") ? CF_ERR_NOMEM : CF_ERR_EXTERNAL,
                        "Bullet, %s: %s", what, why);
}

/* Append an event (the array grows; out of memory drops it and says so). */
cf_status cf_world_push_event(cf_world *sim, const cf_event *e, cf_error *err)
{
    if (sim->n_ev == sim->cap_ev) {
        int cap = sim->cap_ev ? 2 * sim->cap_ev : 16;
        cf_event *ev = realloc(sim->ev, (size_t)cap * sizeof *ev);
        if (!ev)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory recording an event");
        sim->ev = ev, sim->cap_ev = cap;
    }
    sim->ev[sim->n_ev++] = *e;
    return CF_OK;
}

int cf_world_alive_fragments(const cf_world *sim, int *in_fracture)
{
    int n = 0, nf = 0;
    for (int i = 0; i < sim->n_frag; i++) {
        n += sim->frag[i].mode != CF_MODE_DEAD;
        nf += sim->frag[i].mode == CF_MODE_FRACTURE;
    }
    if (in_fracture)
        *in_fracture = nf;
    return n;
}

/* Fragments first .. n_frag - 1 were born. */
cf_status cf_world_fragments_born(cf_world *sim, int first, cf_error *err)
{
    if (first >= sim->n_frag)
        return CF_OK;
    cf_event e = {.type = CF_EVENT_FRAGMENTS, .time = sim->t, .first = first,
                  .count = sim->n_frag - first, .alive = cf_world_alive_fragments(sim, NULL)};
    return cf_world_push_event(sim, &e, err);
}
