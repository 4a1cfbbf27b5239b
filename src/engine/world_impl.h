/* The world record: what a world (world_create.c, world_step.c,
 * world_query.c) owns and the stages that take
 * the whole world read, the solver step (fracture.h) and the mode
 * hand-offs (handoff.h).  Data only: the functions are in those headers,
 * so that this one includes no stage above it. */
#ifndef COHFRAC_SIM_PRIVATE_H
#define COHFRAC_SIM_PRIVATE_H

#include "arena.h"
#include "cf_bullet.h"
#include "clock.h"
#include "cohesive.h"
#include "contact.h"
#include "decompose.h"
#include "fracture.h"
#include "fragment.h"
#include "cohfrac/world.h"
#include "insertion.h"
#include "obstacle.h"
#include "pbd.h"
#include "profile.h"
#include "solid.h"

struct cf_world {
    cf_world_def def;        /* the world's copy (obstacles and boundaries too) */
    cf_solid solid;
    const cf_cohesive_law *law; /* the cohesive law (PPR) and its parameters */
    double law_params[CF_LAW_PARAMS_MAX];
    cf_obstacles obs;
    cf_fragment *frag;
    int n_frag, cap_frag;
    cf_contact_caches contact; /* the fragments' contact caches, by fragment */
    cfb_world *bullet;       /* NULL for the pbd rigid backend */
    double t;                /* s */
    cf_world_tick_fn tick;   /* heartbeat inside a step (cf_world_set_tick), or NULL */
    int threads;             /* the element loops' threads (cf_world_set_threads) */
    void *tick_user;
    long step;               /* rigid steps done */
    double dt_fracture;      /* s: solver.dt_fracture, or cfl_fraction dt_cfl */
    double h_fracture;       /* s: the last fracture step taken (the penalty's stiffness) */
    double dt_outer;         /* s: dt_rigid (fracture-only runs: a whole number of
                                fracture steps) */
    double next_frame;       /* s */
    cf_profile prof;         /* wall time per stage (profile.h) */
    cf_arena arena;          /* the step's scratch, empty between steps (arena.h) */
    long steps_rigid, steps_fracture;
    long long tet_steps_fracture; /* sum over fracture steps of the tets stepped */
    long steps_side_by_side;      /* of the fracture steps, those taken one per thread */
    double t_fracture;       /* s of simulated time with a fragment in fracture mode */
    cf_energy_flows flow;
    double e0;               /* J, initial kinetic + strain energy */
    double mx0[3];           /* kg m, initial sum m x */
    int n_handoffs;
    double max_momentum_error, total_handoff_loss;
    double wall_start;
    int *obstacle_body;      /* [n_obstacles] Bullet body of each obstacle */
    unsigned char *obstacle_moving; /* [n_obstacles] kinematic (restored on a re-step) */
    unsigned long long bullet_base; /* Bullet allocator bytes when the run was created */
    int *tet_of_user;        /* [n_tets] the solid's tet of each input tet (the solid is
                                renumbered for locality at load: renumber.h) */
    int *user_of_tet;        /* [n_tets] the input tet of each of the solid's */
    cf_int_list cand;        /* facets that qualify at a check (scratch of the step) */
    cf_int_list touched;     /* nodes whose star the step's insertions changed (scratch) */
    cf_int_list crushed;     /* tets the step's check crushed (scratch) */
    cf_bars_scratch bar_scratch; /* of cf_bars_patch */
    cf_initial_bounds bounds;/* taken at create */
    cf_event *ev;            /* events since the caller last drained them */
    int n_ev, cap_ev;
};

/* Whether any step of world w reads the bars: the pbd backend's rigid
 * steps, and fracture steps with constraints.  Explicit fracture mode
 * beside Bullet never does, and building and patching them for it cost
 * the 202,231-tet plaster drop a serial hundredth of its break
 * (docs/performance.md). */
static inline int cf_world_reads_bars(const cf_world *w)
{
    return !w->bullet || w->def.solver.constraints != CF_CONSTRAINTS_NONE;
}

/* The narrow view of world w that the solver step gets (fracture.h); made
 * for each use, as the fragment count changes. */
static inline cf_step_ctx cf_world_step_ctx(cf_world *w)
{
    return (cf_step_ctx){.solid = &w->solid, .def = &w->def, .obs = &w->obs, .law = w->law,
                         .law_params = w->law_params, .contact = &w->contact,
                         .n_frag = w->n_frag, .flow = &w->flow, .prof = &w->prof,
                         .cand = &w->cand, .touched = &w->touched, .crushed = &w->crushed,
                         .bar_scratch = &w->bar_scratch};
}

#endif
