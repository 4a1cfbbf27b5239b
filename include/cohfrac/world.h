/* cohfrac — the engine: a world of Tet4 bodies that fall, collide and
 * break (docs/architecture.md).
 *
 * cf_world_create builds what a world definition (cohfrac/types.h) asks
 * for and nothing else (no Bullet world for the `pbd` rigid backend);
 * cf_world_step advances it by the step its caller gives: the caller owns
 * time (the run loop of cohfrac/sim.h steps to the scene's duration).
 * The world does no file
 * I/O and prints nothing: what happened in a step (hand-offs, new
 * fragments, cohesive insertions) is pushed as events the caller drains
 * (cf_world_events), and everything else is read through the queries below.
 * The run loop that writes HDF5 and shows progress is cohfrac/sim.h. */
#ifndef COHFRAC_WORLD_H
#define COHFRAC_WORLD_H

#include <stdint.h>

#include "cohfrac/error.h"
#include "cohfrac/types.h"

typedef struct cf_world cf_world;

/* The energy ledger (J) and momenta of the whole scene at the current
 * state.  Balance: residual = kinetic + strain + cohesive_stored +
 * cohesive_dissipated + plastic_dissipated + contact + pbd + damping +
 * handoff + integration
 * - (initial + work_gravity + work_boundary + work_obstacles); zero for an
 * exact integrator.  work_obstacles is the work of moving obstacles: the
 * impulse they give a node times their velocity, and for Bullet bodies the
 * energy gained in a rigid step in contact when the scene has moving ones.
 * Kinetic energy of the in-house solver is the leapfrog estimate
 * 1/2 sum m v(n-1/2).v(n+1/2) at the last force evaluation; Bullet bodies'
 * is 1/2 M v^2 + 1/2 w.I w.  `contact`, `pbd`, `damping`, `handoff` are
 * energies removed since t = 0 (see docs/physics.md §4-§9);
 * `integration` is what Bullet's integrator changed in bodies that touched
 * nothing during a rigid step (its implicit gyroscopic term: a free
 * spinning asymmetric body loses a little), never booked as contact.
 * `plastic_dissipated` is the work of crushing (material
 * compressive_strength, docs/physics.md §2.1), 0 without it. */
typedef struct cf_ledger {
    double kinetic, strain, cohesive_stored, cohesive_dissipated, plastic_dissipated;
    double work_gravity, work_boundary, work_obstacles;
    double contact, pbd, damping, handoff, integration;
    double initial;            /* kinetic + strain at t = 0 */
    double residual;
    double momentum[3];        /* kg m/s */
    double angular_momentum[3];/* kg m^2/s, about the origin */
    double mass_moment[3];     /* kg m, sum m x (gravity's work is g . its change) */
} cf_ledger;

/* Build the world `def` describes: every body's mesh placed (scale,
 * orientation, position), renumbered for locality and joined into one solid;
 * boundary conditions, obstacles, the initial fragments (one per connected
 * piece of each body, a Bullet body each in hybrid runs with the Bullet
 * backend).  What the world needs of `def` is copied: `def` and the meshes
 * it points to may be freed after the call.  Threads: the world's own,
 * def->solver.threads (0: the calling thread's OpenMP setting now, all
 * cores by default); its steps run their loops on them and leave the
 * caller's OpenMP setting as it was.
 * Errors: those of cf_world_def_check; CF_ERR_SCENE_VALUE for a boundary
 * region that selects no node or a crack plane with no facet on it;
 * CF_ERR_MESH_* for a mesh that fails its checks; CF_ERR_EXTERNAL (Bullet,
 * FCL); CF_ERR_NOMEM.  On error *out is NULL. */
cf_status cf_world_create(const cf_world_def *def, cf_world **out, cf_error *err);

/* One rigid step of dt seconds (sub-cycled in fracture mode), with
 * hand-offs and the divergence guard.  dt is the regular step
 * cf_world_dt_outer(w) (dt_rigid; fracture-only runs: a whole number of
 * fracture steps), or less to end a run between two regular steps; a
 * fracture-only run then takes the fewest whole fracture steps that cover
 * dt, so cf_world_time may lie less than one fracture step past t + dt.
 * A dt outside (0, cf_world_dt_outer] is a programming error (assert).
 * Errors: CF_ERR_DIVERGED (a non-finite or faster than 1e5 m/s node, more
 * inverted tets than solver.guard.max_inverted_fraction, or kinetic +
 * strain + cohesive energy above (1 + solver.guard.max_energy_growth)
 * times the initial energy plus all work input; the message names
 * dt/dt_cfl and what to change), CF_ERR_NOMEM. */
cf_status cf_world_step(cf_world *w, double dt, cf_error *err);

/* Threads for this world's element loops from the next step on (n >= 1;
 * other worlds and the caller's OpenMP setting keep theirs).  The results
 * do not depend on it: the state hash is the same for any count. */
void cf_world_set_threads(cf_world *w, int n);

/* A heartbeat inside a long rigid step, for progress displays: fn(user, t)
 * is called after every fracture sub-step (t the simulated time it
 * reached, s) and after every cut of the convex decomposition of a
 * fragment handed to Bullet, and at its end (t the time of the hand-off).
 * fn may call the read-only queries (cf_world_stats_get, cf_world_time,
 * cf_world_step_count) and nothing that changes the world.  NULL (the
 * default): no call. */
typedef void (*cf_world_tick_fn)(void *user, double t);
void cf_world_set_tick(cf_world *w, cf_world_tick_fn fn, void *user);

/* Rigid steps taken; the regular rigid step, s (fracture-only runs: a
 * whole number of fracture steps). */
long cf_world_step_count(const cf_world *w);
double cf_world_dt_outer(const cf_world *w);

/* One fragment's record (an initial body or a product of a split). */
typedef struct cf_frag_info {
    int id;
    int parent;              /* -1 for an initial body */
    double birth_time;       /* s */
    double mass;             /* kg */
    int n_tets;
    double inertia_principal[3]; /* kg m^2 */
    int n_hulls;             /* convex hulls of its Bullet shape, 0 none */
    double hull_volume_error;/* hull volume / tet volume - 1 */
    double decomposition_time; /* s of wall time */
    double com_rest[3];      /* m: centre of mass in the rest mesh; the pose maps
                                X to com + R (X - com_rest) */
    int surface_first, surface_count; /* its boundary triangles in the output's
                                /surfaces (filled in by the run loop; 0, 0 when none) */
    int debris;              /* 1: debris, a sphere in Bullet (docs/physics.md §9.2) */
} cf_frag_info;

/* One hand-off between modes. */
typedef struct cf_handoff_record {
    double time;             /* s */
    int fragment;            /* the fragment that changed mode (the parent for a split) */
    int direction;           /* 0 rigid -> fracture, 1 fracture -> rigid */
    double momentum_error;   /* |P_after - P_before| / |P_before| */
    double momentum_change[3];         /* P_after - P_before, kg m/s */
    double angular_momentum_change[3]; /* L_after - L_before about the origin, kg m^2/s */
    double handoff_loss;     /* J: kinetic energy not carried by rigid motion */
} cf_handoff_record;

/* What happened during the steps since the caller last drained the events,
 * in order. */
typedef enum {
    CF_EVENT_FRAGMENTS,  /* fragments first .. first + count - 1 were born
                            (the initial bodies at create, pieces of a split) */
    CF_EVENT_HANDOFF,    /* a fragment changed mode: `handoff` */
    CF_EVENT_INSERTIONS  /* cohesive elements first .. first + count - 1 were inserted
                            during the rigid step that ended at `time` */
} cf_event_type;

typedef struct cf_event {
    cf_event_type type;
    double time;             /* s */
    int first, count;        /* fragments or cohesive elements */
    int alive;               /* fragments alive after the event */
    cf_handoff_record handoff;
} cf_event;

/* The events pushed since the last cf_world_clear_events: *n of them. */
const cf_event *cf_world_events(const cf_world *w, int *n);
void cf_world_clear_events(cf_world *w);

/* Fragment `id`'s record (any id below cf_world_fragments_ever, dead or
 * alive).  Returns 0, or -1 for an unknown id. */
int cf_world_fragment_info(const cf_world *w, int id, cf_frag_info *out);
int cf_world_fragments_ever(const cf_world *w);

/* Simulated time, s. */
double cf_world_time(const cf_world *w);

/* The fracture-mode step (solver.dt_fracture, or cfl_fraction x dt_cfl)
 * and the mesh's explicit stability limit dt_cfl (docs/physics.md §3), s. */
double cf_world_dt_fracture(const cf_world *w);
double cf_world_dt_cfl(const cf_world *w);

/* The explicit stability limit of a Tet4 mesh before any world is made:
 * min over tets of h / c_d, h twice the inradius (6 V / total face area)
 * and c_d = sqrt(E (1 - nu) / (rho (1 + nu) (1 - 2 nu))) the dilatational
 * wave speed (docs/physics.md §3), the mesh scaled by `scale` first.  In s;
 * INFINITY for a mesh without tets, NaN when a tet is degenerate. */
double cf_mesh_dt_cfl(const cf_mesh *m, double scale, const cf_material *mat);

/* Where body b puts points x [n][3] given in its mesh's file units, as
 * cf_world_create places the mesh's nodes: out = position + scale R (x - c),
 * R the body's orientation and c the bounding-box centre of `mesh`'s nodes
 * (m).  out may be x. */
void cf_body_place(const cf_body_def *b, const cf_mesh *mesh, const double *x, int n,
                   double *out);

/* The energy ledger and momenta now. */
void cf_world_ledger(const cf_world *w, cf_ledger *out);

/* One alive fragment's rigid state now (pose as docs/physics.md §1).  `kinetic` is
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
int cf_world_fragments(cf_world *w, cf_fragment_state *out, int cap);

/* Number of tets of the scene's solid, and the fragment (id) that tet t
 * belongs to now: fragments of two runs of one scene are matched through
 * their tets.  -1 for t out of range. */
int cf_world_tet_count(const cf_world *w);
int cf_world_tet_fragment(const cf_world *w, int t);

/* The rest mesh as placed at create, before any node duplication: its
 * node count, the positions X[n][3] (m) in the world's node numbering, and
 * tet t's four nodes in that numbering (t in input order; returns 0, or -1
 * out of range).  A fragment's rest shape is its tets on these nodes; its
 * pose (cf_fragment_state com, quat) moves X - com_rest (cf_frag_info). */
int cf_world_rest_node_count(const cf_world *w);
void cf_world_rest_nodes(const cf_world *w, double *X);
int cf_world_rest_tet(const cf_world *w, int t, int nodes[4]);

/* The four corners of tet t (input numbering) now, x[4][3] in m: the
 * nodes of a fracture-mode or pbd-rigid fragment as they are, those of a
 * Bullet body its rest shape moved by the body's pose.  Returns 0, or -1
 * for t out of range. */
int cf_world_tet_positions(const cf_world *w, int t, double x[12]);

/* The tets of fracture-mode fragments now, for the viewers, in input order:
 * tets[k] (input numbering), stress[k][6] the Cauchy stress at the last
 * insertion check (Pa; xx yy zz yz xz xy), damage[k] the largest damage
 * of the cohesive elements on its faces (0 intact, 1 a free crack face:
 * the energy they dissipated over G_I times their area, docs/physics.md
 * §6).  Each array holds cf_world_tet_count() entries (times 6 for
 * stress).  Returns how many were written, -1 when out of memory. */
int cf_world_fracture_tets(const cf_world *w, int *tets, double *stress, double *damage);

/* Support distance of fragment `id` along unit direction d now: the largest
 * (R (X - X_cm)).d over its nodes, m, with X the rest positions and R the
 * fragment's rigid pose (deformation is not seen); 0 for a dead or unknown
 * fragment. */
double cf_world_fragment_support(cf_world *w, int id, const double d[3]);

/* A landing to come, a rigid fragment in flight whose ballistic path
 * meets an obstacle hard enough to send it to fracture mode, or one under
 * way, a piece in fracture mode since an impact of its own. */
typedef struct cf_landing {
    int fragment;            /* id */
    int n_tets;
    int under_way;           /* 1: in fracture mode now, 0: to come */
    double time;             /* s: the simulated time it lands at; under way, when
                                its spell began */
    double speed;            /* m/s: its approach along the obstacle's normal then
                                (0 under way) */
    double impact;           /* m/s: the contact impulse over its mass that the
                                impact rule will see, (1 + e) speed m_eff / m, m_eff
                                the mass its point of contact brings, e the pair's
                                restitution; under way, the one that began the spell */
    double hold;             /* s: its landing time, the longest a fixed obstacle
                                holds it in fracture mode (docs/physics.md §9) */
} cf_landing;

/* The landings under way, the pieces (not initial bodies) in fracture
 * mode since an impact of their own (not their parent's spell: a break's
 * length is its cracks' growth), and those to come before simulated time
 * `until` (s), the forecast of the impact rule (docs/physics.md §9): each
 * rigid fragment with a Bullet body that can still break and touches
 * nothing (no contact in Bullet's last step, and clear of every obstacle
 * by a thousandth of its size), its centre of mass on its ballistic path
 * under gravity, its shape at its pose now (its spin is not followed),
 * against the obstacles; those whose impact passes the impact threshold
 * and the strongest impact the fragment has taken (a contact it took
 * whole does not send it back).  Other fragments and bodies are not
 * looked for, nor a mesh obstacle farther than its contact query reaches
 * (5 % of its size).  Writes up to `cap` to out (may be NULL with cap 0) and
 * returns how many there are; with the pbd rigid backend, those under way
 * only; none in a fracture-only run.  Reads the world only. */
int cf_world_landings(cf_world *w, double until, cf_landing *out, int cap);

/* FNV-1a hash of the state's bits: every node's position and velocity,
 * each tet's fragment, each fragment's mode and its Bullet body's state.
 * Two runs of one scene give the same hash at the same step, for any thread
 * count (the element loops write per-element results and sum them in a
 * fixed order). */
uint64_t cf_world_state_hash(const cf_world *w);

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
                                     largest seen at a frame (filled in by the run
                                     loop, cohfrac/sim.h; 0 from cf_world_memory) */
} cf_memory;

void cf_world_memory(const cf_world *w, cf_memory *m);

/* The stages of a step, in the order they first run (docs/architecture.md,
 * "The step, stage by stage", has a section per stage: what it reads and
 * writes).  Each stage is a function of the same name in the engine and a
 * timer of the same name in the profile (cf_world_stats.stage,
 * cf_step_stats.stage).  The timers take turns: each charges the wall time
 * since the last one stopped, so no time is counted twice and the stages
 * add up to the step.  A stage may run several times in a step (collision
 * runs in every projection sweep); with the pbd rigid backend the rigid
 * fragments' damped steps run the solver's stages too. */
#define CF_STAGES(X)                                                                               \
    X(RIGID_STEP, rigid_step)         /* Bullet steps the rigid fragments; impacts */              \
    X(ELASTICITY, elasticity)         /* Tet4 forces, stress, strain energy */                     \
    X(INSERTION_CHECK, insertion_check) /* facets that meet the criterion; the growth rule */      \
    X(NODE_DUPLICATION, node_duplication) /* cohesive elements inserted, nodes split; crushing */  \
    X(COHESIVE_FORCES, cohesive_forces) /* PPR tractions and crack-face contact forces */          \
    X(COLLISION, collision)           /* obstacles, rigid bodies' hulls, other bodies, friction */ \
    X(INTEGRATION, integration)       /* velocity kick, ledger's kinetic energy, prediction */     \
    X(PBD_PROJECTION, pbd_projection) /* PBD/XPBD bars and crack-face constraints */               \
    X(VELOCITY_UPDATE, velocity_update) /* v = (p - x)/dt, x = p, the speed cap */                 \
    X(SPLIT, split)                   /* fracture-mode fragments that fell apart */                \
    X(HANDOFF, handoff)               /* rigid <-> fracture mode */                                \
    X(CONVEX_DECOMPOSITION, convex_decomposition) /* a new rigid fragment's hulls */              \
    X(BOOKKEEPING, bookkeeping)       /* events, the guards, the caller's heartbeat */

typedef enum {
#define CF_STAGE_ENUM(id, name) CF_STAGE_##id,
    CF_STAGES(CF_STAGE_ENUM)
#undef CF_STAGE_ENUM
    CF_STAGE_COUNT
} cf_stage;

/* The in-house solver's own stages (one step of a fragment,
 * cf_solver_step) are the range FIRST..LAST of cf_stage: the time per
 * fracture step of the summary and `cohfrac bench`'s columns. */
#define CF_STAGE_SOLVER_FIRST CF_STAGE_ELASTICITY
#define CF_STAGE_SOLVER_LAST CF_STAGE_VELOCITY_UPDATE

/* The stage's name ("elasticity"), or "?" for a value out of range. */
const char *cf_stage_name(cf_stage s);

/* The fracture-mode step so far, for benchmarks: steps taken, wall time
 * per stage (s, as in the run summary), and the sizes of what the step
 * works on now (fracture-mode fragments only). */
typedef struct cf_step_stats {
    long fracture_steps;                   /* fracture-mode fragment steps since creation */
    long long tet_steps;                   /* tets stepped, summed over those steps */
    double fracture_time;                  /* s simulated with a fragment in fracture mode */
    double spell_time;                     /* s since the fracture-mode fragment that has been
                                              in it longest entered it (0: none in it) */
    double stage[CF_STAGE_COUNT];          /* s of wall time since creation (cf_stage) */
    int tets, nodes, bars, cohesive;       /* in fracture mode now */
    int iterations;                        /* constraint iterations per step */
    int check;                             /* 1: the insertion criterion is checked */
    int xpbd;                              /* 1: XPBD bars (compliance, multipliers) */
    int colours;                           /* most bar colours in one fragment (a sweep
                                              waits once per colour) */
    int serial_bars;                       /* bars no colour could take (swept on one thread) */
} cf_step_stats;

void cf_world_step_stats(const cf_world *w, cf_step_stats *out);

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

/* One cohesive element (crack facet) now. */
typedef struct cf_crack_row {
    double time;             /* s */
    int element;             /* cohesive element index (order of insertion) */
    double centroid[3];      /* m, mid-surface centre */
    double normal[3];        /* unit, mid-surface normal from side A to side B */
    double area;             /* m^2, mid-surface */
    double opening;          /* m, normal opening, mean of its three node pairs */
    double sliding;          /* m, tangential opening, the same mean */
    int failed;              /* 1: every node pair has failed (a free crack face) */
    int tets[2];             /* the tets on sides A and B, indices of the mesh's tets:
                                the facet the element lies on */
} cf_crack_row;

/* Number of cohesive elements, and element e's state: 0, or -1 with *out
 * zeroed for e outside 0 <= e < count. */
int cf_world_cohesive_count(const cf_world *w);
int cf_world_crack(const cf_world *w, int e, cf_crack_row *out);

/* Crack area now, m^2 (cf_solid_crack_area). */
double cf_world_crack_area(const cf_world *w);

/* The initial state's bounds, for readers that check a run's outcome
 * (tests/checks/check_physics.py): the box around the nodes (m), total mass (kg),
 * kinetic + strain energy (J), fastest node (m/s), fastest kinematic
 * obstacle or prescribed velocity (m/s), and the release speed (m/s): the
 * particle velocity a stress wave of the strongest facet's strength carries,
 * max(sigma_max / sqrt(rho E), tau_max / sqrt(rho mu)) times the largest
 * strength factor (1-D wave theory, v = sigma / (rho c)); 0 without an
 * insertion criterion.  A piece cut free from a body held at its strength
 * springs back at most at about that speed. */
typedef struct cf_initial_bounds {
    double lower[3], upper[3];
    double mass, energy, max_speed, max_obstacle_speed, release_speed;
} cf_initial_bounds;

void cf_world_initial_bounds(const cf_world *w, cf_initial_bounds *out);

/* Figures for a run summary: sizes, steps per mode, fragments, hand-offs,
 * the convex decomposition of the rigid fragments alive now, and the wall
 * time each stage of the step took since create (s, cf_stage). */
typedef struct cf_world_stats {
    int tets, nodes_input, nodes;       /* nodes after duplication */
    double dt_fracture, dt_cfl, dt_outer;/* s */
    int mass_scaled;                    /* tets whose density solver.mass_scaling raised */
    double mass_added, mass_total;      /* kg: what it added; the bodies' mass with it (0: none) */
    double wave_speed_least;            /* the slowest scaled tet's wave speed over c_d */
    long steps_rigid, steps_fracture;   /* rigid steps; fracture-mode fragment steps */
    int threads;
    int alive, in_fracture, ever;       /* fragments */
    int cohesive;
    int handoffs;
    double max_momentum_error, handoff_loss; /* relative; J */
    int debris;                         /* fragments alive that are debris (§9.2) */
    double debris_mass, mass_alive;     /* kg: their mass, and all fragments' alive */
    int rigid_with_hulls, hulls;        /* Bullet bodies alive with hulls, and the hulls */
    double hull_error_median, hull_error_worst; /* hull volume / tet volume - 1 (NaN:
                                                 * no memory to sort them) */
    double stage[CF_STAGE_COUNT];       /* s of wall time in each stage since create */
} cf_world_stats;

void cf_world_stats_get(const cf_world *w, cf_world_stats *out);

/* The world's copy of its definition (settings, obstacles, boundary
 * conditions; no bodies: they are used up at create). */
const cf_world_def *cf_world_definition(const cf_world *w);

void cf_world_destroy(cf_world *w);

#endif
