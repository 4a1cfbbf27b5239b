/* The simulation state shared by the driver (sim.c), the solver step
 * (fracture.c) and the mode hand-offs (handoff.c). */
#ifndef COHFRAC_SIM_PRIVATE_H
#define COHFRAC_SIM_PRIVATE_H

#include "cf_bullet.h"
#include "clock.h"
#include "cohesive.h"
#include "contact.h"
#include "decompose.h"
#include "cohfrac/world.h"
#include "fragments.h"
#include "insertion.h"
#include "obstacle.h"
#include "pbd.h"
#include "solid.h"

/* Energy removed or put in by each mechanism since t = 0, J (docs/physics.md §4-§6;
 * the ledger balance is in cf_world_ledger). */
typedef struct cf_energy_flows {
    double boundary;   /* work of prescribed velocities */
    double obstacles;  /* work of moving obstacles (the energy contact with them put in) */
    double contact;    /* removed by obstacle contact: restitution, friction, and
                          the Bullet bodies' energy change beyond gravity's work */
    double pbd;        /* removed by the PBD/XPBD projection */
    double damping;    /* removed by global damping */
    double handoff;    /* non-rigid kinetic + strain + cohesive stored energy
                          dropped at fracture -> rigid hand-offs, less put_in */
    double put_in;     /* energy hand-offs put in (part of handoff): the strain
                          of pieces wedged between obstacles entering fracture
                          mode, and gravity's potential of pieces moved clear of
                          obstacles */
    double integration; /* changed by Bullet's integrator in bodies touching nothing */
} cf_energy_flows;

typedef enum { CF_MODE_DEAD = -1, CF_MODE_RIGID = 0, CF_MODE_FRACTURE = 1 } cf_mode;

typedef struct cf_fragment {
    int parent;              /* -1 for an initial body */
    double birth_time;       /* s */
    cf_mode mode;
    int *tets, nt;           /* ascending */
    cf_int_list nodes;
    /* Rest-shape mass properties: principal axes Q (columns), moments. */
    double mass, com_rest[3], Q[9], principal[3];
    double volume;           /* m^3, its tets' rest volume */
    int body;                /* Bullet body id, -1 when none */
    double q_match[4];       /* shape-matching warm start */
    /* In-house solver state (fracture mode, or pbd rigid mode). */
    cf_bars bars;
    cf_int_list coh;         /* its cohesive elements */
    long steps, quiet;       /* solver steps in this mode; steps since the last insertion */
    int separated;           /* its cohesive elements with every node pair failed at the
                                last split check; -1: not counted yet */
    double t_enter;          /* s, when fracture mode began */
    double e_enter;          /* J, its kinetic energy when fracture mode began */
    int *contact;            /* [nodes.n] obstacle in contact after the last projection, -1 */
    double *vn_pre;          /* [nodes.n] normal velocity before projection, m/s */
    double *v_old;           /* [nodes.n][3] velocity at the start of the step, m/s */
    double *term;            /* [nodes.n] per-node energy terms, J, summed in node order */
    int scratch_cap;
    cf_pair_force *pairs;    /* [3 pairs_cap] cohesive forces of a step (scratch) */
    int pairs_cap;           /* elements it has room for */
    /* Energy ledger state at the last force evaluation (in-house solver). */
    double e_kin;            /* J, 1/2 sum m v(n-1/2).v(n+1/2) (leapfrog estimate) */
    double e_strain;         /* J */
    double mx[3];            /* kg m, sum m x */
    /* What the last projection (bars, obstacles, prescribed nodes, friction
     * and restitution) did, booked into the world's flows when the next step
     * starts or the hand-off takes the fragment (cf_fragment_book_pending):
     * the projection of step n takes the state to n + 1, and e_kin is the
     * kinetic energy at step n. */
    cf_energy_flows pending;
    int n_inverted;          /* tets with det F <= 0 */
    /* Rigid mode with Bullet: the convex decomposition (principal frame). */
    cf_hulls hulls;
    double decompose_time;   /* s of wall time to decompose it */
    double pushed;           /* N s: impulse fracture-mode nodes gave its body
                                since the last rigid step (impact trigger) */
    cf_node_impulses push;   /* fracture mode: impulses its nodes gave bodies */
    cf_hull_set near;        /* fracture mode: hulls of the rigid bodies near it
                                this rigid step */
    cf_frag_surface surface; /* fracture mode: its boundary, for contact with
                                other bodies' fragments */
} cf_fragment;

/* Convex decomposition settings (docs/physics.md §9): split until the hulls exceed
 * the tet volume by at most this fraction, into at most this many hulls (and
 * at most one per CF_HULL_TETS_PER_HULL tets of the fragment), cutting no
 * cell of fewer than twice CF_HULL_MIN_TETS tets. */
#define CF_HULL_MAX_ERROR 0.05
#define CF_HULL_MAX_COUNT 64
#define CF_HULL_MIN_TETS 4
#define CF_HULL_TETS_PER_HULL 2


typedef struct cf_profile {
    double rigid, stress, insertion, forces, pbd, bodies, handoff, decompose; /* s of wall time */
} cf_profile;

struct cf_world {
    cf_world_def def;        /* the world's copy (obstacles and boundaries too) */
    cf_solid solid;
    const cf_cohesive_law *law; /* the cohesive law (PPR) and its parameters */
    double law_params[CF_LAW_PARAMS_MAX];
    cf_obstacles obs;
    cf_fragment *frag;
    int n_frag, cap_frag;
    cfb_world *bullet;       /* NULL for the pbd rigid backend */
    double t;                /* s */
    cf_world_tick_fn tick;   /* heartbeat inside a step (cf_world_set_tick), or NULL */
    void *tick_user;
    long step;               /* rigid steps done */
    long n_steps;            /* rigid steps in the scene's duration */
    double dt_fracture;      /* s: solver.dt_fracture, or cfl_fraction dt_cfl */
    double h_fracture;       /* s: the last fracture step taken (the penalty's stiffness) */
    double dt_outer;         /* s: dt_rigid (fracture-only runs: a whole number of
                                fracture steps) */
    double next_frame;       /* s */
    cf_profile prof;
    long steps_rigid, steps_fracture;
    long long tet_steps_fracture; /* sum over fracture steps of the tets stepped */
    double t_fracture;       /* s of simulated time with a fragment in fracture mode */
    cf_energy_flows flow;
    double e0;               /* J, initial kinetic + strain energy */
    double mx0[3];           /* kg m, initial sum m x */
    int n_handoffs;
    double max_momentum_error, total_handoff_loss;
    double wall_start;
    int *obstacle_body;      /* [n_obstacles] Bullet body of each obstacle */
    unsigned char *obstacle_moving; /* [n_obstacles] kinematic (restored on a re-step) */
    double *body_boxes;      /* [n_frag][6] Bullet bodies' boxes (cf_body_boxes) */
    unsigned long long bullet_base; /* Bullet allocator bytes when the run was created */
    int *tet_of_user;        /* [n_tets] the solid's tet of each input tet (the solid is
                                renumbered for locality at load: renumber.h) */
    cf_int_list cand;        /* facets that qualify at a check (scratch of the step) */
    cf_int_list touched;     /* nodes whose star the step's insertions changed (scratch) */
    cf_int_list crushed;     /* tets the step's check crushed (scratch) */
    cf_bars_scratch bar_scratch; /* of cf_bars_patch */
    cf_initial_bounds bounds;/* taken at create */
    cf_event *ev;            /* events since the caller last drained them */
    int n_ev, cap_ev;
};

/* One step of the in-house solver on fragment f (source Table 6.2): with
 * `fracture` set, stresses every check_interval steps, cohesive insertion,
 * internal and cohesive forces; otherwise (pbd rigid mode) global damping
 * instead.  Then prediction, PBD bars + collision constraints, velocity
 * update, friction and restitution.  t: time at the start of the step (s).
 * Returns CF_OK or CF_ERR_NOMEM. */
cf_status cf_solver_step(cf_world *sim, int fi, double t, double dt, int fracture);

/* Whether rigid fragment fi (nodes in the in-house solver) would hit an
 * obstacle during the next step of length dt faster than the impact
 * threshold (normal approach speed). */
int cf_pbd_impact(const cf_world *sim, int fi, double dt);

/* The energy (J) of the penalty contact's springs (docs/physics.md §7.1)
 * under fragment f's nodes at their positions now (time sim->t, the
 * stiffness of the last fracture step): the part of a fracture-mode
 * fragment's e_strain beyond its tets'.  0 without the penalty contact. */
double cf_fragment_spring_energy(const cf_world *sim, const cf_fragment *f);

/* Whether fragment f is debris (docs/physics.md §9.2): 1 or 0. */
int cf_fragment_is_debris(const cf_world *sim, const cf_fragment *f);

/* Compute the rest-shape mass properties of fragment fi. */
void cf_fragment_rest_props(cf_world *sim, int fi);

/* Rigid -> fracture: nodes from the Bullet state `st` (x = R X + c,
 * v = v + w x r), body removed.  Records the hand-off. */
cf_status cf_handoff_to_fracture(cf_world *sim, int fi, const cfb_state *st, cf_error *err);

/* Fracture -> rigid: split fragment fi into its connected components; each
 * becomes a rigid fragment (a Bullet body with momentum-preserving
 * velocities, or a pbd rigid fragment).  Records momentum error and
 * handoff_loss. */
cf_status cf_handoff_to_rigid(cf_world *sim, int fi, cf_error *err);

/* Fracture-only runs: split fracture-mode fragment fi into its connected
 * components, each a new fracture-mode fragment (its tets, nodes, bars and
 * cohesive elements; the ledger's kinetic energy, strain energy and mass
 * moment carried over node by node, so the ledger does not jump).  Sets
 * *first to the first new fragment and returns the number made (0: fi is
 * one piece and stays), or -1 when out of memory. */
int cf_fragment_split_fracture(cf_world *sim, int fi, int *first);

/* Add a Bullet body for rigid fragment fi with COM pos, rotation R (rest ->
 * current), velocity v and angular velocity w. */
cf_status cf_fragment_add_body(cf_world *sim, int fi, const double pos[3], const double R[9],
                               const double v[3], const double w[3], cf_error *err);

/* Centre of mass, rotation, velocities of fragment fi, whatever its mode.
 * In fracture mode the rotation is the shape matching's, warm-started from
 * and written back to the fragment's q_match: the step's own calls.
 * cf_fragment_pose_peek leaves q_match alone, so that reading a pose
 * (output frames, queries) never changes a run's bits. */
void cf_fragment_pose(cf_world *sim, int fi, double com[3], double R[9], double v[3], double w[3]);
void cf_fragment_pose_peek(const cf_world *sim, int fi, double com[3], double R[9], double v[3],
                           double w[3]);

/* The ledger state of fragment fi from its nodes now: exact kinetic energy,
 * zero strain energy, sum m x. */
void cf_fragment_ledger_reset(cf_world *sim, int fi);

/* Adds fragment f's pending flows to the world's and clears them. */
void cf_fragment_book_pending(cf_world *sim, cf_fragment *f);

/* Bullet collision margin of fragment fi: 0.1% of its size, m (Bullet's
 * default 4 cm would hold small fragments off the ground). */
double cf_fragment_margin(const cf_world *sim, int fi);

/* Push a hand-off event (handoff.c records them). */
cf_status cf_world_push_handoff(cf_world *sim, const cf_handoff_record *r, cf_error *err);

/* A rigid step is re-run at most this many times for fragments that go to
 * fracture mode during it. */
#define CF_MAX_RESTEPS 4

/* Angular momentum of fragment f's Bullet body about its centre of mass,
 * I w with I = Rb diag(principal) Rb^T, kg m^2/s. */
void cf_body_spin(const cf_fragment *f, const cfb_state *st, double Iw[3]);

/* Linear (kg m/s) and angular momentum (kg m^2/s, about the origin) of
 * fragment f's Bullet body in state st: P = M v, L = M c x v + I w. */
void cf_body_momenta(const cf_fragment *f, const cfb_state *st, double P[3], double L[3]);

/* The same for fragment fi now: of its Bullet body, or of its nodes. */
void cf_fragment_momenta(const cf_world *sim, int fi, double P[3], double L[3]);

/* Kinetic energy of rigid fragment fi's Bullet body, J. */
double cf_body_kinetic_energy(const cf_world *sim, int fi);

/* Append a new fragment; returns its index or -1 (out of memory). */
int cf_fragment_new(cf_world *sim, int parent, double birth_time);

/* The initial body fragment fi descends from (its family: fragments of one
 * body do not collide with each other). */
int cf_fragment_root(const cf_world *sim, int fi);

#endif
