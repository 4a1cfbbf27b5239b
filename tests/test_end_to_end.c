/* End to end on the small bunny: the source's bunny drop (Fig 6.3
 * parameters, a 1 m fall) falls in Bullet, breaks in fracture mode into
 * >= 2 fragments,
 * and every hand-off conserves linear momentum to 1e-9.  The HDF5 file it
 * writes is checked further by tools/check_run.py (free fall, datasets). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "check.h"
#include "world_impl.h"

#include <stdio.h>

static void test_small_bunny_drop_breaks(void **state)
{
    (void)state;
    const char *sets[] = {
        "bodies[1].mesh=\"bunny_small\"",
        "duration=0.6",
        "output.file=\"" COHFRAC_BINARY_DIR "/e2e/bunny_small_drop.h5\"",
    };
    cf_world_def sc;
    cf_error err = {0};
    cf_status st = cf_scene_load(COHFRAC_SOURCE_DIR "/scenes/bunny_drop.lua", sets, 3,
                                 COHFRAC_MESH_DIR, &sc, &err);
    if (st != CF_OK)
        fail_msg("%s", err.msg);
    cf_run_options opt = {.progress = 1, .mesh_dir = COHFRAC_MESH_DIR};
    cf_sim *sim = NULL;
    st = cf_sim_create(&sc, &opt, &sim, &err);
    if (st == CF_OK)
        st = cf_sim_run(sim, &err);
    if (st != CF_OK)
        fail_msg("%s", err.msg);
    cf_sim_print_summary(sim, stdout);
    int alive = 0;
    for (int i = 0; i < cf_sim_world(sim)->n_frag; i++)
        alive += cf_sim_world(sim)->frag[i].mode != CF_MODE_DEAD;
    assert_true(alive >= 2);
    assert_true(cf_sim_world(sim)->solid.n_coh > 0);
    assert_true(cf_sim_world(sim)->n_handoffs >= 2); /* rigid -> fracture -> rigid */
    assert_true(cf_sim_world(sim)->max_momentum_error <= 1e-9);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_small_bunny_drop_breaks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
