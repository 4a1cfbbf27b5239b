/* The rigid backends against closed forms, through cf_compare_run
 * (src/cli/compare.h):
 *
 * scenes/compare/spinning_top.lua: a torque-free symmetric top; its axis
 * precesses about L at Omega_p = |L| / I_1.  Measured (dt_rigid 1e-3 s):
 * Bullet 0.37 % off, pbd 10.6 % off (the damped-PBD rigid mode loses
 * angular momentum, ~18 % over the 1.5 s; both errors are first order in
 * dt_rigid).  Tolerances: Bullet 1 %, pbd 15 %.
 *
 * scenes/compare/free_fall.lua: Bullet's semi-implicit Euler with sub-step
 * h = dt_rigid / rigid_substeps gives z_n = z0 - g h^2 n (n + 1) / 2, i.e.
 * an error of exactly g t h / 2 against z0 - g t^2 / 2: the measured error
 * must equal it to round-off: 1e-8 relative (1e-11 m; 5,000 sub-steps of
 * x += v h at x = 5 m accumulate at most ~2e-12 m; measured 2.3e-10).
 *
 * Both write compare.md / compare.csv / fragments.csv (and compare.png when
 * matplotlib is importable) into a temporary directory. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <stdlib.h>
#include <unistd.h>

#include "compare.h"
#include "verify.h"

#define TOP_TOL_BULLET 0.01
#define TOP_TOL_PBD 0.15

static long file_size(const char *dir, const char *name)
{
    char path[1200];
    struct stat sb;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return stat(path, &sb) == 0 ? (long)sb.st_size : -1;
}

static void remove_outputs(const char *dir)
{
    static const char *const names[] = {"compare.md", "compare.csv", "fragments.csv",
                                        "compare.png"};
    char path[1200];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        remove(path);
    }
    rmdir(dir);
}

static void run_compare(const char *scene, char *dir, cf_compare_result *res)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/compare/%s", COHFRAC_SOURCE_DIR, scene);
    strcpy(dir, "/tmp/cohfrac_compare_XXXXXX");
    assert_non_null(mkdtemp(dir));
    cf_compare_options opt = {.scene = path,
                              .out_dir = dir,
                              .mesh_dir = COHFRAC_MESH_DIR,
                              .plot = 1,
                              .plot_script = COHFRAC_SOURCE_DIR "/python/cohfrac/compare_plot.py",
                              .headline = stdout};
    cf_error err = {0};
    if (cf_compare_run(&opt, res, &err) != CF_OK)
        fail_msg("%s", err.msg);
    /* the report files, whole (no .tmp left behind) */
    assert_true(file_size(dir, "compare.md") > 0);
    assert_true(file_size(dir, "compare.csv") > 0);
    assert_true(file_size(dir, "fragments.csv") > 0);
    assert_true(file_size(dir, "compare.md.tmp") < 0);
    if (system("/usr/bin/python3 -c 'import matplotlib' 2>/dev/null") == 0) {
        assert_true(res->plot_made);
        assert_true(file_size(dir, "compare.png") > 0);
    } else {
        printf("compare: matplotlib not importable, compare.png not checked\n");
    }
}

static void symmetric_top_precession(void **state)
{
    (void)state;
    (void)verify_open; /* shared helper; this case goes through cf_compare_run */
    verify_begin("compare");
    char dir[64];
    cf_compare_result res;
    run_compare("spinning_top.lua", dir, &res);
    assert_true(res.top);
    assert_int_equal(res.reference, CF_CMP_REF_FREE_FALL);
    int ok = verify_figure("compare", "top precession rate, Bullet (rad/s)",
                           res.omega_measured[CF_CMP_BULLET], res.omega_p, TOP_TOL_BULLET,
                           "rad/s");
    ok &= verify_figure("compare", "top precession rate, pbd (rad/s)",
                        res.omega_measured[CF_CMP_PBD], res.omega_p, TOP_TOL_PBD, "rad/s");
    verify_figure("compare", "top angular momentum drift, Bullet (reported)",
                  res.l_drift_final[CF_CMP_BULLET], 0, 0, "");
    verify_figure("compare", "top angular momentum drift, pbd (reported)",
                  res.l_drift_final[CF_CMP_PBD], 0, 0, "");
    verify_figure("compare", "top wall time pbd / Bullet (reported)",
                  res.wall[CF_CMP_PBD] / res.wall[CF_CMP_BULLET], 0, 0, "");
    remove_outputs(dir);
    assert_true(ok);
}

static void bullet_free_fall(void **state)
{
    (void)state;
    char dir[64];
    cf_compare_result res;
    run_compare("free_fall.lua", dir, &res);
    assert_int_equal(res.reference, CF_CMP_REF_FREE_FALL);
    /* the scene: dt_rigid 1e-3 s, 5 sub-steps, g = 9.81 m/s^2 */
    double h = 1e-3 / 5, g = 9.81, T = res.duration;
    double expected = 0.5 * g * T * h;
    int ok = verify_figure("compare", "free fall: Bullet error / (g t h / 2)",
                           res.ref_err_final[CF_CMP_BULLET] / expected, 1.0, 1e-8, "");
    verify_figure("compare", "free fall: Bullet error at 1 s (reported, m)",
                  res.ref_err_final[CF_CMP_BULLET], 0, 0, "m");
    /* the pbd rigid step is the same integrator with h = dt_rigid */
    verify_figure("compare", "free fall: pbd error / (g t dt / 2) (reported)",
                  res.ref_err_final[CF_CMP_PBD] / (0.5 * g * T * 1e-3), 1.0, 0, "");
    remove_outputs(dir);
    assert_true(ok);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(symmetric_top_precession),
                                       cmocka_unit_test(bullet_free_fall)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
