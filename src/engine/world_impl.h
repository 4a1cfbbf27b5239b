/* The simulation state shared by the driver (sim.c), the solver step
 * (fracture.c) and the mode hand-offs (handoff.c). */
#ifndef COHFRAC_SIM_PRIVATE_H
#define COHFRAC_SIM_PRIVATE_H

#include "cf_bullet.h"
#include "clock.h"
#include "cohesive.h"
#include "contact.h"
#include "decompose.h"
#include "fragment.h"
#include "cohfrac/world.h"
#include "insertion.h"
#include "obstacle.h"
#include "pbd.h"
#include "solid.h"

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

/* Rigid -> fracture: nodes from the Bullet state `st` (x = R X + c,
 * v = v + w x r), body removed.  Fills *rec with the hand-off's record (the
 * step makes it an event) and adds it to the run's totals. */
cf_status cf_handoff_to_fracture(cf_world *sim, int fi, const cfb_state *st, cf_handoff_record *rec,
                                 cf_error *err);

/* Fracture -> rigid: split fragment fi into its connected components; each
 * becomes a rigid fragment (a Bullet body with momentum-preserving
 * velocities, or a pbd rigid fragment).  Fills *rec with the hand-off's
 * record (momentum error, handoff_loss) and adds it to the run's totals. */
cf_status cf_handoff_to_rigid(cf_world *sim, int fi, cf_handoff_record *rec, cf_error *err);

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

/* A rigid step is re-run at most this many times for fragments that go to
 * fracture mode during it. */
#define CF_MAX_RESTEPS 4


#endif
