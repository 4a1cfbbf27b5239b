/* cohfrac — one settings schema: every number, integer, flag and choice of
 * a world's `material` and `solver` settings, written once.
 *
 * CF_SETTINGS below is the single list: the key path, where the value lives
 * in cf_world_def, its kind, default, allowed interval, SI unit and a line
 * of documentation.  From it come the defaults (cf_default_material,
 * cf_default_solver), the range checks of cf_world_def_check, the Lua scene
 * reader and the resolved scene it writes back (cohfrac/scene.h), and
 * docs/settings.md (tests/settings_doc.c prints it; ctest settings_doc
 * fails when the file differs).  The rules between settings (dt_fracture
 * <= dt_rigid) are cf_solver_check_rules, which both the reader and the
 * check call.  Bodies, obstacles, boundary conditions and output are lists of
 * records with their own keys (cohfrac/scene.h).
 */
#ifndef COHFRAC_SETTINGS_H
#define COHFRAC_SETTINGS_H

#include <math.h>
#include <stddef.h>

#include "cohfrac/error.h"
#include "cohfrac/types.h"

typedef enum {
    CF_SET_NUM,   /* a double */
    CF_SET_INT,   /* an int */
    CF_SET_BOOL,  /* an int, 0 or 1; true/false in a scene */
    CF_SET_ENUM,  /* an enum, one of `names` (its value is the index) */
    CF_SET_TABLE, /* a table of further settings, `<table>.<key>` */
    CF_SET_CUSTOM /* read and written by the scene reader itself (solver.crack_plane) */
} cf_setting_kind;

/* Allowed intervals: lo, hi, lo closed, hi closed, why (appended to the
 * scene reader's message, or NULL). */
#define CF_R_ANY -INFINITY, INFINITY, 1, 1, NULL
#define CF_R_POSITIVE 0.0, INFINITY, 0, 0, NULL
#define CF_R_NON_NEGATIVE 0.0, INFINITY, 1, 0, NULL
#define CF_R_AT_LEAST_ONE 1.0, INFINITY, 1, 0, NULL
#define CF_R_UNIT 0.0, 1.0, 1, 1, NULL
#define CF_R_ITERATIONS 1.0, CF_MAX_ITERATIONS, 1, 1, NULL
#define CF_R_PIECE_TETS 0.0, CF_MAX_PIECE_TETS, 1, 1, NULL
#define CF_R_FRICTION_ANGLE 0.0, 60.0, 1, 1, NULL
#define CF_R_KINK 0.0, 180.0, 0, 1, NULL
#define CF_R_POISSON -1.0, 0.5, 0, 0, "(Poisson's ratio of a stable isotropic solid)"
#define CF_R_PPR_SHAPE                                                                         \
    1.0, INFINITY, 0, 0, "(the PPR cohesive law needs shape parameters alpha, beta > 1)"
#define CF_R_NONE 0.0, 0.0, 1, 1, NULL /* tables, flags and choices */

/* X(table, key, kind, field of cf_world_def, default, default from (a key
 *   of the same table read before, or NULL), enum names (or NULL), range,
 *   unit, doc), in the order a scene is read and written. */
#define CF_SETTINGS(X)                                                                         \
    X("material", "E", NUM, material.E, 1e6, NULL, NULL, CF_R_POSITIVE, "Pa",                 \
      "Young's modulus")                                                                       \
    X("material", "nu", NUM, material.nu, 0.3, NULL, NULL, CF_R_POISSON, "",                  \
      "Poisson's ratio")                                                                       \
    X("material", "rho", NUM, material.rho, 2400, NULL, NULL, CF_R_POSITIVE, "kg/m^3",        \
      "density")                                                                               \
    X("material", "G_I", NUM, material.G_I, 22, NULL, NULL, CF_R_POSITIVE, "N/m",             \
      "mode I fracture energy (PPR phi_n)")                                                    \
    X("material", "sigma_max", NUM, material.sigma_max, 1e4, NULL, NULL, CF_R_POSITIVE, "Pa", \
      "cohesive (tensile) strength")                                                           \
    X("material", "alpha", NUM, material.alpha, 2, NULL, NULL, CF_R_PPR_SHAPE, "",            \
      "PPR shape parameter, mode I")                                                           \
    X("material", "G_II", NUM, material.G_II, 22, "G_I", NULL, CF_R_POSITIVE, "N/m",          \
      "mode II fracture energy (PPR phi_t); default G_I")                                      \
    X("material", "tau_max", NUM, material.tau_max, 1e4, "sigma_max", NULL, CF_R_POSITIVE,    \
      "Pa", "cohesive shear strength; default sigma_max")                                      \
    X("material", "beta", NUM, material.beta, 2, "alpha", NULL, CF_R_PPR_SHAPE, "",           \
      "PPR shape parameter, mode II; default alpha")                                           \
    X("material", "friction", NUM, material.friction, 0.5, NULL, NULL, CF_R_NON_NEGATIVE, "", \
      "Coulomb friction coefficient with obstacles")                                           \
    X("material", "restitution", NUM, material.restitution, 0, NULL, NULL, CF_R_UNIT, "",     \
      "restitution coefficient with obstacles")                                                \
    X("material", "crack_friction", NUM, material.crack_friction, 0, NULL, NULL,              \
      CF_R_NON_NEGATIVE, "",                                                                   \
      "Coulomb friction coefficient of a cohesive element's faces pressed together, bonded "  \
      "or failed (explicit runs, docs/physics.md 6); 0 none")                                  \
    X("material", "compressive_strength", NUM, material.compressive_strength, 0, NULL, NULL,  \
      CF_R_NON_NEGATIVE, "Pa",                                                                 \
      "crushing strength of the Tet4s in uniaxial compression (docs/physics.md 2.1); 0 none")  \
    X("material", "internal_friction_angle", NUM, material.internal_friction_angle, 0, NULL,  \
      NULL, CF_R_FRICTION_ANGLE, "degree",                                                     \
      "the crushing strength grows with pressure (Drucker-Prager); 0 von Mises")              \
    X("material", "strength", TABLE, material, 0, NULL, NULL, CF_R_NONE, "",                  \
      "the strength's scatter")                                                                \
    X("material.strength", "distribution", ENUM, material.weibull, 0, NULL, cf_names_strength,\
      CF_R_NONE, "", "uniform (every facet at sigma_max) or a Weibull strength field")        \
    X("material.strength", "modulus", NUM, material.weibull_modulus, 10, NULL, NULL,          \
      CF_R_POSITIVE, "", "Weibull modulus m")                                                  \
    X("material.strength", "seed", INT, material.strength_seed, 1, NULL, NULL, CF_R_ANY, "",  \
      "seed of the strength field")                                                            \
    X("material.strength", "area", NUM, material.strength_area, 0, NULL, NULL,                \
      CF_R_NON_NEGATIVE, "m^2",                                                                \
      "Weibull reference area A0, the field's correlation length squared; 0 l_ch^2")          \
    X("material", "nucleation_radius", NUM, material.nucleation_radius, 0, NULL, NULL,        \
      CF_R_NON_NEGATIVE, "m", "R_n: no crack nucleates within R_n / ratio^2 of a crack; 0 l_ch") \
    X("material", "crushing_strain", NUM, material.crushing_strain, 0, NULL, NULL,            \
      CF_R_NON_NEGATIVE, "", "plastic strain at which a crushing tet leaves as debris; 0 never") \
    X("material", "cohesive_law", ENUM, material.cohesive_law, 0, NULL, cf_cohesive_law_names,\
      CF_R_NONE, "", "the cohesive law, one per src/engine/cohesive_<law>.c (docs/physics.md 6)") \
    X("solver", "mode", ENUM, solver.mode, 0, NULL, cf_names_mode, CF_R_NONE, "",             \
      "hybrid: rigid mode with fracture mode on impact; fracture: fracture mode throughout")   \
    X("solver", "rigid_backend", ENUM, solver.rigid_backend, 0, NULL, cf_names_backend,       \
      CF_R_NONE, "", "Bullet, or the source's damped PBD rigid mode")                          \
    X("solver", "dt_rigid", NUM, solver.dt_rigid, 1e-3, NULL, NULL, CF_R_POSITIVE, "s",       \
      "the rigid step")                                                                        \
    X("solver", "rigid_substeps", INT, solver.rigid_substeps, 5, NULL, NULL, CF_R_ITERATIONS, \
      "", "Bullet sub-steps per rigid step")                                                   \
    X("solver", "ccd", BOOL, solver.ccd, 1, NULL, NULL, CF_R_NONE, "",                        \
      "Bullet continuous collision detection for rigid fragments")                            \
    X("solver", "sleeping", TABLE, solver, 0, NULL, NULL, CF_R_NONE, "",                      \
      "Bullet deactivation below both speeds for 2 s")                                         \
    X("solver.sleeping", "linear", NUM, solver.sleep_linear, 0, NULL, NULL, CF_R_NON_NEGATIVE,\
      "m/s", "linear speed; 0 with angular 0: no sleeping")                                   \
    X("solver.sleeping", "angular", NUM, solver.sleep_angular, 0, NULL, NULL,                 \
      CF_R_NON_NEGATIVE, "rad/s", "angular speed")                                             \
    X("solver", "dt_fracture", NUM, solver.dt_fracture, 5e-6, NULL, NULL, CF_R_POSITIVE, "s", \
      "the fracture step, at most dt_rigid")                                                   \
    X("solver", "cfl_fraction", NUM, solver.cfl_fraction, 0, NULL, NULL, CF_R_NON_NEGATIVE,   \
      "", "> 0: dt_fracture = cfl_fraction dt_cfl of the mesh instead")                        \
    X("solver", "check_interval", INT, solver.check_interval, 1, NULL, NULL,                  \
      CF_R_AT_LEAST_ONE, "", "fracture steps between insertion checks")                        \
    X("solver", "quiet_steps", INT, solver.quiet_steps, 400, NULL, NULL, CF_R_AT_LEAST_ONE,   \
      "", "quiet fracture steps before a fragment goes back to rigid mode")                   \
    X("solver", "quiet_growth", NUM, solver.quiet_growth, 0, NULL, NULL, CF_R_NON_NEGATIVE,   \
      "", "insertions still quiet, over its cohesive elements (0: none; docs/physics.md 9)")  \
    X("solver", "max_fracture_time", NUM, solver.max_fracture_time, 0.05, NULL, NULL,         \
      CF_R_POSITIVE, "s", "the longest a fragment stays in fracture mode")                     \
    X("solver", "impact_threshold", NUM, solver.impact_threshold, 0.2, NULL, NULL,            \
      CF_R_NON_NEGATIVE, "m/s",                                                                \
      "a rigid step's contact impulse over the mass that starts fracture mode, when new or "   \
      "stronger than one taken (docs/physics.md 9)")                                           \
    X("solver", "elasticity", ENUM, solver.elasticity, 0, NULL, cf_names_elasticity,         \
      CF_R_NONE, "", "corotational Tet4, or the source's small strain")                        \
    X("solver", "criterion", ENUM, solver.criterion, 0, NULL, cf_names_criterion, CF_R_NONE,  \
      "", "insertion criterion (docs/physics.md 5): facet traction, the source's, none")      \
    X("solver", "crack_growth", ENUM, solver.crack_growth, 0, NULL, cf_names_growth,          \
      CF_R_NONE, "", "fronts and nuclei (docs/physics.md 5.1), or every qualifying facet")    \
    X("solver", "front_direction", ENUM, solver.front_direction, 0, NULL, cf_names_front,     \
      CF_R_NONE, "",                                                                           \
      "fronts: onto any facet, or one whose normal stress reaches it (docs/physics.md 5.1)")  \
    X("solver", "front_threshold", ENUM, solver.front_threshold, 0, NULL, cf_names_front_threshold, \
      CF_R_NONE, "",                                                                           \
      "a front's threshold: the strength's, or at most the toughness's at the vertex ahead, "  \
      "or at most a penny crack's of the front's radius (docs/physics.md 5.1)")                \
    X("solver", "front_max_kink", NUM, solver.front_max_kink, 180, NULL, NULL, CF_R_KINK,      \
      "degree", "fronts: the most a front may turn from the crack facet it extends "          \
      "(docs/physics.md 5.1); 180 no limit")                                                   \
    X("solver", "front_split", ENUM, solver.front_split, 0, NULL, cf_names_front_split,       \
      CF_R_NONE, "",                                                                           \
      "fronts: split the vertices behind a new front facet along its plane, or none "         \
      "(docs/physics.md 5.1)")                                                                 \
    X("solver", "front_split_reach", NUM, solver.front_split_reach, 0, NULL, NULL,            \
      CF_R_NON_NEGATIVE, "m",                                                                  \
      "a split takes no facet farther from the vertex it parts (rest centroids, "             \
      "docs/physics.md 5.1); 0 no limit")                                                      \
    X("solver", "front_snap", ENUM, solver.front_snap, 0, NULL, cf_names_front_snap,          \
      CF_R_NONE, "",                                                                           \
      "fronts: move a new front facet's vertex ahead onto the plane across the largest "      \
      "principal stress, or none (docs/physics.md 5.1)")                                      \
    X("solver", "obstacle_contact", ENUM, solver.obstacle_contact, 0, NULL,                   \
      cf_names_obstacle_contact, CF_R_NONE, "",                                                \
      "explicit runs: project nodes onto obstacles, or a penalty force (docs/physics.md 7.1)") \
    X("solver", "mass_scaling", NUM, solver.mass_scaling, 0, NULL, NULL, CF_R_UNIT, "",       \
      "floor of a tet's stable step over the median's, by added mass; 0 none")                \
    X("solver", "bulk_viscosity", NUM, solver.bulk_viscosity, 0, NULL, NULL, CF_R_UNIT, "",   \
      "linear bulk viscosity b1 of fracture mode (docs/physics.md 2.3); 0 none")              \
    X("solver", "min_piece_tets", INT, solver.min_piece_tets, 4, NULL, NULL, CF_R_PIECE_TETS, \
      "", "no insertion closes a piece of at most this many tets; 0 no bound")                \
    X("solver", "min_piece_size", NUM, solver.min_piece_size, 0, NULL, NULL,                  \
      CF_R_NON_NEGATIVE, "m", "nor one whose equal-volume sphere is narrower; 0 no bound")    \
    X("solver", "debris_tets", INT, solver.debris_tets, 4, NULL, NULL, CF_R_PIECE_TETS, "",   \
      "a piece of at most this many tets is debris; 0 none")                                  \
    X("solver", "debris_size", NUM, solver.debris_size, 0, NULL, NULL, CF_R_NON_NEGATIVE, "m",\
      "a piece whose equal-volume sphere is narrower is debris; 0 none")                      \
    X("solver", "crack_plane", CUSTOM, solver, 0, NULL, NULL, CF_R_NONE, "",                  \
      "{point, normal, tolerance}: the only facets that may crack; none by default")          \
    X("solver", "constraints", ENUM, solver.constraints, 0, NULL, cf_names_constraints,       \
      CF_R_NONE, "", "the source's PBD bars, XPBD bars, or none (explicit)")                  \
    X("solver", "pbd", TABLE, solver, 0, NULL, NULL, CF_R_NONE, "", "PBD bars")              \
    X("solver.pbd", "k_stiffness", NUM, solver.k_stiffness, 0.9, NULL, NULL, CF_R_UNIT, "",   \
      "stiffness of a projection")                                                             \
    X("solver.pbd", "iterations", INT, solver.iterations, 3, NULL, NULL, CF_R_ITERATIONS, "", \
      "sweeps per step")                                                                       \
    X("solver.pbd", "k_damping", NUM, solver.k_damping, 1, NULL, NULL, CF_R_UNIT, "",         \
      "global damping of the pbd rigid mode")                                                  \
    X("solver.pbd", "iteration_independent", BOOL, solver.iteration_independent, 0, NULL,     \
      NULL, CF_R_NONE, "", "k' = 1 - (1 - k)^(1/iterations)")                                  \
    X("solver", "xpbd", TABLE, solver, 0, NULL, NULL, CF_R_NONE, "", "XPBD bars")            \
    X("solver.xpbd", "compliance_scale", NUM, solver.compliance_scale, 1, NULL, NULL,         \
      CF_R_POSITIVE, "", "bar compliance = scale L^2 / (E V_trib)")                            \
    X("solver", "contact_stiffness", NUM, solver.contact_stiffness, 0, NULL, NULL,            \
      CF_R_NON_NEGATIVE, "Pa/m", "crack-face penalty of explicit runs; 0 the stability cap")  \
    X("solver", "time_continuity", ENUM, solver.time_continuity, 0, NULL,                     \
      cf_names_time_continuity, CF_R_NONE, "",                                                 \
      "cohesive tractions that rise from zero with the capped stiffness: the tangential "     \
      "only, or the normal too (docs/physics.md 6)")                                           \
    X("solver", "guard", TABLE, solver, 0, NULL, NULL, CF_R_NONE, "", "the divergence guard")\
    X("solver.guard", "max_inverted_fraction", NUM, solver.max_inverted_fraction, 0.01, NULL, \
      NULL, CF_R_UNIT, "", "stop when more of a body's fracture-mode tets are inverted")      \
    X("solver.guard", "max_energy_growth", NUM, solver.max_energy_growth, 0.5, NULL, NULL,    \
      CF_R_POSITIVE, "", "stop when the energy exceeds input and work by this fraction")      \
    X("solver", "threads", INT, solver.threads, 0, NULL, NULL, CF_R_NON_NEGATIVE, "",         \
      "threads of the element loops; 0 all cores")

/* The spellings of material.cohesive_law: the laws the engine was built
 * with, PPR first, NULL after the last. */
extern const char *const cf_cohesive_law_names[];

/* One entry of CF_SETTINGS. */
typedef struct cf_setting {
    const char *table;          /* "material", "solver.pbd", ... */
    const char *key;            /* the key in it */
    cf_setting_kind kind;
    size_t offset;              /* of the value in cf_world_def (NUM a double, else an int) */
    double def;                 /* default (ENUM: the value; BOOL 0 or 1) */
    const char *def_from;       /* NULL, or the key whose value is the default */
    const char *const *names;   /* ENUM: the spellings by value, NULL after the last */
    double lo, hi;              /* NUM, INT: the allowed interval */
    int lo_closed, hi_closed;
    const char *why;            /* appended to a range message, or NULL */
    const char *unit;           /* SI unit, "" for none */
    const char *doc;
} cf_setting;

/* The schema, in order; *n receives its length. */
const cf_setting *cf_settings(int *n);

/* The entry of key `key` in table `table` ("solver.pbd"), or NULL. */
const cf_setting *cf_setting_find(const char *table, const char *key);

/* The value of setting e in d, as a double (NUM, INT, BOOL, ENUM), and
 * setting it. */
double cf_setting_get(const cf_setting *e, const cf_world_def *d);
void cf_setting_set(const cf_setting *e, cf_world_def *d, double v);

/* The rules between settings: solver.sleeping's two speeds both > 0 or
 * both 0, dt_fracture <= dt_rigid, and at most CF_MAX_SUBSTEPS fracture
 * steps in a rigid step.  Errors: CF_ERR_SCENE_VALUE naming the key. */
cf_status cf_solver_check_rules(const cf_solver_settings *s, cf_error *err);

#endif
