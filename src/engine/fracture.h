/* The in-house solver step (source Table 6.2, docs/physics.md §4), per
 * fragment, and what it shares with the hand-offs.  The step sees the
 * world through a narrow context (cf_step_ctx), never the whole world. */
#ifndef COHFRAC_FRACTURE_H
#define COHFRAC_FRACTURE_H

#include "cohesive_law.h"
#include "contact.h"
#include "fragment.h"
#include "insertion.h"
#include "obstacle.h"
#include "pbd.h"
#include "profile.h"
#include "solid.h"

/* What the solver step reads and writes beyond its fragment
 * (docs/architecture.md, "The step, stage by stage"): the solid, the
 * settings, the obstacles, the cohesive law, the fragments' contact caches
 * (indexed by fragment, n_frag of them), the world's energy flows and
 * profile, and the step's scratch lists.  The world makes one for each
 * call (cf_world_step_ctx, world_impl.h). */
typedef struct cf_step_ctx {
    cf_solid *solid;
    const cf_world_def *def;
    const cf_obstacles *obs;
    const cf_cohesive_law *law;
    const double *law_params;
    cf_contact_caches *contact;
    int n_frag;
    cf_energy_flows *flow;
    cf_profile *prof;
    cf_int_list *cand, *touched, *crushed; /* facets, nodes, tets of a check */
    cf_bars_scratch *bar_scratch;
} cf_step_ctx;

/* One step of the pbd rigid backend (source Table 6.1) on rigid fragment
 * f, number fi of the world's (its contact cache's index): gravity and
 * global damping, then prediction, PBD bars + collision constraints,
 * velocity update, friction and restitution.  t: time at the start of the
 * step (s).  Returns CF_OK or CF_ERR_NOMEM. */
cf_status cf_pbd_rigid_step(const cf_step_ctx *c, cf_fragment *f, int fi, double t, double dt);

/* One fracture step of length dt from time t (s) of the fracture-mode
 * fragments frag[list[0..n)] (source Table 6.2): stresses every
 * check_interval steps, cohesive insertion, internal and cohesive forces,
 * then what cf_pbd_rigid_step does after its damping.  The same bits as
 * stepping each in list order, but stage by stage over all of them (their
 * nodes and elements are disjoint; only insertion, which grows the solid's
 * shared tables, takes them one at a time, in list order).  Fragments
 * below the Tet4 kernel's parallel size step side by side, one per thread
 * (docs/performance.md, "Fragments side by side").  work: 2 n ints of
 * scratch.  *side_by_side: how many stepped so.  Returns CF_OK or
 * CF_ERR_NOMEM. */
cf_status cf_fracture_pass(const cf_step_ctx *c, cf_fragment *frag, const int *list, int n,
                           int *work, double t, double dt, int *side_by_side);

/* Whether rigid fragment f (nodes in the in-house solver) would hit an
 * obstacle during the next step of length dt from time t faster than the
 * impact threshold (normal approach speed). */
int cf_pbd_impact(const cf_step_ctx *c, const cf_fragment *f, double t, double dt);

/* The energy (J) of the penalty contact's springs (docs/physics.md §7.1)
 * under fragment f's nodes at their positions at time t, with the
 * stiffness of fracture step h (the last one taken; 0: none yet): the part
 * of a fracture-mode fragment's e_strain beyond its tets'.  0 without the
 * penalty contact. */
double cf_fragment_spring_energy(const cf_step_ctx *c, const cf_fragment *f, double t, double h);

#endif
