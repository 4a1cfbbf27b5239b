/* Scene loading: defaults, values, overrides, every error code, the sandbox
 * and the round trip through the resolved text.  Scene scripts and dummy
 * meshes are written to a fresh temporary directory. */
#define _XOPEN_SOURCE 700 /* mkdtemp, realpath */

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "cohfrac/scene.h"

#include <lauxlib.h>
#include <lua.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* The temporary tree: <tmp>/cube.{node,ele}, <tmp>/sub/part.{node,ele},
 * <tmp>/meshes/bunny.{node,ele} (a prepared-mesh directory), <tmp>/beam.msh,
 * obstacle surfaces <tmp>/sub/wall.obj and <tmp>/ramp.STL. */
static char tmp[256];      /* as created */
static char tmp_real[512]; /* realpath(tmp): what resolved mesh paths start with */
static char mesh_dir[300];
static char created[64][400]; /* files and directories, removed in reverse */
static int n_created;

static const char *at(const char *name)
{
    static char buf[4][400];
    static int next;
    char *b = buf[next++ % 4];
    snprintf(b, sizeof buf[0], "%s/%s", tmp, name);
    return b;
}

static void remember(const char *path)
{
    assert_true(n_created < 64);
    snprintf(created[n_created++], sizeof created[0], "%s", path);
}

static void write_file(const char *name, const char *content)
{
    const char *path = at(name);
    int known = 0;
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(content, f);
    fclose(f);
    for (int i = 0; i < n_created; i++)
        known |= strcmp(created[i], path) == 0;
    if (!known)
        remember(path);
}

static void make_dir(const char *name)
{
    assert_int_equal(mkdir(at(name), 0700), 0);
    remember(at(name));
}

static int setup(void **state)
{
    const char *base = getenv("TMPDIR");
    char *real;
    (void)state;
    snprintf(tmp, sizeof tmp, "%s/cohfrac_scene_XXXXXX", base && *base ? base : "/tmp");
    if (!mkdtemp(tmp))
        return -1;
    real = realpath(tmp, NULL);
    if (!real)
        return -1;
    snprintf(tmp_real, sizeof tmp_real, "%s", real);
    free(real);
    /* Contents do not matter: scenes only check that the .node exists. */
    write_file("cube.node", "8 3 0 0\n");
    write_file("cube.ele", "6 4 0\n");
    make_dir("sub");
    write_file("sub/part.node", "4 3 0 0\n");
    write_file("sub/part.ele", "1 4 0\n");
    make_dir("meshes");
    write_file("meshes/bunny.node", "4 3 0 0\n");
    write_file("meshes/bunny.ele", "1 4 0\n");
    write_file("beam.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    /* Obstacle surfaces: only their existence is checked. */
    write_file("sub/wall.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write_file("ramp.STL", "solid ramp\nendsolid ramp\n");
    snprintf(mesh_dir, sizeof mesh_dir, "%s/meshes", tmp);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    while (n_created > 0)
        remove(created[--n_created]);
    return remove(tmp);
}

/* Write `text` as scene.lua and load it. */
static cf_status load_text(const char *text, const char *const *ov, int n_ov, cf_scene *s,
                           cf_error *e)
{
    write_file("scene.lua", text);
    return cf_scene_load(at("scene.lua"), ov, n_ov, mesh_dir, s, e);
}

static void load_ok(const char *text, const char *const *ov, int n_ov, cf_scene *s)
{
    cf_error e = {0};
    cf_status st = load_text(text, ov, n_ov, s, &e);
    if (st != CF_OK)
        fail_msg("expected success, got %s: %s\nscene:\n%s", cf_status_name(st), e.msg, text);
}

static int is_empty(const cf_scene *s)
{
    static const cf_scene zero;
    return memcmp(s, &zero, sizeof zero) == 0;
}

/* Loading must fail with `code`, a message containing `needle`, and an
 * empty scene. */
static void expect_error(const char *text, const char *const *ov, int n_ov, cf_status code,
                         const char *needle)
{
    cf_scene s;
    cf_error e = {0};
    cf_status st = load_text(text, ov, n_ov, &s, &e);
    if (st != code || e.code != code || !strstr(e.msg, needle))
        fail_msg("scene:\n%s\nexpected %s with \"%s\", got %s: %s", text, cf_status_name(code),
                 needle, cf_status_name(st), e.msg);
    assert_true(is_empty(&s));
}

/* CMocka 1.1 compares only floats; scenes hold doubles. */
#define assert_double_equal(a, b, tol) check_double((a), (b), (tol), #a, __LINE__)

static void check_double(double got, double want, double tol, const char *what, int line)
{
    if (!(fabs(got - want) <= tol))
        fail_msg("line %d: %s is %.17g, expected %.17g", line, what, got, want);
}

static void assert_vec(const double *got, const double *want, int n)
{
    for (int i = 0; i < n; i++)
        assert_double_equal(got[i], want[i], 1e-15);
}

static void assert_mesh(const char *got, const char *rel)
{
    char want[1024];
    snprintf(want, sizeof want, "%s/%s", tmp_real, rel);
    assert_string_equal(got, want);
}

#define MIN_BODY "bodies = { { mesh = 'cube.node' } }"

/* ---------------------------------------------------------------- values */

static void test_defaults_minimal(void **state)
{
    cf_scene s;
    (void)state;
    load_ok("return { " MIN_BODY " }", NULL, 0, &s);

    assert_string_equal(s.name, "scene");
    assert_double_equal(s.duration, 1.0, 0);
    assert_vec(s.world.gravity, (const double[]){0, 0, -9.81}, 3);

    assert_double_equal(s.world.material.E, 1e6, 0);
    assert_double_equal(s.world.material.nu, 0.3, 0);
    assert_double_equal(s.world.material.rho, 2400, 0);
    assert_double_equal(s.world.material.G_I, 22, 0);
    assert_double_equal(s.world.material.sigma_max, 1e4, 0);
    assert_double_equal(s.world.material.alpha, 2, 0);
    assert_double_equal(s.world.material.G_II, 22, 0);
    assert_double_equal(s.world.material.tau_max, 1e4, 0);
    assert_double_equal(s.world.material.beta, 2, 0);
    assert_double_equal(s.world.material.friction, 0.5, 0);
    assert_double_equal(s.world.material.restitution, 0.0, 0);

    assert_int_equal(s.world.n_bodies, 1);
    assert_mesh(s.sources[0].mesh, "cube");
    assert_double_equal(s.world.bodies[0].scale, 1.0, 0);
    assert_vec(s.world.bodies[0].position, (const double[]){0, 0, 0}, 3);
    assert_vec(s.world.bodies[0].orientation, (const double[]){1, 0, 0, 0}, 4);
    assert_vec(s.world.bodies[0].velocity, (const double[]){0, 0, 0}, 3);
    assert_vec(s.world.bodies[0].angular_velocity, (const double[]){0, 0, 0}, 3);
    assert_int_equal(s.sources[0].primitive.type, CF_PRIM_NONE);
    assert_vec(s.world.bodies[0].expansion_rate, (const double[]){0, 0, 0}, 3);
    assert_int_equal(s.world.bodies[0].has_expansion_center, 0);
    assert_int_equal(s.sources[0].hollow_layers, 0);
    assert_int_equal(s.world.n_boundaries, 0);
    assert_null(s.world.boundaries);
    assert_int_equal(s.world.n_obstacles, 0);
    assert_null(s.world.obstacles);

    assert_int_equal(s.world.solver.rigid_backend, CF_RIGID_BULLET);
    assert_double_equal(s.world.solver.dt_rigid, 1e-3, 0);
    assert_int_equal(s.world.solver.rigid_substeps, 5);
    assert_int_equal(s.world.solver.ccd, 1);
    assert_double_equal(s.world.solver.sleep_linear, 0.0, 0);
    assert_double_equal(s.world.solver.sleep_angular, 0.0, 0);
    assert_double_equal(s.world.solver.dt_fracture, 5e-6, 0);
    assert_int_equal(s.world.solver.check_interval, 1);
    assert_int_equal(s.world.solver.quiet_steps, 400);
    assert_double_equal(s.world.solver.max_fracture_time, 0.05, 0);
    assert_double_equal(s.world.solver.impact_threshold, 0.2, 0);
    assert_int_equal(s.world.solver.elasticity, CF_ELASTICITY_COROTATIONAL);
    assert_double_equal(s.world.solver.k_stiffness, 0.9, 0);
    assert_int_equal(s.world.solver.iterations, 3);
    assert_double_equal(s.world.solver.k_damping, 1.0, 0);
    assert_int_equal(s.world.solver.threads, 0);
    assert_int_equal(s.world.solver.mode, CF_RUN_HYBRID);
    assert_int_equal(s.world.solver.criterion, CF_CRITERION_TRACTION);
    assert_int_equal(s.world.solver.has_crack_plane, 0);
    assert_int_equal(s.world.solver.constraints, CF_CONSTRAINTS_PBD);
    assert_int_equal(s.world.solver.iteration_independent, 0);
    assert_double_equal(s.world.solver.compliance_scale, 1.0, 0);
    assert_double_equal(s.world.solver.contact_stiffness, 0.0, 0);
    assert_double_equal(s.world.solver.max_inverted_fraction, 0.01, 0);
    assert_double_equal(s.world.solver.max_energy_growth, 0.5, 0);

    assert_true(s.output.file[0] == '/' && strstr(s.output.file, "/out/scene.h5") != NULL); /* beside the scene */
    assert_double_equal(s.output.frame_interval, 0.01, 0);
    assert_non_null(s.resolved);
    cf_scene_free(&s);
    assert_true(is_empty(&s));
}

static const char FULL_SCENE[] =
    "local r = 0.5 -- scripts may compute values\n"
    "return {\n"
    "  name = 'drop',\n"
    "  duration = 2.5,\n"
    "  gravity = {0, -9.8, 0},\n"
    "  material = { E = 0.6, nu = 0.23, rho = 1000, G_I = 20, sigma_max = 1e-4, alpha = 3,\n"
    "               G_II = 30, tau_max = 2e-4, beta = 4, friction = 0.7, restitution = 0.2 },\n"
    "  bodies = {\n"
    "    { mesh = 'cube.node', scale = 2, position = {1, 2, 3}, orientation = {0, 0, 0, 2},\n"
    "      velocity = {0, 0, -1}, angular_velocity = {0.5, 0, 0} },\n"
    "    { mesh = 'bunny', orientation = {1, 1, 1, 1} },\n"
    "    { mesh = 'sub/part.ele' },\n"
    "  },\n"
    "  obstacles = {\n"
    "    { type = 'plane', point = {0, 0, -1}, normal = {0, 0, 5} },\n"
    "    { type = 'sphere', center = {0, 0, 3}, radius = r, velocity = {0, 0, -10} },\n"
    "    { type = 'box', center = {1, 1, 1}, half_extents = {1, 2, 3} },\n"
    "    { type = 'plane', normal = {1, 1, 0} },\n"
    "  },\n"
    "  solver = { rigid_backend = 'pbd', dt_rigid = 2e-3, rigid_substeps = 10,\n"
    "             dt_fracture = 3e-6, check_interval = 10, quiet_steps = 100,\n"
    "             max_fracture_time = 0.1, impact_threshold = 0.5, elasticity = 'linear',\n"
    "             pbd = { k_stiffness = 1, iterations = 4, k_damping = 0 }, threads = 2 },\n"
    "  output = { file = 'res/drop.h5', frame_interval = 0.02 },\n"
    "}\n";

static void test_full_scene(void **state)
{
    cf_scene s;
    const double h = sqrt(0.5);
    (void)state;
    load_ok(FULL_SCENE, NULL, 0, &s);

    assert_string_equal(s.name, "drop");
    assert_double_equal(s.duration, 2.5, 0);
    assert_vec(s.world.gravity, (const double[]){0, -9.8, 0}, 3);
    assert_double_equal(s.world.material.E, 0.6, 0);
    assert_double_equal(s.world.material.nu, 0.23, 0);
    assert_double_equal(s.world.material.rho, 1000, 0);
    assert_double_equal(s.world.material.G_I, 20, 0);
    assert_double_equal(s.world.material.sigma_max, 1e-4, 0);
    assert_double_equal(s.world.material.alpha, 3, 0);
    assert_double_equal(s.world.material.G_II, 30, 0);
    assert_double_equal(s.world.material.tau_max, 2e-4, 0);
    assert_double_equal(s.world.material.beta, 4, 0);
    assert_double_equal(s.world.material.friction, 0.7, 0);
    assert_double_equal(s.world.material.restitution, 0.2, 0);

    assert_int_equal(s.world.n_bodies, 3);
    assert_mesh(s.sources[0].mesh, "cube");
    assert_double_equal(s.world.bodies[0].scale, 2, 0);
    assert_vec(s.world.bodies[0].position, (const double[]){1, 2, 3}, 3);
    assert_vec(s.world.bodies[0].orientation, (const double[]){0, 0, 0, 1}, 4);
    assert_vec(s.world.bodies[0].velocity, (const double[]){0, 0, -1}, 3);
    assert_vec(s.world.bodies[0].angular_velocity, (const double[]){0.5, 0, 0}, 3);
    assert_mesh(s.sources[1].mesh, "meshes/bunny");
    assert_vec(s.world.bodies[1].orientation, (const double[]){0.5, 0.5, 0.5, 0.5}, 4);
    assert_mesh(s.sources[2].mesh, "sub/part");

    assert_int_equal(s.world.n_obstacles, 4);
    assert_int_equal(s.world.obstacles[0].type, CF_OBSTACLE_PLANE);
    assert_vec(s.world.obstacles[0].point, (const double[]){0, 0, -1}, 3);
    assert_vec(s.world.obstacles[0].normal, (const double[]){0, 0, 1}, 3);
    assert_int_equal(s.world.obstacles[1].type, CF_OBSTACLE_SPHERE);
    assert_vec(s.world.obstacles[1].center, (const double[]){0, 0, 3}, 3);
    assert_double_equal(s.world.obstacles[1].radius, 0.5, 0);
    assert_vec(s.world.obstacles[1].velocity, (const double[]){0, 0, -10}, 3);
    assert_int_equal(s.world.obstacles[2].type, CF_OBSTACLE_BOX);
    assert_vec(s.world.obstacles[2].center, (const double[]){1, 1, 1}, 3);
    assert_vec(s.world.obstacles[2].half_extents, (const double[]){1, 2, 3}, 3);
    assert_vec(s.world.obstacles[2].velocity, (const double[]){0, 0, 0}, 3);
    assert_vec(s.world.obstacles[3].point, (const double[]){0, 0, 0}, 3);
    assert_vec(s.world.obstacles[3].normal, (const double[]){h, h, 0}, 3);

    assert_int_equal(s.world.solver.rigid_backend, CF_RIGID_PBD);
    assert_double_equal(s.world.solver.dt_rigid, 2e-3, 0);
    assert_int_equal(s.world.solver.rigid_substeps, 10);
    assert_double_equal(s.world.solver.dt_fracture, 3e-6, 0);
    assert_int_equal(s.world.solver.check_interval, 10);
    assert_int_equal(s.world.solver.quiet_steps, 100);
    assert_double_equal(s.world.solver.max_fracture_time, 0.1, 0);
    assert_double_equal(s.world.solver.impact_threshold, 0.5, 0);
    assert_int_equal(s.world.solver.elasticity, CF_ELASTICITY_LINEAR);
    assert_double_equal(s.world.solver.k_stiffness, 1, 0);
    assert_int_equal(s.world.solver.iterations, 4);
    assert_double_equal(s.world.solver.k_damping, 0, 0);
    assert_int_equal(s.world.solver.threads, 2);
    /* A relative output path starts at the scene file's directory. */
    assert_true(s.output.file[0] == '/' && strstr(s.output.file, "/res/drop.h5") != NULL);
    assert_double_equal(s.output.frame_interval, 0.02, 0);
    cf_scene_free(&s);
}

/* G_II, tau_max, beta follow G_I, sigma_max, alpha; output.file follows name. */
static void test_derived_defaults(void **state)
{
    cf_scene s;
    (void)state;
    load_ok("return { name = 'beam', material = { G_I = 5, sigma_max = 7, alpha = 3 }, " MIN_BODY
            " }",
            NULL, 0, &s);
    assert_double_equal(s.world.material.G_II, 5, 0);
    assert_double_equal(s.world.material.tau_max, 7, 0);
    assert_double_equal(s.world.material.beta, 3, 0);
    assert_true(s.output.file[0] == '/' && strstr(s.output.file, "/out/beam.h5") != NULL); /* beside the scene */
    cf_scene_free(&s);
}

/* Every spelling of a mesh path reaches the same absolute base path. */
static void test_mesh_paths(void **state)
{
    static const char *const spellings[] = {"cube", "./cube", "cube.node", "cube.ele",
                                            "sub/../cube", NULL};
    char text[1200];
    (void)state;
    for (int i = 0; spellings[i]; i++) {
        cf_scene s;
        const char *m = spellings[i];
        /* A bare "cube" would be a prepared mesh name: give it a directory. */
        snprintf(text, sizeof text, "return { bodies = { { mesh = '%s%s' } } }",
                 strchr(m, '/') || strchr(m, '.') ? "" : "./", m);
        load_ok(text, NULL, 0, &s);
        assert_mesh(s.sources[0].mesh, "cube");
        cf_scene_free(&s);
    }
    {
        cf_scene s;
        snprintf(text, sizeof text, "return { bodies = { { mesh = '%s/sub/part' } } }", tmp);
        load_ok(text, NULL, 0, &s);
        assert_mesh(s.sources[0].mesh, "sub/part");
        cf_scene_free(&s);
    }
}

static void test_prepared_mesh(void **state)
{
    cf_scene s;
    (void)state;
    load_ok("return { bodies = { { mesh = 'bunny' } } }", NULL, 0, &s);
    assert_mesh(s.sources[0].mesh, "meshes/bunny");
    cf_scene_free(&s);
}

/* Every key added with primitives, expansion, boundaries and the fracture
 * solver options. */
static const char NEW_KEYS_SCENE[] =
    "return {\n"
    "  bodies = {\n"
    "    { mesh = { type = 'box', size = {1, 2, 3}, cells = {2, 3, 4}, tets_per_cell = 5 },\n"
    "      expansion_rate = 0.5, expansion_center = {1, 0, 0} },\n"
    "    { mesh = { type = 'sphere', radius = 0.5, mesh_size = 0.1 },\n"
    "      expansion_rate = {1, 2, 3} },\n"
    "    { mesh = { type = 'hollow_sphere', radius = 0.5, thickness = 0.1, mesh_size = 0.05 } },\n"
    "    { mesh = { type = 'plate', size = {1, 1, 0.01}, mesh_size = 0.02 } },\n"
    "    { mesh = { type = 'notched_beam', size = {2, 0.1, 0.2}, notch = {0.1, 0.02, 0.3},\n"
    "               mesh_size = 0.01 } },\n"
    "    { mesh = 'sub/../beam.msh' },\n"
    "  },\n"
    "  boundary = {\n"
    "    { region = { type = 'box', min = {-1, -1, -1}, max = {1, 1, -0.9} }, fixed = true },\n"
    "    { region = { type = 'plane', point = {0, 0, 1}, normal = {0, 0, 2}, tolerance = 1e-3 },\n"
    "      velocity = {0, 0, -0.1}, axes = 'zx', body = 2 },\n"
    "    { region = { type = 'group', name = 'top' }, velocity = {-0.0, 1, 0}, axes = 'y',\n"
    "      fixed = false },\n"
    "  },\n"
    "  solver = { mode = 'fracture', criterion = 'none',\n"
    "             crack_plane = { point = {0, 0, 0.5}, normal = {3, 0, 4}, tolerance = 1e-4 },\n"
    "             constraints = 'xpbd', pbd = { iteration_independent = true },\n"
    "             xpbd = { compliance_scale = 2 }, contact_stiffness = 1e9,\n"
    "             guard = { max_inverted_fraction = 0.1, max_energy_growth = 2 } },\n"
    "  output = { file = '' },\n"
    "}\n";

static void test_new_keys(void **state)
{
    cf_scene s;
    const cf_primitive *p;
    const cf_boundary *b;
    (void)state;
    load_ok(NEW_KEYS_SCENE, NULL, 0, &s);

    assert_int_equal(s.world.n_bodies, 6);
    p = &s.sources[0].primitive;
    assert_string_equal(s.sources[0].mesh, "");
    assert_int_equal(p->type, CF_PRIM_BOX);
    assert_vec(p->size, (const double[]){1, 2, 3}, 3);
    assert_int_equal(p->cells[0], 2);
    assert_int_equal(p->cells[1], 3);
    assert_int_equal(p->cells[2], 4);
    assert_int_equal(p->tets_per_cell, 5);
    assert_vec(s.world.bodies[0].expansion_rate, (const double[]){0.5, 0.5, 0.5}, 3);
    assert_int_equal(s.world.bodies[0].has_expansion_center, 1);
    assert_vec(s.world.bodies[0].expansion_center, (const double[]){1, 0, 0}, 3);

    p = &s.sources[1].primitive;
    assert_string_equal(s.sources[1].mesh, "");
    assert_int_equal(p->type, CF_PRIM_SPHERE);
    assert_double_equal(p->radius, 0.5, 0);
    assert_double_equal(p->mesh_size, 0.1, 0);
    assert_vec(s.world.bodies[1].expansion_rate, (const double[]){1, 2, 3}, 3);
    assert_int_equal(s.world.bodies[1].has_expansion_center, 0);

    p = &s.sources[2].primitive;
    assert_int_equal(p->type, CF_PRIM_HOLLOW_SPHERE);
    assert_double_equal(p->radius, 0.5, 0);
    assert_double_equal(p->thickness, 0.1, 0);
    assert_double_equal(p->mesh_size, 0.05, 0);

    p = &s.sources[3].primitive;
    assert_int_equal(p->type, CF_PRIM_PLATE);
    assert_vec(p->size, (const double[]){1, 1, 0.01}, 3);
    assert_double_equal(p->mesh_size, 0.02, 0);

    p = &s.sources[4].primitive;
    assert_int_equal(p->type, CF_PRIM_NOTCHED_BEAM);
    assert_vec(p->size, (const double[]){2, 0.1, 0.2}, 3);
    assert_vec(p->notch, (const double[]){0.1, 0.02, 0.3}, 3);
    assert_double_equal(p->mesh_size, 0.01, 0);

    /* A Gmsh file keeps its extension and becomes absolute. */
    assert_int_equal(s.sources[5].primitive.type, CF_PRIM_NONE);
    assert_mesh(s.sources[5].mesh, "beam.msh");

    assert_int_equal(s.world.n_boundaries, 3);
    b = &s.world.boundaries[0];
    assert_int_equal(b->type, CF_REGION_BOX);
    assert_vec(b->min, (const double[]){-1, -1, -1}, 3);
    assert_vec(b->max, (const double[]){1, 1, -0.9}, 3);
    assert_vec(b->velocity, (const double[]){0, 0, 0}, 3);
    assert_int_equal(b->axes, 7);
    assert_int_equal(b->body, -1);
    b = &s.world.boundaries[1];
    assert_int_equal(b->type, CF_REGION_PLANE);
    assert_vec(b->point, (const double[]){0, 0, 1}, 3);
    assert_vec(b->normal, (const double[]){0, 0, 1}, 3);
    assert_double_equal(b->tolerance, 1e-3, 0);
    assert_vec(b->velocity, (const double[]){0, 0, -0.1}, 3);
    assert_int_equal(b->axes, 1 | 4);
    assert_int_equal(b->body, 1);
    b = &s.world.boundaries[2];
    assert_int_equal(b->type, CF_REGION_GROUP);
    assert_string_equal(b->group, "top");
    assert_vec(b->velocity, (const double[]){0, 1, 0}, 3);
    assert_int_equal(b->axes, 2);
    assert_int_equal(b->body, -1);

    assert_int_equal(s.world.solver.mode, CF_RUN_FRACTURE);
    assert_int_equal(s.world.solver.criterion, CF_CRITERION_NONE);
    assert_int_equal(s.world.solver.has_crack_plane, 1);
    assert_vec(s.world.solver.crack_plane_point, (const double[]){0, 0, 0.5}, 3);
    assert_vec(s.world.solver.crack_plane_normal, (const double[]){0.6, 0, 0.8}, 3);
    assert_double_equal(s.world.solver.crack_plane_tolerance, 1e-4, 0);
    assert_int_equal(s.world.solver.constraints, CF_CONSTRAINTS_XPBD);
    assert_int_equal(s.world.solver.iteration_independent, 1);
    assert_double_equal(s.world.solver.k_stiffness, 0.9, 0);
    assert_double_equal(s.world.solver.compliance_scale, 2, 0);
    assert_double_equal(s.world.solver.contact_stiffness, 1e9, 0);
    assert_double_equal(s.world.solver.max_inverted_fraction, 0.1, 0);
    assert_double_equal(s.world.solver.max_energy_growth, 2, 0);
    assert_string_equal(s.output.file, "");
    assert_non_null(strstr(s.resolved, "file = \"\","));
    cf_scene_free(&s);
    assert_true(is_empty(&s));
}

/* Defaults inside the new tables: box cells and tets_per_cell, plane
 * tolerances, boundary axes and body, and the other constraint modes. */
static void test_new_defaults(void **state)
{
    cf_scene s;
    (void)state;
    load_ok("return { bodies = { { mesh = { type = 'box', size = {1, 1, 1} } } },\n"
            "  boundary = { { region = { type = 'plane', point = {0,0,0}, normal = {0,1,0} },\n"
            "                 velocity = {1, 2, 3} } },\n"
            "  solver = { mode = 'fracture', crack_plane = { point = {0,0,0}, normal = {0,0,1} },\n"
            "             constraints = 'none', criterion = 'source', xpbd = {}, guard = {} } }",
            NULL, 0, &s);
    assert_int_equal(s.sources[0].primitive.type, CF_PRIM_BOX);
    assert_int_equal(s.sources[0].primitive.cells[0], 1);
    assert_int_equal(s.sources[0].primitive.cells[1], 1);
    assert_int_equal(s.sources[0].primitive.cells[2], 1);
    assert_int_equal(s.sources[0].primitive.tets_per_cell, 6);
    assert_int_equal(s.world.n_boundaries, 1);
    assert_double_equal(s.world.boundaries[0].tolerance, 1e-6, 0);
    assert_int_equal(s.world.boundaries[0].axes, 7);
    assert_int_equal(s.world.boundaries[0].body, -1);
    assert_vec(s.world.boundaries[0].velocity, (const double[]){1, 2, 3}, 3);
    assert_int_equal(s.world.solver.has_crack_plane, 1);
    assert_double_equal(s.world.solver.crack_plane_tolerance, 1e-6, 0);
    assert_int_equal(s.world.solver.constraints, CF_CONSTRAINTS_NONE);
    assert_int_equal(s.world.solver.criterion, CF_CRITERION_SOURCE);
    assert_double_equal(s.world.solver.compliance_scale, 1, 0);
    assert_double_equal(s.world.solver.max_inverted_fraction, 0.01, 0);
    assert_double_equal(s.world.solver.max_energy_growth, 0.5, 0);
    cf_scene_free(&s);

    /* The new keys also take overrides, primitives included. */
    {
        static const char *const ov[] = {"bodies[1].mesh.radius=0.25", "solver.constraints='xpbd'",
                                         "bodies[1].expansion_rate={1, 0, 0}"};
        load_ok("return { bodies = { { mesh = { type = 'sphere', radius = 1, mesh_size = 0.1 } } } }",
                ov, 3, &s);
        assert_double_equal(s.sources[0].primitive.radius, 0.25, 0);
        assert_int_equal(s.world.solver.constraints, CF_CONSTRAINTS_XPBD);
        assert_vec(s.world.bodies[0].expansion_rate, (const double[]){1, 0, 0}, 3);
        cf_scene_free(&s);
    }
}

/* ---------------------------------------------------------------- overrides */

static void test_overrides(void **state)
{
    static const char *const ov[] = {
        "solver.dt_rigid=2e-3",          /* number */
        "solver.rigid_backend=\"pbd\"",  /* string */
        "gravity={0,0,-1}",              /* vector */
        "bodies[1].scale=3",             /* list index */
        " solver.pbd.iterations = 7 ",   /* spaces; intermediate table created */
        "bodies[2].mesh='sub/part'",     /* a new list item */
        "name = 'a=b'",                  /* '=' inside the value */
        "material.E = 2 * 1e5",          /* any expression */
    };
    cf_scene s;
    (void)state;
    load_ok("return { solver = { dt_rigid = 1 }, " MIN_BODY " }", ov, 8, &s);
    assert_double_equal(s.world.solver.dt_rigid, 2e-3, 0);
    assert_int_equal(s.world.solver.rigid_backend, CF_RIGID_PBD);
    assert_vec(s.world.gravity, (const double[]){0, 0, -1}, 3);
    assert_double_equal(s.world.bodies[0].scale, 3, 0);
    assert_int_equal(s.world.solver.iterations, 7);
    assert_int_equal(s.world.n_bodies, 2);
    assert_mesh(s.sources[1].mesh, "sub/part");
    assert_string_equal(s.name, "a=b");
    assert_true(s.output.file[0] == '/' && strstr(s.output.file, "/out/a=b.h5") != NULL); /* beside the scene */
    assert_double_equal(s.world.material.E, 2e5, 0);
    cf_scene_free(&s);

    /* Overrides apply in order; a later one wins.  They also reach a scene
     * that lacks the table altogether. */
    {
        static const char *const twice[] = {"duration=2", "duration=3"};
        load_ok("return { " MIN_BODY " }", twice, 2, &s);
        assert_double_equal(s.duration, 3, 0);
        cf_scene_free(&s);
    }
}

/* The keys added for hollow bodies, obstacle materials, mesh obstacles,
 * continuous collision detection and sleeping. */
static const char SHELL_KEYS_SCENE[] =
    "return {\n"
    "  bodies = { { mesh = 'cube.node', hollow_layers = 2 }, { mesh = 'bunny' } },\n"
    "  obstacles = {\n"
    "    { type = 'plane', friction = 0.5, restitution = 0 },\n"
    "    { type = 'sphere', center = {0, 0, 1}, radius = 0.1, velocity = {10, 0, 0},\n"
    "      friction = 2, restitution = 0.25 },\n"
    "    { type = 'box', center = {0, 0, 0}, half_extents = {1, 1, 1} },\n"
    "    { type = 'mesh', file = 'sub/wall.obj', scale = 2, orientation = {0, 0, 0, 3},\n"
    "      position = {1, 2, 3}, friction = 0 },\n"
    "    { type = 'mesh', file = 'ramp.STL' },\n"
    "  },\n"
    "  solver = { ccd = false, sleeping = { linear = 0.05, angular = 0.1 } },\n"
    "}\n";

/* ---------------------------------------------------------------- round trip */

static void assert_same_scene(const cf_scene *a, const cf_scene *b)
{
    assert_string_equal(a->name, b->name);
    assert_memory_equal(&a->duration, &b->duration, sizeof a->duration);
    assert_memory_equal(a->world.gravity, b->world.gravity, sizeof a->world.gravity);
    assert_memory_equal(&a->world.material, &b->world.material, sizeof a->world.material);
    assert_int_equal(a->world.n_bodies, b->world.n_bodies);
    for (int i = 0; i < a->world.n_bodies; i++) {
        const cf_body_def *x = &a->world.bodies[i], *y = &b->world.bodies[i];
        const cf_body_source *p = &a->sources[i], *q = &b->sources[i];
        assert_string_equal(p->mesh, q->mesh);
        assert_memory_equal(&x->scale, &y->scale, sizeof x->scale);
        assert_memory_equal(x->position, y->position, sizeof x->position);
        assert_memory_equal(x->orientation, y->orientation, sizeof x->orientation);
        assert_memory_equal(x->velocity, y->velocity, sizeof x->velocity);
        assert_memory_equal(x->angular_velocity, y->angular_velocity, sizeof x->angular_velocity);
        assert_int_equal(p->primitive.type, q->primitive.type);
        assert_memory_equal(p->primitive.size, q->primitive.size, sizeof p->primitive.size);
        assert_memory_equal(p->primitive.cells, q->primitive.cells, sizeof p->primitive.cells);
        assert_int_equal(p->primitive.tets_per_cell, q->primitive.tets_per_cell);
        assert_memory_equal(&p->primitive.radius, &q->primitive.radius, sizeof(double));
        assert_memory_equal(&p->primitive.thickness, &q->primitive.thickness, sizeof(double));
        assert_memory_equal(p->primitive.notch, q->primitive.notch, sizeof p->primitive.notch);
        assert_memory_equal(&p->primitive.mesh_size, &q->primitive.mesh_size, sizeof(double));
        assert_memory_equal(x->expansion_rate, y->expansion_rate, sizeof x->expansion_rate);
        assert_int_equal(x->has_expansion_center, y->has_expansion_center);
        assert_memory_equal(x->expansion_center, y->expansion_center,
                            sizeof x->expansion_center);
        assert_int_equal(p->hollow_layers, q->hollow_layers);
    }
    assert_int_equal(a->world.n_boundaries, b->world.n_boundaries);
    for (int i = 0; i < a->world.n_boundaries; i++) {
        const cf_boundary *x = &a->world.boundaries[i], *y = &b->world.boundaries[i];
        assert_int_equal(x->type, y->type);
        assert_memory_equal(x->min, y->min, sizeof x->min);
        assert_memory_equal(x->max, y->max, sizeof x->max);
        assert_memory_equal(x->point, y->point, sizeof x->point);
        assert_memory_equal(x->normal, y->normal, sizeof x->normal);
        assert_memory_equal(&x->tolerance, &y->tolerance, sizeof x->tolerance);
        assert_string_equal(x->group, y->group);
        assert_int_equal(x->body, y->body);
        assert_int_equal(x->axes, y->axes);
        assert_memory_equal(x->velocity, y->velocity, sizeof x->velocity);
    }
    assert_int_equal(a->world.n_obstacles, b->world.n_obstacles);
    for (int i = 0; i < a->world.n_obstacles; i++) {
        const cf_obstacle *x = &a->world.obstacles[i], *y = &b->world.obstacles[i];
        assert_int_equal(x->type, y->type);
        assert_memory_equal(x->point, y->point, sizeof x->point);
        assert_memory_equal(x->normal, y->normal, sizeof x->normal);
        assert_memory_equal(x->center, y->center, sizeof x->center);
        assert_memory_equal(&x->radius, &y->radius, sizeof x->radius);
        assert_memory_equal(x->half_extents, y->half_extents, sizeof x->half_extents);
        assert_memory_equal(x->velocity, y->velocity, sizeof x->velocity);
        assert_string_equal(x->file, y->file);
        assert_memory_equal(&x->scale, &y->scale, sizeof x->scale);
        assert_memory_equal(x->orientation, y->orientation, sizeof x->orientation);
        assert_memory_equal(x->position, y->position, sizeof x->position);
        assert_memory_equal(&x->friction, &y->friction, sizeof x->friction);
        assert_memory_equal(&x->restitution, &y->restitution, sizeof x->restitution);
    }
    const cf_solver_settings *sa = &a->world.solver, *sb = &b->world.solver;
    assert_int_equal(sa->rigid_backend, sb->rigid_backend);
    assert_int_equal(sa->ccd, sb->ccd);
    assert_memory_equal(&sa->sleep_linear, &sb->sleep_linear, sizeof(double));
    assert_memory_equal(&sa->sleep_angular, &sb->sleep_angular, sizeof(double));
    assert_memory_equal(&sa->dt_rigid, &sb->dt_rigid, sizeof(double));
    assert_int_equal(sa->rigid_substeps, sb->rigid_substeps);
    assert_memory_equal(&sa->dt_fracture, &sb->dt_fracture, sizeof(double));
    assert_int_equal(sa->check_interval, sb->check_interval);
    assert_int_equal(sa->quiet_steps, sb->quiet_steps);
    assert_memory_equal(&sa->max_fracture_time, &sb->max_fracture_time,
                        sizeof(double));
    assert_memory_equal(&sa->impact_threshold, &sb->impact_threshold,
                        sizeof(double));
    assert_int_equal(sa->elasticity, sb->elasticity);
    assert_memory_equal(&sa->k_stiffness, &sb->k_stiffness, sizeof(double));
    assert_int_equal(sa->iterations, sb->iterations);
    assert_memory_equal(&sa->k_damping, &sb->k_damping, sizeof(double));
    assert_int_equal(sa->threads, sb->threads);
    assert_int_equal(sa->mode, sb->mode);
    assert_int_equal(sa->criterion, sb->criterion);
    assert_int_equal(sa->has_crack_plane, sb->has_crack_plane);
    assert_memory_equal(sa->crack_plane_point, sb->crack_plane_point, 3 * sizeof(double));
    assert_memory_equal(sa->crack_plane_normal, sb->crack_plane_normal, 3 * sizeof(double));
    assert_memory_equal(&sa->crack_plane_tolerance, &sb->crack_plane_tolerance,
                        sizeof(double));
    assert_int_equal(sa->constraints, sb->constraints);
    assert_int_equal(sa->iteration_independent, sb->iteration_independent);
    assert_memory_equal(&sa->compliance_scale, &sb->compliance_scale,
                        sizeof(double));
    assert_memory_equal(&sa->contact_stiffness, &sb->contact_stiffness,
                        sizeof(double));
    assert_memory_equal(&sa->max_inverted_fraction, &sb->max_inverted_fraction,
                        sizeof(double));
    assert_memory_equal(&sa->max_energy_growth, &sb->max_energy_growth,
                        sizeof(double));
    assert_string_equal(a->output.file, b->output.file);
    assert_memory_equal(&a->output.frame_interval, &b->output.frame_interval, sizeof(double));
    assert_string_equal(a->resolved, b->resolved);
}

/* Load, write `resolved`, load that from elsewhere (another directory, no
 * mesh directory): the same scene, bit for bit, and the same text. */
static void round_trip(const char *text, const char *const *ov, int n_ov)
{
    cf_scene a, b;
    cf_error e = {0};
    load_ok(text, ov, n_ov, &a);
    write_file("sub/resolved.lua", a.resolved);
    if (cf_scene_load(at("sub/resolved.lua"), NULL, 0, NULL, &b, &e) != CF_OK)
        fail_msg("resolved scene does not load: %s\n%s", e.msg, a.resolved);
    assert_same_scene(&a, &b);
    cf_scene_free(&a);
    cf_scene_free(&b);
}

static void test_round_trip(void **state)
{
    static const char *const ov[] = {"material.nu=1/3", "bodies[1].position={0.1, -0.2, 1e-300}",
                                     "bodies[2].velocity={-0.0, 0, 1e300}",
                                     "name='q\"uo\\\\te\\n\\1' .. '2'"};
    (void)state;
    round_trip("return { " MIN_BODY " }", NULL, 0);
    round_trip(FULL_SCENE, NULL, 0);
    round_trip(FULL_SCENE, ov, 4);
    /* Vectors whose normalised form moves by an ulp when normalised again:
     * the resolved text must still read back bit for bit. */
    round_trip("return { " MIN_BODY ", obstacles = { { type = 'plane', normal = {1, 1, 13} },"
               " { type = 'plane', normal = {1e-300, 3e-300, 0} } } }",
               NULL, 0);
    round_trip("return { bodies = { { mesh = 'cube.node', orientation = {1, 0, 1, 13} } } }",
               NULL, 0);
    /* Every new key: primitives, a .msh path, expansion, boundaries (fixed,
     * -0.0 velocity), crack_plane, constraints, xpbd, guard, no output file. */
    round_trip(NEW_KEYS_SCENE, NULL, 0);
    round_trip("return { bodies = { { mesh = { type = 'box', size = {0.1, 0.2, 0.3} } } },\n"
               "  boundary = { { region = { type = 'plane', point = {0,0,0},\n"
               "                            normal = {1, 1, 13} }, fixed = true, axes = 'zy' } },\n"
               "  solver = { mode = 'fracture',\n"
               "             crack_plane = { point = {0,0,0}, normal = {1e-300, 3e-300, 0} } } }",
               NULL, 0);
    /* hollow_layers, obstacle friction/restitution, mesh obstacles, ccd,
     * sleeping. */
    round_trip(SHELL_KEYS_SCENE, NULL, 0);
    {
        static const char *const ov[] = {"bodies[1].hollow_layers=3", "solver.ccd=false",
                                         "solver.sleeping.angular=0.25",
                                         "solver.sleeping.linear=1/3",
                                         "obstacles[1].restitution=1/3"};
        round_trip("return { " MIN_BODY ", obstacles = { { type = 'plane' } } }", ov, 5);
    }
}

/* ---------------------------------------------------------------- shells, obstacles, Bullet */

static void test_shell_obstacle_keys(void **state)
{
    cf_scene s;
    const cf_obstacle *o;
    (void)state;
    load_ok(SHELL_KEYS_SCENE, NULL, 0, &s);
    assert_int_equal(s.sources[0].hollow_layers, 2);
    assert_int_equal(s.sources[1].hollow_layers, 0);

    assert_int_equal(s.world.n_obstacles, 5);
    o = &s.world.obstacles[0];
    assert_double_equal(o->friction, 0.5, 0);
    assert_double_equal(o->restitution, 0.0, 0);
    o = &s.world.obstacles[1];
    assert_double_equal(o->friction, 2, 0);
    assert_double_equal(o->restitution, 0.25, 0);
    assert_vec(o->velocity, (const double[]){10, 0, 0}, 3);
    /* Defaults: factors of 1 (the material's own values). */
    o = &s.world.obstacles[2];
    assert_double_equal(o->friction, 1, 0);
    assert_double_equal(o->restitution, 1, 0);
    o = &s.world.obstacles[3];
    assert_int_equal(o->type, CF_OBSTACLE_MESH);
    assert_mesh(o->file, "sub/wall.obj");
    assert_double_equal(o->scale, 2, 0);
    assert_vec(o->orientation, (const double[]){0, 0, 0, 1}, 4);
    assert_vec(o->position, (const double[]){1, 2, 3}, 3);
    assert_double_equal(o->friction, 0, 0);
    assert_double_equal(o->restitution, 1, 0);
    o = &s.world.obstacles[4];
    assert_int_equal(o->type, CF_OBSTACLE_MESH);
    assert_mesh(o->file, "ramp.STL");
    assert_double_equal(o->scale, 1, 0);
    assert_vec(o->orientation, (const double[]){1, 0, 0, 0}, 4);
    assert_vec(o->position, (const double[]){0, 0, 0}, 3);

    assert_int_equal(s.world.solver.ccd, 0);
    assert_double_equal(s.world.solver.sleep_linear, 0.05, 0);
    assert_double_equal(s.world.solver.sleep_angular, 0.1, 0);
    assert_non_null(strstr(s.resolved, "hollow_layers = 2,"));
    assert_non_null(strstr(s.resolved, "ccd = false,"));
    assert_non_null(strstr(s.resolved, "type = \"mesh\","));
    cf_scene_free(&s);

    /* An absolute surface path; overrides reach the new keys. */
    {
        char text[1200];
        static const char *const ov[] = {"solver.sleeping.linear=0.5", "solver.ccd=true",
                                         "solver.sleeping.angular=0.125",
                                         "bodies[1].hollow_layers=1",
                                         "obstacles[1].friction=0.75"};
        snprintf(text, sizeof text,
                 "return { " MIN_BODY ", obstacles = { { type = 'mesh', file = '%s/sub/wall.obj' } },"
                 " solver = { ccd = false } }",
                 tmp);
        load_ok(text, ov, 5, &s);
        assert_mesh(s.world.obstacles[0].file, "sub/wall.obj");
        assert_double_equal(s.world.obstacles[0].friction, 0.75, 0);
        assert_double_equal(s.world.solver.sleep_linear, 0.5, 0);
        assert_double_equal(s.world.solver.sleep_angular, 0.125, 0);
        assert_int_equal(s.world.solver.ccd, 1);
        assert_int_equal(s.sources[0].hollow_layers, 1);
        cf_scene_free(&s);
    }
}

#define OBSTACLE(o) "return { " MIN_BODY ", obstacles = { " o " } }"

static void test_error_shell_obstacle_keys(void **state)
{
    static const struct {
        const char *text;
        cf_status code;
        const char *needle;
    } cases[] = {
        /* hollow_layers */
        {"return { bodies = { { mesh = 'cube.node', hollow_layers = -1 } } }", CF_ERR_SCENE_VALUE,
         "'bodies[1].hollow_layers' must be >= 0, got -1"},
        {"return { bodies = { { mesh = 'cube.node', hollow_layers = 1.5 } } }", CF_ERR_SCENE_TYPE,
         "'bodies[1].hollow_layers' must be an integer, got 1.5"},
        {"return { bodies = { { mesh = 'cube.node', hollow_layers = 'two' } } }",
         CF_ERR_SCENE_TYPE, "'bodies[1].hollow_layers' must be an integer, got string"},
        {"return { bodies = { { mesh = 'cube.node', hollow_layer = 1 } } }", CF_ERR_SCENE_KEY,
         "unknown key 'bodies[1].hollow_layer'; allowed: mesh, "},
        /* obstacle friction / restitution */
        {OBSTACLE("{ type = 'plane', friction = -0.5 }"), CF_ERR_SCENE_VALUE,
         "'obstacles[1].friction' must be >= 0, got -0.5"},
        {OBSTACLE("{ type = 'sphere', center = {0,0,0}, radius = 1, restitution = -1 }"),
         CF_ERR_SCENE_VALUE, "'obstacles[1].restitution' must be >= 0, got -1"},
        {OBSTACLE("{ type = 'box', center = {0,0,0}, half_extents = {1,1,1}, friction = 'ice' }"),
         CF_ERR_SCENE_TYPE, "'obstacles[1].friction' must be a number, got string"},
        {OBSTACLE("{ type = 'plane', restitution = 0/0 }"), CF_ERR_SCENE_VALUE,
         "'obstacles[1].restitution' must be a finite number"},
        /* mesh obstacles */
        {OBSTACLE("{ type = 'mesh' }"), CF_ERR_SCENE_KEY,
         "missing required key 'obstacles[1].file'"},
        {OBSTACLE("{ type = 'mesh', file = 'nosuch.obj' }"), CF_ERR_FILE_OPEN,
         "obstacles[1].file: surface 'nosuch.obj' not found: no file "},
        {OBSTACLE("{ type = 'mesh', file = 'sub/nosuch.stl' }"), CF_ERR_FILE_OPEN,
         "(relative paths start at the scene file's directory)"},
        {OBSTACLE("{ type = 'mesh', file = 'cube.node' }"), CF_ERR_SCENE_VALUE,
         "'obstacles[1].file' is \"cube.node\"; a triangle surface must be in a format "
         "assimp reads"},
        {OBSTACLE("{ type = 'mesh', file = 3 }"), CF_ERR_SCENE_TYPE,
         "'obstacles[1].file' must be a string, got number"},
        {OBSTACLE("{ type = 'mesh', file = 'sub/wall.obj', scale = 0 }"), CF_ERR_SCENE_VALUE,
         "'obstacles[1].scale' must be > 0, got 0"},
        {OBSTACLE("{ type = 'mesh', file = 'sub/wall.obj', orientation = {0, 0, 0, 0} }"),
         CF_ERR_SCENE_VALUE, "'obstacles[1].orientation' must be a non-zero quaternion"},
        {OBSTACLE("{ type = 'mesh', file = 'sub/wall.obj', orientation = {1, 0, 0} }"),
         CF_ERR_SCENE_TYPE, "'obstacles[1].orientation' must be a list of 4 numbers"},
        {OBSTACLE("{ type = 'mesh', file = 'sub/wall.obj', position = 'here' }"),
         CF_ERR_SCENE_TYPE, "'obstacles[1].position' must be a list of 3 numbers, got string"},
        {OBSTACLE("{ type = 'mesh', file = 'sub/wall.obj', center = {0,0,0} }"), CF_ERR_SCENE_KEY,
         "unknown key 'obstacles[1].center'; allowed: type, file, scale, orientation, position, "
         "friction, restitution"},
        {OBSTACLE("{ type = 'mesh', file = 'sub/wall.obj', velocity = {1,0,0} }"),
         CF_ERR_SCENE_KEY, "unknown key 'obstacles[1].velocity'"},
        {OBSTACLE("{ type = 'torus' }"), CF_ERR_SCENE_VALUE,
         "'obstacles[1].type' is \"torus\"; allowed: plane, sphere, box, mesh"},
        /* ccd, sleeping */
        {"return { " MIN_BODY ", solver = { ccd = 1 } }", CF_ERR_SCENE_TYPE,
         "'solver.ccd' must be a boolean (true or false), got number"},
        {"return { " MIN_BODY ", solver = { sleeping = 0.1 } }", CF_ERR_SCENE_TYPE,
         "'solver.sleeping' must be a table, got number"},
        {"return { " MIN_BODY ", solver = { sleeping = { linear = -0.1 } } }", CF_ERR_SCENE_VALUE,
         "'solver.sleeping.linear' must be >= 0, got -0.1"},
        {"return { " MIN_BODY ", solver = { sleeping = { angular = 'slow' } } }", CF_ERR_SCENE_TYPE,
         "'solver.sleeping.angular' must be a number, got string"},
        {"return { " MIN_BODY ", solver = { sleeping = { time = 2 } } }", CF_ERR_SCENE_KEY,
         "unknown key 'solver.sleeping.time'; allowed: linear, angular"},
        {"return { " MIN_BODY ", solver = { sleeping = { linear = 0.1 } } }", CF_ERR_SCENE_VALUE,
         "'solver.sleeping' needs linear and angular both > 0 (or both 0: no sleeping), got "
         "linear = 0.1 m/s, angular = 0 rad/s"},
        {"return { " MIN_BODY ", solver = { sleeping = { linear = 0, angular = 0.2 } } }",
         CF_ERR_SCENE_VALUE, "got linear = 0 m/s, angular = 0.2 rad/s"},
    };
    (void)state;
    for (int i = 0; i < (int)(sizeof cases / sizeof cases[0]); i++)
        expect_error(cases[i].text, NULL, 0, cases[i].code, cases[i].needle);
    /* Through an override too. */
    {
        static const char *const ov[] = {"bodies[1].hollow_layers=-2"};
        expect_error("return { " MIN_BODY " }", ov, 1, CF_ERR_SCENE_VALUE,
                     "'bodies[1].hollow_layers' must be >= 0, got -2");
    }
}

/* ---------------------------------------------------------------- sandbox */

static void test_sandbox_libraries(void **state)
{
    cf_scene s;
    (void)state;
    load_ok("local t = {'a', 'b'}; table.insert(t, 'c')\n"
            "return { name = string.format('%s%d', table.concat(t), math.floor(2.5)),\n"
            "         duration = math.pi, " MIN_BODY " }",
            NULL, 0, &s);
    assert_string_equal(s.name, "abc2");
    assert_double_equal(s.duration, M_PI, 0);
    cf_scene_free(&s);
}

static void test_sandbox_blocks(void **state)
{
    static const char *const blocked[] = {
        "io.open('/etc/passwd')", "os.exit(1)",          "dofile('x.lua')",
        "loadfile('x.lua')",      "load('return 1')",    "require('os')",
        "collectgarbage()",       "package.loadlib('x')", "debug.getinfo(1)",
    };
    char text[256];
    (void)state;
    for (int i = 0; i < (int)(sizeof blocked / sizeof blocked[0]); i++) {
        snprintf(text, sizeof text, "local x = %s\nreturn { " MIN_BODY " }", blocked[i]);
        expect_error(text, NULL, 0, CF_ERR_SCENE_SYNTAX, "scene.lua:1:");
    }
}

static int dump_writer(lua_State *L, const void *p, size_t size, void *ud)
{
    (void)L;
    return fwrite(p, 1, size, ud) != size;
}

static void test_bytecode_rejected(void **state)
{
    cf_scene s;
    cf_error e = {0};
    lua_State *L = luaL_newstate();
    FILE *f;
    (void)state;
    assert_int_equal(luaL_loadstring(L, "return { " MIN_BODY " }"), LUA_OK);
    write_file("compiled.lua", "");
    f = fopen(at("compiled.lua"), "wb");
    assert_non_null(f);
    assert_int_equal(lua_dump(L, dump_writer, f, 0), 0);
    fclose(f);
    lua_close(L);
    assert_int_equal(cf_scene_load(at("compiled.lua"), NULL, 0, mesh_dir, &s, &e),
                     CF_ERR_SCENE_SYNTAX);
    assert_non_null(strstr(e.msg, "binary chunk"));
    assert_non_null(strstr(e.msg, "compiled.lua"));
    assert_true(is_empty(&s));
}

/* ---------------------------------------------------------------- errors */

static void test_error_file_open(void **state)
{
    cf_scene s;
    cf_error e = {0};
    (void)state;
    assert_int_equal(cf_scene_load(at("missing.lua"), NULL, 0, mesh_dir, &s, &e),
                     CF_ERR_FILE_OPEN);
    assert_non_null(strstr(e.msg, "missing.lua"));
    assert_true(is_empty(&s));

    expect_error("return { bodies = { { mesh = 'nosuch' } } }", NULL, 0, CF_ERR_FILE_OPEN,
                 "bodies[1].mesh: prepared mesh 'nosuch' not found in ");
    expect_error("return { bodies = { { mesh = 'bunny_small' } } }", NULL, 0, CF_ERR_FILE_OPEN,
                 "run `cohfrac mesh /usr/share/glmark2/models/bunny.obj -o ");
    expect_error("return { bodies = { { mesh = 'cube.node' }, { mesh = 'sub/nosuch.node' } } }",
                 NULL, 0,
                 CF_ERR_FILE_OPEN, "bodies[2].mesh: mesh 'sub/nosuch.node' not found");
}

static void test_error_syntax(void **state)
{
    (void)state;
    expect_error("return {\n  name = 'x',\n  duration = = 1,\n}", NULL, 0, CF_ERR_SCENE_SYNTAX,
                 "scene.lua:3:");
    expect_error("local t = nil\n\nreturn t.x", NULL, 0, CF_ERR_SCENE_SYNTAX, "scene.lua:3:");
    expect_error("error('custom failure')", NULL, 0, CF_ERR_SCENE_SYNTAX,
                 "scene.lua:1: custom failure");
    expect_error("error({})", NULL, 0, CF_ERR_SCENE_SYNTAX, "scene.lua: (error object");
}

static void test_error_key(void **state)
{
    (void)state;
    expect_error("return { " MIN_BODY ", solver = { pbd = { k_stiffnes = 1 } } }", NULL, 0,
                 CF_ERR_SCENE_KEY,
                 "scene.lua: unknown key 'solver.pbd.k_stiffnes'; allowed: k_stiffness, "
                 "iterations, k_damping, iteration_independent (did you mean 'k_stiffness'?)");
    expect_error("return { " MIN_BODY ", gravty = {0,0,0} }", NULL, 0, CF_ERR_SCENE_KEY,
                 "unknown key 'gravty'; allowed: name, duration, gravity, material, bodies, "
                 "boundary, obstacles, solver, output");
    expect_error("return { bodies = { { mesh = 'cube.node' }, { mesh = 'cube.node', pos = {} } } }",
                 NULL, 0, CF_ERR_SCENE_KEY, "unknown key 'bodies[2].pos'");
    expect_error("return { " MIN_BODY ", material = { 1e6 } }", NULL, 0, CF_ERR_SCENE_KEY,
                 "unknown key 'material[1]'");
    expect_error("return { " MIN_BODY ", obstacles = { { type = 'plane', radius = 1 } } }", NULL,
                 0, CF_ERR_SCENE_KEY,
                 "unknown key 'obstacles[1].radius'; allowed: type, point, normal");
    expect_error("return { name = 'x' }", NULL, 0, CF_ERR_SCENE_KEY,
                 "missing required key 'bodies'");
    expect_error("return { bodies = { { scale = 2 } } }", NULL, 0, CF_ERR_SCENE_KEY,
                 "missing required key 'bodies[1].mesh'");
    expect_error("return { " MIN_BODY ", obstacles = { { center = {0,0,0} } } }", NULL, 0,
                 CF_ERR_SCENE_KEY, "missing required key 'obstacles[1].type'");
    expect_error("return { " MIN_BODY ", obstacles = { { type = 'sphere', center = {0,0,0} } } }",
                 NULL, 0, CF_ERR_SCENE_KEY, "missing required key 'obstacles[1].radius'");
}

static void test_error_type(void **state)
{
    static const struct {
        const char *body, *top, *needle;
    } cases[] = {
        {"position = 'up'", "",
         "scene.lua: 'bodies[1].position' must be a list of 3 numbers, got string"},
        {"position = {1, 2}", "", "'bodies[1].position' must be a list of 3 numbers, got a table "
                                  "of 2 entries"},
        {"velocity = {1, 'x', 3}", "", "'bodies[1].velocity' must be a list of 3 numbers, got "
                                       "string at [2]"},
        {"orientation = {1, 0, 0}", "", "'bodies[1].orientation' must be a list of 4 numbers"},
        {"scale = '2'", "", "'bodies[1].scale' must be a number, got string"},
        {"mesh = 5", "", "'bodies[1].mesh' must be a string (a mesh name or path) or a table "
                         "(a primitive), got number"},
        {"", "duration = true", "'duration' must be a number, got boolean"},
        {"", "material = 5", "'material' must be a table, got number"},
        {"", "solver = { iterations = 3, pbd = 3 }", "unknown key"},
        {"", "solver = { pbd = 3 }", "'solver.pbd' must be a table, got number"},
        {"", "solver = { pbd = { iterations = 2.5 } }",
         "'solver.pbd.iterations' must be an integer, got 2.5"},
        {"", "solver = { threads = 'all' }", "'solver.threads' must be an integer, got string"},
        {"", "solver = { rigid_backend = 1 }", "'solver.rigid_backend' must be a string"},
        {"", "obstacles = { 'floor' }", "'obstacles[1]' must be a table, got string"},
        {"", "obstacles = { type = 'plane' }", "'obstacles' must be a list of tables"},
        {"", "obstacles = { [1] = { type = 'plane' }, [3] = { type = 'plane' } }",
         "'obstacles' must be a list without holes; [2] is missing"},
        {"", "output = { file = {} }", "'output.file' must be a string, got table"},
    };
    char text[512];
    (void)state;
    for (int i = 0; i < (int)(sizeof cases / sizeof cases[0]); i++) {
        cf_status want = strcmp(cases[i].needle, "unknown key") == 0 ? CF_ERR_SCENE_KEY
                                                                      : CF_ERR_SCENE_TYPE;
        snprintf(text, sizeof text,
                 "return { bodies = { { mesh = 'cube.node'%s%s } }%s%s }",
                 *cases[i].body ? ", " : "", cases[i].body, *cases[i].top ? ", " : "",
                 cases[i].top);
        expect_error(text, NULL, 0, want, cases[i].needle);
    }
    expect_error("return 42", NULL, 0, CF_ERR_SCENE_TYPE, "the script must return a table, got "
                                                          "number");
    expect_error("return { bodies = { mesh = 'cube.node' } }", NULL, 0, CF_ERR_SCENE_TYPE,
                 "'bodies' must be a list of tables ({ {...}, {...} }), found key 'mesh'");
}

static void test_error_value(void **state)
{
    static const struct {
        const char *body, *top, *needle;
    } cases[] = {
        {"", "material = { E = 0 }", "'material.E' must be > 0, got 0"},
        {"", "material = { E = -1e6 }", "'material.E' must be > 0"},
        {"", "material = { nu = 0.5 }", "'material.nu' must be in (-1, 0.5)"},
        {"", "material = { nu = -1 }", "'material.nu' must be in (-1, 0.5)"},
        {"", "material = { rho = 0 }", "'material.rho' must be > 0"},
        {"", "material = { G_I = 0 }", "'material.G_I' must be > 0"},
        {"", "material = { G_II = -1 }", "'material.G_II' must be > 0"},
        {"", "material = { sigma_max = 0 }", "'material.sigma_max' must be > 0"},
        {"", "material = { tau_max = 0 }", "'material.tau_max' must be > 0"},
        {"", "material = { alpha = 1 }",
         "'material.alpha' must be > 1 (the PPR cohesive law needs shape parameters alpha, beta "
         "> 1), got 1"},
        {"", "material = { beta = 0.5 }", "'material.beta' must be > 1"},
        {"", "material = { friction = -0.1 }", "'material.friction' must be >= 0"},
        {"", "material = { restitution = 1.5 }", "'material.restitution' must be in [0, 1]"},
        {"", "material = { E = 0/0 }", "'material.E' must be a finite number"},
        {"", "duration = 0", "'duration' must be > 0"},
        {"", "solver = { dt_rigid = 0 }", "'solver.dt_rigid' must be > 0"},
        {"", "solver = { dt_fracture = -1e-6 }", "'solver.dt_fracture' must be > 0"},
        {"", "solver = { dt_fracture = 1e-2 }",
         "'solver.dt_fracture' must not exceed solver.dt_rigid (0.001), got 0.01"},
        {"", "solver = { dt_rigid = 1e-6 }", "'solver.dt_fracture' must not exceed"},
        {"", "solver = { rigid_substeps = 0 }", "'solver.rigid_substeps' must be in [1, 1000], got 0"},
        {"", "solver = { check_interval = 0 }", "'solver.check_interval' must be >= 1"},
        {"", "solver = { quiet_steps = 0 }", "'solver.quiet_steps' must be >= 1"},
        {"", "solver = { max_fracture_time = 0 }", "'solver.max_fracture_time' must be > 0"},
        {"", "solver = { threads = -1 }", "'solver.threads' must be >= 0"},
        {"", "solver = { threads = 1e10 }", "'solver.threads' is out of range"},
        {"", "solver = { pbd = { k_stiffness = 1.5 } }",
         "'solver.pbd.k_stiffness' must be in [0, 1], got 1.5"},
        {"", "solver = { pbd = { k_damping = -0.1 } }", "'solver.pbd.k_damping' must be in [0, 1]"},
        {"", "solver = { pbd = { iterations = 0 } }", "'solver.pbd.iterations' must be in [1, 1000], got 0"},
        {"", "solver = { rigid_backend = 'bulet' }",
         "'solver.rigid_backend' is \"bulet\"; allowed: bullet, pbd (did you mean 'bullet'?)"},
        {"", "solver = { elasticity = 'neo' }",
         "'solver.elasticity' is \"neo\"; allowed: corotational, linear"},
        {"", "output = { frame_interval = 0 }", "'output.frame_interval' must be > 0"},
        {"", "name = ''", "'name' must not be empty"},
        {"", "name = string.rep('n', 200)", "'name' is too long"},
        {"", "name = 'a\\0b'", "'name' must not contain NUL bytes"},
        {"", "obstacles = { { type = 'cylinder' } }",
         "'obstacles[1].type' is \"cylinder\"; allowed: plane, sphere, box"},
        {"", "obstacles = { { type = 'sphere', center = {0,0,0}, radius = 0 } }",
         "'obstacles[1].radius' must be > 0"},
        {"", "obstacles = { { type = 'box', center = {0,0,0}, half_extents = {1, 0, 1} } }",
         "'obstacles[1].half_extents' must have every component > 0"},
        {"", "obstacles = { { type = 'plane', normal = {0, 0, 0} } }",
         "'obstacles[1].normal' must be a non-zero vector"},
        {"", "bodies = { { mesh = 'cube.node' }, { mesh = 'cube.node', orientation = {0,0,0,0} } }",
         "'bodies[2].orientation' must be a non-zero quaternion"},
        {"scale = 0", "", "'bodies[1].scale' must be > 0"},
        {"position = {0, 1/0, 0}", "", "'bodies[1].position' must hold finite numbers"},
        {"mesh = ''", "", "'bodies[1].mesh' must not be empty"},
    };
    char text[512];
    (void)state;
    for (int i = 0; i < (int)(sizeof cases / sizeof cases[0]); i++) {
        /* A case that sets bodies itself replaces the default one. */
        if (strncmp(cases[i].top, "bodies", 6) == 0)
            snprintf(text, sizeof text, "return { %s }", cases[i].top);
        else
            snprintf(text, sizeof text, "return { bodies = { { mesh = 'cube.node'%s%s } }%s%s }",
                     *cases[i].body ? ", " : "", cases[i].body, *cases[i].top ? ", " : "",
                     cases[i].top);
        expect_error(text, NULL, 0, CF_ERR_SCENE_VALUE, cases[i].needle);
    }
    expect_error("return { bodies = {} }", NULL, 0, CF_ERR_SCENE_VALUE, "'bodies' is empty");
}

/* One case per new kind of error; `text` is the whole scene and every
 * needle names the key path. */
#define FRACTURE "solver = { mode = 'fracture' }"
#define PRIM(m) "return { bodies = { { mesh = " m " } } }"
#define BOUNDARY(b) "return { " MIN_BODY ", boundary = { " b " }, " FRACTURE " }"
#define ZBOX "region = { type = 'box', min = {0,0,0}, max = {1,1,1} }"

static void test_error_new_keys(void **state)
{
    static const struct {
        const char *text;
        cf_status code;
        const char *needle;
    } cases[] = {
        /* primitives */
        {PRIM("{ type = 'cone' }"), CF_ERR_SCENE_VALUE,
         "'bodies[1].mesh.type' is \"cone\"; allowed: box, sphere, hollow_sphere, plate, "
         "notched_beam"},
        {PRIM("{ radius = 1 }"), CF_ERR_SCENE_KEY, "missing required key 'bodies[1].mesh.type'"},
        {PRIM("{ type = 'sphere', radiuss = 1, mesh_size = 0.1 }"), CF_ERR_SCENE_KEY,
         "unknown key 'bodies[1].mesh.radiuss'; allowed: type, radius, mesh_size (did you mean "
         "'radius'?)"},
        {PRIM("{ type = 'box', size = {1,1,1}, radius = 1 }"), CF_ERR_SCENE_KEY,
         "unknown key 'bodies[1].mesh.radius'; allowed: type, size, cells, tets_per_cell"},
        {PRIM("{ type = 'sphere', radius = 1 }"), CF_ERR_SCENE_KEY,
         "missing required key 'bodies[1].mesh.mesh_size'"},
        {PRIM("{ type = 'box' }"), CF_ERR_SCENE_KEY, "missing required key 'bodies[1].mesh.size'"},
        {PRIM("{ type = 'notched_beam', size = {2, 0.1, 0.2}, mesh_size = 0.01 }"),
         CF_ERR_SCENE_KEY, "missing required key 'bodies[1].mesh.notch'"},
        {PRIM("{ type = 'box', size = {1,1,1}, tets_per_cell = 4 }"), CF_ERR_SCENE_VALUE,
         "'bodies[1].mesh.tets_per_cell' must be 5 or 6, got 4"},
        {PRIM("{ type = 'box', size = {1,1,1}, tets_per_cell = 5.5 }"), CF_ERR_SCENE_TYPE,
         "'bodies[1].mesh.tets_per_cell' must be an integer, got 5.5"},
        {PRIM("{ type = 'box', size = {1,0,1} }"), CF_ERR_SCENE_VALUE,
         "'bodies[1].mesh.size' must have every component > 0, got {1, 0, 1}"},
        {PRIM("{ type = 'box', size = {1,1,1}, cells = {1, 0, 1} }"), CF_ERR_SCENE_VALUE,
         "'bodies[1].mesh.cells' must hold integers in [1, "},
        {PRIM("{ type = 'box', size = {1,1,1}, cells = {1, 2.5, 1} }"), CF_ERR_SCENE_TYPE,
         "'bodies[1].mesh.cells' must be a list of 3 integers, got 2.5 at [2]"},
        {PRIM("{ type = 'box', size = {1,1,1}, cells = {2000, 2000, 2000} }"), CF_ERR_SCENE_VALUE,
         "'bodies[1].mesh.cells' = {2000, 2000, 2000} gives"},
        {PRIM("{ type = 'sphere', radius = 0, mesh_size = 0.1 }"), CF_ERR_SCENE_VALUE,
         "'bodies[1].mesh.radius' must be > 0, got 0"},
        {PRIM("{ type = 'hollow_sphere', radius = 0.5, thickness = 0.5, mesh_size = 0.1 }"),
         CF_ERR_SCENE_VALUE, "'bodies[1].mesh.thickness' must be < radius (0.5)"},
        {PRIM("{ type = 'hollow_sphere', radius = 0.5, thickness = 0.7, mesh_size = 0.1 }"),
         CF_ERR_SCENE_VALUE, "got 0.7"},
        {PRIM("{ type = 'plate', size = {1,1,0.1}, mesh_size = -1 }"), CF_ERR_SCENE_VALUE,
         "'bodies[1].mesh.mesh_size' must be > 0"},
        {PRIM("{ type = 'notched_beam', size = {2, 0.1, 0.2}, notch = {0.2, 0.02, 0},"
              " mesh_size = 0.01 }"),
         CF_ERR_SCENE_VALUE,
         "'bodies[1].mesh.notch' depth (notch[1]) must be in (0, 0.2), less than the beam "
         "height size[3], got 0.2"},
        {PRIM("{ type = 'notched_beam', size = {2, 0.1, 0.2}, notch = {0.1, 0, 0},"
              " mesh_size = 0.01 }"),
         CF_ERR_SCENE_VALUE, "'bodies[1].mesh.notch' width (notch[2]) must be > 0"},
        {PRIM("{ type = 'notched_beam', size = {2, 0.1, 0.2}, notch = {0.1, 0.2, -0.95},"
              " mesh_size = 0.01 }"),
         CF_ERR_SCENE_VALUE, "'bodies[1].mesh.notch' must lie inside the beam length"},
        {PRIM("true"), CF_ERR_SCENE_TYPE,
         "'bodies[1].mesh' must be a string (a mesh name or path) or a table"},
        {PRIM("'nosuch.msh'"), CF_ERR_FILE_OPEN,
         "bodies[1].mesh: Gmsh mesh 'nosuch.msh' not found: no file "},
        /* expansion */
        {"return { bodies = { { mesh = 'cube.node', expansion_rate = 'fast' } } }",
         CF_ERR_SCENE_TYPE,
         "'bodies[1].expansion_rate' must be a number or a list of 3 numbers, got string"},
        {"return { bodies = { { mesh = 'cube.node', expansion_rate = {1, 2} } } }",
         CF_ERR_SCENE_TYPE, "'bodies[1].expansion_rate' must be a list of 3 numbers"},
        {"return { bodies = { { mesh = 'cube.node', expansion_rate = 1/0 } } }",
         CF_ERR_SCENE_VALUE, "'bodies[1].expansion_rate' must be a finite number"},
        {"return { bodies = { { mesh = 'cube.node', expansion_center = 0 } } }",
         CF_ERR_SCENE_TYPE, "'bodies[1].expansion_center' must be a list of 3 numbers"},
        /* boundary */
        {BOUNDARY("{ " ZBOX ", velocity = {0,0,1}, fixed = true }"), CF_ERR_SCENE_VALUE,
         "'boundary[1]' gives both 'velocity' and 'fixed = true'; give one of them"},
        {BOUNDARY("{ " ZBOX " }"), CF_ERR_SCENE_KEY,
         "missing required key 'boundary[1].velocity' (or 'fixed = true')"},
        {BOUNDARY("{ " ZBOX ", fixed = false }"), CF_ERR_SCENE_KEY,
         "missing required key 'boundary[1].velocity'"},
        {BOUNDARY("{ " ZBOX ", fixed = 1 }"), CF_ERR_SCENE_TYPE,
         "'boundary[1].fixed' must be a boolean (true or false), got number"},
        {BOUNDARY("{ " ZBOX ", fixed = true, axes = 'xx' }"), CF_ERR_SCENE_VALUE,
         "'boundary[1].axes' is \"xx\"; allowed: distinct letters from \"xyz\""},
        {BOUNDARY("{ " ZBOX ", fixed = true, axes = 'w' }"), CF_ERR_SCENE_VALUE,
         "'boundary[1].axes' is \"w\""},
        {BOUNDARY("{ " ZBOX ", fixed = true, axes = '' }"), CF_ERR_SCENE_VALUE,
         "'boundary[1].axes' must not be empty"},
        {BOUNDARY("{ " ZBOX ", fixed = true, body = 2 }"), CF_ERR_SCENE_VALUE,
         "'boundary[1].body' must be in [1, 1] (a 1-based index into bodies), got 2"},
        {BOUNDARY("{ " ZBOX ", fixed = true, body = 0 }"), CF_ERR_SCENE_VALUE,
         "'boundary[1].body' must be in [1, 1]"},
        {BOUNDARY("{ " ZBOX ", fixed = true }, { " ZBOX ", fixed = true, body = 1.5 }"),
         CF_ERR_SCENE_TYPE, "'boundary[2].body' must be an integer, got 1.5"},
        {"return { " MIN_BODY ", boundary = { { " ZBOX ", fixed = true } } }", CF_ERR_SCENE_VALUE,
         "'boundary' has 1 entry but solver.mode is \"hybrid\": boundary conditions need "
         "solver.mode = \"fracture\""},
        {BOUNDARY("{ fixed = true }"), CF_ERR_SCENE_KEY,
         "missing required key 'boundary[1].region'"},
        {BOUNDARY("{ region = 'top', fixed = true }"), CF_ERR_SCENE_TYPE,
         "'boundary[1].region' must be a table, got string"},
        {BOUNDARY("{ region = { type = 'cylinder' }, fixed = true }"), CF_ERR_SCENE_VALUE,
         "'boundary[1].region.type' is \"cylinder\"; allowed: box, plane, group"},
        {BOUNDARY("{ " ZBOX ", fixed = true, vel = {0,0,0} }"), CF_ERR_SCENE_KEY,
         "unknown key 'boundary[1].vel'; allowed: region, velocity, fixed, axes, body"},
        {BOUNDARY("{ region = { type = 'group', name = 'g', normal = {0,0,1} }, fixed = true }"),
         CF_ERR_SCENE_KEY, "unknown key 'boundary[1].region.normal'; allowed: type, name"},
        {BOUNDARY("{ region = { type = 'box', min = {0,0,0}, max = {1,0,1} }, fixed = true }"),
         CF_ERR_SCENE_VALUE,
         "'boundary[1].region.max' must exceed min in every component, got max[2] = 0 <= "
         "min[2] = 0"},
        {BOUNDARY("{ region = { type = 'box', min = {0,0,0} }, fixed = true }"), CF_ERR_SCENE_KEY,
         "missing required key 'boundary[1].region.max'"},
        {BOUNDARY("{ region = { type = 'plane', point = {0,0,0}, normal = {0,0,0} },"
                  " fixed = true }"),
         CF_ERR_SCENE_VALUE, "'boundary[1].region.normal' must be a non-zero vector"},
        {BOUNDARY("{ region = { type = 'plane', point = {0,0,0}, normal = {0,0,1},"
                  " tolerance = 0 }, fixed = true }"),
         CF_ERR_SCENE_VALUE, "'boundary[1].region.tolerance' must be > 0"},
        {BOUNDARY("{ region = { type = 'group', name = string.rep('g', 64) }, fixed = true }"),
         CF_ERR_SCENE_VALUE, "'boundary[1].region.name' is too long (64 bytes, at most 63)"},
        {BOUNDARY("{ region = { type = 'group' }, fixed = true }"), CF_ERR_SCENE_KEY,
         "missing required key 'boundary[1].region.name'"},
        /* solver */
        {"return { " MIN_BODY ", solver = { mode = 'rigid' } }", CF_ERR_SCENE_VALUE,
         "'solver.mode' is \"rigid\"; allowed: hybrid, fracture"},
        {"return { " MIN_BODY ", solver = { criterion = 'stress' } }", CF_ERR_SCENE_VALUE,
         "'solver.criterion' is \"stress\"; allowed: traction, source, none"},
        {"return { " MIN_BODY ", solver = { constraints = 'pdb' } }", CF_ERR_SCENE_VALUE,
         "'solver.constraints' is \"pdb\"; allowed: pbd, xpbd, none (did you mean 'pbd'?)"},
        {"return { " MIN_BODY ", solver = { crack_plane = { point = {0,0,0}, normal = {0,0,0} } } }",
         CF_ERR_SCENE_VALUE, "'solver.crack_plane.normal' must be a non-zero vector, got all zeros"},
        {"return { " MIN_BODY ", solver = { crack_plane = { point = {0,0,0} } } }", CF_ERR_SCENE_KEY,
         "missing required key 'solver.crack_plane.normal'"},
        {"return { " MIN_BODY ", solver = { crack_plane = { point = {0,0,0}, normal = {0,0,1},"
         " tol = 1 } } }",
         CF_ERR_SCENE_KEY, "unknown key 'solver.crack_plane.tol'; allowed: point, normal, tolerance"},
        {"return { " MIN_BODY ", solver = { crack_plane = true } }", CF_ERR_SCENE_TYPE,
         "'solver.crack_plane' must be a table, got boolean"},
        {"return { " MIN_BODY ", solver = { pbd = { iteration_independent = 1 } } }",
         CF_ERR_SCENE_TYPE, "'solver.pbd.iteration_independent' must be a boolean"},
        {"return { " MIN_BODY ", solver = { xpbd = { compliance_scale = 0 } } }",
         CF_ERR_SCENE_VALUE, "'solver.xpbd.compliance_scale' must be > 0, got 0"},
        {"return { " MIN_BODY ", solver = { xpbd = { compliance = 1 } } }", CF_ERR_SCENE_KEY,
         "unknown key 'solver.xpbd.compliance'"},
        {"return { " MIN_BODY ", solver = { contact_stiffness = -1 } }", CF_ERR_SCENE_VALUE,
         "'solver.contact_stiffness' must be >= 0, got -1"},
        {"return { " MIN_BODY ", solver = { guard = { max_inverted_fraction = 1.5 } } }",
         CF_ERR_SCENE_VALUE, "'solver.guard.max_inverted_fraction' must be in [0, 1], got 1.5"},
        {"return { " MIN_BODY ", solver = { guard = { max_energy_growth = 0 } } }",
         CF_ERR_SCENE_VALUE, "'solver.guard.max_energy_growth' must be > 0, got 0"},
        {"return { " MIN_BODY ", solver = { guard = { max_inverted = 0.1 } } }", CF_ERR_SCENE_KEY,
         "unknown key 'solver.guard.max_inverted'; allowed: max_inverted_fraction, "
         "max_energy_growth"},
        {"return { " MIN_BODY ", output = { file = 5 } }", CF_ERR_SCENE_TYPE,
         "'output.file' must be a string, got number"},
    };
    (void)state;
    for (int i = 0; i < (int)(sizeof cases / sizeof cases[0]); i++)
        expect_error(cases[i].text, NULL, 0, cases[i].code, cases[i].needle);
}

static void test_error_override(void **state)
{
    static const struct {
        const char *ov, *needle;
    } cases[] = {
        {"solver.dt_rigid", "bad override 'solver.dt_rigid': expected key.path=value"},
        {"=1", "bad override '=1': empty key path"},
        {"  =1", "empty key path"},
        {"solver..dt_rigid=1", "bad override 'solver..dt_rigid=1': expected a key name"},
        {"solver.=1", "expected a key name"},
        {"bodies[0].scale=1", "bad override 'bodies[0].scale=1': bad list index"},
        {"bodies[x].scale=1", "bad list index"},
        {"bodies[].scale=1", "bad list index"},
        {"bodies[1.scale=1", "bad list index"},
        {"bodies[99999999999].scale=1", "bad list index"},
        {"bodies[1]x=1", "unexpected 'x' in the key path"},
        {"solver.dt_rigid=", "bad override 'solver.dt_rigid=': no value after '='"},
        {"solver.dt_rigid=1e-", "bad override 'solver.dt_rigid=1e-': the value does not parse"},
        {"gravity={0,0,", "the value does not parse"},
        {"solver.dt_rigid=1 2", "the value does not parse"},
        {"name=drop", "bad override 'name=drop': the value is nil"},
        {"name=nosuch.field", "the value fails"},
        {"name=io.open('x')", "the value fails"},
        {"name.first='x'", "bad override 'name.first='x'': part 1 of the key path is a string"},
    };
    (void)state;
    for (int i = 0; i < (int)(sizeof cases / sizeof cases[0]); i++)
        expect_error("return { name = 'n', " MIN_BODY " }", &cases[i].ov, 1,
                     CF_ERR_SCENE_OVERRIDE, cases[i].needle);
    /* A well-formed override is still validated like the script. */
    {
        static const char *const ov[] = {"solver.pbd.k_stiffnes=1"};
        expect_error("return { " MIN_BODY " }", ov, 1, CF_ERR_SCENE_KEY,
                     "unknown key 'solver.pbd.k_stiffnes'");
    }
}

/* A NULL error record is allowed; the scene still comes back empty. */
static void test_error_without_record(void **state)
{
    cf_scene s;
    (void)state;
    write_file("scene.lua", "return { }");
    assert_int_equal(cf_scene_load(at("scene.lua"), NULL, 0, mesh_dir, &s, NULL),
                     CF_ERR_SCENE_KEY);
    assert_true(is_empty(&s));
    cf_scene_free(&s);
    cf_scene_free(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_minimal),  cmocka_unit_test(test_full_scene),
        cmocka_unit_test(test_derived_defaults),  cmocka_unit_test(test_mesh_paths),
        cmocka_unit_test(test_prepared_mesh),     cmocka_unit_test(test_overrides),
        cmocka_unit_test(test_round_trip),        cmocka_unit_test(test_sandbox_libraries),
        cmocka_unit_test(test_sandbox_blocks),    cmocka_unit_test(test_bytecode_rejected),
        cmocka_unit_test(test_error_file_open),   cmocka_unit_test(test_error_syntax),
        cmocka_unit_test(test_error_key),         cmocka_unit_test(test_error_type),
        cmocka_unit_test(test_error_value),       cmocka_unit_test(test_error_override),
        cmocka_unit_test(test_error_without_record), cmocka_unit_test(test_new_keys),
        cmocka_unit_test(test_new_defaults),      cmocka_unit_test(test_error_new_keys),
        cmocka_unit_test(test_shell_obstacle_keys),
        cmocka_unit_test(test_error_shell_obstacle_keys),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
