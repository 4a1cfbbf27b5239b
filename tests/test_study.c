/* `cohfrac study` (src/cli/study.h): the trajectory error against a
 * closed form (free fall with two time steps), fragment matching through
 * the family tree and mass on written files, the mass-distribution
 * distance, the cache, and the usage and scene errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "check.h"
#include "cohfrac/h5_output.h"
#include "study.h"
#include "fixtures.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define SCENE COHFRAC_SOURCE_DIR "/tests/data/study_free_fall.lua"

static char *tmpdir(const char *name)
{
    static char dir[512];
    snprintf(dir, sizeof dir, "%s/%s_XXXXXX", COHFRAC_BINARY_DIR, name);
    assert_non_null(mkdtemp(dir));
    return dir;
}

/* Symplectic Euler free fall: x_n = x0 + g t^2/2 + g t dt/2, so runs with
 * steps dt1 and dt2 are |g| t |dt1 - dt2| / 2 apart at time t; over the
 * frames t_k = 0, 0.01, ..., 0.1 the RMS is that times sqrt(mean t_k^2). */
static void test_free_fall_error_is_closed_form(void **state)
{
    (void)state;
    const char *vary[] = {"solver.dt_fracture=1e-4,5e-4"};
    const char *ref[] = {"solver.dt_fracture=1e-5", "solver.constraints=\"none\""};
    cf_study_options o = {.scene = SCENE, .vary = vary, .n_vary = 1, .reference = ref,
                          .n_reference = 2, .out_dir = tmpdir("study"),
                          .mesh_dir = COHFRAC_MESH_DIR, .exe = COHFRAC_EXE, .jobs = 2};
    cf_study_result r;
    cf_error err = {0};
    if (cf_study_run(&o, &r, &err) != CF_OK)
        fail_msg("study: %s", err.msg);
    assert_int_equal(r.n_cases, 3);
    double mean_t2 = 0;
    for (int k = 0; k <= 10; k++)
        mean_t2 += 1e-4 * k * k / 11.0;
    const double dts[] = {1e-4, 5e-4};
    for (int i = 1; i <= 2; i++) {
        double expect = 9.81 * (dts[i - 1] - 1e-5) / 2 * sqrt(mean_t2);
        printf("FIGURE dt %g: traj_rms %.6e m, closed form %.6e m, traj_rel %.4g\n", dts[i - 1],
               r.cases[i].traj_rms, expect, r.cases[i].traj_rel);
        assert_int_equal(r.cases[i].exit_code, 0);
        assert_near(r.cases[i].traj_rms, expect, 1e-4 * expect); /* round-off of 1e4 steps */
        assert_int_equal(r.cases[i].n_fragments, 1);
        assert_near(r.cases[i].mass_ks, 0, 0);
        /* v_n = g t_n for any dt, up to the round-off of v = (p - x) / dt */
        assert_near(r.cases[i].p_err, 0, 1e-7);
        assert_true(r.cases[i].peak_rss > 1e6 && r.cases[i].wall > 0);
    }
    assert_near(r.cases[0].traj_rms, 0, 0);
    /* travel: |g| t^2 / 2 + |g| t dt / 2, RMS over the frames */
    double D = 0;
    for (int k = 0; k <= 10; k++) {
        double t = 0.01 * k, x = 9.81 * (t * t + t * 1e-5) / 2;
        D += x * x / 11;
    }
    assert_near(r.travel, sqrt(D), 1e-9);
    /* Both are within 5%; which is cheaper is a matter of wall time. */
    assert_true(r.best == 1 || r.best == 2);
    assert_true(r.cases[r.best].pareto && r.cases[r.best].traj_rel <= 0.05);
    cf_study_free(&r);

    /* Again: every run comes from the cache, with the same figures. */
    o.progress = 0;
    if (cf_study_run(&o, &r, &err) != CF_OK)
        fail_msg("study again: %s", err.msg);
    assert_int_equal(r.n_cached, 3);
    assert_near(r.cases[1].traj_rms, 9.81 * (1e-4 - 1e-5) / 2 * sqrt(mean_t2), 1e-4 * 5e-5);
    char path[1100];
    snprintf(path, sizeof path, "%s/study.md", r.out_dir);
    assert_int_equal(access(path, R_OK), 0);
    snprintf(path, sizeof path, "%s/study.csv", r.out_dir);
    assert_int_equal(access(path, R_OK), 0);
    cf_study_free(&r);
}

/* A case whose resolved scene is the reference's runs once and gets the
 * reference's figures: zero error, the same process figures. */
static void test_case_equal_to_reference_runs_once(void **state)
{
    (void)state;
    const char *vary[] = {"solver.dt_fracture=1e-4", "solver.constraints=\"none\""};
    const char *ref[] = {"solver.dt_fracture=1e-4", "solver.constraints=\"none\""};
    cf_study_options o = {.scene = SCENE, .vary = vary, .n_vary = 2, .reference = ref,
                          .n_reference = 2, .out_dir = tmpdir("study_same"),
                          .mesh_dir = COHFRAC_MESH_DIR, .exe = COHFRAC_EXE, .jobs = 2};
    cf_study_result r;
    cf_error err = {0};
    if (cf_study_run(&o, &r, &err) != CF_OK)
        fail_msg("study: %s", err.msg);
    assert_int_equal(r.n_cases, 2);
    assert_string_equal(r.cases[0].hash, r.cases[1].hash);
    assert_int_equal(r.cases[1].exit_code, 0);
    assert_near(r.cases[1].traj_rms, 0, 0);
    assert_near(r.cases[1].wall, r.cases[0].wall, 0);
    assert_int_equal(r.n_cached, 0);
    cf_study_free(&r);
}

/* A file with one body of mass 3 kg at the origin moving along +x at 1 m/s,
 * which splits at t = 0.5 s into pieces of the given masses (kg, heaviest
 * at +y when `swap` is 0) placed so that their centre of mass stays on the
 * body's path; n_kids = 0: no split. */
static void write_tree(const char *path, int n_kids, int swap)
{
    cf_h5 *h;
    cf_error err = {0};
    assert_int_equal(cf_h5_open(path, "tree", "return {}", &h, &err), CF_OK);
    cf_frag_info body = {.id = 0, .parent = -1, .mass = 3, .n_tets = 3};
    assert_int_equal(cf_h5_add_fragments(h, &body, 1, &err), CF_OK);
    for (int k = 0; k <= 10; k++) {
        double t = 0.1 * k;
        cf_frag_frame fr[2] = {{0}};
        int n = 1;
        fr[0].id = 0, fr[0].com[0] = t, fr[0].quat[0] = 1;
        if (n_kids && k == 5) {
            cf_frag_info kids[2] = {{.id = 1, .parent = 0, .birth_time = t, .mass = swap ? 1 : 2},
                                    {.id = 2, .parent = 0, .birth_time = t, .mass = swap ? 2 : 1}};
            assert_int_equal(cf_h5_add_fragments(h, kids, 2, &err), CF_OK);
        }
        if (n_kids && k >= 5) {
            /* heavy piece (2 kg) at y = +0.1, light one (1 kg) at y = -0.2 */
            n = 2;
            for (int i = 0; i < 2; i++) {
                int heavy = (i == 0) != swap;
                fr[i].id = 1 + i, fr[i].com[0] = t, fr[i].quat[0] = 1;
                fr[i].com[1] = heavy ? 0.1 : -0.2;
            }
        }
        assert_int_equal(cf_h5_write_frame(h, k, t, fr, n, &err), CF_OK);
    }
    assert_int_equal(cf_h5_close(h, &err), CF_OK);
}

static void test_matching_by_family_tree_and_mass(void **state)
{
    (void)state;
    char *dir = tmpdir("study_tree"), ref[600], swapped[600], whole[600];
    snprintf(ref, sizeof ref, "%s/ref.h5", dir);
    snprintf(swapped, sizeof swapped, "%s/swapped.h5", dir);
    snprintf(whole, sizeof whole, "%s/whole.h5", dir);
    write_tree(ref, 2, 0);
    write_tree(swapped, 2, 1); /* the same pieces under the other ids */
    write_tree(whole, 0, 0);   /* never splits */
    cf_study_case c;
    double D;
    cf_error err = {0};
    if (cf_study_measure(swapped, ref, &c, &D, &err) != CF_OK)
        fail_msg("%s", err.msg);
    /* The body travels 0..1 m: D = sqrt(mean t^2) over t = 0, 0.1, ..., 1. */
    assert_near(D, sqrt(3.85 / 11), 1e-12);
    assert_near(c.traj_rms, 0, 1e-15); /* matched by mass, not by id */
    assert_near(c.mass_ks, 0, 1e-15);
    assert_int_equal(c.n_fragments, 2);
    /* Unbroken against broken: the body is compared with its pieces' common
     * centre of mass (on its path); the mass distributions {3} and {1, 2}
     * differ by all of the mass at m = 2 kg. */
    if (cf_study_measure(whole, ref, &c, NULL, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_near(c.traj_rms, 0, 1e-15);
    assert_near(c.mass_ks, 1, 1e-15);
    /* Broken against unbroken: each piece against the body; e^2 = (2 (0.1)^2
     * + 1 (0.2)^2) / 3 = 0.02 m^2 over the 6 frames from the split, 0 before. */
    if (cf_study_measure(ref, whole, &c, NULL, &err) != CF_OK)
        fail_msg("%s", err.msg);
    assert_near(c.traj_rms, sqrt(0.02 * 6 / 11), 1e-12);
    /* Not an output file: CF_ERR_FILE_OPEN naming it. */
    assert_int_equal(cf_study_measure(SCENE, ref, &c, NULL, &err), CF_ERR_FILE_OPEN);
    assert_non_null(strstr(err.msg, "study_free_fall.lua"));
}

static void test_bad_vary_and_bad_key(void **state)
{
    (void)state;
    cf_study_result r;
    cf_error err = {0};
    const char *no_eq[] = {"solver.dt_fracture"};
    cf_study_options o = {.scene = SCENE, .vary = no_eq, .n_vary = 1,
                          .out_dir = tmpdir("study_bad"), .mesh_dir = COHFRAC_MESH_DIR,
                          .exe = COHFRAC_EXE};
    assert_int_equal(cf_study_run(&o, &r, &err), CF_ERR_USAGE);
    assert_non_null(strstr(err.msg, "solver.dt_fracture"));
    cf_study_free(&r);
    const char *empty[] = {"solver.dt_fracture=1e-4,,2e-4"};
    o.vary = empty;
    assert_int_equal(cf_study_run(&o, &r, &err), CF_ERR_USAGE);
    assert_non_null(strstr(err.msg, "empty value"));
    cf_study_free(&r);
    const char *typo[] = {"solver.pbd.k_stiffnes=0.5,0.9"};
    o.vary = typo;
    assert_int_equal(cf_study_run(&o, &r, &err), CF_ERR_SCENE_KEY);
    assert_non_null(strstr(err.msg, "k_stiffnes"));
    cf_study_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_free_fall_error_is_closed_form),
        cmocka_unit_test(test_case_equal_to_reference_runs_once),
        cmocka_unit_test(test_matching_by_family_tree_and_mass),
        cmocka_unit_test(test_bad_vary_and_bad_key),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
