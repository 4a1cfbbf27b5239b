/* The in-house solver step (source Table 6.2, docs/physics.md §4), per
 * fragment, and what it shares with the hand-offs. */
#ifndef COHFRAC_FRACTURE_H
#define COHFRAC_FRACTURE_H

#include "world_impl.h"

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

#endif
