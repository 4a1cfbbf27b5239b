/* The meshes a world definition names: bodies' Tet4 meshes (files,
 * prepared meshes, primitives, hollowed shells) and mesh obstacles'
 * surfaces, made by mesh preparation for the engine. */
#include "cohfrac/mesh.h"
#include "cohfrac/surface.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *cf_default_mesh_dir(void)
{
    static char dir[4096];
    const char *env = getenv("COHFRAC_MESH_DIR");
    if (env && *env)
        return env;
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    if (xdg && xdg[0] == '/') /* the spec ignores a relative XDG_CACHE_HOME */
        snprintf(dir, sizeof dir, "%s/cohfrac/meshes", xdg);
    else if (home && home[0] == '/')
        snprintf(dir, sizeof dir, "%s/.cache/cohfrac/meshes", home);
    else
        snprintf(dir, sizeof dir, "/tmp/cohfrac-meshes");
    return dir;
}

static cf_status body_mesh(const cf_body_source *bd, int b, const char *mesh_dir, cf_mesh *m,
                           cf_error *err)
{
    cf_status st = bd->primitive.type != CF_PRIM_NONE
                       ? cf_mesh_primitive(&bd->primitive, mesh_dir, m, err)
                       : cf_mesh_load(bd->mesh, m, err);
    /* bodies[i].hollow_layers: keep a shell of tets along the surface. */
    if (st == CF_OK && bd->hollow_layers > 0) {
        st = cf_mesh_hollow(m, bd->hollow_layers, err);
        if (st != CF_OK) {
            if (err) {
                char why[sizeof err->msg];
                memcpy(why, err->msg, sizeof why);
                cf_error_set(err, st, "bodies[%d].hollow_layers = %d on %s: %s", b + 1,
                             bd->hollow_layers, bd->mesh[0] ? bd->mesh : "the body's primitive mesh",
                             why);
            }
            cf_mesh_free(m);
        }
    }
    return st;
}

cf_status cf_world_meshes_load(cf_world_def *def, const cf_body_source *src, const char *mesh_dir,
                               cf_world_meshes *out, cf_error *err)
{
    memset(out, 0, sizeof *out);
    if (!mesh_dir)
        mesh_dir = cf_default_mesh_dir();
    out->bodies = calloc((size_t)def->n_bodies + 1, sizeof *out->bodies);
    out->obstacles = calloc((size_t)def->n_obstacles + 1, sizeof *out->obstacles);
    out->n_bodies = def->n_bodies, out->n_obstacles = def->n_obstacles;
    cf_status st = out->bodies && out->obstacles
                       ? CF_OK
                       : cf_error_set(err, CF_ERR_NOMEM, "out of memory for the scene's meshes");
    for (int b = 0; src && b < def->n_bodies && st == CF_OK; b++)
        if (!def->bodies[b].tet_mesh)
            st = body_mesh(&src[b], b, mesh_dir, &out->bodies[b], err);
    for (int j = 0; j < def->n_obstacles && st == CF_OK; j++) {
        const cf_obstacle *o = &def->obstacles[j];
        if (o->type != CF_OBSTACLE_MESH || o->vertices)
            continue;
        st = cf_surface_load(o->file, &out->obstacles[j], err);
        if (st == CF_OK && out->obstacles[j].n_tris == 0)
            st = cf_error_set(err, CF_ERR_SCENE_VALUE, "obstacles[%d].file %s has no triangle",
                              j + 1, o->file);
    }
    if (st != CF_OK) {
        cf_world_meshes_free(out);
        return st;
    }
    for (int b = 0; src && b < def->n_bodies; b++)
        if (!def->bodies[b].tet_mesh)
            def->bodies[b].tet_mesh = &out->bodies[b];
    for (int j = 0; j < def->n_obstacles; j++) {
        cf_obstacle *o = &def->obstacles[j];
        if (o->type != CF_OBSTACLE_MESH || o->vertices)
            continue;
        o->vertices = out->obstacles[j].v, o->n_vertices = out->obstacles[j].n_verts;
        o->triangles = out->obstacles[j].tri, o->n_triangles = out->obstacles[j].n_tris;
    }
    return CF_OK;
}

void cf_world_meshes_free(cf_world_meshes *m)
{
    if (!m)
        return;
    for (int b = 0; m->bodies && b < m->n_bodies; b++)
        cf_mesh_free(&m->bodies[b]);
    for (int j = 0; m->obstacles && j < m->n_obstacles; j++)
        cf_surface_free(&m->obstacles[j]);
    free(m->bodies), free(m->obstacles);
    memset(m, 0, sizeof *m);
}
