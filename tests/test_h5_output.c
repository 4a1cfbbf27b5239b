/* Tests of the HDF5 output: write a run, read it back with the HDF5 C API
 * and check shapes, values, fill values, attributes and the XDMF sidecar;
 * read a file whose writer is still open or was killed; error reporting. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "fixtures.h"

#include "cohfrac/h5_output.h"
#include "trajectory.h"

#include <hdf5.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* ---- fixture: one temporary directory per test ------------------------- */

typedef struct fixture {
    char dir[256];
} fixture;

static int make_tmpdir(void **state)
{
    fixture *fx = calloc(1, sizeof *fx);
    if (!fx)
        return -1;
    const char *tmp = getenv("TMPDIR");
    snprintf(fx->dir, sizeof fx->dir, "%s/cohfrac_h5_XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(fx->dir)) {
        free(fx);
        return -1;
    }
    *state = fx;
    return 0;
}

static int remove_tmpdir(void **state)
{
    fixture *fx = *state;
    fixture_remove_tree(fx->dir);
    free(fx);
    return 0;
}

static void join(char *out, size_t n, const fixture *fx, const char *name)
{
    snprintf(out, n, "%s/%s", fx->dir, name);
}

/* ---- reading helpers --------------------------------------------------- */

static int dims_of(hid_t f, const char *name, hsize_t *dims)
{
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    hid_t s = H5Dget_space(d);
    int rank = H5Sget_simple_extent_ndims(s);
    H5Sget_simple_extent_dims(s, dims, NULL);
    H5Sclose(s);
    H5Dclose(d);
    return rank;
}

static void read_all(hid_t f, const char *name, hid_t mtype, void *buf)
{
    hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
    assert_true(d >= 0);
    assert_true(H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    H5Dclose(d);
}

/* Reads a whole 1-D dataset and checks its length. */
static void read_1d(hid_t f, const char *name, hid_t mtype, void *buf, hsize_t expect_len)
{
    hsize_t dims[3];
    assert_int_equal(dims_of(f, name, dims), 1);
    assert_int_equal(dims[0], expect_len);
    read_all(f, name, mtype, buf);
}

/* A scalar variable-length string (attribute of `obj`, or a dataset when
 * `attr` is NULL), returned malloc'd. */
static char *read_string(hid_t f, const char *obj, const char *attr)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    char *v = NULL;
    if (attr) {
        hid_t a = H5Aopen_by_name(f, obj, attr, H5P_DEFAULT, H5P_DEFAULT);
        assert_true(a >= 0);
        assert_true(H5Aread(a, t, &v) >= 0);
        H5Aclose(a);
    } else {
        hid_t d = H5Dopen2(f, obj, H5P_DEFAULT);
        assert_true(d >= 0);
        assert_true(H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &v) >= 0);
        H5Dclose(d);
    }
    H5Tclose(t);
    assert_non_null(v);
    char *copy = strdup(v);
    H5free_memory(v);
    return copy;
}

static void check_string(hid_t f, const char *obj, const char *attr, const char *expect)
{
    char *s = read_string(f, obj, attr);
    assert_string_equal(s, expect);
    free(s);
}


static int count_occurrences(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle))
        ++n;
    return n;
}

static int file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* ---- the scenario ------------------------------------------------------ */

/* Deterministic state of fragment `id` in frame `t`. */
static cf_frag_frame frag_state(int id, int t, int mode)
{
    cf_frag_frame f;
    f.id = id;
    f.mode = mode;
    f.com[0] = id + 0.1 * t;
    f.com[1] = 2.0 * id;
    f.com[2] = 3.0 - 0.01 * t;
    f.quat[0] = 1.0;
    f.quat[1] = 0.1 * id;
    f.quat[2] = 0.01 * t;
    f.quat[3] = -0.5;
    f.v[0] = id;
    f.v[1] = t;
    f.v[2] = -1.0 - id;
    f.w[0] = 0.5 * id;
    f.w[1] = 0.0;
    f.w[2] = 0.25 * t;
    return f;
}

static const double *frag_field(const cf_frag_frame *f, const char *field)
{
    if (strcmp(field, "position") == 0)
        return f->com;
    if (strcmp(field, "orientation") == 0)
        return f->quat;
    if (strcmp(field, "velocity") == 0)
        return f->v;
    return f->w;
}

#define NFRAMES 4
#define NFRAGS 3
/* Which fragments are alive in each frame (listed out of id order on purpose)
 * and their mode.  Fragment 0 lives alone, splits into 1 and 2, then ends. */
static const int ALIVE[NFRAMES][NFRAGS] = {{0, -1, -1}, {0, -1, -1}, {2, 0, 1}, {2, 1, -1}};
static const int MODE[NFRAMES] = {0, 1, 1, 0};
static const long STEPS[NFRAMES] = {0, 10, 20, 30};
static const double TIMES[NFRAMES] = {0.0, 0.01, 0.02, 0.03};
static const char SCENE_TEXT[] = "-- drop \"bunny\" onto the floor\n"
                                 "scene { name = 'drop', dt = 1e-3,\n"
                                 "        note = \"M\xc3\xbcller 2007\" }\n";

static int alive_in(int t, int id)
{
    for (int k = 0; k < NFRAGS; ++k)
        if (ALIVE[t][k] == id)
            return 1;
    return 0;
}

static void write_scenario(const char *path)
{
    cf_error err = {0};
    cf_h5 *h = NULL;
    assert_int_equal(cf_h5_open(path, "drop", SCENE_TEXT, &h, &err), CF_OK);
    assert_non_null(h);

    const cf_frag_info first = {0, -1, 0.0, 2.5, 100, {1.0, 2.0, 3.0}, 0, 0, 0, {0, 0, 0}, 0, 0, 0};
    assert_int_equal(cf_h5_add_fragments(h, &first, 1, &err), CF_OK);
    for (int t = 0; t < NFRAMES; ++t) {
        if (t == 2) {
            /* the split's children, given out of id order */
            const cf_frag_info kids[2] = {{2, 0, 0.02, 1.0, 40, {0.1, 0.2, 0.3}, 0, 0, 0, {0, 0, 0}, 0, 0, 1},
                                          {1, 0, 0.02, 1.5, 60, {0.4, 0.5, 0.6}, 0, 0, 0, {0, 0, 0}, 0, 0, 0}};
            assert_int_equal(cf_h5_add_fragments(h, kids, 2, &err), CF_OK);
        }
        cf_frag_frame frames[NFRAGS];
        int n = 0;
        for (int k = 0; k < NFRAGS; ++k)
            if (ALIVE[t][k] >= 0)
                frames[n++] = frag_state(ALIVE[t][k], t, MODE[t]);
        assert_int_equal(cf_h5_write_frame(h, STEPS[t], TIMES[t], frames, n, &err), CF_OK);
        assert_int_equal(
            cf_h5_write_observable(h, "kinetic_energy", NULL, STEPS[t], TIMES[t], 10.0 - t, &err), CF_OK);
        if (t % 2 == 0)
            assert_int_equal(
                cf_h5_write_observable(h, "n_cohesive", NULL, STEPS[t], TIMES[t], 5.0 * t, &err), CF_OK);
        if (t == 1 || t == 3) {
            const cf_handoff_record r = {.time = TIMES[t], .fragment = 0, .direction = t == 1 ? 0 : 1,
                                         .momentum_error = 1e-12 * t, .handoff_loss = 0.5 * t};
            assert_int_equal(cf_h5_add_handoff(h, &r, &err), CF_OK);
        }
    }
    assert_int_equal(cf_h5_close(h, &err), CF_OK);
}

/* ---- tests ------------------------------------------------------------- */

static void test_round_trip(void **state)
{
    fixture *fx = *state;
    char path[512], xdmf[512];
    join(path, sizeof path, fx, "made/on/demand/run.h5");
    join(xdmf, sizeof xdmf, fx, "made/on/demand/run.xdmf");
    write_scenario(path);

    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);

    /* root attributes, scene, H5MD metadata */
    check_string(f, "/", "creator", "cohfrac");
    check_string(f, "/", "units", "SI");
    check_string(f, "/", "up_axis", "+z");
    check_string(f, "/", "quaternion_order", "wxyz");
    check_string(f, "/", "scene_name", "drop");
    char *version = read_string(f, "/", "version");
    assert_true(strlen(version) > 0);
    free(version);
    check_string(f, "/parameters/scene", NULL, SCENE_TEXT);
    int h5md_version[2] = {0, 0};
    hid_t a = H5Aopen_by_name(f, "/h5md", "version", H5P_DEFAULT, H5P_DEFAULT);
    assert_true(a >= 0);
    assert_true(H5Aread(a, H5T_NATIVE_INT, h5md_version) >= 0);
    H5Aclose(a);
    assert_int_equal(h5md_version[0], 1);
    assert_int_equal(h5md_version[1], 1);
    check_string(f, "/h5md/creator", "name", "cohfrac");

    /* step and time, the same for every field */
    const char *fields[] = {"id",       "position",         "orientation",
                            "velocity", "angular_velocity", "mode"};
    for (int i = 0; i < 6; ++i) {
        char name[128];
        int64_t step[NFRAMES];
        double time[NFRAMES];
        snprintf(name, sizeof name, "/particles/fragments/%s/step", fields[i]);
        read_1d(f, name, H5T_NATIVE_INT64, step, NFRAMES);
        snprintf(name, sizeof name, "/particles/fragments/%s/time", fields[i]);
        read_1d(f, name, H5T_NATIVE_DOUBLE, time, NFRAMES);
        for (int t = 0; t < NFRAMES; ++t) {
            assert_int_equal(step[t], STEPS[t]);
            assert_true(time[t] == TIMES[t]);
        }
    }

    /* id and mode: [T][N], -1 where not alive (including not yet born) */
    hsize_t dims[3];
    int ids[NFRAMES][NFRAGS], modes[NFRAMES][NFRAGS];
    assert_int_equal(dims_of(f, "/particles/fragments/id/value", dims), 2);
    assert_int_equal(dims[0], NFRAMES);
    assert_int_equal(dims[1], NFRAGS);
    assert_int_equal(dims_of(f, "/particles/fragments/mode/value", dims), 2);
    read_all(f, "/particles/fragments/id/value", H5T_NATIVE_INT, ids);
    read_all(f, "/particles/fragments/mode/value", H5T_NATIVE_INT, modes);
    for (int t = 0; t < NFRAMES; ++t)
        for (int j = 0; j < NFRAGS; ++j) {
            assert_int_equal(ids[t][j], alive_in(t, j) ? j : -1);
            assert_int_equal(modes[t][j], alive_in(t, j) ? MODE[t] : -1);
        }

    /* vector fields: [T][N][k], NaN where not alive */
    const char *vec[] = {"position", "orientation", "velocity", "angular_velocity"};
    for (int i = 0; i < 4; ++i) {
        const int k = strcmp(vec[i], "orientation") == 0 ? 4 : 3;
        char name[128];
        double buf[NFRAMES * NFRAGS * 4];
        snprintf(name, sizeof name, "/particles/fragments/%s/value", vec[i]);
        assert_int_equal(dims_of(f, name, dims), 3);
        assert_int_equal(dims[0], NFRAMES);
        assert_int_equal(dims[1], NFRAGS);
        assert_int_equal(dims[2], k);
        read_all(f, name, H5T_NATIVE_DOUBLE, buf);
        for (int t = 0; t < NFRAMES; ++t)
            for (int j = 0; j < NFRAGS; ++j) {
                cf_frag_frame s = frag_state(j, t, 0);
                const double *want = frag_field(&s, vec[i]);
                for (int c = 0; c < k; ++c) {
                    double got = buf[(t * NFRAGS + j) * k + c];
                    if (alive_in(t, j))
                        assert_true(got == want[c]);
                    else
                        assert_true(isnan(got));
                }
            }
    }

    /* the fill values are declared, so later extensions fill the same way */
    hid_t d = H5Dopen2(f, "/particles/fragments/position/value", H5P_DEFAULT);
    hid_t dcpl = H5Dget_create_plist(d);
    double fill = 0.0;
    assert_true(H5Pget_fill_value(dcpl, H5T_NATIVE_DOUBLE, &fill) >= 0);
    assert_true(isnan(fill));
    H5Pclose(dcpl);
    H5Dclose(d);

    /* fragment records, stored by id */
    int parent[NFRAGS], ntets[NFRAGS], debris[NFRAGS];
    double birth[NFRAGS], mass[NFRAGS], inertia[NFRAGS][3];
    read_1d(f, "/fragments/parent", H5T_NATIVE_INT, parent, NFRAGS);
    read_1d(f, "/fragments/n_tets", H5T_NATIVE_INT, ntets, NFRAGS);
    read_1d(f, "/fragments/birth_time", H5T_NATIVE_DOUBLE, birth, NFRAGS);
    read_1d(f, "/fragments/mass", H5T_NATIVE_DOUBLE, mass, NFRAGS);
    read_1d(f, "/fragments/debris", H5T_NATIVE_INT, debris, NFRAGS);
    assert_int_equal(debris[0], 0);
    assert_int_equal(debris[1], 0);
    assert_int_equal(debris[2], 1); /* given out of id order */
    assert_int_equal(dims_of(f, "/fragments/inertia_principal", dims), 2);
    assert_int_equal(dims[0], NFRAGS);
    assert_int_equal(dims[1], 3);
    read_all(f, "/fragments/inertia_principal", H5T_NATIVE_DOUBLE, inertia);
    assert_int_equal(parent[0], -1);
    assert_int_equal(parent[1], 0);
    assert_int_equal(parent[2], 0);
    assert_int_equal(ntets[0], 100);
    assert_int_equal(ntets[1], 60);
    assert_int_equal(ntets[2], 40);
    assert_true(birth[0] == 0.0 && birth[1] == 0.02 && birth[2] == 0.02);
    assert_true(mass[0] == 2.5 && mass[1] == 1.5 && mass[2] == 1.0);
    assert_true(inertia[0][2] == 3.0 && inertia[1][0] == 0.4 && inertia[2][1] == 0.2);

    /* observables: created on first use, one row per sample */
    int64_t ostep[NFRAMES];
    double otime[NFRAMES], oval[NFRAMES];
    read_1d(f, "/observables/kinetic_energy/step", H5T_NATIVE_INT64, ostep, NFRAMES);
    read_1d(f, "/observables/kinetic_energy/time", H5T_NATIVE_DOUBLE, otime, NFRAMES);
    read_1d(f, "/observables/kinetic_energy/value", H5T_NATIVE_DOUBLE, oval, NFRAMES);
    for (int t = 0; t < NFRAMES; ++t) {
        assert_int_equal(ostep[t], STEPS[t]);
        assert_true(otime[t] == TIMES[t]);
        assert_true(oval[t] == 10.0 - t);
    }
    read_1d(f, "/observables/n_cohesive/step", H5T_NATIVE_INT64, ostep, 2);
    read_1d(f, "/observables/n_cohesive/value", H5T_NATIVE_DOUBLE, oval, 2);
    assert_int_equal(ostep[0], 0);
    assert_int_equal(ostep[1], 20);
    assert_true(oval[0] == 0.0 && oval[1] == 10.0);

    /* hand-offs */
    double htime[2], herr[2], hloss[2];
    int hfrag[2], hdir[2];
    read_1d(f, "/handoffs/time", H5T_NATIVE_DOUBLE, htime, 2);
    read_1d(f, "/handoffs/fragment", H5T_NATIVE_INT, hfrag, 2);
    read_1d(f, "/handoffs/direction", H5T_NATIVE_INT, hdir, 2);
    read_1d(f, "/handoffs/momentum_error", H5T_NATIVE_DOUBLE, herr, 2);
    read_1d(f, "/handoffs/handoff_loss", H5T_NATIVE_DOUBLE, hloss, 2);
    assert_true(htime[0] == 0.01 && htime[1] == 0.03);
    assert_int_equal(hfrag[0], 0);
    assert_int_equal(hfrag[1], 0);
    assert_int_equal(hdir[0], 0);
    assert_int_equal(hdir[1], 1);
    assert_true(herr[0] == 1e-12 && herr[1] == 3e-12);
    assert_true(hloss[0] == 0.5 && hloss[1] == 1.5);

    /* the sidecar's topology: alive columns of each frame, in frame order */
    int conn[7];
    const int want_conn[7] = {0, 0, 0, 1, 2, 1, 2};
    read_1d(f, "/xdmf/polyvertex", H5T_NATIVE_INT, conn, 7);
    assert_memory_equal(conn, want_conn, sizeof conn);
    assert_true(H5Fclose(f) >= 0);

    char *x = fixture_read_file(xdmf);
    assert_non_null(x);
    assert_non_null(strstr(x, "<Xdmf Version=\"3.0\""));
    assert_non_null(strstr(x, "CollectionType=\"Temporal\""));
    assert_int_equal(count_occurrences(x, "<Grid Name=\"frame_"), NFRAMES);
    assert_int_equal(count_occurrences(x, "TopologyType=\"Polyvertex\""), NFRAMES);
    /* last frame: row 3 of [4][3](,3), and cells 5..6 of the 7 alive entries */
#define FRAGS ">run.h5:/particles/fragments/"
    assert_non_null(strstr(x, FRAGS "position/value|3 0 0:1 1 1:1 3 3:4 3 3<"));
    assert_non_null(strstr(x, FRAGS "velocity/value|3 0 0:1 1 1:1 3 3:4 3 3<"));
    assert_non_null(strstr(x, FRAGS "id/value|3 0:1 1:1 3:4 3<"));
    assert_non_null(strstr(x, ">run.h5:/xdmf/polyvertex|5:1:2:7<"));
    /* first frame: one fragment, one column wide at the time */
    assert_non_null(strstr(x, FRAGS "position/value|0 0 0:1 1 1:1 1 3:4 3 3<"));
#undef FRAGS
    assert_non_null(strstr(x, "<Time Value=\"0.03\"/>"));
    assert_null(strstr(x, fx->dir)); /* relative to the sidecar, so the pair can move */
    free(x);
    char tmp[600];
    snprintf(tmp, sizeof tmp, "%s.tmp", xdmf);
    assert_false(file_exists(tmp));
}

/* Two identical runs give identical bytes (no timestamps in the file). */
static void test_reproducible_bytes(void **state)
{
    fixture *fx = *state;
    char p1[512], p2[512];
    join(p1, sizeof p1, fx, "one.h5");
    join(p2, sizeof p2, fx, "two.h5");
    write_scenario(p1);
    write_scenario(p2);
    struct stat s1, s2;
    assert_int_equal(stat(p1, &s1), 0);
    assert_int_equal(stat(p2, &s2), 0);
    assert_int_equal(s1.st_size, s2.st_size);
    char *b1 = malloc((size_t)s1.st_size), *b2 = malloc((size_t)s2.st_size);
    FILE *f1 = fopen(p1, "rb"), *f2 = fopen(p2, "rb");
    assert_non_null(f1);
    assert_non_null(f2);
    assert_int_equal(fread(b1, 1, (size_t)s1.st_size, f1), (size_t)s1.st_size);
    assert_int_equal(fread(b2, 1, (size_t)s2.st_size, f2), (size_t)s2.st_size);
    fclose(f1);
    fclose(f2);
    assert_memory_equal(b1, b2, (size_t)s1.st_size);
    free(b1);
    free(b2);
}

/* Many frames, fragments born one per frame up to 70: both dimensions cross
 * chunk boundaries, and 20 observables outgrow the first table size. */
static void test_growth(void **state)
{
    fixture *fx = *state;
    enum { T = 100, NMAX = 70, NOBS = 20 };
    char path[512], xdmf[512];
    join(path, sizeof path, fx, "growth.out");
    join(xdmf, sizeof xdmf, fx, "growth.out.xdmf");
    cf_error err = {0};
    cf_h5 *h = NULL;
    assert_int_equal(cf_h5_open(path, "growth", "", &h, &err), CF_OK);
    cf_frag_frame frames[NMAX];
    for (int t = 0; t < T; ++t) {
        int n = t + 1 < NMAX ? t + 1 : NMAX;
        if (t < NMAX) {
            cf_frag_info fi = {t, t == 0 ? -1 : 0, 0.001 * t, 1.0, 4, {1, 1, 1}, 0, 0, 0, {0, 0, 0}, 0, 0, 0};
            assert_int_equal(cf_h5_add_fragments(h, &fi, 1, &err), CF_OK);
        }
        for (int j = 0; j < n; ++j)
            frames[j] = frag_state(j, t, 1);
        assert_int_equal(cf_h5_write_frame(h, t, 0.001 * t, frames, n, &err), CF_OK);
        for (int o = 0; o < NOBS; ++o) {
            char name[32];
            snprintf(name, sizeof name, "obs_%02d", o);
            assert_int_equal(cf_h5_write_observable(h, name, NULL, t, 0.001 * t, 100.0 * o + t, &err),
                             CF_OK);
        }
    }
    assert_int_equal(cf_h5_close(h, &err), CF_OK);

    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    hsize_t dims[3];
    assert_int_equal(dims_of(f, "/particles/fragments/velocity/value", dims), 3);
    assert_int_equal(dims[0], T);
    assert_int_equal(dims[1], NMAX);
    static int ids[T][NMAX];
    static double vel[T][NMAX][3];
    read_all(f, "/particles/fragments/id/value", H5T_NATIVE_INT, ids);
    read_all(f, "/particles/fragments/velocity/value", H5T_NATIVE_DOUBLE, vel);
    for (int t = 0; t < T; ++t)
        for (int j = 0; j < NMAX; ++j) {
            assert_int_equal(ids[t][j], j <= t ? j : -1);
            if (j <= t) {
                cf_frag_frame s = frag_state(j, t, 1);
                assert_true(vel[t][j][0] == s.v[0] && vel[t][j][1] == s.v[1] &&
                            vel[t][j][2] == s.v[2]);
            } else {
                assert_true(isnan(vel[t][j][0]) && isnan(vel[t][j][2]));
            }
        }
    double val[T];
    read_1d(f, "/observables/obs_19/value", H5T_NATIVE_DOUBLE, val, T);
    for (int t = 0; t < T; ++t)
        assert_true(val[t] == 1900.0 + t);
    int parent[NMAX];
    read_1d(f, "/fragments/parent", H5T_NATIVE_INT, parent, NMAX);
    assert_int_equal(parent[0], -1);
    assert_int_equal(parent[NMAX - 1], 0);
    assert_true(H5Fclose(f) >= 0);

    /* a name without .h5 keeps its extension and gets .xdmf appended */
    char *x = fixture_read_file(xdmf);
    assert_non_null(x);
    assert_int_equal(count_occurrences(x, "<Grid Name=\"frame_"), T);
    assert_non_null(
        strstr(x, ">growth.out:/particles/fragments/position/value|99 0 0:1 1 1:1 70 3:100 70 3<"));
    free(x);
}

/* Checks a file from outside: used by the child process below. */
static int check_frames(const char *path, int expect_frames)
{
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return 10;
    int rc = 0;
    hsize_t dims[3] = {0, 0, 0};
    hid_t d = H5Dopen2(f, "/particles/fragments/id/step", H5P_DEFAULT);
    hid_t s = d >= 0 ? H5Dget_space(d) : H5I_INVALID_HID;
    if (s < 0 || H5Sget_simple_extent_dims(s, dims, NULL) != 1 || dims[0] != (hsize_t)expect_frames)
        rc = 11;
    if (s >= 0)
        H5Sclose(s);
    if (d >= 0)
        H5Dclose(d);
    /* the count a reader trusts in a killed run's file (docs/output.md) */
    int64_t whole = -1;
    hid_t a = H5Aopen_by_name(f, "/", "frames", H5P_DEFAULT, H5P_DEFAULT);
    if (rc == 0 && (a < 0 || H5Aread(a, H5T_NATIVE_INT64, &whole) < 0 || whole != expect_frames))
        rc = 14;
    if (a >= 0)
        H5Aclose(a);
    double pos[3] = {0, 0, 0};
    hsize_t start[3] = {(hsize_t)expect_frames - 1, 0, 0}, count[3] = {1, 1, 3};
    d = H5Dopen2(f, "/particles/fragments/position/value", H5P_DEFAULT);
    s = d >= 0 ? H5Dget_space(d) : H5I_INVALID_HID;
    hid_t ms = H5Screate_simple(3, count, NULL);
    if (rc == 0 && (s < 0 || H5Sselect_hyperslab(s, H5S_SELECT_SET, start, NULL, count, NULL) < 0 ||
                    H5Dread(d, H5T_NATIVE_DOUBLE, ms, s, H5P_DEFAULT, pos) < 0))
        rc = 12;
    cf_frag_frame want = frag_state(0, expect_frames - 1, 0);
    if (rc == 0 && (pos[0] != want.com[0] || pos[1] != want.com[1] || pos[2] != want.com[2]))
        rc = 13;
    H5Sclose(ms);
    if (s >= 0)
        H5Sclose(s);
    if (d >= 0)
        H5Dclose(d);
    H5Fclose(f);
    return rc;
}

static const char *g_self = NULL; /* argv[0], for re-running this program */

/* An open output at path holding fragment 0 in frames 0 .. T-1. */
static cf_h5 *one_fragment_frames(const char *path, int T)
{
    cf_error err = {0};
    cf_h5 *h = NULL;
    assert_int_equal(cf_h5_open(path, "frames", "x = 1", &h, &err), CF_OK);
    const cf_frag_info fi = {0, -1, 0.0, 1.0, 10, {1, 1, 1}, 0, 0, 0, {0, 0, 0}, 0, 0, 0};
    assert_int_equal(cf_h5_add_fragments(h, &fi, 1, &err), CF_OK);
    for (int t = 0; t < T; ++t) {
        cf_frag_frame fr = frag_state(0, t, 0);
        assert_int_equal(cf_h5_write_frame(h, t, 0.1 * t, &fr, 1, &err), CF_OK);
    }
    return h;
}

/* While the writer still has the file open, another process can open it
 * and sees every flushed frame. */
static void test_readable_while_open(void **state)
{
    fixture *fx = *state;
    char path[512];
    join(path, sizeof path, fx, "live.h5");
    cf_error err = {0};
    cf_h5 *h = one_fragment_frames(path, 2);
    /* A fresh process (exec), so nothing is shared with this one's HDF5 state. */
    char exe[1024];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len > 0)
        exe[len] = '\0';
    else
        snprintf(exe, sizeof exe, "%s", g_self);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        execl(exe, exe, "--check-frames", path, "2", (char *)NULL);
        _exit(127);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);

    cf_frag_frame fr = frag_state(0, 2, 0);
    assert_int_equal(cf_h5_write_frame(h, 2, 0.2, &fr, 1, &err), CF_OK);
    assert_int_equal(cf_h5_close(h, &err), CF_OK);
    assert_int_equal(check_frames(path, 3), 0);
}

/* A run killed without closing leaves a readable file holding every frame
 * written before the kill, and no sidecar. */
static void test_killed_writer(void **state)
{
    fixture *fx = *state;
    char path[512], xdmf[512];
    join(path, sizeof path, fx, "killed.h5");
    join(xdmf, sizeof xdmf, fx, "killed.xdmf");
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        cf_error err = {0};
        cf_h5 *h = NULL;
        const cf_frag_info fi[2] = {{0, -1, 0.0, 1.0, 10, {1, 1, 1}, 0, 0, 0, {0, 0, 0}, 0, 0, 0},
                                    {1, -1, 0.0, 2.0, 20, {2, 2, 2}, 0, 0, 0, {0, 0, 0}, 0, 0, 0}};
        if (cf_h5_open(path, "killed", "", &h, &err) != CF_OK ||
            cf_h5_add_fragments(h, fi, 2, &err) != CF_OK)
            _exit(2);
        for (int t = 0; t < 3; ++t) {
            cf_frag_frame fr[2] = {frag_state(0, t, 0), frag_state(1, t, 0)};
            /* observables before their frame: the frame's flush covers them */
            if (cf_h5_write_observable(h, "energy", NULL, t, 0.1 * t, 1.0 * t, &err) != CF_OK ||
                cf_h5_write_frame(h, t, 0.1 * t, fr, 2, &err) != CF_OK)
                _exit(3);
        }
        /* an observable sample after the last flush may or may not be there */
        cf_h5_write_observable(h, "energy", NULL, 3, 0.3, 3.0, &err);
        kill(getpid(), SIGKILL);
        _exit(4);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFSIGNALED(status));
    assert_int_equal(WTERMSIG(status), SIGKILL);

    assert_int_equal(check_frames(path, 3), 0);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    hsize_t dims[3];
    assert_int_equal(dims_of(f, "/particles/fragments/id/value", dims), 2);
    assert_int_equal(dims[0], 3);
    assert_int_equal(dims[1], 2);
    assert_int_equal(dims_of(f, "/observables/energy/step", dims), 1);
    assert_true(dims[0] >= 3);
    assert_int_equal(dims_of(f, "/fragments/mass", dims), 1);
    assert_int_equal(dims[0], 2);
    assert_true(H5Fclose(f) >= 0);
    assert_false(file_exists(xdmf));
}

/* A run killed during a frame's flush may leave step a row longer than the
 * values (HDF5 writes the flush's metadata entry by entry); the readers
 * take the root attribute `frames` as the count, so such a file reads as
 * its whole frames.  Made here by lengthening step after a close. */
static void test_killed_during_a_flush(void **state)
{
    fixture *fx = *state;
    char path[512];
    join(path, sizeof path, fx, "torn.h5");
    cf_error err = {0};
    assert_int_equal(cf_h5_close(one_fragment_frames(path, 3), &err), CF_OK);

    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(f >= 0);
    hid_t d = H5Dopen2(f, "/particles/fragments/id/step", H5P_DEFAULT);
    hsize_t four = 4;
    assert_true(d >= 0 && H5Dset_extent(d, &four) >= 0);
    H5Dclose(d);
    assert_true(H5Fclose(f) >= 0);

    cf_trajectory tr;
    assert_int_equal(cf_trajectory_read(path, &tr, &err), CF_OK);
    assert_int_equal(tr.T, 3);
    assert_int_equal(tr.N, 1);
    cf_frag_frame last = frag_state(0, 2, 0);
    assert_true(tr.pos[6] == last.com[0] && tr.pos[8] == last.com[2]);
    cf_trajectory_free(&tr);

    /* without the count (an older file) the shapes disagree: an error */
    f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(f >= 0 && H5Adelete(f, "frames") >= 0);
    assert_true(H5Fclose(f) >= 0);
    assert_int_equal(cf_trajectory_read(path, &tr, &err), CF_ERR_MESH_FORMAT);
    assert_non_null(strstr(err.msg, "torn.h5"));
}

/* Runs `open` with stderr sent to a file; returns what was printed. */
static char *capture_open_stderr(const fixture *fx, const char *path, cf_status *st, cf_h5 **h,
                                 cf_error *err)
{
    char log[512];
    join(log, sizeof log, fx, "stderr.txt");
    fflush(stderr);
    int saved = dup(2);
    int fd = open(log, O_CREAT | O_TRUNC | O_WRONLY, 0644);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, 2);
    close(fd);
    *st = cf_h5_open(path, "x", "", h, err);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    char *text = fixture_read_file(log);
    unlink(log);
    return text;
}

static void test_open_errors(void **state)
{
    fixture *fx = *state;
    char plain[512], under[600], beside[600];
    join(plain, sizeof plain, fx, "plain");
    FILE *fp = fopen(plain, "w");
    assert_non_null(fp);
    fputs("not a directory\n", fp);
    fclose(fp);

    /* a directory that would have to be made under a regular file */
    snprintf(under, sizeof under, "%s/sub/out.h5", plain);
    cf_error err = {0};
    cf_h5 *h = (cf_h5 *)&err; /* must be reset to NULL */
    assert_int_equal(cf_h5_open(under, "x", "", &h, &err), CF_ERR_OUTPUT);
    assert_int_equal(err.code, CF_ERR_OUTPUT);
    assert_null(h);
    assert_non_null(strstr(err.msg, under));

    /* the parent itself is a regular file */
    snprintf(beside, sizeof beside, "%s/out.h5", plain);
    memset(&err, 0, sizeof err);
    assert_int_equal(cf_h5_open(beside, "x", "", &h, &err), CF_ERR_OUTPUT);
    assert_non_null(strstr(err.msg, beside));
    assert_null(h);

    /* the path is a directory: a message that says so, and nothing
     * printed by HDF5 */
    memset(&err, 0, sizeof err);
    cf_status st = CF_OK;
    char *printed = capture_open_stderr(fx, fx->dir, &st, &h, &err);
    assert_int_equal(st, CF_ERR_OUTPUT);
    assert_null(h);
    assert_non_null(strstr(err.msg, fx->dir));
    assert_non_null(strstr(err.msg, "is a directory"));
    assert_non_null(printed);
    assert_string_equal(printed, "");
    free(printed);

    /* empty path and missing out pointer */
    assert_int_equal(cf_h5_open("", "x", "", &h, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_open(beside, "x", "", NULL, &err), CF_ERR_OUTPUT);
    /* a NULL error record is allowed */
    assert_int_equal(cf_h5_open(under, "x", "", &h, NULL), CF_ERR_OUTPUT);
}

/* Bad arguments are refused before anything is written, and the file stays
 * usable. */
static void test_bad_arguments(void **state)
{
    fixture *fx = *state;
    char path[512];
    join(path, sizeof path, fx, "args.h5");
    cf_error err = {0};
    cf_h5 *h = NULL;
    assert_int_equal(cf_h5_open(path, NULL, NULL, &h, &err), CF_OK);

    const cf_frag_info skip = {1, -1, 0.0, 1.0, 1, {1, 1, 1}, 0, 0, 0, {0, 0, 0}, 0, 0, 0};
    assert_int_equal(cf_h5_add_fragments(h, &skip, 1, &err), CF_ERR_OUTPUT);
    assert_non_null(strstr(err.msg, path));
    const cf_frag_info twice[2] = {{0, -1, 0.0, 1.0, 1, {1, 1, 1}, 0, 0, 0, {0, 0, 0}, 0, 0, 0},
                                   {0, -1, 0.0, 1.0, 1, {1, 1, 1}, 0, 0, 0, {0, 0, 0}, 0, 0, 0}};
    assert_int_equal(cf_h5_add_fragments(h, twice, 2, &err), CF_ERR_OUTPUT);
    const cf_frag_info orphan = {0, 5, 0.0, 1.0, 1, {1, 1, 1}, 0, 0, 0, {0, 0, 0}, 0, 0, 0};
    assert_int_equal(cf_h5_add_fragments(h, &orphan, 1, &err), CF_ERR_OUTPUT);

    cf_frag_frame dup[2] = {frag_state(3, 0, 0), frag_state(3, 0, 0)};
    assert_int_equal(cf_h5_write_frame(h, 0, 0.0, dup, 2, &err), CF_ERR_OUTPUT);
    assert_non_null(strstr(err.msg, "twice"));
    cf_frag_frame neg = frag_state(0, 0, 0);
    neg.id = -2;
    assert_int_equal(cf_h5_write_frame(h, 0, 0.0, &neg, 1, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_write_frame(h, 0, 0.0, NULL, 1, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_write_observable(h, "a/b", NULL, 0, 0.0, 1.0, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_write_observable(h, "", NULL, 0, 0.0, 1.0, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_add_handoff(h, NULL, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_write_frame(NULL, 0, 0.0, NULL, 0, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_add_fragments(NULL, NULL, 0, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_write_observable(NULL, "e", NULL, 0, 0.0, 0.0, &err), CF_ERR_OUTPUT);
    assert_int_equal(cf_h5_add_handoff(NULL, NULL, &err), CF_ERR_OUTPUT);

    /* a frame with no fragment alive is still a frame */
    assert_int_equal(cf_h5_write_frame(h, 0, 0.0, NULL, 0, &err), CF_OK);
    cf_frag_frame one = frag_state(1, 1, 0); /* id 1 without a record is allowed */
    assert_int_equal(cf_h5_write_frame(h, 1, 0.5, &one, 1, &err), CF_OK);
    assert_int_equal(cf_h5_close(h, &err), CF_OK);
    assert_int_equal(cf_h5_close(NULL, &err), CF_OK);

    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(f >= 0);
    hsize_t dims[3];
    assert_int_equal(dims_of(f, "/particles/fragments/id/value", dims), 2);
    assert_int_equal(dims[0], 2);
    assert_int_equal(dims[1], 2);
    int ids[2][2];
    read_all(f, "/particles/fragments/id/value", H5T_NATIVE_INT, ids);
    assert_int_equal(ids[0][0], -1);
    assert_int_equal(ids[0][1], -1);
    assert_int_equal(ids[1][0], -1);
    assert_int_equal(ids[1][1], 1);
    assert_int_equal(dims_of(f, "/fragments/mass", dims), 1);
    assert_int_equal(dims[0], 0);
    assert_int_equal(dims_of(f, "/handoffs/time", dims), 1);
    assert_int_equal(dims[0], 0);
    check_string(f, "/", "scene_name", "");
    check_string(f, "/parameters/scene", NULL, "");
    assert_true(H5Fclose(f) >= 0);
}

int main(int argc, char **argv)
{
    /* child mode of test_readable_while_open */
    if (argc == 4 && strcmp(argv[1], "--check-frames") == 0) {
        H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
        return check_frames(argv[2], atoi(argv[3]));
    }
    g_self = argv[0];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_round_trip, make_tmpdir, remove_tmpdir),
        cmocka_unit_test_setup_teardown(test_reproducible_bytes, make_tmpdir, remove_tmpdir),
        cmocka_unit_test_setup_teardown(test_growth, make_tmpdir, remove_tmpdir),
        cmocka_unit_test_setup_teardown(test_readable_while_open, make_tmpdir, remove_tmpdir),
        cmocka_unit_test_setup_teardown(test_killed_writer, make_tmpdir, remove_tmpdir),
        cmocka_unit_test_setup_teardown(test_killed_during_a_flush, make_tmpdir, remove_tmpdir),
        cmocka_unit_test_setup_teardown(test_open_errors, make_tmpdir, remove_tmpdir),
        cmocka_unit_test_setup_teardown(test_bad_arguments, make_tmpdir, remove_tmpdir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
