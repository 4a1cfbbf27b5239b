/* cohfrac — comparing the two rigid backends on one scene.
 *
 * cf_compare_run loads the scene twice, once with solver.rigid_backend =
 * "bullet" and once with "pbd" (solver.pbd.k_damping = 1, the source's
 * rigid mode), both without HDF5 output, advances them in lockstep and
 * samples both at t = 0 and every output.frame_interval s.  Fragments are
 * matched through their tets: the partner of a Bullet-run fragment is the
 * pbd-run fragment that holds most of its tets.
 *
 * Metrics per sample (units in brackets):
 *   com_dist     [m]   |COM_bullet - COM_pbd| of matched fragments, mass-weighted
 *                      mean over the Bullet run's fragments (by their mass)
 *   orient_diff  [rad] angle of q_bullet^-1 q_pbd, mass-weighted the same way
 *   per backend:
 *   ref_err      [m]   |COM of the whole body - analytic reference| (below)
 *   ke_drift     [-]   (E(t) - E(0)) / |E(0)|, E = sum over fragments of
 *                      kinetic - m g.x_com (absolute when E(0) = 0)
 *   p_drift      [-]   |P(t) - P(0) - M g t| / max(|P(0)|, M |g| T, 1e-300),
 *                      T the scene's duration
 *   l_drift      [-]   |L(t) - L(0)| / |L(0)|, L the sum over fragments of the
 *                      angular momentum about each fragment's COM (absolute,
 *                      kg m^2/s, when L(0) = 0)
 *
 * Analytic references, detected from the scene (first rule that applies):
 *   "free fall" / "projectile": one body, no obstacles, no boundary
 *       conditions: COM = x0 + v0 t + g t^2/2 with x0 the body's COM at t = 0
 *       and v0 = body.velocity (+ the expansion field at the COM); "free
 *       fall" when v0 = 0.
 *   "symmetric top" (in addition): the same, with a non-zero
 *       angular_velocity and two principal moments equal within 1e-3
 *       (relative) and the third distinct: the symmetry axis precesses about
 *       the constant angular momentum L at Omega_p = |L| / I_1 (Euler's
 *       equations, I_1 the repeated moment).  Each backend's rate is the
 *       least-squares slope of the unwrapped angle of the symmetry axis
 *       projected on the plane normal to L.
 *   "bounce": one body, one plane obstacle, solver.criterion = "none" (no
 *       fracture), zero angular velocity, gravity towards the plane and the
 *       body above it: a point at the COM at height h = support of the body
 *       along -n above the plane, in free flight, bouncing with restitution
 *       e = material.restitution x the obstacle's restitution factor
 *       (frictionless); compared up to the second contact.
 *
 * Files written into the output directory (each written to NAME.tmp, then
 * renamed, so a killed run never leaves a half-written file):
 *   compare.md      the report (Markdown)
 *   compare.csv     time series: one row per sample
 *   fragments.csv   the Bullet run's fragments at the end with their partners
 *   compare.png     2x2 plots by python/cohfrac/compare_plot.py (Debian python3 and
 *                   python3-matplotlib); a failure there is a warning only */
#ifndef COHFRAC_COMPARE_H
#define COHFRAC_COMPARE_H

#include <stdio.h>

#include "cohfrac/error.h"

enum { CF_CMP_BULLET = 0, CF_CMP_PBD = 1 };

/* Which analytic reference the scene has (see above). */
typedef enum {
    CF_CMP_REF_NONE,
    CF_CMP_REF_FREE_FALL,
    CF_CMP_REF_PROJECTILE,
    CF_CMP_REF_BOUNCE
} cf_compare_ref;

typedef struct cf_compare_options {
    const char *scene;               /* path of the scene script (required) */
    const char *const *overrides;    /* "key.path=value", applied before the
                                        backend overrides; may be NULL */
    int n_overrides;
    const char *out_dir;             /* NULL: build/compare/<scene name> */
    const char *mesh_dir;            /* NULL: build/meshes */
    int threads;                     /* OpenMP threads, 0: the scene's setting */
    int progress;                    /* 1: progress lines on stderr */
    int plot;                        /* 1: make compare.png */
    const char *plot_script;         /* NULL: python/cohfrac/compare_plot.py from the
                                        working directory, else next to the
                                        executable (../tools/) */
    FILE *headline;                  /* the report's headline goes here (NULL: nowhere) */
} cf_compare_options;

/* Summary figures.  Index [b] is the backend, CF_CMP_BULLET or CF_CMP_PBD.
 * "final" is the last sample, "max" the largest magnitude over the samples;
 * reference figures are NaN when the scene has no such reference. */
typedef struct cf_compare_result {
    char scene_name[128];
    char out_dir[1024];
    int n_samples;
    double duration;                 /* s, simulated */
    double wall[2];                  /* s, wall time of cf_sim_advance calls */
    double wall_split[2];            /* s, the same from the first step that split
                                        the scene's bodies on (0 if none split) */
    double t_split[2];               /* s, simulated time of that split (NaN: none) */
    int n_fragments[2];              /* alive at the end */
    double com_dist_final, com_dist_max;       /* m */
    double orient_final, orient_max;           /* rad */
    cf_compare_ref reference;
    double ref_err_final[2], ref_err_max[2];   /* m, COM vs the reference */
    double ref_until;                          /* s, end of the reference's validity */
    double ke_drift_final[2], ke_drift_max[2]; /* relative */
    double p_drift_final[2], p_drift_max[2];   /* relative */
    double l_drift_final[2], l_drift_max[2];   /* relative (or kg m^2/s) */
    int top;                                   /* 1: symmetric top detected */
    double omega_p;                            /* rad/s, analytic precession rate */
    double omega_measured[2];                  /* rad/s */
    double omega_rel_err[2];                   /* |measured - analytic| / analytic */
    int plot_made;                             /* 1: compare.png written */
} cf_compare_result;

/* Run the comparison and write the files.  `res` (may be NULL) receives
 * the figures.  Errors: those of cf_scene_load (2), cf_sim_create;
 * CF_ERR_DIVERGED when either run diverges (the files are still written
 * up to that time); CF_ERR_OUTPUT when the directory or a file cannot be
 * written; CF_ERR_NOMEM. */
cf_status cf_compare_run(const cf_compare_options *opt, cf_compare_result *res, cf_error *err);

#endif
