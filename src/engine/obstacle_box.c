/* An axis-aligned box moving at constant velocity (kinematic): centre at
 * t = 0, half extents, velocity. */
#include "obstacle.h"

#include "def_check.h"

#include "linalg.h"

#include <math.h>

static double distance(const cf_obstacles *obs, int j, double t, const double p[3],
                       double normal[3])
{
    const cf_obstacle *o = &obs->o[j];
    /* Inside: distance to the nearest face; outside: to the surface. */
    double c[3], d[3], q[3], out2 = 0, inside = -INFINITY;
    int axis = 0;
    cf_obstacle_center(o, t, c);
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

static int bullet_body(cfb_world *w, const cf_obstacle *o)
{
    return cfb_add_box(w, o->center, o->half_extents, o->velocity, o->friction,
                       o->restitution);
}

static cf_status check(int j, const cf_obstacle *o, cf_error *err)
{
    char key[96];
    for (int k = 0; k < 3; k++)
        CHECK(cf_obstacle_key(key, sizeof key, j, "half_extents"), o->half_extents[k],
              CF_POSITIVE);
    return CF_OK;
}

const cf_obstacle_kind cf_obstacle_box = {
    distance, cf_obstacle_kinematic_velocity, bullet_body, NULL, check};
