/* A static plane: point and outward normal. */
#include "obstacle.h"

#include "def_check.h"

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

static cf_status check(int j, const cf_obstacle *o, cf_error *err)
{
    char key[96];
    return cf_check_unit(cf_obstacle_key(key, sizeof key, j, "normal"), o->normal, 3, err);
}

const cf_obstacle_kind cf_obstacle_plane = {
    distance, cf_obstacle_static_velocity, bullet_body, NULL, check};
