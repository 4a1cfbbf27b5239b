/* Two identical elastic bars collide end on
 * (scenes/verification/bar_collision.lua): contact between fracture-mode
 * fragments of different bodies.  Bar theory: they part after 2 L/c0 (within
 * 5%), bar 1 at rest and bar 2 at v0 (each within 2% of v0); linear
 * momentum stays M v0 to round-off at every step; the energy ledger
 * balances (residual below 1e-6 of the input) and the collision is elastic:
 * kinetic + strain energy after it is within 1% of the input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "world_impl.h"
#include "verify.h"

/* Smallest x of bar 2's nodes minus largest x of bar 1's, m. */
static double gap(const cf_sim *sim)
{
    double hi1 = -INFINITY, lo2 = INFINITY;
    for (int b = 0; b < 2; b++) {
        const cf_fragment *f = &cf_sim_world(sim)->frag[b];
        for (int i = 0; i < f->nodes.n; i++) {
            double x = cf_sim_world(sim)->solid.x[3 * f->nodes.v[i]];
            if (b == 0)
                hi1 = fmax(hi1, x);
            else
                lo2 = fmin(lo2, x);
        }
    }
    return lo2 - hi1;
}

static void bars_exchange_momentum(void **state)
{
    (void)state;
    verify_begin("bar_collision");
    cf_scene sc;
    cf_sim *sim = verify_open("bar_collision.lua", NULL, &sc);
    const cf_material *m = &sc.world.material;
    double c0 = sqrt(m->E / m->rho), v0 = sc.world.bodies[0].velocity[0], L = 0.5;
    cf_ledger l;
    cf_world_ledger(cf_sim_world(sim), &l);
    double P0 = l.momentum[0], drift = 0, t_part = -1;
    cf_error err;
    while (!cf_sim_done(sim)) {
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        cf_world_ledger(cf_sim_world(sim), &l);
        drift = fmax(drift, sqrt(pow(l.momentum[0] - P0, 2) + pow(l.momentum[1], 2) +
                                 pow(l.momentum[2], 2)) / P0);
        if (t_part < 0 && gap(sim) > 1e-6)
            t_part = cf_world_time(cf_sim_world(sim));
    }
    cf_fragment_state fs[2];
    assert_int_equal(cf_world_fragments(cf_sim_world(sim), fs, 2), 2);
    printf("bar_collision: c0 = %g m/s, dt/dt_cfl = %.2f, contact removed %.3g J\n", c0,
           cf_sim_world(sim)->dt_fracture / cf_sim_world(sim)->solid.dt_cfl, l.contact);
    int ok = verify_figure("bar_collision", "time the bars part", t_part, 2 * L / c0, 0.05, "s");
    ok &= verify_figure("bar_collision", "bar 1 velocity after / v0", fs[0].v[0] / v0, 0, 0.02, "");
    ok &= verify_figure("bar_collision", "bar 2 velocity after / v0", fs[1].v[0] / v0, 1, 0.02, "");
    ok &= verify_figure("bar_collision", "|P - P0|/|P0|, every step", drift, 0, 1e-12, "");
    ok &= verify_figure("bar_collision", "(kinetic + strain) after / input",
                        (l.kinetic + l.strain) / l.initial, 1, 0.01, "");
    ok &= verify_figure("bar_collision", "ledger residual / input", l.residual / l.initial, 0,
                        1e-6, "");
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    assert_true(ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(bars_exchange_momentum)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
