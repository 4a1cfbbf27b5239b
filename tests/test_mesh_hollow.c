/* cf_mesh_hollow: the shell of a structured box, node renumbering, groups
 * and the errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "check.h"
#include "cohfrac/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A 1 m cube centred at the origin in n^3 cells of 6 Kuhn tets. */
static void cube(int n, cf_mesh *m)
{
    const double size[3] = {1.0, 1.0, 1.0};
    const int cells[3] = {n, n, n};
    cf_error e = {0};
    if (cf_mesh_box(size, cells, 6, m, &e) != CF_OK)
        fail_msg("cf_mesh_box: %s", e.msg);
}

/* Every tet index in range, every node used, every tet positive. */
static void assert_valid(const cf_mesh *m)
{
    cf_error e = {0};
    char *used = calloc((size_t)m->n_nodes, 1);
    assert_non_null(used);
    for (int i = 0; i < 4 * m->n_tets; i++) {
        assert_in_range(m->tets[i], 0, m->n_nodes - 1);
        used[m->tets[i]] = 1;
    }
    for (int i = 0; i < m->n_nodes; i++)
        if (!used[i])
            fail_msg("node %d is used by no tet", i);
    free(used);
    if (cf_mesh_check(m, "hollow", &e) != CF_OK)
        fail_msg("%s", e.msg);
}

/* Grid index (0..n) of a coordinate of the unit cube centred at 0. */
static int grid(double c, int n)
{
    return (int)lround((c + 0.5) * n);
}

/* 6^3 cells, one layer: exactly the outer shell of cells (every Kuhn tet
 * of a cell uses the cell's lowest and highest corner, so each boundary
 * cell is kept whole and no inner cell has a boundary node). */
static void test_one_layer(void **state)
{
    cf_mesh m, solid;
    cf_error e = {0};
    const int n = 6;
    (void)state;
    cube(n, &m);
    cube(n, &solid);
    assert_int_equal(cf_mesh_hollow(&m, 1, &e), CF_OK);
    assert_valid(&m);

    /* Volume 1 - (4/6)^3 = 19/27 m^3; 216 - 64 cells of 6 tets. */
    assert_near(cf_mesh_volume(&m), 19.0 / 27.0, 1e-12);
    assert_int_equal(m.n_tets, (216 - 64) * 6);
    /* Nodes: the 7^3 grid less its 3^3 interior nodes (indices 2..4). */
    assert_int_equal(m.n_nodes, 343 - 27);

    /* No tet inside: every centroid lies in a boundary cell. */
    for (int t = 0; t < m.n_tets; t++) {
        double c[3] = {0, 0, 0};
        int in_shell = 0;
        for (int j = 0; j < 4; j++)
            for (int k = 0; k < 3; k++)
                c[k] += 0.25 * m.x[3 * m.tets[4 * t + j] + k];
        for (int k = 0; k < 3; k++) {
            int cell = (int)floor((c[k] + 0.5) * n);
            in_shell |= cell == 0 || cell == n - 1;
        }
        if (!in_shell)
            fail_msg("tet %d (centroid %g %g %g) is inside the shell", t, c[0], c[1], c[2]);
    }

    /* Renumbered in the old order: node positions are the solid's grid
     * nodes with the interior ones skipped, ascending in the grid index. */
    {
        int prev = -1;
        for (int i = 0; i < m.n_nodes; i++) {
            int gi = grid(m.x[3 * i], n), gj = grid(m.x[3 * i + 1], n), gk = grid(m.x[3 * i + 2], n);
            int old = (gk * (n + 1) + gj) * (n + 1) + gi;
            int interior = gi >= 2 && gi <= 4 && gj >= 2 && gj <= 4 && gk >= 2 && gk <= 4;
            assert_false(interior);
            assert_true(old > prev);
            assert_memory_equal(&m.x[3 * i], &solid.x[3 * old], 3 * sizeof(double));
            prev = old;
        }
    }
    cf_mesh_free(&m);
    cf_mesh_free(&solid);
}

/* Two layers on 6^3: the outer two cells; three would remove nothing. */
static void test_two_layers_and_too_many(void **state)
{
    cf_mesh m;
    cf_error e = {0};
    (void)state;
    cube(6, &m);
    assert_int_equal(cf_mesh_hollow(&m, 2, &e), CF_OK);
    assert_valid(&m);
    assert_near(cf_mesh_volume(&m), 26.0 / 27.0, 1e-12);
    assert_int_equal(m.n_tets, (216 - 8) * 6);
    assert_int_equal(m.n_nodes, 343 - 1);
    cf_mesh_free(&m);

    cube(6, &m);
    assert_int_equal(cf_mesh_hollow(&m, 3, &e), CF_ERR_SCENE_VALUE);
    assert_int_equal(e.code, CF_ERR_SCENE_VALUE);
    assert_non_null(strstr(e.msg, "nothing would be removed"));
    /* Left as it was. */
    assert_int_equal(m.n_tets, 216 * 6);
    assert_int_equal(m.n_nodes, 343);
    assert_int_equal(cf_mesh_hollow(&m, 0, &e), CF_ERR_SCENE_VALUE);
    assert_non_null(strstr(e.msg, "layers must be >= 1"));
    assert_int_equal(m.n_tets, 216 * 6);
    cf_mesh_free(&m);

    /* Too coarse to have an inside at all. */
    cube(2, &m);
    assert_int_equal(cf_mesh_hollow(&m, 1, NULL), CF_ERR_SCENE_VALUE);
    assert_int_equal(m.n_tets, 8 * 6);
    cf_mesh_free(&m);

    /* No tets: nothing to keep. */
    memset(&m, 0, sizeof m);
    assert_int_equal(cf_mesh_hollow(&m, 1, &e), CF_ERR_SCENE_VALUE);
    assert_non_null(strstr(e.msg, "nothing would be kept"));
}

/* Node groups lose the dropped nodes and follow the renumbering; nodes no
 * tet used are dropped too. */
static void test_groups(void **state)
{
    cf_mesh m;
    cf_error e = {0};
    const int n = 6, centre = (3 * 7 + 3) * 7 + 3, corner = 0, edge = 1, inner = (2 * 7 + 2) * 7 + 2;
    double cx[3], kx[3], ex[3];
    (void)state;
    cube(n, &m);
    memcpy(cx, &m.x[3 * corner], sizeof cx);
    memcpy(ex, &m.x[3 * edge], sizeof ex);
    memcpy(kx, &m.x[3 * (inner - 1)], sizeof kx); /* (1,2,2): kept, an inner-cell node */
    m.n_groups = 2;
    m.groups = calloc(2, sizeof *m.groups);
    assert_non_null(m.groups);
    strcpy(m.groups[0].name, "mixed");
    m.groups[0].dim = 2;
    m.groups[0].n_nodes = 5;
    m.groups[0].nodes = malloc(5 * sizeof(int));
    assert_non_null(m.groups[0].nodes);
    memcpy(m.groups[0].nodes, (const int[]){corner, edge, inner - 1, inner, centre}, 5 * sizeof(int));
    strcpy(m.groups[1].name, "core");
    m.groups[1].dim = 0;
    m.groups[1].n_nodes = 2;
    m.groups[1].nodes = malloc(2 * sizeof(int));
    assert_non_null(m.groups[1].nodes);
    memcpy(m.groups[1].nodes, (const int[]){inner, centre}, 2 * sizeof(int));

    assert_int_equal(cf_mesh_hollow(&m, 1, &e), CF_OK);
    assert_valid(&m);
    assert_int_equal(m.n_groups, 2);
    assert_int_equal(m.groups[0].n_nodes, 3);
    assert_memory_equal(&m.x[3 * m.groups[0].nodes[0]], cx, sizeof cx);
    assert_memory_equal(&m.x[3 * m.groups[0].nodes[1]], ex, sizeof ex);
    assert_memory_equal(&m.x[3 * m.groups[0].nodes[2]], kx, sizeof kx);
    assert_true(m.groups[0].nodes[0] < m.groups[0].nodes[1]);
    assert_true(m.groups[0].nodes[1] < m.groups[0].nodes[2]);
    assert_int_equal(m.groups[1].n_nodes, 0);
    assert_null(m.groups[1].nodes);
    assert_string_equal(m.groups[1].name, "core");
    cf_mesh_free(&m);

    /* An isolated node (no tet) goes away. */
    cube(n, &m);
    {
        double *x = realloc(m.x, (size_t)(m.n_nodes + 1) * 3 * sizeof(double));
        assert_non_null(x);
        m.x = x;
        x[3 * m.n_nodes] = 5, x[3 * m.n_nodes + 1] = 5, x[3 * m.n_nodes + 2] = 5;
        m.n_nodes++;
    }
    assert_int_equal(cf_mesh_hollow(&m, 1, &e), CF_OK);
    assert_valid(&m);
    assert_int_equal(m.n_nodes, 343 - 27);
    cf_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_layer),
        cmocka_unit_test(test_two_layers_and_too_many),
        cmocka_unit_test(test_groups),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
