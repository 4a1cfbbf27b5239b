/* The in-house solver step (source Table 6.2, DESIGN §3), per fragment. */
#include "sim.h"

#include "linalg.h"
#include "tet4.h"

#include <stdlib.h>
#include <time.h>

double cf_wall_time(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int ensure_scratch(cf_fragment *f)
{
    if (f->scratch_cap >= f->nodes.n)
        return 0;
    int cap = f->nodes.n + f->nodes.n / 2 + 16;
    int *c = realloc(f->contact, (size_t)cap * sizeof(int));
    if (!c)
        return -1;
    f->contact = c;
    double *v = realloc(f->vn_pre, (size_t)cap * sizeof(double));
    if (!v)
        return -1;
    f->vn_pre = v;
    f->scratch_cap = cap;
    return 0;
}

/* Stresses, then extrinsic insertion on every facet that qualifies. */
static cf_status check_and_insert(cf_sim *sim, cf_fragment *f, int *inserted)
{
    cf_solid *s = &sim->solid;
    int *cand = malloc((size_t)f->nt * 4 * sizeof(int));
    if (!cand)
        return CF_ERR_NOMEM;
    double t0 = cf_wall_time();
    int nc = cf_insertion_candidates(s, f->tets, f->nt, sim->scene->solver.criterion, cand);
    if (nc < 0) {
        free(cand);
        return CF_ERR_NOMEM;
    }
    for (int i = 0; i < nc; i++) {
        if (cf_crack_facet(s, cand[i], &f->nodes) || cf_int_list_push(&f->coh, s->n_coh - 1)) {
            free(cand);
            return CF_ERR_NOMEM;
        }
    }
    free(cand);
    if (nc > 0 && cf_bars_build(&f->bars, s, f->tets, f->nt))
        return CF_ERR_NOMEM;
    *inserted = nc;
    sim->prof.insertion += cf_wall_time() - t0;
    return CF_OK;
}


/* Friction and restitution of nodes in contact, relative to the obstacle. */
static void contact_velocities(cf_sim *sim, cf_fragment *f, double t)
{
    cf_solid *s = &sim->solid;
    double mu = s->mat.friction, e = s->mat.restitution;
    for (int i = 0; i < f->nodes.n; i++) {
        int j = f->contact[i];
        if (j < 0)
            continue;
        int a = f->nodes.v[i];
        double n[3], u[3], vr[3];
        cf_obstacle_distance(&sim->obs.o[j], t, &s->x[3 * a], n);
        cf_obstacle_velocity(&sim->obs.o[j], u);
        v3_sub(&s->v[3 * a], u, vr);
        double vn = v3_dot(vr, n), vt[3];
        for (int k = 0; k < 3; k++)
            vt[k] = vr[k] - vn * n[k];
        double vn_new = vn;
        if (f->vn_pre[i] < 0 && vn < -e * f->vn_pre[i])
            vn_new = -e * f->vn_pre[i];
        /* Coulomb: the tangential change is bounded by mu times the normal one. */
        double dvn = fabs(vn_new - (f->vn_pre[i] < 0 ? f->vn_pre[i] : 0));
        double vtl = v3_norm(vt);
        double scale = vtl > 0 ? fmax(0.0, 1.0 - mu * dvn / vtl) : 0;
        for (int k = 0; k < 3; k++)
            s->v[3 * a + k] = u[k] + vn_new * n[k] + scale * vt[k];
    }
}

cf_status cf_solver_step(cf_sim *sim, int fi, double t, double dt, int fracture)
{
    cf_fragment *f = &sim->frag[fi];
    cf_solid *s = &sim->solid;
    const cf_solver_settings *set = &sim->scene->solver;
    const double *g = sim->scene->gravity;
    double t0 = cf_wall_time();

    /* Stresses and internal forces (fracture mode only). */
    if (fracture) {
        int check = (f->steps % set->check_interval) == 0;
        cf_tet4_forces(s, f->tets, f->nt, set->elasticity, check);
        double t1 = cf_wall_time();
        sim->prof.stress += t1 - t0;
        int inserted = 0;
        if (check) {
            cf_status st = check_and_insert(sim, f, &inserted);
            if (st != CF_OK)
                return st;
        }
        f->quiet = inserted ? 0 : f->quiet + 1;
        t0 = cf_wall_time();
    }
    if (ensure_scratch(f))
        return CF_ERR_NOMEM;

    /* f = f_ext - f_int + f_coh ; v <- v + dt M^-1 f */
    const int *nodes = f->nodes.v;
    int nn = f->nodes.n;
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        for (int k = 0; k < 3; k++)
            s->f[3 * a + k] = s->m[a] * g[k];
    }
    if (fracture) {
        cf_tet4_scatter(s, f->tets, f->nt);
        cf_cohesive_forces(s, &sim->ppr, f->coh.v, f->coh.n);
    }
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        v3_axpy(dt / s->m[a], &s->f[3 * a], &s->v[3 * a]);
    }
    if (!fracture)
        cf_global_damping(s, nodes, nn, set->k_damping);
    double t1 = cf_wall_time();
    sim->prof.forces += t1 - t0;

    /* Prediction, then PBD bars, crack and obstacle collision constraints. */
    double t_next = t + dt;
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        for (int k = 0; k < 3; k++)
            s->p[3 * a + k] = s->x[3 * a + k] + dt * s->v[3 * a + k];
        f->contact[i] = -1;
        f->vn_pre[i] = 0;
    }
    for (int it = 0; it < set->iterations; it++) {
        cf_bars_project(&f->bars, s, set->k_stiffness);
        if (fracture)
            cf_cohesive_project_contact(s, f->coh.v, f->coh.n);
        for (int i = 0; i < nn; i++) {
            int a = nodes[i];
            double n[3];
            int hit = cf_obstacles_project(&sim->obs, t_next, &s->p[3 * a], n);
            if (hit >= 0 && f->contact[i] < 0) {
                double u[3], vr[3];
                cf_obstacle_velocity(&sim->obs.o[hit], u);
                v3_sub(&s->v[3 * a], u, vr);
                f->vn_pre[i] = v3_dot(vr, n);
            }
            if (hit >= 0)
                f->contact[i] = hit;
        }
    }
    /* v <- (p - x)/dt ; x <- p */
    for (int i = 0; i < nn; i++) {
        int a = nodes[i];
        for (int k = 0; k < 3; k++) {
            s->v[3 * a + k] = (s->p[3 * a + k] - s->x[3 * a + k]) / dt;
            s->x[3 * a + k] = s->p[3 * a + k];
        }
    }
    contact_velocities(sim, f, t_next);
    sim->prof.pbd += cf_wall_time() - t1;
    f->steps++;
    return CF_OK;
}

int cf_pbd_impact(const cf_sim *sim, int fi, double dt)
{
    const cf_fragment *f = &sim->frag[fi];
    const cf_solid *s = &sim->solid;
    const double *g = sim->scene->gravity;
    for (int i = 0; i < f->nodes.n; i++) {
        int a = f->nodes.v[i];
        double v[3], p[3];
        for (int k = 0; k < 3; k++) {
            v[k] = s->v[3 * a + k] + dt * g[k];
            p[k] = s->x[3 * a + k] + dt * v[k];
        }
        for (int j = 0; j < sim->obs.n; j++) {
            double n[3];
            if (cf_obstacle_distance(&sim->obs.o[j], sim->t + dt, p, n) >= 0)
                continue;
            double u[3], vr[3];
            cf_obstacle_velocity(&sim->obs.o[j], u);
            v3_sub(v, u, vr);
            if (-v3_dot(vr, n) > sim->scene->solver.impact_threshold)
                return 1;
        }
    }
    return 0;
}
