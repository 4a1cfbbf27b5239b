/* Hand-off between rigid mode (Bullet, or the pbd rigid backend) and
 * fracture mode (docs/physics.md §9). */
#ifndef COHFRAC_HANDOFF_H
#define COHFRAC_HANDOFF_H

#include "world_impl.h"

/* Convex decomposition settings (docs/physics.md §9): split until the hulls exceed
 * the tet volume by at most this fraction, into at most this many hulls (and
 * at most one per CF_HULL_TETS_PER_HULL tets of the fragment), cutting no
 * cell of fewer than twice CF_HULL_MIN_TETS tets. */
#define CF_HULL_MAX_ERROR 0.05
#define CF_HULL_MAX_COUNT 64
#define CF_HULL_MIN_TETS 4
#define CF_HULL_TETS_PER_HULL 2

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
