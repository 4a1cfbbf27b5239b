#include "pbd.h"

#include "linalg.h"

#include <stdlib.h>
#include <string.h>

typedef struct {
    int a, b;       /* ascending node pair */
    double vol;     /* m^3, this tet's share */
} edge;

static int cmp_edge(const void *x, const void *y)
{
    const edge *e = x, *f = y;
    if (e->a != f->a)
        return e->a < f->a ? -1 : 1;
    return (e->b > f->b) - (e->b < f->b);
}

int cf_bars_build(cf_bars *b, const cf_solid *s, const int *tets, int nt)
{
    static const int E[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    edge *e = malloc((size_t)(nt ? nt : 1) * 6 * sizeof *e);
    if (!e)
        return -1;
    for (int i = 0; i < nt; i++)
        for (int k = 0; k < 6; k++) {
            int p = s->tet[4 * tets[i] + E[k][0]], q = s->tet[4 * tets[i] + E[k][1]];
            edge *x = &e[6 * i + k];
            x->a = p < q ? p : q, x->b = p < q ? q : p;
            x->vol = s->vol[tets[i]] / 6.0; /* tributary volume: a sixth per edge */
        }
    qsort(e, (size_t)nt * 6, sizeof *e, cmp_edge);
    int n = 0;
    for (int i = 0; i < 6 * nt; i++) {
        if (n > 0 && e[i].a == e[n - 1].a && e[i].b == e[n - 1].b)
            e[n - 1].vol += e[i].vol;
        else
            e[n++] = e[i];
    }
    size_t cap = (size_t)(n ? n : 1);
    int *ends = malloc(cap * 2 * sizeof(int));
    double *rest = malloc(cap * sizeof(double)), *compliance = malloc(cap * sizeof(double));
    double *lambda = calloc(cap, sizeof(double));
    if (!ends || !rest || !compliance || !lambda) {
        free(e), free(ends), free(rest), free(compliance), free(lambda);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        double d[3];
        ends[2 * i] = e[i].a, ends[2 * i + 1] = e[i].b;
        v3_sub(&s->X[3 * e[i].a], &s->X[3 * e[i].b], d);
        rest[i] = v3_norm(d);
        /* A bar of section V/L and length L: stiffness E V / L^2. */
        compliance[i] = rest[i] * rest[i] / (s->mat.E * e[i].vol);
    }
    free(e);
    cf_bars_free(b);
    b->n = n, b->ends = ends, b->rest = rest, b->compliance = compliance, b->lambda = lambda;
    return 0;
}

void cf_bars_free(cf_bars *b)
{
    free(b->ends);
    free(b->rest);
    free(b->compliance);
    free(b->lambda);
    memset(b, 0, sizeof *b);
}

double cf_pbd_effective_stiffness(double k, int iterations, int iteration_independent)
{
    if (!iteration_independent || iterations < 1)
        return k;
    return 1.0 - pow(1.0 - k, 1.0 / iterations);
}

void cf_bars_project(const cf_bars *b, cf_solid *s, double k)
{
    for (int i = 0; i < b->n; i++) {
        int i1 = b->ends[2 * i], i2 = b->ends[2 * i + 1];
        double *p1 = &s->p[3 * i1], *p2 = &s->p[3 * i2];
        double w1 = 1.0 / s->m[i1], w2 = 1.0 / s->m[i2];
        double d[3];
        v3_sub(p1, p2, d);
        double len = v3_norm(d);
        if (len == 0)
            continue;
        double c = k * (len - b->rest[i]) / ((w1 + w2) * len);
        v3_axpy(-w1 * c, d, p1);
        v3_axpy(w2 * c, d, p2);
    }
}

void cf_bars_project_xpbd(cf_bars *b, cf_solid *s, double dt, double scale)
{
    for (int i = 0; i < b->n; i++) {
        int i1 = b->ends[2 * i], i2 = b->ends[2 * i + 1];
        double *p1 = &s->p[3 * i1], *p2 = &s->p[3 * i2];
        double w1 = 1.0 / s->m[i1], w2 = 1.0 / s->m[i2];
        double d[3];
        v3_sub(p1, p2, d);
        double len = v3_norm(d);
        if (len == 0)
            continue;
        double at = scale * b->compliance[i] / (dt * dt);
        double dl = (-(len - b->rest[i]) - at * b->lambda[i]) / (w1 + w2 + at);
        b->lambda[i] += dl;
        v3_axpy(w1 * dl / len, d, p1);
        v3_axpy(-w2 * dl / len, d, p2);
    }
}

void cf_bars_reset_lambda(cf_bars *b)
{
    if (b->n > 0)
        memset(b->lambda, 0, (size_t)b->n * sizeof(double));
}

void cf_obstacle_velocity(const cf_obstacle *o, double u[3])
{
    for (int k = 0; k < 3; k++)
        u[k] = o->type == CF_OBSTACLE_PLANE ? 0.0 : o->velocity[k];
}

double cf_obstacle_distance(const cf_obstacles *obs, int j, double t, const double p[3],
                            double normal[3])
{
    const cf_obstacle *o = &obs->o[j];
    double c[3] = {o->center[0] + t * o->velocity[0], o->center[1] + t * o->velocity[1],
                   o->center[2] + t * o->velocity[2]};
    double d[3];
    switch (o->type) {
    case CF_OBSTACLE_PLANE:
        memcpy(normal, o->normal, 3 * sizeof(double));
        v3_sub(p, o->point, d);
        return v3_dot(d, o->normal);
    case CF_OBSTACLE_SPHERE: {
        v3_sub(p, c, d);
        double l = v3_norm(d);
        for (int k = 0; k < 3; k++)
            normal[k] = l > 0 ? d[k] / l : (k == 2);
        return l - o->radius;
    }
    case CF_OBSTACLE_BOX: {
        /* Inside: distance to the nearest face; outside: to the surface. */
        double q[3], out2 = 0, inside = -INFINITY;
        int axis = 0;
        v3_sub(p, c, d);
        for (int k = 0; k < 3; k++) {
            q[k] = fabs(d[k]) - o->half_extents[k];
            if (q[k] > 0)
                out2 += q[k] * q[k];
            if (q[k] > inside)
                inside = q[k], axis = k;
        }
        if (out2 > 0) {
            double l = sqrt(out2);
            for (int k = 0; k < 3; k++)
                normal[k] = (q[k] > 0 ? q[k] * (d[k] < 0 ? -1 : 1) : 0) / l;
            return l;
        }
        normal[0] = normal[1] = normal[2] = 0;
        normal[axis] = d[axis] < 0 ? -1 : 1;
        return inside;
    }
    case CF_OBSTACLE_MESH: {
        double q[3], dist;
        if (cff_mesh_closest(obs->mesh[j], p, obs->range[j], q, normal, &dist) == 1)
            return dist;
        return INFINITY;
    }
    }
    return INFINITY;
}

int cf_obstacles_project(const cf_obstacles *obs, double t, double p[3], double normal[3])
{
    int hit = -1;
    for (int j = 0; j < obs->n; j++) {
        double nrm[3];
        double dist = cf_obstacle_distance(obs, j, t, p, nrm);
        if (dist < 0) {
            v3_axpy(-dist, nrm, p);
            memcpy(normal, nrm, sizeof nrm);
            hit = j;
        }
    }
    return hit;
}
