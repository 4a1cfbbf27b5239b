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
cf_status cf_world_push_event(cf_world *w, const cf_event *e, cf_error *err)
{
    if (w->n_ev == w->cap_ev) {
        int cap = w->cap_ev ? 2 * w->cap_ev : 16;
        cf_event *ev = realloc(w->ev, (size_t)cap * sizeof *ev);
        if (!ev)
            return cf_error_set(err, CF_ERR_NOMEM, "out of memory recording an event");
        w->ev = ev, w->cap_ev = cap;
    }
    w->ev[w->n_ev++] = *e;
    return CF_OK;
}

int cf_world_alive_fragments(const cf_world *w, int *in_fracture)
{
    int n = 0, nf = 0;
    for (int i = 0; i < w->n_frag; i++) {
        n += w->frag[i].mode != CF_MODE_DEAD;
        nf += w->frag[i].mode == CF_MODE_FRACTURE;
    }
    if (in_fracture)
        *in_fracture = nf;
    return n;
}

/* Fragments first .. n_frag - 1 were born. */
cf_status cf_world_fragments_born(cf_world *w, int first, cf_error *err)
{
    if (first >= w->n_frag)
        return CF_OK;
    cf_event e = {.type = CF_EVENT_FRAGMENTS, .time = w->t, .first = first,
                  .count = w->n_frag - first, .alive = cf_world_alive_fragments(w, NULL)};
    return cf_world_push_event(w, &e, err);
}
