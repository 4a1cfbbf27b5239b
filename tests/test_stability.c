/* `cohfrac stability --quick` (src/cli/stability.h): the corners of
 * the map whose outcome is known from the theory of the explicit step and
 * of PBD, with one body on a plane and two bodies of very different mass in
 * contact, and the files it writes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "stability.h"
#include "fixtures.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* The case of mode m, E, dt/dt_cfl and mass ratio (0: the cube against the
 * plane). */
static const cf_stability_case *find_case(const cf_stability_result *r, cf_stability_mode m,
                                          double E, double ratio, double mass)
{
    for (int i = 0; i < r->n; i++)
        if (r->cases[i].mode == m && r->cases[i].E == E && r->cases[i].dt_ratio == ratio &&
            r->cases[i].mass_ratio == mass)
            return &r->cases[i];
    fail_msg("no case %s E %g dt/dt_cfl %g mass ratio %g", cf_stability_mode_name(m), E, ratio,
             mass);
    return NULL;
}

static const cf_stability_case *find(const cf_stability_result *r, cf_stability_mode m,
                                     double E, double ratio)
{
    return find_case(r, m, E, ratio, 0);
}

static void test_quick_map_corners(void **state)
{
    (void)state;
    char dir[256];
    snprintf(dir, sizeof dir, "%s/stability_XXXXXX", COHFRAC_BINARY_DIR);
    assert_non_null(mkdtemp(dir));
    cf_stability_options opt = {.quick = 1, .out_dir = dir, .plot = 0};
    cf_stability_result r;
    cf_error err = {0};
    if (cf_stability_run(&opt, &r, &err) != CF_OK)
        fail_msg("stability: %s", err.msg);
    for (int i = 0; i < r.n; i++)
        printf("FIGURE %-12s E %-8.3g dt/dt_cfl %-4g mass ratio %-5g %s %s step %ld, energy "
               "ratio %.3g\n",
               cf_stability_mode_name(r.cases[i].mode), r.cases[i].E, r.cases[i].dt_ratio,
               r.cases[i].mass_ratio, r.cases[i].stable ? "stable" : "unstable:",
               r.cases[i].reason, r.cases[i].fail_step, r.cases[i].energy_ratio);
    /* Explicit elasticity is stable below the CFL limit and not far above it. */
    const cf_stability_case *c = find(&r, CF_STAB_NONE, 7e10, 0.5);
    assert_true(c->stable);
    assert_true(c->energy_ratio <= 1.1);
    c = find(&r, CF_STAB_NONE, 7e10, 100);
    assert_false(c->stable);
    assert_true(c->fail_step > 0 && c->fail_step <= 10);
    /* Converged PBD bars hold glass together well past the explicit limit. */
    assert_true(find(&r, CF_STAB_PBD_STIFF, 7e10, 10)->stable);
    /* The source's E = 0.6 Pa cube is crushed flat by a 10 m/s impact. */
    c = find(&r, CF_STAB_PBD_SRC, 0.6, 0.5);
    assert_false(c->stable);
    assert_string_equal(c->reason, "inverted");
    /* Two deformable cubes in contact, a light impactor on a heavy target
     * and the reverse: below the CFL limit the contact adds no instability
     * and no energy; far above it they blow up within a few steps. */
    for (int k = 0; k < 2; k++) {
        double mass = k ? 100 : 0.01;
        c = find_case(&r, CF_STAB_NONE, 7e10, 0.5, mass);
        assert_true(c->stable);
        assert_true(c->energy_ratio <= 1.1);
        c = find_case(&r, CF_STAB_NONE, 7e10, 100, mass);
        assert_false(c->stable);
        assert_true(c->fail_step > 0 && c->fail_step <= 10);
    }
    char path[400];
    snprintf(path, sizeof path, "%s/stability.csv", dir);
    assert_int_equal(access(path, R_OK), 0);
    snprintf(path, sizeof path, "%s/stability.md", dir);
    assert_int_equal(access(path, R_OK), 0);
    cf_stability_free(&r);
    fixture_remove_tree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_quick_map_corners),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
