/* The engine through its C API, without Lua: a world built from
 * cf_default_*() and a box mesh made in code steps to the same state, bit
 * for bit, as the same scene loaded from Lua (so the defaults are the
 * schema's and the loader only fills the structs); the world keeps its own
 * copy of the definition; cf_world_def_check rejects bad values with the
 * loader's codes and key paths; events and queries report what happened. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "cohfrac/mesh.h"
#include "cohfrac/scene.h"
#include "cohfrac/sim.h"
#include "cohfrac/version.h"
#include "cohfrac/world.h"
#include "check.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char lua_scene[] =
    "return { name = 'api', duration = 0.5,\n"
    "  material = { E = 1e5, sigma_max = 3e3 },\n"
    "  bodies = { { mesh = { type = 'box', size = {0.2, 0.2, 0.2}, cells = {3, 3, 3} },\n"
    "               position = {0, 0, 1} } },\n"
    "  obstacles = { { type = 'plane' } },\n"
    "  solver = { constraints = 'xpbd', threads = 1 },\n"
    "  output = { file = '' } }\n";

/* The same scene as lua_scene, built in C; *box receives the mesh. */
/* s of simulated time, the Lua scene's duration */
#define API_DURATION 0.5

static cf_world_def api_scene(cf_mesh *box, cf_body_def *body, cf_obstacle *ground)
{
    const double size[3] = {0.2, 0.2, 0.2};
    const int cells[3] = {3, 3, 3};
    cf_error err = {0};
    if (cf_mesh_box(size, cells, 6, box, &err) != CF_OK)
        fail_msg("box: %s", err.msg);
    cf_world_def def = cf_default_world_def();
    def.material.E = 1e5;
    def.material.sigma_max = def.material.tau_max = 3e3;
    def.solver.constraints = CF_CONSTRAINTS_XPBD;
    def.solver.threads = 1;
    *body = cf_default_body();
    body->tet_mesh = box;
    body->position[2] = 1.0;
    *ground = cf_default_obstacle(CF_OBSTACLE_PLANE);
    def.bodies = body, def.n_bodies = 1;
    def.obstacles = ground, def.n_obstacles = 1;
    return def;
}

static void test_api_world_equals_lua_scene(void **state)
{
    (void)state;
    cf_error err = {0};
    cf_mesh box;
    cf_body_def body;
    cf_obstacle ground;
    cf_world_def def = api_scene(&box, &body, &ground);
    cf_world *w = NULL;
    assert_int_equal(cf_world_create(&def, &w, &err), CF_OK);
    /* The world keeps its own copy: the caller's definition and mesh go. */
    cf_mesh_free(&box);
    memset(&ground, 0xff, sizeof ground);
    int handoffs = 0, born = 0, inserted = 0;
    /* As the run loop steps it: ceil(duration / dt) regular steps. */
    double dt = cf_world_dt_outer(w);
    long n_steps = lround(ceil(API_DURATION / dt - 1e-9));
    while (cf_world_step_count(w) < n_steps) {
        assert_int_equal(cf_world_step(w, dt, &err), CF_OK);
        int n;
        const cf_event *ev = cf_world_events(w, &n);
        for (int i = 0; i < n; i++) {
            handoffs += ev[i].type == CF_EVENT_HANDOFF;
            born += ev[i].type == CF_EVENT_FRAGMENTS ? ev[i].count : 0;
            inserted += ev[i].type == CF_EVENT_INSERTIONS ? ev[i].count : 0;
        }
        cf_world_clear_events(w);
    }
    uint64_t h_api = cf_world_state_hash(w);
    int alive = cf_world_fragments(w, NULL, 0);
    /* Every cohesive element was announced once; every fragment too (the
     * initial body at create, drained here with the first step's). */
    assert_int_equal(inserted, cf_world_cohesive_count(w));
    cf_crack_row row;
    assert_true(inserted > 0);
    for (int e = 0; e < inserted; e++) { /* each lies on the face its two tets share */
        assert_int_equal(cf_world_crack(w, e, &row), 0);
        int a[4], b[4], shared = 0;
        assert_int_equal(cf_world_rest_tet(w, row.tets[0], a), 0);
        assert_int_equal(cf_world_rest_tet(w, row.tets[1], b), 0);
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++)
                shared += a[i] == b[j];
        assert_int_equal(shared, 3);
    }
    assert_int_equal(cf_world_crack(w, inserted, &row), -1); /* past the end: refused */
    assert_int_equal(cf_world_crack(w, -1, &row), -1);
    assert_true(row.area == 0 && row.element == 0);
    assert_string_equal(cf_version(), COHFRAC_VERSION_STRING);
    assert_int_equal(born, cf_world_fragments_ever(w));
    assert_true(handoffs >= 2); /* rigid -> fracture -> rigid */
    assert_true(fabs(cf_world_time(w) - 0.5) < 1e-12);
    /* Tet corners follow each fragment's pose: the volume-weighted centre
     * of a fragment's tets is its centre of mass (lumped masses, uniform
     * density), to round-off. */
    int ever = cf_world_fragments_ever(w);
    double *acc = calloc((size_t)ever * 4, sizeof(double)), x[12];
    for (int t = 0; t < cf_world_tet_count(w); t++) {
        assert_int_equal(cf_world_tet_positions(w, t, x), 0);
        double a[3], b[3], c[3], vol;
        for (int k = 0; k < 3; k++)
            a[k] = x[3 + k] - x[k], b[k] = x[6 + k] - x[k], c[k] = x[9 + k] - x[k];
        vol = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
        assert_true(vol > 0);
        double *s = &acc[4 * cf_world_tet_fragment(w, t)];
        for (int k = 0; k < 3; k++)
            s[k] += vol * 0.25 * (x[k] + x[3 + k] + x[6 + k] + x[9 + k]);
        s[3] += vol;
    }
    cf_fragment_state fs[64];
    int nf = cf_world_fragments(w, fs, 64);
    for (int i = 0; i < nf && i < 64; i++)
        for (int k = 0; k < 3; k++)
            assert_near(acc[4 * fs[i].id + k] / acc[4 * fs[i].id + 3], fs[i].com[k], 1e-9);
    free(acc);
    assert_int_equal(cf_world_tet_positions(w, -1, x), -1);
    cf_world_destroy(w);

    cf_scene sc;
    cf_sim *sim = NULL;
    assert_int_equal(cf_scene_load_text("api.lua", lua_scene, NULL, 0, COHFRAC_MESH_DIR, &sc, &err),
                     CF_OK);
    cf_run_options opt = {.mesh_dir = COHFRAC_MESH_DIR};
    assert_int_equal(cf_sim_create(&sc, &opt, &sim, &err), CF_OK);
    while (!cf_sim_done(sim))
        assert_int_equal(cf_sim_advance(sim, &err), CF_OK);
    uint64_t h_lua = cf_world_state_hash(cf_sim_world(sim));
    printf("FIGURE api world: %d fragments alive, %d cohesive elements, %d hand-offs, hash "
           "%016llx (API) %016llx (Lua)\n",
           alive, inserted, handoffs, (unsigned long long)h_api, (unsigned long long)h_lua);
    assert_true(h_api == h_lua);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

/* Each bad value: the code and the key path the scene loader would give. */
static void test_check_names_the_key(void **state)
{
    (void)state;
    cf_mesh box;
    cf_body_def body;
    cf_obstacle ground;
    const struct {
        const char *key;
        cf_status code;
    } cases[] = {
        {"solver.dt_rigid", CF_ERR_SCENE_VALUE},   {"material.nu", CF_ERR_SCENE_VALUE},
        {"bodies[1].scale", CF_ERR_SCENE_VALUE},   {"bodies[1].tet_mesh", CF_ERR_SCENE_VALUE},
        {"obstacles[1].normal", CF_ERR_SCENE_VALUE}, {"solver.pbd.iterations", CF_ERR_SCENE_VALUE},
        {"solver.dt_fracture", CF_ERR_SCENE_VALUE}, {"bodies", CF_ERR_SCENE_VALUE},
        /* each obstacle kind checks its own parameters (obstacle_<type>.c) */
        {"obstacles[1].radius", CF_ERR_SCENE_VALUE},
        {"obstacles[1].half_extents", CF_ERR_SCENE_VALUE},
        {"obstacles[1]", CF_ERR_SCENE_VALUE},
        {"obstacles[1].type", CF_ERR_SCENE_VALUE},
        {"obstacles[1].friction", CF_ERR_SCENE_VALUE},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cf_world_def def = api_scene(&box, &body, &ground);
        switch (i) {
        case 0: def.solver.dt_rigid = -1e-3; break;
        case 1: def.material.nu = 0.5; break;
        case 2: body.scale = 0; break;
        case 3: body.tet_mesh = NULL; break;
        case 4: ground.normal[2] = 2; break;
        case 5: def.solver.iterations = 0; break;
        case 6: def.solver.dt_fracture = 1; break;
        case 7: def.n_bodies = 0; break;
        case 8: ground = cf_default_obstacle(CF_OBSTACLE_SPHERE); break; /* radius 0 */
        case 9: ground = cf_default_obstacle(CF_OBSTACLE_BOX); break;    /* half-extents 0 */
        case 10: ground = cf_default_obstacle(CF_OBSTACLE_MESH); break;  /* no triangle */
        case 11: ground.type = (cf_obstacle_type)CF_OBSTACLE_TYPE_COUNT; break;
        case 12: ground.friction = -1; break;
        }
        cf_error err = {0};
        cf_world *w = (cf_world *)&err; /* must come back NULL */
        assert_int_equal(cf_world_create(&def, &w, &err), cases[i].code);
        assert_null(w);
        char quoted[64];
        snprintf(quoted, sizeof quoted, "'%s'", cases[i].key);
        if (!strstr(err.msg, quoted))
            fail_msg("case %zu: \"%s\" does not name %s", i, err.msg, quoted);
        cf_mesh_free(&box);
    }
}

static void record_threads(void *user, double t)
{
    (void)t;
    *(int *)user = omp_get_max_threads();
}

/* Each world runs its loops on its own thread count, and neither creating
 * nor stepping one changes the caller's OpenMP setting or another world's. */
static void test_threads_are_the_worlds(void **state)
{
    (void)state;
    cf_mesh box[2];
    cf_body_def body[2];
    cf_obstacle ground[2];
    cf_world *w[2] = {NULL, NULL};
    int seen[2] = {0, 0};
    omp_set_num_threads(3);
    for (int i = 0; i < 2; i++) {
        cf_world_def def = api_scene(&box[i], &body[i], &ground[i]);
        def.solver.mode = CF_RUN_FRACTURE; /* every step ticks from inside */
        def.solver.constraints = CF_CONSTRAINTS_NONE;
        def.solver.cfl_fraction = 0.5;
        def.solver.threads = i == 0 ? 1 : 0; /* 0: the caller's setting, 3 */
        cf_error err = {0};
        assert_int_equal(cf_world_create(&def, &w[i], &err), CF_OK);
        assert_int_equal(omp_get_max_threads(), 3);
        cf_world_set_tick(w[i], record_threads, &seen[i]);
    }
    cf_world_set_threads(w[1], 2);
    for (int k = 0; k < 2; k++)
        for (int i = 0; i < 2; i++) {
            cf_error err = {0};
            assert_int_equal(cf_world_step(w[i], cf_world_dt_outer(w[i]), &err), CF_OK);
            assert_int_equal(omp_get_max_threads(), 3);
        }
    assert_int_equal(seen[0], 1);
    assert_int_equal(seen[1], 2);
    cf_world_stats ws;
    cf_world_stats_get(w[0], &ws);
    assert_int_equal(ws.threads, 1);
    assert_true(cf_world_state_hash(w[0]) == cf_world_state_hash(w[1]));
    for (int i = 0; i < 2; i++) {
        cf_world_destroy(w[i]);
        cf_mesh_free(&box[i]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_api_world_equals_lua_scene),
        cmocka_unit_test(test_check_names_the_key),
        cmocka_unit_test(test_threads_are_the_worlds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
