/* Reading back a run's HDF5 output (layout in src/io/include/cohfrac/h5_output.h)
 * for the studies: fragment trajectories, the family tree, and the first
 * and last sample of the observables a study compares. */
#ifndef COHFRAC_TRAJECTORY_H
#define COHFRAC_TRAJECTORY_H

#include "cohfrac/error.h"

/* The observables read, by their names under /observables. */
#define CF_TRAJ_OBSERVABLES(X)                                                 \
    X(CF_OBS_KINETIC, "energy_kinetic")                                        \
    X(CF_OBS_STRAIN, "energy_strain")                                          \
    X(CF_OBS_DISSIPATED, "energy_cohesive_dissipated")                         \
    X(CF_OBS_CRACK_AREA, "crack_area")                                         \
    X(CF_OBS_RESIDUAL, "energy_residual")                                      \
    X(CF_OBS_WORK_GRAVITY, "work_gravity")                                     \
    X(CF_OBS_WORK_BOUNDARY, "work_boundary")                                   \
    X(CF_OBS_WORK_OBSTACLES, "work_obstacles")                                 \
    X(CF_OBS_PX, "momentum_x")                                                 \
    X(CF_OBS_PY, "momentum_y")                                                 \
    X(CF_OBS_PZ, "momentum_z")                                                 \
    X(CF_OBS_LX, "angular_momentum_x")                                         \
    X(CF_OBS_LY, "angular_momentum_y")                                         \
    X(CF_OBS_LZ, "angular_momentum_z")

typedef enum {
#define CF_X_OBS_ENUM(id, name) id,
    CF_TRAJ_OBSERVABLES(CF_X_OBS_ENUM)
#undef CF_X_OBS_ENUM
    CF_OBS_COUNT
} cf_traj_observable;

typedef struct cf_trajectory {
    int T;              /* complete frames */
    int N;              /* fragment columns = fragment records */
    double *time;       /* [T] s */
    double *pos;        /* [T][N][3] centre of mass, m; NaN when not alive */
    int *parent;        /* [N] -1 for an initial body */
    double *mass;       /* [N] kg */
    double first[CF_OBS_COUNT], last[CF_OBS_COUNT]; /* NaN when not written */
} cf_trajectory;

/* Read `path`.  Errors: CF_ERR_FILE_OPEN (missing or not HDF5),
 * CF_ERR_MESH_FORMAT (a dataset missing or of the wrong shape: not a cohfrac
 * output), CF_ERR_NOMEM; the message names the file and the dataset.  On
 * error *t is empty. */
cf_status cf_trajectory_read(const char *path, cf_trajectory *t, cf_error *err);

void cf_trajectory_free(cf_trajectory *t);

#endif
