/* Surfaces: OBJ/OFF/STL input, enclosed volume, self-intersections, the
 * valence-3 repair, decimation and cf_mesh_prepare through tetgen. */
#define _XOPEN_SOURCE 700 /* mkdtemp, setenv, st_mtim */

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "fixtures.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cohfrac/mesh.h"
#include "cohfrac/surface.h"

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/cohfrac-test-surface-XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    fixture_remove_tree(tmpdir);
    return 0;
}

static const char *tpath(const char *name)
{
    static char path[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(path[k], sizeof path[k], "%s/%s", tmpdir, name);
    return path[k];
}

static void put(const char *name, const char *text)
{
    FILE *f = fopen(tpath(name), "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* ---- the unit cube: corners by bits (x bit 0, y bit 1, z bit 2) ---- */

static const int cube_quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

static void cube_surface(cf_surface *s, const double scale[3], const double shift[3])
{
    s->n_verts = 8, s->n_tris = 12;
    s->v = malloc(8 * 3 * sizeof(double));
    s->tri = malloc(12 * 3 * sizeof(int));
    for (int i = 0; i < 8; i++)
        for (int k = 0; k < 3; k++)
            s->v[3 * i + k] = ((i >> k) & 1) * scale[k] + shift[k];
    for (int f = 0; f < 6; f++) {
        const int *q = cube_quads[f];
        int *t = &s->tri[6 * f];
        t[0] = q[0], t[1] = q[1], t[2] = q[2];
        t[3] = q[0], t[4] = q[2], t[5] = q[3];
    }
}

/* Two unit cubes, the second shifted by `shift`, as one surface. */
static void two_cubes(cf_surface *u, const double shift[3])
{
    double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    cf_surface a, b;
    cube_surface(&a, one, zero);
    cube_surface(&b, one, shift);
    *u = (cf_surface){16, 24, malloc(48 * sizeof(double)), malloc(72 * sizeof(int))};
    memcpy(u->v, a.v, 24 * sizeof(double));
    memcpy(u->v + 24, b.v, 24 * sizeof(double));
    memcpy(u->tri, a.tri, 36 * sizeof(int));
    for (int i = 0; i < 36; i++)
        u->tri[36 + i] = b.tri[i] + 8;
    cf_surface_free(&a);
    cf_surface_free(&b);
}

static void check_unit_cube(const cf_surface *s)
{
    assert_int_equal(s->n_verts, 8);
    assert_int_equal(s->n_tris, 12);
    assert_true(cf_surface_volume(s) == 1.0);
    char why[256];
    assert_int_equal(cf_surface_check_closed(s, why, sizeof why), 1);
    assert_int_equal(cf_surface_self_intersections(s, NULL, 0), 0);
}

static void test_load_obj(void **state)
{
    (void)state;
    char text[2048];
    size_t n = (size_t)snprintf(text, sizeof text,
                                "# unit cube with quads\nmtllib none.mtl\no cube\n");
    for (int i = 0; i < 8; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "v %d %d %d\n", i & 1, (i >> 1) & 1,
                              (i >> 2) & 1);
    n += (size_t)snprintf(text + n, sizeof text - n, "vt 0 0\nvn 0 0 1\ns off\n");
    for (int f = 0; f < 5; f++) {
        const int *q = cube_quads[f];
        n += (size_t)snprintf(text + n, sizeof text - n, "f %d/1/1 %d//1 %d/1 %d\r\n", q[0] + 1,
                              q[1] + 1, q[2] + 1, q[3] + 1);
    }
    /* the last face with relative (negative) indices: -8 is vertex 0 */
    const int *q = cube_quads[5];
    snprintf(text + n, sizeof text - n, "f %d %d %d %d\n", q[0] - 8, q[1] - 8, q[2] - 8, q[3] - 8);
    put("cube.obj", text);
    cf_surface s;
    cf_error err = {0};
    assert_int_equal(cf_surface_load(tpath("cube.obj"), &s, &err), CF_OK);
    check_unit_cube(&s);
    cf_surface_free(&s);
}

static void test_load_off(void **state)
{
    (void)state;
    cf_surface c, s;
    cf_error err = {0};
    double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    cube_surface(&c, one, zero);
    assert_int_equal(cf_surface_write_off(&c, tpath("cube.off"), &err), CF_OK);
    assert_int_equal(cf_surface_load(tpath("cube.off"), &s, &err), CF_OK);
    check_unit_cube(&s);
    assert_memory_equal(s.v, c.v, 24 * sizeof(double));
    assert_memory_equal(s.tri, c.tri, 36 * sizeof(int));
    cf_surface_free(&s);
    /* hand-written: header and counts on one line, comments, quads with colour */
    char text[1024];
    size_t n = (size_t)snprintf(text, sizeof text, "OFF 8 6 12 # counts\n");
    for (int i = 0; i < 8; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "%d %d %d\n", i & 1, (i >> 1) & 1,
                              (i >> 2) & 1);
    for (int f = 0; f < 6; f++) {
        const int *q = cube_quads[f];
        n += (size_t)snprintf(text + n, sizeof text - n, "4 %d %d %d %d 255 0 0\n", q[0], q[1],
                              q[2], q[3]);
    }
    put("quads.off", text);
    assert_int_equal(cf_surface_load(tpath("quads.off"), &s, &err), CF_OK);
    check_unit_cube(&s);
    cf_surface_free(&s);
    cf_surface_free(&c);
}

static void put_le32(FILE *f, uint32_t u)
{
    for (int k = 0; k < 4; k++)
        fputc((int)((u >> (8 * k)) & 0xff), f);
}

static void put_float(FILE *f, float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    put_le32(f, u);
}

static void test_load_stl(void **state)
{
    (void)state;
    cf_surface c, s;
    cf_error err = {0};
    double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    cube_surface(&c, one, zero);
    /* ASCII: 36 corners welded back to 8 vertices */
    FILE *f = fopen(tpath("cube_a.stl"), "w");
    assert_non_null(f);
    fprintf(f, "solid cube\n");
    for (int t = 0; t < 12; t++) {
        fprintf(f, "  facet normal 0 0 0\n    outer loop\n");
        for (int k = 0; k < 3; k++) {
            const double *p = &c.v[3 * c.tri[3 * t + k]];
            fprintf(f, "      vertex %g %g %g\n", p[0], p[1], p[2]);
        }
        fprintf(f, "    endloop\n  endfacet\n");
    }
    fprintf(f, "endsolid cube\n");
    fclose(f);
    assert_int_equal(cf_surface_load(tpath("cube_a.stl"), &s, &err), CF_OK);
    check_unit_cube(&s);
    cf_surface_free(&s);
    /* binary, with a header that misleadingly starts with "solid" */
    f = fopen(tpath("cube_b.STL"), "wb");
    assert_non_null(f);
    char header[80] = "solid but binary";
    fwrite(header, 1, 80, f);
    put_le32(f, 12);
    for (int t = 0; t < 12; t++) {
        for (int k = 0; k < 3; k++)
            put_float(f, 0.0f);
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                put_float(f, (float)c.v[3 * c.tri[3 * t + k] + d]);
        fputc(0, f), fputc(0, f);
    }
    fclose(f);
    assert_int_equal(cf_surface_load(tpath("cube_b.STL"), &s, &err), CF_OK);
    check_unit_cube(&s);
    cf_surface_free(&s);
    cf_surface_free(&c);
}

static void test_load_errors(void **state)
{
    (void)state;
    cf_surface s;
    cf_error err = {0};
    assert_int_equal(cf_surface_load(tpath("none.obj"), &s, &err), CF_ERR_FILE_OPEN);
    assert_non_null(strstr(err.msg, "none.obj"));
    put("x.xyz9", "ply\n");
    assert_int_equal(cf_surface_load(tpath("x.xyz9"), &s, &err), CF_ERR_FILE_OPEN);
    assert_non_null(strstr(err.msg, ".obj, .off or .stl"));
    put("x.ply", "ply\n"); /* assimp's formats: its reason, the file named */
    assert_int_equal(cf_surface_load(tpath("x.ply"), &s, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "x.ply"));
    /* assimp's reasons, the file named; an index past the vertex list is
     * CF_ERR_MESH_INDEX, whether assimp refuses the file (OBJ) or only logs
     * it and clamps (OFF) */
    put("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    assert_int_equal(cf_surface_load(tpath("bad.obj"), &s, &err), CF_ERR_MESH_INDEX);
    assert_non_null(strstr(err.msg, "bad.obj: "));
    assert_non_null(strstr(err.msg, "out of range"));
    put("idx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    assert_int_equal(cf_surface_load(tpath("idx.off"), &s, &err), CF_ERR_MESH_INDEX);
    assert_non_null(strstr(err.msg, "idx.off: "));
    put("junk.obj", "v 0 0 0\nv 1 zero 0\n");
    assert_int_equal(cf_surface_load(tpath("junk.obj"), &s, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "junk.obj: "));
    put("short.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n");
    assert_int_equal(cf_surface_load(tpath("short.off"), &s, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "short.off: "));
    /* coordinates that are not finite numbers */
    put("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n");
    assert_int_equal(cf_surface_load(tpath("nan.obj"), &s, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "not a finite number"));
    /* a missing material library is no defect of the geometry */
    put("mtl.obj", "mtllib none.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                   "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n");
    assert_int_equal(cf_surface_load(tpath("mtl.obj"), &s, &err), CF_OK);
    assert_int_equal(s.n_verts, 4);
    assert_int_equal(s.n_tris, 4);
    cf_surface_free(&s);
    assert_int_equal(cf_surface_load(tpath("short.off"), &s, &err), CF_ERR_MESH_PARSE);
    assert_null(s.v);
}

/* Formats beyond OBJ/OFF/STL come through assimp: the unit cube as ASCII
 * PLY (quads, triangulated on the way in) encloses volume 1. */
static void test_load_ply_through_assimp(void **state)
{
    (void)state;
    put("cube.ply", "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\n"
                    "property float y\nproperty float z\nelement face 6\n"
                    "property list uchar int vertex_indices\nend_header\n"
                    "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
                    "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n");
    cf_surface s;
    cf_error err = {0};
    assert_int_equal(cf_surface_load(tpath("cube.ply"), &s, &err), CF_OK);
    assert_int_equal(s.n_tris, 12);
    assert_true(fabs(cf_surface_volume(&s) - 1.0) < 1e-12);
    cf_surface_free(&s);
}

static void test_enclosed_volume(void **state)
{
    (void)state;
    cf_surface s;
    double scale[3] = {2, 3, 4}, shift[3] = {10, -5, 3};
    cube_surface(&s, scale, shift);
    assert_true(cf_surface_volume(&s) == 24.0);
    cf_surface_flip(&s);
    assert_true(cf_surface_volume(&s) == -24.0);
    char why[256];
    assert_int_equal(cf_surface_check_closed(&s, why, sizeof why), 1);
    /* an open box is reported with the edge that has one triangle */
    s.n_tris = 11;
    assert_int_equal(cf_surface_check_closed(&s, why, sizeof why), 0);
    assert_non_null(strstr(why, "triangle 10 only"));
    cf_surface_free(&s);
}

/* ---- self-intersections ---- */

/* Number of intersecting pairs of the two triangles a and b (9 numbers
 * each); exactly equal corners become one shared vertex. */
static int pair_count(const double a[9], const double b[9])
{
    double v[18];
    int tri[6], nv = 0;
    for (int c = 0; c < 6; c++) {
        const double *p = c < 3 ? &a[3 * c] : &b[3 * (c - 3)];
        int id = -1;
        for (int k = 0; k < nv; k++)
            if (v[3 * k] == p[0] && v[3 * k + 1] == p[1] && v[3 * k + 2] == p[2])
                id = k;
        if (id < 0) {
            memcpy(&v[3 * nv], p, 3 * sizeof(double));
            id = nv++;
        }
        tri[c] = id;
    }
    cf_surface s = {nv, 2, v, tri};
    int pairs[2] = {-1, -1};
    int n = cf_surface_self_intersections(&s, pairs, 1);
    if (n == 1) {
        assert_int_equal(pairs[0], 0);
        assert_int_equal(pairs[1], 1);
    }
    return n;
}

static void test_intersection_cases(void **state)
{
    (void)state;
    const double base[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    /* disjoint corners: a vertical triangle piercing the base's interior */
    const double pierce[9] = {0.2, 0.2, -1, 0.3, 0.2, 1, 0.2, 0.3, 1};
    assert_int_equal(pair_count(base, pierce), 1);
    /* the same, moved beyond the hypotenuse x + y = 1 */
    const double miss[9] = {0.6, 0.6, -1, 0.7, 0.6, 1, 0.6, 0.7, 1};
    assert_int_equal(pair_count(base, miss), 0);
    /* coplanar, one inside the other */
    const double inside[9] = {0.1, 0.1, 0, 0.5, 0.1, 0, 0.1, 0.5, 0};
    assert_int_equal(pair_count(base, inside), 1);
    /* shared vertex: a wedge through the base's interior vs one outside */
    const double vx_in[9] = {0, 0, 0, 0.3, 0.3, 1, 0.3, 0.3, -1};
    const double vx_out[9] = {0, 0, 0, -0.3, -0.3, 1, -0.3, 0.2, -1};
    assert_int_equal(pair_count(base, vx_in), 1);
    assert_int_equal(pair_count(base, vx_out), 0);
    /* shared vertex, coplanar: overlapping wedge vs a neighbour beside it */
    const double vx_cop_in[9] = {0, 0, 0, 0.5, 0.2, 0, 0.3, 0.6, 0};
    const double vx_cop_out[9] = {0, 0, 0, -1, 0, 0, 0, -1, 0};
    assert_int_equal(pair_count(base, vx_cop_in), 1);
    assert_int_equal(pair_count(base, vx_cop_out), 0);
    /* shared edge: folded flat onto the base vs unfolded vs bent up */
    const double fold[9] = {1, 0, 0, 0, 0, 0, 0.3, 0.3, 0};
    const double flat[9] = {1, 0, 0, 0, 0, 0, 0.3, -0.3, 0};
    const double bent[9] = {1, 0, 0, 0, 0, 0, 0.3, 0.3, 0.01};
    assert_int_equal(pair_count(base, fold), 1);
    assert_int_equal(pair_count(base, flat), 0);
    assert_int_equal(pair_count(base, bent), 0);
    /* a triangle with a repeated corner (a defect, found by fuzz_surface:
     * it used to overflow the shared-corner bookkeeping) counts as
     * intersecting a neighbour that shares it */
    double v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    int tri[6] = {0, 1, 2, 0, 0, 3};
    cf_surface s = {4, 2, v, tri};
    int pairs[2] = {-1, -1};
    assert_int_equal(cf_surface_self_intersections(&s, pairs, 1), 1);
    assert_int_equal(pairs[0], 0);
    assert_int_equal(pairs[1], 1);
}

/* Geodesic sphere: icosahedron split `level` times, radius r, centre c;
 * triangles counter-clockwise seen from outside. */
static void icosphere(cf_surface *s, int level, double r, const double c[3])
{
    const double g = (1.0 + sqrt(5.0)) / 2.0;
    const double iv[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                              {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                              {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    const int it[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                           {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                           {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                           {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    int maxv = 12, maxt = 20;
    for (int l = 0; l < level; l++)
        maxv += 3 * maxt / 2, maxt *= 4;
    double *v = malloc((size_t)maxv * 3 * sizeof *v);
    int *t = malloc((size_t)maxt * 3 * sizeof *t);
    assert_non_null(v);
    assert_non_null(t);
    for (int i = 0; i < 12; i++) {
        double n = sqrt(iv[i][0] * iv[i][0] + iv[i][1] * iv[i][1] + iv[i][2] * iv[i][2]);
        for (int k = 0; k < 3; k++)
            v[3 * i + k] = iv[i][k] / n;
    }
    memcpy(t, it, sizeof it);
    int nv = 12, nt = 20;
    for (int l = 0; l < level; l++) {
        int nv0 = nv;
        int *mid = malloc((size_t)nv0 * nv0 * sizeof *mid); /* edge (lo,hi) -> midpoint */
        int *t2 = malloc((size_t)nt * 12 * sizeof *t2);
        assert_non_null(mid);
        assert_non_null(t2);
        for (long i = 0; i < (long)nv0 * nv0; i++)
            mid[i] = -1;
        for (int f = 0; f < nt; f++) {
            int m[3], *T = &t[3 * f];
            for (int e = 0; e < 3; e++) {
                int a = T[e], b = T[(e + 1) % 3];
                long key = a < b ? (long)a * nv0 + b : (long)b * nv0 + a;
                if (mid[key] < 0) {
                    double p[3], n = 0;
                    for (int k = 0; k < 3; k++)
                        p[k] = 0.5 * (v[3 * a + k] + v[3 * b + k]), n += p[k] * p[k];
                    for (int k = 0; k < 3; k++)
                        v[3 * nv + k] = p[k] / sqrt(n);
                    mid[key] = nv++;
                }
                m[e] = mid[key];
            }
            int q[4][3] = {{T[0], m[0], m[2]}, {T[1], m[1], m[0]}, {T[2], m[2], m[1]},
                           {m[0], m[1], m[2]}};
            memcpy(&t2[12 * f], q, sizeof q);
        }
        free(mid);
        memcpy(t, t2, (size_t)nt * 12 * sizeof *t);
        free(t2);
        nt *= 4;
    }
    for (int i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++)
            v[3 * i + k] = r * v[3 * i + k] + c[k];
    s->n_verts = nv, s->n_tris = nt, s->v = v, s->tri = t;
}

static int aabb_overlap(const cf_surface *s, int a, int b)
{
    for (int k = 0; k < 3; k++) {
        double lo_a = INFINITY, hi_a = -INFINITY, lo_b = INFINITY, hi_b = -INFINITY;
        for (int c = 0; c < 3; c++) {
            lo_a = fmin(lo_a, s->v[3 * s->tri[3 * a + c] + k]);
            hi_a = fmax(hi_a, s->v[3 * s->tri[3 * a + c] + k]);
            lo_b = fmin(lo_b, s->v[3 * s->tri[3 * b + c] + k]);
            hi_b = fmax(hi_b, s->v[3 * s->tri[3 * b + c] + k]);
        }
        if (lo_a > hi_b || lo_b > hi_a)
            return 0;
    }
    return 1;
}

/* The grid search must find exactly the pairs a brute-force scan finds. */
static void test_intersections_grid_vs_brute_force(void **state)
{
    (void)state;
    cf_surface a, b;
    double c0[3] = {0, 0, 0}, c1[3] = {0.55, 0.2, 0.1};
    icosphere(&a, 2, 1.0, c0);
    icosphere(&b, 2, 0.8, c1);
    assert_int_equal(a.n_tris, 320);
    char why[256];
    assert_int_equal(cf_surface_check_closed(&a, why, sizeof why), 1);
    assert_int_equal(cf_surface_self_intersections(&a, NULL, 0), 0);
    /* a polyhedral sphere's volume is a bit below 4/3 pi */
    double va = cf_surface_volume(&a);
    assert_true(va < 4.0 / 3.0 * M_PI && va > 0.95 * 4.0 / 3.0 * M_PI);
    /* both spheres in one surface */
    cf_surface u = {a.n_verts + b.n_verts, a.n_tris + b.n_tris, NULL, NULL};
    u.v = malloc((size_t)u.n_verts * 3 * sizeof(double));
    u.tri = malloc((size_t)u.n_tris * 3 * sizeof(int));
    memcpy(u.v, a.v, (size_t)a.n_verts * 3 * sizeof(double));
    memcpy(u.v + 3 * a.n_verts, b.v, (size_t)b.n_verts * 3 * sizeof(double));
    memcpy(u.tri, a.tri, (size_t)a.n_tris * 3 * sizeof(int));
    for (int i = 0; i < 3 * b.n_tris; i++)
        u.tri[3 * a.n_tris + i] = b.tri[i] + a.n_verts;
    int np = cf_surface_self_intersections(&u, NULL, 0);
    assert_true(np > 20);
    int *pairs = malloc((size_t)np * 2 * sizeof(int));
    assert_int_equal(cf_surface_self_intersections(&u, pairs, np), np);
    /* brute force over box-overlapping pairs, two triangles at a time */
    int k = 0;
    for (int i = 0; i < u.n_tris; i++)
        for (int j = i + 1; j < u.n_tris; j++) {
            if (!aabb_overlap(&u, i, j))
                continue;
            double P[9], Q[9];
            for (int c = 0; c < 9; c++) {
                P[c] = u.v[3 * u.tri[3 * i + c / 3] + c % 3];
                Q[c] = u.v[3 * u.tri[3 * j + c / 3] + c % 3];
            }
            /* corners shared in the big surface are shared in the pair */
            if (pair_count(P, Q)) {
                assert_true(k < np);
                assert_int_equal(pairs[2 * k], i); /* same pairs, same order */
                assert_int_equal(pairs[2 * k + 1], j);
                /* every pair has one triangle from each sphere */
                assert_true(i < a.n_tris && j >= a.n_tris);
                k++;
            }
        }
    assert_int_equal(k, np);
    free(pairs);
    cf_surface_free(&u);
    cf_surface_free(&a);
    cf_surface_free(&b);
}

/* Octahedron |x|+|y|+|z| = 1 whose face (+x,+y,+z) is split at a new
 * vertex v (valence 3).  v is then pushed out beyond the neighbouring face
 * (+y,+x,-z), so the edge z->v pierces that face: the fan overlaps its
 * neighbour as in the bunny.  Returns v's index (6). */
static int defect_octahedron(cf_surface *s)
{
    static const double ov[7][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},     {0, -1, 0},
                                    {0, 0, 1},  {0, 0, -1}, {0.4, 0.4, -0.4}};
    /* faces with outward orientation; face (0,2,4) is replaced by v's fan */
    static const int ot[10][3] = {{2, 0, 5}, {3, 0, 4}, {0, 3, 5}, {2, 1, 4}, {1, 2, 5},
                                  {3, 1, 5}, {1, 3, 4}, {6, 0, 2}, {6, 2, 4}, {6, 4, 0}};
    s->n_verts = 7, s->n_tris = 10;
    s->v = malloc(sizeof ov);
    s->tri = malloc(sizeof ot);
    memcpy(s->v, ov, sizeof ov);
    memcpy(s->tri, ot, sizeof ot);
    return 6;
}

static void test_repair_valence3(void **state)
{
    (void)state;
    cf_surface s;
    defect_octahedron(&s);
    char why[256];
    assert_int_equal(cf_surface_check_closed(&s, why, sizeof why), 1); /* closed, but... */
    int pairs[16];
    int n = cf_surface_self_intersections(&s, pairs, 8);
    assert_true(n >= 1);
    /* every pair has a triangle of v's fan (7, 8, 9) and one outside it */
    for (int k = 0; k < n && k < 8; k++) {
        int in0 = pairs[2 * k] >= 7, in1 = pairs[2 * k + 1] >= 7;
        assert_true(in0 != in1);
    }
    /* face 0 = (+y,+x,-z) is the pierced neighbour */
    int hit0 = 0;
    for (int k = 0; k < n && k < 8; k++)
        hit0 |= pairs[2 * k] == 0;
    assert_true(hit0);
    assert_int_equal(cf_surface_repair_valence3(&s), 1);
    assert_int_equal(s.n_verts, 6);
    assert_int_equal(s.n_tris, 8);
    assert_int_equal(cf_surface_self_intersections(&s, NULL, 0), 0);
    assert_int_equal(cf_surface_check_closed(&s, why, sizeof why), 1);
    /* the cap restores the octahedron exactly, orientation included */
    assert_true(cf_surface_volume(&s) == 4.0 / 3.0);
    /* nothing left to do: a second call changes nothing */
    assert_int_equal(cf_surface_repair_valence3(&s), 0);
    assert_int_equal(s.n_tris, 8);
    cf_surface_free(&s);

    /* a clean surface is left untouched */
    double c[3] = {0, 0, 0};
    icosphere(&s, 1, 1.0, c);
    cf_surface ref;
    icosphere(&ref, 1, 1.0, c);
    assert_int_equal(cf_surface_repair_valence3(&s), 0);
    assert_int_equal(s.n_tris, ref.n_tris);
    assert_memory_equal(s.tri, ref.tri, (size_t)s.n_tris * 3 * sizeof(int));
    cf_surface_free(&s);
    cf_surface_free(&ref);
}

static void test_decimate(void **state)
{
    (void)state;
    cf_surface s, t;
    double c[3] = {0.5, -0.25, 2.0};
    icosphere(&s, 4, 1.0, c);
    assert_int_equal(s.n_tris, 5120);
    double v0 = cf_surface_volume(&s);
    assert_int_equal(cf_surface_decimate(&s, 500), 500);
    assert_int_equal(s.n_tris, 500);
    assert_int_equal(s.n_verts, 252); /* closed genus 0: V = F/2 + 2 */
    char why[256];
    assert_int_equal(cf_surface_check_closed(&s, why, sizeof why), 1);
    assert_int_equal(cf_surface_self_intersections(&s, NULL, 0), 0);
    /* still a sphere: volume within 3 %, vertices near radius 1 */
    assert_true(fabs(cf_surface_volume(&s) / v0 - 1.0) < 0.03);
    for (int i = 0; i < s.n_verts; i++) {
        double d = 0;
        for (int k = 0; k < 3; k++)
            d += (s.v[3 * i + k] - c[k]) * (s.v[3 * i + k] - c[k]);
        assert_true(fabs(sqrt(d) - 1.0) < 0.03);
    }
    /* no vertex of valence < 4 */
    assert_true(s.n_verts > 0);
    int *val = calloc((size_t)s.n_verts + 1, sizeof *val);
    for (int i = 0; i < 3 * s.n_tris; i++)
        val[s.tri[i]]++;
    for (int i = 0; i < s.n_verts; i++)
        assert_true(val[i] >= 4);
    free(val);
    /* reproducible */
    icosphere(&t, 4, 1.0, c);
    assert_int_equal(cf_surface_decimate(&t, 500), 500);
    assert_int_equal(t.n_verts, s.n_verts);
    assert_memory_equal(t.v, s.v, (size_t)s.n_verts * 3 * sizeof(double));
    assert_memory_equal(t.tri, s.tri, (size_t)s.n_tris * 3 * sizeof(int));
    cf_surface_free(&s);
    cf_surface_free(&t);
}

/* Midpoint subdivision: the unit cube's 12 triangles become 48 over
 * 8 + 18 vertices (one per edge), the same closed surface: volume and
 * every vertex on the cube's faces exactly. */
static void test_subdivide(void **state)
{
    (void)state;
    cf_surface s;
    double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    cube_surface(&s, one, zero);
    double v0 = cf_surface_volume(&s);
    assert_int_equal(cf_surface_subdivide(&s), 0);
    assert_int_equal(s.n_tris, 48);
    assert_int_equal(s.n_verts, 26);
    assert_true(cf_surface_volume(&s) == v0);
    char why[256];
    assert_int_equal(cf_surface_check_closed(&s, why, sizeof why), 1);
    assert_int_equal(cf_surface_self_intersections(&s, NULL, 0), 0);
    for (int i = 0; i < s.n_verts; i++) {
        int on_face = 0;
        for (int k = 0; k < 3; k++)
            on_face |= s.v[3 * i + k] == 0 || s.v[3 * i + k] == 1;
        assert_true(on_face);
    }
    assert_int_equal(cf_surface_subdivide(&s), 0); /* and again */
    assert_int_equal(s.n_tris, 192);
    assert_true(fabs(cf_surface_volume(&s) - v0) < 1e-15);
    cf_surface_free(&s);
}

/* The real input (docs/scenes.md): the bunny of glmark2-data has exactly the
 * two intersecting pairs tetgen -d reports (its facets 22950/69662 and
 * 69660/69662, 1-based), both made by one valence-3 vertex. */
static void test_real_bunny_defect(void **state)
{
    (void)state;
    const char *path = "/usr/share/glmark2/models/bunny.obj";
    if (access(path, R_OK) != 0)
        skip();
    cf_surface s;
    cf_error err = {0};
    assert_int_equal(cf_surface_load(path, &s, &err), CF_OK);
    assert_int_equal(s.n_verts, 34835);
    assert_int_equal(s.n_tris, 69666);
    int pairs[8];
    assert_int_equal(cf_surface_self_intersections(&s, pairs, 4), 2);
    assert_int_equal(pairs[0], 22949);
    assert_int_equal(pairs[1], 69661);
    assert_int_equal(pairs[2], 69659);
    assert_int_equal(pairs[3], 69661);
    double v0 = cf_surface_volume(&s);
    assert_int_equal(cf_surface_repair_valence3(&s), 1);
    assert_int_equal(s.n_verts, 34834);
    assert_int_equal(s.n_tris, 69664);
    assert_int_equal(cf_surface_self_intersections(&s, NULL, 0), 0);
    char why[256];
    assert_int_equal(cf_surface_check_closed(&s, why, sizeof why), 1);
    /* the removed dent is tiny: the volume (about 1.6) moves by < 1e-6 */
    assert_true(v0 > 1.5 && v0 < 1.7);
    assert_true(fabs(cf_surface_volume(&s) - v0) < 1e-6 * v0);
    cf_surface_free(&s);
}

/* ---- cf_mesh_prepare: runs the tetgen program ---- */

static int have_tetgen(void)
{
    const char *path = getenv("PATH");
    if (!path)
        return 0;
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *d = strtok(buf, ":"); d; d = strtok(NULL, ":")) {
        char p[4200];
        snprintf(p, sizeof p, "%s/tetgen", d);
        if (access(p, X_OK) == 0)
            return 1;
    }
    return 0;
}


static void test_prepare_cube(void **state)
{
    (void)state;
    if (!have_tetgen())
        skip();
    cf_surface c;
    cf_error err = {0};
    double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    cube_surface(&c, one, zero);
    assert_int_equal(cf_surface_write_off(&c, tpath("pcube.off"), &err), CF_OK);
    cf_surface_free(&c);
    /* the output directory does not exist yet */
    char out[512];
    snprintf(out, sizeof out, "%s/made/here/cube", tmpdir);
    cf_mesh_prep_opts o = {.input = tpath("pcube.off"), .output = out, .target_tets = 0};
    assert_int_equal(cf_mesh_prepare(&o, &err), CF_OK);
    cf_mesh m;
    assert_int_equal(cf_mesh_load_tetgen(out, &m, &err), CF_OK); /* checks orientation */
    assert_true(m.n_nodes >= 8 && m.n_tets >= 5);
    assert_true(fabs(cf_mesh_volume(&m) - 1.0) < 1e-12);
    for (int i = 0; i < 3 * m.n_nodes; i++) /* nodes stay inside the cube */
        assert_true(m.x[i] >= 0.0 && m.x[i] <= 1.0);
    cf_mesh_free(&m);
    /* the second call is served from the cache: files untouched */
    char node[600], stamp[600];
    snprintf(node, sizeof node, "%s.node", out);
    snprintf(stamp, sizeof stamp, "%s.stamp", out);
    struct stat s0, s1;
    assert_int_equal(stat(node, &s0), 0);
    char *stamp_text = fixture_read_file(stamp);
    assert_non_null(stamp_text);
    assert_non_null(strstr(stamp_text, "target_tets 0\n"));
    assert_non_null(strstr(stamp_text, "pcube.off"));
    free(stamp_text);
    assert_int_equal(cf_mesh_prepare(&o, &err), CF_OK);
    assert_int_equal(stat(node, &s1), 0);
    assert_true(s0.st_mtim.tv_sec == s1.st_mtim.tv_sec &&
                s0.st_mtim.tv_nsec == s1.st_mtim.tv_nsec);

    /* a size target: within 5 % (10 % allowed), volume still exact */
    char out2[512], out3[512];
    snprintf(out2, sizeof out2, "%s/cube3000", tmpdir);
    snprintf(out3, sizeof out3, "%s/cube3000b", tmpdir);
    cf_mesh_prep_opts o2 = {.input = tpath("pcube.off"), .output = out2, .target_tets = 3000};
    assert_int_equal(cf_mesh_prepare(&o2, &err), CF_OK);
    assert_int_equal(cf_mesh_load_tetgen(out2, &m, &err), CF_OK);
    assert_true(m.n_tets > 2700 && m.n_tets < 3300);
    assert_true(fabs(cf_mesh_volume(&m) - 1.0) < 1e-12);
    cf_mesh_free(&m);
    /* reproducible: a second output from the same input is identical */
    cf_mesh_prep_opts o3 = {.input = tpath("pcube.off"), .output = out3, .target_tets = 3000};
    assert_int_equal(cf_mesh_prepare(&o3, &err), CF_OK);
    char p2[600], p3[600];
    for (int e = 0; e < 2; e++) {
        snprintf(p2, sizeof p2, "%s%s", out2, e ? ".ele" : ".node");
        snprintf(p3, sizeof p3, "%s%s", out3, e ? ".ele" : ".node");
        char *a = fixture_read_file(p2), *b = fixture_read_file(p3);
        assert_non_null(a);
        assert_non_null(b);
        assert_string_equal(a, b);
        free(a);
        free(b);
    }
}

static void test_prepare_repairs_and_rejects(void **state)
{
    (void)state;
    if (!have_tetgen())
        skip();
    cf_error err = {0};
    cf_surface s;
    /* the valence-3 defect is repaired on the way: an exact octahedron */
    defect_octahedron(&s);
    assert_int_equal(cf_surface_write_off(&s, tpath("oct.off"), &err), CF_OK);
    cf_surface_free(&s);
    cf_mesh_prep_opts o = {.input = tpath("oct.off"), .output = tpath("oct"), .target_tets = 0};
    assert_int_equal(cf_mesh_prepare(&o, &err), CF_OK);
    cf_mesh m;
    assert_int_equal(cf_mesh_load_tetgen(tpath("oct"), &m, &err), CF_OK);
    assert_true(fabs(cf_mesh_volume(&m) - 4.0 / 3.0) < 1e-12);
    cf_mesh_free(&m);

    /* an open box */
    double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0}, half[3] = {0.5, 0.5, 0.5};
    cube_surface(&s, one, zero);
    s.n_tris = 11;
    assert_int_equal(cf_surface_write_off(&s, tpath("open.off"), &err), CF_OK);
    cf_surface_free(&s);
    cf_mesh_prep_opts o2 = {.input = tpath("open.off"), .output = tpath("open"), .target_tets = 0,
                            .no_repair = 1};
    assert_int_equal(cf_mesh_prepare(&o2, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "not a closed"));
    assert_null(fopen(tpath("open.node"), "r"));

    /* two interpenetrating cubes: no valence-3 vertex to remove */
    cf_surface u;
    two_cubes(&u, half);
    assert_int_equal(cf_surface_write_off(&u, tpath("two.off"), &err), CF_OK);
    cf_mesh_prep_opts o3 = {.input = tpath("two.off"), .output = tpath("two"), .target_tets = 0,
                            .no_repair = 1};
    assert_int_equal(cf_mesh_prepare(&o3, &err), CF_ERR_SURFACE_INTERSECT);
    assert_non_null(strstr(err.msg, "faces "));
    assert_null(fopen(tpath("two.node"), "r")); /* nothing written */
    cf_surface_free(&u);

    /* tetgen missing */
    setenv("COHFRAC_TETGEN", "/nonexistent/tetgen", 1);
    cf_mesh_prep_opts o4 = {.input = tpath("pcube.off"), .output = tpath("notet"), .target_tets = 0};
    cube_surface(&s, one, zero);
    assert_int_equal(cf_surface_write_off(&s, tpath("pcube.off"), &err), CF_OK);
    cf_surface_free(&s);
    assert_int_equal(cf_mesh_prepare(&o4, &err), CF_ERR_EXTERNAL);
    assert_non_null(strstr(err.msg, "/nonexistent/tetgen"));
    unsetenv("COHFRAC_TETGEN");
}

/* Volume of the tets `cohfrac mesh` made from `name`.off. */
static double meshed_volume(const char *name, cf_error *err)
{
    char base[256];
    snprintf(base, sizeof base, "%s", tpath(name));
    char off[300];
    snprintf(off, sizeof off, "%s.off", base);
    cf_mesh_prep_opts o = {.input = off, .output = base, .target_tets = 0};
    if (cf_mesh_prepare(&o, err) != CF_OK)
        return -1;
    cf_mesh m;
    if (cf_mesh_load_tetgen(base, &m, err) != CF_OK)
        return -1;
    double v = cf_mesh_volume(&m);
    cf_mesh_free(&m);
    return v;
}

/* CGAL's repair (cf_surface_repair), checked by the volume the tets then
 * enclose, which is exact in double for these corners: a box with one face
 * missing is closed (1 m^3), a box with one face turned inwards is turned
 * back (1), and two unit boxes overlapping by half in each direction become
 * their union, 2 - 1/8 = 1.875. */
static void test_prepare_repairs_with_cgal(void **state)
{
    (void)state;
    if (!have_tetgen())
        skip();
    cf_error err = {0};
    double one[3] = {1, 1, 1}, zero[3] = {0, 0, 0}, half[3] = {0.5, 0.5, 0.5};
    cf_surface s;
    cube_surface(&s, one, zero);
    s.n_tris = 10; /* the last quad gone: a hole */
    assert_int_equal(cf_surface_write_off(&s, tpath("hole.off"), &err), CF_OK);
    int t[3] = {s.tri[3], s.tri[4], s.tri[5]};
    s.n_tris = 12;
    s.tri[3] = t[0], s.tri[4] = t[2], s.tri[5] = t[1]; /* one triangle inside out */
    assert_int_equal(cf_surface_write_off(&s, tpath("flip.off"), &err), CF_OK);
    cf_surface_free(&s);
    assert_true(fabs(meshed_volume("hole", &err) - 1.0) < 1e-12);
    assert_true(fabs(meshed_volume("flip", &err) - 1.0) < 1e-12);

    cf_surface u;
    two_cubes(&u, half);
    char report[512];
    assert_int_equal(cf_surface_repair(&u, report, sizeof report, &err), CF_OK);
    assert_non_null(strstr(report, "their union"));
    assert_true(fabs(cf_surface_volume(&u) - 1.875) < 1e-12);
    assert_int_equal(cf_surface_self_intersections(&u, NULL, 0), 0);
    assert_int_equal(cf_surface_write_off(&u, tpath("union.off"), &err), CF_OK);
    assert_true(fabs(meshed_volume("union", &err) - 1.875) < 1e-12);

    /* Two boxes sharing one edge (non-manifold): no exact repair holds, the
     * alpha wrap does; it stands off the boxes, so it encloses more than
     * their 2 m^3, by about the offset over their area (12 m^2). */
    cf_surface_free(&u);
    two_cubes(&u, (double[3]){1, 1, 0});
    assert_int_equal(cf_surface_write_off(&u, tpath("edge.off"), &err), CF_OK);
    assert_int_equal(cf_surface_repair(&u, report, sizeof report, &err), CF_OK);
    assert_non_null(strstr(report, "wrapped"));
    char why[256];
    assert_int_equal(cf_surface_check_closed(&u, why, sizeof why), 1);
    assert_int_equal(cf_surface_self_intersections(&u, NULL, 0), 0);
    double diag = sqrt(4 + 4 + 1), off = diag / 2000;
    double vol = cf_surface_volume(&u);
    assert_true(vol > 2.0 && vol < 2.0 + 2 * 12 * off);
    cf_surface_free(&u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_load_obj),
        cmocka_unit_test(test_load_off),
        cmocka_unit_test(test_load_stl),
        cmocka_unit_test(test_load_errors),
        cmocka_unit_test(test_load_ply_through_assimp),
        cmocka_unit_test(test_enclosed_volume),
        cmocka_unit_test(test_intersection_cases),
        cmocka_unit_test(test_intersections_grid_vs_brute_force),
        cmocka_unit_test(test_repair_valence3),
        cmocka_unit_test(test_decimate),
        cmocka_unit_test(test_subdivide),
        cmocka_unit_test(test_real_bunny_defect),
        cmocka_unit_test(test_prepare_cube),
        cmocka_unit_test(test_prepare_repairs_and_rejects),
        cmocka_unit_test(test_prepare_repairs_with_cgal),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
