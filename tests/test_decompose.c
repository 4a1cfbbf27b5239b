/* Convex decomposition of fragments into tet-cluster hulls (docs/physics.md §9). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "decompose.h"
#include "fixtures.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static const cf_material mat = {1e6, 0.3, 2400, 22, 22, 1e3, 1e3, 2, 2, 0.5, 0, 0, 10, 1, 0, 0, 0, 0, 0, 0, 0};

/* A 2 x 2 x 1 block of unit cells; the tets of the first three cells form
 * an L whose convex hull is 3.5 against a volume of 3. */
static void l_shape(cf_solid *s, int **tets, int *nt)
{
    cf_mesh m;
    fixture_box(&m, 2, 2, 1, 2.0, 2.0, 1.0);
    int *body = calloc((size_t)m.n_tets, sizeof(int));
    assert_int_equal(cf_solid_init(s, &m, &mat, body, NULL), CF_OK);
    free(body), cf_mesh_free(&m);
    *nt = 18; /* cells (0,0), (1,0), (0,1); cell (1,1) is tets 18..23 */
    *tets = malloc((size_t)*nt * sizeof(int));
    for (int t = 0; t < *nt; t++)
        (*tets)[t] = t;
}

/* Whether p lies inside at least one hull, judged by the hull's support
 * along 26 directions (exact for the axis-aligned and diagonal faces here). */
static int inside_some_hull(const cf_hulls *h, const double p[3])
{
    for (int k = 0; k < h->n_hulls; k++) {
        int in = 1;
        for (int d = 0; d < 27 && in; d++) { /* the 26 directions of {-1,0,1}^3 */
            if (d == 13)
                continue;
            double dir[3] = {(d % 3) - 1.0, ((d / 3) % 3) - 1.0, (d / 9) - 1.0};
            double best = -INFINITY;
            for (int i = h->start[k]; i < h->start[k + 1]; i++) {
                const double *x = &h->pts[3 * i];
                best = fmax(best, x[0] * dir[0] + x[1] * dir[1] + x[2] * dir[2]);
            }
            in = p[0] * dir[0] + p[1] * dir[1] + p[2] * dir[2] <= best + 1e-12;
        }
        if (in)
            return 1;
    }
    return 0;
}

/* Cut far past any bound (an error below zero is never met), so that tets
 * are clipped by several planes each: the cells partition space, so the
 * hulls of the parts inside them hold the whole L, and their volumes add
 * up to its volume at least.  They hold 0.9999 of it here (the part not
 * traced: parts too flat for a hull are left out); the clip that dropped
 * crossing points past 12 made hulls of 0.959 of it. */
static void test_deep_cuts_lose_no_volume(void **state)
{
    (void)state;
    cf_solid s;
    int *tets, nt;
    l_shape(&s, &tets, &nt);
    cf_hulls h;
    assert_int_equal(cf_decompose(&s, tets, nt, -0.5, 48, 1, &h, NULL, NULL), 0);
    printf("FIGURE deep cuts: %d hulls, hull volume %.12g for a volume of %.12g\n", h.n_hulls,
           h.hull_volume, h.tet_volume);
    assert_true(h.n_hulls >= 16);
    assert_true(fabs(h.tet_volume - 3.0) < 1e-12);
    assert_true(h.hull_volume >= 3.0 * (1 - 1e-3));
    for (int t = 0; t < nt; t++)
        for (int j = 0; j < 4; j++)
            assert_true(inside_some_hull(&h, &s.X[3 * s.tet[4 * tets[t] + j]]));
    cf_hulls_free(&h);
    free(tets);
    cf_solid_free(&s);
}

/* One hull over the L: error = 3.5/3 - 1 = 1/6 exactly. */
static void test_single_hull_error_is_the_l_shapes_excess(void **state)
{
    (void)state;
    cf_solid s;
    int *tets, nt;
    l_shape(&s, &tets, &nt);
    cf_hulls h;
    assert_int_equal(cf_decompose(&s, tets, nt, 0.05, 1, 4, &h, NULL, NULL), 0);
    assert_int_equal(h.n_hulls, 1);
    assert_true(fabs(h.tet_volume - 3.0) < 1e-12);
    assert_true(fabs(h.hull_volume - 3.5) < 1e-12);
    assert_true(fabs(cf_hulls_error(&h) - 1.0 / 6.0) < 1e-12);
    cf_hulls_free(&h);
    free(tets);
    cf_solid_free(&s);
}

static void count_cut(void *user) { ++*(int *)user; }

/* Bisection along the L's principal spread cuts it into two convex
 * quadrilateral prisms: the bound holds and is met exactly, and the hulls
 * still cover every node.  The heartbeat comes once per cut (one cell
 * more each) and changes nothing: the same hulls without it. */
static void test_decomposition_meets_the_error_bound(void **state)
{
    (void)state;
    cf_solid s;
    int *tets, nt, cuts = 0;
    l_shape(&s, &tets, &nt);
    cf_hulls h, quiet;
    assert_int_equal(cf_decompose(&s, tets, nt, 0.05, 8, 4, &h, count_cut, &cuts), 0);
    assert_int_equal(cf_decompose(&s, tets, nt, 0.05, 8, 4, &quiet, NULL, NULL), 0);
    assert_true(h.n_hulls >= 2 && h.n_hulls <= 8);
    assert_true(cuts >= h.n_hulls - 1 && cuts <= 7);
    assert_int_equal(quiet.n_hulls, h.n_hulls);
    assert_memory_equal(quiet.pts, h.pts, (size_t)h.start[h.n_hulls] * 3 * sizeof(double));
    cf_hulls_free(&quiet);
    assert_true(cf_hulls_error(&h) <= 0.05);
    assert_true(fabs(cf_hulls_error(&h)) < 1e-9);
    for (int t = 0; t < nt; t++)
        for (int j = 0; j < 4; j++)
            assert_true(inside_some_hull(&h, &s.X[3 * s.tet[4 * tets[t] + j]]));
    cf_hulls_free(&h);
    free(tets);
    cf_solid_free(&s);
}

/* A convex block needs one hull, with no error. */
static void test_convex_block_keeps_one_hull(void **state)
{
    (void)state;
    cf_solid s;
    cf_mesh m;
    fixture_box(&m, 3, 2, 2, 0.3, 0.2, 0.2);
    int *body = calloc((size_t)m.n_tets, sizeof(int));
    assert_int_equal(cf_solid_init(&s, &m, &mat, body, NULL), CF_OK);
    free(body), cf_mesh_free(&m);
    int *all = malloc((size_t)s.n_tets * sizeof(int));
    for (int t = 0; t < s.n_tets; t++)
        all[t] = t;
    cf_hulls h;
    assert_int_equal(cf_decompose(&s, all, s.n_tets, 0.05, 16, 4, &h, NULL, NULL), 0);
    assert_int_equal(h.n_hulls, 1);
    assert_int_equal(h.start[1], 8); /* the box's corners */
    assert_true(fabs(cf_hulls_error(&h)) < 1e-12);
    cf_hulls_free(&h);
    free(all);
    cf_solid_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_single_hull_error_is_the_l_shapes_excess),
        cmocka_unit_test(test_decomposition_meets_the_error_bound),
        cmocka_unit_test(test_deep_cuts_lose_no_volume),
        cmocka_unit_test(test_convex_block_keeps_one_hull),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
