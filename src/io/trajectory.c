/* Reading a run's HDF5 output back: see trajectory.h. */
#include "trajectory.h"

#include "h5_quiet.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static const char *const obs_names[] = {
#define CF_X_OBS_NAME(id, name) name,
    CF_TRAJ_OBSERVABLES(CF_X_OBS_NAME)
#undef CF_X_OBS_NAME
};

void *cf_h5_read_all(hid_t file, const char *name, hid_t type, size_t size, int *rank,
                      hsize_t dims[3])
{
    if (H5Lexists(file, name, H5P_DEFAULT) <= 0)
        return NULL;
    hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
    if (d < 0)
        return NULL;
    hid_t sp = H5Dget_space(d);
    int r = H5Sget_simple_extent_ndims(sp);
    void *buf = NULL;
    if (r >= 1 && r <= 3) {
        H5Sget_simple_extent_dims(sp, dims, NULL);
        size_t n = 1;
        for (int i = 0; i < r; i++)
            n *= dims[i];
        buf = malloc(n ? n * size : 1);
        if (buf && n && H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) {
            free(buf);
            buf = NULL;
        }
    }
    *rank = r;
    H5Sclose(sp);
    H5Dclose(d);
    return buf;
}

hsize_t cf_h5_whole_frames(hid_t file, hsize_t rows)
{
    int64_t whole = -1;
    if (H5Aexists_by_name(file, "/", "frames", H5P_DEFAULT) > 0) {
        hid_t a = H5Aopen_by_name(file, "/", "frames", H5P_DEFAULT, H5P_DEFAULT);
        if (a < 0 || H5Aread(a, H5T_NATIVE_INT64, &whole) < 0)
            whole = -1;
        if (a >= 0)
            H5Aclose(a);
    }
    return whole >= 0 && (hsize_t)whole < rows ? (hsize_t)whole : rows;
}

/* First and last complete sample of an observable (NaN when absent). */
static void read_observable(hid_t file, const char *name, double *first, double *last)
{
    char path[128];
    int r1, r2;
    hsize_t ds[3], dv[3];
    *first = *last = NAN;
    snprintf(path, sizeof path, "/observables/%s/step", name);
    long long *step = cf_h5_read_all(file, path, H5T_NATIVE_LLONG, sizeof(long long), &r1, ds);
    snprintf(path, sizeof path, "/observables/%s/value", name);
    double *v = cf_h5_read_all(file, path, H5T_NATIVE_DOUBLE, sizeof(double), &r2, dv);
    if (step && v && r1 == 1 && r2 == 1) {
        hsize_t n = ds[0] < dv[0] ? ds[0] : dv[0];
        if (n > 0)
            *first = v[0], *last = v[n - 1];
    }
    free(step), free(v);
}

cf_status cf_trajectory_read(const char *path, cf_trajectory *t, cf_error *err)
{
    memset(t, 0, sizeof *t);
    quiet_state q;
    quiet_begin(&q);
    cf_status st = CF_OK;
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0) {
        quiet_end(&q);
        return cf_error_set(err, CF_ERR_FILE_OPEN,
                            "%s: cannot open as HDF5 (missing, or not a cohfrac output)", path);
    }
    int rs, rt, rp, rpar, rm;
    hsize_t ds[3], dt[3], dp[3], dpar[3], dm[3];
    long long *step = cf_h5_read_all(file, "/particles/fragments/position/step", H5T_NATIVE_LLONG,
                               sizeof(long long), &rs, ds);
    t->time = cf_h5_read_all(file, "/particles/fragments/position/time", H5T_NATIVE_DOUBLE,
                       sizeof(double), &rt, dt);
    t->pos = cf_h5_read_all(file, "/particles/fragments/position/value", H5T_NATIVE_DOUBLE,
                      sizeof(double), &rp, dp);
    t->parent = cf_h5_read_all(file, "/fragments/parent", H5T_NATIVE_INT, sizeof(int), &rpar, dpar);
    t->mass = cf_h5_read_all(file, "/fragments/mass", H5T_NATIVE_DOUBLE, sizeof(double), &rm, dm);
    if (step) /* the whole frames (a killed run's file: docs/output.md) */
        ds[0] = cf_h5_whole_frames(file, ds[0]);
    if (!step || !t->time || !t->pos || !t->parent || !t->mass)
        st = cf_error_set(err, CF_ERR_MESH_FORMAT,
                          "%s: /particles/fragments/position or /fragments/{parent,mass} "
                          "missing or unreadable: not a cohfrac output file",
                          path);
    else if (rs != 1 || rt != 1 || rp != 3 || dp[2] != 3 || rpar != 1 || rm != 1 ||
             dt[0] < ds[0] || dp[0] < ds[0] || dm[0] != dpar[0] || dp[1] < dpar[0])
        st = cf_error_set(err, CF_ERR_MESH_FORMAT,
                          "%s: fragment datasets of inconsistent shapes (position %dD, "
                          "parent %d, mass %d): not a cohfrac output file",
                          path, rp, (int)dpar[0], (int)dm[0]);
    if (st == CF_OK) {
        /* Keep the fragments that have records: columns [0, N) of each frame. */
        t->T = (int)ds[0];
        t->N = (int)dpar[0];
        int cols = (int)dp[1];
        for (int k = 0; k < t->T && cols != t->N; k++)
            memmove(&t->pos[3 * (size_t)k * t->N], &t->pos[3 * (size_t)k * cols],
                    3 * (size_t)t->N * sizeof(double));
        for (int i = 0; i < CF_OBS_COUNT; i++)
            read_observable(file, obs_names[i], &t->first[i], &t->last[i]);
    }
    free(step);
    H5Fclose(file);
    quiet_end(&q);
    if (st != CF_OK)
        cf_trajectory_free(t);
    return st;
}

void cf_trajectory_free(cf_trajectory *t)
{
    free(t->time), free(t->pos), free(t->parent), free(t->mass);
    memset(t, 0, sizeof *t);
}
