/* The CFL estimate is tight (docs/physics.md §3): the explicit solver with no PBD
 * (scenes/verification/wave_bar.lua) runs stable at dt = 0.9 dt_cfl, and at
 * dt = 3 dt_cfl the divergence guard stops it with CF_ERR_DIVERGED. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "world_impl.h"
#include "verify.h"

/* Run wave_bar.lua at dt = fraction dt_cfl; returns the status and the
 * simulated time reached. */
static cf_status run_at(const char *fraction, double *t_end, double *growth)
{
    cf_scene sc;
    char set[64];
    snprintf(set, sizeof set, "solver.cfl_fraction=%s", fraction);
    const char *sets[] = {set, "duration=0.03", NULL};
    cf_sim *sim = verify_open("wave_bar.lua", sets, &sc);
    cf_error err;
    cf_status st = cf_sim_run(sim, &err);
    if (st != CF_OK)
        printf("dt = %s dt_cfl: %s\n", fraction, err.msg);
    cf_ledger l;
    cf_world_ledger(cf_sim_world(sim), &l);
    *t_end = cf_world_time(cf_sim_world(sim));
    *growth = (l.kinetic + l.strain) / (l.initial + l.work_boundary);
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    return st;
}

static void cfl_is_tight(void **state)
{
    (void)state;
    verify_begin("cfl");
    double t_stable, t_unstable, g_stable, g_unstable;
    cf_status stable = run_at("0.9", &t_stable, &g_stable);
    cf_status unstable = run_at("3.0", &t_unstable, &g_unstable);
    int ok = verify_figure("cfl", "0.9 dt_cfl: (kinetic + strain) / work input", g_stable, 1.0,
                           0.05, "");
    ok &= verify_figure("cfl", "3 dt_cfl: simulated time when the guard stopped it", t_unstable,
                        0, 0, "s");
    assert_int_equal(stable, CF_OK);
    assert_int_equal(unstable, CF_ERR_DIVERGED);
    assert_true(t_unstable < 0.03);
    assert_true(ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(cfl_is_tight)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
