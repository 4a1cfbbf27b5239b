/* TetGen .node/.ele reading, volumes and the error messages of bad input. */
#define _XOPEN_SOURCE 700 /* mkdtemp */

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fixtures.h"
#include "cohfrac/mesh.h"

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/cohfrac-test-mesh-XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    fixture_remove_tree(tmpdir);
    return 0;
}

/* Write `text` to <tmpdir>/<name>; returns the path (static buffer). */
static const char *put(const char *name, const char *text)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

static const char *base(const char *name)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    return path;
}

/* Two tets on the facet (0,1,2) with apexes above and below, each of
 * volume 1/6 (base area 1/2, height 1). */
static const double two_x[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.2, 0.2, 1}, {0.3, 0.3, -1}};
static const int two_t[2][4] = {{0, 1, 2, 3}, {0, 2, 1, 4}};

static void check_two(const cf_mesh *m)
{
    assert_int_equal(m->n_nodes, 5);
    assert_int_equal(m->n_tets, 2);
    for (int i = 0; i < 5; i++)
        for (int k = 0; k < 3; k++)
            assert_true(m->x[3 * i + k] == two_x[i][k]);
    for (int t = 0; t < 2; t++)
        for (int k = 0; k < 4; k++)
            assert_int_equal(m->tets[4 * t + k], two_t[t][k]);
    assert_true(fabs(cf_mesh_volume(m) - 1.0 / 3.0) < 1e-15);
}

static void test_zero_based_with_comments(void **state)
{
    (void)state;
    put("two0.node", "# nodes with one attribute and a boundary marker\n"
                     "5  3  1  1\n"
                     "\n"
                     "0  0.0 0.0 0.0   7.5  1   # corner\n"
                     "1  1.0 0.0 0.0   7.5  1\n"
                     "2  0.0 1.0 0.0   7.5  1\n"
                     "   # an indented comment line\n"
                     "3  0.2 0.2 1.0   7.5  0\n"
                     "4  0.3 0.3 -1e0  7.5  0\n");
    put("two0.ele", "2 4 1   # one region attribute\n"
                    "0  0 1 2 3  1\n"
                    "1  0 2 1 4  2\n");
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_tetgen(base("two0"), &m, &err), CF_OK);
    check_two(&m);
    cf_mesh_free(&m);
}

static void test_one_based_and_extension(void **state)
{
    (void)state;
    put("two1.node", "5 3 0 0\n"
                     "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0.2 0.2 1\n5 0.3 0.3 -1\n");
    put("two1.ele", "# 1-based\n2 4 0\n1 1 2 3 4\n2 1 3 2 5\n");
    cf_mesh m;
    cf_error err = {0};
    /* the base may be given with either extension */
    assert_int_equal(cf_mesh_load_tetgen(base("two1.ele"), &m, &err), CF_OK);
    check_two(&m);
    cf_mesh_free(&m);
    assert_int_equal(cf_mesh_load_tetgen(base("two1.node"), &m, &err), CF_OK);
    check_two(&m);
    cf_mesh_free(&m);
}

/* Unit cube, corners numbered by bits (x = bit 0, y = bit 1, z = bit 2). */
static void cube_nodes(double x[8][3])
{
    for (int i = 0; i < 8; i++)
        x[i][0] = i & 1, x[i][1] = (i >> 1) & 1, x[i][2] = (i >> 2) & 1;
}

static void test_cube_volume_exact(void **state)
{
    (void)state;
    double x[8][3];
    cube_nodes(x);
    /* 5 tets: the regular tet (0,3,5,6) in the middle and the four corners
     * 1, 2, 4, 7 cut off, each with its three neighbours. */
    int cut5[5][4] = {{1, 0, 3, 5}, {2, 0, 6, 3}, {4, 0, 5, 6}, {7, 3, 6, 5}, {0, 3, 5, 6}};
    cf_mesh m = {.n_nodes = 8, .n_tets = 5, .x = &x[0][0], .tets = &cut5[0][0]};
    double expect_corner = 1.0 / 6.0, expect_centre = 1.0 / 3.0;
    for (int t = 0; t < 5; t++) {
        const int *T = cut5[t];
        double v = cf_tet_volume(x[T[0]], x[T[1]], x[T[2]], x[T[3]]);
        if (v < 0) { /* orient positively by swapping two nodes */
            int s = cut5[t][2];
            cut5[t][2] = cut5[t][3], cut5[t][3] = s;
            v = -v;
        }
        assert_true(fabs(v - (t == 4 ? expect_centre : expect_corner)) < 1e-15);
    }
    cf_error err = {0};
    assert_int_equal(cf_mesh_check(&m, "cube5", &err), CF_OK);
    assert_true(cf_mesh_volume(&m) == 1.0); /* exactly: determinants sum to 6 */

    /* 6 tets around the main diagonal 0-7 (Kuhn): each 1/6. */
    int six[6][4];
    static const int path[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
    for (int t = 0; t < 6; t++) {
        six[t][0] = 0, six[t][1] = path[t][0], six[t][2] = path[t][1], six[t][3] = 7;
        if (cf_tet_volume(x[0], x[six[t][1]], x[six[t][2]], x[7]) < 0) {
            int s = six[t][1];
            six[t][1] = six[t][2], six[t][2] = s;
        }
    }
    cf_mesh k = {.n_nodes = 8, .n_tets = 6, .x = &x[0][0], .tets = &six[0][0]};
    assert_int_equal(cf_mesh_check(&k, "cube6", &err), CF_OK);
    assert_true(cf_mesh_volume(&k) == 1.0);
    /* with two tets inverted the signed total is 4/6 - 2/6 */
    int s = six[0][1];
    six[0][1] = six[0][2], six[0][2] = s;
    s = six[1][1];
    six[1][1] = six[1][2], six[1][2] = s;
    assert_true(fabs(cf_mesh_volume(&k) - 1.0 / 3.0) < 1e-15);
    assert_int_equal(cf_mesh_orient_positive(&k), 2);
    assert_true(cf_mesh_volume(&k) == 1.0);
}

static void test_write_read_roundtrip(void **state)
{
    (void)state;
    double x[5][3];
    memcpy(x, two_x, sizeof x);
    x[3][0] = 0.1 + 0.2; /* not exactly representable in short decimal */
    x[4][2] = -1.0 / 3.0;
    int t[2][4];
    memcpy(t, two_t, sizeof t);
    cf_mesh m = {.n_nodes = 5, .n_tets = 2, .x = &x[0][0], .tets = &t[0][0]}, r;
    cf_error err = {0};
    assert_int_equal(cf_mesh_write_tetgen(&m, base("rt"), &err), CF_OK);
    assert_int_equal(cf_mesh_load_tetgen(base("rt"), &r, &err), CF_OK);
    assert_int_equal(r.n_nodes, 5);
    assert_int_equal(r.n_tets, 2);
    assert_memory_equal(r.x, &x[0][0], sizeof x); /* bit-exact */
    assert_memory_equal(r.tets, &t[0][0], sizeof t);
    cf_mesh_free(&r);
}

/* ---- one test per error ---- */

static void test_missing_file(void **state)
{
    (void)state;
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_tetgen(base("nothere"), &m, &err), CF_ERR_FILE_OPEN);
    assert_int_equal(err.code, CF_ERR_FILE_OPEN);
    assert_non_null(strstr(err.msg, "nothere.node"));
    assert_null(m.x);
    assert_int_equal(m.n_nodes, 0);
    /* .node present, .ele missing */
    put("half.node", "1 3 0 0\n0 0 0 0\n");
    assert_int_equal(cf_mesh_load_tetgen(base("half"), &m, &err), CF_ERR_FILE_OPEN);
    assert_non_null(strstr(err.msg, "half.ele"));
    assert_null(m.x);
}

static void test_truncated_file(void **state)
{
    (void)state;
    put("trunc.node", "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0.2 0.2 1\n");
    put("trunc.ele", "1 4 0\n0 0 1 2 3\n");
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_tetgen(base("trunc"), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "trunc.node:"));
    assert_non_null(strstr(err.msg, "4 of 5 nodes"));
    assert_null(m.x);
    assert_null(m.tets);
    /* a short line: the node on line 3 lacks z */
    put("short.node", "2 3 0 0\n0 0 0 0\n1 1 0\n");
    put("short.ele", "0 4 0\n");
    assert_int_equal(cf_mesh_load_tetgen(base("short"), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "short.node:3:"));
}

static void test_garbage_line(void **state)
{
    (void)state;
    put("junk.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0.2 zz 1\n");
    put("junk.ele", "1 4 0\n0 0 1 2 3\n");
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_tetgen(base("junk"), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "junk.node:5:"));
    assert_non_null(strstr(err.msg, "'zz'"));
    /* quadratic tets are refused with a hint */
    put("quad.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
    put("quad.ele", "1 10 0\n0 0 1 2 3 0 1 2 3 0 1\n");
    assert_int_equal(cf_mesh_load_tetgen(base("quad"), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "quad.ele:1:"));
    assert_non_null(strstr(err.msg, "-o2"));
}

static void test_index_out_of_range(void **state)
{
    (void)state;
    put("oor.node", "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0.2 0.2 1\n4 0.3 0.3 -1\n");
    put("oor.ele", "2 4 0\n0 0 1 2 3\n# second tet\n1 0 2 1 5\n");
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_tetgen(base("oor"), &m, &err), CF_ERR_MESH_INDEX);
    assert_non_null(strstr(err.msg, "oor.ele:4:"));
    assert_non_null(strstr(err.msg, "tet 1"));
    assert_non_null(strstr(err.msg, "node 5"));
    assert_null(m.tets);
    /* 1-based file: node 0 does not exist */
    put("oor1.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
    put("oor1.ele", "1 4 0\n1 0 1 2 3\n");
    assert_int_equal(cf_mesh_load_tetgen(base("oor1"), &m, &err), CF_ERR_MESH_INDEX);
    assert_non_null(strstr(err.msg, "tet 0"));
}

static void test_inverted_tet(void **state)
{
    (void)state;
    put("inv.node", "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0.2 0.2 1\n4 0.3 0.3 -1\n");
    /* tet 1 has its apex below the facet (0,1,2) listed counter-clockwise */
    put("inv.ele", "2 4 0\n0 0 1 2 3\n1 0 1 2 4\n");
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_tetgen(base("inv"), &m, &err), CF_ERR_MESH_INVERTED);
    assert_non_null(strstr(err.msg, "tet 1"));
    assert_non_null(strstr(err.msg, "inverted"));
    assert_non_null(strstr(err.msg, "-0.167")); /* its volume, m^3 */
    assert_null(m.x);
    /* a flat tet is degenerate, not inverted */
    put("flat.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 1 1 0\n");
    put("flat.ele", "1 4 0\n0 0 1 2 3\n");
    assert_int_equal(cf_mesh_load_tetgen(base("flat"), &m, &err), CF_ERR_MESH_INVERTED);
    assert_non_null(strstr(err.msg, "tet 0"));
    assert_non_null(strstr(err.msg, "degenerate"));
    /* the unchecked loader reads it, and orienting fixes the inverted one */
    assert_int_equal(cf_mesh_load_tetgen_unchecked(base("inv"), &m, &err), CF_OK);
    assert_int_equal(cf_mesh_orient_positive(&m), 1);
    assert_int_equal(cf_mesh_check(&m, "inv", &err), CF_OK);
    assert_true(fabs(cf_mesh_volume(&m) - 1.0 / 3.0) < 1e-15);
    cf_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_zero_based_with_comments),
        cmocka_unit_test(test_one_based_and_extension),
        cmocka_unit_test(test_cube_volume_exact),
        cmocka_unit_test(test_write_read_roundtrip),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_truncated_file),
        cmocka_unit_test(test_garbage_line),
        cmocka_unit_test(test_index_out_of_range),
        cmocka_unit_test(test_inverted_tet),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
