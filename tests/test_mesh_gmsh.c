/* Gmsh MSH reading: 4.1 ASCII, 4.1 binary and 2.2 ASCII give the same mesh;
 * physical groups; the errors of unsupported and bad files.
 *
 * The fixtures in tests/data/gmsh/ were written by gmsh 4.8 from cube.geo
 * (the unit cube [0,1]^3, Physical Volume "solid", Physical Surfaces
 * "bottom" (z = 0) and "top" (z = 1)); the commands are in cube.geo. */
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

#include "check.h"
#include "fixtures.h"
#include "cohfrac/mesh.h"

#define DATA COHFRAC_SOURCE_DIR "/tests/data/gmsh/"

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/cohfrac-test-gmsh-XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    fixture_remove_tree(tmpdir);
    return 0;
}

/* Write `n` bytes to <tmpdir>/<name>; returns the path (static buffer). */
static const char *put(const char *name, const char *data, size_t n)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
    return path;
}

static const char *put_text(const char *name, const char *text)
{
    return put(name, text, strlen(text));
}

static char *read_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)len + 1);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)len, f), (size_t)len);
    b[len] = '\0';
    fclose(f);
    *n = (size_t)len;
    return b;
}

static const cf_mesh_group *group(const cf_mesh *m, const char *name)
{
    for (int g = 0; g < m->n_groups; g++)
        if (!strcmp(m->groups[g].name, name))
            return &m->groups[g];
    return NULL;
}

/* The cube in any of the three formats: volume 1, every tet positive, the
 * groups where they belong.  Returns the counts for cross-format checks. */
static void check_cube(const char *file, int counts[4])
{
    cf_mesh m;
    cf_error err = {0};
    cf_status st = cf_mesh_load_gmsh(file, &m, &err);
    if (st != CF_OK)
        fail_msg("%s: %s", file, err.msg);
    assert_true(m.n_tets > 0);
    assert_near(cf_mesh_volume(&m), 1.0, 1e-12);
    assert_int_equal(cf_mesh_check(&m, file, &err), CF_OK);
    assert_int_equal(m.n_groups, 3);
    const cf_mesh_group *bottom = group(&m, "bottom"), *top = group(&m, "top"),
                        *solid = group(&m, "solid");
    assert_non_null(bottom);
    assert_non_null(top);
    assert_non_null(solid);
    assert_int_equal(bottom->dim, 2);
    assert_int_equal(solid->dim, 3);
    assert_true(bottom->n_nodes >= 4);
    for (int i = 0; i < bottom->n_nodes; i++) {
        assert_true(m.x[3 * bottom->nodes[i] + 2] == 0.0);
        if (i > 0)
            assert_true(bottom->nodes[i] > bottom->nodes[i - 1]); /* ascending, unique */
    }
    for (int i = 0; i < top->n_nodes; i++)
        assert_true(m.x[3 * top->nodes[i] + 2] == 1.0);
    assert_int_equal(solid->n_nodes, m.n_nodes); /* every node is in some tet */
    counts[0] = m.n_nodes, counts[1] = m.n_tets, counts[2] = bottom->n_nodes,
    counts[3] = top->n_nodes;
    cf_mesh_free(&m);
    assert_null(m.x);
    assert_null(m.groups);
    assert_int_equal(m.n_groups, 0);
}

static void test_three_formats_agree(void **state)
{
    (void)state;
    int a[4], b[4], c[4];
    check_cube(DATA "cube_v41.msh", a);
    check_cube(DATA "cube_v41_bin.msh", b);
    check_cube(DATA "cube_v22.msh", c);
    for (int k = 0; k < 4; k++) {
        assert_int_equal(a[k], b[k]);
        assert_int_equal(a[k], c[k]);
    }
}

static void test_load_dispatch(void **state)
{
    (void)state;
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load(DATA "cube_v41.msh", &m, &err), CF_OK);
    assert_true(m.n_groups == 3); /* only the Gmsh loader fills groups */
    cf_mesh_free(&m);
    /* any other name is a TetGen base name */
    put_text("two.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
    put_text("two.ele", "1 4 0\n0 0 1 2 3\n");
    char base[512];
    snprintf(base, sizeof base, "%s/two", tmpdir);
    assert_int_equal(cf_mesh_load(base, &m, &err), CF_OK);
    assert_int_equal(m.n_tets, 1);
    assert_int_equal(m.n_groups, 0);
    cf_mesh_free(&m);
    snprintf(base, sizeof base, "%s/missing.msh", tmpdir);
    assert_int_equal(cf_mesh_load(base, &m, &err), CF_ERR_FILE_OPEN);
}

/* A hand-written 2.2 file: tags out of order and with gaps, an inverted tet
 * (re-oriented), an unnamed group. */
static void test_sparse_tags_and_orientation(void **state)
{
    (void)state;
    const char *text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                       "$Comments\nanything $Nodes here\n$EndComments\n"
                       "$Nodes\n5\n"
                       "40 0 0 0\n10 1 0 0\n30 0 1 0\n20 0 0 1\n7 0 0 -1\n"
                       "$EndNodes\n"
                       "$Elements\n3\n"
                       "1 4 2 9 1 40 10 30 20\n"  /* positive */
                       "2 4 2 9 1 40 10 30 7\n"   /* inverted */
                       "3 2 2 5 2 40 10 30\n"     /* triangle in group 2:5 */
                       "$EndElements\n";
    const char *path = put_text("sparse.msh", text);
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_gmsh(path, &m, &err), CF_OK);
    assert_int_equal(m.n_nodes, 5);
    assert_int_equal(m.n_tets, 2);
    assert_true(m.x[3 * 1 + 0] == 1.0); /* tag 10 is the second node of the file */
    assert_int_equal(m.tets[0], 0);
    assert_int_equal(m.tets[1], 1);
    assert_near(cf_mesh_volume(&m), 1.0 / 3.0, 1e-15);
    assert_int_equal(m.n_groups, 2);
    assert_string_equal(m.groups[0].name, "2:5"); /* sorted by (dim, tag) */
    assert_int_equal(m.groups[0].n_nodes, 3);
    assert_string_equal(m.groups[1].name, "3:9");
    assert_int_equal(m.groups[1].n_nodes, 5);
    cf_mesh_free(&m);
}

/* ---- errors ---- */

static void test_version_40_rejected(void **state)
{
    (void)state;
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_gmsh(DATA "cube_v40.msh", &m, &err), CF_ERR_MESH_FORMAT);
    assert_non_null(strstr(err.msg, "4.0"));
    assert_non_null(strstr(err.msg, "4.1"));
    assert_non_null(strstr(err.msg, "msh41"));
    assert_null(m.x);
    /* 2.2 binary and other versions likewise */
    static const char bin22[] = "$MeshFormat\n2.2 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n";
    assert_int_equal(cf_mesh_load_gmsh(put("b22.msh", bin22, sizeof bin22 - 1), &m, &err),
                     CF_ERR_MESH_FORMAT);
    assert_non_null(strstr(err.msg, "binary MSH 2.2"));
    const char *v3 = "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n";
    assert_int_equal(cf_mesh_load_gmsh(put_text("v3.msh", v3), &m, &err),
                     CF_ERR_MESH_FORMAT);
    assert_non_null(strstr(err.msg, "4.1"));
}

static void test_surface_only_rejected(void **state)
{
    (void)state;
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_gmsh(DATA "cube_surface.msh", &m, &err), CF_ERR_MESH_FORMAT);
    assert_non_null(strstr(err.msg, "no tetrahedra"));
    assert_non_null(strstr(err.msg, "gmsh -3"));
    assert_null(m.x);
    assert_int_equal(m.n_groups, 0);
}

static void test_truncated(void **state)
{
    (void)state;
    cf_mesh m;
    cf_error err = {0};
    static const char *files[] = {"cube_v41.msh", "cube_v41_bin.msh", "cube_v22.msh"};
    for (int f = 0; f < 3; f++) {
        char src[512];
        snprintf(src, sizeof src, DATA "%s", files[f]);
        size_t n;
        char *text = read_file(src, &n);
        /* cut in the middle of the file, then just before the end */
        size_t cuts[] = {n / 2, n / 3, n - 20, 40};
        for (int c = 0; c < 4; c++) {
            const char *p = put("cut.msh", text, cuts[c]);
            cf_status st = cf_mesh_load_gmsh(p, &m, &err);
            if (st != CF_ERR_MESH_PARSE)
                fail_msg("%s cut at %zu: %s", files[f], cuts[c], err.msg);
            assert_non_null(strstr(err.msg, "cut.msh"));
            assert_null(m.x);
            assert_null(m.tets);
            assert_null(m.groups);
        }
        free(text);
    }
    /* ASCII: the line is named (here the count the rest cannot hold) */
    const char *t = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0\n";
    assert_int_equal(cf_mesh_load_gmsh(put_text("t.msh", t), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "t.msh:5:"));
    assert_non_null(strstr(err.msg, "truncated"));
    /* a file that stops after its last element: no $EndElements */
    const char *u = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n"
                    "3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 0 1 2 3 4\n";
    assert_int_equal(cf_mesh_load_gmsh(put_text("u.msh", u), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "u.msh:14:"));
    assert_non_null(strstr(err.msg, "$EndElements"));
    /* binary: the byte offset is named */
    size_t n;
    char *bin = read_file(DATA "cube_v41_bin.msh", &n);
    assert_int_equal(cf_mesh_load_gmsh(put("b.msh", bin, n - 100), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "b.msh: byte "));
    free(bin);
}

static void test_garbage(void **state)
{
    (void)state;
    cf_mesh m;
    cf_error err = {0};
    const char *a = "hello\n";
    assert_int_equal(cf_mesh_load_gmsh(put_text("a.msh", a), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "$MeshFormat"));
    const char *b = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n0 1 0 1\n1\n0 zz 0\n"
                    "$EndNodes\n";
    assert_int_equal(cf_mesh_load_gmsh(put_text("b.msh", b), &m, &err), CF_ERR_MESH_PARSE);
    assert_non_null(strstr(err.msg, "b.msh:8:"));
    assert_non_null(strstr(err.msg, "'zz'"));
    assert_int_equal(cf_mesh_load_gmsh(put("e.msh", "", 0), &m, &err), CF_ERR_MESH_PARSE);
    /* random bytes after a binary header */
    static const char head[] = "$MeshFormat\n4.1 1 8\n\x01\x00\x00\x00\n$EndMeshFormat\n$Nodes\n";
    char junk[400];
    size_t h = sizeof head - 1; /* the header, with its NUL bytes */
    memcpy(junk, head, h);
    for (size_t i = h; i < sizeof junk; i++)
        junk[i] = (char)(i * 37 + 11);
    assert_int_equal(cf_mesh_load_gmsh(put("j.msh", junk, sizeof junk), &m, &err),
                     CF_ERR_MESH_PARSE);
    assert_null(m.x);
}

static void test_missing_node(void **state)
{
    (void)state;
    const char *text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                       "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"
                       "$Elements\n2\n"
                       "1 4 0 1 2 3 4\n"
                       "2 4 0 1 2 3 5\n"
                       "$EndElements\n";
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_gmsh(put_text("miss.msh", text), &m, &err),
                     CF_ERR_MESH_INDEX);
    assert_non_null(strstr(err.msg, "miss.msh:14:"));
    assert_non_null(strstr(err.msg, "element 2"));
    assert_non_null(strstr(err.msg, "node 5"));
    assert_null(m.x);
    assert_null(m.tets);
}

static void test_missing_file(void **state)
{
    (void)state;
    cf_mesh m;
    cf_error err = {0};
    assert_int_equal(cf_mesh_load_gmsh(DATA "no_such_file.msh", &m, &err), CF_ERR_FILE_OPEN);
    assert_non_null(strstr(err.msg, "no_such_file.msh"));
    assert_null(m.x);
    assert_int_equal(m.n_nodes, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_three_formats_agree),
        cmocka_unit_test(test_load_dispatch),
        cmocka_unit_test(test_sparse_tags_and_orientation),
        cmocka_unit_test(test_version_40_rejected),
        cmocka_unit_test(test_surface_only_rejected),
        cmocka_unit_test(test_truncated),
        cmocka_unit_test(test_garbage),
        cmocka_unit_test(test_missing_node),
        cmocka_unit_test(test_missing_file),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
