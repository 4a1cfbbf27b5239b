#include "pbd.h"

#include "linalg.h"

#include <stdlib.h>
#include <string.h>

static int cmp_pair(const void *a, const void *b)
{
    const int *x = a, *y = b;
    if (x[0] != y[0])
        return x[0] < y[0] ? -1 : 1;
    return (x[1] > y[1]) - (x[1] < y[1]);
}

int cf_bars_build(cf_bars *b, const cf_solid *s, const int *tets, int nt)
{
    static const int E[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    int *e = malloc((size_t)nt * 12 * sizeof(int));
    if (!e)
        return -1;
    for (int i = 0; i < nt; i++)
        for (int k = 0; k < 6; k++) {
            int a = s->tet[4 * tets[i] + E[k][0]], c = s->tet[4 * tets[i] + E[k][1]];
            e[12 * i + 2 * k] = a < c ? a : c;
            e[12 * i + 2 * k + 1] = a < c ? c : a;
        }
    qsort(e, (size_t)nt * 6, 2 * sizeof(int), cmp_pair);
    int n = 0;
    for (int i = 0; i < 6 * nt; i++)
        if (n == 0 || e[2 * i] != e[2 * (n - 1)] || e[2 * i + 1] != e[2 * (n - 1) + 1]) {
            e[2 * n] = e[2 * i], e[2 * n + 1] = e[2 * i + 1];
            n++;
        }
    double *rest = malloc((size_t)(n ? n : 1) * sizeof(double));
    if (!rest) {
        free(e);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        double d[3];
        v3_sub(&s->X[3 * e[2 * i]], &s->X[3 * e[2 * i + 1]], d);
        rest[i] = v3_norm(d);
    }
    cf_bars_free(b);
    b->n = n, b->ends = e, b->rest = rest;
    return 0;
}

void cf_bars_free(cf_bars *b)
{
    free(b->ends);
    free(b->rest);
    memset(b, 0, sizeof *b);
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

void cf_obstacle_velocity(const cf_obstacle *o, double u[3])
{
    for (int k = 0; k < 3; k++)
        u[k] = o->type == CF_OBSTACLE_PLANE ? 0.0 : o->velocity[k];
}

double cf_obstacle_distance(const cf_obstacle *o, double t, const double p[3], double normal[3])
{
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
    }
    return INFINITY;
}

int cf_obstacles_project(const cf_obstacles *obs, double t, double p[3], double normal[3])
{
    int hit = -1;
    for (int j = 0; j < obs->n; j++) {
        double nrm[3];
        double dist = cf_obstacle_distance(&obs->o[j], t, p, nrm);
        if (dist < 0) {
            v3_axpy(-dist, nrm, p);
            memcpy(normal, nrm, sizeof nrm);
            hit = j;
        }
    }
    return hit;
}
