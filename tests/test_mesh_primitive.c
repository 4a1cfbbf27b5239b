/* Meshed primitives: the structured box (5 and 6 tets per cell: counts,
 * orientation, volume, conformity, centring) and the Gmsh-made sphere,
 * hollow sphere, plate and notched beam (volume, centring, cache), plus the
 * errors of bad parameters and of a missing gmsh. */
#define _XOPEN_SOURCE 700 /* mkdtemp, setenv */

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
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fixtures.h"
#include "cohfrac/mesh.h"

static char cache[512]; /* a fresh cache directory under the build tree */

static int setup(void **state)
{
    (void)state;
    snprintf(cache, sizeof cache, "%s/test-primitive-XXXXXX", COHFRAC_BINARY_DIR);
    return mkdtemp(cache) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    fixture_remove_tree(cache);
    return 0;
}

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

static int cmp_face(const void *a, const void *b)
{
    const int *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return (x[k] > y[k]) - (x[k] < y[k]);
    return 0;
}

/* Every face is shared by two tets, or lies on the box boundary and belongs
 * to one; returns the number of boundary faces. */
static int check_conforming(const cf_mesh *m, const double size[3])
{
    int nf = 4 * m->n_tets;
    int(*f)[3] = malloc((size_t)nf * sizeof *f);
    assert_non_null(f);
    static const int face[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    for (int t = 0; t < m->n_tets; t++)
        for (int j = 0; j < 4; j++) {
            int *F = f[4 * t + j];
            for (int k = 0; k < 3; k++)
                F[k] = m->tets[4 * t + face[j][k]];
            qsort(F, 3, sizeof(int), cmp_int);
        }
    qsort(f, (size_t)nf, sizeof *f, cmp_face);
    int boundary = 0;
    for (int i = 0; i < nf;) {
        int n = 1;
        while (i + n < nf && !cmp_face(f[i], f[i + n]))
            n++;
        if (n > 2)
            fail_msg("face (%d %d %d) is shared by %d tets", f[i][0], f[i][1], f[i][2], n);
        if (n == 1) { /* its three nodes on one face of the box */
            int on_plane = 0;
            for (int a = 0; a < 3; a++)
                for (int s = -1; s <= 1; s += 2) {
                    int all = 1;
                    for (int k = 0; k < 3; k++)
                        all &= m->x[3 * f[i][k] + a] == s * 0.5 * size[a];
                    on_plane |= all;
                }
            if (!on_plane)
                fail_msg("face (%d %d %d) belongs to one tet but is inside the box", f[i][0],
                         f[i][1], f[i][2]);
            boundary++;
        }
        i += n;
    }
    free(f);
    return boundary;
}

static void bbox(const cf_mesh *m, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++)
        lo[k] = INFINITY, hi[k] = -INFINITY;
    for (int i = 0; i < m->n_nodes; i++)
        for (int k = 0; k < 3; k++) {
            double v = m->x[3 * i + k];
            lo[k] = v < lo[k] ? v : lo[k];
            hi[k] = v > hi[k] ? v : hi[k];
        }
}

static void check_box(int tets_per_cell)
{
    const double size[3] = {2.0, 0.3, 1.7};
    const int cells[3] = {5, 2, 3};
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_box(size, cells, tets_per_cell, &m, &err), CF_OK);
    assert_int_equal(m.n_nodes, 6 * 3 * 4);
    assert_int_equal(m.n_tets, tets_per_cell * 5 * 2 * 3);
    assert_int_equal(m.n_groups, 0);
    for (int t = 0; t < m.n_tets; t++) {
        const int *T = &m.tets[4 * t];
        assert_true(cf_tet_volume(&m.x[3 * T[0]], &m.x[3 * T[1]], &m.x[3 * T[2]],
                                  &m.x[3 * T[3]]) > 0);
    }
    assert_int_equal(cf_mesh_check(&m, "box", &err), CF_OK);
    double v = size[0] * size[1] * size[2];
    assert_near(cf_mesh_volume(&m), v, 1e-12 * v);
    /* 2 triangles per boundary square */
    assert_int_equal(check_conforming(&m, size), 4 * (5 * 2 + 2 * 3 + 5 * 3));
    double lo[3], hi[3];
    bbox(&m, lo, hi);
    for (int k = 0; k < 3; k++) {
        assert_true(lo[k] == -0.5 * size[k]);
        assert_true(hi[k] == 0.5 * size[k]);
    }
    cf_mesh_free(&m);
}

static void test_box_6(void **state)
{
    (void)state;
    check_box(6);
}

static void test_box_5(void **state)
{
    (void)state;
    check_box(5);
    /* one cell: 5 tets, the central one a third of the cube */
    const double s[3] = {1, 1, 1};
    const int c[3] = {1, 1, 1};
    cf_mesh m;
    assert_int_equal(cf_mesh_box(s, c, 5, &m, NULL), CF_OK);
    assert_int_equal(m.n_tets, 5);
    assert_true(cf_mesh_volume(&m) == 1.0);
    cf_mesh_free(&m);
}

static void expect_bad_box(const double s[3], const int c[3], int tpc, const char *word)
{
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_box(s, c, tpc, &m, &err), CF_ERR_SCENE_VALUE);
    if (!strstr(err.msg, word))
        fail_msg("message '%s' does not name '%s'", err.msg, word);
    assert_null(m.x);
    assert_null(m.tets);
}

static void test_box_bad(void **state)
{
    (void)state;
    const double s[3] = {1, 1, 1}, s0[3] = {1, -1, 1}, sn[3] = {1, 1, NAN};
    const int c[3] = {2, 2, 2}, c0[3] = {2, 2, 0};
    expect_bad_box(s0, c, 6, "size along y");
    expect_bad_box(sn, c, 6, "size along z");
    expect_bad_box(s, c0, 6, "cells along z");
    expect_bad_box(s, c, 4, "tets_per_cell");
    /* through cf_mesh_primitive too */
    cf_primitive p = {.type = CF_PRIM_BOX, .size = {1, 1, 1}, .cells = {1, 1, 1}, .tets_per_cell = 7};
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_primitive(&p, cache, &m, &err), CF_ERR_SCENE_VALUE);
    p.tets_per_cell = 6;
    assert_int_equal(cf_mesh_primitive(&p, cache, &m, &err), CF_OK);
    assert_int_equal(m.n_tets, 6);
    cf_mesh_free(&m);
}

/* ---- gmsh primitives ---- */

static void expect_bad(cf_primitive p, const char *word)
{
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_primitive(&p, cache, &m, &err), CF_ERR_SCENE_VALUE);
    if (!strstr(err.msg, word))
        fail_msg("message '%s' does not name '%s'", err.msg, word);
    assert_null(m.x);
}

static const cf_primitive sphere = {.type = CF_PRIM_SPHERE, .radius = 0.5, .mesh_size = 0.1};
static const cf_primitive hollow = {
    .type = CF_PRIM_HOLLOW_SPHERE, .radius = 0.5, .thickness = 0.15, .mesh_size = 0.1};
static const cf_primitive plate = {.type = CF_PRIM_PLATE, .size = {1.0, 0.6, 0.05},
                                   .mesh_size = 0.1};
static const cf_primitive beam = {.type = CF_PRIM_NOTCHED_BEAM, .size = {1.0, 0.2, 0.3},
                                  .notch = {0.1, 0.04, 0.15}, .mesh_size = 0.05};

static void test_primitive_bad(void **state)
{
    (void)state;
    cf_primitive p = sphere;
    p.radius = 0;
    expect_bad(p, "radius");
    p = sphere;
    p.mesh_size = -1;
    expect_bad(p, "mesh_size");
    p = hollow;
    p.thickness = 0.5;
    expect_bad(p, "thickness");
    p = plate;
    p.size[2] = 0;
    expect_bad(p, "size along z");
    p = beam;
    p.notch[0] = 0.3;
    expect_bad(p, "notch depth");
    p = beam;
    p.notch[1] = 0;
    expect_bad(p, "notch width");
    p = beam;
    p.notch[2] = -0.49;
    expect_bad(p, "notch offset");
    p = beam;
    p.type = (cf_primitive_type)42;
    expect_bad(p, "unknown primitive type");
    /* nothing was written */
    DIR *d = opendir(cache);
    assert_non_null(d);
    struct dirent *e;
    int n = 0;
    while ((e = readdir(d)))
        n += e->d_name[0] != '.';
    closedir(d);
    assert_int_equal(n, 0);
}

/* Mesh `p` into `dir`; the mesh file's path into `path`. */
static void mesh_primitive(const cf_primitive *p, const char *dir, cf_mesh *m, char path[1024])
{
    cf_error err = {0};
    cf_status st = cf_mesh_primitive(p, dir, m, &err);
    if (st == CF_ERR_EXTERNAL && !getenv("COHFRAC_GMSH") && strstr(err.msg, "install Gmsh"))
        skip(); /* no gmsh on this machine */
    if (st != CF_OK)
        fail_msg("%s", err.msg);
    path[0] = '\0';
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t n = strlen(e->d_name);
        if (n > 4 && !strcmp(e->d_name + n - 4, ".msh")) {
            assert_true(path[0] == '\0'); /* one mesh, temporaries gone */
            snprintf(path, 1024, "%s/%s", dir, e->d_name);
        } else if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            size_t l = strlen(e->d_name);
            assert_true(l > 4 && !strcmp(e->d_name + l - 4, ".geo")); /* the script only */
        }
    }
    closedir(d);
    assert_true(path[0] != '\0');
}

/* Mesh, check volume and centring, mesh again from the cache. */
static void check_gmsh(const cf_primitive *p, const char *sub, double volume, double rel_tol)
{
    char dir[600], path[1024];
    snprintf(dir, sizeof dir, "%s/%s/cache", cache, sub); /* created with mkdir -p */
    cf_mesh m, again;
    mesh_primitive(p, dir, &m, path);
    const char *name = strrchr(path, '/') + 1;
    static const char *types[] = {"", "", "sphere_", "hollow_sphere_", "plate_", "notched_beam_"};
    assert_true(!strncmp(name, types[p->type], strlen(types[p->type])));
    assert_int_equal((int)strlen(name), (int)strlen(types[p->type]) + 16 + 4);
    double v = cf_mesh_volume(&m);
    if (!(fabs(v - volume) <= rel_tol * volume))
        fail_msg("%s: volume %.17g, expected %.17g within %g %%", sub, v, volume, 100 * rel_tol);
    double lo[3], hi[3];
    bbox(&m, lo, hi);
    for (int k = 0; k < 3; k++)
        assert_near(lo[k] + hi[k], 0.0, 1e-12);
    struct stat s1, s2;
    assert_int_equal(stat(path, &s1), 0);
    mesh_primitive(p, dir, &again, path);
    assert_int_equal(stat(path, &s2), 0);
    assert_true(s1.st_mtim.tv_sec == s2.st_mtim.tv_sec && s1.st_mtim.tv_nsec == s2.st_mtim.tv_nsec);
    assert_int_equal(again.n_nodes, m.n_nodes);
    assert_int_equal(again.n_tets, m.n_tets);
    assert_memory_equal(again.x, m.x, (size_t)m.n_nodes * 3 * sizeof(double));
    cf_mesh_free(&m);
    cf_mesh_free(&again);
}

static void test_sphere(void **state)
{
    (void)state;
    double r = sphere.radius;
    check_gmsh(&sphere, "sphere", 4.0 / 3.0 * M_PI * r * r * r, 0.03);
}

static void test_hollow_sphere(void **state)
{
    (void)state;
    double r = hollow.radius, q = r - hollow.thickness;
    check_gmsh(&hollow, "hollow", 4.0 / 3.0 * M_PI * (r * r * r - q * q * q), 0.03);
}

static void test_plate(void **state)
{
    (void)state;
    check_gmsh(&plate, "plate", 1.0 * 0.6 * 0.05, 1e-9);
}

static void test_notched_beam(void **state)
{
    (void)state;
    check_gmsh(&beam, "beam", 1.0 * 0.2 * 0.3 - 0.1 * 0.04 * 0.2, 1e-9);
    /* the notch is where it was asked: no node inside the slot */
    cf_mesh m;
    char path[1024], dir[600];
    snprintf(dir, sizeof dir, "%s/beam/cache", cache);
    mesh_primitive(&beam, dir, &m, path);
    for (int i = 0; i < m.n_nodes; i++) {
        const double *x = &m.x[3 * i];
        int inside = fabs(x[0] - 0.15) < 0.02 - 1e-9 && x[2] < -0.15 + 0.1 - 1e-9;
        assert_false(inside);
    }
    cf_mesh_free(&m);
}

static void test_gmsh_missing_or_failing(void **state)
{
    (void)state;
    char dir[600];
    snprintf(dir, sizeof dir, "%s/nogmsh", cache);
    cf_mesh m;
    cf_error err = {0};
    setenv("COHFRAC_GMSH", "/nonexistent/gmsh-not-here", 1);
    cf_status st = cf_mesh_primitive(&sphere, dir, &m, &err);
    unsetenv("COHFRAC_GMSH");
    assert_int_equal(st, CF_ERR_EXTERNAL);
    assert_non_null(strstr(err.msg, "/nonexistent/gmsh-not-here"));
    assert_non_null(strstr(err.msg, "COHFRAC_GMSH"));
    assert_null(m.x);
    /* a program that fails: its command line is quoted */
    setenv("COHFRAC_GMSH", "false", 1);
    st = cf_mesh_primitive(&sphere, dir, &m, &err);
    unsetenv("COHFRAC_GMSH");
    assert_int_equal(st, CF_ERR_EXTERNAL);
    assert_non_null(strstr(err.msg, "false -3 -format msh41"));
    assert_non_null(strstr(err.msg, "exit status 1"));
    /* no cache file and no temporaries are left */
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d)))
        assert_true(e->d_name[0] == '.');
    closedir(d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box_6),
        cmocka_unit_test(test_box_5),
        cmocka_unit_test(test_box_bad),
        cmocka_unit_test(test_primitive_bad),
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_hollow_sphere),
        cmocka_unit_test(test_plate),
        cmocka_unit_test(test_notched_beam),
        cmocka_unit_test(test_gmsh_missing_or_failing),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
