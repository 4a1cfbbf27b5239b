/* The table of obstacle types and what every type shares: set-up,
 * dispatch, and the collision projection of the in-house solver. */
#include "obstacle.h"

#include "linalg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const cf_obstacle_kind *cf_obstacle_kind_of(cf_obstacle_type type)
{
    static const cf_obstacle_kind *const kinds[CF_OBSTACLE_TYPE_COUNT] = {
#define CF_OBSTACLE_ENTRY_(NAME, name) [CF_OBSTACLE_##NAME] = &cf_obstacle_##name,
        CF_OBSTACLE_TYPES(CF_OBSTACLE_ENTRY_)
#undef CF_OBSTACLE_ENTRY_
    };
    return (unsigned)type < sizeof kinds / sizeof kinds[0] ? kinds[type] : NULL;
}

void cf_obstacle_velocity(const cf_obstacle *o, double u[3])
{
    cf_obstacle_kind_of(o->type)->velocity(o, u);
}

double cf_obstacle_distance(const cf_obstacles *obs, int j, double t, const double p[3],
                            double normal[3])
{
    const cf_obstacle *o = &obs->o[j];
    if (o->type == CF_OBSTACLE_PLANE) /* the common case, without the table's call */
        return cf_plane_distance(o, p, normal);
    return cf_obstacle_kind_of(o->type)->distance(obs, j, t, p, normal);
}

cf_status cf_obstacles_create(cf_obstacles *obs, const cf_world_def *def, cfb_world *bullet,
                              int *body, cf_error *err)
{
    int n = def->n_obstacles;
    obs->n = n;
    obs->planes_only = 1;
    for (int j = 0; j < n; j++)
        obs->planes_only &= def->obstacles[j].type == CF_OBSTACLE_PLANE;
    if (n == 0)
        return CF_OK;
    obs->mesh = calloc((size_t)n, sizeof *obs->mesh);
    obs->range = calloc((size_t)n, sizeof *obs->range);
    if (!obs->mesh || !obs->range)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for obstacles");
    for (int j = 0; j < n; j++) {
        const cf_obstacle_kind *kind = cf_obstacle_kind_of(def->obstacles[j].type);
        body[j] = -1;
        if (kind->prepare) {
            cf_status st = kind->prepare(obs, j, &def->obstacles[j], bullet, &body[j], err);
            if (st != CF_OK)
                return st;
        } else if (bullet) {
            body[j] = kind->bullet_body(bullet, &def->obstacles[j]);
        }
        /* Bullet multiplies the two bodies' coefficients: material x obstacle factor. */
        if (bullet && body[j] < 0)
            return cf_error_set(err, CF_ERR_EXTERNAL, "Bullet refused obstacle %d: %s", j + 1,
                                cfb_last_error());
    }
    return CF_OK;
}

void cf_obstacles_free(cf_obstacles *obs)
{
    for (int j = 0; obs->mesh && j < obs->n; j++)
        cff_mesh_destroy(obs->mesh[j]);
    free(obs->mesh), free(obs->range);
    obs->mesh = NULL, obs->range = NULL;
}

void cf_obstacles_push_out(const cf_obstacles *obs, double t, double p[3])
{
    for (int j = 0; j < obs->n && !cf_obstacles_clear(obs, p); j++) {
        double n[3], d = cf_obstacle_distance(obs, j, t, p, n);
        if (d < 0)
            v3_axpy(-d, n, p);
    }
}

int cf_obstacles_project(const cf_obstacles *obs, double t0, const double x[3], double t,
                         double p[3], double normal[3])
{
    int hit = -1;
    for (int j = 0; j < obs->n; j++) {
        double nrm[3], nx[3];
        double dist = cf_obstacle_distance(obs, j, t, p, nrm);
        if (dist < 0) {
            double allowed = fmin(0.0, cf_obstacle_distance(obs, j, t0, x, nx));
            if (dist < allowed)
                v3_axpy(allowed - dist, nrm, p);
            memcpy(normal, nrm, sizeof nrm);
            hit = j;
        }
    }
    return hit;
}
