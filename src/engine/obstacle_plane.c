/* A static plane: point and outward normal. */
#include "obstacle.h"

#include "linalg.h"

#include <string.h>

static double distance(const cf_obstacles *obs, int j, double t, const double p[3],
                       double normal[3])
{
    (void)t;
    const cf_obstacle *o = &obs->o[j];
    double d[3];
    memcpy(normal, o->normal, 3 * sizeof(double));
    v3_sub(p, o->point, d);
    return v3_dot(d, o->normal);
}

static int bullet_body(cfb_world *w, const cf_obstacle *o)
{
    return cfb_add_plane(w, o->point, o->normal, o->friction, o->restitution);
}

const cf_obstacle_kind cf_obstacle_plane = {
    distance, cf_obstacle_static_velocity, bullet_body, NULL};
