/* cohfrac — numerical stability map of the fracture-mode solver.
 *
 * Every case is a cube of side 0.1 m (rho 2400 kg/m^3, nu 0.25, friction 0.5,
 * restitution 0; 3 x 3 x 3 cells of 6 tets, 162 Tet4, or the same grid with
 * its interior nodes moved at random by up to 45% of a cell, which makes
 * slivers) that starts touching a rigid plane and moves into it at the
 * impact speed, in fracture mode only (solver.mode = "fracture"), without
 * gravity and without cohesive insertion (criterion "none"), so that
 * nothing but the initial kinetic energy goes in.  It runs for
 * CF_STABILITY_STEPS steps of dt = (dt/dt_cfl) x dt_cfl, checked after
 * every step.
 *
 * A case is unstable at the first step where one of these holds:
 *   "nan"       a node position is not finite or a node is faster than
 *               1e5 m/s (the engine's guard);
 *   "energy"    kinetic + strain energy exceeds 1.1 times the initial
 *               kinetic energy (solver.guard.max_energy_growth = 0.1; there
 *               is no work input);
 *   "inverted"  more than 1% of the tets are inverted (det F <= 0;
 *               solver.guard.max_inverted_fraction = 0.01);
 *   "escaped"   the centre of mass leaves the scene box: farther than
 *               2 v T + 0.2 m from its start, or more than 0.1 m below the
 *               plane (T the case's simulated time, v its impact speed).
 * Otherwise it is stable.
 *
 * The mass-ratio cases are two bodies instead: the cube at rest (no plane)
 * hit on its top face by a cube of the same material and mesh whose side is
 * 0.1 (m_impactor/m_target)^(1/3) m, moving at the impact speed; both are
 * in fracture mode and meet through the contact between bodies
 * (contact.h); "escaped" then follows the centre of mass of both.
 *
 * Axes of the full map (cf_stability_run with quick = 0): E in {0.6 Pa (the
 * source's), 1 kPa, 1 MPa, 1 GPa, 70 GPa (glass), 200 GPa (steel)} x
 * dt/dt_cfl in {0.5, 1, 2, 10, 100, 1000} x constraints {none, pbd
 * (k 0.9, 3 iterations: the source's), pbd (k 1, 10 iterations), xpbd} at
 * 10 m/s on the regular mesh; then m_impactor/m_target in {0.01, 0.1, 1,
 * 10, 100} x dt/dt_cfl x constraints at 70 GPa, 10 m/s; then impact speed
 * {1, 10, 100} m/s x dt/dt_cfl x constraints at 70 GPa; then the sliver
 * mesh x dt/dt_cfl x constraints at 70 GPa, 10 m/s.  quick = 1 runs the
 * corners: E {0.6 Pa, 70 GPa} x dt/dt_cfl {0.5, 10, 100} x the four
 * constraint modes at 10 m/s, and mass ratio {0.01, 100} x dt/dt_cfl {0.5,
 * 10, 100} x the four modes at 70 GPa.
 *
 * Files written into the output directory (whole or not at all):
 *   stability.md   date, machine and command; the criteria and one table
 *                  per slice
 *   stability.csv  one row per case
 *   stability.png  heatmaps by python/cohfrac/stability_plot.py (Debian python3 and
 *                  python3-matplotlib); a failure there is a warning only */
#ifndef COHFRAC_STABILITY_H
#define COHFRAC_STABILITY_H

#include "cohfrac/error.h"

#define CF_STABILITY_STEPS 600

typedef enum {
    CF_STAB_NONE,     /* explicit elasticity, no constraints */
    CF_STAB_PBD_SRC,  /* PBD bars, k 0.9, 3 iterations (the source's) */
    CF_STAB_PBD_STIFF,/* PBD bars, k 1, 10 iterations */
    CF_STAB_XPBD,     /* XPBD bars, compliance from E */
    CF_STAB_N_MODES
} cf_stability_mode;

/* Name of a mode as in the files: "none", "pbd_k0.9_it3", "pbd_k1_it10",
 * "xpbd". */
const char *cf_stability_mode_name(cf_stability_mode m);

typedef struct cf_stability_case {
    const char *slice;      /* "E x dt", "mass x dt", "speed x dt", "mesh x dt" */
    double E;               /* Pa */
    double dt_ratio;        /* dt / dt_cfl */
    double speed;           /* m/s */
    int sliver;             /* 1: the perturbed mesh */
    double mass_ratio;      /* m_impactor / m_target of the two-cube case, 0:
                               the cube against the plane */
    cf_stability_mode mode;
    /* results */
    int stable;
    const char *reason;     /* "", "nan", "energy", "inverted", "escaped",
                               or "error" (the engine failed otherwise) */
    long fail_step;         /* first failing step (1-based), 0 when stable */
    double energy_ratio;    /* largest (kinetic + strain) / initial kinetic */
    double dt;              /* s */
    double wall;            /* s */
} cf_stability_case;

typedef struct cf_stability_options {
    int quick;
    const char *out_dir;    /* NULL: build/stability */
    const char *plot_script;/* NULL: python/cohfrac/stability_plot.py (see report.h) */
    int progress;           /* 1: a line per case on stderr */
    int plot;               /* 1: make stability.png */
    const char *command;    /* the command line, quoted in stability.md (may be NULL) */
} cf_stability_options;

typedef struct cf_stability_result {
    cf_stability_case *cases; /* [n], owned; free with cf_stability_free */
    int n;
    char out_dir[1024];
    int plot_made;
} cf_stability_result;

/* Run the matrix and write the files.  Errors: CF_ERR_OUTPUT (the output
 * directory or a file), CF_ERR_NOMEM, CF_ERR_SCENE_* / CF_ERR_MESH_* (the
 * generated scene or mesh; a defect), CF_ERR_EXTERNAL.  An unstable case is
 * a result, not an error. */
cf_status cf_stability_run(const cf_stability_options *opt, cf_stability_result *res,
                           cf_error *err);
void cf_stability_free(cf_stability_result *res);

#endif
