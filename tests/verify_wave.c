/* Elastic wave in a slender bar (scenes/verification/wave_bar.lua):
 * explicit Tet4, no PBD, dt = 0.9 dt_cfl.  The front reaches the gauge at
 * distance d from the pushed end at d/c0 (c0 = sqrt(E/rho), within 3%), and
 * behind it the axial stress is -rho c0 v0 (within 5%). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "world_impl.h"
#include "tet4.h"
#include "verify.h"

/* Mean axial stress (Pa) of the tets whose centroid lies in [x0, x1]. */
static double gauge_stress(const cf_sim *sim, double x0, double x1)
{
    const cf_solid *s = &cf_sim_world(sim)->solid;
    double sum = 0, vol = 0;
    for (int t = 0; t < s->n_tets; t++) {
        double c = 0;
        for (int j = 0; j < 4; j++)
            c += 0.25 * s->X[3 * s->tet[4 * t + j]];
        if (c >= x0 && c <= x1) {
            double sig[9];
            cf_tet4_stress(s, t, cf_sim_world(sim)->def.solver.elasticity, sig);
            sum += sig[0] * s->vol[t], vol += s->vol[t];
        }
    }
    return sum / vol;
}

static void front_speed_and_stress(void **state)
{
    (void)state;
    verify_begin("wave_bar");
    cf_scene sc;
    cf_sim *sim = verify_open("wave_bar.lua", NULL, &sc);
    const cf_material *m = &sc.world.material;
    double c0 = sqrt(m->E / m->rho), v0 = sc.world.boundaries[0].velocity[0];
    double sigma_ref = -m->rho * c0 * v0, gauge = 0.25, d = gauge + 0.5, L = 1.0;
    double t_prev = 0, s_prev = 0, t_arrive = -1, plateau = 0;
    int n_plateau = 0;
    cf_error err;
    while (!cf_sim_done(sim)) {
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        double t = cf_world_time(cf_sim_world(sim)), sg = gauge_stress(sim, gauge - 0.02, gauge + 0.02);
        /* arrival: the stress crosses half its plateau value */
        if (t_arrive < 0 && sg <= 0.5 * sigma_ref)
            t_arrive = t_prev + (t - t_prev) * (0.5 * sigma_ref - s_prev) / (sg - s_prev);
        /* plateau: after the front has passed, before the reflection returns */
        if (t > (d + 0.1 * L) / c0 && t < (L + (0.5 - gauge)) / c0 - 0.05 * L / c0)
            plateau += sg, n_plateau++;
        t_prev = t, s_prev = sg;
    }
    printf("wave_bar: c0 = %g m/s, dt/dt_cfl = %.3f, %d plateau samples\n", c0,
           cf_sim_world(sim)->dt_fracture / cf_sim_world(sim)->solid.dt_cfl,
           n_plateau);
    assert_true(t_arrive > 0 && n_plateau > 0);
    int ok = verify_figure("wave_bar", "front arrival time at 0.75 L", t_arrive, d / c0, 0.03, "s");
    ok &= verify_figure("wave_bar", "stress behind the front", plateau / n_plateau, sigma_ref,
                        0.05, "Pa");
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    assert_true(ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(front_speed_and_stress)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
