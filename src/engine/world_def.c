/* World definitions: the defaults of every setting (the scene schema's,
 * cohfrac/scene.h) and the check cf_world_create runs on what a program or
 * the scene loader filled in. */
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

cf_material cf_default_material(void)
{
    cf_material m;
    memset(&m, 0, sizeof m);
    m.E = 1e6, m.nu = 0.3, m.rho = 2400.0;
    m.G_I = m.G_II = 22.0;
    m.sigma_max = m.tau_max = 1e4;
    m.alpha = m.beta = 2.0;
    m.friction = 0.5, m.restitution = 0.0;
    m.weibull = 0, m.weibull_modulus = 10.0, m.strength_seed = 1;
    return m;
}

cf_solver_settings cf_default_solver(void)
{
    cf_solver_settings s;
    memset(&s, 0, sizeof s);
    s.mode = CF_RUN_HYBRID;
    s.rigid_backend = CF_RIGID_BULLET;
    s.dt_rigid = 1e-3, s.rigid_substeps = 5;
    s.dt_fracture = 5e-6, s.cfl_fraction = 0.0;
    s.check_interval = 1, s.quiet_steps = 400;
    s.max_fracture_time = 0.05, s.impact_threshold = 0.2;
    s.ccd = 1;
    s.elasticity = CF_ELASTICITY_COROTATIONAL;
    s.criterion = CF_CRITERION_TRACTION;
    s.crack_growth = CF_GROWTH_FRONTS, s.min_piece_tets = 4, s.debris_tets = 4;
    s.obstacle_contact = CF_OBSTACLE_CONTACT_KINEMATIC;
    s.crack_plane_normal[2] = 1.0, s.crack_plane_tolerance = 1e-6;
    s.constraints = CF_CONSTRAINTS_PBD;
    s.k_stiffness = 0.9, s.iterations = 3, s.k_damping = 1.0;
    s.compliance_scale = 1.0;
    s.max_inverted_fraction = 0.01, s.max_energy_growth = 0.5;
    return s;
}

cf_output_settings cf_default_output(void)
{
    cf_output_settings o;
    memset(&o, 0, sizeof o);
    o.frame_interval = 0.01;
    o.fields = 1;
    return o;
}

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
    snprintf(d.name, sizeof d.name, "scene");
    d.duration = 1.0;
    d.gravity[2] = -9.81;
    d.material = cf_default_material();
    d.solver = cf_default_solver();
    d.output = cf_default_output();
    return d;
}

/* The allowed intervals of settings beyond def_check.h's. */
static const cf_interval FRICTION_ANGLE = {0.0, 60.0, 1, 1}; /* degrees */
static const cf_interval AT_LEAST_ONE = {1.0, INFINITY, 1, 0};
static const cf_interval UNIT = {0.0, 1.0, 1, 1};
static const cf_interval POISSON = {-1.0, 0.5, 0, 0};
static const cf_interval PPR_SHAPE = {1.0, INFINITY, 0, 0};
static const cf_interval ITERATIONS = {1.0, CF_MAX_ITERATIONS, 1, 1};
static const cf_interval PIECE_TETS = {0.0, CF_MAX_PIECE_TETS, 1, 1};

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

cf_status cf_world_def_check(const cf_world_def *d, cf_error *err)
{
    const cf_material *m = &d->material;
    const cf_solver_settings *s = &d->solver;
    CHECK("duration", d->duration, CF_POSITIVE);
    CHECK("material.E", m->E, CF_POSITIVE);
    CHECK("material.nu", m->nu, POISSON);
    CHECK("material.rho", m->rho, CF_POSITIVE);
    CHECK("material.G_I", m->G_I, CF_POSITIVE);
    CHECK("material.G_II", m->G_II, CF_POSITIVE);
    CHECK("material.sigma_max", m->sigma_max, CF_POSITIVE);
    CHECK("material.tau_max", m->tau_max, CF_POSITIVE);
    CHECK("material.alpha", m->alpha, PPR_SHAPE);
    CHECK("material.beta", m->beta, PPR_SHAPE);
    CHECK("material.friction", m->friction, CF_NON_NEGATIVE);
    CHECK("material.restitution", m->restitution, UNIT);
    CHECK("material.strength.modulus", m->weibull_modulus, CF_POSITIVE);
    CHECK("material.strength.area", m->strength_area, CF_NON_NEGATIVE);
    CHECK("material.nucleation_radius", m->nucleation_radius, CF_NON_NEGATIVE);
    CHECK("material.internal_friction_angle", m->internal_friction_angle, FRICTION_ANGLE);
    CHECK("solver.dt_rigid", s->dt_rigid, CF_POSITIVE);
    CHECK("solver.rigid_substeps", s->rigid_substeps, ITERATIONS);
    CHECK("solver.dt_fracture", s->dt_fracture, CF_POSITIVE);
    if (s->dt_rigid > d->duration)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'solver.dt_rigid' (%g s) exceeds 'duration' (%g s): the run is "
                            "whole rigid steps; lower solver.dt_rigid to at most the duration",
                            s->dt_rigid, d->duration);
    if (s->dt_rigid / s->dt_fracture > CF_MAX_SUBSTEPS)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'solver.dt_rigid' / 'solver.dt_fracture' = %.3g fracture steps in one "
                            "rigid step, above the limit %d: lower solver.dt_rigid or raise "
                            "solver.dt_fracture",
                            s->dt_rigid / s->dt_fracture, CF_MAX_SUBSTEPS);
    if (s->dt_fracture > s->dt_rigid)
        return cf_error_set(err, CF_ERR_SCENE_VALUE,
                            "'solver.dt_fracture' must not exceed solver.dt_rigid (%g), got %g",
                            s->dt_rigid, s->dt_fracture);
    CHECK("solver.cfl_fraction", s->cfl_fraction, CF_NON_NEGATIVE);
    CHECK("solver.check_interval", s->check_interval, AT_LEAST_ONE);
    CHECK("solver.quiet_steps", s->quiet_steps, AT_LEAST_ONE);
    CHECK("solver.min_piece_tets", s->min_piece_tets, PIECE_TETS);
    CHECK("solver.min_piece_size", s->min_piece_size, CF_NON_NEGATIVE);
    CHECK("solver.debris_tets", s->debris_tets, PIECE_TETS);
    CHECK("solver.debris_size", s->debris_size, CF_NON_NEGATIVE);
    CHECK("solver.max_fracture_time", s->max_fracture_time, CF_POSITIVE);
    CHECK("solver.impact_threshold", s->impact_threshold, CF_NON_NEGATIVE);
    CHECK("solver.sleeping.linear", s->sleep_linear, CF_NON_NEGATIVE);
    CHECK("solver.sleeping.angular", s->sleep_angular, CF_NON_NEGATIVE);
    CHECK("solver.pbd.k_stiffness", s->k_stiffness, UNIT);
    CHECK("solver.pbd.iterations", s->iterations, ITERATIONS);
    CHECK("solver.pbd.k_damping", s->k_damping, UNIT);
    CHECK("solver.xpbd.compliance_scale", s->compliance_scale, CF_POSITIVE);
    CHECK("solver.contact_stiffness", s->contact_stiffness, CF_NON_NEGATIVE);
    CHECK("solver.mass_scaling", s->mass_scaling, UNIT);
    CHECK("solver.guard.max_inverted_fraction", s->max_inverted_fraction, UNIT);
    CHECK("solver.guard.max_energy_growth", s->max_energy_growth, CF_POSITIVE);
    CHECK("solver.threads", s->threads, CF_NON_NEGATIVE);
    CHECK("output.frame_interval", d->output.frame_interval, CF_POSITIVE);
    if (s->has_crack_plane) {
        cf_status st = cf_check_unit("solver.crack_plane.normal", s->crack_plane_normal, 3, err);
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
