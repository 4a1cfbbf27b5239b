/* Linear momentum to round-off through cohesive insertion, node
 * duplication and the fracture -> rigid hand-off
 * (scenes/verification/momentum.lua): a free, expanding block tears apart;
 * its total momentum stays M v0 within 1e-12 relative at every step. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "handoff.h"
#include "verify.h"

static double drift(const cf_sim *sim, const double P0[3])
{
    cf_ledger l;
    cf_world_ledger(cf_sim_world(sim), &l);
    double d[3] = {l.momentum[0] - P0[0], l.momentum[1] - P0[1], l.momentum[2] - P0[2]};
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) /
           sqrt(P0[0] * P0[0] + P0[1] * P0[1] + P0[2] * P0[2]);
}

static void momentum_to_round_off(void **state)
{
    (void)state;
    verify_begin("momentum");
    cf_scene sc;
    cf_sim *sim = verify_open("momentum.lua", NULL, &sc);
    cf_error err;
    cf_ledger l;
    cf_world_ledger(cf_sim_world(sim), &l);
    double P0[3] = {l.momentum[0], l.momentum[1], l.momentum[2]}, worst_fracture = 0;
    int nodes0 = cf_sim_world(sim)->solid.n_nodes;
    while (!cf_sim_done(sim)) {
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        worst_fracture = fmax(worst_fracture, drift(sim, P0));
    }
    int n_coh = cf_sim_world(sim)->solid.n_coh, copies = cf_sim_world(sim)->solid.n_nodes - nodes0;
    /* Hand the torn block (the fracture-mode fragments it has come apart
     * into) to rigid mode (pbd rigid backend: no Bullet world in this scene)
     * and fly on. */
    cf_world *w = cf_sim_world(sim);
    cf_handoff_record rec;
    for (int fi = 0, n = w->n_frag; fi < n; fi++)
        if (w->frag[fi].mode == CF_MODE_FRACTURE && cf_handoff_to_rigid(w, fi, &rec, &err) != CF_OK)
            fail_msg("%s", err.msg);
    double after_handoff = drift(sim, P0), worst_rigid = 0;
    int pieces = 0;
    for (int fi = 0; fi < w->n_frag; fi++)
        pieces += w->frag[fi].mode != CF_MODE_DEAD;
    for (int k = 0; k < 50; k++) { /* past the duration: regular steps */
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        worst_rigid = fmax(worst_rigid, drift(sim, P0));
    }
    printf("momentum: %d cohesive elements, %d node copies, %d fragments after the hand-off\n",
           n_coh, copies, pieces);
    assert_true(n_coh > 0 && copies > 0 && pieces > 1);
    int ok = verify_figure("momentum", "|P - P0|/|P0|, fracture mode (insertion, duplication)",
                           worst_fracture, 0, 1e-12, "");
    ok &= verify_figure("momentum", "|P - P0|/|P0| after the hand-off", after_handoff, 0, 1e-12,
                        "");
    ok &= verify_figure("momentum", "|P - P0|/|P0|, pbd rigid mode after it", worst_rigid, 0,
                        1e-12, "");
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    assert_true(ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(momentum_to_round_off)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
