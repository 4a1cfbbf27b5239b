/* The source's mixed-mode beam (scenes/verification/mixed_mode_beam.lua,
 * source Fig 6.6): PBD with k_stiffness = 1 and 4 iterations, dt = 3e-5 s
 * for 300 steps, runs to the end without tripping the divergence guard (no
 * NaN, no inverted tets beyond 1%, no energy growth beyond the work put in).
 * Reported beside it: dt / dt_cfl, and the crack angle at the notch
 * (the first cohesive elements within 3 cm of the notch tip, least-squares
 * line through the tip; degrees from vertical) next to the source's ~30. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "world_impl.h"
#include "verify.h"

/* Angle from vertical (degrees) of the line through the notch tip (xt, zt)
 * fitted to the centroids of the first `want` cohesive elements near it. */
static double crack_angle(const cf_solid *s, double xt, double zt, int want)
{
    double sxz = 0, szz = 0;
    int n = 0;
    for (int c = 0; c < s->n_coh && n < want; c++) {
        const cf_cohesive *ce = &s->coh[c];
        double m[3] = {0, 0, 0};
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                m[k] += s->X[3 * s->tet0[4 * ce->tet[0] + ce->slot[0][i]] + k] / 3.0;
        double dx = m[0] - xt, dz = m[2] - zt;
        if (dz <= 0 || dx * dx + dz * dz > 0.03 * 0.03)
            continue;
        sxz += dx * dz, szz += dz * dz, n++;
    }
    return n > 0 ? atan(sxz / szz) * 180.0 / 3.14159265358979323846 : NAN;
}

static void beam_stays_stable(void **state)
{
    (void)state;
    verify_begin("mixed_mode_beam");
    cf_scene sc;
    /* The source's step, 2.1 dt_cfl (the scene ships a stable 1e-5 s). */
    const char *sets[] = {"bodies[1].mesh.mesh_size=0.012", "solver.dt_fracture=3e-5", NULL};
    cf_sim *sim = verify_open("mixed_mode_beam.lua", sets, &sc);
    cf_error err;
    cf_status st = cf_sim_run(sim, &err);
    if (st != CF_OK)
        printf("mixed_mode_beam: %s\n", err.msg);
    const cf_primitive *b = &sc.sources[0].primitive;
    double xt = b->notch[2], zt = -0.5 * b->size[2] + b->notch[0];
    double angle = fabs(crack_angle(&cf_sim_world(sim)->solid, xt, zt, 20));
    printf("mixed_mode_beam: %ld steps, %d tets, %d cohesive elements\n", cf_sim_world(sim)->steps_fracture,
           cf_sim_world(sim)->solid.n_tets, cf_sim_world(sim)->solid.n_coh);
    verify_figure("mixed_mode_beam", "dt / dt_cfl of this mesh (reported)",
                  cf_sim_world(sim)->dt_fracture / cf_sim_world(sim)->solid.dt_cfl, 0, 0, "");
    verify_figure("mixed_mode_beam", "crack angle at the notch (reported)", angle, 30, 0, "deg");
    /* Steps of the run (the solver steps of all its fragments, once the
     * beam is in pieces, are more). */
    double steps = floor(cf_world_time(cf_sim_world(sim)) / cf_sim_world(sim)->dt_fracture + 0.5);
    int ok = verify_figure("mixed_mode_beam", "steps run at dt = 3e-5 s without divergence",
                           steps, 300, 1e-9, "");
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    assert_int_equal(st, CF_OK);
    assert_true(ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(beam_stays_stable)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
