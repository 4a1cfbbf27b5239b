/* Free fall and bounce on a plane (scenes/verification/bounce.lua, Bullet
 * rigid mode): before the contact z = z0 - g t^2/2 (error of Bullet's
 * semi-implicit Euler: g t h / 2); after it the apex height of the centre
 * of mass above its resting height is e^2 times the drop height, within 1%.
 * (Bullet's restitution on a box landing flat; it varies with the number of
 * sub-steps, see docs/physics.md.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cohfrac/sim.h"
#include "cohfrac/scene.h"
#include "world_impl.h"
#include "verify.h"

static void apex_ratio_is_e_squared(void **state)
{
    (void)state;
    verify_begin("bounce");
    cf_scene sc;
    cf_sim *sim = verify_open("bounce.lua", NULL, &sc);
    cf_error err;
    double com[3], R[9], v[3], w[3];
    cf_fragment_pose(&cf_sim_world(sim)->frag[0], &cf_sim_world(sim)->solid,
                     cf_sim_world(sim)->bullet, com, R, v, w);
    double bottom = INFINITY;
    for (int i = 0; i < cf_sim_world(sim)->solid.n_nodes; i++)
        bottom = fmin(bottom, cf_sim_world(sim)->solid.x[3 * i + 2]);
    double z0 = com[2], g = -sc.world.gravity[2], z_contact = INFINITY, apex = -INFINITY;
    double z_rest = z0 - bottom; /* the plane is z = 0 */
    double fall_err = 0, vz_prev = 0;
    int phase = 0; /* 0 falling, 1 rising after the first bounce, 2 done */
    while (!cf_sim_done(sim) && phase < 2) {
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        cf_fragment_pose(&cf_sim_world(sim)->frag[0], &cf_sim_world(sim)->solid,
                     cf_sim_world(sim)->bullet, com, R, v, w);
        double t = cf_world_time(cf_sim_world(sim));
        if (phase == 0 && v[2] > 0)
            phase = 1;
        if (phase == 0) {
            z_contact = fmin(z_contact, com[2]);
            if (com[2] > z0 - 0.8) /* well before the contact */
                fall_err = fmax(fall_err, fabs(com[2] - (z0 - 0.5 * g * t * t)));
        } else if (phase == 1) {
            apex = fmax(apex, com[2]);
            if (vz_prev > 0 && v[2] <= 0)
                phase = 2;
        }
        vz_prev = v[2];
    }
    double e = sc.world.material.restitution;
    double ratio = (apex - z_rest) / (z0 - z_rest);
    printf("bounce: z0 = %.4f m, resting height %.4f m, lowest %.4f m, apex %.4f m\n", z0,
           z_rest, z_contact, apex);
    /* 3%: Bullet's sequential impulses reach the four landing corners one
     * after the other, so the box leaves the floor spinning (about 8 rad/s
     * here) and the apex moves by a few percent with the sub-step count. */
    int ok = verify_figure("bounce", "apex height / drop height", ratio, e * e, 0.03, "");
    ok &= verify_figure("bounce", "free-fall error / fall height (reported)", fall_err / 0.8, 0,
                        0, "");
    cf_sim_destroy(sim);
    cf_scene_free(&sc);
    assert_true(phase == 2);
    assert_true(ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(apex_ratio_is_e_squared)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
