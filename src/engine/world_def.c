/* World definitions: the defaults of every setting (those of the settings
 * schema, cohfrac/settings.h, and of the records a scene lists) and the
 * check cf_world_create runs on what a program or the scene loader filled
 * in. */
#include "cohfrac/settings.h"
#include "cohfrac/types.h"
#include "def_check.h"
#include "obstacle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cf_mesh_free(cf_mesh *m)
{
    if (!m)
        return;
    free(m->x);
    free(m->tets);
    for (int g = 0; g < m->n_groups && m->groups; g++)
        free(m->groups[g].nodes);
    free(m->groups);
    memset(m, 0, sizeof *m);
}

/* Every setting of the schema at its default (cohfrac/settings.h), the
 * defaults taken from another key after the rest. */
static cf_world_def schema_defaults(void)
{
    cf_world_def d;
    memset(&d, 0, sizeof d);
    int n;
    const cf_setting *e = cf_settings(&n);
    for (int i = 0; i < n; i++)
        cf_setting_set(&e[i], &d, e[i].def);
    for (int i = 0; i < n; i++) {
        const cf_setting *from = e[i].def_from ? cf_setting_find(e[i].table, e[i].def_from) : NULL;
        if (from)
            cf_setting_set(&e[i], &d, cf_setting_get(from, &d));
    }
    /* solver.crack_plane, when a scene gives one without these */
    d.solver.crack_plane_normal[2] = 1.0, d.solver.crack_plane_tolerance = 1e-6;
    return d;
}

cf_material cf_default_material(void) { return schema_defaults().material; }

cf_solver_settings cf_default_solver(void) { return schema_defaults().solver; }

cf_body_def cf_default_body(void)
{
    cf_body_def b;
    memset(&b, 0, sizeof b);
    b.scale = 1.0;
    b.orientation[0] = 1.0;
    return b;
}

cf_obstacle cf_default_obstacle(cf_obstacle_type type)
{
    cf_obstacle o;
    memset(&o, 0, sizeof o);
    o.type = type;
    o.normal[2] = 1.0;
    o.scale = 1.0;
    o.orientation[0] = 1.0;
    o.friction = o.restitution = 1.0;
    return o;
}

cf_world_def cf_default_world_def(void)
{
    cf_world_def d;
    memset(&d, 0, sizeof d);
    d.gravity[2] = -9.81;
    d.material = cf_default_material();
    d.solver = cf_default_solver();
    return d;
}

static cf_status check_mesh(int b, const cf_mesh *m, cf_error *err)
{
    if (!m)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'bodies[%d].tet_mesh' is not set: give the body a Tet4 mesh, or "
                            "let mesh preparation make it (cf_world_meshes_load)",
                            b + 1);
    if (m->n_nodes < 4 || m->n_tets < 1 || !m->x || !m->tets)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'bodies[%d].tet_mesh' is empty (%d nodes, %d tets)", b + 1, m->n_nodes,
                            m->n_tets);
    for (int i = 0; i < 4 * m->n_tets; i++)
        if (m->tets[i] < 0 || m->tets[i] >= m->n_nodes)
            return cf_error_set(err, CF_ERR_MESH_INDEX,
                                "bodies[%d].tet_mesh: tet %d uses node %d, outside [0, %d)", b + 1,
                                i / 4, m->tets[i], m->n_nodes);
    return CF_OK;
}

static cf_status check_obstacle(int j, const cf_obstacle *o, cf_error *err)
{
    const cf_obstacle_kind *kind = cf_obstacle_kind_of(o->type);
    if (!kind)
        return cf_error_set(err, CF_ERR_SCENE_VALUE, "'obstacles[%d].type' is not a known type",
                            j + 1);
    cf_status st = kind->check(j, o, err);
    if (st != CF_OK)
        return st;
    char key[96];
    CHECK(cf_obstacle_key(key, sizeof key, j, "friction"), o->friction, CF_NON_NEGATIVE);
    CHECK(cf_obstacle_key(key, sizeof key, j, "restitution"), o->restitution, CF_NON_NEGATIVE);
    return CF_OK;
}

/* Each number and integer of the schema in its interval, each choice one
 * of its spellings. */
static cf_status check_schema(const cf_world_def *d, cf_error *err)
{
    int n;
    const cf_setting *e = cf_settings(&n);
    for (int i = 0; i < n; i++) {
        char key[96];
        snprintf(key, sizeof key, "%s.%s", e[i].table, e[i].key);
        double v = cf_setting_get(&e[i], d);
        if (e[i].kind == CF_SET_NUM || e[i].kind == CF_SET_INT) {
            cf_interval r = {e[i].lo, e[i].hi, e[i].lo_closed, e[i].hi_closed};
            CHECK(key, v, r);
        } else if (e[i].kind == CF_SET_ENUM) {
            int k = 0;
            while (e[i].names[k])
                k++;
            if (v < 0 || v >= k)
                return cf_error_set(err, CF_ERR_SCENE_VALUE, "'%s' is not a known choice (%g)",
                                    key, v);
        }
    }
    return CF_OK;
}

cf_status cf_world_def_check(const cf_world_def *d, cf_error *err)
{
    const cf_solver_settings *s = &d->solver;
    cf_status st = check_schema(d, err);
    if (st == CF_OK)
        st = cf_solver_check_rules(s, err);
    if (st != CF_OK)
        return st;
    if (s->has_crack_plane) {
        st = cf_check_unit("solver.crack_plane.normal", s->crack_plane_normal, 3, err);
        if (st != CF_OK)
            return st;
        CHECK("solver.crack_plane.tolerance", s->crack_plane_tolerance, CF_POSITIVE);
    }
    if (d->n_bodies < 1 || !d->bodies)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'bodies' is empty; a scene needs at least one body");
    for (int b = 0; b < d->n_bodies; b++) {
        char key[64];
        snprintf(key, sizeof key, "bodies[%d].scale", b + 1);
        CHECK(key, d->bodies[b].scale, CF_POSITIVE);
        snprintf(key, sizeof key, "bodies[%d].orientation", b + 1);
        cf_status st = cf_check_unit(key, d->bodies[b].orientation, 4, err);
        if (st == CF_OK)
            st = check_mesh(b, d->bodies[b].tet_mesh, err);
        if (st != CF_OK)
            return st;
    }
    for (int j = 0; j < d->n_obstacles; j++) {
        cf_status st = check_obstacle(j, &d->obstacles[j], err);
        if (st != CF_OK)
            return st;
    }
    if (d->n_boundaries > 0 && s->mode != CF_RUN_FRACTURE)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'boundary' has %d entries but solver.mode is not \"fracture\": "
                            "boundary conditions need solver.mode = \"fracture\"",
                            d->n_boundaries);
    for (int c = 0; c < d->n_boundaries; c++)
        if (d->boundaries[c].body >= d->n_bodies)
            return cf_error_set(err, CF_ERR_SCENE_VALUE,
                                "'boundary[%d].body' must be in [1, %d], got %d", c + 1,
                                d->n_bodies, d->boundaries[c].body + 1);
    return CF_OK;
}
