/* The energy ledger of a world (docs/physics.md §10): what the step's
 * energy guard and the queries share. */
#ifndef COHFRAC_WORLD_LEDGER_H
#define COHFRAC_WORLD_LEDGER_H

#include "world_impl.h"

/* Kinetic energy minus gravity's potential work of fragment f in Bullet
 * state st: what a Bullet body keeps in free flight, J. */
double cf_world_body_energy(const cf_world *w, const cf_fragment *f, const cfb_state *st);

/* The ledger into *l; the momenta too with `momenta` (for fragments in
 * fracture mode a pass over their nodes, which the energy guard does not
 * need).  cf_world_ledger is this with momenta. */
void cf_world_ledger_terms(const cf_world *w, cf_ledger *l, int momenta);

#endif
