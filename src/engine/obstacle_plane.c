/* A static plane: point and outward normal. */
#include "obstacle.h"

static double distance(const cf_obstacles *obs, int j, double t, const double p[3],
                       double normal[3])
{
    (void)t;
    return cf_plane_distance(&obs->o[j], p, normal);
}

static int bullet_body(cfb_world *w, const cf_obstacle *o)
{
    return cfb_add_plane(w, o->point, o->normal, o->friction, o->restitution);
}

const cf_obstacle_kind cf_obstacle_plane = {
    distance, cf_obstacle_static_velocity, bullet_body, NULL};
