/* The coloured PBD sweep and the Tet4 force scatter: four bars at a time as
 * vector lanes, and the work split between threads (the default count),
 * give exactly the bits of the plain formulas done one bar, one tet at a
 * time in the documented order. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "check.h"

#include "fixtures.h"
#include "pbd.h"
#include "tet4.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const cf_material mat = {1e6, 0.3, 2400, 22, 22, 1e3, 1e3, 2, 2, 0.5, 0, 0, 10, 1, 0, 0, 0, 0, 0, 0, 0};

/* A box of 12 x 10 x 10 hexahedra in Tet4 (above the parallel thresholds of
 * bars and tets), its nodes moved off the rest shape by up to 5 %.  Returns
 * the list of all its tets, ascending (free it). */
static int *strained_box(cf_solid *s, cf_mesh *m)
{
    fixture_box(m, 12, 10, 10, 0.6, 0.5, 0.5);
    int *body = calloc((size_t)m->n_tets, sizeof(int));
    assert_int_equal(cf_solid_init(s, m, &mat, body, NULL), CF_OK);
    free(body);
    unsigned long long r = 987654321;
    for (int i = 0; i < 3 * s->n_nodes; i++) {
        r = r * 6364136223846793005ull + 1442695040888963407ull;
        s->x[i] = s->X[i] * (1 + 0.05 * ((double)(r >> 11) / 9007199254740992.0 - 0.5));
    }
    assert_true(s->n_tets >= CF_TET4_PARALLEL_MIN);
    int *all = malloc((size_t)s->n_tets * sizeof(int));
    for (int t = 0; t < s->n_tets; t++)
        all[t] = t;
    return all;
}

/* Bar i projected alone (docs/physics.md §7): C = |p1 - p2| - rest, moved
 * by -w1/(w1+w2) and +w2/(w1+w2) of k C along p1 - p2. */
static void one_bar(const cf_bars *b, double *p, double k, int i)
{
    double *p1 = &p[4 * b->ends[2 * i]], *p2 = &p[4 * b->ends[2 * i + 1]], d[3];
    double w1 = p1[3], w2 = p2[3]; /* rows x y z 1/m */
    for (int c = 0; c < 3; c++)
        d[c] = p1[c] - p2[c];
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (len == 0)
        return;
    double c = k * (len - b->rest[i]) / ((w1 + w2) * len);
    for (int q = 0; q < 3; q++) {
        p1[q] += -w1 * c * d[q];
        p2[q] += w2 * c * d[q];
    }
}

static void test_sweep_equals_one_bar_at_a_time(void **state)
{
    (void)state;
    cf_mesh m;
    cf_solid s;
    int *all = strained_box(&s, &m);
    cf_bars b = {0};
    assert_int_equal(cf_bars_build(&b, &s, all, s.n_tets), 0);
    assert_true(b.n >= CF_BARS_PARALLEL_MIN);
    int partial = 0; /* a colour whose size is no multiple of four */
    for (int c = 0; c < b.n_colors; c++)
        partial |= (b.color_start[c + 1] - b.color_start[c]) % 4 != 0;
    assert_true(partial);
    size_t rows = (size_t)s.n_nodes * 4 * sizeof(double);
    for (int a = 0; a < s.n_nodes; a++) {
        memcpy(&s.p[4 * a], &s.x[3 * a], 3 * sizeof(double));
        s.p[4 * a + 3] = 1.0 / s.m[a];
    }
    b.rest[b.color_start[1]] = 0.0; /* a bar of rest length 0 */
    int z = b.color_start[2]; /* and a bar of length zero, left alone */
    memcpy(&s.p[4 * b.ends[2 * z]], &s.p[4 * b.ends[2 * z + 1]], 3 * sizeof(double));
    double *want = malloc(rows);
    memcpy(want, s.p, rows);
    for (int it = 0; it < 3; it++) {
        for (int i = 0; i < b.n; i++) /* colour by colour, each colour in order */
            one_bar(&b, want, 0.9, i);
        cf_bars_project(&b, &s, 0.9, NULL, NULL);
        assert_memory_equal(s.p, want, rows);
    }
    /* The sweep moved the nodes: the comparison is not of untouched arrays. */
    int moved = 0;
    for (int a = 0; a < s.n_nodes; a++)
        moved += memcmp(&s.p[4 * a], &s.x[3 * a], 3 * sizeof(double)) != 0;
    assert_true(moved > 0);
    free(want), free(all);
    cf_bars_free(&b);
    cf_solid_free(&s), cf_mesh_free(&m);
}

static void test_scatter_equals_the_tet_order_sum(void **state)
{
    (void)state;
    cf_mesh m;
    cf_solid s;
    int *all = strained_box(&s, &m), *nodes = malloc((size_t)s.n_nodes * sizeof(int));
    for (int i = 0; i < s.n_nodes; i++)
        nodes[i] = (5 * i) % s.n_nodes; /* the list in no particular order */
    assert_int_equal(s.n_nodes % 5 != 0, 1);
    cf_tet4_forces(&s, all, s.n_tets, CF_ELASTICITY_COROTATIONAL, NULL, 0, NULL);
    const double g[3] = {0.1, -0.2, -9.81};
    double *want = malloc((size_t)s.n_nodes * 3 * sizeof(double));
    for (int a = 0; a < s.n_nodes; a++)
        for (int k = 0; k < 3; k++)
            want[3 * a + k] = s.m[a] * g[k];
    for (int t = 0; t < s.n_tets; t++)
        for (int j = 0; j < 4; j++)
            for (int k = 0; k < 3; k++)
                want[3 * s.tet[4 * t + j] + k] += s.tf[12 * t + 3 * j + k];
    cf_tet4_scatter(&s, all, s.n_tets, nodes, s.n_nodes, g);
    assert_memory_equal(s.f, want, (size_t)s.n_nodes * 3 * sizeof(double));
    /* Internal forces balance: the sum is the weight (closed form). */
    double sum[3] = {0, 0, 0}, mass = 0;
    for (int a = 0; a < s.n_nodes; a++) {
        mass += s.m[a];
        for (int k = 0; k < 3; k++)
            sum[k] += s.f[3 * a + k];
    }
    for (int k = 0; k < 3; k++)
        assert_near(sum[k], mass * g[k], 1e-9 * mass * 10);
    free(want), free(all), free(nodes);
    cf_solid_free(&s), cf_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sweep_equals_one_bar_at_a_time),
        cmocka_unit_test(test_scatter_equals_the_tet_order_sum),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
