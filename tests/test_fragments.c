/* Fragment mass properties, shape matching and global damping. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "check.h"

#include "fixtures.h"
#include "fragment.h"
#include "pieces.h"
#include "linalg.h"

#include <math.h>
#include <stdlib.h>

static const cf_material mat = {1e6, 0.3, 2400, 22, 22, 1e3, 1e3, 2, 2, 0.5, 0, 0, 10, 1, 0, 0, 0, 0, 0, 0, 0};

static void box_solid(cf_solid *s, int **all, double lx, double ly, double lz)
{
    cf_mesh m;
    fixture_box(&m, 3, 4, 5, lx, ly, lz);
    int *body = calloc((size_t)m.n_tets, sizeof(int));
    assert_int_equal(cf_solid_init(s, &m, &mat, body, NULL), CF_OK);
    free(body), cf_mesh_free(&m);
    *all = malloc((size_t)s->n_tets * sizeof(int));
    for (int t = 0; t < s->n_tets; t++)
        (*all)[t] = t;
}

/* A box's inertia from its tets equals m (b^2 + c^2)/12 etc. exactly. */
static void test_box_inertia_matches_analytic(void **state)
{
    (void)state;
    double lx = 0.3, ly = 0.5, lz = 0.7;
    cf_solid s;
    int *all;
    box_solid(&s, &all, lx, ly, lz);
    cf_mass_props mp;
    cf_tet_mass_props(&s, all, s.n_tets, s.X, &mp);
    double M = 2400 * lx * ly * lz;
    assert_near(mp.mass, M, 1e-12 * M);
    assert_near(mp.com[0], lx / 2, 1e-14);
    assert_near(mp.com[1], ly / 2, 1e-14);
    assert_near(mp.com[2], lz / 2, 1e-14);
    assert_near(mp.inertia[0], M * (ly * ly + lz * lz) / 12, 1e-12 * M);
    assert_near(mp.inertia[4], M * (lx * lx + lz * lz) / 12, 1e-12 * M);
    assert_near(mp.inertia[8], M * (lx * lx + ly * ly) / 12, 1e-12 * M);
    assert_near(mp.inertia[1], 0.0, 1e-12 * M);
    assert_near(mp.inertia[5], 0.0, 1e-12 * M);
    free(all), cf_solid_free(&s);
}

/* Shape matching recovers a known rotation; angular momentum of a rigid spin
 * gives back its angular velocity. */
static void test_shape_matching_recovers_rotation(void **state)
{
    (void)state;
    cf_solid s;
    int *all;
    box_solid(&s, &all, 0.3, 0.5, 0.7);
    double q[4] = {cos(1.1), 0.3 * sin(1.1), -0.4 * sin(1.1), sqrt(0.75) * sin(1.1)}, R[9];
    quat_normalize(q);
    quat_to_mat(q, R);
    double w[3] = {0.3, -2.0, 1.0}, c[3] = {1, 2, 3};
    for (int i = 0; i < s.n_nodes; i++) {
        double r[3];
        m3_mulv(R, &s.X[3 * i], r);
        for (int k = 0; k < 3; k++)
            s.x[3 * i + k] = r[k] + c[k];
    }
    cf_node_state ns0;
    int *nodes = malloc((size_t)s.n_nodes * sizeof(int));
    for (int i = 0; i < s.n_nodes; i++)
        nodes[i] = i;
    cf_nodes_momenta(&s, nodes, s.n_nodes, &ns0);
    for (int i = 0; i < s.n_nodes; i++) {
        double r[3], wr[3];
        v3_sub(&s.x[3 * i], ns0.com, r);
        v3_cross(w, r, wr);
        for (int k = 0; k < 3; k++)
            s.v[3 * i + k] = 0.5 + wr[k];
    }
    double qm[4] = {1, 0, 0, 0};
    cf_node_state ns;
    cf_nodes_state(&s, nodes, s.n_nodes, qm, &ns);
    for (int k = 0; k < 9; k++)
        assert_near(ns.R[k], R[k], 1e-10);
    double wout[3];
    cf_nodes_angular_velocity(&s, nodes, s.n_nodes, ns.com, ns.L, wout);
    for (int k = 0; k < 3; k++) {
        assert_near(wout[k], w[k], 1e-10);
        assert_near(ns.v[k], 0.5, 1e-12);
    }
    free(nodes), free(all), cf_solid_free(&s);
}

/* Global damping with k = 1 keeps only the rigid motion and preserves linear
 * and angular momentum to round-off. */
static void test_global_damping_preserves_momenta(void **state)
{
    (void)state;
    cf_solid s;
    int *all;
    box_solid(&s, &all, 0.3, 0.5, 0.7);
    int *nodes = malloc((size_t)s.n_nodes * sizeof(int));
    for (int i = 0; i < s.n_nodes; i++) {
        nodes[i] = i;
        for (int k = 0; k < 3; k++)
            s.v[3 * i + k] = sin(0.7 * i + 2.0 * k) + (k == 2 ? s.x[3 * i] : 0);
    }
    cf_node_state a, b;
    cf_nodes_momenta(&s, nodes, s.n_nodes, &a);
    cf_global_damping(&s, nodes, s.n_nodes, 1.0);
    cf_nodes_momenta(&s, nodes, s.n_nodes, &b);
    for (int k = 0; k < 3; k++) {
        assert_near(b.v[k], a.v[k], 1e-13);
        assert_near(b.L[k], a.L[k], 1e-12 * (fabs(a.L[0]) + fabs(a.L[1]) + fabs(a.L[2])));
    }
    assert_true(b.ke < a.ke); /* the deformation part is gone */
    /* Now rigid: a second pass changes nothing. */
    cf_global_damping(&s, nodes, s.n_nodes, 1.0);
    cf_node_state c;
    cf_nodes_momenta(&s, nodes, s.n_nodes, &c);
    assert_near(c.ke, b.ke, 1e-12 * b.ke);
    free(nodes), free(all), cf_solid_free(&s);
}

/* The quiet count of docs/physics.md §9: with growth 0 any insertion
 * restarts it; with growth 0.01 a fragment of 300 cohesive elements stays
 * quiet through 3 insertions since the last restart, and the 4th restarts
 * it (the elements it brings are counted too). */
static void test_quiet_through_a_trickle(void **state)
{
    (void)state;
    cf_fragment f = {.coh = {.n = 300}};
    for (int i = 0; i < 5; i++)
        cf_fragment_count_quiet(&f, 0, 0.0);
    assert_int_equal(f.quiet, 5);
    cf_fragment_count_quiet(&f, 1, 0.0);
    assert_int_equal(f.quiet, 0);
    assert_int_equal(f.grown, 0);
    for (int i = 0; i < 3; i++) { /* one insertion a step, 3 <= 0.01 x 301..303 */
        f.coh.n++;
        cf_fragment_count_quiet(&f, 1, 0.01);
        cf_fragment_count_quiet(&f, 0, 0.01);
    }
    assert_int_equal(f.quiet, 6);
    assert_int_equal(f.grown, 3);
    f.coh.n++;
    cf_fragment_count_quiet(&f, 1, 0.01); /* 4 > 0.01 x 304 */
    assert_int_equal(f.quiet, 0);
    assert_int_equal(f.grown, 0);
    cf_fragment_count_quiet(&f, 0, 0.01);
    assert_int_equal(f.quiet, 1);
}

/* Which pieces can split no further (docs/physics.md §9.2): with cracks
 * from fronts, a split leaves pieces of more than min_piece_tets tets and
 * at least the volume of a sphere of min_piece_size each, so a fragment
 * of fewer than twice that cannot split; crushing that cuts tets free, or
 * the source's rule (no piece bound), can still break it. */
static void test_pieces_too_small_to_split(void **state)
{
    (void)state;
    cf_solver_settings set = cf_default_solver();
    cf_material mat = cf_default_material();
    set.crack_growth = CF_GROWTH_FRONTS, set.min_piece_tets = 4;
    set.debris_tets = 0, set.debris_size = 0, set.min_piece_size = 0;
    mat.crushing_strain = 0;
    cf_fragment f = {.parent = 0, .volume = 1e-3};
    f.nt = 9; /* 4 + 5: one side would close a piece of 4 */
    assert_int_equal(cf_fragment_cannot_split(&f, &set, &mat), 1);
    f.nt = 10; /* 5 + 5 */
    assert_int_equal(cf_fragment_cannot_split(&f, &set, &mat), 0);
    set.min_piece_size = 0.1; /* pieces of at least pi/6 (0.1)^3 = 5.24e-4 m^3 each */
    assert_int_equal(cf_fragment_cannot_split(&f, &set, &mat), 1);
    f.volume = 1.1e-3;
    assert_int_equal(cf_fragment_cannot_split(&f, &set, &mat), 0);
    f.nt = 9;
    mat.crushing_strain = 0.05; /* crushing cuts single tets free */
    assert_int_equal(cf_fragment_cannot_split(&f, &set, &mat), 0);
    mat.crushing_strain = 0;
    set.crack_growth = CF_GROWTH_ALL; /* the source's rule closes any piece */
    assert_int_equal(cf_fragment_cannot_split(&f, &set, &mat), 0);
    set.debris_tets = 9; /* debris, whatever the rule */
    assert_int_equal(cf_fragment_cannot_split(&f, &set, &mat), 1);
    set.crack_growth = CF_GROWTH_FRONTS, set.debris_tets = 0;
    f.parent = -1; /* an initial body keeps its impact in fracture mode */
    assert_int_equal(cf_fragment_cannot_split(&f, &set, &mat), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box_inertia_matches_analytic),
        cmocka_unit_test(test_shape_matching_recovers_rotation),
        cmocka_unit_test(test_global_damping_preserves_momenta),
        cmocka_unit_test(test_pieces_too_small_to_split),
        cmocka_unit_test(test_quiet_through_a_trickle),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
