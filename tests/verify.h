/* Shared pieces of the verification cases (tests/verify_*.c): load a scene
 * of scenes/verification/ with overrides, and report a figure next to its
 * reference.  Figures are printed and appended, one JSON object per line, to
 * <build>/verification/<case>.json, from which tools/physics_doc.py
 * refreshes docs/physics.md. */
#ifndef COHFRAC_TEST_VERIFY_H
#define COHFRAC_TEST_VERIFY_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "cohfrac/scene.h"
#include "cohfrac/sim.h"

/* Load scenes/verification/<file> with `sets` overrides (NULL-terminated)
 * and build the simulation; output goes to <build>/verification/. */
static cf_sim *verify_open(const char *file, const char *const *sets, cf_scene *sc)
{
    char path[1024], out[1200];
    const char *all[32];
    int n = 0;
    snprintf(path, sizeof path, "%s/scenes/verification/%s", COHFRAC_SOURCE_DIR, file);
    mkdir(COHFRAC_BINARY_DIR "/verification", 0777);
    snprintf(out, sizeof out, "output.file=\"%s/verification/%.*s.h5\"", COHFRAC_BINARY_DIR,
             (int)(strlen(file) - 4), file);
    all[n++] = out;
    for (int i = 0; sets && sets[i] && n < 32; i++)
        all[n++] = sets[i];
    cf_error err;
    if (cf_scene_load(path, all, n, COHFRAC_MESH_DIR, sc, &err) != CF_OK)
        fail_msg("%s", err.msg);
    cf_run_options opt = {.progress = 0, .mesh_dir = COHFRAC_MESH_DIR};
    cf_sim *sim = NULL;
    if (cf_sim_create(sc, &opt, &sim, &err) != CF_OK)
        fail_msg("%s", err.msg);
    return sim;
}

/* Step sim to its end; returns the largest |residual| / input over its
 * rigid steps (input: initial energy + the positive work of gravity,
 * prescribed nodes and moving obstacles), and the last ledger in *last.
 * A step that fails fails the test. */
static inline double verify_worst_residual(cf_sim *sim, cf_ledger *last)
{
    cf_error err;
    double worst = 0;
    while (!cf_sim_done(sim)) {
        if (cf_sim_advance(sim, &err) != CF_OK)
            fail_msg("%s", err.msg);
        cf_world_ledger(cf_sim_world(sim), last);
        double in = last->initial + fmax(0.0, last->work_gravity) +
                    fmax(0.0, last->work_boundary) + fmax(0.0, last->work_obstacles);
        if (in > 0)
            worst = fmax(worst, fabs(last->residual) / in);
    }
    return worst;
}

/* Report `quantity` of case `name`: measured against reference with a
 * relative (or, when reference is 0, absolute) tolerance; returns whether
 * it holds.  tolerance <= 0: reported only, never fails. */
static int verify_figure(const char *name, const char *quantity, double measured,
                         double reference, double tolerance, const char *unit)
{
    double dev = reference != 0 ? fabs(measured - reference) / fabs(reference)
                                : fabs(measured);
    int ok = tolerance <= 0 || dev <= tolerance;
    printf("FIGURE %-22s %-42s measured %-12.6g reference %-12.6g %s  deviation %.3g "
           "(tolerance %s%.3g) %s\n",
           name, quantity, measured, reference, unit, dev, tolerance > 0 ? "" : "none ",
           tolerance > 0 ? tolerance : 0, ok ? "PASS" : "FAIL");
    char path[1024];
    snprintf(path, sizeof path, "%s/verification/%s.json", COHFRAC_BINARY_DIR, name);
    FILE *f = fopen(path, "a");
    if (f) {
        fprintf(f,
                "{\"case\": \"%s\", \"quantity\": \"%s\", \"measured\": %.9g, \"reference\": "
                "%.9g, \"unit\": \"%s\", \"deviation\": %.6g, \"tolerance\": %.6g, \"pass\": %s}\n",
                name, quantity, measured, reference, unit, dev, tolerance, ok ? "true" : "false");
        fclose(f);
    }
    return ok;
}

/* Start a case: forget the figures of an earlier run. */
static void verify_begin(const char *name)
{
    char path[1024];
    mkdir(COHFRAC_BINARY_DIR "/verification", 0777);
    snprintf(path, sizeof path, "%s/verification/%s.json", COHFRAC_BINARY_DIR, name);
    remove(path);
}

#endif
