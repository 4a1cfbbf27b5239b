/* cohfrac — running a scene.
 *
 * cf_sim_create builds everything the scene asks for (and nothing else: no
 * Bullet world for the `pbd` rigid backend, no output file when the scene's
 * output file is empty); cf_sim_run advances it to the scene's duration,
 * writing frames to the HDF5 file; cf_sim_print_summary prints the closing
 * summary (wall time, time per stage, steps per mode, fragments, cohesive
 * elements, hand-off momentum error and loss, memory per subsystem). */
#ifndef COHFRAC_SIM_H
#define COHFRAC_SIM_H

#include <stdint.h>
#include <stdio.h>

#include "cohfrac/error.h"
#include "cohfrac/scene.h"

typedef struct cf_sim cf_sim;

typedef struct cf_run_options {
    int progress;      /* 1: progress display on stderr (bar on a TTY, lines otherwise) */
    int threads;       /* OpenMP threads for element loops; 0: scene's setting */
    const char *mesh_dir; /* where primitives are meshed and cached (NULL: "build/meshes") */
} cf_run_options;

/* The energy ledger (J) and momenta of the whole scene at the current
 * state.  Balance: residual = kinetic + strain + cohesive_stored +
 * cohesive_dissipated + contact + pbd + damping + handoff + integration
 * - (initial + work_gravity + work_boundary + work_obstacles); zero for an
 * exact integrator.  work_obstacles is the work of moving obstacles: the
 * impulse they give a node times their velocity, and for Bullet bodies the
 * energy gained in a rigid step in contact when the scene has moving ones.
 * Kinetic energy of the in-house solver is the leapfrog estimate
 * 1/2 sum m v(n-1/2).v(n+1/2) at the last force evaluation; Bullet bodies'
 * is 1/2 M v^2 + 1/2 w.I w.  `contact`, `pbd`, `damping`, `handoff` are
 * energies removed since t = 0 (see DESIGN §3-§6 and docs/physics.md);
 * `integration` is what Bullet's integrator changed in bodies that touched
 * nothing during a rigid step (its implicit gyroscopic term: a free
 * spinning asymmetric body loses a little), never booked as contact. */
typedef struct cf_ledger {
    double kinetic, strain, cohesive_stored, cohesive_dissipated;
    double work_gravity, work_boundary, work_obstacles;
    double contact, pbd, damping, handoff, integration;
    double initial;            /* kinetic + strain at t = 0 */
    double residual;
    double momentum[3];        /* kg m/s */
    double angular_momentum[3];/* kg m^2/s, about the origin */
    double mass_moment[3];     /* kg m, sum m x (gravity's work is g . its change) */
} cf_ledger;

/* Errors: those of cf_mesh_load_tetgen for each body, CF_ERR_OUTPUT,
 * CF_ERR_EXTERNAL (Bullet world), CF_ERR_NOMEM. */
cf_status cf_sim_create(const cf_scene *scene, const cf_run_options *opt, cf_sim **out,
                        cf_error *err);

/* Advance to the scene's duration.  Errors: CF_ERR_DIVERGED (a
 * non-finite or faster than 1e5 m/s node, more inverted tets than
 * solver.guard.max_inverted_fraction, or kinetic + strain + cohesive energy
 * above (1 + solver.guard.max_energy_growth) times the initial energy plus
 * all work input; the message names dt/dt_cfl and what to change; the output
 * file is closed and readable), CF_ERR_OUTPUT, CF_ERR_NOMEM. */
cf_status cf_sim_run(cf_sim *sim, cf_error *err);

/* One rigid step (dt_rigid, sub-cycled in fracture mode), with hand-offs,
 * the divergence guard, and a frame when one is due.  Returns CF_OK; the
 * errors of cf_sim_run.  cf_sim_done tells when the duration is reached. */
cf_status cf_sim_advance(cf_sim *sim, cf_error *err);
int cf_sim_done(const cf_sim *sim);

/* Simulated time, s. */
double cf_sim_time(const cf_sim *sim);

/* The fracture-mode step (solver.dt_fracture, or cfl_fraction x dt_cfl)
 * and the mesh's explicit stability limit dt_cfl (DESIGN §3.2), s. */
double cf_sim_dt_fracture(const cf_sim *sim);
double cf_sim_dt_cfl(const cf_sim *sim);

/* The energy ledger and momenta now. */
void cf_sim_ledger(const cf_sim *sim, cf_ledger *out);

/* One alive fragment's rigid state now (pose as DESIGN §2).  `kinetic` is
 * the kinetic energy of its nodes (fracture mode, pbd rigid backend) or of
 * its Bullet body; momenta are those of the same. */
typedef struct cf_fragment_state {
    int id;                     /* fragment index, as in /fragments */
    int parent;                 /* -1 for an initial body */
    double birth_time;          /* s */
    int mode;                   /* 0 rigid, 1 fracture */
    int n_tets;
    double mass;                /* kg */
    double com[3];              /* m */
    double quat[4];             /* w,x,y,z: rest shape -> current */
    double v[3];                /* m/s, centre of mass */
    double w[3];                /* rad/s, world frame */
    double kinetic;             /* J */
    double momentum[3];         /* kg m/s */
    double angular_momentum[3]; /* kg m^2/s, about the fragment's centre of mass */
    double principal[3];        /* kg m^2 */
    double axes[9];             /* principal axes in the rest frame, columns */
} cf_fragment_state;

/* The alive fragments now, in id order: writes up to `cap` to out (may be
 * NULL with cap 0) and returns how many are alive. */
int cf_sim_fragments(cf_sim *sim, cf_fragment_state *out, int cap);

/* Number of tets of the scene's solid, and the fragment (id) that tet t
 * belongs to now: fragments of two runs of one scene are matched through
 * their tets.  -1 for t out of range. */
int cf_sim_tet_count(const cf_sim *sim);
int cf_sim_tet_fragment(const cf_sim *sim, int t);

/* Support distance of fragment `id` along unit direction d now: the largest
 * (R (X - X_cm)).d over its nodes, m, with X the rest positions and R the
 * fragment's rigid pose (deformation is not seen); 0 for a dead or unknown
 * fragment. */
double cf_sim_fragment_support(cf_sim *sim, int id, const double d[3]);

/* FNV-1a hash of the state's bits: every node's position and velocity,
 * each tet's fragment, each fragment's mode and its Bullet body's state.
 * Two runs of one scene give the same hash at the same step, for any thread
 * count (the element loops write per-element results and sum them in a
 * fixed order). */
uint64_t cf_sim_state_hash(const cf_sim *sim);

/* Memory each subsystem of the run holds now, bytes; 0 for one the scene
 * does not use (nothing of it is allocated). */
typedef struct cf_memory {
    unsigned long long solid;     /* Tet4 nodes and elements: positions, velocities,
                                     lumped masses, rest shapes, stresses, node-to-tet map */
    unsigned long long fracture;  /* facets, crack flags, crack-plane candidates: only
                                     when solver.criterion is not "none" */
    unsigned long long cohesive;  /* the cohesive elements' array (its capacity) */
    unsigned long long fragments; /* fragment records, their tet and node lists, PBD bars,
                                     convex hulls, contact scratch */
    unsigned long long bullet;    /* held by Bullet's allocator beyond what it held when
                                     this run was created (world, bodies, shapes); counted
                                     for the process, so exact with one run at a time */
    unsigned long long collision; /* FCL hierarchies of mesh obstacles and of
                                     fragment surfaces (contact between bodies) */
    unsigned long long output;    /* HDF5 metadata cache of the output file, the
                                     largest seen at a frame (the file is closed at
                                     the end of cf_sim_run) */
} cf_memory;

void cf_sim_memory(const cf_sim *sim, cf_memory *m);

/* The fracture-mode step so far, for benchmarks: steps taken, wall time
 * per stage (s, as in the run summary), and the sizes of what the step
 * works on now (fracture-mode fragments only). */
typedef struct cf_step_stats {
    long fracture_steps;
    double stress, insertion, forces, pbd; /* s of wall time since creation */
    int tets, nodes, bars, cohesive;       /* in fracture mode now */
    int iterations;                        /* constraint iterations per step */
    int check;                             /* 1: the insertion criterion is checked */
    int xpbd;                              /* 1: XPBD bars (compliance, multipliers) */
} cf_step_stats;

void cf_sim_step_stats(const cf_sim *sim, cf_step_stats *out);

/* The traffic model (docs/performance.md): the bytes one fracture-mode
 * step must move between memory and the cores at the least, each array
 * the step needs read or written once per pass that needs it, from the
 * sizes in `st`:
 *   per tet:  node indices 16 + inverse rest shape 72 + volume 8 + rotation
 *             warm start read and written 64 + strain energy 8 = 168 B;
 *             plus, when the criterion is checked, the stress written
 *             72 B and read back 72 B by the criterion
 *   per node: position and velocity read and written 96 + lumped mass 8 =
 *             104 B, and the prediction read and written in every
 *             constraint iteration, 48 B each
 *   per bar:  node pair 8 + rest length 8 read in every constraint
 *             iteration; XPBD also compliance 8 and the multiplier read
 *             and written 16
 *   per cohesive element: its state read and written, 2 sizeof(cf_cohesive)
 * Returns bytes per step. */
double cf_step_traffic(const cf_step_stats *st);

void cf_sim_print_summary(const cf_sim *sim, FILE *out);
void cf_sim_destroy(cf_sim *sim);

#endif
