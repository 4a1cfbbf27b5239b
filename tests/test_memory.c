/* A scene pays only for what it uses: the engine's memory accounting
 * (cf_sim_memory) shows no Bullet world, fracture state, cohesive arrays,
 * FCL mesh or output for a scene that needs none of them, and each of
 * them once the scene asks for it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "cohfrac/scene.h"
#include "cohfrac/sim.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define BOUNCE COHFRAC_SOURCE_DIR "/scenes/compare/bounce.lua"

/* Run 20 ms of the bounce scene (a box falling onto a plane) with the
 * overrides and return its memory accounting at the end. */
static cf_memory run(const char **sets, int n)
{
    const char *all[8] = {"duration=0.02", "output.frame_interval=0.01"};
    memcpy(&all[2], sets, (size_t)n * sizeof *sets);
    cf_scene sc;
    cf_error err = {0};
    if (cf_scene_load(BOUNCE, all, n + 2, COHFRAC_MESH_DIR, &sc, &err) != CF_OK)
        fail_msg("scene: %s", err.msg);
    cf_run_options opt = {.mesh_dir = COHFRAC_MESH_DIR, .threads = 1};
    cf_sim *sim = NULL;
    if (cf_sim_create(&sc, &opt, &sim, &err) != CF_OK || cf_sim_run(sim, &err) != CF_OK)
        fail_msg("run: %s", err.msg);
    cf_memory m;
    cf_sim_memory(sim, &m);
    printf("FIGURE %s %s: solid %llu, fracture %llu, cohesive %llu, fragments %llu, bullet %llu, "
           "collision %llu, output %llu bytes\n",
           n > 0 ? sets[0] : "", n > 1 ? sets[1] : "", m.solid, m.fracture, m.cohesive,
           m.fragments, m.bullet, m.collision, m.output);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    return m;
}

static void test_rigid_pbd_scene_allocates_nothing_else(void **state)
{
    (void)state;
    const char *sets[] = {"solver.rigid_backend=\"pbd\"", "output.file=\"\""};
    cf_memory m = run(sets, 2);
    assert_true(m.solid > 0 && m.fragments > 0);
    assert_true(m.fracture == 0); /* criterion "none": no facets */
    assert_true(m.cohesive == 0);
    assert_true(m.bullet == 0);   /* measured by the allocator hook */
    assert_true(m.collision == 0);
    assert_true(m.output == 0);
}

static void test_each_subsystem_when_asked_for(void **state)
{
    (void)state;
    char dir[512], off[600], h5[600], obstacle[800];
    snprintf(dir, sizeof dir, "%s/memory_XXXXXX", COHFRAC_BINARY_DIR);
    assert_non_null(mkdtemp(dir));
    snprintf(h5, sizeof h5, "output.file=\"%s/out.h5\"", dir);
    const char *bullet[] = {"solver.rigid_backend=\"bullet\"", "solver.criterion=\"traction\"",
                            h5};
    cf_memory m = run(bullet, 3);
    assert_true(m.bullet > 0);
    assert_true(m.fracture > 0);
    assert_true(m.output > 0);
    assert_true(m.collision == 0);

    /* A closed tetrahedron below the box as a mesh obstacle (FCL). */
    snprintf(off, sizeof off, "%s/tet.off", dir);
    FILE *f = fopen(off, "w");
    assert_non_null(f);
    fputs("OFF\n4 4 0\n-1 -1 -0.5\n1 -1 -0.5\n0 1 -0.5\n0 0 0.1\n"
          "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n", f);
    fclose(f);
    snprintf(obstacle, sizeof obstacle, "obstacles[2]={type=\"mesh\", file=\"%s\"}", off);
    const char *mesh[] = {"solver.rigid_backend=\"pbd\"", "output.file=\"\"", obstacle};
    m = run(mesh, 3);
    assert_true(m.collision > 0);
    assert_true(m.bullet == 0);
    assert_true(m.fracture == 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rigid_pbd_scene_allocates_nothing_else),
        cmocka_unit_test(test_each_subsystem_when_asked_for),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
