/* The energy ledger (world_ledger.h, docs/physics.md §10). */
#include "world_ledger.h"

#include "linalg.h"

#include <string.h>

/* Kinetic energy minus gravity's potential work: what a Bullet body keeps
 * in free flight, J. */
double cf_world_body_energy(const cf_world *w, const cf_fragment *f, const cfb_state *st)
{
    return cf_body_kinetic_energy(f, st) - f->mass * v3_dot(w->def.gravity, st->pos);
}

/* The ledger; the momenta too with `momenta` (for fragments in fracture
 * mode a pass over their nodes, which the energy guard does not need). */
void cf_world_ledger_terms(const cf_world *w, cf_ledger *l, int momenta)
{
    const cf_solid *s = &w->solid;
    memset(l, 0, sizeof *l);
    for (int fi = 0; fi < w->n_frag; fi++) {
        const cf_fragment *f = &w->frag[fi];
        if (f->mode == CF_MODE_DEAD)
            continue;
        double P[3] = {0, 0, 0}, L[3] = {0, 0, 0};
        if (f->body >= 0) {
            cfb_state st;
            cfb_get_state(w->bullet, f->body, &st);
            l->kinetic += cf_body_kinetic_energy(f, &st);
            v3_axpy(f->mass, st.pos, l->mass_moment);
            if (momenta)
                cf_body_momenta(f, &st, P, L);
        } else {
            l->kinetic += f->e_kin;
            l->strain += f->e_strain;
            v3_axpy(1.0, f->mx, l->mass_moment);
            if (momenta)
                cf_fragment_momenta(f, &w->solid, w->bullet, P, L);
        }
        v3_axpy(1.0, P, l->momentum);
        v3_axpy(1.0, L, l->angular_momentum);
    }
    cf_cohesive_energy(s, NULL, 0, &l->cohesive_stored, &l->cohesive_dissipated);
    l->plastic_dissipated = 0;
    if (s->wp)
        for (int t = 0; t < s->n_tets; t++) /* tet order: the same sum on any thread count */
            l->plastic_dissipated += s->wp[t];
    double dmx[3];
    v3_sub(l->mass_moment, w->mx0, dmx);
    l->work_gravity = v3_dot(w->def.gravity, dmx);
    l->work_boundary = w->flow.boundary;
    l->work_obstacles = w->flow.obstacles;
    l->contact = w->flow.contact, l->pbd = w->flow.pbd;
    l->damping = w->flow.damping, l->handoff = w->flow.handoff;
    if (s->bv_work) /* the bulk viscosity's, tet by tet (tet4.h) */
        for (int t = 0; t < s->n_tets; t++)
            l->damping += s->bv_work[t];
    l->integration = w->flow.integration;
    l->initial = w->e0;
    l->residual = l->kinetic + l->strain + l->cohesive_stored + l->cohesive_dissipated +
                  l->plastic_dissipated + l->contact + l->pbd + l->damping + l->handoff + l->integration -
                  (l->initial + l->work_gravity + l->work_boundary + l->work_obstacles);
}

void cf_world_ledger(const cf_world *w, cf_ledger *l) { cf_world_ledger_terms(w, l, 1); }
