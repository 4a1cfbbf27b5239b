/* Energy conservation of a free-vibrating elastic block (explicit Tet4, no
 * PBD, dt = 0.5 dt_cfl): over 10,000 steps the total energy kinetic +
 * strain drifts by less than 0.1% of its initial value, and the ledger's
 * residual stays below 1% of the peak total energy.  With the bulk
 * viscosity (docs/physics.md §2.3) the same block rings down, and what it
 * loses is what the ledger books as damping. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "world_impl.h"
#include "verify.h"

static void energy_is_conserved(void **state)
{
    (void)state;
    verify_begin("vibration");
    cf_scene sc;
    const char *sets[] = {"duration=2.9", NULL};
    cf_sim *sim = verify_open("vibration.lua", sets, &sc);
    cf_error err;
    cf_ledger l;
    cf_world_ledger(cf_sim_world(sim), &l);
    double e0 = l.initial, drift = 0, resid = 0, peak = e0;
    while (!cf_sim_done(sim)) {
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        cf_world_ledger(cf_sim_world(sim), &l);
        double e = l.kinetic + l.strain;
        drift = fmax(drift, fabs(e - e0) / e0);
        peak = fmax(peak, e);
        resid = fmax(resid, fabs(l.residual));
    }
    long steps = cf_sim_world(sim)->steps_fracture;
    double ratio = cf_sim_world(sim)->dt_fracture / cf_sim_world(sim)->solid.dt_cfl;
    printf("vibration: %ld explicit steps at dt/dt_cfl = %.3f, E0 = %.6g J\n", steps, ratio, e0);
    assert_true(steps >= 10000);
    int ok = verify_figure("vibration", "max |E - E0| / E0 over 10,000 steps", drift, 0, 1e-3, "");
    ok &= verify_figure("vibration", "ledger residual / peak energy", resid / peak, 0, 1e-2, "");
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    assert_true(ok);
}

/* solver.bulk_viscosity = 0.06: the breathing block loses most of its
 * energy over the same steps, the ledger's damping never falls, and it
 * holds what the block lost: the residual stays at the undamped run's
 * level. */
static void viscosity_takes_what_it_books(void **state)
{
    (void)state;
    verify_begin("vibration");
    cf_scene sc;
    const char *sets[] = {"duration=2.9", "solver.bulk_viscosity=0.06", NULL};
    cf_sim *sim = verify_open("vibration.lua", sets, &sc);
    cf_error err;
    cf_ledger l;
    cf_world_ledger(cf_sim_world(sim), &l);
    double e0 = l.initial, resid = 0, e = e0, damping_fall = 0, last_damping = 0;
    while (!cf_sim_done(sim)) {
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        cf_world_ledger(cf_sim_world(sim), &l);
        damping_fall = fmax(damping_fall, last_damping - l.damping);
        e = l.kinetic + l.strain, last_damping = l.damping;
        resid = fmax(resid, fabs(l.residual));
    }
    printf("vibration with bulk viscosity 0.06: E0 = %.6g J, E_end = %.6g J, damping %.6g J, "
           "largest residual %.3g J\n", e0, e, l.damping, resid);
    int ok = verify_figure("vibration", "bulk viscosity 0.06: E_end / E0", e / e0, 0, 0.5, "");
    ok &= verify_figure("vibration", "bulk viscosity 0.06: ledger residual / E0", resid / e0, 0,
                        1e-3, "");
    ok &= verify_figure("vibration", "bulk viscosity 0.06: largest fall of the damping / E0",
                        damping_fall / e0, 0, 1e-12, "");
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    assert_true(ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(energy_is_conserved),
                                       cmocka_unit_test(viscosity_takes_what_it_books)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
