/* Point queries against triangle meshes (cf_fcl.h): closest point,
 * pseudo-normal and signed distance in the face, edge and vertex regions of
 * a cube, a non-convex prism checked against brute force, max_dist
 * rejection, a moved and sheared mesh after cff_mesh_update, the triangle
 * and barycentric coordinates of the closest point, concurrent queries and
 * bad input. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cf_fcl.h"

#define TOL 1e-12

/* Unit cube [-0.5, 0.5]^3: 8 corners (bit 0 -> x, 1 -> y, 2 -> z), 12
 * triangles counter-clockwise seen from outside. */
static const int CUBE_TRIS[12][3] = {
    {0, 2, 3}, {0, 3, 1}, /* z = -0.5 */
    {4, 5, 7}, {4, 7, 6}, /* z = +0.5 */
    {0, 1, 5}, {0, 5, 4}, /* y = -0.5 */
    {2, 6, 7}, {2, 7, 3}, /* y = +0.5 */
    {0, 4, 6}, {0, 6, 2}, /* x = -0.5 */
    {1, 3, 7}, {1, 7, 5}, /* x = +0.5 */
};

static void cube_verts(double v[8][3])
{
    for (int i = 0; i < 8; ++i) {
        v[i][0] = (i & 1) ? 0.5 : -0.5;
        v[i][1] = (i & 2) ? 0.5 : -0.5;
        v[i][2] = (i & 4) ? 0.5 : -0.5;
    }
}

static cff_mesh *make_cube(void)
{
    double v[8][3];
    cube_verts(v);
    cff_mesh *m = cff_mesh_create(&v[0][0], 8, &CUBE_TRIS[0][0], 12);
    assert_non_null(m);
    return m;
}

static void assert_vec(const double a[3], double x, double y, double z, double tol)
{
    if (fabs(a[0] - x) > tol || fabs(a[1] - y) > tol || fabs(a[2] - z) > tol)
        fail_msg("(%.17g, %.17g, %.17g) != (%.17g, %.17g, %.17g)", a[0], a[1], a[2], x, y, z);
}

/* One query with the expected closest point, normal and signed distance. */
static void expect(const cff_mesh *m, double px, double py, double pz, const double qe[3],
                   const double ne[3], double de)
{
    const double p[3] = {px, py, pz};
    double q[3], n[3], d = NAN;
    assert_int_equal(cff_mesh_closest(m, p, INFINITY, q, n, &d), 1);
    assert_vec(q, qe[0], qe[1], qe[2], TOL);
    assert_vec(n, ne[0], ne[1], ne[2], TOL);
    if (fabs(d - de) > TOL) fail_msg("d = %.17g, expected %.17g", d, de);
}

/* Face, edge and vertex regions in front of the cube, and points behind its
 * faces: closest points, pseudo-normals and distances in closed form. */
static void test_cube_regions(void **state)
{
    (void)state;
    cff_mesh *m = make_cube();
    const double r2 = sqrt(0.5), r3 = 1.0 / sqrt(3.0);

    /* Face region: the face normal, d = height above the face. */
    expect(m, 1.25, 0.1, -0.2, (double[]){0.5, 0.1, -0.2}, (double[]){1, 0, 0}, 0.75);
    expect(m, 0.1, -0.3, -2.0, (double[]){0.1, -0.3, -0.5}, (double[]){0, 0, -1}, 1.5);
    /* On a face's diagonal (an edge between two coplanar triangles): the
     * edge pseudo-normal is the face normal. */
    expect(m, 0.2, 0.9, 0.2, (double[]){0.2, 0.5, 0.2}, (double[]){0, 1, 0}, 0.4);
    /* Edge region: the mean of the two face normals, d = distance to the
     * edge line. */
    expect(m, 1.0, 1.0, 0.1, (double[]){0.5, 0.5, 0.1}, (double[]){r2, r2, 0}, sqrt(0.5));
    expect(m, -0.5 - 0.3, 0.25, 0.5 + 0.4, (double[]){-0.5, 0.25, 0.5},
           (double[]){-r2, 0, r2}, 0.5);
    /* Vertex region: three faces, each seen under 90 degrees (split in one
     * or two triangles) -> (1,1,1)/sqrt 3. */
    expect(m, 1.0, 1.0, 1.0, (double[]){0.5, 0.5, 0.5}, (double[]){r3, r3, r3}, sqrt(0.75));
    expect(m, -0.5 - 0.1, -0.5 - 0.2, -0.5 - 0.2, (double[]){-0.5, -0.5, -0.5},
           (double[]){-r3, -r3, -r3}, 0.3);
    /* Behind a face: negative distance to the nearest face. */
    expect(m, 0.3, 0.1, -0.05, (double[]){0.5, 0.1, -0.05}, (double[]){1, 0, 0}, -0.2);
    expect(m, -0.1, 0.05, -0.4, (double[]){-0.1, 0.05, -0.5}, (double[]){0, 0, -1}, -0.1);
    /* On the surface: d = 0, q = p. */
    expect(m, 0.5, 0.125, -0.25, (double[]){0.5, 0.125, -0.25}, (double[]){1, 0, 0}, 0.0);

    /* Centre: 0.5 behind every face; q is on one of them. */
    const double c[3] = {0, 0, 0};
    double q[3], n[3], d;
    assert_int_equal(cff_mesh_closest(m, c, 1.0, q, n, &d), 1);
    assert_true(fabs(d + 0.5) <= TOL);
    assert_true(fabs(fabs(q[0]) + fabs(q[1]) + fabs(q[2]) - 0.5) <= TOL);
    assert_true(fabs(q[0] * n[0] + q[1] * n[1] + q[2] * n[2] - 0.5) <= TOL);
    cff_mesh_destroy(m);
}

/* Nothing within max_dist gives 0 and leaves the outputs alone; the bound
 * is inclusive. */
static void test_max_dist(void **state)
{
    (void)state;
    cff_mesh *m = make_cube();
    const double far[3] = {3.0, 0.0, 0.0}, inside[3] = {0.0, 0.1, 0.0};
    double q[3] = {7, 7, 7}, n[3] = {7, 7, 7}, d = 7;
    assert_int_equal(cff_mesh_closest(m, far, 1.0, q, n, &d), 0);
    assert_int_equal(cff_mesh_closest(m, far, 2.4999, q, n, &d), 0);
    assert_true(q[0] == 7 && n[0] == 7 && d == 7);
    assert_int_equal(cff_mesh_closest(m, far, 2.5, q, n, &d), 1);
    assert_true(fabs(d - 2.5) <= TOL);
    assert_int_equal(cff_mesh_closest(m, far, 100.0, q, n, &d), 1);
    assert_vec(q, 0.5, 0, 0, TOL);
    /* Behind the surface the bound applies to |d|. */
    assert_int_equal(cff_mesh_closest(m, inside, 0.39, q, n, &d), 0);
    assert_int_equal(cff_mesh_closest(m, inside, 0.41, q, n, &d), 1);
    assert_true(fabs(d + 0.4) <= TOL);
    /* A point on the surface is within max_dist = 0 (its distance may come
     * out as round-off). */
    const double on[3] = {0.1, 0.2, 0.5};
    assert_int_equal(cff_mesh_closest(m, on, 0.0, q, n, &d), 1);
    assert_true(fabs(d) <= TOL);
    assert_vec(n, 0, 0, 1, TOL);
    cff_mesh_destroy(m);
}

/* L-shaped prism: the L (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) extruded over
 * z in [0, 1], with a concave edge and two concave vertices at (1,1). */
static const double L_POLY[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};

static int make_l_prism(double v[12][3], int t[20][3])
{
    for (int i = 0; i < 6; ++i) {
        v[i][0] = v[i + 6][0] = L_POLY[i][0];
        v[i][1] = v[i + 6][1] = L_POLY[i][1];
        v[i][2] = 0.0;
        v[i + 6][2] = 1.0;
    }
    int k = 0;
    /* Caps: fans from the reflex corner 3; bottom seen from below. */
    const int fan[4][2] = {{4, 5}, {5, 0}, {0, 1}, {1, 2}};
    for (int i = 0; i < 4; ++i) {
        t[k][0] = 3 + 6, t[k][1] = fan[i][0] + 6, t[k][2] = fan[i][1] + 6, ++k;
        t[k][0] = 3, t[k][1] = fan[i][1], t[k][2] = fan[i][0], ++k;
    }
    /* Walls: the polygon is counter-clockwise, so (i, i+1, i+1 top) faces out. */
    for (int i = 0; i < 6; ++i) {
        const int j = (i + 1) % 6;
        t[k][0] = i, t[k][1] = j, t[k][2] = j + 6, ++k;
        t[k][0] = i, t[k][1] = j + 6, t[k][2] = i + 6, ++k;
    }
    return k;
}

static int inside_l(const double p[3])
{
    if (p[2] <= 0.0 || p[2] >= 1.0 || p[0] <= 0.0 || p[1] <= 0.0) return 0;
    return (p[0] < 2.0 && p[1] < 1.0) || (p[0] < 1.0 && p[1] < 2.0);
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Distance from p to segment ab. */
static double seg_dist(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3];
    for (int i = 0; i < 3; ++i) ab[i] = b[i] - a[i], ap[i] = p[i] - a[i];
    double t = dot3(ap, ab) / dot3(ab, ab);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    double r[3];
    for (int i = 0; i < 3; ++i) r[i] = ap[i] - t * ab[i];
    return sqrt(dot3(r, r));
}

/* Brute force, by another route than the library: the plane distance when
 * the projection falls inside (same-side tests), else the nearest edge. */
static double tri_dist(const double p[3], const double *a, const double *b, const double *c)
{
    double e0[3], e1[3], nrm[3];
    for (int i = 0; i < 3; ++i) e0[i] = b[i] - a[i], e1[i] = c[i] - a[i];
    nrm[0] = e0[1] * e1[2] - e0[2] * e1[1];
    nrm[1] = e0[2] * e1[0] - e0[0] * e1[2];
    nrm[2] = e0[0] * e1[1] - e0[1] * e1[0];
    const double nn = sqrt(dot3(nrm, nrm));
    for (int i = 0; i < 3; ++i) nrm[i] /= nn;
    double ap[3];
    for (int i = 0; i < 3; ++i) ap[i] = p[i] - a[i];
    const double h = dot3(ap, nrm);
    double proj[3];
    for (int i = 0; i < 3; ++i) proj[i] = p[i] - h * nrm[i];
    const double *V[3] = {a, b, c};
    int in = 1;
    for (int k = 0; k < 3; ++k) {
        const double *u = V[k], *w = V[(k + 1) % 3];
        double ed[3], up[3], cr[3];
        for (int i = 0; i < 3; ++i) ed[i] = w[i] - u[i], up[i] = proj[i] - u[i];
        cr[0] = ed[1] * up[2] - ed[2] * up[1];
        cr[1] = ed[2] * up[0] - ed[0] * up[2];
        cr[2] = ed[0] * up[1] - ed[1] * up[0];
        if (dot3(cr, nrm) < 0) in = 0;
    }
    if (in) return fabs(h);
    double d = seg_dist(p, a, b);
    const double d2 = seg_dist(p, b, c), d3 = seg_dist(p, c, a);
    if (d2 < d) d = d2;
    if (d3 < d) d = d3;
    return d;
}

static double lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

/* Random points in the box [lo, hi]: |d| equals the brute-force distance,
 * the sign says inside/outside, q lies |d| from p and n is unit.  Every
 * fifth point is put on the plane y = x, every tenth on a line x = y = c
 * (c around 1), to visit the edges and vertices there.  Done on both kinds
 * of hierarchy (odd seeds: the deforming mesh's axis-aligned boxes). */
static void brute_force_check(const char *name, const double (*v)[3], const int (*t)[3], int nv,
                              int nt, int (*inside)(const double *), const double lo[3],
                              const double hi[3], uint64_t seed)
{
    cff_mesh *m = seed % 2 ? cff_mesh_create_deforming(&v[0][0], nv, &t[0][0], nt)
                           : cff_mesh_create(&v[0][0], nv, &t[0][0], nt);
    assert_non_null(m);
    int n_in = 0, n_out = 0;
    double worst = 0.0;
    for (int it = 0; it < 20000; ++it) {
        double p[3];
        for (int i = 0; i < 3; ++i) p[i] = lo[i] + (hi[i] - lo[i]) * lcg(&seed);
        if (it % 5 == 0) p[1] = p[0];
        if (it % 10 == 0) p[0] = p[1] = 1.0 + 0.4 * (lcg(&seed) - 0.5);
        double bf = INFINITY;
        for (int k = 0; k < nt; ++k) {
            const double dk = tri_dist(p, v[t[k][0]], v[t[k][1]], v[t[k][2]]);
            if (dk < bf) bf = dk;
        }
        double q[3], n[3], d;
        assert_int_equal(cff_mesh_closest(m, p, INFINITY, q, n, &d), 1);
        const double err = fabs(fabs(d) - bf);
        if (err > worst) worst = err;
        if (err > 1e-12)
            fail_msg("%s, p (%.17g %.17g %.17g): |d| %.17g, brute force %.17g", name, p[0], p[1],
                     p[2], d, bf);
        double pq[3];
        for (int i = 0; i < 3; ++i) pq[i] = p[i] - q[i];
        assert_true(fabs(sqrt(dot3(pq, pq)) - fabs(d)) <= 1e-12);
        assert_true(fabs(sqrt(dot3(n, n)) - 1.0) <= 1e-12);
        if (bf > 1e-9) {
            const int in = inside(p);
            if (in != (d < 0))
                fail_msg("%s, p (%.17g %.17g %.17g): inside %d but d = %.17g", name, p[0], p[1],
                         p[2], in, d);
            in ? ++n_in : ++n_out;
        }
    }
    print_message("%s: %d inside, %d outside, max | |d| - brute force | = %.3e\n", name, n_in,
                  n_out, worst);
    assert_true(n_in > 500 && n_out > 500);
    cff_mesh_destroy(m);
}

/* Regular tetrahedron with corners (1,1,1), (1,-1,-1), (-1,1,-1),
 * (-1,-1,1): the face opposite corner i is v_i . x = -1. */
static const double TET[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};

static int inside_tet(const double p[3])
{
    for (int i = 0; i < 4; ++i)
        if (dot3(TET[i], p) <= -1.0) return 0;
    return 1;
}

/* The non-convex L prism, and the tetrahedron, whose 70.5 degree edges and
 * sharp corners defeat a sign taken from the nearest triangle's own normal:
 * only the edge and vertex pseudo-normals get every point right. */
static void test_brute_force(void **state)
{
    (void)state;
    double v[12][3];
    int t[20][3];
    const int nt = make_l_prism(v, t);
    assert_int_equal(nt, 20);
    const double lo[3] = {-0.7, -0.7, -0.7}, hi[3] = {2.7, 2.7, 1.7};
    for (uint64_t seed = 12344; seed <= 12345; seed++)
        brute_force_check("L prism", (const double(*)[3])v, (const int(*)[3])t, 12, nt, inside_l,
                          lo, hi, seed);

    /* Faces opposite each corner, counter-clockwise from outside (normal
     * along -v_i). */
    int tt[4][3];
    for (int i = 0; i < 4; ++i) {
        int k = 0;
        for (int j = 0; j < 4; ++j)
            if (j != i) tt[i][k++] = j;
        const double *a = TET[tt[i][0]], *b = TET[tt[i][1]], *c = TET[tt[i][2]];
        double e0[3], e1[3];
        for (int x = 0; x < 3; ++x) e0[x] = b[x] - a[x], e1[x] = c[x] - a[x];
        const double nrm[3] = {e0[1] * e1[2] - e0[2] * e1[1], e0[2] * e1[0] - e0[0] * e1[2],
                               e0[0] * e1[1] - e0[1] * e1[0]};
        if (dot3(nrm, TET[i]) > 0) {
            const int sw = tt[i][1];
            tt[i][1] = tt[i][2];
            tt[i][2] = sw;
        }
    }
    const double tlo[3] = {-1.6, -1.6, -1.6}, thi[3] = {1.6, 1.6, 1.6};
    for (uint64_t seed = 776; seed <= 777; seed++)
        brute_force_check("tetrahedron", TET, (const int(*)[3])tt, 4, 4, inside_tet, tlo, thi,
                          seed);

    /* Closed form at the L's concave edge x = y = 1, from inside: q on the
     * edge, whose pseudo-normal is the mean of the notch walls' normals
     * (+x and +y); p is behind it. */
    cff_mesh *m = cff_mesh_create(&v[0][0], 12, &t[0][0], nt);
    assert_non_null(m);
    const double r2 = sqrt(0.5);
    expect(m, 0.9, 0.9, 0.5, (double[]){1, 1, 0.5}, (double[]){r2, r2, 0}, -sqrt(0.02));
    /* In the notch, off the bisector: 0.1 in front of the x = 1 wall. */
    expect(m, 1.1, 1.3, 0.5, (double[]){1, 1.3, 0.5}, (double[]){1, 0, 0}, 0.1);
    cff_mesh_destroy(m);
    /* Tetrahedron corner (1,1,1): its pseudo-normal is (1,1,1)/sqrt 3 by
     * symmetry; along it the closest point is the corner. */
    m = cff_mesh_create(&TET[0][0], 4, &tt[0][0], 4);
    assert_non_null(m);
    const double r3 = 1.0 / sqrt(3.0);
    expect(m, 1.5, 1.5, 1.5, (double[]){1, 1, 1}, (double[]){r3, r3, r3}, sqrt(0.75));
    cff_mesh_destroy(m);
}

/* Queries from several threads on one mesh give the serial answers. */
static void test_concurrent_queries(void **state)
{
    (void)state;
    double v[12][3];
    int t[20][3];
    const int nt = make_l_prism(v, t);
    cff_mesh *m = cff_mesh_create(&v[0][0], 12, &t[0][0], nt);
    assert_non_null(m);
    enum { N = 4000 };
    static double pts[N][3], ds[N], dp[N];
    static int rs[N], rp[N];
    uint64_t seed = 99;
    for (int i = 0; i < N; ++i)
        for (int k = 0; k < 3; ++k) pts[i][k] = -1.0 + 4.0 * lcg(&seed);
    for (int i = 0; i < N; ++i) {
        double q[3], n[3];
        rs[i] = cff_mesh_closest(m, pts[i], 0.8, q, n, &ds[i]);
    }
    int bad = 0;
#pragma omp parallel for schedule(dynamic, 16) reduction(+ : bad)
    for (int i = 0; i < N; ++i) {
        double q[3], n[3];
        for (int rep = 0; rep < 5; ++rep) {
            dp[i] = NAN;
            rp[i] = cff_mesh_closest(m, pts[i], 0.8, q, n, &dp[i]);
            if (rp[i] != rs[i] || (rp[i] == 1 && dp[i] != ds[i])) ++bad;
        }
    }
    assert_int_equal(bad, 0);
    int hits = 0;
    for (int i = 0; i < N; ++i) hits += rs[i] == 1;
    assert_true(hits > 100 && hits < N);
    cff_mesh_destroy(m);
}

static void test_bad_input(void **state)
{
    (void)state;
    double v[8][3];
    cube_verts(v);
    int t[12][3];
    memcpy(t, CUBE_TRIS, sizeof t);

    assert_null(cff_mesh_create(&v[0][0], 8, &t[0][0], 0));
    assert_non_null(strstr(cff_last_error(), "triangle"));
    assert_null(cff_mesh_create(NULL, 8, &t[0][0], 12));
    assert_true(strlen(cff_last_error()) > 0);
    assert_null(cff_mesh_create(&v[0][0], 8, NULL, 12));
    assert_null(cff_mesh_create(&v[0][0], 2, &t[0][0], 12));

    t[5][1] = 8;
    assert_null(cff_mesh_create(&v[0][0], 8, &t[0][0], 12));
    assert_non_null(strstr(cff_last_error(), "triangle 5"));
    assert_non_null(strstr(cff_last_error(), "out of range"));
    t[5][1] = -1;
    assert_null(cff_mesh_create(&v[0][0], 8, &t[0][0], 12));
    assert_non_null(strstr(cff_last_error(), "out of range"));
    t[5][1] = t[5][0];
    assert_null(cff_mesh_create(&v[0][0], 8, &t[0][0], 12));
    assert_non_null(strstr(cff_last_error(), "degenerate"));
    memcpy(t, CUBE_TRIS, sizeof t);
    v[3][1] = NAN;
    assert_null(cff_mesh_create(&v[0][0], 8, &t[0][0], 12));
    assert_non_null(strstr(cff_last_error(), "non-finite"));
    /* Collinear corners. */
    const double line[3][3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    const int tri[3] = {0, 1, 2};
    assert_null(cff_mesh_create(&line[0][0], 3, tri, 1));
    assert_non_null(strstr(cff_last_error(), "degenerate"));

    cff_mesh *m = make_cube();
    const double p[3] = {1, 0, 0}, nanp[3] = {NAN, 0, 0};
    double q[3], n[3], d;
    assert_int_equal(cff_mesh_closest(m, p, -1.0, q, n, &d), -1);
    assert_non_null(strstr(cff_last_error(), "max_dist"));
    assert_int_equal(cff_mesh_closest(m, p, NAN, q, n, &d), -1);
    assert_int_equal(cff_mesh_closest(m, nanp, 1.0, q, n, &d), -1);
    assert_non_null(strstr(cff_last_error(), "non-finite"));
    assert_int_equal(cff_mesh_closest(NULL, p, 1.0, q, n, &d), -1);
    assert_int_equal(cff_mesh_closest(m, p, 1.0, NULL, n, &d), -1);
    assert_int_equal(cff_mesh_closest(m, p, 1.0, q, n, NULL), -1);
    cff_mesh_destroy(m);
    cff_mesh_destroy(NULL);

    /* A single triangle (an open mesh) is fine; its front is the CCW side. */
    const double tv[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m = cff_mesh_create(&tv[0][0], 3, tri, 1);
    assert_non_null(m);
    const double above[3] = {0.25, 0.25, 0.5}, below[3] = {0.25, 0.25, -0.5};
    assert_int_equal(cff_mesh_closest(m, above, 1.0, q, n, &d), 1);
    assert_true(fabs(d - 0.5) <= TOL);
    assert_vec(n, 0, 0, 1, TOL);
    assert_int_equal(cff_mesh_closest(m, below, 1.0, q, n, &d), 1);
    assert_true(fabs(d + 0.5) <= TOL);
    cff_mesh_destroy(m);
}

/* The cube moved by (2, 0, 0) and stretched to 3 units along z, refitted:
 * queries see the new surface only, and the triangle and barycentric
 * coordinates reproduce the closest point.  Destroys m. */
static void check_update(cff_mesh *m)
{
    assert_non_null(m);
    double v[8][3];
    cube_verts(v);
    for (int i = 0; i < 8; ++i)
        v[i][0] += 2, v[i][2] *= 3;
    assert_int_equal(cff_mesh_update(m, &v[0][0]), 0);
    /* Above the old top face, now inside the stretched cube, 0.3 m behind
     * its nearest face x = 1.5. */
    const double p[3] = {1.8, 0.0, 1.0};
    double q[3], n[3], d, bary[3];
    int tri = -1;
    assert_int_equal(cff_mesh_closest_tri(m, p, INFINITY, q, n, &d, &tri, bary), 1);
    assert_true(fabs(d + 0.3) < TOL);
    assert_vec(n, -1, 0, 0, TOL);
    assert_true(tri >= 0 && tri < 12);
    double r[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c)
            r[c] += bary[k] * v[CUBE_TRIS[tri][k]][c];
    assert_vec(r, q[0], q[1], q[2], TOL);
    assert_true(fabs(bary[0] + bary[1] + bary[2] - 1) < TOL);
    /* The old position of the cube is empty now. */
    const double old[3] = {0, 0, 0};
    assert_int_equal(cff_mesh_closest(m, old, INFINITY, q, n, &d), 1);
    assert_true(fabs(d - 1.5) < TOL);
    assert_vec(n, -1, 0, 0, TOL);
    /* A non-finite vertex is refused and leaves the mesh as it was. */
    v[3][1] = NAN;
    assert_int_equal(cff_mesh_update(m, &v[0][0]), -1);
    assert_non_null(strstr(cff_last_error(), "non-finite"));
    assert_int_equal(cff_mesh_closest(m, old, INFINITY, q, n, &d), 1);
    assert_true(fabs(d - 1.5) < TOL);
    cff_mesh_destroy(m);
}

/* Both kinds of hierarchy: oriented boxes (static meshes) and axis-aligned
 * boxes (deforming meshes). */
static void test_update(void **state)
{
    (void)state;
    check_update(make_cube());
    double v[8][3];
    cube_verts(v);
    check_update(cff_mesh_create_deforming(&v[0][0], 8, &CUBE_TRIS[0][0], 12));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cube_regions),
        cmocka_unit_test(test_max_dist),
        cmocka_unit_test(test_brute_force),
        cmocka_unit_test(test_update),
        cmocka_unit_test(test_concurrent_queries),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
