/* Obstacles: static or kinematic (constant velocity) shapes that fragments
 * hit, in both modes.  Each type lives in one file, obstacle_<type>.c,
 * behind one interface (cf_obstacle_kind): its signed distance and normal
 * for the in-house solver's collision constraint, its velocity, its Bullet
 * body in rigid mode, and any set-up its queries need.  obstacles.c
 * holds the table of types and what is common to all. */
#ifndef COHFRAC_OBSTACLE_H
#define COHFRAC_OBSTACLE_H

#include "cf_bullet.h"
#include "cf_fcl.h"
#include "cohfrac/types.h"

/* The world's obstacles at time t: their definitions and, per obstacle,
 * what its queries need (mesh obstacles: the FCL mesh, and the depth range
 * m behind the surface within which a node counts as inside; NULL and 0 for
 * the analytic ones). */
typedef struct cf_obstacles {
    int n;
    const cf_obstacle *o;
    cff_mesh **mesh;
    double *range;
    int planes_only; /* every obstacle a static plane (or none) */
} cf_obstacles;

typedef struct cf_obstacle_kind {
    /* Signed distance of point p from obstacle j at time t, m (negative
     * inside), and the outward unit normal there. */
    double (*distance)(const cf_obstacles *obs, int j, double t, const double p[3],
                       double normal[3]);
    /* The obstacle's (constant) velocity, m/s. */
    void (*velocity)(const cf_obstacle *o, double u[3]);
    /* Its Bullet body in rigid mode (a static or kinematic collision
     * object): returns the Bullet id, or -1 (cfb_last_error says why). */
    int (*bullet_body)(cfb_world *bullet, const cf_obstacle *o);
    /* Optional (NULL for analytic shapes): set up obstacle j from its
     * definition `def` (surfaces included), its query structures in obs
     * and, with a Bullet world, its body (*body), for shapes whose Bullet
     * body needs what the set-up makes.  Errors: CF_ERR_EXTERNAL (FCL),
     * CF_ERR_NOMEM. */
    cf_status (*prepare)(cf_obstacles *obs, int j, const cf_obstacle *def, cfb_world *bullet,
                         int *body, cf_error *err);
    /* Check the type's own parameters of obstacle j (cf_world_def_check;
     * friction and restitution are checked for every type).  Errors:
     * CF_ERR_SCENE_VALUE naming the key (def_check.h). */
    cf_status (*check)(int j, const cf_obstacle *o, cf_error *err);
} cf_obstacle_kind;

/* One kind per line of CF_OBSTACLE_TYPES (cohfrac/types.h). */
#define CF_OBSTACLE_KIND_(NAME, name) extern const cf_obstacle_kind cf_obstacle_##name;
CF_OBSTACLE_TYPES(CF_OBSTACLE_KIND_)
#undef CF_OBSTACLE_KIND_

/* The kind of obstacle type `type` (the table in obstacles.c), NULL for
 * a value outside cf_obstacle_type. */
const cf_obstacle_kind *cf_obstacle_kind_of(cf_obstacle_type type);

/* Set up every obstacle of `def` (obs->o must point at the world's copy of
 * def->obstacles); body[j] gets obstacle j's Bullet id (-1 when none). */
cf_status cf_obstacles_create(cf_obstacles *obs, const cf_world_def *def, cfb_world *bullet,
                              int *body, cf_error *err);
void cf_obstacles_free(cf_obstacles *obs);

/* Signed distance of point p from the static plane o (m, negative behind
 * it) and its outward normal: obstacle_plane.c's distance, here inline
 * because the projection asks it for every node at every iteration
 * (cf_obstacle_distance takes it without the table's call). */
static inline double cf_plane_distance(const cf_obstacle *o, const double p[3],
                                       double normal[3])
{
    for (int k = 0; k < 3; k++)
        normal[k] = o->normal[k];
    return (p[0] - o->point[0]) * o->normal[0] + (p[1] - o->point[1]) * o->normal[1] +
           (p[2] - o->point[2]) * o->normal[2];
}

/* Keep a node's prediction p (at time t) out of every obstacle, moving it
 * along the obstacle's normal: to the surface, or, when the node was already
 * inside at x (at time t0, the step's start), no deeper than it was then.
 * An overlap present at the start of the step is thus never pushed out on p
 * alone, which would turn depth/dt into velocity (energy no load put in);
 * only the obstacle's own motion over the step moves p.  Returns the index
 * of the last obstacle that was hit, or -1; `normal` receives its outward
 * normal. */
int cf_obstacles_project(const cf_obstacles *obs, double t0, const double x[3], double t,
                         double p[3], double normal[3]);

/* Move point p (at time t) onto the surface of each obstacle it lies
 * inside, in obstacle order, along that obstacle's normal: a node put
 * back on the surface where nothing may push it out over a step (a
 * crushed tet's, a wedged piece's at its hand-off). */
void cf_obstacles_push_out(const cf_obstacles *obs, double t, double p[3]);

/* Whether p lies on or outside every obstacle when all are static planes
 * (planes_only), which cf_obstacles_project would then leave alone: its test
 * inline, for the nodes far from the ground (most of them), without its
 * calls.  0 when some obstacle is another kind or p is behind a plane. */
static inline int cf_obstacles_clear(const cf_obstacles *obs, const double p[3])
{
    if (!obs->planes_only)
        return 0;
    for (int j = 0; j < obs->n; j++) {
        double normal[3];
        if (cf_plane_distance(&obs->o[j], p, normal) < 0)
            return 0;
    }
    return 1;
}

/* Velocity of obstacle o, m/s. */
void cf_obstacle_velocity(const cf_obstacle *o, double u[3]);

/* Signed distance of point p from obstacle j at time t (negative inside) and
 * the outward normal there. */
double cf_obstacle_distance(const cf_obstacles *obs, int j, double t, const double p[3],
                            double normal[3]);

/* The two velocities there are: none (planes, meshes) and the constant
 * `velocity` of a kinematic obstacle (spheres, boxes).  Inline, with the
 * centre below, so that the types depend on the table and never the other
 * way round. */
static inline void cf_obstacle_static_velocity(const cf_obstacle *o, double u[3])
{
    (void)o;
    u[0] = u[1] = u[2] = 0.0;
}

static inline void cf_obstacle_kinematic_velocity(const cf_obstacle *o, double u[3])
{
    for (int k = 0; k < 3; k++)
        u[k] = o->velocity[k];
}

/* Where a kinematic obstacle's centre is at time t: center + t velocity. */
static inline void cf_obstacle_center(const cf_obstacle *o, double t, double c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = o->center[k] + t * o->velocity[k];
}

#endif
