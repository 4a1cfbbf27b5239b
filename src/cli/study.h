/* cohfrac — error against run time: one scene over a grid of settings,
 * measured against a reference run of the same scene.
 *
 * cf_study_run loads the scene once per case (the --set overrides, then the
 * case's own), so a bad key or value is reported before anything runs.
 * The cases are the reference and every combination of the --vary values
 * (without --vary: the reference and the scene as written).
 * Each runs as a separate `cohfrac run` process on the resolved scene
 * (`jobs` at a time), writing its HDF5 output under OUT/runs/<hash>.h5,
 * where <hash> is the FNV-1a hash of the resolved scene text (output file
 * blanked) and the program's version.  A case whose OUT/runs/<hash>.meta
 * exists and whose resolved scene is unchanged is not run again (cached).
 *
 * Reference (default): the same scene with the explicit CZM solver and no
 * PBD, at half the explicit stability limit: solver.constraints = "none",
 * solver.cfl_fraction = 0.5 (dt = 0.5 dt_cfl).  `reference` replaces these
 * two with the given "key=value" overrides.
 *
 * Metrics of a case against the reference (units in brackets):
 *   traj_rms   [m]  mass-weighted RMS distance between the case's fragments'
 *                   centres of mass and their partners' in the reference,
 *                   over the frames both runs reached:
 *                     e(t)^2 = sum_f m_f |x_f(t) - y_f(t)|^2 / sum_f m_f,
 *                     traj_rms = sqrt(mean over frames of e(t)^2).
 *                   Fragments are matched through the family tree and mass:
 *                   initial bodies in order; the children of two matched
 *                   fragments are paired largest with largest; y_f(t) is
 *                   the centre of mass of the reference fragments alive at
 *                   t that descend from the partner of f's nearest matched
 *                   ancestor-or-self (or of that partner's nearest alive
 *                   ancestor, before it is born).  Frames are paired by
 *                   nearest time.
 *   traj_rel   [-]  traj_rms / D, D = RMS over the frames of the distance
 *                   the initial bodies' centres of mass travel in the
 *                   reference (mass-weighted over bodies).  The "within
 *                   tolerance" verdict uses traj_rel.
 *   n_fragments     alive at the last frame
 *   mass_ks    [-]  Kolmogorov-Smirnov distance between the final fragment
 *                   mass distributions (fraction of the mass in fragments of
 *                   mass <= m), 0 same, 1 disjoint
 *   crack_area [m^2], dissipated [J]: the last sample of the observables
 *                   crack_area (facets whose cohesive element failed
 *                   completely; fragments that part at insertion and return
 *                   to rigid mode before their cohesive elements fail leave
 *                   it at 0) and energy_cohesive_dissipated
 *   p_err, l_err [-] |P - P_ref| / |P_ref| at the last frame, and the same
 *                   for the angular momentum L about the origin, divided by
 *                   max(|L_ref|, |P_ref| D) (L_ref vanishes for motion
 *                   along a line through the origin)
 *   residual_rel [-] |energy-ledger residual| / (initial energy + work input)
 *                   at the last frame
 *   wall [s], cpu [s], peak_rss [bytes]: of the case's process (elapsed time,
 *                   user + system time and maximum resident set size from
 *                   wait4); runs that share the cores (jobs > 1) slow each
 *                   other: time with jobs = 1 for clean figures
 *   speedup    [-]  wall of the reference / wall of the case
 *
 * The Pareto front: the finished cases (exit status 0) that no other
 * finished case beats in both wall time and traj_rel.  `best` is the
 * cheapest (least wall time) finished case with traj_rel <= tolerance.
 *
 * Files written into the output directory (each whole or not at all):
 *   study.md    the report: command, machine, date, reference, table,
 *               Pareto front and the verdict
 *   study.csv   one row per case, the columns above
 *   study.png   traj_rel against wall time, log-log, Pareto front marked,
 *               by python/cohfrac/study_plot.py (Debian python3 + matplotlib); a
 *               failure there is a warning only
 *   runs/<hash>.{lua,h5,xdmf,log,meta}: each case's resolved scene, output,
 *               summary and process figures */
#ifndef COHFRAC_STUDY_H
#define COHFRAC_STUDY_H

#include "cohfrac/error.h"

typedef struct cf_study_options {
    const char *scene;                 /* path of the scene script (required) */
    const char *const *overrides;      /* "key.path=value" for every case; may be NULL */
    int n_overrides;
    const char *const *vary;           /* "key.path=v1,v2,..." (Lua values, commas
                                          inside {} or quotes do not split) */
    int n_vary;
    const char *const *reference;      /* "key.path=value"; NULL: the default above */
    int n_reference;
    const char *out_dir;               /* NULL: build/studies/<scene name> */
    const char *mesh_dir;              /* NULL: build/meshes */
    const char *exe;                   /* the cohfrac program that runs the cases;
                                          NULL: this process's own executable */
    const char *command;               /* the command line, quoted in study.md (may be NULL) */
    int jobs;                          /* processes at a time (0: 1) */
    int threads;                       /* threads per case (0: cores / jobs, at least 1) */
    double tolerance;                  /* traj_rel bound of the verdict (0: 0.05) */
    int progress;                      /* 1: a line per finished case on stderr */
    int plot;                          /* 1: make study.png */
    const char *plot_script;           /* NULL: python/cohfrac/study_plot.py (see report.h) */
} cf_study_options;

typedef struct cf_study_case {
    char label[512];           /* "reference" or the varied "key=value" pairs */
    char hash[17];             /* hex, names the files under runs/ */
    int exit_code;             /* of `cohfrac run`: 0 ok, 3 diverged, ... */
    int cached;                /* 1: reused from an earlier study */
    double t_end;              /* s, simulated time of the last frame */
    double wall, cpu;          /* s */
    double peak_rss;           /* bytes */
    int n_fragments;
    double traj_rms, traj_rel; /* m, -; NaN when not measurable */
    double mass_ks;            /* - */
    double crack_area;         /* m^2 */
    double dissipated;         /* J */
    double p_err, l_err;       /* - */
    double residual_rel;       /* - */
    double speedup;            /* - */
    int pareto;                /* 1: on the Pareto front */
} cf_study_case;

typedef struct cf_study_result {
    char scene_name[128];
    char out_dir[1024];
    int n_cases;
    cf_study_case *cases;      /* [n_cases]; cases[0] is the reference */
    int n_cached;
    double travel;             /* m, D above */
    int best;                  /* case index, -1 when none is within tolerance */
    int plot_made;             /* 1: study.png written */
} cf_study_result;

/* Run the study and write the files.  Errors: CF_ERR_USAGE (a --vary or
 * --reference item without '=' or with an empty value list); those of
 * cf_scene_load for any case (the message names the case's overrides);
 * CF_ERR_EXTERNAL (a case's process could not start, or the reference did
 * not write a readable output: see runs/<hash>.log); CF_ERR_OUTPUT;
 * CF_ERR_NOMEM.  A case that diverges is a result (its exit code is in the
 * table, its metrics cover the frames it reached), not an error.  Free
 * `res` with cf_study_free, also after an error. */
cf_status cf_study_run(const cf_study_options *opt, cf_study_result *res, cf_error *err);
void cf_study_free(cf_study_result *res);

/* The metrics of one output file against a reference output (both written
 * by `cohfrac run`): fills c's t_end, n_fragments, traj_rms, traj_rel,
 * mass_ks, crack_area, dissipated, p_err, l_err and residual_rel, and the
 * reference's travel D (m) into *travel (may be NULL).  Errors: those of
 * reading either file (CF_ERR_FILE_OPEN, CF_ERR_MESH_FORMAT: the message
 * names the file), CF_ERR_NOMEM. */
cf_status cf_study_measure(const char *case_h5, const char *reference_h5, cf_study_case *c,
                           double *travel, cf_error *err);

#endif
