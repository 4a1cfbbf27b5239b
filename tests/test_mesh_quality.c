/* The quality that sets the explicit step, and peeling boundary slivers:
 * closed-form angles and volumes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cohfrac/mesh.h"

/* The Kuhn cube: six congruent tets with dihedral angles of 45, 60 and 90
 * degrees, so the smallest is 45 and every tet sets the same step. */
static void test_kuhn_cube_quality(void **state)
{
    (void)state;
    cf_mesh m = {0};
    cf_error err;
    assert_int_equal(cf_mesh_box((double[3]){1, 1, 1}, (int[3]){1, 1, 1}, 6, &m, &err), CF_OK);
    cf_mesh_quality q = cf_mesh_quality_of(&m);
    assert_true(fabs(q.min_dihedral - 45.0) < 1e-9);
    assert_true(fabs(q.dt_ratio - 1.0) < 1e-12);
    int peeled = -1;
    double volume = -1;
    assert_int_equal(cf_mesh_peel_slivers(&m, 0.25, &peeled, &volume, &err), CF_OK);
    assert_int_equal(peeled, 0);
    assert_int_equal(m.n_tets, 6);
    cf_mesh_free(&m);
}

/* A square pyramid (two tets under the square a b c d, apex e below) with a
 * cap of height delta on top: the tet (a, b, c, d) whose faces abd and bcd
 * are the surface.  Peeling removes the cap alone (the surface flips from
 * bd to ac), the volume falls by delta / 6, and the step is set by a
 * pyramid tet again. */
static void test_peel_boundary_cap(void **state)
{
    (void)state;
    const double delta = 1e-2;
    double x[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, delta, 0.5, 0.5, -1};
    int tets[] = {0, 1, 2, 4, 0, 2, 3, 4, 0, 1, 2, 3};
    cf_mesh m = {5, 3, malloc(sizeof x), malloc(sizeof tets), 0, NULL};
    assert_non_null(m.x);
    assert_non_null(m.tets);
    memcpy(m.x, x, sizeof x), memcpy(m.tets, tets, sizeof tets);
    cf_mesh_orient_positive(&m);
    double before = cf_mesh_volume(&m);
    cf_mesh_quality q = cf_mesh_quality_of(&m);
    assert_int_equal(q.worst_tet, 2);
    assert_true(q.dt_ratio < 0.05);

    cf_error err;
    int peeled = -1;
    double volume = -1;
    assert_int_equal(cf_mesh_peel_slivers(&m, 0.25, &peeled, &volume, &err), CF_OK);
    assert_int_equal(peeled, 1);
    assert_int_equal(m.n_tets, 2);
    assert_int_equal(m.n_nodes, 5);
    assert_true(fabs(volume - delta / 6) < 1e-15);
    assert_true(fabs(before - cf_mesh_volume(&m) - delta / 6) < 1e-15);
    assert_true(cf_mesh_quality_of(&m).dt_ratio > 0.9);
    assert_int_equal(cf_mesh_check(&m, "peeled", &err), CF_OK);
    cf_mesh_free(&m);
}

/* A mesh of one flat tet is left alone: nothing would remain. */
static void test_peel_keeps_a_lone_tet(void **state)
{
    (void)state;
    double x[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 1e-3};
    int tets[] = {0, 1, 2, 3};
    cf_mesh m = {4, 1, malloc(sizeof x), malloc(sizeof tets), 0, NULL};
    assert_non_null(m.x);
    assert_non_null(m.tets);
    memcpy(m.x, x, sizeof x), memcpy(m.tets, tets, sizeof tets);
    cf_error err;
    int peeled = -1;
    double volume = -1;
    assert_int_equal(cf_mesh_peel_slivers(&m, 0.25, &peeled, &volume, &err), CF_OK);
    assert_int_equal(peeled, 0);
    assert_int_equal(m.n_tets, 1);
    cf_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kuhn_cube_quality),
        cmocka_unit_test(test_peel_boundary_cap),
        cmocka_unit_test(test_peel_keeps_a_lone_tet),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
