/* A sphere moving at constant velocity (kinematic): centre at t = 0,
 * radius, velocity. */
#include "obstacle.h"

#include "def_check.h"

#include "linalg.h"

static double distance(const cf_obstacles *obs, int j, double t, const double p[3],
                       double normal[3])
{
    const cf_obstacle *o = &obs->o[j];
    double c[3], d[3];
    cf_obstacle_center(o, t, c);
    v3_sub(p, c, d);
    double l = v3_norm(d);
    for (int k = 0; k < 3; k++)
        normal[k] = l > 0 ? d[k] / l : (k == 2);
    return l - o->radius;
}

static int bullet_body(cfb_world *w, const cf_obstacle *o)
{
    return cfb_add_sphere(w, o->center, o->radius, o->velocity, o->friction, o->restitution);
}

static cf_status check(int j, const cf_obstacle *o, cf_error *err)
{
    char key[96];
    CHECK(cf_obstacle_key(key, sizeof key, j, "radius"), o->radius, CF_POSITIVE);
    return CF_OK;
}

const cf_obstacle_kind cf_obstacle_sphere = {
    distance, cf_obstacle_kinematic_velocity, bullet_body, NULL, check};
