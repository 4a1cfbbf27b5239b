/* Mode-I and mode-II separation through one pre-selected facet plane
 * (scenes/verification/mode_i.lua, mode_ii.lua): explicit Tet4 + extrinsic
 * PPR, no PBD.  When every node pair has failed, the dissipated energy is
 * G x area within 1% (PPR: the work of the traction to complete failure is
 * phi_n = G_I, phi_t = G_II; Park, Paulino, Roesler 2009).  The ledger's
 * residual stays below 1% of the peak energy. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "world_impl.h"
#include "verify.h"

static void separate(const char *scene, const char *name, double G, double area)
{
    verify_begin(name);
    cf_scene sc;
    cf_sim *sim = verify_open(scene, NULL, &sc);
    cf_error err;
    cf_ledger l;
    double peak = 0, resid = 0;
    while (!cf_sim_done(sim)) {
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        cf_world_ledger(cf_sim_world(sim), &l);
        double e = l.kinetic + l.strain + l.cohesive_stored + l.cohesive_dissipated;
        peak = fmax(peak, fmax(e, l.initial + l.work_boundary));
        resid = fmax(resid, fabs(l.residual));
    }
    int pairs = 0, failed = 0;
    for (int c = 0; c < cf_sim_world(sim)->solid.n_coh; c++)
        for (int i = 0; i < 3; i++)
            pairs++, failed += cf_sim_world(sim)->solid.coh[c].failed[i] != 0;
    printf("%s: %d cohesive elements, %d of %d node pairs failed, boundary work %.6g J\n", name,
           cf_sim_world(sim)->solid.n_coh, failed, pairs, l.work_boundary);
    assert_int_equal(failed, pairs);
    int ok = verify_figure(name, "dissipated energy", l.cohesive_dissipated, G * area, 0.01, "J");
    ok &= verify_figure(name, "ledger residual / peak energy", resid / peak, 0, 0.01, "");
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    assert_true(ok);
}

static void mode_i(void **state)
{
    (void)state;
    separate("mode_i.lua", "mode_i", 22.0, 0.1 * 0.1);
}

static void mode_ii(void **state)
{
    (void)state;
    separate("mode_ii.lua", "mode_ii", 44.0, 0.2 * 0.2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(mode_i), cmocka_unit_test(mode_ii)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
