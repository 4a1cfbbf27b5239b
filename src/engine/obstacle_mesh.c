/* A static triangle surface, closed or open: scaled, rotated and moved into
 * the world, queried through FCL; a node counts as inside only within 5%
 * of the surface's size behind it (deeper nodes have gone through). */
#include "obstacle.h"

#include "def_check.h"

#include "linalg.h"

#include <math.h>
#include <stdlib.h>

static double distance(const cf_obstacles *obs, int j, double t, const double p[3],
                       double normal[3])
{
    (void)t;
    double q[3], dist;
    if (cff_mesh_closest(obs->mesh[j], p, obs->range[j], q, normal, &dist) == 1)
        return dist;
    return INFINITY;
}

/* The surface placed in the world: x' = position + scale R x, [n][3]. */
static double *place(const cf_obstacle *o)
{
    double R[9], *v = malloc(((size_t)o->n_vertices * 3 + 1) * sizeof(double));
    if (!v)
        return NULL;
    quat_to_mat(o->orientation, R);
    for (int i = 0; i < o->n_vertices; i++) {
        double y[3];
        m3_mulv(R, &o->vertices[3 * i], y);
        for (int k = 0; k < 3; k++)
            v[3 * i + k] = o->position[k] + o->scale * y[k];
    }
    return v;
}

static cf_status prepare(cf_obstacles *obs, int j, const cf_obstacle *o, cfb_world *bullet,
                        int *body, cf_error *err)
{
    double *v = place(o), lo[3], hi[3], diag[3];
    if (!v)
        return cf_error_set(err, CF_ERR_NOMEM, "out of memory for obstacle %d", j + 1);
    points_bbox(v, o->n_vertices, lo, hi);
    v3_sub(hi, lo, diag);
    obs->range[j] = 0.05 * v3_norm(diag);
    obs->mesh[j] = cff_mesh_create(v, o->n_vertices, o->triangles, o->n_triangles);
    if (obs->mesh[j] && bullet)
        *body = cfb_add_trimesh(bullet, v, o->n_vertices, o->triangles, o->n_triangles,
                                o->friction, o->restitution);
    free(v);
    if (!obs->mesh[j])
        return cf_error_set(err, CF_ERR_EXTERNAL, "FCL refused obstacle %d (%s): %s", j + 1,
                            o->file, cff_last_error());
    return CF_OK;
}

/* Besides the placement, the surface must be there and index its own
 * vertices: the set-up hands it to FCL and Bullet as it is. */
static cf_status check(int j, const cf_obstacle *o, cf_error *err)
{
    char key[96];
    CHECK(cf_obstacle_key(key, sizeof key, j, "scale"), o->scale, CF_POSITIVE);
    cf_status st = cf_check_unit(cf_obstacle_key(key, sizeof key, j, "orientation"),
                                 o->orientation, 4, err);
    if (st == CF_OK && (!o->vertices || !o->triangles || o->n_triangles < 1))
        st = cf_error_set(err, CF_ERR_SCENE_VALUE,
                          "'obstacles[%d]' (mesh %s) has no triangle: give vertices and "
                          "triangles, or let mesh preparation read `file` "
                          "(cf_world_meshes_load)",
                          j + 1, o->file[0] ? o->file : "without a file");
    for (int i = 0; st == CF_OK && i < 3 * o->n_triangles; i++)
        if (o->triangles[i] < 0 || o->triangles[i] >= o->n_vertices)
            st = cf_error_set(err, CF_ERR_SCENE_VALUE,
                              "obstacles[%d]: triangle %d uses vertex %d, outside [0, %d)",
                              j + 1, i / 3, o->triangles[i], o->n_vertices);
    return st;
}

const cf_obstacle_kind cf_obstacle_mesh = {
    distance, cf_obstacle_static_velocity, NULL, prepare, check};
