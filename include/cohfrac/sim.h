/* cohfrac — running a scene.
 *
 * cf_sim_create builds everything the scene asks for (and nothing else: no
 * Bullet world for the `pbd` rigid backend, no output file when the scene's
 * output file is empty); cf_sim_run advances it to the scene's duration,
 * writing frames to the HDF5 file; cf_sim_print_summary prints the closing
 * summary (wall time, time per stage, steps per mode, fragments, cohesive
 * elements, hand-off momentum error and loss). */
#ifndef COHFRAC_SIM_H
#define COHFRAC_SIM_H

#include <stdio.h>

#include "cohfrac/error.h"
#include "cohfrac/scene.h"

typedef struct cf_sim cf_sim;

typedef struct cf_run_options {
    int progress;      /* 1: progress display on stderr (bar on a TTY, lines otherwise) */
    int threads;       /* OpenMP threads for element loops; 0: scene's setting */
} cf_run_options;

/* Errors: those of cf_mesh_load_tetgen for each body, CF_ERR_OUTPUT,
 * CF_ERR_EXTERNAL (Bullet world), CF_ERR_NOMEM. */
cf_status cf_sim_create(const cf_scene *scene, const cf_run_options *opt, cf_sim **out,
                        cf_error *err);

/* Errors: CF_ERR_DIVERGED (NaN positions; the file is closed and readable),
 * CF_ERR_OUTPUT, CF_ERR_NOMEM. */
cf_status cf_sim_run(cf_sim *sim, cf_error *err);

void cf_sim_print_summary(const cf_sim *sim, FILE *out);
void cf_sim_destroy(cf_sim *sim);

#endif
