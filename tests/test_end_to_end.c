/* End to end on the 979-tet bunny: the default drop (gypsum plaster, a
 * 5.1 m fall onto its side, run on to 0.535 s) falls in
 * Bullet, breaks in fracture mode into pieces of which at least two hold
 * 5 % of the mass each, and every hand-off conserves linear momentum to
 * 1e-9.  (The source's own bunny drop, with its cohesive law that never
 * lets go, no longer breaks once the hand-off keeps what still holds.)  The HDF5 file it
 * writes is checked further by tests/checks/check_run.py (free fall, datasets). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "check.h"
#include "world_impl.h"

#include <stdio.h>

static void test_bunny_drop_breaks(void **state)
{
    (void)state;
    const char *sets[] = {
        "duration=0.535",
        "output.file=\"" COHFRAC_BINARY_DIR "/e2e/bunny_1k_drop.h5\"",
    };
    cf_scene sc;
    cf_error err = {0};
    cf_status st = cf_scene_load(COHFRAC_SOURCE_DIR "/scenes/plaster_bunny_drop.lua", sets, 2,
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
    const cf_world *w = cf_sim_world(sim);
    int pieces = 0;
    double total = 0;
    for (int i = 0; i < w->n_frag; i++)
        total += w->frag[i].mode != CF_MODE_DEAD ? w->frag[i].mass : 0;
    for (int i = 0; i < w->n_frag; i++)
        pieces += w->frag[i].mode != CF_MODE_DEAD && w->frag[i].mass >= 0.05 * total;
    printf("FIGURE end to end: %d pieces of at least 5 %% of the mass\n", pieces);
    assert_true(pieces >= 2);
    assert_true(cf_sim_world(sim)->solid.n_coh > 0);
    assert_true(cf_sim_world(sim)->n_handoffs >= 2); /* rigid -> fracture -> rigid */
    assert_true(cf_sim_world(sim)->max_momentum_error <= 1e-9);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bunny_drop_breaks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
