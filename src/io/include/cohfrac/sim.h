/* cohfrac — running a world: the loop that turns a scene (cohfrac/scene.h:
 * a world definition, a duration and an output) into an HDF5 file, a
 * progress display and a summary.
 *
 * cf_sim_create makes the meshes the definition names (mesh preparation,
 * cohfrac/surface.h), creates the engine's world (cohfrac/world.h) and
 * opens the output file (cohfrac/h5_output.h; none when output.file is "");
 * cf_sim_advance steps the world once, drains its events into HDF5 rows
 * and progress lines, and writes a frame when one is due; cf_sim_run does
 * that to the duration and closes the file; cf_sim_print_summary prints the
 * closing summary (wall time, time per stage, steps per mode, fragments,
 * cohesive elements, hand-off momentum error and loss, memory per
 * subsystem). */
#ifndef COHFRAC_SIM_H
#define COHFRAC_SIM_H

#include <signal.h>
#include <stdio.h>

#include "cohfrac/error.h"
#include "cohfrac/scene.h"
#include "cohfrac/types.h"
#include "cohfrac/world.h"

typedef struct cf_sim cf_sim;

typedef struct cf_run_options {
    int progress;         /* 1: progress display on stderr (a bar on a TTY with events
                             printed above it, lines otherwise) */
    int threads;          /* OpenMP threads for element loops; 0: the definition's setting */
    const char *mesh_dir; /* where primitives are meshed and cached (NULL:
                             cf_default_mesh_dir) */
    int force;            /* 1: overwrite an existing output file that is not a cohfrac
                             output (otherwise CF_ERR_OUTPUT: nothing the user did not
                             ask to lose is overwritten) */
    const volatile sig_atomic_t *stop; /* when set and *stop becomes nonzero (a signal handler),
                             cf_sim_run finishes the step, writes a last frame,
                             closes the file and returns CF_ERR_INTERRUPTED */
} cf_run_options;

/* Errors: those of cf_scene_check (before anything is written),
 * cf_world_meshes_load, cf_world_create, and CF_ERR_OUTPUT (cf_h5_open; or
 * the output file exists and is not a cohfrac output, and opt->force is
 * 0).  `sc` is read during the call only. */
cf_status cf_sim_create(const cf_scene *sc, const cf_run_options *opt, cf_sim **out,
                        cf_error *err);

/* The same from a scene script held in memory (cf_scene_load_text: `name`
 * stands for the file in messages, `overrides` are "key.path=value"
 * strings): what a binding that builds scenes from its own data calls
 * (python/cohfrac).  Prepared meshes are looked up in opt->mesh_dir.
 * Errors: those of cf_scene_load_text and cf_sim_create. */
cf_status cf_sim_create_text(const char *name, const char *text, const char *const *overrides,
                             int n_overrides, const cf_run_options *opt, cf_sim **out,
                             cf_error *err);

/* One rigid step of the world (cf_world_step), its events written and
 * shown, a frame when due.  Errors: those of cf_world_step (the output file
 * then holds every frame written so far), CF_ERR_OUTPUT, CF_ERR_NOMEM. */
cf_status cf_sim_advance(cf_sim *sim, cf_error *err);
int cf_sim_done(const cf_sim *sim);

/* Advance to the duration, then close the output file (also on error: what
 * was written stays readable).  CF_ERR_INTERRUPTED when opt->stop was set. */
cf_status cf_sim_run(cf_sim *sim, cf_error *err);

/* The world being run: for every query of cohfrac/world.h. */
cf_world *cf_sim_world(const cf_sim *sim);

/* The world's memory plus the output file's (cf_memory.output). */
void cf_sim_memory(const cf_sim *sim, cf_memory *m);

void cf_sim_print_summary(const cf_sim *sim, FILE *out);
void cf_sim_destroy(cf_sim *sim);

#endif
