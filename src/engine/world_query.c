/* What a world tells its caller: events, fragments, tets, cracks, the
 * state hash, statistics and memory, and its few settings (threads, the
 * heartbeat). */
#include "world_events.h"

#include "hash.h"
#include "linalg.h"
#include "sort.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const cf_event *cf_world_events(const cf_world *w, int *n)
{
    *n = w->n_ev;
    return w->ev;
}

void cf_world_clear_events(cf_world *w) { w->n_ev = 0; }

int cf_world_fragments_ever(const cf_world *w) { return w->n_frag; }

int cf_world_fragment_info(const cf_world *w, int id, cf_frag_info *o)
{
    if (id < 0 || id >= w->n_frag)
        return -1;
    const cf_fragment *f = &w->frag[id];
    memset(o, 0, sizeof *o);
    o->id = id;
    o->parent = f->parent;
    o->birth_time = f->birth_time;
    o->mass = f->mass;
    o->n_tets = f->nt;
    memcpy(o->inertia_principal, f->principal, sizeof f->principal);
    o->n_hulls = f->body >= 0 ? f->hulls.n_hulls : 0;
    o->debris = cf_fragment_is_debris(f, &w->def.solver);
    o->hull_volume_error = cf_hulls_error(&f->hulls);
    o->decomposition_time = f->decompose_time;
    memcpy(o->com_rest, f->com_rest, sizeof o->com_rest);
    return 0;
}

void cf_world_initial_bounds(const cf_world *w, cf_initial_bounds *out) { *out = w->bounds; }

int cf_world_fragments(cf_world *w, cf_fragment_state *out, int cap)
{
    int n = 0;
    for (int fi = 0; fi < w->n_frag; fi++) {
        cf_fragment *f = &w->frag[fi];
        if (f->mode == CF_MODE_DEAD)
            continue;
        if (n < cap) {
            cf_fragment_state *o = &out[n];
            double R[9];
            memset(o, 0, sizeof *o);
            o->id = fi, o->parent = f->parent, o->birth_time = f->birth_time;
            o->mode = f->mode, o->n_tets = f->nt, o->mass = f->mass;
            memcpy(o->principal, f->principal, sizeof o->principal);
            memcpy(o->axes, f->Q, sizeof o->axes);
            cf_fragment_pose_peek(f, &w->solid, w->bullet, o->com, R, o->v, o->w);
            mat_to_quat(R, o->quat);
            for (int k = 0; k < 3; k++)
                o->momentum[k] = f->mass * o->v[k];
            if (f->body >= 0) {
                cfb_state st;
                cfb_get_state(w->bullet, f->body, &st);
                cf_body_spin(f, &st, o->angular_momentum);
                o->kinetic = cf_body_kinetic_energy(f, &st);
            } else {
                cf_node_state ns;
                cf_nodes_momenta(&w->solid, f->nodes.v, f->nodes.n, &ns);
                memcpy(o->angular_momentum, ns.L, sizeof ns.L);
                for (int k = 0; k < 3; k++)
                    o->momentum[k] = ns.M * ns.v[k];
                o->kinetic = ns.ke;
            }
        }
        n++;
    }
    return n;
}

/* The largest (R (X - X_cm)).d over fragment f's nodes, m; *arm (may be
 * NULL) gets R (X - X_cm) at the centre of the nodes within a thousandth
 * of f's size of it (a face or an edge that lands flat meets the
 * obstacle there, not at one of its corners). */
static double support(const cf_world *w, const cf_fragment *f, const double R[9],
                      const double d[3], double arm[3])
{
    double Rd[3], best = -INFINITY;
    m3_tmulv(R, d, Rd); /* (R r).d = r.(R^T d), r from the rest centre of mass */
    for (int i = 0; i < f->nodes.n; i++) {
        double r[3];
        v3_sub(&w->solid.X[3 * f->nodes.v[i]], f->com_rest, r);
        best = fmax(best, v3_dot(r, Rd));
    }
    if (!f->nodes.n)
        return 0;
    if (arm) {
        double sum[3] = {0, 0, 0}, near = 1e-3 * cbrt(f->volume);
        int k = 0;
        for (int i = 0; i < f->nodes.n; i++) {
            double r[3];
            v3_sub(&w->solid.X[3 * f->nodes.v[i]], f->com_rest, r);
            if (v3_dot(r, Rd) >= best - near)
                v3_axpy(1.0, r, sum), k++;
        }
        for (int c = 0; c < 3; c++)
            sum[c] /= k;
        m3_mulv(R, sum, arm);
    }
    return best;
}

double cf_world_fragment_support(cf_world *w, int id, const double d[3])
{
    if (id < 0 || id >= w->n_frag || w->frag[id].mode == CF_MODE_DEAD)
        return 0;
    const cf_fragment *f = &w->frag[id];
    double com[3], R[9], v[3], omega[3];
    cf_fragment_pose_peek(f, &w->solid, w->bullet, com, R, v, omega);
    return support(w, f, R, d, NULL);
}

#define CF_LANDING_ITERATIONS 200
#define CF_LANDING_GAP 1e-3 /* of the fragment's equal-volume radius: arrived */

/* Where fragment f (rotation R, centre of mass c moving at v now) first
 * meets an obstacle on its ballistic path within `horizon` s: conservative
 * advancement, each advance the time in which the centre of mass, at its
 * speed and gravity's, cannot close the gap to the nearest obstacle (its
 * signed distance less f's extent toward it), with the obstacles' own
 * speed.  A contact it leaves (moving away) is stepped over.  Returns the
 * time from now (s), the approach speed there (*speed, m/s), the
 * obstacle (*hit), its normal n_hit and f's point of contact from its centre
 * of mass (arm, m); or -1 when it meets none in time or touches one now. */
static double first_contact(const cf_world *w, const cf_fragment *f, const double R[9],
                            const double c[3], const double v[3], double horizon,
                            double *speed, int *hit, double n_hit[3], double arm[3])
{
    const double *g = w->def.gravity;
    double gn = sqrt(v3_dot(g, g)), umax = 0;
    for (int j = 0; j < w->obs.n; j++) {
        double u[3];
        cf_obstacle_velocity(&w->obs.o[j], u);
        umax = fmax(umax, sqrt(v3_dot(u, u)));
    }
    double tol = fmax(1e-9, CF_LANDING_GAP * cbrt(3 * f->volume / (4 * acos(-1.0))));
    double tau = 0;
    for (int it = 0; it < CF_LANDING_ITERATIONS && tau <= horizon; it++) {
        double p[3], vel[3], gap = INFINITY, approach = 0;
        for (int k = 0; k < 3; k++) {
            p[k] = c[k] + tau * (v[k] + 0.5 * tau * g[k]);
            vel[k] = v[k] + tau * g[k];
        }
        for (int j = 0; j < w->obs.n; j++) {
            double n[3], u[3], vr[3];
            double d = cf_obstacle_distance(&w->obs, j, w->t + tau, p, n);
            double m[3] = {-n[0], -n[1], -n[2]}; /* toward the obstacle */
            d -= support(w, f, R, m, NULL);
            if (d < gap) {
                cf_obstacle_velocity(&w->obs.o[j], u);
                v3_sub(vel, u, vr);
                gap = d, approach = -v3_dot(vr, n), *hit = j;
                memcpy(n_hit, n, sizeof n);
            }
        }
        double s = sqrt(v3_dot(vel, vel)) + umax;
        if (!isfinite(gap))
            return -1; /* no obstacle within reach (a far mesh obstacle's query) */
        if (it == 0 && gap <= tol)
            return -1; /* touching now (a body just handed back has no contact yet) */
        if (gap <= tol && approach > 0) { /* arrived: where it strikes */
            double m[3] = {-n_hit[0], -n_hit[1], -n_hit[2]};
            support(w, f, R, m, arm);
            *speed = approach;
            return tau;
        }
        /* the time in which s t + g t^2 / 2 reaches the gap; a contact it
           leaves, one tolerance's travel on */
        double need = fmax(gap, tol);
        tau += gn > 0 ? 2 * need / (s + sqrt(s * s + 2 * gn * need)) : need / fmax(s, 1e-12);
    }
    return -1;
}

/* The impact the rule will see of fragment f (rotation R) striking along
 * normal n at `speed` at its point `arm` from its centre of mass, m/s:
 * the contact impulse over its mass, (1 + e) speed m_eff / m, with m_eff
 * = 1 / (1/m + (r x n).I^-1 (r x n)) the mass the contact point brings
 * (a corner strike turns the body and moves its centre less) and e the
 * pair's restitution. */
static double impact_of(const cf_world *w, const cf_fragment *f, const double R[9], int j,
                        const double n[3], const double arm[3], double speed)
{
    double rn[3], RQ[9], a[3], turn = 0;
    v3_cross(arm, n, rn);
    m3_mul(R, f->Q, RQ); /* principal axes in the world */
    m3_tmulv(RQ, rn, a);
    for (int k = 0; k < 3; k++)
        turn += f->principal[k] > 0 ? a[k] * a[k] / f->principal[k] : 0;
    double e = w->solid.mat.restitution * w->obs.o[j].restitution;
    return (1 + e) * speed / (1 + f->mass * turn);
}

int cf_world_landings(cf_world *w, double until, cf_landing *out, int cap)
{
    const cf_solver_settings *set = &w->def.solver;
    int n = 0;
    if (set->mode == CF_RUN_FRACTURE)
        return 0; /* no impact began it, and none will come */
    for (int fi = 0; fi < w->n_frag; fi++) {
        const cf_fragment *f = &w->frag[fi];
        if (f->mode == CF_MODE_FRACTURE) {
            /* under way: a piece's own landing, not a body's break nor a
               piece's share of its parent's spell, whose length the
               cracks' growth tells */
            if (f->parent < 0 || f->t_enter < f->birth_time)
                continue;
            if (n < cap)
                out[n] = (cf_landing){.fragment = fi, .n_tets = f->nt, .under_way = 1,
                                      .time = f->t_enter, .impact = f->dv_enter,
                                      .hold = cf_fragment_landing_time(
                                          f, &w->solid.mat, set->impact_threshold)};
            n++;
            continue;
        }
        if (!w->bullet || f->mode != CF_MODE_RIGID || f->body < 0 ||
            cfb_contact_impulse(w->bullet, f->body) > 0 ||
            !cf_fragment_can_break(f, &w->solid, set))
            continue;
        double com[3], R[9], v[3], omega[3], n_hit[3] = {0, 0, 0}, arm[3] = {0, 0, 0}, speed = 0;
        int j = -1;
        cf_fragment_pose_peek(f, &w->solid, w->bullet, com, R, v, omega);
        double tau = first_contact(w, f, R, com, v, until - w->t, &speed, &j, n_hit, arm);
        double dv = tau < 0 ? 0 : impact_of(w, f, R, j, n_hit, arm, speed);
        if (dv <= set->impact_threshold || dv <= f->dv_taken)
            continue;
        if (n < cap)
            out[n] = (cf_landing){.fragment = fi, .n_tets = f->nt, .time = w->t + tau,
                                  .speed = speed, .impact = dv,
                                  .hold = cf_fragment_landing_time(f, &w->solid.mat,
                                                                   set->impact_threshold)};
        n++;
    }
    return n;
}

int cf_world_tet_count(const cf_world *w) { return w->solid.n_tets; }

int cf_world_rest_node_count(const cf_world *w) { return w->solid.n_verts0; }

void cf_world_rest_nodes(const cf_world *w, double *X)
{
    memcpy(X, w->solid.X, (size_t)w->solid.n_verts0 * 3 * sizeof(double));
}

int cf_world_rest_tet(const cf_world *w, int t, int nodes[4])
{
    if (t < 0 || t >= w->solid.n_tets)
        return -1;
    memcpy(nodes, &w->solid.tet0[4 * w->tet_of_user[t]], 4 * sizeof(int));
    return 0;
}

int cf_world_tet_positions(const cf_world *w, int t, double x[12])
{
    if (t < 0 || t >= w->solid.n_tets)
        return -1;
    const cf_solid *s = &w->solid;
    int st = w->tet_of_user[t], fi = s->tet_frag[st];
    const cf_fragment *f = &w->frag[fi];
    double com[3], R[9], v[3], omega[3];
    if (f->body >= 0) /* rigid in Bullet: the nodes are not moved, the pose is */
        cf_fragment_pose_peek(f, &w->solid, w->bullet, com, R, v, omega);
    for (int j = 0; j < 4; j++) {
        int a = s->tet[4 * st + j];
        if (f->body < 0) {
            memcpy(&x[3 * j], &s->x[3 * a], 3 * sizeof(double));
            continue;
        }
        double r[3], y[3];
        v3_sub(&s->X[3 * a], f->com_rest, r);
        m3_mulv(R, r, y);
        for (int k = 0; k < 3; k++)
            x[3 * j + k] = com[k] + y[k];
    }
    return 0;
}

int cf_world_fracture_tets(const cf_world *w, int *tets, double *stress, double *damage)
{
    const cf_solid *s = &w->solid;
    int nt = s->n_tets, n = 0;
    /* damage by the solid's tets: each element's to both its sides */
    double *d = calloc((size_t)(nt > 0 ? nt : 1), sizeof *d);
    if (!d)
        return -1;
    for (int e = 0; e < s->n_coh; e++) {
        double de = cf_cohesive_damage(s, e);
        for (int side = 0; side < 2; side++)
            d[s->coh[e].tet[side]] = fmax(d[s->coh[e].tet[side]], de);
    }
    static const int voigt[6] = {0, 4, 8, 5, 2, 1}; /* xx yy zz yz xz xy of [3][3] */
    for (int t = 0; t < nt; t++) {
        int st = w->tet_of_user[t];
        if (w->frag[s->tet_frag[st]].mode != CF_MODE_FRACTURE)
            continue;
        tets[n] = t;
        damage[n] = d[st];
        for (int k = 0; k < 6; k++)
            stress[6 * n + k] = s->sigma ? s->sigma[9 * st + voigt[k]] : 0.0;
        n++;
    }
    free(d);
    return n;
}

int cf_world_tet_fragment(const cf_world *w, int t)
{
    return t >= 0 && t < w->solid.n_tets ? w->solid.tet_frag[w->tet_of_user[t]] : -1;
}

int cf_world_cohesive_count(const cf_world *w) { return w->solid.n_coh; }

int cf_world_crack(const cf_world *w, int e, cf_crack_row *r)
{
    memset(r, 0, sizeof *r);
    if (e < 0 || e >= w->solid.n_coh)
        return -1;
    r->time = w->t;
    r->element = e;
    for (int side = 0; side < 2; side++)
        r->tets[side] = w->user_of_tet[w->solid.coh[e].tet[side]];
    cf_cohesive_state(&w->solid, e, r->centroid, r->normal, &r->area, &r->opening, &r->sliding,
                      &r->failed);
    return 0;
}

double cf_world_crack_area(const cf_world *w) { return cf_solid_crack_area(&w->solid); }

const char *cf_stage_name(cf_stage s)
{
#define CF_STAGE_NAME(id, name) #name,
    static const char *const names[] = {CF_STAGES(CF_STAGE_NAME)};
#undef CF_STAGE_NAME
    return s >= 0 && s < CF_STAGE_COUNT ? names[s] : "?";
}

const cf_world_def *cf_world_definition(const cf_world *w) { return &w->def; }

void cf_world_set_tick(cf_world *w, cf_world_tick_fn fn, void *user)
{
    w->tick = fn, w->tick_user = user;
}

void cf_world_set_threads(cf_world *w, int n)
{
    if (n >= 1)
        w->threads = n;
}

long cf_world_step_count(const cf_world *w) { return w->step; }

double cf_world_dt_outer(const cf_world *w) { return w->dt_outer; }

double cf_world_time(const cf_world *w) { return w->t; }

double cf_world_dt_fracture(const cf_world *w) { return w->dt_fracture; }

double cf_world_dt_cfl(const cf_world *w) { return w->solid.dt_cfl; }

uint64_t cf_world_state_hash(const cf_world *w)
{
    const cf_solid *s = &w->solid;
    uint64_t h = CF_FNV1A_SEED;
    h = cf_fnv1a(h, s->x, (size_t)s->n_nodes * 3 * sizeof(double));
    h = cf_fnv1a(h, s->v, (size_t)s->n_nodes * 3 * sizeof(double));
    h = cf_fnv1a(h, s->tet_frag, (size_t)s->n_tets * sizeof(int));
    for (int fi = 0; fi < w->n_frag; fi++) {
        const cf_fragment *f = &w->frag[fi];
        int mode = f->mode;
        h = cf_fnv1a(h, &mode, sizeof mode);
        if (f->body >= 0) {
            cfb_state st;
            cfb_get_state(w->bullet, f->body, &st);
            h = cf_fnv1a(h, &st, sizeof st);
        }
    }
    return h;
}

void cf_world_stats_get(const cf_world *w, cf_world_stats *o)
{
    const cf_profile *p = &w->prof;
    memset(o, 0, sizeof *o);
    o->tets = w->solid.n_tets, o->nodes_input = w->solid.n_verts0;
    o->nodes = w->solid.n_nodes;
    o->dt_fracture = w->dt_fracture, o->dt_cfl = w->solid.dt_cfl, o->dt_outer = w->dt_outer;
    o->mass_scaled = w->solid.n_mass_scaled, o->mass_added = w->solid.mass_added;
    o->mass_total = w->solid.mass_total;
    o->wave_speed_least = o->mass_scaled ? 1.0 / sqrt(w->solid.mass_scale_max) : 1.0;
    o->steps_rigid = w->steps_rigid, o->steps_fracture = w->steps_fracture;
    o->threads = w->threads;
    o->alive = cf_world_alive_fragments(w, &o->in_fracture);
    o->ever = w->n_frag;
    o->cohesive = w->solid.n_coh;
    o->handoffs = w->n_handoffs;
    o->max_momentum_error = w->max_momentum_error, o->handoff_loss = w->total_handoff_loss;
    memcpy(o->stage, p->stage, sizeof o->stage);
    /* Convex decomposition of the rigid fragments alive now: median and worst
     * error (NaN when there is no memory to sort them: unknown, not 0). */
    double *e = malloc((size_t)(w->n_frag + 1) * sizeof(double));
    int n = 0;
    for (int fi = 0; fi < w->n_frag; fi++) {
        const cf_fragment *f = &w->frag[fi];
        if (f->mode != CF_MODE_DEAD)
            o->mass_alive += f->mass;
        if (f->mode != CF_MODE_DEAD && cf_fragment_is_debris(f, &w->def.solver)) {
            o->debris++;
            o->debris_mass += f->mass;
            continue;
        }
        if (f->mode == CF_MODE_RIGID && f->body >= 0) {
            if (e)
                e[n] = cf_hulls_error(&f->hulls);
            n++;
            o->hulls += f->hulls.n_hulls;
        }
    }
    if (n > 0 && !e) {
        o->hull_error_median = o->hull_error_worst = NAN;
    } else if (n > 0) {
        cf_doubles_sort(e, n);
        o->hull_error_median = n % 2 ? e[n / 2] : 0.5 * (e[n / 2 - 1] + e[n / 2]);
        o->hull_error_worst = e[n - 1];
    }
    o->rigid_with_hulls = n;
    free(e);
}

void cf_world_memory(const cf_world *w, cf_memory *m)
{
    const cf_solid *s = &w->solid;
    const unsigned long long D = sizeof(double), I = sizeof(int);
    unsigned long long cn = (unsigned long long)s->cap_nodes, nt = (unsigned long long)s->n_tets;
    memset(m, 0, sizeof *m);
    /* per node: X x v f, the row p, m vcap speed; origin bc */
    m->solid = cn * (19 * D + 2 * I) + nt * (27 * D + 9 * I) +
               ((unsigned long long)s->n_verts0 + 1 + 4 * nt) * I + (s->ep ? nt * 7 * D : 0) +
               (s->bv_eta ? nt * 3 * D : 0); /* the bulk viscosity's eta, rate, work */
    if (s->facet)
        m->fracture = nt * (9 * D + 3 + 6 + 20 * I) + cn * (1 + 7 * D + sizeof(unsigned)) +
                      (unsigned long long)s->n_facets * (1 + (s->candidate != NULL)) +
                      (unsigned long long)s->n_verts0 * (sizeof(unsigned) + sizeof(int)) +
                      (s->vert_front_active ? (unsigned long long)s->n_verts0 * (sizeof(float) + 1) +
                                                   (unsigned long long)nt * sizeof(float)
                                             : 0) +
                      (s->nucleus ? (unsigned long long)s->n_facets * I : 0); /* "crack" */
    m->cohesive = (unsigned long long)s->cap_coh *
                  (sizeof(cf_cohesive) + (s->coh_fric ? sizeof *s->coh_fric : 0));
    m->fragments = (unsigned long long)w->cap_frag * sizeof(cf_fragment);
    for (int i = 0; i < w->n_frag; i++) {
        const cf_fragment *f = &w->frag[i];
        m->fragments += (unsigned long long)f->nt * I + (unsigned long long)f->nodes.cap * I +
                        (unsigned long long)f->coh.cap * I +
                        (unsigned long long)f->bars.n * (2 * I + 3 * D) +
                        (unsigned long long)f->scratch_cap * (I + 5 * D + I + 6 * D) +
                        (unsigned long long)f->pairs_cap * 3 * sizeof(cf_pair_force);
        if (f->hulls.n_hulls)
            m->fragments += (unsigned long long)f->hulls.start[f->hulls.n_hulls] * 3 * D +
                            ((unsigned long long)f->hulls.n_hulls + 1) * I;
    }
    unsigned long long b = cfb_allocated_bytes();
    m->bullet = b > w->bullet_base ? b - w->bullet_base : 0;
    for (int j = 0; w->obs.mesh && j < w->obs.n; j++)
        m->collision += cff_mesh_bytes(w->obs.mesh[j]);
    for (int i = 0; i < w->contact.cap; i++) {
        const cf_frag_surface *fs = &w->contact.v[i].surface;
        m->collision += cff_mesh_bytes(fs->mesh) +
                        (unsigned long long)fs->nv * (I + 3 * D) + 3ull * fs->ntri * I;
    }
}

void cf_world_step_stats(const cf_world *w, cf_step_stats *o)
{
    const cf_solver_settings *set = &w->def.solver;
    memset(o, 0, sizeof *o);
    o->fracture_steps = w->steps_fracture;
    o->tet_steps = w->tet_steps_fracture, o->fracture_time = w->t_fracture;
    memcpy(o->stage, w->prof.stage, sizeof o->stage);
    for (int i = 0; i < w->n_frag; i++) {
        const cf_fragment *f = &w->frag[i];
        if (f->mode != CF_MODE_FRACTURE)
            continue;
        o->tets += f->nt, o->nodes += f->nodes.n, o->bars += f->bars.n, o->cohesive += f->coh.n;
        o->spell_time = fmax(o->spell_time, w->t - f->t_enter); /* pieces keep their parent's */
        if (f->bars.color_start) {
            o->colours = f->bars.n_colors > o->colours ? f->bars.n_colors : o->colours;
            o->serial_bars += f->bars.n - f->bars.color_start[CF_BARS_COLORS];
        }
    }
    o->iterations = set->constraints == CF_CONSTRAINTS_NONE ? 0 : set->iterations;
    o->check = set->criterion != CF_CRITERION_NONE;
    o->xpbd = set->constraints == CF_CONSTRAINTS_XPBD;
}

double cf_step_traffic(const cf_step_stats *st)
{
    double tet = 168 + (st->check ? 144 : 0);
    double node = 104 + 48.0 * st->iterations;
    double bar = (st->xpbd ? 40.0 : 16.0) * st->iterations;
    return tet * st->tets + node * st->nodes + bar * st->bars +
           2.0 * sizeof(cf_cohesive) * st->cohesive;
}
